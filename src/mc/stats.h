/*
 * stats.h: the summary of one Monte Carlo output (DESIGN.md "Documents" -> result): moments,
 * quantiles, histogram, standard errors, yield against spec limits with a Wilson interval, ppm
 * out of spec (empirical and from the fitted normal), Cp and Cpk.
 *
 * Everything here is deterministic: a summary depends only on the values in their order, and
 * the same array always gives a bit-identical summary. Running moments (Welford's update,
 * Chan et al.'s pairwise merge) let blocks of samples be combined in block order. Nothing here
 * allocates; the caller passes the scratch space.
 *
 * Conventions. Undefined figures are NAN (an sd of zero makes skewness, kurtosis, Cp and Cpk
 * undefined; with no spec every spec figure is NAN). A value exactly on a spec limit is in
 * spec. Spec limits are in the unit of the output.
 */
#ifndef PRSM_MC_STATS_H
#define PRSM_MC_STATS_H

#include <stddef.h>

#include "util/error.h"

/* Spec limits of an output, same unit as the output. A side is used only when has_* != 0. */
typedef struct {
	int has_lower, has_upper;
	double lower, upper;
} prsm_spec;

/* Running mean and sum of squared deviations from the mean (Welford). */
typedef struct {
	size_t n;
	double mean, m2;
} prsm_moments;

#define PRSM_MOMENTS_INIT {0, 0.0, 0.0}

void prsm_moments_init(prsm_moments *m);

/* Add one value (Welford's update). */
void prsm_moments_add(prsm_moments *m, double x);

/* Merge other into into (Chan, Golub & LeVeque 1979 pairwise formulas); either may be empty.
 * Merging the blocks of a sample in a fixed order gives a fixed result. */
void prsm_moments_merge(prsm_moments *into, const prsm_moments *other);

/* Sample standard deviation (divisor n - 1); NAN when n < 2. */
double prsm_moments_sd(const prsm_moments *m);

/* Quantile probabilities: 0.135 %, 1, 5, 50, 95, 99, 99.865 % (the +-3 sigma tails). */
#define PRSM_STATS_QUANTILES 7
extern const double prsm_stats_quantile_p[PRSM_STATS_QUANTILES];

#define PRSM_STATS_HIST_BINS 40

/* Anderson-Darling p-value below which the normal fit is rejected (its ppm withheld). */
#define PRSM_STATS_NORMAL_P_MIN 0.01
/* Tail samples (5 % of n) a tail fit needs. */
#define PRSM_STATS_TAIL_MIN 50

/* z of the two-sided 95 % normal interval, Phi^-1(0.975). */
#define PRSM_STATS_Z95 1.959963984540054

typedef struct {
	size_t n;                 /* sample count */
	double mean, sd;          /* sd: sample sd, divisor n - 1 */
	double skewness;          /* GSL's: (1/n) sum ((y - mean)/sd)^3; NAN when sd = 0 */
	double kurtosis_excess;   /* GSL's: (1/n) sum ((y - mean)/sd)^4 - 3; NAN when sd = 0 */
	double min, max;
	double quantile[PRSM_STATS_QUANTILES]; /* at prsm_stats_quantile_p: type-7 linear
	                                         interpolation of the sorted sample */
	/* Histogram: PRSM_STATS_HIST_BINS equal bins over [hist_lower, hist_upper] = [min, max]; bin
	 * k holds hist_lower + k w <= y < hist_lower + (k + 1) w, the last bin also holds max. When
	 * all values are equal the range is widened to [v - h, v + h], h = 1e-6 max(|v|, 1), so the
	 * bin width stays > 0. */
	double hist_lower, hist_upper;
	size_t hist_count[PRSM_STATS_HIST_BINS];
	/* Standard errors, all asymptotic and distribution-free (none assumes a normal output):
	 * se_mean = sd / sqrt(n);
	 * se_sd from Var(s^2) = s^4 (kurtosis_excess / n + 2 / (n - 1)), se_sd = se(s^2) / (2 sd)
	 *   (reduces to the normal-theory sd / sqrt(2 (n - 1)) when kurtosis_excess = 0);
	 * se_quantile_median = (y_(n-c+1) - y_(c)) / (2 z), c = round((n + 1)/2 - z sqrt(n)/2),
	 *   z = PRSM_STATS_Z95 (McKean & Schrader 1984: the order-statistic interval of the median
	 *   read as +-z SE). */
	double se_mean, se_sd, se_quantile_median;
	int has_spec;             /* a spec with at least one side was given */
	/* Fraction in spec, its Wilson 95 % score interval (z = PRSM_STATS_Z95) and its binomial
	 * (Wald) standard error sqrt(yield (1 - yield) / n). */
	double yield, yield_low95, yield_high95, se_yield;
	double ppm_low, ppm_high;               /* samples below lower / above upper, per million
	                                           (0 for a side without a limit) */
	double ppm_low_normal, ppm_high_normal; /* 1e6 Phi((L - mean)/sd), 1e6 Q((U - mean)/sd) of the
	                                           fitted normal (sd = 0: the point mass at mean);
	                                           not to be trusted when normal_rejected (the
	                                           result document then withholds them) */
	/* The normal fit tested: Anderson-Darling A*^2 = A^2 (1 + 0.75/n + 2.25/n^2) with the mean
	 * and sd estimated, its p-value (D'Agostino & Stephens 1986, Table 4.9); rejected at
	 * p < PRSM_STATS_NORMAL_P_MIN (NAN and 0 for n < 8 or sd = 0). */
	double normal_ad, normal_ad_p;
	int normal_rejected;
	/* Tail fits that assume no shape: a generalised Pareto distribution fitted by probability-
	 * weighted moments (Hosking & Wallis 1987) to the excesses over the 5 % / 95 % quantile,
	 * P(beyond a limit) = (k/n) (1 + xi x / sigma)^(-1/xi); per million. A limit inside the
	 * threshold takes the counted figure. NAN without a spec on that side or with fewer than
	 * PRSM_STATS_TAIL_MIN tail samples. */
	double ppm_low_tail, ppm_high_tail;
	/* Cp = (U - L)/(6 sd) (NAN for a one-sided spec); Cpk = min over the given sides of
	 * (U - mean)/(3 sd), (mean - L)/(3 sd); se_cpk = sqrt(1/(9 n) + Cpk^2 / (2 (n - 1)))
	 * (Bissell 1990). All NAN when sd = 0. */
	double cp, cpk, se_cpk;
} prsm_stats_summary;

/* Summarise y[0..n): n >= 2, every value finite (else PRSM_EINVAL). scratch: n doubles the
 * function overwrites (it sorts a copy of y there); it may not alias y. spec may be NULL (no
 * spec); a spec with both sides needs lower <= upper and finite limits. Returns 0 or a
 * negative PRSM_E* code with err filled. */
int prsm_stats_summarise(prsm_stats_summary *out, const double *y, size_t n, const prsm_spec *spec,
                         double *scratch, prsm_error *err);

/* Wilson score interval for k successes out of n trials (k <= n) at normal quantile z > 0:
 * the p with (k/n - p)^2 = z^2 p (1 - p) / n. n = 0 gives [0, 1]; k = 0 gives low = 0 and
 * k = n gives high = 1 exactly. */
void prsm_stats_wilson(size_t k, size_t n, double z, double *low, double *high);

#endif
