/*
 * life.c: duty-cycle mean load, L10 life, static and dynamic capacity, preload derating and
 * column limits (docs/model/kinematics-efficiency-stiffness-life.md). See life.h for the methods and their sources.
 */
#include "model/life.h"

#include <math.h>
#include <string.h>

int prsm_life_cubic_mean_load(double *out_N, const double *F, const double *w, size_t n,
                              prsm_error *err)
{
	*out_N = NAN;
	if (n == 0)
		return prsm_error_set(err, PRSM_EINVAL, "/duty_cycle", "duty cycle: no steps");
	double num = 0.0, den = 0.0;
	for (size_t i = 0; i < n; i++) {
		if (!(w[i] >= 0.0) || !isfinite(w[i]) || !isfinite(F[i]))
			return prsm_error_set(err, PRSM_EINVAL, "/duty_cycle",
			                      "duty cycle step %zu: load %g N and weight %g must be finite, the "
			                      "weight >= 0", i, F[i], w[i]);
		const double a = fabs(F[i]);
		num += a * a * a * w[i];
		den += w[i];
	}
	if (!(den > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/duty_cycle", "duty cycle: the weights sum to 0");
	*out_N = cbrt(num / den); /* docs/model/kinematics-efficiency-stiffness-life.md cubic mean */
	return 0;
}

int prsm_life_cubic_mean_load_speed_time(double *out_N, const double *F, const double *speed_rpm,
                                         const double *time_fraction, size_t n, prsm_error *err)
{
	*out_N = NAN;
	if (n == 0)
		return prsm_error_set(err, PRSM_EINVAL, "/duty_cycle", "duty cycle: no steps");
	/* weighted by revolutions n_i q_i; the loads are cubed, the weights are not */
	double num = 0.0, den = 0.0;
	for (size_t i = 0; i < n; i++) {
		const double wi = fabs(speed_rpm[i]) * time_fraction[i];
		if (!(time_fraction[i] >= 0.0) || !isfinite(wi) || !isfinite(F[i]))
			return prsm_error_set(err, PRSM_EINVAL, "/duty_cycle",
			                      "duty cycle step %zu: load %g N, speed %g rpm, time fraction %g must "
			                      "be finite, the fraction >= 0", i, F[i], speed_rpm[i], time_fraction[i]);
		const double a = fabs(F[i]);
		num += a * a * a * wi;
		den += wi;
	}
	if (!(den > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/duty_cycle", "duty cycle: no revolutions");
	*out_N = cbrt(num / den);
	return 0;
}

int prsm_life_reliability_factor(double *a1, int percent, prsm_error *err)
{
	/* docs/model/kinematics-efficiency-stiffness-life.md */
	static const int pct[] = {90, 95, 96, 97, 98, 99};
	static const double fac[] = {1.0, 0.62, 0.53, 0.44, 0.33, 0.21};
	for (size_t i = 0; i < sizeof pct / sizeof pct[0]; i++)
		if (pct[i] == percent) {
			*a1 = fac[i];
			return 0;
		}
	*a1 = NAN;
	return prsm_error_set(err, PRSM_EINVAL, "/reliability_percent",
	                      "reliability %d %% has no factor (90, 95, 96, 97, 98 or 99)", percent);
}

int prsm_life_l10(prsm_life_rating *out, double C, double Fm, double speed_rpm, double lead_mm,
                  int percent, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->capacity_N = C;
	out->mean_load_N = Fm;
	out->reliability_percent = percent;
	int rc = prsm_life_reliability_factor(&out->reliability_factor, percent, err);
	if (rc)
		return rc;
	if (!(C > 0.0) || !(Fm > 0.0) || !(speed_rpm >= 0.0) || !(lead_mm > 0.0) || !isfinite(C) ||
	    !isfinite(Fm) || !isfinite(speed_rpm) || !isfinite(lead_mm))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "L10: needs C_a > 0 (%g N), F_m > 0 (%g N), speed >= 0 (%g rpm), lead > 0 "
		                      "(%g mm)", C, Fm, speed_rpm, lead_mm);
	const double r = C / Fm;
	out->revolutions = out->reliability_factor * r * r * r * 1e6; /* docs/model/kinematics-efficiency-stiffness-life.md */
	out->hours = speed_rpm > 0.0 ? out->revolutions / (60.0 * speed_rpm) : 0.0;
	out->distance_km = out->revolutions * lead_mm * 1e-6;
	return 0;
}

int prsm_life_static_capacity(prsm_static_capacity *out, const prsm_hertz *h, double nz,
                              int contacts, double K, double p_allow, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->p_allow_MPa = p_allow;
	out->axial_component = nz;
	out->contacts = contacts;
	out->load_factor = K;
	if (!(h->load_N > 0.0) || !(h->p_max_MPa > 0.0) || !(p_allow > 0.0) || !(nz > 0.0 && nz <= 1.0) ||
	    contacts < 1 || !(K >= 1.0) || !isfinite(K) || !isfinite(p_allow))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "static capacity: needs a Hertz solution at a positive load, p_allow > 0 "
		                      "(%g MPa), 0 < n_z <= 1 (%g), contacts >= 1 (%d), load factor >= 1 (%g)",
		                      p_allow, nz, contacts, K);
	/* p_max ~ Q^(1/3) at fixed geometry (docs/model/kinematics-efficiency-stiffness-life.md, Hertz) */
	const double s = p_allow / h->p_max_MPa;
	out->q_allow_N = h->load_N * s * s * s;
	out->C0a_N = out->q_allow_N * nz * contacts / K;
	return 0;
}

int prsm_life_raceway_rating(double *out_N, const prsm_lp_raceway *r, const prsm_lp_method *m,
                             prsm_error *err)
{
	*out_N = NAN;
	const double D = r->ball_diameter_mm, ca = cos(r->contact_angle_rad);
	const double g = D * ca / r->pitch_diameter_mm;
	if (!(D > 0.0) || !(r->pitch_diameter_mm > 0.0) || !(ca > 0.0) || r->elements < 1 ||
	    !(g > 0.0 && g < 1.0) || !(r->conformity > 0.5))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "raceway rating: needs D > 0 (%g mm), 0 <= alpha < pi/2, 0 < gamma < 1 "
		                      "(%g), conformity > 0.5 (%g), Z >= 1 (%d)", D, g, r->conformity,
		                      r->elements);
	const double f = r->conformity;
	const double conform = isinf(f) ? 1.0 : pow(2.0 * f / (2.0 * f - 1.0), 0.41);
	const double near = r->outer ? 1.0 + g : 1.0 - g, far = r->outer ? 1.0 - g : 1.0 + g;
	*out_N = m->material_factor * m->constant * conform * pow(near, 1.39) / cbrt(far) *
	         pow(g / ca, 0.3) * pow(D, m->diameter_exponent) / cbrt((double)r->elements);
	return 0;
}

double prsm_life_combine_ratings(const double *q, size_t n, double x)
{
	double s = 0.0;
	for (size_t i = 0; i < n; i++) {
		if (!(q[i] > 0.0))
			return 0.0;
		s += pow(q[i], -x);
	}
	return pow(s, -1.0 / x);
}

double prsm_life_distribution_factor(const double *loads, size_t n, double x)
{
	double mean = 0.0;
	for (size_t i = 0; i < n; i++)
		mean += fabs(loads[i]);
	if (n == 0 || !(mean > 0.0))
		return NAN;
	mean /= (double)n;
	double s = 0.0;
	for (size_t i = 0; i < n; i++)
		s += pow(fabs(loads[i]) / mean, x);
	return pow(s / (double)n, -1.0 / x);
}

int prsm_life_dynamic_capacity(prsm_dynamic_capacity *out, const prsm_design *d,
                               const prsm_lp_method *mi, double load_factor, prsm_error *err)
{
	const prsm_lp_method defaults = PRSM_LP_METHOD_INIT;
	const prsm_lp_method *m = mi ? mi : &defaults;
	memset(out, 0, sizeof *out);
	out->method = *m;
	out->load_factor = load_factor;
	out->rollers = d->rollers;
	out->threads = d->engaged_threads;
	const double rs = d->screw_radius_mm, rr = d->roller_radius_mm, rn = d->nut_radius_mm;
	const double a = rs + rr, beta = d->flank_angle_rad;
	if (!(load_factor > 0.0 && load_factor <= 1.0) || d->rollers < 1 || d->engaged_threads < 1 ||
	    !(rs > 0.0 && rr > 0.0 && rn > 0.0) || !(beta > 0.0 && beta < M_PI / 2.0) ||
	    !(d->roller_arc_radius_mm > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "dynamic capacity: needs a load factor in (0, 1] (%g), Z >= 1, n_t >= 1, "
		                      "positive radii and 0 < beta < pi/2", load_factor);
	/* the roller flank as a ball: D = 2R, d_m = 2a, alpha = pi/2 - beta (life.h) */
	out->ball_diameter_mm = 2.0 * d->roller_arc_radius_mm;
	out->contact_angle_rad = 0.5 * M_PI - beta;
	out->gamma = out->ball_diameter_mm * cos(out->contact_angle_rad) / (2.0 * a);
	out->carrier_ratio = rs / (2.0 * a);
	prsm_lp_raceway ring = {out->ball_diameter_mm, out->contact_angle_rad, 2.0 * a, INFINITY,
	                        d->rollers, 0};
	int rc;
	if ((rc = prsm_life_raceway_rating(&out->q_screw_N, &ring, m, err)))
		return rc;
	ring.outer = 1;
	if ((rc = prsm_life_raceway_rating(&out->q_nut_N, &ring, m, err)))
		return rc;
	/* roller flanks from the mating ring at the same contact: stressed-volume law (life.h) */
	const double kc = out->carrier_ratio, Z = d->rollers, e = m->weibull_slope;
	const double u_s = Z * (1.0 - kc), u_n = Z * kc, u_r = (rn / rr) * kc;
	const double life_rs = pow(rr / rs, -1.0 / e) * u_s / u_r; /* L_roller / L_screw */
	const double life_rn = pow(rr / rn, -1.0 / e) * u_n / u_r;
	out->q_roller_screw_side_N = out->q_screw_N * pow(life_rs, 1.0 / m->life_exponent);
	out->q_roller_nut_side_N = out->q_nut_N * pow(life_rn, 1.0 / m->life_exponent);
	const double q[4] = {out->q_screw_N, out->q_roller_screw_side_N, out->q_roller_nut_side_N,
	                     out->q_nut_N};
	out->q_combined_N = prsm_life_combine_ratings(q, 4, m->combination_exponent);
	out->axial_contact_N = out->q_combined_N * sin(out->contact_angle_rad);
	out->row_N = Z * out->axial_contact_N;
	/* n_t equal rows in series: n_t^(1 - 1/x) (x = 10/3 gives 7/10) */
	const double rows = pow((double)d->engaged_threads, 1.0 - 1.0 / m->combination_exponent);
	out->C_a_N = load_factor * out->row_N * rows;
	return 0;
}

int prsm_life_preload_load(double *out_N, double F, double Fpr, prsm_error *err)
{
	*out_N = NAN;
	if (!(Fpr >= 0.0) || !isfinite(Fpr) || !isfinite(F))
		return prsm_error_set(err, PRSM_EINVAL, "/preload_N",
		                      "preload %g N must be finite and >= 0 (load %g N)", Fpr, F);
	const double a = fabs(F), lift = pow(2.0, 1.5) * Fpr;
	*out_N = a >= lift ? a : Fpr * pow(1.0 + a / lift, 1.5);
	return 0;
}

int prsm_life_column(prsm_column *out, double dr, double L, int fixity, double E, double rho,
                     prsm_error *err)
{
	/* end fixity: Euler factor m, first-mode eigenvalue lambda, catalogue f_c (steel, with the
	 * catalogues' 0.8) */
	static const double m_[] = {0.25, 1.0, 2.0457, 4.0};
	static const double lam[] = {1.8751040687, M_PI, 3.9266023120, 4.7300407449};
	static const double fc[] = {3.4, 9.7, 15.1, 21.9};
	memset(out, 0, sizeof *out);
	out->fixity = fixity;
	out->root_diameter_mm = dr;
	out->free_length_mm = L;
	if (fixity < PRSM_FIXITY_FIXED_FREE || fixity > PRSM_FIXITY_FIXED_FIXED)
		return prsm_error_set(err, PRSM_EINVAL, "/column/fixity", "column: unknown end fixity %d",
		                      fixity);
	if (!(dr > 0.0) || !(L > 0.0) || !(E > 0.0) || !(rho > 0.0) || !isfinite(dr) || !isfinite(L))
		return prsm_error_set(err, PRSM_EINVAL, "/column",
		                      "column: needs root diameter, free length, E and density > 0 (d_r %g mm, "
		                      "L %g mm, E %g MPa, rho %g kg/m^3)", dr, L, E, rho);
	out->buckling_factor = m_[fixity];
	out->speed_eigenvalue = lam[fixity];
	out->catalogue_speed_factor = fc[fixity];
	const double I = M_PI * dr * dr * dr * dr / 64.0;  /* mm^4 */
	const double A = M_PI * dr * dr / 4.0;              /* mm^2 */
	/* E/rho in mm^2/s^2: (N/mm^2) / (kg/mm^3) = 1e3 mm^2/s^2 per unit, rho kg/m^3 = 1e-9 kg/mm^3 */
	const double c = sqrt(E * I / (rho * 1e-9 * A) * 1e3); /* mm^2/s */
	const double l = lam[fixity] / L;
	out->critical_speed_rpm = 60.0 / (2.0 * M_PI) * l * l * c;
	out->catalogue_speed_rpm = fc[fixity] * dr / (L * L) * 1e7;
	out->buckling_load_N = m_[fixity] * M_PI * M_PI * E * I / (L * L);
	return 0;
}
