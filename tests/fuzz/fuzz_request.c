/*
 * fuzz_request.c: a libFuzzer-style target (LLVMFuzzerTestOneInput) for the service's request
 * parser: the bytes as a request body (prsm_http_parse_body: UTF-8, JSON, duplicate members,
 * an object at the top), then, for a document, both readers a POST reaches — the study
 * kind's validation with the service's limits and the synchronous analysis — and the
 * canonical JSON of what parsed; the bytes also as header values (framing, media type,
 * token, a form's boundary) and as a calibration form (multipart/form-data, boundary "b"). Nothing may crash, leak or read out of bounds; run it under ASan.
 *
 * Built by CMake as fuzz_request_replay (with replay.c: every corpus file once, a CTest
 * test) and, when the compiler is clang, as fuzz_request (libFuzzer).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "http/request.h"
#include "io/global.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/canonical.h"
#include "job/kind.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	prsm_global_init();
	const char *body = (const char *)data;
	prsm_problems problems;
	prsm_problems_init(&problems);
	cJSON *doc = NULL;
	int status = prsm_http_parse_body(&doc, body, size, &problems);
	if (status == 0 && doc) {
		prsm_job_limits lim = {20000, 10.0, 1};
		cJSON *norm = NULL;
		prsm_problems_init(&problems);
		if (prsm_job_kind_study.normalise(&norm, doc, &lim, &problems) == 0) {
			char *canon = NULL;
			prsm_error err = PRSM_ERROR_INIT;
			prsm_canonical_json(&canon, NULL, norm, 1u << 22, &err);
			free(canon);
		}
		cJSON_Delete(norm);
		prsm_problems_init(&problems);
		cJSON *out = NULL;
		prsm_app_analyze(&out, doc, &problems);
		cJSON_Delete(out);
		cJSON_Delete(doc);
	}
	/* the same bytes as header values (NUL-terminated copy, at most 4 KiB) */
	char header[4097];
	size_t n = size < sizeof header - 1 ? size : sizeof header - 1;
	memcpy(header, data, n);
	header[n] = '\0';
	prsm_problems_init(&problems);
	prsm_http_check_framing(1, header, 0, &problems);
	prsm_http_is_json_type(header);
	prsm_http_bearer_ok(header, "token");
	char boundary[PRSM_HTTP_BOUNDARY_MAX + 1];
	prsm_http_multipart_boundary(header, boundary, sizeof boundary);
	/* the bytes as a calibration form with the boundary "b" (the corpus' form-*.txt seeds) */
	prsm_problems_init(&problems);
	cJSON *form = NULL;
	if (prsm_http_calibration_form(&form, body, size, "b", &problems) == 0)
		cJSON_Delete(form);
	return 0;
}
