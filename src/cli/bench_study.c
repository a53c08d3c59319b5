/*
 * bench_study.c: the Monte Carlo entries of `prsm bench` (issue: study throughput):
 * case A in linear mode with a realistic tolerance set (samples/s on 1 and 2 threads, and the
 * engine's own overhead over the model's time), Ishigami (samples/s), and Sobol indices of
 * Ishigami at N = 16384 base samples with Sobol and with plain random sampling (seconds and the
 * largest error against the exact indices).
 */
#include <cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "app/study.h"
#include "io/study_json.h"
#include "util/clock.h"

/* Case A (docs/model/geometry-and-meshing.md) with the tolerances of studies/case-a-tolerances.json, linear mode, the
 * outputs at screw angle 0 (backlash, load sharing, stiffness). */
static const char case_a_study[] =
	"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	" \"target_axial_clearance_um\": 20,"
	" \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}},"
	" \"tolerances\": ["
	"  {\"parameter\": \"screw.pitch_radius_um\", \"tol_um\": 4},"
	"  {\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": 5},"
	"  {\"parameter\": \"screw.thickness_um\", \"tol_um\": 3, \"cpk\": 1.33},"
	"  {\"parameter\": \"nut.thickness_um\", \"tol_um\": 3, \"cpk\": 1.33},"
	"  {\"parameter\": \"screw.runout_um\", \"tol_um\": 8},"
	"  {\"parameter\": \"nut.runout_um\", \"distribution\": \"rayleigh\", \"sigma\": 2.5},"
	"  {\"parameter\": \"roller.pitch_radius_um\", \"distribution\": \"normal\", \"sd\": 1.0},"
	"  {\"parameter\": \"roller.thickness_um\", \"tol_um\": 2},"
	"  {\"parameter\": \"roller.pin_radial_um\", \"distribution\": \"uniform\", \"lower\": -5, \"upper\": 5},"
	"  {\"parameter\": \"carrier.runout_um\", \"distribution\": \"rayleigh\", \"sigma\": 3.0}],"
	" \"outputs\": [\"backlash_um\", \"load_sharing_factor\", \"stiffness_N_per_um\"],"
	" \"monte_carlo\": {\"samples\": 16384, \"block_size\": 1024, \"seed\": 1}}";

static const char ishigami_study[] =
	"{\"model\": {\"benchmark\": \"ishigami\"},"
	" \"tolerances\": ["
	"  {\"parameter\": \"x1\", \"distribution\": \"uniform\", \"lower\": -3.141592653589793, \"upper\": 3.141592653589793},"
	"  {\"parameter\": \"x2\", \"distribution\": \"uniform\", \"lower\": -3.141592653589793, \"upper\": 3.141592653589793},"
	"  {\"parameter\": \"x3\", \"distribution\": \"uniform\", \"lower\": -3.141592653589793, \"upper\": 3.141592653589793}],"
	" \"monte_carlo\": {\"samples\": 1000000, \"block_size\": 4096, \"seed\": 1}}";

static prsm_io_study *load(const char *text)
{
	prsm_problems pr;
	prsm_problems_init(&pr);
	cJSON *doc = cJSON_Parse(text);
	prsm_io_study *s = calloc(1, sizeof *s);
	if (!doc || !s || prsm_app_study_load(s, doc, NULL, &pr)) {
		fprintf(stderr, "prsm bench: built-in study invalid: %s\n", pr.count ? pr.items[0].message : "?");
		free(s);
		s = NULL;
	}
	cJSON_Delete(doc);
	return s;
}

/* Samples per second of one plain run. */
static double run_rate(prsm_io_study *s, int threads, double *seconds)
{
	prsm_mc_result r;
	prsm_error err = PRSM_ERROR_INIT;
	s->study.mc.threads = threads;
	if (prsm_mc_run(&r, &s->study.model, s->study.vars, s->study.d, s->study.corr, s->study.n_corr,
	                &s->study.mc, &err))
		return NAN;
	double rate = (double)r.n / r.elapsed_s;
	if (seconds)
		*seconds = r.elapsed_s;
	prsm_mc_result_free(&r);
	return rate;
}

/* The engine's overhead: one thread through the engine against the model alone on the same
 * inputs (sampling, quantiles, bookkeeping), percent of the model's time. */
static double overhead_percent(prsm_io_study *s)
{
	prsm_mc_result r;
	prsm_error err = PRSM_ERROR_INIT;
	s->study.mc.threads = 1;
	if (prsm_mc_run(&r, &s->study.model, s->study.vars, s->study.d, s->study.corr, s->study.n_corr,
	                &s->study.mc, &err))
		return NAN;
	const prsm_mc_model *m = &s->study.model;
	void *ws = NULL;
	double y[PRSM_MC_MAX_OUTPUTS], acc = 0.0;
	unsigned flags;
	if (m->workspace_alloc)
		m->workspace_alloc(&ws, m->ctx);
	double t0 = prsm_clock_seconds();
	for (size_t j = 0; j < r.n; j++) {
		m->eval(y, &flags, m->ctx, ws, r.x + j * r.d);
		acc += y[0];
	}
	double t_model = prsm_clock_seconds() - t0;
	if (m->workspace_free)
		m->workspace_free(ws);
	double pct = 100.0 * (r.elapsed_s - t_model) / t_model;
	prsm_mc_result_free(&r);
	return acc == acc ? pct : NAN;
}

/* Sobol indices of Ishigami at N base samples: seconds, and the largest |estimate - exact|. */
static double sobol_ishigami(prsm_io_study *s, prsm_sampler_kind sampler, double *max_error)
{
	prsm_study_result *r = calloc(1, sizeof *r);
	prsm_error err = PRSM_ERROR_INIT;
	if (!r)
		return NAN;
	s->study.mc.samples = 1024;
	s->study.mc.threads = 1;
	s->study.sens.src = 0;
	s->study.sens.stack = 0;
	s->study.sens.sobol = 1;
	s->study.sens.sobol_samples = 16384;
	s->study.sens.bootstrap = 0;
	s->study.sens.sobol_sampler = sampler;
	if (prsm_study_run(r, &s->study, &err)) {
		free(r);
		return NAN;
	}
	double mean, var, S[3], ST[3];
	prsm_bench_exact(&s->bench, NULL, &mean, &var, S, ST);
	*max_error = 0.0;
	for (int i = 0; i < 3; i++) {
		*max_error = fmax(*max_error, fabs(r->out[0].by_group[i].sobol.first - S[i]));
		*max_error = fmax(*max_error, fabs(r->out[0].by_group[i].sobol.total - ST[i]));
	}
	double t = r->elapsed_sensitivity_s;
	prsm_study_result_free(r);
	free(r);
	return t;
}

void prsm_cli_bench_study(cJSON *list, double budget_s)
{
	prsm_io_study *a = load(case_a_study), *ish = load(ishigami_study);
	if (a) {
		double sec;
		double r1 = run_rate(a, 1, &sec);
		/* size the runs to the budget */
		size_t n = (size_t)fmax(4096.0, fmin(1e6, r1 * budget_s));
		a->study.mc.samples = n;
		prsm_cli_bench_add(list, "study_case_a_linear", run_rate(a, 1, NULL), "samples/s", 1, 0);
		prsm_cli_bench_add(list, "study_case_a_linear", run_rate(a, 2, NULL), "samples/s", 2, 0);
		prsm_cli_bench_add(list, "study_engine_overhead_case_a", overhead_percent(a), "percent", 1, 1);
	}
	if (ish) {
		double r1 = run_rate(ish, 1, NULL);
		ish->study.mc.samples = (size_t)fmax(65536.0, fmin(4e6, r1 * budget_s));
		prsm_cli_bench_add(list, "study_ishigami", run_rate(ish, 1, NULL), "samples/s", 1, 0);
		prsm_cli_bench_add(list, "study_ishigami", run_rate(ish, 2, NULL), "samples/s", 2, 0);
		double err_sobol, err_random;
		double t_sobol = sobol_ishigami(ish, PRSM_SAMPLER_SOBOL, &err_sobol);
		double t_random = sobol_ishigami(ish, PRSM_SAMPLER_RANDOM, &err_random);
		prsm_cli_bench_add(list, "sobol_indices_ishigami_16384_sobol_seconds", t_sobol, "s", 1, 4);
		prsm_cli_bench_add(list, "sobol_indices_ishigami_16384_sobol_max_error", err_sobol, "abs", 1, 5);
		prsm_cli_bench_add(list, "sobol_indices_ishigami_16384_random_seconds", t_random, "s", 1, 4);
		prsm_cli_bench_add(list, "sobol_indices_ishigami_16384_random_max_error", err_random, "abs", 1, 5);
	}
	free(a);
	free(ish);
}
