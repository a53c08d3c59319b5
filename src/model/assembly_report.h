/*
 * assembly_report.h: everything the error analysis of one concrete error set reports
 * (docs/model/errors-and-assembly.md): gaps and backlash over a revolution, load sharing and stiffness at the
 * operating load, transmission error over a revolution and a stroke, its spectrum with the
 * named frequencies. Also the signal helpers the TE statistics use.
 */
#ifndef PRSM_MODEL_ASSEMBLY_REPORT_H
#define PRSM_MODEL_ASSEMBLY_REPORT_H

#include "model/assembly.h"

/* Caller-owned buffers; sizes from prsm_assembly_record_length(). */
typedef struct {
	prsm_assembly_gaps plus, minus; /* gaps of the two load directions at one angle */
	double *te_mm;                  /* TE record: record_length values */
	double *spectrum_mm;            /* fft_length values; on return the amplitude spectrum in the
	                                   first spectrum_bins */
} prsm_assembly_workspace;

typedef struct {
	int mode;                       /* PRSM_MODE_* used */
	int angles_per_revolution;
	/* at theta = 0 */
	double backlash_mm, backlash_plus_mm, backlash_minus_mm;
	double gap_min_mm[2][2], gap_max_mm[2][2]; /* [side][dir] over rollers and threads */
	/* over one screw revolution */
	double backlash_min_mm, backlash_max_mm, backlash_mean_mm;
	double sharing_factor_max;      /* worst load-sharing factor over the revolution */
	/* at the operating load, theta = 0, "+" direction */
	prsm_assembly_state operating;
	double stiffness_ratio;         /* dF/du over its value with nominal gaps */
	/* transmission error at the measuring load, "+" direction (docs/model/errors-and-assembly.md) */
	double measuring_load_N;
	double te_revolution_pp_mm, te_revolution_rms_mm; /* first screw revolution */
	int has_stroke;
	double stroke_mm;
	double te_stroke_pp_mm, te_stroke_rms_mm;   /* whole stroke, raw (rms about the mean) */
	double lead_deviation;                     /* least-squares slope of TE on travel, mm/mm */
	double te_stroke_residual_pp_mm;           /* peak-to-peak after removing that line */
	int record_length;              /* TE samples computed */
	double record_revolutions;      /* revolutions the spectrum is taken from */
	prsm_assembly_frequencies frequencies;
	double line_amplitude_mm[5];    /* at the named frequencies, in prsm_assembly_frequencies order */
	double peak_frequency_per_rev, peak_amplitude_mm; /* strongest line of the spectrum */
	int spectrum_bins;              /* bins of spectrum_mm, bin b at b spectrum_step_per_rev */
	double spectrum_step_per_rev;   /* bin spacing, cycles per screw revolution */
	int edge_contacts, failed_contacts; /* summed over every evaluation (exact mode); failed also
	                                     * counts elastic solves that did not converge (§9) */
} prsm_assembly_report;

/* Samples of the TE record, and the zero-padded FFT length of its spectrum (a power of two). */
void prsm_assembly_record_length(int *record_length, int *fft_length, const prsm_assembly *as,
                                 const prsm_assembly_options *o);

/* The work of prsm_assembly_analyse in linear-mode contact-gap evaluations (one flank gap of one
 * thread of one roller at one screw angle; an exact-mode gap, which solves the contact point,
 * counts PRSM_ASSEMBLY_EXACT_COST of them: measured 1.8e6 exact against 3.4e7 linear gaps per
 * second on case A): what a service budgets synchronous requests by. */
#define PRSM_ASSEMBLY_EXACT_COST 16.0
double prsm_assembly_cost(const prsm_assembly *as, const prsm_assembly_options *o);

/* The whole error analysis of error set e (docs/model/errors-and-assembly.md). ws buffers sized by
 * prsm_assembly_record_length(). Returns 0, or PRSM_ECANCELLED when o->cancel was raised or
 * o->deadline_s passed (checked every PRSM_ASSEMBLY_STOP_EVERY angles; r is then incomplete). */
#define PRSM_ASSEMBLY_STOP_EVERY 32
int prsm_assembly_analyse(prsm_assembly_report *r, const prsm_assembly *as, const prsm_errors *e,
                          const prsm_assembly_options *o, prsm_assembly_workspace *ws);

/* TE record: u(theta_i) - u(0) at theta_i = i dtheta (rad), i < n, load F_N, "+" direction.
 * Adds edge/failed contact counts to *edge, *failed (may be NULL). Returns 0. */
int prsm_assembly_te_record(double *te_mm, int n, double dtheta_rad, const prsm_assembly *as,
                            const prsm_errors *e, int mode, double F_N, prsm_assembly_gaps *ws,
                            int *edge, int *failed);

/* Signal helpers on a record x[0..n) sampled `per_rev` times per screw revolution. */
/* Least-squares line x ~ a + b i; writes a, b (per sample). */
void prsm_signal_fit_line(double *a, double *b, const double *x, int n);
/* Peak-to-peak and RMS about the mean. */
void prsm_signal_pp_rms(double *pp, double *rms, const double *x, int n);
/* Amplitude of the component at f cycles per revolution: the record less its least-squares
 * line, Hann window, 2 |sum w x e^{-i 2 pi f t}| / sum w (a pure sine of amplitude A inside
 * the record reads A when f is resolved, f >= 2 / revolutions). */
double prsm_signal_amplitude(const double *x, int n, double per_rev, double f_per_rev);

#endif
