/*
 * vibrate.c: the vibration analyses of a simulation request: model, the rules that need it, the
 * run of each analysis and its result (see vibrate.h; docs/vibration.md).
 */
#include "app/vibrate.h"
#include "app/text.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/json_util.h"

struct prsm_app_vibration {
	prsm_io_vib_request q;        /* the request, defaults resolved */
	prsm_dyn_options dyn;         /* the transient options the request gave (load, friction, masses) */
	prsm_vib_model *model;
	prsm_io_vib_result r;
	int ran;
	const prsm_vib_split *split;  /* a sweep's or basin grid's tasks over processes; NULL: here */
};

/* A problem at /dynamics/<section>/<key> (the rules that need the model). */
static void problem(prsm_problems *p, const char *section, const char *key, const char *code, const char *fmt, ...)
	__attribute__((format(printf, 5, 6)));
static void problem(prsm_problems *p, const char *section, const char *key, const char *code, const char *fmt, ...)
{
	char ptr[PRSM_PROBLEM_POINTER_MAX], msg[PRSM_PROBLEM_MESSAGE_MAX];
	snprintf(ptr, sizeof ptr, "/dynamics/%s%s%s", section, key ? "/" : "", key ? key : "");
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	prsm_problems_add(p, ptr, code, "%s", msg);
}

static void roller_rule(prsm_problems *p, const prsm_vib_params *P, const char *section, const char *key, int roller)
{
	if (P->kind == PRSM_VIB_REDUCED && roller >= P->rollers)
		problem(p, section, key, "range", "the design has %d rollers: 0 to %d (got %d)", P->rollers, P->rollers - 1,
		        roller);
}

static void clock_rule(prsm_problems *p, const prsm_vib_params *P, const char *section, int clock)
{
	if (clock == PRSM_VIB_CLOCK_TE && P->kind == PRSM_VIB_REDUCED && !(P->te_period_rev > 0.0))
		problem(p, section, "clock", "no_te_period",
		        "the TE lines have no common period (within 1000 screw revolutions, e.g. orders with k*): use the "
		        "mesh clock");
}

/* The rules that need the model, and the linear band's defaults. */
static void model_rules(prsm_app_vibration *v, prsm_problems *p)
{
	prsm_io_vib_request *q = &v->q;
	const prsm_vib_params *P = prsm_vib_model_params(v->model);
	switch (q->analysis) {
	case PRSM_IO_DYN_VIBRATION:
		roller_rule(p, P, "steady_state", "roller", q->steady_state.roller);
		clock_rule(p, P, "steady_state", q->steady_state.clock);
		if (q->steady_state.lyapunov && q->steady_state.lyapunov_exponents > P->poincare_size)
			problem(p, "steady_state", "lyapunov_exponents", "range",
			        "the model's Poincare vector has %d components: at most %d exponents (got %d)", P->poincare_size,
			        P->poincare_size, q->steady_state.lyapunov_exponents);
		break;
	case PRSM_IO_DYN_SWEEP:
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		roller_rule(p, P, "sweep", "roller", q->sweep.roller);
		clock_rule(p, P, "sweep", q->sweep.clock);
		break;
	case PRSM_IO_DYN_BASINS:
		roller_rule(p, P, "basins", "roller", q->basins.roller);
		break;
	case PRSM_IO_DYN_LINEAR: {
		prsm_io_vib_linear *l = &q->linear;
		if (l->input == PRSM_VIB_IN_MESH_ERROR)
			roller_rule(p, P, "linear", "input_roller", l->input_roller);
		if (l->output == PRSM_VIB_OUT_MESH_DEFLECTION)
			roller_rule(p, P, "linear", "output_roller", l->output_roller);
		if (P->kind == PRSM_VIB_REDUCED) {
			const int axial = l->output != PRSM_VIB_OUT_MESH_DEFLECTION;
			const double f = (axial ? P->axial_frequency_rad_s : P->reference_frequency_rad_s) / (2.0 * M_PI);
			if (isnan(l->from_Hz))
				l->from_Hz = (axial ? 0.5 : 0.75) * f;
			if (isnan(l->to_Hz))
				l->to_Hz = (axial ? 1.5 : 1.4) * f;
			if (!(l->to_Hz > l->from_Hz))
				problem(p, "linear", "to_Hz", "order", "the band runs from %g Hz to %g Hz: from_Hz < to_Hz",
				        l->from_Hz, l->to_Hz);
		}
		break;
	}
	default:
		break;
	}
}

/* A failure of the model as a problem at its field: a design's fields are under /design. */
static int model_problem(prsm_problems *problems, int rc, const prsm_error *err)
{
	char ptr[2 * PRSM_JSON_POINTER_MAX];
	const char *p = err->pointer;
	const int ours = strncmp(p, "/dynamics", 9) == 0;
	snprintf(ptr, sizeof ptr, "%s%s", ours || p[0] == '\0' ? "" : "/design", p);
	prsm_problems_add(problems, ptr,
	                  rc == PRSM_ENOCONVERGE ? "no_convergence" : rc == PRSM_EGEOMETRY ? "geometry" : "model",
	                  "%s", err->message);
	return rc;
}

int prsm_app_vibration_new(prsm_app_vibration **out, const prsm_io_vib_request *q, const prsm_design *d,
                           const prsm_analysis *a, const prsm_dyn_options *dyn, const prsm_errors *errors,
                           const prsm_assembly_options *assembly, prsm_problems *problems)
{
	*out = NULL;
	prsm_app_vibration *v = calloc(1, sizeof *v); /* handed to the caller on success */
	if (v == NULL)
		return PRSM_ENOMEM;
	v->q = *q;
	if (dyn != NULL)
		v->dyn = *dyn;
	else
		prsm_dyn_options_init(&v->dyn);
	prsm_error err = PRSM_ERROR_INIT;
	int rc;
	if (q->gear_pair_model)
		rc = prsm_vib_gear_pair_new(&v->model, &q->gear_pair, &err);
	else
		rc = prsm_vib_model_new(&v->model, d, a, &v->dyn, &q->vibration, q->te_from_errors ? errors : NULL,
		                        q->te_from_errors ? assembly : NULL, &err);
	if (rc) {
		model_problem(problems, rc, &err);
		prsm_app_vibration_free(v);
		return rc;
	}
	const int before = prsm_problems_total(problems);
	model_rules(v, problems);
	if (prsm_problems_total(problems) > before) {
		prsm_app_vibration_free(v);
		return PRSM_EINVAL;
	}
	*out = v;
	return 0;
}

static size_t sweep_grid(const prsm_io_vib_sweep *s)
{
	return (size_t)floor((s->to - s->from) / s->step + 1e-9) + 1;
}

size_t prsm_app_vibration_work(const prsm_app_vibration *v)
{
	const prsm_io_vib_request *q = &v->q;
	switch (q->analysis) {
	case PRSM_IO_DYN_SWEEP: /* independent points are computed once for both directions */
		return sweep_grid(&q->sweep) * (size_t)(q->sweep.continuation ? q->sweep.up + q->sweep.down : 1);
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		return 2 * sweep_grid(&q->sweep);
	case PRSM_IO_DYN_BASINS:
		return (size_t)q->basins.deflection_cells * (size_t)q->basins.rate_cells;
	default:
		return 1;
	}
}

const char *prsm_app_vibration_work_unit(const prsm_app_vibration *v)
{
	switch (v->q.analysis) {
	case PRSM_IO_DYN_SWEEP:
	case PRSM_IO_DYN_FREQUENCY_RESPONSE:
		return "sweep_points";
	case PRSM_IO_DYN_BASINS:
		return "basin_cells";
	default:
		return "analyses";
	}
}

static void effort_add(prsm_vib_effort *a, const prsm_vib_effort *b)
{
	a->steps += b->steps;
	a->rejected += b->rejected;
	a->rhs_evaluations += b->rhs_evaluations;
	a->events += b->events;
	a->switches += b->switches;
}

static void sweep_options(prsm_vib_sweep_options *so, const prsm_io_vib_request *q, int threads)
{
	const prsm_io_vib_sweep *s = &q->sweep;
	prsm_vib_sweep_options_init(so);
	double to_engine = 1.0;
	so->parameter = prsm_io_sweep_parameter_engine(s->parameter, &to_engine);
	so->from = s->from * to_engine;
	so->to = s->to * to_engine;
	so->step = s->step * to_engine;
	so->up = s->up;
	so->down = s->down;
	so->continuation = s->continuation;
	so->steady.transient_periods = s->transient_periods;
	so->steady.recorded_periods = s->recorded_periods;
	so->steady.clock = s->clock;
	so->steady.observable = s->observable;
	so->steady.index = s->roller;
	so->steady.period_tol = s->period_tolerance;
	so->steady.lyapunov = s->lyapunov;
	so->steady.lyapunov_periods = s->lyapunov_periods;
	so->steady.integration = q->integration;
	so->threads = threads;
}

static int run_linear(prsm_app_vibration *v, prsm_error *err)
{
	const prsm_io_vib_request *q = &v->q;
	const prsm_io_vib_linear *l = &q->linear;
	prsm_io_vib_result *r = &v->r;
	const int pair = q->gear_pair_model;
	int rc = prsm_vib_linearise(&r->linear, v->model, err);
	if (rc)
		return rc;
	r->input = l->input;
	r->input_roller = l->input == PRSM_VIB_IN_MESH_ERROR ? l->input_roller : 0;
	r->output = l->output;
	r->output_roller = l->output == PRSM_VIB_OUT_MESH_DEFLECTION ? l->output_roller : 0;
	const double lo = pair ? l->from_frequency_ratio : 2.0 * M_PI * l->from_Hz;
	const double hi = pair ? l->to_frequency_ratio : 2.0 * M_PI * l->to_Hz;
	const size_t n = (size_t)l->points;
	r->frf_omega = malloc(n * sizeof(double));
	r->frf_re = malloc(n * sizeof(double));
	r->frf_im = malloc(n * sizeof(double));
	if (!r->frf_omega || !r->frf_re || !r->frf_im)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the FRF");
	r->frf_points = n;
	for (size_t i = 0; i < n; i++)
		r->frf_omega[i] = lo + (hi - lo) * (double)i / (double)(n - 1);
	rc = prsm_vib_frf(r->frf_re, r->frf_im, v->model, &r->linear, r->input, r->input_roller, r->output,
	                  r->output_roller, r->frf_omega, n, err);
	if (rc)
		return rc;
	return prsm_vib_half_power_run(&r->half_power, v->model, &r->linear, r->input, r->input_roller, r->output,
	                               r->output_roller, lo, hi, err);
}

static int run_vibration(prsm_app_vibration *v, const prsm_cancel_flag *cancel, prsm_error *err)
{
	const prsm_io_vib_request *q = &v->q;
	const prsm_io_vib_steady *s = &q->steady_state;
	prsm_io_vib_result *r = &v->r;
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	so.transient_periods = s->transient_periods;
	so.recorded_periods = s->recorded_periods;
	so.clock = s->clock;
	so.observable = s->observable;
	so.index = s->roller;
	so.period_tol = s->period_tolerance;
	so.samples_per_period = s->samples_per_period;
	so.lyapunov = 0; /* the exponents below, after the same transient */
	so.integration = q->integration;
	int rc = prsm_vib_steady_state(&r->steady, v->model, NULL, &so, cancel, err);
	if (rc)
		return rc;
	effort_add(&r->effort, &r->steady.effort);
	if (!s->lyapunov)
		return 0;
	prsm_vib_lyapunov_options lo = PRSM_VIB_LYAPUNOV_OPTIONS_INIT;
	lo.method = s->lyapunov_method;
	lo.exponents = s->lyapunov_exponents;
	lo.transient_periods = s->transient_periods;
	lo.periods = s->lyapunov_periods;
	lo.clock = r->steady.clock;
	lo.integration = q->integration;
	rc = prsm_vib_lyapunov_run(&r->lyapunov, v->model, NULL, &lo, cancel, err);
	if (rc)
		return rc;
	effort_add(&r->effort, &r->lyapunov.effort);
	r->with_lyapunov = 1;
	const double lmax = r->lyapunov.lambda[0];
	r->steady.lyapunov = lmax;
	if (r->steady.classification != PRSM_VIB_PERIODIC)
		r->steady.classification = lmax > 1e-3 ? PRSM_VIB_CHAOTIC : PRSM_VIB_QUASI_PERIODIC;
	return 0;
}

static int run_basins(prsm_app_vibration *v, int threads, const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                      void *progress_ctx, prsm_error *err)
{
	const prsm_io_vib_request *q = &v->q;
	const prsm_io_vib_basins *b = &q->basins;
	const prsm_vib_params *P = prsm_vib_model_params(v->model);
	prsm_vib_basin_options bo;
	prsm_vib_basin_options_init(&bo);
	if (P->kind == PRSM_VIB_REDUCED) {
		bo.x_state = 1 + b->roller;              /* P_{j+1} = r_b1 phi_j / b_g */
		bo.v_state = P->rollers + 1 + 1 + b->roller; /* its rate V_{j+1} */
	}
	bo.x_min = b->deflection_min;
	bo.x_max = b->deflection_max;
	bo.nx = b->deflection_cells;
	bo.v_min = b->rate_min;
	bo.v_max = b->rate_max;
	bo.nv = b->rate_cells;
	bo.periods = b->periods;
	bo.identify_periods = b->identify_periods;
	bo.distance = b->distance;
	bo.period_tol = b->period_tolerance;
	bo.integration = q->integration;
	bo.threads = threads;
	bo.split = v->split;
	const int rc = prsm_vib_basins_run(&v->r.basins, v->model, &bo, cancel, progress, progress_ctx, err);
	if (rc == 0)
		effort_add(&v->r.effort, &v->r.basins.effort);
	return rc;
}

int prsm_app_vibration_run(prsm_app_vibration *v, int threads, const prsm_cancel_flag *cancel,
                           prsm_progress_fn progress, void *progress_ctx, prsm_error *err)
{
	if (v->ran) {
		prsm_io_vib_result_free(&v->r);
		v->ran = 0;
	}
	memset(&v->r, 0, sizeof v->r);
	prsm_io_vib_result *r = &v->r;
	r->analysis = v->q.analysis;
	r->threads = threads < 1 ? 1 : threads;
	prsm_progress pr = PRSM_PROGRESS_INIT;
	pr.planned = prsm_app_vibration_work(v);
	if (progress)
		progress(progress_ctx, &pr);
	int rc = 0;
	switch (v->q.analysis) {
	case PRSM_IO_DYN_LINEAR:
		rc = run_linear(v, err);
		break;
	case PRSM_IO_DYN_VIBRATION:
		rc = run_vibration(v, cancel, err);
		break;
	case PRSM_IO_DYN_SWEEP: {
		prsm_vib_sweep_options so;
		sweep_options(&so, &v->q, r->threads);
		so.split = v->split;
		rc = prsm_vib_sweep_run(&r->sweep, v->model, &so, cancel, progress, progress_ctx, err);
		if (rc == 0)
			effort_add(&r->effort, &r->sweep.effort);
		break;
	}
	case PRSM_IO_DYN_FREQUENCY_RESPONSE: {
		prsm_vib_sweep_options so;
		sweep_options(&so, &v->q, r->threads);
		r->with_harmonic_balance = v->q.gear_pair_model && v->q.gear_pair.stiffness_variation == 0.0;
		rc = prsm_vib_frequency_response_run(&r->fr, v->model, &so, v->q.frequency_response.agreement_tolerance,
		                                     cancel, progress, progress_ctx, err);
		if (rc == 0)
			effort_add(&r->effort, &r->fr.sweep.effort);
		break;
	}
	case PRSM_IO_DYN_BASINS:
		rc = run_basins(v, r->threads, cancel, progress, progress_ctx, err);
		break;
	default:
		rc = prsm_error_set(err, PRSM_EINVAL, "/dynamics/analysis", "not a vibration analysis");
	}
	if (rc) {
		prsm_io_vib_result_free(r);
		return rc;
	}
	pr.done = pr.planned;
	if (progress)
		progress(progress_ctx, &pr);
	v->ran = 1;
	return 0;
}

int prsm_app_vibration_set_split(prsm_app_vibration *v, const prsm_vib_split *split)
{
	const int can = v->q.analysis == PRSM_IO_DYN_SWEEP || v->q.analysis == PRSM_IO_DYN_BASINS;
	v->split = can ? split : NULL;
	return can;
}

cJSON *prsm_app_vibration_result(const prsm_app_vibration *v, const char *name, const prsm_problems *warnings)
{
	if (!v->ran)
		return NULL;
	return prsm_io_vibration_result_to_json(name, &v->q, &v->dyn, v->model, &v->r, warnings);
}

int prsm_app_vibration_csv(FILE *f, const prsm_app_vibration *v)
{
	return v->ran ? prsm_io_vibration_write_csv(f, &v->q, v->model, &v->r) : PRSM_EINVAL;
}

int prsm_app_vibration_text(FILE *f, const prsm_app_vibration *v, const prsm_problems *warnings)
{
	return v->ran ? prsm_app_text_vibration(f, &v->q, v->model, &v->r, warnings) : PRSM_EINVAL;
}

const prsm_io_vib_request *prsm_app_vibration_request(const prsm_app_vibration *v)
{
	return &v->q;
}

const prsm_vib_model *prsm_app_vibration_model(const prsm_app_vibration *v)
{
	return v->model;
}

const prsm_io_vib_result *prsm_app_vibration_output(const prsm_app_vibration *v)
{
	return v->ran ? &v->r : NULL;
}

void prsm_app_vibration_free(prsm_app_vibration *v)
{
	if (v == NULL)
		return;
	if (v->ran)
		prsm_io_vib_result_free(&v->r);
	prsm_vib_model_free(v->model);
	free(v);
}
