/*
 * bench_models.c: the analytic benchmark models and their exact moments and Sobol indices
 * (Ishigami & Homma 1990; Sobol's G-function, Saltelli et al. 2008).
 */
#include "mc/bench_models.h"

#include <math.h>
#include <string.h>

const char *prsm_bench_name(prsm_bench_kind k)
{
	switch (k) {
	case PRSM_BENCH_ISHIGAMI: return "ishigami";
	case PRSM_BENCH_GFUNCTION: return "gfunction";
	case PRSM_BENCH_LINEAR: return "linear";
	case PRSM_BENCH_EXPRESSION: return "expression";
	}
	return "?";
}

int prsm_bench_kind_parse(const char *name, prsm_bench_kind *out)
{
	for (int k = 0; k <= PRSM_BENCH_LINEAR; k++)
		if (strcmp(name, prsm_bench_name((prsm_bench_kind)k)) == 0) {
			*out = (prsm_bench_kind)k;
			return 0;
		}
	return PRSM_ENOTFOUND;
}

double prsm_bench_eval(const prsm_bench_model *b, const double *x)
{
	switch (b->kind) {
	case PRSM_BENCH_ISHIGAMI: {
		double s1 = sin(x[0]), s2 = sin(x[1]), x3 = x[2];
		return s1 + b->a * s2 * s2 + b->b * x3 * x3 * x3 * x3 * s1;
	}
	case PRSM_BENCH_GFUNCTION: {
		double g = 1.0;
		for (size_t i = 0; i < b->inputs; i++)
			g *= (fabs(4.0 * x[i] - 2.0) + b->coef[i]) / (1.0 + b->coef[i]);
		return g;
	}
	case PRSM_BENCH_LINEAR: {
		double y = b->constant;
		for (size_t i = 0; i < b->inputs; i++)
			y += b->coef[i] * x[i];
		return y;
	}
	case PRSM_BENCH_EXPRESSION:
		break;
	}
	return NAN;
}

static int bench_eval(double *y, unsigned *flags, const void *ctx, void *ws, const double *x)
{
	(void)ws;
	*flags = 0;
	y[0] = prsm_bench_eval(ctx, x);
	return 0;
}

void prsm_bench_mc_model(prsm_mc_model *out, const prsm_bench_model *b)
{
	memset(out, 0, sizeof *out);
	out->n_outputs = 1;
	out->ctx = b;
	out->eval = bench_eval;
}

int prsm_bench_exact(const prsm_bench_model *b, const double *sd, double *mean, double *variance,
                     double *first, double *total)
{
	const size_t d = b->inputs;
	switch (b->kind) {
	case PRSM_BENCH_ISHIGAMI: {
		/* Ishigami & Homma 1990; benchmarks.md */
		const double a = b->a, bb = b->b, pi4 = pow(M_PI, 4), pi8 = pi4 * pi4;
		double V1 = 0.5 * pow(1.0 + bb * pi4 / 5.0, 2);
		double V2 = a * a / 8.0;
		double V13 = bb * bb * pi8 * (1.0 / 18.0 - 1.0 / 50.0);
		double V = V1 + V2 + V13;
		*mean = a / 2.0;
		*variance = V;
		first[0] = V1 / V;
		first[1] = V2 / V;
		first[2] = 0.0;
		total[0] = (V1 + V13) / V;
		total[1] = V2 / V;
		total[2] = V13 / V;
		return 0;
	}
	case PRSM_BENCH_GFUNCTION: {
		double prod = 1.0;
		for (size_t i = 0; i < d; i++)
			prod *= 1.0 + 1.0 / (3.0 * pow(1.0 + b->coef[i], 2));
		double V = prod - 1.0;
		*mean = 1.0;
		*variance = V;
		for (size_t i = 0; i < d; i++) {
			double Vi = 1.0 / (3.0 * pow(1.0 + b->coef[i], 2));
			first[i] = Vi / V;
			total[i] = Vi * (prod / (1.0 + Vi)) / V;
		}
		return 0;
	}
	case PRSM_BENCH_LINEAR: {
		double V = 0.0;
		for (size_t i = 0; i < d; i++)
			V += pow(b->coef[i] * sd[i], 2);
		*mean = NAN; /* depends on the input means */
		*variance = V;
		for (size_t i = 0; i < d; i++)
			first[i] = total[i] = V > 0 ? pow(b->coef[i] * sd[i], 2) / V : 0.0;
		return 0;
	}
	case PRSM_BENCH_EXPRESSION:
		break;
	}
	return PRSM_EINVAL;
}
