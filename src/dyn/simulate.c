/*
 * simulate.c: the transient of docs/model §8.2 integrated with GSL odeiv2 (§8.2.6).
 *
 * States, scaled so that one absolute tolerance fits all (angles in rad, speeds divided by the
 * speed scale, energies by the energy scale): speed input psi_k, psi-dot_k (k = 0..K-1) with
 * theta(t) from the signal in closed form; torque input theta, theta-dot first. Two energy
 * accumulators (input and output work) come last. Output times are reached exactly by
 * gsl_odeiv2_evolve_apply limited to the next output time (or to a kink of a ramp signal,
 * after which the stepper restarts). After every accepted step the events of the step are
 * located on a copy of the step, integrated again from its start by a second driver of the same
 * stepper: the first times each carrier ratio (and, for a torque input, the screw speed) reach
 * 50, 90 and 99 % of the settled value (regula falsi, Illinois variant, to 1e-12 s), and the
 * Karnopp stick and slip transitions (bisection to 1e-12 s, then a restart in the new mode).
 * A torque input from rest starts with an implicit stepper (msbdf, Jacobian by central
 * differences) and hands over to rk8pd once the screw runs faster than the switch speed.
 *
 * Allocation: the result's arrays (prsm_dyn_result_free), and the drivers and scratch of one
 * run, freed before it returns. Nothing is allocated per step.
 */
#include "dyn/dyn_internal.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define EVENT_TIME_TOL_S 1e-12
#define EVENT_MAX_ITER 200
#define SHARES 3
#define SWITCH_BACK_FACTOR 0.1 /* back to the implicit stepper below this share of the switch speed */


static const double share_of_settled[SHARES] = {0.5, 0.9, 0.99};

typedef struct {
	const prsm_dyn_model *m;
	dyn_scratch s;
	int torque;                  /* theta and theta-dot are states */
	int K;
	size_t n;                    /* number of states */
	size_t i_psi;                /* first carrier state */
	size_t i_energy;             /* input work, then output work */
	double w_scale;              /* rad/s */
	double E_scale;              /* J */
	double *jac_y, *jac_f1, *jac_f2; /* n each */
	prsm_dyn_point pt;
	prsm_dyn_stage_point sp[PRSM_DYN_STAGES_MAX];
	int rc;                      /* the first failure inside a right-hand side */
	prsm_error rhs_err;
	long rhs, jac;
} sim_ctx;

static void unpack(const sim_ctx *c, double t, const double *y, dyn_motion *mo, double *psi,
                   double *psid)
{
	for (int k = 0; k < c->K; k++) {
		psi[k] = y[c->i_psi + 2 * (size_t)k];
		psid[k] = y[c->i_psi + 2 * (size_t)k + 1] * c->w_scale;
	}
	mo->t = t;
	mo->psi = psi;
	mo->psi_dot = psid;
	if (c->torque) {
		mo->theta = y[0];
		mo->theta_dot = c->s.stuck ? 0.0 : y[1] * c->w_scale;
		mo->theta_ddot = 0.0;
	} else {
		dyn_speed_input(c->m, t, &mo->theta, &mo->theta_dot, &mo->theta_ddot);
	}
}

/* Evaluate the state y at t into c->pt, c->sp (detail as c->s.detail). */
static int eval_state(sim_ctx *c, double t, const double *y, prsm_error *err)
{
	double psi[PRSM_DYN_STAGES_MAX], psid[PRSM_DYN_STAGES_MAX];
	dyn_motion mo;
	unpack(c, t, y, &mo, psi, psid);
	if (c->torque)
		return dyn_eval_torque(c->m, &c->s, &mo, &c->pt, c->sp, err);
	return dyn_eval_motion(c->m, &c->s, &mo, &c->pt, c->sp, err);
}

static int rhs(double t, const double y[], double dydt[], void *params)
{
	sim_ctx *c = params;
	prsm_error err = PRSM_ERROR_INIT;
	c->s.detail = 0;
	c->rhs++;
	int rc = eval_state(c, t, y, &err);
	if (rc) {
		if (c->rc == 0) {
			c->rc = rc;
			c->rhs_err = err;
		}
		return GSL_EBADFUNC;
	}
	if (c->torque) {
		dydt[0] = c->s.stuck ? 0.0 : y[1] * c->w_scale;
		dydt[1] = c->s.stuck ? 0.0 : c->pt.screw_accel_rad_s2 / c->w_scale;
	}
	for (int k = 0; k < c->K; k++) {
		dydt[c->i_psi + 2 * (size_t)k] = y[c->i_psi + 2 * (size_t)k + 1] * c->w_scale;
		dydt[c->i_psi + 2 * (size_t)k + 1] = c->sp[k].carrier_accel_rad_s2 / c->w_scale;
	}
	dydt[c->i_energy] = c->pt.power_input_W / c->E_scale;
	dydt[c->i_energy + 1] = c->pt.power_output_W / c->E_scale;
	return GSL_SUCCESS;
}

/* Jacobian by central differences (docs/model §8.2.6): only the speeds enter the right-hand
 * side (the angles and the energies do not), so only their columns are differenced. */
static int jacobian(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
	sim_ctx *c = params;
	const size_t n = c->n;
	c->jac++;
	memset(dfdy, 0, n * n * sizeof(double));
	memcpy(c->jac_y, y, n * sizeof(double));
	for (size_t j = 0; j < n; j++) {
		const int speed = (c->torque && j == 1) || (j >= c->i_psi && j < c->i_energy && (j - c->i_psi) % 2 == 1);
		if (!speed)
			continue;
		const double dj = 6e-6 * fmax(1.0, fabs(y[j]));
		c->jac_y[j] = y[j] + dj;
		if (rhs(t, c->jac_y, c->jac_f1, c) != GSL_SUCCESS)
			return GSL_EBADFUNC;
		c->jac_y[j] = y[j] - dj;
		if (rhs(t, c->jac_y, c->jac_f2, c) != GSL_SUCCESS)
			return GSL_EBADFUNC;
		c->jac_y[j] = y[j];
		for (size_t i = 0; i < n; i++)
			dfdy[i * n + j] = (c->jac_f1[i] - c->jac_f2[i]) / (2.0 * dj);
	}
	/* the signals' time dependence */
	const double dt = 6e-6 * fmax(fabs(t), 1e-3 * c->m->opts.time.end_s);
	const double t1 = t + dt, t0 = t - dt >= 0.0 ? t - dt : t;
	if (rhs(t1, y, c->jac_f1, c) != GSL_SUCCESS || rhs(t0, y, c->jac_f2, c) != GSL_SUCCESS)
		return GSL_EBADFUNC;
	for (size_t i = 0; i < n; i++)
		dfdt[i] = (c->jac_f1[i] - c->jac_f2[i]) / (t1 - t0);
	return GSL_SUCCESS;
}

typedef struct {
	gsl_odeiv2_driver *main, *sub; /* the run's driver and the events' */
	int implicit;                  /* main is msbdf or rk4imp */
} driver_pair;

static void pair_free(driver_pair *p)
{
	if (p->main)
		gsl_odeiv2_driver_free(p->main);
	if (p->sub)
		gsl_odeiv2_driver_free(p->sub);
	p->main = p->sub = NULL;
}

static int pair_alloc(driver_pair *p, const gsl_odeiv2_system *sys, const gsl_odeiv2_step_type *T,
                      double h0, const prsm_dyn_time *tm)
{
	p->main = gsl_odeiv2_driver_alloc_y_new(sys, T, h0, tm->abs_tol, tm->rel_tol);
	p->sub = gsl_odeiv2_driver_alloc_y_new(sys, T, h0, tm->abs_tol, tm->rel_tol);
	p->implicit = T != gsl_odeiv2_step_rk8pd;
	if (p->main == NULL || p->sub == NULL) {
		pair_free(p);
		return PRSM_ENOMEM;
	}
	return 0;
}

/* The state at t in [t0, t1] of the step from (t0, y0): integrated again by the sub-driver. */
static int state_at(sim_ctx *c, gsl_odeiv2_driver *sub, double t0, const double *y0, double t, double *y)
{
	memcpy(y, y0, c->n * sizeof(double));
	if (t <= t0)
		return 0;
	gsl_odeiv2_driver_reset(sub);
	gsl_odeiv2_driver_reset_hstart(sub, t - t0);
	double tt = t0;
	int status = gsl_odeiv2_driver_apply(sub, &tt, t, y);
	if (status != GSL_SUCCESS)
		return c->rc ? c->rc : PRSM_ENOCONVERGE;
	return 0;
}

/* Event function of a share crossing: >= 0 once reached. which < SHARES * K: carrier
 * which / SHARES; else the screw speed (torque input). */
static double share_function(const sim_ctx *c, int which, double t, const double *y)
{
	const prsm_dyn_settled *st = &c->m->settled;
	const double q = share_of_settled[which % SHARES];
	double psi[PRSM_DYN_STAGES_MAX], psid[PRSM_DYN_STAGES_MAX];
	dyn_motion mo;
	unpack(c, t, y, &mo, psi, psid);
	if (which < SHARES * c->K) {
		const int k = which / SHARES;
		const double r = st->carrier_ratio[k];
		if (mo.theta_dot == 0.0)
			return -1.0;
		return (psid[k] / mo.theta_dot - q * r) * (r > 0.0 ? 1.0 : -1.0);
	}
	const double w = st->screw_speed_rad_s;
	return (mo.theta_dot - q * w) * (w > 0.0 ? 1.0 : -1.0);
}

/* First time in (t0, t1] where event `which` reaches 0 from below: Illinois. */
static int locate_share(double *t_out, sim_ctx *c, gsl_odeiv2_driver *sub, int which, double t0,
                        const double *y0, double g0, double t1, double g1, double *ywork)
{
	double a = t0, ga = g0, b = t1, gb = g1;
	int side = 0;
	for (int it = 0; it < EVENT_MAX_ITER && b - a > EVENT_TIME_TOL_S; it++) {
		double t = (a * gb - b * ga) / (gb - ga);
		if (!(t > a && t < b))
			t = 0.5 * (a + b);
		int rc = state_at(c, sub, t0, y0, t, ywork);
		if (rc)
			return rc;
		const double g = share_function(c, which, t, ywork);
		if (g >= 0.0) {
			b = t;
			gb = g;
			if (side == 1)
				ga *= 0.5;
			side = 1;
		} else {
			a = t;
			ga = g;
			if (side == -1)
				gb *= 0.5;
			side = -1;
		}
	}
	*t_out = b;
	return 0;
}

/* Karnopp (docs/model §8.2.6): does the mode have to change at (t, y)? */
static int mode_change(int *out, sim_ctx *c, double t, const double *y, prsm_error *err)
{
	double Tf, Tb;
	int rc = dyn_breakaway(&Tf, &Tb, c->m, &c->s, t, err);
	if (rc)
		return rc;
	const double Tm = prsm_dyn_signal_value(&c->m->opts.input.signal, t);
	const int inside = Tb <= Tm && Tm <= Tf;
	if (c->s.stuck)
		*out = !inside;
	else
		*out = inside && fabs(y[1] * c->w_scale) < c->m->stick_band_rad_s;
	return 0;
}

/* The first time in (t0, t1] the mode must change, by bisection (the state at t1 says it must). */
static int locate_mode_change(double *t_out, sim_ctx *c, gsl_odeiv2_driver *sub, double t0,
                              const double *y0, double t1, double *ywork, prsm_error *err)
{
	double a = t0, b = t1;
	for (int it = 0; it < EVENT_MAX_ITER && b - a > EVENT_TIME_TOL_S; it++) {
		const double t = 0.5 * (a + b);
		int change, rc = state_at(c, sub, t0, y0, t, ywork);
		if (rc == 0)
			rc = mode_change(&change, c, t, ywork, err);
		if (rc)
			return rc;
		if (change)
			b = t;
		else
			a = t;
	}
	*t_out = b;
	return 0;
}

static void record(prsm_dyn_result *r, size_t i, const sim_ctx *c, const double *y)
{
	prsm_dyn_point *p = &r->point[i];
	*p = c->pt;
	p->energy_input_J = y[c->i_energy] * c->E_scale;
	p->energy_output_J = y[c->i_energy + 1] * c->E_scale;
	p->energy_efficiency = p->energy_input_J != 0.0 ? p->energy_output_J / p->energy_input_J : NAN;
	memcpy(&r->stage[i * (size_t)c->K], c->sp, (size_t)c->K * sizeof(prsm_dyn_stage_point));
	if (p->power_balance_relative > r->max_power_balance_relative)
		r->max_power_balance_relative = p->power_balance_relative;
	if (p->newton_euler_residual > r->max_newton_euler_residual)
		r->max_newton_euler_residual = p->newton_euler_residual;
}

void prsm_dyn_result_free(prsm_dyn_result *r)
{
	free(r->point);
	free(r->stage);
	r->point = NULL;
	r->stage = NULL;
	r->points = 0;
}

static const gsl_odeiv2_step_type *implicit_type(int stepper)
{
	return stepper == PRSM_DYN_STEPPER_RK4IMP ? gsl_odeiv2_step_rk4imp : gsl_odeiv2_step_msbdf;
}

int prsm_dyn_simulate(prsm_dyn_result *out, const prsm_dyn_model *m, const prsm_cancel_flag *cancel,
                      prsm_progress_fn progress, void *progress_ctx, prsm_error *err)
{
	const prsm_dyn_options *o = &m->opts;
	const prsm_dyn_time *tm = &o->time;
	const prsm_dyn_settled *settled = &m->settled;
	const int K = m->stages;
	memset(out, 0, sizeof *out);
	out->stages = K;
	out->settled = *settled;
	out->stepper_switch_time_s = NAN;
	for (int k = 0; k < K; k++)
		for (int j = 0; j < SHARES; j++)
			out->carrier_time_to_share_s[k][j] = NAN;
	for (int j = 0; j < SHARES; j++)
		out->speed_time_to_share_s[j] = NAN;

	sim_ctx c;
	memset(&c, 0, sizeof c);
	driver_pair impl = {0}, expl = {0}, *D = NULL;
	double *y = NULL, *y0 = NULL, *ywork = NULL;
	int rc = 0;
	c.m = m;
	c.K = K;
	c.torque = o->input.kind == PRSM_DYN_INPUT_TORQUE;
	c.i_psi = c.torque ? 2 : 0;
	c.i_energy = c.i_psi + 2 * (size_t)K;
	c.n = c.i_energy + 2;
	const size_t npts = dyn_output_points(o);
	out->point = calloc(npts, sizeof *out->point);
	out->stage = calloc(npts * (size_t)K, sizeof *out->stage);
	y = calloc(6 * c.n, sizeof(double));
	dyn_scratch_init(&c.s, m);
	if (out->point == NULL || out->stage == NULL || y == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu output points", npts);
		goto cleanup;
	}
	out->points = npts;
	y0 = y + c.n;
	ywork = y0 + c.n;
	c.jac_y = ywork + c.n;
	c.jac_f1 = c.jac_y + c.n;
	c.jac_f2 = c.jac_f1 + c.n;

	/* scales (docs/model §8.2.6) */
	const prsm_dyn_signal *sig = &o->input.signal;
	if (!isnan(tm->speed_scale_rad_s))
		c.w_scale = tm->speed_scale_rad_s;
	else if (!c.torque)
		c.w_scale = fmax(fabs(sig->value), fabs(sig->shape == PRSM_DYN_SHAPE_SINE ? sig->sine_amplitude : 0.0));
	else if (settled->defined && settled->screw_speed_rad_s != 0.0)
		c.w_scale = fabs(settled->screw_speed_rad_s);
	else
		c.w_scale = fmax(fabs(o->input.initial_speed_rad_s), m->stiff_switch_rad_s);
	if (!(c.w_scale > 0.0 && isfinite(c.w_scale)))
		c.w_scale = 1.0;
	double P_scale = settled->defined ? fabs(settled->point.power_input_W) : 0.0;
	if (!(P_scale > 0.0 && isfinite(P_scale)))
		P_scale = fabs(o->load.value) * m->lambda_K * c.w_scale;
	if (!(P_scale > 0.0 && isfinite(P_scale)))
		P_scale = 1.0;
	c.E_scale = P_scale * tm->end_s;
	double rate = 0.0;
	for (int k = 0; k < K && settled->defined; k++)
		if (isfinite(settled->carrier_rate_per_s[k]))
			rate = fmax(rate, settled->carrier_rate_per_s[k]);
	double h0 = !isnan(tm->initial_step_s) ? tm->initial_step_s : rate > 0.0 ? 1e-3 / rate : 1e-6 * tm->end_s;
	h0 = fmin(h0, fmin(tm->output_step_s, tm->end_s));

	/* initial state: carriers at rest */
	double t = 0.0;
	if (c.torque) {
		y[0] = 0.0;
		y[1] = o->input.initial_speed_rad_s / c.w_scale;
	}
	gsl_odeiv2_system sys = {rhs, jacobian, c.n, &c};
	const int karnopp = o->friction.stick_model == PRSM_DYN_STICK_KARNOPP;
	if (karnopp && o->input.initial_speed_rad_s == 0.0) {
		c.s.stuck = 1; /* at rest: it sticks unless the torque is outside the break-away band */
		int change;
		if ((rc = mode_change(&change, &c, 0.0, y, err)))
			goto cleanup;
		c.s.stuck = !change;
	}
	int use_implicit = tm->stepper == PRSM_DYN_STEPPER_MSBDF || tm->stepper == PRSM_DYN_STEPPER_RK4IMP ||
	                   (tm->stepper == PRSM_DYN_STEPPER_AUTO && c.torque);
	if (c.torque && use_implicit && fabs(o->input.initial_speed_rad_s) > m->stiff_switch_rad_s)
		use_implicit = 0;
	if (use_implicit) {
		if (pair_alloc(&impl, &sys, implicit_type(tm->stepper), h0, tm)) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the ODE stepper");
			goto cleanup;
		}
		D = &impl;
	}
	if (!use_implicit || c.torque) {
		if (pair_alloc(&expl, &sys, gsl_odeiv2_step_rk8pd, h0, tm)) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the ODE stepper");
			goto cleanup;
		}
		if (!use_implicit)
			D = &expl;
	}

	/* the kinks of ramp signals: the stepper restarts there */
	double kinks[2];
	int nkinks = 0;
	if (sig->shape == PRSM_DYN_SHAPE_RAMP && sig->ramp_time_s < tm->end_s)
		kinks[nkinks++] = sig->ramp_time_s;
	if (o->load.shape == PRSM_DYN_SHAPE_RAMP && o->load.ramp_time_s < tm->end_s)
		kinks[nkinks++] = o->load.ramp_time_s;

	/* t = 0 (the 0+ state of a step) */
	c.s.detail = 1;
	if ((rc = eval_state(&c, t, y, err)))
		goto cleanup;
	record(out, 0, &c, y);
	const int nshare = SHARES * K + (c.torque ? SHARES : 0);
	int found[SHARES * PRSM_DYN_STAGES_MAX + SHARES] = {0};
	for (int j = 0; j < nshare; j++) {
		const int usable = settled->defined && (j < SHARES * K ? isfinite(settled->carrier_ratio[j / SHARES]) &&
		                                                         settled->carrier_ratio[j / SHARES] != 0.0
		                                                       : settled->screw_speed_rad_s != 0.0);
		if (!usable)
			found[j] = 1;
		else if (share_function(&c, j, 0.0, y) >= 0.0) {
			found[j] = 1;
			if (j < SHARES * K)
				out->carrier_time_to_share_s[j / SHARES][j % SHARES] = 0.0;
			else
				out->speed_time_to_share_s[j % SHARES] = 0.0;
		}
	}
	size_t next = 1;
	const size_t planned_ns = (size_t)llround(tm->end_s * 1e9);
	size_t reported_ns = 0;
	double h = h0;
	while (next < npts) {
		const double t_out = next + 1 == npts ? tm->end_s : (double)next * tm->output_step_s;
		double t_stop = t_out;
		int at_kink = 0;
		for (int i = 0; i < nkinks; i++)
			if (kinks[i] > t && kinks[i] < t_stop) {
				t_stop = kinks[i];
				at_kink = 1;
			}
		const double t0 = t;
		memcpy(y0, y, c.n * sizeof(double));
		c.s.detail = 0;
		const int status = gsl_odeiv2_evolve_apply(D->main->e, D->main->c, D->main->s, &sys, &t, t_stop, &h, y);
		if (status != GSL_SUCCESS) {
			if (c.rc) {
				rc = prsm_error_set(err, c.rc, c.rhs_err.pointer, "the simulation stopped at t = %.6g s: %s",
				                    t, c.rhs_err.message);
			} else {
				rc = prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamics/time",
				                    "the integration did not converge at t = %.6g s (GSL: %s); try "
				                    "looser tolerances or the msbdf stepper", t, gsl_strerror(status));
			}
			goto cleanup;
		}
		out->steps++;
		if (out->steps > tm->max_steps || !(h > 1e-15 * fmax(t, tm->end_s))) {
			rc = prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamics/time",
			                    "the integration did not converge: %ld steps, step %.3g s at t = %.6g s",
			                    out->steps, h, t);
			goto cleanup;
		}
		if (prsm_cancel_requested(cancel)) {
			rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "cancelled at t = %.6g s of %.6g s", t, tm->end_s);
			goto cleanup;
		}
		/* Karnopp: a mode change inside the step cuts it there */
		int restart = 0;
		if (karnopp) {
			int change;
			if ((rc = mode_change(&change, &c, t, y, err)))
				goto cleanup;
			if (change) {
				double te;
				if ((rc = locate_mode_change(&te, &c, D->sub, t0, y0, t, ywork, err)) ||
				    (rc = state_at(&c, D->sub, t0, y0, te, y)))
					goto cleanup;
				t = te;
				c.s.stuck = !c.s.stuck;
				if (out->mode_changes < PRSM_DYN_MODE_CHANGES_MAX) {
					out->mode_change_time_s[out->mode_changes] = te;
					out->mode_change_to_stick[out->mode_changes] = c.s.stuck;
				}
				out->mode_changes++;
				y[1] = 0.0; /* sticking holds the screw; slip starts from rest */
				out->events++;
				restart = 1;
			}
		}
		/* share crossings inside [t0, t] */
		for (int j = 0; j < nshare; j++) {
			if (found[j])
				continue;
			const double g1 = share_function(&c, j, t, y);
			if (g1 < 0.0)
				continue;
			const double g0 = share_function(&c, j, t0, y0);
			double te = t;
			if (g0 < 0.0 && (rc = locate_share(&te, &c, D->sub, j, t0, y0, g0, t, g1, ywork)))
				goto cleanup;
			found[j] = 1;
			out->events++;
			if (j < SHARES * K)
				out->carrier_time_to_share_s[j / SHARES][j % SHARES] = te;
			else
				out->speed_time_to_share_s[j % SHARES] = te;
		}
		/* the stiff start is over (or back) */
		if (c.torque && impl.main != NULL) {
			const double w = fabs(y[1] * c.w_scale);
			driver_pair *want = D;
			if (D == &impl && !c.s.stuck && w > m->stiff_switch_rad_s)
				want = &expl;
			else if (D == &expl && (c.s.stuck || w < SWITCH_BACK_FACTOR * m->stiff_switch_rad_s))
				want = &impl;
			if (want != D) {
				if (want == &expl && isnan(out->stepper_switch_time_s))
					out->stepper_switch_time_s = t;
				D = want;
				restart = 1;
			}
		}
		if (restart || (at_kink && t == t_stop)) {
			gsl_odeiv2_driver_reset(D->main);
			if (!(h > 0.0))
				h = h0;
		}
		if (t == t_out) {
			c.s.detail = 1;
			if ((rc = eval_state(&c, t, y, err)))
				goto cleanup;
			record(out, next, &c, y);
			next++;
			const size_t done_ns = (size_t)llround(t * 1e9);
			if (progress != NULL && (done_ns - reported_ns >= planned_ns / 200 || next == npts)) {
				prsm_progress p = PRSM_PROGRESS_INIT;
				p.done = done_ns;
				p.planned = planned_ns;
				progress(progress_ctx, &p);
				reported_ns = done_ns;
			}
		}
	}
cleanup:
	out->rhs_evaluations = c.rhs;
	out->jacobian_evaluations = c.jac;
	pair_free(&impl);
	pair_free(&expl);
	free(y);
	if (rc)
		prsm_dyn_result_free(out);
	return rc;
}
