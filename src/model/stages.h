/*
 * stages.h: the chain of a multi-stage PRSM (docs/model/kinematics-efficiency-stiffness-life.md, seed 000), in steady motion.
 *
 * Stages k = 1..K are nested: every screw turns at the input speed omega (the screws are
 * coupled by splines), no nut turns, and the nut of stage k pushes the screw of stage k+1
 * through a thrust bearing, so the nut of stage k travels at v_k = omega sum_{i<=k} L_i / 2pi
 * and the output (nut K) at v = omega sum L / 2pi. The load F acts on nut K.
 *
 * Forces (quasi-static, positive along the motion, F opposing it). Screw k >= 2 slides
 * axially in the spline of screw k-1 at omega L_{k-1} / 2pi while the spline carries the torque
 * M_k of stages k..K; Coulomb friction there is s_k = mu_SS M_k / r_SS,k (seed 000: f_Sk =
 * mu_SS |M_Sk| / r_SSk) and opposes the sliding. The balance of screw k and nut k-1 gives
 *   thrust bearing load   B_k = F + s_k                      (k >= 2)
 *   axial load of stage k F_k = F + s_{k+1}   (s_{K+1} = 0)
 * and the thrust bearing between the non-rotating nut k-1 and screw k (relative speed omega)
 * costs the torque N_k = mu_NS B_k r_NS,k (seed 000: M_Nk = mu_NS |F_Nk| r_NSk). The torque
 * through spline k is
 *   M_k = T_k(F_k) + N_k + M_{k+1},   M_{K+1} = 0,   M_1 = T_in,
 * with T_k(F) the input torque of stage k alone at axial load F (its sliding, spin, gear and
 * drag losses, model/losses.h). M_k appears in s_k and so in N_k: solved in closed form,
 *   M_k = (T_k + M_{k+1} + mu_NS r_NS F) / (1 - mu_NS mu_SS r_NS / r_SS),
 * going from stage K down to stage 1, since F_k needs only s_{k+1}. The chain locks when
 * mu_NS mu_SS r_NS / r_SS >= 1. Efficiency (docs/model/kinematics-efficiency-stiffness-life.md): eta = F sum L / (2 pi T_in).
 *
 * Power balance, exact: T_in omega = F v + sum (T_k omega - F_k omega L_k / 2pi) (stage
 * losses) + sum s_k omega L_{k-1} / 2pi (splines) + sum N_k omega (thrust bearings).
 *
 * With mu_SS = mu_NS = 0 every stage carries F and T_in = sum F L_k / (2 pi eta_k): the chain
 * efficiency is sum L_k / sum (L_k / eta_k), the travel-weighted harmonic mean of the stage
 * efficiencies (the stages share the input power side by side; it is not their product, which
 * would describe stages in series, each driving the next one's input).
 *
 * Units: N, mm, N m, rad/s. No allocation.
 */
#ifndef PRSM_MODEL_STAGES_H
#define PRSM_MODEL_STAGES_H

#include "util/error.h"

#define PRSM_STAGES_MAX 8

/* Input torque of stage k (0-based) alone at axial load F_N, N m; NaN when it cannot be
 * computed (the chain then fails with PRSM_EINVAL). */
typedef double (*prsm_stage_torque_fn)(void *ctx, int stage, double load_N);

typedef struct {
	int stages;                                  /* K, 1 .. PRSM_STAGES_MAX */
	double lead_mm[PRSM_STAGES_MAX];             /* L_k, mm */
	double spline_friction;                      /* mu_SS, - */
	double thrust_bearing_friction;              /* mu_NS, - */
	double spline_radius_mm[PRSM_STAGES_MAX];    /* r_SS,k for k >= 2 (index k-1), mm */
	double thrust_radius_mm[PRSM_STAGES_MAX];    /* r_NS,k for k >= 2 (index k-1), mm */
	double axial_load_N;                         /* F on the last nut, N, >= 0 */
	double screw_speed_rad_s;                    /* omega, rad/s */
} prsm_chain_input;

typedef struct {
	double load_N;               /* F_k: axial load carried by stage k, N */
	double thrust_load_N;        /* B_k: thrust bearing between nut k-1 and screw k, N (0 for k = 1) */
	double spline_force_N;       /* s_k: spline friction on screw k, N (0 for k = 1) */
	double spline_torque_Nm;     /* M_k: torque into screw k (k = 1: the input torque), N m */
	double thrust_torque_Nm;     /* N_k, N m */
	double stage_torque_Nm;      /* T_k(F_k), N m */
	double stage_efficiency;     /* F_k L_k / (2 pi T_k) */
	double nut_speed_mm_s;       /* v_k, mm/s */
	double stage_loss_W;         /* T_k omega - F_k omega L_k / 2pi, W */
	double spline_loss_W;        /* s_k omega L_{k-1} / 2pi, W */
	double thrust_loss_W;        /* N_k omega, W */
} prsm_chain_stage;

typedef struct {
	int stages;
	prsm_chain_stage stage[PRSM_STAGES_MAX];
	double total_lead_mm;        /* sum L_k, mm */
	double output_speed_mm_s;    /* omega sum L / 2pi, mm/s */
	double input_torque_Nm;      /* T_in = M_1, N m */
	double ideal_torque_Nm;      /* F sum L / 2pi, N m */
	double efficiency;           /* F sum L / (2 pi T_in) */
	double input_power_W, output_power_W, loss_power_W; /* at omega */
	double harmonic_efficiency;  /* sum L_k / sum (L_k / eta_k(F_k)): the frictionless-coupling rule */
} prsm_chain;

/* Solve the chain. Returns 0, or PRSM_EINVAL (err says why: bad input, a stage torque NaN,
 * or couplings that lock). */
int prsm_stages_chain(prsm_chain *out, const prsm_chain_input *in, prsm_stage_torque_fn torque,
                      void *ctx, prsm_error *err);

#endif
