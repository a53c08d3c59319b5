/*
 * perturb.h: what manufacturing errors do to one flank pair (docs/model/errors-and-assembly.md).
 *
 * A perturbation moves the surfaces and axes of one pair: the body's (screw or nut) axis
 * offset, pitch radius, flank angle and axial flank shift, the roller's axis offset, pitch
 * radius, arc radius and axial flank shift. Two evaluation modes with one interface:
 *   exact:  perturb the pair and re-solve the contact (warm start from the nominal point);
 *   linear: the nominal contact once, then by the envelope theorem the first-order gap change
 *           is the partial derivative of G at the fixed contact point, so
 *           gap ~ gap_nominal + sum_i dG/de_i e_i.
 * Axial shifts here are per pair as modelled (roller flank below the body flank); the assembly
 * layer maps part errors, phases and load directions onto them.
 */
#ifndef PRSM_MODEL_PERTURB_H
#define PRSM_MODEL_PERTURB_H

#include "model/contact.h"

enum {
	PRSM_PERTURB_BODY_DX,       /* body axis offset x, mm */
	PRSM_PERTURB_BODY_DY,       /* body axis offset y, mm */
	PRSM_PERTURB_BODY_RADIUS,   /* body pitch-radius deviation, mm */
	PRSM_PERTURB_BODY_BETA,     /* body flank-angle deviation, rad */
	PRSM_PERTURB_BODY_SHIFT,    /* body axial flank shift (opens the gap), mm */
	PRSM_PERTURB_ROLLER_DX,     /* roller axis offset x, mm */
	PRSM_PERTURB_ROLLER_DY,     /* roller axis offset y, mm */
	PRSM_PERTURB_ROLLER_RADIUS, /* roller pitch-radius deviation (arc centre height), mm */
	PRSM_PERTURB_ROLLER_ARC,    /* roller flank arc-radius deviation, mm */
	PRSM_PERTURB_ROLLER_SHIFT,  /* roller axial flank shift (opens the gap), mm */
	PRSM_PERTURB_COUNT
};

/* Names of the perturbation components with units, for reports ("body_dx_mm", ...). */
extern const char *const prsm_perturb_names[PRSM_PERTURB_COUNT];

/* out = nominal moved by e (PRSM_PERTURB_COUNT components in the units above). */
void prsm_perturb_apply(prsm_flank_pair *out, const prsm_flank_pair *nominal, const double *e);

/* dG/de_i at the contact point (x, y) of the nominal pair, mm of gap per unit of e_i. */
void prsm_perturb_sensitivities(double *out, const prsm_flank_pair *nominal, double x_mm,
                                double y_mm);

/* Exact mode: gap of the perturbed pair, Newton warm-started at (x, y) of the nominal contact.
 * Returns 0 or PRSM_ENOCONVERGE; *edge gets the edge flags of the new contact. */
int prsm_perturb_gap_exact(double *gap_mm, int *edge, const prsm_flank_pair *nominal,
                           double x_mm, double y_mm, const double *e);

/* Linear mode: nominal gap + sens . e */
double prsm_perturb_gap_linear(double nominal_gap_mm, const double *sens, const double *e);

#endif
