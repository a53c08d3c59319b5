/*
 * alloc.c: tolerance allocation with a linear stack model, exactly (KKT, one Brent root per
 * multiplier) or with NLopt (issue 7, item 4; benchmarks.md "Tolerance allocation, closed
 * form"). See alloc.h for the problem and the method.
 *
 * Numerics. Multipliers span many decades, so every root is taken on u = ln lambda; the closed
 * forms are evaluated in logarithms (ln T = (ln(k B / 2) - ln a) / (k + 2) for RSS with a
 * reciprocal-power cost, W0 of exp(L) by Newton on w + ln w = L when exp(L) would overflow), so
 * no multiplier, however large or small, overflows. For one constraint the result is the closed
 * form of benchmarks.md to rounding: the root function ln h(u) - ln L is linear in u there.
 */
#include "opt/alloc.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_sf_lambert.h>
#include <nlopt.h>

#include "util/clock.h"

/* Root on u = ln lambda: Brent to this absolute / relative width. The allocation is computed
 * from ln lambda by log-sum-exp, so no multiplier is ever exponentiated during the solve and the
 * search range can span any cost scale. */
#define U_EPSABS 1e-14
#define U_EPSREL 1e-15
#define U_MAX 1e5                  /* |ln lambda| searched */
#define ROOT_MAX_ITER 400
/* Several constraints: projected Newton on the dual, then (if it stalls) coordinate-ascent
 * sweeps; the relative residual that ends them. */
#define NEWTON_MAX_ITER 200
#define MAX_SWEEPS 5000
#define KKT_RTOL 1e-12

const char *prsm_alloc_cost_name(prsm_alloc_cost_kind k)
{
	switch (k) {
	case PRSM_ALLOC_COST_RECIPROCAL: return "reciprocal";
	case PRSM_ALLOC_COST_RECIPROCAL_SQUARED: return "reciprocal_squared";
	case PRSM_ALLOC_COST_RECIPROCAL_POWER: return "reciprocal_power";
	case PRSM_ALLOC_COST_EXPONENTIAL: return "exponential";
	}
	return "unknown";
}

const char *prsm_alloc_stack_name(prsm_alloc_stack s)
{
	return s == PRSM_ALLOC_RSS ? "rss" : s == PRSM_ALLOC_WORST_CASE ? "worst_case" : "unknown";
}

const char *prsm_alloc_solver_name(prsm_alloc_solver s)
{
	switch (s) {
	case PRSM_ALLOC_SOLVER_EXACT: return "exact";
	case PRSM_ALLOC_SOLVER_SLSQP: return "slsqp";
	case PRSM_ALLOC_SOLVER_COBYLA: return "cobyla";
	}
	return "unknown";
}

static double cost_power(const prsm_alloc_cost *c)
{
	switch (c->kind) {
	case PRSM_ALLOC_COST_RECIPROCAL: return 1.0;
	case PRSM_ALLOC_COST_RECIPROCAL_SQUARED: return 2.0;
	default: return c->power;
	}
}

double prsm_alloc_cost_eval(const prsm_alloc_cost *c, double t)
{
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL)
		return c->fixed + c->coefficient * exp(-c->rate * t);
	if (!(t > 0.0))
		return INFINITY;
	return c->fixed + c->coefficient * pow(t, -cost_power(c));
}

/* d cost / d T (cost units per tolerance unit). */
static double cost_slope(const prsm_alloc_cost *c, double t)
{
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL)
		return -c->rate * c->coefficient * exp(-c->rate * t);
	const double k = cost_power(c);
	return -k * c->coefficient * pow(t, -k - 1.0);
}

/* The weight of tolerance i in constraint o: c^2 (RSS) or |c| (worst case). */
static double weight(const prsm_alloc_problem *p, size_t o, size_t i)
{
	const double c = p->c[o][i];
	return p->stack == PRSM_ALLOC_RSS ? c * c : fabs(c);
}

double prsm_alloc_stack_value(const prsm_alloc_problem *p, size_t o, const double *t)
{
	double s = 0.0;
	if (p->stack == PRSM_ALLOC_WORST_CASE) {
		for (size_t i = 0; i < p->n; i++)
			s += fabs(p->c[o][i]) * t[i];
		return s;
	}
	/* scaled by the largest term, so that a large c T does not overflow its square */
	double big = 0.0;
	for (size_t i = 0; i < p->n; i++)
		big = fmax(big, fabs(p->c[o][i] * t[i]));
	if (big == 0.0 || !isfinite(big))
		return big;
	for (size_t i = 0; i < p->n; i++) {
		const double e = p->c[o][i] * t[i] / big;
		s += e * e;
	}
	return big * sqrt(s);
}

/* W0(exp(L)) for any L (Lambert W of a number that may overflow). */
static double lambert_w0_exp(double L)
{
	if (L < 600.0)
		return gsl_sf_lambert_W0(exp(L));
	double w = L - log(L);
	for (int it = 0; it < 50; it++) {
		double f = w + log(w) - L, dw = f / (1.0 + 1.0 / w);
		w -= dw;
		if (fabs(dw) <= 1e-16 * w)
			break;
	}
	return w;
}

/* The tolerance that minimises cost(T) + a T^2 (RSS) or cost(T) + a T (worst case) on
 * [t_min, t_max], with ln a given (a = 0: ln_a = -inf). *bound: -1, 0, +1. */
static double t_opt(const prsm_alloc_problem *p, size_t i, double ln_a, int *bound)
{
	const prsm_alloc_cost *c = &p->cost[i];
	double t;
	if (ln_a == -INFINITY) {
		t = INFINITY;
	} else if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL) {
		const double m = c->rate, B = c->coefficient;
		if (p->stack == PRSM_ALLOC_RSS) /* m B e^{-mT} = 2 a T: m T = W0(m^2 B / (2 a)) */
			t = lambert_w0_exp(2.0 * log(m) + log(B / 2.0) - ln_a) / m;
		else /* m B e^{-mT} = a */
			t = (log(m) + log(B) - ln_a) / m;
	} else {
		const double k = cost_power(c), B = c->coefficient;
		if (p->stack == PRSM_ALLOC_RSS) /* k B T^{-k-1} = 2 a T */
			t = exp((log(k * 0.5) + log(B) - ln_a) / (k + 2.0));
		else /* k B T^{-k-1} = a */
			t = exp((log(k) + log(B) - ln_a) / (k + 1.0));
	}
	*bound = 0;
	if (!(t > p->t_min[i])) { /* also NaN */
		t = p->t_min[i];
		*bound = -1;
	} else if (t >= p->t_max[i]) {
		t = p->t_max[i];
		*bound = 1;
	}
	return t;
}

/* d T / d a of t_opt at an interior optimum t with a > 0 (from differentiating the
 * stationarity condition). */
static double t_slope(const prsm_alloc_problem *p, size_t i, double t, double a)
{
	const prsm_alloc_cost *c = &p->cost[i];
	if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL)
		return p->stack == PRSM_ALLOC_RSS ? -t / (a * (1.0 + c->rate * t)) : -1.0 / (c->rate * a);
	const double k = cost_power(c);
	return p->stack == PRSM_ALLOC_RSS ? -t / ((k + 2.0) * a) : -t / ((k + 1.0) * a);
}

/* The exact solver's state: multipliers as u = ln lambda (-inf for 0), the logarithms of the
 * weights, and where the allocation goes. */
typedef struct {
	const prsm_alloc_problem *p;
	double lnw[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_TOLERANCES]; /* ln weight, -inf for 0 */
	double u[PRSM_ALLOC_MAX_CONSTRAINTS];                              /* ln lambda_o */
	size_t o;                  /* the multiplier being solved for (1-D root) */
	double *t;                 /* out: the allocation at the trial multipliers */
	int *bound;
	size_t *evaluations;
	double deadline;           /* prsm_clock_seconds() at which the time cap ends; INFINITY: none */
} dual_ws;

/* Allocation for the multipliers w->u with u_o replaced by uo (o = p->m: none replaced):
 * a_i = sum_o lambda_o w_oi by log-sum-exp, so no multiplier overflows. */
static void allocate_ln(dual_ws *w, size_t o, double uo)
{
	const prsm_alloc_problem *p = w->p;
	double v[PRSM_ALLOC_MAX_CONSTRAINTS];
	for (size_t i = 0; i < p->n; i++) {
		double mx = -INFINITY;
		for (size_t q = 0; q < p->m; q++) {
			v[q] = (q == o ? uo : w->u[q]) + w->lnw[q][i];
			mx = fmax(mx, v[q]);
		}
		double ln_a = mx;
		if (isfinite(mx)) {
			double s = 0.0;
			for (size_t q = 0; q < p->m; q++)
				s += exp(v[q] - mx);
			ln_a = mx + log(s);
		}
		w->t[i] = t_opt(p, i, ln_a, &w->bound[i]);
	}
	(*w->evaluations)++;
}

/* Brent's method on fn over the bracket [lo, hi] until the bracket is within epsabs + epsrel
 * |x| or ROOT_MAX_ITER iterations; *root gets the last estimate (it keeps its value when the
 * first iteration fails). Returns 0, or -1 when the solver cannot be allocated. */
static int brent_root(double *root, double (*fn)(double, void *), void *ctx, double lo, double hi, double epsabs,
                      double epsrel)
{
	gsl_function F = {fn, ctx};
	gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
	if (!s)
		return -1;
	gsl_root_fsolver_set(s, &F, lo, hi);
	for (int it = 0; it < ROOT_MAX_ITER; it++) {
		if (gsl_root_fsolver_iterate(s))
			break;
		*root = gsl_root_fsolver_root(s);
		if (gsl_root_test_interval(gsl_root_fsolver_x_lower(s), gsl_root_fsolver_x_upper(s), epsabs, epsrel) ==
		    GSL_SUCCESS)
			break;
	}
	gsl_root_fsolver_free(s);
	return 0;
}

static double root_fn(double u, void *params)
{
	dual_ws *w = params;
	allocate_ln(w, w->o, u);
	double h = prsm_alloc_stack_value(w->p, w->o, w->t);
	return log(fmax(h, 1e-300)) - log(w->p->limit[w->o]);
}

/* u_o with the others fixed: -inf (lambda_o = 0) when the constraint is slack there, else the
 * root of h_o = L_o. */
static int solve_one(dual_ws *w, size_t o, prsm_error *err)
{
	const prsm_alloc_problem *p = w->p;
	int has = 0;
	for (size_t i = 0; i < p->n; i++)
		has |= p->c[o][i] != 0.0;
	w->o = o;
	if (!has) {
		w->u[o] = -INFINITY;
		return 0;
	}
	allocate_ln(w, o, -INFINITY);
	if (prsm_alloc_stack_value(p, o, w->t) <= p->limit[o]) {
		w->u[o] = -INFINITY;
		return 0;
	}
	double u0 = isfinite(w->u[o]) ? w->u[o] : 0.0;
	double f0 = root_fn(u0, w);
	double lo = u0, hi = u0, flo = f0, fhi = f0;
	char ptr[48];
	snprintf(ptr, sizeof ptr, "/constraints/%zu", o);
	for (double step = 1.0; f0 > 0.0 ? fhi > 0.0 : flo < 0.0; step *= 2.0) {
		if (f0 > 0.0) {
			lo = hi, flo = fhi;
			hi = fmin(u0 + step, U_MAX);
			fhi = root_fn(hi, w);
			if (hi >= U_MAX && fhi > 0.0)
				return prsm_error_set(err, PRSM_EINVAL, ptr,
				                      "constraint %zu cannot be met within the lower bounds", o);
		} else {
			hi = lo, fhi = flo;
			lo = fmax(u0 - step, -U_MAX);
			flo = root_fn(lo, w);
			if (lo <= -U_MAX && flo < 0.0) {
				w->u[o] = lo;
				return 0;
			}
		}
	}
	double u = flo == 0.0 ? lo : hi;
	if (flo != 0.0 && fhi != 0.0 && brent_root(&u, root_fn, w, lo, hi, U_EPSABS, U_EPSREL))
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	w->u[o] = u;
	return 0;
}

int prsm_alloc_check(const prsm_alloc_problem *p, prsm_error *err)
{
	char ptr[48];
	if (p->n < 1 || p->n > PRSM_ALLOC_MAX_TOLERANCES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "1 to %d tolerances", PRSM_ALLOC_MAX_TOLERANCES);
	if (p->m < 1 || p->m > PRSM_ALLOC_MAX_CONSTRAINTS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "1 to %d constraints", PRSM_ALLOC_MAX_CONSTRAINTS);
	if (p->stack != PRSM_ALLOC_RSS && p->stack != PRSM_ALLOC_WORST_CASE)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "unknown stack model");
	for (size_t i = 0; i < p->n; i++) {
		const prsm_alloc_cost *c = &p->cost[i];
		snprintf(ptr, sizeof ptr, "/allocate/%zu", i);
		if (!(isfinite(c->fixed) && c->fixed >= 0.0) || !(isfinite(c->coefficient) && c->coefficient > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "tolerance %zu: the cost needs A >= 0 and B > 0", i);
		if (c->kind == PRSM_ALLOC_COST_RECIPROCAL_POWER && !(isfinite(c->power) && c->power > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "tolerance %zu: the power k must be > 0", i);
		if (c->kind == PRSM_ALLOC_COST_EXPONENTIAL && !(isfinite(c->rate) && c->rate > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "tolerance %zu: the rate m must be > 0", i);
		if ((int)c->kind < 0 || c->kind > PRSM_ALLOC_COST_EXPONENTIAL)
			return prsm_error_set(err, PRSM_EINVAL, ptr, "tolerance %zu: unknown cost model", i);
		if (!(isfinite(p->t_min[i]) && p->t_min[i] >= 0.0) || !(p->t_max[i] > p->t_min[i]))
			return prsm_error_set(err, PRSM_EINVAL, ptr,
			                      "tolerance %zu: bounds need 0 <= min < max (min %g, max %g)", i,
			                      p->t_min[i], p->t_max[i]);
		int used = 0;
		for (size_t o = 0; o < p->m; o++) {
			if (!isfinite(p->c[o][i]))
				return prsm_error_set(err, PRSM_EINVAL, ptr, "constraint %zu: sensitivity %zu is not finite", o, i);
			used |= p->c[o][i] != 0.0;
		}
		if (!used && !isfinite(p->t_max[i]))
			return prsm_error_set(err, PRSM_EINVAL, ptr,
			                      "tolerance %zu moves no constrained output and has no upper bound: "
			                      "its cheapest half-width is infinite", i);
	}
	for (size_t o = 0; o < p->m; o++) {
		snprintf(ptr, sizeof ptr, "/constraints/%zu", o);
		if (!(p->limit[o] > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "constraint %zu: the assembly tolerance must be > 0", o);
		if (!isfinite(p->limit[o]))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "constraint %zu: the assembly tolerance is not finite", o);
		double h = prsm_alloc_stack_value(p, o, p->t_min);
		if (!(h < p->limit[o]))
			return prsm_error_set(err, PRSM_EINVAL, ptr,
			                      "constraint %zu cannot be met: with every tolerance at its lower bound "
			                      "the stack is %.6g, the limit %.6g", o, h, p->limit[o]);
	}
	return 0;
}

static void finish(prsm_alloc_solution *out, const prsm_alloc_problem *p)
{
	out->total_cost = 0.0;
	for (size_t i = 0; i < p->n; i++) {
		out->cost[i] = prsm_alloc_cost_eval(&p->cost[i], out->t[i]);
		out->total_cost += out->cost[i];
	}
	for (size_t o = 0; o < p->m; o++)
		out->stack[o] = prsm_alloc_stack_value(p, o, out->t);
}

/* KKT residual: the worst relative violation of h_o <= L_o, or of h_o = L_o where lambda_o > 0. */
static double kkt_residual(const prsm_alloc_problem *p, const double *u, const double *t)
{
	double r = 0.0;
	for (size_t o = 0; o < p->m; o++) {
		double e = prsm_alloc_stack_value(p, o, t) / p->limit[o] - 1.0;
		r = fmax(r, u[o] > -INFINITY ? fabs(e) : fmax(e, 0.0));
	}
	return r;
}

/* Cancelled or out of time? Fills err. */
static int interrupted(const dual_ws *w, prsm_alloc_solution *out, prsm_error *err)
{
	if (prsm_cancel_requested(w->p->cancel))
		return prsm_error_set(err, PRSM_ECANCELLED, NULL, "the allocation was cancelled");
	if (prsm_clock_seconds() >= w->deadline) {
		out->time_cap = 1;
		return prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the time cap of %.3g s ran out during the solve",
		                      w->p->max_time_s);
	}
	return 0;
}

/* ---- projected Newton on the dual (several constraints) ---------------------------------- */

/* In normalised multipliers mu_o = lambda_o L_o^q (q = 2 RSS, 1 worst case) the dual is
 * D(mu) = sum_i [cost_i(T_i) + a_i phi(T_i)] - sum_o mu_o with a_i = sum_o mu_o v_oi,
 * v_oi = w_oi / L_o^q, phi(T) = T^2 or T, concave; its gradient r_o = sum_i v_oi phi(T_i) - 1
 * (the relative violation), its Hessian H_op = sum_i v_oi v_pi phi'(T_i) dT_i/da_i over the
 * tolerances inside their bounds. */
typedef struct {
	double v[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_TOLERANCES];
	double r[PRSM_ALLOC_MAX_CONSTRAINTS];
	double H[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_CONSTRAINTS];
	double value;
} dual_eval;

static void dual_at(dual_eval *e, dual_ws *w, const double *mu)
{
	const prsm_alloc_problem *p = w->p;
	const int rss = p->stack == PRSM_ALLOC_RSS;
	double dphi[PRSM_ALLOC_MAX_TOLERANCES];
	e->value = 0.0;
	for (size_t o = 0; o < p->m; o++) {
		e->r[o] = -1.0;
		e->value -= mu[o];
	}
	for (size_t i = 0; i < p->n; i++) {
		double a = 0.0;
		for (size_t o = 0; o < p->m; o++)
			a += mu[o] * e->v[o][i];
		const double t = t_opt(p, i, a > 0.0 ? log(a) : -INFINITY, &w->bound[i]);
		const double phi = rss ? t * t : t;
		w->t[i] = t;
		e->value += prsm_alloc_cost_eval(&p->cost[i], t) + a * phi;
		for (size_t o = 0; o < p->m; o++)
			e->r[o] += e->v[o][i] * phi;
		dphi[i] = w->bound[i] == 0 && a > 0.0 ? (rss ? 2.0 * t : 1.0) * t_slope(p, i, t, a) : 0.0;
	}
	for (size_t o = 0; o < p->m; o++)
		for (size_t q = 0; q <= o; q++) {
			double h = 0.0;
			for (size_t i = 0; i < p->n; i++)
				h += e->v[o][i] * e->v[q][i] * dphi[i];
			e->H[o][q] = e->H[q][o] = h;
		}
	(*w->evaluations)++;
}

/* Solve A x = b for a symmetric positive definite A (n x n, Cholesky in place). 0 or -1. */
static int cholesky_solve(double A[][PRSM_ALLOC_MAX_CONSTRAINTS], double *x, const double *b, size_t n)
{
	for (size_t j = 0; j < n; j++) {
		double d = A[j][j];
		for (size_t k = 0; k < j; k++)
			d -= A[j][k] * A[j][k];
		if (!(d > 0.0) || !isfinite(d))
			return -1;
		A[j][j] = sqrt(d);
		for (size_t i = j + 1; i < n; i++) {
			double s = A[i][j];
			for (size_t k = 0; k < j; k++)
				s -= A[i][k] * A[j][k];
			A[i][j] = s / A[j][j];
		}
	}
	for (size_t i = 0; i < n; i++) {
		double s = b[i];
		for (size_t k = 0; k < i; k++)
			s -= A[i][k] * x[k];
		x[i] = s / A[i][i];
	}
	for (size_t i = n; i-- > 0;) {
		double s = x[i];
		for (size_t k = i + 1; k < n; k++)
			s -= A[k][i] * x[k];
		x[i] = s / A[i][i];
	}
	return 0;
}

/* Projected Newton from w->u: on return 0, w->u and w->t hold the KKT point (residual <=
 * KKT_RTOL); 1 when it stalled (w->u unchanged); or the code of interrupted(). */
static int solve_newton(dual_ws *w, prsm_alloc_solution *out, prsm_error *err)
{
	const prsm_alloc_problem *p = w->p;
	const size_t m = p->m;
	const double q_pow = p->stack == PRSM_ALLOC_RSS ? 2.0 : 1.0;
	dual_eval *e = &(dual_eval){0}, *e2 = &(dual_eval){0};
	double mu[PRSM_ALLOC_MAX_CONSTRAINTS], mu2[PRSM_ALLOC_MAX_CONSTRAINTS], lnL[PRSM_ALLOC_MAX_CONSTRAINTS];
	for (size_t o = 0; o < m; o++) {
		lnL[o] = log(p->limit[o]);
		mu[o] = exp(w->u[o] + q_pow * lnL[o]);
		for (size_t i = 0; i < p->n; i++)
			e->v[o][i] = e2->v[o][i] = exp(w->lnw[o][i] - q_pow * lnL[o]);
		if (!isfinite(mu[o]))
			return 1;
	}
	dual_at(e, w, mu);
	double res = kkt_residual(p, w->u, w->t);
	for (int it = 0; it < NEWTON_MAX_ITER; it++) {
		if (res <= KKT_RTOL)
			break;
		int rc = interrupted(w, out, err);
		if (rc)
			return rc;
		/* free multipliers: positive, or at 0 with the constraint violated */
		size_t F[PRSM_ALLOC_MAX_CONSTRAINTS], nf = 0;
		for (size_t o = 0; o < m; o++)
			if (mu[o] > 0.0 || e->r[o] > 0.0)
				F[nf++] = o;
		double M[PRSM_ALLOC_MAX_CONSTRAINTS][PRSM_ALLOC_MAX_CONSTRAINTS], rf[PRSM_ALLOC_MAX_CONSTRAINTS],
		       d[PRSM_ALLOC_MAX_CONSTRAINTS];
		double diag = 0.0;
		for (size_t a = 0; a < nf; a++)
			diag = fmax(diag, -e->H[F[a]][F[a]]);
		double delta = 1e-12 * diag + 1e-300;
		int ok = -1;
		for (int tries = 0; tries < 8 && ok; tries++, delta *= 1e3) {
			for (size_t a = 0; a < nf; a++) {
				for (size_t b = 0; b < nf; b++)
					M[a][b] = -e->H[F[a]][F[b]];
				M[a][a] += delta;
				rf[a] = e->r[F[a]];
			}
			ok = cholesky_solve(M, d, rf, nf);
		}
		if (ok)
			return 1;
		double slope = 0.0;
		for (size_t a = 0; a < nf; a++)
			slope += rf[a] * d[a];
		int accepted = 0;
		for (double alpha = 1.0; alpha > 1e-15 && !accepted; alpha *= 0.5) {
			for (size_t o = 0; o < m; o++)
				mu2[o] = 0.0;
			for (size_t a = 0; a < nf; a++)
				mu2[F[a]] = fmax(0.0, mu[F[a]] + alpha * d[a]);
			double u2[PRSM_ALLOC_MAX_CONSTRAINTS];
			for (size_t o = 0; o < m; o++)
				u2[o] = mu2[o] > 0.0 ? log(mu2[o]) - q_pow * lnL[o] : -INFINITY;
			dual_at(e2, w, mu2);
			double res2 = kkt_residual(p, u2, w->t);
			if (e2->value >= e->value + 1e-4 * alpha * slope || res2 < res) {
				accepted = 1;
				res = res2;
				memcpy(mu, mu2, sizeof mu);
				dual_eval *tmp = e;
				e = e2;
				e2 = tmp;
			}
		}
		if (!accepted) {
			dual_at(e, w, mu); /* w->t back to mu's allocation */
			return 1;
		}
	}
	if (res > KKT_RTOL) {
		dual_at(e, w, mu);
		return 1;
	}
	for (size_t o = 0; o < m; o++)
		w->u[o] = mu[o] > 0.0 ? log(mu[o]) - q_pow * lnL[o] : -INFINITY;
	dual_at(e, w, mu);
	return 0;
}

static int solve_exact(prsm_alloc_solution *out, const prsm_alloc_problem *p, double deadline, prsm_error *err)
{
	dual_ws *w = &(dual_ws){0};
	w->p = p;
	w->t = out->t;
	w->bound = out->at_bound;
	w->evaluations = &out->evaluations;
	w->deadline = deadline;
	for (size_t o = 0; o < p->m; o++) {
		w->u[o] = -INFINITY;
		for (size_t i = 0; i < p->n; i++) {
			double wt = weight(p, o, i);
			w->lnw[o][i] = wt > 0.0 ? log(wt) : -INFINITY;
		}
	}
	int rc = 0, newton_tried = 0;
	double r = INFINITY;
	for (int sweep = 1; sweep <= MAX_SWEEPS; sweep++) {
		for (size_t o = 0; o < p->m; o++) {
			rc = solve_one(w, o, err);
			if (rc)
				return rc;
		}
		out->sweeps = sweep;
		allocate_ln(w, p->m, 0.0);
		r = kkt_residual(p, w->u, w->t);
		if (p->m == 1 || r <= KKT_RTOL)
			break;
		if (!newton_tried) {
			/* from the first sweep's multipliers: quadratic convergence where the sweeps crawl */
			newton_tried = 1;
			rc = solve_newton(w, out, err);
			if (rc < 0)
				return rc;
			allocate_ln(w, p->m, 0.0);
			r = kkt_residual(p, w->u, w->t);
			if (r <= KKT_RTOL)
				break;
		}
		rc = interrupted(w, out, err);
		if (rc)
			return rc;
	}
	for (size_t o = 0; o < p->m; o++)
		out->multiplier[o] = exp(w->u[o]);
	if (r > 1e-9)
		return prsm_error_set(err, PRSM_ENOCONVERGE, NULL,
		                      "the multipliers did not settle in %d sweeps (constraint residual %.3g)",
		                      out->sweeps, r);
	return 0;
}

/* ---- NLopt ------------------------------------------------------------------------------- */

typedef struct {
	const prsm_alloc_problem *p;
	double cost_scale;         /* objective divided by this (the start point's cost) */
	size_t o;
	size_t *evaluations;
	nlopt_opt opt;             /* forced to stop when p->cancel is set */
} nl_ctx;

static double nl_objective(unsigned n, const double *x, double *grad, void *data)
{
	nl_ctx *c = data;
	double f = 0.0;
	(*c->evaluations)++;
	if (prsm_cancel_requested(c->p->cancel))
		nlopt_force_stop(c->opt);
	for (unsigned i = 0; i < n; i++) {
		double t = exp(x[i]);
		f += prsm_alloc_cost_eval(&c->p->cost[i], t);
		if (grad)
			grad[i] = cost_slope(&c->p->cost[i], t) * t / c->cost_scale;
	}
	return f / c->cost_scale;
}

static double nl_constraint(unsigned n, const double *x, double *grad, void *data)
{
	const nl_ctx *c = data;
	const prsm_alloc_problem *p = c->p;
	const double L = p->limit[c->o];
	double s = 0.0;
	for (unsigned i = 0; i < n; i++) {
		double t = exp(x[i]), ct = p->c[c->o][i] * t / L;
		if (p->stack == PRSM_ALLOC_RSS) {
			s += ct * ct;
			if (grad)
				grad[i] = 2.0 * ct * ct;
		} else {
			s += fabs(ct);
			if (grad)
				grad[i] = fabs(ct);
		}
	}
	return s - 1.0;
}

static int solve_nlopt(prsm_alloc_solution *out, const prsm_alloc_problem *p, prsm_alloc_solver solver,
                       double deadline, prsm_error *err)
{
	const unsigned n = (unsigned)p->n;
	double x[PRSM_ALLOC_MAX_TOLERANCES], lb[PRSM_ALLOC_MAX_TOLERANCES], ub[PRSM_ALLOC_MAX_TOLERANCES];
	nl_ctx ctx[PRSM_ALLOC_MAX_CONSTRAINTS + 1];
	int rc = 0;
	/* start: every constraint's share split equally, within the bounds */
	for (size_t i = 0; i < p->n; i++) {
		double t = p->t_max[i];
		for (size_t o = 0; o < p->m; o++) {
			size_t used = 0;
			for (size_t j = 0; j < p->n; j++)
				used += p->c[o][j] != 0.0;
			if (p->c[o][i] != 0.0) {
				double share = p->stack == PRSM_ALLOC_RSS ? p->limit[o] / sqrt((double)used)
				                                          : p->limit[o] / (double)used;
				t = fmin(t, share / fabs(p->c[o][i]));
			}
		}
		t = fmax(t, p->t_min[i]);
		if (!(t > 0.0))
			t = 1e-6 * p->t_max[i];
		x[i] = log(t);
		lb[i] = p->t_min[i] > 0.0 ? log(p->t_min[i]) : x[i] - 60.0;
		ub[i] = isfinite(p->t_max[i]) ? log(p->t_max[i]) : x[i] + 60.0;
		x[i] = fmin(fmax(x[i], lb[i]), ub[i]);
	}
	double cost0 = 0.0;
	for (size_t i = 0; i < p->n; i++)
		cost0 += prsm_alloc_cost_eval(&p->cost[i], exp(x[i]));
	nlopt_opt opt = nlopt_create(solver == PRSM_ALLOC_SOLVER_COBYLA ? NLOPT_LN_COBYLA : NLOPT_LD_SLSQP, n);
	if (!opt)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	ctx[0] = (nl_ctx){p, cost0 > 0.0 && isfinite(cost0) ? cost0 : 1.0, 0, &out->evaluations, opt};
	nlopt_set_min_objective(opt, nl_objective, &ctx[0]);
	for (size_t o = 0; o < p->m; o++) {
		ctx[o + 1] = ctx[0];
		ctx[o + 1].o = o;
		nlopt_add_inequality_constraint(opt, nl_constraint, &ctx[o + 1], 1e-14);
	}
	nlopt_set_lower_bounds(opt, lb);
	nlopt_set_upper_bounds(opt, ub);
	nlopt_set_xtol_abs1(opt, 1e-13);
	nlopt_set_ftol_rel(opt, 1e-15);
	nlopt_set_maxeval(opt, 200000);
	if (isfinite(deadline)) {
		double left = deadline - prsm_clock_seconds();
		nlopt_set_maxtime(opt, fmax(left, 1e-6));
	}
	if (solver == PRSM_ALLOC_SOLVER_COBYLA)
		nlopt_set_initial_step1(opt, 0.1);
	double f;
	nlopt_result r = nlopt_optimize(opt, x, &f);
	nlopt_destroy(opt);
	if (r == NLOPT_FORCED_STOP && prsm_cancel_requested(p->cancel)) {
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "the allocation was cancelled");
		goto cleanup;
	}
	if (r == NLOPT_MAXTIME_REACHED) {
		out->time_cap = 1;
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the time cap of %.3g s ran out during the solve",
		                    p->max_time_s);
		goto cleanup;
	}
	if (r < 0) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "NLopt %s failed (%s)",
		                    prsm_alloc_solver_name(solver), nlopt_result_to_string(r));
		goto cleanup;
	}
	for (size_t i = 0; i < p->n; i++) {
		out->t[i] = exp(x[i]);
		out->at_bound[i] = x[i] <= lb[i] + 1e-9 && p->t_min[i] > 0.0 ? -1
		                   : x[i] >= ub[i] - 1e-9 && isfinite(p->t_max[i]) ? 1 : 0;
	}
	for (size_t o = 0; o < p->m; o++)
		out->multiplier[o] = NAN;
cleanup:
	return rc;
}

int prsm_alloc_solve(prsm_alloc_solution *out, const prsm_alloc_problem *p, prsm_alloc_solver solver,
                     prsm_error *err)
{
	const double t0 = prsm_clock_seconds();
	const double deadline = p->max_time_s > 0.0 ? t0 + p->max_time_s : INFINITY;
	memset(out, 0, sizeof *out);
	int rc = prsm_alloc_check(p, err);
	if (rc)
		return rc;
	if (prsm_cancel_requested(p->cancel))
		return prsm_error_set(err, PRSM_ECANCELLED, NULL, "the allocation was cancelled");
	out->solver = solver;
	if (solver == PRSM_ALLOC_SOLVER_EXACT) {
		rc = solve_exact(out, p, deadline, err);
		if (rc == PRSM_ENOCONVERGE && !out->time_cap) {
			/* polish where the dual methods stall */
			prsm_error_clear(err);
			rc = solve_nlopt(out, p, PRSM_ALLOC_SOLVER_SLSQP, deadline, err);
			out->solver = PRSM_ALLOC_SOLVER_SLSQP;
		}
	} else {
		rc = solve_nlopt(out, p, solver, deadline, err);
	}
	if (rc == 0)
		finish(out, p);
	return rc;
}

/* ---- yield ------------------------------------------------------------------------------- */

double prsm_alloc_normal_out_fraction(const prsm_spec *spec, double mean, double sigma)
{
	double q = 0.0;
	if (spec->has_lower)
		q += sigma > 0.0 ? gsl_cdf_ugaussian_P((spec->lower - mean) / sigma) : (mean < spec->lower);
	if (spec->has_upper)
		q += sigma > 0.0 ? gsl_cdf_ugaussian_Q((spec->upper - mean) / sigma) : (mean > spec->upper);
	return q;
}

static int inside(const prsm_spec *spec, double mean, prsm_error *err)
{
	if (!spec->has_lower && !spec->has_upper)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the spec has no limit");
	if (!isfinite(mean) || (spec->has_lower && !(mean > spec->lower)) ||
	    (spec->has_upper && !(mean < spec->upper)))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "the nominal %.6g is not strictly inside the spec: no tolerance can meet it", mean);
	return 0;
}

typedef struct {
	const prsm_spec *spec;
	double mean, ln_q;
} sigma_ctx;

static double sigma_fn(double v, void *params)
{
	const sigma_ctx *c = params;
	return log(prsm_alloc_normal_out_fraction(c->spec, c->mean, exp(v))) - c->ln_q;
}

int prsm_alloc_sigma_for_out_fraction(double *sigma, const prsm_spec *spec, double mean,
                                      double out_fraction, prsm_error *err)
{
	int rc = inside(spec, mean, err);
	if (rc)
		return rc;
	if (!(out_fraction > 0.0 && out_fraction < 0.5))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "the fraction out of spec must be in (0, 0.5): target yield above 50 %%");
	const double du = spec->has_upper ? spec->upper - mean : INFINITY;
	const double dl = spec->has_lower ? mean - spec->lower : INFINITY;
	if (!spec->has_lower || !spec->has_upper) {
		*sigma = fmin(du, dl) / gsl_cdf_ugaussian_Qinv(out_fraction);
		return 0;
	}
	const double d = fmin(du, dl);
	if (du == dl) { /* symmetric: both tails q/2 */
		*sigma = d / gsl_cdf_ugaussian_Qinv(0.5 * out_fraction);
		return 0;
	}
	double lo = log(d / gsl_cdf_ugaussian_Qinv(0.5 * out_fraction));
	double hi = log(d / gsl_cdf_ugaussian_Qinv(out_fraction));
	sigma_ctx c = {spec, mean, log(out_fraction)};
	double flo = sigma_fn(lo, &c), fhi = sigma_fn(hi, &c), v = hi;
	if (flo >= 0.0) {
		v = lo;
	} else if (fhi > 0.0 && brent_root(&v, sigma_fn, &c, lo, hi, 1e-15, 1e-15)) {
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	*sigma = exp(v);
	return 0;
}

int prsm_alloc_worst_case_limit(double *limit, const prsm_spec *spec, double mean, prsm_error *err)
{
	int rc = inside(spec, mean, err);
	if (rc)
		return rc;
	*limit = fmin(spec->has_upper ? spec->upper - mean : INFINITY,
	              spec->has_lower ? mean - spec->lower : INFINITY);
	return 0;
}
