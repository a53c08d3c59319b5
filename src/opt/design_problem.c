/*
 * design_problem.c: the PRSM design problem of design_problem.h: variables to a design by the
 * standard rules (docs/model/geometry-and-meshing.md), the design through the nominal and operating-point analyses
 * (§2, §5, §6), objectives and scaled constraints, and the cheap bounds that prune integer
 * combinations.
 */
#include "opt/design_problem.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model/compliance.h"
#include "model/geometry.h"

const char *const prsm_dp_objective_names[] = {"efficiency", "stiffness_N_per_um", "mass_kg",
                                                "reflected_inertia_kg_m2", NULL};
static const int objective_sense[] = {PRSM_OPT_MAXIMISE, PRSM_OPT_MAXIMISE, PRSM_OPT_MINIMISE,
                                      PRSM_OPT_MINIMISE};

const char *const prsm_dp_constraint_names[] = {
	"analysable", "roller_fit", "standard_rules", "nut_outer_diameter_mm",
	"screw_diameter_min_mm", "screw_diameter_max_mm", "static_safety", "life_h",
	"life_revolutions", "p_max_MPa", "critical_speed_ratio", NULL};
/* +1: the value must not exceed the limit; -1: must not fall below it */
static const int constraint_side[] = {1, 1, 1, 1, -1, 1, -1, -1, -1, 1, -1};

#define RAD_PER_DEG (M_PI / 180.0)
#define RPM_PER_RAD_S (60.0 / (2.0 * M_PI))

void prsm_dp_spec_init(prsm_dp_spec *s, const prsm_design *base)
{
	memset(s, 0, sizeof *s);
	s->base = *base;
	s->nut_outer_diameter_max_mm = NAN;
	s->screw_diameter_min_mm = s->screw_diameter_max_mm = NAN;
	s->static_safety_min = NAN;
	s->life_min_h = s->life_min_revolutions = NAN;
	s->p_max_max_MPa = NAN;
	s->critical_speed_factor_min = NAN;
	s->standard_rules = 1;
}

/* Index of each continuous variable in x (-1 when fixed): pitch, radius, flank. */
static void continuous_index(const prsm_dp_spec *s, int idx[3])
{
	int n = 0;
	idx[0] = s->pitch.vary ? n++ : -1;
	idx[1] = s->radius.vary ? n++ : -1;
	idx[2] = s->flank_deg.vary ? n++ : -1;
}

/* Index of each discrete variable in levels (-1 when fixed): starts, rollers, threads, and the
 * pitch (or lead) when it takes a list of values. */
static void discrete_index(const prsm_dp_spec *s, int idx[4])
{
	int n = 0;
	idx[0] = s->starts.count ? n++ : -1;
	idx[1] = s->rollers.count ? n++ : -1;
	idx[2] = s->threads.count ? n++ : -1;
	idx[3] = s->n_pitch_values ? n++ : -1;
}

void prsm_dp_design_at(prsm_design *out, const prsm_dp_spec *s, const double *x,
                       const double *levels)
{
	int ci[3], di[4];
	continuous_index(s, ci);
	discrete_index(s, di);
	const prsm_design *b = &s->base;
	*out = *b;
	int n = di[0] >= 0 ? (int)levels[di[0]] : b->starts;
	out->starts = n;
	if (di[1] >= 0)
		out->rollers = (int)levels[di[1]];
	if (di[2] >= 0)
		out->engaged_threads = (int)levels[di[2]];
	/* pitch, or lead L = n P (docs/model/geometry-and-meshing.md) */
	if (ci[0] >= 0)
		out->pitch_mm = s->pitch_is_lead ? x[ci[0]] / n : x[ci[0]];
	else if (di[3] >= 0) /* one of the allowed values */
		out->pitch_mm = s->pitch_is_lead ? levels[di[3]] / n : levels[di[3]];
	else if (s->pitch_is_lead)
		out->pitch_mm = b->pitch_mm * b->starts / n; /* the base lead kept */
	if (ci[2] >= 0)
		out->flank_angle_rad = x[ci[2]] * RAD_PER_DEG;
	/* radii by the standard rule r_s = (n - 2) r_r; everything derived is recomputed */
	double rr = b->roller_radius_mm;
	if (ci[1] >= 0)
		rr = s->radius_is_screw ? x[ci[1]] / (n - 2) : x[ci[1]];
	out->roller_radius_mm = rr;
	out->screw_radius_mm = out->nut_radius_mm = out->roller_arc_radius_mm = NAN;
	out->screw_crest_radius_mm = out->screw_root_radius_mm = NAN;
	out->roller_crest_radius_mm = out->roller_root_radius_mm = NAN;
	out->nut_crest_radius_mm = out->nut_root_radius_mm = NAN;
}

/* Nut-unit mass (kg) and the inertia reflected to the screw (kg m^2); see the header. */
static void mass_inertia(double *mass_kg, double *inertia_kg_m2, const prsm_design *d)
{
	const double mm3 = 1e-9, mm = 1e-3; /* m^3 per mm^3, m per mm */
	double length_mm = d->engaged_threads * d->pitch_mm;
	double ro = prsm_compliance_nut_outer_radius_mm(d->nut_outer_radius_mm, d);
	double rn = d->nut_radius_mm, rr = d->roller_radius_mm, rs = d->screw_radius_mm;
	double m_nut = d->nut_material.density_kg_m3 * M_PI * (ro * ro - rn * rn) * length_mm * mm3;
	double m_roller = d->roller_material.density_kg_m3 * M_PI * rr * rr * length_mm * mm3;
	*mass_kg = m_nut + d->rollers * m_roller;
	double screw_length_mm = d->life.column ? d->life.free_length_mm : length_mm;
	double rs_m = rs * mm;
	double j_screw = 0.5 * d->screw_material.density_kg_m3 * M_PI * rs_m * rs_m * rs_m * rs_m *
	                 screw_length_mm * mm;
	double lead_per_rad_m = prsm_design_lead_mm(d) * mm / (2.0 * M_PI);
	double a_m = (rs + rr) * mm, kc = rs / (2.0 * (rs + rr)); /* docs/model/kinematics-efficiency-stiffness-life.md */
	double spin = (1.0 - d->starts) * kc;
	double j_rollers = d->rollers * m_roller *
	                   (a_m * a_m * kc * kc + 0.5 * rr * mm * rr * mm * spin * spin);
	*inertia_kg_m2 = j_screw + *mass_kg * lead_per_rad_m * lead_per_rad_m + j_rollers;
}

static int fail(prsm_dp_figures *fig, int rc, const char *detail)
{
	fig->analysable = 0;
	snprintf(fig->failure, sizeof fig->failure, "%s", detail);
	return rc;
}

int prsm_dp_analyse(prsm_dp_figures *fig, prsm_design *d, const prsm_dp_spec *s, int full,
                    prsm_analysis *a, prsm_performance *perf)
{
	prsm_analysis a_local;
	prsm_performance p_local;
	prsm_analysis *an = a ? a : &a_local;
	prsm_performance *pf = perf ? perf : &p_local;
	memset(pf, 0, sizeof *pf);
	int rc = 0;
	for (int k = 0; k < PRSM_DP_OBJECTIVE_KINDS; k++)
		fig->objective[k] = NAN;
	for (int k = 0; k < PRSM_DP_CONSTRAINT_KINDS; k++)
		fig->constraint_value[k] = NAN;
	fig->analysable = 1;
	fig->failure[0] = '\0';
	fig->z_max = 0;
	fig->roller_fit = NAN;
	fig->rule_warnings = 0;
	fig->nut_outer_diameter_mm = fig->screw_diameter_mm = NAN;
	fig->static_safety = fig->life_h = fig->life_revolutions = fig->p_max_MPa = NAN;
	fig->critical_speed_rpm = fig->critical_speed_ratio = NAN;
	fig->operating_speed_rpm = d->screw_speed_rad_s * RPM_PER_RAD_S;
	if (!full)
		d->stiffness.curve_points = 0;

	prsm_problems errors, warnings;
	prsm_problems_init(&errors);
	prsm_problems_init(&warnings);
	if (prsm_design_resolve(d, &errors)) {
		rc = fail(fig, PRSM_EINVAL, errors.items[0].message);
		goto cleanup;
	}
	prsm_geometry g;
	prsm_geometry_check(&g, &warnings, &errors, d);
	fig->z_max = g.z_max;
	fig->rule_warnings = warnings.count + warnings.dropped;
	double sfit = (d->roller_crest_radius_mm + 0.5 * d->running_clearance_mm) / g.orbit_radius_mm;
	if (sfit > 0.0)
		fig->roller_fit = d->rollers * asin(fmin(sfit, 1.0)) / M_PI; /* docs/model/geometry-and-meshing.md: Z <= Z_max */
	fig->screw_diameter_mm = 2.0 * d->screw_radius_mm;
	fig->nut_outer_diameter_mm = 2.0 * prsm_compliance_nut_outer_radius_mm(d->nut_outer_radius_mm, d);
	for (int i = 0; i < errors.count; i++)
		if (strcmp(errors.items[i].code, "z_max") != 0) {
			/* the roller fit is a constraint of its own; any other error is fatal */
			rc = fail(fig, PRSM_EGEOMETRY, errors.items[i].message);
			goto cleanup;
		}
	prsm_error err = PRSM_ERROR_INIT;
	prsm_problems_init(&errors);
	rc = prsm_analysis_nominal(an, d, &errors, &err);
	if (rc) {
		fail(fig, rc, err.message);
		goto cleanup;
	}
	rc = prsm_performance_compute(pf, d, an, &err);
	if (rc) {
		fail(fig, rc, err.message);
		goto cleanup;
	}
	fig->objective[PRSM_DP_EFFICIENCY] = pf->losses.eta;
	fig->objective[PRSM_DP_STIFFNESS] = pf->stiffness_N_per_um;
	mass_inertia(&fig->objective[PRSM_DP_MASS], &fig->objective[PRSM_DP_INERTIA], d);
	fig->static_safety = pf->static_safety;
	fig->life_h = pf->life.hours;
	fig->life_revolutions = pf->life.revolutions;
	fig->p_max_MPa = fmax(pf->dist.side[0].p_max_MPa, pf->dist.side[1].p_max_MPa);
	if (pf->has_column) {
		fig->critical_speed_rpm = pf->column.critical_speed_rpm;
		fig->critical_speed_ratio = fig->operating_speed_rpm > 0.0
		                                ? fig->critical_speed_rpm / fig->operating_speed_rpm
		                                : INFINITY;
	}
cleanup:
	fig->constraint_value[PRSM_DP_C_ANALYSABLE] = fig->analysable ? 0.0 : 1.0;
	fig->constraint_value[PRSM_DP_C_ROLLER_FIT] = fig->roller_fit;
	fig->constraint_value[PRSM_DP_C_STANDARD_RULES] = fig->rule_warnings;
	fig->constraint_value[PRSM_DP_C_NUT_OUTER_DIAMETER] = fig->nut_outer_diameter_mm;
	fig->constraint_value[PRSM_DP_C_SCREW_DIAMETER_MIN] = fig->screw_diameter_mm;
	fig->constraint_value[PRSM_DP_C_SCREW_DIAMETER_MAX] = fig->screw_diameter_mm;
	fig->constraint_value[PRSM_DP_C_STATIC_SAFETY] = fig->static_safety;
	fig->constraint_value[PRSM_DP_C_LIFE_HOURS] = fig->life_h;
	fig->constraint_value[PRSM_DP_C_LIFE_REVOLUTIONS] = fig->life_revolutions;
	fig->constraint_value[PRSM_DP_C_P_MAX] = fig->p_max_MPa;
	fig->constraint_value[PRSM_DP_C_CRITICAL_SPEED] = fig->critical_speed_ratio;
	if (!perf)
		prsm_performance_free(pf);
	return rc;
}

/* Scaled violation of constraint kind with limit at value v (feasible when <= 0). */
static double scaled(int kind, double limit, double v)
{
	if (kind == PRSM_DP_C_ANALYSABLE || kind == PRSM_DP_C_STANDARD_RULES)
		return v > 0.0 ? v : -1.0; /* pass/fail: -1 when met (optimize.h), else 1 or the count */
	if (isnan(v))
		return NAN;
	if (isinf(v))
		return constraint_side[kind] > 0 ? (v > 0 ? 1.0 : -1.0) : (v > 0 ? -1.0 : 1.0);
	return constraint_side[kind] * (v - limit) / fabs(limit);
}

double prsm_dp_violation(const prsm_dp_spec *s, int i, const prsm_dp_figures *fig, int rollers)
{
	const int kind = s->constraint_kind[i];
	double g = scaled(kind, s->constraint_limit[i], fig->constraint_value[kind]);
	if (kind == PRSM_DP_C_ROLLER_FIT && fig->z_max > 0) {
		/* Z_max is an integer: the floor decides (docs/model/geometry-and-meshing.md), the smooth value only steers */
		if (rollers > fig->z_max)
			g = g > 1e-3 ? g : 1e-3;
		else
			g = g < 0.0 ? g : 0.0;
	} else if (kind == PRSM_DP_C_ROLLER_FIT && rollers > fig->z_max && !(g > 1e-3)) {
		g = 1e-3; /* no Z_max at all: nothing fits */
	}
	return g;
}

int prsm_dp_robust(prsm_robust_eval *out, const prsm_dp_spec *s, const prsm_design *d,
                   const double *g_det, prsm_error *err)
{
	prsm_robust *r = s->robust;
	for (int i = 0; i < s->n_constraints; i++)
		if (!(g_det[i] <= s->robust_gate_tol)) {
			memset(out, 0, sizeof *out);
			snprintf(out->failure, sizeof out->failure, "not run: the constraint %s does not hold",
			         prsm_dp_constraint_names[s->constraint_kind[i]]);
			for (int k = 0; k < r->n; k++) {
				out->v[k].yield = out->v[k].smooth_yield = NAN;
				out->v[k].g = out->v[k].g_solver = 1.0;
			}
			return 0;
		}
	return prsm_robust_evaluate(out, r, d, err);
}

static int dp_eval(void *ctx, const double *x, const double *levels, double *f, double *g,
                   double *gf, double *gg)
{
	(void)gf;
	(void)gg;
	const prsm_dp_spec *s = ctx;
	prsm_design d;
	prsm_dp_figures fig;
	prsm_dp_design_at(&d, s, x, levels);
	prsm_design unresolved = d;
	int rc = prsm_dp_analyse(&fig, &d, s, 0, NULL, NULL);
	for (int k = 0; k < s->n_objectives; k++)
		f[k] = fig.objective[s->objective[k]];
	for (int i = 0; i < s->n_constraints; i++)
		g[i] = prsm_dp_violation(s, i, &fig, d.rollers);
	if (s->robust) {
		/* the problem has a surrogate: g holds the checked values, then the solver's */
		const int nd = s->n_constraints, nc = nd + s->robust->n;
		for (int i = 0; i < nd; i++)
			g[nc + i] = g[i];
		prsm_robust_eval re;
		prsm_error err = PRSM_ERROR_INIT;
		int rrc = rc ? 0 : prsm_dp_robust(&re, s, &unresolved, g, &err);
		for (int k = 0; k < s->robust->n; k++) {
			g[nd + k] = rc || rrc ? 1.0 : re.v[k].g;
			g[nc + nd + k] = rc || rrc ? 1.0 : re.v[k].g_solver;
		}
		if (rrc && !rc)
			rc = rrc;
	}
	return rc;
}

/* Screw pitch radius, nut outer radius and Z_max of the design at one corner of the box. */
static void corner(const prsm_dp_spec *s, int starts, int mask, double *rs, double *ro, int *z_max)
{
	int ci[3], di[4];
	continuous_index(s, ci);
	discrete_index(s, di);
	double x[PRSM_OPT_MAX_CONTINUOUS] = {0};
	const prsm_dp_range *r[3] = {&s->pitch, &s->radius, &s->flank_deg};
	for (int v = 0; v < 3; v++)
		if (ci[v] >= 0)
			x[ci[v]] = (mask >> v) & 1 ? r[v]->max : r[v]->min;
	double lv[PRSM_OPT_MAX_DISCRETE] = {0};
	for (int v = 0; v < 3; v++)
		if (di[v] >= 0)
			lv[di[v]] = v == 0 ? starts : 1;
	if (di[3] >= 0) /* the list's ends bracket it as the range's do */
		lv[di[3]] = mask & 1 ? s->pitch_values[s->n_pitch_values - 1] : s->pitch_values[0];
	prsm_design d;
	prsm_dp_design_at(&d, s, x, lv);
	d.starts = starts;
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_design_resolve(&d, &e);
	*rs = d.screw_radius_mm;
	*ro = prsm_compliance_nut_outer_radius_mm(d.nut_outer_radius_mm, &d);
	*z_max = prsm_geometry_z_max(d.roller_crest_radius_mm, d.running_clearance_mm,
	                             d.screw_radius_mm + d.roller_radius_mm);
}

int prsm_dp_z_max_bound(const prsm_dp_spec *s, int starts)
{
	int best = 0;
	for (int mask = 0; mask < 8; mask++) {
		double rs, ro;
		int z;
		corner(s, starts, mask, &rs, &ro, &z);
		if (z > best)
			best = z;
	}
	return best;
}

/* Every bound used is monotone in the radii and the pitch, so the box's corners bracket it. */
static int dp_prune(void *ctx, const double *levels, const double *lower, const double *upper)
{
	(void)lower;
	(void)upper;
	const prsm_dp_spec *s = ctx;
	int di[4];
	discrete_index(s, di);
	int starts = di[0] >= 0 ? (int)levels[di[0]] : s->base.starts;
	int rollers = di[1] >= 0 ? (int)levels[di[1]] : s->base.rollers;
	double rs_min = INFINITY, rs_max = -INFINITY, ro_min = INFINITY;
	int z_best = 0;
	for (int mask = 0; mask < 8; mask++) {
		double rs, ro;
		int z;
		corner(s, starts, mask, &rs, &ro, &z);
		rs_min = fmin(rs_min, rs);
		rs_max = fmax(rs_max, rs);
		ro_min = fmin(ro_min, ro);
		if (z > z_best)
			z_best = z;
	}
	if (rollers > z_best)
		return 1;
	if (!isnan(s->screw_diameter_min_mm) && 2.0 * rs_max < s->screw_diameter_min_mm)
		return 1;
	if (!isnan(s->screw_diameter_max_mm) && 2.0 * rs_min > s->screw_diameter_max_mm)
		return 1;
	if (!isnan(s->nut_outer_diameter_max_mm) && 2.0 * ro_min > s->nut_outer_diameter_max_mm)
		return 1;
	return 0;
}

static void add_constraint(prsm_dp_spec *s, int kind, double limit)
{
	s->constraint_kind[s->n_constraints] = kind;
	s->constraint_limit[s->n_constraints] = limit;
	s->n_constraints++;
}

static int add_range(prsm_opt_problem *p, const prsm_dp_range *r, const char *name, prsm_error *err)
{
	if (!r->vary)
		return 0;
	if (!(isfinite(r->min) && isfinite(r->max) && r->min < r->max))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: the range [%g, %g] is empty", name,
		                      r->min, r->max);
	int j = p->n_continuous++;
	snprintf(p->continuous_name[j], PRSM_OPT_NAME_MAX, "%s", name);
	p->lower[j] = r->min;
	p->upper[j] = r->max;
	return 0;
}

static int add_set(prsm_opt_problem *p, const prsm_dp_set *set, const char *name, prsm_error *err)
{
	if (set->count == 0)
		return 0;
	if (set->count < 0 || set->count > PRSM_OPT_MAX_LEVELS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: 1..%d values", name, PRSM_OPT_MAX_LEVELS);
	int d = p->n_discrete++;
	snprintf(p->discrete_name[d], PRSM_OPT_NAME_MAX, "%s", name);
	p->n_levels[d] = set->count;
	for (int i = 0; i < set->count; i++)
		p->levels[d][i] = set->values[i];
	return 0;
}

int prsm_dp_problem(prsm_opt_problem *p, prsm_dp_spec *s, prsm_error *err)
{
	memset(p, 0, sizeof *p);
	int rc = add_range(p, &s->pitch, s->pitch_is_lead ? "lead_mm" : "pitch_mm", err);
	if (!rc)
		rc = add_range(p, &s->radius, s->radius_is_screw ? "screw_radius_mm" : "roller_radius_mm", err);
	if (!rc)
		rc = add_range(p, &s->flank_deg, "flank_angle_deg", err);
	if (!rc)
		rc = add_set(p, &s->starts, "starts", err);
	if (!rc)
		rc = add_set(p, &s->rollers, "rollers", err);
	if (!rc)
		rc = add_set(p, &s->threads, "engaged_threads", err);
	if (!rc && s->n_pitch_values) {
		/* allowed values of P (or L): a discrete variable after the sets */
		const char *name = s->pitch_is_lead ? "lead_mm" : "pitch_mm";
		if (s->pitch.vary)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: a range or a list of values, not both", name);
		if (s->n_pitch_values < 0 || s->n_pitch_values > PRSM_OPT_MAX_LEVELS)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: 1..%d values", name, PRSM_OPT_MAX_LEVELS);
		for (int i = 0; i < s->n_pitch_values; i++)
			if (!(s->pitch_values[i] > 0.0) || (i > 0 && !(s->pitch_values[i] > s->pitch_values[i - 1])))
				return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: the values must be positive and "
				                      "ascending (value %d: %g)", name, i, s->pitch_values[i]);
		int d = p->n_discrete++;
		snprintf(p->discrete_name[d], PRSM_OPT_NAME_MAX, "%s", name);
		p->n_levels[d] = s->n_pitch_values;
		for (int i = 0; i < s->n_pitch_values; i++)
			p->levels[d][i] = s->pitch_values[i];
	}
	if (rc)
		return rc;
	if (s->n_objectives < 1 || s->n_objectives > PRSM_OPT_MAX_OBJECTIVES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "1..%d objectives", PRSM_OPT_MAX_OBJECTIVES);
	p->n_objectives = s->n_objectives;
	for (int k = 0; k < s->n_objectives; k++) {
		int kind = s->objective[k];
		if (kind < 0 || kind >= PRSM_DP_OBJECTIVE_KINDS)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "unknown objective %d", kind);
		p->sense[k] = objective_sense[kind];
		snprintf(p->objective_name[k], PRSM_OPT_NAME_MAX, "%s", prsm_dp_objective_names[kind]);
	}
	s->n_constraints = 0;
	add_constraint(s, PRSM_DP_C_ANALYSABLE, 0.0);
	add_constraint(s, PRSM_DP_C_ROLLER_FIT, 1.0);
	if (s->standard_rules)
		add_constraint(s, PRSM_DP_C_STANDARD_RULES, 0.0);
	const double limits[] = {s->nut_outer_diameter_max_mm, s->screw_diameter_min_mm,
	                         s->screw_diameter_max_mm, s->static_safety_min, s->life_min_h,
	                         s->life_min_revolutions, s->p_max_max_MPa, s->critical_speed_factor_min};
	for (int k = PRSM_DP_C_NUT_OUTER_DIAMETER; k < PRSM_DP_CONSTRAINT_KINDS; k++) {
		double l = limits[k - PRSM_DP_C_NUT_OUTER_DIAMETER];
		if (isnan(l))
			continue;
		if (!isfinite(l) || l == 0.0)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "%s: the limit must be finite and "
			                      "nonzero (got %g)", prsm_dp_constraint_names[k], l);
		if (k == PRSM_DP_C_CRITICAL_SPEED && !s->base.life.column)
			return prsm_error_set(err, PRSM_EINVAL, "/design/column",
			                      "a critical-speed constraint needs the design's column data");
		add_constraint(s, k, l);
	}
	p->n_constraints = s->n_constraints;
	for (int i = 0; i < s->n_constraints; i++)
		snprintf(p->constraint_name[i], PRSM_OPT_NAME_MAX, "%s",
		         prsm_dp_constraint_names[s->constraint_kind[i]]);
	if (s->robust) {
		const prsm_robust *r = s->robust;
		if (r->n < 1 || r->n > PRSM_ROBUST_MAX || s->n_constraints + r->n > PRSM_OPT_MAX_CONSTRAINTS)
			return prsm_error_set(err, PRSM_EINVAL, "/robust", "robust constraints: 1..%d",
			                      PRSM_ROBUST_MAX);
		for (int k = 0; k < r->n; k++) {
			if (!(r->c[k].yield_min > 0.0 && r->c[k].yield_min < 1.0) ||
			    !(r->c[k].spec.has_lower || r->c[k].spec.has_upper))
				return prsm_error_set(err, PRSM_EINVAL, "/robust/constraints",
				                      "robust constraint %s: a spec and a target in (0, 1)",
				                      r->c[k].output);
			snprintf(p->constraint_name[p->n_constraints++], PRSM_OPT_NAME_MAX, "yield_%.40s",
			         r->c[k].output);
		}
		p->has_surrogate = 1;
	}
	p->eval = dp_eval;
	p->prune = dp_prune;
	p->ctx = s;
	return 0;
}
