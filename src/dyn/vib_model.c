/*
 * vib_model.c: the reduced vibration model of docs/model §8.3 and the dimensionless gear pair of
 * §8.3.5: options and their checks, the parameters from the design, the rigid model (dyn.h) and
 * the statics engine (stiffness, backlash, gear teeth, TE lines), the derived scaled constants
 * the right-hand side uses (vib_core), sweepable parameters, the static state, observables and
 * the Poincaré vector.
 */
#include "dyn/vib_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_multifit.h>

#include "model/assembly_report.h"
#include "model/losses.h"
#include "model/performance.h"

#define MM 1e-3 /* mm -> m */
#define UM 1e-6 /* um -> m */

int prsm_vib_options_init(prsm_vib_options *o)
{
	const prsm_vib_options d = PRSM_VIB_OPTIONS_INIT;
	*o = d;
	return 0;
}

static int finite_pos(double x)
{
	return x > 0.0 && isfinite(x);
}

static int finite_nonneg(double x)
{
	return x >= 0.0 && isfinite(x);
}

int prsm_vib_gear_pair_check(const prsm_vib_gear_pair *g, prsm_problems *p)
{
	const int before = prsm_problems_total(p);
	const char *b = "/dynamics/vibration";
	char ptr[PRSM_PROBLEM_POINTER_MAX];
	if (!finite_pos(g->damping_ratio) || g->damping_ratio >= 1.0) {
		snprintf(ptr, sizeof ptr, "%s/mesh_damping_ratio", b);
		prsm_problems_add(p, ptr, "range", "the damping ratio must be in (0, 1) (got %g): without damping "
		                  "no transient ends", g->damping_ratio);
	}
	if (!isfinite(g->mean_force) || fabs(g->mean_force) > 1e3) {
		snprintf(ptr, sizeof ptr, "%s/mean_force", b);
		prsm_problems_add(p, ptr, "range", "the mean force f_m must be finite, |f_m| <= 1000 (got %g)", g->mean_force);
	}
	if (!finite_nonneg(g->mesh_error) || g->mesh_error > 1e3) {
		snprintf(ptr, sizeof ptr, "%s/mesh_error", b);
		prsm_problems_add(p, ptr, "range", "the mesh error epsilon must be in [0, 1000] (got %g)", g->mesh_error);
	}
	if (!(g->contact_ratio >= 1.0 && g->contact_ratio <= 2.0)) {
		snprintf(ptr, sizeof ptr, "%s/contact_ratio", b);
		prsm_problems_add(p, ptr, "range", "the contact ratio must be in [1, 2] (got %g)", g->contact_ratio);
	} else {
		const double D = g->contact_ratio - 1.0;
		if (!isfinite(g->stiffness_variation) || 1.0 - g->stiffness_variation * D <= 0.0 ||
		    1.0 + g->stiffness_variation * (1.0 - D) <= 0.0) {
			snprintf(ptr, sizeof ptr, "%s/stiffness_variation", b);
			prsm_problems_add(p, ptr, "range", "the stiffness variation kappa = %g makes a mesh stiffness "
			                  "non-positive (need -1/(1 - D) < kappa < 1/D, D = eps_alpha - 1)",
			                  g->stiffness_variation);
		}
	}
	if (!finite_pos(g->frequency_ratio) || g->frequency_ratio > 1e3) {
		snprintf(ptr, sizeof ptr, "%s/frequency_ratio", b);
		prsm_problems_add(p, ptr, "range", "the frequency ratio must be in (0, 1000] (got %g)", g->frequency_ratio);
	}
	return prsm_problems_total(p) > before ? PRSM_EINVAL : 0;
}

int prsm_vib_options_check(const prsm_vib_options *o, prsm_problems *p)
{
	const int before = prsm_problems_total(p);
	const char *b = "/dynamics/vibration";
	char ptr[PRSM_PROBLEM_POINTER_MAX];
#define VIB_REQUIRE(cond, name, code, ...)                                                        \
	do {                                                                                          \
		if (!(cond)) {                                                                            \
			snprintf(ptr, sizeof ptr, "%s/%s", b, name);                                          \
			prsm_problems_add(p, ptr, code, __VA_ARGS__);                                         \
		}                                                                                         \
	} while (0)
	VIB_REQUIRE(finite_pos(o->screw_speed_rad_s) || !isnan(o->frequency_ratio), "screw_speed_rad_s", "positive",
	            "the screw speed must be > 0 rad/s (got %g)", o->screw_speed_rad_s);
	VIB_REQUIRE(isnan(o->frequency_ratio) || (finite_pos(o->frequency_ratio) && o->frequency_ratio <= 1e3),
	            "frequency_ratio", "range", "the frequency ratio must be in (0, 1000] (got %g)", o->frequency_ratio);
	VIB_REQUIRE(isnan(o->axial_load_N) || isfinite(o->axial_load_N), "axial_load_N", "finite",
	            "the axial load must be finite");
	VIB_REQUIRE(finite_pos(o->axial_damping_ratio) && o->axial_damping_ratio < 1.0, "axial_damping_ratio", "range",
	            "the axial damping ratio must be in (0, 1) (got %g): without damping no transient ends",
	            o->axial_damping_ratio);
	VIB_REQUIRE(finite_pos(o->mesh_damping_ratio) && o->mesh_damping_ratio < 1.0, "mesh_damping_ratio", "range",
	            "the mesh damping ratio must be in (0, 1) (got %g): without damping no transient ends",
	            o->mesh_damping_ratio);
	VIB_REQUIRE(finite_pos(o->mesh_single_stiffness_N_per_mm_um), "mesh_single_stiffness_N_per_mm_um", "positive",
	            "the single-pair mesh stiffness must be > 0 N/(mm um) (got %g)", o->mesh_single_stiffness_N_per_mm_um);
	VIB_REQUIRE(o->double_to_single_stiffness >= 1.0 && o->double_to_single_stiffness <= 10.0,
	            "double_to_single_stiffness", "range", "k_d / k_s must be in [1, 10] (got %g)",
	            o->double_to_single_stiffness);
	VIB_REQUIRE(finite_pos(o->gear_backlash_um) && o->gear_backlash_um <= 1e4, "gear_backlash_um", "range",
	            "the gear half backlash must be in (0, 10000] um (got %g)", o->gear_backlash_um);
	VIB_REQUIRE(finite_nonneg(o->mesh_error_um) && o->mesh_error_um <= 1e4, "mesh_error_um", "range",
	            "the mesh error must be in [0, 10000] um (got %g)", o->mesh_error_um);
	VIB_REQUIRE(isnan(o->axial_stiffness_N_per_um) || finite_pos(o->axial_stiffness_N_per_um),
	            "axial_stiffness_N_per_um", "positive", "the axial stiffness must be > 0 N/um (got %g)",
	            o->axial_stiffness_N_per_um);
	VIB_REQUIRE(isnan(o->axial_half_play_um) || (finite_pos(o->axial_half_play_um) && o->axial_half_play_um <= 1e4),
	            "axial_half_play_um", "range", "the axial half play must be in (0, 10000] um (got %g)",
	            o->axial_half_play_um);
	VIB_REQUIRE(isnan(o->gear_contact_ratio) || (o->gear_contact_ratio >= 1.0 && o->gear_contact_ratio <= 2.0),
	            "gear_contact_ratio", "range", "the contact ratio must be in [1, 2] (got %g)", o->gear_contact_ratio);
	VIB_REQUIRE(isnan(o->gear_pressure_angle_rad) ||
	            (o->gear_pressure_angle_rad > 0.0 && o->gear_pressure_angle_rad < 0.5 * M_PI),
	            "gear_pressure_angle_rad", "range", "the pressure angle must be in (0, 90) deg");
	VIB_REQUIRE(o->gear_teeth_roller >= 0 && o->gear_teeth_roller <= 10000, "gear_teeth_roller", "range",
	            "the roller teeth must be 0 (statics) or a positive count");
	VIB_REQUIRE(o->gear_teeth_ring >= 0 && o->gear_teeth_ring <= 100000, "gear_teeth_ring", "range",
	            "the ring teeth must be 0 (statics) or a positive count");
	VIB_REQUIRE(o->branches >= PRSM_VIB_BRANCHES_BOTH && o->branches <= PRSM_VIB_BRANCHES_AXIAL, "branches", "enum",
	            "the branches are both, gear or axial");
	VIB_REQUIRE(o->te_source >= PRSM_VIB_TE_NONE && o->te_source <= PRSM_VIB_TE_STATICS, "te_lines", "enum",
	            "the TE lines are none, a list, or statics");
	if (o->te_source == PRSM_VIB_TE_LINES) {
		VIB_REQUIRE(o->te_lines >= 0 && o->te_lines <= PRSM_VIB_TE_LINES_MAX, "te_lines", "too_many",
		            "at most %d TE lines (got %d)", PRSM_VIB_TE_LINES_MAX, o->te_lines);
		for (int k = 0; k < o->te_lines && k < PRSM_VIB_TE_LINES_MAX; k++) {
			const prsm_vib_te_line *l = &o->te_line[k];
			if (!finite_pos(l->order_per_rev) || l->order_per_rev > 1e4) {
				snprintf(ptr, sizeof ptr, "%s/te_lines/%d/order_per_rev", b, k);
				prsm_problems_add(p, ptr, "range", "a TE order must be in (0, 10000] per revolution (got %g)",
				                  l->order_per_rev);
			}
			if (!finite_nonneg(l->amplitude_m) || l->amplitude_m > 1e-2) {
				snprintf(ptr, sizeof ptr, "%s/te_lines/%d/amplitude_um", b, k);
				prsm_problems_add(p, ptr, "range", "a TE amplitude must be in [0, 10000] um (got %g um)",
				                  l->amplitude_m / UM);
			}
			if (!isfinite(l->phase_rad)) {
				snprintf(ptr, sizeof ptr, "%s/te_lines/%d/phase_deg", b, k);
				prsm_problems_add(p, ptr, "finite", "a TE phase must be finite");
			}
		}
	}
	if (o->te_source == PRSM_VIB_TE_STATICS) {
		VIB_REQUIRE(o->te_threshold >= 0.0 && o->te_threshold < 1.0, "te_threshold", "range",
		            "the TE line threshold must be in [0, 1) of the largest line (got %g)", o->te_threshold);
		VIB_REQUIRE(o->te_max_lines >= 1 && o->te_max_lines <= PRSM_VIB_TE_LINES_MAX, "te_max_lines", "range",
		            "the TE lines are 1 to %d (got %d)", PRSM_VIB_TE_LINES_MAX, o->te_max_lines);
	}
#undef VIB_REQUIRE
	return prsm_problems_total(p) > before ? PRSM_EINVAL : 0;
}

/* ---- derived constants ---- */

static double frac(double x)
{
	return x - floor(x);
}

/* p = p_k / q_k rational within 1e-9 relative, q <= 100000 (continued fractions); 0 when none */
static int rationalise(double x, long *p, long *q)
{
	long h0 = 0, h1 = 1, k0 = 1, k1 = 0;
	double r = x;
	for (int it = 0; it < 40; it++) {
		const double a = floor(r);
		if (a > 1e12)
			return 0;
		const long ai = (long)a;
		const long h2 = ai * h1 + h0, k2 = ai * k1 + k0;
		if (k2 > 100000)
			return 0;
		h0 = h1;
		h1 = h2;
		k0 = k1;
		k1 = k2;
		if (fabs((double)h1 / (double)k1 - x) <= 1e-9 * fabs(x)) {
			*p = h1;
			*q = k1;
			return 1;
		}
		const double f = r - a;
		if (f < 1e-15)
			return 0;
		r = 1.0 / f;
	}
	return 0;
}

static long gcd_l(long a, long b)
{
	while (b) {
		const long t = a % b;
		a = b;
		b = t;
	}
	return a < 0 ? -a : a;
}

/* §8.3.4: the common period of the lines in screw revolutions; NaN when none within 1000 */
static double te_common_period(const prsm_vib_te_line *l, int n)
{
	if (n == 0)
		return 0.0;
	long p[PRSM_VIB_TE_LINES_MAX], q[PRSM_VIB_TE_LINES_MAX];
	long L = 1;
	for (int k = 0; k < n; k++) {
		if (!rationalise(l[k].order_per_rev, &p[k], &q[k]))
			return NAN;
		L = L / gcd_l(L, q[k]) * q[k];
		if (L > 1000000)
			return NAN;
	}
	long g = 0;
	for (int k = 0; k < n; k++)
		g = gcd_l(g, p[k] * (L / q[k]));
	const double T = (double)L / (double)g;
	return T <= 1000.0 ? T : NAN;
}

static void cross_z(double out[3], const double v[3])
{
	/* z-hat x (v_x, v_y, v_z) = (-v_y, v_x, 0) */
	out[0] = -v[1];
	out[1] = v[0];
	out[2] = 0.0;
}

void vib_core_derive(prsm_vib_model *m)
{
	prsm_vib_params *P = &m->par;
	vib_core *c = &m->c;
	if (P->kind == PRSM_VIB_GEAR_PAIR) {
		const prsm_vib_gear_pair *g = &P->gear_pair;
		memset(c, 0, sizeof *c);
		c->pair = 1;
		c->Z = 1;
		c->n = 2;
		c->gear = 1;
		c->axial = 0;
		c->nc = 1;
		c->zeta = g->damping_ratio;
		c->fm = g->mean_force;
		c->eps = g->mesh_error;
		c->kappa = g->stiffness_variation;
		c->D = g->contact_ratio - 1.0;
		c->Omega = g->frequency_ratio;
		c->we = g->frequency_ratio;
		c->kd = 1.0 + c->kappa * (1.0 - c->D);
		c->ks = 1.0 - c->kappa * c->D;
		P->frequency_ratio = g->frequency_ratio;
		P->states = 2;
		P->poincare_size = 2;
		P->contacts = 1;
		P->rollers = 1;
		P->branches = PRSM_VIB_BRANCHES_GEAR;
		return;
	}
	/* reduced model (§8.3), SI from the echo */
	const int Z = P->rollers;
	c->Z = Z;
	c->n = 2 * (Z + 1) + 2;
	c->gear = P->branches != PRSM_VIB_BRANCHES_AXIAL;
	c->axial = P->branches != PRSM_VIB_BRANCHES_GEAR;
	c->nc = (c->gear ? Z : 0) + (c->axial ? 1 : 0);
	P->states = c->n;
	P->contacts = c->nc;
	P->poincare_size = (c->gear ? 2 * Z + 1 : 0) + (c->axial ? 2 : 0);

	/* gear branch (§8.3.3) */
	const double ks = P->mesh_single_N_per_m, kd = P->mesh_double_N_per_m, eps = P->contact_ratio;
	P->mesh_mean_N_per_m = kd * (eps - 1.0) + ks * (2.0 - eps);
	const double kbar = P->mesh_mean_N_per_m;
	c->kbar = kbar;
	c->kd = kd / kbar;
	c->ks = ks / kbar;
	c->D = eps - 1.0;
	c->Mpp = P->inertia_psipsi_kg_m2;
	c->Mpf = P->inertia_psiphi_kg_m2;
	c->Mff = P->inertia_phiphi_kg_m2;
	c->schur = c->Mpp - Z * c->Mpf * c->Mpf / c->Mff;
	c->rb1 = P->base_radius_roller_m;
	c->rb2 = P->base_radius_ring_m;
	c->bg = P->gear_half_backlash_m;
	c->wref = sqrt(2.0 * c->rb1 * c->rb1 * kbar / c->Mff);
	P->reference_frequency_rad_s = c->wref;
	P->mesh_damping_N_s_per_m = P->mesh_damping_ratio * sqrt(2.0 * kbar * c->Mff) / c->rb1;
	c->two_zeta_g = 2.0 * P->mesh_damping_ratio;
	c->eg = P->mesh_error_m / c->bg;
	P->mesh_frequency_rad_s = (m->mesh_order_per_rev > 0.0 ? m->mesh_order_per_rev : P->teeth_ring * P->carrier_ratio) *
	                          P->screw_speed_rad_s;
	c->we = P->mesh_frequency_rad_s / c->wref;
	P->frequency_ratio = c->we;
	for (int j = 0; j < Z; j++) {
		c->gamma[j] = P->mesh_phase[j];
		c->cphase[j] = cos(2.0 * M_PI * c->gamma[j]);
		c->sphase[j] = sin(2.0 * M_PI * c->gamma[j]);
	}
	c->accel_psi = c->rb2 / (c->wref * c->wref * c->bg);
	c->accel_phi = c->rb1 / (c->wref * c->wref * c->bg);

	/* friction (§8.3.3): v* = (A k* + B) omega_s, the slip per unit scaled rate */
	for (int i = 0; i < 3; i++) {
		c->vstar[i] = (m->v_basis_A[i] * P->carrier_ratio + m->v_basis_B[i]) * P->screw_speed_rad_s;
		P->slip_m_s[i] = c->vstar[i];
		c->gpsi[i] = c->Gpsi[i] * c->bg * c->wref / c->rb2;
		c->gphi[i] = c->Gphi[i] * c->bg * c->wref / c->rb1;
	}
	c->mu = P->mu;
	c->veps2 = P->smoothing_velocity_m_s * P->smoothing_velocity_m_s;
	c->F0 = P->axial_load_N;
	/* the mean mesh force F-bar = f . G_phi / r_b1 at v*, N from F_0 on the loaded flank */
	const double s2 = c->vstar[0] * c->vstar[0] + c->vstar[1] * c->vstar[1] + c->vstar[2] * c->vstar[2] + c->veps2;
	const double inv = 1.0 / sqrt(s2);
	const double N = (-c->F0 / Z) / (c->nz - c->mu * c->vstar[2] * inv);
	P->normal_force_N = N;
	const double fdot = -c->mu * N * inv *
	                    (c->vstar[0] * c->Gphi[0] + c->vstar[1] * c->Gphi[1] + c->vstar[2] * c->Gphi[2]);
	P->mean_mesh_force_N = fdot / c->rb1;
	const double fbar = P->mean_mesh_force_N;
	P->static_mesh_deflection_m = (fbar > 0.0 ? c->bg : (fbar < 0.0 ? -c->bg : 0.0)) + fbar / (2.0 * kbar);

	/* axial branch (§8.3.2) */
	P->axial_mass_kg = m->m_axial;
	P->axial_stiffness_N_per_m = m->k_axial;
	P->axial_frequency_rad_s = sqrt(m->k_axial / m->m_axial);
	P->axial_damping_N_s_per_m = 2.0 * P->axial_damping_ratio * sqrt(m->k_axial * m->m_axial);
	P->axial_static_m = (c->F0 >= 0.0 ? P->axial_half_play_m : -P->axial_half_play_m) + c->F0 / m->k_axial;
	c->ba = P->axial_half_play_m;
	c->r = P->axial_frequency_rad_s / c->wref;
	c->zeta_a = P->axial_damping_ratio;
	c->f0 = c->F0 / (m->k_axial * c->ba);
	c->Fth_scale = m->k_axial * c->ba;
	c->lines = P->te_lines;
	const double wa = P->axial_frequency_rad_s;
	for (int k = 0; k < P->te_lines; k++) {
		const prsm_vib_te_line *l = &P->te_line[k];
		const double w = l->order_per_rev * P->screw_speed_rad_s; /* rad/s */
		c->te_w[k] = w / c->wref;
		c->te_a[k] = -l->amplitude_m * w * w / (c->ba * wa * wa);
		c->te_phi[k] = l->phase_rad;
	}
	P->te_period_rev = te_common_period(P->te_line, P->te_lines);

	/* the equivalent dimensionless numbers (§8.3.5) */
	prsm_vib_gear_pair *g = &P->gear_pair;
	g->damping_ratio = P->mesh_damping_ratio;
	g->mean_force = fbar / (2.0 * kbar * c->bg);
	g->mesh_error = c->eg;
	g->stiffness_variation = (kd - ks) / kbar;
	g->contact_ratio = eps;
	g->frequency_ratio = c->we;
}

/* ---- construction ---- */

static prsm_vib_model *model_alloc(void)
{
	return calloc(1, sizeof(prsm_vib_model));
}

int prsm_vib_gear_pair_new(prsm_vib_model **out, const prsm_vib_gear_pair *g, prsm_error *err)
{
	*out = NULL;
	prsm_problems problems;
	prsm_problems_init(&problems);
	if (prsm_vib_gear_pair_check(g, &problems))
		return prsm_error_set(err, PRSM_EINVAL, problems.items[0].pointer, "%s%s", problems.items[0].message,
		                      prsm_problems_total(&problems) > 1 ? " (and more problems)" : "");
	prsm_vib_model *m = model_alloc();
	if (m == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the vibration model");
	m->par.kind = PRSM_VIB_GEAR_PAIR;
	m->par.gear_pair = *g;
	m->par.screw_speed_rad_s = NAN;
	m->par.axial_load_N = NAN;
	m->par.carrier_ratio = NAN;
	m->par.te_period_rev = 0.0;
	vib_core_derive(m);
	*out = m;
	return 0;
}

void prsm_vib_model_free(prsm_vib_model *m)
{
	free(m);
}

prsm_vib_model *prsm_vib_model_copy(const prsm_vib_model *m)
{
	prsm_vib_model *c = model_alloc();
	if (c != NULL)
		*c = *m;
	return c;
}

const prsm_vib_params *prsm_vib_model_params(const prsm_vib_model *m)
{
	return &m->par;
}

/* The gear teeth and contact ratio of the statics losses, and (when asked) the axial stiffness at
 * F_0 from prsm_performance_compute. */
static int statics_values(double *k_axial_N_per_m, int *z1, int *z2, double *eps, const prsm_design *design,
                          const prsm_analysis *analysis, double F0, double speed, int need_stiffness, prsm_error *err)
{
	prsm_design d = *design;
	d.axial_load_N = fabs(F0);
	d.screw_speed_rad_s = speed;
	if (need_stiffness) {
		prsm_performance perf;
		memset(&perf, 0, sizeof perf);
		int rc = prsm_performance_compute(&perf, &d, analysis, err);
		if (rc) {
			prsm_performance_free(&perf);
			return rc;
		}
		*k_axial_N_per_m = perf.stiffness_N_per_um * 1e6;
		prsm_performance_free(&perf);
	}
	prsm_losses_options lo;
	prsm_losses_options_from_design(&lo, &d);
	lo.spin = 0; /* only the teeth and contact ratios are wanted */
	prsm_losses_nominal nom;
	prsm_losses_prepare(&nom, &d, &analysis->screw, &analysis->nut, &lo);
	if (nom.gear_rc) {
		if (err != NULL)
			*err = nom.gear_err;
		return nom.gear_rc;
	}
	*z1 = nom.gear_teeth_roller;
	*z2 = nom.gear_teeth_ring;
	*eps = nom.gear_eps_alpha;
	return 0;
}

int prsm_vib_model_new(prsm_vib_model **out, const prsm_design *design, const prsm_analysis *analysis,
                       const prsm_dyn_options *dyn, const prsm_vib_options *vo_in, const prsm_errors *errors,
                       const prsm_assembly_options *assembly, prsm_error *err)
{
	*out = NULL;
	prsm_vib_options vdef;
	prsm_vib_options_init(&vdef);
	const prsm_vib_options *vo = vo_in != NULL ? vo_in : &vdef;
	prsm_problems problems;
	prsm_problems_init(&problems);
	if (prsm_vib_options_check(vo, &problems))
		return prsm_error_set(err, PRSM_EINVAL, problems.items[0].pointer, "%s%s", problems.items[0].message,
		                      prsm_problems_total(&problems) > 1 ? " (and more problems)" : "");
	if (design->rollers < 1 || design->rollers > PRSM_VIB_ROLLERS_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/geometry/rollers", "the vibration model takes 1 to %d rollers",
		                      PRSM_VIB_ROLLERS_MAX);
	if (vo->te_source == PRSM_VIB_TE_STATICS && errors == NULL)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/vibration/te_lines",
		                      "TE lines from the statics need an error set (the assembly's errors)");

	/* the rigid model (dyn.h) for the contact, the slip basis, k* and the masses */
	prsm_dyn_options dopt;
	if (dyn != NULL)
		dopt = *dyn;
	else
		prsm_dyn_options_init(&dopt);
	const double F0 = isnan(vo->axial_load_N) ? dopt.load.value : vo->axial_load_N;
	const double speed0 = finite_pos(vo->screw_speed_rad_s) ? vo->screw_speed_rad_s : 100.0;
	dopt.input.kind = PRSM_DYN_INPUT_SPEED;
	dopt.input.signal.shape = PRSM_DYN_SHAPE_STEP;
	dopt.input.signal.value = speed0;
	dopt.load.shape = PRSM_DYN_SHAPE_STEP;
	dopt.load.value = F0;
	dopt.losses = PRSM_DYN_LOSSES_SLIDING_ONLY;
	dopt.friction.model = PRSM_DYN_FRICTION_COULOMB;
	dopt.friction.stick_model = PRSM_DYN_STICK_NONE;
	dopt.time.stepper = PRSM_DYN_STEPPER_AUTO;
	prsm_dyn_model *dm = NULL;
	int rc = prsm_dyn_model_new(&dm, 1, design, analysis, &dopt, err);
	if (rc)
		return rc;
	prsm_vib_model *m = model_alloc();
	if (m == NULL) {
		prsm_dyn_model_free(dm);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the vibration model");
	}
	const prsm_dyn_stage_params *sp = prsm_dyn_model_stage(dm, 0);
	const prsm_dyn_settled *st = prsm_dyn_model_settled(dm);
	prsm_vib_params *P = &m->par;
	P->kind = PRSM_VIB_REDUCED;
	P->branches = vo->branches;
	P->rollers = design->rollers;
	P->axial_load_N = F0;
	P->carrier_ratio = sp->carrier_ratio_min_slip;
	P->ring_gear_ratio = sp->ring_gear_ratio;
	P->mu = sp->mu;
	P->smoothing_velocity_m_s = dopt.friction.smoothing_velocity_m_s;
	/* the loaded flank (§8.0): where the settled rigid state carries F_0 */
	int flank = PRSM_DYN_FLANK_LOWER;
	if (st->defined)
		flank = st->stage[0].flank;
	else if ((F0 >= 0.0) != (design->hand == PRSM_HAND_RIGHT))
		flank = PRSM_DYN_FLANK_UPPER;
	P->flank = flank;
	const int other = 1 - flank;

	/* statics values (§8.3.1) */
	int z1 = 0, z2 = 0;
	double eps_statics = NAN, k_statics = NAN;
	const int need_k = isnan(vo->axial_stiffness_N_per_um);
	if ((rc = statics_values(&k_statics, &z1, &z2, &eps_statics, design, analysis, F0, speed0, need_k, err)))
		goto fail;
	if (need_k && !(k_statics > 0.0)) {
		rc = prsm_error_set(err, PRSM_EINVAL, "/dynamics/vibration/axial_stiffness_N_per_um",
		                    "the statics stiffness at F_0 = %g N is %g N/um: give axial_stiffness_N_per_um", F0,
		                    k_statics * 1e-6);
		goto fail;
	}
	m->k_axial = need_k ? k_statics : vo->axial_stiffness_N_per_um * 1e6;
	m->m_axial = sp->axial_mass_kg;
	P->axial_damping_ratio = vo->axial_damping_ratio;
	P->axial_half_play_m = isnan(vo->axial_half_play_um) ? 0.5 * analysis->backlash_mm * MM : vo->axial_half_play_um * UM;
	if (!(P->axial_half_play_m > 0.0)) {
		rc = prsm_error_set(err, PRSM_EINVAL, "/dynamics/vibration/axial_half_play_um",
		                    "the design has no axial play (backlash %g um): the axial branch needs b_a > 0; give "
		                    "axial_half_play_um", analysis->backlash_mm * 1e3);
		goto fail;
	}
	P->teeth_roller = vo->gear_teeth_roller > 0 ? vo->gear_teeth_roller : z1;
	P->teeth_ring = vo->gear_teeth_ring > 0 ? vo->gear_teeth_ring : z2;
	P->contact_ratio = isnan(vo->gear_contact_ratio) ? eps_statics : vo->gear_contact_ratio;
	if (!(P->contact_ratio >= 1.0 && P->contact_ratio <= 2.0)) {
		rc = prsm_error_set(err, PRSM_EINVAL, "/dynamics/vibration/gear_contact_ratio",
		                    "the contact ratio %g is outside [1, 2]", P->contact_ratio);
		goto fail;
	}
	P->pressure_angle_rad = isnan(vo->gear_pressure_angle_rad) ? sp->gear_pressure_angle_rad : vo->gear_pressure_angle_rad;
	P->gear_face_width_mm = sp->gear_face_width_mm;
	const double i_g = sp->ring_gear_ratio;
	P->base_radius_roller_m = design->roller_radius_mm * MM * cos(P->pressure_angle_rad);
	P->base_radius_ring_m = design->nut_radius_mm * MM * cos(P->pressure_angle_rad);
	P->mesh_single_N_per_m = vo->mesh_single_stiffness_N_per_mm_um * P->gear_face_width_mm * 1e6;
	P->mesh_double_N_per_m = vo->double_to_single_stiffness * P->mesh_single_N_per_m;
	P->gear_half_backlash_m = vo->gear_backlash_um * UM;
	P->mesh_error_m = vo->mesh_error_um * UM;
	P->mesh_damping_ratio = vo->mesh_damping_ratio;
	const int Z = design->rollers;
	for (int j = 0; j < Z; j++)
		P->mesh_phase[j] = frac((double)j * P->teeth_ring / Z);
	/* §8.3.1: mass matrix on (psi, phi_j) with the roller's axial float p_r (n psi-dot + phi-dot) */
	const double p_r = (design->hand == PRSM_HAND_LEFT ? -1.0 : 1.0) * design->pitch_mm * MM / (2.0 * M_PI);
	P->roller_lead_m_per_rad = p_r;
	const double mR = sp->roller_mass_kg, JR = sp->roller_inertia_kg_m2, JC = sp->carrier_inertia_kg_m2;
	const double a = sp->orbit_radius_mm * MM;
	P->inertia_psipsi_kg_m2 = JC + Z * (mR * a * a + JR + mR * p_r * p_r * i_g * i_g);
	P->inertia_psiphi_kg_m2 = JR + mR * p_r * p_r * i_g;
	P->inertia_phiphi_kg_m2 = JR + mR * p_r * p_r;
	/* §8.3.3: G_phi = z x (p - c) + p_r z, G_psi = z x c + z x (p - c) + n p_r z, on both flanks */
	vib_core *c = &m->c;
	for (int fl = 0; fl < 2; fl++) {
		const double p[3] = {sp->contact_mm[fl][0] * MM, sp->contact_mm[fl][1] * MM, 0.0};
		const double pc[3] = {p[0] - a, p[1], 0.0};
		double zpc[3], zp[3];
		cross_z(zpc, pc);
		cross_z(zp, p);
		double *Gphi = fl == flank ? c->Gphi : c->Gphi_o, *Gpsi = fl == flank ? c->Gpsi : c->Gpsi_o;
		for (int i = 0; i < 3; i++) {
			Gphi[i] = zpc[i] + (i == 2 ? p_r : 0.0);
			Gpsi[i] = zp[i] + (i == 2 ? i_g * p_r : 0.0);
		}
	}
	c->nz = sp->normal[flank][2];
	c->nz_o = sp->normal[other][2];
	for (int i = 0; i < 3; i++) {
		m->v_basis_A[i] = sp->A_mm[flank][i] * MM;
		m->v_basis_B[i] = sp->B_mm[flank][i] * MM;
		P->G_phi_m[i] = c->Gphi[i];
		P->G_psi_m[i] = c->Gpsi[i];
	}
	/* the screw speed: given, or from the frequency ratio (omega_e = z_2 k* omega_s / omega_ref) */
	P->screw_speed_rad_s = speed0;
	P->te_lines = 0;
	vib_core_derive(m);
	if (!isnan(vo->frequency_ratio)) {
		P->screw_speed_rad_s = vo->frequency_ratio * c->wref / (P->teeth_ring * P->carrier_ratio);
		vib_core_derive(m);
	}
	/* TE lines (§8.3.4) */
	if (vo->te_source == PRSM_VIB_TE_LINES) {
		P->te_lines = vo->te_lines;
		memcpy(P->te_line, vo->te_line, (size_t)vo->te_lines * sizeof vo->te_line[0]);
	} else if (vo->te_source == PRSM_VIB_TE_STATICS) {
		if ((rc = prsm_vib_te_lines_from_errors(P->te_line, &P->te_lines, design, analysis, errors, assembly,
		                                        P->carrier_ratio, vo->te_threshold, vo->te_max_lines, err)))
			goto fail;
	}
	vib_core_derive(m);
	if (!(c->wref > 0.0 && isfinite(c->wref) && c->schur > 0.0 && isfinite(P->mean_mesh_force_N))) {
		rc = prsm_error_set(err, PRSM_EINVAL, "/dynamics/inertia", "the gear branch has no inertia or stiffness "
		                    "(omega_ref = %g rad/s)", c->wref);
		goto fail;
	}
	prsm_dyn_model_free(dm);
	*out = m;
	return 0;
fail:
	prsm_dyn_model_free(dm);
	free(m);
	return rc;
}

int vib_model_set(prsm_vib_model *m, int parameter, double value, prsm_error *err)
{
	prsm_vib_params *P = &m->par;
	if (!isfinite(value))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "the parameter value %g is not finite", value);
	if (P->kind == PRSM_VIB_GEAR_PAIR) {
		prsm_vib_gear_pair g = P->gear_pair;
		switch (parameter) {
		case PRSM_VIB_PARAM_FREQUENCY_RATIO: g.frequency_ratio = value; break;
		case PRSM_VIB_PARAM_MESH_ERROR: g.mesh_error = value; break;
		case PRSM_VIB_PARAM_DAMPING_RATIO: g.damping_ratio = value; break;
		case PRSM_VIB_PARAM_MEAN_FORCE: g.mean_force = value; break;
		case PRSM_VIB_PARAM_STIFFNESS_VARIATION: g.stiffness_variation = value; break;
		default:
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/parameter",
			                      "the gear pair has no parameter %d (frequency ratio, mesh error, damping "
			                      "ratio, mean force, stiffness variation)", parameter);
		}
		prsm_problems pr;
		prsm_problems_init(&pr);
		if (prsm_vib_gear_pair_check(&g, &pr))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "%s", pr.items[0].message);
		P->gear_pair = g;
		vib_core_derive(m);
		return 0;
	}
	switch (parameter) {
	case PRSM_VIB_PARAM_FREQUENCY_RATIO:
		if (!(value > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "the frequency ratio must be > 0 (got %g)", value);
		P->screw_speed_rad_s = value * m->c.wref / (P->teeth_ring * P->carrier_ratio);
		break;
	case PRSM_VIB_PARAM_SCREW_SPEED:
		if (!(value > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "the screw speed must be > 0 rad/s (got %g)", value);
		P->screw_speed_rad_s = value;
		break;
	case PRSM_VIB_PARAM_MESH_ERROR:
		if (!(value >= 0.0))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "the mesh error must be >= 0 m (got %g)", value);
		P->mesh_error_m = value;
		break;
	case PRSM_VIB_PARAM_DAMPING_RATIO:
		if (!(value > 0.0 && value < 1.0))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep", "the damping ratio must be in (0, 1) (got %g)", value);
		P->mesh_damping_ratio = value;
		break;
	default:
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/sweep/parameter",
		                      "the reduced model sweeps the frequency ratio, the screw speed, the mesh error or "
		                      "the mesh damping ratio (got parameter %d)", parameter);
	}
	vib_core_derive(m);
	return 0;
}

int prsm_vib_model_set(prsm_vib_model *m, int parameter, double value, prsm_error *err)
{
	return vib_model_set(m, parameter, value, err);
}

void prsm_vib_static_state(const prsm_vib_model *m, double *y)
{
	const vib_core *c = &m->c;
	memset(y, 0, (size_t)c->n * sizeof *y);
	if (m->par.kind == PRSM_VIB_GEAR_PAIR) {
		y[0] = (c->fm > 0.0 ? 1.0 : (c->fm < 0.0 ? -1.0 : 0.0)) + c->fm;
		return;
	}
	const double x = m->par.static_mesh_deflection_m / c->bg;
	for (int j = 1; j <= c->Z; j++)
		y[vib_iP(c, j)] = x;
	y[vib_iY(c)] = m->par.axial_static_m / c->ba;
}

double prsm_vib_period(const prsm_vib_model *m, int clock)
{
	const vib_core *c = &m->c;
	if (m->par.kind == PRSM_VIB_GEAR_PAIR)
		return 2.0 * M_PI / c->Omega;
	if (clock == PRSM_VIB_CLOCK_TE) {
		const double Trev = m->par.te_period_rev;
		if (!(Trev > 0.0))
			return NAN;
		return Trev * 2.0 * M_PI / m->par.screw_speed_rad_s * c->wref;
	}
	return 2.0 * M_PI / c->we;
}

int prsm_vib_clock_of(const prsm_vib_model *m, int clock, int observable)
{
	if (clock != PRSM_VIB_CLOCK_AUTO)
		return clock;
	if (m->par.kind == PRSM_VIB_GEAR_PAIR)
		return PRSM_VIB_CLOCK_MESH;
	const int axial_obs = observable == PRSM_VIB_OBS_AXIAL_DEFLECTION || observable == PRSM_VIB_OBS_AXIAL_RATE ||
	                      observable == PRSM_VIB_OBS_THREAD_FORCE;
	if ((axial_obs || !m->c.gear) && m->par.te_period_rev > 0.0)
		return PRSM_VIB_CLOCK_TE;
	return PRSM_VIB_CLOCK_MESH;
}

void vib_mesh_errors(const vib_core *c, double tau, double *e, double *edot)
{
	if (c->eg == 0.0) {
		for (int j = 0; j < c->Z; j++)
			e[j] = edot[j] = 0.0;
		return;
	}
	const double s = sin(c->we * tau), co = cos(c->we * tau);
	for (int j = 0; j < c->Z; j++) {
		e[j] = c->eg * (s * c->cphase[j] + co * c->sphase[j]);
		edot[j] = c->eg * c->we * (co * c->cphase[j] - s * c->sphase[j]);
	}
}

void vib_contacts(const vib_core *c, double tau, const double *y, double *g)
{
	if (c->pair) {
		g[0] = y[0];
		return;
	}
	int k = 0;
	if (c->gear) {
		double e[PRSM_VIB_ROLLERS_MAX], ed[PRSM_VIB_ROLLERS_MAX];
		vib_mesh_errors(c, tau, e, ed);
		for (int j = 0; j < c->Z; j++)
			g[k++] = y[vib_iP(c, 0)] + y[vib_iP(c, j + 1)] - e[j];
	}
	if (c->axial)
		g[k] = y[vib_iY(c)];
}

double prsm_vib_observable(const prsm_vib_model *m, int obs, int index, double tau, const double *y)
{
	const vib_core *c = &m->c;
	if (m->par.kind == PRSM_VIB_GEAR_PAIR) {
		switch (obs) {
		case PRSM_VIB_OBS_MESH_DEFLECTION: return y[0];
		case PRSM_VIB_OBS_MESH_RATE: return y[1];
		case PRSM_VIB_OBS_MESH_FORCE: {
			double kap = 1.0;
			if (c->kappa != 0.0) {
				const double u = frac(c->Omega * tau / (2.0 * M_PI));
				kap = u < c->D ? c->kd : c->ks;
			}
			return kap * vib_dead(y[0]);
		}
		default: return NAN;
		}
	}
	if (index < 0 || index >= c->Z)
		index = 0;
	switch (obs) {
	case PRSM_VIB_OBS_MESH_DEFLECTION: return y[vib_iP(c, 0)] + y[vib_iP(c, index + 1)];
	case PRSM_VIB_OBS_MESH_RATE: return y[vib_iV(c, 0)] + y[vib_iV(c, index + 1)];
	case PRSM_VIB_OBS_AXIAL_DEFLECTION: return y[vib_iY(c)];
	case PRSM_VIB_OBS_AXIAL_RATE: return y[vib_iW(c)];
	case PRSM_VIB_OBS_MESH_FORCE:
	case PRSM_VIB_OBS_THREAD_FORCE: {
		double kap[PRSM_VIB_ROLLERS_MAX], F[PRSM_VIB_ROLLERS_MAX], Fth;
		for (int j = 0; j < c->Z; j++) {
			kap[j] = 1.0;
			if (c->kd != c->ks) {
				const double u = frac(c->we * tau / (2.0 * M_PI) + c->gamma[j]);
				kap[j] = u < c->D ? c->kd : c->ks;
			}
		}
		vib_forces(c, kap, tau, y, F, &Fth);
		return obs == PRSM_VIB_OBS_MESH_FORCE ? F[index] : Fth;
	}
	default: return NAN;
	}
}

int vib_reduced_size(const vib_core *c)
{
	if (c->pair)
		return 2;
	return (c->gear ? 2 * c->Z + 1 : 0) + (c->axial ? 2 : 0);
}

void vib_project(const vib_core *c, const double *v, double *r)
{
	if (c->pair) {
		r[0] = v[0];
		r[1] = v[1];
		return;
	}
	int k = 0;
	if (c->gear) {
		const double p0 = v[vib_iP(c, 0)], v0 = v[vib_iV(c, 0)];
		for (int j = 1; j <= c->Z; j++)
			r[k++] = p0 + v[vib_iP(c, j)];
		for (int j = 1; j <= c->Z; j++)
			r[k++] = v0 + v[vib_iV(c, j)];
		r[k++] = v0;
	}
	if (c->axial) {
		r[k++] = v[vib_iY(c)];
		r[k++] = v[vib_iW(c)];
	}
}

void vib_lift(const vib_core *c, const double *r, double *v)
{
	if (c->pair) {
		v[0] = r[0];
		v[1] = r[1];
		return;
	}
	for (int i = 0; i < c->n; i++)
		v[i] = 0.0;
	int k = 0;
	if (c->gear) {
		const int Z = c->Z;
		const double v0 = r[2 * Z];
		v[vib_iP(c, 0)] = 0.0;
		v[vib_iV(c, 0)] = v0;
		for (int j = 1; j <= Z; j++) {
			v[vib_iP(c, j)] = r[j - 1];
			v[vib_iV(c, j)] = r[Z + j - 1] - v0;
		}
		k = 2 * Z + 1;
	}
	if (c->axial) {
		v[vib_iY(c)] = r[k];
		v[vib_iW(c)] = r[k + 1];
	}
}

void prsm_vib_poincare_vector(const prsm_vib_model *m, const double *y, double *out)
{
	vib_project(&m->c, y, out);
}

/* ---- TE lines (§8.3.4) ---- */

int prsm_vib_te_lines_fit(prsm_vib_te_line *out, const double *te_mm, int n, int per_rev,
                          const double *orders, int n_orders, prsm_error *err)
{
	const int p = 2 + 2 * n_orders;
	if (n_orders < 1 || n < p + 2 || per_rev < 2)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "a TE fit of %d lines needs more than %d samples (got %d)",
		                      n_orders, p + 2, n);
	gsl_matrix *X = gsl_matrix_alloc((size_t)n, (size_t)p);
	gsl_vector *yv = gsl_vector_alloc((size_t)n), *cv = gsl_vector_alloc((size_t)p);
	gsl_matrix *cov = gsl_matrix_alloc((size_t)p, (size_t)p);
	gsl_multifit_linear_workspace *w = gsl_multifit_linear_alloc((size_t)n, (size_t)p);
	int rc = 0;
	if (!X || !yv || !cv || !cov || !w) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the TE fit");
		goto cleanup;
	}
	for (int i = 0; i < n; i++) {
		gsl_matrix_set(X, (size_t)i, 0, 1.0);
		gsl_matrix_set(X, (size_t)i, 1, (double)i / per_rev);
		for (int k = 0; k < n_orders; k++) {
			const double ph = 2.0 * M_PI * orders[k] * i / per_rev;
			gsl_matrix_set(X, (size_t)i, (size_t)(2 + 2 * k), cos(ph));
			gsl_matrix_set(X, (size_t)i, (size_t)(3 + 2 * k), sin(ph));
		}
		gsl_vector_set(yv, (size_t)i, te_mm[i]);
	}
	double chisq = 0.0;
	size_t rank = 0;
	if (gsl_multifit_linear_tsvd(X, yv, 1e-12, cv, cov, &chisq, &rank, w) != 0) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the least-squares fit of the TE lines failed");
		goto cleanup;
	}
	for (int k = 0; k < n_orders; k++) {
		const double cc = gsl_vector_get(cv, (size_t)(2 + 2 * k)), ss = gsl_vector_get(cv, (size_t)(3 + 2 * k));
		out[k].order_per_rev = orders[k];
		out[k].amplitude_m = hypot(cc, ss) * MM;
		out[k].phase_rad = atan2(-ss, cc);
	}
cleanup:
	gsl_multifit_linear_free(w);
	gsl_matrix_free(cov);
	gsl_vector_free(cv);
	gsl_vector_free(yv);
	gsl_matrix_free(X);
	return rc;
}

int prsm_vib_te_lines_from_errors(prsm_vib_te_line *out, int *n_out, const prsm_design *design,
                                  const prsm_analysis *analysis, const prsm_errors *errors,
                                  const prsm_assembly_options *assembly, double k_star, double threshold,
                                  int max_lines, prsm_error *err)
{
	*n_out = 0;
	if (max_lines < 1 || max_lines > PRSM_VIB_TE_LINES_MAX)
		max_lines = PRSM_VIB_TE_LINES_MAX;
	prsm_assembly *as = malloc(sizeof *as);
	prsm_assembly_workspace *ws = calloc(1, sizeof *ws);
	int rc = 0;
	if (as == NULL || ws == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the TE record");
		goto cleanup;
	}
	if ((rc = prsm_assembly_init(as, design, analysis, err)))
		goto cleanup;
	prsm_assembly_options o;
	if (assembly != NULL) {
		o = *assembly;
	} else {
		prsm_assembly_options_default(&o);
		o.stroke_mm = 100.0;
	}
	int n = 0, fft = 0;
	prsm_assembly_record_length(&n, &fft, as, &o);
	ws->te_mm = calloc((size_t)n, sizeof(double));
	ws->spectrum_mm = calloc((size_t)fft, sizeof(double));
	if (ws->te_mm == NULL || ws->spectrum_mm == NULL) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the TE record");
		goto cleanup;
	}
	prsm_assembly_report rep;
	if ((rc = prsm_assembly_analyse(&rep, as, errors, &o, ws))) {
		prsm_error_set(err, rc, NULL, "the TE record was stopped");
		goto cleanup;
	}
	const double M = rep.angles_per_revolution, nyq = 0.5 * M;
	const double step = rep.spectrum_step_per_rev, fmin = 2.0 / rep.record_revolutions;
	const double kc = as->carrier_ratio;
	const prsm_assembly_frequencies *fq = &rep.frequencies;
	const double named[5] = {fq->screw, fq->carrier, fq->roller_spin, fq->roller_pass_screw, fq->roller_pass_nut};
	/* the same lines with k* (§8.3.4): the orders as functions of the carrier ratio */
	const double i_g = kc > 0.0 ? fq->roller_spin / kc : 0.0;
	const double named_k[5] = {1.0 - k_star, k_star, i_g * k_star, as->rollers * (1.0 - k_star), as->rollers * k_star};
	double orders[PRSM_VIB_TE_LINES_MAX], orders_k[PRSM_VIB_TE_LINES_MAX];
	int no = 0;
	for (int i = 0; i < 5 && no < max_lines; i++) {
		int dup = !(named[i] > 0.0 && named[i] < nyq);
		for (int k = 0; k < no && !dup; k++)
			dup = fabs(orders[k] - named[i]) < 1e-9;
		if (!dup) {
			orders[no] = named[i];
			orders_k[no++] = named_k[i];
		}
	}
	/* the strongest other local maxima of the spectrum above threshold x the largest; a maximum
	 * next to a line already taken (1.5 record resolutions) or below the Hann
	 * window's sidelobe envelope of a stronger line (5 % at 2.5 resolutions, falling as the cube of
	 * the distance) is that line's leakage, not a line */
	double largest = 0.0;
	for (int b = 1; b < rep.spectrum_bins; b++)
		if (b * step >= fmin)
			largest = fmax(largest, ws->spectrum_mm[b]);
	const double res = 1.0 / rep.record_revolutions; /* record resolution, per revolution */
	double taken_amp[PRSM_VIB_TE_LINES_MAX];
	for (int k = 0; k < no; k++)
		taken_amp[k] = 0.0; /* named lines: their main lobes only */
	while (no < max_lines) {
		int best = -1;
		for (int b = 1; b + 1 < rep.spectrum_bins; b++) {
			const double f = b * step, A = ws->spectrum_mm[b];
			if (f < fmin || f >= nyq || !(A > ws->spectrum_mm[b - 1] && A >= ws->spectrum_mm[b + 1]) ||
			    !(A > threshold * largest) || !(A > 0.0))
				continue;
			int leak = 0;
			for (int k = 0; k < no && !leak; k++) {
				const double dist = fabs(orders[k] - f) / res;
				leak = dist < 1.5 || (dist >= 2.5 ? A < taken_amp[k] * 0.05 * pow(2.5 / dist, 3.0) : A < taken_amp[k] * 0.05);
			}
			if (!leak && (best < 0 || A > ws->spectrum_mm[best]))
				best = b;
		}
		if (best < 0)
			break;
		taken_amp[no] = ws->spectrum_mm[best];
		orders[no] = best * step;
		orders_k[no++] = best * step;
	}
	if (no == 0)
		goto cleanup;
	prsm_vib_te_line fit[PRSM_VIB_TE_LINES_MAX];
	if ((rc = prsm_vib_te_lines_fit(fit, ws->te_mm, n, (int)M, orders, no, err)))
		goto cleanup;
	for (int k = 0; k < no; k++) {
		if (!(fit[k].amplitude_m > 1e-15))
			continue;
		out[*n_out] = fit[k];
		out[*n_out].order_per_rev = orders_k[k];
		(*n_out)++;
	}
cleanup:
	if (ws != NULL) {
		free(ws->te_mm);
		free(ws->spectrum_mm);
	}
	free(ws);
	free(as);
	return rc;
}
