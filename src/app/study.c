/*
 * study.c: a study's nominal analysis, the engine's model of its design and the range checks
 * of what the engine will compute (see study.h), as the hooks of the study reader
 * (io/study_json.c): the design step asks for the analysis, the model step for the model, the
 * loaded document for the checks.
 */
#include "app/study.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/errors_json.h"
#include "io/json_util.h"
#include "mc/prsm_model.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/performance.h"
#include "util/error.h"

/* prsm_io_study_options.analyse_design: the nominal analysis and the assembly built on it. */
static int analyse_design(prsm_io_study *s, prsm_problems *warnings, prsm_problems *pr, void *ctx)
{
	(void)ctx;
	prsm_error err = PRSM_ERROR_INIT;
	int arc = prsm_analysis_nominal(&s->analysis, &s->design, warnings, &err);
	if (arc == 0)
		arc = prsm_assembly_init(&s->assembly, &s->design, &s->analysis, &err);
	if (arc) {
		/* only the contact solver can tell that the contacts lie on their flanks */
		char ptr[PRSM_JSON_POINTER_MAX + 8];
		snprintf(ptr, sizeof ptr, "/design%s", err.pointer);
		prsm_problems_add(pr, ptr, arc == PRSM_EEDGE ? "edge_contact" : arc == PRSM_EINVAL ? "too_large" : "no_contact",
		                  "%s", err.message);
		return arc;
	}
	return 0;
}

/* What the outputs at the nominal operating point need from the nut unit's performance
 * (prsm_performance, docs/model/kinematics-efficiency-stiffness-life.md), computed once: for nut_unit_stiffness_N_per_um the
 * compliance beyond the contacts, 1/k_unit - 1/k_contacts of the nominal design (mm/N, k_unit the
 * load distribution's stiffness, k_contacts the assembly's with nominal gaps); for
 * efficiency_with_losses the distribution's normal loads of one roller's contacts. Returns 0, or
 * 1 with a problem at the first output that needed them. */
static int nominal_unit_terms(prsm_io_study *s, prsm_problems *pr)
{
	int first = -1, unit = 0, losses = 0;
	for (size_t o = 0; o < s->study.m; o++) {
		int u = s->prsm.outputs[o] == PRSM_OUT_UNIT_STIFFNESS || prsm_output_is_dynamic(s->prsm.outputs[o]),
		    l = s->prsm.outputs[o] == PRSM_OUT_EFFICIENCY_LOSSES;
		if ((u || l) && first < 0)
			first = (int)o;
		unit |= u;
		losses |= l;
	}
	if (first < 0)
		return 0;
	char ip[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append_index(ip, sizeof ip, "/outputs", first);
	prsm_performance perf;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_performance_compute(&perf, &s->design, &s->analysis, &err)) {
		prsm_problems_add(pr, ip, "computation", "the nominal nut unit at the operating load: %s", err.message);
		return 1;
	}
	int bad = 0;
	if (unit) {
		double k_unit = perf.stiffness_N_per_um * 1e3;            /* N/mm */
		double k_contacts = s->assembly.nominal_stiffness_N_per_mm; /* N/mm */
		if (!(k_unit > 0.0) || !(k_contacts > 0.0)) {
			prsm_problems_add(pr, ip, "computation", "the nominal nut unit has no stiffness at the operating load");
			bad = 1;
		}
		/* the thread, core and body springs only add compliance; a contact model stiffer in
		 * the assembly than in the load distribution would make this negative: contacts only */
		s->prsm.unit_rest_compliance_mm_per_N = fmax(0.0, 1.0 / k_unit - 1.0 / k_contacts);
	}
	if (losses && !bad) {
		int nt = perf.threads;
		if (nt < 1 || nt > PRSM_IO_STUDY_MAX_LOSS_THREADS) {
			prsm_problems_add(pr, ip, "computation", "the nominal load distribution has no contact loads");
			bad = 1;
		} else {
			s->loss_threads = nt;
			memcpy(s->loss_loads_N[0], perf.thread_normal_screw_N, (size_t)nt * sizeof(double));
			memcpy(s->loss_loads_N[1], perf.thread_normal_nut_N, (size_t)nt * sizeof(double));
			s->prsm.loss_screw_loads_N = s->loss_loads_N[0];
			s->prsm.loss_nut_loads_N = s->loss_loads_N[1];
		}
	}
	prsm_performance_free(&perf);
	return bad;
}

/* prsm_io_study_options.prepare_model: the dynamic model of the nominal design (dynamic
 * outputs), the nominal nut unit's terms, then the engine's model of the study. */
static void prepare_model(prsm_io_study *out, prsm_problems *pr, void *ctx)
{
	(void)ctx;
	prsm_study *st = &out->study;
	prsm_mc_prsm *p = &out->prsm;
	if (out->has_dynamics) {
		prsm_mc_dyn *d = &out->dynamics;
		d->design = &out->design;
		d->analysis = &out->analysis;
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_mc_dyn_prepare(d, &out->assembly, p->angles_per_revolution, d->window_rev, &err)) {
			prsm_problems_add(pr, err.pointer[0] ? err.pointer : "/dynamics", "computation",
			                  "the dynamic model of the nominal design: %s", err.message);
			return;
		}
		p->dyn = d;
	}
	if (nominal_unit_terms(out, pr) == 0)
		prsm_prsm_mc_model(&st->model, p);
}

/* Magnitudes a study's inputs and outputs may reach (at the 0.135 / 99.865 % quantiles): beyond
 * it their squares, and so the moments, overflow double arithmetic. */
#define RANGE_MAX 1e150
/* Linear assembly mode was checked against exact mode to about 1 % up to errors of this size
 * (docs/model/errors-and-assembly.md), um. */
#define LINEAR_VALID_UM 50.0

/* A document the engine cannot compute is refused here, at the field that makes it so, not at
 * run time without a cause (issue 19, items 4 and 6): every distribution's 0.135 and 99.865 %
 * quantiles within +-RANGE_MAX; a benchmark's outputs too, at the centre and with each input at
 * either quantile in turn; a length error no larger than the thread pitch (an error that size
 * is no manufacturing error of a meshing thread), and in linear assembly mode a warning beyond
 * the range where that mode was checked. prsm_io_study_options.check_study, once the document
 * reads without a problem. */
static void check_ranges(prsm_io_study *out, prsm_problems *warnings, prsm_problems *pr, void *ctx)
{
	(void)ctx;
	prsm_study *st = &out->study;
	const double u[2] = {0.00135, 0.99865};
	const int before = prsm_problems_total(pr);
	for (size_t g = 0; g < out->n_tolerances; g++) {
		const prsm_io_tolerance *t = &out->tolerances[g];
		char tp[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(tp, sizeof tp, "/tolerances", (int)g);
		double q[2];
		for (int k = 0; k < 2; k++)
			q[k] = prsm_dist_quantile(&t->dist, u[k]);
		if (!(fabs(q[0]) <= RANGE_MAX && fabs(q[1]) <= RANGE_MAX)) {
			prsm_problems_add(pr, tp, "range", "the distribution spans %.6g to %.6g (0.135 to 99.865 %%): "
			                  "beyond +-%g its squares overflow double arithmetic", q[0], q[1], RANGE_MAX);
			continue;
		}
		if (out->is_benchmark)
			continue;
		const prsm_mc_binding *b = &out->bindings[st->groups[g].first_var]; /* its first variable's */
		if (b->part == PRSM_PART_DYNAMICS) {
			/* absolute values: a damping ratio in (0, 1), a mesh error >= 0, a backlash > 0 */
			const int damping = b->offset == PRSM_DYN_TOL_DAMPING, error = b->offset == PRSM_DYN_TOL_MESH_ERROR;
			const int bad = damping ? !(q[0] > 0.0 && q[1] < 1.0) : error ? !(q[0] >= 0.0) : !(q[0] > 0.0);
			if (bad)
				prsm_problems_add(pr, tp, "range", "%s spans %.6g to %.6g (0.135 to 99.865 %%): it must be %s there",
				                  t->parameter, q[0], q[1],
				                  damping ? "in (0, 1)" : error ? ">= 0 um" : "> 0 um");
			continue;
		}
		const char *key = strchr(t->parameter, '.');
		const char *unit = key ? prsm_io_error_unit_of(key + 1) : "";
		if (strcmp(unit, "um") != 0 && strcmp(unit, "um_per_300mm") != 0)
			continue;
		const double big = fmax(fabs(q[0]), fabs(q[1])), pitch_um = 1e3 * out->design.pitch_mm;
		if (big > pitch_um)
			prsm_problems_add(pr, tp, "range", "%s reaches %.6g um (99.865 %% quantile), more than the "
			                  "thread pitch (%.6g um): not a manufacturing error of a meshing thread",
			                  t->parameter, big, pitch_um);
		else if (big > LINEAR_VALID_UM && out->assembly_options.mode == PRSM_MODE_LINEAR && warnings)
			prsm_problems_add(warnings, tp, "linear_range", "%s reaches %.3g um: linear assembly mode "
			                  "was checked against exact mode (about 1 %%) only up to %g um errors; use "
			                  "\"assembly\": {\"mode\": \"exact\"} for errors this large",
			                  t->parameter, big, LINEAR_VALID_UM);
	}
	if (!out->is_benchmark || prsm_problems_total(pr) > before)
		return;
	/* a benchmark's outputs at the centre and one input at a time at its quantiles */
	const prsm_mc_model *m = &st->model;
	double x[PRSM_MC_MAX_VARIABLES], y[PRSM_MC_MAX_OUTPUTS];
	unsigned flags;
	void *ws = NULL;
	if (m->workspace_alloc && m->workspace_alloc(&ws, m->ctx))
		return;
	for (size_t i = 0; i < st->d; i++)
		x[i] = prsm_dist_center(&st->vars[i].dist);
	/* the centres first (j = 0, i = d), then each input at either quantile; one problem is enough */
	int stop = 0;
	for (size_t j = 0; j <= st->d && !stop; j++) {
		const size_t i = j == 0 ? st->d : j - 1;
		for (int k = 0; k < (i < st->d ? 2 : 1); k++) {
			const double keep = i < st->d ? x[i] : 0.0;
			if (i < st->d)
				x[i] = prsm_dist_quantile(&st->vars[i].dist, u[k]);
			int bad = m->eval(y, &flags, m->ctx, ws, x) != 0;
			size_t o = 0;
			while (o < st->m && fabs(y[o]) <= RANGE_MAX)
				o++;
			bad |= o < st->m;
			if (bad && out->bench.kind == PRSM_BENCH_EXPRESSION) {
				/* an expression model: the expression at fault, and where; not finite there is a
				 * warning (those samples fail, and the failure policy applies), beyond +-RANGE_MAX
				 * a problem (the moments would overflow) */
				const prsm_expr_model *em = &out->expr;
				const size_t e = em->output_expr[o < st->m ? o : 0];
				const int finite = o < st->m ? isfinite(y[o]) : 0;
				prsm_problems *to = finite ? pr : warnings;
				char ep[PRSM_JSON_POINTER_MAX], where[160];
				if (out->expr_single)
					snprintf(ep, sizeof ep, "/model/expression");
				else
					prsm_json_pointer_append(ep, sizeof ep, "/model/expressions", em->expr_names[e]);
				if (i < st->d)
					snprintf(where, sizeof where, "with %s at its %s quantile %.6g", st->info[i].name,
					         k ? "99.865 %" : "0.135 %", x[i]);
				else
					snprintf(where, sizeof where, "at the distributions' centres");
				if (to && finite)
					prsm_problems_add(to, ep, "range", "%s reaches %.6g %s: beyond +-%g its moments overflow double "
					                  "arithmetic", em->expr_names[e], y[o], where, RANGE_MAX);
				else if (to)
					prsm_problems_add(to, ep, "not_finite", "%s is not finite %s: such samples fail (the failure "
					                  "policy applies)", em->expr_names[e], where);
				stop = 1;
				break;
			}
			if (bad) {
				if (i < st->d)
					prsm_problems_add(pr, "/model", "range", "the model's output leaves +-%g (or is not "
					                  "finite) with %s at its %s quantile %.6g: its moments would overflow "
					                  "double arithmetic; use smaller coefficients or tolerances",
					                  RANGE_MAX, st->info[i].name, k ? "99.865 %" : "0.135 %", x[i]);
				else
					prsm_problems_add(pr, "/model", "range", "the model's output leaves +-%g (or is not "
					                  "finite) at the distributions' centres", RANGE_MAX);
				stop = 1;
				break;
			}
			if (i < st->d)
				x[i] = keep;
		}
	}
	if (ws && m->workspace_free)
		m->workspace_free(ws);
}

int prsm_app_study_options(prsm_io_study_options *o)
{
	prsm_io_study_options_init(o);
	o->analyse_design = analyse_design;
	o->prepare_model = prepare_model;
	o->check_study = check_ranges;
	return 0;
}

int prsm_app_study_load(prsm_io_study *out, const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_io_study_options o;
	prsm_app_study_options(&o);
	return prsm_io_study_load(out, doc, &o, warnings, problems);
}
