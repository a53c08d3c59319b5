/*
 * json_util.h: reading request documents from cJSON trees, reporting every problem at once.
 *
 * Every document reader of io/ (design, study, optimisation, allocation) is built from these
 * pieces: a strict text parser (UTF-8, nesting depth, JSON grammar that cJSON is lax about), RFC
 * 6901 pointer building, an object shape check (unknown and duplicate keys) and typed field
 * readers that check type, finiteness, integrality and range. None of them stops at the first
 * problem: each adds what it finds to a prsm_problems list with the offending field's pointer and
 * a message that names the limit, and the caller reads on.
 *
 * Conventions of the field readers (prsm_json_get_*):
 *   - `obj` is the enclosing object, `obj_pointer` its pointer ("" for the document root), `key`
 *     the field's name; the problem's pointer is obj_pointer + "/" + escaped key.
 *   - Return PRSM_JSON_PRESENT (1) when the field is there and valid (out is written),
 *     PRSM_JSON_ABSENT (0) when it is not there and optional (out is left as it was),
 *     PRSM_EINVAL when it is there but invalid, or missing and required (a problem was added,
 *     out is left as it was).
 *   - A missing required field is reported at the field's own pointer, with "is required".
 *   - Lookup is case-sensitive. With duplicate keys the first occurrence is read; the duplicate
 *     itself is reported by prsm_json_check_keys().
 *
 * No function here allocates memory that outlives the call, except prsm_json_parse(), whose
 * tree the caller owns.
 */
#ifndef PRSM_IO_JSON_UTIL_H
#define PRSM_IO_JSON_UTIL_H

#include <stddef.h>

#include <cJSON.h>

#include "util/error.h"
#include "util/problems.h"

/* Deepest nesting of arrays and objects a document may have (the root object is level 1). */
#define PRSM_JSON_MAX_DEPTH 64
/* Longest number literal accepted (cJSON parses at most 63 characters of a number). */
#define PRSM_JSON_MAX_NUMBER_CHARS 63
/* Size of a pointer buffer: the same as a problem's pointer. */
#define PRSM_JSON_POINTER_MAX PRSM_PROBLEM_POINTER_MAX

enum { PRSM_JSON_ABSENT = 0, PRSM_JSON_PRESENT = 1 };
enum { PRSM_JSON_OPTIONAL = 0, PRSM_JSON_REQUIRED = 1 };

/* Closed or open interval for a number. Use -HUGE_VAL / HUGE_VAL for a side without limit. */
typedef struct {
	double min;        /* lower limit */
	double max;        /* upper limit */
	int min_exclusive; /* 1: value must be > min; 0: >= min */
	int max_exclusive; /* 1: value must be < max; 0: <= max */
} prsm_json_range;

/*
 * Parse len bytes of text (need not be NUL-terminated) into a cJSON tree. Refuses, with one
 * problem at pointer "" each: invalid UTF-8 ("invalid UTF-8 at byte N"), nesting deeper than
 * PRSM_JSON_MAX_DEPTH, raw control characters in strings, number literals that break the JSON
 * grammar or are too long, anything else cJSON rejects and data after the value ("malformed JSON
 * at byte N"). Byte offsets count from 0. A leading UTF-8 byte order mark is skipped.
 * Returns the tree, which the caller owns and frees with cJSON_Delete(), or NULL after adding a
 * problem.
 */
cJSON *prsm_json_parse(const char *text, size_t len, prsm_problems *problems);

/* Offset of the first byte that is not valid UTF-8 (RFC 3629: no overlongs, no surrogates,
 * nothing above U+10FFFF), or len when all of it is valid. The one UTF-8 check of prsm (the
 * canonical form of io/canonical.h uses it too). */
size_t prsm_json_utf8_invalid_at(const char *text, size_t len);

/*
 * out = base + "/" + token, with "~" escaped as "~0" and "/" as "~1" (RFC 6901). base NULL is
 * "", and base may be out itself (appending in place). Returns 0, or PRSM_ENOMEM when the
 * result does not fit in cap bytes; out then holds base (or "" when base does not fit either),
 * still a pointer to an ancestor. The one pointer builder of prsm (io/canonical.c uses it too).
 */
int prsm_json_pointer_append(char *out, size_t cap, const char *base, const char *token);

/* out = base + "/" + index (array element). Same return and overflow rule as above. */
int prsm_json_pointer_append_index(char *out, size_t cap, const char *base, int index);

/* "an object", "an array", "a string", "a number", "a boolean", "null" (for messages). */
const char *prsm_json_type_name(const cJSON *item);

/* Shortest decimal text of v that reads back as v, for messages: util/dtoa's digits (the same
 * as the canonical form's) in printf's %g layout ("2.5", "0.1", "-2", "100000000", "2.385e-07",
 * "1e+15"); "inf", "-inf", "nan" for the non-finite. Writes at most cap bytes (cap >= 32 always
 * suffices). */
void prsm_json_format_number(char *out, size_t cap, double v);

/* Copy at most cap - 1 bytes of s into out, cutting on a UTF-8 character boundary and ending
 * with "..." when it had to cut (for quoting user text in messages). */
void prsm_json_excerpt(char *out, size_t cap, const char *s);

/*
 * Check the shape of an object: every key must be one of `allowed` (NULL-terminated list) and
 * appear once. Unknown keys are reported at their own pointer with a message that names the
 * allowed keys (and the closest one when the key looks like a misspelling); each repetition of a
 * key is reported at that key's pointer. allowed NULL checks duplicates only (free-form maps).
 * Cost is O(n log n) in the number of keys. Returns 0, PRSM_EINVAL when a problem was added, or
 * PRSM_ENOMEM (a problem is added too) when the duplicate check could not allocate.
 */
int prsm_json_check_keys(const cJSON *obj, const char *obj_pointer, const char *const *allowed,
                         prsm_problems *problems);

/* The allowed name (NULL-terminated list) a misspelt key most likely meant (a small edit
 * distance, or the name without its unit suffix), or NULL. */
const char *prsm_json_closest_name(const char *key, const char *const *allowed);

/* Report duplicate keys only (see prsm_json_check_keys()). */
int prsm_json_check_duplicates(const cJSON *obj, const char *obj_pointer, prsm_problems *problems);

/* Value checkers: item is the value itself, pointer its pointer. Return 0 (out written) or
 * PRSM_EINVAL (problem added). */
int prsm_json_number_value(double *out, const cJSON *item, const char *pointer,
                           prsm_json_range range, prsm_problems *problems);
int prsm_json_int_value(int *out, const cJSON *item, const char *pointer, int min, int max,
                        prsm_problems *problems);
/* max_chars counts Unicode characters, as JSON Schema's maxLength does. out points into item. */
int prsm_json_string_value(const char **out, const cJSON *item, const char *pointer,
                           size_t max_chars, prsm_problems *problems);
/* names: NULL-terminated; out is the index of the match. */
int prsm_json_enum_value(int *out, const cJSON *item, const char *pointer,
                         const char *const *names, prsm_problems *problems);
int prsm_json_object_value(const cJSON *item, const char *pointer, prsm_problems *problems);

/* Field readers: the value checkers applied to obj[key] (see the conventions at the top). */
int prsm_json_get_number(double *out, const cJSON *obj, const char *obj_pointer, const char *key,
                         int required, prsm_json_range range, prsm_problems *problems);
int prsm_json_get_int(int *out, const cJSON *obj, const char *obj_pointer, const char *key,
                      int required, int min, int max, prsm_problems *problems);
int prsm_json_get_string(const char **out, const cJSON *obj, const char *obj_pointer,
                         const char *key, int required, size_t max_chars, prsm_problems *problems);
int prsm_json_get_enum(int *out, const cJSON *obj, const char *obj_pointer, const char *key,
                       int required, const char *const *names, prsm_problems *problems);
int prsm_json_get_bool(int *out, const cJSON *obj, const char *obj_pointer, const char *key,
                       int required, prsm_problems *problems);
/* An object member: *out is the member (NULL when absent or invalid). Its keys are not checked:
 * call prsm_json_check_keys() on it. */
int prsm_json_get_object(const cJSON **out, const cJSON *obj, const char *obj_pointer,
                         const char *key, int required, prsm_problems *problems);
/* A section of a document: prsm_json_get_object(), and when the member is present its pointer
 * is written to ptr (cap bytes) and its keys are checked against allowed (NULL-terminated). */
int prsm_json_get_section(const cJSON **out, char *ptr, size_t cap, const cJSON *obj,
                          const char *obj_pointer, const char *key, int required,
                          const char *const *allowed, prsm_problems *problems);

/* Add name: v to o, or name: null when v is not finite (NaN marks "not defined" in results). */
void prsm_json_add_number(cJSON *o, const char *name, double v);

/* Copy every problem of src to dst with prefix put before its pointer (prefix "" or NULL copies
 * them as they are). For nesting a document whose checks know only their own pointers. */
void prsm_json_problems_append_prefixed(prsm_problems *dst, const prsm_problems *src,
                                        const char *prefix);

#endif
