/*
 * analysis.c: the nominal analysis (docs/model/geometry-and-meshing.md, docs/model/kinematics-efficiency-stiffness-life.md).
 */
#include "model/analysis.h"

#include <math.h>
#include <string.h>

void prsm_analysis_solve_thinning(prsm_design *d, double g0_screw_mm, double g0_nut_mm)
{
	/* nominal play B = 2 (g_sr + g_nr); equal gaps g = B/4 on each side */
	const double g = 0.25 * d->target_axial_clearance_mm;
	d->flank_shift_screw_mm = g - g0_screw_mm;
	d->flank_shift_nut_mm = g - g0_nut_mm;
	d->flank_shift_roller_mm = 0.0;
}

static const char *edge_name(int edge)
{
	if (edge & PRSM_EDGE_ARC) return "off the roller's spherical flank (u >= R)";
	if (edge & PRSM_EDGE_ROLLER_CREST) return "beyond the roller crest";
	if (edge & PRSM_EDGE_ROLLER_ROOT) return "below the roller root";
	if (edge & PRSM_EDGE_BODY_CREST) return "beyond the crest of the screw or nut";
	return "beyond the root of the screw or nut";
}

static int solve_side(prsm_contact *out, const prsm_design *d, int side, prsm_error *err)
{
	prsm_flank_pair pair;
	prsm_flank_pair_nominal(&pair, d, side);
	int rc = prsm_contact_solve(out, &pair);
	const char *who = side == PRSM_SIDE_SCREW ? "screw-roller" : "nut-roller";
	if (rc == PRSM_EEDGE)
		return prsm_error_set(err, rc, "/geometry", "the nominal %s contact is an edge contact: %s "
		                      "(rho %.4f mm, u %.4f mm); change the crest/root radii or the flank angle",
		                      who, edge_name(out->edge), out->body_rho_mm, out->roller_u_mm);
	if (rc)
		/* the nominal flanks have no common normal near the pitch circles: not a working design */
		return prsm_error_set(err, PRSM_EGEOMETRY, "/geometry",
		                      "the nominal %s flanks have no contact point on the flanks (no common "
		                      "normal near the pitch circles; Newton left the roller arc): check the "
		                      "flank angle and the radii", who);
	return 0;
}

int prsm_analysis_nominal(prsm_analysis *out, prsm_design *d, prsm_problems *warnings,
                          prsm_error *err)
{
	int rc;
	memset(out, 0, sizeof *out);
	/* derived geometry only: the design was checked before (its rule warnings are the caller's) */
	prsm_problems scratch;
	prsm_problems_init(&scratch);
	prsm_geometry_check(&out->geometry, &scratch, &scratch, d);

	/* G0: gaps with no flank shifts (docs/model/geometry-and-meshing.md, "Tooth thickness and backlash") */
	prsm_design bare = *d;
	bare.flank_shift_screw_mm = bare.flank_shift_roller_mm = bare.flank_shift_nut_mm = 0.0;
	prsm_contact c0;
	if ((rc = solve_side(&c0, &bare, PRSM_SIDE_SCREW, err)))
		return rc;
	out->gap0_screw_mm = c0.gap_mm;
	if ((rc = solve_side(&c0, &bare, PRSM_SIDE_NUT, err)))
		return rc;
	out->gap0_nut_mm = c0.gap_mm;
	if (d->thinning_rule == PRSM_THINNING_EQUAL_GAPS)
		prsm_analysis_solve_thinning(d, out->gap0_screw_mm, out->gap0_nut_mm);

	if ((rc = solve_side(&out->screw, d, PRSM_SIDE_SCREW, err)) ||
	    (rc = solve_side(&out->nut, d, PRSM_SIDE_NUT, err)))
		return rc;
	out->backlash_mm = 2.0 * (out->screw.gap_mm + out->nut.gap_mm);
	if (out->screw.gap_mm < 0.0 || out->nut.gap_mm < 0.0)
		prsm_problems_add(warnings, "/thinning", "interference",
		                  "the teeth interfere nominally (screw-roller gap %.2f um, nut-roller gap "
		                  "%.2f um): thin the teeth or set target_axial_clearance_um",
		                  out->screw.gap_mm * 1e3, out->nut.gap_mm * 1e3);

	const double beta = d->flank_angle_rad, R = d->roller_arc_radius_mm;
	out->offset_rule_mm = d->pitch_mm / (M_PI * tan(beta));
	out->curvature_estimate_screw[0] = 1.0 / R;
	out->curvature_estimate_screw[1] = 1.0 / R + sin(beta) / out->screw.body_rho_mm;
	out->curvature_estimate_nut[0] = 1.0 / R;
	out->curvature_estimate_nut[1] = 1.0 / R - sin(beta) / out->nut.body_rho_mm;

	prsm_kinematics_compute(&out->kinematics, d, &out->screw, &out->nut);
	prsm_efficiency_sliding(&out->efficiency, d, &out->kinematics, &out->screw, &out->nut);

	/* Hertz at the operating load shared equally over rollers and threads (docs/model/kinematics-efficiency-stiffness-life.md) */
	out->contacts_sharing = d->rollers * d->engaged_threads;
	out->axial_load_per_contact_N = d->axial_load_N / out->contacts_sharing;
	const double Qs = out->axial_load_per_contact_N / fabs(out->screw.normal[2]);
	const double Qn = out->axial_load_per_contact_N / fabs(out->nut.normal[2]);
	const prsm_material *ms = &d->screw_material, *mr = &d->roller_material, *mn = &d->nut_material;
	if (prsm_hertz_solve(&out->hertz_screw, out->screw.curvature_per_mm[0], out->screw.curvature_per_mm[1],
	                     ms->E_MPa, ms->poisson, mr->E_MPa, mr->poisson, Qs) ||
	    prsm_hertz_solve(&out->hertz_nut, out->nut.curvature_per_mm[0], out->nut.curvature_per_mm[1],
	                     mn->E_MPa, mn->poisson, mr->E_MPa, mr->poisson, Qn))
		return prsm_error_set(err, PRSM_EGEOMETRY, "/geometry",
		                      "a contact has non-positive relative curvature: the flanks conform or "
		                      "diverge, and Hertz theory does not apply");
	return 0;
}
