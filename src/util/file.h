/*
 * file.h: reading a whole request file (or standard input) into memory with a size cap.
 */
#ifndef PRSM_UTIL_FILE_H
#define PRSM_UTIL_FILE_H

#include <stddef.h>

#include "util/error.h"

/* Read path ("-" = stdin) into a NUL-terminated buffer the caller frees with free().
 * More than max_bytes is an error (PRSM_EINVAL), as is an unreadable file (PRSM_EIO). */
int prsm_file_read(char **out, size_t *len, const char *path, size_t max_bytes, prsm_error *err);

#endif
