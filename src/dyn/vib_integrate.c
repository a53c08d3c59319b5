/*
 * vib_integrate.c: the right-hand side of the vibration models (docs/model §8.3.2, §8.3.3,
 * §8.3.5), its Jacobian-vector product, and the step-by-step integrator of §8.4.
 *
 * Integration choice (docs/model §8.4, issue 16): GSL's rk8pd stepper with the y_new error
 * control, driven here one step at a time (gsl_odeiv2_step_apply + gsl_odeiv2_control_hadjust,
 * the derivative at the end of each step reused as the next one's start, no allocation per step).
 *  - The rectangular mesh stiffness k_j(t) jumps at known times: the steps stop exactly at every
 *    switching instant of every roller and the stepper restarts there with the new stiffness
 *    (each step sees one smooth vector field).
 *  - The dead zones h(x; 1) are continuous: for the state alone §8.4 lets the error control
 *    shrink the steps that straddle a kink, and asks for the crossings to be located only for the
 *    variational equations (Lyapunov exponents, shooting), whose Jacobian jumps there. We locate
 *    every crossing in both cases (LOCATE_AUTO): when a trial step changes the region of a
 *    contact, regula falsi (Illinois) on re-steps from the step's start finds the first crossing,
 *    the step ends just past it (its own error estimate checked) and the variational part uses
 *    the side of each kink the step started on (the frozen "mode"), so it is exact on both sides.
 *    Measured on the gear pair with impacts: half the steps of the error control alone, and
 *    converged to 1e-12 where the error control alone (LOCATE_NEVER) is off by 1e-9 even at a
 *    tolerance of 1e-12 (its error estimate misjudges a step across a kink).
 * Outputs between steps come from Hermite interpolation with the derivatives at both ends:
 * quintic for positions (their second derivative is a rate's derivative), cubic for rates.
 */
#include "dyn/vib_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- right-hand side ---- */

void vib_trig_eval(const vib_core *c, double tau, vib_trig *t)
{
	if (c->pair) {
		t->pair_c = cos(c->Omega * tau);
		return;
	}
	t->mesh_s = sin(c->we * tau);
	t->mesh_c = cos(c->we * tau);
	t->te_sum = 0.0;
	for (int l = 0; l < c->lines; l++)
		t->te_sum += c->te_a[l] * cos(c->te_w[l] * tau + c->te_phi[l]);
}

void vib_rhs(const vib_core *c, const double *kap, const vib_trig *trig, double tau, const double *y, double *f,
             const signed char *mode)
{
	vib_trig own;
	if (trig == NULL) {
		vib_trig_eval(c, tau, &own);
		trig = &own;
	}
	if (c->pair) {
		/* §8.3.5: x'' + 2 zeta x' + kappa(tau) h(x; 1) = f_m + epsilon Omega^2 cos(Omega tau) */
		const double x = y[0], v = y[1];
		const double hx = mode != NULL ? vib_dead_on(x, mode[0]) : vib_dead(x);
		f[0] = v;
		f[1] = -2.0 * c->zeta * v - kap[0] * hx + c->fm + c->eps * c->Omega * c->Omega * trig->pair_c;
		return;
	}
	const int Z = c->Z;
	double Fth = c->F0;
	const int k = c->gear ? Z : 0; /* the thread's contact index */
	if (c->axial) {
		/* §8.3.2, scaled: Y' = r W, W' = r (F_0/(k_a b_a) - 2 zeta_a W - h(Y; 1) + TE''/(b_a omega_a^2)) */
		const double Y = y[vib_iY(c)], W = y[vib_iW(c)];
		const double hY = mode != NULL ? vib_dead_on(Y, mode[k]) : vib_dead(Y);
		const double te = trig->te_sum;
		f[vib_iY(c)] = c->r * W;
		f[vib_iW(c)] = c->r * (c->f0 - 2.0 * c->zeta_a * W - hY + te);
		Fth = c->Fth_scale * (hY + 2.0 * c->zeta_a * W);
	} else {
		f[vib_iY(c)] = 0.0;
		f[vib_iW(c)] = 0.0;
	}
	if (!c->gear) {
		for (int j = 0; j <= Z; j++)
			f[vib_iP(c, j)] = f[vib_iV(c, j)] = 0.0;
		return;
	}
	/* §8.3.3: friction on the flank that carries F_th (N_j from F_th), mesh forces of both ring gears.
	 * With b = v* + g_psi V_0 the slip of roller j is v_j = b + g_phi V_j, so |v_j|^2, v_j,z and
	 * v_j . G are affine or quadratic in V_j with coefficients common to all rollers, and
	 * f_j = fac v_j, fac = -mu N_j / s = -mu (-F_th/Z) / (n_z s - mu v_z), s = |v_j|_eps. */
	const int same = (Fth >= 0.0) == (c->F0 >= 0.0);
	const double *Gphi = same ? c->Gphi : c->Gphi_o, *Gpsi = same ? c->Gpsi : c->Gpsi_o;
	const double nz = same ? c->nz : c->nz_o;
	double gphi[3], gpsi[3];
	if (same) {
		memcpy(gphi, c->gphi, sizeof gphi);
		memcpy(gpsi, c->gpsi, sizeof gpsi);
	} else {
		for (int i = 0; i < 3; i++) {
			gphi[i] = Gphi[i] * c->bg * c->wref / c->rb1;
			gpsi[i] = Gpsi[i] * c->bg * c->wref / c->rb2;
		}
	}
	const double V0 = y[vib_iV(c, 0)], P0 = y[vib_iP(c, 0)];
	double b[3];
	for (int i = 0; i < 3; i++)
		b[i] = c->vstar[i] + gpsi[i] * V0;
	const double bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + c->veps2;
	const double bg2 = 2.0 * (b[0] * gphi[0] + b[1] * gphi[1] + b[2] * gphi[2]);
	const double gg = gphi[0] * gphi[0] + gphi[1] * gphi[1] + gphi[2] * gphi[2];
	const double bGf = b[0] * Gphi[0] + b[1] * Gphi[1] + b[2] * Gphi[2];
	const double gGf = gphi[0] * Gphi[0] + gphi[1] * Gphi[1] + gphi[2] * Gphi[2];
	const double bGp = b[0] * Gpsi[0] + b[1] * Gpsi[1] + b[2] * Gpsi[2];
	const double gGp = gphi[0] * Gpsi[0] + gphi[1] * Gpsi[1] + gphi[2] * Gpsi[2];
	const double num = c->mu * Fth / Z; /* -mu (-F_th / Z) */
	const double es = c->eg * trig->mesh_s, ec = c->eg * trig->mesh_c;
	const double Fscale = 2.0 * c->kbar * c->bg; /* N per unit of kappa h + 2 zeta x' */
	double r[PRSM_VIB_ROLLERS_MAX];
	double sum_r = 0.0, Qpsi = 0.0, Fsum = 0.0;
	for (int j = 0; j < Z; j++) {
		const double Vj = y[vib_iV(c, j + 1)];
		const double sq = sqrt(bb + Vj * (bg2 + Vj * gg));
		const double vz = b[2] + gphi[2] * Vj;
		const double fac = num / (nz * sq - c->mu * vz);
		const double Qphi = fac * (bGf + Vj * gGf);
		Qpsi += fac * (bGp + Vj * gGp);
		/* e_j = e_g sin(omega_e tau + 2 pi gamma_j), its rate */
		const double e = es * c->cphase[j] + ec * c->sphase[j];
		const double ed = c->we * (ec * c->cphase[j] - es * c->sphase[j]);
		const double xr = P0 + y[vib_iP(c, j + 1)] - e;
		const double hx = mode != NULL ? vib_dead_on(xr, mode[j]) : vib_dead(xr);
		const double Fj = Fscale * (kap[j] * hx + c->two_zeta_g * (V0 + Vj - ed));
		r[j] = Qphi - c->rb1 * Fj;
		sum_r += r[j];
		Fsum += Fj;
	}
	/* M a = (Q_psi - r_b2 sum F, Q_phi_j - r_b1 F_j): the arrow matrix of §8.3.1 */
	const double rpsi = Qpsi - c->rb2 * Fsum;
	const double apsi = (rpsi - c->Mpf / c->Mff * sum_r) / c->schur;
	const double aphi0 = c->Mpf * apsi, sphi = c->accel_phi / c->Mff;
	f[vib_iP(c, 0)] = V0;
	f[vib_iV(c, 0)] = apsi * c->accel_psi;
	for (int j = 0; j < Z; j++) {
		f[vib_iP(c, j + 1)] = y[vib_iV(c, j + 1)];
		f[vib_iV(c, j + 1)] = (r[j] - aphi0) * sphi;
	}
}

void vib_forces(const vib_core *c, const double *kap, double tau, const double *y, double *mesh, double *Fth_out)
{
	if (c->pair) {
		mesh[0] = kap[0] * vib_dead(y[0]);
		*Fth_out = NAN;
		return;
	}
	double Fth = c->F0;
	if (c->axial)
		Fth = c->Fth_scale * (vib_dead(y[vib_iY(c)]) + 2.0 * c->zeta_a * y[vib_iW(c)]);
	*Fth_out = Fth;
	if (!c->gear) {
		for (int j = 0; j < c->Z; j++)
			mesh[j] = NAN;
		return;
	}
	double e[PRSM_VIB_ROLLERS_MAX], ed[PRSM_VIB_ROLLERS_MAX];
	vib_mesh_errors(c, tau, e, ed);
	const double Fscale = 2.0 * c->kbar * c->bg;
	for (int j = 0; j < c->Z; j++) {
		const double xr = y[vib_iP(c, 0)] + y[vib_iP(c, j + 1)] - e[j];
		mesh[j] = Fscale * (kap[j] * vib_dead(xr) + c->two_zeta_g * (y[vib_iV(c, 0)] + y[vib_iV(c, j + 1)] - ed[j]));
	}
}

/* J(y) v on the frozen side of every kink: analytic for the gear pair, central differences of the
 * (then smooth) right-hand side for the reduced model. */
static void jvp(vib_int *it, double tau, const double *y, const double *v, double *out)
{
	const vib_core *c = it->c;
	const signed char *mode = it->mode[0];
	if (c->pair) {
		out[0] = v[1];
		out[1] = -2.0 * c->zeta * v[1] - (mode[0] != 0 ? it->kap[0] * v[0] : 0.0);
		return;
	}
	const int n = it->n;
	double ymax = 1.0, vmax = 0.0;
	for (int i = 0; i < n; i++) {
		ymax = fmax(ymax, fabs(y[i]));
		vmax = fmax(vmax, fabs(v[i]));
	}
	if (vmax == 0.0) {
		memset(out, 0, (size_t)n * sizeof *out);
		return;
	}
	const double d = 1e-7 * ymax / vmax;
	for (int i = 0; i < n; i++) {
		it->jv_p[i] = y[i] + d * v[i];
		it->jv_m[i] = y[i] - d * v[i];
	}
	vib_rhs(c, it->kap, &it->trig, tau, it->jv_p, it->jv_fp, mode);
	vib_rhs(c, it->kap, &it->trig, tau, it->jv_m, it->jv_fm, mode);
	for (int i = 0; i < n; i++)
		out[i] = (it->jv_fp[i] - it->jv_fm[i]) / (2.0 * d);
}

/* the time functions at tau from the anchored oscillator and polynomial (see vib_internal.h) */
static void trig_at(vib_int *it, double tau)
{
	const vib_core *c = it->c;
	if (it->osc_on) {
		double x = it->osc_w * (tau - it->osc_anchor);
		if (!it->osc_valid || !(fabs(x) <= 0.1)) {
			it->osc_anchor = tau;
			it->osc_c = cos(it->osc_w * tau);
			it->osc_s = sin(it->osc_w * tau);
			it->osc_valid = 1;
			x = 0.0;
		}
		/* Taylor to x^8 and x^9: truncation below 3e-17 for |x| <= 0.1 */
		const double u = x * x;
		const double cx = 1.0 + u * (-1.0 / 2 + u * (1.0 / 24 + u * (-1.0 / 720 + u * (1.0 / 40320))));
		const double sx = x * (1.0 + u * (-1.0 / 6 + u * (1.0 / 120 + u * (-1.0 / 5040 + u * (1.0 / 362880)))));
		const double cv = it->osc_c * cx - it->osc_s * sx, sv = it->osc_s * cx + it->osc_c * sx;
		if (c->pair) {
			it->trig.pair_c = cv;
		} else {
			it->trig.mesh_c = cv;
			it->trig.mesh_s = sv;
		}
	}
	if (it->te_on) {
		double d = tau - it->te_anchor;
		if (!it->te_valid || !(fabs(d) * it->te_wmax <= 0.1)) {
			/* s_m = sum_k a_k w_k^m cos^(m)(w_k tau_a + phi_k) / m! */
			it->te_anchor = tau;
			for (int m = 0; m < 10; m++)
				it->te_coef[m] = 0.0;
			for (int l = 0; l < c->lines; l++) {
				const double th = c->te_w[l] * tau + c->te_phi[l], co = cos(th), si = sin(th);
				const double der[4] = {co, -si, -co, si};
				double wm = c->te_a[l];
				for (int m = 0; m < 10; m++) {
					it->te_coef[m] += wm * der[m & 3];
					wm *= c->te_w[l] / (m + 1);
				}
			}
			it->te_valid = 1;
			d = 0.0;
		}
		double v = it->te_coef[9];
		for (int m = 8; m >= 0; m--)
			v = v * d + it->te_coef[m];
		it->trig.te_sum = v;
	}
}

static void osc_setup(vib_int *it)
{
	const vib_core *c = it->c;
	it->osc_valid = it->te_valid = 0;
	it->osc_on = it->te_on = 0;
	memset(&it->trig, 0, sizeof it->trig);
	it->trig.mesh_c = 1.0;
	if (c->pair) {
		it->osc_on = 1;
		it->osc_w = c->Omega;
		return;
	}
	if (c->eg != 0.0) {
		it->osc_on = 1;
		it->osc_w = c->we;
	}
	if (c->axial && c->lines > 0) {
		it->te_on = 1;
		it->te_wmax = 0.0;
		for (int l = 0; l < c->lines; l++)
			it->te_wmax = fmax(it->te_wmax, fabs(c->te_w[l]));
	}
}

static int sys_fn(double t, const double y[], double f[], void *params)
{
	vib_int *it = params;
	const int n = it->n;
	trig_at(it, t);
	for (int k = 0; k < it->copies; k++)
		vib_rhs(it->c, it->kap, &it->trig, t, y + k * n, f + k * n, NULL);
	for (int i = 0; i < it->nvar; i++)
		jvp(it, t, y, y + (1 + i) * n, f + (1 + i) * n);
	it->effort.rhs_evaluations++;
	return GSL_SUCCESS;
}

/* ---- setup ---- */

int vib_int_init(vib_int *it, const prsm_vib_model *m, int nvar, int copies, const prsm_vib_integration *o,
                 const prsm_cancel_flag *cancel)
{
	memset(it, 0, sizeof *it);
	it->mod = *m;
	it->c = &it->mod.c;
	it->n = it->c->n;
	it->nvar = nvar;
	it->copies = copies;
	it->dim = copies == 2 ? 2 * it->n : it->n * (1 + nvar);
	/* AUTO locates every crossing (see the top of this file): required with variational
	 * equations, and for the state alone cheaper and far more accurate than letting the error
	 * control shrink the steps at the kink; NEVER is the error control alone */
	it->locate = o->locate_kinks != PRSM_VIB_LOCATE_NEVER || nvar > 0;
	it->rel_tol = o->rel_tol;
	it->abs_tol = o->abs_tol;
	it->max_steps = o->max_steps;
	it->cancel = cancel;
	it->h = o->initial_step;
	const size_t dim = (size_t)it->dim, n = (size_t)it->n;
	it->step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, dim);
	it->ctl = gsl_odeiv2_control_y_new(o->abs_tol, o->rel_tol);
	double *buf = calloc(9 * dim + 4 * n, sizeof(double));
	if (it->step == NULL || it->ctl == NULL || buf == NULL) {
		free(buf);
		vib_int_free(it);
		return PRSM_ENOMEM;
	}
	it->y = buf;
	it->y0 = buf + dim;
	it->f0 = buf + 2 * dim;
	it->f1 = buf + 3 * dim;
	it->yerr = buf + 4 * dim;
	it->ylo = buf + 5 * dim;
	it->yhi = buf + 6 * dim;
	it->ftmp = buf + 7 * dim;
	it->scratch = buf + 8 * dim;
	it->jv_p = buf + 9 * dim;
	it->jv_m = it->jv_p + n;
	it->jv_fp = it->jv_m + n;
	it->jv_fm = it->jv_fp + n;
	it->sys.function = sys_fn;
	it->sys.jacobian = NULL;
	it->sys.dimension = dim;
	it->sys.params = it;
	vib_int_model_changed(it);
	return 0;
}

void vib_int_free(vib_int *it)
{
	if (it->step != NULL)
		gsl_odeiv2_step_free(it->step);
	if (it->ctl != NULL)
		gsl_odeiv2_control_free(it->ctl);
	free(it->y);
	it->step = NULL;
	it->ctl = NULL;
	it->y = NULL;
}

static double frac(double x)
{
	return x - floor(x);
}

static int cmp_double(const void *a, const void *b)
{
	const double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : (x > y ? 1 : 0);
}

/* the largest step: a sixth of the shortest period in play (scaled time) */
static double max_step(const vib_core *c)
{
	double w = 1.0;
	if (c->pair) {
		w = fmax(1.0, c->Omega);
	} else {
		if (c->gear)
			w = fmax(fmax(w, c->we), 1.5);
		else
			w = c->r;
		if (c->axial) {
			w = fmax(w, c->r);
			for (int l = 0; l < c->lines; l++)
				w = fmax(w, c->te_w[l]);
		}
	}
	return 2.0 * M_PI / w / 2.0;
}

void vib_int_model_changed(vib_int *it)
{
	const vib_core *c = it->c;
	osc_setup(it);
	it->T = 0.0;
	it->n_off = 0;
	for (int j = 0; j < c->Z; j++)
		it->kap[j] = 1.0;
	it->hmax = max_step(c);
	if (!(it->h > 0.0) || it->h > it->hmax)
		it->h = it->hmax / 4.0;
	if (!c->gear || c->kd == c->ks)
		return;
	if (c->D <= 0.0 || c->D >= 1.0) {
		for (int j = 0; j < c->Z; j++)
			it->kap[j] = c->D <= 0.0 ? c->ks : c->kd;
		return;
	}
	/* §8.4: every roller's switching instants u_j = 0 and u_j = eps_alpha - 1 */
	it->T = 2.0 * M_PI / c->we;
	int n = 0;
	double off[2 * PRSM_VIB_ROLLERS_MAX];
	for (int j = 0; j < c->Z; j++) {
		const double g = c->pair ? 0.0 : c->gamma[j];
		off[n++] = frac(-g);
		off[n++] = frac(c->D - g);
	}
	for (int i = 0; i < n; i++)
		if (off[i] > 1.0 - 1e-12)
			off[i] = 0.0;
	qsort(off, (size_t)n, sizeof off[0], cmp_double);
	for (int i = 0; i < n; i++)
		if (it->n_off == 0 || off[i] - it->off[it->n_off - 1] > 1e-12)
			it->off[it->n_off++] = off[i];
}

static double switch_time(const vib_int *it)
{
	return ((double)it->sw_k + it->off[it->sw_i]) * it->T;
}

/* the stiffness factors of the segment starting at tau (up to the next switch) */
static void segment_stiffness(vib_int *it, double tau)
{
	const vib_core *c = it->c;
	if (it->T <= 0.0)
		return;
	const double mid = 0.5 * (tau + switch_time(it));
	for (int j = 0; j < c->Z; j++) {
		const double g = c->pair ? 0.0 : c->gamma[j];
		const double u = frac(mid / it->T + g);
		it->kap[j] = u < c->D ? c->kd : c->ks;
	}
}

static double time_tol(double tau)
{
	return 1e-12 * fmax(1.0, fabs(tau));
}

static void regions_of(vib_int *it, double tau, const double *y, signed char *out)
{
	vib_contacts(it->c, tau, y, it->g_tmp);
	for (int k = 0; k < it->c->nc; k++)
		out[k] = vib_region(it->g_tmp[k]);
}

void vib_int_set(vib_int *it, double tau, const double *y)
{
	memcpy(it->y, y, (size_t)it->dim * sizeof *y);
	it->tau = tau;
	it->have_f0 = 0;
	if (it->T > 0.0) {
		const double tol = time_tol(tau);
		long k = (long)floor(tau / it->T) - 1;
		int i = 0;
		while (((double)k + it->off[i]) * it->T <= tau + tol) {
			if (++i == it->n_off) {
				i = 0;
				k++;
			}
		}
		it->sw_k = k;
		it->sw_i = i;
		segment_stiffness(it, tau);
	}
	for (int k = 0; k < it->copies; k++)
		regions_of(it, tau, it->y + (k == 1 ? it->n : 0), it->mode[k]);
	gsl_odeiv2_step_reset(it->step);
}

void vib_int_restep(vib_int *it, double tau0, const double *y0, const double *f0, double h, double *out)
{
	memcpy(out, y0, (size_t)it->dim * sizeof *out);
	if (h <= 0.0)
		return;
	gsl_odeiv2_step_apply(it->step, tau0, h, out, it->scratch, f0, NULL, &it->sys);
}

/* ---- dead-zone crossings ---- */

/* 1 when a region of copy 0 (or 1) at (tau, y) differs from the modes; *k_out, *copy_out the first */
static int changed(vib_int *it, double tau, const double *y, int *k_out, int *copy_out)
{
	signed char reg[PRSM_VIB_CONTACTS_MAX];
	for (int cp = 0; cp < it->copies; cp++) {
		regions_of(it, tau, y + (cp == 1 ? it->n : 0), reg);
		for (int k = 0; k < it->c->nc; k++)
			if (reg[k] != it->mode[cp][k]) {
				*k_out = k;
				*copy_out = cp;
				return 1;
			}
	}
	return 0;
}

/* the guard of contact k of copy cp, relative to the boundary it leaves its start mode through */
static double guard(vib_int *it, double tau, const double *y, int k, int cp, signed char to)
{
	vib_contacts(it->c, tau, y + (cp == 1 ? it->n : 0), it->g_tmp);
	const signed char from = it->mode[cp][k];
	const double b = from > 0 ? 1.0 : (from < 0 ? -1.0 : (to > 0 ? 1.0 : -1.0));
	return it->g_tmp[k] - b;
}

static signed char region_now(vib_int *it, double tau, const double *y, int k, int cp)
{
	vib_contacts(it->c, tau, y + (cp == 1 ? it->n : 0), it->g_tmp);
	return vib_region(it->g_tmp[k]);
}

/* The accepted step (tau0, y0, f0) -> y (length h) changed a region: find the first crossing and
 * end the step just past it. Returns the new step length; it->y holds the state there. */
static double locate_kink(vib_int *it, double tau0, double h)
{
	const size_t bytes = (size_t)it->dim * sizeof(double);
	memcpy(it->ylo, it->y0, bytes);
	memcpy(it->yhi, it->y, bytes);
	double lo = 0.0, hi = h;
	int k = 0, cp = 0;
	changed(it, tau0 + hi, it->yhi, &k, &cp);
	signed char to = region_now(it, tau0 + hi, it->yhi, k, cp);
	double glo = guard(it, tau0, it->ylo, k, cp, to), ghi = guard(it, tau0 + hi, it->yhi, k, cp, to);
	int side = 0;
	for (int iter = 0; iter < 100; iter++) {
		if (hi - lo <= 1e-13 * h + 4.0 * DBL_EPSILON * fabs(tau0))
			break;
		double t;
		if (iter % 8 == 7 || !(glo * ghi < 0.0))
			t = 0.5 * (lo + hi);
		else
			t = lo + (hi - lo) * glo / (glo - ghi);
		if (!(t > lo && t < hi))
			t = 0.5 * (lo + hi);
		vib_int_restep(it, tau0, it->y0, it->f0, t, it->ftmp);
		int k2, cp2;
		if (changed(it, tau0 + t, it->ftmp, &k2, &cp2)) {
			hi = t;
			memcpy(it->yhi, it->ftmp, bytes);
			memcpy(it->yerr, it->scratch, bytes); /* the error estimate of the step to hi */
			if (k2 != k || cp2 != cp) {
				k = k2;
				cp = cp2;
				to = region_now(it, tau0 + hi, it->yhi, k, cp);
				glo = guard(it, tau0 + lo, it->ylo, k, cp, to);
				side = 0;
			}
			ghi = guard(it, tau0 + hi, it->yhi, k, cp, to);
			if (side == 1)
				glo *= 0.5; /* Illinois */
			side = 1;
		} else {
			lo = t;
			memcpy(it->ylo, it->ftmp, bytes);
			glo = guard(it, tau0 + lo, it->ylo, k, cp, to);
			if (side == -1)
				ghi *= 0.5;
			side = -1;
		}
	}
	memcpy(it->y, it->yhi, bytes);
	it->effort.events++;
	return hi;
}

double vib_int_locate(vib_int *it, double tau0, const double *y0, const double *f0, double h, double g0,
                      double g1, vib_scalar_fn fn, void *ctx, double *y_at)
{
	double lo = 0.0, hi = h, glo = g0, ghi = g1;
	int side = 0;
	double best;
	for (int iter = 0; iter < 60; iter++) {
		if (hi - lo <= 1e-14 * h || glo == 0.0 || ghi == 0.0)
			break;
		double t = (iter % 8 == 7) ? 0.5 * (lo + hi) : lo + (hi - lo) * glo / (glo - ghi);
		if (!(t > lo && t < hi))
			t = 0.5 * (lo + hi);
		vib_int_restep(it, tau0, y0, f0, t, y_at);
		const double g = fn(ctx, it->c, tau0 + t, y_at);
		if (g == 0.0) {
			lo = hi = t;
			break;
		}
		if ((g > 0.0) == (glo > 0.0)) {
			lo = t;
			glo = g;
			if (side == -1)
				ghi *= 0.5;
			side = -1;
		} else {
			hi = t;
			ghi = g;
			if (side == 1)
				glo *= 0.5;
			side = 1;
		}
	}
	best = fabs(glo) < fabs(ghi) ? lo : hi;
	if (glo == 0.0)
		best = lo;
	else if (ghi == 0.0)
		best = hi;
	vib_int_restep(it, tau0, y0, f0, best, y_at);
	return best / h;
}

/* ---- the driver ---- */

int vib_int_error(const vib_int *it, int rc, prsm_error *err)
{
	if (rc == PRSM_ECANCELLED)
		return prsm_error_set(err, rc, NULL, "cancelled");
	if (rc == PRSM_ENOMEM)
		return prsm_error_set(err, rc, NULL, "out of memory");
	return prsm_error_set(err, rc, NULL, "%s", it->fail[0] ? it->fail : "the integration failed");
}

/* integrate to seg_end, which no stiffness switch precedes */
static int segment(vib_int *it, double seg_end)
{
	const size_t bytes = (size_t)it->dim * sizeof(double);
	if (!it->have_f0) {
		sys_fn(it->tau, it->y, it->f0, it);
		it->have_f0 = 1;
	}
	while (it->tau < seg_end) {
		const double remaining = seg_end - it->tau;
		if (remaining <= time_tol(it->tau)) {
			it->tau = seg_end;
			break;
		}
		double h = fmin(it->h, it->hmax);
		int truncated = 0;
		if (h >= remaining * (1.0 - 1e-12)) {
			h = remaining;
			truncated = 1;
		}
		memcpy(it->y0, it->y, bytes);
		const int st = gsl_odeiv2_step_apply(it->step, it->tau, h, it->y, it->yerr, it->f0, it->f1, &it->sys);
		double hnew = h;
		int adj = GSL_ODEIV_HADJ_NIL;
		int ok = st == GSL_SUCCESS;
		for (int i = 0; i < it->dim && ok; i++)
			ok = isfinite(it->y[i]);
		double tau1 = truncated ? seg_end : it->tau + h;
		int located = 0, cp, kk;
		if (ok && it->locate && changed(it, tau1, it->y, &kk, &cp)) {
			/* a crossing inside: end the step there (its error estimate is the located step's) */
			const double hh = locate_kink(it, it->tau, h);
			hnew = hh;
			adj = gsl_odeiv2_control_hadjust(it->ctl, it->step, it->y, it->yerr, it->f1, &hnew);
			if (adj != GSL_ODEIV_HADJ_DEC) {
				tau1 = it->tau + hh;
				if (tau1 >= seg_end - time_tol(seg_end))
					tau1 = seg_end;
				sys_fn(tau1, it->y, it->f1, it);
				located = 1;
			} else {
				hnew = fmin(hnew, 0.5 * h);
			}
		} else if (ok) {
			adj = gsl_odeiv2_control_hadjust(it->ctl, it->step, it->y, it->yerr, it->f1, &hnew);
		}
		if (!ok || adj == GSL_ODEIV_HADJ_DEC) {
			memcpy(it->y, it->y0, bytes);
			it->h = ok ? hnew : 0.5 * h;
			it->effort.rejected++;
			if (it->h < 1e-13 * fmax(1.0, fabs(it->tau)) || !isfinite(it->h)) {
				snprintf(it->fail, sizeof it->fail, "the step size fell below %g at scaled time %.9g (%s)",
				         1e-13 * fmax(1.0, fabs(it->tau)), it->tau, ok ? "error control" : "non-finite state");
				return PRSM_ENOCONVERGE;
			}
			continue;
		}
		if (located)
			truncated = 1; /* keep the proposed step for the next */
		for (int k = 0; k < it->copies; k++)
			regions_of(it, tau1, it->y + (k == 1 ? it->n : 0), it->mode[k]);
		if (it->obs != NULL) {
			const int rc = it->obs(it->obs_ctx, it, it->tau, it->y0, it->f0, tau1, it->y, it->f1);
			if (rc)
				return rc;
		}
		it->tau = tau1;
		double *t = it->f0;
		it->f0 = it->f1;
		it->f1 = t;
		if (!truncated || adj == GSL_ODEIV_HADJ_DEC)
			it->h = hnew;
		it->effort.steps++;
		if (it->effort.steps > it->max_steps) {
			snprintf(it->fail, sizeof it->fail, "more than %ld steps (scaled time %.9g)", it->max_steps, it->tau);
			return PRSM_ENOCONVERGE;
		}
		if ((it->effort.steps & 1023) == 0 && prsm_cancel_requested(it->cancel))
			return PRSM_ECANCELLED;
	}
	return 0;
}

int vib_int_advance(vib_int *it, double tau_end)
{
	while (it->tau < tau_end - time_tol(tau_end)) {
		double end = tau_end;
		int at_switch = 0;
		if (it->T > 0.0) {
			const double ts = switch_time(it);
			if (ts <= tau_end + time_tol(tau_end)) {
				end = fmin(ts, tau_end);
				at_switch = 1;
			}
		}
		const int rc = segment(it, end);
		if (rc)
			return rc;
		if (at_switch) {
			const double ts = switch_time(it);
			if (++it->sw_i == it->n_off) {
				it->sw_i = 0;
				it->sw_k++;
			}
			segment_stiffness(it, ts);
			it->have_f0 = 0;
			gsl_odeiv2_step_reset(it->step);
			it->effort.switches++;
		}
	}
	it->tau = tau_end;
	return 0;
}

/* ---- interpolation ---- */

void vib_hermite(const vib_core *c, const double *y0, const double *f0, const double *y1, const double *f1,
                 double h, double s, double *out)
{
	const double s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
	/* cubic Hermite basis (the copies of other components) */
	const double c00 = 2 * s3 - 3 * s2 + 1, c10 = s3 - 2 * s2 + s, c01 = -2 * s3 + 3 * s2, c11 = s3 - s2;
	/* quintic Hermite basis (value, first, second derivative at both ends) and its derivative */
	const double q0 = 1 - 10 * s3 + 15 * s4 - 6 * s5, q1 = s - 6 * s3 + 8 * s4 - 3 * s5;
	const double q2 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5, q3 = 0.5 * s3 - s4 + 0.5 * s5;
	const double q4 = -4 * s3 + 7 * s4 - 3 * s5, q5 = 10 * s3 - 15 * s4 + 6 * s5;
	const double d0 = -30 * s2 + 60 * s3 - 30 * s4, d1 = 1 - 18 * s2 + 32 * s3 - 15 * s4;
	const double d2 = s - 4.5 * s2 + 6 * s3 - 2.5 * s4, d3 = 1.5 * s2 - 4 * s3 + 2.5 * s4;
	const double d4 = -12 * s2 + 28 * s3 - 15 * s4, d5 = 30 * s2 - 60 * s3 + 30 * s4;
	const int n = c->n;
	for (int i = 0; i < n; i++)
		out[i] = c00 * y0[i] + c10 * h * f0[i] + c01 * y1[i] + c11 * h * f1[i];
	/* positions p with p' = k v: the quintic through p, k v, k v' at both ends; the rate v is its
	 * derivative over k (a quartic that also matches the step's increment of p) */
	const int np = c->pair ? 1 : c->Z + 2;
	for (int j = 0; j < np; j++) {
		int p, v;
		double k = 1.0;
		if (c->pair) {
			p = 0;
			v = 1;
		} else if (j <= c->Z) {
			p = vib_iP(c, j);
			v = vib_iV(c, j);
		} else {
			p = vib_iY(c);
			v = vib_iW(c);
			k = c->r;
		}
		const double a0 = y0[p], a1 = h * f0[p], a2 = h * h * k * f0[v];
		const double b0 = y1[p], b1 = h * f1[p], b2 = h * h * k * f1[v];
		out[p] = q0 * a0 + q1 * a1 + q2 * a2 + q3 * b2 + q4 * b1 + q5 * b0;
		if (k != 0.0 && h > 0.0)
			out[v] = (d0 * a0 + d1 * a1 + d2 * a2 + d3 * b2 + d4 * b1 + d5 * b0) / (h * k);
	}
}
