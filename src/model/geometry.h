/*
 * geometry.h: completing a design by the standard rules and checking it (docs/model/geometry-and-meshing.md).
 *
 * prsm_design_resolve() fills the fields a document may leave out (marked NaN by io/): nut and
 * screw radii from the standard rule, the roller arc radius, crest and root radii from the
 * pitch. prsm_geometry_check() then derives lead, helix angles, orbit radius and Z_max, and
 * sorts every broken rule into errors (impossible design: rejected, naming the field and the
 * limit) or warnings (possible but non-standard: the consequence is stated).
 * Field names in problems are the design document's JSON pointers.
 */
#ifndef PRSM_MODEL_GEOMETRY_H
#define PRSM_MODEL_GEOMETRY_H

#include "model/design.h"
#include "util/problems.h"

/* Default thread proportions, as fractions of the pitch P. */
#define PRSM_ADDENDUM_PER_PITCH 0.25  /* crest above the pitch radius */
#define PRSM_DEDENDUM_PER_PITCH 0.30  /* root below the pitch radius */

typedef struct {
	double lead_mm;                /* L = n P */
	double orbit_radius_mm;        /* a = r_s + r_r */
	double helix_screw_rad;        /* lambda_s: tan = n P / (2 pi r_s) */
	double helix_roller_rad;       /* lambda_r: tan = P / (2 pi r_r) */
	double helix_nut_rad;          /* lambda_n: tan = n P / (2 pi r_n) */
	int z_max;                     /* most rollers that fit without touching */
	double ring_gear_ratio;        /* i_g = r_n / r_r (ring gear teeth per roller gear teeth) */
	double migration_mm_per_rad;   /* axial roller drift per carrier radian: (P/2pi)(n - r_n/r_r) */
	int standard_rules;            /* 1 when r_s = (n-2) r_r and r_n = n r_r */
} prsm_geometry;

/* Set every optional field of d to NaN ("not given") and the rest to the documented defaults. */
void prsm_design_init(prsm_design *d);

/* Fill the fields left NaN by the document from the rules and defaults; explicit values are
 * kept. Problems (e.g. n < 3 with the standard rule) go to errors. Returns 0 or PRSM_EINVAL. */
int prsm_design_resolve(prsm_design *d, prsm_problems *errors);

/* Derive the geometry of a resolved design and check it. out is filled even when errors are
 * found. Returns 0, or PRSM_EGEOMETRY when at least one error was added. */
int prsm_geometry_check(prsm_geometry *out, prsm_problems *warnings, prsm_problems *errors,
                        const prsm_design *d);

/* The range of real roller screws (catalogues from about 3 to 300 mm nominal diameter, pitch
 * 0.5 to 10 mm, static ratings up to a few MN, speeds up to a few thousand rpm); a value outside
 * it is possible but more likely a unit slip (3250 mm for 3.25 mm given in µm). */
#define PRSM_PLAUSIBLE_RADIUS_MIN_MM 1.0
#define PRSM_PLAUSIBLE_RADIUS_MAX_MM 150.0
#define PRSM_PLAUSIBLE_PITCH_MIN_MM 0.5
#define PRSM_PLAUSIBLE_PITCH_MAX_MM 10.0
#define PRSM_PLAUSIBLE_LOAD_MAX_N 5e6
#define PRSM_PLAUSIBLE_SPEED_MAX_RPM 10000.0

/* Warnings (code "implausible") for radii the document gave, the pitch, the load and the speed
 * outside that range, each naming the field and the unit slip that would explain it. */
void prsm_geometry_plausibility(prsm_problems *warnings, const prsm_design *d);

/* Z_max = floor(pi / asin((r_ro + c/2) / a)) (docs/model/geometry-and-meshing.md); 0 when not even one fits. */
int prsm_geometry_z_max(double roller_crest_radius_mm, double running_clearance_mm,
                        double orbit_radius_mm);

#endif
