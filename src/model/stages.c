/*
 * stages.c: the multi-stage chain of docs/model/kinematics-efficiency-stiffness-life.md (see stages.h for the equations).
 */
#include "model/stages.h"

#include <math.h>
#include <string.h>

int prsm_stages_chain(prsm_chain *out, const prsm_chain_input *in, prsm_stage_torque_fn torque,
                      void *ctx, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const int K = in->stages;
	if (K < 1 || K > PRSM_STAGES_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/stages", "a chain has 1 to %d stages (got %d)",
		                      PRSM_STAGES_MAX, K);
	const double F = in->axial_load_N, w = fabs(in->screw_speed_rad_s);
	const double mss = in->spline_friction, mns = in->thrust_bearing_friction;
	if (!(F >= 0.0 && isfinite(F)) || !isfinite(w) || !(mss >= 0.0 && mss < 1.0) ||
	    !(mns >= 0.0 && mns < 1.0))
		return prsm_error_set(err, PRSM_EINVAL, "", "chain: load %g N, speed %g rad/s, frictions "
		                      "%g, %g out of range", F, in->screw_speed_rad_s, mss, mns);
	out->stages = K;
	for (int k = 0; k < K; k++) {
		if (!(in->lead_mm[k] > 0.0 && isfinite(in->lead_mm[k])))
			return prsm_error_set(err, PRSM_EINVAL, "/stages", "stage %d: lead %g mm", k + 1,
			                      in->lead_mm[k]);
		if (k > 0 && !(in->spline_radius_mm[k] > 0.0 && in->thrust_radius_mm[k] > 0.0 &&
		               isfinite(in->spline_radius_mm[k]) && isfinite(in->thrust_radius_mm[k])))
			return prsm_error_set(err, PRSM_EINVAL, "/couplings", "stage %d: spline radius %g mm, "
			                      "thrust bearing radius %g mm must be positive", k + 1,
			                      in->spline_radius_mm[k], in->thrust_radius_mm[k]);
		out->total_lead_mm += in->lead_mm[k];
	}
	/* docs/model/kinematics-efficiency-stiffness-life.md, backwards from the last stage (stages.h) */
	const double two_pi = 2.0 * M_PI;
	double M_next = 0.0, s_next = 0.0; /* M_{k+1}, N m; s_{k+1}, N */
	for (int k = K - 1; k >= 0; k--) {
		prsm_chain_stage *st = &out->stage[k];
		st->load_N = F + s_next;
		st->stage_torque_Nm = torque(ctx, k, st->load_N);
		if (!isfinite(st->stage_torque_Nm))
			return prsm_error_set(err, PRSM_EINVAL, "/stages", "stage %d: no input torque at %g N",
			                      k + 1, st->load_N);
		const double L_m = in->lead_mm[k] * 1e-3;
		if (k == 0) {
			st->spline_torque_Nm = st->stage_torque_Nm + M_next;
		} else {
			const double rss = in->spline_radius_mm[k] * 1e-3, rns = in->thrust_radius_mm[k] * 1e-3;
			const double lock = mns * mss * rns / rss;
			if (!(lock < 1.0))
				return prsm_error_set(err, PRSM_EINVAL, "/couplings",
				                      "stage %d: the spline and thrust bearing lock "
				                      "(mu_NS mu_SS r_NS / r_SS = %g >= 1)", k + 1, lock);
			st->spline_torque_Nm = (st->stage_torque_Nm + M_next + mns * rns * F) / (1.0 - lock);
			st->spline_force_N = mss * st->spline_torque_Nm / rss;
			st->thrust_load_N = F + st->spline_force_N;
			st->thrust_torque_Nm = mns * st->thrust_load_N * rns;
			st->spline_loss_W = st->spline_force_N * w * in->lead_mm[k - 1] * 1e-3 / two_pi;
			st->thrust_loss_W = st->thrust_torque_Nm * w;
		}
		st->stage_efficiency = st->stage_torque_Nm > 0.0 ? st->load_N * L_m / (two_pi * st->stage_torque_Nm) : 0.0;
		st->stage_loss_W = st->stage_torque_Nm * w - st->load_N * w * L_m / two_pi;
		M_next = st->spline_torque_Nm;
		s_next = st->spline_force_N;
	}
	double v = 0.0, harmonic = 0.0;
	for (int k = 0; k < K; k++) {
		v += w * in->lead_mm[k] / two_pi;
		out->stage[k].nut_speed_mm_s = v;
		harmonic += out->stage[k].stage_efficiency > 0.0 ? in->lead_mm[k] / out->stage[k].stage_efficiency : INFINITY;
	}
	out->harmonic_efficiency = out->total_lead_mm / harmonic;
	out->output_speed_mm_s = v;
	out->input_torque_Nm = out->stage[0].spline_torque_Nm;
	out->ideal_torque_Nm = F * out->total_lead_mm * 1e-3 / two_pi;
	out->efficiency = out->input_torque_Nm > 0.0 ? out->ideal_torque_Nm / out->input_torque_Nm : 0.0;
	out->input_power_W = out->input_torque_Nm * w;
	out->output_power_W = F * v * 1e-3;
	out->loss_power_W = out->input_power_W - out->output_power_W;
	return 0;
}
