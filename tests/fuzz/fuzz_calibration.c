/*
 * fuzz_calibration.c: a libFuzzer-style target (LLVMFuzzerTestOneInput) for the calibration
 * request (schemas/measured-request.schema.json; POST /v1/calibrations, prsm calibrate): the bytes
 * through the command line's reader (prsm_app_calibration_load: the design, the measured
 * section with its curve, the calibrate settings) and, when accepted, the service's (normalise,
 * canonical request, cache key, the stored request read back). No calibration is computed. See
 * fuzz_document.h for what must hold. Corpus: corpus/calibration/.
 */
#include <stdint.h>

#include "fuzz_document.h"
#include "app/calibrate.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The command line's check: the request read and checked, nothing computed. */
static int calibration_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	(void)warnings;
	prsm_app_calibration *c = NULL;
	int rc = prsm_app_calibration_load(&c, doc, NULL, problems);
	prsm_app_calibration_free(c);
	return rc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	prsm_fuzz_document(&prsm_job_kind_calibration, calibration_check, data, size);
	return 0;
}
