/*
 * test_io_errors.c: the analyze request's `errors` and `assembly` objects (io/errors_json):
 * every field with its unit factor, absent fields, every kind of problem at its exact pointer
 * (and all of them at once), the assembly options with their sample-count rule, and the round
 * trip errors -> JSON -> errors.
 */
#include "test_support.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "io/errors_json.h"
#include "io/json_util.h"

#include "test_problems.h"

/* ---- helpers ---------------------------------------------------------------------------- */

/* The message of the problem [code] at pointer; fails the test when there is none. */
static const char *expect(const prsm_problems *p, const char *pointer, const char *code)
{
	int i = find(p, pointer, code);
	if (i < 0) {
		dump(p);
		fail_msg("no problem [%s] at \"%s\"", code, pointer);
	}
	return p->items[i].message;
}

static void expect_count(const prsm_problems *p, int n)
{
	if (p->count != n) {
		dump(p);
		fail_msg("%d problems, expected %d", p->count, n);
	}
}

static prsm_design case_a_design(void)
{
	prsm_design d;
	case_a(&d); /* Z = 10, n = 5, P = 2 mm: lead 10 mm */
	assert_int_equal(d.rollers, 10);
	assert_int_equal(d.starts, 5);
	return d;
}

/* Read the errors object of text (at "/errors") for case A. */
static int read_errors(prsm_errors *e, prsm_problems *p, const char *text)
{
	prsm_design d = case_a_design();
	cJSON *doc = parse_ok(text);
	prsm_problems_init(p);
	int rc = prsm_io_errors_from_json(e, doc, "/errors", &d, p);
	cJSON_Delete(doc);
	return rc;
}

static int read_options(prsm_assembly_options *o, prsm_problems *p, const char *text)
{
	prsm_design d = case_a_design();
	cJSON *doc = parse_ok(text);
	prsm_problems_init(p);
	int rc = prsm_io_assembly_options_from_json(o, doc, "/assembly", &d, p);
	cJSON_Delete(doc);
	return rc;
}

/* Relative tolerance of a unit conversion (one or two roundings). */
#define CONV(x) (4.0 * DBL_EPSILON * fabs(x))
#define UM(x) ((x) / 1000.0)                   /* µm -> mm */
#define MRAD(x) ((x) / 1000.0)                 /* mrad -> rad */
#define DEGR(x) ((x) * M_PI / 180.0)           /* deg -> rad */
#define LEAD(x) ((x) / 1000.0 / 300.0)         /* µm per 300 mm -> mm per mm */
#define assert_conv(actual, expected) assert_close(actual, expected, CONV(expected))

/* Doubles of a struct made only of doubles, compared bit for bit. */
static int same_doubles(const void *a, const void *b, size_t size)
{
	return memcmp(a, b, size) == 0;
}

static void assert_same_errors(const prsm_errors *a, const prsm_errors *b)
{
	assert_int_equal(a->rollers, b->rollers);
	assert_true(same_doubles(&a->screw, &b->screw, sizeof a->screw));
	assert_true(same_doubles(&a->nut, &b->nut, sizeof a->nut));
	assert_true(same_doubles(&a->carrier, &b->carrier, sizeof a->carrier));
	for (int j = 0; j < a->rollers; j++)
		assert_true(same_doubles(&a->roller[j], &b->roller[j], sizeof a->roller[j]));
}

/* ---- every field converts ---------------------------------------------------------------- */

/* Roller j's value of roller field i (API units), varied and non-round; the magnitudes
 * (runout_um, i = 3, and lead_periodic_um, i = 6) stay positive. */
static const char *const roller_json_keys[] = {
	"pitch_radius_um", "thickness_um", "arc_radius_um", "runout_um", "runout_phase_deg",
	"lead_deviation_um_per_300mm", "lead_periodic_um", "lead_periodic_phase_deg",
	"pin_radial_um", "pin_tangential_um", "gear_phase_mrad", "tilt_radial_mrad",
	"tilt_tangential_mrad"};
static const double roller_base[] = {2.113, -3.271, 5.417, 1.931, 47.17, 8.191, 0.733, -151.3,
                                     4.441, -2.297, 0.613, 0.0917, -0.0533};
#define ROLLER_FIELDS 13

static double roller_value(int j, int i)
{
	double v = roller_base[i] * (1.0 + 0.0731 * j);
	if (i != 3 && i != 6 && (j % 2) == 1)
		v = -v;
	return v;
}

static const char *const full_screw =
	"{\"pitch_radius_um\": 3.17, \"thickness_um\": -7.43, \"flank_angle_mrad\": 1.29,"
	" \"runout_um\": 4.61, \"runout_phase_deg\": 37.3, \"lead_deviation_um_per_300mm\": -12.7,"
	" \"lead_periodic_um\": 2.83, \"lead_periodic_phase_deg\": -113.9,"
	" \"start_index_mrad\": [0.11, -0.23, 0.37, -0.41, 0.53],"
	" \"tilt_mrad\": 0.087, \"tilt_phase_deg\": 211.4}";
static const char *const full_nut =
	"{\"pitch_radius_um\": -5.93, \"thickness_um\": 2.39, \"flank_angle_mrad\": -0.77,"
	" \"runout_um\": 8.09, \"runout_phase_deg\": -250.6, \"lead_deviation_um_per_300mm\": 6.47,"
	" \"lead_periodic_um\": 1.57, \"lead_periodic_phase_deg\": 19.1,"
	" \"start_index_mrad\": [-0.07, 0.19, -0.31, 0.43, -0.59],"
	" \"tilt_mrad\": 0.0413, \"tilt_phase_deg\": -33.3}";

static void full_document_converts_every_field(void **state)
{
	(void)state;
	char text[8192];
	size_t k = (size_t)snprintf(text, sizeof text,
	                            "{\"screw\": %s, \"nut\": %s,"
	                            " \"carrier\": {\"runout_um\": 6.73, \"runout_phase_deg\": -71.2},"
	                            " \"rollers\": [", full_screw, full_nut);
	for (int j = 0; j < 10; j++) {
		k += (size_t)snprintf(text + k, sizeof text - k, "%s{", j ? ", " : "");
		for (int i = 0; i < ROLLER_FIELDS; i++)
			k += (size_t)snprintf(text + k, sizeof text - k, "%s\"%s\": %.17g", i ? ", " : "",
			                      roller_json_keys[i], roller_value(j, i));
		k += (size_t)snprintf(text + k, sizeof text - k, "}");
	}
	k += (size_t)snprintf(text + k, sizeof text - k, "]}");
	assert_true(k < sizeof text);

	prsm_errors e;
	prsm_problems p;
	int rc = read_errors(&e, &p, text);
	if (rc != 0)
		dump(&p);
	assert_int_equal(rc, 0);
	assert_int_equal(p.count, 0);
	assert_int_equal(e.rollers, 10);

	const prsm_body_errors *s = &e.screw;
	assert_conv(s->pitch_radius_mm, UM(3.17));
	assert_conv(s->thickness_mm, UM(-7.43));
	assert_conv(s->flank_angle_rad, MRAD(1.29));
	assert_conv(s->runout_mm, UM(4.61));
	assert_conv(s->runout_phase_rad, DEGR(37.3));
	assert_conv(s->lead_deviation, LEAD(-12.7));
	assert_conv(s->lead_periodic_mm, UM(2.83));
	assert_conv(s->lead_periodic_phase_rad, DEGR(-113.9));
	const double screw_index[] = {0.11, -0.23, 0.37, -0.41, 0.53};
	for (int i = 0; i < 5; i++)
		assert_conv(s->start_index_rad[i], MRAD(screw_index[i]));
	for (int i = 5; i < PRSM_ERRORS_MAX_STARTS; i++)
		assert_true(s->start_index_rad[i] == 0.0);
	assert_conv(s->tilt_rad, MRAD(0.087));
	assert_conv(s->tilt_phase_rad, DEGR(211.4));

	const prsm_body_errors *n = &e.nut;
	assert_conv(n->pitch_radius_mm, UM(-5.93));
	assert_conv(n->thickness_mm, UM(2.39));
	assert_conv(n->flank_angle_rad, MRAD(-0.77));
	assert_conv(n->runout_mm, UM(8.09));
	assert_conv(n->runout_phase_rad, DEGR(-250.6));
	assert_conv(n->lead_deviation, LEAD(6.47));
	assert_conv(n->lead_periodic_mm, UM(1.57));
	assert_conv(n->lead_periodic_phase_rad, DEGR(19.1));
	const double nut_index[] = {-0.07, 0.19, -0.31, 0.43, -0.59};
	for (int i = 0; i < 5; i++)
		assert_conv(n->start_index_rad[i], MRAD(nut_index[i]));
	assert_conv(n->tilt_rad, MRAD(0.0413));
	assert_conv(n->tilt_phase_rad, DEGR(-33.3));

	assert_conv(e.carrier.runout_mm, UM(6.73));
	assert_conv(e.carrier.runout_phase_rad, DEGR(-71.2));

	for (int j = 0; j < 10; j++) {
		const prsm_roller_errors *r = &e.roller[j];
		assert_conv(r->pitch_radius_mm, UM(roller_value(j, 0)));
		assert_conv(r->thickness_mm, UM(roller_value(j, 1)));
		assert_conv(r->arc_radius_mm, UM(roller_value(j, 2)));
		assert_conv(r->runout_mm, UM(roller_value(j, 3)));
		assert_conv(r->runout_phase_rad, DEGR(roller_value(j, 4)));
		assert_conv(r->lead_deviation, LEAD(roller_value(j, 5)));
		assert_conv(r->lead_periodic_mm, UM(roller_value(j, 6)));
		assert_conv(r->lead_periodic_phase_rad, DEGR(roller_value(j, 7)));
		assert_conv(r->pin_radial_mm, UM(roller_value(j, 8)));
		assert_conv(r->pin_tangential_mm, UM(roller_value(j, 9)));
		assert_conv(r->gear_phase_rad, MRAD(roller_value(j, 10)));
		assert_conv(r->tilt_radial_rad, MRAD(roller_value(j, 11)));
		assert_conv(r->tilt_tangential_rad, MRAD(roller_value(j, 12)));
	}
	assert_false(prsm_errors_all_zero(&e));
}

static void absent_fields_are_zero(void **state)
{
	(void)state;
	prsm_errors e, zero;
	prsm_problems p;
	prsm_errors_zero(&zero, 10);

	/* no errors object at all */
	prsm_design d = case_a_design();
	prsm_problems_init(&p);
	memset(&e, 0x55, sizeof e);
	assert_int_equal(prsm_io_errors_from_json(&e, NULL, "/errors", &d, &p), 0);
	assert_int_equal(p.count, 0);
	assert_same_errors(&e, &zero);

	/* an empty one, and empty parts */
	memset(&e, 0x55, sizeof e);
	assert_int_equal(read_errors(&e, &p, "{}"), 0);
	assert_same_errors(&e, &zero);
	assert_true(prsm_errors_all_zero(&e));
	assert_int_equal(read_errors(&e, &p, "{\"screw\": {}, \"nut\": {}, \"carrier\": {},"
	                                     " \"rollers\": [{}, {}, {}, {}, {}, {}, {}, {}, {}, {}]}"), 0);
	assert_same_errors(&e, &zero);

	/* one field: only it is set */
	assert_int_equal(read_errors(&e, &p, "{\"nut\": {\"runout_um\": 12.5},"
	                                     " \"rollers\": [{}, {}, {}, {\"gear_phase_mrad\": -0.25},"
	                                     " {}, {}, {}, {}, {}, {}]}"), 0);
	assert_conv(e.nut.runout_mm, 0.0125);
	assert_conv(e.roller[3].gear_phase_rad, -0.00025);
	e.nut.runout_mm = 0.0;
	e.roller[3].gear_phase_rad = 0.0;
	assert_same_errors(&e, &zero);
}

static void limits_are_inclusive(void **state)
{
	(void)state;
	prsm_errors e;
	prsm_problems p;
	int rc = read_errors(&e, &p,
		"{\"screw\": {\"pitch_radius_um\": -500, \"thickness_um\": 500, \"flank_angle_mrad\": -50,"
		"  \"runout_um\": 500, \"runout_phase_deg\": -3600, \"lead_deviation_um_per_300mm\": 1000,"
		"  \"lead_periodic_um\": 0, \"lead_periodic_phase_deg\": 3600,"
		"  \"start_index_mrad\": [-100, 100, 0, 0, 0], \"tilt_mrad\": 20, \"tilt_phase_deg\": 3600},"
		" \"nut\": {\"lead_deviation_um_per_300mm\": -1000, \"tilt_mrad\": 0},"
		" \"carrier\": {\"runout_um\": 0, \"runout_phase_deg\": -3600},"
		" \"rollers\": [{\"arc_radius_um\": -500, \"pin_radial_um\": 500, \"pin_tangential_um\": -500,"
		"  \"gear_phase_mrad\": 100, \"tilt_radial_mrad\": -20, \"tilt_tangential_mrad\": 20},"
		"  {}, {}, {}, {}, {}, {}, {}, {}, {\"gear_phase_mrad\": -100}]}");
	if (rc != 0)
		dump(&p);
	assert_int_equal(rc, 0);
	assert_conv(e.screw.runout_mm, 0.5);
	assert_conv(e.screw.lead_deviation, 1.0 / 300.0);
	assert_conv(e.screw.runout_phase_rad, -20.0 * M_PI);
	assert_conv(e.roller[9].gear_phase_rad, -0.1);
	assert_conv(e.roller[0].tilt_tangential_rad, 0.02);
}

/* ---- problems ---------------------------------------------------------------------------- */

static const struct {
	const char *text;    /* the errors object */
	const char *pointer; /* the one problem it has */
	const char *code;
} bad[] = {
	/* wrong types (the toolkit refuses NaN/inf literals; strings, null, booleans here) */
	{"[]", "/errors", "type"},
	{"{\"screw\": 5}", "/errors/screw", "type"},
	{"{\"carrier\": []}", "/errors/carrier", "type"},
	{"{\"screw\": {\"runout_um\": \"3\"}}", "/errors/screw/runout_um", "type"},
	{"{\"screw\": {\"thickness_um\": null}}", "/errors/screw/thickness_um", "type"},
	{"{\"nut\": {\"flank_angle_mrad\": true}}", "/errors/nut/flank_angle_mrad", "type"},
	{"{\"carrier\": {\"runout_phase_deg\": {}}}", "/errors/carrier/runout_phase_deg", "type"},
	{"{\"nut\": {\"start_index_mrad\": 0.3}}", "/errors/nut/start_index_mrad", "type"},
	{"{\"nut\": {\"start_index_mrad\": [0, 0, \"x\", 0, 0]}}", "/errors/nut/start_index_mrad/2", "type"},
	{"{\"nut\": {\"start_index_mrad\": [0, 0, 0, 0, null]}}", "/errors/nut/start_index_mrad/4", "type"},
	{"{\"rollers\": {}}", "/errors/rollers", "type"},
	{"{\"rollers\": [{}, {}, {}, 5, {}, {}, {}, {}, {}, {}]}", "/errors/rollers/3", "type"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {}, {}, {}, {}, null]}", "/errors/rollers/9", "type"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {\"thickness_um\": \"-2\"}, {}, {}, {}, {}]}",
	 "/errors/rollers/5/thickness_um", "type"},
	{"{\"screw\": {\"pitch_radius_um\": 1e999}}", "/errors/screw/pitch_radius_um", "not_finite"},
	/* out of range */
	{"{\"screw\": {\"pitch_radius_um\": 500.5}}", "/errors/screw/pitch_radius_um", "range"},
	{"{\"nut\": {\"thickness_um\": -501}}", "/errors/nut/thickness_um", "range"},
	{"{\"screw\": {\"flank_angle_mrad\": 50.01}}", "/errors/screw/flank_angle_mrad", "range"},
	{"{\"screw\": {\"runout_um\": 500.001}}", "/errors/screw/runout_um", "range"},
	{"{\"screw\": {\"runout_phase_deg\": 3600.1}}", "/errors/screw/runout_phase_deg", "range"},
	{"{\"nut\": {\"lead_periodic_phase_deg\": -3601}}", "/errors/nut/lead_periodic_phase_deg", "range"},
	{"{\"screw\": {\"lead_deviation_um_per_300mm\": -1000.5}}",
	 "/errors/screw/lead_deviation_um_per_300mm", "range"},
	{"{\"screw\": {\"tilt_mrad\": 20.5}}", "/errors/screw/tilt_mrad", "range"},
	{"{\"nut\": {\"start_index_mrad\": [0, 0, 0, 100.5, 0]}}", "/errors/nut/start_index_mrad/3", "range"},
	{"{\"rollers\": [{\"gear_phase_mrad\": 100.1}, {}, {}, {}, {}, {}, {}, {}, {}, {}]}",
	 "/errors/rollers/0/gear_phase_mrad", "range"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {}, {}, {}, {}, {\"tilt_radial_mrad\": -20.1}]}",
	 "/errors/rollers/9/tilt_radial_mrad", "range"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {}, {}, {}, {\"pin_tangential_um\": 600}, {}]}",
	 "/errors/rollers/8/pin_tangential_um", "range"},
	/* negative magnitudes */
	{"{\"screw\": {\"runout_um\": -0.5}}", "/errors/screw/runout_um", "range"},
	{"{\"nut\": {\"lead_periodic_um\": -1}}", "/errors/nut/lead_periodic_um", "range"},
	{"{\"carrier\": {\"runout_um\": -2}}", "/errors/carrier/runout_um", "range"},
	{"{\"screw\": {\"tilt_mrad\": -0.1}}", "/errors/screw/tilt_mrad", "range"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {}, {}, {\"runout_um\": -1}, {}, {}]}",
	 "/errors/rollers/7/runout_um", "range"},
	/* unknown and duplicate keys */
	{"{\"colour\": 1}", "/errors/colour", "unknown_field"},
	{"{\"screw\": {\"runout\": 3}}", "/errors/screw/runout", "unknown_field"},
	{"{\"carrier\": {\"tilt_mrad\": 1}}", "/errors/carrier/tilt_mrad", "unknown_field"},
	{"{\"screw\": {\"a/b\": 1}}", "/errors/screw/a~1b", "unknown_field"},
	{"{\"rollers\": [{}, {}, {\"pin\": 1}, {}, {}, {}, {}, {}, {}, {}]}", "/errors/rollers/2/pin",
	 "unknown_field"},
	{"{\"screw\": {\"runout_um\": 1, \"runout_um\": 2}}", "/errors/screw/runout_um", "duplicate_key"},
	{"{\"screw\": {}, \"screw\": {}}", "/errors/screw", "duplicate_key"},
	/* array lengths */
	{"{\"screw\": {\"start_index_mrad\": [0, 0, 0, 0]}}", "/errors/screw/start_index_mrad",
	 "array_length"},
	{"{\"nut\": {\"start_index_mrad\": [0, 0, 0, 0, 0, 0]}}", "/errors/nut/start_index_mrad",
	 "array_length"},
	{"{\"rollers\": []}", "/errors/rollers", "array_length"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {}, {}, {}, {}]}", "/errors/rollers", "array_length"},
	{"{\"rollers\": [{}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}]}", "/errors/rollers", "array_length"},
};

static void every_bad_input_at_its_pointer(void **state)
{
	(void)state;
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		prsm_errors e;
		prsm_problems p;
		int rc = read_errors(&e, &p, bad[i].text);
		if (rc != PRSM_EINVAL || p.count != 1 || find(&p, bad[i].pointer, bad[i].code) != 0) {
			dump(&p);
			fail_msg("%s: expected one problem [%s] at \"%s\" (rc %d, %d problems)", bad[i].text,
			         bad[i].code, bad[i].pointer, rc, p.count);
		}
	}
}

static void messages_name_the_limits(void **state)
{
	(void)state;
	prsm_errors e;
	prsm_problems p;
	assert_int_equal(read_errors(&e, &p, "{\"screw\": {\"runout_um\": -0.5, \"tilt_mrad\": -1},"
	                                     " \"nut\": {\"thickness_um\": 600, \"start_index_mrad\": [1]},"
	                                     " \"rollers\": [{}]}"), PRSM_EINVAL);
	expect_count(&p, 5);
	const char *m = expect(&p, "/errors/screw/runout_um", "range");
	assert_non_null(strstr(m, "from 0 to 500"));
	assert_non_null(strstr(m, "runout_phase_deg"));
	m = expect(&p, "/errors/screw/tilt_mrad", "range");
	assert_non_null(strstr(m, "from 0 to 20"));
	assert_non_null(strstr(m, "tilt_phase_deg"));
	assert_string_equal(expect(&p, "/errors/nut/thickness_um", "range"),
	                    "must be a number <= 500 (got 600)");
	assert_string_equal(expect(&p, "/errors/nut/start_index_mrad", "array_length"),
	                    "must have exactly 5 elements, one per start of the design (n = 5); got 1");
	assert_string_equal(expect(&p, "/errors/rollers", "array_length"),
	                    "must have exactly 10 elements, one per roller of the design (Z = 10); got 1");
	/* the type messages give the whole range */
	assert_int_equal(read_errors(&e, &p, "{\"nut\": {\"pitch_radius_um\": \"1\"}}"), PRSM_EINVAL);
	assert_string_equal(expect(&p, "/errors/nut/pitch_radius_um", "type"),
	                    "must be a number from -500 to 500 (got the string \"1\")");
}

static void all_problems_at_once(void **state)
{
	(void)state;
	prsm_errors e;
	prsm_problems p;
	int rc = read_errors(&e, &p,
		"{\"screw\": {\"runout_um\": -1, \"flank_angle_mrad\": \"x\", \"start_index_mrad\": [1, 2],"
		"  \"thickness_um\": 4.5},"
		" \"nut\": {\"tilt_mrad\": 30, \"bogus\": 1, \"pitch_radius_um\": -2.5},"
		" \"carrier\": [],"
		" \"rollers\": [{\"gear_phase_mrad\": 200, \"gear_phase_mrad\": 0}, 7],"
		" \"extra\": null}");
	assert_int_equal(rc, PRSM_EINVAL);
	expect(&p, "/errors/screw/runout_um", "range");
	expect(&p, "/errors/screw/flank_angle_mrad", "type");
	expect(&p, "/errors/screw/start_index_mrad", "array_length");
	expect(&p, "/errors/nut/tilt_mrad", "range");
	expect(&p, "/errors/nut/bogus", "unknown_field");
	expect(&p, "/errors/carrier", "type");
	expect(&p, "/errors/rollers", "array_length");
	expect(&p, "/errors/rollers/0/gear_phase_mrad", "range");
	expect(&p, "/errors/rollers/0/gear_phase_mrad", "duplicate_key");
	expect(&p, "/errors/rollers/1", "type");
	expect(&p, "/errors/extra", "unknown_field");
	expect_count(&p, 11);
	/* the valid fields around them were still read */
	assert_conv(e.screw.thickness_mm, 0.0045);
	assert_conv(e.nut.pitch_radius_mm, -0.0025);
	assert_conv(e.screw.start_index_rad[0], 0.001);
	assert_conv(e.screw.start_index_rad[1], 0.002);
}

/* An unknown design (its document was invalid: 0 rollers, 0 starts): the array lengths cannot
 * be checked, everything else is, so a request's problems all show at once. */
static void unknown_design_checks_all_but_lengths(void **state)
{
	(void)state;
	prsm_design d;
	prsm_design_init(&d);
	d.rollers = d.starts = 0;
	cJSON *doc = parse_ok("{\"screw\": {\"runout_um\": -1, \"start_index_mrad\": [1, 2, 300]},"
	                      " \"rollers\": [{}, {\"bogus\": 1}]}");
	prsm_errors e;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_errors_from_json(&e, doc, "/errors", &d, &p), PRSM_EINVAL);
	expect(&p, "/errors/screw/runout_um", "range");
	expect(&p, "/errors/screw/start_index_mrad/2", "range");
	expect(&p, "/errors/rollers/1/bogus", "unknown_field");
	expect_count(&p, 3);
	cJSON_Delete(doc);
	/* and the options: every field, the sample rule needs the lead */
	doc = parse_ok("{\"mode\": \"fast\", \"stroke_mm\": 1e6}");
	prsm_assembly_options o;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_assembly_options_from_json(&o, doc, "/assembly", &d, &p), PRSM_EINVAL);
	expect(&p, "/assembly/mode", "enum");
	expect(&p, "/assembly/stroke_mm", "range");
	expect_count(&p, 2);
	cJSON_Delete(doc);
}

static void pointer_prefixes_every_problem(void **state)
{
	(void)state;
	prsm_design d = case_a_design();
	cJSON *doc = parse_ok("{\"screw\": {\"runout_um\": -1}}");
	prsm_errors e;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_errors_from_json(&e, doc, "/samples/3/errors", &d, &p), PRSM_EINVAL);
	expect(&p, "/samples/3/errors/screw/runout_um", "range");
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_errors_from_json(&e, doc, "", &d, &p), PRSM_EINVAL);
	expect(&p, "/screw/runout_um", "range");
	cJSON_Delete(doc);
}

/* ---- assembly options -------------------------------------------------------------------- */

static void assert_default_options(const prsm_assembly_options *o)
{
	assert_int_equal(o->mode, PRSM_MODE_LINEAR);
	assert_close(o->measuring_load_N, 50.0, 0.0);
	assert_int_equal(o->angles_per_revolution, 64);
	assert_close(o->stroke_mm, 0.0, 0.0);
	assert_int_equal(o->spectrum_revolutions, 16);
	assert_int_equal(o->curve, 0);
}

static void assembly_defaults(void **state)
{
	(void)state;
	prsm_design d = case_a_design();
	prsm_assembly_options o;
	prsm_problems p;
	prsm_problems_init(&p);
	memset(&o, 0x55, sizeof o);
	assert_int_equal(prsm_io_assembly_options_from_json(&o, NULL, "/assembly", &d, &p), 0);
	assert_default_options(&o);
	memset(&o, 0x55, sizeof o);
	assert_int_equal(read_options(&o, &p, "{}"), 0);
	assert_int_equal(p.count, 0);
	assert_default_options(&o);
}

static void assembly_every_field(void **state)
{
	(void)state;
	prsm_assembly_options o;
	prsm_problems p;
	int rc = read_options(&o, &p, "{\"mode\": \"exact\", \"measuring_load_N\": 123.5,"
	                              " \"angles_per_revolution\": 256, \"stroke_mm\": 250.75,"
	                              " \"spectrum_revolutions\": 32, \"curve\": true}");
	if (rc != 0)
		dump(&p);
	assert_int_equal(rc, 0);
	assert_int_equal(o.mode, PRSM_MODE_EXACT);
	assert_close(o.measuring_load_N, 123.5, 0.0);
	assert_int_equal(o.angles_per_revolution, 256);
	assert_close(o.stroke_mm, 250.75, 0.0);
	assert_int_equal(o.spectrum_revolutions, 32);
	assert_int_equal(o.curve, 1);

	/* one field: the others keep their defaults */
	assert_int_equal(read_options(&o, &p, "{\"mode\": \"linear\", \"curve\": false}"), 0);
	assert_default_options(&o);
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 8.0}"), 0);
	assert_int_equal(o.angles_per_revolution, 8);
	assert_int_equal(o.spectrum_revolutions, 16);
	/* limits are inclusive where the schema says so */
	assert_int_equal(read_options(&o, &p, "{\"measuring_load_N\": 1e6, \"angles_per_revolution\": 4096,"
	                                      " \"stroke_mm\": 0, \"spectrum_revolutions\": 1}"), 0);
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 8, \"stroke_mm\": 10000,"
	                                      " \"spectrum_revolutions\": 1000}"), 0);
}

static const struct {
	const char *text, *pointer, *code;
} bad_options[] = {
	{"[]", "/assembly", "type"},
	{"{\"mode\": \"Exact\"}", "/assembly/mode", "enum"},
	{"{\"mode\": \"nonlinear\"}", "/assembly/mode", "enum"},
	{"{\"mode\": 1}", "/assembly/mode", "type"},
	{"{\"measuring_load_N\": 0}", "/assembly/measuring_load_N", "range"},
	{"{\"measuring_load_N\": -5}", "/assembly/measuring_load_N", "range"},
	{"{\"measuring_load_N\": 1000000.5}", "/assembly/measuring_load_N", "range"},
	{"{\"measuring_load_N\": \"50\"}", "/assembly/measuring_load_N", "type"},
	{"{\"angles_per_revolution\": 7}", "/assembly/angles_per_revolution", "range"},
	{"{\"angles_per_revolution\": 4097}", "/assembly/angles_per_revolution", "range"},
	{"{\"angles_per_revolution\": 64.5}", "/assembly/angles_per_revolution", "not_integer"},
	{"{\"angles_per_revolution\": null}", "/assembly/angles_per_revolution", "type"},
	{"{\"stroke_mm\": -0.1}", "/assembly/stroke_mm", "range"},
	{"{\"stroke_mm\": 10000.01}", "/assembly/stroke_mm", "range"},
	{"{\"spectrum_revolutions\": 0}", "/assembly/spectrum_revolutions", "range"},
	{"{\"spectrum_revolutions\": 1001}", "/assembly/spectrum_revolutions", "range"},
	{"{\"spectrum_revolutions\": 2.5}", "/assembly/spectrum_revolutions", "not_integer"},
	{"{\"curve\": \"yes\"}", "/assembly/curve", "type"},
	{"{\"curve\": 1}", "/assembly/curve", "type"},
	{"{\"speed\": 1}", "/assembly/speed", "unknown_field"},
	{"{\"curve\": true, \"curve\": false}", "/assembly/curve", "duplicate_key"},
	/* the sample-count rule (case A: lead 10 mm) */
	{"{\"angles_per_revolution\": 4096, \"spectrum_revolutions\": 245}", "/assembly", "too_many_samples"},
	{"{\"angles_per_revolution\": 1001, \"stroke_mm\": 10000}", "/assembly", "too_many_samples"},
	{"{\"angles_per_revolution\": 4096, \"stroke_mm\": 2450, \"spectrum_revolutions\": 1}",
	 "/assembly", "too_many_samples"},
	/* not checked against invalid members: only their own problem */
	{"{\"angles_per_revolution\": 5000, \"spectrum_revolutions\": 1000}",
	 "/assembly/angles_per_revolution", "range"},
	{"{\"angles_per_revolution\": 4096, \"stroke_mm\": 1e5}", "/assembly/stroke_mm", "range"},
};

static void assembly_bad_input(void **state)
{
	(void)state;
	for (size_t i = 0; i < sizeof bad_options / sizeof bad_options[0]; i++) {
		prsm_assembly_options o;
		prsm_problems p;
		int rc = read_options(&o, &p, bad_options[i].text);
		if (rc != PRSM_EINVAL || p.count != 1 || find(&p, bad_options[i].pointer, bad_options[i].code) != 0) {
			dump(&p);
			fail_msg("%s: expected one problem [%s] at \"%s\" (rc %d, %d problems)",
			         bad_options[i].text, bad_options[i].code, bad_options[i].pointer, rc, p.count);
		}
	}
}

static void assembly_sample_rule(void **state)
{
	(void)state;
	prsm_assembly_options o;
	prsm_problems p;
	/* exactly at the limit: 4096 x 244 = 999424; 1000 x (10000 mm / 10 mm) = 1000000 */
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 4096, \"spectrum_revolutions\": 244}"), 0);
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 1000, \"stroke_mm\": 10000}"), 0);
	/* the stroke counts only when it is longer than the spectrum record */
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 4096, \"stroke_mm\": 2440,"
	                                      " \"spectrum_revolutions\": 1}"), 0);
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 1001, \"stroke_mm\": 10000}"),
	                 PRSM_EINVAL);
	assert_string_equal(expect(&p, "/assembly", "too_many_samples"),
	                    "angles_per_revolution 1001 x 1000 revolutions (the larger of "
	                    "spectrum_revolutions 16 and stroke_mm 10000 / lead 10 mm) = 1001000 "
	                    "transmission-error samples, more than 1000000");
	/* the longest message fits a problem */
	assert_int_equal(read_options(&o, &p, "{\"angles_per_revolution\": 4095, \"stroke_mm\": 9999.123456789,"
	                                      " \"spectrum_revolutions\": 999}"), PRSM_EINVAL);
	assert_true(strlen(expect(&p, "/assembly", "too_many_samples")) < PRSM_PROBLEM_MESSAGE_MAX - 1);
	/* a design with a shorter lead makes the same stroke more revolutions */
	prsm_design d = case_a_design();
	d.pitch_mm = 0.5; /* lead 2.5 mm: 10000 mm = 4000 revolutions */
	cJSON *doc = parse_ok("{\"angles_per_revolution\": 256, \"stroke_mm\": 10000}");
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_assembly_options_from_json(&o, doc, "/assembly", &d, &p), PRSM_EINVAL);
	expect(&p, "/assembly", "too_many_samples");
	cJSON_Delete(doc);
}

/* ---- round trip -------------------------------------------------------------------------- */

/* xorshift64*: reproducible uniform numbers in [-1, 1) */
static double uniform(uint64_t *s)
{
	*s ^= *s >> 12;
	*s ^= *s << 25;
	*s ^= *s >> 27;
	return (double)((*s * 2685821657736338717ULL) >> 11) / 4503599627370496.0 - 1.0;
}

static void add_value(cJSON *obj, const char *key, double v)
{
	assert_non_null(cJSON_AddNumberToObject(obj, key, v));
}

/* A body object with every field, random within its limits (API units). */
static cJSON *random_body(uint64_t *s)
{
	cJSON *b = cJSON_CreateObject();
	add_value(b, "pitch_radius_um", 499.0 * uniform(s));
	add_value(b, "thickness_um", 499.0 * uniform(s));
	add_value(b, "flank_angle_mrad", 49.0 * uniform(s));
	add_value(b, "runout_um", 499.0 * fabs(uniform(s)));
	add_value(b, "runout_phase_deg", 3599.0 * uniform(s));
	add_value(b, "lead_deviation_um_per_300mm", 999.0 * uniform(s));
	add_value(b, "lead_periodic_um", 499.0 * fabs(uniform(s)));
	add_value(b, "lead_periodic_phase_deg", 3599.0 * uniform(s));
	cJSON *idx = cJSON_AddArrayToObject(b, "start_index_mrad");
	for (int i = 0; i < 5; i++)
		cJSON_AddItemToArray(idx, cJSON_CreateNumber(99.0 * uniform(s)));
	add_value(b, "tilt_mrad", 19.0 * fabs(uniform(s)));
	add_value(b, "tilt_phase_deg", 359.0 * uniform(s));
	return b;
}

static cJSON *random_document(uint64_t seed)
{
	uint64_t s = seed;
	cJSON *doc = cJSON_CreateObject();
	cJSON_AddItemToObject(doc, "screw", random_body(&s));
	cJSON_AddItemToObject(doc, "nut", random_body(&s));
	cJSON *c = cJSON_AddObjectToObject(doc, "carrier");
	add_value(c, "runout_um", 499.0 * fabs(uniform(&s)));
	add_value(c, "runout_phase_deg", 3599.0 * uniform(&s));
	cJSON *rollers = cJSON_AddArrayToObject(doc, "rollers");
	const double limit[ROLLER_FIELDS] = {499, 499, 499, 499, 3599, 999, 499, 3599, 499, 499, 99, 19, 19};
	for (int j = 0; j < 10; j++) {
		cJSON *r = cJSON_CreateObject();
		for (int i = 0; i < ROLLER_FIELDS; i++) {
			double u = uniform(&s);
			add_value(r, roller_json_keys[i], limit[i] * (i == 3 || i == 6 ? fabs(u) : u));
		}
		cJSON_AddItemToArray(rollers, r);
	}
	return doc;
}

static void errors_to_json_and_back(const prsm_errors *e, prsm_errors *back)
{
	prsm_design d = case_a_design();
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *json = prsm_io_errors_to_json(e, d.starts);
	assert_non_null(json);
	int rc = prsm_io_errors_from_json(back, json, "/errors", &d, &p);
	cJSON_Delete(json);
	if (rc != 0)
		dump(&p);
	assert_int_equal(rc, 0);
}

static void round_trip_is_exact(void **state)
{
	(void)state;
	prsm_design d = case_a_design();
	for (uint64_t seed = 1; seed <= 200; seed++) {
		/* a high-entropy set as a request gives it: every field, 17 significant digits */
		cJSON *doc = random_document(0x9E3779B97F4A7C15ULL * seed);
		char *text = cJSON_PrintUnformatted(doc);
		cJSON_Delete(doc);
		assert_non_null(text);
		prsm_errors e, back;
		prsm_problems p;
		int rc = read_errors(&e, &p, text);
		free(text);
		if (rc != 0)
			dump(&p);
		assert_int_equal(rc, 0);
		errors_to_json_and_back(&e, &back);
		assert_same_errors(&e, &back);
	}
	/* a zero set is {} */
	prsm_errors zero;
	prsm_errors_zero(&zero, d.rollers);
	cJSON *json = prsm_io_errors_to_json(&zero, d.starts);
	assert_non_null(json);
	assert_true(cJSON_IsObject(json));
	assert_null(json->child);
	cJSON_Delete(json);
}

static void round_trip_of_engine_values(void **state)
{
	(void)state;
	/* a set made in engine units (e.g. a sample): not every mm is a µm / 1000, so to one unit in
	 * the last place; after that the set is a JSON one and stays put */
	uint64_t s = 0x2545F4914F6CDD1DULL;
	for (int trial = 0; trial < 50; trial++) {
		prsm_errors e, back, again;
		prsm_errors_zero(&e, 10);
		double *v[] = {&e.screw.pitch_radius_mm, &e.screw.thickness_mm, &e.nut.runout_mm,
		               &e.nut.lead_periodic_mm, &e.carrier.runout_mm, &e.screw.runout_phase_rad,
		               &e.nut.lead_deviation, &e.screw.tilt_rad, &e.nut.start_index_rad[4],
		               &e.roller[0].pin_radial_mm, &e.roller[9].tilt_tangential_rad,
		               &e.roller[5].gear_phase_rad, &e.roller[2].lead_deviation};
		const double lim[] = {0.499, 0.499, 0.499, 0.499, 0.499, 62.0, 0.0033, 0.019, 0.099,
		                      0.499, 0.019, 0.099, 0.0033};
		const int magnitude[] = {0, 0, 1, 1, 1, 0, 0, 1, 0, 0, 0, 0, 0};
		for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
			double u = uniform(&s);
			*v[i] = lim[i] * (magnitude[i] ? fabs(u) : u);
		}
		errors_to_json_and_back(&e, &back);
		for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
			const double *b = (const double *)((const char *)&back + ((const char *)v[i] - (const char *)&e));
			assert_close(*b, *v[i], DBL_EPSILON * fabs(*v[i]));
		}
		errors_to_json_and_back(&back, &again);
		assert_same_errors(&back, &again);
	}
}

static void to_json_writes_only_non_zero_fields(void **state)
{
	(void)state;
	/* 63.7 µm, 7.3 deg and 1.5 µm/300 mm do not come back from mm, rad, mm/mm times the unit
	 * factor as they went in (63.70000000000001, ...): the writer rounds them back */
	const char *text = "{\"screw\":{\"runout_um\":63.7,\"runout_phase_deg\":7.3,"
	                   "\"start_index_mrad\":[0,0,0.25,0,0]},"
	                   "\"rollers\":[{},{},{},{},{\"thickness_um\":-2.5,"
	                   "\"lead_deviation_um_per_300mm\":1.5,\"tilt_radial_mrad\":0.125},"
	                   "{},{},{},{},{}]}";
	prsm_errors e;
	prsm_problems p;
	assert_int_equal(read_errors(&e, &p, text), 0);
	cJSON *json = prsm_io_errors_to_json(&e, 5);
	assert_non_null(json);
	const cJSON *screw = cJSON_GetObjectItemCaseSensitive(json, "screw");
	const cJSON *roller4 = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(json, "rollers"), 4);
	assert_true(cJSON_GetObjectItemCaseSensitive(screw, "runout_um")->valuedouble == 63.7);
	assert_true(cJSON_GetObjectItemCaseSensitive(screw, "runout_phase_deg")->valuedouble == 7.3);
	assert_true(cJSON_GetObjectItemCaseSensitive(roller4, "lead_deviation_um_per_300mm")->valuedouble == 1.5);
	char *out = cJSON_PrintUnformatted(json);
	cJSON_Delete(json);
	assert_non_null(out);
	assert_string_equal(out, text);
	free(out);

	/* only a nut start index: the nut holds just that array, of n elements */
	prsm_errors_zero(&e, 10);
	e.nut.start_index_rad[1] = 0.0005;
	e.nut.start_index_rad[7] = 1.0; /* past n: not part of the design, not written */
	json = prsm_io_errors_to_json(&e, 5);
	out = cJSON_PrintUnformatted(json);
	cJSON_Delete(json);
	assert_string_equal(out, "{\"nut\":{\"start_index_mrad\":[0,0.5,0,0,0]}}");
	free(out);
	/* only a carrier run-out */
	prsm_errors_zero(&e, 10);
	e.carrier.runout_mm = 0.003;
	json = prsm_io_errors_to_json(&e, 5);
	out = cJSON_PrintUnformatted(json);
	cJSON_Delete(json);
	assert_string_equal(out, "{\"carrier\":{\"runout_um\":3}}");
	free(out);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(full_document_converts_every_field),
		cmocka_unit_test(absent_fields_are_zero),
		cmocka_unit_test(limits_are_inclusive),
		cmocka_unit_test(every_bad_input_at_its_pointer),
		cmocka_unit_test(messages_name_the_limits),
		cmocka_unit_test(all_problems_at_once),
		cmocka_unit_test(unknown_design_checks_all_but_lengths),
		cmocka_unit_test(pointer_prefixes_every_problem),
		cmocka_unit_test(assembly_defaults),
		cmocka_unit_test(assembly_every_field),
		cmocka_unit_test(assembly_bad_input),
		cmocka_unit_test(assembly_sample_rule),
		cmocka_unit_test(round_trip_is_exact),
		cmocka_unit_test(round_trip_of_engine_values),
		cmocka_unit_test(to_json_writes_only_non_zero_fields),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
