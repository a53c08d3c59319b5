/*
 * kinematics.h: speed ratios and sliding velocities of a PRSM with the nut held (docs/model/kinematics-efficiency-stiffness-life.md).
 *
 * Ratios are per unit screw speed. The carrier ratio from the contact radii assumes rolling
 * without circumferential slip at the contact radii found by the contact solver: on the nut
 * side Omega = -k_c rho_n/u_n, on the screw side rho_s = k_c rho_s - Omega u_s. Sliding
 * velocities are of the roller relative to the screw (nut) at the contact, in the body's
 * (radial, tangential, axial) frame, in mm/s per rad/s of screw speed.
 *
 * The minimum-slip carrier ratio k* (docs/model §8.1, open question O1 of §8.9): with the nut
 * held and the roller spin tied to the carrier by the ring gear (omega_R = (1 - i_g) psi-dot,
 * i_g = r_n / r_r), the velocity of the roller's material point at the screw contact p relative
 * to the screw's is linear in the carrier and screw speeds,
 *   v = A psi-dot + B theta-dot,   A = z x c + (1 - i_g) z x (p - c),
 *                                  B = -z x p - hand (L / 2 pi) z,      c = (a, 0),
 * and isotropic friction (Coulomb or viscous) with nothing else acting on the carrier settles
 * it where A.v = 0, the smallest slip: k* = -(A.B) / |A|^2 (0.37369408 for case A, against
 * 0.37564 from the contact radii). A cage-speed measurement compares with k*; efficiency
 * cannot tell the two apart (2e-5 for case A). Both flanks give the same k*.
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
	double carrier_ratio_min_slip;   /* k* = -(A.B) / |A|^2 (docs/model §8.1): where friction
	                                    settles the carrier; compare cage-speed measurements */
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

/* The slip basis A, B of docs/model §8.1 (mm per rad, pair frame: screw axis at the origin,
 * roller axis at (a, 0)) at the screw-roller contact point (x_mm, y_mm) of design d, with the
 * ring-gear ratio i_g (r_n / r_r for a standard design). */
void prsm_kinematics_slip_basis(double A_mm[3], double B_mm[3], const prsm_design *d, double x_mm,
                                double y_mm, double ring_gear_ratio);

/* k* = -(A.B) / |A|^2 of a slip basis (docs/model §8.1), -. */
double prsm_kinematics_min_slip_ratio(const double A_mm[3], const double B_mm[3]);

#endif
