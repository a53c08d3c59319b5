/*
 * analysis.h: the nominal analysis of one design, everything `prsm analyze` reports that
 * depends on no error set: contacts and gaps (docs/model/geometry-and-meshing.md), backlash, kinematics and sliding
 * efficiency (§5), Hertz contact at the operating load shared equally (§6).
 */
#ifndef PRSM_MODEL_ANALYSIS_H
#define PRSM_MODEL_ANALYSIS_H

#include "model/contact.h"
#include "model/design.h"
#include "model/efficiency.h"
#include "model/geometry.h"
#include "model/hertz.h"
#include "model/kinematics.h"
#include "util/error.h"
#include "util/problems.h"

typedef struct {
	prsm_geometry geometry;
	double gap0_screw_mm, gap0_nut_mm; /* flank gaps with no thinning (G0, docs/model/geometry-and-meshing.md) */
	prsm_contact screw, nut;           /* contacts with the design's flank shifts */
	double backlash_mm;                /* nominal axial play of nut on screw, both directions */
	double offset_rule_mm;             /* P cot(beta) / pi, the rule of thumb for y_c */
	double curvature_estimate_screw[2];/* (1/R, 1/R + sin beta / rho_s), 1/mm */
	double curvature_estimate_nut[2];  /* (1/R, 1/R - sin beta / rho_n), 1/mm */
	prsm_kinematics kinematics;
	prsm_efficiency efficiency;
	int contacts_sharing;              /* Z n_t: contacts on each side sharing the load */
	double axial_load_per_contact_N;   /* F / (Z n_t) */
	prsm_hertz hertz_screw, hertz_nut; /* at the operating load, shared equally */
} prsm_analysis;

/* Solve the flank shifts of a target clearance (equal gaps on both sides, roller unthinned):
 * t_s = B/4 - G0_sr, t_n = B/4 - G0_nr, t_r = 0. Exact, since G is affine in t.
 * g0_* are the gaps with zero shifts. */
void prsm_analysis_solve_thinning(prsm_design *d, double g0_screw_mm, double g0_nut_mm);

/* Nominal analysis of a resolved, checked design (prsm_geometry_check reported its rule
 * warnings; warnings here gets only what the analysis finds, e.g. interfering teeth). When
 * d->thinning_rule asks for it the flank shifts are solved and written back into d.
 * Returns 0, PRSM_EEDGE (a nominal contact is off its flank: err names it) or PRSM_EGEOMETRY
 * (no contact point at all, or a contact where Hertz theory does not apply). */
int prsm_analysis_nominal(prsm_analysis *out, prsm_design *d, prsm_problems *warnings,
                          prsm_error *err);

#endif
