/*
 * analyze.c: the analyze request's analyses (see analyze.h; docs/model/geometry-and-meshing.md
 * to §6): what io/analyze_request.c and io/stages_json.c read, analysed before
 * io/analyze_request.c writes it.
 */
#include "app/analyze.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/design_json.h"
#include "io/json_util.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/nominal.h"
#include "model/performance.h"
#include "model/stages.h"
#include "util/error.h"

/* ---- a chain of stages (docs/model/kinematics-efficiency-stiffness-life.md) ------------------ */

/* Input torque of stage k at axial load F: its analysis at that load (docs/model/kinematics-efficiency-stiffness-life.md). */
static double stage_torque(void *ctx, int k, double load_N)
{
	prsm_io_multistage *m = ctx;
	prsm_design d = m->design[k];
	d.axial_load_N = load_N;
	return prsm_performance_input_torque(&d, &m->analysis[k]);
}

int prsm_app_multistage_load(prsm_io_multistage *out, const cJSON *doc, prsm_problems *warnings,
                             prsm_problems *problems)
{
	int rc = prsm_io_multistage_read(out, doc, warnings, problems);
	if (rc)
		return rc;
	const int K = out->stages;
	char sp[PRSM_JSON_POINTER_MAX], ptr[2 * PRSM_JSON_POINTER_MAX];
	/* each stage must work alone (contacts on the flanks) before the chain asks its torques */
	prsm_error err = PRSM_ERROR_INIT;
	for (int k = 0; k < K; k++) {
		rc = prsm_analysis_nominal(&out->analysis[k], &out->design[k], warnings, &err);
		if (rc) {
			prsm_json_pointer_append_index(sp, sizeof sp, "/stages", k);
			snprintf(ptr, sizeof ptr, "%s%s", sp, err.pointer);
			prsm_problems_add(problems, ptr, rc == PRSM_EEDGE ? "edge_contact" : "no_contact", "%s",
			                  err.message);
			return rc;
		}
	}
	rc = prsm_stages_chain(&out->chain, &out->chain_input, stage_torque, out, &err);
	if (rc) {
		prsm_problems_add(problems, err.pointer, "chain", "%s", err.message);
		return rc;
	}
	/* report every stage at the load it carries */
	for (int k = 0; k < K; k++) {
		out->design[k].axial_load_N = out->chain.stage[k].load_N;
		if ((rc = prsm_analysis_nominal(&out->analysis[k], &out->design[k], warnings, &err)))
			return rc;
	}
	return 0;
}

/* ---- one design ------------------------------------------------------------------------------- */

/* The same diameter and lead with starts 3 to 6: each analysed on its own (MODEL.md §1, §6).
 * design is the document's design with its `nominal` (already resolved into out->given). No
 * problem or warning of theirs reaches the request's lists: an invalid one says why in its
 * own entry. */
static void nominal_alternatives(prsm_io_nominal_result *out, const cJSON *design)
{
	prsm_problems *scratch = malloc(2 * sizeof *scratch);
	prsm_design *d = malloc(sizeof *d);
	prsm_analysis *a = malloc(sizeof *a);
	prsm_performance *perf = calloc(1, sizeof *perf);
	if (!scratch || !d || !a || !perf)
		goto cleanup;
	out->n_alternatives = 0;
	for (int n = PRSM_NOMINAL_STARTS_MIN; n < PRSM_NOMINAL_STARTS_MIN + PRSM_NOMINAL_ALTERNATIVES; n++) {
		prsm_io_nominal_alternative *alt = &out->alternatives[out->n_alternatives++];
		memset(alt, 0, sizeof *alt);
		prsm_nominal given = out->given;
		given.starts = n;
		prsm_nominal_geometry g;
		prsm_problems_init(&scratch[0]);
		prsm_problems_init(&scratch[1]);
		alt->starts = n;
		if (prsm_nominal_resolve(&g, &given, out->beta_rad, out->clearance_mm, &scratch[0])) {
			snprintf(alt->problem, sizeof alt->problem, "%s", scratch[0].items[0].message);
			continue;
		}
		alt->pitch_mm = g.pitch_mm;
		alt->roller_radius_mm = g.roller_radius_mm;
		alt->rollers = g.rollers;
		alt->engaged_threads = g.engaged_threads;
		cJSON *copy = prsm_io_nominal_expanded(design, &g);
		if (copy == NULL) {
			snprintf(alt->problem, sizeof alt->problem, "out of memory");
			continue;
		}
		prsm_geometry geom;
		prsm_error err = PRSM_ERROR_INIT;
		int rc = prsm_io_design_load(d, &geom, NULL, copy, "", &scratch[0]);
		cJSON_Delete(copy);
		if (rc == 0 && (rc = prsm_analysis_nominal(a, d, &scratch[1], &err)) == 0) {
			prsm_performance_free(perf);
			rc = prsm_performance_compute(perf, d, a, &err);
		}
		if (rc) {
			const char *why = scratch[0].count ? scratch[0].items[0].message : err.message;
			snprintf(alt->problem, sizeof alt->problem, "%.*s", (int)sizeof alt->problem - 1, why);
			continue;
		}
		alt->valid = 1;
		alt->makers_C0a_N = perf->makers.C0a_N;
		alt->makers_C_a_N = perf->makers.C_a_N;
		alt->makers_ratio = perf->makers.C0a_over_C_a;
		alt->C0a_N = perf->C0a_N;
		alt->C_a_N = perf->dynamic.C_a_N;
		alt->truncated = perf->C0a_truncation_limited;
	}
cleanup:
	if (perf)
		prsm_performance_free(perf);
	free(perf);
	free(a);
	free(d);
	free(scratch);
}

/* A failure of the operating-point analysis as a problem at the setting's pointer. */
static int performance_problem(prsm_problems *problems, const char *base, int rc, const prsm_error *err)
{
	char ptr[2 * PRSM_JSON_POINTER_MAX];
	snprintf(ptr, sizeof ptr, "%s%s", base, err->pointer);
	prsm_problems_add(problems, ptr, rc == PRSM_ENOCONVERGE ? "no_convergence" : "invalid_setting",
	                  "%s", err->message);
	return rc;
}

/* A chain (the "stages" form): read and analysed, then its `dynamics` object read (its problems
 * after the chain's, as they always came), then each stage's operating point. */
static int load_multistage(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                           prsm_problems *problems)
{
	rq->multistage = 1;
	rq->ms = calloc(1, sizeof *rq->ms);
	if (rq->ms == NULL)
		return PRSM_ENOMEM;
	int rc = prsm_app_multistage_load(rq->ms, doc, warnings, problems);
	rc = prsm_io_analyze_read_chain_dynamics(rq, doc, rc, problems);
	prsm_error err = PRSM_ERROR_INIT;
	for (int k = 0; rc == 0 && k < rq->ms->stages; k++) {
		rc = prsm_performance_compute(&rq->ms_perf[k], &rq->ms->design[k], &rq->ms->analysis[k], &err);
		if (rc) {
			char base[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append_index(base, sizeof base, "/stages", k);
			return performance_problem(problems, base, rc, &err);
		}
	}
	return rc;
}

/* The contact-ellipse truncation of a side as warnings (model/rating.h, MODEL.md §6 static
 * capacity): at the operating load, and at the pressure-limited C_0a (which it then limits). */
static void truncation_warnings(prsm_problems *warnings, const char *base, const prsm_performance *p,
                                double p_allow_MPa, int nominal)
{
	static const char *const edges[2][4] = {{"screw crest", "screw root", "roller crest", "roller root"},
	                                        {"nut crest", "nut root", "roller crest", "roller root"}};
	const prsm_truncation_check *tc[2] = {&p->truncation_screw, &p->truncation_nut};
	const char *side[2] = {"screw-roller", "nut-roller"};
	char ptr[PRSM_JSON_POINTER_MAX];
	for (int s = 0; s < 2; s++) {
		const prsm_truncation *t = &tc[s]->t;
		const char *edge = edges[s][t->edge];
		if (tc[s]->truncated_operating) {
			snprintf(ptr, sizeof ptr, "%s/operating_point/axial_load_N", base);
			prsm_problems_add(warnings, ptr, "ellipse_truncation",
			                  "at this load the %s contact ellipse (semi-axis %.3g mm along the flank) "
			                  "runs over the %s %.3g mm away: the contact is truncated, its stresses "
			                  "exceed Hertz's", side[s], tc[s]->operating_axis_mm, edge, t->margin_mm);
		}
		if (tc[s]->truncated_at_C0a) {
			/* the pitch sets the flank length: the field the user wrote it with */
			snprintf(ptr, sizeof ptr, "%s%s", base, nominal ? "/nominal/lead_mm" : "/geometry/pitch_mm");
			prsm_problems_add(warnings, ptr, "ellipse_truncation",
			                  "%s contact ellipse reaches the %s (%.3g mm away) at p_max %.0f MPa < "
			                  "p_allow %.0f MPa: truncation limits C_0a to %.4g N (%.4g N at p_allow); "
			                  "a coarser pitch keeps it on the flank", side[s], edge, t->margin_mm,
			                  t->p_limit_MPa, p_allow_MPa, s == 0 ? p->C0a_screw_N : p->C0a_nut_N,
			                  s == 0 ? p->C0a_pressure_screw_N : p->C0a_pressure_nut_N);
		}
	}
}

int prsm_app_analyze_load(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                          prsm_problems *problems)
{
	memset(rq, 0, sizeof *rq);
	if (prsm_io_analyze_wrong_kind(doc, problems))
		return PRSM_EINVAL;
	if (prsm_io_is_multistage(doc))
		return load_multistage(rq, doc, warnings, problems);
	int rc = prsm_io_analyze_read(rq, doc, warnings, problems);
	if (rc)
		return rc;
	/* a catalogue size: the plain design document also lists its alternatives with 3 to 6
	 * starts (they add nothing to the lists, so their place after the reading is free) */
	if (rq->with_nominal)
		nominal_alternatives(&rq->nominal, doc);
	prsm_error err = PRSM_ERROR_INIT;
	rc = prsm_analysis_nominal(&rq->a, &rq->d, warnings, &err);
	if (rc == 0 && rq->with_errors)
		rc = prsm_assembly_init(&rq->as, &rq->d, &rq->a, &err);
	if (rc == 0) {
		rc = prsm_performance_compute(&rq->perf, &rq->d, &rq->a, &err);
		if (rc)
			return performance_problem(problems, rq->with_errors ? "/design" : "", rc, &err);
		if (warnings)
			truncation_warnings(warnings, rq->with_errors ? "/design" : "", &rq->perf,
			                    rq->d.life.p_allow_MPa, rq->with_nominal);
		return 0;
	}
	/* only the contact solver can tell that the contacts lie on their flanks */
	char ptr[PRSM_JSON_POINTER_MAX + 8];
	snprintf(ptr, sizeof ptr, "%s%s", rq->with_errors ? "/design" : "", err.pointer);
	prsm_problems_add(problems, ptr,
	                  rc == PRSM_EEDGE ? "edge_contact" : rc == PRSM_EINVAL ? "too_large" : "no_contact",
	                  "%s", err.message);
	return rc;
}

int prsm_app_analyze_run(prsm_analyze_request *rq)
{
	if (!rq->with_errors)
		return 0;
	int n, m;
	prsm_assembly_record_length(&n, &m, &rq->as, &rq->options);
	rq->ws = calloc(1, sizeof *rq->ws);
	if (rq->ws == NULL)
		return PRSM_ENOMEM;
	rq->ws->te_mm = calloc((size_t)n, sizeof(double));
	rq->ws->spectrum_mm = calloc((size_t)m, sizeof(double));
	if (rq->ws->te_mm == NULL || rq->ws->spectrum_mm == NULL)
		return PRSM_ENOMEM;
	return prsm_assembly_analyse(&rq->report, &rq->as, &rq->errors, &rq->options, rq->ws);
}

double prsm_app_analyze_cost(const prsm_analyze_request *rq)
{
	if (rq->multistage)
		return 0.0; /* the operating-point analysis of each stage: no record */
	return rq->with_errors ? prsm_assembly_cost(&rq->as, &rq->options) : 0.0;
}

int prsm_app_analyze(cJSON **out, const cJSON *doc, prsm_problems *problems)
{
	*out = NULL;
	prsm_analyze_request *rq = calloc(1, sizeof *rq);
	if (rq == NULL)
		return PRSM_ENOMEM;
	prsm_problems warnings;
	prsm_problems_init(&warnings);
	int rc = prsm_app_analyze_load(rq, doc, &warnings, problems);
	if (rc == 0)
		rc = prsm_app_analyze_run(rq);
	if (rc == 0) {
		*out = prsm_io_analyze_to_json(rq, &warnings);
		if (*out == NULL)
			rc = PRSM_ENOMEM;
	}
	prsm_io_analyze_free(rq);
	free(rq);
	return rc;
}
