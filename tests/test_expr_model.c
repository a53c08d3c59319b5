/*
 * test_expr_model.c: expression models (mc/expr_model.h, issue 21): names, parse errors with
 * their positions, evaluation against the same formulas in C on random inputs, the engine's
 * model bit-identical at 1 and 2 threads, a division by zero as a sample failure with its index
 * (skip lists it, abort names it), and whole study documents through the reader: the pointer
 * and character of each mistake, inputs and tolerances that name each other, the outputs, and a
 * dimension chain's yield against its normal closed form.
 */
#include "test_support.h"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>

#include "io/global.h"
#include "io/json_util.h"
#include "app/study.h"
#include "io/study_json.h"
#include "mc/expr_model.h"
#include "util/rng.h"

/* A model of the inputs A, B, C, D and the constant k with the given expressions (all outputs). */
static void model_of(prsm_expr_model *m, const char *const *exprs, size_t n)
{
	static const char *const inputs[] = {"A", "B", "C", "D"};
	memset(m, 0, sizeof *m);
	m->n_inputs = 4;
	for (size_t i = 0; i < 4; i++)
		snprintf(m->inputs[i], sizeof m->inputs[i], "%s", inputs[i]);
	m->n_constants = 1;
	snprintf(m->constant_names[0], sizeof m->constant_names[0], "k");
	m->constant_values[0] = 1200.0;
	m->n_exprs = n;
	m->n_outputs = n;
	for (size_t e = 0; e < n; e++) {
		snprintf(m->expr_names[e], sizeof m->expr_names[e], "y%zu", e);
		snprintf(m->exprs[e], sizeof m->exprs[e], "%s", exprs[e]);
		m->output_expr[e] = e;
	}
}

static int setup(void **state)
{
	(void)state;
	prsm_global_init();
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_expr_load(&err) != 0) {
		print_error("muParser: %s\n", err.message);
		return -1;
	}
	return 0;
}

/* ---- names ------------------------------------------------------------------------------------ */

static void test_names(void **state)
{
	(void)state;
	char msg[200];
	const char *good[] = {"A", "gap_mm", "_x", "x1", "preload_N", "Z9_", "a23456789012345678901234567890123456789012345"};
	for (size_t i = 0; i < sizeof good / sizeof good[0]; i++)
		assert_int_equal(prsm_expr_name_check(good[i], msg, sizeof msg), 0);
	const struct {
		const char *name, *says;
	} bad[] = {
		{"", "not a name"},          {"2x", "not a name"},  {"a-b", "not a name"}, {"a b", "not a name"},
		{"\xc3\xa9t\xc3\xa9", "not a name"}, {"x.y", "not a name"},
		{"a234567890123456789012345678901234567890123456789", "at most 47"},
		{"sin", "a function"},       {"max", "a function"}, {"hypot", "a function"}, {"_pi", "a constant"},
		{"_e", "a constant"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		msg[0] = 0;
		assert_int_equal(prsm_expr_name_check(bad[i].name, msg, sizeof msg), PRSM_EINVAL);
		if (!strstr(msg, bad[i].says))
			print_error("'%s': %s\n", bad[i].name, msg);
		assert_non_null(strstr(msg, bad[i].says));
	}
	assert_non_null(prsm_expr_library_version());
}

/* ---- parse errors ----------------------------------------------------------------------------- */

static void test_parse_errors(void **state)
{
	(void)state;
	const struct {
		const char *text;
		int position;     /* 1-based character; length + 1: at the end; 0: none */
		const char *code, *says;
	} cases[] = {
		{"A - B -* C", 8, "syntax", "unexpected operator \"*\""},
		{"A + E", 5, "unknown_name", "unknown name \"E\": not an input (A, B, C, D)"},
		{"A + k * B2", 9, "unknown_name", "unknown name \"B2\""},
		{"(A + B", 7, "syntax", "parenthesis is not closed"},
		{"A + B)", 6, "syntax", "unexpected parenthesis \")\""},
		{"A +", 4, "syntax", "ends too early"},
		{"A B", 3, "syntax", "unexpected name \"B\": an operator is missing"},
		{"A 3", 3, "syntax", "unexpected number \"3\""},
		{"sin A", 1, "syntax", "the function sin needs its arguments in parentheses"},
		{"sin(A, B)", 9, "syntax", "too many arguments for sin"},
		{"atan2(A)", 8, "syntax", "too few arguments for atan2"},
		{"A ? B", 6, "syntax", "misses its \": b\""},
		{"A : B", 4, "syntax", "without its \"?\""},
		{"1e400 + A", 1, "syntax", "the number 1e400 overflows a double"},
		{"A = 3", 3, "not_allowed", "an assignment (=)"},
		{"B + (A += 2)", 8, "not_allowed", "an assignment (+=)"},
		{"A, B", 2, "not_allowed", "a comma outside a function's arguments: one expression per output (2 results"},
		{"max(A, B), C", 10, "not_allowed", "a comma outside"},
		{"A + \xc3\xa9", 5, "not_allowed", "beyond ASCII"},
		{"A + \"x\"", 5, "not_allowed", "strings"},
		{"A # B", 3, "syntax", "unexpected character \"#\""},
		{"", 0, "empty", "empty"},
		{"   ", 0, "empty", "empty"},
	};
	prsm_expr_model m;
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		const char *one[] = {cases[i].text};
		model_of(&m, one, 1);
		prsm_expr_diag d;
		unsigned char used[4];
		const int rc = prsm_expr_check(&m, 0, used, &d);
		if (rc != PRSM_EINVAL || d.position != cases[i].position || strcmp(d.code, cases[i].code) != 0 ||
		    !strstr(d.message, cases[i].says))
			print_error("\"%s\": rc %d, at %d, %s: %s\n", cases[i].text, rc, d.position, d.code, d.message);
		assert_int_equal(rc, PRSM_EINVAL);
		assert_int_equal(d.position, cases[i].position);
		assert_string_equal(d.code, cases[i].code);
		assert_non_null(strstr(d.message, cases[i].says));
	}
	/* valid, and which inputs they read (constants and functions are not inputs) */
	const struct {
		const char *text;
		unsigned char used[4];
	} ok[] = {
		{"A - B - C - D", {1, 1, 1, 1}},
		{"k * max(0, -(A - B))", {1, 1, 0, 0}},
		{"A >= B ? sin(C) : _pi", {1, 1, 1, 0}},
		{"hypot(A, D) + pow(C, 2) + floor(A) + ceil(B) + cbrt(D) + fmod(A, 2)", {1, 1, 1, 1}},
		{"2 * _e\n + 1", {0, 0, 0, 0}},
		{"A == B || C != D && A <= 1", {1, 1, 1, 1}},
	};
	for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
		const char *one[] = {ok[i].text};
		model_of(&m, one, 1);
		prsm_expr_diag d;
		unsigned char used[4];
		const int rc = prsm_expr_check(&m, 0, used, &d);
		if (rc != 0)
			print_error("\"%s\": at %d: %s\n", ok[i].text, d.position, d.message);
		assert_int_equal(rc, 0);
		assert_memory_equal(used, ok[i].used, 4);
	}
}

/* ---- evaluation ------------------------------------------------------------------------------- */

/* The formulas of eval_cases in C. */
static void closed_forms(const double *x, double *y)
{
	const double A = x[0], B = x[1], C = x[2], D = x[3], k = 1200.0;
	y[0] = A - B - C - D;
	y[1] = k * fmax(0.0, -(A - B - C - D));
	y[2] = sqrt(A * A + B * B) * sin(C) / (1.0 + fabs(D));
	y[3] = A > B ? exp(-C * C) : log(1.0 + D * D);
	y[4] = hypot(A, B) - pow(fabs(C), 1.5) + atan2(D, A) + floor(B) + ceil(C) + fmod(A, 0.7);
	y[5] = -A * A + (C - D) * (C + D) / 3.0;
}

static const char *const eval_cases[] = {
	"A - B - C - D",
	"k * max(0, -(A - B - C - D))",
	"sqrt(A^2 + B^2) * sin(C) / (1 + abs(D))",
	"A > B ? exp(-C^2) : ln(1 + D^2)",
	"hypot(A, B) - pow(abs(C), 1.5) + atan2(D, A) + floor(B) + ceil(C) + fmod(A, 0.7)",
	"-A^2 + (C - D) * (C + D) / 3",
};
#define N_EVAL (sizeof eval_cases / sizeof eval_cases[0])

static void test_eval_against_c(void **state)
{
	(void)state;
	prsm_expr_model m;
	model_of(&m, eval_cases, N_EVAL);
	for (size_t e = 0; e < N_EVAL; e++) {
		prsm_expr_diag d;
		assert_int_equal(prsm_expr_check(&m, e, NULL, &d), 0);
	}
	prsm_mc_model mm;
	prsm_expr_mc_model(&mm, &m);
	assert_int_equal((int)mm.n_outputs, (int)N_EVAL);
	void *ws = NULL;
	assert_int_equal(mm.workspace_alloc(&ws, mm.ctx), 0);
	gsl_rng *r = prsm_rng_alloc(20261202, 1);
	assert_non_null(r);
	for (int s = 0; s < 20000; s++) {
		double x[4], y[N_EVAL], want[N_EVAL];
		for (int i = 0; i < 4; i++)
			x[i] = 10.0 * gsl_rng_uniform(r) - 5.0;
		unsigned flags = 7;
		assert_int_equal(mm.eval(y, &flags, mm.ctx, ws, x), 0);
		assert_int_equal((int)flags, 0);
		closed_forms(x, want);
		/* the chain in the same order of operations: the same double */
		assert_memory_equal(&y[0], &want[0], sizeof y[0]);
		for (size_t o = 1; o < N_EVAL; o++)
			assert_close(y[o], want[o], 1e-13 * fmax(1.0, fabs(want[o])));
	}
	gsl_rng_free(r);
	mm.workspace_free(ws);
	/* outputs in the study's order: a subset, reordered */
	m.n_outputs = 2;
	m.output_expr[0] = 5;
	m.output_expr[1] = 0;
	prsm_expr_mc_model(&mm, &m);
	assert_int_equal(mm.workspace_alloc(&ws, mm.ctx), 0);
	const double x[4] = {1.5, 0.25, -2.0, 0.5};
	double y[2], want[N_EVAL];
	unsigned flags;
	assert_int_equal(mm.eval(y, &flags, mm.ctx, ws, x), 0);
	closed_forms(x, want);
	assert_close(y[0], want[5], 1e-15);
	assert_true(y[1] == want[0]);
	mm.workspace_free(ws);
}

/* An output that is not finite fails the sample (PRSM_EINVAL); the others are still computed. */
static void test_eval_not_finite(void **state)
{
	(void)state;
	const char *exprs[] = {"A / (B - C)", "sqrt(D)", "A + B"};
	prsm_expr_model m;
	model_of(&m, exprs, 3);
	prsm_mc_model mm;
	prsm_expr_mc_model(&mm, &m);
	void *ws = NULL;
	assert_int_equal(mm.workspace_alloc(&ws, mm.ctx), 0);
	double y[3];
	unsigned flags;
	const double ok[4] = {1, 2, 3, 4}, div0[4] = {1, 2, 2, 4}, neg[4] = {1, 2, 3, -4}, nan_in[4] = {NAN, 2, 3, 4};
	assert_int_equal(mm.eval(y, &flags, mm.ctx, ws, ok), 0);
	assert_int_equal(mm.eval(y, &flags, mm.ctx, ws, div0), PRSM_EINVAL);
	assert_true(isinf(y[0]) && y[2] == 3.0);
	assert_int_equal(mm.eval(y, &flags, mm.ctx, ws, neg), PRSM_EINVAL);
	assert_true(isnan(y[1]));
	assert_int_equal(mm.eval(y, &flags, mm.ctx, ws, nan_in), PRSM_EINVAL);
	mm.workspace_free(ws);
	/* a workspace of an expression that does not parse is refused, not made */
	const char *broken[] = {"A +"};
	model_of(&m, broken, 1);
	prsm_expr_mc_model(&mm, &m);
	ws = (void *)&m;
	assert_int_equal(mm.workspace_alloc(&ws, mm.ctx), PRSM_EINVAL);
	assert_null(ws);
}

/* ---- the engine ------------------------------------------------------------------------------- */

static void engine_vars(prsm_mc_variable *v)
{
	memset(v, 0, 4 * sizeof *v);
	for (int i = 0; i < 4; i++) {
		v[i].group = i;
		v[i].dist.kind = PRSM_DIST_NORMAL;
		v[i].dist.p[0] = 1.0 + i;
		v[i].dist.p[1] = 0.1 * (i + 1);
	}
	v[3].dist.kind = PRSM_DIST_UNIFORM; /* D on [0, 1] */
	v[3].dist.p[0] = 0.0;
	v[3].dist.p[1] = 1.0;
}

/* A run of several blocks is bit-identical at 1 and 2 threads (each worker with its own parsers). */
static void test_threads_bit_identical(void **state)
{
	(void)state;
	prsm_expr_model m;
	model_of(&m, eval_cases, N_EVAL);
	prsm_mc_model mm;
	prsm_expr_mc_model(&mm, &m);
	prsm_mc_variable v[4];
	engine_vars(v);
	prsm_mc_result r[2];
	for (int t = 0; t < 2; t++) {
		prsm_mc_options o;
		prsm_mc_options_default(&o);
		o.samples = 8192;
		o.block_size = 512;
		o.threads = t + 1;
		o.seed = 77;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_mc_run(&r[t], &mm, v, 4, NULL, 0, &o, &err), 0);
		assert_int_equal((int)r[t].n, 8192);
		assert_int_equal((int)r[t].n_failed, 0);
	}
	assert_memory_equal(r[0].x, r[1].x, 8192 * 4 * sizeof(double));
	assert_memory_equal(r[0].y, r[1].y, 8192 * N_EVAL * sizeof(double));
	/* and each row is the formulas of its inputs */
	for (size_t s = 0; s < 8192; s += 97) {
		double want[N_EVAL];
		closed_forms(&r[0].x[4 * s], want);
		assert_true(r[0].y[N_EVAL * s] == want[0]);
	}
	prsm_mc_result_free(&r[0]);
	prsm_mc_result_free(&r[1]);
}

/* A division by zero at some samples: skip counts and lists them (by index, exactly the samples
 * whose D rounds to 0.3), abort stops at the first with its index. */
static void test_division_by_zero_fails_samples(void **state)
{
	(void)state;
	const char *exprs[] = {"A / (rint(D * 10) - 3)"};
	prsm_expr_model m;
	model_of(&m, exprs, 1);
	prsm_mc_model mm;
	prsm_expr_mc_model(&mm, &m);
	prsm_mc_variable v[4];
	engine_vars(v);
	prsm_mc_options o;
	prsm_mc_options_default(&o);
	o.samples = 4000;
	o.block_size = 256;
	o.threads = 2;
	o.max_failed_fraction = 0.5;
	prsm_mc_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_mc_run(&r, &mm, v, 4, NULL, 0, &o, &err), 0);
	size_t failed = 0, first = SIZE_MAX;
	for (size_t s = 0; s < r.n; s++) {
		const double D = r.x[4 * s + 3];
		const int zero = rint(D * 10.0) == 3.0;
		assert_int_equal(r.status[s] == PRSM_SAMPLE_FAILED, zero);
		if (zero) {
			assert_int_equal(r.fail_code[s], PRSM_EINVAL);
			assert_true(isnan(r.y[s]));
			failed++;
			if (first == SIZE_MAX)
				first = s;
		}
	}
	assert_int_equal((int)r.n_failed, (int)failed);
	assert_true(failed > 300 && failed < 500); /* D uniform on [0, 1]: a tenth */
	prsm_mc_result_free(&r);
	/* abort: an error naming the first failed sample */
	o.failure = PRSM_FAILURE_ABORT;
	char index[32];
	snprintf(index, sizeof index, "sample %zu failed", first);
	const int rc = prsm_mc_run(&r, &mm, v, 4, NULL, 0, &o, &err);
	assert_true(rc < 0);
	if (!strstr(err.message, index))
		print_error("%s (expected \"%s\")\n", err.message, index);
	assert_non_null(strstr(err.message, index));
	prsm_mc_result_free(&r);
}

/* ---- study documents -------------------------------------------------------------------------- */

/* The study of document text, loaded (or refused: NULL, the problems in pr; warnings in w). */
static prsm_io_study *load(const char *text, prsm_problems *w, prsm_problems *pr)
{
	cJSON *doc = cJSON_Parse(text);
	assert_non_null(doc);
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems_init(pr);
	if (w)
		prsm_problems_init(w);
	const int rc = prsm_app_study_load(s, doc, w, pr);
	cJSON_Delete(doc);
	if (rc) {
		free(s);
		return NULL;
	}
	return s;
}

/* The first problem is at pointer, with code, saying says. */
static void refused(const char *text, const char *pointer, const char *code, const char *says)
{
	prsm_problems pr;
	prsm_io_study *s = load(text, NULL, &pr);
	if (s || pr.count == 0 || strcmp(pr.items[0].pointer, pointer) != 0 || strcmp(pr.items[0].code, code) != 0 ||
	    !strstr(pr.items[0].message, says)) {
		print_error("%s\n", text);
		for (int i = 0; i < pr.count; i++)
			print_error("  %s %s %s\n", pr.items[i].pointer, pr.items[i].code, pr.items[i].message);
	}
	assert_null(s);
	assert_true(pr.count > 0);
	assert_string_equal(pr.items[0].pointer, pointer);
	assert_string_equal(pr.items[0].code, code);
	assert_non_null(strstr(pr.items[0].message, says));
}

#define TOLS_AB "\"tolerances\": [{\"parameter\": \"A\", \"distribution\": \"normal\", \"sd\": 1}, " \
                "{\"parameter\": \"B\", \"distribution\": \"uniform\", \"lower\": 0, \"upper\": 1}]"

static void test_documents_refused(void **state)
{
	(void)state;
	refused("{\"model\": {\"expression\": \"A - B -* 2\", \"inputs\": [\"A\", \"B\"]}, " TOLS_AB "}",
	        "/model/expression", "syntax", "at character 8: unexpected operator \"*\"");
	refused("{\"model\": {\"expressions\": {\"gap\": \"A - B\", \"load\": \"A * E\"}, \"inputs\": [\"A\", \"B\"]}, "
	        TOLS_AB "}", "/model/expressions/load", "unknown_name", "at character 5: unknown name \"E\"");
	refused("{\"model\": {\"expression\": \"(A - B\", \"inputs\": [\"A\", \"B\"]}, " TOLS_AB "}",
	        "/model/expression", "syntax", "at the end (character 7): a parenthesis is not closed");
	refused("{\"model\": {\"expression\": \"A - B\", \"inputs\": [\"A\", \"B\", \"C\"]}, " TOLS_AB "}",
	        "/model/inputs/2", "incomplete", "input 'C' has no tolerance");
	refused("{\"model\": {\"expression\": \"A\", \"inputs\": [\"A\"]}, " TOLS_AB "}",
	        "/tolerances/1/parameter", "unknown_parameter", "B: not an input of the model (inputs: A)");
	refused("{\"model\": {\"expression\": \"A\", \"inputs\": [\"A\", \"A\"]}, " TOLS_AB "}",
	        "/model/inputs/1", "duplicate", "input 'A' is listed twice");
	refused("{\"model\": {\"expression\": \"A\", \"inputs\": [\"A\", \"sin\"]}, " TOLS_AB "}",
	        "/model/inputs/1", "bad_name", "'sin' is a function");
	refused("{\"model\": {\"expression\": \"A + B\", \"inputs\": [\"A\", \"B\"], \"constants\": {\"B\": 2}}, " TOLS_AB
	        "}", "/model/constants/B", "duplicate", "'B' is an input");
	refused("{\"model\": {\"expression\": \"A + B\", \"expressions\": {\"y\": \"A\"}, \"inputs\": [\"A\", \"B\"]}, "
	        TOLS_AB "}", "/model/expressions", "conflict", "not both");
	refused("{\"model\": {\"inputs\": [\"A\", \"B\"]}, " TOLS_AB "}", "/model", "required",
	        "needs expression (one output, y) or expressions");
	refused("{\"model\": {\"expression\": \"A + B\", \"inputs\": [\"A\", \"B\"], \"benchmark\": \"linear\"}, " TOLS_AB
	        "}", "/model", "conflict", "a benchmark or expressions");
	refused("{\"model\": {\"expression\": \"A + B\", \"input\": [\"A\", \"B\"]}, " TOLS_AB "}", "/model/input",
	        "unknown_field", "did you mean \"inputs\"");
	refused("{\"model\": {\"expressions\": {\"gap\": \"A - B\"}, \"inputs\": [\"A\", \"B\"]}, " TOLS_AB
	        ", \"outputs\": [\"gap\", \"y\"]}", "/outputs/1", "unknown_output", "'y' is not an output of the model (gap)");
	refused("{\"model\": {\"expressions\": {\"2gap\": \"A - B\"}, \"inputs\": [\"A\", \"B\"]}, " TOLS_AB "}",
	        "/model/expressions/2gap", "bad_name", "not a name");
	refused("{\"model\": {\"expression\": \"A * 1e200 + B\", \"inputs\": [\"A\", \"B\"]}, " TOLS_AB "}",
	        "/model/expression", "range", "y reaches -2.99998e+200 with A at its 0.135 % quantile");
	refused("{\"model\": {\"expression\": \"A + B\", \"inputs\": [\"A\", \"B\"]}, \"errors\": {}, " TOLS_AB "}",
	        "/errors", "not_allowed", "not a model of expressions");
}

/* Warnings: an input no expression reads; an output not finite at a quantile (those samples fail). */
static void test_documents_warned(void **state)
{
	(void)state;
	prsm_problems w, pr;
	prsm_io_study *s = load("{\"model\": {\"expressions\": {\"g\": \"2 * A\"}, \"inputs\": [\"A\", \"B\"]}, " TOLS_AB "}",
	                        &w, &pr);
	assert_non_null(s);
	assert_int_equal(w.count, 1);
	assert_string_equal(w.items[0].pointer, "/model/inputs/1");
	assert_string_equal(w.items[0].code, "unused_input");
	free(s);
	/* B uniform on [0, 1]: its 0.135 % quantile is 0.00135 */
	s = load("{\"model\": {\"expressions\": {\"g\": \"A\", \"h\": \"1 / (B - 0.00135)\"}, \"inputs\": [\"A\", \"B\"]}, "
	         TOLS_AB "}", &w, &pr);
	assert_non_null(s);
	assert_int_equal(w.count, 1);
	assert_string_equal(w.items[0].pointer, "/model/expressions/h");
	assert_string_equal(w.items[0].code, "not_finite");
	assert_non_null(strstr(w.items[0].message, "h is not finite with B at its 0.135 % quantile 0.00135"));
	free(s);
}

/* k max(0, h - g)^1.5 times the normal density of g (par: k, h, mean, sd). */
static double preload_integrand(double g, void *p)
{
	const double *par = p, d = par[1] - g;
	return d > 0.0 ? par[0] * pow(d, 1.5) * gsl_ran_gaussian_pdf(g - par[2], par[3]) : 0.0;
}

static double preload_mean(const double *par)
{
	gsl_integration_workspace *ws = gsl_integration_workspace_alloc(200);
	assert_non_null(ws);
	gsl_function f = {preload_integrand, (void *)(uintptr_t)par};
	double v, e;
	assert_int_equal(gsl_integration_qagil(&f, par[1], 0.0, 1e-12, 200, ws, &v, &e), 0);
	gsl_integration_workspace_free(ws);
	return v;
}

/* The housing stack of studies/stack-housing.json: the gap a normal of known mean and sd, its
 * yield Phi((U - m) / s) - Phi((L - m) / s), its RSS figure 3 s; the cover's preload
 * k max(0, h - gap)^1.5 (nonlinear) its mean by quadrature. */
static void test_housing_stack(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("stack-housing.json");
	prsm_io_study *s = calloc(1, sizeof *s);
	assert_non_null(s);
	prsm_problems pr, w;
	prsm_problems_init(&pr);
	prsm_problems_init(&w);
	const int rc = prsm_app_study_load(s, doc, &w, &pr);
	for (int i = 0; i < pr.count; i++)
		print_error("%s %s\n", pr.items[i].pointer, pr.items[i].message);
	assert_int_equal(rc, 0);
	assert_int_equal(w.count, 0);
	assert_int_equal((int)s->bench.kind, PRSM_BENCH_EXPRESSION);
	assert_string_equal(prsm_bench_name(s->bench.kind), "expression");
	assert_int_equal((int)s->study.m, 2);
	assert_string_equal(s->study.outputs[0].name, "gap_mm");
	/* the gap's exact mean and sd from the tolerances (a linear chain A - B - C - D) */
	double mean = 0.0, var = 0.0;
	for (size_t i = 0; i < s->study.d; i++) {
		const double c = i == 0 ? 1.0 : -1.0, sd = prsm_dist_sd(&s->study.vars[i].dist);
		mean += c * prsm_dist_mean(&s->study.vars[i].dist);
		var += sd * sd;
	}
	s->study.mc.samples = 100000;
	s->study.mc.threads = 2;
	s->study.sens.sobol = 0;
	prsm_study_result *r = calloc(1, sizeof *r);
	assert_non_null(r);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_study_run(r, &s->study, &err), 0);
	const prsm_stats_summary *g = &r->out[0].summary;
	const double sd = sqrt(var), n = (double)g->n;
	assert_close(g->mean, mean, 4.5 * sd / sqrt(n));
	assert_close(g->sd, sd, 4.5 * sd / sqrt(2.0 * n));
	const prsm_spec *spec = &s->study.outputs[0].spec;
	const double p = gsl_cdf_gaussian_P(spec->upper - mean, sd) - gsl_cdf_gaussian_P(spec->lower - mean, sd);
	assert_close(g->yield, p, 4.5 * sqrt(p * (1.0 - p) / n));
	/* the stack figures of a linear chain: RSS 3 sd exactly */
	assert_close(r->out[0].rss, 3.0 * sd, 1e-9 * sd);
	/* the preload k max(0, h - gap)^1.5: its mean by quadrature over the normal gap */
	assert_string_equal(s->expr.constant_names[0], "spigot_mm");
	assert_string_equal(s->expr.constant_names[1], "k_contact");
	const double preload_par[4] = {s->expr.constant_values[1], s->expr.constant_values[0], mean, sd};
	const double preload = preload_mean(preload_par);
	const prsm_stats_summary *f = &r->out[1].summary;
	assert_close(f->mean, preload, 4.5 * f->sd / sqrt(n));
	assert_true(preload > 200.0 && preload < 300.0);
	prsm_study_result_free(r);
	free(r);
	free(s);
	cJSON_Delete(doc);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_names),
		cmocka_unit_test(test_parse_errors),
		cmocka_unit_test(test_eval_against_c),
		cmocka_unit_test(test_eval_not_finite),
		cmocka_unit_test(test_threads_bit_identical),
		cmocka_unit_test(test_division_by_zero_fails_samples),
		cmocka_unit_test(test_documents_refused),
		cmocka_unit_test(test_documents_warned),
		cmocka_unit_test(test_housing_stack),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
