/*
 * nominal.h: a catalogue size, nominal diameter x lead, resolved into a full geometry by the
 * standard rules of MODEL.md §1 (docs/ratings.md "Catalogue sizes").
 *
 * The nominal diameter d_0 is the screw's pitch diameter 2 r_s (MODEL.md §1's check value:
 * screw Ø30, lead 20, 5 starts -> roller Ø10, pitch 4, nut Ø50). With n starts (default 5, the
 * usual catalogue choice; 3 to 12):
 *   P = L / n,   r_s = d_0 / 2,   r_r = r_s / (n - 2),   r_n = n r_r          (MODEL.md §1)
 * the roller count Z is Z_max of MODEL.md §1 for the default roller crest (r_r + P/4, kept
 * inside the arc's domain) and the running clearance, unless given; the engaged threads n_t
 * are round(d_0 / P) (a threaded roller length of about one nominal diameter, at least 4)
 * unless given. The same lead with other starts gives other pitches and rollers, and ratings
 * that differ by a factor of about 2 (prsm reports starts 3 to 6 beside the one chosen).
 * Units: mm, rad.
 */
#ifndef PRSM_MODEL_NOMINAL_H
#define PRSM_MODEL_NOMINAL_H

#include "util/problems.h"

#define PRSM_NOMINAL_STARTS_DEFAULT 5
#define PRSM_NOMINAL_STARTS_MIN 3     /* the standard rule r_s = (n - 2) r_r */
#define PRSM_NOMINAL_THREADS_MIN 4
#define PRSM_NOMINAL_ALTERNATIVES 4   /* starts 3, 4, 5, 6 */
/* the document's limits (schemas/analyze-request.schema.json $defs/nominal states the same) */
#define PRSM_NOMINAL_DIAMETER_MAX_MM 1000.0
#define PRSM_NOMINAL_LEAD_MAX_MM 600.0

typedef struct {
	double diameter_mm;   /* d_0, the screw's pitch diameter, mm */
	double lead_mm;       /* L, mm */
	int starts;           /* n; 0: PRSM_NOMINAL_STARTS_DEFAULT */
	int rollers;          /* Z; 0: Z_max */
	int engaged_threads;  /* n_t; 0: round(d_0 / P), at least PRSM_NOMINAL_THREADS_MIN */
} prsm_nominal;

typedef struct {
	int starts;                 /* n */
	double pitch_mm;            /* P = L / n */
	double screw_radius_mm;     /* r_s = d_0 / 2 */
	double roller_radius_mm;    /* r_r = r_s / (n - 2) */
	double nut_radius_mm;       /* r_n = n r_r */
	int rollers;                /* Z */
	int engaged_threads;        /* n_t */
} prsm_nominal_geometry;

/* Resolve n by the rules above, with the flank half-angle (rad) and the running clearance
 * (mm) the design uses (for Z_max). Problems go to errors at /nominal/...: a non-positive
 * diameter or lead, n < 3, no roller that fits. Returns 0 or PRSM_EINVAL. */
int prsm_nominal_resolve(prsm_nominal_geometry *out, const prsm_nominal *n, double flank_angle_rad,
                         double running_clearance_mm, prsm_problems *errors);

#endif
