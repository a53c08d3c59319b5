/*
 * test_case_a_fixture.h: the vibration tests' fixture (test_vib_reduced, test_vib_mc):
 * studies/case-a.json read as a design with its operating point and analysed, once per group.
 */
#ifndef PRSM_TEST_CASE_A_FIXTURE_H
#define PRSM_TEST_CASE_A_FIXTURE_H

#include "test_support.h"

#include <stdlib.h>

#include "io/design_json.h"
#include "model/analysis.h"

typedef struct {
	prsm_design d;
	prsm_analysis a;
} case_fixture;

static case_fixture *fx;

static int setup(void **state)
{
	(void)state;
	fx = calloc(1, sizeof *fx);
	if (fx == NULL)
		return -1;
	cJSON *doc = prsm_test_read_study("case-a.json");
	prsm_geometry g;
	prsm_problems pr;
	prsm_problems_init(&pr);
	if (prsm_io_design_load(&fx->d, &g, NULL, doc, "", &pr))
		return -1;
	prsm_io_operating_point_from_json(&fx->d, doc, "", &pr);
	cJSON_Delete(doc);
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_analysis_nominal(&fx->a, &fx->d, &pr, &err))
		return -1;
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	free(fx);
	return 0;
}

#endif
