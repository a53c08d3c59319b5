/*
 * study_reader_legacy.c: the hand-written study reader before issue 24's port (src/io/study_json.c
 * as it was, its monte_carlo and sensitivity sections read by study_mc_legacy.c), for the
 * side-by-side proof in tests/test_io_doc.c. Delete it with that test once every document is
 * ported. Only the entry point is renamed: prsm_legacy_study_load.
 */
#include "legacy/design_reader_legacy.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "io/analyze_request.h"
#include "io/design_json.h"
#include "io/errors_json.h"
#include "io/json_util.h"
#include "model/analysis.h"
#include "model/performance.h"
#include "util/utf8.h"
#include "util/version.h"

/* dynamics and dynamic_monte_carlo (issue 17 item 4) came after the port: known here only so that
 * the unknown-key message lists the same names; test_io_doc leaves documents with them out */
static const char *const study_keys[] = {"name", "design", "model", "errors", "assembly",
                                         "tolerances", "correlations", "outputs", "specs",
                                         "monte_carlo", "sensitivity", "rare_events", "dynamics",
                                         "dynamic_monte_carlo", NULL};
static const char *const model_keys[] = {"benchmark", "a", "b", "coefficients", "constant", NULL};
static const char *const bench_names[] = {"ishigami", "gfunction", "linear", NULL};
static const char *const tolerance_keys[] = {
	"parameter", "distribution", "mean", "sd", "lower", "upper", "mode", "mu", "sigma",
	"scale", "location", "shape", "alpha", "beta", "edges", "weights",
	"tol", "tol_um", "tol_mrad", "tol_um_per_300mm", "cpk", "nominal", "shared", NULL};
static const char *const dist_names[] = {"normal", "truncnormal", "uniform", "triangular",
                                         "lognormal", "rayleigh", "exponential", "gamma",
                                         "weibull", "beta", "gumbel", "histogram", NULL}; /* = prsm_dist_kind */
static const char *const spec_keys[] = {"lower", "upper", "yield_method", NULL};
static const char *const yield_method_names[] = {"mc", "auto", "form", "sorm", "is", "subset", NULL};
static const char *const rare_keys[] = {"max_evaluations", "target_cov", "subset_samples", NULL};
static const char *const corr_keys[] = {"between", "rho", NULL};

static const prsm_json_range ANY = {-HUGE_VAL, HUGE_VAL, 0, 0};

/* 1 when parameter q of kind k is the first of that name (a name is reported once). */
static int first_kind_of(const char *name, int k, int q)
{
	for (int j = 0; j <= k; j++)
		for (int r = 0; r < (j == k ? q : 4) && prsm_dist_param_name(j, r); r++)
			if (strcmp(prsm_dist_param_name(j, r), name) == 0)
				return 0;
	return 1;
}
static const prsm_json_range POSITIVE = {0.0, HUGE_VAL, 1, 0};


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

static const char *unit_of(const char *key)
{
	static const char *const units[] = {"um_per_300mm", "um", "mrad", "deg", NULL};
	for (int i = 0; units[i]; i++) {
		size_t lk = strlen(key), lu = strlen(units[i]);
		if (lk > lu + 1 && strcmp(key + lk - lu, units[i]) == 0 && key[lk - lu - 1] == '_')
			return units[i];
	}
	return "";
}

/* Returns 0, or PRSM_ENOTFOUND with a message in msg. */
static int param_find(param_info *pi, const char *path, const prsm_io_study *s, char *msg, size_t cap)
{
	memset(pi, 0, sizeof *pi);
	pi->bench_index = -1;
	if (s->is_benchmark) {
		/* x1 .. xn exactly: no leading zero, sign or blank */
		size_t idx = 0, k = 1;
		int ok = path[0] == 'x' && path[1] >= '1' && path[1] <= '9';
		for (; ok && path[k]; k++) {
			if (path[k] < '0' || path[k] > '9' || idx > 1000) {
				ok = 0;
				break;
			}
			idx = 10 * idx + (size_t)(path[k] - '0');
		}
		if (ok && idx >= 1 && idx <= s->bench.inputs) {
			pi->bench_index = (int)idx - 1;
			pi->unit = "";
			pi->scale = 1.0;
			return 0;
		}
		snprintf(msg, cap, "the %s benchmark has inputs x1 .. x%zu", prsm_bench_name(s->bench.kind),
		         s->bench.inputs);
		return PRSM_ENOTFOUND;
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
	if (strcmp(part, "friction") == 0) {
		pi->part = PRSM_PART_FRICTION;
		pi->scale = 1.0;
		pi->unit = "";
		if (strcmp(key, "screw_roller_mu") == 0)
			pi->offset = 0;
		else if (strcmp(key, "nut_roller_mu") == 0)
			pi->offset = 1;
		else {
			snprintf(msg, cap, "friction parameters are screw_roller_mu and nut_roller_mu "
			                   "(deviations added to the design's coefficients)");
			return PRSM_ENOTFOUND;
		}
		return 0;
	}
	if (strcmp(part, "screw") == 0)
		pi->part = PRSM_PART_SCREW;
	else if (strcmp(part, "nut") == 0)
		pi->part = PRSM_PART_NUT;
	else if (strcmp(part, "carrier") == 0)
		pi->part = PRSM_PART_CARRIER;
	else if (strcmp(part, "roller") == 0)
		pi->part = PRSM_PART_ROLLER;
	else {
		/* the message names the dynamic model's parameters too (issue 17 item 4: today's reader
		 * knows them; documents using them are left out of the comparison) */
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
	pi->per_roller = pi->part == PRSM_PART_ROLLER;
	pi->unit = unit_of(key);
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

/* ---- sections ---------------------------------------------------------------------------- */

static void read_benchmark(prsm_io_study *s, const cJSON *m, const char *ptr, prsm_problems *pr)
{
	int kind = 0;
	prsm_json_check_keys(m, ptr, model_keys, pr);
	if (prsm_json_get_enum(&kind, m, ptr, "benchmark", PRSM_JSON_REQUIRED, bench_names, pr) != PRSM_JSON_PRESENT)
		return;
	prsm_bench_model *b = &s->bench;
	b->kind = (prsm_bench_kind)kind;
	char ap[PRSM_JSON_POINTER_MAX];
	const char *arr_key = kind == PRSM_BENCH_GFUNCTION ? "a" : "coefficients";
	if (kind == PRSM_BENCH_ISHIGAMI) {
		b->inputs = 3;
		b->a = 7.0;
		b->b = 0.1;
		prsm_json_get_number(&b->a, m, ptr, "a", PRSM_JSON_OPTIONAL, ANY, pr);
		prsm_json_get_number(&b->b, m, ptr, "b", PRSM_JSON_OPTIONAL, ANY, pr);
		static const char *const foreign[] = {"coefficients", "constant", NULL};
		for (int k = 0; foreign[k]; k++)
			if (cJSON_GetObjectItemCaseSensitive(m, foreign[k])) {
				prsm_json_pointer_append(ap, sizeof ap, ptr, foreign[k]);
				prsm_problems_add(pr, ap, "not_allowed", "the Ishigami benchmark takes a and b only");
			}
		return;
	}
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(m, arr_key);
	prsm_json_pointer_append(ap, sizeof ap, ptr, arr_key);
	int n = cJSON_GetArraySize(arr);
	if (!cJSON_IsArray(arr) || n < 1 || n > PRSM_BENCH_MAX_INPUTS) {
		prsm_problems_add(pr, ap, arr ? "bad_array" : "required",
		                  "%s: an array of 1 to %d numbers is required", arr_key, PRSM_BENCH_MAX_INPUTS);
		return;
	}
	b->inputs = (size_t)n;
	int i = 0;
	for (const cJSON *it = arr->child; it; it = it->next, i++) {
		char ip[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(ip, sizeof ip, ap, i);
		prsm_json_range r = kind == PRSM_BENCH_GFUNCTION ? (prsm_json_range){0.0, HUGE_VAL, 0, 0} : ANY;
		prsm_json_number_value(&b->coef[i], it, ip, r, pr);
	}
	if (kind == PRSM_BENCH_LINEAR)
		prsm_json_get_number(&b->constant, m, ptr, "constant", PRSM_JSON_OPTIONAL, ANY, pr);
	const char *other = kind == PRSM_BENCH_GFUNCTION ? "coefficients" : "a";
	if (cJSON_GetObjectItemCaseSensitive(m, other) || cJSON_GetObjectItemCaseSensitive(m, "b") ||
	    (kind == PRSM_BENCH_GFUNCTION && cJSON_GetObjectItemCaseSensitive(m, "constant"))) {
		prsm_problems_add(pr, ptr, "not_allowed", "the %s benchmark takes %s only",
		                  bench_names[kind], kind == PRSM_BENCH_GFUNCTION ? "a" : "coefficients and constant");
	}
}

/* The design and what the engine needs of it. Returns 0 when it is usable. */
static int read_design(prsm_io_study *s, const cJSON *doc, prsm_problems *warnings, prsm_problems *pr)
{
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
	prsm_error err = PRSM_ERROR_INIT;
	int arc = prsm_analysis_nominal(&s->analysis, &s->design, warnings, &err);
	if (arc == 0)
		arc = prsm_assembly_init(&s->assembly, &s->design, &s->analysis, &err);
	if (arc) {
		char ptr[PRSM_JSON_POINTER_MAX + 8];
		snprintf(ptr, sizeof ptr, "/design%s", err.pointer);
		prsm_problems_add(pr, ptr, arc == PRSM_EEDGE ? "edge_contact" : arc == PRSM_EINVAL ? "too_large" : "no_contact",
		                  "%s", err.message);
		return arc;
	}
	return 0;
}

/* Read one tolerance into t (and its parameter into pi). Returns 0 when valid. */
static int read_tolerance(prsm_io_tolerance *t, param_info *pi, const prsm_io_study *s,
                          const cJSON *o, const char *ptr, int params_known, prsm_problems *pr)
{
	int bad = prsm_problems_total(pr);
	memset(t, 0, sizeof *t);
	if (prsm_json_object_value(o, ptr, pr))
		return PRSM_EINVAL;
	prsm_json_check_keys(o, ptr, tolerance_keys, pr);
	const char *path = NULL;
	char pp[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(pp, sizeof pp, ptr, "parameter");
	int have_path = prsm_json_get_string(&path, o, ptr, "parameter", PRSM_JSON_REQUIRED,
	                                     PRSM_STUDY_NAME_MAX - 24, pr) == PRSM_JSON_PRESENT;
	if (have_path) {
		prsm_utf8_copy(t->parameter, sizeof t->parameter, path);
		char msg[200];
		if (params_known && param_find(pi, path, s, msg, sizeof msg))
			prsm_problems_add(pr, pp, "unknown_parameter", "%s: %s", path, msg);
	}
	int shared = 0;
	prsm_json_get_bool(&shared, o, ptr, "shared", PRSM_JSON_OPTIONAL, pr);
	t->shared = shared;

	/* the shorthand {"tol_<unit>": t, "cpk": c[, "nominal": x]} or a named distribution */
	const char *tol_key = NULL;
	static const char *const tol_keys[] = {"tol", "tol_um", "tol_mrad", "tol_um_per_300mm", NULL};
	for (int i = 0; tol_keys[i]; i++)
		if (cJSON_GetObjectItemCaseSensitive(o, tol_keys[i])) {
			if (tol_key) {
				prsm_problems_add(pr, ptr, "conflict", "give one of tol, tol_um, tol_mrad, tol_um_per_300mm");
				break;
			}
			tol_key = tol_keys[i];
		}
	const cJSON *dist = cJSON_GetObjectItemCaseSensitive(o, "distribution");
	if (tol_key && dist) {
		prsm_problems_add(pr, ptr, "conflict", "give either a distribution or the %s/cpk shorthand", tol_key);
		return PRSM_EINVAL;
	}
	if (tol_key) {
		char tp[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(tp, sizeof tp, ptr, tol_key);
		if (have_path && params_known && prsm_problems_total(pr) == bad) {
			const char *want = pi->unit;
			const char *got = tol_key[3] == '_' ? tol_key + 4 : "";
			if (strcmp(want, got) != 0)
				prsm_problems_add(pr, tp, "unit", "%s is in %s: use %s%s%s", t->parameter,
				                  want[0] ? want : "its own unit", "tol", want[0] ? "_" : "", want);
		}
		double tol = NAN, cpk = 1.0, nominal = 0.0;
		prsm_json_get_number(&tol, o, ptr, tol_key, PRSM_JSON_REQUIRED, POSITIVE, pr);
		prsm_json_get_number(&cpk, o, ptr, "cpk", PRSM_JSON_OPTIONAL, (prsm_json_range){0.1, 10.0, 0, 0}, pr);
		prsm_json_get_number(&nominal, o, ptr, "nominal", PRSM_JSON_OPTIONAL, ANY, pr);
		for (int k = 0; k < 6; k++)
			for (int q = 0; q < 4 && prsm_dist_param_name(k, q); q++)
				if (strcmp(prsm_dist_param_name(k, q), "mean") != 0 && cJSON_GetObjectItemCaseSensitive(o, prsm_dist_param_name(k, q)) &&
				    first_kind_of(prsm_dist_param_name(k, q), k, q)) {
					char xp[PRSM_JSON_POINTER_MAX];
					prsm_json_pointer_append(xp, sizeof xp, ptr, prsm_dist_param_name(k, q));
					prsm_problems_add(pr, xp, "not_allowed", "%s is a distribution parameter: not with %s",
					                  prsm_dist_param_name(k, q), tol_key);
				}
		if (cJSON_GetObjectItemCaseSensitive(o, "mean"))
			prsm_problems_add(pr, ptr, "not_allowed", "the shorthand takes nominal, not mean");
		t->shorthand = 1;
		t->tol = tol;
		t->cpk = cpk;
		if (isfinite(tol)) {
			if (have_path && params_known && pi->radial) {
				/* a radial magnitude: Rayleigh, with the out-of-tolerance fraction of a centred
				 * normal of that Cpk, P(R > t) = 2 Q(3 Cpk) */
				double tail = 2.0 * gsl_cdf_ugaussian_Q(3.0 * cpk);
				t->dist.kind = PRSM_DIST_RAYLEIGH;
				t->dist.p[0] = tol / sqrt(-2.0 * log(tail));
				if (nominal != 0.0)
					prsm_problems_add(pr, ptr, "not_allowed", "a radial magnitude has no nominal");
			} else {
				prsm_dist_from_tolerance(&t->dist, nominal, tol, cpk);
			}
		}
	} else {
		int kind = 0;
		if (prsm_json_get_enum(&kind, o, ptr, "distribution", PRSM_JSON_REQUIRED, dist_names, pr) ==
		    PRSM_JSON_PRESENT) {
			t->dist.kind = (prsm_dist_kind)kind;
			for (int q = 0; q < 4; q++) {
				const char *pn = prsm_dist_param_name(kind, q);
				if (!pn)
					break;
				/* normal's mean defaults to 0 (a deviation from nominal) */
				int optional = (kind == PRSM_DIST_NORMAL || kind == PRSM_DIST_TRUNCNORMAL) && q == 0;
				double v = optional ? 0.0 : NAN;
				prsm_json_range r = ANY;
				if (kind == PRSM_DIST_TRUNCNORMAL && q >= 2)
					r = (prsm_json_range){-HUGE_VAL, HUGE_VAL, 0, 0};
				int got = prsm_json_get_number(&v, o, ptr, pn,
				                               optional || (kind == PRSM_DIST_TRUNCNORMAL && q >= 2)
				                                   ? PRSM_JSON_OPTIONAL : PRSM_JSON_REQUIRED, r, pr);
				if (kind == PRSM_DIST_TRUNCNORMAL && q >= 2 && got == PRSM_JSON_ABSENT)
					v = q == 2 ? -INFINITY : INFINITY;
				t->dist.p[q] = v;
			}
			if (kind == PRSM_DIST_TRUNCNORMAL && !cJSON_GetObjectItemCaseSensitive(o, "lower") &&
			    !cJSON_GetObjectItemCaseSensitive(o, "upper"))
				prsm_problems_add(pr, ptr, "required", "truncnormal needs lower, upper or both");
			/* parameters of other distributions */
			for (const cJSON *it = o->child; it; it = it->next) {
				if (!it->string)
					continue;
				int mine = 0, foreign = 0;
				for (int k = 0; k < 6; k++)
					for (int q = 0; q < 4 && prsm_dist_param_name(k, q); q++)
						if (strcmp(prsm_dist_param_name(k, q), it->string) == 0) {
							foreign = 1;
							mine |= k == kind;
						}
				if (foreign && !mine) {
					char xp[PRSM_JSON_POINTER_MAX];
					prsm_json_pointer_append(xp, sizeof xp, ptr, it->string);
					prsm_problems_add(pr, xp, "not_allowed", "%s is not a parameter of %s (it takes %s%s%s%s%s%s%s)",
					                  it->string, dist_names[kind], prsm_dist_param_name(kind, 0),
					                  prsm_dist_param_name(kind, 1) ? ", " : "", prsm_dist_param_name(kind, 1) ? prsm_dist_param_name(kind, 1) : "",
					                  prsm_dist_param_name(kind, 2) ? ", " : "", prsm_dist_param_name(kind, 2) ? prsm_dist_param_name(kind, 2) : "",
					                  prsm_dist_param_name(kind, 3) ? ", " : "", prsm_dist_param_name(kind, 3) ? prsm_dist_param_name(kind, 3) : "");
				}
			}
			if (cJSON_GetObjectItemCaseSensitive(o, "cpk") || cJSON_GetObjectItemCaseSensitive(o, "nominal"))
				prsm_problems_add(pr, ptr, "not_allowed", "cpk and nominal belong to the tol shorthand");
		}
	}
	if (prsm_problems_total(pr) == bad) {
		char msg[200];
		if (prsm_dist_check(&t->dist, msg, sizeof msg))
			prsm_problems_add(pr, ptr, "bad_distribution", "%s", msg);
	}
	if (have_path && params_known && prsm_problems_total(pr) == bad) {
		t->per_roller = pi->per_roller;
		t->per_start = pi->per_start;
		t->radial = pi->radial;
		if (shared && !pi->per_roller && !pi->per_start) {
			char sp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(sp, sizeof sp, ptr, "shared");
			prsm_problems_add(pr, sp, "not_allowed", "shared applies to per-roller and per-start parameters only");
		}
	}
	return prsm_problems_total(pr) == bad ? 0 : PRSM_EINVAL;
}

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
	size_t copies = 1;
	if (t->per_roller && !t->shared)
		copies = (size_t)s->design.rollers;
	if (t->per_start && !t->shared)
		copies = (size_t)s->design.starts;
	return copies * (t->radial ? 2 : 1);
}

/* Variables of tolerance g. */
static void build_vars(prsm_io_study *s, size_t g, const param_info *pi)
{
	const prsm_io_tolerance *t = &s->tolerances[g];
	prsm_study *st = &s->study;
	prsm_study_group *gr = &st->groups[g];
	snprintf(gr->name, sizeof gr->name, "%s", t->parameter);
	gr->first_var = st->d;
	prsm_mc_binding b = {pi->part, 0, pi->offset, pi->scale};
	prsm_dist phase = {PRSM_DIST_UNIFORM, {0.0, 2.0 * M_PI, 0.0, 0.0}, NULL};
	const char *dot = strchr(t->parameter, '.');
	const char *key = dot ? dot + 1 : t->parameter;
	char stem[PRSM_STUDY_NAME_MAX];
	/* the key without its unit: runout_um -> runout, tilt_mrad -> tilt */
	size_t unit_len = strlen(unit_of(key));
	snprintf(stem, sizeof stem, "%.*s", (int)(unit_len ? strlen(key) - unit_len - 1 : strlen(key)), key);
	if (s->is_benchmark) {
		/* benchmark inputs keep their own order: x_i is variable i-1 */
		size_t i = (size_t)pi->bench_index;
		st->vars[i].dist = t->dist;
		st->vars[i].group = (int)g;
		st->info[i].phase = st->info[i].phase_of = -1;
		snprintf(st->info[i].name, sizeof st->info[i].name, "%s", t->parameter);
		gr->first_var = i;
		gr->n_vars = 1;
		return;
	} else if (t->per_roller) {
		int Z = t->shared ? 1 : s->design.rollers;
		for (int j = 0; j < Z; j++) {
			b.roller = t->shared ? -1 : j;
			b.offset = pi->offset;
			b.scale = pi->scale;
			char who[32];
			if (t->shared)
				snprintf(who, sizeof who, "roller[*]");
			else
				snprintf(who, sizeof who, "roller[%d]", j);
			size_t m = add_var(s, &t->dist, (int)g, &b, "%s.%s", who, key);
			if (pi->radial) {
				prsm_mc_binding bp = b;
				bp.offset = pi->phase_offset;
				bp.scale = 1.0;
				size_t q = add_var(s, &phase, (int)g, &bp, "%s.%s_phase_rad", who, stem);
				st->info[m].phase = (int)q;
				st->info[q].phase_of = (int)m;
			}
		}
	} else if (t->per_start) {
		int n = t->shared ? 1 : s->design.starts;
		for (int k = 0; k < n; k++) {
			b.roller = t->shared ? -1 : k; /* for starts: which start, -1 all */
			b.offset = pi->offset + (t->shared ? 0 : (size_t)k * sizeof(double));
			if (t->shared)
				add_var(s, &t->dist, (int)g, &b, "%s[*]", t->parameter);
			else
				add_var(s, &t->dist, (int)g, &b, "%s[%d]", t->parameter, k);
		}
	} else {
		b.roller = 0;
		size_t m = add_var(s, &t->dist, (int)g, &b, "%s", t->parameter);
		if (pi->radial) {
			prsm_mc_binding bp = b;
			bp.offset = pi->phase_offset;
			bp.scale = 1.0;
			char part[16];
			snprintf(part, sizeof part, "%.*s", (int)(dot - t->parameter), t->parameter);
			size_t q = add_var(s, &phase, (int)g, &bp, "%s.%s_phase_rad", part, stem);
			st->info[m].phase = (int)q;
			st->info[q].phase_of = (int)m;
		}
	}
	gr->n_vars = st->d - gr->first_var;
}

static int output_index(const prsm_io_study *s, const char *name)
{
	for (size_t o = 0; o < s->study.m; o++)
		if (strcmp(s->study.outputs[o].name, name) == 0)
			return (int)o;
	return -1;
}

/* What the outputs at the nominal operating point need from the nut unit's performance
 * (prsm_performance, docs/model/kinematics-efficiency-stiffness-life.md), computed once: for nut_unit_stiffness_N_per_um the
 * compliance beyond the contacts, 1/k_unit - 1/k_contacts of the nominal design (mm/N, k_unit the
 * load distribution's stiffness, k_contacts the assembly's with nominal gaps); for
 * efficiency_with_losses the distribution's normal loads of one roller's contacts. Returns 0, or
 * 1 with a problem at the first output that needed them. */
static int nominal_unit_terms(prsm_io_study *s, prsm_problems *pr)
{
	int first = -1, unit = 0, losses = 0;
	for (size_t o = 0; o < s->study.m; o++) {
		int u = s->prsm.outputs[o] == PRSM_OUT_UNIT_STIFFNESS, l = s->prsm.outputs[o] == PRSM_OUT_EFFICIENCY_LOSSES;
		if ((u || l) && first < 0)
			first = (int)o;
		unit |= u;
		losses |= l;
	}
	if (first < 0)
		return 0;
	char ip[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append_index(ip, sizeof ip, "/outputs", first);
	prsm_performance perf;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_performance_compute(&perf, &s->design, &s->analysis, &err)) {
		prsm_problems_add(pr, ip, "computation", "the nominal nut unit at the operating load: %s", err.message);
		return 1;
	}
	int bad = 0;
	if (unit) {
		double k_unit = perf.stiffness_N_per_um * 1e3;            /* N/mm */
		double k_contacts = s->assembly.nominal_stiffness_N_per_mm; /* N/mm */
		if (!(k_unit > 0.0) || !(k_contacts > 0.0)) {
			prsm_problems_add(pr, ip, "computation", "the nominal nut unit has no stiffness at the operating load");
			bad = 1;
		}
		/* the thread, core and body springs only add compliance; a contact model stiffer in
		 * the assembly than in the load distribution would make this negative: contacts only */
		s->prsm.unit_rest_compliance_mm_per_N = fmax(0.0, 1.0 / k_unit - 1.0 / k_contacts);
	}
	if (losses && !bad) {
		int nt = perf.threads;
		if (nt < 1 || nt > PRSM_IO_STUDY_MAX_LOSS_THREADS) {
			prsm_problems_add(pr, ip, "computation", "the nominal load distribution has no contact loads");
			bad = 1;
		} else {
			s->loss_threads = nt;
			memcpy(s->loss_loads_N[0], perf.thread_normal_screw_N, (size_t)nt * sizeof(double));
			memcpy(s->loss_loads_N[1], perf.thread_normal_nut_N, (size_t)nt * sizeof(double));
			s->prsm.loss_screw_loads_N = s->loss_loads_N[0];
			s->prsm.loss_nut_loads_N = s->loss_loads_N[1];
		}
	}
	prsm_performance_free(&perf);
	return bad;
}

/* design_ok: the design loaded, so its operating load is known. */
static void read_outputs(prsm_io_study *s, const cJSON *doc, int design_ok, prsm_problems *pr)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(doc, "outputs");
	int n = cJSON_GetArraySize(arr);
	if (!arr) {
		/* default: the benchmark's y, or backlash and load sharing */
		if (s->is_benchmark) {
			snprintf(s->study.outputs[0].name, sizeof s->study.outputs[0].name, "y");
			s->study.m = 1;
		} else {
			snprintf(s->study.outputs[0].name, sizeof s->study.outputs[0].name, "backlash_um");
			s->prsm.outputs[0] = PRSM_OUT_BACKLASH;
			s->study.m = 1;
			if (s->design.axial_load_N > 0.0) {
				snprintf(s->study.outputs[1].name, sizeof s->study.outputs[1].name, "load_sharing_factor");
				s->prsm.outputs[1] = PRSM_OUT_SHARING;
				s->study.m = 2;
			}
		}
		return;
	}
	if (!cJSON_IsArray(arr) || n < 1 || n > PRSM_MC_MAX_OUTPUTS) {
		prsm_problems_add(pr, "/outputs", "bad_array", "outputs: an array of 1 to %d output names",
		                  PRSM_MC_MAX_OUTPUTS);
		return;
	}
	int i = 0;
	for (const cJSON *it = arr->child; it; it = it->next, i++) {
		char ip[PRSM_JSON_POINTER_MAX];
		const char *name = NULL;
		prsm_json_pointer_append_index(ip, sizeof ip, "/outputs", i);
		if (prsm_json_string_value(&name, it, ip, 47, pr))
			continue;
		prsm_output_kind k;
		if (s->is_benchmark ? strcmp(name, "y") != 0 : prsm_output_parse(name, &k) != 0) {
			if (s->is_benchmark)
				prsm_problems_add(pr, ip, "unknown_output", "a benchmark has one output, y");
			else
				prsm_problems_add(pr, ip, "unknown_output",
				                  "unknown output '%s': " PRSM_OUTPUT_NAMES_TEXT, name);
			continue;
		}
		if (output_index(s, name) >= 0) {
			prsm_problems_add(pr, ip, "duplicate", "output '%s' is listed twice", name);
			continue;
		}
		if (!s->is_benchmark && design_ok && !(s->design.axial_load_N > 0.0) &&
		    (k == PRSM_OUT_SHARING || k == PRSM_OUT_STIFFNESS || k == PRSM_OUT_STIFFNESS_RATIO ||
		     k == PRSM_OUT_UNIT_STIFFNESS || k == PRSM_OUT_EFFICIENCY_LOSSES)) {
			prsm_problems_add(pr, ip, "no_load", "%s needs an operating axial load "
			                  "(/design/operating_point/axial_load_N > 0)", name);
			continue;
		}
		snprintf(s->study.outputs[s->study.m].name, sizeof s->study.outputs[0].name, "%s", name);
		if (!s->is_benchmark)
			s->prsm.outputs[s->study.m] = k;
		s->study.m++;
	}
}

static void read_specs(prsm_io_study *s, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *specs = NULL;
	if (prsm_json_get_object(&specs, doc, "", "specs", PRSM_JSON_OPTIONAL, pr) != PRSM_JSON_PRESENT)
		return;
	prsm_json_check_duplicates(specs, "/specs", pr);
	for (const cJSON *it = specs->child; it; it = it->next) {
		char sp[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(sp, sizeof sp, "/specs", it->string);
		int o = output_index(s, it->string);
		if (o < 0) {
			prsm_problems_add(pr, sp, "unknown_output", "'%s' is not one of the study's outputs", it->string);
			continue;
		}
		if (prsm_json_object_value(it, sp, pr))
			continue;
		prsm_json_check_keys(it, sp, spec_keys, pr);
		prsm_spec *spec = &s->study.outputs[o].spec;
		int lo = prsm_json_get_number(&spec->lower, it, sp, "lower", PRSM_JSON_OPTIONAL, ANY, pr);
		int hi = prsm_json_get_number(&spec->upper, it, sp, "upper", PRSM_JSON_OPTIONAL, ANY, pr);
		spec->has_lower = lo == PRSM_JSON_PRESENT;
		spec->has_upper = hi == PRSM_JSON_PRESENT;
		if (lo == PRSM_JSON_ABSENT && hi == PRSM_JSON_ABSENT)
			prsm_problems_add(pr, sp, "required", "a spec needs lower, upper or both");
		if (spec->has_lower && spec->has_upper && !(spec->lower < spec->upper)) {
			char up[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(up, sizeof up, sp, "upper");
			prsm_problems_add(pr, up, "range", "upper must be greater than lower");
		}
		s->study.outputs[o].has_spec = spec->has_lower || spec->has_upper;
		int ym = PRSM_STUDY_YIELD_MC;
		prsm_json_get_enum(&ym, it, sp, "yield_method", PRSM_JSON_OPTIONAL, yield_method_names, pr);
		s->study.outputs[o].yield_method = ym;
	}
}

/* rare_events (issue 21): the settings of the rare-event estimates */
static void read_rare_events(prsm_io_study *s, const cJSON *doc, prsm_problems *pr)
{
	prsm_study_rare_options *ro = &s->study.rare;
	prsm_study_rare_options_default(ro);
	const cJSON *re = NULL;
	char rp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&re, rp, sizeof rp, doc, "", "rare_events", PRSM_JSON_OPTIONAL, rare_keys, pr) !=
	    PRSM_JSON_PRESENT)
		return;
	int n = 0;
	if (prsm_json_get_int(&n, re, rp, "max_evaluations", PRSM_JSON_OPTIONAL, 100, 10000000, pr) == PRSM_JSON_PRESENT)
		ro->max_evaluations = (size_t)n;
	prsm_json_range cov = {0.0, 0.5, 1, 0};
	prsm_json_get_number(&ro->target_cov, re, rp, "target_cov", PRSM_JSON_OPTIONAL, cov, pr);
	if (prsm_json_get_int(&n, re, rp, "subset_samples", PRSM_JSON_OPTIONAL, 100, 1000000, pr) == PRSM_JSON_PRESENT)
		ro->subset_samples = (size_t)n;
}


static void read_correlations_list(prsm_io_study *s, const cJSON *doc, prsm_problems *pr);

static void read_correlations(prsm_io_study *s, const cJSON *doc, prsm_problems *pr)
{
	int before = prsm_problems_total(pr);
	read_correlations_list(s, doc, pr);
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_problems_total(pr) == before && s->study.n_corr &&
	    prsm_mc_correlation_check(s->study.corr, s->study.n_corr, s->study.d, &err))
		prsm_problems_add(pr, "/correlations", "not_positive_definite", "%s", err.message);
}

static void read_correlations_list(prsm_io_study *s, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(doc, "correlations");
	if (!arr)
		return;
	if (!cJSON_IsArray(arr)) {
		prsm_problems_add(pr, "/correlations", "type", "correlations: an array of {between: [a, b], rho}");
		return;
	}
	prsm_study *st = &s->study;
	int i = 0;
	for (const cJSON *it = arr->child; it; it = it->next, i++) {
		char cp[PRSM_JSON_POINTER_MAX], bp[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(cp, sizeof cp, "/correlations", i);
		prsm_json_pointer_append(bp, sizeof bp, cp, "between");
		if (prsm_json_object_value(it, cp, pr))
			continue;
		prsm_json_check_keys(it, cp, corr_keys, pr);
		double rho = NAN;
		prsm_json_get_number(&rho, it, cp, "rho", PRSM_JSON_REQUIRED,
		                     (prsm_json_range){-1.0, 1.0, 1, 1}, pr);
		const cJSON *between = cJSON_GetObjectItemCaseSensitive(it, "between");
		if (!cJSON_IsArray(between) || cJSON_GetArraySize(between) != 2 ||
		    !cJSON_IsString(between->child) || !cJSON_IsString(between->child->next)) {
			prsm_problems_add(pr, bp, "bad_array", "between: the parameters of two tolerances");
			continue;
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
		if (g[0] < 0 || g[1] < 0 || !isfinite(rho) || st->d == 0)
			continue;
		if (g[0] == g[1]) {
			prsm_problems_add(pr, bp, "same", "a tolerance cannot be correlated with itself");
			continue;
		}
		const prsm_study_group *ga = &st->groups[g[0]], *gb = &st->groups[g[1]];
		size_t step_a = s->tolerances[g[0]].radial ? 2 : 1, step_b = s->tolerances[g[1]].radial ? 2 : 1;
		size_t na = ga->n_vars / step_a, nb = gb->n_vars / step_b;
		if (na != nb && na != 1 && nb != 1) {
			prsm_problems_add(pr, bp, "shape", "these tolerances have %zu and %zu variables: correlate per-roller "
			                  "with per-roller, or with a single tolerance", na, nb);
			continue;
		}
		if (na != nb) {
			prsm_problems_add(pr, bp, "shape", "a single tolerance cannot be correlated with each of %zu "
			                  "independent ones: make the per-roller one shared, or correlate like with like",
			                  na > nb ? na : nb);
			continue;
		}
		for (size_t k = 0; k < na; k++) {
			if (st->n_corr >= PRSM_MC_MAX_CORRELATIONS) {
				prsm_problems_add(pr, cp, "too_many", "at most %d correlated variable pairs", PRSM_MC_MAX_CORRELATIONS);
				break;
			}
			prsm_mc_correlation *c = &st->corr[st->n_corr++];
			c->a = ga->first_var + k * step_a;
			c->b = gb->first_var + k * step_b;
			c->rho = rho;
		}
	}
}

int prsm_legacy_study_load(prsm_io_study *out, const cJSON *doc, prsm_problems *warnings, prsm_problems *pr)
{
	memset(out, 0, sizeof *out);
	int start = prsm_problems_total(pr);
	if (prsm_json_object_value(doc, "", pr))
		return PRSM_EINVAL;
	prsm_json_check_keys(doc, "", study_keys, pr);
	const char *name = NULL;
	if (prsm_json_get_string(&name, doc, "", "name", PRSM_JSON_OPTIONAL, 100, pr) == PRSM_JSON_PRESENT)
		prsm_utf8_copy(out->name, sizeof out->name, name);

	const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
	const cJSON *model = cJSON_GetObjectItemCaseSensitive(doc, "model");
	int design_rc = PRSM_EINVAL;
	if (design && model) {
		prsm_problems_add(pr, "/model", "conflict", "a study has a design or a benchmark model, not both");
	} else if (model) {
		out->is_benchmark = 1;
		if (prsm_json_object_value(model, "/model", pr) == 0)
			read_benchmark(out, model, "/model", pr);
		static const char *const design_only[] = {"errors", "assembly", NULL};
		for (int k = 0; design_only[k]; k++)
			if (cJSON_GetObjectItemCaseSensitive(doc, design_only[k])) {
				char kp[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append(kp, sizeof kp, "", design_only[k]);
				prsm_problems_add(pr, kp, "not_allowed", "%s belongs to a design study, not a benchmark",
				                  design_only[k]);
			}
		design_rc = prsm_problems_total(pr) == start ? 0 : PRSM_EINVAL;
	} else if (design) {
		design_rc = read_design(out, doc, warnings, pr);
	} else {
		prsm_problems_add(pr, "/design", "required", "a study needs a design (or a benchmark model)");
	}
	int params_known = design_rc == 0;

	/* tolerances */
	const cJSON *tols = cJSON_GetObjectItemCaseSensitive(doc, "tolerances");
	int nt = cJSON_GetArraySize(tols);
	param_info pis[PRSM_IO_STUDY_MAX_TOLERANCES];
	if (!cJSON_IsArray(tols) || nt < 1 || nt > PRSM_IO_STUDY_MAX_TOLERANCES) {
		prsm_problems_add(pr, "/tolerances", tols ? "bad_array" : "required",
		                  "tolerances: an array of 1 to %d tolerances", PRSM_IO_STUDY_MAX_TOLERANCES);
		nt = 0;
	} else {
		int i = 0;
		for (const cJSON *it = tols->child; it; it = it->next, i++) {
			char tp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(tp, sizeof tp, "/tolerances", i);
			read_tolerance(&out->tolerances[i], &pis[i], out, it, tp, params_known, pr);
			for (int k = 0; k < i; k++)
				if (out->tolerances[i].parameter[0] &&
				    strcmp(out->tolerances[k].parameter, out->tolerances[i].parameter) == 0) {
					char pp[PRSM_JSON_POINTER_MAX];
					prsm_json_pointer_append(pp, sizeof pp, tp, "parameter");
					prsm_problems_add(pr, pp, "duplicate", "%s has a tolerance already (at /tolerances/%d)",
					                  out->tolerances[i].parameter, k);
				}
		}
	}
	out->n_tolerances = (size_t)nt;
	read_outputs(out, doc, design_rc == 0, pr);
	read_specs(out, doc, pr);
	prsm_legacy_study_mc_from_json(out, doc, pr);
	prsm_legacy_study_sensitivity_from_json(out, doc, pr);
	read_rare_events(out, doc, pr);

	/* variables, once everything they depend on is valid */
	prsm_study *st = &out->study;
	if (prsm_problems_total(pr) == start && nt > 0) {
		size_t d = 0;
		for (size_t g = 0; g < (size_t)nt; g++)
			d += count_vars(&out->tolerances[g], out);
		if (d > PRSM_MC_MAX_VARIABLES) {
			prsm_problems_add(pr, "/tolerances", "too_many", "the tolerances make %zu variables (per roller, "
			                  "per start, with phases): at most %d", d, PRSM_MC_MAX_VARIABLES);
		} else {
			if (out->is_benchmark && d != out->bench.inputs)
				prsm_problems_add(pr, "/tolerances", "incomplete", "the %s benchmark has %zu inputs: give "
				                  "each of x1 .. x%zu one tolerance", prsm_bench_name(out->bench.kind),
				                  out->bench.inputs, out->bench.inputs);
			for (size_t g = 0; g < (size_t)nt; g++)
				build_vars(out, g, &pis[g]);
			if (out->is_benchmark)
				st->d = out->bench.inputs;
			st->n_groups = (size_t)nt;
		}
	}
	read_correlations(out, doc, pr);
	if (prsm_problems_total(pr) != start)
		return design_rc && design_rc != PRSM_EINVAL ? design_rc : PRSM_EINVAL;

	/* storage */
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
	if (prsm_problems_total(pr) != start)
		return PRSM_EINVAL;

	/* the model */
	if (out->is_benchmark) {
		prsm_bench_mc_model(&st->model, &out->bench);
		/* benchmark variables are the inputs in order: bind by reordering through the binding */
	} else {
		prsm_mc_prsm *p = &out->prsm;
		p->as = &out->assembly;
		p->an = &out->analysis;
		p->mode = out->assembly_options.mode;
		p->angles_per_revolution = out->assembly_options.angles_per_revolution;
		p->measuring_load_N = out->assembly_options.measuring_load_N;
		p->n_bindings = st->d;
		p->bindings = out->bindings;
		p->n_outputs = st->m;
		if (nominal_unit_terms(out, pr))
			return PRSM_EINVAL;
		prsm_prsm_mc_model(&st->model, p);
	}
	return 0;
}

