/*
 * assembly.h: the assembly under errors (docs/model/errors-and-assembly.md): every flank gap of every roller,
 * engaged thread, flank side and load direction at any screw angle; rigid backlash; the elastic
 * load sharing under an axial load; transmission error over a revolution and a stroke.
 *
 * Conventions (docs/assembly-model.md): roller j sits at carrier angle
 * psi_j = 2 pi j / Z + k_c theta, spins sigma_j = s_r theta relative to the carrier; thread k
 * of the engagement is at z_k = (k - (n_t - 1)/2) P; the "+" load direction pushes the nut
 * towards +z relative to the screw (its chain: the roller's upper flank on the screw's lower
 * flank, the roller's lower flank under the nut's upper flank), "-" the opposite. Gaps are
 * measured in the frame that moves with the nominal nut and roller positions, so only errors
 * make them depend on theta. Elastic unknowns: u, the nut's axial displacement relative to the
 * screw in the load direction, and w_j, each roller's (docs/model/errors-and-assembly.md).
 *
 * Two evaluation modes behind one interface (docs/model/errors-and-assembly.md): exact re-solves every contact of
 * the perturbed pairs, linear sums the sensitivities at the nominal contacts. Nothing here
 * allocates: a prsm_assembly is a plain struct prepared once per design.
 */
#ifndef PRSM_MODEL_ASSEMBLY_H
#define PRSM_MODEL_ASSEMBLY_H

#include "model/analysis.h"
#include "model/errors.h"
#include "util/cancel.h"
#include "model/perturb.h"

/* Most contacts per flank side (rollers x engaged threads) the error analysis takes. */
#define PRSM_ASSEMBLY_MAX_CONTACTS 4096

enum { PRSM_MODE_LINEAR = 0, PRSM_MODE_EXACT = 1 };
enum { PRSM_DIR_PLUS = 0, PRSM_DIR_MINUS = 1 };

/* One flank pair as the assembly uses it: side (screw/nut) x load direction. */
typedef struct {
	prsm_flank_pair pair;            /* modelled or mirrored (z -> -z) nominal pair */
	int mirrored;                    /* 1: axial error terms enter with the opposite sign */
	double x_mm, y_mm;               /* its nominal contact point in the pair frame */
	double gap_mm;                   /* its nominal gap, mm */
	double sens[PRSM_PERTURB_COUNT]; /* dG/de_i at the contact (perturb.h units) */
	double u2_mm2;                   /* squared distance of the contact from the roller axis */
} prsm_assembly_pair;

typedef struct {
	prsm_design design;              /* resolved, with its flank shifts */
	int rollers, threads, starts, hand;
	double pitch_mm, screw_p, roller_p; /* P, p = hand n P/2pi, p_r = hand P/2pi (mm/rad) */
	double carrier_ratio;            /* k_c: carrier turns per screw turn */
	double spin_ratio;               /* s_r: roller spin relative to the carrier per screw turn */
	prsm_assembly_pair pairs[2][2];  /* [side][direction] */
	/* axial contact law f = K delta^{3/2} (docs/model/errors-and-assembly.md, docs/model/kinematics-efficiency-stiffness-life.md): Hertz K converted to the axial
	 * direction, K = K_n |n_z|^{5/2}, N / mm^{3/2}; no thread compliance (issue 4) */
	double k_axial[2];               /* [side] */
	double nominal_stiffness_N_per_mm; /* dF/du at the operating load with nominal gaps */
} prsm_assembly;

/* Gaps of one configuration: gap[side][j * threads + k] for one load direction. Sized for the
 * largest engagement the error analysis takes (64 kB: keep it off small stacks). */
typedef struct {
	int edge_contacts;               /* exact mode: contacts that left their flank */
	int failed_contacts;             /* exact mode: contacts without convergence */
	double gap_mm[2][PRSM_ASSEMBLY_MAX_CONTACTS];
} prsm_assembly_gaps;

/* Result of the elastic solve for one load. */
typedef struct {
	double load_N;                   /* F on the nut, > 0, in the gaps' load direction */
	double u_mm;                     /* nut displacement relative to the screw */
	double w_mm[PRSM_ERRORS_MAX_ROLLERS];      /* roller displacements */
	double roller_load_N[PRSM_ERRORS_MAX_ROLLERS]; /* axial load each roller carries */
	double stiffness_N_per_mm;       /* dF/du */
	double sharing_factor;           /* max_j roller load / (F / Z) */
	int loaded_rollers;              /* rollers carrying load */
	int iterations;                  /* outer Newton iterations */
	int converged;                   /* 1 when the nut and every roller balanced (docs/model/errors-and-assembly.md) */
	/* the gaps the state was solved on: each roller's smallest screw- and nut-side gap, mm (a warm
	 * solve's predictor moves the state with them); gaps_known 0 before the first solve */
	int gaps_known;
	double gs_min_mm[PRSM_ERRORS_MAX_ROLLERS];
	double gn_min_mm[PRSM_ERRORS_MAX_ROLLERS];
} prsm_assembly_state;

/* Prepare a design that passed prsm_analysis_nominal (a): pairs, contacts, sensitivities, K.
 * Returns 0; PRSM_EINVAL when rollers * threads > PRSM_ASSEMBLY_MAX_CONTACTS; PRSM_EGEOMETRY when a mirrored
 * contact cannot be solved. */
int prsm_assembly_init(prsm_assembly *as, const prsm_design *d, const prsm_analysis *a,
                       prsm_error *err);

/* The pair perturbation (perturb.h components) that errors e put on roller j, thread k,
 * side, direction at screw angle theta (rad). */
void prsm_assembly_perturbation(double *out, const prsm_assembly *as, const prsm_errors *e,
                                int j, int k, int side, int dir, double theta_rad);

/* Linear mode for one contact: the nominal gap plus the first-order change of perturbation e
 * at the frozen nominal contact (the roller radii's own curvature included exactly). */
double prsm_assembly_gap_linear(const prsm_assembly_pair *ap, const double *e);

/* Every gap of one load direction at screw angle theta. Returns 0, or PRSM_ENOCONVERGE when
 * an exact contact failed (it is counted, and its gap is the linear one). */
int prsm_assembly_gaps_at(prsm_assembly_gaps *out, const prsm_assembly *as, const prsm_errors *e,
                          int dir, double theta_rad, int mode);

/* Rigid backlash B(theta), mm: per direction min_j [min_k g_sr + min_k g_nr], summed over both
 * directions (docs/model/errors-and-assembly.md). plus/minus (may be NULL) get the two directions' shares. */
double prsm_assembly_backlash(const prsm_assembly *as, const prsm_assembly_gaps *plus,
                              const prsm_assembly_gaps *minus, double *plus_mm, double *minus_mm);

/* Elastic solve (docs/model/errors-and-assembly.md) at axial load F_N > 0 on the gaps g of one direction. st->u_mm
 * and st->w_mm are used as the starting point when warm is 1. Bracketed Newton on u over
 * monotone 1-D roots in w_j, which converges for finite gaps and F > 0; returns 0, or
 * PRSM_ENOCONVERGE (st->converged 0, st still filled with the last iterate) when the nut or a
 * roller did not balance within PRSM_ASSEMBLY_MAX_ITERATIONS, or an input was not finite
 * (docs/model/errors-and-assembly.md: the caller counts it, never uses it silently). */
#define PRSM_ASSEMBLY_MAX_ITERATIONS 200

int prsm_assembly_solve(prsm_assembly_state *st, const prsm_assembly *as,
                        const prsm_assembly_gaps *g, double F_N, int warm);

/* Named frequencies of docs/model/errors-and-assembly.md in cycles per screw revolution. */
typedef struct {
	double screw;           /* a screw-fixed error passing one roller: 1 - k_c */
	double carrier;         /* a nut-fixed error passing one roller: k_c */
	double roller_spin;     /* a roller-fixed error: |s_r| */
	double roller_pass_screw; /* the rollers passing a point of the screw: Z (1 - k_c) */
	double roller_pass_nut; /* the rollers passing a point of the nut: Z k_c */
} prsm_assembly_frequencies;

void prsm_assembly_frequencies_of(prsm_assembly_frequencies *f, const prsm_assembly *as);

/* Options of the error analysis (the analyze request's `assembly` object). */
typedef struct {
	int mode;                        /* PRSM_MODE_* */
	double measuring_load_N;         /* TE measuring load, N (default 50) */
	int angles_per_revolution;       /* screw angles per revolution (default 64) */
	double stroke_mm;                /* stroke for TE and lead deviation; 0: one revolution */
	int spectrum_revolutions;        /* length of the record the spectrum is taken from (default 16) */
	int curve;                       /* 1: report the TE curves and the spectrum itself */
	/* when to give up (prsm_assembly_analyse returns PRSM_ECANCELLED): a raised flag, or the
	 * monotonic clock (util/clock.h prsm_clock_seconds, s) past deadline_s; NULL / 0: never */
	prsm_cancel_flag *cancel;
	double deadline_s;
} prsm_assembly_options;

void prsm_assembly_options_default(prsm_assembly_options *o);

#endif
