/*
 * doc.h: the table-driven document reader. The tables are generated from the annotated JSON
 * Schemas (the .schema.json files of schemas/, "x-prsm") by scripts/gen-io-tables.py at build time, so a field's
 * name, type, limits, unit scale and C member are stated once, in the schema.
 *
 * prsm_io_read checks an object against its table: unknown and repeated keys (with a
 * did-you-mean), every field's type and limits (the messages of json_util.h's value checkers),
 * required members, either/or conflicts; it stores each valid value, scaled, at its member and
 * calls the hand-written hooks for what a table cannot say (cross-field rules, conversions that
 * need other fields). Every problem is collected with its JSON pointer; a member whose value is
 * invalid keeps what it held.
 */
#ifndef PRSM_IO_DOC_H
#define PRSM_IO_DOC_H

#include <stddef.h>

#include <cJSON.h>

#include "util/problems.h"

typedef enum {
	PRSM_IO_NUMBER = 1, /* double, scaled */
	PRSM_IO_INT,        /* int within [min, max] */
	PRSM_IO_SIZE,       /* size_t within [min, max] (min >= 0) */
	PRSM_IO_BOOL,       /* int 0 / 1 */
	PRSM_IO_ENUM,       /* int: values[i] for names[i] */
	PRSM_IO_STRING,     /* checked (max_chars) and, with skip, not stored */
	PRSM_IO_OBJECT,     /* a section: child table at offset (0: the same struct) */
	PRSM_IO_HOOK,       /* read by hook(base, obj, obj_pointer, problems) */
	PRSM_IO_COVERED     /* read by another field's hook */
} prsm_io_kind;

/* A hook: base is the struct the table fills, obj the object holding the field (for a
 * section's "after" hook: the section itself), obj_pointer its pointer. */
typedef void (*prsm_io_hook)(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems);

struct prsm_io_table;

typedef struct {
	const char *name;              /* the JSON member */
	prsm_io_kind kind;
	size_t offset;                 /* of the C member in the table's struct */
	int required;
	double scale;                  /* numbers: stored = value x scale (0 means 1) */
	double divide;                 /* numbers: stored = value / divide instead (0: not) */
	double min, max;               /* numbers and integers */
	int min_exclusive, max_exclusive;
	size_t max_chars;              /* strings: Unicode characters, 0: no limit */
	int skip;                      /* strings: checked, not stored */
	const char *const *names;      /* enums: NULL-terminated */
	const int *values;
	const struct prsm_io_table *child; /* objects */
	prsm_io_hook hook;             /* hooks; objects: run after the section's fields */
	int has_set;                   /* 1: the int member at set_offset is set to set_value when the */
	size_t set_offset;             /*   field is present and valid; objects: before the section */
	int set_value;                 /*   is read */
	const char *conflict_with;     /* a member that must not be present with this one */
	const char *conflict_message;
} prsm_io_field;

typedef struct prsm_io_table {
	const char *struct_name;
	const prsm_io_field *fields;
	size_t n_fields;
	const char *const *keys;       /* the allowed members, NULL-terminated */
} prsm_io_table;

/* Read object obj (pointer obj_pointer) into base by table t: keys, then each field in the
 * schema's order. obj must be an object (the caller checks the document's root). Returns 0, or
 * PRSM_EINVAL when a problem was added. */
int prsm_io_read(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer,
                 prsm_problems *problems);

/* 1 when a problem was added, since the first `from` problems, at obj_pointer/key: the member
 * was there and invalid (for hooks whose rules need their fields valid). */
int prsm_io_problem_at(const prsm_problems *problems, int from, const char *obj_pointer, const char *key);

/* Read only member key of table t from obj (e.g. one section of a document read elsewhere). */
int prsm_io_read_member(void *base, const prsm_io_table *t, const char *key, const cJSON *obj,
                        const char *obj_pointer, prsm_problems *problems);

#endif
