/*
 * bench.c: `prsm bench`, throughput of the engine's kernels as JSON:
 *   {"benchmarks": [{"name", "value", "unit", "threads"}, ...]}
 * Each kernel runs on case A of MODEL.md for a fixed wall-clock budget; every later kernel
 * (assembly, Monte Carlo, optimisation) adds its entry to the same list.
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "model/analysis.h"
#include "model/contact.h"
#include "model/geometry.h"
#include "util/clock.h"

/* Case A of MODEL.md §2 with Z = 10 and 10 engaged threads, 20 um target clearance. */
static void case_a(prsm_design *d)
{
	prsm_problems e;
	prsm_problems_init(&e);
	prsm_design_init(d);
	d->starts = 5;
	d->pitch_mm = 2.0;
	d->roller_radius_mm = 3.25;
	d->rollers = 10;
	d->engaged_threads = 10;
	d->target_axial_clearance_mm = 0.020;
	d->axial_load_N = 7000.0;
	d->screw_speed_rad_s = 100.0;
	prsm_design_resolve(d, &e);
}

static volatile double sink;

/* Warm-started Newton solves on screw-side pairs whose roller axis moves by a few um from one
 * solve to the next, as in a Monte Carlo sample. */
static double bench_contact(double budget_s, int warm)
{
	prsm_design d;
	case_a(&d);
	prsm_flank_pair pair;
	prsm_flank_pair_nominal(&pair, &d, PRSM_SIDE_SCREW);
	double x0, y0, g;
	prsm_contact_start(&pair, &x0, &y0);
	prsm_contact_solve_gap(&pair, &x0, &y0, &g, NULL);
	const double a = pair.roller_x_mm;
	long n = 0;
	double acc = 0.0, t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		for (int i = 0; i < 4096; i++) {
			/* deterministic pseudo-random offsets within +-20 um */
			double off = 0.02 * sin(0.7 * (double)(n + i));
			pair.roller_x_mm = a + off;
			pair.roller_y_mm = 0.5 * off;
			double x = x0, y = y0;
			if (!warm)
				prsm_contact_start(&pair, &x, &y);
			prsm_contact_solve_gap(&pair, &x, &y, &g, NULL);
			acc += g;
		}
		n += 4096;
		t = prsm_clock_seconds();
	}
	sink = acc;
	return (double)n / (t - t0);
}

static double bench_analysis(double budget_s)
{
	prsm_design d;
	case_a(&d);
	long n = 0;
	double t0 = prsm_clock_seconds(), t = t0;
	while (t - t0 < budget_s) {
		for (int i = 0; i < 64; i++) {
			prsm_design di = d;
			prsm_analysis a;
			prsm_problems w;
			prsm_problems_init(&w);
			prsm_analysis_nominal(&a, &di, &w, NULL);
			sink = a.efficiency.eta;
		}
		n += 64;
		t = prsm_clock_seconds();
	}
	return (double)n / (t - t0);
}

static void add(cJSON *list, const char *name, double value, const char *unit, int threads)
{
	cJSON *b = cJSON_CreateObject();
	cJSON_AddStringToObject(b, "name", name);
	cJSON_AddNumberToObject(b, "value", round(value));
	cJSON_AddStringToObject(b, "unit", unit);
	cJSON_AddNumberToObject(b, "threads", threads);
	cJSON_AddItemToArray(list, b);
}

int prsm_cli_bench(int argc, char **argv)
{
	double budget = 0.5;
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
			char *end = NULL;
			budget = strtod(argv[++i], &end);
			if (end == argv[i] || *end != '\0' || !(budget > 0.0 && budget <= 60.0)) {
				fprintf(stderr, "prsm bench: --seconds must be in (0, 60]\n");
				return PRSM_EXIT_USAGE;
			}
		} else {
			fprintf(stderr, "usage: prsm bench [--seconds S]\n");
			return PRSM_EXIT_USAGE;
		}
	}
	cJSON *doc = cJSON_CreateObject();
	cJSON *list = cJSON_AddArrayToObject(doc, "benchmarks");
	add(list, "contact_solve_warm", bench_contact(budget, 1), "solves/s", 1);
	add(list, "contact_solve_cold", bench_contact(budget, 0), "solves/s", 1);
	add(list, "nominal_analysis", bench_analysis(budget), "analyses/s", 1);
	char *text = cJSON_Print(doc);
	printf("%s\n", text);
	free(text);
	cJSON_Delete(doc);
	return 0;
}
