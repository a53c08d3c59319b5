/*
 * bench_models.h: analytic models a study may name instead of a design, so anyone can check
 * the Monte Carlo and sensitivity engine against exact values (docs/studies.md): the
 * Ishigami function, Sobol's G-function and a linear stack. (A study's own expressions are the
 * other analytic model: mc/expr_model.h.)
 */
#ifndef PRSM_MC_BENCH_MODELS_H
#define PRSM_MC_BENCH_MODELS_H

#include "mc/engine.h"

#define PRSM_BENCH_MAX_INPUTS 64

/* PRSM_BENCH_EXPRESSION marks a study's analytic model that is no benchmark but expressions
 * (mc/expr_model.h): its name is "expression", prsm_bench_kind_parse does not take it, it has no
 * closed form here (prsm_bench_eval NAN, prsm_bench_exact PRSM_EINVAL). */
typedef enum {
	PRSM_BENCH_ISHIGAMI = 0,
	PRSM_BENCH_GFUNCTION = 1,
	PRSM_BENCH_LINEAR = 2,
	PRSM_BENCH_EXPRESSION = 3
} prsm_bench_kind;

typedef struct {
	prsm_bench_kind kind;
	size_t inputs;                     /* x_1 .. x_inputs (Ishigami: 3) */
	double a, b;                       /* Ishigami constants (7, 0.1) */
	double coef[PRSM_BENCH_MAX_INPUTS];/* G-function a_i, or linear c_i */
	double constant;                   /* linear c_0 */
} prsm_bench_model;

const char *prsm_bench_name(prsm_bench_kind k);
int prsm_bench_kind_parse(const char *name, prsm_bench_kind *out); /* 0 or PRSM_ENOTFOUND */

/* y = f(x), one output. */
double prsm_bench_eval(const prsm_bench_model *b, const double *x);

/* The engine's view of b (b must outlive it). */
void prsm_bench_mc_model(prsm_mc_model *out, const prsm_bench_model *b);

/* Exact mean and variance, and first-order / total Sobol indices (d = b->inputs entries),
 * for inputs with the benchmark's own distributions (Ishigami: U(-pi, pi); G: U(0, 1)).
 * Linear: needs the inputs' standard deviations sd[] (NULL otherwise). Returns 0. */
int prsm_bench_exact(const prsm_bench_model *b, const double *sd, double *mean, double *variance,
                     double *first, double *total);

#endif
