/*
 * write.h: building a result document with a sticky error. Every call takes the writer and
 * the parent it adds to; once an allocation has failed (or a parent is NULL because an earlier
 * one failed) the calls do nothing but keep w->failed set, and an item that cannot be attached
 * is freed, so a writer checks once, at the end, and never leaks on out-of-memory.
 *
 * Numbers that are not finite are written as null (JSON has no NaN or infinity).
 *
 * The result documents are written by tables generated from their annotated JSON Schemas
 * (schemas/ *-result and analysis, "x-prsm"; scripts/gen-io-writers.py, docs/hacking.md):
 * prsm_io_write writes the members of a struct a table names, in the schema's order, and calls
 * the hand-written hooks (prsm_io_whook_<name>) for what a table cannot say.
 */
#ifndef PRSM_IO_WRITE_H
#define PRSM_IO_WRITE_H

#include <stddef.h>

#include <cJSON.h>

#include "util/problems.h"

typedef struct {
	int failed;      /* an allocation failed: the document is incomplete */
	void *ctx;       /* the document's writer state, for the hooks */
} prsm_jw;

#define PRSM_JW_INIT {0, NULL}

/* A new document root (an object the caller owns); NULL when out of memory. */
cJSON *prsm_jw_root(prsm_jw *w);

/* A new object or array under parent[key] (key NULL: appended to the array parent). NULL when
 * it could not be made or parent is NULL. */
cJSON *prsm_jw_object(prsm_jw *w, cJSON *parent, const char *key);
cJSON *prsm_jw_array(prsm_jw *w, cJSON *parent, const char *key);

/* parent[key] = value (key NULL: appended to the array parent). */
void prsm_jw_number(prsm_jw *w, cJSON *parent, const char *key, double v); /* null unless finite */
void prsm_jw_string(prsm_jw *w, cJSON *parent, const char *key, const char *s);
void prsm_jw_bool(prsm_jw *w, cJSON *parent, const char *key, int b);
void prsm_jw_null(prsm_jw *w, cJSON *parent, const char *key);
void prsm_jw_pair(prsm_jw *w, cJSON *parent, const char *key, double a, double b); /* [a, b] */

/* Attach item (made elsewhere; NULL counts as a failure) at parent[key]; freed when it cannot
 * be attached. Returns item when attached, else NULL. */
cJSON *prsm_jw_item(prsm_jw *w, cJSON *parent, const char *key, cJSON *item);

/* A finished document: root, or NULL (root freed) when an allocation failed. */
cJSON *prsm_jw_done(prsm_jw *w, cJSON *root);

/* Problems as a new array of {pointer, code, message} (the caller owns it); NULL when out of
 * memory. */
cJSON *prsm_io_problems_to_json(const prsm_problems *p);

/* Hooks every result uses: the engine's build identity; a problem list (at: prsm_problems). */
void prsm_io_whook_engine_build(prsm_jw *w, cJSON *obj, const char *key, const void *at);
void prsm_io_whook_problems(prsm_jw *w, cJSON *obj, const char *key, const void *at);

/* ---- the generated tables ------------------------------------------------------------------ */

/* Where a member is: at base + offset, or (deref) through the pointer there, at offset2 in what
 * it points to; then (pointer) through the pointer found there; item (or row) i stride x i
 * further on, and after further (the member of a pointed-to struct). Left out when a pointer on
 * the way is NULL. */
typedef struct {
	size_t offset, offset2, stride, after;
	unsigned char deref, pointer;
} prsm_io_wref;

typedef enum {
	PRSM_IO_W_NUMBER = 1, /* a number of C type `type`, x scale (/ divide), constants or members */
	PRSM_IO_W_BOOL,       /* an int, true when nonzero (& mask when set); no type: mask itself */
	PRSM_IO_W_ENUM,       /* an int: names[i] where values[i] is it, else text (or null) */
	PRSM_IO_W_FLAGS,      /* an int: an array of names[i] whose bit values[i] is set */
	PRSM_IO_W_STRING,     /* a char array (type CHARS) or a const char * (type CSTR) */
	PRSM_IO_W_TEXT,       /* text, as it is (the schema's const) */
	PRSM_IO_W_OBJECT,     /* the child table's members of the struct here */
	PRSM_IO_W_ARRAY,      /* count items (shape): of C type `type` (ints with names: their
	                         names, as ENUM; with a mask: booleans, as BOOL; with is_set:
	                         booleans, true when the int is is_value), structs (child), rows
	                         (the child's members at row i), a tuple (the child's members), a
	                         matrix or a grid */
	PRSM_IO_W_HOOK,       /* hook(w, obj, name, the member here, or the table's struct) */
	PRSM_IO_W_INDEX       /* the row's number + count (an item's index in a rows table) */
} prsm_io_wkind;

typedef enum {
	PRSM_IO_W_DOUBLE = 1,
	PRSM_IO_W_INT,
	PRSM_IO_W_SIZE,
	PRSM_IO_W_U64,
	PRSM_IO_W_ULONG,
	PRSM_IO_W_LONG,
	PRSM_IO_W_CHARS,
	PRSM_IO_W_CSTR
} prsm_io_wtype;

typedef enum {
	PRSM_IO_W_ALWAYS = 0,
	PRSM_IO_W_IF,      /* when the member at `when` is nonzero (a double: not NaN) */
	PRSM_IO_W_IF_NOT,  /* when it is zero */
	PRSM_IO_W_IF_IS,   /* when the int there is when_value */
	PRSM_IO_W_IF_ISNT, /* when it is not */
	PRSM_IO_W_IF_ROW   /* from row when_value on */
} prsm_io_wwhen;

/* An array's items. ITEMS: element i of `at` (with a step: element row + i x step, every
 * step-th from the row's own, as a chain's stages interleave in one array, K per time); MATRIX:
 * count arrays of step numbers, item i element i x step + j of `at` (a row-major C array);
 * SLICE: the row's count numbers of a row-major C array, element row x count + i; GRID: count
 * numbers evenly spaced from the double at `at` to the double at step_at. */
typedef enum {
	PRSM_IO_W_ITEMS = 0,
	PRSM_IO_W_STRUCTS,
	PRSM_IO_W_ROWS,
	PRSM_IO_W_TUPLE,
	PRSM_IO_W_MATRIX,
	PRSM_IO_W_SLICE,
	PRSM_IO_W_GRID
} prsm_io_wshape;

struct prsm_io_wtable;

/* A hook: writes obj[key] (or nothing); at is the member the annotation names, or the struct
 * the table writes. w->ctx is the document's writer state. */
typedef void (*prsm_io_whook)(prsm_jw *w, cJSON *obj, const char *key, const void *at);

typedef struct {
	const char *name;                  /* NULL: an item of the array the table fills */
	unsigned char kind, type;          /* prsm_io_wkind, prsm_io_wtype (items, for arrays) */
	prsm_io_wref at;
	double scale, divide;              /* numbers: x scale (0: 1), then / divide (0: not) */
	unsigned char scale_by, divide_by; /* ... or x (/) the double at scale_at (divide_at) */
	prsm_io_wref scale_at, divide_at;
	const char *text;                  /* TEXT */
	const char *const *names;          /* ENUM, FLAGS */
	const int *values;
	int n_values, mask;
	unsigned char is_set;              /* boolean items: true when the int is is_value (not & mask) */
	int is_value;
	const struct prsm_io_wtable *child; /* OBJECT, ARRAY */
	unsigned char shape;               /* ARRAY: prsm_io_wshape */
	int count;                         /* ARRAY: count items, or (count_type) the count at count_at;
	                                      INDEX: added to the row's number */
	unsigned char count_type;
	prsm_io_wref count_at;
	int step;                          /* ARRAY: the step of ITEMS, a MATRIX's columns, or */
	unsigned char step_type;           /* (step_type) the count at step_at; GRID: step_at is */
	prsm_io_wref step_at;              /* the double the grid ends at */
	prsm_io_whook hook;
	unsigned char when, when_type, else_null; /* prsm_io_wwhen; else_null: null, not left out */
	int when_value;
	prsm_io_wref when_at;
	/* The generated tables give name, text, names, values, child and hook as indices into the
	 * prsm_io_wgen_* arrays below (0: none) and leave the pointers NULL: a table without
	 * addresses needs no relocation when the program starts (a position-independent executable
	 * would otherwise write, and so copy, every page of them: docs/speed.md). Hand-made tables
	 * (tests) set the pointers. */
	unsigned short name_i, text_i, names_i, values_i, child_i, hook_i;
} prsm_io_wfield;

typedef struct prsm_io_wtable {
	const prsm_io_wfield *fields;
	size_t n_fields;
} prsm_io_wtable;

/* What the generated tables' indices name (prsm_io_writers.c; entry 0 is NULL). */
extern const char *const prsm_io_wgen_strings[];
extern const char *const *const prsm_io_wgen_names[];
extern const int *const prsm_io_wgen_values[];
extern const prsm_io_wtable *const prsm_io_wgen_tables[];
extern const prsm_io_whook prsm_io_wgen_hooks[];

/* Write the struct at base as parent[key] (key NULL: appended to the array parent) by table t;
 * returns the object, or NULL when it could not be made. */
cJSON *prsm_io_write(prsm_jw *w, cJSON *parent, const char *key, const void *base, const prsm_io_wtable *t);

/* Write the members of table t into the object (or, for a tuple, array) obj; row: the row of
 * a rows table (else 0). */
void prsm_io_write_fields(prsm_jw *w, cJSON *obj, const void *base, const prsm_io_wtable *t, size_t row);

#endif
