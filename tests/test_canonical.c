/*
 * test_canonical.c: io/canonical against RFC 8785 — the number examples of its Appendix B
 * (given as IEEE 754 bit patterns), the sorting example of §3.2.3 (UTF-16 order, where UTF-8
 * byte order differs), the string escapes, the complete example of §3.2.2 — and what it
 * refuses: duplicate members (with their pointer), invalid UTF-8, the size cap; the UTF-8
 * validator on overlong forms, surrogates and truncated sequences.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include "io/canonical.h"

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
		{0x41b3de4355555555ULL, "333333333.3333333"},
		{0x41b3de4355555556ULL, "333333333.3333334"},
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
	size_t bad = 99;
	assert_true(prsm_utf8_valid("plain", 5, &bad));
	assert_true(prsm_utf8_valid("\xe2\x82\xac\xf0\x9f\x98\x80", 7, &bad));
	assert_false(prsm_utf8_valid("ab\xc0\xaf", 4, &bad)); /* overlong '/' */
	assert_int_equal(bad, 2);
	assert_false(prsm_utf8_valid("\xed\xa0\x80", 3, &bad)); /* a surrogate */
	assert_false(prsm_utf8_valid("x\xe2\x82", 3, &bad));    /* truncated */
	assert_int_equal(bad, 1);
	assert_false(prsm_utf8_valid("\xf4\x90\x80\x80", 4, &bad)); /* above U+10FFFF */
	assert_false(prsm_utf8_valid("\xff", 1, &bad));
	assert_false(prsm_utf8_valid("\x80", 1, &bad));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_numbers),
		cmocka_unit_test(test_rfc_example),
		cmocka_unit_test(test_sorting),
		cmocka_unit_test(test_nested_and_whitespace),
		cmocka_unit_test(test_refusals),
		cmocka_unit_test(test_utf8),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
