/*
 * simulate.c: reading, modelling, integrating and writing a simulation request (see
 * simulate.h; docs/dynamics.md).
 */
#include "app/simulate.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/analyze_request.h"
#include "io/dynamics_json.h"
#include "io/json_util.h"
#include "util/clock.h"

struct prsm_app_simulation {
	prsm_analyze_request rq;      /* the design(s), their statics and the dynamics options */
	prsm_problems warnings;       /* the designs' rule warnings */
	char name[256];               /* the design's (or the chain's) name, "" when none */
	prsm_dyn_model *model;
	prsm_dyn_result result;
	int ran;                      /* result holds a finished run */
};

static const char *const form_message =
	"a simulation request is {\"design\": {...}, \"dynamics\": {...}} or a multi-stage design "
	"{\"stages\": [...], \"dynamics\": {...}} (schemas/simulation.schema.json)";

/* The request's form; problems at their pointers. */
static void check_form(const cJSON *doc, prsm_problems *problems)
{
	const int chain = cJSON_GetObjectItemCaseSensitive(doc, "stages") != NULL;
	if (!chain && cJSON_GetObjectItemCaseSensitive(doc, "design") == NULL) {
		prsm_problems_add(problems, "", "form", "%s", form_message);
		return;
	}
	if (cJSON_GetObjectItemCaseSensitive(doc, "dynamics") == NULL)
		prsm_problems_add(problems, "/dynamics", "required",
		                  "a simulation needs the dynamics object (schemas/dynamics.schema.json; "
		                  "{\"analysis\": \"transient\"} runs every default)");
	static const char *const no[] = {"errors", "assembly"};
	for (int i = 0; !chain && i < 2; i++)
		if (cJSON_GetObjectItemCaseSensitive(doc, no[i]) != NULL) {
			char ptr[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(ptr, sizeof ptr, "", no[i]);
			prsm_problems_add(problems, ptr, "not_simulated",
			                  "the rigid-body transient has no part errors: run the error analysis with "
			                  "prsm analyze, the transient without `%s`", no[i]);
		}
}

static void copy_name(char *out, size_t cap, const cJSON *doc)
{
	const cJSON *d = cJSON_GetObjectItemCaseSensitive(doc, "design");
	const cJSON *n = cJSON_GetObjectItemCaseSensitive(d ? d : doc, "name");
	out[0] = '\0';
	if (cJSON_IsString(n))
		prsm_json_excerpt(out, cap, n->valuestring);
}

/* A failure of the model as a problem at its field: a single design's fields are under /design. */
static int model_problem(prsm_problems *problems, int chain, int rc, const prsm_error *err)
{
	char ptr[2 * PRSM_JSON_POINTER_MAX];
	const char *p = err->pointer;
	const int ours = strncmp(p, "/dynamics", 9) == 0 || strncmp(p, "/couplings", 10) == 0 || strncmp(p, "/stages", 7) == 0;
	snprintf(ptr, sizeof ptr, "%s%s", chain || ours || p[0] == '\0' ? "" : "/design", p);
	prsm_problems_add(problems, ptr,
	                  rc == PRSM_ENOCONVERGE ? "no_convergence" : rc == PRSM_EGEOMETRY ? "geometry" : "model",
	                  "%s", err->message);
	return rc;
}

int prsm_app_simulation_load(prsm_app_simulation **out, const cJSON *doc, prsm_problems *warnings,
                             prsm_problems *problems)
{
	*out = NULL;
	if (!cJSON_IsObject(doc)) {
		prsm_problems_add(problems, "", "type", "%s", form_message);
		return PRSM_EINVAL;
	}
	const int before = prsm_problems_total(problems);
	check_form(doc, problems);
	if (prsm_problems_total(problems) > before && cJSON_GetObjectItemCaseSensitive(doc, "stages") == NULL &&
	    cJSON_GetObjectItemCaseSensitive(doc, "design") == NULL)
		return PRSM_EINVAL; /* not the form: a plain design's problems would only confuse */
	prsm_app_simulation *s = calloc(1, sizeof *s); /* handed to the caller on success */
	if (s == NULL)
		return PRSM_ENOMEM;
	prsm_problems_init(&s->warnings);
	copy_name(s->name, sizeof s->name, doc);
	int rc = prsm_io_analyze_load(&s->rq, doc, &s->warnings, problems);
	if (rc == 0 && prsm_problems_total(problems) > before)
		rc = PRSM_EINVAL;
	if (rc == 0) {
		const int chain = s->rq.multistage;
		const int K = chain ? s->rq.ms->stages : 1;
		const prsm_design *d = chain ? s->rq.ms->design : &s->rq.d;
		const prsm_analysis *a = chain ? s->rq.ms->analysis : &s->rq.a;
		prsm_error err = PRSM_ERROR_INIT;
		rc = prsm_dyn_model_new(&s->model, K, d, a, &s->rq.dyn, &err);
		if (rc)
			model_problem(problems, chain, rc, &err);
	}
	if (warnings)
		for (int i = 0; i < s->warnings.count; i++)
			prsm_problems_add(warnings, s->warnings.items[i].pointer, s->warnings.items[i].code, "%s",
			                  s->warnings.items[i].message);
	if (rc) {
		prsm_app_simulation_free(s);
		return rc;
	}
	*out = s;
	return 0;
}

size_t prsm_app_simulation_points(const prsm_app_simulation *s)
{
	/* 0, step, 2 step, ... and the end (as dyn/ lays them out) */
	const prsm_dyn_time *t = &s->rq.dyn.time;
	const double q = floor(t->end_s / t->output_step_s * (1.0 + 1e-12));
	if (!(q < 2.0 * PRSM_DYN_OUTPUT_POINTS_MAX))
		return (size_t)2 * PRSM_DYN_OUTPUT_POINTS_MAX;
	size_t n = (size_t)q + 1;
	if ((double)(n - 1) * t->output_step_s < t->end_s * (1.0 - 1e-12))
		n++;
	return n;
}

/* The time cap and the caller's cancel flag, looked at with each progress report. */
typedef struct {
	const prsm_cancel_flag *cancel;
	prsm_cancel_flag stop;
	double deadline_s;
	int timed_out;
	prsm_progress_fn progress;
	void *ctx;
} watch;

static void watch_progress(void *ctx, const prsm_progress *p)
{
	watch *wt = ctx;
	if (wt->progress)
		wt->progress(wt->ctx, p);
	if (prsm_cancel_requested(wt->cancel)) {
		prsm_cancel_set(&wt->stop, 1);
	} else if (prsm_clock_seconds() > wt->deadline_s) {
		wt->timed_out = 1;
		prsm_cancel_set(&wt->stop, 1);
	}
}

int prsm_app_simulation_run(prsm_app_simulation *s, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                            void *progress_ctx, double max_time_s, prsm_error *err)
{
	if (s->ran) {
		prsm_dyn_result_free(&s->result);
		s->ran = 0;
	}
	int rc;
	if (max_time_s > 0.0) {
		watch wt = {cancel, 0, prsm_clock_seconds() + max_time_s, 0, progress, progress_ctx};
		rc = prsm_dyn_simulate(&s->result, s->model, &wt.stop, watch_progress, &wt, err);
		if (rc == PRSM_ECANCELLED && wt.timed_out) {
			char where[sizeof err->message];
			snprintf(where, sizeof where, "%s", err->message);
			rc = prsm_error_set(err, PRSM_ECANCELLED, "/dynamics/time/end_s",
			                    "the simulation took longer than the time cap of %g s (%s)", max_time_s, where);
		}
	} else {
		rc = prsm_dyn_simulate(&s->result, s->model, cancel, progress, progress_ctx, err);
	}
	s->ran = rc == 0;
	return rc;
}

cJSON *prsm_app_simulation_result(const prsm_app_simulation *s)
{
	if (!s->ran)
		return NULL;
	return prsm_io_dynamics_result_to_json(s->name, s->model, &s->result, &s->warnings);
}

int prsm_app_simulation_csv(FILE *f, const prsm_app_simulation *s)
{
	return s->ran ? prsm_io_dynamics_write_csv(f, s->model, &s->result) : PRSM_EINVAL;
}

int prsm_app_simulation_text(FILE *f, const prsm_app_simulation *s)
{
	return s->ran ? prsm_io_dynamics_write_text(f, s->model, &s->result, &s->warnings) : PRSM_EINVAL;
}

const prsm_dyn_model *prsm_app_simulation_model(const prsm_app_simulation *s)
{
	return s->model;
}

const prsm_dyn_result *prsm_app_simulation_dyn_result(const prsm_app_simulation *s)
{
	return s->ran ? &s->result : NULL;
}

void prsm_app_simulation_free(prsm_app_simulation *s)
{
	if (s == NULL)
		return;
	if (s->ran)
		prsm_dyn_result_free(&s->result);
	prsm_dyn_model_free(s->model);
	prsm_io_analyze_free(&s->rq);
	free(s);
}

int prsm_app_simulation_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_app_simulation *s;
	const int rc = prsm_app_simulation_load(&s, doc, warnings, problems);
	prsm_app_simulation_free(s);
	return rc;
}

int prsm_app_simulate(cJSON **result, const cJSON *doc, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                      void *progress_ctx, double max_time_s, prsm_problems *problems, prsm_error *err)
{
	*result = NULL;
	prsm_app_simulation *s;
	int rc = prsm_app_simulation_load(&s, doc, NULL, problems);
	if (rc)
		return problems->count ? prsm_error_set(err, rc, problems->items[0].pointer, "%s", problems->items[0].message)
		                       : prsm_error_set(err, rc, NULL, "the request could not be loaded");
	rc = prsm_app_simulation_run(s, cancel, progress, progress_ctx, max_time_s, err);
	if (rc == 0) {
		*result = prsm_app_simulation_result(s);
		if (*result == NULL)
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory writing the result");
	}
	prsm_app_simulation_free(s);
	return rc;
}
