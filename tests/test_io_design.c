/*
 * test_io_design.c: the design document reader (io/design_json) and the JSON helpers under it
 * (io/json_util): conversions, every kind of problem with its exact pointer, the strict parser,
 * and every example design in studies/.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/analyze.h"
#include "io/design_json.h"
#include "io/stages_json.h"
#include "io/json_util.h"
#include "model/compliance.h"

#include "test_problems.h"
#include "test_support.h"

/* ---- helpers ---------------------------------------------------------------------------- */

/* |a - b| <= tol, with both values in the message (cmocka 1.1.5 has no double assertion). */
#define assert_near(a, b, tol)                                                                  \
	do {                                                                                    \
		double a_ = (a), b_ = (b);                                                      \
		if (!(fabs(a_ - b_) <= (tol)))                                                  \
			fail_msg("%s = %.17g, expected %.17g (tolerance %g)", #a, a_, b_, (double)(tol)); \
	} while (0)

static void expect(const prsm_problems *p, const char *pointer, const char *code)
{
	if (find(p, pointer, code) < 0) {
		dump(p);
		fail_msg("no problem [%s] at \"%s\"", code, pointer);
	}
}

/* Read the design at text (top level) into d; returns the rc of prsm_io_design_load. */
static int load_text(prsm_design *d, prsm_problems *problems, const char *text)
{
	prsm_geometry g;
	cJSON *doc = parse_ok(text);
	prsm_problems_init(problems);
	int rc = prsm_io_design_load(d, &g, NULL, doc, "", problems);
	cJSON_Delete(doc);
	return rc;
}

#define CASE_A_GEOMETRY \
	"\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"rollers\": 10"

/* ---- valid documents -------------------------------------------------------------------- */

static void case_a_loads_and_resolves(void **state)
{
	(void)state;
	cJSON *doc = parse_ok("{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10}}");
	prsm_design d;
	prsm_geometry g;
	prsm_problems problems, warnings;
	prsm_problems_init(&problems);
	prsm_problems_init(&warnings);
	int rc = prsm_io_design_load(&d, &g, &warnings, doc, "", &problems);
	cJSON_Delete(doc);
	if (rc != 0)
		dump(&problems);
	assert_int_equal(rc, 0);
	assert_int_equal(problems.count, 0);
	assert_int_equal(warnings.count, 0);
	assert_int_equal(d.starts, 5);
	assert_int_equal(d.hand, PRSM_HAND_RIGHT);
	assert_int_equal(d.rollers, 10);
	assert_int_equal(d.engaged_threads, 10);
	assert_near(d.pitch_mm, 2.0, 0.0);
	assert_near(d.roller_radius_mm, 3.25, 0.0);
	assert_near(d.screw_radius_mm, 9.75, 1e-12);   /* (n-2) r_r */
	assert_near(d.nut_radius_mm, 16.25, 1e-12);   /* r_s + 2 r_r */
	assert_near(d.flank_angle_rad, M_PI / 4.0, 1e-15);
	assert_near(d.roller_arc_radius_mm, 3.25 * sqrt(2.0), 1e-12);
	assert_near(d.screw_material.E_MPa, 206000.0, 0.0);
	assert_near(d.nut_material.poisson, 0.3, 0.0);
	assert_near(d.running_clearance_mm, 0.1, 0.0);
	assert_int_equal(d.thinning_rule, PRSM_THINNING_EQUAL_GAPS);
	assert_near(d.target_axial_clearance_mm, 0.0, 0.0);
	assert_near(d.axial_load_N, 0.0, 0.0);
	assert_int_equal(g.z_max, 10);
	assert_int_equal(g.standard_rules, 1);
	assert_near(g.lead_mm, 10.0, 1e-12);
	assert_near(g.helix_screw_rad * 180.0 / M_PI, 9.2710, 5e-5); /* docs/model/geometry-and-meshing.md */
}

static void every_field_converts(void **state)
{
	(void)state;
	const char *text =
		"{\"name\": \"högh entropy\", \"description\": \"all fields\","
		" \"geometry\": {\"starts\": 7, \"hand\": \"left\", \"pitch_mm\": 1.73,"
		"  \"flank_angle_deg\": 43.7, \"roller_radius_mm\": 2.385, \"screw_radius_mm\": 11.93,"
		"  \"nut_radius_mm\": 16.71, \"roller_arc_radius_mm\": 3.447,"
		"  \"screw_crest_radius_mm\": 12.37, \"screw_root_radius_mm\": 11.41,"
		"  \"roller_crest_radius_mm\": 2.821, \"roller_root_radius_mm\": 1.867,"
		"  \"nut_crest_radius_mm\": 16.27, \"nut_root_radius_mm\": 17.23,"
		"  \"rollers\": 9, \"engaged_threads\": 17, \"running_clearance_mm\": 0.137},"
		" \"thinning\": {\"screw_um\": 13.7, \"roller_um\": -4.3, \"nut_um\": 21.9},"
		" \"materials\": {\"screw\": {\"E_GPa\": 207.3, \"poisson\": 0.291},"
		"  \"roller\": {\"E_GPa\": 198.6}, \"nut\": {\"poisson\": 0.283}},"
		" \"friction\": {\"screw_roller\": 0.0637, \"nut_roller\": 0.0291},"
		" \"operating_point\": {\"axial_load_N\": 7345.5, \"screw_speed_rpm\": -1234.5}}";
	cJSON *doc = parse_ok(text);
	prsm_design d;
	prsm_problems problems;
	prsm_problems_init(&problems);
	int rc = prsm_io_design_from_json(&d, doc, "", &problems);
	cJSON_Delete(doc);
	if (rc != 0)
		dump(&problems);
	assert_int_equal(rc, 0);
	assert_int_equal(d.starts, 7);
	assert_int_equal(d.hand, PRSM_HAND_LEFT);
	assert_near(d.pitch_mm, 1.73, 0.0);
	assert_near(d.flank_angle_rad, 43.7 * M_PI / 180.0, 1e-15);
	assert_near(d.roller_radius_mm, 2.385, 0.0);
	assert_near(d.screw_radius_mm, 11.93, 0.0);
	assert_near(d.nut_radius_mm, 16.71, 0.0);
	assert_near(d.roller_arc_radius_mm, 3.447, 0.0);
	assert_near(d.screw_crest_radius_mm, 12.37, 0.0);
	assert_near(d.screw_root_radius_mm, 11.41, 0.0);
	assert_near(d.roller_crest_radius_mm, 2.821, 0.0);
	assert_near(d.roller_root_radius_mm, 1.867, 0.0);
	assert_near(d.nut_crest_radius_mm, 16.27, 0.0);
	assert_near(d.nut_root_radius_mm, 17.23, 0.0);
	assert_int_equal(d.rollers, 9);
	assert_int_equal(d.engaged_threads, 17);
	assert_near(d.running_clearance_mm, 0.137, 0.0);
	assert_int_equal(d.thinning_rule, PRSM_THINNING_GIVEN);
	assert_near(d.flank_shift_screw_mm, 0.00685, 1e-15);  /* 13.7 µm / 2 */
	assert_near(d.flank_shift_roller_mm, -0.00215, 1e-15);
	assert_near(d.flank_shift_nut_mm, 0.01095, 1e-15);
	assert_near(d.screw_material.E_MPa, 207300.0, 1e-9);
	assert_near(d.screw_material.poisson, 0.291, 0.0);
	assert_near(d.roller_material.E_MPa, 198600.0, 1e-9);
	assert_near(d.roller_material.poisson, 0.3, 0.0);       /* default kept */
	assert_near(d.nut_material.E_MPa, 206000.0, 0.0);       /* default kept */
	assert_near(d.nut_material.poisson, 0.283, 0.0);
	assert_near(d.mu_screw_roller, 0.0637, 0.0);
	assert_near(d.mu_nut_roller, 0.0291, 0.0);
	assert_near(d.axial_load_N, 7345.5, 0.0);
	assert_near(d.screw_speed_rad_s, -1234.5 * 2.0 * M_PI / 60.0, 1e-12);
}

static void absent_optional_radii_stay_nan(void **state)
{
	(void)state;
	cJSON *doc = parse_ok("{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10}}");
	prsm_design d;
	prsm_problems problems;
	prsm_problems_init(&problems);
	assert_int_equal(prsm_io_design_from_json(&d, doc, "", &problems), 0);
	cJSON_Delete(doc);
	assert_true(isnan(d.screw_radius_mm));
	assert_true(isnan(d.nut_radius_mm));
	assert_true(isnan(d.roller_arc_radius_mm));
	assert_true(isnan(d.screw_crest_radius_mm));
	assert_true(isnan(d.nut_root_radius_mm));
}

/* ---- problems --------------------------------------------------------------------------- */

static void many_problems_at_once(void **state)
{
	(void)state;
	const char *text =
		"{\"geometry\": {\"starts\": 2.5, \"pitch_mm\": -2, \"roller_radius_mm\": 3.25,"
		"  \"rollers\": \"ten\", \"engaged_threads\": 10, \"engaged_threads\": 11,"
		"  \"colour\": \"red\", \"a/b~c\": 1, \"running_clearance_mm\": 1e999},"
		" \"materialz\": {}, \"operating_point\": {\"axial_load_N\": 7000}}";
	cJSON *doc = parse_ok(text);
	prsm_design d;
	prsm_problems p;
	prsm_problems_init(&p);
	int rc = prsm_io_design_from_json(&d, doc, "", &p);
	cJSON_Delete(doc);
	assert_int_equal(rc, PRSM_EINVAL);
	expect(&p, "/materialz", "unknown_field");
	expect(&p, "/geometry/engaged_threads", "duplicate_key");
	expect(&p, "/geometry/colour", "unknown_field");
	expect(&p, "/geometry/a~1b~0c", "unknown_field");
	expect(&p, "/geometry/starts", "not_integer");
	expect(&p, "/geometry/pitch_mm", "range");
	expect(&p, "/geometry/rollers", "type");
	expect(&p, "/geometry/running_clearance_mm", "not_finite");
	if (p.count != 8)
		dump(&p);
	assert_int_equal(p.count, 8);
	assert_string_equal(p.items[find(&p, "/geometry/pitch_mm", "range")].message,
	                    "must be a number > 0 (got -2)");
	assert_string_equal(p.items[find(&p, "/geometry/starts", "not_integer")].message,
	                    "must be an integer from 1 to 12 (got 2.5)");
	assert_string_equal(p.items[find(&p, "/geometry/rollers", "type")].message,
	                    "must be an integer from 1 to 64 (got the string \"ten\")");
	const char *unknown = p.items[find(&p, "/materialz", "unknown_field")].message;
	assert_non_null(strstr(unknown, "did you mean \"materials\"?"));
	assert_non_null(strstr(unknown, "operating_point"));
	const char *colour = p.items[find(&p, "/geometry/colour", "unknown_field")].message;
	assert_non_null(strstr(colour, "allowed: starts, hand, pitch_mm"));
	assert_non_null(strstr(colour, "more"));
}

static void limits_are_named(void **state)
{
	(void)state;
	const char *text =
		"{\"name\": 17, \"geometry\": {\"starts\": 13, \"hand\": \"up\", \"pitch_mm\": 50.5,"
		"  \"flank_angle_deg\": 90, \"roller_radius_mm\": 0, \"rollers\": 0, \"nut_length_mm\": -4,"
		"  \"running_clearance_mm\": -0.01},"
		" \"target_axial_clearance_um\": 5000.5,"
		" \"materials\": {\"screw\": {\"E_GPa\": 0, \"poisson\": 0.5}, \"nut\": []},"
		" \"friction\": {\"screw_roller\": 1},"
		" \"operating_point\": {\"axial_load_N\": 1.5e8, \"screw_speed_rpm\": -100000.5}}";
	prsm_design d;
	prsm_problems p;
	assert_int_equal(load_text(&d, &p, text), PRSM_EINVAL);
	expect(&p, "/name", "type");
	expect(&p, "/geometry/starts", "range");
	expect(&p, "/geometry/hand", "enum");
	expect(&p, "/geometry/pitch_mm", "range");
	expect(&p, "/geometry/flank_angle_deg", "range");
	expect(&p, "/geometry/roller_radius_mm", "range");
	expect(&p, "/geometry/rollers", "range");
	expect(&p, "/geometry/nut_length_mm", "range");
	expect(&p, "/geometry/running_clearance_mm", "range");
	expect(&p, "/target_axial_clearance_um", "range");
	expect(&p, "/materials/screw/E_GPa", "range");
	expect(&p, "/materials/screw/poisson", "range");
	expect(&p, "/materials/nut", "type");
	expect(&p, "/friction/screw_roller", "range");
	expect(&p, "/operating_point/axial_load_N", "range");
	expect(&p, "/operating_point/screw_speed_rpm", "range");
	if (p.count != 16)
		dump(&p);
	assert_int_equal(p.count, 16);
	assert_string_equal(p.items[find(&p, "/geometry/starts", "range")].message,
	                    "must be an integer <= 12 (got 13)");
	assert_string_equal(p.items[find(&p, "/geometry/pitch_mm", "range")].message,
	                    "must be a number <= 50 (got 50.5)");
	assert_string_equal(p.items[find(&p, "/geometry/flank_angle_deg", "range")].message,
	                    "must be a number < 90 (got 90)");
	assert_string_equal(p.items[find(&p, "/geometry/hand", "enum")].message,
	                    "must be one of \"right\", \"left\" (got the string \"up\")");
	assert_string_equal(p.items[find(&p, "/operating_point/axial_load_N", "range")].message,
	                    "must be a number <= 100000000 (got 150000000)");
	assert_string_equal(p.items[find(&p, "/materials/screw/poisson", "range")].message,
	                    "must be a number < 0.5 (got 0.5)");
}

static void missing_and_wrong_types(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems p;

	assert_int_equal(load_text(&d, &p, "[1, 2]"), PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "", "type");

	assert_int_equal(load_text(&d, &p, "{\"name\": \"no geometry\"}"), PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "/geometry", "required");

	assert_int_equal(load_text(&d, &p, "{\"geometry\": [], \"friction\": 0.05}"), PRSM_EINVAL);
	assert_int_equal(p.count, 2);
	expect(&p, "/geometry", "type");
	expect(&p, "/friction", "type");

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {\"hand\": \"right\"}}"), PRSM_EINVAL);
	expect(&p, "/geometry/starts", "required");
	expect(&p, "/geometry/pitch_mm", "required");
	expect(&p, "/geometry/roller_radius_mm", "required");
	expect(&p, "/geometry/rollers", "required");
	expect(&p, "/geometry/engaged_threads", "required");
	assert_int_equal(p.count, 5);
	assert_string_equal(p.items[find(&p, "/geometry/pitch_mm", "required")].message,
	                    "is required (a number > 0 and <= 50)");
}

static void rollers_above_z_max(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems p;
	int rc = load_text(&d, &p, "{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25,"
	                           " \"rollers\": 11, \"engaged_threads\": 10}}");
	assert_int_equal(rc, PRSM_EGEOMETRY);
	expect(&p, "/geometry/rollers", "z_max");
	assert_non_null(strstr(p.items[find(&p, "/geometry/rollers", "z_max")].message, "Z_max = 10"));
}

static void two_starts_under_the_standard_rule(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems p;
	int rc = load_text(&d, &p, "{\"geometry\": {\"starts\": 2, \"pitch_mm\": 1.5, \"roller_radius_mm\": 3.25,"
	                           " \"rollers\": 4, \"engaged_threads\": 10}}");
	assert_int_equal(rc, PRSM_EINVAL);
	expect(&p, "/geometry/starts", "starts_min");
	assert_int_equal(p.count, 1); /* the rule check does not pile consequences on top */
}

static void nut_length_converts_to_threads(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems p;
	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"nut_length_mm\": 21.73}}"), 0);
	assert_int_equal(d.engaged_threads, 10); /* floor(21.73 / 2) */

	/* 0.6 / 0.2 is 2.9999999999999996 in doubles: still 3 whole threads */
	assert_int_equal(load_text(&d, &p, "{\"geometry\": {\"starts\": 5, \"pitch_mm\": 0.2,"
	                                   " \"roller_radius_mm\": 3.25, \"rollers\": 10, \"nut_length_mm\": 0.6}}"), 0);
	assert_int_equal(d.engaged_threads, 3);

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"nut_length_mm\": 1.93}}"),
	                 PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "/geometry/nut_length_mm", "range");
	assert_non_null(strstr(p.items[0].message, "shorter than one pitch"));

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"nut_length_mm\": 1002.1}}"),
	                 PRSM_EINVAL);
	expect(&p, "/geometry/nut_length_mm", "range");

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"nut_length_mm\": 21.73,"
	                                   " \"engaged_threads\": 10}}"), PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "/geometry/nut_length_mm", "conflict");
}

/* A case A design with this thread_compliance object. */
#define THREAD_COMPLIANCE(tc) \
	"{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10}, \"stiffness\": {\"thread_compliance\": " tc "}}"

/* thread_compliance: model "none" wins over a width (a conflict at it), width "given" needs
 * width_mm; the problems in the document's reading order. */
static void thread_compliance_rules(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems p;
	assert_int_equal(load_text(&d, &p, THREAD_COMPLIANCE("{\"model\": \"none\", \"width\": \"ellipse\"}")),
	                 PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "/stiffness/thread_compliance/width", "conflict");
	assert_int_equal(load_text(&d, &p, THREAD_COMPLIANCE("{\"model\": \"none\"}")), 0);
	assert_int_equal(d.stiffness.width_rule, PRSM_THREAD_COMPLIANCE_NONE);
	assert_int_equal(load_text(&d, &p, THREAD_COMPLIANCE("{\"width\": \"given\", \"width_mm\": 2.385,"
	                                                     " \"negative_terms\": \"keep\"}")), 0);
	assert_int_equal(d.stiffness.width_rule, PRSM_THREAD_WIDTH_GIVEN);
	assert_near(d.stiffness.width_mm, 2.385, 0.0);
	assert_int_equal(d.stiffness.negative_terms, PRSM_YAMAMOTO_KEEP);
	assert_int_equal(load_text(&d, &p, THREAD_COMPLIANCE("{\"model\": \"rigid\", \"width\": \"given\","
	                                                     " \"calibration\": 0}")), PRSM_EINVAL);
	assert_int_equal(p.count, 3);
	assert_string_equal(p.items[0].pointer, "/stiffness/thread_compliance/model");
	assert_string_equal(p.items[1].pointer, "/stiffness/thread_compliance/width_mm");
	assert_string_equal(p.items[1].message, "is required with width \"given\" (mm)");
	assert_string_equal(p.items[2].pointer, "/stiffness/thread_compliance/calibration");
}

/* The multi-stage document's table: its keys, the stages, then the couplings' radii (one per
 * coupling). */
static void multistage_reads_by_its_table(void **state)
{
	(void)state;
	prsm_io_multistage *ms = calloc(1, sizeof *ms);
	assert_non_null(ms);
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = parse_ok("{\"nmae\": 1, \"stages\": [{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10}},"
	                      " {\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10}}], \"couplings\": {"
	                      "\"spline_friction\": 1,"
	                      " \"spline_radius_mm\": [3, 4], \"thrust_bearing_radius_mm\": [12.5]}}");
	assert_int_equal(prsm_io_multistage_read(ms, doc, NULL, &p), PRSM_EINVAL);
	assert_int_equal(p.count, 3);
	assert_string_equal(p.items[0].pointer, "/nmae");
	assert_string_equal(p.items[1].pointer, "/couplings/spline_friction");
	assert_string_equal(p.items[2].pointer, "/couplings/spline_radius_mm");
	assert_int_equal(ms->stages, 2);
	assert_near(ms->chain_input.thrust_radius_mm[1], 12.5, 0.0);
	assert_int_equal(ms->thrust_radius_default[1], 0);
	assert_int_equal(ms->spline_radius_default[1], 1);
	cJSON_Delete(doc);

	/* stages that are no array stop the reading: no couplings problem after it */
	prsm_problems_init(&p);
	doc = parse_ok("{\"stages\": {}, \"couplings\": {\"spline_friction\": 1}}");
	assert_int_equal(prsm_io_multistage_read(ms, doc, NULL, &p), PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "/stages", "type");
	cJSON_Delete(doc);
	free(ms);
}

static void thinning_or_target(void **state)
{
	(void)state;
	prsm_design d;
	prsm_problems p;
	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10},"
	                                   " \"thinning\": {\"screw_um\": 41.3}, \"target_axial_clearance_um\": 20}"),
	                 PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	expect(&p, "/target_axial_clearance_um", "conflict");

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10},"
	                                   " \"target_axial_clearance_um\": 23.7}"), 0);
	assert_int_equal(d.thinning_rule, PRSM_THINNING_EQUAL_GAPS);
	assert_near(d.target_axial_clearance_mm, 0.0237, 1e-15);

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10},"
	                                   " \"thinning\": {\"nut_um\": -7.9}}"), 0);
	assert_int_equal(d.thinning_rule, PRSM_THINNING_GIVEN);
	assert_near(d.flank_shift_nut_mm, -0.00395, 1e-15);
	assert_near(d.flank_shift_screw_mm, 0.0, 0.0);

	assert_int_equal(load_text(&d, &p, "{\"geometry\": {" CASE_A_GEOMETRY ", \"engaged_threads\": 10},"
	                                   " \"thinning\": {\"nut_um\": 20000.5, \"gear_um\": 1}}"), PRSM_EINVAL);
	expect(&p, "/thinning/nut_um", "range");
	expect(&p, "/thinning/gear_um", "unknown_field");
}

static void base_pointer_prefixes_everything(void **state)
{
	(void)state;
	cJSON *doc = parse_ok("{\"design\": {\"geometry\": {\"starts\": 5, \"pitch_mm\": \"2\","
	                      " \"roller_radius_mm\": 3.25, \"rollers\": 10, \"engaged_threads\": 10},"
	                      " \"thinning\": {}, \"target_axial_clearance_um\": 10}}");
	prsm_design d;
	prsm_problems p;
	prsm_problems_init(&p);
	const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
	assert_int_equal(prsm_io_design_load(&d, NULL, NULL, design, "/design", &p), PRSM_EINVAL);
	cJSON_Delete(doc);
	expect(&p, "/design/geometry/pitch_mm", "type");
	expect(&p, "/design/target_axial_clearance_um", "conflict");
	assert_int_equal(p.count, 2);

	/* the model's own problems get the prefix too */
	doc = parse_ok("{\"design\": {\"geometry\": {\"starts\": 2, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25,"
	               " \"rollers\": 11, \"engaged_threads\": 10}}}");
	prsm_problems_init(&p);
	design = cJSON_GetObjectItemCaseSensitive(doc, "design");
	assert_int_equal(prsm_io_design_load(&d, NULL, NULL, design, "/design", &p), PRSM_EINVAL);
	expect(&p, "/design/geometry/starts", "starts_min");

	cJSON *starts = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(design, "geometry"), "starts");
	cJSON_SetNumberValue(starts, 5);
	prsm_problems warnings;
	prsm_problems_init(&warnings);
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_design_load(&d, NULL, &warnings, design, "/design", &p), PRSM_EGEOMETRY);
	expect(&p, "/design/geometry/rollers", "z_max");
	cJSON_Delete(doc);
}

static void non_standard_design_warns(void **state)
{
	(void)state;
	cJSON *doc = parse_ok("{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25,"
	                      " \"screw_radius_mm\": 10.37, \"rollers\": 8, \"engaged_threads\": 10}}");
	prsm_design d;
	prsm_geometry g;
	prsm_problems p, w;
	prsm_problems_init(&p);
	prsm_problems_init(&w);
	assert_int_equal(prsm_io_design_load(&d, &g, &w, doc, "/x~1y", &p), 0);
	cJSON_Delete(doc);
	assert_int_equal(p.count, 0);
	assert_true(w.count >= 1);
	expect(&w, "/x~1y/geometry/screw_radius_mm", "standard_rule");
	assert_int_equal(g.standard_rules, 0);
}

/* ---- json_util -------------------------------------------------------------------------- */

static void parse_refuses_bad_text(void **state)
{
	(void)state;
	static const struct {
		const char *text;
		size_t len; /* 0: strlen */
		const char *code;
		const char *message_start;
	} cases[] = {
		{"{\"name\": \"caf\xC3\x28\"}", 0, "invalid_utf8", "invalid UTF-8 at byte 13"},
		{"{\"name\": \"\xC0\xAF\"}", 0, "invalid_utf8", "invalid UTF-8 at byte 10"},       /* overlong */
		{"{\"name\": \"\xED\xA0\x80\"}", 0, "invalid_utf8", "invalid UTF-8 at byte 10"},   /* surrogate */
		{"{\"name\": \"\xF4\x90\x80\x80\"}", 0, "invalid_utf8", "invalid UTF-8 at byte 10"}, /* > U+10FFFF */
		{"{\"name\": \"\xE2\x82\"", 0, "invalid_utf8", "invalid UTF-8 at byte 10"},        /* truncated */
		{"{\"a\": }", 0, "malformed_json", "malformed JSON at byte 6"},
		{"{\"a\": 1,\n \"b\": tru}", 0, "malformed_json", "malformed JSON at byte 15 (line 2, column 7)"},
		{"{\"a\": 1} x", 0, "malformed_json", "malformed JSON at byte 9"},
		{"{\"a\": 01}", 0, "malformed_json", "malformed JSON at byte 6"},
		{"{\"a\": 1.}", 0, "malformed_json", "malformed JSON at byte 6"},
		{"{\"a\": -}", 0, "malformed_json", "malformed JSON at byte 6"},
		{"{\"a\": \"tab\there\"}", 0, "malformed_json", "malformed JSON at byte 10"},
		{"{\"a\": \"\\u0000\"}", 0, "malformed_json", "malformed JSON at byte 7"},
		{"{\"a\": 1}\0{", 10, "malformed_json", "malformed JSON at byte 8"},
		{"   \n", 0, "malformed_json", "malformed JSON at byte 4"},
		{"", 0, "malformed_json", "malformed JSON at byte 0"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		prsm_problems p;
		prsm_problems_init(&p);
		size_t len = cases[i].len ? cases[i].len : strlen(cases[i].text);
		cJSON *doc = prsm_json_parse(cases[i].text, len, &p);
		if (doc != NULL || p.count != 1 || strcmp(p.items[0].code, cases[i].code) != 0 ||
		    strncmp(p.items[0].message, cases[i].message_start, strlen(cases[i].message_start)) != 0) {
			dump(&p);
			cJSON_Delete(doc);
			fail_msg("case %zu: expected [%s] %s...", i, cases[i].code, cases[i].message_start);
		}
		assert_string_equal(p.items[0].pointer, "");
	}
}

static void parse_depth_limit(void **state)
{
	(void)state;
	char text[2 * (PRSM_JSON_MAX_DEPTH + 1) + 1];
	prsm_problems p;
	/* exactly the limit parses */
	int n = PRSM_JSON_MAX_DEPTH;
	memset(text, '[', (size_t)n);
	memset(text + n, ']', (size_t)n);
	text[2 * n] = '\0';
	prsm_problems_init(&p);
	cJSON *doc = prsm_json_parse(text, strlen(text), &p);
	assert_non_null(doc);
	cJSON_Delete(doc);
	/* one more level is refused, at the byte that opens it */
	n = PRSM_JSON_MAX_DEPTH + 1;
	memset(text, '[', (size_t)n);
	memset(text + n, ']', (size_t)n);
	text[2 * n] = '\0';
	prsm_problems_init(&p);
	assert_null(prsm_json_parse(text, strlen(text), &p));
	assert_int_equal(p.count, 1);
	assert_string_equal(p.items[0].code, "too_deep");
	assert_non_null(strstr(p.items[0].message, "deeper than 64 levels at byte 64"));
	/* brackets inside strings do not count */
	char quoted[300];
	snprintf(quoted, sizeof quoted, "{\"a\": \"%.*s\"}", 200,
	         "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["
	         "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[");
	prsm_problems_init(&p);
	doc = prsm_json_parse(quoted, strlen(quoted), &p);
	assert_non_null(doc);
	cJSON_Delete(doc);
}

static void parse_unterminated_buffer(void **state)
{
	(void)state;
	/* the text need not end in NUL: ASan checks that nothing reads past len */
	const char src[] = "\xEF\xBB\xBF{\"geometry\": {\"starts\": 5}, \"x\": [1.25e-3, -0.5, \"\xC3\xA9\"]}";
	size_t len = sizeof src - 1;
	char *buf = malloc(len);
	assert_non_null(buf);
	memcpy(buf, src, len);
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = prsm_json_parse(buf, len, &p);
	free(buf);
	assert_non_null(doc);
	assert_int_equal(p.count, 0);
	const cJSON *x = cJSON_GetObjectItemCaseSensitive(doc, "x");
	assert_near(cJSON_GetArrayItem(x, 0)->valuedouble, 1.25e-3, 0.0);
	assert_string_equal(cJSON_GetArrayItem(x, 2)->valuestring, "\xC3\xA9");
	cJSON_Delete(doc);

	/* the number at the end of the buffer is parsed within len */
	buf = malloc(4);
	assert_non_null(buf);
	memcpy(buf, "1234", 4);
	prsm_problems_init(&p);
	doc = prsm_json_parse(buf, 3, &p);
	free(buf);
	assert_non_null(doc);
	assert_near(doc->valuedouble, 123.0, 0.0);
	cJSON_Delete(doc);
}

static void pointers_escape_and_bound(void **state)
{
	(void)state;
	char out[16];
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, "", "a/b~c"), 0);
	assert_string_equal(out, "/a~1b~0c");
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, "/x", ""), 0);
	assert_string_equal(out, "/x/");
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, NULL, "k"), 0);
	assert_string_equal(out, "/k");
	assert_int_equal(prsm_json_pointer_append_index(out, sizeof out, "/tol", 17), 0);
	assert_string_equal(out, "/tol/17");
	/* does not fit: left at the parent */
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, "/design", "abcdefgh"), PRSM_ENOMEM);
	assert_string_equal(out, "/design");
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, "/design", "abc~~~"), PRSM_ENOMEM);
	assert_string_equal(out, "/design");
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, "/design", "abcdefg"), 0);
	assert_string_equal(out, "/design/abcdefg");
	/* in place */
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, "/a", "b"), 0);
	assert_int_equal(prsm_json_pointer_append(out, sizeof out, out, "c"), 0);
	assert_string_equal(out, "/a/b/c");
}

static void numbers_and_excerpts_format(void **state)
{
	(void)state;
	char buf[40];
	prsm_json_format_number(buf, sizeof buf, 0.1);
	assert_string_equal(buf, "0.1");
	prsm_json_format_number(buf, sizeof buf, -2.0);
	assert_string_equal(buf, "-2");
	prsm_json_format_number(buf, sizeof buf, 1e8);
	assert_string_equal(buf, "100000000");
	prsm_json_format_number(buf, sizeof buf, 2.385e-7);
	assert_string_equal(buf, "2.385e-07");
	prsm_json_format_number(buf, sizeof buf, -INFINITY);
	assert_string_equal(buf, "-inf");
	char ex[8];
	prsm_json_excerpt(ex, sizeof ex, "abc");
	assert_string_equal(ex, "abc");
	prsm_json_excerpt(ex, sizeof ex, "a\nb\xC3\xA9xyz"); /* cut before the é's second byte */
	assert_string_equal(ex, "a?b...");
	assert_int_equal(prsm_json_utf8_invalid_at("ok\xF0\x9F\x98\x80", 6), 6);
}

static void duplicates_in_a_large_object(void **state)
{
	(void)state;
	/* 40 keys, more than the pairwise limit: the sorted path, reported in document order */
	char text[1024];
	size_t k = 0;
	k += (size_t)snprintf(text + k, sizeof text - k, "{");
	for (int i = 0; i < 40; i++) {
		int key = (i == 23) ? 7 : (i == 31 ? 7 : (i == 35 ? 2 : i));
		k += (size_t)snprintf(text + k, sizeof text - k, "%s\"k%d\": %d", i ? ", " : "", key, i);
	}
	snprintf(text + k, sizeof text - k, "}");
	cJSON *doc = parse_ok(text);
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_json_check_keys(doc, "/map", NULL, &p), PRSM_EINVAL);
	cJSON_Delete(doc);
	assert_int_equal(p.count, 3);
	assert_string_equal(p.items[0].pointer, "/map/k7");
	assert_string_equal(p.items[1].pointer, "/map/k7");
	assert_string_equal(p.items[2].pointer, "/map/k2");
	assert_string_equal(p.items[0].code, "duplicate_key");
}

static void field_readers_report_absence(void **state)
{
	(void)state;
	cJSON *doc = parse_ok("{\"flag\": true, \"n\": 3.0, \"s\": \"\xC3\xA9t\xC3\xA9\"}");
	prsm_problems p;
	prsm_problems_init(&p);
	int b = -1, n = -1;
	const char *s = NULL;
	double x = 7.25;
	assert_int_equal(prsm_json_get_bool(&b, doc, "", "flag", PRSM_JSON_REQUIRED, &p), PRSM_JSON_PRESENT);
	assert_int_equal(b, 1);
	assert_int_equal(prsm_json_get_int(&n, doc, "", "n", PRSM_JSON_REQUIRED, 1, 5, &p), PRSM_JSON_PRESENT);
	assert_int_equal(n, 3); /* 3.0 is an integer, as in JSON Schema */
	assert_int_equal(prsm_json_get_string(&s, doc, "", "s", PRSM_JSON_REQUIRED, 3, &p), PRSM_JSON_PRESENT);
	assert_int_equal(prsm_json_get_string(&s, doc, "", "s", PRSM_JSON_REQUIRED, 2, &p), PRSM_EINVAL);
	expect(&p, "/s", "too_long");
	prsm_json_range any = {-INFINITY, INFINITY, 0, 0};
	assert_int_equal(prsm_json_get_number(&x, doc, "", "Flag", PRSM_JSON_OPTIONAL, any, &p), PRSM_JSON_ABSENT);
	assert_near(x, 7.25, 0.0); /* untouched; lookup is case-sensitive */
	assert_int_equal(prsm_json_get_bool(&b, doc, "", "n", PRSM_JSON_REQUIRED, &p), PRSM_EINVAL);
	expect(&p, "/n", "type");
	assert_int_equal(p.count, 2);
	cJSON_Delete(doc);
}

/* ---- studies/ --------------------------------------------------------------------------- */

static void studies_load_without_problems(void **state)
{
	(void)state;
	char dir[512], path[1024];
	prsm_test_source_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/studies", dir);
	DIR *d = opendir(path);
	if (d == NULL)
		fail_msg("cannot open %s (set PRSM_SOURCE_DIR)", path);
	int loaded = 0;
	struct dirent *e;
	while ((e = readdir(d)) != NULL) {
		size_t nl = strlen(e->d_name);
		if (nl < 6 || strcmp(e->d_name + nl - 5, ".json") != 0)
			continue;
		snprintf(path, sizeof path, "%s/studies/%s", dir, e->d_name);
		size_t len = 0;
		char *text = prsm_test_read_file(path, &len);
		assert_non_null(text);
		prsm_problems p, w;
		prsm_problems_init(&p);
		prsm_problems_init(&w);
		cJSON *doc = prsm_json_parse(text, len, &p);
		free(text);
		if (doc == NULL) {
			dump(&p);
			fail_msg("%s does not parse", path);
		}
		/* a multi-stage design (docs/model/kinematics-efficiency-stiffness-life.md) loads and analyses as a whole */
		if (prsm_io_is_multistage(doc)) {
			prsm_io_multistage *ms = calloc(1, sizeof *ms);
			assert_non_null(ms);
			int mrc = prsm_app_multistage_load(ms, doc, &w, &p);
			cJSON_Delete(doc);
			if (mrc != 0 || p.count != 0) {
				dump(&p);
				fail_msg("%s: %d problems", path, p.count);
			}
			assert_true(ms->stages >= 2);
			assert_true(ms->chain.efficiency > 0.0 && ms->chain.efficiency < 1.0);
			free(ms);
			loaded++;
			continue;
		}
		/* a study or an optimisation embeds its design under /design, an allocation under
		 * /study/design (an analytic allocation has none: test_alloc_io loads it); a design
		 * file is the design */
		const cJSON *design = cJSON_GetObjectItemCaseSensitive(doc, "design");
		const char *base = design ? "/design" : "";
		/* a study of a model (a benchmark or expressions, issue 21) has no design (test_expr_model
		 * reads studies/stack-housing.json) */
		if (!design && cJSON_GetObjectItemCaseSensitive(doc, "model") && cJSON_GetObjectItemCaseSensitive(doc, "tolerances")) {
			cJSON_Delete(doc);
			continue;
		}
		/* a simulation of the bare gear pair has no design (test_io_vibration reads it) */
		if (!design && cJSON_GetObjectItemCaseSensitive(doc, "dynamics") &&
		    !cJSON_GetObjectItemCaseSensitive(doc, "geometry")) {
			cJSON_Delete(doc);
			continue;
		}
		if (cJSON_GetObjectItemCaseSensitive(doc, "allocate")) {
			design = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(doc, "study"), "design");
			base = "/study/design";
			if (!design) {
				cJSON_Delete(doc);
				continue;
			}
		}
		prsm_design des;
		prsm_geometry g;
		int rc = prsm_io_design_load(&des, &g, &w, design ? design : doc, base, &p);
		cJSON_Delete(doc);
		if (rc != 0 || p.count != 0) {
			dump(&p);
			fail_msg("%s: %d problems", path, p.count);
		}
		assert_true(des.rollers <= g.z_max);
		loaded++;
	}
	closedir(d);
	assert_true(loaded >= 4);
}

static void seed000_files_match_the_reference(void **state)
{
	(void)state;
	char dir[512], path[1024];
	prsm_test_source_dir(dir, sizeof dir);
	static const struct {
		const char *file;
		double rs, rr, rn, helix_screw_deg;
	} stages[] = {
		{"seed000-stage1.json", 9.75, 3.25, 16.25, 9.2710},
		{"seed000-stage2.json", 16.5, 5.5, 27.5, 5.51},
	};
	for (int i = 0; i < 2; i++) {
		snprintf(path, sizeof path, "%s/studies/%s", dir, stages[i].file);
		size_t len = 0;
		char *text = prsm_test_read_file(path, &len);
		assert_non_null(text);
		prsm_problems p;
		prsm_problems_init(&p);
		cJSON *doc = prsm_json_parse(text, len, &p);
		free(text);
		assert_non_null(doc);
		prsm_design d;
		prsm_geometry g;
		assert_int_equal(prsm_io_design_load(&d, &g, NULL, doc, "", &p), 0);
		cJSON_Delete(doc);
		assert_near(d.screw_radius_mm, stages[i].rs, 0.0);
		assert_near(d.roller_radius_mm, stages[i].rr, 0.0);
		assert_near(d.nut_radius_mm, stages[i].rn, 0.0);
		assert_near(g.lead_mm, 10.0, 1e-12);
		assert_int_equal(d.rollers, 7);
		assert_near(g.helix_screw_rad * 180.0 / M_PI, stages[i].helix_screw_deg, 5e-3);
		assert_near(d.screw_speed_rad_s, 100.0, 1e-9);
		assert_near(d.axial_load_N, 7000.0, 0.0);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(case_a_loads_and_resolves),
		cmocka_unit_test(every_field_converts),
		cmocka_unit_test(absent_optional_radii_stay_nan),
		cmocka_unit_test(many_problems_at_once),
		cmocka_unit_test(limits_are_named),
		cmocka_unit_test(missing_and_wrong_types),
		cmocka_unit_test(rollers_above_z_max),
		cmocka_unit_test(two_starts_under_the_standard_rule),
		cmocka_unit_test(nut_length_converts_to_threads),
		cmocka_unit_test(thread_compliance_rules),
		cmocka_unit_test(multistage_reads_by_its_table),
		cmocka_unit_test(thinning_or_target),
		cmocka_unit_test(base_pointer_prefixes_everything),
		cmocka_unit_test(non_standard_design_warns),
		cmocka_unit_test(parse_refuses_bad_text),
		cmocka_unit_test(parse_depth_limit),
		cmocka_unit_test(parse_unterminated_buffer),
		cmocka_unit_test(pointers_escape_and_bound),
		cmocka_unit_test(numbers_and_excerpts_format),
		cmocka_unit_test(duplicates_in_a_large_object),
		cmocka_unit_test(field_readers_report_absence),
		cmocka_unit_test(studies_load_without_problems),
		cmocka_unit_test(seed000_files_match_the_reference),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
