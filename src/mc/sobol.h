/*
 * sobol.h: the Sobol' low-discrepancy sequence of the Monte Carlo engine's `sobol` sampler
 * (DESIGN.md, "Monte Carlo engine"), in up to 21,201 dimensions.
 *
 * Direction numbers: Joe and Kuo's new-joe-kuo-6.21201 (SIAM J. Sci. Comput. 30 (2008) 2635),
 * the table chosen for good two-dimensional projections, compiled in from the C source that
 * scripts/gen-sobol-table.py generates at build time (cmake/SobolTable.cmake). Dimension 1 is
 * van der Corput's sequence. Each dimension has 32 direction numbers of 32 bits, so a sequence
 * has 2^32 points with 32-bit resolution.
 *
 * Order: Gray code (Antonov-Saleev). Point n is the XOR of the direction numbers V_k over the
 * set bits k of gray(n) = n ^ (n >> 1), so any index is reached directly in O(32 dim)
 * (prsm_sobol_seq_seek) and the next point costs one XOR per dimension. The first 2^m points
 * are the same set as in natural order: a (t, m, s)-net. The engine generates each block of
 * samples from its own first index, which is why a block's points do not depend on the
 * thread that runs it or on the other blocks.
 *
 * Randomisation (prsm_sobol_seq_init with scramble != 0): Matousek's affine matrix scramble,
 * i.e. a random linear matrix scramble (LMS, Owen-style: digit i of a coordinate becomes digit
 * i plus a random GF(2) combination of the digits above it, a random lower-triangular 32 x 32
 * matrix with unit diagonal per dimension) followed by a random digital shift (XOR with a
 * random word per dimension). The scramble multiplies each dimension's generator matrix once at
 * initialisation, so generating stays one XOR per coordinate and skip-ahead stays exact; nets
 * stay nets with the same t. The random words come from the Philox stream (seed, stream) of
 * util/rng.h, drawn dimension by dimension (34 32-bit words each: 32 matrix rows, then the
 * shift's high and low words), so the first k dimensions of a sequence do not depend on how
 * many dimensions follow. Each randomised point is uniform on (0, 1)^dim, so estimates are
 * unbiased and independent seeds give independent replicates.
 *
 * Output: a coordinate is the 52-bit number (x << 20) ^ shift, with x the 32-bit (scrambled)
 * sequence digit and shift a 52-bit digital shift (0 unscrambled), centred in its 2^-52 cell:
 * u = (k + 1/2) 2^-52, so 2^-53 <= u <= 1 - 2^-53, never 0 or 1 (inverse CDFs follow).
 * Unscrambled, u = x / 2^32 + 2^-53.
 */
#ifndef PRSM_MC_SOBOL_H
#define PRSM_MC_SOBOL_H

#include <stddef.h>
#include <stdint.h>

#define PRSM_SOBOL_MAX_DIM 21201               /* Joe-Kuo new-joe-kuo-6.21201 */
#define PRSM_SOBOL_BITS 32                     /* direction numbers per dimension, and their bits */
#define PRSM_SOBOL_MAX_POINTS (UINT64_C(1) << PRSM_SOBOL_BITS)

typedef struct {
	size_t dim;
	uint32_t *v;                               /* PRSM_SOBOL_BITS x dim: v[k * dim + j], bit k of gray(n) */
	uint64_t *shift;                           /* dim 52-bit digital shifts (0 unscrambled) */
	uint32_t *x;                               /* dim: the point at index `next` (before the shift) */
	uint64_t next;                             /* index of the point prsm_sobol_seq_next returns */
} prsm_sobol_seq;

/* A sequence of dim dimensions at index 0; scrambled (see above) by the Philox stream
 * (seed, stream) when scramble != 0. Returns 0, PRSM_EINVAL (dim is 0 or more than
 * PRSM_SOBOL_MAX_DIM; s is then empty) or PRSM_ENOMEM. Free with prsm_sobol_seq_free. */
int prsm_sobol_seq_init(prsm_sobol_seq *s, size_t dim, int scramble, uint64_t seed, uint64_t stream);

void prsm_sobol_seq_free(prsm_sobol_seq *s);

/* Move to index n (< PRSM_SOBOL_MAX_POINTS) directly: O(32 dim), whatever the current index. */
void prsm_sobol_seq_seek(prsm_sobol_seq *s, uint64_t n);

/* The point at the current index as 32-bit digits (scramble and the top 32 bits of the shift
 * applied: the coordinate's first 32 binary digits), then advance. */
void prsm_sobol_seq_next_u32(prsm_sobol_seq *s, uint32_t *x);

/* The point at the current index in (0, 1)^dim, then advance. */
void prsm_sobol_seq_next(prsm_sobol_seq *s, double *u);

/* Points first .. first + n - 1 as n rows of dim, row-major, in (0, 1): a seek, then n steps.
 * The points depend only on the sequence and `first`. Requires first + n <= PRSM_SOBOL_MAX_POINTS. */
void prsm_sobol_seq_block(prsm_sobol_seq *s, double *u, size_t n, uint64_t first);

/* The generated table (scripts/gen-sobol-table.py): per dimension the degree s of its
 * primitive polynomial (0 for dimension 1) and its interior coefficients a; the initial
 * direction numbers m_1..m_s of every dimension one after another. */
extern const unsigned char prsm_sobol_table_degree[PRSM_SOBOL_MAX_DIM];
extern const uint32_t prsm_sobol_table_a[PRSM_SOBOL_MAX_DIM];
extern const uint32_t prsm_sobol_table_m[];
extern const size_t prsm_sobol_table_m_count;

#endif
