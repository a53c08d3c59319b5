/*
 * analyze_request.c: the analyze request from JSON to its result (docs/model/geometry-and-meshing.md–§6), for the CLI
 * and the service alike.
 */
#include "io/analyze_request.h"

#include <stdlib.h>
#include <string.h>

#include "io/analysis_json.h"
#include "io/assembly_json.h"
#include "io/design_json.h"
#include "io/dynamics_json.h"
#include "io/errors_json.h"
#include "io/json_util.h"
#include "util/error.h"

static const char *const request_keys[] = {"design", "errors", "assembly", "dynamics", NULL};

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
	if (!rq->with_errors)
		return prsm_io_design_load(&rq->d, g, warnings, doc, "", problems);
	prsm_json_check_keys(doc, "", request_keys, problems);
	const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
	rc = prsm_io_design_load(&rq->d, g, warnings, design, "/design", problems);
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

int prsm_io_analyze_load(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                         prsm_problems *problems)
{
	memset(rq, 0, sizeof *rq);
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
		return rc ? performance_problem(problems, rq->with_errors ? "/design" : "", rc, &err) : 0;
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
