/*
 * mem.c: prefaulting large buffers; see mem.h.
 */
#include "util/mem.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

#define POPULATE_MIN ((size_t)64 * 1024)

void prsm_mem_populate(void *p, size_t n)
{
	if (p == NULL || n < POPULATE_MIN)
		return;
	const long ps = sysconf(_SC_PAGESIZE);
	const size_t page = ps > 0 ? (size_t)ps : 4096;
	const uintptr_t begin = ((uintptr_t)p + page - 1) / page * page;
	const uintptr_t end = ((uintptr_t)p + n) / page * page;
	if (end > begin)
		(void)madvise((void *)begin, (size_t)(end - begin), MADV_POPULATE_WRITE); /* a hint: errors ignored */
}

void *prsm_mem_calloc_populated(size_t n)
{
	void *p = calloc(1, n);
	prsm_mem_populate(p, n);
	return p;
}
