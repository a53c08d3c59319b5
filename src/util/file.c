/*
 * file.c: bounded whole-file reads.
 */
#include "util/file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int prsm_file_read(char **out, size_t *len, const char *path, size_t max_bytes, prsm_error *err)
{
	int rc = 0;
	FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "rb");
	char *buf = NULL;
	size_t cap = 0, n = 0;
	*out = NULL;
	*len = 0;
	if (f == NULL)
		return prsm_error_set(err, PRSM_EIO, NULL, "cannot open %s: %s", path, strerror(errno));
	for (;;) {
		if (n + 1 >= cap) {
			size_t ncap = cap ? cap * 2 : 65536;
			if (ncap > max_bytes + 2)
				ncap = max_bytes + 2;
			if (ncap <= cap) {
				rc = prsm_error_set(err, PRSM_EINVAL, NULL, "%s is larger than %zu bytes", path, max_bytes);
				goto cleanup;
			}
			char *nb = realloc(buf, ncap);
			if (nb == NULL) {
				rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory reading %s", path);
				goto cleanup;
			}
			buf = nb;
			cap = ncap;
		}
		size_t got = fread(buf + n, 1, cap - 1 - n, f);
		n += got;
		if (n > max_bytes) {
			rc = prsm_error_set(err, PRSM_EINVAL, NULL, "%s is larger than %zu bytes", path, max_bytes);
			goto cleanup;
		}
		if (got == 0) {
			if (ferror(f))
				rc = prsm_error_set(err, PRSM_EIO, NULL, "error reading %s", path);
			break;
		}
	}
cleanup:
	if (f != stdin)
		fclose(f);
	if (rc) {
		free(buf);
		return rc;
	}
	if (buf == NULL && (buf = malloc(1)) == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	buf[n] = '\0';
	*out = buf;
	*len = n;
	return 0;
}
