/*
 * analyze_request.c: the analyze request from JSON, and its result to JSON
 * (docs/model/geometry-and-meshing.md–§6), for the CLI and the service alike; the analysis
 * between the two is app/analyze.c's.
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

cJSON *prsm_io_nominal_expanded(const cJSON *design, const prsm_nominal_geometry *g)
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
		nominal->beta_rad = beta;
		nominal->clearance_mm = clearance;
	}
	cJSON *expanded = prsm_io_nominal_expanded(design, &g);
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
		prsm_io_dynamics_read(&rq->dyn, NULL, dyn, stages, problems);
}

int prsm_io_analyze_read(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                         prsm_problems *problems)
{
	int rc;
	prsm_geometry geometry, *g = &geometry;
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

int prsm_io_analyze_read_chain_dynamics(prsm_analyze_request *rq, const cJSON *doc, int rc,
                                        prsm_problems *problems)
{
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
	return rc;
}

int prsm_io_analyze_wrong_kind(const cJSON *doc, prsm_problems *problems)
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
