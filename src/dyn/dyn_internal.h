/*
 * dyn_internal.h: the model struct behind dyn.h and the evaluation that dyn/model.c (the
 * settled state, prsm_dyn_evaluate) and dyn/simulate.c (the right-hand side, every output time)
 * share. Nothing outside src/dyn includes it.
 *
 * The model is read-only once built, so one model may serve several simulations on several
 * threads; everything an evaluation changes lives in the caller's dyn_scratch.
 */
#ifndef PRSM_DYN_INTERNAL_H
#define PRSM_DYN_INTERNAL_H

#include "dyn/dyn.h"
#include "model/losses.h"

/* One stage, in SI (m, kg, rad) unless the name says otherwise. */
typedef struct {
	prsm_dyn_stage_params par;     /* the public echo (mm) */
	double p[2][3], n[2][3];       /* screw contact (m) and the normal the screw pushes along */
	double pn[2][3], nn[2][3];     /* nut contact (m) and the normal the nut pushes along */
	double A[2][3], B[2][3];       /* slip basis, m per rad */
	double B_norm;                 /* |B| of the lower flank, m per rad */
	double a, r_g;                 /* orbit and roller gear pitch radius, m */
	double i_g;                    /* ring-gear ratio, - */
	double Z;                      /* rollers, as a double */
	double lambda, lambda_prev;    /* Lambda_k and Lambda_{k-1} (0 for k = 0), m/rad */
	double lead_prev;              /* L_{k-1} / 2 pi, m/rad (0 for k = 0) */
	double mu, mu_s;               /* Coulomb mu (mu_c) and mu_s, - */
	double tan_alpha, cos_alpha;   /* ring-gear pressure angle */
	double m_R, J_R, m_C, J_C, m_S, J_S, J_psi, M_axial; /* kg, kg m^2 */
	double r_SS, r_NS;             /* coupling radii, m (k >= 1) */
	/* the statics engine's view of the stage (losses = STATICS, efficiency_statics) */
	prsm_design design;            /* the stage design with the model's mu */
	prsm_analysis analysis;        /* its nominal analysis */
	double eta_slide;              /* statics sliding efficiency with the model's mu */
	prsm_losses_options loss_options;
	prsm_losses_nominal loss_nominal;
	/* The loss torques at the reference load F_ref (model/losses.h at the load distribution
	 * of F_ref, or the equal share when F_ref = 0, then at 1 N), split by how they scale with
	 * the load when the distribution keeps its shape, s = F / F_ref: the spin moments as
	 * Q^(4/3), the sliding friction's moment about the roller axis as Q. Then
	 *   T_loss(F, w) = s^(4/3) T_spin + G |s M_lin + s^(4/3) M_spin| + T_0 + c w
	 * is prsm_losses_compute_prepared's T_spin + T_gear + T_drag + T_seal at the scaled loads
	 * (tests/test_dyn_model.c holds the two against each other). */
	double loss_scale_load_N;      /* F_ref, or 1 N for the equal share */
	double loss_spin_Nm;           /* T_spin at F_ref */
	double loss_moment_lin_Nm;     /* roller moment: tangential friction + helix terms at F_ref */
	double loss_moment_spin_Nm;    /* roller moment: the spin couples at F_ref */
	double loss_gear_per_moment;   /* T_gear / |M_roller|, - */
	double loss_constant_Nm;       /* drag (at rest) + seal, N m */
	double loss_viscous_Nm_s;      /* the drag's viscous part, N m s/rad */
	int threads;                   /* n_t */
} dyn_stage;

struct prsm_dyn_model {
	int stages;
	prsm_dyn_options opts;
	dyn_stage stage[PRSM_DYN_STAGES_MAX];
	double hand;                   /* +1 right-hand, -1 left-hand, all stages */
	double J_theta;                /* kg m^2 */
	double lambda_K;               /* Lambda_K, m/rad */
	double stick_band_rad_s;       /* v_K resolved */
	double stiff_switch_rad_s;     /* resolved */
	prsm_dyn_settled settled;
};

/* What an evaluation may change, and the flags of the evaluation. */
typedef struct {
	int flank[PRSM_DYN_STAGES_MAX];/* preferred flank per stage: the last one that carried */
	int stuck;                     /* Karnopp stick: theta-dot = theta-ddot = 0, T_in = T_m */
	int direction;                 /* 0; +1 / -1: break-away evaluation (slip along +-B, mu_s,
	                                  carriers at rest, the coupling signs +-1) */
	int detail;                    /* 1: the Newton-Euler recovery and every power */
	long evaluations;              /* stage passes done (statistics) */
} dyn_scratch;

/* The motion the evaluation is asked for. */
typedef struct {
	double t, theta, theta_dot, theta_ddot;
	const double *psi, *psi_dot;   /* K each */
} dyn_motion;

/* Evaluate at a motion with theta-ddot given (docs/model §8.2.4): fills pt (T_in, powers) and
 * sp[K] (carrier accelerations, forces). Returns 0 or PRSM_ENOCONVERGE with err. */
int dyn_eval_motion(const prsm_dyn_model *m, dyn_scratch *s, const dyn_motion *mo,
                    prsm_dyn_point *pt, prsm_dyn_stage_point *sp, prsm_error *err);

/* Torque input: solve theta-ddot so that T_in = T_m(t) (docs/model §8.2.4, "Torque input"),
 * then evaluate; mo->theta_ddot is set. Stuck: theta-ddot = 0 and T_in = T_m. */
int dyn_eval_torque(const prsm_dyn_model *m, dyn_scratch *s, dyn_motion *mo, prsm_dyn_point *pt,
                    prsm_dyn_stage_point *sp, prsm_error *err);

/* The screw's speed, acceleration and angle at t under a speed input (angle from 0). */
void dyn_speed_input(const prsm_dyn_model *m, double t, double *theta, double *theta_dot,
                     double *theta_ddot);

/* A scratch for the model: flanks at their guess (the settled ones). */
void dyn_scratch_init(dyn_scratch *s, const prsm_dyn_model *m);

/* Break-away torques with a caller's scratch (dyn.h, prsm_dyn_breakaway_torques). */
int dyn_breakaway(double *forward_Nm, double *backward_Nm, const prsm_dyn_model *m, dyn_scratch *s,
                  double t, prsm_error *err);

/* The settled state of m (dyn/settled.c), into m->settled. */
int dyn_settle(prsm_dyn_model *m, prsm_error *err);

/* The statics chain (model/stages.h) of the model's stages at load_N and speed_rad_s, each
 * stage's torque with every loss (losses STATICS) or from its sliding efficiency (dyn/model.c). */
int dyn_statics_chain(prsm_chain *out, const prsm_dyn_model *m, double load_N, double speed_rad_s,
                      prsm_error *err);

/* Number of output times of the options' grid (dyn/model.c). */
size_t dyn_output_points(const prsm_dyn_options *o);

#endif
