/* The optimisation and allocation readers before issue 24's port (tests/legacy/), for
 * tests/test_io_doc.c. Each fills the same struct as today's reader; the structs are freed by
 * today's functions (prsm_io_allocation_free, prsm_io_optimization_release). */
#ifndef PRSM_TESTS_OPT_ALLOC_READER_LEGACY_H
#define PRSM_TESTS_OPT_ALLOC_READER_LEGACY_H

#include <cJSON.h>

#include "io/allocation_json.h"
#include "io/optimization_json.h"
#include "util/problems.h"

/* prsm_io_allocation_read as it was (allocation_reader_legacy.c). */
int prsm_legacy_allocation_read(prsm_io_allocation **out, const cJSON *doc, size_t max_samples,
                                prsm_problems *warnings, prsm_problems *problems);
/* prsm_io_optimization_read as it was (optimization_reader_legacy.c). */
int prsm_legacy_optimization_read(prsm_io_optimization *od, const cJSON *doc, size_t max_evaluations,
                                  prsm_problems *warnings, prsm_problems *problems);

#endif
