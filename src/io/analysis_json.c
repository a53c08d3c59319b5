/*
 * analysis_json.c: mapping the nominal analysis to its JSON result and a text summary.
 * Engine units (mm, N, MPa, rad) are converted here to the units the field names say.
 */
#include "io/analysis_json.h"

#include <math.h>

#include "io/json_util.h"

#include "model/geometry.h"

#define DEG (180.0 / M_PI)
#define RPM_PER_RAD_S (60.0 / (2.0 * M_PI))

#ifndef PRSM_VERSION
#define PRSM_VERSION "0.0.0"
#endif
#define PRSM_MODEL_VERSION "MODEL.md 2026-11 (§1, §2, §3, §4, §5, §6)"

static void vec(cJSON *o, const char *name, const double *v, int n)
{
	cJSON *arr = cJSON_AddArrayToObject(o, name);
	for (int i = 0; i < n; i++)
		cJSON_AddItemToArray(arr, cJSON_CreateNumber(v[i]));
}

cJSON *prsm_io_problems_to_json(const prsm_problems *p)
{
	cJSON *arr = cJSON_CreateArray();
	for (int i = 0; arr && i < p->count; i++) {
		cJSON *it = cJSON_CreateObject();
		cJSON_AddStringToObject(it, "pointer", p->items[i].pointer);
		if (p->items[i].code[0])
			cJSON_AddStringToObject(it, "code", p->items[i].code);
		cJSON_AddStringToObject(it, "message", p->items[i].message);
		cJSON_AddItemToArray(arr, it);
	}
	if (arr && p->dropped) {
		cJSON *it = cJSON_CreateObject();
		cJSON_AddStringToObject(it, "pointer", "");
		cJSON_AddStringToObject(it, "code", "truncated");
		char msg[96];
		snprintf(msg, sizeof msg, "%d more problems not listed", p->dropped);
		cJSON_AddStringToObject(it, "message", msg);
		cJSON_AddItemToArray(arr, it);
	}
	return arr;
}

cJSON *prsm_io_problem_document(int status, const char *title, const prsm_problems *p)
{
	cJSON *doc = cJSON_CreateObject();
	cJSON_AddStringToObject(doc, "type", "about:blank");
	cJSON_AddStringToObject(doc, "title", title);
	cJSON_AddNumberToObject(doc, "status", status);
	char detail[PRSM_PROBLEM_POINTER_MAX + PRSM_PROBLEM_MESSAGE_MAX + 8];
	if (p->count == 1)
		snprintf(detail, sizeof detail, "%s: %s", p->items[0].pointer, p->items[0].message);
	else
		snprintf(detail, sizeof detail, "%d problems in the request", prsm_problems_total(p));
	cJSON_AddStringToObject(doc, "detail", detail);
	cJSON_AddItemToObject(doc, "errors", prsm_io_problems_to_json(p));
	return doc;
}

static cJSON *contact_json(const prsm_contact *c, double gap0_mm, const double est[2])
{
	cJSON *o = cJSON_CreateObject();
	prsm_json_add_number(o, "x_mm", c->x_mm);
	prsm_json_add_number(o, "y_mm", c->y_mm);
	prsm_json_add_number(o, "gap_um", c->gap_mm * 1e3);
	prsm_json_add_number(o, "gap_unthinned_um", gap0_mm * 1e3);
	prsm_json_add_number(o, "contact_radius_body_mm", c->body_rho_mm);
	prsm_json_add_number(o, "contact_radius_roller_mm", c->roller_u_mm);
	prsm_json_add_number(o, "angle_on_body_deg", c->body_angle_rad * DEG);
	prsm_json_add_number(o, "angle_on_roller_deg", c->roller_angle_rad * DEG);
	vec(o, "normal_radial_tangential_axial", c->normal, 3);
	vec(o, "relative_curvatures_per_mm", c->curvature_per_mm, 2);
	vec(o, "relative_curvatures_estimate_per_mm", est, 2);
	cJSON_AddNumberToObject(o, "newton_iterations", c->iterations);
	cJSON_AddBoolToObject(o, "edge_contact", c->edge != 0);
	return o;
}

static cJSON *hertz_json(const prsm_hertz *h)
{
	cJSON *o = cJSON_CreateObject();
	prsm_json_add_number(o, "normal_load_N", h->load_N);
	prsm_json_add_number(o, "sum_rho_per_mm", h->sum_rho_per_mm);
	prsm_json_add_number(o, "curvature_difference", h->curvature_difference);
	prsm_json_add_number(o, "ellipticity_a_over_b", h->kappa);
	prsm_json_add_number(o, "semi_major_a_mm", h->a_mm);
	prsm_json_add_number(o, "semi_minor_b_mm", h->b_mm);
	prsm_json_add_number(o, "approach_um", h->delta_mm * 1e3);
	prsm_json_add_number(o, "p_max_MPa", h->p_max_MPa);
	return o;
}

static cJSON *material_json(const prsm_material *m)
{
	cJSON *o = cJSON_CreateObject();
	prsm_json_add_number(o, "E_GPa", m->E_MPa * 1e-3);
	prsm_json_add_number(o, "poisson", m->poisson);
	return o;
}

/* The design as the engine used it, every default and derived radius filled in. */
static cJSON *design_json(const prsm_design *d)
{
	cJSON *o = cJSON_CreateObject();
	cJSON *g = cJSON_AddObjectToObject(o, "geometry");
	cJSON_AddNumberToObject(g, "starts", d->starts);
	cJSON_AddStringToObject(g, "hand", d->hand == PRSM_HAND_LEFT ? "left" : "right");
	prsm_json_add_number(g, "pitch_mm", d->pitch_mm);
	prsm_json_add_number(g, "flank_angle_deg", d->flank_angle_rad * DEG);
	prsm_json_add_number(g, "screw_radius_mm", d->screw_radius_mm);
	prsm_json_add_number(g, "roller_radius_mm", d->roller_radius_mm);
	prsm_json_add_number(g, "nut_radius_mm", d->nut_radius_mm);
	prsm_json_add_number(g, "roller_arc_radius_mm", d->roller_arc_radius_mm);
	prsm_json_add_number(g, "screw_crest_radius_mm", d->screw_crest_radius_mm);
	prsm_json_add_number(g, "screw_root_radius_mm", d->screw_root_radius_mm);
	prsm_json_add_number(g, "roller_crest_radius_mm", d->roller_crest_radius_mm);
	prsm_json_add_number(g, "roller_root_radius_mm", d->roller_root_radius_mm);
	prsm_json_add_number(g, "nut_crest_radius_mm", d->nut_crest_radius_mm);
	prsm_json_add_number(g, "nut_root_radius_mm", d->nut_root_radius_mm);
	cJSON_AddNumberToObject(g, "rollers", d->rollers);
	cJSON_AddNumberToObject(g, "engaged_threads", d->engaged_threads);
	prsm_json_add_number(g, "running_clearance_mm", d->running_clearance_mm);
	cJSON *t = cJSON_AddObjectToObject(o, "thinning");
	prsm_json_add_number(t, "screw_um", 2e3 * d->flank_shift_screw_mm);
	prsm_json_add_number(t, "roller_um", 2e3 * d->flank_shift_roller_mm);
	prsm_json_add_number(t, "nut_um", 2e3 * d->flank_shift_nut_mm);
	cJSON *m = cJSON_AddObjectToObject(o, "materials");
	cJSON_AddItemToObject(m, "screw", material_json(&d->screw_material));
	cJSON_AddItemToObject(m, "roller", material_json(&d->roller_material));
	cJSON_AddItemToObject(m, "nut", material_json(&d->nut_material));
	cJSON *f = cJSON_AddObjectToObject(o, "friction");
	prsm_json_add_number(f, "screw_roller", d->mu_screw_roller);
	prsm_json_add_number(f, "nut_roller", d->mu_nut_roller);
	cJSON *op = cJSON_AddObjectToObject(o, "operating_point");
	prsm_json_add_number(op, "axial_load_N", d->axial_load_N);
	prsm_json_add_number(op, "screw_speed_rpm", d->screw_speed_rad_s * RPM_PER_RAD_S);
	return o;
}

cJSON *prsm_io_analysis_to_json(const prsm_analysis *a, const prsm_design *d,
                                const prsm_problems *warnings)
{
	cJSON *root = cJSON_CreateObject();
	if (root == NULL)
		return NULL;
	cJSON *eng = cJSON_AddObjectToObject(root, "engine");
	cJSON_AddStringToObject(eng, "name", "prsm");
	cJSON_AddStringToObject(eng, "version", PRSM_VERSION);
	cJSON_AddStringToObject(eng, "model", PRSM_MODEL_VERSION);

	cJSON_AddItemToObject(root, "design", design_json(d));
	cJSON_AddItemToObject(root, "warnings", prsm_io_problems_to_json(warnings));

	const prsm_geometry *g = &a->geometry;
	cJSON *geo = cJSON_AddObjectToObject(root, "geometry");
	prsm_json_add_number(geo, "lead_mm", g->lead_mm);
	prsm_json_add_number(geo, "orbit_radius_mm", g->orbit_radius_mm);
	prsm_json_add_number(geo, "helix_angle_screw_deg", g->helix_screw_rad * DEG);
	prsm_json_add_number(geo, "helix_angle_roller_deg", g->helix_roller_rad * DEG);
	prsm_json_add_number(geo, "helix_angle_nut_deg", g->helix_nut_rad * DEG);
	cJSON_AddNumberToObject(geo, "z_max", g->z_max);
	prsm_json_add_number(geo, "ring_gear_ratio", g->ring_gear_ratio);
	prsm_json_add_number(geo, "roller_migration_mm_per_carrier_rev", g->migration_mm_per_rad * 2.0 * M_PI);
	cJSON_AddBoolToObject(geo, "standard_rules", g->standard_rules);

	cJSON *th = cJSON_AddObjectToObject(root, "thinning");
	cJSON_AddStringToObject(th, "rule", d->thinning_rule == PRSM_THINNING_EQUAL_GAPS
	                                        ? "equal_gaps: roller unthinned, screw and nut thinned so both flank gaps equal a quarter of the target clearance"
	                                        : "given");
	if (d->thinning_rule == PRSM_THINNING_EQUAL_GAPS)
		prsm_json_add_number(th, "target_axial_clearance_um", d->target_axial_clearance_mm * 1e3);
	prsm_json_add_number(th, "flank_shift_screw_um", d->flank_shift_screw_mm * 1e3);
	prsm_json_add_number(th, "flank_shift_roller_um", d->flank_shift_roller_mm * 1e3);
	prsm_json_add_number(th, "flank_shift_nut_um", d->flank_shift_nut_mm * 1e3);

	cJSON *con = cJSON_AddObjectToObject(root, "contacts");
	cJSON_AddItemToObject(con, "screw_roller", contact_json(&a->screw, a->gap0_screw_mm, a->curvature_estimate_screw));
	cJSON_AddItemToObject(con, "nut_roller", contact_json(&a->nut, a->gap0_nut_mm, a->curvature_estimate_nut));
	prsm_json_add_number(con, "offset_rule_mm", a->offset_rule_mm);
	prsm_json_add_number(root, "backlash_um", a->backlash_mm * 1e3);

	const prsm_kinematics *k = &a->kinematics;
	const double w = d->screw_speed_rad_s;
	cJSON *kin = cJSON_AddObjectToObject(root, "kinematics");
	prsm_json_add_number(kin, "carrier_ratio_ideal", k->carrier_ratio_ideal);
	prsm_json_add_number(kin, "carrier_ratio", k->carrier_ratio);
	prsm_json_add_number(kin, "roller_spin_ratio_ideal", k->roller_spin_ratio_ideal);
	prsm_json_add_number(kin, "roller_spin_ratio", k->roller_spin_ratio);
	prsm_json_add_number(kin, "roller_absolute_ratio_ideal", k->roller_abs_ratio_ideal);
	prsm_json_add_number(kin, "roller_absolute_ratio", k->roller_abs_ratio);
	prsm_json_add_number(kin, "nut_travel_per_screw_rev_mm", fabs(k->nut_speed_mm_per_rad) * 2.0 * M_PI);
	prsm_json_add_number(kin, "slip_ratio_screw", k->slip_ratio_screw);
	prsm_json_add_number(kin, "slip_ratio_nut", k->slip_ratio_nut);
	prsm_json_add_number(kin, "nut_speed_mm_s", k->nut_speed_mm_per_rad * w);
	prsm_json_add_number(kin, "carrier_speed_rpm", k->carrier_ratio * w * RPM_PER_RAD_S);
	prsm_json_add_number(kin, "roller_spin_speed_rpm", k->roller_spin_ratio * w * RPM_PER_RAD_S);
	prsm_json_add_number(kin, "slip_speed_screw_mm_s", k->slip_ratio_screw * fabs(k->nut_speed_mm_per_rad * w));

	const prsm_efficiency *e = &a->efficiency;
	cJSON *eff = cJSON_AddObjectToObject(root, "efficiency");
	cJSON_AddStringToObject(eff, "model", "sliding friction at the screw and nut contacts, 3-D normals and slip (MODEL.md §5); spin, gear-mesh and drag losses not included");
	prsm_json_add_number(eff, "eta", e->eta);
	prsm_json_add_number(eff, "eta_back", e->eta_back);
	prsm_json_add_number(eff, "eta_closed_form", e->eta_closed_form);
	prsm_json_add_number(eff, "eta_back_closed_form", e->eta_back_closed_form);
	prsm_json_add_number(eff, "input_torque_Nm", e->input_torque_Nm);
	prsm_json_add_number(eff, "ideal_torque_Nm", e->ideal_torque_Nm);
	prsm_json_add_number(eff, "friction_torque_Nm", e->friction_torque_Nm);
	prsm_json_add_number(eff, "back_driving_torque_Nm", e->back_torque_Nm);
	prsm_json_add_number(eff, "input_power_W", e->input_power_W);
	prsm_json_add_number(eff, "output_power_W", e->output_power_W);
	prsm_json_add_number(eff, "loss_power_W", e->loss_power_W);

	cJSON *hz = cJSON_AddObjectToObject(root, "hertz");
	cJSON_AddStringToObject(hz, "load_sharing", "equal over rollers and engaged threads; normal load = axial load per contact / axial part of the normal");
	cJSON_AddNumberToObject(hz, "contacts_per_side", a->contacts_sharing);
	prsm_json_add_number(hz, "axial_load_per_contact_N", a->axial_load_per_contact_N);
	cJSON_AddItemToObject(hz, "screw_roller", hertz_json(&a->hertz_screw));
	cJSON_AddItemToObject(hz, "nut_roller", hertz_json(&a->hertz_nut));
	return root;
}

void prsm_io_analysis_print_text(FILE *out, const prsm_analysis *a, const prsm_design *d,
                                 const prsm_problems *warnings)
{
	const prsm_geometry *g = &a->geometry;
	const prsm_kinematics *k = &a->kinematics;
	const prsm_efficiency *e = &a->efficiency;
	fprintf(out, "PRSM nominal analysis (prsm %s, %s)\n\n", PRSM_VERSION, PRSM_MODEL_VERSION);
	fprintf(out, "Geometry\n");
	fprintf(out, "  starts %d (%s hand), pitch %.4g mm, lead %.4g mm, flank half-angle %.4g deg\n",
	        d->starts, d->hand == PRSM_HAND_LEFT ? "left" : "right", d->pitch_mm, g->lead_mm,
	        d->flank_angle_rad * DEG);
	fprintf(out, "  pitch radii: screw %.4f, roller %.4f, nut %.4f mm; orbit %.4f mm; R %.4f mm\n",
	        d->screw_radius_mm, d->roller_radius_mm, d->nut_radius_mm, g->orbit_radius_mm,
	        d->roller_arc_radius_mm);
	fprintf(out, "  helix angles: screw %.4f, roller %.4f, nut %.4f deg\n", g->helix_screw_rad * DEG,
	        g->helix_roller_rad * DEG, g->helix_nut_rad * DEG);
	fprintf(out, "  rollers %d of Z_max %d, engaged threads %d\n\n", d->rollers, g->z_max,
	        d->engaged_threads);
	fprintf(out, "Contacts                     screw-roller     nut-roller\n");
	fprintf(out, "  point x, y (mm)         %8.5f %7.5f %8.5f %7.5f\n", a->screw.x_mm, a->screw.y_mm,
	        a->nut.x_mm, a->nut.y_mm);
	fprintf(out, "  gap unthinned (um)         %10.3f     %10.3f\n", a->gap0_screw_mm * 1e3,
	        a->gap0_nut_mm * 1e3);
	fprintf(out, "  gap (um)                   %10.3f     %10.3f\n", a->screw.gap_mm * 1e3,
	        a->nut.gap_mm * 1e3);
	fprintf(out, "  angle on body (deg)        %10.4f     %10.4f\n", a->screw.body_angle_rad * DEG,
	        a->nut.body_angle_rad * DEG);
	fprintf(out, "  angle on roller (deg)      %10.4f     %10.4f\n", a->screw.roller_angle_rad * DEG,
	        a->nut.roller_angle_rad * DEG);
	fprintf(out, "  Hertz p_max (MPa)          %10.1f     %10.1f\n", a->hertz_screw.p_max_MPa,
	        a->hertz_nut.p_max_MPa);
	fprintf(out, "  Hertz a x b (mm)        %6.4f x %6.4f %6.4f x %6.4f\n", a->hertz_screw.a_mm,
	        a->hertz_screw.b_mm, a->hertz_nut.a_mm, a->hertz_nut.b_mm);
	fprintf(out, "  nominal axial backlash %.3f um\n\n", a->backlash_mm * 1e3);
	fprintf(out, "Kinematics (nut held)\n");
	fprintf(out, "  carrier ratio %.5f (ideal %.5f), roller spin %.5f relative to carrier\n",
	        k->carrier_ratio, k->carrier_ratio_ideal, k->roller_spin_ratio);
	fprintf(out, "  sliding at the screw contact %.4f x nut speed\n\n", k->slip_ratio_screw);
	fprintf(out, "Efficiency (sliding, mu %.3g)\n", d->mu_screw_roller);
	fprintf(out, "  eta %.4f (closed form %.4f), back-driving %.4f (closed form %.4f)\n", e->eta,
	        e->eta_closed_form, e->eta_back, e->eta_back_closed_form);
	fprintf(out, "  at %.6g N: input torque %.4g N m (ideal %.4g N m)\n\n", d->axial_load_N,
	        e->input_torque_Nm, e->ideal_torque_Nm);
	fprintf(out, "Warnings: %d\n", prsm_problems_total(warnings));
	for (int i = 0; i < warnings->count; i++)
		fprintf(out, "  %s: %s\n", warnings->items[i].pointer, warnings->items[i].message);
}
