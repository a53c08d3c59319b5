/*
 * dynamics_json.h: the `dynamics` object of a request (schemas/dynamics.schema.json) into the
 * options of the rigid-body transient (dyn/dyn.h) or of the vibration analyses (dyn/vib.h), and
 * the result documents (schemas/dynamics-result.schema.json) and time series and sweeps (CSV)
 * of both (their text summaries: app/text.h). docs/dynamics.md, docs/vibration.md.
 *
 * The reader is the table generated from the annotated schema (io/doc.h) filling
 * prsm_dyn_options directly; what a table cannot say is in the hooks of dynamics_json.c (the
 * input's kind-specific names, the per-stage masses, the step cap) and in
 * prsm_io_dynamics_read (the chain's form of the masses, the default output step, then
 * the model's own cross-field rules, prsm_dyn_options_check). The analysis and the sections of
 * the vibration analyses (gear_pair, vibration, steady_state, sweep, basins, linear,
 * frequency_response) are read by one step of the table, prsm_io_step_dynamics_vibration, each
 * section by its own generated table ($defs of the schema) into prsm_io_vib_request; the rules
 * between them follow: which sections and members belong with which analysis by the schema's
 * "rules" (prsm_io_check_rules), the number of stages, the sizes of sweeps and grids and the
 * vibration model's own checks (prsm_vib_options_check, prsm_vib_gear_pair_check) here. Every
 * problem is at its JSON pointer under /dynamics.
 *
 * The writers use the sticky-error writer of io/write.h: a result is whole or not at all.
 */
#ifndef PRSM_IO_DYNAMICS_JSON_H
#define PRSM_IO_DYNAMICS_JSON_H

#include <stdio.h>

#include <cJSON.h>

#include "dyn/dyn.h"
#include "dyn/vib.h"
#include "io/write.h"
#include "prsm_io_enums.h"
#include "util/problems.h"

/* The model a simulation result names ("engine"."model"). */
#define PRSM_DYN_MODEL_VERSION "prsm dynamics 2026-12 (docs/dynamics.md: rigid-body transient of single- and multi-stage screws)"
/* ... and a result of the vibration analyses. */
#define PRSM_VIB_MODEL_VERSION "prsm vibration 2027-01 (docs/vibration.md: reduced elastic model of a PRSM and the 1-DOF gear pair)"

/* Default output grid: end_s / PRSM_IO_DYN_DEFAULT_OUTPUTS (501 output times; for the default
 * 0.005 s a step of 1e-5 s, where a case-A start-up still runs at its full speed: every output
 * time cuts the integrator's step and evaluates every force, docs/dynamics.md). */
#define PRSM_IO_DYN_DEFAULT_OUTPUTS 500

/* The residual limits the result's checks judge against: the power balance relative to the
 * input power, the Newton-Euler recovery of the carrier acceleration (relative), -. */
#define PRSM_IO_DYN_POWER_BALANCE_LIMIT 1e-6
#define PRSM_IO_DYN_NEWTON_EULER_LIMIT 1e-9

/* The whole result document {engine, name, warnings, dynamics} (schemas/dynamics-result.schema.json);
 * name may be NULL or "". The caller owns it; NULL when out of memory. The checks' warnings are
 * appended to a copy of warnings (may be NULL). */
cJSON *prsm_io_dynamics_result_to_json(const char *name, const prsm_dyn_model *m, const prsm_dyn_result *r,
                                       const prsm_problems *warnings);

/* The time series as CSV: a header line, then one line per output time (numbers in %.17g,
 * empty where a value is not defined, e.g. the efficiency at rest). Returns 0 or PRSM_EIO. */
int prsm_io_dynamics_write_csv(FILE *f, const prsm_dyn_model *m, const prsm_dyn_result *r);

/* ---- the vibration analyses (docs/vibration.md) ---------------------------------------------- */

/* The analyses (PRSM_IO_DYN_TRANSIENT, _LINEAR, _VIBRATION, _SWEEP, _FREQUENCY_RESPONSE, _BASINS;
 * PRSM_IO_DYN_ANALYSES of them) and the sweep's parameters (PRSM_IO_SWEEP_FREQUENCY_RATIO, ...,
 * each in its unit: screw speed rad/s, mesh error um) are the schema's enums, generated with their
 * names, prsm_io_dynamics_analysis_name() and prsm_io_sweep_parameter_name() (prsm_io_enums.h,
 * "constants" in schemas/dynamics.schema.json). The engine's PRSM_VIB_PARAM_* of a sweep parameter
 * and the factor from the request's unit to the engine's (um -> m): */
int prsm_io_sweep_parameter_engine(int parameter, double *to_engine);

/* steady_state: one steady state (analysis vibration) */
typedef struct {
	int transient_periods;       /* n_tr forcing periods before the recording (300) */
	int recorded_periods;        /* n_rec (64) */
	int clock;                   /* PRSM_VIB_CLOCK_* (AUTO) */
	int observable;              /* PRSM_VIB_OBS_* (MESH_DEFLECTION) */
	int roller;                  /* the observable's roller (0) */
	double period_tolerance;     /* NaN: the model's (1e-6 gear pair, 1e-4 reduced) */
	int samples_per_period;      /* spectrum and phase portrait (128) */
	int lyapunov;                /* 1: the Lyapunov exponents after the transient */
	int lyapunov_method;         /* PRSM_VIB_LYAPUNOV_* (BENETTIN) */
	int lyapunov_exponents;      /* how many (1) */
	int lyapunov_periods;        /* N (2000) */
} prsm_io_vib_steady;

/* sweep: a bifurcation diagram (analysis sweep; frequency_response takes its grid) */
typedef struct {
	int parameter;               /* PRSM_IO_SWEEP_* (FREQUENCY_RATIO) */
	double from, to, step;       /* in the parameter's unit (0.7, 1.6, 0.05) */
	int up, down;                /* "directions" (both) */
	int continuation;            /* 1: each point from the previous end state (1) */
	int transient_periods, recorded_periods; /* per point (300, 64) */
	int clock, observable, roller;
	double period_tolerance;     /* NaN: the model's */
	int lyapunov;                /* 1: lambda_max per point (0) */
	int lyapunov_periods;        /* (2000) */
} prsm_io_vib_sweep;

/* basins: a grid of initial states (analysis basins); the states are scaled (gear pair: x and x';
 * reduced: the spin deflection P_{roller+1} = r_b1 phi / b_g and its rate V_{roller+1}) */
typedef struct {
	double deflection_min, deflection_max; /* (-2, 4) */
	int deflection_cells;        /* (41) */
	double rate_min, rate_max;   /* (-3, 3) */
	int rate_cells;              /* (41) */
	int periods;                 /* n_b (100) */
	int identify_periods;        /* (64) */
	double distance;             /* (1e-3) */
	int roller;                  /* reduced: the roller whose spin is varied (0) */
	double period_tolerance;     /* NaN: the model's */
} prsm_io_vib_basins;

/* linear: the FRF and its half-power damping (analysis linear) */
typedef struct {
	int input;                   /* PRSM_VIB_IN_* (MESH_ERROR) */
	int input_roller;            /* (0) */
	int output;                  /* PRSM_VIB_OUT_* (MESH_DEFLECTION) */
	int output_roller;           /* (0) */
	double from_Hz, to_Hz;       /* reduced model; NaN: around the output's mode */
	double from_frequency_ratio, to_frequency_ratio; /* gear pair (0.5, 1.5) */
	int points;                  /* FRF grid (401) */
} prsm_io_vib_linear;

/* frequency_response (the grid is the sweep object's) */
typedef struct {
	double agreement_tolerance;  /* the two directions agree within this, relative (1e-3) */
} prsm_io_vib_frequency_response;

/* Everything a request asks of the vibration analyses. */
typedef struct {
	int analysis;                /* PRSM_IO_DYN_* */
	int gear_pair_model;         /* 1: the request's gear_pair (no design); 0: the reduced model */
	prsm_vib_gear_pair gear_pair;
	prsm_vib_options vibration;  /* the reduced model's options */
	prsm_io_vib_steady steady_state;
	prsm_io_vib_sweep sweep;
	prsm_io_vib_basins basins;
	prsm_io_vib_linear linear;
	prsm_io_vib_frequency_response frequency_response;
	prsm_vib_integration integration; /* time.rel_tol, abs_tol, max_steps, or the analysis' defaults */
	int te_from_errors;          /* vibration.te_lines "statics": the request's error set */
} prsm_io_vib_request;

/* The defaults of each section: the gear pair's (dyn/vib.h, checked by the generated
 * prsm_io_defaults_*); those of steady_state, sweep, basins, linear and frequency_response are
 * generated from the schema ("init": {"generate"}, declared in prsm_io_tables.h); the request's,
 * each. */
void prsm_io_gear_pair_init(prsm_vib_gear_pair *g);
void prsm_io_vib_request_init(prsm_io_vib_request *r);

/*
 * Read the dynamics object obj (at /dynamics; NULL: absent, every default) into the transient's
 * options *o and the vibration request *v (may be NULL: checked only), both set to the defaults
 * first: the fields by the schema's table, output_step_s = end_s / 500 when not given, the
 * single-stage or chain form of the masses, then prsm_dyn_options_check (each of its problems
 * unless the field already has one), and the vibration analyses' sections and rules. stages: the
 * request's stages, 1 for a design, 0 for a request without a design (the gear-pair form,
 * {"dynamics": {"analysis", "gear_pair", ...}}). couplings are not part of the object: the caller
 * copies a chain's from its multi-stage document. Every problem with its pointer. Returns 0 or
 * PRSM_EINVAL.
 */
int prsm_io_dynamics_read(prsm_dyn_options *o, prsm_io_vib_request *v, const cJSON *obj, int stages,
                          prsm_problems *problems);

/* What a vibration analysis computed (filled by app/simulate.c, written here). */
typedef struct {
	int analysis;                /* PRSM_IO_DYN_* */
	int threads;                 /* the engine threads it ran on (not written: results do not depend on it) */
	/* LINEAR */
	prsm_vib_linear linear;
	int input, input_roller, output, output_roller;
	size_t frf_points;
	double *frf_omega;           /* rad/s (reduced) or per unit tau (gear pair) */
	double *frf_re, *frf_im;
	prsm_vib_half_power half_power;
	/* VIBRATION */
	prsm_vib_steady steady;
	int with_lyapunov;
	prsm_vib_lyapunov lyapunov;
	/* SWEEP, FREQUENCY_RESPONSE (fr.sweep) */
	prsm_vib_sweep sweep;
	prsm_vib_frequency_response fr;
	int with_harmonic_balance;   /* FREQUENCY_RESPONSE: gear pair with kappa = 0 */
	/* BASINS */
	prsm_vib_basins basins;
	prsm_vib_effort effort;      /* the analysis' whole effort */
} prsm_io_vib_result;

void prsm_io_vib_result_free(prsm_io_vib_result *r);

/* The whole result document of a vibration analysis (schemas/dynamics-result.schema.json):
 * {engine, name, warnings, dynamics: {analysis, model, parameters, <analysis>, convergence}}.
 * dyn: the transient options the request gave (the reduced model's load, friction and masses).
 * The caller owns it; NULL when out of memory. */
cJSON *prsm_io_vibration_result_to_json(const char *name, const prsm_io_vib_request *q, const prsm_dyn_options *dyn,
                                        const prsm_vib_model *m, const prsm_io_vib_result *r,
                                        const prsm_problems *warnings);

/* The analysis' series as CSV: vibration the recorded window (time, observable, its rate),
 * sweep and frequency_response the bifurcation points (one row per Poincare point), basins the
 * grid's labels, linear the FRF. Returns 0 or PRSM_EIO. */
int prsm_io_vibration_write_csv(FILE *f, const prsm_io_vib_request *q, const prsm_vib_model *m,
                                const prsm_io_vib_result *r);

#endif
