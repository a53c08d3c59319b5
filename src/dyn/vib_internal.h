/*
 * vib_internal.h: what the files of the vibration model share (dyn/vib_*.c): the model struct
 * behind vib.h, its right-hand side and Jacobian-vector product, the step-by-step integrator
 * with the mesh-stiffness switching schedule and the location of dead-zone crossings, and the
 * small worker pool of the sweeps and basins. Nothing outside src/dyn includes it.
 *
 * The model is a plain struct without pointers, so an analysis copies it (by value) and may
 * change a parameter of its copy (sweeps) without touching the caller's.
 */
#ifndef PRSM_DYN_VIB_INTERNAL_H
#define PRSM_DYN_VIB_INTERNAL_H

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "dyn/vib.h"

/* what the right-hand side needs beyond the public echo (scaled, docs/model §8.3.5, §8.4) */
typedef struct {
	int pair;                    /* 1: the dimensionless gear pair */
	int Z;                       /* rollers (gear pair: 1) */
	int n;                       /* state size */
	int gear, axial;             /* 1: the branch moves */
	int nc;                      /* contacts: Z meshes when gear, + 1 thread when axial */
	/* gear pair */
	double zeta, fm, eps, kappa, D, Omega; /* zeta, f_m, epsilon, kappa, eps_alpha - 1, Omega */
	/* reduced model, gear branch */
	double we;                   /* omega_e: mesh frequency per unit tau */
	double kd, ks;               /* k_d / k-bar, k_s / k-bar */
	double eg;                   /* e_g / b_g */
	double two_zeta_g;           /* 2 zeta_g */
	double cphase[PRSM_VIB_ROLLERS_MAX], sphase[PRSM_VIB_ROLLERS_MAX]; /* cos, sin 2 pi gamma_j */
	double gamma[PRSM_VIB_ROLLERS_MAX];
	/* mass matrix solve (arrow structure), SI */
	double Mpp, Mpf, Mff;        /* M_psipsi, M_psiphi, M_phiphi */
	double schur;                /* M_psipsi - Z M_psiphi^2 / M_phiphi */
	double rb1, rb2, bg;         /* m */
	double wref;                 /* omega_ref, 1/s */
	double kbar;                 /* N/m */
	double accel_psi, accel_phi; /* generalised acceleration (rad/s^2) -> P'' : r_b / (omega_ref^2 b_g) */
	/* friction (§8.3.3), SI */
	double vstar[3];             /* v* (m/s) */
	double gpsi[3], gphi[3];     /* slip per unit V_0, V_j (m/s) */
	double Gpsi[3], Gphi[3];     /* m per rad */
	double Gpsi_o[3], Gphi_o[3]; /* the same on the other flank (F_th < 0) */
	double nz, nz_o;             /* n_z of the loaded flank and of the other */
	double mu, veps2;            /* mu, v_eps^2 */
	double F0;                   /* F_0, N */
	/* axial branch (§8.3.2) */
	double r;                    /* omega_a / omega_ref */
	double zeta_a;
	double f0;                   /* F_0 / (k_a b_a) */
	double Fth_scale;            /* k_a b_a, N */
	double ba;                   /* m */
	int lines;
	double te_w[PRSM_VIB_TE_LINES_MAX]; /* nu omega_s / omega_ref, per unit tau */
	double te_a[PRSM_VIB_TE_LINES_MAX]; /* -A (nu omega_s)^2 / (b_a omega_a^2): the term of W' / r */
	double te_phi[PRSM_VIB_TE_LINES_MAX];
} vib_core;

struct prsm_vib_model {
	prsm_vib_params par;         /* the public echo */
	vib_core c;
	/* what set_param needs to re-derive */
	double v_basis_A[3], v_basis_B[3]; /* slip basis of the loaded flank, m per rad */
	double te_order_base[PRSM_VIB_TE_LINES_MAX]; /* orders per screw revolution */
	double k_axial, m_axial;     /* k_a (N/m), m_a (kg) */
	double mesh_order_per_rev;   /* > 0: the mesh frequency omega_m = this x omega_s (the dynamic
	                                Monte Carlo rounds z_2 k* to its window, vib_mc.c); 0: z_2 k* */
};

/* state indices of the reduced model */
static inline int vib_iP(const vib_core *c, int k) { (void)c; return k; }            /* P_k, k = 0 .. Z */
static inline int vib_iV(const vib_core *c, int k) { return c->Z + 1 + k; }         /* V_k */
static inline int vib_iY(const vib_core *c) { return 2 * (c->Z + 1); }
static inline int vib_iW(const vib_core *c) { return 2 * (c->Z + 1) + 1; }

/* h(x; 1) of the unit dead zone */
static inline double vib_dead(double x)
{
	return x > 1.0 ? x - 1.0 : (x < -1.0 ? x + 1.0 : 0.0);
}
static inline signed char vib_region(double x)
{
	return x > 1.0 ? 1 : (x < -1.0 ? -1 : 0);
}
/* h(x) on the branch of a region (the Jacobian's side) */
static inline double vib_dead_on(double x, signed char mode)
{
	return mode > 0 ? x - 1.0 : (mode < 0 ? x + 1.0 : 0.0);
}

/* Model derivations (vib_model.c) */
void vib_core_derive(prsm_vib_model *m);          /* re-derive c (and the echo) from par */
int vib_model_set(prsm_vib_model *m, int parameter, double value, prsm_error *err);

/* the mesh-error value and rate (scaled) of roller j at tau */
void vib_mesh_errors(const vib_core *c, double tau, double *e, double *edot);

/* The relative deflections (the guards) of every contact: x_j - e_j for the meshes (gear pair:
 * x), Y for the thread. */
void vib_contacts(const vib_core *c, double tau, const double *y, double *g);

/* The time functions of the right-hand side at one tau: sin, cos of the mesh phase omega_e tau,
 * cos(Omega tau) of the gear pair, the TE excitation sum_k te_a_k cos(w_k tau + phi_k). */
typedef struct {
	double mesh_s, mesh_c, pair_c;
	double te_sum;
} vib_trig;

void vib_trig_eval(const vib_core *c, double tau, vib_trig *t);

/* Right-hand side of one copy of the state (scaled). kap[j]: the stiffness factor of roller j in
 * the current segment (k_j / k-bar). trig: the time functions at tau (NULL: computed here).
 * mode: NULL for the true dead zones, else the region of each contact (the frozen side of the
 * Jacobian). */
void vib_rhs(const vib_core *c, const double *kap, const vib_trig *trig, double tau, const double *y, double *f,
             const signed char *mode);

/* Forces of a state: mesh forces F_j (N; gear pair kappa h(x)), thread force F_th (N). */
void vib_forces(const vib_core *c, const double *kap, double tau, const double *y, double *mesh, double *Fth);

/* ---- integrator (vib_integrate.c) ---- */

typedef struct vib_int vib_int;

/* Called after every accepted step (tau0, y0, f0) -> (tau1, y1, f1), copy 0 of the state. */
typedef int (*vib_observer_fn)(void *ctx, vib_int *it, double tau0, const double *y0, const double *f0,
                               double tau1, const double *y1, const double *f1);

struct vib_int {
	prsm_vib_model mod;          /* the model (copy) */
	vib_core *c;                 /* = &mod.c */
	int n;                       /* one copy's state size */
	int nvar;                    /* tangent vectors integrated with copy 0 */
	int copies;                  /* 1, or 2 (two trajectories) */
	int dim;
	int locate;                  /* 1: dead-zone crossings located */
	double rel_tol, abs_tol;
	gsl_odeiv2_system sys;
	gsl_odeiv2_step *step;
	gsl_odeiv2_control *ctl;
	double *y, *y0, *f0, *f1, *yerr, *ylo, *yhi, *ftmp, *scratch;
	double *jv_p, *jv_m, *jv_fp, *jv_fm; /* FD Jacobian-vector products (n each) */
	double tau, h;               /* time, proposed step */
	double hmax;                 /* largest step (a fraction of the mesh period) */
	int have_f0;
	/* mesh-stiffness switching (§8.4): sorted offsets of every roller's switching instants in a
	 * mesh period, the next one's index */
	double T;                    /* mesh period, tau (0: no switching) */
	int n_off;
	double off[2 * PRSM_VIB_ROLLERS_MAX + 2];
	long sw_k;                   /* next switch: (sw_k + off[sw_i]) T */
	int sw_i;
	double kap[PRSM_VIB_ROLLERS_MAX];
	signed char mode[2][PRSM_VIB_CONTACTS_MAX]; /* region of every contact at the step start */
	/* the time functions, without a cos per line per right-hand side: the mesh (or the gear
	 * pair's) oscillator from exact cos / sin at an anchor time, advanced by the angle-addition
	 * formulas with Taylor series of cos / sin of w (tau - anchor); the TE sum as its Taylor
	 * polynomial of degree 9 about its anchor. Both re-anchored when |w (tau - anchor)| > 0.1 for
	 * the fastest frequency involved (truncation below 3e-17 relative). */
	int osc_on;
	double osc_w, osc_c, osc_s, osc_anchor;
	int te_on;
	double te_coef[10], te_anchor, te_wmax;
	int osc_valid, te_valid;
	vib_trig trig;
	double g_tmp[PRSM_VIB_CONTACTS_MAX];
	prsm_vib_effort effort;
	long max_steps;
	const prsm_cancel_flag *cancel;
	vib_observer_fn obs;
	void *obs_ctx;
	char fail[PRSM_ERROR_MESSAGE_MAX];
};

/* Allocate an integrator for m with nvar tangent vectors and `copies` copies. Returns 0 or PRSM_ENOMEM. */
int vib_int_init(vib_int *it, const prsm_vib_model *m, int nvar, int copies, const prsm_vib_integration *o,
                 const prsm_cancel_flag *cancel);
/* The model of an integrator was changed (a sweep parameter): re-derive what depends on it. */
void vib_int_model_changed(vib_int *it);
void vib_int_free(vib_int *it);
/* Set the time and the state (dim entries); the stiffness segment and regions follow. */
void vib_int_set(vib_int *it, double tau, const double *y);
/* Integrate to tau_end exactly. Returns 0, PRSM_ENOCONVERGE (it->fail says why), PRSM_ECANCELLED. */
int vib_int_advance(vib_int *it, double tau_end);
/* The state at tau0 + h of the step from (tau0, y0, f0) (h no longer than the accepted step). */
void vib_int_restep(vib_int *it, double tau0, const double *y0, const double *f0, double h, double *out);
/* Hermite interpolation of copy 0 between (y0, f0) and (y1, f1) over a step of length h, at
 * fraction s in [0, 1]: quintic for positions, cubic for rates. */
void vib_hermite(const vib_core *c, const double *y0, const double *f0, const double *y1, const double *f1,
                 double h, double s, double *out);
/* Locate the first zero of g(tau) = fn(state) in (tau0, tau0 + h] by regula falsi on re-steps,
 * given g0 = g(tau0) and g1 = g(tau0 + h) of opposite signs; returns the fraction of h. */
typedef double (*vib_scalar_fn)(void *ctx, const vib_core *c, double tau, const double *y);
double vib_int_locate(vib_int *it, double tau0, const double *y0, const double *f0, double h, double g0,
                      double g1, vib_scalar_fn fn, void *ctx, double *y_at);

/* Reduced (Poincaré) coordinates: the projection of a full state difference / tangent vector,
 * and the lift of a reduced vector back (the rigid carrier component set to 0). */
void vib_project(const vib_core *c, const double *v, double *r);
void vib_lift(const vib_core *c, const double *r, double *v);
int vib_reduced_size(const vib_core *c);

/* ---- worker pool (vib_sweep.c) ---- */

typedef struct vib_pool vib_pool;
/* a task: returns 0 or a PRSM_E* that stops the pool (cancellation) */
typedef int (*vib_task_fn)(void *ctx, vib_pool *pool, size_t task);
/* Run tasks 0 .. n-1 on `threads` threads (inline when 1). units: planned progress units;
 * tasks report done units with vib_pool_done. Returns the first (lowest task) nonzero code. */
int vib_pool_run(size_t n, int threads, vib_task_fn fn, void *ctx, size_t units, const prsm_cancel_flag *cancel,
                 prsm_progress_fn progress, void *progress_ctx);
void vib_pool_done(vib_pool *pool, size_t units);
int vib_pool_cancelled(const vib_pool *pool);

/* ---- steady state core (vib_analysis.c), shared with sweeps and basins ---- */

/* Integrate n periods of length T from tau0 (state in it), recording the Poincaré vectors (if
 * poincare != NULL, n x size) at the end of every period. */
int vib_periods(vib_int *it, double tau0, double T, int n, double *poincare);

/* Default tolerance of the period test. */
double vib_default_period_tol(const prsm_vib_model *m);

/* Steady state with an existing integrator (state set, time tau0 = 0); out allocated. */
int vib_steady_core(prsm_vib_steady *out, vib_int *it, const prsm_vib_steady_options *o, int light,
                    prsm_error *err);

/* The Benettin exponent lambda_max of it's model from its current state over `periods`
 * periods of length T (the integrator must have nvar >= exponents). */
int vib_benettin(vib_int *it, double T, int transient, int periods, int exponents, int blocks,
                 prsm_vib_lyapunov *out);

/* messages */
int vib_int_error(const vib_int *it, int rc, prsm_error *err);

#endif
