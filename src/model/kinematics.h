/*
 * kinematics.h: speed ratios and sliding velocities of a PRSM with the nut held (docs/model/kinematics-efficiency-stiffness-life.md).
 *
 * Ratios are per unit screw speed. The carrier ratio from the contact radii assumes rolling
 * without circumferential slip at the contact radii found by the contact solver: on the nut
 * side Omega = -k_c rho_n/u_n, on the screw side rho_s = k_c rho_s - Omega u_s. Sliding
 * velocities are of the roller relative to the screw (nut) at the contact, in the body's
 * (radial, tangential, axial) frame, in mm/s per rad/s of screw speed.
 */
#ifndef PRSM_MODEL_KINEMATICS_H
#define PRSM_MODEL_KINEMATICS_H

#include "model/contact.h"
#include "model/design.h"

typedef struct {
	double carrier_ratio_ideal;      /* k_c = r_s / (2 (r_s + r_r)) */
	double roller_spin_ratio_ideal;  /* roller spin relative to the carrier, -(r_n/r_r) k_c */
	double roller_abs_ratio_ideal;   /* absolute roller spin, k_c + spin (= (1-n) k_c standard) */
	double carrier_ratio;            /* k_c from the contact radii */
	double roller_spin_ratio;        /* relative to the carrier, from the contact radii */
	double roller_abs_ratio;         /* absolute, from the contact radii */
	double nut_speed_mm_per_rad;     /* axial nut speed per screw speed, -hand L / 2 pi */
	double slip_screw[3];            /* roller minus screw at the screw contact, mm/rad */
	double slip_nut[3];              /* roller minus nut at the nut contact, mm/rad */
	double slip_ratio_screw;         /* |slip_screw| / |nut speed| (~ 1/sin beta) */
	double slip_ratio_nut;           /* |slip_nut| / |nut speed| (~ 0: rolling) */
} prsm_kinematics;

/* Ratios and slips from the two nominal contacts (screw pair and nut pair of
 * prsm_flank_pair_nominal). Returns 0. */
int prsm_kinematics_compute(prsm_kinematics *out, const prsm_design *d,
                            const prsm_contact *screw, const prsm_contact *nut);

#endif
