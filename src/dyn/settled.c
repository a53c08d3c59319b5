/*
 * settled.c: the settled state of docs/model §8.2.5, algebraic rather than by waiting: the
 * carriers at k* theta-dot (isotropic friction, no carrier drag) or at the bracketed root of
 * Z f.A - c_C psi-dot = 0, stage by stage from the last; for a torque input the screw speed at
 * which the running torque balances the motor's; then every force from docs/model §8.2.4 with
 * theta-ddot = 0, and the statics engine's efficiency at the same load and speed beside it.
 */
#include "dyn/dyn_internal.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <string.h>

#define ROOT_MAX_ITER 300
#define ROOT_REL_TOL 1e-14
#define SPEED_SEARCH_MAX_RAD_S 1e8


typedef struct {
	const prsm_dyn_model *m;
	dyn_scratch *s;
	double w;                          /* screw speed, rad/s */
	double psid[PRSM_DYN_STAGES_MAX];  /* carrier speeds, rad/s */
	double psi[PRSM_DYN_STAGES_MAX];
	int k;                             /* the carrier being settled */
	prsm_dyn_point pt;
	prsm_dyn_stage_point sp[PRSM_DYN_STAGES_MAX];
	int rc;
	prsm_error *err;
} settle_ctx;

static int evaluate(settle_ctx *c)
{
	dyn_motion mo = {0.0, 0.0, c->w, 0.0, c->psi, c->psid};
	return dyn_eval_motion(c->m, c->s, &mo, &c->pt, c->sp, c->err);
}

/* J_psi psi-ddot_k = Z f.A - c_C psi-dot of carrier c->k at psi-dot_k = x, N m */
static double carrier_balance(double x, void *p)
{
	settle_ctx *c = p;
	c->psid[c->k] = x;
	int rc = evaluate(c);
	if (rc) {
		c->rc = rc;
		return NAN;
	}
	return c->sp[c->k].carrier_accel_rad_s2 * c->m->stage[c->k].J_psi;
}

/* Brent on [lo, hi] of f; the bracket's ends have opposite signs or one is a root. */
static int bracketed_root(double *out, gsl_function *f, double lo, double hi, double flo, double fhi,
                          const char *what, prsm_error *err)
{
	if (flo == 0.0 || fhi == 0.0) {
		*out = flo == 0.0 ? lo : hi;
		return 0;
	}
	if (!(flo * fhi < 0.0))
		return prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamics", "%s: no sign change in [%g, %g]", what, lo, hi);
	gsl_root_fsolver *r = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
	if (r == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for a root solver");
	int rc = PRSM_ENOCONVERGE, status = gsl_root_fsolver_set(r, f, lo, hi);
	for (int it = 0; it < ROOT_MAX_ITER && status == GSL_SUCCESS; it++) {
		status = gsl_root_fsolver_iterate(r);
		if (status != GSL_SUCCESS)
			break;
		const double a = gsl_root_fsolver_x_lower(r), b = gsl_root_fsolver_x_upper(r);
		if (gsl_root_test_interval(a, b, 0.0, ROOT_REL_TOL) == GSL_SUCCESS || a == b) {
			*out = gsl_root_fsolver_root(r);
			rc = 0;
			break;
		}
	}
	gsl_root_fsolver_free(r);
	if (rc)
		return prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamics", "%s did not converge", what);
	return 0;
}

/* The carriers' settled speeds at screw speed c->w (docs/model §8.2.5). */
static int settle_carriers(settle_ctx *c)
{
	const prsm_dyn_model *m = c->m;
	for (int k = 0; k < m->stages; k++)
		c->psid[k] = m->stage[k].par.carrier_ratio_min_slip * c->w;
	if (m->opts.friction.carrier_drag_Nm_s_per_rad == 0.0 || c->w == 0.0)
		return 0; /* friction alone: A.v = 0 at k* for every isotropic law */
	gsl_function f = {carrier_balance, c};
	for (int k = m->stages - 1; k >= 0; k--) {
		c->k = k;
		const double x1 = m->stage[k].par.carrier_ratio_min_slip * c->w;
		const double lo = fmin(0.0, x1), hi = fmax(0.0, x1);
		c->rc = 0;
		const double flo = carrier_balance(lo, c), fhi = carrier_balance(hi, c);
		if (c->rc)
			return c->rc;
		double x;
		int rc = bracketed_root(&x, &f, lo, hi, flo, fhi, "the settled carrier speed", c->err);
		if (rc == 0 && c->rc)
			rc = c->rc;
		if (rc)
			return rc;
		c->psid[k] = x;
	}
	return 0;
}

/* Motor torque minus the running torque at screw speed w with the carriers settled, N m. */
static double torque_balance(double w, void *p)
{
	settle_ctx *c = p;
	c->w = w;
	int rc = settle_carriers(c);
	if (rc == 0)
		rc = evaluate(c);
	if (rc) {
		c->rc = rc;
		return NAN;
	}
	return prsm_dyn_signal_value(&c->m->opts.input.signal, 0.0) - c->pt.input_torque_Nm;
}

/* Torque input: the speed where the running torque balances the motor torque (it rises with
 * the speed: friction and drag oppose the motion). *defined = 0 when none up to 1e8 rad/s. */
static int settled_speed(double *w_out, int *defined, int *at_rest, settle_ctx *c)
{
	const prsm_dyn_model *m = c->m;
	*defined = 1;
	*at_rest = 0;
	c->rc = 0;
	if (m->opts.friction.stick_model == PRSM_DYN_STICK_KARNOPP && m->opts.input.initial_speed_rad_s == 0.0) {
		double Tf, Tb;
		int rc = dyn_breakaway(&Tf, &Tb, m, c->s, 0.0, c->err);
		if (rc)
			return rc;
		const double Tm = prsm_dyn_signal_value(&m->opts.input.signal, 0.0);
		if (Tb <= Tm && Tm <= Tf) {
			*w_out = 0.0;
			*at_rest = 1;
			return 0;
		}
	}
	const double H0 = torque_balance(0.0, c);
	if (c->rc)
		return c->rc;
	if (H0 == 0.0) {
		*w_out = 0.0;
		*at_rest = 1;
		return 0;
	}
	const double dir = H0 > 0.0 ? 1.0 : -1.0;
	/* from the smoothing speed of the contact up, 4 times per step */
	double lo = 0.0, flo = H0, fhi = NAN;
	double hi = dir * m->opts.friction.smoothing_velocity_m_s / m->stage[0].B_norm;
	for (;;) {
		fhi = torque_balance(hi, c);
		if (c->rc)
			return c->rc;
		if (fhi * dir <= 0.0)
			break;
		lo = hi;
		flo = fhi;
		hi *= 4.0;
		if (fabs(hi) > SPEED_SEARCH_MAX_RAD_S) {
			*defined = 0;
			return 0;
		}
	}
	gsl_function f = {torque_balance, c};
	int rc = bracketed_root(w_out, &f, fmin(lo, hi), fmax(lo, hi), lo < hi ? flo : fhi, lo < hi ? fhi : flo,
	                        "the settled screw speed", c->err);
	return rc ? rc : c->rc;
}

static void settled_undefined(prsm_dyn_settled *out, int K)
{
	const double nan = NAN;
	out->defined = 0;
	out->screw_speed_rad_s = out->input_torque_Nm = out->efficiency = out->efficiency_statics = nan;
	for (int k = 0; k < K; k++)
		out->carrier_ratio[k] = out->carrier_rate_per_s[k] = nan;
}

int dyn_settle(prsm_dyn_model *m, prsm_error *err)
{
	prsm_dyn_settled *out = &m->settled;
	const int K = m->stages;
	memset(out, 0, sizeof *out);
	for (int k = 0; k < K; k++) {
		out->carrier_ratio_min_slip[k] = m->stage[k].par.carrier_ratio_min_slip;
		out->carrier_ratio_statics[k] = m->stage[k].par.carrier_ratio_statics;
	}
	/* at the final input (sine: its mean): the signals held at their values meanwhile */
	const prsm_dyn_signal input = m->opts.input.signal, load = m->opts.load;
	m->opts.input.signal.shape = PRSM_DYN_SHAPE_STEP;
	m->opts.load.shape = PRSM_DYN_SHAPE_STEP;
	dyn_scratch s;
	settle_ctx c;
	memset(&c, 0, sizeof c);
	int rc = 0;
	dyn_scratch_init(&s, m);
	c.m = m;
	c.s = &s;
	c.err = err;
	int defined = 1, at_rest = 0;
	double w;
	if (m->opts.input.kind == PRSM_DYN_INPUT_SPEED) {
		w = input.value;
	} else if ((rc = settled_speed(&w, &defined, &at_rest, &c))) {
		goto done;
	}
	if (!defined) {
		settled_undefined(out, K);
		goto done;
	}
	c.w = w;
	if ((rc = settle_carriers(&c)))
		goto done;
	s.detail = 1;
	if ((rc = evaluate(&c)))
		goto done;
	out->defined = 1;
	out->at_rest = at_rest;
	out->point = c.pt;
	memcpy(out->stage, c.sp, sizeof c.sp);
	out->screw_speed_rad_s = w;
	out->input_torque_Nm = c.pt.input_torque_Nm;
	out->efficiency = w != 0.0 ? c.pt.efficiency : NAN;
	for (int k = 0; k < K; k++)
		out->carrier_ratio[k] = w != 0.0 ? c.psid[k] / w : NAN;
	/* sigma_c = -d psi-ddot_k / d psi-dot_k about the settled state (central difference) */
	s.detail = 0;
	for (int k = 0; k < K; k++) {
		const dyn_stage *st = &m->stage[k];
		const double x = c.psid[k];
		const double dx = 1e-6 * fmax(fabs(x), m->opts.friction.smoothing_velocity_m_s /
		                                         sqrt(st->A[0][0] * st->A[0][0] + st->A[0][1] * st->A[0][1]));
		c.psid[k] = x + dx;
		if ((rc = evaluate(&c)))
			goto done;
		const double up = c.sp[k].carrier_accel_rad_s2;
		c.psid[k] = x - dx;
		if ((rc = evaluate(&c)))
			goto done;
		out->carrier_rate_per_s[k] = -(up - c.sp[k].carrier_accel_rad_s2) / (2.0 * dx);
		c.psid[k] = x;
	}
	/* the statics engine at the same load and speed (model/stages.h) */
	out->efficiency_statics = NAN;
	if (m->opts.friction.model != PRSM_DYN_FRICTION_VISCOUS && load.value >= 0.0) {
		prsm_chain chain;
		prsm_error chain_err = PRSM_ERROR_INIT;
		if (dyn_statics_chain(&chain, m, load.value, fabs(w), &chain_err) == 0)
			out->efficiency_statics = chain.efficiency;
	}
done:
	m->opts.input.signal = input;
	m->opts.load = load;
	return rc;
}
