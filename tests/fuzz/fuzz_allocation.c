/*
 * fuzz_allocation.c: a libFuzzer-style target (LLVMFuzzerTestOneInput) for the
 * tolerance-allocation document (schemas/allocation.schema.json, POST /v1/allocations,
 * prsm allocate): the bytes through the command line's check (prsm_app_allocation_check with
 * the document's caps: the embedded study or the analytic stack, costs, bounds, constraints,
 * the linearisation and the linear allocation at f = 1) and, when accepted, the service's
 * (normalise with its limits, canonical request, cache key, the stored request read back).
 * No Monte Carlo verification is run. See fuzz_document.h. Corpus: corpus/allocation/.
 */
#include <stdint.h>

#include "fuzz_document.h"
#include "app/allocate.h"
#include "io/allocation_json.h"

static int allocation_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	return prsm_app_allocation_check(doc, 0, warnings, problems);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	prsm_fuzz_document(&prsm_job_kind_allocation, allocation_check, data, size);
	return 0;
}
