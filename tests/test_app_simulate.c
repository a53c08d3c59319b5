/*
 * test_app_simulate.c: a simulation request from JSON to its result (app/simulate.h,
 * io/dynamics_json.c): validation case V1 of the dynamics model (open numbers: k*, tau, the
 * transient times, eta(0+), the settled torque and efficiency) in the result document; the
 * document's series equal to the model's own run, number for number; the echoed parameters read
 * back give the same run; a two-stage chain with its couplings; the CSV and the text summary;
 * the form's and the model's problems at their pointers; a run that does not converge, is
 * cancelled or runs out of time returns no result; an analyze request with dynamics says the
 * transient is not run; the job kind's normalise and run, and a cancel from another thread.
 */
#include "test_dyn_support.h"
#include "test_problems.h"

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>

#include "app/simulate.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "job/kind.h"
#include "io/dynamics_json.h"

static const char *const v1_design =
	"{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45, \"roller_radius_mm\": 3.25,"
	" \"rollers\": 10, \"engaged_threads\": 10}}";

/* {"design": case A, "dynamics": <dyn>} */
static cJSON *request(const char *dyn)
{
	char text[4096];
	snprintf(text, sizeof text, "{\"design\": %s, \"dynamics\": %s}", v1_design, dyn);
	return parse_ok(text);
}

static const char *const v1_dynamics =
	"{\"analysis\": \"transient\", \"input\": {\"kind\": \"speed\", \"value_rad_s\": 1}, \"load\": {\"axial_load_N\": 100},"
	" \"friction\": {\"model\": \"viscous\", \"viscous_N_s_per_m\": 25}, \"losses\": \"sliding_only\","
	" \"time\": {\"end_s\": 0.001, \"output_step_s\": 1e-5}}";

static prsm_app_simulation *load_ok(const cJSON *doc)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_app_simulation *s = NULL;
	const int rc = prsm_app_simulation_load(&s, doc, NULL, &p);
	if (rc) {
		dump(&p);
		fail();
	}
	return s;
}

static void run_ok(prsm_app_simulation *s)
{
	prsm_error err = PRSM_ERROR_INIT;
	const int rc = prsm_app_simulation_run(s, NULL, NULL, NULL, 0.0, &err);
	if (rc) {
		print_error("run: %s\n", err.message);
		fail();
	}
}

static const cJSON *at(const cJSON *o, const char *path)
{
	/* keys and array indices separated by '/' */
	const cJSON *cur = o;
	const char *p = path;
	while (*p) {
		char key[64];
		size_t n = strcspn(p, "/");
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

static void test_v1_in_the_result(void **state)
{
	(void)state;
	cJSON *doc = request(v1_dynamics);
	prsm_app_simulation *s = load_ok(doc);
	assert_int_equal(prsm_app_simulation_points(s), 101);
	run_ok(s);
	cJSON *res = prsm_app_simulation_result(s);
	assert_non_null(res);
	const cJSON *d = at(res, "dynamics");
	assert_string_equal(at(res, "engine/model")->valuestring, PRSM_DYN_MODEL_VERSION);
	/* validation case V1 (docs/dynamics.md), to its tolerances */
	assert_rel(num(d, "model/stages/0/carrier_ratio_min_slip"), 0.37369408, 1e-6);
	assert_rel(num(d, "settled/stages/0/carrier_ratio"), 0.37369408, 1e-6);
	assert_rel(num(d, "model/stages/0/carrier_side_inertia_kg_mm2"), 2.148289e-5 * 1e6, 1e-6);
	assert_rel(1.0 / num(d, "settled/stages/0/carrier_rate_per_s"), 1.277814e-4, 1e-6);
	assert_rel(num(d, "settled/stages/0/time_to_50_percent_s"), 8.857132e-5, 1e-5);
	assert_rel(num(d, "settled/stages/0/time_to_99_percent_s"), 5.884551e-4, 1e-5);
	assert_rel(num(d, "transient/input_torque_Nm/0"), 0.1838830, 1e-6);
	assert_close(num(d, "transient/efficiency/0"), 0.8655226, 1e-6);
	assert_rel(num(d, "settled/input_torque_Nm"), 0.1604052, 1e-6);
	assert_close(num(d, "settled/efficiency"), 0.9922054, 1e-6);
	assert_true(cJSON_IsNull(at(d, "settled/efficiency_statics"))); /* no statics viscous friction */
	/* the A, B of the text (lower flank, mm per rad) */
	assert_close(num(d, "model/stages/0/flanks/lower/A_mm/0"), -2.507125, 1e-6);
	assert_close(num(d, "model/stages/0/flanks/lower/A_mm/1"), 25.81091, 1e-5);
	assert_close(num(d, "model/stages/0/flanks/lower/B_mm/2"), -1.591549, 1e-6);
	assert_string_equal(at(d, "settled/stages/0/loaded_flank")->valuestring, "lower");
	assert_true(cJSON_IsTrue(at(d, "checks/passed")));
	assert_true(cJSON_IsTrue(at(d, "convergence/converged")));
	assert_int_equal(cJSON_GetArraySize(at(res, "warnings")), 0);

	/* every series is the model's run, number for number */
	const prsm_dyn_result *r = prsm_app_simulation_dyn_result(s);
	assert_non_null(r);
	assert_int_equal((int)num(d, "transient/points"), (int)r->points);
	const cJSON *ts = at(d, "transient/time_s"), *ratio = at(d, "transient/stages/0/carrier_ratio");
	const cJSON *eff = at(d, "transient/efficiency"), *pb = at(d, "checks/power_balance_residual_W");
	assert_int_equal(cJSON_GetArraySize(ts), 101);
	for (int i = 0; i < 101; i++) {
		assert_true(cJSON_GetArrayItem(ts, i)->valuedouble == r->point[i].time_s);
		assert_true(cJSON_GetArrayItem(ratio, i)->valuedouble == r->stage[i].carrier_ratio);
		assert_true(cJSON_GetArrayItem(eff, i)->valuedouble == r->point[i].efficiency);
		assert_true(cJSON_GetArrayItem(pb, i)->valuedouble == r->point[i].power_balance_residual_W);
	}
	/* and the model's run of the same design and options, directly */
	prsm_design dd;
	prsm_analysis aa;
	dyn_case_a(&dd, &aa, 0.05);
	prsm_dyn_options o;
	dyn_v1_options(&o);
	prsm_dyn_model *m = dyn_test_model(1, &dd, &aa, &o);
	prsm_dyn_result direct;
	dyn_test_simulate(&direct, m);
	assert_int_equal(direct.points, r->points);
	for (size_t i = 0; i < r->points; i++) {
		assert_close(r->stage[i].carrier_ratio, direct.stage[i].carrier_ratio, 1e-12);
		assert_close(r->point[i].input_torque_Nm, direct.point[i].input_torque_Nm, 1e-12);
	}
	prsm_dyn_result_free(&direct);
	prsm_dyn_model_free(m);

	/* the echoed parameters are a dynamics object that gives the same run */
	cJSON *again = cJSON_CreateObject();
	cJSON_AddItemToObject(again, "design", cJSON_Parse(v1_design));
	cJSON_AddItemToObject(again, "dynamics", cJSON_Duplicate(at(d, "parameters"), 1));
	prsm_app_simulation *s2 = load_ok(again);
	run_ok(s2);
	const prsm_dyn_result *r2 = prsm_app_simulation_dyn_result(s2);
	assert_int_equal(r2->points, r->points);
	for (size_t i = 0; i < r->points; i++)
		assert_close(r2->point[i].input_torque_Nm, r->point[i].input_torque_Nm, 1e-12 * r->point[i].input_torque_Nm);
	prsm_app_simulation_free(s2);
	cJSON_Delete(again);

	/* CSV: a header and a row per output time, as many columns each */
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	assert_non_null(f);
	assert_int_equal(prsm_app_simulation_csv(f, s), 0);
	fclose(f);
	int rows = 0, commas_header = -1, commas = 0;
	for (size_t i = 0; i < len; i++) {
		if (buf[i] == ',')
			commas++;
		if (buf[i] == '\n') {
			if (commas_header < 0)
				commas_header = commas;
			else
				assert_int_equal(commas, commas_header);
			commas = 0;
			rows++;
		}
	}
	assert_int_equal(rows, 102);
	assert_true(strncmp(buf, "time_s,", 7) == 0);
	free(buf);
	/* text */
	buf = NULL;
	f = open_memstream(&buf, &len);
	assert_int_equal(prsm_app_simulation_text(f, s), 0);
	fclose(f);
	assert_non_null(strstr(buf, "k* 0.37369408"));
	free(buf);

	cJSON_Delete(res);
	prsm_app_simulation_free(s);
	cJSON_Delete(doc);
}

static void test_two_stages(void **state)
{
	(void)state;
	cJSON *doc = prsm_test_read_study("dynamics-seed000-row1.json");
	cJSON *t = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "dynamics"), "time");
	cJSON_ReplaceItemInObjectCaseSensitive(t, "end_s", cJSON_CreateNumber(5e-4));
	cJSON_ReplaceItemInObjectCaseSensitive(t, "output_step_s", cJSON_CreateNumber(5e-5));
	prsm_app_simulation *s = load_ok(doc);
	const prsm_dyn_options *o = prsm_dyn_model_options(prsm_app_simulation_model(s));
	/* the chain's couplings come from the multi-stage document; the seed's masses per stage */
	assert_true(o->couplings.spline_friction == 0.10);
	assert_true(o->couplings.thrust_bearing_friction == 0.055);
	assert_true(o->couplings.thrust_radius_mm[1] == 0.5 * (16.25 + 16.5));
	assert_true(o->inertia.stage[1].nut_mass_kg == 20.0);
	assert_true(o->inertia.stage[0].carrier_inertia_kg_m2 == 2.95e-6);
	run_ok(s);
	cJSON *res = prsm_app_simulation_result(s);
	assert_non_null(res);
	const cJSON *d = at(res, "dynamics");
	assert_int_equal((int)num(d, "stages"), 2);
	assert_int_equal(cJSON_GetArraySize(at(d, "transient/stages")), 2);
	assert_int_equal(cJSON_GetArraySize(at(d, "transient/stages/1/thrust_torque_Nm")), 11);
	assert_null(cJSON_GetObjectItemCaseSensitive(at(d, "transient/stages/0"), "thrust_torque_Nm"));
	assert_true(num(d, "settled/stages/1/thrust_torque_Nm") > 0.0);
	/* seed 000: stage 2 settles slightly higher than stage 1 */
	assert_true(num(d, "settled/stages/1/carrier_ratio") > num(d, "settled/stages/0/carrier_ratio"));
	/* the settled chain efficiency is the statics chain's (sliding only) */
	assert_close(num(d, "settled/efficiency"), num(d, "settled/efficiency_statics"), 1e-4);
	assert_int_equal(cJSON_GetArraySize(at(d, "parameters/inertia/stages")), 2);
	assert_true(cJSON_IsTrue(at(d, "checks/passed")));
	cJSON_Delete(res);
	prsm_app_simulation_free(s);
	cJSON_Delete(doc);
}

/* The request text's load problems: exactly one at pointer. */
static void refused_at(const char *text, const char *pointer, int want_rc)
{
	cJSON *doc = parse_ok(text);
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_app_simulation *s = (prsm_app_simulation *)1;
	const int rc = prsm_app_simulation_load(&s, doc, NULL, &p);
	cJSON_Delete(doc);
	assert_null(s);
	int n = 0;
	for (int i = 0; i < p.count; i++)
		n += strcmp(p.items[i].pointer, pointer) == 0;
	if (rc != want_rc || n != 1) {
		print_error("%s: rc %d, %d at %s\n", text, rc, n, pointer);
		dump(&p);
		fail();
	}
}

static void test_refused_at_their_pointers(void **state)
{
	(void)state;
	char text[4096];
	refused_at("[1]", "", PRSM_EINVAL);
	refused_at(v1_design, "", PRSM_EINVAL); /* a plain design */
	snprintf(text, sizeof text, "{\"design\": %s}", v1_design);
	refused_at(text, "/dynamics", PRSM_EINVAL);
	snprintf(text, sizeof text, "{\"design\": %s, \"errors\": {}, \"dynamics\": {}}", v1_design);
	refused_at(text, "/errors", PRSM_EINVAL);
	snprintf(text, sizeof text, "{\"design\": %s, \"dynamics\": {\"time\": {\"end_s\": 0}}}", v1_design);
	refused_at(text, "/dynamics/time/end_s", PRSM_EINVAL);
	/* the design's own problems under /design, with the dynamics' */
	snprintf(text, sizeof text, "{\"design\": {\"geometry\": {\"starts\": 0}}, \"dynamics\": {\"losses\": 1}}");
	refused_at(text, "/dynamics/losses", PRSM_EINVAL);
	/* the model: rollers that migrate (r_n is not n r_r) */
	refused_at("{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"flank_angle_deg\": 45, "
	           "\"roller_radius_mm\": 3.25, \"screw_radius_mm\": 9.75, \"nut_radius_mm\": 16.5, \"rollers\": 10, "
	           "\"engaged_threads\": 10}}, \"dynamics\": {}}",
	           "/design/geometry/nut_radius_mm", PRSM_EINVAL);
	/* a chain: its stages' masses in stages, one per stage */
	cJSON *doc = prsm_test_read_study("dynamics-seed000-row2.json");
	cJSON *in = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "dynamics"), "inertia");
	cJSON_DeleteItemFromArray(cJSON_GetObjectItemCaseSensitive(in, "stages"), 1);
	char *chain = cJSON_PrintUnformatted(doc);
	refused_at(chain, "/dynamics/inertia/stages", PRSM_EINVAL);
	free(chain);
	cJSON_Delete(doc);
}

static void test_no_result_without_convergence(void **state)
{
	(void)state;
	cJSON *doc = request("{\"time\": {\"end_s\": 0.001, \"max_steps\": 3}}");
	cJSON *res = (cJSON *)1;
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_app_simulate(&res, doc, NULL, NULL, NULL, 0.0, &p, &err);
	assert_int_equal(rc, PRSM_ENOCONVERGE);
	assert_null(res);
	assert_string_equal(err.pointer, "/dynamics/time");
	assert_non_null(strstr(err.message, "did not converge"));
	/* cancelled before it starts, and out of time */
	prsm_cancel_flag stop = 1;
	rc = prsm_app_simulate(&res, doc, &stop, NULL, NULL, 0.0, &p, &err);
	assert_int_equal(rc, PRSM_ECANCELLED);
	assert_null(res);
	cJSON_Delete(doc);
	doc = request(v1_dynamics);
	rc = prsm_app_simulate(&res, doc, NULL, NULL, NULL, 1e-12, &p, &err);
	assert_int_equal(rc, PRSM_ECANCELLED);
	assert_null(res);
	assert_non_null(strstr(err.message, "time cap"));
	/* and with time enough: a result */
	rc = prsm_app_simulate(&res, doc, NULL, NULL, NULL, 600.0, &p, &err);
	assert_int_equal(rc, 0);
	assert_non_null(res);
	cJSON_Delete(res);
	cJSON_Delete(doc);
}

static void test_analyze_checks_but_does_not_simulate(void **state)
{
	(void)state;
	cJSON *doc = request(v1_dynamics), *res = NULL;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_analyze(&res, doc, &p), 0);
	assert_null(cJSON_GetObjectItemCaseSensitive(res, "dynamics"));
	const cJSON *w = cJSON_GetObjectItemCaseSensitive(res, "warnings");
	int noted = 0;
	for (const cJSON *it = w ? w->child : NULL; it; it = it->next)
		noted += strcmp(cJSON_GetObjectItemCaseSensitive(it, "code")->valuestring, "not_simulated") == 0;
	assert_int_equal(noted, 1);
	cJSON_Delete(res);
	cJSON_Delete(doc);
	/* its dynamics object is checked */
	doc = request("{\"time\": {\"end_s\": -1}}");
	res = NULL;
	prsm_problems_init(&p);
	assert_int_equal(prsm_app_analyze(&res, doc, &p), PRSM_EINVAL);
	assert_true(find(&p, "/dynamics/time/end_s", "range") >= 0);
	cJSON_Delete(doc);
}

/* The job kind (job/kind_simulation.c): normalise, then run with progress and the service's time
 * cap, the result and the time series handed back; a run cancelled from another thread. */
typedef struct {
	const prsm_job_kind *kind;
	char *request;
	prsm_cancel_flag cancel;
	atomic_int reports;
	int rc;
	prsm_job_output out;
	prsm_error err;
} kind_run;

static void count_progress(void *ctx, const prsm_progress *p)
{
	kind_run *k = ctx;
	assert_true(p->done <= p->planned);
	atomic_fetch_add(&k->reports, 1);
}

static void *run_kind(void *arg)
{
	kind_run *k = arg;
	prsm_job_run_ctx ctx = {&k->cancel, count_progress, k, {0, 600.0, 1}};
	k->rc = k->kind->run(&k->out, k->request, &ctx, &k->err);
	return NULL;
}

static char *normalised(const prsm_job_kind *kind, cJSON *doc)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_job_limits lim = {0, 600.0, 1};
	cJSON *norm = NULL;
	if (kind->normalise(&norm, doc, &lim, &p)) {
		dump(&p);
		fail();
	}
	char *text = cJSON_PrintUnformatted(norm);
	cJSON_Delete(norm);
	return text;
}

static void test_job_kind(void **state)
{
	(void)state;
	const prsm_job_kind *kind = prsm_job_kind_by_name("simulation");
	assert_non_null(kind);
	assert_ptr_equal(prsm_job_kind_by_collection("simulations"), kind);
	assert_string_equal(kind->progress_unit, "simulated_ns");
	/* the unit of a stored request follows its analysis */
	assert_non_null(kind->progress_unit_of);
	const char *units[][2] = {{"transient", "simulated_ns"}, {"sweep", "sweep_points"},
	                          {"frequency_response", "sweep_points"}, {"basins", "basin_cells"},
	                          {"linear", "analyses"}, {"vibration", "analyses"}};
	for (size_t i = 0; i < sizeof units / sizeof units[0]; i++) {
		char rq[128];
		snprintf(rq, sizeof rq, "{\"dynamics\": {\"analysis\": \"%s\"}}", units[i][0]);
		assert_string_equal(kind->progress_unit_of(rq), units[i][1]);
	}
	assert_string_equal(kind->progress_unit_of("{\"dynamics\": {}}"), "simulated_ns");
	assert_non_null(strstr(kind->version(), PRSM_DYN_MODEL_VERSION));
	cJSON *doc = request(v1_dynamics);
	kind_run k = {kind, normalised(kind, doc), 0, 0, 0, {0}, PRSM_ERROR_INIT};
	run_kind(&k);
	assert_int_equal(k.rc, 0);
	assert_true(atomic_load(&k.reports) > 0);
	assert_int_equal((int)k.out.samples_done, 1000000); /* 1 ms simulated */
	cJSON *res = cJSON_Parse(k.out.result);
	assert_non_null(res);
	assert_rel(num(res, "dynamics/settled/efficiency"), 0.9922054, 1e-6);
	cJSON_Delete(res);
	assert_non_null(k.out.csv);
	assert_true(strncmp(k.out.csv, "time_s,", 7) == 0);
	prsm_job_output_free(&k.out);
	free(k.request);
	cJSON_Delete(doc);
	/* the service's cap on output times, at the output step */
	doc = request("{\"time\": {\"end_s\": 0.5, \"output_step_s\": 1e-6}}");
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_job_limits lim = {0, 0.0, 1};
	cJSON *norm = NULL;
	assert_int_equal(kind->normalise(&norm, doc, &lim, &p), PRSM_EINVAL);
	assert_true(find(&p, "/dynamics/time/output_step_s", "service_cap") >= 0);
	cJSON_Delete(doc);
	/* a long run, cancelled from this thread while a worker runs it */
	doc = request("{\"input\": {\"shape\": \"sine\", \"value_rad_s\": 100, \"sine_amplitude_rad_s\": 50, "
	              "\"sine_frequency_Hz\": 2000}, \"time\": {\"end_s\": 100, \"output_step_s\": 0.001}}");
	kind_run c = {kind, normalised(kind, doc), 0, 0, 0, {0}, PRSM_ERROR_INIT};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, run_kind, &c), 0);
	while (atomic_load(&c.reports) == 0)
		sched_yield();
	prsm_cancel_set(&c.cancel, 1);
	pthread_join(th, NULL);
	assert_int_equal(c.rc, PRSM_ECANCELLED);
	assert_null(c.out.result);
	free(c.request);
	cJSON_Delete(doc);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_v1_in_the_result),
		cmocka_unit_test(test_two_stages),
		cmocka_unit_test(test_refused_at_their_pointers),
		cmocka_unit_test(test_no_result_without_convergence),
		cmocka_unit_test(test_analyze_checks_but_does_not_simulate),
		cmocka_unit_test(test_job_kind),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
