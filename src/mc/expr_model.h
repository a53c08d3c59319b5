/*
 * expr_model.h: a model given as expressions (issue 21, docs/studies.md "Expression models"):
 * each output an arithmetic expression of named inputs and constants, such as a dimension chain
 * "A - B - C - D" or a preload "k * max(0, -gap)", run by the Monte Carlo engine like the
 * built-in models. Pure C, no JSON: the study reader (io/study_json.c) fills the struct.
 *
 * The expressions are parsed and evaluated by muParser (Ingo Berg; Debian's libmuparser2v5), a
 * bytecode compiler for such formulas, through its C interface (muParserDLL.h). muParser is a C++
 * library that brings libstdc++ and libgomp; linked, it would cost every process's start-up
 * about 3 ms and 80 page faults, so it is loaded with dlopen() the first time an expression is
 * checked or a workspace made (the library's SONAME, PRSM_MUPARSER_SONAME, from the build).
 *
 * The syntax is muParser's: numbers (1.5, 2e-3), the inputs and constants by name, + - * / ^
 * (power, right-associative), unary -, comparisons (< <= > >= == !=), && ||, the conditional
 * c ? a : b, parentheses, the constants _pi and _e and the functions sin cos tan asin acos atan
 * atan2 sinh cosh tanh asinh acosh atanh exp log (natural) ln log2 log10 sqrt abs sign rint min
 * max sum avg, with pow, hypot, fmod, floor, ceil and cbrt added here. Refused: an assignment
 * (=, +=, ...), a comma outside a function's arguments (several results), strings, characters
 * beyond ASCII.
 *
 * A handle of muParser is not safe to share between threads, so each worker's workspace holds
 * its own parsers (one per output), each compiled once, with the inputs bound to the
 * workspace's own array: a sample copies its inputs there and evaluates each output's bytecode,
 * without allocating. An output that is not finite (a division by zero, the square root of a
 * negative number) fails the sample with PRSM_EINVAL, and the engine's failure policy applies.
 */
#ifndef PRSM_MC_EXPR_MODEL_H
#define PRSM_MC_EXPR_MODEL_H

#include <stddef.h>

#include "mc/engine.h"
#include "util/error.h"

#define PRSM_EXPR_MAX_INPUTS 64        /* = a study's tolerances */
#define PRSM_EXPR_MAX_OUTPUTS 16       /* = PRSM_MC_MAX_OUTPUTS */
#define PRSM_EXPR_MAX_CONSTANTS 64
#define PRSM_EXPR_NAME_MAX 48          /* a name: 1 to 47 characters */
#define PRSM_EXPR_TEXT_MAX 2001        /* an expression: 1 to 2000 characters (ASCII) */

typedef struct {
	size_t n_inputs;                                            /* 1 .. PRSM_EXPR_MAX_INPUTS */
	char inputs[PRSM_EXPR_MAX_INPUTS][PRSM_EXPR_NAME_MAX];      /* input i is x[i] of a sample */
	size_t n_constants;
	char constant_names[PRSM_EXPR_MAX_CONSTANTS][PRSM_EXPR_NAME_MAX];
	double constant_values[PRSM_EXPR_MAX_CONSTANTS];
	size_t n_exprs;                                             /* 1 .. PRSM_EXPR_MAX_OUTPUTS */
	char expr_names[PRSM_EXPR_MAX_OUTPUTS][PRSM_EXPR_NAME_MAX];
	char exprs[PRSM_EXPR_MAX_OUTPUTS][PRSM_EXPR_TEXT_MAX];
	size_t n_outputs;                                           /* the outputs a sample evaluates: */
	size_t output_expr[PRSM_EXPR_MAX_OUTPUTS];                  /* output o is exprs[output_expr[o]] */
} prsm_expr_model;

/* What is wrong with one expression, and where. */
typedef struct {
	int position;       /* 1-based character of the expression the problem is at; 0: none (empty),
	                       length + 1: at its end */
	const char *code;   /* "syntax", "unknown_name" (not an input, constant or function),
	                       "not_allowed" (an assignment, several results, a string, beyond ASCII),
	                       "empty", "unavailable" (muParser cannot be loaded) */
	char message[240];  /* "unexpected operator \"*\"", ... (without the position) */
} prsm_expr_diag;

/* Load muParser (once; thread-safe). Returns 0, or PRSM_EIO with err naming the library and
 * dlerror()'s reason. */
int prsm_expr_load(prsm_error *err);

/* muParser's version ("2.3.3 (Release) ..."), or NULL when it cannot be loaded. */
const char *prsm_expr_library_version(void);

/* A valid name for an input, a constant or an output: a letter or _ then letters, digits or _,
 * at most PRSM_EXPR_NAME_MAX - 1 characters, not a function or constant of the syntax (sin,
 * _pi, ...). Returns 0, or PRSM_EINVAL with a message in msg (cap bytes). */
int prsm_expr_name_check(const char *name, char *msg, size_t cap);

/* Parse expression e of m with m's inputs and constants defined: 0, or PRSM_EINVAL with the
 * position and message in diag (a syntax error, an unknown name, an assignment, several
 * results), or PRSM_EIO (muParser cannot be loaded; diag says so, position 0). used (may be
 * NULL; m->n_inputs entries) gets 1 for each input the expression reads, else 0. Reentrant:
 * the reading of muParser's error details, which uses a static buffer, is serialised. */
int prsm_expr_check(const prsm_expr_model *m, size_t e, unsigned char *used, prsm_expr_diag *diag);

/* The engine's view of m (m must outlive it): m->n_outputs outputs, inputs x[0 .. n_inputs-1],
 * a workspace per worker (its parsers; PRSM_EIO when muParser cannot be loaded, PRSM_EINVAL
 * when an expression does not parse: check them first), eval failing a sample whose output is
 * not finite with PRSM_EINVAL. */
void prsm_expr_mc_model(prsm_mc_model *out, const prsm_expr_model *m);

#endif
