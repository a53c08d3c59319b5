/*
 * study.h: one tolerance study run by every process of an MPI job (docs/mpi.md), with the
 * result one process gives, byte for byte.
 *
 * Rank 0 leads: it runs prsm_study_run_with (mc/study.h) with a runner whose plain run and
 * Saltelli replicates are spread over the ranks; the other ranks follow its commands until it
 * says the study is over. Every rank must have loaded the same study (the same document and
 * options).
 *
 *   * The plain run's blocks go out in chunks of k blocks (k: the engine threads per rank) to
 *     whichever rank is free, rank 0 included (on a thread of its own, its main thread handing
 *     out and merging): each rank runs its chunk as a split run (prsm_mc_options.first_block,
 *     block_count) without stop rules and sends the rows back; rank 0 puts them in their
 *     blocks' slots, merges the completed prefix in block order with prsm_mc_prefix_add (the
 *     engine's own stop rules: failure policy, targets, min_samples) and stops after the block
 *     one process stops after: no more chunks go out, the ones running are waited for and
 *     dropped. The time cap and a cancel stop it at the prefix done then, as in one process.
 *   * The Sobol' phase's Saltelli replicates are independent runs: replicate q on rank q mod
 *     size, gathered round by round in q order.
 *   * Rank 0 then summarises; the others return at once.
 *
 * A rank whose chunk or replicate fails (out of memory, PRSM_PAR_FAULT) sends its error instead
 * of rows, and rank 0 ends the study with an error naming the rank; a rank that dies takes the
 * job down with it (mpirun and srun end the others).
 */
#ifndef PRSM_PAR_STUDY_H
#define PRSM_PAR_STUDY_H

#include "mc/study.h"
#include "util/error.h"

/* Rank 0: as prsm_study_run (r filled, or an error in err). The other ranks: their part, then
 * rank 0's return code (r left empty); a rank's own failure to communicate ends the job
 * (prsm_par_abort). Needs prsm_par_init; with one process, rank 0 runs every chunk itself. */
int prsm_par_study_run(prsm_study_result *r, const prsm_study *s, prsm_error *err);

/*
 * Whole studies on demand, for a command whose own work runs on rank 0 (prsm allocate: the Monte
 * Carlo corrections; prsm optimize: the robust constraints' studies; docs/mpi.md).
 *
 * Rank 0 hands prsm_par_study_service() to the application layer (app/allocate.h,
 * app/optimize.h), which calls it for each study with the study document the study was loaded
 * from: the document (bytes) and the study's settings (the prsm_study struct's plain fields, as
 * the caller changed them) go to every rank, every rank loads the same model from the document,
 * and the study runs as prsm_par_study_run runs it: prsm_study_run's result, byte for byte. When
 * its command is done rank 0 calls prsm_par_study_service_finish(code) (also when it never ran a
 * study: a document it refused).
 *
 * The other ranks call prsm_par_study_serve(load, release, ctx): for each study, load builds the
 * study of the document text (the study reader; 0 or a PRSM_E* code with err), the rank takes
 * rank 0's settings into it, runs its part, release frees it; it returns rank 0's code at the
 * finish. A rank that cannot load what rank 0 loaded ends the job (prsm_par_abort).
 */
typedef int (*prsm_par_study_load_fn)(void *ctx, prsm_study **study, void **handle, const char *text, size_t len,
                                      prsm_error *err);
typedef void (*prsm_par_study_release_fn)(void *ctx, void *handle);

const prsm_study_service *prsm_par_study_service(void);
void prsm_par_study_service_finish(int code);
int prsm_par_study_serve(prsm_par_study_load_fn load, prsm_par_study_release_fn release, void *ctx);

#endif
