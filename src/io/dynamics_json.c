/*
 * dynamics_json.c: the dynamics request object read by its generated table with the hooks a
 * table cannot say, and a simulation's result as JSON (the sticky-error writer, io/write.h),
 * CSV and text (see dynamics_json.h; docs/dynamics.md).
 *
 * Units at the API are in the names: kg mm^2 for inertias (kg m^2 inside, x 1e6 out), mm for
 * positions and radii, degrees for the gear pressure angle; everything else is SI as the model
 * has it.
 */
#include "io/dynamics_json.h"

#include <inttypes.h>
#include <math.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "prsm_io_tables.h"
#include "util/error.h"
#include "util/version.h"

#define KG_MM2 1e6             /* kg m^2 -> kg mm^2 */
#define DEG (180.0 / M_PI)     /* rad -> deg */

static const char *const later_analyses[] = {"vibration", "sweep", "linear", "frequency_response", "basins",
                                             "calibrate", NULL};

/* The per-stage fields of `inertia` (the single-stage form; a chain's are in inertia.stages). */
static const char *const stage_keys[] = {"gear_face_width_mm", "roller_mass_kg", "roller_inertia_kg_mm2",
                                         "carrier_mass_kg", "carrier_inertia_kg_mm2", "nut_mass_kg",
                                         "screw_mass_kg", "screw_inertia_kg_mm2", NULL};

/* ---- the hooks of the table (schemas/dynamics.schema.json, x-prsm) ---------------------------- */

/* "analysis": transient here; the analyses the dynamics model has beyond it come later. */
void prsm_io_hook_dynamics_analysis(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	(void)base;
	const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, "analysis");
	if (a == NULL)
		return;
	char ptr[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "analysis");
	const char *s;
	if (prsm_json_string_value(&s, a, ptr, 64, problems))
		return;
	for (int i = 0; later_analyses[i]; i++)
		if (strcmp(s, later_analyses[i]) == 0) {
			prsm_problems_add(problems, ptr, "not_available",
			                  "\"%s\" is an analysis of the dynamics model that this engine does not run "
			                  "yet: only \"transient\" (the start-up transient, docs/dynamics.md)", s);
			return;
		}
	static const char *const names[] = {"transient", NULL};
	int i;
	prsm_json_enum_value(&i, a, ptr, names, problems);
}

static int has(const cJSON *obj, const char *key)
{
	return cJSON_GetObjectItemCaseSensitive(obj, key) != NULL;
}

/* The input section's names follow its kind: value_rad_s and sine_amplitude_rad_s for a speed,
 * value_Nm (required) and sine_amplitude_Nm for a torque; only a torque input has an initial
 * speed (a speed input starts at its signal). */
void prsm_io_hook_dynamics_input(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	const prsm_dyn_options *o = base;
	char ptr[PRSM_JSON_POINTER_MAX];
	if (prsm_io_problem_at(problems, 0, obj_pointer, "kind"))
		return; /* the kind is unknown: nothing to hold the names against */
	if (o->input.kind == PRSM_DYN_INPUT_TORQUE) {
		if (!has(obj, "value_Nm")) {
			prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "value_Nm");
			prsm_problems_add(problems, ptr, "required", "a torque input needs value_Nm, the motor torque in N m");
		}
		if (has(obj, "value_rad_s")) {
			prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "value_rad_s");
			prsm_problems_add(problems, ptr, "input_kind",
			                  "a torque input is given in N m (value_Nm); value_rad_s is a speed input's");
		}
		if (has(obj, "sine_amplitude_rad_s")) {
			prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "sine_amplitude_rad_s");
			prsm_problems_add(problems, ptr, "input_kind",
			                  "the sine amplitude of a torque input is sine_amplitude_Nm");
		}
		return;
	}
	if (has(obj, "value_Nm")) {
		prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "value_Nm");
		prsm_problems_add(problems, ptr, "input_kind",
		                  "a speed input is given in rad/s (value_rad_s); value_Nm needs \"kind\": \"torque\"");
	}
	if (has(obj, "sine_amplitude_Nm")) {
		prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "sine_amplitude_Nm");
		prsm_problems_add(problems, ptr, "input_kind", "the sine amplitude of a speed input is sine_amplitude_rad_s");
	}
	if (has(obj, "initial_speed_rad_s")) {
		prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "initial_speed_rad_s");
		prsm_problems_add(problems, ptr, "input_kind",
		                  "a speed input starts at its signal's value: initial_speed_rad_s is for a torque input");
	}
}

/* The masses: the single-stage fields into stage 0, each item of `stages` into its stage, by
 * the table of one stage (schemas/dynamics.schema.json, $defs/stage_inertia). Which form the
 * request may use depends on its number of stages: prsm_io_dynamics_from_json checks that. */
void prsm_io_hook_dynamics_inertia(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_dyn_options *o = base;
	for (int i = 0; stage_keys[i]; i++)
		prsm_io_read_member(&o->inertia.stage[0], &prsm_io_t_dynamics_stage_inertia, stage_keys[i], obj, obj_pointer,
		                    problems);
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(obj, "stages");
	if (arr == NULL)
		return;
	char ap[PRSM_JSON_POINTER_MAX], ip[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ap, sizeof ap, obj_pointer, "stages");
	const int n = cJSON_GetArraySize(arr);
	if (!cJSON_IsArray(arr) || n < 1 || n > PRSM_DYN_STAGES_MAX) {
		prsm_problems_add(problems, ap, cJSON_IsArray(arr) ? "size" : "type",
		                  "must be an array of 1 to %d objects, one per stage of the chain", PRSM_DYN_STAGES_MAX);
		return;
	}
	int k = 0;
	for (const cJSON *it = arr->child; it; it = it->next, k++) {
		prsm_json_pointer_append_index(ip, sizeof ip, ap, k);
		if (prsm_json_object_value(it, ip, problems) == 0)
			prsm_io_read(&o->inertia.stage[k], &prsm_io_t_dynamics_stage_inertia, it, ip, problems);
	}
}

/* time.max_steps: an integer into a long. */
void prsm_io_hook_dynamics_max_steps(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_dyn_options *o = base;
	int v;
	if (prsm_json_get_int(&v, obj, obj_pointer, "max_steps", PRSM_JSON_OPTIONAL, 1, 1000000000, problems) ==
	    PRSM_JSON_PRESENT)
		o->time.max_steps = v;
}

/* ---- the reader -------------------------------------------------------------------------------- */

/* 1 when a problem since `from` is at pointer exactly. */
static int problem_at_pointer(const prsm_problems *p, int from, const char *pointer)
{
	for (int i = from; i < p->count; i++)
		if (strcmp(p->items[i].pointer, pointer) == 0)
			return 1;
	return 0;
}

/* The single-stage form (fields of `inertia`) or the chain's (`inertia.stages`, K objects). */
static void check_inertia_form(const cJSON *obj, int stages, prsm_problems *problems)
{
	const cJSON *in = cJSON_GetObjectItemCaseSensitive(obj, "inertia");
	if (!cJSON_IsObject(in))
		return;
	char ptr[PRSM_JSON_POINTER_MAX];
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(in, "stages");
	if (stages == 1 && arr != NULL) {
		prsm_problems_add(problems, "/dynamics/inertia/stages", "single_stage",
		                  "a single-stage screw gives its masses directly in inertia (stages is for a chain)");
	} else if (stages > 1) {
		for (int i = 0; stage_keys[i]; i++)
			if (has(in, stage_keys[i])) {
				prsm_json_pointer_append(ptr, sizeof ptr, "/dynamics/inertia", stage_keys[i]);
				prsm_problems_add(problems, ptr, "chain",
				                  "a chain of %d stages gives each stage's masses in inertia.stages "
				                  "(%d objects, stage 1 first)", stages, stages);
			}
		if (cJSON_IsArray(arr) && cJSON_GetArraySize(arr) != stages &&
		    !problem_at_pointer(problems, 0, "/dynamics/inertia/stages"))
			prsm_problems_add(problems, "/dynamics/inertia/stages", "size",
			                  "must have %d objects, one per stage of the chain (got %d)", stages,
			                  cJSON_GetArraySize(arr));
	}
}

int prsm_io_dynamics_from_json(prsm_dyn_options *o, const cJSON *obj, int stages, prsm_problems *problems)
{
	prsm_dyn_options_init(o);
	const int before = prsm_problems_total(problems);
	if (obj != NULL) {
		if (prsm_json_object_value(obj, "/dynamics", problems))
			return PRSM_EINVAL;
		o->time.output_step_s = NAN; /* given, or end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS below */
		prsm_io_read(o, &prsm_io_t_dynamics, obj, "/dynamics", problems);
		check_inertia_form(obj, stages, problems);
		if (isnan(o->time.output_step_s))
			o->time.output_step_s = o->time.end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS;
	} else {
		o->time.output_step_s = o->time.end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS;
	}
	/* the model's cross-field rules, each once: a field refused above keeps its default, which
	 * the rules may not hold against it */
	prsm_problems cross;
	prsm_problems_init(&cross);
	prsm_dyn_options_check(o, stages, &cross);
	const int first = problems->count;
	for (int i = 0; i < cross.count; i++)
		if (!problem_at_pointer(problems, before < first ? before : first, cross.items[i].pointer))
			prsm_problems_add(problems, cross.items[i].pointer, cross.items[i].code, "%s", cross.items[i].message);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

/* ---- the result --------------------------------------------------------------------------------- */

static const char *const input_kind_names[] = {"speed", "torque"};
static const char *const shape_names[] = {"step", "ramp", "sine"};
static const char *const friction_names[] = {"coulomb", "viscous", "stribeck"};
static const char *const stick_names[] = {"none", "karnopp"};
static const char *const losses_names[] = {"statics", "sliding_only"};
static const char *const stepper_names[] = {"auto", "rk8pd", "msbdf", "rk4imp"};
static const char *const flank_names[] = {"upper", "lower"};
static const char *const share_names[3] = {"time_to_50_percent_s", "time_to_90_percent_s", "time_to_99_percent_s"};

static const char *name_of(const char *const *names, int n, int v)
{
	return v >= 0 && v < n ? names[v] : "unknown";
}
#define NAME(names, v) name_of(names, (int)(sizeof names / sizeof names[0]), (v))

/* An array of n numbers, the first at first, each stride bytes after the previous, x scale. */
static void series(prsm_jw *w, cJSON *obj, const char *key, const double *first, size_t stride, size_t n,
                   double scale)
{
	cJSON *a = prsm_jw_array(w, obj, key);
	for (size_t i = 0; a && i < n; i++)
		prsm_jw_number(w, a, NULL, *(const double *)(const void *)((const char *)first + i * stride) * scale);
}

static void vec3(prsm_jw *w, cJSON *obj, const char *key, const double v[3])
{
	series(w, obj, key, v, sizeof v[0], 3, 1.0);
}

/* |B| of stage 0 in m per rad (the stick band's and the stiff switch's default, docs/dynamics.md) */
static double slip_per_rad_m(const prsm_dyn_stage_params *p)
{
	const double *B = p->B_mm[PRSM_DYN_FLANK_LOWER];
	return sqrt(B[0] * B[0] + B[1] * B[1] + B[2] * B[2]) * 1e-3;
}

/* One stage's masses in the request's names (kg, kg mm^2, mm). */
static void stage_masses(prsm_jw *w, cJSON *o, const prsm_dyn_stage_params *p)
{
	prsm_jw_number(w, o, "gear_face_width_mm", p->gear_face_width_mm);
	prsm_jw_number(w, o, "roller_mass_kg", p->roller_mass_kg);
	prsm_jw_number(w, o, "roller_inertia_kg_mm2", p->roller_inertia_kg_m2 * KG_MM2);
	prsm_jw_number(w, o, "carrier_mass_kg", p->carrier_mass_kg);
	prsm_jw_number(w, o, "carrier_inertia_kg_mm2", p->carrier_inertia_kg_m2 * KG_MM2);
	prsm_jw_number(w, o, "nut_mass_kg", p->nut_mass_kg);
	prsm_jw_number(w, o, "screw_mass_kg", p->screw_mass_kg);
	prsm_jw_number(w, o, "screw_inertia_kg_mm2", p->screw_inertia_kg_m2 * KG_MM2);
}

static void write_signal_fields(prsm_jw *w, cJSON *o, const prsm_dyn_signal *s, const char *amp_key)
{
	prsm_jw_number(w, o, "ramp_time_s", s->ramp_time_s);
	prsm_jw_number(w, o, amp_key, s->sine_amplitude);
	prsm_jw_number(w, o, "sine_frequency_Hz", s->sine_frequency_Hz);
}

/* The dynamics object as the model ran it, every default written out in the request's names:
 * a valid dynamics object (schemas/dynamics.schema.json) that reproduces the run. Left out:
 * what the model chooses itself when it is not given (mu of stages that differ, static_mu =
 * mu, the first step and the speed scale). */
static void write_parameters(prsm_jw *w, cJSON *obj, const prsm_dyn_model *m)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	const int K = prsm_dyn_model_stages(m);
	const prsm_dyn_stage_params *p0 = prsm_dyn_model_stage(m, 0);
	const int torque = o->input.kind == PRSM_DYN_INPUT_TORQUE;
	cJSON *par = prsm_jw_object(w, obj, "parameters");
	prsm_jw_string(w, par, "analysis", "transient");
	cJSON *in = prsm_jw_object(w, par, "input");
	prsm_jw_string(w, in, "kind", NAME(input_kind_names, o->input.kind));
	prsm_jw_string(w, in, "shape", NAME(shape_names, o->input.signal.shape));
	prsm_jw_number(w, in, torque ? "value_Nm" : "value_rad_s", o->input.signal.value);
	write_signal_fields(w, in, &o->input.signal, torque ? "sine_amplitude_Nm" : "sine_amplitude_rad_s");
	prsm_jw_number(w, in, "motor_inertia_kg_mm2", o->input.motor_inertia_kg_m2 * KG_MM2);
	prsm_jw_number(w, in, "viscous_drag_Nm_s_per_rad", o->input.viscous_drag_Nm_s_per_rad);
	if (torque)
		prsm_jw_number(w, in, "initial_speed_rad_s", o->input.initial_speed_rad_s);

	cJSON *ld = prsm_jw_object(w, par, "load");
	prsm_jw_number(w, ld, "axial_load_N", o->load.value);
	prsm_jw_string(w, ld, "shape", o->load.shape == PRSM_DYN_SHAPE_STEP ? "constant" : NAME(shape_names, o->load.shape));
	write_signal_fields(w, ld, &o->load, "sine_amplitude_N");

	const prsm_dyn_friction *f = &o->friction;
	cJSON *fr = prsm_jw_object(w, par, "friction");
	prsm_jw_string(w, fr, "model", NAME(friction_names, f->model));
	prsm_jw_number(w, fr, "viscous_N_s_per_m", f->viscous_N_s_per_m);
	int same_mu = 1;
	for (int k = 1; k < K; k++)
		same_mu &= prsm_dyn_model_stage(m, k)->mu == p0->mu;
	if (!isnan(f->mu) || same_mu)
		prsm_jw_number(w, fr, "mu", isnan(f->mu) ? p0->mu : f->mu);
	prsm_jw_number(w, fr, "smoothing_velocity_m_s", f->smoothing_velocity_m_s);
	if (!isnan(f->static_mu))
		prsm_jw_number(w, fr, "static_mu", f->static_mu);
	prsm_jw_number(w, fr, "stribeck_velocity_m_s", f->stribeck_velocity_m_s);
	prsm_jw_string(w, fr, "stick_model", NAME(stick_names, f->stick_model));
	const double v_eps_rad_s = f->smoothing_velocity_m_s / slip_per_rad_m(p0);
	prsm_jw_number(w, fr, "stick_band_rad_s", isnan(f->stick_band_rad_s) ? 10.0 * v_eps_rad_s : f->stick_band_rad_s);
	prsm_jw_number(w, fr, "carrier_drag_Nm_s_per_rad", f->carrier_drag_Nm_s_per_rad);
	prsm_jw_number(w, fr, "coupling_smoothing_rad_s", f->coupling_smoothing_rad_s);

	prsm_jw_string(w, par, "losses", NAME(losses_names, o->losses));

	cJSON *ine = prsm_jw_object(w, par, "inertia");
	prsm_jw_number(w, ine, "density_kg_m3", o->inertia.density_kg_m3);
	prsm_jw_number(w, ine, "stroke_mm", o->inertia.stroke_mm);
	prsm_jw_number(w, ine, "payload_kg", o->inertia.payload_kg);
	if (K == 1) {
		stage_masses(w, ine, p0);
	} else {
		cJSON *st = prsm_jw_array(w, ine, "stages");
		for (int k = 0; k < K; k++)
			stage_masses(w, prsm_jw_object(w, st, NULL), prsm_dyn_model_stage(m, k));
	}

	const prsm_dyn_time *t = &o->time;
	cJSON *ti = prsm_jw_object(w, par, "time");
	prsm_jw_number(w, ti, "end_s", t->end_s);
	prsm_jw_number(w, ti, "output_step_s", t->output_step_s);
	prsm_jw_string(w, ti, "stepper", NAME(stepper_names, t->stepper));
	prsm_jw_number(w, ti, "rel_tol", t->rel_tol);
	prsm_jw_number(w, ti, "abs_tol", t->abs_tol);
	if (!isnan(t->initial_step_s))
		prsm_jw_number(w, ti, "initial_step_s", t->initial_step_s);
	if (isfinite(t->stiff_switch_rad_s) || isnan(t->stiff_switch_rad_s))
		prsm_jw_number(w, ti, "stiff_switch_rad_s",
		               isnan(t->stiff_switch_rad_s) ? 100.0 * v_eps_rad_s : t->stiff_switch_rad_s);
	if (!isnan(t->speed_scale_rad_s))
		prsm_jw_number(w, ti, "speed_scale_rad_s", t->speed_scale_rad_s);
	prsm_jw_number(w, ti, "max_steps", (double)t->max_steps);
}

/* What the model made of each stage (docs/dynamics.md): its kinematic structure, the masses and
 * the couplings; the chain's screw-side inertia. */
static void write_model(prsm_jw *w, cJSON *obj, const prsm_dyn_model *m)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	const int K = prsm_dyn_model_stages(m);
	cJSON *mo = prsm_jw_object(w, obj, "model");
	prsm_jw_number(w, mo, "screw_side_inertia_kg_mm2", prsm_dyn_model_screw_side_inertia(m) * KG_MM2);
	if (K > 1) {
		cJSON *c = prsm_jw_object(w, mo, "couplings");
		prsm_jw_number(w, c, "spline_friction", o->couplings.spline_friction);
		prsm_jw_number(w, c, "thrust_bearing_friction", o->couplings.thrust_bearing_friction);
	}
	cJSON *arr = prsm_jw_array(w, mo, "stages");
	for (int k = 0; k < K; k++) {
		const prsm_dyn_stage_params *p = prsm_dyn_model_stage(m, k);
		cJSON *s = prsm_jw_object(w, arr, NULL);
		prsm_jw_number(w, s, "stage", k + 1);
		prsm_jw_number(w, s, "rollers", p->rollers);
		prsm_jw_number(w, s, "lead_mm", p->lead_mm);
		prsm_jw_number(w, s, "cumulative_lead_mm_per_rad", p->cumulative_lead_m_per_rad * 1e3);
		prsm_jw_number(w, s, "ring_gear_ratio", p->ring_gear_ratio);
		prsm_jw_number(w, s, "gear_pitch_radius_mm", p->gear_pitch_radius_mm);
		prsm_jw_number(w, s, "orbit_radius_mm", p->orbit_radius_mm);
		prsm_jw_number(w, s, "gear_pressure_angle_deg", p->gear_pressure_angle_rad * DEG);
		prsm_jw_number(w, s, "carrier_ratio_min_slip", p->carrier_ratio_min_slip);
		prsm_jw_number(w, s, "carrier_ratio_statics", p->carrier_ratio_statics);
		prsm_jw_number(w, s, "min_slip_mm_per_rad", p->min_slip_mm_per_rad);
		prsm_jw_number(w, s, "mu", p->mu);
		prsm_jw_number(w, s, "static_mu", p->static_mu);
		cJSON *fl = prsm_jw_object(w, s, "flanks");
		for (int side = 0; side < 2; side++) {
			cJSON *f = prsm_jw_object(w, fl, flank_names[side]);
			vec3(w, f, "contact_mm", p->contact_mm[side]);
			vec3(w, f, "normal", p->normal[side]);
			vec3(w, f, "nut_contact_mm", p->nut_contact_mm[side]);
			vec3(w, f, "nut_normal", p->nut_normal[side]);
			vec3(w, f, "A_mm", p->A_mm[side]);
			vec3(w, f, "B_mm", p->B_mm[side]);
			prsm_jw_number(w, f, "normal_dot_A_mm", p->normal_dot_A_mm[side]);
			prsm_jw_number(w, f, "normal_dot_B_mm", p->normal_dot_B_mm[side]);
		}
		stage_masses(w, s, p);
		prsm_jw_number(w, s, "roller_length_mm", p->roller_length_mm);
		prsm_jw_number(w, s, "carrier_side_inertia_kg_mm2", p->carrier_side_inertia_kg_m2 * KG_MM2);
		prsm_jw_number(w, s, "axial_mass_kg", p->axial_mass_kg);
		if (k > 0) {
			prsm_jw_number(w, s, "spline_radius_mm", p->spline_radius_mm);
			prsm_jw_number(w, s, "thrust_bearing_radius_mm", p->thrust_radius_mm);
		}
		if (o->losses == PRSM_DYN_LOSSES_STATICS)
			prsm_jw_number(w, s, "loss_reference_load_N", p->loss_reference_load_N);
	}
}

/* The forces of one stage at one time (settled), per roller unless the name says. */
static void stage_forces(prsm_jw *w, cJSON *o, const prsm_dyn_stage_point *sp, int k)
{
	prsm_jw_string(w, o, "loaded_flank", NAME(flank_names, sp->flank));
	prsm_jw_number(w, o, "contact_normal_force_N", sp->contact_normal_force_N);
	prsm_jw_number(w, o, "nut_contact_force_N", sp->nut_contact_force_N);
	prsm_jw_number(w, o, "gear_tangential_force_N", sp->gear_tangential_force_N);
	prsm_jw_number(w, o, "gear_tooth_force_N", sp->gear_tooth_force_N);
	prsm_jw_number(w, o, "cage_force_N", sp->cage_force_N);
	prsm_jw_number(w, o, "slip_speed_m_s", sp->slip_speed_m_s);
	prsm_jw_number(w, o, "stage_axial_load_N", sp->stage_axial_load_N);
	prsm_jw_number(w, o, "spline_torque_Nm", sp->spline_torque_Nm);
	if (k > 0) {
		prsm_jw_number(w, o, "spline_force_N", sp->spline_force_N);
		prsm_jw_number(w, o, "thrust_load_N", sp->thrust_load_N);
		prsm_jw_number(w, o, "thrust_torque_Nm", sp->thrust_torque_Nm);
	}
	prsm_jw_number(w, o, "loss_torque_Nm", sp->loss_torque_Nm);
	prsm_jw_number(w, o, "sliding_power_W", sp->sliding_power_W);
}

static void write_settled(prsm_jw *w, cJSON *obj, const prsm_dyn_model *m, const prsm_dyn_result *r)
{
	const prsm_dyn_settled *s = &r->settled;
	const int K = r->stages;
	const int torque = prsm_dyn_model_options(m)->input.kind == PRSM_DYN_INPUT_TORQUE;
	cJSON *se = prsm_jw_object(w, obj, "settled");
	prsm_jw_bool(w, se, "defined", s->defined);
	prsm_jw_bool(w, se, "at_rest", s->at_rest);
	prsm_jw_number(w, se, "screw_speed_rad_s", s->screw_speed_rad_s);
	prsm_jw_number(w, se, "axial_load_N", s->point.axial_load_N);
	prsm_jw_number(w, se, "input_torque_Nm", s->input_torque_Nm);
	prsm_jw_number(w, se, "efficiency", s->efficiency);
	prsm_jw_number(w, se, "efficiency_statics", s->efficiency_statics);
	prsm_jw_number(w, se, "power_input_W", s->point.power_input_W);
	prsm_jw_number(w, se, "power_output_W", s->point.power_output_W);
	prsm_jw_number(w, se, "power_sliding_W", s->point.power_sliding_W);
	prsm_jw_number(w, se, "power_couplings_W", s->point.power_couplings_W);
	prsm_jw_number(w, se, "power_other_W", s->point.power_other_W);
	if (torque) {
		cJSON *sp = prsm_jw_object(w, se, "speed");
		for (int j = 0; j < 3; j++)
			prsm_jw_number(w, sp, share_names[j], r->speed_time_to_share_s[j]);
	}
	cJSON *arr = prsm_jw_array(w, se, "stages");
	for (int k = 0; k < K; k++) {
		cJSON *o = prsm_jw_object(w, arr, NULL);
		prsm_jw_number(w, o, "stage", k + 1);
		prsm_jw_number(w, o, "carrier_ratio", s->carrier_ratio[k]);
		prsm_jw_number(w, o, "carrier_ratio_min_slip", s->carrier_ratio_min_slip[k]);
		prsm_jw_number(w, o, "carrier_ratio_statics", s->carrier_ratio_statics[k]);
		prsm_jw_number(w, o, "carrier_rate_per_s", s->carrier_rate_per_s[k]);
		for (int j = 0; j < 3; j++)
			prsm_jw_number(w, o, share_names[j], r->carrier_time_to_share_s[k][j]);
		stage_forces(w, o, &s->stage[k], k);
	}
}

static void write_transient(prsm_jw *w, cJSON *obj, const prsm_dyn_model *m, const prsm_dyn_result *r)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	const int K = r->stages;
	const size_t n = r->points;
	cJSON *tr = prsm_jw_object(w, obj, "transient");
	prsm_jw_number(w, tr, "points", (double)n);
	if (n == 0)
		return;
	const prsm_dyn_point *p = r->point;
	const size_t ps = sizeof *p;
	series(w, tr, "time_s", &p->time_s, ps, n, 1.0);
	series(w, tr, "screw_angle_rad", &p->screw_angle_rad, ps, n, 1.0);
	series(w, tr, "screw_speed_rad_s", &p->screw_speed_rad_s, ps, n, 1.0);
	series(w, tr, "screw_accel_rad_s2", &p->screw_accel_rad_s2, ps, n, 1.0);
	series(w, tr, "axial_load_N", &p->axial_load_N, ps, n, 1.0);
	if (o->input.kind == PRSM_DYN_INPUT_TORQUE)
		series(w, tr, "motor_torque_Nm", &p->motor_torque_Nm, ps, n, 1.0);
	series(w, tr, "input_torque_Nm", &p->input_torque_Nm, ps, n, 1.0);
	series(w, tr, "efficiency", &p->efficiency, ps, n, 1.0);
	series(w, tr, "energy_input_J", &p->energy_input_J, ps, n, 1.0);
	series(w, tr, "energy_output_J", &p->energy_output_J, ps, n, 1.0);
	series(w, tr, "energy_efficiency", &p->energy_efficiency, ps, n, 1.0);
	cJSON *pw = prsm_jw_object(w, tr, "power_W");
	series(w, pw, "input", &p->power_input_W, ps, n, 1.0);
	series(w, pw, "output", &p->power_output_W, ps, n, 1.0);
	series(w, pw, "sliding", &p->power_sliding_W, ps, n, 1.0);
	series(w, pw, "couplings", &p->power_couplings_W, ps, n, 1.0);
	series(w, pw, "other", &p->power_other_W, ps, n, 1.0);
	series(w, pw, "kinetic", &p->power_kinetic_W, ps, n, 1.0);
	if (o->friction.stick_model == PRSM_DYN_STICK_KARNOPP) {
		cJSON *a = prsm_jw_array(w, tr, "stuck");
		for (size_t i = 0; a && i < n; i++)
			prsm_jw_bool(w, a, NULL, p[i].stuck);
	}
	cJSON *arr = prsm_jw_array(w, tr, "stages");
	const size_t ss = (size_t)K * sizeof *r->stage;
	for (int k = 0; k < K; k++) {
		const prsm_dyn_stage_point *s = &r->stage[k];
		cJSON *so = prsm_jw_object(w, arr, NULL);
		prsm_jw_number(w, so, "stage", k + 1);
		series(w, so, "carrier_angle_rad", &s->carrier_angle_rad, ss, n, 1.0);
		series(w, so, "carrier_speed_rad_s", &s->carrier_speed_rad_s, ss, n, 1.0);
		series(w, so, "carrier_ratio", &s->carrier_ratio, ss, n, 1.0);
		series(w, so, "nut_position_mm", &s->nut_position_mm, ss, n, 1.0);
		series(w, so, "contact_normal_force_N", &s->contact_normal_force_N, ss, n, 1.0);
		series(w, so, "nut_contact_force_N", &s->nut_contact_force_N, ss, n, 1.0);
		series(w, so, "gear_tangential_force_N", &s->gear_tangential_force_N, ss, n, 1.0);
		series(w, so, "gear_tooth_force_N", &s->gear_tooth_force_N, ss, n, 1.0);
		series(w, so, "cage_force_N", &s->cage_force_N, ss, n, 1.0);
		series(w, so, "slip_speed_m_s", &s->slip_speed_m_s, ss, n, 1.0);
		series(w, so, "stage_axial_load_N", &s->stage_axial_load_N, ss, n, 1.0);
		series(w, so, "spline_torque_Nm", &s->spline_torque_Nm, ss, n, 1.0);
		if (k > 0) {
			series(w, so, "spline_force_N", &s->spline_force_N, ss, n, 1.0);
			series(w, so, "thrust_load_N", &s->thrust_load_N, ss, n, 1.0);
			series(w, so, "thrust_torque_Nm", &s->thrust_torque_Nm, ss, n, 1.0);
		}
		series(w, so, "sliding_power_W", &s->sliding_power_W, ss, n, 1.0);
		cJSON *fl = prsm_jw_array(w, so, "upper_flank");
		for (size_t i = 0; fl && i < n; i++)
			prsm_jw_bool(w, fl, NULL, r->stage[i * (size_t)K + (size_t)k].flank == PRSM_DYN_FLANK_UPPER);
	}
}

static void write_checks(prsm_jw *w, cJSON *obj, const prsm_dyn_result *r, prsm_problems *warnings)
{
	const size_t n = r->points;
	cJSON *ch = prsm_jw_object(w, obj, "checks");
	const int pb_ok = r->max_power_balance_relative <= PRSM_IO_DYN_POWER_BALANCE_LIMIT;
	const int ne_ok = r->max_newton_euler_residual <= PRSM_IO_DYN_NEWTON_EULER_LIMIT;
	prsm_jw_number(w, ch, "max_power_balance_relative", r->max_power_balance_relative);
	prsm_jw_number(w, ch, "power_balance_limit", PRSM_IO_DYN_POWER_BALANCE_LIMIT);
	prsm_jw_number(w, ch, "max_newton_euler_residual", r->max_newton_euler_residual);
	prsm_jw_number(w, ch, "newton_euler_limit", PRSM_IO_DYN_NEWTON_EULER_LIMIT);
	prsm_jw_bool(w, ch, "passed", pb_ok && ne_ok);
	if (n > 0) {
		const prsm_dyn_point *p = r->point;
		series(w, ch, "power_balance_residual_W", &p->power_balance_residual_W, sizeof *p, n, 1.0);
		series(w, ch, "power_balance_relative", &p->power_balance_relative, sizeof *p, n, 1.0);
		series(w, ch, "newton_euler_residual", &p->newton_euler_residual, sizeof *p, n, 1.0);
	}
	if (warnings && !pb_ok)
		prsm_problems_add(warnings, "/dynamics/time", "power_balance",
		                  "the power balance closes only to %.3g of the input power (limit %g): tighten "
		                  "rel_tol and abs_tol", r->max_power_balance_relative, PRSM_IO_DYN_POWER_BALANCE_LIMIT);
	if (warnings && !ne_ok)
		prsm_problems_add(warnings, "/dynamics", "newton_euler",
		                  "the Newton-Euler recovery of the carrier acceleration differs by %.3g (limit %g)",
		                  r->max_newton_euler_residual, PRSM_IO_DYN_NEWTON_EULER_LIMIT);
}

void prsm_io_dynamics_write(prsm_jw *w, cJSON *obj, const char *key, const prsm_dyn_model *m,
                            const prsm_dyn_result *r, prsm_problems *warnings)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	cJSON *d = prsm_jw_object(w, obj, key);
	prsm_jw_string(w, d, "analysis", "transient");
	prsm_jw_number(w, d, "stages", r->stages);
	write_parameters(w, d, m);
	write_model(w, d, m);
	write_settled(w, d, m, r);
	if (o->friction.stick_model == PRSM_DYN_STICK_KARNOPP) {
		cJSON *st = prsm_jw_object(w, d, "stick");
		double fwd = NAN, back = NAN;
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_dyn_breakaway_torques(&fwd, &back, m, 0.0, &err))
			fwd = back = NAN;
		prsm_jw_number(w, st, "breakaway_torque_Nm", fwd);
		prsm_jw_number(w, st, "holding_torque_backward_Nm", back);
		prsm_jw_number(w, st, "mode_changes", r->mode_changes);
		const int kept = r->mode_changes < PRSM_DYN_MODE_CHANGES_MAX ? r->mode_changes : PRSM_DYN_MODE_CHANGES_MAX;
		cJSON *a = prsm_jw_array(w, st, "changes");
		for (int i = 0; a && i < kept; i++) {
			cJSON *c = prsm_jw_object(w, a, NULL);
			prsm_jw_number(w, c, "time_s", r->mode_change_time_s[i]);
			prsm_jw_string(w, c, "to", r->mode_change_to_stick[i] ? "stick" : "slip");
		}
	}
	write_transient(w, d, m, r);
	write_checks(w, d, r, warnings);
	cJSON *cv = prsm_jw_object(w, d, "convergence");
	prsm_jw_bool(w, cv, "converged", 1);
	prsm_jw_number(w, cv, "steps", (double)r->steps);
	prsm_jw_number(w, cv, "max_steps", (double)o->time.max_steps);
	prsm_jw_number(w, cv, "rhs_evaluations", (double)r->rhs_evaluations);
	prsm_jw_number(w, cv, "jacobian_evaluations", (double)r->jacobian_evaluations);
	prsm_jw_number(w, cv, "events", (double)r->events);
	prsm_jw_number(w, cv, "stepper_switch_time_s", r->stepper_switch_time_s);
}

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

cJSON *prsm_io_dynamics_result_to_json(const char *name, const prsm_dyn_model *m, const prsm_dyn_result *r,
                                       const prsm_problems *warnings)
{
	prsm_problems all;
	if (warnings)
		all = *warnings;
	else
		prsm_problems_init(&all);
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	cJSON *eng = prsm_jw_object(&w, root, "engine");
	prsm_jw_string(&w, eng, "name", "prsm");
	prsm_jw_string(&w, eng, "version", PRSM_VERSION);
	prsm_jw_string(&w, eng, "model", PRSM_DYN_MODEL_VERSION);
	prsm_jw_string(&w, eng, "build", prsm_engine_build());
	if (name && name[0])
		prsm_jw_string(&w, root, "name", name);
	/* the dynamics first (its checks add warnings), then the warnings before it */
	cJSON *tmp = prsm_jw_root(&w);
	prsm_io_dynamics_write(&w, tmp, "dynamics", m, r, &all);
	write_problems(&w, root, "warnings", &all);
	cJSON *d = tmp ? cJSON_DetachItemFromObjectCaseSensitive(tmp, "dynamics") : NULL;
	cJSON_Delete(tmp);
	prsm_jw_item(&w, root, "dynamics", d);
	if (w.failed) {
		cJSON_Delete(root);
		return NULL;
	}
	return root;
}

/* ---- CSV and text -------------------------------------------------------------------------------- */

static void csv_number(FILE *f, double v)
{
	if (isfinite(v))
		fprintf(f, ",%.17g", v);
	else
		fputc(',', f);
}

int prsm_io_dynamics_write_csv(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	const int K = r->stages;
	const int karnopp = o->friction.stick_model == PRSM_DYN_STICK_KARNOPP;
	fputs("time_s,screw_angle_rad,screw_speed_rad_s,screw_accel_rad_s2,axial_load_N,motor_torque_Nm,"
	      "input_torque_Nm,efficiency,energy_efficiency,power_input_W,power_output_W,power_sliding_W,"
	      "power_couplings_W,power_other_W,power_kinetic_W,power_balance_residual_W,newton_euler_residual",
	      f);
	if (karnopp)
		fputs(",stuck", f);
	static const char *const cols[] = {"carrier_ratio", "carrier_speed_rad_s", "nut_position_mm",
	                                   "contact_normal_force_N", "nut_contact_force_N", "gear_tangential_force_N",
	                                   "gear_tooth_force_N", "cage_force_N", "slip_speed_m_s", "stage_axial_load_N",
	                                   "spline_force_N", "thrust_torque_Nm"};
	for (int k = 0; k < K; k++)
		for (size_t c = 0; c < sizeof cols / sizeof cols[0]; c++)
			if (k > 0 || c < 10)
				fprintf(f, ",stage%d_%s", k + 1, cols[c]);
	fputc('\n', f);
	for (size_t i = 0; i < r->points; i++) {
		const prsm_dyn_point *p = &r->point[i];
		fprintf(f, "%.17g", p->time_s);
		const double v[] = {p->screw_angle_rad, p->screw_speed_rad_s, p->screw_accel_rad_s2, p->axial_load_N,
		                    p->motor_torque_Nm, p->input_torque_Nm, p->efficiency, p->energy_efficiency,
		                    p->power_input_W, p->power_output_W, p->power_sliding_W, p->power_couplings_W,
		                    p->power_other_W, p->power_kinetic_W, p->power_balance_residual_W,
		                    p->newton_euler_residual};
		for (size_t j = 0; j < sizeof v / sizeof v[0]; j++)
			csv_number(f, v[j]);
		if (karnopp)
			fprintf(f, ",%d", p->stuck);
		for (int k = 0; k < K; k++) {
			const prsm_dyn_stage_point *s = &r->stage[i * (size_t)K + (size_t)k];
			const double sv[] = {s->carrier_ratio, s->carrier_speed_rad_s, s->nut_position_mm,
			                     s->contact_normal_force_N, s->nut_contact_force_N, s->gear_tangential_force_N,
			                     s->gear_tooth_force_N, s->cage_force_N, s->slip_speed_m_s, s->stage_axial_load_N,
			                     s->spline_force_N, s->thrust_torque_Nm};
			for (size_t j = 0; j < sizeof sv / sizeof sv[0]; j++)
				if (k > 0 || j < 10)
					csv_number(f, sv[j]);
		}
		fputc('\n', f);
	}
	return ferror(f) ? PRSM_EIO : 0;
}

int prsm_io_dynamics_write_text(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r,
                                const prsm_problems *warnings)
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
