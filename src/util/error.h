/*
 * error.h: the error value every layer of prsm passes back to its caller.
 *
 * Functions return 0 on success or a negative PRSM_E* code; when they fail they fill the
 * caller's prsm_error (code, one-line message, JSON pointer of the offending request field when
 * there is one). The struct is plain data so a job can carry it between threads. One table
 * (prsm_error_http_status) maps codes to HTTP statuses and one (prsm_error_exit_code) to the
 * CLI's exit codes.
 */
#ifndef PRSM_UTIL_ERROR_H
#define PRSM_UTIL_ERROR_H

#include <stddef.h>

enum {
	PRSM_OK = 0,
	PRSM_EINVAL = -1,      /* the request or an argument is invalid */
	PRSM_ENOTFOUND = -2,   /* a named thing does not exist */
	PRSM_ECANCELLED = -3,  /* the job was cancelled */
	PRSM_ENOCONVERGE = -4, /* an iterative solve did not converge */
	PRSM_EEDGE = -5,       /* a contact left its flank (edge contact) */
	PRSM_ENOMEM = -6,      /* allocation failed or a bounded buffer is full */
	PRSM_EIO = -7,         /* reading or writing a file failed */
	PRSM_EGEOMETRY = -8    /* the design is physically impossible */
};

#define PRSM_ERROR_MESSAGE_MAX 256
#define PRSM_ERROR_POINTER_MAX 128

typedef struct {
	int code;                               /* PRSM_E* */
	char message[PRSM_ERROR_MESSAGE_MAX];   /* one line, no trailing newline */
	char pointer[PRSM_ERROR_POINTER_MAX];   /* RFC 6901 JSON pointer, "" when none */
} prsm_error;

#define PRSM_ERROR_INIT {0, {0}, {0}}

/* Fill err (if not NULL) and return code. pointer may be NULL. printf-style message. */
int prsm_error_set(prsm_error *err, int code, const char *pointer, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));

/* Reset err to "no error". */
void prsm_error_clear(prsm_error *err);

/* Short symbolic name of a code ("EINVAL"). Never NULL. */
const char *prsm_error_name(int code);

/* HTTP status that answers a request that failed with this code. */
int prsm_error_http_status(int code);

/* CLI exit code (DESIGN.md: 1 invalid request, 2 computation failed). */
int prsm_error_exit_code(int code);

#endif
