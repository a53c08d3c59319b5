/*
 * fuzz_optimization.c: a libFuzzer-style target (LLVMFuzzerTestOneInput) for the
 * design-optimisation document (schemas/optimization.schema.json, POST /v1/optimizations,
 * prsm optimize): the bytes through the command line's check (prsm_app_optimization_check with
 * the document's caps: base design, variables, objectives, constraints, solver, robust
 * section, the feasibility scan of the integer levels) and, when accepted, the service's
 * (normalise with its limits, canonical request, cache key, the stored request read back).
 * No optimisation is run. See fuzz_document.h. Corpus: corpus/optimization/.
 */
#include <stdint.h>

#include "fuzz_document.h"
#include "app/optimize.h"
#include "io/optimization_json.h"

static int optimization_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	return prsm_app_optimization_check(doc, 0, warnings, problems);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	prsm_fuzz_document(&prsm_job_kind_optimization, optimization_check, data, size);
	return 0;
}
