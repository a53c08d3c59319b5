/*
 * measured_result.c: the calibration result document (schemas/measured-result.schema.json) by
 * its generated table (the view it reads and the hooks) and its text summary (see measured.h;
 * docs/measured-data.md). Units are in every key: um, um/300mm, deg, N, rad/s, N m s/rad.
 */
#include <math.h>
#include <string.h>

#include "io/errors_json.h"
#include "io/measured.h"
#include "io/write.h"
#include "prsm_io_writers.h"
#include "util/error.h"

#define DEG (180.0 / M_PI)

/* The estimates (or standard errors: at) by parameter name. */
void prsm_io_whook_calib_by_name(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_calibration_result_view *v = w->ctx;
	const double *x = at;
	cJSON *o = prsm_jw_object(w, obj, key);
	for (int j = 0; j < v->fit->params; j++)
		prsm_jw_number(w, o, v->key[j], x[j]);
}

/* The correlation matrix, row by row (at: the fit). */
void prsm_io_whook_calib_correlation(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_calib_fit *f = at;
	const int P = f->params;
	cJSON *corr = prsm_jw_array(w, obj, key);
	for (int a = 0; a < P; a++) {
		cJSON *row = prsm_jw_array(w, corr, NULL);
		for (int b = 0; b < P; b++)
			prsm_jw_number(w, row, NULL, f->correlation[a * P + b]);
	}
}

/* A physical field's sensitivity (at: its element of sensitivity_um), the key naming the unit. */
void prsm_io_whook_calib_sensitivity(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_calib_physical_result *r = ((const prsm_io_calibration_result_view *)w->ctx)->phys;
	const double *s = at;
	const char *unit = r->fit.unit[s - r->sensitivity_um];
	char name[48];
	snprintf(name, sizeof name, "sensitivity_um_per_%s", strcmp(unit, "um/300mm") == 0 ? "um_per_300mm" : unit);
	prsm_jw_number(w, obj, name, *s);
}

void prsm_io_whook_calib_errors(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_calibration *c = ((const prsm_io_calibration_result_view *)w->ctx)->c;
	prsm_jw_item(w, obj, key, prsm_io_errors_to_json(&c->calibrated, c->starts));
}

/* The calibrated model's TE at every measured point: measured - residual, um. */
void prsm_io_whook_calib_fitted_te(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_calibration_result_view *v = w->ctx;
	cJSON *fitted = prsm_jw_array(w, obj, key);
	for (size_t i = 0; i < v->curve->n; i++)
		prsm_jw_number(w, fitted, NULL, v->curve->te_um[i] - v->fit->residual_um[i]);
}

cJSON *prsm_io_calibration_to_json(const prsm_io_calibration *c)
{
	prsm_io_calibration_result_view v = {
		.c = c, .curve = c->curve, .m = c->measured, .has_curve = c->curve != NULL,
		.file_shown = c->curve && c->source_csv == 1, .has_fit = c->has_line || c->has_physical,
		.line = c->has_line ? &c->line : NULL, .phys = c->has_physical ? &c->physical : NULL,
		.cage_difference = c->has_cage ? c->cage.ratio - c->cage.k_star : NAN,
		.efficiency_difference = c->has_friction ? c->friction.efficiency - c->friction.efficiency_model : NAN,
	};
	if (c->curve) {
		v.revolutions = prsm_meas_revolutions(c->curve);
		v.stroke_mm = c->curve->travel_mm[c->curve->n - 1] - c->curve->travel_mm[0];
	}
	if (c->has_spectrum) { /* the spectrum up to 1.5 x the highest named order below Nyquist */
		const prsm_meas_spectrum *s = &c->spectrum;
		double top = 0.0;
		for (int l = 0; l < s->orders; l++)
			if (!s->above_nyquist[l])
				top = fmax(top, s->order_per_rev[l]);
		size_t nb = (size_t)ceil((1.5 * top + 2.0 * s->resolution_per_rev) / s->step_per_rev) + 1;
		nb = nb > s->bins ? s->bins : nb;
		v.spectrum_bins = nb > 8192 ? 8192 : nb;
	}
	if (v.has_fit) {
		const prsm_calib_fit *f = v.fit = c->has_line ? &c->line.fit : &c->physical.fit;
		for (int j = 0; j < f->params; j++) { /* the unit in the key: name_um, name_um_per_300mm, ... */
			const char *u = f->unit[j];
			const char *suffix = strcmp(u, "um") == 0 ? "_um" : strcmp(u, "um/300mm") == 0 ? "_um_per_300mm" : "";
			const int has_unit = strstr(f->name[j], "_um") || strstr(f->name[j], "_mrad") || strstr(f->name[j], "_deg");
			snprintf(v.key[j], sizeof v.key[j], "%s%s", f->name[j], has_unit ? "" : suffix);
		}
		v.fitted = c->curve && f->residual_um && f->points == c->curve->n;
	}
	prsm_jw w = {0, &v};
	cJSON *root = prsm_jw_root(&w);
	prsm_io_write_fields(&w, root, &v, &prsm_io_w_calibration_result, 0);
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
