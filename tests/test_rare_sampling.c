/*
 * test_rare_sampling.c: the rare-event engine's sampling estimators (mc/rare.h): importance
 * sampling around the design point(s), subset simulation, plain MC in U; each against exact
 * values within its own reported interval or standard error, bit-identical on 1 and 2 threads,
 * cancellation and the time cap, failing limit states. FORM and SORM are in test_rare.c.
 */
#include "test_support.h"

#include <stdatomic.h>
#include <time.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>

#include "mc/dist.h"
#include "mc/engine.h"
#include "io/global.h"
#include "mc/rare.h"
#include "util/cancel.h"
#include "util/rng.h"

#define MAXD 128

static void set_normal(prsm_mc_variable *v, double mean, double sd)
{
	memset(v, 0, sizeof *v);
	v->dist.kind = PRSM_DIST_NORMAL;
	v->dist.p[0] = mean;
	v->dist.p[1] = sd;
}

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

static const double rs_exact[2] = {0.07864960352514257, 2.034760087224798e-4};
static const double rs_mu[2] = {4.0, 7.0};

/* ---- IS --------------------------------------------------------------------------------------- */

/* R - S: FORM then IS around the design point; the exact value inside the 95 % interval. */
static void test_is_r_minus_s(void **state)
{
	(void)state;
	for (int k = 0; k < 2; k++) {
		prsm_mc_variable v[2];
		rs_vars(v, rs_mu[k]);
		prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
		prsm_rare_options o = opts();
		prsm_rare_result r;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
		printf("IS R-S mu_R=%g: pf %.6g se %.3g cov %.4f (rel err %.3f) [%.6g, %.6g], %zu samples, %zu failures, %zu evaluations "
		       "(FORM %zu), exact %.6g\n",
		       rs_mu[k], r.is.pf, r.is.se, r.is.cov, r.is.cov_rel_error, r.is.lower, r.is.upper, r.is.samples, r.is.failures,
		       r.evaluations, r.form.evaluations, rs_exact[k]);
		assert_true(r.has_form && r.has_is);
		assert_true(r.is.converged);
		assert_int_equal(r.is.stop, PRSM_RARE_STOP_CONVERGED);
		assert_true(r.is.cov <= o.target_cov);
		assert_true(r.is.lower <= rs_exact[k] && rs_exact[k] <= r.is.upper);
		assert_int_equal(r.is.n_centres, 1);
		assert_int_equal(r.evaluations, r.form.evaluations + r.is.evaluations);
		assert_true(r.is.samples <= r.is.evaluations);
		/* rounds sized from the projection waste little */
		assert_true(r.is.evaluations <= r.is.samples + 2 * o.block_size);
		prsm_rare_result_free(&r);
	}
}

/* Plain MC in U (no centre) on the first case, and IS with explicit centres: at the origin it is
 * plain MC with other streams. */
static void test_mc_r_minus_s(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	rs_vars(v, 4.0);
	prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
	prsm_rare_options o = opts();
	o.seed = 5;
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_MC, &p, &o, &err), 0);
	printf("MC R-S mu_R=4: pf %.6g cov %.4f [%.6g, %.6g] %zu samples\n", r.pf, r.cov, r.lower, r.upper, r.is.samples);
	assert_true(r.converged);
	assert_true(r.lower <= rs_exact[0] && rs_exact[0] <= r.upper);
	/* binomial standard error */
	double pf = r.pf, n = (double)r.is.samples;
	assert_true(fabs(r.is.se - sqrt(pf * (1 - pf) / (n - 1))) < 1e-12);
	assert_int_equal(r.is.samples % o.block_size, 0);
	prsm_rare_result_free(&r);

	double c0[2] = {0.0, 0.0};
	prsm_rare_is_result is;
	assert_int_equal(prsm_rare_is(&is, &p, c0, NULL, 1, &o, &err), 0);
	assert_true(is.lower <= rs_exact[0] && rs_exact[0] <= is.upper);
	/* a centre with weight 0 alone is refused */
	double w0 = 0.0;
	assert_int_equal(prsm_rare_is(&is, &p, c0, &w0, 1, &o, &err), PRSM_EINVAL);
}

/* A sum of 50 normals: IS in 50 dimensions around FORM's design point. */
static void test_is_sum_of_normals(void **state)
{
	(void)state;
	enum { N = 50 };
	prsm_mc_variable v[N];
	linear_ctx l;
	memset(&l, 0, sizeof l);
	l.n = N;
	double mean = 0.0, var = 0.0;
	for (size_t i = 0; i < N; i++) {
		double mu = 0.1 * (double)(i % 5), sd = 0.2 + 0.05 * (double)(i % 3);
		set_normal(&v[i], mu, sd);
		l.a[i] = -1.0;
		mean += mu;
		var += sd * sd;
	}
	double beta = 4.2;
	l.c = mean + beta * sqrt(var);
	double exact = gsl_cdf_ugaussian_Q(beta);
	prsm_rare_problem p = problem(&l, linear_g, v, N);
	prsm_rare_options o = opts();
	o.threads = 2;
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("IS %d normals: pf %.5g [%.5g, %.5g] cov %.4f (rel err %.3f), %zu evaluations; exact %.5g\n", N, r.pf,
	       r.lower, r.upper, r.cov, r.is.cov_rel_error, r.evaluations, exact);
	assert_true(r.converged);
	assert_true(r.lower <= exact && exact <= r.upper);
	prsm_rare_result_free(&r);
}

/* Exponentials from normals (inside the limit state): P = Q_gamma(t; n, 1). */
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

static void test_exponentials(void **state)
{
	(void)state;
	enum { N = 10 };
	prsm_mc_variable v[N];
	for (size_t i = 0; i < N; i++)
		set_normal(&v[i], 0.0, 1.0);
	expsum_ctx e = {N, 30.0};
	double exact = gsl_cdf_gamma_Q(e.t, (double)N, 1.0);
	prsm_rare_problem p = problem(&e, expsum_g, v, N);
	prsm_rare_options o = opts();
	o.threads = 2;
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	o.max_samples = 30000;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("IS exponentials: pf %.5g se %.3g [%.5g, %.5g] cov %.4f (rel err %.3f), %zu evaluations, stop %s; exact %.5g (FORM %.5g)\n",
	       r.pf, r.is.se, r.lower, r.upper, r.cov, r.is.cov_rel_error, r.evaluations, prsm_rare_stop_name(r.stop), exact, r.form.pf);
	/* the failure domain is the outside of a convex set: its probability lies far from the design
	 * point and IS around it is slow (CoV ~0.1 at 30000 samples), but unbiased: within 3 standard
	 * errors */
	assert_true(r.stop == PRSM_RARE_STOP_CONVERGED || r.stop == PRSM_RARE_STOP_MAX_SAMPLES);
	assert_true(fabs(r.pf - exact) <= 3.0 * r.is.se);
	prsm_rare_result_free(&r);

	/* subset simulation: over 40 seeds at N = 1000 the mean is 1.06 +- 0.07 of the exact value and
	 * the observed CoV 0.41 against a reported 0.34 (Au & Beck's delta ignores the correlation
	 * between levels); the estimate is skewed (a product of five factors), so it is checked in
	 * logarithms: |ln(P / exact)| <= 3 delta */
	prsm_rare_subset_result s;
	o.seed = 3;
	o.subset_samples = 2000;
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	printf("subset exponentials: pf %.5g cov %.4f [%.5g, %.5g], %d levels, %zu evaluations; exact %.5g\n", s.pf, s.cov,
	       s.lower, s.upper, s.levels, s.evaluations, exact);
	assert_true(s.converged);
	assert_true(fabs(log(s.pf / exact)) <= 3.0 * s.cov);
}

/* Three exponentials above 20 (P = 221 e^-20 = 4.56e-7): the failure domain wraps around the
 * origin, IS around the one design point sees a few heavy weights, and with the CoV alone as
 * the stop rule it stopped at CoV 0.064 some 20 % low with the exact value outside its
 * interval. The CoV's own error (the fourth moment) keeps it from claiming convergence, and
 * prsm_rare_run with the fallback (auto's) hands the rest of the budget to subset simulation,
 * whose interval holds the exact value. */
static void test_is_heavy_weights(void **state)
{
	(void)state;
	enum { N = 3 };
	prsm_mc_variable v[N];
	for (size_t i = 0; i < N; i++)
		set_normal(&v[i], 0.0, 1.0);
	expsum_ctx e = {N, 20.0};
	double exact = gsl_cdf_gamma_Q(e.t, (double)N, 1.0);
	prsm_rare_problem p = problem(&e, expsum_g, v, N);
	prsm_rare_options o = opts();
	o.target_cov = 0.1;
	o.max_evaluations = 20000;
	o.max_samples = 20000;
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("IS 3 exponentials: pf %.5g [%.5g, %.5g] cov %.4f (rel err %.3f), converged %d, stop %s; exact %.5g\n",
	       r.pf, r.lower, r.upper, r.cov, r.is.cov_rel_error, r.converged, prsm_rare_stop_name(r.stop), exact);
	assert_true(r.is.cov_rel_error > o.is_max_cov_error);
	assert_false(r.converged);
	prsm_rare_result_free(&r);

	o.is_fallback_subset = 1;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("IS then subset: %s pf %.5g [%.5g, %.5g], %zu evaluations; %s\n", prsm_rare_method_name(r.method), r.pf,
	       r.lower, r.upper, r.evaluations, r.note);
	assert_int_equal(r.method, PRSM_RARE_SUBSET);
	assert_true(r.has_is && r.has_subset);
	assert_true(r.evaluations <= o.max_evaluations);
	assert_true(r.lower <= exact && exact <= r.upper);
	prsm_rare_result_free(&r);

	/* a FORM that does not converge (here: one iteration allowed) hands the budget to subset
	 * simulation instead of sampling around its last iterate */
	o.form_max_iterations = 1;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("FORM stopped, then subset: %s pf %.5g [%.5g, %.5g], %zu evaluations; %s\n", prsm_rare_method_name(r.method),
	       r.pf, r.lower, r.upper, r.evaluations, r.note);
	assert_false(r.form.converged);
	assert_false(r.has_is);
	assert_int_equal(r.method, PRSM_RARE_SUBSET);
	assert_non_null(strstr(r.note, "FORM did not converge"));
	assert_true(r.form.evaluations <= o.max_evaluations / 4 + 1);
	assert_true(r.evaluations <= o.max_evaluations);
	assert_true(r.lower <= exact && exact <= r.upper);
	prsm_rare_result_free(&r);
}

/* ---- subset ----------------------------------------------------------------------------------- */

static void test_subset_r_minus_s(void **state)
{
	(void)state;
	for (int k = 0; k < 2; k++) {
		prsm_mc_variable v[2];
		rs_vars(v, rs_mu[k]);
		prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
		prsm_rare_options o = opts();
		prsm_rare_subset_result s;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
		printf("subset R-S mu_R=%g: pf %.6g cov %.4f [%.6g, %.6g], %d levels, %zu evaluations, exact %.6g\n", rs_mu[k],
		       s.pf, s.cov, s.lower, s.upper, s.levels, s.evaluations, rs_exact[k]);
		for (int j = 0; j < s.levels; j++)
			printf("  level %d: b %.4f p %.4f gamma %.3f delta %.4f acceptance %.3f\n", j, s.threshold[j],
			       s.p_cond[j], s.gamma[j], s.delta[j], s.acceptance[j]);
		assert_true(s.converged);
		assert_int_equal(s.stop, PRSM_RARE_STOP_CONVERGED);
		assert_true(s.lower <= rs_exact[k] && rs_exact[k] <= s.upper);
		assert_int_equal(s.samples_per_level, 1000);
		assert_int_equal(s.chains, 100);
		assert_true(s.threshold[s.levels - 1] == 0.0);
		/* cost: N at level 0, at most N - N_c per further level */
		assert_true(s.evaluations <= 1000 + (size_t)(s.levels - 1) * 900);
		/* intermediate levels: p0, or a little more where rejected moves repeat the threshold's g */
		for (int j = 0; j + 1 < s.levels; j++)
			assert_true(s.p_cond[j] >= 0.1 && s.p_cond[j] <= 0.12);
		assert_true(fabs(s.p_cond[0] - 0.1) < 1e-12);
	}
	/* k = 0: level 0 alone has ~79 failures of 1000 < N_c = 100, so one more level */

	/* two levels allowed for four needed: no estimate, the bound P(g <= b_1) = p0^2 */
	prsm_mc_variable v[2];
	rs_vars(v, 7.0);
	prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
	prsm_rare_options o = opts();
	o.subset_max_levels = 2;
	prsm_rare_subset_result s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	assert_int_equal(s.stop, PRSM_RARE_STOP_MAX_LEVELS);
	assert_false(s.converged);
	assert_true(isnan(s.pf));
	assert_int_equal(s.levels, 2);
	assert_true(s.bound >= 0.01 && s.bound <= 0.0121);
}

/* Over ten seeds the reported CoV is about the observed scatter. */
static void test_subset_cov_scatter(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	rs_vars(v, 7.0);
	prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
	enum { SEEDS = 12 };
	double sum = 0.0, sum2 = 0.0, cov = 0.0;
	size_t inside = 0;
	for (int k = 0; k < SEEDS; k++) {
		prsm_rare_options o = opts();
		o.seed = 100 + (uint64_t)k;
		prsm_rare_subset_result s;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
		assert_true(s.converged);
		sum += s.pf;
		sum2 += s.pf * s.pf;
		cov += s.cov;
		inside += s.lower <= rs_exact[1] && rs_exact[1] <= s.upper;
	}
	double mean = sum / SEEDS, sd = sqrt((sum2 - SEEDS * mean * mean) / (SEEDS - 1));
	double observed = sd / mean, reported = cov / SEEDS;
	printf("subset over %d seeds: mean %.5g (exact %.5g), observed CoV %.4f, mean reported CoV %.4f, %zu/%d intervals hold it\n",
	       SEEDS, mean, rs_exact[1], observed, reported, inside, SEEDS);
	/* the scatter of 12 estimates is itself uncertain by ~20 %: a factor of 2 either way */
	assert_true(observed / reported > 0.5 && observed / reported < 2.0);
	assert_true(fabs(mean - rs_exact[1]) < 3.0 * sd / sqrt((double)SEEDS));
	assert_true(inside >= SEEDS - 3);
}

/* A sum of 100 normals by subset simulation (modified Metropolis in 100 dimensions), uniform
 * proposals. */
static void test_subset_high_dim(void **state)
{
	(void)state;
	enum { N = 100 };
	prsm_mc_variable v[N];
	linear_ctx l;
	memset(&l, 0, sizeof l);
	l.n = N;
	for (size_t i = 0; i < N; i++) {
		set_normal(&v[i], 1.0, 1.0);
		l.a[i] = -1.0;
	}
	double beta = 3.5;
	l.c = N + beta * sqrt((double)N);
	double exact = gsl_cdf_ugaussian_Q(beta);
	prsm_rare_problem p = problem(&l, linear_g, v, N);
	prsm_rare_options o = opts();
	o.threads = 2;
	o.subset_proposal = PRSM_RARE_PROPOSAL_UNIFORM;
	prsm_rare_subset_result s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	printf("subset %d normals: pf %.5g cov %.4f [%.5g, %.5g], %d levels, acceptance %.3f, %zu evaluations; exact %.5g\n", N,
	       s.pf, s.cov, s.lower, s.upper, s.levels, s.acceptance[1], s.evaluations, exact);
	assert_true(s.converged);
	assert_true(fabs(s.pf - exact) <= 3.0 * s.cov * s.pf);
	assert_true(s.acceptance[1] > 0.1);
}

/* A series system min(g1, g2): beta1 = 3, beta2 = 3.2, rho = 0.6. Exact union:
 * Q(3) + int_{-inf}^{3} phi(x) Q((3.2 - 0.6 x) / 0.8) dx. IS needs both design points
 * (FORM's second start), subset simulation finds both by itself. */
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

static double series_integrand(double x, void *pp)
{
	const series_ctx *c = pp;
	return exp(-0.5 * x * x) / sqrt(2.0 * M_PI) * gsl_cdf_ugaussian_Q((c->b2 - 0.6 * x) / 0.8);
}

static double series_exact(const series_ctx *c)
{
	gsl_integration_workspace *w = gsl_integration_workspace_alloc(1000);
	gsl_function f = {series_integrand, (void *)(uintptr_t)c};
	double res, abserr;
	gsl_integration_qags(&f, -12.0, c->b1, 0.0, 1e-11, 1000, w, &res, &abserr);
	gsl_integration_workspace_free(w);
	return gsl_cdf_ugaussian_Q(c->b1) + res;
}

static void test_series_system(void **state)
{
	(void)state;
	prsm_mc_variable v[3];
	for (int i = 0; i < 3; i++)
		set_normal(&v[i], 0.0, 1.0);
	series_ctx c = {3.0, 3.2};
	double exact = series_exact(&c);
	prsm_rare_problem p = problem(&c, series_g, v, 3);
	prsm_rare_options o = opts();
	double starts[3] = {0.0, 4.0, 0.0};
	o.starts = starts;
	o.n_starts = 1;
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("series: exact %.6g (Q(3) %.6g + Q(3.2) %.6g); FORM %.6g (beta %.6f, %zu points); IS %.6g [%.6g, %.6g] cov %.4f, "
	       "%zu evaluations\n",
	       exact, gsl_cdf_ugaussian_Q(3.0), gsl_cdf_ugaussian_Q(3.2), r.form.pf, r.form.beta, r.form.n_points, r.pf,
	       r.lower, r.upper, r.cov, r.evaluations);
	assert_true(fabs(r.form.beta - 3.0) < 1e-6);
	assert_int_equal(r.form.n_points, 2);
	assert_int_equal(r.is.n_centres, 2);
	assert_true(r.converged);
	assert_true(r.lower <= exact && exact <= r.upper);
	prsm_rare_result_free(&r);

	prsm_rare_subset_result s;
	o.seed = 2;
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	printf("series subset: %.6g cov %.4f [%.6g, %.6g], %d levels, %zu evaluations\n", s.pf, s.cov, s.lower, s.upper,
	       s.levels, s.evaluations);
	assert_true(s.converged);
	assert_true(s.lower <= exact && exact <= s.upper);
}

/* Correlated inputs through the copula: normals with normal-score correlation rho, g = c - x0 - x1
 * (the sum is normal with variance s0^2 + s1^2 + 2 rho s0 s1); IS and subset. */
static void test_correlated_sampling(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	set_normal(&v[0], 1.0, 0.5);
	set_normal(&v[1], 2.0, 0.8);
	prsm_mc_correlation corr = {0, 1, 0.6};
	double sd = sqrt(0.25 + 0.64 + 2 * 0.6 * 0.4);
	linear_ctx l = {2, {-1.0, -1.0}, 3.0 + 3.8 * sd};
	double exact = gsl_cdf_ugaussian_Q(3.8);
	prsm_rare_problem p = problem(&l, linear_g, v, 2);
	p.corr = &corr;
	p.n_corr = 1;
	prsm_rare_options o = opts();
	prsm_rare_result r;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	printf("correlated: FORM beta %.8f, IS %.5g [%.5g, %.5g]; exact %.5g\n", r.form.beta, r.pf, r.lower, r.upper, exact);
	assert_true(fabs(r.form.beta - 3.8) < 1e-6);
	assert_true(r.lower <= exact && exact <= r.upper);
	prsm_rare_result_free(&r);
	prsm_rare_subset_result s;
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	printf("correlated subset: %.5g [%.5g, %.5g]\n", s.pf, s.lower, s.upper);
	assert_true(s.lower <= exact && exact <= s.upper);
}

/* ---- determinism ------------------------------------------------------------------------------ */

static void test_threads_identical(void **state)
{
	(void)state;
	enum { N = 10 };
	prsm_mc_variable v[N];
	for (size_t i = 0; i < N; i++)
		set_normal(&v[i], 0.0, 1.0);
	expsum_ctx e = {N, 28.0};
	prsm_rare_problem p = problem(&e, expsum_g, v, N);
	prsm_rare_result r[2];
	prsm_rare_subset_result s[2];
	prsm_rare_is_result m[2];
	for (int t = 0; t < 2; t++) {
		prsm_rare_options o = opts();
		o.threads = t + 1;
		o.seed = 77;
		o.target_cov = 0.02; /* several rounds */
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_run(&r[t], PRSM_RARE_IS, &p, &o, &err), 0);
		assert_int_equal(prsm_rare_subset(&s[t], &p, &o, &err), 0);
		o.max_samples = 20000;
		assert_int_equal(prsm_rare_is(&m[t], &p, NULL, NULL, 0, &o, &err), 0);
		r[t].is.elapsed_s = r[t].form.elapsed_s = r[t].elapsed_s = 0.0;
		s[t].elapsed_s = 0.0;
		m[t].elapsed_s = 0.0;
	}
	printf("threads: IS pf %.10g (%zu samples, %zu evaluations), subset pf %.10g (%zu evaluations), MC %zu failures\n",
	       r[0].pf, r[0].is.samples, r[0].evaluations, s[0].pf, s[0].evaluations, m[0].failures);
	assert_memory_equal(&r[0].is, &r[1].is, sizeof r[0].is);
	assert_memory_equal(r[0].form.u_star, r[1].form.u_star, N * sizeof(double));
	assert_memory_equal(&r[0].form.beta, &r[1].form.beta, sizeof(double));
	assert_int_equal(r[0].form.evaluations, r[1].form.evaluations);
	assert_memory_equal(&r[0].pf, &r[1].pf, sizeof(double));
	assert_memory_equal(&s[0], &s[1], sizeof s[0]);
	assert_memory_equal(&m[0], &m[1], sizeof m[0]);
	assert_true(r[0].is.samples + 8 * 256 >= r[0].is.evaluations);
	for (int t = 0; t < 2; t++)
		prsm_rare_result_free(&r[t]);
}

/* The progress callback: called from the calling thread, the last call with every evaluation. */
typedef struct {
	int calls;
	size_t last_done, planned;
	double last_cov, goal;
} progress_log;

static void on_progress(void *ctx, const prsm_progress *pr)
{
	progress_log *l = ctx;
	l->calls++;
	l->last_done = pr->done;
	l->planned = pr->planned;
	l->last_cov = pr->interval_width;
	l->goal = pr->interval_goal;
}

static void test_progress(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	rs_vars(v, 4.0);
	prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
	prsm_rare_options o = opts();
	progress_log l;
	memset(&l, 0, sizeof l);
	o.progress = on_progress;
	o.progress_ctx = &l;
	o.threads = 2;
	prsm_rare_is_result is;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_is(&is, &p, NULL, NULL, 0, &o, &err), 0);
	assert_true(l.calls >= 1);
	assert_int_equal(l.last_done, is.evaluations);
	assert_int_equal(l.planned, o.max_evaluations);
	assert_memory_equal(&l.last_cov, &is.cov, sizeof is.cov);
	assert_true(l.goal == o.target_cov);
	prsm_rare_subset_result s;
	memset(&l, 0, sizeof l);
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	assert_true(l.calls >= 1);
	assert_int_equal(l.last_done, s.evaluations);
}

/* Another seed or stream offset gives other numbers. */
static void test_seed_matters(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	rs_vars(v, 7.0);
	prsm_rare_problem p = problem(&rs_ctx, linear_g, v, 2);
	prsm_rare_options o = opts();
	prsm_rare_subset_result a, b, c;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_subset(&a, &p, &o, &err), 0);
	o.seed = 2;
	assert_int_equal(prsm_rare_subset(&b, &p, &o, &err), 0);
	o.seed = 1;
	o.stream_offset = 1000;
	assert_int_equal(prsm_rare_subset(&c, &p, &o, &err), 0);
	assert_true(a.pf != b.pf && a.pf != c.pf);
}

/* ---- cancel, time cap, failures --------------------------------------------------------------- */

typedef struct {
	prsm_cancel_flag *flag;
	atomic_size_t *count;
	size_t after;     /* raise the flag after this many evaluations */
	long sleep_ns;    /* per evaluation */
} slow_ctx;

static int slow_g(double *value, const void *ctx, void *ws, const double *x)
{
	const slow_ctx *c = ctx;
	(void)ws;
	size_t n = atomic_fetch_add(c->count, 1) + 1;
	if (c->flag && n >= c->after)
		prsm_cancel_set(c->flag, 1);
	if (c->sleep_ns > 0) {
		struct timespec ts = {0, c->sleep_ns};
		nanosleep(&ts, NULL);
	}
	*value = 4.0 - x[0] + 0.1 * x[1];
	return 0;
}

static void test_cancel_and_time_cap(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	for (int i = 0; i < 2; i++)
		set_normal(&v[i], 0.0, 1.0);
	prsm_cancel_flag flag;
	atomic_init(&flag, 0);
	atomic_size_t count;
	atomic_init(&count, 0);
	slow_ctx c = {&flag, &count, 1500, 0};
	prsm_rare_problem p = problem(&c, slow_g, v, 2);
	prsm_rare_options o = opts();
	o.cancel = &flag;
	o.threads = 2;
	prsm_rare_subset_result s;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	printf("cancelled subset: stop %s after %zu evaluations, %d levels\n", prsm_rare_stop_name(s.stop), s.evaluations,
	       s.levels);
	assert_int_equal(s.stop, PRSM_RARE_STOP_CANCELLED);
	assert_false(s.converged);
	assert_true(isnan(s.pf));
	assert_true(s.evaluations < 3000);

	/* IS and FORM see a raised flag at once */
	prsm_rare_result r;
	assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), 0);
	assert_int_equal(r.stop, PRSM_RARE_STOP_CANCELLED);
	assert_false(r.converged);
	assert_int_equal(r.evaluations, 0);
	prsm_rare_result_free(&r);
	prsm_rare_is_result is;
	assert_int_equal(prsm_rare_is(&is, &p, NULL, NULL, 0, &o, &err), 0);
	assert_int_equal(is.stop, PRSM_RARE_STOP_CANCELLED);

	/* the time cap: 0.05 s of a run that would take minutes */
	prsm_cancel_set(&flag, 0);
	c.flag = NULL;
	c.sleep_ns = 200000;
	o.time_cap_s = 0.05;
	o.max_samples = 1000000;
	o.max_evaluations = 1000000;
	o.target_cov = 0.001;
	assert_int_equal(prsm_rare_is(&is, &p, NULL, NULL, 0, &o, &err), 0);
	printf("time cap: MC stop %s after %zu evaluations, %zu samples kept\n", prsm_rare_stop_name(is.stop), is.evaluations,
	       is.samples);
	assert_int_equal(is.stop, PRSM_RARE_STOP_TIME_CAP);
	assert_false(is.converged);
	assert_true(is.evaluations < 1000000);
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	assert_int_equal(s.stop, PRSM_RARE_STOP_TIME_CAP);

	/* the evaluation budget */
	c.sleep_ns = 0;
	o.time_cap_s = 0.0;
	o.max_evaluations = 2500;
	assert_int_equal(prsm_rare_is(&is, &p, NULL, NULL, 0, &o, &err), 0);
	assert_int_equal(is.stop, PRSM_RARE_STOP_MAX_EVALUATIONS);
	assert_true(is.evaluations <= 2500);
	assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), 0);
	printf("budget 2500: subset stop %s, %zu evaluations, bound %.3g\n", prsm_rare_stop_name(s.stop), s.evaluations,
	       s.bound);
	assert_int_equal(s.stop, PRSM_RARE_STOP_MAX_EVALUATIONS);
	assert_true(s.evaluations <= 2500);
	assert_true(s.bound > 0.0 && s.bound <= 0.01 + 1e-15);
}

/* Fails (an error code, or NaN) where x0 > limit. */
typedef struct {
	double limit;
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
	*value = 5.0 - x[0] - 0.5 * x[1];
	return 0;
}

/* The first MC sample with u0 > limit, from the documented streams: block b is stream
 * (seed, 2^48 + b), a sample d normals by inversion. */
static size_t first_beyond(uint64_t seed, double limit, size_t block, size_t d)
{
	for (size_t b = 0;; b++) {
		gsl_rng *r = prsm_rng_alloc(seed, (UINT64_C(1) << 48) + b);
		for (size_t i = 0; i < block; i++) {
			double u0 = 0.0;
			for (size_t j = 0; j < d; j++) {
				double z = prsm_normal_quantile(prsm_rng_uniform_pos(r));
				if (j == 0)
					u0 = z;
			}
			if (u0 > limit) {
				gsl_rng_free(r);
				return b * block + i;
			}
		}
		gsl_rng_free(r);
	}
}

static void test_failing_limit_state(void **state)
{
	(void)state;
	prsm_mc_variable v[2];
	for (int i = 0; i < 2; i++)
		set_normal(&v[i], 0.0, 1.0);
	for (int nan = 0; nan < 2; nan++) {
		failing_ctx c = {3.0, nan};
		prsm_rare_problem p = problem(&c, failing_g, v, 2);
		size_t expect = first_beyond(1, 3.0, 256, 2);
		for (int t = 0; t < 2; t++) {
			prsm_rare_options o = opts();
			o.threads = t + 1;
			prsm_rare_is_result is;
			prsm_error err = PRSM_ERROR_INIT;
			assert_int_equal(prsm_rare_is(&is, &p, NULL, NULL, 0, &o, &err), PRSM_ENOCONVERGE);
			printf("failing MC (%s, %d threads): %s\n", nan ? "NaN" : "EINVAL", t + 1, err.message);
			assert_int_equal(is.failed_index, expect);
			char num[48];
			snprintf(num, sizeof num, "MC sample %zu", expect);
			assert_non_null(strstr(err.message, num));
			assert_non_null(strstr(err.message, nan ? "non-finite" : "EINVAL"));
			/* subset simulation reaches x0 > 3 in its chains */
			prsm_rare_subset_result s;
			assert_int_equal(prsm_rare_subset(&s, &p, &o, &err), PRSM_ENOCONVERGE);
			printf("failing subset (%d threads): %s (index %zu)\n", t + 1, err.message, s.failed_index);
			assert_non_null(strstr(err.message, "subset level"));
			assert_true(s.failed_index != SIZE_MAX);
			/* IS around the design point (5, 0) x ...: FORM's line search fails first */
			prsm_rare_result r;
			assert_int_equal(prsm_rare_run(&r, PRSM_RARE_IS, &p, &o, &err), PRSM_ENOCONVERGE);
			assert_non_null(strstr(err.message, "FORM evaluation"));
			prsm_rare_result_free(&r);
		}
	}
	/* failing beyond x0 = 4: level 0 (P(u0 > 4) = 3e-5) passes, a chain of a later level fails;
	 * the same level, chain and sample for 1 and 2 threads */
	size_t sidx[2];
	for (int t = 0; t < 2; t++) {
		failing_ctx c4 = {4.0, 0};
		prsm_rare_problem p4 = problem(&c4, failing_g, v, 2);
		prsm_rare_options o4 = opts();
		o4.threads = t + 1;
		prsm_rare_subset_result s;
		prsm_error e4 = PRSM_ERROR_INIT;
		assert_int_equal(prsm_rare_subset(&s, &p4, &o4, &e4), PRSM_ENOCONVERGE);
		printf("failing subset beyond 4 (%d threads): %s (index %zu)\n", t + 1, e4.message, s.failed_index);
		assert_true(s.failed_index >= 1000);
		assert_non_null(strstr(e4.message, "chain"));
		sidx[t] = s.failed_index;
	}
	assert_int_equal(sidx[0], sidx[1]);

	/* IS around a given centre beyond the limit: the first sample fails (or one of the first) */
	failing_ctx c = {3.0, 0};
	prsm_rare_problem p = problem(&c, failing_g, v, 2);
	double centre[2] = {4.0, 2.0};
	prsm_rare_options o = opts();
	prsm_rare_is_result is;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_rare_is(&is, &p, centre, NULL, 1, &o, &err), PRSM_ENOCONVERGE);
	assert_non_null(strstr(err.message, "IS sample"));
	assert_true(is.failed_index < 10);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_is_r_minus_s),
		cmocka_unit_test(test_mc_r_minus_s),
		cmocka_unit_test(test_is_sum_of_normals),
		cmocka_unit_test(test_exponentials),
		cmocka_unit_test(test_is_heavy_weights),
		cmocka_unit_test(test_subset_r_minus_s),
		cmocka_unit_test(test_subset_cov_scatter),
		cmocka_unit_test(test_subset_high_dim),
		cmocka_unit_test(test_series_system),
		cmocka_unit_test(test_correlated_sampling),
		cmocka_unit_test(test_threads_identical),
		cmocka_unit_test(test_progress),
		cmocka_unit_test(test_seed_matters),
		cmocka_unit_test(test_cancel_and_time_cap),
		cmocka_unit_test(test_failing_limit_state),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
