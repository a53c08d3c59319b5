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
#include "prsm_vocab.h"

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>

/* The names are the schema's (study.schema.json, $defs/output_name: the generated prsm_vocab.h),
 * each by its constant; the older names a document may still use, and what each names. */
static const char *const output_names[PRSM_OUT_COUNT] = PRSM_OUTPUT_NAMES;
static const char *const older_names[] = PRSM_OUTPUT_OLDER_NAMES;
static const prsm_output_kind older_kinds[] = PRSM_OUTPUT_OLDER_VALUES;

int prsm_output_is_dynamic(prsm_output_kind k)
{
	return k >= PRSM_OUT_DYN_FIRST && k < PRSM_OUT_COUNT;
}

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
	for (int k = 0; older_names[k]; k++)
		if (strcmp(name, older_names[k]) == 0) {
			*out = older_kinds[k];
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
	/* dynamic outputs */
	prsm_vib_model *vib;            /* this thread's reduced model (p->dyn) */
	int dyn_set[PRSM_DYN_TOLS];     /* a dynamic tolerance drew this sample's value */
	double dyn_val[PRSM_DYN_TOLS];  /* its value (m, m, -) */
	double te_dyn_mm[PRSM_MC_DYN_RECORD_MAX]; /* the TE record of the line fit, mm */
} workspace;

static int wants_dynamic(const prsm_mc_prsm *p)
{
	for (size_t i = 0; i < p->n_outputs; i++)
		if (prsm_output_is_dynamic(p->outputs[i]))
			return p->dyn != NULL;
	return 0;
}

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
	if (wants_dynamic(p)) {
		prsm_error err = PRSM_ERROR_INIT;
		const int rc = prsm_vib_model_new(&w->vib, p->dyn->design, p->dyn->analysis, &p->dyn->dyn, &p->dyn->vib,
		                                  NULL, NULL, &err);
		if (rc) {
			free(w->te_mm);
			free(w);
			return rc;
		}
	}
	*out = w;
	return 0;
}

static void ws_free(void *ws)
{
	workspace *w = ws;
	if (w) {
		free(w->te_mm);
		prsm_vib_model_free(w->vib);
	}
	free(w);
}

static void bind(workspace *w, const prsm_mc_prsm *p, const double *x)
{
	w->e = p->base;
	w->design.mu_screw_roller = p->as->design.mu_screw_roller;
	w->design.mu_nut_roller = p->as->design.mu_nut_roller;
	for (int k = 0; k < PRSM_DYN_TOLS; k++)
		w->dyn_set[k] = 0;
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
		case PRSM_PART_DYNAMICS: /* absolute values */
			w->dyn_set[b->offset] = 1;
			w->dyn_val[b->offset] = v;
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

/* One sample's dynamic outputs (MODEL-DYNAMICS.md §8.6): its statics (linear or exact mode, as the
 * study) give the §8.3 inputs: the TE lines by least squares at the named orders (§8.3.4, the
 * projection of prsm_mc_dyn_prepare), b_a = half the backlash at theta = 0 (B0, mm), k_a the nut
 * unit's axial stiffness at the operating load (the sampled contacts, N/mm, in series with the rest
 * of the unit); the dynamic tolerances set e_g, b_g and the damping ratios (else the dynamics
 * section's values). */
static int dyn_eval(prsm_vib_mc_out *out, const prsm_mc_prsm *p, workspace *w, double B0_mm, double k_contacts_N_per_mm)
{
	const prsm_mc_dyn *d = p->dyn;
	prsm_vib_mc_sample s;
	prsm_vib_mc_sample_init(&s);
	s.window_rev = d->window_rev;
	if (!(k_contacts_N_per_mm > 0.0))
		return PRSM_ENOCONVERGE;
	s.axial_stiffness_N_per_m = 1e3 / (1.0 / k_contacts_N_per_mm + p->unit_rest_compliance_mm_per_N);
	/* no axial play (a preloaded or interfering thread): the dead zone of §8.3.2 does not describe
	 * it; the sample fails with PRSM_EGEOMETRY, counted apart from integration failures */
	if (!(B0_mm > 0.0))
		return PRSM_EGEOMETRY;
	s.axial_half_play_m = 0.5 * B0_mm * 1e-3;
	s.te_source = 1;
	s.te_lines = d->n_orders;
	for (int k = 0; k < d->n_orders; k++) {
		double a = 0.0, b = 0.0;
		const double *pc = d->projection[2 * k], *ps = d->projection[2 * k + 1];
		for (int i = 0; i < d->record_n; i++) {
			a += pc[i] * w->te_dyn_mm[i];
			b += ps[i] * w->te_dyn_mm[i];
		}
		/* TE ~ a cos + b sin = A cos(nu theta + phi): A = |(a, b)|, phi = atan2(-b, a) */
		s.te_line[k].order_per_rev = d->order_kstar[k];
		s.te_line[k].amplitude_m = hypot(a, b) * 1e-3;
		s.te_line[k].phase_rad = atan2(-b, a);
	}
	s.mesh_error_m = w->dyn_set[PRSM_DYN_TOL_MESH_ERROR] ? w->dyn_val[PRSM_DYN_TOL_MESH_ERROR] : d->vib.mesh_error_um * 1e-6;
	s.gear_half_backlash_m = w->dyn_set[PRSM_DYN_TOL_BACKLASH] ? w->dyn_val[PRSM_DYN_TOL_BACKLASH]
	                                                            : d->vib.gear_backlash_um * 1e-6;
	s.axial_damping_ratio = w->dyn_set[PRSM_DYN_TOL_DAMPING] ? w->dyn_val[PRSM_DYN_TOL_DAMPING] : d->vib.axial_damping_ratio;
	s.mesh_damping_ratio = w->dyn_set[PRSM_DYN_TOL_DAMPING] ? w->dyn_val[PRSM_DYN_TOL_DAMPING] : d->vib.mesh_damping_ratio;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_vib_mc_apply(w->vib, &s, &err);
	if (rc)
		return rc; /* a drawn value out of range (a negative mesh error, a damping ratio >= 1) */
	prsm_vib_mc_options o = d->options;
	if (wants(p, PRSM_OUT_DYN_LYAPUNOV, PRSM_OUT_DYN_LYAPUNOV))
		o.lyapunov_windows = PRSM_MC_DYN_LYAPUNOV_WINDOWS; /* an integrated sample's lyapunov_max */
	rc = prsm_vib_mc_eval(out, w->vib, &o, NULL, &err);
	return rc;
}

int prsm_mc_dyn_prepare(prsm_mc_dyn *d, const prsm_assembly *as, int angles_per_revolution, double window_rev,
                        prsm_error *err)
{
	prsm_assembly_frequencies fq;
	prsm_assembly_frequencies_of(&fq, as);
	const double kc = as->carrier_ratio;
	/* the nominal reduced model gives k* (§8.1) */
	prsm_vib_model *m = NULL;
	int rc = prsm_vib_model_new(&m, d->design, d->analysis, &d->dyn, &d->vib, NULL, NULL, err);
	if (rc)
		return rc;
	const double ks = prsm_vib_model_params(m)->carrier_ratio;
	prsm_vib_model_free(m);
	const double i_g = kc > 0.0 ? fq.roller_spin / kc : 0.0;
	const double named[5] = {fq.screw, fq.carrier, fq.roller_spin, fq.roller_pass_screw, fq.roller_pass_nut};
	const double named_k[5] = {1.0 - ks, ks, i_g * ks, as->rollers * (1.0 - ks), as->rollers * ks};
	const int M = angles_per_revolution;
	d->per_rev = M;
	d->n_orders = 0;
	for (int i = 0; i < 5; i++) {
		int dup = !(named[i] > 0.0 && named[i] < 0.5 * M);
		for (int k = 0; k < d->n_orders && !dup; k++)
			dup = fabs(d->order_kc[k] - named[i]) < 1e-9;
		if (!dup) {
			d->order_kc[d->n_orders] = named[i];
			d->order_kstar[d->n_orders++] = named_k[i];
		}
	}
	/* the window: given, or the common period of the named orders (at most 64 revolutions) */
	double W = window_rev;
	for (int q = 1; q <= 64 && !(W > 0.0); q++) {
		int ok = 1;
		for (int k = 0; k < d->n_orders && ok; k++)
			ok = fabs(q * d->order_kc[k] - nearbyint(q * d->order_kc[k])) < 1e-6;
		if (ok)
			W = q;
	}
	if (!(W > 0.0))
		W = 8.0;
	d->window_rev = W;
	/* the record: the window, at least 4 revolutions */
	const double revs = fmax(W, 4.0);
	d->record_n = (int)lround(revs * M);
	const int np = 2 + 2 * d->n_orders;
	if (d->record_n > PRSM_MC_DYN_RECORD_MAX || d->record_n < np + 2)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamic_monte_carlo/window_revolutions",
		                      "the TE record of %g revolutions at %d angles per revolution has %d angles: %d to %d",
		                      revs, M, d->record_n, np + 2, PRSM_MC_DYN_RECORD_MAX);
	/* the least-squares projection (X^T X)^-1 X^T of the design matrix [1, i / M, cos, sin] */
	const size_t n = (size_t)d->record_n, pp = (size_t)np;
	gsl_matrix *X = gsl_matrix_alloc(n, pp), *XtX = gsl_matrix_alloc(pp, pp);
	gsl_permutation *perm = gsl_permutation_alloc(pp);
	gsl_vector *col = gsl_vector_alloc(pp);
	if (!X || !XtX || !perm || !col) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the TE fit");
		goto done;
	}
	for (size_t i = 0; i < n; i++) {
		gsl_matrix_set(X, i, 0, 1.0);
		gsl_matrix_set(X, i, 1, (double)i / M);
		for (int k = 0; k < d->n_orders; k++) {
			const double ph = 2.0 * M_PI * d->order_kc[k] * (double)i / M;
			gsl_matrix_set(X, i, (size_t)(2 + 2 * k), cos(ph));
			gsl_matrix_set(X, i, (size_t)(3 + 2 * k), sin(ph));
		}
	}
	for (size_t a = 0; a < pp; a++)
		for (size_t b = 0; b < pp; b++) {
			double sum = 0.0;
			for (size_t i = 0; i < n; i++)
				sum += gsl_matrix_get(X, i, a) * gsl_matrix_get(X, i, b);
			gsl_matrix_set(XtX, a, b, sum);
		}
	int sgn = 0;
	if (gsl_linalg_LU_decomp(XtX, perm, &sgn) || fabs(gsl_linalg_LU_det(XtX, sgn)) < 1e-300) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, "/dynamic_monte_carlo/window_revolutions",
		                    "the named TE orders cannot be told apart over %g revolutions", revs);
		goto done;
	}
	/* row r of the projection: e_r^T (X^T X)^-1 X^T, i.e. X (X^T X)^-1 e_r as a column */
	for (int k = 0; k < 2 * d->n_orders; k++) {
		gsl_vector_set_basis(col, (size_t)(2 + k));
		gsl_linalg_LU_svx(XtX, perm, col);
		for (size_t i = 0; i < n; i++) {
			double sum = 0.0;
			for (size_t b = 0; b < pp; b++)
				sum += gsl_matrix_get(X, i, b) * gsl_vector_get(col, b);
			d->projection[k][i] = sum;
		}
	}
done:
	gsl_matrix_free(X);
	gsl_matrix_free(XtX);
	gsl_permutation_free(perm);
	gsl_vector_free(col);
	return rc;
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
	const int dyn = wants_dynamic(p);
	int need0 = dyn || wants(p, PRSM_OUT_BACKLASH, PRSM_OUT_SHARING) ||
	            wants(p, PRSM_OUT_STIFFNESS, PRSM_OUT_STIFFNESS_RATIO) ||
	            wants(p, PRSM_OUT_UNIT_STIFFNESS, PRSM_OUT_UNIT_STIFFNESS);
	if (need0) {
		prsm_assembly_gaps_at(&w->plus, as, &w->e, PRSM_DIR_PLUS, 0.0, p->mode);
		prsm_assembly_gaps_at(&w->minus, as, &w->e, PRSM_DIR_MINUS, 0.0, p->mode);
		edge += w->plus.edge_contacts + w->minus.edge_contacts;
		failed += w->plus.failed_contacts + w->minus.failed_contacts;
		B0 = prsm_assembly_backlash(as, &w->plus, &w->minus, NULL, NULL);
	}
	int need_solve = dyn || wants(p, PRSM_OUT_SHARING, PRSM_OUT_STIFFNESS) ||
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
	/* the TE record of the line fit (§8.3.4) */
	if (dyn)
		prsm_assembly_te_record(w->te_dyn_mm, p->dyn->record_n, 2.0 * M_PI / p->dyn->per_rev, as, &w->e, p->mode,
		                        p->measuring_load_N, &w->minus, &edge, &failed);
	if (failed)
		return PRSM_ENOCONVERGE;
	if (edge)
		*flags |= PRSM_MC_FLAG_EDGE;
	prsm_vib_mc_out dout;
	memset(&dout, 0, sizeof dout);
	if (dyn) {
		const int rc = dyn_eval(&dout, p, w, B0, as->design.axial_load_N > 0.0 ? w->st.stiffness_N_per_mm : NAN);
		if (rc)
			return rc;
	}

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
		case PRSM_OUT_DYN_PEAK_TE: v = dout.peak_dynamic_te_m * 1e6; break;
		case PRSM_OUT_DYN_THREAD_FORCE: v = dout.peak_thread_force_N; break;
		case PRSM_OUT_DYN_AXIAL_RMS: v = dout.axial_vibration_rms_m_s2; break;
		case PRSM_OUT_DYN_CONTACT_LOSS: v = dout.contact_loss ? 1.0 : 0.0; break;
		case PRSM_OUT_DYN_MESH_FORCE: v = dout.mesh_force_peak_N; break;
		case PRSM_OUT_DYN_REGIME: v = dout.regime; break;
		case PRSM_OUT_DYN_INTEGRATED: v = dout.integrated ? 1.0 : 0.0; break;
		case PRSM_OUT_DYN_LYAPUNOV: v = dout.lyapunov_max_per_s; break;
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
