/*
 * calib.h: calibration of the model against measured data (MODEL-DYNAMICS.md §8.5 items 3 and 4):
 *
 *  - the LINE MODEL of a measured TE curve,
 *        TE(theta) = c_0 + c_1 s / 300 + sum_l (a_l cos nu_l(k) theta + b_l sin nu_l(k) theta),
 *    s the travel in mm, nu_l(k) = alpha_l + beta_l k the named orders of §8.5 item 2 (cycles per
 *    screw revolution) and the carrier ratio k the one nonlinear parameter; solved by variable
 *    projection: the profile S(k) (the linear parameters by least squares, Householder QR) on a
 *    grid over the prior +- the half width, a bounded 1-D refinement of S(k) by NLopt (LN_BOBYQA
 *    or LN_COBYLA), then a Gauss-Newton polish of every parameter with the analytic Jacobian;
 *  - the PHYSICAL MODEL: chosen error fields of a prsm_errors (run-outs with or without their
 *    phases, lead errors, pin errors, ...), TE from the statics assembly model (MODEL.md §4,
 *    model/assembly.h) at the measured angles plus an offset (and a slope unless a lead error
 *    is fitted), by NLopt LN_BOBYQA from the given start, then Gauss-Newton with central
 *    differences (step 1e-3 of each parameter's scale); a run-out fitted with its phase is
 *    solved in Cartesian components (x, y) = e (cos phi, sin phi), where the TE is nearly
 *    linear, and reported back as magnitude and phase by the delta method;
 *  - uncertainty (§8.5): Cov = s^2 (J^T J)^-1, s^2 = S / (N - p), standard errors, the
 *    correlation matrix, the condition number of J^T J (raw and with unit-norm columns), the
 *    lag-1 autocorrelation r_1 of the residuals and the inflation sqrt((1 + r_1)/(1 - r_1)) of
 *    every standard error when r_1 > 0.2; amplitudes A = sqrt(a^2 + b^2) and phases
 *    theta = atan2(b, a) (a cos + b sin = A cos(nu theta - theta)) with delta-method errors;
 *  - the identifiability caveats of §8.5, each with whether this fit triggers it;
 *  - friction from a measured efficiency (§8.5 item 4): the root of eta_model(mu) = eta_meas
 *    (bracketed, Brent) with the statics engine's efficiency and losses at the test's load and
 *    speed, its standard error through d eta / d mu; and the carrier drag c_C that explains a
 *    measured cage ratio below k* (root of the settled ratio of the rigid model, dyn.h).
 *
 * Pure C (GSL, NLopt), no JSON. Units: SI or as named (um, mm, rad); the line model's
 * parameters in um (c_0, a_l, b_l), um per 300 mm (c_1) and - (k). A physical field's values
 * are in the unit the caller names (`scale` converts to the engine's mm, rad or mm/mm).
 * Ownership: nothing here keeps memory beyond a call except the results' residual arrays
 * (prsm_calib_*_free).
 */
#ifndef PRSM_DYN_CALIB_H
#define PRSM_DYN_CALIB_H

#include <stddef.h>

#include "dyn/dyn.h"
#include "dyn/measured.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/design.h"
#include "model/errors.h"
#include "util/error.h"

/* The named orders of §8.5 item 2, nu = alpha + beta k. */
enum {
	PRSM_CALIB_LINE_SCREW_REV = 0,         /* 1: screw lead wobble, screw tilt with run-out */
	PRSM_CALIB_LINE_SCREW = 1,             /* 1 - k */
	PRSM_CALIB_LINE_CARRIER = 2,           /* k: nut- and carrier-fixed errors */
	PRSM_CALIB_LINE_ROLLER_SPIN = 3,       /* i_g k: roller run-out and profile */
	PRSM_CALIB_LINE_ROLLER_PASS_NUT = 4,   /* Z k */
	PRSM_CALIB_LINE_ROLLER_PASS_SCREW = 5, /* Z (1 - k) */
	PRSM_CALIB_LINE_MESH = 6               /* z_2 k */
};
#define PRSM_CALIB_LINE_KINDS 7
/* the default set: every named order of MODEL-DYNAMICS §8.5 item 2, the line model's orders
 * (§8.5 item 3); the mesh line only when z_2 is known, each line only below the record's
 * Nyquist order at the prior */
#define PRSM_CALIB_LINES_DEFAULT 0x7f
#define PRSM_CALIB_PARAMS_MAX (3 + 2 * PRSM_CALIB_LINE_KINDS)
#define PRSM_CALIB_FIELDS_MAX 16
#define PRSM_CALIB_CAVEATS_MAX 8
#define PRSM_CALIB_NAME_MAX 64

/* The line names of §8.5 ("screw_rev", "screw", "carrier", "roller_spin", "roller_pass_nut",
 * "roller_pass_screw", "mesh"). */
const char *prsm_calib_line_name(int kind);

/* The kinematics the orders follow from. */
typedef struct {
	double ring_gear_ratio;      /* i_g = r_n / r_r, - */
	int rollers;                 /* Z */
	int ring_gear_teeth;         /* z_2 (0: unknown; the mesh line is then refused) */
} prsm_calib_kinematics;

/* nu_l = alpha + beta k, cycles per screw revolution. */
void prsm_calib_order_coefficients(double *alpha, double *beta, int kind, const prsm_calib_kinematics *kin);

/* Options of a calibration (the request's dynamics.calibrate, docs/measured-data.md). */
enum { PRSM_CALIB_MODEL_LINE = 0, PRSM_CALIB_MODEL_PHYSICAL = 1 };
enum { PRSM_CALIB_REFINE_BOBYQA = 0, PRSM_CALIB_REFINE_COBYLA = 1 };

typedef struct {
	int model;                   /* PRSM_CALIB_MODEL_* (LINE) */
	int lines_mask;              /* bit l: line kind l in the line model (PRSM_CALIB_LINES_DEFAULT) */
	double carrier_ratio_prior;  /* centre of the grid on k, -; NaN: k* of the design (§8.1) */
	double grid_half_width;      /* the grid covers the prior +- this, - (0.025) */
	int grid_points;             /* (2001) */
	int refine;                  /* PRSM_CALIB_REFINE_* (BOBYQA) */
	double autocorrelation_limit;/* inflate the errors when r_1 exceeds this, - (0.2) */
	int fields;                  /* physical model: the parameters (names resolved by the caller) */
	char field_names[PRSM_CALIB_FIELDS_MAX][PRSM_CALIB_NAME_MAX];
	int mode;                    /* physical model: PRSM_MODE_LINEAR or PRSM_MODE_EXACT (LINEAR) */
	double measuring_load_N;     /* physical model and comparison: TE measuring load, N (50) */
	int max_evaluations;         /* physical model: NLopt evaluations of S (2000) */
} prsm_calib_options;

/* Set the defaults above. Returns 0. */
int prsm_calib_options_init(prsm_calib_options *o);

/* One identifiability caveat of §8.5. */
enum {
	PRSM_CALIB_CAVEAT_RESOLUTION = 0,      /* two lines closer than 1 / N_rev */
	PRSM_CALIB_CAVEAT_SLOPE_LOW_ORDER = 1, /* slope and a low-order line correlated (short stroke) */
	PRSM_CALIB_CAVEAT_SCREW_RUNOUT = 2,    /* a screw run-out's first harmonic cancels: invisible in TE */
	PRSM_CALIB_CAVEAT_SAME_PART_ORDER = 3, /* errors of one part at one order are one parameter */
	PRSM_CALIB_CAVEAT_ROLLER_SUM = 4,      /* roller errors at the spin order add as one vector */
	PRSM_CALIB_CAVEAT_CORRELATED_RESIDUALS = 5 /* r_1 > limit: errors inflated */
};
#define PRSM_CALIB_CAVEAT_KINDS 6

typedef struct {
	int code;                    /* PRSM_CALIB_CAVEAT_* */
	int triggered;               /* 1: this fit shows it (the message says where) */
	char message[320];
} prsm_calib_caveat;

/* What every fit reports (§8.5 "Uncertainty"). */
typedef struct {
	int params;                  /* p */
	size_t points;               /* N */
	char name[PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX][PRSM_CALIB_NAME_MAX];
	char unit[PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX][16];
	double estimate[PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX];
	double standard_error[PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX];       /* inflated when r_1 > limit */
	double standard_error_white[PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX]; /* s^2 (J^T J)^-1 alone */
	double correlation[(PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX) * (PRSM_CALIB_PARAMS_MAX + PRSM_CALIB_FIELDS_MAX)];
	double sum_of_squares_um2;   /* S at the estimate, um^2 */
	double residual_sd_um;       /* s = sqrt(S / (N - p)), um */
	double condition_number;     /* of J^T J in the parameters' units */
	double condition_number_scaled; /* of J^T J with unit-norm columns (the correlation's) */
	double lag1_autocorrelation; /* r_1 of the residuals in sample order, - */
	double inflation;            /* the factor applied to the standard errors (1: none), - */
	int gauss_newton_iterations;
	int converged;               /* 1: the Gauss-Newton step fell below 1e-10 of every scale */
	int caveats;
	prsm_calib_caveat caveat[PRSM_CALIB_CAVEATS_MAX];
	double *residual_um;         /* N residuals measured - model (allocated) */
} prsm_calib_fit;

void prsm_calib_fit_free(prsm_calib_fit *f);

/* ---- the line model ---- */

typedef struct {
	prsm_calib_fit fit;          /* parameters: c0_um, c1_um_per_300mm, then a_<line>_um, b_<line>_um
	                                per line, then carrier_ratio */
	int lines;                   /* L */
	int kind[PRSM_CALIB_LINE_KINDS];
	double alpha[PRSM_CALIB_LINE_KINDS], beta[PRSM_CALIB_LINE_KINDS];
	double order_per_rev[PRSM_CALIB_LINE_KINDS];   /* nu_l at the estimate of k */
	double amplitude_um[PRSM_CALIB_LINE_KINDS], amplitude_se_um[PRSM_CALIB_LINE_KINDS];
	double phase_rad[PRSM_CALIB_LINE_KINDS], phase_se_rad[PRSM_CALIB_LINE_KINDS];
	int dropped;                 /* lines asked for but not fitted (at or above the Nyquist order, or
	                                the same order as another) */
	int dropped_kind[PRSM_CALIB_LINE_KINDS];
	double carrier_ratio, carrier_ratio_se; /* k and its standard error */
	double carrier_ratio_prior;  /* the grid's centre */
	double grid_from, grid_to;   /* the grid on k */
	int grid_points;
	double grid_best_k;          /* the grid's minimum */
	double grid_best_S_um2;
	int grid_local_minima;       /* interior local minima of S(k) on the grid (side minima: aliases) */
	double refined_k;            /* after the 1-D refinement */
	int refine_evaluations;
	int refine_used;             /* PRSM_CALIB_REFINE_* that ran (BOBYQA hands over to COBYLA when it refuses) */
	double revolutions, resolution_per_rev;
} prsm_calib_line_result;

/* Residual-free model value of the line model at one point: p as in prsm_calib_line_result.fit
 * (c0, c1, a_1, b_1, .., a_L, b_L, k), lines with coefficients alpha, beta; grad (p values, may be
 * NULL) gets the analytic derivatives. */
double prsm_calib_line_value(const double *p, int lines, const double *alpha, const double *beta, double theta_rad,
                             double travel_mm, double *grad);

/* Calibrate the line model on curve c (completed and checked). Returns 0, PRSM_EINVAL (no line
 * below the Nyquist order, fewer points than parameters + 2, a mesh line without z_2),
 * PRSM_ENOCONVERGE, PRSM_ENOMEM. out->fit.residual_um is allocated (prsm_calib_line_free). */
int prsm_calib_line(prsm_calib_line_result *out, const prsm_meas_curve *c, const prsm_calib_kinematics *kin,
                    const prsm_calib_options *o, prsm_error *err);
void prsm_calib_line_free(prsm_calib_line_result *r);

/* ---- the physical model ---- */

enum { PRSM_CALIB_PART_SCREW = 0, PRSM_CALIB_PART_NUT = 1, PRSM_CALIB_PART_CARRIER = 2, PRSM_CALIB_PART_ROLLER = 3 };

/* One error field to calibrate, in the caller's unit. */
typedef struct {
	char name[PRSM_CALIB_NAME_MAX]; /* as the request names it, e.g. "nut.runout_um" */
	char unit[16];               /* "um", "mrad", "deg", "um/300mm" */
	int part;                    /* PRSM_CALIB_PART_* */
	int roller;                  /* PART_ROLLER: the roller */
	size_t offset;               /* of the double in prsm_body_errors, prsm_carrier_errors or prsm_roller_errors */
	double scale;                /* caller's unit per engine unit (um per mm: 1000) */
	double limit;                /* |value| <= limit in the caller's unit */
	int magnitude;               /* 1: a radial magnitude >= 0 with a phase at phase_offset */
	size_t phase_offset;
	int phase;                   /* 1: a phase itself */
	int lead;                    /* 1: a cumulative lead error (the slope then is this, not a nuisance) */
} prsm_calib_field;

typedef struct {
	prsm_calib_fit fit;          /* parameters: the fields in their units, then offset_um (and
	                                slope_um_per_300mm when no lead error is fitted) */
	int fields;
	double start[PRSM_CALIB_FIELDS_MAX];          /* the start values, the fields' units */
	double sensitivity_um[PRSM_CALIB_FIELDS_MAX]; /* RMS of d TE / d field over the record at the
	                                 estimate, um per unit */
	double first_order_um[PRSM_CALIB_FIELDS_MAX]; /* the same at the field = 0 (the other fields as
	                                 estimated; a phase: its magnitude's): the first-order effect,
	                                 0 for a run-out whose first harmonic cancels (MODEL §4) */
	int evaluations;             /* TE curves computed */
	int optimizer_status;        /* NLopt's return code */
} prsm_calib_physical_result;

/* The statics TE (MODEL.md §4: u(theta) - u(theta_0) at load F_N, "+" direction) of error set
 * e at the n angles theta_rad, um, as a measurement gives it: the nut's position error along its
 * forward travel, -hand (u - u_0), whose slope on the travel is the statics report's lead
 * deviation. as prepared by prsm_assembly_init; gaps is a
 * caller's scratch (64 kB). Returns 0, or PRSM_ENOCONVERGE when an elastic solve failed. */
int prsm_calib_statics_te(double *te_um, const prsm_assembly *as, const prsm_errors *e, const double *theta_rad,
                          size_t n, int mode, double F_N, prsm_assembly_gaps *gaps);

/* Calibrate the fields (their start values read from base, the other errors kept as base has
 * them) on curve c. Returns 0, PRSM_EINVAL, PRSM_ENOCONVERGE, PRSM_ENOMEM. estimate holds the
 * calibrated error set when not NULL. */
int prsm_calib_physical(prsm_calib_physical_result *out, prsm_errors *estimate, const prsm_meas_curve *c,
                        const prsm_assembly *as, const prsm_errors *base, const prsm_calib_field *fields, int n_fields,
                        const prsm_calib_options *o, prsm_error *err);
void prsm_calib_physical_free(prsm_calib_physical_result *r);

/* A field's value in e, in the field's unit, and setting it. */
double prsm_calib_field_get(const prsm_errors *e, const prsm_calib_field *f);
void prsm_calib_field_set(prsm_errors *e, const prsm_calib_field *f, double value);

/* ---- §8.5 item 4 ---- */

typedef struct {
	double efficiency;           /* measured, - */
	double efficiency_sd;        /* -, NaN: none */
	double axial_load_N, screw_speed_rad_s; /* the test's */
	double efficiency_model;     /* the statics engine's at the design's mu, - */
	double mu_design;            /* the design's mu_screw_roller */
	double z;                    /* (measured - model) / sd, - */
	int found;                   /* 1: a mu in [0, 0.5] gives the measured efficiency */
	double mu;                   /* the root, - */
	double mu_se;                /* sd / |d eta / d mu|, - (NaN without sd) */
	double deta_dmu;             /* at the root, - */
	double mu_sliding_only;      /* (1 - eta) / (1 + eta): sliding alone at beta = 45 deg, - */
	/* the losses assumed, at the root: on or off, and the torque split, N m */
	int spin, gear;
	double input_torque_Nm, ideal_torque_Nm, sliding_torque_Nm, spin_torque_Nm, gear_torque_Nm,
	    drag_torque_Nm, seal_torque_Nm;
	int evaluations;
} prsm_calib_friction;

/* Friction from a measured efficiency on design d (resolved and checked; its nominal analysis is
 * re-run at each mu). Returns 0 (found 0 when no mu gives it: the message in err), PRSM_EINVAL,
 * PRSM_ENOCONVERGE. */
int prsm_calib_friction_compute(prsm_calib_friction *out, const prsm_design *d, double efficiency,
                                double efficiency_sd, double axial_load_N, double screw_speed_rad_s, prsm_error *err);

typedef struct {
	double ratio, ratio_sd;      /* measured cage to screw speed ratio and its uncertainty, - */
	double axial_load_N, screw_speed_rad_s; /* of the measurement */
	double k_star;               /* the minimum-slip ratio of the rigid model (§8.1), - */
	double k_statics;            /* the statics engine's contact-radius ratio, - */
	double z_k_star, z_statics;  /* z-scores against both, - */
	int above_k_star;            /* 1: the measured ratio is above k*: no drag explains it (flagged) */
	int drag_found;              /* 1: c_C found */
	double carrier_drag_Nm_s_per_rad;    /* c_C whose settled ratio is the measured one, N m s/rad */
	double carrier_drag_se_Nm_s_per_rad; /* sd / |d k / d c_C| */
	double dk_dcC;               /* at the root, per (N m s/rad) */
	int evaluations;
} prsm_calib_cage;

/* Compare a measured cage ratio with k* and the statics ratio and find the carrier drag c_C
 * (root of Z f.A - c_C psi-dot = 0 in the settled state of the rigid model with options dyn,
 * whose speed and load are set to the measurement's). Returns 0, PRSM_EINVAL, PRSM_ENOCONVERGE. */
int prsm_calib_cage_compute(prsm_calib_cage *out, const prsm_design *d, const prsm_analysis *a,
                            const prsm_dyn_options *dyn, double ratio, double ratio_sd, double axial_load_N,
                            double screw_speed_rad_s, prsm_error *err);

#endif
