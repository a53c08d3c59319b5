/*
 * efficiency.h: sliding efficiency from the 3-D contact model (docs/model/kinematics-efficiency-stiffness-life.md).
 *
 * Every roller and thread carries the same axial force through a screw contact and a nut
 * contact. At each contact the normal force N acts along the flank normal and Coulomb friction
 * mu N opposes the sliding velocity of prsm_kinematics. Output power is the axial force times
 * the nut speed, the loss is the sum of mu N |v_slip| over the contacts, and the rolling bodies
 * (carrier, gears) are lossless, so
 *   eta  = F v / (F v + loss)          F = N (|n_z| - mu |s_z|)   (screw drives)
 *   eta' = 1 - loss / (F' v)           F' = N (|n_z| + mu |s_z|)  (nut drives)
 * with s the unit sliding direction. For beta = 45 deg this agrees with the closed forms
 * tan(beta)/tan(beta+rho) and tan(beta-rho)/tan(beta) to better than 1e-3.
 */
#ifndef PRSM_MODEL_EFFICIENCY_H
#define PRSM_MODEL_EFFICIENCY_H

#include "model/contact.h"
#include "model/design.h"
#include "model/kinematics.h"

typedef struct {
	double eta;                 /* direct efficiency (torque in, axial force out) */
	double eta_back;            /* back-driving efficiency (axial force in, torque out) */
	double eta_closed_form;     /* tan(beta) / tan(beta + atan mu) */
	double eta_back_closed_form;/* tan(beta - atan mu) / tan(beta), 0 when self-locking */
	double axial_per_normal_screw; /* axial force per unit normal force at the screw contact, drive */
	double axial_per_normal_nut;   /* |n_z| at the nut contact */
	double loss_per_axial_mm;   /* sliding loss per unit axial force, mm per rad of screw */
	/* at the design's operating point */
	double input_torque_Nm;     /* screw torque to drive the axial load */
	double ideal_torque_Nm;     /* F L / 2 pi: the lossless torque */
	double friction_torque_Nm;  /* input - ideal: all of it sliding at the screw contact here */
	double back_torque_Nm;      /* screw torque delivered when the load back-drives */
	double input_power_W, output_power_W, loss_power_W; /* at the operating speed */
} prsm_efficiency;

/* Sliding efficiency from the nominal contacts and kinematics. Returns 0. */
int prsm_efficiency_sliding(prsm_efficiency *out, const prsm_design *d, const prsm_kinematics *k,
                            const prsm_contact *screw, const prsm_contact *nut);

#endif
