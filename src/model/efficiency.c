/*
 * efficiency.c: sliding efficiency by power balance over the contacts (docs/model/kinematics-efficiency-stiffness-life.md).
 */
#include "model/efficiency.h"

#include <math.h>

#include "model/geometry.h"

int prsm_efficiency_sliding(prsm_efficiency *out, const prsm_design *d, const prsm_kinematics *k,
                            const prsm_contact *screw, const prsm_contact *nut)
{
	const double v = fabs(k->nut_speed_mm_per_rad); /* mm per rad of screw */
	const double mu_s = d->mu_screw_roller, mu_n = d->mu_nut_roller;
	const double slip_s = k->slip_ratio_screw * v, slip_n = k->slip_ratio_nut * v; /* mm/rad */
	const double sz = slip_s > 0.0 ? fabs(k->slip_screw[2]) / slip_s : 0.0;
	const double nz_s = fabs(screw->normal[2]), nz_n = fabs(nut->normal[2]);

	/* per unit normal force at the screw contact */
	const double F_drive = nz_s - mu_s * sz;
	const double F_back = nz_s + mu_s * sz;
	/* the nut contact carries the same axial force: N_n = F / |n_z,n| */
	const double loss_drive = mu_s * slip_s + mu_n * (F_drive / nz_n) * slip_n;
	const double loss_back = mu_s * slip_s + mu_n * (F_back / nz_n) * slip_n;

	out->eta = F_drive > 0.0 ? F_drive * v / (F_drive * v + loss_drive) : 0.0;
	out->eta_back = fmax(0.0, 1.0 - loss_back / (F_back * v));
	out->axial_per_normal_screw = F_drive;
	out->axial_per_normal_nut = nz_n;
	out->loss_per_axial_mm = F_drive > 0.0 ? loss_drive / F_drive : INFINITY;

	const double beta = d->flank_angle_rad, rho = atan(mu_s);
	out->eta_closed_form = beta + rho < M_PI / 2 ? tan(beta) / tan(beta + rho) : 0.0;
	out->eta_back_closed_form = beta > rho ? tan(beta - rho) / tan(beta) : 0.0;

	/* operating point: T = F L / (2 pi eta) (docs/model/kinematics-efficiency-stiffness-life.md), N mm -> N m */
	const double F = d->axial_load_N, L = prsm_design_lead_mm(d);
	out->ideal_torque_Nm = F * L / (2.0 * M_PI) * 1e-3;
	out->input_torque_Nm = out->eta > 0.0 ? out->ideal_torque_Nm / out->eta : INFINITY;
	out->friction_torque_Nm = out->input_torque_Nm - out->ideal_torque_Nm;
	out->back_torque_Nm = out->ideal_torque_Nm * out->eta_back;
	const double w = fabs(d->screw_speed_rad_s);
	out->input_power_W = out->input_torque_Nm * w;
	out->output_power_W = out->ideal_torque_Nm * w;
	out->loss_power_W = out->friction_torque_Nm * w;
	return 0;
}
