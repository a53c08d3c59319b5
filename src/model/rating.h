/*
 * rating.h: the capacities of a PRSM by the makers' convention beside the load distribution's,
 * and the contact-ellipse truncation check (MODEL.md §6, "Static capacity" and "Dynamic
 * capacity"; docs/ratings.md).
 *
 * MAKERS' CONVENTION. Roller-screw catalogues rate with the load shared equally over all
 * Z n_t contacts of a side: the static rating C_0a is the axial load at which a contact
 * reaches the permanent-deformation criterion, 0.0001 of the rolling element's curvature
 * diameter, which ISO 76 equates for ball contacts with a peak pressure of 4200 MPa (prsm
 * takes the stated p_allow, default 4200 MPa); the dynamic rating C_a is the Lundberg–Palmgren
 * rating of model/life.h with the load factor 1 (equal sharing over the thread rows). The
 * load-distribution figures (model/performance.h) rate the most loaded contact of the spring
 * chain instead, and are lower.
 *
 * ELLIPSE TRUNCATION. The contact ellipse is centred on the contact point; when its semi-axis
 * along the flank profile exceeds the distance along the profile to the nearest crest or root
 * edge of either flank, the ellipse is truncated there and Hertz theory no longer holds (the
 * edge stress rises sharply): a hard limit of static capacity, as in ball-bearing practice
 * (a ball's contact ellipse must stay within the groove shoulder). The profile direction has
 * the relative curvature of the roller's arc, 1/R, the straight screw or nut flank adding none
 * (MODEL.md §2 "Curvatures": k = (1/R, 1/R ± sin beta / rho)); the semi-axis along it is the
 * major axis a when 1/R is the smaller principal curvature (the screw side) and the minor
 * axis b otherwise (the nut side, whose circumferential curvature 1/R - sin beta / rho_n is
 * smaller). Both semi-axes grow as Q^(1/3) (Hertz), as does p_max, so the truncation limit is
 * a peak pressure p_limit = p_ref x margin / s_ref: the static capacity is the load at which
 * the most loaded contact reaches min(p_allow, p_limit).
 *
 * The distances along the profile are measured in the axial section through the contact:
 * along the straight screw or nut flank |rho_edge - rho| / cos beta, along the roller's arc
 * R |asin(u_edge / R) - asin(u / R)|. No allocation. Units: mm, N, MPa.
 */
#ifndef PRSM_MODEL_RATING_H
#define PRSM_MODEL_RATING_H

#include "model/contact.h"
#include "model/design.h"
#include "model/hertz.h"
#include "util/error.h"

/* Which edge bounds the flank around a contact (the nearest one). */
enum {
	PRSM_FLANK_EDGE_BODY_CREST = 0,   /* crest of the screw or nut thread */
	PRSM_FLANK_EDGE_BODY_ROOT = 1,    /* root of the screw or nut thread */
	PRSM_FLANK_EDGE_ROLLER_CREST = 2, /* crest of the roller thread */
	PRSM_FLANK_EDGE_ROLLER_ROOT = 3   /* root of the roller thread */
};

typedef struct {
	double distance_mm[4];       /* along the profile from the contact to each edge, mm
	                                (PRSM_FLANK_EDGE_* order) */
	double margin_mm;            /* the smallest of them, mm */
	int edge;                    /* PRSM_FLANK_EDGE_* of the smallest */
	int profile_is_major;        /* 1: the semi-axis along the profile is a; 0: b */
	double profile_axis_ref_mm;  /* that semi-axis at the reference load, mm */
	double load_ref_N;           /* the reference normal load, N */
	double p_ref_MPa;            /* p_max at the reference load, MPa */
	double q_limit_N;            /* normal load at which the semi-axis reaches margin_mm, N */
	double p_limit_MPa;          /* p_max at q_limit_N, MPa */
} prsm_truncation;

/* The truncation limit of one side's contact c (PRSM_SIDE_SCREW or PRSM_SIDE_NUT) of the
 * resolved design d, from a Hertz solution ref of that contact at any load > 0 (its semi-axes
 * and p_max scale as Q^(1/3)). Returns 0, or PRSM_EINVAL (err says why) when ref has no load,
 * the contact point lies outside its flanks (margin <= 0) or the side is unknown. */
int prsm_rating_truncation(prsm_truncation *out, const prsm_design *d, const prsm_contact *c,
                           const prsm_hertz *ref, int side, prsm_error *err);

/* The check at an operating point: the limit, and the most loaded contact against it. */
typedef struct {
	prsm_truncation t;           /* the side's limit */
	double operating_axis_mm;    /* semi-axis along the profile of the most loaded contact at
	                                the operating load, mm (0 at no load) */
	int truncated_operating;     /* 1 when it exceeds t.margin_mm */
	int truncated_at_C0a;        /* 1 when t.p_limit_MPa < p_allow: truncation limits C_0a */
} prsm_truncation_check;

/* The semi-axis along the profile at normal load Q_N >= 0, mm. */
double prsm_truncation_profile_axis_mm(const prsm_truncation *t, double Q_N);

/* The makers' convention (see the top comment): equal sharing on both sides. */
typedef struct {
	double p_allow_MPa;          /* the criterion's peak pressure, MPa */
	int contacts;                /* Z n_t contacts per side */
	double C0a_screw_N, C0a_nut_N; /* equal sharing at p_allow, each side, N */
	double C0a_N;                /* the smaller: the makers' C_0a, N */
	double C0a_truncation_limited_N; /* the same with p_allow replaced by min(p_allow, p_limit)
	                                    of each side, N (<= C0a_N) */
	int truncated;               /* 1 when the ellipse at C0a_N is truncated on either side */
	double C_a_N;                /* Lundberg–Palmgren with load factor 1 (equal sharing), N */
	double C0a_over_C_a;         /* C0a_N / C_a_N, - */
} prsm_makers_rating;

/* The makers' static rating from the equal-sharing capacities of each side (axial load at
 * p_allow with every contact equally loaded, model/life.h prsm_life_static_capacity), the
 * truncation limits of each side and the equal-sharing dynamic rating C_a_N. Returns 0 or
 * PRSM_EINVAL for non-positive inputs. */
int prsm_rating_makers(prsm_makers_rating *out, double C0a_equal_screw_N, double C0a_equal_nut_N,
                       const prsm_truncation *screw, const prsm_truncation *nut,
                       double p_allow_MPa, int contacts, double C_a_equal_N, prsm_error *err);

#endif
