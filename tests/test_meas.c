/*
 * test_meas.c: measured data in (io/measured.h, dyn/measured.h; MODEL-DYNAMICS.md §8.5 items 1
 * and 2): the CSV reader on good files (comments, a byte-order mark, CRLF, quoted fields, extra
 * columns, travel only) and every bad one refused with its line and column (a bad number, NaN,
 * a missing column, a short or long row, an unclosed quote, a non-monotonic angle, fewer than
 * four revolutions, travel against angle, a million rows, an empty file); the `measured` section
 * and the calibration options refused at their JSON pointers; the spectrum's named lines and
 * lead deviation on synthetic records with known amplitudes; the comparison's statistics by
 * direct computation.
 */
#include "test_support.h"

#include "dyn/measured.h"
#include "io/global.h"
#include "io/measured.h"

static int parse(prsm_meas_curve *c, prsm_io_csv_origin *o, const char *text, prsm_problems *p)
{
	prsm_problems_init(p);
	return prsm_io_measured_csv_parse(c, o, text, strlen(text), "bench.csv", p);
}

/* One problem whose message holds want (and the pointer is the file). */
static void expect_problem(const prsm_problems *p, const char *pointer, const char *want)
{
	if (p->count != 1 || strstr(p->items[0].message, want) == NULL || strcmp(p->items[0].pointer, pointer) != 0) {
		for (int i = 0; i < p->count; i++)
			print_error("problem %s: %s\n", p->items[i].pointer, p->items[i].message);
		print_error("wanted one at %s with \"%s\"\n", pointer, want);
		fail();
	}
}

/* A CSV of revs revolutions, per_rev points each, a TE of a known sine. */
static char *csv_text(double revs, int per_rev, int travel_only)
{
	const size_t n = (size_t)(revs * per_rev) + 1;
	const size_t cap = n * 80 + 200;
	char *t = malloc(cap);
	size_t len = (size_t)snprintf(t, cap, travel_only ? "travel_mm,te_um\n" : "screw_angle_rad,travel_mm,te_um\n");
	for (size_t i = 0; i < n; i++) {
		const double th = 2.0 * M_PI * (double)i / per_rev;
		const double te = 0.731 * sin(1.875 * th + 0.4);
		if (travel_only)
			len += (size_t)snprintf(t + len, cap - len, "%.12f,%.9f\n", th * 10.0 / (2.0 * M_PI), te);
		else
			len += (size_t)snprintf(t + len, cap - len, "%.12f,%.12f,%.9f\n", th, th * 10.0 / (2.0 * M_PI), te);
	}
	return t;
}

static void test_csv_good(void **state)
{
	(void)state;
	const char *text = "\xEF\xBB\xBF# a bench export\r\n"
	                   "\r\n"
	                   "time_s, screw_angle_rad ,\"te_um\",note\r\n"
	                   "0.0, 0.0, 1.25, \"start, slow\"\r\n"
	                   "# a comment between rows\n"
	                   "0.1,0.5,-2.5e-1,\"he said \"\"ok\"\"\"\n"
	                   "0.2,1.0,+3.5,\n"
	                   "0.3,1.5,0.125";
	prsm_meas_curve c;
	prsm_io_csv_origin o;
	prsm_problems p;
	assert_int_equal(parse(&c, &o, text, &p), 0);
	assert_int_equal(c.n, 4);
	assert_true(c.has_angle && !c.has_travel);
	assert_close(c.angle_rad[1], 0.5, 0.0);
	assert_close(c.te_um[1], -0.25, 0.0);
	assert_close(c.te_um[2], 3.5, 0.0);
	assert_close(c.te_um[3], 0.125, 0.0);
	assert_int_equal(o.line[0], 4);
	assert_int_equal(o.line[1], 6);
	assert_int_equal(o.line[3], 8);
	assert_int_equal(o.column[0], 2);
	assert_int_equal(o.column[2], 3);
	prsm_meas_curve_free(&c);
	prsm_io_csv_origin_free(&o);
	/* travel only: the angle follows with the lead, 2 pi s / L */
	char *t = csv_text(4.25, 16, 1);
	assert_int_equal(parse(&c, &o, t, &p), 0);
	assert_int_equal(prsm_io_measured_curve_check(&c, &o, "bench.csv", 10.0, &p), 0);
	assert_close(c.angle_rad[16], 2.0 * M_PI, 1e-9);
	assert_close(prsm_meas_revolutions(&c), 4.25, 1e-9);
	prsm_meas_curve_free(&c);
	prsm_io_csv_origin_free(&o);
	free(t);
}

static void test_csv_bad(void **state)
{
	(void)state;
	static const struct {
		const char *text, *want;
	} cases[] = {
		{"screw_angle_rad,te_um\n0,1\n0.1,1.2x\n", "line 3, column 2 (te_um): \"1.2x\" is not a number"},
		{"screw_angle_rad,te_um\n0,1\n0.1,nan\n", "line 3, column 2 (te_um): \"nan\" is not a finite number"},
		{"screw_angle_rad,te_um\n0,1\n0.1,1e999\n", "line 3, column 2 (te_um): \"1e999\" is not a finite number"},
		{"screw_angle_rad,te_um\n0,1\n0x10,1\n", "line 3, column 1 (screw_angle_rad): \"0x10\" is not a number"},
		{"screw_angle_rad,te_um\n0,1\n,1\n", "line 3, column 1 (screw_angle_rad): the value is empty"},
		{"screw_angle_rad,travel_mm\n0,1\n", "line 1: the header has no te_um column"},
		{"time_s,te_um\n0,1\n", "line 1: the header has neither screw_angle_rad nor travel_mm"},
		{"screw_angle_rad,te_um,x\n0,1,2\n0.1\n", "line 3, column 2 (te_um): the row has 1 field, the header 3"},
		{"screw_angle_rad,te_um\n0,1\n0.1,2,3\n", "line 3, column 3: more fields than the header's 2 columns"},
		{"screw_angle_rad,te_um\n0,\"1\n", "line 2, column 2: a quoted field is not closed"},
		{"screw_angle_rad,te_um\n0,\"1\"x\n", "line 2, column 2: text after the closing quote"},
		{"screw_angle_rad,te_um,te_um\n", "line 1, column 3 (te_um): the column is named twice"},
		{"# only a comment\n\n", "line 3: no header row"},
		{"screw_angle_rad,te_um\n# nothing\n", "no data rows after the header"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		prsm_meas_curve c;
		prsm_io_csv_origin o;
		prsm_problems p;
		assert_int_equal(parse(&c, &o, cases[i].text, &p), PRSM_EINVAL);
		expect_problem(&p, "bench.csv", cases[i].want);
		assert_null(c.te_um); /* nothing kept */
	}
}

/* The model's findings at the CSV line and column: non-monotonic angle, too short, travel
 * against angle, a NaN that came through (not from the parser: from arrays) */
static void test_csv_curve_findings(void **state)
{
	(void)state;
	char *t = csv_text(6.0, 8, 0);
	/* line 1 header, sample i on line i + 2: swap samples 10 and 11's angles on line 13 */
	prsm_meas_curve c;
	prsm_io_csv_origin o;
	prsm_problems p;
	assert_int_equal(parse(&c, &o, t, &p), 0);
	c.angle_rad[11] = c.angle_rad[10];
	assert_int_equal(prsm_io_measured_curve_check(&c, &o, "bench.csv", 10.0, &p), PRSM_EINVAL);
	expect_problem(&p, "bench.csv", "line 13, column 1 (screw_angle_rad): the screw angle must increase strictly");
	prsm_meas_curve_free(&c);
	prsm_io_csv_origin_free(&o);
	/* travel off by 2 % of the lead */
	assert_int_equal(parse(&c, &o, t, &p), 0);
	c.travel_mm[20] += 0.2;
	assert_int_equal(prsm_io_measured_curve_check(&c, &o, "bench.csv", 10.0, &p), PRSM_EINVAL);
	expect_problem(&p, "bench.csv", "line 22, column 2 (travel_mm): the travel");
	prsm_meas_curve_free(&c);
	prsm_io_csv_origin_free(&o);
	free(t);
	/* 3.875 revolutions */
	t = csv_text(3.875, 8, 0);
	assert_int_equal(parse(&c, &o, t, &p), 0);
	assert_int_equal(prsm_io_measured_curve_check(&c, &o, "bench.csv", 10.0, &p), PRSM_EINVAL);
	expect_problem(&p, "bench.csv", "line 33, column 1 (screw_angle_rad): the TE record covers 3.875 screw revolutions");
	prsm_meas_curve_free(&c);
	prsm_io_csv_origin_free(&o);
	free(t);
}

/* A million rows: refused at the cap with the line, fast, nothing allocated for them. */
static void test_csv_cap(void **state)
{
	(void)state;
	const size_t rows = 1000000;
	const size_t cap = rows * 24 + 64;
	char *t = malloc(cap);
	size_t len = (size_t)snprintf(t, cap, "screw_angle_rad,te_um\n");
	for (size_t i = 0; i < rows; i++)
		len += (size_t)snprintf(t + len, cap - len, "%zu.5,0.%zu\n", i, i % 1000);
	prsm_meas_curve c;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_measured_csv_parse(&c, NULL, t, len, "big.csv", &p), PRSM_EINVAL);
	char want[80];
	snprintf(want, sizeof want, "line %d: more than %d data rows", PRSM_MEAS_POINTS_MAX + 2, PRSM_MEAS_POINTS_MAX);
	expect_problem(&p, "big.csv", want);
	/* the file reader: the same, from disk */
	char path[] = "/tmp/prsm-test-meas-XXXXXX";
	const int fd = mkstemp(path);
	assert_true(fd >= 0);
	FILE *f = fdopen(fd, "w");
	assert_int_equal(fwrite(t, 1, len, f), len);
	fclose(f);
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_measured_csv_read(&c, NULL, path, &p), PRSM_EINVAL);
	expect_problem(&p, path, want);
	remove(path);
	free(t);
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_measured_csv_read(&c, NULL, "/nonexistent/prsm.csv", &p), PRSM_EIO);
	assert_int_equal(p.count, 1);
}

static void test_json_measured(void **state)
{
	(void)state;
	static const struct {
		const char *json, *pointer, *want;
	} cases[] = {
		{"{\"te\": {\"screw_angle_rad\": [0, 1, 2], \"travel_mm\": [0, 1], \"te_um\": [0, 1, 2]}}", "/measured/te/travel_mm",
		 "has 2 items"},
		{"{\"te\": {\"screw_angle_rad\": [0, 1, 2, 3], \"te_um\": [0, 1, 2, \"3\"]}}", "/measured/te/te_um/3",
		 "must be a number"},
		{"{\"te\": {\"screw_angle_rad\": [0, 1]}}", "/measured/te/te_um", "required"},
		{"{\"te\": {\"te_um\": [0, 1]}}", "/measured/te", "screw_angle_rad or travel_mm"},
		{"{\"te\": {\"te_um\": [0, 1], \"angle\": [0, 1]}}", "/measured/te/angle", ""},
		{"{\"cage_ratio_sd\": 0.001}", "/measured/cage_ratio_sd", "cage_ratio"},
		{"{\"cage_ratio\": 1.5}", "/measured/cage_ratio", ""},
		{"{\"efficiency\": -0.2}", "/measured/efficiency", ""},
		{"{\"efficency\": 0.9}", "/measured/efficency", ""},
		{"{\"te_noise_sd_um\": \"low\"}", "/measured/te_noise_sd_um", ""},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		cJSON *doc = cJSON_Parse(cases[i].json);
		assert_non_null(doc);
		prsm_meas_data m;
		prsm_problems p;
		prsm_problems_init(&p);
		assert_int_equal(prsm_io_measured_read(&m, doc, &p), PRSM_EINVAL);
		int found = 0;
		for (int k = 0; k < p.count; k++)
			found |= strcmp(p.items[k].pointer, cases[i].pointer) == 0 && strstr(p.items[k].message, cases[i].want);
		if (!found) {
			for (int k = 0; k < p.count; k++)
				print_error("  %s: %s\n", p.items[k].pointer, p.items[k].message);
			print_error("case %zu: wanted %s\n", i, cases[i].pointer);
			fail();
		}
		prsm_meas_data_free(&m);
		cJSON_Delete(doc);
	}
	/* a good one, and the model's finding at the array item's pointer */
	cJSON *doc = cJSON_Parse("{\"te\": {\"travel_mm\": [0, 2.5, 5, 7.5, 10, 12.5, 12.5, 17.5, 20, 22.5, 25, 27.5, 30, "
	                         "32.5, 35, 37.5, 40, 42.5], \"te_um\": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, "
	                         "16, 17]}, \"cage_ratio\": 0.3713, \"cage_ratio_sd\": 0.0012, \"efficiency\": 0.8921}");
	prsm_meas_data m;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_measured_read(&m, doc, &p), 0);
	assert_true(m.has_te);
	assert_int_equal(m.te.n, 18);
	assert_close(m.cage_ratio, 0.3713, 0.0);
	assert_close(m.cage_ratio_sd, 0.0012, 0.0);
	assert_close(m.efficiency, 0.8921, 0.0);
	assert_true(isnan(m.efficiency_sd));
	assert_int_equal(prsm_io_measured_curve_check(&m.te, NULL, NULL, 10.0, &p), PRSM_EINVAL);
	assert_int_equal(p.count, 1);
	assert_string_equal(p.items[0].pointer, "/measured/te/travel_mm/6");
	prsm_meas_data_free(&m);
	cJSON_Delete(doc);
}

static void test_json_calibrate(void **state)
{
	(void)state;
	static const struct {
		const char *json, *pointer;
	} cases[] = {
		{"{\"lines\": [\"screw\", \"carier\"]}", "/dynamics/calibrate/lines/1"},
		{"{\"lines\": [\"screw\", \"screw\"]}", "/dynamics/calibrate/lines/1"},
		{"{\"lines\": []}", "/dynamics/calibrate/lines"},
		{"{\"model\": \"physical\"}", "/dynamics/calibrate/parameters"},
		{"{\"model\": \"physical\", \"parameters\": [\"nut.runout_um\"], \"grid_points\": 11}", "/dynamics/calibrate/grid_points"},
		{"{\"parameters\": [\"nut.runout_um\"]}", "/dynamics/calibrate/parameters"},
		{"{\"grid_points\": 2}", "/dynamics/calibrate/grid_points"},
		{"{\"carrier_ratio_prior\": 1}", "/dynamics/calibrate/carrier_ratio_prior"},
		{"{\"model\": \"spline\"}", "/dynamics/calibrate/model"},
		{"{\"grid_width\": 0.1}", "/dynamics/calibrate/grid_width"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		cJSON *doc = cJSON_Parse(cases[i].json);
		prsm_calib_options o;
		prsm_problems p;
		prsm_problems_init(&p);
		assert_int_equal(prsm_io_calibrate_options_read(&o, doc, &p), PRSM_EINVAL);
		int found = 0;
		for (int k = 0; k < p.count; k++)
			found |= strcmp(p.items[k].pointer, cases[i].pointer) == 0;
		if (!found) {
			for (int k = 0; k < p.count; k++)
				print_error("  %s: %s\n", p.items[k].pointer, p.items[k].message);
			print_error("case %zu: wanted %s\n", i, cases[i].pointer);
			fail();
		}
		cJSON_Delete(doc);
	}
	cJSON *doc = cJSON_Parse("{\"lines\": [\"mesh\", \"screw_rev\"], \"grid_points\": 3001, \"grid_half_width\": 0.0173,"
	                         " \"refine\": \"cobyla\"}");
	prsm_calib_options o;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_calibrate_options_read(&o, doc, &p), 0);
	assert_int_equal(o.lines_mask, (1 << PRSM_CALIB_LINE_MESH) | (1 << PRSM_CALIB_LINE_SCREW_REV));
	assert_int_equal(o.grid_points, 3001);
	assert_close(o.grid_half_width, 0.0173, 0.0);
	assert_int_equal(o.refine, PRSM_CALIB_REFINE_COBYLA);
	assert_true(isnan(o.carrier_ratio_prior));
	cJSON_Delete(doc);
}

/* §8.5 item 2: a record of known lines and slope: the lead deviation exact, each named order's
 * amplitude within the window's scalloping (1 %) when it sits on the resolution grid, and the
 * found order within a bin */
static void test_spectrum(void **state)
{
	(void)state;
	const double revs = 16.0, per_rev = 64;
	const size_t n = (size_t)(revs * per_rev) + 1;
	prsm_meas_curve c;
	assert_int_equal(prsm_meas_curve_alloc(&c, n, NULL), 0);
	const double orders[3] = {1.0, 1.875, 3.75}, amp[3] = {1.84, 0.443, 0.181}, ph[3] = {0.3, 2.1, -1.2};
	for (size_t i = 0; i < n; i++) {
		const double th = 2.0 * M_PI * (double)i / per_rev;
		c.angle_rad[i] = th;
		c.travel_mm[i] = th * 10.0 / (2.0 * M_PI);
		c.te_um[i] = 0.777 + 12.3 * c.travel_mm[i] / 300.0;
		for (int l = 0; l < 3; l++)
			c.te_um[i] += amp[l] * cos(orders[l] * th + ph[l]);
	}
	c.has_angle = c.has_travel = 1;
	const double ask[4] = {1.0, 1.875, 3.75, 40.0};
	prsm_meas_spectrum s;
	assert_int_equal(prsm_meas_spectrum_compute(&s, &c, ask, 4, NULL), 0);
	/* the least-squares slope on travel, by its own sums (the lines bias it a little) */
	double sm = 0.0, ym = 0.0, sxy = 0.0, sxx = 0.0;
	for (size_t i = 0; i < n; i++)
		sm += c.travel_mm[i] / (double)n, ym += c.te_um[i] / (double)n;
	for (size_t i = 0; i < n; i++)
		sxy += (c.travel_mm[i] - sm) * (c.te_um[i] - ym), sxx += (c.travel_mm[i] - sm) * (c.travel_mm[i] - sm);
	assert_close(s.lead_deviation_um_per_300mm, 300.0 * sxy / sxx, 1e-9);
	assert_close(s.lead_deviation_um_per_300mm, 12.3, 0.3);
	assert_close(s.resolution_per_rev, 1.0 / 16.0, 1e-12);
	assert_close(s.samples_per_rev, 64.0, 1e-9);
	assert_false(s.resampled);
	for (int l = 0; l < 3; l++) {
		assert_close(s.found_amplitude_um[l], amp[l], 0.01 * amp[l] + 0.002);
		assert_close(s.found_order_per_rev[l], orders[l], s.step_per_rev);
	}
	assert_true(s.above_nyquist[3]);
	assert_true(isnan(s.found_amplitude_um[3]));
	prsm_meas_spectrum_free(&s);
	/* the same record with uneven spacing: resampled, the same lines */
	for (size_t i = 1; i + 1 < n; i++)
		c.angle_rad[i] += 0.2 * (2.0 * M_PI / per_rev) * sin(0.37 * (double)i);
	for (size_t i = 0; i < n; i++) {
		c.travel_mm[i] = c.angle_rad[i] * 10.0 / (2.0 * M_PI);
		const double th = c.angle_rad[i];
		c.te_um[i] = 0.777 + 12.3 * c.travel_mm[i] / 300.0;
		for (int l = 0; l < 3; l++)
			c.te_um[i] += amp[l] * cos(orders[l] * th + ph[l]);
	}
	assert_int_equal(prsm_meas_spectrum_compute(&s, &c, ask, 3, NULL), 0);
	assert_true(s.resampled);
	for (int l = 0; l < 3; l++)
		assert_close(s.found_amplitude_um[l], amp[l], 0.02 * amp[l] + 0.003);
	prsm_meas_spectrum_free(&s);
	prsm_meas_curve_free(&c);
}

/* §8.5 item 1: measured - model by direct sums */
static void test_compare(void **state)
{
	(void)state;
	const size_t n = 301;
	prsm_meas_curve c;
	assert_int_equal(prsm_meas_curve_alloc(&c, n, NULL), 0);
	double *model = malloc(n * sizeof(double)), *res = malloc(n * sizeof(double));
	for (size_t i = 0; i < n; i++) {
		c.angle_rad[i] = 0.1 * (double)i;
		c.travel_mm[i] = c.angle_rad[i] * 10.0 / (2.0 * M_PI);
		model[i] = 0.53 * sin(1.3 * c.angle_rad[i]);
		c.te_um[i] = model[i] + 2.385 + 7.7 * c.travel_mm[i] / 300.0 + 0.1 * cos(5.1 * c.angle_rad[i]);
	}
	prsm_meas_comparison cmp;
	prsm_meas_compare(&cmp, &c, model, 0.05, res);
	double mean = 0.0;
	for (size_t i = 0; i < n; i++)
		mean += c.te_um[i] - model[i];
	mean /= (double)n;
	assert_close(cmp.offset_um, mean, 1e-12);
	double ss = 0.0, lo = 1e9, hi = -1e9;
	for (size_t i = 0; i < n; i++) {
		const double r = c.te_um[i] - model[i] - mean;
		assert_close(res[i], r, 1e-12);
		ss += r * r;
		lo = fmin(lo, r);
		hi = fmax(hi, r);
	}
	assert_close(cmp.rms_um, sqrt(ss / (double)n), 1e-12);
	assert_close(cmp.peak_to_peak_um, hi - lo, 1e-12);
	assert_close(cmp.z_rms, cmp.rms_um / 0.05, 1e-12);
	assert_close(cmp.lead_deviation_um_per_300mm, 7.7, 0.05);
	assert_close(prsm_meas_z(0.3712, 0.3737, 0.0011), (0.3712 - 0.3737) / 0.0011, 1e-12);
	assert_true(isnan(prsm_meas_z(0.3712, 0.3737, NAN)));
	free(model);
	free(res);
	prsm_meas_curve_free(&c);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_csv_good),      cmocka_unit_test(test_csv_bad),       cmocka_unit_test(test_csv_curve_findings),
		cmocka_unit_test(test_csv_cap),       cmocka_unit_test(test_json_measured), cmocka_unit_test(test_json_calibrate),
		cmocka_unit_test(test_spectrum),      cmocka_unit_test(test_compare),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
