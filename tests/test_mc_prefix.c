/*
 * test_mc_prefix.c: the engine's prefix merge (prsm_mc_prefix_*, src/mc/engine.h), by which a
 * run split over processes (src/par, MPI) decides where to stop. A run computed without its stop
 * rules and fed back block by block must stop exactly where prsm_mc_run with those rules stops:
 * a stop target, the failure policy `abort` (with the same error naming the same sample) and
 * `skip` beyond the allowed failed fraction (issue 20).
 */
#include "test_support.h"

#include <string.h>

#include "mc/bench_models.h"
#include "mc/engine.h"

/* Fails when x0 > 0.9 (a tenth of the samples), flags an edge contact when x0 < 0.05. */
static int flaky_eval(double *y, unsigned *flags, const void *ctx, void *ws, const double *x)
{
	(void)ctx;
	(void)ws;
	*flags = x[0] < 0.05 ? PRSM_MC_FLAG_EDGE : 0;
	if (x[0] > 0.9)
		return PRSM_ENOCONVERGE;
	y[0] = x[0] + 2.0 * x[1];
	return 0;
}

static void uniform_vars(prsm_mc_variable *v, size_t d, double lo, double hi)
{
	for (size_t i = 0; i < d; i++) {
		v[i].dist.kind = PRSM_DIST_UNIFORM;
		v[i].dist.p[0] = lo;
		v[i].dist.p[1] = hi;
		v[i].group = (int)i;
	}
}

/* Feed the blocks of full (a run of the same seed without stop rules) to a prefix under the
 * options o until it says stop; *rows the rows merged. Returns the prefix's verdict (1: stop). */
static int replay(prsm_mc_prefix *p, const prsm_mc_result *full, const prsm_mc_options *o, size_t m,
                  prsm_stop_reason *stop, int *code, prsm_error *err)
{
	const size_t B = o->block_size, total = (o->samples + B - 1) / B;
	prsm_mc_prefix_init(p);
	for (size_t row = 0; row < full->n; row += B) {
		size_t nb = full->n - row < B ? full->n - row : B;
		if (prsm_mc_prefix_add(p, o, m, total, full->y + row * m, full->status + row, full->fail_code + row, nb, stop,
		                       code, err))
			return 1;
	}
	return 0;
}

/* A stop target (Ishigami, standard error of the mean <= 0.05): the prefix stops at the block
 * prsm_mc_run stops at, with the same counts. */
static void test_target(void **state)
{
	(void)state;
	prsm_bench_model b;
	memset(&b, 0, sizeof b);
	b.kind = PRSM_BENCH_ISHIGAMI;
	b.inputs = 3;
	b.a = 7.0;
	b.b = 0.1;
	prsm_mc_model mdl;
	prsm_bench_mc_model(&mdl, &b);
	prsm_mc_variable v[3];
	uniform_vars(v, 3, -M_PI, M_PI);
	for (int k = 0; k < 2; k++) {
		prsm_mc_options o;
		prsm_mc_options_default(&o);
		o.seed = 7 + (uint64_t)k;
		o.samples = 1000000;
		o.block_size = k ? 300 : 512; /* 300: blocks that do not divide the sample cap */
		o.n_targets = 1;
		o.targets[0].kind = PRSM_TARGET_SE;
		o.targets[0].output = 0;
		o.targets[0].value = 0.05;
		prsm_error err = PRSM_ERROR_INIT;
		prsm_mc_result want, full;
		assert_int_equal(prsm_mc_run(&want, &mdl, v, 3, NULL, 0, &o, &err), 0);
		assert_int_equal(want.stop, PRSM_STOP_TARGET);
		prsm_mc_options of = o;
		of.n_targets = 0;
		of.samples = want.n + 20 * o.block_size;
		assert_int_equal(prsm_mc_run(&full, &mdl, v, 3, NULL, 0, &of, &err), 0);
		prsm_mc_prefix p;
		prsm_stop_reason stop = PRSM_STOP_SAMPLE_CAP;
		int code = -1;
		assert_int_equal(replay(&p, &full, &o, 1, &stop, &code, &err), 1);
		assert_int_equal(stop, PRSM_STOP_TARGET);
		assert_int_equal(code, 0);
		assert_int_equal(p.rows, want.n);
		prsm_mc_result fin;
		memset(&fin, 0, sizeof fin);
		prsm_mc_prefix_finish(&fin, &p, &o, stop);
		assert_int_equal(fin.n, want.n);
		assert_int_equal(fin.n_ok, want.n_ok);
		assert_int_equal(fin.n_failed, want.n_failed);
		assert_int_equal(fin.stop, want.stop);
		assert_int_equal(fin.converged, want.converged);
		/* the same rows: the split run's outputs are the single run's */
		assert_memory_equal(full.y, want.y, want.n * sizeof *want.y);
		prsm_mc_result_free(&want);
		prsm_mc_result_free(&full);
	}
}

/* The failure policy: abort stops at the block of the first failed sample with prsm_mc_run's
 * code and message; skip stops where the failed fraction exceeds the limit. */
static void test_failures(void **state)
{
	(void)state;
	prsm_mc_model mdl = {1, NULL, NULL, NULL, flaky_eval};
	prsm_mc_variable v[2];
	uniform_vars(v, 2, 0.0, 1.0);
	for (int policy = 0; policy < 2; policy++) {
		prsm_mc_options o;
		prsm_mc_options_default(&o);
		o.seed = 11;
		o.samples = 20000;
		o.block_size = 256;
		o.failure = policy ? PRSM_FAILURE_ABORT : PRSM_FAILURE_SKIP;
		o.max_failed_fraction = 0.05; /* a tenth fail: skip stops too */
		prsm_error e1 = PRSM_ERROR_INIT, e2 = PRSM_ERROR_INIT;
		prsm_mc_result want, full;
		int rc = prsm_mc_run(&want, &mdl, v, 2, NULL, 0, &o, &e1);
		prsm_mc_options of = o;
		of.failure = PRSM_FAILURE_SKIP;
		of.max_failed_fraction = 1.0;
		assert_int_equal(prsm_mc_run(&full, &mdl, v, 2, NULL, 0, &of, &e2), 0);
		prsm_mc_prefix p;
		prsm_stop_reason stop = PRSM_STOP_SAMPLE_CAP;
		int code = 0;
		prsm_error e3 = PRSM_ERROR_INIT;
		assert_int_equal(replay(&p, &full, &o, 1, &stop, &code, &e3), 1);
		assert_int_equal(stop, PRSM_STOP_FAILURES);
		if (policy) {
			/* abort: the run's error, naming the same sample */
			assert_int_equal(rc, PRSM_ENOCONVERGE);
			assert_int_equal(code, rc);
			assert_string_equal(e3.message, e1.message);
			size_t first = 0;
			while (full.status[first] != PRSM_SAMPLE_FAILED)
				first++;
			assert_int_equal(p.rows, (first / 256 + 1) * 256);
		} else {
			assert_int_equal(rc, 0);
			assert_int_equal(code, 0);
			assert_int_equal(want.stop, PRSM_STOP_FAILURES);
			prsm_mc_result fin;
			memset(&fin, 0, sizeof fin);
			prsm_mc_prefix_finish(&fin, &p, &o, stop);
			assert_int_equal(fin.n, want.n);
			assert_int_equal(fin.n_failed, want.n_failed);
			assert_int_equal(fin.n_edge, want.n_edge);
			assert_int_equal(fin.stop, want.stop);
			prsm_mc_result_free(&want);
		}
		prsm_mc_result_free(&full);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_target),
		cmocka_unit_test(test_failures),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
