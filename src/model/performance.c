/*
 * performance.c: efficiency with every loss, thread compliance, load distribution, stiffness,
 * capacity, life and column limits at the design's operating point (docs/model/kinematics-efficiency-stiffness-life.md).
 */
#include "model/performance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The design's thread-compliance settings as model/compliance.h options. */
static void compliance_options(prsm_compliance_options *o, const prsm_design *d)
{
	const prsm_design_stiffness *s = &d->stiffness;
	*o = (prsm_compliance_options)PRSM_COMPLIANCE_OPTIONS_INIT;
	o->width_rule = s->width_rule;
	o->width_fraction = s->width_fraction;
	o->width_mm = s->width_mm;
	o->ellipse_factor = s->ellipse_factor;
	o->calibration = s->calibration;
	o->negative_terms = s->negative_terms;
	o->nut_outer_radius_mm = d->nut_outer_radius_mm;
}

/* Thread compliance, segments and the load-distribution parameters of d. */
static int chain_params(prsm_loaddist_params *p, prsm_design_compliance *tc,
                        prsm_segment_compliance *seg, const prsm_design *d, const prsm_analysis *a,
                        prsm_error *err)
{
	prsm_compliance_options o;
	compliance_options(&o, d);
	/* the ellipse rule takes the contact ellipse at the operating load, shared equally */
	const double ellipse_a[2] = {a->hertz_screw.a_mm, a->hertz_nut.a_mm};
	if (o.width_rule == PRSM_THREAD_WIDTH_ELLIPSE && !(ellipse_a[0] > 0.0 && ellipse_a[1] > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/stiffness/thread_compliance/width",
		                      "the ellipse width rule needs a positive operating load (the contact "
		                      "ellipse at that load sets the width)");
	int rc;
	if ((rc = prsm_compliance_design(tc, d, &o, ellipse_a, err)) ||
	    (rc = prsm_compliance_segments(seg, d, tc->nut_outer_radius_mm, err)))
		return rc;
	const int entry = d->stiffness.load_entry == PRSM_ENTRY_OPPOSITE_SIDE ? PRSM_LOAD_ENTRY_OPPOSITE
	                                                                       : PRSM_LOAD_ENTRY_SAME;
	return prsm_loaddist_params_from_design(p, d, &a->screw, &a->nut, tc, seg, entry, err);
}

/* Normal loads of one roller's contacts from the distribution (for the spin loss). */
static int torque_with_losses(prsm_losses_result *out, const prsm_design *d, const prsm_analysis *a,
                              const prsm_loaddist_result *dist, prsm_error *err)
{
	prsm_losses_options o;
	prsm_losses_options_from_design(&o, d);
	return prsm_losses_compute(out, d, &a->kinematics, &a->screw, &a->nut,
	                           dist ? dist->normal_screw_N : NULL, dist ? dist->normal_nut_N : NULL,
	                           &o, err);
}

/* p_max of the most loaded contact of one side at total load F, MPa; NaN when the solve fails. */
static double peak_pressure(prsm_loaddist_workspace *ws, const prsm_loaddist_params *p, double F,
                            int side, prsm_error *err)
{
	prsm_loaddist_result r;
	if (prsm_loaddist_solve(&r, ws, p, F, err))
		return NAN;
	return r.side[side].p_max_MPa;
}

/* C_0a of one side: the load at which its most loaded contact reaches p_allow (docs/model/kinematics-efficiency-stiffness-life.md).
 * p_max ~ F^(1/3) at a fixed distribution, so F <- F (p_allow / p_max(F))^3 converges fast (the
 * max/mean factor changes slowly with F); it starts from the equal-sharing figure and falls
 * back to bisection in log F if it has not converged in 30 steps. */
static int static_capacity_side(double *out_N, prsm_loaddist_workspace *ws,
                                const prsm_loaddist_params *p, const prsm_static_capacity *equal,
                                double p_allow, int side, prsm_error *err)
{
	double F = equal->C0a_N; /* equal sharing: an upper bound of C_0a */
	for (int i = 0; i < 30; i++) {
		const double pm = peak_pressure(ws, p, F, side, err);
		if (!isfinite(pm))
			return err->code ? err->code : PRSM_ENOCONVERGE;
		const double r = p_allow / pm, next = F * r * r * r;
		if (fabs(next - F) <= 1e-12 * F) {
			*out_N = next;
			return 0;
		}
		F = next;
	}
	const double hi0 = equal->C0a_N; /* bisection in log F between a bracket */
	double lo = hi0, hi = hi0;
	for (;; lo *= 0.5) {
		const double pm = peak_pressure(ws, p, lo, side, err);
		if (!isfinite(pm))
			return err->code ? err->code : PRSM_ENOCONVERGE;
		if (pm <= p_allow || lo < 1e-9 * hi0)
			break;
	}
	for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; i++) {
		const double mid = sqrt(lo * hi);
		const double pm = peak_pressure(ws, p, mid, side, err);
		if (!isfinite(pm))
			return err->code ? err->code : PRSM_ENOCONVERGE;
		if (pm > p_allow)
			hi = mid;
		else
			lo = mid;
	}
	*out_N = 0.5 * (lo + hi);
	return 0;
}

/* The ellipse truncation of both sides (model/rating.h) and, at the operating load, of the
 * most loaded contact of each side. */
static int truncation(prsm_performance *out, const prsm_design *d, const prsm_analysis *a,
                      const prsm_loaddist_params *p, prsm_error *err)
{
	prsm_truncation_check *tc[2] = {&out->truncation_screw, &out->truncation_nut};
	const prsm_contact *c[2] = {&a->screw, &a->nut};
	const int loaded = fabs(d->axial_load_N) > 0.0;
	for (int s = 0; s < 2; s++) {
		int rc = prsm_rating_truncation(&tc[s]->t, d, c[s], &p->side[s].reference, s, err);
		if (rc)
			return rc;
		tc[s]->truncated_at_C0a = tc[s]->t.p_limit_MPa < d->life.p_allow_MPa;
		if (loaded) {
			const double q = out->dist.side[s].max_normal_N;
			tc[s]->operating_axis_mm = prsm_truncation_profile_axis_mm(&tc[s]->t, q);
			tc[s]->truncated_operating = q > tc[s]->t.q_limit_N;
		}
	}
	return 0;
}

static int capacity_and_life(prsm_performance *out, const prsm_design *d, const prsm_analysis *a,
                             prsm_loaddist_workspace *ws, const prsm_loaddist_params *p,
                             prsm_error *err)
{
	const prsm_design_life *L = &d->life;
	const double F = fabs(d->axial_load_N);
	int rc;
	/* static: the equal-sharing figure per side (model/life.h), then the distribution's */
	const int contacts = d->rollers * d->engaged_threads;
	prsm_hertz href[2] = {p->side[0].reference, p->side[1].reference};
	if ((rc = prsm_life_static_capacity(&out->static_screw, &href[0], p->side[0].axial_component,
	                                    contacts, 1.0, L->p_allow_MPa, err)) ||
	    (rc = prsm_life_static_capacity(&out->static_nut, &href[1], p->side[1].axial_component,
	                                    contacts, 1.0, L->p_allow_MPa, err)))
		return rc;
	if ((rc = static_capacity_side(&out->C0a_pressure_screw_N, ws, p, &out->static_screw,
	                               L->p_allow_MPa, PRSM_SIDE_SCREW, err)) ||
	    (rc = static_capacity_side(&out->C0a_pressure_nut_N, ws, p, &out->static_nut,
	                               L->p_allow_MPa, PRSM_SIDE_NUT, err)))
		return rc;
	out->static_screw.load_factor = out->static_screw.C0a_N / out->C0a_pressure_screw_N;
	out->static_nut.load_factor = out->static_nut.C0a_N / out->C0a_pressure_nut_N;
	out->C0a_pressure_N = fmin(out->C0a_pressure_screw_N, out->C0a_pressure_nut_N);
	/* the ellipse truncation limits C_0a (model/rating.h): the load at which the most loaded
	 * contact reaches the lower of p_allow and p_limit, solved again only when p_limit is lower */
	if ((rc = truncation(out, d, a, p, err)))
		return rc;
	out->C0a_screw_N = out->C0a_pressure_screw_N;
	out->C0a_nut_N = out->C0a_pressure_nut_N;
	const prsm_truncation *tr[2] = {&out->truncation_screw.t, &out->truncation_nut.t};
	double *side_N[2] = {&out->C0a_screw_N, &out->C0a_nut_N};
	const prsm_static_capacity *equal[2] = {&out->static_screw, &out->static_nut};
	for (int s = 0; s < 2; s++)
		if (tr[s]->p_limit_MPa < L->p_allow_MPa &&
		    (rc = static_capacity_side(side_N[s], ws, p, equal[s], tr[s]->p_limit_MPa, s, err)))
			return rc;
	out->C0a_N = fmin(out->C0a_screw_N, out->C0a_nut_N);
	out->C0a_truncation_limited = out->C0a_N < out->C0a_pressure_N;
	out->static_safety = F > 0.0 ? out->C0a_N / F : INFINITY;

	/* dynamic: L-P with the distribution factor of the thread rows at the operating load */
	out->distribution_factor = 1.0;
	if (F > 0.0) {
		const double fs = prsm_life_distribution_factor(out->thread_load_screw_N, (size_t)out->threads, 10.0 / 3.0);
		const double fn = prsm_life_distribution_factor(out->thread_load_nut_N, (size_t)out->threads, 10.0 / 3.0);
		out->distribution_factor = fmin(fs, fn);
	}
	prsm_lp_method m = PRSM_LP_METHOD_INIT;
	m.material_factor = L->lp_material_factor;
	if ((rc = prsm_life_dynamic_capacity(&out->dynamic, d, &m, out->distribution_factor, err)))
		return rc;
	out->C0a_over_C_a = out->C0a_N / out->dynamic.C_a_N;
	/* the makers' convention: equal sharing everywhere (model/rating.h, MODEL.md §6) */
	prsm_dynamic_capacity equal_dynamic;
	if ((rc = prsm_life_dynamic_capacity(&equal_dynamic, d, &m, 1.0, err)) ||
	    (rc = prsm_rating_makers(&out->makers, out->static_screw.C0a_N, out->static_nut.C0a_N,
	                             &out->truncation_screw.t, &out->truncation_nut.t, L->p_allow_MPa,
	                             contacts, equal_dynamic.C_a_N, err)))
		return rc;

	/* life: cubic mean of the duty cycle (or the operating load), preload, reliability */
	if (L->duty_steps > 0) {
		if ((rc = prsm_life_cubic_mean_load(&out->mean_load_N, L->duty_load_N, L->duty_travel_mm,
		                                    (size_t)L->duty_steps, err)))
			return rc;
	} else {
		out->mean_load_N = F;
	}
	out->equivalent_load_N = out->mean_load_N;
	if (L->preload_N > 0.0 &&
	    (rc = prsm_life_preload_load(&out->equivalent_load_N, out->mean_load_N, L->preload_N, err)))
		return rc;
	const double rpm = fabs(d->screw_speed_rad_s) * 60.0 / (2.0 * M_PI);
	if (out->equivalent_load_N > 0.0) {
		if ((rc = prsm_life_l10(&out->life, out->dynamic.C_a_N, out->equivalent_load_N, rpm,
		                        prsm_design_lead_mm(d), L->reliability_percent, err)))
			return rc;
	} else { /* no load: no fatigue */
		out->life.capacity_N = out->dynamic.C_a_N;
		out->life.reliability_percent = L->reliability_percent;
		out->life.revolutions = out->life.hours = out->life.distance_km = INFINITY;
		prsm_life_reliability_factor(&out->life.reliability_factor, L->reliability_percent, err);
	}
	if (L->column) {
		out->has_column = 1;
		if ((rc = prsm_life_column(&out->column, 2.0 * d->screw_root_radius_mm, L->free_length_mm,
		                           L->fixity, d->screw_material.E_MPa,
		                           d->screw_material.density_kg_m3, err)))
			return rc;
	}
	return 0;
}

int prsm_performance_compute(prsm_performance *out, const prsm_design *d, const prsm_analysis *a,
                             prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const int nt = d->engaged_threads;
	const double F = fabs(d->axial_load_N);
	prsm_loaddist_params p;
	int rc = chain_params(&p, &out->compliance, &out->segments, d, a, err);
	if (rc)
		return rc;
	out->threads = nt;
	out->thread_load_screw_N = calloc((size_t)nt, sizeof(double));
	out->thread_load_nut_N = calloc((size_t)nt, sizeof(double));
	out->thread_normal_screw_N = calloc((size_t)nt, sizeof(double));
	out->thread_normal_nut_N = calloc((size_t)nt, sizeof(double));
	prsm_loaddist_workspace *ws = prsm_loaddist_alloc(nt);
	if (!out->thread_load_screw_N || !out->thread_load_nut_N || !out->thread_normal_screw_N ||
	    !out->thread_normal_nut_N || !ws) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the load distribution");
		goto cleanup;
	}
	/* load distribution and stiffness at the operating load (docs/model/kinematics-efficiency-stiffness-life.md) */
	if (F > 0.0) {
		if ((rc = prsm_loaddist_solve(&out->dist, ws, &p, F, err)))
			goto cleanup;
		memcpy(out->thread_load_screw_N, out->dist.axial_screw_N, (size_t)nt * sizeof(double));
		memcpy(out->thread_load_nut_N, out->dist.axial_nut_N, (size_t)nt * sizeof(double));
		memcpy(out->thread_normal_screw_N, out->dist.normal_screw_N, (size_t)nt * sizeof(double));
		memcpy(out->thread_normal_nut_N, out->dist.normal_nut_N, (size_t)nt * sizeof(double));
		out->stiffness_N_per_um = out->dist.stiffness_N_per_mm * 1e-3;
		/* efficiency with every loss, spin at the distributed loads (docs/model/kinematics-efficiency-stiffness-life.md) */
		rc = torque_with_losses(&out->losses, d, a, &out->dist, err);
	} else {
		rc = torque_with_losses(&out->losses, d, a, NULL, err);
	}
	out->dist.axial_screw_N = out->dist.axial_nut_N = NULL; /* they point into ws */
	out->dist.normal_screw_N = out->dist.normal_nut_N = NULL;
	if (rc)
		goto cleanup;
	if ((rc = capacity_and_life(out, d, a, ws, &p, err)))
		goto cleanup;

	/* the load-deflection curve, on request */
	if (d->stiffness.curve_points > 0) {
		const size_t n = (size_t)d->stiffness.curve_points;
		double fmax = d->stiffness.curve_max_load_N;
		if (isnan(fmax))
			fmax = F > 0.0 ? 2.0 * F : out->C0a_N;
		out->curve_points = (int)n;
		out->curve_load_N = calloc(n, sizeof(double));
		out->curve_approach_um = calloc(n, sizeof(double));
		out->curve_stiffness_N_per_um = calloc(n, sizeof(double));
		if (!out->curve_load_N || !out->curve_approach_um || !out->curve_stiffness_N_per_um) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the load-deflection curve");
			goto cleanup;
		}
		if ((rc = prsm_loaddist_curve(out->curve_load_N, out->curve_approach_um,
		                              out->curve_stiffness_N_per_um, ws, &p, fmax, n, err)))
			goto cleanup;
		for (size_t i = 0; i < n; i++) {
			out->curve_approach_um[i] *= 1e3;
			out->curve_stiffness_N_per_um[i] *= 1e-3;
		}
	}
cleanup:
	prsm_loaddist_free(ws);
	return rc;
}

void prsm_performance_free(prsm_performance *p)
{
	free(p->thread_load_screw_N);
	free(p->thread_load_nut_N);
	free(p->thread_normal_screw_N);
	free(p->thread_normal_nut_N);
	free(p->curve_load_N);
	free(p->curve_approach_um);
	free(p->curve_stiffness_N_per_um);
	p->thread_load_screw_N = p->thread_load_nut_N = NULL;
	p->thread_normal_screw_N = p->thread_normal_nut_N = NULL;
	p->curve_load_N = p->curve_approach_um = p->curve_stiffness_N_per_um = NULL;
}

double prsm_performance_input_torque(const prsm_design *d, const prsm_analysis *a)
{
	prsm_error err = PRSM_ERROR_INIT;
	prsm_loaddist_params p;
	prsm_design_compliance tc;
	prsm_segment_compliance seg;
	prsm_losses_result r;
	if (chain_params(&p, &tc, &seg, d, a, &err))
		return NAN;
	const double F = fabs(d->axial_load_N);
	int rc;
	if (F > 0.0) {
		prsm_loaddist_workspace *ws = prsm_loaddist_alloc(d->engaged_threads);
		prsm_loaddist_result dist;
		if (ws == NULL)
			return NAN;
		rc = prsm_loaddist_solve(&dist, ws, &p, F, &err);
		if (rc == 0)
			rc = torque_with_losses(&r, d, a, &dist, &err);
		prsm_loaddist_free(ws);
	} else {
		rc = torque_with_losses(&r, d, a, NULL, &err);
	}
	return rc ? NAN : r.input_torque_Nm;
}

int prsm_performance_normal_loads(double *screw_N, double *nut_N, const prsm_design *d,
                                  const prsm_analysis *a, prsm_error *err)
{
	const int nt = d->engaged_threads;
	const double F = fabs(d->axial_load_N);
	prsm_loaddist_params p;
	prsm_design_compliance tc;
	prsm_segment_compliance seg;
	int rc = chain_params(&p, &tc, &seg, d, a, err);
	if (rc)
		return rc;
	if (!(F > 0.0)) {
		for (int i = 0; i < nt; i++)
			screw_N[i] = nut_N[i] = 0.0;
		return 0;
	}
	prsm_loaddist_workspace *ws = prsm_loaddist_alloc(nt);
	if (ws == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the load distribution");
	prsm_loaddist_result dist;
	rc = prsm_loaddist_solve(&dist, ws, &p, F, err);
	if (rc == 0) {
		memcpy(screw_N, dist.normal_screw_N, (size_t)nt * sizeof(double));
		memcpy(nut_N, dist.normal_nut_N, (size_t)nt * sizeof(double));
	}
	prsm_loaddist_free(ws);
	return rc;
}
