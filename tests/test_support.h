/*
 * test_support.h: shared fixtures of the unit tests (cmocka).
 */
#ifndef PRSM_TEST_SUPPORT_H
#define PRSM_TEST_SUPPORT_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/geometry.h"

#define DEG (M_PI / 180.0)

/* The source tree: $PRSM_SOURCE_DIR, else two levels up from this file. */
static inline void prsm_test_source_dir(char *out, size_t cap)
{
	const char *env = getenv("PRSM_SOURCE_DIR");
	if (env != NULL && env[0] != '\0') {
		snprintf(out, cap, "%s", env);
		return;
	}
	snprintf(out, cap, "%s", __FILE__);
	for (int up = 0; up < 2; up++) {
		char *slash = strrchr(out, '/');
		if (slash == NULL) {
			snprintf(out, cap, "..");
			return;
		}
		*slash = '\0';
	}
	if (out[0] == '\0')
		snprintf(out, cap, "/");
}

/* A file of at most 1 MiB, malloc'd (the caller frees it); NULL when unreadable. */
static inline char *prsm_test_read_file(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	if (f == NULL)
		return NULL;
	size_t cap = 1 << 20, n;
	char *buf = malloc(cap);
	if (buf != NULL) {
		n = fread(buf, 1, cap, f);
		*len = n;
	}
	fclose(f);
	return buf;
}

/* studies/NAME of the source tree, parsed; fails the test when it cannot be read or parsed.
 * The caller owns the tree (cJSON_Delete). */
static inline cJSON *prsm_test_read_study(const char *name)
{
	char dir[512], path[1024];
	prsm_test_source_dir(dir, sizeof dir);
	snprintf(path, sizeof path, "%s/studies/%s", dir, name);
	size_t len = 0;
	char *text = prsm_test_read_file(path, &len);
	assert_non_null(text);
	cJSON *doc = cJSON_ParseWithLength(text, len);
	free(text);
	assert_non_null(doc);
	return doc;
}

/* |actual - expected| <= tol, with a readable failure message. */
#define assert_close(actual, expected, tol)                                                       \
	do {                                                                                          \
		double a_ = (actual), e_ = (expected), t_ = (tol);                                        \
		if (!(fabs(a_ - e_) <= t_)) {                                                             \
			print_error("%s = %.12g, expected %.12g within %.3g\n", #actual, a_, e_, t_);        \
			fail();                                                                               \
		}                                                                                         \
	} while (0)

/* A standard-rule design, resolved; aborts the test on problems. */
static inline void standard_design(prsm_design *d, int starts, double pitch_mm, double roller_radius_mm,
                                   double flank_deg, int rollers, int threads)
{
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_design_init(d);
	d->starts = starts;
	d->pitch_mm = pitch_mm;
	d->roller_radius_mm = roller_radius_mm;
	d->flank_angle_rad = flank_deg * DEG;
	d->rollers = rollers;
	d->engaged_threads = threads;
	assert_int_equal(prsm_design_resolve(d, &e), 0);
}

/* Case A of docs/model/geometry-and-meshing.md: r_s 9.75, r_r 3.25, r_n 16.25, P 2, n 5, beta 45 deg, t = 0. */
static inline void case_a(prsm_design *d)
{
	standard_design(d, 5, 2.0, 3.25, 45.0, 10, 10);
}

#endif
