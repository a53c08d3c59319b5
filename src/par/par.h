/*
 * par.h: prsm over many processes (MPI), at the engine's edge (issue 20; docs/mpi.md).
 *
 * One `prsm` binary runs alone or under mpirun/srun. It does not link the MPI library: a
 * process that a launcher started (or that was given --mpi) loads it with dlopen() when the
 * command starts (the SONAME the build found, PRSM_MPI_SONAME), through a table of the few
 * functions used, so that every other process starts as fast as before. Nothing of MPI shows
 * through this interface: ranks, byte buffers and error codes only. mc/, model/ and opt/ never
 * include it; src/par/study.c and the command line (cli/study.c, cli/batch.c) do.
 *
 * Every wait (a broadcast, a gather, a receive) polls its request and sleeps between polls
 * (50 us growing to 2 ms), so a rank that waits for another leaves its core to the computing
 * ones (Open MPI's blocking calls spin) and oversubscribed runs stay usable.
 *
 * The calls are made from one thread of each process (MPI_THREAD_FUNNELED): other threads
 * (the engine's workers, the batch's job workers) never call them.
 */
#ifndef PRSM_PAR_PAR_H
#define PRSM_PAR_PAR_H

#include <signal.h>
#include <stddef.h>

#include "util/error.h"

/* 1 when this prsm was built with MPI (the CMake feature PRSM_MPI found it); the library it
 * loads (its SONAME, "" when built without). */
int prsm_par_built(void);
const char *prsm_par_library(void);

/* 1 when the environment says an MPI launcher started this process: Open MPI's mpirun
 * (OMPI_COMM_WORLD_SIZE), a PMIx launcher (PMIX_RANK), a PMI-1/2 launcher such as MPICH's
 * hydra (PMI_RANK and PMI_SIZE), or Slurm's srun (SLURM_PROCID and SLURM_NTASKS in a job step,
 * SLURM_STEP_ID). *rank and *size (either may be NULL) get what the launcher says, 0 and 1 when
 * it says nothing; reading them needs no MPI. */
int prsm_par_launched(int *rank, int *size);

/* Load the MPI library and initialise it (MPI_Init_thread, funneled). Returns 0 or PRSM_EIO
 * with err saying why (built without MPI, the library not found, MPI_Init failed). */
int prsm_par_init(prsm_error *err);

/* 1 between prsm_par_init and prsm_par_finalize. */
int prsm_par_active(void);
/* This process's rank and the number of processes (0 and 1 when not active). */
int prsm_par_rank(void);
int prsm_par_size(void);

/* MPI_Finalize (when active). */
void prsm_par_finalize(void);

/* Collective: rank 0's len bytes at buf into every rank's buf. 0 or PRSM_EIO. */
int prsm_par_bcast(void *buf, size_t len, prsm_error *err);

/* Collective: rank 0's *buf (*len bytes) to every rank; on the others *buf becomes a malloc'd
 * copy (the caller frees it; NUL-terminated after *len bytes). 0, PRSM_ENOMEM or PRSM_EIO. */
int prsm_par_bcast_blob(char **buf, size_t *len, prsm_error *err);

/* A byte buffer of one rank. */
typedef struct {
	char *data;
	size_t len;
} prsm_par_blob;

/* Collective: every rank's len bytes at mine to rank 0, which gets them in rank order in
 * all[0 .. size-1] (all[0] is a copy of its own; each malloc'd, free with prsm_par_blobs_free);
 * all is ignored on the other ranks. Sizes may differ from rank to rank. 0, PRSM_ENOMEM or
 * PRSM_EIO. */
int prsm_par_gather(const void *mine, size_t len, prsm_par_blob *all, prsm_error *err);
void prsm_par_blobs_free(prsm_par_blob *all, int n);

/* Point to point: len bytes to rank `to` with a tag (0..30000; the gather uses 30001). Returns when the buffer may be
 * reused. 0 or PRSM_EIO. */
int prsm_par_send(int to, int tag, const void *buf, size_t len, prsm_error *err);

/* Receive the next message from any rank (from < 0) or from `from`, with any tag (want_tag < 0)
 * or that one: *src, *tag and *buf (malloc'd, NUL-terminated after *len bytes: the caller frees
 * it). Waits until one comes; stop (may be NULL) nonzero gives up: PRSM_ECANCELLED. 0 or
 * PRSM_EIO (out of memory for the message ends the run, prsm_par_abort). */
int prsm_par_recv(int from, int want_tag, int *src, int *tag, char **buf, size_t *len,
                  const volatile sig_atomic_t *stop, prsm_error *err);

/* 1 when a message waits (from any rank), without receiving it. */
int prsm_par_probe(void);

/* End the whole run: "prsm: rank R of N: MESSAGE" on stderr, then MPI_Abort with code (every
 * rank ends; mpirun or srun reports it). Without MPI active: the message and exit(code). */
_Noreturn void prsm_par_abort(int code, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The test hook of docs/mpi.md: PRSM_PAR_FAULT=fail:R (rank R reports a failure where it
 * computes) or exit:R (rank R exits at once, without a word to the others). Returns 1 (fail)
 * when this rank should report a failure now; exits for exit:R. */
int prsm_par_fault(void);

#endif
