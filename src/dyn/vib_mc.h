/*
 * vib_mc.h: one Monte Carlo sample of the reduced vibration model (MODEL-DYNAMICS.md §8.6 on the
 * model of §8.3 and the analyses of §8.4; docs/vibration.md, "Monte Carlo over dynamic outputs").
 *
 * A sample sets what the tolerances change in a reduced model (prsm_vib_mc_apply: the statics
 * engine's axial stiffness and play and TE lines of the sample's error set, the gear backlash,
 * the mesh error and the damping ratios), then prsm_vib_mc_eval computes its dynamic outputs:
 *
 *  - linear screening (exact for the piecewise-linear model): the closed-form steady state with
 *    every contact on its loaded flank. Axial branch: the line sum of §8.3.2. Gear branch: the
 *    periodic solution of the linear time-periodic system (rectangular mesh stiffness, the
 *    friction linearised about v*), segment by segment with matrix exponentials between the
 *    stiffness switches, for the mean load and the mesh error (mesh-periodic) and for each TE
 *    line reaching the gear branch through the thread force (z(tau) = e^{i w tau} p(tau), p
 *    mesh-periodic); rollers with equal mesh phase are one group (their motions are equal).
 *    When min (y - b_a) > 0 and min s (d_j - e_j) - b_g > 0 (s the sign of the mean mesh load)
 *    and the thread force keeps its sign over the window, the sample is P1 and its outputs are
 *    the closed form's.
 *  - otherwise integration (vib_integrate.c, from the closed form's state at t = 0): whole
 *    windows until the Poincaré test of §8.4 passes (period m <= max_period), then m windows
 *    recorded for the outputs; non-periodic after max_windows.
 *
 * With o->lyapunov_windows > 0 the sample also gets §8.6's lyapunov_max: a screened sample's
 * largest Floquet exponent (the axial -zeta_a omega_a, the log of the spectral radius of the gear
 * branch's monodromy over a mesh period and of each group's antisymmetric roller motion, per
 * second), an integrated sample's Benettin estimate over that many windows.
 *
 * The window (Poincaré period) is W screw revolutions: every TE line order and the mesh order
 * z_2 k* are rounded to multiples of 1/W (a shift below 1/(2W) per revolution) so that the whole
 * response is W-periodic; a line rounded to order 0 is dropped, lines of equal order merged.
 *
 * Units: SI (m, N, s, rad) unless a name says otherwise. No JSON, no allocation kept.
 */
#ifndef PRSM_DYN_VIB_MC_H
#define PRSM_DYN_VIB_MC_H

#include "dyn/vib.h"

/* What a sample changes in the model (every value in its unit; NaN: keep the model's). */
typedef struct {
	double axial_stiffness_N_per_m;   /* k_a */
	double axial_half_play_m;         /* b_a (> 0) */
	int te_source;                    /* 1: te_line replaces the model's lines; 0: keep them */
	int te_lines;
	prsm_vib_te_line te_line[PRSM_VIB_TE_LINES_MAX]; /* orders per screw revolution, amplitude m, phase rad */
	double gear_half_backlash_m;      /* b_g (> 0) */
	double mesh_error_m;              /* e_g (>= 0) */
	double axial_damping_ratio;       /* zeta_a in (0, 1) */
	double mesh_damping_ratio;        /* zeta_g in (0, 1) */
	double window_rev;                /* W, screw revolutions (> 0) */
} prsm_vib_mc_sample;

void prsm_vib_mc_sample_init(prsm_vib_mc_sample *s); /* everything NaN / kept, W = 8 */

/* Apply s to m (a reduced model with both branches) and re-derive. Returns 0 or PRSM_EINVAL
 * (a value out of range: err says which). */
int prsm_vib_mc_apply(prsm_vib_model *m, const prsm_vib_mc_sample *s, prsm_error *err);

typedef struct {
	int grid_per_segment;        /* closed form: samples per stiffness segment (64, a power of 2) */
	int axial_grid_per_cycle;    /* closed form: samples per cycle of the fastest TE line (64) */
	int max_windows;             /* integration: windows before "non-periodic" (12) */
	int max_period;              /* largest period m in windows (4) */
	double period_tol;           /* Poincaré test, scaled state (1e-4, §8.4 for the multi-roller model) */
	prsm_vib_integration integration; /* rel = abs = 1e-9 (§8.4: enough for classification) */
	int force_integration;       /* 1: integrate also a screened sample (tests) */
	int screen_only;             /* 1: never integrate (bench); a contact-loss sample then has
	                                integrated = 0 and regime -1 */
	int lyapunov_windows;        /* > 0: lyapunov_max, a screened sample's exactly, an integrated
	                                one's by Benettin's method over this many windows after the
	                                recording; 0 (default): NaN, not computed */
	int reference;               /* 1: the screen's reference loops (tests: the fast loops give the
	                                same bits, docs/vibration.md "Speed of the screen") */
} prsm_vib_mc_options;

void prsm_vib_mc_options_init(prsm_vib_mc_options *o);

typedef struct {
	int screened;                /* 1: the linear closed form (P1, no contact loss) */
	int integrated;              /* 1: integrated */
	int contact_loss;            /* 1: a contact (thread or a mesh) leaves its loaded flank */
	int regime;                  /* 1: P1, m: period m windows, 0: non-periodic */
	double peak_dynamic_te_m;    /* max |X - X_static| over the window, m */
	double peak_thread_force_N;  /* max s F_th over the window, N */
	double axial_vibration_rms_m_s2; /* RMS nut acceleration (F_0 - F_th) / m_a, m/s^2 */
	double mesh_force_peak_N;    /* max over rollers and time of s F_j (both meshes), N */
	double axial_margin;         /* linear response: min (s y - b_a) / b_a */
	double mesh_margin;          /* linear response: min (s (d_j - e_j) - b_g) / b_g */
	double thread_force_min_N;   /* linear response: min s F_th, N */
	double lyapunov_max_per_s;   /* §8.6 lyapunov_max, 1/s: a screened sample's largest Lyapunov
	                                exponent, the largest real part of its Floquet exponents
	                                (the axial -zeta_a omega_a, the gear branch's log|mu| / T,
	                                the rigid carrier angle left out); an integrated sample's is
	                                Benettin's estimate (§8.4); NaN when not screened and not
	                                integrated, or without o->lyapunov_windows */
	double lyapunov_gear_per_s;  /* the gear branch's share of it, 1/s (NaN likewise) */
	int windows;                 /* windows integrated (0 when screened) */
	double window_s;             /* the window, s */
	double max_return_distance;  /* Poincaré test: the largest return distance of the period found */
	prsm_vib_effort effort;
} prsm_vib_mc_out;

/* The closed form of m (after prsm_vib_mc_apply) into out (screened = 1 when every contact stays
 * on its loaded flank); state0 (may be NULL; m's state size) gets the linear steady state at
 * t = 0. Returns 0, PRSM_EINVAL (no TE window, a singular segment), PRSM_ENOMEM. */
int prsm_vib_mc_screen(prsm_vib_mc_out *out, double *state0, const prsm_vib_model *m,
                       const prsm_vib_mc_options *o, prsm_error *err);

/* Integrate m from state0 (NULL: static) as described above; fills the integration outputs.
 * Returns 0, PRSM_ENOCONVERGE, PRSM_ECANCELLED, PRSM_ENOMEM. */
int prsm_vib_mc_integrate(prsm_vib_mc_out *out, const prsm_vib_model *m, const double *state0,
                          const prsm_vib_mc_options *o, const prsm_cancel_flag *cancel, prsm_error *err);

/* Screen, and integrate when the screen fails (or o->force_integration). */
int prsm_vib_mc_eval(prsm_vib_mc_out *out, const prsm_vib_model *m, const prsm_vib_mc_options *o,
                     const prsm_cancel_flag *cancel, prsm_error *err);

#endif
