/*
 * measured_result.c: the calibration result document (schemas/measured-result.schema.json) on
 * the sticky-error writer (io/write.h) and its text summary (see measured.h;
 * docs/measured-data.md). Units are in every key: um, um/300mm, deg, N, rad/s, N m s/rad.
 */
#include <math.h>
#include <string.h>

#include "io/errors_json.h"
#include "io/measured.h"
#include "io/write.h"
#include "util/error.h"
#include "util/version.h"

#define DEG (180.0 / M_PI)

static const char *const caveat_names[PRSM_CALIB_CAVEAT_KINDS] = {
	"resolution", "slope_low_order", "screw_runout", "same_part_order", "roller_sum", "correlated_residuals"};

static void write_problems(prsm_jw *w, cJSON *obj, const char *key, const prsm_problems *p)
{
	cJSON *a = prsm_jw_array(w, obj, key);
	for (int i = 0; a && i < p->count; i++) {
		cJSON *o = prsm_jw_object(w, a, NULL);
		prsm_jw_string(w, o, "pointer", p->items[i].pointer);
		prsm_jw_string(w, o, "code", p->items[i].code);
		prsm_jw_string(w, o, "message", p->items[i].message);
	}
}

/* the uncertainty block every fit has (MODEL-DYNAMICS §8.5, §8.7 `calibration`) */
static void write_fit(prsm_jw *w, cJSON *o, const prsm_calib_fit *f)
{
	const int P = f->params;
	cJSON *params = prsm_jw_array(w, o, "parameters");
	cJSON *est = prsm_jw_object(w, o, "estimates");
	cJSON *se = prsm_jw_object(w, o, "standard_errors");
	for (int j = 0; j < P; j++) {
		char key[PRSM_CALIB_NAME_MAX + 24];
		/* the unit in the key: name_um, name_um_per_300mm, ... */
		const char *u = f->unit[j];
		const char *suffix = strcmp(u, "um") == 0 ? "_um" : strcmp(u, "um/300mm") == 0 ? "_um_per_300mm" : "";
		const int has_unit = strstr(f->name[j], "_um") || strstr(f->name[j], "_mrad") || strstr(f->name[j], "_deg");
		snprintf(key, sizeof key, "%s%s", f->name[j], has_unit ? "" : suffix);
		cJSON *p = prsm_jw_object(w, params, NULL);
		prsm_jw_string(w, p, "name", key);
		prsm_jw_string(w, p, "unit", u);
		prsm_jw_number(w, p, "estimate", f->estimate[j]);
		prsm_jw_number(w, p, "standard_error", f->standard_error[j]);
		prsm_jw_number(w, p, "standard_error_white", f->standard_error_white[j]);
		prsm_jw_number(w, est, key, f->estimate[j]);
		prsm_jw_number(w, se, key, f->standard_error[j]);
	}
	cJSON *corr = prsm_jw_array(w, o, "correlation");
	for (int a = 0; a < P; a++) {
		cJSON *row = prsm_jw_array(w, corr, NULL);
		for (int b = 0; b < P; b++)
			prsm_jw_number(w, row, NULL, f->correlation[a * P + b]);
	}
	prsm_jw_number(w, o, "points", (double)f->points);
	prsm_jw_number(w, o, "residual_sd_um", f->residual_sd_um);
	prsm_jw_number(w, o, "sum_of_squares_um2", f->sum_of_squares_um2);
	prsm_jw_number(w, o, "condition_number", f->condition_number);
	prsm_jw_number(w, o, "condition_number_scaled", f->condition_number_scaled);
	prsm_jw_number(w, o, "residual_lag1_autocorrelation", f->lag1_autocorrelation);
	prsm_jw_number(w, o, "inflation", f->inflation);
	prsm_jw_number(w, o, "gauss_newton_iterations", f->gauss_newton_iterations);
	prsm_jw_bool(w, o, "converged", f->converged);
	cJSON *cav = prsm_jw_array(w, o, "caveats");
	for (int i = 0; i < f->caveats; i++) {
		cJSON *c = prsm_jw_object(w, cav, NULL);
		prsm_jw_string(w, c, "code", caveat_names[f->caveat[i].code]);
		prsm_jw_bool(w, c, "triggered", f->caveat[i].triggered);
		prsm_jw_string(w, c, "message", f->caveat[i].message);
	}
}

static void write_line(prsm_jw *w, cJSON *o, const prsm_calib_line_result *r)
{
	prsm_jw_string(w, o, "model", "line");
	write_fit(w, o, &r->fit);
	cJSON *lines = prsm_jw_array(w, o, "lines");
	for (int l = 0; l < r->lines; l++) {
		cJSON *x = prsm_jw_object(w, lines, NULL);
		prsm_jw_string(w, x, "name", prsm_calib_line_name(r->kind[l]));
		prsm_jw_number(w, x, "order_per_rev", r->order_per_rev[l]);
		prsm_jw_number(w, x, "amplitude_um", r->amplitude_um[l]);
		prsm_jw_number(w, x, "amplitude_se_um", r->amplitude_se_um[l]);
		prsm_jw_number(w, x, "phase_deg", r->phase_rad[l] * DEG);
		prsm_jw_number(w, x, "phase_se_deg", r->phase_se_rad[l] * DEG);
	}
	cJSON *dropped = prsm_jw_array(w, o, "dropped_lines");
	for (int l = 0; l < r->dropped; l++)
		prsm_jw_string(w, dropped, NULL, prsm_calib_line_name(r->dropped_kind[l]));
	cJSON *k = prsm_jw_object(w, o, "carrier_ratio");
	prsm_jw_number(w, k, "estimate", r->carrier_ratio);
	prsm_jw_number(w, k, "standard_error", r->carrier_ratio_se);
	prsm_jw_number(w, k, "prior", r->carrier_ratio_prior);
	cJSON *g = prsm_jw_object(w, k, "grid");
	prsm_jw_number(w, g, "from", r->grid_from);
	prsm_jw_number(w, g, "to", r->grid_to);
	prsm_jw_number(w, g, "points", r->grid_points);
	prsm_jw_number(w, g, "best", r->grid_best_k);
	prsm_jw_number(w, g, "best_sum_of_squares_um2", r->grid_best_S_um2);
	prsm_jw_number(w, g, "local_minima", r->grid_local_minima);
	prsm_jw_number(w, k, "refined", r->refined_k);
	prsm_jw_string(w, k, "refine_method", r->refine_used == PRSM_CALIB_REFINE_COBYLA ? "cobyla" : "bobyqa");
	prsm_jw_number(w, k, "refine_evaluations", r->refine_evaluations);
	prsm_jw_number(w, o, "revolutions", r->revolutions);
	prsm_jw_number(w, o, "resolution_per_rev", r->resolution_per_rev);
}

static void write_physical(prsm_jw *w, cJSON *o, const prsm_io_calibration *c)
{
	const prsm_calib_physical_result *r = &c->physical;
	prsm_jw_string(w, o, "model", "physical");
	write_fit(w, o, &r->fit);
	cJSON *s = prsm_jw_array(w, o, "fields");
	for (int i = 0; i < r->fields; i++) {
		cJSON *x = prsm_jw_object(w, s, NULL);
		prsm_jw_string(w, x, "name", r->fit.name[i]);
		prsm_jw_number(w, x, "start", r->start[i]);
		prsm_jw_number(w, x, "estimate", r->fit.estimate[i]);
		prsm_jw_number(w, x, "standard_error", r->fit.standard_error[i]);
		char key[48];
		snprintf(key, sizeof key, "sensitivity_um_per_%s",
		         strcmp(r->fit.unit[i], "um/300mm") == 0 ? "um_per_300mm" : r->fit.unit[i]);
		prsm_jw_number(w, x, key, r->sensitivity_um[i]);
	}
	prsm_jw_item(w, o, "errors", prsm_io_errors_to_json(&c->calibrated, c->starts));
	prsm_jw_number(w, o, "evaluations", r->evaluations);
	prsm_jw_number(w, o, "optimizer_status", r->optimizer_status);
	prsm_jw_string(w, o, "mode", c->options.mode == PRSM_MODE_EXACT ? "exact" : "linear");
	prsm_jw_number(w, o, "measuring_load_N", c->options.measuring_load_N);
}

cJSON *prsm_io_calibration_to_json(const prsm_io_calibration *c)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	cJSON *eng = prsm_jw_object(&w, root, "engine");
	prsm_jw_string(&w, eng, "name", "prsm");
	prsm_jw_string(&w, eng, "version", PRSM_VERSION);
	prsm_jw_string(&w, eng, "model", PRSM_CALIB_MODEL_VERSION);
	prsm_jw_string(&w, eng, "build", prsm_engine_build());
	if (c->name[0])
		prsm_jw_string(&w, root, "name", c->name);
	write_problems(&w, root, "warnings", &c->warnings);
	const prsm_meas_data *m = c->measured;
	/* what was measured */
	cJSON *mo = prsm_jw_object(&w, root, "measured");
	if (c->curve) {
		prsm_jw_string(&w, mo, "source", c->source_csv ? "csv" : "json");
		if (c->source_csv == 1)
			prsm_jw_string(&w, mo, "file", c->source);
		prsm_jw_number(&w, mo, "points", (double)c->curve->n);
		prsm_jw_number(&w, mo, "revolutions", prsm_meas_revolutions(c->curve));
		prsm_jw_number(&w, mo, "stroke_mm", c->curve->travel_mm[c->curve->n - 1] - c->curve->travel_mm[0]);
	}
	prsm_jw_number(&w, mo, "lead_mm", c->lead_mm);
	prsm_jw_number(&w, mo, "te_noise_sd_um", m->te_noise_sd_um);
	/* §8.5 item 1 */
	cJSON *cmp = prsm_jw_object(&w, root, "comparison");
	cJSON *kin = prsm_jw_object(&w, cmp, "kinematics");
	prsm_jw_number(&w, kin, "carrier_ratio_min_slip", c->k_star);
	prsm_jw_number(&w, kin, "carrier_ratio_statics", c->k_statics);
	prsm_jw_number(&w, kin, "ring_gear_ratio", c->ring_gear_ratio);
	prsm_jw_number(&w, kin, "rollers", c->rollers);
	if (c->ring_gear_teeth > 0)
		prsm_jw_number(&w, kin, "ring_gear_teeth", c->ring_gear_teeth);
	if (c->has_comparison) {
		const prsm_meas_comparison *t = &c->comparison;
		cJSON *te = prsm_jw_object(&w, cmp, "te");
		prsm_jw_bool(&w, te, "with_errors", c->with_errors);
		prsm_jw_number(&w, te, "measuring_load_N", c->measuring_load_N);
		prsm_jw_number(&w, te, "offset_um", t->offset_um);
		prsm_jw_number(&w, te, "residual_rms_um", t->rms_um);
		prsm_jw_number(&w, te, "residual_peak_to_peak_um", t->peak_to_peak_um);
		prsm_jw_number(&w, te, "residual_max_abs_um", t->max_abs_um);
		prsm_jw_number(&w, te, "residual_lead_deviation_um_per_300mm", t->lead_deviation_um_per_300mm);
		prsm_jw_number(&w, te, "measured_rms_um", t->measured_rms_um);
		prsm_jw_number(&w, te, "model_rms_um", t->model_rms_um);
		prsm_jw_number(&w, te, "z_rms", t->z_rms);
	}
	if (c->has_cage) {
		const prsm_calib_cage *k = &c->cage;
		cJSON *o = prsm_jw_object(&w, cmp, "cage_ratio");
		prsm_jw_number(&w, o, "measured", k->ratio);
		prsm_jw_number(&w, o, "standard_uncertainty", k->ratio_sd);
		prsm_jw_number(&w, o, "axial_load_N", k->axial_load_N);
		prsm_jw_number(&w, o, "screw_speed_rad_s", k->screw_speed_rad_s);
		prsm_jw_number(&w, o, "carrier_ratio_min_slip", k->k_star);
		prsm_jw_number(&w, o, "carrier_ratio_statics", k->k_statics);
		prsm_jw_number(&w, o, "difference_min_slip", k->ratio - k->k_star);
		prsm_jw_number(&w, o, "z_min_slip", k->z_k_star);
		prsm_jw_number(&w, o, "z_statics", k->z_statics);
	}
	if (c->has_friction) {
		const prsm_calib_friction *f = &c->friction;
		cJSON *o = prsm_jw_object(&w, cmp, "efficiency");
		prsm_jw_number(&w, o, "measured", f->efficiency);
		prsm_jw_number(&w, o, "standard_uncertainty", f->efficiency_sd);
		prsm_jw_number(&w, o, "axial_load_N", f->axial_load_N);
		prsm_jw_number(&w, o, "screw_speed_rad_s", f->screw_speed_rad_s);
		prsm_jw_number(&w, o, "model", f->efficiency_model);
		prsm_jw_number(&w, o, "difference", f->efficiency - f->efficiency_model);
		prsm_jw_number(&w, o, "z", f->z);
	}
	/* §8.5 item 2 */
	if (c->has_spectrum) {
		const prsm_meas_spectrum *s = &c->spectrum;
		cJSON *id = prsm_jw_object(&w, root, "identification");
		prsm_jw_number(&w, id, "lead_deviation_um_per_300mm", s->lead_deviation_um_per_300mm);
		prsm_jw_number(&w, id, "line_offset_um", s->line_offset_um);
		prsm_jw_number(&w, id, "revolutions", s->revolutions);
		prsm_jw_number(&w, id, "resolution_per_rev", s->resolution_per_rev);
		prsm_jw_number(&w, id, "samples_per_rev", s->samples_per_rev);
		prsm_jw_number(&w, id, "carrier_ratio", c->k_star);
		prsm_jw_bool(&w, id, "resampled", s->resampled);
		cJSON *lines = prsm_jw_array(&w, id, "lines");
		double top = 0.0;
		for (int l = 0; l < s->orders; l++) {
			cJSON *x = prsm_jw_object(&w, lines, NULL);
			prsm_jw_string(&w, x, "name", prsm_calib_line_name(c->spectrum_kind[l]));
			prsm_jw_number(&w, x, "order_per_rev", s->order_per_rev[l]);
			prsm_jw_number(&w, x, "found_order_per_rev", s->found_order_per_rev[l]);
			prsm_jw_number(&w, x, "amplitude_um", s->found_amplitude_um[l]);
			prsm_jw_bool(&w, x, "above_nyquist", s->above_nyquist[l]);
			if (!s->above_nyquist[l])
				top = fmax(top, s->order_per_rev[l]);
		}
		/* the spectrum up to 1.5 x the highest named order below Nyquist (at most 8192 bins) */
		cJSON *sp = prsm_jw_object(&w, id, "spectrum");
		prsm_jw_number(&w, sp, "step_per_rev", s->step_per_rev);
		cJSON *amp = prsm_jw_array(&w, sp, "amplitude_um");
		size_t nb = (size_t)ceil((1.5 * top + 2.0 * s->resolution_per_rev) / s->step_per_rev) + 1;
		if (nb > s->bins)
			nb = s->bins;
		if (nb > 8192)
			nb = 8192;
		for (size_t b = 0; b < nb; b++)
			prsm_jw_number(&w, amp, NULL, s->amplitude_um[b]);
	}
	/* §8.5 item 3 */
	if (c->has_line || c->has_physical) {
		cJSON *cal = prsm_jw_object(&w, root, "calibration");
		if (c->has_line)
			write_line(&w, cal, &c->line);
		else
			write_physical(&w, cal, c);
		/* the calibrated model's TE at every measured point (measured - residual), um: what a
		 * plot overlays on the measurement, for either model */
		const prsm_calib_fit *fit = c->has_line ? &c->line.fit : &c->physical.fit;
		if (c->curve && fit->residual_um && fit->points == c->curve->n) {
			cJSON *fitted = prsm_jw_array(&w, cal, "fitted_te_um");
			for (size_t i = 0; i < c->curve->n; i++)
				prsm_jw_number(&w, fitted, NULL, c->curve->te_um[i] - fit->residual_um[i]);
		}
	}
	/* §8.5 item 4 */
	if (c->has_friction) {
		const prsm_calib_friction *f = &c->friction;
		cJSON *o = prsm_jw_object(&w, root, "friction");
		prsm_jw_bool(&w, o, "found", f->found);
		prsm_jw_number(&w, o, "mu", f->mu);
		prsm_jw_number(&w, o, "mu_standard_error", f->mu_se);
		prsm_jw_number(&w, o, "mu_design", f->mu_design);
		prsm_jw_number(&w, o, "mu_sliding_only", f->mu_sliding_only);
		prsm_jw_number(&w, o, "efficiency_per_mu", f->deta_dmu);
		cJSON *l = prsm_jw_object(&w, o, "losses_assumed");
		prsm_jw_bool(&w, l, "spin", f->spin);
		prsm_jw_bool(&w, l, "gear_mesh", f->gear);
		prsm_jw_number(&w, l, "input_torque_Nm", f->input_torque_Nm);
		prsm_jw_number(&w, l, "ideal_torque_Nm", f->ideal_torque_Nm);
		prsm_jw_number(&w, l, "sliding_torque_Nm", f->sliding_torque_Nm);
		prsm_jw_number(&w, l, "spin_torque_Nm", f->spin_torque_Nm);
		prsm_jw_number(&w, l, "gear_torque_Nm", f->gear_torque_Nm);
		prsm_jw_number(&w, l, "drag_torque_Nm", f->drag_torque_Nm);
		prsm_jw_number(&w, l, "seal_torque_Nm", f->seal_torque_Nm);
	}
	if (c->has_cage) {
		const prsm_calib_cage *k = &c->cage;
		cJSON *o = prsm_jw_object(&w, root, "carrier_drag");
		prsm_jw_bool(&w, o, "above_min_slip", k->above_k_star);
		prsm_jw_bool(&w, o, "found", k->drag_found);
		prsm_jw_number(&w, o, "carrier_drag_Nm_s_per_rad", k->carrier_drag_Nm_s_per_rad);
		prsm_jw_number(&w, o, "carrier_drag_se_Nm_s_per_rad", k->carrier_drag_se_Nm_s_per_rad);
		prsm_jw_number(&w, o, "ratio_per_drag_rad_per_N_m_s", k->dk_dcC);
	}
	return prsm_jw_done(&w, root);
}

/* ---- text ---- */

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

int prsm_io_calibration_write_text(FILE *f, const prsm_io_calibration *c)
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
