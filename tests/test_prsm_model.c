/*
 * test_prsm_model.c: the Monte Carlo model of a roller screw (mc/prsm_model.h). Its workspace
 * prepares the friction-independent part of the losses once (model/losses.h,
 * prsm_losses_prepare); every sample's efficiency_with_losses must still be, bit for bit, what
 * prsm_losses_compute gives for the sample's friction, and its errors the same.
 */
#include "test_support.h"

#include "mc/prsm_model.h"
#include "model/analysis.h"
#include "model/efficiency.h"
#include "model/losses.h"
#include "model/performance.h"

typedef struct {
	prsm_design d;
	prsm_analysis an;
	prsm_assembly *as;
	prsm_performance perf;
	prsm_mc_binding bindings[2];
	prsm_mc_prsm p;
} fixture;

static void setup_case_a(fixture *f, int gear_teeth_roller, int gear_teeth_ring)
{
	memset(f, 0, sizeof *f);
	case_a(&f->d);
	f->d.axial_load_N = 7000.0;
	f->d.screw_speed_rad_s = 100.0;
	f->d.losses.roller_gear_teeth = gear_teeth_roller;
	f->d.losses.ring_gear_teeth = gear_teeth_ring;
	prsm_problems w;
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(&f->an, &f->d, &w, NULL), 0);
	f->as = calloc(1, sizeof *f->as);
	assert_non_null(f->as);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_assembly_init(f->as, &f->d, &f->an, &err), 0);
	/* friction tolerances: screw-roller and nut-roller mu, scale 1 */
	f->bindings[0] = (prsm_mc_binding){PRSM_PART_FRICTION, 0, 0, 1.0};
	f->bindings[1] = (prsm_mc_binding){PRSM_PART_FRICTION, 0, 1, 1.0};
	f->p.as = f->as;
	f->p.an = &f->an;
	f->p.mode = PRSM_MODE_LINEAR;
	f->p.angles_per_revolution = 16;
	f->p.measuring_load_N = 50.0;
	f->p.n_bindings = 2;
	f->p.bindings = f->bindings;
	f->p.n_outputs = 2;
	f->p.outputs[0] = PRSM_OUT_EFFICIENCY_LOSSES;
	f->p.outputs[1] = PRSM_OUT_EFFICIENCY;
}

static void teardown(fixture *f)
{
	if (f->p.loss_screw_loads_N)
		prsm_performance_free(&f->perf);
	free(f->as);
}

static uint64_t splitmix64(uint64_t *s)
{
	uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
	return z ^ (z >> 31);
}

static int same_bits(double a, double b)
{
	return memcmp(&a, &b, sizeof a) == 0;
}

/* Samples against prsm_losses_compute at the same friction, with the nominal load distribution
 * (as the study loader sets it) or the equal share. */
static void check_samples(fixture *f)
{
	prsm_mc_model m;
	prsm_prsm_mc_model(&m, &f->p);
	void *ws = NULL;
	assert_int_equal(m.workspace_alloc(&ws, m.ctx), 0);
	prsm_losses_options o;
	prsm_losses_options_from_design(&o, &f->as->design);
	uint64_t seed = 0xE7A5ull;
	for (int i = 0; i < 200; i++) {
		/* offsets in [-0.05, 0.25): some negative coefficients, some wedged flanks */
		double x[2];
		for (int k = 0; k < 2; k++)
			x[k] = -0.05 + 0.3 * (double)(splitmix64(&seed) >> 11) * 0x1.0p-53;
		double y[2] = {NAN, NAN};
		unsigned flags = 0;
		int rc = m.eval(y, &flags, m.ctx, ws, x);
		prsm_design e = f->as->design;
		e.mu_screw_roller += x[0] * 1.0;
		e.mu_nut_roller += x[1] * 1.0;
		if (!(e.mu_screw_roller >= 0.0) || !(e.mu_nut_roller >= 0.0)) {
			assert_int_equal(rc, PRSM_EINVAL);
			continue;
		}
		prsm_losses_result r;
		prsm_error err = PRSM_ERROR_INIT;
		int rc_direct = prsm_losses_compute(&r, &e, &f->an.kinematics, &f->an.screw, &f->an.nut,
		                                    f->p.loss_screw_loads_N, f->p.loss_nut_loads_N, &o, &err);
		assert_int_equal(rc, rc_direct);
		if (rc)
			continue;
		prsm_efficiency eff;
		prsm_efficiency_sliding(&eff, &e, &f->an.kinematics, &f->an.screw, &f->an.nut);
		if (!same_bits(y[0], r.eta) || !same_bits(y[1], eff.eta)) {
			print_error("sample %d (mu %.17g, %.17g): %.17g vs %.17g, %.17g vs %.17g\n", i,
			            e.mu_screw_roller, e.mu_nut_roller, y[0], r.eta, y[1], eff.eta);
			fail();
		}
	}
	m.workspace_free(ws);
}

static void test_losses_samples_bit_identical(void **state)
{
	(void)state;
	fixture *f = calloc(1, sizeof *f);
	assert_non_null(f);
	/* equal share of the load */
	setup_case_a(f, 0, 0);
	check_samples(f);
	/* the nominal load distribution, as prsm study has it */
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_performance_compute(&f->perf, &f->d, &f->an, &err), 0);
	assert_int_equal(f->perf.threads, f->d.engaged_threads);
	f->p.loss_screw_loads_N = f->perf.thread_normal_screw_N;
	f->p.loss_nut_loads_N = f->perf.thread_normal_nut_N;
	check_samples(f);
	teardown(f);
	/* gears that disagree with the threads (PRSM_LOSSES_GEAR_RATIO): still computed */
	setup_case_a(f, 19, 0);
	check_samples(f);
	teardown(f);
	free(f);
}

/* An error of the prepared part (no internal mesh: z_2 = z_1) fails every sample as before. */
static void test_losses_error_every_sample(void **state)
{
	(void)state;
	fixture *f = calloc(1, sizeof *f);
	assert_non_null(f);
	setup_case_a(f, 40, 40);
	prsm_mc_model m;
	prsm_prsm_mc_model(&m, &f->p);
	void *ws = NULL;
	assert_int_equal(m.workspace_alloc(&ws, m.ctx), 0);
	for (int i = 0; i < 3; i++) {
		const double x[2] = {0.01 * i, 0.0};
		double y[2];
		unsigned flags;
		assert_int_equal(m.eval(y, &flags, m.ctx, ws, x), PRSM_EINVAL);
	}
	/* without efficiency_with_losses the same design samples fine */
	f->p.n_outputs = 1;
	f->p.outputs[0] = PRSM_OUT_EFFICIENCY;
	void *ws2 = NULL;
	assert_int_equal(m.workspace_alloc(&ws2, m.ctx), 0);
	const double x[2] = {0.0, 0.0};
	double y[2];
	unsigned flags;
	assert_int_equal(m.eval(y, &flags, m.ctx, ws2, x), 0);
	assert_true(y[0] > 0.8 && y[0] < 1.0);
	m.workspace_free(ws2);
	m.workspace_free(ws);
	teardown(f);
	free(f);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_losses_samples_bit_identical),
		cmocka_unit_test(test_losses_error_every_sample),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
