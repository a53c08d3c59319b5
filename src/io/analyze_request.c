/*
 * analyze_request.c: the analyze request from JSON to its result (docs/model/geometry-and-meshing.md–§6), for the CLI
 * and the service alike.
 */
#include "io/analyze_request.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/analysis_json.h"
#include "io/assembly_json.h"
#include "io/design_json.h"
#include "io/dynamics_json.h"
#include "io/errors_json.h"
#include "io/doc.h"
#include "io/json_util.h"
#include "io/write.h"
#include "prsm_io_tables.h"
#include "prsm_io_writers.h"
#include "util/error.h"

static const char *const request_keys[] = {"design", "errors", "assembly", "dynamics", NULL};

/* ---- catalogue sizes: {"nominal": {"diameter_mm", "lead_mm", ...}} (model/nominal.h) ---- */

/* the geometry members a catalogue size sets, and the nominal member a problem of each is
 * reported at (the user wrote that one, not the geometry's) */
static const char *const nominal_sets[][2] = {
	{"starts", "starts"}, {"pitch_mm", "lead_mm"}, {"roller_radius_mm", "diameter_mm"},
	{"screw_radius_mm", "diameter_mm"}, {"nut_radius_mm", "diameter_mm"}, {"rollers", "rollers"},
	{"engaged_threads", "engaged_threads"}, {"nut_length_mm", "engaged_threads"}};
#define NOMINAL_SETS (sizeof nominal_sets / sizeof nominal_sets[0])

/* A number member of geometry, or fallback when it is absent or not a number. */
static double geometry_number(const cJSON *geometry, const char *key, double fallback)
{
	const cJSON *v = cJSON_GetObjectItemCaseSensitive(geometry, key);
	return cJSON_IsNumber(v) ? v->valuedouble : fallback;
}

/* Read design["nominal"] into *n (pointer base + "/nominal"); a geometry member it sets is a
 * conflict. Returns 0 or PRSM_EINVAL. */
static int read_nominal(prsm_nominal *n, const cJSON *design, const char *base, prsm_problems *problems)
{
	const int before = prsm_problems_total(problems);
	char np[PRSM_JSON_POINTER_MAX], gp[PRSM_JSON_POINTER_MAX], ptr[PRSM_JSON_POINTER_MAX];
	const cJSON *nom = NULL;
	memset(n, 0, sizeof *n);
	/* its members, limits and units from the schema (analyze-request.schema.json $defs/nominal) */
	if (prsm_json_get_object(&nom, design, base, "nominal", PRSM_JSON_REQUIRED, problems) == PRSM_JSON_PRESENT &&
	    nom != NULL) {
		prsm_json_pointer_append(np, sizeof np, base, "nominal");
		prsm_io_read(n, &prsm_io_t_nominal, nom, np, problems);
	}
	const cJSON *geometry = cJSON_GetObjectItemCaseSensitive(design, "geometry");
	prsm_json_pointer_append(gp, sizeof gp, base, "geometry");
	for (size_t i = 0; cJSON_IsObject(geometry) && i < NOMINAL_SETS; i++)
		if (cJSON_GetObjectItemCaseSensitive(geometry, nominal_sets[i][0])) {
			prsm_json_pointer_append(ptr, sizeof ptr, gp, nominal_sets[i][0]);
			prsm_problems_add(problems, ptr, "conflict",
			                  "is set by the catalogue size (nominal.%s): give nominal or this field, "
			                  "not both", nominal_sets[i][1]);
		}
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

/* A copy of design with `nominal` replaced by the geometry g resolves it to; NULL when out of
 * memory. The caller owns it. */
static cJSON *nominal_expanded(const cJSON *design, const prsm_nominal_geometry *g)
{
	cJSON *copy = cJSON_Duplicate(design, 1);
	if (copy == NULL)
		return NULL;
	cJSON_DeleteItemFromObjectCaseSensitive(copy, "nominal");
	cJSON *geometry = cJSON_GetObjectItemCaseSensitive(copy, "geometry");
	if (geometry == NULL)
		geometry = cJSON_AddObjectToObject(copy, "geometry");
	if (!cJSON_IsObject(geometry) || !cJSON_AddNumberToObject(geometry, "starts", g->starts) ||
	    !cJSON_AddNumberToObject(geometry, "pitch_mm", g->pitch_mm) ||
	    !cJSON_AddNumberToObject(geometry, "roller_radius_mm", g->roller_radius_mm) ||
	    !cJSON_AddNumberToObject(geometry, "rollers", g->rollers) ||
	    !cJSON_AddNumberToObject(geometry, "engaged_threads", g->engaged_threads)) {
		cJSON_Delete(copy);
		return NULL;
	}
	return copy;
}

/* Problems from index `from` on at a geometry member the catalogue size set, moved to the
 * nominal member the user wrote. */
static void nominal_repoint(prsm_problems *p, int from, const char *base)
{
	char gp[PRSM_JSON_POINTER_MAX], ptr[PRSM_JSON_POINTER_MAX];
	for (int i = from; p && i < p->count; i++)
		for (size_t k = 0; k < NOMINAL_SETS; k++) {
			snprintf(gp, sizeof gp, "%s/geometry/%s", base, nominal_sets[k][0]);
			if (strcmp(p->items[i].pointer, gp) == 0) {
				snprintf(ptr, sizeof ptr, "%s/nominal/%s", base, nominal_sets[k][1]);
				snprintf(p->items[i].pointer, sizeof p->items[i].pointer, "%s", ptr);
				break;
			}
		}
}

/* The same diameter and lead with starts 3 to 6: each analysed on its own (MODEL.md §1, §6). */
static void nominal_alternatives(prsm_io_nominal_result *out, const cJSON *design, double beta,
                                 double clearance_mm)
{
	prsm_problems *scratch = malloc(2 * sizeof *scratch);
	prsm_design *d = malloc(sizeof *d);
	prsm_analysis *a = malloc(sizeof *a);
	prsm_performance *perf = calloc(1, sizeof *perf);
	if (!scratch || !d || !a || !perf)
		goto cleanup;
	out->n_alternatives = 0;
	for (int n = PRSM_NOMINAL_STARTS_MIN; n < PRSM_NOMINAL_STARTS_MIN + PRSM_NOMINAL_ALTERNATIVES; n++) {
		prsm_io_nominal_alternative *alt = &out->alternatives[out->n_alternatives++];
		memset(alt, 0, sizeof *alt);
		prsm_nominal given = out->given;
		given.starts = n;
		prsm_nominal_geometry g;
		prsm_problems_init(&scratch[0]);
		prsm_problems_init(&scratch[1]);
		alt->starts = n;
		if (prsm_nominal_resolve(&g, &given, beta, clearance_mm, &scratch[0])) {
			snprintf(alt->problem, sizeof alt->problem, "%s", scratch[0].items[0].message);
			continue;
		}
		alt->pitch_mm = g.pitch_mm;
		alt->roller_radius_mm = g.roller_radius_mm;
		alt->rollers = g.rollers;
		alt->engaged_threads = g.engaged_threads;
		cJSON *copy = nominal_expanded(design, &g);
		if (copy == NULL) {
			snprintf(alt->problem, sizeof alt->problem, "out of memory");
			continue;
		}
		prsm_geometry geom;
		prsm_error err = PRSM_ERROR_INIT;
		int rc = prsm_io_design_load(d, &geom, NULL, copy, "", &scratch[0]);
		cJSON_Delete(copy);
		if (rc == 0 && (rc = prsm_analysis_nominal(a, d, &scratch[1], &err)) == 0) {
			prsm_performance_free(perf);
			rc = prsm_performance_compute(perf, d, a, &err);
		}
		if (rc) {
			const char *why = scratch[0].count ? scratch[0].items[0].message : err.message;
			snprintf(alt->problem, sizeof alt->problem, "%.*s", (int)sizeof alt->problem - 1, why);
			continue;
		}
		alt->valid = 1;
		alt->makers_C0a_N = perf->makers.C0a_N;
		alt->makers_C_a_N = perf->makers.C_a_N;
		alt->makers_ratio = perf->makers.C0a_over_C_a;
		alt->C0a_N = perf->C0a_N;
		alt->C_a_N = perf->dynamic.C_a_N;
		alt->truncated = perf->C0a_truncation_limited;
	}
cleanup:
	if (perf)
		prsm_performance_free(perf);
	free(perf);
	free(a);
	free(d);
	free(scratch);
}

int prsm_io_design_load_sized(prsm_design *out, prsm_geometry *geom, prsm_problems *warnings, const cJSON *design,
                              const char *base, prsm_problems *problems, prsm_io_nominal_result *nominal)
{
	if (!cJSON_IsObject(design) || !cJSON_GetObjectItemCaseSensitive(design, "nominal"))
		return prsm_io_design_load(out, geom, warnings, design, base, problems);
	prsm_nominal given;
	int rc = read_nominal(&given, design, base, problems);
	if (nominal)
		nominal->given = given;
	if (rc)
		return rc;
	const cJSON *geometry = cJSON_GetObjectItemCaseSensitive(design, "geometry");
	const double beta = geometry_number(geometry, "flank_angle_deg", 45.0) * M_PI / 180.0;
	const double clearance = geometry_number(geometry, "running_clearance_mm", 0.1);
	prsm_problems *errors = malloc(sizeof *errors);
	if (errors == NULL)
		return PRSM_ENOMEM;
	prsm_problems_init(errors);
	prsm_nominal_geometry g;
	rc = prsm_nominal_resolve(&g, &given, beta, clearance, errors);
	prsm_json_problems_append_prefixed(problems, errors, base);
	free(errors);
	if (rc)
		return rc;
	if (nominal) {
		nominal->resolved = g;
		nominal_alternatives(nominal, design, beta, clearance);
	}
	cJSON *expanded = nominal_expanded(design, &g);
	if (expanded == NULL)
		return PRSM_ENOMEM;
	const int from_problems = problems->count, from_warnings = warnings ? warnings->count : 0;
	rc = prsm_io_design_load(out, geom, warnings, expanded, base, problems);
	nominal_repoint(problems, from_problems, base);
	nominal_repoint(warnings, from_warnings, base);
	cJSON_Delete(expanded);
	return rc;
}

/* The `dynamics` object of doc, when there is one, for a chain of `stages` stages. */
static void read_dynamics(prsm_analyze_request *rq, const cJSON *doc, int stages, prsm_problems *problems)
{
	const cJSON *dyn = cJSON_GetObjectItemCaseSensitive(doc, "dynamics");
	rq->with_dynamics = dyn != NULL;
	if (dyn != NULL)
		prsm_io_dynamics_from_json(&rq->dyn, dyn, stages, problems);
}

/* The document part: design, and the error set with its options when asked. Returns 0 or
 * PRSM_EINVAL / PRSM_EGEOMETRY (prsm_io_design_load's codes). */
static int load_document(prsm_analyze_request *rq, prsm_geometry *g, prsm_problems *warnings,
                         prsm_problems *problems, const cJSON *doc)
{
	int rc;
	rq->with_errors = cJSON_IsObject(doc) && cJSON_GetObjectItemCaseSensitive(doc, "design") != NULL;
	const cJSON *design = rq->with_errors ? cJSON_GetObjectItemCaseSensitive(doc, "design") : doc;
	/* a catalogue size (analyze-request.schema.json $defs/catalogue_design): the plain design
	 * document also lists its alternatives with 3 to 6 starts */
	if (!rq->with_errors) {
		rq->with_nominal = cJSON_IsObject(design) && cJSON_GetObjectItemCaseSensitive(design, "nominal") != NULL;
		return prsm_io_design_load_sized(&rq->d, g, warnings, design, "", problems,
		                                 rq->with_nominal ? &rq->nominal : NULL);
	}
	prsm_json_check_keys(doc, "", request_keys, problems);
	rc = prsm_io_design_load_sized(&rq->d, g, warnings, design, "/design", problems, NULL);
	const cJSON *errors = NULL, *opts = NULL;
	char ep[PRSM_JSON_POINTER_MAX], op[PRSM_JSON_POINTER_MAX];
	prsm_json_get_object(&errors, doc, "", "errors", PRSM_JSON_OPTIONAL, problems);
	prsm_json_get_object(&opts, doc, "", "assembly", PRSM_JSON_OPTIONAL, problems);
	prsm_json_pointer_append(ep, sizeof ep, "", "errors");
	prsm_json_pointer_append(op, sizeof op, "", "assembly");
	/* the error set's shape (Z rollers, n starts) and the lead need the design; when it is
	 * invalid the rest is still checked against an unknown one, all problems at once */
	prsm_design unknown;
	prsm_design_init(&unknown);
	unknown.rollers = unknown.starts = 0;
	const prsm_design *shape = rc == 0 ? &rq->d : &unknown;
	prsm_io_errors_from_json(&rq->errors, errors, ep, shape, problems);
	prsm_io_assembly_options_from_json(&rq->options, opts, op, shape, problems);
	read_dynamics(rq, doc, 1, problems);
	if (rc == 0 && (problems->count || problems->dropped))
		rc = PRSM_EINVAL;
	return rc;
}

/* A failure of the operating-point analysis as a problem at the setting's pointer. */
static int performance_problem(prsm_problems *problems, const char *base, int rc, const prsm_error *err)
{
	char ptr[2 * PRSM_JSON_POINTER_MAX];
	snprintf(ptr, sizeof ptr, "%s%s", base, err->pointer);
	prsm_problems_add(problems, ptr, rc == PRSM_ENOCONVERGE ? "no_convergence" : "invalid_setting",
	                  "%s", err->message);
	return rc;
}

static int load_multistage(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                           prsm_problems *problems)
{
	rq->multistage = 1;
	rq->ms = calloc(1, sizeof *rq->ms);
	if (rq->ms == NULL)
		return PRSM_ENOMEM;
	int rc = prsm_io_multistage_load(rq->ms, doc, warnings, problems);
	/* the dynamics object, checked for the stages the document has, valid or not */
	int K = rq->ms->stages;
	if (K < 1) {
		const int n = cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(doc, "stages"));
		K = n < 1 ? 1 : n > PRSM_STAGES_MAX ? PRSM_STAGES_MAX : n;
	}
	read_dynamics(rq, doc, K, problems);
	if (rq->with_dynamics) {
		const prsm_chain_input *in = &rq->ms->chain_input;
		rq->dyn.couplings.spline_friction = in->spline_friction;
		rq->dyn.couplings.thrust_bearing_friction = in->thrust_bearing_friction;
		for (int k = 1; k < rq->ms->stages; k++) {
			rq->dyn.couplings.spline_radius_mm[k] = in->spline_radius_mm[k];
			rq->dyn.couplings.thrust_radius_mm[k] = in->thrust_radius_mm[k];
		}
		if (rc == 0 && (problems->count || problems->dropped))
			rc = PRSM_EINVAL;
	}
	prsm_error err = PRSM_ERROR_INIT;
	for (int k = 0; rc == 0 && k < rq->ms->stages; k++) {
		rc = prsm_performance_compute(&rq->ms_perf[k], &rq->ms->design[k], &rq->ms->analysis[k], &err);
		if (rc) {
			char base[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(base, sizeof base, "/stages", k);
			return performance_problem(problems, base, rc, &err);
		}
	}
	return rc;
}

/* The contact-ellipse truncation of a side as warnings (model/rating.h, MODEL.md §6 static
 * capacity): at the operating load, and at the pressure-limited C_0a (which it then limits). */
static void truncation_warnings(prsm_problems *warnings, const char *base, const prsm_performance *p,
                                double p_allow_MPa, int nominal)
{
	static const char *const edges[2][4] = {{"screw crest", "screw root", "roller crest", "roller root"},
	                                        {"nut crest", "nut root", "roller crest", "roller root"}};
	const prsm_truncation_check *tc[2] = {&p->truncation_screw, &p->truncation_nut};
	const char *side[2] = {"screw-roller", "nut-roller"};
	char ptr[PRSM_JSON_POINTER_MAX];
	for (int s = 0; s < 2; s++) {
		const prsm_truncation *t = &tc[s]->t;
		const char *edge = edges[s][t->edge];
		if (tc[s]->truncated_operating) {
			snprintf(ptr, sizeof ptr, "%s/operating_point/axial_load_N", base);
			prsm_problems_add(warnings, ptr, "ellipse_truncation",
			                  "at this load the %s contact ellipse (semi-axis %.3g mm along the flank) "
			                  "runs over the %s %.3g mm away: the contact is truncated, its stresses "
			                  "exceed Hertz's", side[s], tc[s]->operating_axis_mm, edge, t->margin_mm);
		}
		if (tc[s]->truncated_at_C0a) {
			/* the pitch sets the flank length: the field the user wrote it with */
			snprintf(ptr, sizeof ptr, "%s%s", base, nominal ? "/nominal/lead_mm" : "/geometry/pitch_mm");
			prsm_problems_add(warnings, ptr, "ellipse_truncation",
			                  "%s contact ellipse reaches the %s (%.3g mm away) at p_max %.0f MPa < "
			                  "p_allow %.0f MPa: truncation limits C_0a to %.4g N (%.4g N at p_allow); "
			                  "a coarser pitch keeps it on the flank", side[s], edge, t->margin_mm,
			                  t->p_limit_MPa, p_allow_MPa, s == 0 ? p->C0a_screw_N : p->C0a_nut_N,
			                  s == 0 ? p->C0a_pressure_screw_N : p->C0a_pressure_nut_N);
		}
	}
}

/* A document of another kind, told by its keys (as `prsm validate` tells them apart): the
 * command that runs it, instead of a list of unknown fields. Returns 1 when it is one. */
static int wrong_kind(const cJSON *doc, prsm_problems *problems)
{
	static const struct {
		const char *key, *also, *kind, *command, *route;
	} kinds[] = {
		{"allocate", NULL, "a tolerance allocation", "prsm allocate", "POST /v1/allocations"},
		{"variables", "objectives", "a design optimisation", "prsm optimize", "POST /v1/optimizations"},
		{"tolerances", NULL, "a tolerance study", "prsm study", "POST /v1/studies"},
		{"monte_carlo", NULL, "a tolerance study", "prsm study", "POST /v1/studies"},
	};
	if (!cJSON_IsObject(doc))
		return 0;
	for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
		if (cJSON_GetObjectItemCaseSensitive(doc, kinds[i].key) &&
		    (!kinds[i].also || cJSON_GetObjectItemCaseSensitive(doc, kinds[i].also))) {
			prsm_problems_add(problems, "", "wrong_kind",
			                  "this is %s (it has `%s`), not a design: run it with `%s FILE` (%s)",
			                  kinds[i].kind, kinds[i].key, kinds[i].command, kinds[i].route);
			return 1;
		}
	return 0;
}

int prsm_io_analyze_load(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                         prsm_problems *problems)
{
	memset(rq, 0, sizeof *rq);
	if (wrong_kind(doc, problems))
		return PRSM_EINVAL;
	if (prsm_io_is_multistage(doc))
		return load_multistage(rq, doc, warnings, problems);
	prsm_geometry g;
	int rc = load_document(rq, &g, warnings, problems, doc);
	if (rc)
		return rc;
	prsm_error err = PRSM_ERROR_INIT;
	rc = prsm_analysis_nominal(&rq->a, &rq->d, warnings, &err);
	if (rc == 0 && rq->with_errors)
		rc = prsm_assembly_init(&rq->as, &rq->d, &rq->a, &err);
	if (rc == 0) {
		rc = prsm_performance_compute(&rq->perf, &rq->d, &rq->a, &err);
		if (rc)
			return performance_problem(problems, rq->with_errors ? "/design" : "", rc, &err);
		if (warnings)
			truncation_warnings(warnings, rq->with_errors ? "/design" : "", &rq->perf,
			                    rq->d.life.p_allow_MPa, rq->with_nominal);
		return 0;
	}
	/* only the contact solver can tell that the contacts lie on their flanks */
	char ptr[PRSM_JSON_POINTER_MAX + 8];
	snprintf(ptr, sizeof ptr, "%s%s", rq->with_errors ? "/design" : "", err.pointer);
	prsm_problems_add(problems, ptr,
	                  rc == PRSM_EEDGE ? "edge_contact" : rc == PRSM_EINVAL ? "too_large" : "no_contact",
	                  "%s", err.message);
	return rc;
}

int prsm_io_analyze_run(prsm_analyze_request *rq)
{
	if (!rq->with_errors)
		return 0;
	int n, m;
	prsm_assembly_record_length(&n, &m, &rq->as, &rq->options);
	rq->ws = calloc(1, sizeof *rq->ws);
	if (rq->ws == NULL)
		return PRSM_ENOMEM;
	rq->ws->te_mm = calloc((size_t)n, sizeof(double));
	rq->ws->spectrum_mm = calloc((size_t)m, sizeof(double));
	if (rq->ws->te_mm == NULL || rq->ws->spectrum_mm == NULL)
		return PRSM_ENOMEM;
	return prsm_assembly_analyse(&rq->report, &rq->as, &rq->errors, &rq->options, rq->ws);
}

double prsm_io_analyze_cost(const prsm_analyze_request *rq)
{
	if (rq->multistage)
		return 0.0; /* the operating-point analysis of each stage: no record */
	return rq->with_errors ? prsm_assembly_cost(&rq->as, &rq->options) : 0.0;
}

cJSON *prsm_io_analyze_to_json(const prsm_analyze_request *rq, const prsm_problems *warnings_in)
{
	prsm_problems with_note;
	const prsm_problems *warnings = warnings_in;
	if (rq->with_dynamics) {
		if (warnings_in)
			with_note = *warnings_in;
		else
			prsm_problems_init(&with_note);
		prsm_problems_add(&with_note, "/dynamics", "not_simulated",
		                  "the analysis is the statics: the transient of `dynamics` is run by prsm simulate "
		                  "(POST /v1/simulations)");
		warnings = &with_note;
	}
	if (rq->multistage)
		return prsm_io_multistage_to_json(rq->ms, rq->ms_perf, warnings);
	cJSON *res = prsm_io_analysis_to_json(&rq->a, &rq->d, &rq->perf, warnings);
	if (res == NULL)
		return NULL;
	if (rq->with_nominal) {
		prsm_jw w = PRSM_JW_INIT;
		cJSON *nominal = prsm_jw_root(&w);
		prsm_io_write_fields(&w, nominal, &rq->nominal, &prsm_io_w_nominal_result, 0);
		nominal = prsm_jw_done(&w, nominal);
		if (nominal == NULL) {
			cJSON_Delete(res);
			return NULL;
		}
		cJSON_AddItemToObject(res, "nominal", nominal);
	}
	if (rq->with_errors) {
		cJSON_AddItemToObject(res, "errors", prsm_io_errors_to_json(&rq->errors, rq->d.starts));
		cJSON_AddItemToObject(res, "assembly",
		                      prsm_io_assembly_to_json(&rq->report, &rq->as, &rq->options, rq->ws));
	}
	return res;
}

void prsm_io_analyze_free(prsm_analyze_request *rq)
{
	prsm_performance_free(&rq->perf);
	for (int k = 0; k < PRSM_STAGES_MAX; k++)
		prsm_performance_free(&rq->ms_perf[k]);
	free(rq->ms);
	rq->ms = NULL;
	if (rq->ws) {
		free(rq->ws->te_mm);
		free(rq->ws->spectrum_mm);
		free(rq->ws);
		rq->ws = NULL;
	}
}

int prsm_io_analyze(cJSON **out, const cJSON *doc, prsm_problems *problems)
{
	*out = NULL;
	prsm_analyze_request *rq = calloc(1, sizeof *rq);
	if (rq == NULL)
		return PRSM_ENOMEM;
	prsm_problems warnings;
	prsm_problems_init(&warnings);
	int rc = prsm_io_analyze_load(rq, doc, &warnings, problems);
	if (rc == 0)
		rc = prsm_io_analyze_run(rq);
	if (rc == 0) {
		*out = prsm_io_analyze_to_json(rq, &warnings);
		if (*out == NULL)
			rc = PRSM_ENOMEM;
	}
	prsm_io_analyze_free(rq);
	free(rq);
	return rc;
}
