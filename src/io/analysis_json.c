/*
 * analysis_json.c: the analysis result (schemas/analysis.schema.json) by its generated tables:
 * the views they read, the values derived for them and the hooks.
 */
#include "io/analysis_json.h"

#include <math.h>

#include "model/compliance.h"
#include "prsm_io_writers.h"

#define RPM_PER_RAD_S (60.0 / (2.0 * M_PI))

cJSON *prsm_io_problem_document(int status, const char *title, const prsm_problems *p)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *doc = prsm_jw_root(&w);
	prsm_jw_string(&w, doc, "type", "about:blank");
	prsm_jw_string(&w, doc, "title", title);
	prsm_jw_number(&w, doc, "status", status);
	char detail[PRSM_PROBLEM_POINTER_MAX + PRSM_PROBLEM_MESSAGE_MAX + 8];
	if (p->count == 1 && p->items[0].pointer[0])
		snprintf(detail, sizeof detail, "%s: %s", p->items[0].pointer, p->items[0].message);
	else if (p->count == 1) /* the whole document: no pointer to put before the message */
		snprintf(detail, sizeof detail, "%s", p->items[0].message);
	else
		snprintf(detail, sizeof detail, "%d problems in the request", prsm_problems_total(p));
	prsm_jw_string(&w, doc, "detail", detail);
	prsm_jw_item(&w, doc, "errors", prsm_io_problems_to_json(p));
	return prsm_jw_done(&w, doc);
}

void prsm_io_whook_nut_outer_radius(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_design *d = at;
	prsm_jw_number(w, obj, key, prsm_compliance_nut_outer_radius_mm(d->nut_outer_radius_mm, d));
}

void prsm_io_analysis_write(prsm_jw *w, cJSON *obj, const prsm_analysis *a, const prsm_design *d,
                            const prsm_performance *p, const prsm_problems *warnings)
{
	const prsm_kinematics *k = &a->kinematics;
	const double s = d->screw_speed_rad_s, F = fabs(d->axial_load_N);
	prsm_io_analysis_view v = {
		.a = a, .d = d, .p = p, .warnings = warnings,
		.screw = {&a->screw, a->gap0_screw_mm, a->curvature_estimate_screw},
		.nut = {&a->nut, a->gap0_nut_mm, a->curvature_estimate_nut},
		.screw_side = {&p->dist.side[PRSM_SIDE_SCREW], p->thread_load_screw_N, p->threads,
		               p->dist.side[PRSM_SIDE_SCREW].max_index + 1},
		.nut_side = {&p->dist.side[PRSM_SIDE_NUT], p->thread_load_nut_N, p->threads,
		             p->dist.side[PRSM_SIDE_NUT].max_index + 1},
		.loaded = F > 0.0, .F = F,
		.nut_travel_mm = fabs(k->nut_speed_mm_per_rad) * 2.0 * M_PI,
		.nut_speed_mm_s = k->nut_speed_mm_per_rad * s,
		.carrier_speed_rpm = k->carrier_ratio * s * RPM_PER_RAD_S,
		.spin_speed_rpm = k->roller_spin_ratio * s * RPM_PER_RAD_S,
		.slip_speed_mm_s = k->slip_ratio_screw * fabs(k->nut_speed_mm_per_rad * s),
		.axial_N_per_um = F > 0.0 ? p->stiffness_N_per_um : NAN,
		.approach_um = F > 0.0 ? p->dist.approach_mm * 1e3 : 0.0,
		.hours = p->life.hours > 0.0 ? p->life.hours : NAN,
		.speed_margin = s != 0.0 ? p->column.catalogue_speed_rpm / fabs(s * RPM_PER_RAD_S) : NAN,
		.buckling_margin = F > 0.0 ? p->column.buckling_load_N / F : NAN,
	};
	prsm_io_write_fields(w, obj, &v, &prsm_io_w_analysis, 0);
}

cJSON *prsm_io_analysis_to_json(const prsm_analysis *a, const prsm_design *d,
                                const prsm_performance *perf, const prsm_problems *warnings)
{
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	prsm_io_analysis_write(&w, root, a, d, perf, warnings);
	return prsm_jw_done(&w, root);
}
