/*
 * test_alloc_io.c: the allocation document end to end (io/allocation_json.h): analytic
 * documents reproduce the closed forms of benchmarks.md (LS-1 at 99.73 % with a reciprocal
 * cost, worst case with k = 2.7, exponential cost with RSS by its stationarity) to 1e-6; the
 * Monte Carlo-corrected case-A allocation (studies/allocate-case-a.json with fewer samples)
 * meets its target within its Wilson interval and the next wider step did not; results are
 * identical on 1 and 2 threads; cancellation before and during the run; and the document's
 * error paths, each at its JSON pointer.
 */
#include "test_support.h"

#include <gsl/gsl_errno.h>
#include <stdlib.h>
#include <string.h>

#include "app/allocate.h"
#include "app/study.h"
#include "io/allocation_json.h"
#include "io/global.h"
#include "util/file.h"

static cJSON *parse(const char *text)
{
	cJSON *doc = cJSON_Parse(text);
	assert_non_null(doc);
	return doc;
}

static cJSON *run_ok(const cJSON *doc, int threads)
{
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	int rc = prsm_app_allocate(&res, doc, NULL, NULL, NULL, 0.0, threads, &pr, &err);
	if (rc) {
		for (int i = 0; i < pr.count; i++)
			print_error("%s: %s\n", pr.items[i].pointer, pr.items[i].message);
		print_error("%s\n", err.message);
	}
	assert_int_equal(rc, 0);
	assert_non_null(res);
	return res;
}

static double num(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	assert_true(cJSON_IsNumber(v));
	return v->valuedouble;
}

static const cJSON *item(const cJSON *o, const char *key)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
	assert_non_null(v);
	return v;
}

static void assert_rel(double a, double e, double rel)
{
	assert_close(a, e, rel * fabs(e));
}

static const char *LS1 =
	"{\"analytic\": {\"outputs\": [{\"name\": \"y\", \"nominal\": 0.1}]},"
	" \"allocate\": ["
	"  {\"parameter\": \"x1\", \"sensitivities\": {\"y\": 1}, \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.5}},"
	"  {\"parameter\": \"x2\", \"sensitivities\": {\"y\": 1}, \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.4}},"
	"  {\"parameter\": \"x3\", \"sensitivities\": {\"y\": -1}, \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.3}},"
	"  {\"parameter\": \"x4\", \"sensitivities\": {\"y\": -1}, \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.2}}],"
	" \"constraints\": [{\"output\": \"y\", \"spec\": {\"lower\": 0, \"upper\": 0.2}, \"target_ppm\": 44.557090604135930}]}";

/* LS-1 at its own 44.557 ppm: sigma_Y = 0.0244948974278318, T_asm = 3 sigma; reciprocal cost,
 * RSS: T_i = mu B_i^{1/3} (c_i^2 = 1). */
static void test_ls1(void **state)
{
	(void)state;
	cJSON *doc = parse(LS1);
	cJSON *res = run_ok(doc, 0);
	const double B[4] = {0.5, 0.4, 0.3, 0.2}, tasm = 3.0 * 0.024494897427831785;
	double s = 0.0;
	for (int i = 0; i < 4; i++)
		s += pow(B[i], 2.0 / 3.0);
	const cJSON *tols = item(res, "tolerances");
	for (int i = 0; i < 4; i++)
		assert_rel(num(cJSON_GetArrayItem(tols, i), "half_width"), tasm / sqrt(s) * cbrt(B[i]), 1e-6);
	const cJSON *c = cJSON_GetArrayItem(item(res, "constraints"), 0);
	assert_rel(num(c, "assembly_tolerance"), tasm, 1e-9);
	assert_close(num(c, "predicted_yield"), 1.0 - 44.557090604135930e-6, 1e-9);
	assert_true(cJSON_IsTrue(item(c, "meets_target")));
	assert_true(cJSON_IsNull(item(c, "monte_carlo")));
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* Worst case, reciprocal power k = 2.7: T_i = T_asm (B_i/|c_i|)^{1/(k+1)} / sum |c_j| (B_j/|c_j|)^{1/(k+1)}. */
static void test_worst_case_power(void **state)
{
	(void)state;
	cJSON *doc = parse(
		"{\"analytic\": {\"outputs\": [{\"name\": \"gap_um\", \"nominal\": 21.7}]},"
		" \"allocate\": ["
		"  {\"parameter\": \"a_um\", \"sensitivities\": {\"gap_um\": 1.2}, \"cost\": {\"model\": \"reciprocal_power\", \"coefficient\": 2.385, \"power\": 2.7}},"
		"  {\"parameter\": \"b_um\", \"sensitivities\": {\"gap_um\": -0.8}, \"cost\": {\"model\": \"reciprocal_power\", \"coefficient\": 1.3, \"power\": 2.7}},"
		"  {\"parameter\": \"c_um\", \"sensitivities\": {\"gap_um\": 2.5}, \"cost\": {\"model\": \"reciprocal_power\", \"coefficient\": 0.71, \"power\": 2.7}}],"
		" \"constraints\": [{\"output\": \"gap_um\", \"spec\": {\"lower\": 5, \"upper\": 35}, \"target_yield_percent\": 99}],"
		" \"stack\": \"worst_case\"}");
	cJSON *res = run_ok(doc, 0);
	const double B[3] = {2.385, 1.3, 0.71}, C[3] = {1.2, 0.8, 2.5}, k = 2.7, tasm = 13.3;
	double s = 0.0;
	for (int i = 0; i < 3; i++)
		s += C[i] * pow(B[i] / C[i], 1.0 / (k + 1.0));
	const cJSON *tols = item(res, "tolerances");
	for (int i = 0; i < 3; i++)
		assert_rel(num(cJSON_GetArrayItem(tols, i), "half_width"), tasm / s * pow(B[i] / C[i], 1.0 / (k + 1.0)), 1e-6);
	assert_rel(num(cJSON_GetArrayItem(item(res, "constraints"), 0), "assembly_tolerance"), tasm, 1e-12);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* Exponential cost with RSS, an assembly tolerance given: m B e^{-mT} = 2 lambda c^2 T. */
static void test_exponential(void **state)
{
	(void)state;
	cJSON *doc = parse(
		"{\"analytic\": {\"outputs\": [{\"name\": \"y\", \"nominal\": 0}]},"
		" \"allocate\": ["
		"  {\"parameter\": \"x1\", \"sensitivities\": {\"y\": 1.2}, \"cost\": {\"model\": \"exponential\", \"coefficient\": 2.385, \"rate\": 31.7, \"fixed\": 1}},"
		"  {\"parameter\": \"x2\", \"sensitivities\": {\"y\": -0.8}, \"cost\": {\"model\": \"exponential\", \"coefficient\": 1.3, \"rate\": 12.2}}],"
		" \"constraints\": [{\"output\": \"y\", \"assembly_tolerance\": 0.0735}]}");
	cJSON *res = run_ok(doc, 0);
	const double B[2] = {2.385, 1.3}, C[2] = {1.2, -0.8}, m[2] = {31.7, 12.2};
	const cJSON *c = cJSON_GetArrayItem(item(res, "constraints"), 0);
	double lambda = num(c, "multiplier"), stack = 0.0;
	for (int i = 0; i < 2; i++) {
		double t = num(cJSON_GetArrayItem(item(res, "tolerances"), i), "half_width");
		assert_rel(m[i] * B[i] * exp(-m[i] * t), 2.0 * lambda * C[i] * C[i] * t, 1e-9);
		stack += C[i] * C[i] * t * t;
	}
	assert_rel(sqrt(stack), 0.0735, 1e-12);
	assert_true(cJSON_IsNull(item(c, "spec")));
	assert_true(cJSON_IsNull(item(c, "predicted_yield")));
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* studies/allocate-case-a.json with samples cut to n. */
static cJSON *alloc_case_a(size_t samples)
{
	cJSON *doc = prsm_test_read_study("allocate-case-a.json");
	cJSON *mc = cJSON_GetObjectItemCaseSensitive(doc, "monte_carlo");
	cJSON_ReplaceItemInObject(mc, "samples", cJSON_CreateNumber((double)samples));
	return doc;
}

static void test_case_a_corrected(void **state)
{
	(void)state;
	cJSON *doc = alloc_case_a(2048);
	cJSON *res = run_ok(doc, 1);
	const cJSON *c = cJSON_GetArrayItem(item(res, "constraints"), 0);
	const double target = num(c, "target_yield");
	const cJSON *mc = item(c, "monte_carlo");
	const double y = num(mc, "fraction");
	const cJSON *iv = item(mc, "interval95");
	/* accepted on the evidence: the interval's lower end at or above the target */
	assert_true(y >= target);
	assert_true(cJSON_GetArrayItem(iv, 0)->valuedouble >= target);
	assert_true(cJSON_GetArrayItem(iv, 0)->valuedouble <= target + 0.01);
	assert_true(cJSON_IsTrue(item(c, "meets_target")));
	const cJSON *cor = item(res, "correction");
	assert_true(cJSON_IsTrue(item(cor, "converged")));
	/* a step with a larger scale failed, and it is within the bracket's tolerance */
	const double f = num(cor, "scale");
	double f_fail = INFINITY;
	const cJSON *st;
	cJSON_ArrayForEach(st, item(cor, "steps")) {
		if (!cJSON_IsTrue(item(st, "meets_target")))
			f_fail = fmin(f_fail, num(st, "scale"));
		else
			assert_true(num(st, "scale") <= f);
	}
	assert_true(f_fail > f && f_fail <= f * 1.0101);
	/* the cost at the reported allocation sums its tolerances' costs */
	double total = 0.0;
	const cJSON *t;
	cJSON_ArrayForEach(t, item(res, "tolerances"))
		total += num(t, "cost");
	assert_rel(num(res, "total_cost"), total, 1e-12);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* Issue 19, item 1: a correction step meets its target only when the lower end of the yield's
 * 95 % Wilson interval does, so an accepted allocation truly meets it. With 8,192 samples and
 * seed 2 the point-estimate rule accepted widths whose true yield was 99.624 % against the
 * 99.73 % target. The reported widths are checked by an independent run of the study (65,536
 * samples, another seed): its yield must not be significantly below the target. */
static void test_case_a_meets_truly(void **state)
{
	(void)state;
	cJSON *doc = alloc_case_a(8192);
	cJSON *mc = cJSON_GetObjectItemCaseSensitive(doc, "monte_carlo");
	cJSON_DeleteItemFromObjectCaseSensitive(mc, "seed");
	cJSON_AddNumberToObject(mc, "seed", 2);
	cJSON *res = run_ok(doc, 0);
	const cJSON *c = cJSON_GetArrayItem(item(res, "constraints"), 0);
	const double target = num(c, "target_yield");
	assert_true(cJSON_IsTrue(item(c, "meets_target")));
	const cJSON *cm = item(c, "monte_carlo");
	assert_true(cJSON_GetArrayItem(item(cm, "interval95"), 0)->valuedouble >= target);
	assert_true(num(cm, "confidence_meets_target") >= 0.975);

	/* the study at the reported widths, run afresh */
	prsm_io_allocation *d = NULL;
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_io_study_options study;
	prsm_app_study_options(&study);
	assert_int_equal(prsm_io_allocation_read(&d, doc, 0, &study, NULL, &pr), 0);
	prsm_study *s = &d->study->study;
	size_t i = 0;
	const cJSON *t;
	cJSON_ArrayForEach(t, item(res, "tolerances")) {
		const prsm_study_group *gr = &s->groups[d->opt.group[i++]];
		const double r = num(t, "half_width") / num(t, "reference_half_width");
		for (size_t v = gr->first_var; v < gr->first_var + gr->n_vars; v++)
			if (s->info[v].phase_of < 0) {
				const prsm_dist ref = s->vars[v].dist;
				assert_int_equal(prsm_alloc_dist_scale(&s->vars[v].dist, &ref, r), 0);
			}
	}
	s->mc.samples = 65536;
	s->mc.seed = 7;
	s->mc.n_targets = 0;
	s->sens.src = s->sens.stack = s->sens.sobol = 0;
	prsm_study_result *sr = calloc(1, sizeof *sr);
	assert_non_null(sr);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(sr, s, &err), 0);
	const prsm_stats_summary *sm = &sr->out[d->opt.output[0]].summary;
	const double se = sqrt(target * (1.0 - target) / (double)sm->n);
	print_message("accepted at the Wilson lower end: independent yield %.5f (target %.4f, se %.5f)\n",
	              sm->yield, target, se);
	assert_true(sm->yield >= target - 3.0 * se);
	prsm_study_result_free(sr);
	free(sr);
	prsm_io_allocation_free(d);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

static void strip(cJSON *res)
{
	cJSON_DeleteItemFromObject(res, "elapsed_s");
	cJSON_DeleteItemFromObject(cJSON_GetObjectItemCaseSensitive(res, "monte_carlo"), "threads");
}

static void test_threads(void **state)
{
	(void)state;
	cJSON *doc = alloc_case_a(2048);
	cJSON *a = run_ok(doc, 1), *b = run_ok(doc, 2);
	strip(a);
	strip(b);
	char *ta = cJSON_PrintUnformatted(a), *tb = cJSON_PrintUnformatted(b);
	assert_string_equal(ta, tb);
	free(ta);
	free(tb);
	cJSON_Delete(a);
	cJSON_Delete(b);
	cJSON_Delete(doc);
}

typedef struct {
	prsm_cancel_flag *cancel;
	size_t cancel_at;      /* samples done at which to cancel */
	size_t calls;
} cancel_ctx;

static void cancel_progress(void *ctx, const prsm_progress *p)
{
	cancel_ctx *c = ctx;
	c->calls++;
	assert_true(p->done <= p->planned);
	if (p->done >= c->cancel_at)
		*c->cancel = 1;
}

static void test_cancel(void **state)
{
	(void)state;
	cJSON *doc = alloc_case_a(2048);
	prsm_problems pr;
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	prsm_cancel_flag cancel = 1;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_allocate(&res, doc, &cancel, NULL, NULL, 0.0, 1, &pr, &err),
	                 PRSM_ECANCELLED);
	assert_null(res);
	/* cancelled after the first run met the target at some scale: best so far comes back */
	cancel = 0;
	cancel_ctx cc = {&cancel, 2048, 0};
	assert_int_equal(prsm_app_allocate(&res, doc, &cancel, cancel_progress, &cc, 0.0, 1, &pr, &err),
	                 PRSM_ECANCELLED);
	assert_true(cc.calls > 0);
	assert_non_null(res);
	assert_true(cJSON_IsTrue(item(res, "cancelled")));
	assert_string_equal(item(item(res, "correction"), "stop_reason")->valuestring, "cancelled");
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* A yield target and a given assembly tolerance together (case A's backlash at 99.73 % and
 * load_sharing_factor within 0.4, RSS): the correction scales the backlash limit only; the
 * given 0.4 stays 0.4 at every step, binds at the reported one and is met there. */
static void test_mixed_targets(void **state)
{
	(void)state;
	cJSON *doc = alloc_case_a(4096);
	cJSON *outs = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "study"), "outputs");
	cJSON_AddItemToArray(outs, cJSON_CreateString("load_sharing_factor"));
	cJSON_AddItemToArray(cJSON_GetObjectItemCaseSensitive(doc, "constraints"),
	                     parse("{\"output\": \"load_sharing_factor\", \"assembly_tolerance\": 0.4}"));
	cJSON *res = run_ok(doc, 1);
	const cJSON *cor = item(res, "correction");
	const double f = num(cor, "scale");
	assert_true(cJSON_IsTrue(item(cor, "converged")));
	assert_true(fabs(f - 1.0) > 0.05); /* the correction moved: the test means something */
	const cJSON *bl = cJSON_GetArrayItem(item(res, "constraints"), 0);
	const cJSON *ls = cJSON_GetArrayItem(item(res, "constraints"), 1);
	assert_rel(num(bl, "assembly_tolerance"), f * num(bl, "assembly_tolerance_linear"), 1e-12);
	assert_true(cJSON_IsTrue(item(bl, "meets_target")));
	assert_close(num(ls, "assembly_tolerance"), 0.4, 0.0);
	assert_close(num(ls, "assembly_tolerance_linear"), 0.4, 0.0);
	assert_true(num(ls, "multiplier") > 0.0); /* binding at the reported step */
	assert_rel(num(ls, "stack"), 0.4, 1e-9);
	assert_true(num(ls, "stack") <= 0.4 * (1.0 + 1e-9));
	assert_true(cJSON_IsTrue(item(ls, "meets_target")));
	assert_true(cJSON_IsNull(item(ls, "target_yield")));
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* A time cap that ends before the first Monte Carlo run: the linear allocation comes back
 * unverified, stop time_cap, not converged (no step read out of range). */
static void test_time_cap(void **state)
{
	(void)state;
	cJSON *doc = alloc_case_a(2048);
	prsm_problems pr;
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_allocate(&res, doc, NULL, NULL, NULL, 1e-9, 1, &pr, &err), 0);
	assert_non_null(res);
	const cJSON *cor = item(res, "correction");
	assert_string_equal(item(cor, "stop_reason")->valuestring, "time_cap");
	assert_true(cJSON_IsFalse(item(cor, "converged")));
	assert_int_equal(cJSON_GetArraySize(item(cor, "steps")), 1);
	const cJSON *st = cJSON_GetArrayItem(item(cor, "steps"), 0);
	assert_true(cJSON_IsTrue(item(st, "reported")));
	assert_true(cJSON_IsNull(cJSON_GetArrayItem(item(st, "yields"), 0)));
	assert_close(num(item(res, "monte_carlo"), "samples_total"), 0.0, 0.0);
	assert_close(num(cor, "scale"), 1.0, 0.0);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

/* The nominal outside a spec: refused at the constraint's spec with a readable message. */
static void test_spec_message(void **state)
{
	(void)state;
	cJSON *doc = parse(LS1);
	cJSON *c0 = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(doc, "constraints"), 0);
	cJSON_ReplaceItemInObject(c0, "spec", parse("{\"lower\": 0.15, \"upper\": 0.2}"));
	prsm_problems pr;
	prsm_problems_init(&pr);
	assert_int_equal(prsm_app_allocation_check(doc, 0, NULL, &pr), PRSM_EINVAL);
	assert_int_equal(pr.count, 1);
	assert_string_equal(pr.items[0].pointer, "/constraints/0/spec");
	assert_string_equal(pr.items[0].message,
	                    "output 0: the nominal 0.1 is not strictly inside the spec: no tolerance can meet it");
	cJSON_Delete(doc);
}

/* Extreme but valid figures: a 1e300 assembly tolerance is simply slack (every tolerance at its
 * upper bound), a 1e100 cost coefficient is solved like any other. */
static void test_extremes(void **state)
{
	(void)state;
	cJSON *doc = parse(LS1);
	cJSON *c0 = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(doc, "constraints"), 0);
	cJSON_DeleteItemFromObject(c0, "target_ppm");
	cJSON_AddItemToObject(c0, "assembly_tolerance", cJSON_CreateNumber(1e300));
	cJSON *a;
	cJSON_ArrayForEach(a, cJSON_GetObjectItemCaseSensitive(doc, "allocate"))
		cJSON_AddItemToObject(a, "bounds", parse("{\"lower\": 0.005, \"upper\": 0.2}"));
	cJSON *res = run_ok(doc, 0);
	const cJSON *t;
	cJSON_ArrayForEach(t, item(res, "tolerances"))
		assert_close(num(t, "half_width"), 0.2, 0.0);
	cJSON_Delete(res);
	/* LS-1 with every cost coefficient times 1e99: the same half-widths */
	cJSON_Delete(doc);
	doc = parse(LS1);
	cJSON *ref = run_ok(doc, 0);
	cJSON_ArrayForEach(a, cJSON_GetObjectItemCaseSensitive(doc, "allocate")) {
		cJSON *cost = cJSON_GetObjectItemCaseSensitive(a, "cost");
		double b = num(cost, "coefficient");
		cJSON_ReplaceItemInObject(cost, "coefficient", cJSON_CreateNumber(b * 1e99));
	}
	res = run_ok(doc, 0);
	for (int i = 0; i < 4; i++)
		assert_rel(num(cJSON_GetArrayItem(item(res, "tolerances"), i), "half_width"),
		           num(cJSON_GetArrayItem(item(ref, "tolerances"), i), "half_width"), 1e-12);
	assert_rel(num(res, "total_cost"), 1e99 * num(ref, "total_cost"), 1e-12);
	cJSON_Delete(res);
	cJSON_Delete(ref);
	cJSON_Delete(doc);
}

/* The document with one member replaced (JSON text), checked: the problem at pointer. */
static void expect_problem(const char *base, const char *path_key, const char *value_json, const char *pointer,
                           size_t max_samples)
{
	cJSON *doc = parse(base);
	cJSON *parent = doc;
	char keys[256];
	snprintf(keys, sizeof keys, "%s", path_key);
	char *tok = keys;
	for (char *slash = strchr(tok, '/'); slash; slash = strchr(tok, '/')) {
		*slash = 0;
		cJSON *child = cJSON_IsArray(parent) ? cJSON_GetArrayItem(parent, (int)strtol(tok, NULL, 10))
		                                     : cJSON_GetObjectItemCaseSensitive(parent, tok);
		assert_non_null(child);
		parent = child;
		tok = slash + 1;
	}
	if (cJSON_IsArray(parent)) {
		assert_non_null(value_json);
		cJSON_ReplaceItemInArray(parent, (int)strtol(tok, NULL, 10), parse(value_json));
	} else {
		if (cJSON_GetObjectItemCaseSensitive(parent, tok))
			cJSON_DeleteItemFromObject(parent, tok);
		if (value_json)
			cJSON_AddItemToObject(parent, tok, parse(value_json));
	}
	prsm_problems pr;
	prsm_problems_init(&pr);
	int rc = prsm_app_allocation_check(doc, max_samples, NULL, &pr);
	int found = 0;
	for (int i = 0; i < pr.count; i++)
		found |= strcmp(pr.items[i].pointer, pointer) == 0;
	if (!found || rc != PRSM_EINVAL) {
		print_error("%s = %s: rc %d, expected a problem at %s; got:\n", path_key, value_json ? value_json : "(deleted)",
		            rc, pointer);
		for (int i = 0; i < pr.count; i++)
			print_error("  %s: %s\n", pr.items[i].pointer, pr.items[i].message);
		fail();
	}
	cJSON_Delete(doc);
}

static void test_errors(void **state)
{
	(void)state;
	expect_problem(LS1, "allocate/0/cost/coefficient", "-1", "/allocate/0/cost/coefficient", 0);
	expect_problem(LS1, "allocate/0/cost/model", "\"quadratic\"", "/allocate/0/cost/model", 0);
	expect_problem(LS1, "allocate/0/cost/power", "2", "/allocate/0/cost/power", 0);
	expect_problem(LS1, "allocate/1/bounds", "{\"lower\": 0.3, \"upper\": 0.2}", "/allocate/1/bounds/upper", 0);
	expect_problem(LS1, "allocate/1/bounds", "{\"lower\": -0.1}", "/allocate/1/bounds/lower", 0);
	expect_problem(LS1, "allocate/2/sensitivities", "{\"z\": 1}", "/allocate/2/sensitivities/z", 0);
	expect_problem(LS1, "allocate/2/sd_ratio", "0", "/allocate/2/sd_ratio", 0);
	expect_problem(LS1, "constraints/0/target_ppm", "0", "/constraints/0/target_ppm", 0);
	expect_problem(LS1, "constraints/0/target_yield_percent", "99", "/constraints/0", 0);
	expect_problem(LS1, "constraints/0/target_ppm", NULL, "/constraints/0", 0);
	expect_problem(LS1, "constraints/0/output", "\"q\"", "/constraints/0/output", 0);
	expect_problem(LS1, "constraints/0/spec", "{\"lower\": 0.3, \"upper\": 0.2}", "/constraints/0/spec/upper", 0);
	/* the nominal outside the spec: no allocation meets it */
	expect_problem(LS1, "constraints/0/spec", "{\"lower\": 0.15, \"upper\": 0.2}", "/constraints/0/spec", 0);
	/* the lower bounds alone break the limit */
	expect_problem(LS1, "allocate/0/bounds", "{\"lower\": 0.09}", "/constraints/0", 0);
	/* cost figures beyond 1e100 (their costs would overflow) */
	expect_problem(LS1, "allocate/0/cost/coefficient", "1e308", "/allocate/0/cost/coefficient", 0);
	expect_problem(LS1, "allocate/0/cost/fixed", "1e200", "/allocate/0/cost/fixed", 0);
	expect_problem(LS1, "monte_carlo", "{\"samples\": 100}", "/monte_carlo", 0);
	expect_problem(LS1, "stack", "\"sum\"", "/stack", 0);
	/* issue 19, item 8: a huge but finite figure is refused at its field, not as "not finite" */
	expect_problem(LS1, "allocate/0/sensitivities/y", "1e308", "/allocate/0/sensitivities/y", 0);
	expect_problem(LS1, "analytic/outputs/0/nominal", "-1e200", "/analytic/outputs/0/nominal", 0);
	expect_problem(LS1, "study", "{}", "/analytic", 0);
	expect_problem(LS1, "extra", "1", "/extra", 0);
	expect_problem(LS1, "allocate", "[]", "/allocate", 0);
	/* a study */
	cJSON *ca = alloc_case_a(2048);
	char *a = cJSON_PrintUnformatted(ca);
	cJSON_Delete(ca);
	expect_problem(a, "monte_carlo/samples", "1000000", "/monte_carlo/samples", 200000);
	expect_problem(a, "monte_carlo/max_corrections", "31", "/monte_carlo/max_corrections", 0);
	/* 1,419 samples at least can show 99.73 % (none out of spec): fewer are refused */
	expect_problem(a, "monte_carlo/samples", "1418", "/monte_carlo/samples", 0);
	expect_problem(a, "allocate/0/parameter", "\"screw.tilt_mrad\"", "/allocate/0/parameter", 0);
	expect_problem(a, "allocate/1/parameter", "\"screw.pitch_radius_um\"", "/allocate/1/parameter", 0);
	expect_problem(a, "constraints/0/output", "\"te_pp_um\"", "/constraints/0/output", 0);
	expect_problem(a, "study/monte_carlo/samples", "-5", "/study/monte_carlo/samples", 0);
	expect_problem(a, "study/tolerances/5", "{\"parameter\": \"nut.runout_um\", \"distribution\": \"lognormal\", "
	               "\"mu\": 0.5, \"sigma\": 0.3}", "/allocate/8/parameter", 0);
	free(a);
}

/* LS-1 as a study (an expression model) whose correction judges the yield by a rare-event
 * method (issue 21 item 4): at 44.557 ppm, 2000 samples could never show the target (the
 * sample-count check stands aside for a rare-event yield), FORM is exact on this linear stack
 * of normals, so the linear allocation (f = 1) meets the target to rounding and the correction
 * ends there; with importance sampling the target is judged on the interval's far end, so the
 * accepted allocation is a little tighter. The analytic stack refuses yield_method. */
static const char *LS1_STUDY =
	"{\"study\": {\"model\": {\"expression\": \"0.1 + x1 + x2 - x3 - x4\", \"inputs\": [\"x1\", \"x2\", \"x3\", \"x4\"]},"
	"   \"tolerances\": [{\"parameter\": \"x1\", \"tol\": 0.02}, {\"parameter\": \"x2\", \"tol\": 0.02},"
	"                   {\"parameter\": \"x3\", \"tol\": 0.02}, {\"parameter\": \"x4\", \"tol\": 0.02}],"
	"   \"outputs\": [\"y\"], \"specs\": {\"y\": {\"lower\": 0, \"upper\": 0.2}},"
	"   \"monte_carlo\": {\"samples\": 2000, \"seed\": 5}},"
	" \"allocate\": ["
	"  {\"parameter\": \"x1\", \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.5}},"
	"  {\"parameter\": \"x2\", \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.4}},"
	"  {\"parameter\": \"x3\", \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.3}},"
	"  {\"parameter\": \"x4\", \"cost\": {\"model\": \"reciprocal\", \"coefficient\": 0.2}}],"
	" \"constraints\": [{\"output\": \"y\", \"target_ppm\": 44.557090604135930, \"yield_method\": \"";

static void test_rare_yield(void **state)
{
	(void)state;
	const double p0 = 1.0 - 44.557090604135930e-6;
	for (int k = 0; k < 2; k++) {
		char text[2048];
		snprintf(text, sizeof text, "%s%s\"}]}", LS1_STUDY, k == 0 ? "form" : "is");
		cJSON *doc = parse(text);
		cJSON *res = run_ok(doc, 2);
		const cJSON *c0 = cJSON_GetArrayItem(item(res, "constraints"), 0);
		const cJSON *mc = item(c0, "monte_carlo");
		const cJSON *corr = item(res, "correction");
		double f = num(corr, "scale");
		print_message("%s: scale %.6g, yield %.12g (target %.12g)\n", k == 0 ? "form" : "is", f, num(mc, "fraction"), p0);
		assert_true(cJSON_IsTrue(item(c0, "meets_target")));
		assert_string_equal(item(mc, "yield_method")->valuestring, k == 0 ? "form" : "is");
		if (k == 0) {
			assert_string_equal(item(mc, "interval_method")->valuestring, "rare-event point estimate, no interval");
			/* the reported step is the linear allocation, whose FORM yield is the target to rounding */
			assert_true(f >= 0.99 && f <= 1.0);
			if (f == 1.0)
				assert_true(fabs(num(mc, "fraction") - p0) < 1e-12);
		} else {
			assert_string_equal(item(mc, "interval_method")->valuestring, "rare-event estimate, 95 %");
			double lo = cJSON_GetArrayItem(item(mc, "interval95"), 0)->valuedouble;
			assert_true(lo >= p0);
			assert_true(f > 0.8 && f <= 1.0);
		}
		cJSON_Delete(res);
		cJSON_Delete(doc);
	}
	/* the analytic stack has no Monte Carlo to judge */
	char text[2048];
	snprintf(text, sizeof text, "%.*s, \"yield_method\": \"form\"}]}", (int)(strlen(LS1) - 3), LS1);
	cJSON *doc = parse(text);
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_error err = PRSM_ERROR_INIT;
	cJSON *res = NULL;
	assert_int_not_equal(prsm_app_allocate(&res, doc, NULL, NULL, NULL, 0.0, 1, &pr, &err), 0);
	int found = 0;
	for (int i = 0; i < pr.count; i++)
		found |= strcmp(pr.items[i].pointer, "/constraints/0/yield_method") == 0;
	assert_true(found);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ls1),
		cmocka_unit_test(test_worst_case_power),
		cmocka_unit_test(test_exponential),
		cmocka_unit_test(test_case_a_corrected),
		cmocka_unit_test(test_case_a_meets_truly),
		cmocka_unit_test(test_threads),
		cmocka_unit_test(test_cancel),
		cmocka_unit_test(test_mixed_targets),
		cmocka_unit_test(test_time_cap),
		cmocka_unit_test(test_spec_message),
		cmocka_unit_test(test_extremes),
		cmocka_unit_test(test_errors),
		cmocka_unit_test(test_rare_yield),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
