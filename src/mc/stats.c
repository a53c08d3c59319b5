/*
 * stats.c: running moments and the summary of one Monte Carlo output (see stats.h for the
 * definitions and standard errors). Sorting, moments and quantiles are GSL's (gsl_sort is a
 * heapsort, so the order of equal values never matters and the result is reproducible); the
 * normal tails are gsl_cdf_ugaussian_P/Q so they stay accurate far out (a Cpk of 2 is 0.001
 * ppm).
 */
#include "mc/stats.h"

#include <assert.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const double prsm_stats_quantile_p[PRSM_STATS_QUANTILES] = {0.00135, 0.01, 0.05, 0.5,
                                                            0.95,    0.99, 0.99865};

void prsm_moments_init(prsm_moments *m)
{
	m->n = 0;
	m->mean = 0.0;
	m->m2 = 0.0;
}

void prsm_moments_add(prsm_moments *m, double x)
{
	m->n++;
	const double delta = x - m->mean;
	m->mean += delta / (double)m->n;
	m->m2 += delta * (x - m->mean);
}

void prsm_moments_merge(prsm_moments *into, const prsm_moments *other)
{
	const size_t na = into->n, nb = other->n;
	if (nb == 0)
		return;
	if (na == 0) {
		*into = *other;
		return;
	}
	const double n = (double)(na + nb);
	const double delta = other->mean - into->mean;
	const double mean = into->mean + delta * ((double)nb / n);
	const double m2 = into->m2 + other->m2 + delta * delta * ((double)na * (double)nb / n);
	into->n = na + nb;
	into->mean = mean;
	into->m2 = m2;
}

double prsm_moments_sd(const prsm_moments *m)
{
	if (m->n < 2)
		return NAN;
	return sqrt(m->m2 / (double)(m->n - 1));
}

void prsm_stats_wilson(size_t k, size_t n, double z, double *low, double *high)
{
	assert(k <= n && z > 0.0);
	if (n == 0) {
		*low = 0.0;
		*high = 1.0;
		return;
	}
	const double nn = (double)n, p = (double)k / nn, z2 = z * z;
	const double denom = 1.0 + z2 / nn;
	const double centre = (p + z2 / (2.0 * nn)) / denom;
	const double half = (z / denom) * sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn));
	*low = k == 0 ? 0.0 : fmax(0.0, centre - half);
	*high = k == n ? 1.0 : fmin(1.0, centre + half);
}

/* Histogram of the sorted sample over [lo, hi], hi > lo. */
static void histogram(size_t *count, const double *sorted, size_t n, double lo, double hi)
{
	for (size_t b = 0; b < PRSM_STATS_HIST_BINS; b++)
		count[b] = 0;
	const double scale = (double)PRSM_STATS_HIST_BINS / (hi - lo);
	for (size_t i = 0; i < n; i++) {
		double t = (sorted[i] - lo) * scale;
		size_t b = t <= 0.0 ? 0 : (size_t)t;
		if (b >= PRSM_STATS_HIST_BINS)
			b = PRSM_STATS_HIST_BINS - 1;
		count[b]++;
	}
}

/* McKean & Schrader (1984) standard error of the median from the sorted sample. */
static double median_standard_error(const double *sorted, size_t n)
{
	const double z = PRSM_STATS_Z95;
	double c = floor(((double)n + 1.0) / 2.0 - z * sqrt((double)n) / 2.0 + 0.5);
	if (c < 1.0)
		c = 1.0;
	const size_t ci = (size_t)c;              /* 1-based order statistic y_(c) */
	const size_t lo = ci - 1, hi = n - ci;    /* 0-based y_(c), y_(n-c+1) */
	if (hi <= lo)
		return 0.0;
	return (sorted[hi] - sorted[lo]) / (2.0 * z);
}

/* Anderson-Darling A*^2 of the normal fit (mean and sd estimated) and its p-value,
 * D'Agostino & Stephens (1986), Table 4.9. */
static void anderson_darling(prsm_stats_summary *out, const double *sorted, size_t n)
{
	out->normal_ad = out->normal_ad_p = NAN;
	out->normal_rejected = 0;
	if (n < 8 || !(out->sd > 0.0))
		return;
	const double nn = (double)n;
	double s = 0.0;
	for (size_t i = 0; i < n; i++) {
		const double zi = (sorted[i] - out->mean) / out->sd, zj = (sorted[n - 1 - i] - out->mean) / out->sd;
		/* ln Phi(z_i) + ln(1 - Phi(z_{n+1-i})), each from its own tail (no cancellation) */
		const double a = gsl_cdf_ugaussian_P(zi), b = gsl_cdf_ugaussian_Q(zj);
		s += (2.0 * (double)i + 1.0) * (log(fmax(a, DBL_MIN)) + log(fmax(b, DBL_MIN)));
	}
	const double A2 = -nn - s / nn;
	const double A = A2 * (1.0 + 0.75 / nn + 2.25 / (nn * nn));
	double p;
	if (A >= 0.6)
		p = exp(1.2937 - 5.709 * A + 0.0186 * A * A);
	else if (A >= 0.34)
		p = exp(0.9177 - 4.279 * A - 1.38 * A * A);
	else if (A >= 0.2)
		p = 1.0 - exp(-8.318 + 42.796 * A - 59.938 * A * A);
	else
		p = 1.0 - exp(-13.436 + 101.14 * A - 223.73 * A * A);
	out->normal_ad = A;
	out->normal_ad_p = fmin(fmax(p, 0.0), 1.0);
	out->normal_rejected = out->normal_ad_p < PRSM_STATS_NORMAL_P_MIN;
}

/* Probability beyond a limit from a generalised Pareto fit to the k excesses e[0..k) (ascending)
 * over the threshold, the limit x beyond it (x > 0), k of n samples in the tail. Hosking &
 * Wallis (1987) probability-weighted moments: a0 = mean e, a1 = mean (1 - p_i) e_(i),
 * p_i = (i + 0.65) / k; shape xi = 2 - a0 / (a0 - 2 a1), scale sigma = 2 a0 a1 / (a0 - 2 a1). */
static double gpd_tail(const double *e, size_t k, size_t n, double x)
{
	double a0 = 0.0, a1 = 0.0;
	for (size_t i = 0; i < k; i++) {
		a0 += e[i];
		a1 += (1.0 - ((double)i + 0.65) / (double)k) * e[i];
	}
	a0 /= (double)k;
	a1 /= (double)k;
	const double den = a0 - 2.0 * a1;
	if (!(a0 > 0.0) || !(den > 0.0))
		return NAN;
	const double xi = 2.0 - a0 / den, sigma = 2.0 * a0 * a1 / den;
	const double frac = (double)k / (double)n;
	if (fabs(xi) < 1e-9)
		return frac * exp(-x / sigma);
	const double t = 1.0 + xi * x / sigma;
	if (t <= 0.0)
		return 0.0; /* beyond the fitted endpoint (xi < 0) */
	return frac * pow(t, -1.0 / xi);
}

/* ppm beyond the limits from the tail fits (see prsm_stats_summary); sorted ascending. */
static void tail_figures(prsm_stats_summary *out, const double *sorted, size_t n, const prsm_spec *spec)
{
	out->ppm_low_tail = out->ppm_high_tail = NAN;
	const size_t k = n / 20;
	if (k < PRSM_STATS_TAIL_MIN)
		return;
	double *e = malloc(k * sizeof *e);
	if (!e)
		return;
	if (spec->has_upper) {
		const double u = sorted[n - 1 - k];
		for (size_t i = 0; i < k; i++)
			e[i] = sorted[n - k + i] - u;
		out->ppm_high_tail = spec->upper <= u ? out->ppm_high : 1e6 * gpd_tail(e, k, n, spec->upper - u);
	}
	if (spec->has_lower) {
		const double u = sorted[k];
		for (size_t i = 0; i < k; i++)
			e[i] = u - sorted[k - 1 - i];
		out->ppm_low_tail = spec->lower >= u ? out->ppm_low : 1e6 * gpd_tail(e, k, n, u - spec->lower);
	}
	free(e);
}

static void spec_figures(prsm_stats_summary *out, const double *sorted, size_t n, const prsm_spec *spec)
{
	size_t below = 0, above = 0;
	for (size_t i = 0; i < n; i++) {
		if (spec->has_lower && sorted[i] < spec->lower)
			below++;
		else if (spec->has_upper && sorted[i] > spec->upper)
			above++;
	}
	const double nn = (double)n;
	const size_t inside = n - below - above;
	out->yield = (double)inside / nn;
	prsm_stats_wilson(inside, n, PRSM_STATS_Z95, &out->yield_low95, &out->yield_high95);
	out->se_yield = sqrt(out->yield * (1.0 - out->yield) / nn);
	/* no sample (or every one) out of spec: the binomial formula says 0, which is not how sure
	 * n samples make us; the Wilson interval's half-width in standard errors says it */
	if (inside == 0 || inside == n)
		out->se_yield = (out->yield_high95 - out->yield_low95) / (2.0 * PRSM_STATS_Z95);
	out->ppm_low = 1e6 * (double)below / nn;
	out->ppm_high = 1e6 * (double)above / nn;

	const double mean = out->mean, sd = out->sd;
	out->ppm_low_normal = 0.0;
	out->ppm_high_normal = 0.0;
	if (spec->has_lower)
		out->ppm_low_normal = sd > 0.0 ? 1e6 * gsl_cdf_ugaussian_P((spec->lower - mean) / sd)
		                               : (mean < spec->lower ? 1e6 : 0.0);
	if (spec->has_upper)
		out->ppm_high_normal = sd > 0.0 ? 1e6 * gsl_cdf_ugaussian_Q((spec->upper - mean) / sd)
		                                : (mean > spec->upper ? 1e6 : 0.0);
	tail_figures(out, sorted, n, spec);

	out->cp = NAN;
	out->cpk = NAN;
	out->se_cpk = NAN;
	if (!(sd > 0.0))
		return;
	if (spec->has_lower && spec->has_upper)
		out->cp = (spec->upper - spec->lower) / (6.0 * sd);
	double cpk = INFINITY;
	if (spec->has_upper)
		cpk = fmin(cpk, (spec->upper - mean) / (3.0 * sd));
	if (spec->has_lower)
		cpk = fmin(cpk, (mean - spec->lower) / (3.0 * sd));
	out->cpk = cpk;
	out->se_cpk = sqrt(1.0 / (9.0 * nn) + cpk * cpk / (2.0 * (nn - 1.0)));
}

int prsm_stats_summarise(prsm_stats_summary *out, const double *y, size_t n, const prsm_spec *spec,
                         double *scratch, prsm_error *err)
{
	assert(out != NULL && y != NULL && scratch != NULL && scratch != y);
	memset(out, 0, sizeof *out);
	if (n < 2)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a summary needs at least 2 samples, got %zu", n);
	for (size_t i = 0; i < n; i++)
		if (!isfinite(y[i]))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "sample %zu is not finite", i);
	int has_spec = spec != NULL && (spec->has_lower || spec->has_upper);
	if (has_spec) {
		if ((spec->has_lower && !isfinite(spec->lower)) || (spec->has_upper && !isfinite(spec->upper)))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "spec limits must be finite");
		if (spec->has_lower && spec->has_upper && !(spec->lower <= spec->upper))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "spec lower limit %g is above the upper %g",
			                      spec->lower, spec->upper);
	}

	const double nn = (double)n;
	const double mean = gsl_stats_mean(y, 1, n);
	const double sd = gsl_stats_sd_m(y, 1, n, mean);
	if (!isfinite(mean) || !isfinite(sd))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the samples span too wide a range for double arithmetic");
	out->n = n;
	out->mean = mean;
	out->sd = sd;
	if (sd > 0.0) {
		out->skewness = gsl_stats_skew_m_sd(y, 1, n, mean, sd);
		out->kurtosis_excess = gsl_stats_kurtosis_m_sd(y, 1, n, mean, sd);
	} else {
		out->skewness = NAN;
		out->kurtosis_excess = NAN;
	}

	memcpy(scratch, y, n * sizeof *scratch);
	gsl_sort(scratch, 1, n);
	out->min = scratch[0];
	out->max = scratch[n - 1];
	for (size_t q = 0; q < PRSM_STATS_QUANTILES; q++)
		out->quantile[q] = gsl_stats_quantile_from_sorted_data(scratch, 1, n, prsm_stats_quantile_p[q]);

	if (out->max > out->min) {
		out->hist_lower = out->min;
		out->hist_upper = out->max;
	} else {
		const double h = 1e-6 * fmax(fabs(out->min), 1.0);
		out->hist_lower = out->min - h;
		out->hist_upper = out->min + h;
	}
	if (!isfinite(out->hist_upper - out->hist_lower))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the samples span too wide a range for double arithmetic");
	histogram(out->hist_count, scratch, n, out->hist_lower, out->hist_upper);

	out->se_mean = sd / sqrt(nn);
	/* se(s) = se(s^2) / (2 s) with Var(s^2) = s^4 (kurtosis_excess / n + 2 / (n - 1)) */
	const double kurt = isnan(out->kurtosis_excess) ? 0.0 : out->kurtosis_excess;
	out->se_sd = 0.5 * sd * sqrt(fmax(kurt / nn + 2.0 / (nn - 1.0), 0.0));
	out->se_quantile_median = median_standard_error(scratch, n);

	anderson_darling(out, scratch, n);
	out->has_spec = has_spec;
	if (has_spec) {
		spec_figures(out, scratch, n, spec);
	} else {
		out->yield = out->yield_low95 = out->yield_high95 = out->se_yield = NAN;
		out->ppm_low = out->ppm_high = out->ppm_low_normal = out->ppm_high_normal = NAN;
		out->ppm_low_tail = out->ppm_high_tail = NAN;
		out->cp = out->cpk = out->se_cpk = NAN;
	}
	return 0;
}
