/*
 * test_sha256.c: util/sha256 against the FIPS 180-2 / NIST example digests (empty, "abc", the
 * two-block message, a million 'a's fed in uneven pieces) and the hex form.
 */
#include "test_support.h"

#include <string.h>

#include "util/sha256.h"

static void test_known_answers(void **state)
{
	(void)state;
	char hex[PRSM_SHA256_HEX];
	prsm_sha256_hex(hex, "", 0);
	assert_string_equal(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
	prsm_sha256_hex(hex, "abc", 3);
	assert_string_equal(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
	const char *two = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
	prsm_sha256_hex(hex, two, strlen(two));
	assert_string_equal(hex, "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

static void test_incremental_million(void **state)
{
	(void)state;
	char chunk[997];
	memset(chunk, 'a', sizeof chunk);
	prsm_sha256 h;
	prsm_sha256_init(&h);
	size_t left = 1000000;
	while (left) {
		size_t n = left < sizeof chunk ? left : sizeof chunk;
		prsm_sha256_update(&h, chunk, n);
		left -= n;
	}
	uint8_t d[PRSM_SHA256_BYTES];
	prsm_sha256_final(&h, d);
	char hex[PRSM_SHA256_HEX];
	prsm_sha256_to_hex(hex, d);
	assert_string_equal(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_known_answers),
		cmocka_unit_test(test_incremental_million),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
