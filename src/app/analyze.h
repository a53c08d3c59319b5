/*
 * analyze.h: running an analyze request (schemas/analyze-request.schema.json), shared by
 * `prsm analyze`/`prsm validate` and the service's POST /v1/designs/analyze: read by
 * io/analyze_request.h (or io/stages_json.h for a chain), analysed here (the nominal analysis,
 * the operating point, a catalogue size's alternatives, the error analysis, a chain's stage
 * loads), written by io/analyze_request.h.
 *
 * The analysis's findings are problems of the document like the reader's, in the same list
 * and in the order the reading meets them: the contact solver's (an edge contact, no contact
 * point) at the pointer of the design's geometry, a failed operating point at its setting.
 */
#ifndef PRSM_APP_ANALYZE_H
#define PRSM_APP_ANALYZE_H

#include <cJSON.h>

#include "io/analyze_request.h"
#include "io/stages_json.h"
#include "util/problems.h"

/* Read the request doc (not taken over) into rq and run the nominal analysis. Problems of the
 * document and of the nominal contacts go to problems, rule and analysis warnings to
 * warnings. Returns 0, PRSM_EINVAL (the document), PRSM_EEDGE or PRSM_EGEOMETRY (the design
 * cannot work) or PRSM_ENOMEM. rq is zeroed first; free it with prsm_io_analyze_free. */
int prsm_app_analyze_load(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                          prsm_problems *problems);

/* The error analysis of a loaded request with errors (nothing to do without them); allocates
 * rq->ws. Returns 0, PRSM_ENOMEM, or PRSM_ECANCELLED when rq->options.cancel or
 * rq->options.deadline_s stopped it (the report is then incomplete). */
int prsm_app_analyze_run(prsm_analyze_request *rq);

/* What prsm_app_analyze_run will cost a loaded request, in contact-gap evaluations
 * (prsm_assembly_cost; 0 without an error analysis): the service's synchronous budget. */
double prsm_app_analyze_cost(const prsm_analyze_request *rq);

/* Everything in one call, for a service: load, run and build the result (*out, owned by the
 * caller) or fill problems. Returns 0 or the code of prsm_app_analyze_load/run. */
int prsm_app_analyze(cJSON **out, const cJSON *doc, prsm_problems *problems);

/* Read (prsm_io_multistage_read) and analyse the multi-stage document: each stage alone (its
 * contacts on the flanks), the chain's stage loads, each stage at the load it carries. Every
 * problem with its pointer; rule and analysis warnings of the stages to warnings. Returns 0,
 * PRSM_EINVAL, PRSM_EGEOMETRY or PRSM_EEDGE. */
int prsm_app_multistage_load(prsm_io_multistage *out, const cJSON *doc, prsm_problems *warnings,
                             prsm_problems *problems);

#endif
