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

#endif
