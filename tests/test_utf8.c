/*
 * test_utf8.c: util/utf8.h, byte-bounded copies that keep UTF-8 valid.
 *
 * High-entropy strings of 1- to 4-byte characters (every sequence class of RFC 3629's table,
 * drawn by a fixed-seed generator) are copied into every capacity from 1 to their length + 1;
 * each copy must be valid UTF-8 (io/json_util.h's validator, an independent check), a prefix of
 * the source, and the longest such prefix that fits: the next character would not have.
 */
#include "test_support.h"

#include "io/json_util.h"
#include "util/problems.h"
#include "util/utf8.h"

static uint64_t state_ = 0x9E3779B97F4A7C15u;
static uint32_t next_u32(void)
{
	state_ ^= state_ << 13;
	state_ ^= state_ >> 7;
	state_ ^= state_ << 17;
	return (uint32_t)(state_ >> 11);
}

/* One random scalar value of 1..4 bytes in UTF-8 into out; returns its length. */
static size_t random_char(char *out)
{
	uint32_t cp;
	switch (next_u32() % 4) {
	case 0: cp = 0x20 + next_u32() % 0x5F; break;
	case 1: cp = 0x80 + next_u32() % (0x800 - 0x80); break;
	case 2:
		do
			cp = 0x800 + next_u32() % (0x10000 - 0x800);
		while (cp >= 0xD800 && cp <= 0xDFFF);
		break;
	default: cp = 0x10000 + next_u32() % (0x110000 - 0x10000); break;
	}
	unsigned char *u = (unsigned char *)out;
	if (cp < 0x80) {
		u[0] = (unsigned char)cp;
		return 1;
	}
	if (cp < 0x800) {
		u[0] = (unsigned char)(0xC0 | (cp >> 6));
		u[1] = (unsigned char)(0x80 | (cp & 0x3F));
		return 2;
	}
	if (cp < 0x10000) {
		u[0] = (unsigned char)(0xE0 | (cp >> 12));
		u[1] = (unsigned char)(0x80 | ((cp >> 6) & 0x3F));
		u[2] = (unsigned char)(0x80 | (cp & 0x3F));
		return 3;
	}
	u[0] = (unsigned char)(0xF0 | (cp >> 18));
	u[1] = (unsigned char)(0x80 | ((cp >> 12) & 0x3F));
	u[2] = (unsigned char)(0x80 | ((cp >> 6) & 0x3F));
	u[3] = (unsigned char)(0x80 | (cp & 0x3F));
	return 4;
}

static void test_copy_every_capacity(void **state)
{
	(void)state;
	char src[512], dst[512];
	size_t bounds[160];
	for (int trial = 0; trial < 400; trial++) {
		size_t len = 0, nchars = 0;
		int want = 1 + (int)(next_u32() % 100);
		bounds[0] = 0;
		for (int k = 0; k < want; k++) {
			len += random_char(src + len);
			bounds[++nchars] = len;
		}
		src[len] = '\0';
		assert_int_equal(prsm_json_utf8_invalid_at(src, len), len);
		for (size_t cap = 1; cap <= len + 1; cap++) {
			int whole = prsm_utf8_copy(dst, cap, src);
			const size_t got = strlen(dst);
			assert_int_equal(whole, cap > len);
			assert_int_equal(prsm_json_utf8_invalid_at(dst, got), got);
			assert_memory_equal(dst, src, got);
			/* the longest character boundary below cap */
			size_t best = 0;
			for (size_t k = 0; k <= nchars; k++)
				if (bounds[k] <= cap - 1)
					best = bounds[k];
			assert_int_equal(got, best);
		}
	}
}

/* A problem message quoting a long non-ASCII string: cut at a character, still valid. */
static void test_problem_message_cut(void **state)
{
	(void)state;
	char euro[400];
	size_t n = 0;
	for (int i = 0; i < 120; i++)
		n += (size_t)snprintf(euro + n, sizeof euro - n, "\xE2\x82\xAC");
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_problems_add(&p, "/name", "x", "unknown parameter '%s'", euro);
	const char *m = p.items[0].message;
	assert_true(strlen(m) < PRSM_PROBLEM_MESSAGE_MAX);
	assert_int_equal(prsm_json_utf8_invalid_at(m, strlen(m)), strlen(m));
	assert_int_equal((strlen(m) - strlen("unknown parameter '")) % 3, 0);
	/* trimming leaves whole strings alone */
	char whole[] = "a\xE2\x82\xAC" "b";
	prsm_utf8_trim_partial(whole);
	assert_string_equal(whole, "a\xE2\x82\xAC" "b");
	char cut[] = "a\xF0\x9F\x98";
	prsm_utf8_trim_partial(cut);
	assert_string_equal(cut, "a");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_copy_every_capacity),
		cmocka_unit_test(test_problem_message_cut),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
