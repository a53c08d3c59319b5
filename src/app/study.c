/*
 * study.c: a study's nominal analysis and the engine's model of its design (see study.h), as
 * the hooks of the study reader (io/study_json.c): the design step asks for the analysis, the
 * model step for the model.
 */
#include "app/study.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

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

int prsm_app_study_options(prsm_io_study_options *o)
{
	prsm_io_study_options_init(o);
	o->analyse_design = analyse_design;
	o->prepare_model = prepare_model;
	return 0;
}

int prsm_app_study_load(prsm_io_study *out, const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_io_study_options o;
	prsm_app_study_options(&o);
	return prsm_io_study_load(out, doc, &o, warnings, problems);
}
