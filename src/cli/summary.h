/*
 * summary.h: the text summary of an analyze request (prsm analyze --format text).
 */
#ifndef PRSM_CLI_SUMMARY_H
#define PRSM_CLI_SUMMARY_H

#include <stdio.h>

#include "io/analyze_request.h"

/* The engineer's one-page summary of a loaded and run request. */
void prsm_cli_print_analyze(FILE *out, const prsm_analyze_request *rq, const prsm_problems *warnings);

#endif
