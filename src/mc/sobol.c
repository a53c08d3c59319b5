/*
 * sobol.c: the Sobol' sequence with Joe-Kuo direction numbers, Gray-code order, direct
 * skip-ahead and a linear matrix scramble with a digital shift (see sobol.h).
 */
#include "mc/sobol.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"
#include "util/rng.h"

#define SHIFT_LOW_BITS 20                       /* 32 + 20 = 52 bits of a coordinate */

/* The 32 direction numbers of dimension j (0-based) from the table: V_i = m_i 2^(32-i) for
 * i <= s, then Bratley-Fox's recurrence V_i = a_1 V_(i-1) ^ ... ^ a_(s-1) V_(i-s+1) ^ V_(i-s)
 * ^ (V_(i-s) >> s), a_k the coefficient of x^(s-k). Dimension 1: V_i = 2^(32-i). */
static void direction_numbers(uint32_t *V, size_t j, size_t m_offset)
{
	unsigned s = prsm_sobol_table_degree[j];
	if (s == 0) {
		for (unsigned i = 0; i < PRSM_SOBOL_BITS; i++)
			V[i] = UINT32_C(1) << (PRSM_SOBOL_BITS - 1 - i);
		return;
	}
	uint32_t a = prsm_sobol_table_a[j];
	const uint32_t *m = prsm_sobol_table_m + m_offset;
	for (unsigned i = 0; i < s && i < PRSM_SOBOL_BITS; i++)
		V[i] = m[i] << (PRSM_SOBOL_BITS - 1 - i);
	for (unsigned i = s; i < PRSM_SOBOL_BITS; i++) {
		uint32_t v = V[i - s] ^ (V[i - s] >> s);
		for (unsigned k = 1; k < s; k++)
			if ((a >> (s - 1 - k)) & 1u)
				v ^= V[i - k];
		V[i] = v;
	}
}

/* Linear matrix scramble of one dimension's direction numbers: digit r (r = 0 the most
 * significant, bit 31) of each becomes the parity of row r of a random lower-triangular matrix
 * with unit diagonal times its digits, i.e. digit r plus random ones of the digits above it. */
static void scramble_lms(uint32_t *V, gsl_rng *rng)
{
	uint32_t row[PRSM_SOBOL_BITS];
	for (unsigned r = 0; r < PRSM_SOBOL_BITS; r++) {
		uint32_t diag = UINT32_C(1) << (PRSM_SOBOL_BITS - 1 - r);
		uint32_t above = (uint32_t) ~(diag | (diag - 1u));  /* the r more significant bits */
		row[r] = ((uint32_t)gsl_rng_get(rng) & above) | diag;
	}
	/* digit r of the scrambled V[i] is parity(row[r] & V[i]), the sum over GF(2) of column b of
	 * the matrix for each set bit b of V[i]: col[b] holds column b (bit 31 - r = bit b of row[r]) */
	uint32_t col[PRSM_SOBOL_BITS] = {0};
	for (unsigned r = 0; r < PRSM_SOBOL_BITS; r++)
		for (uint32_t bits = row[r]; bits; bits &= bits - 1u)
			col[__builtin_ctz(bits)] |= UINT32_C(1) << (PRSM_SOBOL_BITS - 1 - r);
	for (unsigned i = 0; i < PRSM_SOBOL_BITS; i++) {
		uint32_t y = 0;
		for (uint32_t bits = V[i]; bits; bits &= bits - 1u)
			y ^= col[__builtin_ctz(bits)];
		V[i] = y;
	}
}

void prsm_sobol_seq_free(prsm_sobol_seq *s)
{
	free(s->v);
	free(s->shift);
	free(s->x);
	memset(s, 0, sizeof *s);
}

int prsm_sobol_seq_init(prsm_sobol_seq *s, size_t dim, int scramble, uint64_t seed, uint64_t stream)
{
	memset(s, 0, sizeof *s);
	if (dim == 0 || dim > PRSM_SOBOL_MAX_DIM)
		return PRSM_EINVAL;
	s->dim = dim;
	s->v = malloc(PRSM_SOBOL_BITS * dim * sizeof *s->v);
	s->shift = calloc(dim, sizeof *s->shift);
	s->x = calloc(dim, sizeof *s->x);
	gsl_rng *rng = scramble ? prsm_rng_alloc(seed, stream) : NULL;
	if (!s->v || !s->shift || !s->x || (scramble && !rng)) {
		if (rng)
			gsl_rng_free(rng);
		prsm_sobol_seq_free(s);
		return PRSM_ENOMEM;
	}
	size_t m_offset = 0;
	for (size_t j = 0; j < dim; j++) {
		uint32_t V[PRSM_SOBOL_BITS];
		assert(m_offset + prsm_sobol_table_degree[j] <= prsm_sobol_table_m_count);
		direction_numbers(V, j, m_offset);
		m_offset += prsm_sobol_table_degree[j];
		if (rng) {
			scramble_lms(V, rng);
			uint64_t hi = (uint32_t)gsl_rng_get(rng);
			uint64_t lo = (uint32_t)gsl_rng_get(rng) >> (32 - SHIFT_LOW_BITS);
			s->shift[j] = hi << SHIFT_LOW_BITS | lo;
		}
		for (unsigned k = 0; k < PRSM_SOBOL_BITS; k++)
			s->v[k * dim + j] = V[k];
	}
	if (rng)
		gsl_rng_free(rng);
	s->next = 0;
	return 0;
}

void prsm_sobol_seq_seek(prsm_sobol_seq *s, uint64_t n)
{
	assert(n < PRSM_SOBOL_MAX_POINTS);
	size_t dim = s->dim;
	uint64_t g = n ^ (n >> 1);
	memset(s->x, 0, dim * sizeof *s->x);
	for (unsigned k = 0; g; k++, g >>= 1)
		if (g & 1u) {
			const uint32_t *vk = s->v + k * dim;
			for (size_t j = 0; j < dim; j++)
				s->x[j] ^= vk[j];
		}
	s->next = n;
}

/* Step from point n = s->next to n + 1: gray(n + 1) = gray(n) ^ 2^ctz(n + 1). */
static void advance(prsm_sobol_seq *s)
{
	uint64_t n1 = ++s->next;
	if (n1 >= PRSM_SOBOL_MAX_POINTS)
		return;                                 /* the end: a seek is needed */
	const uint32_t *vk = s->v + (size_t)__builtin_ctzll(n1) * s->dim;
	for (size_t j = 0; j < s->dim; j++)
		s->x[j] ^= vk[j];
}

void prsm_sobol_seq_next_u32(prsm_sobol_seq *s, uint32_t *x)
{
	assert(s->next < PRSM_SOBOL_MAX_POINTS);
	for (size_t j = 0; j < s->dim; j++)
		x[j] = s->x[j] ^ (uint32_t)(s->shift[j] >> SHIFT_LOW_BITS);
	advance(s);
}

static void point_double(const prsm_sobol_seq *s, double *u)
{
	for (size_t j = 0; j < s->dim; j++) {
		uint64_t k = ((uint64_t)s->x[j] << SHIFT_LOW_BITS) ^ s->shift[j];
		u[j] = ((double)(int64_t)k + 0.5) * 0x1p-52; /* exact: k < 2^52 (the signed conversion is
		                                                 the cheaper, and the same double) */
	}
}

void prsm_sobol_seq_next(prsm_sobol_seq *s, double *u)
{
	assert(s->next < PRSM_SOBOL_MAX_POINTS);
	point_double(s, u);
	advance(s);
}

void prsm_sobol_seq_block(prsm_sobol_seq *s, double *u, size_t n, uint64_t first)
{
	assert(first <= PRSM_SOBOL_MAX_POINTS && n <= PRSM_SOBOL_MAX_POINTS - first);
	if (n == 0)
		return;
	if (s->next != first)
		prsm_sobol_seq_seek(s, first);
	for (size_t i = 0; i < n; i++) {
		point_double(s, u + i * s->dim);
		advance(s);
	}
}
