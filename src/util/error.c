/*
 * error.c: filling prsm_error and mapping its codes to HTTP statuses and exit codes.
 */
#include "util/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int prsm_error_set(prsm_error *err, int code, const char *pointer, const char *fmt, ...)
{
	if (err == NULL)
		return code;
	err->code = code;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->message, sizeof err->message, fmt, ap);
	va_end(ap);
	snprintf(err->pointer, sizeof err->pointer, "%s", pointer ? pointer : "");
	return code;
}

void prsm_error_clear(prsm_error *err)
{
	if (err == NULL)
		return;
	memset(err, 0, sizeof *err);
}

const char *prsm_error_name(int code)
{
	switch (code) {
	case PRSM_OK: return "OK";
	case PRSM_EINVAL: return "EINVAL";
	case PRSM_ENOTFOUND: return "ENOTFOUND";
	case PRSM_ECANCELLED: return "ECANCELLED";
	case PRSM_ENOCONVERGE: return "ENOCONVERGE";
	case PRSM_EEDGE: return "EEDGE";
	case PRSM_ENOMEM: return "ENOMEM";
	case PRSM_EIO: return "EIO";
	case PRSM_EGEOMETRY: return "EGEOMETRY";
	default: return "EUNKNOWN";
	}
}

int prsm_error_http_status(int code)
{
	switch (code) {
	case PRSM_OK: return 200;
	case PRSM_EINVAL:
	case PRSM_EGEOMETRY:
	case PRSM_EEDGE: return 422;
	case PRSM_ENOTFOUND: return 404;
	case PRSM_ECANCELLED: return 409;
	case PRSM_ENOMEM: return 503;
	default: return 500;
	}
}

int prsm_error_exit_code(int code)
{
	switch (code) {
	case PRSM_OK: return 0;
	case PRSM_EINVAL:
	case PRSM_EGEOMETRY:
	case PRSM_EEDGE:
	case PRSM_ENOTFOUND: return 1;
	default: return 2;
	}
}
