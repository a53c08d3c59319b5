/*
 * calib.c: the line model and the physical model calibrated on a measured TE curve, their
 * uncertainty and identifiability caveats, friction from a measured efficiency and carrier drag
 * from a measured cage ratio (MODEL-DYNAMICS.md §8.5 items 3 and 4; see calib.h).
 */
#include "dyn/calib.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_vector.h>
#include <nlopt.h>

#include "model/performance.h"
#include "util/problems.h"

#define PMAX (PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX)

static const char *const line_names[PRSM_CALIB_LINE_KINDS] = {"screw_rev",         "screw",           "carrier",
                                                              "roller_spin",       "roller_pass_nut", "roller_pass_screw",
                                                              "mesh"};

const char *prsm_calib_line_name(int kind)
{
	return kind >= 0 && kind < PRSM_CALIB_LINE_KINDS ? line_names[kind] : "?";
}

/* §8.5 item 2: the named orders as functions of the carrier ratio k */
void prsm_calib_order_coefficients(double *alpha, double *beta, int kind, const prsm_calib_kinematics *kin)
{
	switch (kind) {
	case PRSM_CALIB_LINE_SCREW_REV: *alpha = 1.0; *beta = 0.0; break;
	case PRSM_CALIB_LINE_SCREW: *alpha = 1.0; *beta = -1.0; break;
	case PRSM_CALIB_LINE_CARRIER: *alpha = 0.0; *beta = 1.0; break;
	case PRSM_CALIB_LINE_ROLLER_SPIN: *alpha = 0.0; *beta = kin->ring_gear_ratio; break;
	case PRSM_CALIB_LINE_ROLLER_PASS_NUT: *alpha = 0.0; *beta = kin->rollers; break;
	case PRSM_CALIB_LINE_ROLLER_PASS_SCREW: *alpha = kin->rollers; *beta = -kin->rollers; break;
	default: *alpha = 0.0; *beta = kin->ring_gear_teeth; break;
	}
}

int prsm_calib_options_init(prsm_calib_options *o)
{
	memset(o, 0, sizeof *o);
	o->model = PRSM_CALIB_MODEL_LINE;
	o->lines_mask = PRSM_CALIB_LINES_DEFAULT;
	o->carrier_ratio_prior = NAN;
	o->grid_half_width = 0.025;
	o->grid_points = 2001;
	o->refine = PRSM_CALIB_REFINE_BOBYQA;
	o->autocorrelation_limit = 0.2;
	o->mode = PRSM_MODE_LINEAR;
	o->measuring_load_N = 50.0;
	o->max_evaluations = 2000;
	return 0;
}

void prsm_calib_fit_free(prsm_calib_fit *f)
{
	free(f->residual_um);
	f->residual_um = NULL;
}

void prsm_calib_line_free(prsm_calib_line_result *r)
{
	prsm_calib_fit_free(&r->fit);
}

void prsm_calib_physical_free(prsm_calib_physical_result *r)
{
	prsm_calib_fit_free(&r->fit);
}

static void caveat(prsm_calib_fit *f, int code, int triggered, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void caveat(prsm_calib_fit *f, int code, int triggered, const char *fmt, ...)
{
	if (f->caveats >= PRSM_CALIB_CAVEATS_MAX)
		return;
	prsm_calib_caveat *c = &f->caveat[f->caveats++];
	c->code = code;
	c->triggered = triggered;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(c->message, sizeof c->message, fmt, ap);
	va_end(ap);
}

/* ---- linear algebra ---- */

/* Least squares J delta = r (n x p, row-major) by the SVD, singular values below 1e-13 of the
 * largest dropped. Returns 0 or PRSM_ENOMEM. */
static int svd_solve(double *delta, const double *J, const double *r, size_t n, int p)
{
	gsl_matrix *A = gsl_matrix_alloc(n, (size_t)p), *V = gsl_matrix_alloc((size_t)p, (size_t)p);
	gsl_vector *S = gsl_vector_alloc((size_t)p), *w = gsl_vector_alloc((size_t)p);
	int rc = 0;
	if (!A || !V || !S || !w) {
		rc = PRSM_ENOMEM;
		goto done;
	}
	memcpy(A->data, J, n * (size_t)p * sizeof(double));
	gsl_linalg_SV_decomp(A, V, S, w);
	const double smax = gsl_vector_get(S, 0);
	for (int j = 0; j < p; j++)
		delta[j] = 0.0;
	for (int k = 0; k < p; k++) {
		const double s = gsl_vector_get(S, (size_t)k);
		if (!(s > 1e-13 * smax))
			continue;
		double ur = 0.0;
		for (size_t i = 0; i < n; i++)
			ur += gsl_matrix_get(A, i, (size_t)k) * r[i];
		for (int j = 0; j < p; j++)
			delta[j] += gsl_matrix_get(V, (size_t)j, (size_t)k) * ur / s;
	}
done:
	gsl_matrix_free(A);
	gsl_matrix_free(V);
	gsl_vector_free(S);
	gsl_vector_free(w);
	return rc;
}

/* (J^T J)^-1 by the SVD into cov (p x p; infinite on the diagonal along a null direction) and
 * the condition numbers of J^T J raw and with unit-norm columns. */
static int covariance(double *cov, double *cond, double *cond_scaled, const double *J, size_t n, int p)
{
	gsl_matrix *A = gsl_matrix_alloc(n, (size_t)p), *V = gsl_matrix_alloc((size_t)p, (size_t)p);
	gsl_vector *S = gsl_vector_alloc((size_t)p), *w = gsl_vector_alloc((size_t)p);
	int rc = 0;
	if (!A || !V || !S || !w) {
		rc = PRSM_ENOMEM;
		goto done;
	}
	memcpy(A->data, J, n * (size_t)p * sizeof(double));
	gsl_linalg_SV_decomp(A, V, S, w);
	const double smax = gsl_vector_get(S, 0), smin = gsl_vector_get(S, (size_t)p - 1);
	*cond = smin > 0.0 ? (smax / smin) * (smax / smin) : INFINITY;
	for (int a = 0; a < p; a++)
		for (int b = 0; b < p; b++) {
			double c = 0.0;
			int null = 0;
			for (int k = 0; k < p; k++) {
				const double s = gsl_vector_get(S, (size_t)k);
				const double va = gsl_matrix_get(V, (size_t)a, (size_t)k), vb = gsl_matrix_get(V, (size_t)b, (size_t)k);
				if (!(s > 1e-14 * smax)) {
					if (fabs(va) > 1e-8 && fabs(vb) > 1e-8)
						null = 1;
					continue;
				}
				c += va * vb / (s * s);
			}
			cov[a * p + b] = null ? (a == b ? INFINITY : NAN) : c;
		}
	/* unit-norm columns */
	memcpy(A->data, J, n * (size_t)p * sizeof(double));
	for (int j = 0; j < p; j++) {
		double nn = 0.0;
		for (size_t i = 0; i < n; i++)
			nn += gsl_matrix_get(A, i, (size_t)j) * gsl_matrix_get(A, i, (size_t)j);
		nn = sqrt(nn);
		for (size_t i = 0; i < n && nn > 0.0; i++)
			gsl_matrix_set(A, i, (size_t)j, gsl_matrix_get(A, i, (size_t)j) / nn);
	}
	gsl_linalg_SV_decomp(A, V, S, w);
	const double t0 = gsl_vector_get(S, 0), t1 = gsl_vector_get(S, (size_t)p - 1);
	*cond_scaled = t1 > 0.0 ? (t0 / t1) * (t0 / t1) : INFINITY;
done:
	gsl_matrix_free(A);
	gsl_matrix_free(V);
	gsl_vector_free(S);
	gsl_vector_free(w);
	return rc;
}

/* §8.5 "Uncertainty": s, the covariance cov_out (p x p, s^2 (J^T J)^-1 times the inflation
 * squared), standard errors, correlation, condition numbers, r_1 and the inflation. */
static int uncertainty(prsm_calib_fit *f, double *cov_out, const double *J, size_t n, int p, double S, double limit)
{
	double cond = NAN, conds = NAN;
	int rc = covariance(cov_out, &cond, &conds, J, n, p);
	if (rc)
		return rc;
	f->params = p;
	f->points = n;
	f->sum_of_squares_um2 = S;
	const double s2 = S / (double)(n - (size_t)p);
	f->residual_sd_um = sqrt(s2);
	f->condition_number = cond;
	f->condition_number_scaled = conds;
	f->lag1_autocorrelation = prsm_meas_lag1(f->residual_um, n);
	const double r1 = f->lag1_autocorrelation;
	f->inflation = r1 > limit && r1 < 1.0 ? sqrt((1.0 + r1) / (1.0 - r1)) : 1.0;
	for (int a = 0; a < p * p; a++)
		cov_out[a] *= s2;
	for (int j = 0; j < p; j++) {
		f->standard_error_white[j] = sqrt(cov_out[j * p + j]);
		f->standard_error[j] = f->standard_error_white[j] * f->inflation;
	}
	for (int a = 0; a < p; a++)
		for (int b = 0; b < p; b++) {
			const double d = sqrt(cov_out[a * p + a] * cov_out[b * p + b]);
			f->correlation[a * p + b] = a == b ? 1.0 : (d > 0.0 && isfinite(d) ? cov_out[a * p + b] / d : NAN);
		}
	for (int a = 0; a < p * p; a++)
		cov_out[a] *= f->inflation * f->inflation;
	return 0;
}

/* ---- the line model ---- */

double prsm_calib_line_value(const double *p, int lines, const double *alpha, const double *beta, double theta,
                             double travel_mm, double *grad)
{
	const double k = p[2 + 2 * lines];
	double v = p[0] + p[1] * travel_mm / 300.0, dk = 0.0;
	for (int l = 0; l < lines; l++) {
		const double nu = alpha[l] + beta[l] * k;
		const double c = cos(nu * theta), s = sin(nu * theta);
		const double a = p[2 + 2 * l], b = p[3 + 2 * l];
		v += a * c + b * s;
		dk += beta[l] * theta * (-a * s + b * c);
		if (grad) {
			grad[2 + 2 * l] = c;
			grad[3 + 2 * l] = s;
		}
	}
	if (grad) {
		grad[0] = 1.0;
		grad[1] = travel_mm / 300.0;
		grad[2 + 2 * lines] = dk;
	}
	return v;
}

/* The profile S(k): the linear parameters by least squares (Householder QR). */
typedef struct {
	const prsm_meas_curve *c;
	int lines;
	const double *alpha, *beta;
	gsl_matrix *X;
	gsl_vector *tau, *y, *beta_lin, *res;
	int evaluations;
} profile_ws;

static double profile(profile_ws *w, double k, double *linear)
{
	const size_t n = w->c->n;
	const int q = 2 + 2 * w->lines;
	for (size_t i = 0; i < n; i++) {
		double *row = gsl_matrix_ptr(w->X, i, 0);
		const double th = w->c->angle_rad[i];
		row[0] = 1.0;
		row[1] = w->c->travel_mm[i] / 300.0;
		for (int l = 0; l < w->lines; l++) {
			const double ph = (w->alpha[l] + w->beta[l] * k) * th;
			row[2 + 2 * l] = cos(ph);
			row[3 + 2 * l] = sin(ph);
		}
	}
	w->evaluations++;
	gsl_linalg_QR_decomp(w->X, w->tau);
	gsl_linalg_QR_lssolve(w->X, w->tau, w->y, w->beta_lin, w->res);
	double S = 0.0;
	for (size_t i = 0; i < n; i++)
		S += gsl_vector_get(w->res, i) * gsl_vector_get(w->res, i);
	if (linear)
		for (int j = 0; j < q; j++)
			linear[j] = gsl_vector_get(w->beta_lin, (size_t)j);
	return S;
}

static double profile_nlopt(unsigned n, const double *x, double *grad, void *data)
{
	(void)n;
	(void)grad;
	return profile(data, x[0], NULL);
}

static double sum_sq_line(const prsm_meas_curve *c, const double *p, int lines, const double *alpha,
                          const double *beta, double *r)
{
	double S = 0.0;
	for (size_t i = 0; i < c->n; i++) {
		const double e = c->te_um[i] - prsm_calib_line_value(p, lines, alpha, beta, c->angle_rad[i], c->travel_mm[i], NULL);
		if (r)
			r[i] = e;
		S += e * e;
	}
	return S;
}

/* The caveats every line fit prints (§8.5), those this fit shows triggered. */
static void line_caveats(prsm_calib_line_result *r, double limit)
{
	prsm_calib_fit *f = &r->fit;
	const int L = r->lines, P = f->params;
	/* two lines closer than the resolution */
	char buf[256] = "";
	int close = 0;
	for (int a = 0; a < L; a++)
		for (int b = a + 1; b < L; b++) {
			const double d = fabs(r->order_per_rev[a] - r->order_per_rev[b]);
			if (d < r->resolution_per_rev) {
				close++;
				if (close == 1)
					snprintf(buf, sizeof buf, "%s (%.5g) and %s (%.5g) are %.3g apart", line_names[r->kind[a]],
					         r->order_per_rev[a], line_names[r->kind[b]], r->order_per_rev[b], d);
			}
		}
	if (close)
		caveat(f, PRSM_CALIB_CAVEAT_RESOLUTION, 1,
		       "lines closer than the resolution 1/N_rev = %.4g cycles per revolution cannot be separated: %s%s; "
		       "record more revolutions", r->resolution_per_rev, buf, close > 1 ? " (and more pairs)" : "");
	else
		caveat(f, PRSM_CALIB_CAVEAT_RESOLUTION, 0,
		       "two lines closer than the resolution 1/N_rev = %.4g cycles per revolution cannot be separated "
		       "(none are here)", r->resolution_per_rev);
	/* slope against low-order lines */
	double worst = 0.0;
	int wl = -1;
	for (int l = 0; l < L; l++)
		for (int j = 0; j < 2; j++) {
			const double c = fabs(f->correlation[1 * P + 2 + 2 * l + j]);
			if (c > worst) {
				worst = c;
				wl = l;
			}
		}
	int low = -1;
	for (int l = 0; l < L; l++)
		if (r->order_per_rev[l] * r->revolutions < 2.0)
			low = l;
	if (worst > 0.5 || low >= 0)
		caveat(f, PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER, 1,
		       "the slope and a low-order line trade off over this stroke: %s (order %.4g, %.3g cycles in the record, "
		       "correlation with the slope up to %.2f)", line_names[r->kind[low >= 0 ? low : wl]],
		       r->order_per_rev[low >= 0 ? low : wl], r->order_per_rev[low >= 0 ? low : wl] * r->revolutions, worst);
	else
		caveat(f, PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER, 0,
		       "a slope and a low-order line are correlated over a short stroke (here at most %.2f)", worst);
	caveat(f, PRSM_CALIB_CAVEAT_SCREW_RUNOUT, 0,
	       "the first harmonic of a screw run-out cancels among evenly spaced rollers (MODEL §4): it is invisible in TE, "
	       "and the screw and screw_rev lines do not measure it");
	caveat(f, PRSM_CALIB_CAVEAT_SAME_PART_ORDER, 0,
	       "each line is the sum of every error seen at its order: errors of one part at one order (run-out and tilt) "
	       "are one parameter");
	caveat(f, PRSM_CALIB_CAVEAT_ROLLER_SUM, 0,
	       "the individual rollers' errors at the roller_spin order combine into one vector sum");
	if (f->inflation > 1.0)
		caveat(f, PRSM_CALIB_CAVEAT_CORRELATED_RESIDUALS, 1,
		       "the residuals are correlated (lag-1 autocorrelation %.3f > %.2f): white-noise errors would be "
		       "optimistic, every standard error is inflated by %.4f", f->lag1_autocorrelation, limit, f->inflation);
	else
		caveat(f, PRSM_CALIB_CAVEAT_CORRELATED_RESIDUALS, 0,
		       "white-noise errors are optimistic when the residuals are correlated (lag-1 autocorrelation here %.3f, "
		       "the errors are inflated above %.2f)", f->lag1_autocorrelation, limit);
}

int prsm_calib_line(prsm_calib_line_result *out, const prsm_meas_curve *c, const prsm_calib_kinematics *kin,
                    const prsm_calib_options *o, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const size_t n = c->n;
	const double revs = prsm_meas_revolutions(c);
	const double nyq = 0.5 * (double)(n - 1) / revs; /* mean samples per revolution / 2 */
	const double k0 = o->carrier_ratio_prior;
	if (!(k0 > 0.0 && k0 < 1.0))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/calibrate/carrier_ratio_prior",
		                      "the carrier-ratio prior must lie in (0, 1) (got %g)", k0);
	if (o->grid_points < 3 || !(o->grid_half_width > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/calibrate/grid_points",
		                      "the grid on k needs at least 3 points and a positive half width");
	out->revolutions = revs;
	out->resolution_per_rev = 1.0 / revs;
	int no_teeth = 0;
	for (int kind = 0; kind < PRSM_CALIB_LINE_KINDS; kind++) {
		if (!(o->lines_mask & (1 << kind)))
			continue;
		if (kind == PRSM_CALIB_LINE_MESH && kin->ring_gear_teeth <= 0) {
			out->dropped_kind[out->dropped++] = kind; /* no z_2: no mesh order */
			no_teeth = 1;
			continue;
		}
		double al, be;
		prsm_calib_order_coefficients(&al, &be, kind, kin);
		/* the order at the prior below the Nyquist order, and no order twice; a line that
		 * crosses the Nyquist order within the grid aliases there, which is one of the side
		 * minima of S(k) the grid's global search is for (§8.5 item 3) */
		const double at_prior = al + be * k0;
		int dup = 0;
		for (int l = 0; l < out->lines && !dup; l++)
			dup = fabs(out->alpha[l] - al) < 1e-12 && fabs(out->beta[l] - be) < 1e-12;
		if (!(at_prior < nyq) || dup) {
			out->dropped_kind[out->dropped++] = kind;
			continue;
		}
		out->kind[out->lines] = kind;
		out->alpha[out->lines] = al;
		out->beta[out->lines] = be;
		out->lines++;
	}
	const int L = out->lines, q = 2 + 2 * L, P = q + 1;
	if (L == 0 && no_teeth && out->dropped == 1)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/calibrate/lines",
		                      "the mesh line needs the ring gear's teeth z_2 (losses.gear_teeth_ring or the default rule)");
	if (L == 0)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/calibrate/lines",
		                      "no line of the line model lies below the Nyquist order %.4g of the record", nyq);
	if (n < (size_t)P + 2)
		return prsm_error_set(err, PRSM_EINVAL, "/measured", "the line model has %d parameters: the curve needs more "
		                      "than %d points (got %zu)", P, P + 2, n);
	profile_ws w = {c, L, out->alpha, out->beta, NULL, NULL, NULL, NULL, NULL, 0};
	w.X = gsl_matrix_alloc(n, (size_t)q);
	w.tau = gsl_vector_alloc((size_t)q);
	w.y = gsl_vector_alloc(n);
	w.beta_lin = gsl_vector_alloc((size_t)q);
	w.res = gsl_vector_alloc(n);
	double *J = malloc(n * (size_t)P * sizeof(double));
	double *r = malloc(n * sizeof(double));
	out->fit.residual_um = malloc(n * sizeof(double));
	int rc = 0;
	nlopt_opt opt = NULL;
	if (!w.X || !w.tau || !w.y || !w.beta_lin || !w.res || !J || !r || !out->fit.residual_um) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the line model of %zu points", n);
		goto cleanup;
	}
	for (size_t i = 0; i < n; i++)
		gsl_vector_set(w.y, i, c->te_um[i]);
	/* 1. the global grid on k (§8.5: S(k) has side minima where a line aliases onto another) */
	out->carrier_ratio_prior = k0;
	out->grid_from = k0 - o->grid_half_width;
	out->grid_to = k0 + o->grid_half_width;
	out->grid_points = o->grid_points;
	const double dk = (out->grid_to - out->grid_from) / (o->grid_points - 1);
	double Sm2 = NAN, Sm1 = NAN;
	out->grid_best_S_um2 = INFINITY;
	for (int g = 0; g < o->grid_points; g++) {
		const double k = out->grid_from + g * dk;
		const double S = profile(&w, k, NULL);
		if (S < out->grid_best_S_um2) {
			out->grid_best_S_um2 = S;
			out->grid_best_k = k;
		}
		if (g >= 2 && Sm1 < Sm2 && Sm1 <= S)
			out->grid_local_minima++;
		Sm2 = Sm1;
		Sm1 = S;
	}
	/* 2. the bounded 1-D refinement of S(k) */
	double x[1] = {out->grid_best_k}, f_opt = 0.0;
	double lb[1] = {fmax(out->grid_from, out->grid_best_k - dk)}, ub[1] = {fmin(out->grid_to, out->grid_best_k + dk)};
	int refine = o->refine;
	for (int attempt = 0; attempt < 2; attempt++) {
		opt = nlopt_create(refine == PRSM_CALIB_REFINE_COBYLA ? NLOPT_LN_COBYLA : NLOPT_LN_BOBYQA, 1);
		if (opt == NULL) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the refinement of k");
			goto cleanup;
		}
		nlopt_set_min_objective(opt, profile_nlopt, &w);
		nlopt_set_lower_bounds(opt, lb);
		nlopt_set_upper_bounds(opt, ub);
		nlopt_set_xtol_abs1(opt, 1e-14);
		nlopt_set_ftol_rel(opt, 1e-15);
		nlopt_set_maxeval(opt, 500);
		nlopt_set_initial_step1(opt, 0.25 * dk);
		x[0] = out->grid_best_k;
		const nlopt_result nr = nlopt_optimize(opt, x, &f_opt);
		nlopt_destroy(opt);
		opt = NULL;
		out->refine_used = refine;
		if (nr > 0 || nr == NLOPT_ROUNDOFF_LIMITED)
			break;
		/* BOBYQA may refuse a one-dimensional problem: COBYLA then */
		refine = PRSM_CALIB_REFINE_COBYLA;
		x[0] = out->grid_best_k;
	}
	if (!(profile(&w, x[0], NULL) <= out->grid_best_S_um2))
		x[0] = out->grid_best_k;
	out->refined_k = x[0];
	out->refine_evaluations = w.evaluations - o->grid_points;
	/* 3. Gauss-Newton polish of every parameter (analytic Jacobian) */
	double p[PRSM_CALIB_PARAMS_MAX], trial[PRSM_CALIB_PARAMS_MAX], delta[PRSM_CALIB_PARAMS_MAX];
	profile(&w, x[0], p);
	p[q] = x[0];
	double S = sum_sq_line(c, p, L, out->alpha, out->beta, r);
	out->fit.converged = 0;
	for (int it = 0; it < 50 && !out->fit.converged; it++) {
		for (size_t i = 0; i < n; i++)
			prsm_calib_line_value(p, L, out->alpha, out->beta, c->angle_rad[i], c->travel_mm[i], J + i * (size_t)P);
		if (svd_solve(delta, J, r, n, P)) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the Gauss-Newton step");
			goto cleanup;
		}
		double t = 1.0, St = INFINITY;
		for (int h = 0; h < 30; h++, t *= 0.5) {
			for (int j = 0; j < P; j++)
				trial[j] = p[j] + t * delta[j];
			St = sum_sq_line(c, trial, L, out->alpha, out->beta, NULL);
			if (St <= S)
				break;
		}
		out->fit.gauss_newton_iterations = it + 1;
		int small = 1;
		for (int j = 0; j < P; j++)
			small = small && fabs(t * delta[j]) <= 1e-10 * (fabs(p[j]) + (j == q ? 1.0 : 1e-3));
		if (St <= S) {
			memcpy(p, trial, sizeof(double) * (size_t)P);
			S = sum_sq_line(c, p, L, out->alpha, out->beta, r);
		} else {
			small = 1; /* no descent left along the Gauss-Newton direction: at the minimum to rounding */
		}
		out->fit.converged = small;
	}
	memcpy(out->fit.residual_um, r, n * sizeof(double));
	for (size_t i = 0; i < n; i++)
		prsm_calib_line_value(p, L, out->alpha, out->beta, c->angle_rad[i], c->travel_mm[i], J + i * (size_t)P);
	double cov[PRSM_CALIB_PARAMS_MAX * PRSM_CALIB_PARAMS_MAX];
	if ((rc = uncertainty(&out->fit, cov, J, n, P, S, o->autocorrelation_limit))) {
		rc = prsm_error_set(err, rc, NULL, "out of memory for the covariance");
		goto cleanup;
	}
	/* names, estimates, amplitudes and phases (delta method) */
	snprintf(out->fit.name[0], PRSM_CALIB_NAME_MAX, "offset");
	snprintf(out->fit.unit[0], 16, "um");
	snprintf(out->fit.name[1], PRSM_CALIB_NAME_MAX, "slope");
	snprintf(out->fit.unit[1], 16, "um/300mm");
	for (int l = 0; l < L; l++) {
		snprintf(out->fit.name[2 + 2 * l], PRSM_CALIB_NAME_MAX, "%s_cos", line_names[out->kind[l]]);
		snprintf(out->fit.name[3 + 2 * l], PRSM_CALIB_NAME_MAX, "%s_sin", line_names[out->kind[l]]);
		snprintf(out->fit.unit[2 + 2 * l], 16, "um");
		snprintf(out->fit.unit[3 + 2 * l], 16, "um");
		const double a = p[2 + 2 * l], b = p[3 + 2 * l], A = hypot(a, b);
		const int ia = 2 + 2 * l, ib = 3 + 2 * l;
		const double vaa = cov[ia * P + ia], vbb = cov[ib * P + ib], vab = cov[ia * P + ib];
		out->order_per_rev[l] = out->alpha[l] + out->beta[l] * p[q];
		out->amplitude_um[l] = A;
		out->phase_rad[l] = atan2(b, a);
		if (A > 0.0) {
			out->amplitude_se_um[l] = sqrt(fmax(0.0, (a * a * vaa + 2 * a * b * vab + b * b * vbb) / (A * A)));
			out->phase_se_rad[l] = sqrt(fmax(0.0, (b * b * vaa - 2 * a * b * vab + a * a * vbb) / (A * A * A * A)));
		} else {
			out->amplitude_se_um[l] = sqrt(0.5 * (vaa + vbb));
			out->phase_se_rad[l] = INFINITY;
		}
	}
	snprintf(out->fit.name[q], PRSM_CALIB_NAME_MAX, "carrier_ratio");
	snprintf(out->fit.unit[q], 16, "-");
	for (int j = 0; j < P; j++)
		out->fit.estimate[j] = p[j];
	out->carrier_ratio = p[q];
	out->carrier_ratio_se = out->fit.standard_error[q];
	line_caveats(out, o->autocorrelation_limit);
cleanup:
	if (opt)
		nlopt_destroy(opt);
	gsl_matrix_free(w.X);
	gsl_vector_free(w.tau);
	gsl_vector_free(w.y);
	gsl_vector_free(w.beta_lin);
	gsl_vector_free(w.res);
	free(J);
	free(r);
	if (rc)
		prsm_calib_line_free(out);
	return rc;
}

/* ---- the physical model ---- */

int prsm_calib_statics_te(double *te_um, const prsm_assembly *as, const prsm_errors *e, const double *theta,
                          size_t n, int mode, double F_N, prsm_assembly_gaps *gaps)
{
	/* MODEL.md §4: TE(theta) = u(theta) - u(theta_0) at the measuring load, "+" direction, in
	 * the measurement's convention: the nut's position error along its forward travel (-hand z,
	 * MODEL-DYNAMICS §8.0), -hand (u - u_0), so that its slope on the travel is the lead deviation
	 * the statics report gives (assembly_report.c: the slope on the nut's position -p theta) */
	const double sign = as->hand < 0 ? 1.0 : -1.0;
	prsm_assembly_state st;
	double u0 = 0.0;
	int rc = 0;
	for (size_t i = 0; i < n; i++) {
		prsm_assembly_gaps_at(gaps, as, e, PRSM_DIR_PLUS, theta[i], mode);
		if (prsm_assembly_solve(&st, as, gaps, F_N, i > 0))
			rc = PRSM_ENOCONVERGE;
		if (i == 0)
			u0 = st.u_mm;
		te_um[i] = sign * (st.u_mm - u0) * 1000.0;
	}
	return rc;
}

static void *part_base(prsm_errors *e, const prsm_calib_field *f)
{
	switch (f->part) {
	case PRSM_CALIB_PART_SCREW: return &e->screw;
	case PRSM_CALIB_PART_NUT: return &e->nut;
	case PRSM_CALIB_PART_CARRIER: return &e->carrier;
	default: return &e->roller[f->roller];
	}
}

static const void *part_base_const(const prsm_errors *e, const prsm_calib_field *f)
{
	switch (f->part) {
	case PRSM_CALIB_PART_SCREW: return &e->screw;
	case PRSM_CALIB_PART_NUT: return &e->nut;
	case PRSM_CALIB_PART_CARRIER: return &e->carrier;
	default: return &e->roller[f->roller];
	}
}

double prsm_calib_field_get(const prsm_errors *e, const prsm_calib_field *f)
{
	const char *b = part_base_const(e, f);
	double v;
	memcpy(&v, b + f->offset, sizeof v);
	return v * f->scale;
}

void prsm_calib_field_set(prsm_errors *e, const prsm_calib_field *f, double value)
{
	char *b = part_base(e, f);
	const double v = value / f->scale;
	memcpy(b + f->offset, &v, sizeof v);
}

/* The internal variables: a field alone, or a magnitude and its phase as (x, y). */
typedef struct {
	int field, phase_field;      /* phase_field >= 0: Cartesian pair */
	double typical;              /* the variable's scale, field unit */
} ivar;

typedef struct {
	const prsm_meas_curve *c;
	const prsm_assembly *as;
	prsm_errors e;               /* the working error set */
	const prsm_calib_field *f;
	int nf, nv;
	ivar v[PRSM_CALIB_FIELDS_MAX];
	int slope;                   /* 1: a slope nuisance */
	int mode;
	double F_N;
	prsm_assembly_gaps *gaps;
	double *te, *tmp;
	int evaluations, failed;
} phys_ws;

static double field_typical(const prsm_calib_field *f)
{
	return f->phase ? 30.0 : 1.0; /* 30 deg, or 1 um, mrad, um/300mm */
}

/* number of internal coordinates */
static int coords(const phys_ws *w)
{
	int k = 0;
	for (int j = 0; j < w->nv; j++)
		k += w->v[j].phase_field >= 0 ? 2 : 1;
	return k;
}

/* coordinates of variable j start here */
static int coord_of(const phys_ws *w, int j)
{
	int k = 0;
	for (int i = 0; i < j; i++)
		k += w->v[i].phase_field >= 0 ? 2 : 1;
	return k;
}

static void apply_coords(phys_ws *w, const double *x)
{
	for (int j = 0; j < w->nv; j++) {
		const ivar *v = &w->v[j];
		const int k = coord_of(w, j);
		if (v->phase_field >= 0) {
			const double m = hypot(x[k], x[k + 1]), ph = atan2(x[k + 1], x[k]);
			prsm_calib_field_set(&w->e, &w->f[v->field], m);
			prsm_calib_field_set(&w->e, &w->f[v->phase_field], ph * w->f[v->phase_field].scale);
		} else {
			prsm_calib_field_set(&w->e, &w->f[v->field], x[k]);
		}
	}
}

/* The model TE at coordinates x into te (um). */
static void model_te(phys_ws *w, const double *x, double *te)
{
	apply_coords(w, x);
	if (prsm_calib_statics_te(te, w->as, &w->e, w->c->angle_rad, w->c->n, w->mode, w->F_N, w->gaps))
		w->failed++;
	w->evaluations++;
}

/* S with the offset (and slope) by least squares, residuals into r (may be NULL) */
static double nuisance_fit(const phys_ws *w, const double *te, double *r, double *off, double *slope)
{
	const prsm_meas_curve *c = w->c;
	const size_t n = c->n;
	double my = 0.0, ms = 0.0;
	for (size_t i = 0; i < n; i++) {
		my += c->te_um[i] - te[i];
		ms += c->travel_mm[i] / 300.0;
	}
	my /= (double)n;
	ms /= (double)n;
	double b = 0.0;
	if (w->slope) {
		double sxy = 0.0, sxx = 0.0;
		for (size_t i = 0; i < n; i++) {
			const double ds = c->travel_mm[i] / 300.0 - ms;
			sxy += ds * (c->te_um[i] - te[i] - my);
			sxx += ds * ds;
		}
		b = sxx > 0.0 ? sxy / sxx : 0.0;
	}
	const double a = my - b * ms;
	double S = 0.0;
	for (size_t i = 0; i < n; i++) {
		const double e = c->te_um[i] - te[i] - a - b * c->travel_mm[i] / 300.0;
		if (r)
			r[i] = e;
		S += e * e;
	}
	if (off)
		*off = a;
	if (slope)
		*slope = b;
	return S;
}

static double phys_objective(unsigned n, const double *x, double *grad, void *data)
{
	(void)n;
	(void)grad;
	phys_ws *w = data;
	model_te(w, x, w->te);
	return nuisance_fit(w, w->te, NULL, NULL, NULL);
}

int prsm_calib_physical(prsm_calib_physical_result *out, prsm_errors *estimate, const prsm_meas_curve *c,
                        const prsm_assembly *as, const prsm_errors *base, const prsm_calib_field *fields, int n_fields,
                        const prsm_calib_options *o, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (n_fields < 1 || n_fields > PRSM_CALIB_FIELDS_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/calibrate/parameters",
		                      "the physical model calibrates 1 to %d error fields (got %d)", PRSM_CALIB_FIELDS_MAX,
		                      n_fields);
	const size_t n = c->n;
	phys_ws w;
	memset(&w, 0, sizeof w);
	w.c = c;
	w.as = as;
	w.e = *base;
	w.f = fields;
	w.nf = n_fields;
	w.mode = o->mode;
	w.F_N = o->measuring_load_N;
	w.slope = 1;
	/* pair each magnitude with its phase when both are fitted */
	int used[PRSM_CALIB_FIELDS_MAX] = {0};
	for (int i = 0; i < n_fields; i++) {
		if (fields[i].lead)
			w.slope = 0;
		if (used[i])
			continue;
		ivar v = {i, -1, field_typical(&fields[i])};
		for (int j = 0; j < n_fields && fields[i].magnitude; j++)
			if (j != i && fields[j].phase && fields[j].part == fields[i].part && fields[j].roller == fields[i].roller &&
			    fields[j].offset == fields[i].phase_offset)
				v.phase_field = j;
		for (int j = 0; j < n_fields && fields[i].phase; j++) /* a phase listed first: wait for its magnitude */
			if (j != i && fields[j].magnitude && fields[j].part == fields[i].part && fields[j].roller == fields[i].roller &&
			    fields[j].phase_offset == fields[i].offset)
				v.field = -1;
		if (v.field < 0)
			continue;
		used[i] = 1;
		if (v.phase_field >= 0)
			used[v.phase_field] = 1;
		w.v[w.nv++] = v;
	}
	const int nx = coords(&w);
	const int nuis = 1 + w.slope, P = nx + nuis;
	if (n < (size_t)P + 2)
		return prsm_error_set(err, PRSM_EINVAL, "/measured", "the physical model has %d parameters: the curve needs more "
		                      "than %d points (got %zu)", P, P + 2, n);
	w.gaps = malloc(sizeof *w.gaps);
	w.te = malloc(n * sizeof(double));
	w.tmp = malloc(n * sizeof(double));
	double *J = malloc(n * (size_t)P * sizeof(double));
	double *r = malloc(n * sizeof(double));
	out->fit.residual_um = malloc(n * sizeof(double));
	int rc = 0;
	nlopt_opt opt = NULL;
	if (!w.gaps || !w.te || !w.tmp || !J || !r || !out->fit.residual_um) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the physical model of %zu points", n);
		goto cleanup;
	}
	/* the start: the given error set; bounds: the fields' limits */
	double x[2 * PRSM_CALIB_FIELDS_MAX], lb[2 * PRSM_CALIB_FIELDS_MAX], ub[2 * PRSM_CALIB_FIELDS_MAX],
	    step[2 * PRSM_CALIB_FIELDS_MAX];
	for (int i = 0; i < n_fields; i++)
		out->start[i] = prsm_calib_field_get(base, &fields[i]);
	for (int j = 0; j < w.nv; j++) {
		const ivar *v = &w.v[j];
		const prsm_calib_field *f = &fields[v->field];
		const int k = coord_of(&w, j);
		const double val = prsm_calib_field_get(base, f);
		if (v->phase_field >= 0) {
			const double ph = prsm_calib_field_get(base, &fields[v->phase_field]) / fields[v->phase_field].scale;
			x[k] = val * cos(ph);
			x[k + 1] = val * sin(ph);
			lb[k] = lb[k + 1] = -f->limit;
			ub[k] = ub[k + 1] = f->limit;
			step[k] = step[k + 1] = v->typical;
		} else {
			x[k] = val;
			lb[k] = f->magnitude ? 0.0 : -f->limit;
			ub[k] = f->limit;
			step[k] = f->magnitude && val < v->typical ? v->typical : v->typical;
		}
	}
	for (int k = 0; k < nx; k++) {
		x[k] = fmin(ub[k], fmax(lb[k], x[k]));
		if (x[k] + step[k] > ub[k] && x[k] - step[k] < lb[k])
			step[k] = 0.5 * (ub[k] - lb[k]);
	}
	double fbest = 0.0;
	int algorithm = nx >= 2 ? NLOPT_LN_BOBYQA : NLOPT_LN_COBYLA;
	opt = nlopt_create(algorithm, (unsigned)nx);
	if (opt == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the optimiser");
		goto cleanup;
	}
	nlopt_set_min_objective(opt, phys_objective, &w);
	nlopt_set_lower_bounds(opt, lb);
	nlopt_set_upper_bounds(opt, ub);
	nlopt_set_initial_step(opt, step);
	double xtol[2 * PRSM_CALIB_FIELDS_MAX];
	for (int k = 0; k < nx; k++)
		xtol[k] = 1e-7 * (k < nx ? 1.0 : 1.0);
	nlopt_set_xtol_abs(opt, xtol);
	nlopt_set_ftol_rel(opt, 1e-13);
	nlopt_set_maxeval(opt, o->max_evaluations > 0 ? o->max_evaluations : 2000);
	out->optimizer_status = nlopt_optimize(opt, x, &fbest);
	nlopt_destroy(opt);
	opt = NULL;
	if (out->optimizer_status < 0 && out->optimizer_status != NLOPT_ROUNDOFF_LIMITED) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the optimiser of the physical model failed (NLopt %d)",
		                    out->optimizer_status);
		goto cleanup;
	}
	/* Gauss-Newton polish, central differences of 1e-3 of each coordinate's scale; the
	 * nuisances (offset, slope) are linear columns */
	double typ[2 * PRSM_CALIB_FIELDS_MAX];
	for (int j = 0; j < w.nv; j++) {
		const int k = coord_of(&w, j);
		typ[k] = w.v[j].typical;
		if (w.v[j].phase_field >= 0)
			typ[k + 1] = w.v[j].typical;
	}
	double off = 0.0, slope = 0.0, xt[2 * PRSM_CALIB_FIELDS_MAX], delta[PMAX];
	model_te(&w, x, w.te);
	double S = nuisance_fit(&w, w.te, r, &off, &slope);
	for (int it = 0; it < 12; it++) {
		for (int k = 0; k < nx; k++) {
			const double h = 1e-3 * fmax(typ[k], fabs(x[k]));
			memcpy(xt, x, sizeof(double) * (size_t)nx);
			xt[k] = x[k] + h;
			model_te(&w, xt, w.tmp);
			xt[k] = x[k] - h;
			model_te(&w, xt, w.te);
			for (size_t i = 0; i < n; i++)
				J[i * (size_t)P + (size_t)k] = (w.tmp[i] - w.te[i]) / (2.0 * h);
		}
		for (size_t i = 0; i < n; i++) {
			J[i * (size_t)P + (size_t)nx] = 1.0;
			if (w.slope)
				J[i * (size_t)P + (size_t)nx + 1] = c->travel_mm[i] / 300.0;
		}
		model_te(&w, x, w.te);
		S = nuisance_fit(&w, w.te, r, &off, &slope);
		if (it == 11)
			break;
		if (svd_solve(delta, J, r, n, P)) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the Gauss-Newton step");
			goto cleanup;
		}
		double t = 1.0, St = INFINITY;
		for (int h = 0; h < 20; h++, t *= 0.5) {
			for (int k = 0; k < nx; k++)
				xt[k] = fmin(ub[k], fmax(lb[k], x[k] + t * delta[k]));
			model_te(&w, xt, w.tmp);
			St = nuisance_fit(&w, w.tmp, NULL, NULL, NULL);
			if (St <= S)
				break;
		}
		out->fit.gauss_newton_iterations = it + 1;
		int small = 1;
		for (int k = 0; k < nx; k++)
			small = small && fabs(xt[k] - x[k]) <= 1e-9 * fmax(typ[k], fabs(x[k]));
		if (St <= S)
			memcpy(x, xt, sizeof(double) * (size_t)nx);
		else
			small = 1;
		if (small) {
			out->fit.converged = 1;
			/* the Jacobian at the final point */
			it = 10;
		}
	}
	memcpy(out->fit.residual_um, r, n * sizeof(double));
	double cov[PMAX * PMAX];
	if ((rc = uncertainty(&out->fit, cov, J, n, P, S, o->autocorrelation_limit))) {
		rc = prsm_error_set(err, rc, NULL, "out of memory for the covariance");
		goto cleanup;
	}
	/* back to the fields' own parameters: magnitude and phase by the delta method. G maps the
	 * coordinates (and nuisances) to the reported parameters, in the order fields, nuisances. */
	const int R = n_fields + nuis;
	double G[PMAX * PMAX];
	memset(G, 0, sizeof G);
	double est[PMAX];
	for (int j = 0; j < w.nv; j++) {
		const ivar *v = &w.v[j];
		const int k = coord_of(&w, j);
		if (v->phase_field >= 0) {
			const double a = x[k], b = x[k + 1], m = hypot(a, b), ps = fields[v->phase_field].scale;
			double ph = atan2(b, a) * ps;
			if (ph < 0.0)
				ph += 2.0 * M_PI * ps;
			est[v->field] = m;
			est[v->phase_field] = ph;
			if (m > 0.0) {
				G[v->field * P + k] = a / m;
				G[v->field * P + k + 1] = b / m;
				G[v->phase_field * P + k] = -b / (m * m) * ps;
				G[v->phase_field * P + k + 1] = a / (m * m) * ps;
			} else {
				G[v->field * P + k] = 1.0;
				G[v->phase_field * P + k + 1] = INFINITY;
			}
		} else {
			est[v->field] = x[k];
			G[v->field * P + k] = 1.0;
		}
	}
	est[n_fields] = off;
	G[n_fields * P + nx] = 1.0;
	if (w.slope) {
		est[n_fields + 1] = slope;
		G[(n_fields + 1) * P + nx + 1] = 1.0;
	}
	double cu[PMAX * PMAX], cw[PMAX * PMAX];
	const double infl2 = out->fit.inflation * out->fit.inflation;
	for (int a = 0; a < R; a++)
		for (int b = 0; b < R; b++) {
			double s = 0.0;
			for (int i = 0; i < P; i++)
				for (int j = 0; j < P; j++) {
					const double gi = G[a * P + i], gj = G[b * P + j];
					if (gi != 0.0 && gj != 0.0)
						s += gi * cov[i * P + j] * gj;
				}
			cu[a * R + b] = s;
			cw[a * R + b] = s / infl2;
		}
	out->fit.params = R;
	for (int a = 0; a < R; a++) {
		out->fit.estimate[a] = est[a];
		out->fit.standard_error[a] = sqrt(cu[a * R + a]);
		out->fit.standard_error_white[a] = sqrt(cw[a * R + a]);
		if (a < n_fields) {
			snprintf(out->fit.name[a], PRSM_CALIB_NAME_MAX, "%s", fields[a].name);
			snprintf(out->fit.unit[a], 16, "%s", fields[a].unit);
		}
	}
	snprintf(out->fit.name[n_fields], PRSM_CALIB_NAME_MAX, "offset");
	snprintf(out->fit.unit[n_fields], 16, "um");
	if (w.slope) {
		snprintf(out->fit.name[n_fields + 1], PRSM_CALIB_NAME_MAX, "slope");
		snprintf(out->fit.unit[n_fields + 1], 16, "um/300mm");
	}
	for (int a = 0; a < R; a++)
		for (int b = 0; b < R; b++) {
			const double d = sqrt(cu[a * R + a] * cu[b * R + b]);
			out->fit.correlation[a * R + b] = a == b ? 1.0 : (d > 0.0 && isfinite(d) ? cu[a * R + b] / d : NAN);
		}
	/* the sensitivities: RMS of d TE / d field over the record, um per field unit */
	for (int j = 0; j < w.nv; j++) {
		const ivar *v = &w.v[j];
		const int k = coord_of(&w, j);
		double s1 = 0.0, s2 = 0.0;
		if (v->phase_field >= 0) {
			const double m = hypot(x[k], x[k + 1]);
			const double cs = m > 0.0 ? x[k] / m : 1.0, sn = m > 0.0 ? x[k + 1] / m : 0.0;
			for (size_t i = 0; i < n; i++) {
				const double jm = J[i * (size_t)P + (size_t)k] * cs + J[i * (size_t)P + (size_t)k + 1] * sn;
				const double jp = (-J[i * (size_t)P + (size_t)k] * sn + J[i * (size_t)P + (size_t)k + 1] * cs) * m;
				s1 += jm * jm;
				s2 += jp * jp;
			}
			out->sensitivity_um[v->field] = sqrt(s1 / (double)n);
			out->sensitivity_um[v->phase_field] = sqrt(s2 / (double)n) / fields[v->phase_field].scale;
		} else {
			for (size_t i = 0; i < n; i++)
				s1 += J[i * (size_t)P + (size_t)k] * J[i * (size_t)P + (size_t)k];
			out->sensitivity_um[v->field] = sqrt(s1 / (double)n);
		}
	}
	out->fields = n_fields;
	out->evaluations = w.evaluations;
	/* the caveats (§8.5) */
	prsm_calib_fit *f = &out->fit;
	caveat(f, PRSM_CALIB_CAVEAT_RESOLUTION, 0,
	       "two lines closer than the resolution 1/N_rev = %.4g cycles per revolution cannot be separated",
	       1.0 / prsm_meas_revolutions(c));
	/* slope against a field */
	double worst = 0.0;
	int wf = -1;
	for (int i = 0; i < n_fields && w.slope; i++) {
		const double cc = fabs(f->correlation[(n_fields + 1) * R + i]);
		if (cc > worst) {
			worst = cc;
			wf = i;
		}
	}
	if (worst > 0.5)
		caveat(f, PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER, 1,
		       "the slope and %s trade off over this stroke (correlation %.2f)", fields[wf].name, worst);
	else
		caveat(f, PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER, 0,
		       "a slope and a low-order line are correlated over a short stroke (here at most %.2f)", worst);
	/* the first-order effect of each magnitude (or plain field) at zero, the others as estimated:
	 * a run-out whose first harmonic cancels among evenly spaced rollers has none (MODEL §4) */
	apply_coords(&w, x);
	const prsm_errors at_estimate = w.e;
	double sens0_max = 0.0;
	for (int i = 0; i < n_fields; i++) {
		if (fields[i].phase)
			continue;
		const double h = 1e-3 * field_typical(&fields[i]);
		w.e = at_estimate;
		prsm_calib_field_set(&w.e, &fields[i], 0.0);
		if (prsm_calib_statics_te(w.te, as, &w.e, c->angle_rad, n, w.mode, w.F_N, w.gaps))
			w.failed++;
		prsm_calib_field_set(&w.e, &fields[i], h);
		if (prsm_calib_statics_te(w.tmp, as, &w.e, c->angle_rad, n, w.mode, w.F_N, w.gaps))
			w.failed++;
		w.evaluations += 2;
		double s0 = 0.0;
		for (size_t k = 0; k < n; k++)
			s0 += (w.tmp[k] - w.te[k]) * (w.tmp[k] - w.te[k]);
		out->first_order_um[i] = sqrt(s0 / (double)n) / h;
		sens0_max = fmax(sens0_max, out->first_order_um[i] * field_typical(&fields[i]));
	}
	for (int i = 0; i < n_fields; i++)
		if (fields[i].phase)
			for (int j = 0; j < n_fields; j++)
				if (fields[j].magnitude && fields[j].part == fields[i].part && fields[j].roller == fields[i].roller &&
				    fields[j].phase_offset == fields[i].offset)
					out->first_order_um[i] = out->first_order_um[j];
	w.e = at_estimate;
	char names[200] = "";
	int invisible = 0, screw = 0;
	for (int i = 0; i < n_fields; i++) {
		const size_t ro = fields[i].part == PRSM_CALIB_PART_CARRIER  ? offsetof(prsm_carrier_errors, runout_mm)
		                  : fields[i].part == PRSM_CALIB_PART_ROLLER ? offsetof(prsm_roller_errors, runout_mm)
		                                                             : offsetof(prsm_body_errors, runout_mm);
		const int runout = fields[i].magnitude && fields[i].offset == ro;
		if (!runout)
			continue;
		const double s0 = out->first_order_um[i] * field_typical(&fields[i]);
		if (s0 < 1e-4 || s0 < 1e-3 * sens0_max) {
			invisible++;
			screw += fields[i].part == PRSM_CALIB_PART_SCREW;
			snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s (%.2g um of TE per um at zero)",
			         invisible > 1 ? ", " : "", fields[i].name, out->first_order_um[i]);
		}
	}
	if (invisible)
		caveat(f, PRSM_CALIB_CAVEAT_SCREW_RUNOUT, 1,
		       "the first harmonic of a %s run-out cancels among evenly spaced rollers (MODEL §4): invisible in TE to "
		       "first order, it cannot be calibrated from it: %s", screw ? "screw" : "part's", names);
	else
		caveat(f, PRSM_CALIB_CAVEAT_SCREW_RUNOUT, 0,
		       "the first harmonic of a screw run-out cancels among evenly spaced rollers (MODEL §4): it is invisible "
		       "in TE and cannot be calibrated from it");
	/* one parameter: highly correlated pairs */
	double cmax = 0.0;
	int ca = -1, cb = -1;
	for (int a = 0; a < n_fields; a++)
		for (int b = a + 1; b < n_fields; b++) {
			if ((fields[a].phase && fields[b].magnitude) || (fields[b].phase && fields[a].magnitude))
				if (fields[a].part == fields[b].part && fields[a].roller == fields[b].roller)
					continue; /* a magnitude and its own phase */
			const double cc = fabs(f->correlation[a * R + b]);
			if (cc > cmax || (isnan(cc) && cmax < 2.0)) {
				cmax = isnan(cc) ? 2.0 : cc;
				ca = a;
				cb = b;
			}
		}
	if (cmax > 0.95)
		caveat(f, PRSM_CALIB_CAVEAT_SAME_PART_ORDER, 1,
		       "%s and %s act as one parameter (correlation %s): errors of the same part at the same order cannot be "
		       "told apart by TE", fields[ca].name, fields[cb].name, cmax > 1.0 ? "undefined" : cmax > 0.9995 ? "1.000" : "above 0.95");
	else
		caveat(f, PRSM_CALIB_CAVEAT_SAME_PART_ORDER, 0,
		       "errors of the same part at the same order (run-out and tilt) are one parameter");
	int rollers_same = 0;
	for (int a = 0; a < n_fields; a++)
		for (int b = a + 1; b < n_fields; b++)
			rollers_same += fields[a].part == PRSM_CALIB_PART_ROLLER && fields[b].part == PRSM_CALIB_PART_ROLLER &&
			                fields[a].offset == fields[b].offset && fields[a].roller != fields[b].roller;
	caveat(f, PRSM_CALIB_CAVEAT_ROLLER_SUM, rollers_same > 0,
	       "the individual rollers' errors at the roller_spin order combine into one vector sum%s",
	       rollers_same ? ": the rollers' fields here are not separately identifiable" : "");
	if (f->inflation > 1.0)
		caveat(f, PRSM_CALIB_CAVEAT_CORRELATED_RESIDUALS, 1,
		       "the residuals are correlated (lag-1 autocorrelation %.3f > %.2f): every standard error is inflated "
		       "by %.4f", f->lag1_autocorrelation, o->autocorrelation_limit, f->inflation);
	else
		caveat(f, PRSM_CALIB_CAVEAT_CORRELATED_RESIDUALS, 0,
		       "white-noise errors are optimistic when the residuals are correlated (lag-1 autocorrelation here %.3f)",
		       f->lag1_autocorrelation);
	if (estimate) {
		apply_coords(&w, x);
		*estimate = w.e;
	}
	if (w.failed)
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL,
		                    "%d statics TE evaluations had an elastic solve that did not converge", w.failed);
cleanup:
	if (opt)
		nlopt_destroy(opt);
	free(w.gaps);
	free(w.te);
	free(w.tmp);
	free(J);
	free(r);
	if (rc)
		prsm_calib_physical_free(out);
	return rc;
}

/* ---- §8.5 item 4: friction from efficiency ---- */

typedef struct {
	prsm_design d;
	double target;
	int evaluations, failed;
	prsm_performance last;
	int have_last;
} eta_ctx;

static double eta_at(eta_ctx *c, double mu, prsm_losses_result *losses)
{
	prsm_design d = c->d;
	d.mu_screw_roller = mu;
	prsm_analysis a;
	prsm_problems warn;
	prsm_problems_init(&warn);
	prsm_error e = PRSM_ERROR_INIT;
	c->evaluations++;
	if (prsm_analysis_nominal(&a, &d, &warn, &e)) {
		c->failed++;
		return NAN;
	}
	prsm_performance p;
	if (prsm_performance_compute(&p, &d, &a, &e)) {
		c->failed++;
		return NAN;
	}
	const double eta = p.losses.eta;
	if (losses)
		*losses = p.losses;
	prsm_performance_free(&p);
	return eta;
}

static double eta_root_fn(double mu, void *data)
{
	eta_ctx *c = data;
	return eta_at(c, mu, NULL) - c->target;
}

int prsm_calib_friction_compute(prsm_calib_friction *out, const prsm_design *d, double efficiency, double sd,
                                double load, double speed, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->efficiency = efficiency;
	out->efficiency_sd = sd;
	out->axial_load_N = load;
	out->screw_speed_rad_s = speed;
	out->mu = NAN;
	out->mu_se = NAN;
	out->deta_dmu = NAN;
	if (!(efficiency > 0.0 && efficiency < 1.0))
		return prsm_error_set(err, PRSM_EINVAL, "/measured/efficiency", "a measured efficiency lies in (0, 1) (got %g)",
		                      efficiency);
	if (!(load > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/measured/efficiency_axial_load_N",
		                      "the efficiency needs a positive axial load (got %g N)", load);
	eta_ctx *c = calloc(1, sizeof *c);
	if (c == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	c->d = *d;
	c->d.axial_load_N = load;
	c->d.screw_speed_rad_s = speed;
	c->target = efficiency;
	out->spin = d->losses.spin;
	out->gear = d->losses.gear_mesh;
	out->mu_design = d->mu_screw_roller;
	out->efficiency_model = eta_at(c, d->mu_screw_roller, NULL);
	out->z = prsm_meas_z(efficiency, out->efficiency_model, sd);
	/* sliding alone at beta = 45 deg: eta = (1 - mu) / (1 + mu) (MODEL §5) */
	out->mu_sliding_only = (1.0 - efficiency) / (1.0 + efficiency);
	int rc = 0;
	const double lo = 0.0, hi = 0.5;
	const double flo = eta_root_fn(lo, c), fhi = eta_root_fn(hi, c);
	if (!(flo >= 0.0 && fhi <= 0.0)) {
		rc = 0;
		prsm_error_set(err, PRSM_EINVAL, "/measured/efficiency",
		               "no friction coefficient in [0, 0.5] gives the efficiency %.6g with the assumed losses "
		               "(%.6g at mu = 0, %.6g at mu = 0.5)", efficiency, flo + efficiency, fhi + efficiency);
		goto done;
	}
	gsl_function F = {eta_root_fn, c};
	gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
	if (s == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto done;
	}
	gsl_root_fsolver_set(s, &F, lo, hi);
	double mu = NAN;
	for (int it = 0; it < 200; it++) {
		gsl_root_fsolver_iterate(s);
		mu = gsl_root_fsolver_root(s);
		const double a = gsl_root_fsolver_x_lower(s), b = gsl_root_fsolver_x_upper(s);
		if (gsl_root_test_interval(a, b, 1e-13, 1e-11) == GSL_SUCCESS)
			break;
	}
	gsl_root_fsolver_free(s);
	if (c->failed) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the statics efficiency could not be computed at every mu");
		goto done;
	}
	out->found = 1;
	out->mu = mu;
	const double h = 1e-5;
	out->deta_dmu = (eta_at(c, mu + h, NULL) - eta_at(c, fmax(0.0, mu - h), NULL)) / (mu + h - fmax(0.0, mu - h));
	out->mu_se = sd > 0.0 && isfinite(sd) ? sd / fabs(out->deta_dmu) : NAN;
	prsm_losses_result L;
	eta_at(c, mu, &L);
	out->input_torque_Nm = L.input_torque_Nm;
	out->ideal_torque_Nm = L.ideal_torque_Nm;
	out->sliding_torque_Nm = L.sliding_torque_Nm;
	out->spin_torque_Nm = L.spin_torque_Nm;
	out->gear_torque_Nm = L.gear_torque_Nm;
	out->drag_torque_Nm = L.drag_torque_Nm;
	out->seal_torque_Nm = L.seal_torque_Nm;
done:
	out->evaluations = c->evaluations;
	free(c);
	return rc;
}

/* ---- §8.5 item 4: carrier drag from the cage ratio ---- */

typedef struct {
	const prsm_design *d;
	const prsm_analysis *a;
	prsm_dyn_options o;
	double target;
	int evaluations, failed;
	prsm_error err;
} cage_ctx;

static double settled_ratio(cage_ctx *c, double drag)
{
	c->o.friction.carrier_drag_Nm_s_per_rad = drag;
	prsm_dyn_model *m = NULL;
	c->evaluations++;
	if (prsm_dyn_model_new(&m, 1, c->d, c->a, &c->o, &c->err)) {
		c->failed++;
		return NAN;
	}
	const double k = prsm_dyn_model_settled(m)->carrier_ratio[0];
	prsm_dyn_model_free(m);
	return k;
}

static double cage_fn(double drag, void *data)
{
	cage_ctx *c = data;
	return settled_ratio(c, drag) - c->target;
}

int prsm_calib_cage_compute(prsm_calib_cage *out, const prsm_design *d, const prsm_analysis *a,
                            const prsm_dyn_options *dyn, double ratio, double sd, double load, double speed,
                            prsm_error *err)
{
	memset(out, 0, sizeof *out);
	out->ratio = ratio;
	out->ratio_sd = sd;
	out->axial_load_N = load;
	out->screw_speed_rad_s = speed;
	out->carrier_drag_Nm_s_per_rad = NAN;
	out->carrier_drag_se_Nm_s_per_rad = NAN;
	out->dk_dcC = NAN;
	if (!(ratio > 0.0 && ratio < 1.0))
		return prsm_error_set(err, PRSM_EINVAL, "/measured/cage_ratio", "a cage ratio lies in (0, 1) (got %g)", ratio);
	cage_ctx *c = calloc(1, sizeof *c);
	if (c == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	c->d = d;
	c->a = a;
	if (dyn)
		c->o = *dyn;
	else
		prsm_dyn_options_init(&c->o);
	c->o.input.kind = PRSM_DYN_INPUT_SPEED;
	c->o.input.signal.shape = PRSM_DYN_SHAPE_STEP;
	c->o.input.signal.value = speed;
	c->o.load.shape = PRSM_DYN_SHAPE_STEP;
	c->o.load.value = load;
	c->target = ratio;
	int rc = 0;
	prsm_dyn_model *m = NULL;
	c->o.friction.carrier_drag_Nm_s_per_rad = 0.0;
	if ((rc = prsm_dyn_model_new(&m, 1, d, a, &c->o, err)))
		goto done;
	const prsm_dyn_settled *st = prsm_dyn_model_settled(m);
	out->k_star = st->carrier_ratio_min_slip[0];
	out->k_statics = st->carrier_ratio_statics[0];
	const double k0 = st->carrier_ratio[0]; /* without drag: k* (§8.1) */
	prsm_dyn_model_free(m);
	out->z_k_star = prsm_meas_z(ratio, out->k_star, sd);
	out->z_statics = prsm_meas_z(ratio, out->k_statics, sd);
	if (ratio > k0) {
		out->above_k_star = 1; /* §8.5 item 4: a ratio above k* cannot be explained by drag */
		goto done;
	}
	/* bracket c_C: the settled ratio falls from k* towards 0 as the drag grows */
	double hi = 1e-7, fhi = cage_fn(hi, c);
	for (int i = 0; i < 80 && fhi > 0.0; i++) {
		hi *= 2.0;
		fhi = cage_fn(hi, c);
	}
	if (c->failed || !(fhi <= 0.0)) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "no carrier drag up to %g N m s/rad brings the settled ratio "
		                    "down to %g%s%s", hi, ratio, c->failed ? ": " : "", c->failed ? c->err.message : "");
		goto done;
	}
	gsl_function F = {cage_fn, c};
	gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
	if (s == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto done;
	}
	gsl_root_fsolver_set(s, &F, 0.0, hi);
	double cC = NAN;
	for (int it = 0; it < 200; it++) {
		gsl_root_fsolver_iterate(s);
		cC = gsl_root_fsolver_root(s);
		if (gsl_root_test_interval(gsl_root_fsolver_x_lower(s), gsl_root_fsolver_x_upper(s), 1e-30, 1e-12) ==
		    GSL_SUCCESS)
			break;
	}
	gsl_root_fsolver_free(s);
	if (c->failed) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the settled state failed: %s", c->err.message);
		goto done;
	}
	out->drag_found = 1;
	out->carrier_drag_Nm_s_per_rad = cC;
	const double h = fmax(1e-4 * cC, 1e-12);
	out->dk_dcC = (settled_ratio(c, cC + h) - settled_ratio(c, fmax(0.0, cC - h))) / (cC + h - fmax(0.0, cC - h));
	out->carrier_drag_se_Nm_s_per_rad = sd > 0.0 && isfinite(sd) ? sd / fabs(out->dk_dcC) : NAN;
done:
	out->evaluations = c->evaluations;
	free(c);
	return rc;
}
