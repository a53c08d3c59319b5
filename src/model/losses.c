/*
 * losses.c: efficiency with spin, ring-gear mesh, drag and seal losses (docs/model/kinematics-efficiency-stiffness-life.md).
 * The physics and its assumptions are stated in losses.h.
 */
#include "model/losses.h"

#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>
#include <math.h>
#include <string.h>

#include "model/efficiency.h"
#include "model/hertz.h"

#define NMM_TO_NM 1e-3  /* N mm -> N m; also mm/s -> m/s and N mm/s -> W */
#define ROLLING_SLIP 1e-9 /* |slip| / |v| below which a contact rolls (no sliding friction) */
#define RATIO_TOL 1e-9  /* relative tolerance of an integer gear ratio */
#define TEETH_SEARCH_MAX 1000

/* One side (screw or nut) of a roller, per unit screw speed and per unit normal load. */
typedef struct {
	double nz;            /* |n_z| of the contact normal, - */
	double rel_ratio;     /* (Omega_r - omega_b) / omega, - */
	double spin_ratio;    /* omega_spin / omega = rel_ratio n_z, - */
	double tangential_mm; /* moment of the sliding friction about the roller axis per N, mm */
	double helix_mm;      /* p_r f_z per N of normal load, mm */
	double mu;            /* Coulomb mu of the contact, - */
	double a1_mm;         /* Hertz semi-major axis at Q = 1 N, mm */
	double ellint_E;      /* E(e) of the contact ellipse, - */
	double sum_Q_N;       /* sum of the roller's normal loads on this side, N */
	double spin_moment_Nmm; /* sum of (3/8) mu Q a E over them, N mm */
} side;

void prsm_losses_options_from_design(prsm_losses_options *out, const prsm_design *d)
{
	const prsm_losses_options defaults = PRSM_LOSSES_OPTIONS_INIT;
	const prsm_design_losses *l = &d->losses;
	*out = defaults;
	out->spin = l->spin;
	out->gear = l->gear_mesh;
	out->gear_mu = l->gear_friction;
	out->gear_teeth_roller = l->roller_gear_teeth;
	out->gear_teeth_ring = l->ring_gear_teeth;
	out->gear_contact_ratio = l->gear_contact_ratio;
	out->gear_pressure_angle_rad = l->gear_pressure_angle_rad;
	out->drag_torque_Nm = l->drag_torque_Nm;
	out->viscous_drag_Nm_s_per_rad = l->viscous_drag_Nm_s_per_rad;
	out->seal_torque_Nm = l->seal_torque_Nm;
}

double prsm_losses_spin_moment_Nmm(double mu, double Q_N, double a_mm, double b_mm)
{
	/* docs/model/kinematics-efficiency-stiffness-life.md: (3/8) mu Q a E(e); GSL takes the modulus e = sqrt(1 - b^2/a^2) */
	const double r = b_mm / a_mm;
	const double e = sqrt(fmax(0.0, 1.0 - r * r));
	return 0.375 * mu * Q_N * a_mm * gsl_sf_ellint_Ecomp(e, GSL_PREC_DOUBLE);
}

double prsm_losses_gear_loss_factor(int z1, int z2, double eps_alpha, double eps_1, double eps_2)
{
	/* Ohlendorf, internal mesh: pi (u - 1)/(z_1 u) (1 - eps_alpha + eps_1^2 + eps_2^2) */
	const double u = (double)z2 / (double)z1;
	return M_PI * (u - 1.0) / ((double)z1 * u) * (1.0 - eps_alpha + eps_1 * eps_1 + eps_2 * eps_2);
}

static int nonneg(double x)
{
	return x >= 0.0 && isfinite(x);
}

/* Kinematic and friction coefficients of one side (losses.h, parts 2 and 3). slip: roller
 * minus body at the contact, body frame, mm/rad; body_ratio: body speed / screw speed. */
static void side_coefficients(side *s, const prsm_contact *c, const double slip[3], double body_ratio,
                              double abs_ratio, double orbit_mm, double p_r, double mu, double v)
{
	s->nz = fabs(c->normal[2]);
	s->rel_ratio = abs_ratio - body_ratio;
	s->spin_ratio = s->rel_ratio * s->nz;
	s->mu = mu;
	s->tangential_mm = s->helix_mm = 0.0;
	const double sn = sqrt(slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2]);
	if (!(sn > ROLLING_SLIP * fabs(v)))
		return; /* rolling: no sliding friction (the gear takes the moment, losses.h) */
	/* unit slip in the pair frame (body axis at the origin, roller axis at (a, 0)) */
	const double th = atan2(c->y_mm, c->x_mm), ct = cos(th), st = sin(th);
	const double sx = (slip[0] * ct - slip[1] * st) / sn;
	const double sy = (slip[0] * st + slip[1] * ct) / sn;
	const double sz = slip[2] / sn;
	/* friction on the roller per N: -mu s; screw-motion velocity about the roller axis per rad:
	 * z x (p - A) + p_r z = (-y, x - a, p_r) */
	s->tangential_mm = -mu * (sx * (-c->y_mm) + sy * (c->x_mm - orbit_mm));
	s->helix_mm = -mu * sz * p_r;
}

/* Hertz semi-major axis at 1 N and E(e) of a contact (docs/model/kinematics-efficiency-stiffness-life.md); a scales as Q^(1/3). */
static int contact_hertz(double *a1_mm, double *ellint_E, const prsm_contact *c,
                         const prsm_material *body, const prsm_material *roller)
{
	prsm_hertz h;
	int rc = prsm_hertz_solve(&h, c->curvature_per_mm[0], c->curvature_per_mm[1], body->E_MPa,
	                          body->poisson, roller->E_MPa, roller->poisson, 1.0);
	if (rc)
		return rc;
	const double r = h.b_mm / h.a_mm;
	*a1_mm = h.a_mm;
	*ellint_E = gsl_sf_ellint_Ecomp(sqrt(fmax(0.0, 1.0 - r * r)), GSL_PREC_DOUBLE);
	return 0;
}

/* Sum of the loads and of the spin moments (3/8) mu Q a E of one side, N and N mm. */
static void side_loads(side *s, const double *loads, int n_t, double equal_share_N, int spin)
{
	s->sum_Q_N = s->spin_moment_Nmm = 0.0;
	for (int i = 0; i < n_t; i++) {
		const double Q = loads ? loads[i] : equal_share_N;
		s->sum_Q_N += Q;
		if (spin)
			s->spin_moment_Nmm += 0.375 * s->mu * Q * s->a1_mm * cbrt(Q) * s->ellint_E;
	}
}

static int check_loads(const double *loads, int n, const char *which, prsm_error *err)
{
	if (!loads)
		return 0;
	for (int i = 0; i < n; i++)
		if (!nonneg(loads[i]))
			return prsm_error_set(err, PRSM_EINVAL, NULL,
			                      "%s normal load %d must be finite and >= 0 N (got %g)", which, i,
			                      loads[i]);
	return 0;
}

static int check_inputs(const prsm_design *d, const prsm_losses_options *o, prsm_error *err)
{
	if (d->rollers < 1 || d->engaged_threads < 1)
		return prsm_error_set(err, PRSM_EINVAL, "/geometry/rollers",
		                      "losses need at least one roller and one engaged thread (got %d, %d)",
		                      d->rollers, d->engaged_threads);
	if (!nonneg(d->mu_screw_roller))
		return prsm_error_set(err, PRSM_EINVAL, "/friction/screw_roller",
		                      "friction coefficient must be finite and >= 0 (got %g)", d->mu_screw_roller);
	if (!nonneg(d->mu_nut_roller))
		return prsm_error_set(err, PRSM_EINVAL, "/friction/nut_roller",
		                      "friction coefficient must be finite and >= 0 (got %g)", d->mu_nut_roller);
	if (!isfinite(d->axial_load_N))
		return prsm_error_set(err, PRSM_EINVAL, "/operating_point/axial_load_N",
		                      "axial load must be finite (got %g N)", d->axial_load_N);
	if (!isfinite(d->screw_speed_rad_s))
		return prsm_error_set(err, PRSM_EINVAL, "/operating_point/screw_speed_rpm",
		                      "screw speed must be finite (got %g rad/s)", d->screw_speed_rad_s);
	if (!nonneg(o->gear_mu))
		return prsm_error_set(err, PRSM_EINVAL, "/losses/gear_friction",
		                      "gear friction coefficient must be finite and >= 0 (got %g)", o->gear_mu);
	if (o->gear_teeth_roller < 0 || o->gear_teeth_ring < 0)
		return prsm_error_set(err, PRSM_EINVAL, "/losses/roller_gear_teeth",
		                      "gear teeth must be > 0, or 0 for the default rule (got z_1 %d, z_2 %d)",
		                      o->gear_teeth_roller, o->gear_teeth_ring);
	if (!(o->gear_pressure_angle_rad > 0.0 && o->gear_pressure_angle_rad < 0.5 * M_PI))
		return prsm_error_set(err, PRSM_EINVAL, "/losses/gear_pressure_angle_deg",
		                      "gear pressure angle must be in (0, 90) deg (got %g rad)",
		                      o->gear_pressure_angle_rad);
	if (!isnan(o->gear_pitch_radius_mm) && !(o->gear_pitch_radius_mm > 0.0 && isfinite(o->gear_pitch_radius_mm)))
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "roller gear pitch radius must be > 0 mm, or NaN for r_r (got %g mm)",
		                      o->gear_pitch_radius_mm);
	if (!nonneg(o->drag_torque_Nm))
		return prsm_error_set(err, PRSM_EINVAL, "/losses/drag_torque_Nm",
		                      "drag torque must be finite and >= 0 N m (got %g)", o->drag_torque_Nm);
	if (!nonneg(o->viscous_drag_Nm_s_per_rad))
		return prsm_error_set(err, PRSM_EINVAL, "/losses/viscous_drag_Nm_s_per_rad",
		                      "viscous drag must be finite and >= 0 N m s/rad (got %g)",
		                      o->viscous_drag_Nm_s_per_rad);
	if (!nonneg(o->seal_torque_Nm))
		return prsm_error_set(err, PRSM_EINVAL, "/losses/seal_torque_Nm",
		                      "seal torque must be finite and >= 0 N m (got %g)", o->seal_torque_Nm);
	return 0;
}

/* Teeth and contact ratios of the ring-gear mesh (losses.h, part 3). */
static int gear_setup(prsm_losses_nominal *out, const prsm_design *d, const prsm_losses_options *o,
                      prsm_error *err)
{
	const double ratio = d->nut_radius_mm / d->roller_radius_mm; /* r_n / r_r */
	int z1 = o->gear_teeth_roller, z2 = o->gear_teeth_ring;
	if (z1 == 0 && z2 > 0)
		z1 = (int)lround(z2 / ratio);
	if (z1 == 0) {
		z1 = PRSM_LOSSES_ROLLER_TEETH_MIN;
		for (int z = PRSM_LOSSES_ROLLER_TEETH_MIN; z <= TEETH_SEARCH_MAX; z++) {
			double q = z * ratio;
			if (fabs(q - nearbyint(q)) <= RATIO_TOL * q) {
				z1 = z;
				break;
			}
		}
	}
	if (z2 == 0)
		z2 = (int)lround(z1 * ratio);
	if (z1 < 1 || z2 <= z1)
		return prsm_error_set(err, PRSM_EINVAL, "/losses/ring_gear_teeth",
		                      "the ring gear needs more teeth than the roller gear (z_1 %d, z_2 %d)", z1, z2);
	if (fabs((double)z2 / z1 - ratio) > RATIO_TOL * ratio)
		out->gear_flags |= PRSM_LOSSES_GEAR_RATIO;

	const int has1 = !isnan(o->gear_eps_roller), has2 = !isnan(o->gear_eps_ring);
	double ea = o->gear_contact_ratio, e1 = 0.5 * ea, e2 = 0.5 * ea;
	if (has1 != has2)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "give both addendum contact ratios eps_1 and eps_2, or neither");
	if (has1) {
		e1 = o->gear_eps_roller;
		e2 = o->gear_eps_ring;
		ea = e1 + e2;
		if (!(e1 >= 0.0 && e1 <= 1.0 && e2 >= 0.0 && e2 <= 1.0))
			return prsm_error_set(err, PRSM_EINVAL, NULL,
			                      "addendum contact ratios must be in [0, 1] for Ohlendorf's H_v "
			                      "(got %g, %g)", e1, e2);
	}
	if (!(ea >= 1.0 && ea <= 2.0))
		return prsm_error_set(err, PRSM_EINVAL, "/losses/gear_contact_ratio",
		                      "gear contact ratio must be in [1, 2] for Ohlendorf's H_v (got %g)", ea);
	out->gear_teeth_roller = z1;
	out->gear_teeth_ring = z2;
	out->gear_eps_alpha = ea;
	out->gear_eps_roller = e1;
	out->gear_eps_ring = e2;
	out->gear_Hv = prsm_losses_gear_loss_factor(z1, z2, ea, e1, e2);
	return 0;
}

/* The gear part of the result from the prepared one, or its error. */
static int gear_apply(prsm_losses_result *out, const prsm_losses_nominal *nm, prsm_error *err)
{
	out->flags |= nm->gear_flags;
	if (nm->gear_rc) {
		if (err)
			*err = nm->gear_err;
		return nm->gear_rc;
	}
	out->gear_teeth_roller = nm->gear_teeth_roller;
	out->gear_teeth_ring = nm->gear_teeth_ring;
	out->gear_eps_alpha = nm->gear_eps_alpha;
	out->gear_eps_roller = nm->gear_eps_roller;
	out->gear_eps_ring = nm->gear_eps_ring;
	out->gear_Hv = nm->gear_Hv;
	return 0;
}

void prsm_losses_prepare(prsm_losses_nominal *out, const prsm_design *d, const prsm_contact *screw,
                         const prsm_contact *nut, const prsm_losses_options *opts)
{
	const prsm_losses_options defaults = PRSM_LOSSES_OPTIONS_INIT;
	const prsm_losses_options *o = opts ? opts : &defaults;
	memset(out, 0, sizeof *out);
	out->spin = o->spin != 0;
	if (out->spin) {
		out->hertz_rc = contact_hertz(&out->a1_mm[0], &out->ellint_E[0], screw, &d->screw_material,
		                              &d->roller_material);
		if (!out->hertz_rc)
			out->hertz_rc = contact_hertz(&out->a1_mm[1], &out->ellint_E[1], nut, &d->nut_material,
			                              &d->roller_material);
	}
	out->gear_rc = gear_setup(out, d, o, &out->gear_err);
}

/* -1, 0 or 1 */
static double sign_of(double x)
{
	return (double)((x > 0.0) - (x < 0.0));
}

/* Every input check of a losses request: the design and options, then each side's loads. */
static int check_request(const prsm_design *d, const prsm_losses_options *o, const double *screw_loads_N,
                         const double *nut_loads_N, prsm_error *err)
{
	int rc = check_inputs(d, o, err);
	if (!rc)
		rc = check_loads(screw_loads_N, d->engaged_threads, "screw-side", err);
	if (!rc)
		rc = check_loads(nut_loads_N, d->engaged_threads, "nut-side", err);
	return rc;
}

static int compute_checked(prsm_losses_result *out, const prsm_losses_nominal *nm, const prsm_design *d,
                           const prsm_kinematics *k, const prsm_contact *screw, const prsm_contact *nut,
                           const double *screw_loads_N, const double *nut_loads_N,
                           const prsm_losses_options *o, prsm_error *err);

int prsm_losses_compute(prsm_losses_result *out, const prsm_design *d, const prsm_kinematics *k,
                        const prsm_contact *screw, const prsm_contact *nut,
                        const double *screw_loads_N, const double *nut_loads_N,
                        const prsm_losses_options *opts, prsm_error *err)
{
	const prsm_losses_options defaults = PRSM_LOSSES_OPTIONS_INIT;
	const prsm_losses_options *o = opts ? opts : &defaults;
	/* the inputs first: the gear rule is only evaluated for valid options */
	memset(out, 0, sizeof *out);
	int rc = check_request(d, o, screw_loads_N, nut_loads_N, err);
	if (rc)
		return rc;
	prsm_losses_nominal nominal;
	prsm_losses_prepare(&nominal, d, screw, nut, o);
	return compute_checked(out, &nominal, d, k, screw, nut, screw_loads_N, nut_loads_N, o, err);
}

int prsm_losses_compute_prepared(prsm_losses_result *out, const prsm_losses_nominal *nm,
                                 const prsm_design *d, const prsm_kinematics *k,
                                 const prsm_contact *screw, const prsm_contact *nut,
                                 const double *screw_loads_N, const double *nut_loads_N,
                                 const prsm_losses_options *opts, prsm_error *err)
{
	const prsm_losses_options defaults = PRSM_LOSSES_OPTIONS_INIT;
	const prsm_losses_options *o = opts ? opts : &defaults;
	memset(out, 0, sizeof *out);
	int rc = check_request(d, o, screw_loads_N, nut_loads_N, err);
	if (rc)
		return rc;
	return compute_checked(out, nm, d, k, screw, nut, screw_loads_N, nut_loads_N, o, err);
}

/* prsm_losses_compute_prepared once the request passed check_request; out is zeroed. */
static int compute_checked(prsm_losses_result *out, const prsm_losses_nominal *nm, const prsm_design *d,
                           const prsm_kinematics *k, const prsm_contact *screw, const prsm_contact *nut,
                           const double *screw_loads_N, const double *nut_loads_N,
                           const prsm_losses_options *o, prsm_error *err)
{
	int rc;
	if (o->spin && !nm->spin)
		return prsm_error_set(err, PRSM_EINVAL, NULL,
		                      "losses: the nominal part was prepared with spin off");

	/* 1. sliding (docs/model/kinematics-efficiency-stiffness-life.md), from prsm_efficiency */
	prsm_efficiency eff;
	prsm_efficiency_sliding(&eff, d, k, screw, nut);
	out->eta_slide = eff.eta;
	out->eta_back_slide = eff.eta_back;
	out->eta_closed_form = eff.eta_closed_form;
	out->eta_back_closed_form = eff.eta_back_closed_form;
	if (!(eff.eta > 0.0)) {
		/* friction wedges the flanks: no torque drives the load (eta 0, torques undefined);
		 * the load may still back-drive, with the sliding losses only */
		out->flags |= PRSM_LOSSES_DRIVE_LOCKED;
		out->eta = 0.0;
		out->eta_back = eff.eta_back > 0.0 ? eff.eta_back : 0.0;
		if (!(eff.eta_back > 0.0))
			out->flags |= PRSM_LOSSES_SELF_LOCKING;
		out->ideal_torque_Nm = fabs(d->axial_load_N) * prsm_design_lead_mm(d) * 1e-3 / (2.0 * M_PI);
		out->sliding_torque_Nm = out->input_torque_Nm = out->back_output_torque_Nm = NAN;
		out->input_power_W = out->sliding_power_W = out->loss_power_W = NAN;
		out->output_power_W = fabs(d->axial_load_N) * fabs(k->nut_speed_mm_per_rad * d->screw_speed_rad_s) * 1e-3;
		return gear_apply(out, nm, err);
	}

	const double F = fabs(d->axial_load_N), w = fabs(d->screw_speed_rad_s); /* N, rad/s */
	const double L = prsm_design_lead_mm(d);                                 /* mm */
	const int Z = d->rollers, nt = d->engaged_threads;
	const double v = k->nut_speed_mm_per_rad, p_r = prsm_design_roller_p(d);
	const double orbit = prsm_design_orbit_radius_mm(d);
	const int spin = o->spin != 0, gear = o->gear != 0;

	/* 2. spin and the roller's moment coefficients, per unit screw speed */
	side s = {0}, n = {0};
	side_coefficients(&s, screw, k->slip_screw, 1.0, k->roller_abs_ratio, orbit, p_r,
	                  d->mu_screw_roller, v);
	side_coefficients(&n, nut, k->slip_nut, 0.0, k->roller_abs_ratio, orbit, p_r,
	                  d->mu_nut_roller, v);
	if (spin && nm->hertz_rc && nm->hertz_rc != PRSM_EINVAL)
		return prsm_error_set(err, nm->hertz_rc, "/geometry", "the Hertz contact solve failed (%s)",
		                      prsm_error_name(nm->hertz_rc));
	if (spin && nm->hertz_rc)
		return prsm_error_set(err, PRSM_EGEOMETRY, "/geometry",
		                      "spin friction needs Hertzian contacts: a contact has non-positive "
		                      "relative curvature or a material a non-positive modulus");
	if (spin) {
		s.a1_mm = nm->a1_mm[0];
		s.ellint_E = nm->ellint_E[0];
		n.a1_mm = nm->a1_mm[1];
		n.ellint_E = nm->ellint_E[1];
	}
	/* equal share of docs/model/kinematics-efficiency-stiffness-life.md: F / (Z n_t |n_z|) per contact */
	side_loads(&s, screw_loads_N, nt, F / (Z * nt * s.nz), spin);
	side_loads(&n, nut_loads_N, nt, F / (Z * nt * n.nz), spin);
	out->spin_speed_screw_rad_s = s.spin_ratio * d->screw_speed_rad_s;
	out->spin_speed_nut_rad_s = n.spin_ratio * d->screw_speed_rad_s;
	out->spin_moment_screw_Nm = s.spin_moment_Nmm * NMM_TO_NM;
	out->spin_moment_nut_Nm = n.spin_moment_Nmm * NMM_TO_NM;
	out->spin_ellint_E_screw = s.ellint_E;
	out->spin_ellint_E_nut = n.ellint_E;
	/* torque on the screw = spin power / omega, N m */
	out->spin_torque_Nm = Z * (s.spin_moment_Nmm * fabs(s.spin_ratio) +
	                           n.spin_moment_Nmm * fabs(n.spin_ratio)) * NMM_TO_NM;
	out->spin_power_W = Z * (s.spin_moment_Nmm * fabs(out->spin_speed_screw_rad_s) +
	                         n.spin_moment_Nmm * fabs(out->spin_speed_nut_rad_s)) * NMM_TO_NM;

	/* 3. ring-gear mesh: the moment about the roller axis the gears balance, N mm */
	const double m_tan = s.tangential_mm * s.sum_Q_N + n.tangential_mm * n.sum_Q_N;
	const double m_helix = s.helix_mm * s.sum_Q_N + n.helix_mm * n.sum_Q_N;
	const double m_spin = -sign_of(s.rel_ratio) * s.nz * s.spin_moment_Nmm -
	                      sign_of(n.rel_ratio) * n.nz * n.spin_moment_Nmm;
	out->roller_moment_friction_Nm = m_tan * NMM_TO_NM;
	out->roller_moment_helix_Nm = m_helix * NMM_TO_NM;
	out->roller_moment_spin_Nm = m_spin * NMM_TO_NM;
	out->roller_moment_Nm = (m_tan + m_helix + m_spin) * NMM_TO_NM;
	double gear_torque_per_N = 0.0; /* F -> 0 limit of T_gear / F, N m / N (equal share) */
	if ((rc = gear_apply(out, nm, err)))
		return rc;
	if (gear) {
		const double r_gear = isnan(o->gear_pitch_radius_mm) ? d->roller_radius_mm
		                                                     : o->gear_pitch_radius_mm; /* mm */
		const double spin_rel = fabs(k->roller_spin_ratio); /* roller against carrier and ring */
		const double M = fabs(m_tan + m_helix + m_spin);    /* N mm */
		out->gear_tangential_force_N = M / r_gear;
		out->gear_normal_force_N = out->gear_tangential_force_N / cos(o->gear_pressure_angle_rad);
		out->gear_pitch_speed_m_s = spin_rel * r_gear * w * NMM_TO_NM;
		out->gear_power_W = Z * o->gear_mu * out->gear_tangential_force_N *
		                    out->gear_pitch_speed_m_s * out->gear_Hv;
		out->gear_torque_Nm = Z * o->gear_mu * M * spin_rel * out->gear_Hv * NMM_TO_NM;
		gear_torque_per_N = o->gear_mu * spin_rel * out->gear_Hv * NMM_TO_NM *
		                    fabs((s.tangential_mm + s.helix_mm) / s.nz +
		                         (n.tangential_mm + n.helix_mm) / n.nz);
	} else {
		out->gear_Hv = 0.0;
	}

	/* 4. drag and seal, N m */
	out->drag_torque_Nm = o->drag_torque_Nm + o->viscous_drag_Nm_s_per_rad * w;
	out->seal_torque_Nm = o->seal_torque_Nm;

	/* the split (docs/model/kinematics-efficiency-stiffness-life.md): T = F L / (2 pi eta_slide) + T_spin + T_gear + T_drag + T_seal */
	const double per_N = L / (2.0 * M_PI) * NMM_TO_NM; /* ideal torque per N of load, N m/N */
	out->ideal_torque_Nm = F * per_N;
	out->sliding_torque_Nm = out->ideal_torque_Nm / eff.eta - out->ideal_torque_Nm;
	const double extra = out->spin_torque_Nm + out->gear_torque_Nm + out->drag_torque_Nm +
	                     out->seal_torque_Nm;
	out->input_torque_Nm = out->ideal_torque_Nm + out->sliding_torque_Nm + extra;
	out->back_output_torque_Nm = out->ideal_torque_Nm * eff.eta_back - extra;

	if (F > 0.0) {
		out->eta = out->ideal_torque_Nm / out->input_torque_Nm;
		out->eta_back = fmax(0.0, out->back_output_torque_Nm / out->ideal_torque_Nm);
		if (!(out->back_output_torque_Nm > 0.0))
			out->flags |= PRSM_LOSSES_SELF_LOCKING;
	} else {
		out->flags |= PRSM_LOSSES_NO_LOAD;
		if (out->input_torque_Nm > 0.0) {
			out->eta = out->eta_back = 0.0;
		} else {
			/* F -> 0+: spin ~ F^(4/3) vanishes against F, the gear's friction part stays */
			out->flags |= PRSM_LOSSES_LIMIT;
			const double g = gear_torque_per_N / per_N; /* - */
			out->eta = g > 0.0 ? 1.0 / (1.0 / eff.eta + g) : eff.eta;
			out->eta_back = fmax(0.0, eff.eta_back - g);
		}
	}
	if (w == 0.0)
		out->flags |= PRSM_LOSSES_AT_REST;

	/* powers at the operating speed, W */
	out->input_power_W = out->input_torque_Nm * w;
	out->output_power_W = out->ideal_torque_Nm * w;
	out->sliding_power_W = out->sliding_torque_Nm * w;
	out->drag_power_W = out->drag_torque_Nm * w;
	out->seal_power_W = out->seal_torque_Nm * w;
	out->loss_power_W = out->sliding_power_W + out->spin_power_W + out->gear_power_W +
	                    out->drag_power_W + out->seal_power_W;
	return 0;
}
