/*
 * bench_dyn.c: the rigid-body dynamics entries of `prsm bench` (issue 15; docs/dynamics.md):
 *   - case A's Coulomb start-up (studies/dynamics-case-a-coulomb.json: a step to 100 rad/s
 *     against 7 kN, regularised Coulomb friction, the statics losses) integrated to 0.005 s of
 *     simulated time with an output step of 1e-5 s (501 output times), simulations/s on one core;
 *   - seed 000's two-stage screw, friction row 1 (studies/dynamics-seed000-row1.json), from rest
 *     to 0.005 s at the same output step, simulations/s on one core.
 * Each entry times prsm_dyn_simulate alone: the request is read and its model (kinematic
 * structure, masses, statics references, settled state) built once, as a sweep over input
 * values would reuse it; the checks at every output time are part of what is timed.
 *
 * The vibration entries (issue 16; docs/vibration.md), each the seconds of one run on one core
 * (the fastest of the runs that fit the budget, at least one):
 *   - vibration_sweep_gear_pair_91_points_s: a 1-DOF gear-pair sweep with impacts (zeta 0.05,
 *     f_m 0.1, epsilon 0.2) of 91 points (Omega 0.5 to 2.3, up, continuation), each 300 transient
 *     and 64 recorded periods, the steady state of every point (Poincare points, extremes,
 *     spectrum) as `prsm simulate` runs it; target < 2 s;
 *   - vibration_case_a_response_1s_s: case A's reduced model, both branches, V5's TE lines and a
 *     0.1 um mesh error, 1 s of response at 330 rad/s from the static state with 1e4 output
 *     times (prsm_vib_time_response); target < 1 s.
 * The models are built once, outside the timing.
 *
 * The dynamic Monte Carlo entries (issue 17 item 4; docs/vibration.md, "Monte Carlo over dynamic
 * outputs"), samples/s of a case-A study on one core (prsm_study_run, Monte Carlo phase only):
 *   - dynamic_study_screened_samples_per_s: case A at 330 rad/s, 7 kN, payload 400 kg, linear
 *     assembly mode, 16 angles per revolution, pitch-radius, thickness, run-out and lead tolerances
 *     small enough that every sample keeps its axial play, damping ratio uniform 0.02 to 0.08, a
 *     mesh error of 0: every sample is settled by the linear screen (its statics, the TE line fit,
 *     the closed form of both branches); target >= 1e4 samples/s;
 *   - dynamic_study_integrated_samples_per_s: the same with a mesh error of 30 um, far beyond the
 *     static mesh deflection, so every sample rattles and is integrated (12 windows at most).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>

#include <stdlib.h>
#include <string.h>

#include "app/simulate.h"
#include "app/study.h"
#include "io/study_json.h"
#include "mc/study.h"
#include "dyn/vib.h"
#include "cli/commands.h"
#include "util/clock.h"

static const char coulomb_case_a[] =
	"{\"design\": {\"geometry\": {\"starts\": 5, \"hand\": \"right\", \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	" \"target_axial_clearance_um\": 20, \"friction\": {\"screw_roller\": 0.05, \"nut_roller\": 0.05}},"
	" \"dynamics\": {\"analysis\": \"transient\","
	"  \"input\": {\"kind\": \"speed\", \"shape\": \"step\", \"value_rad_s\": 100},"
	"  \"load\": {\"axial_load_N\": 7000},"
	"  \"friction\": {\"model\": \"coulomb\", \"smoothing_velocity_m_s\": 0.0001},"
	"  \"losses\": \"statics\", \"time\": {\"end_s\": 0.005, \"output_step_s\": 1e-05}}}";

static const char two_stage_seed000[] =
	"{\"stages\": ["
	"  {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45, \"screw_radius_mm\": 9.75,"
	"   \"roller_radius_mm\": 3.25, \"nut_radius_mm\": 16.25, \"rollers\": 7, \"engaged_threads\": 10},"
	"   \"target_axial_clearance_um\": 20, \"friction\": {\"screw_roller\": 0.05, \"nut_roller\": 0}},"
	"  {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45, \"screw_radius_mm\": 16.5,"
	"   \"roller_radius_mm\": 5.5, \"nut_radius_mm\": 27.5, \"rollers\": 7, \"engaged_threads\": 10},"
	"   \"target_axial_clearance_um\": 20, \"friction\": {\"screw_roller\": 0.05, \"nut_roller\": 0}}],"
	" \"couplings\": {\"spline_friction\": 0.1, \"thrust_bearing_friction\": 0.055},"
	" \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 954.9296585513721},"
	" \"dynamics\": {\"analysis\": \"transient\","
	"  \"input\": {\"kind\": \"speed\", \"shape\": \"step\", \"value_rad_s\": 100},"
	"  \"load\": {\"axial_load_N\": 7000}, \"friction\": {\"model\": \"coulomb\"},"
	"  \"losses\": \"sliding_only\","
	"  \"inertia\": {\"stages\": ["
	"   {\"roller_mass_kg\": 0.014, \"roller_inertia_kg_mm2\": 0.077, \"carrier_inertia_kg_mm2\": 2.95,"
	"    \"nut_mass_kg\": 2.2, \"screw_mass_kg\": 0.761, \"screw_inertia_kg_mm2\": 51.94},"
	"   {\"roller_mass_kg\": 0.039, \"roller_inertia_kg_mm2\": 0.471, \"carrier_inertia_kg_mm2\": 19.88,"
	"    \"nut_mass_kg\": 20, \"screw_mass_kg\": 0.761, \"screw_inertia_kg_mm2\": 172.3}]},"
	"  \"time\": {\"end_s\": 0.005, \"output_step_s\": 1e-05}}}";

static const char gear_pair_sweep[] =
	"{\"dynamics\": {\"analysis\": \"sweep\","
	"  \"gear_pair\": {\"damping_ratio\": 0.05, \"mean_load\": 0.1, \"error_amplitude\": 0.2},"
	"  \"sweep\": {\"parameter\": \"frequency_ratio\", \"from\": 0.5, \"to\": 2.3, \"step\": 0.02,"
	"   \"directions\": [\"up\"], \"transient_periods\": 300, \"recorded_periods\": 64}}}";

static const char case_a_330[] =
	"{\"design\": {\"geometry\": {\"starts\": 5, \"hand\": \"right\", \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10, \"running_clearance_mm\": 0.1},"
	" \"target_axial_clearance_um\": 20, \"friction\": {\"screw_roller\": 0.05, \"nut_roller\": 0.05}},"
	" \"dynamics\": {\"analysis\": \"vibration\", \"load\": {\"axial_load_N\": 7000}, \"inertia\": {\"payload_kg\": 400},"
	"  \"vibration\": {\"screw_speed_rad_s\": 330, \"gear_backlash_um\": 5, \"mesh_error_um\": 0.1, \"te_lines\": ["
	"   {\"order_per_rev\": 1, \"amplitude_um\": 1.84}, {\"order_per_rev\": 1.875, \"amplitude_um\": 0.443},"
	"   {\"order_per_rev\": 0.625, \"amplitude_um\": 0.26}, {\"order_per_rev\": 3.75, \"amplitude_um\": 0.181},"
	"   {\"order_per_rev\": 0.375, \"amplitude_um\": 0.141}]}}}";

static const char dynamic_study[] =
	"{\"design\": {\"geometry\": {\"starts\": 5, \"hand\": \"right\", \"pitch_mm\": 2, \"flank_angle_deg\": 45,"
	" \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10, \"running_clearance_mm\": 0.1},"
	" \"target_axial_clearance_um\": 20, \"friction\": {\"screw_roller\": 0.05, \"nut_roller\": 0.05},"
	" \"operating_point\": {\"axial_load_N\": 7000, \"screw_speed_rpm\": 955}},"
	" \"assembly\": {\"mode\": \"linear\", \"angles_per_revolution\": 16, \"measuring_load_N\": 50},"
	" \"tolerances\": [{\"parameter\": \"screw.pitch_radius_um\", \"tol_um\": 2},"
	"  {\"parameter\": \"nut.thickness_um\", \"tol_um\": 1},"
	"  {\"parameter\": \"screw.runout_um\", \"tol_um\": 4},"
	"  {\"parameter\": \"screw.lead_deviation_um_per_300mm\", \"distribution\": \"uniform\", \"lower\": -6, \"upper\": 6},"
	"  {\"parameter\": \"damping_ratio\", \"distribution\": \"uniform\", \"lower\": 0.02, \"upper\": 0.08}],"
	" \"outputs\": [\"peak_dynamic_te_um\", \"peak_thread_force_N\", \"axial_vibration_rms_m_s2\", \"mesh_force_peak_N\"],"
	" \"monte_carlo\": {\"samples\": %d, \"block_size\": %d, \"seed\": 1, \"threads\": 1},"
	" \"sensitivity\": {\"src\": false, \"stack\": false},"
	" \"dynamics\": {\"analysis\": \"vibration\", \"inertia\": {\"payload_kg\": 400},"
	"  \"vibration\": {\"screw_speed_rad_s\": 330, \"gear_backlash_um\": 5, \"mesh_error_um\": %g}}}";

static volatile double sink;

/* Samples/s of the dynamic study with `samples` samples and mesh error e_um (one thread); also
 * the screened share into *screened_share. NAN when it fails. */
static double bench_dynamic_study(int samples, double e_um, double *screened_share)
{
	char text[4096];
	snprintf(text, sizeof text, dynamic_study, samples, samples < 64 ? 16 : 64, e_um);
	*screened_share = NAN;
	cJSON *doc = cJSON_Parse(text);
	prsm_io_study *st = calloc(1, sizeof *st);
	prsm_problems pr;
	prsm_problems_init(&pr);
	double rate = NAN;
	if (doc == NULL || st == NULL || prsm_app_study_load(st, doc, NULL, &pr)) {
		fprintf(stderr, "prsm bench: built-in dynamic study invalid: %s %s\n", pr.count ? pr.items[0].pointer : "",
		        pr.count ? pr.items[0].message : "?");
	} else {
		prsm_study_result r;
		memset(&r, 0, sizeof r);
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_study_run(&r, &st->study, &err) == 0 && r.elapsed_run_s > 0.0) {
			rate = (double)r.run.n / r.elapsed_run_s;
			if (r.dynamics.present && r.run.n > 0)
				*screened_share = (double)r.dynamics.screened / (double)r.run.n;
		} else {
			fprintf(stderr, "prsm bench: dynamic study failed: %s\n", err.message);
		}
		prsm_study_result_free(&r);
	}
	cJSON_Delete(doc);
	free(st);
	return rate;
}

/* A loaded request (NULL, said on stderr, when invalid). */
static prsm_app_simulation *load(const char *text)
{
	cJSON *doc = cJSON_Parse(text);
	prsm_problems w, pr;
	prsm_problems_init(&w);
	prsm_problems_init(&pr);
	prsm_app_simulation *s = NULL;
	if (doc == NULL || prsm_app_simulation_load(&s, doc, &w, &pr)) {
		fprintf(stderr, "prsm bench: built-in request invalid: %s %s\n", pr.count ? pr.items[0].pointer : "",
		        pr.count ? pr.items[0].message : "?");
		s = NULL;
	}
	cJSON_Delete(doc);
	return s;
}

/* Seconds of the fastest sweep run (one thread) within the budget; NAN when it fails. */
static double bench_vibration_sweep(double budget_s)
{
	prsm_app_simulation *s = load(gear_pair_sweep);
	if (s == NULL)
		return NAN;
	prsm_app_simulation_set_threads(s, 1);
	double best = NAN, t0 = prsm_clock_seconds();
	do {
		prsm_error err = PRSM_ERROR_INIT;
		const double a = prsm_clock_seconds();
		if (prsm_app_simulation_run(s, NULL, NULL, NULL, 0.0, &err)) {
			fprintf(stderr, "prsm bench: sweep failed: %s\n", err.message);
			best = NAN;
			break;
		}
		const double t = prsm_clock_seconds() - a;
		best = isnan(best) || t < best ? t : best;
	} while (prsm_clock_seconds() - t0 + best < budget_s);
	prsm_app_simulation_free(s);
	return best;
}

/* Seconds of the fastest 1 s response of case A's reduced model within the budget. */
static double bench_vibration_response(double budget_s)
{
	prsm_app_simulation *s = load(case_a_330);
	if (s == NULL)
		return NAN;
	const prsm_vib_model *m = prsm_app_vibration_model(prsm_app_simulation_vibration(s));
	const prsm_vib_integration integ = PRSM_VIB_INTEGRATION_INIT;
	double best = NAN, t0 = prsm_clock_seconds();
	do {
		prsm_vib_response r;
		prsm_error err = PRSM_ERROR_INIT;
		const double a = prsm_clock_seconds();
		const int rc = prsm_vib_time_response(&r, m, NULL, 1.0, 1e-4, &integ, NULL, &err);
		const double t = prsm_clock_seconds() - a;
		if (rc) {
			fprintf(stderr, "prsm bench: response failed: %s\n", err.message);
			prsm_vib_response_free(&r);
			best = NAN;
			break;
		}
		sink = (double)r.points;
		prsm_vib_response_free(&r);
		best = isnan(best) || t < best ? t : best;
	} while (prsm_clock_seconds() - t0 + best < budget_s);
	prsm_app_simulation_free(s);
	return best;
}

/* Simulations per second of the request text (NAN when it does not load or run). */
static double bench_simulation(const char *text, double budget_s)
{
	cJSON *doc = cJSON_Parse(text);
	prsm_problems w, pr;
	prsm_problems_init(&w);
	prsm_problems_init(&pr);
	prsm_app_simulation *s = NULL;
	if (doc == NULL || prsm_app_simulation_load(&s, doc, &w, &pr)) {
		fprintf(stderr, "prsm bench: built-in simulation invalid: %s %s\n", pr.count ? pr.items[0].pointer : "",
		        pr.count ? pr.items[0].message : "?");
		cJSON_Delete(doc);
		return NAN;
	}
	cJSON_Delete(doc);
	const prsm_dyn_model *m = prsm_app_simulation_model(s);
	long n = 0;
	double rate = NAN, t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		prsm_dyn_result r = {0};
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_dyn_simulate(&r, m, NULL, NULL, NULL, &err)) {
			fprintf(stderr, "prsm bench: simulation failed: %s\n", err.message);
			prsm_dyn_result_free(&r);
			n = 0;
			break;
		}
		sink = (double)r.points;
		prsm_dyn_result_free(&r);
		n++;
		t = prsm_clock_seconds();
	}
	if (n > 0)
		rate = (double)n / (t - t0);
	prsm_app_simulation_free(s);
	return rate;
}

void prsm_cli_bench_dyn(cJSON *list, double budget_s)
{
	prsm_cli_bench_add(list, "startup_coulomb_case_a_5ms", bench_simulation(coulomb_case_a, budget_s),
	                   "simulations/s", 1, 0);
	prsm_cli_bench_add(list, "startup_two_stage_seed000_5ms", bench_simulation(two_stage_seed000, budget_s),
	                   "simulations/s", 1, 0);
	prsm_cli_bench_add(list, "vibration_sweep_gear_pair_91_points_s", bench_vibration_sweep(budget_s), "s", 1, 3);
	prsm_cli_bench_add(list, "vibration_case_a_response_1s_s", bench_vibration_response(budget_s), "s", 1, 3);
	/* the screened rate from a run of about the budget (a first short run sizes it) */
	double share = NAN;
	const double r0 = bench_dynamic_study(256, 0.0, &share);
	int n = isfinite(r0) ? (int)fmin(262144.0, fmax(256.0, r0 * budget_s)) : 256;
	n = (n + 63) / 64 * 64;
	const double rs = bench_dynamic_study(n, 0.0, &share);
	prsm_cli_bench_add(list, "dynamic_study_screened_samples_per_s", share == 1.0 ? rs : NAN, "samples/s", 1, 0);
	const double ri = bench_dynamic_study(4, 30.0, &share);
	prsm_cli_bench_add(list, "dynamic_study_integrated_samples_per_s", share == 0.0 ? ri : NAN, "samples/s", 1, 3);
}
