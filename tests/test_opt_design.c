/*
 * test_opt_design.c: the PRSM design problem (src/opt/design_problem.h) through the generic
 * optimiser: the 4-variable search over starts 3-6, pitch, roller radius and Z up to Z_max on
 * case A's operating point; every returned design re-analysed (prsm_performance_compute) and
 * feasible; pruning; determinism; the weighted sum and the Pareto front (efficiency against
 * stiffness) non-dominated and sorted, each point's design re-analysed.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "model/analysis.h"
#include "io/global.h"
#include "model/performance.h"
#include "opt/design_problem.h"
#include "opt/pareto.h"
#include "util/clock.h"

/* Case A's settings, unresolved: the optimiser varies the geometry. */
static void base_design(prsm_design *d)
{
	prsm_design_init(d);
	d->starts = 5;
	d->pitch_mm = 2.0;
	d->roller_radius_mm = 3.25;
	d->rollers = 10;
	d->engaged_threads = 10;
	d->target_axial_clearance_mm = 0.020;
	d->axial_load_N = 7000.0;
	d->screw_speed_rad_s = 100.0;
}

static void spec_four(prsm_dp_spec *s, int objective)
{
	prsm_design base;
	base_design(&base);
	prsm_dp_spec_init(s, &base);
	s->starts.count = 4;
	for (int i = 0; i < 4; i++)
		s->starts.values[i] = 3 + i;
	s->pitch.vary = 1;
	s->pitch.min = 1.0;
	s->pitch.max = 3.0;
	s->radius.vary = 1;
	s->radius.min = 2.5;
	s->radius.max = 5.0;
	int zmax = 0;
	for (int n = 3; n <= 6; n++) {
		int z = prsm_dp_z_max_bound(s, n);
		zmax = z > zmax ? z : zmax;
	}
	s->rollers.count = 0;
	for (int z = 3; z <= zmax; z++)
		s->rollers.values[s->rollers.count++] = z;
	s->n_objectives = 1;
	s->objective[0] = objective;
	s->static_safety_min = 2.5;
	s->life_min_h = 2000.0;
	s->nut_outer_diameter_max_mm = 50.0;
}

/* Re-analyse the design at (x, levels) from scratch and check every constraint against its raw
 * limit (the optimiser's feasibility has no tolerance). */
static void reanalyse_feasible(const prsm_dp_spec *s, const double *x, const double *levels,
                               const double *objectives)
{
	prsm_design d;
	prsm_dp_design_at(&d, s, x, levels);
	prsm_problems e, w;
	prsm_problems_init(&e);
	prsm_problems_init(&w);
	assert_int_equal(prsm_design_resolve(&d, &e), 0);
	prsm_geometry g;
	assert_int_equal(prsm_geometry_check(&g, &w, &e, &d), 0);
	assert_true(d.rollers <= g.z_max);
	assert_int_equal(w.count, 0);
	prsm_analysis a;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_analysis_nominal(&a, &d, &w, &err), 0);
	prsm_performance perf;
	assert_int_equal(prsm_performance_compute(&perf, &d, &a, &err), 0);
	assert_true(perf.static_safety >= s->static_safety_min);
	assert_true(perf.life.hours >= s->life_min_h);
	double od = 2.0 * prsm_compliance_nut_outer_radius_mm(d.nut_outer_radius_mm, &d);
	assert_true(od <= s->nut_outer_diameter_max_mm);
	for (int k = 0; k < s->n_objectives; k++) {
		if (s->objective[k] == PRSM_DP_EFFICIENCY)
			assert_close(objectives[k], perf.losses.eta, 1e-12);
		if (s->objective[k] == PRSM_DP_STIFFNESS)
			assert_close(objectives[k], perf.stiffness_N_per_um, 1e-9);
	}
	prsm_performance_free(&perf);
}

static void run_four(prsm_opt_result *r, prsm_dp_spec *s, int objective, size_t budget)
{
	spec_four(s, objective);
	prsm_opt_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dp_problem(&p, s, &err), 0);
	prsm_opt_options o;
	prsm_opt_options_init(&o);
	o.max_evaluations = budget;
	o.multistart = 1;
	o.xtol_rel = 1e-4;
	o.ftol_rel = 1e-6;
	double t0 = prsm_clock_seconds();
	assert_int_equal(prsm_opt_run(r, &p, &o, &err), 0);
	print_message("%s: %.6g at n=%g Z=%g P=%.4f r_r=%.4f; %zu evaluations, %zu of %zu combinations "
	              "pruned, %zu runs (%zu feasible), %.3f s\n",
	              prsm_dp_objective_names[objective], r->objectives[0], r->levels[0], r->levels[1],
	              r->x[0], r->x[1], r->evaluations, r->pruned, r->combinations, r->runs,
	              r->runs_feasible, prsm_clock_seconds() - t0);
}

static void test_four_variables(void **state)
{
	(void)state;
	prsm_dp_spec s;
	prsm_opt_result r;
	run_four(&r, &s, PRSM_DP_STIFFNESS, 1500);
	assert_int_equal(r.status, PRSM_OPT_FEASIBLE);
	assert_true(r.pruned > 0);
	reanalyse_feasible(&s, r.x, r.levels, r.objectives);
	run_four(&r, &s, PRSM_DP_EFFICIENCY, 1500);
	assert_int_equal(r.status, PRSM_OPT_FEASIBLE);
	reanalyse_feasible(&s, r.x, r.levels, r.objectives);
}

/* Same input and seed: bit-identical results. */
static void test_determinism(void **state)
{
	(void)state;
	prsm_dp_spec s;
	prsm_opt_result r[2];
	run_four(&r[0], &s, PRSM_DP_STIFFNESS, 600);
	run_four(&r[1], &s, PRSM_DP_STIFFNESS, 600);
	assert_memory_equal(r[0].x, r[1].x, sizeof r[0].x);
	assert_memory_equal(r[0].levels, r[1].levels, sizeof r[0].levels);
	assert_memory_equal(r[0].objectives, r[1].objectives, sizeof r[0].objectives);
	assert_memory_equal(r[0].constraints, r[1].constraints, sizeof r[0].constraints);
	assert_int_equal(r[0].evaluations, r[1].evaluations);
}

/* Pruning never drops a combination that has a feasible point: the Z above each start count's
 * bound cannot fit at any corner, and each pruned (n, Z) fails the fit at the box's best corner. */
static void test_pruning(void **state)
{
	(void)state;
	prsm_dp_spec s;
	spec_four(&s, PRSM_DP_STIFFNESS);
	prsm_opt_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), 0);
	for (int n = 3; n <= 6; n++) {
		int zb = prsm_dp_z_max_bound(&s, n);
		assert_true(zb >= 3);
		for (int z = 3; z <= zb + 1; z++) {
			double lv[2] = {n, z};
			int pruned = p.prune(p.ctx, lv, p.lower, p.upper);
			/* the nut OD limit may prune more; never less than Z > bound */
			if (z > zb)
				assert_int_equal(pruned, 1);
			if (!pruned) {
				/* a corner with the largest roller radius fits z rollers */
				double x[2] = {p.lower[0], p.upper[1]};
				prsm_design d;
				prsm_dp_design_at(&d, &s, x, lv);
				prsm_problems e;
				prsm_problems_init(&e);
				prsm_design_resolve(&d, &e);
				assert_true(z <= prsm_geometry_z_max(d.roller_crest_radius_mm, d.running_clearance_mm,
				                                     d.screw_radius_mm + d.roller_radius_mm));
			}
		}
	}
}

/* The constraints' violations judge the raw limits: the roller fit by the integer Z_max (Z_max + 1
 * rollers violate it however close Z asin(s)/pi is to 1; Z_max rollers meet it), the pass/fail
 * ones -1 when met; each g <= 0 exactly when the figure meets its limit. */
static void test_violation(void **state)
{
	(void)state;
	prsm_dp_spec s;
	spec_four(&s, PRSM_DP_STIFFNESS);
	prsm_opt_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), 0);
	const double x[2] = {2.0, 3.2};
	for (int n = 4; n <= 6; n++) {
		double lv[2] = {n, 3};
		prsm_design d;
		prsm_dp_figures fig;
		prsm_dp_design_at(&d, &s, x, lv);
		prsm_dp_analyse(&fig, &d, &s, 0, NULL, NULL);
		const int z_max = fig.z_max;
		assert_true(z_max >= 3);
		for (int z = z_max; z <= z_max + 1; z++) {
			lv[1] = z;
			prsm_dp_design_at(&d, &s, x, lv);
			prsm_dp_analyse(&fig, &d, &s, 0, NULL, NULL);
			for (int i = 0; i < s.n_constraints; i++) {
				const int kind = s.constraint_kind[i];
				const double g = prsm_dp_violation(&s, i, &fig, d.rollers);
				const double v = fig.constraint_value[kind], l = s.constraint_limit[i];
				if (kind == PRSM_DP_C_ROLLER_FIT)
					assert_true(z > z_max ? g >= 1e-3 : g <= 0.0);
				else if (kind == PRSM_DP_C_ANALYSABLE)
					assert_true(fig.analysable ? g == -1.0 : g == 1.0);
				else if (kind == PRSM_DP_C_STANDARD_RULES)
					assert_true(fig.rule_warnings == 0 ? g == -1.0 : g == fig.rule_warnings);
				else if (kind == PRSM_DP_C_STATIC_SAFETY || kind == PRSM_DP_C_LIFE_HOURS)
					assert_int_equal(g <= 0.0, v >= l);
				else
					assert_int_equal(g <= 0.0, v <= l);
			}
		}
	}
}

/* An impossible limit: no feasible design, reported as infeasible with the violation. */
static void test_infeasible(void **state)
{
	(void)state;
	prsm_dp_spec s;
	spec_four(&s, PRSM_DP_EFFICIENCY);
	s.static_safety_min = 1000.0;
	prsm_opt_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), 0);
	prsm_opt_options o;
	prsm_opt_options_init(&o);
	o.max_evaluations = 300;
	o.multistart = 1;
	prsm_opt_result r;
	assert_int_equal(prsm_opt_run(&r, &p, &o, &err), 0);
	assert_int_equal(r.status, PRSM_OPT_INFEASIBLE);
	int violated = 0;
	for (int i = 0; i < p.n_constraints; i++)
		if (r.constraints[i] > 0.0) {
			violated++;
			assert_string_equal(p.constraint_name[i], "static_safety");
		}
	assert_int_equal(violated, 1);
	/* a critical-speed limit without column data is refused */
	spec_four(&s, PRSM_DP_EFFICIENCY);
	s.critical_speed_factor_min = 1.25;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), PRSM_EINVAL);
	spec_four(&s, PRSM_DP_EFFICIENCY);
	s.pitch.min = 3.0;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), PRSM_EINVAL);
}

/* The efficiency-stiffness front: non-dominated, sorted, each point re-analysed and feasible;
 * the weighted sum lands between the anchors. */
static void test_pareto(void **state)
{
	(void)state;
	prsm_dp_spec s;
	spec_four(&s, PRSM_DP_EFFICIENCY);
	s.n_objectives = 2;
	s.objective[1] = PRSM_DP_STIFFNESS;
	prsm_opt_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), 0);
	prsm_opt_options o;
	prsm_opt_options_init(&o);
	o.max_evaluations = 3000;
	o.multistart = 1;
	o.xtol_rel = 1e-4;
	prsm_opt_front *f = calloc(1, sizeof *f);
	assert_int_equal(prsm_opt_pareto(f, &p, &o, 0, 1, 6, &err), 0);
	print_message("front: %d points, %d dropped, %zu evaluations, %.3f s\n", f->n_points,
	              f->dominated_removed, f->evaluations, f->elapsed_s);
	assert_true(f->n_points >= 3);
	for (int i = 0; i < f->n_points; i++) {
		const prsm_opt_point *pt = &f->points[i];
		print_message("  eta %.5f stiffness %.2f N/um (n=%g Z=%g P=%.3f r_r=%.3f)\n",
		              pt->objectives[0], pt->objectives[1], pt->levels[0], pt->levels[1], pt->x[0],
		              pt->x[1]);
		reanalyse_feasible(&s, pt->x, pt->levels, pt->objectives);
		if (i > 0)
			assert_true(f->points[i - 1].objectives[0] <= pt->objectives[0]);
		for (int j = 0; j < f->n_points; j++)
			assert_false(prsm_opt_dominates(&p, 0, 1, f->points[j].objectives, pt->objectives));
	}
	/* sorted by efficiency ascending: stiffness must then descend; no two points the same
	 * trade-off (within 1e-4 of the front's range in both) */
	for (int i = 1; i < f->n_points; i++)
		assert_true(f->points[i].objectives[1] < f->points[i - 1].objectives[1]);
	for (int i = 0; i < f->n_points; i++)
		for (int j = 0; j < i; j++)
			assert_false(fabs(f->points[i].objectives[0] - f->points[j].objectives[0]) <=
			                 1e-4 * (f->nadir[0] - f->ideal[0]) &&
			             fabs(f->points[i].objectives[1] - f->points[j].objectives[1]) <=
			                 1e-4 * (f->nadir[1] - f->ideal[1]));
	prsm_opt_result r;
	double ideal[PRSM_OPT_MAX_OBJECTIVES], range[PRSM_OPT_MAX_OBJECTIVES];
	o.max_evaluations = 1500;
	assert_int_equal(prsm_opt_weighted_sum(&r, ideal, range, &p, &o, &err), 0);
	assert_int_equal(r.status, PRSM_OPT_FEASIBLE);
	assert_true(range[0] > 0.0 && range[1] > 0.0);
	reanalyse_feasible(&s, r.x, r.levels, r.objectives);
	free(f);
}

/* Cancelled in the middle: the best feasible design so far, flagged. */
static prsm_cancel_flag cancel_flag;
static void cancel_after(void *ctx, const prsm_progress *pr)
{
	(void)ctx;
	if (pr->done >= 700)
		cancel_flag = 1;
}

static void test_cancel(void **state)
{
	(void)state;
	prsm_dp_spec s;
	spec_four(&s, PRSM_DP_STIFFNESS);
	prsm_opt_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_dp_problem(&p, &s, &err), 0);
	prsm_opt_options o;
	prsm_opt_options_init(&o);
	o.max_evaluations = 5000;
	o.cancel = &cancel_flag;
	o.progress = cancel_after;
	cancel_flag = 0;
	prsm_opt_result r;
	assert_int_equal(prsm_opt_run(&r, &p, &o, &err), PRSM_ECANCELLED);
	assert_true(r.cancelled);
	assert_true(r.evaluations < 760);
	assert_int_equal(r.status, PRSM_OPT_FEASIBLE);
	reanalyse_feasible(&s, r.x, r.levels, r.objectives);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_four_variables), cmocka_unit_test(test_determinism),
		cmocka_unit_test(test_pruning),        cmocka_unit_test(test_infeasible),
		cmocka_unit_test(test_pareto),         cmocka_unit_test(test_cancel),
		cmocka_unit_test(test_violation),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
