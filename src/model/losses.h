/*
 * losses.h: efficiency of a PRSM at an operating point with every loss, and the torque and
 * power split by cause (docs/model/kinematics-efficiency-stiffness-life.md, second bullet).
 *
 * Input torque on the screw (N m), direct drive (torque in, axial force out):
 *   T = F L / (2 pi eta_slide) + T_spin + T_gear + T_drag + T_seal,   eta = F L / (2 pi T)
 * Back-driving (the load F pushes the nut, the screw delivers torque):
 *   T_out = F L eta'_slide / (2 pi) - T_spin - T_gear - T_drag - T_seal,
 *   eta' = 2 pi T_out / (F L), clamped at 0 (then PRSM_LOSSES_SELF_LOCKING).
 * F and omega enter by magnitude (the losses oppose the motion whatever its sense).
 *
 * 1. Sliding: eta_slide and eta'_slide are prsm_efficiency_sliding's (model/efficiency.h).
 *
 * 2. Spin (docs/model/kinematics-efficiency-stiffness-life.md with the Hertz contact of §6). Every body turns about an axis parallel
 *    to the screw axis z in the nominal design: screw omega, nut 0, carrier k_c omega, and the
 *    roller k_c omega about z plus its spin relative to the carrier about its own axis, also
 *    along z. Angular velocities add as free vectors (the axis offsets only add translations),
 *    so the roller's absolute angular velocity is Omega_r = roller_abs_ratio omega z-hat and
 *    the relative angular velocity of roller and body is (Omega_r - omega_b) z-hat: purely
 *    axial (true while the roller axes stay parallel to z; a tilted roller adds a radial part).
 *    Its component along the unit contact normal n is the spin speed, rad/s:
 *      omega_spin,screw = (roller_abs_ratio - 1) n_z,s omega,
 *      omega_spin,nut   =  roller_abs_ratio      n_z,n omega,      n_z = contact->normal[2].
 *    Friction against full spin over the Hertz ellipse (p = p_max sqrt(1 - x^2/a^2 - y^2/b^2),
 *    Q = 2 pi a b p_max / 3) gives the moment, N mm,
 *      M = integral of mu p sqrt(x^2 + y^2) dA = (3/8) mu Q a E(e),  e^2 = 1 - b^2/a^2
 *    (x = a r cos t, y = b r sin t: mu p_max a b (pi/16) 4 a E(e), with p_max = 3Q/(2 pi a b)),
 *    E the complete elliptic integral of the second kind of modulus e (GSL's convention:
 *    gsl_sf_ellint_Ecomp takes the modulus e, not the parameter e^2). a, b scale as Q^(1/3):
 *    one prsm_hertz_solve per side at Q = 1 N gives them for every load. The spin power is
 *    Z sum M |omega_spin| (every roller alike) and T_spin is that power / omega. The spin moment
 *    is the full-spin value even where the contact also slides grossly (screw side), where
 *    the true moment is smaller: an upper bound there.
 *
 * 3. Ring-gear mesh. Each roller carries spur teeth at its ends in mesh with the ring gears
 *    fixed in the nut; they take whatever moment about the roller's own axis the contacts
 *    leave. On one roller (axis A, parallel to z) the contact forces are the normal force N n,
 *    the sliding friction f = -mu N s/|s| (s: slip of the roller against the body,
 *    prsm_kinematics; zero at a rolling contact, |s| < 1e-9 |v|) and the spin couple
 *    -M sign(Omega_r - omega_b) n. The roller flank, either side of its thread, is invariant
 *    under the screw motion (turn d phi about A, advance p_r d phi), so a force normal to it has
 *    the moment -p_r N_z about A; the roller floats axially, so sum N_z = -sum f_z and the
 *    normal forces together have the moment p_r sum f_z. The moment the gear must balance is
 *      M_roller = sum over the roller's contacts of [ f . (z-hat x (p - A) + p_r z-hat)
 *                                                    - M sign(Omega_r - omega_b) |n_z| ],
 *    that is: the tangential friction times its lever arm, plus the helix term p_r f_z, plus
 *    the spin couples' axial parts. The tangential gear force is F_t = |M_roller| / r_gear
 *    (shared by the two ring gears). Static friction at the rolling nut contact could carry part
 *    of this moment; taking all of it through the gear makes the mesh loss an upper bound.
 *    Mesh loss per roller (Ohlendorf's tooth-loss factor, as in ISO/TR 14179-2):
 *      P = mu_gear F_t v_pitch H_v,   v_pitch = |roller spin relative to the carrier| r_gear omega
 *      H_v = pi (u - 1) / (z_1 u) (1 - eps_alpha + eps_1^2 + eps_2^2),   u = z_2 / z_1
 *    for the internal spur mesh. External pairs have (u + 1): the sliding speed at a distance x
 *    from the pitch point is x |omega_1 -+ omega_2|, the difference for an internal pair whose
 *    members turn the same way; averaging mu F |v_slide| over a mesh period with one tooth
 *    carrying F in the single-contact zone and two carrying F/2 in the double zones gives the
 *    polynomial, valid for 1 <= eps_alpha <= 2 and eps_1, eps_2 <= 1 (the test checks it by
 *    integration). Sources: the FVA KnowledgeBase "Power loss" page
 *    (doc.fva-service.de/90/en/root-power-loss.html: cylindrical-gear H_v after Ohlendorf) and
 *    a public gearbox-loss script implementing H_v = pi (u + 1)/(z_1 u cos beta_b)(...) for
 *    external spur/helical pairs (Ohlendorf's dissertation, ISO/TR 14179-2 and Fernandes et al.
 *    were not at hand to check); the internal sign (u - 1) is the ISO convention of a negative
 *    u for internal gears and follows from the derivation above.
 *    Teeth: z_1 given, or the smallest z_1 >= 17 (the undercut limit of a 20 deg standard
 *    pinion) for which z_1 r_n / r_r is an integer within 1e-9, or 17 when none up to 1000 is;
 *    z_2 given, or round(z_1 r_n / r_r). When z_2 / z_1 differs from r_n / r_r the gears fight
 *    the threads (roller migration, docs/model/geometry-and-meshing.md): PRSM_LOSSES_GEAR_RATIO; the loss is still
 *    computed from the thread kinematics. eps_1 = eps_2 = eps_alpha / 2 unless both are given.
 *    The pressure angle only sets the normal and radial tooth forces reported.
 *
 * 4. Drag and seal: T_drag = drag_torque + viscous_drag |omega|, T_seal = seal_torque.
 *
 * Loads: the normal loads of one roller's n_t screw-side and n_t nut-side contacts (from a
 * load distribution; every roller alike), or NULL for the equal share F / (Z n_t |n_z|) of
 * docs/model/kinematics-efficiency-stiffness-life.md. Given loads are used as they are (not checked against F).
 *
 * Special operating points:
 *  - omega = 0 (PRSM_LOSSES_AT_REST): torques and efficiencies are the omega -> 0+ limits
 *    (viscous drag 0), every power and spin speed is 0.
 *  - F = 0 (PRSM_LOSSES_NO_LOAD): nothing is delivered. With a drag or seal torque (or given
 *    loads that still cause spin or gear losses) T > 0 and eta = eta' = 0. With no torque at
 *    all (T = 0) eta and eta' are the F -> 0+ limits for the equal share (sliding and the part
 *    of the gear loss proportional to F; spin vanishes like F^(1/3)): PRSM_LOSSES_LIMIT.
 *
 * Units: mm, N, rad, s inside; torques N m, powers W, speeds rad/s and m/s at the output.
 * No allocation, no global state.
 */
#ifndef PRSM_MODEL_LOSSES_H
#define PRSM_MODEL_LOSSES_H

#include <math.h>

#include "model/contact.h"
#include "model/design.h"
#include "model/kinematics.h"
#include "util/error.h"

/* Flags of prsm_losses_result.flags. */
enum {
	PRSM_LOSSES_SELF_LOCKING = 1, /* under load, back-driving delivers no torque: eta' = 0 */
	PRSM_LOSSES_NO_LOAD = 2,      /* F = 0 */
	PRSM_LOSSES_AT_REST = 4,      /* omega = 0: powers 0, torques are the omega -> 0+ limits */
	PRSM_LOSSES_LIMIT = 8,        /* eta, eta' are the F -> 0+ limits (no load, no torque) */
	PRSM_LOSSES_GEAR_RATIO = 16,  /* z_2 / z_1 != r_n / r_r: gears and threads disagree */
	PRSM_LOSSES_DRIVE_LOCKED = 32 /* friction wedges the flanks: eta 0, the input torque and the
	                                 powers that need it NaN, nothing else computed */
};

/* Smallest default roller gear teeth (undercut limit of a 20 deg standard pinion). */
#define PRSM_LOSSES_ROLLER_TEETH_MIN 17

typedef struct {
	int spin;                      /* 1: spin friction at the contacts; 0: off */
	int gear;                      /* 1: ring-gear mesh loss; 0: off */
	double gear_mu;                /* mean Coulomb mu of the gear teeth, - (0.05) */
	int gear_teeth_roller;         /* z_1 of each roller gear; 0: the default rule */
	int gear_teeth_ring;           /* z_2 of each ring gear; 0: round(z_1 r_n / r_r) */
	double gear_contact_ratio;     /* eps_alpha, in [1, 2], - (1.5) */
	double gear_eps_roller;        /* eps_1, roller-tip share of eps_alpha; NaN: eps_alpha/2 */
	double gear_eps_ring;          /* eps_2, ring-tip share; NaN: eps_alpha / 2. Both or none;
	                                  when given, eps_alpha = eps_1 + eps_2 */
	double gear_pressure_angle_rad;/* alpha, rad (20 deg) */
	double gear_pitch_radius_mm;   /* roller gear pitch radius r_gear, mm; NaN: r_r */
	double drag_torque_Nm;         /* constant drag torque on the screw, N m (0) */
	double viscous_drag_Nm_s_per_rad; /* drag torque per screw speed, N m s/rad (0) */
	double seal_torque_Nm;         /* seal torque on the screw, N m (0) */
} prsm_losses_options;

#define PRSM_LOSSES_OPTIONS_INIT                                                                  \
	{1, 1, 0.05, 0, 0, 1.5, NAN, NAN, 20.0 * M_PI / 180.0, NAN, 0.0, 0.0, 0.0}

typedef struct {
	/* efficiencies, - */
	double eta;                    /* direct: F L / (2 pi T) */
	double eta_back;               /* back-driving: 2 pi T_out / (F L), >= 0 */
	double eta_slide, eta_back_slide; /* sliding only (prsm_efficiency_sliding) */
	double eta_closed_form;        /* tan(beta) / tan(beta + atan mu) (docs/model/kinematics-efficiency-stiffness-life.md) */
	double eta_back_closed_form;   /* tan(beta - atan mu) / tan(beta) */
	/* torques on the screw, N m */
	double ideal_torque_Nm;        /* F L / 2 pi */
	double sliding_torque_Nm;      /* F L / (2 pi eta_slide) - F L / 2 pi */
	double spin_torque_Nm, gear_torque_Nm, drag_torque_Nm, seal_torque_Nm;
	double input_torque_Nm;        /* T, the sum of the above */
	double back_output_torque_Nm;  /* T_out, unclamped: < 0 when the screw must hold the load */
	/* powers at the operating speed, W */
	double input_power_W, output_power_W; /* T omega, F v */
	double sliding_power_W, spin_power_W, gear_power_W, drag_power_W, seal_power_W;
	double loss_power_W;           /* sum of the five losses */
	/* spin (docs/model/kinematics-efficiency-stiffness-life.md) */
	double spin_speed_screw_rad_s, spin_speed_nut_rad_s; /* signed, along the contact normal */
	double spin_moment_screw_Nm, spin_moment_nut_Nm;     /* sum over one roller's n_t contacts */
	double spin_ellint_E_screw, spin_ellint_E_nut;       /* E(e) of the contact ellipses, - */
	/* gear mesh, per roller */
	int gear_teeth_roller, gear_teeth_ring;  /* z_1, z_2 used */
	double gear_eps_alpha, gear_eps_roller, gear_eps_ring; /* contact ratios used, - */
	double gear_Hv;                /* tooth-loss factor H_v, - (0 when the gear loss is off) */
	double roller_moment_friction_Nm; /* tangential sliding friction x lever arm, N m */
	double roller_moment_helix_Nm; /* p_r sum f_z: normal forces balancing friction's axial part */
	double roller_moment_spin_Nm;  /* axial parts of the spin couples, N m */
	double roller_moment_Nm;       /* their sum, the moment the gears balance (signed), N m */
	double gear_tangential_force_N;/* F_t = |M_roller| / r_gear, both ring gears together, N */
	double gear_normal_force_N;    /* F_t / cos(alpha), N */
	double gear_pitch_speed_m_s;   /* v_pitch, m/s */
	int flags;                     /* PRSM_LOSSES_* */
} prsm_losses_result;

/* The options of a design's "losses" section (model/design.h); the fields the design has no
 * place for (eps_1, eps_2, r_gear) keep their defaults. */
void prsm_losses_options_from_design(prsm_losses_options *out, const prsm_design *d);

/* Spin moment (3/8) mu Q a E(e), e^2 = 1 - b^2/a^2, of a Hertz contact with semi-axes
 * a_mm >= b_mm > 0 under the normal load Q_N, N mm (docs/model/kinematics-efficiency-stiffness-life.md). */
double prsm_losses_spin_moment_Nmm(double mu, double Q_N, double a_mm, double b_mm);

/* Ohlendorf's tooth-loss factor of an internal spur mesh, pi (u - 1)/(z_1 u)
 * (1 - eps_alpha + eps_1^2 + eps_2^2), u = z_2 / z_1 (see above), -. No checks. */
double prsm_losses_gear_loss_factor(int z1, int z2, double eps_alpha, double eps_1, double eps_2);

/*
 * The part of prsm_losses_compute that depends only on the nominal design, its contacts and the
 * options, not on the friction coefficients, the loads, the operating point or the kinematics:
 * the Hertz semi-major axis at 1 N and E(e) of each contact (when spin is on: two
 * prsm_hertz_solve, the costly part) and the ring-gear teeth and contact ratios. A caller that
 * evaluates the losses many times with only the friction coefficients changed (the Monte Carlo
 * model, mc/prsm_model.h) prepares it once and calls prsm_losses_compute_prepared; the results
 * are bit-identical to prsm_losses_compute's. An error found here is kept and reported by
 * prsm_losses_compute_prepared at the point where prsm_losses_compute reports it.
 */
typedef struct {
	int spin;                      /* the Hertz part below was computed (opts->spin was on) */
	int hertz_rc;                  /* 0, or a side's prsm_hertz_solve error (PRSM_EINVAL: not
	                                  Hertzian, reported as PRSM_EGEOMETRY) */
	double a1_mm[2];               /* Hertz semi-major axis at Q = 1 N, screw and nut side, mm */
	double ellint_E[2];            /* E(e) of the contact ellipses, screw and nut side, - */
	int gear_rc;                   /* 0, or the error of the gear teeth or contact ratios */
	prsm_error gear_err;           /* its message when gear_rc != 0 */
	int gear_flags;                /* PRSM_LOSSES_GEAR_RATIO or 0 */
	int gear_teeth_roller, gear_teeth_ring;                /* z_1, z_2 */
	double gear_eps_alpha, gear_eps_roller, gear_eps_ring; /* contact ratios, - */
	double gear_Hv;                /* Ohlendorf's H_v with the gear loss on, - */
} prsm_losses_nominal;

/* Fill *out for design d (its friction coefficients and operating point are not read), its
 * nominal contacts and the options (NULL: PRSM_LOSSES_OPTIONS_INIT). */
void prsm_losses_prepare(prsm_losses_nominal *out, const prsm_design *d, const prsm_contact *screw,
                         const prsm_contact *nut, const prsm_losses_options *opts);

/*
 * Losses and efficiencies of design d at its operating point (d->axial_load_N,
 * d->screw_speed_rad_s) from the nominal contacts and kinematics (prsm_analysis_nominal).
 * Returns 0; PRSM_EINVAL (err says which input) for a negative or non-finite torque, friction
 * coefficient, load or speed, bad teeth or contact ratios, no rollers or threads, or a sliding
 * efficiency of 0 (the flanks wedge); PRSM_EGEOMETRY when spin is on and a contact is not
 * Hertzian. out is zeroed first.
 */
int prsm_losses_compute(prsm_losses_result *out,
                        const prsm_design *d,          /* resolved design and operating point */
                        const prsm_kinematics *k,      /* prsm_kinematics_compute of the contacts */
                        const prsm_contact *screw,     /* nominal screw-roller contact */
                        const prsm_contact *nut,       /* nominal nut-roller contact */
                        const double *screw_loads_N,   /* n_t normal loads of one roller, or NULL */
                        const double *nut_loads_N,     /* n_t normal loads of one roller, or NULL */
                        const prsm_losses_options *opts, /* NULL: PRSM_LOSSES_OPTIONS_INIT */
                        prsm_error *err);

/* prsm_losses_compute with the friction-independent part taken from nominal, which
 * prsm_losses_prepare filled for the same design (friction and operating point aside), contacts
 * and options. PRSM_EINVAL when spin is on and nominal was prepared with it off. */
int prsm_losses_compute_prepared(prsm_losses_result *out, const prsm_losses_nominal *nominal,
                                 const prsm_design *d, const prsm_kinematics *k,
                                 const prsm_contact *screw, const prsm_contact *nut,
                                 const double *screw_loads_N, const double *nut_loads_N,
                                 const prsm_losses_options *opts, prsm_error *err);

#endif
