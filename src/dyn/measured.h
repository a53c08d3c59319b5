/*
 * measured.h: measured data of one screw on a test bench (MODEL-DYNAMICS.md §8.5, seeds 001 and
 * 004) and what the model layer does with it before any calibration: the TE curve checked
 * (finite, strictly increasing screw angle, at least four screw revolutions, at most
 * PRSM_MEAS_POINTS_MAX points), its travel and angle completed from each other with the lead,
 * the comparison with a model curve (§8.5 item 1: measured - model, with the offset of the
 * measurement's zero removed) and the identification by spectrum (§8.5 item 2: the record
 * detrended by its least-squares line on travel, whose slope is the lead deviation in
 * um/300 mm, Hann window, FFT over the whole record, the largest amplitude within +-2
 * resolution bins of every named order).
 *
 * Pure C, no JSON, CSV or I/O: the readers in io/measured*.c fill these structs and map a
 * failing sample's index back to its CSV line or JSON pointer.
 *
 * Units: every member names its unit (rad, mm, um); ratios and efficiencies are dimensionless.
 * Ownership: prsm_meas_curve_alloc allocates the three arrays of a curve, prsm_meas_curve_free
 * releases them; prsm_meas_spectrum_compute allocates the spectrum arrays it returns
 * (prsm_meas_spectrum_free).
 */
#ifndef PRSM_DYN_MEASURED_H
#define PRSM_DYN_MEASURED_H

#include <stddef.h>

#include "util/error.h"

/* Most points of a measured TE curve (a bigger record is refused with a message, never read
 * whole: decimate it, a TE curve needs no more than a few hundred points per revolution). */
#define PRSM_MEAS_POINTS_MAX 200000
/* Fewest screw revolutions a TE record must cover (§8.5: "at least four screw revolutions"). */
#define PRSM_MEAS_REVOLUTIONS_MIN 4.0
/* Largest relative difference between a given travel and L theta / 2 pi (both columns given). */
#define PRSM_MEAS_TRAVEL_TOLERANCE 1e-3

/* A measured TE curve: n samples, screw angle strictly increasing. */
typedef struct {
	size_t n;
	double *angle_rad;            /* screw angle theta_i from the record's start, rad */
	double *travel_mm;            /* nominal nut travel s_i = L theta_i / 2 pi, mm */
	double *te_um;                /* transmission error (nut position error), um */
	int has_angle, has_travel;    /* which of the two the source gave (the other is computed) */
} prsm_meas_curve;

/* Everything a `measured` section may hold (NaN: not measured). */
typedef struct {
	int has_te;                   /* a TE curve was given */
	prsm_meas_curve te;
	double te_noise_sd_um;        /* measurement noise sigma of the TE, um; NaN: unknown (the fit's s) */
	double cage_ratio;            /* measured cage (carrier) to screw speed ratio, - */
	double cage_ratio_sd;         /* its standard uncertainty, -; NaN: none stated */
	double cage_axial_load_N;     /* load of the cage measurement, N; NaN: the design's */
	double cage_screw_speed_rad_s;/* screw speed of the cage measurement, rad/s; NaN: the design's */
	double efficiency;            /* measured direct efficiency, - */
	double efficiency_sd;         /* its standard uncertainty, -; NaN: none stated */
	double efficiency_axial_load_N;       /* load of the efficiency test, N; NaN: the design's */
	double efficiency_screw_speed_rad_s;  /* screw speed of the test, rad/s; NaN: the design's */
} prsm_meas_data;

/* Set every member to "not measured" (NaN, no curve). Returns 0. */
int prsm_meas_data_init(prsm_meas_data *m);
/* Release the curve of m (and reset it). */
void prsm_meas_data_free(prsm_meas_data *m);

/* Allocate a curve of n points (zeroed). Returns 0, PRSM_EINVAL (n > PRSM_MEAS_POINTS_MAX) or
 * PRSM_ENOMEM. */
int prsm_meas_curve_alloc(prsm_meas_curve *c, size_t n, prsm_error *err);
void prsm_meas_curve_free(prsm_meas_curve *c);

/* What a check found wrong, and at which sample (prsm_meas_curve_check). */
enum {
	PRSM_MEAS_OK = 0,
	PRSM_MEAS_NOT_FINITE = 1,     /* a value is NaN or infinite (column: which array) */
	PRSM_MEAS_NOT_INCREASING = 2, /* angle (or travel) not strictly increasing at this sample */
	PRSM_MEAS_TOO_SHORT = 3,      /* fewer than PRSM_MEAS_REVOLUTIONS_MIN revolutions (index: last) */
	PRSM_MEAS_TOO_FEW = 4,        /* fewer than 8 points */
	PRSM_MEAS_TOO_MANY = 5,       /* more than PRSM_MEAS_POINTS_MAX */
	PRSM_MEAS_TRAVEL_MISMATCH = 6 /* travel and angle disagree with the lead at this sample */
};
enum { PRSM_MEAS_COL_ANGLE = 0, PRSM_MEAS_COL_TRAVEL = 1, PRSM_MEAS_COL_TE = 2 };

typedef struct {
	int what;                     /* PRSM_MEAS_* */
	size_t index;                 /* the offending sample */
	int column;                   /* PRSM_MEAS_COL_* of the offending value */
	double revolutions;           /* TOO_SHORT: what the record covers */
} prsm_meas_problem;

/*
 * Complete and check a curve for a screw of lead lead_mm (> 0): the missing one of angle and
 * travel from the other (theta = 2 pi s / L), then every value finite, the angle strictly
 * increasing, travel and angle agreeing within PRSM_MEAS_TRAVEL_TOLERANCE when both were
 * given, at least 8 points and PRSM_MEAS_REVOLUTIONS_MIN revolutions. Returns 0, or PRSM_EINVAL
 * with *problem saying what and where and err a message without the place (the reader adds
 * the line and column, or the JSON pointer).
 */
int prsm_meas_curve_complete(prsm_meas_curve *c, double lead_mm, prsm_meas_problem *problem, prsm_error *err);

/* Screw revolutions the curve covers, (theta_{n-1} - theta_0) / 2 pi. */
double prsm_meas_revolutions(const prsm_meas_curve *c);

/* Least-squares line te ~ a + b s on travel: a (um), b (um per mm). */
void prsm_meas_fit_line(double *a_um, double *b_um_per_mm, const prsm_meas_curve *c);

/* Lag-1 autocorrelation of x[0..n) about its mean, -. */
double prsm_meas_lag1(const double *x, size_t n);

/* ---- §8.5 item 1: comparison -------------------------------------------------------------- */

typedef struct {
	double offset_um;             /* mean of measured - model (the zero point of the record), um */
	double rms_um;                /* RMS of measured - model - offset, um */
	double peak_to_peak_um;       /* its peak to peak, um */
	double max_abs_um;            /* its largest magnitude, um */
	double lead_deviation_um_per_300mm; /* slope of measured - model on travel, um per 300 mm */
	double measured_rms_um;       /* RMS of the measured TE about its mean, um */
	double model_rms_um;          /* RMS of the model TE about its mean, um */
	double z_rms;                 /* rms_um / noise sigma (NaN when the noise is unknown), - */
} prsm_meas_comparison;

/* Compare measured te_um with model_um (same n samples); noise_sd_um NaN: unknown. residual_um
 * (n values, may be NULL) gets measured - model - offset. */
void prsm_meas_compare(prsm_meas_comparison *out, const prsm_meas_curve *c, const double *model_um,
                       double noise_sd_um, double *residual_um);

/* z-score (measured - model) / sd; NaN when sd is not positive and finite. */
double prsm_meas_z(double measured, double model, double sd);

/* ---- §8.5 item 2: identification by spectrum --------------------------------------------- */

#define PRSM_MEAS_ORDERS_MAX 16

typedef struct {
	double lead_deviation_um_per_300mm; /* slope of the least-squares line on travel x 300, um/300 mm */
	double line_offset_um;        /* its value at travel 0, um */
	double revolutions;           /* record length, screw revolutions */
	double resolution_per_rev;    /* 1 / revolutions, cycles per screw revolution */
	double samples_per_rev;       /* mean sampling rate, samples per revolution */
	int resampled;                /* 1: the angles were not equally spaced; the spectrum is of the
	                                 record interpolated linearly onto an equal grid */
	/* the one-sided amplitude spectrum (Hann, zero padded): bin b at b * step, a pure sine of
	 * amplitude A inside the record reads A at its order */
	size_t bins;
	double step_per_rev;          /* bin spacing, cycles per screw revolution */
	double *amplitude_um;         /* bins values */
	/* the named orders asked for, and what was found within +-2 resolutions of each */
	int orders;
	double order_per_rev[PRSM_MEAS_ORDERS_MAX];      /* the named order, cycles per revolution */
	double found_order_per_rev[PRSM_MEAS_ORDERS_MAX];/* where the largest amplitude near it is */
	double found_amplitude_um[PRSM_MEAS_ORDERS_MAX]; /* that amplitude, um */
	int above_nyquist[PRSM_MEAS_ORDERS_MAX];         /* 1: the order is not below the Nyquist order */
} prsm_meas_spectrum;

/* The identification of §8.5 item 2 for the named orders (n_orders <= PRSM_MEAS_ORDERS_MAX).
 * Allocates out->amplitude_um (prsm_meas_spectrum_free). Returns 0, PRSM_EINVAL or PRSM_ENOMEM. */
int prsm_meas_spectrum_compute(prsm_meas_spectrum *out, const prsm_meas_curve *c, const double *orders_per_rev,
                               int n_orders, prsm_error *err);
void prsm_meas_spectrum_free(prsm_meas_spectrum *s);

#endif
