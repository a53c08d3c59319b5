/*
 * analysis_json.c: mapping the nominal analysis to its JSON result and a text summary.
 * Engine units (mm, N, MPa, rad) are converted here to the units the field names say.
 */
#include "io/analysis_json.h"

#include <math.h>

#include "io/design_json.h"
#include "io/json_util.h"

#include "model/geometry.h"
#include "model/life.h"
#include "util/version.h"

#define DEG (180.0 / M_PI)
#define RPM_PER_RAD_S (60.0 / (2.0 * M_PI))

#ifndef PRSM_VERSION
#define PRSM_VERSION "0.0.0"
#endif

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
	prsm_json_add_number(o, "density_kg_m3", m->density_kg_m3);
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
	prsm_json_add_number(g, "nut_outer_radius_mm",
	                     prsm_compliance_nut_outer_radius_mm(d->nut_outer_radius_mm, d));
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
	const prsm_design_losses *l = &d->losses;
	cJSON *lo = cJSON_AddObjectToObject(o, "losses");
	cJSON_AddBoolToObject(lo, "spin", l->spin);
	cJSON_AddBoolToObject(lo, "gear_mesh", l->gear_mesh);
	prsm_json_add_number(lo, "gear_friction", l->gear_friction);
	if (l->roller_gear_teeth)
		cJSON_AddNumberToObject(lo, "roller_gear_teeth", l->roller_gear_teeth);
	if (l->ring_gear_teeth)
		cJSON_AddNumberToObject(lo, "ring_gear_teeth", l->ring_gear_teeth);
	prsm_json_add_number(lo, "gear_contact_ratio", l->gear_contact_ratio);
	prsm_json_add_number(lo, "gear_pressure_angle_deg", l->gear_pressure_angle_rad * DEG);
	prsm_json_add_number(lo, "drag_torque_Nm", l->drag_torque_Nm);
	prsm_json_add_number(lo, "viscous_drag_Nm_s_per_rad", l->viscous_drag_Nm_s_per_rad);
	prsm_json_add_number(lo, "seal_torque_Nm", l->seal_torque_Nm);
	const prsm_design_stiffness *st = &d->stiffness;
	cJSON *so = cJSON_AddObjectToObject(o, "stiffness");
	cJSON *tc = cJSON_AddObjectToObject(so, "thread_compliance");
	cJSON_AddStringToObject(tc, "model", st->width_rule == PRSM_THREAD_COMPLIANCE_NONE ? "none" : "yamamoto");
	if (st->width_rule != PRSM_THREAD_COMPLIANCE_NONE)
		cJSON_AddStringToObject(tc, "width", prsm_io_width_names[st->width_rule - PRSM_THREAD_WIDTH_SHARE]);
	if (st->width_rule == PRSM_THREAD_WIDTH_SHARE)
		prsm_json_add_number(tc, "width_fraction", st->width_fraction);
	if (st->width_rule == PRSM_THREAD_WIDTH_GIVEN)
		prsm_json_add_number(tc, "width_mm", st->width_mm);
	if (st->width_rule == PRSM_THREAD_WIDTH_ELLIPSE)
		prsm_json_add_number(tc, "ellipse_factor", st->ellipse_factor);
	prsm_json_add_number(tc, "calibration", st->calibration);
	cJSON_AddStringToObject(tc, "negative_terms", prsm_io_negative_terms_names[st->negative_terms]);
	cJSON_AddStringToObject(so, "load_entry", prsm_io_load_entry_names[st->load_entry]);
	if (st->curve_points > 0) {
		cJSON *cu = cJSON_AddObjectToObject(so, "load_deflection_curve");
		cJSON_AddNumberToObject(cu, "points", st->curve_points);
		if (!isnan(st->curve_max_load_N))
			prsm_json_add_number(cu, "max_load_N", st->curve_max_load_N);
	}
	const prsm_design_life *lf = &d->life;
	cJSON *li = cJSON_AddObjectToObject(o, "life");
	prsm_json_add_number(li, "p_allow_MPa", lf->p_allow_MPa);
	cJSON_AddNumberToObject(li, "reliability_percent", lf->reliability_percent);
	if (lf->duty_steps > 0) {
		cJSON *dc = cJSON_AddArrayToObject(li, "duty_cycle");
		for (int i = 0; i < lf->duty_steps; i++) {
			cJSON *step = cJSON_CreateObject();
			prsm_json_add_number(step, "axial_load_N", lf->duty_load_N[i]);
			prsm_json_add_number(step, "travel_mm", lf->duty_travel_mm[i]);
			cJSON_AddItemToArray(dc, step);
		}
	}
	prsm_json_add_number(li, "preload_N", lf->preload_N);
	prsm_json_add_number(li, "lp_material_factor", lf->lp_material_factor);
	if (lf->column) {
		cJSON *co = cJSON_AddObjectToObject(o, "column");
		prsm_json_add_number(co, "free_length_mm", lf->free_length_mm);
		cJSON_AddStringToObject(co, "fixity", prsm_io_fixity_names[lf->fixity]);
	}
	return o;
}

static cJSON *tooth_json(const prsm_thread_compliance *t)
{
	cJSON *o = cJSON_CreateObject();
	prsm_json_add_number(o, "width_mm", t->width_mm);
	prsm_json_add_number(o, "root_thickness_mm", t->tooth.root_thickness_mm);
	prsm_json_add_number(o, "load_thickness_mm", t->tooth.load_thickness_mm);
	prsm_json_add_number(o, "load_height_mm", t->tooth.load_height_mm);
	cJSON *terms = cJSON_AddObjectToObject(o, "yamamoto_terms_mm2_per_N");
	prsm_json_add_number(terms, "bending", t->terms.bending);
	prsm_json_add_number(terms, "shear", t->terms.shear);
	prsm_json_add_number(terms, "root_tilt", t->terms.root_tilt);
	prsm_json_add_number(terms, "root_shear", t->terms.root_shear);
	prsm_json_add_number(terms, "radial", t->terms.radial);
	prsm_json_add_number(terms, "sum_used", t->terms.sum_mm2_per_N);
	cJSON *neg = cJSON_AddArrayToObject(o, "negative_terms");
	static const char *const names[] = {"bending", "shear", "root_tilt", "root_shear", "radial"};
	for (int i = 0; i < 5; i++)
		if (t->terms.negative_terms & (1 << i))
			cJSON_AddItemToArray(neg, cJSON_CreateString(names[i]));
	prsm_json_add_number(o, "compliance_um_per_kN", t->compliance_mm_per_N * 1e6);
	return o;
}

static void losses_json(cJSON *root, const prsm_performance *p)
{
	const prsm_losses_result *l = &p->losses;
	cJSON *eff = cJSON_AddObjectToObject(root, "efficiency");
	cJSON_AddStringToObject(eff, "model", "sliding friction at the screw and nut contacts (3-D normals and slip), spin friction (3/8) mu Q a E(e) at every contact of the load distribution, ring-gear mesh loss (Ohlendorf's H_v, internal mesh), drag and seal torques (docs/model/kinematics-efficiency-stiffness-life.md); T = F L / (2 pi eta_sliding) + T_spin + T_gear + T_drag + T_seal");
	prsm_json_add_number(eff, "eta", l->eta);
	prsm_json_add_number(eff, "eta_back", l->eta_back);
	prsm_json_add_number(eff, "eta_sliding", l->eta_slide);
	prsm_json_add_number(eff, "eta_back_sliding", l->eta_back_slide);
	prsm_json_add_number(eff, "eta_closed_form", l->eta_closed_form);
	prsm_json_add_number(eff, "eta_back_closed_form", l->eta_back_closed_form);
	cJSON_AddBoolToObject(eff, "self_locking", (l->flags & PRSM_LOSSES_SELF_LOCKING) != 0);
	cJSON_AddBoolToObject(eff, "drive_locked", (l->flags & PRSM_LOSSES_DRIVE_LOCKED) != 0);
	cJSON *t = cJSON_AddObjectToObject(eff, "torque_Nm");
	prsm_json_add_number(t, "ideal", l->ideal_torque_Nm);
	prsm_json_add_number(t, "sliding", l->sliding_torque_Nm);
	prsm_json_add_number(t, "spin", l->spin_torque_Nm);
	prsm_json_add_number(t, "gear_mesh", l->gear_torque_Nm);
	prsm_json_add_number(t, "drag", l->drag_torque_Nm);
	prsm_json_add_number(t, "seal", l->seal_torque_Nm);
	prsm_json_add_number(t, "input", l->input_torque_Nm);
	prsm_json_add_number(eff, "back_driving_output_torque_Nm", l->back_output_torque_Nm);
	cJSON *w = cJSON_AddObjectToObject(eff, "power_W");
	prsm_json_add_number(w, "input", l->input_power_W);
	prsm_json_add_number(w, "output", l->output_power_W);
	prsm_json_add_number(w, "sliding", l->sliding_power_W);
	prsm_json_add_number(w, "spin", l->spin_power_W);
	prsm_json_add_number(w, "gear_mesh", l->gear_power_W);
	prsm_json_add_number(w, "drag", l->drag_power_W);
	prsm_json_add_number(w, "seal", l->seal_power_W);
	prsm_json_add_number(w, "loss", l->loss_power_W);
	cJSON *sp = cJSON_AddObjectToObject(eff, "spin");
	prsm_json_add_number(sp, "speed_screw_contact_rad_s", l->spin_speed_screw_rad_s);
	prsm_json_add_number(sp, "speed_nut_contact_rad_s", l->spin_speed_nut_rad_s);
	prsm_json_add_number(sp, "moment_screw_side_per_roller_Nm", l->spin_moment_screw_Nm);
	prsm_json_add_number(sp, "moment_nut_side_per_roller_Nm", l->spin_moment_nut_Nm);
	cJSON *g = cJSON_AddObjectToObject(eff, "gear_mesh");
	cJSON_AddNumberToObject(g, "roller_teeth", l->gear_teeth_roller);
	cJSON_AddNumberToObject(g, "ring_teeth", l->gear_teeth_ring);
	prsm_json_add_number(g, "contact_ratio", l->gear_eps_alpha);
	prsm_json_add_number(g, "loss_factor_Hv", l->gear_Hv);
	prsm_json_add_number(g, "roller_moment_Nm", l->roller_moment_Nm);
	prsm_json_add_number(g, "tangential_force_per_roller_N", l->gear_tangential_force_N);
	prsm_json_add_number(g, "pitch_speed_m_s", l->gear_pitch_speed_m_s);
}

static void side_json(cJSON *o, const char *name, const prsm_loaddist_side_result *s,
                      const double *loads, int n)
{
	cJSON *x = cJSON_AddObjectToObject(o, name);
	cJSON *arr = cJSON_AddArrayToObject(x, "thread_loads_N");
	for (int i = 0; i < n; i++)
		cJSON_AddItemToArray(arr, cJSON_CreateNumber(loads[i]));
	prsm_json_add_number(x, "max_over_mean", s->max_over_mean);
	cJSON_AddNumberToObject(x, "most_loaded_thread", s->max_index + 1);
	prsm_json_add_number(x, "most_loaded_axial_N", s->max_axial_N);
	prsm_json_add_number(x, "most_loaded_normal_N", s->max_normal_N);
	prsm_json_add_number(x, "p_max_MPa", s->p_max_MPa);
	prsm_json_add_number(x, "semi_major_a_mm", s->a_mm);
	prsm_json_add_number(x, "semi_minor_b_mm", s->b_mm);
	cJSON_AddNumberToObject(x, "lifted_off_contacts", s->lifted_off);
}

/* Thread compliance, load distribution, stiffness, capacity, life, column (docs/model/kinematics-efficiency-stiffness-life.md). */
static void performance_json(cJSON *root, const prsm_performance *p, const prsm_design *d)
{
	const prsm_design_compliance *c = &p->compliance;
	cJSON *tc = cJSON_AddObjectToObject(root, "thread_compliance");
	const int none = c->options.width_rule == PRSM_THREAD_COMPLIANCE_NONE;
	static const char *const rules[] = {"none: rigid threads",
		"yamamoto, width share: width_fraction x the thread circumference at the pitch radius per contact (2 pi r_s / Z screw, 2 pi r_n / Z nut, pi r_r roller)",
		"yamamoto, width given", "yamamoto, width ellipse: ellipse_factor x the Hertz major axis 2a at the operating load"};
	cJSON_AddStringToObject(tc, "rule", rules[c->options.width_rule]);
	cJSON_AddStringToObject(tc, "caution", "thread stiffness is uncertain by a factor of about 3 between the width rules (docs/model/kinematics-efficiency-stiffness-life.md): compare them before trusting a stiffness");
	prsm_json_add_number(tc, "calibration", c->options.calibration);
	cJSON_AddStringToObject(tc, "negative_terms", prsm_io_negative_terms_names[c->options.negative_terms]);
	prsm_json_add_number(tc, "nut_outer_radius_mm", c->nut_outer_radius_mm);
	if (!none) {
		cJSON_AddItemToObject(tc, "screw", tooth_json(&c->screw));
		cJSON_AddItemToObject(tc, "roller_screw_side", tooth_json(&c->roller_screw_side));
		cJSON_AddItemToObject(tc, "roller_nut_side", tooth_json(&c->roller_nut_side));
		cJSON_AddItemToObject(tc, "nut", tooth_json(&c->nut));
	}
	prsm_json_add_number(tc, "screw_side_um_per_kN", c->screw_side_mm_per_N * 1e6);
	prsm_json_add_number(tc, "nut_side_um_per_kN", c->nut_side_mm_per_N * 1e6);
	cJSON *seg = cJSON_AddObjectToObject(tc, "body_stretch_per_pitch_um_per_kN");
	prsm_json_add_number(seg, "screw_core", p->segments.screw_mm_per_N * 1e6);
	prsm_json_add_number(seg, "roller_core", p->segments.roller_mm_per_N * 1e6);
	prsm_json_add_number(seg, "nut_body", p->segments.nut_mm_per_N * 1e6);

	const double F = fabs(d->axial_load_N);
	cJSON *ld = cJSON_AddObjectToObject(root, "load_distribution");
	cJSON_AddStringToObject(ld, "model", "spring chain per roller (docs/model/kinematics-efficiency-stiffness-life.md): Hertz + thread compliance per contact, screw core, roller core and nut body stretch between threads; rollers share the load equally");
	cJSON_AddStringToObject(ld, "load_entry", prsm_io_load_entry_names[d->stiffness.load_entry]);
	prsm_json_add_number(ld, "axial_load_N", F);
	cJSON_AddNumberToObject(ld, "rollers", d->rollers);
	cJSON_AddNumberToObject(ld, "threads", p->threads);
	if (F > 0.0) {
		prsm_json_add_number(ld, "roller_load_N", p->dist.roller_load_N);
		side_json(ld, "screw_side", &p->dist.side[PRSM_SIDE_SCREW], p->thread_load_screw_N, p->threads);
		side_json(ld, "nut_side", &p->dist.side[PRSM_SIDE_NUT], p->thread_load_nut_N, p->threads);
		cJSON_AddNumberToObject(ld, "iterations", p->dist.iterations);
	}

	cJSON *st = cJSON_AddObjectToObject(root, "stiffness");
	cJSON_AddStringToObject(st, "includes", "nut unit over the engagement: Hertz contacts, thread compliance, screw core, roller cores and nut body; not the support bearings, the housing or the screw outside the nut");
	prsm_json_add_number(st, "at_load_N", F);
	prsm_json_add_number(st, "axial_N_per_um", F > 0.0 ? p->stiffness_N_per_um : NAN);
	prsm_json_add_number(st, "approach_um", F > 0.0 ? p->dist.approach_mm * 1e3 : 0.0);
	if (p->curve_points > 0) {
		cJSON *cu = cJSON_AddArrayToObject(st, "load_deflection_curve");
		for (int i = 0; i < p->curve_points; i++) {
			cJSON *pt = cJSON_CreateObject();
			prsm_json_add_number(pt, "load_N", p->curve_load_N[i]);
			prsm_json_add_number(pt, "approach_um", p->curve_approach_um[i]);
			prsm_json_add_number(pt, "stiffness_N_per_um", p->curve_stiffness_N_per_um[i]);
			cJSON_AddItemToArray(cu, pt);
		}
	}

	cJSON *cap = cJSON_AddObjectToObject(root, "capacity");
	cJSON *s0 = cJSON_AddObjectToObject(cap, "static");
	cJSON_AddStringToObject(s0, "definition", "C_0a: the axial load at which the most loaded contact of the load distribution reaches p_allow (docs/model/kinematics-efficiency-stiffness-life.md), the smaller of the two sides");
	prsm_json_add_number(s0, "C0a_N", p->C0a_N);
	prsm_json_add_number(s0, "screw_side_N", p->C0a_screw_N);
	prsm_json_add_number(s0, "nut_side_N", p->C0a_nut_N);
	prsm_json_add_number(s0, "equal_sharing_screw_side_N", p->static_screw.C0a_N);
	prsm_json_add_number(s0, "equal_sharing_nut_side_N", p->static_nut.C0a_N);
	prsm_json_add_number(s0, "load_factor_screw_side", p->static_screw.load_factor);
	prsm_json_add_number(s0, "load_factor_nut_side", p->static_nut.load_factor);
	prsm_json_add_number(s0, "p_allow_MPa", p->static_screw.p_allow_MPa);
	prsm_json_add_number(s0, "safety_factor", p->static_safety);
	const prsm_dynamic_capacity *dy = &p->dynamic;
	cJSON *c1 = cJSON_AddObjectToObject(cap, "dynamic");
	cJSON_AddStringToObject(c1, "method", dy->method.name);
	cJSON *k = cJSON_AddObjectToObject(c1, "constants");
	prsm_json_add_number(k, "f_c_N_mm", dy->method.constant);
	prsm_json_add_number(k, "material_factor_b_m", dy->method.material_factor);
	prsm_json_add_number(k, "diameter_exponent", dy->method.diameter_exponent);
	prsm_json_add_number(k, "combination_exponent", dy->method.combination_exponent);
	prsm_json_add_number(k, "life_exponent", dy->method.life_exponent);
	prsm_json_add_number(k, "weibull_slope", dy->method.weibull_slope);
	cJSON_AddStringToObject(c1, "caution", "there is no ISO standard for roller screws; makers borrow from ball screws and bearings, and catalogue C_a values differ by maker");
	prsm_json_add_number(c1, "C_a_N", dy->C_a_N);
	prsm_json_add_number(c1, "distribution_factor", p->distribution_factor);
	prsm_json_add_number(c1, "ball_diameter_mm", dy->ball_diameter_mm);
	prsm_json_add_number(c1, "contact_angle_deg", dy->contact_angle_rad * DEG);
	prsm_json_add_number(c1, "gamma", dy->gamma);
	prsm_json_add_number(c1, "q_screw_N", dy->q_screw_N);
	prsm_json_add_number(c1, "q_nut_N", dy->q_nut_N);
	prsm_json_add_number(c1, "q_roller_screw_side_N", dy->q_roller_screw_side_N);
	prsm_json_add_number(c1, "q_roller_nut_side_N", dy->q_roller_nut_side_N);
	prsm_json_add_number(c1, "q_combined_N", dy->q_combined_N);
	prsm_json_add_number(c1, "thread_row_N", dy->row_N);

	const prsm_life_rating *lr = &p->life;
	cJSON *li = cJSON_AddObjectToObject(root, "life");
	cJSON_AddStringToObject(li, "definition", "L = a1 (C_a / F_e)^3 10^6 screw revolutions (docs/model/kinematics-efficiency-stiffness-life.md); F_e the cubic mean load of the duty cycle weighted by travel (or the operating load), raised by the preload derating; null when F_e = 0");
	prsm_json_add_number(li, "mean_load_N", p->mean_load_N);
	prsm_json_add_number(li, "equivalent_load_N", p->equivalent_load_N);
	cJSON_AddNumberToObject(li, "duty_cycle_steps", d->life.duty_steps);
	prsm_json_add_number(li, "preload_N", d->life.preload_N);
	cJSON_AddNumberToObject(li, "reliability_percent", lr->reliability_percent);
	prsm_json_add_number(li, "reliability_factor_a1", lr->reliability_factor);
	prsm_json_add_number(li, "revolutions", lr->revolutions);
	prsm_json_add_number(li, "hours", lr->hours > 0.0 ? lr->hours : NAN);
	prsm_json_add_number(li, "distance_km", lr->distance_km);

	if (p->has_column) {
		const prsm_column *co = &p->column;
		cJSON *cl = cJSON_AddObjectToObject(root, "column");
		cJSON_AddStringToObject(cl, "fixity", prsm_io_fixity_names[co->fixity]);
		prsm_json_add_number(cl, "free_length_mm", co->free_length_mm);
		prsm_json_add_number(cl, "root_diameter_mm", co->root_diameter_mm);
		prsm_json_add_number(cl, "critical_speed_rpm", co->critical_speed_rpm);
		prsm_json_add_number(cl, "catalogue_critical_speed_rpm", co->catalogue_speed_rpm);
		prsm_json_add_number(cl, "buckling_load_N", co->buckling_load_N);
		prsm_json_add_number(cl, "speed_margin", d->screw_speed_rad_s != 0.0 ? co->catalogue_speed_rpm / fabs(d->screw_speed_rad_s * RPM_PER_RAD_S) : NAN);
		prsm_json_add_number(cl, "buckling_margin", F > 0.0 ? co->buckling_load_N / F : NAN);
		cJSON_AddStringToObject(cl, "formulas", "critical speed: beam theory (60/2 pi) (lambda/L)^2 sqrt(E I / rho A) and the catalogue n = f_c d_r / L^2 10^7 (steel, with the catalogues' 0.8); buckling: Euler m pi^2 E I / L^2, I = pi d_r^4 / 64; no safety factor applied");
	}
}

cJSON *prsm_io_analysis_to_json(const prsm_analysis *a, const prsm_design *d,
                                const prsm_performance *perf, const prsm_problems *warnings)
{
	cJSON *root = cJSON_CreateObject();
	if (root == NULL)
		return NULL;
	cJSON *eng = cJSON_AddObjectToObject(root, "engine");
	cJSON_AddStringToObject(eng, "name", "prsm");
	cJSON_AddStringToObject(eng, "version", PRSM_VERSION);
	cJSON_AddStringToObject(eng, "model", PRSM_MODEL_VERSION);
	cJSON_AddStringToObject(eng, "build", prsm_engine_build());

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

	if (perf) {
		losses_json(root, perf);
	} else {
		const prsm_efficiency *e = &a->efficiency;
		cJSON *eff = cJSON_AddObjectToObject(root, "efficiency");
		cJSON_AddStringToObject(eff, "model", "sliding friction only, at the screw and nut contacts, 3-D normals and slip (docs/model/kinematics-efficiency-stiffness-life.md)");
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
	}

	cJSON *hz = cJSON_AddObjectToObject(root, "hertz");
	cJSON_AddStringToObject(hz, "load_sharing", "equal over rollers and engaged threads; normal load = axial load per contact / axial part of the normal");
	cJSON_AddNumberToObject(hz, "contacts_per_side", a->contacts_sharing);
	prsm_json_add_number(hz, "axial_load_per_contact_N", a->axial_load_per_contact_N);
	cJSON_AddItemToObject(hz, "screw_roller", hertz_json(&a->hertz_screw));
	cJSON_AddItemToObject(hz, "nut_roller", hertz_json(&a->hertz_nut));
	if (perf)
		performance_json(root, perf, d);
	return root;
}
