/*
 * optimization_reader_legacy.c: the hand-written optimisation reader before issue 24's port
 * (src/io/optimization_json.c as it was), for the side-by-side proof in tests/test_io_doc.c.
 * Delete it with that test once every document is ported. Only the entry point is renamed:
 * prsm_legacy_optimization_read; the method names and prsm_io_optimization_release are today's.
 * One fix, made in both readers: a set's value that is not a valid integer was stored from an
 * uninitialised variable (and the next value's order checked against it: undefined behaviour,
 * seen to report a spurious "order" problem); it is now the last good value (lo - 1 before the
 * first), so the next value is checked against the last good one.
 */
#include "legacy/opt_alloc_reader_legacy.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/design_json.h"
#include "io/json_util.h"
#include "app/study.h"
#include "io/study_json.h"
#include "opt/design_problem.h"
#include "util/utf8.h"


static const char *const doc_keys[] = {"name", "description", "design", "variables", "objectives",
                                       "multi_objective", "constraints", "robust", "solver", NULL};
static const char *const robust_keys[] = {"tolerances", "correlations", "assembly", "monte_carlo",
                                          "constraints", "surrogate", NULL};
static const char *const robust_mc_keys[] = {"samples", "seed", "sampler", "block_size", "threads",
                                             "failure", "edge_contact", NULL};
static const char *const robust_constraint_keys[] = {"output", "spec", "yield_min_percent", NULL};
static const char *const spec_keys[] = {"lower", "upper", NULL};
/* Robust studies: default samples per candidate and the document's cap. */
#define ROBUST_DEFAULT_SAMPLES 256
#define ROBUST_MAX_SAMPLES 65536
static const char *const variable_keys[] = {"starts", "pitch_mm", "lead_mm", "roller_radius_mm",
                                            "screw_radius_mm", "rollers", "engaged_threads",
                                            "flank_angle_deg", NULL};
static const char *const range_keys[] = {"min", "max", NULL};
static const char *const set_keys[] = {"values", "min", "max", NULL};
static const char *const objective_keys[] = {"name", "weight", NULL};
static const char *const multi_keys[] = {"method", "points", NULL};
static const char *const constraint_keys[] = {
	"nut_outer_diameter_max_mm", "screw_diameter_min_mm", "screw_diameter_max_mm",
	"static_safety_min", "life_min_h", "life_min_revolutions", "p_max_max_MPa",
	"critical_speed_factor_min", "standard_rules", NULL};
static const char *const solver_keys[] = {"algorithm", "max_evaluations", "max_time_s", "multistart",
                                          "seed", "xtol_rel", "ftol_rel", "constraint_tolerance",
                                          NULL};


/* A continuous range {min, max} at obj[key]. */
static void read_range(prsm_dp_range *r, const cJSON *obj, const char *base, const char *key,
                       double lo, double hi, prsm_problems *pr)
{
	const cJSON *o = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&o, ptr, sizeof ptr, obj, base, key, PRSM_JSON_OPTIONAL, range_keys,
	                          pr) != PRSM_JSON_PRESENT)
		return;
	prsm_json_range rg = {lo, hi, 1, 0};
	int a = prsm_json_get_number(&r->min, o, ptr, "min", PRSM_JSON_REQUIRED, rg, pr);
	int b = prsm_json_get_number(&r->max, o, ptr, "max", PRSM_JSON_REQUIRED, rg, pr);
	if (a == PRSM_JSON_PRESENT && b == PRSM_JSON_PRESENT) {
		if (!(r->min < r->max)) {
			char mp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(mp, sizeof mp, ptr, "max");
			prsm_problems_add(pr, mp, "empty_range", "max (%g) must exceed min (%g)", r->max, r->min);
		}
		r->vary = 1;
	}
}

/* A discrete set {values} or {min, max} at obj[key] (integers in [lo, hi]). max may be left
 * out when allow_auto: *auto_max is then set and the caller fills the set. */
static void read_set(prsm_dp_set *s, const cJSON *obj, const char *base, const char *key, int lo,
                     int hi, int allow_auto, int *auto_min, prsm_problems *pr)
{
	const cJSON *o = NULL;
	char ptr[PRSM_JSON_POINTER_MAX], vp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&o, ptr, sizeof ptr, obj, base, key, PRSM_JSON_OPTIONAL, set_keys,
	                          pr) != PRSM_JSON_PRESENT)
		return;
	const cJSON *values = cJSON_GetObjectItemCaseSensitive(o, "values");
	prsm_json_pointer_append(vp, sizeof vp, ptr, "values");
	if (values) {
		if (cJSON_GetObjectItemCaseSensitive(o, "min") || cJSON_GetObjectItemCaseSensitive(o, "max"))
			prsm_problems_add(pr, vp, "conflict", "give values or min/max, not both");
		if (!cJSON_IsArray(values)) {
			prsm_problems_add(pr, vp, "type", "must be an array, got %s", prsm_json_type_name(values));
			return;
		}
		int n = cJSON_GetArraySize(values);
		if (n < 1 || n > PRSM_OPT_MAX_LEVELS) {
			prsm_problems_add(pr, vp, "count", "1..%d values (got %d)", PRSM_OPT_MAX_LEVELS, n);
			return;
		}
		int i = 0, bad = 0;
		const cJSON *v;
		cJSON_ArrayForEach(v, values) {
			char ip[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(ip, sizeof ip, vp, i);
			int x = i > 0 ? s->values[i - 1] : lo - 1; /* was uninitialised: see the top */
			if (prsm_json_int_value(&x, v, ip, lo, hi, pr)) {
				bad = 1;
			} else if (i > 0 && x <= s->values[i - 1]) {
				prsm_problems_add(pr, ip, "order", "values must be distinct and ascending");
				bad = 1;
			}
			s->values[i++] = x;
		}
		if (!bad)
			s->count = n;
		return;
	}
	int mn = lo, mx = hi;
	int a = prsm_json_get_int(&mn, o, ptr, "min", PRSM_JSON_REQUIRED, lo, hi, pr);
	int b = prsm_json_get_int(&mx, o, ptr, "max", allow_auto ? PRSM_JSON_OPTIONAL : PRSM_JSON_REQUIRED,
	                          lo, hi, pr);
	if (a != PRSM_JSON_PRESENT || b < 0)
		return;
	if (b == PRSM_JSON_ABSENT) {
		*auto_min = mn; /* rollers up to Z_max: filled once the geometry is known */
		return;
	}
	if (mx < mn || mx - mn + 1 > PRSM_OPT_MAX_LEVELS) {
		char mp[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(mp, sizeof mp, ptr, "max");
		prsm_problems_add(pr, mp, "range", "max (%d) must be at least min (%d) and span at most %d "
		                  "values", mx, mn, PRSM_OPT_MAX_LEVELS);
		return;
	}
	for (int v = mn; v <= mx; v++)
		s->values[s->count++] = v;
}

static void read_variables(prsm_io_optimization *od, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *v = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&v, ptr, sizeof ptr, doc, "", "variables", PRSM_JSON_REQUIRED,
	                          variable_keys, pr) != PRSM_JSON_PRESENT)
		return;
	prsm_dp_spec *s = &od->spec;
	int unused = -1, rollers_min = -1;
	read_set(&s->starts, v, ptr, "starts", 3, PRSM_DESIGN_STARTS_MAX, 0, &unused, pr);
	static const char *const pairs[][2] = {{"pitch_mm", "lead_mm"}, {"roller_radius_mm", "screw_radius_mm"}};
	for (int k = 0; k < 2; k++)
		if (cJSON_GetObjectItemCaseSensitive(v, pairs[k][0]) &&
		    cJSON_GetObjectItemCaseSensitive(v, pairs[k][1])) {
			char p2[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(p2, sizeof p2, ptr, pairs[k][1]);
			prsm_problems_add(pr, p2, "conflict", "give %s or %s, not both", pairs[k][0], pairs[k][1]);
		}
	s->pitch_is_lead = cJSON_GetObjectItemCaseSensitive(v, "lead_mm") != NULL &&
	                   !cJSON_GetObjectItemCaseSensitive(v, "pitch_mm");
	read_range(&s->pitch, v, ptr, s->pitch_is_lead ? "lead_mm" : "pitch_mm", 0.0,
	           s->pitch_is_lead ? PRSM_DESIGN_PITCH_MAX_MM * PRSM_DESIGN_STARTS_MAX
	                            : PRSM_DESIGN_PITCH_MAX_MM, pr);
	s->radius_is_screw = cJSON_GetObjectItemCaseSensitive(v, "screw_radius_mm") != NULL &&
	                     !cJSON_GetObjectItemCaseSensitive(v, "roller_radius_mm");
	read_range(&s->radius, v, ptr, s->radius_is_screw ? "screw_radius_mm" : "roller_radius_mm", 0.0,
	           1000.0, pr);
	read_range(&s->flank_deg, v, ptr, "flank_angle_deg", 0.0, 90.0, pr);
	if (s->flank_deg.vary && s->flank_deg.max >= 90.0) {
		char p2[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(p2, sizeof p2, ptr, "flank_angle_deg");
		prsm_problems_add(pr, p2, "range", "flank angle must stay below 90 deg");
	}
	read_set(&s->rollers, v, ptr, "rollers", 1, PRSM_DESIGN_ROLLERS_MAX, 1, &rollers_min, pr);
	read_set(&s->threads, v, ptr, "engaged_threads", 1, PRSM_DESIGN_ENGAGED_THREADS_MAX, 0, &unused, pr);
	od->rollers_auto_max = rollers_min;
	if (!s->pitch.vary && !s->radius.vary && !s->flank_deg.vary && !s->starts.count &&
	    !s->rollers.count && rollers_min < 0 && !s->threads.count)
		prsm_problems_add(pr, ptr, "nothing_varies", "give at least one variable a range or values");
}

static void read_objectives(prsm_io_optimization *od, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(doc, "objectives");
	if (!arr) {
		prsm_problems_add(pr, "/objectives", "required", "is required (1..%d objectives)",
		                  PRSM_OPT_MAX_OBJECTIVES);
		return;
	}
	if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) < 1 ||
	    cJSON_GetArraySize(arr) > PRSM_OPT_MAX_OBJECTIVES) {
		prsm_problems_add(pr, "/objectives", "count", "must be an array of 1..%d objectives",
		                  PRSM_OPT_MAX_OBJECTIVES);
		return;
	}
	int i = 0, seen[PRSM_DP_OBJECTIVE_KINDS] = {0};
	const cJSON *o;
	cJSON_ArrayForEach(o, arr) {
		char ip[PRSM_JSON_POINTER_MAX], np[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(ip, sizeof ip, "/objectives", i);
		if (prsm_json_object_value(o, ip, pr)) {
			i++;
			continue;
		}
		prsm_json_check_keys(o, ip, objective_keys, pr);
		int kind = 0;
		double w = 1.0;
		prsm_json_get_number(&w, o, ip, "weight", PRSM_JSON_OPTIONAL,
		                     (prsm_json_range){0.0, 1e6, 0, 0}, pr);
		if (prsm_json_get_enum(&kind, o, ip, "name", PRSM_JSON_REQUIRED, prsm_dp_objective_names,
		                       pr) == PRSM_JSON_PRESENT) {
			prsm_json_pointer_append(np, sizeof np, ip, "name");
			if (seen[kind]++)
				prsm_problems_add(pr, np, "duplicate", "objective %s given twice",
				                  prsm_dp_objective_names[kind]);
			od->spec.objective[od->spec.n_objectives] = kind;
			od->weight[od->spec.n_objectives] = w;
			od->spec.n_objectives++;
		}
		i++;
	}
}

static void read_multi(prsm_io_optimization *od, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *m = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	od->method = PRSM_IO_OPT_SINGLE;
	od->points = 7;
	int n = od->spec.n_objectives;
	int present = prsm_json_get_section(&m, ptr, sizeof ptr, doc, "", "multi_objective",
	                                    PRSM_JSON_OPTIONAL, multi_keys, pr);
	if (present != PRSM_JSON_PRESENT) {
		if (n > 1)
			prsm_problems_add(pr, "/multi_objective", "required",
			                  "%d objectives need a multi_objective method (weighted_sum or pareto)", n);
		return;
	}
	int method = PRSM_IO_OPT_WEIGHTED;
	prsm_json_get_enum(&method, m, ptr, "method", PRSM_JSON_REQUIRED, prsm_io_opt_method_names, pr);
	prsm_json_get_int(&od->points, m, ptr, "points", PRSM_JSON_OPTIONAL, 2,
	                  PRSM_IO_OPT_MAX_PARETO_POINTS, pr);
	od->method = method;
	char mp[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(mp, sizeof mp, ptr, "method");
	if (method == PRSM_IO_OPT_PARETO && n != 2)
		prsm_problems_add(pr, mp, "objectives", "a Pareto sweep needs exactly 2 objectives (got %d)", n);
	if (method == PRSM_IO_OPT_WEIGHTED) {
		double sum = 0.0;
		for (int k = 0; k < n; k++)
			sum += od->weight[k];
		if (!(sum > 0.0))
			prsm_problems_add(pr, "/objectives", "weights", "at least one weight must be positive");
	}
	if (method == PRSM_IO_OPT_SINGLE && n > 1)
		prsm_problems_add(pr, mp, "objectives", "single needs exactly one objective (got %d)", n);
}

static void read_constraints(prsm_io_optimization *od, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *c = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&c, ptr, sizeof ptr, doc, "", "constraints", PRSM_JSON_OPTIONAL,
	                          constraint_keys, pr) != PRSM_JSON_PRESENT)
		return;
	prsm_dp_spec *s = &od->spec;
	double *field[] = {&s->nut_outer_diameter_max_mm, &s->screw_diameter_min_mm,
	                   &s->screw_diameter_max_mm, &s->static_safety_min, &s->life_min_h,
	                   &s->life_min_revolutions, &s->p_max_max_MPa, &s->critical_speed_factor_min};
	const prsm_json_range big = {0.0, 1e15, 1, 0};
	for (int k = 0; k < 8; k++)
		prsm_json_get_number(field[k], c, ptr, constraint_keys[k], PRSM_JSON_OPTIONAL, big, pr);
	prsm_json_get_bool(&s->standard_rules, c, ptr, "standard_rules", PRSM_JSON_OPTIONAL, pr);
	if (!isnan(s->screw_diameter_min_mm) && !isnan(s->screw_diameter_max_mm) &&
	    !(s->screw_diameter_min_mm < s->screw_diameter_max_mm))
		prsm_problems_add(pr, "/constraints/screw_diameter_max_mm", "empty_range",
		                  "screw_diameter_max_mm (%g) must exceed screw_diameter_min_mm (%g)",
		                  s->screw_diameter_max_mm, s->screw_diameter_min_mm);
	if (!isnan(s->critical_speed_factor_min) && !s->base.life.column)
		prsm_problems_add(pr, "/constraints/critical_speed_factor_min", "needs_column",
		                  "a critical-speed constraint needs the design's column "
		                  "(free_length_mm and fixity)");
}

static void read_solver(prsm_io_optimization *od, const cJSON *doc, size_t max_evaluations, prsm_problems *pr)
{
	prsm_opt_options *o = &od->options;
	prsm_opt_options_init(o);
	o->xtol_rel = 1e-4;
	o->ftol_rel = 1e-6;
	const cJSON *s = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&s, ptr, sizeof ptr, doc, "", "solver", PRSM_JSON_OPTIONAL,
	                          solver_keys, pr) != PRSM_JSON_PRESENT)
		return;
	size_t cap = max_evaluations ? max_evaluations : PRSM_IO_OPT_MAX_EVALUATIONS;
	if (cap > PRSM_IO_OPT_MAX_EVALUATIONS)
		cap = PRSM_IO_OPT_MAX_EVALUATIONS;
	prsm_json_get_enum(&o->algorithm, s, ptr, "algorithm", PRSM_JSON_OPTIONAL,
	                   prsm_opt_algorithm_names, pr);
	int me = (int)o->max_evaluations;
	if (prsm_json_get_int(&me, s, ptr, "max_evaluations", PRSM_JSON_OPTIONAL, 1, (int)cap, pr) ==
	    PRSM_JSON_PRESENT)
		o->max_evaluations = (size_t)me;
	prsm_json_get_number(&o->max_time_s, s, ptr, "max_time_s", PRSM_JSON_OPTIONAL,
	                     (prsm_json_range){0.0, PRSM_IO_OPT_MAX_TIME_S, 1, 0}, pr);
	prsm_json_get_int(&o->multistart, s, ptr, "multistart", PRSM_JSON_OPTIONAL, 1,
	                  PRSM_IO_OPT_MAX_MULTISTART, pr);
	double seed = 1.0;
	if (prsm_json_get_number(&seed, s, ptr, "seed", PRSM_JSON_OPTIONAL,
	                         (prsm_json_range){0.0, 9007199254740991.0, 0, 0}, pr) == PRSM_JSON_PRESENT) {
		if (seed != floor(seed))
			prsm_problems_add(pr, "/solver/seed", "integer", "must be an integer (got %g)", seed);
		o->seed = (unsigned long)seed;
	}
	const prsm_json_range tol = {0.0, 0.1, 0, 0};
	prsm_json_get_number(&o->xtol_rel, s, ptr, "xtol_rel", PRSM_JSON_OPTIONAL, tol, pr);
	prsm_json_get_number(&o->ftol_rel, s, ptr, "ftol_rel", PRSM_JSON_OPTIONAL, tol, pr);
	prsm_json_get_number(&o->constraint_tol, s, ptr, "constraint_tolerance", PRSM_JSON_OPTIONAL,
	                     tol, pr);
}

/* ---- robust constraints ---- */


/* Re-point a problem of the candidate study document into the optimisation document. */
static void add_study_problem(prsm_problems *pr, const prsm_io_optimization *od, const prsm_problem *p)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	const char *q = p->pointer;
	if (strncmp(q, "/design", 7) == 0 && (q[7] == '\0' || q[7] == '/')) {
		prsm_problems_add(pr, "/robust", "base_design", "the tolerance set is checked on the base "
		                  "design, which its study refuses at %.80s: %.120s", q, p->message);
		return;
	}
	if (strncmp(q, "/outputs/", 9) == 0 || strncmp(q, "/specs/", 7) == 0) {
		int o = -1;
		if (q[1] == 'o') {
			o = (int)strtol(q + 9, NULL, 10);
		} else {
			const cJSON *outs = cJSON_GetObjectItemCaseSensitive(od->study, "outputs");
			int i = 0;
			const cJSON *it;
			cJSON_ArrayForEach(it, outs) {
				if (cJSON_IsString(it) && strncmp(q + 7, it->valuestring, strlen(it->valuestring)) == 0)
					o = i;
				i++;
			}
		}
		int k = o >= 0 && o < PRSM_MC_MAX_OUTPUTS ? od->robust_output_of[o] : 0;
		char base[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(base, sizeof base, "/robust/constraints", k);
		prsm_json_pointer_append(ptr, sizeof ptr, base, q[1] == 'o' ? "output" : "spec");
		prsm_problems_add(pr, ptr, p->code, "%s", p->message);
		return;
	}
	snprintf(ptr, sizeof ptr, "/robust%.*s", (int)(sizeof ptr - 8), q);
	prsm_problems_add(pr, ptr, p->code, "%s", p->message);
}

/* One robust constraint at /robust/constraints/i into od->robust.c[k]; 0 when valid. */
static int read_robust_constraint(prsm_io_optimization *od, const cJSON *it, const char *ip, prsm_problems *pr)
{
	const int before = prsm_problems_total(pr);
	if (prsm_json_object_value(it, ip, pr))
		return PRSM_EINVAL;
	prsm_json_check_keys(it, ip, robust_constraint_keys, pr);
	prsm_robust_constraint *c = &od->robust.c[od->robust.n];
	memset(c, 0, sizeof *c);
	const char *name = NULL;
	char op[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(op, sizeof op, ip, "output");
	if (prsm_json_get_string(&name, it, ip, "output", PRSM_JSON_REQUIRED, PRSM_ROBUST_NAME_MAX - 1,
	                         pr) == PRSM_JSON_PRESENT) {
		prsm_output_kind kind;
		if (prsm_output_parse(name, &kind))
			prsm_problems_add(pr, op, "unknown_output",
			                  "unknown output '%s': " PRSM_OUTPUT_NAMES_TEXT, name);
		else
			for (int k = 0; k < od->robust.n; k++)
				if (strcmp(od->robust.c[k].output, name) == 0)
					prsm_problems_add(pr, op, "duplicate", "%s has a robust constraint already "
					                  "(at /robust/constraints/%d)", name, k);
		snprintf(c->output, sizeof c->output, "%s", name);
	}
	const cJSON *spec = NULL;
	char sp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&spec, sp, sizeof sp, it, ip, "spec", PRSM_JSON_REQUIRED, spec_keys,
	                          pr) == PRSM_JSON_PRESENT) {
		const prsm_json_range any = {-1e300, 1e300, 0, 0};
		int lo = prsm_json_get_number(&c->spec.lower, spec, sp, "lower", PRSM_JSON_OPTIONAL, any, pr);
		int hi = prsm_json_get_number(&c->spec.upper, spec, sp, "upper", PRSM_JSON_OPTIONAL, any, pr);
		c->spec.has_lower = lo == PRSM_JSON_PRESENT;
		c->spec.has_upper = hi == PRSM_JSON_PRESENT;
		if (lo == PRSM_JSON_ABSENT && hi == PRSM_JSON_ABSENT)
			prsm_problems_add(pr, sp, "required", "a spec needs lower, upper or both");
		if (c->spec.has_lower && c->spec.has_upper && !(c->spec.lower < c->spec.upper)) {
			char up[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(up, sizeof up, sp, "upper");
			prsm_problems_add(pr, up, "range", "upper must be greater than lower");
		}
	}
	double pct = NAN;
	if (prsm_json_get_number(&pct, it, ip, "yield_min_percent", PRSM_JSON_REQUIRED,
	                         (prsm_json_range){0.0, 100.0, 1, 1}, pr) == PRSM_JSON_PRESENT)
		c->yield_min = pct / 100.0;
	if (prsm_problems_total(pr) > before)
		return PRSM_EINVAL;
	od->robust.n++;
	return 0;
}

/* The "robust" section: its constraints, and the study document every candidate's study is
 * made from, checked once on the base design (every problem re-pointed under /robust). */
static void read_robust(prsm_io_optimization *od, const cJSON *doc, const cJSON *design, int design_ok,
                        prsm_problems *pr)
{
	const cJSON *r = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&r, ptr, sizeof ptr, doc, "", "robust", PRSM_JSON_OPTIONAL,
	                          robust_keys, pr) != PRSM_JSON_PRESENT)
		return;
	const int before = prsm_problems_total(pr);
	prsm_robust_init(&od->robust);
	od->has_robust = 1;
	int kind = PRSM_ROBUST_KERNEL;
	prsm_json_get_enum(&kind, r, ptr, "surrogate", PRSM_JSON_OPTIONAL, prsm_robust_surrogate_names, pr);
	od->robust.surrogate = (prsm_robust_surrogate)kind;
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(r, "constraints");
	if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) < 1 ||
	    cJSON_GetArraySize(arr) > PRSM_ROBUST_MAX) {
		prsm_problems_add(pr, "/robust/constraints", arr ? "count" : "required",
		                  "an array of 1..%d robust constraints {output, spec, yield_min_percent}",
		                  PRSM_ROBUST_MAX);
	} else {
		int i = 0;
		const cJSON *it;
		cJSON_ArrayForEach(it, arr) {
			char ip[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(ip, sizeof ip, "/robust/constraints", i++);
			read_robust_constraint(od, it, ip, pr);
		}
	}
	if (!cJSON_GetObjectItemCaseSensitive(r, "tolerances"))
		prsm_problems_add(pr, "/robust/tolerances", "required", "robust constraints need the "
		                  "tolerance set (as a study's tolerances)");
	const cJSON *mc = NULL;
	char mp[PRSM_JSON_POINTER_MAX];
	prsm_json_get_section(&mc, mp, sizeof mp, r, ptr, "monte_carlo", PRSM_JSON_OPTIONAL,
	                      robust_mc_keys, pr);
	int samples = ROBUST_DEFAULT_SAMPLES;
	prsm_json_get_int(&samples, mc, mp, "samples", PRSM_JSON_OPTIONAL, 16, ROBUST_MAX_SAMPLES, pr);
	if (prsm_problems_total(pr) > before || !design_ok)
		return;

	/* the study document of the base design: every candidate's is this one with its geometry */
	cJSON *st = cJSON_CreateObject();
	od->study = st;
	if (!st)
		return;
	cJSON_AddItemToObject(st, "design", cJSON_Duplicate(design, 1));
	static const char *const copied[] = {"tolerances", "correlations", "assembly", NULL};
	for (int k = 0; copied[k]; k++) {
		const cJSON *it = cJSON_GetObjectItemCaseSensitive(r, copied[k]);
		if (it)
			cJSON_AddItemToObject(st, copied[k], cJSON_Duplicate(it, 1));
	}
	cJSON *outs = cJSON_AddArrayToObject(st, "outputs");
	cJSON *specs = cJSON_AddObjectToObject(st, "specs");
	for (int k = 0; k < od->robust.n; k++) {
		const prsm_robust_constraint *c = &od->robust.c[k];
		od->robust_output_of[k] = k;
		cJSON_AddItemToArray(outs, cJSON_CreateString(c->output));
		cJSON *so = cJSON_AddObjectToObject(specs, c->output);
		if (c->spec.has_lower)
			cJSON_AddNumberToObject(so, "lower", c->spec.lower);
		if (c->spec.has_upper)
			cJSON_AddNumberToObject(so, "upper", c->spec.upper);
	}
	cJSON *smc = mc ? cJSON_Duplicate(mc, 1) : cJSON_CreateObject();
	cJSON_AddItemToObject(st, "monte_carlo", smc);
	if (!cJSON_GetObjectItemCaseSensitive(smc, "samples"))
		cJSON_AddNumberToObject(smc, "samples", ROBUST_DEFAULT_SAMPLES);
	cJSON *sens = cJSON_AddObjectToObject(st, "sensitivity");
	cJSON_AddFalseToObject(sens, "src");
	cJSON_AddFalseToObject(sens, "stack");

	prsm_io_study *s = calloc(1, sizeof *s);
	prsm_problems *sp = malloc(sizeof *sp);
	if (s && sp) {
		prsm_problems_init(sp);
		if (prsm_app_study_load(s, st, NULL, sp)) {
			for (int i = 0; i < sp->count; i++)
				add_study_problem(pr, od, &sp->items[i]);
			if (sp->count == 0)
				prsm_problems_add(pr, "/robust", "invalid", "the robust study cannot be built");
		} else {
			od->robust.seed = s->study.mc.seed;
			od->robust.samples = s->study.mc.samples;
			snprintf(od->sampler, sizeof od->sampler, "%s", prsm_sampler_name(s->study.mc.sampler));
			od->block_size = s->study.mc.block_size;
			od->threads = s->study.mc.threads;
		}
	} else {
		prsm_problems_add(pr, "/robust", "memory", "out of memory");
	}
	free(sp);
	free(s);
}

/* Replaced radii of the base design as warnings (the optimiser's rules recompute them). */
static void base_warnings(const cJSON *doc, prsm_problems *warnings)
{
	static const char *const derived[] = {"screw_radius_mm", "nut_radius_mm", "roller_arc_radius_mm",
	                                      "screw_crest_radius_mm", "screw_root_radius_mm",
	                                      "roller_crest_radius_mm", "roller_root_radius_mm",
	                                      "nut_crest_radius_mm", "nut_root_radius_mm", NULL};
	const cJSON *g = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "design"),
	                                                  "geometry");
	for (int k = 0; g && derived[k]; k++)
		if (cJSON_GetObjectItemCaseSensitive(g, derived[k])) {
			char p[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(p, sizeof p, "/design/geometry", derived[k]);
			prsm_problems_add(warnings, p, "replaced", "the optimiser derives %s from the standard "
			                  "rules and the default thread proportions; the given value is not used",
			                  derived[k]);
		}
}

int prsm_legacy_optimization_read(prsm_io_optimization *od, const cJSON *doc, size_t max_evaluations,
                                  prsm_problems *warnings, prsm_problems *pr)
{
	memset(od, 0, sizeof *od);
	const int before = prsm_problems_total(pr);
	if (prsm_json_object_value(doc, "", pr))
		return PRSM_EINVAL;
	prsm_json_check_keys(doc, "", doc_keys, pr);
	const char *text = NULL;
	if (prsm_json_get_string(&text, doc, "", "name", PRSM_JSON_OPTIONAL, 100, pr) == PRSM_JSON_PRESENT)
		prsm_utf8_copy(od->name, sizeof od->name, text);
	prsm_json_get_string(&text, doc, "", "description", PRSM_JSON_OPTIONAL, 2000, pr);
	prsm_design base;
	const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
	int design_ok = 0;
	if (!design)
		prsm_problems_add(pr, "/design", "required", "is required (the base design)");
	else
		design_ok = prsm_io_design_from_json(&base, design, "/design", pr) == 0;
	if (!design_ok)
		prsm_design_init(&base);
	prsm_dp_spec_init(&od->spec, &base);
	read_variables(od, doc, pr);
	read_objectives(od, doc, pr);
	read_multi(od, doc, pr);
	read_constraints(od, doc, pr);
	read_solver(od, doc, max_evaluations, pr);
	read_robust(od, doc, design, design_ok, pr);
	if (prsm_problems_total(pr) > before)
		return PRSM_EINVAL;
	if (od->has_robust) {
		od->spec.robust = &od->robust;
		od->spec.robust_gate_tol = 0.0; /* studies only for candidates meeting every other limit */
	}
	base_warnings(doc, warnings);
	return 0;
}

