/*
 * stages_json.c: the multi-stage document and its result (docs/model/kinematics-efficiency-stiffness-life.md);
 * the analysis of the chain is app/analyze.c's. The document is read by the table generated from
 * schemas/multistage-design.schema.json; here are its step (the stages, each a design at the
 * common operating point) and a hook (the coupling radii, one per coupling).
 */
#include "io/stages_json.h"

#include <string.h>

#include "io/analysis_json.h"
#include "io/design_json.h"
#include "io/doc.h"
#include "io/json_util.h"
#include "prsm_io_tables.h"
#include "prsm_io_writers.h"
#include "model/geometry.h"

/* What the steps share while a document is read. */
typedef struct {
	prsm_problems *warnings; /* the stages' rule warnings */
	int rc;                  /* the first stage's return code that is not 0 */
} ms_reading;

int prsm_io_is_multistage(const cJSON *doc)
{
	return cJSON_IsObject(doc) && cJSON_GetObjectItemCaseSensitive(doc, "stages") != NULL;
}

/* The stages at the common operating point, and the couplings' defaults (stages_json.h). A
 * `stages` that is no array of 1 to PRSM_STAGES_MAX stops the reading. */
int prsm_io_step_ms_stages(prsm_io_at *at, prsm_problems *problems)
{
	prsm_io_multistage *out = at->root;
	ms_reading *c = at->ctx;
	const cJSON *stages = cJSON_GetObjectItemCaseSensitive(at->obj, "stages");
	const int K = cJSON_GetArraySize(stages);
	if (!cJSON_IsArray(stages) || K < 1 || K > PRSM_STAGES_MAX) {
		prsm_problems_add(problems, "/stages", cJSON_IsArray(stages) ? "size" : "type",
		                  "must be an array of 1 to %d stage designs", PRSM_STAGES_MAX);
		return 1;
	}
	out->stages = K;
	/* the common operating point, then each stage */
	prsm_design op;
	prsm_design_init(&op);
	prsm_io_operating_point_from_json(&op, at->obj, "", problems);
	int i = 0;
	char sp[PRSM_JSON_POINTER_MAX], ptr[2 * PRSM_JSON_POINTER_MAX];
	for (const cJSON *st = stages->child; st; st = st->next, i++) {
		prsm_json_pointer_append_index(sp, sizeof sp, "/stages", i);
		if (cJSON_IsObject(st) && cJSON_GetObjectItemCaseSensitive(st, "operating_point")) {
			prsm_json_pointer_append(ptr, sizeof ptr, sp, "operating_point");
			prsm_problems_add(problems, ptr, "stage_operating_point",
			                  "give the operating point once, at the top level: the load acts on the "
			                  "last nut and every screw turns at the same speed");
		}
		int src = prsm_io_design_load(&out->design[i], NULL, c->warnings, st, sp, problems);
		if (src && !c->rc)
			c->rc = src;
		out->design[i].axial_load_N = op.axial_load_N;
		out->design[i].screw_speed_rad_s = op.screw_speed_rad_s;
	}
	/* the couplings' defaults (stages_json.h) */
	prsm_chain_input *in = &out->chain_input;
	in->stages = K;
	in->axial_load_N = op.axial_load_N;
	in->screw_speed_rad_s = op.screw_speed_rad_s;
	for (int k = 0; k < K; k++) {
		out->spline_radius_default[k] = out->thrust_radius_default[k] = k > 0;
		in->lead_mm[k] = prsm_design_lead_mm(&out->design[k]);
		if (k > 0) {
			in->spline_radius_mm[k] = out->design[k - 1].screw_radius_mm;
			in->thrust_radius_mm[k] = 0.5 * (out->design[k - 1].nut_radius_mm + out->design[k].screw_radius_mm);
		}
	}
	return 0;
}

/* An optional array of K-1 radii (one per coupling, stage 2 .. K) into r[1..K-1]. */
static void read_radii(double *r, int *is_default, const cJSON *c, const char *cp, const char *key,
                       int K, prsm_problems *problems)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(c, key);
	char ap[PRSM_JSON_POINTER_MAX], ip[PRSM_JSON_POINTER_MAX];
	if (arr == NULL)
		return;
	prsm_json_pointer_append(ap, sizeof ap, cp, key);
	if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) != K - 1) {
		prsm_problems_add(problems, ap, cJSON_IsArray(arr) ? "size" : "type",
		                  "must be an array of %d radii in mm, one per coupling (stage 2 to %d)", K - 1, K);
		return;
	}
	int i = 1;
	for (const cJSON *it = arr->child; it; it = it->next, i++) {
		prsm_json_pointer_append_index(ip, sizeof ip, ap, i - 1);
		if (prsm_json_number_value(&r[i], it, ip, (prsm_json_range){0.0, 1e6, 1, 0}, problems) == 0)
			is_default[i] = 0;
	}
}

/* "couplings": once its frictions are read, the radii. */
void prsm_io_hook_ms_radii(void *base, const cJSON *c, const char *cp, prsm_problems *problems)
{
	prsm_io_multistage *m = base;
	read_radii(m->chain_input.spline_radius_mm, m->spline_radius_default, c, cp, "spline_radius_mm", m->stages,
	           problems);
	read_radii(m->chain_input.thrust_radius_mm, m->thrust_radius_default, c, cp, "thrust_bearing_radius_mm",
	           m->stages, problems);
}

int prsm_io_multistage_read(prsm_io_multistage *out, const cJSON *doc, prsm_problems *warnings,
                            prsm_problems *problems)
{
	memset(out, 0, sizeof *out);
	if (prsm_json_object_value(doc, "", problems) != 0)
		return PRSM_EINVAL;
	ms_reading c = {warnings, 0};
	prsm_io_read_ctx(out, &prsm_io_t_multistage, doc, "", &c, problems);
	if (c.rc || problems->count || problems->dropped)
		return c.rc ? c.rc : PRSM_EINVAL;
	return 0;
}

void prsm_io_whook_stages(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	const prsm_io_multistage_view *v = at;
	prsm_problems none;
	prsm_problems_init(&none);
	cJSON *arr = prsm_jw_array(w, obj, key);
	for (int k = 0; arr && k < v->m->stages; k++)
		prsm_io_analysis_write(w, prsm_jw_object(w, arr, NULL), &v->m->analysis[k], &v->m->design[k], &v->perf[k], &none);
}

cJSON *prsm_io_multistage_to_json(const prsm_io_multistage *m, const prsm_performance *perf,
                                  const prsm_problems *warnings)
{
	prsm_io_multistage_view v = {m, perf, warnings, {0}};
	for (int k = 0; k < PRSM_STAGES_MAX; k++)
		v.stage[k] = k + 1;
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	prsm_io_write_fields(&w, root, &v, &prsm_io_w_multistage, 0);
	return prsm_jw_done(&w, root);
}
