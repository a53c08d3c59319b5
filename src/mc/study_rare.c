/*
 * study_rare.c: the rare-event phase of a study (issue 21 item 4, docs/rare-events.md).
 *
 * A spec's out-of-spec probability is the sum of two disjoint events, below the lower limit and
 * above the upper, so each side is a limit state of its own (g = (y - L)/scale, (U - y)/scale:
 * prsm_rare_spec_limit_state) and the sides' probabilities add. Per side:
 *   auto     the plain run's kept samples beyond the limit are the pilot: when their count reaches
 *            the CoV target within the budget (prsm_rare_auto_select says mc) the counted figure
 *            stands with its Wilson interval; otherwise the method auto picks runs (IS after FORM,
 *            subset simulation, or FORM);
 *   form, sorm, is, subset   that method runs on the side whatever the count.
 * The rare engine runs on the study's variables and correlations (its own Nataf/Gaussian-copula
 * map, the engine's), with the study's seed on streams of its own (RARE_STREAM_BASE + a key per
 * output and side), on the study's threads: every figure is bit-identical for any thread count.
 * No JSON here (mc/ never sees documents).
 */
#include "mc/study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "util/clock.h"

/* The rare-event phase's streams: far from the plain run's block keys (from 0) and the Saltelli
 * run's (from 2^40), each (output, side) 2^52 apart so that the rare engine's own keys (up to
 * about 3 x 2^48 plus the blocks) never meet another side's. */
#define RARE_STREAM_BASE (UINT64_C(1) << 56)
#define RARE_STREAM_SIDE (UINT64_C(1) << 52)

void prsm_study_rare_options_default(prsm_study_rare_options *o)
{
	o->max_evaluations = 20000;
	o->target_cov = 0.1;
	o->subset_samples = 1000;
}

static prsm_rare_method rare_method_of(int yield_method)
{
	switch (yield_method) {
	case PRSM_STUDY_YIELD_FORM:
		return PRSM_RARE_FORM;
	case PRSM_STUDY_YIELD_SORM:
		return PRSM_RARE_SORM;
	case PRSM_STUDY_YIELD_IS:
		return PRSM_RARE_IS;
	case PRSM_STUDY_YIELD_SUBSET:
		return PRSM_RARE_SUBSET;
	case PRSM_STUDY_YIELD_AUTO:
		return PRSM_RARE_AUTO;
	default:
		return PRSM_RARE_MC;
	}
}

const char *prsm_study_yield_method_name(int yield_method)
{
	/* prsm_rare_method_name's, but for the spec's own enum: mc is its default, auto is not */
	return yield_method == PRSM_STUDY_YIELD_MC ? "mc" : prsm_rare_method_name(rare_method_of(yield_method));
}

/* The side as the plain run counted it: pf = failures / n with its Wilson 95 % interval. */
static void side_counted(prsm_study_rare_side *sd)
{
	sd->ran = 0;
	sd->method = PRSM_RARE_MC;
	sd->pf = sd->n ? (double)sd->failures / (double)sd->n : NAN;
	prsm_stats_wilson(sd->failures, sd->n, PRSM_STATS_Z95, &sd->lower, &sd->upper);
	sd->cov = sd->failures ? sqrt((1.0 - sd->pf) / ((double)sd->n * sd->pf)) : NAN;
	sd->beta = sd->pf > 0.0 && sd->pf < 1.0 ? -gsl_cdf_ugaussian_Pinv(sd->pf) : NAN;
	sd->evaluations = 0;
	sd->converged = 1;
	sd->stop = PRSM_RARE_STOP_CONVERGED;
}

/* Copy what the rare engine found into the side: the estimate of the method that ran and, when
 * FORM ran, its design point and the importance of each tolerance (its variables' gamma^2). */
static int side_take(prsm_study_rare_side *sd, const prsm_rare_result *rr, const prsm_study *s)
{
	sd->ran = 1;
	sd->method = rr->method;
	sd->pf = rr->pf;
	sd->lower = rr->lower;
	sd->upper = rr->upper;
	sd->cov = rr->cov;
	sd->beta = rr->beta;
	sd->evaluations = rr->evaluations;
	sd->converged = rr->converged;
	sd->stop = rr->stop;
	if (rr->has_subset && rr->method == PRSM_RARE_SUBSET && !isfinite(rr->pf) && isfinite(rr->subset.bound)) {
		/* subset simulation stopped before its last level reached the limit: what it shows is an
		 * upper bound, P(g <= the last threshold) */
		sd->lower = 0.0;
		sd->upper = rr->subset.bound;
	}
	if (!rr->has_form || !rr->form.x_star || !rr->form.importance || !(isfinite(rr->form.beta)))
		return 0;
	sd->x_star = malloc(s->d * sizeof *sd->x_star);
	if (!sd->x_star)
		return PRSM_ENOMEM;
	memcpy(sd->x_star, rr->form.x_star, s->d * sizeof *sd->x_star);
	sd->has_design_point = 1;
	sd->form_beta = rr->form.beta;
	for (size_t g = 0; g < s->n_groups; g++) {
		double sum = 0.0;
		for (size_t v = s->groups[g].first_var; v < s->groups[g].first_var + s->groups[g].n_vars; v++)
			sum += rr->form.importance[v];
		sd->importance[g] = sum;
	}
	return 0;
}

/* The combined figure: the sides' probabilities add (disjoint events), and so do the ends of
 * their intervals (a conservative interval of the sum). */
static void combine(prsm_study_output_result *res)
{
	double pf = 0.0, lo = 0.0, hi = 0.0;
	res->rare_ppm_from_rare = 0;
	for (int k = 0; k < 2; k++) {
		const prsm_study_rare_side *sd = &res->rare[k];
		if (!sd->present)
			continue;
		pf += sd->pf;
		lo += sd->lower;
		hi += sd->upper;
		res->rare_ppm_from_rare |= sd->ran;
	}
	res->rare_ppm = 1e6 * pf;
	res->rare_ppm_low95 = isfinite(lo) ? 1e6 * lo : NAN;
	res->rare_ppm_high95 = isfinite(hi) ? 1e6 * fmin(hi, 1.0) : NAN;
}

int prsm_study_rare(prsm_study_result *r, const prsm_study *s, double deadline_s, prsm_error *err)
{
	const prsm_mc_result *run = &r->run;
	prsm_study_rare_options ro = s->rare;
	if (ro.max_evaluations == 0)
		prsm_study_rare_options_default(&ro);
	r->rare_outputs = s->m;
	for (size_t o = 0; o < s->m; o++) {
		const prsm_study_output *out = &s->outputs[o];
		prsm_study_output_result *res = &r->out[o];
		if (!out->has_spec || out->yield_method == PRSM_STUDY_YIELD_MC)
			continue;
		res->has_rare = 1;
		memset(res->rare, 0, sizeof res->rare);
		for (int k = 0; k < 2; k++) {
			prsm_study_rare_side *sd = &res->rare[k];
			sd->present = k == 0 ? out->spec.has_lower : out->spec.has_upper;
			sd->pf = sd->lower = sd->upper = sd->cov = sd->beta = sd->form_beta = NAN;
			for (size_t g = 0; g < s->n_groups; g++)
				sd->importance[g] = NAN;
			if (!sd->present)
				continue;
			double limit = k == 0 ? out->spec.lower : out->spec.upper;
			for (size_t j = 0; j < run->n; j++) {
				if (!prsm_mc_sample_kept(&s->mc, run->status[j]))
					continue;
				double y = run->y[j * s->m + o];
				sd->n++;
				sd->failures += k == 0 ? (y < limit) : (y > limit);
			}
		}
		for (int k = 0; k < 2; k++) {
			prsm_study_rare_side *sd = &res->rare[k];
			if (!sd->present)
				continue;
			prsm_rare_options opt;
			prsm_rare_options_init(&opt);
			opt.seed = s->mc.seed;
			opt.stream_offset = RARE_STREAM_BASE + (uint64_t)(2 * o + (size_t)k) * RARE_STREAM_SIDE;
			opt.threads = s->mc.threads > 0 ? s->mc.threads : 1;
			opt.cancel = s->mc.cancel;
			prsm_study_progress_relay relay = {s->mc.progress, s->mc.progress_ctx, "rare_events", "evaluations", 0, 0};
			if (s->mc.progress) {
				opt.progress = prsm_study_progress_relay_fn;
				opt.progress_ctx = &relay;
			}
			opt.max_evaluations = ro.max_evaluations;
			opt.max_samples = ro.max_evaluations;
			opt.target_cov = ro.target_cov;
			opt.subset_samples = ro.subset_samples;
			if (opt.min_samples > opt.max_samples)
				opt.min_samples = opt.max_samples;
			prsm_rare_method method = rare_method_of(out->yield_method);
			if (method == PRSM_RARE_AUTO) {
				char why[PRSM_RARE_REASON_MAX];
				method = prsm_rare_auto_select(sd->failures, sd->n, s->d, &opt, why, sizeof why);
				snprintf(sd->note, sizeof sd->note, "auto: %.150s", why);
				opt.is_fallback_subset = 1;
				if (method == PRSM_RARE_MC) {
					side_counted(sd);
					continue;
				}
			}
			if (deadline_s > 0.0) {
				double left = deadline_s - prsm_clock_seconds();
				if (left <= 0.0) {
					side_counted(sd);
					snprintf(sd->note, sizeof sd->note,
					         "the study's time cap was reached before the rare-event phase: the counted figure stands");
					continue;
				}
				opt.time_cap_s = left;
			}
			/* g of order 1: the spec's width, else the output's sd */
			prsm_rare_spec spec = {&s->model, o, k == 0 ? PRSM_RARE_SIDE_LOWER : PRSM_RARE_SIDE_UPPER,
			                       out->spec.lower, out->spec.upper, 1.0};
			if (out->spec.has_lower && out->spec.has_upper && out->spec.upper > out->spec.lower)
				spec.scale = out->spec.upper - out->spec.lower;
			else if (res->summary.sd > 0.0)
				spec.scale = res->summary.sd;
			prsm_rare_problem p = {{0}, s->vars, s->d, s->n_corr ? s->corr : NULL, s->n_corr};
			prsm_rare_spec_limit_state(&p.limit, &spec);
			prsm_rare_result rr;
			prsm_error e2 = PRSM_ERROR_INIT;
			int rc = prsm_rare_run(&rr, method, &p, &opt, &e2);
			if (rc) {
				prsm_rare_result_free(&rr);
				return prsm_error_set(err, rc, NULL, "%s, %s limit, %s: %s", out->name,
				                      k == 0 ? "lower" : "upper", prsm_rare_method_name(method), e2.message);
			}
			char note[sizeof sd->note];
			snprintf(note, sizeof note, "%s", sd->note);
			rc = side_take(sd, &rr, s);
			if (note[0] && rr.note[0])
				snprintf(sd->note, sizeof sd->note, "%.150s; %.150s", note, rr.note);
			else if (note[0])
				snprintf(sd->note, sizeof sd->note, "%s", note);
			prsm_rare_result_free(&rr);
			if (rc)
				return prsm_error_set(err, rc, NULL, "out of memory");
			if (sd->stop == PRSM_RARE_STOP_CANCELLED)
				return prsm_error_set(err, PRSM_ECANCELLED, NULL, "the study was cancelled");
		}
		combine(res);
	}
	return 0;
}
