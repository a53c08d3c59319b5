/*
 * measured.c: checking a measured TE curve, comparing it with a model curve and identifying its
 * lines by spectrum (MODEL-DYNAMICS.md §8.5 items 1 and 2; see measured.h).
 */
#include "dyn/measured.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_fft_real.h>

int prsm_meas_data_init(prsm_meas_data *m)
{
	memset(m, 0, sizeof *m);
	m->te_noise_sd_um = NAN;
	m->cage_ratio = NAN;
	m->cage_ratio_sd = NAN;
	m->cage_axial_load_N = NAN;
	m->cage_screw_speed_rad_s = NAN;
	m->efficiency = NAN;
	m->efficiency_sd = NAN;
	m->efficiency_axial_load_N = NAN;
	m->efficiency_screw_speed_rad_s = NAN;
	return 0;
}

void prsm_meas_data_free(prsm_meas_data *m)
{
	prsm_meas_curve_free(&m->te);
	m->has_te = 0;
}

int prsm_meas_curve_alloc(prsm_meas_curve *c, size_t n, prsm_error *err)
{
	memset(c, 0, sizeof *c);
	if (n > PRSM_MEAS_POINTS_MAX)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "a measured TE curve has at most %d points (got %zu): decimate it",
		                      PRSM_MEAS_POINTS_MAX, n);
	const size_t m = n > 0 ? n : 1;
	c->angle_rad = calloc(m, sizeof(double));
	c->travel_mm = calloc(m, sizeof(double));
	c->te_um = calloc(m, sizeof(double));
	if (!c->angle_rad || !c->travel_mm || !c->te_um) {
		prsm_meas_curve_free(c);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for a measured curve of %zu points", n);
	}
	c->n = n;
	return 0;
}

void prsm_meas_curve_free(prsm_meas_curve *c)
{
	free(c->angle_rad);
	free(c->travel_mm);
	free(c->te_um);
	memset(c, 0, sizeof *c);
}

double prsm_meas_revolutions(const prsm_meas_curve *c)
{
	return c->n < 2 ? 0.0 : (c->angle_rad[c->n - 1] - c->angle_rad[0]) / (2.0 * M_PI);
}

static int fail(prsm_meas_problem *p, int what, size_t index, int column)
{
	p->what = what;
	p->index = index;
	p->column = column;
	return PRSM_EINVAL;
}

int prsm_meas_curve_complete(prsm_meas_curve *c, double lead_mm, prsm_meas_problem *p, prsm_error *err)
{
	memset(p, 0, sizeof *p);
	p->revolutions = NAN;
	if (!(lead_mm > 0.0) || !isfinite(lead_mm))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the lead must be positive to relate travel and angle");
	if (c->n > PRSM_MEAS_POINTS_MAX) {
		fail(p, PRSM_MEAS_TOO_MANY, PRSM_MEAS_POINTS_MAX, PRSM_MEAS_COL_TE);
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a measured TE curve has at most %d points (got %zu): decimate it",
		                      PRSM_MEAS_POINTS_MAX, c->n);
	}
	if (!c->has_angle && !c->has_travel)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a TE curve needs the screw angle or the travel of each point");
	/* every value finite, column by column in the order of a row */
	for (size_t i = 0; i < c->n; i++) {
		if (c->has_angle && !isfinite(c->angle_rad[i])) {
			fail(p, PRSM_MEAS_NOT_FINITE, i, PRSM_MEAS_COL_ANGLE);
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the screw angle is not a finite number");
		}
		if (c->has_travel && !isfinite(c->travel_mm[i])) {
			fail(p, PRSM_MEAS_NOT_FINITE, i, PRSM_MEAS_COL_TRAVEL);
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the travel is not a finite number");
		}
		if (!isfinite(c->te_um[i])) {
			fail(p, PRSM_MEAS_NOT_FINITE, i, PRSM_MEAS_COL_TE);
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the TE is not a finite number");
		}
	}
	const int col = c->has_angle ? PRSM_MEAS_COL_ANGLE : PRSM_MEAS_COL_TRAVEL;
	const double *x = c->has_angle ? c->angle_rad : c->travel_mm;
	for (size_t i = 1; i < c->n; i++)
		if (!(x[i] > x[i - 1])) {
			fail(p, PRSM_MEAS_NOT_INCREASING, i, col);
			return prsm_error_set(err, PRSM_EINVAL, NULL,
			                      "the %s must increase strictly from point to point (%.17g after %.17g)",
			                      c->has_angle ? "screw angle" : "travel", x[i], x[i - 1]);
		}
	const double to_angle = 2.0 * M_PI / lead_mm; /* rad per mm of travel */
	if (c->has_angle && c->has_travel) {
		const double span = fabs(c->travel_mm[c->n ? c->n - 1 : 0] - c->travel_mm[0]) + lead_mm;
		for (size_t i = 0; i < c->n; i++) {
			const double want = c->angle_rad[i] / to_angle;
			if (fabs(c->travel_mm[i] - want) > PRSM_MEAS_TRAVEL_TOLERANCE * span) {
				fail(p, PRSM_MEAS_TRAVEL_MISMATCH, i, PRSM_MEAS_COL_TRAVEL);
				return prsm_error_set(err, PRSM_EINVAL, NULL,
				                      "the travel %.9g mm does not follow the screw angle %.9g rad with the lead %.6g mm "
				                      "(%.9g mm expected)", c->travel_mm[i], c->angle_rad[i], lead_mm, want);
			}
		}
	} else if (c->has_angle) {
		for (size_t i = 0; i < c->n; i++)
			c->travel_mm[i] = c->angle_rad[i] / to_angle;
	} else {
		for (size_t i = 0; i < c->n; i++)
			c->angle_rad[i] = c->travel_mm[i] * to_angle;
	}
	if (c->n < 8) {
		fail(p, PRSM_MEAS_TOO_FEW, c->n ? c->n - 1 : 0, col);
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a TE curve needs at least 8 points (got %zu)", c->n);
	}
	const double revs = prsm_meas_revolutions(c);
	if (!(revs >= PRSM_MEAS_REVOLUTIONS_MIN)) {
		fail(p, PRSM_MEAS_TOO_SHORT, c->n - 1, col);
		p->revolutions = revs;
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "the TE record covers %.4g screw revolutions; at least %g are needed to separate its lines "
		                      "(MODEL §8.5)", revs, PRSM_MEAS_REVOLUTIONS_MIN);
	}
	p->revolutions = revs;
	return 0;
}

void prsm_meas_fit_line(double *a, double *b, const prsm_meas_curve *c)
{
	double sm = 0.0, ym = 0.0;
	const size_t n = c->n;
	for (size_t i = 0; i < n; i++) {
		sm += c->travel_mm[i];
		ym += c->te_um[i];
	}
	sm /= (double)n;
	ym /= (double)n;
	double sxy = 0.0, sxx = 0.0;
	for (size_t i = 0; i < n; i++) {
		const double ds = c->travel_mm[i] - sm;
		sxy += ds * (c->te_um[i] - ym);
		sxx += ds * ds;
	}
	*b = sxx > 0.0 ? sxy / sxx : 0.0;
	*a = ym - *b * sm;
}

double prsm_meas_lag1(const double *x, size_t n)
{
	if (n < 3)
		return NAN;
	double m = 0.0;
	for (size_t i = 0; i < n; i++)
		m += x[i];
	m /= (double)n;
	double num = 0.0, den = 0.0;
	for (size_t i = 0; i < n; i++) {
		den += (x[i] - m) * (x[i] - m);
		if (i + 1 < n)
			num += (x[i] - m) * (x[i + 1] - m);
	}
	return den > 0.0 ? num / den : 0.0;
}

double prsm_meas_z(double measured, double model, double sd)
{
	if (!(sd > 0.0) || !isfinite(sd) || !isfinite(measured) || !isfinite(model))
		return NAN;
	return (measured - model) / sd;
}

void prsm_meas_compare(prsm_meas_comparison *out, const prsm_meas_curve *c, const double *model_um,
                       double noise_sd_um, double *residual_um)
{
	memset(out, 0, sizeof *out);
	const size_t n = c->n;
	double off = 0.0, mm = 0.0, ym = 0.0;
	for (size_t i = 0; i < n; i++) {
		off += c->te_um[i] - model_um[i];
		mm += model_um[i];
		ym += c->te_um[i];
	}
	off /= (double)n;
	mm /= (double)n;
	ym /= (double)n;
	double lo = INFINITY, hi = -INFINITY, ss = 0.0, sy = 0.0, sm = 0.0, big = 0.0;
	double s_mean = 0.0;
	for (size_t i = 0; i < n; i++)
		s_mean += c->travel_mm[i];
	s_mean /= (double)n;
	double sxy = 0.0, sxx = 0.0;
	for (size_t i = 0; i < n; i++) {
		const double r = c->te_um[i] - model_um[i] - off;
		lo = fmin(lo, r);
		hi = fmax(hi, r);
		big = fmax(big, fabs(r));
		ss += r * r;
		sy += (c->te_um[i] - ym) * (c->te_um[i] - ym);
		sm += (model_um[i] - mm) * (model_um[i] - mm);
		const double ds = c->travel_mm[i] - s_mean;
		sxy += ds * r;
		sxx += ds * ds;
		if (residual_um)
			residual_um[i] = r;
	}
	out->offset_um = off;
	out->rms_um = sqrt(ss / (double)n);
	out->peak_to_peak_um = hi - lo;
	out->max_abs_um = big;
	out->lead_deviation_um_per_300mm = sxx > 0.0 ? 300.0 * sxy / sxx : 0.0;
	out->measured_rms_um = sqrt(sy / (double)n);
	out->model_rms_um = sqrt(sm / (double)n);
	out->z_rms = noise_sd_um > 0.0 && isfinite(noise_sd_um) ? out->rms_um / noise_sd_um : NAN;
}

/* ---- spectrum (§8.5 item 2) ---- */

void prsm_meas_spectrum_free(prsm_meas_spectrum *s)
{
	free(s->amplitude_um);
	s->amplitude_um = NULL;
	s->bins = 0;
}

int prsm_meas_spectrum_compute(prsm_meas_spectrum *out, const prsm_meas_curve *c, const double *orders, int n_orders,
                               prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (n_orders < 0 || n_orders > PRSM_MEAS_ORDERS_MAX || c->n < 8)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a spectrum needs at least 8 points and at most %d named orders",
		                      PRSM_MEAS_ORDERS_MAX);
	const size_t n = c->n;
	const double revs = prsm_meas_revolutions(c);
	const double dth = (c->angle_rad[n - 1] - c->angle_rad[0]) / (double)(n - 1); /* mean step, rad */
	out->revolutions = revs;
	out->resolution_per_rev = 1.0 / revs;
	out->samples_per_rev = 2.0 * M_PI / dth;
	/* detrend on travel: the slope is the lead deviation (§8.5 item 2) */
	double a, b;
	prsm_meas_fit_line(&a, &b, c);
	out->lead_deviation_um_per_300mm = 300.0 * b;
	out->line_offset_um = a;
	/* equal spacing within 1e-6 of the step, else linear interpolation onto the equal grid */
	for (size_t i = 1; i < n && !out->resampled; i++)
		out->resampled = fabs(c->angle_rad[i] - c->angle_rad[i - 1] - dth) > 1e-6 * dth;
	size_t m = 2;
	while (m < 4 * n) /* zero padded at least four times: bins a quarter of the resolution apart */
		m *= 2;
	double *x = calloc(m, sizeof(double));
	if (x == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the spectrum of %zu points", n);
	double wsum = 0.0;
	size_t j = 0;
	for (size_t i = 0; i < n; i++) {
		double te, s;
		if (!out->resampled) {
			te = c->te_um[i];
			s = c->travel_mm[i];
		} else {
			const double th = c->angle_rad[0] + (double)i * dth;
			while (j + 2 < n && c->angle_rad[j + 1] < th)
				j++;
			const double t = (th - c->angle_rad[j]) / (c->angle_rad[j + 1] - c->angle_rad[j]);
			te = c->te_um[j] + t * (c->te_um[j + 1] - c->te_um[j]);
			s = c->travel_mm[j] + t * (c->travel_mm[j + 1] - c->travel_mm[j]);
		}
		const double win = 0.5 - 0.5 * cos(2.0 * M_PI * ((double)i + 0.5) / (double)n);
		x[i] = win * (te - a - b * s);
		wsum += win;
	}
	/* m is a power of two: the radix-2 transform cannot fail */
	gsl_fft_real_radix2_transform(x, 1, m);
	out->bins = m / 2 + 1;
	out->amplitude_um = malloc(out->bins * sizeof(double));
	if (out->amplitude_um == NULL) {
		free(x);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the spectrum of %zu points", n);
	}
	out->amplitude_um[0] = fabs(x[0]) / wsum;
	for (size_t k = 1; k < m / 2; k++)
		out->amplitude_um[k] = 2.0 * hypot(x[k], x[m - k]) / wsum;
	out->amplitude_um[m / 2] = fabs(x[m / 2]) / wsum;
	free(x);
	out->step_per_rev = out->samples_per_rev / (double)m;
	/* the named orders: the largest amplitude within +-2 resolutions */
	out->orders = n_orders;
	const double nyq = 0.5 * out->samples_per_rev;
	for (int l = 0; l < n_orders; l++) {
		const double nu = orders[l];
		out->order_per_rev[l] = nu;
		out->above_nyquist[l] = !(nu < nyq);
		out->found_order_per_rev[l] = NAN;
		out->found_amplitude_um[l] = NAN;
		if (out->above_nyquist[l] || !(nu >= 0.0))
			continue;
		const double lo = nu - 2.0 * out->resolution_per_rev, hi = nu + 2.0 * out->resolution_per_rev;
		long b0 = (long)ceil(lo / out->step_per_rev), b1 = (long)floor(hi / out->step_per_rev);
		if (b0 < 0)
			b0 = 0;
		if (b1 > (long)out->bins - 1)
			b1 = (long)out->bins - 1;
		double best = -1.0;
		for (long k = b0; k <= b1; k++)
			if (out->amplitude_um[k] > best) {
				best = out->amplitude_um[k];
				out->found_amplitude_um[l] = best;
				out->found_order_per_rev[l] = (double)k * out->step_per_rev;
			}
	}
	return 0;
}
