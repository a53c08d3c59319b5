/*
 * compliance.c: Yamamoto's thread-tooth compliance with an explicit effective width, and the
 * stretch compliance of body segments (docs/model/kinematics-efficiency-stiffness-life.md). See compliance.h for the formulas, the
 * width rules and the negative-term pathology.
 */
#include "model/compliance.h"

#include <math.h>
#include <string.h>

static const char *part_name(int part)
{
	switch (part) {
	case PRSM_THREAD_SCREW: return "screw";
	case PRSM_THREAD_ROLLER: return "roller";
	case PRSM_THREAD_NUT: return "nut";
	default: return "thread";
	}
}

int prsm_compliance_yamamoto(prsm_yamamoto *out, const prsm_thread_tooth *t, int negative_policy,
                             prsm_error *err)
{
	const double P = t->pitch_mm, a = t->root_thickness_mm, b = t->load_thickness_mm;
	const double c = t->load_height_mm, beta = t->flank_angle_rad, nu = t->poisson;
	const double E = t->E_MPa, d = t->diameter_mm;
	memset(out, 0, sizeof *out);
	if (!(E > 0.0) || !(nu > -1.0 && nu < 0.5) || !(P > 0.0) || !(d > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Yamamoto tooth: needs E > 0, -1 < nu < 0.5, P > 0, d > 0 "
		                      "(E %g MPa, nu %g, P %g mm, d %g mm)", E, nu, P, d);
	if (!(beta > 0.0 && beta < M_PI / 2.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Yamamoto tooth: flank angle %g rad outside (0, pi/2)", beta);
	if (!(b > 0.0 && b <= a && a < 2.0 * P && c >= 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Yamamoto tooth: needs 0 < b <= a < 2P and c >= 0 (a %g, b %g, c %g, "
		                      "P %g mm)", a, b, c, P);
	if (t->internal && !(t->outer_diameter_mm > d))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Yamamoto tooth: the nut's outer diameter %g mm must exceed its pitch "
		                      "diameter %g mm", t->outer_diameter_mm, d);

	const double tb = tan(beta), cot = 1.0 / tb;
	const double ba = b / a, ca = c / a, lnab = log(a / b);
	/* docs/model/kinematics-efficiency-stiffness-life.md thread compliance; Yamamoto's terms, each per unit load per unit width */
	out->bending = (1.0 - nu * nu) * 0.75 / E *
	               ((1.0 - (2.0 - ba) * (2.0 - ba) + 2.0 * lnab) * cot * cot * cot - 4.0 * ca * ca * tb);
	out->shear = (1.0 + nu) * 1.2 / E * cot * lnab;
	out->root_tilt = (1.0 - nu * nu) * 12.0 * c / (M_PI * E * a * a) * (c - 0.5 * b * tb);
	out->root_shear = (1.0 - nu * nu) * 2.0 / (M_PI * E) *
	                  ((P / a) * log((P + 0.5 * a) / (P - 0.5 * a)) + 0.5 * log(4.0 * P * P / (a * a) - 1.0));
	double ring = 1.0 - nu; /* solid body */
	if (t->internal) {
		const double Do2 = t->outer_diameter_mm * t->outer_diameter_mm, d2 = d * d;
		ring = (Do2 + d2) / (Do2 - d2) + nu; /* Lame thick ring */
	}
	out->radial = ring * 0.5 * tb * tb * (d / P) / E;

	const double terms[5] = {out->bending, out->shear, out->root_tilt, out->root_shear, out->radial};
	/* a term is negative when it is below -1e-12 of the terms' scale: a root-tilt term that is
	 * exactly 0 as printed (c = (b/2) tan beta, case A) must not be flagged by rounding */
	double scale = 0.0, sum = 0.0;
	for (int i = 0; i < 5; i++)
		scale += fabs(terms[i]);
	for (int i = 0; i < 5; i++) {
		if (terms[i] < -1e-12 * scale) {
			out->negative_terms |= 1 << i;
			if (negative_policy == PRSM_YAMAMOTO_CLAMP) {
				out->clamped = 1;
				continue;
			}
		}
		sum += terms[i];
	}
	out->sum_mm2_per_N = sum;
	if (!(sum > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "Yamamoto tooth: the terms sum to %g mm^2/N (not positive) with the "
		                      "negative terms kept; clamp them or use another rule", sum);
	return 0;
}

/* Depth c from the pitch line to the tooth root of a straight-flank thread, and the root
 * thickness a: the root radius or the closing of the groove, whichever comes first. */
static void straight_tooth(prsm_thread_tooth *t, double P, double beta, double b, double depth)
{
	const double tb = tan(beta);
	const double close = (P - b) / (2.0 * tb); /* groove width P - b - 2 y tan beta = 0 */
	const double c = fmin(depth, close);
	t->load_thickness_mm = b;
	t->load_height_mm = c;
	t->root_thickness_mm = fmin(b + 2.0 * c * tb, P);
}

int prsm_compliance_tooth(prsm_thread_tooth *out, const prsm_design *d, int part,
                          double nut_outer_radius_mm, prsm_error *err)
{
	const double P = d->pitch_mm, beta = d->flank_angle_rad;
	memset(out, 0, sizeof *out);
	out->pitch_mm = P;
	out->flank_angle_rad = beta;
	if (!(P > 0.0) || !(beta > 0.0 && beta < M_PI / 2.0))
		return prsm_error_set(err, PRSM_EINVAL, "/geometry",
		                      "thread tooth: needs P > 0 and 0 < beta < pi/2 (P %g mm, beta %g rad)",
		                      P, beta);
	double b, depth;
	const prsm_material *m;
	const char *thinning = "/thinning"; /* where a tooth thinned away is the design's problem */
	switch (part) {
	case PRSM_THREAD_SCREW:
		m = &d->screw_material;
		b = 0.5 * P - 2.0 * d->flank_shift_screw_mm;
		depth = d->screw_radius_mm - d->screw_root_radius_mm;
		out->diameter_mm = 2.0 * d->screw_radius_mm;
		thinning = "/thinning/screw_um";
		break;
	case PRSM_THREAD_NUT:
		m = &d->nut_material;
		b = 0.5 * P - 2.0 * d->flank_shift_nut_mm;
		depth = d->nut_root_radius_mm - d->nut_radius_mm;
		out->diameter_mm = 2.0 * d->nut_radius_mm;
		out->internal = 1;
		out->outer_diameter_mm = 2.0 * nut_outer_radius_mm;
		thinning = "/thinning/nut_um";
		break;
	case PRSM_THREAD_ROLLER:
		m = &d->roller_material;
		b = 0.5 * P - 2.0 * d->flank_shift_roller_mm;
		depth = d->roller_radius_mm - d->roller_root_radius_mm;
		out->diameter_mm = 2.0 * d->roller_radius_mm;
		thinning = "/thinning/roller_um";
		break;
	default:
		return prsm_error_set(err, PRSM_EINVAL, NULL, "thread tooth: unknown part %d", part);
	}
	out->E_MPa = m->E_MPa;
	out->poisson = m->poisson;
	if (!(b > 0.0 && b < P) || !(depth > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, !(depth > 0.0) ? "/geometry" : thinning,
		                      "%s tooth: needs 0 < thickness at the pitch line (%g mm) < P (%g mm) and "
		                      "a root below the pitch line (depth %g mm)", part_name(part), b, P, depth);
	if (part != PRSM_THREAD_ROLLER) {
		straight_tooth(out, P, beta, b, depth);
		return 0;
	}
	/* roller: arc flank of radius R about the roller axis (docs/model/geometry-and-meshing.md); the tooth is
	 * b + 2 (sqrt(R^2 - u^2) - sqrt(R^2 - r_r^2)) thick at radius u */
	const double R = d->roller_arc_radius_mm, rr = d->roller_radius_mm;
	const double u_root = d->roller_root_radius_mm;
	if (!(R > rr) || !(u_root > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/geometry",
		                      "roller tooth: needs R (%g mm) > r_r (%g mm) and a positive root radius",
		                      R, rr);
	const double h0 = sqrt(R * R - rr * rr);
	double u = u_root;
	const double s = 0.5 * (P - b) + h0; /* sqrt(R^2 - u^2) where the groove closes */
	if (s < R)
		u = fmax(u_root, sqrt(R * R - s * s));
	out->load_thickness_mm = b;
	out->load_height_mm = rr - u;
	out->root_thickness_mm = fmin(b + 2.0 * (sqrt(R * R - u * u) - h0), P);
	return 0;
}

int prsm_compliance_thread(prsm_thread_compliance *out, const prsm_thread_tooth *tooth, int part,
                           const prsm_compliance_options *o, double share_mm, double ellipse_a_mm,
                           prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->part = part;
	out->width_rule = o->width_rule;
	out->calibration = o->calibration;
	out->tooth = *tooth;
	if (o->width_rule == PRSM_THREAD_COMPLIANCE_NONE)
		return 0;
	if (!(o->calibration >= 0.0) || !isfinite(o->calibration))
		return prsm_error_set(err, PRSM_EINVAL, "/thread_compliance/calibration",
		                      "thread compliance: calibration factor %g must be finite and >= 0",
		                      o->calibration);
	double w;
	switch (o->width_rule) {
	case PRSM_THREAD_WIDTH_SHARE:
		w = o->width_fraction * share_mm;
		break;
	case PRSM_THREAD_WIDTH_GIVEN:
		w = o->width_mm;
		break;
	case PRSM_THREAD_WIDTH_ELLIPSE:
		w = o->ellipse_factor * 2.0 * ellipse_a_mm;
		break;
	default:
		return prsm_error_set(err, PRSM_EINVAL, "/thread_compliance/width_rule",
		                      "thread compliance: unknown width rule %d", o->width_rule);
	}
	if (!(w > 0.0) || !isfinite(w))
		return prsm_error_set(err, PRSM_EINVAL, "/thread_compliance",
		                      "thread compliance: the %s thread's effective width %g mm must be "
		                      "positive", part_name(part), w);
	out->width_mm = w;
	int rc = prsm_compliance_yamamoto(&out->terms, tooth, o->negative_terms, err);
	if (rc)
		return rc;
	/* docs/model/kinematics-efficiency-stiffness-life.md: per-unit-width terms over the explicit width, times the calibration */
	out->compliance_mm_per_N = o->calibration * out->terms.sum_mm2_per_N / w;
	return 0;
}

int prsm_compliance_design(prsm_design_compliance *out, const prsm_design *d,
                           const prsm_compliance_options *opt, const double ellipse_a_mm[2],
                           prsm_error *err)
{
	const prsm_compliance_options defaults = PRSM_COMPLIANCE_OPTIONS_INIT;
	const prsm_compliance_options *o = opt ? opt : &defaults;
	memset(out, 0, sizeof *out);
	out->options = *o;
	out->nut_outer_radius_mm = prsm_compliance_nut_outer_radius_mm(o->nut_outer_radius_mm, d);
	out->options.nut_outer_radius_mm = out->nut_outer_radius_mm;
	if (o->width_rule == PRSM_THREAD_WIDTH_ELLIPSE && !ellipse_a_mm)
		return prsm_error_set(err, PRSM_EINVAL, "/thread_compliance/width_rule",
		                      "thread compliance: the ellipse rule needs the Hertz semi-axes");
	if (!(d->rollers > 0))
		return prsm_error_set(err, PRSM_EINVAL, "/geometry/rollers",
		                      "thread compliance: needs at least one roller (%d)", d->rollers);
	const double a_s = ellipse_a_mm ? ellipse_a_mm[0] : 0.0;
	const double a_n = ellipse_a_mm ? ellipse_a_mm[1] : 0.0;
	/* circumference share per contact at the pitch radius: Z contacts per turn on the screw
	 * and the nut, two (one per side) on a roller */
	const double Z = d->rollers;
	const double share_s = 2.0 * M_PI * d->screw_radius_mm / Z;
	const double share_n = 2.0 * M_PI * d->nut_radius_mm / Z;
	const double share_r = M_PI * d->roller_radius_mm;
	prsm_thread_tooth ts, tr, tn;
	int rc;
	if ((rc = prsm_compliance_tooth(&ts, d, PRSM_THREAD_SCREW, out->nut_outer_radius_mm, err)) ||
	    (rc = prsm_compliance_tooth(&tr, d, PRSM_THREAD_ROLLER, out->nut_outer_radius_mm, err)) ||
	    (rc = prsm_compliance_tooth(&tn, d, PRSM_THREAD_NUT, out->nut_outer_radius_mm, err)))
		return rc;
	if ((rc = prsm_compliance_thread(&out->screw, &ts, PRSM_THREAD_SCREW, o, share_s, a_s, err)) ||
	    (rc = prsm_compliance_thread(&out->roller_screw_side, &tr, PRSM_THREAD_ROLLER, o, share_r, a_s, err)) ||
	    (rc = prsm_compliance_thread(&out->roller_nut_side, &tr, PRSM_THREAD_ROLLER, o, share_r, a_n, err)) ||
	    (rc = prsm_compliance_thread(&out->nut, &tn, PRSM_THREAD_NUT, o, share_n, a_n, err)))
		return rc;
	out->screw_side_mm_per_N = out->screw.compliance_mm_per_N + out->roller_screw_side.compliance_mm_per_N;
	out->nut_side_mm_per_N = out->nut.compliance_mm_per_N + out->roller_nut_side.compliance_mm_per_N;
	out->negative_terms = out->screw.terms.negative_terms | out->roller_screw_side.terms.negative_terms |
	                      out->nut.terms.negative_terms;
	return 0;
}

double prsm_compliance_stretch(double length_mm, double E_MPa, double area_mm2)
{
	return length_mm / (E_MPa * area_mm2);
}

double prsm_compliance_nut_outer_radius_mm(double given_mm, const prsm_design *d)
{
	return isnan(given_mm) ? PRSM_NUT_OUTER_PER_PITCH_RADIUS * d->nut_radius_mm : given_mm;
}

int prsm_compliance_segments(prsm_segment_compliance *out, const prsm_design *d,
                             double nut_outer_radius_mm, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const double Ro = prsm_compliance_nut_outer_radius_mm(nut_outer_radius_mm, d);
	const double rs = d->screw_root_radius_mm, rr = d->roller_root_radius_mm;
	const double rn = d->nut_root_radius_mm;
	out->screw_area_mm2 = M_PI * rs * rs;
	out->roller_area_mm2 = M_PI * rr * rr;
	out->nut_area_mm2 = M_PI * (Ro * Ro - rn * rn);
	if (!(rs > 0.0) || !(rr > 0.0) || !(Ro > rn) || !(d->pitch_mm > 0.0) ||
	    !(d->screw_material.E_MPa > 0.0) || !(d->roller_material.E_MPa > 0.0) ||
	    !(d->nut_material.E_MPa > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/geometry",
		                      "segment stretch: needs positive root radii, a nut outer radius (%g mm) "
		                      "beyond the nut root (%g mm), P > 0 and positive moduli", Ro, rn);
	/* docs/model/kinematics-efficiency-stiffness-life.md spring chain: P / (E A) per pitch */
	out->screw_mm_per_N = prsm_compliance_stretch(d->pitch_mm, d->screw_material.E_MPa, out->screw_area_mm2);
	out->roller_mm_per_N = prsm_compliance_stretch(d->pitch_mm, d->roller_material.E_MPa, out->roller_area_mm2);
	out->nut_mm_per_N = prsm_compliance_stretch(d->pitch_mm, d->nut_material.E_MPa, out->nut_area_mm2);
	return 0;
}
