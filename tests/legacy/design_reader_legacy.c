/*
 * design_reader_legacy.c: the hand-written design reader as it was before the table-driven one
 * (src/io/doc.h, tables generated from schemas/design.schema.json), kept for the side-by-side
 * proof of issue 24 (tests/test_io_doc.c): both readers must give identical structs and problem
 * lists on every document. Delete it with that test once every document is ported.
 */
#include "legacy/design_reader_legacy.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>

#include "io/design_json.h"

#include "io/json_util.h"
#include "model/compliance.h"
#include "model/life.h"

static const char *const design_keys[] = {
	"name", "description", "geometry", "thinning", "target_axial_clearance_um", "materials",
	"friction", "operating_point", "losses", "stiffness", "life", "column", NULL};
static const char *const geometry_keys[] = {
	"starts", "hand", "pitch_mm", "flank_angle_deg", "roller_radius_mm", "screw_radius_mm",
	"nut_radius_mm", "roller_arc_radius_mm", "screw_crest_radius_mm", "screw_root_radius_mm",
	"roller_crest_radius_mm", "roller_root_radius_mm", "nut_crest_radius_mm", "nut_root_radius_mm",
	"rollers", "engaged_threads", "nut_length_mm", "running_clearance_mm", "nut_outer_radius_mm", NULL};
static const char *const thinning_keys[] = {"screw_um", "roller_um", "nut_um", NULL};
static const char *const materials_keys[] = {"screw", "roller", "nut", NULL};
static const char *const material_keys[] = {"E_GPa", "poisson", "density_kg_m3", NULL};
static const char *const friction_keys[] = {"screw_roller", "nut_roller", NULL};
static const char *const operating_keys[] = {"axial_load_N", "screw_speed_rpm", NULL};
static const char *const losses_keys[] = {
	"spin", "gear_mesh", "gear_friction", "roller_gear_teeth", "ring_gear_teeth",
	"gear_contact_ratio", "gear_pressure_angle_deg", "drag_torque_Nm", "viscous_drag_Nm_s_per_rad",
	"seal_torque_Nm", NULL};
static const char *const stiffness_keys[] = {"thread_compliance", "load_entry", "load_deflection_curve", NULL};
static const char *const compliance_keys[] = {
	"model", "width", "width_fraction", "width_mm", "ellipse_factor", "calibration", "negative_terms", NULL};
static const char *const curve_keys[] = {"points", "max_load_N", NULL};
static const char *const life_keys[] = {
	"p_allow_MPa", "reliability_percent", "duty_cycle", "preload_N", "lp_material_factor", NULL};
static const char *const duty_keys[] = {"axial_load_N", "travel_mm", NULL};
static const char *const column_keys[] = {"free_length_mm", "fixity", NULL};
/* enum names, in the order of the model's constants (design_json.h) */
static const char *const compliance_model_names[] = {"yamamoto", "none", NULL};
static const char *const legacy_width_names[] = {"share", "given", "ellipse", NULL};
static const char *const legacy_negative_terms_names[] = {"clamp", "keep", NULL};
static const char *const legacy_load_entry_names[] = {"same_side", "opposite_side", NULL};
static const char *const legacy_fixity_names[] = {"fixed_free", "supported_supported", "fixed_supported",
                                            "fixed_fixed", NULL};
static const char *const hand_names[] = {"right", "left", NULL}; /* index 0, 1 */

static prsm_json_range range(double min, int min_exclusive, double max, int max_exclusive)
{
	return (prsm_json_range){min, max, min_exclusive, max_exclusive};
}

/* (0, inf): lengths and radii */
static prsm_json_range positive(void)
{
	return range(0.0, 1, INFINITY, 0);
}

/* obj[key] is there at all, whatever its type (for the either/or rules). */
static int has_member(const cJSON *obj, const char *key)
{
	return cJSON_IsObject(obj) && cJSON_GetObjectItemCaseSensitive(obj, key) != NULL;
}

/* engaged_threads, or nut_length_mm converted to whole threads; exactly one of them. */
static void read_engagement(prsm_design *d, const cJSON *g, const char *gp, int pitch_ok,
                            prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	const int has_threads = has_member(g, "engaged_threads");
	const int has_length = has_member(g, "nut_length_mm");
	if (!has_threads && !has_length) {
		prsm_json_pointer_append(ptr, sizeof ptr, gp, "engaged_threads");
		prsm_problems_add(problems, ptr, "required",
		                  "is required (an integer from 1 to %d), or give nut_length_mm instead",
		                  PRSM_DESIGN_ENGAGED_THREADS_MAX);
		return;
	}
	if (has_threads)
		prsm_json_get_int(&d->engaged_threads, g, gp, "engaged_threads", PRSM_JSON_REQUIRED, 1,
		                  PRSM_DESIGN_ENGAGED_THREADS_MAX, problems);
	double length_mm = NAN;
	int length_ok = has_length && prsm_json_get_number(&length_mm, g, gp, "nut_length_mm",
	                                                   PRSM_JSON_REQUIRED, positive(),
	                                                   problems) == PRSM_JSON_PRESENT;
	prsm_json_pointer_append(ptr, sizeof ptr, gp, "nut_length_mm");
	if (has_threads && has_length) {
		prsm_problems_add(problems, ptr, "conflict",
		                  "give engaged_threads or nut_length_mm, not both");
		return;
	}
	if (!length_ok || !pitch_ok)
		return;
	/* whole threads in the nut length; a ratio within 1e-9 of a whole number counts as whole */
	double threads = floor(length_mm / d->pitch_mm + 1e-9);
	if (threads < 1.0)
		prsm_problems_add(problems, ptr, "range",
		                  "nut_length_mm %g mm is shorter than one pitch (%g mm): no thread engages",
		                  length_mm, d->pitch_mm);
	else if (threads > PRSM_DESIGN_ENGAGED_THREADS_MAX)
		prsm_problems_add(problems, ptr, "range",
		                  "nut_length_mm %g mm gives %g engaged threads at pitch %g mm, more than %d",
		                  length_mm, threads, d->pitch_mm, PRSM_DESIGN_ENGAGED_THREADS_MAX);
	else
		d->engaged_threads = (int)threads;
}

static void read_geometry(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char gp[PRSM_JSON_POINTER_MAX];
	const cJSON *g;
	if (prsm_json_get_section(&g, gp, sizeof gp, doc, base, "geometry",
	                          PRSM_JSON_REQUIRED, geometry_keys, problems) != PRSM_JSON_PRESENT)
		return;

	prsm_json_get_int(&d->starts, g, gp, "starts", PRSM_JSON_REQUIRED, 1, PRSM_DESIGN_STARTS_MAX,
	                  problems);
	int hand;
	if (prsm_json_get_enum(&hand, g, gp, "hand", PRSM_JSON_OPTIONAL, hand_names, problems) == PRSM_JSON_PRESENT)
		d->hand = hand == 0 ? PRSM_HAND_RIGHT : PRSM_HAND_LEFT;
	const int pitch_ok = prsm_json_get_number(&d->pitch_mm, g, gp, "pitch_mm", PRSM_JSON_REQUIRED,
	                                          range(0.0, 1, PRSM_DESIGN_PITCH_MAX_MM, 0),
	                                          problems) == PRSM_JSON_PRESENT;
	double beta_deg;
	if (prsm_json_get_number(&beta_deg, g, gp, "flank_angle_deg", PRSM_JSON_OPTIONAL,
	                         range(0.0, 1, 90.0, 1), problems) == PRSM_JSON_PRESENT)
		d->flank_angle_rad = beta_deg * (M_PI / 180.0);
	prsm_json_get_number(&d->roller_radius_mm, g, gp, "roller_radius_mm", PRSM_JSON_REQUIRED,
	                     positive(), problems);

	/* optional radii: left NaN when absent, for prsm_design_resolve() */
	const struct {
		const char *key;
		double *field; /* mm */
	} radii[] = {
		{"screw_radius_mm", &d->screw_radius_mm},
		{"nut_radius_mm", &d->nut_radius_mm},
		{"roller_arc_radius_mm", &d->roller_arc_radius_mm},
		{"screw_crest_radius_mm", &d->screw_crest_radius_mm},
		{"screw_root_radius_mm", &d->screw_root_radius_mm},
		{"roller_crest_radius_mm", &d->roller_crest_radius_mm},
		{"roller_root_radius_mm", &d->roller_root_radius_mm},
		{"nut_crest_radius_mm", &d->nut_crest_radius_mm},
		{"nut_root_radius_mm", &d->nut_root_radius_mm},
		{"nut_outer_radius_mm", &d->nut_outer_radius_mm},
	};
	for (size_t i = 0; i < sizeof radii / sizeof radii[0]; i++)
		prsm_json_get_number(radii[i].field, g, gp, radii[i].key, PRSM_JSON_OPTIONAL, positive(),
		                     problems);

	prsm_json_get_int(&d->rollers, g, gp, "rollers", PRSM_JSON_REQUIRED, 1, PRSM_DESIGN_ROLLERS_MAX,
	                  problems);
	read_engagement(d, g, gp, pitch_ok, problems);
	prsm_json_get_number(&d->running_clearance_mm, g, gp, "running_clearance_mm", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, INFINITY, 0), problems);
}

/* thinning (given flank shifts) or target_axial_clearance_um (the rule solves them), not both */
static void read_backlash(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char tp[PRSM_JSON_POINTER_MAX];
	const cJSON *t;
	const prsm_json_range thin = range(-PRSM_DESIGN_THINNING_MAX_UM, 0, PRSM_DESIGN_THINNING_MAX_UM, 0);
	if (prsm_json_get_section(&t, tp, sizeof tp, doc, base, "thinning",
	                          PRSM_JSON_OPTIONAL, thinning_keys, problems) == PRSM_JSON_PRESENT) {
		const struct {
			const char *key;
			double *shift; /* mm per flank */
		} parts[] = {
			{"screw_um", &d->flank_shift_screw_mm},
			{"roller_um", &d->flank_shift_roller_mm},
			{"nut_um", &d->flank_shift_nut_mm},
		};
		for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) {
			double um;
			/* docs/model/errors-and-assembly.md: a thickness change dt shifts each flank by dt/2 */
			if (prsm_json_get_number(&um, t, tp, parts[i].key, PRSM_JSON_OPTIONAL, thin, problems) == PRSM_JSON_PRESENT)
				*parts[i].shift = um / 2.0 / 1000.0;
		}
		d->thinning_rule = PRSM_THINNING_GIVEN;
	}
	double clearance_um;
	if (prsm_json_get_number(&clearance_um, doc, base, "target_axial_clearance_um", PRSM_JSON_OPTIONAL,
	                         range(0.0, 0, PRSM_DESIGN_CLEARANCE_MAX_UM, 0), problems) == PRSM_JSON_PRESENT) {
		d->target_axial_clearance_mm = clearance_um / 1000.0;
		d->thinning_rule = PRSM_THINNING_EQUAL_GAPS;
	}
	if (has_member(doc, "thinning") && has_member(doc, "target_axial_clearance_um")) {
		prsm_json_pointer_append(tp, sizeof tp, base, "target_axial_clearance_um");
		prsm_problems_add(problems, tp, "conflict",
		                  "give either thinning (flank shifts) or target_axial_clearance_um "
		                  "(the engine solves the thinning), not both");
	}
}

static void read_materials(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char mp[PRSM_JSON_POINTER_MAX], pp[PRSM_JSON_POINTER_MAX];
	const cJSON *m;
	if (prsm_json_get_section(&m, mp, sizeof mp, doc, base, "materials",
	                          PRSM_JSON_OPTIONAL, materials_keys, problems) != PRSM_JSON_PRESENT)
		return;
	prsm_material *parts[] = {&d->screw_material, &d->roller_material, &d->nut_material};
	for (int i = 0; i < 3; i++) {
		const cJSON *part;
		if (prsm_json_get_section(&part, pp, sizeof pp, m, mp, materials_keys[i],
		                          PRSM_JSON_OPTIONAL, material_keys, problems) != PRSM_JSON_PRESENT)
			continue;
		double e_gpa;
		if (prsm_json_get_number(&e_gpa, part, pp, "E_GPa", PRSM_JSON_OPTIONAL,
		                         range(0.0, 1, PRSM_DESIGN_E_MAX_GPA, 0), problems) == PRSM_JSON_PRESENT)
			parts[i]->E_MPa = e_gpa * 1000.0;
		prsm_json_get_number(&parts[i]->poisson, part, pp, "poisson", PRSM_JSON_OPTIONAL,
		                     range(0.0, 0, 0.5, 1), problems);
		prsm_json_get_number(&parts[i]->density_kg_m3, part, pp, "density_kg_m3", PRSM_JSON_OPTIONAL,
		                     range(0.0, 1, PRSM_DESIGN_DENSITY_MAX_KG_M3, 0), problems);
	}
}

static void read_friction(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char fp[PRSM_JSON_POINTER_MAX];
	const cJSON *f;
	if (prsm_json_get_section(&f, fp, sizeof fp, doc, base, "friction",
	                          PRSM_JSON_OPTIONAL, friction_keys, problems) != PRSM_JSON_PRESENT)
		return;
	prsm_json_get_number(&d->mu_screw_roller, f, fp, "screw_roller", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, 1.0, 1), problems);
	prsm_json_get_number(&d->mu_nut_roller, f, fp, "nut_roller", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, 1.0, 1), problems);
}

static void legacy_operating_point_from_json(prsm_design *d, const cJSON *doc, const char *base,
                                       prsm_problems *problems)
{
	char op[PRSM_JSON_POINTER_MAX];
	const cJSON *o;
	if (prsm_json_get_section(&o, op, sizeof op, doc, base, "operating_point",
	                          PRSM_JSON_OPTIONAL, operating_keys, problems) != PRSM_JSON_PRESENT)
		return;
	prsm_json_get_number(&d->axial_load_N, o, op, "axial_load_N", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, PRSM_DESIGN_LOAD_MAX_N, 0), problems);
	double rpm;
	if (prsm_json_get_number(&rpm, o, op, "screw_speed_rpm", PRSM_JSON_OPTIONAL,
	                         range(-PRSM_DESIGN_SPEED_MAX_RPM, 0, PRSM_DESIGN_SPEED_MAX_RPM, 0),
	                         problems) == PRSM_JSON_PRESENT)
		d->screw_speed_rad_s = rpm * (2.0 * M_PI / 60.0);
}

/* "losses": spin, gear mesh, drag and seal (docs/model/kinematics-efficiency-stiffness-life.md) */
static void read_losses(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char lp[PRSM_JSON_POINTER_MAX];
	const cJSON *l;
	if (prsm_json_get_section(&l, lp, sizeof lp, doc, base, "losses", PRSM_JSON_OPTIONAL,
	                          losses_keys, problems) != PRSM_JSON_PRESENT)
		return;
	prsm_design_losses *o = &d->losses;
	prsm_json_get_bool(&o->spin, l, lp, "spin", PRSM_JSON_OPTIONAL, problems);
	prsm_json_get_bool(&o->gear_mesh, l, lp, "gear_mesh", PRSM_JSON_OPTIONAL, problems);
	prsm_json_get_number(&o->gear_friction, l, lp, "gear_friction", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, 1.0, 1), problems);
	prsm_json_get_int(&o->roller_gear_teeth, l, lp, "roller_gear_teeth", PRSM_JSON_OPTIONAL, 6,
	                  PRSM_DESIGN_GEAR_TEETH_MAX, problems);
	prsm_json_get_int(&o->ring_gear_teeth, l, lp, "ring_gear_teeth", PRSM_JSON_OPTIONAL, 12,
	                  PRSM_DESIGN_GEAR_TEETH_MAX, problems);
	prsm_json_get_number(&o->gear_contact_ratio, l, lp, "gear_contact_ratio", PRSM_JSON_OPTIONAL,
	                     range(1.0, 0, 2.0, 0), problems);
	double deg;
	if (prsm_json_get_number(&deg, l, lp, "gear_pressure_angle_deg", PRSM_JSON_OPTIONAL,
	                         range(5.0, 0, 45.0, 0), problems) == PRSM_JSON_PRESENT)
		o->gear_pressure_angle_rad = deg * (M_PI / 180.0);
	prsm_json_get_number(&o->drag_torque_Nm, l, lp, "drag_torque_Nm", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, PRSM_DESIGN_TORQUE_MAX_NM, 0), problems);
	prsm_json_get_number(&o->viscous_drag_Nm_s_per_rad, l, lp, "viscous_drag_Nm_s_per_rad",
	                     PRSM_JSON_OPTIONAL, range(0.0, 0, PRSM_DESIGN_TORQUE_MAX_NM, 0), problems);
	prsm_json_get_number(&o->seal_torque_Nm, l, lp, "seal_torque_Nm", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, PRSM_DESIGN_TORQUE_MAX_NM, 0), problems);
}

/* "stiffness": thread compliance, load entry, load-deflection curve (docs/model/kinematics-efficiency-stiffness-life.md) */
static void read_stiffness(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char sp[PRSM_JSON_POINTER_MAX], cp[PRSM_JSON_POINTER_MAX];
	const cJSON *s, *c;
	if (prsm_json_get_section(&s, sp, sizeof sp, doc, base, "stiffness", PRSM_JSON_OPTIONAL,
	                          stiffness_keys, problems) != PRSM_JSON_PRESENT)
		return;
	prsm_design_stiffness *o = &d->stiffness;
	prsm_json_get_enum(&o->load_entry, s, sp, "load_entry", PRSM_JSON_OPTIONAL, legacy_load_entry_names, problems);
	if (prsm_json_get_section(&c, cp, sizeof cp, s, sp, "thread_compliance", PRSM_JSON_OPTIONAL,
	                          compliance_keys, problems) == PRSM_JSON_PRESENT) {
		int model = 0, width = 0, neg;
		int has_model = prsm_json_get_enum(&model, c, cp, "model", PRSM_JSON_OPTIONAL,
		                                   compliance_model_names, problems) == PRSM_JSON_PRESENT;
		if (prsm_json_get_enum(&width, c, cp, "width", PRSM_JSON_OPTIONAL, legacy_width_names, problems) ==
		    PRSM_JSON_PRESENT)
			o->width_rule = PRSM_THREAD_WIDTH_SHARE + width;
		if (has_model && model == 1) {
			o->width_rule = PRSM_THREAD_COMPLIANCE_NONE;
			if (has_member(c, "width")) {
				char wp[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append(wp, sizeof wp, cp, "width");
				prsm_problems_add(problems, wp, "conflict",
				                  "a width has no meaning with model \"none\" (rigid threads)");
			}
		}
		prsm_json_get_number(&o->width_fraction, c, cp, "width_fraction", PRSM_JSON_OPTIONAL,
		                     range(0.0, 1, 1.0, 0), problems);
		int has_width_mm = prsm_json_get_number(&o->width_mm, c, cp, "width_mm", PRSM_JSON_OPTIONAL,
		                                        range(0.0, 1, 1000.0, 0), problems) == PRSM_JSON_PRESENT;
		if (o->width_rule == PRSM_THREAD_WIDTH_GIVEN && !has_width_mm && !has_member(c, "width_mm")) {
			char wp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(wp, sizeof wp, cp, "width_mm");
			prsm_problems_add(problems, wp, "required", "is required with width \"given\" (mm)");
		}
		prsm_json_get_number(&o->ellipse_factor, c, cp, "ellipse_factor", PRSM_JSON_OPTIONAL,
		                     range(0.0, 1, 100.0, 0), problems);
		prsm_json_get_number(&o->calibration, c, cp, "calibration", PRSM_JSON_OPTIONAL,
		                     range(0.0, 1, 100.0, 0), problems);
		if (prsm_json_get_enum(&neg, c, cp, "negative_terms", PRSM_JSON_OPTIONAL, legacy_negative_terms_names,
		                       problems) == PRSM_JSON_PRESENT)
			o->negative_terms = neg == 0 ? PRSM_YAMAMOTO_CLAMP : PRSM_YAMAMOTO_KEEP;
	}
	if (prsm_json_get_section(&c, cp, sizeof cp, s, sp, "load_deflection_curve", PRSM_JSON_OPTIONAL,
	                          curve_keys, problems) == PRSM_JSON_PRESENT) {
		o->curve_points = 21;
		prsm_json_get_int(&o->curve_points, c, cp, "points", PRSM_JSON_OPTIONAL, 2,
		                  PRSM_DESIGN_CURVE_POINTS_MAX, problems);
		prsm_json_get_number(&o->curve_max_load_N, c, cp, "max_load_N", PRSM_JSON_OPTIONAL,
		                     range(0.0, 1, PRSM_DESIGN_LOAD_MAX_N, 0), problems);
	}
}

/* "life": allowed pressure, reliability, duty cycle, preload (docs/model/kinematics-efficiency-stiffness-life.md) */
static void read_life(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char lp[PRSM_JSON_POINTER_MAX], dp[PRSM_JSON_POINTER_MAX], ip[PRSM_JSON_POINTER_MAX];
	const cJSON *l;
	if (prsm_json_get_section(&l, lp, sizeof lp, doc, base, "life", PRSM_JSON_OPTIONAL, life_keys,
	                          problems) != PRSM_JSON_PRESENT)
		return;
	prsm_design_life *o = &d->life;
	prsm_json_get_number(&o->p_allow_MPa, l, lp, "p_allow_MPa", PRSM_JSON_OPTIONAL,
	                     range(0.0, 1, 20000.0, 0), problems);
	int pct;
	if (prsm_json_get_int(&pct, l, lp, "reliability_percent", PRSM_JSON_OPTIONAL, 90, 99, problems) ==
	    PRSM_JSON_PRESENT) {
		if (pct > 90 && pct < 95) {
			prsm_json_pointer_append(ip, sizeof ip, lp, "reliability_percent");
			prsm_problems_add(problems, ip, "enum", "must be 90, 95, 96, 97, 98 or 99 (got %d)", pct);
		} else {
			o->reliability_percent = pct;
		}
	}
	prsm_json_get_number(&o->preload_N, l, lp, "preload_N", PRSM_JSON_OPTIONAL,
	                     range(0.0, 0, PRSM_DESIGN_LOAD_MAX_N, 0), problems);
	prsm_json_get_number(&o->lp_material_factor, l, lp, "lp_material_factor", PRSM_JSON_OPTIONAL,
	                     range(0.0, 1, 10.0, 0), problems);
	const cJSON *duty = cJSON_GetObjectItemCaseSensitive(l, "duty_cycle");
	if (duty == NULL)
		return;
	prsm_json_pointer_append(dp, sizeof dp, lp, "duty_cycle");
	const int n = cJSON_GetArraySize(duty);
	if (!cJSON_IsArray(duty) || n < 1 || n > PRSM_DUTY_CYCLE_MAX) {
		prsm_problems_add(problems, dp, cJSON_IsArray(duty) ? "size" : "type",
		                  "must be an array of 1 to %d steps {axial_load_N, travel_mm}",
		                  PRSM_DUTY_CYCLE_MAX);
		return;
	}
	double travel_sum = 0.0;
	int i = 0;
	for (const cJSON *step = duty->child; step; step = step->next, i++) {
		prsm_json_pointer_append_index(ip, sizeof ip, dp, i);
		if (prsm_json_object_value(step, ip, problems) != 0)
			continue;
		prsm_json_check_keys(step, ip, duty_keys, problems);
		prsm_json_get_number(&o->duty_load_N[i], step, ip, "axial_load_N", PRSM_JSON_REQUIRED,
		                     range(-PRSM_DESIGN_LOAD_MAX_N, 0, PRSM_DESIGN_LOAD_MAX_N, 0), problems);
		if (prsm_json_get_number(&o->duty_travel_mm[i], step, ip, "travel_mm", PRSM_JSON_REQUIRED,
		                         range(0.0, 0, 1e9, 0), problems) == PRSM_JSON_PRESENT)
			travel_sum += o->duty_travel_mm[i];
	}
	o->duty_steps = n;
	if (!(travel_sum > 0.0))
		prsm_problems_add(problems, dp, "range", "the steps' travel_mm must not all be 0");
}

/* "column": free length and end fixity of the screw (docs/model/kinematics-efficiency-stiffness-life.md) */
static void read_column(prsm_design *d, const cJSON *doc, const char *base, prsm_problems *problems)
{
	char cp[PRSM_JSON_POINTER_MAX];
	const cJSON *c;
	if (prsm_json_get_section(&c, cp, sizeof cp, doc, base, "column", PRSM_JSON_OPTIONAL, column_keys,
	                          problems) != PRSM_JSON_PRESENT)
		return;
	int ok = prsm_json_get_number(&d->life.free_length_mm, c, cp, "free_length_mm", PRSM_JSON_REQUIRED,
	                              range(0.0, 1, 1e6, 0), problems) == PRSM_JSON_PRESENT;
	ok &= prsm_json_get_enum(&d->life.fixity, c, cp, "fixity", PRSM_JSON_REQUIRED, legacy_fixity_names,
	                         problems) == PRSM_JSON_PRESENT;
	d->life.column = ok;
}

int prsm_legacy_design_from_json(prsm_design *out, const cJSON *doc, const char *base_pointer,
                             prsm_problems *problems)
{
	assert(out != NULL && problems != NULL);
	const char *base = base_pointer ? base_pointer : "";
	const int before = prsm_problems_total(problems);
	prsm_design_init(out);
	if (prsm_json_object_value(doc, base, problems) != 0)
		return PRSM_EINVAL;
	prsm_json_check_keys(doc, base, design_keys, problems);
	const char *text;
	prsm_json_get_string(&text, doc, base, "name", PRSM_JSON_OPTIONAL, PRSM_DESIGN_NAME_MAX_CHARS,
	                     problems);
	prsm_json_get_string(&text, doc, base, "description", PRSM_JSON_OPTIONAL,
	                     PRSM_DESIGN_DESCRIPTION_MAX_CHARS, problems);
	read_geometry(out, doc, base, problems);
	read_backlash(out, doc, base, problems);
	read_materials(out, doc, base, problems);
	read_friction(out, doc, base, problems);
	legacy_operating_point_from_json(out, doc, base, problems);
	read_losses(out, doc, base, problems);
	read_stiffness(out, doc, base, problems);
	read_life(out, doc, base, problems);
	read_column(out, doc, base, problems);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

