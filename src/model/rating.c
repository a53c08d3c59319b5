/*
 * rating.c: the makers' convention and the contact-ellipse truncation check (MODEL.md §6
 * "Static capacity"; see rating.h for the method).
 */
#include "model/rating.h"

#include <math.h>
#include <string.h>

int prsm_rating_truncation(prsm_truncation *out, const prsm_design *d, const prsm_contact *c,
                           const prsm_hertz *ref, int side, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (side != PRSM_SIDE_SCREW && side != PRSM_SIDE_NUT)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "truncation: unknown side %d", side);
	if (!(ref->load_N > 0.0) || !(ref->p_max_MPa > 0.0) || !(ref->a_mm > 0.0) || !(ref->b_mm > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "truncation: needs a Hertz solution at a positive load (got %g N)",
		                      ref->load_N);
	const double cb = cos(d->flank_angle_rad), R = d->roller_arc_radius_mm;
	const double rho = c->body_rho_mm, u = c->roller_u_mm;
	double crest, root;
	if (side == PRSM_SIDE_SCREW) {
		crest = d->screw_crest_radius_mm - rho; /* external thread: crest outside */
		root = rho - d->screw_root_radius_mm;
	} else {
		crest = rho - d->nut_crest_radius_mm; /* internal thread: crest inside */
		root = d->nut_root_radius_mm - rho;
	}
	/* rating.h: the straight flank |d rho| / cos beta, the roller arc R |d asin(u / R)| */
	out->distance_mm[PRSM_FLANK_EDGE_BODY_CREST] = crest / cb;
	out->distance_mm[PRSM_FLANK_EDGE_BODY_ROOT] = root / cb;
	const double au = asin(fmin(1.0, u / R));
	out->distance_mm[PRSM_FLANK_EDGE_ROLLER_CREST] =
		R * (asin(fmin(1.0, d->roller_crest_radius_mm / R)) - au);
	out->distance_mm[PRSM_FLANK_EDGE_ROLLER_ROOT] =
		R * (au - asin(fmin(1.0, d->roller_root_radius_mm / R)));
	out->edge = 0;
	for (int i = 1; i < 4; i++)
		if (out->distance_mm[i] < out->distance_mm[out->edge])
			out->edge = i;
	out->margin_mm = out->distance_mm[out->edge];
	if (!(out->margin_mm > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "truncation: the contact point lies outside its flank (margin %g mm)",
		                      out->margin_mm);
	/* the profile curvature is 1/R: the principal curvature nearer to it is the profile's */
	const double k_profile = 1.0 / R;
	out->profile_is_major =
		fabs(c->curvature_per_mm[0] - k_profile) <= fabs(c->curvature_per_mm[1] - k_profile);
	out->profile_axis_ref_mm = out->profile_is_major ? ref->a_mm : ref->b_mm;
	out->load_ref_N = ref->load_N;
	out->p_ref_MPa = ref->p_max_MPa;
	/* semi-axes and p_max ~ Q^(1/3) (MODEL.md §6, Hertz) */
	const double s = out->margin_mm / out->profile_axis_ref_mm;
	out->q_limit_N = ref->load_N * s * s * s;
	out->p_limit_MPa = ref->p_max_MPa * s;
	return 0;
}

double prsm_truncation_profile_axis_mm(const prsm_truncation *t, double Q_N)
{
	if (!(Q_N > 0.0))
		return 0.0;
	return t->profile_axis_ref_mm * cbrt(Q_N / t->load_ref_N);
}

int prsm_rating_makers(prsm_makers_rating *out, double C0s, double C0n,
                       const prsm_truncation *ts, const prsm_truncation *tn, double p_allow,
                       int contacts, double Ca, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (!(C0s > 0.0) || !(C0n > 0.0) || !(p_allow > 0.0) || !(Ca > 0.0) || contacts < 1 ||
	    !(ts->p_limit_MPa > 0.0) || !(tn->p_limit_MPa > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "makers' rating: needs positive capacities (C_0a %g and %g N, C_a %g N), "
		                      "p_allow %g MPa and truncation limits", C0s, C0n, Ca, p_allow);
	out->p_allow_MPa = p_allow;
	out->contacts = contacts;
	out->C0a_screw_N = C0s;
	out->C0a_nut_N = C0n;
	out->C0a_N = fmin(C0s, C0n);
	/* equal sharing: the axial load ~ Q ~ p^3, so a lower pressure limit scales it by its cube */
	const double fs = fmin(1.0, ts->p_limit_MPa / p_allow), fn = fmin(1.0, tn->p_limit_MPa / p_allow);
	out->C0a_truncation_limited_N = fmin(C0s * fs * fs * fs, C0n * fn * fn * fn);
	out->truncated = ts->p_limit_MPa < p_allow || tn->p_limit_MPa < p_allow;
	out->C_a_N = Ca;
	out->C0a_over_C_a = out->C0a_N / Ca;
	return 0;
}
