/*
 * eval.c: one state of the rigid-body model (docs/model §8.2.4): the normal force of each
 * stage backwards from the last, its friction, the carrier's Lagrange acceleration, the spline
 * torque and thrust-bearing force of each coupling, the input torque; with detail, the
 * Newton-Euler recovery of the roller and carrier forces and every power of the balance.
 */
#include "dyn/dyn_internal.h"

#include <math.h>
#include <string.h>

#define WEDGE_TOL 1e-12      /* |n_z - mu s_z| below which the flanks wedge */
#define COUPLING_TOL 1e-13   /* relative change of the spline force at convergence */
#define COUPLING_MAX_ITER 200
#define TORQUE_MAX_ITER 30
#define TORQUE_TOL 1e-12     /* relative residual of the torque balance */

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* sigma(x) = x / sqrt(x^2 + eps^2) (docs/model §8.2.3) */
static double smooth_sign(double x, double eps)
{
	return x / sqrt(x * x + eps * eps);
}

void dyn_scratch_init(dyn_scratch *s, const prsm_dyn_model *m)
{
	memset(s, 0, sizeof *s);
	for (int k = 0; k < m->stages; k++)
		s->flank[k] = m->settled.defined ? m->settled.stage[k].flank : PRSM_DYN_FLANK_LOWER;
}

/* The statics engine's spin, gear, drag and seal torques of stage st at the axial load F (N)
 * and screw speed w (rad/s), the load distribution of the reference load scaled to F
 * (docs/model §8.2.3, losses "statics"; the split is in dyn_internal.h), N m. */
static double loss_torque(const dyn_stage *st, double F, double w)
{
	const double s = F / st->loss_scale_load_N, s43 = s * cbrt(s);
	return s43 * st->loss_spin_Nm + st->loss_gear_per_moment * fabs(s * st->loss_moment_lin_Nm +
	                                                                s43 * st->loss_moment_spin_Nm) +
	       st->loss_constant_Nm + st->loss_viscous_Nm_s * w;
}

/* Normal force and friction of one roller on flank fl (docs/model §8.2.4): Phi = Z (N n_z + f_z)
 * is the axial force the stage's rollers need from the screw. */
static int contact_on(const prsm_dyn_model *m, const dyn_stage *st, const dyn_scratch *s, int fl,
                      double thd, double psid, double Phi, double *N, double f[3], double v[3])
{
	const prsm_dyn_friction *fr = &m->opts.friction;
	const double *A = st->A[fl], *B = st->B[fl], *n = st->n[fl];
	const double Z = st->Z;
	double shat[3], mu;
	if (s->direction) {
		/* break-away: slip about to start along +-B, static friction, carriers at rest */
		for (int i = 0; i < 3; i++) {
			v[i] = 0.0;
			shat[i] = s->direction * B[i] / st->B_norm;
		}
		mu = st->mu_s;
	} else {
		for (int i = 0; i < 3; i++)
			v[i] = A[i] * psid + B[i] * thd;
		if (fr->model == PRSM_DYN_FRICTION_VISCOUS) {
			for (int i = 0; i < 3; i++)
				f[i] = -fr->viscous_N_s_per_m * v[i];
			*N = (Phi - Z * f[2]) / (Z * n[2]);
			return isfinite(*N) ? 0 : PRSM_ENOCONVERGE;
		}
		const double speed = sqrt(dot3(v, v));
		const double r = sqrt(speed * speed + fr->smoothing_velocity_m_s * fr->smoothing_velocity_m_s);
		for (int i = 0; i < 3; i++)
			shat[i] = v[i] / r;
		mu = st->mu;
		if (fr->model == PRSM_DYN_FRICTION_STRIBECK) {
			const double q = speed / fr->stribeck_velocity_m_s;
			mu += (st->mu_s - st->mu) * exp(-q * q);
		}
	}
	const double den = n[2] - mu * shat[2];
	if (!(fabs(den) > WEDGE_TOL))
		return PRSM_ENOCONVERGE;
	*N = Phi / (Z * den);
	for (int i = 0; i < 3; i++)
		f[i] = -mu * *N * shat[i];
	return isfinite(*N) ? 0 : PRSM_ENOCONVERGE;
}

/* The flank that carries (docs/model §8.0, "Active flank"): the preferred one if its N >= 0,
 * else the other. Neither (beyond rounding): friction wedges the flanks, no axial force passes
 * (the statics engine's sliding efficiency is 0 there). */
static int contact(const prsm_dyn_model *m, const dyn_stage *st, dyn_scratch *s, int k, double thd,
                   double psid, double Phi, int *flank, double *N_out, double f_out[3],
                   double v_out[3], prsm_error *err)
{
	double N[2] = {NAN, NAN}, f[2][3] = {{0.0}}, v[2][3] = {{0.0}};
	int rc[2] = {1, 1}, fl = s->flank[k];
	for (int attempt = 0; attempt < 2; attempt++, fl ^= 1) {
		rc[fl] = contact_on(m, st, s, fl, thd, psid, Phi, &N[fl], f[fl], v[fl]);
		if (rc[fl] == 0 && N[fl] >= 0.0)
			goto found;
	}
	fl = rc[1] || (rc[0] == 0 && N[0] >= N[1]) ? 0 : 1;
	if ((rc[0] && rc[1]) || N[fl] < -1e-9 * fabs(Phi) / st->Z)
		return prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamics/friction",
		                      "stage %d: friction wedges the flanks (mu %g): no axial force can pass "
		                      "the screw-roller contact on either flank", k + 1, st->mu);
found:
	s->flank[k] = *flank = fl;
	*N_out = N[fl];
	memcpy(f_out, f[fl], sizeof f[fl]);
	memcpy(v_out, v[fl], sizeof v[fl]);
	return 0;
}

/* Newton-Euler recovery of roller and carrier (docs/model §8.2.4, "Checks"): N' from the
 * roller's axial balance, then spin, tangential and carrier balances for F_t, P_y and psi-ddot;
 * the radial balance for P_x. F: force of the screw on the roller. */
static void newton_euler(prsm_dyn_stage_point *q, const prsm_dyn_model *m, const dyn_stage *st,
                         int fl, const double F[3], double zdd, double psid, double psidd_L)
{
	const double cC = m->opts.friction.carrier_drag_Nm_s_per_rad;
	const double a = st->a, rg = st->r_g, Z = st->Z;
	const double *p = st->p[fl];
	/* the nut flank whose normal gives N' >= 0: m_R z-ddot = F_z + N' n'_z */
	const double need = st->m_R * zdd - F[2];
	int nf = 1 - fl;
	if (need * st->nn[nf][2] < 0.0)
		nf = fl;
	const double *nn = st->nn[nf], *pn = st->pn[nf];
	const double Np = need / nn[2];
	/* moments about the roller axis c = (a, 0): z.((r - c) x F) = (r_x - a) F_y - r_y F_x */
	const double S_screw = (p[0] - a) * F[1] - p[1] * F[0];
	const double S_nut = Np * ((pn[0] - a) * nn[1] - pn[1] * nn[0]);
	const double S = S_screw + S_nut, Ty = F[1] + Np * nn[1];
	/* eliminate F_t = (J_R (1 - i_g) psi-ddot - S) / r_g and P_y = -(J_C psi-ddot + c_C psi-dot) /
	 * (Z a) from m_R a psi-ddot = Ty + F_t + P_y; the coefficient of psi-ddot is J_psi / (Z a) */
	const double Jpsi = st->J_C + Z * (st->m_R * a * a + st->J_R * (1.0 - st->i_g) * (1.0 - st->i_g));
	const double psidd = (Z * a * (Ty - S / rg) - cC * psid) / Jpsi;
	const double Ft = (st->J_R * (1.0 - st->i_g) * psidd - S) / rg;
	const double Py = -(st->J_C * psidd + cC * psid) / (Z * a);
	const double Px = -st->m_R * a * psid * psid - F[0] - Np * nn[0] + fabs(Ft) * st->tan_alpha;
	q->nut_contact_force_N = Np;
	q->gear_tangential_force_N = Ft;
	q->gear_tooth_force_N = fabs(Ft) / (2.0 * st->cos_alpha);
	q->cage_force_N = hypot(Px, Py);
	q->newton_euler_carrier_accel_rad_s2 = psidd;
	/* the size of the terms that cancel in psi-ddot */
	const double scale = fabs(psidd_L) + Z * a * (fabs(F[1]) + fabs(Np * nn[1]) +
	                                              (fabs(S_screw) + fabs(S_nut)) / rg) / Jpsi;
	q->newton_euler_residual = scale > 0.0 ? fabs(psidd - psidd_L) / scale : 0.0;
}

int dyn_eval_motion(const prsm_dyn_model *m, dyn_scratch *s, const dyn_motion *mo,
                    prsm_dyn_point *pt, prsm_dyn_stage_point *sp, prsm_error *err)
{
	const prsm_dyn_options *o = &m->opts;
	const int K = m->stages, statics = o->losses == PRSM_DYN_LOSSES_STATICS;
	const double h = m->hand, thd = mo->theta_dot, thdd = mo->theta_ddot;
	const double cC = o->friction.carrier_drag_Nm_s_per_rad;
	const double mu_SS = o->couplings.spline_friction, mu_NS = o->couplings.thrust_bearing_friction;
	const double F_N = prsm_dyn_signal_value(&o->load, mo->t);
	const double sig = s->direction ? (double)s->direction
	                                : smooth_sign(thd, o->friction.coupling_smoothing_rad_s);
	double B_next = 0.0, M_next = 0.0, s_next = 0.0; /* B_{k+1}, M_{k+1}, s_{k+1} */
	double P_slide = 0.0, P_coup = 0.0, P_other = 0.0, P_kin = 0.0, ne_max = 0.0;
	int rc;
	s->evaluations++;
	for (int k = K - 1; k >= 0; k--) {
		const dyn_stage *st = &m->stage[k];
		prsm_dyn_stage_point *q = &sp[k];
		const double psid = s->direction ? 0.0 : mo->psi_dot[k];
		const double zdd = -h * st->lambda * thdd;               /* nut k, m/s^2 */
		const double F_on = k == K - 1 ? h * F_N : -B_next;      /* external force on group k */
		const double Phi = st->M_axial * zdd - F_on;             /* = Z (N n_z + f_z) */
		double N = 0.0, f[3] = {0.0}, v[3] = {0.0}, F[3];
		int fl = 0;
		if ((rc = contact(m, st, s, k, thd, psid, Phi, &fl, &N, f, v, err)))
			return rc;
		const double *n = st->n[fl], *p = st->p[fl];
		for (int i = 0; i < 3; i++)
			F[i] = N * n[i] + f[i];
		const double tau = -st->Z * (p[0] * F[1] - p[1] * F[0]); /* rollers on screw k */
		const double psidd = s->direction ? 0.0 : (st->Z * dot3(f, st->A[fl]) - cC * psid) / st->J_psi;
		const double Fz = st->Z * F[2];                          /* all rollers, N */
		double T_loss = 0.0;
		if (statics)
			T_loss = sig * loss_torque(st, fabs(Fz), fabs(thd));
		double M, B = 0.0, s_k = 0.0, T_NS = 0.0;
		if (k == 0) {
			M = st->J_S * thdd + M_next - tau + T_loss;
		} else {
			/* screw k: axial m_S z-ddot_{k-1} = -Z F_z + s_k + B_k - s_{k+1} (the spline of screw k+1
			 * reacts on screw k), rotation J_S theta-ddot = M_k - M_{k+1} + tau - T_NS - T_loss;
			 * |M| and |B| inside s_k and T_NS: a contraction of factor mu_SS mu_NS r_NS / r_SS */
			const double zdd_prev = -h * st->lambda_prev * thdd;
			int it;
			for (it = 0; it < COUPLING_MAX_ITER; it++) {
				B = st->m_S * zdd_prev + Fz - s_k + s_next;
				T_NS = mu_NS * fabs(B) * st->r_NS * sig;
				M = st->J_S * thdd + M_next - tau + T_NS + T_loss;
				const double s_new = h * mu_SS * fabs(M) / st->r_SS * sig;
				const int done = fabs(s_new - s_k) <= COUPLING_TOL * fabs(s_new);
				s_k = s_new;
				if (done)
					break;
			}
			if (it == COUPLING_MAX_ITER)
				return prsm_error_set(err, PRSM_ENOCONVERGE, "/couplings",
				                      "stage %d: the spline and thrust-bearing forces do not converge "
				                      "(the coupling locks)", k + 1);
			B = st->m_S * zdd_prev + Fz - s_k + s_next;
			T_NS = mu_NS * fabs(B) * st->r_NS * sig;
			M = st->J_S * thdd + M_next - tau + T_NS + T_loss;
			P_coup += h * s_k * st->lead_prev * thd + T_NS * thd;
		}
		q->carrier_angle_rad = mo->psi ? mo->psi[k] : 0.0;
		q->carrier_speed_rad_s = psid;
		q->carrier_accel_rad_s2 = psidd;
		q->carrier_ratio = thd != 0.0 ? psid / thd : NAN;
		q->nut_position_mm = st->lambda * mo->theta * 1e3;
		q->flank = fl;
		q->contact_normal_force_N = N;
		memcpy(q->friction_force_N, f, sizeof f);
		q->slip_speed_m_s = sqrt(dot3(v, v));
		q->stage_axial_load_N = fabs(Fz);
		q->spline_torque_Nm = M;
		q->spline_force_N = s_k;
		q->thrust_load_N = fabs(B);
		q->thrust_torque_Nm = T_NS;
		q->loss_torque_Nm = T_loss;
		q->sliding_power_W = -st->Z * dot3(f, v);
		if (s->detail && !s->direction) {
			newton_euler(q, m, st, fl, F, zdd, psid, psidd);
			ne_max = fmax(ne_max, q->newton_euler_residual);
		} else {
			q->nut_contact_force_N = q->gear_tangential_force_N = q->gear_tooth_force_N = NAN;
			q->cage_force_N = q->newton_euler_carrier_accel_rad_s2 = NAN;
			q->newton_euler_residual = 0.0;
		}
		P_slide += q->sliding_power_W;
		P_other += T_loss * thd + cC * psid * psid;
		P_kin += st->J_psi * psid * psidd;
		M_next = M;
		B_next = B;
		s_next = s_k;
	}
	const prsm_dyn_input *in = &o->input;
	pt->time_s = mo->t;
	pt->screw_angle_rad = mo->theta;
	pt->screw_speed_rad_s = thd;
	pt->screw_accel_rad_s2 = thdd;
	pt->axial_load_N = F_N;
	pt->input_torque_Nm = M_next + in->viscous_drag_Nm_s_per_rad * thd + in->motor_inertia_kg_m2 * thdd;
	pt->motor_torque_Nm = pt->input_torque_Nm;
	pt->power_input_W = pt->input_torque_Nm * thd;
	pt->power_output_W = F_N * m->lambda_K * thd;
	pt->efficiency = thd != 0.0 && pt->power_input_W != 0.0 ? pt->power_output_W / pt->power_input_W : NAN;
	pt->power_sliding_W = P_slide;
	pt->power_couplings_W = P_coup;
	pt->power_other_W = P_other + in->viscous_drag_Nm_s_per_rad * thd * thd;
	pt->power_kinetic_W = m->J_theta * thd * thdd + P_kin;
	const double terms[] = {pt->power_output_W, pt->power_sliding_W, pt->power_couplings_W,
	                        pt->power_other_W, pt->power_kinetic_W};
	double sum = 0.0, mag = fabs(pt->power_input_W);
	for (size_t i = 0; i < sizeof terms / sizeof terms[0]; i++) {
		sum += terms[i];
		mag += fabs(terms[i]);
	}
	pt->power_balance_residual_W = pt->power_input_W - sum;
	const double ref = fmax(fabs(pt->power_input_W), 0.5 * mag);
	pt->power_balance_relative = ref > 0.0 ? fabs(pt->power_balance_residual_W) / ref : 0.0;
	pt->newton_euler_residual = ne_max;
	pt->stuck = s->stuck;
	return 0;
}

int dyn_eval_torque(const prsm_dyn_model *m, dyn_scratch *s, dyn_motion *mo, prsm_dyn_point *pt,
                    prsm_dyn_stage_point *sp, prsm_error *err)
{
	const double Tm = prsm_dyn_signal_value(&m->opts.input.signal, mo->t);
	int rc;
	if (s->stuck) {
		/* Karnopp stick (docs/model §8.2.6): the static friction holds whatever T_m is */
		mo->theta_dot = mo->theta_ddot = 0.0;
		if ((rc = dyn_eval_motion(m, s, mo, pt, sp, err)))
			return rc;
		pt->input_torque_Nm = pt->motor_torque_Nm = Tm;
		pt->power_input_W = 0.0;
		return 0;
	}
	/* T_in is affine in theta-ddot while the slip directions and the signs of M_k, B_k hold
	 * (nearly so with the statics losses): secant steps from theta-ddot = 0 */
	double x0 = 0.0, x1, T0, T1;
	mo->theta_ddot = x0;
	if ((rc = dyn_eval_motion(m, s, mo, pt, sp, err)))
		return rc;
	T0 = pt->input_torque_Nm;
	x1 = (Tm - T0) / m->J_theta;
	int it;
	for (it = 0; it < TORQUE_MAX_ITER; it++) {
		mo->theta_ddot = x1;
		if ((rc = dyn_eval_motion(m, s, mo, pt, sp, err)))
			return rc;
		T1 = pt->input_torque_Nm;
		const double tol = TORQUE_TOL * (fabs(Tm) + fabs(T0) + m->J_theta * fabs(x1));
		if (fabs(T1 - Tm) <= tol || x1 == x0)
			break;
		double slope = (T1 - T0) / (x1 - x0);
		if (!(slope > 0.0) || !isfinite(slope))
			slope = m->J_theta;
		x0 = x1;
		T0 = T1;
		x1 += (Tm - T1) / slope;
	}
	if (it == TORQUE_MAX_ITER)
		return prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamics/input",
		                      "no screw acceleration balances the motor torque %g N m at t = %g s "
		                      "(the torque balance did not converge)", Tm, mo->t);
	pt->motor_torque_Nm = Tm;
	return 0;
}

void dyn_speed_input(const prsm_dyn_model *m, double t, double *theta, double *theta_dot,
                     double *theta_ddot)
{
	const prsm_dyn_signal *sg = &m->opts.input.signal;
	const double v = sg->value;
	*theta_dot = prsm_dyn_signal_value(sg, t);
	*theta_ddot = prsm_dyn_signal_rate(sg, t);
	switch (sg->shape) {
	case PRSM_DYN_SHAPE_RAMP: {
		const double tr = sg->ramp_time_s;
		*theta = t < tr ? 0.5 * v * t * t / tr : v * (t - 0.5 * tr);
		break;
	}
	case PRSM_DYN_SHAPE_SINE: {
		const double w = 2.0 * M_PI * sg->sine_frequency_Hz;
		*theta = v * t + (w > 0.0 ? sg->sine_amplitude * (1.0 - cos(w * t)) / w : 0.0);
		break;
	}
	default:
		*theta = v * t;
	}
}

int dyn_breakaway(double *forward_Nm, double *backward_Nm, const prsm_dyn_model *m, dyn_scratch *s,
                  double t, prsm_error *err)
{
	double psi[PRSM_DYN_STAGES_MAX] = {0}, psid[PRSM_DYN_STAGES_MAX] = {0};
	prsm_dyn_point pt;
	prsm_dyn_stage_point sp[PRSM_DYN_STAGES_MAX];
	dyn_motion mo = {t, 0.0, 0.0, 0.0, psi, psid};
	const int detail = s->detail, stuck = s->stuck;
	int flank[PRSM_DYN_STAGES_MAX], rc = 0;
	memcpy(flank, s->flank, sizeof flank);
	s->detail = s->stuck = 0;
	s->direction = 1;
	rc = dyn_eval_motion(m, s, &mo, &pt, sp, err);
	*forward_Nm = pt.input_torque_Nm;
	if (rc == 0) {
		s->direction = -1;
		rc = dyn_eval_motion(m, s, &mo, &pt, sp, err);
		*backward_Nm = pt.input_torque_Nm;
	}
	s->direction = 0;
	s->detail = detail;
	s->stuck = stuck;
	memcpy(s->flank, flank, sizeof flank);
	return rc;
}
