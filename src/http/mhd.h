/*
 * mhd.h: libmicrohttpd, loaded when the service starts rather than when any command starts.
 *
 * libmicrohttpd brings GnuTLS and its seven libraries (p11-kit, libtasn1, libidn2, ...), whose
 * loading, relocation and constructors cost about 5 ms of every process's start-up on the
 * development machine: as much as a whole Sobol' study of Ishigami. Only `prsm serve` (and the
 * service's tests) need it, so the server reaches it through this table, filled by dlopen() of
 * the library the build found (its SONAME, PRSM_MHD_SONAME) the first time a server starts.
 * The members have the library's own prototypes (__typeof__ of its declarations), so a call
 * through the table is checked exactly as a direct call is.
 */
#ifndef PRSM_HTTP_MHD_H
#define PRSM_HTTP_MHD_H

#include <microhttpd.h>

#include "util/error.h"

typedef struct {
	__typeof__(MHD_start_daemon) *start_daemon;
	__typeof__(MHD_stop_daemon) *stop_daemon;
	__typeof__(MHD_quiesce_daemon) *quiesce_daemon;
	__typeof__(MHD_get_daemon_info) *get_daemon_info;
	__typeof__(MHD_get_version) *get_version;
	__typeof__(MHD_get_connection_values) *get_connection_values;
	__typeof__(MHD_lookup_connection_value) *lookup_connection_value;
	__typeof__(MHD_create_response_from_buffer) *create_response_from_buffer;
	__typeof__(MHD_create_response_from_fd) *create_response_from_fd;
	__typeof__(MHD_add_response_header) *add_response_header;
	__typeof__(MHD_queue_response) *queue_response;
	__typeof__(MHD_destroy_response) *destroy_response;
} prsm_mhd_api;

/* The loaded functions; valid once prsm_mhd_load() has returned 0. */
extern prsm_mhd_api prsm_mhd;

/* Load the library and every function of the table (once; later calls return at once;
 * thread-safe). Returns 0, or PRSM_EIO with err naming the library and dlerror()'s reason. */
int prsm_mhd_load(prsm_error *err);

#endif
