/*
 * study_json.c: reading a study document (see study_json.h; the result: study_result.c).
 *
 * The fields, their limits and C members are stated once, in schemas/study.schema.json
 * ("x-prsm"); io/doc.c reads the document by the table generated from it. What a table cannot
 * say is here, as the steps the schema names: the design (or the benchmark, or the expression
 * model with its expressions parsed; the design's nominal analysis and the engine's model of it
 * are computed by the caller's hooks, study_json.h), what each tolerance's parameter
 * is and its distribution (a named one, a histogram's bins or the tol/cpk shorthand), the
 * outputs, specs, targets and correlations that name each other, and the variables the engine
 * samples. Reading never stops at the first problem; the variables are
 * built only when every section is valid. A tolerance on a per-roller parameter ("roller.*")
 * becomes one variable per roller, drawn independently, unless "shared": true; a start-index
 * tolerance one per start; a radial magnitude (run-out, periodic lead, tilt) gets a second
 * variable, its direction, uniform on [0, 2 pi).
 */
#include "io/study_json.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "io/analyze_request.h"
#include "io/design_json.h"
#include "io/doc.h"
#include "io/dynamics_json.h"
#include "io/errors_json.h"
#include "io/json_util.h"
#include "prsm_io_tables.h"

static const prsm_json_range ANY = {-HUGE_VAL, HUGE_VAL, 0, 0};

/* What the steps share while a study is read. */
typedef struct {
	prsm_problems *warnings;        /* the design's rule warnings (may be NULL) */
	int design_rc;                  /* 0: the design (or benchmark) loaded: the parameters can be known */
	const prsm_io_study_options *o; /* the caller's hooks (never NULL) */
} study_reading;

/* ---- parameters -------------------------------------------------------------------------- */

/* What a tolerance path names. */
typedef struct {
	prsm_part part;
	size_t offset;            /* engine field (errors structs) or friction index */
	double scale;             /* engine units per API unit */
	int per_roller, per_start, radial;
	size_t phase_offset;
	const char *unit;         /* the unit suffix its shorthand must use: "um", "mrad", ... or "" */
	int bench_index;          /* benchmark input index, else -1 */
} param_info;

/* Returns 0, or PRSM_ENOTFOUND with a message in msg. */
static int param_find(param_info *pi, const char *path, const prsm_io_study *s, char *msg, size_t cap)
{
	memset(pi, 0, sizeof *pi);
	pi->bench_index = -1;
	if (s->is_benchmark && s->bench.kind == PRSM_BENCH_EXPRESSION) {
		const prsm_expr_model *m = &s->expr;
		for (size_t i = 0; i < m->n_inputs; i++)
			if (strcmp(m->inputs[i], path) == 0) {
				pi->bench_index = (int)i;
				pi->unit = "";
				pi->scale = 1.0;
				return 0;
			}
		int k = snprintf(msg, cap, "not an input of the model (inputs: ");
		for (size_t i = 0; i < m->n_inputs && k > 0 && (size_t)k < cap; i++)
			k += snprintf(msg + k, cap - (size_t)k, "%s%s", i ? ", " : "", m->inputs[i]);
		if (k > 0 && (size_t)k < cap)
			snprintf(msg + k, cap - (size_t)k, ")");
		return PRSM_ENOTFOUND;
	}
	if (s->is_benchmark) {
		/* x1 .. xn exactly: no leading zero, sign or blank */
		const size_t digits = strspn(path + 1, "0123456789");
		const size_t idx = path[0] == 'x' && path[1] != '0' && digits && digits < 5 && !path[1 + digits]
		                       ? (size_t)strtoul(path + 1, NULL, 10) : 0;
		if (idx >= 1 && idx <= s->bench.inputs) {
			pi->bench_index = (int)idx - 1;
			pi->unit = "";
			pi->scale = 1.0;
			return 0;
		}
		snprintf(msg, cap, "the %s benchmark has inputs x1 .. x%zu", prsm_bench_name(s->bench.kind),
		         s->bench.inputs);
		return PRSM_ENOTFOUND;
	}
	if (strcmp(path, "damping_ratio") == 0) { /* the dynamic model's zeta_a = zeta_g, absolute */
		*pi = (param_info){PRSM_PART_DYNAMICS, PRSM_DYN_TOL_DAMPING, 1.0, 0, 0, 0, 0, "", -1};
		return 0;
	}
	const char *dot = strchr(path, '.');
	char part[16];
	if (!dot || (size_t)(dot - path) >= sizeof part) {
		snprintf(msg, cap, "a parameter is part.field, e.g. screw.runout_um or roller.pitch_radius_um");
		return PRSM_ENOTFOUND;
	}
	memcpy(part, path, (size_t)(dot - path));
	part[dot - path] = 0;
	const char *key = dot + 1;
	if (strcmp(part, "friction") == 0) { /* offset 0: screw-roller, 1: nut-roller */
		*pi = (param_info){PRSM_PART_FRICTION, strcmp(key, "nut_roller_mu") == 0, 1.0, 0, 0, 0, 0, "", -1};
		if (pi->offset == 1 || strcmp(key, "screw_roller_mu") == 0)
			return 0;
		snprintf(msg, cap, "friction parameters are screw_roller_mu and nut_roller_mu "
		                   "(deviations added to the design's coefficients)");
		return PRSM_ENOTFOUND;
	}
	if (strcmp(part, "ring_gear") == 0) { /* the dynamic model's gear branch, absolute values in um */
		static const char *const keys[] = {"mesh_error_um", "backlash_um", NULL};
		for (int k = 0; keys[k]; k++)
			if (strcmp(key, keys[k]) == 0) {
				*pi = (param_info){PRSM_PART_DYNAMICS, k == 0 ? PRSM_DYN_TOL_MESH_ERROR : PRSM_DYN_TOL_BACKLASH, 1e-6,
				                   0, 0, 0, 0, "um", -1};
				return 0;
			}
		const char *guess = prsm_json_closest_name(key, keys);
		if (guess)
			snprintf(msg, cap, "'%s' is not a ring-gear parameter (did you mean 'ring_gear.%s'?): mesh_error_um or "
			         "backlash_um", key, guess);
		else
			snprintf(msg, cap, "'%s' is not a ring-gear parameter: mesh_error_um or backlash_um", key);
		return PRSM_ENOTFOUND;
	}
	static const char *const parts[] = {"screw", "nut", "carrier", "roller"}; /* = prsm_part */
	int p = 0;
	while (p < 4 && strcmp(part, parts[p]) != 0)
		p++;
	if (p == 4) {
		static const char *const all_parts[] = {"screw", "nut", "carrier", "roller", "friction", "ring_gear", NULL};
		const char *guess = prsm_json_closest_name(part, all_parts);
		if (guess)
			snprintf(msg, cap, "unknown part '%s' (did you mean '%s'?): screw, nut, carrier, roller, friction or "
			         "ring_gear (or damping_ratio)", part, guess);
		else
			snprintf(msg, cap, "unknown part '%s': screw, nut, carrier, roller, friction or ring_gear (or "
			         "damping_ratio)", part);
		return PRSM_ENOTFOUND;
	}
	pi->part = (prsm_part)p;
	pi->per_roller = pi->part == PRSM_PART_ROLLER;
	pi->unit = prsm_io_error_unit_of(key);
	if ((pi->part == PRSM_PART_SCREW || pi->part == PRSM_PART_NUT) &&
	    strcmp(key, "start_index_mrad") == 0) {
		pi->per_start = 1;
		pi->offset = offsetof(prsm_body_errors, start_index_rad);
		pi->scale = 1e-3;
		return 0;
	}
	prsm_io_error_field f;
	if (prsm_io_error_field_find(&f, part, key)) {
		const char *names[48];
		prsm_io_error_field_names(part, names, 48);
		const char *guess = prsm_json_closest_name(key, names);
		if (guess)
			snprintf(msg, cap, "'%s' is not an error of the %s (did you mean '%s.%s'?)", key, part, part, guess);
		else
			snprintf(msg, cap, "'%s' is not an error of the %s (see the errors object of the analyze request)",
			         key, part);
		return PRSM_ENOTFOUND;
	}
	if (f.phase) {
		snprintf(msg, cap, "directions are not toleranced: every radial error's direction is drawn "
		                   "uniformly on [0, 360) deg with its magnitude");
		return PRSM_ENOTFOUND;
	}
	pi->offset = f.offset;
	pi->scale = 1.0 / f.scale;
	pi->radial = f.magnitude;
	pi->phase_offset = f.phase_offset;
	return 0;
}

/* ---- the design or the benchmark --------------------------------------------------------- */

/* "model": the benchmark, its constants and its inputs' coefficients ($defs/model's table) */
static void read_benchmark(prsm_io_study *s, const cJSON *m, prsm_problems *pr)
{
	prsm_bench_model *b = &s->bench;
	const prsm_io_at at = {.base = b, .table = &prsm_io_t_bench_model, .obj = m, .pointer = "/model", .index = -1};
	prsm_io_read(b, &prsm_io_t_bench_model, m, "/model", pr);
	if (prsm_io_get(&at, "benchmark", pr) != PRSM_JSON_PRESENT)
		return;
	const prsm_bench_kind kind = b->kind;
	if (kind == PRSM_BENCH_ISHIGAMI) {
		b->inputs = 3;
		b->a = 7.0;
		b->b = 0.1;
		prsm_json_get_number(&b->a, m, "/model", "a", PRSM_JSON_OPTIONAL, ANY, pr);
		prsm_io_get(&at, "b", pr);
		static const char *const foreign[] = {"coefficients", "constant", NULL};
		for (int k = 0; foreign[k]; k++)
			if (cJSON_GetObjectItemCaseSensitive(m, foreign[k]))
				prsm_io_problem(pr, "/model", foreign[k], "not_allowed", "the Ishigami benchmark takes a and b only");
		return;
	}
	prsm_io_get(&at, kind == PRSM_BENCH_GFUNCTION ? "a" : "coefficients", pr);
	if (b->inputs == 0) /* not an array of 1 to 64 */
		return;
	if (kind == PRSM_BENCH_LINEAR)
		prsm_io_get(&at, "constant", pr);
	const char *other = kind == PRSM_BENCH_GFUNCTION ? "coefficients" : "a";
	if (cJSON_GetObjectItemCaseSensitive(m, other) || cJSON_GetObjectItemCaseSensitive(m, "b") ||
	    (kind == PRSM_BENCH_GFUNCTION && cJSON_GetObjectItemCaseSensitive(m, "constant")))
		prsm_problems_add(pr, "/model", "not_allowed", "the %s benchmark takes %s only", prsm_bench_name(kind),
		                  kind == PRSM_BENCH_GFUNCTION ? "a" : "coefficients and constant");
}

/* The design and what the engine needs of it. Returns 0 when it is usable. */
static int read_design(prsm_io_study *s, const cJSON *doc, const study_reading *c, prsm_problems *pr)
{
	prsm_problems *warnings = c->warnings;
	prsm_geometry g;
	const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
	int rc = prsm_io_design_load_sized(&s->design, &g, warnings, design, "/design", pr, NULL);
	prsm_design unknown;
	prsm_design_init(&unknown);
	unknown.rollers = unknown.starts = 0;
	const prsm_design *shape = rc == 0 ? &s->design : &unknown;
	const cJSON *errors = NULL, *opts = NULL;
	prsm_json_get_object(&errors, doc, "", "errors", PRSM_JSON_OPTIONAL, pr);
	prsm_json_get_object(&opts, doc, "", "assembly", PRSM_JSON_OPTIONAL, pr);
	prsm_io_errors_from_json(&s->prsm.base, errors, "/errors", shape, pr);
	prsm_io_assembly_options_from_json(&s->assembly_options, opts, "/assembly", shape, pr);
	if (rc)
		return rc;
	/* the nominal analysis and the assembly are the caller's (app/study.c), here, where the
	 * steps after this one need to know whether the design works */
	return c->o->analyse_design ? c->o->analyse_design(s, warnings, pr, c->o->ctx) : 0;
}

/* A model of expressions rather than a benchmark: no "benchmark", and a member an expression
 * model has ($defs/expression_model's). */
static int is_expression_model(const cJSON *m)
{
	const char *const *keys = prsm_io_t_expr_model.keys;
	if (!cJSON_IsObject(m) || cJSON_GetObjectItemCaseSensitive(m, "benchmark"))
		return 0;
	for (int k = 0; keys[k]; k++)
		if (cJSON_GetObjectItemCaseSensitive(m, keys[k]))
			return 1;
	return 0;
}

/* "model" as expressions ($defs/expression_model's table and its steps) */
static void read_expressions(prsm_io_study *s, const cJSON *m, study_reading *c, prsm_problems *pr)
{
	s->bench.kind = PRSM_BENCH_EXPRESSION;
	s->expr_single = cJSON_GetObjectItemCaseSensitive(m, "expression") != NULL;
	prsm_io_read_ctx(&s->expr, &prsm_io_t_expr_model, m, "/model", c, pr);
	s->bench.inputs = s->expr.n_inputs;
}

/* The design (with its nominal analysis and assembly, by the caller's hook) or the model (a
 * benchmark or expressions), exactly one. */
int prsm_io_step_design(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_study *s = at->root;
	study_reading *c = at->ctx;
	const cJSON *design = cJSON_GetObjectItemCaseSensitive(at->obj, "design");
	const cJSON *model = cJSON_GetObjectItemCaseSensitive(at->obj, "model");
	if (design && model) {
		prsm_problems_add(pr, "/model", "conflict", "a study has a design or a benchmark model, not both");
	} else if (model) {
		s->is_benchmark = 1;
		const int expressions = is_expression_model(model);
		if (cJSON_IsObject(model) && cJSON_GetObjectItemCaseSensitive(model, "benchmark") &&
		    (cJSON_GetObjectItemCaseSensitive(model, "expression") ||
		     cJSON_GetObjectItemCaseSensitive(model, "expressions")))
			prsm_problems_add(pr, "/model", "conflict", "a model is a benchmark or expressions, not both");
		else if (prsm_json_object_value(model, "/model", pr) == 0)
			expressions ? read_expressions(s, model, c, pr) : read_benchmark(s, model, pr);
		static const char *const design_only[] = {"errors", "assembly", NULL};
		for (int k = 0; design_only[k]; k++)
			if (cJSON_GetObjectItemCaseSensitive(at->obj, design_only[k]))
				prsm_io_problem(pr, "", design_only[k], "not_allowed", "%s belongs to a design study, not a %s",
				                design_only[k], expressions ? "model of expressions" : "benchmark");
		c->design_rc = prsm_problems_total(pr) == at->start ? 0 : PRSM_EINVAL;
	} else if (design) {
		c->design_rc = read_design(s, at->obj, c, pr);
	} else {
		prsm_problems_add(pr, "/design", "required", "a study needs a design (or a benchmark model)");
	}
	return 0;
}

/* ---- the expression model ---------------------------------------------------------------- */

/* "model"."inputs"[i]: a name, once */
int prsm_io_step_expr_input(prsm_io_at *at, prsm_problems *pr)
{
	prsm_expr_model *m = at->base;
	const char *name = at->obj->valuestring;
	char msg[200];
	if (prsm_expr_name_check(name, msg, sizeof msg)) {
		prsm_problems_add(pr, at->pointer, "bad_name", "%s", msg);
		return 0;
	}
	for (int k = 0; k < at->index; k++)
		if (strcmp(m->inputs[k], name) == 0) {
			prsm_problems_add(pr, at->pointer, "duplicate", "input '%s' is listed twice (at /model/inputs/%d)", name, k);
			return 0;
		}
	snprintf(m->inputs[at->index], sizeof m->inputs[0], "%s", name);
	return 0;
}

/* One expression's text, output name and its place in m. */
static void put_expression(prsm_expr_model *m, const char *name, const char *text)
{
	snprintf(m->expr_names[m->n_exprs], sizeof m->expr_names[0], "%s", name);
	snprintf(m->exprs[m->n_exprs], sizeof m->exprs[0], "%s", text);
	m->n_exprs++;
}

/* "expressions" (outputs: 1 or more) or "constants", a map of named items: an object without
 * repeated keys, at most max items. Returns its first item, or NULL (after a problem, or when it
 * is empty). */
static const cJSON *named_items(const cJSON *map, const char *p, int outputs, int max, prsm_problems *pr)
{
	if (prsm_json_object_value(map, p, pr) || prsm_json_check_duplicates(map, p, pr))
		return NULL;
	const int n = cJSON_GetArraySize(map);
	if (n >= outputs && n <= max)
		return map->child;
	if (outputs)
		prsm_problems_add(pr, p, "range", "expressions: 1 to %d named outputs (got %d)", max, n);
	else
		prsm_problems_add(pr, p, "range", "constants: at most %d", max);
	return NULL;
}

/* An item of a map of named items: its pointer ip, its name checked. Returns 0 when it is valid. */
static int named_item(char ip[PRSM_JSON_POINTER_MAX], const cJSON *it, const char *p, prsm_problems *pr)
{
	char msg[200];
	prsm_json_pointer_append(ip, PRSM_JSON_POINTER_MAX, p, it->string);
	if (prsm_expr_name_check(it->string, msg, sizeof msg) == 0)
		return 0;
	prsm_problems_add(pr, ip, "bad_name", "%s", msg);
	return 1;
}

/* "expression" (the one output, y) or "expressions" (named outputs), exactly one. */
static void read_expression_texts(prsm_expr_model *m, const cJSON *o, prsm_problems *pr)
{
	const size_t text_max = sizeof m->exprs[0] - 1;
	const cJSON *one = cJSON_GetObjectItemCaseSensitive(o, "expression");
	const cJSON *many = cJSON_GetObjectItemCaseSensitive(o, "expressions");
	const char *text;
	char ip[PRSM_JSON_POINTER_MAX];
	if (one && many) {
		prsm_io_problem(pr, "/model", "expressions", "conflict",
		                "give expression (one output, y) or expressions (named outputs), not both");
	} else if (!one && !many) {
		prsm_problems_add(pr, "/model", "required", "an expression model needs expression (one output, y) or "
		                  "expressions (named outputs, each with its expression)");
	} else if (one) {
		if (prsm_json_string_value(&text, one, "/model/expression", text_max, pr) == 0)
			put_expression(m, "y", text);
	} else {
		for (const cJSON *it = named_items(many, "/model/expressions", 1, PRSM_EXPR_MAX_OUTPUTS, pr); it; it = it->next)
			if (named_item(ip, it, "/model/expressions", pr) == 0 &&
			    prsm_json_string_value(&text, it, ip, text_max, pr) == 0)
				put_expression(m, it->string, text);
	}
}

/* "constants": named numbers, no input's name. */
static void read_constants(prsm_expr_model *m, const cJSON *o, prsm_problems *pr)
{
	const cJSON *cs = cJSON_GetObjectItemCaseSensitive(o, "constants");
	char ip[PRSM_JSON_POINTER_MAX];
	double v;
	for (const cJSON *it = cs ? named_items(cs, "/model/constants", 0, PRSM_EXPR_MAX_CONSTANTS, pr) : NULL; it;
	     it = it->next) {
		if (named_item(ip, it, "/model/constants", pr))
			continue;
		int clash = 0;
		for (size_t i = 0; i < m->n_inputs && !clash; i++)
			clash = strcmp(m->inputs[i], it->string) == 0;
		if (clash) {
			prsm_problems_add(pr, ip, "duplicate", "'%s' is an input: a constant has a name of its own", it->string);
		} else if (prsm_json_number_value(&v, it, ip, ANY, pr) == 0) {
			snprintf(m->constant_names[m->n_constants], sizeof m->constant_names[0], "%s", it->string);
			m->constant_values[m->n_constants++] = v;
		}
	}
}

/* "model" of expressions, once its inputs are read: the expressions and constants, then each
 * expression parsed (a mistake reported at its character); an input no expression reads is a
 * warning. */
int prsm_io_step_expr_model(prsm_io_at *at, prsm_problems *pr)
{
	prsm_expr_model *m = at->base;
	const study_reading *c = at->ctx;
	read_expression_texts(m, at->obj, pr);
	read_constants(m, at->obj, pr);
	if (prsm_problems_total(pr) != at->start)
		return 0;
	unsigned char used[PRSM_EXPR_MAX_INPUTS] = {0}, one[PRSM_EXPR_MAX_INPUTS];
	for (size_t e = 0; e < m->n_exprs; e++) {
		char ep[PRSM_JSON_POINTER_MAX];
		prsm_expr_diag diag;
		if (cJSON_GetObjectItemCaseSensitive(at->obj, "expression"))
			snprintf(ep, sizeof ep, "/model/expression");
		else
			prsm_json_pointer_append(ep, sizeof ep, "/model/expressions", m->expr_names[e]);
		const int rc = prsm_expr_check(m, e, one, &diag);
		if (rc == PRSM_EIO) {
			prsm_problems_add(pr, "/model", diag.code, "%s", diag.message);
			return 0;
		}
		if (rc == 0) {
			for (size_t i = 0; i < m->n_inputs; i++)
				used[i] |= one[i];
		} else if (diag.position == 0) {
			prsm_problems_add(pr, ep, diag.code, "%s", diag.message);
		} else if (diag.position > (int)strlen(m->exprs[e])) {
			prsm_problems_add(pr, ep, diag.code, "at the end (character %d): %s", diag.position, diag.message);
		} else {
			prsm_problems_add(pr, ep, diag.code, "at character %d: %s", diag.position, diag.message);
		}
	}
	if (prsm_problems_total(pr) != at->start || !c || !c->warnings)
		return 0;
	for (size_t i = 0; i < m->n_inputs; i++)
		if (!used[i]) {
			char ip[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(ip, sizeof ip, "/model/inputs", (int)i);
			prsm_problems_add(c->warnings, ip, "unused_input", "input '%s' is in no expression: its tolerance changes "
			                  "no output", m->inputs[i]);
		}
	return 0;
}

/* ---- tolerances -------------------------------------------------------------------------- */

static const char *const hist_arrays[] = {"edges", "weights", NULL};

/* 1 when distribution kind takes the member name: a parameter, or a histogram's bins (the arrays
 * it takes instead of parameters: bin i on [edges[i], edges[i + 1]), weights[i] its weight). */
static int takes(int kind, const char *name)
{
	for (int q = 0; q < 4 && prsm_dist_param_name(kind, q); q++)
		if (strcmp(prsm_dist_param_name(kind, q), name) == 0)
			return 1;
	return kind == PRSM_DIST_HISTOGRAM && (strcmp(name, hist_arrays[0]) == 0 || strcmp(name, hist_arrays[1]) == 0);
}

/* The shorthand {"tol_<unit>": t, "cpk": c[, "nominal": x]}: a normal of sd t / (3 cpk) around the
 * nominal, or for a radial magnitude the Rayleigh with the out-of-tolerance fraction of a centred
 * normal of that Cpk, P(R > t) = 2 Q(3 Cpk). */
static void read_shorthand(prsm_io_at *at, const char *tol_key, const char *path, const param_info *pi,
                           prsm_problems *pr)
{
	prsm_io_tolerance *t = at->base;
	const cJSON *o = at->obj;
	if (path && prsm_problems_total(pr) == at->start) {
		const char *want = pi->unit;
		const char *got = tol_key[3] == '_' ? tol_key + 4 : "";
		if (strcmp(want, got) != 0)
			prsm_io_problem(pr, at->pointer, tol_key, "unit", "%s is in %s: use %s%s%s", t->parameter,
			                want[0] ? want : "its own unit", "tol", want[0] ? "_" : "", want);
	}
	double nominal = 0.0;
	t->tol = NAN;
	t->cpk = 1.0;
	prsm_io_get(at, tol_key, pr);
	prsm_io_get(at, "cpk", pr);
	prsm_json_get_number(&nominal, o, at->pointer, "nominal", PRSM_JSON_OPTIONAL, ANY, pr);
	for (int k = 0; k < PRSM_DIST_KIND_COUNT; k++)
		for (int q = 0; q < 4 && prsm_dist_param_name(k, q); q++) {
			const char *pn = prsm_dist_param_name(k, q);
			int seen = 0; /* each name once (location and scale belong to several kinds) */
			for (int j = 0; j < k && !seen; j++)
				seen = takes(j, pn);
			if (!seen && strcmp(pn, "mean") != 0 && cJSON_GetObjectItemCaseSensitive(o, pn))
				prsm_io_problem(pr, at->pointer, pn, "not_allowed", "%s is a distribution parameter: not with %s",
				                pn, tol_key);
		}
	for (int a = 0; hist_arrays[a]; a++)
		if (cJSON_GetObjectItemCaseSensitive(o, hist_arrays[a]))
			prsm_io_problem(pr, at->pointer, hist_arrays[a], "not_allowed",
			                "%s belongs to a histogram distribution: not with %s", hist_arrays[a], tol_key);
	if (cJSON_GetObjectItemCaseSensitive(o, "mean"))
		prsm_problems_add(pr, at->pointer, "not_allowed", "the shorthand takes nominal, not mean");
	t->shorthand = 1;
	if (!isfinite(t->tol))
		return;
	if (path && pi->radial) {
		t->dist.kind = PRSM_DIST_RAYLEIGH;
		t->dist.p[0] = t->tol / sqrt(-2.0 * log(2.0 * gsl_cdf_ugaussian_Q(3.0 * t->cpk)));
		if (nominal != 0.0)
			prsm_problems_add(pr, at->pointer, "not_allowed", "a radial magnitude has no nominal");
	} else {
		prsm_dist_from_tolerance(&t->dist, nominal, t->tol, t->cpk);
	}
}

/* A histogram's edges and weights, then its bins checked: a problem at the array at fault. */
static void read_histogram(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_tolerance *t = at->base;
	const int before = prsm_problems_total(pr);
	prsm_io_get(at, "edges", pr);
	prsm_io_get(at, "weights", pr);
	if (prsm_problems_total(pr) != before)
		return;
	char msg[200];
	if (prsm_dist_histogram_set(&t->dist, &t->hist, msg, sizeof msg) == 0)
		return;
	/* "histogram edges ...", "histogram weights ..." or "histogram has N edges ... one weight per bin" */
	const char *key = strncmp(msg, "histogram edges", 15) == 0 ? "edges" : "weights";
	prsm_io_problem(pr, at->pointer, key, "bad_distribution", "%s", msg);
}

/* A named distribution: its parameters in its order (normal's and truncnormal's mean and the
 * location of the others default to 0, a deviation from nominal; truncnormal's bounds to none,
 * one at least; prsm_dist_param_default), or a histogram's bins; no other's. */
static void read_named(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_tolerance *t = at->base;
	const cJSON *o = at->obj;
	if (prsm_io_get(at, "distribution", pr) != PRSM_JSON_PRESENT)
		return;
	const int kind = t->dist.kind, bounded = kind == PRSM_DIST_TRUNCNORMAL;
	for (int q = 0; q < 4 && prsm_dist_param_name(kind, q); q++) {
		double fallback = NAN;
		const int optional = prsm_dist_param_default(kind, q, &fallback);
		double v = optional && q == 0 ? fallback : NAN;
		if (prsm_json_get_number(&v, o, at->pointer, prsm_dist_param_name(kind, q),
		                         optional ? PRSM_JSON_OPTIONAL : PRSM_JSON_REQUIRED, ANY, pr) == PRSM_JSON_ABSENT &&
		    optional)
			v = fallback;
		t->dist.p[q] = v;
	}
	if (kind == PRSM_DIST_HISTOGRAM)
		read_histogram(at, pr);
	if (bounded && !cJSON_GetObjectItemCaseSensitive(o, "lower") && !cJSON_GetObjectItemCaseSensitive(o, "upper"))
		prsm_problems_add(pr, at->pointer, "required", "truncnormal needs lower, upper or both");
	char list[64] = ""; /* "mean, sd" */
	for (int q = 0; q < 4 && prsm_dist_param_name(kind, q); q++)
		snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", q ? ", " : "", prsm_dist_param_name(kind, q));
	if (kind == PRSM_DIST_HISTOGRAM)
		snprintf(list, sizeof list, "edges, weights");
	for (const cJSON *it = o->child; it; it = it->next) { /* the parameters of other distributions */
		int any = 0;
		for (int j = 0; j < PRSM_DIST_KIND_COUNT && it->string; j++)
			any |= takes(j, it->string);
		if (any && !takes(kind, it->string))
			prsm_io_problem(pr, at->pointer, it->string, "not_allowed", "%s is not a parameter of %s (it takes %s)",
			                it->string, prsm_dist_name(kind), list);
	}
	if (cJSON_GetObjectItemCaseSensitive(o, "cpk") || cJSON_GetObjectItemCaseSensitive(o, "nominal"))
		prsm_problems_add(pr, at->pointer, "not_allowed", "cpk and nominal belong to the tol shorthand");
}

/* "tolerances"[i]: a parameter the design (or the benchmark) has, the shorthand or a named
 * distribution, checked, and one tolerance per parameter */
int prsm_io_step_tolerance(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_tolerance *t = at->base;
	const prsm_io_study *s = at->root;
	const study_reading *c = at->ctx;
	/* the parameter, when it was read and the design (or benchmark) is known */
	const char *path = c->design_rc == 0 && prsm_io_was_read(at, "parameter")
	                       ? cJSON_GetObjectItemCaseSensitive(at->obj, "parameter")->valuestring : NULL;
	param_info pi;
	char msg[200];
	memset(&pi, 0, sizeof pi);
	if (path && param_find(&pi, path, s, msg, sizeof msg))
		prsm_io_problem(pr, at->pointer, "parameter", "unknown_parameter", "%s: %s", path, msg);
	prsm_io_get(at, "shared", pr);
	static const char *const tol_keys[] = {"tol", "tol_um", "tol_mrad", "tol_um_per_300mm", NULL};
	const char *tol_key = NULL;
	for (int i = 0; tol_keys[i]; i++)
		if (cJSON_GetObjectItemCaseSensitive(at->obj, tol_keys[i])) {
			if (tol_key) {
				prsm_problems_add(pr, at->pointer, "conflict", "give one of tol, tol_um, tol_mrad, tol_um_per_300mm");
				break;
			}
			tol_key = tol_keys[i];
		}
	if (tol_key && cJSON_GetObjectItemCaseSensitive(at->obj, "distribution")) {
		prsm_problems_add(pr, at->pointer, "conflict", "give either a distribution or the %s/cpk shorthand", tol_key);
	} else {
		if (tol_key)
			read_shorthand(at, tol_key, path, &pi, pr);
		else
			read_named(at, pr);
		if (prsm_problems_total(pr) == at->start && prsm_dist_check(&t->dist, msg, sizeof msg))
			prsm_problems_add(pr, at->pointer, "bad_distribution", "%s", msg);
		if (path && prsm_problems_total(pr) == at->start) {
			t->per_roller = pi.per_roller;
			t->per_start = pi.per_start;
			t->radial = pi.radial;
			if (t->shared && !pi.per_roller && !pi.per_start)
				prsm_io_problem(pr, at->pointer, "shared", "not_allowed",
				                "shared applies to per-roller and per-start parameters only");
		}
	}
	for (int k = 0; k < at->index; k++)
		if (t->parameter[0] && strcmp(s->tolerances[k].parameter, t->parameter) == 0)
			prsm_io_problem(pr, at->pointer, "parameter", "duplicate", "%s has a tolerance already (at /tolerances/%d)",
			                t->parameter, k);
	return 0;
}

/* ---- variables --------------------------------------------------------------------------- */

/* Append one variable bound as b. Returns its index. */
static size_t add_var(prsm_io_study *s, const prsm_dist *dist, int group, const prsm_mc_binding *b,
                      const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static size_t add_var(prsm_io_study *s, const prsm_dist *dist, int group, const prsm_mc_binding *b,
                      const char *fmt, ...)
{
	prsm_study *st = &s->study;
	size_t i = st->d++;
	st->vars[i].dist = *dist;
	st->vars[i].group = group;
	st->info[i].phase = st->info[i].phase_of = -1;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(st->info[i].name, sizeof st->info[i].name, fmt, ap);
	va_end(ap);
	s->bindings[i] = *b;
	return i;
}

static size_t count_vars(const prsm_io_tolerance *t, const prsm_io_study *s)
{
	if (s->is_benchmark)
		return 1;
	const int copies = t->shared ? 1 : t->per_roller ? s->design.rollers : t->per_start ? s->design.starts : 1;
	return (size_t)copies * (t->radial ? 2 : 1);
}

/* The variables of tolerance g: one per roller (per start) unless shared, a radial magnitude's
 * each followed by its direction; a benchmark's inputs keep their order (x_i is variable i-1). */
static void build_vars(prsm_io_study *s, size_t g)
{
	const prsm_io_tolerance *t = &s->tolerances[g];
	prsm_study *st = &s->study;
	prsm_study_group *gr = &st->groups[g];
	param_info info, *pi = &info;
	char msg[200];
	param_find(pi, t->parameter, s, msg, sizeof msg); /* found when it was read */
	snprintf(gr->name, sizeof gr->name, "%s", t->parameter);
	/* one variable, named as the tolerance */
	if (s->is_benchmark || pi->part == PRSM_PART_DYNAMICS) {
		const prsm_mc_binding b = {pi->part, 0, pi->offset, pi->scale};
		if (s->is_benchmark) /* x_i is variable i - 1 (the step sets the count once all are in) */
			st->d = (size_t)pi->bench_index;
		gr->first_var = add_var(s, &t->dist, (int)g, &b, "%s", t->parameter);
		gr->n_vars = 1;
		return;
	}
	static const prsm_dist phase = {PRSM_DIST_UNIFORM, {0.0, 2.0 * M_PI, 0.0, 0.0}, NULL};
	const char *key = strchr(t->parameter, '.') + 1;
	/* the key without its unit: runout_um -> runout, tilt_mrad -> tilt */
	const size_t unit_len = strlen(prsm_io_error_unit_of(key));
	const int stem = (int)(unit_len ? strlen(key) - unit_len - 1 : strlen(key));
	const int each = t->per_roller || t->per_start, n = (int)count_vars(t, s) / (t->radial ? 2 : 1);
	gr->first_var = st->d;
	for (int j = 0; j < n; j++) {
		char who[32], idx[16] = ""; /* roller[j].key, part.key[j] or part.key */
		if (t->per_roller && t->shared)
			snprintf(who, sizeof who, "roller[*]");
		else if (t->per_roller)
			snprintf(who, sizeof who, "roller[%d]", j);
		else
			snprintf(who, sizeof who, "%.*s", (int)(key - 1 - t->parameter), t->parameter);
		if (t->per_start && t->shared)
			snprintf(idx, sizeof idx, "[*]");
		else if (t->per_start)
			snprintf(idx, sizeof idx, "[%d]", j);
		/* a start's index error: the start's own double, -1 all starts */
		const prsm_mc_binding b = {pi->part, each ? (t->shared ? -1 : j) : 0,
		                           pi->offset + (t->per_start && !t->shared ? (size_t)j * sizeof(double) : 0), pi->scale};
		const size_t m = add_var(s, &t->dist, (int)g, &b, "%s.%s%s", who, key, idx);
		if (pi->radial) {
			const prsm_mc_binding bp = {b.part, b.roller, pi->phase_offset, 1.0};
			const size_t q = add_var(s, &phase, (int)g, &bp, "%s.%.*s_phase_rad", who, stem, key);
			st->info[m].phase = (int)q;
			st->info[q].phase_of = (int)m;
		}
	}
	gr->n_vars = st->d - gr->first_var;
}

/* The variables of every tolerance, once everything they depend on is valid. */
int prsm_io_step_variables(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_study *s = at->root;
	const size_t nt = s->n_tolerances;
	if (prsm_problems_total(pr) != at->start || nt == 0)
		return 0;
	size_t d = 0;
	for (size_t g = 0; g < nt; g++)
		d += count_vars(&s->tolerances[g], s);
	if (d > PRSM_MC_MAX_VARIABLES) {
		prsm_problems_add(pr, "/tolerances", "too_many", "the tolerances make %zu variables (per roller, "
		                  "per start, with phases): at most %d", d, PRSM_MC_MAX_VARIABLES);
		return 0;
	}
	if (s->is_benchmark && s->bench.kind == PRSM_BENCH_EXPRESSION) {
		for (size_t i = 0; i < s->expr.n_inputs; i++) {
			int found = 0;
			for (size_t g = 0; g < nt && !found; g++)
				found = strcmp(s->tolerances[g].parameter, s->expr.inputs[i]) == 0;
			if (!found) {
				char ip[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append_index(ip, sizeof ip, "/model/inputs", (int)i);
				prsm_problems_add(pr, ip, "incomplete", "input '%s' has no tolerance: give it one (parameter \"%s\")",
				                  s->expr.inputs[i], s->expr.inputs[i]);
			}
		}
	} else if (s->is_benchmark && d != s->bench.inputs) {
		prsm_problems_add(pr, "/tolerances", "incomplete", "the %s benchmark has %zu inputs: give "
		                  "each of x1 .. x%zu one tolerance", prsm_bench_name(s->bench.kind),
		                  s->bench.inputs, s->bench.inputs);
	}
	for (size_t g = 0; g < nt; g++)
		build_vars(s, g);
	if (s->is_benchmark)
		s->study.d = s->bench.inputs;
	s->study.n_groups = nt;
	return 0;
}

/* "correlations"[i]: between two tolerances, variable by variable */
int prsm_io_step_correlation(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_study *s = at->root;
	prsm_study *st = &s->study;
	const prsm_mc_correlation *item = at->base;
	char bp[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(bp, sizeof bp, at->pointer, "between");
	const cJSON *between = cJSON_GetObjectItemCaseSensitive(at->obj, "between");
	if (!cJSON_IsArray(between) || cJSON_GetArraySize(between) != 2 || !cJSON_IsString(between->child) ||
	    !cJSON_IsString(between->child->next)) {
		prsm_problems_add(pr, bp, "bad_array", "between: the parameters of two tolerances");
		return 0;
	}
	int g[2] = {-1, -1};
	for (int k = 0; k < 2; k++) {
		const char *name = (k ? between->child->next : between->child)->valuestring;
		for (size_t t = 0; t < s->n_tolerances; t++)
			if (strcmp(s->tolerances[t].parameter, name) == 0)
				g[k] = (int)t;
		if (g[k] < 0) {
			char ep[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(ep, sizeof ep, bp, k);
			prsm_problems_add(pr, ep, "unknown_tolerance", "'%s' is not one of the study's tolerances", name);
		}
	}
	if (g[0] < 0 || g[1] < 0 || !prsm_io_was_read(at, "rho") || st->d == 0)
		return 0;
	if (g[0] == g[1]) {
		prsm_problems_add(pr, bp, "same", "a tolerance cannot be correlated with itself");
		return 0;
	}
	const prsm_study_group *ga = &st->groups[g[0]], *gb = &st->groups[g[1]];
	size_t step_a = s->tolerances[g[0]].radial ? 2 : 1, step_b = s->tolerances[g[1]].radial ? 2 : 1;
	size_t na = ga->n_vars / step_a, nb = gb->n_vars / step_b;
	if (na != nb && na != 1 && nb != 1) {
		prsm_problems_add(pr, bp, "shape", "these tolerances have %zu and %zu variables: correlate per-roller "
		                  "with per-roller, or with a single tolerance", na, nb);
		return 0;
	}
	if (na != nb) {
		prsm_problems_add(pr, bp, "shape", "a single tolerance cannot be correlated with each of %zu "
		                  "independent ones: make the per-roller one shared, or correlate like with like",
		                  na > nb ? na : nb);
		return 0;
	}
	for (size_t k = 0; k < na; k++) {
		if (st->n_corr >= PRSM_MC_MAX_CORRELATIONS) {
			prsm_problems_add(pr, at->pointer, "too_many", "at most %d correlated variable pairs",
			                  PRSM_MC_MAX_CORRELATIONS);
			break;
		}
		st->corr[st->n_corr++] = (prsm_mc_correlation){ga->first_var + k * step_a, gb->first_var + k * step_b,
		                                               item->rho};
	}
	return 0;
}

/* "correlations": the pairs make a positive definite matrix */
int prsm_io_step_correlations(prsm_io_at *at, prsm_problems *pr)
{
	const prsm_study *st = &((prsm_io_study *)at->root)->study;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_problems_total(pr) == at->start && st->n_corr &&
	    prsm_mc_correlation_check(st->corr, st->n_corr, st->d, &err))
		prsm_problems_add(pr, "/correlations", "not_positive_definite", "%s", err.message);
	return 0;
}

/* ---- outputs, specs, targets ------------------------------------------------------------- */

static int output_index(const prsm_io_study *s, const char *name)
{
	for (size_t o = 0; o < s->study.m; o++)
		if (strcmp(s->study.outputs[o].name, name) == 0)
			return (int)o;
	return -1;
}

/* "monte_carlo"."seed": an integer up to 2^53, which JSON may spell 1e3 */
void prsm_io_hook_seed(void *base, const cJSON *mc, const char *p, prsm_problems *pr)
{
	prsm_mc_options *o = base;
	double seed;
	if (prsm_json_get_number(&seed, mc, p, "seed", PRSM_JSON_OPTIONAL,
	                         (prsm_json_range){0.0, 9007199254740992.0, 0, 0}, pr) == PRSM_JSON_PRESENT) {
		if (seed != floor(seed))
			prsm_problems_add(pr, "/monte_carlo/seed", "integer", "seed must be an integer");
		else
			o->seed = (uint64_t)seed;
	}
}

/* "sensitivity"."sobol": true, false or the Saltelli design's settings ($defs/sobol's table; its
 * sampler is random or sobol, lhs refused with its own message) */
void prsm_io_hook_sobol(void *base, const cJSON *sec, const char *p, prsm_problems *pr)
{
	static const char *const sampler_names[] = {"random", "lhs", "sobol", NULL};
	prsm_sens_options *o = base;
	const cJSON *sob = cJSON_GetObjectItemCaseSensitive(sec, "sobol");
	char sp[PRSM_JSON_POINTER_MAX];
	int v;
	prsm_json_pointer_append(sp, sizeof sp, p, "sobol");
	if (sob && cJSON_IsBool(sob))
		o->sobol = cJSON_IsTrue(sob);
	if (!sob || cJSON_IsBool(sob))
		return;
	if (!cJSON_IsObject(sob)) {
		prsm_problems_add(pr, sp, "type", "sobol: true, false or an object {samples, bootstrap, sampler}");
		return;
	}
	o->sobol = 1;
	prsm_io_read(o, &prsm_io_t_sobol, sob, sp, pr);
	if (o->bootstrap == 1)
		prsm_io_problem(pr, sp, "bootstrap", "range", "bootstrap: 0 (none) or at least 2 resamples");
	if (prsm_json_get_enum(&v, sob, sp, "sampler", PRSM_JSON_OPTIONAL, sampler_names, pr) == PRSM_JSON_PRESENT) {
		if (v == PRSM_SAMPLER_LHS)
			prsm_io_problem(pr, sp, "sampler", "enum", "the Saltelli design takes random or sobol");
		o->sobol_sampler = (prsm_sampler_kind)v;
	}
}

/* "outputs" absent: the benchmark's y, or backlash and load sharing */
int prsm_io_step_outputs(prsm_io_at *at, prsm_problems *pr)
{
	(void)pr;
	prsm_io_study *s = at->root;
	prsm_study_output *o = s->study.outputs;
	if (at->obj)
		return 0;
	if (s->is_benchmark && s->bench.kind == PRSM_BENCH_EXPRESSION) { /* every expression, in order */
		for (size_t e = 0; e < s->expr.n_exprs; e++) {
			snprintf(o[e].name, sizeof o[e].name, "%s", s->expr.expr_names[e]);
			s->expr.output_expr[e] = e;
		}
		s->study.m = s->expr.n_exprs;
		return 0;
	}
	const char *first = s->is_benchmark ? "y" : prsm_output_name(PRSM_OUT_BACKLASH);
	snprintf(o[0].name, sizeof o[0].name, "%s", first);
	s->prsm.outputs[0] = PRSM_OUT_BACKLASH;
	s->study.m = 1;
	if (!s->is_benchmark && s->design.axial_load_N > 0.0) {
		snprintf(o[1].name, sizeof o[1].name, "%s", prsm_output_name(PRSM_OUT_SHARING));
		s->prsm.outputs[1] = PRSM_OUT_SHARING;
		s->study.m = 2;
	}
	return 0;
}

/* "outputs"[i]: a known one, once, at a load when it needs one */
int prsm_io_step_output(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_study *s = at->root;
	const study_reading *c = at->ctx;
	const char *name = at->obj->valuestring;
	const prsm_expr_model *m = &s->expr;
	const int expr = s->is_benchmark && s->bench.kind == PRSM_BENCH_EXPRESSION;
	prsm_output_kind k = PRSM_OUT_BACKLASH;
	size_t e = 0;
	while (expr && e < m->n_exprs && strcmp(m->expr_names[e], name) != 0)
		e++;
	if (expr && e == m->n_exprs && c->design_rc == 0) {
		char list[300] = "";
		for (size_t j = 0; j < m->n_exprs; j++)
			snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", j ? ", " : "", m->expr_names[j]);
		prsm_problems_add(pr, at->pointer, "unknown_output", "'%s' is not an output of the model (%s)", name, list);
		return 0;
	}
	if (!expr && (s->is_benchmark ? strcmp(name, "y") != 0 : prsm_output_parse(name, &k) != 0)) {
		if (s->is_benchmark)
			prsm_problems_add(pr, at->pointer, "unknown_output", "a benchmark has one output, y");
		else
			prsm_problems_add(pr, at->pointer, "unknown_output", "unknown output '%s': " PRSM_OUTPUT_NAMES_TEXT, name);
		return 0;
	}
	if (output_index(s, name) >= 0) {
		prsm_problems_add(pr, at->pointer, "duplicate", "output '%s' is listed twice", name);
		return 0;
	}
	static const char needs_load[PRSM_OUT_COUNT] = PRSM_OUTPUT_NEEDS_LOAD; /* the schema's */
	if (!s->is_benchmark && c->design_rc == 0 && !(s->design.axial_load_N > 0.0) && needs_load[k]) {
		prsm_problems_add(pr, at->pointer, "no_load", "%s needs an operating axial load "
		                  "(/design/operating_point/axial_load_N > 0)", name);
		return 0;
	}
	snprintf(s->study.outputs[s->study.m].name, sizeof s->study.outputs[0].name, "%s", name);
	if (expr)
		s->expr.output_expr[s->study.m] = e < m->n_exprs ? e : 0;
	else if (!s->is_benchmark)
		s->prsm.outputs[s->study.m] = k;
	s->study.m++;
	return 0;
}

/* "specs": keyed by an output of the study */
void *prsm_io_key_spec(const prsm_io_at *at, const char *key, prsm_problems *pr)
{
	prsm_io_study *s = at->root;
	const int o = output_index(s, key);
	if (o >= 0)
		return &s->study.outputs[o];
	prsm_problems_add(pr, at->pointer, "unknown_output", "'%s' is not one of the study's outputs", key);
	return NULL;
}

/* "specs".output: lower, upper or both, lower < upper */
int prsm_io_step_spec(prsm_io_at *at, prsm_problems *pr)
{
	prsm_study_output *o = at->base;
	prsm_spec *spec = &o->spec;
	spec->has_lower = prsm_io_was_read(at, "lower");
	spec->has_upper = prsm_io_was_read(at, "upper");
	if (!cJSON_GetObjectItemCaseSensitive(at->obj, "lower") && !cJSON_GetObjectItemCaseSensitive(at->obj, "upper"))
		prsm_problems_add(pr, at->pointer, "required", "a spec needs lower, upper or both");
	if (spec->has_lower && spec->has_upper && !(spec->lower < spec->upper))
		prsm_io_problem(pr, at->pointer, "upper", "range", "upper must be greater than lower");
	o->has_spec = spec->has_lower || spec->has_upper;
	return 0;
}

/* "monte_carlo"."targets"[i]: for an output of the study, exactly one kind; a yield's needs the
 * output's spec (nonzero: not kept) */
int prsm_io_step_target(prsm_io_at *at, prsm_problems *pr)
{
	prsm_mc_target *tg = at->base;
	const prsm_io_study *s = at->root;
	if (!prsm_io_was_read(at, "output"))
		return 1;
	const char *name = cJSON_GetObjectItemCaseSensitive(at->obj, "output")->valuestring;
	const int o = output_index(s, name);
	if (o < 0) {
		prsm_io_problem(pr, at->pointer, "output", "unknown_output", "'%s' is not one of the study's outputs", name);
		return 1;
	}
	tg->output = (size_t)o;
	int kinds = prsm_io_get(at, "standard_error", pr) == PRSM_JSON_PRESENT;
	kinds += prsm_io_get(at, "cv", pr) == PRSM_JSON_PRESENT;
	kinds += prsm_io_get(at, "yield_interval_width", pr) == PRSM_JSON_PRESENT;
	if (kinds != 1) {
		prsm_problems_add(pr, at->pointer, "required",
		                  "a target has exactly one of standard_error, cv, yield_interval_width");
		return 1;
	}
	if (tg->kind == PRSM_TARGET_YIELD_WIDTH) {
		const prsm_study_output *so = &s->study.outputs[o];
		if (!so->has_spec) {
			prsm_problems_add(pr, at->pointer, "no_spec", "a yield target needs a spec for %s in specs", name);
			return 1;
		}
		tg->has_lower = so->spec.has_lower;
		tg->has_upper = so->spec.has_upper;
		tg->lower = so->spec.lower;
		tg->upper = so->spec.upper;
	}
	return 0;
}

/* ---- the model --------------------------------------------------------------------------- */

/* Storage within limits, then the engine's model of the study (a design study's by the
 * caller's hook). */
int prsm_io_step_model(prsm_io_at *at, prsm_problems *pr)
{
	const study_reading *c = at->ctx;
	prsm_io_study *out = at->root;
	prsm_study *st = &out->study;
	if (prsm_problems_total(pr) != at->start)
		return 0;
	double stored = (double)(st->d + st->m) * (double)st->mc.samples;
	if (stored > PRSM_MC_MAX_STORED)
		prsm_problems_add(pr, "/monte_carlo/samples", "too_large",
		                  "%zu samples of %zu variables and %zu outputs would store %.0f values (limit %d): "
		                  "take fewer samples", st->mc.samples, st->d, st->m, stored, PRSM_MC_MAX_STORED);
	if (st->sens.sobol) {
		double ss = (double)st->m * (double)(st->n_groups + 2) * (double)st->sens.sobol_samples;
		if (ss > PRSM_MC_MAX_STORED)
			prsm_problems_add(pr, "/sensitivity/sobol/samples", "too_large",
			                  "the Saltelli design would store %.0f values (limit %d)", ss, PRSM_MC_MAX_STORED);
	}
	if (prsm_problems_total(pr) != at->start)
		return 0;
	if (out->is_benchmark && out->bench.kind == PRSM_BENCH_EXPRESSION) {
		/* the variables are the inputs in order; the outputs those the study asks for */
		out->expr.n_outputs = st->m;
		prsm_expr_mc_model(&st->model, &out->expr);
		return 0;
	}
	if (out->is_benchmark) {
		/* benchmark variables are the inputs in order */
		prsm_bench_mc_model(&st->model, &out->bench);
		return 0;
	}
	prsm_mc_prsm *p = &out->prsm;
	p->as = &out->assembly;
	p->an = &out->analysis;
	p->mode = out->assembly_options.mode;
	p->angles_per_revolution = out->assembly_options.angles_per_revolution;
	p->measuring_load_N = out->assembly_options.measuring_load_N;
	p->n_bindings = st->d;
	p->bindings = out->bindings;
	p->n_outputs = st->m;
	p->dyn = NULL;
	/* the dynamic model of the nominal design, the nut unit's terms and the model itself are
	 * computed: the caller's (app/study.c) */
	if (c->o->prepare_model)
		c->o->prepare_model(out, pr, c->o->ctx);
	return 0;
}

/* "dynamic_monte_carlo"."grid_per_segment": a power of 2 from 8 to 256 */
void prsm_io_hook_grid_per_segment(void *base, const cJSON *dmc, const char *p, prsm_problems *pr)
{
	int *grid = &((prsm_io_study *)base)->dynamics.options.grid_per_segment;
	if (prsm_json_get_int(grid, dmc, p, "grid_per_segment", PRSM_JSON_OPTIONAL, 8, 256, pr) == PRSM_JSON_PRESENT &&
	    (*grid & (*grid - 1)) != 0)
		prsm_io_problem(pr, p, "grid_per_segment", "enum", "grid_per_segment is a power of 2 (8 to 256)");
}

/* "dynamics" and "dynamic_monte_carlo" (docs/vibration.md, "Monte Carlo over dynamic outputs"):
 * read when a dynamic output is asked (the section as a vibration analysis takes it), refused
 * otherwise; contact_loss, regime and integrated are added to the outputs when missing (the
 * probabilities and the screening summary count them); the stop rule becomes yield-width
 * targets on them (checked on the completed blocks, like the other targets). */
int prsm_io_step_dynamics(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_study *s = at->root;
	const study_reading *c = at->ctx;
	const cJSON *dyn = cJSON_GetObjectItemCaseSensitive(at->obj, "dynamics");
	s->has_dynamics = 0;
	if (c->design_rc != 0)
		return 0;
	int first_out = -1, first_tol = -1;
	for (size_t o = 0; o < s->study.m && !s->is_benchmark; o++)
		if (first_out < 0 && prsm_output_is_dynamic(s->prsm.outputs[o]))
			first_out = (int)o;
	for (size_t g = 0; g < s->n_tolerances && !s->is_benchmark; g++) {
		const char *name = s->tolerances[g].parameter;
		if (first_tol < 0 && (strncmp(name, "ring_gear.", 10) == 0 || strcmp(name, "damping_ratio") == 0))
			first_tol = (int)g;
	}
	if (first_out < 0) {
		if (dyn) {
			char names[400] = ""; /* the dynamic outputs' names, in the order of their constants */
			size_t n = 0;
			for (int k = 0; k < PRSM_OUT_COUNT && n < sizeof names; k++)
				if (prsm_output_is_dynamic((prsm_output_kind)k))
					n += (size_t)snprintf(names + n, sizeof names - n, "%s%s", n ? ", " : "",
					                      prsm_output_name((prsm_output_kind)k));
			prsm_problems_add(pr, "/dynamics", "not_used", "the dynamics section is for dynamic outputs (%s): name one "
			                  "in outputs, or leave the section out", names);
		}
		if (cJSON_GetObjectItemCaseSensitive(at->obj, "dynamic_monte_carlo"))
			prsm_problems_add(pr, "/dynamic_monte_carlo", "not_used", "dynamic_monte_carlo is for dynamic outputs");
		if (first_tol >= 0) {
			char tp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(tp, sizeof tp, "/tolerances", first_tol);
			prsm_io_problem(pr, tp, "parameter", "not_used", "%s is a parameter of the dynamic model: it needs a "
			                "dynamic output and the dynamics section", s->tolerances[first_tol].parameter);
		}
		return 0;
	}
	if (dyn == NULL) {
		char op[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(op, sizeof op, "/outputs", first_out);
		prsm_problems_add(pr, "/dynamics", "required", "output %s (at %s) needs the dynamics section: the reduced "
		                  "vibration model as a vibration analysis takes it (docs/vibration.md)",
		                  s->study.outputs[first_out].name, op);
		return 0;
	}
	s->dyn_stop_half_width = NAN;
	prsm_io_vib_request *v = malloc(sizeof *v);
	prsm_dyn_options o;
	if (v == NULL) {
		prsm_problems_add(pr, "/dynamics", "memory", "out of memory reading the dynamics section");
		return 0;
	}
	const int before = prsm_problems_total(pr);
	if (prsm_io_dynamics_read(&o, v, dyn, 1, pr) == 0) {
		if (v->analysis != PRSM_IO_DYN_VIBRATION)
			prsm_problems_add(pr, "/dynamics/analysis", "enum", "the dynamic outputs take the vibration analysis's "
			                  "model: \"analysis\": \"vibration\"");
		else if (v->gear_pair_model)
			prsm_problems_add(pr, "/dynamics/gear_pair", "not_allowed", "the dynamic outputs take the reduced model of "
			                  "the design, not the gear pair");
		else if (v->vibration.branches != PRSM_VIB_BRANCHES_BOTH)
			prsm_problems_add(pr, "/dynamics/vibration/branches", "enum", "the dynamic outputs need both branches "
			                  "(the thread and the ring gears)");
	}
	prsm_mc_dyn *d = &s->dynamics;
	d->dyn = o;
	d->vib = v->vibration;
	free(v);
	if (!cJSON_GetObjectItemCaseSensitive(dyn, "load"))
		d->dyn.load.value = s->design.axial_load_N; /* F_0: the operating load of the statics */
	/* the sample replaces the TE lines, the axial stiffness and the play */
	d->vib.te_source = PRSM_VIB_TE_NONE;
	d->vib.te_lines = 0;
	d->vib.axial_stiffness_N_per_um = NAN;
	d->vib.axial_half_play_um = NAN;
	prsm_vib_mc_options_init(&d->options);
	d->window_rev = 0.0;
	prsm_io_get(at, "dynamic_monte_carlo", pr); /* its table; rel_tol is the absolute tolerance too */
	d->options.integration.abs_tol = d->options.integration.rel_tol;
	if (prsm_problems_total(pr) != before)
		return 0;
	/* contact_loss, regime, integrated always (the probabilities and the screening summary) */
	static const prsm_output_kind always[3] = {PRSM_OUT_DYN_CONTACT_LOSS, PRSM_OUT_DYN_REGIME, PRSM_OUT_DYN_INTEGRATED};
	int idx[3];
	for (int k = 0; k < 3; k++) {
		idx[k] = output_index(s, prsm_output_name(always[k]));
		if (idx[k] >= 0)
			continue;
		if (s->study.m >= PRSM_MC_MAX_OUTPUTS) {
			prsm_problems_add(pr, "/outputs", "too_many", "dynamic outputs add contact_loss, regime and integrated: "
			                  "at most %d outputs in all", PRSM_MC_MAX_OUTPUTS);
			return 0;
		}
		idx[k] = (int)s->study.m;
		snprintf(s->study.outputs[s->study.m].name, sizeof s->study.outputs[0].name, "%s", prsm_output_name(always[k]));
		s->prsm.outputs[s->study.m] = always[k];
		s->study.m++;
	}
	/* the stop rule: 95 % Wilson width of P(loss) and P(periodic) <= 2 x half-width */
	if (!isnan(s->dyn_stop_half_width)) {
		prsm_mc_options *mo = &s->study.mc;
		if (mo->n_targets + 2 > PRSM_MC_MAX_TARGETS) {
			prsm_problems_add(pr, "/dynamic_monte_carlo/stop_half_width", "too_many", "the stop rule adds two targets: "
			                  "at most %d in all", PRSM_MC_MAX_TARGETS);
			return 0;
		}
		prsm_mc_target t = {PRSM_TARGET_YIELD_WIDTH, (size_t)idx[0], 2.0 * s->dyn_stop_half_width, 0, 1, 0.0, 0.5};
		mo->targets[mo->n_targets++] = t;
		prsm_mc_target r = {PRSM_TARGET_YIELD_WIDTH, (size_t)idx[1], 2.0 * s->dyn_stop_half_width, 1, 0, 0.5, 0.0};
		mo->targets[mo->n_targets++] = r;
	}
	s->has_dynamics = 1;
	return 0;
}

int prsm_io_study_options_init(prsm_io_study_options *o)
{
	*o = (prsm_io_study_options)PRSM_IO_STUDY_OPTIONS_INIT;
	return 0;
}

/* prsm_io_study_load without hooks->check_study (the range checks of app/study.c) and the
 * warning on the older output name: the document as read. */
static int study_read(prsm_io_study *out, const cJSON *doc, const prsm_io_study_options *hooks,
                      prsm_problems *warnings, prsm_problems *pr)
{
	static const prsm_io_study_options none = PRSM_IO_STUDY_OPTIONS_INIT;
	memset(out, 0, sizeof *out);
	if (prsm_json_object_value(doc, "", pr))
		return PRSM_EINVAL;
	study_reading c = {warnings, PRSM_EINVAL, hooks ? hooks : &none};
	if (prsm_io_read_ctx(out, &prsm_io_t_study, doc, "", &c, pr) == 0)
		return 0;
	return c.design_rc && c.design_rc != PRSM_EINVAL ? c.design_rc : PRSM_EINVAL;
}

int prsm_io_study_load(prsm_io_study *out, const cJSON *doc, const prsm_io_study_options *hooks,
                       prsm_problems *warnings, prsm_problems *pr)
{
	int rc = study_read(out, doc, hooks, warnings, pr);
	if (rc)
		return rc;
	const int before = prsm_problems_total(pr);
	/* what only a computation can tell: the caller's (app/study.c) */
	if (hooks && hooks->check_study)
		hooks->check_study(out, warnings, pr, hooks->ctx);
	/* "efficiency" is the older name of the sliding efficiency: say which efficiency it is, as a
	 * spec on it is easily read as one on analyze's eta with its losses */
	for (size_t o = 0; warnings && !out->is_benchmark && o < out->study.m; o++)
		if (strcmp(out->study.outputs[o].name, "efficiency") == 0) {
			char op[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(op, sizeof op, "/outputs", (int)o);
			prsm_problems_add(warnings, op, "older_name",
			                  "efficiency is the sliding efficiency (friction on the flanks only; case A 0.90467), "
			                  "not prsm analyze's eta with its losses (efficiency_with_losses, case A 0.89579): "
			                  "name it efficiency_sliding, or ask for efficiency_with_losses to judge a spec on the "
			                  "efficiency the analysis shows");
		}
	return prsm_problems_total(pr) > before ? PRSM_EINVAL : 0;
}
