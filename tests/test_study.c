/*
 * test_study.c: study documents through io/study_json into the engine: the roller screw as a
 * sampled model (determinism across threads, per-roller and shared variables, phases), the
 * Gaussian copula, the tolerance shorthand, and the LS-1 stack of reference/benchmarks.md.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>

#include "app/study.h"
#include "io/study_json.h"
#include "io/global.h"
#include "model/performance.h"

static const char *design_json =
	"\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	" \"target_axial_clearance_um\": 20,"
	" \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}}";

static prsm_io_study *load(const char *text, prsm_problems *pr)
{
	cJSON *doc = cJSON_Parse(text);
	assert_non_null(doc);
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems_init(pr);
	int rc = prsm_app_study_load(s, doc, NULL, pr);
	cJSON_Delete(doc);
	if (rc) {
		for (int i = 0; i < pr->count; i++)
			print_message("%s: %s\n", pr->items[i].pointer, pr->items[i].message);
		free(s);
		return NULL;
	}
	return s;
}

static char *study_text(const char *tolerances, const char *rest)
{
	size_t n = strlen(design_json) + strlen(tolerances) + strlen(rest) + 64;
	char *t = malloc(n);
	snprintf(t, n, "{%s, \"tolerances\": [%s]%s}", design_json, tolerances, rest);
	return t;
}

/* A roller screw study gives bit-identical samples for 1, 2 and 8 threads, in both modes. */
static void test_prsm_threads(void **state)
{
	(void)state;
	for (int mode = 0; mode < 2; mode++) {
		char rest[512];
		snprintf(rest, sizeof rest,
		         ", \"assembly\": {\"mode\": \"%s\", \"angles_per_revolution\": 8},"
		         " \"outputs\": [\"backlash_um\", \"backlash_min_um\", \"load_sharing_factor\", "
		         "\"stiffness_N_per_um\", \"te_pp_um\", \"efficiency\"],"
		         " \"monte_carlo\": {\"samples\": %d, \"block_size\": 16, \"seed\": 99}",
		         mode ? "exact" : "linear", mode ? 48 : 400);
		char *t = study_text("{\"parameter\": \"screw.runout_um\", \"tol_um\": 6},"
		                     "{\"parameter\": \"nut.pitch_radius_um\", \"distribution\": \"uniform\", \"lower\": -4, \"upper\": 4},"
		                     "{\"parameter\": \"roller.thickness_um\", \"tol_um\": 2.5, \"cpk\": 1.2},"
		                     "{\"parameter\": \"roller.runout_um\", \"distribution\": \"rayleigh\", \"sigma\": 1.3},"
		                     "{\"parameter\": \"screw.start_index_mrad\", \"distribution\": \"normal\", \"sd\": 0.2},"
		                     "{\"parameter\": \"friction.screw_roller_mu\", \"distribution\": \"uniform\", \"lower\": -0.01, \"upper\": 0.02}",
		                     rest);
		prsm_problems pr;
		prsm_io_study *s = load(t, &pr);
		free(t);
		assert_non_null(s);
		/* 2 + 1 + 10 + 20 + 5 + 1 variables */
		assert_int_equal(s->study.d, 39);
		prsm_mc_result r[3];
		int threads[3] = {1, 2, 8};
		for (int k = 0; k < 3; k++) {
			prsm_error err = PRSM_ERROR_INIT;
			s->study.mc.threads = threads[k];
			assert_int_equal(prsm_mc_run(&r[k], &s->study.model, s->study.vars, s->study.d, NULL, 0,
			                             &s->study.mc, &err), 0);
			assert_int_equal(r[k].n_failed, 0);
		}
		for (int k = 1; k < 3; k++) {
			assert_memory_equal(r[0].x, r[k].x, r[0].n * r[0].d * sizeof(double));
			assert_memory_equal(r[0].y, r[k].y, r[0].n * r[0].m * sizeof(double));
		}
		/* outputs move: the errors reach the model */
		prsm_moments m;
		prsm_moments_init(&m);
		for (size_t j = 0; j < r[0].n; j++)
			prsm_moments_add(&m, r[0].y[j * r[0].m]);
		assert_true(prsm_moments_sd(&m) > 0.1);
		for (int k = 0; k < 3; k++)
			prsm_mc_result_free(&r[k]);
		free(s);
	}
}

/* Per-roller tolerances draw one variable per roller (and a phase per radial one); shared
 * draws one for all; the sample's value reaches every roller it is bound to. */
static void test_per_roller_and_shared(void **state)
{
	(void)state;
	char *t = study_text("{\"parameter\": \"roller.thickness_um\", \"tol_um\": 3, \"shared\": true},"
	                     "{\"parameter\": \"roller.runout_um\", \"distribution\": \"rayleigh\", \"sigma\": 1}",
	                     ", \"outputs\": [\"backlash_um\"], \"sensitivity\": {\"stack\": false}");
	prsm_problems pr;
	prsm_io_study *s = load(t, &pr);
	free(t);
	assert_non_null(s);
	assert_int_equal(s->study.d, 1 + 20);
	assert_int_equal(s->study.groups[0].n_vars, 1);
	assert_int_equal(s->study.groups[1].n_vars, 20);
	assert_string_equal(s->study.info[0].name, "roller[*].thickness_um");
	assert_string_equal(s->study.info[1].name, "roller[0].runout_um");
	assert_string_equal(s->study.info[2].name, "roller[0].runout_phase_rad");
	assert_int_equal(s->study.info[1].phase, 2);
	assert_int_equal(s->study.info[2].phase_of, 1);
	/* a shared thickness deviation t thickens every roller: each flank moves t/2 (docs/model/errors-and-assembly.md,
	 * dgap/dt = 1 for a part's thickness), a direction's chain has a screw-side and a nut-side
	 * roller flank, and B adds both directions: B falls by 2 t */
	double x[21] = {0}, y0, y1;
	unsigned flags;
	void *ws;
	const prsm_mc_model *mdl = &s->study.model;
	assert_int_equal(mdl->workspace_alloc(&ws, mdl->ctx), 0);
	assert_int_equal(mdl->eval(&y0, &flags, mdl->ctx, ws, x), 0);
	x[0] = 1.7;
	assert_int_equal(mdl->eval(&y1, &flags, mdl->ctx, ws, x), 0);
	assert_close(y1 - y0, -2.0 * 1.7, 1e-9);
	mdl->workspace_free(ws);
	free(s);
}

/* The Gaussian copula: the normal scores of two correlated tolerances have correlation rho
 * (within 4.5 standard errors of Fisher's z), uncorrelated ones none. */
static void test_copula(void **state)
{
	(void)state;
	char *t = study_text("{\"parameter\": \"screw.pitch_radius_um\", \"distribution\": \"uniform\", \"lower\": -3, \"upper\": 5},"
	                     "{\"parameter\": \"nut.pitch_radius_um\", \"distribution\": \"normal\", \"mean\": 1, \"sd\": 2},"
	                     "{\"parameter\": \"screw.thickness_um\", \"distribution\": \"normal\", \"sd\": 1}",
	                     ", \"correlations\": [{\"between\": [\"screw.pitch_radius_um\", \"nut.pitch_radius_um\"], \"rho\": 0.63}],"
	                     " \"outputs\": [\"backlash_um\"], \"monte_carlo\": {\"samples\": 20000, \"seed\": 3}");
	prsm_problems pr;
	prsm_io_study *s = load(t, &pr);
	free(t);
	assert_non_null(s);
	assert_int_equal(s->study.n_corr, 1);
	prsm_mc_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_mc_run(&r, &s->study.model, s->study.vars, s->study.d, s->study.corr,
	                             s->study.n_corr, &s->study.mc, &err), 0);
	double sxy = 0, sxx = 0, syy = 0, sxz = 0, szz = 0;
	for (size_t j = 0; j < r.n; j++) {
		double a = gsl_cdf_ugaussian_Pinv((r.x[j * 3] + 3.0) / 8.0);
		double b = (r.x[j * 3 + 1] - 1.0) / 2.0;
		double c = r.x[j * 3 + 2];
		sxy += a * b;
		sxx += a * a;
		syy += b * b;
		sxz += a * c;
		szz += c * c;
	}
	double rho = sxy / sqrt(sxx * syy), rho0 = sxz / sqrt(sxx * szz);
	double se_z = 1.0 / sqrt((double)r.n - 3.0);
	assert_close(atanh(rho), atanh(0.63), 4.5 * se_z);
	assert_close(atanh(rho0), 0.0, 4.5 * se_z);
	/* the marginals are untouched: uniform mean 1, normal sd 2 */
	prsm_moments mu, mn;
	prsm_moments_init(&mu);
	prsm_moments_init(&mn);
	for (size_t j = 0; j < r.n; j++) {
		prsm_moments_add(&mu, r.x[j * 3]);
		prsm_moments_add(&mn, r.x[j * 3 + 1]);
	}
	assert_close(mu.mean, 1.0, 4.5 * 8.0 / sqrt(12.0 * (double)r.n));
	assert_close(prsm_moments_sd(&mn), 2.0, 4.5 * 2.0 / sqrt(2.0 * (double)r.n));
	prsm_mc_result_free(&r);
	free(s);
}

/* LS-1 of reference/benchmarks.md through a study document: stack figures exact, Cpk and the
 * normal-fit ppm within their standard errors, SRC^2 shares. */
static void test_ls1(void **state)
{
	(void)state;
	const char *text =
		"{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1, 1, -1, -1]},"
		" \"tolerances\": ["
		"  {\"parameter\": \"x1\", \"tol\": 0.05, \"nominal\": 30.0},"
		"  {\"parameter\": \"x2\", \"tol\": 0.04, \"nominal\": 20.0},"
		"  {\"parameter\": \"x3\", \"tol\": 0.03, \"nominal\": 24.9},"
		"  {\"parameter\": \"x4\", \"tol\": 0.02, \"nominal\": 25.0}],"
		" \"specs\": {\"y\": {\"lower\": 0, \"upper\": 0.2}},"
		" \"monte_carlo\": {\"samples\": 40000, \"seed\": 2026, \"threads\": 2}}";
	prsm_problems pr;
	prsm_io_study *s = load(text, &pr);
	assert_non_null(s);
	prsm_study_result *r = calloc(1, sizeof *r);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(r, &s->study, &err), 0);
	const prsm_study_output_result *o = &r->out[0];
	assert_close(o->nominal, 0.1, 1e-12);
	assert_close(o->worst_low, -0.04, 1e-12);
	assert_close(o->worst_high, 0.24, 1e-12);
	assert_close(o->rss, 0.07348469228349534, 1e-12);
	assert_close(o->summary.sd, 0.024494897427831785, 4.5 * o->summary.se_sd);
	assert_close(o->summary.cpk, 1.3608276348795, 4.5 * o->summary.se_cpk);
	assert_true(o->src_r2 > 0.999999);
	const double share[4] = {25.0 / 54, 16.0 / 54, 9.0 / 54, 4.0 / 54};
	for (int i = 0; i < 4; i++) {
		double w = share[i];
		assert_close(o->by_group[i].src_percent / 100.0, w, 4.5 * 2.0 * w * sqrt((1.0 - w) / 40000.0));
	}
	prsm_study_result_free(r);
	free(r);
	free(s);
}

/* Issue 19, item 7: the RSS stack counts each tolerance with its own sd, as the allocation
 * does. LS-1's stack with uniform tolerances: RSS = 3 sqrt(sum (c_i T_i / sqrt 3)^2) =
 * sqrt(3 sum T_i^2), and the Monte Carlo puts at most about 0.3 % of the assemblies outside
 * nominal +- RSS (a half-width taken as 3 sd put 8.3 % outside). */
static void test_rss_uniform(void **state)
{
	(void)state;
	const char *text =
		"{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1, 1, -1, -1]},"
		" \"tolerances\": ["
		"  {\"parameter\": \"x1\", \"distribution\": \"uniform\", \"lower\": 29.95, \"upper\": 30.05},"
		"  {\"parameter\": \"x2\", \"distribution\": \"uniform\", \"lower\": 19.96, \"upper\": 20.04},"
		"  {\"parameter\": \"x3\", \"distribution\": \"uniform\", \"lower\": 24.87, \"upper\": 24.93},"
		"  {\"parameter\": \"x4\", \"distribution\": \"uniform\", \"lower\": 24.98, \"upper\": 25.02}],"
		" \"specs\": {\"y\": {\"lower\": 0.01, \"upper\": 0.19}},"
		" \"monte_carlo\": {\"samples\": 20000, \"seed\": 20261125}}";
	prsm_problems pr;
	prsm_io_study *s = load(text, &pr);
	assert_non_null(s);
	/* the spec: nominal 0.1 +- the RSS half-width expected */
	const double rss = sqrt(3.0 * (0.05 * 0.05 + 0.04 * 0.04 + 0.03 * 0.03 + 0.02 * 0.02));
	s->study.outputs[0].spec.lower = 0.1 - rss;
	s->study.outputs[0].spec.upper = 0.1 + rss;
	prsm_study_result *r = calloc(1, sizeof *r);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(r, &s->study, &err), 0);
	const prsm_study_output_result *o = &r->out[0];
	assert_close(o->nominal, 0.1, 1e-12);
	assert_close(o->rss, rss, 1e-12);
	assert_close(o->worst_high - o->nominal, 0.14, 1e-12);
	/* a sum of four uniforms is lighter-tailed than a normal: outside +-3 sd well under 1 % */
	print_message("outside nominal +- RSS: %.4f %%\n", 100.0 * (1.0 - o->summary.yield));
	assert_true(o->summary.yield >= 0.99);
	prsm_study_result_free(r);
	free(r);
	free(s);
}

/* nut_unit_stiffness_N_per_um: the sample's contacts in series with the nominal unit's other
 * compliance (docs/model/kinematics-efficiency-stiffness-life.md). An error-free sample is the nominal nut unit of prsm_performance
 * (prsm analyze's stiffness); with errors the extra compliance is the same for every sample, so
 * the unit stiffness varies less than the contacts' (dk_unit/dk_c = (k_unit/k_c)^2 < 1). */
static void test_nut_unit_stiffness(void **state)
{
	(void)state;
	const char *rest = ", \"outputs\": [\"stiffness_N_per_um\", \"nut_unit_stiffness_N_per_um\", \"efficiency_with_losses\"],"
	                   " \"monte_carlo\": {\"samples\": 64, \"block_size\": 16, \"seed\": 5}";
	/* error-free: a tolerance too narrow to move anything */
	char *t = study_text("{\"parameter\": \"nut.pitch_radius_um\", \"distribution\": \"normal\", \"sd\": 1e-9}", rest);
	prsm_problems pr;
	prsm_io_study *s = load(t, &pr);
	free(t);
	assert_non_null(s);
	prsm_analysis a;
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_analysis_nominal(&a, &s->design, &w, &err), 0);
	prsm_performance perf;
	assert_int_equal(prsm_performance_compute(&perf, &s->design, &a, &err), 0);
	double k_unit = perf.stiffness_N_per_um, eta = perf.losses.eta;
	prsm_performance_free(&perf);
	prsm_mc_result r;
	assert_int_equal(prsm_mc_run(&r, &s->study.model, s->study.vars, s->study.d, NULL, 0, &s->study.mc, &err), 0);
	for (size_t j = 0; j < r.n; j++) {
		assert_close(r.y[j * 3 + 1], k_unit, 1e-9 * k_unit);
		assert_close(r.y[j * 3], s->assembly.nominal_stiffness_N_per_mm * 1e-3, 1e-6 * r.y[j * 3]);
		assert_close(r.y[j * 3 + 2], eta, 1e-12);
	}
	assert_true(k_unit < r.y[0]); /* the threads, cores and body only add compliance */
	prsm_mc_result_free(&r);
	free(s);

	/* with errors: one extra compliance for every sample, and a narrower spread */
	t = study_text("{\"parameter\": \"nut.pitch_radius_um\", \"distribution\": \"uniform\", \"lower\": -4.3, \"upper\": 4.3},"
	               "{\"parameter\": \"roller.thickness_um\", \"tol_um\": 2.7, \"cpk\": 0.9},"
	               "{\"parameter\": \"screw.runout_um\", \"tol_um\": 5.5},"
	               "{\"parameter\": \"friction.screw_roller_mu\", \"distribution\": \"uniform\", \"lower\": -0.013, \"upper\": 0.021}",
	               rest);
	s = load(t, &pr);
	free(t);
	assert_non_null(s);
	assert_int_equal(prsm_mc_run(&r, &s->study.model, s->study.vars, s->study.d, NULL, 0, &s->study.mc, &err), 0);
	double rest0 = 1.0 / k_unit - 1.0 / (s->assembly.nominal_stiffness_N_per_mm * 1e-3); /* um/N */
	prsm_moments mc, mu;
	prsm_moments_init(&mc);
	prsm_moments_init(&mu);
	for (size_t j = 0; j < r.n; j++) {
		double kc = r.y[j * 3], ku = r.y[j * 3 + 1];
		assert_close(1.0 / ku - 1.0 / kc, rest0, 1e-9 * rest0);
		prsm_moments_add(&mc, kc);
		prsm_moments_add(&mu, ku);
	}
	/* the efficiency with every loss at the sample's friction is the nominal unit's with that
	 * friction (the load distribution does not depend on friction): the friction variable is last */
	for (size_t j = 0; j < r.n; j += 13) {
		prsm_design d2 = s->design;
		d2.mu_screw_roller += r.x[j * r.d + r.d - 1];
		assert_int_equal(prsm_performance_compute(&perf, &d2, &a, &err), 0);
		assert_close(r.y[j * 3 + 2], perf.losses.eta, 1e-12);
		prsm_performance_free(&perf);
	}
	assert_true(prsm_moments_sd(&mc) > 1.0);
	assert_true(prsm_moments_sd(&mu) < prsm_moments_sd(&mc));
	prsm_mc_result_free(&r);
	free(s);

	/* it needs an operating load, at its pointer */
	cJSON *doc = cJSON_Parse("{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	                         " \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	                         " \"target_axial_clearance_um\": 20},"
	                         " \"tolerances\": [{\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": 3}],"
	                         " \"outputs\": [\"backlash_um\", \"nut_unit_stiffness_N_per_um\"]}");
	s = calloc(1, sizeof *s);
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_study_load(s, doc, NULL, &pr), PRSM_EINVAL);
	assert_string_equal(pr.items[0].pointer, "/outputs/1");
	assert_string_equal(pr.items[0].code, "no_load");
	cJSON_Delete(doc);
	free(s);
}

/* Issue 19, items 4 and 6: a document the engine cannot compute is refused at the field that
 * makes it so (it used to pass and fail at run time without a cause); a length error the size
 * of a thread pitch is refused, and linear assembly mode beyond its checked range warned of. */
static void expect_refused(const char *text, const char *pointer, const char *code)
{
	prsm_problems pr;
	assert_null(load(text, &pr));
	int found = 0;
	for (int i = 0; i < pr.count; i++)
		found |= strcmp(pr.items[i].pointer, pointer) == 0 && strcmp(pr.items[i].code, code) == 0;
	assert_true(found);
}

static void test_ranges(void **state)
{
	(void)state;
	expect_refused("{\"model\": {\"benchmark\": \"ishigami\", \"a\": 1e308}, \"tolerances\": ["
	               "{\"parameter\": \"x1\", \"distribution\": \"uniform\", \"lower\": -3, \"upper\": 3},"
	               "{\"parameter\": \"x2\", \"distribution\": \"uniform\", \"lower\": -3, \"upper\": 3},"
	               "{\"parameter\": \"x3\", \"distribution\": \"uniform\", \"lower\": -3, \"upper\": 3}]}",
	               "/model", "range");
	expect_refused("{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1e300]}, \"tolerances\": ["
	               "{\"parameter\": \"x1\", \"distribution\": \"normal\", \"mean\": 0, \"sd\": 1}]}",
	               "/model", "range");
	expect_refused("{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1]}, \"tolerances\": ["
	               "{\"parameter\": \"x1\", \"distribution\": \"lognormal\", \"mu\": 700, \"sigma\": 1}]}",
	               "/tolerances/0", "range");
	expect_refused("{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1]}, \"tolerances\": ["
	               "{\"parameter\": \"x1\", \"distribution\": \"normal\", \"mean\": 1e300, \"sd\": 1e299}]}",
	               "/tolerances/0", "range");
	/* a run-out of 1e9 um on a 2 mm pitch: refused; 500 um in linear mode: a warning */
	char *t = study_text("{\"parameter\": \"screw.runout_um\", \"tol_um\": 1e9, \"cpk\": 1}",
	                     ", \"monte_carlo\": {\"samples\": 64}");
	expect_refused(t, "/tolerances/0", "range");
	free(t);
	t = study_text("{\"parameter\": \"screw.runout_um\", \"tol_um\": 500, \"cpk\": 1}",
	               ", \"monte_carlo\": {\"samples\": 64}");
	cJSON *doc = cJSON_Parse(t);
	assert_non_null(doc);
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems pr, w;
	prsm_problems_init(&pr);
	prsm_problems_init(&w);
	assert_int_equal(prsm_app_study_load(s, doc, &w, &pr), 0);
	int warned = 0;
	for (int i = 0; i < w.count; i++)
		warned |= strcmp(w.items[i].code, "linear_range") == 0 && strcmp(w.items[i].pointer, "/tolerances/0") == 0;
	assert_true(warned);
	cJSON_Delete(doc);
	free(s);
	free(t);
}

/* The range checks are a computation, the application's hook (prsm_io_study_options.check_study,
 * app/study.c): the reader alone takes a distribution beyond +-1e150 and a benchmark whose output
 * overflows, the application refuses both at their pointers. */
static void test_range_hook(void **state)
{
	(void)state;
	static const char *const docs[][2] = {
		{"{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1]}, \"tolerances\": ["
		 "{\"parameter\": \"x1\", \"distribution\": \"normal\", \"mean\": 1e300, \"sd\": 1e299}]}", "/tolerances/0"},
		{"{\"model\": {\"benchmark\": \"linear\", \"coefficients\": [1e300]}, \"tolerances\": ["
		 "{\"parameter\": \"x1\", \"distribution\": \"normal\", \"mean\": 0, \"sd\": 1}]}", "/model"},
	};
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	for (size_t k = 0; k < sizeof docs / sizeof docs[0]; k++) {
		cJSON *doc = cJSON_Parse(docs[k][0]);
		assert_non_null(doc);
		prsm_problems pr;
		prsm_problems_init(&pr);
		assert_int_equal(prsm_io_study_load(s, doc, NULL, NULL, &pr), 0);
		assert_int_equal(pr.count, 0);
		prsm_io_study_options o;
		prsm_app_study_options(&o);
		assert_non_null(o.check_study);
		o.check_study = NULL; /* the other hooks alone: still no check */
		assert_int_equal(prsm_io_study_load(s, doc, &o, NULL, &pr), 0);
		assert_int_equal(pr.count, 0);
		assert_int_equal(prsm_app_study_load(s, doc, NULL, &pr), PRSM_EINVAL);
		assert_int_equal(pr.count, 1);
		assert_string_equal(pr.items[0].pointer, docs[k][1]);
		assert_string_equal(pr.items[0].code, "range");
		cJSON_Delete(doc);
	}
	free(s);
}

/* The sliding efficiency is efficiency_sliding; its older name, efficiency, gives the same
 * samples and a warning that it is not analyze's eta with its losses (issue 18). */
static void test_efficiency_names(void **state)
{
	(void)state;
	double mean[2];
	const char *names[2] = {"efficiency_sliding", "efficiency"};
	for (int k = 0; k < 2; k++) {
		char rest[256];
		snprintf(rest, sizeof rest,
		         ", \"outputs\": [\"backlash_um\", \"%s\"], \"specs\": {\"%s\": {\"lower\": 0.85}},"
		         " \"monte_carlo\": {\"samples\": 64, \"seed\": 3}", names[k], names[k]);
		char *t = study_text("{\"parameter\": \"friction.screw_roller_mu\", \"distribution\": \"uniform\", "
		                     "\"lower\": -0.01, \"upper\": 0.02}", rest);
		cJSON *doc = cJSON_Parse(t);
		free(t);
		assert_non_null(doc);
		prsm_io_study *s = calloc(1, sizeof *s);
		assert_non_null(s);
		prsm_problems pr, warn;
		prsm_problems_init(&pr);
		prsm_problems_init(&warn);
		assert_int_equal(prsm_app_study_load(s, doc, &warn, &pr), 0);
		cJSON_Delete(doc);
		int older = 0;
		for (int i = 0; i < warn.count; i++)
			if (strcmp(warn.items[i].code, "older_name") == 0) {
				older++;
				assert_string_equal(warn.items[i].pointer, "/outputs/1");
				assert_non_null(strstr(warn.items[i].message, "efficiency_with_losses"));
			}
		assert_int_equal(older, k == 1 ? 1 : 0);
		prsm_study_result r;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_study_run(&r, &s->study, &err), 0);
		mean[k] = r.out[1].summary.mean;
		prsm_study_result_free(&r);
		free(s);
	}
	assert_true(mean[0] == mean[1] && mean[0] > 0.85 && mean[0] < 0.95);
}

/* A study's design given as a catalogue size (nominal diameter x lead, issue 18) samples exactly
 * as the same study with the geometry the rules resolve it to written out; a bad size is
 * reported at the nominal member the user wrote. */
static void test_catalogue_size(void **state)
{
	(void)state;
	const char *rest = "\"tolerances\": [{\"parameter\": \"roller.pitch_radius_um\", \"tol_um\": 3},"
	                   " {\"parameter\": \"nut.runout_um\", \"tol_um\": 8}],"
	                   " \"outputs\": [\"backlash_um\", \"load_sharing_factor\"], \"monte_carlo\": {\"samples\": 500, \"seed\": 4}}";
	const char *op = "\"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}, \"target_axial_clearance_um\": 20";
	char text[2048];
	snprintf(text, sizeof text, "{\"design\": {\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": 10}, %s}, %s", op, rest);
	prsm_problems pr;
	prsm_io_study *a = load(text, &pr);
	assert_non_null(a);
	/* the rules of MODEL.md section 1: 5 starts, P = L / n, r_r = r_s / (n - 2), n_t = round(d / P) */
	assert_int_equal(a->design.starts, 5);
	assert_true(a->design.pitch_mm == 2.0);
	assert_true(fabs(a->design.roller_radius_mm - 5.0) < 1e-12);
	assert_int_equal(a->design.engaged_threads, 15);
	snprintf(text, sizeof text,
	         "{\"design\": {\"geometry\": {\"starts\": %d, \"pitch_mm\": %.17g, \"roller_radius_mm\": %.17g,"
	         " \"rollers\": %d, \"engaged_threads\": %d}, %s}, %s",
	         a->design.starts, a->design.pitch_mm, a->design.roller_radius_mm, a->design.rollers, a->design.engaged_threads,
	         op, rest);
	prsm_io_study *b = load(text, &pr);
	assert_non_null(b);
	prsm_study_result ra, rb;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(&ra, &a->study, &err), 0);
	assert_int_equal(prsm_study_run(&rb, &b->study, &err), 0);
	assert_int_equal(ra.run.n, rb.run.n);
	assert_memory_equal(ra.run.y, rb.run.y, ra.run.n * a->study.m * sizeof(double));
	prsm_study_result_free(&ra);
	prsm_study_result_free(&rb);
	free(a);
	free(b);
	/* refused at the member written */
	snprintf(text, sizeof text, "{\"design\": {\"nominal\": {\"diameter_mm\": 30, \"lead_mm\": -10},"
	         " \"geometry\": {\"starts\": 4}, %s}, %s", op, rest);
	assert_null(load(text, &pr));
	int lead = 0, starts = 0;
	for (int i = 0; i < pr.count; i++) {
		lead |= strcmp(pr.items[i].pointer, "/design/nominal/lead_mm") == 0;
		starts |= strcmp(pr.items[i].pointer, "/design/geometry/starts") == 0;
	}
	assert_true(lead && starts);
}

/* Issue 24, item 4: the study reader alone analyses nothing; the nominal analysis is the
 * application's hook (app/study.h), at the design step. A design whose contacts leave their
 * flanks reads without a problem, and its tolerance on an unknown parameter is reported; with
 * the hooks the edge contact comes first and, the design unusable, the parameter is not judged. */
static void test_reader_hooks(void **state)
{
	(void)state;
	cJSON *doc = cJSON_Parse("{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 10,"
	                         " \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	                         " \"target_axial_clearance_um\": 20,"
	                         " \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}},"
	                         " \"tolerances\": [{\"parameter\": \"nut.pitch_radius_um\", \"tol_um\": 3}]}");
	assert_non_null(doc);
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems pr;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_io_study_load(s, doc, NULL, NULL, &pr), 0);
	assert_int_equal(pr.count, 0);
	assert_null(s->study.model.eval); /* no hooks, no model: the study cannot run */
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_study_load(s, doc, NULL, &pr), PRSM_EEDGE);
	assert_int_equal(pr.count, 1);
	assert_string_equal(pr.items[0].pointer, "/design/geometry");
	assert_string_equal(pr.items[0].code, "edge_contact");

	/* an unknown parameter: judged when the design reads (no hooks), not beside an edge contact */
	cJSON *tol = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(doc, "tolerances"), 0);
	cJSON_ReplaceItemInObjectCaseSensitive(tol, "parameter", cJSON_CreateString("nut.no_such_um"));
	prsm_problems_init(&pr);
	assert_int_equal(prsm_io_study_load(s, doc, NULL, NULL, &pr), PRSM_EINVAL);
	assert_int_equal(pr.count, 1);
	assert_string_equal(pr.items[0].pointer, "/tolerances/0/parameter");
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_study_load(s, doc, NULL, &pr), PRSM_EEDGE);
	assert_int_equal(pr.count, 1);
	assert_string_equal(pr.items[0].code, "edge_contact");
	cJSON_Delete(doc);
	free(s);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_prsm_threads),
		cmocka_unit_test(test_per_roller_and_shared),
		cmocka_unit_test(test_copula),
		cmocka_unit_test(test_ls1),
		cmocka_unit_test(test_rss_uniform),
		cmocka_unit_test(test_ranges),
		cmocka_unit_test(test_nut_unit_stiffness),
		cmocka_unit_test(test_efficiency_names),
		cmocka_unit_test(test_catalogue_size),
		cmocka_unit_test(test_reader_hooks),
		cmocka_unit_test(test_range_hook),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
