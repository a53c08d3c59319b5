/*
 * test_study_rare.c: a study's specs estimated by the rare-event engine (issue 21 item 4,
 * docs/rare-events.md): the document's yield_method and rare_events settings through
 * io/study_json into prsm_study_run and back out as the result's rare_event section, against
 * closed forms (R - S with normals: Phi(-beta); a sum of exponentials: the gamma tail), the
 * sides of a two-sided spec added, auto keeping the Monte Carlo count where it suffices, the
 * same figures for any thread count, and bad settings refused with their pointers.
 */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "app/study.h"
#include "io/study_json.h"

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

/* R - S, R ~ N(mu_r, 1), S ~ N(2, 1), spec lower 0 with the method given. */
static char *rs_study(double mu_r, const char *method, int samples, int threads)
{
	char *t = malloc(1024);
	snprintf(t, 1024,
	         "{\"name\": \"R - S\", \"model\": {\"expression\": \"R - S\", \"inputs\": [\"R\", \"S\"]},"
	         " \"tolerances\": [{\"parameter\": \"R\", \"distribution\": \"normal\", \"mean\": %.17g, \"sd\": 1},"
	         " {\"parameter\": \"S\", \"distribution\": \"normal\", \"mean\": 2, \"sd\": 1}],"
	         " \"outputs\": [\"y\"], \"specs\": {\"y\": {\"lower\": 0, \"yield_method\": \"%s\"}},"
	         " \"monte_carlo\": {\"samples\": %d, \"seed\": 7, \"threads\": %d}}",
	         mu_r, method, samples, threads);
	return t;
}

static void run(prsm_study_result *r, prsm_io_study *s)
{
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_study_run(r, &s->study, &err);
	if (rc)
		print_message("%s\n", err.message);
	assert_int_equal(rc, 0);
}

/* FORM is exact on a limit state linear in the standard normal space: P = Phi(-5/sqrt 2) for
 * mu_R = 7 and Phi(-sqrt 2) = 0.0786496 for mu_R = 4; the design point is (R, S) = (4.5, 4.5)
 * (resp. (3, 3)), each tolerance half the importance. */
static void test_form_exact(void **state)
{
	(void)state;
	const double mu[2] = {7.0, 4.0};
	for (int c = 0; c < 2; c++) {
		char *t = rs_study(mu[c], "form", 1000, 1);
		prsm_problems pr;
		prsm_io_study *s = load(t, &pr);
		free(t);
		assert_non_null(s);
		prsm_study_result r;
		run(&r, s);
		const prsm_study_output_result *o = &r.out[0];
		assert_true(o->has_rare);
		const prsm_study_rare_side *lo = &o->rare[0];
		assert_true(lo->present && lo->ran);
		assert_false(o->rare[1].present);
		assert_int_equal(lo->method, PRSM_RARE_FORM);
		double beta = (mu[c] - 2.0) / sqrt(2.0);
		double exact = gsl_cdf_ugaussian_Q(beta);
		if (c == 1)
			assert_true(fabs(exact - 0.0786496) < 5e-8);
		else
			assert_true(fabs(exact - 2.03476e-4) < 5e-10);
		assert_true(fabs(lo->pf - exact) <= 1e-8 * exact);
		assert_true(fabs(lo->beta - beta) < 1e-7);
		assert_true(isnan(lo->lower) && isnan(lo->upper));
		assert_true(lo->has_design_point);
		double xs = 2.0 + beta / sqrt(2.0); /* the nearest point of R = S: both at mu - beta/sqrt 2 */
		assert_true(fabs(lo->x_star[0] - xs) < 1e-6 && fabs(lo->x_star[1] - xs) < 1e-6);
		assert_true(fabs(lo->importance[0] - 0.5) < 1e-6 && fabs(lo->importance[1] - 0.5) < 1e-6);
		assert_true(fabs(o->rare_ppm - 1e6 * exact) <= 1e-8 * 1e6 * exact);
		assert_true(o->rare_ppm_from_rare);
		/* the JSON carries it */
		cJSON *doc = prsm_io_study_result_to_json(s, &r);
		assert_non_null(doc);
		const cJSON *re = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "outputs"), "y"),
		                                      "rare_event");
		assert_non_null(re);
		const cJSON *l = cJSON_GetObjectItem(re, "lower");
		assert_string_equal(cJSON_GetObjectItem(l, "method")->valuestring, "form");
		assert_true(cJSON_IsNull(cJSON_GetArrayItem(cJSON_GetObjectItem(l, "interval95_ppm"), 0)));
		const cJSON *tol = cJSON_GetObjectItem(cJSON_GetObjectItem(l, "design_point"), "tolerances");
		assert_int_equal(cJSON_GetArraySize(tol), 2);
		assert_string_equal(cJSON_GetObjectItem(cJSON_GetArrayItem(tol, 1), "parameter")->valuestring, "S");
		assert_null(cJSON_GetObjectItem(re, "upper"));
		cJSON_Delete(doc);
		prsm_study_result_free(&r);
		free(s);
	}
}

/* Importance sampling and subset simulation: the exact value inside their own 95 % intervals,
 * within the evaluation budget. */
static void test_sampling_methods(void **state)
{
	(void)state;
	const char *methods[2] = {"is", "subset"};
	double exact = gsl_cdf_ugaussian_Q(5.0 / sqrt(2.0));
	for (int k = 0; k < 2; k++) {
		char *t = rs_study(7.0, methods[k], 1000, 2);
		prsm_problems pr;
		prsm_io_study *s = load(t, &pr);
		free(t);
		assert_non_null(s);
		prsm_study_result r;
		run(&r, s);
		const prsm_study_rare_side *lo = &r.out[0].rare[0];
		assert_true(lo->ran);
		assert_int_equal(lo->method, k == 0 ? PRSM_RARE_IS : PRSM_RARE_SUBSET);
		print_message("%s: %.6g [%.6g, %.6g] cov %.3g, %zu evaluations (exact %.6g)\n", methods[k], lo->pf,
		              lo->lower, lo->upper, lo->cov, lo->evaluations, exact);
		assert_true(lo->lower <= exact && exact <= lo->upper);
		assert_true(lo->cov > 0.0 && lo->cov < 0.5);
		assert_true(lo->evaluations > 0 && lo->evaluations <= 20000);
		assert_true(fabs(r.out[0].rare_ppm_low95 - 1e6 * lo->lower) < 1e-9 * 1e6 * lo->upper);
		prsm_study_result_free(&r);
		free(s);
	}
}

/* A sum of three unit exponentials above 20: P = Q_gamma(20; 3, 1) = 221 e^-20, about 4.6e-7,
 * which 2000 Monte Carlo samples never see; auto then picks a rare-event method and hits it
 * within its interval. The lower side (below 0.05, P = P_gamma(0.05; 3) = 2.0e-5) also gets one. */
static void test_auto_exponential_sum(void **state)
{
	(void)state;
	const char *text =
		"{\"model\": {\"expression\": \"a + b + c\", \"inputs\": [\"a\", \"b\", \"c\"]},"
		" \"tolerances\": [{\"parameter\": \"a\", \"distribution\": \"exponential\", \"scale\": 1},"
		" {\"parameter\": \"b\", \"distribution\": \"exponential\", \"scale\": 1},"
		" {\"parameter\": \"c\", \"distribution\": \"exponential\", \"scale\": 1}],"
		" \"outputs\": [\"y\"], \"specs\": {\"y\": {\"lower\": 0.05, \"upper\": 20, \"yield_method\": \"auto\"}},"
		" \"rare_events\": {\"max_evaluations\": 20000, \"target_cov\": 0.1},"
		" \"monte_carlo\": {\"samples\": 2000, \"seed\": 11}}";
	prsm_problems pr;
	prsm_io_study *s = load(text, &pr);
	assert_non_null(s);
	prsm_study_result r;
	run(&r, s);
	const prsm_study_output_result *o = &r.out[0];
	double exact[2] = {gsl_cdf_gamma_P(0.05, 3.0, 1.0), gsl_cdf_gamma_Q(20.0, 3.0, 1.0)};
	assert_true(fabs(exact[1] - 221.0 * exp(-20.0)) < 1e-12 * exact[1]);
	for (int k = 0; k < 2; k++) {
		const prsm_study_rare_side *sd = &o->rare[k];
		print_message("side %d: %s %.6g [%.6g, %.6g], %zu counted of %zu, %zu evaluations (exact %.6g): %s\n", k,
		              prsm_rare_method_name(sd->method), sd->pf, sd->lower, sd->upper, sd->failures, sd->n,
		              sd->evaluations, exact[k], sd->note);
		assert_true(sd->present && sd->ran);
		assert_int_equal(sd->n, 2000);
		assert_true(sd->method == PRSM_RARE_IS || sd->method == PRSM_RARE_SUBSET);
		assert_true(strncmp(sd->note, "auto: ", 6) == 0);
		assert_true(sd->lower <= exact[k] && exact[k] <= sd->upper);
	}
	assert_int_equal(o->rare[1].failures, 0);
	/* the sides add */
	assert_true(fabs(o->rare_ppm - 1e6 * (o->rare[0].pf + o->rare[1].pf)) < 1e-9 * o->rare_ppm);
	prsm_study_result_free(&r);
	free(s);
}

/* auto keeps the Monte Carlo count where it already meets the CoV target (the R - S case at
 * mu_R = 4, P = 0.079: some 315 of 4000 samples fail): no evaluation, the Wilson interval. */
static void test_auto_keeps_count(void **state)
{
	(void)state;
	char *t = rs_study(4.0, "auto", 4000, 1);
	prsm_problems pr;
	prsm_io_study *s = load(t, &pr);
	free(t);
	assert_non_null(s);
	prsm_study_result r;
	run(&r, s);
	const prsm_study_output_result *o = &r.out[0];
	const prsm_study_rare_side *lo = &o->rare[0];
	assert_false(lo->ran);
	assert_int_equal(lo->method, PRSM_RARE_MC);
	assert_int_equal(lo->evaluations, 0);
	assert_true(lo->failures > 200 && lo->failures < 450);
	assert_true(fabs(lo->pf - (double)lo->failures / 4000.0) < 1e-15);
	double wl, wh;
	prsm_stats_wilson(lo->failures, 4000, PRSM_STATS_Z95, &wl, &wh);
	assert_true(lo->lower == wl && lo->upper == wh);
	/* the count is the study's own: the summary's ppm below the limit */
	assert_true(fabs(1e6 * lo->pf - o->summary.ppm_low) < 1e-6);
	assert_false(o->rare_ppm_from_rare);
	prsm_study_result_free(&r);
	free(s);
}

/* The default (mc) adds nothing; and every figure is the same for 1 and 2 threads. */
static void test_default_and_threads(void **state)
{
	(void)state;
	char *t = rs_study(7.0, "mc", 1000, 1);
	prsm_problems pr;
	prsm_io_study *s = load(t, &pr);
	free(t);
	assert_non_null(s);
	prsm_study_result r;
	run(&r, s);
	assert_false(r.out[0].has_rare);
	cJSON *doc = prsm_io_study_result_to_json(s, &r);
	assert_null(cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "outputs"), "y"), "rare_event"));
	cJSON_Delete(doc);
	prsm_study_result_free(&r);
	free(s);

	char *json[2];
	for (int k = 0; k < 2; k++) {
		t = rs_study(7.0, "subset", 1000, k + 1);
		s = load(t, &pr);
		free(t);
		assert_non_null(s);
		run(&r, s);
		doc = prsm_io_study_result_to_json(s, &r);
		cJSON *re = cJSON_GetObjectItem(cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "outputs"), "y"), "rare_event");
		assert_non_null(re);
		json[k] = cJSON_PrintUnformatted(re);
		cJSON_Delete(doc);
		prsm_study_result_free(&r);
		free(s);
	}
	assert_string_equal(json[0], json[1]);
	free(json[0]);
	free(json[1]);
}

/* Progress names its phase: the plain run, the summaries, the rare-event estimates (counted in
 * evaluations), the Sobol run (counted in base rows over every replicate). */
typedef struct {
	char seq[16][16];
	int n;
	int rare_in_evaluations, sobol_planned_ok;
	size_t sobol_last;
} phases;

static void on_progress(void *ctx, const prsm_progress *p)
{
	phases *ph = ctx;
	const char *name = p->phase ? p->phase : "(none)";
	if (ph->n == 0 || strcmp(ph->seq[ph->n - 1], name) != 0) {
		if (ph->n < 16)
			snprintf(ph->seq[ph->n++], sizeof ph->seq[0], "%s", name);
	}
	if (p->phase && strcmp(p->phase, "rare_events") == 0)
		ph->rare_in_evaluations = p->unit && strcmp(p->unit, "evaluations") == 0;
	if (p->phase && strcmp(p->phase, "sobol") == 0) {
		ph->sobol_planned_ok = p->planned == 512 && p->done <= 512 && p->done >= ph->sobol_last;
		ph->sobol_last = p->done;
	}
}

static void test_phases(void **state)
{
	(void)state;
	const char *text =
		"{\"model\": {\"expression\": \"R - S\", \"inputs\": [\"R\", \"S\"]},"
		" \"tolerances\": [{\"parameter\": \"R\", \"distribution\": \"normal\", \"mean\": 7, \"sd\": 1},"
		" {\"parameter\": \"S\", \"distribution\": \"normal\", \"mean\": 2, \"sd\": 1}],"
		" \"outputs\": [\"y\"], \"specs\": {\"y\": {\"lower\": 0, \"yield_method\": \"is\"}},"
		" \"sensitivity\": {\"sobol\": {\"samples\": 512}},"
		" \"monte_carlo\": {\"samples\": 2048, \"block_size\": 256, \"seed\": 7}}";
	prsm_problems pr;
	prsm_io_study *s = load(text, &pr);
	assert_non_null(s);
	phases ph;
	memset(&ph, 0, sizeof ph);
	s->study.mc.progress = on_progress;
	s->study.mc.progress_ctx = &ph;
	prsm_study_result r;
	run(&r, s);
	for (int i = 0; i < ph.n; i++)
		print_message("phase %d: %s\n", i, ph.seq[i]);
	assert_int_equal(ph.n, 4);
	assert_string_equal(ph.seq[0], "monte_carlo");
	assert_string_equal(ph.seq[1], "summary");
	assert_string_equal(ph.seq[2], "rare_events");
	assert_string_equal(ph.seq[3], "sobol");
	assert_true(ph.rare_in_evaluations);
	assert_true(ph.sobol_planned_ok);
	assert_int_equal(ph.sobol_last, 512);
	prsm_study_result_free(&r);
	free(s);
}

/* Bad settings are refused with their pointers, all at once. */
static void test_refused(void **state)
{
	(void)state;
	const char *text =
		"{\"model\": {\"expression\": \"R - S\", \"inputs\": [\"R\", \"S\"]},"
		" \"tolerances\": [{\"parameter\": \"R\", \"distribution\": \"normal\", \"mean\": 7, \"sd\": 1},"
		" {\"parameter\": \"S\", \"distribution\": \"normal\", \"mean\": 2, \"sd\": 1}],"
		" \"outputs\": [\"y\"], \"specs\": {\"y\": {\"lower\": 0, \"yield_method\": \"montecarlo\"}},"
		" \"rare_events\": {\"max_evaluations\": 5, \"target_cov\": -1, \"subset_sample\": 10}}";
	prsm_problems pr;
	prsm_io_study *s = load(text, &pr);
	assert_null(s);
	const char *want[4] = {"/specs/y/yield_method", "/rare_events/max_evaluations", "/rare_events/target_cov",
	                       "/rare_events/subset_sample"};
	for (int k = 0; k < 4; k++) {
		int found = 0;
		for (int i = 0; i < pr.count; i++)
			found |= strcmp(pr.items[i].pointer, want[k]) == 0;
		if (!found)
			print_message("no problem at %s\n", want[k]);
		assert_true(found);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_form_exact),
		cmocka_unit_test(test_sampling_methods),
		cmocka_unit_test(test_auto_exponential_sum),
		cmocka_unit_test(test_auto_keeps_count),
		cmocka_unit_test(test_default_and_threads),
		cmocka_unit_test(test_refused),
		cmocka_unit_test(test_phases),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
