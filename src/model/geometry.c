/*
 * geometry.c: standard-rule completion and the rule checks of docs/model/geometry-and-meshing.md.
 */
#include "model/geometry.h"

#include <math.h>

#include "model/compliance.h"
#include "model/life.h"

double prsm_design_lead_mm(const prsm_design *d)
{
	return d->starts * d->pitch_mm; /* docs/model/geometry-and-meshing.md: L = n P */
}

double prsm_design_screw_p(const prsm_design *d)
{
	return d->hand * d->starts * d->pitch_mm / (2.0 * M_PI);
}

double prsm_design_roller_p(const prsm_design *d)
{
	return d->hand * d->pitch_mm / (2.0 * M_PI);
}

double prsm_design_orbit_radius_mm(const prsm_design *d)
{
	return d->screw_radius_mm + d->roller_radius_mm;
}

void prsm_design_init(prsm_design *d)
{
	const prsm_material steel = {206000.0, 0.3, 7850.0};
	*d = (prsm_design){0};
	d->starts = 0;
	d->hand = PRSM_HAND_RIGHT;
	d->pitch_mm = NAN;
	d->flank_angle_rad = M_PI / 4.0;
	d->screw_radius_mm = NAN;
	d->roller_radius_mm = NAN;
	d->nut_radius_mm = NAN;
	d->roller_arc_radius_mm = NAN;
	d->screw_crest_radius_mm = d->screw_root_radius_mm = NAN;
	d->roller_crest_radius_mm = d->roller_root_radius_mm = NAN;
	d->nut_crest_radius_mm = d->nut_root_radius_mm = NAN;
	d->rollers = 0;
	d->engaged_threads = 0;
	d->running_clearance_mm = 0.1;
	d->flank_shift_screw_mm = d->flank_shift_roller_mm = d->flank_shift_nut_mm = 0.0;
	d->thinning_rule = PRSM_THINNING_EQUAL_GAPS;
	d->target_axial_clearance_mm = 0.0;
	d->screw_material = d->roller_material = d->nut_material = steel;
	d->mu_screw_roller = 0.05;
	d->mu_nut_roller = 0.05;
	d->axial_load_N = 0.0;
	d->screw_speed_rad_s = 0.0;
	d->nut_outer_radius_mm = NAN;
	/* docs/model/kinematics-efficiency-stiffness-life.md: drag and seal torques default 0; spin and gear mesh on */
	d->losses = (prsm_design_losses){1, 1, 0.05, 0, 0, 1.5, 20.0 * M_PI / 180.0, 0.0, 0.0, 0.0};
	/* docs/model/kinematics-efficiency-stiffness-life.md: Yamamoto with the circumference-share width, calibration 1, clamped */
	d->stiffness = (prsm_design_stiffness){PRSM_THREAD_WIDTH_SHARE, 1.0, 1.0, 1.0, 1.0,
	                                       PRSM_YAMAMOTO_CLAMP, PRSM_ENTRY_SAME_SIDE, 0, NAN};
	d->life = (prsm_design_life){0};
	d->life.p_allow_MPa = PRSM_STATIC_P_ALLOW_MPA;
	d->life.reliability_percent = 90;
	d->life.lp_material_factor = 1.0;
	d->life.fixity = PRSM_FIXITY_SUPPORTED_SUPPORTED;
}

int prsm_design_resolve(prsm_design *d, prsm_problems *errors)
{
	int before = prsm_problems_total(errors);
	double P = d->pitch_mm, rr = d->roller_radius_mm;
	d->derived = 0;
	if (isnan(d->screw_radius_mm)) {
		/* docs/model/geometry-and-meshing.md: r_s = (n - 2) r_r needs n >= 3 */
		if (d->starts < 3)
			prsm_problems_add(errors, "/geometry/starts", "starts_min",
			                  "the standard rule r_s = (n-2) r_r needs at least 3 starts (got %d); "
			                  "give screw_radius_mm explicitly for fewer", d->starts);
		d->screw_radius_mm = (d->starts - 2) * rr;
		d->derived |= PRSM_DERIVED_SCREW_RADIUS;
	}
	if (isnan(d->nut_radius_mm)) {
		d->nut_radius_mm = d->screw_radius_mm + 2.0 * rr; /* pitch circles tangent */
		d->derived |= PRSM_DERIVED_NUT_RADIUS;
	}
	if (isnan(d->roller_arc_radius_mm)) {
		d->roller_arc_radius_mm = rr / sin(d->flank_angle_rad); /* R = r_r / sin beta */
		d->derived |= PRSM_DERIVED_ARC_RADIUS;
	}
	double ha = PRSM_ADDENDUM_PER_PITCH * P, hf = PRSM_DEDENDUM_PER_PITCH * P;
	if (isnan(d->screw_crest_radius_mm)) {
		d->screw_crest_radius_mm = d->screw_radius_mm + ha;
		d->derived |= PRSM_DERIVED_SCREW_CREST;
	}
	if (isnan(d->screw_root_radius_mm)) {
		d->screw_root_radius_mm = d->screw_radius_mm - hf;
		d->derived |= PRSM_DERIVED_SCREW_ROOT;
	}
	if (isnan(d->roller_crest_radius_mm)) {
		/* keep the default crest inside the arc's domain u < R */
		double lim = rr + 0.9 * (d->roller_arc_radius_mm - rr);
		d->roller_crest_radius_mm = fmin(rr + ha, lim);
		d->derived |= PRSM_DERIVED_ROLLER_CREST;
	}
	if (isnan(d->roller_root_radius_mm)) {
		d->roller_root_radius_mm = rr - hf;
		d->derived |= PRSM_DERIVED_ROLLER_ROOT;
	}
	if (isnan(d->nut_crest_radius_mm)) {
		d->nut_crest_radius_mm = d->nut_radius_mm - ha;
		d->derived |= PRSM_DERIVED_NUT_CREST;
	}
	if (isnan(d->nut_root_radius_mm)) {
		d->nut_root_radius_mm = d->nut_radius_mm + hf;
		d->derived |= PRSM_DERIVED_NUT_ROOT;
	}
	return prsm_problems_total(errors) > before ? PRSM_EINVAL : 0;
}

/* The pointer of a thread-extent problem: the radius's own field when the bound that fails
 * involves a radius the document gave (root_bad: the root's, crest_bad: the crest's), else
 * pitch_mm, from which the default crest and root radii follow (geometry.h). */
static const char *extent_pointer(const prsm_design *d, int crest_bit, int root_bit, int crest_bad,
                                  int root_bad, const char *own)
{
	if ((root_bad && !(d->derived & root_bit)) || (crest_bad && !(d->derived & crest_bit)))
		return own;
	return "/geometry/pitch_mm";
}

/* A note for a problem of derived crest or root radii: which rule made them. */
static const char *extent_note(const prsm_design *d, int crest_bit, int root_bit)
{
	return (d->derived & (crest_bit | root_bit)) == (crest_bit | root_bit)
		       ? " (the default crest and root radii are the pitch radius + 0.25 P and - 0.30 P: "
		         "the pitch is too coarse for this radius, or give the crest and root radii)"
		       : "";
}

int prsm_geometry_z_max(double roller_crest_radius_mm, double running_clearance_mm,
                        double orbit_radius_mm)
{
	double s = (roller_crest_radius_mm + 0.5 * running_clearance_mm) / orbit_radius_mm;
	if (!(s > 0.0) || s >= 1.0)
		return s >= 1.0 ? 1 : 0;
	return (int)floor(M_PI / asin(s)); /* docs/model/geometry-and-meshing.md */
}

static int near(double a, double b)
{
	return fabs(a - b) <= 1e-9 * fmax(1.0, fabs(b));
}

int prsm_geometry_check(prsm_geometry *out, prsm_problems *warnings, prsm_problems *errors,
                        const prsm_design *d)
{
	int before = prsm_problems_total(errors);
	const double rs = d->screw_radius_mm, rr = d->roller_radius_mm, rn = d->nut_radius_mm;
	const double P = d->pitch_mm, n = d->starts, R = d->roller_arc_radius_mm;
	const double a = rs + rr;

	out->lead_mm = prsm_design_lead_mm(d);
	out->orbit_radius_mm = a;
	out->helix_screw_rad = atan(n * P / (2.0 * M_PI * rs));
	out->helix_roller_rad = atan(P / (2.0 * M_PI * rr));
	out->helix_nut_rad = atan(n * P / (2.0 * M_PI * rn));
	out->ring_gear_ratio = rn / rr;
	out->migration_mm_per_rad = P / (2.0 * M_PI) * (n - rn / rr); /* docs/model/geometry-and-meshing.md */
	out->z_max = prsm_geometry_z_max(d->roller_crest_radius_mm, d->running_clearance_mm, a);
	out->standard_rules = near(rs, (n - 2.0) * rr) && near(rn, n * rr);

	if (!(rs > 0.0))
		prsm_problems_add(errors, "/geometry/screw_radius_mm", "radius_positive",
		                  "screw pitch radius must be positive (got %g mm)", rs);
	if (!(rn > rs + rr))
		prsm_problems_add(errors, "/geometry/nut_radius_mm", "nut_radius",
		                  "nut pitch radius %g mm must exceed screw + roller radius %g mm", rn, rs + rr);
	if (!(d->screw_root_radius_mm > 0.0 && d->screw_root_radius_mm < rs && rs < d->screw_crest_radius_mm))
		prsm_problems_add(errors,
		                  extent_pointer(d, PRSM_DERIVED_SCREW_CREST, PRSM_DERIVED_SCREW_ROOT,
		                                 !(rs < d->screw_crest_radius_mm),
		                                 !(d->screw_root_radius_mm > 0.0 && d->screw_root_radius_mm < rs),
		                                 "/geometry/screw_root_radius_mm"),
		                  "thread_extent", "screw needs 0 < root (%g) < pitch radius (%g) < crest (%g) mm%s",
		                  d->screw_root_radius_mm, rs, d->screw_crest_radius_mm,
		                  extent_note(d, PRSM_DERIVED_SCREW_CREST, PRSM_DERIVED_SCREW_ROOT));
	if (!isnan(d->nut_outer_radius_mm) && !(d->nut_outer_radius_mm > d->nut_root_radius_mm))
		prsm_problems_add(errors, "/geometry/nut_outer_radius_mm", "nut_wall",
		                  "nut outer radius %g mm must exceed the nut root radius %g mm",
		                  d->nut_outer_radius_mm, d->nut_root_radius_mm);
	if (!(d->roller_root_radius_mm > 0.0 && d->roller_root_radius_mm < rr && rr < d->roller_crest_radius_mm))
		prsm_problems_add(errors,
		                  extent_pointer(d, PRSM_DERIVED_ROLLER_CREST, PRSM_DERIVED_ROLLER_ROOT,
		                                 !(rr < d->roller_crest_radius_mm),
		                                 !(d->roller_root_radius_mm > 0.0 && d->roller_root_radius_mm < rr),
		                                 "/geometry/roller_root_radius_mm"),
		                  "thread_extent", "roller needs 0 < root (%g) < pitch radius (%g) < crest (%g) mm%s",
		                  d->roller_root_radius_mm, rr, d->roller_crest_radius_mm,
		                  extent_note(d, PRSM_DERIVED_ROLLER_CREST, PRSM_DERIVED_ROLLER_ROOT));
	if (!(d->nut_crest_radius_mm < rn && rn < d->nut_root_radius_mm))
		prsm_problems_add(errors,
		                  extent_pointer(d, PRSM_DERIVED_NUT_CREST, PRSM_DERIVED_NUT_ROOT,
		                                 !(d->nut_crest_radius_mm < rn), !(rn < d->nut_root_radius_mm),
		                                 "/geometry/nut_crest_radius_mm"),
		                  "thread_extent", "nut needs crest (%g) < pitch radius (%g) < root (%g) mm (internal thread)%s",
		                  d->nut_crest_radius_mm, rn, d->nut_root_radius_mm,
		                  extent_note(d, PRSM_DERIVED_NUT_CREST, PRSM_DERIVED_NUT_ROOT));
	if (!(R > rr))
		prsm_problems_add(errors, "/geometry/roller_arc_radius_mm", "arc_radius",
		                  "roller flank arc radius %g mm must exceed the roller pitch radius %g mm", R, rr);
	else if (!(d->roller_crest_radius_mm < R))
		prsm_problems_add(errors, "/geometry/roller_crest_radius_mm", "arc_domain",
		                  "roller crest radius %g mm must stay below the flank arc radius R = %g mm "
		                  "(the arc domain is too small for the thread height)",
		                  d->roller_crest_radius_mm, R);
	if (d->screw_crest_radius_mm + d->roller_root_radius_mm > a)
		prsm_problems_add(errors,
		                  extent_pointer(d, PRSM_DERIVED_SCREW_CREST, PRSM_DERIVED_ROLLER_ROOT, 1, 1,
		                                 "/geometry/screw_crest_radius_mm"),
		                  "crest_clearance",
		                  "screw crest %g mm + roller root %g mm exceed the orbit radius a = %g mm",
		                  d->screw_crest_radius_mm, d->roller_root_radius_mm, a);
	if (d->nut_crest_radius_mm < a + d->roller_root_radius_mm && rn > rs + rr)
		prsm_problems_add(errors,
		                  extent_pointer(d, PRSM_DERIVED_NUT_CREST, PRSM_DERIVED_ROLLER_ROOT, 1, 1,
		                                 "/geometry/nut_crest_radius_mm"),
		                  "crest_clearance",
		                  "nut crest %g mm must be at least a + roller root = %g mm",
		                  d->nut_crest_radius_mm, a + d->roller_root_radius_mm);
	if (d->rollers > out->z_max)
		prsm_problems_add(errors, "/geometry/rollers", "z_max",
		                  "%d rollers do not fit: adjacent rollers touch above Z_max = %d "
		                  "(roller crest %g mm, running clearance %g mm, orbit radius %g mm)",
		                  d->rollers, out->z_max, d->roller_crest_radius_mm,
		                  d->running_clearance_mm, a);

	if (!near(rn, rs + 2.0 * rr))
		prsm_problems_add(warnings, "/geometry/nut_radius_mm", "annulus",
		                  "r_n = %g mm differs from r_s + 2 r_r = %g mm: the roller pitch circles do "
		                  "not touch both screw and nut; the nut-side gap carries the difference",
		                  rn, rs + 2.0 * rr);
	if (!near(rn, n * rr))
		prsm_problems_add(warnings, "/geometry/nut_radius_mm", "helix_match",
		                  "r_n = %g mm differs from n r_r = %g mm: roller and nut helix angles differ, "
		                  "and rollers drift axially by %.4g mm per carrier radian unless the ring gear "
		                  "ratio matches", rn, n * rr, out->migration_mm_per_rad);
	if (!near(rs, (n - 2.0) * rr))
		prsm_problems_add(warnings, "/geometry/screw_radius_mm", "standard_rule",
		                  "r_s = %g mm differs from the standard rule (n-2) r_r = %g mm", rs,
		                  (n - 2.0) * rr);
	return prsm_problems_total(errors) > before ? PRSM_EGEOMETRY : 0;
}

/* A radius, pitch, load or speed outside what real roller screws have, with the unit slip that
 * would explain it (geometry.h). */
static void implausible(prsm_problems *w, const char *pointer, const char *what, double v, double lo,
                        double hi, const char *unit)
{
	if (!(v < lo || v > hi))
		return;
	if (v > hi && v / 1000.0 >= lo && v / 1000.0 <= hi)
		prsm_problems_add(w, pointer, "implausible",
		                  "%g %s: a value in µm? %s is %g to %g %s in real roller screws (%g µm = %g %s)",
		                  v, unit, what, lo, hi, unit, v, v / 1000.0, unit);
	else if (v < lo && v * 25.4 >= lo && v * 25.4 <= hi)
		prsm_problems_add(w, pointer, "implausible",
		                  "%g %s: a value in inches? %s is %g to %g %s in real roller screws; %g in "
		                  "would be %g %s", v, unit, what, lo, hi, unit, v, v * 25.4, unit);
	else if (v < lo && v * 1000.0 >= lo && v * 1000.0 <= hi)
		prsm_problems_add(w, pointer, "implausible",
		                  "%g %s: a value in m? %s is %g to %g %s in real roller screws (%g m = %g %s)",
		                  v, unit, what, lo, hi, unit, v, v * 1000.0, unit);
	else
		prsm_problems_add(w, pointer, "implausible",
		                  "%g %s is outside the range of real roller screws (%s %g to %g %s): check "
		                  "the unit", v, unit, what, lo, hi, unit);
}

void prsm_geometry_plausibility(prsm_problems *warnings, const prsm_design *d)
{
	implausible(warnings, "/geometry/roller_radius_mm", "a roller pitch radius", d->roller_radius_mm,
	            PRSM_PLAUSIBLE_RADIUS_MIN_MM, PRSM_PLAUSIBLE_RADIUS_MAX_MM, "mm");
	if (!(d->derived & PRSM_DERIVED_SCREW_RADIUS))
		implausible(warnings, "/geometry/screw_radius_mm", "a screw pitch radius", d->screw_radius_mm,
		            PRSM_PLAUSIBLE_RADIUS_MIN_MM, PRSM_PLAUSIBLE_RADIUS_MAX_MM, "mm");
	if (!(d->derived & PRSM_DERIVED_NUT_RADIUS))
		implausible(warnings, "/geometry/nut_radius_mm", "a nut pitch radius", d->nut_radius_mm,
		            PRSM_PLAUSIBLE_RADIUS_MIN_MM, PRSM_PLAUSIBLE_RADIUS_MAX_MM, "mm");
	implausible(warnings, "/geometry/pitch_mm", "the pitch", d->pitch_mm, PRSM_PLAUSIBLE_PITCH_MIN_MM,
	            PRSM_PLAUSIBLE_PITCH_MAX_MM, "mm");
	const double F = fabs(d->axial_load_N), rpm = fabs(d->screw_speed_rad_s) * 30.0 / M_PI;
	if (F > PRSM_PLAUSIBLE_LOAD_MAX_N)
		prsm_problems_add(warnings, "/operating_point/axial_load_N", "implausible",
		                  "%g N is above the static ratings of the largest roller screws (about %g N): "
		                  "a value in mN, or in g?", F, PRSM_PLAUSIBLE_LOAD_MAX_N);
	if (rpm > PRSM_PLAUSIBLE_SPEED_MAX_RPM)
		prsm_problems_add(warnings, "/operating_point/screw_speed_rpm", "implausible",
		                  "%g rpm is above the speeds of real roller screws (at most about %g rpm): a "
		                  "value in rad/min or in mm/min?", rpm, PRSM_PLAUSIBLE_SPEED_MAX_RPM);
}
