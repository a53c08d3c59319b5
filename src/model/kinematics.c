/*
 * kinematics.c: ideal and contact-radius kinematics, sliding velocities (docs/model/kinematics-efficiency-stiffness-life.md).
 */
#include "model/kinematics.h"

#include <math.h>

#include "model/geometry.h"

/* Roller velocity minus body velocity at contact c (pair frame: screw axis at the origin,
 * roller axis at (a, 0)), per unit screw speed, expressed in the body's cylindrical frame.
 * body_spin: 1 for the screw, 0 for the nut; the nut translates axially at v. */
static void relative_velocity(double out[3], const prsm_contact *c, double a, double kc,
                              double spin, double v, double body_spin, double body_v)
{
	const double x = c->x_mm, y = c->y_mm;
	/* roller: carrier rotation about z, spin about its axis, axial translation */
	double vr[3] = {-kc * y - spin * y, kc * x + spin * (x - a), v};
	double vb[3] = {-body_spin * y, body_spin * x, body_v};
	double d[3] = {vr[0] - vb[0], vr[1] - vb[1], vr[2] - vb[2]};
	double rho = hypot(x, y), er[2] = {x / rho, y / rho};
	out[0] = d[0] * er[0] + d[1] * er[1];
	out[1] = -d[0] * er[1] + d[1] * er[0];
	out[2] = d[2];
}

static double norm3(const double v[3])
{
	return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

int prsm_kinematics_compute(prsm_kinematics *out, const prsm_design *d, const prsm_contact *screw,
                            const prsm_contact *nut)
{
	const double rs = d->screw_radius_mm, rr = d->roller_radius_mm, rn = d->nut_radius_mm;
	const double a = prsm_design_orbit_radius_mm(d);
	/* docs/model/kinematics-efficiency-stiffness-life.md: rolling at the pitch circles */
	out->carrier_ratio_ideal = rs / (2.0 * (rs + rr));
	out->roller_spin_ratio_ideal = -(rn / rr) * out->carrier_ratio_ideal;
	out->roller_abs_ratio_ideal = out->carrier_ratio_ideal + out->roller_spin_ratio_ideal;
	/* rolling at the contact radii: Omega = -k_c rho_n/u_n; rho_s = k_c rho_s - Omega u_s */
	const double rho_s = screw->body_rho_mm, u_s = screw->roller_u_mm;
	const double rho_n = nut->body_rho_mm, u_n = nut->roller_u_mm;
	out->carrier_ratio = rho_s / (rho_s + u_s * rho_n / u_n);
	out->roller_spin_ratio = -out->carrier_ratio * rho_n / u_n;
	out->roller_abs_ratio = out->carrier_ratio + out->roller_spin_ratio;
	/* the nut advances one lead per screw turn, against the helix (docs/model/geometry-and-meshing.md) */
	const double v = -prsm_design_screw_p(d);
	out->nut_speed_mm_per_rad = v;
	relative_velocity(out->slip_screw, screw, a, out->carrier_ratio, out->roller_spin_ratio, v, 1.0, 0.0);
	relative_velocity(out->slip_nut, nut, a, out->carrier_ratio, out->roller_spin_ratio, v, 0.0, v);
	out->slip_ratio_screw = norm3(out->slip_screw) / fabs(v);
	out->slip_ratio_nut = norm3(out->slip_nut) / fabs(v);
	/* docs/model §8.1: the carrier ratio friction settles at (open question O1) */
	double A[3], B[3];
	prsm_kinematics_slip_basis(A, B, d, screw->x_mm, screw->y_mm, rn / rr);
	out->carrier_ratio_min_slip = prsm_kinematics_min_slip_ratio(A, B);
	return 0;
}

void prsm_kinematics_slip_basis(double A_mm[3], double B_mm[3], const prsm_design *d, double x_mm,
                                double y_mm, double ring_gear_ratio)
{
	/* docs/model §8.1: A = z x c + (1 - i_g) z x (p - c), B = -z x p - hand (L / 2 pi) z, with
	 * z x (x, y, 0) = (-y, x, 0) */
	const double a = prsm_design_orbit_radius_mm(d), spin = 1.0 - ring_gear_ratio;
	A_mm[0] = -spin * y_mm;
	A_mm[1] = a + spin * (x_mm - a);
	A_mm[2] = 0.0;
	B_mm[0] = y_mm;
	B_mm[1] = -x_mm;
	B_mm[2] = -prsm_design_screw_p(d); /* hand n P / 2 pi = hand L / 2 pi */
}

double prsm_kinematics_min_slip_ratio(const double A_mm[3], const double B_mm[3])
{
	const double AB = A_mm[0] * B_mm[0] + A_mm[1] * B_mm[1] + A_mm[2] * B_mm[2];
	const double AA = A_mm[0] * A_mm[0] + A_mm[1] * A_mm[1] + A_mm[2] * A_mm[2];
	return -AB / AA;
}
