/*
 * cancel.h: the cancel flag a job's worker raises and the engine, the optimisers and the
 * allocation poll from other threads. A C11 atomic, so a raise in one thread and a poll in
 * another is not a data race (ThreadSanitizer checks this in the tsan test build); relaxed
 * ordering is enough because nothing is published through the flag: the worker only asks the
 * computation to stop as soon as it can.
 */
#ifndef PRSM_UTIL_CANCEL_H
#define PRSM_UTIL_CANCEL_H

#include <stdatomic.h>

typedef atomic_int prsm_cancel_flag;

/* Nonzero when flag (may be NULL: never cancelled) has been raised. */
static inline int prsm_cancel_requested(const prsm_cancel_flag *flag)
{
	return flag != NULL && atomic_load_explicit(flag, memory_order_relaxed) != 0;
}

/* The values a flag holds: lowered, raised by a cancel of the job, raised because the service is
 * stopping (its job is queued again; an executor that hands work to another system, such as
 * Slurm, may leave that work running and pick it up at the restart). */
enum { PRSM_CANCEL_NONE = 0, PRSM_CANCEL_JOB = 1, PRSM_CANCEL_SHUTDOWN = 2 };

/* The flag's value (PRSM_CANCEL_NONE when flag is NULL). */
static inline int prsm_cancel_reason(const prsm_cancel_flag *flag)
{
	return flag != NULL ? atomic_load_explicit(flag, memory_order_relaxed) : PRSM_CANCEL_NONE;
}

/* Raise (value PRSM_CANCEL_JOB or PRSM_CANCEL_SHUTDOWN) or lower (0) the flag. */
static inline void prsm_cancel_set(prsm_cancel_flag *flag, int value)
{
	atomic_store_explicit(flag, value, memory_order_relaxed);
}

#endif
