/* The readers before issue 24's port (tests/legacy/), for tests/test_io_doc.c. */
#ifndef PRSM_TESTS_DESIGN_READER_LEGACY_H
#define PRSM_TESTS_DESIGN_READER_LEGACY_H

#include <cJSON.h>

#include "model/design.h"
#include "util/problems.h"

int prsm_legacy_design_from_json(prsm_design *out, const cJSON *doc, const char *base_pointer,
                                 prsm_problems *problems);

#include "model/assembly.h"

int prsm_legacy_assembly_options_from_json(prsm_assembly_options *out, const cJSON *obj,
                                           const char *pointer, const prsm_design *d,
                                           prsm_problems *problems);

#include "io/study_json.h"

void prsm_legacy_study_mc_from_json(prsm_io_study *s, const cJSON *doc, prsm_problems *pr);
void prsm_legacy_study_sensitivity_from_json(prsm_io_study *s, const cJSON *doc, prsm_problems *pr);
/* The whole study reader (study_reader_legacy.c): prsm_io_study_load as it was. */
int prsm_legacy_study_load(prsm_io_study *out, const cJSON *doc, prsm_problems *warnings, prsm_problems *pr);

#endif
