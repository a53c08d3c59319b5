/*
 * errors.h: one concrete set of manufacturing and assembly errors of a PRSM (docs/model/errors-and-assembly.md).
 *
 * A measured part, or one Monte Carlo sample. Every error is a perturbation of a surface or an
 * axis; model/assembly.h maps them, with the phases the screw angle gives, onto the flank pairs
 * of every roller and thread (docs/assembly-model.md). Engine units: mm, rad, mm per mm.
 * Signs: a positive pitch-radius deviation makes the part larger, a positive thickness
 * deviation makes its teeth thicker (closes its gaps), a positive lead deviation makes its
 * lead longer.
 */
#ifndef PRSM_MODEL_ERRORS_H
#define PRSM_MODEL_ERRORS_H

#define PRSM_ERRORS_MAX_STARTS 12  /* = PRSM_DESIGN_STARTS_MAX */
#define PRSM_ERRORS_MAX_ROLLERS 64 /* = PRSM_DESIGN_ROLLERS_MAX */

/* Screw or nut. */
typedef struct {
	double pitch_radius_mm;          /* pitch-radius deviation, mm (+ larger) */
	double thickness_mm;             /* tooth-thickness deviation, mm (+ thicker) */
	double flank_angle_rad;          /* flank half-angle deviation, rad */
	double runout_mm;                /* thread-axis eccentricity to the axis it turns on, mm >= 0 */
	double runout_phase_rad;         /* its direction, in the part's own frame, rad */
	double lead_deviation;           /* cumulative lead error, mm per mm of length */
	double lead_periodic_mm;         /* once-per-turn axial wobble of the flanks, amplitude mm */
	double lead_periodic_phase_rad;  /* its phase in the part's own frame, rad */
	double start_index_rad[PRSM_ERRORS_MAX_STARTS]; /* index error of each start, rad */
	double tilt_rad;                 /* thread-axis tilt (misalignment), rad >= 0 */
	double tilt_phase_rad;           /* direction of the tilt in the part's own frame, rad */
} prsm_body_errors;

/* One roller. */
typedef struct {
	double pitch_radius_mm;          /* pitch-radius deviation, mm (+ larger) */
	double thickness_mm;             /* tooth-thickness deviation, mm (+ thicker) */
	double arc_radius_mm;            /* flank arc-radius deviation, mm */
	double runout_mm;                /* thread-axis eccentricity to its journals, mm >= 0 */
	double runout_phase_rad;         /* its direction in the roller's frame, rad */
	double lead_deviation;           /* cumulative lead (pitch) error along the roller, mm/mm */
	double lead_periodic_mm;         /* once-per-turn axial wobble, amplitude mm */
	double lead_periodic_phase_rad;  /* its phase in the roller's frame, rad */
	double pin_radial_mm;            /* carrier pin-hole position error, radial (+ outwards), mm */
	double pin_tangential_mm;        /* ... tangential (+ in the carrier's positive sense), mm */
	double gear_phase_rad;           /* thread-to-gear phase error, rad */
	double tilt_radial_rad;          /* axis tilt in the carrier frame, radial component, rad */
	double tilt_tangential_rad;      /* ... tangential component, rad */
} prsm_roller_errors;

/* The carrier (both rings together). */
typedef struct {
	double runout_mm;                /* pin circle eccentric to the carrier's axis, mm >= 0 */
	double runout_phase_rad;         /* its direction in the carrier frame from roller 0, rad */
} prsm_carrier_errors;

typedef struct {
	prsm_body_errors screw, nut;
	prsm_carrier_errors carrier;
	int rollers;                     /* entries of roller[] that belong to the design (= Z) */
	prsm_roller_errors roller[PRSM_ERRORS_MAX_ROLLERS];
} prsm_errors;

/* All errors zero, for a design with `rollers` rollers (clamped to PRSM_ERRORS_MAX_ROLLERS). */
void prsm_errors_zero(prsm_errors *e, int rollers);

/* 1 when every error is zero. */
int prsm_errors_all_zero(const prsm_errors *e);

#endif
