/*
 * json_util.c: strict JSON text parsing, RFC 6901 pointers and the typed field readers that every
 * io/ document reader is built from (see json_util.h for the conventions).
 *
 * cJSON is lax in a few places that matter for a service: it accepts invalid UTF-8, leading zeros
 * and "1." as numbers, raw control characters in strings, and nests up to 1000 levels by
 * recursion. prsm_json_parse() checks those first with one linear pass over the text, then lets
 * cJSON build the tree, then refuses data after the value.
 */
#include "io/json_util.h"

#include <assert.h>
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/dtoa.h"

/* Room for describing a value or a range inside a message. */
#define DESCRIBE_MAX 96

/* ---- text ------------------------------------------------------------------------------- */

size_t prsm_json_utf8_invalid_at(const char *text, size_t len)
{
	const unsigned char *s = (const unsigned char *)text;
	size_t i = 0;
	while (i < len) {
		unsigned char c = s[i];
		if (c < 0x80) {
			i++;
			continue;
		}
		/* RFC 3629 / Unicode Table 3-7: well-formed byte sequences */
		int follow;
		unsigned char lo = 0x80, hi = 0xBF;
		if (c >= 0xC2 && c <= 0xDF) {
			follow = 1;
		} else if (c == 0xE0) {
			follow = 2;
			lo = 0xA0;
		} else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) {
			follow = 2;
		} else if (c == 0xED) {
			follow = 2;
			hi = 0x9F; /* no UTF-16 surrogates */
		} else if (c == 0xF0) {
			follow = 3;
			lo = 0x90;
		} else if (c >= 0xF1 && c <= 0xF3) {
			follow = 3;
		} else if (c == 0xF4) {
			follow = 3;
			hi = 0x8F; /* nothing above U+10FFFF */
		} else {
			return i;
		}
		for (int k = 1; k <= follow; k++) {
			if (i + (size_t)k >= len)
				return i;
			unsigned char b = s[i + (size_t)k];
			unsigned char l = (k == 1) ? lo : 0x80, h = (k == 1) ? hi : 0xBF;
			if (b < l || b > h)
				return i;
		}
		i += (size_t)follow + 1;
	}
	return len;
}

/* 1-based line and byte column of offset off, for messages. */
static void line_column(const char *text, size_t off, size_t *line, size_t *column)
{
	size_t l = 1, line_start = 0;
	for (size_t i = 0; i < off; i++) {
		if (text[i] == '\n') {
			l++;
			line_start = i + 1;
		}
	}
	*line = l;
	*column = off - line_start + 1;
}

static void add_malformed(prsm_problems *problems, const char *text, size_t off, const char *what)
{
	size_t line, column;
	line_column(text, off, &line, &column);
	prsm_problems_add(problems, "", "malformed_json", "malformed JSON at byte %zu (line %zu, column %zu)%s%s",
	                  off, line, column, what ? ": " : "", what ? what : "");
}

static int is_digit(char c)
{
	return c >= '0' && c <= '9';
}

/* 1 when s[0..n) is a JSON number: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)? */
static int number_grammar_ok(const char *s, size_t n)
{
	size_t k = 0;
	if (k < n && s[k] == '-')
		k++;
	if (k >= n)
		return 0;
	if (s[k] == '0') {
		k++;
	} else if (is_digit(s[k])) {
		while (k < n && is_digit(s[k]))
			k++;
	} else {
		return 0;
	}
	if (k < n && s[k] == '.') {
		k++;
		if (!(k < n && is_digit(s[k])))
			return 0;
		while (k < n && is_digit(s[k]))
			k++;
	}
	if (k < n && (s[k] == 'e' || s[k] == 'E')) {
		k++;
		if (k < n && (s[k] == '+' || s[k] == '-'))
			k++;
		if (!(k < n && is_digit(s[k])))
			return 0;
		while (k < n && is_digit(s[k]))
			k++;
	}
	return k == n;
}

static int is_number_char(char c)
{
	return is_digit(c) || c == '+' || c == '-' || c == '.' || c == 'e' || c == 'E';
}

/*
 * One pass over the text outside of cJSON: nesting depth, raw control characters and the \u0000
 * escape in strings, number literals. Structural errors it does not look for are cJSON's.
 * Returns 0 or PRSM_EINVAL after adding one problem.
 */
static int prescan(const char *text, size_t start, size_t len, prsm_problems *problems)
{
	int depth = 0;
	size_t i = start;
	while (i < len) {
		char c = text[i];
		if (c == '"') {
			i++;
			while (i < len && text[i] != '"') {
				unsigned char s = (unsigned char)text[i];
				if (s < 0x20) {
					char what[64];
					snprintf(what, sizeof what, "control character U+%04X in a string must be escaped", s);
					add_malformed(problems, text, i, what);
					return PRSM_EINVAL;
				}
				if (s == '\\') {
					if (i + 5 < len && memcmp(text + i + 1, "u0000", 5) == 0) {
						add_malformed(problems, text, i, "the escape \\u0000 (NUL) is not accepted in strings");
						return PRSM_EINVAL;
					}
					i += 2;
				} else {
					i++;
				}
			}
			i++; /* the closing quote; an unterminated string is cJSON's to report */
			continue;
		}
		if (c == '[' || c == '{') {
			if (++depth > PRSM_JSON_MAX_DEPTH) {
				size_t line, column;
				line_column(text, i, &line, &column);
				prsm_problems_add(problems, "", "too_deep",
				                  "JSON nesting deeper than %d levels at byte %zu (line %zu, column %zu)",
				                  PRSM_JSON_MAX_DEPTH, i, line, column);
				return PRSM_EINVAL;
			}
		} else if (c == ']' || c == '}') {
			if (depth > 0)
				depth--;
		} else if (c == '-' || is_digit(c)) {
			size_t j = i;
			while (j < len && is_number_char(text[j]))
				j++;
			if (!number_grammar_ok(text + i, j - i)) {
				add_malformed(problems, text, i, "invalid number");
				return PRSM_EINVAL;
			}
			if (j - i > PRSM_JSON_MAX_NUMBER_CHARS) {
				char what[80];
				snprintf(what, sizeof what, "number longer than %d characters",
				         PRSM_JSON_MAX_NUMBER_CHARS);
				add_malformed(problems, text, i, what);
				return PRSM_EINVAL;
			}
			i = j;
			continue;
		}
		i++;
	}
	return 0;
}

static int is_json_space(char c)
{
	return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

cJSON *prsm_json_parse(const char *text, size_t len, prsm_problems *problems)
{
	assert(problems != NULL);
	assert(text != NULL || len == 0);
	if (text == NULL)
		text = "";
	size_t bad = prsm_json_utf8_invalid_at(text, len);
	if (bad < len) {
		prsm_problems_add(problems, "", "invalid_utf8", "invalid UTF-8 at byte %zu", bad);
		return NULL;
	}
	size_t start = 0;
	if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
		start = 3; /* RFC 8259 §8.1: a parser may ignore a byte order mark */
	size_t first = start;
	while (first < len && is_json_space(text[first]))
		first++;
	if (first >= len) {
		add_malformed(problems, text, first, "the document is empty");
		return NULL;
	}
	if (prescan(text, start, len, problems) != 0)
		return NULL;

	const char *end = NULL;
	cJSON *root = cJSON_ParseWithLengthOpts(text + start, len - start, &end, 0);
	if (root == NULL) {
		size_t off = (end != NULL && end >= text && end <= text + len) ? (size_t)(end - text) : start;
		add_malformed(problems, text, off, NULL);
		return NULL;
	}
	size_t off = (end != NULL) ? (size_t)(end - text) : len;
	while (off < len && is_json_space(text[off]))
		off++;
	if (off < len) {
		cJSON_Delete(root);
		add_malformed(problems, text, off, "unexpected data after the JSON value");
		return NULL;
	}
	return root;
}

/* ---- pointers and messages ------------------------------------------------------------- */

int prsm_json_pointer_append(char *out, size_t cap, const char *base, const char *token)
{
	assert(out != NULL && cap > 0);
	if (base == NULL)
		base = "";
	if (token == NULL)
		token = "";
	size_t blen = strlen(base);
	if (blen + 1 > cap) {
		out[0] = '\0';
		return PRSM_ENOMEM;
	}
	if (out != base)
		memmove(out, base, blen + 1);
	size_t k = blen;
	if (k + 1 >= cap)
		goto overflow;
	out[k++] = '/';
	for (const char *t = token; *t; t++) {
		const char *rep = NULL;
		if (*t == '~')
			rep = "~0";
		else if (*t == '/')
			rep = "~1";
		size_t need = rep ? 2 : 1;
		if (k + need >= cap)
			goto overflow;
		if (rep) {
			out[k++] = rep[0];
			out[k++] = rep[1];
		} else {
			out[k++] = *t;
		}
	}
	out[k] = '\0';
	return 0;
overflow:
	out[blen] = '\0';
	return PRSM_ENOMEM;
}

int prsm_json_pointer_append_index(char *out, size_t cap, const char *base, int index)
{
	char token[16];
	assert(index >= 0);
	snprintf(token, sizeof token, "%d", index);
	return prsm_json_pointer_append(out, cap, base, token);
}

const char *prsm_json_type_name(const cJSON *item)
{
	if (item == NULL)
		return "nothing";
	if (cJSON_IsObject(item))
		return "an object";
	if (cJSON_IsArray(item))
		return "an array";
	if (cJSON_IsString(item))
		return "a string";
	if (cJSON_IsNumber(item))
		return "a number";
	if (cJSON_IsBool(item))
		return "a boolean";
	if (cJSON_IsNull(item))
		return "null";
	return "an invalid value";
}

void prsm_json_format_number(char *out, size_t cap, double v)
{
	assert(out != NULL && cap > 0);
	if (isnan(v)) {
		snprintf(out, cap, "nan");
		return;
	}
	if (isinf(v)) {
		snprintf(out, cap, "%s", v > 0 ? "inf" : "-inf");
		return;
	}
	if (v == floor(v) && fabs(v) < 1e15) {
		snprintf(out, cap, "%.0f", v);
		return;
	}
	/* util/dtoa's shortest digits in printf's %g layout with that many digits */
	char d[PRSM_DTOA_DIGITS_MAX + 1], text[PRSM_DTOA_TEXT_MAX];
	int point, k = prsm_dtoa_shortest(v, d, &point), x = point - 1;
	const char *sign = v < 0 ? "-" : "";
	if (x < -4 || x >= k) /* d[.ddd]e(+|-)xx */
		snprintf(text, sizeof text, "%s%c%s%.*se%c%02d", sign, d[0], k > 1 ? "." : "", k - 1, d + 1,
		         x < 0 ? '-' : '+', abs(x));
	else if (x >= 0) /* ddd[.ddd] */
		snprintf(text, sizeof text, "%s%.*s%s%s", sign, x + 1, d, k > x + 1 ? "." : "", d + x + 1);
	else /* 0.000ddd */
		snprintf(text, sizeof text, "%s0.%.*s%s", sign, -x - 1, "0000", d);
	snprintf(out, cap, "%s", text);
}

void prsm_json_excerpt(char *out, size_t cap, const char *s)
{
	assert(out != NULL && cap >= 4);
	if (s == NULL)
		s = "";
	size_t n = strlen(s), cut = n;
	int cutting = n >= cap;
	if (cutting) {
		cut = cap - 4; /* room for "..." and the NUL */
		while (cut > 0 && ((unsigned char)s[cut] & 0xC0) == 0x80)
			cut--;
	}
	for (size_t i = 0; i < cut; i++) {
		unsigned char c = (unsigned char)s[i];
		out[i] = (c < 0x20 || c == 0x7F) ? '?' : (char)c; /* messages are one line */
	}
	if (cutting)
		memcpy(out + cut, "...", 4);
	else
		out[cut] = '\0';
}

/* "the string \"abc\"", "2.5", "true", "null", "an object": what a message says it got. */
static void describe_got(char *out, size_t cap, const cJSON *item)
{
	if (cJSON_IsString(item)) {
		char ex[40];
		prsm_json_excerpt(ex, sizeof ex, item->valuestring);
		snprintf(out, cap, "the string \"%s\"", ex);
	} else if (cJSON_IsNumber(item)) {
		prsm_json_format_number(out, cap, item->valuedouble);
	} else if (cJSON_IsBool(item)) {
		snprintf(out, cap, "%s", cJSON_IsTrue(item) ? "true" : "false");
	} else {
		snprintf(out, cap, "%s", prsm_json_type_name(item));
	}
}

/* " > 0 and <= 50", " from 0 to 1", "" (no limits): the range as words, with a leading space. */
static void describe_range(char *out, size_t cap, prsm_json_range r)
{
	char lo[40], hi[40];
	int has_lo = isfinite(r.min), has_hi = isfinite(r.max);
	prsm_json_format_number(lo, sizeof lo, r.min);
	prsm_json_format_number(hi, sizeof hi, r.max);
	if (has_lo && has_hi && !r.min_exclusive && !r.max_exclusive)
		snprintf(out, cap, " from %s to %s", lo, hi);
	else if (has_lo && has_hi)
		snprintf(out, cap, " %s %s and %s %s", r.min_exclusive ? ">" : ">=", lo,
		         r.max_exclusive ? "<" : "<=", hi);
	else if (has_lo)
		snprintf(out, cap, " %s %s", r.min_exclusive ? ">" : ">=", lo);
	else if (has_hi)
		snprintf(out, cap, " %s %s", r.max_exclusive ? "<" : "<=", hi);
	else
		out[0] = '\0';
}

/* ---- object shape ----------------------------------------------------------------------- */

static const char *key_of(const cJSON *item)
{
	return (item != NULL && item->string != NULL) ? item->string : "";
}

typedef struct {
	const char *name;
	int index;
} key_entry;

static int key_entry_cmp(const void *a, const void *b)
{
	const key_entry *x = a, *y = b;
	int c = strcmp(x->name, y->name);
	if (c != 0)
		return c;
	return (x->index > y->index) - (x->index < y->index);
}

static void report_duplicate(prsm_problems *problems, const char *obj_pointer, const cJSON *child)
{
	char ptr[PRSM_JSON_POINTER_MAX], ex[64];
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, key_of(child));
	prsm_json_excerpt(ex, sizeof ex, key_of(child));
	prsm_problems_add(problems, ptr, "duplicate_key",
	                  "duplicate key \"%s\": give each field once (which one counts is undefined in JSON)", ex);
}

int prsm_json_check_duplicates(const cJSON *obj, const char *obj_pointer, prsm_problems *problems)
{
	int n = 0, found = 0;
	for (const cJSON *c = obj ? obj->child : NULL; c != NULL; c = c->next)
		n++;
	if (n < 2)
		return 0;
	if (n <= 16) { /* small objects: compare every pair, report in document order */
		for (const cJSON *c = obj->child; c != NULL; c = c->next) {
			for (const cJSON *p = obj->child; p != c; p = p->next) {
				if (strcmp(key_of(p), key_of(c)) == 0) {
					report_duplicate(problems, obj_pointer, c);
					found = 1;
					break;
				}
			}
		}
		return found ? PRSM_EINVAL : 0;
	}
	/* large objects (a hostile body can hold 100k keys): sort once, O(n log n) */
	key_entry *keys = malloc((size_t)n * sizeof *keys);
	unsigned char *dup = calloc((size_t)n, 1);
	int rc = 0;
	if (keys == NULL || dup == NULL) {
		prsm_problems_add(problems, obj_pointer ? obj_pointer : "", "out_of_memory",
		                  "could not check the %d keys of this object for duplicates: out of memory", n);
		rc = PRSM_ENOMEM;
		goto cleanup;
	}
	int i = 0;
	for (const cJSON *c = obj->child; c != NULL; c = c->next, i++)
		keys[i] = (key_entry){key_of(c), i};
	qsort(keys, (size_t)n, sizeof *keys, key_entry_cmp);
	for (i = 1; i < n; i++) {
		if (strcmp(keys[i].name, keys[i - 1].name) == 0) {
			dup[keys[i].index] = 1;
			found = 1;
		}
	}
	i = 0;
	for (const cJSON *c = obj->child; c != NULL; c = c->next, i++)
		if (dup[i])
			report_duplicate(problems, obj_pointer, c);
	rc = found ? PRSM_EINVAL : 0;
cleanup:
	free(keys);
	free(dup);
	return rc;
}

/* Levenshtein distance of two short lowercase-folded strings; -1 when either is too long. */
static int edit_distance(const char *a, const char *b)
{
	enum { MAXLEN = 64 };
	size_t la = strlen(a), lb = strlen(b);
	if (la > MAXLEN || lb > MAXLEN)
		return -1;
	int prev[MAXLEN + 1], cur[MAXLEN + 1];
	for (size_t j = 0; j <= lb; j++)
		prev[j] = (int)j;
	for (size_t i = 1; i <= la; i++) {
		cur[0] = (int)i;
		for (size_t j = 1; j <= lb; j++) {
			int cost = tolower((unsigned char)a[i - 1]) != tolower((unsigned char)b[j - 1]);
			int best = prev[j - 1] + cost;
			if (prev[j] + 1 < best)
				best = prev[j] + 1;
			if (cur[j - 1] + 1 < best)
				best = cur[j - 1] + 1;
			cur[j] = best;
		}
		memcpy(prev, cur, (lb + 1) * sizeof prev[0]);
	}
	return prev[lb];
}

/* The allowed name a misspelt key most likely meant, or NULL. A key that is an allowed name
 * without its unit suffix ("pitch" for "pitch_mm") counts as a match. */
const char *prsm_json_closest_name(const char *key, const char *const *allowed)
{
	size_t klen = strlen(key);
	if (klen == 0)
		return NULL;
	const char *best = NULL;
	int best_d = -1;
	for (const char *const *a = allowed; *a; a++) {
		if (strncmp(*a, key, klen) == 0 && (*a)[klen] == '_')
			return *a;
		int d = edit_distance(key, *a);
		if (d < 0)
			continue;
		int limit = (int)(klen / 3) > 2 ? (int)(klen / 3) : 2;
		if (d <= limit && (best_d < 0 || d < best_d)) {
			best = *a;
			best_d = d;
		}
	}
	return best;
}

static void report_unknown(prsm_problems *problems, const char *obj_pointer, const cJSON *child,
                           const char *const *allowed)
{
	char ptr[PRSM_JSON_POINTER_MAX], ex[64], msg[PRSM_PROBLEM_MESSAGE_MAX];
	const char *key = key_of(child);
	prsm_json_pointer_append(ptr, sizeof ptr, obj_pointer, key);
	prsm_json_excerpt(ex, sizeof ex, key);
	const char *guess = prsm_json_closest_name(key, allowed);
	int len;
	if (guess)
		len = snprintf(msg, sizeof msg, "unknown field \"%s\" (did you mean \"%s\"?); allowed: ", ex, guess);
	else
		len = snprintf(msg, sizeof msg, "unknown field \"%s\"; allowed: ", ex);
	size_t k = (len > 0 && (size_t)len < sizeof msg) ? (size_t)len : strlen(msg);
	int total = 0;
	for (const char *const *a = allowed; *a; a++)
		total++;
	const size_t tail = 20; /* room for " and 99 more" */
	int listed = 0;
	for (const char *const *a = allowed; *a; a++, listed++) {
		size_t need = strlen(*a) + (listed ? 2 : 0);
		if (k + need + tail >= sizeof msg)
			break;
		k += (size_t)snprintf(msg + k, sizeof msg - k, "%s%s", listed ? ", " : "", *a);
	}
	if (listed < total)
		snprintf(msg + k, sizeof msg - k, " and %d more", total - listed);
	prsm_problems_add(problems, ptr, "unknown_field", "%s", msg);
}

int prsm_json_check_keys(const cJSON *obj, const char *obj_pointer, const char *const *allowed,
                         prsm_problems *problems)
{
	int rc = prsm_json_check_duplicates(obj, obj_pointer, problems);
	if (allowed == NULL || obj == NULL)
		return rc;
	for (const cJSON *c = obj->child; c != NULL; c = c->next) {
		const char *key = key_of(c);
		int known = 0;
		for (const char *const *a = allowed; *a && !known; a++)
			known = strcmp(*a, key) == 0;
		if (!known) {
			report_unknown(problems, obj_pointer, c, allowed);
			if (rc == 0)
				rc = PRSM_EINVAL;
		}
	}
	return rc;
}

/* ---- value checkers --------------------------------------------------------------------- */

static int check_finite(const cJSON *item, const char *pointer, prsm_problems *problems)
{
	char got[16];
	if (isfinite(item->valuedouble))
		return 0;
	prsm_json_format_number(got, sizeof got, item->valuedouble);
	prsm_problems_add(problems, pointer, "not_finite",
	                  "must be a finite number (got %s: the literal is out of the range of a double)",
	                  got);
	return PRSM_EINVAL;
}

int prsm_json_number_value(double *out, const cJSON *item, const char *pointer,
                           prsm_json_range range, prsm_problems *problems)
{
	char rdesc[DESCRIBE_MAX], got[DESCRIBE_MAX], limit[40];
	if (!cJSON_IsNumber(item)) {
		describe_range(rdesc, sizeof rdesc, range);
		describe_got(got, sizeof got, item);
		prsm_problems_add(problems, pointer, "type", "must be a number%s (got %s)", rdesc, got);
		return PRSM_EINVAL;
	}
	if (check_finite(item, pointer, problems) != 0)
		return PRSM_EINVAL;
	double v = item->valuedouble;
	prsm_json_format_number(got, sizeof got, v);
	int low = range.min_exclusive ? !(v > range.min) : !(v >= range.min);
	int high = range.max_exclusive ? !(v < range.max) : !(v <= range.max);
	if (low || high) {
		prsm_json_format_number(limit, sizeof limit, low ? range.min : range.max);
		const char *op = low ? (range.min_exclusive ? ">" : ">=") : (range.max_exclusive ? "<" : "<=");
		prsm_problems_add(problems, pointer, "range", "must be a number %s %s (got %s)", op, limit, got);
		return PRSM_EINVAL;
	}
	*out = v;
	return 0;
}

int prsm_json_int_value(int *out, const cJSON *item, const char *pointer, int min, int max,
                        prsm_problems *problems)
{
	char got[DESCRIBE_MAX];
	assert(min <= max);
	describe_got(got, sizeof got, item);
	if (!cJSON_IsNumber(item)) {
		prsm_problems_add(problems, pointer, "type", "must be an integer from %d to %d (got %s)",
		                  min, max, got);
		return PRSM_EINVAL;
	}
	if (check_finite(item, pointer, problems) != 0)
		return PRSM_EINVAL;
	double v = item->valuedouble;
	if (v != floor(v)) {
		prsm_problems_add(problems, pointer, "not_integer", "must be an integer from %d to %d (got %s)",
		                  min, max, got);
		return PRSM_EINVAL;
	}
	if (v < (double)min) {
		prsm_problems_add(problems, pointer, "range", "must be an integer >= %d (got %s)", min, got);
		return PRSM_EINVAL;
	}
	if (v > (double)max) {
		prsm_problems_add(problems, pointer, "range", "must be an integer <= %d (got %s)", max, got);
		return PRSM_EINVAL;
	}
	*out = (int)v; /* in [min, max], so representable */
	return 0;
}

int prsm_json_string_value(const char **out, const cJSON *item, const char *pointer,
                           size_t max_chars, prsm_problems *problems)
{
	char got[DESCRIBE_MAX];
	if (!cJSON_IsString(item) || item->valuestring == NULL) {
		describe_got(got, sizeof got, item);
		prsm_problems_add(problems, pointer, "type", "must be a string (got %s)", got);
		return PRSM_EINVAL;
	}
	size_t chars = 0;
	for (const unsigned char *s = (const unsigned char *)item->valuestring; *s; s++)
		chars += (*s & 0xC0) != 0x80; /* count UTF-8 lead bytes: characters */
	if (chars > max_chars) {
		prsm_problems_add(problems, pointer, "too_long",
		                  "must be a string of at most %zu characters (got %zu)", max_chars, chars);
		return PRSM_EINVAL;
	}
	*out = item->valuestring;
	return 0;
}

/* "\"right\", \"left\"" into out, bounded. */
static void list_names(char *out, size_t cap, const char *const *names)
{
	size_t k = 0;
	out[0] = '\0';
	for (const char *const *n = names; *n; n++) {
		int w = snprintf(out + k, cap - k, "%s\"%s\"", n == names ? "" : ", ", *n);
		if (w < 0 || (size_t)w >= cap - k)
			break;
		k += (size_t)w;
	}
}

int prsm_json_enum_value(int *out, const cJSON *item, const char *pointer,
                         const char *const *names, prsm_problems *problems)
{
	char got[DESCRIBE_MAX], list[DESCRIBE_MAX];
	if (cJSON_IsString(item) && item->valuestring != NULL) {
		for (int i = 0; names[i]; i++) {
			if (strcmp(names[i], item->valuestring) == 0) {
				*out = i;
				return 0;
			}
		}
	}
	describe_got(got, sizeof got, item);
	list_names(list, sizeof list, names);
	prsm_problems_add(problems, pointer, cJSON_IsString(item) ? "enum" : "type",
	                  "must be one of %s (got %s)", list, got);
	return PRSM_EINVAL;
}

int prsm_json_object_value(const cJSON *item, const char *pointer, prsm_problems *problems)
{
	char got[DESCRIBE_MAX];
	if (cJSON_IsObject(item))
		return 0;
	describe_got(got, sizeof got, item);
	prsm_problems_add(problems, pointer, "type", "must be an object (got %s)", got);
	return PRSM_EINVAL;
}

/* ---- field readers ---------------------------------------------------------------------- */

/* obj[key] (case-sensitive, first occurrence) and its pointer. */
static const cJSON *member(char *ptr, size_t cap, const cJSON *obj, const char *obj_pointer,
                           const char *key)
{
	prsm_json_pointer_append(ptr, cap, obj_pointer, key);
	return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

static int missing(int required, const char *ptr, prsm_problems *problems, const char *what)
{
	if (!required)
		return PRSM_JSON_ABSENT;
	prsm_problems_add(problems, ptr, "required", "is required (%s)", what);
	return PRSM_EINVAL;
}

int prsm_json_get_number(double *out, const cJSON *obj, const char *obj_pointer, const char *key,
                         int required, prsm_json_range range, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX], what[DESCRIBE_MAX + 16], rdesc[DESCRIBE_MAX];
	const cJSON *item = member(ptr, sizeof ptr, obj, obj_pointer, key);
	if (item == NULL) {
		describe_range(rdesc, sizeof rdesc, range);
		snprintf(what, sizeof what, "a number%s", rdesc);
		return missing(required, ptr, problems, what);
	}
	return prsm_json_number_value(out, item, ptr, range, problems) == 0 ? PRSM_JSON_PRESENT : PRSM_EINVAL;
}

int prsm_json_get_int(int *out, const cJSON *obj, const char *obj_pointer, const char *key,
                      int required, int min, int max, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX], what[DESCRIBE_MAX];
	const cJSON *item = member(ptr, sizeof ptr, obj, obj_pointer, key);
	if (item == NULL) {
		snprintf(what, sizeof what, "an integer from %d to %d", min, max);
		return missing(required, ptr, problems, what);
	}
	return prsm_json_int_value(out, item, ptr, min, max, problems) == 0 ? PRSM_JSON_PRESENT : PRSM_EINVAL;
}

int prsm_json_get_string(const char **out, const cJSON *obj, const char *obj_pointer,
                         const char *key, int required, size_t max_chars, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX], what[DESCRIBE_MAX];
	const cJSON *item = member(ptr, sizeof ptr, obj, obj_pointer, key);
	if (item == NULL) {
		snprintf(what, sizeof what, "a string of at most %zu characters", max_chars);
		return missing(required, ptr, problems, what);
	}
	return prsm_json_string_value(out, item, ptr, max_chars, problems) == 0 ? PRSM_JSON_PRESENT
	                                                                          : PRSM_EINVAL;
}

int prsm_json_get_enum(int *out, const cJSON *obj, const char *obj_pointer, const char *key,
                       int required, const char *const *names, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX], what[DESCRIBE_MAX + 16], list[DESCRIBE_MAX];
	const cJSON *item = member(ptr, sizeof ptr, obj, obj_pointer, key);
	if (item == NULL) {
		list_names(list, sizeof list, names);
		snprintf(what, sizeof what, "one of %s", list);
		return missing(required, ptr, problems, what);
	}
	return prsm_json_enum_value(out, item, ptr, names, problems) == 0 ? PRSM_JSON_PRESENT : PRSM_EINVAL;
}

int prsm_json_get_bool(int *out, const cJSON *obj, const char *obj_pointer, const char *key,
                       int required, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX], got[DESCRIBE_MAX];
	const cJSON *item = member(ptr, sizeof ptr, obj, obj_pointer, key);
	if (item == NULL)
		return missing(required, ptr, problems, "true or false");
	if (cJSON_IsBool(item)) {
		*out = cJSON_IsTrue(item) ? 1 : 0;
		return PRSM_JSON_PRESENT;
	}
	describe_got(got, sizeof got, item);
	prsm_problems_add(problems, ptr, "type", "must be true or false (got %s)", got);
	return PRSM_EINVAL;
}

int prsm_json_get_object(const cJSON **out, const cJSON *obj, const char *obj_pointer,
                         const char *key, int required, prsm_problems *problems)
{
	char ptr[PRSM_JSON_POINTER_MAX];
	*out = NULL;
	const cJSON *item = member(ptr, sizeof ptr, obj, obj_pointer, key);
	if (item == NULL)
		return missing(required, ptr, problems, "an object");
	if (prsm_json_object_value(item, ptr, problems) != 0)
		return PRSM_EINVAL;
	*out = item;
	return PRSM_JSON_PRESENT;
}

int prsm_json_get_section(const cJSON **out, char *ptr, size_t cap, const cJSON *obj,
                          const char *obj_pointer, const char *key, int required,
                          const char *const *allowed, prsm_problems *problems)
{
	int rc = prsm_json_get_object(out, obj, obj_pointer, key, required, problems);
	if (rc != PRSM_JSON_PRESENT)
		return rc;
	prsm_json_pointer_append(ptr, cap, obj_pointer, key);
	prsm_json_check_keys(*out, ptr, allowed, problems);
	return rc;
}

void prsm_json_problems_append_prefixed(prsm_problems *dst, const prsm_problems *src,
                                        const char *prefix)
{
	char ptr[PRSM_PROBLEM_POINTER_MAX];
	if (prefix == NULL)
		prefix = "";
	for (int i = 0; i < src->count; i++) {
		const prsm_problem *p = &src->items[i];
		snprintf(ptr, sizeof ptr, "%s%s", prefix, p->pointer);
		prsm_problems_add(dst, ptr, p->code[0] ? p->code : NULL, "%s", p->message);
	}
	dst->dropped += src->dropped;
}

void prsm_json_add_number(cJSON *o, const char *name, double v)
{
	if (isfinite(v))
		cJSON_AddNumberToObject(o, name, v);
	else
		cJSON_AddNullToObject(o, name);
}
