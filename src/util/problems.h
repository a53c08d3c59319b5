/*
 * problems.h: a bounded list of (JSON pointer, message) pairs.
 *
 * Validation reports every problem of a request at once (DESIGN.md, "Errors"), and the model's
 * rule checks report warnings the same way. The list has a fixed capacity; entries past it are
 * counted in `dropped` so the caller can say "and N more".
 */
#ifndef PRSM_UTIL_PROBLEMS_H
#define PRSM_UTIL_PROBLEMS_H

#define PRSM_PROBLEMS_MAX 64
#define PRSM_PROBLEM_POINTER_MAX 128
#define PRSM_PROBLEM_MESSAGE_MAX 240

typedef struct {
	char pointer[PRSM_PROBLEM_POINTER_MAX]; /* RFC 6901 pointer into the request, "" for the whole */
	char code[32];                          /* short machine-readable tag, e.g. "z_max" */
	char message[PRSM_PROBLEM_MESSAGE_MAX]; /* one line a person can act on */
} prsm_problem;

typedef struct {
	int count;
	int dropped;
	prsm_problem items[PRSM_PROBLEMS_MAX];
} prsm_problems;

void prsm_problems_init(prsm_problems *p);
/* Append one problem (printf-style message). code may be NULL. */
void prsm_problems_add(prsm_problems *p, const char *pointer, const char *code, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* Total number of problems, including dropped ones. */
int prsm_problems_total(const prsm_problems *p);

#endif
