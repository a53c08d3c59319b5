/*
 * calibrate.c: reading, computing and writing a calibration request (see calibrate.h;
 * docs/measured-data.md, MODEL-DYNAMICS.md §8.5).
 */
#include "app/calibrate.h"
#include "app/text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dyn/calib.h"
#include "dyn/dyn.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/errors_json.h"
#include "io/json_util.h"
#include "io/stages_json.h"

struct prsm_app_calibration {
	prsm_analyze_request rq;     /* the design, its statics, the error set and the rigid model's options */
	int rq_loaded;
	prsm_meas_data meas;         /* the measured section (its JSON curve) */
	prsm_meas_curve csv_curve;   /* the CSV curve */
	prsm_io_csv_origin origin;
	const prsm_meas_curve *curve;/* the one used (NULL: none) */
	prsm_calib_options options;
	prsm_calib_field fields[PRSM_CALIB_FIELDS_MAX];
	prsm_io_calibration out;
	int ran;
};

static const cJSON *item(const cJSON *o, const char *key)
{
	return cJSON_IsObject(o) ? cJSON_GetObjectItemCaseSensitive(o, key) : NULL;
}

/* "part.key" or "roller.<index>.key" into a field; problems at pointer. */
static int resolve_field(prsm_calib_field *f, const char *name, const prsm_design *d, const char *pointer,
                         prsm_problems *problems)
{
	memset(f, 0, sizeof *f);
	snprintf(f->name, sizeof f->name, "%s", name);
	char part[16] = "", key[PRSM_CALIB_NAME_MAX] = "";
	const char *dot = strchr(name, '.');
	if (dot == NULL || (size_t)(dot - name) >= sizeof part) {
		prsm_problems_add(problems, pointer, "unknown_field",
		                  "\"%s\" is no error field: part.field, e.g. nut.runout_um or roller.3.pin_radial_um", name);
		return PRSM_EINVAL;
	}
	memcpy(part, name, (size_t)(dot - name));
	const char *rest = dot + 1;
	if (strcmp(part, "screw") == 0) {
		f->part = PRSM_CALIB_PART_SCREW;
	} else if (strcmp(part, "nut") == 0) {
		f->part = PRSM_CALIB_PART_NUT;
	} else if (strcmp(part, "carrier") == 0) {
		f->part = PRSM_CALIB_PART_CARRIER;
	} else if (strcmp(part, "roller") == 0) {
		f->part = PRSM_CALIB_PART_ROLLER;
		char *end;
		const long j = strtol(rest, &end, 10);
		if (end == rest || *end != '.' || j < 0 || j >= d->rollers) {
			prsm_problems_add(problems, pointer, "unknown_field",
			                  "\"%s\": a roller's field names its roller, roller.<0..%d>.field (e.g. roller.0.runout_um)",
			                  name, d->rollers - 1);
			return PRSM_EINVAL;
		}
		f->roller = (int)j;
		rest = end + 1;
	} else {
		prsm_problems_add(problems, pointer, "unknown_field", "\"%s\": the part is screw, nut, carrier or roller", name);
		return PRSM_EINVAL;
	}
	snprintf(key, sizeof key, "%s", rest);
	prsm_io_error_field ef;
	if (prsm_io_error_field_find(&ef, part, key)) {
		prsm_problems_add(problems, pointer, "unknown_field",
		                  "\"%s\": %s has no error field %s (the names of the errors object, e.g. runout_um, "
		                  "runout_phase_deg, lead_deviation_um_per_300mm)", name, part, key);
		return PRSM_EINVAL;
	}
	f->offset = ef.offset;
	f->scale = ef.scale;
	f->limit = ef.limit;
	f->magnitude = ef.magnitude;
	f->phase_offset = ef.phase_offset;
	f->phase = ef.phase;
	f->lead = strstr(key, "lead_deviation") != NULL;
	const size_t kl = strlen(key);
	if (kl > 13 && strcmp(key + kl - 13, "_um_per_300mm") == 0)
		snprintf(f->unit, sizeof f->unit, "um/300mm");
	else if (kl > 3 && strcmp(key + kl - 3, "_um") == 0)
		snprintf(f->unit, sizeof f->unit, "um");
	else if (kl > 5 && strcmp(key + kl - 5, "_mrad") == 0)
		snprintf(f->unit, sizeof f->unit, "mrad");
	else if (kl > 4 && strcmp(key + kl - 4, "_deg") == 0)
		snprintf(f->unit, sizeof f->unit, "deg");
	else
		snprintf(f->unit, sizeof f->unit, "-");
	return 0;
}

int prsm_app_calibration_load(prsm_app_calibration **out, const cJSON *doc, const char *csv_path,
                              prsm_problems *problems)
{
	*out = NULL;
	if (!cJSON_IsObject(doc)) {
		prsm_problems_add(problems, "", "type", "a calibration request is {\"design\": {...}, \"measured\": {...}, "
		                  "\"dynamics\": {\"analysis\": \"calibrate\", ...}} (schemas/measured-request.schema.json)");
		return PRSM_EINVAL;
	}
	const int before = prsm_problems_total(problems);
	if (prsm_io_is_multistage(doc) || item(doc, "stages")) {
		prsm_problems_add(problems, "/stages", "single_stage", "a calibration takes one design (\"design\"), not a chain");
		return PRSM_EINVAL;
	}
	if (!item(doc, "design")) {
		prsm_problems_add(problems, "/design", "required", "a calibration needs the design of the measured screw");
		return PRSM_EINVAL;
	}
	const cJSON *dyn = item(doc, "dynamics");
	const cJSON *an = item(dyn, "analysis");
	if (!cJSON_IsObject(dyn))
		prsm_problems_add(problems, "/dynamics", "required",
		                  "a calibration request has {\"dynamics\": {\"analysis\": \"calibrate\"}} (and its options in "
		                  "dynamics.calibrate)");
	else if (!cJSON_IsString(an) || strcmp(an->valuestring, "calibrate") != 0)
		prsm_problems_add(problems, "/dynamics/analysis", "calibrate",
		                  "prsm calibrate runs the analysis \"calibrate\"; the others run with prsm simulate");
	prsm_app_calibration *c = calloc(1, sizeof *c); /* handed to the caller on success */
	cJSON *dup = cJSON_Duplicate(doc, 1);
	if (c == NULL || dup == NULL) {
		free(c);
		cJSON_Delete(dup);
		return PRSM_ENOMEM;
	}
	prsm_problems_init(&c->out.warnings);
	/* the statics and the rigid model read the request without what is calibration's own */
	cJSON_DeleteItemFromObjectCaseSensitive(dup, "measured");
	cJSON *ddyn = cJSON_GetObjectItemCaseSensitive(dup, "dynamics");
	if (cJSON_IsObject(ddyn)) {
		cJSON_DeleteItemFromObjectCaseSensitive(ddyn, "analysis");
		cJSON_DeleteItemFromObjectCaseSensitive(ddyn, "calibrate");
		if (ddyn->child == NULL)
			cJSON_DeleteItemFromObjectCaseSensitive(dup, "dynamics");
	}
	int rc = prsm_app_analyze_load(&c->rq, dup, &c->out.warnings, problems);
	cJSON_Delete(dup);
	c->rq_loaded = 1;
	const int design_ok = rc == 0;
	prsm_io_measured_read(&c->meas, item(doc, "measured"), problems);
	prsm_io_calibrate_options_read(&c->options, item(dyn, "calibrate"), problems);
	c->out.lead_mm = design_ok ? c->rq.d.starts * c->rq.d.pitch_mm : NAN;
	/* the curve: the CSV file, else the document's CSV text (measured.te_csv, e.g. a service
	 * upload), else its arrays (measured.te) */
	const cJSON *te_csv = item(item(doc, "measured"), "te_csv");
	if (te_csv && !cJSON_IsString(te_csv)) {
		prsm_problems_add(problems, "/measured/te_csv", "type",
		                  "te_csv is the TE curve as CSV text (a header row naming screw_angle_rad, travel_mm "
		                  "and te_um), a string");
		te_csv = NULL;
	} else if (te_csv && item(item(doc, "measured"), "te") && !csv_path) {
		prsm_problems_add(problems, "/measured/te_csv", "one_curve",
		                  "the TE curve is given twice: as arrays (measured.te) and as CSV text (measured.te_csv); "
		                  "give one");
		te_csv = NULL;
	}
	const char *csv_source = csv_path ? csv_path : te_csv ? "/measured/te_csv" : NULL;
	if (csv_source) {
		const int crc = csv_path ? prsm_io_measured_csv_read(&c->csv_curve, &c->origin, csv_path, problems)
		                         : prsm_io_measured_csv_parse(&c->csv_curve, &c->origin, te_csv->valuestring,
		                                                      strlen(te_csv->valuestring), csv_source, problems);
		if (crc == 0) {
			if (csv_path && (c->meas.has_te || te_csv))
				prsm_problems_add(&c->out.warnings, te_csv ? "/measured/te_csv" : "/measured/te", "replaced",
				                  "the TE curve of %s replaces the one in the document", csv_path);
			c->curve = &c->csv_curve;
			c->out.source_csv = csv_path ? 1 : 2;
			snprintf(c->out.source, sizeof c->out.source, "%s", csv_source);
			if (design_ok)
				prsm_io_measured_curve_check(&c->csv_curve, &c->origin, csv_source, c->out.lead_mm, problems);
		} else if (rc == 0) {
			rc = crc;
		}
	} else if (c->meas.has_te) {
		c->curve = &c->meas.te;
		snprintf(c->out.source, sizeof c->out.source, "/measured/te");
		if (design_ok)
			prsm_io_measured_curve_check(&c->meas.te, NULL, NULL, c->out.lead_mm, problems);
	}
	if (c->curve == NULL && isnan(c->meas.efficiency) && isnan(c->meas.cage_ratio) &&
	    prsm_problems_total(problems) == before)
		prsm_problems_add(problems, "/measured", "required",
		                  "nothing measured: give the TE curve (measured.te, measured.te_csv, or prsm calibrate --measured "
		                  "FILE.csv), "
		                  "a cage ratio or an efficiency");
	if (c->curve == NULL && c->options.model == PRSM_CALIB_MODEL_PHYSICAL && item(item(dyn, "calibrate"), "model"))
		prsm_problems_add(problems, "/dynamics/calibrate/model", "needs_te",
		                  "the physical model is calibrated on a TE curve: give measured.te, measured.te_csv or --measured "
		                  "FILE.csv");
	/* the physical model's fields */
	if (design_ok && c->options.model == PRSM_CALIB_MODEL_PHYSICAL) {
		for (int i = 0; i < c->options.fields; i++) {
			char ptr[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(ptr, sizeof ptr, "/dynamics/calibrate/parameters", i);
			resolve_field(&c->fields[i], c->options.field_names[i], &c->rq.d, ptr, problems);
		}
	}
	if (rc == 0 && prsm_problems_total(problems) > before)
		rc = PRSM_EINVAL;
	if (rc) {
		prsm_app_calibration_free(c);
		return rc;
	}
	const cJSON *nm = item(item(doc, "design"), "name");
	if (cJSON_IsString(nm))
		prsm_json_excerpt(c->out.name, sizeof c->out.name, nm->valuestring);
	*out = c;
	return 0;
}

/* §8.5 item 2: the named orders at k (mesh only with z_2) */
static int named_orders(double *orders, int *kinds, const prsm_calib_kinematics *kin, double k)
{
	int n = 0;
	for (int kind = 0; kind < PRSM_CALIB_LINE_KINDS; kind++) {
		if (kind == PRSM_CALIB_LINE_MESH && kin->ring_gear_teeth <= 0)
			continue;
		double a, b;
		prsm_calib_order_coefficients(&a, &b, kind, kin);
		orders[n] = a + b * k;
		kinds[n++] = kind;
	}
	return n;
}

int prsm_app_calibration_run(prsm_app_calibration *c, prsm_error *err)
{
	prsm_io_calibration *o = &c->out;
	const prsm_design *d = &c->rq.d;
	o->measured = &c->meas;
	o->curve = c->curve;
	o->options = c->options;
	o->rollers = d->rollers;
	o->ring_gear_ratio = d->nut_radius_mm / d->roller_radius_mm;
	o->ring_gear_teeth = c->rq.perf.losses.gear_teeth_ring;
	o->starts = d->starts;
	o->with_errors = !prsm_errors_all_zero(&c->rq.errors);
	o->measuring_load_N = c->options.measuring_load_N;
	/* the rigid model's carrier ratios (§8.1) at the design's operating point */
	prsm_dyn_options dyn;
	if (c->rq.with_dynamics)
		dyn = c->rq.dyn;
	else
		prsm_dyn_options_init(&dyn);
	dyn.input.kind = PRSM_DYN_INPUT_SPEED;
	dyn.input.signal.shape = PRSM_DYN_SHAPE_STEP;
	dyn.input.signal.value = d->screw_speed_rad_s > 0.0 ? d->screw_speed_rad_s : 100.0;
	dyn.load.shape = PRSM_DYN_SHAPE_STEP;
	dyn.load.value = d->axial_load_N > 0.0 ? d->axial_load_N : 100.0;
	dyn.friction.carrier_drag_Nm_s_per_rad = 0.0;
	/* the minimum-slip ratio k* (§8.1) and the contact-radius ratio, as the statics kinematics
	 * give them (the rigid model settles at k* without drag) */
	o->k_star = c->rq.a.kinematics.carrier_ratio_min_slip;
	o->k_statics = c->rq.a.kinematics.carrier_ratio;
	int rc = 0;
	const prsm_calib_kinematics kin = {o->ring_gear_ratio, d->rollers, o->ring_gear_teeth};
	if (c->curve) {
		const prsm_meas_curve *cv = c->curve;
		/* §8.5 item 1: the model TE of the design with its errors (statics §4) */
		double *model = malloc(cv->n * sizeof(double));
		prsm_assembly_gaps *gaps = malloc(sizeof *gaps);
		if (model == NULL || gaps == NULL) {
			free(model);
			free(gaps);
			return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the model TE");
		}
		rc = prsm_calib_statics_te(model, &c->rq.as, &c->rq.errors, cv->angle_rad, cv->n, c->options.mode,
		                           c->options.measuring_load_N, gaps);
		free(gaps);
		if (rc) {
			free(model);
			return prsm_error_set(err, rc, NULL, "the statics TE of the error set did not converge");
		}
		prsm_meas_compare(&o->comparison, cv, model, c->meas.te_noise_sd_um, NULL);
		o->has_comparison = 1;
		free(model);
		/* §8.5 item 2 */
		double orders[PRSM_CALIB_LINE_KINDS];
		const int no = named_orders(orders, o->spectrum_kind, &kin, o->k_star);
		if ((rc = prsm_meas_spectrum_compute(&o->spectrum, cv, orders, no, err)))
			return rc;
		o->has_spectrum = 1;
		/* §8.5 item 3 */
		if (c->options.model == PRSM_CALIB_MODEL_LINE) {
			prsm_calib_options lo = c->options;
			if (isnan(lo.carrier_ratio_prior))
				lo.carrier_ratio_prior = o->k_star;
			if ((rc = prsm_calib_line(&o->line, cv, &kin, &lo, err)))
				return rc;
			o->has_line = 1;
		} else {
			if ((rc = prsm_calib_physical(&o->physical, &o->calibrated, cv, &c->rq.as, &c->rq.errors, c->fields,
			                              c->options.fields, &c->options, err)))
				return rc;
			o->has_physical = 1;
		}
	}
	/* §8.5 item 4 */
	const prsm_meas_data *ms = &c->meas;
	if (isfinite(ms->efficiency)) {
		const double F = isfinite(ms->efficiency_axial_load_N) ? ms->efficiency_axial_load_N : d->axial_load_N;
		const double w = isfinite(ms->efficiency_screw_speed_rad_s) ? ms->efficiency_screw_speed_rad_s : d->screw_speed_rad_s;
		prsm_error fe = PRSM_ERROR_INIT;
		rc = prsm_calib_friction_compute(&o->friction, d, ms->efficiency, ms->efficiency_sd, F, w, &fe);
		if (rc) {
			*err = fe;
			return rc;
		}
		if (!o->friction.found)
			prsm_problems_add(&o->warnings, "/measured/efficiency", "no_friction", "%s", fe.message);
		o->has_friction = 1;
	}
	if (isfinite(ms->cage_ratio)) {
		const double F = isfinite(ms->cage_axial_load_N) ? ms->cage_axial_load_N : dyn.load.value;
		const double w = isfinite(ms->cage_screw_speed_rad_s) ? ms->cage_screw_speed_rad_s : dyn.input.signal.value;
		if ((rc = prsm_calib_cage_compute(&o->cage, d, &c->rq.a, &dyn, ms->cage_ratio, ms->cage_ratio_sd, F, w, err)))
			return rc;
		if (o->cage.above_k_star)
			prsm_problems_add(&o->warnings, "/measured/cage_ratio", "above_min_slip",
			                  "the measured cage ratio %.6g is above the minimum-slip ratio k* = %.6f: a carrier drag "
			                  "only lowers it, so drag cannot explain it", ms->cage_ratio, o->cage.k_star);
		o->has_cage = 1;
	}
	c->ran = 1;
	return 0;
}

cJSON *prsm_app_calibration_result(const prsm_app_calibration *c)
{
	return c->ran ? prsm_io_calibration_to_json(&c->out) : NULL;
}

int prsm_app_calibration_text(FILE *f, const prsm_app_calibration *c)
{
	return c->ran ? prsm_app_text_calibration(f, &c->out) : PRSM_EINVAL;
}

const prsm_io_calibration *prsm_app_calibration_data(const prsm_app_calibration *c)
{
	return &c->out;
}

void prsm_app_calibration_free(prsm_app_calibration *c)
{
	if (c == NULL)
		return;
	if (c->rq_loaded)
		prsm_io_analyze_free(&c->rq);
	prsm_meas_data_free(&c->meas);
	prsm_meas_curve_free(&c->csv_curve);
	prsm_io_csv_origin_free(&c->origin);
	prsm_meas_spectrum_free(&c->out.spectrum);
	prsm_calib_line_free(&c->out.line);
	prsm_calib_physical_free(&c->out.physical);
	free(c);
}
