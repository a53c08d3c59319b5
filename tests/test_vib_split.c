/*
 * test_vib_split.c: a sweep's and a basin grid's tasks spread over parts (dyn/vib.h
 * prsm_vib_split, what src/par does over the ranks of an MPI job), without MPI: the parts run one
 * after the other in this process, the exchange keeping each part's buffer and handing part 0
 * (run last) all of them. Part 0's result is the whole run's, byte for byte, for 2 and 3 parts
 * (a continuation sweep up and down, independent points up and down, a basin grid); the other
 * parts return empty results; a part's failure ends part 0's run naming it; every part exchanges
 * exactly once.
 */
#include "test_support.h"

#include "dyn/vib.h"
#include "io/global.h"

#define PARTS_MAX 4

static int same_bytes(const void *a, const void *b, size_t n)
{
	return memcmp(a, b, n) == 0;
}

typedef struct {
	int parts;
	prsm_vib_share kept[PARTS_MAX];
	int calls[PARTS_MAX];
	int fail_part;               /* this part's buffer replaced by a failure (-1: none) */
	int current;                 /* the part running */
} fake_exchange;

static int exchange(void *ctx, const void *mine, size_t len, prsm_vib_share *shares, prsm_error *err)
{
	(void)err;
	fake_exchange *f = ctx;
	const int p = f->current;
	f->calls[p]++;
	prsm_vib_share_head h;
	if (p == f->fail_part) {
		memset(&h, 0, sizeof h);
		h.code = PRSM_EIO;
		snprintf(h.message, sizeof h.message, "a test failure");
		mine = &h;
		len = sizeof h;
	}
	f->kept[p].data = malloc(len ? len : 1);
	assert_non_null(f->kept[p].data);
	memcpy(f->kept[p].data, mine, len);
	f->kept[p].len = len;
	if (p == 0)
		for (int q = 0; q < f->parts; q++) {
			shares[q] = f->kept[q];
			f->kept[q].data = NULL;
		}
	return 0;
}

static prsm_vib_model *gear_pair(double eps, double Omega)
{
	prsm_vib_gear_pair g = PRSM_VIB_GEAR_PAIR_INIT;
	g.damping_ratio = 0.05;
	g.mean_force = 0.1;
	g.mesh_error = eps;
	g.frequency_ratio = Omega;
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_gear_pair_new(&m, &g, &err), 0);
	return m;
}

/* The sweep of so over `parts` parts (run 1 .. parts-1, then 0) into *out (part 0's). */
static int split_sweep(prsm_vib_sweep *out, const prsm_vib_model *m, prsm_vib_sweep_options so, int parts,
                       int fail_part, prsm_error *err)
{
	fake_exchange f;
	memset(&f, 0, sizeof f);
	f.parts = parts;
	f.fail_part = fail_part;
	prsm_vib_split sp = {parts, 0, exchange, &f};
	so.split = &sp;
	for (int p = parts - 1; p >= 1; p--) {
		prsm_vib_sweep mine;
		sp.part = f.current = p;
		assert_int_equal(prsm_vib_sweep_run(&mine, m, &so, NULL, NULL, NULL, err), 0);
		assert_int_equal(mine.points, 0); /* a follower's result is empty */
		assert_null(mine.point);
		prsm_vib_sweep_free(&mine);
	}
	sp.part = f.current = 0;
	int rc = prsm_vib_sweep_run(out, m, &so, NULL, NULL, NULL, err);
	for (int p = 0; p < parts; p++)
		assert_int_equal(f.calls[p], 1);
	return rc;
}

static void same_sweep(const prsm_vib_sweep *a, const prsm_vib_sweep *b)
{
	assert_int_equal(a->points, b->points);
	assert_int_equal(a->recorded, b->recorded);
	assert_int_equal(a->states, b->states);
	assert_true(same_bytes(a->point, b->point, a->points * sizeof *a->point));
	assert_true(same_bytes(a->poincare, b->poincare, a->points * (size_t)a->recorded * sizeof(double)));
	assert_true(same_bytes(a->end_state, b->end_state, a->points * (size_t)a->states * sizeof(double)));
	assert_true(same_bytes(&a->effort, &b->effort, sizeof a->effort));
	assert_string_equal(a->first_error, b->first_error);
}

static void test_sweeps(void **state)
{
	(void)state;
	prsm_vib_model *m = gear_pair(0.2, 1.0);
	prsm_vib_sweep_options so;
	prsm_vib_sweep_options_init(&so);
	so.from = 0.6;
	so.to = 1.4;
	so.step = 0.1;
	so.steady.transient_periods = 60;
	so.steady.recorded_periods = 16;
	prsm_error err = PRSM_ERROR_INIT;
	for (int cont = 1; cont >= 0; cont--) {
		so.continuation = cont;
		prsm_vib_sweep whole;
		assert_int_equal(prsm_vib_sweep_run(&whole, m, &so, NULL, NULL, NULL, &err), 0);
		for (int parts = 2; parts <= 3; parts++) {
			prsm_vib_sweep s;
			assert_int_equal(split_sweep(&s, m, so, parts, -1, &err), 0);
			same_sweep(&whole, &s);
			prsm_vib_sweep_free(&s);
		}
		/* the up direction alone (one task: the second and third parts compute nothing) */
		so.down = 0;
		prsm_vib_sweep up, s;
		assert_int_equal(prsm_vib_sweep_run(&up, m, &so, NULL, NULL, NULL, &err), 0);
		assert_int_equal(split_sweep(&s, m, so, 3, -1, &err), 0);
		same_sweep(&up, &s);
		prsm_vib_sweep_free(&s);
		prsm_vib_sweep_free(&up);
		so.down = 1;
		prsm_vib_sweep_free(&whole);
	}
	/* a part that fails ends part 0's sweep, naming it */
	prsm_vib_sweep s;
	assert_int_equal(split_sweep(&s, m, so, 3, 2, &err), PRSM_EIO);
	assert_non_null(strstr(err.message, "rank 2 of 3 failed: a test failure"));
	assert_null(s.point);
	prsm_vib_model_free(m);
}

static int split_basins(prsm_vib_basins *out, const prsm_vib_model *m, prsm_vib_basin_options bo, int parts,
                        int fail_part, prsm_error *err)
{
	fake_exchange f;
	memset(&f, 0, sizeof f);
	f.parts = parts;
	f.fail_part = fail_part;
	prsm_vib_split sp = {parts, 0, exchange, &f};
	bo.split = &sp;
	for (int p = parts - 1; p >= 1; p--) {
		prsm_vib_basins mine;
		sp.part = f.current = p;
		assert_int_equal(prsm_vib_basins_run(&mine, m, &bo, NULL, NULL, NULL, err), 0);
		assert_null(mine.label);
		prsm_vib_basins_free(&mine);
	}
	sp.part = f.current = 0;
	int rc = prsm_vib_basins_run(out, m, &bo, NULL, NULL, NULL, err);
	for (int p = 0; p < parts; p++)
		assert_int_equal(f.calls[p], 1);
	return rc;
}

static void test_basins(void **state)
{
	(void)state;
	/* epsilon 0.02, Omega 0.90: two coexisting orbits */
	prsm_vib_model *m = gear_pair(0.02, 0.9);
	prsm_vib_basin_options bo;
	prsm_vib_basin_options_init(&bo);
	bo.nx = 7;
	bo.nv = 5;
	bo.x_min = 0.8;
	bo.x_max = 1.4;
	bo.v_min = -0.3;
	bo.v_max = 0.3;
	bo.periods = 40;
	bo.identify_periods = 8;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_vib_basins whole;
	assert_int_equal(prsm_vib_basins_run(&whole, m, &bo, NULL, NULL, NULL, &err), 0);
	assert_true(whole.attractors >= 2);
	for (int parts = 2; parts <= 3; parts++) {
		prsm_vib_basins b;
		assert_int_equal(split_basins(&b, m, bo, parts, -1, &err), 0);
		assert_int_equal(b.attractors, whole.attractors);
		assert_true(same_bytes(b.label, whole.label, 35 * sizeof(int)));
		for (int a = 0; a < b.attractors; a++) {
			assert_int_equal(b.attractor[a].period, whole.attractor[a].period);
			assert_int_equal(b.attractor[a].cells, whole.attractor[a].cells);
			assert_true(same_bytes(b.attractor[a].poincare, whole.attractor[a].poincare,
			                       (size_t)b.attractor[a].period * (size_t)b.poincare_size * sizeof(double)));
		}
		assert_true(same_bytes(&b.effort, &whole.effort, sizeof b.effort));
		assert_int_equal(b.other, whole.other);
		assert_int_equal(b.failed, whole.failed);
		prsm_vib_basins_free(&b);
	}
	prsm_vib_basins b;
	assert_int_equal(split_basins(&b, m, bo, 2, 1, &err), PRSM_EIO);
	assert_non_null(strstr(err.message, "rank 1 of 2 failed: a test failure"));
	prsm_vib_basins_free(&whole);
	prsm_vib_model_free(m);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_sweeps),
		cmocka_unit_test(test_basins),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
