/*
 * mem.h: prefaulting large buffers (docs/speed.md).
 *
 * A process touching fresh memory takes a page fault per 4 KiB page; on the virtual machines
 * prsm is measured on each costs 10-15 µs, so a 700 KB buffer written in full cost about 2 ms in
 * faults where populating the same pages in one system call (Linux's MADV_POPULATE_WRITE, 5.14)
 * takes about 0.3 ms. Only for buffers that are about to be written in full: populating memory
 * that is never used commits it for nothing.
 */
#ifndef PRSM_UTIL_MEM_H
#define PRSM_UTIL_MEM_H

#include <stddef.h>

/* Prefault the whole pages inside [p, p + n) for writing, in one system call. Contents are
 * unchanged; nothing happens for small ranges (under 64 KiB) or where the kernel does not
 * support it. */
void prsm_mem_populate(void *p, size_t n);

/* calloc(1, n), its pages then prefaulted (prsm_mem_populate): for a large struct that its user
 * clears or fills in full. Free with free(). */
void *prsm_mem_calloc_populated(size_t n);

#endif
