/*
 * stages_json.c: the multi-stage document and its analysis (docs/model/kinematics-efficiency-stiffness-life.md).
 */
#include "io/stages_json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/analysis_json.h"
#include "io/design_json.h"
#include "io/json_util.h"
#include "model/geometry.h"
#include "model/performance.h"

static const char *const multistage_keys[] = {"name", "description", "stages", "couplings",
                                              "operating_point", "dynamics", NULL};
static const char *const coupling_keys[] = {"spline_friction", "thrust_bearing_friction",
                                            "spline_radius_mm", "thrust_bearing_radius_mm", NULL};

int prsm_io_is_multistage(const cJSON *doc)
{
	return cJSON_IsObject(doc) && cJSON_GetObjectItemCaseSensitive(doc, "stages") != NULL;
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

/* Input torque of stage k at axial load F: its analysis at that load (docs/model/kinematics-efficiency-stiffness-life.md). */
static double stage_torque(void *ctx, int k, double load_N)
{
	prsm_io_multistage *m = ctx;
	prsm_design d = m->design[k];
	d.axial_load_N = load_N;
	return prsm_performance_input_torque(&d, &m->analysis[k]);
}

int prsm_io_multistage_load(prsm_io_multistage *out, const cJSON *doc, prsm_problems *warnings,
                            prsm_problems *problems)
{
	memset(out, 0, sizeof *out);
	if (prsm_json_object_value(doc, "", problems) != 0)
		return PRSM_EINVAL;
	prsm_json_check_keys(doc, "", multistage_keys, problems);
	const char *text;
	prsm_json_get_string(&text, doc, "", "name", PRSM_JSON_OPTIONAL, PRSM_DESIGN_NAME_MAX_CHARS, problems);
	prsm_json_get_string(&text, doc, "", "description", PRSM_JSON_OPTIONAL,
	                     PRSM_DESIGN_DESCRIPTION_MAX_CHARS, problems);
	const cJSON *stages = cJSON_GetObjectItemCaseSensitive(doc, "stages");
	const int K = cJSON_GetArraySize(stages);
	if (!cJSON_IsArray(stages) || K < 1 || K > PRSM_STAGES_MAX) {
		prsm_problems_add(problems, "/stages", cJSON_IsArray(stages) ? "size" : "type",
		                  "must be an array of 1 to %d stage designs", PRSM_STAGES_MAX);
		return PRSM_EINVAL;
	}
	out->stages = K;
	/* the common operating point, then each stage */
	prsm_design op;
	prsm_design_init(&op);
	prsm_io_operating_point_from_json(&op, doc, "", problems);
	int rc = 0, i = 0;
	char sp[PRSM_JSON_POINTER_MAX], ptr[2 * PRSM_JSON_POINTER_MAX];
	for (const cJSON *st = stages->child; st; st = st->next, i++) {
		prsm_json_pointer_append_index(sp, sizeof sp, "/stages", i);
		if (cJSON_IsObject(st) && cJSON_GetObjectItemCaseSensitive(st, "operating_point")) {
			prsm_json_pointer_append(ptr, sizeof ptr, sp, "operating_point");
			prsm_problems_add(problems, ptr, "stage_operating_point",
			                  "give the operating point once, at the top level: the load acts on the "
			                  "last nut and every screw turns at the same speed");
		}
		int src = prsm_io_design_load(&out->design[i], NULL, warnings, st, sp, problems);
		if (src && !rc)
			rc = src;
		out->design[i].axial_load_N = op.axial_load_N;
		out->design[i].screw_speed_rad_s = op.screw_speed_rad_s;
	}
	/* couplings, with the defaults of stages_json.h */
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
	char cp[PRSM_JSON_POINTER_MAX];
	const cJSON *c;
	if (prsm_json_get_section(&c, cp, sizeof cp, doc, "", "couplings", PRSM_JSON_OPTIONAL, coupling_keys,
	                          problems) == PRSM_JSON_PRESENT) {
		prsm_json_get_number(&in->spline_friction, c, cp, "spline_friction", PRSM_JSON_OPTIONAL,
		                     (prsm_json_range){0.0, 1.0, 0, 1}, problems);
		prsm_json_get_number(&in->thrust_bearing_friction, c, cp, "thrust_bearing_friction",
		                     PRSM_JSON_OPTIONAL, (prsm_json_range){0.0, 1.0, 0, 1}, problems);
		read_radii(in->spline_radius_mm, out->spline_radius_default, c, cp, "spline_radius_mm", K, problems);
		read_radii(in->thrust_radius_mm, out->thrust_radius_default, c, cp, "thrust_bearing_radius_mm", K,
		           problems);
	}
	if (rc || problems->count || problems->dropped)
		return rc ? rc : PRSM_EINVAL;

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
	rc = prsm_stages_chain(&out->chain, in, stage_torque, out, &err);
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

#define RPM_PER_RAD_S (60.0 / (2.0 * M_PI))

cJSON *prsm_io_multistage_to_json(const prsm_io_multistage *m, const prsm_performance *perf,
                                  const prsm_problems *warnings)
{
	cJSON *root = cJSON_CreateObject();
	if (root == NULL)
		return NULL;
	const prsm_chain *c = &m->chain;
	const prsm_chain_input *in = &m->chain_input;
	cJSON *ch = cJSON_AddObjectToObject(root, "chain");
	cJSON_AddStringToObject(ch, "model", "nested stages (docs/model/kinematics-efficiency-stiffness-life.md): screws coupled by splines turn at the input speed, nut k pushes screw k+1 through a thrust bearing; spline friction s_k = mu_SS M_k / r_SS and thrust-bearing torque mu_NS B_k r_NS (seed 000); eta = F sum L / (2 pi T_in)");
	cJSON_AddNumberToObject(ch, "stages", c->stages);
	prsm_json_add_number(ch, "axial_load_N", in->axial_load_N);
	prsm_json_add_number(ch, "screw_speed_rpm", in->screw_speed_rad_s * RPM_PER_RAD_S);
	prsm_json_add_number(ch, "total_lead_mm", c->total_lead_mm);
	prsm_json_add_number(ch, "output_speed_mm_s", c->output_speed_mm_s);
	prsm_json_add_number(ch, "input_torque_Nm", c->input_torque_Nm);
	prsm_json_add_number(ch, "ideal_torque_Nm", c->ideal_torque_Nm);
	prsm_json_add_number(ch, "efficiency", c->efficiency);
	prsm_json_add_number(ch, "efficiency_frictionless_couplings", c->harmonic_efficiency);
	prsm_json_add_number(ch, "input_power_W", c->input_power_W);
	prsm_json_add_number(ch, "output_power_W", c->output_power_W);
	prsm_json_add_number(ch, "loss_power_W", c->loss_power_W);
	cJSON *cp = cJSON_AddObjectToObject(ch, "couplings");
	prsm_json_add_number(cp, "spline_friction", in->spline_friction);
	prsm_json_add_number(cp, "thrust_bearing_friction", in->thrust_bearing_friction);
	cJSON *per = cJSON_AddArrayToObject(ch, "per_stage");
	for (int k = 0; k < c->stages; k++) {
		const prsm_chain_stage *st = &c->stage[k];
		cJSON *o = cJSON_CreateObject();
		cJSON_AddNumberToObject(o, "stage", k + 1);
		prsm_json_add_number(o, "lead_mm", in->lead_mm[k]);
		prsm_json_add_number(o, "axial_load_N", st->load_N);
		prsm_json_add_number(o, "stage_torque_Nm", st->stage_torque_Nm);
		prsm_json_add_number(o, "stage_efficiency", st->stage_efficiency);
		prsm_json_add_number(o, "torque_into_screw_Nm", st->spline_torque_Nm);
		prsm_json_add_number(o, "nut_speed_mm_s", st->nut_speed_mm_s);
		prsm_json_add_number(o, "carrier_ratio", m->analysis[k].kinematics.carrier_ratio);
		prsm_json_add_number(o, "carrier_ratio_ideal", m->analysis[k].kinematics.carrier_ratio_ideal);
		prsm_json_add_number(o, "stage_loss_W", st->stage_loss_W);
		if (k > 0) {
			prsm_json_add_number(o, "spline_radius_mm", in->spline_radius_mm[k]);
			cJSON_AddBoolToObject(o, "spline_radius_default", m->spline_radius_default[k]);
			prsm_json_add_number(o, "spline_friction_force_N", st->spline_force_N);
			prsm_json_add_number(o, "spline_loss_W", st->spline_loss_W);
			prsm_json_add_number(o, "thrust_bearing_radius_mm", in->thrust_radius_mm[k]);
			cJSON_AddBoolToObject(o, "thrust_bearing_radius_default", m->thrust_radius_default[k]);
			prsm_json_add_number(o, "thrust_bearing_load_N", st->thrust_load_N);
			prsm_json_add_number(o, "thrust_bearing_torque_Nm", st->thrust_torque_Nm);
			prsm_json_add_number(o, "thrust_bearing_loss_W", st->thrust_loss_W);
		}
		cJSON_AddItemToArray(per, o);
	}
	cJSON *stages = cJSON_AddArrayToObject(root, "stages");
	prsm_problems none;
	prsm_problems_init(&none);
	for (int k = 0; k < m->stages; k++)
		cJSON_AddItemToArray(stages, prsm_io_analysis_to_json(&m->analysis[k], &m->design[k], &perf[k], &none));
	cJSON_AddItemToObject(root, "warnings", prsm_io_problems_to_json(warnings));
	return root;
}
