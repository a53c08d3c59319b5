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
	if (isnan(d->screw_radius_mm)) {
		/* docs/model/geometry-and-meshing.md: r_s = (n - 2) r_r needs n >= 3 */
		if (d->starts < 3)
			prsm_problems_add(errors, "/geometry/starts", "starts_min",
			                  "the standard rule r_s = (n-2) r_r needs at least 3 starts (got %d); "
			                  "give screw_radius_mm explicitly for fewer", d->starts);
		d->screw_radius_mm = (d->starts - 2) * rr;
	}
	if (isnan(d->nut_radius_mm))
		d->nut_radius_mm = d->screw_radius_mm + 2.0 * rr; /* pitch circles tangent */
	if (isnan(d->roller_arc_radius_mm))
		d->roller_arc_radius_mm = rr / sin(d->flank_angle_rad); /* R = r_r / sin beta */
	double ha = PRSM_ADDENDUM_PER_PITCH * P, hf = PRSM_DEDENDUM_PER_PITCH * P;
	if (isnan(d->screw_crest_radius_mm)) d->screw_crest_radius_mm = d->screw_radius_mm + ha;
	if (isnan(d->screw_root_radius_mm)) d->screw_root_radius_mm = d->screw_radius_mm - hf;
	if (isnan(d->roller_crest_radius_mm)) {
		/* keep the default crest inside the arc's domain u < R */
		double lim = rr + 0.9 * (d->roller_arc_radius_mm - rr);
		d->roller_crest_radius_mm = fmin(rr + ha, lim);
	}
	if (isnan(d->roller_root_radius_mm)) d->roller_root_radius_mm = rr - hf;
	if (isnan(d->nut_crest_radius_mm)) d->nut_crest_radius_mm = d->nut_radius_mm - ha;
	if (isnan(d->nut_root_radius_mm)) d->nut_root_radius_mm = d->nut_radius_mm + hf;
	return prsm_problems_total(errors) > before ? PRSM_EINVAL : 0;
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
		prsm_problems_add(errors, "/geometry/screw_root_radius_mm", "thread_extent",
		                  "screw needs 0 < root (%g) < pitch radius (%g) < crest (%g) mm",
		                  d->screw_root_radius_mm, rs, d->screw_crest_radius_mm);
	if (!isnan(d->nut_outer_radius_mm) && !(d->nut_outer_radius_mm > d->nut_root_radius_mm))
		prsm_problems_add(errors, "/geometry/nut_outer_radius_mm", "nut_wall",
		                  "nut outer radius %g mm must exceed the nut root radius %g mm",
		                  d->nut_outer_radius_mm, d->nut_root_radius_mm);
	if (!(d->roller_root_radius_mm > 0.0 && d->roller_root_radius_mm < rr && rr < d->roller_crest_radius_mm))
		prsm_problems_add(errors, "/geometry/roller_root_radius_mm", "thread_extent",
		                  "roller needs 0 < root (%g) < pitch radius (%g) < crest (%g) mm",
		                  d->roller_root_radius_mm, rr, d->roller_crest_radius_mm);
	if (!(d->nut_crest_radius_mm < rn && rn < d->nut_root_radius_mm))
		prsm_problems_add(errors, "/geometry/nut_crest_radius_mm", "thread_extent",
		                  "nut needs crest (%g) < pitch radius (%g) < root (%g) mm (internal thread)",
		                  d->nut_crest_radius_mm, rn, d->nut_root_radius_mm);
	if (!(R > rr))
		prsm_problems_add(errors, "/geometry/roller_arc_radius_mm", "arc_radius",
		                  "roller flank arc radius %g mm must exceed the roller pitch radius %g mm", R, rr);
	else if (!(d->roller_crest_radius_mm < R))
		prsm_problems_add(errors, "/geometry/roller_crest_radius_mm", "arc_domain",
		                  "roller crest radius %g mm must stay below the flank arc radius R = %g mm "
		                  "(the arc domain is too small for the thread height)",
		                  d->roller_crest_radius_mm, R);
	if (d->screw_crest_radius_mm + d->roller_root_radius_mm > a)
		prsm_problems_add(errors, "/geometry/screw_crest_radius_mm", "crest_clearance",
		                  "screw crest %g mm + roller root %g mm exceed the orbit radius a = %g mm",
		                  d->screw_crest_radius_mm, d->roller_root_radius_mm, a);
	if (d->nut_crest_radius_mm < a + d->roller_root_radius_mm && rn > rs + rr)
		prsm_problems_add(errors, "/geometry/nut_crest_radius_mm", "crest_clearance",
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
