/*
 * vib_analysis.c: the analyses of one operating point (docs/model §8.4): the time response, the
 * steady state after a transient (Poincaré section at the forcing period, period classification,
 * extremes refined at the zeros of the rates, spectrum with the named frequencies, phase portrait,
 * time shares of contact loss) and the largest Lyapunov exponents (Benettin's variational method
 * with QR every period, and the two-trajectory method as one stacked system).
 */
#include "dyn/vib_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_fft_real.h>

double vib_default_period_tol(const prsm_vib_model *m)
{
	return m->par.kind == PRSM_VIB_GEAR_PAIR ? 1e-6 : 1e-4;
}

int prsm_vib_period_of(const double *P, int n, int size, double tol, int max_period, double *distance)
{
	double d1 = NAN;
	/* a period must show at least twice in the record: m <= n / 2 */
	for (int m = 1; m <= max_period && 2 * m <= n; m++) {
		double dmax = 0.0;
		for (int i = 0; i + m < n; i++)
			for (int k = 0; k < size; k++)
				dmax = fmax(dmax, fabs(P[(size_t)(i + m) * size + k] - P[(size_t)i * size + k]));
		if (m == 1)
			d1 = dmax;
		if (dmax < tol) {
			if (distance != NULL)
				*distance = dmax;
			return m;
		}
	}
	if (distance != NULL)
		*distance = d1;
	return 0;
}

int vib_periods(vib_int *it, double tau0, double T, int n, double *poincare)
{
	const int size = vib_reduced_size(it->c);
	for (int i = 1; i <= n; i++) {
		const int rc = vib_int_advance(it, tau0 + i * T);
		if (rc)
			return rc;
		if (poincare != NULL)
			vib_project(it->c, it->y, poincare + (size_t)(i - 1) * size);
	}
	return 0;
}

static void effort_add(prsm_vib_effort *a, const prsm_vib_effort *b)
{
	a->steps += b->steps;
	a->rejected += b->rejected;
	a->rhs_evaluations += b->rhs_evaluations;
	a->events += b->events;
	a->switches += b->switches;
}

/* ---- time response ---- */

typedef struct {
	const prsm_vib_model *m;
	prsm_vib_response *r;
	double to_tau;               /* model time unit -> tau */
	double step;                 /* output step, model unit */
	double end;
	size_t next;
	double ybuf[PRSM_VIB_STATE_MAX];
} response_ctx;

static void response_store(response_ctx *x, vib_int *it, size_t k, double tau, const double *y)
{
	prsm_vib_response *r = x->r;
	const vib_core *c = it->c;
	const int n = c->n, Z = r->rollers, nc = c->nc;
	r->tau[k] = tau;
	r->time_s[k] = c->pair ? tau : tau / c->wref;
	memcpy(r->state + k * (size_t)n, y, (size_t)n * sizeof *y);
	double *mf = r->mesh_force + k * Z, *md = r->mesh_deflection + k * Z;
	unsigned char *lost = r->contact_lost + k * (size_t)nc;
	if (c->pair) {
		md[0] = y[0];
		mf[0] = it->kap[0] * vib_dead(y[0]);
		lost[0] = y[0] <= 1.0;
		r->axial_deflection[k] = NAN;
		r->thread_force_N[k] = NAN;
		return;
	}
	/* the forces (vib_forces) and the guards (vib_contacts) with one evaluation of the mesh errors */
	double Fth = c->F0;
	if (c->axial)
		Fth = c->Fth_scale * (vib_dead(y[vib_iY(c)]) + 2.0 * c->zeta_a * y[vib_iW(c)]);
	r->axial_deflection[k] = c->axial ? y[vib_iY(c)] : NAN;
	r->thread_force_N[k] = Fth;
	int g = 0;
	if (c->gear) {
		double e[PRSM_VIB_ROLLERS_MAX], ed[PRSM_VIB_ROLLERS_MAX];
		vib_mesh_errors(c, tau, e, ed);
		const double Fscale = 2.0 * c->kbar * c->bg;
		for (int j = 0; j < Z; j++) {
			const double xj = y[vib_iP(c, 0)] + y[vib_iP(c, j + 1)], xr = xj - e[j];
			md[j] = xj;
			mf[j] = Fscale * (it->kap[j] * vib_dead(xr) + c->two_zeta_g * (y[vib_iV(c, 0)] + y[vib_iV(c, j + 1)] - ed[j]));
			lost[g++] = xr <= 1.0;
		}
	} else {
		for (int j = 0; j < Z; j++) {
			md[j] = y[vib_iP(c, 0)] + y[vib_iP(c, j + 1)];
			mf[j] = NAN;
		}
	}
	if (c->axial)
		lost[g] = y[vib_iY(c)] <= 1.0;
}

static double output_time(const response_ctx *x, size_t k)
{
	return k + 1 == x->r->points ? x->end : (double)k * x->step;
}

static int response_obs(void *ctx, vib_int *it, double tau0, const double *y0, const double *f0, double tau1,
                        const double *y1, const double *f1)
{
	response_ctx *x = ctx;
	const double h = tau1 - tau0;
	while (x->next < x->r->points) {
		const double ts = output_time(x, x->next) * x->to_tau;
		if (ts > tau1 + 1e-12 * fmax(1.0, fabs(tau1)))
			break;
		const double s = fmin(1.0, fmax(0.0, (ts - tau0) / h));
		vib_hermite(it->c, y0, f0, y1, f1, h, s, x->ybuf);
		response_store(x, it, x->next, ts, x->ybuf);
		x->next++;
	}
	return 0;
}

void prsm_vib_response_free(prsm_vib_response *r)
{
	free(r->tau);
	free(r->time_s);
	free(r->state);
	free(r->mesh_deflection);
	free(r->mesh_force);
	free(r->axial_deflection);
	free(r->thread_force_N);
	free(r->contact_lost);
	memset(r, 0, sizeof *r);
}

int prsm_vib_time_response(prsm_vib_response *out, const prsm_vib_model *m, const double *initial_state, double end,
                           double output_step, const prsm_vib_integration *integ, const prsm_cancel_flag *cancel,
                           prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const prsm_vib_integration idef = PRSM_VIB_INTEGRATION_INIT;
	if (integ == NULL)
		integ = &idef;
	if (!(end > 0.0 && isfinite(end)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/time/end_s", "the end time must be > 0 (got %g)", end);
	if (!(output_step > 0.0 && isfinite(output_step)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/time/output_step_s", "the output step must be > 0 (got %g)",
		                      output_step);
	const double q = floor(end / output_step * (1.0 + 1e-12));
	if (!(q < PRSM_VIB_OUTPUT_POINTS_MAX))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/time/output_step_s",
		                      "%g every %g is more than %d output points: raise the output step", end, output_step,
		                      PRSM_VIB_OUTPUT_POINTS_MAX);
	size_t npts = (size_t)q + 1;
	if ((double)(npts - 1) * output_step < end * (1.0 - 1e-12))
		npts++;
	const vib_core *c = &m->c;
	const int n = c->n, Z = c->Z;
	out->points = npts;
	out->states = n;
	out->rollers = Z;
	out->contacts = c->nc;
	out->tau = malloc(npts * sizeof(double));
	out->time_s = malloc(npts * sizeof(double));
	out->state = malloc(npts * (size_t)n * sizeof(double));
	out->mesh_deflection = malloc(npts * (size_t)Z * sizeof(double));
	out->mesh_force = malloc(npts * (size_t)Z * sizeof(double));
	out->axial_deflection = malloc(npts * sizeof(double));
	out->thread_force_N = malloc(npts * sizeof(double));
	out->contact_lost = malloc(npts * (size_t)(c->nc > 0 ? c->nc : 1));
	if (!out->tau || !out->time_s || !out->state || !out->mesh_deflection || !out->mesh_force ||
	    !out->axial_deflection || !out->thread_force_N || !out->contact_lost) {
		prsm_vib_response_free(out);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu output points", npts);
	}
	vib_int it;
	if (vib_int_init(&it, m, 0, 1, integ, cancel)) {
		prsm_vib_response_free(out);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the integrator");
	}
	double y0[PRSM_VIB_STATE_MAX];
	if (initial_state != NULL)
		memcpy(y0, initial_state, (size_t)n * sizeof *y0);
	else
		prsm_vib_static_state(m, y0);
	vib_int_set(&it, 0.0, y0);
	response_ctx x;
	memset(&x, 0, sizeof x);
	x.m = m;
	x.r = out;
	x.to_tau = m->par.kind == PRSM_VIB_GEAR_PAIR ? 1.0 : c->wref;
	x.step = output_step;
	x.end = end;
	response_store(&x, &it, 0, 0.0, y0);
	x.next = 1;
	it.obs = response_obs;
	it.obs_ctx = &x;
	int rc = vib_int_advance(&it, end * x.to_tau);
	out->effort = it.effort;
	if (rc) {
		vib_int_error(&it, rc, err);
		vib_int_free(&it);
		prsm_vib_response_free(out);
		return rc;
	}
	/* the last output exactly at the end */
	while (x.next < npts)
		response_store(&x, &it, x.next++, end * x.to_tau, it.y);
	vib_int_free(&it);
	return 0;
}

/* ---- steady state ---- */

#define EXTREMES_MAX (2 * PRSM_VIB_ROLLERS_MAX + 4)

typedef struct {
	const prsm_vib_model *m;     /* the integrator's model */
	const vib_core *c;
	double tau_start, T;
	int periods, sps;
	size_t n_samples, next;
	double *samp_x, *samp_v;     /* main observable and its rate */
	int obs, obs_index;
	/* extremes */
	int nx;
	int light;                   /* 1: only the main observable */
	prsm_vib_extreme ex[EXTREMES_MAX];
	int refine[EXTREMES_MAX];    /* 1: refined at the zeros (sign changes) of its rate */
	int have[EXTREMES_MAX];
	double sum[EXTREMES_MAX], sum2[EXTREMES_MAX];
	/* contacts: time in each region (-1, 0, +1) */
	double region_time[PRSM_VIB_CONTACTS_MAX][3];
	double ya[PRSM_VIB_STATE_MAX], yb[PRSM_VIB_STATE_MAX];
	int rate_index;              /* for the root finder */
	int contact_index;
	double boundary;
	vib_int *it;
} recorder;

/* the observable values of the list at a state */
static void rec_values(recorder *r, const double *kap, double tau, const double *y, double *val)
{
	const vib_core *c = r->c;
	double F[PRSM_VIB_ROLLERS_MAX], Fth = NAN;
	int forces = 0;
	for (int i = 0; i < r->nx; i++)
		forces |= r->ex[i].observable == PRSM_VIB_OBS_MESH_FORCE || r->ex[i].observable == PRSM_VIB_OBS_THREAD_FORCE;
	if (forces)
		vib_forces(c, kap, tau, y, F, &Fth);
	for (int i = 0; i < r->nx; i++) {
		const int o = r->ex[i].observable, j = r->ex[i].index;
		double v;
		if (c->pair) {
			v = o == PRSM_VIB_OBS_MESH_DEFLECTION ? y[0] : (o == PRSM_VIB_OBS_MESH_RATE ? y[1] : F[0]);
		} else {
			switch (o) {
			case PRSM_VIB_OBS_MESH_DEFLECTION: v = y[vib_iP(c, 0)] + y[vib_iP(c, j + 1)]; break;
			case PRSM_VIB_OBS_MESH_RATE: v = y[vib_iV(c, 0)] + y[vib_iV(c, j + 1)]; break;
			case PRSM_VIB_OBS_MESH_FORCE: v = F[j]; break;
			case PRSM_VIB_OBS_AXIAL_DEFLECTION: v = y[vib_iY(c)]; break;
			case PRSM_VIB_OBS_AXIAL_RATE: v = y[vib_iW(c)]; break;
			default: v = Fth; break;
			}
		}
		val[i] = v;
	}
}

/* the rate of an observable (its sign is what matters) from the state y and its derivative f
 * (scaled time) */
static double rate_of(const vib_core *c, const double *kap, double tau, int obs, int j, const double *y, const double *f)
{
	if (c->pair) {
		switch (obs) {
		case PRSM_VIB_OBS_MESH_DEFLECTION: return y[1];
		case PRSM_VIB_OBS_MESH_RATE: return f[1];
		default: return (fabs(y[0]) > 1.0 ? kap[0] : 0.0) * y[1]; /* kappa h(x) */
		}
	}
	const int V0 = vib_iV(c, 0), Vj = vib_iV(c, j + 1);
	switch (obs) {
	case PRSM_VIB_OBS_MESH_DEFLECTION: return y[V0] + y[Vj];
	case PRSM_VIB_OBS_MESH_RATE: return f[V0] + f[Vj];
	case PRSM_VIB_OBS_AXIAL_DEFLECTION: return y[vib_iW(c)];
	case PRSM_VIB_OBS_AXIAL_RATE: return f[vib_iW(c)];
	case PRSM_VIB_OBS_THREAD_FORCE: {
		/* F_th = k_a b_a (h(Y) + 2 zeta_a W) */
		const double Y = y[vib_iY(c)];
		return (fabs(Y) > 1.0 ? f[vib_iY(c)] : 0.0) + 2.0 * c->zeta_a * f[vib_iW(c)];
	}
	default: {
		/* F_j = 2 k-bar b_g (kappa_j h(x_j - e_j) + 2 zeta_g (x_j' - e_j')) */
		double e = 0.0, ed = 0.0, edd = 0.0;
		if (c->eg != 0.0) {
			const double s = sin(c->we * tau), co = cos(c->we * tau);
			e = c->eg * (s * c->cphase[j] + co * c->sphase[j]);
			ed = c->eg * c->we * (co * c->cphase[j] - s * c->sphase[j]);
			edd = -c->we * c->we * e;
		}
		const double xr = y[vib_iP(c, 0)] + y[vib_iP(c, j + 1)] - e;
		return (fabs(xr) > 1.0 ? kap[j] : 0.0) * (y[V0] + y[Vj] - ed) + c->two_zeta_g * (f[V0] + f[Vj] - edd);
	}
	}
}

static double rate_fn(void *ctx, const vib_core *c, double tau, const double *y)
{
	recorder *r = ctx;
	const int o = r->ex[r->rate_index].observable;
	double f[PRSM_VIB_STATE_MAX];
	if (o != PRSM_VIB_OBS_MESH_DEFLECTION && o != PRSM_VIB_OBS_AXIAL_DEFLECTION)
		vib_rhs(c, r->it->kap, NULL, tau, y, f, NULL);
	return rate_of(c, r->it->kap, tau, o, r->ex[r->rate_index].index, y, f);
}

static double guard_fn(void *ctx, const vib_core *c, double tau, const double *y)
{
	recorder *r = ctx;
	double g[PRSM_VIB_CONTACTS_MAX];
	vib_contacts(c, tau, y, g);
	return g[r->contact_index] - r->boundary;
}

static void rec_update(recorder *r, int i, double v)
{
	if (!r->have[i]) {
		r->ex[i].min = r->ex[i].max = v;
		r->have[i] = 1;
	} else {
		r->ex[i].min = fmin(r->ex[i].min, v);
		r->ex[i].max = fmax(r->ex[i].max, v);
	}
}

static void rec_sample(recorder *r, vib_int *it, double tau, const double *y)
{
	double val[EXTREMES_MAX];
	rec_values(r, it->kap, tau, y, val);
	for (int i = 0; i < r->nx; i++) {
		rec_update(r, i, val[i]);
		r->sum[i] += val[i];
		r->sum2[i] += val[i] * val[i];
	}
	const size_t k = r->next;
	r->samp_x[k] = prsm_vib_observable(r->m, r->obs, r->obs_index, tau, y);
	if (r->obs == PRSM_VIB_OBS_MESH_DEFLECTION || r->obs == PRSM_VIB_OBS_AXIAL_DEFLECTION) {
		r->samp_v[k] = prsm_vib_observable(r->m, r->obs == PRSM_VIB_OBS_MESH_DEFLECTION ? PRSM_VIB_OBS_MESH_RATE
		                                                                                  : PRSM_VIB_OBS_AXIAL_RATE,
		                                   r->obs_index, tau, y);
	} else {
		r->samp_v[k] = NAN;
	}
}

static int rec_obs(void *ctx, vib_int *it, double tau0, const double *y0, const double *f0, double tau1,
                   const double *y1, const double *f1)
{
	recorder *r = ctx;
	const vib_core *c = it->c;
	const double h = tau1 - tau0;
	/* samples */
	while (r->next < r->n_samples) {
		const double ts = r->tau_start + (double)r->next * r->T / r->sps;
		if (ts > tau1 + 1e-12 * fmax(1.0, fabs(tau1)))
			break;
		const double s = fmin(1.0, fmax(0.0, (ts - tau0) / h));
		vib_hermite(c, y0, f0, y1, f1, h, s, r->ya);
		rec_sample(r, it, ts, r->ya);
		r->next++;
	}
	/* extremes: the step end, and the zeros of a position's rate inside the step */
	double val[EXTREMES_MAX];
	rec_values(r, it->kap, tau1, y1, val);
	for (int i = 0; i < r->nx; i++) {
		rec_update(r, i, val[i]);
		if (!r->refine[i])
			continue;
		const double r0 = rate_of(c, it->kap, tau0, r->ex[i].observable, r->ex[i].index, y0, f0);
		const double r1 = rate_of(c, it->kap, tau1, r->ex[i].observable, r->ex[i].index, y1, f1);
		if (!(r0 * r1 < 0.0))
			continue;
		/* only where it can be a new extreme (the step is a fraction of a period) */
		const double range = r->ex[i].max - r->ex[i].min;
		const double v0 = prsm_vib_observable(r->m, r->ex[i].observable, r->ex[i].index, tau0, y0);
		const double vend = fmax(v0, val[i]), vlow = fmin(v0, val[i]);
		if (r0 > 0.0 && vend < r->ex[i].max - 0.25 * range)
			continue;
		if (r0 < 0.0 && vlow > r->ex[i].min + 0.25 * range)
			continue;
		r->rate_index = i;
		const double s = vib_int_locate(it, tau0, y0, f0, h, r0, r1, rate_fn, r, r->yb);
		double v2[EXTREMES_MAX];
		rec_values(r, it->kap, tau0 + s * h, r->yb, v2);
		rec_update(r, i, v2[i]);
	}
	/* contact regions */
	double g0[PRSM_VIB_CONTACTS_MAX], g1[PRSM_VIB_CONTACTS_MAX];
	vib_contacts(c, tau0, y0, g0);
	vib_contacts(c, tau1, y1, g1);
	for (int k = 0; k < c->nc; k++) {
		const signed char a = vib_region(g0[k]), b = vib_region(g1[k]);
		if (a == b || it->locate) {
			/* located crossings end the step: the step is in its start region */
			r->region_time[k][a + 1] += h;
			continue;
		}
		r->contact_index = k;
		r->boundary = a > 0 ? 1.0 : (a < 0 ? -1.0 : (b > 0 ? 1.0 : -1.0));
		const double s = vib_int_locate(it, tau0, y0, f0, h, g0[k] - r->boundary, g1[k] - r->boundary, guard_fn, r,
		                                r->yb);
		r->region_time[k][a + 1] += s * h;
		r->region_time[k][b + 1] += (1.0 - s) * h;
	}
	return 0;
}

void prsm_vib_steady_free(prsm_vib_steady *s)
{
	free(s->poincare);
	free(s->poincare_observable);
	free(s->extreme);
	free(s->spectrum_frequency);
	free(s->spectrum_amplitude);
	free(s->portrait_x);
	free(s->portrait_v);
	free(s->loss_share);
	free(s->back_share);
	free(s->final_state);
	memset(s, 0, sizeof *s);
}

/* One-sided amplitude of the line at f cycles per sample in x[0..n) (§8.4 "Spectra").
 * f = 0: the window-weighted mean. Otherwise the mean is removed first (it would leak into every
 * line that does not fall on a bin), and:
 *   - a Hann record (w given as Hann: a non-periodic response) is used as it is;
 *   - a rectangular record is cut to the longest tail holding a whole number of the line's
 *     cycles when the line's period is a whole number of samples (the forcing clock's
 *     subharmonics: k sps samples); over whole cycles of both the line and the response's
 *     period the transform is exact: a period-1 response has no subharmonic lines, not the
 *     leakage of the forcing line and the mean into them;
 *   - a line whose period is not a whole number of samples (a mechanism or TE order) gets a
 *     Hann window over the whole record, whose leakage falls off as the cube of the distance. */
static double line_amplitude(const double *x, const double *w, size_t n, double wsum, double f, int hann)
{
	if (n == 0)
		return NAN;
	if (f == 0.0) {
		double acc = 0.0;
		for (size_t i = 0; i < n; i++)
			acc += w[i] * x[i];
		return fabs(acc) / wsum;
	}
	size_t first = 0, len = n;
	int use_hann = hann;
	if (!hann) {
		const double P = 1.0 / f, Pr = round(P);
		if (Pr >= 2.0 && fabs(P - Pr) <= 1e-9 * Pr && (size_t)Pr <= n) {
			len = n / (size_t)Pr * (size_t)Pr;
			first = n - len;
		} else {
			use_hann = 1;
		}
	}
	double mean = 0.0, ws = 0.0;
	for (size_t i = 0; i < len; i++) {
		const double wi = hann ? w[first + i] : use_hann ? 0.5 - 0.5 * cos(2.0 * M_PI * ((double)i + 0.5) / (double)len) : 1.0;
		mean += wi * x[first + i];
		ws += wi;
	}
	mean /= ws;
	double re = 0.0, im = 0.0;
	for (size_t i = 0; i < len; i++) {
		const double wi = hann ? w[first + i] : use_hann ? 0.5 - 0.5 * cos(2.0 * M_PI * ((double)i + 0.5) / (double)len) : 1.0;
		const double ph = 2.0 * M_PI * f * (double)(first + i);
		const double v = wi * (x[first + i] - mean);
		re += v * cos(ph);
		im -= v * sin(ph);
	}
	return 2.0 * hypot(re, im) / ws;
}

static void add_line(prsm_vib_steady *s, const char *name, double order, double freq, double amp)
{
	if (s->lines >= PRSM_VIB_LINES_MAX)
		return;
	prsm_vib_line *l = &s->line[s->lines++];
	snprintf(l->name, sizeof l->name, "%s", name);
	l->order_per_rev = order;
	l->frequency = freq;
	l->amplitude = amp;
}

/* §8.4 "Spectra" of the main observable's samples */
static int spectrum(prsm_vib_steady *s, const prsm_vib_model *m, const double *samples, int sps, int periods,
                    double T)
{
	const int per = s->classification == PRSM_VIB_PERIODIC && s->period > 0 ? s->period : 1;
	int used = periods / per * per;
	if (used < 1)
		used = periods;
	s->spectrum_periods = used;
	s->spectrum_window_hann = s->classification != PRSM_VIB_PERIODIC;
	const size_t n = (size_t)used * sps;
	double *x = malloc(n * sizeof *x), *w = malloc(n * sizeof *w);
	if (x == NULL || w == NULL) {
		free(x);
		free(w);
		return PRSM_ENOMEM;
	}
	/* the last `used` periods of the record */
	const size_t first = (size_t)(periods - used) * sps;
	double wsum = 0.0;
	for (size_t i = 0; i < n; i++) {
		w[i] = s->spectrum_window_hann ? 0.5 - 0.5 * cos(2.0 * M_PI * ((double)i + 0.5) / n) : 1.0;
		wsum += w[i];
		x[i] = samples[first + i];
	}
	/* frequency unit: gear pair rad per tau, reduced Hz */
	const int pair = m->par.kind == PRSM_VIB_GEAR_PAIR;
	const double dt_tau = T / sps;
	const double to_freq = pair ? 2.0 * M_PI / dt_tau : m->c.wref / dt_tau; /* cycles per sample -> unit */
	/* full spectrum */
	const size_t bins = n / 2 + 1;
	s->spectrum_bins = (int)bins;
	s->spectrum_frequency = malloc(bins * sizeof(double));
	s->spectrum_amplitude = malloc(bins * sizeof(double));
	double *buf = malloc(n * sizeof(double));
	gsl_fft_real_wavetable *wt = gsl_fft_real_wavetable_alloc(n);
	gsl_fft_real_workspace *ws = gsl_fft_real_workspace_alloc(n);
	int rc = 0;
	if (!s->spectrum_frequency || !s->spectrum_amplitude || !buf || !wt || !ws) {
		rc = PRSM_ENOMEM;
		goto done;
	}
	for (size_t i = 0; i < n; i++)
		buf[i] = w[i] * x[i];
	gsl_fft_real_transform(buf, 1, n, wt, ws);
	/* halfcomplex: buf[0] = X_0, buf[2k-1] = Re X_k, buf[2k] = Im X_k */
	s->spectrum_frequency[0] = 0.0;
	s->spectrum_amplitude[0] = fabs(buf[0]) / wsum;
	for (size_t k = 1; k < bins; k++) {
		const double re = buf[2 * k - 1], im = (2 * k < n) ? buf[2 * k] : 0.0;
		s->spectrum_frequency[k] = (double)k / n * (pair ? 2.0 * M_PI / dt_tau : m->c.wref / dt_tau);
		s->spectrum_amplitude[k] = ((2 * k == n) ? 1.0 : 2.0) * hypot(re, im) / wsum;
	}
	(void)to_freq;
	/* named lines (§8.4): the frequency in cycles per sample */
	const double f_forcing = 1.0 / sps; /* the clock's frequency */
	char name[40];
	if (pair) {
		for (int i = 1; i <= 4; i++) {
			snprintf(name, sizeof name, i == 1 ? "forcing" : "harmonic_%d", i);
			add_line(s, name, NAN, i * m->c.Omega, line_amplitude(x, w, n, wsum, i * f_forcing, s->spectrum_window_hann));
		}
		for (int k = 2; k <= 8; k++) {
			snprintf(name, sizeof name, "subharmonic_%d", k);
			add_line(s, name, NAN, m->c.Omega / k, line_amplitude(x, w, n, wsum, f_forcing / k, s->spectrum_window_hann));
		}
		const double fn = 1.0 / (2.0 * M_PI) * dt_tau; /* natural frequency 1 rad per tau */
		add_line(s, "natural", NAN, 1.0, fn < 0.5 ? line_amplitude(x, w, n, wsum, fn, s->spectrum_window_hann) : NAN);
		add_line(s, "mean", NAN, 0.0, line_amplitude(x, w, n, wsum, 0.0, s->spectrum_window_hann));
	} else {
		const prsm_vib_params *P = &m->par;
		const double ws_rev = P->screw_speed_rad_s / (2.0 * M_PI); /* screw rev per s */
		const double dt_s = dt_tau / m->c.wref;
		const double k = P->carrier_ratio, Z = P->rollers;
		const struct {
			const char *name;
			double order;
		} mech[] = {{"mesh", P->teeth_ring * k},
		            {"mesh_harmonic_2", 2.0 * P->teeth_ring * k},
		            {"mesh_harmonic_3", 3.0 * P->teeth_ring * k},
		            {"screw", 1.0},
		            {"screw_minus_carrier", 1.0 - k},
		            {"carrier", k},
		            {"roller_spin", P->ring_gear_ratio * k},
		            {"roller_pass_screw", Z * (1.0 - k)},
		            {"roller_pass_nut", Z * k}};
		for (size_t i = 0; i < sizeof mech / sizeof mech[0]; i++) {
			const double fHz = mech[i].order * ws_rev;
			const double fs = fHz * dt_s;
			add_line(s, mech[i].name, mech[i].order, fHz, fs < 0.5 ? line_amplitude(x, w, n, wsum, fs, s->spectrum_window_hann) : NAN);
		}
		if (s->clock == PRSM_VIB_CLOCK_MESH)
			for (int kk = 2; kk <= 8; kk++) {
				snprintf(name, sizeof name, "mesh_subharmonic_%d", kk);
				const double order = P->teeth_ring * k / kk;
				add_line(s, name, order, order * ws_rev, line_amplitude(x, w, n, wsum, f_forcing / kk, s->spectrum_window_hann));
			}
		for (int l = 0; l < P->te_lines; l++) {
			snprintf(name, sizeof name, "te_line_%d", l);
			const double fHz = P->te_line[l].order_per_rev * ws_rev, fs = fHz * dt_s;
			add_line(s, name, P->te_line[l].order_per_rev, fHz, fs < 0.5 ? line_amplitude(x, w, n, wsum, fs, s->spectrum_window_hann) : NAN);
		}
		const double fr = P->reference_frequency_rad_s / (2.0 * M_PI), fa = P->axial_frequency_rad_s / (2.0 * M_PI);
		add_line(s, "natural_roller", fr / ws_rev, fr, fr * dt_s < 0.5 ? line_amplitude(x, w, n, wsum, fr * dt_s, s->spectrum_window_hann) : NAN);
		add_line(s, "natural_axial", fa / ws_rev, fa, fa * dt_s < 0.5 ? line_amplitude(x, w, n, wsum, fa * dt_s, s->spectrum_window_hann) : NAN);
		add_line(s, "mean", 0.0, 0.0, line_amplitude(x, w, n, wsum, 0.0, s->spectrum_window_hann));
	}
done:
	if (wt != NULL)
		gsl_fft_real_wavetable_free(wt);
	if (ws != NULL)
		gsl_fft_real_workspace_free(ws);
	free(buf);
	free(x);
	free(w);
	return rc;
}

static int resolve_T(const prsm_vib_model *m, int clock, int obs, int *clock_out, double *T, prsm_error *err)
{
	*clock_out = prsm_vib_clock_of(m, clock, obs);
	*T = prsm_vib_period(m, *clock_out);
	if (!(*T > 0.0 && isfinite(*T)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/clock",
		                      "the TE lines have no common period (within 1000 screw revolutions): use the mesh "
		                      "clock");
	return 0;
}

static int check_steady(const prsm_vib_model *m, const prsm_vib_steady_options *o, prsm_error *err)
{
	if (o->transient_periods < 0 || o->recorded_periods < 2 ||
	    (double)o->transient_periods + o->recorded_periods + (o->lyapunov ? o->lyapunov_periods : 0) > PRSM_VIB_PERIODS_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/transient_periods",
		                      "transient >= 0 and recorded >= 2 periods, at most %d in all (got %d + %d)",
		                      PRSM_VIB_PERIODS_MAX, o->transient_periods, o->recorded_periods);
	if (o->samples_per_period < 4 || o->samples_per_period > PRSM_VIB_SAMPLES_PER_PERIOD_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/vibration/samples_per_period",
		                      "4 to %d samples per period (got %d)", PRSM_VIB_SAMPLES_PER_PERIOD_MAX,
		                      o->samples_per_period);
	if ((double)o->recorded_periods * o->samples_per_period > 4e7)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/recorded_periods",
		                      "%d recorded periods x %d samples is too many", o->recorded_periods,
		                      o->samples_per_period);
	if (o->lyapunov && o->lyapunov_periods < 10)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/lyapunov", "at least 10 Lyapunov periods");
	const vib_core *c = &m->c;
	const int axial_obs = o->observable == PRSM_VIB_OBS_AXIAL_DEFLECTION || o->observable == PRSM_VIB_OBS_AXIAL_RATE ||
	                      o->observable == PRSM_VIB_OBS_THREAD_FORCE;
	if (o->observable < PRSM_VIB_OBS_MESH_DEFLECTION || o->observable > PRSM_VIB_OBS_THREAD_FORCE ||
	    (c->pair && axial_obs) || (!c->pair && axial_obs && !c->axial) || (!c->pair && !axial_obs && !c->gear) ||
	    o->index < 0 || o->index >= c->Z)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/observable",
		                      "the observable %d (index %d) is not one of this model's moving branches", o->observable,
		                      o->index);
	if (!(o->integration.rel_tol > 0.0 && o->integration.rel_tol < 1e-2 && o->integration.abs_tol > 0.0 &&
	      o->integration.abs_tol < 1e-2))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/time/rel_tol", "the tolerances must be in (0, 0.01)");
	if (o->integration.max_steps < 1)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/time/max_steps", "max_steps must be >= 1");
	return 0;
}

static void lyapunov_init_integration(prsm_vib_integration *li, const prsm_vib_integration *base)
{
	*li = *base;
	if (li->locate_kinks == PRSM_VIB_LOCATE_NEVER)
		li->locate_kinks = PRSM_VIB_LOCATE_AUTO;
}

int vib_steady_core(prsm_vib_steady *out, vib_int *it, const prsm_vib_steady_options *o, int light, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const prsm_vib_model *m = &it->mod;
	const vib_core *c = it->c;
	int rc = check_steady(m, o, err);
	if (rc)
		return rc;
	double T;
	if ((rc = resolve_T(m, o->clock, o->observable, &out->clock, &T, err)))
		return rc;
	out->period_tau = T;
	out->period_s = c->pair ? NAN : T / c->wref;
	out->period_tol = isnan(o->period_tol) ? vib_default_period_tol(m) : o->period_tol;
	out->recorded = o->recorded_periods;
	const int size = vib_reduced_size(c);
	out->poincare_size = size;
	out->contacts = c->nc;
	out->lyapunov = NAN;
	out->lyapunov_per_s = NAN;
	const prsm_vib_effort effort0 = it->effort;
	const double tau0 = it->tau;
	/* transient */
	if ((rc = vib_periods(it, tau0, T, o->transient_periods, NULL)))
		goto fail_int;
	/* the recorder */
	recorder *r = calloc(1, sizeof *r);
	const size_t ns = (size_t)o->recorded_periods * o->samples_per_period;
	out->poincare = malloc((size_t)o->recorded_periods * size * sizeof(double));
	out->poincare_observable = malloc((size_t)o->recorded_periods * sizeof(double));
	out->final_state = malloc((size_t)c->n * sizeof(double));
	out->loss_share = calloc((size_t)(c->nc > 0 ? c->nc : 1), sizeof(double));
	out->back_share = calloc((size_t)(c->nc > 0 ? c->nc : 1), sizeof(double));
	double *samp_x = malloc(ns * sizeof(double)), *samp_v = malloc(ns * sizeof(double));
	if (!r || !out->poincare || !out->poincare_observable || !out->final_state || !out->loss_share ||
	    !out->back_share || !samp_x || !samp_v) {
		free(r);
		free(samp_x);
		free(samp_v);
		prsm_vib_steady_free(out);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the recording");
	}
	r->m = m;
	r->c = c;
	r->it = it;
	r->tau_start = it->tau;
	r->T = T;
	r->periods = o->recorded_periods;
	r->sps = o->samples_per_period;
	r->n_samples = ns;
	r->samp_x = samp_x;
	r->samp_v = samp_v;
	r->obs = o->observable;
	r->obs_index = o->index;
	r->light = light;
	/* the extremes of every natural observable (light: the main one) */
	r->nx = 0;
#define ADD_EX(OBS, IDX, REF)                                                                     \
	do {                                                                                          \
		r->ex[r->nx].observable = (OBS);                                                          \
		r->ex[r->nx].index = (IDX);                                                               \
		r->refine[r->nx] = (REF);                                                                 \
		r->nx++;                                                                                  \
	} while (0)
	if (light) {
		ADD_EX(o->observable, o->index, 1);
	} else if (c->pair) {
		ADD_EX(PRSM_VIB_OBS_MESH_DEFLECTION, 0, 1);
		ADD_EX(PRSM_VIB_OBS_MESH_RATE, 0, 1);
		ADD_EX(PRSM_VIB_OBS_MESH_FORCE, 0, 1);
	} else {
		if (c->gear) {
			for (int j = 0; j < c->Z; j++)
				ADD_EX(PRSM_VIB_OBS_MESH_DEFLECTION, j, 1);
			for (int j = 0; j < c->Z; j++)
				ADD_EX(PRSM_VIB_OBS_MESH_FORCE, j, 1);
		}
		if (c->axial) {
			ADD_EX(PRSM_VIB_OBS_AXIAL_DEFLECTION, 0, 1);
			ADD_EX(PRSM_VIB_OBS_THREAD_FORCE, 0, 1);
		}
	}
#undef ADD_EX
	rec_sample(r, it, it->tau, it->y);
	r->next = 1;
	it->obs = rec_obs;
	it->obs_ctx = r;
	const double t_rec = it->tau;
	for (int i = 1; i <= o->recorded_periods; i++) {
		if ((rc = vib_int_advance(it, t_rec + i * T)))
			break;
		vib_project(c, it->y, out->poincare + (size_t)(i - 1) * size);
		out->poincare_observable[i - 1] = prsm_vib_observable(m, o->observable, o->index, it->tau, it->y);
	}
	it->obs = NULL;
	it->obs_ctx = NULL;
	if (rc) {
		free(r);
		free(samp_x);
		free(samp_v);
		prsm_vib_steady_free(out);
		return vib_int_error(it, rc, err);
	}
	memcpy(out->final_state, it->y, (size_t)c->n * sizeof(double));
	/* classification (§8.4) */
	out->period = prsm_vib_period_of(out->poincare, o->recorded_periods, size, out->period_tol, PRSM_VIB_PERIOD_MAX,
	                                 &out->max_return_distance);
	out->classification = out->period > 0 ? PRSM_VIB_PERIODIC : PRSM_VIB_NON_PERIODIC;
	/* extremes */
	out->extreme = malloc((size_t)r->nx * sizeof *out->extreme);
	if (out->extreme == NULL) {
		rc = PRSM_ENOMEM;
	} else {
		out->extremes = r->nx;
		for (int i = 0; i < r->nx; i++) {
			out->extreme[i] = r->ex[i];
			const double nsamp = (double)ns;
			out->extreme[i].mean = r->sum[i] / nsamp;
			out->extreme[i].rms = sqrt(fmax(0.0, r->sum2[i] / nsamp - out->extreme[i].mean * out->extreme[i].mean));
		}
	}
	/* contact shares */
	const double total = o->recorded_periods * T;
	for (int k = 0; k < c->nc; k++) {
		out->loss_share[k] = (r->region_time[k][1] + r->region_time[k][0]) / total;
		out->back_share[k] = r->region_time[k][0] / total;
	}
	if (rc == 0 && !light)
		rc = spectrum(out, m, samp_x, o->samples_per_period, o->recorded_periods, T);
	if (rc == 0 && !light) {
		out->portrait_points = ns;
		out->portrait_x = samp_x;
		out->portrait_v = samp_v;
		samp_x = samp_v = NULL;
	}
	free(r);
	free(samp_x);
	free(samp_v);
	if (rc) {
		prsm_vib_steady_free(out);
		return prsm_error_set(err, rc, NULL, "out of memory for the spectrum");
	}
	/* lambda_max after the recording (Benettin, §8.4) */
	if (o->lyapunov) {
		vib_int lv;
		prsm_vib_integration li;
		lyapunov_init_integration(&li, &o->integration);
		const int nexp = c->pair ? 2 : 1;
		if (vib_int_init(&lv, m, nexp, 1, &li, it->cancel)) {
			prsm_vib_steady_free(out);
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the variational equations");
		}
		double *y = calloc((size_t)lv.dim, sizeof(double));
		if (y == NULL) {
			vib_int_free(&lv);
			prsm_vib_steady_free(out);
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the variational equations");
		}
		memcpy(y, it->y, (size_t)c->n * sizeof(double));
		vib_int_set(&lv, it->tau, y);
		free(y);
		prsm_vib_lyapunov ly;
		rc = vib_benettin(&lv, T, 50, o->lyapunov_periods, nexp, 10, &ly);
		effort_add(&out->effort, &lv.effort);
		if (rc) {
			vib_int_error(&lv, rc, err);
			vib_int_free(&lv);
			prsm_vib_steady_free(out);
			return rc;
		}
		vib_int_free(&lv);
		out->lyapunov = ly.lambda[0];
		out->lyapunov_per_s = c->pair ? NAN : ly.lambda[0] * c->wref;
		if (out->classification != PRSM_VIB_PERIODIC)
			out->classification = out->lyapunov > 1e-3 ? PRSM_VIB_CHAOTIC : PRSM_VIB_QUASI_PERIODIC;
	}
	out->effort.steps += it->effort.steps - effort0.steps;
	out->effort.rejected += it->effort.rejected - effort0.rejected;
	out->effort.rhs_evaluations += it->effort.rhs_evaluations - effort0.rhs_evaluations;
	out->effort.events += it->effort.events - effort0.events;
	out->effort.switches += it->effort.switches - effort0.switches;
	return 0;
fail_int:
	return vib_int_error(it, rc, err);
}

int prsm_vib_steady_state(prsm_vib_steady *out, const prsm_vib_model *m, const double *initial_state,
                          const prsm_vib_steady_options *o, const prsm_cancel_flag *cancel, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	vib_int it;
	if (vib_int_init(&it, m, 0, 1, &o->integration, cancel))
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the integrator");
	double y0[PRSM_VIB_STATE_MAX];
	if (initial_state != NULL)
		memcpy(y0, initial_state, (size_t)m->c.n * sizeof *y0);
	else
		prsm_vib_static_state(m, y0);
	if (!isnan(o->integration.initial_step))
		it.h = o->integration.initial_step;
	vib_int_set(&it, 0.0, y0);
	const int rc = vib_steady_core(out, &it, o, 0, err);
	vib_int_free(&it);
	return rc;
}

/* ---- Lyapunov exponents (§8.4) ---- */

/* QR (modified Gram-Schmidt) of the k tangent vectors in reduced coordinates; logs of R_ii into
 * logs; the vectors lifted back, orthonormal. */
static void tangent_qr(vib_int *it, int k, double *logs, double *rbuf)
{
	const vib_core *c = it->c;
	const int n = it->n, nr = vib_reduced_size(c);
	double *r[PRSM_VIB_STATE_MAX];
	for (int i = 0; i < k; i++) {
		r[i] = rbuf + (size_t)i * nr;
		vib_project(c, it->y + (size_t)(1 + i) * n, r[i]);
	}
	for (int i = 0; i < k; i++) {
		for (int j = 0; j < i; j++) {
			double d = 0.0;
			for (int q = 0; q < nr; q++)
				d += r[j][q] * r[i][q];
			for (int q = 0; q < nr; q++)
				r[i][q] -= d * r[j][q];
		}
		double nn = 0.0;
		for (int q = 0; q < nr; q++)
			nn += r[i][q] * r[i][q];
		nn = sqrt(nn);
		logs[i] = log(nn);
		for (int q = 0; q < nr; q++)
			r[i][q] /= nn;
		vib_lift(c, r[i], it->y + (size_t)(1 + i) * n);
	}
}

int vib_benettin(vib_int *it, double T, int transient, int periods, int exponents, int blocks, prsm_vib_lyapunov *out)
{
	memset(out, 0, sizeof *out);
	const vib_core *c = it->c;
	const int n = it->n, nr = vib_reduced_size(c);
	const int k = exponents;
	/* initial tangent vectors (lifted from the reduced coordinates): a generic direction (every
	 * component 1 / sqrt(nr): it has a component along every mode) and the unit vectors e_0,
	 * e_1, ...; the first QR orthonormalises them */
	for (int i = 0; i < k; i++) {
		double e[PRSM_VIB_STATE_MAX] = {0};
		if (i == 0)
			for (int q = 0; q < nr; q++)
				e[q] = 1.0 / sqrt((double)nr);
		else
			e[(i - 1) % nr] = 1.0;
		vib_lift(c, e, it->y + (size_t)(1 + i) * n);
	}
	vib_int_set(it, it->tau, it->y);
	double logs[PRSM_VIB_STATE_MAX], sums[PRSM_VIB_STATE_MAX] = {0};
	if (blocks < 1)
		blocks = 1;
	if (blocks > 64)
		blocks = 64;
	if (blocks > periods)
		blocks = periods;
	const int per_block = periods / blocks;
	double block_sum = 0.0;
	int block = 0, in_block = 0;
	const double tau0 = it->tau;
	double *rbuf = malloc((size_t)k * nr * sizeof(double));
	if (rbuf == NULL)
		return PRSM_ENOMEM;
	for (int p = 1; p <= transient + periods; p++) {
		int rc = vib_int_advance(it, tau0 + p * T);
		if (rc) {
			free(rbuf);
			return rc;
		}
		tangent_qr(it, k, logs, rbuf);
		vib_int_set(it, it->tau, it->y);
		if (p <= transient)
			continue;
		for (int i = 0; i < k; i++)
			sums[i] += logs[i];
		block_sum += logs[0];
		if (++in_block == per_block && block < blocks) {
			out->block_lambda[block++] = block_sum / (per_block * T);
			block_sum = 0.0;
			in_block = 0;
		}
	}
	free(rbuf);
	out->exponents = k;
	out->periods = periods;
	out->period_tau = T;
	out->blocks = block;
	out->sum = 0.0;
	for (int i = 0; i < k; i++) {
		out->lambda[i] = sums[i] / (periods * T);
		out->lambda_per_s[i] = c->pair ? NAN : out->lambda[i] * c->wref;
		out->sum += out->lambda[i];
	}
	double mean = 0.0, var = 0.0;
	out->block_min = INFINITY;
	out->block_max = -INFINITY;
	for (int b = 0; b < block; b++) {
		mean += out->block_lambda[b] / block;
		out->block_min = fmin(out->block_min, out->block_lambda[b]);
		out->block_max = fmax(out->block_max, out->block_lambda[b]);
	}
	for (int b = 0; b < block; b++)
		var += (out->block_lambda[b] - mean) * (out->block_lambda[b] - mean);
	out->block_sd = block > 1 ? sqrt(var / (block - 1)) : NAN;
	out->effort = it->effort;
	return 0;
}

/* method (b): two trajectories integrated as one stacked system, renormalised every period */
static int two_trajectories(vib_int *it, double T, int periods, int blocks, double d0, prsm_vib_lyapunov *out)
{
	memset(out, 0, sizeof *out);
	const vib_core *c = it->c;
	const int n = it->n, nr = vib_reduced_size(c);
	double e[PRSM_VIB_STATE_MAX], v[PRSM_VIB_STATE_MAX], r1[PRSM_VIB_STATE_MAX], r2[PRSM_VIB_STATE_MAX];
	for (int q = 0; q < nr; q++)
		e[q] = d0 / sqrt((double)nr);
	vib_lift(c, e, v);
	for (int i = 0; i < n; i++)
		it->y[n + i] = it->y[i] + v[i];
	vib_int_set(it, it->tau, it->y);
	if (blocks < 1)
		blocks = 1;
	if (blocks > 64)
		blocks = 64;
	if (blocks > periods)
		blocks = periods;
	const int per_block = periods / blocks;
	double sum = 0.0, block_sum = 0.0;
	int block = 0, in_block = 0;
	const double tau0 = it->tau;
	for (int p = 1; p <= periods; p++) {
		const int rc = vib_int_advance(it, tau0 + p * T);
		if (rc)
			return rc;
		vib_project(c, it->y, r1);
		vib_project(c, it->y + n, r2);
		double d = 0.0;
		for (int q = 0; q < nr; q++) {
			e[q] = r2[q] - r1[q];
			d += e[q] * e[q];
		}
		d = sqrt(d);
		const double l = log(d / d0);
		sum += l;
		block_sum += l;
		for (int q = 0; q < nr; q++)
			e[q] *= d0 / d;
		vib_lift(c, e, v);
		for (int i = 0; i < n; i++)
			it->y[n + i] = it->y[i] + v[i];
		vib_int_set(it, it->tau, it->y);
		if (++in_block == per_block && block < blocks) {
			out->block_lambda[block++] = block_sum / (per_block * T);
			block_sum = 0.0;
			in_block = 0;
		}
	}
	out->exponents = 1;
	out->periods = periods;
	out->period_tau = T;
	out->blocks = block;
	out->lambda[0] = sum / (periods * T);
	out->lambda_per_s[0] = c->pair ? NAN : out->lambda[0] * c->wref;
	out->sum = out->lambda[0];
	double mean = 0.0, var = 0.0;
	out->block_min = INFINITY;
	out->block_max = -INFINITY;
	for (int b = 0; b < block; b++) {
		mean += out->block_lambda[b] / block;
		out->block_min = fmin(out->block_min, out->block_lambda[b]);
		out->block_max = fmax(out->block_max, out->block_lambda[b]);
	}
	for (int b = 0; b < block; b++)
		var += (out->block_lambda[b] - mean) * (out->block_lambda[b] - mean);
	out->block_sd = block > 1 ? sqrt(var / (block - 1)) : NAN;
	out->effort = it->effort;
	return 0;
}

int prsm_vib_lyapunov_run(prsm_vib_lyapunov *out, const prsm_vib_model *m, const double *initial_state,
                          const prsm_vib_lyapunov_options *o, const prsm_cancel_flag *cancel, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const vib_core *c = &m->c;
	const int nr = vib_reduced_size(c);
	if (o->method != PRSM_VIB_LYAPUNOV_BENETTIN && o->method != PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/lyapunov/method", "the method is benettin or two_trajectories");
	if (o->method == PRSM_VIB_LYAPUNOV_BENETTIN && (o->exponents < 1 || o->exponents > nr))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/lyapunov/exponents", "1 to %d exponents (got %d)", nr,
		                      o->exponents);
	if (o->periods < 1 || o->transient_periods < 0 || (double)o->periods + o->transient_periods > PRSM_VIB_PERIODS_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/lyapunov/periods", "1 to %d periods", PRSM_VIB_PERIODS_MAX);
	if (o->method == PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES && !(o->separation > 0.0 && o->separation < 1e-2))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/lyapunov/separation", "d_0 must be in (0, 0.01)");
	int clock;
	double T;
	int rc = resolve_T(m, o->clock, PRSM_VIB_OBS_MESH_DEFLECTION, &clock, &T, err);
	if (rc)
		return rc;
	double y0[PRSM_VIB_STATE_MAX];
	if (initial_state != NULL)
		memcpy(y0, initial_state, (size_t)c->n * sizeof *y0);
	else
		prsm_vib_static_state(m, y0);
	/* the transient with the state alone */
	vib_int it;
	if (vib_int_init(&it, m, 0, 1, &o->integration, cancel))
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the integrator");
	vib_int_set(&it, 0.0, y0);
	/* the last (up to 100) transient periods carry the tangent vectors too: they align with the
	 * slowest-decaying (fastest-growing) directions before the measurement starts */
	const int two = o->method == PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES;
	const int tangent_transient = two ? 0 : (o->transient_periods < 100 ? o->transient_periods : 100);
	rc = vib_periods(&it, 0.0, T, o->transient_periods - tangent_transient, NULL);
	const double tau = it.tau;
	memcpy(y0, it.y, (size_t)c->n * sizeof *y0);
	prsm_vib_effort eff = it.effort;
	const double h = it.h;
	vib_int_free(&it);
	if (rc)
		return prsm_error_set(err, rc, NULL, "the transient failed: %s", rc == PRSM_ECANCELLED ? "cancelled" : "no convergence");
	prsm_vib_integration li;
	lyapunov_init_integration(&li, &o->integration);
	if (two) {
		/* tolerances at least 1e3 below d_0 (§8.4) */
		li.abs_tol = fmin(li.abs_tol, 1e-3 * o->separation);
		li.rel_tol = fmin(li.rel_tol, 1e-3 * o->separation);
	}
	if (vib_int_init(&it, m, two ? 0 : o->exponents, two ? 2 : 1, &li, cancel))
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the variational equations");
	double *y = calloc((size_t)it.dim, sizeof(double));
	if (y == NULL) {
		vib_int_free(&it);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	memcpy(y, y0, (size_t)c->n * sizeof *y0);
	it.h = h;
	vib_int_set(&it, tau, y);
	free(y);
	if (two) {
		rc = two_trajectories(&it, T, o->periods, o->blocks, o->separation, out);
	} else {
		rc = vib_benettin(&it, T, tangent_transient, o->periods, o->exponents, o->blocks, out);
	}
	if (rc)
		vib_int_error(&it, rc, err);
	effort_add(&eff, &it.effort);
	out->effort = eff;
	vib_int_free(&it);
	return rc;
}
