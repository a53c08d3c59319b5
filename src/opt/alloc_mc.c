/*
 * alloc_mc.c: tolerance allocation on a tolerance study: the linear model from central
 * differences of the study's model, the yield rule, and the Monte Carlo correction with common
 * random numbers (see alloc_mc.h for the method).
 */
#include "opt/alloc_mc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "util/clock.h"

/* Directions tried for a radial magnitude (as the study's stack figures). */
#define RADIAL_PHASES 8
#define SHRINK 0.8
#define GROW 1.25

const char *prsm_alloc_stop_name(prsm_alloc_stop s)
{
	switch (s) {
	case PRSM_ALLOC_STOP_LINEAR: return "linear";
	case PRSM_ALLOC_STOP_CONVERGED: return "converged";
	case PRSM_ALLOC_STOP_MAX_CORRECTIONS: return "max_corrections";
	case PRSM_ALLOC_STOP_INFEASIBLE: return "infeasible";
	case PRSM_ALLOC_STOP_TIME_CAP: return "time_cap";
	case PRSM_ALLOC_STOP_CANCELLED: return "cancelled";
	}
	return "unknown";
}

int prsm_alloc_model_problem(prsm_alloc_problem *p, prsm_alloc_step *step, const prsm_alloc_model *md,
                             double scale, prsm_error *err)
{
	memset(p, 0, sizeof *p);
	p->n = md->n;
	p->m = md->m;
	p->stack = md->stack;
	step->scale = scale;
	for (size_t i = 0; i < md->n; i++) {
		p->cost[i] = md->cost[i];
		p->t_min[i] = md->t_min[i];
		p->t_max[i] = md->t_max[i];
	}
	for (size_t o = 0; o < md->m; o++) {
		double tasm;
		int rc = 0;
		char ptr[48];
		prsm_error e2 = PRSM_ERROR_INIT;
		step->sigma_max[o] = NAN;
		if (!md->has_target[o]) {
			tasm = md->assembly_tol[o]; /* given: a hard limit, never scaled */
		} else if (md->stack == PRSM_ALLOC_RSS) {
			double sigma;
			rc = prsm_alloc_sigma_for_out_fraction(&sigma, &md->spec[o], md->nominal[o], md->out_fraction[o], &e2);
			tasm = 3.0 * sigma * scale;
		} else {
			rc = prsm_alloc_worst_case_limit(&tasm, &md->spec[o], md->nominal[o], &e2);
			tasm *= scale;
		}
		if (rc) {
			snprintf(ptr, sizeof ptr, "/constraints/%zu/spec", o);
			return prsm_error_set(err, rc, ptr, "output %zu: %s", o, e2.message);
		}
		snprintf(ptr, sizeof ptr, "/constraints/%zu", o);
		step->assembly_tol[o] = tasm;
		if (md->stack == PRSM_ALLOC_RSS) {
			step->sigma_max[o] = tasm / 3.0;
			/* sqrt(T_asm^2 - 9 var_fixed) without squaring T_asm (no overflow) */
			const double ratio = 3.0 * sqrt(md->fixed_var[o]) / tasm;
			const double free1 = tasm * sqrt((1.0 - ratio) * (1.0 + ratio));
			if (!(ratio < 1.0) || !(free1 > 0.0))
				return prsm_error_set(err, PRSM_EINVAL, ptr,
				                      "output %zu: the tolerances not allocated already take the whole "
				                      "budget (their 3 sd %.6g, the assembly tolerance %.6g)",
				                      o, 3.0 * sqrt(md->fixed_var[o]), tasm);
			p->limit[o] = free1;
			for (size_t i = 0; i < md->n; i++)
				p->c[o][i] = 3.0 * md->c[o][i] / md->k[i];
		} else {
			double free1 = tasm - md->fixed_wc[o];
			if (!(free1 > 0.0))
				return prsm_error_set(err, PRSM_EINVAL, ptr,
				                      "output %zu: the tolerances not allocated already take the whole "
				                      "budget (worst case %.6g, the assembly tolerance %.6g)",
				                      o, md->fixed_wc[o], tasm);
			p->limit[o] = free1;
			for (size_t i = 0; i < md->n; i++)
				p->c[o][i] = md->c[o][i];
		}
		step->limit[o] = p->limit[o];
	}
	return 0;
}

int prsm_alloc_model_allocate(prsm_alloc_step *step, const prsm_alloc_model *md, double scale,
                              prsm_cancel_flag *cancel, double max_time_s, prsm_error *err)
{
	memset(step, 0, sizeof *step);
	prsm_alloc_problem *p = malloc(sizeof *p);
	if (!p)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int rc = prsm_alloc_model_problem(p, step, md, scale, err);
	p->cancel = cancel;
	p->max_time_s = max_time_s;
	if (rc == 0)
		rc = prsm_alloc_solve(&step->sol, p, md->solver, err);
	if (rc == 0) {
		step->meets = 1;
		step->assembly_ok = 1;
		for (size_t o = 0; o < md->m; o++) {
			double var = md->fixed_var[o];
			for (size_t i = 0; i < md->n; i++) {
				double e = md->c[o][i] * step->sol.t[i] / md->k[i];
				var += e * e;
			}
			step->predicted_sd[o] = sqrt(var);
			step->predicted_yield[o] = 1.0 - prsm_alloc_normal_out_fraction(&md->spec[o], md->nominal[o],
			                                                                step->predicted_sd[o]);
			if (md->has_target[o] && step->predicted_yield[o] < 1.0 - md->out_fraction[o] - 1e-12)
				step->meets = 0;
			if (!md->has_target[o] && !(step->sol.stack[o] <= step->limit[o] * (1.0 + 1e-9)))
				step->assembly_ok = 0;
		}
		step->meets &= step->assembly_ok;
	}
	free(p);
	return rc;
}

int prsm_alloc_dist_scale(prsm_dist *out, const prsm_dist *d, double r)
{
	const double c = prsm_dist_center(d);
	*out = *d;
	switch (d->kind) {
	case PRSM_DIST_NORMAL:
		out->p[1] = d->p[1] * r;
		break;
	case PRSM_DIST_TRUNCNORMAL:
		out->p[0] = c + (d->p[0] - c) * r;
		out->p[1] = d->p[1] * r;
		out->p[2] = isfinite(d->p[2]) ? c + (d->p[2] - c) * r : d->p[2];
		out->p[3] = isfinite(d->p[3]) ? c + (d->p[3] - c) * r : d->p[3];
		break;
	case PRSM_DIST_UNIFORM:
		out->p[0] = c + (d->p[0] - c) * r;
		out->p[1] = c + (d->p[1] - c) * r;
		break;
	case PRSM_DIST_TRIANGULAR:
		out->p[0] = c + (d->p[0] - c) * r;
		out->p[1] = c + (d->p[1] - c) * r;
		out->p[2] = c + (d->p[2] - c) * r;
		break;
	case PRSM_DIST_RAYLEIGH:
		out->p[0] = d->p[0] * r;
		break;
	default:
		return PRSM_EINVAL;
	}
	return 0;
}

int prsm_alloc_mc_linearise(prsm_alloc_model *md, const prsm_study *s, const prsm_alloc_mc_options *o,
                            prsm_error *err)
{
	const prsm_mc_model *mdl = &s->model;
	const size_t d = s->d;
	void *ws = NULL;
	unsigned flags;
	int rc = 0;
	double *x = malloc(d * sizeof *x), y0[PRSM_MC_MAX_OUTPUTS], yp[PRSM_MC_MAX_OUTPUTS],
	       ym[PRSM_MC_MAX_OUTPUTS];
	int alloc_of[PRSM_MC_MAX_GROUPS];
	double sum_sq[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_TOLERANCES] = {{0}};
	double sum_abs[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_TOLERANCES] = {{0}};
	if (!x || (mdl->workspace_alloc && mdl->workspace_alloc(&ws, mdl->ctx))) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	for (size_t g = 0; g < s->n_groups; g++)
		alloc_of[g] = -1;
	for (size_t i = 0; i < md->n; i++) {
		alloc_of[o->group[i]] = (int)i;
		const prsm_study_group *gr = &s->groups[o->group[i]];
		const prsm_dist *ref = &s->vars[gr->first_var].dist;
		prsm_dist tmp;
		if (prsm_alloc_dist_scale(&tmp, ref, 1.0)) {
			rc = prsm_error_set(err, PRSM_EINVAL, NULL, "%s: a %s distribution cannot be scaled to a "
			                    "tolerance width; use normal, truncnormal, uniform, triangular or rayleigh",
			                    gr->name, prsm_dist_name(ref->kind));
			goto cleanup;
		}
		md->t_ref[i] = prsm_dist_halfwidth(ref);
		double sde = prsm_study_sd_effective(s, gr->first_var);
		if (!(md->t_ref[i] > 0.0) || !(sde > 0.0)) {
			rc = prsm_error_set(err, PRSM_EINVAL, NULL, "%s: the distribution has no width", gr->name);
			goto cleanup;
		}
		md->k[i] = md->t_ref[i] / sde;
	}
	for (size_t v = 0; v < d; v++)
		x[v] = prsm_dist_center(&s->vars[v].dist);
	rc = mdl->eval(y0, &flags, mdl->ctx, ws, x);
	if (rc) {
		rc = prsm_error_set(err, rc, NULL, "the model failed at the distributions' centres");
		goto cleanup;
	}
	for (size_t q = 0; q < md->m; q++) {
		md->nominal[q] = y0[o->output[q]];
		md->fixed_var[q] = md->fixed_wc[q] = 0.0;
	}
	for (size_t v = 0; v < d; v++) {
		if (s->info[v].phase_of >= 0)
			continue;
		const double c = x[v], t = prsm_dist_halfwidth(&s->vars[v].dist);
		double delta[PRSM_MC_MAX_OUTPUTS] = {0};
		if (s->info[v].phase >= 0) {
			const size_t ph = (size_t)s->info[v].phase;
			const double ph0 = x[ph];
			x[v] = c + t;
			for (int k = 0; k < RADIAL_PHASES; k++) {
				x[ph] = 2.0 * M_PI * k / RADIAL_PHASES;
				rc = mdl->eval(yp, &flags, mdl->ctx, ws, x);
				if (rc)
					goto failed;
				for (size_t q = 0; q < md->m; q++)
					delta[q] = fmax(delta[q], fabs(yp[o->output[q]] - y0[o->output[q]]));
			}
			x[ph] = ph0;
		} else {
			x[v] = c + t;
			rc = mdl->eval(yp, &flags, mdl->ctx, ws, x);
			if (rc)
				goto failed;
			x[v] = c - t;
			rc = mdl->eval(ym, &flags, mdl->ctx, ws, x);
			if (rc)
				goto failed;
			for (size_t q = 0; q < md->m; q++)
				delta[q] = 0.5 * (yp[o->output[q]] - ym[o->output[q]]);
		}
		x[v] = c;
		const int a = alloc_of[s->vars[v].group];
		const double sde = prsm_study_sd_effective(s, v);
		for (size_t q = 0; q < md->m; q++) {
			if (a >= 0) {
				sum_sq[q][a] += (delta[q] / t) * (delta[q] / t);
				sum_abs[q][a] += fabs(delta[q]) / t;
				if (s->groups[s->vars[v].group].n_vars == 1 || (s->groups[s->vars[v].group].n_vars == 2 &&
				                                                s->info[v].phase >= 0))
					sum_abs[q][a] = delta[q] / t; /* one variable: keep the sign */
			} else {
				md->fixed_var[q] += (delta[q] / t * sde) * (delta[q] / t * sde);
				md->fixed_wc[q] += fabs(delta[q]);
			}
		}
		continue;
	failed:
		rc = prsm_error_set(err, rc, NULL, "the model failed with %s at its half-width", s->info[v].name);
		goto cleanup;
	}
	for (size_t q = 0; q < md->m; q++)
		for (size_t i = 0; i < md->n; i++)
			md->c[q][i] = md->stack == PRSM_ALLOC_RSS
			                  ? copysign(sqrt(sum_sq[q][i]), sum_abs[q][i])
			                  : sum_abs[q][i];
cleanup:
	if (ws && mdl->workspace_free)
		mdl->workspace_free(ws);
	free(x);
	return rc;
}

/* ---- Monte Carlo ------------------------------------------------------------------------- */

typedef struct {
	const prsm_alloc_mc_options *o;
	size_t offset;              /* samples of the runs before this one */
	size_t planned;
	double best;                /* best cost so far, NAN when none */
} progress_ctx;

static void on_progress(void *ctx, const prsm_progress *p)
{
	const progress_ctx *pc = ctx;
	prsm_progress q = PRSM_PROGRESS_INIT;
	q.done = pc->offset + p->done;
	q.planned = pc->planned;
	q.best = pc->best;
	pc->o->progress(pc->o->progress_ctx, &q);
}

/* Set the study's allocated distributions to the widths t (scaled from ref). */
static void apply_widths(prsm_study *s, const prsm_dist *ref, const prsm_alloc_model *md,
                         const prsm_alloc_mc_options *o, const double *t)
{
	for (size_t i = 0; i < md->n; i++) {
		const prsm_study_group *gr = &s->groups[o->group[i]];
		for (size_t v = gr->first_var; v < gr->first_var + gr->n_vars; v++)
			if (s->info[v].phase_of < 0)
				prsm_alloc_dist_scale(&s->vars[v].dist, &ref[v], t[i] / md->t_ref[i]);
	}
}

static int run_mc(prsm_alloc_step *st, prsm_study *s, const prsm_alloc_model *md,
                  const prsm_alloc_mc_options *o, size_t *kept, prsm_error *err)
{
	prsm_study_result *r = calloc(1, sizeof *r);
	if (!r)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int rc = prsm_study_service_run(o->service, r, s, o->study_source, o->study_source_len, err);
	if (rc == 0) {
		st->has_mc = 1;
		st->meets = st->assembly_ok; /* the given assembly tolerances: the linear stack */
		for (size_t q = 0; q < md->m; q++) {
			const prsm_stats_summary *sm = &r->out[o->output[q]].summary;
			st->samples = sm->n;
			st->mc_mean[q] = sm->mean;
			st->mc_sd[q] = sm->sd;
			st->mc_yield[q] = sm->yield;
			st->mc_low95[q] = sm->yield_low95;
			st->mc_high95[q] = sm->yield_high95;
			st->mc_confidence[q] = NAN;
			st->mc_meets[q] = 1;
			st->mc_interval[q] = PRSM_ALLOC_YIELD_WILSON;
			st->mc_method[q] = PRSM_RARE_MC;
			const prsm_study_output_result *res = &r->out[o->output[q]];
			if (res->has_rare && res->rare_ppm_from_rare) {
				/* the rare-event estimate of the spec (study_rare.c): judged on its interval's
				 * far end, or on the point when FORM/SORM give none */
				const double p0 = 1.0 - md->out_fraction[q];
				const double yl = 1.0 - 1e-6 * res->rare_ppm_high95, yh = 1.0 - 1e-6 * res->rare_ppm_low95;
				const int k = res->rare[1].present && (!res->rare[0].present || res->rare[1].pf >= res->rare[0].pf);
				st->mc_method[q] = res->rare[k].ran ? (int)res->rare[k].method : (int)res->rare[1 - k].method;
				st->mc_yield[q] = 1.0 - 1e-6 * res->rare_ppm;
				st->mc_low95[q] = yl;
				st->mc_high95[q] = yh;
				st->mc_interval[q] = isfinite(yl) && isfinite(yh) ? PRSM_ALLOC_YIELD_RARE : PRSM_ALLOC_YIELD_RARE_POINT;
				if (md->has_target[q]) {
					if (st->mc_interval[q] == PRSM_ALLOC_YIELD_RARE) {
						double se = (yh - yl) / (2.0 * PRSM_STATS_Z95);
						st->mc_meets[q] = yl >= p0;
						st->mc_confidence[q] = se > 0.0 ? gsl_cdf_ugaussian_P((st->mc_yield[q] - p0) / se)
						                                : (st->mc_yield[q] >= p0 ? 1.0 : 0.0);
					} else {
						st->mc_meets[q] = st->mc_yield[q] >= p0;
					}
					if (!st->mc_meets[q])
						st->meets = 0;
				}
				continue;
			}
			if (md->has_target[q]) {
				/* decided on the evidence: the Wilson interval's lower end (see alloc_mc.h) */
				const double p0 = 1.0 - md->out_fraction[q];
				st->mc_meets[q] = sm->yield_low95 >= p0;
				st->mc_confidence[q] = sm->n > 0 ? gsl_cdf_ugaussian_P((sm->yield - p0) /
				                                                        sqrt(p0 * (1.0 - p0) / (double)sm->n))
				                                 : NAN;
				if (!st->mc_meets[q])
					st->meets = 0;
			}
		}
		*kept = r->run.n;
		if (r->run.stop == PRSM_STOP_TIME_CAP)
			rc = PRSM_ENOCONVERGE; /* marks "time cap" for the caller; err untouched */
		prsm_study_result_free(r);
	}
	free(r);
	return rc;
}

int prsm_alloc_mc_run(prsm_alloc_mc_result *out, prsm_study *s, const prsm_alloc_model *md,
                      const prsm_alloc_mc_options *o, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->best = -1;
	const double t0 = prsm_clock_seconds();
	prsm_dist *ref = malloc(s->d * sizeof *ref);
	prsm_study_output saved_out[PRSM_MC_MAX_OUTPUTS];
	const prsm_mc_options saved_mc = s->mc;
	const prsm_sens_options saved_sens = s->sens;
	int rc = 0;
	if (!ref)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	for (size_t v = 0; v < s->d; v++)
		ref[v] = s->vars[v].dist;
	memcpy(saved_out, s->outputs, sizeof saved_out);
	for (size_t q = 0; q < md->m; q++) {
		s->outputs[o->output[q]].has_spec = md->spec[q].has_lower || md->spec[q].has_upper;
		s->outputs[o->output[q]].spec = md->spec[q];
	}
	s->sens.src = s->sens.stack = s->sens.sobol = 0;
	s->mc.n_targets = 0;
	s->mc.cancel = o->cancel;
	progress_ctx pc = {o, 0, s->mc.samples * (size_t)(o->max_corrections + 1), NAN};
	if (o->progress) {
		s->mc.progress = on_progress;
		s->mc.progress_ctx = &pc;
	} else {
		s->mc.progress = NULL;
	}
	int has_target = 0;
	for (size_t q = 0; q < md->m; q++)
		has_target |= md->has_target[q];
	const int verify = o->verify && has_target;
	double f = 1.0, f_ok = NAN, f_fail = NAN, g_ok = NAN, g_fail = NAN;
	int last_side = 0; /* +1: the last step met every target, -1: it missed one */
	out->stop = verify ? PRSM_ALLOC_STOP_MAX_CORRECTIONS : PRSM_ALLOC_STOP_LINEAR;
	for (int k = 0; k < (verify ? o->max_corrections + 1 : 1) && k < PRSM_ALLOC_MAX_STEPS; k++) {
		if (prsm_cancel_requested(o->cancel)) {
			out->stop = PRSM_ALLOC_STOP_CANCELLED;
			break;
		}
		double left = 0.0; /* time left, 0: no cap */
		if (o->max_time_s > 0.0) {
			left = o->max_time_s - (prsm_clock_seconds() - t0);
			if (left <= 0.0 && k > 0) {
				out->stop = PRSM_ALLOC_STOP_TIME_CAP;
				break;
			}
			left = fmax(left, 1e-9); /* the linear allocation is always tried */
		}
		prsm_alloc_step *st = &out->steps[out->n_steps];
		prsm_error e2 = PRSM_ERROR_INIT;
		int arc = prsm_alloc_model_allocate(st, md, f, o->cancel, left, &e2);
		if (arc == PRSM_ECANCELLED) {
			out->stop = PRSM_ALLOC_STOP_CANCELLED;
			break;
		}
		if (arc && st->sol.time_cap) {
			out->stop = PRSM_ALLOC_STOP_TIME_CAP;
			break;
		}
		if (arc) {
			if (k == 0) {
				rc = prsm_error_set(err, arc, e2.pointer[0] ? e2.pointer : NULL, "%s", e2.message);
				goto cleanup;
			}
			/* shrinking went past what the lower bounds allow */
			out->stop = PRSM_ALLOC_STOP_INFEASIBLE;
			break;
		}
		out->n_steps++;
		if (!verify) {
			out->best = 0;
			break;
		}
		if (o->max_time_s > 0.0) {
			left = o->max_time_s - (prsm_clock_seconds() - t0);
			if (left <= 0.0) {
				if (k > 0)
					out->n_steps--; /* the linear allocation stays, unverified */
				out->stop = PRSM_ALLOC_STOP_TIME_CAP;
				break;
			}
			s->mc.time_cap_s = left;
		}
		apply_widths(s, ref, md, o, st->sol.t);
		size_t ran = 0;
		pc.offset = out->samples_total;
		int mrc = run_mc(st, s, md, o, &ran, err);
		out->samples_total += ran;
		if (mrc == PRSM_ECANCELLED) {
			out->n_steps--;
			out->stop = PRSM_ALLOC_STOP_CANCELLED;
			break;
		}
		if (mrc == PRSM_ENOCONVERGE && st->has_mc) {
			out->stop = PRSM_ALLOC_STOP_TIME_CAP;
			break;
		}
		if (mrc) {
			rc = mrc;
			goto cleanup;
		}
		/* g: the smallest margin of the yield's Wilson lower end over its target (what decides) */
		double g = INFINITY;
		for (size_t q = 0; q < md->m; q++)
			if (md->has_target[q])
				g = fmin(g, st->mc_low95[q] - (1.0 - md->out_fraction[q]));
		if (st->meets) {
			if (out->best < 0 || st->scale > out->steps[out->best].scale)
				out->best = out->n_steps - 1;
			pc.best = out->steps[out->best].sol.total_cost;
			if (last_side > 0 && !isnan(f_fail))
				g_fail *= 0.5; /* Illinois: the failing end kept twice, so halve its margin */
			f_ok = f, g_ok = g, last_side = 1;
			/* a larger f changes nothing when every tolerance is at its upper bound or every
			 * target's constraint is slack (the given assembly tolerances or the bounds decide) */
			int all_upper = 1, targets_slack = 1;
			for (size_t i = 0; i < md->n; i++)
				all_upper &= st->sol.at_bound[i] == 1;
			for (size_t q = 0; q < md->m; q++)
				if (md->has_target[q] && !(st->sol.stack[q] < st->limit[q] * (1.0 - 1e-9)))
					targets_slack = 0;
			if (all_upper || (targets_slack && isnan(f_fail))) {
				out->stop = PRSM_ALLOC_STOP_CONVERGED;
				break;
			}
		} else {
			if (last_side < 0 && !isnan(f_ok))
				g_ok *= 0.5; /* Illinois: the accepted end kept twice */
			f_fail = f, g_fail = g, last_side = -1;
		}
		if (isnan(f_fail)) {
			f = f_ok * GROW;
		} else if (isnan(f_ok)) {
			f = f_fail * SHRINK;
		} else {
			double lo = log(f_ok), hi = log(f_fail);
			if (fabs(hi - lo) <= log1p(o->scale_rtol)) {
				out->stop = PRSM_ALLOC_STOP_CONVERGED;
				break;
			}
			/* secant on ln f (Illinois regula falsi: the margin of an end kept twice in a row
			 * is halved, so a step-like margin, the Monte Carlo yield of a finite sample, still
			 * closes the bracket), kept in the inner 10..90 % of the bracket */
			double u = g_ok != g_fail ? lo + (hi - lo) * g_ok / (g_ok - g_fail) : 0.5 * (lo + hi);
			double a = fmin(lo, hi), b = fmax(lo, hi);
			u = fmin(fmax(u, a + 0.1 * (b - a)), b - 0.1 * (b - a));
			f = exp(u);
		}
	}
	if (out->best < 0 && out->n_steps > 0)
		out->best = 0; /* nothing met the target: report the linear allocation */
	out->converged = out->best >= 0 && out->steps[out->best].meets &&
	                 (out->stop == PRSM_ALLOC_STOP_CONVERGED || out->stop == PRSM_ALLOC_STOP_LINEAR);
	if (out->stop == PRSM_ALLOC_STOP_CANCELLED) {
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the allocation was cancelled");
	} else if (out->best < 0) {
		/* the time cap ran out before the linear allocation was solved */
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL,
		                    "the time cap of %.3g s ran out before the linear allocation was solved",
		                    o->max_time_s);
	}
cleanup:
	for (size_t v = 0; v < s->d; v++)
		s->vars[v].dist = ref[v];
	memcpy(s->outputs, saved_out, sizeof saved_out);
	s->mc = saved_mc;
	s->sens = saved_sens;
	out->elapsed_s = prsm_clock_seconds() - t0;
	free(ref);
	return rc;
}
