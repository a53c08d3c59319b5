/*
 * design.h: the typed nominal design of a single-stage planetary roller screw (MODEL.md §1).
 *
 * This is what io/ fills from a design document and what every model function reads. All
 * quantities are in the engine's units: mm, N, MPa, rad, s. Fields that the document may leave
 * out are resolved by prsm_design_resolve() (standard-rule radii, default crest and root radii,
 * roller arc radius), so after it every field is set; the flank shifts of a target clearance
 * are solved by prsm_analysis_nominal(), which needs the contact solver.
 */
#ifndef PRSM_MODEL_DESIGN_H
#define PRSM_MODEL_DESIGN_H

#include "util/error.h"

enum { PRSM_HAND_RIGHT = 1, PRSM_HAND_LEFT = -1 };

typedef struct {
	double E_MPa;   /* Young's modulus, MPa */
	double poisson; /* Poisson's ratio, - */
} prsm_material;

/* How a target clearance is split into flank shifts (the rule is reported with the result). */
enum { PRSM_THINNING_GIVEN = 0, PRSM_THINNING_EQUAL_GAPS = 1 };

typedef struct {
	/* threads (MODEL.md §1) */
	int starts;                   /* n: starts of screw and nut */
	int hand;                     /* PRSM_HAND_RIGHT or PRSM_HAND_LEFT, shared by all threads */
	double pitch_mm;              /* P, shared by all threads */
	double flank_angle_rad;       /* beta: flank half-angle from the radial line */
	double screw_radius_mm;       /* r_s, pitch radius */
	double roller_radius_mm;      /* r_r, pitch radius */
	double nut_radius_mm;         /* r_n, pitch radius */
	double roller_arc_radius_mm;  /* R, roller flank arc radius (default r_r / sin beta) */
	/* thread extents, radii of the flank ends */
	double screw_crest_radius_mm, screw_root_radius_mm;
	double roller_crest_radius_mm, roller_root_radius_mm;
	double nut_crest_radius_mm, nut_root_radius_mm; /* nut crest < nut root (internal thread) */
	/* assembly */
	int rollers;                  /* Z */
	int engaged_threads;          /* n_t: threads of one roller engaged on each side */
	double running_clearance_mm;  /* c: minimum gap between adjacent roller crests */
	/* tooth thinning: axial flank shift per flank t_i (MODEL.md §2), mm; half the thickness
	 * reduction of the tooth. Positive removes material and opens the gap. */
	double flank_shift_screw_mm, flank_shift_roller_mm, flank_shift_nut_mm;
	int thinning_rule;            /* PRSM_THINNING_* */
	double target_axial_clearance_mm; /* total axial play (both directions), when the rule solves it */
	/* materials and friction */
	prsm_material screw_material, roller_material, nut_material;
	double mu_screw_roller;       /* Coulomb friction coefficient at the screw-roller contact */
	double mu_nut_roller;         /* Coulomb friction coefficient at the nut-roller contact */
	/* operating point */
	double axial_load_N;          /* F on the nut, N */
	double screw_speed_rad_s;     /* omega of the screw, rad/s */
} prsm_design;

/* Lead L = n P, mm (MODEL.md §1). */
double prsm_design_lead_mm(const prsm_design *d);
/* Screw helicoid parameter p_s = hand n P / 2 pi, mm/rad. */
double prsm_design_screw_p(const prsm_design *d);
/* Roller helicoid parameter p_r = hand P / 2 pi, mm/rad. */
double prsm_design_roller_p(const prsm_design *d);
/* Roller orbit radius a = r_s + r_r, mm. */
double prsm_design_orbit_radius_mm(const prsm_design *d);

#endif
