/*
 * test_rng.c: the Philox stream of util/rng.h — Random123's published known answers for
 * philox4x64-10, the word order of the gsl_rng wrapper, determinism and independence of
 * (seed, stream), moments of gsl_rng_uniform and gsl_ran_gaussian, the open interval of
 * prsm_rng_uniform_pos.
 */
#include "test_support.h"

#include "util/rng.h"
#include "util/simd.h"

#include <string.h>

#include <Random123/philox.h>
#include <gsl/gsl_randist.h>

/* Random123 kat_vectors, lines "philox4x64 10 ctr[4] key[2] expected[4]". */
static const struct {
	uint64_t ctr[4], key[2], expected[4];
} philox_kat[] = {
	{{0, 0, 0, 0},
	 {0, 0},
	 {0x16554d9eca36314cULL, 0xdb20fe9d672d0fdcULL, 0xd7e772cee186176bULL, 0x7e68b68aec7ba23bULL}},
	{{~0ULL, ~0ULL, ~0ULL, ~0ULL},
	 {~0ULL, ~0ULL},
	 {0x87b092c3013fe90bULL, 0x438c3c67be8d0224ULL, 0x9cc7d7c69cd777b6ULL, 0xa09caebf594f0ba0ULL}},
	{{0x243f6a8885a308d3ULL, 0x13198a2e03707344ULL, 0xa4093822299f31d0ULL, 0x082efa98ec4e6c89ULL},
	 {0x452821e638d01377ULL, 0xbe5466cf34e90c6cULL},
	 {0xa528f45403e61d95ULL, 0x38c72dbd566e9788ULL, 0xa5a1610e72fd18b5ULL, 0x57bd43b5e52b7fe6ULL}},
};

static philox4x64_ctr_t philox_block(uint64_t counter, uint64_t seed, uint64_t stream)
{
	philox4x64_ctr_t c = {{counter, 0, 0, 0}};
	philox4x64_key_t k = {{seed, stream}};
	return philox4x64_R(10, c, k);
}

static void test_philox_known_answers(void **state)
{
	(void)state;
	for (size_t i = 0; i < sizeof philox_kat / sizeof philox_kat[0]; i++) {
		philox4x64_ctr_t c, out;
		philox4x64_key_t k;
		memcpy(c.v, philox_kat[i].ctr, sizeof c.v);
		memcpy(k.v, philox_kat[i].key, sizeof k.v);
		out = philox4x64_R(10, c, k);
		for (int j = 0; j < 4; j++)
			assert_true(out.v[j] == philox_kat[i].expected[j]);
	}
}

static void test_type_properties(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(2385, 713);
	assert_non_null(r);
	assert_ptr_equal(r->type, prsm_rng_philox);
	assert_string_equal(gsl_rng_name(r), "prsm-philox4x64-10");
	assert_true(gsl_rng_max(r) == 0xffffffffUL);
	assert_true(gsl_rng_min(r) == 0);
	gsl_rng_free(r);
}

/* Stream (0, 0) starts with the first KAT block, low word of v[0] first. Later blocks and a
 * high-entropy key follow the documented layout. */
static void test_wrapper_word_order(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(0, 0);
	assert_non_null(r);
	for (int j = 0; j < 4; j++) {
		assert_true(gsl_rng_get(r) == (philox_kat[0].expected[j] & 0xffffffffULL));
		assert_true(gsl_rng_get(r) == (philox_kat[0].expected[j] >> 32));
	}
	const uint64_t seed = 0x9e3779b97f4a7c15ULL, stream = 4711;
	prsm_rng_set_stream(r, seed, stream);
	for (uint64_t b = 0; b < 5; b++) {
		philox4x64_ctr_t out = philox_block(b, seed, stream);
		for (int j = 0; j < 4; j++) {
			assert_true(gsl_rng_get(r) == (out.v[j] & 0xffffffffULL));
			assert_true(gsl_rng_get(r) == (out.v[j] >> 32));
		}
	}
	gsl_rng_free(r);
}

/* gsl_rng_uniform is the top 53 bits of two consecutive words, first word high. */
static void test_get_double_layout(void **state)
{
	(void)state;
	gsl_rng *a = prsm_rng_alloc(31337, 12), *b = prsm_rng_alloc(31337, 12);
	assert_non_null(a);
	assert_non_null(b);
	for (int i = 0; i < 1000; i++) {
		uint64_t hi = gsl_rng_get(b), lo = gsl_rng_get(b);
		double expected = (double)(((hi << 32) | lo) >> 11) * 0x1p-53;
		double u = gsl_rng_uniform(a);
		assert_true(u == expected);
		assert_true(u >= 0.0 && u < 1.0);
	}
	gsl_rng_free(a);
	gsl_rng_free(b);
}

static void test_set_means_stream_zero(void **state)
{
	(void)state;
	gsl_rng *a = gsl_rng_alloc(prsm_rng_philox), *b = prsm_rng_alloc(8675309, 0);
	assert_non_null(a);
	assert_non_null(b);
	gsl_rng_set(a, 8675309);
	for (int i = 0; i < 100; i++)
		assert_true(gsl_rng_get(a) == gsl_rng_get(b));
	gsl_rng_free(a);
	gsl_rng_free(b);
}

static void test_determinism(void **state)
{
	(void)state;
	enum { N = 1001 }; /* odd, to end in the middle of a block */
	static double first[N];
	gsl_rng *r = prsm_rng_alloc(20240611, 17);
	assert_non_null(r);
	for (int i = 0; i < N; i++)
		first[i] = gsl_rng_uniform(r);
	/* wander off to other streams, then come back */
	prsm_rng_set_stream(r, 1, 2);
	(void)gsl_rng_get(r);
	prsm_rng_set_stream(r, 20240611, 17);
	for (int i = 0; i < N; i++)
		assert_true(gsl_rng_uniform(r) == first[i]);

	/* a clone continues the same sequence; two generators interleaved do not disturb each
	 * other (no shared state) */
	prsm_rng_set_stream(r, 20240611, 17);
	for (int i = 0; i < 400; i++)
		(void)gsl_rng_uniform(r);
	gsl_rng *c = gsl_rng_clone(r);
	gsl_rng *other = prsm_rng_alloc(5, 5);
	assert_non_null(c);
	assert_non_null(other);
	for (int i = 400; i < N; i++) {
		(void)gsl_rng_uniform(other);
		assert_true(gsl_rng_uniform(c) == first[i]);
		assert_true(gsl_rng_uniform(r) == first[i]);
	}
	gsl_rng_free(other);
	gsl_rng_free(c);
	gsl_rng_free(r);
}

/* Counts equal words at equal positions; for independent streams about n / 2^32. */
static int count_equal_words(uint64_t seed_a, uint64_t stream_a, uint64_t seed_b, uint64_t stream_b, int n)
{
	gsl_rng *a = prsm_rng_alloc(seed_a, stream_a), *b = prsm_rng_alloc(seed_b, stream_b);
	assert_non_null(a);
	assert_non_null(b);
	int equal = 0;
	for (int i = 0; i < n; i++)
		equal += gsl_rng_get(a) == gsl_rng_get(b);
	gsl_rng_free(a);
	gsl_rng_free(b);
	return equal;
}

static void test_streams_differ(void **state)
{
	(void)state;
	assert_true(count_equal_words(42, 0, 42, 1, 4096) <= 1);
	assert_true(count_equal_words(42, 0, 43, 0, 4096) <= 1);
	assert_true(count_equal_words(42, 7, 7, 42, 4096) <= 1); /* seed and stream are not symmetric */
	assert_true(count_equal_words(0, 0, 0, 1ULL << 63, 4096) <= 1);
}

/* |mean - expected| and |variance - expected| within 5 standard errors of the estimators. */
static void check_moments(const double *x, size_t n, double mean, double var)
{
	double m = 0.0;
	for (size_t i = 0; i < n; i++)
		m += x[i];
	m /= (double)n;
	double m2 = 0.0, m4 = 0.0;
	for (size_t i = 0; i < n; i++) {
		double d = x[i] - m, d2 = d * d;
		m2 += d2;
		m4 += d2 * d2;
	}
	m2 /= (double)(n - 1);
	m4 /= (double)n;
	assert_close(m, mean, 5.0 * sqrt(var / (double)n));
	assert_close(m2, var, 5.0 * sqrt((m4 - m2 * m2) / (double)n));
}

enum { MOMENT_N = 1000000 };
static double sample[MOMENT_N];

static void test_uniform_moments(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(2718281828ULL, 3);
	assert_non_null(r);
	double lo = 1.0, hi = 0.0;
	for (size_t i = 0; i < MOMENT_N; i++) {
		sample[i] = gsl_rng_uniform(r);
		lo = fmin(lo, sample[i]);
		hi = fmax(hi, sample[i]);
	}
	assert_true(lo >= 0.0 && lo < 1e-5);
	assert_true(hi < 1.0 && hi > 1.0 - 1e-5);
	check_moments(sample, MOMENT_N, 0.5, 1.0 / 12.0);
	gsl_rng_free(r);
}

static void test_uniform_pos_open_interval(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(1414213562ULL, 99);
	assert_non_null(r);
	double lo = 1.0, hi = 0.0;
	for (size_t i = 0; i < MOMENT_N; i++) {
		double u = prsm_rng_uniform_pos(r);
		assert_true(u > 0.0 && u < 1.0);
		/* a multiple of 2^-53 */
		double k = u * 0x1p53;
		assert_true(k == floor(k));
		sample[i] = u;
		lo = fmin(lo, u);
		hi = fmax(hi, u);
	}
	assert_true(lo < 1e-5 && hi > 1.0 - 1e-5);
	check_moments(sample, MOMENT_N, 0.5, 1.0 / 12.0);

	/* the same words as gsl_rng_uniform (no zero was drawn in this short run) */
	gsl_rng *a = prsm_rng_alloc(1414213562ULL, 98), *b = prsm_rng_alloc(1414213562ULL, 98);
	assert_non_null(a);
	assert_non_null(b);
	for (int i = 0; i < 1000; i++)
		assert_true(prsm_rng_uniform_pos(a) == gsl_rng_uniform(b));
	gsl_rng_free(a);
	gsl_rng_free(b);
	gsl_rng_free(r);
}

static void test_gaussian_moments(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(1618033988ULL, 5);
	assert_non_null(r);
	const double sigma = 2.385;
	for (size_t i = 0; i < MOMENT_N; i++)
		sample[i] = gsl_ran_gaussian(r, sigma);
	check_moments(sample, MOMENT_N, 0.0, sigma * sigma);
	for (size_t i = 0; i < MOMENT_N; i++)
		sample[i] = gsl_ran_gaussian_ziggurat(r, sigma);
	check_moments(sample, MOMENT_N, 0.0, sigma * sigma);
	gsl_rng_free(r);
}

/* The bulk draw is the same sequence as one call at a time, from any position in a block. */
static void test_fill_uniform_pos(void **state)
{
	(void)state;
	double a[1003], b[1003];
	for (int skip = 0; skip < 9; skip++) {
		gsl_rng *r1 = prsm_rng_alloc(20261121, 77), *r2 = prsm_rng_alloc(20261121, 77);
		for (int k = 0; k < skip; k++) {
			gsl_rng_get(r1); /* leaves the word position odd or even */
			gsl_rng_get(r2);
		}
		for (int i = 0; i < 1003; i++)
			a[i] = prsm_rng_uniform_pos(r1);
		prsm_rng_fill_uniform_pos(r2, b, 500);
		prsm_rng_fill_uniform_pos(r2, b + 500, 503);
		assert_memory_equal(a, b, sizeof a);
		assert_int_equal(gsl_rng_get(r1), gsl_rng_get(r2));
		gsl_rng_free(r1);
		gsl_rng_free(r2);
	}
}

/* The reference conversion of a block word: prsm_rng_uniform_pos's k / 2^53, 0 for k = 0. */
static double word_uniform_reference(uint64_t v)
{
	const uint64_t k = ((v << 32) | (v >> 32)) >> 11;
	return (double)k * 0x1p-53;
}

/* The chunk conversion gives the reference's bits, for random words and for the
 * words at the edges of its two cases (k = 0, 1, 2^52 - 1, 2^52, 2^52 + 1, 2^53 - 1, the low 11
 * bits that are dropped), and counts the zeros. */
static void test_chunk_conversion(void **state)
{
	(void)state;
	static const uint64_t edge_k[] = {0, 1, 2, (UINT64_C(1) << 52) - 1, UINT64_C(1) << 52, (UINT64_C(1) << 52) + 1,
	                                  (UINT64_C(1) << 53) - 1, UINT64_C(1) << 51, 12345};
	gsl_rng *r = prsm_rng_alloc(20261126, 11);
	assert_non_null(r);
	uint64_t w[64];
	double u[64];
	for (int round = 0; round < 20000; round++) {
		unsigned expect_zeros = 0;
		for (int i = 0; i < 64; i++) {
			uint64_t v = ((uint64_t)gsl_rng_get(r) << 32) | gsl_rng_get(r);
			if (round % 4 == 0 && i % 3 == 0) {
				/* a word whose k is an edge value, with arbitrary dropped low bits: k's top 32
				 * bits are the word's low half, its low 21 bits the top of the high half */
				const uint64_t k = edge_k[(size_t)(round / 4 + i) % (sizeof edge_k / sizeof edge_k[0])];
				const uint64_t rot = (k << 11) | (v & 0x7ff);
				v = (rot << 32) | (rot >> 32);
			}
			w[i] = v;
			expect_zeros += word_uniform_reference(v) == 0.0;
		}
		const int zeros = prsm_rng_uniforms_of_words_for_test(w, u);
		if (zeros < 0) { /* no AVX2 here: the chunks are not drawn either */
			gsl_rng_free(r);
			skip();
		}
		assert_int_equal(zeros, (int)expect_zeros);
		for (int i = 0; i < 64; i++) {
			const double ref = word_uniform_reference(w[i]);
			if (memcmp(&u[i], &ref, sizeof ref) != 0)
				fail_msg("word %016llx: %a against %a", (unsigned long long)w[i], u[i], ref);
		}
	}
	gsl_rng_free(r);
}

/* The AVX2 build's Philox blocks (the round keys and the first two rounds' shared products
 * computed once, the rounds in BMI2 assembly) are Random123's philox4x64_R(10) word for word:
 * random keys and counters, keys of all zeros and all ones, counters that wrap. */
static void test_philox_chunk_words(void **state)
{
	(void)state;
	gsl_rng *r = prsm_rng_alloc(20261126, 29);
	assert_non_null(r);
	static const uint64_t edge[] = {0, 1, UINT64_MAX, UINT64_MAX - 7, UINT64_C(1) << 63, 0x9E3779B97F4A7C15};
	const size_t ne = sizeof edge / sizeof edge[0];
	uint64_t w[64];
	for (int t = 0; t < 20000; t++) {
		uint64_t v[3];
		for (int i = 0; i < 3; i++)
			v[i] = ((uint64_t)gsl_rng_get(r) << 32) | gsl_rng_get(r);
		if (t < (int)(ne * ne * ne)) {
			v[0] = edge[(size_t)t % ne];
			v[1] = edge[(size_t)t / ne % ne];
			v[2] = edge[(size_t)t / (ne * ne)];
		}
		if (prsm_rng_philox_words_for_test(v[0], v[1], v[2], w) < 0) {
			gsl_rng_free(r);
			skip();
		}
		const philox4x64_key_t key = {{v[0], v[1]}};
		for (uint64_t j = 0; j < 16; j++) {
			const philox4x64_ctr_t ctr = {{v[2] + j, 0, 0, 0}};
			const philox4x64_ctr_t out = philox4x64_R(10, ctr, key);
			for (int i = 0; i < 4; i++)
				if (w[4 * j + (uint64_t)i] != out.v[i])
					fail_msg("key %016llx %016llx, counter %016llx, block %llu word %d: %016llx against %016llx",
					         (unsigned long long)v[0], (unsigned long long)v[1], (unsigned long long)v[2],
					         (unsigned long long)j, i, (unsigned long long)w[4 * j + (uint64_t)i],
					         (unsigned long long)out.v[i]);
		}
	}
	gsl_rng_free(r);
}

/* The bulk draw is one call at a time with the AVX2 builds allowed (by chunks, then the blocks
 * and words left) and not (by blocks): long draws in many streams, from odd and even word
 * positions. */
static void test_fill_builds(void **state)
{
	(void)state;
	enum { N = 20000 };
	static double a[N], b[N];
	for (int allow = 0; allow < 2; allow++) {
		prsm_simd_allow_avx2(allow);
		for (uint64_t stream = 0; stream < 24; stream++) {
			const size_t n = N - (size_t)(stream * 131 % 97); /* not a whole number of chunks */
			gsl_rng *r1 = prsm_rng_alloc(20261126 + stream, stream), *r2 = prsm_rng_alloc(20261126 + stream, stream);
			for (uint64_t k = 0; k < stream % 3; k++) {
				gsl_rng_get(r1);
				gsl_rng_get(r2);
			}
			for (size_t i = 0; i < n; i++)
				a[i] = prsm_rng_uniform_pos(r1);
			prsm_rng_fill_uniform_pos(r2, b, n);
			assert_memory_equal(a, b, n * sizeof a[0]);
			assert_int_equal(gsl_rng_get(r1), gsl_rng_get(r2));
			gsl_rng_free(r1);
			gsl_rng_free(r2);
		}
	}
	prsm_simd_allow_avx2(1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_philox_known_answers),
		cmocka_unit_test(test_type_properties),
		cmocka_unit_test(test_wrapper_word_order),
		cmocka_unit_test(test_get_double_layout),
		cmocka_unit_test(test_set_means_stream_zero),
		cmocka_unit_test(test_determinism),
		cmocka_unit_test(test_streams_differ),
		cmocka_unit_test(test_uniform_moments),
		cmocka_unit_test(test_uniform_pos_open_interval),
		cmocka_unit_test(test_fill_uniform_pos),
		cmocka_unit_test(test_philox_chunk_words),
		cmocka_unit_test(test_chunk_conversion),
		cmocka_unit_test(test_fill_builds),
		cmocka_unit_test(test_gaussian_moments),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
