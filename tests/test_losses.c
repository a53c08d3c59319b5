/*
 * test_losses.c: docs/model/kinematics-efficiency-stiffness-life.md efficiency with spin, ring-gear mesh, drag and seal losses
 * (model/losses.h): sliding-only equals prsm_efficiency and the closed form; the spin moment
 * against a numerical integral of mu p r over the Hertz ellipse; the spin speed against the
 * curl of the bodies' velocity fields; the spin torque against per-contact Hertz solves; the
 * roller moment against an explicit force balance with the mirrored nut flank; Ohlendorf's
 * H_v against a mesh-cycle average of the sliding power; the directions in load, lead, roller
 * count and speed, with finite-difference checks of the derivatives; the energy balance; the
 * no-load, at-rest and self-locking points; every error path.
 */
#include "test_support.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <stddef.h>
#include <string.h>

#include "io/global.h"
#include "model/analysis.h"
#include "model/hertz.h"
#include "model/losses.h"

#define RPM (2.0 * M_PI / 60.0) /* rad/s per rpm */

static void analyse(prsm_analysis *a, prsm_design *d)
{
	prsm_problems w;
	prsm_problems_init(&w);
	assert_int_equal(prsm_analysis_nominal(a, d, &w, NULL), 0);
}

/* Losses of d at its operating point with options o and equal shares; asserts success. */
static void losses(prsm_losses_result *out, prsm_design *d, const prsm_losses_options *o)
{
	prsm_analysis a;
	prsm_error err = PRSM_ERROR_INIT;
	analyse(&a, d);
	int rc = prsm_losses_compute(out, d, &a.kinematics, &a.screw, &a.nut, NULL, NULL, o, &err);
	if (rc)
		print_error("prsm_losses_compute: %s\n", err.message);
	assert_int_equal(rc, 0);
}

static prsm_losses_options only(int spin, int gear, double drag_Nm, double viscous, double seal_Nm)
{
	prsm_losses_options o = PRSM_LOSSES_OPTIONS_INIT;
	o.spin = spin;
	o.gear = gear;
	o.drag_torque_Nm = drag_Nm;
	o.viscous_drag_Nm_s_per_rad = viscous;
	o.seal_torque_Nm = seal_Nm;
	return o;
}

/* Body frame (radial, tangential, axial) at angle th -> pair frame. */
static void to_cartesian(double out[3], const double v[3], double th)
{
	out[0] = v[0] * cos(th) - v[1] * sin(th);
	out[1] = v[0] * sin(th) + v[1] * cos(th);
	out[2] = v[2];
}

/* ---- 1. sliding only ---------------------------------------------------------------------- */

/* With spin, gear and drag off eta and eta' are prsm_efficiency's exactly, and within 0.001 of
 * tan b / tan(b + rho) (docs/model/kinematics-efficiency-stiffness-life.md: 0.9048 at mu 0.05, beta 45 deg). */
static void test_sliding_only(void **state)
{
	(void)state;
	const double mus[] = {0.05, 0.0731, 0.10};
	const prsm_losses_options o = only(0, 0, 0.0, 0.0, 0.0);
	for (int i = 0; i < 3; i++) {
		prsm_design d;
		prsm_analysis a;
		prsm_losses_result r;
		case_a(&d);
		d.mu_screw_roller = mus[i];
		d.mu_nut_roller = 0.0817;
		d.axial_load_N = 7123.4;
		d.screw_speed_rad_s = 91.7;
		analyse(&a, &d);
		losses(&r, &d, &o);
		assert_true(r.eta == a.efficiency.eta);
		assert_true(r.eta_back == a.efficiency.eta_back);
		double rho = atan(mus[i]);
		assert_close(r.eta, tan(d.flank_angle_rad) / tan(d.flank_angle_rad + rho), 1e-3);
		assert_close(r.eta_back, tan(d.flank_angle_rad - rho) / tan(d.flank_angle_rad), 1e-3);
		assert_close(r.spin_torque_Nm + r.gear_torque_Nm + r.drag_torque_Nm + r.seal_torque_Nm, 0.0, 0.0);
		assert_close(r.input_torque_Nm, a.efficiency.input_torque_Nm, 1e-12 * r.input_torque_Nm);
	}
	prsm_design d;
	prsm_losses_result r;
	case_a(&d);
	d.axial_load_N = 2385.0;
	d.screw_speed_rad_s = 37.3;
	losses(&r, &d, &o);
	assert_close(r.eta_closed_form, 0.9048, 5e-5);
	assert_close(r.eta, 0.9048, 1e-3);
	assert_close(r.eta_back, 0.9048, 1e-3);
}

/* ---- 2. spin -------------------------------------------------------------------------------- */

typedef struct {
	double a, b, x;
} ellipse;

static double inner_integrand(double y, void *p)
{
	const ellipse *e = p;
	double s = 1.0 - e->x * e->x / (e->a * e->a) - y * y / (e->b * e->b);
	return sqrt(fmax(s, 0.0)) * sqrt(e->x * e->x + y * y);
}

static double outer_integrand(double x, void *p)
{
	ellipse e = *(const ellipse *)p;
	e.x = x;
	double Y = e.b * sqrt(fmax(0.0, 1.0 - x * x / (e.a * e.a)));
	gsl_integration_workspace *ws = gsl_integration_workspace_alloc(2000);
	gsl_function f = {inner_integrand, &e};
	double r = 0.0, abserr;
	gsl_integration_qags(&f, 0.0, Y, 0.0, 1e-12, 2000, ws, &r, &abserr);
	gsl_integration_workspace_free(ws);
	return r;
}

/* integral of mu p(x, y) sqrt(x^2 + y^2) over the ellipse, by quadrature in x and y */
static double spin_moment_by_quadrature(double mu, double Q, double a, double b)
{
	ellipse e = {a, b, 0.0};
	gsl_integration_workspace *ws = gsl_integration_workspace_alloc(2000);
	gsl_function f = {outer_integrand, &e};
	double r = 0.0, abserr;
	gsl_integration_qags(&f, 0.0, a, 0.0, 1e-11, 2000, ws, &r, &abserr);
	gsl_integration_workspace_free(ws);
	double p_max = 1.5 * Q / (M_PI * a * b);
	return 4.0 * mu * p_max * r; /* four quadrants */
}

/* (3/8) mu Q a E(e) equals the integral of mu p r over the Hertz ellipse, for several
 * ellipticities (to 1e-6; it is exact). */
static void test_spin_moment_integral(void **state)
{
	(void)state;
	prsm_global_init();
	const double Fr[] = {0.0, 0.3719, 0.5, 0.9, 0.9873};
	for (int i = 0; i < 5; i++) {
		prsm_hertz h;
		double sum = 0.4137, k1 = sum * (1 - Fr[i]) / 2, k2 = sum * (1 + Fr[i]) / 2;
		assert_int_equal(prsm_hertz_solve(&h, k1, k2, 211300.0, 0.293, 204700.0, 0.301, 173.9), 0);
		double mu = 0.0613;
		double M = prsm_losses_spin_moment_Nmm(mu, h.load_N, h.a_mm, h.b_mm);
		double Mq = spin_moment_by_quadrature(mu, h.load_N, h.a_mm, h.b_mm);
		assert_close(M, Mq, 1e-6 * Mq);
		if (Fr[i] == 0.0) /* circle: 3 pi mu Q a / 16 */
			assert_close(M, 3.0 * M_PI * mu * h.load_N * h.a_mm / 16.0, 1e-12 * M);
	}
}

/* The spin speed from the curl of the velocity fields: roller = carrier rotation about z +
 * spin about its axis at (a, 0) + axial translation; screw = rotation about z; nut = axial
 * translation. Omega_rel = curl(v_roller - v_body) / 2 by central differences, projected on
 * the contact normal in the pair frame. Also checks that Omega_rel is axial. */
typedef struct {
	double kc, spin, a, v, body_spin, body_v;
} fields;

static void relative_velocity(double out[3], const fields *f, const double p[3])
{
	double vr[3] = {-f->kc * p[1] - f->spin * p[1], f->kc * p[0] + f->spin * (p[0] - f->a), f->v};
	double vb[3] = {-f->body_spin * p[1], f->body_spin * p[0], f->body_v};
	for (int i = 0; i < 3; i++)
		out[i] = vr[i] - vb[i];
}

static void half_curl(double out[3], const fields *f, const double p[3])
{
	double J[3][3], h = 1e-3; /* J[i][j] = d v_i / d x_j */
	for (int j = 0; j < 3; j++) {
		double pp[3] = {p[0], p[1], p[2]}, pm[3] = {p[0], p[1], p[2]}, vp[3], vm[3];
		pp[j] += h;
		pm[j] -= h;
		relative_velocity(vp, f, pp);
		relative_velocity(vm, f, pm);
		for (int i = 0; i < 3; i++)
			J[i][j] = (vp[i] - vm[i]) / (2 * h);
	}
	out[0] = 0.5 * (J[2][1] - J[1][2]);
	out[1] = 0.5 * (J[0][2] - J[2][0]);
	out[2] = 0.5 * (J[1][0] - J[0][1]);
}

static void test_spin_speed_independent(void **state)
{
	(void)state;
	const double designs[][4] = {{5, 2.0, 3.25, 45.0}, {4, 1.3, 2.87, 38.0}, {7, 2.5, 3.1, 55.0}};
	const prsm_losses_options o = only(1, 0, 0.0, 0.0, 0.0);
	for (int i = 0; i < 3; i++) {
		prsm_design d;
		prsm_analysis a;
		prsm_losses_result r;
		standard_design(&d, (int)designs[i][0], designs[i][1], designs[i][2], designs[i][3], 3, 5);
		d.axial_load_N = 3917.0;
		d.screw_speed_rad_s = -47.3; /* the sign carries through */
		analyse(&a, &d);
		losses(&r, &d, &o);
		const prsm_kinematics *k = &a.kinematics;
		const prsm_contact *c[2] = {&a.screw, &a.nut};
		const double got[2] = {r.spin_speed_screw_rad_s, r.spin_speed_nut_rad_s};
		for (int side = 0; side < 2; side++) {
			fields f = {k->carrier_ratio, k->roller_spin_ratio, prsm_design_orbit_radius_mm(&d),
			            k->nut_speed_mm_per_rad, side == 0 ? 1.0 : 0.0,
			            side == 0 ? 0.0 : k->nut_speed_mm_per_rad};
			double p[3] = {c[side]->x_mm, c[side]->y_mm, 0.731}, W[3], n[3];
			half_curl(W, &f, p);
			assert_close(W[0], 0.0, 1e-9);
			assert_close(W[1], 0.0, 1e-9);
			to_cartesian(n, c[side]->normal, atan2(c[side]->y_mm, c[side]->x_mm));
			double spin = (W[0] * n[0] + W[1] * n[1] + W[2] * n[2]) * d.screw_speed_rad_s;
			assert_close(got[side], spin, 1e-9 * fabs(spin));
		}
	}
	/* case A: (-1.5026 - 1) 0.70251 and -1.5026 n_z,nut per unit screw speed */
	prsm_design d;
	prsm_losses_result r;
	case_a(&d);
	d.screw_speed_rad_s = 1.0;
	losses(&r, &d, &o);
	assert_close(r.spin_speed_screw_rad_s, -2.5026 * 0.70251, 5e-4);
}

/* The spin torque against a Hertz solve at every contact's own load (a ~ Q^(1/3) checked on
 * the way), with equal shares and with given, unequal per-thread loads. */
static void test_spin_torque_per_contact(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	prsm_losses_result r;
	prsm_error err = PRSM_ERROR_INIT;
	standard_design(&d, 4, 1.3, 2.87, 38.0, 4, 7);
	d.axial_load_N = 6311.0;
	d.screw_speed_rad_s = 83.1;
	d.mu_screw_roller = 0.0577;
	d.mu_nut_roller = 0.0691;
	analyse(&a, &d);
	const prsm_losses_options o = only(1, 0, 0.0, 0.0, 0.0);
	double qs[7], qn[7];
	for (int load_case = 0; load_case < 2; load_case++) {
		for (int t = 0; t < 7; t++) {
			double share = d.axial_load_N / (4 * 7);
			double wgt = load_case ? (1.9 - 0.23 * t) / (1.9 - 0.23 * 3) : 1.0; /* mean 1 */
			qs[t] = share * wgt / a.screw.normal[2];
			qn[t] = share * wgt / a.nut.normal[2];
		}
		assert_int_equal(prsm_losses_compute(&r, &d, &a.kinematics, &a.screw, &a.nut,
		                                     load_case ? qs : NULL, load_case ? qn : NULL, &o, &err), 0);
		const prsm_contact *c[2] = {&a.screw, &a.nut};
		const prsm_material *m[2] = {&d.screw_material, &d.nut_material};
		const double mu[2] = {d.mu_screw_roller, d.mu_nut_roller};
		const double *q[2] = {qs, qn};
		const double sp[2] = {r.spin_speed_screw_rad_s, r.spin_speed_nut_rad_s};
		double power = 0.0, moment[2] = {0.0, 0.0};
		for (int side = 0; side < 2; side++)
			for (int t = 0; t < 7; t++) {
				prsm_hertz h;
				assert_int_equal(prsm_hertz_solve(&h, c[side]->curvature_per_mm[0], c[side]->curvature_per_mm[1],
				                                  m[side]->E_MPa, m[side]->poisson, d.roller_material.E_MPa,
				                                  d.roller_material.poisson, q[side][t]), 0);
				double M = prsm_losses_spin_moment_Nmm(mu[side], q[side][t], h.a_mm, h.b_mm) * 1e-3;
				moment[side] += M;
				power += 4 * M * fabs(sp[side]);
			}
		assert_close(r.spin_moment_screw_Nm, moment[0], 1e-9 * moment[0]);
		assert_close(r.spin_moment_nut_Nm, moment[1], 1e-9 * moment[1]);
		assert_close(r.spin_power_W, power, 1e-9 * power);
		assert_close(r.spin_torque_Nm, power / d.screw_speed_rad_s, 1e-9 * r.spin_torque_Nm);
	}
}

/* Spin alone: T_spin ~ F^(4/3), so eta falls slowly with load (d eta/dF = -eta^2 c F^(-2/3)/3,
 * c = T_spin / (F^(4/3) L/2pi)); T_spin ~ Z^(-1/3) at a given load: more rollers, less loss. */
static void test_spin_directions(void **state)
{
	(void)state;
	const prsm_losses_options o = only(1, 0, 0.0, 0.0, 0.0);
	prsm_design d;
	prsm_losses_result r0, r1, rp, rm;
	case_a(&d);
	d.screw_speed_rad_s = 61.3;
	const double F = 8461.0;
	d.axial_load_N = F;
	losses(&r0, &d, &o);
	d.axial_load_N = 2.385 * F;
	losses(&r1, &d, &o);
	assert_close(r1.spin_torque_Nm / r0.spin_torque_Nm, pow(2.385, 4.0 / 3.0), 1e-12);
	assert_true(r1.eta < r0.eta);
	assert_true(r0.eta < r0.eta_slide);
	/* finite difference of eta in F */
	const double h = 1e-4 * F;
	d.axial_load_N = F + h;
	losses(&rp, &d, &o);
	d.axial_load_N = F - h;
	losses(&rm, &d, &o);
	double fd = (rp.eta - rm.eta) / (2 * h);
	double c = r0.spin_torque_Nm / (pow(F, 4.0 / 3.0) * 10.0 / (2 * M_PI) * 1e-3);
	double analytic = -r0.eta * r0.eta * c * pow(F, -2.0 / 3.0) / 3.0;
	assert_true(analytic < 0.0);
	assert_close(fd, analytic, 1e-6 * fabs(analytic));
	/* log-derivative of the spin torque: 4/3 */
	double dlog = (log(rp.spin_torque_Nm) - log(rm.spin_torque_Nm)) / (log(F + h) - log(F - h));
	assert_close(dlog, 4.0 / 3.0, 1e-8);
	/* rollers */
	double prev_eta = 0.0;
	d.axial_load_N = F;
	for (int Z = 3; Z <= 10; Z++) {
		prsm_losses_result rz;
		d.rollers = Z;
		losses(&rz, &d, &o);
		assert_close(rz.spin_torque_Nm / r0.spin_torque_Nm, cbrt(10.0 / Z), 1e-12);
		assert_true(rz.eta > prev_eta);
		prev_eta = rz.eta;
	}
}

/* ---- 3. gear mesh --------------------------------------------------------------------------- */

/* Ohlendorf's H_v against the mesh-cycle average of the sliding power of an internal pair:
 * ring axis at the origin, pinion axis at (r2 - r1, 0), pitch point (r2, 0); contacts along
 * the line of action at base-pitch spacing, one tooth carrying F in the single zone, two
 * carrying F/2 in the double zones; sliding speed |v_pinion - v_ring| from the rigid motions. */
static double hv_by_mesh_average(int z1, int z2, double eps1, double eps2, double alpha)
{
	const double m = 0.731, r1 = 0.5 * m * z1, r2 = 0.5 * m * z2, w1 = 1.0, w2 = w1 * r1 / r2;
	const double pb = M_PI * m * cos(alpha);
	const double P[2] = {r2, 0.0}, O1[2] = {r2 - r1, 0.0};
	const double t[2] = {sin(alpha), cos(alpha)}; /* line of action through P */
	const int N = 200000;
	double sum = 0.0;
	for (int i = 0; i < N; i++) {
		double x0 = (i + 0.5) / N; /* phase of the mesh cycle, base pitches */
		double xs[4];
		int nc = 0;
		for (int j = -3; j <= 3; j++) {
			double x = x0 + j;
			if (x >= -eps2 && x <= eps1)
				xs[nc++] = x;
		}
		for (int c = 0; c < nc; c++) {
			double q[2] = {P[0] + xs[c] * pb * t[0], P[1] + xs[c] * pb * t[1]};
			double v1[2] = {-w1 * (q[1] - O1[1]), w1 * (q[0] - O1[0])};
			double v2[2] = {-w2 * q[1], w2 * q[0]};
			sum += hypot(v1[0] - v2[0], v1[1] - v2[1]) / nc;
		}
	}
	/* loss / (mu F_t v_pitch); F along the line of action: F_n v_slide / (F_t w1 r1) */
	return sum / N / cos(alpha) / (w1 * r1);
}

static void test_gear_loss_factor(void **state)
{
	(void)state;
	const int z[][2] = {{17, 85}, {23, 71}, {19, 133}};
	const double eps[][2] = {{0.75, 0.75}, {0.613, 0.871}, {0.9, 0.5}};
	for (int i = 0; i < 3; i++) {
		double ea = eps[i][0] + eps[i][1];
		double hv = prsm_losses_gear_loss_factor(z[i][0], z[i][1], ea, eps[i][0], eps[i][1]);
		double num = hv_by_mesh_average(z[i][0], z[i][1], eps[i][0], eps[i][1], 20.0 * DEG);
		assert_close(hv, num, 1e-6 * hv);
	}
	/* case A default: z_1 = 17, z_2 = 85, eps 1.5: pi 4/85 0.625 */
	assert_close(prsm_losses_gear_loss_factor(17, 85, 1.5, 0.75, 0.75), M_PI * 4.0 / 85.0 * 0.625, 1e-15);
}

/* The roller moment from an explicit force balance: the screw pushes the roller along the
 * screw contact normal, the nut along the normal of its other flank (the pair turned 180 deg
 * about the x axis: (n_r, -n_t, -n_z)), the nut load set by the roller's axial balance with
 * the friction forces; friction -mu N s/|s|; moments about the roller axis. */
static void test_gear_moment_balance(void **state)
{
	(void)state;
	const double designs[][4] = {{5, 2.0, 3.25, 45.0}, {4, 1.3, 2.87, 38.0}};
	for (int i = 0; i < 2; i++) {
		prsm_design d;
		prsm_analysis a;
		prsm_losses_result r;
		prsm_error err = PRSM_ERROR_INIT;
		standard_design(&d, (int)designs[i][0], designs[i][1], designs[i][2], designs[i][3], 3, 4);
		d.mu_screw_roller = 0.0713;
		d.mu_nut_roller = 0.0588;
		d.axial_load_N = 4129.0;
		d.screw_speed_rad_s = 57.7;
		analyse(&a, &d);
		const double A[2] = {prsm_design_orbit_radius_mm(&d), 0.0};
		const prsm_contact *cs = &a.screw, *cn = &a.nut;
		double ths = atan2(cs->y_mm, cs->x_mm), thn = atan2(cn->y_mm, cn->x_mm);
		double ns[3], nn[3], ss[3], sn[3];
		double nn_body[3] = {cn->normal[0], -cn->normal[1], -cn->normal[2]};
		to_cartesian(ns, cs->normal, ths);
		to_cartesian(nn, nn_body, thn);
		to_cartesian(ss, a.kinematics.slip_screw, ths);
		to_cartesian(sn, a.kinematics.slip_nut, thn);
		double ls = sqrt(ss[0] * ss[0] + ss[1] * ss[1] + ss[2] * ss[2]);
		double ln = sqrt(sn[0] * sn[0] + sn[1] * sn[1] + sn[2] * sn[2]);
		assert_true(ln < 1e-9 * fabs(a.kinematics.nut_speed_mm_per_rad)); /* the nut rolls */
		const double Ns = 311.7;
		double fs[3], Fs[3], Fn[3];
		for (int j = 0; j < 3; j++)
			fs[j] = -d.mu_screw_roller * Ns * ss[j] / ls;
		double Nn = (Ns * ns[2] + fs[2]) / -nn[2]; /* axial balance: Ns ns_z + fs_z + Nn nn_z = 0 */
		for (int j = 0; j < 3; j++) {
			Fs[j] = Ns * ns[j] + fs[j];
			Fn[j] = Nn * nn[j];
		}
		assert_close(Fs[2] + Fn[2], 0.0, 1e-9 * Ns);
		double tau = (cs->x_mm - A[0]) * Fs[1] - (cs->y_mm - A[1]) * Fs[0] +
		             (cn->x_mm - A[0]) * Fn[1] - (cn->y_mm - A[1]) * Fn[0]; /* N mm, one thread */
		double qs[4] = {Ns, Ns, Ns, Ns}, qn[4] = {Nn, Nn, Nn, Nn};
		prsm_losses_options o = only(0, 1, 0.0, 0.0, 0.0);
		assert_int_equal(prsm_losses_compute(&r, &d, &a.kinematics, cs, cn, qs, qn, &o, &err), 0);
		assert_close(r.roller_moment_Nm * 1e3, 4 * tau, 1e-9 * fabs(tau));
		assert_close(r.roller_moment_spin_Nm, 0.0, 0.0);
		/* F_t and the mesh power from their definitions */
		double Ft = 4 * fabs(tau) / d.roller_radius_mm;
		assert_close(r.gear_tangential_force_N, Ft, 1e-9 * Ft);
		double vp = fabs(a.kinematics.roller_spin_ratio) * d.roller_radius_mm * d.screw_speed_rad_s * 1e-3;
		assert_close(r.gear_pitch_speed_m_s, vp, 1e-12 * vp);
		double P = 3 * 0.05 * Ft * vp * r.gear_Hv;
		assert_close(r.gear_power_W, P, 1e-12 * P);
		assert_close(r.gear_torque_Nm, P / d.screw_speed_rad_s, 1e-12 * r.gear_torque_Nm);
		assert_close(r.gear_normal_force_N, Ft / cos(20.0 * DEG), 1e-9 * Ft);

		/* with spin: the couples -M sign(Omega_rel . n) n on the roller, their z parts added */
		o.spin = 1;
		assert_int_equal(prsm_losses_compute(&r, &d, &a.kinematics, cs, cn, qs, qn, &o, &err), 0);
		double Om = a.kinematics.roller_abs_ratio;
		double ws = (Om - 1.0) * ns[2], wn = Om * nn[2]; /* relative angular velocity . normal */
		double Ms = r.spin_moment_screw_Nm, Mn = r.spin_moment_nut_Nm;
		double spin_z = -Ms * (ws > 0 ? 1 : -1) * ns[2] - Mn * (wn > 0 ? 1 : -1) * nn[2];
		assert_close(r.roller_moment_spin_Nm, spin_z, 1e-12 * fabs(spin_z));
		assert_close(r.roller_moment_Nm, 4 * tau * 1e-3 + spin_z, 1e-9 * fabs(r.roller_moment_Nm));
	}
}

/* Teeth rules, the ratio flag, the off switch. */
static void test_gear_teeth(void **state)
{
	(void)state;
	prsm_design d;
	prsm_losses_result r;
	case_a(&d);
	d.axial_load_N = 5311.0;
	d.screw_speed_rad_s = 23.9;
	prsm_losses_options o = only(1, 1, 0.0, 0.0, 0.0);
	losses(&r, &d, &o);
	assert_int_equal(r.gear_teeth_roller, 17);
	assert_int_equal(r.gear_teeth_ring, 85);
	assert_int_equal(r.flags & PRSM_LOSSES_GEAR_RATIO, 0);
	assert_close(r.gear_Hv, M_PI * 4.0 / 85.0 * 0.625, 1e-15);
	assert_true(r.gear_torque_Nm > 0.0);
	/* z_2 given: z_1 = round(z_2 r_r / r_n) */
	o.gear_teeth_ring = 101;
	losses(&r, &d, &o);
	assert_int_equal(r.gear_teeth_roller, 20);
	assert_true(r.flags & PRSM_LOSSES_GEAR_RATIO);
	/* a non-integer ratio r_n / r_r = 4.5: the smallest z_1 >= 17 with z_1 4.5 integer is 18 */
	prsm_design e;
	prsm_problems pr;
	prsm_problems_init(&pr);
	prsm_design_init(&e);
	e.starts = 5;
	e.pitch_mm = 2.0;
	e.roller_radius_mm = 3.25;
	e.nut_radius_mm = 4.5 * 3.25;
	e.screw_radius_mm = 4.5 * 3.25 - 2 * 3.25;
	e.flank_angle_rad = 45.0 * DEG;
	e.rollers = 3;
	e.engaged_threads = 5;
	assert_int_equal(prsm_design_resolve(&e, &pr), 0);
	e.axial_load_N = 1000.0;
	o = only(1, 1, 0.0, 0.0, 0.0);
	losses(&r, &e, &o);
	assert_int_equal(r.gear_teeth_roller, 18);
	assert_int_equal(r.gear_teeth_ring, 81);
	/* explicit eps_1, eps_2 */
	o.gear_eps_roller = 0.613;
	o.gear_eps_ring = 0.871;
	losses(&r, &d, &o);
	assert_close(r.gear_eps_alpha, 1.484, 1e-15);
	assert_close(r.gear_Hv, prsm_losses_gear_loss_factor(17, 85, 1.484, 0.613, 0.871), 1e-15);
	/* off */
	o = only(1, 0, 0.0, 0.0, 0.0);
	losses(&r, &d, &o);
	assert_close(r.gear_torque_Nm, 0.0, 0.0);
	assert_close(r.gear_power_W, 0.0, 0.0);
}

/* ---- 4. drag, directions --------------------------------------------------------------------- */

/* A constant drag torque: eta = 1/(1/eta_s + T_d / (F L / 2pi)) rises with lead (starts, pitch)
 * and with load, d eta/dF = eta^2 T_d / (F^2 L/2pi). Viscous drag c omega: eta falls with
 * speed, d eta/d omega = -eta^2 c / (F L / 2pi). */
static void test_drag_directions(void **state)
{
	(void)state;
	const double Td = 0.0371, c = 0.00173;
	const prsm_losses_options o = only(0, 0, Td, 0.0, 0.0);
	double prev = 0.0;
	for (int n = 4; n <= 7; n++) { /* more starts, same roller and pitch */
		prsm_design d;
		prsm_losses_result r;
		standard_design(&d, n, 2.0, 3.25, 45.0, 4, 10);
		d.axial_load_N = 1734.0;
		d.screw_speed_rad_s = 31.4;
		losses(&r, &d, &o);
		assert_true(r.eta > prev);
		prev = r.eta;
	}
	prev = 0.0;
	for (int i = 0; i < 4; i++) { /* larger pitch */
		prsm_design d;
		prsm_losses_result r;
		standard_design(&d, 5, 1.25 + 0.5 * i, 3.25, 45.0, 4, 10);
		d.axial_load_N = 1734.0;
		d.screw_speed_rad_s = 31.4;
		losses(&r, &d, &o);
		assert_true(r.eta > prev);
		prev = r.eta;
	}
	prsm_design d;
	prsm_losses_result r, rp, rm;
	case_a(&d);
	const double F = 1734.0, w = 31.4, k = 10.0 / (2 * M_PI) * 1e-3;
	d.screw_speed_rad_s = w;
	d.axial_load_N = F;
	losses(&r, &d, &o);
	assert_close(r.eta, 1.0 / (1.0 / r.eta_slide + Td / (k * F)), 1e-14);
	d.axial_load_N = F * 1.0001;
	losses(&rp, &d, &o);
	d.axial_load_N = F * 0.9999;
	losses(&rm, &d, &o);
	double fd = (rp.eta - rm.eta) / (2e-4 * F);
	double an = r.eta * r.eta * Td / (k * F * F);
	assert_true(an > 0.0);
	assert_close(fd, an, 1e-6 * an);
	/* viscous drag in speed */
	const prsm_losses_options ov = only(0, 0, 0.0, c, 0.0);
	d.axial_load_N = F;
	losses(&r, &d, &ov);
	d.screw_speed_rad_s = w * 1.0001;
	losses(&rp, &d, &ov);
	d.screw_speed_rad_s = w * 0.9999;
	losses(&rm, &d, &ov);
	fd = (rp.eta - rm.eta) / (2e-4 * w);
	an = -r.eta * r.eta * c / (k * F);
	assert_true(rp.eta < r.eta && r.eta < rm.eta);
	assert_close(fd, an, 1e-6 * fabs(an));
	assert_close(r.drag_torque_Nm, c * w, 1e-15);
}

/* ---- 5. balance and special points ----------------------------------------------------------- */

static void test_energy_balance(void **state)
{
	(void)state;
	const double pts[][3] = {{10000.0, 100.0, 0.0}, {2385.0, 1733.0, 1.0}, {731.9, 12.7, 2.0}};
	for (int i = 0; i < 3; i++) {
		prsm_design d;
		prsm_losses_result r;
		if (pts[i][2] == 0.0)
			case_a(&d);
		else if (pts[i][2] == 1.0)
			standard_design(&d, 4, 1.3, 2.87, 38.0, 5, 9);
		else
			standard_design(&d, 7, 2.5, 3.1, 55.0, 3, 6);
		d.axial_load_N = pts[i][0];
		d.screw_speed_rad_s = pts[i][1] * RPM;
		const prsm_losses_options o = only(1, 1, 0.0213, 0.000417, 0.0388);
		losses(&r, &d, &o);
		double sum = r.output_power_W + r.sliding_power_W + r.spin_power_W + r.gear_power_W +
		             r.drag_power_W + r.seal_power_W;
		assert_close(r.input_power_W, sum, 1e-12 * r.input_power_W);
		assert_close(r.loss_power_W, sum - r.output_power_W, 1e-12 * r.input_power_W);
		assert_close(r.eta, r.output_power_W / r.input_power_W, 1e-14);
		double out = r.ideal_torque_Nm * r.eta_back_slide - r.spin_torque_Nm - r.gear_torque_Nm -
		             r.drag_torque_Nm - r.seal_torque_Nm;
		assert_close(r.back_output_torque_Nm, out, 1e-15);
		assert_true(r.eta < r.eta_slide && r.eta_back < r.eta_back_slide);
	}
}

static void test_special_points(void **state)
{
	(void)state;
	prsm_design d;
	prsm_losses_result r, small;
	case_a(&d);
	d.screw_speed_rad_s = 44.4;
	/* no load with drag: eta = eta' = 0, the drag power is all the input */
	d.axial_load_N = 0.0;
	prsm_losses_options o = only(1, 1, 0.0123, 0.0, 0.0);
	losses(&r, &d, &o);
	assert_true(r.flags & PRSM_LOSSES_NO_LOAD);
	assert_int_equal(r.flags & (PRSM_LOSSES_LIMIT | PRSM_LOSSES_SELF_LOCKING), 0);
	assert_close(r.eta, 0.0, 0.0);
	assert_close(r.eta_back, 0.0, 0.0);
	assert_close(r.input_power_W, 0.0123 * 44.4, 1e-15);
	/* no load, no torque: the F -> 0+ limit */
	o = only(1, 1, 0.0, 0.0, 0.0);
	losses(&r, &d, &o);
	assert_true(r.flags & PRSM_LOSSES_LIMIT);
	assert_close(r.input_torque_Nm, 0.0, 0.0);
	d.axial_load_N = 1e-9;
	losses(&small, &d, &o);
	assert_close(r.eta, small.eta, 1e-5);
	assert_close(r.eta_back, small.eta_back, 1e-5);
	assert_true(r.eta < r.eta_slide); /* the gear's friction part stays */
	o = only(1, 0, 0.0, 0.0, 0.0);
	d.axial_load_N = 0.0;
	losses(&r, &d, &o);
	assert_true(r.eta == r.eta_slide && r.eta_back == r.eta_back_slide);
	/* at rest: torques are the limits, powers 0 */
	d.axial_load_N = 4711.0;
	o = only(1, 1, 0.0213, 0.5, 0.0388);
	d.screw_speed_rad_s = 0.0;
	losses(&r, &d, &o);
	d.screw_speed_rad_s = 1e-9;
	losses(&small, &d, &o);
	assert_true(r.flags & PRSM_LOSSES_AT_REST);
	assert_close(r.input_torque_Nm, small.input_torque_Nm, 1e-9);
	assert_close(r.input_power_W + r.spin_power_W + r.gear_power_W + r.spin_speed_screw_rad_s, 0.0, 0.0);
	assert_close(r.drag_torque_Nm, 0.0213, 1e-15);
	/* self-locking: a seal torque larger than the back-driving torque */
	d.screw_speed_rad_s = 10.0;
	o = only(0, 0, 0.0, 0.0, 100.0);
	losses(&r, &d, &o);
	assert_true(r.flags & PRSM_LOSSES_SELF_LOCKING);
	assert_close(r.eta_back, 0.0, 0.0);
	assert_true(r.back_output_torque_Nm < 0.0);
	assert_true(r.eta > 0.0);
	/* the sign of F and omega does not matter */
	prsm_losses_result neg;
	o = only(1, 1, 0.0213, 0.0011, 0.0);
	losses(&r, &d, &o);
	prsm_analysis a;
	prsm_error err = PRSM_ERROR_INIT;
	analyse(&a, &d); /* the analysis wants F >= 0 for its Hertz contacts */
	d.axial_load_N = -4711.0;
	d.screw_speed_rad_s = -10.0;
	assert_int_equal(prsm_losses_compute(&neg, &d, &a.kinematics, &a.screw, &a.nut, NULL, NULL, &o, &err), 0);
	assert_close(neg.eta, r.eta, 1e-15);
	assert_close(neg.input_torque_Nm, r.input_torque_Nm, 1e-15);
}

/* ---- 6. errors ------------------------------------------------------------------------------ */

static void expect_einval(prsm_design *d, const prsm_losses_options *o, const double *qs, const double *qn)
{
	prsm_analysis a;
	prsm_design good = *d;
	good.mu_screw_roller = 0.05;
	good.mu_nut_roller = 0.05;
	good.rollers = 10;
	good.axial_load_N = 1000.0;
	good.screw_speed_rad_s = 10.0;
	analyse(&a, &good);
	prsm_losses_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_losses_compute(&r, d, &a.kinematics, &a.screw, &a.nut, qs, qn, o, &err),
	                 PRSM_EINVAL);
	assert_int_equal(err.code, PRSM_EINVAL);
	assert_true(strlen(err.message) > 10);
}

static void test_errors(void **state)
{
	(void)state;
	prsm_design d;
	case_a(&d);
	d.axial_load_N = 1000.0;
	d.screw_speed_rad_s = 10.0;
	prsm_losses_options o;
	/* options */
	double bad[] = {-0.1, NAN, INFINITY};
	for (int i = 0; i < 3; i++) {
		o = only(1, 1, bad[i], 0.0, 0.0);
		expect_einval(&d, &o, NULL, NULL);
		o = only(1, 1, 0.0, bad[i], 0.0);
		expect_einval(&d, &o, NULL, NULL);
		o = only(1, 1, 0.0, 0.0, bad[i]);
		expect_einval(&d, &o, NULL, NULL);
		o = only(1, 1, 0.0, 0.0, 0.0);
		o.gear_mu = bad[i];
		expect_einval(&d, &o, NULL, NULL);
		o = only(1, 1, 0.0, 0.0, 0.0);
		o.gear_contact_ratio = bad[i];
		expect_einval(&d, &o, NULL, NULL);
	}
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_teeth_roller = -17;
	expect_einval(&d, &o, NULL, NULL);
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_teeth_ring = -3;
	expect_einval(&d, &o, NULL, NULL);
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_teeth_roller = 40;
	o.gear_teeth_ring = 40; /* u = 1: no internal mesh */
	expect_einval(&d, &o, NULL, NULL);
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_contact_ratio = 0.93;
	expect_einval(&d, &o, NULL, NULL);
	o.gear_contact_ratio = 2.17;
	expect_einval(&d, &o, NULL, NULL);
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_eps_roller = 0.7; /* only one of the two */
	expect_einval(&d, &o, NULL, NULL);
	o.gear_eps_ring = 1.2;
	expect_einval(&d, &o, NULL, NULL);
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_pressure_angle_rad = 0.0;
	expect_einval(&d, &o, NULL, NULL);
	o = only(1, 1, 0.0, 0.0, 0.0);
	o.gear_pitch_radius_mm = -3.25;
	expect_einval(&d, &o, NULL, NULL);
	/* design and operating point */
	o = only(1, 1, 0.0, 0.0, 0.0);
	prsm_design e = d;
	e.mu_screw_roller = -0.01;
	expect_einval(&e, &o, NULL, NULL);
	e = d;
	e.mu_nut_roller = NAN;
	expect_einval(&e, &o, NULL, NULL);
	e = d;
	e.axial_load_N = NAN;
	expect_einval(&e, &o, NULL, NULL);
	e = d;
	e.screw_speed_rad_s = INFINITY;
	expect_einval(&e, &o, NULL, NULL);
	e = d;
	e.rollers = 0;
	expect_einval(&e, &o, NULL, NULL);
	e = d;
	e.mu_screw_roller = 1.2; /* beta + rho > 90 deg: the flanks wedge, the drive locks */
	{
		prsm_analysis a;
		prsm_design good = e;
		good.mu_screw_roller = 0.05;
		analyse(&a, &good);
		prsm_losses_result r;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_losses_compute(&r, &e, &a.kinematics, &a.screw, &a.nut, NULL, NULL, &o, &err), 0);
		assert_true(r.flags & PRSM_LOSSES_DRIVE_LOCKED);
		assert_true(r.eta == 0.0 && isnan(r.input_torque_Nm));
		assert_true(r.gear_teeth_roller > 0 && r.gear_teeth_ring > r.gear_teeth_roller);
	}
	/* loads */
	double q[10], qn[10];
	for (int i = 0; i < 10; i++)
		q[i] = qn[i] = 14.2;
	q[7] = -1.0;
	expect_einval(&d, &o, q, NULL);
	q[7] = 14.2;
	qn[3] = NAN;
	expect_einval(&d, &o, NULL, qn);
	/* NULL options are the defaults */
	prsm_analysis a;
	prsm_losses_result r1, r2;
	prsm_error err = PRSM_ERROR_INIT;
	analyse(&a, &d);
	const prsm_losses_options def = PRSM_LOSSES_OPTIONS_INIT;
	assert_int_equal(prsm_losses_compute(&r1, &d, &a.kinematics, &a.screw, &a.nut, NULL, NULL, NULL, &err), 0);
	assert_int_equal(prsm_losses_compute(&r2, &d, &a.kinematics, &a.screw, &a.nut, NULL, NULL, &def, &err), 0);
	assert_true(r1.eta == r2.eta);
	/* the design's losses section maps onto the options */
	prsm_losses_options from;
	d.losses.drag_torque_Nm = 0.0419;
	d.losses.roller_gear_teeth = 19;
	prsm_losses_options_from_design(&from, &d);
	assert_close(from.drag_torque_Nm, 0.0419, 0.0);
	assert_int_equal(from.gear_teeth_roller, 19);
	assert_int_equal(from.spin, 1);
	assert_true(isnan(from.gear_eps_roller));
}

/* ---- 6b. the friction-independent part, prepared once -------------------------------------- */

/* prsm_losses_result up to and including flags: no padding before it (doubles, then two ints,
 * then doubles), so the bytes compare the values bit for bit (NaN included). */
#define RESULT_BYTES (offsetof(prsm_losses_result, flags) + sizeof(int))

/* prsm_losses_compute and one prsm_losses_prepare + prsm_losses_compute_prepared per friction
 * pair give the same bits, the same code and the same message, for every option set, equal
 * shares and a load distribution, rolling, self-locking and wedged (drive-locked) friction. */
static void test_prepared_bit_identical(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	case_a(&d);
	d.axial_load_N = 7000.0;
	d.screw_speed_rad_s = 955.0 * RPM;
	analyse(&a, &d);
	prsm_losses_options opts[6] = {only(1, 1, 0.0, 0.0, 0.0), only(0, 0, 0.0, 0.0, 0.0),
	                               only(1, 0, 0.2, 0.001, 0.05), only(0, 1, 0.0, 0.0, 0.05),
	                               only(1, 1, 0.1, 0.0, 0.0), only(1, 1, 0.0, 0.0, 0.0)};
	opts[4].gear_teeth_roller = 19; /* z_2 / z_1 != r_n / r_r: PRSM_LOSSES_GEAR_RATIO */
	opts[5].gear_teeth_roller = 40;
	opts[5].gear_teeth_ring = 40;   /* no internal mesh: an error of the prepared part */
	double qs[10], qn[10];
	for (int i = 0; i < 10; i++) {
		qs[i] = 120.0 - 7.5 * i;
		qn[i] = 118.0 - 7.0 * i;
	}
	const double mus[][2] = {{0.05, 0.05}, {0.0, 0.0}, {0.031, 0.077}, {0.3, 0.01},
	                         {0.9, 0.2}, {1.2, 0.05}, {0.05, 1.5}};
	int compared = 0;
	for (int io = 0; io < 6; io++) {
		prsm_losses_nominal nm;
		prsm_losses_prepare(&nm, &d, &a.screw, &a.nut, &opts[io]);
		for (int il = 0; il < 2; il++) {
			for (size_t im = 0; im < sizeof mus / sizeof mus[0]; im++) {
				prsm_design e = d;
				e.mu_screw_roller = mus[im][0];
				e.mu_nut_roller = mus[im][1];
				prsm_losses_result r1, r2;
				prsm_error err1 = PRSM_ERROR_INIT, err2 = PRSM_ERROR_INIT;
				const double *ls = il ? qs : NULL, *ln = il ? qn : NULL;
				int rc1 = prsm_losses_compute(&r1, &e, &a.kinematics, &a.screw, &a.nut, ls, ln,
				                              &opts[io], &err1);
				int rc2 = prsm_losses_compute_prepared(&r2, &nm, &e, &a.kinematics, &a.screw, &a.nut,
				                                       ls, ln, &opts[io], &err2);
				assert_int_equal(rc1, rc2);
				assert_int_equal(io == 5 ? PRSM_EINVAL : 0, rc1);
				assert_string_equal(err1.message, err2.message);
				assert_string_equal(err1.pointer, err2.pointer);
				assert_memory_equal(&r1, &r2, RESULT_BYTES);
				compared++;
			}
		}
	}
	assert_int_equal(compared, 6 * 2 * 7);
	/* a contact that is not Hertzian: the same EGEOMETRY from both, when spin is on */
	prsm_contact bent = a.screw;
	bent.curvature_per_mm[0] = -fabs(bent.curvature_per_mm[1]) - 0.1;
	prsm_losses_nominal nm;
	prsm_losses_prepare(&nm, &d, &bent, &a.nut, &opts[0]);
	assert_int_not_equal(nm.hertz_rc, 0);
	prsm_losses_result r1, r2;
	prsm_error err1 = PRSM_ERROR_INIT, err2 = PRSM_ERROR_INIT;
	assert_int_equal(prsm_losses_compute(&r1, &d, &a.kinematics, &bent, &a.nut, NULL, NULL, &opts[0], &err1),
	                 PRSM_EGEOMETRY);
	assert_int_equal(prsm_losses_compute_prepared(&r2, &nm, &d, &a.kinematics, &bent, &a.nut, NULL, NULL,
	                                              &opts[0], &err2), PRSM_EGEOMETRY);
	assert_string_equal(err1.message, err2.message);
	/* prepared with spin off, asked with spin on */
	prsm_losses_prepare(&nm, &d, &a.screw, &a.nut, &opts[1]);
	assert_int_equal(prsm_losses_compute_prepared(&r2, &nm, &d, &a.kinematics, &a.screw, &a.nut, NULL,
	                                              NULL, &opts[0], &err2), PRSM_EINVAL);
	/* NULL options prepare the defaults */
	const prsm_losses_options def = PRSM_LOSSES_OPTIONS_INIT;
	prsm_losses_nominal n1, n2;
	prsm_losses_prepare(&n1, &d, &a.screw, &a.nut, NULL);
	prsm_losses_prepare(&n2, &d, &a.screw, &a.nut, &def);
	assert_true(n1.a1_mm[0] == n2.a1_mm[0] && n1.gear_Hv == n2.gear_Hv && n1.a1_mm[0] > 0.0);
}

/* ---- 7. case A figures ------------------------------------------------------------------------ */

/* Case A at 10 kN and 100 rpm, each loss alone and all together (printed for the record). */
static void test_case_a_figures(void **state)
{
	(void)state;
	prsm_design d;
	prsm_losses_result r[5];
	case_a(&d);
	d.axial_load_N = 10000.0;
	d.screw_speed_rad_s = 100.0 * RPM;
	const prsm_losses_options o[5] = {only(0, 0, 0, 0, 0), only(1, 0, 0, 0, 0), only(0, 1, 0, 0, 0),
	                                  only(1, 1, 0, 0, 0), only(1, 1, 0.05, 0.0, 0.0)};
	const char *name[5] = {"sliding", "+spin", "+gear", "+spin+gear", "+spin+gear+drag 0.05"};
	for (int i = 0; i < 5; i++) {
		losses(&r[i], &d, &o[i]);
		print_message("case A 10 kN 100 rpm %-22s eta %.5f eta' %.5f T %.5f N m (spin %.5f, gear %.6f)\n",
		              name[i], r[i].eta, r[i].eta_back, r[i].input_torque_Nm, r[i].spin_torque_Nm,
		              r[i].gear_torque_Nm);
	}
	print_message("  spin speeds %.4f / %.4f rad/s, spin moments per roller %.5f / %.5f N m, E %.5f / %.5f\n",
	              r[3].spin_speed_screw_rad_s, r[3].spin_speed_nut_rad_s, r[3].spin_moment_screw_Nm,
	              r[3].spin_moment_nut_Nm, r[3].spin_ellint_E_screw, r[3].spin_ellint_E_nut);
	print_message("  roller moment %.5f N m (friction %.5f, helix %.5f, spin %.5f), F_t %.3f N, "
	              "H_v %.5f, z %d/%d, v_pitch %.5f m/s\n",
	              r[3].roller_moment_Nm, r[3].roller_moment_friction_Nm, r[3].roller_moment_helix_Nm,
	              r[3].roller_moment_spin_Nm, r[3].gear_tangential_force_N, r[3].gear_Hv,
	              r[3].gear_teeth_roller, r[3].gear_teeth_ring, r[3].gear_pitch_speed_m_s);
	print_message("  powers: in %.3f W, out %.3f, sliding %.3f, spin %.3f, gear %.4f, drag %.3f\n",
	              r[4].input_power_W, r[4].output_power_W, r[4].sliding_power_W, r[4].spin_power_W,
	              r[4].gear_power_W, r[4].drag_power_W);
	assert_true(r[0].eta > r[1].eta && r[1].eta > r[3].eta && r[3].eta > r[4].eta);
	assert_true(r[0].eta > r[2].eta && r[2].eta > r[3].eta);
	assert_close(r[0].eta, 0.9048, 1e-3);
	assert_close(r[3].gear_Hv, M_PI * 4.0 / 85.0 * 0.625, 1e-15);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_sliding_only),
		cmocka_unit_test(test_spin_moment_integral),
		cmocka_unit_test(test_spin_speed_independent),
		cmocka_unit_test(test_spin_torque_per_contact),
		cmocka_unit_test(test_spin_directions),
		cmocka_unit_test(test_gear_loss_factor),
		cmocka_unit_test(test_gear_moment_balance),
		cmocka_unit_test(test_gear_teeth),
		cmocka_unit_test(test_drag_directions),
		cmocka_unit_test(test_energy_balance),
		cmocka_unit_test(test_special_points),
		cmocka_unit_test(test_errors),
		cmocka_unit_test(test_prepared_bit_identical),
		cmocka_unit_test(test_case_a_figures),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
