/*
 * measured_result.c: the calibration result document (schemas/measured-result.schema.json) by
 * its generated table (the view it reads and the hooks) (see measured.h; the text summary is in
 * app/text.c; docs/measured-data.md). Units are in every key: um, um/300mm, deg, N, rad/s, N m s/rad.
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
