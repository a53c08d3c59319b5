/*
 * study.c: run a tolerance study and summarise it (DESIGN.md, "Documents": result).
 *
 * Order of work: the plain run (mc/engine); per output the summary over the samples kept
 * (mc/stats), SRC and SRRC over the same rows (mc/sens), the worst-case and RSS stack from
 * one-at-a-time changes at the distributions' centres; then, when asked, a Saltelli run on
 * streams of its own for the Sobol indices with bootstrap intervals (random sampling) or
 * randomised-QMC replicate intervals (Sobol' sampling). Between the two, specs that ask for a
 * rare-event estimate of their out-of-spec probability get it (study_rare.c).
 */
#include "mc/study.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <stddef.h>
#include <string.h>

#include "util/clock.h"
#include "util/mem.h"
#include "util/rng.h"

/* The Saltelli run's streams start here, so its blocks never reuse the plain run's. */
#define SALTELLI_STREAM_OFFSET (UINT64_C(1) << 40)
/* Randomised-QMC replicates of a Saltelli run with the Sobol' sampler, and the fewest rows
 * each must have (fewer replicates for a small N). */
#define SOBOL_REPLICATES 16
#define SOBOL_REPLICATE_MIN_ROWS 32
/* Phases tried for a radial error's worst direction in the stack figures. */
#define STACK_PHASES 8

void prsm_sens_options_default(prsm_sens_options *s)
{
	memset(s, 0, sizeof *s);
	s->src = 1;
	s->sobol = 0;
	s->sobol_samples = 4096;
	s->bootstrap = 200;
	s->sobol_sampler = PRSM_SAMPLER_SOBOL;
	s->stack = 1;
}

void prsm_study_result_free(prsm_study_result *r)
{
	if (!r)
		return;
	prsm_mc_result_free(&r->run);
	for (size_t o = 0; o < r->rare_outputs && o < PRSM_MC_MAX_OUTPUTS; o++)
		for (int k = 0; k < 2; k++) {
			free(r->out[o].rare[k].x_star);
			r->out[o].rare[k].x_star = NULL;
		}
	r->rare_outputs = 0;
}

static void warn(prsm_study_result *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void warn(prsm_study_result *r, const char *fmt, ...)
{
	if (r->n_warnings >= PRSM_STUDY_WARNINGS)
		return;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(r->warnings[r->n_warnings++], sizeof r->warnings[0], fmt, ap);
	va_end(ap);
}

double prsm_study_sd_effective(const prsm_study *s, size_t v)
{
	const prsm_dist *d = &s->vars[v].dist;
	double sd = prsm_dist_sd(d);
	if (s->info[v].phase < 0)
		return sd;
	double mean = prsm_dist_mean(d);
	return sqrt(0.5 * (sd * sd + mean * mean));
}

/* One-at-a-time stack: centre x0, each variable moved by its half-width T_i (radial magnitudes
 * with their worst phase), Delta_i = change of each output. Worst case: the sum of |Delta_i|;
 * RSS: three times the linear stack's sd, sqrt(sum (Delta_i sd_i / T_i)^2), each variable with
 * its own sd (a half-width is 3 sd only for the {tol, cpk 1} normal: sqrt 3 sd for a uniform),
 * as the allocation's linear model counts them. */
static int stack(prsm_study_result *r, const prsm_study *s, prsm_error *err)
{
	const prsm_mc_model *mdl = &s->model;
	const size_t d = s->d, m = s->m;
	void *ws = NULL;
	double *x = malloc(d * sizeof *x), y0[PRSM_MC_MAX_OUTPUTS], yp[PRSM_MC_MAX_OUTPUTS],
	       ym[PRSM_MC_MAX_OUTPUTS], sum_abs[PRSM_MC_MAX_OUTPUTS] = {0}, sum_sq[PRSM_MC_MAX_OUTPUTS] = {0};
	int rc = 0;
	unsigned flags;
	if (!x || (mdl->workspace_alloc && mdl->workspace_alloc(&ws, mdl->ctx))) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	for (size_t i = 0; i < d; i++)
		x[i] = prsm_dist_center(&s->vars[i].dist);
	if (mdl->eval(y0, &flags, mdl->ctx, ws, x)) {
		warn(r, "no worst-case/RSS figures: the model failed at the distributions' centres");
		goto cleanup;
	}
	for (size_t o = 0; o < m; o++)
		for (size_t g = 0; g < s->n_groups; g++)
			r->out[o].by_group[g].stack_um = 0.0;
	for (size_t i = 0; i < d; i++) {
		if (s->info[i].phase_of >= 0)
			continue;
		const double c = x[i], t = prsm_dist_halfwidth(&s->vars[i].dist);
		double delta[PRSM_MC_MAX_OUTPUTS] = {0};
		if (s->info[i].phase >= 0) {
			/* radial error: the largest change over its direction */
			const size_t ph = (size_t)s->info[i].phase;
			const double ph0 = x[ph];
			x[i] = c + t;
			for (int k = 0; k < STACK_PHASES; k++) {
				x[ph] = 2.0 * M_PI * k / STACK_PHASES;
				if (mdl->eval(yp, &flags, mdl->ctx, ws, x))
					goto failed;
				for (size_t o = 0; o < m; o++)
					delta[o] = fmax(delta[o], fabs(yp[o] - y0[o]));
			}
			x[ph] = ph0;
		} else {
			x[i] = c + t;
			if (mdl->eval(yp, &flags, mdl->ctx, ws, x))
				goto failed;
			x[i] = c - t;
			if (mdl->eval(ym, &flags, mdl->ctx, ws, x))
				goto failed;
			for (size_t o = 0; o < m; o++)
				delta[o] = 0.5 * fabs(yp[o] - ym[o]);
		}
		x[i] = c;
		const double sd_per_t = t > 0.0 ? prsm_study_sd_effective(s, i) / t : 0.0;
		for (size_t o = 0; o < m; o++) {
			sum_abs[o] += delta[o];
			sum_sq[o] += (delta[o] * sd_per_t) * (delta[o] * sd_per_t);
			r->out[o].by_group[s->vars[i].group].stack_um += delta[o];
		}
		continue;
	failed:
		warn(r, "no worst-case/RSS figures: the model failed with %s at its half-width", s->info[i].name);
		goto cleanup;
	}
	for (size_t o = 0; o < m; o++) {
		prsm_study_output_result *q = &r->out[o];
		q->has_stack = 1;
		q->nominal = y0[o];
		q->worst_low = y0[o] - sum_abs[o];
		q->worst_high = y0[o] + sum_abs[o];
		q->rss = 3.0 * sqrt(sum_sq[o]);
	}
cleanup:
	if (ws && mdl->workspace_free)
		mdl->workspace_free(ws);
	free(x);
	return rc;
}

static int output_named(const prsm_study *s, const char *name)
{
	for (size_t o = 0; o < s->m; o++)
		if (strcmp(s->outputs[o].name, name) == 0)
			return (int)o;
	return -1;
}

static void probability(prsm_study_probability *p, size_t count, size_t n)
{
	p->count = count;
	p->n = n;
	p->p = n ? (double)count / (double)n : NAN;
	prsm_stats_wilson(count, n, PRSM_STATS_Z95, &p->low95, &p->high95);
}

void prsm_study_dynamics_summary(prsm_study_dynamics *out, const prsm_study *s, const prsm_mc_result *run)
{
	memset(out, 0, sizeof *out);
	const int ol = output_named(s, "contact_loss"), orr = output_named(s, "regime"), oi = output_named(s, "integrated");
	if (ol < 0 || orr < 0 || oi < 0 || run->y == NULL)
		return;
	out->present = 1;
	size_t n = 0, loss = 0, np = 0;
	for (size_t j = 0; j < run->n; j++) {
		if (run->status[j] == PRSM_SAMPLE_FAILED) {
			if (run->fail_code != NULL && run->fail_code[j] == PRSM_EGEOMETRY)
				out->no_play++;
			else
				out->failed++;
		}
		if (!prsm_mc_sample_kept(&s->mc, run->status[j]))
			continue;
		const double *y = run->y + j * s->m;
		n++;
		loss += y[ol] > 0.5;
		np += y[orr] < 0.5; /* regime 0: non-periodic */
		if (y[oi] > 0.5)
			out->integrated++;
		else
			out->screened++;
	}
	probability(&out->contact_loss, loss, n);
	probability(&out->non_periodic, np, n);
}

int prsm_study_summarise(prsm_study_result *r, const prsm_study *s, prsm_error *err)
{
	const prsm_mc_result *run = &r->run;
	prsm_study_dynamics_summary(&r->dynamics, s, run);
	const size_t d = s->d, m = s->m, n = run->n;
	int rc = 0;
	size_t nk = 0;
	for (size_t j = 0; j < n; j++)
		nk += prsm_mc_sample_kept(&s->mc, run->status[j]) ? 1 : 0;
	if (nk < 2)
		return prsm_error_set(err, PRSM_ENOCONVERGE, NULL,
		                      "only %zu of %zu samples were usable: nothing to summarise", nk, n);
	double *y = malloc(nk * sizeof *y), *scratch = malloc(nk * sizeof *scratch);
	double *xk = NULL, *coef = malloc(d * sizeof *coef);
	if (!y || !scratch || !coef) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	int do_src = s->sens.src && nk >= d + 2;
	if (s->sens.src && !do_src)
		warn(r, "no SRC/SRRC: %zu usable samples for %zu variables (need at least %zu)", nk, d, d + 2);
	if (do_src) {
		xk = malloc(nk * d * sizeof *xk);
		if (!xk) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
			goto cleanup;
		}
		size_t q = 0;
		for (size_t j = 0; j < n; j++)
			if (prsm_mc_sample_kept(&s->mc, run->status[j]))
				memcpy(xk + (q++) * d, run->x + j * d, d * sizeof *xk);
	}
	for (size_t o = 0; o < m; o++) {
		prsm_study_output_result *res = &r->out[o];
		size_t q = 0;
		for (size_t j = 0; j < n; j++)
			if (prsm_mc_sample_kept(&s->mc, run->status[j]))
				y[q++] = run->y[j * m + o];
		rc = prsm_stats_summarise(&res->summary, y, nk, s->outputs[o].has_spec ? &s->outputs[o].spec : NULL,
		                          scratch, err);
		if (rc)
			goto cleanup;
		if (res->summary.has_spec && res->summary.normal_rejected)
			warn(r, "%s: the sample is not normal (Anderson-Darling A* = %.3g, p = %.2g): its fitted-normal "
			        "ppm are withheld; the counted ppm and the tail fit (a generalised Pareto over the "
			        "outer 5 %%) do not assume a shape",
			     s->outputs[o].name, res->summary.normal_ad, res->summary.normal_ad_p);
		for (size_t g = 0; g < s->n_groups; g++) {
			res->by_group[g].src = res->by_group[g].srrc = NAN;
			res->by_group[g].src_percent = res->by_group[g].srrc_percent = NAN;
		}
		res->src_r2 = res->srrc_r2 = NAN;
		if (!do_src || !(res->summary.sd > 0.0))
			continue;
		for (int ranks = 0; ranks < 2; ranks++) {
			double r2;
			rc = prsm_sens_src(coef, &r2, NULL, xk, nk, d, y, ranks, err);
			if (rc)
				goto cleanup;
			if (ranks)
				res->srrc_r2 = r2;
			else
				res->src_r2 = r2;
			for (size_t g = 0; g < s->n_groups; g++) {
				const prsm_study_group *gr = &s->groups[g];
				double sq = 0.0;
				for (size_t v = gr->first_var; v < gr->first_var + gr->n_vars; v++)
					sq += coef[v] * coef[v];
				double one = gr->n_vars == 1 ? coef[gr->first_var] : NAN;
				if (ranks) {
					res->by_group[g].srrc = one;
					res->by_group[g].srrc_percent = 100.0 * sq;
				} else {
					res->by_group[g].src = one;
					res->by_group[g].src_percent = 100.0 * sq;
				}
			}
		}
		res->has_src = 1;
		if (res->src_r2 < 0.7)
			warn(r, "%s: the linear fit explains only %.0f %% of the variance (R^2 = %.3f): SRC "
			        "shares are not a variance decomposition here; use the Sobol indices",
			     s->outputs[o].name, 100.0 * res->src_r2, res->src_r2);
	}
	if (s->sens.stack)
		rc = stack(r, s, err);
cleanup:
	free(y);
	free(scratch);
	free(xk);
	free(coef);
	return rc;
}

void prsm_study_progress_relay_fn(void *ctx, const prsm_progress *p)
{
	const prsm_study_progress_relay *rl = ctx;
	prsm_progress q = *p;
	q.phase = rl->phase;
	if (rl->unit)
		q.unit = rl->unit;
	if (rl->planned) {
		q.done = rl->offset + p->done;
		q.planned = rl->planned;
	}
	rl->fn(rl->ctx, &q);
}

/* Seed of randomised-QMC replicate r (replicate 0 keeps the study's seed): splitmix64. */
static uint64_t replicate_seed(uint64_t seed, size_t r)
{
	if (r == 0)
		return seed;
	uint64_t z = seed + UINT64_C(0x9e3779b97f4a7c15) * (uint64_t)r;
	z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
	z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
	return z ^ (z >> 31);
}

/* The Sobol' indices: a Saltelli run on streams of its own. Random sampling: one run, bootstrap
 * intervals. Sobol' sampling: R randomised-QMC replicates (each an independently scrambled
 * sequence of N / R rows; SOBOL_REPLICATES, fewer for small N), the indices of the pooled rows
 * with intervals from the replicates' spread (prsm_sens_sobol_replicated), since a bootstrap of
 * a low-discrepancy sample gives intervals many times too wide. */
size_t prsm_study_sobol_replicates(const prsm_study *s)
{
	const size_t N = s->sens.sobol_samples;
	size_t R = s->sens.sobol_sampler == PRSM_SAMPLER_SOBOL ? N / SOBOL_REPLICATE_MIN_ROWS : 1;
	return R < 1 ? 1 : R > SOBOL_REPLICATES ? SOBOL_REPLICATES : R;
}

void prsm_study_sobol_options(prsm_mc_options *mo, const prsm_study *s, size_t q)
{
	const size_t N = s->sens.sobol_samples, R = prsm_study_sobol_replicates(s);
	*mo = s->mc;
	mo->samples = N / R + (q < N % R ? 1 : 0);
	mo->seed = replicate_seed(s->mc.seed, q);
	mo->sampler = s->sens.sobol_sampler;
	mo->n_targets = 0;
	mo->first_block = mo->block_count = 0;
	mo->stream_offset = SALTELLI_STREAM_OFFSET;
	mo->failure = PRSM_FAILURE_SKIP;
	mo->max_failed_fraction = 1.0;
	mo->time_cap_s = 0.0;
}

static int sobol(prsm_study_result *r, const prsm_study *s, const prsm_study_runner *runner, double deadline_s,
                 prsm_error *err)
{
	const size_t N = s->sens.sobol_samples, G = s->n_groups, K = G + 2, m = s->m;
	const int qmc = s->sens.sobol_sampler == PRSM_SAMPLER_SOBOL;
	const size_t R = prsm_study_sobol_replicates(s);
	/* The outputs of the kept rows, gathered as each replicate finishes (whose own arrays are
	 * then freed, so the next replicate reuses their memory): output o's K columns at
	 * buf + o K N, column k at + k N (rows in replicate order), compacted to a column length
	 * of nk once every replicate has run. Holding every replicate until the end and copying
	 * then touched twice the memory, a page fault per 4 KiB. */
	double *buf = malloc((m * K * N > 0 ? m * K * N : 1) * sizeof *buf);
	prsm_mem_populate(buf, m * K * N * sizeof *buf); /* written in full: its pages at once */
	size_t *kept_end = calloc(R, sizeof *kept_end);
	prsm_sobol_index *idx = malloc(G * sizeof *idx);
	gsl_rng *rng = prsm_rng_alloc(s->mc.seed, SALTELLI_STREAM_OFFSET - 1);
	prsm_mc_result sr;
	memset(&sr, 0, sizeof sr);
	prsm_sampler_kind sampler = s->sens.sobol_sampler;
	char warning0[sizeof sr.warning] = "";
	int rc = 0;
	size_t ran = 0, complete = 0, n = 0, nk = 0;
	if (!buf || !kept_end || !idx || !rng) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	for (size_t q = 0; q < R; q++) {
		if (q > 0 && (prsm_cancel_requested(s->mc.cancel) ||
		              (deadline_s > 0.0 && prsm_clock_seconds() >= deadline_s)))
			break;
		prsm_mc_options mo;
		prsm_study_sobol_options(&mo, s, q);
		if (deadline_s > 0.0)
			mo.time_cap_s = fmax(deadline_s - prsm_clock_seconds(), 1e-9);
		/* progress: the phase's base rows, every replicate's in turn */
		prsm_study_progress_relay relay = {s->mc.progress, s->mc.progress_ctx, "sobol", NULL, 0, N};
		for (size_t k = 0; k < q; k++)
			relay.offset += N / R + (k < N % R ? 1 : 0);
		if (mo.progress) {
			mo.progress = prsm_study_progress_relay_fn;
			mo.progress_ctx = &relay;
		}
		if (runner && runner->replicate)
			rc = runner->replicate(&sr, s, q, &mo, runner->ctx, err);
		else
			rc = prsm_mc_run_saltelli(&sr, &s->model, s->vars, s->d, s->n_groups, s->corr, s->n_corr, &mo, err);
		if (rc)
			goto cleanup;
		ran++;
		if (q == 0) {
			sampler = sr.sampler;
			memcpy(warning0, sr.warning, sizeof warning0);
		}
		size_t kq = 0;
		for (size_t o = 0; o < m; o++)
			for (size_t k = 0; k < K; k++) {
				double *col = buf + (o * K + k) * N + nk;
				size_t p = 0;
				for (size_t j = 0; j < sr.n; j++)
					if (prsm_mc_sample_kept(&s->mc, sr.status[j]))
						col[p++] = sr.ys[(o * K + k) * sr.n + j];
				kq = p;
			}
		const size_t run_n = sr.n;
		prsm_mc_result_free(&sr);
		n += run_n;
		nk += kq;
		kept_end[q] = nk;
		if (run_n == mo.samples && kq >= 2)
			complete++;
		if (run_n < mo.samples)
			break; /* the time cap or cancel stopped it */
	}
	r->has_sobol = 1;
	r->sobol_rows = n;
	r->sobol_rows_ok = nk;
	r->sobol_evaluations = n * K;
	r->sobol_sampler = sampler;
	r->sobol_replicates = qmc ? ran : 0;
	if (warning0[0])
		warn(r, "Sobol indices: %s", warning0);
	if (s->n_corr)
		warn(r, "Sobol indices assume independent inputs; the study's correlations are kept inside A "
		        "and B but broken in the mixed rows");
	if (nk < 2) {
		warn(r, "no Sobol indices: %zu usable rows", nk);
		goto cleanup;
	}
	const int replicated = qmc && complete == ran && ran >= 2;
	if (qmc && !replicated)
		warn(r, "Sobol indices: %s: no standard errors or intervals (they need at least 2 complete "
		        "randomised-QMC replicates of %d rows or more)",
		     ran < R ? "the time cap or cancel stopped the replicates" : "too few base samples",
		     SOBOL_REPLICATE_MIN_ROWS);
	for (size_t o = 0; o < m; o++) {
		/* output o's columns to length nk, in place (each moves down, never over one not yet moved) */
		double *y = buf + o * K * N;
		for (size_t k = 1; k < K; k++)
			memmove(y + k * nk, y + k * N, nk * sizeof *y);
		double V;
		if (replicated) {
			rc = prsm_sens_sobol_replicated(idx, &V, y, y + nk, y + 2 * nk, nk, G, kept_end, ran, err);
		} else {
			/* every output's bootstrap draws the same resamples */
			prsm_rng_set_stream(rng, s->mc.seed, SALTELLI_STREAM_OFFSET - 1);
			size_t done = 0;
			const size_t nboot = qmc ? 0 : s->sens.bootstrap;
			rc = prsm_sens_sobol_until(idx, &V, y, y + nk, y + 2 * nk, nk, G, nboot, rng,
			                           s->mc.cancel, deadline_s, &done, err);
			if (rc == 0 && done < nboot)
				warn(r, "Sobol indices of %s: the bootstrap stopped (%s) after %zu of %zu resamples: no "
				        "standard errors or intervals",
				     s->outputs[o].name, prsm_cancel_requested(s->mc.cancel) ? "cancelled" : "time cap", done,
				     nboot);
		}
		if (rc)
			goto cleanup;
		r->out[o].has_sobol = 1;
		r->out[o].sobol_variance = V;
		for (size_t g = 0; g < G; g++)
			r->out[o].by_group[g].sobol = idx[g];
	}
cleanup:
	free(buf);
	free(idx);
	free(kept_end);
	if (rng)
		gsl_rng_free(rng);
	prsm_mc_result_free(&sr);
	return rc;
}

/* Clear what a run of s fills and reads: the header, the first s->m outputs and the rest. The
 * outputs beyond m are never read; clearing all PRSM_MC_MAX_OUTPUTS of them (220 KiB) cost a
 * page fault per 4 KiB, more than a small study's sampling. */
static void result_clear(prsm_study_result *r, const prsm_study *s)
{
	memset(r, 0, offsetof(prsm_study_result, out));
	memset(r->out, 0, (s->m < PRSM_MC_MAX_OUTPUTS ? s->m : PRSM_MC_MAX_OUTPUTS) * sizeof r->out[0]);
	memset(&r->has_sobol, 0, sizeof *r - offsetof(prsm_study_result, has_sobol));
}

int prsm_study_run(prsm_study_result *r, const prsm_study *s, prsm_error *err)
{
	return prsm_study_run_with(r, s, NULL, err);
}

int prsm_study_adopt(prsm_study *mine, const prsm_study *from, prsm_error *err)
{
	if (mine->d != from->d || mine->model.n_outputs != from->model.n_outputs || mine->m != from->m ||
	    mine->n_groups != from->n_groups)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the study document gives %zu variables, %zu outputs and %zu "
		                      "tolerances here, %zu, %zu and %zu there", mine->d, mine->model.n_outputs, mine->n_groups,
		                      from->d, from->model.n_outputs, from->n_groups);
	for (size_t v = 0; v < mine->d; v++)
		if ((from->vars[v].dist.kind == PRSM_DIST_HISTOGRAM) != (mine->vars[v].dist.kind == PRSM_DIST_HISTOGRAM))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "variable %zu is a histogram on one side only", v);
	const prsm_mc_model model = mine->model;
	const prsm_dist_histogram *hist[PRSM_MC_MAX_VARIABLES];
	for (size_t v = 0; v < mine->d; v++)
		hist[v] = mine->vars[v].dist.hist;
	memcpy(mine, from, sizeof *mine);
	mine->model = model;
	for (size_t v = 0; v < mine->d; v++)
		mine->vars[v].dist.hist = hist[v];
	mine->mc.cancel = NULL;
	mine->mc.progress = NULL;
	mine->mc.progress_ctx = NULL;
	return 0;
}

int prsm_study_service_run(const prsm_study_service *svc, prsm_study_result *r, const prsm_study *s,
                           const char *source, size_t source_len, prsm_error *err)
{
	if (svc && svc->run && source && source_len)
		return svc->run(r, s, source, source_len, svc->ctx, err);
	return prsm_study_run(r, s, err);
}

int prsm_study_run_with(prsm_study_result *r, const prsm_study *s, const prsm_study_runner *runner,
                        prsm_error *err)
{
	result_clear(r, s);
	double t0 = prsm_clock_seconds();
	prsm_mc_options mo = s->mc;
	prsm_study_progress_relay relay = {s->mc.progress, s->mc.progress_ctx, "monte_carlo", NULL, 0, 0};
	if (mo.progress) {
		mo.progress = prsm_study_progress_relay_fn;
		mo.progress_ctx = &relay;
	}
	int rc = runner && runner->run ? runner->run(&r->run, s, runner->ctx, err)
	                               : prsm_mc_run(&r->run, &s->model, s->vars, s->d, s->corr, s->n_corr, &mo, err);
	if (rc)
		return rc;
	r->elapsed_run_s = prsm_clock_seconds() - t0;
	if (r->run.warning[0])
		warn(r, "%s", r->run.warning);
	if (s->mc.sampler == PRSM_SAMPLER_SOBOL)
		warn(r, "Sobol' sampling: the standard errors, the yield intervals and the stop rule treat the "
		        "points as independent, which overstates the error of a scrambled Sobol' sample (often "
		        "several times): they are conservative, and a stop target is reached later than it "
		        "needs to be");
	if (r->run.stop == PRSM_STOP_FAILURES) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL,
		                    "%zu failed and %zu edge-contact samples in the first %zu: more than the "
		                    "allowed fraction %g (failure policy: skip)",
		                    r->run.n_failed, r->run.n_edge, r->run.n, s->mc.max_failed_fraction);
		goto fail;
	}
	if (r->run.stop == PRSM_STOP_CANCELLED) {
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the study was cancelled");
		goto fail;
	}
	double t1 = prsm_clock_seconds();
	if (s->mc.progress) { /* the summaries, SRC and stack: no count, but a name */
		prsm_progress pg = PRSM_PROGRESS_INIT;
		pg.phase = "summary";
		s->mc.progress(s->mc.progress_ctx, &pg);
	}
	rc = prsm_study_summarise(r, s, err);
	if (rc)
		goto fail;
	/* the rare-event phase (specs with a yield method other than mc), under the same time cap */
	rc = prsm_study_rare(r, s, s->mc.time_cap_s > 0.0 ? t0 + s->mc.time_cap_s : 0.0, err);
	if (rc)
		goto fail;
	if (s->sens.sobol) {
		/* every phase honours the study's time cap and cancel, the bootstrap too */
		rc = sobol(r, s, runner, s->mc.time_cap_s > 0.0 ? t0 + s->mc.time_cap_s : 0.0, err);
		if (rc)
			goto fail;
	}
	r->elapsed_sensitivity_s = prsm_clock_seconds() - t1;
	return 0;
fail:
	prsm_study_result_free(r);
	return rc;
}
