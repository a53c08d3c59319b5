/*
 * allocate.c: checking and running an allocation document (see allocate.h).
 */
#include "app/allocate.h"
#include "app/study.h"

#include <stdlib.h>
#include <string.h>

#include "io/allocation_json.h"
#include "util/clock.h"

/* A study's linear model (central differences of its model), then the linear allocation at
 * f = 1 must be possible. Problems at their pointers. */
static int prepare(prsm_io_allocation *d, prsm_problems *pr)
{
	prsm_alloc_model *md = &d->model;
	prsm_error err = PRSM_ERROR_INIT;
	int rc;
	if (d->is_study) {
		prsm_study *st = &d->study->study;
		st->mc.samples = d->samples;
		st->mc.seed = d->seed;
		if (d->threads)
			st->mc.threads = d->threads;
		rc = prsm_alloc_mc_linearise(md, st, &d->opt, &err);
		if (rc) {
			prsm_problems_add(pr, "/study", "model", "%s", err.message);
			return rc == PRSM_ENOMEM ? rc : PRSM_EINVAL;
		}
	}
	prsm_alloc_step *st0 = malloc(sizeof *st0);
	if (!st0)
		return PRSM_ENOMEM;
	rc = prsm_alloc_model_allocate(st0, md, 1.0, NULL, 0.0, &err);
	free(st0);
	if (rc) {
		prsm_problems_add(pr, err.pointer[0] ? err.pointer : "/constraints", "infeasible", "%s", err.message);
		rc = rc == PRSM_ENOMEM ? rc : PRSM_EINVAL;
	}
	return rc;
}

/* Read and prepare; *out NULL unless 0 is returned. */
static int load(prsm_io_allocation **out, const cJSON *doc, size_t max_samples,
                prsm_problems *warnings, prsm_problems *pr)
{
	prsm_io_study_options study;
	prsm_app_study_options(&study);
	int rc = prsm_io_allocation_read(out, doc, max_samples, &study, warnings, pr);
	if (rc == 0 && (rc = prepare(*out, pr)) != 0) {
		prsm_io_allocation_free(*out);
		*out = NULL;
	}
	return rc;
}

int prsm_app_allocation_check(const cJSON *doc, size_t max_samples, prsm_problems *warnings,
                              prsm_problems *problems)
{
	prsm_io_allocation *d;
	int rc = load(&d, doc, max_samples, warnings, problems);
	prsm_io_allocation_free(d);
	return rc;
}

int prsm_app_allocate(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                      prsm_progress_fn progress, void *progress_ctx, double max_time_s, int threads,
                      prsm_problems *problems, prsm_error *err)
{
	return prsm_app_allocate_with(result, doc, cancel, progress, progress_ctx, max_time_s, threads, NULL,
	                              problems, err);
}

int prsm_app_allocate_with(cJSON **result, const cJSON *doc, prsm_cancel_flag *cancel,
                           prsm_progress_fn progress, void *progress_ctx, double max_time_s, int threads,
                           const prsm_study_service *service, prsm_problems *problems, prsm_error *err)
{
	*result = NULL;
	char *source = NULL;
	prsm_io_allocation *d;
	int rc = load(&d, doc, 0, NULL, problems);
	if (rc)
		return prsm_error_set(err, rc, problems->count ? problems->items[0].pointer : NULL, "%s",
		                      rc == PRSM_EINVAL ? "the allocation document is invalid" : "could not load the allocation");
	prsm_alloc_mc_result *r = calloc(1, sizeof *r);
	if (!r) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	d->opt.cancel = cancel;
	d->opt.progress = progress;
	d->opt.progress_ctx = progress_ctx;
	d->opt.max_time_s = max_time_s;
	if (d->is_study) {
		if (threads > 0)
			d->study->study.mc.threads = threads;
		if (service) {
			/* the corrections' studies run elsewhere: the embedded study document goes with them */
			source = cJSON_PrintUnformatted(cJSON_GetObjectItemCaseSensitive(doc, "study"));
			if (!source) {
				rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
				goto cleanup;
			}
			d->opt.service = service;
			d->opt.study_source = source;
			d->opt.study_source_len = strlen(source);
		}
		rc = prsm_alloc_mc_run(r, &d->study->study, &d->model, &d->opt, err);
		if (rc && !(rc == PRSM_ECANCELLED && r->best >= 0))
			goto cleanup;
		if (r->best < 0) { /* prsm_alloc_mc_run promises a step; never read steps[-1] */
			rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "no allocation step finished");
			goto cleanup;
		}
	} else {
		double t0 = prsm_clock_seconds();
		if (prsm_cancel_requested(cancel)) {
			rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the allocation was cancelled");
			goto cleanup;
		}
		rc = prsm_alloc_model_allocate(&r->steps[0], &d->model, 1.0, cancel, max_time_s, err);
		if (rc)
			goto cleanup;
		r->n_steps = 1;
		r->best = 0;
		r->stop = PRSM_ALLOC_STOP_LINEAR;
		r->converged = r->steps[0].meets;
		r->elapsed_s = prsm_clock_seconds() - t0;
		if (progress) {
			prsm_progress p = PRSM_PROGRESS_INIT;
			p.done = p.planned = r->steps[0].sol.evaluations;
			p.best = r->steps[0].sol.total_cost;
			progress(progress_ctx, &p);
		}
	}
	*result = prsm_io_allocation_result_json(d, r, rc == PRSM_ECANCELLED);
	if (!*result)
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
cleanup:
	cJSON_free(source);
	free(r);
	prsm_io_allocation_free(d);
	return rc;
}
