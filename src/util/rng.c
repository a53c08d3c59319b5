/*
 * rng.c: Philox4x64-10 (Random123's philox.h) as a gsl_rng_type; see rng.h for the stream
 * layout. The state holds the key, the counter of the next block and the current block's eight
 * 32-bit words; a block is computed only when its first word is asked for.
 */
#include "util/rng.h"

#include <assert.h>

#include <Random123/philox.h>

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

void prsm_rng_fill_uniform_pos(gsl_rng *r, double *u, size_t n)
{
	assert(r != NULL && r->type == prsm_rng_philox);
	prsm_rng_state *st = r->state;
	size_t i = 0;
	/* whole blocks while at a block boundary: the four numbers of a fresh block straight from
	 * its words (as the loop below reads them), the state left as after reading it all; a block
	 * with a zero number goes to the loop below, which redraws it */
	while (st->next_word == PRSM_RNG_WORDS_PER_BLOCK && n - i >= 4) {
		rng_refill(st);
		uint64_t k[4];
		for (int j = 0; j < 4; j++) {
			const uint64_t v = st->block[j];
			k[j] = ((v << 32) | (v >> 32)) >> 11;
		}
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
			uint64_t v = st->block[st->next_word / 2];
			uint64_t k = ((v << 32) | (v >> 32)) >> 11;
			if (k != 0) {
				st->next_word += 2;
				u[i++] = (double)k * 0x1p-53;
				continue;
			}
		}
		u[i++] = prsm_rng_uniform_pos(r);
	}
}
