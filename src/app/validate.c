/*
 * validate.c: any request read as its command reads it (see validate.h).
 */
#include "app/validate.h"

#include <stdlib.h>
#include <string.h>

#include "app/allocate.h"
#include "app/calibrate.h"
#include "app/optimize.h"
#include "app/simulate.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/write.h"
#include "app/study.h"
#include "io/study_json.h"
#include "util/error.h"

static const cJSON *member(const cJSON *o, const char *key)
{
	return cJSON_IsObject(o) ? cJSON_GetObjectItemCaseSensitive(o, key) : NULL;
}

prsm_doc_kind prsm_app_doc_kind(const cJSON *doc, int csv_given)
{
	if (!cJSON_IsObject(doc))
		return csv_given ? PRSM_DOC_CALIBRATION : PRSM_DOC_DESIGN;
	if (member(doc, "allocate"))
		return PRSM_DOC_ALLOCATION;
	if (member(doc, "variables") && member(doc, "objectives"))
		return PRSM_DOC_OPTIMIZATION;
	if (member(doc, "tolerances"))
		return PRSM_DOC_STUDY;
	const cJSON *an = member(member(doc, "dynamics"), "analysis");
	if (csv_given || member(doc, "measured") || (cJSON_IsString(an) && strcmp(an->valuestring, "calibrate") == 0))
		return PRSM_DOC_CALIBRATION;
	if (member(doc, "dynamics"))
		return PRSM_DOC_SIMULATION;
	return PRSM_DOC_DESIGN;
}

const char *prsm_app_doc_kind_name(prsm_doc_kind k)
{
	switch (k) {
	case PRSM_DOC_DESIGN: return "design";
	case PRSM_DOC_STUDY: return "study";
	case PRSM_DOC_OPTIMIZATION: return "optimization";
	case PRSM_DOC_ALLOCATION: return "allocation";
	case PRSM_DOC_SIMULATION: return "simulation";
	case PRSM_DOC_CALIBRATION: return "calibration";
	}
	return "design";
}

static int validate_study(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_io_study *s = calloc(1, sizeof *s); /* large: on the heap */
	if (!s)
		return PRSM_ENOMEM;
	int rc = prsm_app_study_load(s, doc, warnings, problems);
	free(s);
	return rc;
}

static int validate_calibration(const cJSON *doc, const char *csv_path, prsm_problems *warnings,
                                prsm_problems *problems)
{
	prsm_app_calibration *c = NULL;
	int rc = prsm_app_calibration_load(&c, doc, csv_path, problems);
	if (rc == 0) {
		const prsm_problems *w = &prsm_app_calibration_data(c)->warnings;
		for (int i = 0; i < w->count; i++)
			prsm_problems_add(warnings, w->items[i].pointer, w->items[i].code, "%s", w->items[i].message);
		prsm_app_calibration_free(c);
	}
	return rc;
}

static int validate_design(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_analyze_request *rq = calloc(1, sizeof *rq); /* large: on the heap */
	if (!rq)
		return PRSM_ENOMEM;
	int rc = prsm_app_analyze_load(rq, doc, warnings, problems);
	prsm_io_analyze_free(rq);
	free(rq);
	return rc;
}

int prsm_app_validate(const cJSON *doc, const char *csv_path, prsm_doc_kind *kind, prsm_problems *warnings,
                      prsm_problems *problems)
{
	const prsm_doc_kind k = prsm_app_doc_kind(doc, csv_path != NULL);
	if (kind)
		*kind = k;
	switch (k) {
	case PRSM_DOC_ALLOCATION: return prsm_app_allocation_check(doc, 0, warnings, problems);
	case PRSM_DOC_OPTIMIZATION: return prsm_app_optimization_check(doc, 0, warnings, problems);
	case PRSM_DOC_STUDY: return validate_study(doc, warnings, problems);
	case PRSM_DOC_CALIBRATION: return validate_calibration(doc, csv_path, warnings, problems);
	case PRSM_DOC_SIMULATION: return prsm_app_simulation_check(doc, warnings, problems);
	case PRSM_DOC_DESIGN: break;
	}
	return validate_design(doc, warnings, problems);
}

cJSON *prsm_app_validation_to_json(int rc, prsm_doc_kind kind, const prsm_problems *warnings,
                                   const prsm_problems *problems)
{
	cJSON *res = cJSON_CreateObject();
	if (res == NULL)
		return NULL;
	prsm_problems why; /* an invalid read names at least one problem */
	if (rc != 0 && prsm_problems_total(problems) == 0) {
		prsm_problems_init(&why);
		prsm_problems_add(&why, "", "invalid", "the document cannot be read (%s)", prsm_error_name(rc));
		problems = &why;
	}
	prsm_jw w = PRSM_JW_INIT;
	prsm_jw_bool(&w, res, "valid", rc == 0);
	prsm_jw_string(&w, res, "read_as", prsm_app_doc_kind_name(kind));
	prsm_io_whook_problems(&w, res, "errors", problems);
	prsm_io_whook_problems(&w, res, "warnings", warnings);
	return prsm_jw_done(&w, res);
}
