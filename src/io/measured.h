/*
 * measured.h: measured data in and calibration results out (docs/measured-data.md).
 *
 * In: a measured TE curve from CSV text (a header row naming the columns screw_angle_rad,
 * travel_mm and te_um, any others ignored; '#' comment lines and blank lines skipped; RFC 4180
 * quoting; CRLF or LF) with every problem at its line and column, and nothing read past
 * PRSM_MEAS_POINTS_MAX rows or PRSM_IO_MEASURED_CSV_BYTES_MAX bytes; the `measured` section of a
 * calibration request (schemas/measured.schema.json, read by its generated table with the hook
 * for the curve's arrays) and the `dynamics.calibrate` options (schemas/measured-request.schema.json
 * $defs/calibrate), each problem at its JSON pointer. A curve's own checks (finite, increasing,
 * four revolutions, travel against angle) are the model's (dyn/measured.h); their findings are
 * mapped back here to the CSV line and column or the JSON pointer of the offending value.
 *
 * Out: the calibration result document (schemas/measured-result.schema.json), by
 * app/calibrate.c (its text summary: app/text.h).
 */
#ifndef PRSM_IO_MEASURED_H
#define PRSM_IO_MEASURED_H

#include <stddef.h>
#include <stdio.h>

#include <cJSON.h>

#include "dyn/calib.h"
#include "dyn/measured.h"
#include "util/problems.h"

/* Largest CSV file read, bytes. */
#define PRSM_IO_MEASURED_CSV_BYTES_MAX (64u * 1024u * 1024u)

/* Where each row of a CSV curve came from (for the model's findings). */
typedef struct {
	long *line;                  /* line number of each data row (1-based), n entries */
	int column[3];               /* 1-based column of screw_angle_rad, travel_mm, te_um (0: absent) */
} prsm_io_csv_origin;

void prsm_io_csv_origin_free(prsm_io_csv_origin *o);

/* Parse CSV text (len bytes, not necessarily NUL-terminated) into curve c (allocated here,
 * prsm_meas_curve_free) and origin (may be NULL; allocated, prsm_io_csv_origin_free). Every
 * problem of the text goes to problems at pointer `source` as "line L, column C (name): ...";
 * parsing stops at the first. Returns 0, PRSM_EINVAL or PRSM_ENOMEM. */
int prsm_io_measured_csv_parse(prsm_meas_curve *c, prsm_io_csv_origin *origin, const char *text, size_t len,
                               const char *source, prsm_problems *problems);

/* Read the CSV file at path (at most PRSM_IO_MEASURED_CSV_BYTES_MAX bytes) as above. Returns 0,
 * PRSM_EINVAL (a problem), PRSM_EIO (the file cannot be read: a problem says so), PRSM_ENOMEM. */
int prsm_io_measured_csv_read(prsm_meas_curve *c, prsm_io_csv_origin *origin, const char *path,
                              prsm_problems *problems);

/* Complete and check a curve with the design's lead (prsm_meas_curve_complete): a finding goes
 * to problems at the CSV line and column (origin given; pointer `source`) or at the JSON pointer
 * of the value (origin NULL; the curve from /measured/te). Returns 0 or PRSM_EINVAL. */
int prsm_io_measured_curve_check(prsm_meas_curve *c, const prsm_io_csv_origin *origin, const char *source,
                                 double lead_mm, prsm_problems *problems);

/* Read the `measured` section obj (NULL: absent) into m (prsm_meas_data_init first; the curve,
 * when given as arrays, allocated: prsm_meas_data_free). Problems at /measured/... Returns 0 or
 * PRSM_EINVAL. */
int prsm_io_measured_read(prsm_meas_data *m, const cJSON *obj, prsm_problems *problems);

/* Read dynamics.calibrate (obj NULL: the defaults) into o. Returns 0 or PRSM_EINVAL. */
int prsm_io_calibrate_options_read(prsm_calib_options *o, const cJSON *obj, prsm_problems *problems);

/* The model a calibration result names ("engine"."model"). */
#define PRSM_CALIB_MODEL_VERSION "prsm calibration 2027-02 (docs/measured-data.md: comparison, identification and calibration against measured data)"

/* Everything a calibration computed (filled by app/calibrate.c, written here). */
typedef struct {
	char name[256];              /* the design's name, "" when none */
	char source[256];            /* the CSV path, "/measured/te_csv" or "/measured/te" */
	int source_csv;              /* 1: the curve came from a CSV file, 2: from CSV text in the request
	                              * (measured.te_csv), 0: from its arrays */
	double lead_mm;              /* L = n P */
	const prsm_meas_data *measured;
	const prsm_meas_curve *curve;/* NULL: no TE curve */
	/* the kinematics of the orders */
	double k_star, k_statics;    /* minimum-slip and contact-radius carrier ratios, - */
	double ring_gear_ratio;      /* i_g */
	int rollers, ring_gear_teeth;
	/* §8.5 item 1 */
	int with_errors;             /* the request gave an error set */
	double measuring_load_N;
	int has_comparison;
	prsm_meas_comparison comparison;
	/* §8.5 item 2 (orders at k*) */
	int has_spectrum;
	prsm_meas_spectrum spectrum;
	int spectrum_kind[PRSM_CALIB_LINE_KINDS];
	/* §8.5 item 3 */
	prsm_calib_options options;
	int has_line, has_physical;
	prsm_calib_line_result line;
	prsm_calib_physical_result physical;
	prsm_errors calibrated;      /* the physical model's error set */
	int starts;                  /* n (the errors object's start_index_mrad) */
	/* §8.5 item 4 */
	int has_friction, has_cage;
	prsm_calib_friction friction;
	prsm_calib_cage cage;
	prsm_problems warnings;
} prsm_io_calibration;

/* The result document (schemas/measured-result.schema.json); the caller owns it, NULL when out
 * of memory. */
cJSON *prsm_io_calibration_to_json(const prsm_io_calibration *c);

#endif
