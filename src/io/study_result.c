/*
 * study_result.c: the result of a study (schemas/study-result.schema.json) and its samples as
 * CSV (see study_json.h).
 */
#include "io/study_json.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/write.h"
#include "prsm_io_writers.h"
#include "prsm_vocab.h"

void prsm_io_whook_output_spec(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_study_result_view *v = w->ctx;
	const prsm_study_output *so = &v->s->study.outputs[v->o];
	prsm_io_write(w, obj, key, &so->spec, &prsm_io_w_spec);
	cJSON *sp = cJSON_GetObjectItemCaseSensitive(obj, key);
	if (sp && so->yield_method != PRSM_STUDY_YIELD_MC)
		prsm_jw_string(w, sp, "yield_method", prsm_study_yield_method_name(so->yield_method));
}

void prsm_io_whook_rss_interval(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_study_output_result *q = at;
	prsm_jw_pair(w, obj, key, q->nominal - q->rss, q->nominal + q->rss);
}

/* The stack figures' caveat (schemas/study-result.schema.json, stack/caveat): the physical range
 * of the built-in outputs that have one (study.schema.json, $defs/output_name: a bound it does
 * not give is NAN, which no value passes), and the linearity of the output (the SRC fit's R²). */
void prsm_io_whook_stack_caveat(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	static const char *const ranges[PRSM_OUT_COUNT] = PRSM_OUTPUT_RANGE;
	static const double lows[PRSM_OUT_COUNT] = PRSM_OUTPUT_LOW, highs[PRSM_OUT_COUNT] = PRSM_OUTPUT_HIGH;
	const prsm_study_output_result *q = at;
	const prsm_io_study_result_view *v = w->ctx;
	const char *name = v->s->study.outputs[v->o].name;
	prsm_output_kind k = PRSM_OUT_BACKLASH;
	const char *range = !v->s->is_benchmark && prsm_output_parse(name, &k) == 0 ? ranges[k] : NULL;
	char msg[600] = "";
	size_t n = 0;
	if (range && (q->worst_low < lows[k] || q->worst_high > highs[k]))
		n += (size_t)snprintf(msg, sizeof msg, "the worst case [%.4g, %.4g] reaches values %s cannot take (it is %s): "
		                      "the one-at-a-time changes do not add up for it", q->worst_low, q->worst_high, name, range);
	if (q->has_src && q->src_r2 < 0.9 && n < sizeof msg)
		snprintf(msg + n, sizeof msg - n, "%s%s is not linear in the tolerances (R² of the linear fit %.2f): sums of "
		         "one-at-a-time changes misstate its range", n ? "; " : "", n ? "it" : name, q->src_r2);
	if (msg[0]) {
		size_t m = strlen(msg);
		snprintf(msg + m, sizeof msg - m, "; use the Monte Carlo quantiles");
		prsm_jw_string(w, obj, key, msg);
	} else {
		prsm_jw_null(w, obj, key);
	}
}

void prsm_io_whook_contributions(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_study *st = &((const prsm_io_study_result_view *)w->ctx)->s->study;
	cJSON *arr = prsm_jw_array(w, obj, key);
	for (size_t g = 0; arr && g < st->n_groups; g++) {
		cJSON *t = prsm_jw_object(w, arr, NULL);
		prsm_jw_string(w, t, "parameter", st->groups[g].name);
		prsm_jw_number(w, t, "variables", (double)st->groups[g].n_vars);
		prsm_io_write_fields(w, t, at, &prsm_io_w_contribution, g);
	}
}

void prsm_io_whook_rare_stop(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_jw_string(w, obj, key, prsm_rare_stop_name(((const prsm_study_rare_side *)at)->stop));
}

/* A rare-event side's FORM design point (schemas/study-result.schema.json, $defs/rare_side):
 * nothing when FORM found none. */
void prsm_io_whook_rare_design_point(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_study_rare_side *sd = at;
	if (!sd->has_design_point || !sd->x_star)
		return;
	const prsm_study *st = &((const prsm_io_study_result_view *)w->ctx)->s->study;
	cJSON *dp = prsm_jw_object(w, obj, key);
	prsm_jw_number(w, dp, "reliability_index", sd->form_beta);
	cJSON *tol = prsm_jw_array(w, dp, "tolerances");
	for (size_t g = 0; tol && g < st->n_groups; g++) {
		cJSON *t = prsm_jw_object(w, tol, NULL);
		prsm_jw_string(w, t, "parameter", st->groups[g].name);
		prsm_jw_number(w, t, "importance_percent", 100.0 * sd->importance[g]);
	}
	cJSON *vars = prsm_jw_array(w, dp, "variables");
	for (size_t v = 0; vars && v < st->d; v++) {
		cJSON *t = prsm_jw_object(w, vars, NULL);
		prsm_jw_string(w, t, "name", st->info[v].name);
		prsm_jw_number(w, t, "value", sd->x_star[v]);
	}
}

/* The first PRSM_MC_LISTED_FAILURES samples of a status. */
static void samples(prsm_jw *w, cJSON *obj, const char *key, const prsm_mc_result *run, int status)
{
	cJSON *arr = prsm_jw_array(w, obj, key);
	size_t n = 0;
	for (size_t j = 0; arr && j < run->n; j++)
		if (run->status[j] == status && n++ < PRSM_MC_LISTED_FAILURES)
			prsm_jw_number(w, arr, NULL, (double)(run->first_sample + j));
}

void prsm_io_whook_failed_samples(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	samples(w, obj, key, &((const prsm_io_study_result_view *)at)->r->run, PRSM_SAMPLE_FAILED);
}

void prsm_io_whook_edge_contact_samples(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	samples(w, obj, key, &((const prsm_io_study_result_view *)at)->r->run, PRSM_SAMPLE_EDGE);
}

/* Each tolerance as drawn: its distribution's parameters, except a normal's mean and sd (they
 * are its moments); a truncated normal's parent mean and sd are echoed as parent_mean and
 * parent_sd. */
void prsm_io_whook_tolerances(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_study *s = ((const prsm_io_study_result_view *)at)->s;
	cJSON *arr = prsm_jw_array(w, obj, key);
	for (size_t g = 0; arr && g < s->n_tolerances; g++) {
		const prsm_io_tolerance *t = &s->tolerances[g];
		cJSON *o = prsm_jw_object(w, arr, NULL);
		prsm_jw_string(w, o, "distribution", prsm_dist_name(t->dist.kind));
		for (int q = 0; q < 4 && prsm_dist_param_name(t->dist.kind, q); q++) {
			const char *pn = prsm_dist_param_name(t->dist.kind, q);
			if (t->dist.kind == PRSM_DIST_NORMAL)
				continue;
			if (t->dist.kind == PRSM_DIST_TRUNCNORMAL && q < 2)
				pn = q == 0 ? "parent_mean" : "parent_sd";
			prsm_jw_number(w, o, pn, t->dist.p[q]);
		}
		prsm_jw_number(w, o, "mean", prsm_dist_mean(&t->dist));
		prsm_jw_number(w, o, "sd", prsm_dist_sd(&t->dist));
		prsm_jw_number(w, o, "halfwidth", prsm_dist_halfwidth(&t->dist));
		if (t->shorthand) {
			prsm_jw_number(w, o, "tol", t->tol);
			prsm_jw_number(w, o, "cpk", t->cpk);
		}
		prsm_jw_string(w, o, "parameter", t->parameter);
		prsm_jw_number(w, o, "variables", (double)s->study.groups[g].n_vars);
		if (t->per_roller || t->per_start)
			prsm_jw_bool(w, o, "shared", t->shared);
		if (t->radial)
			prsm_jw_string(w, o, "direction", "uniform on [0, 2 pi) rad, drawn independently");
	}
}

void prsm_io_whook_outputs(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	prsm_io_study_result_view *v = w->ctx;
	cJSON *outs = prsm_jw_object(w, obj, key);
	for (v->o = 0; outs && v->o < v->s->study.m; v->o++)
		prsm_io_write(w, outs, v->s->study.outputs[v->o].name, &v->r->out[v->o], &prsm_io_w_output);
}

/* A probability's half interval width (schemas/study-result.schema.json, $defs/probability). */
void prsm_io_whook_half_width(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_study_probability *p = at;
	prsm_jw_number(w, obj, key, 0.5 * (p->high95 - p->low95));
}

cJSON *prsm_io_study_result_to_json(const prsm_io_study *s, const prsm_study_result *r)
{
	prsm_io_study_result_view v = {
		.s = s, .r = r, .model = s->is_benchmark ? prsm_bench_name(s->bench.kind) : "design",
		.bootstrap = r->sobol_replicates ? 0 : s->study.sens.bootstrap,
		.sobol_method = r->sobol_replicates >= 2 ? 2 : r->sobol_replicates > 0,
		.has_dynamics = s->has_dynamics && r->dynamics.present,
		.dyn_load_N = isnan(s->dynamics.vib.axial_load_N) ? s->dynamics.dyn.load.value : s->dynamics.vib.axial_load_N,
	};
	prsm_jw w = {0, &v};
	cJSON *doc = prsm_jw_root(&w);
	prsm_io_write_fields(&w, doc, &v, &prsm_io_w_study_result, 0);
	return prsm_jw_done(&w, doc);
}

int prsm_io_study_write_csv(FILE *f, const prsm_io_study *s, const prsm_study_result *r)
{
	static const char *const status_names[] = {"ok", "failed", "edge_contact", "unrun"};
	const prsm_study *st = &s->study;
	const prsm_mc_result *run = &r->run;
	fprintf(f, "sample,status");
	for (size_t i = 0; i < st->d; i++)
		fprintf(f, ",%s", st->info[i].name);
	for (size_t o = 0; o < st->m; o++)
		fprintf(f, ",%s", st->outputs[o].name);
	fputc('\n', f);
	for (size_t j = 0; j < run->n; j++) {
		fprintf(f, "%zu,%s", run->first_sample + j, status_names[run->status[j] & 3]);
		for (size_t i = 0; i < st->d; i++)
			fprintf(f, ",%.17g", run->x[j * st->d + i]);
		for (size_t o = 0; o < st->m; o++) {
			double v = run->y[j * st->m + o];
			if (isfinite(v))
				fprintf(f, ",%.17g", v);
			else
				fputc(',', f);
		}
		fputc('\n', f);
	}
	return ferror(f) ? PRSM_EIO : 0;
}
