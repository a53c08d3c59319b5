/*
 * performance.h: the operating-point analysis of a single-stage PRSM beyond its geometry
 * (docs/model/kinematics-efficiency-stiffness-life.md second bullet, §6): efficiency with spin, gear-mesh, drag and seal losses and
 * the input torque split by cause; thread compliance (with its rule echoed); the spring-chain
 * load distribution over the threads, its max/mean factor and the most loaded contact's
 * p_max; the axial stiffness of the nut unit and, on request, its load-deflection curve; the
 * static and dynamic capacities; L10 life with the duty cycle, reliability and preload; the
 * screw's column limits.
 *
 * Everything here reads the design's settings (prsm_design.losses, .stiffness, .life) and its
 * nominal analysis (prsm_analysis_nominal: contacts, kinematics, sliding efficiency).
 *
 * Static capacity C_0a (docs/model/kinematics-efficiency-stiffness-life.md): the axial load at which the most loaded contact of the
 * distribution reaches p_allow, found by solving the load distribution at that load (the
 * factor max/mean grows with the load, so the operating point's factor is not used); each
 * side separately, C_0a the smaller. Dynamic capacity C_a: model/life.h's Lundberg–Palmgren
 * adaptation times the L–P factor of the distribution over the thread rows at the operating
 * load (1 when the operating load is 0). Life: L10 = a1 (C_a / F_e)^3 10^6 revolutions with
 * F_e the cubic mean load of the duty cycle (or the operating load), raised by the preload
 * derating when a preload is given.
 *
 * Allocation: prsm_performance_compute allocates the per-thread arrays and the curve inside
 * *out; prsm_performance_free releases them.
 */
#ifndef PRSM_MODEL_PERFORMANCE_H
#define PRSM_MODEL_PERFORMANCE_H

#include "model/analysis.h"
#include "model/compliance.h"
#include "model/life.h"
#include "model/loaddist.h"
#include "model/losses.h"
#include "model/rating.h"
#include "util/error.h"

typedef struct {
	/* thread compliance and body segments (echo of the rule with the values) */
	prsm_design_compliance compliance;
	prsm_segment_compliance segments;
	/* efficiency with every loss (docs/model/kinematics-efficiency-stiffness-life.md) */
	prsm_losses_result losses;
	/* load distribution at the operating load (docs/model/kinematics-efficiency-stiffness-life.md) */
	int threads;                 /* n_t */
	double *thread_load_screw_N; /* axial load of each thread, screw side, per roller, N */
	double *thread_load_nut_N;   /* axial load of each thread, nut side, per roller, N */
	double *thread_normal_screw_N; /* normal load of each contact, screw side, per roller, N (0 at F = 0) */
	double *thread_normal_nut_N;   /* normal load of each contact, nut side, per roller, N (0 at F = 0) */
	prsm_loaddist_result dist;   /* factors, most loaded contact, approach, stiffness */
	double stiffness_N_per_um;   /* axial stiffness of the nut unit at the load, N/um */
	/* load-deflection curve (when asked) */
	int curve_points;
	double *curve_load_N, *curve_approach_um, *curve_stiffness_N_per_um;
	/* capacity */
	prsm_static_capacity static_screw, static_nut; /* the contact data at p_allow */
	double C0a_screw_N, C0a_nut_N, C0a_N;        /* from the distribution at min(p_allow, the
	                                                truncation limit p_limit), N */
	double C0a_pressure_screw_N, C0a_pressure_nut_N, C0a_pressure_N; /* the same at p_allow alone, N */
	int C0a_truncation_limited;  /* 1 when the ellipse truncation, not p_allow, sets C0a_N */
	double static_safety;        /* C_0a / F (INFINITY at F = 0) */
	prsm_dynamic_capacity dynamic;
	double distribution_factor;  /* L-P factor of the thread-row loads, <= 1 */
	double C0a_over_C_a;         /* C0a_N / dynamic.C_a_N, - */
	/* the contact-ellipse truncation check (model/rating.h, MODEL.md §6 static capacity) */
	prsm_truncation_check truncation_screw, truncation_nut;
	/* the makers' convention: equal sharing, p_allow, L-P with load factor 1 (model/rating.h) */
	prsm_makers_rating makers;
	/* life */
	double mean_load_N;          /* cubic mean of the duty cycle, or |F|, N */
	double equivalent_load_N;    /* after the preload derating, N */
	prsm_life_rating life;
	int has_column;
	prsm_column column;
} prsm_performance;

/* Compute everything for the design d (resolved, with its nominal analysis a). Allocates
 * inside *out (prsm_performance_free). Returns 0, PRSM_EINVAL (err names the setting) or
 * PRSM_ENOCONVERGE (the load distribution did not converge), PRSM_ENOMEM. */
int prsm_performance_compute(prsm_performance *out, const prsm_design *d, const prsm_analysis *a,
                             prsm_error *err);

void prsm_performance_free(prsm_performance *p);

/* The input torque of the design at its axial load (d->axial_load_N), with every loss and the
 * load distribution of this load, N m; NaN when it cannot be computed. For the multi-stage
 * chain (docs/model/kinematics-efficiency-stiffness-life.md). */
double prsm_performance_input_torque(const prsm_design *d, const prsm_analysis *a);

/* The normal loads of one roller's n_t screw-side and n_t nut-side contacts at the design's
 * axial load (d->axial_load_N), thread 1 first, N: the load distribution that
 * prsm_performance_compute hands to the spin loss (all 0 at no load). screw_N and nut_N hold
 * d->engaged_threads entries each. Allocates a load-distribution workspace and frees it.
 * Returns 0, PRSM_EINVAL, PRSM_ENOCONVERGE or PRSM_ENOMEM (err says why). */
int prsm_performance_normal_loads(double *screw_N, double *nut_N, const prsm_design *d,
                                  const prsm_analysis *a, prsm_error *err);

#endif
