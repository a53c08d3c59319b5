/*
 * assembly_json.c: the error analysis as JSON and text (units converted here: mm -> um,
 * rad -> deg or mrad, N/mm -> N/um).
 */
#include "io/assembly_json.h"

#include <math.h>

#include "io/json_util.h"

#define UM 1e3 /* um per mm */

static const char *const line_names[5] = {"screw", "carrier", "roller_spin", "roller_pass_screw",
                                          "roller_pass_nut"};
static const char *const line_sources[5] = {
	"a screw-fixed error passing one roller (1 - k_c)",
	"a nut-fixed error passing one roller (k_c)",
	"a roller-fixed error (roller spin relative to the carrier, |s_r|)",
	"the rollers passing a point of the screw (Z (1 - k_c))",
	"the rollers passing a point of the nut (Z k_c)"};

static cJSON *scaled_array(const double *v, int n, double scale)
{
	cJSON *a = cJSON_CreateArray();
	for (int i = 0; a && i < n; i++)
		cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i] * scale));
	return a;
}

/* Sensitivities of one pair in the units of the API: um of gap per um of error, per mrad for
 * the flank angle. */
static cJSON *sens_json(const prsm_assembly_pair *p)
{
	static const char *const names[PRSM_PERTURB_COUNT] = {
		"body_axis_x_um_per_um", "body_axis_y_um_per_um", "body_pitch_radius_um_per_um",
		"body_flank_angle_um_per_mrad", "body_flank_shift_um_per_um", "roller_axis_x_um_per_um",
		"roller_axis_y_um_per_um", "roller_pitch_radius_um_per_um", "roller_arc_radius_um_per_um",
		"roller_flank_shift_um_per_um"};
	cJSON *o = cJSON_CreateObject();
	/* mm/mm = um/um; the flank angle's mm/rad = um/mrad: the engine's numbers as they are */
	for (int i = 0; i < PRSM_PERTURB_COUNT; i++)
		prsm_json_add_number(o, names[i], p->sens[i]);
	prsm_json_add_number(o, "nominal_gap_um", p->gap_mm * UM);
	cJSON_AddBoolToObject(o, "mirrored", p->mirrored);
	return o;
}

static const char *pair_key(int side, int dir)
{
	static const char *const k[2][2] = {{"screw_roller_plus", "screw_roller_minus"},
	                                    {"nut_roller_plus", "nut_roller_minus"}};
	return k[side][dir];
}

/* Gaps of one side, roller by roller: [[thread 0 .. n_t - 1] per roller], um. */
static cJSON *gap_table(const prsm_assembly *as, const prsm_assembly_gaps *g, int side)
{
	cJSON *a = cJSON_CreateArray();
	for (int j = 0; a && j < as->rollers; j++)
		cJSON_AddItemToArray(a, scaled_array(&g->gap_mm[side][j * as->threads], as->threads, UM));
	return a;
}

cJSON *prsm_io_assembly_to_json(const prsm_assembly_report *r, const prsm_assembly *as,
                                const prsm_assembly_options *o, const prsm_assembly_workspace *ws)
{
	cJSON *root = cJSON_CreateObject();
	if (root == NULL)
		return NULL;
	cJSON_AddStringToObject(root, "mode", r->mode == PRSM_MODE_EXACT ? "exact" : "linear");
	cJSON_AddStringToObject(root, "conventions",
	                        "plus: the nut pushed towards +z relative to the screw (roller's upper flank on "
	                        "the screw, lower flank under the nut); minus the opposite. Gaps in the frame "
	                        "that moves with the nominal nut and rollers (docs/assembly-model.md)");
	cJSON *sens = cJSON_AddObjectToObject(root, "sensitivities");
	for (int side = 0; side < 2; side++)
		for (int dir = 0; dir < 2; dir++)
			cJSON_AddItemToObject(sens, pair_key(side, dir), sens_json(&as->pairs[side][dir]));

	cJSON *gaps = cJSON_AddObjectToObject(root, "gaps_at_zero");
	for (int side = 0; side < 2; side++)
		for (int dir = 0; dir < 2; dir++) {
			cJSON *g = cJSON_AddObjectToObject(gaps, pair_key(side, dir));
			prsm_json_add_number(g, "min_um", r->gap_min_mm[side][dir] * UM);
			prsm_json_add_number(g, "max_um", r->gap_max_mm[side][dir] * UM);
			if (o->curve && ws)
				cJSON_AddItemToObject(g, "per_roller_and_thread_um",
				                      gap_table(as, dir == PRSM_DIR_PLUS ? &ws->plus : &ws->minus, side));
		}

	cJSON *b = cJSON_AddObjectToObject(root, "backlash");
	prsm_json_add_number(b, "at_zero_um", r->backlash_mm * UM);
	prsm_json_add_number(b, "plus_um", r->backlash_plus_mm * UM);
	prsm_json_add_number(b, "minus_um", r->backlash_minus_mm * UM);
	prsm_json_add_number(b, "min_over_revolution_um", r->backlash_min_mm * UM);
	prsm_json_add_number(b, "max_over_revolution_um", r->backlash_max_mm * UM);
	prsm_json_add_number(b, "mean_over_revolution_um", r->backlash_mean_mm * UM);

	cJSON *ls = cJSON_AddObjectToObject(root, "load_sharing");
	const prsm_assembly_state *st = &r->operating;
	prsm_json_add_number(ls, "axial_load_N", as->design.axial_load_N);
	if (as->design.axial_load_N > 0.0) {
		prsm_json_add_number(ls, "sharing_factor", st->sharing_factor);
		prsm_json_add_number(ls, "sharing_factor_max_over_revolution", r->sharing_factor_max);
		cJSON_AddNumberToObject(ls, "loaded_rollers", st->loaded_rollers);
		cJSON_AddItemToObject(ls, "roller_loads_N", scaled_array(st->roller_load_N, as->rollers, 1.0));
		prsm_json_add_number(ls, "nut_displacement_um", st->u_mm * UM);
		prsm_json_add_number(ls, "stiffness_N_per_um", st->stiffness_N_per_mm / UM);
		prsm_json_add_number(ls, "nominal_stiffness_N_per_um", as->nominal_stiffness_N_per_mm / UM);
		prsm_json_add_number(ls, "stiffness_ratio", r->stiffness_ratio);
	}
	cJSON_AddStringToObject(ls, "contact_law",
	                        "Hertz point contacts, axial K from the nominal curvatures; no thread or body "
	                        "compliance (docs/model/kinematics-efficiency-stiffness-life.md thread compliance comes with the load distribution)");

	cJSON *te = cJSON_AddObjectToObject(root, "transmission_error");
	prsm_json_add_number(te, "measuring_load_N", r->measuring_load_N);
	cJSON_AddNumberToObject(te, "angles_per_revolution", r->angles_per_revolution);
	cJSON *rev = cJSON_AddObjectToObject(te, "revolution");
	prsm_json_add_number(rev, "peak_to_peak_um", r->te_revolution_pp_mm * UM);
	prsm_json_add_number(rev, "rms_um", r->te_revolution_rms_mm * UM);
	if (r->has_stroke) {
		cJSON *s = cJSON_AddObjectToObject(te, "stroke");
		prsm_json_add_number(s, "stroke_mm", r->stroke_mm);
		prsm_json_add_number(s, "peak_to_peak_um", r->te_stroke_pp_mm * UM);
		prsm_json_add_number(s, "rms_um", r->te_stroke_rms_mm * UM);
		prsm_json_add_number(s, "lead_deviation_um_per_300mm", r->lead_deviation * 300.0 * UM);
		prsm_json_add_number(s, "residual_peak_to_peak_um", r->te_stroke_residual_pp_mm * UM);
	} else {
		cJSON_AddNullToObject(te, "stroke");
	}
	cJSON *sp = cJSON_AddObjectToObject(te, "spectrum");
	prsm_json_add_number(sp, "record_revolutions", r->record_revolutions);
	const double hz = as->design.screw_speed_rad_s / (2.0 * M_PI); /* screw revolutions per s */
	cJSON *lines = cJSON_AddArrayToObject(sp, "lines");
	const double fr[5] = {r->frequencies.screw, r->frequencies.carrier, r->frequencies.roller_spin,
	                      r->frequencies.roller_pass_screw, r->frequencies.roller_pass_nut};
	for (int i = 0; i < 5; i++) {
		cJSON *l = cJSON_CreateObject();
		cJSON_AddStringToObject(l, "name", line_names[i]);
		cJSON_AddStringToObject(l, "source", line_sources[i]);
		prsm_json_add_number(l, "frequency_per_rev", fr[i]);
		prsm_json_add_number(l, "frequency_Hz", fr[i] * fabs(hz));
		prsm_json_add_number(l, "amplitude_um", r->line_amplitude_mm[i] * UM);
		cJSON_AddItemToArray(lines, l);
	}
	cJSON *pk = cJSON_AddObjectToObject(sp, "peak");
	prsm_json_add_number(pk, "frequency_per_rev", r->peak_frequency_per_rev);
	prsm_json_add_number(pk, "frequency_Hz", r->peak_frequency_per_rev * fabs(hz));
	prsm_json_add_number(pk, "amplitude_um", r->peak_amplitude_mm * UM);
	if (o->curve && ws) {
		prsm_json_add_number(sp, "step_per_rev", r->spectrum_step_per_rev);
		cJSON_AddItemToObject(sp, "amplitude_um", scaled_array(ws->spectrum_mm, r->spectrum_bins, UM));
		cJSON *c = cJSON_AddObjectToObject(te, "curve");
		prsm_json_add_number(c, "step_deg", 360.0 / r->angles_per_revolution);
		prsm_json_add_number(c, "travel_per_step_mm", -as->screw_p * 2.0 * M_PI / r->angles_per_revolution);
		cJSON_AddItemToObject(c, "te_um", scaled_array(ws->te_mm, r->record_length, UM));
	}
	cJSON *cc = cJSON_AddObjectToObject(root, "contacts");
	cJSON_AddNumberToObject(cc, "edge", r->edge_contacts);
	cJSON_AddNumberToObject(cc, "failed", r->failed_contacts);
	return root;
}
