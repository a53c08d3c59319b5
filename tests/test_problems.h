/*
 * test_problems.h: helpers of the document tests: parse a JSON text that must parse, find a
 * problem by pointer and code, print the problems of a failing check.
 */
#ifndef PRSM_TEST_PROBLEMS_H
#define PRSM_TEST_PROBLEMS_H

#include <stdio.h>
#include <string.h>

#include <cJSON.h>

#include "io/json_util.h"
#include "util/problems.h"

static cJSON *parse_ok(const char *text)
{
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = prsm_json_parse(text, strlen(text), &p);
	if (doc == NULL)
		fail_msg("parse failed: %s", p.count ? p.items[0].message : "?");
	assert_int_equal(p.count, 0);
	return doc;
}

/* Index of the problem at pointer with code, or -1. */
static int find(const prsm_problems *p, const char *pointer, const char *code)
{
	for (int i = 0; i < p->count; i++)
		if (strcmp(p->items[i].pointer, pointer) == 0 && strcmp(p->items[i].code, code) == 0)
			return i;
	return -1;
}

static void dump(const prsm_problems *p)
{
	for (int i = 0; i < p->count; i++)
		fprintf(stderr, "  [%s] %s: %s\n", p->items[i].code, p->items[i].pointer, p->items[i].message);
}

#endif
