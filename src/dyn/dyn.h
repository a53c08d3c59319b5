/*
 * dyn.h: the rigid-body transient of single- and multi-stage planetary roller screws
 * (docs/model §8.0–8.2): start-up, the carriers settling, the efficiency rising, the forces in
 * the couplings of a nested chain (docs/model §7).
 *
 * The layer sits between model/ (the statics engine it builds on: contacts, kinematics, losses,
 * the chain) and mc/; it is pure C with no JSON. A run is three steps:
 *
 *   prsm_dyn_options o;  prsm_dyn_options_init(&o);  ... set what the request gives ...
 *   prsm_dyn_model *m;   prsm_dyn_model_new(&m, K, designs, analyses, &o, &err);
 *   prsm_dyn_result r;   prsm_dyn_simulate(&r, m, cancel, progress, ctx, &err);
 *   ... r.point[i], r.stage[i * K + k], r.settled ...
 *   prsm_dyn_result_free(&r);  prsm_dyn_model_free(m);
 *
 * The model (docs/model §8.1, §8.2.4). Generalised coordinates: the screw angle theta (common to
 * every stage: the screws are splined together) and one carrier angle psi_k per stage. The
 * ring gear ties each roller's spin to its carrier, omega_R = (1 - i_g) psi-dot; the nut contact
 * rolls; the lead ties the nuts to the screw, z-dot_N,k = -hand Lambda_k theta-dot with
 * Lambda_k = sum_{i<=k} L_i / 2 pi. The screw-roller slip is v = A psi-dot + B theta-dot
 * (model/kinematics.h, prsm_kinematics_slip_basis) and the normal force does no work on either
 * free motion (n.A = n.B = 0): the carriers are driven by friction alone and settle at the
 * minimum-slip ratio k* = -(A.B)/|A|^2, not at the statics engine's contact-radius ratio.
 * Friction per roller (all n_t threads lumped, docs/model §8.2.3): viscous f = -c_f v,
 * regularised Coulomb f = -mu N v / sqrt(|v|^2 + v_eps^2), Stribeck mu(|v|), optional Karnopp
 * stick of the screw (torque input). Normal forces come backwards from the last stage (axial
 * balance of each group nut + rollers + carrier), the spline torque M_k and thrust-bearing
 * force B_k of each coupling from screw k's balances, the input torque from screw 1.
 *
 * Conventions (docs/model §8.0): SI inside (m, kg, s, N, rad) and in every member without a
 * unit suffix; members named _mm are in mm like the statics engine. theta-dot > 0 drives the nut
 * forward (along -hand z); the axial load F_N > 0 resists forward travel. Nut positions are
 * forward travel, mm. Stage index k = 0..K-1 in C (stage 1 of the text is index 0, the driven
 * one); per-stage arrays of the result are point-major: stage[i * K + k].
 *
 * Where docs/model §8 leaves room, this is what the code does:
 *  - screw k's axial balance includes the reaction -s_{k+1} of the spline that drives screw k+1
 *    (the text's balance leaves it out, which only matters from three stages on): with it the
 *    power balance closes exactly and B_k = F + s_k as in the statics chain (model/stages.h);
 *  - with losses STATICS each stage's loss torque acts on its own screw (in the torque through
 *    its spline, as in the statics chain), sign sigma(theta-dot), at the stage's instantaneous
 *    axial load Z |F_z| with the load distribution of the statics chain's load for that stage
 *    scaled to it (exact at the settled state);
 *  - the coupling and loss powers are sigma(theta-dot) theta-dot times the torque (the text's
 *    |theta-dot|), so the balance is an identity also near theta-dot = 0;
 *  - the transient times are shares of the settled carrier ratio (k* without a carrier drag,
 *    which may keep a carrier below 99 % of k*);
 *  - Karnopp: the screw sticks once |theta-dot| < v_K with T_b <= T_m <= T_f (theta-dot is then
 *    set to 0), and slips when T_m leaves the band; both located by bisection to 1e-12 s;
 *  - the settled state of a sine input or load is taken at its mean.
 *
 * Numbers that do not come out of a solve are never silently returned: a run that does not
 * converge, or that the cancel flag stops, returns its PRSM_E* code with err saying why and no
 * curve (docs/model §9).
 */
#ifndef PRSM_DYN_DYN_H
#define PRSM_DYN_DYN_H

#include <stddef.h>

#include "model/analysis.h"
#include "model/design.h"
#include "model/stages.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/problems.h"
#include "util/progress.h"

#define PRSM_DYN_STAGES_MAX PRSM_STAGES_MAX

/* Limits of the output grid (docs/model §8.7: refused by the request reader, and here). */
#define PRSM_DYN_OUTPUT_STEP_MIN_S 1e-9
#define PRSM_DYN_OUTPUT_POINTS_MAX 1000000
/* Stick and slip transitions a result keeps the times of. */
#define PRSM_DYN_MODE_CHANGES_MAX 64

enum { PRSM_DYN_INPUT_SPEED = 0, PRSM_DYN_INPUT_TORQUE = 1 };
/* Signal shapes (docs/model §8.2.1); "constant" is PRSM_DYN_SHAPE_STEP. */
enum { PRSM_DYN_SHAPE_STEP = 0, PRSM_DYN_SHAPE_RAMP = 1, PRSM_DYN_SHAPE_SINE = 2 };
enum { PRSM_DYN_FRICTION_COULOMB = 0, PRSM_DYN_FRICTION_VISCOUS = 1, PRSM_DYN_FRICTION_STRIBECK = 2 };
enum { PRSM_DYN_STICK_NONE = 0, PRSM_DYN_STICK_KARNOPP = 1 };
enum { PRSM_DYN_LOSSES_STATICS = 0, PRSM_DYN_LOSSES_SLIDING_ONLY = 1 };
/* Steppers (docs/model §8.2.6). AUTO: rk8pd for speed input; for torque input msbdf while the
 * screw is slower than time.stiff_switch_rad_s, then rk8pd (and back to msbdf below a tenth of
 * it, e.g. when a Karnopp screw comes to rest). MSBDF and RK4IMP (implicit, the Jacobian by
 * central differences): the whole run for speed input; for torque input they hand over to
 * rk8pd as AUTO does. RK8PD: the whole run. */
enum { PRSM_DYN_STEPPER_AUTO = 0, PRSM_DYN_STEPPER_RK8PD = 1, PRSM_DYN_STEPPER_MSBDF = 2,
       PRSM_DYN_STEPPER_RK4IMP = 3 };
/* The screw flank that carries the load (docs/model §8.0): UPPER is the statics contact
 * (normal out of the screw tooth, +z), LOWER its image under the half-turn about x. */
enum { PRSM_DYN_FLANK_UPPER = 0, PRSM_DYN_FLANK_LOWER = 1 };

/* A signal of time: the input speed (rad/s) or torque (N m), or the axial load (N). */
typedef struct {
	int shape;                /* PRSM_DYN_SHAPE_* */
	double value;             /* step: the value for t > 0 (and at t = 0+); ramp: the final
	                             value; sine: the mean. Unit of the signal */
	double ramp_time_s;       /* ramp: value min(t / ramp_time_s, 1); > 0, s */
	double sine_amplitude;    /* sine: value + sine_amplitude sin(2 pi f t); unit of the signal */
	double sine_frequency_Hz; /* f of the sine, Hz */
} prsm_dyn_signal;

#define PRSM_DYN_SIGNAL_INIT(v) {PRSM_DYN_SHAPE_STEP, (v), 0.01, 0.0, 0.0}

/* docs/model §8.2.1 */
typedef struct {
	int kind;                         /* PRSM_DYN_INPUT_SPEED or PRSM_DYN_INPUT_TORQUE */
	prsm_dyn_signal signal;           /* screw speed theta-dot, rad/s (speed input) or motor
	                                     torque T_m, N m (torque input) */
	double motor_inertia_kg_m2;       /* J_M on the first screw, kg m^2 (0) */
	double viscous_drag_Nm_s_per_rad; /* c_v: drag torque c_v theta-dot on the screw, N m s/rad (0) */
	double initial_speed_rad_s;       /* torque input: screw speed at t = 0, rad/s (0: at rest) */
} prsm_dyn_input;

/* docs/model §8.2.3 */
typedef struct {
	int model;                     /* PRSM_DYN_FRICTION_* at the screw-roller contacts */
	double viscous_N_s_per_m;      /* c_f per roller (viscous), N s/m (25) */
	double mu;                     /* Coulomb mu (Stribeck: the kinetic mu_c), -; NaN: each
	                                  stage design's mu_screw_roller */
	double smoothing_velocity_m_s; /* v_eps of the regularised Coulomb law, m/s (1e-4) */
	double static_mu;              /* mu_s of the Stribeck law and of the Karnopp break-away, -;
	                                  NaN: mu (Stribeck off) */
	double stribeck_velocity_m_s;  /* v_S, m/s (1e-3) */
	int stick_model;               /* PRSM_DYN_STICK_* (KARNOPP: torque input only) */
	double stick_band_rad_s;       /* v_K: the screw may stick while |theta-dot| < v_K, rad/s;
	                                  NaN: 10 v_eps / |B| (stage 1) */
	double carrier_drag_Nm_s_per_rad; /* c_C: drag torque -c_C psi-dot on every carrier,
	                                     N m s/rad (0; docs/model §8.9 O1) */
	double coupling_smoothing_rad_s;  /* omega_eps of sigma(x) = x / sqrt(x^2 + omega_eps^2),
	                                     the sign of the coupling and statics-loss torques, rad/s (1e-3) */
} prsm_dyn_friction;

/* Masses and inertias of one stage (docs/model §8.2.2); NaN: from the geometry (solid steel of
 * options.inertia.density_kg_m3). */
typedef struct {
	double gear_face_width_mm;     /* b_w at each roller end, mm; NaN: 2 P */
	double roller_mass_kg;         /* m_R; NaN: rho pi r_r^2 l_R, l_R = n_t P + 2 b_w */
	double roller_inertia_kg_m2;   /* J_R about its own axis; NaN: m_R r_r^2 / 2 */
	double carrier_mass_kg;        /* m_C; NaN: two rings r_s .. r_n, P thick */
	double carrier_inertia_kg_m2;  /* J_C; NaN: m_C (r_n^2 + r_s^2) / 2 */
	double nut_mass_kg;            /* m_N; NaN: annulus r_n .. nut_outer_radius, length l_R */
	double screw_mass_kg;          /* m_S; NaN: solid cylinder r_s, length l_R + stroke */
	double screw_inertia_kg_m2;    /* J_S; NaN: m_S r_s^2 / 2 */
} prsm_dyn_stage_inertia;

#define PRSM_DYN_STAGE_INERTIA_INIT {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN}

typedef struct {
	double density_kg_m3;          /* rho of every part, kg/m^3 (7850) */
	double stroke_mm;              /* screw length beyond the nut, mm (100) */
	double payload_kg;             /* m_p on the last nut, kg (0) */
	prsm_dyn_stage_inertia stage[PRSM_DYN_STAGES_MAX]; /* per stage, index k */
} prsm_dyn_inertia;

/* Couplings of the nested chain (docs/model §7, §8.2.3); index k for the coupling that drives
 * stage k >= 1 (stage k+1 of the text) from stage k-1. */
typedef struct {
	double spline_friction;            /* mu_SS, - (0) */
	double thrust_bearing_friction;    /* mu_NS, - (0) */
	double spline_radius_mm[PRSM_DYN_STAGES_MAX]; /* r_SS,k, mm; NaN: r_s of stage k-1 */
	double thrust_radius_mm[PRSM_DYN_STAGES_MAX]; /* r_NS,k, mm; NaN: (r_n,k-1 + r_s,k) / 2 */
} prsm_dyn_couplings;

/* docs/model §8.2.6 */
typedef struct {
	double end_s;                  /* simulated time, s (0.005) */
	double output_step_s;          /* output every this, from t = 0, s (1e-6); the end is
	                                  always an output time */
	int stepper;                   /* PRSM_DYN_STEPPER_* */
	double rel_tol, abs_tol;       /* of gsl_odeiv2_control_y_new on the scaled states (1e-10) */
	double initial_step_s;         /* NaN: 1e-3 / sigma_c, the carrier's friction rate */
	double stiff_switch_rad_s;     /* an implicit stepper hands over to rk8pd once |theta-dot|
	                                  exceeds this, rad/s; NaN: 100 v_eps / |B|; INFINITY: never */
	double speed_scale_rad_s;      /* speeds are integrated divided by this, rad/s; NaN: the
	                                  input speed (speed input) or the settled speed (torque) */
	long max_steps;                /* accepted steps allowed before PRSM_ENOCONVERGE (10^7) */
} prsm_dyn_time;

typedef struct {
	prsm_dyn_input input;
	prsm_dyn_signal load;          /* axial load F_N on the last nut, N (> 0 resists forward travel) */
	prsm_dyn_friction friction;
	int losses;                    /* PRSM_DYN_LOSSES_*: STATICS adds each stage's spin, gear,
	                                  drag and seal torques (model/losses.h) to its screw */
	prsm_dyn_inertia inertia;
	prsm_dyn_couplings couplings;
	prsm_dyn_time time;
} prsm_dyn_options;

#define PRSM_DYN_OPTIONS_INIT                                                                     \
	{{PRSM_DYN_INPUT_SPEED, PRSM_DYN_SIGNAL_INIT(100.0), 0.0, 0.0, 0.0},                         \
	 PRSM_DYN_SIGNAL_INIT(7000.0),                                                               \
	 {PRSM_DYN_FRICTION_COULOMB, 25.0, NAN, 1e-4, NAN, 1e-3, PRSM_DYN_STICK_NONE, NAN, 0.0, 1e-3}, \
	 PRSM_DYN_LOSSES_STATICS,                                                                    \
	 {7850.0, 100.0, 0.0,                                                                        \
	  {PRSM_DYN_STAGE_INERTIA_INIT, PRSM_DYN_STAGE_INERTIA_INIT, PRSM_DYN_STAGE_INERTIA_INIT,    \
	   PRSM_DYN_STAGE_INERTIA_INIT, PRSM_DYN_STAGE_INERTIA_INIT, PRSM_DYN_STAGE_INERTIA_INIT,    \
	   PRSM_DYN_STAGE_INERTIA_INIT, PRSM_DYN_STAGE_INERTIA_INIT}},                               \
	 {0.0, 0.0, {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN}, {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN}}, \
	 {0.005, 1e-6, PRSM_DYN_STEPPER_AUTO, 1e-10, 1e-10, NAN, NAN, NAN, 10000000L}}

/* Set *o to PRSM_DYN_OPTIONS_INIT. Returns 0. */
int prsm_dyn_options_init(prsm_dyn_options *o);

/* Check the options for a chain of `stages` stages: every problem to problems, at the JSON
 * pointer of the request's dynamics object (docs/model §8.7; per-stage inertia of a chain at
 * /dynamics/inertia/stages/<k>/...). Returns 0 or PRSM_EINVAL. */
int prsm_dyn_options_check(const prsm_dyn_options *o, int stages, prsm_problems *problems);

/* What the model made of one stage: geometry, kinematic structure, masses (echoed with the
 * result). Vectors are in the pair frame of roller 0 (screw axis at the origin, roller axis at
 * (a, 0), docs/model §8.0), index [flank][x, y, z]. */
typedef struct {
	int rollers;                   /* Z */
	double lead_mm;                /* L_k */
	double cumulative_lead_m_per_rad; /* Lambda_k = sum_{i<=k} L_i / 2 pi, m/rad */
	double ring_gear_ratio;        /* i_g = r_n / r_r */
	double gear_pitch_radius_mm;   /* r_g1 = a / (i_g - 1) (= r_r for a standard design), mm */
	double orbit_radius_mm;        /* a = r_s + r_r, mm */
	double contact_mm[2][3];       /* screw-roller contact p, mm */
	double normal[2][3];           /* unit normal along which the screw pushes the roller, - */
	double nut_contact_mm[2][3];   /* nut-roller contact p_n, mm (the nut flank paired with the
	                                  screw flank of the same index carries the other side) */
	double nut_normal[2][3];       /* unit normal along which the nut pushes the roller, - */
	double A_mm[2][3], B_mm[2][3]; /* slip basis of docs/model §8.1, mm per rad */
	double normal_dot_A_mm[2], normal_dot_B_mm[2]; /* n.A, n.B: 0 to rounding (the check) */
	double carrier_ratio_min_slip; /* k* = -(A.B)/|A|^2 */
	double carrier_ratio_statics;  /* the statics engine's contact-radius ratio */
	double min_slip_mm_per_rad;    /* |B - (A.B) A/|A|^2|: slip per screw speed at k*, mm/rad */
	double mu;                     /* Coulomb mu at the screw contact (Stribeck: mu_c), - */
	double static_mu;              /* mu_s, - */
	double gear_pressure_angle_rad;/* alpha of the ring-gear teeth, rad */
	/* docs/model §8.2.2 */
	double gear_face_width_mm, roller_length_mm;
	double roller_mass_kg, roller_inertia_kg_m2;
	double carrier_mass_kg, carrier_inertia_kg_m2;
	double nut_mass_kg, screw_mass_kg, screw_inertia_kg_m2;
	double carrier_side_inertia_kg_m2; /* J_psi = J_C + Z (m_R a^2 + J_R (1 - i_g)^2), kg m^2 */
	double axial_mass_kg;          /* M_k = m_N + Z m_R + m_C (+ m_p on the last), kg */
	/* couplings (stage k >= 1) */
	double spline_radius_mm, thrust_radius_mm;
	/* losses = STATICS: the load the spin loss's distribution was solved at, N */
	double loss_reference_load_N;
} prsm_dyn_stage_params;

/* A state of the model. */
typedef struct {
	double time_s;                 /* for the input and load signals, s */
	double screw_angle_rad;        /* theta (speed input: NaN for the signal's integral) */
	double screw_speed_rad_s;      /* theta-dot (speed input: NaN for the signal's value) */
	double screw_accel_rad_s2;     /* theta-ddot; NaN: from the input (speed: the signal's
	                                  derivative; torque: solved from the motor torque) */
	double carrier_angle_rad[PRSM_DYN_STAGES_MAX];
	double carrier_speed_rad_s[PRSM_DYN_STAGES_MAX];
} prsm_dyn_state;

/* One stage at one time (docs/model §8.2.5). Forces per roller unless said. */
typedef struct {
	double carrier_angle_rad;      /* psi_k */
	double carrier_speed_rad_s;    /* psi-dot_k */
	double carrier_accel_rad_s2;   /* psi-ddot_k, Lagrange form J_psi psi-ddot = Z f.A - c_C psi-dot */
	double carrier_ratio;          /* psi-dot_k / theta-dot; NaN while theta-dot = 0 */
	double nut_position_mm;        /* forward travel of nut k since t = 0, mm */
	int flank;                     /* PRSM_DYN_FLANK_* of the loaded screw flank */
	double contact_normal_force_N; /* N_k at the screw contact */
	double friction_force_N[3];    /* f_k on the roller, pair frame */
	double slip_speed_m_s;         /* |v_k| */
	double stage_axial_load_N;     /* Z_k |F_k,z|: all rollers of the stage */
	double nut_contact_force_N;    /* N' (Newton-Euler recovery) */
	double gear_tangential_force_N;/* F_t at the gear pitch point, both ring gears, +y */
	double gear_tooth_force_N;     /* |F_t| / (2 cos alpha): one gear (seed 000's F_RG) */
	double cage_force_N;           /* |P|: pin force, both ends (seed 000's F_RP) */
	double spline_torque_Nm;       /* M_k: torque into screw k (k = 0: before J_M and c_v) */
	double spline_force_N;         /* s_k along z on screw k (k >= 1), N */
	double thrust_load_N;          /* |B_k| through the thrust bearing (k >= 1), N */
	double thrust_torque_Nm;       /* T_NS,k (k >= 1), N m */
	double loss_torque_Nm;         /* statics losses charged to screw k, signed sigma(theta-dot), N m */
	double sliding_power_W;        /* Z_k (-f_k . v_k) */
	double newton_euler_carrier_accel_rad_s2; /* psi-ddot from the Newton-Euler recovery */
	double newton_euler_residual;  /* |NE - Lagrange psi-ddot| / (|psi-ddot| + the size of the
	                                  terms that cancel in it, Z a (|F_y| + |N' n'_y| + (|screw
	                                  moment| + |nut moment|) / r_g1) / J_psi), - */
} prsm_dyn_stage_point;

/* The screw and the powers at one time (docs/model §8.2.4, §8.2.5). */
typedef struct {
	double time_s;
	double screw_angle_rad, screw_speed_rad_s, screw_accel_rad_s2;
	double axial_load_N;           /* F_N(t) */
	double motor_torque_Nm;        /* torque input: T_m(t); speed input: = input_torque_Nm */
	double input_torque_Nm;        /* T_in = M_1 + c_v theta-dot + J_M theta-ddot (+ the statics
	                                  losses of stage 1 inside M_1); stuck: T_m */
	double efficiency;             /* F_N Lambda_K / T_in; NaN while theta-dot = 0 */
	double energy_input_J, energy_output_J; /* integrals of the input and output powers */
	double energy_efficiency;      /* energy_output_J / energy_input_J; NaN while it is 0 */
	double power_input_W;          /* T_in theta-dot */
	double power_output_W;         /* F_N Lambda_K theta-dot */
	double power_sliding_W;        /* sum_k Z_k (-f_k . v_k) */
	double power_couplings_W;      /* spline sliding and thrust-bearing torques */
	double power_other_W;          /* statics losses, c_v theta-dot^2, carrier drags */
	double power_kinetic_W;        /* J_theta theta-dot theta-ddot + sum J_psi psi-dot psi-ddot */
	double power_balance_residual_W;  /* input - all the rest */
	double power_balance_relative; /* |residual| / max(|P_in|, sum of the terms' magnitudes) */
	double newton_euler_residual;  /* the largest of the stages' */
	int stuck;                     /* Karnopp: 1 while the screw sticks */
} prsm_dyn_point;

/* The settled state, computed algebraically (docs/model §8.2.5), not by waiting. */
typedef struct {
	int defined;                   /* 0: no steady state (a torque input that no speed
	                                  balances: the screw runs away); the rest is NaN */
	int at_rest;                   /* torque input below what starts the screw: speed 0 */
	prsm_dyn_point point;          /* theta-ddot = 0 at the final input (sine: the mean) */
	prsm_dyn_stage_point stage[PRSM_DYN_STAGES_MAX];
	double screw_speed_rad_s;      /* speed input: the final value; torque input: the balance */
	double carrier_ratio[PRSM_DYN_STAGES_MAX];         /* settled psi-dot_k / theta-dot */
	double carrier_ratio_min_slip[PRSM_DYN_STAGES_MAX];/* k*_k */
	double carrier_ratio_statics[PRSM_DYN_STAGES_MAX]; /* the statics contact-radius ratio */
	double input_torque_Nm;
	double efficiency;             /* F_N Lambda_K / T_in */
	double efficiency_statics;     /* the statics engine's at the same load and speed: the chain
	                                  (model/stages.h) with each stage's torque from its sliding
	                                  efficiency (losses SLIDING_ONLY) or with every loss and the
	                                  load distribution (STATICS); NaN for viscous friction */
	double carrier_rate_per_s[PRSM_DYN_STAGES_MAX];    /* sigma_c: linearised friction rate of
	                                  each carrier about the settled state, 1/s */
} prsm_dyn_settled;

typedef struct {
	int stages;                    /* K */
	size_t points;                 /* output times */
	prsm_dyn_point *point;         /* points entries */
	prsm_dyn_stage_point *stage;   /* points * stages entries: [i * stages + k] */
	prsm_dyn_settled settled;
	/* first time psi-dot_k / theta-dot reaches 50, 90, 99 % of the settled ratio (k* without
	 * carrier drag), s; NaN when not within the run */
	double carrier_time_to_share_s[PRSM_DYN_STAGES_MAX][3];
	/* torque input: first time theta-dot reaches 50, 90, 99 % of the settled speed, s */
	double speed_time_to_share_s[3];
	double max_power_balance_relative; /* over the output times */
	double max_newton_euler_residual;  /* over the output times and stages */
	/* Karnopp: the times the screw stuck or started to slip (the first
	 * PRSM_DYN_MODE_CHANGES_MAX of them; mode_changes counts all), s */
	int mode_changes;
	double mode_change_time_s[PRSM_DYN_MODE_CHANGES_MAX];
	int mode_change_to_stick[PRSM_DYN_MODE_CHANGES_MAX]; /* 1: stuck there; 0: started to slip */
	long steps, rhs_evaluations, jacobian_evaluations, events; /* integration effort */
	double stepper_switch_time_s;  /* when an implicit stepper handed over to rk8pd; NaN: never */
} prsm_dyn_result;

typedef struct prsm_dyn_model prsm_dyn_model;

/*
 * Build the model of a chain of `stages` stages (1 .. PRSM_DYN_STAGES_MAX) from the resolved,
 * checked designs and their nominal analyses (prsm_analysis_nominal), stage 1 first, and the
 * options (copied; NULL: PRSM_DYN_OPTIONS_INIT): the kinematic structure, masses, the statics
 * references and the settled state. Allocates *out (prsm_dyn_model_free). Returns 0;
 * PRSM_EINVAL for bad options (err->pointer at the field) or a design the rigid model cannot
 * take (roller migration, mixed hands); PRSM_ENOCONVERGE or PRSM_EGEOMETRY from the statics
 * references (losses = STATICS); PRSM_ENOMEM.
 */
int prsm_dyn_model_new(prsm_dyn_model **out, int stages, const prsm_design *designs,
                       const prsm_analysis *analyses, const prsm_dyn_options *opts, prsm_error *err);

/* Release a model (NULL is fine). */
void prsm_dyn_model_free(prsm_dyn_model *m);

int prsm_dyn_model_stages(const prsm_dyn_model *m);
/* Stage k (0-based) as the model has it. */
const prsm_dyn_stage_params *prsm_dyn_model_stage(const prsm_dyn_model *m, int k);
/* The options the model runs with (its copy). */
const prsm_dyn_options *prsm_dyn_model_options(const prsm_dyn_model *m);
/* J_theta = J_M + sum_k [J_S,k + M_k Lambda_k^2] + sum_{k>=1} m_S,k Lambda_{k-1}^2, kg m^2. */
double prsm_dyn_model_screw_side_inertia(const prsm_dyn_model *m);
/* The settled state (computed by prsm_dyn_model_new). */
const prsm_dyn_settled *prsm_dyn_model_settled(const prsm_dyn_model *m);

/* Forces, accelerations, powers and both checks of one state (docs/model §8.2.4): what the
 * integrator's right-hand side and every output time use. stage has K entries. Returns 0, or
 * PRSM_ENOCONVERGE (err says why: the flanks wedge, the couplings lock, the torque balance of
 * a torque input has no solution). */
int prsm_dyn_evaluate(prsm_dyn_point *point, prsm_dyn_stage_point *stage, const prsm_dyn_model *m,
                      const prsm_dyn_state *state, prsm_error *err);

/*
 * Integrate from t = 0 (carriers at rest; screw at the input speed, or at
 * input.initial_speed_rad_s for torque input) to time.end_s with GSL odeiv2, writing every
 * output time (docs/model §8.2.6). cancel (may be NULL) is polled after every step; progress
 * (may be NULL) is called with done / planned in simulated nanoseconds. Allocates the arrays
 * of *out (prsm_dyn_result_free), also on failure none are left. Returns 0; PRSM_ECANCELLED;
 * PRSM_ENOCONVERGE (the integration failed: err says when and why; no curve); PRSM_ENOMEM.
 */
int prsm_dyn_simulate(prsm_dyn_result *out, const prsm_dyn_model *m, const prsm_cancel_flag *cancel,
                      prsm_progress_fn progress, void *progress_ctx, prsm_error *err);

/* Release the arrays of a result (a zeroed result is fine). */
void prsm_dyn_result_free(prsm_dyn_result *r);

/* Karnopp break-away torques (docs/model §8.2.6) at time t (the load's value then): the motor
 * torque that starts the resting screw forward, T_f = T_in(theta-dot -> 0+, psi-dot = 0,
 * theta-ddot = 0) with mu_s and the slip along +B, and the holding limit backward T_b (slip
 * along -B), N m. Returns 0 or PRSM_ENOCONVERGE (err says why). */
int prsm_dyn_breakaway_torques(double *forward_Nm, double *backward_Nm, const prsm_dyn_model *m,
                               double t_s, prsm_error *err);

/* The value of a signal at t, and its time derivative (unit per s). */
double prsm_dyn_signal_value(const prsm_dyn_signal *s, double t_s);
double prsm_dyn_signal_rate(const prsm_dyn_signal *s, double t_s);

#endif
