/*
 * test_io_defaults.c: every annotated schema's "default"s are what the C init functions set
 * (issue 24). scripts/gen-io-tables.py writes prsm_io_defaults_<table>() for each table whose
 * struct has a hand-written init function, and prsm_io_defaults_all() to run them all; a table
 * added later is checked without a change here.
 */
#include "test_support.h"

#include "io/global.h"
#include "util/problems.h"

int prsm_io_defaults_all(prsm_problems *problems);

static void test_schema_defaults(void **state)
{
	(void)state;
	prsm_problems p;
	prsm_problems_init(&p);
	const int bad = prsm_io_defaults_all(&p);
	for (int k = 0; k < p.count; k++)
		print_error("%s: %s\n", p.items[k].pointer, p.items[k].message);
	assert_int_equal(bad, 0);
	assert_int_equal(p.count, 0);
}

int main(void)
{
	prsm_global_init();
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_schema_defaults),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
