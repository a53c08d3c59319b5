/*
 * simulate.c: reading, modelling, integrating and writing a simulation request (see
 * simulate.h; docs/dynamics.md): the transient here, the vibration analyses through
 * app/vibrate.h (docs/vibration.md).
 */
#include "app/simulate.h"
#include "app/text.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/vibrate.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/dynamics_json.h"
#include "io/json_util.h"
#include "util/clock.h"

struct prsm_app_simulation {
	prsm_analyze_request rq;      /* the design(s), their statics and the dynamics options */
	prsm_problems warnings;       /* the designs' rule warnings */
	char name[256];               /* the design's (or the chain's) name, "" when none */
	int analysis;                 /* PRSM_IO_DYN_* */
	int gear_pair;                /* the request without a design: the 1-DOF gear pair */
	int threads;                  /* engine threads of the vibration analyses (1) */
	prsm_app_vibration *vib;      /* analysis other than transient: its model and run */
	prsm_dyn_model *model;        /* transient */
	prsm_dyn_result result;
	int ran;                      /* result holds a finished run */
};

static const char *const form_message =
	"a simulation request is {\"design\": {...}, \"dynamics\": {...}}, a multi-stage design "
	"{\"stages\": [...], \"dynamics\": {...}} or a gear pair {\"dynamics\": {\"analysis\": ..., "
	"\"gear_pair\": {...}}} (schemas/simulation.schema.json)";

static const cJSON *item(const cJSON *o, const char *key)
{
	return cJSON_IsObject(o) ? cJSON_GetObjectItemCaseSensitive(o, key) : NULL;
}

/* The analysis the dynamics object names (PRSM_IO_DYN_TRANSIENT when absent or unknown), and
 * whether its TE lines come from an error set. */
static int peek_analysis(const cJSON *doc, int *te_statics)
{
	const cJSON *dyn = item(doc, "dynamics"), *a = item(dyn, "analysis");
	const cJSON *te = item(item(dyn, "vibration"), "te_lines");
	*te_statics = cJSON_IsString(te) && strcmp(te->valuestring, "statics") == 0;
	if (!cJSON_IsString(a))
		return PRSM_IO_DYN_TRANSIENT;
	for (int i = 0; i < PRSM_IO_DYN_ANALYSES; i++)
		if (strcmp(a->valuestring, prsm_io_dynamics_analysis_name(i)) == 0)
			return i;
	return PRSM_IO_DYN_TRANSIENT;
}

/* The request's form; problems at their pointers. */
static void check_form(const cJSON *doc, prsm_problems *problems)
{
	const int chain = cJSON_GetObjectItemCaseSensitive(doc, "stages") != NULL;
	const int design = cJSON_GetObjectItemCaseSensitive(doc, "design") != NULL;
	if (!chain && !design) {
		if (cJSON_GetObjectItemCaseSensitive(doc, "dynamics") == NULL) {
			prsm_problems_add(problems, "", "form", "%s", form_message);
			return;
		}
		/* the gear pair: its dynamics object and a name */
		static const char *const keys[] = {"dynamics", "name", NULL};
		prsm_json_check_keys(doc, "", keys, problems);
		const cJSON *n = cJSON_GetObjectItemCaseSensitive(doc, "name");
		const char *s;
		if (n != NULL)
			prsm_json_string_value(&s, n, "/name", 200, problems);
		return;
	}
	if (cJSON_GetObjectItemCaseSensitive(doc, "dynamics") == NULL)
		prsm_problems_add(problems, "/dynamics", "required",
		                  "a simulation needs the dynamics object (schemas/dynamics.schema.json; "
		                  "{\"analysis\": \"transient\"} runs every default)");
	int te_statics = 0;
	const int analysis = peek_analysis(doc, &te_statics);
	const int with_errors = analysis != PRSM_IO_DYN_TRANSIENT && te_statics;
	static const char *const no[] = {"errors", "assembly"};
	for (int i = 0; !chain && i < 2; i++) {
		char ptr[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(ptr, sizeof ptr, "", no[i]);
		const int has = cJSON_GetObjectItemCaseSensitive(doc, no[i]) != NULL;
		if (has && !with_errors)
			prsm_problems_add(problems, ptr, "not_simulated",
			                  analysis == PRSM_IO_DYN_TRANSIENT
			                      ? "the rigid-body transient has no part errors: run the error analysis with "
			                        "prsm analyze, the transient without `%s`"
			                      : "the vibration model takes part errors only as the TE lines of "
			                        "vibration.te_lines \"statics\": without them, leave out `%s`",
			                  no[i]);
		if (!has && with_errors && i == 0)
			prsm_problems_add(problems, ptr, "required",
			                  "vibration.te_lines \"statics\" fits the TE lines to the statics TE of the error set "
			                  "`errors` (analyze-request.schema.json)");
	}
}

static void copy_name(char *out, size_t cap, const cJSON *doc)
{
	const cJSON *d = cJSON_GetObjectItemCaseSensitive(doc, "design");
	const cJSON *n = cJSON_GetObjectItemCaseSensitive(d && cJSON_IsObject(d) ? d : doc, "name");
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

/* The vibration analyses' request (the dynamics object read again: its problems were reported
 * with the document's) and model. */
static int load_vibration(prsm_app_simulation *s, const cJSON *doc, int stages, prsm_problems *problems)
{
	prsm_io_vib_request *q = malloc(sizeof *q);
	prsm_dyn_options *dyn = malloc(sizeof *dyn);
	prsm_problems *again = malloc(sizeof *again);
	int rc = PRSM_ENOMEM;
	if (q && dyn && again) {
		prsm_problems_init(again);
		rc = prsm_io_dynamics_read(dyn, q, item(doc, "dynamics"), stages, again);
		if (rc && stages == 0) /* the gear pair's form: these are its only problems */
			for (int i = 0; i < again->count; i++)
				prsm_problems_add(problems, again->items[i].pointer, again->items[i].code, "%s",
				                  again->items[i].message);
		else if (rc && problems->count == 0)
			prsm_problems_add(problems, again->count ? again->items[0].pointer : "/dynamics", "model", "%s",
			                  again->count ? again->items[0].message : "the dynamics object is invalid");
	}
	if (rc == 0) {
		s->analysis = q->analysis;
		if (s->analysis != PRSM_IO_DYN_TRANSIENT)
			rc = prsm_app_vibration_new(&s->vib, q, stages ? &s->rq.d : NULL, stages ? &s->rq.a : NULL,
			                            stages ? &s->rq.dyn : dyn, &s->rq.errors, &s->rq.options, problems);
	}
	free(q);
	free(dyn);
	free(again);
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
	const int chain = cJSON_GetObjectItemCaseSensitive(doc, "stages") != NULL;
	const int design = cJSON_GetObjectItemCaseSensitive(doc, "design") != NULL;
	const int gear_pair = !chain && !design && cJSON_GetObjectItemCaseSensitive(doc, "dynamics") != NULL;
	if (prsm_problems_total(problems) > before && !chain && !design && !gear_pair)
		return PRSM_EINVAL; /* not the form: a plain design's problems would only confuse */
	prsm_app_simulation *s = calloc(1, sizeof *s); /* handed to the caller on success */
	if (s == NULL)
		return PRSM_ENOMEM;
	prsm_problems_init(&s->warnings);
	s->threads = 1;
	s->gear_pair = gear_pair;
	copy_name(s->name, sizeof s->name, doc);
	int rc;
	if (gear_pair) {
		rc = load_vibration(s, doc, 0, problems);
		if (rc == 0 && prsm_problems_total(problems) > before)
			rc = PRSM_EINVAL;
	} else {
		rc = prsm_app_analyze_load(&s->rq, doc, &s->warnings, problems);
		if (rc == 0 && prsm_problems_total(problems) > before)
			rc = PRSM_EINVAL;
		const int K = s->rq.multistage ? s->rq.ms->stages : 1;
		if (rc == 0)
			rc = load_vibration(s, doc, K, problems);
		if (rc == 0 && s->analysis == PRSM_IO_DYN_TRANSIENT) {
			const prsm_design *d = chain ? s->rq.ms->design : &s->rq.d;
			const prsm_analysis *a = chain ? s->rq.ms->analysis : &s->rq.a;
			prsm_error err = PRSM_ERROR_INIT;
			rc = prsm_dyn_model_new(&s->model, K, d, a, &s->rq.dyn, &err);
			if (rc)
				model_problem(problems, chain, rc, &err);
		}
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

int prsm_app_simulation_analysis(const prsm_app_simulation *s)
{
	return s->analysis;
}

int prsm_app_simulation_set_split(prsm_app_simulation *s, const prsm_vib_split *split)
{
	return s->vib != NULL && prsm_app_vibration_set_split(s->vib, split);
}

void prsm_app_simulation_set_threads(prsm_app_simulation *s, int threads)
{
	s->threads = threads < 1 ? 1 : threads > 256 ? 256 : threads;
}

size_t prsm_app_simulation_work(const prsm_app_simulation *s, const char **unit)
{
	if (s->vib != NULL) {
		if (unit)
			*unit = prsm_app_vibration_work_unit(s->vib);
		return prsm_app_vibration_work(s->vib);
	}
	if (unit)
		*unit = "simulated_ns";
	return (size_t)(s->rq.dyn.time.end_s * 1e9 + 0.5);
}

const prsm_app_vibration *prsm_app_simulation_vibration(const prsm_app_simulation *s)
{
	return s->vib;
}

size_t prsm_app_simulation_points(const prsm_app_simulation *s)
{
	if (s->analysis != PRSM_IO_DYN_TRANSIENT)
		return 0;
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

/* The vibration analyses' watchdog: a thread that raises the run's own flag when the caller's
 * flag is raised or the time cap passes (a steady state reports no progress to look at them). */
typedef struct {
	const prsm_cancel_flag *cancel;
	prsm_cancel_flag stop;
	double deadline_s;            /* 0: none */
	atomic_int done, timed_out;
	pthread_mutex_t mu;
	pthread_cond_t cv;
} watchdog;

static void *watchdog_main(void *arg)
{
	watchdog *wd = arg;
	pthread_mutex_lock(&wd->mu);
	while (!atomic_load(&wd->done)) {
		if (prsm_cancel_requested(wd->cancel)) {
			prsm_cancel_set(&wd->stop, 1);
		} else if (wd->deadline_s > 0.0 && prsm_clock_seconds() > wd->deadline_s) {
			atomic_store(&wd->timed_out, 1);
			prsm_cancel_set(&wd->stop, 1);
		}
		struct timespec ts;
		clock_gettime(CLOCK_REALTIME, &ts);
		ts.tv_nsec += 20 * 1000 * 1000; /* 20 ms */
		if (ts.tv_nsec >= 1000000000L) {
			ts.tv_sec++;
			ts.tv_nsec -= 1000000000L;
		}
		pthread_cond_timedwait(&wd->cv, &wd->mu, &ts);
	}
	pthread_mutex_unlock(&wd->mu);
	return NULL;
}

static int run_vibration(prsm_app_simulation *s, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                         void *progress_ctx, double max_time_s, prsm_error *err)
{
	if (max_time_s <= 0.0 && cancel == NULL)
		return prsm_app_vibration_run(s->vib, s->threads, NULL, progress, progress_ctx, err);
	watchdog wd;
	memset(&wd, 0, sizeof wd);
	wd.cancel = cancel;
	atomic_init(&wd.stop, 0);
	atomic_init(&wd.done, 0);
	atomic_init(&wd.timed_out, 0);
	wd.deadline_s = max_time_s > 0.0 ? prsm_clock_seconds() + max_time_s : 0.0;
	pthread_mutex_init(&wd.mu, NULL);
	pthread_cond_init(&wd.cv, NULL);
	pthread_t th;
	const int started = pthread_create(&th, NULL, watchdog_main, &wd) == 0;
	/* without the thread the caller's flag is still polled by the engine */
	int rc = prsm_app_vibration_run(s->vib, s->threads, started ? &wd.stop : cancel, progress, progress_ctx, err);
	if (started) {
		pthread_mutex_lock(&wd.mu);
		atomic_store(&wd.done, 1);
		pthread_cond_signal(&wd.cv);
		pthread_mutex_unlock(&wd.mu);
		pthread_join(th, NULL);
	}
	pthread_cond_destroy(&wd.cv);
	pthread_mutex_destroy(&wd.mu);
	if (rc == PRSM_ECANCELLED && atomic_load(&wd.timed_out))
		rc = prsm_error_set(err, PRSM_ECANCELLED, "/dynamics/analysis",
		                    "the analysis took longer than the time cap of %g s", max_time_s);
	return rc;
}

int prsm_app_simulation_run(prsm_app_simulation *s, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                            void *progress_ctx, double max_time_s, prsm_error *err)
{
	if (s->vib != NULL) {
		const int rc = run_vibration(s, cancel, progress, progress_ctx, max_time_s, err);
		s->ran = rc == 0;
		return rc;
	}
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
	if (s->vib != NULL)
		return prsm_app_vibration_result(s->vib, s->name, &s->warnings);
	return prsm_io_dynamics_result_to_json(s->name, s->model, &s->result, &s->warnings);
}

int prsm_app_simulation_csv(FILE *f, const prsm_app_simulation *s)
{
	if (s->vib != NULL)
		return s->ran ? prsm_app_vibration_csv(f, s->vib) : PRSM_EINVAL;
	return s->ran ? prsm_io_dynamics_write_csv(f, s->model, &s->result) : PRSM_EINVAL;
}

int prsm_app_simulation_text(FILE *f, const prsm_app_simulation *s)
{
	if (s->vib != NULL)
		return s->ran ? prsm_app_vibration_text(f, s->vib, &s->warnings) : PRSM_EINVAL;
	return s->ran ? prsm_app_text_transient(f, s->model, &s->result, &s->warnings) : PRSM_EINVAL;
}

const prsm_dyn_model *prsm_app_simulation_model(const prsm_app_simulation *s)
{
	return s->model;
}

const prsm_dyn_result *prsm_app_simulation_dyn_result(const prsm_app_simulation *s)
{
	return s->ran && s->vib == NULL ? &s->result : NULL;
}

void prsm_app_simulation_free(prsm_app_simulation *s)
{
	if (s == NULL)
		return;
	if (s->ran && s->vib == NULL)
		prsm_dyn_result_free(&s->result);
	prsm_app_vibration_free(s->vib);
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
