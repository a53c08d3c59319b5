/*
 * model.c: the options of a transient run and the model built from the statics engine's stages
 * (docs/model §8.1, §8.2.1–8.2.3): the kinematic structure of each stage from its solved
 * contacts, the masses and inertias, the couplings of the chain, the statics references
 * (sliding efficiency, the loss model, the chain), then the settled state (dyn/settled.c).
 */
#include "dyn/dyn_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/efficiency.h"
#include "model/geometry.h"
#include "model/kinematics.h"
#include "model/performance.h"

#define MM 1e-3 /* mm -> m */
#define DEFAULT_NUT_OUTER_PER_RN 1.3 /* docs/model §8.2.2: r_no = 1.3 r_n */


int prsm_dyn_options_init(prsm_dyn_options *o)
{
	const prsm_dyn_options defaults = PRSM_DYN_OPTIONS_INIT;
	*o = defaults;
	return 0;
}

double prsm_dyn_signal_value(const prsm_dyn_signal *s, double t)
{
	switch (s->shape) {
	case PRSM_DYN_SHAPE_RAMP:
		return s->value * fmin(fmax(t, 0.0) / s->ramp_time_s, 1.0);
	case PRSM_DYN_SHAPE_SINE:
		return s->value + s->sine_amplitude * sin(2.0 * M_PI * s->sine_frequency_Hz * t);
	default:
		return s->value;
	}
}

double prsm_dyn_signal_rate(const prsm_dyn_signal *s, double t)
{
	switch (s->shape) {
	case PRSM_DYN_SHAPE_RAMP:
		return t >= 0.0 && t < s->ramp_time_s ? s->value / s->ramp_time_s : 0.0;
	case PRSM_DYN_SHAPE_SINE: {
		const double w = 2.0 * M_PI * s->sine_frequency_Hz;
		return s->sine_amplitude * w * cos(w * t);
	}
	default:
		return 0.0;
	}
}

/* ---- options ---- */

static int finite_nonneg(double x)
{
	return x >= 0.0 && isfinite(x);
}

static int finite_pos(double x)
{
	return x > 0.0 && isfinite(x);
}

/* A signal's problems at base/shape, base/<value_name>, base/ramp_time_s,
 * base/sine_amplitude<suffix>, base/sine_frequency_Hz (suffix: the unit, "_rad_s", "_Nm", "_N"). */
static void check_signal(const prsm_dyn_signal *s, const char *base, const char *value_name,
                         const char *suffix, const char *unit, prsm_problems *p)
{
	char ptr[PRSM_PROBLEM_POINTER_MAX];
	if (s->shape != PRSM_DYN_SHAPE_STEP && s->shape != PRSM_DYN_SHAPE_RAMP && s->shape != PRSM_DYN_SHAPE_SINE) {
		snprintf(ptr, sizeof ptr, "%s/shape", base);
		prsm_problems_add(p, ptr, "enum", "shape must be step (constant), ramp or sine");
		return;
	}
	if (!isfinite(s->value)) {
		snprintf(ptr, sizeof ptr, "%s/%s", base, value_name);
		prsm_problems_add(p, ptr, "finite", "the value must be a finite number of %s", unit);
	}
	if (s->shape == PRSM_DYN_SHAPE_RAMP && !finite_pos(s->ramp_time_s)) {
		snprintf(ptr, sizeof ptr, "%s/ramp_time_s", base);
		prsm_problems_add(p, ptr, "positive", "a ramp needs a ramp time > 0 s (got %g)", s->ramp_time_s);
	}
	if (s->shape == PRSM_DYN_SHAPE_SINE) {
		if (!isfinite(s->sine_amplitude)) {
			snprintf(ptr, sizeof ptr, "%s/sine_amplitude%s", base, suffix);
			prsm_problems_add(p, ptr, "finite", "the sine amplitude must be finite (%s)", unit);
		}
		if (!finite_nonneg(s->sine_frequency_Hz)) {
			snprintf(ptr, sizeof ptr, "%s/sine_frequency_Hz", base);
			prsm_problems_add(p, ptr, "nonnegative", "the sine frequency must be >= 0 Hz (got %g)",
			                  s->sine_frequency_Hz);
		}
	}
}

/* Output times: 0, step, 2 step, ... and the end. */
static size_t output_points(double end_s, double step_s)
{
	const double q = floor(end_s / step_s * (1.0 + 1e-12));
	if (!(q < 2.0 * PRSM_DYN_OUTPUT_POINTS_MAX))
		return (size_t)2 * PRSM_DYN_OUTPUT_POINTS_MAX;
	size_t n = (size_t)q + 1;
	if ((double)(n - 1) * step_s < end_s * (1.0 - 1e-12))
		n++;
	return n;
}

size_t dyn_output_points(const prsm_dyn_options *o)
{
	return output_points(o->time.end_s, o->time.output_step_s);
}

static void check_mass(double x, const char *base, const char *name, prsm_problems *p)
{
	char ptr[PRSM_PROBLEM_POINTER_MAX];
	if (!isnan(x) && !finite_nonneg(x)) {
		snprintf(ptr, sizeof ptr, "%s/%s", base, name);
		prsm_problems_add(p, ptr, "nonnegative", "%s must be >= 0, or left out for the geometry's value "
		                  "(got %g)", name, x);
	}
}

int prsm_dyn_options_check(const prsm_dyn_options *o, int stages, prsm_problems *p)
{
	const int before = prsm_problems_total(p);
	const prsm_dyn_input *in = &o->input;
	const int torque = in->kind == PRSM_DYN_INPUT_TORQUE;
	if (in->kind != PRSM_DYN_INPUT_SPEED && !torque)
		prsm_problems_add(p, "/dynamics/input/kind", "enum", "the input is a speed or a torque");
	check_signal(&in->signal, "/dynamics/input", torque ? "value_Nm" : "value_rad_s",
	             torque ? "_Nm" : "_rad_s", torque ? "N m" : "rad/s", p);
	if (!finite_nonneg(in->motor_inertia_kg_m2))
		prsm_problems_add(p, "/dynamics/input/motor_inertia_kg_mm2", "nonnegative",
		                  "the motor inertia must be >= 0 (got %g kg m^2)", in->motor_inertia_kg_m2);
	if (!finite_nonneg(in->viscous_drag_Nm_s_per_rad))
		prsm_problems_add(p, "/dynamics/input/viscous_drag_Nm_s_per_rad", "nonnegative",
		                  "the viscous drag must be >= 0 N m s/rad (got %g)", in->viscous_drag_Nm_s_per_rad);
	if (!isfinite(in->initial_speed_rad_s))
		prsm_problems_add(p, "/dynamics/input/initial_speed_rad_s", "finite",
		                  "the initial screw speed must be finite");
	check_signal(&o->load, "/dynamics/load", "axial_load_N", "_N", "N", p);

	const prsm_dyn_friction *f = &o->friction;
	if (f->model != PRSM_DYN_FRICTION_COULOMB && f->model != PRSM_DYN_FRICTION_VISCOUS &&
	    f->model != PRSM_DYN_FRICTION_STRIBECK)
		prsm_problems_add(p, "/dynamics/friction/model", "enum", "friction is coulomb, viscous or stribeck");
	if (f->model == PRSM_DYN_FRICTION_VISCOUS && !finite_nonneg(f->viscous_N_s_per_m))
		prsm_problems_add(p, "/dynamics/friction/viscous_N_s_per_m", "nonnegative",
		                  "the viscous friction coefficient must be >= 0 N s/m (got %g)", f->viscous_N_s_per_m);
	if (!isnan(f->mu) && !finite_nonneg(f->mu))
		prsm_problems_add(p, "/dynamics/friction/mu", "nonnegative", "mu must be >= 0 (got %g)", f->mu);
	if (!finite_pos(f->smoothing_velocity_m_s))
		prsm_problems_add(p, "/dynamics/friction/smoothing_velocity_m_s", "positive",
		                  "the smoothing velocity must be > 0 m/s (got %g)", f->smoothing_velocity_m_s);
	if (!isnan(f->static_mu) && !finite_nonneg(f->static_mu))
		prsm_problems_add(p, "/dynamics/friction/static_mu", "nonnegative",
		                  "the static mu must be >= 0 (got %g)", f->static_mu);
	if (!finite_pos(f->stribeck_velocity_m_s))
		prsm_problems_add(p, "/dynamics/friction/stribeck_velocity_m_s", "positive",
		                  "the Stribeck velocity must be > 0 m/s (got %g)", f->stribeck_velocity_m_s);
	if (f->stick_model != PRSM_DYN_STICK_NONE && f->stick_model != PRSM_DYN_STICK_KARNOPP)
		prsm_problems_add(p, "/dynamics/friction/stick_model", "enum", "the stick model is none or karnopp");
	if (f->stick_model == PRSM_DYN_STICK_KARNOPP && !torque)
		prsm_problems_add(p, "/dynamics/friction/stick_model", "karnopp_torque",
		                  "the Karnopp stick model needs a torque input (a prescribed speed never sticks)");
	if (f->stick_model == PRSM_DYN_STICK_KARNOPP && f->model == PRSM_DYN_FRICTION_VISCOUS)
		prsm_problems_add(p, "/dynamics/friction/stick_model", "karnopp_viscous",
		                  "viscous friction has no static friction to stick with: use coulomb or stribeck");
	if (!isnan(f->stick_band_rad_s) && !finite_pos(f->stick_band_rad_s))
		prsm_problems_add(p, "/dynamics/friction/stick_band_rad_s", "positive",
		                  "the stick band must be > 0 rad/s (got %g)", f->stick_band_rad_s);
	if (!finite_nonneg(f->carrier_drag_Nm_s_per_rad))
		prsm_problems_add(p, "/dynamics/friction/carrier_drag_Nm_s_per_rad", "nonnegative",
		                  "the carrier drag must be >= 0 N m s/rad (got %g)", f->carrier_drag_Nm_s_per_rad);
	if (!finite_pos(f->coupling_smoothing_rad_s))
		prsm_problems_add(p, "/dynamics/friction/coupling_smoothing_rad_s", "positive",
		                  "the sign smoothing speed must be > 0 rad/s (got %g)", f->coupling_smoothing_rad_s);
	if (o->losses != PRSM_DYN_LOSSES_STATICS && o->losses != PRSM_DYN_LOSSES_SLIDING_ONLY)
		prsm_problems_add(p, "/dynamics/losses", "enum", "losses are statics or sliding_only");

	const prsm_dyn_inertia *I = &o->inertia;
	if (!finite_pos(I->density_kg_m3))
		prsm_problems_add(p, "/dynamics/inertia/density_kg_m3", "positive",
		                  "the density must be > 0 kg/m^3 (got %g)", I->density_kg_m3);
	if (!finite_nonneg(I->stroke_mm))
		prsm_problems_add(p, "/dynamics/inertia/stroke_mm", "nonnegative", "the stroke must be >= 0 mm (got %g)",
		                  I->stroke_mm);
	if (!finite_nonneg(I->payload_kg))
		prsm_problems_add(p, "/dynamics/inertia/payload_kg", "nonnegative", "the payload must be >= 0 kg (got %g)",
		                  I->payload_kg);
	for (int k = 0; k < stages && k < PRSM_DYN_STAGES_MAX; k++) {
		const prsm_dyn_stage_inertia *s = &I->stage[k];
		char base[PRSM_PROBLEM_POINTER_MAX];
		if (stages > 1)
			snprintf(base, sizeof base, "/dynamics/inertia/stages/%d", k);
		else
			snprintf(base, sizeof base, "/dynamics/inertia");
		if (!isnan(s->gear_face_width_mm) && !finite_pos(s->gear_face_width_mm)) {
			char ptr[PRSM_PROBLEM_POINTER_MAX + 32];
			snprintf(ptr, sizeof ptr, "%s/gear_face_width_mm", base);
			prsm_problems_add(p, ptr, "positive", "the gear face width must be > 0 mm (got %g)",
			                  s->gear_face_width_mm);
		}
		check_mass(s->roller_mass_kg, base, "roller_mass_kg", p);
		check_mass(s->roller_inertia_kg_m2, base, "roller_inertia_kg_mm2", p);
		check_mass(s->carrier_mass_kg, base, "carrier_mass_kg", p);
		check_mass(s->carrier_inertia_kg_m2, base, "carrier_inertia_kg_mm2", p);
		check_mass(s->nut_mass_kg, base, "nut_mass_kg", p);
		check_mass(s->screw_mass_kg, base, "screw_mass_kg", p);
		check_mass(s->screw_inertia_kg_m2, base, "screw_inertia_kg_mm2", p);
	}

	const prsm_dyn_couplings *c = &o->couplings;
	if (!(c->spline_friction >= 0.0 && c->spline_friction < 1.0))
		prsm_problems_add(p, "/couplings/spline_friction", "range", "mu_SS must be in [0, 1) (got %g)",
		                  c->spline_friction);
	if (!(c->thrust_bearing_friction >= 0.0 && c->thrust_bearing_friction < 1.0))
		prsm_problems_add(p, "/couplings/thrust_bearing_friction", "range", "mu_NS must be in [0, 1) (got %g)",
		                  c->thrust_bearing_friction);
	for (int k = 1; k < stages && k < PRSM_DYN_STAGES_MAX; k++) {
		char ptr[PRSM_PROBLEM_POINTER_MAX];
		if (!isnan(c->spline_radius_mm[k]) && !finite_pos(c->spline_radius_mm[k])) {
			snprintf(ptr, sizeof ptr, "/couplings/spline_radius_mm/%d", k - 1);
			prsm_problems_add(p, ptr, "positive", "the spline radius must be > 0 mm (got %g)", c->spline_radius_mm[k]);
		}
		if (!isnan(c->thrust_radius_mm[k]) && !finite_pos(c->thrust_radius_mm[k])) {
			snprintf(ptr, sizeof ptr, "/couplings/thrust_bearing_radius_mm/%d", k - 1);
			prsm_problems_add(p, ptr, "positive", "the thrust-bearing radius must be > 0 mm (got %g)",
			                  c->thrust_radius_mm[k]);
		}
	}

	const prsm_dyn_time *t = &o->time;
	if (!finite_pos(t->end_s))
		prsm_problems_add(p, "/dynamics/time/end_s", "positive", "the end time must be > 0 s (got %g)", t->end_s);
	if (!(t->output_step_s >= PRSM_DYN_OUTPUT_STEP_MIN_S && isfinite(t->output_step_s)))
		prsm_problems_add(p, "/dynamics/time/output_step_s", "output_step_min",
		                  "the output step must be at least %g s (got %g)", PRSM_DYN_OUTPUT_STEP_MIN_S,
		                  t->output_step_s);
	else if (finite_pos(t->end_s) && output_points(t->end_s, t->output_step_s) > PRSM_DYN_OUTPUT_POINTS_MAX)
		prsm_problems_add(p, "/dynamics/time/output_step_s", "output_points_max",
		                  "%g s every %g s is more than %d output points: raise the output step",
		                  t->end_s, t->output_step_s, PRSM_DYN_OUTPUT_POINTS_MAX);
	if (t->stepper < PRSM_DYN_STEPPER_AUTO || t->stepper > PRSM_DYN_STEPPER_RK4IMP)
		prsm_problems_add(p, "/dynamics/time/stepper", "enum", "the stepper is rk8pd or msbdf");
	else if (torque && t->stepper == PRSM_DYN_STEPPER_RK8PD && in->initial_speed_rad_s == 0.0 &&
	         f->model != PRSM_DYN_FRICTION_VISCOUS)
		prsm_problems_add(p, "/dynamics/time/stepper", "stiff_explicit",
		                  "a torque input from rest is stiff near zero speed (friction slope mu N / "
		                  "v_eps): use the implicit stepper msbdf (it hands over to rk8pd once running)");
	if (!finite_pos(t->rel_tol) || t->rel_tol >= 1e-2)
		prsm_problems_add(p, "/dynamics/time/rel_tol", "range", "rel_tol must be in (0, 0.01) (got %g)", t->rel_tol);
	if (!finite_pos(t->abs_tol) || t->abs_tol >= 1e-2)
		prsm_problems_add(p, "/dynamics/time/abs_tol", "range", "abs_tol must be in (0, 0.01) (got %g)", t->abs_tol);
	if (!isnan(t->initial_step_s) && !finite_pos(t->initial_step_s))
		prsm_problems_add(p, "/dynamics/time/initial_step_s", "positive", "the initial step must be > 0 s");
	if (!isnan(t->stiff_switch_rad_s) && !(t->stiff_switch_rad_s > 0.0))
		prsm_problems_add(p, "/dynamics/time/stiff_switch_rad_s", "positive", "the switch speed must be > 0 rad/s");
	if (!isnan(t->speed_scale_rad_s) && !finite_pos(t->speed_scale_rad_s))
		prsm_problems_add(p, "/dynamics/time/speed_scale_rad_s", "positive", "the speed scale must be > 0 rad/s");
	if (t->max_steps < 1)
		prsm_problems_add(p, "/dynamics/time/max_steps", "positive", "max_steps must be >= 1");
	return prsm_problems_total(p) > before ? PRSM_EINVAL : 0;
}

/* ---- the model ---- */

/* (radial, tangential, axial) at the point (x, y) -> (x, y, z) */
static void cylindrical_to_cartesian(double out[3], const double nrtz[3], double x, double y)
{
	const double rho = hypot(x, y), cr = x / rho, sr = y / rho;
	out[0] = nrtz[0] * cr - nrtz[1] * sr;
	out[1] = nrtz[0] * sr + nrtz[1] * cr;
	out[2] = nrtz[2];
}

/* The half-turn about x, (x, y, z) -> (x, -y, -z) (docs/model §8.0): the other flank. */
static void half_turn(double out[3], const double v[3])
{
	out[0] = v[0];
	out[1] = -v[1];
	out[2] = -v[2];
}

static double dot3(const double a[3], const double b[3])
{
	return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double pick(double override, double geometric)
{
	return isnan(override) ? geometric : override;
}

static int stage_build(prsm_dyn_model *m, int k, const prsm_design *designs,
                       const prsm_analysis *analyses, prsm_error *err)
{
	const prsm_design *d = &designs[k];
	const prsm_analysis *an = &analyses[k];
	const prsm_dyn_options *o = &m->opts;
	dyn_stage *st = &m->stage[k];
	prsm_dyn_stage_params *par = &st->par;
	char base[64];
	if (m->stages > 1)
		snprintf(base, sizeof base, "/stages/%d", k);
	else
		base[0] = '\0';
	char ptr[128];
	const double rs = d->screw_radius_mm, rr = d->roller_radius_mm, rn = d->nut_radius_mm;
	const double P = d->pitch_mm, a = rs + rr;

	if ((double)d->hand != m->hand) {
		snprintf(ptr, sizeof ptr, "%s/geometry/hand", base);
		return prsm_error_set(err, PRSM_EINVAL, ptr, "stage %d has the other hand: the rigid chain "
		                      "needs every stage of one hand (docs/model §8.0)", k + 1);
	}
	/* docs/model §8.1 item 2: the nut contact must roll, no migration */
	const prsm_geometry *g = &an->geometry;
	if (fabs(g->migration_mm_per_rad) > 1e-9 * P) {
		snprintf(ptr, sizeof ptr, "%s/geometry/nut_radius_mm", base);
		return prsm_error_set(err, PRSM_EINVAL, ptr,
		                      "r_n = %g mm differs from n r_r = %g mm: roller and nut helix angles "
		                      "differ, and rollers drift axially by %.4g mm per carrier radian; the "
		                      "rigid-body dynamics needs rolling nut contacts (docs/model §8.1)",
		                      rn, d->starts * rr, g->migration_mm_per_rad);
	}
	const double i_g = rn / rr, r_g1 = a / (i_g - 1.0);
	const prsm_contact *sc = &an->screw, *nc = &an->nut;
	if (fabs(nc->x_mm - (a + r_g1)) > 1e-6 || fabs(nc->y_mm) > 1e-6) {
		snprintf(ptr, sizeof ptr, "%s/geometry/nut_radius_mm", base);
		return prsm_error_set(err, PRSM_EINVAL, ptr,
		                      "the nut contact (%.6g, %.6g) mm is not at the ring-gear pitch point "
		                      "(%.6g, 0) mm (r_n differs from r_s + 2 r_r): it would slip; the rigid-body "
		                      "dynamics needs rolling nut contacts (docs/model §8.1)",
		                      nc->x_mm, nc->y_mm, a + r_g1);
	}
	par->rollers = d->rollers;
	par->lead_mm = prsm_design_lead_mm(d);
	par->ring_gear_ratio = i_g;
	par->gear_pitch_radius_mm = r_g1;
	par->orbit_radius_mm = a;
	par->carrier_ratio_statics = an->kinematics.carrier_ratio;
	/* docs/model §8.0: the statics contact is the upper flank (normal out of the screw tooth);
	 * the lower flank is its image under the half-turn about x */
	const double p_up[3] = {sc->x_mm, sc->y_mm, 0.0}, pn_up[3] = {nc->x_mm, nc->y_mm, 0.0};
	double n_up[3], nn_up[3];
	cylindrical_to_cartesian(n_up, sc->normal, sc->x_mm, sc->y_mm);
	cylindrical_to_cartesian(nn_up, nc->normal, nc->x_mm, nc->y_mm);
	memcpy(par->contact_mm[0], p_up, sizeof p_up);
	memcpy(par->normal[0], n_up, sizeof n_up);
	memcpy(par->nut_contact_mm[0], pn_up, sizeof pn_up);
	memcpy(par->nut_normal[0], nn_up, sizeof nn_up);
	half_turn(par->contact_mm[1], p_up);
	half_turn(par->normal[1], n_up);
	half_turn(par->nut_contact_mm[1], pn_up);
	half_turn(par->nut_normal[1], nn_up);
	for (int fl = 0; fl < 2; fl++) {
		prsm_kinematics_slip_basis(par->A_mm[fl], par->B_mm[fl], d, par->contact_mm[fl][0],
		                           par->contact_mm[fl][1], i_g);
		par->normal_dot_A_mm[fl] = dot3(par->normal[fl], par->A_mm[fl]);
		par->normal_dot_B_mm[fl] = dot3(par->normal[fl], par->B_mm[fl]);
		for (int i = 0; i < 3; i++) {
			st->p[fl][i] = par->contact_mm[fl][i] * MM;
			st->n[fl][i] = par->normal[fl][i];
			st->pn[fl][i] = par->nut_contact_mm[fl][i] * MM;
			st->nn[fl][i] = par->nut_normal[fl][i];
			st->A[fl][i] = par->A_mm[fl][i] * MM;
			st->B[fl][i] = par->B_mm[fl][i] * MM;
		}
	}
	/* docs/model §8.1 item 6 */
	const double *A = par->A_mm[PRSM_DYN_FLANK_LOWER], *B = par->B_mm[PRSM_DYN_FLANK_LOWER];
	par->carrier_ratio_min_slip = prsm_kinematics_min_slip_ratio(A, B);
	double vmin[3];
	for (int i = 0; i < 3; i++)
		vmin[i] = B[i] + par->carrier_ratio_min_slip * A[i];
	par->min_slip_mm_per_rad = sqrt(dot3(vmin, vmin));
	st->B_norm = sqrt(dot3(st->B[PRSM_DYN_FLANK_LOWER], st->B[PRSM_DYN_FLANK_LOWER]));
	par->mu = isnan(o->friction.mu) ? d->mu_screw_roller : o->friction.mu;
	par->static_mu = isnan(o->friction.static_mu) ? par->mu : o->friction.static_mu;
	if (!finite_nonneg(par->mu)) {
		snprintf(ptr, sizeof ptr, "%s/friction/screw_roller", base);
		return prsm_error_set(err, PRSM_EINVAL, ptr, "stage %d: the screw-roller mu must be >= 0 (got %g)",
		                      k + 1, par->mu);
	}
	par->gear_pressure_angle_rad = d->losses.gear_pressure_angle_rad;

	/* docs/model §8.2.2: solid steel unless overridden */
	const prsm_dyn_stage_inertia *ov = &o->inertia.stage[k];
	const double rho = o->inertia.density_kg_m3;
	const double rs_m = rs * MM, rr_m = rr * MM, rn_m = rn * MM;
	par->gear_face_width_mm = pick(ov->gear_face_width_mm, 2.0 * P);
	par->roller_length_mm = d->engaged_threads * P + 2.0 * par->gear_face_width_mm;
	const double lR = par->roller_length_mm * MM;
	const double rno = (isnan(d->nut_outer_radius_mm) ? DEFAULT_NUT_OUTER_PER_RN * rn : d->nut_outer_radius_mm) * MM;
	par->roller_mass_kg = pick(ov->roller_mass_kg, rho * M_PI * rr_m * rr_m * lR);
	par->roller_inertia_kg_m2 = pick(ov->roller_inertia_kg_m2, 0.5 * par->roller_mass_kg * rr_m * rr_m);
	par->carrier_mass_kg = pick(ov->carrier_mass_kg, 2.0 * rho * M_PI * (rn_m * rn_m - rs_m * rs_m) * P * MM);
	par->carrier_inertia_kg_m2 = pick(ov->carrier_inertia_kg_m2,
	                                  0.5 * par->carrier_mass_kg * (rn_m * rn_m + rs_m * rs_m));
	par->nut_mass_kg = pick(ov->nut_mass_kg, rho * M_PI * (rno * rno - rn_m * rn_m) * lR);
	par->screw_mass_kg = pick(ov->screw_mass_kg, rho * M_PI * rs_m * rs_m * (lR + o->inertia.stroke_mm * MM));
	par->screw_inertia_kg_m2 = pick(ov->screw_inertia_kg_m2, 0.5 * par->screw_mass_kg * rs_m * rs_m);
	const double Z = d->rollers, a_m = a * MM;
	par->carrier_side_inertia_kg_m2 =
		par->carrier_inertia_kg_m2 +
		Z * (par->roller_mass_kg * a_m * a_m + par->roller_inertia_kg_m2 * (1.0 - i_g) * (1.0 - i_g));
	par->axial_mass_kg = par->nut_mass_kg + Z * par->roller_mass_kg + par->carrier_mass_kg +
	                     (k == m->stages - 1 ? o->inertia.payload_kg : 0.0);
	if (!(par->carrier_side_inertia_kg_m2 > 0.0)) {
		snprintf(ptr, sizeof ptr, "/dynamics/inertia%s", m->stages > 1 ? "/stages" : "");
		return prsm_error_set(err, PRSM_EINVAL, ptr, "stage %d: the carrier side has no inertia (J_psi = "
		                      "0): give the carrier or the rollers a mass", k + 1);
	}
	st->a = a_m;
	st->r_g = r_g1 * MM;
	st->i_g = i_g;
	st->Z = Z;
	st->mu = par->mu;
	st->mu_s = par->static_mu;
	st->tan_alpha = tan(par->gear_pressure_angle_rad);
	st->cos_alpha = cos(par->gear_pressure_angle_rad);
	st->m_R = par->roller_mass_kg;
	st->J_R = par->roller_inertia_kg_m2;
	st->m_C = par->carrier_mass_kg;
	st->J_C = par->carrier_inertia_kg_m2;
	st->m_S = par->screw_mass_kg;
	st->J_S = par->screw_inertia_kg_m2;
	st->J_psi = par->carrier_side_inertia_kg_m2;
	st->M_axial = par->axial_mass_kg;
	st->threads = d->engaged_threads;

	/* docs/model §7, §8.2.3: couplings of stage k >= 1, radii as the statics chain */
	const prsm_dyn_couplings *c = &o->couplings;
	const double lead_m = par->lead_mm * MM / (2.0 * M_PI);
	st->lambda = (k > 0 ? m->stage[k - 1].lambda : 0.0) + lead_m;
	par->cumulative_lead_m_per_rad = st->lambda;
	if (k > 0) {
		const prsm_design *prev = &designs[k - 1];
		st->lambda_prev = m->stage[k - 1].lambda;
		st->lead_prev = prsm_design_lead_mm(prev) * MM / (2.0 * M_PI);
		par->spline_radius_mm = pick(c->spline_radius_mm[k], prev->screw_radius_mm);
		par->thrust_radius_mm = pick(c->thrust_radius_mm[k], 0.5 * (prev->nut_radius_mm + rs));
		st->r_SS = par->spline_radius_mm * MM;
		st->r_NS = par->thrust_radius_mm * MM;
		const double lock = c->spline_friction * c->thrust_bearing_friction * st->r_NS / st->r_SS;
		if (!(lock < 1.0))
			return prsm_error_set(err, PRSM_EINVAL, "/couplings",
			                      "stage %d: the spline and thrust bearing lock (mu_NS mu_SS r_NS / r_SS "
			                      "= %g >= 1)", k + 1, lock);
	}

	/* the statics engine's view with the model's mu */
	st->design = *d;
	st->design.mu_screw_roller = par->mu;
	st->analysis = *an;
	prsm_efficiency eff;
	prsm_efficiency_sliding(&eff, &st->design, &an->kinematics, &an->screw, &an->nut);
	st->eta_slide = eff.eta;
	if (o->losses == PRSM_DYN_LOSSES_STATICS) {
		prsm_losses_options_from_design(&st->loss_options, &st->design);
		prsm_losses_prepare(&st->loss_nominal, &st->design, &an->screw, &an->nut, &st->loss_options);
		/* a probe at no load reports what the losses refuse (teeth, Hertz) here, not mid-run */
		prsm_losses_result r;
		prsm_design probe = st->design;
		probe.axial_load_N = 0.0;
		probe.screw_speed_rad_s = 0.0;
		int rc = prsm_losses_compute_prepared(&r, &st->loss_nominal, &probe, &an->kinematics, &an->screw,
		                                      &an->nut, NULL, NULL, &st->loss_options, err);
		if (rc)
			return rc;
	}
	return 0;
}

/* Stage torque of the statics chain (model/stages.h): with every loss and the load distribution
 * (losses STATICS), or from the sliding efficiency. */
typedef struct {
	const prsm_dyn_model *m;
	double speed_rad_s;
} statics_ctx;

static double statics_stage_torque(void *ctx, int k, double load_N)
{
	const statics_ctx *c = ctx;
	const dyn_stage *st = &c->m->stage[k];
	if (c->m->opts.losses == PRSM_DYN_LOSSES_STATICS) {
		prsm_design d = st->design;
		d.axial_load_N = load_N;
		d.screw_speed_rad_s = c->speed_rad_s;
		return prsm_performance_input_torque(&d, &st->analysis);
	}
	if (!(st->eta_slide > 0.0))
		return NAN;
	return load_N * st->par.lead_mm * MM / (2.0 * M_PI * st->eta_slide);
}

int dyn_statics_chain(prsm_chain *out, const prsm_dyn_model *m, double load_N, double speed_rad_s,
                      prsm_error *err)
{
	prsm_chain_input in;
	memset(&in, 0, sizeof in);
	in.stages = m->stages;
	in.spline_friction = m->opts.couplings.spline_friction;
	in.thrust_bearing_friction = m->opts.couplings.thrust_bearing_friction;
	in.axial_load_N = load_N;
	in.screw_speed_rad_s = speed_rad_s;
	for (int k = 0; k < m->stages; k++) {
		in.lead_mm[k] = m->stage[k].par.lead_mm;
		in.spline_radius_mm[k] = k > 0 ? m->stage[k].par.spline_radius_mm : 0.0;
		in.thrust_radius_mm[k] = k > 0 ? m->stage[k].par.thrust_radius_mm : 0.0;
	}
	statics_ctx ctx = {m, speed_rad_s};
	return prsm_stages_chain(out, &in, statics_stage_torque, &ctx, err);
}

/* The final value of a signal (sine: its mean). */
static double final_value(const prsm_dyn_signal *s)
{
	return s->value;
}

/* losses STATICS (docs/model §8.2.3): each stage's loss torques at its statics chain load with
 * the load distribution there, split as dyn_internal.h says (the shape they scale with during
 * the run). */
static int loss_references(prsm_dyn_model *m, prsm_error *err)
{
	const double F = fabs(final_value(&m->opts.load));
	const double w = m->opts.input.kind == PRSM_DYN_INPUT_SPEED ? fabs(final_value(&m->opts.input.signal)) : 0.0;
	prsm_chain chain;
	double *loads = NULL;
	int rc = dyn_statics_chain(&chain, m, F, w, err);
	for (int k = 0; k < m->stages && rc == 0; k++) {
		dyn_stage *st = &m->stage[k];
		const int nt = st->threads;
		const double Fk = chain.stage[k].load_N;
		prsm_design d = st->design;
		st->par.loss_reference_load_N = Fk;
		d.screw_speed_rad_s = 0.0;
		const double *ls = NULL, *ln = NULL;
		if (Fk > 0.0) {
			free(loads);
			loads = calloc((size_t)(2 * nt), sizeof(double));
			if (loads == NULL) {
				rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the loss model");
				break;
			}
			d.axial_load_N = Fk;
			if ((rc = prsm_performance_normal_loads(loads, loads + nt, &d, &st->analysis, err)))
				break;
			ls = loads;
			ln = loads + nt;
		} else {
			d.axial_load_N = 1.0; /* the equal share, proportional to the load */
		}
		st->loss_scale_load_N = d.axial_load_N;
		prsm_losses_result r;
		if ((rc = prsm_losses_compute_prepared(&r, &st->loss_nominal, &d, &st->analysis.kinematics,
		                                       &st->analysis.screw, &st->analysis.nut, ls, ln,
		                                       &st->loss_options, err)))
			break;
		st->loss_spin_Nm = r.spin_torque_Nm;
		st->loss_moment_lin_Nm = r.roller_moment_friction_Nm + r.roller_moment_helix_Nm;
		st->loss_moment_spin_Nm = r.roller_moment_spin_Nm;
		st->loss_gear_per_moment = r.roller_moment_Nm != 0.0 ? r.gear_torque_Nm / fabs(r.roller_moment_Nm) : 0.0;
		st->loss_constant_Nm = r.drag_torque_Nm + r.seal_torque_Nm;
		st->loss_viscous_Nm_s = st->loss_options.viscous_drag_Nm_s_per_rad;
	}
	free(loads);
	return rc;
}

int prsm_dyn_model_new(prsm_dyn_model **out, int stages, const prsm_design *designs,
                       const prsm_analysis *analyses, const prsm_dyn_options *opts, prsm_error *err)
{
	*out = NULL;
	if (stages < 1 || stages > PRSM_DYN_STAGES_MAX)
		return prsm_error_set(err, PRSM_EINVAL, "/stages", "a chain has 1 to %d stages (got %d)",
		                      PRSM_DYN_STAGES_MAX, stages);
	prsm_dyn_options defaults;
	prsm_dyn_options_init(&defaults);
	if (opts == NULL)
		opts = &defaults;
	prsm_problems problems;
	prsm_problems_init(&problems);
	if (prsm_dyn_options_check(opts, stages, &problems))
		return prsm_error_set(err, PRSM_EINVAL, problems.items[0].pointer, "%s%s",
		                      problems.items[0].message,
		                      prsm_problems_total(&problems) > 1 ? " (and more problems)" : "");
	prsm_dyn_model *m = calloc(1, sizeof *m);
	if (m == NULL)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the dynamics model");
	m->stages = stages;
	m->opts = *opts;
	m->hand = designs[0].hand == PRSM_HAND_LEFT ? -1.0 : 1.0;
	int rc = 0;
	for (int k = 0; k < stages && rc == 0; k++)
		rc = stage_build(m, k, designs, analyses, err);
	if (rc)
		goto fail;
	/* docs/model §8.2.2: J_theta = J_M + sum [J_S,k + M_k Lambda_k^2] + sum_{k>=1} m_S,k Lambda_{k-1}^2 */
	m->J_theta = opts->input.motor_inertia_kg_m2;
	for (int k = 0; k < stages; k++) {
		const dyn_stage *st = &m->stage[k];
		m->J_theta += st->J_S + st->M_axial * st->lambda * st->lambda + st->m_S * st->lambda_prev * st->lambda_prev;
	}
	m->lambda_K = m->stage[stages - 1].lambda;
	const double v_eps_rad_s = opts->friction.smoothing_velocity_m_s / m->stage[0].B_norm;
	m->stick_band_rad_s = isnan(opts->friction.stick_band_rad_s) ? 10.0 * v_eps_rad_s : opts->friction.stick_band_rad_s;
	m->stiff_switch_rad_s = isnan(opts->time.stiff_switch_rad_s) ? 100.0 * v_eps_rad_s : opts->time.stiff_switch_rad_s;
	if (opts->losses == PRSM_DYN_LOSSES_STATICS && (rc = loss_references(m, err)))
		goto fail;
	if ((rc = dyn_settle(m, err)))
		goto fail;
	*out = m;
	return 0;
fail:
	prsm_dyn_model_free(m);
	return rc;
}

void prsm_dyn_model_free(prsm_dyn_model *m)
{
	if (m == NULL)
		return;
	free(m);
}

int prsm_dyn_model_stages(const prsm_dyn_model *m)
{
	return m->stages;
}

const prsm_dyn_stage_params *prsm_dyn_model_stage(const prsm_dyn_model *m, int k)
{
	return k >= 0 && k < m->stages ? &m->stage[k].par : NULL;
}

const prsm_dyn_options *prsm_dyn_model_options(const prsm_dyn_model *m)
{
	return &m->opts;
}

double prsm_dyn_model_screw_side_inertia(const prsm_dyn_model *m)
{
	return m->J_theta;
}

const prsm_dyn_settled *prsm_dyn_model_settled(const prsm_dyn_model *m)
{
	return &m->settled;
}

int prsm_dyn_evaluate(prsm_dyn_point *point, prsm_dyn_stage_point *stage, const prsm_dyn_model *m,
                      const prsm_dyn_state *state, prsm_error *err)
{
	dyn_scratch s;
	dyn_scratch_init(&s, m);
	s.detail = 1;
	dyn_motion mo = {state->time_s, state->screw_angle_rad, state->screw_speed_rad_s,
	                 state->screw_accel_rad_s2, state->carrier_angle_rad, state->carrier_speed_rad_s};
	int rc;
	if (m->opts.input.kind == PRSM_DYN_INPUT_SPEED) {
		double th, thd, thdd;
		dyn_speed_input(m, state->time_s, &th, &thd, &thdd);
		if (isnan(mo.theta))
			mo.theta = th;
		if (isnan(mo.theta_dot))
			mo.theta_dot = thd;
		if (isnan(mo.theta_ddot))
			mo.theta_ddot = thdd;
		rc = dyn_eval_motion(m, &s, &mo, point, stage, err);
	} else if (isnan(mo.theta_ddot)) {
		rc = dyn_eval_torque(m, &s, &mo, point, stage, err);
	} else {
		rc = dyn_eval_motion(m, &s, &mo, point, stage, err);
	}
	return rc;
}

int prsm_dyn_breakaway_torques(double *forward_Nm, double *backward_Nm, const prsm_dyn_model *m,
                               double t_s, prsm_error *err)
{
	dyn_scratch s;
	dyn_scratch_init(&s, m);
	return dyn_breakaway(forward_Nm, backward_Nm, m, &s, t_s, err);
}
