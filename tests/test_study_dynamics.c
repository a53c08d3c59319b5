/*
 * test_study_dynamics.c: a tolerance study with dynamic outputs (docs/vibration.md, "Monte Carlo
 * over dynamic outputs"; MODEL-DYNAMICS.md §8.6), from studies/case-a-dynamic.json cut down:
 *  - the probabilities' Wilson intervals against a direct computation of the score interval, and
 *    the screening counts against the samples' own outputs;
 *  - 1 and 2 threads give bit-identical samples (inputs, outputs, status) and summaries, with some
 *    samples integrated after the screen and the stop rule deciding on the completed blocks;
 *  - the stop rule stops at the first block whose Wilson half-widths are below the limit;
 *  - the refusals, each at its JSON pointer: a negative damping ratio, a damping tolerance
 *    reaching below 0, an unknown output, a dynamic output without the dynamics section, an
 *    unknown ring-gear parameter (with its did-you-mean), a transient analysis, a dynamics section
 *    without a dynamic output, an unknown key of dynamic_monte_carlo.
 */
#include "test_support.h"

#include "io/global.h"
#include "app/study.h"
#include "io/study_json.h"
#include "mc/study.h"

static cJSON *doc_base(int samples, double mesh_error_max_um)
{
	cJSON *doc = prsm_test_read_study("case-a-dynamic.json");
	cJSON *mc = cJSON_GetObjectItemCaseSensitive(doc, "monte_carlo");
	cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(mc, "samples"), samples);
	cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(mc, "block_size"), 16);
	cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(mc, "seed"), 7);
	cJSON *tol = cJSON_GetObjectItemCaseSensitive(doc, "tolerances");
	cJSON *t;
	cJSON_ArrayForEach(t, tol)
	{
		const cJSON *p = cJSON_GetObjectItemCaseSensitive(t, "parameter");
		if (strcmp(p->valuestring, "ring_gear.mesh_error_um") == 0)
			cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(t, "upper"), mesh_error_max_um);
	}
	/* cheap integrations: few windows, a looser tolerance */
	cJSON *dmc = cJSON_GetObjectItemCaseSensitive(doc, "dynamic_monte_carlo");
	cJSON_DeleteItemFromObjectCaseSensitive(dmc, "stop_half_width");
	cJSON_AddNumberToObject(dmc, "max_windows", 3);
	cJSON_AddNumberToObject(dmc, "rel_tol", 1e-7);
	return doc;
}

static prsm_io_study *load_doc(cJSON *doc, prsm_problems *pr)
{
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems_init(pr);
	const int rc = prsm_app_study_load(s, doc, NULL, pr);
	if (rc) {
		free(s);
		return NULL;
	}
	return s;
}

/* the problem at pointer (exactly), its message containing `text` (NULL: any) */
static void expect_problem(cJSON *doc, const char *pointer, const char *text)
{
	prsm_problems pr;
	prsm_io_study *s = load_doc(doc, &pr);
	if (s != NULL) {
		free(s);
		print_error("loaded, expected a problem at %s\n", pointer);
		fail();
	}
	int found = 0;
	for (int i = 0; i < pr.count; i++) {
		if (strcmp(pr.items[i].pointer, pointer) == 0 && (text == NULL || strstr(pr.items[i].message, text)))
			found = 1;
	}
	if (!found) {
		for (int i = 0; i < pr.count; i++)
			print_message("  %s: %s\n", pr.items[i].pointer, pr.items[i].message);
		print_error("no problem at %s (%s)\n", pointer, text ? text : "any");
		fail();
	}
	cJSON_Delete(doc);
}

static int output_of(const prsm_io_study *s, const char *name)
{
	for (size_t o = 0; o < s->study.m; o++)
		if (strcmp(s->study.outputs[o].name, name) == 0)
			return (int)o;
	return -1;
}

/* the Wilson score interval written out: (p + z^2/2n -+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n) */
static void wilson_direct(size_t k, size_t n, double *lo, double *hi)
{
	const double z = 1.959963984540054, p = (double)k / (double)n, z2 = z * z, nn = (double)n;
	const double c = p + z2 / (2.0 * nn), r = z * sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn));
	*lo = (c - r) / (1.0 + z2 / nn);
	*hi = (c + r) / (1.0 + z2 / nn);
}

/* (c) the probabilities and their intervals on a synthetic run */
static void test_wilson(void **state)
{
	(void)state;
	prsm_study st;
	memset(&st, 0, sizeof st);
	st.m = 3;
	snprintf(st.outputs[0].name, sizeof st.outputs[0].name, "contact_loss");
	snprintf(st.outputs[1].name, sizeof st.outputs[1].name, "regime");
	snprintf(st.outputs[2].name, sizeof st.outputs[2].name, "integrated");
	prsm_mc_options_default(&st.mc);
	const size_t n = 200;
	prsm_mc_result run;
	memset(&run, 0, sizeof run);
	run.n = n;
	run.m = 3;
	double *y = calloc(3 * n, sizeof *y);
	unsigned char *status = calloc(n, 1);
	int *code = calloc(n, sizeof *code);
	run.y = y;
	run.status = status;
	run.fail_code = code;
	size_t loss = 0, np = 0, integ = 0, failed = 0, noplay = 0;
	for (size_t j = 0; j < n; j++) {
		if (j % 37 == 5) {
			status[j] = PRSM_SAMPLE_FAILED;
			code[j] = j % 2 ? PRSM_EGEOMETRY : PRSM_ENOCONVERGE;
			y[3 * j] = y[3 * j + 1] = y[3 * j + 2] = NAN;
			noplay += j % 2;
			failed += 1 - j % 2;
			continue;
		}
		const int l = j % 7 == 0 || j % 11 == 0;
		y[3 * j] = l;
		y[3 * j + 1] = l && j % 3 == 0 ? 0.0 : (l && j % 3 == 1 ? 2.0 : 1.0);
		y[3 * j + 2] = l;
		loss += l;
		np += l && j % 3 == 0;
		integ += l;
	}
	prsm_study_dynamics d;
	prsm_study_dynamics_summary(&d, &st, &run);
	assert_int_equal(d.present, 1);
	const size_t kept = n - failed - noplay;
	assert_int_equal(d.contact_loss.n, kept);
	assert_int_equal(d.contact_loss.count, loss);
	assert_int_equal(d.non_periodic.count, np);
	assert_int_equal(d.integrated, integ);
	assert_int_equal(d.screened, kept - integ);
	assert_int_equal(d.failed, failed);
	assert_int_equal(d.no_play, noplay);
	double lo, hi;
	wilson_direct(loss, kept, &lo, &hi);
	assert_close(d.contact_loss.p, (double)loss / kept, 1e-15);
	assert_close(d.contact_loss.low95, lo, 1e-12);
	assert_close(d.contact_loss.high95, hi, 1e-12);
	wilson_direct(np, kept, &lo, &hi);
	assert_close(d.non_periodic.low95, lo, 1e-12);
	assert_close(d.non_periodic.high95, hi, 1e-12);
	/* no event: the interval starts at 0 exactly */
	for (size_t j = 0; j < n; j++)
		y[3 * j] = status[j] == PRSM_SAMPLE_FAILED ? NAN : 0.0;
	prsm_study_dynamics_summary(&d, &st, &run);
	assert_true(d.contact_loss.low95 == 0.0);
	wilson_direct(0, kept, &lo, &hi);
	assert_close(d.contact_loss.high95, hi, 1e-12);
	/* without the three outputs: no summary */
	snprintf(st.outputs[2].name, sizeof st.outputs[2].name, "backlash_um");
	prsm_study_dynamics_summary(&d, &st, &run);
	assert_int_equal(d.present, 0);
	free(y);
	free(status);
	free(code);
}

static void run_study(prsm_study_result *r, prsm_io_study *s, int threads)
{
	s->study.mc.threads = threads;
	prsm_error err = PRSM_ERROR_INIT;
	memset(r, 0, sizeof *r);
	const int rc = prsm_study_run(r, &s->study, &err);
	if (rc)
		print_error("study: %s\n", err.message);
	assert_int_equal(rc, 0);
}

/* (d) threads 1 and 2: the same samples bit for bit, some of them integrated; and the stop rule */
static void test_threads_identical(void **state)
{
	(void)state;
	cJSON *doc = doc_base(48, 10.0);
	cJSON *dmc = cJSON_GetObjectItemCaseSensitive(doc, "dynamic_monte_carlo");
	cJSON_AddNumberToObject(dmc, "stop_half_width", 0.25);
	prsm_problems pr;
	prsm_io_study *s = load_doc(doc, &pr);
	cJSON_Delete(doc);
	assert_non_null(s);
	assert_int_equal(s->has_dynamics, 1);
	assert_int_equal(s->study.mc.n_targets, 2);
	prsm_study_result r1, r2;
	run_study(&r1, s, 1);
	run_study(&r2, s, 2);
	assert_int_equal(r1.run.n, r2.run.n);
	const size_t n = r1.run.n, d = s->study.d, m = s->study.m;
	assert_memory_equal(r1.run.x, r2.run.x, n * d * sizeof(double));
	assert_memory_equal(r1.run.y, r2.run.y, n * m * sizeof(double));
	assert_memory_equal(r1.run.status, r2.run.status, n);
	assert_int_equal(r1.run.stop, r2.run.stop);
	assert_memory_equal(&r1.dynamics, &r2.dynamics, sizeof r1.dynamics);
	const prsm_study_dynamics *dy = &r1.dynamics;
	print_message("n %zu (stop %s): screened %zu integrated %zu failed %zu no play %zu; P(loss) %.3f [%.3f, %.3f] "
	              "P(np) %.3f\n", n, prsm_stop_reason_name(r1.run.stop), dy->screened, dy->integrated, dy->failed,
	              dy->no_play, dy->contact_loss.p, dy->contact_loss.low95, dy->contact_loss.high95, dy->non_periodic.p);
	assert_int_equal(dy->present, 1);
	assert_true(dy->integrated >= 1);      /* the screen let some through */
	assert_true(dy->screened > dy->integrated);
	/* every integrated sample lost contact in the closed form; the screened ones are P1 */
	const int ol = output_of(s, "contact_loss"), oreg = output_of(s, "regime"), oi = output_of(s, "integrated");
	assert_true(ol >= 0 && oreg >= 0 && oi >= 0);
	for (size_t j = 0; j < n; j++) {
		if (r1.run.status[j] != PRSM_SAMPLE_OK)
			continue;
		const double *y = r1.run.y + j * m;
		if (y[oi] == 0.0) {
			assert_true(y[ol] == 0.0);
			assert_true(y[oreg] == 1.0);
		}
	}
	/* the stop rule: the first block (16 samples) whose half-widths are both below 0.25 */
	assert_int_equal(r1.run.stop, PRSM_STOP_TARGET);
	assert_true(n < 48);
	assert_true(0.5 * (dy->contact_loss.high95 - dy->contact_loss.low95) < 0.25);
	assert_true(0.5 * (dy->non_periodic.high95 - dy->non_periodic.low95) < 0.25);
	/* and not one block earlier: the half-width of the count over the previous blocks */
	if (n > 16) {
		size_t kept = 0, loss = 0;
		for (size_t j = 0; j < n - 16; j++)
			if (r1.run.status[j] == PRSM_SAMPLE_OK) {
				kept++;
				loss += r1.run.y[j * m + ol] > 0.5;
			}
		double lo, hi;
		wilson_direct(loss, kept, &lo, &hi);
		size_t np = 0;
		for (size_t j = 0; j < n - 16; j++)
			if (r1.run.status[j] == PRSM_SAMPLE_OK)
				np += r1.run.y[j * m + oreg] < 0.5;
		double lo2, hi2;
		wilson_direct(np, kept, &lo2, &hi2);
		assert_true(0.5 * (hi - lo) >= 0.25 || 0.5 * (hi2 - lo2) >= 0.25);
	}
	prsm_study_result_free(&r1);
	prsm_study_result_free(&r2);
	free(s);
}

/* (f) lyapunov_max as a study output (§8.6): on screened case-A samples the axial mode decides,
 * -zeta_a omega_a with omega_a = sqrt(k_a / m_a), k_a the sample's nut unit stiffness (an output
 * of its own) and zeta_a its damping ratio (an input): lyapunov_max / (zeta sqrt(k_a)) is
 * -1 / sqrt(m_a), the same for every sample up to the roundings of k_a's unit conversions
 * (some 1e-15; 1e-12 asserted). An integrated sample's (Benettin) is checked in test_vib_mc. */
static void test_lyapunov_output(void **state)
{
	(void)state;
	cJSON *doc = doc_base(32, 6.0); /* below the contact-loss threshold: (nearly) all screened */
	cJSON *outs = cJSON_GetObjectItemCaseSensitive(doc, "outputs");
	cJSON_AddItemToArray(outs, cJSON_CreateString("lyapunov_max"));
	cJSON_AddItemToArray(outs, cJSON_CreateString("nut_unit_stiffness_N_per_um"));
	prsm_problems pr;
	prsm_io_study *s = load_doc(doc, &pr);
	cJSON_Delete(doc);
	assert_non_null(s);
	prsm_study_result r;
	run_study(&r, s, 1);
	const size_t n = r.run.n, d = s->study.d, m = s->study.m;
	const int ly = output_of(s, "lyapunov_max"), ok = output_of(s, "nut_unit_stiffness_N_per_um"),
	          oi = output_of(s, "integrated");
	assert_true(ly >= 0 && ok >= 0 && oi >= 0);
	size_t iz = d;
	for (size_t i = 0; i < d; i++)
		if (strcmp(s->study.info[i].name, "damping_ratio") == 0)
			iz = i;
	assert_true(iz < d);
	double c0 = NAN;
	int screened = 0, integrated = 0;
	for (size_t j = 0; j < n; j++) {
		if (r.run.status[j] != PRSM_SAMPLE_OK)
			continue;
		const double *y = r.run.y + j * m, zeta = r.run.x[j * d + iz];
		assert_true(isfinite(y[ly]));
		if (y[oi] != 0.0) {
			integrated++;
			continue;
		}
		const double cj = y[ly] / (zeta * sqrt(y[ok] * 1e6));
		if (isnan(c0))
			c0 = cj;
		assert_close(cj, c0, 1e-12 * fabs(c0));
		screened++;
	}
	print_message("%d screened samples: lyapunov_max / (zeta sqrt(k_a)) = %.12g kg^-1/2 (m_a %.6g kg); %d "
	              "integrated\n", screened, c0, 1.0 / (c0 * c0), integrated);
	assert_true(screened >= 8);
	assert_true(c0 < 0.0);
	prsm_study_result_free(&r);
	free(s);
}

/* (e) the refusals at their pointers */
static void test_refusals(void **state)
{
	(void)state;
	cJSON *doc, *dyn;
	/* a negative damping ratio in the dynamics section */
	doc = doc_base(16, 10.0);
	dyn = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "dynamics"), "vibration");
	cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(dyn, "mesh_damping_ratio"), -0.02);
	expect_problem(doc, "/dynamics/vibration/mesh_damping_ratio", NULL);
	/* a damping tolerance reaching below 0 */
	doc = doc_base(16, 10.0);
	cJSON *t;
	cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(doc, "tolerances"))
	if (strcmp(cJSON_GetObjectItemCaseSensitive(t, "parameter")->valuestring, "damping_ratio") == 0)
		cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(t, "lower"), -0.01);
	const int nt = cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(doc, "tolerances"));
	char tp[64];
	snprintf(tp, sizeof tp, "/tolerances/%d", nt - 1);
	expect_problem(doc, tp, "in (0, 1)");
	/* an unknown output */
	doc = doc_base(16, 10.0);
	cJSON *outs = cJSON_GetObjectItemCaseSensitive(doc, "outputs");
	cJSON_AddItemToArray(outs, cJSON_CreateString("peak_dynamic_te_mm"));
	snprintf(tp, sizeof tp, "/outputs/%d", cJSON_GetArraySize(outs) - 1);
	expect_problem(doc, tp, "unknown output");
	/* a dynamic output without the dynamics section */
	doc = doc_base(16, 10.0);
	cJSON_DeleteItemFromObjectCaseSensitive(doc, "dynamics");
	expect_problem(doc, "/dynamics", "needs the dynamics section");
	/* an unknown ring-gear parameter: did you mean */
	doc = doc_base(16, 10.0);
	cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(doc, "tolerances"))
	if (strcmp(cJSON_GetObjectItemCaseSensitive(t, "parameter")->valuestring, "ring_gear.mesh_error_um") == 0)
		cJSON_SetValuestring(cJSON_GetObjectItemCaseSensitive(t, "parameter"), "ring_gear.mesh_eror_um");
	snprintf(tp, sizeof tp, "/tolerances/%d/parameter", nt - 2);
	expect_problem(doc, tp, "did you mean 'ring_gear.mesh_error_um'");
	/* the transient analysis */
	doc = doc_base(16, 10.0);
	cJSON_SetValuestring(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "dynamics"), "analysis"),
	                     "transient");
	expect_problem(doc, "/dynamics/vibration", "vibration analyses");
	/* a dynamics section without a dynamic output */
	doc = doc_base(16, 10.0);
	cJSON_ReplaceItemInObjectCaseSensitive(doc, "outputs", cJSON_CreateStringArray((const char *[]){"backlash_um"}, 1));
	expect_problem(doc, "/dynamics", "for dynamic outputs");
	/* an unknown key of dynamic_monte_carlo */
	doc = doc_base(16, 10.0);
	cJSON_AddNumberToObject(cJSON_GetObjectItemCaseSensitive(doc, "dynamic_monte_carlo"), "stop_halfwidth", 0.02);
	expect_problem(doc, "/dynamic_monte_carlo/stop_halfwidth", NULL);
	/* and the document itself loads */
	doc = doc_base(16, 10.0);
	prsm_problems pr;
	prsm_io_study *s = load_doc(doc, &pr);
	for (int i = 0; s == NULL && i < pr.count; i++)
		print_message("  %s: %s\n", pr.items[i].pointer, pr.items[i].message);
	assert_non_null(s);
	assert_int_equal(s->dynamics.n_orders, 5);
	assert_close(s->dynamics.window_rev, 8.0, 0.0);
	free(s);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_wilson),
		cmocka_unit_test(test_refusals),
		cmocka_unit_test(test_threads_identical),
		cmocka_unit_test(test_lyapunov_output),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
