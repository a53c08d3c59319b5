/*
 * measured.c: the CSV reader of measured TE curves and the JSON readers of the `measured`
 * section and the calibration options (see measured.h; docs/measured-data.md).
 */
#include "io/measured.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/doc.h"
#include "io/json_util.h"
#include "prsm_io_tables.h"
#include "util/error.h"

static const char *const column_names[] = {"screw_angle_rad", "travel_mm", "te_um", NULL};

void prsm_io_csv_origin_free(prsm_io_csv_origin *o)
{
	if (o == NULL)
		return;
	free(o->line);
	o->line = NULL;
}

/* ---- CSV ---- */

typedef struct {
	const char *p, *end;
	long line;                   /* of the current position, 1-based */
	const char *source;
	prsm_problems *problems;
	char field[128];             /* the current field, NUL-terminated (cut at 127 bytes) */
	size_t field_len;            /* its true length */
	int quoted;
} csv;

static int csv_problem(csv *s, long line, int column, const char *name, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static int csv_problem(csv *s, long line, int column, const char *name, const char *fmt, ...)
{
	char msg[PRSM_PROBLEM_MESSAGE_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	if (column > 0)
		prsm_problems_add(s->problems, s->source, "csv", "line %ld, column %d%s%s%s: %s", line, column,
		                  name ? " (" : "", name ? name : "", name ? ")" : "", msg);
	else
		prsm_problems_add(s->problems, s->source, "csv", "line %ld: %s", line, msg);
	return PRSM_EINVAL;
}

/* Read one field at s->p. Returns 1 when the row goes on (a comma followed), 0 at the row's
 * end (newline or end of text), -1 on an error (unterminated quote, text after a closing
 * quote). */
static int csv_field(csv *s, int column)
{
	s->field_len = 0;
	s->quoted = 0;
	/* leading blanks */
	while (s->p < s->end && (*s->p == ' ' || *s->p == '\t'))
		s->p++;
	if (s->p < s->end && *s->p == '"') {
		s->quoted = 1;
		const long start = s->line;
		s->p++;
		for (;;) {
			if (s->p >= s->end)
				return csv_problem(s, start, column, NULL, "a quoted field is not closed"), -1;
			const char ch = *s->p++;
			if (ch == '"') {
				if (s->p < s->end && *s->p == '"') {
					s->p++;
				} else {
					break;
				}
			} else if (ch == '\n') {
				s->line++;
			}
			if (s->field_len + 1 < sizeof s->field)
				s->field[s->field_len] = ch;
			s->field_len++;
		}
		while (s->p < s->end && (*s->p == ' ' || *s->p == '\t'))
			s->p++;
		if (s->p < s->end && *s->p != ',' && *s->p != '\n' && *s->p != '\r')
			return csv_problem(s, s->line, column, NULL, "text after the closing quote of a field"), -1;
	} else {
		while (s->p < s->end && *s->p != ',' && *s->p != '\n' && *s->p != '\r') {
			if (s->field_len + 1 < sizeof s->field)
				s->field[s->field_len] = *s->p;
			s->field_len++;
			s->p++;
		}
		/* trailing blanks */
		while (s->field_len > 0 && s->field_len < sizeof s->field &&
		       (s->field[s->field_len - 1] == ' ' || s->field[s->field_len - 1] == '\t'))
			s->field_len--;
	}
	s->field[s->field_len < sizeof s->field ? s->field_len : sizeof s->field - 1] = '\0';
	if (s->p < s->end && *s->p == ',') {
		s->p++;
		return 1;
	}
	if (s->p < s->end && *s->p == '\r')
		s->p++;
	if (s->p < s->end && *s->p == '\n') {
		s->p++;
		s->line++;
	}
	return 0;
}

/* A line that holds nothing or a comment: skipped whole. */
static int skip_blank_or_comment(csv *s)
{
	const char *q = s->p;
	while (q < s->end && (*q == ' ' || *q == '\t'))
		q++;
	if (q < s->end && *q != '#' && *q != '\n' && *q != '\r')
		return 0;
	while (q < s->end && *q != '\n')
		q++;
	s->p = q < s->end ? q + 1 : q;
	s->line++;
	return 1;
}

/* A decimal number: [+-] digits [. digits] [(e|E) [+-] digits], nothing else (no nan, inf, hex). */
static int parse_number(double *out, const char *t)
{
	const char *q = t;
	if (*q == '+' || *q == '-')
		q++;
	int digits = 0;
	while (*q >= '0' && *q <= '9')
		q++, digits++;
	if (*q == '.') {
		q++;
		while (*q >= '0' && *q <= '9')
			q++, digits++;
	}
	if (digits == 0)
		return -1;
	if (*q == 'e' || *q == 'E') {
		q++;
		if (*q == '+' || *q == '-')
			q++;
		int ed = 0;
		while (*q >= '0' && *q <= '9')
			q++, ed++;
		if (ed == 0)
			return -1;
	}
	if (*q != '\0')
		return -1;
	errno = 0;
	char *end;
	*out = strtod(t, &end);
	if (end != q)
		return -1;
	return isfinite(*out) ? 0 : -2;
}

int prsm_io_measured_csv_parse(prsm_meas_curve *c, prsm_io_csv_origin *origin, const char *text, size_t len,
                               const char *source, prsm_problems *problems)
{
	memset(c, 0, sizeof *c);
	if (origin)
		memset(origin, 0, sizeof *origin);
	csv s = {text, text + len, 1, source, problems, {0}, 0, 0};
	/* a UTF-8 byte-order mark */
	if (len >= 3 && (unsigned char)text[0] == 0xEF && (unsigned char)text[1] == 0xBB && (unsigned char)text[2] == 0xBF)
		s.p += 3;
	while (s.p < s.end && skip_blank_or_comment(&s))
		;
	if (s.p >= s.end)
		return csv_problem(&s, s.line, 0, NULL, "no header row: the first line that is not a comment names the columns "
		                                        "(screw_angle_rad and/or travel_mm, and te_um)");
	/* the header */
	const long header_line = s.line;
	int col[3] = {0, 0, 0}, ncols = 0, more = 1;
	while (more) {
		more = csv_field(&s, ncols + 1);
		if (more < 0)
			return PRSM_EINVAL;
		ncols++;
		for (int k = 0; k < 3; k++)
			if (s.field_len == strlen(column_names[k]) && strcmp(s.field, column_names[k]) == 0) {
				if (col[k])
					return csv_problem(&s, header_line, ncols, column_names[k], "the column is named twice (also column %d)",
					                   col[k]);
				col[k] = ncols;
			}
		if (ncols > 1000)
			return csv_problem(&s, header_line, ncols, NULL, "more than 1000 columns");
	}
	if (!col[2])
		return csv_problem(&s, header_line, 0, NULL, "the header has no te_um column (the TE of each point, um); it names "
		                                            "%d column%s", ncols, ncols == 1 ? "" : "s");
	if (!col[0] && !col[1])
		return csv_problem(&s, header_line, 0, NULL,
		                   "the header has neither screw_angle_rad nor travel_mm: one of them places each point");
	/* the rows: counted first (the cap, before anything is allocated), then read */
	size_t rows = 0;
	{
		csv t = s;
		t.problems = NULL;
		while (t.p < t.end) {
			if (skip_blank_or_comment(&t))
				continue;
			if (rows == PRSM_MEAS_POINTS_MAX)
				return csv_problem(&s, t.line, 0, NULL,
				                   "more than %d data rows: a measured TE curve is limited to %d points "
				                   "(decimate it: a few hundred points per revolution are plenty)",
				                   PRSM_MEAS_POINTS_MAX, PRSM_MEAS_POINTS_MAX);
			rows++;
			/* to the end of the row, quotes respected */
			int inq = 0;
			while (t.p < t.end) {
				const char ch = *t.p++;
				if (ch == '"')
					inq = !inq;
				else if (ch == '\n') {
					t.line++;
					if (!inq)
						break;
				}
			}
		}
	}
	if (rows == 0)
		return csv_problem(&s, s.line, 0, NULL, "no data rows after the header");
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_meas_curve_alloc(c, rows, &err)) {
		prsm_problems_add(problems, source, "memory", "%s", err.message);
		return PRSM_ENOMEM;
	}
	if (origin) {
		origin->line = malloc(rows * sizeof(long));
		if (origin->line == NULL) {
			prsm_meas_curve_free(c);
			prsm_problems_add(problems, source, "memory", "out of memory for %zu rows", rows);
			return PRSM_ENOMEM;
		}
		for (int k = 0; k < 3; k++)
			origin->column[k] = col[k];
	}
	c->has_angle = col[0] != 0;
	c->has_travel = col[1] != 0;
	double *dest[3] = {c->angle_rad, c->travel_mm, c->te_um};
	size_t row = 0;
	int rc = 0;
	while (s.p < s.end && rc == 0) {
		if (skip_blank_or_comment(&s))
			continue;
		const long line = s.line;
		int k = 0;
		more = 1;
		while (more) {
			more = csv_field(&s, k + 1);
			if (more < 0) {
				rc = PRSM_EINVAL;
				break;
			}
			k++;
			if (k > ncols) {
				rc = csv_problem(&s, line, k, NULL, "more fields than the header's %d columns", ncols);
				break;
			}
			for (int j = 0; j < 3; j++) {
				if (col[j] != k)
					continue;
				double v;
				const int pr = s.field_len >= sizeof s.field ? -1 : parse_number(&v, s.field);
				if (s.field_len == 0)
					rc = csv_problem(&s, line, k, column_names[j], "the value is empty");
				else if (pr == -2 || (pr == -1 && (strstr(s.field, "nan") || strstr(s.field, "NaN") ||
				                                   strstr(s.field, "NAN") || strstr(s.field, "inf") ||
				                                   strstr(s.field, "Inf") || strstr(s.field, "INF"))))
					rc = csv_problem(&s, line, k, column_names[j], "\"%s\" is not a finite number", s.field);
				else if (pr == -1)
					rc = csv_problem(&s, line, k, column_names[j], "\"%.40s%s\" is not a number", s.field,
					                 s.field_len > 40 ? "..." : "");
				else
					dest[j][row] = v;
			}
			if (rc)
				break;
		}
		if (rc)
			break;
		if (k < ncols) { /* the first of the columns read that the row does not reach */
			int missing = -1;
			for (int j = 0; j < 3; j++)
				if (col[j] > k && (missing < 0 || col[j] < col[missing]))
					missing = j;
			if (missing >= 0) {
				rc = csv_problem(&s, line, col[missing], column_names[missing], "the row has %d field%s, the header "
				                 "%d: the value is missing", k, k == 1 ? "" : "s", ncols);
				break;
			}
		}
		if (origin)
			origin->line[row] = line;
		row++;
	}
	if (rc) {
		prsm_meas_curve_free(c);
		prsm_io_csv_origin_free(origin);
		return rc;
	}
	return 0;
}

int prsm_io_measured_csv_read(prsm_meas_curve *c, prsm_io_csv_origin *origin, const char *path,
                              prsm_problems *problems)
{
	memset(c, 0, sizeof *c);
	if (origin)
		memset(origin, 0, sizeof *origin);
	FILE *f = fopen(path, "rb");
	if (f == NULL) {
		prsm_problems_add(problems, path, "io", "cannot open the measured CSV: %s", strerror(errno));
		return PRSM_EIO;
	}
	size_t cap = 1 << 16, len = 0;
	char *buf = malloc(cap);
	int rc = 0;
	while (buf) {
		if (len == cap) {
			if (cap > PRSM_IO_MEASURED_CSV_BYTES_MAX)
				break; /* too large: said below */
			char *nb = realloc(buf, cap * 2);
			if (nb == NULL) {
				free(buf);
				buf = NULL;
				break;
			}
			buf = nb;
			cap *= 2;
		}
		const size_t got = fread(buf + len, 1, cap - len, f);
		len += got;
		if (got == 0) {
			if (ferror(f)) {
				prsm_problems_add(problems, path, "io", "cannot read the measured CSV");
				rc = PRSM_EIO;
			}
			break;
		}
	}
	fclose(f);
	if (buf == NULL) {
		prsm_problems_add(problems, path, "memory", "out of memory reading the measured CSV");
		return PRSM_ENOMEM;
	}
	if (rc == 0 && len > PRSM_IO_MEASURED_CSV_BYTES_MAX) {
		prsm_problems_add(problems, path, "too_large",
		                  "the measured CSV is larger than %u MiB: a TE curve is limited to %d points (decimate it)",
		                  PRSM_IO_MEASURED_CSV_BYTES_MAX >> 20, PRSM_MEAS_POINTS_MAX);
		rc = PRSM_EINVAL;
	}
	if (rc == 0)
		rc = prsm_io_measured_csv_parse(c, origin, buf, len, path, problems);
	free(buf);
	return rc;
}

int prsm_io_measured_curve_check(prsm_meas_curve *c, const prsm_io_csv_origin *origin, const char *source,
                                 double lead_mm, prsm_problems *problems)
{
	prsm_meas_problem p;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_meas_curve_complete(c, lead_mm, &p, &err) == 0)
		return 0;
	const int column = p.what == PRSM_MEAS_OK ? -1 : p.column;
	if (origin && origin->line && c->n > 0) {
		const size_t i = p.index < c->n ? p.index : c->n - 1;
		if (column >= 0 && origin->column[column] > 0)
			prsm_problems_add(problems, source, "csv", "line %ld, column %d (%s): %s", origin->line[i],
			                  origin->column[column], column_names[column], err.message);
		else
			prsm_problems_add(problems, source, "csv", "line %ld: %s", origin->line[i], err.message);
	} else if (origin) {
		prsm_problems_add(problems, source, "csv", "%s", err.message);
	} else {
		char ptr[PRSM_JSON_POINTER_MAX];
		if (column >= 0 && c->n > 0 && p.what != PRSM_MEAS_TOO_MANY) {
			char arr[PRSM_JSON_POINTER_MAX];
			prsm_json_pointer_append(arr, sizeof arr, "/measured/te", column_names[column]);
			prsm_json_pointer_append_index(ptr, sizeof ptr, arr, (int)(p.index < c->n ? p.index : c->n - 1));
		} else {
			snprintf(ptr, sizeof ptr, "/measured/te");
		}
		prsm_problems_add(problems, ptr, "measured", "%s", err.message);
	}
	return PRSM_EINVAL;
}

/* ---- JSON: the table's hooks ---- */

/* measured.te: the arrays, all of one length, every item a number (finite by JSON) */
void prsm_io_hook_measured_te(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_meas_data *m = base;
	const cJSON *te = cJSON_GetObjectItemCaseSensitive(obj, "te");
	if (te == NULL)
		return;
	char ptr[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "te");
	if (prsm_json_object_value(te, ptr, problems))
		return;
	if (prsm_json_check_keys(te, ptr, column_names, problems))
		return;
	const cJSON *arr[3];
	int n = -1, bad = 0;
	for (int k = 0; k < 3; k++) {
		arr[k] = cJSON_GetObjectItemCaseSensitive(te, column_names[k]);
		char ap[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append(ap, sizeof ap, ptr, column_names[k]);
		if (arr[k] == NULL) {
			if (k == 2) {
				prsm_problems_add(problems, ap, "required", "the TE of each point, um, is required");
				bad = 1;
			}
			continue;
		}
		if (!cJSON_IsArray(arr[k])) {
			prsm_problems_add(problems, ap, "type", "must be an array of numbers (got %s)", prsm_json_type_name(arr[k]));
			bad = 1;
			arr[k] = NULL;
			continue;
		}
		const int len = cJSON_GetArraySize(arr[k]);
		if (len > PRSM_MEAS_POINTS_MAX) {
			prsm_problems_add(problems, ap, "too_many", "a measured TE curve has at most %d points (got %d): decimate it",
			                  PRSM_MEAS_POINTS_MAX, len);
			bad = 1;
			arr[k] = NULL;
			continue;
		}
		if (n >= 0 && len != n) {
			prsm_problems_add(problems, ap, "length", "has %d items where the other arrays of the curve have %d", len, n);
			bad = 1;
		}
		if (n < 0)
			n = len;
		int i = 0;
		for (const cJSON *it = arr[k]->child; it; it = it->next, i++)
			if (!cJSON_IsNumber(it)) {
				char ip[PRSM_JSON_POINTER_MAX];
				prsm_json_pointer_append_index(ip, sizeof ip, ap, i);
				prsm_problems_add(problems, ip, "type", "must be a number (got %s)", prsm_json_type_name(it));
				bad = 1;
				break;
			}
	}
	if (!bad && arr[0] == NULL && arr[1] == NULL) {
		prsm_problems_add(problems, ptr, "required", "the curve needs screw_angle_rad or travel_mm beside te_um");
		bad = 1;
	}
	if (bad || n < 0)
		return;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_meas_curve_free(&m->te);
	if (prsm_meas_curve_alloc(&m->te, (size_t)n, &err)) {
		prsm_problems_add(problems, ptr, "memory", "%s", err.message);
		return;
	}
	double *dest[3] = {m->te.angle_rad, m->te.travel_mm, m->te.te_um};
	for (int k = 0; k < 3; k++) {
		if (arr[k] == NULL)
			continue;
		int i = 0;
		for (const cJSON *it = arr[k]->child; it; it = it->next, i++)
			dest[k][i] = it->valuedouble;
	}
	m->te.has_angle = arr[0] != NULL;
	m->te.has_travel = arr[1] != NULL;
	m->has_te = 1;
}

static const char *const line_keys[PRSM_CALIB_LINE_KINDS + 1] = {
	"screw_rev", "screw", "carrier", "roller_spin", "roller_pass_nut", "roller_pass_screw", "mesh", NULL};

void prsm_io_hook_calibrate_lines(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	prsm_calib_options *o = base;
	const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, "lines");
	if (a == NULL)
		return;
	char ptr[PRSM_JSON_POINTER_MAX];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, "lines");
	if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) < 1 || cJSON_GetArraySize(a) > PRSM_CALIB_LINE_KINDS) {
		prsm_problems_add(problems, ptr, "bad_array", "must be an array of 1 to %d line names (%s, ...)",
		                  PRSM_CALIB_LINE_KINDS, line_keys[0]);
		return;
	}
	int mask = 0, i = 0, bad = 0;
	for (const cJSON *it = a->child; it; it = it->next, i++) {
		char ip[PRSM_JSON_POINTER_MAX];
		prsm_json_pointer_append_index(ip, sizeof ip, ptr, i);
		int v;
		if (prsm_json_enum_value(&v, it, ip, line_keys, problems)) {
			bad = 1;
			continue;
		}
		if (mask & (1 << v)) {
			prsm_problems_add(problems, ip, "duplicate", "the line %s is named twice", line_keys[v]);
			bad = 1;
		}
		mask |= 1 << v;
	}
	if (!bad)
		o->lines_mask = mask;
}

/* Each of `parameters` (a string of at most PRSM_CALIB_NAME_MAX - 1 characters, the schema's
 * maxLength) in the order given; a name given twice is a problem, and kept. */
int prsm_io_step_calibrate_parameter(prsm_io_at *at, prsm_problems *problems)
{
	prsm_calib_options *o = at->base;
	const char *s = at->obj->valuestring;
	for (int j = 0; j < o->fields; j++)
		if (strcmp(o->field_names[j], s) == 0)
			prsm_problems_add(problems, at->pointer, "duplicate", "\"%s\" is named twice", s);
	snprintf(o->field_names[o->fields++], PRSM_CALIB_NAME_MAX, "%s", s);
	return 0;
}

/* After the fields (the table's last step): a standard uncertainty, or the load and speed of a
 * measurement, needs the measured value it belongs to. */
int prsm_io_step_measured_needs(prsm_io_at *at, prsm_problems *problems)
{
	static const char *const pairs[][2] = {{"cage_ratio_sd", "cage_ratio"}, {"efficiency_sd", "efficiency"},
	                                       {"cage_axial_load_N", "cage_ratio"},
	                                       {"cage_screw_speed_rad_s", "cage_ratio"},
	                                       {"efficiency_axial_load_N", "efficiency"},
	                                       {"efficiency_screw_speed_rad_s", "efficiency"}};
	for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++)
		if (cJSON_GetObjectItemCaseSensitive(at->obj, pairs[k][0]) &&
		    !cJSON_GetObjectItemCaseSensitive(at->obj, pairs[k][1]))
			prsm_io_problem(problems, at->pointer, pairs[k][0], "needs", "belongs to a measured %s, which is not given",
			                pairs[k][1]);
	return 0;
}

/* obj (NULL: absent, nothing read) at pointer into base by table t. */
static int read_object(void *base, const prsm_io_table *t, const cJSON *obj, const char *pointer, prsm_problems *problems)
{
	if (obj == NULL)
		return 0;
	if (prsm_json_object_value(obj, pointer, problems))
		return PRSM_EINVAL;
	return prsm_io_read(base, t, obj, pointer, problems);
}

int prsm_io_measured_read(prsm_meas_data *m, const cJSON *obj, prsm_problems *problems)
{
	prsm_meas_data_init(m);
	return read_object(m, &prsm_io_t_measured, obj, "/measured", problems);
}

/* After the fields (the table's last step): the members of the other model than `model` names,
 * and the physical model's parameters. */
int prsm_io_step_calibrate_model_members(prsm_io_at *at, prsm_problems *problems)
{
	const prsm_calib_options *o = at->base;
	const cJSON *model = cJSON_GetObjectItemCaseSensitive(at->obj, "model");
	const int physical = o->model == PRSM_CALIB_MODEL_PHYSICAL;
	if (physical && o->fields == 0 && !prsm_io_problem_at(problems, at->start, at->pointer, "parameters"))
		prsm_io_problem(problems, at->pointer, "parameters", "required",
		                "the physical model calibrates the error fields named here (e.g. [\"nut.runout_um\", "
		                "\"nut.runout_phase_deg\"])");
	static const char *const line_only[] = {"lines", "carrier_ratio_prior", "grid_half_width", "grid_points", "refine", NULL};
	static const char *const phys_only[] = {"parameters", "max_evaluations", NULL};
	const char *const *wrong = physical ? line_only : phys_only;
	for (int i = 0; wrong[i]; i++)
		if (cJSON_GetObjectItemCaseSensitive(at->obj, wrong[i]))
			prsm_io_problem(problems, at->pointer, wrong[i], "not_used", "belongs to the %s model, not the %s "
			                "model (\"model\": \"%s\")", physical ? "line" : "physical", physical ? "physical" : "line",
			                model && cJSON_IsString(model) ? model->valuestring : "line");
	return 0;
}

int prsm_io_calibrate_options_read(prsm_calib_options *o, const cJSON *obj, prsm_problems *problems)
{
	prsm_calib_options_init(o);
	return read_object(o, &prsm_io_t_dynamics_calibrate, obj, "/dynamics/calibrate", problems);
}
