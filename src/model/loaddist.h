/*
 * loaddist.h: load distribution over the threads of a PRSM by the spring chain, the axial
 * stiffness of the nut unit and its load-deflection curve (docs/model/kinematics-efficiency-stiffness-life.md, "Load distribution
 * over threads").
 *
 * THE MODEL. The Z rollers share the axial load F equally (nominal assembly: docs/model/errors-and-assembly.md adds
 * the unequal sharing), so one roller is modelled, carrying W = F/Z. Threads are numbered
 * i = 1..n_t along the axis (index i-1 in the arrays). At each thread there are three axial
 * displacements, screw x_i, roller y_i, nut z_i (mm, positive in the direction of the load
 * on the nut), and between neighbouring threads three body segments of one pitch:
 *
 *   screw core   compliance c_s = Z * screw_segment_mm_per_N   (the core is shared by Z rollers)
 *   roller core  compliance c_r = roller_segment_mm_per_N       (per roller)
 *   nut body     compliance c_n = Z * nut_segment_mm_per_N     (shared by Z rollers)
 *
 * (the per-pitch P/(E A) of prsm_compliance_segments; 0 makes that body rigid). Two contacts
 * per thread: the screw-side contact i between screw node i and roller node i, the nut-side
 * contact i between roller node i and nut node i, with the relative axial displacements
 *
 *   a_i = y_i - x_i,   b_i = z_i - y_i      (mm)
 *
 * and optional initial axial gaps g_s,i, g_n,i (mm; pitch errors). The compressions a_i - g_s,i
 * and b_i - g_n,i and the axial loads p_i (screw side), q_i (nut side) follow the contact law
 *
 *   compression = C n_z^(-5/3) q^(2/3) + c_t q     for q > 0,   q = 0 for compression <= 0
 *
 * i.e. Hertz (normal approach delta_n = C Q^(2/3), normal load Q = q/n_z, axial approach
 * delta_n/n_z, docs/model/kinematics-efficiency-stiffness-life.md "Hertz point contact") in series with the linear axial thread
 * compliance c_t (docs/model/kinematics-efficiency-stiffness-life.md "Thread compliance", both threads of the contact); contacts carry
 * compression only (lift-off). PRSM_LOADDIST_LINEAR replaces Hertz by delta_n = C Q, i.e.
 * approach = (C/n_z^2 + c_t) q (for tests and linear studies).
 *
 * SIGN CONVENTIONS AND LOAD ENTRY. The nut is pushed by W in +z (per roller) and the screw is
 * held at its load point, the end of thread 1, where x_1 = 0 is the reference. The roller
 * pushes the screw in +z at each thread, so the screw core is in TENSION between its threads,
 * carrying T_i = p_{i+1} + ... + p_{n_t} between threads i and i+1. The roller core carries
 * R_i = sum_{k>i} (q_k - p_k) (tension > 0). The nut's load enters
 *
 *   PRSM_LOAD_ENTRY_SAME      at thread 1, the screw's end: the nut body is in COMPRESSION,
 *                             N_i = -sum_{k>i} q_k (a bolt and its nut: screw in tension,
 *                             nut in compression). Screw stretch and nut shortening both take
 *                             approach away from the far threads: on both sides the load is
 *                             largest at thread 1 and falls monotonically away from it.
 *   PRSM_LOAD_ENTRY_OPPOSITE  at thread n_t, the far end: the nut body is in TENSION,
 *                             N_i = sum_{k<=i} q_k (screw and nut both in tension). The nut
 *                             side now peaks at thread n_t, the screw side still at thread 1;
 *                             the roller core, stretched by the difference of the two sides
 *                             (R_i > 0), evens both out: a more uniform distribution.
 *
 * Each roller sits between the two sides: with a rigid roller (c_r = 0) the screw side sees
 * only the screw's stretch, a_{i+1} - a_i = -c_s T_i, whichever the entry, and the entry only
 * mirrors the nut side. How much OPPOSITE gains therefore depends on c_r against Z c_s and
 * Z c_n: little for stiff rollers (case A at 10 kN, default thread compliance: max/mean on the
 * screw side 1.158 SAME, 1.151 OPPOSITE; nut side 1.079, 1.067; 1.161 and 1.075 for both with
 * rigid rollers).
 *
 * Reversing F mirrors everything (the other flanks carry, every segment force changes sign:
 * screw in compression and nut in tension for SAME, both in compression for OPPOSITE), with the
 * same loads: F is given as a magnitude. Compatibility over one pitch:
 *
 *   a_{i+1} - a_i = c_r R_i - c_s T_i,     b_{i+1} - b_i = c_n N_i - c_r R_i
 *
 * and equilibrium sum p_i = sum q_i = W. The approach of the nut unit is the relative axial
 * displacement of the nut's load point from the screw's load point:
 *   SAME      u = z_1 - x_1 = a_1 + b_1
 *   OPPOSITE  u = z_{n_t} - x_1 = c_s sum_{i<n_t} T_i + a_{n_t} + b_{n_t}
 * and the axial stiffness is the tangent K = dF/du = Z dW/du (docs/model/kinematics-efficiency-stiffness-life.md). Uniform flank play
 * (backlash) is not part of u unless given as gaps; the nut is radially guided.
 *
 * THE SOLVER. A contact's state is a parameter t on its load-compression curve, explicit
 * both ways: with a Hertz term t = q^(2/3), q = t^(3/2), compression = t (C' + c_t t^(1/2))
 * (C' = C n_z^(-5/3)), and for t <= 0 (lifted off) q = 0, compression = C' t; without one
 * t = q, compression = (linear compliance) t. So no law is inverted while iterating and the
 * compression always has a positive slope. Unknowns: t_i (screw side) and tau_i (nut side),
 * i = 1..n_t, and the cumulative loads T_i, U_i = sum_{k>i} q_k, i = 1..n_t-1: 4 n_t - 2 in all.
 * Equations: two equilibria per thread, T_{i-1} - T_i = p(t_i) and U_{i-1} - U_i = q(tau_i)
 * (T_0 = U_0 = W, T_{n_t} = U_{n_t} = 0), and the two compatibilities per pitch. Ordered thread
 * by thread the Jacobian is banded with 2 sub- and 2 superdiagonals for any compliances,
 * including 0 (rigid bodies: nothing is divided by a compliance). Newton with that exact
 * tangent and a banded LU with partial pivoting (O(n_t)), from the rigid-body solution (every
 * contact at W/n_t), damped by Deuflhard's natural monotonicity test (the affine-covariant
 * NLEQ-ERR: a step is accepted when the simplified Newton correction shrinks, which does not
 * depend on how forces and lengths are weighed against each other); when no damping passes
 * (an active set of lifted-off contacts changing across the step) a full step is taken, at
 * most 8 times. Converged when every equilibrium is within tolerance x W and every
 * compatibility within tolerance x the lengths it adds up (compressions at the equal share,
 * body stretch under W, gaps). The tangent factorised once more at the solution, without the
 * floor of 1e-12 that keeps zero-load contacts regular while iterating, gives dW/du.
 * Robustness: 100000 random cases (n_t 1..500, compliances over 5 decades, F 0.01 N..1 MN,
 * gaps up to 0.1 mm, both laws and entries) all converge, 5.8 iterations on average, at most
 * about 300 (with large gaps at tiny loads), hence the default limit of 500.
 *
 * COST (measured, gcc -O2, on the 2-core build machine): n_t = 10 about 4.5 us a solve,
 * n_t = 30 about 18 us (4 Newton iterations, the banded solves dominate), n_t = 100 70 us,
 * n_t = 500 0.5-0.7 ms. Nothing is allocated except by prsm_loaddist_alloc.
 *
 * Units: mm, N, MPa.
 */
#ifndef PRSM_MODEL_LOADDIST_H
#define PRSM_MODEL_LOADDIST_H

#include <stddef.h>

#include "model/compliance.h"
#include "model/contact.h"
#include "model/design.h"
#include "model/hertz.h"
#include "util/error.h"

/* Where the nut's load enters (see the top comment). */
enum { PRSM_LOAD_ENTRY_SAME = 0, PRSM_LOAD_ENTRY_OPPOSITE = 1 };

/* Contact law of a side. */
enum {
	PRSM_LOADDIST_HERTZ = 0,  /* delta_n = C Q^(2/3) */
	PRSM_LOADDIST_LINEAR = 1  /* delta_n = C Q */
};

/* Reference normal load of the Hertz solution prsm_loaddist_params_from_design stores, N (the
 * law is an exact power, so any load gives the same coefficient). */
#define PRSM_LOADDIST_REFERENCE_LOAD_N 1000.0

/* One side (screw-roller or nut-roller) of every thread. */
typedef struct {
	double contact_coefficient;  /* C: HERTZ delta_n = C Q^(2/3), mm/N^(2/3); LINEAR
	                                delta_n = C Q, mm/N; >= 0 */
	double axial_component;      /* n_z: axial component of the contact normal, (0, 1] */
	double thread_mm_per_N;      /* c_t: axial thread compliance of one contact (both threads
	                                in series), mm/N, >= 0 (C and c_t not both 0) */
	prsm_hertz reference;        /* a Hertz solution of this contact at any load_N > 0, for p_max
	                                and the semi-axes (~ Q^(1/3)); load_N = 0: not reported */
	const double *gap_mm;        /* n_t initial axial gaps, thread 1 first, mm (negative:
	                                interference); NULL: all 0. Borrowed, not copied. */
} prsm_loaddist_side;

typedef struct {
	int threads;                    /* n_t: engaged threads per roller and side, >= 1 */
	int rollers;                    /* Z, >= 1 */
	int load_entry;                 /* PRSM_LOAD_ENTRY_* */
	int contact_law;                /* PRSM_LOADDIST_HERTZ or PRSM_LOADDIST_LINEAR */
	prsm_loaddist_side side[2];     /* [PRSM_SIDE_SCREW], [PRSM_SIDE_NUT] */
	double screw_segment_mm_per_N;  /* whole screw core over one pitch, mm/N, >= 0 (x Z inside) */
	double roller_segment_mm_per_N; /* one roller core over one pitch, mm/N, >= 0 */
	double nut_segment_mm_per_N;    /* whole nut body over one pitch, mm/N, >= 0 (x Z inside) */
	double tolerance;               /* relative residual at convergence (see THE SOLVER), - */
	int max_iterations;             /* Newton iterations allowed */
} prsm_loaddist_params;

#define PRSM_LOADDIST_PARAMS_INIT                                                                 \
	{.threads = 0, .rollers = 0, .load_entry = PRSM_LOAD_ENTRY_SAME,                             \
	 .contact_law = PRSM_LOADDIST_HERTZ, .tolerance = 1e-12, .max_iterations = 500}

/* What one side's distribution does at its most loaded contact. */
typedef struct {
	double max_over_mean;    /* max_i p_i / (W / n_t), >= 1, - */
	int max_index;           /* index of the most loaded contact, 0 = thread 1 */
	double max_axial_N;      /* its axial load, N */
	double max_normal_N;     /* its normal load Q = q / n_z, N */
	double p_max_MPa;        /* its Hertz peak pressure, MPa (NaN without a reference) */
	double a_mm, b_mm;       /* its contact-ellipse semi-axes, mm (NaN without a reference) */
	int lifted_off;          /* contacts of this side carrying no load */
} prsm_loaddist_side_result;

typedef struct {
	int threads, rollers, load_entry; /* echo */
	double load_N;               /* F, total axial load of the nut, N */
	double roller_load_N;        /* W = F / Z, N */
	/* per-thread loads of one roller, thread 1 first, n_t each; they point into the workspace
	 * and are valid until its next solve or its free */
	const double *axial_screw_N; /* p_i: axial loads of the screw-side contacts, N */
	const double *axial_nut_N;   /* q_i: axial loads of the nut-side contacts, N */
	const double *normal_screw_N;/* p_i / n_z, N */
	const double *normal_nut_N;  /* q_i / n_z, N */
	prsm_loaddist_side_result side[2]; /* [PRSM_SIDE_SCREW], [PRSM_SIDE_NUT] */
	double approach_mm;          /* u: nut load point relative to screw load point, mm */
	double stiffness_N_per_mm;   /* K = dF/du at F (tangent), N/mm */
	int iterations;              /* Newton iterations used */
	double residual_N;           /* largest per-thread equilibrium residual at the end, N */
	double residual_mm;          /* largest per-pitch compatibility residual at the end, mm */
} prsm_loaddist_result;

typedef struct prsm_loaddist_workspace prsm_loaddist_workspace;

/* Workspace for solves of up to max_threads threads. Allocates; the caller releases it with
 * prsm_loaddist_free. Returns NULL if max_threads < 1 or memory runs out. */
prsm_loaddist_workspace *prsm_loaddist_alloc(int max_threads);

/* Release a workspace (NULL is fine). */
void prsm_loaddist_free(prsm_loaddist_workspace *ws);

/* Largest n_t the workspace takes (0 for NULL). */
int prsm_loaddist_capacity(const prsm_loaddist_workspace *ws);

/* Solve the spring chain (docs/model/kinematics-efficiency-stiffness-life.md) for the total axial load load_N (> 0) of the nut. The
 * per-thread arrays of out point into ws. Returns 0; PRSM_EINVAL (err says which) for a NULL or
 * too small workspace or invalid params or load; PRSM_ENOCONVERGE when Newton does not reach
 * the tolerance in max_iterations (out then holds the last iterate, its iterations and residual). */
int prsm_loaddist_solve(prsm_loaddist_result *out, prsm_loaddist_workspace *ws,
                        const prsm_loaddist_params *p, double load_N, prsm_error *err);

/* Load-deflection curve: points solves at F_k = max_load_N k / points, k = 1..points (F = 0
 * itself is left out: the Hertz contacts have zero stiffness there), writing F_k (N), u (mm)
 * and K (N/mm) into the caller's arrays of points entries (any of them may be NULL). Uses and
 * overwrites ws. Returns 0 or the first solve's failure (PRSM_EINVAL, PRSM_ENOCONVERGE). */
int prsm_loaddist_curve(double *load_N, double *approach_mm, double *stiffness_N_per_mm,
                        prsm_loaddist_workspace *ws, const prsm_loaddist_params *p,
                        double max_load_N, size_t points, prsm_error *err);

/* Params of a resolved design: the Hertz coefficients C = delta / Q^(2/3) and the reference
 * solutions from prsm_hertz_solve at PRSM_LOADDIST_REFERENCE_LOAD_N with the contacts'
 * curvatures and the materials (screw-roller, nut-roller), n_z = |normal[2]| of each contact,
 * the thread compliances tc->screw_side_mm_per_N and nut_side_mm_per_N, the segment
 * compliances of seg, Z and n_t of the design, no gaps, PRSM_LOADDIST_PARAMS_INIT's solver
 * settings. Returns 0, PRSM_EINVAL (bad load entry, Z or n_t) or PRSM_EGEOMETRY (a contact
 * where Hertz theory does not apply). */
int prsm_loaddist_params_from_design(prsm_loaddist_params *out, const prsm_design *d,
                                     const prsm_contact *screw_contact,
                                     const prsm_contact *nut_contact,
                                     const prsm_design_compliance *tc,
                                     const prsm_segment_compliance *seg, int load_entry,
                                     prsm_error *err);

#endif
