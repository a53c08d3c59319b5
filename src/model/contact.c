/*
 * contact.c: helicoid flank gap, its analytic derivatives and the Newton contact solve
 * (docs/model/geometry-and-meshing.md).
 *
 *   body flank:   Z_b = P/4 + sigma (rho - r_b) tan beta + p_b theta - t_b
 *                 sigma = -1 for the screw (flank falls outwards), +1 for the nut
 *   roller flank: Z_r = z_c - sqrt(R^2 - u^2) + p_r phi + t_r,  z_c = P/4 + sqrt(R^2 - r_r^2)
 *   gap:          G = Z_r - Z_b
 *
 * theta is measured about the body axis from the frame's x axis, phi about the roller axis
 * from the ray pointing at the mating part (-x for the screw side, +x for the nut side), both
 * counter-clockwise. The derivatives need no atan2: grad theta = (-Y, X)/rho^2.
 */
#include "model/contact.h"

#include <math.h>

#include "model/geometry.h"

#define NEWTON_MAX_ITER 30
#define NEWTON_TOL_MM 1e-12
#define NEWTON_QUADRATIC_MM 1e-6 /* steps below this are in Newton's quadratic regime */

static double body_sigma(const prsm_flank_pair *p)
{
	return p->side == PRSM_SIDE_SCREW ? -1.0 : 1.0;
}

void prsm_flank_pair_nominal(prsm_flank_pair *out, const prsm_design *d, int side)
{
	const double a = prsm_design_orbit_radius_mm(d);
	out->side = side;
	out->quarter_pitch_mm = 0.25 * d->pitch_mm;
	out->body_x_mm = 0.0;
	out->body_y_mm = 0.0;
	out->body_tan_beta = tan(d->flank_angle_rad);
	out->body_p = prsm_design_screw_p(d); /* nut has the same starts and hand */
	if (side == PRSM_SIDE_SCREW) {
		out->body_radius_mm = d->screw_radius_mm;
		out->body_shift_mm = d->flank_shift_screw_mm;
		out->body_root_mm = d->screw_root_radius_mm;
		out->body_crest_mm = d->screw_crest_radius_mm;
	} else {
		out->body_radius_mm = d->nut_radius_mm;
		out->body_shift_mm = d->flank_shift_nut_mm;
		out->body_root_mm = d->nut_root_radius_mm;
		out->body_crest_mm = d->nut_crest_radius_mm;
	}
	out->roller_x_mm = a;
	out->roller_y_mm = 0.0;
	out->roller_radius_mm = d->roller_radius_mm;
	out->arc_radius_mm = d->roller_arc_radius_mm;
	out->roller_p = prsm_design_roller_p(d);
	out->roller_shift_mm = d->flank_shift_roller_mm;
	out->roller_root_mm = d->roller_root_radius_mm;
	out->roller_crest_mm = d->roller_crest_radius_mm;
}

/* Roller angle phi of the offset w from the roller axis (see the file comment). */
static double roller_phi(const prsm_flank_pair *p, double wx, double wy)
{
	return p->side == PRSM_SIDE_SCREW ? atan2(-wy, -wx) : atan2(wy, wx);
}

double prsm_contact_gap(const prsm_flank_pair *p, double x, double y)
{
	const double X = x - p->body_x_mm, Y = y - p->body_y_mm;
	const double wx = x - p->roller_x_mm, wy = y - p->roller_y_mm;
	const double rho = sqrt(X * X + Y * Y);
	const double R = p->arc_radius_mm;
	const double S = sqrt(R * R - (wx * wx + wy * wy));
	const double zc = p->quarter_pitch_mm + sqrt(R * R - p->roller_radius_mm * p->roller_radius_mm);
	const double Zr = zc - S + p->roller_p * roller_phi(p, wx, wy) + p->roller_shift_mm;
	const double Zb = p->quarter_pitch_mm + body_sigma(p) * (rho - p->body_radius_mm) * p->body_tan_beta +
	                  p->body_p * atan2(Y, X) - p->body_shift_mm;
	return Zr - Zb;
}

void prsm_contact_gap_derivatives(const prsm_flank_pair *p, double x, double y, double g[2],
                                  double h[3])
{
	const double X = x - p->body_x_mm, Y = y - p->body_y_mm;
	const double wx = x - p->roller_x_mm, wy = y - p->roller_y_mm;
	const double rho2 = X * X + Y * Y, rho = sqrt(rho2);
	const double u2 = wx * wx + wy * wy;
	const double R = p->arc_radius_mm;
	const double S = sqrt(R * R - u2);
	const double st = body_sigma(p) * p->body_tan_beta;
	const double pb = p->body_p, pr = p->roller_p;
	/* the Monte Carlo kernel: three divisions, the rest multiplications by these reciprocals */
	const double iS = 1.0 / S, iu2 = 1.0 / u2, irho = 1.0 / rho;
	const double irho2 = irho * irho;
	/* grad: w/S + p_r (-wy, wx)/u^2 - sigma tan(beta) (X, Y)/rho - p_b (-Y, X)/rho^2 */
	g[0] = wx * iS - pr * wy * iu2 - st * X * irho + pb * Y * irho2;
	g[1] = wy * iS + pr * wx * iu2 - st * Y * irho - pb * X * irho2;
	if (h == NULL)
		return;
	const double iS3 = iS * iS * iS, irho3 = irho2 * irho, irho4 = irho2 * irho2, iu4 = iu2 * iu2;
	/* Hess of -S: I/S + w w^T / S^3; Hess of an angle about (0,0) at (X,Y):
	 * [[2XY, Y^2-X^2], [Y^2-X^2, -2XY]] / r^4; Hess rho = [[Y^2, -XY], [-XY, X^2]] / rho^3 */
	const double wxy = wx * wy, XY = X * Y;
	h[0] = iS + wx * wx * iS3 + pr * 2.0 * wxy * iu4 - st * Y * Y * irho3 - pb * 2.0 * XY * irho4;
	h[1] = wxy * iS3 + pr * (wy * wy - wx * wx) * iu4 + st * XY * irho3 - pb * (Y * Y - X * X) * irho4;
	h[2] = iS + wy * wy * iS3 - pr * 2.0 * wxy * iu4 - st * X * X * irho3 + pb * 2.0 * XY * irho4;
}

void prsm_contact_start(const prsm_flank_pair *p, double *x, double *y)
{
	/* unit vector from the body axis to the roller axis, and its normal */
	double dx = p->roller_x_mm - p->body_x_mm, dy = p->roller_y_mm - p->body_y_mm;
	double dn = hypot(dx, dy);
	dx /= dn;
	dy /= dn;
	double off = 0.0;
	if (p->side == PRSM_SIDE_SCREW) {
		/* docs/model/geometry-and-meshing.md: y_c ~ P cot(beta)/pi on the side the hand gives */
		double P = 4.0 * p->quarter_pitch_mm;
		off = (p->roller_p >= 0.0 ? 1.0 : -1.0) * P / (M_PI * p->body_tan_beta);
	}
	*x = p->body_x_mm + p->body_radius_mm * dx - off * dy;
	*y = p->body_y_mm + p->body_radius_mm * dy + off * dx;
}

int prsm_contact_solve_gap(const prsm_flank_pair *p, double *x_mm, double *y_mm, double *gap_mm,
                           int *iterations)
{
	double x = *x_mm, y = *y_mm, g[2], h[3];
	const double R = p->arc_radius_mm;
	const double maxstep = 0.5 * R;
	double last = 0.0; /* the previous step, mm (0: none yet) */
	int it;
	for (it = 1; it <= NEWTON_MAX_ITER; it++) {
		prsm_contact_gap_derivatives(p, x, y, g, h);
		double det = h[0] * h[2] - h[1] * h[1];
		if (!(det > 0.0) || !(h[0] > 0.0))
			break; /* not a minimum of the gap: no common normal here */
		double dx = -(h[2] * g[0] - h[1] * g[1]) / det;
		double dy = -(h[0] * g[1] - h[1] * g[0]) / det;
		double step = sqrt(dx * dx + dy * dy);
		if (step > maxstep) {
			dx *= maxstep / step;
			dy *= maxstep / step;
		}
		x += dx;
		y += dy;
		double wx = x - p->roller_x_mm, wy = y - p->roller_y_mm;
		if (wx * wx + wy * wy >= R * R)
			break; /* left the arc's domain: cannot continue */
		/* Converged when the step was below the tolerance, or when, in the quadratic regime
		 * (step small, e_next ~ K step^2 with K = step / last^2 measured on the last two
		 * steps), the error left after this step is a thousandth of it: that saves the one
		 * evaluation which would only confirm a step at the rounding level (K is about
		 * 0.5 / mm for case A). */
		const int quadratic = last > 0.0 && step < NEWTON_QUADRATIC_MM &&
		                      step * step * step < 1e-3 * NEWTON_TOL_MM * last * last;
		if (step < NEWTON_TOL_MM || quadratic) {
			*x_mm = x;
			*y_mm = y;
			*gap_mm = prsm_contact_gap(p, x, y);
			if (iterations)
				*iterations = it;
			return 0;
		}
		last = step;
	}
	*x_mm = x;
	*y_mm = y;
	*gap_mm = NAN;
	if (iterations)
		*iterations = it;
	return PRSM_ENOCONVERGE;
}

int prsm_contact_edge(const prsm_flank_pair *p, double x, double y)
{
	int e = 0;
	double rho = hypot(x - p->body_x_mm, y - p->body_y_mm);
	double u = hypot(x - p->roller_x_mm, y - p->roller_y_mm);
	if (p->side == PRSM_SIDE_SCREW) {
		if (rho < p->body_root_mm) e |= PRSM_EDGE_BODY_ROOT;
		if (rho > p->body_crest_mm) e |= PRSM_EDGE_BODY_CREST;
	} else {
		if (rho > p->body_root_mm) e |= PRSM_EDGE_BODY_ROOT;
		if (rho < p->body_crest_mm) e |= PRSM_EDGE_BODY_CREST;
	}
	if (u < p->roller_root_mm) e |= PRSM_EDGE_ROLLER_ROOT;
	if (u > p->roller_crest_mm) e |= PRSM_EDGE_ROLLER_CREST;
	if (u >= p->arc_radius_mm) e |= PRSM_EDGE_ARC;
	return e;
}

int prsm_contact_solve(prsm_contact *out, const prsm_flank_pair *p)
{
	double x, y, gap;
	int iters = 0;
	prsm_contact_start(p, &x, &y);
	int rc = prsm_contact_solve_gap(p, &x, &y, &gap, &iters);
	*out = (prsm_contact){0};
	out->x_mm = x;
	out->y_mm = y;
	out->gap_mm = gap;
	out->iterations = iters;
	if (rc != 0)
		return rc;

	const double X = x - p->body_x_mm, Y = y - p->body_y_mm;
	const double wx = x - p->roller_x_mm, wy = y - p->roller_y_mm;
	const double rho = hypot(X, Y);
	out->body_rho_mm = rho;
	out->roller_u_mm = hypot(wx, wy);
	out->body_angle_rad = atan2(Y, X);
	out->roller_angle_rad = roller_phi(p, wx, wy);

	/* body flank gradient: dZ_b = sigma tan(beta) (X,Y)/rho + p_b (-Y, X)/rho^2 */
	const double st = body_sigma(p) * p->body_tan_beta;
	const double zx = st * X / rho - p->body_p * Y / (rho * rho);
	const double zy = st * Y / rho + p->body_p * X / (rho * rho);
	const double norm = sqrt(1.0 + zx * zx + zy * zy);
	/* normal (-Zx, -Zy, 1)/norm; radial and tangential components in the body frame */
	const double er[2] = {X / rho, Y / rho}, et[2] = {-Y / rho, X / rho};
	out->normal[0] = (-zx * er[0] - zy * er[1]) / norm;
	out->normal[1] = (-zx * et[0] - zy * et[1]) / norm;
	out->normal[2] = 1.0 / norm;

	/* relative principal curvatures: generalized eigenvalues of Hess G with the first
	 * fundamental form I of the body flank, scaled by the normal's axial part (docs/model/geometry-and-meshing.md) */
	double g[2], h[3];
	prsm_contact_gap_derivatives(p, x, y, g, h);
	const double I11 = 1.0 + zx * zx, I12 = zx * zy, I22 = 1.0 + zy * zy;
	const double A = I11 * I22 - I12 * I12;
	const double B = -(h[0] * I22 + h[2] * I11 - 2.0 * h[1] * I12);
	const double C = h[0] * h[2] - h[1] * h[1];
	const double disc = sqrt(fmax(B * B - 4.0 * A * C, 0.0));
	const double q = -0.5 * (B + (B < 0 ? -disc : disc));
	double k1 = q / A, k2 = C / q;
	if (k1 > k2) {
		double t = k1;
		k1 = k2;
		k2 = t;
	}
	out->curvature_per_mm[0] = k1 / norm;
	out->curvature_per_mm[1] = k2 / norm;

	out->edge = prsm_contact_edge(p, x, y);
	return out->edge ? PRSM_EEDGE : 0;
}
