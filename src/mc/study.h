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

typedef struct {
	char name[48];                   /* output name with its unit, e.g. "backlash_um" */
	int has_spec;
	prsm_spec spec;
} prsm_study_output;

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
} prsm_study;

void prsm_sens_options_default(prsm_sens_options *s);

/* Per output and tolerance. */
typedef struct {
	double src, srrc;                /* the coefficient when the tolerance has one variable, else NAN */
	double src_percent, srrc_percent;/* 100 x sum of squared coefficients over its variables */
	double stack_um;                 /* one-at-a-time change over its half-widths, summed |.| (output unit) */
	prsm_sobol_index sobol;
} prsm_study_contribution;

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
} prsm_study_output_result;

#define PRSM_STUDY_WARNINGS 8

typedef struct {
	prsm_mc_result run;              /* the samples (inputs, outputs, status) */
	prsm_study_output_result out[PRSM_MC_MAX_OUTPUTS];
	int has_sobol;
	size_t sobol_rows, sobol_rows_ok, sobol_evaluations;
	prsm_sampler_kind sobol_sampler;
	size_t sobol_replicates;         /* randomised-QMC replicates run (Sobol' sampler), else 0 */
	double elapsed_run_s, elapsed_sensitivity_s;
	int n_warnings;
	char warnings[PRSM_STUDY_WARNINGS][256];
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

/* The Saltelli replicates of the study's Sobol phase (randomised-QMC replicates with the Sobol'
 * sampler, else 1), and the engine options of replicate q without a time cap. */
size_t prsm_study_sobol_replicates(const prsm_study *s);
void prsm_study_sobol_options(prsm_mc_options *mo, const prsm_study *s, size_t q);

/* Summaries, SRC/SRRC and stack figures of an existing plain run (used by prsm_study_run and
 * by split runs merged with prsm_mc_result_concat). */
int prsm_study_summarise(prsm_study_result *r, const prsm_study *s, prsm_error *err);

void prsm_study_result_free(prsm_study_result *r);

/* The sd variable v contributes to a linear output along one direction, in its unit: its
 * distribution's sd; for a radial magnitude R with a uniform phase, which moves an output by
 * (dy/dR) R cos(phase), sqrt(E[R^2] / 2). */
double prsm_study_sd_effective(const prsm_study *s, size_t v);

#endif
