/*
 * design.h: the typed nominal design of a single-stage planetary roller screw (docs/model/geometry-and-meshing.md).
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
	double density_kg_m3; /* density, kg/m^3 (column critical speed, masses) */
} prsm_material;

/* Losses beyond flank sliding (docs/model/kinematics-efficiency-stiffness-life.md, second bullet); src/model/losses.h computes them. */
typedef struct {
	int spin;                     /* spin friction at every contact: 1 on (default), 0 off */
	int gear_mesh;                /* ring-gear mesh loss: 1 on (default), 0 off */
	double gear_friction;         /* Coulomb mu of the gear teeth, - */
	int roller_gear_teeth;        /* z_1; 0: the default rule of losses.h */
	int ring_gear_teeth;          /* z_2; 0: z_1 r_n / r_r */
	double gear_contact_ratio;    /* epsilon_alpha, - */
	double gear_pressure_angle_rad; /* rad */
	double drag_torque_Nm;        /* load-independent drag torque on the screw, N m */
	double viscous_drag_Nm_s_per_rad; /* drag torque per screw speed, N m s/rad */
	double seal_torque_Nm;        /* seal torque, N m */
} prsm_design_losses;

/* Load entry of the spring-chain load distribution (docs/model/kinematics-efficiency-stiffness-life.md). */
enum { PRSM_ENTRY_SAME_SIDE = 0, PRSM_ENTRY_OPPOSITE_SIDE = 1 };

/* Thread compliance, load distribution and stiffness settings (docs/model/kinematics-efficiency-stiffness-life.md). The thread
 * compliance fields mirror prsm_compliance_options (model/compliance.h). */
typedef struct {
	int width_rule;               /* PRSM_THREAD_COMPLIANCE_NONE or PRSM_THREAD_WIDTH_* */
	double width_fraction;        /* share rule: fraction of the circumference share, - */
	double width_mm;              /* given rule: effective width, mm */
	double ellipse_factor;        /* ellipse rule: w = factor x 2a, - */
	double calibration;           /* multiplies every thread compliance, - */
	int negative_terms;           /* PRSM_YAMAMOTO_CLAMP or PRSM_YAMAMOTO_KEEP */
	int load_entry;               /* PRSM_ENTRY_* */
	int curve_points;             /* load-deflection curve points; 0: no curve */
	double curve_max_load_N;      /* its largest load, N; NaN: 2 x the operating load */
} prsm_design_stiffness;

#define PRSM_DUTY_CYCLE_MAX 64

/* Capacity and life settings (docs/model/kinematics-efficiency-stiffness-life.md). */
typedef struct {
	double p_allow_MPa;           /* allowed peak pressure for C_0a, MPa */
	int reliability_percent;      /* 90, 95, 96, 97, 98 or 99 */
	int duty_steps;               /* 0: the operating load throughout */
	double duty_load_N[PRSM_DUTY_CYCLE_MAX];    /* axial load of each step, N */
	double duty_travel_mm[PRSM_DUTY_CYCLE_MAX]; /* travel of each step, mm */
	double preload_N;             /* preload of a two-half nut, N; 0: none */
	double lp_material_factor;    /* b_m of the Lundberg-Palmgren rating, - */
	int column;                   /* 1 when free length and fixity are given */
	double free_length_mm;        /* unsupported screw length, mm */
	int fixity;                   /* PRSM_FIXITY_* (model/life.h) */
} prsm_design_life;

/* How a target clearance is split into flank shifts (the rule is reported with the result). */
enum { PRSM_THINNING_GIVEN = 0, PRSM_THINNING_EQUAL_GAPS = 1 };

typedef struct {
	/* threads (docs/model/geometry-and-meshing.md) */
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
	/* tooth thinning: axial flank shift per flank t_i (docs/model/geometry-and-meshing.md), mm; half the thickness
	 * reduction of the tooth. Positive removes material and opens the gap. */
	double flank_shift_screw_mm, flank_shift_roller_mm, flank_shift_nut_mm;
	int thinning_rule;            /* PRSM_THINNING_* */
	double target_axial_clearance_mm; /* total axial play (both directions), when the rule solves it */
	/* materials and friction */
	prsm_material screw_material, roller_material, nut_material;
	double mu_screw_roller;       /* Coulomb friction coefficient at the screw-roller contact */
	double mu_nut_roller;         /* Coulomb friction coefficient at the nut-roller contact */
	double nut_outer_radius_mm;   /* outer radius of the nut body, mm; NaN: 1.3 r_n */
	prsm_design_losses losses;    /* efficiency beyond sliding */
	prsm_design_stiffness stiffness; /* thread compliance, load distribution, stiffness */
	prsm_design_life life;        /* capacity, life, column */
	int derived;                  /* PRSM_DERIVED_* bits: the radii prsm_design_resolve filled by
	                                 a rule or default (0 until then) */
	/* operating point */
	double axial_load_N;          /* F on the nut, N */
	double screw_speed_rad_s;     /* omega of the screw, rad/s */
} prsm_design;

/* Which radii prsm_design_resolve derived (model/geometry.h): a problem of a derived radius is
 * reported at the field the document gave (pitch_mm, roller_radius_mm), not at the radius. */
enum {
	PRSM_DERIVED_SCREW_RADIUS = 1, PRSM_DERIVED_NUT_RADIUS = 2, PRSM_DERIVED_ARC_RADIUS = 4,
	PRSM_DERIVED_SCREW_CREST = 8, PRSM_DERIVED_SCREW_ROOT = 16, PRSM_DERIVED_ROLLER_CREST = 32,
	PRSM_DERIVED_ROLLER_ROOT = 64, PRSM_DERIVED_NUT_CREST = 128, PRSM_DERIVED_NUT_ROOT = 256
};

/* Lead L = n P, mm (docs/model/geometry-and-meshing.md). */
double prsm_design_lead_mm(const prsm_design *d);
/* Screw helicoid parameter p_s = hand n P / 2 pi, mm/rad. */
double prsm_design_screw_p(const prsm_design *d);
/* Roller helicoid parameter p_r = hand P / 2 pi, mm/rad. */
double prsm_design_roller_p(const prsm_design *d);
/* Roller orbit radius a = r_s + r_r, mm. */
double prsm_design_orbit_radius_mm(const prsm_design *d);

#endif
