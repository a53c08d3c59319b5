/*
 * vib_hb.c: the one-harmonic balance of the gear pair with constant mesh stiffness (docs/model
 * §8.4 "Frequency response with jumps" (i)): x = x_m + A cos(Omega tau - theta) through the dead
 * zone's describing functions N_0, N_1; for each amplitude A the mean equation N_0(x_m, A) = f_m
 * (monotone in x_m: bisection) and the first harmonic's quadratic in s = Omega^2,
 *     (A^2 - eps^2) s^2 + A^2 (4 zeta^2 - 2 N_1) s + A^2 N_1^2 = 0.
 * Parametrised by A the curve has a low branch (from A = 0, Omega = 0 up to where the two roots
 * merge) and a high branch (back down to A = eps, Omega -> infinity); isolas (further intervals
 * of A with two roots) are separate segments. Folds are the extrema of Omega along the curve,
 * refined by golden-section search on Omega(A) of their branch. Between two folds the branch is
 * unstable (counted along the curve). HB is approximate near impacts (a few 1e-3 in frequency,
 * §8.4); the integrated sweeps and shooting are the reference.
 */
#include "dyn/vib_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double clamp_acos(double v)
{
	return acos(v > 1.0 ? 1.0 : (v < -1.0 ? -1.0 : v));
}

void prsm_vib_dead_zone_describing(double xm, double A, double *N0, double *N1)
{
	if (!(A > 0.0)) {
		*N0 = vib_dead(xm);
		*N1 = fabs(xm) > 1.0 ? 1.0 : 0.0;
		return;
	}
	const double t1 = clamp_acos((1.0 - xm) / A), t2 = clamp_acos((-1.0 - xm) / A);
	const double s1 = sin(t1), s2 = sin(t2), c1 = cos(t1), c2 = cos(t2);
	*N0 = ((xm - 1.0) * t1 + A * s1 + (xm + 1.0) * (M_PI - t2) - A * s2) / M_PI;
	*N1 = (2.0 * (xm - 1.0) * s1 + A * (t1 + s1 * c1) - 2.0 * (xm + 1.0) * s2 + A * (M_PI - t2 - s2 * c2)) / (M_PI * A);
}

/* x_m with N_0(x_m, A) = f_m: h(x) - 1 <= ... so the root lies in [f_m - 1, f_m + 1] */
static double mean_of(double A, double fm)
{
	double lo = fm - 1.0 - 1e-12, hi = fm + 1.0 + 1e-12, N0, N1;
	for (int i = 0; i < 200 && hi - lo > 1e-15 * fmax(1.0, fabs(hi)); i++) {
		const double mid = 0.5 * (lo + hi);
		prsm_vib_dead_zone_describing(mid, A, &N0, &N1);
		if (N0 < fm)
			lo = mid;
		else
			hi = mid;
	}
	return 0.5 * (lo + hi);
}

/* the roots s = Omega^2 at amplitude A: n (0..2), s[0] the low branch, s[1] the high one */
static int roots_at(const prsm_vib_gear_pair *g, double A, double *xm, double s[2], double *disc)
{
	const double eps = g->mesh_error, zeta = g->damping_ratio;
	*xm = mean_of(A, g->mean_force);
	double N0, N1;
	prsm_vib_dead_zone_describing(*xm, A, &N0, &N1);
	const double a = A * A - eps * eps, b = A * A * (4.0 * zeta * zeta - 2.0 * N1), c = A * A * N1 * N1;
	*disc = b * b - 4.0 * a * c;
	if (c <= 0.0)
		return 0;
	if (a < 0.0 || a == 0.0) {
		/* one positive root (the low branch): s = 2c / (-b + sqrt(D)), D > b^2 */
		const double D = fmax(*disc, 0.0);
		const double den = -b + sqrt(D);
		if (!(den > 0.0))
			return 0;
		s[0] = 2.0 * c / den;
		return 1;
	}
	if (*disc < 0.0 || !(-b > 0.0))
		return 0;
	const double q = sqrt(*disc);
	s[0] = 2.0 * c / (-b + q);
	s[1] = (-b + q) / (2.0 * a);
	return 2;
}

/* Omega on a branch at A (NaN when the branch has no root there) */
static double omega_on(const prsm_vib_gear_pair *g, double A, int branch)
{
	double xm, s[2], D;
	const int n = roots_at(g, A, &xm, s, &D);
	if (branch == 0 && n >= 1)
		return sqrt(s[0]);
	if (branch == 1 && n == 2)
		return sqrt(s[1]);
	return NAN;
}

/* the merge of the two branches between A_lo (two roots) and A_hi (none): bisection on the disc */
static double merge_between(const prsm_vib_gear_pair *g, double lo, double hi)
{
	for (int i = 0; i < 200 && hi - lo > 1e-14 * hi; i++) {
		const double mid = 0.5 * (lo + hi);
		double xm, s[2], D;
		if (roots_at(g, mid, &xm, s, &D) == 2)
			lo = mid;
		else
			hi = mid;
	}
	return lo;
}

/* golden-section search of an extremum of Omega(A) on a branch within [a, b]; sign +1: maximum */
static double golden(const prsm_vib_gear_pair *g, int branch, double a, double b, int sign)
{
	const double r = 0.5 * (sqrt(5.0) - 1.0);
	double x1 = b - r * (b - a), x2 = a + r * (b - a);
	double f1 = sign * omega_on(g, x1, branch), f2 = sign * omega_on(g, x2, branch);
	for (int i = 0; i < 200 && b - a > 1e-13 * b; i++) {
		if (!(f1 <= f2) && !isnan(f1)) {
			b = x2;
			x2 = x1;
			f2 = f1;
			x1 = b - r * (b - a);
			f1 = sign * omega_on(g, x1, branch);
		} else {
			a = x1;
			x1 = x2;
			f1 = f2;
			x2 = a + r * (b - a);
			f2 = sign * omega_on(g, x2, branch);
		}
	}
	return 0.5 * (a + b);
}

void prsm_vib_hb_free(prsm_vib_hb *h)
{
	free(h->point);
	memset(h, 0, sizeof *h);
}

typedef struct {
	double A, W, xm;
	int branch, segment;
} raw_point;

int prsm_vib_harmonic_balance(prsm_vib_hb *out, const prsm_vib_gear_pair *g, double omega_min, double omega_max,
                              int samples, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (g->stiffness_variation != 0.0)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/vibration/stiffness_variation",
		                      "harmonic balance takes the constant mesh stiffness (kappa = 0)");
	if (!(omega_min >= 0.0 && omega_max > omega_min && isfinite(omega_max)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "the frequency range must be 0 <= from < to");
	if (samples < 100)
		samples = 100;
	if (samples > 200000)
		samples = 200000;
	if (!(g->mesh_error > 0.0))
		return 0; /* no excitation: no curve */
	/* a geometric grid of amplitudes, fine enough near the merge */
	const double eps = g->mesh_error;
	const double A_lo = 1e-3 * eps, A_hi = fmax(100.0, 1e3 * eps);
	const int N = samples;
	raw_point *raw = malloc((size_t)(4 * N + 16) * sizeof *raw);
	double *As = malloc((size_t)(N + 1) * sizeof *As);
	int *nr = malloc((size_t)(N + 1) * sizeof *nr);
	double (*ss)[2] = malloc((size_t)(N + 1) * sizeof *ss);
	double *xms = malloc((size_t)(N + 1) * sizeof *xms);
	int rc = 0;
	if (!raw || !As || !nr || !ss || !xms) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the HB curve");
		goto cleanup;
	}
	for (int i = 0; i <= N; i++) {
		As[i] = A_lo * pow(A_hi / A_lo, (double)i / N);
		double D;
		nr[i] = roots_at(g, As[i], &xms[i], ss[i], &D);
	}
	/* segments: maximal runs of A with roots; a run that starts below eps (one root) is the main
	 * curve's low branch; each run of two roots ends (and isolas also start) at a merge */
	size_t np = 0;
	int segment = 0;
	int i = 0;
	while (i <= N) {
		if (nr[i] == 0) {
			i++;
			continue;
		}
		int j = i;
		while (j + 1 <= N && nr[j + 1] > 0)
			j++;
		/* run [i, j] */
		double A_start = As[i], A_end = As[j];
		if (i > 0 && nr[i] == 2)
			A_start = merge_between(g, As[i], As[i - 1]);
		if (j < N && nr[j] == 2)
			A_end = merge_between(g, As[j], As[j + 1]);
		/* low branch ascending */
		if (i > 0 && nr[i] == 2) {
			raw[np++] = (raw_point){A_start, omega_on(g, A_start, 0), mean_of(A_start, g->mean_force), 0, segment};
		}
		for (int k = i; k <= j; k++)
			raw[np++] = (raw_point){As[k], sqrt(ss[k][0]), xms[k], 0, segment};
		if (j < N && nr[j] == 2) {
			const double W = omega_on(g, A_end, 0);
			raw[np++] = (raw_point){A_end, W, mean_of(A_end, g->mean_force), 0, segment};
			raw[np++] = (raw_point){A_end, W, mean_of(A_end, g->mean_force), 1, segment};
		}
		/* high branch descending */
		for (int k = j; k >= i; k--)
			if (nr[k] == 2)
				raw[np++] = (raw_point){As[k], sqrt(ss[k][1]), xms[k], 1, segment};
		if (i > 0 && nr[i] == 2)
			raw[np++] = (raw_point){A_start, omega_on(g, A_start, 0), mean_of(A_start, g->mean_force), 1, segment};
		segment++;
		i = j + 1;
	}
	/* folds: the extrema of Omega along each segment (the merges included only as interior points) */
	int *keep = calloc(np > 0 ? np : 1, sizeof *keep);
	if (keep == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	for (size_t k = 1; k + 1 < np && out->folds < 16; k++) {
		if (raw[k - 1].segment != raw[k].segment || raw[k + 1].segment != raw[k].segment)
			continue;
		const double d1 = raw[k].W - raw[k - 1].W, d2 = raw[k + 1].W - raw[k].W;
		if (!(d1 * d2 < 0.0))
			continue;
		const int sign = d1 > 0.0 ? 1 : -1;
		prsm_vib_fold *f = &out->fold[out->folds];
		if (raw[k - 1].branch == raw[k].branch && raw[k + 1].branch == raw[k].branch) {
			const double a = fmin(raw[k - 1].A, raw[k + 1].A), b = fmax(raw[k - 1].A, raw[k + 1].A);
			const double A = golden(g, raw[k].branch, a, b, sign);
			f->amplitude = A;
			f->omega = omega_on(g, A, raw[k].branch);
			f->mean = mean_of(A, g->mean_force);
		} else {
			f->amplitude = raw[k].A;
			f->omega = raw[k].W;
			f->mean = raw[k].xm;
		}
		f->kind = sign;
		keep[k] = sign;
		out->folds++;
	}
	/* the points inside the range, with stability by the fold count along each segment */
	out->point = malloc((np > 0 ? np : 1) * sizeof *out->point);
	if (out->point == NULL) {
		free(keep);
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto cleanup;
	}
	int seg = -1, stable = 1;
	for (size_t k = 0; k < np; k++) {
		if (raw[k].segment != seg) {
			seg = raw[k].segment;
			stable = seg == 0; /* isolas: their first half counted unstable until a fold */
		}
		if (keep[k])
			stable = !stable;
		if (!(raw[k].W >= omega_min && raw[k].W <= omega_max))
			continue;
		prsm_vib_hb_point *p = &out->point[out->points++];
		p->omega = raw[k].W;
		p->amplitude = raw[k].A;
		p->mean = raw[k].xm;
		p->branch = raw[k].branch;
		p->segment = raw[k].segment;
		p->stable = stable;
	}
	free(keep);
cleanup:
	free(raw);
	free(As);
	free(nr);
	free(ss);
	free(xms);
	if (rc)
		prsm_vib_hb_free(out);
	return rc;
}
