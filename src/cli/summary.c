/*
 * summary.c: the engineer's one-page text summary of `prsm analyze --format text` (the
 * documents are io/'s business; printing for a person is the command line's).
 */
#include "cli/summary.h"

#include <math.h>

#include "io/analysis_json.h"
#include "model/geometry.h"
#include "model/life.h"
#include "util/version.h"

#define DEG (180.0 / M_PI)                  /* degrees per radian */
#define RPM_PER_RAD_S (60.0 / (2.0 * M_PI)) /* rpm per rad/s */
#define UM 1e3                              /* um per mm */

static void print_analysis(FILE *out, const prsm_analysis *a, const prsm_design *d,
                                 const prsm_performance *perf, const prsm_problems *warnings)
{
	const prsm_geometry *g = &a->geometry;
	const prsm_kinematics *k = &a->kinematics;
	const double F = fabs(d->axial_load_N), rpm = d->screw_speed_rad_s * RPM_PER_RAD_S;
	fprintf(out, "PRSM analysis (prsm %s, %s)\n", PRSM_VERSION, PRSM_MODEL_VERSION);
	fprintf(out, "Operating point: %.6g N axial, %.6g rpm\n\n", F, rpm);
	fprintf(out, "Geometry\n");
	fprintf(out, "  starts %d (%s hand), pitch %.4g mm, lead %.4g mm, flank half-angle %.4g deg\n",
	        d->starts, d->hand == PRSM_HAND_LEFT ? "left" : "right", d->pitch_mm, g->lead_mm,
	        d->flank_angle_rad * DEG);
	fprintf(out, "  pitch radii: screw %.4f, roller %.4f, nut %.4f mm; orbit %.4f mm; R %.4f mm\n",
	        d->screw_radius_mm, d->roller_radius_mm, d->nut_radius_mm, g->orbit_radius_mm,
	        d->roller_arc_radius_mm);
	fprintf(out, "  helix angles: screw %.4f, roller %.4f, nut %.4f deg\n", g->helix_screw_rad * DEG,
	        g->helix_roller_rad * DEG, g->helix_nut_rad * DEG);
	fprintf(out, "  rollers %d of Z_max %d, engaged threads %d, nominal backlash %.3f um\n\n",
	        d->rollers, g->z_max, d->engaged_threads, a->backlash_mm * 1e3);
	fprintf(out, "Contacts                     screw-roller     nut-roller\n");
	fprintf(out, "  gap (um)                   %10.3f     %10.3f\n", a->screw.gap_mm * 1e3,
	        a->nut.gap_mm * 1e3);
	fprintf(out, "  contact radius body (mm)   %10.4f     %10.4f\n", a->screw.body_rho_mm, a->nut.body_rho_mm);
	fprintf(out, "  p_max equal sharing (MPa)  %10.1f     %10.1f\n", a->hertz_screw.p_max_MPa,
	        a->hertz_nut.p_max_MPa);
	if (perf && F > 0.0)
		fprintf(out, "  p_max most loaded (MPa)    %10.1f     %10.1f   (thread %d / %d)\n",
		        perf->dist.side[0].p_max_MPa, perf->dist.side[1].p_max_MPa,
		        perf->dist.side[0].max_index + 1, perf->dist.side[1].max_index + 1);
	fprintf(out, "\nKinematics (nut held): carrier ratio %.5f (ideal %.5f), roller spin %.5f, slip %.4f x v\n\n",
	        k->carrier_ratio, k->carrier_ratio_ideal, k->roller_spin_ratio, k->slip_ratio_screw);
	if (!perf) {
		const prsm_efficiency *e = &a->efficiency;
		fprintf(out, "Efficiency (sliding only, mu %.3g): eta %.4f, back-driving %.4f\n\n",
		        d->mu_screw_roller, e->eta, e->eta_back);
	} else {
		const prsm_losses_result *l = &perf->losses;
		fprintf(out, "Efficiency: eta %.4f, back-driving %.4f%s (sliding only %.4f / %.4f; closed form %.4f)\n",
		        l->eta, l->eta_back, (l->flags & PRSM_LOSSES_SELF_LOCKING) ? " (self-locking)" : "",
		        l->eta_slide, l->eta_back_slide, l->eta_closed_form);
		fprintf(out, "  input torque %.4g N m = ideal %.4g + sliding %.4g + spin %.4g + gear %.3g + drag %.3g + seal %.3g\n",
		        l->input_torque_Nm, l->ideal_torque_Nm, l->sliding_torque_Nm, l->spin_torque_Nm,
		        l->gear_torque_Nm, l->drag_torque_Nm, l->seal_torque_Nm);
		fprintf(out, "  power in %.4g W, out %.4g W, loss %.4g W\n\n", l->input_power_W, l->output_power_W,
		        l->loss_power_W);
		const prsm_design_compliance *c = &perf->compliance;
		fprintf(out, "Stiffness and load distribution (%s entry)\n",
		        d->stiffness.load_entry == PRSM_ENTRY_OPPOSITE_SIDE ? "opposite-side" : "same-side");
		if (c->options.width_rule == PRSM_THREAD_COMPLIANCE_NONE)
			fprintf(out, "  thread compliance: none (rigid threads)\n");
		else
			fprintf(out, "  thread compliance: Yamamoto, width %s, calibration %.3g: screw side %.4g, nut side %.4g um/kN per contact\n",
			        c->options.width_rule == PRSM_THREAD_WIDTH_SHARE ? "share" :
			        c->options.width_rule == PRSM_THREAD_WIDTH_GIVEN ? "given" : "ellipse",
			        c->options.calibration, c->screw_side_mm_per_N * 1e6, c->nut_side_mm_per_N * 1e6);
		if (F > 0.0) {
			fprintf(out, "  axial stiffness %.4g N/um at %.6g N (approach %.3f um)\n", perf->stiffness_N_per_um,
			        F, perf->dist.approach_mm * 1e3);
			fprintf(out, "  max/mean thread load: screw side %.3f, nut side %.3f\n",
			        perf->dist.side[0].max_over_mean, perf->dist.side[1].max_over_mean);
			fprintf(out, "  thread loads per roller, screw side (N):");
			for (int i = 0; i < perf->threads && i < 12; i++)
				fprintf(out, " %.4g", perf->thread_load_screw_N[i]);
			fprintf(out, "%s\n", perf->threads > 12 ? " ..." : "");
		} else {
			fprintf(out, "  no load: stiffness not defined (Hertz contacts have none at zero load)\n");
		}
		fprintf(out, "\nCapacity and life\n");
		fprintf(out, "  C_0a %.5g N at p_allow %.0f MPa (static safety %.3g); C_a %.5g N (L-P, distribution factor %.3f)\n",
		        perf->C0a_N, d->life.p_allow_MPa, perf->static_safety, perf->dynamic.C_a_N,
		        perf->distribution_factor);
		if (perf->C0a_truncation_limited)
			fprintf(out, "  C_0a limited by the contact-ellipse truncation (%.5g N at p_allow alone)\n",
			        perf->C0a_pressure_N);
		fprintf(out, "  makers' convention (equal sharing): C_0a %.5g N, C_a %.5g N, C_0a/C_a %.3f; "
		        "load distribution: C_0a/C_a %.3f\n", perf->makers.C0a_N, perf->makers.C_a_N,
		        perf->makers.C0a_over_C_a, perf->C0a_over_C_a);
		if (perf->equivalent_load_N > 0.0 && perf->life.hours > 0.0)
			fprintf(out, "  L%d life at %.5g N equivalent: %.4g revolutions, %.4g h, %.4g km\n",
			        100 - perf->life.reliability_percent, perf->equivalent_load_N, perf->life.revolutions,
			        perf->life.hours, perf->life.distance_km);
		else if (perf->equivalent_load_N > 0.0) /* the JSON's hours is null: no time at 0 rpm */
			fprintf(out, "  L%d life at %.5g N equivalent: %.4g revolutions, %.4g km; hours not rated "
			        "at 0 rpm\n", 100 - perf->life.reliability_percent, perf->equivalent_load_N,
			        perf->life.revolutions, perf->life.distance_km);
		if (perf->has_column)
			fprintf(out, "  column (%.5g mm): critical speed %.5g rpm (catalogue %.5g), buckling %.5g N\n",
			        perf->column.free_length_mm, perf->column.critical_speed_rpm,
			        perf->column.catalogue_speed_rpm, perf->column.buckling_load_N);
		fprintf(out, "\n");
	}
	fprintf(out, "Warnings: %d\n", prsm_problems_total(warnings));
	for (int i = 0; i < warnings->count; i++)
		fprintf(out, "  %s: %s\n", warnings->items[i].pointer, warnings->items[i].message);
}

static void print_assembly(FILE *out, const prsm_assembly_report *r, const prsm_assembly *as)
{
	fprintf(out, "\nErrors and assembly (%s mode; docs/assembly-model.md)\n",
	        r->mode == PRSM_MODE_EXACT ? "exact" : "linear");
	fprintf(out, "  backlash at theta 0 (um)     %10.3f  (+ %.3f, - %.3f)\n", r->backlash_mm * UM,
	        r->backlash_plus_mm * UM, r->backlash_minus_mm * UM);
	fprintf(out, "  backlash over a turn (um)    %10.3f .. %.3f, mean %.3f\n", r->backlash_min_mm * UM,
	        r->backlash_max_mm * UM, r->backlash_mean_mm * UM);
	if (as->design.axial_load_N > 0.0) {
		fprintf(out, "  load sharing factor          %10.4f  (worst over a turn %.4f), %d of %d rollers loaded\n",
		        r->operating.sharing_factor, r->sharing_factor_max, r->operating.loaded_rollers, as->rollers);
		fprintf(out, "  axial stiffness (N/um)       %10.1f  (%.3f of nominal %.1f)\n",
		        r->operating.stiffness_N_per_mm / UM, r->stiffness_ratio, as->nominal_stiffness_N_per_mm / UM);
	}
	fprintf(out, "  TE at %g N over a turn (um)  p-p %.4f, rms %.4f\n", r->measuring_load_N,
	        r->te_revolution_pp_mm * UM, r->te_revolution_rms_mm * UM);
	if (r->has_stroke)
		fprintf(out, "  TE over %g mm (um)           p-p %.4f, lead deviation %.3f um/300 mm\n", r->stroke_mm,
		        r->te_stroke_pp_mm * UM, r->lead_deviation * 300.0 * UM);
	fprintf(out, "  TE spectrum peak             %.4f /rev, %.4f um\n", r->peak_frequency_per_rev,
	        r->peak_amplitude_mm * UM);
	if (r->edge_contacts || r->failed_contacts)
		fprintf(out, "  contacts off their flanks: %d edge, %d failed\n", r->edge_contacts, r->failed_contacts);
}

static void print_multistage(FILE *out, const prsm_io_multistage *m,
                                   const prsm_performance *perf, const prsm_problems *warnings)
{
	const prsm_chain *c = &m->chain;
	const prsm_chain_input *in = &m->chain_input;
	fprintf(out, "Multi-stage PRSM, %d stages\n", c->stages);
	fprintf(out, "  load %.6g N on the last nut, screw speed %.6g rpm; couplings: spline mu %.3g, thrust bearing mu %.3g\n",
	        in->axial_load_N, in->screw_speed_rad_s * RPM_PER_RAD_S, in->spline_friction,
	        in->thrust_bearing_friction);
	fprintf(out, "  output speed %.5g mm/s (lead sum %.5g mm); input torque %.5g N m; chain efficiency %.4f (%.4f with frictionless couplings)\n\n",
	        c->output_speed_mm_s, c->total_lead_mm, c->input_torque_Nm, c->efficiency,
	        c->harmonic_efficiency);
	fprintf(out, "  stage  load N     torque N m  eta     carrier  spline N  thrust N m\n");
	for (int k = 0; k < c->stages; k++) {
		const prsm_chain_stage *st = &c->stage[k];
		fprintf(out, "  %5d  %9.6g  %10.5g  %.4f  %.5f  %8.4g  %10.4g\n", k + 1, st->load_N,
		        st->stage_torque_Nm, st->stage_efficiency, m->analysis[k].kinematics.carrier_ratio,
		        st->spline_force_N, st->thrust_torque_Nm);
	}
	fprintf(out, "\n");
	prsm_problems none;
	prsm_problems_init(&none);
	for (int k = 0; k < m->stages; k++) {
		fprintf(out, "---- stage %d ----\n", k + 1);
		print_analysis(out, &m->analysis[k], &m->design[k], &perf[k], &none);
		fprintf(out, "\n");
	}
	fprintf(out, "Warnings: %d\n", prsm_problems_total(warnings));
	for (int i = 0; i < warnings->count; i++)
		fprintf(out, "  %s: %s\n", warnings->items[i].pointer, warnings->items[i].message);
}

void prsm_cli_print_analyze(FILE *out, const prsm_analyze_request *rq,
                                const prsm_problems *warnings)
{
	if (rq->multistage) {
		print_multistage(out, rq->ms, rq->ms_perf, warnings);
		return;
	}
	print_analysis(out, &rq->a, &rq->d, &rq->perf, warnings);
	if (rq->with_errors)
		print_assembly(out, &rq->report, &rq->as);
}
