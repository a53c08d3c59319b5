/*
 * robust.c: the robust (Monte Carlo yield) constraints of robust.h: the candidate's study built
 * by the caller, run with common random numbers, each constraint's yield, its Wilson interval
 * and the smooth stand-in the solver sees; a small cache of recent candidates.
 */
#include "opt/robust.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "util/clock.h"

const char *const prsm_robust_surrogate_names[] = {"kernel", "normal", "none", NULL};

/* Y_s is clamped to [CLAMP, 1 - CLAMP] before the probit: |g_solver| stays below about 7. */
#define CLAMP 1e-12

void prsm_robust_init(prsm_robust *r)
{
	memset(r, 0, sizeof *r);
	r->surrogate = PRSM_ROBUST_KERNEL;
}

void prsm_robust_forget(prsm_robust *r)
{
	r->cache_used = r->cache_next = 0;
}

/* Fraction of a normal N(mean, sd) inside spec (sd = 0: the point mass at mean). */
static double normal_in_spec(const prsm_spec *sp, double mean, double sd)
{
	if (!(sd > 0.0)) {
		int in = (!sp->has_lower || mean >= sp->lower) && (!sp->has_upper || mean <= sp->upper);
		return in ? 1.0 : 0.0;
	}
	double hi = sp->has_upper ? gsl_cdf_ugaussian_P((sp->upper - mean) / sd) : 1.0;
	double lo = sp->has_lower ? gsl_cdf_ugaussian_P((sp->lower - mean) / sd) : 0.0;
	return fmax(0.0, hi - lo);
}

static double probit_clamped(double p)
{
	return gsl_cdf_ugaussian_Pinv(fmin(fmax(p, CLAMP), 1.0 - CLAMP));
}

int prsm_robust_value_of(prsm_robust_value *out, const prsm_study *s, const prsm_study_result *res,
                         size_t o, const prsm_robust_constraint *c, prsm_robust_surrogate kind,
                         prsm_error *err)
{
	const prsm_stats_summary *sm = &res->out[o].summary;
	if (sm->n < 2)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: fewer than 2 samples kept", c->output);
	out->yield = sm->yield;
	out->yield_low95 = sm->yield_low95;
	out->yield_high95 = sm->yield_high95;
	out->mean = sm->mean;
	out->sd = sm->sd;
	out->normal_yield = normal_in_spec(&c->spec, sm->mean, sm->sd);
	out->g = c->yield_min - sm->yield;
	double ys = sm->yield;
	if (kind == PRSM_ROBUST_NORMAL) {
		ys = out->normal_yield;
	} else if (kind == PRSM_ROBUST_KERNEL && sm->sd > 0.0) {
		/* each kept sample's indicator smoothed by a normal kernel of width h (robust.h) */
		const prsm_mc_result *run = &res->run;
		const double h = sm->sd * cbrt(1.0 / (double)sm->n);
		double sum = 0.0;
		size_t kept = 0;
		for (size_t i = 0; i < run->n; i++) {
			if (!prsm_mc_sample_kept(&s->mc, run->status[i]))
				continue;
			const double y = run->y[i * run->m + o];
			double in = c->spec.has_upper ? gsl_cdf_ugaussian_P((c->spec.upper - y) / h) : 1.0;
			if (c->spec.has_lower)
				in -= gsl_cdf_ugaussian_P((c->spec.lower - y) / h);
			sum += in;
			kept++;
		}
		ys = kept ? sum / (double)kept : sm->yield;
	}
	out->smooth_yield = ys;
	out->g_solver = probit_clamped(c->yield_min) - probit_clamped(ys);
	return 0;
}

static void key_of(double key[6], const prsm_design *d)
{
	key[0] = d->starts;
	key[1] = d->pitch_mm;
	key[2] = d->roller_radius_mm;
	key[3] = d->rollers;
	key[4] = d->engaged_threads;
	key[5] = d->flank_angle_rad;
}

/* Run the study of d and fill out (out->evaluated 0 with a reason when it cannot). */
static int run_study(prsm_robust_eval *out, prsm_robust *r, const prsm_design *d, prsm_error *err)
{
	prsm_study *study = NULL;
	void *handle = NULL;
	prsm_study_result *res = NULL;
	prsm_error e2 = PRSM_ERROR_INIT;
	if (!r->build || !r->release)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "robust constraints without a study builder");
	const char *source = NULL;
	size_t source_len = 0;
	int rc = r->build(r->build_ctx, &study, &handle, &source, &source_len, d, &e2);
	if (rc) {
		if (rc == PRSM_ENOMEM) {
			rc = prsm_error_set(err, rc, NULL, "%s", e2.message);
			goto cleanup;
		}
		snprintf(out->failure, sizeof out->failure, "the candidate's study: %.200s", e2.message);
		rc = 0;
		goto cleanup;
	}
	size_t index[PRSM_ROBUST_MAX];
	for (int k = 0; k < r->n; k++) {
		size_t o = 0;
		while (o < study->m && strcmp(study->outputs[o].name, r->c[k].output) != 0)
			o++;
		if (o == study->m) {
			snprintf(out->failure, sizeof out->failure, "the candidate's study has no output %s",
			         r->c[k].output);
			goto cleanup;
		}
		index[k] = o;
		study->outputs[o].has_spec = r->c[k].spec.has_lower || r->c[k].spec.has_upper;
		study->outputs[o].spec = r->c[k].spec;
	}
	study->sens.src = study->sens.stack = study->sens.sobol = 0;
	study->mc.n_targets = 0;
	study->mc.cancel = r->cancel;
	study->mc.progress = NULL;
	res = calloc(1, sizeof *res);
	if (!res) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	rc = prsm_study_service_run(r->service, res, study, source, source_len, &e2);
	r->studies++;
	r->samples_total += res->run.n;
	if (rc == PRSM_ECANCELLED) {
		rc = prsm_error_set(err, rc, NULL, "%s", e2.message);
		goto cleanup;
	}
	if (rc == PRSM_ENOMEM) {
		rc = prsm_error_set(err, rc, NULL, "%s", e2.message);
		goto cleanup;
	}
	if (rc) {
		snprintf(out->failure, sizeof out->failure, "the candidate's Monte Carlo run: %.200s", e2.message);
		rc = 0;
		goto cleanup;
	}
	out->failed = res->run.n_failed;
	out->edge = res->run.n_edge;
	for (int k = 0; k < r->n; k++) {
		if (prsm_robust_value_of(&out->v[k], study, res, index[k], &r->c[k], r->surrogate, &e2)) {
			snprintf(out->failure, sizeof out->failure, "%s", e2.message);
			goto cleanup;
		}
		out->samples = res->out[index[k]].summary.n;
	}
	out->evaluated = 1;
cleanup:
	if (res) {
		prsm_study_result_free(res);
		free(res);
	}
	if (handle)
		r->release(r->build_ctx, handle);
	return rc;
}

int prsm_robust_evaluate(prsm_robust_eval *out, prsm_robust *r, const prsm_design *d,
                         prsm_error *err)
{
	double key[6];
	key_of(key, d);
	for (int i = 0; i < r->cache_used; i++)
		if (memcmp(r->cache[i].key, key, sizeof key) == 0) {
			*out = r->cache[i].e;
			return 0;
		}
	memset(out, 0, sizeof *out);
	for (int k = 0; k < r->n; k++) {
		/* until evaluated: violated for the check and for the solver */
		out->v[k].yield = out->v[k].smooth_yield = NAN;
		out->v[k].g = out->v[k].g_solver = 1.0;
	}
	const double t0 = prsm_clock_seconds();
	int rc = run_study(out, r, d, err);
	out->elapsed_s = prsm_clock_seconds() - t0;
	r->elapsed_s += out->elapsed_s;
	if (rc)
		return rc;
	if (!out->evaluated)
		for (int k = 0; k < r->n; k++) {
			out->v[k].g = out->v[k].g_solver = 1.0;
			out->v[k].yield = NAN;
		}
	prsm_robust_cache_entry *ce = &r->cache[r->cache_next];
	memcpy(ce->key, key, sizeof key);
	ce->e = *out;
	r->cache_next = (r->cache_next + 1) % PRSM_ROBUST_CACHE;
	if (r->cache_used < PRSM_ROBUST_CACHE)
		r->cache_used++;
	return 0;
}
