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
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "prsm_io_tables.h"
#include "util/error.h"
#include "util/version.h"

#define KG_MM2 1e6             /* kg m^2 -> kg mm^2 */
#define DEG (180.0 / M_PI)     /* rad -> deg */

/* The per-stage fields of `inertia` (the single-stage form; a chain's are in inertia.stages). */
static const char *const stage_keys[] = {"gear_face_width_mm", "roller_mass_kg", "roller_inertia_kg_mm2",
                                         "carrier_mass_kg", "carrier_inertia_kg_mm2", "nut_mass_kg",
                                         "screw_mass_kg", "screw_inertia_kg_mm2", NULL};

/* ---- the hooks of the table (schemas/dynamics.schema.json, x-prsm) ---------------------------- */

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

/* ---- the vibration analyses: sections, step and rules (docs/vibration.md) ---------------------- */

static const char *const analysis_names[] = {"transient", "linear", "vibration", "sweep", "frequency_response",
                                             "basins", NULL};
/* the section each vibration analysis reads, besides the model's */
static const char *const analysis_section[PRSM_IO_DYN_ANALYSES] = {NULL, "linear", "steady_state", "sweep",
                                                                   "frequency_response", "basins"};

const char *prsm_io_dynamics_analysis_name(int analysis)
{
	return analysis >= 0 && analysis < PRSM_IO_DYN_ANALYSES ? analysis_names[analysis] : "unknown";
}

static const char *const sweep_parameter_names[PRSM_IO_SWEEP_PARAMETERS] = {
	"frequency_ratio", "screw_speed_rad_s", "mesh_error_um", "mesh_damping_ratio",
	"error_amplitude", "damping_ratio", "mean_load", "stiffness_variation"};

const char *prsm_io_sweep_parameter_name(int parameter)
{
	return parameter >= 0 && parameter < PRSM_IO_SWEEP_PARAMETERS ? sweep_parameter_names[parameter] : "unknown";
}

int prsm_io_sweep_parameter_engine(int parameter, double *to_engine)
{
	static const int engine[PRSM_IO_SWEEP_PARAMETERS] = {
		PRSM_VIB_PARAM_FREQUENCY_RATIO, PRSM_VIB_PARAM_SCREW_SPEED, PRSM_VIB_PARAM_MESH_ERROR,
		PRSM_VIB_PARAM_DAMPING_RATIO, PRSM_VIB_PARAM_MESH_ERROR, PRSM_VIB_PARAM_DAMPING_RATIO,
		PRSM_VIB_PARAM_MEAN_FORCE, PRSM_VIB_PARAM_STIFFNESS_VARIATION};
	if (to_engine != NULL)
		*to_engine = parameter == PRSM_IO_SWEEP_MESH_ERROR_UM ? 1e-6 : 1.0;
	return parameter >= 0 && parameter < PRSM_IO_SWEEP_PARAMETERS ? engine[parameter] : -1;
}

void prsm_io_gear_pair_init(prsm_vib_gear_pair *g)
{
	const prsm_vib_gear_pair d = PRSM_VIB_GEAR_PAIR_INIT;
	*g = d;
}

void prsm_io_vib_steady_init(prsm_io_vib_steady *s)
{
	memset(s, 0, sizeof *s);
	s->transient_periods = 300;
	s->recorded_periods = 64;
	s->clock = PRSM_VIB_CLOCK_AUTO;
	s->observable = PRSM_VIB_OBS_MESH_DEFLECTION;
	s->roller = 0;
	s->period_tolerance = NAN;
	s->samples_per_period = 128;
	s->lyapunov = 0;
	s->lyapunov_method = PRSM_VIB_LYAPUNOV_BENETTIN;
	s->lyapunov_exponents = 1;
	s->lyapunov_periods = 2000;
}

void prsm_io_vib_sweep_init(prsm_io_vib_sweep *s)
{
	memset(s, 0, sizeof *s);
	s->parameter = PRSM_IO_SWEEP_FREQUENCY_RATIO;
	s->from = 0.7;
	s->to = 1.6;
	s->step = 0.05;
	s->up = s->down = 1;
	s->continuation = 1;
	s->transient_periods = 300;
	s->recorded_periods = 64;
	s->clock = PRSM_VIB_CLOCK_AUTO;
	s->observable = PRSM_VIB_OBS_MESH_DEFLECTION;
	s->roller = 0;
	s->period_tolerance = NAN;
	s->lyapunov = 0;
	s->lyapunov_periods = 2000;
}

void prsm_io_vib_basins_init(prsm_io_vib_basins *b)
{
	memset(b, 0, sizeof *b);
	b->deflection_min = -2.0;
	b->deflection_max = 4.0;
	b->deflection_cells = 41;
	b->rate_min = -3.0;
	b->rate_max = 3.0;
	b->rate_cells = 41;
	b->periods = 100;
	b->identify_periods = 64;
	b->distance = 1e-3;
	b->roller = 0;
	b->period_tolerance = NAN;
}

void prsm_io_vib_linear_init(prsm_io_vib_linear *l)
{
	memset(l, 0, sizeof *l);
	l->input = PRSM_VIB_IN_MESH_ERROR;
	l->output = PRSM_VIB_OUT_MESH_DEFLECTION;
	l->from_Hz = l->to_Hz = NAN;
	l->from_frequency_ratio = 0.5;
	l->to_frequency_ratio = 1.5;
	l->points = 401;
}

void prsm_io_vib_frequency_response_init(prsm_io_vib_frequency_response *f)
{
	f->agreement_tolerance = 1e-3;
}

void prsm_io_vib_request_init(prsm_io_vib_request *r)
{
	memset(r, 0, sizeof *r);
	r->analysis = PRSM_IO_DYN_TRANSIENT;
	prsm_io_gear_pair_init(&r->gear_pair);
	prsm_vib_options_init(&r->vibration);
	prsm_io_vib_steady_init(&r->steady_state);
	prsm_io_vib_sweep_init(&r->sweep);
	prsm_io_vib_basins_init(&r->basins);
	prsm_io_vib_linear_init(&r->linear);
	prsm_io_vib_frequency_response_init(&r->frequency_response);
	const prsm_vib_integration integ = PRSM_VIB_INTEGRATION_INIT;
	r->integration = integ;
}

/* vibration.te_lines: "none", "statics", or the lines, each by its table ($defs/te_line). */
void prsm_io_hook_vibration_te_lines(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_vib_options *o = base;
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(obj, "te_lines");
	if (t == NULL)
		return;
	char ptr[PRSM_JSON_POINTER_MAX], ip[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "te_lines");
	if (cJSON_IsString(t)) {
		static const char *const names[] = {"none", "statics", NULL};
		int i;
		if (prsm_json_enum_value(&i, t, ptr, names, problems) == 0)
			o->te_source = i == 0 ? PRSM_VIB_TE_NONE : PRSM_VIB_TE_STATICS;
		return;
	}
	const int n = cJSON_GetArraySize(t);
	if (!cJSON_IsArray(t) || n > PRSM_VIB_TE_LINES_MAX) {
		prsm_problems_add(problems, ptr, cJSON_IsArray(t) ? "size" : "type",
		                  "must be \"none\", \"statics\" or an array of at most %d lines "
		                  "{\"order_per_rev\", \"amplitude_um\", \"phase_deg\"}", PRSM_VIB_TE_LINES_MAX);
		return;
	}
	const int before = prsm_problems_total(problems);
	int k = 0;
	for (const cJSON *it = t->child; it; it = it->next, k++) {
		prsm_json_pointer_append_index(ip, sizeof ip, ptr, k);
		prsm_vib_te_line l = {NAN, NAN, 0.0};
		if (prsm_json_object_value(it, ip, problems) == 0)
			prsm_io_read(&l, &prsm_io_t_dynamics_te_line, it, ip, problems);
		o->te_line[k] = l;
	}
	if (prsm_problems_total(problems) == before) {
		o->te_source = PRSM_VIB_TE_LINES;
		o->te_lines = n;
	}
}

/* sweep.directions: ["up"], ["down"] or both. */
void prsm_io_hook_sweep_directions(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_io_vib_sweep *s = base;
	const cJSON *d = cJSON_GetObjectItemCaseSensitive(obj, "directions");
	if (d == NULL)
		return;
	char ptr[PRSM_JSON_POINTER_MAX], ip[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "directions");
	const int n = cJSON_GetArraySize(d);
	if (!cJSON_IsArray(d) || n < 1 || n > 2) {
		prsm_problems_add(problems, ptr, cJSON_IsArray(d) ? "size" : "type",
		                  "must be [\"up\"], [\"down\"] or [\"up\", \"down\"]");
		return;
	}
	static const char *const names[] = {"up", "down", NULL};
	int up = 0, down = 0, k = 0, bad = 0;
	for (const cJSON *it = d->child; it; it = it->next, k++) {
		prsm_json_pointer_append_index(ip, sizeof ip, ptr, k);
		int i;
		if (prsm_json_enum_value(&i, it, ip, names, problems)) {
			bad = 1;
			continue;
		}
		if ((i == 0 && up) || (i == 1 && down)) {
			prsm_problems_add(problems, ip, "duplicate", "each direction once");
			bad = 1;
		}
		up |= i == 0;
		down |= i == 1;
	}
	if (!bad) {
		s->up = up;
		s->down = down;
	}
}

/* A section of the vibration analyses: the item at key, by its table, into base. */
static void read_section(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer,
                         const char *key, prsm_problems *problems)
{
	const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
	if (it == NULL)
		return;
	char ptr[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, key);
	if (prsm_json_object_value(it, ptr, problems) == 0)
		prsm_io_read(base, t, it, ptr, problems);
}

/* The step of the dynamics table (schemas/dynamics.schema.json, "order"): the analysis and the
 * sections of the vibration analyses into the caller's prsm_io_vib_request (at->ctx; NULL: read
 * into a scratch request, checked only). */
int prsm_io_step_dynamics_vibration(prsm_io_at *at, prsm_problems *problems)
{
	prsm_io_vib_request *scratch = NULL, *v = at->ctx;
	if (v == NULL) {
		scratch = malloc(sizeof *scratch);
		if (scratch == NULL) {
			prsm_problems_add(problems, at->pointer, "memory", "out of memory reading the dynamics object");
			return 1;
		}
		prsm_io_vib_request_init(scratch);
		v = scratch;
	}
	const cJSON *obj = at->obj;
	const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, "analysis");
	if (a != NULL) {
		char ptr[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(ptr, sizeof ptr, at->pointer, "analysis");
		const char *s;
		v->analysis = -1; /* unknown until read */
		if (prsm_json_string_value(&s, a, ptr, 64, problems) == 0) {
			if (strcmp(s, "calibrate") == 0)
				prsm_problems_add(problems, ptr, "not_available",
				                  "\"calibrate\" runs with prsm calibrate FILE [--measured CSV], a design with its "
				                  "measured data (docs/measured-data.md); a simulation is transient, linear, vibration, "
				                  "sweep, frequency_response or basins (docs/dynamics.md, docs/vibration.md)");
			else
				prsm_json_enum_value(&v->analysis, a, ptr, analysis_names, problems);
		}
	}
	v->gear_pair_model = cJSON_GetObjectItemCaseSensitive(obj, "gear_pair") != NULL;
	read_section(&v->gear_pair, &prsm_io_t_dynamics_gear_pair, obj, at->pointer, "gear_pair", problems);
	read_section(&v->vibration, &prsm_io_t_dynamics_vibration, obj, at->pointer, "vibration", problems);
	read_section(&v->steady_state, &prsm_io_t_dynamics_steady_state, obj, at->pointer, "steady_state", problems);
	read_section(&v->sweep, &prsm_io_t_dynamics_sweep, obj, at->pointer, "sweep", problems);
	read_section(&v->basins, &prsm_io_t_dynamics_basins, obj, at->pointer, "basins", problems);
	read_section(&v->linear, &prsm_io_t_dynamics_linear, obj, at->pointer, "linear", problems);
	read_section(&v->frequency_response, &prsm_io_t_dynamics_frequency_response, obj, at->pointer,
	             "frequency_response", problems);
	free(scratch);
	return 0;
}

/* A problem at /dynamics/<section>[/<key>] unless one is there already. */
static void problem_once(prsm_problems *p, int from, const char *section, const char *key, const char *code,
                         const char *fmt, ...) __attribute__((format(printf, 6, 7)));
static void problem_once(prsm_problems *p, int from, const char *section, const char *key, const char *code,
                         const char *fmt, ...)
{
	char ptr[PRSM_JSON_POINTER_MAX], sec[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(sec, sizeof sec, "/dynamics", section);
	if (key != NULL)
		prsm_json_pointer_append(ptr, sizeof ptr, sec, key);
	else
		snprintf(ptr, sizeof ptr, "%s", sec);
	for (int i = from; i < p->count; i++)
		if (strcmp(p->items[i].pointer, ptr) == 0)
			return;
	char msg[PRSM_PROBLEM_MESSAGE_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	prsm_problems_add(p, ptr, code, "%s", msg);
}

static const cJSON *member(const cJSON *obj, const char *key)
{
	return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

/* Every member of section (an object of obj) but the allowed ones: "not used" at its pointer. */
static void only_members(prsm_problems *p, int from, const cJSON *obj, const char *section,
                         const char *const *allowed, const char *why)
{
	const cJSON *s = member(obj, section);
	if (!cJSON_IsObject(s))
		return;
	for (const cJSON *it = s->child; it; it = it->next) {
		int ok = 0;
		for (int i = 0; allowed[i] && !ok; i++)
			ok = it->string != NULL && strcmp(it->string, allowed[i]) == 0;
		if (!ok && it->string != NULL)
			problem_once(p, from, section, it->string, "not_used", "%s", why);
	}
}

static int axial_observable(int obs)
{
	return obs == PRSM_VIB_OBS_AXIAL_DEFLECTION || obs == PRSM_VIB_OBS_AXIAL_RATE || obs == PRSM_VIB_OBS_THREAD_FORCE;
}

/* The observable and clock of a section against the model's moving branches. */
static void observable_rules(prsm_problems *p, int from, const prsm_io_vib_request *v, const char *section,
                             int observable, int clock)
{
	const int pair = v->gear_pair_model, br = v->vibration.branches;
	if (axial_observable(observable) && (pair || br == PRSM_VIB_BRANCHES_GEAR))
		problem_once(p, from, section, "observable", "branch",
		             "%s: an axial observable needs the reduced model's axial branch (vibration.branches both or "
		             "axial)", pair ? "a gear pair has none" : "the axial branch is off");
	else if (!axial_observable(observable) && !pair && br == PRSM_VIB_BRANCHES_AXIAL)
		problem_once(p, from, section, "observable", "branch",
		             "the gear branch is off (vibration.branches axial): observe axial_deflection, axial_rate "
		             "or thread_force");
	if (clock == PRSM_VIB_CLOCK_TE && (pair || v->vibration.te_source == PRSM_VIB_TE_NONE))
		problem_once(p, from, section, "clock", "no_te",
		             "the te clock is the common period of the TE lines: %s", pair ? "a gear pair has none"
		                                                                       : "give vibration.te_lines");
}

static void periods_rule(prsm_problems *p, int from, const char *section, int transient, int recorded,
                         int lyapunov, int lyapunov_periods)
{
	const double total = (double)transient + recorded + (lyapunov ? lyapunov_periods : 0);
	if (total > PRSM_VIB_PERIODS_MAX)
		problem_once(p, from, section, "transient_periods", "too_long",
		             "%.0f forcing periods per run (transient + recorded%s), at most %d", total,
		             lyapunov ? " + Lyapunov" : "", PRSM_VIB_PERIODS_MAX);
}

/* A sweep grid value of parameter par is valid for the model (the engine's ranges). */
static const char *sweep_value_invalid(const prsm_io_vib_request *v, int par, double x)
{
	switch (par) {
	case PRSM_IO_SWEEP_FREQUENCY_RATIO:
		return x > 0.0 && x <= 1e3 ? NULL : "a frequency ratio is in (0, 1000]";
	case PRSM_IO_SWEEP_SCREW_SPEED:
		return x > 0.0 && x <= 1e6 ? NULL : "a screw speed is in (0, 1e6] rad/s";
	case PRSM_IO_SWEEP_MESH_ERROR_UM:
		return x >= 0.0 && x <= 1e4 ? NULL : "a mesh error is in [0, 10000] um";
	case PRSM_IO_SWEEP_MESH_DAMPING_RATIO:
	case PRSM_IO_SWEEP_DAMPING_RATIO:
		return x > 0.0 && x < 1.0 ? NULL : "a damping ratio is in (0, 1): without damping no transient ends";
	case PRSM_IO_SWEEP_ERROR_AMPLITUDE:
		return x >= 0.0 && x <= 1e3 ? NULL : "an error amplitude is in [0, 1000]";
	case PRSM_IO_SWEEP_MEAN_LOAD:
		return fabs(x) <= 1e3 ? NULL : "a mean load is in [-1000, 1000]";
	case PRSM_IO_SWEEP_STIFFNESS_VARIATION: {
		const double D = v->gear_pair.contact_ratio - 1.0;
		return 1.0 - x * D > 0.0 && 1.0 + x * (1.0 - D) > 0.0
		       ? NULL : "the stiffness variation makes a mesh stiffness non-positive (-1/(1 - D) < kappa < 1/D)";
	}
	default:
		return "unknown parameter";
	}
}

static void sweep_rules(prsm_problems *p, int from, const cJSON *obj, const prsm_io_vib_request *v, int fr)
{
	const prsm_io_vib_sweep *s = &v->sweep;
	const cJSON *so = member(obj, "sweep");
	const int pair = v->gear_pair_model;
	static const int reduced_only[] = {PRSM_IO_SWEEP_SCREW_SPEED, PRSM_IO_SWEEP_MESH_ERROR_UM,
	                                   PRSM_IO_SWEEP_MESH_DAMPING_RATIO};
	int ok_par = 1;
	if (fr && s->parameter != PRSM_IO_SWEEP_FREQUENCY_RATIO) {
		problem_once(p, from, "sweep", "parameter", "frequency_response",
		             "a frequency response sweeps the frequency ratio (got %s)", prsm_io_sweep_parameter_name(s->parameter));
		ok_par = 0;
	} else if (s->parameter != PRSM_IO_SWEEP_FREQUENCY_RATIO) {
		int reduced = 0;
		for (size_t i = 0; i < sizeof reduced_only / sizeof reduced_only[0]; i++)
			reduced |= s->parameter == reduced_only[i];
		if (reduced == pair) {
			problem_once(p, from, "sweep", "parameter", "model",
			             "%s is a parameter of the %s: the %s sweeps frequency_ratio, %s",
			             prsm_io_sweep_parameter_name(s->parameter), pair ? "reduced model" : "gear pair",
			             pair ? "gear pair" : "reduced model",
			             pair ? "error_amplitude, damping_ratio, mean_load or stiffness_variation"
			                  : "screw_speed_rad_s, mesh_error_um or mesh_damping_ratio");
			ok_par = 0;
		}
	}
	if (fr && member(so, "directions") != NULL && !(s->up && s->down))
		problem_once(p, from, "sweep", "directions", "frequency_response",
		             "a frequency response sweeps both ways (its jumps are where they disagree): [\"up\", \"down\"]");
	if (!(s->to >= s->from)) {
		problem_once(p, from, "sweep", "to", "order", "the sweep runs from %g to %g: to must be >= from", s->from,
		             s->to);
		return;
	}
	const double q = floor((s->to - s->from) / s->step + 1e-9);
	if (!(q + 1.0 <= PRSM_VIB_SWEEP_POINTS_MAX)) {
		problem_once(p, from, "sweep", "step", "too_many",
		             "the sweep has %.4g points per direction, at most %d: raise the step", q + 1.0,
		             PRSM_VIB_SWEEP_POINTS_MAX);
		return;
	}
	const int dirs = fr ? 2 : s->up + s->down;
	const double total = (q + 1.0) * dirs *
	                     ((double)s->transient_periods + s->recorded_periods + (s->lyapunov ? s->lyapunov_periods : 0));
	if (total > 5e8)
		problem_once(p, from, "sweep", NULL, "too_long",
		             "the sweep integrates %.3g forcing periods in all, at most 5e8: fewer points or periods", total);
	periods_rule(p, from, "sweep", s->transient_periods, s->recorded_periods, s->lyapunov, s->lyapunov_periods);
	if (ok_par) {
		const char *why = sweep_value_invalid(v, s->parameter, s->from);
		if (why)
			problem_once(p, from, "sweep", "from", "range", "%s (got %g)", why, s->from);
		const double last = s->from + q * s->step;
		why = sweep_value_invalid(v, s->parameter, last);
		if (why)
			problem_once(p, from, "sweep", "to", "range", "%s (the last grid value is %g)", why, last);
	}
	observable_rules(p, from, v, "sweep", s->observable, s->clock);
	if (pair && s->roller != 0)
		problem_once(p, from, "sweep", "roller", "model", "a gear pair has one mesh: roller 0");
}

static void steady_rules(prsm_problems *p, int from, const prsm_io_vib_request *v)
{
	const prsm_io_vib_steady *s = &v->steady_state;
	periods_rule(p, from, "steady_state", s->transient_periods, s->recorded_periods, s->lyapunov, s->lyapunov_periods);
	if ((double)s->recorded_periods * s->samples_per_period > 4e7)
		problem_once(p, from, "steady_state", "samples_per_period", "too_many",
		             "%d recorded periods x %d samples is more than 4e7 samples", s->recorded_periods,
		             s->samples_per_period);
	observable_rules(p, from, v, "steady_state", s->observable, s->clock);
	if (v->gear_pair_model && s->roller != 0)
		problem_once(p, from, "steady_state", "roller", "model", "a gear pair has one mesh: roller 0");
	if (v->gear_pair_model && s->lyapunov_exponents > 2)
		problem_once(p, from, "steady_state", "lyapunov_exponents", "range",
		             "a gear pair has 2 Lyapunov exponents (got %d)", s->lyapunov_exponents);
	if (s->lyapunov_method == PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES && s->lyapunov_exponents != 1)
		problem_once(p, from, "steady_state", "lyapunov_exponents", "range",
		             "two trajectories give the largest exponent only: 1 (got %d)", s->lyapunov_exponents);
}

static void basins_rules(prsm_problems *p, int from, const prsm_io_vib_request *v)
{
	const prsm_io_vib_basins *b = &v->basins;
	if (!(b->deflection_max > b->deflection_min))
		problem_once(p, from, "basins", "deflection_max", "order", "the grid needs deflection_min < deflection_max");
	if (!(b->rate_max > b->rate_min))
		problem_once(p, from, "basins", "rate_max", "order", "the grid needs rate_min < rate_max");
	const double cells = (double)b->deflection_cells * b->rate_cells;
	if (cells > PRSM_VIB_BASIN_CELLS_MAX)
		problem_once(p, from, "basins", "deflection_cells", "too_many", "%.0f cells, at most %d", cells,
		             PRSM_VIB_BASIN_CELLS_MAX);
	else if (cells * ((double)b->periods + b->identify_periods) > 2e8)
		problem_once(p, from, "basins", "periods", "too_long",
		             "the grid integrates %.3g forcing periods in all, at most 2e8", cells * ((double)b->periods +
		                                                                                     b->identify_periods));
	if (v->gear_pair_model && b->roller != 0)
		problem_once(p, from, "basins", "roller", "model", "a gear pair has one mesh: roller 0");
	if (!v->gear_pair_model && v->vibration.branches == PRSM_VIB_BRANCHES_AXIAL)
		problem_once(p, from, "basins", NULL, "branch",
		             "the basins vary a roller's spin: the gear branch is off (vibration.branches axial)");
}

static void linear_rules(prsm_problems *p, int from, const cJSON *obj, const prsm_io_vib_request *v)
{
	const prsm_io_vib_linear *l = &v->linear;
	const cJSON *lo = member(obj, "linear");
	const int pair = v->gear_pair_model, br = v->vibration.branches;
	static const char *const hz[] = {"from_Hz", "to_Hz"}, *const ratio[] = {"from_frequency_ratio",
	                                                                          "to_frequency_ratio"};
	for (int i = 0; i < 2; i++) {
		if (pair && member(lo, hz[i]))
			problem_once(p, from, "linear", hz[i], "model",
			             "a gear pair is dimensionless: give the band as from_frequency_ratio, to_frequency_ratio");
		if (!pair && member(lo, ratio[i]))
			problem_once(p, from, "linear", ratio[i], "model",
			             "the reduced model's band is in Hz: from_Hz, to_Hz");
	}
	if (pair && !(l->to_frequency_ratio > l->from_frequency_ratio))
		problem_once(p, from, "linear", "to_frequency_ratio", "order", "the band needs from < to");
	if (!pair && !isnan(l->from_Hz) && !isnan(l->to_Hz) && !(l->to_Hz > l->from_Hz))
		problem_once(p, from, "linear", "to_Hz", "order", "the band needs from_Hz < to_Hz");
	const int axial_in = l->input != PRSM_VIB_IN_MESH_ERROR, axial_out = l->output != PRSM_VIB_OUT_MESH_DEFLECTION;
	if (pair && axial_in)
		problem_once(p, from, "linear", "input", "model", "a gear pair is excited by its mesh error: mesh_error");
	if (pair && axial_out)
		problem_once(p, from, "linear", "output", "model", "a gear pair's output is its mesh deflection");
	if (!pair && axial_in && br == PRSM_VIB_BRANCHES_GEAR)
		problem_once(p, from, "linear", "input", "branch", "the axial branch is off (vibration.branches gear)");
	if (!pair && !axial_in && br == PRSM_VIB_BRANCHES_AXIAL)
		problem_once(p, from, "linear", "input", "branch", "the gear branch is off (vibration.branches axial)");
	if (!pair && axial_out && br == PRSM_VIB_BRANCHES_GEAR)
		problem_once(p, from, "linear", "output", "branch", "the axial branch is off (vibration.branches gear)");
	if (!pair && !axial_out && br == PRSM_VIB_BRANCHES_AXIAL)
		problem_once(p, from, "linear", "output", "branch", "the gear branch is off (vibration.branches axial)");
	if (pair && l->input_roller != 0)
		problem_once(p, from, "linear", "input_roller", "model", "a gear pair has one mesh: roller 0");
	if (pair && l->output_roller != 0)
		problem_once(p, from, "linear", "output_roller", "model", "a gear pair has one mesh: roller 0");
}

/* The vibration model's own checks (dyn/vib.h), each problem at the request's name for it. */
static void model_checks(prsm_problems *p, int from, const prsm_io_vib_request *v)
{
	prsm_problems mp;
	prsm_problems_init(&mp);
	if (v->gear_pair_model)
		prsm_vib_gear_pair_check(&v->gear_pair, &mp);
	else
		prsm_vib_options_check(&v->vibration, &mp);
	static const char *const rename[][2] = {
		{"/dynamics/vibration/gear_pressure_angle_rad", "/dynamics/vibration/gear_pressure_angle_deg"},
	};
	static const char *const pair_names[][2] = {
		{"mesh_damping_ratio", "damping_ratio"}, {"mean_force", "mean_load"}, {"mesh_error", "error_amplitude"},
		{"contact_ratio", "contact_ratio"},      {"stiffness_variation", "stiffness_variation"},
		{"frequency_ratio", "frequency_ratio"}};
	for (int i = 0; i < mp.count; i++) {
		char ptr[PRSM_JSON_POINTER_MAX];
		snprintf(ptr, sizeof ptr, "%s", mp.items[i].pointer);
		for (size_t k = 0; k < sizeof rename / sizeof rename[0]; k++)
			if (strcmp(ptr, rename[k][0]) == 0)
				snprintf(ptr, sizeof ptr, "%s", rename[k][1]);
		if (v->gear_pair_model) {
			const char *leaf = strrchr(mp.items[i].pointer, '/');
			for (size_t k = 0; leaf && k < sizeof pair_names / sizeof pair_names[0]; k++)
				if (strcmp(leaf + 1, pair_names[k][0]) == 0)
					snprintf(ptr, sizeof ptr, "/dynamics/gear_pair/%s", pair_names[k][1]);
		}
		if (!problem_at_pointer(p, from, ptr))
			prsm_problems_add(p, ptr, mp.items[i].code, "%s", mp.items[i].message);
	}
}

/* The rules of the vibration analyses (analysis != transient) and of the transient against their
 * sections, once each field has been read. */
static void vibration_rules(prsm_problems *p, int from, const cJSON *obj, prsm_io_vib_request *v, int stages)
{
	const int an = v->analysis;
	static const char *const vib_sections[] = {"gear_pair", "vibration", "steady_state", "sweep", "basins", "linear",
	                                           "frequency_response", NULL};
	if (an == PRSM_IO_DYN_TRANSIENT) {
		for (int i = 0; vib_sections[i] && stages > 0; i++)
			if (member(obj, vib_sections[i]))
				problem_once(p, from, vib_sections[i], NULL, "not_used",
				             "belongs to the vibration analyses (docs/vibration.md): the transient does not use it; "
				             "set \"analysis\" to linear, vibration, sweep, frequency_response or basins");
		if (stages == 0)
			problem_once(p, from, "analysis", NULL, "design",
			             "the transient needs a design: a request without one is a gear pair "
			             "(an analysis other than transient, and gear_pair)");
		return;
	}
	const int pair = v->gear_pair_model;
	if (stages > 1)
		problem_once(p, from, "analysis", NULL, "single_stage",
		             "the vibration model (docs/vibration.md) is built for a single-stage screw, not a chain of %d",
		             stages);
	if (stages >= 1 && pair)
		problem_once(p, from, "gear_pair", NULL, "with_design",
		             "the gear pair is a request of its own, without a design: {\"dynamics\": {\"analysis\": ..., "
		             "\"gear_pair\": {...}}}; a design runs its reduced model (the vibration object)");
	if (stages == 0 && !pair)
		problem_once(p, from, "gear_pair", NULL, "required",
		             "a request without a design is a gear pair: give gear_pair (or a design for the reduced model)");
	/* the transient's members the vibration analyses do not use */
	static const char *const integ[] = {"rel_tol", "abs_tol", "max_steps", NULL};
	only_members(p, from, obj, "time", integ,
	             "the vibration analyses count forcing periods (steady_state, sweep, basins): their time object "
	             "holds rel_tol, abs_tol and max_steps only");
	static const char *const none[] = {NULL};
	if (member(obj, "input"))
		problem_once(p, from, "input", NULL, "not_used",
		             "the vibration model runs at the constant screw speed of vibration.screw_speed_rad_s "
		             "(or vibration.frequency_ratio): input drives the transient only");
	if (member(obj, "losses"))
		problem_once(p, from, "losses", NULL, "not_used",
		             "the vibration model has the screw-contact friction only: losses belong to the transient");
	if (pair) {
		static const char *const design_only[] = {"load", "friction", "inertia", "vibration"};
		for (size_t i = 0; i < sizeof design_only / sizeof design_only[0]; i++)
			if (member(obj, design_only[i]))
				problem_once(p, from, design_only[i], NULL, "not_used",
				             "a gear pair is dimensionless and has every parameter in gear_pair: %s is the reduced "
				             "model's (with a design)", design_only[i]);
	} else {
		static const char *const load_keys[] = {"axial_load_N", "shape", NULL};
		only_members(p, from, obj, "load", load_keys, "the vibration model's load is constant: axial_load_N");
		if (cJSON_IsObject(member(obj, "load")) && member(member(obj, "load"), "shape") &&
		    cJSON_IsString(member(member(obj, "load"), "shape")) &&
		    strcmp(member(member(obj, "load"), "shape")->valuestring, "constant") != 0 &&
		    strcmp(member(member(obj, "load"), "shape")->valuestring, "step") != 0)
			problem_once(p, from, "load", "shape", "not_used", "the vibration model's load is constant");
		static const char *const fric_keys[] = {"model", "mu", "smoothing_velocity_m_s", NULL};
		only_members(p, from, obj, "friction", fric_keys,
		             "the vibration model's friction is regularised Coulomb: model, mu, smoothing_velocity_m_s");
		const cJSON *fm = member(member(obj, "friction"), "model");
		if (cJSON_IsString(fm) && strcmp(fm->valuestring, "coulomb") != 0)
			problem_once(p, from, "friction", "model", "not_used",
			             "the vibration model's friction is regularised Coulomb (docs/vibration.md)");
	}
	(void)none;
	/* the sections against the analysis */
	for (int a = PRSM_IO_DYN_LINEAR; a < PRSM_IO_DYN_ANALYSES; a++) {
		const char *sec = analysis_section[a];
		if (member(obj, sec) && a != an && !(a == PRSM_IO_DYN_SWEEP && an == PRSM_IO_DYN_FREQUENCY_RESPONSE))
			problem_once(p, from, sec, NULL, "not_used", "belongs to analysis %s, not %s", analysis_names[a],
			             analysis_names[an]);
	}
	/* the integration: the time object's tolerances, else the analysis' */
	const double tol = an == PRSM_IO_DYN_LINEAR || an == PRSM_IO_DYN_VIBRATION ? 1e-10 : 1e-9;
	const cJSON *t = member(obj, "time");
	v->integration.rel_tol = tol;
	v->integration.abs_tol = tol;
	(void)t;
	if (an == PRSM_IO_DYN_VIBRATION)
		steady_rules(p, from, v);
	else if (an == PRSM_IO_DYN_SWEEP || an == PRSM_IO_DYN_FREQUENCY_RESPONSE)
		sweep_rules(p, from, obj, v, an == PRSM_IO_DYN_FREQUENCY_RESPONSE);
	else if (an == PRSM_IO_DYN_BASINS)
		basins_rules(p, from, v);
	else if (an == PRSM_IO_DYN_LINEAR)
		linear_rules(p, from, obj, v);
	v->te_from_errors = !pair && v->vibration.te_source == PRSM_VIB_TE_STATICS;
	model_checks(p, from, v);
}

int prsm_io_dynamics_read(prsm_dyn_options *o, prsm_io_vib_request *v_in, const cJSON *obj, int stages,
                          prsm_problems *problems)
{
	prsm_io_vib_request *scratch = NULL, *v = v_in;
	if (v == NULL) {
		scratch = malloc(sizeof *scratch);
		if (scratch == NULL) {
			prsm_problems_add(problems, "/dynamics", "memory", "out of memory reading the dynamics object");
			return PRSM_EINVAL;
		}
		v = scratch;
	}
	prsm_io_vib_request_init(v);
	prsm_dyn_options_init(o);
	const int before = prsm_problems_total(problems);
	const int first = problems->count;
	if (obj != NULL) {
		if (prsm_json_object_value(obj, "/dynamics", problems)) {
			free(scratch);
			return PRSM_EINVAL;
		}
		o->time.output_step_s = NAN; /* given, or end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS below */
		prsm_io_read_ctx(o, &prsm_io_t_dynamics, obj, "/dynamics", v, problems);
		if (stages >= 1)
			check_inertia_form(obj, stages, problems);
		if (isnan(o->time.output_step_s))
			o->time.output_step_s = o->time.end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS;
	} else {
		o->time.output_step_s = o->time.end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS;
	}
	if (v->analysis <= PRSM_IO_DYN_TRANSIENT) { /* the transient, or an analysis not known */
		/* the model's cross-field rules, each once: a field refused above keeps its default, which
		 * the rules may not hold against it */
		prsm_problems cross;
		prsm_problems_init(&cross);
		prsm_dyn_options_check(o, stages >= 1 ? stages : 1, &cross);
		for (int i = 0; i < cross.count; i++)
			if (!problem_at_pointer(problems, first, cross.items[i].pointer))
				prsm_problems_add(problems, cross.items[i].pointer, cross.items[i].code, "%s", cross.items[i].message);
	}
	if (v->analysis >= 0)
		vibration_rules(problems, first, obj, v, stages);
	/* the integration settings a vibration analysis takes from `time` */
	const cJSON *t = member(obj, "time");
	if (member(t, "rel_tol"))
		v->integration.rel_tol = o->time.rel_tol;
	if (member(t, "abs_tol"))
		v->integration.abs_tol = o->time.abs_tol;
	if (member(t, "max_steps"))
		v->integration.max_steps = o->time.max_steps;
	free(scratch);
	return prsm_problems_total(problems) > before ? PRSM_EINVAL : 0;
}

int prsm_io_dynamics_from_json(prsm_dyn_options *o, const cJSON *obj, int stages, prsm_problems *problems)
{
	return prsm_io_dynamics_read(o, NULL, obj, stages, problems);
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

/* ---- the vibration analyses' results (schemas/dynamics-result.schema.json) ----------------------- */

static const char *const class_names[] = {"periodic", "non_periodic", "quasi_periodic", "chaotic", "failed"};
static const char *const clock_names[] = {"auto", "mesh", "te"};
static const char *const obs_names[] = {"mesh_deflection", "mesh_rate", "mesh_force",
                                        "axial_deflection", "axial_rate", "thread_force"};
static const char *const branch_names[] = {"both", "gear", "axial"};
static const char *const eig_kind_names[] = {"rigid", "real", "oscillatory"};
static const char *const in_names[] = {"mesh_error", "nut_force", "te"};
static const char *const out_names[] = {"mesh_deflection", "axial_deflection", "thread_force"};
static const char *const method_names[] = {"benettin", "two_trajectories"};

#define UM 1e6 /* m -> um */
#define MM 1e3 /* m -> mm */

void prsm_io_vib_result_free(prsm_io_vib_result *r)
{
	if (r == NULL)
		return;
	prsm_vib_linear_free(&r->linear);
	free(r->frf_omega);
	free(r->frf_re);
	free(r->frf_im);
	prsm_vib_steady_free(&r->steady);
	prsm_vib_sweep_free(&r->sweep);
	prsm_vib_frequency_response_free(&r->fr);
	prsm_vib_basins_free(&r->basins);
	memset(r, 0, sizeof *r);
}

static void int_series(prsm_jw *w, cJSON *obj, const char *key, const int *v, size_t n)
{
	cJSON *a = prsm_jw_array(w, obj, key);
	for (size_t i = 0; a && i < n; i++)
		prsm_jw_number(w, a, NULL, v[i]);
}

static void write_gear_pair(prsm_jw *w, cJSON *obj, const char *key, const prsm_vib_gear_pair *g)
{
	cJSON *o = prsm_jw_object(w, obj, key);
	prsm_jw_number(w, o, "damping_ratio", g->damping_ratio);
	prsm_jw_number(w, o, "mean_load", g->mean_force);
	prsm_jw_number(w, o, "error_amplitude", g->mesh_error);
	prsm_jw_number(w, o, "stiffness_variation", g->stiffness_variation);
	prsm_jw_number(w, o, "contact_ratio", g->contact_ratio);
	prsm_jw_number(w, o, "frequency_ratio", g->frequency_ratio);
}

static void write_te_lines(prsm_jw *w, cJSON *obj, const char *key, const prsm_vib_te_line *l, int n)
{
	cJSON *a = prsm_jw_array(w, obj, key);
	for (int k = 0; a && k < n; k++) {
		cJSON *o = prsm_jw_object(w, a, NULL);
		prsm_jw_number(w, o, "order_per_rev", l[k].order_per_rev);
		prsm_jw_number(w, o, "amplitude_um", l[k].amplitude_m * UM);
		prsm_jw_number(w, o, "phase_deg", l[k].phase_rad * DEG);
	}
}

static void write_steady_params(prsm_jw *w, cJSON *o, int transient, int recorded, int clock, int observable,
                                int roller, double tol)
{
	prsm_jw_number(w, o, "transient_periods", transient);
	prsm_jw_number(w, o, "recorded_periods", recorded);
	prsm_jw_string(w, o, "clock", NAME(clock_names, clock));
	prsm_jw_string(w, o, "observable", NAME(obs_names, observable));
	prsm_jw_number(w, o, "roller", roller);
	if (!isnan(tol))
		prsm_jw_number(w, o, "period_tolerance", tol);
}

/* The request's dynamics object as the analysis ran it, every default written out: a valid
 * dynamics object (schemas/dynamics.schema.json) that reproduces the run. The statics engine's
 * values the reduced model takes when they are not given stay out (model has them). */
static void write_vib_parameters(prsm_jw *w, cJSON *d, const prsm_io_vib_request *q, const prsm_dyn_options *dyn,
                                 const prsm_vib_params *P)
{
	cJSON *par = prsm_jw_object(w, d, "parameters");
	prsm_jw_string(w, par, "analysis", prsm_io_dynamics_analysis_name(q->analysis));
	if (q->gear_pair_model) {
		write_gear_pair(w, par, "gear_pair", &q->gear_pair);
	} else {
		cJSON *ld = prsm_jw_object(w, par, "load");
		prsm_jw_number(w, ld, "axial_load_N", dyn->load.value);
		prsm_jw_string(w, ld, "shape", "constant");
		cJSON *fr = prsm_jw_object(w, par, "friction");
		prsm_jw_string(w, fr, "model", "coulomb");
		prsm_jw_number(w, fr, "mu", isnan(dyn->friction.mu) ? P->mu : dyn->friction.mu);
		prsm_jw_number(w, fr, "smoothing_velocity_m_s", dyn->friction.smoothing_velocity_m_s);
		cJSON *ine = prsm_jw_object(w, par, "inertia");
		prsm_jw_number(w, ine, "density_kg_m3", dyn->inertia.density_kg_m3);
		prsm_jw_number(w, ine, "stroke_mm", dyn->inertia.stroke_mm);
		prsm_jw_number(w, ine, "payload_kg", dyn->inertia.payload_kg);
		const prsm_dyn_stage_inertia *si = &dyn->inertia.stage[0];
		const struct {
			const char *key;
			double v, scale;
		} masses[] = {{"gear_face_width_mm", si->gear_face_width_mm, 1.0},
		              {"roller_mass_kg", si->roller_mass_kg, 1.0},
		              {"roller_inertia_kg_mm2", si->roller_inertia_kg_m2, KG_MM2},
		              {"carrier_mass_kg", si->carrier_mass_kg, 1.0},
		              {"carrier_inertia_kg_mm2", si->carrier_inertia_kg_m2, KG_MM2},
		              {"nut_mass_kg", si->nut_mass_kg, 1.0},
		              {"screw_mass_kg", si->screw_mass_kg, 1.0},
		              {"screw_inertia_kg_mm2", si->screw_inertia_kg_m2, KG_MM2}};
		for (size_t i = 0; i < sizeof masses / sizeof masses[0]; i++)
			if (!isnan(masses[i].v))
				prsm_jw_number(w, ine, masses[i].key, masses[i].v * masses[i].scale);
		const prsm_vib_options *o = &q->vibration;
		cJSON *vo = prsm_jw_object(w, par, "vibration");
		if (isnan(o->frequency_ratio))
			prsm_jw_number(w, vo, "screw_speed_rad_s", o->screw_speed_rad_s);
		else
			prsm_jw_number(w, vo, "frequency_ratio", o->frequency_ratio);
		if (!isnan(o->axial_load_N))
			prsm_jw_number(w, vo, "axial_load_N", o->axial_load_N);
		prsm_jw_number(w, vo, "axial_damping_ratio", o->axial_damping_ratio);
		prsm_jw_number(w, vo, "mesh_damping_ratio", o->mesh_damping_ratio);
		prsm_jw_number(w, vo, "mesh_single_stiffness_N_per_mm_um", o->mesh_single_stiffness_N_per_mm_um);
		prsm_jw_number(w, vo, "double_to_single_stiffness", o->double_to_single_stiffness);
		prsm_jw_number(w, vo, "gear_backlash_um", o->gear_backlash_um);
		prsm_jw_number(w, vo, "mesh_error_um", o->mesh_error_um);
		if (!isnan(o->axial_stiffness_N_per_um))
			prsm_jw_number(w, vo, "axial_stiffness_N_per_um", o->axial_stiffness_N_per_um);
		if (!isnan(o->axial_half_play_um))
			prsm_jw_number(w, vo, "axial_half_play_um", o->axial_half_play_um);
		if (!isnan(o->gear_contact_ratio))
			prsm_jw_number(w, vo, "gear_contact_ratio", o->gear_contact_ratio);
		if (!isnan(o->gear_pressure_angle_rad))
			prsm_jw_number(w, vo, "gear_pressure_angle_deg", o->gear_pressure_angle_rad * DEG);
		if (o->gear_teeth_roller > 0)
			prsm_jw_number(w, vo, "gear_teeth_roller", o->gear_teeth_roller);
		if (o->gear_teeth_ring > 0)
			prsm_jw_number(w, vo, "gear_teeth_ring", o->gear_teeth_ring);
		prsm_jw_string(w, vo, "branches", NAME(branch_names, o->branches));
		if (o->te_source == PRSM_VIB_TE_LINES)
			write_te_lines(w, vo, "te_lines", o->te_line, o->te_lines);
		else
			prsm_jw_string(w, vo, "te_lines", o->te_source == PRSM_VIB_TE_STATICS ? "statics" : "none");
		prsm_jw_number(w, vo, "te_threshold", o->te_threshold);
		prsm_jw_number(w, vo, "te_max_lines", o->te_max_lines);
	}
	switch (q->analysis) {
	case PRSM_IO_DYN_VIBRATION: {
		const prsm_io_vib_steady *s = &q->steady_state;
		cJSON *o = prsm_jw_object(w, par, "steady_state");
		write_steady_params(w, o, s->transient_periods, s->recorded_periods, s->clock, s->observable, s->roller,
		                    s->period_tolerance);
		prsm_jw_number(w, o, "samples_per_period", s->samples_per_period);
		prsm_jw_bool(w, o, "lyapunov", s->lyapunov);
		prsm_jw_string(w, o, "lyapunov_method", NAME(method_names, s->lyapunov_method));
		prsm_jw_number(w, o, "lyapunov_exponents", s->lyapunov_exponents);
		prsm_jw_number(w, o, "lyapunov_periods", s->lyapunov_periods);
		break;
	}
	case PRSM_IO_DYN_SWEEP:
	case PRSM_IO_DYN_FREQUENCY_RESPONSE: {
		const prsm_io_vib_sweep *s = &q->sweep;
		const int fr = q->analysis == PRSM_IO_DYN_FREQUENCY_RESPONSE;
		cJSON *o = prsm_jw_object(w, par, "sweep");
		prsm_jw_string(w, o, "parameter", prsm_io_sweep_parameter_name(s->parameter));
		prsm_jw_number(w, o, "from", s->from);
		prsm_jw_number(w, o, "to", s->to);
		prsm_jw_number(w, o, "step", s->step);
		cJSON *dirs = prsm_jw_array(w, o, "directions");
		if (s->up || fr)
			prsm_jw_string(w, dirs, NULL, "up");
		if (s->down || fr)
			prsm_jw_string(w, dirs, NULL, "down");
		prsm_jw_bool(w, o, "continuation", fr ? 1 : s->continuation);
		write_steady_params(w, o, s->transient_periods, s->recorded_periods, s->clock, s->observable, s->roller,
		                    s->period_tolerance);
		prsm_jw_bool(w, o, "lyapunov", s->lyapunov);
		prsm_jw_number(w, o, "lyapunov_periods", s->lyapunov_periods);
		if (fr) {
			cJSON *f = prsm_jw_object(w, par, "frequency_response");
			prsm_jw_number(w, f, "agreement_tolerance", q->frequency_response.agreement_tolerance);
		}
		break;
	}
	case PRSM_IO_DYN_BASINS: {
		const prsm_io_vib_basins *b = &q->basins;
		cJSON *o = prsm_jw_object(w, par, "basins");
		prsm_jw_number(w, o, "deflection_min", b->deflection_min);
		prsm_jw_number(w, o, "deflection_max", b->deflection_max);
		prsm_jw_number(w, o, "deflection_cells", b->deflection_cells);
		prsm_jw_number(w, o, "rate_min", b->rate_min);
		prsm_jw_number(w, o, "rate_max", b->rate_max);
		prsm_jw_number(w, o, "rate_cells", b->rate_cells);
		prsm_jw_number(w, o, "periods", b->periods);
		prsm_jw_number(w, o, "identify_periods", b->identify_periods);
		prsm_jw_number(w, o, "distance", b->distance);
		prsm_jw_number(w, o, "roller", b->roller);
		if (!isnan(b->period_tolerance))
			prsm_jw_number(w, o, "period_tolerance", b->period_tolerance);
		break;
	}
	case PRSM_IO_DYN_LINEAR: {
		const prsm_io_vib_linear *l = &q->linear;
		cJSON *o = prsm_jw_object(w, par, "linear");
		prsm_jw_string(w, o, "input", NAME(in_names, l->input));
		prsm_jw_number(w, o, "input_roller", l->input_roller);
		prsm_jw_string(w, o, "output", NAME(out_names, l->output));
		prsm_jw_number(w, o, "output_roller", l->output_roller);
		if (q->gear_pair_model) {
			prsm_jw_number(w, o, "from_frequency_ratio", l->from_frequency_ratio);
			prsm_jw_number(w, o, "to_frequency_ratio", l->to_frequency_ratio);
		} else {
			prsm_jw_number(w, o, "from_Hz", l->from_Hz);
			prsm_jw_number(w, o, "to_Hz", l->to_Hz);
		}
		prsm_jw_number(w, o, "points", l->points);
		break;
	}
	default:
		break;
	}
	cJSON *t = prsm_jw_object(w, par, "time");
	prsm_jw_number(w, t, "rel_tol", q->integration.rel_tol);
	prsm_jw_number(w, t, "abs_tol", q->integration.abs_tol);
	prsm_jw_number(w, t, "max_steps", (double)q->integration.max_steps);
}

/* What the model runs with (prsm_vib_params), in the request's units. */
static void write_vib_model(prsm_jw *w, cJSON *d, const prsm_vib_params *P)
{
	cJSON *m = prsm_jw_object(w, d, "model");
	const int pair = P->kind == PRSM_VIB_GEAR_PAIR;
	prsm_jw_string(w, m, "kind", pair ? "gear_pair" : "reduced");
	prsm_jw_number(w, m, "states", P->states);
	prsm_jw_number(w, m, "poincare_size", P->poincare_size);
	prsm_jw_number(w, m, "contacts", P->contacts);
	if (pair) {
		write_gear_pair(w, m, "gear_pair", &P->gear_pair);
		return;
	}
	prsm_jw_string(w, m, "branches", NAME(branch_names, P->branches));
	prsm_jw_number(w, m, "rollers", P->rollers);
	prsm_jw_number(w, m, "screw_speed_rad_s", P->screw_speed_rad_s);
	prsm_jw_number(w, m, "frequency_ratio", P->frequency_ratio);
	prsm_jw_number(w, m, "axial_load_N", P->axial_load_N);
	prsm_jw_number(w, m, "carrier_ratio", P->carrier_ratio);
	prsm_jw_number(w, m, "ring_gear_ratio", P->ring_gear_ratio);
	prsm_jw_number(w, m, "mesh_order_per_rev", P->teeth_ring * P->carrier_ratio);
	prsm_jw_number(w, m, "mesh_frequency_Hz", P->mesh_frequency_rad_s / (2.0 * M_PI));
	prsm_jw_number(w, m, "reference_frequency_Hz", P->reference_frequency_rad_s / (2.0 * M_PI));
	prsm_jw_number(w, m, "axial_frequency_Hz", P->axial_frequency_rad_s / (2.0 * M_PI));
	cJSON *a = prsm_jw_object(w, m, "axial");
	prsm_jw_number(w, a, "mass_kg", P->axial_mass_kg);
	prsm_jw_number(w, a, "stiffness_N_per_um", P->axial_stiffness_N_per_m / UM);
	prsm_jw_number(w, a, "damping_N_s_per_m", P->axial_damping_N_s_per_m);
	prsm_jw_number(w, a, "damping_ratio", P->axial_damping_ratio);
	prsm_jw_number(w, a, "half_play_um", P->axial_half_play_m * UM);
	prsm_jw_number(w, a, "static_deflection_um", P->axial_static_m * UM);
	cJSON *g = prsm_jw_object(w, m, "gear");
	prsm_jw_number(w, g, "teeth_roller", P->teeth_roller);
	prsm_jw_number(w, g, "teeth_ring", P->teeth_ring);
	prsm_jw_number(w, g, "pressure_angle_deg", P->pressure_angle_rad * DEG);
	prsm_jw_number(w, g, "contact_ratio", P->contact_ratio);
	prsm_jw_number(w, g, "face_width_mm", P->gear_face_width_mm);
	prsm_jw_number(w, g, "base_radius_roller_mm", P->base_radius_roller_m * MM);
	prsm_jw_number(w, g, "base_radius_ring_mm", P->base_radius_ring_m * MM);
	prsm_jw_number(w, g, "single_stiffness_N_per_um", P->mesh_single_N_per_m / UM);
	prsm_jw_number(w, g, "double_stiffness_N_per_um", P->mesh_double_N_per_m / UM);
	prsm_jw_number(w, g, "mean_stiffness_N_per_um", P->mesh_mean_N_per_m / UM);
	prsm_jw_number(w, g, "half_backlash_um", P->gear_half_backlash_m * UM);
	prsm_jw_number(w, g, "mesh_error_um", P->mesh_error_m * UM);
	prsm_jw_number(w, g, "damping_ratio", P->mesh_damping_ratio);
	prsm_jw_number(w, g, "damping_N_s_per_m", P->mesh_damping_N_s_per_m);
	series(w, g, "mesh_phase", P->mesh_phase, sizeof P->mesh_phase[0], (size_t)P->rollers, 1.0);
	prsm_jw_number(w, g, "inertia_psipsi_kg_mm2", P->inertia_psipsi_kg_m2 * KG_MM2);
	prsm_jw_number(w, g, "inertia_psiphi_kg_mm2", P->inertia_psiphi_kg_m2 * KG_MM2);
	prsm_jw_number(w, g, "inertia_phiphi_kg_mm2", P->inertia_phiphi_kg_m2 * KG_MM2);
	prsm_jw_number(w, g, "roller_lead_mm_per_rad", P->roller_lead_m_per_rad * MM);
	cJSON *f = prsm_jw_object(w, m, "friction");
	prsm_jw_number(w, f, "mu", P->mu);
	prsm_jw_number(w, f, "smoothing_velocity_m_s", P->smoothing_velocity_m_s);
	prsm_jw_string(w, f, "flank", NAME(flank_names, P->flank));
	vec3(w, f, "slip_m_s", P->slip_m_s);
	series(w, f, "slip_per_roller_spin_mm", P->G_phi_m, sizeof P->G_phi_m[0], 3, MM);
	series(w, f, "slip_per_carrier_rate_mm", P->G_psi_m, sizeof P->G_psi_m[0], 3, MM);
	prsm_jw_number(w, f, "normal_force_N", P->normal_force_N);
	prsm_jw_number(w, f, "mean_mesh_force_N", P->mean_mesh_force_N);
	prsm_jw_number(w, f, "static_mesh_deflection_um", P->static_mesh_deflection_m * UM);
	write_gear_pair(w, m, "equivalent_gear_pair", &P->gear_pair);
	write_te_lines(w, m, "te_lines", P->te_line, P->te_lines);
	prsm_jw_number(w, m, "te_period_rev", P->te_period_rev);
}

static void write_observable(prsm_jw *w, cJSON *o, const char *key, int observable, int index)
{
	cJSON *ob = prsm_jw_object(w, o, key);
	prsm_jw_string(w, ob, "name", NAME(obs_names, observable));
	if (axial_observable(observable))
		prsm_jw_null(w, ob, "roller");
	else
		prsm_jw_number(w, ob, "roller", index);
}

static void write_lyapunov(prsm_jw *w, cJSON *o, const char *key, const prsm_vib_lyapunov *l, int method,
                           const prsm_vib_params *P)
{
	cJSON *ly = prsm_jw_object(w, o, key);
	const int pair = P->kind == PRSM_VIB_GEAR_PAIR;
	prsm_jw_string(w, ly, "method", NAME(method_names, method));
	series(w, ly, "exponents_per_tau", l->lambda, sizeof l->lambda[0], (size_t)l->exponents, 1.0);
	cJSON *ps = prsm_jw_array(w, ly, "exponents_per_s");
	for (int i = 0; ps && i < l->exponents; i++)
		prsm_jw_number(w, ps, NULL, pair ? NAN : l->lambda[i] * P->reference_frequency_rad_s);
	prsm_jw_number(w, ly, "sum_per_tau", l->sum);
	prsm_jw_number(w, ly, "periods", l->periods);
	prsm_jw_number(w, ly, "blocks", l->blocks);
	prsm_jw_number(w, ly, "block_min_per_tau", l->block_min);
	prsm_jw_number(w, ly, "block_max_per_tau", l->block_max);
	prsm_jw_number(w, ly, "block_sd_per_tau", l->block_sd);
}

static void write_vibration(prsm_jw *w, cJSON *d, const prsm_io_vib_request *q, const prsm_vib_params *P,
                            const prsm_io_vib_result *r)
{
	const prsm_vib_steady *s = &r->steady;
	const prsm_io_vib_steady *o = &q->steady_state;
	const int pair = P->kind == PRSM_VIB_GEAR_PAIR;
	cJSON *v = prsm_jw_object(w, d, "vibration");
	prsm_jw_string(w, v, "classification", NAME(class_names, s->classification));
	prsm_jw_number(w, v, "period", s->period);
	prsm_jw_string(w, v, "clock", NAME(clock_names, s->clock));
	prsm_jw_number(w, v, "forcing_period_tau", s->period_tau);
	prsm_jw_number(w, v, "forcing_period_s", pair ? NAN : s->period_s);
	prsm_jw_number(w, v, "period_tolerance", s->period_tol);
	prsm_jw_number(w, v, "max_return_distance", s->max_return_distance);
	write_observable(w, v, "observable", o->observable, o->roller);
	cJSON *pc = prsm_jw_object(w, v, "poincare");
	prsm_jw_number(w, pc, "points", s->recorded);
	prsm_jw_number(w, pc, "size", s->poincare_size);
	series(w, pc, "observable", s->poincare_observable, sizeof(double), (size_t)s->recorded, 1.0);
	cJSON *vecs = prsm_jw_array(w, pc, "vectors");
	for (int i = 0; vecs && i < s->recorded; i++)
		series(w, vecs, NULL, s->poincare + (size_t)i * s->poincare_size, sizeof(double), (size_t)s->poincare_size,
		       1.0);
	cJSON *ex = prsm_jw_array(w, v, "extremes");
	for (int i = 0; ex && i < s->extremes; i++) {
		const prsm_vib_extreme *x = &s->extreme[i];
		cJSON *e = prsm_jw_object(w, ex, NULL);
		prsm_jw_string(w, e, "observable", NAME(obs_names, x->observable));
		if (axial_observable(x->observable))
			prsm_jw_null(w, e, "roller");
		else
			prsm_jw_number(w, e, "roller", x->index);
		prsm_jw_number(w, e, "min", x->min);
		prsm_jw_number(w, e, "max", x->max);
		prsm_jw_number(w, e, "mean", x->mean);
		prsm_jw_number(w, e, "rms", x->rms);
		prsm_jw_number(w, e, "amplitude", 0.5 * (x->max - x->min));
	}
	cJSON *sp = prsm_jw_array(w, v, "spectrum");
	for (int i = 0; sp && i < s->lines; i++) {
		const prsm_vib_line *l = &s->line[i];
		cJSON *e = prsm_jw_object(w, sp, NULL);
		prsm_jw_string(w, e, "name", l->name);
		prsm_jw_number(w, e, "order_per_rev", pair ? NAN : l->order_per_rev);
		prsm_jw_number(w, e, "frequency_Hz", pair ? NAN : l->frequency);
		prsm_jw_number(w, e, "frequency_ratio",
		               pair ? l->frequency : l->frequency * 2.0 * M_PI / P->reference_frequency_rad_s);
		prsm_jw_number(w, e, "amplitude", l->amplitude);
	}
	cJSON *sf = prsm_jw_object(w, v, "spectrum_full");
	prsm_jw_string(w, sf, "window", s->spectrum_window_hann ? "hann" : "rectangular");
	prsm_jw_number(w, sf, "periods", s->spectrum_periods);
	prsm_jw_number(w, sf, "bins", s->spectrum_bins);
	const size_t nb = (size_t)s->spectrum_bins;
	if (pair) {
		series(w, sf, "frequency_ratio", s->spectrum_frequency, sizeof(double), nb, 1.0);
	} else {
		series(w, sf, "frequency_Hz", s->spectrum_frequency, sizeof(double), nb, 1.0);
		series(w, sf, "frequency_ratio", s->spectrum_frequency, sizeof(double), nb,
		       2.0 * M_PI / P->reference_frequency_rad_s);
	}
	series(w, sf, "amplitude", s->spectrum_amplitude, sizeof(double), nb, 1.0);
	cJSON *pp = prsm_jw_object(w, v, "phase_portrait");
	prsm_jw_number(w, pp, "points", (double)s->portrait_points);
	prsm_jw_number(w, pp, "samples_per_period", o->samples_per_period);
	series(w, pp, "observable", s->portrait_x, sizeof(double), s->portrait_points, 1.0);
	series(w, pp, "rate", s->portrait_v, sizeof(double), s->portrait_points, 1.0);
	cJSON *ct = prsm_jw_array(w, v, "contacts");
	for (int k = 0; ct && k < s->contacts; k++) {
		cJSON *e = prsm_jw_object(w, ct, NULL);
		char name[32];
		if (!pair && k == P->rollers)
			snprintf(name, sizeof name, "thread");
		else
			snprintf(name, sizeof name, "mesh_%d", k);
		prsm_jw_string(w, e, "contact", name);
		prsm_jw_number(w, e, "open_share", s->loss_share[k]);
		prsm_jw_number(w, e, "back_flank_share", s->back_share[k]);
	}
	if (r->with_lyapunov)
		write_lyapunov(w, v, "lyapunov", &r->lyapunov, o->lyapunov_method, P);
	else
		prsm_jw_null(w, v, "lyapunov");
}

/* One sweep point; value in the request's unit. */
static void write_sweep_point(prsm_jw *w, cJSON *arr, const prsm_vib_sweep *s, size_t k, const char *par_name,
                              double from_engine)
{
	const prsm_vib_sweep_point *p = &s->point[k];
	cJSON *o = prsm_jw_object(w, arr, NULL);
	prsm_jw_number(w, o, par_name, p->parameter * from_engine);
	const int failed = p->classification == PRSM_VIB_FAILED;
	prsm_jw_bool(w, o, "converged", !failed);
	prsm_jw_string(w, o, "classification", NAME(class_names, p->classification));
	if (failed) {
		prsm_jw_string(w, o, "error", prsm_error_name(p->status));
		prsm_jw_null(w, o, "period");
	} else {
		prsm_jw_null(w, o, "error");
		prsm_jw_number(w, o, "period", p->period);
	}
	const double nan = NAN;
	prsm_jw_number(w, o, "min", failed ? nan : p->min);
	prsm_jw_number(w, o, "max", failed ? nan : p->max);
	prsm_jw_number(w, o, "mean", failed ? nan : p->mean);
	prsm_jw_number(w, o, "rms", failed ? nan : p->rms);
	prsm_jw_number(w, o, "amplitude", failed ? nan : p->amplitude);
	prsm_jw_number(w, o, "lyapunov_per_tau", failed ? nan : p->lyapunov);
	prsm_jw_number(w, o, "max_return_distance", failed ? nan : p->max_return_distance);
	series(w, o, "poincare", s->poincare + k * (size_t)s->recorded, sizeof(double), failed ? 0 : (size_t)s->recorded,
	       1.0);
}

static void write_sweep_direction(prsm_jw *w, cJSON *o, const char *key, const prsm_vib_sweep *s, int direction,
                                  const char *par_name, double from_engine)
{
	cJSON *a = prsm_jw_array(w, o, key);
	for (size_t k = 0; a && k < s->points; k++)
		if (s->point[k].direction == direction)
			write_sweep_point(w, a, s, k, par_name, from_engine);
}

static size_t failed_points(const prsm_vib_sweep *s)
{
	size_t n = 0;
	for (size_t k = 0; k < s->points; k++)
		n += s->point[k].classification == PRSM_VIB_FAILED;
	return n;
}

static void write_sweep(prsm_jw *w, cJSON *d, const prsm_io_vib_request *q, const prsm_vib_sweep *s)
{
	const prsm_io_vib_sweep *o = &q->sweep;
	double to_engine = 1.0;
	prsm_io_sweep_parameter_engine(o->parameter, &to_engine);
	const char *name = prsm_io_sweep_parameter_name(o->parameter);
	cJSON *sw = prsm_jw_object(w, d, "sweep");
	prsm_jw_string(w, sw, "parameter", name);
	prsm_jw_number(w, sw, "grid", (double)s->grid);
	prsm_jw_number(w, sw, "recorded_periods", s->recorded);
	prsm_jw_bool(w, sw, "continuation", o->continuation);
	write_observable(w, sw, "observable", o->observable, o->roller);
	prsm_jw_number(w, sw, "failed_points", (double)failed_points(s));
	if (s->first_error[0])
		prsm_jw_string(w, sw, "first_error", s->first_error);
	else
		prsm_jw_null(w, sw, "first_error");
	write_sweep_direction(w, sw, "up", s, 1, name, 1.0 / to_engine);
	write_sweep_direction(w, sw, "down", s, -1, name, 1.0 / to_engine);
}

static void write_frequency_response(prsm_jw *w, cJSON *d, const prsm_io_vib_request *q, const prsm_io_vib_result *r)
{
	const prsm_vib_frequency_response *f = &r->fr;
	cJSON *o = prsm_jw_object(w, d, "frequency_response");
	if (r->with_harmonic_balance) {
		const prsm_vib_hb *h = &f->hb;
		cJSON *hb = prsm_jw_object(w, o, "harmonic_balance");
		prsm_jw_number(w, hb, "points", (double)h->points);
		const size_t ps = sizeof *h->point;
		series(w, hb, "frequency_ratio", &h->point->omega, ps, h->points, 1.0);
		series(w, hb, "amplitude", &h->point->amplitude, ps, h->points, 1.0);
		series(w, hb, "mean", &h->point->mean, ps, h->points, 1.0);
		cJSON *br = prsm_jw_array(w, hb, "branch");
		cJSON *sg = prsm_jw_array(w, hb, "segment");
		cJSON *st = prsm_jw_array(w, hb, "stable");
		for (size_t i = 0; i < h->points; i++) {
			prsm_jw_string(w, br, NULL, h->point[i].branch ? "high" : "low");
			prsm_jw_number(w, sg, NULL, h->point[i].segment);
			prsm_jw_bool(w, st, NULL, h->point[i].stable);
		}
		cJSON *fo = prsm_jw_array(w, hb, "folds");
		for (int i = 0; fo && i < h->folds; i++) {
			cJSON *e = prsm_jw_object(w, fo, NULL);
			prsm_jw_number(w, e, "frequency_ratio", h->fold[i].omega);
			prsm_jw_number(w, e, "amplitude", h->fold[i].amplitude);
			prsm_jw_number(w, e, "mean", h->fold[i].mean);
			prsm_jw_string(w, e, "kind", h->fold[i].kind > 0 ? "maximum" : "minimum");
		}
	} else {
		prsm_jw_null(w, o, "harmonic_balance");
	}
	const char *name = prsm_io_sweep_parameter_name(PRSM_IO_SWEEP_FREQUENCY_RATIO);
	prsm_jw_number(w, o, "grid", (double)f->sweep.grid);
	prsm_jw_number(w, o, "agreement_tolerance", q->frequency_response.agreement_tolerance);
	prsm_jw_number(w, o, "failed_points", (double)failed_points(&f->sweep));
	write_sweep_direction(w, o, "sweep_up", &f->sweep, 1, name, 1.0);
	write_sweep_direction(w, o, "sweep_down", &f->sweep, -1, name, 1.0);
	cJSON *jumps = prsm_jw_array(w, o, "jumps");
	for (int k = 0; jumps && k < f->jumps; k++) {
		const prsm_vib_jump *j = &f->jump[k];
		const prsm_vib_exact_fold *x = &f->exact_fold[k];
		cJSON *e = prsm_jw_object(w, jumps, NULL);
		prsm_jw_string(w, e, "direction", j->direction > 0 ? "up" : "down");
		prsm_jw_number(w, e, "from_frequency_ratio", j->from);
		prsm_jw_number(w, e, "to_frequency_ratio", j->to);
		cJSON *ef = prsm_jw_object(w, e, "exact_fold");
		prsm_jw_bool(w, ef, "found", x->found);
		prsm_jw_number(w, ef, "frequency_ratio", x->found ? x->omega : NAN);
		prsm_jw_number(w, ef, "last_frequency_ratio", x->orbits > 0 ? x->last_omega : NAN);
		prsm_jw_number(w, ef, "last_multiplier", x->orbits > 0 ? x->last_multiplier : NAN);
		prsm_jw_number(w, ef, "amplitude", x->orbits > 0 ? x->amplitude : NAN);
		prsm_jw_number(w, ef, "period", x->period);
		prsm_jw_number(w, ef, "orbits", x->orbits);
	}
}

static void write_basins(prsm_jw *w, cJSON *d, const prsm_vib_basins *b)
{
	cJSON *o = prsm_jw_object(w, d, "basins");
	prsm_jw_number(w, o, "deflection_cells", b->nx);
	prsm_jw_number(w, o, "rate_cells", b->nv);
	const int nx = b->nx, nv = b->nv;
	cJSON *xs = prsm_jw_array(w, o, "deflection");
	for (int i = 0; xs && i < nx; i++)
		prsm_jw_number(w, xs, NULL, nx > 1 ? b->x_min + (b->x_max - b->x_min) * i / (nx - 1) : b->x_min);
	cJSON *vs = prsm_jw_array(w, o, "rate");
	for (int i = 0; vs && i < nv; i++)
		prsm_jw_number(w, vs, NULL, nv > 1 ? b->v_min + (b->v_max - b->v_min) * i / (nv - 1) : b->v_min);
	cJSON *lab = prsm_jw_array(w, o, "labels");
	for (int i = 0; lab && i < nx; i++)
		int_series(w, lab, NULL, b->label + (size_t)i * (size_t)nv, (size_t)nv);
	cJSON *at = prsm_jw_array(w, o, "attractors");
	for (int a = 0; at && a < b->attractors; a++) {
		const prsm_vib_attractor *x = &b->attractor[a];
		cJSON *e = prsm_jw_object(w, at, NULL);
		prsm_jw_number(w, e, "label", a);
		prsm_jw_number(w, e, "period", x->period);
		prsm_jw_number(w, e, "cells", (double)x->cells);
		prsm_jw_number(w, e, "fraction", x->fraction);
		cJSON *pts = prsm_jw_array(w, e, "poincare");
		for (int k = 0; pts && k < x->period; k++)
			series(w, pts, NULL, x->poincare + (size_t)k * b->poincare_size, sizeof(double), (size_t)b->poincare_size,
			       1.0);
	}
	cJSON *ot = prsm_jw_object(w, o, "other");
	prsm_jw_number(w, ot, "cells", (double)b->other);
	prsm_jw_number(w, ot, "fraction", b->other_fraction);
	cJSON *fa = prsm_jw_object(w, o, "failed");
	prsm_jw_number(w, fa, "cells", (double)b->failed);
	prsm_jw_number(w, fa, "fraction", b->failed_fraction);
}

/* The FRF's unit: output over input (gear pair: dimensionless). */
static const char *frf_unit(int pair, int input, int output)
{
	if (pair)
		return "-";
	const int in_N = input == PRSM_VIB_IN_NUT_FORCE, out_N = output == PRSM_VIB_OUT_THREAD_FORCE;
	return in_N ? (out_N ? "N/N" : "m/N") : (out_N ? "N/m" : "m/m");
}

static void write_linear(prsm_jw *w, cJSON *d, const prsm_vib_params *P, const prsm_io_vib_result *r)
{
	const prsm_vib_linear *l = &r->linear;
	const int pair = P->kind == PRSM_VIB_GEAR_PAIR;
	const double wref = pair ? 1.0 : P->reference_frequency_rad_s;
	cJSON *o = prsm_jw_object(w, d, "linear");
	prsm_jw_number(w, o, "dofs", l->dofs);
	cJSON *ev = prsm_jw_array(w, o, "eigenvalues");
	for (int i = 0; ev && i < l->eigenvalues; i++) {
		cJSON *e = prsm_jw_object(w, ev, NULL);
		prsm_jw_number(w, e, "real_per_s", pair ? NAN : l->eig_re[i]);
		prsm_jw_number(w, e, "imag_rad_s", pair ? NAN : l->eig_im[i]);
		prsm_jw_number(w, e, "frequency_Hz", pair ? NAN : l->frequency_Hz[i]);
		prsm_jw_number(w, e, "real_per_tau", l->eig_re[i] / wref);
		prsm_jw_number(w, e, "imag_per_tau", l->eig_im[i] / wref);
		prsm_jw_number(w, e, "frequency_ratio", fabs(l->eig_im[i]) / wref);
		prsm_jw_number(w, e, "damping_ratio", l->damping_ratio[i]);
		prsm_jw_string(w, e, "kind", NAME(eig_kind_names, l->kind[i]));
	}
	cJSON *md = prsm_jw_object(w, o, "modes");
	cJSON *co = prsm_jw_array(w, md, "coordinates");
	for (int k = 0; co && k < l->shape_size; k++) {
		char name[40];
		if (pair)
			snprintf(name, sizeof name, "x");
		else if (k < P->rollers && l->shape_size > (P->branches == PRSM_VIB_BRANCHES_AXIAL ? 1 : 0))
			snprintf(name, sizeof name, "mesh_deflection_%d", k);
		else
			snprintf(name, sizeof name, "axial_deflection");
		prsm_jw_string(w, co, NULL, name);
	}
	cJSON *sh = prsm_jw_array(w, md, "shapes");
	for (int i = 0; sh && i < l->eigenvalues; i++) {
		cJSON *e = prsm_jw_object(w, sh, NULL);
		prsm_jw_number(w, e, "eigenvalue", i);
		const size_t off = (size_t)i * (size_t)l->shape_size;
		series(w, e, "re", l->shape_re + off, sizeof(double), (size_t)l->shape_size, 1.0);
		series(w, e, "im", l->shape_im + off, sizeof(double), (size_t)l->shape_size, 1.0);
	}
	cJSON *fr = prsm_jw_object(w, o, "frf");
	prsm_jw_string(w, fr, "input", NAME(in_names, r->input));
	prsm_jw_number(w, fr, "input_roller", r->input_roller);
	prsm_jw_string(w, fr, "output", NAME(out_names, r->output));
	prsm_jw_number(w, fr, "output_roller", r->output_roller);
	prsm_jw_string(w, fr, "unit", frf_unit(pair, r->input, r->output));
	prsm_jw_number(w, fr, "points", (double)r->frf_points);
	const size_t n = r->frf_points;
	if (!pair)
		series(w, fr, "frequency_Hz", r->frf_omega, sizeof(double), n, 1.0 / (2.0 * M_PI));
	series(w, fr, "frequency_ratio", r->frf_omega, sizeof(double), n, 1.0 / wref);
	cJSON *mag = prsm_jw_array(w, fr, "magnitude");
	cJSON *ph = prsm_jw_array(w, fr, "phase_deg");
	for (size_t i = 0; mag && ph && i < n; i++) {
		prsm_jw_number(w, mag, NULL, hypot(r->frf_re[i], r->frf_im[i]));
		prsm_jw_number(w, ph, NULL, atan2(r->frf_im[i], r->frf_re[i]) * DEG);
	}
	series(w, fr, "real", r->frf_re, sizeof(double), n, 1.0);
	series(w, fr, "imag", r->frf_im, sizeof(double), n, 1.0);
	const prsm_vib_half_power *h = &r->half_power;
	cJSON *hp = prsm_jw_object(w, o, "half_power");
	prsm_jw_bool(w, hp, "defined", h->defined);
	if (h->defined)
		prsm_jw_null(w, hp, "reason");
	else
		prsm_jw_string(w, hp, "reason", h->reason);
	const double hz = pair ? NAN : 1.0 / (2.0 * M_PI);
	prsm_jw_number(w, hp, "peak_frequency_Hz", h->peak_omega * hz);
	prsm_jw_number(w, hp, "peak_frequency_ratio", h->peak_omega / wref);
	prsm_jw_number(w, hp, "peak_magnitude", h->peak_magnitude);
	prsm_jw_number(w, hp, "lower_frequency_Hz", h->omega_1 * hz);
	prsm_jw_number(w, hp, "upper_frequency_Hz", h->omega_2 * hz);
	prsm_jw_number(w, hp, "lower_frequency_ratio", h->omega_1 / wref);
	prsm_jw_number(w, hp, "upper_frequency_ratio", h->omega_2 / wref);
	prsm_jw_number(w, hp, "damping_ratio", h->defined ? h->damping_ratio : NAN);
	prsm_jw_number(w, hp, "modal_damping_ratio", h->modal_damping_ratio);
	prsm_jw_number(w, hp, "modal_frequency_Hz", h->modal_omega * hz);
	prsm_jw_number(w, hp, "modal_frequency_ratio", h->modal_omega / wref);
	prsm_jw_number(w, hp, "grid", (double)h->grid);
}

static void write_vib_dynamics(prsm_jw *w, cJSON *root, const prsm_io_vib_request *q, const prsm_dyn_options *dyn,
                               const prsm_vib_model *m, const prsm_io_vib_result *r)
{
	const prsm_vib_params *P = prsm_vib_model_params(m);
	cJSON *d = prsm_jw_object(w, root, "dynamics");
	prsm_jw_string(w, d, "analysis", prsm_io_dynamics_analysis_name(q->analysis));
	write_vib_parameters(w, d, q, dyn, P);
	write_vib_model(w, d, P);
	size_t failed = 0;
	switch (q->analysis) {
	case PRSM_IO_DYN_LINEAR:
		write_linear(w, d, P, r);
		break;
	case PRSM_IO_DYN_VIBRATION:
		write_vibration(w, d, q, P, r);
		break;
	case PRSM_IO_DYN_SWEEP:
		write_sweep(w, d, q, &r->sweep);
		failed = failed_points(&r->sweep);
		break;
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		write_frequency_response(w, d, q, r);
		failed = failed_points(&r->fr.sweep);
		break;
	case PRSM_IO_DYN_BASINS:
		write_basins(w, d, &r->basins);
		failed = r->basins.failed;
		break;
	default:
		break;
	}
	cJSON *cv = prsm_jw_object(w, d, "convergence");
	prsm_jw_bool(w, cv, "converged", failed == 0);
	prsm_jw_number(w, cv, "failed_points", (double)failed);
	prsm_jw_number(w, cv, "steps", (double)r->effort.steps);
	prsm_jw_number(w, cv, "rejected_steps", (double)r->effort.rejected);
	prsm_jw_number(w, cv, "rhs_evaluations", (double)r->effort.rhs_evaluations);
	prsm_jw_number(w, cv, "kink_crossings", (double)r->effort.events);
	prsm_jw_number(w, cv, "stiffness_switches", (double)r->effort.switches);
	prsm_jw_number(w, cv, "max_steps", (double)q->integration.max_steps);
	prsm_jw_number(w, cv, "rel_tol", q->integration.rel_tol);
	prsm_jw_number(w, cv, "abs_tol", q->integration.abs_tol);
}

cJSON *prsm_io_vibration_result_to_json(const char *name, const prsm_io_vib_request *q, const prsm_dyn_options *dyn,
                                        const prsm_vib_model *m, const prsm_io_vib_result *r,
                                        const prsm_problems *warnings)
{
	prsm_problems none;
	prsm_problems_init(&none);
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	cJSON *eng = prsm_jw_object(&w, root, "engine");
	prsm_jw_string(&w, eng, "name", "prsm");
	prsm_jw_string(&w, eng, "version", PRSM_VERSION);
	prsm_jw_string(&w, eng, "model", PRSM_VIB_MODEL_VERSION);
	prsm_jw_string(&w, eng, "build", prsm_engine_build());
	if (name && name[0])
		prsm_jw_string(&w, root, "name", name);
	write_problems(&w, root, "warnings", warnings ? warnings : &none);
	write_vib_dynamics(&w, root, q, dyn, m, r);
	return prsm_jw_done(&w, root);
}

/* ---- CSV and text of the vibration analyses ----------------------------------------------------- */

static void csv_sweep(FILE *f, const prsm_vib_sweep *s, const char *par_name, double from_engine, const char *obs)
{
	fprintf(f, "direction,%s,classification,period,lyapunov_per_tau,min,max,poincare_index,poincare_%s\n", par_name, obs);
	for (size_t k = 0; k < s->points; k++) {
		const prsm_vib_sweep_point *p = &s->point[k];
		const char *dir = p->direction > 0 ? "up" : "down";
		if (p->classification == PRSM_VIB_FAILED) {
			fprintf(f, "%s,%.17g,failed,,,,,,\n", dir, p->parameter * from_engine);
			continue;
		}
		for (int i = 0; i < s->recorded; i++) {
			fprintf(f, "%s,%.17g,%s,%d", dir, p->parameter * from_engine, NAME(class_names, p->classification),
			        p->period);
			csv_number(f, p->lyapunov);
			csv_number(f, p->min);
			csv_number(f, p->max);
			fprintf(f, ",%d", i);
			csv_number(f, s->poincare[k * (size_t)s->recorded + (size_t)i]);
			fputc('\n', f);
		}
	}
}

int prsm_io_vibration_write_csv(FILE *f, const prsm_io_vib_request *q, const prsm_vib_model *m,
                                const prsm_io_vib_result *r)
{
	const prsm_vib_params *P = prsm_vib_model_params(m);
	const int pair = P->kind == PRSM_VIB_GEAR_PAIR;
	switch (q->analysis) {
	case PRSM_IO_DYN_VIBRATION: {
		const prsm_vib_steady *s = &r->steady;
		const char *obs = NAME(obs_names, q->steady_state.observable);
		fprintf(f, "time_tau,time_s,%s,%s_rate\n", obs, obs);
		const int per = q->steady_state.samples_per_period;
		for (size_t i = 0; i < s->portrait_points; i++) {
			/* the recording starts at phase 0 after the transient */
			const double tau = (q->steady_state.transient_periods + (double)i / per) * s->period_tau;
			fprintf(f, "%.17g", tau);
			csv_number(f, pair ? NAN : tau / P->reference_frequency_rad_s);
			csv_number(f, s->portrait_x[i]);
			csv_number(f, s->portrait_v[i]);
			fputc('\n', f);
		}
		break;
	}
	case PRSM_IO_DYN_SWEEP: {
		double to_engine = 1.0;
		prsm_io_sweep_parameter_engine(q->sweep.parameter, &to_engine);
		csv_sweep(f, &r->sweep, prsm_io_sweep_parameter_name(q->sweep.parameter), 1.0 / to_engine,
		          NAME(obs_names, q->sweep.observable));
		break;
	}
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		csv_sweep(f, &r->fr.sweep, "frequency_ratio", 1.0, NAME(obs_names, q->sweep.observable));
		break;
	case PRSM_IO_DYN_BASINS: {
		const prsm_vib_basins *b = &r->basins;
		fputs("deflection,rate,label\n", f);
		for (int i = 0; i < b->nx; i++)
			for (int j = 0; j < b->nv; j++) {
				const double x = b->nx > 1 ? b->x_min + (b->x_max - b->x_min) * i / (b->nx - 1) : b->x_min;
				const double v = b->nv > 1 ? b->v_min + (b->v_max - b->v_min) * j / (b->nv - 1) : b->v_min;
				fprintf(f, "%.17g,%.17g,%d\n", x, v, b->label[(size_t)i * (size_t)b->nv + (size_t)j]);
			}
		break;
	}
	case PRSM_IO_DYN_LINEAR: {
		const double wref = pair ? 1.0 : P->reference_frequency_rad_s;
		fputs(pair ? "frequency_ratio,magnitude,phase_deg,real,imag\n"
		           : "frequency_Hz,frequency_ratio,magnitude,phase_deg,real,imag\n", f);
		for (size_t i = 0; i < r->frf_points; i++) {
			if (pair)
				fprintf(f, "%.17g", r->frf_omega[i]);
			else
				fprintf(f, "%.17g,%.17g", r->frf_omega[i] / (2.0 * M_PI), r->frf_omega[i] / wref);
			csv_number(f, hypot(r->frf_re[i], r->frf_im[i]));
			csv_number(f, atan2(r->frf_im[i], r->frf_re[i]) * DEG);
			csv_number(f, r->frf_re[i]);
			csv_number(f, r->frf_im[i]);
			fputc('\n', f);
		}
		break;
	}
	default:
		break;
	}
	return ferror(f) ? PRSM_EIO : 0;
}

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

int prsm_io_vibration_write_text(FILE *f, const prsm_io_vib_request *q, const prsm_vib_model *m,
                                 const prsm_io_vib_result *r, const prsm_problems *warnings)
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
