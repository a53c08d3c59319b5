/*
 * test_rare.c: the rare-event engine's FORM and SORM, its space (copula, marginals), the auto
 * rule, the one-call interface and its errors (mc/rare.h, docs/rare-events.md). The sampling
 * estimators are in test_rare_sampling.c. Exact values come from closed forms and GSL
 * (quadrature, gamma CDF).
 */
#include "test_support.h"

#include <stdatomic.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>

#include "mc/engine.h"
#include "io/global.h"
#include "mc/rare.h"

#define MAXD 128

/* ---- problems --------------------------------------------------------------------------------- */

static void set_normal(prsm_mc_variable *v, double mean, double sd)
{
	memset(v, 0, sizeof *v);
	v->dist.kind = PRSM_DIST_NORMAL;
	v->dist.p[0] = mean;
	v->dist.p[1] = sd;
}

/* g = sum a_i x_i + c */
typedef struct {
	size_t n;
	double a[MAXD];
	double c;
} linear_ctx;

static int linear_g(double *value, const void *ctx, void *ws, const double *x)
{
	const linear_ctx *l = ctx;
	(void)ws;
	double s = l->c;
	for (size_t i = 0; i < l->n; i++)
		s += l->a[i] * x[i];
	*value = s;
	return 0;
}

static prsm_rare_problem problem(const void *ctx, int (*g)(double *, const void *, void *, const double *),
                                 const prsm_mc_variable *v, size_t d)
{
	prsm_rare_problem p;
	memset(&p, 0, sizeof p);
	p.limit.ctx = ctx;
	p.limit.g = g;
	p.vars = v;
	p.d = d;
	return p;
}

/* R - S with R ~ N(mu_r, 1), S ~ N(2, 1) */
static linear_ctx rs_ctx = {2, {1.0, -1.0}, 0.0};

static void rs_vars(prsm_mc_variable *v, double mu_r)
{
	set_normal(&v[0], mu_r, 1.0);
	set_normal(&v[1], 2.0, 1.0);
}

static prsm_rare_options opts(void)
{
	prsm_rare_options o;
	prsm_rare_options_init(&o);
	return o;
}

/* ---- tests ------------------------------------------------------------------------------------ */

static void test_options(void **state)
{
	(void)state;
	prsm_rare_options a = PRSM_RARE_OPTIONS_INIT, b;
	memset(&b, 0xff, sizeof b);
	assert_int_equal(prsm_rare_options_init(&b), 0);
	/* the documented defaults (member by member: padding is not compared) */
	assert_true(b.seed == a.seed && b.seed == 1 && b.stream_offset == 0 && b.threads == 1);
	assert_true(b.time_cap_s == 0.0 && b.cancel == NULL && b.progress == NULL && b.progress_ctx == NULL);
	assert_true(b.max_evaluations == 100000 && b.target_cov == 0.05);
	assert_true(b.form_max_iterations == 100 && b.form_tol_g == 1e-8 && b.form_tol_u == 1e-6 && b.fd_step == 1e-4);
	assert_true(b.line_search_max == 30 && b.armijo == 0.1 && b.backtrack == 0.5 && b.n_starts == 0 && !b.starts);
	assert_true(b.hessian_step == 1e-3);
	assert_true(b.block_size == 256 && b.round_blocks == 8 && b.min_samples == 1000 && b.min_failures == 10);
	assert_true(b.max_samples == 100000 && b.pilot_samples == 1024);
	assert_true(b.subset_samples == 1000 && b.subset_p0 == 0.1 && b.subset_max_levels == 20);
	assert_true(b.subset_proposal == PRSM_RARE_PROPOSAL_NORMAL && b.subset_width == 1.0);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_options_check(&a, 3, &err), 0);
	prsm_rare_options c = a;
	c.threads = 0;
	assert_int_equal(prsm_rare_options_check(&c, 3, &err), PRSM_EINVAL);
	c = a;
	c.subset_p0 = 0.9;
	assert_int_equal(prsm_rare_options_check(&c, 3, &err), PRSM_EINVAL);
	c = a;
	c.target_cov = 0.0;
	assert_int_equal(prsm_rare_options_check(&c, 3, &err), PRSM_EINVAL);
	c = a;
	c.n_starts = 1;
	c.starts = NULL;
	assert_int_equal(prsm_rare_options_check(&c, 3, &err), PRSM_EINVAL);
	assert_int_equal(prsm_rare_options_check(&a, 0, &err), PRSM_EINVAL);
	prsm_rare_method m;
	for (int k = 0; k <= PRSM_RARE_SUBSET; k++) {
		assert_int_equal(prsm_rare_method_parse(prsm_rare_method_name((prsm_rare_method)k), &m), 0);
		assert_int_equal((int)m, k);
	}
	assert_int_equal(prsm_rare_method_parse("sorm2", &m), PRSM_ENOTFOUND);
	assert_string_equal(prsm_rare_stop_name(PRSM_RARE_STOP_CANCELLED), "cancelled");
}

/* R - S: FORM is exact (a linear limit state of normals), beta to 1e-6 on both cases. */
static void test_form_r_minus_s(void **state)
{
	(void)state;
	const double mus[2] = {4.0, 7.0};
	const double exact_pf[2] = {0.0786496, 2.03476e-4};
	for (int k = 0; k < 2; k++) {
		prsm_mc_variable v[2];
		rs_vars(v, mus[k]);
		prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
		prsm_rare_options o = opts();
		prsm_rare_form_result f;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
		double beta = (mus[k] - 2.0) / sqrt(2.0);
		printf("R-S mu_R=%g: beta %.12f (exact %.12f) pf %.7g (exact %.7g) iterations %zu evaluations %zu: %s\n",
		       mus[k], f.beta, beta, f.pf, gsl_cdf_ugaussian_Q(beta), f.iterations, f.evaluations, f.reason);
		assert_true(f.converged);
		assert_int_equal(f.stop, PRSM_RARE_STOP_CONVERGED);
		assert_true(fabs(f.beta - beta) < 1e-6);
		assert_true(fabs(f.pf - exact_pf[k]) < 1e-6 * exact_pf[k] + 5e-8 * (k == 0));
		assert_true(fabs(f.pf / exact_pf[k] - 1.0) < 2e-5);
		/* design point: u* = beta (-1, 1) / sqrt 2, x* = (mu_R + u1, 2 + u2): R = S there */
		assert_true(fabs(f.u_star[0] + beta / sqrt(2.0)) < 1e-6);
		assert_true(fabs(f.u_star[1] - beta / sqrt(2.0)) < 1e-6);
		assert_true(fabs(f.alpha[0] + 1.0 / sqrt(2.0)) < 1e-9);
		assert_true(fabs(f.x_star[0] - f.x_star[1]) < 1e-6);
		assert_true(fabs(f.x_star[0] - (mus[k] + 2.0) / 2.0) < 1e-6);
		assert_true(fabs(f.alpha2[0] - 0.5) < 1e-9 && fabs(f.alpha2[1] - 0.5) < 1e-9);
		assert_true(fabs(f.importance[0] - 0.5) < 1e-9);
		assert_int_equal(f.n_points, 1);
		assert_true(f.iterations <= 3);
		assert_int_equal(f.failed_index, SIZE_MAX);
		prsm_rare_form_result_free(&f);
	}
}

/* A sum of 100 normals with different means and sds: FORM exact, in 100 dimensions; the
 * importance factors are sigma_i^2 / sum sigma^2. */
static void test_form_sum_of_normals(void **state)
{
	(void)state;
	enum { N = 100 };
	prsm_mc_variable v[N];
	linear_ctx l;
	memset(&l, 0, sizeof l);
	l.n = N;
	double mean = 0.0, var = 0.0;
	for (size_t i = 0; i < N; i++) {
		double mu = 1.0 + 0.01 * (double)i, sd = 0.5 + 0.01 * (double)(i % 7);
		set_normal(&v[i], mu, sd);
		l.a[i] = -1.0;
		mean += mu;
		var += sd * sd;
	}
	double beta = 3.7;
	l.c = mean + beta * sqrt(var);
	prsm_rare_problem p = problem(&l, linear_g, v, N);
	prsm_rare_options o = opts();
	o.threads = 2;
	prsm_rare_form_result f;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	printf("sum of %d normals: beta %.10f (exact %.10f), %zu iterations, %zu evaluations\n", N, f.beta, beta,
	       f.iterations, f.evaluations);
	assert_true(f.converged);
	assert_true(fabs(f.beta - beta) < 1e-6);
	double s = 0.0;
	for (size_t i = 0; i < N; i++) {
		double sd = v[i].dist.p[1];
		assert_true(fabs(f.importance[i] - sd * sd / var) < 1e-9);
		s += f.alpha2[i];
	}
	assert_true(fabs(s - 1.0) < 1e-12);
	prsm_rare_form_result_free(&f);
}

/* Exponentials E_i = -ln Q(u_i) built from standard normals inside the limit state:
 * g = t - sum E_i; P = Q_gamma(t; n, 1). FORM's design point is symmetric, u_i = b with
 * Q(b) = exp(-t / n): beta = sqrt(n) b. */
typedef struct {
	size_t n;
	double t;
} expsum_ctx;

static int expsum_g(double *value, const void *ctx, void *ws, const double *x)
{
	const expsum_ctx *e = ctx;
	(void)ws;
	double s = 0.0;
	for (size_t i = 0; i < e->n; i++)
		s += -log(gsl_cdf_ugaussian_Q(x[i]));
	*value = e->t - s;
	return 0;
}

static void test_form_sorm_exponentials(void **state)
{
	(void)state;
	enum { N = 10 };
	prsm_mc_variable v[N];
	for (size_t i = 0; i < N; i++)
		set_normal(&v[i], 0.0, 1.0);
	expsum_ctx e = {N, 30.0};
	prsm_rare_problem p = problem(&e, expsum_g, v, N);
	prsm_rare_options o = opts();
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_SORM, &p, &o, &err), 0);
	double exact = gsl_cdf_gamma_Q(e.t, (double)N, 1.0);
	double b = gsl_cdf_ugaussian_Qinv(exp(-e.t / N));
	double beta = sqrt((double)N) * b;
	printf("exponentials: FORM beta %.9f (exact FORM %.9f) pf %.4g, SORM Breitung %.4g HR %.4g Tvedt %.4g, exact %.4g; "
	       "kappa %.6f..%.6f; %zu evaluations\n",
	       r.form.beta, beta, r.form.pf, r.sorm.pf_breitung, r.sorm.pf_hr, r.sorm.pf_tvedt, exact, r.sorm.kappa[0],
	       r.sorm.kappa[N - 2], r.evaluations);
	assert_true(r.form.converged);
	assert_true(fabs(r.form.beta - beta) < 1e-5);
	for (size_t i = 0; i < N; i++)
		assert_true(fabs(r.form.u_star[i] - b) < 1e-4);
	assert_true(r.sorm.converged);
	/* by symmetry the n - 1 curvatures are equal: g = t - sum E(u_i), E = -ln Q, E' = h = phi / Q,
	 * E'' = h (h - u); kappa = -E''(b) / (sqrt(n) E'(b)) (negative: the safe set is convex) */
	double h = gsl_ran_ugaussian_pdf(b) / gsl_cdf_ugaussian_Q(b);
	double kappa = -h * (h - b) / (sqrt((double)N) * h);
	for (size_t i = 0; i + 1 < N; i++)
		assert_true(fabs(r.sorm.kappa[i] / kappa - 1.0) < 1e-5);
	double breitung = r.form.pf * pow(1.0 + beta * kappa, -0.5 * (N - 1));
	assert_true(fabs(r.sorm.pf_breitung / breitung - 1.0) < 1e-4);
	/* FORM is off by a factor 75 here (1 + beta kappa = 0.31: strongly curved); SORM much less */
	assert_true(fabs(log(r.sorm.pf_breitung / exact)) < 0.25 * fabs(log(r.form.pf / exact)));
	assert_true(fabs(log(r.sorm.pf_tvedt / exact)) < 0.35 * fabs(log(r.form.pf / exact)));
	assert_true(fabs(r.pf - r.sorm.pf_tvedt) == 0.0);
	assert_int_equal(r.method, PRSM_RARE_SORM);
	prsm_rare_result_free(&r);
}

/* The paraboloid g = beta - u_n + kappa / 2 sum_{i<n} u_i^2: curvatures kappa, Breitung's value
 * Phi(-beta) (1 + beta kappa)^-(n-1)/2 exactly; the exact P by a 1-D quadrature over the
 * chi-square of the first n - 1 coordinates. */
typedef struct {
	size_t n;
	double beta, kappa;
} para_ctx;

static int para_g(double *value, const void *ctx, void *ws, const double *x)
{
	const para_ctx *c = ctx;
	(void)ws;
	double s = 0.0;
	for (size_t i = 0; i + 1 < c->n; i++)
		s += x[i] * x[i];
	*value = c->beta - x[c->n - 1] + 0.5 * c->kappa * s;
	return 0;
}

static double para_integrand(double s, void *pp)
{
	const para_ctx *c = pp;
	return gsl_cdf_ugaussian_Q(c->beta + 0.5 * c->kappa * s) * gsl_ran_chisq_pdf(s, (double)(c->n - 1));
}

static double para_exact(const para_ctx *c)
{
	gsl_integration_workspace *w = gsl_integration_workspace_alloc(1000);
	gsl_function f = {para_integrand, (void *)(uintptr_t)c};
	double res, abserr;
	gsl_integration_qagiu(&f, 0.0, 0.0, 1e-10, 1000, w, &res, &abserr);
	gsl_integration_workspace_free(w);
	return res;
}

static void test_sorm_paraboloid(void **state)
{
	(void)state;
	const para_ctx cases[] = {{6, 3.0, 0.2}, {6, 3.0, -0.1}, {3, 2.5, 0.5}, {20, 3.5, 0.05}};
	for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
		const para_ctx *c = &cases[k];
		prsm_mc_variable v[32];
		for (size_t i = 0; i < c->n; i++)
			set_normal(&v[i], 0.0, 1.0);
		prsm_rare_problem p = problem(c, para_g, v, c->n);
		prsm_rare_options o = opts();
		o.threads = 2;
		prsm_rare_result r;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_run(&r, PRSM_RARE_SORM, &p, &o, &err), 0);
		double breitung = gsl_cdf_ugaussian_Q(c->beta) * pow(1.0 + c->beta * c->kappa, -0.5 * (double)(c->n - 1));
		double exact = para_exact(c);
		printf("paraboloid n=%zu beta=%g kappa=%g: FORM %.5g Breitung %.8g (formula %.8g) HR %.5g Tvedt %.5g exact %.5g, "
		       "%zu evaluations\n",
		       c->n, c->beta, c->kappa, r.form.pf, r.sorm.pf_breitung, breitung, r.sorm.pf_hr, r.sorm.pf_tvedt, exact,
		       r.evaluations);
		assert_true(r.form.converged);
		assert_true(fabs(r.form.beta - c->beta) < 1e-6);
		assert_true(r.sorm.converged);
		assert_int_equal(r.sorm.n_curvatures, c->n - 1);
		for (size_t i = 0; i + 1 < c->n; i++)
			assert_true(fabs(r.sorm.kappa[i] - c->kappa) < 1e-6);
		assert_true(fabs(r.sorm.pf_breitung / breitung - 1.0) < 1e-6);
		assert_true(fabs(r.sorm.beta_breitung - gsl_cdf_ugaussian_Qinv(breitung)) < 1e-6);
		/* Tvedt's is the closest (exact to its asymptotics for a paraboloid) */
		assert_true(fabs(r.sorm.pf_tvedt / exact - 1.0) < 0.03);
		assert_true(fabs(r.sorm.pf_tvedt / exact - 1.0) <= fabs(r.sorm.pf_breitung / exact - 1.0) + 1e-12);
		assert_int_equal(r.sorm.evaluations, 2 * c->n * c->n);
		prsm_rare_result_free(&r);
	}
	/* 1 + beta kappa <= 0: every formula refuses, FORM's value stands */
	para_ctx bad = {4, 3.0, -0.5};
	prsm_mc_variable v[4];
	for (size_t i = 0; i < 4; i++)
		set_normal(&v[i], 0.0, 1.0);
	prsm_rare_problem p = problem(&bad, para_g, v, 4);
	prsm_rare_options o = opts();
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_SORM, &p, &o, &err), 0);
	printf("paraboloid kappa=-0.5 beta=3: %s\n", r.sorm.reason);
	assert_true(r.form.converged);
	assert_false(r.sorm.ok_breitung);
	assert_false(r.sorm.ok_tvedt);
	assert_false(r.sorm.converged);
	assert_int_equal(r.sorm.stop, PRSM_RARE_STOP_CURVATURE);
	assert_true(isnan(r.sorm.pf_breitung));
	assert_true(r.pf == r.form.pf || r.sorm.ok_hr);
	prsm_rare_result_free(&r);
}

/* Correlated lognormals through the Gaussian copula: g = c - sum a_i ln x_i is linear in the
 * normal scores z = L u, so FORM is exact with beta = (c - sum a mu) / sqrt(a' S C S a), and
 * the importance by variable is (a_i sigma_i (C ...)) ... = gamma_i^2 with gamma proportional
 * to the gradient in z: (a_i sigma_i)^2 / sum. */
typedef struct {
	double a[3], c;
} loglin_ctx;

static int loglin_g(double *value, const void *ctx, void *ws, const double *x)
{
	const loglin_ctx *l = ctx;
	(void)ws;
	*value = l->c - l->a[0] * log(x[0]) - l->a[1] * log(x[1]) - l->a[2] * log(x[2]);
	return 0;
}

static void test_form_correlated(void **state)
{
	(void)state;
	prsm_mc_variable v[3];
	memset(v, 0, sizeof v);
	const double mu[3] = {0.1, -0.2, 0.3}, sg[3] = {0.2, 0.3, 0.1};
	for (int i = 0; i < 3; i++) {
		v[i].dist.kind = PRSM_DIST_LOGNORMAL;
		v[i].dist.p[0] = mu[i];
		v[i].dist.p[1] = sg[i];
	}
	prsm_mc_correlation corr[2] = {{0, 1, 0.5}, {1, 2, -0.3}};
	loglin_ctx l = {{1.0, 2.0, 0.5}, 0.0};
	double C[3][3] = {{1, 0.5, 0}, {0.5, 1, -0.3}, {0, -0.3, 1}};
	double m = 0.0, var = 0.0;
	for (int i = 0; i < 3; i++) {
		m += l.a[i] * mu[i];
		for (int j = 0; j < 3; j++)
			var += l.a[i] * sg[i] * C[i][j] * l.a[j] * sg[j];
	}
	double beta = 3.2;
	l.c = m + beta * sqrt(var);
	prsm_rare_problem p = problem(&l, loglin_g, v, 3);
	p.corr = corr;
	p.n_corr = 2;
	prsm_rare_options o = opts();
	prsm_rare_form_result f;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	double s2 = 0.0;
	for (int i = 0; i < 3; i++)
		s2 += l.a[i] * sg[i] * l.a[i] * sg[i];
	printf("correlated lognormals: beta %.10f (exact %.10f), importance %.6f %.6f %.6f (exact %.6f %.6f %.6f)\n", f.beta,
	       beta, f.importance[0], f.importance[1], f.importance[2], pow(l.a[0] * sg[0], 2) / s2,
	       pow(l.a[1] * sg[1], 2) / s2, pow(l.a[2] * sg[2], 2) / s2);
	assert_true(f.converged);
	assert_true(fabs(f.beta - beta) < 1e-6);
	for (int i = 0; i < 3; i++)
		assert_true(fabs(f.importance[i] - pow(l.a[i] * sg[i], 2) / s2) < 1e-7);
	/* x* on the limit state, and the map the same as prsm_rare_u_to_x */
	double x[3], g;
	assert_int_equal(prsm_rare_u_to_x(&p, f.u_star, x, &err), 0);
	assert_memory_equal(x, f.x_star, sizeof x);
	loglin_g(&g, &l, NULL, x);
	assert_true(fabs(g) < 1e-8);
	prsm_rare_form_result_free(&f);

	/* a correlation matrix that is not positive definite is refused, as by the engine */
	prsm_mc_correlation badc[3] = {{0, 1, 0.9}, {1, 2, 0.9}, {0, 2, -0.9}};
	p.corr = badc;
	p.n_corr = 3;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "positive definite"));
	prsm_rare_form_result_free(&f);
}

/* The engine's other marginals: a Rayleigh tail (exact: P = exp(-t^2 / 2 sigma^2), FORM exact in
 * one variable) and the sum of two uniforms (P = eps^2 / 2, FORM's beta = sqrt 2 Phi^-1(1 - eps/2)). */
static void test_form_marginals(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	memset(v, 0, sizeof v);
	v[0].dist.kind = PRSM_DIST_RAYLEIGH;
	v[0].dist.p[0] = 0.5;
	linear_ctx l = {1, {-1.0}, 2.5};
	prsm_rare_problem p = problem(&l, linear_g, v, 1);
	prsm_rare_options o = opts();
	prsm_rare_form_result f;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	double exact = exp(-2.5 * 2.5 / (2.0 * 0.25));
	printf("rayleigh: pf %.10g exact %.10g beta %.10f\n", f.pf, exact, f.beta);
	assert_true(f.converged);
	assert_true(fabs(f.pf / exact - 1.0) < 1e-6);
	prsm_rare_form_result_free(&f);

	for (int i = 0; i < 2; i++) {
		v[i].dist.kind = PRSM_DIST_UNIFORM;
		v[i].dist.p[0] = 0.0;
		v[i].dist.p[1] = 1.0;
	}
	double eps = 0.02;
	linear_ctx l2 = {2, {-1.0, -1.0}, 2.0 - eps};
	p = problem(&l2, linear_g, v, 2);
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	double beta = sqrt(2.0) * gsl_cdf_ugaussian_Qinv(eps / 2.0);
	printf("two uniforms: beta %.10f (exact FORM %.10f) pf %.5g, exact P %.5g\n", f.beta, beta, f.pf, eps * eps / 2);
	assert_true(f.converged);
	assert_true(fabs(f.beta - beta) < 1e-5);
	prsm_rare_form_result_free(&f);
}

/* A series system min(g1, g2) of two planes, beta1 = 3 and beta2 = 3.2 at 53 degrees: FORM from
 * the origin finds the nearer plane, a second start finds the other. */
typedef struct {
	double b1, b2;
} series_ctx;

static int series_g(double *value, const void *ctx, void *ws, const double *x)
{
	const series_ctx *c = ctx;
	(void)ws;
	double g1 = c->b1 - x[0], g2 = c->b2 - (0.6 * x[0] + 0.8 * x[1]);
	*value = g1 < g2 ? g1 : g2;
	return 0;
}

static void test_form_series_starts(void **state)
{
	(void)state;
	prsm_mc_variable v[3];
	for (int i = 0; i < 3; i++)
		set_normal(&v[i], 0.0, 1.0);
	series_ctx c = {3.0, 3.2};
	prsm_rare_problem p = problem(&c, series_g, v, 3);
	prsm_rare_options o = opts();
	prsm_rare_form_result f;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	assert_true(f.converged);
	assert_true(fabs(f.beta - 3.0) < 1e-6);
	assert_int_equal(f.n_points, 1);
	prsm_rare_form_result_free(&f);
	double starts[2 * 3] = {0.0, 4.0, 0.0, 3.0, 0.0, 0.0};
	o.starts = starts;
	o.n_starts = 2;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	printf("series: %zu design points, beta %.8f and %.8f\n", f.n_points, f.point_beta[0], f.point_beta[1]);
	assert_int_equal(f.n_points, 2);
	assert_true(fabs(f.point_beta[0] - 3.0) < 1e-6);
	assert_true(fabs(f.point_beta[1] - 3.2) < 1e-6);
	assert_true(fabs(f.points[3 + 0] - 3.2 * 0.6) < 1e-5 && fabs(f.points[3 + 1] - 3.2 * 0.8) < 1e-5);
	assert_true(fabs(f.beta - 3.0) < 1e-6);
	prsm_rare_form_result_free(&f);
}

/* Origin in the failure domain: beta < 0, P_f = Phi(-beta) > 1/2; SORM does not apply. */
static void test_form_negative_beta(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	rs_vars(v, 1.0); /* R - S: mean -1, sd sqrt 2 */
	prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
	prsm_rare_options o = opts();
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_SORM, &p, &o, &err), 0);
	assert_true(r.form.converged);
	assert_true(fabs(r.form.beta + 1.0 / sqrt(2.0)) < 1e-6);
	assert_true(fabs(r.form.pf - gsl_cdf_ugaussian_P(1.0 / sqrt(2.0))) < 1e-7);
	assert_false(r.sorm.converged);
	assert_non_null(strstr(r.sorm.reason, "beta"));
	prsm_rare_result_free(&r);
}

/* FORM's gradient runs in parallel: 1 and 2 threads give the same bits. */
static void form_same(const prsm_rare_form_result *a, const prsm_rare_form_result *b)
{
	size_t d = a->d;
	assert_int_equal(a->d, b->d);
	assert_memory_equal(&a->beta, &b->beta, sizeof a->beta);
	assert_memory_equal(&a->pf, &b->pf, sizeof a->pf);
	assert_memory_equal(&a->g_star, &b->g_star, sizeof a->g_star);
	assert_memory_equal(&a->grad_norm, &b->grad_norm, sizeof a->grad_norm);
	assert_memory_equal(a->u_star, b->u_star, d * sizeof *a->u_star);
	assert_memory_equal(a->x_star, b->x_star, d * sizeof *a->x_star);
	assert_memory_equal(a->alpha, b->alpha, d * sizeof *a->alpha);
	assert_memory_equal(a->importance, b->importance, d * sizeof *a->importance);
	assert_memory_equal(a->points, b->points, PRSM_RARE_MAX_DESIGN_POINTS * d * sizeof *a->points);
	assert_memory_equal(a->point_beta, b->point_beta, sizeof a->point_beta);
	assert_int_equal(a->iterations, b->iterations);
	assert_int_equal(a->evaluations, b->evaluations);
	assert_int_equal(a->n_points, b->n_points);
	assert_string_equal(a->reason, b->reason);
}

static void test_form_sorm_threads(void **state)
{
	(void)state;
	enum { N = 12 };
	prsm_mc_variable v[N];
	for (size_t i = 0; i < N; i++)
		set_normal(&v[i], 0.0, 1.0);
	expsum_ctx e = {N, 34.0};
	prsm_rare_problem p = problem(&e, expsum_g, v, N);
	prsm_rare_result r[3];
	for (int t = 0; t < 3; t++) {
		prsm_rare_options o = opts();
		o.threads = t + 1;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_run(&r[t], PRSM_RARE_SORM, &p, &o, &err), 0);
	}
	for (int t = 1; t < 3; t++) {
		form_same(&r[0].form, &r[t].form);
		assert_memory_equal(r[0].sorm.kappa, r[t].sorm.kappa, (N - 1) * sizeof(double));
		assert_memory_equal(&r[0].sorm.pf_tvedt, &r[t].sorm.pf_tvedt, sizeof(double));
		assert_memory_equal(&r[0].pf, &r[t].pf, sizeof(double));
		assert_int_equal(r[0].evaluations, r[t].evaluations);
	}
	for (int t = 0; t < 3; t++)
		prsm_rare_result_free(&r[t]);
}

/* A limit state that fails (an error code, or NaN) at some evaluation: an error naming the
 * evaluation, never a crash; the index is the same for any thread count. */
typedef struct {
	double limit; /* fails when x0 > limit */
	int nan;
} failing_ctx;

static int failing_g(double *value, const void *ctx, void *ws, const double *x)
{
	const failing_ctx *c = ctx;
	(void)ws;
	if (x[0] > c->limit) {
		if (c->nan) {
			*value = NAN;
			return 0;
		}
		return PRSM_EINVAL;
	}
	*value = 3.0 - x[0] - 0.5 * x[1];
	return 0;
}

static void test_form_failures(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	for (int i = 0; i < 2; i++)
		set_normal(&v[i], 0.0, 1.0);
	for (int nan = 0; nan < 2; nan++) {
		failing_ctx c = {2.0, nan};
		prsm_rare_problem p = problem(&c, failing_g, v, 2);
		size_t idx[2];
		for (int t = 0; t < 2; t++) {
			prsm_rare_options o = opts();
			o.threads = t + 1;
			prsm_rare_form_result f;
			prsm_error err = PRSM_ERROR_INIT;
			assert_int_equal(prsm_rare_form(&f, &p, &o, &err), PRSM_ENOCONVERGE);
			printf("failing FORM (%s): %s\n", nan ? "NaN" : "EINVAL", err.message);
			assert_non_null(strstr(err.message, "FORM evaluation"));
			assert_non_null(strstr(err.message, nan ? "non-finite" : "EINVAL"));
			char num[32];
			snprintf(num, sizeof num, "evaluation %zu", f.failed_index);
			assert_non_null(strstr(err.message, num));
			idx[t] = f.failed_index;
			prsm_rare_form_result_free(&f);
			prsm_rare_result r;
			assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), PRSM_ENOCONVERGE);
			prsm_rare_result_free(&r);
		}
		assert_int_equal(idx[0], idx[1]);
		/* the first evaluation beyond x0 = 2: the line search's trial at the HL-RF point (2.4, 1.2) */
		assert_int_equal(idx[0], 5);
	}
}

/* FORM that does not converge says why: a limit state without gradient, an iteration cap (IS
 * then samples around the last iterate and says so), a budget. */
static int flat_g(double *value, const void *ctx, void *ws, const double *x)
{
	(void)ctx;
	(void)ws;
	(void)x;
	*value = 1.0;
	return 0;
}

static void test_form_not_converged(void **state)
{
	(void)state;
	prsm_mc_variable v[3];
	for (int i = 0; i < 3; i++)
		set_normal(&v[i], 0.0, 1.0);
	prsm_rare_problem p = problem(NULL, flat_g, v, 3);
	prsm_rare_options o = opts();
	prsm_rare_form_result f;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	printf("flat: %s\n", f.reason);
	assert_false(f.converged);
	assert_int_equal(f.stop, PRSM_RARE_STOP_ZERO_GRADIENT);
	assert_int_equal(f.n_points, 0);
	assert_int_equal(f.evaluations, 7);
	prsm_rare_form_result_free(&f);

	enum { N = 10 };
	prsm_mc_variable w[N];
	for (size_t i = 0; i < N; i++)
		set_normal(&w[i], 0.0, 1.0);
	expsum_ctx e = {N, 30.0};
	p = problem(&e, expsum_g, w, N);
	o.form_max_iterations = 1;
	o.max_samples = 4096;
	prsm_rare_result r;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("FORM capped at 1 iteration: %s; IS %.4g cov %.3f (%s)\n", r.form.reason, r.pf, r.cov, r.note);
	assert_int_equal(r.form.stop, PRSM_RARE_STOP_MAX_ITERATIONS);
	assert_true(r.has_is);
	assert_int_equal(r.is.n_centres, 1);
	assert_non_null(strstr(r.note, "FORM did not converge"));
	prsm_rare_result_free(&r);
	/* SORM needs a converged FORM */
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_SORM, &p, &o, &err), 0);
	assert_int_equal(r.sorm.stop, PRSM_RARE_STOP_FORM);
	assert_true(r.pf == r.form.pf);
	prsm_rare_result_free(&r);
	/* a budget below one gradient */
	o.form_max_iterations = 100;
	o.max_evaluations = 15;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	assert_int_equal(f.stop, PRSM_RARE_STOP_MAX_EVALUATIONS);
	assert_true(f.evaluations <= 15);
	prsm_rare_form_result_free(&f);
}

/* The auto rule on first-block counts. */
static void test_auto_select(void **state)
{
	(void)state;
	prsm_rare_options o = opts();
	char why[160];
	/* 80 failures in 1024: plain MC reaches CoV 0.05 in ~4700 samples */
	assert_int_equal(prsm_rare_auto_select(80, 1024, 2, &o, why, sizeof why), PRSM_RARE_MC);
	printf("auto: %s\n", why);
	/* 1 failure in 1024: MC would need ~420000 > max_samples: IS in 2 variables */
	assert_int_equal(prsm_rare_auto_select(1, 1024, 2, &o, why, sizeof why), PRSM_RARE_IS);
	printf("auto: %s\n", why);
	assert_int_equal(prsm_rare_auto_select(0, 1024, 50, &o, why, sizeof why), PRSM_RARE_IS);
	/* many variables: subset simulation */
	assert_int_equal(prsm_rare_auto_select(0, 1024, 500, &o, why, sizeof why), PRSM_RARE_SUBSET);
	printf("auto: %s\n", why);
	/* a budget too small for IS and subset: FORM; smaller still: MC */
	o.max_evaluations = 1500;
	assert_int_equal(prsm_rare_auto_select(0, 1024, 60, &o, why, sizeof why), PRSM_RARE_FORM);
	printf("auto: %s\n", why);
	o.max_evaluations = 100;
	assert_int_equal(prsm_rare_auto_select(0, 1024, 60, &o, why, sizeof why), PRSM_RARE_MC);
	printf("auto: %s\n", why);
	assert_int_equal(prsm_rare_auto_select(0, 1024, 60, &o, NULL, 0), PRSM_RARE_MC);
}

/* prsm_rare_run with auto on both R - S cases: MC for the first, IS for the second, each
 * interval holding the exact value. */
static void test_run_auto(void **state)
{
	(void)state;
	const double mus[2] = {4.0, 7.0};
	const double exact_pf[2] = {0.07864960352514257, 2.034760087224798e-4};
	const prsm_rare_method expect[2] = {PRSM_RARE_MC, PRSM_RARE_IS};
	for (int k = 0; k < 2; k++) {
		prsm_mc_variable v[2];
		rs_vars(v, mus[k]);
		prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
		prsm_rare_options o = opts();
		o.seed = 11;
		prsm_rare_result r;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_run(&r, PRSM_RARE_AUTO, &p, &o, &err), 0);
		printf("auto mu_R=%g: %s (%s): pf %.6g [%.6g, %.6g] cov %.4f, %zu evaluations, exact %.6g\n", mus[k],
		       prsm_rare_method_name(r.method), r.note, r.pf, r.lower, r.upper, r.cov, r.evaluations, exact_pf[k]);
		assert_int_equal(r.method, expect[k]);
		assert_int_equal(r.requested, PRSM_RARE_AUTO);
		assert_true(r.converged);
		assert_true(r.cov <= o.target_cov);
		assert_true(r.lower <= exact_pf[k] && exact_pf[k] <= r.upper);
		assert_true(fabs(r.beta - gsl_cdf_ugaussian_Qinv(r.pf)) < 1e-12);
		prsm_rare_result_free(&r);
	}
}

/* The spec limit state over an engine model: y = S - R against upper 0 is R - S. */
static int diff_eval(double *y, unsigned *flags, const void *ctx, void *ws, const double *x)
{
	(void)ctx;
	(void)ws;
	*flags = 0;
	y[0] = x[1] - x[0];
	y[1] = 0.0;
	return 0;
}

/* A model workspace that counts its allocations (through the model's ctx) and its frees (a free
 * callback sees only the workspace: a file-scope counter). */
static atomic_int g_frees;

static int count_alloc(void **ws, const void *ctx)
{
	atomic_int *allocs = (atomic_int *)(uintptr_t)ctx;
	atomic_fetch_add(allocs, 1);
	*ws = malloc(16);
	return *ws ? 0 : PRSM_ENOMEM;
}

static void count_free(void *ws)
{
	atomic_fetch_add(&g_frees, 1);
	free(ws);
}

static void test_spec_limit_state(void **state)
{
	(void)state;
	atomic_int allocs;
	atomic_init(&allocs, 0);
	atomic_init(&g_frees, 0);
	prsm_mc_model m = {2, &allocs, count_alloc, count_free, diff_eval};
	prsm_rare_spec spec = {&m, 0, PRSM_RARE_SIDE_UPPER, -INFINITY, 0.0, 2.0};
	prsm_mc_variable v[2];
	rs_vars(v, 7.0);
	prsm_rare_problem p;
	memset(&p, 0, sizeof p);
	prsm_rare_spec_limit_state(&p.limit, &spec);
	p.vars = v;
	p.d = 2;
	prsm_rare_options o = opts();
	o.threads = 2;
	prsm_rare_form_result f;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	assert_true(fabs(f.beta - 5.0 / sqrt(2.0)) < 1e-6);
	assert_true(fabs(f.g0 - 2.5) < 1e-12); /* (0 - (2 - 7)) / 2 */
	prsm_rare_form_result_free(&f);
	/* both sides, lower far away: the same design point */
	spec.side = PRSM_RARE_SIDE_BOTH;
	spec.lower = -30.0;
	assert_int_equal(prsm_rare_form(&f, &p, &o, &err), 0);
	assert_true(fabs(f.beta - 5.0 / sqrt(2.0)) < 1e-6);
	prsm_rare_form_result_free(&f);
	/* one model workspace per thread and call, each freed */
	assert_int_equal(atomic_load(&allocs), 4);
	assert_int_equal(atomic_load(&g_frees), 4);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_options),
		cmocka_unit_test(test_form_r_minus_s),
		cmocka_unit_test(test_form_sum_of_normals),
		cmocka_unit_test(test_form_sorm_exponentials),
		cmocka_unit_test(test_sorm_paraboloid),
		cmocka_unit_test(test_form_correlated),
		cmocka_unit_test(test_form_marginals),
		cmocka_unit_test(test_form_series_starts),
		cmocka_unit_test(test_form_negative_beta),
		cmocka_unit_test(test_form_sorm_threads),
		cmocka_unit_test(test_form_failures),
		cmocka_unit_test(test_form_not_converged),
		cmocka_unit_test(test_auto_select),
		cmocka_unit_test(test_run_auto),
		cmocka_unit_test(test_spec_limit_state),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
