/*
 * test_app_vibration.c: the vibration analyses of a simulation request from JSON to their
 * result (app/simulate.h, app/vibrate.h, io/dynamics_json.c; docs/vibration.md): the open
 * validation case V4a through the document (the amplitudes at Omega 0.5, 1.0, 1.5 to 1e-6
 * relative, the mean 1 + f_m, lambda_1 = lambda_2 = -zeta to 2e-4), the result's numbers the
 * engine's own, sweep, frequency-response and basin documents bit-identical for 1 and 2 threads,
 * the reduced model of case A (the TE response of the thread at 330 rad/s against the closed
 * form's period and mean, a linear analysis), a sweep whose points fail reported point by point,
 * the echoed parameters read back give the same result, cancel and the time cap, the model's
 * problems at their pointers, the CSV and text, and the job kind with progress in sweep points.
 */
#include "test_support.h"
#include "test_problems.h"

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>

#include "app/simulate.h"
#include "io/dynamics_json.h"
#include "io/global.h"
#include "job/kind.h"

static prsm_app_simulation *load_ok(const cJSON *doc)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_app_simulation *s = NULL;
	if (prsm_app_simulation_load(&s, doc, NULL, &p)) {
		dump(&p);
		fail();
	}
	return s;
}

static cJSON *run_result(const char *text, int threads)
{
	cJSON *doc = parse_ok(text);
	prsm_app_simulation *s = load_ok(doc);
	cJSON_Delete(doc);
	prsm_app_simulation_set_threads(s, threads);
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_app_simulation_run(s, NULL, NULL, NULL, 0.0, &err);
	if (rc) {
		print_error("run: %s (%s)\n", err.message, err.pointer);
		fail();
	}
	cJSON *res = prsm_app_simulation_result(s);
	assert_non_null(res);
	prsm_app_simulation_free(s);
	return res;
}

static const cJSON *at(const cJSON *o, const char *path)
{
	const cJSON *cur = o;
	const char *p = path;
	while (*p) {
		char key[64];
		const size_t n = strcspn(p, "/");
		snprintf(key, sizeof key, "%.*s", (int)n, p);
		cur = cJSON_IsArray(cur) ? cJSON_GetArrayItem(cur, (int)strtol(key, NULL, 10))
		                         : cJSON_GetObjectItemCaseSensitive(cur, key);
		if (cur == NULL) {
			print_error("no %s in the result\n", path);
			fail();
		}
		p += n;
		if (*p == '/')
			p++;
	}
	return cur;
}

static double num(const cJSON *o, const char *path)
{
	const cJSON *v = at(o, path);
	return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

static const char *str(const cJSON *o, const char *path)
{
	const cJSON *v = at(o, path);
	return cJSON_IsString(v) ? v->valuestring : "";
}

static char *print(const cJSON *res)
{
	char *t = cJSON_PrintUnformatted(res);
	assert_non_null(t);
	return t;
}

static double closed_form_amplitude(double eps, double zeta, double W)
{
	return eps * W * W / sqrt((1.0 - W * W) * (1.0 - W * W) + (2.0 * zeta * W) * (2.0 * zeta * W));
}

/* V4a (open, docs/model 8.8): zeta 0.05, f_m 0.1, epsilon 0.005, kappa 0 -- no contact loss */
static void test_v4a_through_the_document(void **state)
{
	(void)state;
	const double W[3] = {0.5, 1.0, 1.5}, expect[3] = {0.00166298, 0.05, 0.00893589};
	for (int i = 0; i < 3; i++) {
		char text[600];
		snprintf(text, sizeof text,
		         "{\"name\": \"V4a\", \"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {\"damping_ratio\": 0.05,"
		         " \"mean_load\": 0.1, \"error_amplitude\": 0.005, \"frequency_ratio\": %.17g},"
		         " \"steady_state\": {\"lyapunov\": %s, \"lyapunov_exponents\": 2}}}", W[i], i == 1 ? "true" : "false");
		cJSON *res = run_result(text, 1);
		assert_string_equal(str(res, "name"), "V4a");
		assert_string_equal(str(res, "engine/model"), PRSM_VIB_MODEL_VERSION);
		const cJSON *v = at(res, "dynamics/vibration");
		assert_string_equal(str(v, "classification"), "periodic");
		assert_int_equal((int)num(v, "period"), 1);
		assert_string_equal(str(v, "extremes/0/observable"), "mesh_deflection");
		const double amp = num(v, "extremes/0/amplitude");
		assert_close(amp, expect[i], 1e-6 * expect[i] + 5e-9); /* the published digits */
		assert_close(amp, closed_form_amplitude(0.005, 0.05, W[i]), 1e-6 * amp);
		assert_close(0.5 * (num(v, "extremes/0/max") + num(v, "extremes/0/min")), 1.1, 1e-8);
		assert_close(num(v, "extremes/0/mean"), 1.1, 1e-8);
		assert_string_equal(str(v, "spectrum/0/name"), "forcing");
		assert_close(num(v, "spectrum/0/frequency_ratio"), W[i], 1e-12);
		assert_true(cJSON_IsNull(at(v, "spectrum/0/frequency_Hz")));
		assert_close(num(v, "contacts/0/open_share"), 0.0, 0.0);
		assert_int_equal((int)num(v, "poincare/points"), 64);
		assert_int_equal(cJSON_GetArraySize(at(v, "phase_portrait/observable")), 64 * 128);
		if (i == 1) {
			assert_close(num(v, "lyapunov/exponents_per_tau/0"), -0.05, 2e-4);
			assert_close(num(v, "lyapunov/exponents_per_tau/1"), -0.05, 2e-4);
			assert_close(num(v, "lyapunov/sum_per_tau"), -0.1, 1e-8);
			assert_true(cJSON_IsNull(at(v, "lyapunov/exponents_per_s/0")));
		} else {
			assert_true(cJSON_IsNull(at(v, "lyapunov")));
		}
		/* the parameters echoed, every default filled in; the model's own */
		assert_close(num(res, "dynamics/parameters/gear_pair/contact_ratio"), 1.5, 0.0);
		assert_int_equal((int)num(res, "dynamics/parameters/steady_state/transient_periods"), 300);
		assert_string_equal(str(res, "dynamics/model/kind"), "gear_pair");
		assert_true(cJSON_IsTrue(at(res, "dynamics/convergence/converged")));
		cJSON_Delete(res);
	}
}

/* The result's numbers are the engine's, and the echoed parameters reproduce the result. */
static void test_engine_numbers_and_echo(void **state)
{
	(void)state;
	const char *text = "{\"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {\"error_amplitude\": 0.2, "
	                   "\"frequency_ratio\": 0.7}, \"steady_state\": {\"transient_periods\": 200, \"recorded_periods\": 16,"
	                   " \"samples_per_period\": 32}}}";
	cJSON *res = run_result(text, 1);
	prsm_vib_gear_pair g = PRSM_VIB_GEAR_PAIR_INIT;
	g.mesh_error = 0.2;
	g.frequency_ratio = 0.7;
	prsm_vib_model *m = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_vib_gear_pair_new(&m, &g, &err), 0);
	prsm_vib_steady_options so = PRSM_VIB_STEADY_OPTIONS_INIT;
	so.transient_periods = 200;
	so.recorded_periods = 16;
	so.samples_per_period = 32;
	prsm_vib_steady s;
	assert_int_equal(prsm_vib_steady_state(&s, m, NULL, &so, NULL, &err), 0);
	const cJSON *v = at(res, "dynamics/vibration");
	assert_int_equal((int)num(v, "period"), s.period);
	for (int i = 0; i < s.recorded; i++)
		assert_true(cJSON_GetArrayItem(at(v, "poincare/observable"), i)->valuedouble == s.poincare_observable[i]);
	assert_true(num(v, "extremes/0/min") == s.extreme[0].min && num(v, "extremes/0/max") == s.extreme[0].max);
	assert_true(num(v, "contacts/0/open_share") == s.loss_share[0]);
	prsm_vib_steady_free(&s);
	prsm_vib_model_free(m);
	/* the echoed dynamics object, run again, gives the same document */
	cJSON *again = cJSON_CreateObject();
	cJSON_AddItemToObject(again, "dynamics", cJSON_Duplicate(at(res, "dynamics/parameters"), 1));
	char *t = print(again);
	cJSON *res2 = run_result(t, 2);
	char *a = print(at(res, "dynamics")), *b = print(at(res2, "dynamics"));
	assert_string_equal(a, b);
	free(a);
	free(b);
	free(t);
	cJSON_Delete(again);
	cJSON_Delete(res2);
	cJSON_Delete(res);
}

/* Sweeps (continuation and independent), frequency responses and basin grids: the result
 * documents of 1 and 2 threads are bit-identical. */
static void test_threads_bit_identical(void **state)
{
	(void)state;
	static const char *const docs[] = {
		"{\"dynamics\": {\"analysis\": \"sweep\", \"gear_pair\": {\"error_amplitude\": 0.2}, \"sweep\": {\"from\": 0.6,"
		" \"to\": 1.4, \"step\": 0.1, \"transient_periods\": 100, \"recorded_periods\": 16, \"lyapunov\": true,"
		" \"lyapunov_periods\": 50}}}",
		"{\"dynamics\": {\"analysis\": \"sweep\", \"gear_pair\": {\"error_amplitude\": 0.2}, \"sweep\": {\"from\": 0.6,"
		" \"to\": 1.4, \"step\": 0.1, \"transient_periods\": 100, \"recorded_periods\": 16, \"continuation\": false}}}",
		"{\"dynamics\": {\"analysis\": \"frequency_response\", \"gear_pair\": {\"error_amplitude\": 0.02}, \"sweep\": "
		"{\"from\": 0.84, \"to\": 0.96, \"step\": 0.02, \"transient_periods\": 200, \"recorded_periods\": 16}}}",
		"{\"dynamics\": {\"analysis\": \"basins\", \"gear_pair\": {\"error_amplitude\": 0.02, \"frequency_ratio\": 0.9},"
		" \"basins\": {\"deflection_cells\": 7, \"rate_cells\": 6, \"periods\": 60, \"identify_periods\": 16}}}",
	};
	for (size_t i = 0; i < sizeof docs / sizeof docs[0]; i++) {
		cJSON *r1 = run_result(docs[i], 1), *r2 = run_result(docs[i], 2);
		char *a = print(r1), *b = print(r2);
		assert_string_equal(a, b);
		free(a);
		free(b);
		cJSON_Delete(r2);
		if (i == 0) {
			const cJSON *up = at(r1, "dynamics/sweep/up"), *down = at(r1, "dynamics/sweep/down");
			assert_int_equal(cJSON_GetArraySize(up), 9);
			assert_int_equal(cJSON_GetArraySize(down), 9);
			assert_close(num(up, "0/frequency_ratio"), 0.6, 1e-15);
			assert_close(num(down, "0/frequency_ratio"), 1.4, 1e-12);
			assert_int_equal(cJSON_GetArraySize(at(up, "3/poincare")), 16);
			assert_true(cJSON_IsNumber(at(up, "3/lyapunov_per_tau")));
		}
		if (i == 2) { /* HB's folds bracket its jumps' exact folds */
			assert_true(cJSON_IsObject(at(r1, "dynamics/frequency_response/harmonic_balance")));
			assert_true(cJSON_GetArraySize(at(r1, "dynamics/frequency_response/harmonic_balance/folds")) >= 2);
			assert_int_equal(cJSON_GetArraySize(at(r1, "dynamics/frequency_response/sweep_up")), 7);
		}
		if (i == 3) {
			double total = num(r1, "dynamics/basins/other/fraction") + num(r1, "dynamics/basins/failed/fraction");
			for (int a_ = 0; a_ < cJSON_GetArraySize(at(r1, "dynamics/basins/attractors")); a_++)
				total += cJSON_GetArrayItem(at(r1, "dynamics/basins/attractors"), a_) ?
				             num(cJSON_GetArrayItem(at(r1, "dynamics/basins/attractors"), a_), "fraction") : 0.0;
			assert_close(total, 1.0, 1e-12);
			assert_int_equal(cJSON_GetArraySize(at(r1, "dynamics/basins/labels")), 7);
			assert_int_equal(cJSON_GetArraySize(at(r1, "dynamics/basins/labels/0")), 6);
		}
		cJSON_Delete(r1);
	}
}

/* A sweep whose points do not converge: each point says so, none is drawn, the run is a result. */
static void test_failed_points_reported(void **state)
{
	(void)state;
	cJSON *res = run_result("{\"dynamics\": {\"analysis\": \"sweep\", \"gear_pair\": {\"error_amplitude\": 0.2},"
	                        " \"sweep\": {\"from\": 0.8, \"to\": 1.0, \"step\": 0.1, \"directions\": [\"up\"]},"
	                        " \"time\": {\"max_steps\": 50}}}", 1);
	const cJSON *up = at(res, "dynamics/sweep/up");
	assert_int_equal(cJSON_GetArraySize(up), 3);
	for (int i = 0; i < 3; i++) {
		const cJSON *p = cJSON_GetArrayItem(up, i);
		assert_true(cJSON_IsFalse(at(p, "converged")));
		assert_string_equal(str(p, "classification"), "failed");
		assert_string_equal(str(p, "error"), prsm_error_name(PRSM_ENOCONVERGE));
		assert_true(cJSON_IsNull(at(p, "amplitude")) && cJSON_IsNull(at(p, "period")));
		assert_int_equal(cJSON_GetArraySize(at(p, "poincare")), 0);
	}
	assert_int_equal(cJSON_GetArraySize(at(res, "dynamics/sweep/down")), 0);
	assert_int_equal((int)num(res, "dynamics/sweep/failed_points"), 3);
	assert_true(cJSON_IsString(at(res, "dynamics/sweep/first_error")));
	assert_true(cJSON_IsFalse(at(res, "dynamics/convergence/converged")));
	assert_int_equal((int)num(res, "dynamics/convergence/failed_points"), 3);
	cJSON_Delete(res);
}

/* Case A's reduced model: the thread's TE response at 330 rad/s (the V5 lines), and a linear
 * analysis at omega_e = 1. */
static void test_case_a(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("vibration-case-a-330.json");
	assert_non_null(doc);
	char *t = print(doc);
	cJSON *res = run_result(t, 1);
	free(t);
	cJSON_Delete(doc);
	const cJSON *d = at(res, "dynamics");
	assert_string_equal(str(d, "model/kind"), "reduced");
	assert_close(num(d, "model/axial/stiffness_N_per_um"), 611.40, 0.01);
	assert_close(num(d, "model/axial/half_play_um"), 10.0, 1e-6);
	assert_close(num(d, "model/te_period_rev"), 8.0, 0.0);
	assert_string_equal(str(d, "vibration/classification"), "periodic");
	assert_int_equal((int)num(d, "vibration/period"), 1);
	assert_string_equal(str(d, "vibration/clock"), "te");
	assert_close(num(d, "vibration/forcing_period_s"), 8.0 * 2.0 * M_PI / 330.0, 1e-12);
	int seen = 0;
	const cJSON *ex = at(d, "vibration/extremes");
	for (int i = 0; i < cJSON_GetArraySize(ex); i++) {
		const cJSON *e = cJSON_GetArrayItem(ex, i);
		if (strcmp(str(e, "observable"), "thread_force") == 0) {
			assert_close(num(e, "mean"), 7000.0, 0.5); /* the TE adds no mean force */
			assert_true(num(e, "min") > 5000.0 && num(e, "max") < 9000.0);
			seen++;
		}
		if (strcmp(str(e, "observable"), "axial_deflection") == 0) {
			assert_true(num(e, "min") > 1.0); /* never out of contact: y > b_a */
			seen++;
		}
	}
	assert_int_equal(seen, 2);
	cJSON_Delete(res);
	doc = prsm_test_read_study("vibration-case-a-linear.json");
	t = print(doc);
	res = run_result(t, 1);
	free(t);
	cJSON_Delete(doc);
	d = at(res, "dynamics");
	assert_close(num(d, "model/frequency_ratio"), 1.0, 1e-12);
	const cJSON *ev = at(d, "linear/eigenvalues");
	assert_int_equal(cJSON_GetArraySize(ev), 2 * (int)num(d, "linear/dofs"));
	assert_string_equal(str(ev, "0/kind"), "rigid");
	assert_true(cJSON_IsTrue(at(d, "linear/half_power/defined")));
	/* half-power damping next to the modal one: O(zeta^2) apart */
	assert_close(num(d, "linear/half_power/damping_ratio"), num(d, "linear/half_power/modal_damping_ratio"), 0.002);
	assert_true(num(d, "linear/half_power/peak_frequency_Hz") > 25000 && num(d, "linear/half_power/peak_frequency_Hz") < 45000);
	assert_int_equal(cJSON_GetArraySize(at(d, "linear/frf/magnitude")), 401);
	assert_string_equal(str(d, "linear/frf/unit"), "m/m");
	cJSON_Delete(res);
}

/* The problems only the model can find, at their pointers; the forms of the request. */
static void test_refused_at_their_pointers(void **state)
{
	(void)state;
	static const struct {
		const char *doc, *pointer;
	} cases[] = {
		{"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10}, \"target_axial_clearance_um\": 20},"
		 " \"dynamics\": {\"analysis\": \"vibration\", \"steady_state\": {\"roller\": 12}}}", "/dynamics/steady_state/roller"},
		{"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10}, \"target_axial_clearance_um\": 20},"
		 " \"dynamics\": {\"analysis\": \"vibration\", \"vibration\": {\"te_lines\": \"statics\"}}}", "/errors"},
		{"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10}, \"target_axial_clearance_um\": 20},"
		 " \"errors\": {}, \"dynamics\": {\"analysis\": \"vibration\"}}", "/errors"},
		{"{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10}, \"target_axial_clearance_um\": 20},"
		 " \"dynamics\": {\"analysis\": \"linear\", \"linear\": {\"from_Hz\": 1e8}}}", "/dynamics/linear/to_Hz"},
		{"{\"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {}}, \"design\": 3}", "/design"},
		{"{\"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {}}, \"errors\": {}}", "/errors"},
		{"{\"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {}}, \"name\": 7}", "/name"},
		{"{\"dynamics\": {\"analysis\": \"vibration\"}}", "/dynamics/gear_pair"},
		{"{\"dynamics\": {\"gear_pair\": {}}}", "/dynamics/analysis"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		cJSON *doc = parse_ok(cases[i].doc);
		prsm_problems p;
		prsm_problems_init(&p);
		prsm_app_simulation *s = NULL;
		const int rc = prsm_app_simulation_check(doc, NULL, &p);
		int found = 0;
		for (int j = 0; j < p.count; j++)
			found += strcmp(p.items[j].pointer, cases[i].pointer) == 0;
		if (rc == 0 || found != 1) {
			print_error("case %zu: rc %d, %d at %s\n", i, rc, found, cases[i].pointer);
			dump(&p);
			fail();
		}
		prsm_app_simulation_free(s);
		cJSON_Delete(doc);
	}
}

/* Cancel and the time cap: no result. */
static void test_cancel_and_time_cap(void **state)
{
	(void)state;
	const char *text = "{\"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {\"error_amplitude\": 0.2, "
	                   "\"frequency_ratio\": 1.3}, \"steady_state\": {\"transient_periods\": 900000, \"recorded_periods\": 64}}}";
	cJSON *doc = parse_ok(text);
	prsm_app_simulation *s = load_ok(doc);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_app_simulation_run(s, NULL, NULL, NULL, 0.05, &err), PRSM_ECANCELLED);
	assert_non_null(strstr(err.message, "time cap"));
	assert_null(prsm_app_simulation_result(s));
	prsm_cancel_flag stop;
	atomic_init(&stop, 1);
	assert_int_equal(prsm_app_simulation_run(s, &stop, NULL, NULL, 0.0, &err), PRSM_ECANCELLED);
	assert_null(prsm_app_simulation_result(s));
	prsm_app_simulation_free(s);
	cJSON_Delete(doc);
}

/* CSV and text of each analysis. */
static int csv_rows(prsm_app_simulation *s, char *first, size_t cap)
{
	FILE *f = tmpfile();
	assert_non_null(f);
	assert_int_equal(prsm_app_simulation_csv(f, s), 0);
	rewind(f);
	int rows = 0;
	char line[4096];
	first[0] = '\0';
	while (fgets(line, sizeof line, f)) {
		if (rows == 0) {
			const size_t n = strlen(line) < cap - 1 ? strlen(line) : cap - 1;
			memcpy(first, line, n);
			first[n] = '\0';
		}
		rows++;
	}
	fclose(f);
	return rows;
}

static void test_csv_and_text(void **state)
{
	(void)state;
	static const struct {
		const char *doc, *head;
		int rows;
	} cases[] = {
		{"{\"dynamics\": {\"analysis\": \"vibration\", \"gear_pair\": {}, \"steady_state\": {\"transient_periods\": 10,"
		 " \"recorded_periods\": 4, \"samples_per_period\": 8}}}", "time_tau,time_s,mesh_deflection,mesh_deflection_rate", 33},
		{"{\"dynamics\": {\"analysis\": \"sweep\", \"gear_pair\": {}, \"sweep\": {\"parameter\": \"mean_load\", \"from\": 0.1,"
		 " \"to\": 0.3, \"step\": 0.1, \"transient_periods\": 10, \"recorded_periods\": 4}}}",
		 "direction,mean_load,classification", 1 + 6 * 4},
		{"{\"dynamics\": {\"analysis\": \"basins\", \"gear_pair\": {}, \"basins\": {\"deflection_cells\": 3, \"rate_cells\": 2,"
		 " \"periods\": 5, \"identify_periods\": 4}}}", "deflection,rate,label", 7},
		{"{\"dynamics\": {\"analysis\": \"linear\", \"gear_pair\": {}, \"linear\": {\"points\": 11}}}",
		 "frequency_ratio,magnitude,phase_deg", 12},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		cJSON *doc = parse_ok(cases[i].doc);
		prsm_app_simulation *s = load_ok(doc);
		cJSON_Delete(doc);
		prsm_error err = PRSM_ERROR_INIT;
		assert_int_equal(prsm_app_simulation_run(s, NULL, NULL, NULL, 0.0, &err), 0);
		char first[512];
		assert_int_equal(csv_rows(s, first, sizeof first), cases[i].rows);
		assert_true(strncmp(first, cases[i].head, strlen(cases[i].head)) == 0);
		FILE *f = tmpfile();
		assert_int_equal(prsm_app_simulation_text(f, s), 0);
		assert_true(ftell(f) > 50);
		fclose(f);
		prsm_app_simulation_free(s);
	}
}

/* The job kind: progress in sweep points, the result and the CSV handed back. */
typedef struct {
	size_t last_done, last_planned;
	int reports;
} progress_seen;

static void seen_progress(void *ctx, const prsm_progress *p)
{
	progress_seen *k = ctx;
	assert_true(p->done <= p->planned);
	k->last_done = p->done;
	k->last_planned = p->planned;
	k->reports++;
}

static void test_job_kind(void **state)
{
	(void)state;
	const prsm_job_kind *kind = prsm_job_kind_by_name("simulation");
	assert_non_null(strstr(kind->version(), PRSM_VIB_MODEL_VERSION));
	cJSON *doc = parse_ok("{\"dynamics\": {\"analysis\": \"sweep\", \"gear_pair\": {\"error_amplitude\": 0.2},"
	                      " \"sweep\": {\"from\": 0.6, \"to\": 1.4, \"step\": 0.1, \"transient_periods\": 50,"
	                      " \"recorded_periods\": 8}}}");
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_job_limits lim = {0, 600.0, 2};
	cJSON *norm = NULL;
	assert_int_equal(kind->normalise(&norm, doc, &lim, &p), 0);
	char *request = cJSON_PrintUnformatted(norm);
	cJSON_Delete(norm);
	prsm_cancel_flag cancel;
	atomic_init(&cancel, 0);
	progress_seen seen = {0, 0, 0};
	prsm_job_run_ctx ctx = {&cancel, seen_progress, &seen, {0, 600.0, 2}};
	prsm_job_output out;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(kind->run(&out, request, &ctx, &err), 0);
	assert_true(seen.reports > 2);
	assert_int_equal((int)seen.last_planned, 18);
	assert_int_equal((int)seen.last_done, 18);
	assert_int_equal((int)out.samples_done, 18);
	assert_int_equal((int)out.samples_planned, 18);
	cJSON *res = cJSON_Parse(out.result);
	assert_int_equal(cJSON_GetArraySize(at(res, "dynamics/sweep/up")), 9);
	cJSON_Delete(res);
	assert_true(strncmp(out.csv, "direction,frequency_ratio,", 26) == 0);
	prsm_job_output_free(&out);
	free(request);
	cJSON_Delete(doc);
	/* the service's cap on recorded values, at the step */
	doc = parse_ok("{\"dynamics\": {\"analysis\": \"sweep\", \"gear_pair\": {}, \"sweep\": {\"from\": 0.1, \"to\": 900,"
	               " \"step\": 0.05, \"transient_periods\": 1}}}");
	prsm_problems_init(&p);
	assert_int_equal(kind->normalise(&norm, doc, &lim, &p), PRSM_EINVAL);
	assert_true(find(&p, "/dynamics/sweep/step", "service_cap") >= 0);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_v4a_through_the_document),
		cmocka_unit_test(test_engine_numbers_and_echo),
		cmocka_unit_test(test_threads_bit_identical),
		cmocka_unit_test(test_failed_points_reported),
		cmocka_unit_test(test_case_a),
		cmocka_unit_test(test_refused_at_their_pointers),
		cmocka_unit_test(test_cancel_and_time_cap),
		cmocka_unit_test(test_csv_and_text),
		cmocka_unit_test(test_job_kind),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
