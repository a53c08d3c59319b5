/*
 * problems.c: the bounded problem list used by validation and rule checks.
 */
#include "util/problems.h"
#include "util/utf8.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void prsm_problems_init(prsm_problems *p)
{
	p->count = 0;
	p->dropped = 0;
}

void prsm_problems_add(prsm_problems *p, const char *pointer, const char *code, const char *fmt, ...)
{
	if (p->count >= PRSM_PROBLEMS_MAX) {
		p->dropped++;
		return;
	}
	prsm_problem *it = &p->items[p->count++];
	prsm_utf8_copy(it->pointer, sizeof it->pointer, pointer ? pointer : "");
	prsm_utf8_copy(it->code, sizeof it->code, code ? code : "");
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(it->message, sizeof it->message, fmt, ap);
	va_end(ap);
	if (n < 0 || (size_t)n >= sizeof it->message)
		prsm_utf8_trim_partial(it->message); /* a quoted request string cut mid-character */
}

int prsm_problems_total(const prsm_problems *p)
{
	return p->count + p->dropped;
}
