/*
 * expr_model.c: expression models on muParser, loaded on demand (see expr_model.h).
 *
 * muParser's C interface has two traps this file steps around: mupError() reports and clears
 * the error flag (so it is read once, right after the call that may fail), and mupEvalMulti() on
 * a handle whose expression did not parse dereferences freed bytecode (so it is called only after
 * a successful evaluation). Its error text (mupGetErrorMsg) is only the offending token in 2.3.3,
 * and its string results live in a static buffer: the messages are written here from the error
 * code, the position and the token, read under a lock.
 */
#include "mc/expr_model.h"

#include <ctype.h>
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <muParserDLL.h>

#ifndef PRSM_MUPARSER_SONAME
#define PRSM_MUPARSER_SONAME "libmuparser.so.2"
#endif

/* ---- the library ----------------------------------------------------------------------------- */

/* The functions used, with muParser's own prototypes. */
static struct {
	__typeof__(mupCreate) *create;
	__typeof__(mupRelease) *release;
	__typeof__(mupGetVersion) *get_version;
	__typeof__(mupSetExpr) *set_expr;
	__typeof__(mupEval) *eval;
	__typeof__(mupEvalMulti) *eval_multi;
	__typeof__(mupDefineVar) *define_var;
	__typeof__(mupDefineConst) *define_const;
	__typeof__(mupDefineFun1) *define_fun1;
	__typeof__(mupDefineFun2) *define_fun2;
	__typeof__(mupError) *error;
	__typeof__(mupGetErrorCode) *get_error_code;
	__typeof__(mupGetErrorPos) *get_error_pos;
	__typeof__(mupGetErrorToken) *get_error_token;
	__typeof__(mupGetExprVarNum) *get_expr_var_num;
	__typeof__(mupGetExprVar) *get_expr_var;
} mup;

static pthread_once_t load_once_flag = PTHREAD_ONCE_INIT;
static int load_rc;
static char load_message[300];
static char version[96];
/* muParser's string results (error token, version) share one static buffer */
static pthread_mutex_t strings_lock = PTHREAD_MUTEX_INITIALIZER;

/* A function of the library into a member of the table (POSIX: dlsym's result may be used as a
 * function pointer; copy its bytes). */
static int resolve(void *lib, void *member, size_t size, const char *name)
{
	void *f = dlsym(lib, name);
	if (f == NULL)
		return -1;
	memcpy(member, &f, size);
	return 0;
}

#define RESOLVE(m, name)                                              \
	do {                                                              \
		if (!missing && resolve(lib, &mup.m, sizeof mup.m, name))     \
			missing = name;                                           \
	} while (0)

static void load_once(void)
{
	void *lib = dlopen(PRSM_MUPARSER_SONAME, RTLD_NOW | RTLD_LOCAL);
	if (lib == NULL) {
		const char *why = dlerror();
		load_rc = PRSM_EIO;
		snprintf(load_message, sizeof load_message, "expression models need muParser: cannot load %s (%s); "
		         "install libmuparser2v5", PRSM_MUPARSER_SONAME, why ? why : "unknown reason");
		return;
	}
	/* the library stays loaded for the life of the process */
	const char *missing = NULL;
	RESOLVE(create, "mupCreate");
	RESOLVE(release, "mupRelease");
	RESOLVE(get_version, "mupGetVersion");
	RESOLVE(set_expr, "mupSetExpr");
	RESOLVE(eval, "mupEval");
	RESOLVE(eval_multi, "mupEvalMulti");
	RESOLVE(define_var, "mupDefineVar");
	RESOLVE(define_const, "mupDefineConst");
	RESOLVE(define_fun1, "mupDefineFun1");
	RESOLVE(define_fun2, "mupDefineFun2");
	RESOLVE(error, "mupError");
	RESOLVE(get_error_code, "mupGetErrorCode");
	RESOLVE(get_error_pos, "mupGetErrorPos");
	RESOLVE(get_error_token, "mupGetErrorToken");
	RESOLVE(get_expr_var_num, "mupGetExprVarNum");
	RESOLVE(get_expr_var, "mupGetExprVar");
	if (missing) {
		load_rc = PRSM_EIO;
		snprintf(load_message, sizeof load_message, "%s has no %s (muParser too old?)", PRSM_MUPARSER_SONAME,
		         missing);
		memset(&mup, 0, sizeof mup);
		return;
	}
	muParserHandle_t h = mup.create(muBASETYPE_FLOAT);
	snprintf(version, sizeof version, "%s", mup.get_version(h));
	mup.release(h);
}

int prsm_expr_load(prsm_error *err)
{
	pthread_once(&load_once_flag, load_once);
	if (load_rc)
		return prsm_error_set(err, load_rc, NULL, "%s", load_message);
	return 0;
}

const char *prsm_expr_library_version(void)
{
	return prsm_expr_load(NULL) ? NULL : version;
}

/* ---- names ----------------------------------------------------------------------------------- */

/* The functions added to muParser's own (sin, ..., max, sum, avg: its Parser class). */
static double fn_pow(double a, double b)
{
	return pow(a, b);
}

static double fn_hypot(double a, double b)
{
	return hypot(a, b);
}

static double fn_fmod(double a, double b)
{
	return fmod(a, b);
}

static double fn_floor(double a)
{
	return floor(a);
}

static double fn_ceil(double a)
{
	return ceil(a);
}

static double fn_cbrt(double a)
{
	return cbrt(a);
}

/* The names of the syntax: muParser's functions and constants, then the ones added here. */
static const char *const reserved[] = {
	"sin",  "cos",  "tan",  "asin", "acos",  "atan",  "atan2", "sinh", "cosh", "tanh", "asinh", "acosh",
	"atanh", "log2", "log10", "log", "ln",   "exp",   "sqrt",  "sign", "rint", "abs",  "min",   "max",
	"sum",  "avg",  "_pi",  "_e",   "pow",   "hypot", "fmod",  "floor", "ceil", "cbrt", NULL,
};

static int is_function(const char *name)
{
	for (int i = 0; reserved[i]; i++)
		if (strcmp(reserved[i], name) == 0)
			return name[0] != '_';
	return 0;
}

int prsm_expr_name_check(const char *name, char *msg, size_t cap)
{
	const size_t n = strlen(name);
	int ok = n > 0 && n < PRSM_EXPR_NAME_MAX && (isalpha((unsigned char)name[0]) || name[0] == '_');
	for (size_t i = 1; ok && i < n; i++)
		ok = isalnum((unsigned char)name[i]) || name[i] == '_';
	for (size_t i = 0; ok && i < n; i++)
		ok = (unsigned char)name[i] < 0x80; /* isalpha of the C locale: ASCII only */
	if (!ok) {
		snprintf(msg, cap, "'%.60s%s' is not a name: a letter or _, then letters, digits or _, at most %d "
		         "characters", name, n > 60 ? "..." : "", PRSM_EXPR_NAME_MAX - 1);
		return PRSM_EINVAL;
	}
	for (int i = 0; reserved[i]; i++)
		if (strcmp(reserved[i], name) == 0) {
			snprintf(msg, cap, "'%s' is a %s of the expressions' syntax: choose another name", name,
			         name[0] == '_' ? "constant" : "function");
			return PRSM_EINVAL;
		}
	return 0;
}

/* ---- parsers --------------------------------------------------------------------------------- */

/* A parser of expression e of m with the inputs bound to x[] (n_inputs doubles). NULL when
 * muParser cannot make one. */
static muParserHandle_t parser_new(const prsm_expr_model *m, size_t e, double *x)
{
	muParserHandle_t h = mup.create(muBASETYPE_FLOAT);
	if (h == NULL)
		return NULL;
	mup.define_fun2(h, "pow", fn_pow, 1);
	mup.define_fun2(h, "hypot", fn_hypot, 1);
	mup.define_fun2(h, "fmod", fn_fmod, 1);
	mup.define_fun1(h, "floor", fn_floor, 1);
	mup.define_fun1(h, "ceil", fn_ceil, 1);
	mup.define_fun1(h, "cbrt", fn_cbrt, 1);
	for (size_t c = 0; c < m->n_constants; c++)
		mup.define_const(h, m->constant_names[c], m->constant_values[c]);
	for (size_t i = 0; i < m->n_inputs; i++)
		mup.define_var(h, m->inputs[i], &x[i]);
	mup.set_expr(h, m->exprs[e]);
	return h;
}

/* ---- checks ---------------------------------------------------------------------------------- */

static int diag_set(prsm_expr_diag *d, int position, const char *code, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));

static int diag_set(prsm_expr_diag *d, int position, const char *code, const char *fmt, ...)
{
	va_list ap;
	d->position = position;
	d->code = code;
	va_start(ap, fmt);
	vsnprintf(d->message, sizeof d->message, fmt, ap);
	va_end(ap);
	return PRSM_EINVAL;
}

/* What the text alone shows: characters beyond printable ASCII (tab and line breaks allowed),
 * strings, an assignment (= not part of ==, <=, >=, !=). */
static int check_text(const char *s, prsm_expr_diag *d)
{
	const size_t n = strlen(s);
	size_t blank = 0;
	for (size_t i = 0; i < n; i++) {
		const unsigned char c = (unsigned char)s[i];
		if (c >= 0x80)
			return diag_set(d, (int)i + 1, "not_allowed", "a character beyond ASCII: names, numbers and operators are ASCII");
		if (c < 0x20 && c != '\t' && c != '\n' && c != '\r')
			return diag_set(d, (int)i + 1, "not_allowed", "a control character (code %u)", c);
		if (c == '"')
			return diag_set(d, (int)i + 1, "not_allowed", "strings are not part of the syntax");
		if (c == '=' && !(i > 0 && strchr("=<>!", s[i - 1])) && s[i + 1] != '=') {
			const int compound = i > 0 && strchr("+-*/^", s[i - 1]) != NULL;
			return diag_set(d, (int)i + 1 - compound, "not_allowed",
			                "an assignment (%.*s=) would change an input: compare with ==",
			                compound, compound ? s + i - 1 : "");
		}
		blank += c == ' ' || c == '\t' || c == '\n' || c == '\r';
	}
	if (n == 0 || blank == n)
		return diag_set(d, 0, "empty", "the expression is empty");
	return 0;
}

/* The name or number at the start of token (muParser's token runs on to the end of the text). */
static void token_head(char *out, size_t cap, const char *token)
{
	size_t n = 0;
	if (isalpha((unsigned char)token[0]) || token[0] == '_')
		while (isalnum((unsigned char)token[n]) || token[n] == '_')
			n++;
	else if (isdigit((unsigned char)token[0]) || token[0] == '.')
		while (isalnum((unsigned char)token[n]) || token[n] == '.' ||
		       ((token[n] == '+' || token[n] == '-') && n > 0 && (token[n - 1] == 'e' || token[n - 1] == 'E')))
			n++;
	else
		n = token[0] ? 1 : 0;
	if (n >= cap)
		n = cap - 1;
	memcpy(out, token, n);
	out[n] = 0;
}

/* The message of muParser's error code (muParserDef.h, EErrorCodes) at token. Returns 1 when
 * it is a name that is not an input, a constant or a function, else 0. */
static int describe(char *msg, size_t cap, int code, const char *token, const prsm_expr_model *m)
{
	char head[64];
	int unknown = 0;
	token_head(head, sizeof head, token);
	switch (code) {
	case 0: /* ecUNEXPECTED_OPERATOR */
		snprintf(msg, cap, "unexpected operator \"%s\"", head);
		break;
	case 1: /* ecUNASSIGNABLE_TOKEN */
		if (isalpha((unsigned char)head[0]) || head[0] == '_') {
			if (is_function(head)) {
				snprintf(msg, cap, "the function %s needs its arguments in parentheses: %s(...)", head, head);
			} else {
				unknown = 1;
				int k = snprintf(msg, cap, "unknown name \"%s\": not an input (", head);
				for (size_t i = 0; i < m->n_inputs && k > 0 && (size_t)k < cap; i++)
					k += snprintf(msg + k, cap - (size_t)k, "%s%s", i ? ", " : "", m->inputs[i]);
				if (k > 0 && (size_t)k < cap)
					snprintf(msg + k, cap - (size_t)k, "), a constant or a function");
			}
		} else if (isdigit((unsigned char)head[0]) || head[0] == '.') {
			snprintf(msg, cap, isinf(strtod(head, NULL)) ? "the number %s overflows a double"
			                                             : "unreadable number \"%s\"", head);
		} else {
			snprintf(msg, cap, "unexpected character \"%s\"", head);
		}
		break;
	case 2: /* ecUNEXPECTED_EOF */
		snprintf(msg, cap, "the expression ends too early");
		break;
	case 3: /* ecUNEXPECTED_ARG_SEP */
		snprintf(msg, cap, "unexpected comma");
		break;
	case 4: /* ecUNEXPECTED_ARG */
		snprintf(msg, cap, "a comma outside a function's arguments");
		break;
	case 5: /* ecUNEXPECTED_VAL */
		snprintf(msg, cap, "unexpected number \"%s\": an operator is missing before it", head);
		break;
	case 6: /* ecUNEXPECTED_VAR */
		snprintf(msg, cap, "unexpected name \"%s\": an operator is missing before it", head);
		break;
	case 7: /* ecUNEXPECTED_PARENS */
		snprintf(msg, cap, "unexpected parenthesis \"%s\"", head);
		break;
	case 8: case 9: case 13: case 17: /* strings */
		snprintf(msg, cap, "strings are not part of the syntax");
		break;
	case 10: /* ecVAL_EXPECTED */
		snprintf(msg, cap, "a value is expected");
		break;
	case 11: /* ecMISSING_PARENS */
		snprintf(msg, cap, "a parenthesis is not closed");
		break;
	case 12: /* ecUNEXPECTED_FUN */
		snprintf(msg, cap, "unexpected function \"%s\": an operator is missing before it", head);
		break;
	case 14: /* ecTOO_MANY_PARAMS */
		snprintf(msg, cap, "too many arguments for %s", head);
		break;
	case 15: /* ecTOO_FEW_PARAMS */
		snprintf(msg, cap, "too few arguments for %s", head);
		break;
	case 32: /* ecUNEXPECTED_CONDITIONAL */
		snprintf(msg, cap, "unexpected \"?\"");
		break;
	case 33: /* ecMISSING_ELSE_CLAUSE */
		snprintf(msg, cap, "a condition c ? a : b misses its \": b\"");
		break;
	case 34: /* ecMISPLACED_COLON */
		snprintf(msg, cap, "\":\" without its \"?\"");
		break;
	case 35: case 36: case 37: /* too many computations, identifier or expression too long */
		snprintf(msg, cap, "too long or too complex for muParser");
		break;
	default:
		snprintf(msg, cap, "syntax error (muParser error %d at \"%s\")", code, head);
		break;
	}
	return unknown;
}

/* The first comma outside parentheses, or -1. */
static int top_level_comma(const char *s)
{
	int depth = 0;
	for (int i = 0; s[i]; i++) {
		depth += s[i] == '(' ? 1 : s[i] == ')' ? -1 : 0;
		if (s[i] == ',' && depth == 0)
			return i;
	}
	return -1;
}

int prsm_expr_check(const prsm_expr_model *m, size_t e, unsigned char *used, prsm_expr_diag *diag)
{
	diag->position = 0;
	diag->code = "";
	diag->message[0] = 0;
	if (used)
		memset(used, 0, m->n_inputs);
	const char *s = m->exprs[e];
	const int len = (int)strlen(s);
	if (check_text(s, diag))
		return PRSM_EINVAL;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_expr_load(&err)) {
		diag_set(diag, 0, "unavailable", "%s", err.message);
		return PRSM_EIO;
	}
	double x[PRSM_EXPR_MAX_INPUTS];
	for (size_t i = 0; i < m->n_inputs; i++)
		x[i] = 1.0;
	muParserHandle_t h = parser_new(m, e, x);
	if (h == NULL)
		return diag_set(diag, 0, "unavailable", "muParser could not make a parser");
	(void)mup.eval(h);
	int rc = 0;
	if (mup.error(h)) {
		const int code = mup.get_error_code(h), pos = mup.get_error_pos(h);
		pthread_mutex_lock(&strings_lock);
		const char *t = mup.get_error_token(h);
		char token[80];
		snprintf(token, sizeof token, "%s", t ? t : "");
		pthread_mutex_unlock(&strings_lock);
		char msg[sizeof diag->message];
		const int unknown = describe(msg, sizeof msg, code, token, m);
		/* muParser's offset is 0-based (ASCII: bytes are characters); at or past the end, or none */
		rc = diag_set(diag, pos >= 0 && pos < len ? pos + 1 : len + 1, unknown ? "unknown_name" : "syntax", "%s", msg);
	} else {
		int results = 0;
		(void)mup.eval_multi(h, &results);
		if (results > 1)
			rc = diag_set(diag, top_level_comma(s) + 1, "not_allowed", "a comma outside a function's arguments: one "
			              "expression per output (%d results here)", results);
	}
	if (rc == 0 && used) {
		const int nv = mup.get_expr_var_num(h);
		for (int v = 0; v < nv; v++) {
			const muChar_t *name;
			muFloat_t *p;
			mup.get_expr_var(h, (unsigned)v, &name, &p);
			if (p >= x && p < x + m->n_inputs)
				used[p - x] = 1;
		}
	}
	mup.release(h);
	return rc;
}

/* ---- the engine's model ---------------------------------------------------------------------- */

typedef struct {
	double x[PRSM_EXPR_MAX_INPUTS];               /* the sample's inputs, bound to every parser */
	muParserHandle_t h[PRSM_EXPR_MAX_OUTPUTS];    /* output o's parser */
	size_t n;
} expr_ws;

static void expr_ws_free(void *p)
{
	expr_ws *w = p;
	if (w == NULL)
		return;
	for (size_t o = 0; o < w->n; o++)
		if (w->h[o])
			mup.release(w->h[o]);
	free(w);
}

/* A worker's parsers, each compiled by one evaluation (at inputs 0). */
static int expr_ws_alloc(void **out, const void *ctx)
{
	const prsm_expr_model *m = ctx;
	*out = NULL;
	if (prsm_expr_load(NULL))
		return PRSM_EIO;
	expr_ws *w = calloc(1, sizeof *w);
	if (w == NULL)
		return PRSM_ENOMEM;
	for (size_t o = 0; o < m->n_outputs; o++) {
		w->h[o] = parser_new(m, m->output_expr[o], w->x);
		w->n = o + 1;
		if (w->h[o] == NULL) {
			expr_ws_free(w);
			return PRSM_ENOMEM;
		}
		(void)mup.eval(w->h[o]);
		if (mup.error(w->h[o])) {
			expr_ws_free(w);
			return PRSM_EINVAL;
		}
	}
	*out = w;
	return 0;
}

static int expr_eval(double *y, unsigned *flags, const void *ctx, void *ws, const double *x)
{
	const prsm_expr_model *m = ctx;
	expr_ws *w = ws;
	*flags = 0;
	memcpy(w->x, x, m->n_inputs * sizeof *x);
	int rc = 0;
	for (size_t o = 0; o < m->n_outputs; o++) {
		y[o] = mup.eval(w->h[o]);
		if (!isfinite(y[o]))
			rc = PRSM_EINVAL;
	}
	return rc;
}

void prsm_expr_mc_model(prsm_mc_model *out, const prsm_expr_model *m)
{
	memset(out, 0, sizeof *out);
	out->n_outputs = m->n_outputs;
	out->ctx = m;
	out->workspace_alloc = expr_ws_alloc;
	out->workspace_free = expr_ws_free;
	out->eval = expr_eval;
}
