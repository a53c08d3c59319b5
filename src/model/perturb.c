/*
 * perturb.c: exact and linear flank gaps under errors (docs/model/errors-and-assembly.md).
 */
#include "model/perturb.h"

#include <math.h>

const char *const prsm_perturb_names[PRSM_PERTURB_COUNT] = {
	"body_dx_mm",      "body_dy_mm",      "body_radius_mm",   "body_flank_angle_rad",
	"body_shift_mm",   "roller_dx_mm",    "roller_dy_mm",     "roller_radius_mm",
	"roller_arc_radius_mm", "roller_shift_mm"};

void prsm_perturb_apply(prsm_flank_pair *out, const prsm_flank_pair *p, const double *e)
{
	*out = *p;
	out->body_x_mm += e[PRSM_PERTURB_BODY_DX];
	out->body_y_mm += e[PRSM_PERTURB_BODY_DY];
	out->body_radius_mm += e[PRSM_PERTURB_BODY_RADIUS];
	out->body_tan_beta = tan(atan(p->body_tan_beta) + e[PRSM_PERTURB_BODY_BETA]);
	out->body_shift_mm += e[PRSM_PERTURB_BODY_SHIFT];
	out->roller_x_mm += e[PRSM_PERTURB_ROLLER_DX];
	out->roller_y_mm += e[PRSM_PERTURB_ROLLER_DY];
	out->roller_radius_mm += e[PRSM_PERTURB_ROLLER_RADIUS];
	out->arc_radius_mm += e[PRSM_PERTURB_ROLLER_ARC];
	out->roller_shift_mm += e[PRSM_PERTURB_ROLLER_SHIFT];
}

void prsm_perturb_sensitivities(double *s, const prsm_flank_pair *p, double x, double y)
{
	const double X = x - p->body_x_mm, Y = y - p->body_y_mm;
	const double wx = x - p->roller_x_mm, wy = y - p->roller_y_mm;
	const double rho2 = X * X + Y * Y, rho = sqrt(rho2), u2 = wx * wx + wy * wy;
	const double R = p->arc_radius_mm, rr = p->roller_radius_mm;
	const double S = sqrt(R * R - u2), C = sqrt(R * R - rr * rr);
	const double sigma = p->side == PRSM_SIDE_SCREW ? -1.0 : 1.0;
	const double tb = p->body_tan_beta;
	/* G = Z_r(x - r) - Z_b(x - b): moving an axis by d changes G by -/+ grad Z . d */
	/* grad Z_b = sigma tan(beta) (X, Y)/rho + p_b (-Y, X)/rho^2 */
	s[PRSM_PERTURB_BODY_DX] = sigma * tb * X / rho - p->body_p * Y / rho2;
	s[PRSM_PERTURB_BODY_DY] = sigma * tb * Y / rho + p->body_p * X / rho2;
	/* Z_b = ... + sigma (rho - r_b) tan(beta): dZ_b/dr_b = -sigma tan(beta) */
	s[PRSM_PERTURB_BODY_RADIUS] = sigma * tb;
	/* dZ_b/dbeta = sigma (rho - r_b) sec^2(beta) */
	s[PRSM_PERTURB_BODY_BETA] = -sigma * (rho - p->body_radius_mm) * (1.0 + tb * tb);
	s[PRSM_PERTURB_BODY_SHIFT] = 1.0;
	/* grad Z_r = w/S + p_r (-wy, wx)/u^2 */
	s[PRSM_PERTURB_ROLLER_DX] = -(wx / S - p->roller_p * wy / u2);
	s[PRSM_PERTURB_ROLLER_DY] = -(wy / S + p->roller_p * wx / u2);
	/* z_c = P/4 + sqrt(R^2 - r_r^2) */
	s[PRSM_PERTURB_ROLLER_RADIUS] = -rr / C;
	s[PRSM_PERTURB_ROLLER_ARC] = R / C - R / S;
	s[PRSM_PERTURB_ROLLER_SHIFT] = 1.0;
}

int prsm_perturb_gap_exact(double *gap_mm, int *edge, const prsm_flank_pair *nominal, double x,
                           double y, const double *e)
{
	prsm_flank_pair q;
	prsm_perturb_apply(&q, nominal, e);
	int rc = prsm_contact_solve_gap(&q, &x, &y, gap_mm, NULL);
	if (edge)
		*edge = rc ? 0 : prsm_contact_edge(&q, x, y);
	return rc;
}

double prsm_perturb_gap_linear(double nominal_gap_mm, const double *sens, const double *e)
{
	double g = nominal_gap_mm;
	for (int i = 0; i < PRSM_PERTURB_COUNT; i++)
		g += sens[i] * e[i];
	return g;
}
