/*
 * life.h: capacity and life of a PRSM, the parts of docs/model/kinematics-efficiency-stiffness-life.md that need no load
 * distribution: cubic mean load of a duty cycle, L10 life in revolutions, hours and distance
 * with reliability factors, static capacity from an allowed peak pressure, a Lundberg–Palmgren
 * dynamic capacity, the preload derating of ball-screw practice, and the screw column limits
 * (critical speed, Euler buckling).
 *
 * Dynamic capacity (there is no ISO standard for roller screws; makers borrow from ball
 * bearings and ball screws, docs/model/kinematics-efficiency-stiffness-life.md). The method used here, named in prsm_lp_method.name:
 * Lundberg–Palmgren's basic dynamic capacity of a ball-bearing raceway (Harris & Kotzalas,
 * Rolling Bearing Analysis; the basis of ISO 281):
 *
 *   Q_c = b_m 98.1 (2f/(2f - 1))^0.41 ((1 -+ g)^1.39 / (1 +- g)^(1/3)) (g / cos alpha)^0.3
 *         D^1.8 Z^(-1/3)            [N, mm; upper signs inner raceway, lower outer]
 *
 * with the roller flank as the ball: docs/model/geometry-and-meshing.md makes it a spherical zone of radius R, so
 * D = 2R, centred on the roller axis, so the "ball set" pitch diameter is d_m = 2a (a = orbit
 * radius); the contact angle from the radial plane is alpha = pi/2 - beta; then
 * g = D cos alpha / d_m = r_r / a, the screw is the inner raceway (contact radius
 * (d_m - D cos alpha)/2 = r_s) and the nut the outer (r_n). The flanks of screw and nut are
 * straight in the axial section: conformity f = r_groove / D -> infinity, factor 1 (outside
 * the range of conformities the exponent 0.41 was fitted on: an extrapolation). The carrier
 * ratio of the PRSM, r_s / (2a) = (1 - g)/2, is the cage ratio of that bearing, so the ring
 * ratings refer to revolutions of screw relative to nut, like L10. The roller flanks are
 * stressed on fixed circles (a ball's axis wanders, a roller's does not), so they are rated as
 * raceways too, from the mating raceway's rating at the same contact by L–P's stressed-volume
 * law (same Hertz ellipse and subsurface stress; life N ~ l^(-1/e) in stress cycles for a
 * track of length l, e = 10/9): Q_c,roller = Q_c,ring ((l_r/l_ring)^(-1/e) u_ring/u_r)^(1/3),
 * u = stress cycles per screw revolution: screw Z (1 - k_c), nut Z k_c, roller flank
 * (r_n/r_r) k_c; l = 2 pi x the contact radius. The four surfaces (screw, roller screw side,
 * roller nut side, nut) combine the L–P way, Q_c = (sum Q_c,i^(-10/3))^(-3/10), after each is
 * turned into its axial component (x sin alpha). One thread row of Z rollers rates Z Q_c,a;
 * n_t equally loaded rows combine to n_t^(7/10) times that (the same rule), and a
 * load-distribution factor (input, <= 1; prsm_life_distribution_factor() gives the L–P one of
 * a computed distribution) multiplies the result.
 *
 * Units: mm, N, MPa, rad, rpm. No allocation.
 */
#ifndef PRSM_MODEL_LIFE_H
#define PRSM_MODEL_LIFE_H

#include <stddef.h>

#include "model/design.h"
#include "model/hertz.h"
#include "util/error.h"

/* Default allowed peak contact pressure for the static capacity, MPa (docs/model/kinematics-efficiency-stiffness-life.md; the
 * ISO 76 figure for ball contacts). */
#define PRSM_STATIC_P_ALLOW_MPA 4200.0

/* ---- duty cycle and life ---- */

/* Cubic mean load F_m = (sum |F_i|^3 w_i / sum w_i)^(1/3) (docs/model/kinematics-efficiency-stiffness-life.md), with the weights w_i
 * the travel of each step (mm, or any unit). Returns 0 or PRSM_EINVAL (n = 0, a negative or
 * non-finite weight, all weights 0, a non-finite load). */
int prsm_life_cubic_mean_load(double *out_N, const double *loads_N, const double *travel,
                              size_t n, prsm_error *err);

/* The same with the weights of ball-screw catalogues (ISO 3408-5 / DIN 69051 practice):
 * w_i = n_i q_i, speed (rpm) times time fraction. Equal to the travel-weighted mean, travel
 * being proportional to n_i q_i. Returns 0 or PRSM_EINVAL. */
int prsm_life_cubic_mean_load_speed_time(double *out_N, const double *loads_N,
                                         const double *speed_rpm, const double *time_fraction,
                                         size_t n, prsm_error *err);

/* Reliability factor a1 for 90, 95, 96, 97, 98, 99 %: 1, 0.62, 0.53, 0.44, 0.33, 0.21
 * (docs/model/kinematics-efficiency-stiffness-life.md). Returns 0 or PRSM_EINVAL for any other percentage. */
int prsm_life_reliability_factor(double *a1, int reliability_percent, prsm_error *err);

typedef struct {
	double capacity_N;          /* C_a used */
	double mean_load_N;         /* F_m used */
	int reliability_percent;    /* 90 .. 99 */
	double reliability_factor;  /* a1 */
	double revolutions;         /* L = a1 (C_a/F_m)^3 1e6 screw revolutions */
	double hours;               /* L / (60 n), at screw speed n (rpm); 0 when n = 0 */
	double distance_km;         /* L x lead, km */
} prsm_life_rating;

/* L10 life (docs/model/kinematics-efficiency-stiffness-life.md) at the given reliability, in revolutions, hours at speed_rpm (>= 0)
 * and distance with lead_mm. Returns 0 or PRSM_EINVAL. */
int prsm_life_l10(prsm_life_rating *out, double capacity_N, double mean_load_N, double speed_rpm,
                  double lead_mm, int reliability_percent, prsm_error *err);

/* ---- static capacity ---- */

typedef struct {
	double p_allow_MPa;         /* allowed peak pressure */
	double q_allow_N;           /* normal load of one contact at which p_max = p_allow */
	double axial_component;     /* n_z of the contact normal: axial load / normal load */
	int contacts;               /* contacts sharing the axial load on this side (Z n_t) */
	double load_factor;         /* most loaded contact / mean contact load, >= 1 */
	double C0a_N;               /* q_allow n_z contacts / load_factor */
} prsm_static_capacity;

/* Static capacity of one side (docs/model/kinematics-efficiency-stiffness-life.md): the axial load at which the most loaded contact
 * reaches p_allow. From a Hertz solution h at any load Q_ref > 0 of this contact
 * (p_max ~ Q^(1/3)): Q_allow = Q_ref (p_allow / p_ref)^3, C_0a = Q_allow n_z contacts / K.
 * Returns 0 or PRSM_EINVAL. */
int prsm_life_static_capacity(prsm_static_capacity *out, const prsm_hertz *h,
                              double axial_component, int contacts, double load_factor,
                              double p_allow_MPa, prsm_error *err);

/* ---- dynamic capacity ---- */

typedef struct {
	const char *name;           /* method, for the output */
	double constant;            /* 98.1, N and mm (Lundberg–Palmgren, Harris) */
	double material_factor;     /* b_m, - (1: L–P's original constant; ISO 281 uses 1.3) */
	double diameter_exponent;   /* 1.8 */
	double combination_exponent;/* 10/3: (sum Q^-x)^(-1/x) over surfaces and rows */
	double life_exponent;       /* 3: L = (C/F)^3 */
	double weibull_slope;       /* e = 10/9 (point contact), for the track-length law */
} prsm_lp_method;

#define PRSM_LP_METHOD_INIT                                                                     \
	{"Lundberg-Palmgren point contact, ball-bearing raceway form (Harris; ISO 281 basis), "    \
	 "roller flank as a ball of diameter 2R",                                                  \
	 98.1, 1.0, 1.8, 10.0 / 3.0, 3.0, 10.0 / 9.0}

/* One raceway of the L–P ball-bearing formula. */
typedef struct {
	double ball_diameter_mm;    /* D */
	double contact_angle_rad;   /* alpha, from the radial plane */
	double pitch_diameter_mm;   /* d_m */
	double conformity;          /* f = groove radius / D (> 0.5); INFINITY for a straight flank */
	int elements;               /* Z */
	int outer;                  /* 0 inner raceway, 1 outer */
} prsm_lp_raceway;

/* Q_c of one raceway (normal load per element, N, for 1e6 revolutions of the rings relative to
 * each other). Returns 0 or PRSM_EINVAL. */
int prsm_life_raceway_rating(double *out_N, const prsm_lp_raceway *r, const prsm_lp_method *m,
                             prsm_error *err);

/* (sum q_i^(-x))^(-1/x): the L–P combination of ratings in series (x = 10/3), N. 0 if any
 * q_i <= 0. */
double prsm_life_combine_ratings(const double *ratings_N, size_t n, double exponent);

/* L–P factor of an unequal load distribution over rows of equal rating: with loads q_k and
 * mean q, [mean((q_k/q)^x)]^(-1/x) (x = 10/3), <= 1, 1 for equal loads. Returns NaN when
 * n = 0 or the loads sum to 0. */
double prsm_life_distribution_factor(const double *loads_N, size_t n, double exponent);

typedef struct {
	prsm_lp_method method;      /* echo */
	double ball_diameter_mm;    /* D = 2R */
	double contact_angle_rad;   /* alpha = pi/2 - beta */
	double gamma;               /* D cos alpha / d_m = r_r / a */
	double carrier_ratio;       /* k_c = r_s / (2a) */
	double q_screw_N;           /* screw raceway, normal load per contact */
	double q_nut_N;             /* nut raceway */
	double q_roller_screw_side_N, q_roller_nut_side_N; /* roller flanks */
	double q_combined_N;        /* the four combined (L-P), normal load per contact */
	double axial_contact_N;     /* q_combined sin alpha: axial rating of one roller-thread */
	double row_N;               /* one thread row: Z axial_contact */
	int rollers, threads;       /* Z, n_t */
	double load_factor;         /* input, multiplies the rating */
	double C_a_N;               /* load_factor row n_t^(7/10): axial dynamic capacity */
} prsm_dynamic_capacity;

/* Dynamic capacity of a resolved design by the method (NULL: PRSM_LP_METHOD_INIT) with a
 * load-distribution factor in (0, 1]. Returns 0 or PRSM_EINVAL. */
int prsm_life_dynamic_capacity(prsm_dynamic_capacity *out, const prsm_design *d,
                               const prsm_lp_method *m, double load_factor, prsm_error *err);

/* ---- preload ---- */

/* Load on the working half of a nut preloaded by F_pr against a second half (ball-screw
 * practice, e.g. the "modified external load" of ball-screw catalogues): from Hertz's
 * delta ~ Q^(2/3) for both halves, the unloaded half lifts off at |F| = 2^(3/2) F_pr; below
 * that the working half carries F_pr (1 + |F| / (2^(3/2) F_pr))^(3/2) (exact at both ends,
 * an approximation between), above it |F|. Returns 0 or PRSM_EINVAL. */
int prsm_life_preload_load(double *out_N, double load_N, double preload_N, prsm_error *err);

/* ---- column limits ---- */

enum {
	PRSM_FIXITY_FIXED_FREE = 0,
	PRSM_FIXITY_SUPPORTED_SUPPORTED = 1,
	PRSM_FIXITY_FIXED_SUPPORTED = 2,
	PRSM_FIXITY_FIXED_FIXED = 3
};

typedef struct {
	int fixity;                 /* PRSM_FIXITY_* */
	double root_diameter_mm;    /* d_r */
	double free_length_mm;      /* L between supports (or to the free end) */
	double buckling_factor;     /* m: 1/4, 1, 2.046, 4 */
	double speed_eigenvalue;    /* lambda of the first bending mode: 1.875, pi, 3.927, 4.730 */
	double catalogue_speed_factor; /* f_c of n = f_c d_r / L^2 1e7: 3.4, 9.7, 15.1, 21.9 */
	double critical_speed_rpm;  /* beam theory: (60/2pi) (lambda/L)^2 sqrt(E I/(rho A)) */
	double catalogue_speed_rpm; /* f_c d_r / L^2 1e7 (includes the catalogues' 0.8) */
	double buckling_load_N;     /* Euler: m pi^2 E I / L^2, I = pi d_r^4 / 64 */
} prsm_column;

/* Column limits of a screw: critical speed (beam theory with E and density, and the
 * catalogue formula for steel) and Euler buckling load, no safety factor applied except the
 * one built into the catalogue constants. Returns 0 or PRSM_EINVAL. */
int prsm_life_column(prsm_column *out, double root_diameter_mm, double free_length_mm, int fixity,
                     double E_MPa, double density_kg_m3, prsm_error *err);

#endif
