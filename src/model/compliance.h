/*
 * compliance.h: thread-tooth compliance and body-segment stretch compliance (docs/model/kinematics-efficiency-stiffness-life.md,
 * "Thread compliance" and "Load distribution over threads").
 *
 * Yamamoto's tooth formulas (A. Yamamoto, The Theory and Computation of Threads Connection,
 * Yokendo, Tokyo 1980; reproduced for PRSM threads by e.g. Zhang, Liu, Tong, Ma, "Load
 * distribution of planetary roller screw mechanism and its improvement approach", Proc. IMechE
 * C 230 (2016)) give the axial deflection of a thread tooth at its load point per unit thread
 * width, for an axial load W per unit width (N/mm), as five terms, each W/E times a factor of
 * the tooth shape (a: tooth thickness at the root, b: at the load point, c: radial distance
 * from the root to the load point, beta: flank half-angle, P: pitch, d: pitch diameter):
 *
 *   bending     (1 - nu^2) 3/4 [ (1 - (2 - b/a)^2 + 2 ln(a/b)) cot^3 beta - 4 (c/a)^2 tan beta ]
 *   shear       (1 + nu) 6/5 cot beta ln(a/b)
 *   root tilt   (1 - nu^2) 12 c / (pi a^2) (c - (b/2) tan beta)
 *   root shear  (1 - nu^2) 2/pi [ (P/a) ln((P + a/2)/(P - a/2)) + 1/2 ln(4 P^2/a^2 - 1) ]
 *   radial      external thread (solid body): (1 - nu) (tan^2 beta / 2) (d / P)
 *               internal thread (ring of outer diameter D_o):
 *                  ((D_o^2 + d^2)/(D_o^2 - d^2) + nu) (tan^2 beta / 2) (d / P)
 *
 * (The radial term is the axial projection, tan beta, of the radial displacement of a solid
 * cylinder, or of a thick ring by Lame, under the radial flank pressure W tan beta / P.)
 * A sum of terms lambda (mm^2/N) turns into the axial compliance of one thread contact
 * (mm/N) as  c = calibration * lambda / w  with an effective width w (mm) that Yamamoto's
 * bolt-nut setting does not need (there the load runs round the whole turn) and the PRSM,
 * with point contacts, does. The width is always explicit here and named by a rule:
 *
 *   PRSM_THREAD_WIDTH_SHARE (default): w = fraction x the thread circumference at the pitch
 *     radius per contact on it: 2 pi r_s / Z on the screw, 2 pi r_n / Z on the nut, pi r_r on
 *     the roller (two contacts per roller turn, one per side). fraction 1 is Yamamoto's own
 *     assumption (load spread evenly round the turn) applied per contact: the stiffest of the
 *     choices, an upper bound of the thread stiffness.
 *   PRSM_THREAD_WIDTH_GIVEN: w = width_mm for every part (1 mm reproduces the codes that use
 *     the per-unit-width values as they are).
 *   PRSM_THREAD_WIDTH_ELLIPSE: w = factor x 2a, a the Hertz semi-major axis at the contact
 *     (load-dependent; the caller passes a).
 *   PRSM_THREAD_COMPLIANCE_NONE: rigid threads, compliance 0.
 * Stiffness differs by a factor of about 3 or more between these rules (docs/model/kinematics-efficiency-stiffness-life.md): the
 * caller must echo the rule, the width and the calibration factor with every result.
 *
 * The known pathology: with 90-degree profiles (beta = 45 deg) the short, wide teeth of a PRSM
 * (c/a about 0.25) make the bending term negative, because its radial-load part
 * -4 (c/a)^2 tan beta outgrows the cantilever part; the root-tilt term goes negative when
 * c < (b/2) tan beta. The slender-cantilever assumptions behind the formula do not hold
 * there. Every negative term is flagged (bit mask); by default (PRSM_YAMAMOTO_CLAMP) it is set
 * to 0, so the compliance is never below the sum of the non-negative terms; PRSM_YAMAMOTO_KEEP
 * keeps the terms as printed (flagged, and refused if the sum is not positive).
 *
 * Units: mm, N, MPa, rad. No allocation.
 */
#ifndef PRSM_MODEL_COMPLIANCE_H
#define PRSM_MODEL_COMPLIANCE_H

#include <math.h>

#include "model/design.h"
#include "util/error.h"

/* Threaded parts. */
enum { PRSM_THREAD_SCREW = 0, PRSM_THREAD_ROLLER = 1, PRSM_THREAD_NUT = 2 };

/* Effective-width rules (echo the rule with the result). */
enum {
	PRSM_THREAD_COMPLIANCE_NONE = 0, /* rigid threads: compliance 0 */
	PRSM_THREAD_WIDTH_SHARE = 1,     /* fraction x circumference at the pitch radius per contact */
	PRSM_THREAD_WIDTH_GIVEN = 2,     /* one explicit width, mm */
	PRSM_THREAD_WIDTH_ELLIPSE = 3    /* factor x Hertz major axis 2a */
};

/* What to do with a Yamamoto term that comes out negative. */
enum { PRSM_YAMAMOTO_CLAMP = 0, PRSM_YAMAMOTO_KEEP = 1 };

/* Bits of prsm_yamamoto.negative_terms. */
enum {
	PRSM_YAMAMOTO_BENDING = 1,
	PRSM_YAMAMOTO_SHEAR = 2,
	PRSM_YAMAMOTO_ROOT_TILT = 4,
	PRSM_YAMAMOTO_ROOT_SHEAR = 8,
	PRSM_YAMAMOTO_RADIAL = 16
};

/* Nut outer radius used when the caller gives none: 1.3 r_n, a roller-screw nut wall of
 * about 0.3 r_n. An assumption, echoed in prsm_design_compliance.nut_outer_radius_mm. */
#define PRSM_NUT_OUTER_PER_PITCH_RADIUS 1.3

typedef struct {
	int width_rule;             /* PRSM_THREAD_COMPLIANCE_NONE or PRSM_THREAD_WIDTH_* */
	double width_fraction;      /* SHARE: fraction of the circumference share, - */
	double width_mm;            /* GIVEN: effective width, mm */
	double ellipse_factor;      /* ELLIPSE: w = factor x 2a, - */
	double calibration;         /* multiplies every thread compliance, - */
	int negative_terms;         /* PRSM_YAMAMOTO_CLAMP or PRSM_YAMAMOTO_KEEP */
	double nut_outer_radius_mm; /* outer radius of the nut body, mm; NaN: 1.3 r_n */
} prsm_compliance_options;

/* Defaults: circumference share with fraction 1, calibration 1, negative terms clamped,
 * nut outer radius 1.3 r_n. */
#define PRSM_COMPLIANCE_OPTIONS_INIT \
	{PRSM_THREAD_WIDTH_SHARE, 1.0, 1.0, 1.0, 1.0, PRSM_YAMAMOTO_CLAMP, NAN}

/* Shape of one thread tooth in the axial section, as Yamamoto's formulas need it. */
typedef struct {
	double pitch_mm;            /* P */
	double flank_angle_rad;     /* beta, from the radial line */
	double root_thickness_mm;   /* a: axial tooth thickness at the root */
	double load_thickness_mm;   /* b: axial tooth thickness at the load point (pitch line) */
	double load_height_mm;      /* c: radial distance from the root to the load point */
	double diameter_mm;         /* d: pitch diameter (radial term) */
	double outer_diameter_mm;   /* D_o: outer diameter of an internal thread's body, mm */
	int internal;               /* 1 for an internal thread (nut), 0 for screw and roller */
	double E_MPa;               /* Young's modulus, MPa */
	double poisson;             /* Poisson's ratio, - */
} prsm_thread_tooth;

/* Yamamoto's terms, axial deflection per unit load per unit width, mm^2/N (as printed, before
 * the negative-term policy), and their sum after the policy. */
typedef struct {
	double bending, shear, root_tilt, root_shear, radial; /* mm^2/N */
	double sum_mm2_per_N;       /* sum used: negative terms 0 when clamped, mm^2/N */
	int negative_terms;         /* PRSM_YAMAMOTO_* bits of the terms that came out negative */
	int clamped;                /* 1 when negative terms were set to 0 */
} prsm_yamamoto;

/* The compliance of one thread contact, with everything that made it. */
typedef struct {
	int part;                   /* PRSM_THREAD_* */
	int width_rule;             /* rule used (echo) */
	double width_mm;            /* effective width used, mm (0 for NONE) */
	double calibration;         /* calibration factor used, - */
	prsm_thread_tooth tooth;    /* tooth shape used */
	prsm_yamamoto terms;        /* per-unit-width terms */
	double compliance_mm_per_N; /* axial compliance of one thread contact, mm/N */
} prsm_thread_compliance;

/* The thread compliances of a design and the series sums per side. */
typedef struct {
	prsm_compliance_options options;          /* echo, with the nut outer radius resolved */
	double nut_outer_radius_mm;               /* used for the nut's radial term, mm */
	prsm_thread_compliance screw;             /* screw thread at a screw-side contact */
	prsm_thread_compliance roller_screw_side; /* roller thread at a screw-side contact */
	prsm_thread_compliance roller_nut_side;   /* roller thread at a nut-side contact */
	prsm_thread_compliance nut;               /* nut thread at a nut-side contact */
	double screw_side_mm_per_N;               /* screw + roller (screw side), axial, mm/N */
	double nut_side_mm_per_N;                 /* nut + roller (nut side), axial, mm/N */
	int negative_terms;                       /* OR of the parts' negative-term bits */
} prsm_design_compliance;

/* Axial stretch compliances of the body segments over one pitch (spring chain, docs/model/kinematics-efficiency-stiffness-life.md). */
typedef struct {
	double screw_area_mm2;      /* pi r_root^2 of the screw */
	double roller_area_mm2;     /* pi r_root^2 of the roller */
	double nut_area_mm2;        /* pi (R_o^2 - r_root^2) of the nut */
	double screw_mm_per_N;      /* P / (E A), screw core */
	double roller_mm_per_N;     /* P / (E A), roller core */
	double nut_mm_per_N;        /* P / (E A), nut annulus */
} prsm_segment_compliance;

/* Yamamoto's five terms of one tooth, and their sum under the policy (PRSM_YAMAMOTO_*).
 * Returns 0, or PRSM_EINVAL (err says which) for a shape outside the formulas' domain
 * (0 < b <= a < 2P, c >= 0, E > 0, D_o > d for an internal thread) or, with KEEP, a sum that
 * is not positive. */
int prsm_compliance_yamamoto(prsm_yamamoto *out, const prsm_thread_tooth *tooth,
                             int negative_policy, prsm_error *err);

/* Tooth shape of a part of a resolved design (docs/model/geometry-and-meshing.md): b = P/2 - 2 t (flank shift t),
 * c = the depth from the pitch line to the root radius, or to where the groove between two
 * teeth closes if that comes first (the default dedendum 0.3 P is deeper than the V of a
 * 45-degree thread), a = the tooth thickness there (at most P). The roller's arc flank gives
 * its true thickness; its flank angle is the arc's slope at the pitch circle (= beta).
 * nut_outer_radius_mm is used for the nut only. Returns 0 or PRSM_EINVAL (e.g. thinning
 * leaves no tooth). */
int prsm_compliance_tooth(prsm_thread_tooth *out, const prsm_design *d, int part,
                          double nut_outer_radius_mm, prsm_error *err);

/* Compliance of one thread contact of a tooth: calibration x sum / w, w from the options
 * (share_circumference_mm: the part's circumference share per contact for the SHARE rule;
 * ellipse_a_mm: the Hertz semi-major axis for the ELLIPSE rule; either may be 0 when its rule
 * is not used). part is echoed. Returns 0 or PRSM_EINVAL. */
int prsm_compliance_thread(prsm_thread_compliance *out, const prsm_thread_tooth *tooth, int part,
                           const prsm_compliance_options *opt, double share_circumference_mm,
                           double ellipse_a_mm, prsm_error *err);

/* Screw, roller and nut thread compliances of a resolved design with the options (NULL:
 * defaults). ellipse_a_mm[0] (screw side) and [1] (nut side) are the Hertz semi-major axes,
 * needed only by the ELLIPSE rule (NULL otherwise). Returns 0 or PRSM_EINVAL. */
int prsm_compliance_design(prsm_design_compliance *out, const prsm_design *d,
                           const prsm_compliance_options *opt, const double ellipse_a_mm[2],
                           prsm_error *err);

/* The nut outer radius used: given_mm, or 1.3 r_n when it is NaN, mm. */
double prsm_compliance_nut_outer_radius_mm(double given_mm, const prsm_design *d);

/* Axial stretch compliance of a uniform bar: length / (E A), mm/N. */
double prsm_compliance_stretch(double length_mm, double E_MPa, double area_mm2);

/* Stretch compliances over one pitch of the screw core (root radius), roller core (root
 * radius) and nut annulus (root radius to nut_outer_radius_mm; NaN: 1.3 r_n). Returns 0 or
 * PRSM_EINVAL (non-positive area or modulus). */
int prsm_compliance_segments(prsm_segment_compliance *out, const prsm_design *d,
                             double nut_outer_radius_mm, prsm_error *err);

#endif
