/*
 * sens.c: standardized regression coefficients (on values or ranks) by GSL's least squares, and
 * Sobol' indices from a Saltelli design with a bootstrap over the design's rows (see sens.h for
 * the estimators). Every input is checked before GSL sees it, so GSL's error handler is never
 * reached on a valid call.
 */
#include "mc/sens.h"
#include "util/clock.h"

#include <assert.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <gsl/gsl_vector.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* rank[i] = average rank (1-based) of data[i]; perm: n entries of scratch. */
static void average_ranks(double *rank, size_t *perm, const double *data, size_t n)
{
	gsl_sort_index(perm, data, 1, n);
	size_t i = 0;
	while (i < n) {
		size_t j = i;
		while (j + 1 < n && data[perm[j + 1]] == data[perm[i]])
			j++;
		const double r = 0.5 * (double)(i + j) + 1.0;
		for (size_t t = i; t <= j; t++)
			rank[perm[t]] = r;
		i = j + 1;
	}
}

/* Centre and scale v[0..n) in place by its mean and sample sd; returns the sd (0: left as is). */
static double standardize(double *v, size_t n)
{
	const double mean = gsl_stats_mean(v, 1, n);
	const double sd = gsl_stats_sd_m(v, 1, n, mean);
	if (sd > 0.0)
		for (size_t i = 0; i < n; i++)
			v[i] = (v[i] - mean) / sd;
	return sd;
}

int prsm_sens_src(double *coef, double *r2, int *constant, const double *x, size_t n, size_t d,
                  const double *y, int ranks, prsm_error *err)
{
	assert(coef != NULL && r2 != NULL && x != NULL && y != NULL);
	if (d == 0 || n < d + 2)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "regression on %zu inputs needs at least %zu samples, got %zu", d, d + 2, n);
	for (size_t i = 0; i < n; i++) {
		if (!isfinite(y[i]))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "output sample %zu is not finite", i);
		for (size_t j = 0; j < d; j++)
			if (!isfinite(x[i * d + j]))
				return prsm_error_set(err, PRSM_EINVAL, NULL, "input %zu of sample %zu is not finite", j, i);
	}

	int rc = 0;
	double *col = malloc(n * sizeof *col);
	double *rank = malloc(n * sizeof *rank);
	size_t *perm = malloc(n * sizeof *perm);
	size_t *column_of = malloc(d * sizeof *column_of); /* fit column k <- input column_of[k] */
	gsl_matrix *X = gsl_matrix_alloc(n, d);
	gsl_vector *yv = gsl_vector_alloc(n);
	gsl_vector *c = NULL;
	gsl_matrix *cov = NULL;
	gsl_multifit_linear_workspace *work = NULL;
	if (col == NULL || rank == NULL || perm == NULL || column_of == NULL || X == NULL || yv == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the regression of %zu x %zu", n, d);
		goto cleanup;
	}

	/* standardized (ranked) inputs into the first p columns of X */
	size_t p = 0;
	for (size_t j = 0; j < d; j++) {
		for (size_t i = 0; i < n; i++)
			col[i] = x[i * d + j];
		double *v = col;
		if (ranks) {
			average_ranks(rank, perm, col, n);
			v = rank;
		}
		const double sd = standardize(v, n);
		coef[j] = 0.0;
		if (constant != NULL)
			constant[j] = !(sd > 0.0);
		if (!(sd > 0.0))
			continue;
		for (size_t i = 0; i < n; i++)
			gsl_matrix_set(X, i, p, v[i]);
		column_of[p++] = j;
	}

	/* standardized (ranked) output */
	for (size_t i = 0; i < n; i++)
		col[i] = y[i];
	double *v = col;
	if (ranks) {
		average_ranks(rank, perm, col, n);
		v = rank;
	}
	if (!(standardize(v, n) > 0.0)) {
		for (size_t j = 0; j < d; j++)
			coef[j] = NAN;
		*r2 = NAN;
		goto cleanup;
	}
	double ss_total = 0.0;
	for (size_t i = 0; i < n; i++) {
		gsl_vector_set(yv, i, v[i]);
		ss_total += v[i] * v[i];
	}
	if (p == 0) {
		*r2 = 0.0;
		goto cleanup;
	}

	c = gsl_vector_alloc(p);
	cov = gsl_matrix_alloc(p, p);
	work = gsl_multifit_linear_alloc(n, p);
	if (c == NULL || cov == NULL || work == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the regression of %zu x %zu", n, d);
		goto cleanup;
	}
	gsl_matrix_const_view Xp = gsl_matrix_const_submatrix(X, 0, 0, n, p);
	double ss_residual = 0.0;
	if (gsl_multifit_linear(&Xp.matrix, yv, c, cov, &ss_residual, work) != 0) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the least-squares fit of the sensitivity regression failed");
		goto cleanup;
	}
	for (size_t k = 0; k < p; k++)
		coef[column_of[k]] = gsl_vector_get(c, k);
	*r2 = 1.0 - ss_residual / ss_total;

cleanup:
	if (work != NULL)
		gsl_multifit_linear_free(work);
	if (cov != NULL)
		gsl_matrix_free(cov);
	if (c != NULL)
		gsl_vector_free(c);
	if (yv != NULL)
		gsl_vector_free(yv);
	if (X != NULL)
		gsl_matrix_free(X);
	free(column_of);
	free(perm);
	free(rank);
	free(col);
	return rc;
}

/* Row j of the (resampled) design. */
static inline size_t row_of(const size_t *rows, size_t j)
{
	return rows != NULL ? rows[j] : j;
}

/* first[i], total[i] (i < d) and *V over the rows rows[0..n) (NULL: 0..n-1); stride is the
 * length of each column of yAB (yAB[i * stride + row]). */
static void sobol_estimate(double *first, double *total, double *V, const double *yA, const double *yB,
                           const double *yAB, size_t n, size_t stride, size_t d, const size_t *rows)
{
	const double nn = (double)n;
	double sum = 0.0;
	for (size_t j = 0; j < n; j++) {
		const size_t r = row_of(rows, j);
		sum += yA[r] + yB[r];
	}
	const double f0 = sum / (2.0 * nn);
	double ss = 0.0;
	for (size_t j = 0; j < n; j++) {
		const size_t r = row_of(rows, j);
		ss += (yA[r] - f0) * (yA[r] - f0) + (yB[r] - f0) * (yB[r] - f0);
	}
	*V = ss / (2.0 * nn - 1.0);
	for (size_t i = 0; i < d; i++) {
		const double *yi = yAB + i * stride;
		double s_first = 0.0, s_total = 0.0;
		for (size_t j = 0; j < n; j++) {
			const size_t r = row_of(rows, j);
			const double diff = yi[r] - yA[r];
			s_first += (yB[r] - f0) * diff;
			s_total += diff * diff;
		}
		if (*V > 0.0) {
			first[i] = s_first / nn / *V;
			total[i] = s_total / (2.0 * nn) / *V;
		} else {
			first[i] = NAN;
			total[i] = NAN;
		}
	}
}

/* Bootstrap sd and 95 % percentile interval of b[0..nboot) (sorted in place); NAN when any
 * resample is NAN. */
static void bootstrap_figures(double *se, double *low, double *high, double *b, size_t nboot)
{
	for (size_t k = 0; k < nboot; k++)
		if (isnan(b[k])) {
			*se = *low = *high = NAN;
			return;
		}
	*se = gsl_stats_sd(b, 1, nboot);
	gsl_sort(b, 1, nboot);
	*low = gsl_stats_quantile_from_sorted_data(b, 1, nboot, 0.025);
	*high = gsl_stats_quantile_from_sorted_data(b, 1, nboot, 0.975);
}

int prsm_sens_sobol(prsm_sobol_index *out, double *variance_out, const double *yA, const double *yB,
                    const double *yAB, size_t n, size_t d, size_t nboot, gsl_rng *rng, prsm_error *err)
{
	return prsm_sens_sobol_until(out, variance_out, yA, yB, yAB, n, d, nboot, rng, NULL, 0.0, NULL, err);
}

int prsm_sens_sobol_until(prsm_sobol_index *out, double *variance_out, const double *yA, const double *yB,
                          const double *yAB, size_t n, size_t d, size_t nboot, gsl_rng *rng,
                          const prsm_cancel_flag *cancel, double deadline_s, size_t *boot_done,
                          prsm_error *err)
{
	if (boot_done != NULL)
		*boot_done = 0;
	assert(out != NULL && yA != NULL && yB != NULL && yAB != NULL);
	if (n < 2 || d == 0)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "Sobol' indices need n >= 2 rows and d >= 1 inputs");
	if (nboot == 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the bootstrap needs at least 2 resamples (or 0 for none)");
	if (nboot > SIZE_MAX / (2 * d) / sizeof(double))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%zu bootstrap resamples are too many", nboot);
	if (nboot > 0 && rng == NULL)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the bootstrap needs a random number generator");
	if (nboot > 0 && n > gsl_rng_max(rng) - gsl_rng_min(rng))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%zu rows exceed the range of generator %s", n,
		                      gsl_rng_name(rng));
	for (size_t j = 0; j < n; j++)
		if (!isfinite(yA[j]) || !isfinite(yB[j]))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "row %zu of the A or B sample is not finite", j);
	for (size_t k = 0; k < n * d; k++)
		if (!isfinite(yAB[k]))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "row %zu of the A_B sample of input %zu is not finite",
			                      k % n, k / n);

	int rc = 0;
	double *first = malloc(d * sizeof *first);
	double *total = malloc(d * sizeof *total);
	double *boot = NULL;
	size_t *rows = NULL;
	if (first == NULL || total == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for Sobol' indices of %zu inputs", d);
		goto cleanup;
	}
	double V;
	sobol_estimate(first, total, &V, yA, yB, yAB, n, n, d, NULL);
	if (variance_out != NULL)
		*variance_out = V;
	for (size_t i = 0; i < d; i++) {
		out[i].first = first[i];
		out[i].total = total[i];
		out[i].first_se = out[i].total_se = NAN;
		out[i].first_low = out[i].first_high = out[i].total_low = out[i].total_high = NAN;
	}
	if (nboot == 0)
		goto cleanup;

	/* boot[(2 i) nboot + b]: first-order index i of resample b; boot[(2 i + 1) nboot + b]: total */
	boot = malloc(2 * d * nboot * sizeof *boot);
	rows = malloc(n * sizeof *rows);
	if (boot == NULL || rows == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu bootstrap resamples", nboot);
		goto cleanup;
	}
	for (size_t b = 0; b < nboot; b++) {
		if (prsm_cancel_requested(cancel) || (deadline_s > 0.0 && prsm_clock_seconds() > deadline_s)) {
			/* stopped: the indices stand, no error or interval from a partial bootstrap */
			if (boot_done != NULL)
				*boot_done = b;
			goto cleanup;
		}
		for (size_t j = 0; j < n; j++)
			rows[j] = (size_t)gsl_rng_uniform_int(rng, n);
		double Vb;
		sobol_estimate(first, total, &Vb, yA, yB, yAB, n, n, d, rows);
		for (size_t i = 0; i < d; i++) {
			boot[(2 * i) * nboot + b] = first[i];
			boot[(2 * i + 1) * nboot + b] = total[i];
		}
	}
	if (boot_done != NULL)
		*boot_done = nboot;
	for (size_t i = 0; i < d; i++) {
		bootstrap_figures(&out[i].first_se, &out[i].first_low, &out[i].first_high, boot + (2 * i) * nboot, nboot);
		bootstrap_figures(&out[i].total_se, &out[i].total_low, &out[i].total_high, boot + (2 * i + 1) * nboot,
		                  nboot);
	}

cleanup:
	free(rows);
	free(boot);
	free(total);
	free(first);
	return rc;
}

int prsm_sens_sobol_replicated(prsm_sobol_index *out, double *variance_out, const double *yA,
                               const double *yB, const double *yAB, size_t n, size_t d,
                               const size_t *rep_end, size_t R, prsm_error *err)
{
	if (R < 2 || rep_end == NULL || rep_end[R - 1] != n)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "replicated Sobol' indices need R >= 2 replicates "
		                      "covering the n rows");
	for (size_t r = 0; r < R; r++)
		if (rep_end[r] < (r ? rep_end[r - 1] : 0) + 2)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "replicate %zu has fewer than 2 rows", r);
	int rc = prsm_sens_sobol(out, variance_out, yA, yB, yAB, n, d, 0, NULL, err);
	if (rc)
		return rc;
	double *first = malloc(d * sizeof *first), *total = malloc(d * sizeof *total);
	double *rep = malloc(2 * d * R * sizeof *rep); /* rep[(2 i) R + r] first, [(2 i + 1) R + r] total */
	if (!first || !total || !rep) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu Sobol' replicates", R);
		goto cleanup;
	}
	for (size_t r = 0; r < R; r++) {
		/* replicate r's rows lo .. rep_end[r] - 1: its own columns' ranges, in row order */
		const size_t lo = r ? rep_end[r - 1] : 0;
		double V;
		sobol_estimate(first, total, &V, yA + lo, yB + lo, yAB + lo, rep_end[r] - lo, n, d, NULL);
		for (size_t i = 0; i < d; i++) {
			rep[(2 * i) * R + r] = first[i];
			rep[(2 * i + 1) * R + r] = total[i];
		}
	}
	const double t = gsl_cdf_tdist_Pinv(0.975, (double)(R - 1));
	for (size_t i = 0; i < d; i++) {
		double se[2];
		for (int k = 0; k < 2; k++) {
			const double *v = rep + (2 * i + (size_t)k) * R;
			int bad = 0;
			for (size_t r = 0; r < R; r++)
				bad |= isnan(v[r]);
			se[k] = bad ? NAN : gsl_stats_sd(v, 1, R) / sqrt((double)R);
		}
		out[i].first_se = se[0];
		out[i].total_se = se[1];
		out[i].first_low = out[i].first - t * se[0];
		out[i].first_high = out[i].first + t * se[0];
		out[i].total_low = out[i].total - t * se[1];
		out[i].total_high = out[i].total + t * se[1];
	}
cleanup:
	free(first);
	free(total);
	free(rep);
	return rc;
}
