/*
 * bench.c: `prsm bench`, throughput of the engine's kernels as JSON:
 *   {"benchmarks": [{"name", "value", "unit", "threads"}, ...]}
 * Each kernel runs on case A (studies/case-a.json) for a fixed wall-clock budget; every later kernel
 * (assembly, Monte Carlo, optimisation) adds its entry to the same list.
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/assembly_report.h"
#include "model/contact.h"
#include "model/geometry.h"
#include "model/loaddist.h"
#include "model/performance.h"
#include "util/clock.h"

void prsm_cli_bench_case_a(prsm_design *d)
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

/* Case A, resolved by the standard rules. */
static void case_a(prsm_design *d)
{
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_cli_bench_case_a(d);
	prsm_design_resolve(d, &e);
}

static volatile double sink;

/* Warm-started Newton solves on screw-side pairs whose roller axis moves by a few um from one
 * solve to the next, as in a Monte Carlo sample. */
static double bench_contact(double budget_s, int warm)
{
	prsm_design d;
	case_a(&d);
	prsm_flank_pair pair;
	prsm_flank_pair_nominal(&pair, &d, PRSM_SIDE_SCREW);
	double x0, y0, g;
	prsm_contact_start(&pair, &x0, &y0);
	prsm_contact_solve_gap(&pair, &x0, &y0, &g, NULL);
	const double a = pair.roller_x_mm;
	long n = 0;
	double acc = 0.0, t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		for (int i = 0; i < 4096; i++) {
			/* deterministic pseudo-random offsets within +-20 um */
			double off = 0.02 * sin(0.7 * (double)(n + i));
			pair.roller_x_mm = a + off;
			pair.roller_y_mm = 0.5 * off;
			double x = x0, y = y0;
			if (!warm)
				prsm_contact_start(&pair, &x, &y);
			prsm_contact_solve_gap(&pair, &x, &y, &g, NULL);
			acc += g;
		}
		n += 4096;
		t = prsm_clock_seconds();
	}
	sink = acc;
	return (double)n / (t - t0);
}

static double bench_analysis(double budget_s)
{
	prsm_design d;
	case_a(&d);
	long n = 0;
	double t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		for (int i = 0; i < 64; i++) {
			prsm_design di = d;
			prsm_analysis a;
			prsm_problems w;
			prsm_problems_init(&w);
			prsm_analysis_nominal(&a, &di, &w, NULL);
			sink = a.efficiency.eta;
		}
		n += 64;
		t = prsm_clock_seconds();
	}
	return (double)n / (t - t0);
}

/* The operating-point analysis of case A at 7 kN (docs/model/kinematics-efficiency-stiffness-life.md: losses, load distribution,
 * stiffness, C_0a by bisection, C_a, life) after one nominal analysis; what the optimiser pays
 * for an efficiency-and-stiffness evaluation. */
static double bench_performance(double budget_s)
{
	prsm_design d;
	case_a(&d);
	prsm_analysis a;
	prsm_problems w;
	prsm_problems_init(&w);
	if (prsm_analysis_nominal(&a, &d, &w, NULL))
		return NAN;
	long n = 0;
	double t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		for (int i = 0; i < 8; i++) {
			prsm_performance p;
			prsm_error err = PRSM_ERROR_INIT;
			d.axial_load_N = 7000.0 + (double)(i & 3);
			if (prsm_performance_compute(&p, &d, &a, &err) == 0)
				sink = p.stiffness_N_per_um;
			prsm_performance_free(&p);
		}
		n += 8;
		t = prsm_clock_seconds();
	}
	return (double)n / (t - t0);
}

/* One spring-chain solve of case A (n_t = 10, Hertz + Yamamoto threads + bodies). */
static double bench_loaddist(double budget_s)
{
	prsm_design d;
	case_a(&d);
	prsm_analysis a;
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	prsm_design_compliance tc;
	prsm_segment_compliance seg;
	prsm_loaddist_params p;
	if (prsm_analysis_nominal(&a, &d, &w, NULL) || prsm_compliance_design(&tc, &d, NULL, NULL, &err) ||
	    prsm_compliance_segments(&seg, &d, NAN, &err) ||
	    prsm_loaddist_params_from_design(&p, &d, &a.screw, &a.nut, &tc, &seg, PRSM_LOAD_ENTRY_SAME, &err))
		return NAN;
	prsm_loaddist_workspace *ws = prsm_loaddist_alloc(d.engaged_threads);
	if (ws == NULL)
		return NAN;
	long n = 0;
	double t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		for (int i = 0; i < 64; i++) {
			prsm_loaddist_result r;
			if (prsm_loaddist_solve(&r, ws, &p, 7000.0 + (double)i, &err) == 0)
				sink = r.stiffness_N_per_mm;
		}
		n += 64;
		t = prsm_clock_seconds();
	}
	prsm_loaddist_free(ws);
	return (double)n / (t - t0);
}

/* An error set with every kind of error present (tens of um, a few mrad), varied per call by
 * the deterministic index i as a Monte Carlo sample would be. */
static void sample_errors(prsm_errors *e, int Z, int n, long i)
{
	prsm_errors_zero(e, Z);
	const double v = sin(0.37 * (double)i);
	prsm_body_errors *b[2] = {&e->screw, &e->nut};
	for (int p = 0; p < 2; p++) {
		b[p]->pitch_radius_mm = 0.004 * v;
		b[p]->thickness_mm = -0.003 + 0.002 * v;
		b[p]->flank_angle_rad = 0.001 * v;
		b[p]->runout_mm = 0.008;
		b[p]->runout_phase_rad = 1.0 + v;
		b[p]->lead_deviation = 1e-5 * v;
		b[p]->lead_periodic_mm = 0.002;
		b[p]->lead_periodic_phase_rad = v;
		for (int k = 0; k < n; k++)
			b[p]->start_index_rad[k] = 0.001 * sin(1.3 * k + v);
		b[p]->tilt_rad = 2e-4;
		b[p]->tilt_phase_rad = 0.5 * v;
	}
	e->carrier.runout_mm = 0.005;
	for (int j = 0; j < Z; j++) {
		prsm_roller_errors *r = &e->roller[j];
		const double w = sin(0.37 * (double)i + 1.7 * j);
		r->pitch_radius_mm = 0.003 * w;
		r->thickness_mm = 0.002 * w;
		r->arc_radius_mm = 0.01 * w;
		r->runout_mm = 0.004;
		r->runout_phase_rad = w;
		r->lead_periodic_mm = 0.001;
		r->pin_radial_mm = 0.005 * w;
		r->pin_tangential_mm = -0.005 * w;
		r->gear_phase_rad = 0.002 * w;
		r->tilt_radial_rad = 1e-4 * w;
	}
}

/* docs/model/errors-and-assembly.md kernels, case A (Z = 10, n_t = 10): (a) gaps of both directions, backlash and the
 * elastic load sharing at the operating load; (b) the TE curve, 64 screw angles at 50 N. */
static double bench_assembly(double budget_s, int mode, int te)
{
	prsm_design d;
	case_a(&d);
	prsm_analysis a;
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_assembly as;
	if (prsm_analysis_nominal(&a, &d, &w, NULL) || prsm_assembly_init(&as, &d, &a, NULL))
		return 0.0;
	prsm_assembly_gaps *g = malloc(2 * sizeof *g);
	if (g == NULL)
		return 0.0;
	double te_mm[64];
	prsm_errors e;
	prsm_assembly_state st;
	long n = 0;
	double acc = 0.0, t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		const int batch = te ? 4 : 64;
		for (int i = 0; i < batch; i++) {
			sample_errors(&e, as.rollers, as.starts, n + i);
			if (te) {
				prsm_assembly_te_record(te_mm, 64, 2.0 * M_PI / 64, &as, &e, mode, 50.0, &g[0], NULL, NULL);
				acc += te_mm[63];
			} else {
				prsm_assembly_gaps_at(&g[0], &as, &e, PRSM_DIR_PLUS, 0.1 * (double)i, mode);
				prsm_assembly_gaps_at(&g[1], &as, &e, PRSM_DIR_MINUS, 0.1 * (double)i, mode);
				acc += prsm_assembly_backlash(&as, &g[0], &g[1], NULL, NULL);
				prsm_assembly_solve(&st, &as, &g[0], d.axial_load_N, 0);
				acc += st.sharing_factor;
			}
		}
		n += batch;
		t = prsm_clock_seconds();
	}
	free(g);
	sink = acc;
	return (double)n / (t - t0);
}

void prsm_cli_bench_add(cJSON *list, const char *name, double value, const char *unit, int threads,
                        int decimals)
{
	cJSON *b = cJSON_CreateObject();
	double scale = pow(10.0, decimals);
	cJSON_AddStringToObject(b, "name", name);
	if (isfinite(value))
		cJSON_AddNumberToObject(b, "value", round(value * scale) / scale);
	else
		cJSON_AddNullToObject(b, "value");
	cJSON_AddStringToObject(b, "unit", unit);
	cJSON_AddNumberToObject(b, "threads", threads);
	cJSON_AddItemToArray(list, b);
}

static void add(cJSON *list, const char *name, double value, const char *unit, int threads)
{
	prsm_cli_bench_add(list, name, value, unit, threads, 0);
}

int prsm_cli_bench(int argc, char **argv)
{
	double budget = 0.5;
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
			char *end = NULL;
			budget = strtod(argv[++i], &end);
			if (end == argv[i] || *end != '\0' || !(budget > 0.0 && budget <= 60.0)) {
				fprintf(stderr, "prsm bench: --seconds must be in (0, 60]\n");
				return PRSM_EXIT_USAGE;
			}
		} else {
			fprintf(stderr, "usage: prsm bench [--seconds S]\n");
			return PRSM_EXIT_USAGE;
		}
	}
	cJSON *doc = cJSON_CreateObject();
	cJSON *list = cJSON_AddArrayToObject(doc, "benchmarks");
	add(list, "contact_solve_warm", bench_contact(budget, 1), "solves/s", 1);
	add(list, "contact_solve_cold", bench_contact(budget, 0), "solves/s", 1);
	add(list, "nominal_analysis", bench_analysis(budget), "analyses/s", 1);
	add(list, "load_distribution_case_a", bench_loaddist(budget), "solves/s", 1);
	add(list, "operating_point_analysis_case_a", bench_performance(budget), "analyses/s", 1);
	add(list, "backlash_load_sharing_linear", bench_assembly(budget, PRSM_MODE_LINEAR, 0), "evaluations/s", 1);
	add(list, "backlash_load_sharing_exact", bench_assembly(budget, PRSM_MODE_EXACT, 0), "evaluations/s", 1);
	add(list, "te_curve_64_linear", bench_assembly(budget, PRSM_MODE_LINEAR, 1), "curves/s", 1);
	add(list, "te_curve_64_exact", bench_assembly(budget, PRSM_MODE_EXACT, 1), "curves/s", 1);
	prsm_cli_bench_study(list, budget);
	prsm_cli_bench_dyn(list, budget);
	prsm_cli_bench_opt(list);
	int rc = prsm_cli_print_json(doc, NULL);
	cJSON_Delete(doc);
	return rc;
}
