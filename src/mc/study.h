/*
 * study.h: a tolerance study as typed data, and everything computed from its samples
 * (DESIGN.md, "Documents": study and result).
 *
 * The io layer turns a study document into a prsm_study: the model (a design's assembly or an
 * analytic benchmark), its variables (one per tolerance, per roller for per-roller tolerances,
 * plus a phase variable for radial errors) grouped by tolerance, the outputs with their specs,
 * and the engine and sensitivity settings. prsm_study_run runs the engine and summarises:
 * statistics and yield per output, SRC/SRRC with the fit's R², Sobol indices from a Saltelli
 * run, and worst-case / RSS stack figures from one-at-a-time sensitivities at the centre.
 */
#ifndef PRSM_MC_STUDY_H
#define PRSM_MC_STUDY_H

#include "mc/engine.h"
#include "mc/rare.h"
#include "mc/sens.h"
#include "mc/stats.h"

#define PRSM_STUDY_NAME_MAX 96

typedef struct {
	char name[PRSM_STUDY_NAME_MAX];  /* e.g. "roller[3].pitch_radius_um", "screw.runout_phase_rad" */
	int phase_of;                    /* a phase variable: index of its magnitude; else -1 */
	int phase;                       /* a magnitude with a uniform phase: index of the phase; else -1 */
} prsm_study_varinfo;

typedef struct {
	char name[PRSM_STUDY_NAME_MAX];  /* the tolerance as the study names it */
	size_t first_var, n_vars;        /* its variables: first_var .. first_var + n_vars - 1 */
} prsm_study_group;

/* How a spec's out-of-spec probability is estimated (issue 21 item 4, docs/rare-events.md): mc
 * counts the plain run's samples (the default); auto keeps the count when the plain run saw
 * enough failures on a side for its CoV target and otherwise runs the method
 * prsm_rare_auto_select picks on those counts; the others always run that rare-event method
 * on each side of the spec. */
typedef enum {
	PRSM_STUDY_YIELD_MC = 0,
	PRSM_STUDY_YIELD_AUTO = 1,
	PRSM_STUDY_YIELD_FORM = 2,
	PRSM_STUDY_YIELD_SORM = 3,
	PRSM_STUDY_YIELD_IS = 4,
	PRSM_STUDY_YIELD_SUBSET = 5
} prsm_study_yield_method;

typedef struct {
	char name[48];                   /* output name with its unit, e.g. "backlash_um" */
	int has_spec;
	prsm_spec spec;
	int yield_method;                /* prsm_study_yield_method (mc) */
} prsm_study_output;

/* The document's name of a yield method ("mc", "auto", "form", ...; "mc" for any other value). */
const char *prsm_study_yield_method_name(int yield_method);

/* Settings of the rare-event phase (prsm_study_rare_options_default). */
typedef struct {
	size_t max_evaluations;          /* model evaluations per spec side (20000) */
	double target_cov;               /* IS and auto's projection of plain MC: CoV target (0.1) */
	size_t subset_samples;           /* subset simulation: samples per level (1000) */
} prsm_study_rare_options;

typedef struct {
	int src;                         /* SRC and SRRC (default 1) */
	int sobol;                       /* Sobol indices by a Saltelli run (default 0) */
	size_t sobol_samples;            /* its base rows N: N (groups + 2) evaluations */
	size_t bootstrap;                /* resamples for the Sobol intervals (default 200) */
	prsm_sampler_kind sobol_sampler; /* default sobol (up to 21201 dimensions = 2 x variables) */
	int stack;                       /* worst-case and RSS figures (default 1) */
} prsm_sens_options;

typedef struct {
	prsm_mc_model model;
	size_t d;
	prsm_mc_variable vars[PRSM_MC_MAX_VARIABLES];
	prsm_study_varinfo info[PRSM_MC_MAX_VARIABLES];
	size_t n_groups;
	prsm_study_group groups[PRSM_MC_MAX_GROUPS];
	size_t n_corr;
	prsm_mc_correlation corr[PRSM_MC_MAX_CORRELATIONS];
	size_t m;
	prsm_study_output outputs[PRSM_MC_MAX_OUTPUTS];
	prsm_mc_options mc;
	prsm_sens_options sens;
	prsm_study_rare_options rare;
} prsm_study;

void prsm_sens_options_default(prsm_sens_options *s);
void prsm_study_rare_options_default(prsm_study_rare_options *o);

/* Per output and tolerance. */
typedef struct {
	double src, srrc;                /* the coefficient when the tolerance has one variable, else NAN */
	double src_percent, srrc_percent;/* 100 x sum of squared coefficients over its variables */
	double stack_um;                 /* one-at-a-time change over its half-widths, summed |.| (output unit) */
	prsm_sobol_index sobol;
} prsm_study_contribution;

/* One side of a spec (lower or upper) in the rare-event phase. */
typedef struct {
	int present;                     /* the spec has a limit on this side */
	int ran;                         /* a rare-event method ran; else the counted figure stands */
	prsm_rare_method method;         /* what gave pf: PRSM_RARE_MC is the plain run's count */
	size_t failures, n;              /* the plain run's kept samples beyond this limit, of n */
	double pf;                       /* P(beyond this limit), dimensionless */
	double lower, upper;             /* its 95 % interval (Wilson for a count); NAN for FORM/SORM */
	double cov;                      /* coefficient of variation of pf; NAN when none */
	double beta;                     /* generalised reliability index -Phi^-1(pf) */
	size_t evaluations;              /* model evaluations the method used (0 for a count) */
	int converged;
	prsm_rare_stop stop;
	char note[2 * PRSM_RARE_REASON_MAX]; /* why this method (auto), and how it ended */
	int has_design_point;            /* FORM ran and found one */
	double form_beta;                /* FORM's reliability index */
	double importance[PRSM_MC_MAX_GROUPS]; /* FORM's importance by variable summed over each
	                                    tolerance's variables, dimensionless (sum 1) */
	double *x_star;                  /* d: the design point in the variables' units (NULL if none) */
} prsm_study_rare_side;

typedef struct {
	prsm_stats_summary summary;
	int has_src;
	double src_r2, srrc_r2;
	int has_stack;
	double nominal;                  /* the model at the centre of every distribution */
	double worst_low, worst_high;    /* nominal -/+ sum of |one-at-a-time changes| */
	double rss;                      /* RSS half-width: 3 sqrt(sum (change_i sd_i / T_i)^2), each
	                                    tolerance's own sd (prsm_study_sd_effective), T_i its
	                                    half-width: the 3-sigma range of the linear stack */
	int has_sobol;
	double sobol_variance;
	prsm_study_contribution by_group[PRSM_MC_MAX_GROUPS];
	int has_rare;                    /* the spec asked for a yield method other than mc */
	prsm_study_rare_side rare[2];    /* [0] below the lower limit, [1] above the upper */
	double rare_ppm, rare_ppm_low95, rare_ppm_high95; /* out of spec, per million: the sum of the
	                                    sides' estimates and of their interval ends (NAN when a
	                                    side has no interval) */
	int rare_ppm_from_rare;          /* a rare-event method (not only the count) gave a side */
} prsm_study_output_result;

#define PRSM_STUDY_WARNINGS 8

/* A probability counted from the kept samples, with its 95 % Wilson interval. */
typedef struct {
	size_t count, n;                 /* samples with the event, kept samples */
	double p, low95, high95;         /* count / n and the Wilson interval (z = PRSM_STATS_Z95) */
} prsm_study_probability;

/* The dynamic outputs' summary (MODEL-DYNAMICS.md §8.6; a study with the outputs contact_loss,
 * regime and integrated): P(contact loss), P(non-periodic: regime 0), and the screen's count. */
typedef struct {
	int present;
	prsm_study_probability contact_loss, non_periodic;
	size_t screened;                 /* kept samples whose outputs are the linear closed form */
	size_t integrated;               /* kept samples integrated after the screen found contact loss */
	size_t failed;                   /* failed samples other than no_play (an integration or a closed
	                                    form that failed) */
	size_t no_play;                  /* failed samples without axial play (backlash <= 0: the thread
	                                    model of §8.3.2 needs b_a > 0; fail code PRSM_EGEOMETRY) */
} prsm_study_dynamics;

/* The dynamics summary of a run whose outputs (names) include contact_loss, regime and
 * integrated; present 0 otherwise. */
void prsm_study_dynamics_summary(prsm_study_dynamics *out, const prsm_study *s, const prsm_mc_result *run);

typedef struct {
	prsm_mc_result run;              /* the samples (inputs, outputs, status) */
	size_t rare_outputs;             /* out[0 .. rare_outputs - 1] may hold rare-event design
	                                    points (prsm_study_rare), freed by prsm_study_result_free */
	prsm_study_output_result out[PRSM_MC_MAX_OUTPUTS];
	int has_sobol;
	size_t sobol_rows, sobol_rows_ok, sobol_evaluations;
	prsm_sampler_kind sobol_sampler;
	size_t sobol_replicates;         /* randomised-QMC replicates run (Sobol' sampler), else 0 */
	double elapsed_run_s, elapsed_sensitivity_s;
	int n_warnings;
	char warnings[PRSM_STUDY_WARNINGS][256];
	prsm_study_dynamics dynamics;    /* the dynamic outputs' probabilities and screen (present 0: none) */
} prsm_study_result;

/* Run the study and summarise it. Allocates inside *r (free with prsm_study_result_free).
 * Returns 0; PRSM_EINVAL for settings the engine refuses; the model's code (exit 2) when the
 * failure policy stops the run, with err naming the sample or the failed fraction. */
int prsm_study_run(prsm_study_result *r, const prsm_study *s, prsm_error *err);

/* Who runs a study's engine runs: prsm_study_run_with calls these instead of the engine (a
 * caller that spreads the runs over processes, src/par). run: the plain run, as prsm_mc_run(out,
 * &s->model, ..., &s->mc, err) would return it. replicate: Saltelli replicate q of the Sobol
 * phase (prsm_study_sobol_replicates), with the options mo (prsm_study_sobol_options and the time
 * left), as prsm_mc_run_saltelli would return it. Either may be NULL: the engine's. */
typedef struct {
	int (*run)(prsm_mc_result *out, const prsm_study *s, void *ctx, prsm_error *err);
	int (*replicate)(prsm_mc_result *out, const prsm_study *s, size_t q, const prsm_mc_options *mo, void *ctx,
	                 prsm_error *err);
	void *ctx;
} prsm_study_runner;

/* prsm_study_run with the engine runs made by runner (NULL: prsm_study_run). */
int prsm_study_run_with(prsm_study_result *r, const prsm_study *s, const prsm_study_runner *runner,
                        prsm_error *err);

/* Who runs a caller's whole studies (opt/: an allocation's Monte Carlo corrections, the robust
 * constraints' studies): run is called instead of prsm_study_run, with the study document s was
 * loaded from (source, source_len bytes of JSON text: the study reader gives the same model from
 * it in any process) while s itself carries the settings the caller changed since (the
 * distributions, specs, targets, sensitivities: the struct's plain fields). src/par runs them
 * over the ranks of an MPI job, with prsm_study_run's result. NULL: this process. */
typedef struct {
	int (*run)(prsm_study_result *r, const prsm_study *s, const char *source, size_t source_len, void *ctx,
	           prsm_error *err);
	void *ctx;
} prsm_study_service;

/* Take the settings of `from` (the same study document's study, as its caller changed it: in
 * another process, say) into `mine`: every plain field; mine's own model and histogram bins kept
 * (the same, loaded from the same document); none of from's pointers (cancel, progress) kept.
 * Returns 0, or PRSM_EINVAL with err when the two differ in their sizes (variables, outputs,
 * tolerances) or in which variables are histograms. */
int prsm_study_adopt(prsm_study *mine, const prsm_study *from, prsm_error *err);

/* prsm_study_run through svc: svc->run when svc, its run and source are set, else prsm_study_run. */
int prsm_study_service_run(const prsm_study_service *svc, prsm_study_result *r, const prsm_study *s,
                           const char *source, size_t source_len, prsm_error *err);

/* The Saltelli replicates of the study's Sobol phase (randomised-QMC replicates with the Sobol'
 * sampler, else 1), and the engine options of replicate q without a time cap. */
size_t prsm_study_sobol_replicates(const prsm_study *s);
void prsm_study_sobol_options(prsm_mc_options *mo, const prsm_study *s, size_t q);

/* Progress of a study's phases: each engine run's reports relayed with the phase's name, its
 * unit when it is not samples, and (planned > 0) counts offset into the phase's own total. */
typedef struct {
	prsm_progress_fn fn;
	void *ctx;
	const char *phase;               /* "monte_carlo", "rare_events", "sobol" */
	const char *unit;                /* NULL: samples */
	size_t offset, planned;          /* planned 0: the run's own counts */
} prsm_study_progress_relay;

void prsm_study_progress_relay_fn(void *ctx, const prsm_progress *p);

/* The rare-event phase of prsm_study_run: for every output whose spec asks for a yield method
 * other than mc, each side's probability from the plain run's counts or a rare-event method
 * (src/mc/study_rare.c). deadline_s: the study's time cap as a prsm_clock_seconds() time, 0 for
 * none. Returns 0, or the rare engine's error (err names the output and side). */
int prsm_study_rare(prsm_study_result *r, const prsm_study *s, double deadline_s, prsm_error *err);

/* Summaries, SRC/SRRC and stack figures of an existing plain run (used by prsm_study_run and
 * by split runs merged with prsm_mc_result_concat). */
int prsm_study_summarise(prsm_study_result *r, const prsm_study *s, prsm_error *err);

void prsm_study_result_free(prsm_study_result *r);

/* The sd variable v contributes to a linear output along one direction, in its unit: its
 * distribution's sd; for a radial magnitude R with a uniform phase, which moves an output by
 * (dy/dR) R cos(phase), sqrt(E[R^2] / 2). */
double prsm_study_sd_effective(const prsm_study *s, size_t v);

#endif
