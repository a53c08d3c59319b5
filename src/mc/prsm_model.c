/*
 * prsm_model.c: one Monte Carlo sample of a roller screw: bind the sampled values to an error
 * set and evaluate the assembly's outputs (docs/model/errors-and-assembly.md) and the sliding efficiency (§5).
 */
#include "mc/prsm_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/assembly_report.h"
#include "model/efficiency.h"
#include "model/losses.h"

static const char *const output_names[PRSM_OUT_COUNT] = {
	"backlash_um", "backlash_min_um", "backlash_max_um", "load_sharing_factor",
	"stiffness_N_per_um", "stiffness_ratio", "te_pp_um", "te_rms_um", "efficiency_sliding",
	"efficiency_back", "nut_unit_stiffness_N_per_um", "efficiency_with_losses"};

const char *prsm_output_name(prsm_output_kind k)
{
	return (unsigned)k < PRSM_OUT_COUNT ? output_names[k] : "?";
}

int prsm_output_parse(const char *name, prsm_output_kind *out)
{
	for (int k = 0; k < PRSM_OUT_COUNT; k++)
		if (strcmp(name, output_names[k]) == 0) {
			*out = (prsm_output_kind)k;
			return 0;
		}
	if (strcmp(name, "efficiency") == 0) { /* the older name of efficiency_sliding */
		*out = PRSM_OUT_EFFICIENCY;
		return 0;
	}
	return PRSM_ENOTFOUND;
}

/* Per-thread scratch: about 130 kB, so it lives on the heap. */
typedef struct {
	prsm_errors e;
	prsm_assembly_gaps plus, minus;
	prsm_assembly_state st;
	prsm_design design;             /* copy whose friction the samples change */
	prsm_losses_options loss_options; /* the design's losses section (no friction in it) */
	prsm_losses_nominal loss_nominal; /* efficiency_with_losses: what of the losses does not
	                                   depend on friction (Hertz contacts, gear teeth), once */
	double *te_mm;                  /* angles_per_revolution */
} workspace;

static int wants(const prsm_mc_prsm *p, prsm_output_kind a, prsm_output_kind b)
{
	for (size_t i = 0; i < p->n_outputs; i++)
		if (p->outputs[i] == a || p->outputs[i] == b)
			return 1;
	return 0;
}

static int ws_alloc(void **out, const void *ctx)
{
	const prsm_mc_prsm *p = ctx;
	workspace *w = calloc(1, sizeof *w);
	if (!w)
		return PRSM_ENOMEM;
	w->te_mm = calloc((size_t)(p->angles_per_revolution > 0 ? p->angles_per_revolution : 1),
	                  sizeof *w->te_mm);
	if (!w->te_mm) {
		free(w);
		return PRSM_ENOMEM;
	}
	w->design = p->as->design;
	prsm_losses_options_from_design(&w->loss_options, &w->design);
	/* a sample changes only the friction coefficients of the design the losses see (the
	 * contacts, kinematics and loads are the nominal ones): the Hertz solves and the gear rule
	 * are the same in every sample, and an error they find is reported by every sample */
	if (wants(p, PRSM_OUT_EFFICIENCY_LOSSES, PRSM_OUT_EFFICIENCY_LOSSES))
		prsm_losses_prepare(&w->loss_nominal, &w->design, &p->an->screw, &p->an->nut,
		                    &w->loss_options);
	*out = w;
	return 0;
}

static void ws_free(void *ws)
{
	workspace *w = ws;
	if (w)
		free(w->te_mm);
	free(w);
}

static void bind(workspace *w, const prsm_mc_prsm *p, const double *x)
{
	w->e = p->base;
	w->design.mu_screw_roller = p->as->design.mu_screw_roller;
	w->design.mu_nut_roller = p->as->design.mu_nut_roller;
	for (size_t i = 0; i < p->n_bindings; i++) {
		const prsm_mc_binding *b = &p->bindings[i];
		double v = x[i] * b->scale;
		char *base = NULL;
		switch (b->part) {
		case PRSM_PART_SCREW: base = (char *)&w->e.screw; break;
		case PRSM_PART_NUT: base = (char *)&w->e.nut; break;
		case PRSM_PART_CARRIER: base = (char *)&w->e.carrier; break;
		case PRSM_PART_ROLLER: base = (char *)&w->e.roller[b->roller < 0 ? 0 : b->roller]; break;
		case PRSM_PART_FRICTION:
			if (b->offset == 0)
				w->design.mu_screw_roller += v;
			else
				w->design.mu_nut_roller += v;
			continue;
		}
		/* a shared tolerance: every roller (roller = -1) or every start (body part, roller = -1) */
		int copies = 1;
		size_t stride = 0;
		if (b->roller < 0 && b->part == PRSM_PART_ROLLER) {
			base = (char *)&w->e.roller[0];
			copies = p->as->rollers;
			stride = sizeof w->e.roller[0];
		} else if (b->roller < 0) {
			copies = p->as->starts;
			stride = sizeof(double);
		}
		for (int k = 0; k < copies; k++) {
			double cur;
			char *at = base + (size_t)k * stride + b->offset;
			memcpy(&cur, at, sizeof cur);
			cur += v;
			memcpy(at, &cur, sizeof cur);
		}
	}
}

static int prsm_eval(double *y, unsigned *flags, const void *ctx, void *wsp, const double *x)
{
	const prsm_mc_prsm *p = ctx;
	workspace *w = wsp;
	const prsm_assembly *as = p->as;
	const int M = p->angles_per_revolution;
	const double dtheta = 2.0 * M_PI / M;
	int edge = 0, failed = 0;
	double B0 = NAN, Bmin = INFINITY, Bmax = -INFINITY, te_pp = NAN, te_rms = NAN;
	double eta = NAN, eta_back = NAN;
	*flags = 0;
	if (!wsp)
		return PRSM_ENOMEM;
	bind(w, p, x);

	if (wants(p, PRSM_OUT_BACKLASH_MIN, PRSM_OUT_BACKLASH_MAX)) {
		for (int i = 0; i < M; i++) {
			prsm_assembly_gaps_at(&w->plus, as, &w->e, PRSM_DIR_PLUS, i * dtheta, p->mode);
			prsm_assembly_gaps_at(&w->minus, as, &w->e, PRSM_DIR_MINUS, i * dtheta, p->mode);
			edge += w->plus.edge_contacts + w->minus.edge_contacts;
			failed += w->plus.failed_contacts + w->minus.failed_contacts;
			double B = prsm_assembly_backlash(as, &w->plus, &w->minus, NULL, NULL);
			Bmin = fmin(Bmin, B);
			Bmax = fmax(Bmax, B);
		}
	}
	if (wants(p, PRSM_OUT_TE_PP, PRSM_OUT_TE_RMS)) {
		prsm_assembly_te_record(w->te_mm, M, dtheta, as, &w->e, p->mode, p->measuring_load_N,
		                        &w->minus, &edge, &failed);
		prsm_signal_pp_rms(&te_pp, &te_rms, w->te_mm, M);
	}
	/* theta = 0 last, so the "+" gaps are there for the elastic solve */
	int need0 = wants(p, PRSM_OUT_BACKLASH, PRSM_OUT_SHARING) ||
	            wants(p, PRSM_OUT_STIFFNESS, PRSM_OUT_STIFFNESS_RATIO) ||
	            wants(p, PRSM_OUT_UNIT_STIFFNESS, PRSM_OUT_UNIT_STIFFNESS);
	if (need0) {
		prsm_assembly_gaps_at(&w->plus, as, &w->e, PRSM_DIR_PLUS, 0.0, p->mode);
		prsm_assembly_gaps_at(&w->minus, as, &w->e, PRSM_DIR_MINUS, 0.0, p->mode);
		edge += w->plus.edge_contacts + w->minus.edge_contacts;
		failed += w->plus.failed_contacts + w->minus.failed_contacts;
		B0 = prsm_assembly_backlash(as, &w->plus, &w->minus, NULL, NULL);
	}
	int need_solve = wants(p, PRSM_OUT_SHARING, PRSM_OUT_STIFFNESS) ||
	                 wants(p, PRSM_OUT_STIFFNESS_RATIO, PRSM_OUT_UNIT_STIFFNESS);
	if (need_solve && as->design.axial_load_N > 0.0)
		failed += prsm_assembly_solve(&w->st, as, &w->plus, as->design.axial_load_N, 0) != 0;
	int wants_sliding = wants(p, PRSM_OUT_EFFICIENCY, PRSM_OUT_EFFICIENCY_BACK);
	int wants_losses = wants(p, PRSM_OUT_EFFICIENCY_LOSSES, PRSM_OUT_EFFICIENCY_LOSSES);
	if ((wants_sliding || wants_losses) &&
	    (!(w->design.mu_screw_roller >= 0.0) || !(w->design.mu_nut_roller >= 0.0)))
		return PRSM_EINVAL; /* a friction tolerance drew a negative coefficient */
	if (wants_sliding) {
		prsm_efficiency eff;
		prsm_efficiency_sliding(&eff, &w->design, &p->an->kinematics, &p->an->screw, &p->an->nut);
		eta = eff.eta;
		eta_back = eff.eta_back;
	}
	double eta_losses = NAN;
	if (wants_losses) {
		prsm_losses_result lr;
		prsm_error lerr = PRSM_ERROR_INIT;
		int lrc = prsm_losses_compute_prepared(&lr, &w->loss_nominal, &w->design, &p->an->kinematics,
		                                       &p->an->screw, &p->an->nut, p->loss_screw_loads_N,
		                                       p->loss_nut_loads_N, &w->loss_options, &lerr);
		if (lrc)
			return lrc;
		eta_losses = lr.eta;
	}
	if (failed)
		return PRSM_ENOCONVERGE;
	if (edge)
		*flags |= PRSM_MC_FLAG_EDGE;

	for (size_t i = 0; i < p->n_outputs; i++) {
		double v = NAN;
		switch (p->outputs[i]) {
		case PRSM_OUT_BACKLASH: v = B0 * 1e3; break;
		case PRSM_OUT_BACKLASH_MIN: v = Bmin * 1e3; break;
		case PRSM_OUT_BACKLASH_MAX: v = Bmax * 1e3; break;
		case PRSM_OUT_SHARING: v = w->st.sharing_factor; break;
		case PRSM_OUT_STIFFNESS: v = w->st.stiffness_N_per_mm * 1e-3; break;
		case PRSM_OUT_STIFFNESS_RATIO:
			v = as->nominal_stiffness_N_per_mm > 0 ? w->st.stiffness_N_per_mm / as->nominal_stiffness_N_per_mm : NAN;
			break;
		case PRSM_OUT_TE_PP: v = te_pp * 1e3; break;
		case PRSM_OUT_TE_RMS: v = te_rms * 1e3; break;
		case PRSM_OUT_EFFICIENCY: v = eta; break;
		case PRSM_OUT_EFFICIENCY_BACK: v = eta_back; break;
		case PRSM_OUT_EFFICIENCY_LOSSES: v = eta_losses; break;
		case PRSM_OUT_UNIT_STIFFNESS: /* springs in series (docs/model/kinematics-efficiency-stiffness-life.md), N/mm to N/um */
			v = w->st.stiffness_N_per_mm > 0.0
			        ? 1e-3 / (1.0 / w->st.stiffness_N_per_mm + p->unit_rest_compliance_mm_per_N)
			        : NAN;
			break;
		case PRSM_OUT_COUNT: break;
		}
		y[i] = v;
	}
	return 0;
}

void prsm_prsm_mc_model(prsm_mc_model *out, const prsm_mc_prsm *p)
{
	memset(out, 0, sizeof *out);
	out->n_outputs = p->n_outputs;
	out->ctx = p;
	out->workspace_alloc = ws_alloc;
	out->workspace_free = ws_free;
	out->eval = prsm_eval;
}
