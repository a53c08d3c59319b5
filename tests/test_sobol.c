/*
 * test_sobol.c: the Sobol' sequence of mc/sobol.h (Joe-Kuo new-joe-kuo-6.21201 direction
 * numbers, Gray-code order, skip-ahead, linear matrix scramble + digital shift) and the
 * engine's `sobol` sampler built on it: known points, stratification (one-dimensional strata in
 * all 21,201 dimensions, two-dimensional (t, m, 2)-nets kept by the scramble), skip-ahead,
 * integration accuracy in 104 dimensions against plain Monte Carlo's standard error, and the
 * case A tolerance study (52 variables, a 104-dimensional Saltelli design) sampled by Sobol
 * with bit-identical results for 1 and 2 threads.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "app/study.h"
#include "io/study_json.h"
#include "io/global.h"
#include "mc/engine.h"
#include "mc/sobol.h"
#include "util/rng.h"

static prsm_sobol_seq seq(size_t dim, int scramble, uint64_t seed)
{
	prsm_sobol_seq s;
	assert_int_equal(prsm_sobol_seq_init(&s, dim, scramble, seed, 3), 0);
	return s;
}

/* ---- known points --------------------------------------------------------------------------- */

/* The unscrambled sequence in Gray-code order: dimensions 1-3, points 0-7 (times 8: the classic
 * 0, 1/2, 3/4, 1/4, 3/8, 7/8, 5/8, 1/8 of van der Corput in Gray order, and Joe-Kuo's
 * dimensions 2 (s 1, a 0, m 1) and 3 (s 2, a 1, m 1 3)); deeper points of higher dimensions
 * as scipy.stats.qmc.Sobol(d, scramble=False, bits=32) gives them (scipy ships the same
 * table), times 2^32. */
static void test_known_points(void **state)
{
	(void)state;
	static const int first8[8][3] = {{0, 0, 0}, {4, 4, 4}, {6, 2, 2}, {2, 6, 6},
	                                 {3, 3, 5}, {7, 7, 1}, {5, 1, 7}, {1, 5, 3}};
	prsm_sobol_seq s = seq(3, 0, 0);
	for (int i = 0; i < 8; i++) {
		uint32_t x[3];
		double u[3];
		prsm_sobol_seq_seek(&s, (uint64_t)i);
		prsm_sobol_seq_next(&s, u);
		prsm_sobol_seq_seek(&s, (uint64_t)i);
		prsm_sobol_seq_next_u32(&s, x);
		for (int j = 0; j < 3; j++) {
			assert_int_equal(x[j], (uint32_t)first8[i][j] << 29);
			/* the double is the centre of its 2^-52 cell: x / 2^32 + 2^-53, never 0 */
			assert_true(u[j] == (double)first8[i][j] / 8.0 + 0x1p-53);
		}
	}
	prsm_sobol_seq_free(&s);

	/* indices 1000..1003 of dimensions 104, 1000 and 21201 */
	static const uint32_t deep[4][3] = {{2378170368u, 859832320u, 356515840u},
	                                    {230686720u, 3007315968u, 2503999488u},
	                                    {3451912192u, 4081057792u, 3577741312u},
	                                    {1304428544u, 1933574144u, 1430257664u}};
	s = seq(PRSM_SOBOL_MAX_DIM, 0, 0);
	uint32_t *x = malloc(PRSM_SOBOL_MAX_DIM * sizeof *x);
	assert_non_null(x);
	prsm_sobol_seq_seek(&s, 1000);
	for (int i = 0; i < 4; i++) {
		prsm_sobol_seq_next_u32(&s, x);
		assert_int_equal(x[103], deep[i][0]);
		assert_int_equal(x[999], deep[i][1]);
		assert_int_equal(x[21200], deep[i][2]);
	}
	prsm_sobol_seq_free(&s);
	/* points 100000 and 131071 (17 direction numbers) of dimensions 1, 2, 52, 104 */
	static const uint32_t far[2][4] = {{262307840u, 462061568u, 3649601536u, 2045345792u},
	                                   {32768u, 2147516416u, 578977792u, 94076928u}};
	static const uint64_t far_index[2] = {100000, 131071};
	s = seq(104, 0, 0);
	for (int i = 0; i < 2; i++) {
		prsm_sobol_seq_seek(&s, far_index[i]);
		prsm_sobol_seq_next_u32(&s, x);
		assert_int_equal(x[0], far[i][0]);
		assert_int_equal(x[1], far[i][1]);
		assert_int_equal(x[51], far[i][2]);
		assert_int_equal(x[103], far[i][3]);
	}
	prsm_sobol_seq_free(&s);
	free(x);
}

/* Dimensions: 1..21201, nothing else; the engine's sampler says EINVAL beyond. */
static void test_limits(void **state)
{
	(void)state;
	prsm_sobol_seq s;
	assert_int_equal(prsm_sobol_seq_init(&s, 0, 1, 1, 0), PRSM_EINVAL);
	assert_int_equal(prsm_sobol_seq_init(&s, PRSM_SOBOL_MAX_DIM + 1, 1, 1, 0), PRSM_EINVAL);
	double u[1];
	assert_int_equal(prsm_mc_block_uniforms(u, 0, PRSM_SOBOL_MAX_DIM + 1, PRSM_SAMPLER_SOBOL, 5, 0, 0, NULL),
	                 PRSM_EINVAL);
	/* past GSL's old limit of 40 the engine's sampler just works */
	double v[2 * 104];
	assert_int_equal(prsm_mc_block_uniforms(v, 2, 104, PRSM_SAMPLER_SOBOL, 5, 0, 0, NULL), 0);
	for (int j = 0; j < 2 * 104; j++)
		assert_true(v[j] > 0.0 && v[j] < 1.0);
}

/* ---- stratification ----------------------------------------------------------------------- */

/* The first 2^10 points of every one of the 21,201 dimensions fall one in each interval
 * [k/1024, (k+1)/1024), unscrambled and scrambled; no coordinate is 0 or 1. */
static void test_one_dimensional_strata(void **state)
{
	(void)state;
	const size_t D = PRSM_SOBOL_MAX_DIM, N = 1024;
	unsigned char *seen = malloc(D * N / 8);
	double *u = malloc(D * sizeof *u);
	assert_non_null(seen);
	assert_non_null(u);
	for (int scramble = 0; scramble < 2; scramble++) {
		prsm_sobol_seq s = seq(D, scramble, 20261121);
		memset(seen, 0, D * N / 8);
		size_t twice = 0;
		double lo = 1.0, hi = 0.0;
		for (size_t i = 0; i < N; i++) {
			prsm_sobol_seq_next(&s, u);
			for (size_t j = 0; j < D; j++) {
				size_t k = (size_t)(u[j] * (double)N), bit = j * N + k;
				twice += (seen[bit / 8] >> (bit % 8)) & 1u;
				seen[bit / 8] |= (unsigned char)(1u << (bit % 8));
				lo = fmin(lo, u[j]);
				hi = fmax(hi, u[j]);
			}
		}
		assert_int_equal(twice, 0); /* N points in N cells, none twice: each exactly once */
		assert_true(lo > 0.0 && hi < 1.0);
		prsm_sobol_seq_free(&s);
	}
	free(seen);
	free(u);
}

/* The quality parameter t of the 2-D projection (j, k) of points' top m bits: the smallest t
 * such that every elementary interval of volume 2^(t-m), [a/2^p, (a+1)/2^p) x [b/2^q,
 * (b+1)/2^q) with p + q = m - t, holds exactly 2^t of the 2^m points. */
static int net_t(const uint32_t *xj, const uint32_t *xk, int m)
{
	size_t n = (size_t)1 << m;
	static unsigned count[1 << 12];
	for (int t = 0; t <= m; t++) {
		int ok = 1;
		for (int p = 0; p <= m - t && ok; p++) {
			int q = m - t - p;
			memset(count, 0, ((size_t)1 << (m - t)) * sizeof *count);
			for (size_t i = 0; i < n; i++) {
				size_t a = p ? xj[i] >> (32 - p) : 0, b = q ? xk[i] >> (32 - q) : 0;
				count[a << q | b]++;
			}
			for (size_t c = 0; c < ((size_t)1 << (m - t)) && ok; c++)
				ok = count[c] == (1u << t);
		}
		if (ok)
			return t;
	}
	return m + 1;
}

/* Two-dimensional projections at m = 10: every pair of the first 32 dimensions and pairs spread
 * over all 21,201 are (t, 10, 2)-nets; dimensions 1 and 2 with t = 0 (Sobol's first two
 * dimensions are a (0, m, 2)-net for every m); the scramble keeps each projection's t exactly
 * (the linear matrix scramble is nonsingular lower-triangular and the shift a translation), and
 * no projection is far from a net: t <= 6 for the first 32 dimensions and t <= 5 for the
 * spread pairs, the largest values of this table (Joe and Kuo chose it for small 2-D t-values;
 * the values are printed). */
static void test_two_dimensional_nets(void **state)
{
	(void)state;
	const int m = 10;
	const size_t N = (size_t)1 << m, D = PRSM_SOBOL_MAX_DIM;
	static const size_t far[][2] = {{0, 21200}, {1, 21199}, {103, 104}, {999, 1000}, {5000, 5001},
	                                {12345, 20000}, {21000, 21200}, {51, 103}, {2047, 2048}, {40, 41}};
	/* the dimensions looked at: 0..31 and those of the spread pairs, column c of x[scramble] */
	size_t col[32 + 2 * sizeof far / sizeof far[0]], nc = 0;
	for (size_t j = 0; j < 32; j++)
		col[nc++] = j;
	for (size_t f = 0; f < sizeof far / sizeof far[0]; f++)
		for (int e = 0; e < 2; e++)
			col[nc++] = far[f][e];
	uint32_t *x[2], *point = malloc(D * sizeof *point);
	assert_non_null(point);
	for (int sc = 0; sc < 2; sc++) {
		x[sc] = malloc(N * nc * sizeof *x[sc]); /* column-major: x[c * N + i] */
		assert_non_null(x[sc]);
		prsm_sobol_seq s = seq(D, sc, 99);
		for (size_t i = 0; i < N; i++) {
			prsm_sobol_seq_next_u32(&s, point);
			for (size_t c = 0; c < nc; c++)
				x[sc][c * N + i] = point[col[c]];
		}
		prsm_sobol_seq_free(&s);
	}
	assert_int_equal(net_t(x[0], x[0] + N, m), 0);
	int worst_low = 0, worst_far = 0;
	for (size_t j = 0; j < 32; j++)
		for (size_t k = j + 1; k < 32; k++) {
			int t0 = net_t(x[0] + j * N, x[0] + k * N, m), t1 = net_t(x[1] + j * N, x[1] + k * N, m);
			assert_int_equal(t0, t1);
			worst_low = t0 > worst_low ? t0 : worst_low;
		}
	for (size_t f = 0; f < sizeof far / sizeof far[0]; f++) {
		size_t j = 32 + 2 * f, k = j + 1;
		int t0 = net_t(x[0] + j * N, x[0] + k * N, m), t1 = net_t(x[1] + j * N, x[1] + k * N, m);
		print_message("t of dimensions (%zu, %zu): %d\n", far[f][0] + 1, far[f][1] + 1, t0);
		assert_int_equal(t0, t1);
		worst_far = t0 > worst_far ? t0 : worst_far;
	}
	print_message("largest t at m = 10: %d (pairs of dimensions 1-32), %d (spread pairs)\n", worst_low,
	              worst_far);
	assert_true(worst_low <= 6);
	assert_true(worst_far <= 5);
	free(x[0]);
	free(x[1]);
	free(point);
}

/* ---- skip-ahead ------------------------------------------------------------------------------ */

/* Points from a seek to n equal the sequential points; blocks equal the same rows of a longer
 * run; near the end of the 2^32 points too; the engine's blocks do not depend on the order. */
static void test_skip_ahead(void **state)
{
	(void)state;
	const size_t D = 104, N = 5000;
	prsm_sobol_seq s = seq(D, 1, 7);
	double *all = malloc(N * D * sizeof *all), *part = malloc(N * D * sizeof *part);
	assert_non_null(all);
	assert_non_null(part);
	for (size_t i = 0; i < N; i++)
		prsm_sobol_seq_next(&s, all + i * D);
	static const size_t starts[] = {0, 1, 2, 3, 511, 512, 1023, 1024, 1025, 3000, 4095, 4999};
	for (size_t q = 0; q < sizeof starts / sizeof starts[0]; q++) {
		size_t n0 = starts[q];
		prsm_sobol_seq t = seq(D, 1, 7);
		prsm_sobol_seq_block(&t, part, N - n0, n0);
		assert_memory_equal(part, all + n0 * D, (N - n0) * D * sizeof *part);
		prsm_sobol_seq_free(&t);
	}
	/* far out: a seek to n + k equals k steps from n */
	static const uint64_t far[] = {UINT64_C(2147483645), UINT64_C(3000000000), UINT64_C(4294967280)};
	uint32_t a[104], b[104];
	for (size_t q = 0; q < sizeof far / sizeof far[0]; q++) {
		prsm_sobol_seq_seek(&s, far[q]);
		for (uint64_t k = 0; k < 15; k++) {
			prsm_sobol_seq_next_u32(&s, a);
			prsm_sobol_seq t = seq(D, 1, 7);
			prsm_sobol_seq_seek(&t, far[q] + k);
			prsm_sobol_seq_next_u32(&t, b);
			assert_memory_equal(a, b, sizeof a);
			prsm_sobol_seq_free(&t);
		}
	}
	prsm_sobol_seq_free(&s);
	/* the engine: 8 blocks of 128 rows in any order and apart equal one block of 1024 */
	assert_int_equal(prsm_mc_block_uniforms(all, 1024, D, PRSM_SAMPLER_SOBOL, 11, 0, 0, NULL), 0);
	for (size_t b8 = 8; b8-- > 0;) {
		assert_int_equal(prsm_mc_block_uniforms(part, 128, D, PRSM_SAMPLER_SOBOL, 11, b8, b8 * 128, NULL), 0);
		assert_memory_equal(part, all + b8 * 128 * D, 128 * D * sizeof *part);
	}
	free(all);
	free(part);
}

/* ---- integration in 104 dimensions ----------------------------------------------------------- */

#define INT_DIM 104

/* f1 = prod (1 + (x_i - 1/2) / i): smooth, mean 1, variance prod (1 + 1/(12 i^2)) - 1.
 * f2 = Sobol's g-function with a_i = i: prod (|4 x_i - 2| + a_i) / (1 + a_i), mean 1,
 * variance prod (1 + 1/(3 (1 + a_i)^2)) - 1 (a kink at 1/2 in every dimension). */
static double integrand(int which, const double *x)
{
	double p = 1.0;
	for (int i = 0; i < INT_DIM; i++) {
		double c = (double)(i + 1);
		p *= which == 0 ? 1.0 + (x[i] - 0.5) / c : (fabs(4.0 * x[i] - 2.0) + c) / (1.0 + c);
	}
	return p;
}

static double integrand_variance(int which)
{
	double p = 1.0;
	for (int i = 0; i < INT_DIM; i++) {
		double c = (double)(i + 1);
		p *= which == 0 ? 1.0 + 1.0 / (12.0 * c * c) : 1.0 + 1.0 / (3.0 * (1.0 + c) * (1.0 + c));
	}
	return p - 1.0;
}

/* With N = 4096 points, the root-mean-square error of the scrambled Sobol estimate over R
 * independent scrambles (seeds) against plain Monte Carlo's standard error sigma / sqrt(N)
 * (sigma exact): the QMC error must be at least 10 times smaller, i.e. worth 100 times the
 * samples of plain Monte Carlo. Plain Monte Carlo through the same engine (Philox) is
 * measured too, and must be within its own standard error's range (a check of the yardstick). */
static void test_integration_104(void **state)
{
	(void)state;
	const size_t N = 4096, R = 8;
	double *u = malloc(N * INT_DIM * sizeof *u);
	assert_non_null(u);
	for (int which = 0; which < 2; which++) {
		double se_mc = sqrt(integrand_variance(which) / (double)N);
		double ss_qmc = 0.0, ss_mc = 0.0;
		for (size_t r = 0; r < R; r++) {
			for (int smp = 0; smp < 2; smp++) {
				prsm_sampler_kind k = smp ? PRSM_SAMPLER_RANDOM : PRSM_SAMPLER_SOBOL;
				assert_int_equal(prsm_mc_block_uniforms(u, N, INT_DIM, k, 1000 + r, 0, 0, NULL), 0);
				double sum = 0.0;
				for (size_t i = 0; i < N; i++)
					sum += integrand(which, u + i * INT_DIM);
				double e = sum / (double)N - 1.0;
				if (smp)
					ss_mc += e * e;
				else
					ss_qmc += e * e;
			}
		}
		double rmse_qmc = sqrt(ss_qmc / (double)R), rmse_mc = sqrt(ss_mc / (double)R);
		print_message("%s, d = %d, N = %zu: RMS error over %zu seeds: Sobol %.3g, random %.3g; "
		              "MC standard error %.3g (ratio %.0f)\n",
		              which ? "g-function a_i = i" : "prod(1 + (x_i - 1/2)/i)", INT_DIM, N, R, rmse_qmc,
		              rmse_mc, se_mc, se_mc / rmse_qmc);
		assert_true(rmse_qmc < se_mc / 10.0);
		/* the chi-square of R squared errors: the random RMS error is within [0.3, 2] se with
		 * probability better than 1 - 1e-4 */
		assert_true(rmse_mc > 0.3 * se_mc && rmse_mc < 2.0 * se_mc);
	}
	free(u);
}

/* ---- the engine on case A ----------------------------------------------------------------- */

/* studies/case-a-tolerances.json (52 variables) with sampler sobol for both the Monte Carlo run
 * and the Saltelli design (104 dimensions): no fallback, no warning about it, and the same
 * bits for 1 and 2 threads. Sample counts are cut to keep the test fast. */
static void test_case_a_sobol_threads(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("case-a-tolerances.json");
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems pr;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_study_load(s, doc, NULL, &pr), 0);
	cJSON_Delete(doc);
	assert_int_equal(s->study.d, 52);
	s->study.mc.sampler = PRSM_SAMPLER_SOBOL;
	s->study.mc.samples = 256;
	s->study.mc.block_size = 32;
	s->study.mc.n_targets = 0;
	s->study.sens.sobol = 1;
	s->study.sens.sobol_sampler = PRSM_SAMPLER_SOBOL;
	s->study.sens.sobol_samples = 128;
	s->study.sens.bootstrap = 20;
	prsm_study_result *r[2];
	for (int k = 0; k < 2; k++) {
		prsm_error err = PRSM_ERROR_INIT;
		r[k] = calloc(1, sizeof *r[k]);
		assert_non_null(r[k]);
		s->study.mc.threads = k + 1;
		int rc = prsm_study_run(r[k], &s->study, &err);
		if (rc)
			fail_msg("%s", err.message);
		assert_int_equal(r[k]->run.sampler, PRSM_SAMPLER_SOBOL);
		assert_int_equal(r[k]->sobol_sampler, PRSM_SAMPLER_SOBOL);
		assert_int_equal(r[k]->sobol_rows, 128);
		assert_string_equal(r[k]->run.warning, "");
		for (int w = 0; w < r[k]->n_warnings; w++)
			assert_null(strstr(r[k]->warnings[w], "Sobol sampling"));
	}
	const prsm_mc_result *a = &r[0]->run, *b = &r[1]->run;
	assert_int_equal(a->n, 256);
	assert_int_equal(b->n, a->n);
	assert_memory_equal(a->x, b->x, a->n * a->d * sizeof *a->x);
	assert_memory_equal(a->y, b->y, a->n * a->m * sizeof *a->y);
	for (size_t o = 0; o < s->study.m; o++) {
		assert_true(r[0]->out[o].has_sobol);
		assert_memory_equal(&r[0]->out[o].sobol_variance, &r[1]->out[o].sobol_variance, sizeof(double));
		for (size_t g = 0; g < s->study.n_groups; g++)
			assert_memory_equal(&r[0]->out[o].by_group[g].sobol, &r[1]->out[o].by_group[g].sobol,
			                    sizeof(prsm_sobol_index));
	}
	for (int k = 0; k < 2; k++) {
		prsm_study_result_free(r[k]);
		free(r[k]);
	}
	free(s);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_known_points),
		cmocka_unit_test(test_limits),
		cmocka_unit_test(test_one_dimensional_strata),
		cmocka_unit_test(test_two_dimensional_nets),
		cmocka_unit_test(test_skip_ahead),
		cmocka_unit_test(test_integration_104),
		cmocka_unit_test(test_case_a_sobol_threads),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
