/*
 * bench_opt.c: the design-optimisation entry of `prsm bench` (issue 7, "Speed"): a
 * deterministic 4-variable design optimisation of case A's operating point (7000 N, 100 rad/s,
 * 20 um play) — starts 3..6, pitch 1..3 mm, roller radius 2.5..5 mm and every roller count from
 * 3 up to Z_max — maximising the axial stiffness with static safety >= 2.5, L10 >= 2000 h and a
 * nut outer diameter <= 50 mm; COBYLA, 2 Sobol starts per combination, 2000 evaluations, seed 1.
 * The goal is under 2 s on the 2-core reference machine; it reports the seconds, the
 * evaluations and the optimum (which must not change from run to run).
 */
#include <cJSON.h>
#include <math.h>

#include "cli/commands.h"
#include "model/geometry.h"
#include "opt/design_problem.h"
#include "opt/optimize.h"
#include "util/clock.h"

void prsm_cli_bench_opt(cJSON *list)
{
	prsm_design base;
	prsm_cli_bench_case_a(&base);
	prsm_dp_spec s;
	prsm_dp_spec_init(&s, &base);
	for (int n = 3; n <= 6; n++)
		s.starts.values[s.starts.count++] = n;
	s.pitch = (prsm_dp_range){1, 1.0, 3.0};
	s.radius = (prsm_dp_range){1, 2.5, 5.0};
	int z_max = 0;
	for (int n = 3; n <= 6; n++) {
		int z = prsm_dp_z_max_bound(&s, n);
		z_max = z > z_max ? z : z_max;
	}
	for (int z = 3; z <= z_max; z++)
		s.rollers.values[s.rollers.count++] = z;
	s.n_objectives = 1;
	s.objective[0] = PRSM_DP_STIFFNESS;
	s.static_safety_min = 2.5;
	s.life_min_h = 2000.0;
	s.nut_outer_diameter_max_mm = 50.0;
	prsm_opt_problem p;
	prsm_opt_options o;
	prsm_opt_result r;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_opt_options_init(&o);
	o.max_evaluations = 2000;
	o.multistart = 2;
	o.xtol_rel = 1e-4;
	o.ftol_rel = 1e-6;
	double t0 = prsm_clock_seconds();
	int rc = prsm_dp_problem(&p, &s, &err);
	if (rc == 0)
		rc = prsm_opt_run(&r, &p, &o, &err);
	double t = prsm_clock_seconds() - t0;
	int ok = rc == 0 && r.status == PRSM_OPT_FEASIBLE;
	prsm_cli_bench_add(list, "design_optimization_4var_seconds", ok ? t : NAN, "s", 1, 3);
	prsm_cli_bench_add(list, "design_optimization_4var_evaluations", ok ? (double)r.evaluations : NAN,
	                   "evaluations", 1, 0);
	prsm_cli_bench_add(list, "design_optimization_4var_combinations_pruned",
	                   ok ? (double)r.pruned : NAN, "combinations", 1, 0);
	prsm_cli_bench_add(list, "design_optimization_4var_best_stiffness", ok ? r.objectives[0] : NAN,
	                   "N/um", 1, 3);
}
