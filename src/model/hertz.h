/*
 * hertz.h: Hertz point contact in Harris's formulation (docs/model/kinematics-efficiency-stiffness-life.md).
 *
 * From the relative principal curvatures k1 <= k2 (1/mm): sum rho = k1 + k2 and the curvature
 * difference F(rho) = (k2 - k1)/(k1 + k2). The ellipticity kappa = a/b solves
 *   F(rho) = ((kappa^2 + 1) E(e) - 2 K(e)) / ((kappa^2 - 1) E(e)),  e^2 = 1 - 1/kappa^2
 * with complete elliptic integrals K, E (GSL). Then
 *   a* = (2 kappa^2 E / pi)^(1/3), b* = (2 E / (pi kappa))^(1/3),
 *   delta* = (2 K / pi) (pi / (2 kappa^2 E))^(1/3),
 *   a = a* (3 Q S / (2 sum rho))^(1/3), b likewise, delta = delta* (3 Q S/(2 sum rho))^(2/3) sum rho/2,
 *   p_max = 3 Q / (2 pi a b),  S = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.
 */
#ifndef PRSM_MODEL_HERTZ_H
#define PRSM_MODEL_HERTZ_H

typedef struct {
	double sum_rho_per_mm;   /* k1 + k2, 1/mm */
	double curvature_difference; /* F(rho), - */
	double kappa;            /* a/b, >= 1 */
	double ellint_K, ellint_E; /* complete elliptic integrals of modulus e */
	double a_star, b_star, delta_star; /* dimensionless Harris coefficients */
	double a_mm, b_mm;       /* semi-axes of the contact ellipse, mm */
	double delta_mm;         /* approach of the two bodies, mm */
	double p_max_MPa;        /* peak pressure, MPa */
	double load_N;           /* normal load Q, N */
} prsm_hertz;

/* Solve the contact of two bodies with relative principal curvatures k1, k2 (1/mm, both > 0)
 * under normal load Q_N >= 0. Returns 0, or PRSM_EINVAL when either principal curvature is not
 * positive, a modulus is not positive, the load is negative or the curvature sum is not finite
 * (or prsm_hertz_coefficients' error). */
int prsm_hertz_solve(prsm_hertz *out, double k1_per_mm, double k2_per_mm, double E1_MPa,
                     double nu1, double E2_MPa, double nu2, double Q_N);

/* The ellipticity solve. F <= PRSM_HERTZ_CIRCLE_F is the circular contact, exactly: kappa = 1,
 * K = E = pi/2. Otherwise kappa is the root of F(kappa) = F in ln kappa by GSL's Brent solver
 * (gsl_root_fsolver_brent, always given a checked bracket) to an interval of width
 * PRSM_HERTZ_TOL (1 + ln kappa) in ln kappa, i.e. kappa to a relative 1e-15 (1 + ln kappa), the
 * tolerance of the bisection it replaces. F above F(PRSM_HERTZ_KAPPA_MAX) = 1 - 2.8e-11 (a
 * curvature ratio k2/k1 beyond 7e10) gives kappa = PRSM_HERTZ_KAPPA_MAX. Whatever the solver,
 * kappa is only as good as F(kappa) computed in doubles: near the circle (K + E) cancellation
 * limits it to about 1e-15 / F relative (no worse than about 2e-8 below F = 1e-7, k2/k1 within
 * 2e-7 of 1), near F = 1 the rounding of F itself to about 1e-16 / (1 - F). GSL's error handler
 * is not touched: the solver gets a checked bracket and finite values, and its return codes are
 * checked. */
#define PRSM_HERTZ_CIRCLE_F 1e-10
#define PRSM_HERTZ_KAPPA_MAX 1e6
#define PRSM_HERTZ_TOL 1e-15
#define PRSM_HERTZ_MAX_ITER 100

/* Only the dimensionless part: kappa, K, E, a*, b*, delta* for a curvature difference F in
 * [0, 1). Returns 0, PRSM_EINVAL (F outside [0, 1)), or PRSM_ENOMEM / PRSM_ENOCONVERGE (the
 * solver could not be allocated, or did not converge in PRSM_HERTZ_MAX_ITER iterations; neither
 * is expected). */
int prsm_hertz_coefficients(prsm_hertz *out, double curvature_difference);

#endif
