/*
 * validate.h: reading any request document as the command that runs it reads it, without
 * running it (prsm validate, POST /v1/validate; schemas/validation.schema.json). The document's
 * kind is found from its members: an allocation (allocate), an optimisation (variables and
 * objectives), a study (tolerances), a calibration request (measured, or dynamics.analysis
 * "calibrate"), a simulation request (dynamics), else a design or analyze request.
 */
#ifndef PRSM_APP_VALIDATE_H
#define PRSM_APP_VALIDATE_H

#include <cJSON.h>

#include "util/problems.h"

typedef enum {
	PRSM_DOC_DESIGN,       /* a design or an analyze request (prsm analyze) */
	PRSM_DOC_STUDY,        /* prsm study */
	PRSM_DOC_OPTIMIZATION, /* prsm optimize */
	PRSM_DOC_ALLOCATION,   /* prsm allocate */
	PRSM_DOC_SIMULATION,   /* prsm simulate */
	PRSM_DOC_CALIBRATION   /* prsm calibrate */
} prsm_doc_kind;

/* The kind of doc (an object; anything else reads as a design, whose reader says what is
 * wrong), or PRSM_DOC_CALIBRATION whenever a measured curve file comes with it (csv_given). */
prsm_doc_kind prsm_app_doc_kind(const cJSON *doc, int csv_given);

/* The kind's name as the validation result gives it ("design", "study", ...). */
const char *prsm_app_doc_kind_name(prsm_doc_kind k);

/* Read doc as its kind's command does (a calibration with the TE curve of the CSV file csv_path,
 * NULL: none): every problem to problems with its JSON pointer, the rule warnings to warnings.
 * *kind (may be NULL) gets the kind read. Returns 0 (valid), PRSM_EINVAL, or the error of a
 * design that cannot be analysed (PRSM_EGEOMETRY, PRSM_EEDGE), PRSM_ENOMEM. */
int prsm_app_validate(const cJSON *doc, const char *csv_path, prsm_doc_kind *kind, prsm_problems *warnings,
                      prsm_problems *problems);

/* The validation result (schemas/validation.schema.json) of a read that returned rc; NULL when
 * out of memory. */
cJSON *prsm_app_validation_to_json(int rc, prsm_doc_kind kind, const prsm_problems *warnings,
                                   const prsm_problems *problems);

#endif
