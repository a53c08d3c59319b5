/*
 * fuzz_dynamics.c: a libFuzzer-style target (LLVMFuzzerTestOneInput) for the simulation request
 * (schemas/simulation.schema.json with its dynamics object, schemas/dynamics.schema.json;
 * POST /v1/simulations, prsm simulate): the bytes through the command line's check
 * (prsm_app_simulation_check: the design or chain with its statics, the dynamics object's table
 * and hooks, the model and its settled state) and, when accepted, the service's (normalise with
 * its cap on output times, canonical request, cache key, the stored request read back). No
 * transient is integrated. See fuzz_document.h for what must hold. Corpus: corpus/dynamics/.
 */
#include <stdint.h>

#include "fuzz_document.h"
#include "app/simulate.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	prsm_fuzz_document(&prsm_job_kind_simulation, prsm_app_simulation_check, data, size);
	return 0;
}
