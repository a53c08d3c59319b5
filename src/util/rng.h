/*
 * rng.h: the counter-based random stream of the Monte Carlo engine (DESIGN.md "Monte Carlo
 * engine").
 *
 * Philox4x64-10 from Random123 (Salmon et al., SC11), wrapped as a gsl_rng_type so every GSL
 * distribution (gsl_ran_*) draws from it. A stream is keyed by (seed, stream): the Philox key is
 * {seed, stream} and the counter is the position in the stream, so block b of a run uses
 * stream b and draws the same numbers whichever thread or process evaluates it. Within a stream
 * the counter {n, 0, 0, 0} gives the n-th 256-bit block, read as eight 32-bit words in the order
 * low(v[0]), high(v[0]), low(v[1]), ..., high(v[3]); a stream is 2^64 blocks long.
 *
 * gsl_rng_get returns those 32-bit words (min 0, max 0xffffffff); gsl_rng_uniform returns
 * k / 2^53 on [0, 1) where k is the top 53 bits of two consecutive words (first word high);
 * gsl_rng_set(r, s) restarts r at stream (s, 0). The generator has no static mutable state:
 * everything lives in the gsl_rng, so one gsl_rng per thread is all the locking needed.
 */
#ifndef PRSM_UTIL_RNG_H
#define PRSM_UTIL_RNG_H

#include <stdint.h>

#include <gsl/gsl_rng.h>

/* The generator type, named "prsm-philox4x64-10", for gsl_rng_alloc and for comparisons with
 * r->type. */
extern const gsl_rng_type *const prsm_rng_philox;

/* A new generator at the beginning of stream (seed, stream). The caller owns it and frees it with
 * gsl_rng_free. Returns NULL when allocation fails. */
gsl_rng *prsm_rng_alloc(uint64_t seed, uint64_t stream);

/* Restart r (which must be of type prsm_rng_philox) at the beginning of stream (seed, stream). */
void prsm_rng_set_stream(gsl_rng *r, uint64_t seed, uint64_t stream);

/* Uniform on the OPEN interval (0, 1): k / 2^53 with k a uniform 53-bit integer in
 * [1, 2^53 - 1] (a zero k is redrawn, probability 2^-53), so never 0 or 1 and symmetric about
 * 1/2. Consumes two 32-bit words (four on a redraw). r must be of type prsm_rng_philox. */
double prsm_rng_uniform_pos(gsl_rng *r);

/* n values of prsm_rng_uniform_pos(r), the same sequence, faster (the Monte Carlo samplers'
 * bulk draw). */
void prsm_rng_fill_uniform_pos(gsl_rng *r, double *u, size_t n);

/* For test_rng only: prsm_rng_fill_uniform_pos's conversion of a chunk's 64 block words w (as
 * prsm_rng_uniform_pos reads them: the top 53 bits k of the word's halves swapped) into k / 2^53
 * (0 for k = 0) by its AVX2 build. Returns how many are 0, or -1 when that build cannot run here
 * (util/simd.h). */
int prsm_rng_uniforms_of_words_for_test(const uint64_t w[64], double u[64]);

/* For test_rng only: the words of the 16 Philox blocks ctr0 .. ctr0 + 15 of stream {key0, key1}
 * (w[4 j + i] = word i of block j) as prsm_rng_fill_uniform_pos's AVX2 build computes them.
 * Returns 0, or -1 when that build cannot run here (util/simd.h). */
int prsm_rng_philox_words_for_test(uint64_t key0, uint64_t key1, uint64_t ctr0, uint64_t w[64]);

#endif
