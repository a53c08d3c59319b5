/*
 * mhd.c: libmicrohttpd loaded on demand (see mhd.h).
 */
#include "http/mhd.h"

#include <dlfcn.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#ifndef PRSM_MHD_SONAME
#define PRSM_MHD_SONAME "libmicrohttpd.so.12"
#endif

prsm_mhd_api prsm_mhd;

static pthread_once_t once = PTHREAD_ONCE_INIT;
static int load_rc;
static char load_message[256];

/* A function of the library into a member of the table (ISO C has no conversion from void *
 * to a function pointer; POSIX guarantees dlsym's result can be used as one: copy the bytes). */
static int resolve(void *lib, void *member, size_t size, const char *name)
{
	void *f = dlsym(lib, name);
	if (f == NULL)
		return -1;
	memcpy(member, &f, size);
	return 0;
}

#define RESOLVE(lib, m) resolve((lib), &prsm_mhd.m, sizeof prsm_mhd.m, "MHD_" #m)

static void load_once(void)
{
	void *lib = dlopen(PRSM_MHD_SONAME, RTLD_NOW | RTLD_LOCAL);
	if (lib == NULL) {
		const char *why = dlerror();
		load_rc = PRSM_EIO;
		snprintf(load_message, sizeof load_message, "cannot load %s, the HTTP library the service needs (%s)",
		         PRSM_MHD_SONAME, why ? why : "unknown reason");
		return;
	}
	/* the library stays loaded for the life of the process */
	const char *missing = NULL;
	if (RESOLVE(lib, start_daemon))
		missing = "MHD_start_daemon";
	else if (RESOLVE(lib, stop_daemon))
		missing = "MHD_stop_daemon";
	else if (RESOLVE(lib, quiesce_daemon))
		missing = "MHD_quiesce_daemon";
	else if (RESOLVE(lib, get_daemon_info))
		missing = "MHD_get_daemon_info";
	else if (RESOLVE(lib, get_version))
		missing = "MHD_get_version";
	else if (RESOLVE(lib, get_connection_values))
		missing = "MHD_get_connection_values";
	else if (RESOLVE(lib, lookup_connection_value))
		missing = "MHD_lookup_connection_value";
	else if (RESOLVE(lib, create_response_from_buffer))
		missing = "MHD_create_response_from_buffer";
	else if (RESOLVE(lib, create_response_from_fd))
		missing = "MHD_create_response_from_fd";
	else if (RESOLVE(lib, add_response_header))
		missing = "MHD_add_response_header";
	else if (RESOLVE(lib, queue_response))
		missing = "MHD_queue_response";
	else if (RESOLVE(lib, destroy_response))
		missing = "MHD_destroy_response";
	if (missing) {
		load_rc = PRSM_EIO;
		snprintf(load_message, sizeof load_message, "%s has no %s (libmicrohttpd too old?)", PRSM_MHD_SONAME,
		         missing);
		memset(&prsm_mhd, 0, sizeof prsm_mhd);
	}
}

int prsm_mhd_load(prsm_error *err)
{
	pthread_once(&once, load_once);
	if (load_rc)
		return prsm_error_set(err, load_rc, NULL, "%s", load_message);
	return 0;
}
