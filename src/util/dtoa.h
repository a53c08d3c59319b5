/*
 * dtoa.h: the shortest decimal form of a double that reads back as the same double, the one
 * number formatter of prsm (RFC 8785 cache keys through io/canonical, the numbers quoted in
 * messages through io/json_util).
 *
 * The digits are those ECMAScript's Number::toString picks (ECMA-262, Number::toString, step 5;
 * RFC 8785 §3.2.2.3): the fewest significant digits k such that the decimal reads back (round
 * to nearest, ties to even) as the double, and among the k-digit decimals that do, the one
 * closest to the double's exact value (the even one on a tie).
 */
#ifndef PRSM_UTIL_DTOA_H
#define PRSM_UTIL_DTOA_H

#include <stddef.h>

/* Most significant digits a double ever needs. */
#define PRSM_DTOA_DIGITS_MAX 17
/* Longest ECMAScript text, "-1.7976931348623157e+308", with its NUL, rounded up. */
#define PRSM_DTOA_TEXT_MAX 32

/*
 * The shortest round-trip digits of |v| (v finite and not zero): k digits '1'-'9' first, no
 * trailing zeros, NUL-terminated in digits, with |v| ~ 0.d1d2...dk x 10^point (so *point is
 * the position of the decimal point after the first digits: 1 for 1.5, 0 for 0.5, -2 for
 * 0.005). Returns k (1..17), or 0 for zero, NaN or an infinity (digits is then "").
 */
int prsm_dtoa_shortest(double v, char digits[PRSM_DTOA_DIGITS_MAX + 1], int *point);

/*
 * ECMAScript's Number.prototype.toString(v) into out: "0" for both zeros, "-2.5", "1e+21",
 * "123456789012345680000", "0.000001", "1e-7", "5e-324". Returns the length, or -1 (out "")
 * for NaN and the infinities, which JSON cannot hold.
 */
int prsm_dtoa_ecmascript(char out[PRSM_DTOA_TEXT_MAX], double v);

#endif
