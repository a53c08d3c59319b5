/*
 * test_calib.c: MODEL-DYNAMICS.md §8.5 items 3 and 4 (dyn/calib.h) against synthetic data with
 * known truth: the line model's analytic Jacobian against central differences; noise-free curves
 * recovered to rounding; noisy curves recovered within their standard errors, and the coverage
 * of the 95 % intervals over many seeds within a band from the binomial standard error; the
 * global grid finding k from a prior 0.02 off; the caveats the fit must trigger (two lines
 * closer than the resolution, correlated residuals with the inflation factor, a screw run-out
 * invisible in TE, two rollers' errors at one order); the physical model recovering run-outs of
 * case A from the statics engine's own TE; friction from an efficiency against the statics
 * engine's efficiency at a known mu; carrier drag from a cage ratio against the settled ratio at
 * a known drag. Inputs are high-entropy (2.385, not 1).
 */
#include "test_dyn_support.h"

#include "dyn/calib.h"
#include "dyn/measured.h"
#include "model/assembly.h"
#include "model/assembly_report.h"
#include "model/performance.h"

/* ---- an independent generator: splitmix64 and Box-Muller ---- */

typedef struct {
	uint64_t s;
	int have;
	double spare;
} rng;

static double uniform(rng *r)
{
	uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
	z ^= z >> 31;
	return ((double)(z >> 11) + 0.5) / 9007199254740992.0;
}

static double gauss(rng *r)
{
	if (r->have) {
		r->have = 0;
		return r->spare;
	}
	const double u = uniform(r), v = uniform(r);
	const double m = sqrt(-2.0 * log(u));
	r->spare = m * sin(2.0 * M_PI * v);
	r->have = 1;
	return m * cos(2.0 * M_PI * v);
}

/* ---- synthetic line-model curves ---- */

static const prsm_calib_kinematics case_a_kin = {5.0, 10, 85};

/* A curve of revs revolutions at per_rev points from the line model with parameters p (lines of
 * mask), plus white noise sigma (or AR(1) noise of lag-1 correlation phi). */
static void synth(prsm_meas_curve *c, double revs, int per_rev, const double *p, int mask, double sigma, double phi,
                  uint64_t seed)
{
	const size_t n = (size_t)(revs * per_rev) + 1;
	assert_int_equal(prsm_meas_curve_alloc(c, n, NULL), 0);
	double alpha[PRSM_CALIB_LINE_KINDS], beta[PRSM_CALIB_LINE_KINDS];
	int L = 0;
	for (int k = 0; k < PRSM_CALIB_LINE_KINDS; k++)
		if (mask & (1 << k))
			prsm_calib_order_coefficients(&alpha[L], &beta[L], k, &case_a_kin), L++;
	rng r = {seed * 7919u + 17u, 0, 0.0};
	double e = 0.0;
	for (size_t i = 0; i < n; i++) {
		const double th = 2.0 * M_PI * (double)i / per_rev;
		c->angle_rad[i] = th;
		c->travel_mm[i] = th * 10.0 / (2.0 * M_PI);
		const double w = gauss(&r);
		e = i == 0 ? w : phi * e + sqrt(1.0 - phi * phi) * w;
		c->te_um[i] = prsm_calib_line_value(p, L, alpha, beta, th, c->travel_mm[i], NULL) + sigma * e;
	}
	c->has_angle = c->has_travel = 1;
}

static int count_lines(int mask)
{
	int n = 0;
	for (int k = 0; k < PRSM_CALIB_LINE_KINDS; k++)
		n += (mask >> k) & 1;
	return n;
}

/* random true parameters for a mask: offset, slope, a/b per line, k */
static void truth(double *p, int mask, rng *r, double k)
{
	const int L = count_lines(mask);
	p[0] = 2.0 * uniform(r) - 1.0;
	p[1] = 30.0 * (uniform(r) - 0.5);
	for (int l = 0; l < L; l++) {
		const double A = 0.05 + 1.9 * uniform(r), ph = 2.0 * M_PI * uniform(r);
		p[2 + 2 * l] = A * cos(ph);
		p[3 + 2 * l] = A * sin(ph);
	}
	p[2 + 2 * L] = k;
}

static void test_line_jacobian(void **state)
{
	(void)state;
	rng r = {12345, 0, 0.0};
	const int mask = PRSM_CALIB_LINES_DEFAULT, L = count_lines(mask), P = 3 + 2 * L;
	double alpha[PRSM_CALIB_LINE_KINDS], beta[PRSM_CALIB_LINE_KINDS];
	for (int k = 0, l = 0; k < PRSM_CALIB_LINE_KINDS; k++)
		if (mask & (1 << k))
			prsm_calib_order_coefficients(&alpha[l], &beta[l], k, &case_a_kin), l++;
	for (int trial = 0; trial < 20; trial++) {
		double p[PRSM_CALIB_PARAMS_MAX], g[PRSM_CALIB_PARAMS_MAX];
		truth(p, mask, &r, 0.3 + 0.15 * uniform(&r));
		const double th = 80.0 * uniform(&r), s = th * 10.0 / (2.0 * M_PI);
		prsm_calib_line_value(p, L, alpha, beta, th, s, g);
		for (int j = 0; j < P; j++) {
			const double h = j == P - 1 ? 1e-7 : 1e-5;
			double q[PRSM_CALIB_PARAMS_MAX];
			memcpy(q, p, sizeof q);
			q[j] = p[j] + h;
			const double fp = prsm_calib_line_value(q, L, alpha, beta, th, s, NULL);
			q[j] = p[j] - h;
			const double fm = prsm_calib_line_value(q, L, alpha, beta, th, s, NULL);
			const double fd = (fp - fm) / (2.0 * h);
			assert_close(g[j], fd, 1e-6 * (1.0 + fabs(fd)));
		}
	}
}

static void test_line_noise_free(void **state)
{
	(void)state;
	rng r = {2024, 0, 0.0};
	const int mask = PRSM_CALIB_LINES_DEFAULT, L = count_lines(mask), P = 3 + 2 * L;
	double p[PRSM_CALIB_PARAMS_MAX];
	truth(p, mask, &r, 0.371377);
	prsm_meas_curve c;
	synth(&c, 15.0, 64, p, mask, 0.0, 0.0, 1);
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.carrier_ratio_prior = 0.373694; /* k* of case A: the truth is 0.0023 away */
	prsm_calib_line_result res;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, &err), 0);
	assert_int_equal(res.lines, L);
	assert_int_equal(res.fit.params, P);
	for (int j = 0; j < P; j++)
		assert_close(res.fit.estimate[j], p[j], 1e-8 * (1.0 + fabs(p[j])));
	assert_true(res.fit.residual_sd_um < 1e-9);
	/* amplitudes and phases are the a, b pairs' */
	for (int l = 0; l < L; l++) {
		assert_close(res.amplitude_um[l], hypot(p[2 + 2 * l], p[3 + 2 * l]), 1e-8);
		assert_close(cos(res.phase_rad[l]) * res.amplitude_um[l], p[2 + 2 * l], 1e-8);
	}
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
}

/* Noisy curves: within their standard errors, and the 95 % intervals cover the truth about 95 %
 * of the time over many seeds (band: 4.5 binomial standard errors). */
static void test_line_coverage(void **state)
{
	(void)state;
	const int mask = (1 << PRSM_CALIB_LINE_SCREW_REV) | (1 << PRSM_CALIB_LINE_SCREW) | (1 << PRSM_CALIB_LINE_ROLLER_SPIN) |
	                 (1 << PRSM_CALIB_LINE_ROLLER_PASS_NUT);
	const int L = count_lines(mask), P = 3 + 2 * L;
	const int seeds = 240;
	long inside = 0, total = 0, inside_k = 0;
	double s_ratio = 0.0;
	for (int seed = 0; seed < seeds; seed++) {
		rng r = {(uint64_t)seed * 1000003u + 5u, 0, 0.0};
		double p[PRSM_CALIB_PARAMS_MAX];
		const double k = 0.36 + 0.02 * uniform(&r);
		truth(p, mask, &r, k);
		const double sigma = 0.0731 + 0.1 * uniform(&r);
		prsm_meas_curve c;
		synth(&c, 9.0, 32, p, mask, sigma, 0.0, (uint64_t)seed + 100u);
		prsm_calib_options o;
		prsm_calib_options_init(&o);
		o.lines_mask = mask;
		o.carrier_ratio_prior = 0.37;
		o.grid_points = 401;
		prsm_calib_line_result res;
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, &err), 0);
		for (int j = 0; j < P; j++) {
			const double z = fabs(res.fit.estimate[j] - p[j]) / res.fit.standard_error[j];
			assert_true(z < 6.0); /* never wildly off */
			inside += z <= 1.959964;
			total++;
		}
		inside_k += fabs(res.carrier_ratio - k) <= 1.959964 * res.carrier_ratio_se;
		s_ratio += res.fit.residual_sd_um / sigma;
		prsm_calib_line_free(&res);
		prsm_meas_curve_free(&c);
	}
	const double cov = (double)inside / (double)total, se = sqrt(0.95 * 0.05 / (double)total);
	const double cov_k = (double)inside_k / seeds, se_k = sqrt(0.95 * 0.05 / seeds);
	print_message("line model: 95 %% coverage %.4f over %ld intervals (band +- %.4f); k alone %.4f over %d; mean s/sigma %.4f\n",
	              cov, total, 4.5 * se, cov_k, seeds, s_ratio / seeds);
	assert_true(fabs(cov - 0.95) < 4.5 * se);
	assert_true(fabs(cov_k - 0.95) < 4.5 * se_k);
	assert_true(fabs(s_ratio / seeds - 1.0) < 0.02);
}

/* The grid does the global part: a prior 0.0198 off still finds k (S(k) has side minima). */
static void test_line_global_grid(void **state)
{
	(void)state;
	rng r = {77, 0, 0.0};
	const int mask = PRSM_CALIB_LINES_DEFAULT;
	double p[PRSM_CALIB_PARAMS_MAX];
	truth(p, mask, &r, 0.3587);
	prsm_meas_curve c;
	synth(&c, 15.0, 64, p, mask, 0.0937, 0.0, 9);
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.carrier_ratio_prior = 0.3785;
	o.refine = PRSM_CALIB_REFINE_COBYLA;
	prsm_calib_line_result res;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, NULL), 0);
	assert_true(fabs(res.carrier_ratio - 0.3587) < 4.0 * res.carrier_ratio_se);
	assert_true(fabs(res.grid_best_k - 0.3587) <= (res.grid_to - res.grid_from) / (res.grid_points - 1));
	assert_int_equal(res.refine_used, PRSM_CALIB_REFINE_COBYLA);
	/* no caveat fires on a clean, long record */
	for (int i = 0; i < res.fit.caveats; i++)
		assert_false(res.fit.caveat[i].triggered);
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
}

static const prsm_calib_caveat *find_caveat(const prsm_calib_fit *f, int code)
{
	for (int i = 0; i < f->caveats; i++)
		if (f->caveat[i].code == code)
			return &f->caveat[i];
	return NULL;
}

/* §8.5: two lines closer than the resolution 1/N_rev cannot be separated. k = 0.4913: the screw
 * (1 - k) and carrier (k) lines are 0.0174 apart; over 5 revolutions the resolution is 0.2. */
static void test_caveat_resolution(void **state)
{
	(void)state;
	rng r = {31, 0, 0.0};
	const int mask = (1 << PRSM_CALIB_LINE_SCREW_REV) | (1 << PRSM_CALIB_LINE_SCREW) | (1 << PRSM_CALIB_LINE_CARRIER);
	double p[PRSM_CALIB_PARAMS_MAX];
	truth(p, mask, &r, 0.4913);
	prsm_meas_curve c;
	synth(&c, 5.0, 64, p, mask, 0.05, 0.0, 3);
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.lines_mask = mask;
	o.carrier_ratio_prior = 0.49;
	o.grid_half_width = 0.005;
	prsm_calib_line_result res;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, NULL), 0);
	const prsm_calib_caveat *cv = find_caveat(&res.fit, PRSM_CALIB_CAVEAT_RESOLUTION);
	assert_non_null(cv);
	assert_true(cv->triggered);
	assert_non_null(strstr(cv->message, "screw"));
	assert_non_null(strstr(cv->message, "carrier"));
	/* the two lines trade off: their coefficients are strongly correlated */
	const int P = res.fit.params;
	double worst = 0.0;
	for (int a = 4; a < 6; a++)
		for (int b = 6; b < 8; b++)
			worst = fmax(worst, fabs(res.fit.correlation[a * P + b]));
	assert_true(worst > 0.5);
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
	/* the same lines over 60 revolutions (resolution 0.0167 < 0.0174): resolved, no caveat */
	synth(&c, 60.0, 16, p, mask, 0.05, 0.0, 3);
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, NULL), 0);
	assert_false(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_RESOLUTION)->triggered);
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
}

/* §8.5: correlated residuals (AR(1), phi 0.6): r_1 reported, errors inflated by
 * sqrt((1 + r_1) / (1 - r_1)) */
static void test_caveat_correlated(void **state)
{
	(void)state;
	rng r = {4711, 0, 0.0};
	const int mask = PRSM_CALIB_LINES_DEFAULT;
	double p[PRSM_CALIB_PARAMS_MAX];
	truth(p, mask, &r, 0.3711);
	prsm_meas_curve c;
	synth(&c, 15.0, 64, p, mask, 0.0813, 0.6, 5);
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.carrier_ratio_prior = 0.37;
	prsm_calib_line_result res;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, NULL), 0);
	const double r1 = res.fit.lag1_autocorrelation;
	assert_true(r1 > 0.5 && r1 < 0.7);
	assert_close(prsm_meas_lag1(res.fit.residual_um, c.n), r1, 0.0);
	assert_close(res.fit.inflation, sqrt((1.0 + r1) / (1.0 - r1)), 1e-14);
	for (int j = 0; j < res.fit.params; j++)
		assert_close(res.fit.standard_error[j], res.fit.standard_error_white[j] * res.fit.inflation,
		             1e-12 * res.fit.standard_error[j]);
	assert_true(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_CORRELATED_RESIDUALS)->triggered);
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
}

/* §8.5: a slope and a low-order line trade off over a short stroke: the carrier line (k = 0.37)
 * makes 1.6 cycles in 4.3 revolutions */
static void test_caveat_slope(void **state)
{
	(void)state;
	rng r = {555, 0, 0.0};
	const int mask = (1 << PRSM_CALIB_LINE_CARRIER) | (1 << PRSM_CALIB_LINE_ROLLER_SPIN);
	double p[PRSM_CALIB_PARAMS_MAX];
	truth(p, mask, &r, 0.3697);
	prsm_meas_curve c;
	synth(&c, 4.3, 64, p, mask, 0.0517, 0.0, 11);
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.lines_mask = mask;
	o.carrier_ratio_prior = 0.37;
	prsm_calib_line_result res;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, NULL), 0);
	const prsm_calib_caveat *cv = find_caveat(&res.fit, PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER);
	assert_true(cv->triggered);
	assert_non_null(strstr(cv->message, "carrier"));
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
	/* 40 revolutions: 14.8 cycles, no trade-off */
	synth(&c, 40.0, 16, p, mask, 0.0517, 0.0, 11);
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, NULL), 0);
	assert_false(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER)->triggered);
	prsm_calib_line_free(&res);
	prsm_meas_curve_free(&c);
}

static void test_line_refused(void **state)
{
	(void)state;
	double p[PRSM_CALIB_PARAMS_MAX];
	rng r = {9, 0, 0.0};
	truth(p, 1, &r, 0.37);
	prsm_meas_curve c;
	synth(&c, 4.5, 8, p, 1, 0.1, 0.0, 1);
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.carrier_ratio_prior = 0.37;
	prsm_calib_line_result res;
	prsm_error err = PRSM_ERROR_INIT;
	/* the mesh line without z_2 */
	const prsm_calib_kinematics no_teeth = {5.0, 10, 0};
	o.lines_mask = 1 << PRSM_CALIB_LINE_MESH;
	assert_int_equal(prsm_calib_line(&res, &c, &no_teeth, &o, &err), PRSM_EINVAL);
	assert_string_equal(err.pointer, "/dynamics/calibrate/lines");
	assert_non_null(strstr(err.message, "teeth"));
	/* 8 points per revolution: Nyquist 4, only roller_pass_screw (6.3) asked */
	o.lines_mask = 1 << PRSM_CALIB_LINE_ROLLER_PASS_SCREW;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, &err), PRSM_EINVAL);
	assert_non_null(strstr(err.message, "Nyquist"));
	/* lines above Nyquist at the prior are dropped, the others fitted */
	o.lines_mask = PRSM_CALIB_LINES_DEFAULT;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, &err), 0);
	assert_int_equal(res.dropped, 2);
	assert_int_equal(res.dropped_kind[0], PRSM_CALIB_LINE_ROLLER_PASS_SCREW);
	assert_int_equal(res.dropped_kind[1], PRSM_CALIB_LINE_MESH);
	prsm_calib_line_free(&res);
	/* without z_2 the default set has no mesh line */
	assert_int_equal(prsm_calib_line(&res, &c, &no_teeth, &o, &err), 0);
	assert_int_equal(res.dropped, 2);
	assert_int_equal(res.dropped_kind[1], PRSM_CALIB_LINE_MESH);
	prsm_calib_line_free(&res);
	o.carrier_ratio_prior = 1.2;
	assert_int_equal(prsm_calib_line(&res, &c, &case_a_kin, &o, &err), PRSM_EINVAL);
	prsm_meas_curve_free(&c);
}

/* ---- the physical model on case A ---- */

typedef struct {
	prsm_design d;
	prsm_analysis a;
	prsm_assembly as;
} case_a_assembly;

static case_a_assembly *case_a_as(void)
{
	case_a_assembly *x = malloc(sizeof *x);
	assert_non_null(x);
	dyn_case_a(&x->d, &x->a, 0.05);
	assert_int_equal(prsm_assembly_init(&x->as, &x->d, &x->a, NULL), 0);
	return x;
}

static prsm_calib_field field(const char *name, int part, int roller, size_t offset, double scale, double limit,
                              int magnitude, size_t phase_offset, int phase)
{
	prsm_calib_field f;
	memset(&f, 0, sizeof f);
	snprintf(f.name, sizeof f.name, "%s", name);
	snprintf(f.unit, sizeof f.unit, "%s", phase ? "deg" : "um");
	f.part = part;
	f.roller = roller;
	f.offset = offset;
	f.scale = scale;
	f.limit = limit;
	f.magnitude = magnitude;
	f.phase_offset = phase_offset;
	f.phase = phase;
	return f;
}

#define BODY(m) offsetof(prsm_body_errors, m)
#define ROLLER(m) offsetof(prsm_roller_errors, m)

/* A curve of the statics TE of e (revs revolutions, per_rev points), plus offset, noise sigma. */
static void statics_curve(prsm_meas_curve *c, const prsm_assembly *as, const prsm_errors *e, double revs, int per_rev,
                          double offset, double sigma, uint64_t seed)
{
	const size_t n = (size_t)(revs * per_rev) + 1;
	assert_int_equal(prsm_meas_curve_alloc(c, n, NULL), 0);
	for (size_t i = 0; i < n; i++) {
		c->angle_rad[i] = 2.0 * M_PI * (double)i / per_rev;
		c->travel_mm[i] = c->angle_rad[i] * 10.0 / (2.0 * M_PI);
	}
	c->has_angle = c->has_travel = 1;
	prsm_assembly_gaps *g = malloc(sizeof *g);
	assert_int_equal(prsm_calib_statics_te(c->te_um, as, e, c->angle_rad, n, PRSM_MODE_LINEAR, 50.0, g), 0);
	free(g);
	rng r = {seed, 0, 0.0};
	for (size_t i = 0; i < n; i++)
		c->te_um[i] += offset + sigma * gauss(&r);
}

/* The statics TE here is the assembly report's, in the measurement's sign: its slope on travel
 * is the report's lead deviation. */
static void test_statics_te_sign(void **state)
{
	(void)state;
	case_a_assembly *x = case_a_as();
	prsm_errors e;
	prsm_errors_zero(&e, 10);
	e.screw.lead_deviation = 0.0123 / 300.0; /* 12.3 um per 300 mm */
	e.nut.runout_mm = 0.0041;
	prsm_meas_curve c;
	statics_curve(&c, &x->as, &e, 8.0, 32, 0.0, 0.0, 1);
	double a, b;
	prsm_meas_fit_line(&a, &b, &c);
	prsm_assembly_options o;
	prsm_assembly_options_default(&o);
	o.stroke_mm = 80.0;
	prsm_assembly_workspace ws;
	int n, m;
	prsm_assembly_record_length(&n, &m, &x->as, &o);
	ws.te_mm = calloc((size_t)n, sizeof(double));
	ws.spectrum_mm = calloc((size_t)m, sizeof(double));
	prsm_assembly_report rep;
	assert_int_equal(prsm_assembly_analyse(&rep, &x->as, &e, &o, &ws), 0);
	assert_close(300.0 * b, rep.lead_deviation * 300.0 * 1000.0, 0.02);
	assert_true(300.0 * b > 12.0);
	free(ws.te_mm);
	free(ws.spectrum_mm);
	prsm_meas_curve_free(&c);
	free(x);
}

static prsm_calib_field roller_lead(int j, int phase)
{
	char name[64];
	snprintf(name, sizeof name, phase ? "roller.%d.lead_periodic_phase_deg" : "roller.%d.lead_periodic_um", j);
	return phase ? field(name, PRSM_CALIB_PART_ROLLER, j, ROLLER(lead_periodic_phase_rad), 180.0 / M_PI, 3600.0, 0, 0, 1)
	             : field(name, PRSM_CALIB_PART_ROLLER, j, ROLLER(lead_periodic_mm), 1000.0, 500.0, 1,
	                     ROLLER(lead_periodic_phase_rad), 0);
}

/* Case A's statics TE of a roller's once-per-turn lead wobble (the roller_spin line) and a screw
 * lead error (the slope), plus an offset and noise: recovered within 4 standard errors. */
static void test_physical_recovers(void **state)
{
	(void)state;
	case_a_assembly *x = case_a_as();
	prsm_errors truth_e;
	prsm_errors_zero(&truth_e, 10);
	truth_e.roller[7].lead_periodic_mm = 0.00153;
	truth_e.roller[7].lead_periodic_phase_rad = 41.3 * DEG;
	truth_e.screw.lead_deviation = 0.0123 / 300.0;
	prsm_meas_curve c;
	const double sigma = 0.0437;
	statics_curve(&c, &x->as, &truth_e, 6.0, 24, 0.387, sigma, 99);
	prsm_calib_field f[3] = {
		roller_lead(7, 0), roller_lead(7, 1),
		field("screw.lead_deviation_um_per_300mm", PRSM_CALIB_PART_SCREW, 0, BODY(lead_deviation), 300000.0, 1000.0, 0,
		      0, 0)};
	f[2].lead = 1;
	prsm_errors base, est;
	prsm_errors_zero(&base, 10);
	base.roller[7].lead_periodic_phase_rad = 200.0 * DEG; /* a start on the far side */
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.model = PRSM_CALIB_MODEL_PHYSICAL;
	prsm_calib_physical_result res;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_calib_physical(&res, &est, &c, &x->as, &base, f, 3, &o, &err), 0);
	const double want[4] = {1.53, 41.3, 12.3, 0.387};
	assert_int_equal(res.fit.params, 4); /* 3 fields and the offset: the lead error is the slope */
	for (int j = 0; j < 4; j++) {
		print_message("  %-36s %10.5f +- %.5f (truth %.5f)\n", res.fit.name[j], res.fit.estimate[j],
		              res.fit.standard_error[j], want[j]);
		assert_true(fabs(res.fit.estimate[j] - want[j]) < 4.0 * res.fit.standard_error[j]);
		assert_true(res.fit.standard_error[j] < 0.1 * fabs(want[j]) + 0.01);
	}
	assert_close(res.fit.residual_sd_um, sigma, 0.2 * sigma);
	assert_close(prsm_calib_field_get(&est, &f[0]), res.fit.estimate[0], 1e-9);
	assert_true(res.first_order_um[0] > 0.05);
	assert_false(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_SCREW_RUNOUT)->triggered);
	assert_false(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_ROLLER_SUM)->triggered);
	prsm_calib_physical_free(&res);
	prsm_meas_curve_free(&c);
	free(x);
}

/* The physical model's 95 % intervals over many seeds (a roller's lead wobble with its phase and
 * the screw's lead error, offset; band: 4.5 binomial standard errors) */
static void test_physical_coverage(void **state)
{
	(void)state;
	case_a_assembly *x = case_a_as();
	prsm_calib_field f[3] = {
		roller_lead(4, 0), roller_lead(4, 1),
		field("screw.lead_deviation_um_per_300mm", PRSM_CALIB_PART_SCREW, 0, BODY(lead_deviation), 300000.0, 1000.0, 0,
		      0, 0)};
	f[2].lead = 1;
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.model = PRSM_CALIB_MODEL_PHYSICAL;
	const int seeds = 60;
	long inside = 0, total = 0;
	for (int seed = 0; seed < seeds; seed++) {
		rng r = {(uint64_t)seed * 7777u + 3u, 0, 0.0};
		prsm_errors t;
		prsm_errors_zero(&t, 10);
		const double A = 0.8 + 1.5 * uniform(&r), ph = 360.0 * uniform(&r), lead = 20.0 * (uniform(&r) - 0.5);
		const double off = uniform(&r) - 0.5, sigma = 0.02 + 0.05 * uniform(&r);
		t.roller[4].lead_periodic_mm = A / 1000.0;
		t.roller[4].lead_periodic_phase_rad = ph * DEG;
		t.screw.lead_deviation = lead / 300000.0;
		prsm_meas_curve c;
		statics_curve(&c, &x->as, &t, 5.0, 16, off, sigma, (uint64_t)seed + 1000u);
		prsm_errors base;
		prsm_errors_zero(&base, 10);
		prsm_calib_physical_result res;
		assert_int_equal(prsm_calib_physical(&res, NULL, &c, &x->as, &base, f, 3, &o, NULL), 0);
		const double want[4] = {A, ph, lead, off};
		for (int j = 0; j < 4; j++) {
			double d = res.fit.estimate[j] - want[j];
			if (j == 1)
				d = remainder(d, 360.0);
			inside += fabs(d) <= 1.959964 * res.fit.standard_error[j];
			total++;
		}
		prsm_calib_physical_free(&res);
		prsm_meas_curve_free(&c);
	}
	const double cov = (double)inside / (double)total, se = sqrt(0.95 * 0.05 / (double)total);
	print_message("physical model: 95 %% coverage %.4f over %ld intervals (band +- %.4f)\n", cov, total, 4.5 * se);
	assert_true(fabs(cov - 0.95) < 4.5 * se);
	free(x);
}

/* §8.5: a screw run-out's first harmonic cancels among evenly spaced, equally loaded rollers
 * (MODEL §4): on a record of a screw run-out alone its first-order effect on TE vanishes and the
 * caveat fires (beside another error the gaps are unequal and it no longer cancels: no caveat);
 * two rollers' errors at the roller_spin order combine into one vector sum. */
static void test_physical_caveats(void **state)
{
	(void)state;
	case_a_assembly *x = case_a_as();
	prsm_errors truth_e;
	prsm_errors_zero(&truth_e, 10);
	truth_e.screw.runout_mm = 0.0061;
	truth_e.screw.runout_phase_rad = 30.0 * DEG;
	prsm_meas_curve c;
	statics_curve(&c, &x->as, &truth_e, 6.0, 24, 0.0, 0.0117, 7);
	prsm_calib_field f[4] = {
		field("screw.runout_um", PRSM_CALIB_PART_SCREW, 0, BODY(runout_mm), 1000.0, 500.0, 1, BODY(runout_phase_rad), 0),
		field("screw.runout_phase_deg", PRSM_CALIB_PART_SCREW, 0, BODY(runout_phase_rad), 180.0 / M_PI, 3600.0, 0, 0, 1),
		roller_lead(2, 0), roller_lead(2, 1)};
	prsm_errors base;
	prsm_errors_zero(&base, 10);
	base.screw.runout_mm = 0.002;
	prsm_calib_options o;
	prsm_calib_options_init(&o);
	o.model = PRSM_CALIB_MODEL_PHYSICAL;
	prsm_calib_physical_result res;
	assert_int_equal(prsm_calib_physical(&res, NULL, &c, &x->as, &base, f, 2, &o, NULL), 0);
	print_message("  screw run-out alone: first-order TE %.3g um per um at zero, %.3g at the estimate %.3f um\n",
	              res.first_order_um[0], res.sensitivity_um[0], res.fit.estimate[0]);
	assert_true(res.first_order_um[0] < 1e-4);
	const prsm_calib_caveat *cv = find_caveat(&res.fit, PRSM_CALIB_CAVEAT_SCREW_RUNOUT);
	assert_true(cv->triggered);
	assert_non_null(strstr(cv->message, "screw.runout_um"));
	prsm_calib_physical_free(&res);
	/* beside a roller's lead wobble the rollers are unequally loaded: no longer invisible */
	truth_e.roller[2].lead_periodic_mm = 0.00217;
	truth_e.roller[2].lead_periodic_phase_rad = 77.0 * DEG;
	prsm_meas_curve_free(&c);
	statics_curve(&c, &x->as, &truth_e, 6.0, 24, 0.0, 0.0117, 8);
	assert_int_equal(prsm_calib_physical(&res, NULL, &c, &x->as, &base, f, 4, &o, NULL), 0);
	print_message("  beside a roller wobble: first-order TE per um: screw run-out %.3g, roller %.3g\n",
	              res.first_order_um[0], res.first_order_um[2]);
	assert_false(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_SCREW_RUNOUT)->triggered);
	assert_true(fabs(res.fit.estimate[2] - 2.17) < 4.0 * res.fit.standard_error[2]);
	prsm_calib_physical_free(&res);
	/* two rollers' lead wobbles: one vector sum at the roller_spin order */
	prsm_calib_field g[4] = {roller_lead(2, 0), roller_lead(2, 1), roller_lead(6, 0), roller_lead(6, 1)};
	assert_int_equal(prsm_calib_physical(&res, NULL, &c, &x->as, &base, g, 4, &o, NULL), 0);
	assert_true(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_ROLLER_SUM)->triggered);
	assert_false(find_caveat(&res.fit, PRSM_CALIB_CAVEAT_SCREW_RUNOUT)->triggered);
	print_message("  two rollers: condition number %.3g (unit columns)\n", res.fit.condition_number_scaled);
	prsm_calib_physical_free(&res);
	prsm_meas_curve_free(&c);
	free(x);
}

/* ---- §8.5 item 4 ---- */

static double statics_eta(const prsm_design *d0, double mu, double load, double speed)
{
	prsm_design d = *d0;
	d.mu_screw_roller = mu;
	d.axial_load_N = load;
	d.screw_speed_rad_s = speed;
	prsm_analysis a;
	dyn_test_analyse(&a, &d);
	prsm_performance p;
	assert_int_equal(prsm_performance_compute(&p, &d, &a, NULL), 0);
	const double eta = p.losses.eta;
	prsm_performance_free(&p);
	return eta;
}

static void test_friction(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	const double mu0 = 0.0637, F = 4321.0, w = 57.3;
	const double eta0 = statics_eta(&d, mu0, F, w);
	prsm_calib_friction fr;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_calib_friction_compute(&fr, &d, eta0, 0.0043, F, w, &err), 0);
	assert_true(fr.found);
	assert_close(fr.mu, mu0, 1e-9);
	const double dfd = (statics_eta(&d, mu0 + 1e-4, F, w) - statics_eta(&d, mu0 - 1e-4, F, w)) / 2e-4;
	assert_close(fr.deta_dmu, dfd, 1e-4 * fabs(dfd));
	assert_close(fr.mu_se, 0.0043 / fabs(dfd), 1e-4 * fr.mu_se);
	assert_close(fr.efficiency_model, statics_eta(&d, 0.05, F, w), 1e-15);
	assert_close(fr.z, (eta0 - fr.efficiency_model) / 0.0043, 1e-12);
	assert_close(fr.mu_sliding_only, (1.0 - eta0) / (1.0 + eta0), 1e-15);
	/* sliding alone at 45 deg: the root is the closed form's within the 3-D sum's 0.001 (MODEL §5) */
	d.losses.spin = 0;
	d.losses.gear_mesh = 0;
	const double eta1 = statics_eta(&d, 0.0811, F, w);
	assert_int_equal(prsm_calib_friction_compute(&fr, &d, eta1, NAN, F, w, &err), 0);
	assert_close(fr.mu, 0.0811, 1e-9);
	assert_close(fr.mu_sliding_only, 0.0811, 2e-3);
	assert_true(isnan(fr.mu_se));
	/* an efficiency no mu gives: a drag torque of 0.2 N m caps it below 0.99 */
	d.losses.drag_torque_Nm = 0.2;
	assert_int_equal(prsm_calib_friction_compute(&fr, &d, 0.99, 0.01, F, w, &err), 0);
	assert_false(fr.found);
	assert_string_equal(err.pointer, "/measured/efficiency");
	assert_int_equal(prsm_calib_friction_compute(&fr, &d, 1.2, 0.01, F, w, &err), PRSM_EINVAL);
}

static void test_cage(void **state)
{
	(void)state;
	prsm_design d;
	prsm_analysis a;
	dyn_case_a(&d, &a, 0.05);
	prsm_dyn_options o;
	prsm_dyn_options_init(&o);
	o.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	const double F = 3170.0, w = 41.9, cC = 2.37e-3;
	/* the settled ratio at a known drag (independently: the model's settled state) */
	prsm_dyn_options oc = o;
	oc.input.signal.value = w;
	oc.load.value = F;
	oc.friction.carrier_drag_Nm_s_per_rad = cC;
	prsm_dyn_model *m = dyn_test_model(1, &d, &a, &oc);
	const double k_meas = prsm_dyn_model_settled(m)->carrier_ratio[0];
	const double k_star = prsm_dyn_model_settled(m)->carrier_ratio_min_slip[0];
	prsm_dyn_model_free(m);
	assert_true(k_meas < k_star - 1e-4);
	prsm_calib_cage cg;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_calib_cage_compute(&cg, &d, &a, &o, k_meas, 0.0021, F, w, &err), 0);
	assert_true(cg.drag_found);
	assert_false(cg.above_k_star);
	assert_close(cg.carrier_drag_Nm_s_per_rad, cC, 1e-6 * cC);
	assert_close(cg.k_star, k_star, 0.0);
	assert_close(cg.k_star, 0.37369408, 1e-7);
	assert_close(cg.z_k_star, (k_meas - k_star) / 0.0021, 1e-12);
	/* d k / d c_C by a difference of the settled state */
	oc.friction.carrier_drag_Nm_s_per_rad = cC * 1.01;
	m = dyn_test_model(1, &d, &a, &oc);
	const double k2 = prsm_dyn_model_settled(m)->carrier_ratio[0];
	prsm_dyn_model_free(m);
	const double slope = (k2 - k_meas) / (0.01 * cC);
	assert_close(cg.dk_dcC, slope, 0.02 * fabs(slope));
	assert_close(cg.carrier_drag_se_Nm_s_per_rad, 0.0021 / fabs(cg.dk_dcC), 1e-12);
	/* above k*: no drag explains it, flagged */
	assert_int_equal(prsm_calib_cage_compute(&cg, &d, &a, &o, k_star + 0.0017, 0.001, F, w, &err), 0);
	assert_true(cg.above_k_star);
	assert_false(cg.drag_found);
	assert_int_equal(prsm_calib_cage_compute(&cg, &d, &a, &o, 1.3, 0.001, F, w, &err), PRSM_EINVAL);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_line_jacobian),     cmocka_unit_test(test_line_noise_free),
		cmocka_unit_test(test_line_coverage),     cmocka_unit_test(test_line_global_grid),
		cmocka_unit_test(test_caveat_resolution), cmocka_unit_test(test_caveat_correlated),
		cmocka_unit_test(test_caveat_slope),      cmocka_unit_test(test_line_refused),
		cmocka_unit_test(test_statics_te_sign),
		cmocka_unit_test(test_physical_recovers), cmocka_unit_test(test_physical_coverage),
		cmocka_unit_test(test_physical_caveats),
		cmocka_unit_test(test_friction),          cmocka_unit_test(test_cage),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
