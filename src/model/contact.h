/*
 * contact.h: flank gap functions and the contact solver (docs/model/geometry-and-meshing.md), the innermost kernel.
 *
 * A flank pair is one roller flank against one screw or nut flank, written as axial height
 * fields over the (x, y) plane of a frame in which the pair's geometry is given (nominally the
 * screw axis at the origin and the roller axis at (a, 0)). The gap G = Z_r - Z_b is the axial
 * distance between the flanks; the contact point is its stationary point (common normal) and
 * the flank gap is G there (negative = interference). Newton uses the analytic gradient and
 * Hessian. All lengths mm, angles rad.
 */
#ifndef PRSM_MODEL_CONTACT_H
#define PRSM_MODEL_CONTACT_H

#include "model/design.h"

enum { PRSM_SIDE_SCREW = 0, PRSM_SIDE_NUT = 1 };

/* Edge-contact flags: which bound the stationary point has left. */
enum {
	PRSM_EDGE_BODY_ROOT = 1,    /* rho beyond the screw/nut root */
	PRSM_EDGE_BODY_CREST = 2,   /* rho beyond the screw/nut crest */
	PRSM_EDGE_ROLLER_ROOT = 4,  /* u below the roller root */
	PRSM_EDGE_ROLLER_CREST = 8, /* u beyond the roller crest */
	PRSM_EDGE_ARC = 16          /* u >= R: off the spherical zone */
};

typedef struct {
	int side;                /* PRSM_SIDE_SCREW or PRSM_SIDE_NUT */
	double quarter_pitch_mm; /* P/4: flank height at the pitch radius */
	/* threaded body (screw or nut) */
	double body_x_mm, body_y_mm; /* its axis in the pair frame */
	double body_radius_mm;       /* pitch radius r_s or r_n */
	double body_tan_beta;        /* tan of its flank half-angle */
	double body_p;               /* helicoid parameter p = +-n P / 2 pi, mm/rad */
	double body_shift_mm;        /* t_b: flank shift (thinning + errors), opens the gap */
	double body_root_mm, body_crest_mm; /* flank extent in rho */
	/* roller */
	double roller_x_mm, roller_y_mm; /* its axis in the pair frame */
	double roller_radius_mm;     /* r_r, fixes the arc centre height z_c */
	double arc_radius_mm;        /* R */
	double roller_p;             /* p_r = +-P / 2 pi, mm/rad */
	double roller_shift_mm;      /* t_r: flank shift, opens the gap */
	double roller_root_mm, roller_crest_mm; /* flank extent in u */
} prsm_flank_pair;

typedef struct {
	double x_mm, y_mm;            /* contact point in the pair frame */
	double gap_mm;                /* G at the contact, negative = interference */
	double body_rho_mm;           /* contact radius on the screw/nut */
	double roller_u_mm;           /* contact radius on the roller */
	double body_angle_rad;        /* theta: angle on the body from its x axis */
	double roller_angle_rad;      /* phi: angle on the roller from the ray to the mating part */
	double normal[3];             /* unit normal of the body flank (radial, tangential, axial)
	                                 in the body's cylindrical frame at the contact, axial > 0 */
	double curvature_per_mm[2];   /* relative principal curvatures, ascending, 1/mm */
	int iterations;               /* Newton iterations used */
	int edge;                     /* PRSM_EDGE_* flags, 0 for a flank contact */
} prsm_contact;

/* The nominal flank pair of a resolved design: screw axis at the origin, roller at (a, 0). */
void prsm_flank_pair_nominal(prsm_flank_pair *out, const prsm_design *d, int side);

/* Axial gap G(x, y) of the pair, mm (docs/model/geometry-and-meshing.md). */
double prsm_contact_gap(const prsm_flank_pair *pair, double x_mm, double y_mm);

/* Gradient (2) and Hessian (xx, xy, yy) of G at (x, y); hess may be NULL. */
void prsm_contact_gap_derivatives(const prsm_flank_pair *pair, double x_mm, double y_mm,
                                  double grad[2], double hess[3]);

/* Newton start point of docs/model/geometry-and-meshing.md: screw side (r_s, P cot beta / pi) towards the roller,
 * nut side (r_n, 0). */
void prsm_contact_start(const prsm_flank_pair *pair, double *x_mm, double *y_mm);

/* Fast kernel: Newton from (*x, *y) (warm start), leaves the stationary point in (*x, *y) and
 * the gap in *gap_mm. Returns 0, or PRSM_ENOCONVERGE. Edge checks are the caller's (see
 * prsm_contact_edge). */
int prsm_contact_solve_gap(const prsm_flank_pair *pair, double *x_mm, double *y_mm,
                           double *gap_mm, int *iterations);

/* Edge flags of a stationary point. */
int prsm_contact_edge(const prsm_flank_pair *pair, double x_mm, double y_mm);

/* Full solve from the standard start: point, gap, radii, angles, normal, curvatures, edge.
 * Returns 0, PRSM_ENOCONVERGE, or PRSM_EEDGE (out is filled and out->edge says which bound). */
int prsm_contact_solve(prsm_contact *out, const prsm_flank_pair *pair);

#endif
