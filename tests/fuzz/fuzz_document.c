/*
 * fuzz_document.c: the shared body of the document fuzz targets (see fuzz_document.h).
 */
#include "fuzz_document.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "http/request.h"
#include "io/global.h"
#include "io/analysis_json.h"
#include "io/canonical.h"
#include "io/json_util.h"
#include "job/jobs.h"
#include "util/sha256.h"
#include "util/version.h"

/* An invariant broke: say which, and crash so the fuzzer keeps the input. */
static void broken(const prsm_job_kind *kind, const char *what, const char *detail)
{
	fprintf(stderr, "fuzz %s: %s%s%s\n", kind->name, what, detail ? ": " : "", detail ? detail : "");
	abort();
}

/* The problems and warnings written back as the JSON a response or prsm validate sends; it
 * must be valid UTF-8 (a problem message quotes the document's own text). */
static void write_back(const prsm_job_kind *kind, const prsm_problems *problems, const prsm_problems *warnings)
{
	cJSON *res = prsm_io_problem_document(422, "the request is invalid", problems);
	if (res && warnings)
		cJSON_AddItemToObject(res, "warnings", prsm_io_problems_to_json(warnings));
	char *text = res ? cJSON_PrintUnformatted(res) : NULL;
	cJSON_Delete(res);
	size_t len = text ? strlen(text) : 0, bad = text ? prsm_json_utf8_invalid_at(text, len) : 0;
#ifdef PRSM_FUZZ_SKIP_UTF8_CHECK
	bad = len;
#endif
	if (bad < len) {
		char at[200];
		snprintf(at, sizeof at, "invalid UTF-8 at byte %zu of %.120s", bad, text);
		free(text);
		broken(kind, "the problem document is not valid UTF-8", at);
	}
	free(text);
}

/* The canonical text of a normalised request (*canon, the caller's; NULL when it is not
 * I-JSON or too large, which the service reports as a problem). */
static char *canonical(size_t *len, const cJSON *norm)
{
	char *canon = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_canonical_json(&canon, len, norm, PRSM_JOBS_MAX_REQUEST_BYTES, &err))
		return NULL;
	return canon;
}

/* What prsm_jobs_submit does before it stores the job, and what the job's run reads back. */
static void service(const prsm_job_kind *kind, const uint8_t *data, size_t size)
{
	const prsm_job_limits lim = {200000, 600.0, 1}; /* PRSM_JOBS_OPTIONS_INIT */
	prsm_problems *problems = malloc(sizeof *problems); /* freed below */
	if (!problems)
		return;
	prsm_problems_init(problems);
	cJSON *doc = NULL;
	if (prsm_http_parse_body(&doc, (const char *)data, size, problems)) {
		write_back(kind, problems, NULL);
		free(problems);
		return;
	}
	cJSON *norm = NULL;
	int rc = kind->normalise(&norm, doc, &lim, problems);
	cJSON_Delete(doc);
	if (rc) {
		write_back(kind, problems, NULL);
		free(problems);
		return;
	}
	size_t len = 0;
	char *canon = canonical(&len, norm);
	cJSON_Delete(norm);
	if (!canon)
		broken(kind, "an accepted request has no canonical text", NULL);
	char key[PRSM_SHA256_HEX];
	prsm_jobs_cache_key(key, kind, prsm_engine_build(), canon, len);

	/* the stored request, as the job's run reads it */
	cJSON *stored = cJSON_Parse(canon);
	if (!stored)
		broken(kind, "the stored canonical request does not parse", canon);
	cJSON *again = NULL;
	prsm_problems_init(problems);
	if (kind->normalise(&again, stored, &lim, problems)) {
		char first[PRSM_PROBLEM_POINTER_MAX + PRSM_PROBLEM_MESSAGE_MAX + 240];
		snprintf(first, sizeof first, "%s: %s (request %.200s)", problems->count ? problems->items[0].pointer : "",
		         problems->count ? problems->items[0].message : "", canon);
		broken(kind, "the stored request is refused when read back", first);
	}
	cJSON_Delete(stored);
	size_t len2 = 0;
	char *canon2 = canonical(&len2, again);
	cJSON_Delete(again);
	if (!canon2 || len2 != len || memcmp(canon, canon2, len) != 0)
		broken(kind, "the canonical request is not a fixed point", canon);
	free(canon2);
	free(canon);
	free(problems);
}

void prsm_fuzz_document(const prsm_job_kind *kind, prsm_fuzz_check_fn check, const uint8_t *data,
                        size_t size)
{
	prsm_global_init();
	/* two lists of 64 problems are about 50 KB: on the heap */
	prsm_problems *problems = malloc(sizeof *problems), *warnings = malloc(sizeof *warnings);
	if (!problems || !warnings) {
		free(problems);
		free(warnings);
		return;
	}
	prsm_problems_init(problems);
	prsm_problems_init(warnings);
	int accepted = 0;
	cJSON *doc = prsm_json_parse((const char *)data, size, problems);
	if (doc) {
		accepted = check(doc, warnings, problems) == 0;
		cJSON_Delete(doc);
	}
	write_back(kind, problems, warnings);
	free(problems);
	free(warnings);
	/* the service's limits are tighter than the documents' own: only what the command line
	 * accepts can get past them */
	if (accepted)
		service(kind, data, size);
}
