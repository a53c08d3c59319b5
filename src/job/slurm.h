/*
 * slurm.h: the service's Slurm executor (issue 20; docs/mpi.md "The service on a cluster"):
 * `prsm serve --executor slurm` hands every job above a size to a Slurm cluster instead of
 * running it in its worker thread.
 *
 * A job goes to Slurm when its request's Monte Carlo samples (prsm_slurm_job_samples) reach
 * min_samples. The worker that claimed it then
 *
 *   1. writes SPOOL/<job id>/request.json (the stored canonical request) and job.sh, which runs
 *      `prsm run-job KIND request.json --out result.json --csv samples.csv --error error.json
 *      --counts counts.txt` with the service's per-job limits (threads, time cap, sample cap)
 *      and writes its exit status to exit_code: the kind's own run, so the result is the one the
 *      worker would have computed;
 *   2. submits it: `sbatch --parsable --job-name=prsm-<id> --chdir=SPOOL/<id>
 *      --output=SPOOL/<id>/slurm.out [sbatch_args...] SPOOL/<id>/job.sh` (the Slurm job id from
 *      its output);
 *   3. polls every poll_s: `squeue -h -j ID -o %T` while the job is queued or running (a cancel
 *      of the prsm job runs `scancel ID`; the service stopping leaves the Slurm job to run: the
 *      prsm job is queued again, and its next run finds SPOOL/<id>/ with the same request.json,
 *      job.sh and a jobid that Slurm still lists or that wrote its exit_code, and picks that
 *      Slurm job up instead of submitting it again); once squeue no longer lists
 *      it, `sacct -n -P -X -j ID -o State` for its final state (where accounting is set up) and
 *      the exit_code file;
 *   4. reads the result, the CSV and the counts back (exit code 0), or the kind's error from
 *      error.json (the same failure document as a local run), or reports the Slurm state and
 *      where the job's log is; the service stores it in its SQLite cache as any job.
 *
 * SPOOL and the prsm binary must be reachable at the same paths on the compute nodes (a shared
 * filesystem). The commands are found on PATH (tests put stand-ins there). No shell runs them:
 * they are started with posix_spawnp and their output read from a pipe.
 */
#ifndef PRSM_JOB_SLURM_H
#define PRSM_JOB_SLURM_H

#include <stddef.h>

#include "job/jobs.h"

#define PRSM_SLURM_MAX_ARGS 16
#define PRSM_SLURM_PATH_MAX 1024

typedef struct {
	char spool[PRSM_SLURM_PATH_MAX];        /* absolute directory of the jobs' files */
	char prsm[PRSM_SLURM_PATH_MAX];         /* absolute path of the prsm the jobs run */
	size_t min_samples;                     /* jobs with at least this many samples go to Slurm */
	double poll_s;                          /* seconds between squeue calls, > 0 */
	int n_sbatch_args;
	char *sbatch_args[PRSM_SLURM_MAX_ARGS]; /* extra sbatch arguments, e.g. --partition=long */
	prsm_job_executor executor;             /* filled by prsm_slurm_init; hand &executor to
	                                           prsm_jobs_options.executor */
} prsm_slurm;

/* Check the settings and fill s->executor. spool is created when missing and made absolute;
 * prsm NULL: this binary (/proc/self/exe). Returns 0, or PRSM_EINVAL / PRSM_EIO with err. */
int prsm_slurm_init(prsm_slurm *s, const char *spool, const char *prsm, size_t min_samples, double poll_s,
                    prsm_error *err);

/* The Monte Carlo samples of a request of kind `kind` (its JSON text): a study's
 * monte_carlo.samples; an allocation's (its own monte_carlo.samples, else its study's) times
 * 1 + monte_carlo.max_corrections; an optimisation's robust.monte_carlo.samples times
 * solver.max_evaluations; 0 for the other kinds and for what a request leaves out. */
double prsm_slurm_job_samples(const char *kind, const char *request);

#endif
