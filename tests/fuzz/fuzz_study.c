/*
 * fuzz_study.c: a libFuzzer-style target (LLVMFuzzerTestOneInput) for the tolerance-study
 * document (schemas/study.schema.json, POST /v1/studies, prsm study): the bytes through the
 * command line's reader (prsm_app_study_load with the document's caps) and, when accepted, the
 * service's (normalise with its limits, canonical request, cache key, the stored request read
 * back). See fuzz_document.h for what must hold. Corpus: corpus/study/.
 */
#include <stdint.h>
#include <stdlib.h>

#include "fuzz_document.h"
#include "app/study.h"
#include "io/study_json.h"
#include "util/error.h"

static int study_check(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems)
{
	prsm_io_study *s = calloc(1, sizeof *s); /* about 1 MB; freed below */
	if (!s)
		return PRSM_ENOMEM;
	int rc = prsm_app_study_load(s, doc, warnings, problems);
	free(s);
	return rc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	prsm_fuzz_document(&prsm_job_kind_study, study_check, data, size);
	return 0;
}
