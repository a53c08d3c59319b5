/*
 * optimization_json.c: the optimisation document (schemas/optimization.schema.json) to the
 * design problem of opt/design_problem.h and the optimiser's options, the run (one objective,
 * the normalised weighted sum or the epsilon-constraint Pareto sweep of opt/pareto.h), and the
 * result document (schemas/optimization-result.schema.json). Every problem of the document is
 * reported at once with its JSON pointer, as src/io/study_json.c does for studies.
 */
#include "io/optimization_json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <nlopt.h>

#include "io/analysis_json.h"
#include "io/design_json.h"
#include "io/json_util.h"
#include "io/study_json.h"
#include "model/compliance.h"
#include "model/geometry.h"
#include "opt/design_problem.h"
#include "opt/optimize.h"
#include "opt/pareto.h"
#include "opt/robust.h"
#include "util/clock.h"
#include "util/utf8.h"
#include "util/version.h"

#define PRSM_OPT_MODEL_VERSION "prsm model 2026-11 (docs/model: geometry and meshing; kinematics, efficiency, stiffness and life)"
#define PRSM_OPT_ENGINE_NAME "prsm-opt 1 (NLopt local runs from GSL Sobol starts, integers enumerated with pruning)"

enum { METHOD_SINGLE = 0, METHOD_WEIGHTED = 1, METHOD_PARETO = 2 };
static const char *const method_names[] = {"single", "weighted_sum", "pareto", NULL};

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

/* A loaded document. */
typedef struct {
	char name[404]; /* up to 100 characters of UTF-8 */
	prsm_dp_spec spec;
	prsm_opt_problem problem;
	prsm_opt_options options;
	int method;
	int points;                       /* Pareto levels */
	double weight[PRSM_OPT_MAX_OBJECTIVES];
	int rollers_auto_max;             /* rollers' max defaulted to the Z_max bound */
	/* robust constraints (the "robust" section) */
	int has_robust;
	prsm_robust robust;
	cJSON *study;                     /* the study document of a candidate: the base design (its
	                                     geometry replaced per candidate), the section's tolerances,
	                                     correlations, assembly and monte_carlo, the constrained
	                                     outputs and specs, no sensitivities; owned */
	int robust_output_of[PRSM_MC_MAX_OUTPUTS]; /* constraint index of each study output */
	char sampler[16];                 /* the robust studies' sampler, as run */
	size_t block_size;
	int threads;
} opt_doc;

static void od_free(opt_doc *od)
{
	if (od)
		cJSON_Delete(od->study);
	free(od);
}


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
			int x;
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

static void read_variables(opt_doc *od, const cJSON *doc, prsm_problems *pr)
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

static void read_objectives(opt_doc *od, const cJSON *doc, prsm_problems *pr)
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

static void read_multi(opt_doc *od, const cJSON *doc, prsm_problems *pr)
{
	const cJSON *m = NULL;
	char ptr[PRSM_JSON_POINTER_MAX];
	od->method = METHOD_SINGLE;
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
	int method = METHOD_WEIGHTED;
	prsm_json_get_enum(&method, m, ptr, "method", PRSM_JSON_REQUIRED, method_names, pr);
	prsm_json_get_int(&od->points, m, ptr, "points", PRSM_JSON_OPTIONAL, 2,
	                  PRSM_IO_OPT_MAX_PARETO_POINTS, pr);
	od->method = method;
	char mp[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(mp, sizeof mp, ptr, "method");
	if (method == METHOD_PARETO && n != 2)
		prsm_problems_add(pr, mp, "objectives", "a Pareto sweep needs exactly 2 objectives (got %d)", n);
	if (method == METHOD_WEIGHTED) {
		double sum = 0.0;
		for (int k = 0; k < n; k++)
			sum += od->weight[k];
		if (!(sum > 0.0))
			prsm_problems_add(pr, "/objectives", "weights", "at least one weight must be positive");
	}
	if (method == METHOD_SINGLE && n > 1)
		prsm_problems_add(pr, mp, "objectives", "single needs exactly one objective (got %d)", n);
}

static void read_constraints(opt_doc *od, const cJSON *doc, prsm_problems *pr)
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

static void read_solver(opt_doc *od, const cJSON *doc, size_t max_evaluations, prsm_problems *pr)
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

/* Set obj[key] to the number v (replacing it or adding it). */
static void set_number(cJSON *obj, const char *key, double v)
{
	cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
	if (it && cJSON_IsNumber(it))
		cJSON_SetNumberValue(it, v);
	else {
		cJSON_DeleteItemFromObjectCaseSensitive(obj, key);
		cJSON_AddNumberToObject(obj, key, v);
	}
}

/* The flank angle in degrees that the design reader turns back into exactly beta_rad. */
static double flank_deg_exact(double beta_rad)
{
	double deg = beta_rad * (180.0 / M_PI);
	for (int k = 0; k < 8 && deg * (M_PI / 180.0) != beta_rad; k++)
		deg = nextafter(deg, deg * (M_PI / 180.0) < beta_rad ? INFINITY : -INFINITY);
	return deg;
}

/* Put candidate d's varied fields into the study document's design geometry: what
 * prsm_dp_design_at changes in the base design, with the derived radii left to the rules. */
static void candidate_geometry(cJSON *study, const prsm_design *d)
{
	cJSON *g = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(study, "design"),
	                                            "geometry");
	if (!g)
		return;
	static const char *const derived[] = {"screw_radius_mm", "nut_radius_mm", "roller_arc_radius_mm",
	                                      "screw_crest_radius_mm", "screw_root_radius_mm",
	                                      "roller_crest_radius_mm", "roller_root_radius_mm",
	                                      "nut_crest_radius_mm", "nut_root_radius_mm",
	                                      "nut_length_mm", NULL};
	for (int k = 0; derived[k]; k++)
		cJSON_DeleteItemFromObjectCaseSensitive(g, derived[k]);
	set_number(g, "starts", d->starts);
	set_number(g, "pitch_mm", d->pitch_mm);
	if (isfinite(d->roller_radius_mm))
		set_number(g, "roller_radius_mm", d->roller_radius_mm);
	set_number(g, "rollers", d->rollers);
	set_number(g, "engaged_threads", d->engaged_threads);
	set_number(g, "flank_angle_deg", flank_deg_exact(d->flank_angle_rad));
}

/* prsm_robust_build_fn: the tolerance study of candidate d through the study reader (so the
 * study is exactly the one an equivalent study document gives). */
static int build_study(void *ctx, prsm_study **study, void **handle, const prsm_design *d,
                       prsm_error *err)
{
	opt_doc *od = ctx;
	candidate_geometry(od->study, d);
	prsm_io_study *s = calloc(1, sizeof *s);
	prsm_problems *pr = malloc(sizeof *pr);
	int rc = 0;
	if (!s || !pr) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto fail;
	}
	prsm_problems_init(pr);
	rc = prsm_io_study_load(s, od->study, NULL, pr);
	if (rc) {
		if (pr->count)
			prsm_error_set(err, rc, NULL, "%s: %s", pr->items[0].pointer, pr->items[0].message);
		else
			prsm_error_set(err, rc, NULL, "the study could not be built");
		goto fail;
	}
	free(pr);
	*study = &s->study;
	*handle = s;
	return 0;
fail:
	free(pr);
	free(s);
	return rc;
}

static void release_study(void *ctx, void *handle)
{
	(void)ctx;
	free(handle);
}

/* Re-point a problem of the candidate study document into the optimisation document. */
static void add_study_problem(prsm_problems *pr, const opt_doc *od, const prsm_problem *p)
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
static int read_robust_constraint(opt_doc *od, const cJSON *it, const char *ip, prsm_problems *pr)
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
static void read_robust(opt_doc *od, const cJSON *doc, const cJSON *design, int design_ok,
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
		if (prsm_io_study_load(s, st, NULL, sp)) {
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

/* Read and check everything; od->problem ready when 0 is returned. */
static int load(opt_doc *od, const cJSON *doc, size_t max_evaluations, prsm_problems *warnings,
                prsm_problems *pr)
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
		od->robust.build = build_study;
		od->robust.release = release_study;
		od->robust.build_ctx = od;
		od->spec.robust = &od->robust;
		od->spec.robust_gate_tol = 0.0; /* studies only for candidates meeting every other limit */
	}
	base_warnings(doc, warnings);
	prsm_dp_spec *s = &od->spec;
	/* the rollers' max left out: up to the largest Z_max any start count reaches */
	if (od->rollers_auto_max >= 1) {
		int zb = 0;
		if (s->starts.count)
			for (int i = 0; i < s->starts.count; i++) {
				int z = prsm_dp_z_max_bound(s, s->starts.values[i]);
				zb = z > zb ? z : zb;
			}
		else
			zb = prsm_dp_z_max_bound(s, s->base.starts);
		if (zb > PRSM_DESIGN_ROLLERS_MAX)
			zb = PRSM_DESIGN_ROLLERS_MAX;
		for (int z = od->rollers_auto_max; z <= zb && s->rollers.count < PRSM_OPT_MAX_LEVELS; z++)
			s->rollers.values[s->rollers.count++] = z;
		if (s->rollers.count == 0) {
			prsm_problems_add(pr, "/variables/rollers/min", "z_max",
			                  "no roller count from %d up fits the geometry (Z_max at most %d)",
			                  od->rollers_auto_max, zb);
			return PRSM_EINVAL;
		}
	}
	if (!s->starts.count && s->base.starts < 3)
		prsm_problems_add(pr, "/design/geometry/starts", "starts_min",
		                  "the optimiser's standard rule r_s = (n-2) r_r needs at least 3 starts");
	if (s->radius_is_screw && !s->starts.count && s->radius.vary && s->base.starts < 3)
		return PRSM_EINVAL;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_problems_total(pr) > before)
		return PRSM_EINVAL;
	if (prsm_dp_problem(&od->problem, s, &err)) {
		prsm_problems_add(pr, err.pointer[0] ? err.pointer : "/variables", "invalid", "%s", err.message);
		return PRSM_EINVAL;
	}
	double combos = 1.0;
	for (int d = 0; d < od->problem.n_discrete; d++)
		combos *= od->problem.n_levels[d];
	if (combos > PRSM_OPT_MAX_COMBINATIONS) {
		prsm_problems_add(pr, "/variables", "too_many", "%.0f combinations of starts, rollers and "
		                  "engaged threads exceed %d", combos, PRSM_OPT_MAX_COMBINATIONS);
		return PRSM_EINVAL;
	}
	/* at least one combination must survive the cheap bounds */
	size_t alive = 0, n = (size_t)combos;
	for (size_t c = 0; c < n && !alive; c++) {
		double lv[PRSM_OPT_MAX_DISCRETE];
		size_t r = c;
		for (int d = od->problem.n_discrete - 1; d >= 0; d--) {
			lv[d] = od->problem.levels[d][r % (size_t)od->problem.n_levels[d]];
			r /= (size_t)od->problem.n_levels[d];
		}
		alive += !od->problem.prune(od->problem.ctx, lv, od->problem.lower, od->problem.upper);
	}
	if (!alive) {
		prsm_problems_add(pr, "/variables", "infeasible", "no combination of the variables can fit "
		                  "its rollers and the diameter limits, even at the most favourable corner "
		                  "of the ranges");
		return PRSM_EINVAL;
	}
	for (int k = 0; k < s->n_objectives; k++)
		od->options.weight[k] = od->weight[k];
	return 0;
}

int prsm_io_optimization_check(const cJSON *doc, size_t max_evaluations, prsm_problems *warnings,
                               prsm_problems *problems)
{
	opt_doc *od = calloc(1, sizeof *od);
	if (!od)
		return PRSM_ENOMEM;
	int rc = load(od, doc, max_evaluations, warnings, problems);
	od_free(od);
	return rc;
}

/* ---- the result document ---- */

static const char *const constraint_units[] = {"-", "-", "rule warnings", "mm", "mm", "mm", "-",
                                               "h", "revolutions", "MPa", "-"};

static cJSON *variables_json(const prsm_design *d)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "starts", d->starts);
	prsm_json_add_number(o, "pitch_mm", d->pitch_mm);
	prsm_json_add_number(o, "lead_mm", prsm_design_lead_mm(d));
	prsm_json_add_number(o, "roller_radius_mm", d->roller_radius_mm);
	prsm_json_add_number(o, "screw_radius_mm", d->screw_radius_mm);
	prsm_json_add_number(o, "nut_radius_mm", d->nut_radius_mm);
	cJSON_AddNumberToObject(o, "rollers", d->rollers);
	cJSON_AddNumberToObject(o, "engaged_threads", d->engaged_threads);
	prsm_json_add_number(o, "flank_angle_deg", d->flank_angle_rad * 180.0 / M_PI);
	return o;
}

static cJSON *figures_json(const prsm_dp_figures *f, const prsm_design *d)
{
	cJSON *o = cJSON_CreateObject();
	prsm_json_add_number(o, "efficiency", f->objective[PRSM_DP_EFFICIENCY]);
	prsm_json_add_number(o, "stiffness_N_per_um", f->objective[PRSM_DP_STIFFNESS]);
	prsm_json_add_number(o, "mass_kg", f->objective[PRSM_DP_MASS]);
	prsm_json_add_number(o, "reflected_inertia_kg_m2", f->objective[PRSM_DP_INERTIA]);
	cJSON_AddNumberToObject(o, "rollers", d->rollers);
	cJSON_AddNumberToObject(o, "z_max", f->z_max);
	prsm_json_add_number(o, "nut_outer_diameter_mm", f->nut_outer_diameter_mm);
	prsm_json_add_number(o, "screw_diameter_mm", f->screw_diameter_mm);
	prsm_json_add_number(o, "static_safety", f->static_safety);
	prsm_json_add_number(o, "life_h", f->life_h);
	prsm_json_add_number(o, "life_revolutions", f->life_revolutions);
	prsm_json_add_number(o, "p_max_MPa", f->p_max_MPa);
	prsm_json_add_number(o, "critical_speed_rpm", f->critical_speed_rpm);
	prsm_json_add_number(o, "operating_speed_rpm", f->operating_speed_rpm);
	return o;
}

/* Every constraint with its value, limit and whether it meets its raw limit (g the fresh
 * violations of prsm_dp_violation: no tolerance); violated names to viol. */
static cJSON *constraints_json(const opt_doc *od, const prsm_dp_figures *f, const double *g,
                               cJSON *viol)
{
	cJSON *arr = cJSON_CreateArray();
	const prsm_dp_spec *s = &od->spec;
	for (int i = 0; i < s->n_constraints; i++) {
		int kind = s->constraint_kind[i];
		cJSON *c = cJSON_CreateObject();
		cJSON_AddStringToObject(c, "name", prsm_dp_constraint_names[kind]);
		cJSON_AddStringToObject(c, "unit", constraint_units[kind]);
		prsm_json_add_number(c, "value", f->constraint_value[kind]);
		prsm_json_add_number(c, "limit", s->constraint_limit[i]);
		cJSON_AddStringToObject(c, "bound", kind == PRSM_DP_C_SCREW_DIAMETER_MIN ||
		                                            kind == PRSM_DP_C_STATIC_SAFETY ||
		                                            kind == PRSM_DP_C_LIFE_HOURS ||
		                                            kind == PRSM_DP_C_LIFE_REVOLUTIONS ||
		                                            kind == PRSM_DP_C_CRITICAL_SPEED
		                                        ? "min" : "max");
		int ok = g[i] <= 0.0;
		cJSON_AddBoolToObject(c, "satisfied", ok);
		if (!ok && viol)
			cJSON_AddItemToArray(viol, cJSON_CreateString(prsm_dp_constraint_names[kind]));
		if (kind == PRSM_DP_C_ANALYSABLE && f->failure[0])
			cJSON_AddStringToObject(c, "message", f->failure);
		cJSON_AddItemToArray(arr, c);
	}
	return arr;
}

static cJSON *objectives_json(const opt_doc *od, const double *values)
{
	cJSON *arr = cJSON_CreateArray();
	for (int k = 0; k < od->spec.n_objectives; k++) {
		cJSON *o = cJSON_CreateObject();
		cJSON_AddStringToObject(o, "name", prsm_dp_objective_names[od->spec.objective[k]]);
		cJSON_AddStringToObject(o, "sense", od->problem.sense[k] > 0 ? "minimise" : "maximise");
		prsm_json_add_number(o, "value", values[k]);
		if (od->method == METHOD_WEIGHTED)
			prsm_json_add_number(o, "weight", od->weight[k]);
		cJSON_AddItemToArray(arr, o);
	}
	return arr;
}

static double percent(double fraction)
{
	return 100.0 * fraction;
}

/* The robust constraints of candidate d (unresolved) as the result's "robust" array, re-run
 * from scratch (the cache emptied first: the reported yields are a fresh Monte Carlo run of the
 * study, with common random numbers the one the search saw). g holds the point's fresh
 * deterministic violations (the study runs only when they hold). `satisfied` is that fresh
 * run's yield against its target, no tolerance. Unsatisfied names go to viol. Returns 0,
 * PRSM_ECANCELLED or PRSM_ENOMEM. */
static int robust_json(cJSON **out, const opt_doc *od, const prsm_design *d, const double *g,
                       cJSON *viol)
{
	prsm_robust_eval re;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_robust_forget(od->spec.robust);
	int rc = prsm_dp_robust(&re, &od->spec, d, g, &err);
	if (rc == PRSM_ENOMEM)
		return rc;
	cJSON *arr = cJSON_CreateArray();
	for (int k = 0; k < od->robust.n; k++) {
		const prsm_robust_constraint *c = &od->robust.c[k];
		const prsm_robust_value *v = &re.v[k];
		cJSON *e = cJSON_CreateObject();
		char name[PRSM_OPT_NAME_MAX];
		snprintf(name, sizeof name, "yield_%.40s", c->output);
		cJSON_AddStringToObject(e, "name", name);
		cJSON_AddStringToObject(e, "output", c->output);
		cJSON *sp = cJSON_AddObjectToObject(e, "spec");
		if (c->spec.has_lower)
			prsm_json_add_number(sp, "lower", c->spec.lower);
		if (c->spec.has_upper)
			prsm_json_add_number(sp, "upper", c->spec.upper);
		prsm_json_add_number(e, "yield_min_percent", percent(c->yield_min));
		const int ok = rc == 0 && re.evaluated;
		cJSON_AddBoolToObject(e, "evaluated", ok);
		prsm_json_add_number(e, "yield_percent", ok ? percent(v->yield) : NAN);
		prsm_json_add_number(e, "yield_low95_percent", ok ? percent(v->yield_low95) : NAN);
		prsm_json_add_number(e, "yield_high95_percent", ok ? percent(v->yield_high95) : NAN);
		cJSON_AddNumberToObject(e, "samples", ok ? (double)re.samples : 0.0);
		cJSON_AddNumberToObject(e, "failed_samples", ok ? (double)re.failed : 0.0);
		cJSON_AddNumberToObject(e, "edge_contact_samples", ok ? (double)re.edge : 0.0);
		cJSON_AddNumberToObject(e, "seed", (double)od->robust.seed);
		cJSON_AddStringToObject(e, "sampler", od->sampler);
		prsm_json_add_number(e, "mean", ok ? v->mean : NAN);
		prsm_json_add_number(e, "sd", ok ? v->sd : NAN);
		prsm_json_add_number(e, "normal_yield_percent", ok ? percent(v->normal_yield) : NAN);
		prsm_json_add_number(e, "surrogate_yield_percent", ok ? percent(v->smooth_yield) : NAN);
		/* the fresh run's verdict (the search saw the same yield: common random numbers) */
		const int sat = ok && v->g <= 0.0;
		cJSON_AddBoolToObject(e, "satisfied", sat);
		if (!ok)
			cJSON_AddStringToObject(e, "message", rc ? err.message : re.failure);
		if (!sat && viol)
			cJSON_AddItemToArray(viol, cJSON_CreateString(name));
		cJSON_AddItemToArray(arr, e);
	}
	*out = arr;
	return rc == PRSM_ECANCELLED ? rc : 0;
}

/* The design at (x, levels) analysed afresh and in full: into o as design (+ analysis when
 * full), variables, figures, objectives, constraints and the robust constraints, each
 * constraint judged on this analysis against its raw limit. Returns 0, PRSM_ECANCELLED (a
 * robust study was cancelled) or PRSM_ENOMEM. */
static int point_json(cJSON *o, const opt_doc *od, const double *x, const double *levels,
                      int full, cJSON *violated)
{
	prsm_design d;
	prsm_dp_figures fig;
	prsm_analysis *a = calloc(1, sizeof *a);
	prsm_performance perf;
	if (!a)
		return PRSM_ENOMEM;
	prsm_dp_design_at(&d, &od->spec, x, levels);
	const prsm_design unresolved = d;
	int rc = prsm_dp_analyse(&fig, &d, &od->spec, 1, a, &perf);
	double g[PRSM_OPT_MAX_CONSTRAINTS];
	for (int i = 0; i < od->spec.n_constraints; i++)
		g[i] = prsm_dp_violation(&od->spec, i, &fig, d.rollers);
	cJSON_AddItemToObject(o, "variables", variables_json(&d));
	double f[PRSM_OPT_MAX_OBJECTIVES];
	for (int k = 0; k < od->spec.n_objectives; k++)
		f[k] = fig.objective[od->spec.objective[k]];
	cJSON_AddItemToObject(o, "objectives", objectives_json(od, f));
	cJSON_AddItemToObject(o, "constraints", constraints_json(od, &fig, g, violated));
	int rrc = 0;
	if (od->has_robust) {
		cJSON *rob = NULL;
		rrc = robust_json(&rob, od, &unresolved, g, violated);
		if (rob)
			cJSON_AddItemToObject(o, "robust", rob);
	}
	cJSON_AddItemToObject(o, "figures", figures_json(&fig, &d));
	if (rc == 0) {
		prsm_problems w;
		prsm_problems_init(&w);
		cJSON *an = prsm_io_analysis_to_json(a, &d, &perf, &w);
		if (an) {
			cJSON_AddItemToObject(o, "design", cJSON_Duplicate(cJSON_GetObjectItemCaseSensitive(an, "design"), 1));
			if (full)
				cJSON_AddItemToObject(o, "analysis", an);
			else
				cJSON_Delete(an);
		}
	} else {
		cJSON_AddNullToObject(o, "design");
	}
	prsm_performance_free(&perf);
	free(a);
	return rrc;
}

static void add_run_figures(cJSON *doc, const opt_doc *od, size_t evaluations, size_t combos,
                            size_t pruned, size_t runs, size_t runs_feasible,
                            size_t runs_truncated, int stop, int cancelled, double elapsed_s)
{
	cJSON_AddBoolToObject(doc, "cancelled", cancelled);
	cJSON_AddStringToObject(doc, "stop_reason", prsm_opt_stop_names[stop]);
	cJSON_AddNumberToObject(doc, "evaluations", (double)evaluations);
	cJSON *sv = cJSON_AddObjectToObject(doc, "solver");
	cJSON_AddStringToObject(sv, "algorithm", prsm_opt_algorithm_names[od->options.algorithm]);
	cJSON_AddNumberToObject(sv, "max_evaluations", (double)od->options.max_evaluations);
	prsm_json_add_number(sv, "max_time_s", od->options.max_time_s);
	cJSON_AddNumberToObject(sv, "multistart", od->options.multistart);
	cJSON_AddNumberToObject(sv, "seed", (double)od->options.seed);
	prsm_json_add_number(sv, "xtol_rel", od->options.xtol_rel);
	prsm_json_add_number(sv, "ftol_rel", od->options.ftol_rel);
	prsm_json_add_number(sv, "constraint_tolerance", od->options.constraint_tol);
	cJSON *cb = cJSON_AddObjectToObject(doc, "search");
	cJSON_AddNumberToObject(cb, "combinations", (double)combos);
	cJSON_AddNumberToObject(cb, "pruned", (double)pruned);
	cJSON_AddNumberToObject(cb, "runs", (double)runs);
	cJSON_AddNumberToObject(cb, "runs_feasible", (double)runs_feasible);
	cJSON_AddNumberToObject(cb, "runs_truncated", (double)runs_truncated);
	prsm_json_add_number(doc, "elapsed_s", elapsed_s);
}

/* The robust studies' settings and cost, after the search and the result's re-checks. */
static void add_robust_summary(cJSON *doc, const opt_doc *od)
{
	if (!od->has_robust)
		return;
	const prsm_robust *r = &od->robust;
	cJSON *ro = cJSON_AddObjectToObject(doc, "robust");
	cJSON_AddStringToObject(ro, "method", "Monte Carlo yield of the candidate's tolerance study "
	                        "with common random numbers (the same seed, samples, sampler and "
	                        "block size for every candidate); run only when every other "
	                        "constraint holds");
	cJSON_AddStringToObject(ro, "surrogate", prsm_robust_surrogate_names[r->surrogate]);
	cJSON_AddNumberToObject(ro, "samples_per_study", (double)r->samples);
	cJSON_AddNumberToObject(ro, "seed", (double)r->seed);
	cJSON_AddStringToObject(ro, "sampler", od->sampler);
	cJSON_AddNumberToObject(ro, "block_size", (double)od->block_size);
	cJSON_AddNumberToObject(ro, "threads", od->threads);
	cJSON_AddNumberToObject(ro, "studies", (double)r->studies);
	cJSON_AddNumberToObject(ro, "samples", (double)r->samples_total);
	prsm_json_add_number(ro, "elapsed_s", r->elapsed_s);
}


static cJSON *result_head(const opt_doc *od, const prsm_problems *warnings)
{
	cJSON *doc = cJSON_CreateObject();
	if (!doc)
		return NULL;
	if (od->name[0])
		cJSON_AddStringToObject(doc, "name", od->name);
	cJSON *ver = cJSON_AddObjectToObject(doc, "versions");
	cJSON_AddStringToObject(ver, "prsm", PRSM_VERSION);
	cJSON_AddStringToObject(ver, "engine", PRSM_OPT_ENGINE_NAME);
	cJSON_AddStringToObject(ver, "build", prsm_engine_build());
	char nl[32];
	int maj, min, bug;
	nlopt_version(&maj, &min, &bug);
	snprintf(nl, sizeof nl, "%d.%d.%d", maj, min, bug);
	cJSON_AddStringToObject(ver, "nlopt", nl);
	cJSON_AddStringToObject(ver, "model", PRSM_OPT_MODEL_VERSION);
	cJSON_AddStringToObject(doc, "method", method_names[od->method]);
	cJSON_AddItemToObject(doc, "warnings", prsm_io_problems_to_json(warnings));
	return doc;
}

/* The best design of a run as the result's main part: re-analysed, and feasible only when the
 * optimiser found it so and the fresh check finds no constraint violated. */
static int add_best(cJSON *doc, const opt_doc *od, int status, const double *x, const double *lv)
{
	cJSON *violated = cJSON_CreateArray();
	cJSON *best = cJSON_CreateObject();
	int rc = 0;
	if (status != PRSM_OPT_NOTHING)
		rc = point_json(best, od, x, lv, 1, violated);
	if (status == PRSM_OPT_FEASIBLE && cJSON_GetArraySize(violated) > 0)
		status = PRSM_OPT_INFEASIBLE;
	cJSON_AddStringToObject(doc, "status", status == PRSM_OPT_FEASIBLE     ? "feasible"
	                                       : status == PRSM_OPT_INFEASIBLE ? "infeasible"
	                                                                       : "none");
	cJSON_AddBoolToObject(doc, "feasible", status == PRSM_OPT_FEASIBLE);
	cJSON_AddItemToObject(doc, "violated", violated);
	cJSON_AddItemToObject(doc, "best", status != PRSM_OPT_NOTHING ? best : cJSON_CreateNull());
	if (status == PRSM_OPT_NOTHING)
		cJSON_Delete(best);
	return rc;
}

static void progress_forward(prsm_opt_options *o, prsm_progress_fn fn, void *ctx)
{
	o->progress = fn;
	o->progress_ctx = ctx;
}

int prsm_io_optimization_execute(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                                 prsm_progress_fn progress, void *progress_ctx, double max_time_s,
                                 prsm_problems *problems, prsm_error *err)
{
	*result = NULL;
	prsm_problems warnings;
	prsm_problems_init(&warnings);
	opt_doc *od = calloc(1, sizeof *od);
	prsm_opt_result *r = calloc(1, sizeof *r);
	prsm_opt_front *front = NULL;
	int rc = 0;
	if (!od || !r) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	rc = load(od, doc, 0, &warnings, problems);
	if (rc) {
		prsm_error_set(err, rc, NULL, "the optimisation document is invalid");
		goto cleanup;
	}
	/* the problem's ctx points into od->spec: od does not move from here on */
	od->problem.ctx = &od->spec;
	prsm_opt_options *o = &od->options;
	o->cancel = cancel;
	od->robust.cancel = cancel;
	progress_forward(o, progress, progress_ctx);
	if (max_time_s > 0.0 && max_time_s < o->max_time_s)
		o->max_time_s = max_time_s;
	cJSON *out = result_head(od, &warnings);
	if (!out) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	*result = out;
	int run_rc;
	if (od->method == METHOD_PARETO) {
		front = calloc(1, sizeof *front);
		if (!front) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
			goto cleanup;
		}
		run_rc = prsm_opt_pareto(front, &od->problem, o, 0, 1, od->points, err);
		if (run_rc && run_rc != PRSM_ECANCELLED) {
			rc = run_rc;
			goto cleanup;
		}
		/* the point closest to the ideal (Chebyshev distance, normalised) leads the result */
		const int lead = prsm_opt_front_lead(front, &od->problem);
		od->robust.cancel = NULL; /* the result's re-checks run to the end */
		add_run_figures(out, od, front->evaluations, front->anchor[0].combinations,
		                front->anchor[0].pruned, front->local_runs, front->local_runs_feasible,
		                front->runs_truncated, front->stop,
		                front->cancelled, front->elapsed_s);
		if (lead >= 0)
			rc = add_best(out, od, PRSM_OPT_FEASIBLE, front->points[lead].x, front->points[lead].levels);
		else
			rc = add_best(out, od, PRSM_OPT_NOTHING, NULL, NULL);
		cJSON *pf = cJSON_AddObjectToObject(out, "pareto");
		cJSON_AddStringToObject(pf, "objective_a", prsm_dp_objective_names[od->spec.objective[0]]);
		cJSON_AddStringToObject(pf, "objective_b", prsm_dp_objective_names[od->spec.objective[1]]);
		cJSON_AddNumberToObject(pf, "levels", od->points);
		cJSON_AddNumberToObject(pf, "epsilon_runs", front->runs);
		cJSON_AddNumberToObject(pf, "epsilon_runs_feasible", front->runs_feasible);
		cJSON_AddNumberToObject(pf, "dominated_removed", front->dominated_removed);
		cJSON *pts = cJSON_AddArrayToObject(pf, "points");
		for (int i = 0; i < front->n_points && rc == 0; i++) {
			cJSON *pt = cJSON_CreateObject();
			prsm_json_add_number(pt, "epsilon_limit", front->points[i].eps_limit);
			rc = point_json(pt, od, front->points[i].x, front->points[i].levels, 1, NULL);
			cJSON_AddItemToArray(pts, pt);
		}
		if (rc == 0)
			rc = run_rc;
	} else {
		double ideal[PRSM_OPT_MAX_OBJECTIVES], range[PRSM_OPT_MAX_OBJECTIVES];
		if (od->method == METHOD_WEIGHTED)
			run_rc = prsm_opt_weighted_sum(r, ideal, range, &od->problem, o, err);
		else
			run_rc = prsm_opt_run(r, &od->problem, o, err);
		if (run_rc && run_rc != PRSM_ECANCELLED) {
			rc = run_rc;
			goto cleanup;
		}
		od->robust.cancel = NULL; /* the result's re-checks run to the end */
		add_run_figures(out, od, r->evaluations, r->combinations, r->pruned, r->runs,
		                r->runs_feasible, r->runs_truncated, r->stop,
		                r->cancelled || run_rc == PRSM_ECANCELLED, r->elapsed_s);
		rc = add_best(out, od, r->status, r->x, r->levels);
		if (od->method == METHOD_WEIGHTED) {
			cJSON *nm = cJSON_AddObjectToObject(out, "normalisation");
			cJSON_AddStringToObject(nm, "rule", "each objective as (sense f - ideal) / range, "
			                        "ideal and range from the single-objective optima (payoff table), "
			                        "sense +1 to minimise, -1 to maximise");
			cJSON *arr = cJSON_AddArrayToObject(nm, "objectives");
			for (int k = 0; k < od->spec.n_objectives; k++) {
				cJSON *e = cJSON_CreateObject();
				cJSON_AddStringToObject(e, "name", prsm_dp_objective_names[od->spec.objective[k]]);
				prsm_json_add_number(e, "ideal", od->problem.sense[k] * ideal[k]);
				prsm_json_add_number(e, "range", range[k]);
				cJSON_AddItemToArray(arr, e);
			}
		}
		if (rc == 0)
			rc = run_rc;
	}
	add_robust_summary(out, od);
cleanup:
	if (rc && rc != PRSM_ECANCELLED && *result) {
		cJSON_Delete(*result);
		*result = NULL;
	}
	free(front);
	free(r);
	od_free(od);
	return rc;
}
