/*
 * test_canonical.c: io/canonical against RFC 8785 — the number examples of its Appendix B
 * (given as IEEE 754 bit patterns), the sorting example of §3.2.3 (UTF-16 order, where UTF-8
 * byte order differs), the string escapes, the complete example of §3.2.2 — and what it
 * refuses: duplicate members (with their pointer), invalid UTF-8, the size cap; the shared UTF-8
 * validator on overlong forms, surrogates and truncated sequences.
 *
 * Numbers (util/dtoa, shared with io/json_util's messages) are also checked against node's
 * String(x) on a deterministic stream of 479,232 doubles in five families: every power of two
 * and its 8 neighbours each side (both signs; the family where the former formatter wrote 17
 * digits for 46 powers of two), powers of ten with their neighbours and the layout thresholds
 * (1e21, 1e-6, ...), random bit patterns, random integers below 2^53 and random decimal
 * literals. Node is not needed here: the SHA-256 of each family's "hex text" lines as node
 * writes them is below. `test_canonical --dump` prints the stream ("family hex text" lines);
 * tests/test_canonical_numbers.mjs compares every line with node and prints those digests:
 *
 *   node tests/test_canonical_numbers.mjs build/tests/test_canonical
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include "io/canonical.h"
#include "io/json_util.h"
#include "util/dtoa.h"
#include "util/sha256.h"

static double bits(uint64_t u)
{
	double d;
	memcpy(&d, &u, sizeof d);
	return d;
}

static void test_numbers(void **state)
{
	(void)state;
	static const struct {
		uint64_t bits;
		const char *text;
	} cases[] = {
		{0x0000000000000000ULL, "0"},
		{0x8000000000000000ULL, "0"},
		{0x0000000000000001ULL, "5e-324"},
		{0x8000000000000001ULL, "-5e-324"},
		{0x7fefffffffffffffULL, "1.7976931348623157e+308"},
		{0xffefffffffffffffULL, "-1.7976931348623157e+308"},
		{0x4340000000000000ULL, "9007199254740992"},
		{0xc340000000000000ULL, "-9007199254740992"},
		{0x4430000000000000ULL, "295147905179352830000"},
		{0x44b52d02c7e14af5ULL, "9.999999999999997e+22"},
		{0x44b52d02c7e14af6ULL, "1e+23"},
		{0x44b52d02c7e14af7ULL, "1.0000000000000001e+23"},
		{0x444b1ae4d6e2ef4eULL, "999999999999999700000"},
		{0x444b1ae4d6e2ef4fULL, "999999999999999900000"},
		{0x444b1ae4d6e2ef50ULL, "1e+21"},
		{0x3eb0c6f7a0b5ed8cULL, "9.999999999999997e-7"},
		{0x3eb0c6f7a0b5ed8dULL, "0.000001"},
		{0x3eb0c6f7a0b5ed8eULL, "0.0000010000000000000002"},
		{0x41b3de4355555553ULL, "333333333.3333332"},
		{0x41b3de4355555554ULL, "333333333.33333325"},
		{0x41b3de4355555555ULL, "333333333.3333333"},
		{0x41b3de4355555556ULL, "333333333.3333334"},
		{0x41b3de4355555557ULL, "333333333.33333343"},
		{0xbecbf647612f3696ULL, "-0.0000033333333333333333"},
		{0x43143ff3c1cb0959ULL, "1424953923781206.2"},
		{0x3ff0000000000000ULL, "1"},
		{0x4415af1d78b58c40ULL, "100000000000000000000"},
	};
	char buf[PRSM_CANONICAL_NUMBER_MAX];
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		assert_int_equal(prsm_canonical_number(buf, bits(cases[i].bits)), 0);
		assert_string_equal(buf, cases[i].text);
	}
	assert_int_equal(prsm_canonical_number(buf, 1e-7), 0);
	assert_string_equal(buf, "1e-7");
	assert_int_equal(prsm_canonical_number(buf, 2.385), 0);
	assert_string_equal(buf, "2.385");
	assert_int_equal(prsm_canonical_number(buf, -0.5), 0);
	assert_string_equal(buf, "-0.5");
	assert_int_equal(prsm_canonical_number(buf, 123e18), 0);
	assert_string_equal(buf, "123000000000000000000");
	assert_int_equal(prsm_canonical_number(buf, NAN), PRSM_EINVAL);
	assert_int_equal(prsm_canonical_number(buf, INFINITY), PRSM_EINVAL);
	assert_int_equal(prsm_canonical_number(buf, -INFINITY), PRSM_EINVAL);
}

/* Powers of two, where the double below is half as far as the double above: the correctly
 * rounded 16-digit decimal falls outside the narrow lower half-gap, and the shortest form is
 * the 16-digit decimal above (the former formatter wrote 17 digits for these). Node's
 * String(x) for each. */
static void test_powers_of_two(void **state)
{
	(void)state;
	static const struct {
		uint64_t bits;
		const char *text;
	} cases[] = {
		{0x0060000000000000ULL, "7.120236347223045e-307"},  /* 2^-1017 */
		{0x8060000000000000ULL, "-7.120236347223045e-307"},
		{0x0100000000000000ULL, "7.291122019556398e-304"},  /* 2^-1007 */
		{0x0420000000000000ULL, "8.209073602596753e-289"},  /* 2^-957 */
		{0x0660000000000000ULL, "5.641232424577593e-278"},  /* 2^-921 */
		{0x13e0000000000000ULL, "5.940911144672375e-213"},  /* 2^-705 */
		{0x1480000000000000ULL, "6.083493012144512e-210"},  /* 2^-695 */
		{0x0010000000000000ULL, "2.2250738585072014e-308"}, /* 2^-1022, symmetric: 17 digits */
		{0x7fe0000000000000ULL, "8.98846567431158e+307"},   /* 2^1023 */
	};
	char buf[PRSM_CANONICAL_NUMBER_MAX], digits[PRSM_DTOA_DIGITS_MAX + 1];
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		assert_int_equal(prsm_canonical_number(buf, bits(cases[i].bits)), 0);
		assert_string_equal(buf, cases[i].text);
	}
	/* the same digits in the messages' layout */
	prsm_json_format_number(buf, sizeof buf, bits(0x0060000000000000ULL));
	assert_string_equal(buf, "7.120236347223045e-307");
	int point;
	assert_int_equal(prsm_dtoa_shortest(bits(0x0060000000000000ULL), digits, &point), 16);
	assert_string_equal(digits, "7120236347223045");
	assert_int_equal(point, -306);
	assert_int_equal(prsm_dtoa_shortest(0.005, digits, &point), 1);
	assert_string_equal(digits, "5");
	assert_int_equal(point, -2);
	assert_int_equal(prsm_dtoa_shortest(0.0, digits, &point), 0);
	assert_string_equal(digits, "");
}

/* The messages' layout of io/json_util: printf's %g with the shortest digits. */
static void test_message_numbers(void **state)
{
	(void)state;
	static const struct {
		double v;
		const char *text;
	} cases[] = {
		{0.1, "0.1"}, {-2.0, "-2"}, {1e8, "100000000"}, {2.385e-7, "2.385e-07"}, {1e15, "1e+15"},
		{123456789012345.0, "123456789012345"}, {0.0001, "0.0001"}, {1e-5, "1e-05"},
		{-0.00012, "-0.00012"}, {123.5, "123.5"}, {1.5e300, "1.5e+300"}, {5e-324, "5e-324"},
		{1e21, "1e+21"}, {12345678.25, "12345678.25"}, {-0.0, "-0"}, {NAN, "nan"}, {INFINITY, "inf"},
	};
	char buf[40];
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		prsm_json_format_number(buf, sizeof buf, cases[i].v);
		assert_string_equal(buf, cases[i].text);
	}
}

/* ---- the stream compared with node ---------------------------------------------------- */

enum { FAM_POWERS, FAM_TENS, FAM_BITS, FAM_INTEGERS, FAM_DECIMALS, FAM_COUNT };
static const char *const family_names[FAM_COUNT] = {"powers", "tens", "bits", "integers", "decimals"};
/* Node's String(x), as "%016x text\n" lines, per family (tests/test_canonical_numbers.mjs). */
static const struct {
	long count;
	const char *sha256;
} family_expected[FAM_COUNT] = {
	{69582, "caeaa7a06fffc22f5d7651bc9233d432916f030196fbde22cd9e6a5a34cb7603"},  /* powers */
	{10037, "c983911fc49837fd69f0b8170208312fa54bf808bfaa15735148b8db48157887"},  /* tens */
	{200000, "aadbfe303b696cf51b11ae8ecfed4b21946ab87f6c935898c48a8abe212b0a8b"}, /* bits */
	{100000, "20bf00fdeb28b20bd0d4080422a98b34719013847f1960a6fcd8aaf43afaa6ac"}, /* integers */
	{99613, "727bb1783264b389823ac29f300e8f4be9cdaf0f8be41d2690a8c7ac8c597697"},  /* decimals */
};

static uint64_t splitmix64(uint64_t *s)
{
	uint64_t z = (*s += 0x9E3779B97F4A7C15ULL);
	z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
	z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
	return z ^ (z >> 31);
}

static uint64_t bits_of(double d)
{
	uint64_t u;
	memcpy(&u, &d, sizeof u);
	return u;
}

typedef void (*visit_fn)(void *ctx, int family, double v);

/* The doubles n ulps either side of v (n = -k..k, finite ones only), one sign. */
static void around(visit_fn f, void *ctx, int family, double v, int k)
{
	uint64_t u = bits_of(v);
	for (int n = -k; n <= k; n++) {
		if (n < 0 && (u & 0x7FFFFFFFFFFFFFFFULL) < (uint64_t)-n)
			continue; /* past zero */
		double d = bits((uint64_t)((int64_t)u + n));
		if (isfinite(d) && (bits_of(d) >> 63) == (u >> 63))
			f(ctx, family, d);
	}
}

/* Every double of the stream, in a fixed order. */
static void number_stream(visit_fn f, void *ctx)
{
	/* every power of two (biased exponents 0..2046, 0 being the smallest subnormal's binade
	 * start, i.e. zero) and 8 doubles either side, both signs */
	for (uint64_t e = 0; e <= 2046; e++)
		for (int sign = 0; sign < 2; sign++)
			around(f, ctx, FAM_POWERS, bits((e << 52) | ((uint64_t)sign << 63)), 8);
	/* powers of ten 1e-323..1e308 and 3 doubles either side; 200 either side of the layout
	 * thresholds */
	char lit[64];
	for (int k = -323; k <= 308; k++) {
		snprintf(lit, sizeof lit, "1e%d", k);
		around(f, ctx, FAM_TENS, strtod(lit, NULL), 3);
	}
	static const double thresholds[] = {1e21, 1e-6, 1e-7, 1e15, 1e16, 1e17, 9007199254740992.0};
	for (size_t i = 0; i < sizeof thresholds / sizeof thresholds[0]; i++) {
		around(f, ctx, FAM_TENS, thresholds[i], 200);
		around(f, ctx, FAM_TENS, -thresholds[i], 200);
	}
	uint64_t s = 0x5052534D2D4A4353ULL; /* "PRSM-JCS" */
	for (int i = 0; i < 200000; i++) {
		uint64_t u = splitmix64(&s);
		if (((u >> 52) & 0x7FF) == 0x7FF)
			u ^= 1ULL << 62; /* NaN or infinity: a finite double instead */
		f(ctx, FAM_BITS, bits(u));
	}
	for (int i = 0; i < 100000; i++) {
		uint64_t r = splitmix64(&s);
		uint64_t k = splitmix64(&s) >> (11 + r % 53); /* below 2^53: exact */
		f(ctx, FAM_INTEGERS, (r >> 32) & 1 ? -(double)k : (double)k);
	}
	static const uint64_t pow10[] = {1ULL, 10ULL, 100ULL, 1000ULL, 10000ULL, 100000ULL, 1000000ULL,
	                                 10000000ULL, 100000000ULL, 1000000000ULL, 10000000000ULL,
	                                 100000000000ULL, 1000000000000ULL, 10000000000000ULL,
	                                 100000000000000ULL, 1000000000000000ULL, 10000000000000000ULL,
	                                 100000000000000000ULL};
	for (int i = 0; i < 100000; i++) {
		uint64_t r = splitmix64(&s);
		unsigned long long m = splitmix64(&s) % pow10[1 + r % 17]; /* up to 17 digits */
		int e = (i % 4 == 3) ? (int)(splitmix64(&s) % 640) - 330 : (int)(splitmix64(&s) % 61) - 30;
		snprintf(lit, sizeof lit, "%s%llue%d", (r >> 40) & 1 ? "-" : "", m, e);
		double d = strtod(lit, NULL);
		if (isfinite(d)) /* not past DBL_MAX */
			f(ctx, FAM_DECIMALS, d);
	}
}

typedef struct {
	prsm_sha256 h[FAM_COUNT];
	long count[FAM_COUNT];
	long message_checked;
	FILE *dump;
} stream_state;

static void visit(void *ctx, int family, double v)
{
	stream_state *st = ctx;
	char line[80], text[PRSM_CANONICAL_NUMBER_MAX];
	assert_int_equal(prsm_canonical_number(text, v), 0);
	int n = snprintf(line, sizeof line, "%016llx %s\n", (unsigned long long)bits_of(v), text);
	prsm_sha256_update(&st->h[family], line, (size_t)n);
	st->count[family]++;
	if (st->dump) {
		fprintf(st->dump, "%s %s", family_names[family], line);
		return;
	}
	/* the text reads back as v (-0 aside) */
	assert_true(strtod(text, NULL) == v);
	/* the messages' form: the same digits in printf's %g layout. Away from powers of two the
	 * closest shortest decimal is the correctly rounded one, so %.*g with as many digits writes
	 * the same text. */
	if (v != floor(v) || fabs(v) >= 1e15) {
		char msg[40], want[40], d[PRSM_DTOA_DIGITS_MAX + 1];
		int point, k = prsm_dtoa_shortest(v, d, &point);
		prsm_json_format_number(msg, sizeof msg, v);
		assert_true(strtod(msg, NULL) == v);
		if ((bits_of(v) & 0x000FFFFFFFFFFFFFULL) != 0) {
			snprintf(want, sizeof want, "%.*g", k, v);
			assert_string_equal(msg, want);
			st->message_checked++;
		}
	}
}

static void test_node_stream(void **state)
{
	(void)state;
	stream_state st;
	memset(&st, 0, sizeof st);
	for (int i = 0; i < FAM_COUNT; i++)
		prsm_sha256_init(&st.h[i]);
	number_stream(visit, &st);
	long total = 0;
	int bad = 0;
	for (int i = 0; i < FAM_COUNT; i++) {
		uint8_t digest[PRSM_SHA256_BYTES];
		char hex[PRSM_SHA256_HEX];
		prsm_sha256_final(&st.h[i], digest);
		prsm_sha256_to_hex(hex, digest);
		total += st.count[i];
		if (st.count[i] != family_expected[i].count || strcmp(hex, family_expected[i].sha256) != 0) {
			fprintf(stderr, "family %s: %ld doubles, sha256 %s; node: %ld, %s\n", family_names[i],
			        st.count[i], hex, family_expected[i].count, family_expected[i].sha256);
			bad = 1;
		}
	}
	fprintf(stderr, "%ld doubles compared with node's String(x); %ld message forms with %%.*g\n", total,
	        st.message_checked);
	if (bad)
		fprintf(stderr, "see the differences: node tests/test_canonical_numbers.mjs <this program>\n");
	assert_false(bad);
}

static char *canon(const char *json, int *rc, prsm_error *err)
{
	cJSON *t = cJSON_Parse(json);
	assert_non_null(t);
	char *out = NULL;
	*rc = prsm_canonical_json(&out, NULL, t, 1u << 20, err);
	cJSON_Delete(t);
	return out;
}

static void test_rfc_example(void **state)
{
	(void)state;
	/* RFC 8785 §3.2.2 */
	const char *in = "{\n  \"numbers\": [333333333.33333329, 1E30, 4.50,\n 2e-3, 0.000000000000000000000000001],\n"
	                 "  \"string\": \"\\u20ac$\\u000F\\u000aA'\\u0042\\u0022\\u005c\\\\\\\"\\/\",\n"
	                 "  \"literals\": [null, true, false]\n}";
	const char *want = "{\"literals\":[null,true,false],\"numbers\":[333333333.3333333,1e+30,4.5,0.002,1e-27],"
	                   "\"string\":\"\xe2\x82\xac$\\u000f\\nA'B\\\"\\\\\\\\\\\"/\"}";
	int rc;
	prsm_error err = PRSM_ERROR_INIT;
	char *out = canon(in, &rc, &err);
	assert_int_equal(rc, 0);
	assert_string_equal(out, want);
	free(out);
}

static void test_sorting(void **state)
{
	(void)state;
	/* RFC 8785 §3.2.3: sorted by UTF-16 code units */
	const char *in = "{\"\\u20ac\": \"Euro Sign\", \"\\r\": \"Carriage Return\", \"\\ufb33\": \"Hebrew Letter Dalet With Dagesh\","
	                 " \"1\": \"One\", \"\\ud83d\\ude00\": \"Emoji: Grinning Face\", \"\\u0080\": \"Control\","
	                 " \"\\u00f6\": \"Latin Small Letter O With Diaeresis\"}";
	int rc;
	prsm_error err = PRSM_ERROR_INIT;
	char *out = canon(in, &rc, &err);
	assert_int_equal(rc, 0);
	const char *order[] = {"\\r", "1", "\xc2\x80", "\xc3\xb6", "\xe2\x82\xac", "\xf0\x9f\x98\x80", "\xef\xac\xb3"};
	const char *p = out;
	for (size_t i = 0; i < 7; i++) {
		char key[16];
		snprintf(key, sizeof key, "\"%s\":", order[i]);
		const char *q = strstr(p, key);
		assert_non_null(q);
		p = q + 1;
	}
	free(out);
	/* the emoji (a surrogate pair) sorts before U+FB33 in UTF-16 but after it in UTF-8 */
	assert_true(prsm_canonical_key_compare("\xf0\x9f\x98\x80", "\xef\xac\xb3") < 0);
	assert_true(prsm_canonical_key_compare("a", "ab") < 0);
	assert_int_equal(prsm_canonical_key_compare("ab", "ab"), 0);
}

static void test_nested_and_whitespace(void **state)
{
	(void)state;
	int rc;
	prsm_error err = PRSM_ERROR_INIT;
	char *a = canon("{ \"b\" : [ 1.0 , {\"y\":2,\"x\":1} ], \"a\": \"\\u0007\" }", &rc, &err);
	assert_int_equal(rc, 0);
	assert_string_equal(a, "{\"a\":\"\\u0007\",\"b\":[1,{\"x\":1,\"y\":2}]}");
	free(a);
	char *e = canon("{}", &rc, &err);
	assert_string_equal(e, "{}");
	free(e);
	e = canon("[]", &rc, &err);
	assert_string_equal(e, "[]");
	free(e);
}

static void test_refusals(void **state)
{
	(void)state;
	int rc;
	prsm_error err = PRSM_ERROR_INIT;
	char *out = canon("{\"a\": {\"k/x\": 1, \"k/x\": 2}}", &rc, &err);
	assert_null(out);
	assert_int_equal(rc, PRSM_EINVAL);
	assert_string_equal(err.pointer, "/a/k~1x");
	/* invalid UTF-8 inside a string (cJSON does not check) */
	out = canon("[\"ok\", \"\xc0\xaf\"]", &rc, &err);
	assert_null(out);
	assert_int_equal(rc, PRSM_EINVAL);
	assert_string_equal(err.pointer, "/1");
	/* the size cap */
	cJSON *t = cJSON_Parse("[\"0123456789\", \"0123456789\"]");
	char *s = NULL;
	assert_int_equal(prsm_canonical_json(&s, NULL, t, 10, &err), PRSM_ENOMEM);
	assert_null(s);
	size_t len = 0;
	assert_int_equal(prsm_canonical_json(&s, &len, t, 27, &err), 0);
	assert_int_equal(len, 27);
	free(s);
	cJSON_Delete(t);
}

static void test_utf8(void **state)
{
	(void)state;
	/* the one validator, io/json_util's, which the canonical form uses */
	assert_int_equal(prsm_json_utf8_invalid_at("plain", 5), 5);
	assert_int_equal(prsm_json_utf8_invalid_at("\xe2\x82\xac\xf0\x9f\x98\x80", 7), 7);
	assert_int_equal(prsm_json_utf8_invalid_at("ab\xc0\xaf", 4), 2);     /* overlong '/' */
	assert_int_equal(prsm_json_utf8_invalid_at("\xe0\x80\xaf", 3), 0);  /* overlong, 3 bytes */
	assert_int_equal(prsm_json_utf8_invalid_at("\xed\xa0\x80", 3), 0);  /* a surrogate */
	assert_int_equal(prsm_json_utf8_invalid_at("x\xe2\x82", 3), 1);      /* truncated */
	assert_int_equal(prsm_json_utf8_invalid_at("\xf4\x90\x80\x80", 4), 0); /* above U+10FFFF */
	assert_int_equal(prsm_json_utf8_invalid_at("\xf5\x80\x80\x80", 4), 0);
	assert_int_equal(prsm_json_utf8_invalid_at("\xff", 1), 0);
	assert_int_equal(prsm_json_utf8_invalid_at("\x80", 1), 0);
	assert_int_equal(prsm_json_utf8_invalid_at("\xf4\x8f\xbf\xbf", 4), 4); /* U+10FFFF */
	/* a member name and a long pointer through the shared pointer builder */
	int rc;
	prsm_error err = PRSM_ERROR_INIT;
	char *out = canon("{\"a~b\": {\"ok\": 1, \"bad\xed\xa0\x80\": 2}}", &rc, &err);
	assert_null(out);
	assert_int_equal(rc, PRSM_EINVAL);
	assert_string_equal(err.pointer, "/a~0b");
	char deep[400];
	int k = snprintf(deep, sizeof deep, "{\"");
	for (int i = 0; i < 150; i++)
		deep[k++] = '/';
	snprintf(deep + k, sizeof deep - (size_t)k, "\": [1, 2, {\"x\": 1, \"x\": 2}]}");
	out = canon(deep, &rc, &err);
	assert_null(out);
	assert_int_equal(rc, PRSM_EINVAL);
	assert_string_equal(err.pointer, ""); /* "/~1~1..." does not fit: its ancestor, the root */
}

/* `test_canonical --dump`: the number stream for tests/test_canonical_numbers.mjs. */
static int dump_stream(void)
{
	stream_state st;
	memset(&st, 0, sizeof st);
	st.dump = stdout;
	number_stream(visit, &st);
	return fflush(stdout) == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
	if (argc > 1 && strcmp(argv[1], "--dump") == 0)
		return dump_stream();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_numbers),
		cmocka_unit_test(test_powers_of_two),
		cmocka_unit_test(test_message_numbers),
		cmocka_unit_test(test_node_stream),
		cmocka_unit_test(test_rfc_example),
		cmocka_unit_test(test_sorting),
		cmocka_unit_test(test_nested_and_whitespace),
		cmocka_unit_test(test_refusals),
		cmocka_unit_test(test_utf8),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
