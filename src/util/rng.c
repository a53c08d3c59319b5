/*
 * rng.c: Philox4x64-10 (Random123's philox.h) as a gsl_rng_type; see rng.h for the stream
 * layout. The state holds the key, the counter of the next block and the current block's eight
 * 32-bit words; a block is computed only when its first word is asked for.
 */
#include "util/rng.h"

#include <assert.h>
#include <string.h>

#include <Random123/philox.h>

#include "util/simd.h"

#define PRSM_RNG_WORDS_PER_BLOCK 8u /* 32-bit words in one 4 x 64-bit Philox block */

typedef struct {
	uint64_t key[2];        /* {seed, stream} */
	uint64_t next_block;    /* counter of the block computed next */
	uint64_t block[4];      /* output of the current block */
	unsigned int next_word; /* index of the next 32-bit word of block, 0..8; 8 = used up */
} prsm_rng_state;

static void rng_state_reset(prsm_rng_state *st, uint64_t seed, uint64_t stream)
{
	st->key[0] = seed;
	st->key[1] = stream;
	st->next_block = 0;
	st->block[0] = st->block[1] = st->block[2] = st->block[3] = 0;
	st->next_word = PRSM_RNG_WORDS_PER_BLOCK;
}

/* The next Philox block of the stream into the state, its words unread. */
static inline void rng_refill(prsm_rng_state *st)
{
	philox4x64_ctr_t ctr = {{st->next_block, 0, 0, 0}};
	philox4x64_key_t key = {{st->key[0], st->key[1]}};
	philox4x64_ctr_t out = philox4x64_R(10, ctr, key);
	for (int i = 0; i < 4; i++)
		st->block[i] = out.v[i];
	st->next_block++;
	st->next_word = 0;
}

static uint32_t rng_next_word(prsm_rng_state *st)
{
	if (st->next_word == PRSM_RNG_WORDS_PER_BLOCK)
		rng_refill(st);
	unsigned int w = st->next_word++;
	uint64_t v = st->block[w / 2];
	return (uint32_t)((w % 2 == 0) ? v : (v >> 32));
}

/* Two consecutive words, the first in the high half. */
static uint64_t rng_next_u64(prsm_rng_state *st)
{
	uint64_t hi = rng_next_word(st);
	uint64_t lo = rng_next_word(st);
	return (hi << 32) | lo;
}

static void rng_set(void *state, unsigned long int seed)
{
	rng_state_reset(state, (uint64_t)seed, 0);
}

static unsigned long int rng_get(void *state)
{
	return rng_next_word(state);
}

static double rng_get_double(void *state)
{
	return (double)(rng_next_u64(state) >> 11) * 0x1p-53; /* [0, 1 - 2^-53] */
}

static const gsl_rng_type prsm_rng_philox_type = {
	"prsm-philox4x64-10",   /* name */
	0xffffffffUL,           /* max of get() */
	0,                      /* min of get() */
	sizeof(prsm_rng_state), /* size of the state */
	&rng_set,
	&rng_get,
	&rng_get_double,
};

const gsl_rng_type *const prsm_rng_philox = &prsm_rng_philox_type;

gsl_rng *prsm_rng_alloc(uint64_t seed, uint64_t stream)
{
	gsl_rng *r = gsl_rng_alloc(prsm_rng_philox);
	if (r != NULL)
		prsm_rng_set_stream(r, seed, stream);
	return r;
}

void prsm_rng_set_stream(gsl_rng *r, uint64_t seed, uint64_t stream)
{
	assert(r != NULL && r->type == prsm_rng_philox);
	rng_state_reset(r->state, seed, stream);
}

double prsm_rng_uniform_pos(gsl_rng *r)
{
	assert(r != NULL && r->type == prsm_rng_philox);
	prsm_rng_state *st = r->state;
	uint64_t k;
	do {
		k = rng_next_u64(st) >> 11; /* 53 bits */
	} while (k == 0);
	return (double)k * 0x1p-53; /* [2^-53, 1 - 2^-53] */
}

/* ---- the bulk draw by chunks (docs/speed.md, "Engine overhead") -------------------------------
 *
 * On a processor with AVX2 and BMI2 (util/simd.h), prsm_rng_fill_uniform_pos draws chunks of
 * FILL_BLOCKS consecutive blocks of the stream: their words first, block by block (BMI2's mulx
 * for the 64 x 64 -> 128-bit multiplies, the rounds in assembly, what the blocks share computed
 * once: 85 instructions a block against 106 for Random123's C compiled by GCC; an emulation of
 * the multiplies in AVX2's 32-bit vector multiplies measured twice the instructions), then the
 * chunk's 4 FILL_BLOCKS numbers from the words by a loop without branches that the compiler
 * vectorises, four numbers an instruction. Integer arithmetic and exact floating-point steps:
 * the numbers of prsm_rng_uniform_pos (test_rng checks them). The baseline build keeps the block loop below:
 * with two-lane SSE2 vectors and mul the chunks measured no fewer instructions than it. */
#define FILL_BLOCKS 16u
#define FILL_VALUES (4u * FILL_BLOCKS)

/* The 53-bit number k of one 64-bit block word, as rng_next_u64 reads its two halves (low half
 * first, as the high bits) and prsm_rng_uniform_pos keeps the top 53 bits: k / 2^53 is the
 * uniform. */
static inline uint64_t word_k(uint64_t v)
{
	return ((v << 32) | (v >> 32)) >> 11;
}

#if PRSM_HAVE_AVX2_CLONES
/* The uniform of one 64-bit block word, as prsm_rng_uniform_pos reads the word's two halves (low
 * half first, as the high bits): k = the top 53 bits, k / 2^53 = 0 when k = 0. Built exactly
 * without an integer conversion, which AVX2 lacks for 64-bit integers: with k = b 2^52 + m
 * (m < 2^52), 1/2 + m 2^-53 is the double of exponent -1 and fraction m, which is k / 2^53 when
 * b = 1 and 1/2 more than it when b = 0 (subtracting 1/2 is exact then, Sterbenz). */
static inline double uniform_of_word(uint64_t v)
{
	const uint64_t k = word_k(v);
	const uint64_t half_bits = UINT64_C(0x3fe0000000000000);
	const uint64_t a_bits = half_bits | (k & ((UINT64_C(1) << 52) - 1));
	const uint64_t b_bits = ((k >> 52) - 1) & half_bits; /* 1/2 when bit 52 of k is clear, else +0 */
	double a, b;
	memcpy(&a, &a_bits, sizeof a);
	memcpy(&b, &b_bits, sizeof b);
	return a - b;
}

/* One Philox round of Random123's philox4x64 (_philox4x64round) on x0..x3 with round key k[0],
 * k[1]: {hi(M1 x2) ^ x1 ^ k[0], lo(M1 x2), hi(M0 x0) ^ x3 ^ k[1], lo(M0 x0)}. Written in BMI2
 * assembly (two mulx, four xor, the two moves into rdx that mulx reads, the keys read from
 * memory): GCC's code for the same C spent a quarter more instructions on moves and reloads. */
#define PHILOX_ROUND(x0, x1, x2, x3, k)                                                            \
	do {                                                                                         \
		uint64_t n0_, n1_, n2_, n3_;                                                             \
		__asm__("movq %[in2], %%rdx\n\t"                                                         \
		        "mulx %[m1], %[o1], %[o0]\n\t"                                                   \
		        "movq %[in0], %%rdx\n\t"                                                         \
		        "mulx %[m0], %[o3], %[o2]\n\t"                                                   \
		        "xorq %[in1], %[o0]\n\t"                                                         \
		        "xorq %[k0], %[o0]\n\t"                                                          \
		        "xorq %[in3], %[o2]\n\t"                                                         \
		        "xorq %[k1], %[o2]"                                                              \
		        : [o0] "=&r"(n0_), [o1] "=&r"(n1_), [o2] "=&r"(n2_), [o3] "=&r"(n3_)             \
		        : [in0] "r"(x0), [in1] "r"(x1), [in2] "r"(x2), [in3] "r"(x3), [k0] "m"((k)[0]),  \
		          [k1] "m"((k)[1]), [m0] "r"(philox_m0), [m1] "r"(philox_m1)                     \
		        : "rdx", "cc");                                                                  \
		x0 = n0_;                                                                                \
		x1 = n1_;                                                                                \
		x2 = n2_;                                                                                \
		x3 = n3_;                                                                                \
	} while (0)

/* The words of blocks ctr0 .. ctr0 + FILL_BLOCKS - 1 of stream key: w[4 j + i] = v[i] of block j
 * (the counter wraps as rng_refill's does). philox4x64_R(10, {ctr, 0, 0, 0}, key) written out
 * with what every block of the stream shares computed once: the ten round keys (Random123 bumps
 * the key before each round after the first), and, the counter's other words being 0, round 0's
 * product of word 2 (0) and round 1's of word 0 (round 0 makes it the key's first word). The
 * same integer operations otherwise, so the same words (test_rng checks them against
 * philox4x64_R). */
PRSM_TARGET_AVX2 static void philox_chunk_words(const uint64_t key[2], uint64_t ctr0, uint64_t *restrict w)
{
	uint64_t rk[20];
	rk[0] = key[0];
	rk[1] = key[1];
	for (unsigned r = 1; r < 10; r++) {
		rk[2 * r] = rk[2 * r - 2] + PHILOX_W64_0;
		rk[2 * r + 1] = rk[2 * r - 1] + PHILOX_W64_1;
	}
	/* round 1's product of word 0, which round 0 sets to rk[0] whatever the counter */
	const unsigned __int128 p1w0 = (unsigned __int128)PHILOX_M4x64_0 * rk[0];
	const uint64_t r1_hi = (uint64_t)(p1w0 >> 64) ^ rk[3], r1_lo = (uint64_t)p1w0;
	const uint64_t philox_m0 = PHILOX_M4x64_0, philox_m1 = PHILOX_M4x64_1;
	for (unsigned j = 0; j < FILL_BLOCKS; j++) {
		/* round 0 on {c, 0, 0, 0}: {0 ^ 0 ^ rk[0], 0, hi(M0 c) ^ 0 ^ rk[1], lo(M0 c)} */
		const unsigned __int128 p0 = (unsigned __int128)PHILOX_M4x64_0 * (ctr0 + j);
		const uint64_t y2 = (uint64_t)(p0 >> 64) ^ rk[1], y3 = (uint64_t)p0;
		/* round 1 on {rk[0], 0, y2, y3} */
		const unsigned __int128 p1 = (unsigned __int128)PHILOX_M4x64_1 * y2;
		uint64_t x0 = (uint64_t)(p1 >> 64) ^ rk[2], x1 = (uint64_t)p1, x2 = y3 ^ r1_hi, x3 = r1_lo;
		PHILOX_ROUND(x0, x1, x2, x3, rk + 4); /* rounds 2 to 9, written out */
		PHILOX_ROUND(x0, x1, x2, x3, rk + 6);
		PHILOX_ROUND(x0, x1, x2, x3, rk + 8);
		PHILOX_ROUND(x0, x1, x2, x3, rk + 10);
		PHILOX_ROUND(x0, x1, x2, x3, rk + 12);
		PHILOX_ROUND(x0, x1, x2, x3, rk + 14);
		PHILOX_ROUND(x0, x1, x2, x3, rk + 16);
		PHILOX_ROUND(x0, x1, x2, x3, rk + 18);
		w[4 * j] = x0;
		w[4 * j + 1] = x1;
		w[4 * j + 2] = x2;
		w[4 * j + 3] = x3;
	}
}

/* u[i] = the uniform of word w[i] for the chunk's FILL_VALUES words; returns how many are 0 (k =
 * 0), which the caller must redraw. */
PRSM_TARGET_AVX2 static unsigned uniform_chunk(const uint64_t *restrict w, double *restrict u)
{
	uint64_t zeros = 0; /* 64-bit, as the lanes' compare masks: no narrowing in the sum */
	for (unsigned i = 0; i < FILL_VALUES; i++) {
		const double x = uniform_of_word(w[i]);
		u[i] = x;
		zeros += x == 0.0;
	}
	return (unsigned)zeros;
}
#endif

int prsm_rng_uniforms_of_words_for_test(const uint64_t w[64], double u[64])
{
	_Static_assert(FILL_VALUES == 64, "rng.h promises 64 words a chunk");
#if PRSM_HAVE_AVX2_CLONES
	if (prsm_simd_avx2())
		return (int)uniform_chunk(w, u);
#endif
	(void)w;
	(void)u;
	return -1;
}

int prsm_rng_philox_words_for_test(uint64_t key0, uint64_t key1, uint64_t ctr0, uint64_t w[64])
{
#if PRSM_HAVE_AVX2_CLONES
	if (prsm_simd_avx2()) {
		const uint64_t key[2] = {key0, key1};
		philox_chunk_words(key, ctr0, w);
		return 0;
	}
#endif
	(void)key0;
	(void)key1;
	(void)ctr0;
	(void)w;
	return -1;
}

void prsm_rng_fill_uniform_pos(gsl_rng *r, double *u, size_t n)
{
	assert(r != NULL && r->type == prsm_rng_philox);
	prsm_rng_state *st = r->state;
	size_t i = 0;
#if PRSM_HAVE_AVX2_CLONES
	/* whole chunks while at a block boundary; a chunk with a zero number goes to the loops below,
	 * from its first block (the state is advanced only past the chunks written) */
	if (st->next_word == PRSM_RNG_WORDS_PER_BLOCK && n >= FILL_VALUES && prsm_simd_avx2()) {
		uint64_t w[FILL_VALUES];
		while (n - i >= FILL_VALUES) {
			philox_chunk_words(st->key, st->next_block, w);
			if (uniform_chunk(w, u + i) != 0)
				break;
			st->next_block += FILL_BLOCKS;
			i += FILL_VALUES;
		}
	}
#endif
	/* whole blocks while at a block boundary: the four numbers of a fresh block straight from
	 * its words (as the loop below reads them), the state left as after reading it all; a block
	 * with a zero number goes to the loop below, which redraws it */
	while (st->next_word == PRSM_RNG_WORDS_PER_BLOCK && n - i >= 4) {
		rng_refill(st);
		uint64_t k[4];
		for (int j = 0; j < 4; j++)
			k[j] = word_k(st->block[j]);
		if (k[0] == 0 || k[1] == 0 || k[2] == 0 || k[3] == 0)
			break;
		for (int j = 0; j < 4; j++)
			u[i + (size_t)j] = (double)(int64_t)k[j] * 0x1p-53; /* k < 2^53: the same double, by the
			                                                        cheaper signed conversion */
		i += 4;
		st->next_word = PRSM_RNG_WORDS_PER_BLOCK;
	}
	while (i < n) {
		/* a spent block is refilled here, as rng_next_word would, without the library's
		 * dispatch for every fourth number */
		if (st->next_word == PRSM_RNG_WORDS_PER_BLOCK)
			rng_refill(st);
		/* fast path: two unread words of the current block, in the order rng_next_u64 reads
		 * them (low half first, as the high bits) */
		if (st->next_word % 2 == 0 && st->next_word < PRSM_RNG_WORDS_PER_BLOCK) {
			const uint64_t k = word_k(st->block[st->next_word / 2]);
			if (k != 0) {
				st->next_word += 2;
				u[i++] = (double)k * 0x1p-53;
				continue;
			}
		}
		u[i++] = prsm_rng_uniform_pos(r);
	}
}
