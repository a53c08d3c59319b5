/*
 * test_dyn_support.h: fixtures of the dynamics tests (tests/test_dyn_*.c): case A and seed 000's
 * two-stage screw as the statics engine analyses them, the options of validation case V1
 * (docs/model §8.8), and a model built from them.
 */
#ifndef PRSM_TEST_DYN_SUPPORT_H
#define PRSM_TEST_DYN_SUPPORT_H

#include "test_support.h"

#include "dyn/dyn.h"
#include "io/global.h"
#include "model/analysis.h"

/* The nominal analysis of a resolved design; fails the test on an error. */
static inline void dyn_test_analyse(prsm_analysis *a, prsm_design *d)
{
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_analysis_nominal(a, d, &w, &err)) {
		print_error("analysis: %s\n", err.message);
		fail();
	}
}

/* Case A (docs/model/geometry-and-meshing.md), 10 rollers and threads, analysed. */
static inline void dyn_case_a(prsm_design *d, prsm_analysis *a, double mu)
{
	case_a(d);
	d->mu_screw_roller = mu;
	d->axial_load_N = 7000.0;
	d->screw_speed_rad_s = 100.0;
	dyn_test_analyse(a, d);
}

/* Seed 000's two stages (shared/reference/seed000-two-stage.json): r_r 3.25 and 5.5 mm, 5 starts,
 * pitch 2, 45 deg, 7 rollers, 10 threads assumed, mu 0.05 screw-roller, 0 nut-roller. */
static inline void dyn_seed000(prsm_design d[2], prsm_analysis a[2])
{
	const double rr[2] = {3.25, 5.5};
	for (int k = 0; k < 2; k++) {
		standard_design(&d[k], 5, 2.0, rr[k], 45.0, 7, 10);
		d[k].mu_screw_roller = 0.05;
		d[k].mu_nut_roller = 0.0;
		d[k].thinning_rule = PRSM_THINNING_EQUAL_GAPS;
		d[k].target_axial_clearance_mm = 0.02;
		d[k].axial_load_N = 7000.0;
		d[k].screw_speed_rad_s = 100.0;
		dyn_test_analyse(&a[k], &d[k]);
	}
}

/* Seed 000's masses and inertias (kg, kg mm^2 in the table) into the options. */
static inline void dyn_seed000_inertia(prsm_dyn_options *o)
{
	const double mR[2] = {0.014, 0.039}, mS[2] = {0.761, 0.761}, mN[2] = {2.2, 20.0};
	const double JS[2] = {51.94, 172.3}, JR[2] = {0.077, 0.471}, JC[2] = {2.95, 19.88};
	for (int k = 0; k < 2; k++) {
		prsm_dyn_stage_inertia *s = &o->inertia.stage[k];
		s->roller_mass_kg = mR[k];
		s->screw_mass_kg = mS[k];
		s->nut_mass_kg = mN[k];
		s->screw_inertia_kg_m2 = JS[k] * 1e-6;
		s->roller_inertia_kg_m2 = JR[k] * 1e-6;
		s->carrier_inertia_kg_m2 = JC[k] * 1e-6;
	}
}

/* V1 (docs/model §8.8): viscous 25 N s/m per roller, a step to 1 rad/s, 100 N, sliding only. */
static inline void dyn_v1_options(prsm_dyn_options *o)
{
	prsm_dyn_options_init(o);
	o->input.signal.value = 1.0;
	o->load.value = 100.0;
	o->friction.model = PRSM_DYN_FRICTION_VISCOUS;
	o->friction.viscous_N_s_per_m = 25.0;
	o->losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	o->time.end_s = 1e-3;
	o->time.output_step_s = 1e-5;
}

/* A model; fails the test on an error. The caller frees it. */
static inline prsm_dyn_model *dyn_test_model(int stages, const prsm_design *d, const prsm_analysis *a,
                                             const prsm_dyn_options *o)
{
	prsm_dyn_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_dyn_model_new(&m, stages, d, a, o, &err);
	if (rc) {
		print_error("model: %s (%s) at %s\n", err.message, prsm_error_name(rc), err.pointer);
		fail();
	}
	return m;
}

/* A simulation; fails the test on an error. The caller frees the result. */
static inline void dyn_test_simulate(prsm_dyn_result *r, const prsm_dyn_model *m)
{
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_dyn_simulate(r, m, NULL, NULL, NULL, &err);
	if (rc) {
		print_error("simulate: %s (%s)\n", err.message, prsm_error_name(rc));
		fail();
	}
}

/* |actual - expected| <= rel |expected| */
#define assert_rel(actual, expected, rel)                                                         \
	do {                                                                                          \
		double e2_ = (expected);                                                                  \
		assert_close((actual), e2_, (rel) * fabs(e2_));                                           \
	} while (0)

#endif
