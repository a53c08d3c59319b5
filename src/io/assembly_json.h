/*
 * assembly_json.h: the error analysis of one error set (docs/model/errors-and-assembly.md) as the `assembly`
 * member of the analyze result, and as a section of the text summary. Units in every name:
 * um, N, N/um, deg, mm, cycles per screw revolution (per_rev), Hz at the operating speed.
 */
#ifndef PRSM_IO_ASSEMBLY_JSON_H
#define PRSM_IO_ASSEMBLY_JSON_H

#include <cJSON.h>
#include <stdio.h>

#include "model/assembly_report.h"

/* Build the object; caller owns it. ws is the workspace prsm_assembly_analyse() filled (the
 * TE record, the spectrum and the gaps at theta = 0, reported when o->curve is set). */
cJSON *prsm_io_assembly_to_json(const prsm_assembly_report *r, const prsm_assembly *as,
                                const prsm_assembly_options *o, const prsm_assembly_workspace *ws);

#endif
