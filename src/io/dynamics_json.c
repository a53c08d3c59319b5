/*
 * dynamics_json.c: the dynamics request object read by its generated table with the hooks a
 * table cannot say, and a simulation's result as JSON (the sticky-error writer, io/write.h),
 * and CSV (see dynamics_json.h; docs/dynamics.md; the text summaries are in app/text.c).
 *
 * Units at the API are in the names: kg mm^2 for inertias (kg m^2 inside, x 1e6 out), mm for
 * positions and radii, degrees for the gear pressure angle; everything else is SI as the model
 * has it.
 */
#include "io/dynamics_json.h"

#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "prsm_io_tables.h"
#include "prsm_io_writers.h"
#include "util/error.h"
#include "util/version.h"

#define DEG (180.0 / M_PI)     /* rad -> deg */

/* The per-stage fields of `inertia` (the single-stage form; a chain's are in inertia.stages): the
 * members of one stage's table ($defs/stage_inertia). */
#define STAGE_KEYS (prsm_io_t_dynamics_stage_inertia.keys)

/* ---- the hooks of the table (schemas/dynamics.schema.json, x-prsm) ---------------------------- */

/* The masses: the single-stage fields into stage 0, each item of `stages` into its stage, by
 * the table of one stage (schemas/dynamics.schema.json, $defs/stage_inertia). Which form the
 * request may use depends on its number of stages: prsm_io_dynamics_read checks that. */
void prsm_io_hook_dynamics_inertia(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_dyn_options *o = base;
	for (int i = 0; STAGE_KEYS[i]; i++)
		prsm_io_read_member(&o->inertia.stage[0], &prsm_io_t_dynamics_stage_inertia, STAGE_KEYS[i], obj, obj_pointer,
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

/* ---- the reader -------------------------------------------------------------------------------- */

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
		for (int i = 0; STAGE_KEYS[i]; i++)
			if (cJSON_GetObjectItemCaseSensitive(in, STAGE_KEYS[i])) {
				prsm_json_pointer_append(ptr, sizeof ptr, "/dynamics/inertia", STAGE_KEYS[i]);
				prsm_problems_add(problems, ptr, "chain",
				                  "a chain of %d stages gives each stage's masses in inertia.stages "
				                  "(%d objects, stage 1 first)", stages, stages);
			}
		if (cJSON_IsArray(arr) && cJSON_GetArraySize(arr) != stages)
			prsm_io_problem_once(problems, 0, "/dynamics/inertia/stages", NULL, "size",
			                     "must have %d objects, one per stage of the chain (got %d)", stages,
			                     cJSON_GetArraySize(arr));
	}
}

/* ---- the vibration analyses: sections, step and rules (docs/vibration.md) ---------------------- */

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

/* prsm_io_vib_steady_init, _sweep_init, _basins_init, _linear_init and
 * _frequency_response_init are generated from the schema's defaults (schemas/dynamics.schema.json,
 * "init": {"generate"}; prsm_io_tables.c). */

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
 * sections of the vibration analyses into the prsm_io_vib_request of prsm_io_dynamics_read
 * (at->ctx). */
int prsm_io_step_dynamics_vibration(prsm_io_at *at, prsm_problems *problems)
{
	prsm_io_vib_request *v = at->ctx;
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
				prsm_json_enum_value(&v->analysis, a, ptr, prsm_io_t_dynamics_analysis_names, problems);
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
	return 0;
}

static const cJSON *member(const cJSON *obj, const char *key)
{
	return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
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
		prsm_io_problem_once(p, from, section, "observable", "branch",
		                     "%s: an axial observable needs the reduced model's axial branch (vibration.branches both or "
		                     "axial)", pair ? "a gear pair has none" : "the axial branch is off");
	else if (!axial_observable(observable) && !pair && br == PRSM_VIB_BRANCHES_AXIAL)
		prsm_io_problem_once(p, from, section, "observable", "branch",
		                     "the gear branch is off (vibration.branches axial): observe axial_deflection, axial_rate "
		                     "or thread_force");
	if (clock == PRSM_VIB_CLOCK_TE && (pair || v->vibration.te_source == PRSM_VIB_TE_NONE))
		prsm_io_problem_once(p, from, section, "clock", "no_te",
		                     "the te clock is the common period of the TE lines: %s",
		                     pair ? "a gear pair has none" : "give vibration.te_lines");
}

static void periods_rule(prsm_problems *p, int from, const char *section, int transient, int recorded,
                         int lyapunov, int lyapunov_periods)
{
	const double total = (double)transient + recorded + (lyapunov ? lyapunov_periods : 0);
	if (total > PRSM_VIB_PERIODS_MAX)
		prsm_io_problem_once(p, from, section, "transient_periods", "too_long",
		                     "%.0f forcing periods per run (transient + recorded%s), at most %d", total,
		                     lyapunov ? " + Lyapunov" : "", PRSM_VIB_PERIODS_MAX);
}

/* A gear pair has one mesh: a roller other than 0 is the reduced model's. */
static void one_mesh(prsm_problems *p, int from, const prsm_io_vib_request *v, const char *section, const char *key,
                     int roller)
{
	if (v->gear_pair_model && roller != 0)
		prsm_io_problem_once(p, from, section, key, "model", "a gear pair has one mesh: roller 0");
}

/* A sweep grid value of parameter par is valid for the model (the engine's ranges). */
static const char *sweep_value_invalid(const prsm_io_vib_request *v, int par, double x)
{
	switch (par) {
	case PRSM_IO_SWEEP_FREQUENCY_RATIO:
		return x > 0.0 && x <= 1e3 ? NULL : "a frequency ratio is in (0, 1000]";
	case PRSM_IO_SWEEP_SCREW_SPEED_RAD_S:
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
	static const int reduced_only[] = {PRSM_IO_SWEEP_SCREW_SPEED_RAD_S, PRSM_IO_SWEEP_MESH_ERROR_UM,
	                                   PRSM_IO_SWEEP_MESH_DAMPING_RATIO};
	int ok_par = 1;
	if (fr && s->parameter != PRSM_IO_SWEEP_FREQUENCY_RATIO) {
		prsm_io_problem_once(p, from, "/dynamics/sweep", "parameter", "frequency_response",
		                     "a frequency response sweeps the frequency ratio (got %s)",
		                     prsm_io_sweep_parameter_name(s->parameter));
		ok_par = 0;
	} else if (s->parameter != PRSM_IO_SWEEP_FREQUENCY_RATIO) {
		int reduced = 0;
		for (size_t i = 0; i < sizeof reduced_only / sizeof reduced_only[0]; i++)
			reduced |= s->parameter == reduced_only[i];
		if (reduced == pair) {
			prsm_io_problem_once(p, from, "/dynamics/sweep", "parameter", "model",
			                     "%s is a parameter of the %s: the %s sweeps frequency_ratio, %s",
			                     prsm_io_sweep_parameter_name(s->parameter),
			                     pair ? "reduced model" : "gear pair",
			                     pair ? "gear pair" : "reduced model",
			                     pair ? "error_amplitude, damping_ratio, mean_load or stiffness_variation"
			                          : "screw_speed_rad_s, mesh_error_um or mesh_damping_ratio");
			ok_par = 0;
		}
	}
	if (fr && member(so, "directions") != NULL && !(s->up && s->down))
		prsm_io_problem_once(p, from, "/dynamics/sweep", "directions", "frequency_response",
		                     "a frequency response sweeps both ways (its jumps are where they disagree): [\"up\", \"down\"]");
	if (!(s->to >= s->from)) {
		prsm_io_problem_once(p, from, "/dynamics/sweep", "to", "order",
		                     "the sweep runs from %g to %g: to must be >= from", s->from, s->to);
		return;
	}
	const double q = floor((s->to - s->from) / s->step + 1e-9);
	if (!(q + 1.0 <= PRSM_VIB_SWEEP_POINTS_MAX)) {
		prsm_io_problem_once(p, from, "/dynamics/sweep", "step", "too_many",
		                     "the sweep has %.4g points per direction, at most %d: raise the step", q + 1.0,
		                     PRSM_VIB_SWEEP_POINTS_MAX);
		return;
	}
	const int dirs = fr ? 2 : s->up + s->down;
	const double total = (q + 1.0) * dirs *
	                     ((double)s->transient_periods + s->recorded_periods + (s->lyapunov ? s->lyapunov_periods : 0));
	if (total > 5e8)
		prsm_io_problem_once(p, from, "/dynamics", "sweep", "too_long",
		                     "the sweep integrates %.3g forcing periods in all, at most 5e8: fewer points or periods", total);
	periods_rule(p, from, "/dynamics/sweep", s->transient_periods, s->recorded_periods, s->lyapunov, s->lyapunov_periods);
	if (ok_par) {
		const char *why = sweep_value_invalid(v, s->parameter, s->from);
		if (why)
			prsm_io_problem_once(p, from, "/dynamics/sweep", "from", "range", "%s (got %g)", why, s->from);
		const double last = s->from + q * s->step;
		why = sweep_value_invalid(v, s->parameter, last);
		if (why)
			prsm_io_problem_once(p, from, "/dynamics/sweep", "to", "range",
			                     "%s (the last grid value is %g)", why, last);
	}
	observable_rules(p, from, v, "/dynamics/sweep", s->observable, s->clock);
	one_mesh(p, from, v, "/dynamics/sweep", "roller", s->roller);
}

static void steady_rules(prsm_problems *p, int from, const prsm_io_vib_request *v)
{
	const prsm_io_vib_steady *s = &v->steady_state;
	periods_rule(p, from, "/dynamics/steady_state", s->transient_periods, s->recorded_periods, s->lyapunov, s->lyapunov_periods);
	if ((double)s->recorded_periods * s->samples_per_period > 4e7)
		prsm_io_problem_once(p, from, "/dynamics/steady_state", "samples_per_period", "too_many",
		                     "%d recorded periods x %d samples is more than 4e7 samples", s->recorded_periods,
		                     s->samples_per_period);
	observable_rules(p, from, v, "/dynamics/steady_state", s->observable, s->clock);
	one_mesh(p, from, v, "/dynamics/steady_state", "roller", s->roller);
	if (v->gear_pair_model && s->lyapunov_exponents > 2)
		prsm_io_problem_once(p, from, "/dynamics/steady_state", "lyapunov_exponents", "range",
		                     "a gear pair has 2 Lyapunov exponents (got %d)", s->lyapunov_exponents);
	if (s->lyapunov_method == PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES && s->lyapunov_exponents != 1)
		prsm_io_problem_once(p, from, "/dynamics/steady_state", "lyapunov_exponents", "range",
		                     "two trajectories give the largest exponent only: 1 (got %d)",
		                     s->lyapunov_exponents);
}

static void basins_rules(prsm_problems *p, int from, const prsm_io_vib_request *v)
{
	const prsm_io_vib_basins *b = &v->basins;
	if (!(b->deflection_max > b->deflection_min))
		prsm_io_problem_once(p, from, "/dynamics/basins", "deflection_max", "order",
		                     "the grid needs deflection_min < deflection_max");
	if (!(b->rate_max > b->rate_min))
		prsm_io_problem_once(p, from, "/dynamics/basins", "rate_max", "order",
		                     "the grid needs rate_min < rate_max");
	const double cells = (double)b->deflection_cells * b->rate_cells;
	if (cells > PRSM_VIB_BASIN_CELLS_MAX)
		prsm_io_problem_once(p, from, "/dynamics/basins", "deflection_cells", "too_many",
		                     "%.0f cells, at most %d", cells,
		                     PRSM_VIB_BASIN_CELLS_MAX);
	else if (cells * ((double)b->periods + b->identify_periods) > 2e8)
		prsm_io_problem_once(p, from, "/dynamics/basins", "periods", "too_long",
		                     "the grid integrates %.3g forcing periods in all, at most 2e8",
		                     cells * ((double)b->periods + b->identify_periods));
	one_mesh(p, from, v, "/dynamics/basins", "roller", b->roller);
	if (!v->gear_pair_model && v->vibration.branches == PRSM_VIB_BRANCHES_AXIAL)
		prsm_io_problem_once(p, from, "/dynamics", "basins", "branch",
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
			prsm_io_problem_once(p, from, "/dynamics/linear", hz[i], "model",
			                     "a gear pair is dimensionless: give the band as from_frequency_ratio, to_frequency_ratio");
		if (!pair && member(lo, ratio[i]))
			prsm_io_problem_once(p, from, "/dynamics/linear", ratio[i], "model",
			                     "the reduced model's band is in Hz: from_Hz, to_Hz");
	}
	if (pair && !(l->to_frequency_ratio > l->from_frequency_ratio))
		prsm_io_problem_once(p, from, "/dynamics/linear", "to_frequency_ratio", "order",
		                     "the band needs from < to");
	if (!pair && !isnan(l->from_Hz) && !isnan(l->to_Hz) && !(l->to_Hz > l->from_Hz))
		prsm_io_problem_once(p, from, "/dynamics/linear", "to_Hz", "order", "the band needs from_Hz < to_Hz");
	/* the input and the output: axial, or the mesh's */
	const int axial[2] = {l->input != PRSM_VIB_IN_MESH_ERROR, l->output != PRSM_VIB_OUT_MESH_DEFLECTION};
	if (pair && axial[0])
		prsm_io_problem_once(p, from, "/dynamics/linear", "input", "model",
		                     "a gear pair is excited by its mesh error: mesh_error");
	if (pair && axial[1])
		prsm_io_problem_once(p, from, "/dynamics/linear", "output", "model",
		                     "a gear pair's output is its mesh deflection");
	/* the reduced model's, on a branch that is off */
	for (int i = 0; i < 2 && !pair; i++)
		if (br == (axial[i] ? PRSM_VIB_BRANCHES_GEAR : PRSM_VIB_BRANCHES_AXIAL))
			prsm_io_problem_once(p, from, "/dynamics/linear", i ? "output" : "input", "branch",
			                     "the %s branch is off (vibration.branches %s)", axial[i] ? "axial" : "gear",
			                     axial[i] ? "gear" : "axial");
	one_mesh(p, from, v, "/dynamics/linear", "input_roller", l->input_roller);
	one_mesh(p, from, v, "/dynamics/linear", "output_roller", l->output_roller);
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
		prsm_io_problem_once(p, from, ptr, NULL, mp.items[i].code, "%s", mp.items[i].message);
	}
}

/* The rules of the vibration analyses (analysis != transient) and of the transient against their
 * sections, once each field has been read: which members belong with which analysis is the
 * schema's ("rules", prsm_io_check_rules); the number of stages and the sections' own rules are
 * here. */
static void vibration_rules(prsm_problems *p, int from, const cJSON *obj, prsm_io_vib_request *v, int stages)
{
	const int an = v->analysis;
	if (an == PRSM_IO_DYN_TRANSIENT) {
		if (stages > 0)
			prsm_io_check_rules(&prsm_io_r_dynamics, obj, "/dynamics", from, p);
		else
			prsm_io_problem_once(p, from, "/dynamics", "analysis", "design",
			                     "the transient needs a design: a request without one is a gear pair "
			                     "(an analysis other than transient, and gear_pair)");
		return;
	}
	const int pair = v->gear_pair_model;
	if (stages > 1)
		prsm_io_problem_once(p, from, "/dynamics", "analysis", "single_stage",
		                     "the vibration model (docs/vibration.md) is built for a single-stage screw, not a chain of %d",
		                     stages);
	if (stages >= 1 && pair)
		prsm_io_problem_once(p, from, "/dynamics", "gear_pair", "with_design",
		                     "the gear pair is a request of its own, without a design: {\"dynamics\": {\"analysis\": ..., "
		                     "\"gear_pair\": {...}}}; a design runs its reduced model (the vibration object)");
	if (stages == 0 && !pair)
		prsm_io_problem_once(p, from, "/dynamics", "gear_pair", "required",
		                     "a request without a design is a gear pair: give gear_pair (or a design for the reduced model)");
	prsm_io_check_rules(&prsm_io_r_dynamics, obj, "/dynamics", from, p);
	/* the integration: the time object's tolerances, else the analysis' */
	const double tol = an == PRSM_IO_DYN_LINEAR || an == PRSM_IO_DYN_VIBRATION ? 1e-10 : 1e-9;
	v->integration.rel_tol = tol;
	v->integration.abs_tol = tol;
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
			prsm_io_problem_once(problems, first, cross.items[i].pointer, NULL, cross.items[i].code, "%s",
			                     cross.items[i].message);
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

/* ---- the result --------------------------------------------------------------------------------- */


static const char *name_of(const char *const *names, int n, int v)
{
	return v >= 0 && v < n ? names[v] : "unknown";
}
#define NAME(names, v) name_of(names, (int)(sizeof names / sizeof names[0]), (v))

/* |B| of stage 0 in m per rad (the stick band's and the stiff switch's default, docs/dynamics.md) */
static double slip_per_rad_m(const prsm_dyn_stage_params *p)
{
	const double *B = p->B_mm[PRSM_DYN_FLANK_LOWER];
	return sqrt(B[0] * B[0] + B[1] * B[1] + B[2] * B[2]) * 1e-3;
}

/* The checks: both maxima within their limits (1), else a warning (warnings not NULL) says which. */
static int checks_passed(const prsm_dyn_result *r, prsm_problems *warnings)
{
	const int pb_ok = r->max_power_balance_relative <= PRSM_IO_DYN_POWER_BALANCE_LIMIT;
	const int ne_ok = r->max_newton_euler_residual <= PRSM_IO_DYN_NEWTON_EULER_LIMIT;
	if (warnings && !pb_ok)
		prsm_problems_add(warnings, "/dynamics/time", "power_balance",
		                  "the power balance closes only to %.3g of the input power (limit %g): tighten "
		                  "rel_tol and abs_tol", r->max_power_balance_relative, PRSM_IO_DYN_POWER_BALANCE_LIMIT);
	if (warnings && !ne_ok)
		prsm_problems_add(warnings, "/dynamics", "newton_euler",
		                  "the Newton-Euler recovery of the carrier acceleration differs by %.3g (limit %g)",
		                  r->max_newton_euler_residual, PRSM_IO_DYN_NEWTON_EULER_LIMIT);
	return pb_ok && ne_ok;
}

/* The dynamics result (the document's `dynamics` member) of a finished simulation r of model m,
 * as obj[key]; warnings (may be NULL) gets a problem per failed check. */
static void dynamics_write(prsm_jw *w, cJSON *obj, const char *key, const prsm_dyn_model *m,
                           const prsm_dyn_result *r, prsm_problems *warnings)
{
	const prsm_dyn_options *o = prsm_dyn_model_options(m);
	prsm_io_dyn_result_view v = {
		.m = m, .o = o, .r = r, .torque = o->input.kind == PRSM_DYN_INPUT_TORQUE,
		.karnopp = o->friction.stick_model == PRSM_DYN_STICK_KARNOPP,
		.breakaway_torque_Nm = NAN, .holding_torque_backward_Nm = NAN,
		.kept_changes = r->mode_changes < PRSM_DYN_MODE_CHANGES_MAX ? r->mode_changes : PRSM_DYN_MODE_CHANGES_MAX,
		.power_balance_limit = PRSM_IO_DYN_POWER_BALANCE_LIMIT, .newton_euler_limit = PRSM_IO_DYN_NEWTON_EULER_LIMIT,
	};
	v.torque_series = v.torque && r->points > 0;
	v.stuck_series = v.karnopp && r->points > 0;
	/* what the model made of each stage (docs/dynamics.md) and the chain's screw-side inertia */
	v.model_stages = prsm_dyn_model_stages(m);
	for (int k = 0; k < v.model_stages; k++)
		v.stage[k] = *prsm_dyn_model_stage(m, k);
	v.screw_side_inertia_kg_m2 = prsm_dyn_model_screw_side_inertia(m);
	/* the parameters the model chose: mu when the stages agree, the stick band and the stiff
	 * switch from |B| of stage 0 (docs/dynamics.md); static_mu, initial_step_s and
	 * speed_scale_rad_s are left out when the request leaves them to the model */
	const prsm_dyn_friction *f = &o->friction;
	const prsm_dyn_stage_params *p0 = prsm_dyn_model_stage(m, 0);
	int same_mu = 1;
	for (int k = 1; k < v.model_stages; k++)
		same_mu &= prsm_dyn_model_stage(m, k)->mu == p0->mu;
	v.mu_shown = !isnan(f->mu) || same_mu;
	v.mu = isnan(f->mu) ? p0->mu : f->mu;
	const double v_eps_rad_s = f->smoothing_velocity_m_s / slip_per_rad_m(p0);
	v.stick_band_rad_s = isnan(f->stick_band_rad_s) ? 10.0 * v_eps_rad_s : f->stick_band_rad_s;
	const double sw = o->time.stiff_switch_rad_s;
	v.stiff_switch_shown = isfinite(sw) || isnan(sw);
	v.stiff_switch_rad_s = isnan(sw) ? 100.0 * v_eps_rad_s : sw;
	if (v.karnopp) {
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_dyn_breakaway_torques(&v.breakaway_torque_Nm, &v.holding_torque_backward_Nm, m, 0.0, &err))
			v.breakaway_torque_Nm = v.holding_torque_backward_Nm = NAN;
	}
	v.passed = checks_passed(r, warnings);
	void *ctx = w->ctx;
	w->ctx = &v;
	prsm_io_write(w, obj, key, &v, &prsm_io_w_dyn_result);
	w->ctx = ctx;
}

/* The document's dynamics object: the transient's, or a vibration analysis' (at: the document). */
void prsm_io_whook_dyn_document(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_dyn_document_view *d = at;
	if (d->vib == NULL) {
		dynamics_write(w, obj, key, d->m, d->r, NULL);
		return;
	}
	void *ctx = w->ctx;
	w->ctx = d->vib;
	prsm_io_write(w, obj, key, d->vib, &prsm_io_w_vib_result);
	w->ctx = ctx;
}

/* A result document (engine, name, warnings, dynamics) by its table. */
static cJSON *document(prsm_io_dyn_document_view *d)
{
	d->has_name = d->name && d->name[0];
	prsm_jw w = {0, d};
	cJSON *root = prsm_jw_root(&w);
	prsm_io_write_fields(&w, root, d, &prsm_io_w_dyn_document, 0);
	return prsm_jw_done(&w, root);
}

cJSON *prsm_io_dynamics_result_to_json(const char *name, const prsm_dyn_model *m, const prsm_dyn_result *r,
                                       const prsm_problems *warnings)
{
	prsm_problems all; /* the request's warnings, then the checks' */
	if (warnings)
		all = *warnings;
	else
		prsm_problems_init(&all);
	checks_passed(r, &all);
	prsm_io_dyn_document_view d = {.name = name, .model = PRSM_DYN_MODEL_VERSION, .warnings = &all, .m = m, .r = r};
	return document(&d);
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

/* ---- the vibration analyses' results (schemas/dynamics-result.schema.json) ----------------------- */

static const char *const class_names[] = {"periodic", "non_periodic", "quasi_periodic", "chaotic", "failed"};

/* An observable's name (PRSM_VIB_OBS_*: the schema's names in their order, prsm_io_tables.c) */
static const char *observable_name(int obs)
{
	return obs >= 0 && obs <= PRSM_VIB_OBS_THREAD_FORCE ? prsm_io_t_dynamics_steady_state_observable_names[obs]
	                                                    : "unknown";
}


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

static void write_te_lines(prsm_jw *w, cJSON *obj, const char *key, const prsm_vib_te_line *l, int n)
{
	cJSON *a = prsm_jw_array(w, obj, key);
	for (int k = 0; a && k < n; k++)
		prsm_io_write(w, a, NULL, &l[k], &prsm_io_w_vib_te_line);
}

/* vibration.te_lines as the analysis ran it: the lines, or "statics" or "none" (at: the options). */
void prsm_io_whook_vib_te_lines(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_vib_options *o = at;
	if (o->te_source == PRSM_VIB_TE_LINES)
		write_te_lines(w, obj, key, o->te_line, o->te_lines);
	else
		prsm_jw_string(w, obj, key, o->te_source == PRSM_VIB_TE_STATICS ? "statics" : "none");
}

/* An extreme's roller: null for an axial observable (at: the extreme). */
void prsm_io_whook_vib_extreme_roller(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_vib_extreme *x = at;
	if (axial_observable(x->observable))
		prsm_jw_null(w, obj, key);
	else
		prsm_jw_number(w, obj, key, x->index);
}

void prsm_io_whook_vib_extreme_amplitude(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_vib_extreme *x = at;
	prsm_jw_number(w, obj, key, 0.5 * (x->max - x->min));
}

/* A spectral line's order or frequency in Hz: the reduced model's (gear pair: null). */
void prsm_io_whook_vib_line_reduced(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_number(w, obj, key, ((const prsm_io_vib_result_view *)w->ctx)->pair ? NAN : *(const double *)at);
}

void prsm_io_whook_vib_line_frequency_ratio(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_vib_result_view *v = w->ctx;
	const prsm_vib_line *l = at;
	prsm_jw_number(w, obj, key, v->pair ? l->frequency : l->frequency * 2.0 * M_PI / v->P->reference_frequency_rad_s);
}

/* A contact's name (at: its open share): mesh_<k>, the reduced model's thread last. */
void prsm_io_whook_vib_contact_name(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_vib_result_view *v = w->ctx;
	const long k = (const double *)at - v->r->steady.loss_share;
	char name[32];
	if (!v->pair && k == v->P->rollers)
		snprintf(name, sizeof name, "thread");
	else
		snprintf(name, sizeof name, "mesh_%ld", k);
	prsm_jw_string(w, obj, key, name);
}

/* The sweep's points of one direction (at: the sweep), each by its table; the parameter's value
 * in the request's unit. */
static void sweep_points(prsm_jw *w, cJSON *obj, const char *key, const prsm_vib_sweep *s, int direction)
{
	const prsm_io_vib_result_view *v = w->ctx;
	cJSON *a = prsm_jw_array(w, obj, key);
	for (size_t k = 0; a && k < s->points; k++) {
		const prsm_vib_sweep_point *p = &s->point[k];
		if (p->direction != direction)
			continue;
		const int failed = p->classification == PRSM_VIB_FAILED;
		prsm_io_vib_sweep_point_view pv = {
			.p = p, .parameter = v->point_parameter, .value = p->parameter * v->from_engine, .failed = failed,
			.converged = !failed, .error = failed ? prsm_error_name(p->status) : NULL,
			.poincare = s->poincare + k * (size_t)s->recorded, .poincare_n = failed ? 0 : s->recorded,
		};
		prsm_io_write(w, a, NULL, &pv, &prsm_io_w_vib_sweep_point);
	}
}

void prsm_io_whook_vib_points_up(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	sweep_points(w, obj, key, at, 1);
}

void prsm_io_whook_vib_points_down(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	sweep_points(w, obj, key, at, -1);
}

static size_t failed_points(const prsm_vib_sweep *s)
{
	size_t n = 0;
	for (size_t k = 0; k < s->points; k++)
		n += s->point[k].classification == PRSM_VIB_FAILED;
	return n;
}

/* Its Poincare points, period x poincare_size (at: the attractor): a matrix behind a pointer in
 * each attractor, one pointer more than a table's path follows. */
void prsm_io_whook_vib_attractor_poincare(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_vib_attractor *x = at;
	const size_t size = (size_t)((const prsm_io_vib_result_view *)w->ctx)->r->basins.poincare_size;
	cJSON *pts = prsm_jw_array(w, obj, key);
	for (int k = 0; pts && k < x->period; k++) {
		cJSON *a = prsm_jw_array(w, pts, NULL);
		for (size_t j = 0; a && j < size; j++)
			prsm_jw_number(w, a, NULL, x->poincare[(size_t)k * size + j]);
	}
}

/* The FRF's unit: output over input (gear pair: dimensionless). */
static const char *frf_unit(int pair, int input, int output)
{
	if (pair)
		return "-";
	const int in_N = input == PRSM_VIB_IN_NUT_FORCE, out_N = output == PRSM_VIB_OUT_THREAD_FORCE;
	return in_N ? (out_N ? "N/N" : "m/N") : (out_N ? "N/m" : "m/m");
}

/* An eigenvalue's |Im| per unit tau (at: its imaginary part). */
void prsm_io_whook_vib_eig_frequency_ratio(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_number(w, obj, key, fabs(*(const double *)at) / ((const prsm_io_vib_result_view *)w->ctx)->wref);
}

/* The mode shapes' coordinates: each roller's mesh deflection, then the axial one. */
void prsm_io_whook_vib_mode_coordinates(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_vib_result_view *v = w->ctx;
	const prsm_vib_linear *l = &v->r->linear;
	cJSON *co = prsm_jw_array(w, obj, key);
	for (int k = 0; co && k < l->shape_size; k++) {
		char name[40];
		if (v->pair)
			snprintf(name, sizeof name, "x");
		else if (k < v->P->rollers && l->shape_size > (v->P->branches == PRSM_VIB_BRANCHES_AXIAL ? 1 : 0))
			snprintf(name, sizeof name, "mesh_deflection_%d", k);
		else
			snprintf(name, sizeof name, "axial_deflection");
		prsm_jw_string(w, co, NULL, name);
	}
}

void prsm_io_whook_vib_frf_magnitude(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_vib_result *r = ((const prsm_io_vib_result_view *)w->ctx)->r;
	cJSON *mag = prsm_jw_array(w, obj, key);
	for (size_t i = 0; mag && i < r->frf_points; i++)
		prsm_jw_number(w, mag, NULL, hypot(r->frf_re[i], r->frf_im[i]));
}

void prsm_io_whook_vib_frf_phase(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_vib_result *r = ((const prsm_io_vib_result_view *)w->ctx)->r;
	cJSON *ph = prsm_jw_array(w, obj, key);
	for (size_t i = 0; ph && i < r->frf_points; i++)
		prsm_jw_number(w, ph, NULL, atan2(r->frf_im[i], r->frf_re[i]) * DEG);
}

cJSON *prsm_io_vibration_result_to_json(const char *name, const prsm_io_vib_request *q, const prsm_dyn_options *dyn,
                                        const prsm_vib_model *m, const prsm_io_vib_result *r,
                                        const prsm_problems *warnings)
{
	prsm_problems none;
	prsm_problems_init(&none);
	prsm_io_vib_result_view v = {.q = q, .dyn = dyn, .P = prsm_vib_model_params(m), .r = r};
	v.pair = v.P->kind == PRSM_VIB_GEAR_PAIR;
	/* the request's dynamics object as the analysis ran it, every default written out: a valid
	 * dynamics object that reproduces the run (the statics engine's values the reduced model takes
	 * when they are not given stay out: model has them) */
	const int fr = q->analysis == PRSM_IO_DYN_FREQUENCY_RESPONSE;
	v.mu = isnan(dyn->friction.mu) ? v.P->mu : dyn->friction.mu;
	v.speed_given = isnan(q->vibration.frequency_ratio);
	v.sweep_shown = q->analysis == PRSM_IO_DYN_SWEEP || fr;
	v.directions = (q->sweep.up || fr ? 1 : 0) | (q->sweep.down || fr ? 2 : 0);
	v.continuation = fr ? 1 : q->sweep.continuation;
	v.mesh_order_per_rev = v.P->teeth_ring * v.P->carrier_ratio;
	v.wref = v.pair ? 1.0 : v.P->reference_frequency_rad_s;
	v.inv_wref = 1.0 / v.wref;
	v.hz = v.pair ? NAN : 1.0 / (2.0 * M_PI);
	v.frf_unit = frf_unit(v.pair, r->input, r->output);
	v.spectrum_ratio_scale = v.pair ? 1.0 : 2.0 * M_PI / v.P->reference_frequency_rad_s;
	v.lyapunov_scale = v.pair ? NAN : v.P->reference_frequency_rad_s;
	switch (q->analysis) {
	case PRSM_IO_DYN_SWEEP: {
		double to_engine = 1.0;
		prsm_io_sweep_parameter_engine(q->sweep.parameter, &to_engine);
		v.point_parameter = q->sweep.parameter;
		v.from_engine = 1.0 / to_engine;
		v.failed = failed_points(&r->sweep);
		break;
	}
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		v.point_parameter = PRSM_IO_SWEEP_FREQUENCY_RATIO;
		v.from_engine = 1.0;
		v.failed = failed_points(&r->fr.sweep);
		break;
	case PRSM_IO_DYN_BASINS:
		v.failed = r->basins.failed;
		break;
	default:
		break;
	}
	v.converged = v.failed == 0;
	const int steady = q->analysis == PRSM_IO_DYN_VIBRATION;
	v.observable = steady ? q->steady_state.observable : q->sweep.observable;
	v.observable_roller = steady ? q->steady_state.roller : q->sweep.roller;
	v.observable_has_roller = !axial_observable(v.observable);
	prsm_io_dyn_document_view d = {.name = name, .model = PRSM_VIB_MODEL_VERSION, .warnings = warnings ? warnings : &none,
	                               .vib = &v};
	return document(&d);
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
		const char *obs = observable_name(q->steady_state.observable);
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
		          observable_name(q->sweep.observable));
		break;
	}
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		csv_sweep(f, &r->fr.sweep, "frequency_ratio", 1.0, observable_name(q->sweep.observable));
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
