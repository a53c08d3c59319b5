/*
 * sens.h: sensitivity analysis of one Monte Carlo output (DESIGN.md "Documents" -> result).
 *
 * Two families. Regression: standardized regression coefficients (SRC) of the output on the
 * inputs and, for monotone non-linear responses, the same on ranks (SRRC), each with the R^2
 * of its linear fit; with independent inputs and R^2 near 1, SRC_i^2 is input i's share of the
 * output variance ("% contribution" = 100 SRC_i^2). Variance-based: Sobol' first-order and
 * total indices from a Saltelli design (A, B and the d matrices A_B^i), with bootstrap
 * standard errors and percentile intervals.
 *
 * Undefined results are NAN: an output with zero variance has no sensitivity to share out.
 * Both functions allocate their own scratch (they run once per study, not in a sample loop)
 * and free it before returning. Results depend only on the inputs (and, for the bootstrap, on
 * the generator's state), never on timing or threads.
 */
#ifndef PRSM_MC_SENS_H
#define PRSM_MC_SENS_H

#include <gsl/gsl_rng.h>
#include <stddef.h>

#include "util/cancel.h"
#include "util/error.h"

/* Standardized regression coefficients of y on the columns of x (n rows x d columns,
 * row-major), by least squares (gsl_multifit_linear, no intercept needed) on data centred and
 * scaled by their sample sd, and the fit's R^2 = 1 - SS_res / SS_tot.
 * ranks != 0: the same on ranks (SRRC; average ranks for ties) with its own R^2.
 * Columns with zero variance get coefficient 0 and are flagged in constant[] (may be NULL).
 * y with zero variance: every coefficient and *r2 are NAN (returns 0).
 * Needs n >= d + 2 and finite x, y (else PRSM_EINVAL); PRSM_ENOMEM when scratch allocation
 * fails. Allocates its own scratch (called once per study, not in a sample loop); frees it
 * before returning. */
int prsm_sens_src(double *coef /* d entries */, double *r2, int *constant /* d entries or NULL */,
                  const double *x, size_t n, size_t d, const double *y, int ranks, prsm_error *err);

/* Sobol' indices of one input with bootstrap errors. */
typedef struct {
	double first, total;                  /* indices */
	double first_se, total_se;            /* bootstrap standard errors (sd over resamples) */
	double first_low, first_high, total_low, total_high; /* 95 % percentile bootstrap intervals */
} prsm_sobol_index;

/* Sobol' first-order and total indices from a Saltelli design: yA[n] = f(A), yB[n] = f(B),
 * yAB[i*n + j] = f(A with column i taken from B), i < d, j < n.
 * First order: Saltelli et al. 2010, V_i = mean_j((yB_j - f0)(yAB_ij - yA_j)), where centring
 * yB on f0 = mean of yA and yB changes nothing in expectation but makes the estimate
 * independent of the output's offset (an output of 20 mm +- 1 um would otherwise drown in
 * noise); total: Jansen 1999, VT_i = mean_j((yA_j - yAB_ij)^2) / 2; both divided by
 * V = variance (divisor 2n - 1) of the 2n values yA and yB, returned in *variance_out (may be
 * NULL).
 * Bootstrap: nboot resamples of the rows j (n draws with replacement by gsl_rng_uniform_int on
 * rng), each recomputing f0, V and every index; *_se is the sd of the resampled indices and
 * the interval their 2.5 % and 97.5 % quantiles (type 7). nboot = 0 skips it (errors and
 * intervals NAN; rng may then be NULL); nboot = 1 is refused.
 * V = 0: every index NAN (returns 0). Needs n >= 2 and finite values (else PRSM_EINVAL);
 * PRSM_ENOMEM when scratch allocation fails. Allocates its own scratch and frees it before
 * returning. */
int prsm_sens_sobol(prsm_sobol_index *out /* d entries */, double *variance_out, const double *yA,
                    const double *yB, const double *yAB, size_t n, size_t d, size_t nboot,
                    gsl_rng *rng, prsm_error *err);

/* prsm_sens_sobol that also stops resampling when cancel is raised or the monotonic clock
 * (util/clock.h, s) passes deadline_s (0: none), checked before every resample: the indices are
 * computed, the errors and intervals stay NAN, and *boot_done (may be NULL) says how many
 * resamples ran (nboot when none was stopped). */
int prsm_sens_sobol_until(prsm_sobol_index *out, double *variance_out, const double *yA, const double *yB,
                          const double *yAB, size_t n, size_t d, size_t nboot, gsl_rng *rng,
                          const prsm_cancel_flag *cancel, double deadline_s, size_t *boot_done,
                          prsm_error *err);

/* Sobol' indices from R independent randomised-QMC replicates of a Saltelli design (each its own
 * scrambled Sobol' sequence), stored one after the other: replicate r has rows
 * [rep_end[r - 1], rep_end[r]) (rep_end[-1] = 0, rep_end[R - 1] = n). The indices are those of
 * the pooled rows (as prsm_sens_sobol gives them); their standard errors the sd of the R
 * replicates' own estimates over sqrt R, and the 95 % intervals index +- t(0.975, R - 1) se
 * (Owen's replicated randomised QMC: valid intervals where a bootstrap of a low-discrepancy
 * sample is far too wide, since resampling its rows destroys the very balance that makes it
 * accurate). Needs R >= 2 and at least 2 rows in each replicate (else PRSM_EINVAL), finite
 * values; PRSM_ENOMEM. Scratch is allocated and freed here. */
int prsm_sens_sobol_replicated(prsm_sobol_index *out /* d entries */, double *variance_out,
                               const double *yA, const double *yB, const double *yAB, size_t n,
                               size_t d, const size_t *rep_end, size_t R, prsm_error *err);

#endif
