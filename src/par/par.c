/*
 * par.c: MPI loaded on demand (see par.h).
 *
 * With PRSM_HAVE_MPI the build found an MPI (its headers and PRSM_MPI_SONAME, the library's
 * SONAME): the table below has the functions used, with their own prototypes (__typeof__ of
 * mpi.h's declarations), filled by dlsym from the library dlopen()ed with RTLD_NOW |
 * RTLD_GLOBAL (Open MPI's components, themselves dlopen()ed by MPI_Init, resolve the library's
 * symbols through the global scope). Open MPI's predefined handles (MPI_COMM_WORLD, MPI_BYTE)
 * are addresses of library objects (ompi_mpi_comm_world, ...): they are looked up too. Without
 * PRSM_HAVE_MPI every call says that prsm was built without MPI.
 */
#include "par/par.h"

#include <errno.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifdef PRSM_HAVE_MPI
#include <dlfcn.h>
#include <limits.h>
#include <mpi.h>
#endif

#ifndef PRSM_MPI_SONAME
#define PRSM_MPI_SONAME ""
#endif

static int par_active;
static int par_rank, par_size = 1;

int prsm_par_built(void)
{
#ifdef PRSM_HAVE_MPI
	return 1;
#else
	return 0;
#endif
}

const char *prsm_par_library(void)
{
	return PRSM_MPI_SONAME;
}

/* A whole non-negative decimal number in the variable, else -1. */
static long env_int(const char *name)
{
	const char *v = getenv(name);
	if (!v || !*v)
		return -1;
	char *end = NULL;
	errno = 0;
	long n = strtol(v, &end, 10);
	return (*end || errno || n < 0 || n > 1000000000L) ? -1 : n;
}

int prsm_par_launched(int *rank, int *size)
{
	long r = -1, n = -1;
	int launched = 0;
	if (env_int("OMPI_COMM_WORLD_SIZE") >= 1) {
		launched = 1;
		n = env_int("OMPI_COMM_WORLD_SIZE");
		r = env_int("OMPI_COMM_WORLD_RANK");
	} else if (env_int("PMIX_RANK") >= 0) {
		launched = 1;
		r = env_int("PMIX_RANK");
		n = env_int("PMIX_SIZE"); /* not every PMIx launcher sets it */
		if (n < 1)
			n = env_int("SLURM_NTASKS");
	} else if (env_int("PMI_RANK") >= 0 && env_int("PMI_SIZE") >= 1) {
		launched = 1;
		r = env_int("PMI_RANK");
		n = env_int("PMI_SIZE");
	} else if (env_int("SLURM_PROCID") >= 0 && env_int("SLURM_NTASKS") >= 1 && getenv("SLURM_STEP_ID")) {
		/* srun's tasks (a batch script itself has no step id of its own tasks) */
		launched = 1;
		r = env_int("SLURM_PROCID");
		n = env_int("SLURM_NTASKS");
	}
	if (rank)
		*rank = launched && r >= 0 ? (int)r : 0;
	if (size)
		*size = launched && n >= 1 ? (int)n : 1;
	return launched;
}

int prsm_par_active(void)
{
	return par_active;
}

int prsm_par_rank(void)
{
	return par_active ? par_rank : 0;
}

int prsm_par_size(void)
{
	return par_active ? par_size : 1;
}

_Noreturn static void exit_at_once(int code);

int prsm_par_fault(void)
{
	const char *f = getenv("PRSM_PAR_FAULT");
	if (!f || !par_active)
		return 0;
	const char *colon = strchr(f, ':');
	if (!colon)
		return 0;
	char *end = NULL;
	long r = strtol(colon + 1, &end, 10);
	if (*end || r != par_rank)
		return 0;
	if (strncmp(f, "exit:", 5) == 0) {
		fprintf(stderr, "prsm: rank %d of %d: exiting at once (PRSM_PAR_FAULT=%s)\n", par_rank, par_size, f);
		fflush(stderr);
		exit_at_once(3);
	}
	return strncmp(f, "fail:", 5) == 0;
}

#ifdef PRSM_HAVE_MPI

typedef struct {
	__typeof__(MPI_Initialized) *Initialized;
	__typeof__(MPI_Init_thread) *Init_thread;
	__typeof__(MPI_Finalized) *Finalized;
	__typeof__(MPI_Finalize) *Finalize;
	__typeof__(MPI_Comm_rank) *Comm_rank;
	__typeof__(MPI_Comm_size) *Comm_size;
	__typeof__(MPI_Abort) *Abort;
	__typeof__(MPI_Ibcast) *Ibcast;
	__typeof__(MPI_Isend) *Isend;
	__typeof__(MPI_Irecv) *Irecv;
	__typeof__(MPI_Test) *Test;
	__typeof__(MPI_Iprobe) *Iprobe;
} mpi_api;

static mpi_api mpi;
static MPI_Comm comm_world;
static MPI_Datatype byte_type;
static void *mpi_lib;

/* dlsym's result into a member of the table (as src/http/mhd.c: copy the pointer's bytes). */
static int resolve(void *lib, void *member, size_t size, const char *name)
{
	void *f = dlsym(lib, name);
	if (f == NULL)
		return -1;
	memcpy(member, &f, size);
	return 0;
}

#define RESOLVE(lib, m) (resolve((lib), &mpi.m, sizeof mpi.m, "MPI_" #m) ? "MPI_" #m : NULL)

static int load(prsm_error *err)
{
	void *lib = dlopen(PRSM_MPI_SONAME, RTLD_NOW | RTLD_GLOBAL);
	if (lib == NULL) {
		const char *why = dlerror();
		return prsm_error_set(err, PRSM_EIO, NULL, "cannot load %s, the MPI library (%s): install Open MPI "
		                      "(libopenmpi-dev, openmpi-bin) or run without mpirun and --mpi",
		                      PRSM_MPI_SONAME, why ? why : "unknown reason");
	}
	/* the library stays loaded for the life of the process */
	mpi_lib = lib;
	const char *missing = NULL;
	if (!missing) missing = RESOLVE(lib, Initialized);
	if (!missing) missing = RESOLVE(lib, Init_thread);
	if (!missing) missing = RESOLVE(lib, Finalized);
	if (!missing) missing = RESOLVE(lib, Finalize);
	if (!missing) missing = RESOLVE(lib, Comm_rank);
	if (!missing) missing = RESOLVE(lib, Comm_size);
	if (!missing) missing = RESOLVE(lib, Abort);
	if (!missing) missing = RESOLVE(lib, Ibcast);
	if (!missing) missing = RESOLVE(lib, Isend);
	if (!missing) missing = RESOLVE(lib, Irecv);
	if (!missing) missing = RESOLVE(lib, Test);
	if (!missing) missing = RESOLVE(lib, Iprobe);
#ifdef OPEN_MPI
	/* MPI_COMM_WORLD and MPI_BYTE are the addresses of these objects */
	void *cw = dlsym(lib, "ompi_mpi_comm_world"), *bt = dlsym(lib, "ompi_mpi_byte");
	if (!missing && !cw)
		missing = "ompi_mpi_comm_world";
	if (!missing && !bt)
		missing = "ompi_mpi_byte";
	comm_world = (MPI_Comm)cw;
	byte_type = (MPI_Datatype)bt;
#else
	/* MPICH and its kin: the handles are integer constants */
	comm_world = MPI_COMM_WORLD;
	byte_type = MPI_BYTE;
#endif
	if (missing) {
		memset(&mpi, 0, sizeof mpi);
		return prsm_error_set(err, PRSM_EIO, NULL, "%s has no %s (another MPI than the one prsm was built with?)",
		                      PRSM_MPI_SONAME, missing);
	}
	return 0;
}

int prsm_par_init(prsm_error *err)
{
	if (par_active)
		return 0;
	int rc = load(err);
	if (rc)
		return rc;
	int initialized = 0, provided = 0;
	mpi.Initialized(&initialized);
	if (!initialized && mpi.Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
		return prsm_error_set(err, PRSM_EIO, NULL, "MPI_Init_thread failed");
	if (mpi.Comm_rank(comm_world, &par_rank) != MPI_SUCCESS || mpi.Comm_size(comm_world, &par_size) != MPI_SUCCESS)
		return prsm_error_set(err, PRSM_EIO, NULL, "MPI_Comm_rank or MPI_Comm_size failed");
	par_active = 1;
	return 0;
}

void prsm_par_finalize(void)
{
	if (!par_active)
		return;
	int finalized = 0;
	mpi.Finalized(&finalized);
	if (!finalized)
		mpi.Finalize();
	par_active = 0;
}

/* Wait for a request, polling: 50 us between tests at first, growing to 2 ms. stop (may be
 * NULL) nonzero gives up (the request stays posted: the caller is ending). */
static int wait_request(MPI_Request *req, const volatile sig_atomic_t *stop)
{
	long ns = 50000;
	for (;;) {
		int done = 0;
		if (mpi.Test(req, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS)
			return PRSM_EIO;
		if (done)
			return 0;
		if (stop && *stop)
			return PRSM_ECANCELLED;
		struct timespec ts = {0, ns};
		nanosleep(&ts, NULL);
		if (ns < 2000000)
			ns *= 2;
	}
}

/* MPI counts are ints: messages go in chunks of at most this many bytes. */
#define CHUNK ((size_t)1 << 30)

static int bcast_bytes(void *buf, size_t len, prsm_error *err)
{
	for (size_t off = 0; off < len;) {
		size_t n = len - off < CHUNK ? len - off : CHUNK;
		MPI_Request req;
		if (mpi.Ibcast((char *)buf + off, (int)n, byte_type, 0, comm_world, &req) != MPI_SUCCESS ||
		    wait_request(&req, NULL))
			return prsm_error_set(err, PRSM_EIO, NULL, "MPI broadcast failed");
		off += n;
	}
	return 0;
}

int prsm_par_bcast(void *buf, size_t len, prsm_error *err)
{
	if (!par_active || par_size == 1)
		return 0;
	return bcast_bytes(buf, len, err);
}

int prsm_par_bcast_blob(char **buf, size_t *len, prsm_error *err)
{
	if (!par_active || par_size == 1)
		return 0;
	uint64_t n = par_rank == 0 ? (uint64_t)*len : 0;
	int rc = bcast_bytes(&n, sizeof n, err);
	if (rc)
		return rc;
	if (par_rank != 0) {
		*buf = malloc((size_t)n + 1);
		*len = (size_t)n;
		if (!*buf)
			prsm_par_abort(2, "out of memory for a broadcast of %zu bytes", (size_t)n);
		(*buf)[n] = '\0';
	}
	return n ? bcast_bytes(*buf, (size_t)n, err) : 0;
}

/* One message: its length (8 bytes), then the bytes in chunks, all with the tag. */
int prsm_par_send(int to, int tag, const void *buf, size_t len, prsm_error *err)
{
	if (!par_active)
		return prsm_error_set(err, PRSM_EIO, NULL, "MPI is not active");
	uint64_t n = len;
	MPI_Request req;
	if (mpi.Isend(&n, (int)sizeof n, byte_type, to, tag, comm_world, &req) != MPI_SUCCESS || wait_request(&req, NULL))
		return prsm_error_set(err, PRSM_EIO, NULL, "MPI send to rank %d failed", to);
	for (size_t off = 0; off < len;) {
		size_t c = len - off < CHUNK ? len - off : CHUNK;
		if (mpi.Isend((const char *)buf + off, (int)c, byte_type, to, tag, comm_world, &req) != MPI_SUCCESS ||
		    wait_request(&req, NULL))
			return prsm_error_set(err, PRSM_EIO, NULL, "MPI send to rank %d failed", to);
		off += c;
	}
	return 0;
}

int prsm_par_probe(void)
{
	int flag = 0;
	if (!par_active)
		return 0;
	if (mpi.Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm_world, &flag, MPI_STATUS_IGNORE) != MPI_SUCCESS)
		return 0;
	return flag;
}

int prsm_par_recv(int from, int want_tag, int *src, int *tag, char **buf, size_t *len,
                  const volatile sig_atomic_t *stop, prsm_error *err)
{
	*buf = NULL;
	*len = 0;
	if (!par_active)
		return prsm_error_set(err, PRSM_EIO, NULL, "MPI is not active");
	/* the header of the next message (from anyone, or from `from`) */
	uint64_t n = 0;
	MPI_Status st;
	long ns = 50000;
	for (;;) {
		int flag = 0;
		if (mpi.Iprobe(from < 0 ? MPI_ANY_SOURCE : from, want_tag < 0 ? MPI_ANY_TAG : want_tag, comm_world, &flag,
		               &st) != MPI_SUCCESS)
			return prsm_error_set(err, PRSM_EIO, NULL, "MPI probe failed");
		if (flag)
			break;
		if (stop && *stop)
			return PRSM_ECANCELLED;
		struct timespec ts = {0, ns};
		nanosleep(&ts, NULL);
		if (ns < 2000000)
			ns *= 2;
	}
	const int s = st.MPI_SOURCE, t = st.MPI_TAG;
	MPI_Request req;
	if (mpi.Irecv(&n, (int)sizeof n, byte_type, s, t, comm_world, &req) != MPI_SUCCESS || wait_request(&req, NULL))
		return prsm_error_set(err, PRSM_EIO, NULL, "MPI receive from rank %d failed", s);
	char *b = malloc((size_t)n + 1);
	if (!b)
		prsm_par_abort(2, "out of memory for a message of %zu bytes from rank %d", (size_t)n, s);
	for (size_t off = 0; off < n;) {
		size_t c = n - off < CHUNK ? (size_t)n - off : CHUNK;
		if (mpi.Irecv(b + off, (int)c, byte_type, s, t, comm_world, &req) != MPI_SUCCESS || wait_request(&req, NULL)) {
			free(b);
			return prsm_error_set(err, PRSM_EIO, NULL, "MPI receive from rank %d failed", s);
		}
		off += c;
	}
	b[n] = '\0';
	*buf = b;
	*len = (size_t)n;
	*src = s;
	*tag = t;
	return 0;
}

/* The gather's own tag, apart from what the batch's messages use. */
#define GATHER_TAG 30001

int prsm_par_gather(const void *mine, size_t len, prsm_par_blob *all, prsm_error *err)
{
	if (!par_active || par_rank == 0) {
		/* rank 0 (or no MPI): its own copy, then the others' in rank order */
		const int n = par_active ? par_size : 1;
		memset(all, 0, (size_t)n * sizeof *all);
		all[0].data = malloc(len + 1);
		if (!all[0].data)
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		if (len)
			memcpy(all[0].data, mine, len);
		all[0].data[len] = '\0';
		all[0].len = len;
		for (int r = 1; r < n; r++) {
			int src, tag;
			int rc = prsm_par_recv(r, GATHER_TAG, &src, &tag, &all[r].data, &all[r].len, NULL, err);
			if (rc) {
				prsm_par_blobs_free(all, n);
				return rc;
			}
		}
		return 0;
	}
	return prsm_par_send(0, GATHER_TAG, mine, len, err);
}

_Noreturn void prsm_par_abort(int code, const char *fmt, ...)
{
	char msg[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	if (par_active)
		fprintf(stderr, "prsm: rank %d of %d: %s\n", par_rank, par_size, msg);
	else
		fprintf(stderr, "prsm: %s\n", msg);
	fflush(stderr);
	if (par_active)
		mpi.Abort(comm_world, code);
	exit_at_once(code);
}

/* _exit(code), looked up in the MPI library's scope (its libc) rather than called: neither exit
 * nor _exit is otherwise imported, and every imported symbol is one more lookup at every prsm
 * process's start (BIND_NOW); this is reached only in a process that loaded MPI. */
_Noreturn static void exit_at_once(int code)
{
	void (*ex)(int) = NULL;
	void *f = mpi_lib ? dlsym(mpi_lib, "_exit") : NULL;
	if (f)
		memcpy(&ex, &f, sizeof ex);
	if (ex)
		ex(code);
	abort();
}

#else /* built without MPI */

_Noreturn static void exit_at_once(int code)
{
	(void)code;
	abort(); /* never reached: nothing is active without MPI */
}

static int without(prsm_error *err)
{
	return prsm_error_set(err, PRSM_EIO, NULL, "this prsm was built without MPI (the CMake feature PRSM_MPI found "
	                      "no MPI: install libopenmpi-dev and openmpi-bin, then rebuild)");
}

int prsm_par_init(prsm_error *err)
{
	return without(err);
}

void prsm_par_finalize(void)
{
}

int prsm_par_bcast(void *buf, size_t len, prsm_error *err)
{
	(void)buf;
	(void)len;
	(void)err;
	return 0;
}

int prsm_par_bcast_blob(char **buf, size_t *len, prsm_error *err)
{
	(void)buf;
	(void)len;
	(void)err;
	return 0;
}

int prsm_par_gather(const void *mine, size_t len, prsm_par_blob *all, prsm_error *err)
{
	all[0].data = malloc(len + 1);
	if (!all[0].data)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	if (len)
		memcpy(all[0].data, mine, len);
	all[0].data[len] = '\0';
	all[0].len = len;
	return 0;
}

int prsm_par_send(int to, int tag, const void *buf, size_t len, prsm_error *err)
{
	(void)to;
	(void)tag;
	(void)buf;
	(void)len;
	return without(err);
}

int prsm_par_recv(int from, int want_tag, int *src, int *tag, char **buf, size_t *len,
                  const volatile sig_atomic_t *stop, prsm_error *err)
{
	(void)from;
	(void)want_tag;
	(void)src;
	(void)tag;
	(void)stop;
	*buf = NULL;
	*len = 0;
	return without(err);
}

int prsm_par_probe(void)
{
	return 0;
}

_Noreturn void prsm_par_abort(int code, const char *fmt, ...)
{
	char msg[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	fprintf(stderr, "prsm: %s\n", msg);
	exit_at_once(code);
}

#endif

void prsm_par_blobs_free(prsm_par_blob *all, int n)
{
	if (!all)
		return;
	for (int i = 0; i < n; i++) {
		free(all[i].data);
		all[i].data = NULL;
		all[i].len = 0;
	}
}
