/*
 * test_alloc.c: the linear tolerance allocation of opt/alloc.h against the closed forms of
 * reference/benchmarks.md ("Tolerance allocation, closed form"): RSS and worst case with
 * reciprocal-power costs (k = 1, 2, 2.7) to 1e-6 relative, the exponential cost with RSS
 * against an independent Lambert-W solution with its own bisection on the multiplier, bound
 * clamping and several constraints against NLopt (SLSQP and COBYLA) and a KKT check, the
 * target-yield -> sigma rule plugged back to 1e-9 (LS-1's 44.557 ppm gives its sigma), and
 * every error path.
 */
#include "test_support.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_sf_lambert.h>
#include <string.h>

#include "opt/alloc.h"
#include "io/global.h"
#include "opt/alloc_mc.h"

/* A four-tolerance stack with "high-entropy" figures. */
static const double B4[4] = {2.385, 1.3, 0.71, 3.1};
static const double C4[4] = {1.2, -0.8, 2.5, 0.45};
static const double LIMIT4 = 0.0735;

static void problem4(prsm_alloc_problem *p, prsm_alloc_stack stack, prsm_alloc_cost_kind kind, double k)
{
	memset(p, 0, sizeof *p);
	p->n = 4;
	p->m = 1;
	p->stack = stack;
	for (size_t i = 0; i < 4; i++) {
		p->cost[i] = (prsm_alloc_cost){kind, 0.5, B4[i], k, 0.0};
		p->t_min[i] = 0.0;
		p->t_max[i] = INFINITY;
		p->c[0][i] = C4[i];
	}
	p->limit[0] = LIMIT4;
}

static void assert_rel(double actual, double expected, double rel)
{
	assert_close(actual, expected, rel * fabs(expected));
}

static void rss_power(double k, prsm_alloc_cost_kind kind)
{
	prsm_alloc_problem p;
	problem4(&p, PRSM_ALLOC_RSS, kind, k);
	prsm_alloc_solution s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	/* T_i = mu (B_i/c_i^2)^{1/(k+2)}, mu = T_asm / sqrt(sum c_i^2 (B_i/c_i^2)^{2/(k+2)}) */
	double sum = 0.0;
	for (int i = 0; i < 4; i++)
		sum += C4[i] * C4[i] * pow(B4[i] / (C4[i] * C4[i]), 2.0 / (k + 2.0));
	double mu = LIMIT4 / sqrt(sum), total = 0.0;
	for (int i = 0; i < 4; i++) {
		double t = mu * pow(B4[i] / (C4[i] * C4[i]), 1.0 / (k + 2.0));
		assert_rel(s.t[i], t, 1e-6);
		assert_rel(s.t[i], t, 1e-12); /* what it actually reaches */
		total += 0.5 + B4[i] / pow(t, k);
		assert_int_equal(s.at_bound[i], 0);
	}
	assert_rel(s.total_cost, total, 1e-12);
	assert_rel(s.stack[0], LIMIT4, 1e-13);
	assert_true(s.multiplier[0] > 0.0);
}

static void test_rss_reciprocal_power(void **state)
{
	(void)state;
	rss_power(1.0, PRSM_ALLOC_COST_RECIPROCAL);
	rss_power(2.0, PRSM_ALLOC_COST_RECIPROCAL_SQUARED);
	rss_power(1.0, PRSM_ALLOC_COST_RECIPROCAL_POWER);
	rss_power(2.7, PRSM_ALLOC_COST_RECIPROCAL_POWER);
	rss_power(0.35, PRSM_ALLOC_COST_RECIPROCAL_POWER);
}

static void wc_power(double k)
{
	prsm_alloc_problem p;
	problem4(&p, PRSM_ALLOC_WORST_CASE, PRSM_ALLOC_COST_RECIPROCAL_POWER, k);
	prsm_alloc_solution s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	/* T_i = nu (B_i/|c_i|)^{1/(k+1)}, nu from sum |c_i| T_i = T_asm */
	double sum = 0.0;
	for (int i = 0; i < 4; i++)
		sum += fabs(C4[i]) * pow(B4[i] / fabs(C4[i]), 1.0 / (k + 1.0));
	for (int i = 0; i < 4; i++)
		assert_rel(s.t[i], LIMIT4 / sum * pow(B4[i] / fabs(C4[i]), 1.0 / (k + 1.0)), 1e-12);
	assert_rel(s.stack[0], LIMIT4, 1e-13);
}

static void test_worst_case_reciprocal_power(void **state)
{
	(void)state;
	wc_power(1.0);
	wc_power(2.0);
	wc_power(2.7);
}

/* Exponential cost with RSS: T_i = W0(m^2 B_i / (2 lambda c_i^2)) / m, lambda by bisection. */
static double exp_stack(double lambda, const double *m, double *t)
{
	double s = 0.0;
	for (int i = 0; i < 4; i++) {
		t[i] = gsl_sf_lambert_W0(m[i] * m[i] * B4[i] / (2.0 * lambda * C4[i] * C4[i])) / m[i];
		s += C4[i] * C4[i] * t[i] * t[i];
	}
	return sqrt(s);
}

static void test_rss_exponential(void **state)
{
	(void)state;
	const double m[4] = {31.7, 12.2, 55.0, 20.4}; /* per unit of T */
	prsm_alloc_problem p;
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_EXPONENTIAL, 0.0);
	for (int i = 0; i < 4; i++)
		p.cost[i].rate = m[i];
	prsm_alloc_solution s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	double lo = 1e-12, hi = 1e12, t[4];
	for (int it = 0; it < 300; it++) {
		double mid = sqrt(lo * hi);
		if (exp_stack(mid, m, t) > LIMIT4)
			lo = mid;
		else
			hi = mid;
	}
	exp_stack(sqrt(lo * hi), m, t);
	for (int i = 0; i < 4; i++)
		assert_rel(s.t[i], t[i], 1e-6);
	assert_rel(s.multiplier[0], sqrt(lo * hi), 1e-6);
	/* stationarity: m B e^{-mT} = 2 lambda c^2 T */
	for (int i = 0; i < 4; i++)
		assert_rel(m[i] * B4[i] * exp(-m[i] * s.t[i]), 2.0 * s.multiplier[0] * C4[i] * C4[i] * s.t[i], 1e-10);
}

/* Bounds: the exact solver clamps; SLSQP and COBYLA on the same problem agree. */
static void test_bounds_against_nlopt(void **state)
{
	(void)state;
	prsm_alloc_problem p;
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL_POWER, 1.6);
	prsm_alloc_solution free_s, s, q, r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_alloc_solve(&free_s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	/* cap the widest below its free value, floor the narrowest above it */
	size_t wide = 0, narrow = 0;
	for (size_t i = 1; i < 4; i++) {
		if (free_s.t[i] > free_s.t[wide])
			wide = i;
		if (free_s.t[i] < free_s.t[narrow])
			narrow = i;
	}
	p.t_max[wide] = 0.7 * free_s.t[wide];
	p.t_min[narrow] = 1.4 * free_s.t[narrow];
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	assert_int_equal(s.at_bound[wide], 1);
	assert_int_equal(s.at_bound[narrow], -1);
	assert_close(s.t[wide], p.t_max[wide], 0.0);
	assert_close(s.t[narrow], p.t_min[narrow], 0.0);
	assert_rel(s.stack[0], LIMIT4, 1e-13);
	/* the free ones keep the stationarity k B T^{-k-1} = 2 lambda c^2 T */
	for (size_t i = 0; i < 4; i++)
		if (i != wide && i != narrow)
			assert_rel(1.6 * B4[i] * pow(s.t[i], -2.6), 2.0 * s.multiplier[0] * C4[i] * C4[i] * s.t[i], 1e-10);
	assert_int_equal(prsm_alloc_solve(&q, &p, PRSM_ALLOC_SOLVER_SLSQP, &err), 0);
	assert_int_equal(prsm_alloc_solve(&r, &p, PRSM_ALLOC_SOLVER_COBYLA, &err), 0);
	for (size_t i = 0; i < 4; i++) {
		assert_rel(q.t[i], s.t[i], 1e-5);
		assert_rel(r.t[i], s.t[i], 1e-4);
	}
	assert_true(s.total_cost <= q.total_cost * (1.0 + 1e-9));
	assert_rel(q.total_cost, s.total_cost, 1e-8);
	/* brute force: no feasible perturbation of the exact solution is cheaper */
	for (size_t i = 0; i < 4; i++)
		for (size_t j = 0; j < 4; j++) {
			if (i == j)
				continue;
			double t[4];
			memcpy(t, s.t, sizeof t);
			t[i] *= 1.001;
			if (t[i] > p.t_max[i])
				continue;
			/* give j what keeps the RSS stack on its limit */
			double rest = LIMIT4 * LIMIT4;
			for (size_t k = 0; k < 4; k++)
				if (k != j)
					rest -= C4[k] * C4[k] * t[k] * t[k];
			if (rest <= 0.0)
				continue;
			t[j] = sqrt(rest) / fabs(C4[j]);
			if (t[j] < p.t_min[j] || t[j] > p.t_max[j])
				continue;
			double c = 0.0;
			for (size_t k = 0; k < 4; k++)
				c += prsm_alloc_cost_eval(&p.cost[k], t[k]);
			assert_true(c >= s.total_cost);
		}
}

/* A constraint already met with every tolerance at its upper bound: multiplier 0. */
static void test_slack_constraint(void **state)
{
	(void)state;
	prsm_alloc_problem p;
	problem4(&p, PRSM_ALLOC_WORST_CASE, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	for (int i = 0; i < 4; i++)
		p.t_max[i] = 0.001;
	prsm_alloc_solution s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	assert_close(s.multiplier[0], 0.0, 0.0);
	for (int i = 0; i < 4; i++) {
		assert_close(s.t[i], 0.001, 0.0);
		assert_int_equal(s.at_bound[i], 1);
	}
}

/* Two outputs, two constraints: both hold, the active ones with equality, and SLSQP agrees. */
static void test_two_constraints(void **state)
{
	(void)state;
	for (int stack = 0; stack < 2; stack++) {
		prsm_alloc_problem p;
		problem4(&p, (prsm_alloc_stack)stack, PRSM_ALLOC_COST_RECIPROCAL_POWER, 1.3);
		const double c2[4] = {0.3, 1.9, -0.4, 2.2};
		p.m = 2;
		for (int i = 0; i < 4; i++)
			p.c[1][i] = c2[i];
		p.limit[1] = 0.061;
		prsm_alloc_solution s, q;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
		assert_int_equal(prsm_alloc_solve(&q, &p, PRSM_ALLOC_SOLVER_SLSQP, &err), 0);
		for (size_t o = 0; o < 2; o++) {
			assert_true(s.stack[o] <= p.limit[o] * (1.0 + 1e-11));
			if (s.multiplier[o] > 0.0)
				assert_rel(s.stack[o], p.limit[o], 1e-11);
		}
		assert_true(s.multiplier[0] > 0.0 && s.multiplier[1] > 0.0);
		for (size_t i = 0; i < 4; i++)
			assert_rel(q.t[i], s.t[i], 1e-5);
		assert_rel(q.total_cost, s.total_cost, 1e-8);
	}
}

/* 16 competing constraints on 64 tolerances (nearly parallel sensitivities, and constraints
 * that share tolerances), RSS and worst case: the exact solver settles with several
 * constraints binding, in few evaluations, and agrees with SLSQP. */
static void many_constraints(prsm_alloc_problem *p, prsm_alloc_stack stack, double spread)
{
	memset(p, 0, sizeof *p);
	p->n = PRSM_ALLOC_MAX_TOLERANCES;
	p->m = PRSM_ALLOC_MAX_CONSTRAINTS;
	p->stack = stack;
	uint64_t x = 0x9e3779b97f4a7c15ull;
	for (size_t i = 0; i < p->n; i++) {
		x = x * 6364136223846793005ull + 1442695040888963407ull;
		double r = (double)(x >> 11) / 9007199254740992.0;
		p->cost[i] = (prsm_alloc_cost){i % 3 == 2 ? PRSM_ALLOC_COST_EXPONENTIAL : PRSM_ALLOC_COST_RECIPROCAL_POWER,
		                               0.25, 0.5 + 2.385 * r, i % 3 == 1 ? 2.0 : 1.0, 1.7};
		p->t_min[i] = 1e-4;
		p->t_max[i] = 1.0;
		for (size_t o = 0; o < p->m; o++) {
			x = x * 6364136223846793005ull + 1442695040888963407ull;
			double q = (double)(x >> 11) / 9007199254740992.0;
			p->c[o][i] = (1.0 + 0.3 * r) * (1.0 + spread * (q - 0.5)) * (i % p->m == o ? 3.0 : 1.0);
		}
	}
	for (size_t o = 0; o < p->m; o++)
		p->limit[o] = stack == PRSM_ALLOC_RSS ? 1.0 + 0.01 * (double)o : 12.0 + 0.1 * (double)o;
}

static void test_many_constraints(void **state)
{
	(void)state;
	static prsm_alloc_problem p;
	static prsm_alloc_solution s, q;
	const double spreads[2] = {0.02, 0.6};
	for (int stack = 0; stack < 2; stack++)
		for (int k = 0; k < 2; k++) {
			many_constraints(&p, (prsm_alloc_stack)stack, spreads[k]);
			prsm_error err = PRSM_ERROR_INIT;
			assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
			assert_int_equal(prsm_alloc_solve(&q, &p, PRSM_ALLOC_SOLVER_SLSQP, &err), 0);
			int binding = 0;
			for (size_t o = 0; o < p.m; o++) {
				assert_true(s.stack[o] <= p.limit[o] * (1.0 + 1e-11));
				if (s.multiplier[o] > 0.0) {
					binding++;
					assert_rel(s.stack[o], p.limit[o], 1e-11);
				}
			}
			print_message("stack %d spread %.2f: %d binding, %zu evaluations, %d sweeps, solver %s, cost %.15g vs %.15g\n",
			              stack, spreads[k], binding, s.evaluations, s.sweeps, prsm_alloc_solver_name(s.solver),
			              s.total_cost, q.total_cost);
			assert_int_equal(s.solver, PRSM_ALLOC_SOLVER_EXACT);
			assert_true(s.evaluations < 2000);
			assert_rel(s.total_cost, q.total_cost, 1e-8);
			assert_true(s.total_cost <= q.total_cost * (1.0 + 1e-12));
		}
}

/* Cancellation and the time cap inside the solve (exact and NLopt). */
static void test_cancel_time_cap(void **state)
{
	(void)state;
	static prsm_alloc_problem p;
	static prsm_alloc_solution s;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_cancel_flag cancel = 1;
	many_constraints(&p, PRSM_ALLOC_RSS, 0.6);
	p.cancel = &cancel;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_ECANCELLED);
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_SLSQP, &err), PRSM_ECANCELLED);
	cancel = 0;
	p.max_time_s = 1e-12;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_ENOCONVERGE);
	assert_int_equal(s.time_cap, 1);
	assert_non_null(strstr(err.message, "time cap"));
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_SLSQP, &err), PRSM_ENOCONVERGE);
	assert_int_equal(s.time_cap, 1);
	p.max_time_s = 60.0;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	assert_int_equal(s.time_cap, 0);
}

/* Any cost scale: every coefficient times 1e250 (or 1e-250) gives the same half-widths, the
 * multipliers and costs scaled by the same factor (the roots are taken on ln lambda). */
static void test_cost_scale(void **state)
{
	(void)state;
	const double scales[2] = {1e250, 1e-250};
	for (int stack = 0; stack < 2; stack++)
		for (int k = 0; k < 2; k++) {
			prsm_alloc_problem p, q;
			problem4(&p, (prsm_alloc_stack)stack, PRSM_ALLOC_COST_RECIPROCAL_POWER, 1.3);
			q = p;
			for (int i = 0; i < 4; i++) {
				q.cost[i].coefficient *= scales[k];
				q.cost[i].fixed *= scales[k];
			}
			prsm_alloc_solution a, b;
			prsm_error err = PRSM_ERROR_INIT;
			assert_int_equal(prsm_alloc_solve(&a, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
			assert_int_equal(prsm_alloc_solve(&b, &q, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
			for (int i = 0; i < 4; i++)
				assert_rel(b.t[i], a.t[i], 1e-12);
			assert_rel(b.total_cost, a.total_cost * scales[k], 1e-12);
			assert_rel(b.multiplier[0], a.multiplier[0] * scales[k], 1e-10);
		}
}

/* The model's limits: the correction's scale multiplies the yield targets' T_asm only; a
 * given assembly tolerance stays as given (also 1e300, without overflow); a nominal outside
 * the spec is reported at the constraint's spec with its message intact. */
static void test_model_limits(void **state)
{
	(void)state;
	static prsm_alloc_model md;
	static prsm_alloc_problem p;
	static prsm_alloc_step st;
	prsm_error err = PRSM_ERROR_INIT;
	memset(&md, 0, sizeof md);
	md.n = 4;
	md.m = 3;
	md.stack = PRSM_ALLOC_RSS;
	for (size_t i = 0; i < 4; i++) {
		md.cost[i] = (prsm_alloc_cost){PRSM_ALLOC_COST_RECIPROCAL, 0.0, B4[i], 1.0, 0.0};
		md.t_max[i] = INFINITY;
		md.k[i] = 3.0;
		for (size_t o = 0; o < 3; o++)
			md.c[o][i] = C4[(i + o) % 4];
	}
	md.spec[0] = (prsm_spec){1, 1, 5.0, 35.0};
	md.nominal[0] = 21.7;
	md.has_target[0] = 1;
	md.out_fraction[0] = 0.0027;
	md.assembly_tol[1] = 0.385;
	md.fixed_var[1] = 0.01;
	md.assembly_tol[2] = 1e300;
	assert_int_equal(prsm_alloc_model_problem(&p, &st, &md, 1.0, &err), 0);
	const double tasm0 = st.assembly_tol[0];
	assert_int_equal(prsm_alloc_model_problem(&p, &st, &md, 0.615, &err), 0);
	assert_rel(st.assembly_tol[0], 0.615 * tasm0, 1e-15);
	assert_close(st.assembly_tol[1], 0.385, 0.0);
	assert_rel(p.limit[1], sqrt(0.385 * 0.385 - 0.09), 1e-14);
	assert_close(st.assembly_tol[2], 1e300, 0.0);
	assert_rel(p.limit[2], 1e300, 1e-15);
	assert_int_equal(prsm_alloc_model_problem(&p, &st, &md, 1.7, &err), 0);
	assert_close(st.assembly_tol[1], 0.385, 0.0);
	/* the nominal outside the spec */
	md.nominal[0] = 40.0;
	assert_int_equal(prsm_alloc_model_problem(&p, &st, &md, 1.0, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/constraints/0/spec");
	assert_string_equal(err.message,
	                    "output 0: the nominal 40 is not strictly inside the spec: no tolerance can meet it");
	/* the kept tolerances take the whole given budget */
	md.nominal[0] = 21.7;
	md.fixed_var[1] = 0.02;
	assert_int_equal(prsm_alloc_model_problem(&p, &st, &md, 1.0, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/constraints/1");
}

/* Target yield -> largest sigma, plugged back. */
static void test_sigma_for_yield(void **state)
{
	(void)state;
	prsm_error err = PRSM_ERROR_INIT;
	double sigma;
	/* LS-1: spec [0, 0.2], mean 0.1: 44.557 ppm out of spec at sigma 0.0244948974278318 */
	prsm_spec ls1 = {1, 1, 0.0, 0.2};
	assert_int_equal(prsm_alloc_sigma_for_out_fraction(&sigma, &ls1, 0.1, 4.455709060413593e-05, &err), 0);
	assert_rel(sigma, 0.024494897427831785, 1e-9);
	const prsm_spec specs[4] = {{1, 1, 5.0, 35.0}, {0, 1, 0.0, 3.0}, {1, 0, 0.85, 0.0}, {1, 1, -0.2, 0.31}};
	const double means[4] = {21.7, 1.05, 0.904, 0.02};
	const double q[4] = {0.0027, 1e-6, 0.05, 0.0013};
	for (int k = 0; k < 4; k++) {
		assert_int_equal(prsm_alloc_sigma_for_out_fraction(&sigma, &specs[k], means[k], q[k], &err), 0);
		double back = prsm_alloc_normal_out_fraction(&specs[k], means[k], sigma);
		assert_close(1.0 - back, 1.0 - q[k], 1e-9);
		assert_rel(back, q[k], 1e-9);
	}
	double limit;
	assert_int_equal(prsm_alloc_worst_case_limit(&limit, &specs[0], 21.7, &err), 0);
	assert_close(limit, 13.3, 1e-12);
	assert_int_equal(prsm_alloc_worst_case_limit(&limit, &specs[1], 1.05, &err), 0);
	assert_close(limit, 1.95, 1e-12);
}

static void test_errors(void **state)
{
	(void)state;
	prsm_alloc_problem p;
	prsm_alloc_solution s;
	prsm_error err = PRSM_ERROR_INIT;
	double v;
	/* infeasible: the lower bounds alone break the limit */
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	p.t_min[2] = 0.04;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "cannot be met"));
	/* bounds */
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	p.t_max[1] = 0.0;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	p.t_min[1] = NAN;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	/* costs */
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL_POWER, -1.0);
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_EXPONENTIAL, 0.0);
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	p.cost[0].coefficient = INFINITY;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	/* a tolerance no constraint sees and nothing bounds */
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	p.c[0][3] = 0.0;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	p.t_max[3] = 0.25;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), 0);
	assert_close(s.t[3], 0.25, 0.0);
	/* sizes and limits */
	problem4(&p, PRSM_ALLOC_RSS, PRSM_ALLOC_COST_RECIPROCAL, 1.0);
	p.limit[0] = -1.0;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	p.limit[0] = LIMIT4;
	p.n = 0;
	assert_int_equal(prsm_alloc_solve(&s, &p, PRSM_ALLOC_SOLVER_EXACT, &err), PRSM_EINVAL);
	/* yield rule */
	prsm_spec spec = {1, 1, 0.0, 0.2}, none = {0, 0, 0.0, 0.0};
	assert_int_equal(prsm_alloc_sigma_for_out_fraction(&v, &spec, 0.2, 0.001, &err), PRSM_EINVAL);
	assert_int_equal(prsm_alloc_sigma_for_out_fraction(&v, &spec, 0.1, 0.6, &err), PRSM_EINVAL);
	assert_int_equal(prsm_alloc_sigma_for_out_fraction(&v, &spec, 0.1, 0.0, &err), PRSM_EINVAL);
	assert_int_equal(prsm_alloc_sigma_for_out_fraction(&v, &none, 0.1, 0.01, &err), PRSM_EINVAL);
	assert_int_equal(prsm_alloc_worst_case_limit(&v, &spec, -0.1, &err), PRSM_EINVAL);
	assert_int_equal(prsm_alloc_worst_case_limit(&v, &spec, NAN, &err), PRSM_EINVAL);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rss_reciprocal_power),
		cmocka_unit_test(test_worst_case_reciprocal_power),
		cmocka_unit_test(test_rss_exponential),
		cmocka_unit_test(test_bounds_against_nlopt),
		cmocka_unit_test(test_slack_constraint),
		cmocka_unit_test(test_two_constraints),
		cmocka_unit_test(test_many_constraints),
		cmocka_unit_test(test_cancel_time_cap),
		cmocka_unit_test(test_cost_scale),
		cmocka_unit_test(test_model_limits),
		cmocka_unit_test(test_sigma_for_yield),
		cmocka_unit_test(test_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
