/*
 * allocation_json.c: the tolerance-allocation document (schemas/allocation.schema.json) read
 * and checked with every problem at once (see allocation_json.h). The run: src/app/allocate.c;
 * the result (schemas/allocation-result.schema.json): allocation_result.c.
 *
 * The fields, their limits and C members are stated once, in the schema ("x-prsm"); io/doc.c
 * reads the document by the table generated from it. What a table cannot say is here, as the
 * steps and hooks the schema names: which kind of document it is (an embedded study, read by
 * the study reader with its problems re-pointed under /study, or an analytic stack), names that
 * refer to the study's tolerances and outputs or to the analytic outputs, the cost model's
 * members, the order of bounds and spec limits, the one target of a constraint, the Monte Carlo
 * sample budget, and the move of each array item into the parallel arrays of the allocation
 * model. `study`: the linear model comes from the study's model (src/app); `analytic`: it is
 * the document's own, and there is no Monte Carlo.
 */
#include "io/allocation_json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/errors_json.h"
#include "io/json_util.h"
#include "io/study_json.h"
#include "mc/stats.h"
#include "opt/alloc_mc.h"
#include "prsm_io_tables.h"

#define DEFAULT_MAX_CORRECTIONS 8
#define DEFAULT_SCALE_RTOL 0.01
/* an analytic stack's figures: bounded so that the stack and its squares stay finite */
#define FIGURE_MAX 1e100

/* What the steps share while a document is read. */
typedef struct {
	prsm_problems *warnings; /* the study's (may be NULL) */
	size_t max_samples;      /* the caller's cap, 0: PRSM_IO_ALLOC_MAX_SAMPLES */
	int kind_ok;             /* the study loaded, or the analytic outputs were read without a problem */
	int study_rc;            /* the study reader's return code */
	const prsm_io_study_options *study; /* the study reader's hooks (may be NULL) */
	int out_of_memory;
} alloc_reading;

void prsm_io_allocation_free(prsm_io_allocation *d)
{
	if (d) {
		free(d->study);
		free(d);
	}
}

void prsm_io_alloc_bounds_init(prsm_io_alloc_bounds *b)
{
	b->lower = 0.0;
	b->upper = INFINITY;
}

static int find_name(char names[][48], size_t n, const char *name)
{
	for (size_t i = 0; i < n; i++)
		if (strcmp(names[i], name) == 0)
			return (int)i;
	return -1;
}

/* The string field key of the object a step reads, when it was there and valid; else NULL. */
static const char *string_of(const prsm_io_at *at, const char *key)
{
	return prsm_io_was_read(at, key) ? cJSON_GetObjectItemCaseSensitive(at->obj, key)->valuestring : NULL;
}

/* ---- the kind: a study or an analytic stack ------------------------------------------------ */

int prsm_io_step_alloc_kind(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	alloc_reading *c = at->ctx;
	const cJSON *study = cJSON_GetObjectItemCaseSensitive(at->obj, "study");
	const cJSON *analytic = cJSON_GetObjectItemCaseSensitive(at->obj, "analytic");
	if (study && analytic) {
		prsm_problems_add(pr, "/analytic", "conflict", "an allocation has a study or an analytic stack, not both");
	} else if (study) {
		d->is_study = 1;
		d->study = calloc(1, sizeof *d->study);
		prsm_problems *sp = calloc(1, sizeof *sp);
		if (!d->study || !sp) {
			free(sp);
			c->out_of_memory = 1;
			return 1;
		}
		prsm_problems_init(sp);
		c->study_rc = prsm_io_study_load(d->study, study, c->study, c->warnings, sp);
		prsm_json_problems_append_prefixed(pr, sp, "/study");
		free(sp);
		c->kind_ok = c->study_rc == 0;
	} else if (analytic) {
		prsm_io_get(at, "analytic", pr);
		c->kind_ok = prsm_problems_total(pr) == at->start;
	} else {
		prsm_problems_add(pr, "/study", "required", "an allocation needs a study (or an analytic stack)");
	}
	/* the Monte Carlo run's defaults: the study's samples and seed */
	d->opt.verify = d->is_study;
	d->opt.max_corrections = DEFAULT_MAX_CORRECTIONS;
	d->opt.scale_rtol = DEFAULT_SCALE_RTOL;
	if (d->study) {
		d->samples = d->study->study.mc.samples;
		d->seed = d->study->study.mc.seed;
	}
	return 0;
}

/* analytic/outputs/N: its name, once, and its nominal */
int prsm_io_step_alloc_output(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	const char *name = string_of(at, "name");
	if (name) {
		if (find_name(d->aout_name, (size_t)at->index, name) >= 0)
			prsm_io_problem(pr, at->pointer, "name", "duplicate", "output %s is named twice", name);
		snprintf(d->aout_name[at->index], sizeof d->aout_name[at->index], "%s", name);
	}
	if (prsm_io_get(at, "nominal", pr) == PRSM_JSON_PRESENT)
		d->aout_nominal[at->index] = ((const prsm_io_alloc_output *)at->base)->nominal;
	return 0;
}

/* ---- the tolerances to allocate ------------------------------------------------------------- */

/* allocate/N/parameter: once; a study's tolerance, one whose half-width scales */
int prsm_io_step_alloc_parameter(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	const alloc_reading *c = at->ctx;
	const int i = at->index;
	const char *name = string_of(at, "parameter");
	if (!name)
		return 0;
	snprintf(d->tol_name[i], sizeof d->tol_name[i], "%s", name);
	for (int k = 0; k < i; k++)
		if (strcmp(d->tol_name[k], name) == 0)
			prsm_io_problem(pr, at->pointer, "parameter", "duplicate", "%s is allocated twice (at /allocate/%d)", name,
			                k);
	snprintf(d->unit[i], sizeof d->unit[i], "%s", d->is_study ? prsm_io_error_unit_of(name) : "");
	if (!d->is_study || !c->kind_ok)
		return 0;
	const prsm_io_study *s = d->study;
	int g = -1;
	for (size_t k = 0; k < s->n_tolerances; k++)
		if (strcmp(s->tolerances[k].parameter, name) == 0)
			g = (int)k;
	if (g < 0) {
		prsm_io_problem(pr, at->pointer, "parameter", "unknown_tolerance", "%s is not a tolerance of the study", name);
	} else {
		d->opt.group[i] = (size_t)g;
		if (s->tolerances[g].dist.kind == PRSM_DIST_LOGNORMAL)
			prsm_io_problem(pr, at->pointer, "parameter", "not_scalable", "%s has a lognormal distribution, whose "
			                "half-width does not scale with one parameter: give it a normal, truncnormal, uniform, "
			                "triangular or rayleigh distribution", name);
	}
	return 0;
}

/* allocate/N/cost: the rest only once the model is known */
int prsm_io_step_alloc_cost_model(prsm_io_at *at, prsm_problems *pr)
{
	(void)pr;
	return !prsm_io_was_read(at, "model");
}

/* power and rate belong to their models */
int prsm_io_step_alloc_cost_kind(prsm_io_at *at, prsm_problems *pr)
{
	prsm_alloc_cost *c = at->base;
	c->power = c->kind == PRSM_ALLOC_COST_RECIPROCAL_SQUARED ? 2.0 : 1.0;
	if (c->kind == PRSM_ALLOC_COST_RECIPROCAL_POWER)
		prsm_io_get(at, "power", pr);
	else if (cJSON_GetObjectItemCaseSensitive(at->obj, "power"))
		prsm_io_problem(pr, at->pointer, "power", "not_allowed", "power belongs to the reciprocal_power model");
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL)
		prsm_io_get(at, "rate", pr);
	else if (cJSON_GetObjectItemCaseSensitive(at->obj, "rate"))
		prsm_io_problem(pr, at->pointer, "rate", "not_allowed", "rate belongs to the exponential model");
	return 0;
}

void prsm_io_hook_alloc_bounds(void *base, const cJSON *obj, const char *p, prsm_problems *pr)
{
	(void)obj;
	const prsm_io_alloc_bounds *b = base;
	if (!(b->upper > b->lower))
		prsm_io_problem(pr, p, "upper", "impossible", "the upper bound %g must exceed the lower bound %g", b->upper,
		                b->lower);
}

/* allocate/N/sensitivities (analytic): by the analytic outputs' names, at least one */
static void read_sensitivities(prsm_io_allocation *d, const prsm_io_at *at, prsm_problems *pr)
{
	const cJSON *sens = NULL;
	char sp[PRSM_JSON_POINTER_MAX];
	if (prsm_json_get_section(&sens, sp, sizeof sp, at->obj, at->pointer, "sensitivities", PRSM_JSON_REQUIRED, NULL,
	                          pr) != PRSM_JSON_PRESENT)
		return;
	for (const cJSON *s = sens->child; s; s = s->next) {
		char ep[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(ep, sizeof ep, sp, s->string);
		const int o = find_name(d->aout_name, d->n_aout, s->string);
		double v;
		if (prsm_json_number_value(&v, s, ep, (prsm_json_range){-FIGURE_MAX, FIGURE_MAX, 0, 0}, pr))
			continue;
		if (o < 0)
			prsm_problems_add(pr, ep, "unknown_output", "%s is not an output of /analytic/outputs", s->string);
		else
			d->sens[at->index][o] = v;
	}
	if (!sens->child)
		prsm_problems_add(pr, sp, "required", "give the tolerance's sensitivity to at least one output");
}

/* An analytic tolerance's sensitivities; the item into the allocation model's arrays. */
int prsm_io_step_alloc_tolerance(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	const prsm_io_alloc_tolerance *t = at->base;
	const int i = at->index;
	d->model.cost[i] = t->cost;
	d->model.t_min[i] = t->bounds.lower;
	d->model.t_max[i] = t->bounds.upper;
	d->ref_given[i] = NAN;
	if (!d->is_study) {
		read_sensitivities(d, at, pr);
		d->model.k[i] = prsm_io_was_read(at, "sd_ratio") ? t->sd_ratio : 3.0;
		if (prsm_io_was_read(at, "reference_half_width"))
			d->ref_given[i] = t->reference_half_width;
	}
	return 0;
}

/* ---- the constraints -------------------------------------------------------------------------- */

/* constraints/N/output: once; the study's output (its spec the default) or an analytic one */
int prsm_io_step_alloc_constraint_output(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	const alloc_reading *c = at->ctx;
	const int i = at->index;
	const char *name = string_of(at, "output");
	if (!name)
		return 0;
	snprintf(d->out_name[i], sizeof d->out_name[i], "%s", name);
	if (find_name(d->out_name, (size_t)i, name) >= 0)
		prsm_io_problem(pr, at->pointer, "output", "duplicate", "%s is constrained twice", name);
	if (d->is_study && c->kind_ok) {
		const prsm_study *st = &d->study->study;
		int o = -1;
		for (size_t k = 0; k < st->m; k++)
			if (strcmp(st->outputs[k].name, name) == 0)
				o = (int)k;
		if (o < 0) {
			prsm_io_problem(pr, at->pointer, "output", "unknown_output", "%s is not among the study's outputs", name);
		} else {
			d->opt.output[i] = (size_t)o;
			d->has_spec[i] = st->outputs[o].has_spec;
			d->model.spec[i] = st->outputs[o].spec;
		}
	} else if (!d->is_study && find_name(d->aout_name, d->n_aout, name) < 0) {
		prsm_io_problem(pr, at->pointer, "output", "unknown_output", "%s is not an output of /analytic/outputs", name);
	}
	return 0;
}

void prsm_io_hook_alloc_spec(void *base, const cJSON *obj, const char *p, prsm_problems *pr)
{
	(void)obj;
	const prsm_spec *s = base;
	if (!s->has_lower && !s->has_upper)
		prsm_problems_add(pr, p, "required", "a spec has a lower limit, an upper limit or both");
	if (s->has_lower && s->has_upper && !(s->lower < s->upper))
		prsm_io_problem(pr, p, "upper", "impossible", "the upper limit must exceed the lower limit");
}

/* Exactly one target (a yield target needs a spec); the item into the model's arrays. */
int prsm_io_step_alloc_constraint(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	const alloc_reading *c = at->ctx;
	const prsm_io_alloc_constraint *t = at->base;
	prsm_alloc_model *md = &d->model;
	const int i = at->index;
	if (t->has_spec) {
		md->spec[i] = t->spec;
		d->has_spec[i] = 1;
	}
	d->target_yield[i] = NAN;
	int given = 0;
	if (prsm_io_was_read(at, "target_yield_percent")) {
		given++;
		md->has_target[i] = 1;
		md->out_fraction[i] = (100.0 - t->target_yield_percent) / 100.0;
		d->target_yield[i] = t->target_yield_percent / 100.0;
	}
	if (prsm_io_was_read(at, "target_ppm")) {
		given++;
		md->has_target[i] = 1;
		md->out_fraction[i] = t->target_ppm * 1e-6;
		d->target_yield[i] = 1.0 - t->target_ppm * 1e-6;
	}
	if (prsm_io_was_read(at, "assembly_tolerance")) {
		given++;
		md->has_target[i] = 0;
		md->assembly_tol[i] = t->assembly_tolerance;
	}
	if (given != 1)
		prsm_problems_add(pr, at->pointer, given ? "conflict" : "required",
		                  "give exactly one of target_yield_percent, target_ppm, assembly_tolerance");
	if (t->has_yield_method) {
		if (!d->is_study) {
			prsm_io_problem(pr, at->pointer, "yield_method", "not_allowed",
			                "an analytic allocation has no Monte Carlo: yield_method needs a study");
		} else if (d->study && c->kind_ok && d->opt.output[i] < d->study->study.m &&
		           strcmp(d->study->study.outputs[d->opt.output[i]].name, d->out_name[i]) == 0) {
			d->study->study.outputs[d->opt.output[i]].yield_method = t->yield_method;
		}
	}
	if (md->has_target[i] && given == 1 && !d->has_spec[i] && (!d->is_study || c->kind_ok))
		prsm_problems_add(pr, at->pointer, "required", "a target yield needs a spec: give one here or in the study");
	return 0;
}

/* ---- the Monte Carlo verification ------------------------------------------------------------ */

int prsm_io_step_alloc_mc(prsm_io_at *at, prsm_problems *pr)
{
	if (((prsm_io_allocation *)at->root)->is_study)
		return 0;
	prsm_problems_add(pr, at->pointer, "not_allowed",
	                  "an analytic allocation has no Monte Carlo: its linear model is the document");
	return 1;
}

/* The samples of every run within the cap, and enough to show each target yield. */
int prsm_io_step_alloc_samples(prsm_io_at *at, prsm_problems *pr)
{
	const prsm_io_allocation *d = at->root;
	const alloc_reading *c = at->ctx;
	if (!(d->is_study && d->opt.verify && d->samples > 0))
		return 0;
	const char *sp = cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(at->obj, "monte_carlo"))
	                     ? "/monte_carlo/samples" : "/study/monte_carlo/samples";
	const double total = (double)d->samples * (double)(d->opt.max_corrections + 1);
	const size_t cap = c->max_samples ? c->max_samples : PRSM_IO_ALLOC_MAX_SAMPLES;
	if (total > (double)cap)
		prsm_problems_add(pr, sp, "too_large", "%zu samples x (1 + %d corrections) = %.0f Monte Carlo samples: at most "
		                  "%zu", d->samples, d->opt.max_corrections, total, cap);
	/* a target counts as met when the yield's Wilson lower end reaches it; with no sample out of
	 * spec that end is n / (n + z^2), so fewer samples can never show the target */
	for (size_t o = 0; o < d->model.m; o++) {
		const double p0 = d->target_yield[o];
		if (!(p0 > 0.0 && p0 < 1.0))
			continue;
		/* a rare-event estimate (the output's yield_method) needs no such count */
		if (c->kind_ok && d->study && d->opt.output[o] < d->study->study.m &&
		    d->study->study.outputs[d->opt.output[o]].yield_method != PRSM_STUDY_YIELD_MC)
			continue;
		const double z2 = PRSM_STATS_Z95 * PRSM_STATS_Z95;
		const double n_min = ceil(z2 * p0 / (1.0 - p0));
		if ((double)d->samples < n_min) {
			char cp[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(cp, sizeof cp, "/constraints", (int)o);
			prsm_problems_add(pr, sp, "too_few", "%zu samples cannot show the target yield of %s (%.10g %%): even "
			                  "with no sample out of spec the lower end of the 95 %% Wilson interval stays below it "
			                  "unless there are at least %.0f samples (several times that to leave room for the ones "
			                  "that fail)", d->samples, cp, 100.0 * p0, n_min);
			break;
		}
	}
	return 0;
}

/* An analytic stack's linear model is the document's (a study's: the run's, src/app). */
int prsm_io_step_alloc_model(prsm_io_at *at, prsm_problems *pr)
{
	prsm_io_allocation *d = at->root;
	prsm_alloc_model *md = &d->model;
	if (prsm_problems_total(pr) != at->start || d->is_study)
		return 0;
	for (size_t o = 0; o < md->m; o++) {
		const int ao = find_name(d->aout_name, d->n_aout, d->out_name[o]);
		md->nominal[o] = d->aout_nominal[ao];
		for (size_t i = 0; i < md->n; i++)
			md->c[o][i] = d->sens[i][ao];
	}
	for (size_t i = 0; i < md->n; i++)
		md->t_ref[i] = d->ref_given[i];
	return 0;
}

int prsm_io_allocation_read(prsm_io_allocation **out, const cJSON *doc, size_t max_samples,
                            const prsm_io_study_options *study, prsm_problems *warnings, prsm_problems *pr)
{
	*out = NULL;
	prsm_io_allocation *d = calloc(1, sizeof *d);
	if (!d)
		return PRSM_ENOMEM;
	const int start = prsm_problems_total(pr);
	alloc_reading c = {warnings, max_samples, 0, 0, study, 0};
	int rc = 0;
	if (prsm_json_object_value(doc, "", pr))
		rc = PRSM_EINVAL;
	else
		prsm_io_read_ctx(d, &prsm_io_t_allocation, doc, "", &c, pr);
	if (c.out_of_memory)
		rc = PRSM_ENOMEM;
	else if (prsm_problems_total(pr) != start)
		rc = c.study_rc && c.study_rc != PRSM_EINVAL ? c.study_rc : PRSM_EINVAL;
	if (rc)
		prsm_io_allocation_free(d);
	else
		*out = d;
	return rc;
}
