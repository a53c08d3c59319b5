/*
 * design_json.h: the design document (schemas/design.schema.json) to prsm_design and back to the
 * document's JSON pointers for every problem.
 *
 * Units convert here and nowhere else (the API names the unit, the engine works in mm,
 * N, MPa, rad, s): E_GPa * 1000 -> MPa, deg -> rad, rpm -> rad/s, thinning in µm of tooth
 * thickness -> per-flank shift in mm (half of it), clearance µm -> mm.
 *
 * base_pointer is the JSON pointer of the design object inside the request: "" when the design
 * is the whole document, "/design" when a study embeds it. Every problem carries base_pointer +
 * the field's pointer inside the design.
 */
#ifndef PRSM_IO_DESIGN_JSON_H
#define PRSM_IO_DESIGN_JSON_H

#include <cJSON.h>

#include "model/design.h"
#include "model/geometry.h"
#include "util/problems.h"

/* Limits of the design document; schemas/design.schema.json states the same numbers. */
#define PRSM_DESIGN_STARTS_MAX 12
#define PRSM_DESIGN_PITCH_MAX_MM 50.0
#define PRSM_DESIGN_ROLLERS_MAX 64
#define PRSM_DESIGN_ENGAGED_THREADS_MAX 500
#define PRSM_DESIGN_CLEARANCE_MAX_UM 5000.0
#define PRSM_DESIGN_E_MAX_GPA 2000.0
#define PRSM_DESIGN_LOAD_MAX_N 1e8
#define PRSM_DESIGN_SPEED_MAX_RPM 1e5
#define PRSM_DESIGN_DENSITY_MAX_KG_M3 50000.0
#define PRSM_DESIGN_GEAR_TEETH_MAX 1000
#define PRSM_DESIGN_TORQUE_MAX_NM 1e6
#define PRSM_DESIGN_CURVE_POINTS_MAX 1000

/*
 * Read the design document doc into out (initialised here with prsm_design_init(); optional
 * geometry fields the document leaves out stay NaN for prsm_design_resolve()). Checks types,
 * required and unknown fields, duplicate keys, finiteness, integers and ranges, and the
 * either/or rules (engaged_threads or nut_length_mm; thinning or target_axial_clearance_um),
 * adding every problem found to problems. Does not apply the geometric rules.
 * Returns 0 when no problem was found, PRSM_EINVAL otherwise (out is then partly filled).
 */
int prsm_io_design_from_json(prsm_design *out, const cJSON *doc, const char *base_pointer,
                             prsm_problems *problems);

/*
 * prsm_io_design_from_json(), then, only when it found nothing, prsm_design_resolve() and
 * prsm_geometry_check(), whose problems are added with base_pointer before their pointers:
 * errors to problems, rule warnings (non-standard but possible designs) to warnings (may be
 * NULL to drop them). geom is filled when the check ran.
 * Returns 0; PRSM_EINVAL when the document or the rule completion failed; PRSM_EGEOMETRY when
 * the design is physically impossible.
 */
int prsm_io_design_load(prsm_design *out,         /* the resolved design */
                        prsm_geometry *geom,      /* derived geometry (lead, helix angles, Z_max) */
                        prsm_problems *warnings,  /* non-standard rule warnings, or NULL */
                        const cJSON *doc,         /* the design object */
                        const char *base_pointer, /* its pointer in the request, "" at the top */
                        prsm_problems *problems); /* every error, with its pointer */

/* The "operating_point" member of doc (pointer base), if present, into d's load and speed;
 * problems with their pointers. */
void prsm_io_operating_point_from_json(prsm_design *d, const cJSON *doc, const char *base,
                                       prsm_problems *problems);

#endif
