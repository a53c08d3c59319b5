/*
 * study_result.c: the result of a study (schemas/study-result.schema.json) and its samples as
 * CSV (see study_json.h).
 */
#include "io/study_json.h"

#include <math.h>
#include <stdio.h>

#include "io/json_util.h"
#include "util/version.h"

#define PRSM_ENGINE_NAME "prsm-mc 1 (Philox4x64 blocks, GSL Sobol, Saltelli/Jansen)"
#define PRSM_STUDY_MODEL_VERSION "prsm model 2026-11 (docs/model: errors and assembly; kinematics, efficiency, stiffness and life)"


static cJSON *pair(double a, double b)
{
	cJSON *arr = cJSON_CreateArray();
	cJSON_AddItemToArray(arr, isfinite(a) ? cJSON_CreateNumber(a) : cJSON_CreateNull());
	cJSON_AddItemToArray(arr, isfinite(b) ? cJSON_CreateNumber(b) : cJSON_CreateNull());
	return arr;
}

static cJSON *dist_json(const prsm_io_tolerance *t)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "distribution", prsm_dist_name(t->dist.kind));
	/* parameters, except a normal's mean and sd (they are its moments below); a truncated
	 * normal's parent mean and sd are echoed as parent_mean / parent_sd */
	for (int q = 0; q < 4 && prsm_dist_param_name(t->dist.kind, q); q++) {
		const char *pn = prsm_dist_param_name(t->dist.kind, q);
		if (t->dist.kind == PRSM_DIST_NORMAL)
			continue;
		if (t->dist.kind == PRSM_DIST_TRUNCNORMAL && q < 2)
			pn = q == 0 ? "parent_mean" : "parent_sd";
		prsm_json_add_number(o, pn, t->dist.p[q]);
	}
	prsm_json_add_number(o, "mean", prsm_dist_mean(&t->dist));
	prsm_json_add_number(o, "sd", prsm_dist_sd(&t->dist));
	prsm_json_add_number(o, "halfwidth", prsm_dist_halfwidth(&t->dist));
	if (t->shorthand) {
		prsm_json_add_number(o, "tol", t->tol);
		prsm_json_add_number(o, "cpk", t->cpk);
	}
	return o;
}

static const char *const quantile_names[PRSM_STATS_QUANTILES] = {
	"p0_135", "p1", "p5", "p50", "p95", "p99", "p99_865"};

static cJSON *output_json(const prsm_io_study *s, const prsm_study_result *r, size_t o)
{
	const prsm_study *st = &s->study;
	const prsm_study_output_result *q = &r->out[o];
	const prsm_stats_summary *m = &q->summary;
	cJSON *j = cJSON_CreateObject();
	cJSON_AddNumberToObject(j, "n", (double)m->n);
	prsm_json_add_number(j, "mean", m->mean);
	prsm_json_add_number(j, "sd", m->sd);
	prsm_json_add_number(j, "skewness", m->skewness);
	prsm_json_add_number(j, "kurtosis_excess", m->kurtosis_excess);
	prsm_json_add_number(j, "min", m->min);
	prsm_json_add_number(j, "max", m->max);
	cJSON *qs = cJSON_AddObjectToObject(j, "quantiles");
	for (int k = 0; k < PRSM_STATS_QUANTILES; k++)
		prsm_json_add_number(qs, quantile_names[k], m->quantile[k]);
	cJSON *h = cJSON_AddObjectToObject(j, "histogram");
	prsm_json_add_number(h, "lower", m->hist_lower);
	prsm_json_add_number(h, "upper", m->hist_upper);
	cJSON *counts = cJSON_AddArrayToObject(h, "counts");
	for (int k = 0; k < PRSM_STATS_HIST_BINS; k++)
		cJSON_AddItemToArray(counts, cJSON_CreateNumber((double)m->hist_count[k]));
	cJSON *se = cJSON_AddObjectToObject(j, "standard_errors");
	prsm_json_add_number(se, "mean", m->se_mean);
	prsm_json_add_number(se, "sd", m->se_sd);
	prsm_json_add_number(se, "median", m->se_quantile_median);
	if (st->outputs[o].has_spec) {
		const prsm_spec *sp = &st->outputs[o].spec;
		cJSON *spec = cJSON_AddObjectToObject(j, "spec");
		if (sp->has_lower)
			prsm_json_add_number(spec, "lower", sp->lower);
		if (sp->has_upper)
			prsm_json_add_number(spec, "upper", sp->upper);
		cJSON *y = cJSON_AddObjectToObject(j, "yield");
		prsm_json_add_number(y, "fraction", m->yield);
		cJSON_AddItemToObject(y, "interval95", pair(m->yield_low95, m->yield_high95));
		prsm_json_add_number(y, "standard_error", m->se_yield);
		cJSON_AddStringToObject(y, "interval_method", "Wilson score, 95 %");
		cJSON *ppm = cJSON_AddObjectToObject(j, "ppm");
		prsm_json_add_number(ppm, "low", m->ppm_low);
		prsm_json_add_number(ppm, "high", m->ppm_high);
		/* withheld when the sample is not normal: a normal's tail would mislead */
		prsm_json_add_number(ppm, "low_normal_fit", m->normal_rejected ? NAN : m->ppm_low_normal);
		prsm_json_add_number(ppm, "high_normal_fit", m->normal_rejected ? NAN : m->ppm_high_normal);
		prsm_json_add_number(ppm, "low_tail_fit", m->ppm_low_tail);
		prsm_json_add_number(ppm, "high_tail_fit", m->ppm_high_tail);
		cJSON *nf = cJSON_AddObjectToObject(j, "normality");
		prsm_json_add_number(nf, "anderson_darling", m->normal_ad);
		prsm_json_add_number(nf, "p_value", m->normal_ad_p);
		cJSON_AddBoolToObject(nf, "normal_fit_rejected", m->normal_rejected);
		prsm_json_add_number(j, "cp", m->cp);
		prsm_json_add_number(j, "cpk", m->cpk);
		prsm_json_add_number(j, "cpk_standard_error", m->se_cpk);
	}
	if (q->has_stack) {
		cJSON *sk = cJSON_AddObjectToObject(j, "stack");
		prsm_json_add_number(sk, "nominal", q->nominal);
		cJSON_AddItemToObject(sk, "worst_case", pair(q->worst_low, q->worst_high));
		prsm_json_add_number(sk, "rss_halfwidth", q->rss);
		cJSON_AddItemToObject(sk, "rss", pair(q->nominal - q->rss, q->nominal + q->rss));
		cJSON_AddStringToObject(sk, "method",
		                        "one tolerance at a time at its half-width (3 sd for normal, the range for "
		                        "uniform, the 99.865 % quantile for radial magnitudes at their worst of 8 "
		                        "directions), from the centre of every distribution; worst case sums the "
		                        "changes; RSS is 3 sd of the linear stack, each change scaled to its own "
		                        "distribution's sd (change x sd / half-width) and added in quadrature");
	}
	cJSON *sens = cJSON_AddObjectToObject(j, "sensitivity");
	prsm_json_add_number(sens, "src_r2", q->src_r2);
	prsm_json_add_number(sens, "srrc_r2", q->srrc_r2);
	cJSON_AddStringToObject(sens, "contribution_definition",
	                        "src_percent = 100 x the sum of squared standardized regression coefficients over "
	                        "the tolerance's variables: the share of the output variance the linear fit "
	                        "explains through it (the shares sum to 100 R^2 for independent inputs); "
	                        "sobol_first/sobol_total are variance-based indices (Saltelli 2010 / Jansen "
	                        "1999) over all of the tolerance's variables as one group");
	cJSON *arr = cJSON_AddArrayToObject(sens, "tolerances");
	for (size_t g = 0; g < st->n_groups; g++) {
		const prsm_study_contribution *c = &q->by_group[g];
		cJSON *t = cJSON_CreateObject();
		cJSON_AddStringToObject(t, "parameter", st->groups[g].name);
		cJSON_AddNumberToObject(t, "variables", (double)st->groups[g].n_vars);
		if (q->has_src) {
			prsm_json_add_number(t, "src", c->src);
			prsm_json_add_number(t, "srrc", c->srrc);
			prsm_json_add_number(t, "src_percent", c->src_percent);
			prsm_json_add_number(t, "srrc_percent", c->srrc_percent);
		}
		if (q->has_stack)
			prsm_json_add_number(t, "stack_change", c->stack_um);
		if (q->has_sobol) {
			prsm_json_add_number(t, "sobol_first", c->sobol.first);
			prsm_json_add_number(t, "sobol_first_standard_error", c->sobol.first_se);
			cJSON_AddItemToObject(t, "sobol_first_interval95", pair(c->sobol.first_low, c->sobol.first_high));
			prsm_json_add_number(t, "sobol_total", c->sobol.total);
			prsm_json_add_number(t, "sobol_total_standard_error", c->sobol.total_se);
			cJSON_AddItemToObject(t, "sobol_total_interval95", pair(c->sobol.total_low, c->sobol.total_high));
		}
		cJSON_AddItemToArray(arr, t);
	}
	return j;
}

cJSON *prsm_io_study_result_to_json(const prsm_io_study *s, const prsm_study_result *r)
{
	const prsm_study *st = &s->study;
	const prsm_mc_result *run = &r->run;
	cJSON *doc = cJSON_CreateObject();
	if (!doc)
		return NULL;
	if (s->name[0])
		cJSON_AddStringToObject(doc, "name", s->name);
	cJSON_AddStringToObject(doc, "model", s->is_benchmark ? prsm_bench_name(s->bench.kind) : "design");
	cJSON *ver = cJSON_AddObjectToObject(doc, "versions");
	cJSON_AddStringToObject(ver, "prsm", PRSM_VERSION);
	cJSON_AddStringToObject(ver, "engine", PRSM_ENGINE_NAME);
	cJSON_AddStringToObject(ver, "build", prsm_engine_build());
	cJSON_AddStringToObject(ver, "model", PRSM_STUDY_MODEL_VERSION);
	if (!s->is_benchmark)
		cJSON_AddStringToObject(doc, "assembly_mode", s->prsm.mode == PRSM_MODE_EXACT ? "exact" : "linear");
	cJSON_AddNumberToObject(doc, "seed", (double)st->mc.seed);
	cJSON *smp = cJSON_AddObjectToObject(doc, "samples");
	cJSON_AddNumberToObject(smp, "cap", (double)st->mc.samples);
	cJSON_AddNumberToObject(smp, "run", (double)run->n);
	cJSON_AddNumberToObject(smp, "used", (double)run->n_ok);
	cJSON_AddNumberToObject(smp, "failed", (double)run->n_failed);
	cJSON_AddNumberToObject(smp, "edge_contact", (double)run->n_edge);
	cJSON_AddStringToObject(smp, "edge_contact_policy", st->mc.edge == PRSM_EDGE_INCLUDE ? "include" : "exclude");
	cJSON *fl = cJSON_AddArrayToObject(smp, "failed_samples");
	cJSON *el = cJSON_AddArrayToObject(smp, "edge_contact_samples");
	size_t nf = 0, ne = 0;
	for (size_t j = 0; j < run->n; j++) {
		if (run->status[j] == PRSM_SAMPLE_FAILED && nf++ < PRSM_MC_LISTED_FAILURES)
			cJSON_AddItemToArray(fl, cJSON_CreateNumber((double)(run->first_sample + j)));
		if (run->status[j] == PRSM_SAMPLE_EDGE && ne++ < PRSM_MC_LISTED_FAILURES)
			cJSON_AddItemToArray(el, cJSON_CreateNumber((double)(run->first_sample + j)));
	}
	cJSON_AddNumberToObject(smp, "block_size", (double)st->mc.block_size);
	cJSON_AddNumberToObject(smp, "variables", (double)st->d);
	cJSON *sampler = cJSON_AddObjectToObject(doc, "sampler");
	cJSON_AddStringToObject(sampler, "requested", prsm_sampler_name(st->mc.sampler));
	cJSON_AddStringToObject(sampler, "used", prsm_sampler_name(run->sampler));
	cJSON_AddStringToObject(doc, "stop_reason", prsm_stop_reason_name(run->stop));
	cJSON_AddBoolToObject(doc, "converged", run->converged);
	cJSON *tm = cJSON_AddObjectToObject(doc, "timing_s");
	prsm_json_add_number(tm, "monte_carlo", r->elapsed_run_s);
	prsm_json_add_number(tm, "sensitivity", r->elapsed_sensitivity_s);
	cJSON_AddNumberToObject(tm, "threads", st->mc.threads);
	cJSON_AddBoolToObject(doc, "cache_hit", 0);
	cJSON *w = cJSON_AddArrayToObject(doc, "warnings");
	for (int i = 0; i < r->n_warnings; i++)
		cJSON_AddItemToArray(w, cJSON_CreateString(r->warnings[i]));
	cJSON *tols = cJSON_AddArrayToObject(doc, "tolerances");
	for (size_t g = 0; g < s->n_tolerances; g++) {
		const prsm_io_tolerance *t = &s->tolerances[g];
		cJSON *tj = dist_json(t);
		cJSON_AddStringToObject(tj, "parameter", t->parameter);
		cJSON_AddNumberToObject(tj, "variables", (double)st->groups[g].n_vars);
		if (t->per_roller || t->per_start)
			cJSON_AddBoolToObject(tj, "shared", t->shared);
		if (t->radial)
			cJSON_AddStringToObject(tj, "direction", "uniform on [0, 2 pi) rad, drawn independently");
		cJSON_AddItemToArray(tols, tj);
	}
	if (r->has_sobol) {
		cJSON *so = cJSON_AddObjectToObject(doc, "sobol");
		cJSON_AddNumberToObject(so, "base_samples", (double)r->sobol_rows);
		cJSON_AddNumberToObject(so, "base_samples_used", (double)r->sobol_rows_ok);
		cJSON_AddNumberToObject(so, "evaluations", (double)r->sobol_evaluations);
		cJSON_AddStringToObject(so, "sampler", prsm_sampler_name(r->sobol_sampler));
		cJSON_AddNumberToObject(so, "bootstrap", r->sobol_replicates ? 0.0 : (double)st->sens.bootstrap);
		cJSON_AddNumberToObject(so, "replicates", (double)r->sobol_replicates);
		cJSON_AddStringToObject(so, "interval_method",
		                        r->sobol_replicates >= 2
		                            ? "randomised QMC: the indices of the pooled rows, standard errors the sd of "
		                              "the independently scrambled replicates' indices over sqrt(replicates), "
		                              "95 % intervals +- t(0.975, replicates - 1) standard errors"
		                        : r->sobol_replicates ? "none (too few complete randomised-QMC replicates)"
		                                              : "bootstrap of the rows: sd and 2.5 / 97.5 % quantiles "
		                                                "of the resampled indices");
	}
	cJSON *outs = cJSON_AddObjectToObject(doc, "outputs");
	for (size_t o = 0; o < st->m; o++)
		cJSON_AddItemToObject(outs, st->outputs[o].name, output_json(s, r, o));
	return doc;
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
