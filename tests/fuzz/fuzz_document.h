/*
 * fuzz_document.h: the body shared by the fuzz targets of the service's job documents
 * (fuzz_study.c, fuzz_optimization.c, fuzz_allocation.c, fuzz_dynamics.c, fuzz_calibration.c). Each
 * target only
 * names its job kind (src/job/kind.h) and the command line's check of the same document.
 *
 * For the bytes of one input, prsm_fuzz_document() follows both readers a document reaches:
 *
 *   the command line  prsm_json_parse (prsm study / optimize / allocate / validate read a file
 *                     this way), the kind's check with the document's own caps, and the
 *                     problems and warnings written back as JSON (prsm validate --format json);
 *   the service       when the command line accepted it: prsm_http_parse_body (POST body),
 *                     the kind's normalise with the service's limits, the canonical JSON of the
 *                     normalised request (RFC 8785) and its cache key, i.e. everything a POST
 *                     does before the job is queued; the 422 problem document otherwise.
 *
 * Nothing may crash, leak, read out of bounds or hit undefined behaviour (run it under
 * ASan+UBSan), and these must hold, else the target abort()s with a message on stderr:
 *
 *   - every problem or warning document written back is valid UTF-8 (it is sent as JSON;
 *     compile with -DPRSM_FUZZ_SKIP_UTF8_CHECK to fuzz past an open bug of this kind; the
 *     utf8-cut-* corpus files are the ones util/utf8.h fixed);
 *   - a normalised request the service accepted is valid I-JSON (its canonical text exists);
 *   - the stored request (the canonical text, read back with cJSON_Parse as a job's run does)
 *     is accepted again by normalise, and its canonical text is the same bytes: the cache key
 *     is a fixed point and a queued job never fails to load its own request.
 *
 * No Monte Carlo run, optimisation, allocation or transient is executed: those are the jobs'
 * work.
 */
#ifndef PRSM_FUZZ_DOCUMENT_H
#define PRSM_FUZZ_DOCUMENT_H

#include <stddef.h>
#include <stdint.h>

#include <cJSON.h>

#include "job/kind.h"
#include "util/problems.h"

/* The command line's check of a document (document caps, warnings kept): 0 or a PRSM_E* code. */
typedef int (*prsm_fuzz_check_fn)(const cJSON *doc, prsm_problems *warnings, prsm_problems *problems);

/* Run one input through both readers of kind (see above). */
void prsm_fuzz_document(const prsm_job_kind *kind, prsm_fuzz_check_fn check, const uint8_t *data,
                        size_t size);

#endif
