/*
 * design_problem.h: the PRSM design optimisation as a problem of opt/optimize.h (issue 7).
 *
 * Variables: screw starts n (a set: the nut has n starts too, the rollers one, docs/model/geometry-and-meshing.md),
 * pitch P or lead L = n P (mm, a range, or a list of allowed values such as a catalogue's
 * standard leads: then a discrete variable, P = L / n for each start count), roller pitch radius r_r or screw pitch radius r_s (mm, a
 * range; the other follows the standard rule r_s = (n - 2) r_r, the nut r_n = r_s + 2 r_r = n r_r,
 * crest, root and arc radii the defaults of model/geometry.c), roller count Z (a set, at most
 * Z_max of the geometry), engaged threads n_t (a set) and optionally the flank half-angle beta
 * (deg, a range). A variable not varied keeps the base design's value; everything else (load,
 * speed, friction, materials, target clearance, losses, stiffness and life settings, column) is
 * the base design's.
 *
 * Objectives: efficiency eta at the operating point with every loss (docs/model/kinematics-efficiency-stiffness-life.md, maximise),
 * axial stiffness of the nut unit at the operating load (N/um, §6, maximise), mass of the nut
 * unit (nut body from the nut pitch radius to its outer radius and the Z rollers, over the
 * engaged length n_t P; kg, minimise), and the inertia reflected to the screw (kg m^2, minimise):
 * the screw's own (a solid cylinder of radius r_s over the column's free length, or over the
 * engaged length without one), the nut unit's mass translating at L/2pi per radian, and each
 * roller orbiting at the carrier ratio r_s/(2a) and spinning at (1 - n) times it (docs/model/kinematics-efficiency-stiffness-life.md).
 *
 * Constraints (scaled: g = (value - limit)/|limit| for an upper limit, the reverse for a lower;
 * feasible when g <= 0, i.e. exactly when the value meets its raw limit): the design can be
 * analysed (no impossible geometry, no edge contact; pass/fail: g -1 or 1); roller fit Z <= Z_max
 * (g = Z asin(s)/pi - 1, s = (r_ro + c/2)/a, smooth in the radii for the solver, but the integer
 * Z_max decides its sign: g >= 1e-3 when Z > Z_max, g <= 0 otherwise); the standard rules (no
 * rule warning of prsm_geometry_check; g -1, or the warning count); and those the caller sets:
 * nut outer diameter <= max, screw pitch diameter in [min, max], static safety C_0a/F >= s0,
 * L10 >= hours or revolutions, p_max of the most loaded contact <= limit, screw critical speed
 * (beam theory, needs the column data) >= factor x operating speed. No tolerance anywhere: the
 * optimiser's constraint_tol only steers NLopt (opt/optimize.h).
 *
 * Robust constraints (opt/robust.h, optional): the Monte Carlo yield of a study output of the
 * candidate design against a spec >= a target, with common random numbers. They follow the
 * deterministic constraints in the problem, named "yield_<output>"; the problem then has a
 * surrogate (the solver sees a smooth stand-in, the check uses the Monte Carlo yield). A
 * candidate's study runs only when every deterministic constraint g <= robust_gate_tol (0 in
 * prsm optimize: every one met); otherwise each robust constraint is reported violated (g = 1)
 * without running it.
 *
 * Pruning: a (starts, Z, n_t) combination is skipped when even the most favourable corner of
 * the continuous box cannot fit Z rollers, or puts the screw diameter or the nut outer diameter
 * outside their limits (each is monotone in the radii).
 *
 * The spec is read-only during a run; each evaluation works on its own copy of the base design,
 * so one spec may serve several threads, unless it has robust constraints (their cache changes
 * with every evaluation: one thread at a time). prsm_dp_evaluate allocates inside the model (the
 * performance arrays) and frees before it returns.
 */
#ifndef PRSM_OPT_DESIGN_PROBLEM_H
#define PRSM_OPT_DESIGN_PROBLEM_H

#include "model/analysis.h"
#include "model/design.h"
#include "model/performance.h"
#include "opt/optimize.h"
#include "opt/robust.h"
#include "util/error.h"

enum {
	PRSM_DP_EFFICIENCY = 0,   /* eta, - (maximise) */
	PRSM_DP_STIFFNESS = 1,    /* N/um (maximise) */
	PRSM_DP_MASS = 2,         /* kg (minimise) */
	PRSM_DP_INERTIA = 3,      /* kg m^2 (minimise) */
	PRSM_DP_OBJECTIVE_KINDS = 4
};
/* "efficiency", "stiffness_N_per_um", "mass_kg", "reflected_inertia_kg_m2", NULL. */
extern const char *const prsm_dp_objective_names[];

/* Constraints in the order of the problem (those not set are left out of it). */
enum {
	PRSM_DP_C_ANALYSABLE = 0,        /* 1 when the design cannot be analysed, else 0; <= 0 */
	PRSM_DP_C_ROLLER_FIT,            /* Z asin(s)/pi, <= 1 */
	PRSM_DP_C_STANDARD_RULES,        /* rule warnings, <= 0 */
	PRSM_DP_C_NUT_OUTER_DIAMETER,    /* mm, <= max */
	PRSM_DP_C_SCREW_DIAMETER_MIN,    /* screw pitch diameter 2 r_s, mm, >= min */
	PRSM_DP_C_SCREW_DIAMETER_MAX,    /* mm, <= max */
	PRSM_DP_C_STATIC_SAFETY,         /* C_0a / F, >= min */
	PRSM_DP_C_LIFE_HOURS,            /* L10, h, >= min */
	PRSM_DP_C_LIFE_REVOLUTIONS,      /* L10, screw revolutions, >= min */
	PRSM_DP_C_P_MAX,                 /* MPa, <= max */
	PRSM_DP_C_CRITICAL_SPEED,        /* critical / operating speed, >= factor */
	PRSM_DP_CONSTRAINT_KINDS
};
/* "analysable", "roller_fit", "standard_rules", "nut_outer_diameter_mm", ..., NULL. */
extern const char *const prsm_dp_constraint_names[];

typedef struct {
	int vary;          /* 0: the base design's value */
	double min, max;   /* the range, in the variable's unit (mm or deg) */
} prsm_dp_range;

typedef struct {
	int count;                        /* 0: the base design's value */
	int values[PRSM_OPT_MAX_LEVELS];  /* ascending */
} prsm_dp_set;

typedef struct {
	prsm_design base;            /* from the document, unresolved (radii NaN: the rules fill them) */
	prsm_dp_set starts;          /* n */
	prsm_dp_range pitch;         /* P (mm), or L (mm) when pitch_is_lead */
	int pitch_is_lead;
	int n_pitch_values;          /* > 0: P (or L) takes only these values (standard leads or
	                                pitches, a discrete variable) instead of the range */
	double pitch_values[PRSM_OPT_MAX_LEVELS]; /* mm, ascending */
	prsm_dp_range radius;        /* r_r (mm), or r_s (mm) when radius_is_screw */
	int radius_is_screw;
	prsm_dp_range flank_deg;     /* beta, deg */
	prsm_dp_set rollers;         /* Z */
	prsm_dp_set threads;         /* n_t */
	int n_objectives;
	int objective[PRSM_OPT_MAX_OBJECTIVES]; /* PRSM_DP_* kinds, in the problem's order */
	/* limits; NaN: not constrained */
	double nut_outer_diameter_max_mm;
	double screw_diameter_min_mm, screw_diameter_max_mm; /* screw pitch diameter 2 r_s */
	double static_safety_min;
	double life_min_h;
	double life_min_revolutions;
	double p_max_max_MPa;
	double critical_speed_factor_min;
	int standard_rules;          /* 1: rule warnings are constraint violations */
	prsm_robust *robust;         /* robust constraints; NULL: none (not owned) */
	double robust_gate_tol;      /* run the robust studies only when every other g <= this */
	/* filled by prsm_dp_problem */
	int n_constraints;
	int constraint_kind[PRSM_DP_CONSTRAINT_KINDS];
	double constraint_limit[PRSM_DP_CONSTRAINT_KINDS]; /* in the constraint's unit */
} prsm_dp_spec;

/* Every figure of one evaluated design (NaN when it could not be computed). */
typedef struct {
	int analysable;              /* resolve, geometry (Z_max aside) and the analyses succeeded */
	char failure[PRSM_ERROR_MESSAGE_MAX]; /* why not, when not */
	int z_max;
	double roller_fit;           /* Z asin(s)/pi, <= 1 when the rollers fit */
	int rule_warnings;
	double objective[PRSM_DP_OBJECTIVE_KINDS]; /* by kind: eta, N/um, kg, kg m^2 */
	double nut_outer_diameter_mm, screw_diameter_mm;
	double static_safety, life_h, life_revolutions, p_max_MPa;
	double critical_speed_rpm, operating_speed_rpm, critical_speed_ratio;
	double constraint_value[PRSM_DP_CONSTRAINT_KINDS]; /* by kind, in the kind's unit */
} prsm_dp_figures;

/* Set every variable to "base", no objective, no limit. */
void prsm_dp_spec_init(prsm_dp_spec *s, const prsm_design *base);

/* Fill p (variables, objectives, constraints, callbacks with ctx = s) from s and the
 * constraint list of s (n_constraints, constraint_kind, constraint_limit), then the robust
 * constraints of s->robust. s must outlive p. Returns 0 or PRSM_EINVAL (err says which field). */
int prsm_dp_problem(prsm_opt_problem *p, prsm_dp_spec *s, prsm_error *err);

/* The design at (x, levels) of the problem built from s, unresolved (rules fill the radii). */
void prsm_dp_design_at(prsm_design *out, const prsm_dp_spec *s, const double *x,
                       const double *levels);

/* Analyse a design from prsm_dp_design_at: resolve, check, nominal and operating-point
 * analysis, every figure. When a and perf are not NULL the analysis is kept there (perf then
 * owns arrays: prsm_performance_free; *d is resolved in place); otherwise it is freed.
 * full = 0 skips the load-deflection curve (the optimiser's evaluations). Returns 0 or the
 * model's code (fig->failure says why). */
int prsm_dp_analyse(prsm_dp_figures *fig, prsm_design *d, const prsm_dp_spec *s, int full,
                    prsm_analysis *a, prsm_performance *perf);

/* The scaled violation g of the problem's deterministic constraint i (0 .. s->n_constraints - 1)
 * for the figures fig of a design with `rollers` rollers: what the problem's eval reports, <= 0
 * exactly when the constraint meets its raw limit (no tolerance). */
double prsm_dp_violation(const prsm_dp_spec *s, int i, const prsm_dp_figures *fig, int rollers);

/* The robust constraints at (x, levels): the design's study when every deterministic constraint
 * g_det (s->n_constraints values, scaled as the problem's) holds within s->robust_gate_tol, else
 * every constraint violated (out->evaluated 0, out->failure says why). Returns as
 * prsm_robust_evaluate. */
int prsm_dp_robust(prsm_robust_eval *out, const prsm_dp_spec *s, const prsm_design *d,
                   const double *g_det, prsm_error *err);

/* The largest Z_max over the continuous box for n starts (0 when none fits). */
int prsm_dp_z_max_bound(const prsm_dp_spec *s, int starts);

#endif
