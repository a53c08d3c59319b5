/*
 * utf8.c: see utf8.h.
 */
#include "util/utf8.h"

#include <stdio.h>
#include <string.h>

/* Bytes a sequence with this lead byte has (1 for ASCII and for bytes that cannot lead). */
static size_t sequence_length(unsigned char c)
{
	if (c >= 0xF0 && c <= 0xF4)
		return 4;
	if (c >= 0xE0)
		return c <= 0xEF ? 3 : 1;
	if (c >= 0xC2)
		return 2;
	return 1;
}

void prsm_utf8_trim_partial(char *s)
{
	size_t n = strlen(s);
	/* the last lead byte lies within the last 4 bytes */
	size_t back = 0;
	while (back < n && back < 4) {
		unsigned char c = (unsigned char)s[n - 1 - back];
		if ((c & 0xC0) != 0x80) {
			if (c >= 0x80 && sequence_length(c) > back + 1)
				s[n - 1 - back] = '\0'; /* its continuation bytes were cut off */
			return;
		}
		back++;
	}
	if (back == 4 || back == n)
		s[n - back] = '\0'; /* only continuation bytes: not a character */
}

int prsm_utf8_copy(char *dst, size_t cap, const char *src)
{
	int n = snprintf(dst, cap, "%s", src);
	if (n >= 0 && (size_t)n < cap)
		return 1;
	prsm_utf8_trim_partial(dst);
	return 0;
}
