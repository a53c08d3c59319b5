/*
 * assembly_json.c: the error analysis as the analysis result's "assembly" member, by its
 * generated table (schemas/analysis.schema.json, $defs/assembly): the view it reads and the
 * hooks (units converted by the table: mm -> um, N/mm -> N/um).
 */
#include "io/assembly_json.h"

#include <math.h>

#include "io/analysis_json.h"
#include "prsm_io_writers.h"

#define UM 1e3 /* um per mm */

void prsm_io_whook_spectrum_lines(prsm_jw *w, cJSON *obj, const char *key, const void *at)
{
	static const char *const names[5] = {"screw", "carrier", "roller_spin", "roller_pass_screw", "roller_pass_nut"};
	static const char *const sources[5] = {
		"a screw-fixed error passing one roller (1 - k_c)",
		"a nut-fixed error passing one roller (k_c)",
		"a roller-fixed error (roller spin relative to the carrier, |s_r|)",
		"the rollers passing a point of the screw (Z (1 - k_c))",
		"the rollers passing a point of the nut (Z k_c)"};
	const prsm_io_assembly_view *v = at;
	const prsm_assembly_frequencies *f = &v->r->frequencies;
	const double fr[5] = {f->screw, f->carrier, f->roller_spin, f->roller_pass_screw, f->roller_pass_nut};
	cJSON *arr = prsm_jw_array(w, obj, key);
	for (int i = 0; arr && i < 5; i++) {
		cJSON *l = prsm_jw_object(w, arr, NULL);
		prsm_jw_string(w, l, "name", names[i]);
		prsm_jw_string(w, l, "source", sources[i]);
		prsm_jw_number(w, l, "frequency_per_rev", fr[i]);
		prsm_jw_number(w, l, "frequency_Hz", fr[i] * fabs(v->hz));
		prsm_jw_number(w, l, "amplitude_um", v->r->line_amplitude_mm[i] * UM);
	}
}

cJSON *prsm_io_assembly_to_json(const prsm_assembly_report *r, const prsm_assembly *as,
                                const prsm_assembly_options *o, const prsm_assembly_workspace *ws)
{
	prsm_io_assembly_view v = {
		.r = r, .as = as, .ws = ws, .curve = o->curve && ws, .loaded = as->design.axial_load_N > 0.0,
		.rollers = as->rollers, .hz = as->design.screw_speed_rad_s / (2.0 * M_PI), /* revolutions per s */
		.lead_deviation_um = r->lead_deviation * 300.0 * UM,
		.step_deg = 360.0 / r->angles_per_revolution,
		.travel_per_step_mm = -as->screw_p * 2.0 * M_PI / r->angles_per_revolution,
	};
	v.peak_Hz = r->peak_frequency_per_rev * fabs(v.hz);
	for (int side = 0; side < 2; side++)
		for (int dir = 0; dir < 2; dir++) {
			const prsm_assembly_gaps *g = !ws ? NULL : dir == PRSM_DIR_PLUS ? &ws->plus : &ws->minus;
			v.gaps[side][dir] = (prsm_io_gap_view){r->gap_min_mm[side][dir], r->gap_max_mm[side][dir],
			                                        g ? g->gap_mm[side] : NULL, as->rollers, as->threads, v.curve};
		}
	prsm_jw w = PRSM_JW_INIT;
	cJSON *root = prsm_jw_root(&w);
	prsm_io_write_fields(&w, root, &v, &prsm_io_w_assembly, 0);
	return prsm_jw_done(&w, root);
}
