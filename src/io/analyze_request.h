/*
 * analyze_request.h: the analyze request (schemas/analyze-request.schema.json) from JSON to its
 * result, shared by `prsm analyze`/`prsm validate` and the service's POST /v1/designs/analyze.
 *
 * A request is a design document alone (the nominal and operating-point analysis), a
 * multi-stage design ({"stages": [...]}, docs/model/kinematics-efficiency-stiffness-life.md) or {"design", "errors", "assembly"} (the
 * analysis and the error analysis of docs/model/errors-and-assembly.md for one concrete error set);
 * app/analyze.h runs what is read here. The
 * last two forms may carry the `dynamics` object of a start-up transient (schemas/dynamics.schema.json):
 * it is read and checked here with every other problem, and run by app/simulate.h (`prsm
 * simulate`); the analysis itself stays the statics and says so in a warning. Every problem of the document is reported at once, with its JSON pointer; the
 * contact solver's findings (an edge contact, no contact point) are problems too, at the
 * pointer of the design's geometry.
 */
#ifndef PRSM_IO_ANALYZE_REQUEST_H
#define PRSM_IO_ANALYZE_REQUEST_H

#include <stdio.h>

#include <cJSON.h>

#include "dyn/dyn.h"
#include "model/analysis.h"
#include "model/assembly.h"
#include "model/assembly_report.h"
#include "model/design.h"
#include "model/errors.h"
#include "model/nominal.h"
#include "model/performance.h"
#include "io/stages_json.h"
#include "util/problems.h"

/* One alternative of a catalogue size: the same diameter and lead with other starts (nominal.h). */
typedef struct {
	int starts;                 /* n */
	double pitch_mm;            /* P = L / n, mm */
	double roller_radius_mm;    /* r_r, mm */
	int rollers, engaged_threads; /* Z, n_t */
	int valid;                  /* 1 when the design analyses; 0: problem says why */
	char problem[PRSM_PROBLEM_MESSAGE_MAX]; /* the first problem of an invalid one */
	double makers_C0a_N, makers_C_a_N, makers_ratio; /* makers' convention, N, N, - */
	double C0a_N, C_a_N;        /* load distribution (truncation-limited C_0a), N */
	int truncated;              /* the ellipse truncation limits C_0a */
} prsm_io_nominal_alternative;

/* What the result's `nominal` member shows (schemas/analysis.schema.json $defs/nominal_result). */
typedef struct {
	prsm_nominal given;                       /* as the document gave it (0: by the rules) */
	prsm_nominal_geometry resolved;           /* the geometry the analysis used */
	double beta_rad, clearance_mm;            /* the flank angle, rad, and running clearance, mm, it
	                                             was resolved with (the alternatives use them too) */
	prsm_io_nominal_alternative alternatives[PRSM_NOMINAL_ALTERNATIVES]; /* starts 3 to 6 */
	int n_alternatives;
} prsm_io_nominal_result;

typedef struct {
	int multistage;                /* the multi-stage form (docs/model/kinematics-efficiency-stiffness-life.md): only ms is set */
	prsm_io_multistage *ms;        /* its stages and chain, owned here */
	prsm_performance ms_perf[PRSM_STAGES_MAX]; /* each stage's operating-point analysis */
	prsm_design d;                 /* the resolved design (thinning solved when asked) */
	prsm_analysis a;               /* its nominal analysis */
	prsm_performance perf;         /* its operating-point analysis (docs/model/kinematics-efficiency-stiffness-life.md) */
	int with_errors;               /* the request form with errors and/or assembly */
	prsm_errors errors;            /* the error set (with_errors) */
	prsm_assembly_options options; /* error-analysis options (with_errors) */
	prsm_assembly as;              /* the assembly built from the design (with_errors) */
	prsm_assembly_report report;   /* the error analysis, after prsm_app_analyze_run */
	prsm_assembly_workspace *ws;   /* its buffers, owned here (prsm_io_analyze_free) */
	int with_nominal;              /* the design gave `nominal` (a catalogue size) */
	prsm_io_nominal_result nominal; /* its resolution and alternatives (with_nominal) */
	int with_dynamics;             /* the request has a `dynamics` object (docs/dynamics.md) */
	prsm_dyn_options dyn;          /* its options, read and checked (with_dynamics; a chain's
	                                  couplings copied from the multi-stage document) */
} prsm_analyze_request;

/* A document of another kind, told by its keys (as `prsm validate` tells them apart): a
 * problem naming the command that runs it, instead of a list of unknown fields. Returns 1
 * when it is one. */
int prsm_io_analyze_wrong_kind(const cJSON *doc, prsm_problems *problems);

/* Read a request of the single-design forms (a design document, or {"design", "errors",
 * "assembly", "dynamics"}) into rq, zeroed by the caller; nothing is analysed. Problems of the
 * document go to problems, rule warnings to warnings. Returns 0 or PRSM_EINVAL / PRSM_EGEOMETRY
 * (prsm_io_design_load's codes). The analysis is prsm_app_analyze_load's (app/analyze.h). */
int prsm_io_analyze_read(prsm_analyze_request *rq, const cJSON *doc, prsm_problems *warnings,
                         prsm_problems *problems);

/* The `dynamics` object of a multi-stage request whose chain rq->ms was read (and analysed
 * when that succeeded) with code rc: read for the stages the document has, with the chain's
 * couplings copied into rq->dyn. Returns rc, or PRSM_EINVAL when rc was 0 and the object has
 * problems. */
int prsm_io_analyze_read_chain_dynamics(prsm_analyze_request *rq, const cJSON *doc, int rc,
                                        prsm_problems *problems);

/* The result document of a loaded and run request (app/analyze.h); the caller owns it. NULL
 * when out of memory. A request with `dynamics` gets a warning at /dynamics that the transient
 * was not run. */
cJSON *prsm_io_analyze_to_json(const prsm_analyze_request *rq, const prsm_problems *warnings);

/* Free what rq owns (not rq itself). */
void prsm_io_analyze_free(prsm_analyze_request *rq);

/* A copy of design with `nominal` replaced by the geometry g resolves it to; NULL when out of
 * memory. The caller owns it. */
cJSON *prsm_io_nominal_expanded(const cJSON *design, const prsm_nominal_geometry *g);

/* prsm_io_design_load for a design document that may give its geometry as a catalogue size
 * (`nominal`: diameter x lead, resolved by the standard rules, model/nominal.h): the design at
 * base is read with the geometry the rules give, every problem of a geometry member the size
 * set is reported at the nominal member the user wrote. nominal (may be NULL) gets the size as
 * given and its resolution (the alternatives with 3 to 6 starts are analysed by
 * prsm_app_analyze_load). Without `nominal` it is prsm_io_design_load. Returns its codes, or
 * PRSM_ENOMEM. */
int prsm_io_design_load_sized(prsm_design *out, prsm_geometry *geom, prsm_problems *warnings, const cJSON *design,
                              const char *base, prsm_problems *problems, prsm_io_nominal_result *nominal);

#endif
