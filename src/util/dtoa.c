/*
 * dtoa.c: shortest round-trip decimal digits of a double and ECMAScript's layout of them (see
 * dtoa.h).
 *
 * Method. Let G_p be the decimals of at most p significant digits and I(a) the interval of
 * reals that read back as a (round to nearest, ties to even). For a positive double a:
 *
 *   - The two elements of G_p around a are c, the correctly rounded p-digit decimal (printf's
 *     %.*e, which glibc computes exactly), and c's neighbour in G_p on the other side of a
 *     (one unit in c's last place up or down; below a power of ten the step is the finer one of
 *     the decade below). I(a) is an interval containing a, so some element of G_p lies in
 *     I(a) exactly when c or that neighbour does, and strtod (correctly rounded) tells which:
 *     a decimal is in I(a) exactly when strtod reads it back as a.
 *   - G_p is contained in G_{p+1}, so "G_p meets I(a)" is monotone in p and the fewest digits
 *     are found by bisection on p in 1..17 (G_17 always meets I(a)).
 *   - When both c and the neighbour are in I(a), c is the closer one (ties: glibc rounds to
 *     even, as ECMAScript chooses), which is ECMAScript's choice among the k-digit candidates.
 *
 * Why c alone is not enough: I(a) is symmetric about a except when a is a power of two (its
 * significand field zero), where the gap to the double below is half the gap to the double
 * above. There the correctly rounded c can lie below a, beyond the narrow lower half-gap, while
 * the neighbour above a, farther from a but inside the wide upper half-gap, reads back as a.
 * Testing c alone then finds no p-digit form and settles for p + 1 digits, one more than
 * ECMAScript writes (2^-1017 = 7.120236347223045e-307, not 7.1202363472230444e-307): 46 of
 * the 2046 normal powers of two.
 */
#include "util/dtoa.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* d[0] d[1] ... d[p-1] x 10^(e - p + 1): p significant digits, d[0] != '0'. */
typedef struct {
	char d[PRSM_DTOA_DIGITS_MAX + 2];
	int p, e;
} decimal;

/* The correctly rounded p-digit decimal of a > 0. */
static void rounded(decimal *x, double a, int p)
{
	char t[48];
	snprintf(t, sizeof t, "%.*e", p - 1, a); /* d[.ddd]e(+|-)xx */
	const char *s = t;
	int k = 0;
	for (; *s && *s != 'e'; s++)
		if (*s >= '0' && *s <= '9' && k < PRSM_DTOA_DIGITS_MAX)
			x->d[k++] = *s;
	x->d[k] = '\0';
	x->p = k;
	x->e = *s == 'e' ? (int)strtol(s + 1, NULL, 10) : 0; /* printf's own exponent: |e| <= 324 */
}

/* The double a decimal reads as. */
static double value(const decimal *x)
{
	char t[48];
	snprintf(t, sizeof t, "%se%d", x->d, x->e - (x->p - 1));
	return strtod(t, NULL);
}

/* The next decimal of p digits above x: 1.99 -> 2.00, 9.99e4 -> 1.00e5. */
static void step_up(decimal *x)
{
	int i = x->p - 1;
	while (i >= 0 && x->d[i] == '9')
		x->d[i--] = '0';
	if (i >= 0) {
		x->d[i]++;
		return;
	}
	x->d[0] = '1';
	x->e++;
}

/* The next decimal of p digits below x: 2.00 -> 1.99, 1.00e5 -> 9.99e4. */
static void step_down(decimal *x)
{
	int i = x->p - 1;
	while (i > 0 && x->d[i] == '0')
		x->d[i--] = '9';
	x->d[i]--;
	if (x->d[0] == '0') { /* x was a power of ten: the grid below it is ten times finer */
		memset(x->d, '9', (size_t)x->p);
		x->e--;
	}
}

/* 1 when a decimal of p digits reads back as a, with the closest such one in *x; else 0. */
static int round_trips(decimal *x, double a, int p)
{
	rounded(x, a, p);
	double r = value(x);
	if (r == a)
		return 1;
	if (r < a)
		step_up(x);
	else
		step_down(x);
	return value(x) == a;
}

int prsm_dtoa_shortest(double v, char digits[PRSM_DTOA_DIGITS_MAX + 1], int *point)
{
	digits[0] = '\0';
	*point = 0;
	if (!isfinite(v) || v == 0.0)
		return 0;
	double a = fabs(v);
	decimal best, x;
	int lo = 1, hi = PRSM_DTOA_DIGITS_MAX;
	if (!round_trips(&best, a, hi)) /* cannot happen with a correctly rounding libc */
		rounded(&best, a, hi);
	while (lo < hi) {
		int mid = lo + (hi - lo) / 2;
		if (round_trips(&x, a, mid)) {
			best = x;
			hi = mid;
		} else {
			lo = mid + 1;
		}
	}
	int k = best.p;
	while (k > 1 && best.d[k - 1] == '0')
		k--;
	memcpy(digits, best.d, (size_t)k);
	digits[k] = '\0';
	*point = best.e + 1;
	return k;
}

int prsm_dtoa_ecmascript(char out[PRSM_DTOA_TEXT_MAX], double v)
{
	out[0] = '\0';
	if (!isfinite(v))
		return -1;
	if (v == 0.0) { /* -0 too */
		out[0] = '0';
		out[1] = '\0';
		return 1;
	}
	char d[PRSM_DTOA_DIGITS_MAX + 1];
	int n;
	int k = prsm_dtoa_shortest(v, d, &n);
	char *o = out;
	if (v < 0)
		*o++ = '-';
	if (k <= n && n <= 21) { /* an integer: the digits, then zeros */
		memcpy(o, d, (size_t)k);
		o += k;
		memset(o, '0', (size_t)(n - k));
		o += n - k;
	} else if (0 < n && n <= 21) { /* the point inside the digits */
		memcpy(o, d, (size_t)n);
		o += n;
		*o++ = '.';
		memcpy(o, d + n, (size_t)(k - n));
		o += k - n;
	} else if (-6 < n && n <= 0) { /* 0.000ddd */
		*o++ = '0';
		*o++ = '.';
		memset(o, '0', (size_t)-n);
		o += -n;
		memcpy(o, d, (size_t)k);
		o += k;
	} else { /* d[.ddd]e(+|-)x */
		*o++ = d[0];
		if (k > 1) {
			*o++ = '.';
			memcpy(o, d + 1, (size_t)(k - 1));
			o += k - 1;
		}
		o += snprintf(o, (size_t)(out + PRSM_DTOA_TEXT_MAX - o), "e%c%d", n - 1 >= 0 ? '+' : '-',
		              abs(n - 1));
	}
	*o = '\0';
	return (int)(o - out);
}
