/*
 * vib.h: the reduced vibration model of a planetary roller screw and its analyses
 * (docs/model §8.3, §8.4; MODEL-DYNAMICS.md): time response, steady state with Poincaré
 * sections, period classification, spectra and extremes, bifurcation sweeps up and down with
 * continuation, the largest Lyapunov exponent of the non-smooth system, basins of attraction,
 * the linearised model (eigenvalues, modes, FRF, half-power damping), harmonic balance with its
 * folds, and periodic orbits by shooting (Floquet multipliers). Pure C, no JSON (docs/vibration.md
 * explains the model in words).
 *
 * Two models behind one handle (prsm_vib_model):
 *
 *  - PRSM_VIB_GEAR_PAIR, the 1-DOF Kahraman-Singh gear pair of §8.3.5 in its dimensionless form
 *        x'' + 2 zeta x' + kappa(tau) h(x; 1) = f_m + epsilon Omega^2 cos(Omega tau)
 *    (time tau, lengths in units of the half backlash; kappa(tau) the rectangular mesh stiffness
 *    of mean 1, see prsm_vib_gear_pair). States (x, x').
 *
 *  - PRSM_VIB_REDUCED, the reduced model of a PRSM (§8.3.1-8.3.4) built from a design, its
 *    nominal analysis and the statics engine (axial stiffness at F_0, backlash, ring-gear teeth
 *    and contact ratio, TE lines from an error set), the rigid model of dyn.h (contact point,
 *    normals, slip basis, k*, masses) and explicit overrides. Two branches coupled one way: the
 *    axial thread branch (y, the compression of the loaded flanks, with the statics stiffness and
 *    backlash, excited by the TE lines) and the ring-gear branch (carrier psi and roller spins
 *    phi_j with the time-varying mesh stiffness k_j(t), the gear backlash and the mesh error,
 *    loaded by the screw-contact friction whose normal force is the axial branch's thread force).
 *    Scaled states (§8.4): [P_0, P_1 .. P_Z, V_0, V_1 .. V_Z, Y, W] with P_0 = r_b2 psi / b_g,
 *    P_j = r_b1 phi_{j-1} / b_g, V the derivatives with respect to tau = omega_ref t, Y = y / b_a,
 *    W = y-dot / (b_a omega_a). The mesh deflection of roller j is x_j = d_j / b_g = P_0 + P_{j+1}.
 *
 * Units: the dimensionless model is dimensionless throughout (time tau, frequencies in rad per
 * unit tau). The reduced model works in the scaled states above; every member, option and result
 * whose name carries a unit is in that unit (SI inside: m, kg, s, N, rad; _um and _mm only where
 * the name says so), and times of the reduced model are given in seconds at the API.
 *
 * Integration (§8.4): GSL's rk8pd with the y_new control on the scaled states (rel = abs = 1e-10
 * by default), driven step by step by this layer (no allocation per step). The rectangular mesh
 * stiffness jumps at known times: every integration stops exactly at each switching instant of
 * every roller and restarts the stepper there. The dead-zone kinks |x| = 1 leave the vector field
 * continuous; §8.4 requires their location only for the variational equations (Lyapunov
 * exponents, shooting). We locate every crossing, for the state too (LOCATE_AUTO, the default):
 * regula falsi (Illinois) on the guard, re-stepping from the accepted step's start, the step ends
 * just past the crossing and the Jacobian of each step is that of one side of the kink. For the
 * state alone this halves the steps and is far more accurate than the error control's shrinking
 * steps (LOCATE_NEVER keeps that behaviour; with variational equations it is overridden).
 *
 * Threads: sweeps and basin grids run their independent tasks (the two directions of a
 * continuation sweep, the cells of a basin grid, independent sweep points) on `threads` POSIX
 * threads; every task depends only on its own inputs, so the results are bit-identical for any
 * thread count. Progress is reported from the calling thread.
 *
 * Ownership: prsm_vib_*_new allocate the model (prsm_vib_model_free); every analysis allocates
 * the arrays of its result (the matching *_free releases them, also after a failure).
 * Returns: 0 or a negative PRSM_E* (util/error.h) with err filled: PRSM_EINVAL (bad options,
 * err->pointer at the request field of docs/model §8.7), PRSM_ENOCONVERGE (an integration or a
 * solve failed), PRSM_ECANCELLED, PRSM_ENOMEM.
 */
#ifndef PRSM_DYN_VIB_H
#define PRSM_DYN_VIB_H

#include <stddef.h>
#include <stdint.h>

#include "dyn/dyn.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/design.h"
#include "model/errors.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

#define PRSM_VIB_ROLLERS_MAX 64
#define PRSM_VIB_TE_LINES_MAX 32
/* state size of the reduced model: 2 (Z + 1) gear + 2 axial */
#define PRSM_VIB_STATE_MAX (2 * (PRSM_VIB_ROLLERS_MAX + 1) + 2)
#define PRSM_VIB_CONTACTS_MAX (PRSM_VIB_ROLLERS_MAX + 1)
/* periods m of a periodic steady state (§8.4) */
#define PRSM_VIB_PERIOD_MAX 32
/* limits of the analyses (refused above them, docs/model §8.7: "a sweep of 10^7 points") */
#define PRSM_VIB_SWEEP_POINTS_MAX 20001
#define PRSM_VIB_PERIODS_MAX 1000000      /* forcing periods of one point (transient + recorded + Lyapunov) */
#define PRSM_VIB_BASIN_CELLS_MAX 250000
#define PRSM_VIB_OUTPUT_POINTS_MAX 2000000
#define PRSM_VIB_SAMPLES_PER_PERIOD_MAX 4096

enum { PRSM_VIB_GEAR_PAIR = 0, PRSM_VIB_REDUCED = 1 };
/* which branches of the reduced model move (§8.3): GEAR alone runs with F_th = F_0 (V5's sweep) */
enum { PRSM_VIB_BRANCHES_BOTH = 0, PRSM_VIB_BRANCHES_GEAR = 1, PRSM_VIB_BRANCHES_AXIAL = 2 };
/* the TE excitation (§8.3.4): none, the lines given, or fitted to the statics TE of an error set */
enum { PRSM_VIB_TE_NONE = 0, PRSM_VIB_TE_LINES = 1, PRSM_VIB_TE_STATICS = 2 };
/* dead-zone crossings (see above) */
enum { PRSM_VIB_LOCATE_AUTO = 0, PRSM_VIB_LOCATE_ALWAYS = 1, PRSM_VIB_LOCATE_NEVER = 2 }; /* AUTO = ALWAYS */
/* the forcing period an analysis counts in and takes its Poincaré section at: the mesh period
 * (phase 0 of roller 0's mesh cycle), or the common period of the TE lines; AUTO: the TE period
 * for an axial observable (when the lines have one), else the mesh period */
enum { PRSM_VIB_CLOCK_AUTO = 0, PRSM_VIB_CLOCK_MESH = 1, PRSM_VIB_CLOCK_TE = 2 };
/* observables (index: the roller, where one is meant). Units: deflections scaled (x = d / b_g,
 * y / b_a; the gear pair's x), rates scaled as the states, forces in N (reduced model; mesh force
 * F_j of both meshes of a roller, thread force F_th) or dimensionless (gear pair: kappa h(x)) */
enum {
	PRSM_VIB_OBS_MESH_DEFLECTION = 0, /* x_j = d_j / b_g (gear pair: x) */
	PRSM_VIB_OBS_MESH_RATE = 1,       /* x_j' (derivative in tau) */
	PRSM_VIB_OBS_MESH_FORCE = 2,      /* F_j, N (gear pair: kappa(tau) h(x), -) */
	PRSM_VIB_OBS_AXIAL_DEFLECTION = 3,/* y / b_a */
	PRSM_VIB_OBS_AXIAL_RATE = 4,      /* y-dot / (b_a omega_a) */
	PRSM_VIB_OBS_THREAD_FORCE = 5     /* F_th = k_a h(y; b_a) + c_a y-dot, N */
};
/* steady-state classes (§8.4) */
enum {
	PRSM_VIB_PERIODIC = 0,       /* period m <= 32 */
	PRSM_VIB_NON_PERIODIC = 1,   /* not periodic, lambda_max not computed */
	PRSM_VIB_QUASI_PERIODIC = 2, /* not periodic, lambda_max <= 1e-3 */
	PRSM_VIB_CHAOTIC = 3,        /* not periodic, lambda_max > 1e-3 (scaled time) */
	PRSM_VIB_FAILED = 4          /* the point did not converge (not drawn; err_code says why) */
};
/* sweep parameters; values in the model's units: frequency ratio Omega = omega_e (-), screw
 * speed (rad/s, reduced model), mesh error (gear pair: epsilon; reduced: e_g in m), damping
 * ratio (zeta; reduced: the mesh damping zeta_g), mean force (gear pair: f_m), stiffness
 * variation (gear pair: kappa) */
enum {
	PRSM_VIB_PARAM_FREQUENCY_RATIO = 0,
	PRSM_VIB_PARAM_SCREW_SPEED = 1,
	PRSM_VIB_PARAM_MESH_ERROR = 2,
	PRSM_VIB_PARAM_DAMPING_RATIO = 3,
	PRSM_VIB_PARAM_MEAN_FORCE = 4,
	PRSM_VIB_PARAM_STIFFNESS_VARIATION = 5
};
/* Lyapunov methods (§8.4): (a) variational equations with QR, (b) two trajectories stacked */
enum { PRSM_VIB_LYAPUNOV_BENETTIN = 0, PRSM_VIB_LYAPUNOV_TWO_TRAJECTORIES = 1 };

/* ---------------------------------------------------------------------------------------- */
/* Models                                                                                    */

/* The dimensionless gear pair (§8.3.5, V4). kappa(tau) = 1 + kappa (1 - D) while two tooth
 * pairs mesh (u < D = contact_ratio - 1, u = frac(Omega tau / 2 pi) the mesh phase) and
 * 1 - kappa D otherwise: mean 1, kappa = (k_d - k_s) / k-bar reproduces §8.3.3; kappa = 0 (V4)
 * is the constant stiffness. */
typedef struct {
	double damping_ratio;        /* zeta (0.05) */
	double mean_force;           /* f_m = F-bar / (2 k-bar b_g) (0.1) */
	double mesh_error;           /* epsilon: error amplitude over b_g (0.005) */
	double stiffness_variation;  /* kappa (0) */
	double contact_ratio;        /* eps_alpha in [1, 2] (1.5) */
	double frequency_ratio;      /* Omega = omega_e (1) */
} prsm_vib_gear_pair;

#define PRSM_VIB_GEAR_PAIR_INIT {0.05, 0.1, 0.005, 0.0, 1.5, 1.0}

/* One TE line (§8.3.4): TE(t) = sum A cos(nu omega_s t + phi), nu per screw revolution. */
typedef struct {
	double order_per_rev;        /* nu, cycles per screw revolution */
	double amplitude_m;          /* A, m (>= 0) */
	double phase_rad;            /* phi, rad */
} prsm_vib_te_line;

/* Options of the reduced model (docs/model §8.7 "vibration"); NaN or 0 where marked: the value
 * from the statics engine or the default of §8.3.1. Inertias, friction and the load come from a
 * prsm_dyn_options (dyn.h: inertia, friction.mu, friction.smoothing_velocity_m_s, load.value). */
typedef struct {
	double screw_speed_rad_s;         /* omega_s (330) */
	double frequency_ratio;           /* omega_e; NaN: from the screw speed; given: sets the speed */
	double axial_load_N;              /* F_0; NaN: the dyn options' load value */
	double axial_damping_ratio;       /* zeta_a (0.05) */
	double mesh_damping_ratio;        /* zeta_g (0.05) */
	double mesh_single_stiffness_N_per_mm_um; /* c' of k_s = c' b_w (14, ISO 6336-1) */
	double double_to_single_stiffness;/* k_d / k_s (2) */
	double gear_backlash_um;          /* b_g: half backlash of a mesh along the line of action (5) */
	double mesh_error_um;             /* e_g: first-harmonic mesh error (0) */
	double axial_stiffness_N_per_um;  /* k_a; NaN: statics stiffness.axial_N_per_um at F_0 */
	double axial_half_play_um;        /* b_a; NaN: statics backlash_um / 2 */
	double gear_contact_ratio;        /* eps_alpha; NaN: the statics losses' (1.5) */
	double gear_pressure_angle_rad;   /* alpha; NaN: the design's losses.gear_pressure_angle_rad */
	int gear_teeth_roller;            /* z_1; 0: the statics losses' */
	int gear_teeth_ring;              /* z_2; 0: the statics losses' */
	int branches;                     /* PRSM_VIB_BRANCHES_* */
	int te_source;                    /* PRSM_VIB_TE_* */
	int te_lines;                     /* LINES: entries of te_line */
	prsm_vib_te_line te_line[PRSM_VIB_TE_LINES_MAX];
	double te_threshold;              /* STATICS: other spectrum lines above this share of the
	                                     largest (0.01) */
	int te_max_lines;                 /* STATICS: at most this many lines (32) */
} prsm_vib_options;

#define PRSM_VIB_OPTIONS_INIT                                                                     \
	{330.0, NAN, NAN, 0.05, 0.05, 14.0, 2.0, 5.0, 0.0, NAN, NAN, NAN, NAN, 0, 0,                 \
	 PRSM_VIB_BRANCHES_BOTH, PRSM_VIB_TE_NONE, 0, {{0.0, 0.0, 0.0}}, 0.01, PRSM_VIB_TE_LINES_MAX}

/* Set *o to PRSM_VIB_OPTIONS_INIT. Returns 0. */
int prsm_vib_options_init(prsm_vib_options *o);

/* Check the options: every problem to problems, at /dynamics/vibration/... Returns 0 or PRSM_EINVAL. */
int prsm_vib_options_check(const prsm_vib_options *o, prsm_problems *problems);
/* Same for a gear pair, at /dynamics/vibration/... */
int prsm_vib_gear_pair_check(const prsm_vib_gear_pair *g, prsm_problems *problems);

/* What a model runs with (echoed with every result). SI unless the name says otherwise. */
typedef struct {
	int kind;                    /* PRSM_VIB_GEAR_PAIR or PRSM_VIB_REDUCED */
	int branches;                /* PRSM_VIB_BRANCHES_* (gear pair: GEAR) */
	int rollers;                 /* Z (gear pair: 1) */
	int states;                  /* state size */
	int poincare_size;           /* size of the scaled Poincaré vector (§8.4) */
	int contacts;                /* dead zones: Z meshes (+ the thread, axial branch active) */
	prsm_vib_gear_pair gear_pair;/* gear pair: its parameters; reduced: the equivalent 1-DOF
	                                numbers of §8.3.5 (zeta_g, f_m, e_g / b_g, kappa, eps_alpha, omega_e) */
	/* operating point */
	double screw_speed_rad_s;    /* omega_s */
	double frequency_ratio;      /* omega_e = omega_m / omega_ref */
	double axial_load_N;         /* F_0 */
	double carrier_ratio;        /* k* (§8.1) */
	double ring_gear_ratio;      /* i_g */
	double mesh_frequency_rad_s; /* omega_m = z_2 k* omega_s */
	double reference_frequency_rad_s; /* omega_ref = sqrt(2 r_b1^2 k-bar / M_phiphi) */
	double axial_frequency_rad_s;/* omega_a = sqrt(k_a / m_a) */
	/* axial branch (§8.3.2) */
	double axial_mass_kg;        /* m_a = m_N + Z m_R + m_C + m_p */
	double axial_stiffness_N_per_m; /* k_a */
	double axial_damping_N_s_per_m; /* c_a = 2 zeta_a sqrt(k_a m_a) */
	double axial_damping_ratio;  /* zeta_a */
	double axial_half_play_m;    /* b_a */
	double axial_static_m;       /* y_0 = b_a + F_0 / k_a */
	/* gear branch (§8.3.3) */
	int teeth_roller, teeth_ring;/* z_1, z_2 */
	double pressure_angle_rad;   /* alpha */
	double contact_ratio;        /* eps_alpha */
	double gear_face_width_mm;   /* b_w */
	double base_radius_roller_m, base_radius_ring_m; /* r_b1, r_b2 */
	double mesh_single_N_per_m, mesh_double_N_per_m, mesh_mean_N_per_m; /* k_s, k_d, k-bar */
	double gear_half_backlash_m; /* b_g */
	double mesh_error_m;         /* e_g */
	double mesh_damping_ratio;   /* zeta_g */
	double mesh_damping_N_s_per_m; /* c_g = zeta_g sqrt(2 k-bar M_phiphi) / r_b1 */
	double mesh_phase[PRSM_VIB_ROLLERS_MAX]; /* gamma_j = frac(j z_2 / Z) */
	double inertia_psipsi_kg_m2, inertia_psiphi_kg_m2, inertia_phiphi_kg_m2; /* M (§8.3.1) */
	double roller_lead_m_per_rad;/* p_r = hand P / 2 pi */
	/* friction coupling */
	double mu;                   /* Coulomb mu at the screw contact */
	double smoothing_velocity_m_s; /* v_eps */
	int flank;                   /* PRSM_DYN_FLANK_* carrying F_0 */
	double slip_m_s[3];          /* v* = (A k* + B) omega_s, pair frame */
	double G_phi_m[3], G_psi_m[3]; /* slip per roller spin / carrier rate, m per rad (§8.3.3) */
	double normal_force_N;       /* N per roller at F_0 */
	double mean_mesh_force_N;    /* F-bar = f . G_phi / r_b1 per roller (both meshes) */
	double static_mesh_deflection_m; /* d = b_g + F-bar / (2 k-bar) (sign of F-bar) */
	/* TE lines (§8.3.4), orders with k* */
	int te_lines;
	prsm_vib_te_line te_line[PRSM_VIB_TE_LINES_MAX];
	double te_period_rev;        /* common period of the lines, screw revolutions; NaN: none
	                                (incommensurate within 1e-9 up to 1000 revolutions), 0: no lines */
} prsm_vib_params;

typedef struct prsm_vib_model prsm_vib_model;

/* A gear-pair model (checked). Allocates *out (prsm_vib_model_free). Returns 0, PRSM_EINVAL, PRSM_ENOMEM. */
int prsm_vib_gear_pair_new(prsm_vib_model **out, const prsm_vib_gear_pair *g, prsm_error *err);

/*
 * The reduced model of a single-stage design (resolved, checked; analysis its
 * prsm_analysis_nominal): the rigid model of dyn.h for the contact, k* and the masses (dyn: its
 * inertia, friction mu and smoothing velocity, load; NULL: PRSM_DYN_OPTIONS_INIT), the statics
 * engine for k_a (prsm_performance_compute at F_0), b_a (the nominal backlash), z_1, z_2 and
 * eps_alpha (the losses' gear mesh), and with te_source STATICS the TE of `errors` (assembly
 * options `assembly`, NULL: the defaults with a 100 mm stroke), fitted as §8.3.4 says
 * (prsm_vib_te_lines_from_errors). Allocates *out. Returns 0; PRSM_EINVAL (bad options,
 * a design the rigid model refuses, STATICS without errors); PRSM_ENOCONVERGE (statics);
 * PRSM_ENOMEM.
 */
int prsm_vib_model_new(prsm_vib_model **out, const prsm_design *design, const prsm_analysis *analysis,
                       const prsm_dyn_options *dyn, const prsm_vib_options *options,
                       const prsm_errors *errors, const prsm_assembly_options *assembly,
                       prsm_error *err);

/* Release a model (NULL is fine). */
void prsm_vib_model_free(prsm_vib_model *m);

/* An independent copy (allocates; NULL when out of memory). */
prsm_vib_model *prsm_vib_model_copy(const prsm_vib_model *m);

const prsm_vib_params *prsm_vib_model_params(const prsm_vib_model *m);

/* Change one sweepable parameter (PRSM_VIB_PARAM_*; units above) and every derived quantity.
 * Returns 0 or PRSM_EINVAL (a parameter this model has not, or a value out of range). */
int prsm_vib_model_set(prsm_vib_model *m, int parameter, double value, prsm_error *err);

/* The static state (§8.4 sweeps: d_j = b_g + F-bar/(2 k-bar), y = y_0, velocities 0; gear
 * pair: x = 1 + f_m (sign of f_m), x' = 0) into y (states entries). */
void prsm_vib_static_state(const prsm_vib_model *m, double *y);

/* The forcing period of a clock (PRSM_VIB_CLOCK_*) in scaled time tau (NaN: the clock has no
 * period, e.g. TE with incommensurate lines), and in seconds for the reduced model. */
double prsm_vib_period(const prsm_vib_model *m, int clock);
/* The clock AUTO resolves to for an observable. */
int prsm_vib_clock_of(const prsm_vib_model *m, int clock, int observable);

/* The value of an observable (PRSM_VIB_OBS_*, roller index) in a state at scaled time tau. */
double prsm_vib_observable(const prsm_vib_model *m, int observable, int index, double tau, const double *y);

/* The scaled Poincaré vector of §8.4 (poincare_size entries): gear pair (x, x'); reduced model
 * (x_j, x_j' for every roller, V_0 = psi-dot r_b2 / (b_g omega_ref), then Y, W when the axial
 * branch moves) -- never psi itself (the rigid carrier mode may drift). */
void prsm_vib_poincare_vector(const prsm_vib_model *m, const double *y, double *out);

/* TE lines (§8.3.4): least-squares amplitude and phase of cos/sin at the given orders (cycles per
 * screw revolution) together with a line a + b i (the lead slope is not an excitation), fitted to
 * a TE record te_mm[0..n) sampled per_rev times per screw revolution from theta = 0. out gets
 * n_orders lines in the given order (amplitude m, phase rad: TE ~ sum A cos(2 pi nu i / per_rev + phi)).
 * Returns 0, PRSM_EINVAL (too short a record: n < 2 n_orders + 2), PRSM_ENOCONVERGE. */
int prsm_vib_te_lines_fit(prsm_vib_te_line *out, const double *te_mm, int n, int per_rev,
                          const double *orders_per_rev, int n_orders, prsm_error *err);

/* The TE lines of an error set (§8.3.4): the statics TE over the stroke (prsm_assembly_analyse,
 * options `assembly`), its named lines (screw 1 - k_c, carrier k_c, roller spin, the two roller
 * passes) and the local maxima of its spectrum above threshold x the largest (at most max_lines in
 * all), fitted with prsm_vib_te_lines_fit; the named orders are then re-evaluated with k* (the
 * fitted amplitudes and phases kept), the others kept as found. Lines of zero amplitude are
 * dropped. Returns 0 or an error of the statics engine. */
int prsm_vib_te_lines_from_errors(prsm_vib_te_line *out, int *n_out, const prsm_design *design,
                                  const prsm_analysis *analysis, const prsm_errors *errors,
                                  const prsm_assembly_options *assembly, double k_star,
                                  double threshold, int max_lines, prsm_error *err);

/* ---------------------------------------------------------------------------------------- */
/* Integration                                                                               */

typedef struct {
	double rel_tol, abs_tol;     /* gsl_odeiv2_control_y_new on the scaled states (1e-10; 1e-9 is
	                                enough for classification sweeps, §8.4) */
	int locate_kinks;            /* PRSM_VIB_LOCATE_* */
	long max_steps;              /* accepted steps of one analysis (one sweep point) before
	                                PRSM_ENOCONVERGE (5e7) */
	double initial_step;         /* scaled time; NaN: the forcing period / 64 */
} prsm_vib_integration;

#define PRSM_VIB_INTEGRATION_INIT {1e-10, 1e-10, PRSM_VIB_LOCATE_AUTO, 50000000L, NAN}

/* Effort of an analysis. */
typedef struct {
	long steps, rejected, rhs_evaluations, events, switches;
} prsm_vib_effort;

/* ---------------------------------------------------------------------------------------- */
/* Time response (§8.4 "time_response")                                                      */

typedef struct {
	size_t points;
	int states, rollers, contacts;
	double *tau;                 /* scaled time of each output, - */
	double *time_s;              /* reduced: tau / omega_ref, s; gear pair: = tau */
	double *state;               /* points x states, scaled */
	double *mesh_deflection;     /* points x rollers: x_j = d_j / b_g (gear pair: x) */
	double *mesh_force;          /* points x rollers: F_j, N (gear pair: kappa h(x)) */
	double *axial_deflection;    /* points: y / b_a (reduced model; NaN when the axial branch is off) */
	double *thread_force_N;      /* points: F_th, N (reduced; F_0 when the axial branch is off) */
	unsigned char *contact_lost; /* points x contacts: 1 when the contact is in its dead zone or on
	                                its back flank (|x| <= 1 or x < -1; meshes first, the thread last) */
	prsm_vib_effort effort;
} prsm_vib_response;

/*
 * Integrate from initial_state (NULL: the static state) at t = 0 to end (seconds for the reduced
 * model, tau for the gear pair), output every output_step (same unit; the end is always an
 * output). Outputs between steps are interpolated (quintic Hermite for positions, cubic for
 * rates). Returns 0, PRSM_EINVAL (bad times, too many points), PRSM_ENOCONVERGE, PRSM_ECANCELLED,
 * PRSM_ENOMEM.
 */
int prsm_vib_time_response(prsm_vib_response *out, const prsm_vib_model *m, const double *initial_state,
                           double end, double output_step, const prsm_vib_integration *integration,
                           const prsm_cancel_flag *cancel, prsm_error *err);
void prsm_vib_response_free(prsm_vib_response *r);

/* ---------------------------------------------------------------------------------------- */
/* Steady state (§8.4 "vibration")                                                           */

typedef struct {
	int transient_periods;       /* n_tr (300) */
	int recorded_periods;        /* n_rec (64) */
	int clock;                   /* PRSM_VIB_CLOCK_* */
	int observable, index;       /* the observable of the Poincaré values, spectrum, phase portrait
	                                (MESH_DEFLECTION of roller 0) */
	double period_tol;           /* ||P_{i+m} - P_i||_inf below this: period m; NaN: 1e-6 (gear
	                                pair), 1e-4 (reduced) */
	int samples_per_period;      /* spectrum and phase-portrait samples per forcing period (128) */
	int lyapunov;                /* 1: lambda_max (Benettin, after the recording) */
	int lyapunov_periods;        /* N (2000) */
	prsm_vib_integration integration;
} prsm_vib_steady_options;

#define PRSM_VIB_STEADY_OPTIONS_INIT                                                              \
	{300, 64, PRSM_VIB_CLOCK_AUTO, PRSM_VIB_OBS_MESH_DEFLECTION, 0, NAN, 128, 0, 2000,            \
	 PRSM_VIB_INTEGRATION_INIT}

/* Extremes of one observable over the recorded window: refined at the sign changes of its rate
 * inside each step (regula falsi on re-steps: exact to the integration; a force's corner at a
 * contact boundary is found the same way), besides the step ends and the samples. */
typedef struct {
	int observable, index;
	double min, max;             /* observable's unit */
	double mean, rms;            /* time mean and RMS about it (from the samples) */
} prsm_vib_extreme;

/* A named spectral line (§8.4 "Spectra"). */
typedef struct {
	char name[40];               /* "forcing", "harmonic_2", "subharmonic_3", "mesh", "carrier", ... */
	double order_per_rev;        /* reduced model: cycles per screw revolution; gear pair: NaN */
	double frequency;            /* gear pair: rad per unit tau; reduced: Hz */
	double amplitude;            /* one-sided amplitude, observable's unit */
} prsm_vib_line;

#define PRSM_VIB_LINES_MAX 48

typedef struct {
	int classification;          /* PRSM_VIB_PERIODIC ... */
	int period;                  /* m (periodic), 0 otherwise */
	int clock;                   /* resolved clock */
	double period_tau;           /* forcing period T, scaled time */
	double period_s;             /* reduced: T / omega_ref, s; gear pair: NaN */
	double period_tol;           /* used */
	int recorded;                /* n_rec */
	int poincare_size;           /* size of a Poincaré vector */
	double *poincare;            /* n_rec x poincare_size: P_i at tau = (n_tr + i) T */
	double *poincare_observable; /* n_rec: the observable at those instants */
	double max_return_distance;  /* max_i ||P_{i+m} - P_i||_inf for the period found (or m = 1) */
	int extremes;                /* entries of extreme */
	prsm_vib_extreme *extreme;
	/* spectrum of the observable over an integer number of periods (rectangular window when
	 * periodic, Hann with coherent gain 2 otherwise), one-sided amplitudes */
	int spectrum_window_hann;    /* 1: Hann */
	int spectrum_periods;        /* periods used (a multiple of m when periodic) */
	int spectrum_bins;
	double *spectrum_frequency;  /* gear pair: rad per unit tau; reduced: Hz */
	double *spectrum_amplitude;
	int lines;
	prsm_vib_line line[PRSM_VIB_LINES_MAX];
	/* phase portrait: (observable, its rate) at samples_per_period per period over the window;
	 * the rate is the state rate (forces: NaN) */
	size_t portrait_points;
	double *portrait_x, *portrait_v;
	/* share of the recorded time each contact spends with contact lost (|x| <= 1) and on its
	 * back flank (x < -1); meshes first, the thread last */
	int contacts;
	double *loss_share, *back_share;
	double lyapunov;             /* lambda_max per unit tau (NaN when not asked) */
	double lyapunov_per_s;       /* reduced: lambda omega_ref, 1/s */
	double *final_state;         /* states: the state at the end of the recording (phase 0) */
	prsm_vib_effort effort;
} prsm_vib_steady;

/* The steady state from initial_state (NULL: static) at tau = 0. Allocates *out's arrays
 * (prsm_vib_steady_free). Returns 0, PRSM_EINVAL, PRSM_ENOCONVERGE, PRSM_ECANCELLED, PRSM_ENOMEM. */
int prsm_vib_steady_state(prsm_vib_steady *out, const prsm_vib_model *m, const double *initial_state,
                          const prsm_vib_steady_options *o, const prsm_cancel_flag *cancel,
                          prsm_error *err);
void prsm_vib_steady_free(prsm_vib_steady *s);

/* The smallest m <= max_period, m <= n / 2 (seen at least twice), with ||P_{i+m} - P_i||_inf < tol
 * for every i (poincare: n x size), 0 when none; *distance (may be NULL) gets the largest return distance of that m (of m = 1 when
 * none). */
int prsm_vib_period_of(const double *poincare, int n, int size, double tol, int max_period, double *distance);

/* ---------------------------------------------------------------------------------------- */
/* Largest Lyapunov exponent (§8.4)                                                          */

typedef struct {
	int method;                  /* PRSM_VIB_LYAPUNOV_* */
	int exponents;               /* Benettin: how many (1 .. poincare_size); (b): 1 */
	int transient_periods;       /* before the measurement (300) */
	int periods;                 /* N (2000) */
	int blocks;                  /* block estimates (10) */
	double separation;           /* (b): d_0, scaled (1e-8) */
	int clock;                   /* PRSM_VIB_CLOCK_* (renormalisation every period) */
	prsm_vib_integration integration; /* (b): tolerances at least 1e3 below d_0 are enforced */
} prsm_vib_lyapunov_options;

#define PRSM_VIB_LYAPUNOV_OPTIONS_INIT                                                            \
	{PRSM_VIB_LYAPUNOV_BENETTIN, 1, 300, 2000, 10, 1e-8, PRSM_VIB_CLOCK_AUTO, PRSM_VIB_INTEGRATION_INIT}

typedef struct {
	int exponents;
	double lambda[PRSM_VIB_STATE_MAX]; /* per unit tau, largest first */
	double lambda_per_s[PRSM_VIB_STATE_MAX]; /* reduced: lambda omega_ref, 1/s; gear pair: NaN */
	double sum;                  /* sum of the exponents computed, per unit tau */
	int blocks;
	double block_lambda[64];     /* lambda_1 of each block (blocks <= 64) */
	double block_min, block_max, block_sd; /* spread of the block estimates */
	double period_tau;           /* renormalisation period */
	int periods;
	prsm_vib_effort effort;
} prsm_vib_lyapunov;

/* From initial_state (NULL: static) at tau = 0: transient, then N periods. No allocation in *out. */
int prsm_vib_lyapunov_run(prsm_vib_lyapunov *out, const prsm_vib_model *m, const double *initial_state,
                          const prsm_vib_lyapunov_options *o, const prsm_cancel_flag *cancel,
                          prsm_error *err);

/* ---------------------------------------------------------------------------------------- */
/* Spreading a sweep's or a basin grid's tasks over processes                                */

/* A buffer of one part. */
typedef struct {
	char *data;
	size_t len;
} prsm_vib_share;

/* What a part's buffer starts with: its failure (code nonzero, message) or 0 and its tasks'
 * results after it (the layout is the run's own). */
typedef struct {
	int32_t code;
	int32_t pad;
	uint64_t tasks;              /* tasks whose results follow */
	char message[PRSM_ERROR_MESSAGE_MAX];
} prsm_vib_share_head;

/*
 * The independent tasks of a sweep (a continuation sweep's directions; independent points: the
 * points) or of a basin grid (its cells) spread over `parts` processes (src/par: the ranks of an
 * MPI job, part = rank), each running the same analysis (the same model and options) with its
 * own part. A part computes the tasks t with t mod parts = part on its threads, packs their
 * results after a prsm_vib_share_head (part 0, whose results are in place, a head alone), and
 * calls exchange(ctx, mine, len, shares, err) once (also when it computed nothing, or failed:
 * then a head with its code). A split other than parts >= 1, 0 <= part < parts with an exchange
 * is refused (PRSM_EINVAL). exchange gives part 0
 * every part's buffer in part order (shares[0 .. parts-1], malloc'd: the run frees them; it may
 * replace a part's buffer by a head with a failure) and returns 0, or PRSM_EIO. Part 0 then
 * finishes the analysis as one process does (the efforts summed in task order, a sweep's first
 * error in point order, a basin grid's attractors and labels in grid order): the same result,
 * byte for byte. The other parts return 0 with an empty result. A part's failure ends part 0's
 * run with "rank P of N failed: MESSAGE". Progress on part 0: its own tasks' units scaled to the
 * whole (an estimate; its share of the tasks is every parts-th one).
 */
typedef struct {
	int parts, part;
	int (*exchange)(void *ctx, const void *mine, size_t len, prsm_vib_share *shares, prsm_error *err);
	void *ctx;
} prsm_vib_split;

/* ---------------------------------------------------------------------------------------- */
/* Bifurcation sweeps (§8.4 "sweep")                                                         */

typedef struct {
	int parameter;               /* PRSM_VIB_PARAM_* (FREQUENCY_RATIO) */
	double from, to, step;       /* grid from + i step up to to (rounded to whole steps) */
	int up, down;                /* directions to run (1, 1) */
	int continuation;            /* 1: each point starts from the previous point's end state (the
	                                first from initial_state or the static state); 0: every point
	                                from initial_state / static (independent points, parallel) */
	prsm_vib_steady_options steady; /* per point: periods, clock, observable, tolerance, Lyapunov */
	const double *initial_state; /* NULL: the static state of the first point */
	int threads;                 /* >= 1 */
	const prsm_vib_split *split; /* NULL: every task here */
} prsm_vib_sweep_options;

void prsm_vib_sweep_options_init(prsm_vib_sweep_options *o);

typedef struct {
	double parameter;            /* value, parameter's unit */
	int direction;               /* +1 up, -1 down */
	int status;                  /* 0, or the PRSM_E* of a point that failed (classification FAILED;
	                                the next point starts from the static state) */
	int classification, period;
	double min, max, mean, rms;  /* observable over the recorded window */
	double amplitude;            /* (max - min) / 2 */
	double lyapunov;             /* per unit tau; NaN when not asked */
	double max_return_distance;
} prsm_vib_sweep_point;

typedef struct {
	int parameter;
	size_t grid;                 /* points per direction */
	size_t points;               /* all points: up first (ascending), then down (descending) */
	prsm_vib_sweep_point *point;
	int recorded;                /* n_rec */
	double *poincare;            /* points x n_rec: the observable at the Poincaré instants */
	int states;
	double *end_state;           /* points x states: the state after the recording */
	char first_error[PRSM_ERROR_MESSAGE_MAX]; /* the message of the first failed point, "" if none */
	prsm_vib_effort effort;
} prsm_vib_sweep;

/* Run a sweep. progress (may be NULL) gets done / planned in sweep points from the calling thread.
 * A point that fails is reported (status, FAILED), not an error of the sweep. Returns 0,
 * PRSM_EINVAL, PRSM_ECANCELLED, PRSM_ENOMEM. */
int prsm_vib_sweep_run(prsm_vib_sweep *out, const prsm_vib_model *m, const prsm_vib_sweep_options *o,
                       const prsm_cancel_flag *cancel, prsm_progress_fn progress, void *progress_ctx,
                       prsm_error *err);
void prsm_vib_sweep_free(prsm_vib_sweep *s);

/* ---------------------------------------------------------------------------------------- */
/* Basins of attraction (§8.4 "basins")                                                      */

typedef struct {
	int x_state, v_state;        /* the two state components varied (gear pair: 0, 1; reduced:
	                                P_1 and V_1, roller 0's spin at the carrier held) */
	double x_min, x_max, v_min, v_max; /* the box, scaled */
	int nx, nv;                  /* grid (41 x 41) */
	int periods;                 /* n_b (100) */
	int identify_periods;        /* after n_b, Poincaré points recorded to find a cycle of period
	                                <= identify_periods / 2 (64) */
	double distance;             /* a cell reaches an attractor within this (1e-3), scaled */
	double period_tol;           /* NaN: as the steady state */
	int clock;
	int known;                   /* attractors given, each by a state at phase 0 and its period */
	const double *known_state;   /* known x states */
	const int *known_period;
	prsm_vib_integration integration;
	int threads;
	const prsm_vib_split *split; /* NULL: every cell here */
} prsm_vib_basin_options;

void prsm_vib_basin_options_init(prsm_vib_basin_options *o);

typedef struct {
	int period;                  /* m */
	int given;                   /* 1: from known_state, 0: found in the grid */
	double *poincare;            /* m x poincare_size */
	size_t cells;                /* cells that reach it */
	double fraction;
} prsm_vib_attractor;

typedef struct {
	int nx, nv;
	double x_min, x_max, v_min, v_max;
	int *label;                  /* nx x nv (row i = x index): attractor index, -1 "other",
	                                -2 failed */
	int attractors;
	prsm_vib_attractor *attractor;
	size_t other, failed;
	double other_fraction, failed_fraction;
	int poincare_size;
	prsm_vib_effort effort;
} prsm_vib_basins;

/* Every cell's initial state is the static state with components x_state, v_state set. Attractors
 * not given are found in grid order (a cell whose last identify_periods Poincaré points close a
 * cycle of period <= 32 and that matches none known starts a new one): the labels do not depend
 * on the thread count. progress in cells. */
int prsm_vib_basins_run(prsm_vib_basins *out, const prsm_vib_model *m, const prsm_vib_basin_options *o,
                        const prsm_cancel_flag *cancel, prsm_progress_fn progress, void *progress_ctx,
                        prsm_error *err);
void prsm_vib_basins_free(prsm_vib_basins *b);

/* ---------------------------------------------------------------------------------------- */
/* Periodic orbits by shooting (§8.4 "Periodic orbits")                                      */

typedef struct {
	int converged;
	int period;                  /* m forcing periods */
	int iterations;
	double residual;             /* ||P^m(y) - y||_inf (reduced coordinates) */
	double state[PRSM_VIB_STATE_MAX]; /* on the orbit at phase 0 */
	int multipliers;
	double multiplier_re[PRSM_VIB_STATE_MAX], multiplier_im[PRSM_VIB_STATE_MAX]; /* Floquet, largest |mu| first */
	double min, max;             /* observable (MESH_DEFLECTION / AXIAL for axial-only) over the orbit, refined */
	double lambda_max;           /* ln |mu_max| / (m T), per unit tau */
} prsm_vib_orbit;

/* Newton on P^m(y) - y (reduced coordinates; the rigid carrier angle is held) from guess (NULL:
 * static), with the monodromy matrix from the variational equations. Returns 0 (see converged),
 * PRSM_ENOCONVERGE (integration failed), PRSM_EINVAL. */
int prsm_vib_periodic_orbit(prsm_vib_orbit *out, const prsm_vib_model *m, const double *guess, int period,
                            const prsm_vib_integration *integration, const prsm_cancel_flag *cancel,
                            prsm_error *err);

/* A fold of a branch of periodic orbits located by shooting: natural-parameter continuation of
 * the orbit from `from` towards `to` with the step halved whenever Newton fails (down to 1e-7),
 * the fold then extrapolated from the last two orbits with (mu_max - 1)^2 linear in the parameter
 * (near a fold mu_max - 1 ~ sqrt(|Omega - Omega*|)). */
typedef struct {
	int found;                   /* 1: the branch ended between from and to */
	double omega;                /* Omega* (frequency ratio) */
	double last_omega;           /* the last converged orbit's Omega */
	double last_multiplier;      /* its largest real multiplier */
	double amplitude;            /* (max - min) / 2 of the last orbit */
	int period;
	int orbits;                  /* shooting solves done */
} prsm_vib_exact_fold;

int prsm_vib_fold_track(prsm_vib_exact_fold *out, const prsm_vib_model *m, const double *state, int period,
                        double from, double to, const prsm_vib_integration *integration,
                        const prsm_cancel_flag *cancel, prsm_error *err);

/* ---------------------------------------------------------------------------------------- */
/* Frequency response with jumps (§8.4 "frequency_response"), gear pair with kappa = 0       */

typedef struct {
	double omega;                /* Omega */
	double amplitude;            /* A */
	double mean;                 /* x_m */
	int branch;                  /* 0: low (A from 0 up to the merge), 1: high (back down) */
	int segment;                 /* 0: the main curve; 1, 2, ...: isolas */
	int stable;                  /* 1 outside the fold pairs (by the fold count along the curve) */
} prsm_vib_hb_point;

typedef struct {
	double omega, amplitude, mean;
	int kind;                    /* +1: Omega has a maximum along the curve (the end of the upper
	                                branch on a sweep up), -1: a minimum */
} prsm_vib_fold;

typedef struct {
	size_t points;
	prsm_vib_hb_point *point;    /* along the curve */
	int folds;
	prsm_vib_fold fold[16];
} prsm_vib_hb;

/* The one-harmonic balance curve of the gear pair (kappa = 0) parametrised by A, the points with
 * omega_min <= Omega <= omega_max, its folds refined (extrema of Omega(A)). Returns 0,
 * PRSM_EINVAL (kappa != 0, bad range), PRSM_ENOMEM. */
int prsm_vib_harmonic_balance(prsm_vib_hb *out, const prsm_vib_gear_pair *g, double omega_min,
                              double omega_max, int samples, prsm_error *err);
void prsm_vib_hb_free(prsm_vib_hb *h);
/* The describing functions N_0, N_1 of the unit dead zone at mean x_m and amplitude A (§8.4). */
void prsm_vib_dead_zone_describing(double x_m, double A, double *N0, double *N1);

typedef struct {
	double from, to;             /* the two sweep points the jump lies between */
	int direction;               /* +1: on the sweep up, -1: on the sweep down */
} prsm_vib_jump;

typedef struct {
	prsm_vib_hb hb;              /* harmonic balance (gear pair, kappa = 0; else 0 points) */
	prsm_vib_sweep sweep;        /* the integrated sweeps up and down */
	int jumps;
	prsm_vib_jump jump[32];      /* the boundaries of the runs where the two directions disagree */
	prsm_vib_exact_fold exact_fold[32]; /* per jump: the fold of the branch the sweep leaves there,
	                                by shooting from the sweep's last point on it (periodic only) */
} prsm_vib_frequency_response;

/* HB (gear pair with kappa = 0) over [o->from, o->to] and the sweeps of o (both directions are
 * run whatever o->up and o->down say; parameter FREQUENCY_RATIO). A point's two directions
 * disagree when their classification or period differ or their amplitudes differ by more than
 * agree_tol relative (NaN: 1e-3). */
int prsm_vib_frequency_response_run(prsm_vib_frequency_response *out, const prsm_vib_model *m,
                                    const prsm_vib_sweep_options *o, double agree_tol,
                                    const prsm_cancel_flag *cancel, prsm_progress_fn progress,
                                    void *progress_ctx, prsm_error *err);
void prsm_vib_frequency_response_free(prsm_vib_frequency_response *f);

/* ---------------------------------------------------------------------------------------- */
/* Linearisation, modes, FRF, half-power (§8.4 "linear")                                     */

enum { PRSM_VIB_EIG_RIGID = 0, PRSM_VIB_EIG_REAL = 1, PRSM_VIB_EIG_OSCILLATORY = 2 };
/* FRF inputs: a unit mesh error on roller `index` (m; gear pair: epsilon, response of x relative
 * to the error, Kahraman-Singh), a unit force on the nut (N, axial branch; gear pair: a unit
 * dimensionless force), a unit TE displacement (m, base excitation m_a TE-ddot) */
enum { PRSM_VIB_IN_MESH_ERROR = 0, PRSM_VIB_IN_NUT_FORCE = 1, PRSM_VIB_IN_TE = 2 };
/* FRF outputs: d_j (m; gear pair x), y (m), F_th (N) */
enum { PRSM_VIB_OUT_MESH_DEFLECTION = 0, PRSM_VIB_OUT_AXIAL_DEFLECTION = 1, PRSM_VIB_OUT_THREAD_FORCE = 2 };

typedef struct {
	int dofs;                    /* generalised coordinates: reduced (psi, phi_0 .. phi_{Z-1}[, y]);
	                                gear pair 1 */
	double *M, *C, *K;           /* dofs x dofs, row-major: SI (reduced), dimensionless (gear pair) */
	int eigenvalues;             /* 2 dofs */
	double *eig_re, *eig_im;     /* 1/s (reduced), per unit tau (gear pair); sorted: rigid and real
	                                first by |lambda|, then the complex ones by |Im| (Im >= 0 first) */
	double *frequency_Hz;        /* |Im| / 2 pi (gear pair: |Im|, rad per tau) */
	double *damping_ratio;       /* -Re / |lambda| */
	int *kind;                   /* PRSM_VIB_EIG_* */
	int shape_size;              /* rollers (+1 with the axial branch): d_j then y */
	double *shape_re, *shape_im; /* eigenvalues x shape_size: right eigenvectors' d_j (m) and y (m),
	                                scaled to a largest entry of 1 (phase 0) */
} prsm_vib_linear;

/* The linearised model about the steady state (§8.4): mean mesh stiffness, all contacts closed,
 * the friction Jacobian by central differences (step 1e-7 |v*| per generalised rate), the one-way
 * coupling dQ/dy. Returns 0, PRSM_ENOCONVERGE (the eigensolver), PRSM_ENOMEM. */
int prsm_vib_linearise(prsm_vib_linear *out, const prsm_vib_model *m, prsm_error *err);
void prsm_vib_linear_free(prsm_vib_linear *l);

/* H(omega) = output / input at n angular frequencies (rad/s; gear pair: per unit tau) of the
 * linearised model l of m, into re, im (n each). Returns 0, PRSM_EINVAL (an input or output the
 * model has not), PRSM_ENOCONVERGE (a singular system), PRSM_ENOMEM. */
int prsm_vib_frf(double *re, double *im, const prsm_vib_model *m, const prsm_vib_linear *l, int input,
                 int input_index, int output, int output_index, const double *omega, size_t n,
                 prsm_error *err);

typedef struct {
	int defined;                 /* 0: see reason */
	char reason[120];
	double peak_omega;           /* omega_p (parabola through the top three points) */
	double peak_magnitude;       /* |H_p| */
	double omega_1, omega_2;     /* half-power frequencies (linear interpolation) */
	double damping_ratio;        /* zeta_hp = (omega_2 - omega_1) / (2 omega_p) */
	double modal_damping_ratio;  /* of the eigenvalue nearest omega_p (when l was given), else NaN */
	double modal_omega;          /* its |Im|, same unit as omega */
	size_t grid;                 /* frequencies evaluated */
} prsm_vib_half_power;

/* Half-power damping of the highest peak of |H| on a grid (omega increasing, n >= 3). */
void prsm_vib_half_power_of(prsm_vib_half_power *out, const double *omega, const double *magnitude, size_t n);

/* The FRF of (input, output) on a grid over [omega_lo, omega_hi] with a step <= zeta omega / 50
 * for the least-damped mode inside (at most 200000 points), its half-power damping, and the modal
 * damping of the eigenvalue at the peak; undefined when another distinct mode lies inside the
 * half-power band or the band leaves the range. Returns 0 or the errors of prsm_vib_frf. */
int prsm_vib_half_power_run(prsm_vib_half_power *out, const prsm_vib_model *m, const prsm_vib_linear *l,
                            int input, int input_index, int output, int output_index,
                            double omega_lo, double omega_hi, prsm_error *err);

#endif
