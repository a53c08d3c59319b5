/*
 * utf8.h: byte-bounded copies that never cut a UTF-8 character in two.
 *
 * Text from a request is limited in characters (JSON Schema's maxLength) but kept in fixed byte
 * buffers; snprintf truncates by bytes and can leave half a multi-byte character, which makes
 * every JSON document written from it invalid (found by the fuzz targets, tests/fuzz).
 */
#ifndef PRSM_UTIL_UTF8_H
#define PRSM_UTIL_UTF8_H

#include <stddef.h>

/* Drop an incomplete UTF-8 sequence at the end of the NUL-terminated s (what a byte-bounded
 * truncation of valid UTF-8 leaves); s is otherwise unchanged. */
void prsm_utf8_trim_partial(char *s);

/* snprintf(dst, cap, "%s", src), then prsm_utf8_trim_partial when it was truncated. Returns 1
 * when all of src fitted, 0 when it was cut (at a character boundary). cap >= 1. */
int prsm_utf8_copy(char *dst, size_t cap, const char *src);

#endif
