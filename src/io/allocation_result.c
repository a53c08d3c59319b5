/*
 * allocation_result.c: the allocation result (schemas/allocation-result.schema.json) of a run
 * (src/app/allocate.c) by its generated table: the view it reads and the hooks; see
 * allocation_json.h.
 */
#include "io/allocation_json.h"

#include <assert.h>
#include <math.h>

#include "io/write.h"
#include "prsm_io_writers.h"

/* A tolerance's sensitivities, by output (at: the first output's of the tolerance). */
void prsm_io_whook_sensitivities(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_allocation *d = ((const prsm_io_allocation_result_view *)w->ctx)->d;
	const double *c = at;
	cJSON *sens = prsm_jw_object(w, obj, key);
	for (size_t o = 0; o < d->model.m; o++)
		prsm_jw_number(w, sens, d->out_name[o], c[o * PRSM_ALLOC_MAX_TOLERANCES]);
}

void prsm_io_whook_correction_steps(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_allocation_result_view *v = at;
	const prsm_io_allocation *d = v->d;
	cJSON *steps = prsm_jw_array(w, obj, key);
	for (int k = 0; steps && k < v->r->n_steps; k++) {
		const prsm_alloc_step *st = &v->r->steps[k];
		cJSON *s = prsm_jw_object(w, steps, NULL);
		prsm_jw_number(w, s, "scale", st->scale);
		prsm_jw_number(w, s, "total_cost", st->sol.total_cost);
		cJSON *hw = prsm_jw_array(w, s, "half_widths");
		for (size_t i = 0; i < d->model.n; i++)
			prsm_jw_number(w, hw, NULL, st->sol.t[i]);
		cJSON *ys = prsm_jw_array(w, s, "yields");
		for (size_t o = 0; o < d->model.m; o++)
			if (st->has_mc && d->has_spec[o])
				prsm_io_write_fields(w, prsm_jw_object(w, ys, NULL), st, &prsm_io_w_mc_yield, o);
			else
				prsm_jw_null(w, ys, NULL);
		prsm_jw_bool(w, s, "meets_target", st->meets);
		prsm_jw_bool(w, s, "reported", k == v->r->best);
	}
}

cJSON *prsm_io_allocation_result_json(const prsm_io_allocation *d, const prsm_alloc_mc_result *r,
                                      int cancelled)
{
	const prsm_alloc_model *md = &d->model;
	assert(r->best >= 0 && r->best < r->n_steps);
	const prsm_alloc_step *best = &r->steps[r->best];
	prsm_io_allocation_result_view v = {
		.d = d, .r = r, .best = best, .first = &r->steps[0], .mc = d->is_study ? &d->study->study.mc : NULL,
		.cancelled = cancelled, .max_corrections = d->is_study && d->opt.verify ? d->opt.max_corrections : 0,
	};
	for (int k = 0; k < r->n_steps; k++)
		v.evaluations += r->steps[k].sol.evaluations;
	for (size_t o = 0; o < md->m; o++) {
		v.kept_sd[o] = sqrt(md->fixed_var[o]);
		v.lin_yield[o] = d->has_spec[o] ? r->steps[0].predicted_yield[o] : NAN;
		v.mc_shown[o] = best->has_mc && d->has_spec[o];
		v.meets[o] = md->has_target[o] ? (best->has_mc ? best->mc_meets[o]
		                                               : best->predicted_yield[o] >= d->target_yield[o] - 1e-12)
		                               : best->sol.stack[o] <= best->limit[o] * (1.0 + 1e-9); /* a given
		                                 assembly tolerance: the linear stack within it */
	}
	prsm_jw w = {0, &v};
	cJSON *doc = prsm_jw_root(&w);
	prsm_io_write_fields(&w, doc, &v, &prsm_io_w_allocation_result, 0);
	return prsm_jw_done(&w, doc);
}
