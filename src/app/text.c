/*
 * text.c: the text summaries of a start-up transient, a vibration analysis and a calibration
 * (see text.h; docs/dynamics.md, docs/vibration.md, docs/measured-data.md).
 */
#include "app/text.h"

#include <math.h>
#include <string.h>

#include "util/error.h"

#define KG_MM2 1e6          /* kg m^2 -> kg mm^2 */
#define DEG (180.0 / M_PI)  /* rad -> deg */
#define UM 1e6              /* m -> um */

/* The names the result schema (schemas/dynamics-result.schema.json) gives these enums. */
static const char *const shape_names[] = {"step", "ramp", "sine"};
static const char *const friction_names[] = {"coulomb", "viscous", "stribeck"};
static const char *const losses_names[] = {"statics", "sliding_only"};
static const char *const class_names[] = {"periodic", "non_periodic", "quasi_periodic", "chaotic", "failed"};
static const char *const clock_names[] = {"auto", "mesh", "te"};
static const char *const obs_names[] = {"mesh_deflection", "mesh_rate", "mesh_force",
                                        "axial_deflection", "axial_rate", "thread_force"};
static const char *const branch_names[] = {"both", "gear", "axial"};
static const char *const eig_kind_names[] = {"rigid", "real", "oscillatory"};

static const char *name_of(const char *const *names, int n, int v)
{
	return v >= 0 && v < n ? names[v] : "unknown";
}
#define NAME(names, v) name_of(names, (int)(sizeof names / sizeof names[0]), (v))

static int axial_observable(int obs)
{
	return obs == PRSM_VIB_OBS_AXIAL_DEFLECTION || obs == PRSM_VIB_OBS_AXIAL_RATE || obs == PRSM_VIB_OBS_THREAD_FORCE;
}

static size_t failed_points(const prsm_vib_sweep *s)
{
	size_t n = 0;
	for (size_t k = 0; k < s->points; k++)
		n += s->point[k].classification == PRSM_VIB_FAILED;
	return n;
}

/* ---- a start-up transient ---- */

int prsm_app_text_transient(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r, const prsm_problems *warnings)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	const prsm_dyn_settled *s = &r->settled;
	const int K = r->stages;
	const int torque = o->input.kind == PRSM_DYN_INPUT_TORQUE;
	fprintf(f, "Start-up transient (docs/dynamics.md), %d stage%s, %s input %g %s (%s), load %g N, %s friction, "
	        "losses %s\n", K, K > 1 ? "s" : "", torque ? "torque" : "speed", o->input.signal.value,
	        torque ? "N m" : "rad/s", NAME(shape_names, o->input.signal.shape), o->load.value,
	        NAME(friction_names, o->friction.model), NAME(losses_names, o->losses));
	fprintf(f, "  simulated %g s, %zu output times, %ld steps\n", o->time.end_s, r->points, r->steps);
	if (r->points > 0)
		fprintf(f, "  at t = 0+: input torque %.7g N m, efficiency %.7g\n", r->point[0].input_torque_Nm,
		        r->point[0].efficiency);
	if (s->defined) {
		fprintf(f, "  settled: screw %.7g rad/s, input torque %.7g N m, efficiency %.7g (statics %.7g)%s\n",
		        s->screw_speed_rad_s, s->input_torque_Nm, s->efficiency, s->efficiency_statics,
		        s->at_rest ? ", at rest" : "");
	} else {
		fprintf(f, "  settled: none (no speed balances the motor torque: the screw runs away)\n");
	}
	if (torque)
		fprintf(f, "  screw speed reaches 50 / 90 / 99 %% of settled at %.6g / %.6g / %.6g s\n",
		        r->speed_time_to_share_s[0], r->speed_time_to_share_s[1], r->speed_time_to_share_s[2]);
	for (int k = 0; k < K; k++) {
		const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, k);
		fprintf(f, "  stage %d: k* %.8g (statics contact-radius ratio %.8g), settled carrier ratio %.8g,\n"
		        "           50 / 90 / 99 %% at %.6g / %.6g / %.6g s, J_psi %.6g kg mm^2\n", k + 1,
		        p->carrier_ratio_min_slip, p->carrier_ratio_statics, s->carrier_ratio[k],
		        r->carrier_time_to_share_s[k][0], r->carrier_time_to_share_s[k][1], r->carrier_time_to_share_s[k][2],
		        p->carrier_side_inertia_kg_m2 * KG_MM2);
	}
	fprintf(f, "  checks: power balance %.3g of input (limit %g), Newton-Euler %.3g (limit %g)\n",
	        r->max_power_balance_relative, PRSM_IO_DYN_POWER_BALANCE_LIMIT, r->max_newton_euler_residual,
	        PRSM_IO_DYN_NEWTON_EULER_LIMIT);
	for (int i = 0; warnings && i < warnings->count; i++)
		fprintf(f, "  warning: %s: %s\n", warnings->items[i].pointer, warnings->items[i].message);
	return ferror(f) ? PRSM_EIO : 0;
}

/* ---- a vibration analysis ---- */

static void text_sweep_summary(FILE *f, const prsm_vib_sweep *s, const char *par_name, double from_engine)
{
	for (int dir = 1; dir >= -1; dir -= 2) {
		fprintf(f, "  sweep %s:", dir > 0 ? "up" : "down");
		int prev_class = -1, prev_period = -1, n = 0;
		for (size_t k = 0; k < s->points; k++) {
			const prsm_vib_sweep_point *p = &s->point[k];
			if (p->direction != dir)
				continue;
			if (p->classification != prev_class || p->period != prev_period) {
				if (n++ % 4 == 0)
					fprintf(f, "\n   ");
				if (p->classification == PRSM_VIB_PERIODIC)
					fprintf(f, " from %s %.6g period %d;", par_name, p->parameter * from_engine, p->period);
				else
					fprintf(f, " from %s %.6g %s;", par_name, p->parameter * from_engine,
					        NAME(class_names, p->classification));
				prev_class = p->classification;
				prev_period = p->period;
			}
		}
		fputc('\n', f);
	}
}

int prsm_app_text_vibration(FILE *f, const prsm_io_vib_request *q, const prsm_vib_model *m, const prsm_io_vib_result *r,
                            const prsm_problems *warnings)
{
	const prsm_vib_params *P = prsm_vib_model_params(m);
	const int pair = P->kind == PRSM_VIB_GEAR_PAIR;
	if (pair) {
		const prsm_vib_gear_pair *g = &P->gear_pair;
		fprintf(f, "Gear pair (docs/vibration.md), %s: zeta %g, f_m %g, epsilon %g, kappa %g, eps_alpha %g",
		        prsm_io_dynamics_analysis_name(q->analysis), g->damping_ratio, g->mean_force, g->mesh_error,
		        g->stiffness_variation, g->contact_ratio);
		const int swept = q->analysis == PRSM_IO_DYN_FREQUENCY_RESPONSE || q->analysis == PRSM_IO_DYN_SWEEP;
		if (swept)
			fprintf(f, ", %s swept from %g to %g\n", prsm_io_sweep_parameter_name(q->sweep.parameter), q->sweep.from,
			        q->sweep.to);
		else
			fprintf(f, ", Omega %g\n", g->frequency_ratio);
	} else {
		fprintf(f, "Reduced vibration model (docs/vibration.md), %s: %d rollers, branches %s, screw %.6g rad/s, "
		        "omega_e %.6g, F_0 %g N\n", prsm_io_dynamics_analysis_name(q->analysis), P->rollers,
		        NAME(branch_names, P->branches), P->screw_speed_rad_s, P->frequency_ratio, P->axial_load_N);
		fprintf(f, "  k* %.8g, mesh %.6g Hz, roller mode %.6g Hz, axial %.6g Hz; k_a %.6g N/um, b_a %.6g um, "
		        "b_g %.6g um, e_g %.6g um, %d TE lines\n", P->carrier_ratio, P->mesh_frequency_rad_s / (2.0 * M_PI),
		        P->reference_frequency_rad_s / (2.0 * M_PI), P->axial_frequency_rad_s / (2.0 * M_PI),
		        P->axial_stiffness_N_per_m / UM, P->axial_half_play_m * UM, P->gear_half_backlash_m * UM,
		        P->mesh_error_m * UM, P->te_lines);
	}
	switch (q->analysis) {
	case PRSM_IO_DYN_VIBRATION: {
		const prsm_vib_steady *s = &r->steady;
		if (s->classification == PRSM_VIB_PERIODIC)
			fprintf(f, "  steady state: period %d (%s clock), return distance %.3g\n", s->period,
			        NAME(clock_names, s->clock), s->max_return_distance);
		else
			fprintf(f, "  steady state: %s (%s clock), return distance %.3g\n", NAME(class_names, s->classification),
			        NAME(clock_names, s->clock), s->max_return_distance);
		for (int i = 0; i < s->extremes; i++) {
			const prsm_vib_extreme *x = &s->extreme[i];
			if (i >= 6 && !axial_observable(x->observable))
				continue;
			fprintf(f, "  %s", NAME(obs_names, x->observable));
			if (!axial_observable(x->observable))
				fprintf(f, " %d", x->index);
			fprintf(f, ": min %.9g, max %.9g, mean %.9g, amplitude %.9g\n", x->min, x->max, x->mean,
			        0.5 * (x->max - x->min));
		}
		/* the gear pair's forcing line; the reduced model's strongest named line but the mean */
		int top = -1;
		for (int i = 0; i < s->lines; i++)
			if (pair ? strcmp(s->line[i].name, "forcing") == 0
			         : s->line[i].frequency > 0.0 && (top < 0 || s->line[i].amplitude > s->line[top].amplitude))
				top = i;
		if (top >= 0)
			fprintf(f, "  %s line: %s, amplitude %.6g at %.6g %s\n", pair ? "forcing" : "strongest named",
			        s->line[top].name, s->line[top].amplitude, s->line[top].frequency, pair ? "(frequency ratio)" : "Hz");
		if (s->contacts > 0)
			fprintf(f, "  %s open %.4g of the time\n", pair ? "mesh" : P->branches == PRSM_VIB_BRANCHES_AXIAL ? "thread"
			        : "mesh 0", pair || P->branches != PRSM_VIB_BRANCHES_AXIAL ? s->loss_share[0]
			                                                              : s->loss_share[s->contacts - 1]);
		if (r->with_lyapunov) {
			fprintf(f, "  Lyapunov exponents per unit tau:");
			for (int i = 0; i < r->lyapunov.exponents; i++)
				fprintf(f, " %.6g", r->lyapunov.lambda[i]);
			fprintf(f, " (blocks %.4g to %.4g)\n", r->lyapunov.block_min, r->lyapunov.block_max);
		}
		break;
	}
	case PRSM_IO_DYN_SWEEP: {
		double to_engine = 1.0;
		prsm_io_sweep_parameter_engine(q->sweep.parameter, &to_engine);
		fprintf(f, "  %zu points per direction, %zu failed\n", r->sweep.grid, failed_points(&r->sweep));
		text_sweep_summary(f, &r->sweep, prsm_io_sweep_parameter_name(q->sweep.parameter), 1.0 / to_engine);
		break;
	}
	case PRSM_IO_DYN_FREQUENCY_RESPONSE: {
		const prsm_vib_frequency_response *fr = &r->fr;
		if (r->with_harmonic_balance)
			for (int i = 0; i < fr->hb.folds; i++)
				fprintf(f, "  harmonic balance fold at Omega %.6g (amplitude %.6g)\n", fr->hb.fold[i].omega,
				        fr->hb.fold[i].amplitude);
		for (int k = 0; k < fr->jumps; k++) {
			fprintf(f, "  jump on the sweep %s between Omega %.6g and %.6g", fr->jump[k].direction > 0 ? "up" : "down",
			        fr->jump[k].from, fr->jump[k].to);
			if (fr->exact_fold[k].found)
				fprintf(f, ", exact fold %.8g", fr->exact_fold[k].omega);
			fputc('\n', f);
		}
		if (fr->jumps == 0)
			fprintf(f, "  no jumps: the sweeps up and down agree\n");
		break;
	}
	case PRSM_IO_DYN_BASINS: {
		const prsm_vib_basins *b = &r->basins;
		fprintf(f, "  %d x %d cells, %d attractors\n", b->nx, b->nv, b->attractors);
		for (int a = 0; a < b->attractors; a++)
			fprintf(f, "  attractor %d: period %d, %.4g of the cells\n", a, b->attractor[a].period, b->attractor[a].fraction);
		fprintf(f, "  other %.4g, failed %.4g\n", b->other_fraction, b->failed_fraction);
		break;
	}
	case PRSM_IO_DYN_LINEAR: {
		const prsm_vib_linear *l = &r->linear;
		int shown = 0;
		for (int i = 0; i < l->eigenvalues && shown < 8; i++) {
			if (l->kind[i] == PRSM_VIB_EIG_OSCILLATORY && l->eig_im[i] < 0.0)
				continue;
			/* a repeated eigenvalue (the roller modes) once, with its multiplicity */
			int same = 1, k = i + 1;
			for (; k < l->eigenvalues; k++) {
				if (l->kind[k] == PRSM_VIB_EIG_OSCILLATORY && l->eig_im[k] < 0.0)
					continue;
				if (!(fabs(l->eig_re[k] - l->eig_re[i]) <= 1e-9 * hypot(l->eig_re[i], l->eig_im[i]) &&
				      fabs(l->eig_im[k] - l->eig_im[i]) <= 1e-9 * hypot(l->eig_re[i], l->eig_im[i])))
					break;
				same++;
			}
			char times[24] = "";
			if (same > 1)
				snprintf(times, sizeof times, " x %d", same);
			if (pair)
				fprintf(f, "  eigenvalue %.9g %+.9gi per tau (%s, damping ratio %.6g)%s\n", l->eig_re[i], l->eig_im[i],
				        NAME(eig_kind_names, l->kind[i]), l->damping_ratio[i], times);
			else
				fprintf(f, "  eigenvalue %.6g %+.6gi 1/s: %.6g Hz, damping ratio %.6g (%s)%s\n", l->eig_re[i],
				        l->eig_im[i], l->frequency_Hz[i], l->damping_ratio[i], NAME(eig_kind_names, l->kind[i]), times);
			shown++;
			i = k - 1;
		}
		const prsm_vib_half_power *h = &r->half_power;
		if (h->defined)
			fprintf(f, "  half-power damping %.6g at %.6g %s (modal %.6g)\n", h->damping_ratio,
			        pair ? h->peak_omega : h->peak_omega / (2.0 * M_PI), pair ? "(ratio)" : "Hz", h->modal_damping_ratio);
		else
			fprintf(f, "  half-power damping undefined: %s\n", h->reason);
		break;
	}
	default:
		break;
	}
	fprintf(f, "  effort: %ld steps, %ld kink crossings\n", r->effort.steps, r->effort.events);
	for (int i = 0; warnings && i < warnings->count; i++)
		fprintf(f, "  warning: %s: %s\n", warnings->items[i].pointer, warnings->items[i].message);
	return ferror(f) ? PRSM_EIO : 0;
}

/* ---- a calibration ---- */

static void text_caveats(FILE *f, const prsm_calib_fit *fit)
{
	fprintf(f, "identifiability caveats (* this fit shows it):\n");
	for (int i = 0; i < fit->caveats; i++)
		fprintf(f, "  %s %s\n", fit->caveat[i].triggered ? "*" : "-", fit->caveat[i].message);
}

static void text_fit(FILE *f, const prsm_calib_fit *fit)
{
	fprintf(f, "  %-34s %16s %12s  %s\n", "parameter", "estimate", "std error", "unit");
	for (int j = 0; j < fit->params; j++)
		fprintf(f, "  %-34s %16.8g %12.3g  %s\n", fit->name[j], fit->estimate[j], fit->standard_error[j], fit->unit[j]);
	fprintf(f, "  residual s %.4g um over %zu points, lag-1 autocorrelation %.3f%s, condition number %.3g "
	        "(%.3g with unit columns), Gauss-Newton %d iterations%s\n",
	        fit->residual_sd_um, fit->points, fit->lag1_autocorrelation,
	        fit->inflation > 1.0 ? " (standard errors inflated)" : "", fit->condition_number, fit->condition_number_scaled,
	        fit->gauss_newton_iterations, fit->converged ? "" : " (not converged)");
	/* the strongest correlations */
	double worst = 0.0;
	int wa = -1, wb = -1;
	for (int a = 0; a < fit->params; a++)
		for (int b = a + 1; b < fit->params; b++)
			if (fabs(fit->correlation[a * fit->params + b]) > worst) {
				worst = fabs(fit->correlation[a * fit->params + b]);
				wa = a;
				wb = b;
			}
	if (wa >= 0)
		fprintf(f, "  largest correlation: %s with %s, %.3f\n", fit->name[wa], fit->name[wb],
		        fit->correlation[wa * fit->params + wb]);
}

int prsm_app_text_calibration(FILE *f, const prsm_io_calibration *c)
{
	fprintf(f, "prsm calibrate%s%s\n", c->name[0] ? ": " : "", c->name);
	for (int i = 0; i < c->warnings.count; i++)
		fprintf(f, "warning: %s: %s\n", c->warnings.items[i].pointer, c->warnings.items[i].message);
	if (c->curve)
		fprintf(f, "measured TE: %zu points over %.4g revolutions (%.4g mm of travel, lead %.4g mm) from %s\n", c->curve->n,
		        prsm_meas_revolutions(c->curve), c->curve->travel_mm[c->curve->n - 1] - c->curve->travel_mm[0], c->lead_mm,
		        c->source_csv ? c->source : "the request");
	fprintf(f, "carrier ratio: k* %.6f (minimum slip), statics %.6f\n", c->k_star, c->k_statics);
	if (c->has_comparison)
		fprintf(f, "comparison with the model TE%s at %g N: residual RMS %.4g um, peak to peak %.4g um, lead deviation "
		        "%.4g um/300 mm (measured RMS %.4g, model RMS %.4g um)\n",
		        c->with_errors ? " of the error set" : " (no errors given)", c->measuring_load_N, c->comparison.rms_um,
		        c->comparison.peak_to_peak_um, c->comparison.lead_deviation_um_per_300mm, c->comparison.measured_rms_um,
		        c->comparison.model_rms_um);
	if (c->has_spectrum) {
		const prsm_meas_spectrum *s = &c->spectrum;
		fprintf(f, "identification (spectrum, resolution %.4g per rev, orders at k*): lead deviation %.5g um/300 mm\n",
		        s->resolution_per_rev, s->lead_deviation_um_per_300mm);
		for (int l = 0; l < s->orders; l++) {
			if (s->above_nyquist[l])
				fprintf(f, "  %-18s order %8.5f  above the Nyquist order\n", prsm_calib_line_name(c->spectrum_kind[l]),
				        s->order_per_rev[l]);
			else
				fprintf(f, "  %-18s order %8.5f  %.4g um at %.5f\n", prsm_calib_line_name(c->spectrum_kind[l]),
				        s->order_per_rev[l], s->found_amplitude_um[l], s->found_order_per_rev[l]);
		}
	}
	if (c->has_line) {
		const prsm_calib_line_result *r = &c->line;
		fprintf(f, "calibration, line model: k = %.8f +- %.3g (grid %.4f..%.4f, %d points, best %.6f; %d side minima)\n",
		        r->carrier_ratio, r->carrier_ratio_se, r->grid_from, r->grid_to, r->grid_points, r->grid_best_k,
		        r->grid_local_minima > 0 ? r->grid_local_minima - 1 : 0);
		text_fit(f, &r->fit);
		fprintf(f, "  %-18s %10s %10s %10s %10s %10s\n", "line", "order", "amp um", "+-", "phase deg", "+-");
		for (int l = 0; l < r->lines; l++)
			fprintf(f, "  %-18s %10.6f %10.5f %10.5f %10.3f %10.3f\n", prsm_calib_line_name(r->kind[l]), r->order_per_rev[l],
			        r->amplitude_um[l], r->amplitude_se_um[l], r->phase_rad[l] * DEG, r->phase_se_rad[l] * DEG);
		for (int l = 0; l < r->dropped; l++)
			fprintf(f, "  %-18s left out (at or above the Nyquist order, or the order of another line)\n",
			        prsm_calib_line_name(r->dropped_kind[l]));
		text_caveats(f, &r->fit);
	}
	if (c->has_physical) {
		fprintf(f, "calibration, physical model (%d TE evaluations):\n", c->physical.evaluations);
		text_fit(f, &c->physical.fit);
		text_caveats(f, &c->physical.fit);
	}
	if (c->has_friction) {
		const prsm_calib_friction *r = &c->friction;
		fprintf(f, "efficiency: measured %.5g", r->efficiency);
		if (isfinite(r->efficiency_sd))
			fprintf(f, " +- %.3g", r->efficiency_sd);
		fprintf(f, ", model %.5g at mu %.4g (z %.3g)\n", r->efficiency_model, r->mu_design, r->z);
		if (r->found)
			fprintf(f, "friction: mu = %.5g +- %.3g with spin %s and gear-mesh loss %s (sliding alone at 45 deg: %.5g)\n",
			        r->mu, r->mu_se, r->spin ? "on" : "off", r->gear ? "on" : "off", r->mu_sliding_only);
		else
			fprintf(f, "friction: no mu in [0, 0.5] gives the measured efficiency with the assumed losses\n");
	}
	if (c->has_cage) {
		const prsm_calib_cage *k = &c->cage;
		fprintf(f, "cage ratio: measured %.6g", k->ratio);
		if (isfinite(k->ratio_sd))
			fprintf(f, " +- %.3g", k->ratio_sd);
		fprintf(f, ", k* %.6f (z %.3g), statics %.6f (z %.3g)\n", k->k_star, k->z_k_star, k->k_statics, k->z_statics);
		if (k->above_k_star)
			fprintf(f, "  the measured ratio is above k*: no carrier drag explains it (flagged)\n");
		else if (k->drag_found)
			fprintf(f, "  carrier drag c_C = %.4g +- %.3g N m s/rad explains it\n", k->carrier_drag_Nm_s_per_rad,
			        k->carrier_drag_se_Nm_s_per_rad);
	}
	return ferror(f) ? PRSM_EIO : 0;
}
