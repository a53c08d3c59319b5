/*
 * vib_shoot.c: periodic orbits by shooting (docs/model §8.4 "Periodic orbits"): Newton on
 * P^m(r) - r in the reduced (Poincaré) coordinates, where P is the map over one forcing period
 * from phase 0, with the monodromy matrix from the variational equations integrated with the state
 * (dead-zone crossings located, so the monodromy is exact to the integration tolerance). The
 * Floquet multipliers are the eigenvalues of the monodromy at the solution; a multiplier crossing
 * +1 marks a fold, -1 a period doubling.
 */
#include "dyn/vib_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>

/* One shot: from the reduced r over m periods; F = P^m(r) - r and Phi (nr x nr, row-major). */
static int shot(vib_int *it, double T, int m, const double *r, double *F, double *Phi, double *ybuf)
{
	const vib_core *c = it->c;
	const int n = it->n, nr = vib_reduced_size(c);
	memset(ybuf, 0, (size_t)it->dim * sizeof *ybuf);
	vib_lift(c, r, ybuf);
	for (int i = 0; i < nr; i++) {
		double e[PRSM_VIB_STATE_MAX] = {0};
		e[i] = 1.0;
		vib_lift(c, e, ybuf + (size_t)(1 + i) * n);
	}
	vib_int_set(it, 0.0, ybuf);
	const int rc = vib_int_advance(it, m * T);
	if (rc)
		return rc;
	double p[PRSM_VIB_STATE_MAX];
	vib_project(c, it->y, p);
	for (int i = 0; i < nr; i++)
		F[i] = p[i] - r[i];
	for (int j = 0; j < nr; j++) {
		vib_project(c, it->y + (size_t)(1 + j) * n, p);
		for (int i = 0; i < nr; i++)
			Phi[(size_t)i * nr + j] = p[i];
	}
	return 0;
}

static double norm_inf(const double *v, int n)
{
	double r = 0.0;
	for (int i = 0; i < n; i++)
		r = fmax(r, fabs(v[i]));
	return r;
}

int prsm_vib_periodic_orbit(prsm_vib_orbit *out, const prsm_vib_model *m, const double *guess, int period,
                            const prsm_vib_integration *integ, const prsm_cancel_flag *cancel, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const prsm_vib_integration idef = PRSM_VIB_INTEGRATION_INIT;
	if (integ == NULL)
		integ = &idef;
	if (period < 1 || period > PRSM_VIB_PERIOD_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/orbit/period", "the period is 1 to %d forcing periods",
		                      PRSM_VIB_PERIOD_MAX);
	const vib_core *c = &m->c;
	const int n = c->n, nr = vib_reduced_size(c);
	const int axial_only = !c->pair && !c->gear;
	const int obs = axial_only ? PRSM_VIB_OBS_AXIAL_DEFLECTION : PRSM_VIB_OBS_MESH_DEFLECTION;
	const double T = prsm_vib_period(m, prsm_vib_clock_of(m, PRSM_VIB_CLOCK_AUTO, obs));
	if (!(T > 0.0 && isfinite(T)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/orbit", "the forcing has no period");
	prsm_vib_integration li = *integ;
	if (li.locate_kinks == PRSM_VIB_LOCATE_NEVER)
		li.locate_kinks = PRSM_VIB_LOCATE_AUTO;
	vib_int it;
	if (vib_int_init(&it, m, nr, 1, &li, cancel))
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the variational equations");
	double *ybuf = calloc((size_t)it.dim, sizeof *ybuf);
	double *Phi = malloc((size_t)nr * nr * sizeof *Phi);
	gsl_matrix *J = gsl_matrix_alloc((size_t)nr, (size_t)nr);
	gsl_vector *b = gsl_vector_alloc((size_t)nr), *dx = gsl_vector_alloc((size_t)nr);
	gsl_permutation *perm = gsl_permutation_alloc((size_t)nr);
	int rc = 0;
	if (!ybuf || !Phi || !J || !b || !dx || !perm) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the shooting");
		goto cleanup;
	}
	double y0[PRSM_VIB_STATE_MAX], r[PRSM_VIB_STATE_MAX], F[PRSM_VIB_STATE_MAX];
	if (guess != NULL)
		memcpy(y0, guess, (size_t)n * sizeof *y0);
	else
		prsm_vib_static_state(m, y0);
	vib_project(c, y0, r);
	out->period = period;
	if ((rc = shot(&it, T, period, r, F, Phi, ybuf)))
		goto fail;
	double res = norm_inf(F, nr);
	for (int iter = 0; iter < 40; iter++) {
		out->iterations = iter;
		if (res <= 1e-11 * fmax(1.0, norm_inf(r, nr)))
			break;
		for (int i = 0; i < nr; i++) {
			for (int j = 0; j < nr; j++)
				gsl_matrix_set(J, (size_t)i, (size_t)j, Phi[(size_t)i * nr + j] - (i == j ? 1.0 : 0.0));
			gsl_vector_set(b, (size_t)i, -F[i]);
		}
		int sg;
		gsl_linalg_LU_decomp(J, perm, &sg);
		if (gsl_linalg_LU_solve(J, perm, b, dx) != 0)
			break; /* singular: a fold exactly here; report not converged */
		/* backtracking on the residual */
		double lambda = 1.0, r_try[PRSM_VIB_STATE_MAX];
		int accepted = 0;
		for (int bt = 0; bt < 12; bt++) {
			for (int i = 0; i < nr; i++)
				r_try[i] = r[i] + lambda * gsl_vector_get(dx, (size_t)i);
			double F_try[PRSM_VIB_STATE_MAX];
			rc = shot(&it, T, period, r_try, F_try, Phi, ybuf);
			if (rc == PRSM_ECANCELLED)
				goto fail;
			if (rc == 0 && norm_inf(F_try, nr) < res * (1.0 - 1e-4 * lambda)) {
				memcpy(r, r_try, (size_t)nr * sizeof *r);
				memcpy(F, F_try, (size_t)nr * sizeof *F);
				res = norm_inf(F, nr);
				accepted = 1;
				break;
			}
			rc = 0;
			lambda *= 0.5;
		}
		if (!accepted) {
			/* restore Phi at r */
			if ((rc = shot(&it, T, period, r, F, Phi, ybuf)))
				goto fail;
			break;
		}
	}
	out->residual = res;
	out->converged = res <= 1e-9 * fmax(1.0, norm_inf(r, nr));
	memset(y0, 0, sizeof y0);
	vib_lift(c, r, y0);
	memcpy(out->state, y0, (size_t)n * sizeof *y0);
	/* Floquet multipliers: the eigenvalues of the monodromy */
	{
		gsl_matrix *A = gsl_matrix_alloc((size_t)nr, (size_t)nr);
		gsl_vector_complex *ev = gsl_vector_complex_alloc((size_t)nr);
		gsl_eigen_nonsymm_workspace *ws = gsl_eigen_nonsymm_alloc((size_t)nr);
		if (!A || !ev || !ws) {
			gsl_matrix_free(A);
			gsl_vector_complex_free(ev);
			if (ws != NULL)
				gsl_eigen_nonsymm_free(ws);
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
			goto cleanup;
		}
		for (int i = 0; i < nr; i++)
			for (int j = 0; j < nr; j++)
				gsl_matrix_set(A, (size_t)i, (size_t)j, Phi[(size_t)i * nr + j]);
		const int erc = gsl_eigen_nonsymm(A, ev, ws);
		out->multipliers = erc == 0 ? nr : 0;
		for (int i = 0; i < out->multipliers; i++) {
			const gsl_complex z = gsl_vector_complex_get(ev, (size_t)i);
			out->multiplier_re[i] = GSL_REAL(z);
			out->multiplier_im[i] = GSL_IMAG(z);
		}
		/* largest |mu| first */
		for (int i = 1; i < out->multipliers; i++)
			for (int j = i; j > 0 && hypot(out->multiplier_re[j], out->multiplier_im[j]) >
			                             hypot(out->multiplier_re[j - 1], out->multiplier_im[j - 1]); j--) {
				double t = out->multiplier_re[j];
				out->multiplier_re[j] = out->multiplier_re[j - 1];
				out->multiplier_re[j - 1] = t;
				t = out->multiplier_im[j];
				out->multiplier_im[j] = out->multiplier_im[j - 1];
				out->multiplier_im[j - 1] = t;
			}
		out->lambda_max = out->multipliers > 0
		                      ? log(hypot(out->multiplier_re[0], out->multiplier_im[0])) / (period * T)
		                      : NAN;
		gsl_matrix_free(A);
		gsl_vector_complex_free(ev);
		gsl_eigen_nonsymm_free(ws);
	}
	/* extremes of the observable over the orbit (refined at the zeros of its rate) */
	{
		prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
		so.transient_periods = 0;
		so.recorded_periods = period < 2 ? 2 : period;
		so.observable = obs;
		so.clock = PRSM_VIB_CLOCK_AUTO;
		so.integration = *integ;
		prsm_vib_steady s;
		const int src = prsm_vib_steady_state(&s, m, out->state, &so, cancel, err);
		if (src) {
			rc = src;
			goto cleanup;
		}
		for (int i = 0; i < s.extremes; i++)
			if (s.extreme[i].observable == obs && s.extreme[i].index == 0) {
				out->min = s.extreme[i].min;
				out->max = s.extreme[i].max;
				break;
			}
		prsm_vib_steady_free(&s);
	}
	goto cleanup;
fail:
	vib_int_error(&it, rc, err);
cleanup:
	vib_int_free(&it);
	free(ybuf);
	free(Phi);
	gsl_matrix_free(J);
	gsl_vector_free(b);
	gsl_vector_free(dx);
	gsl_permutation_free(perm);
	return rc;
}

/* the largest real multiplier (the one that reaches +1 at a fold) */
static double real_multiplier(const prsm_vib_orbit *o)
{
	double best = -INFINITY;
	for (int i = 0; i < o->multipliers; i++)
		if (fabs(o->multiplier_im[i]) < 1e-9)
			best = fmax(best, o->multiplier_re[i]);
	return best;
}

int prsm_vib_fold_track(prsm_vib_exact_fold *out, const prsm_vib_model *m, const double *state, int period,
                        double from, double to, const prsm_vib_integration *integ, const prsm_cancel_flag *cancel,
                        prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->omega = NAN;
	out->period = period;
	prsm_vib_model *mm = prsm_vib_model_copy(m);
	if (mm == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	int rc = vib_model_set(mm, PRSM_VIB_PARAM_FREQUENCY_RATIO, from, err);
	prsm_vib_orbit o;
	if (rc == 0)
		rc = prsm_vib_periodic_orbit(&o, mm, state, period, integ, cancel, err);
	out->orbits = 1;
	if (rc || !o.converged) {
		prsm_vib_model_free(mm);
		return rc;
	}
	double W = from, mu = real_multiplier(&o), Wp = NAN, mup = NAN;
	double y[PRSM_VIB_STATE_MAX];
	memcpy(y, o.state, sizeof y);
	double amp = 0.5 * (o.max - o.min);
	double h = 0.5 * (to - from);
	while (fabs(h) > 1e-7) {
		const double W1 = W + h;
		if ((rc = vib_model_set(mm, PRSM_VIB_PARAM_FREQUENCY_RATIO, W1, err)))
			break;
		prsm_vib_orbit o1;
		rc = prsm_vib_periodic_orbit(&o1, mm, y, period, integ, cancel, err);
		out->orbits++;
		if (rc == PRSM_ECANCELLED)
			break;
		const double a1 = 0.5 * (o1.max - o1.min);
		const int same = rc == 0 && o1.converged && fabs(a1 - amp) <= 0.2 * fmax(amp, 1e-12) + 1e-9 &&
		                 real_multiplier(&o1) < 1.0 + 1e-6;
		rc = 0;
		if (same && ((h > 0.0 && W1 <= fmax(from, to)) || (h < 0.0 && W1 >= fmin(from, to)))) {
			Wp = W;
			mup = mu;
			W = W1;
			mu = real_multiplier(&o1);
			memcpy(y, o1.state, sizeof y);
			amp = a1;
		} else {
			h *= 0.5;
		}
	}
	prsm_vib_model_free(mm);
	if (rc)
		return rc;
	out->last_omega = W;
	out->last_multiplier = mu;
	out->amplitude = amp;
	out->found = fabs(W - to) > 1e-6 * fmax(1.0, fabs(to));
	out->omega = W;
	if (out->found && !isnan(Wp) && mu < 1.0 && mup < 1.0) {
		const double q = (1.0 - mu) * (1.0 - mu), qp = (1.0 - mup) * (1.0 - mup);
		if (qp != q) {
			const double Wf = W + q * (W - Wp) / (qp - q);
			if (fabs(Wf - W) < 10.0 * fabs(W - Wp) + 1e-6)
				out->omega = Wf;
		}
	}
	return 0;
}
