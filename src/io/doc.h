/*
 * doc.h: the table-driven document reader. The tables are generated from the annotated JSON
 * Schemas (the .schema.json files of schemas/, "x-prsm") by scripts/gen-io-tables.py at build time, so a field's
 * name, type, limits, unit scale and C member are stated once, in the schema.
 *
 * prsm_io_read checks an object against its table: unknown and repeated keys (with a
 * did-you-mean; members that exist only while an int of the document holds), every field's type
 * and limits (the messages of json_util.h's value checkers), required members (with their own
 * message where the schema gives one), either/or conflicts, arrays (item by item into a C array
 * or a scratch struct) and maps (objects of named items); it stores each valid value, scaled,
 * at its member and calls the hand-written hooks and steps for what a table cannot say
 * (cross-field rules, conversions that need other fields), each at its place in the order.
 * Every problem is collected with its JSON pointer; a member whose value is invalid keeps what
 * it held.
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
	PRSM_IO_LONG,       /* long within [min, max] (an int's range) */
	PRSM_IO_BOOL,       /* int 0 / 1 */
	PRSM_IO_ENUM,       /* int: values[i] for names[i] */
	PRSM_IO_STRING,     /* checked (max_chars); copied into a char array of capacity (0: not) */
	PRSM_IO_OBJECT,     /* a section: child table at offset (0: the same struct) */
	PRSM_IO_HOOK,       /* read by hook(base, obj, obj_pointer, problems) */
	PRSM_IO_COVERED,    /* read by another field's hook, or a step */
	PRSM_IO_ARRAY,      /* items one by one: objects by the child table, strings checked */
	PRSM_IO_MAP,        /* an object of named items: key picks each one's struct, child reads it */
	PRSM_IO_STEP        /* no member: step runs at its place in the table */
} prsm_io_kind;

/* A hook: base is the struct the table fills, obj the object holding the field (for a
 * section's "after" hook: the section itself), obj_pointer its pointer. */
typedef void (*prsm_io_hook)(void *base, const cJSON *obj, const char *obj_pointer, prsm_problems *problems);

struct prsm_io_table;

/* Where a step stands. */
typedef struct {
	void *root;                        /* the struct prsm_io_read fills: the document's */
	void *ctx;                         /* the caller's (prsm_io_read_ctx) */
	void *base;                        /* the struct obj fills (an array's string items: the array's) */
	const struct prsm_io_table *table; /* obj's table (NULL for string items and an array's after) */
	const cJSON *obj;                  /* the object read (an item; for an array's after: the array, or
	                                      NULL when it is absent) */
	const char *pointer;               /* its pointer */
	int index;                         /* an array's item: its index, else -1 */
	int start;                         /* prsm_problems_total when obj's reading began */
	unsigned long long read;           /* bit i: field i of table was there and valid */
} prsm_io_at;

/* A step (hand-written, prsm_io_step_<name>): returns 0 to read on; nonzero stops reading the
 * object (and an array's item is then not kept). */
typedef int (*prsm_io_step)(prsm_io_at *at, prsm_problems *problems);
/* A map's key (prsm_io_key_<name>): the struct the member named key fills (at: the map's
 * holder, obj the member), or NULL after adding a problem. */
typedef void *(*prsm_io_key)(const prsm_io_at *at, const char *key, prsm_problems *problems);

/* Largest item an array reads into a scratch struct (its items not stored). */
#define PRSM_IO_SCRATCH_MAX 256

typedef struct {
	unsigned short name;           /* the JSON member (steps: none) */
	prsm_io_kind kind;
	size_t offset;                 /* of the C member in the table's struct */
	int required;
	double scale;                  /* numbers: stored = value x scale (0 means 1) */
	double divide;                 /* numbers: stored = value / divide instead (0: not) */
	double min, max;               /* numbers and integers */
	int min_exclusive, max_exclusive;
	size_t max_chars;              /* strings (and string items): Unicode characters, 0: no limit */
	size_t capacity;               /* strings: the char array's size, 0: not stored */
	unsigned short names;          /* enums: NULL-terminated */
	unsigned short values;
	unsigned short child;          /* objects; arrays and maps: the items' table */
	unsigned short hook;           /* hooks; objects: run after the section's fields */
	unsigned short init;           /* objects: sets the section's defaults at its turn, present or not */
	int has_set;                   /* 1: the int member at set_offset is set to set_value when the */
	size_t set_offset;             /*   field is present and valid; objects: before the section */
	int set_value;                 /*   is read */
	unsigned short conflict_with;  /* a member that must not be present with this one */
	unsigned short conflict_message;
	unsigned short missing;        /* required: the problem when it is absent (not the generic one) */
	unsigned short only_key;       /* the member belongs with one value of the sibling enum only_key */
	size_t only_offset;            /*   (an int at only_offset, only_value): present while it holds */
	int only_value;                /*   another, a problem (only_code, only_message); only_required: */
	unsigned short only_code;      /*   its problem when absent while it holds that one. Checked once */
	unsigned short only_message;   /*   the object is read, the required first, unless only_key has a */
	unsigned short only_required;  /*   problem */
	int deferred;                  /* read only when a step asks (prsm_io_get) */
	int when;                      /* a member (a key, and read) only when the table's condition holds */
	unsigned short step;           /* steps; arrays and maps: run on each item once read */
	/* arrays: missing (required) or not an array of min_items to max_items: one problem, code
	 * ("required" when missing) and message; stored: item i at offset + i x item_size (compact:
	 * the kept ones without gaps); else object items are read into a scratch struct of
	 * item_size. Their count at count_offset (an int or a size_t; count_size 0: none). items:
	 * PRSM_IO_STRING (max_chars) or PRSM_IO_NUMBER (min, max) when they are not objects */
	int min_items, max_items;
	prsm_io_kind items;
	unsigned short code, message;
	int stored, compact;
	size_t item_size, count_offset, count_size;
	unsigned short after;          /* arrays: a step run once the array is read, present or not */
	unsigned short key;            /* maps */
	unsigned short direction;      /* numbers: a magnitude whose direction is this sibling (a
	                                  negative value: a problem naming it) */
} prsm_io_field;

/* A field names its strings, enum arrays, child table, hooks, steps and keys by index into
 * these arrays of the generated tables (entry 0: none, NULL), so that the field tables hold no
 * address and need no relocation when the program starts (a position-independent executable
 * would otherwise write, and so copy, every page of them: docs/speed.md). */
extern const char *const prsm_io_gen_strings[];
extern const char *const *const prsm_io_gen_names[];
extern const int *const prsm_io_gen_values[];
extern const struct prsm_io_table *const prsm_io_gen_tables[];
extern const prsm_io_hook prsm_io_gen_hooks[];
extern void (*const prsm_io_gen_inits[])(void *);
extern const prsm_io_step prsm_io_gen_steps[];
extern const prsm_io_key prsm_io_gen_keys[];

typedef struct prsm_io_table {
	const char *struct_name;
	const prsm_io_field *fields;
	size_t n_fields;
	const char *const *keys;       /* the allowed members, NULL-terminated */
	/* fields with `when`: members only when the int at when_offset of the document's struct is
	 * nonzero (when_not: zero); otherwise keys_else are the allowed members */
	const char *const *keys_else;
	size_t when_offset;
	int when_not;
} prsm_io_table;

/* A rule of a table's "rules" (its x-prsm; io/doc.c, prsm_io_check_rules): member (with keep:
 * each of its members but those; with sub: its member sub's string value unless one of
 * sub_values) belongs with the values `allowed` of the sibling enum `with` (its JSON value, absent:
 * with_default; not one of with_names: no rule), while `present` is there and `absent` is not
 * (0: no condition); else a problem (code, message; "{value}": the sibling's value) at it. */
typedef struct {
	unsigned short member, sub, with, with_default, with_names, allowed; /* strings, names */
	unsigned short present, absent, keep, sub_values, code, message;
} prsm_io_rule;

typedef struct {
	const prsm_io_rule *rules;
	size_t n;
} prsm_io_rules;

/* Read object obj (pointer obj_pointer) into base by table t: keys, then each field in the
 * schema's order. obj must be an object (the caller checks the document's root). Returns 0, or
 * PRSM_EINVAL when a problem was added. */
int prsm_io_read(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer,
                 prsm_problems *problems);

/* prsm_io_read with ctx for the steps (prsm_io_at.ctx). */
int prsm_io_read_ctx(void *base, const prsm_io_table *t, const cJSON *obj, const char *obj_pointer, void *ctx,
                     prsm_problems *problems);

/* 1 when a problem was added, since the first `from` problems, at obj_pointer/key (key NULL: at
 * obj_pointer): the member was there and invalid (for hooks whose rules need their fields valid). */
int prsm_io_problem_at(const prsm_problems *problems, int from, const char *obj_pointer, const char *key);

/* Read only member key of table t from obj (e.g. one section of a document read elsewhere). */
int prsm_io_read_member(void *base, const prsm_io_table *t, const char *key, const cJSON *obj,
                        const char *obj_pointer, prsm_problems *problems);

/* For a step: field key of at's table ("by" the step, or any) read from at->obj into at->base.
 * Returns PRSM_JSON_PRESENT (1, stored), PRSM_JSON_ABSENT (0) or PRSM_EINVAL (a problem added). */
int prsm_io_get(const prsm_io_at *at, const char *key, prsm_problems *problems);

/* For a step: 1 when field key of at's table was there and valid. */
int prsm_io_was_read(const prsm_io_at *at, const char *key);

/* Check obj (pointer obj_pointer, NULL: absent) against the rules of its table, once it and the
 * members they name are read (the caller places the pass in its problem list's order): each rule
 * in turn, its problems in the document's order of the members; none at a pointer that has one
 * since the first `from` problems. */
void prsm_io_check_rules(const prsm_io_rules *rules, const cJSON *obj, const char *obj_pointer, int from,
                         prsm_problems *problems);

/* prsm_io_problem unless a problem since the first `from` is at pointer/key already. */
void prsm_io_problem_once(prsm_problems *problems, int from, const char *pointer, const char *key, const char *code,
                          const char *fmt, ...) __attribute__((format(printf, 6, 7)));

/* A problem at pointer/key (key NULL: at pointer). */
void prsm_io_problem(prsm_problems *problems, const char *pointer, const char *key, const char *code,
                     const char *fmt, ...) __attribute__((format(printf, 5, 6)));

#endif
