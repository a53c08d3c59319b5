/*
 * assembly_report.c: the error analysis of one error set (docs/model/errors-and-assembly.md).
 */
#include "model/assembly_report.h"
#include "util/clock.h"

#include <math.h>
#include <string.h>

#include <gsl/gsl_fft_real.h>

void prsm_signal_fit_line(double *a, double *b, const double *x, int n)
{
	if (n < 2) {
		*a = n == 1 ? x[0] : 0.0;
		*b = 0.0;
		return;
	}
	const double tm = 0.5 * (n - 1);
	double xm = 0.0;
	for (int i = 0; i < n; i++)
		xm += x[i];
	xm /= n;
	double sxy = 0.0, sxx = 0.0;
	for (int i = 0; i < n; i++) {
		sxy += (i - tm) * (x[i] - xm);
		sxx += (i - tm) * (i - tm);
	}
	*b = sxy / sxx;
	*a = xm - *b * tm;
}

void prsm_signal_pp_rms(double *pp, double *rms, const double *x, int n)
{
	double lo = INFINITY, hi = -INFINITY, m = 0.0, s = 0.0;
	for (int i = 0; i < n; i++) {
		lo = fmin(lo, x[i]);
		hi = fmax(hi, x[i]);
		m += x[i];
	}
	m /= n;
	for (int i = 0; i < n; i++)
		s += (x[i] - m) * (x[i] - m);
	*pp = n > 0 ? hi - lo : 0.0;
	*rms = n > 0 ? sqrt(s / n) : 0.0;
}

double prsm_signal_amplitude(const double *x, int n, double per_rev, double f)
{
	if (n < 2)
		return 0.0;
	double a, b;
	prsm_signal_fit_line(&a, &b, x, n);
	/* phase step per sample, rotated by recurrence and refreshed exactly every 256 samples */
	const double w = 2.0 * M_PI * f / per_rev;
	double re = 0.0, im = 0.0, wsum = 0.0;
	double c = 1.0, s = 0.0;
	const double cs = cos(w), sn = sin(w);
	for (int i = 0; i < n; i++) {
		if ((i & 255) == 0) {
			c = cos(w * i);
			s = sin(w * i);
		}
		const double win = 0.5 - 0.5 * cos(2.0 * M_PI * (i + 0.5) / n);
		const double v = win * (x[i] - a - b * i);
		re += v * c;
		im -= v * s;
		wsum += win;
		const double c2 = c * cs - s * sn;
		s = s * cs + c * sn;
		c = c2;
	}
	return 2.0 * hypot(re, im) / wsum;
}

void prsm_assembly_record_length(int *record_length, int *fft_length, const prsm_assembly *as,
                                 const prsm_assembly_options *o)
{
	const double lead = as->starts * as->pitch_mm;
	double revs = o->spectrum_revolutions;
	if (o->stroke_mm > 0.0 && o->stroke_mm / lead > revs)
		revs = o->stroke_mm / lead;
	int n = (int)ceil(revs * o->angles_per_revolution) + 1;
	if (n < o->angles_per_revolution)
		n = o->angles_per_revolution;
	*record_length = n;
	int m = 2;
	while (m < n)
		m *= 2;
	*fft_length = m;
}

/* Amplitude spectrum of the record, detrended and Hann-windowed, zero-padded to m (a power of
 * two) samples: out[b] for b = 0 .. m/2 at b per_rev / m cycles per revolution. out has m
 * values of room. */
static void amplitude_spectrum(double *out, int m, const double *x, int n)
{
	double a, b, wsum = 0.0;
	prsm_signal_fit_line(&a, &b, x, n);
	for (int i = 0; i < n; i++) {
		const double win = 0.5 - 0.5 * cos(2.0 * M_PI * (i + 0.5) / n);
		out[i] = win * (x[i] - a - b * i);
		wsum += win;
	}
	for (int i = n; i < m; i++)
		out[i] = 0.0;
	/* m is a power of two >= 2, so the transform cannot fail (its only error is a length that
	 * is not); no handler switching here: prsm_global_init switched GSL's handler off */
	gsl_fft_real_radix2_transform(out, 1, (size_t)m);
	/* half-complex: out[k] = Re X_k, out[m - k] = Im X_k for 0 < k < m/2 */
	out[0] = 0.0;
	for (int k = 1; k < m / 2; k++)
		out[k] = 2.0 * hypot(out[k], out[m - k]) / wsum;
	out[m / 2] = fabs(out[m / 2]) / wsum;
}

/* 1 when the caller asked the analysis to stop: its flag, or its deadline on the monotonic clock */
static int stop_requested(const prsm_assembly_options *o)
{
	if (o == NULL)
		return 0;
	if (prsm_cancel_requested(o->cancel))
		return 1;
	return o->deadline_s > 0.0 && prsm_clock_seconds() > o->deadline_s;
}

double prsm_assembly_cost(const prsm_assembly *as, const prsm_assembly_options *o)
{
	int n, fft;
	prsm_assembly_record_length(&n, &fft, as, o);
	/* per angle: the TE record one direction, the revolution both directions (plus the elastic
	 * solve, of the same order) */
	const double contacts = 2.0 * as->rollers * as->threads; /* screw and nut side */
	const double weight = o->mode == PRSM_MODE_EXACT ? PRSM_ASSEMBLY_EXACT_COST : 1.0;
	return weight * contacts * ((double)n + 3.0 * o->angles_per_revolution);
}

static int te_record(double *te, int n, double dtheta, const prsm_assembly *as, const prsm_errors *e, int mode,
                     double F, prsm_assembly_gaps *ws, int *edge, int *failed, const prsm_assembly_options *stop)
{
	prsm_assembly_state st;
	double u0 = 0.0;
	for (int i = 0; i < n; i++) {
		if (i % PRSM_ASSEMBLY_STOP_EVERY == 0 && stop_requested(stop))
			return PRSM_ECANCELLED;
		prsm_assembly_gaps_at(ws, as, e, PRSM_DIR_PLUS, i * dtheta, mode);
		if (edge)
			*edge += ws->edge_contacts;
		if (failed)
			*failed += ws->failed_contacts;
		if (prsm_assembly_solve(&st, as, ws, F, i > 0) && failed)
			++*failed; /* docs/model/errors-and-assembly.md: counted, as a failed contact solve is */
		if (i == 0)
			u0 = st.u_mm;
		te[i] = st.u_mm - u0;
	}
	return 0;
}

int prsm_assembly_te_record(double *te, int n, double dtheta, const prsm_assembly *as,
                            const prsm_errors *e, int mode, double F, prsm_assembly_gaps *ws,
                            int *edge, int *failed)
{
	return te_record(te, n, dtheta, as, e, mode, F, ws, edge, failed, NULL);
}

static void gap_range(double *lo, double *hi, const prsm_assembly *as, const prsm_assembly_gaps *g,
                      int side)
{
	const int n = as->rollers * as->threads;
	*lo = INFINITY;
	*hi = -INFINITY;
	for (int i = 0; i < n; i++) {
		*lo = fmin(*lo, g->gap_mm[side][i]);
		*hi = fmax(*hi, g->gap_mm[side][i]);
	}
}

int prsm_assembly_analyse(prsm_assembly_report *r, const prsm_assembly *as, const prsm_errors *e,
                          const prsm_assembly_options *o, prsm_assembly_workspace *ws)
{
	memset(r, 0, sizeof *r);
	r->mode = o->mode;
	r->angles_per_revolution = o->angles_per_revolution;
	const int M = o->angles_per_revolution;
	const double dtheta = 2.0 * M_PI / M;
	const double F = as->design.axial_load_N;

	/* transmission error at the measuring load (docs/model/errors-and-assembly.md); ws->minus is its scratch */
	int n, fft;
	prsm_assembly_record_length(&n, &fft, as, o);
	r->record_length = n;
	r->measuring_load_N = o->measuring_load_N;
	if (te_record(ws->te_mm, n, dtheta, as, e, o->mode, o->measuring_load_N, &ws->minus, &r->edge_contacts,
	              &r->failed_contacts, o))
		return PRSM_ECANCELLED;

	/* gaps, backlash and load sharing over one revolution */
	r->backlash_min_mm = INFINITY;
	r->backlash_max_mm = -INFINITY;
	prsm_assembly_state st;
	for (int i = 0; i < M; i++) {
		if (i % PRSM_ASSEMBLY_STOP_EVERY == 0 && stop_requested(o))
			return PRSM_ECANCELLED;
		const double th = i * dtheta;
		prsm_assembly_gaps_at(&ws->plus, as, e, PRSM_DIR_PLUS, th, o->mode);
		prsm_assembly_gaps_at(&ws->minus, as, e, PRSM_DIR_MINUS, th, o->mode);
		r->edge_contacts += ws->plus.edge_contacts + ws->minus.edge_contacts;
		r->failed_contacts += ws->plus.failed_contacts + ws->minus.failed_contacts;
		double bp, bm;
		const double B = prsm_assembly_backlash(as, &ws->plus, &ws->minus, &bp, &bm);
		r->backlash_min_mm = fmin(r->backlash_min_mm, B);
		r->backlash_max_mm = fmax(r->backlash_max_mm, B);
		r->backlash_mean_mm += B / M;
		if (F > 0.0) {
			if (prsm_assembly_solve(&st, as, &ws->plus, F, i > 0))
				r->failed_contacts++;
			r->sharing_factor_max = fmax(r->sharing_factor_max, st.sharing_factor);
		}
		if (i == 0) {
			r->backlash_mm = B;
			r->backlash_plus_mm = bp;
			r->backlash_minus_mm = bm;
			for (int side = 0; side < 2; side++) {
				gap_range(&r->gap_min_mm[side][PRSM_DIR_PLUS], &r->gap_max_mm[side][PRSM_DIR_PLUS], as,
				          &ws->plus, side);
				gap_range(&r->gap_min_mm[side][PRSM_DIR_MINUS], &r->gap_max_mm[side][PRSM_DIR_MINUS], as,
				          &ws->minus, side);
			}
			if (F > 0.0)
				r->operating = st;
		}
	}
	if (F > 0.0 && as->nominal_stiffness_N_per_mm > 0.0)
		r->stiffness_ratio = r->operating.stiffness_N_per_mm / as->nominal_stiffness_N_per_mm;
	/* leave the gaps of theta = 0 in the workspace for the caller */
	prsm_assembly_gaps_at(&ws->plus, as, e, PRSM_DIR_PLUS, 0.0, o->mode);
	prsm_assembly_gaps_at(&ws->minus, as, e, PRSM_DIR_MINUS, 0.0, o->mode);

	prsm_signal_pp_rms(&r->te_revolution_pp_mm, &r->te_revolution_rms_mm, ws->te_mm, M < n ? M : n);
	const double lead = as->starts * as->pitch_mm;
	if (o->stroke_mm > 0.0) {
		int ns = (int)ceil(o->stroke_mm / lead * M) + 1;
		if (ns > n)
			ns = n;
		r->has_stroke = 1;
		r->stroke_mm = o->stroke_mm;
		prsm_signal_pp_rms(&r->te_stroke_pp_mm, &r->te_stroke_rms_mm, ws->te_mm, ns);
		double a, b;
		prsm_signal_fit_line(&a, &b, ws->te_mm, ns);
		/* travel per sample: -p dtheta (the nut's position on the screw) */
		r->lead_deviation = b / (-as->screw_p * dtheta);
		double lo = INFINITY, hi = -INFINITY;
		for (int i = 0; i < ns; i++) {
			const double res = ws->te_mm[i] - a - b * i;
			lo = fmin(lo, res);
			hi = fmax(hi, res);
		}
		r->te_stroke_residual_pp_mm = hi - lo;
	}
	/* spectrum of the whole record with the named lines */
	r->record_revolutions = (double)(n - 1) / M;
	prsm_assembly_frequencies_of(&r->frequencies, as);
	const double lines[5] = {r->frequencies.screw, r->frequencies.carrier, r->frequencies.roller_spin,
	                         r->frequencies.roller_pass_screw, r->frequencies.roller_pass_nut};
	for (int i = 0; i < 5; i++)
		r->line_amplitude_mm[i] = prsm_signal_amplitude(ws->te_mm, n, M, lines[i]);
	amplitude_spectrum(ws->spectrum_mm, fft, ws->te_mm, n);
	r->spectrum_bins = fft / 2 + 1;
	r->spectrum_step_per_rev = (double)M / fft;
	/* below two cycles per record the window and the trend dominate, not a line */
	const double fmin_line = 2.0 / r->record_revolutions;
	for (int b = 1; b < r->spectrum_bins; b++) {
		const double f = b * r->spectrum_step_per_rev;
		if (f >= fmin_line && ws->spectrum_mm[b] > r->peak_amplitude_mm) {
			r->peak_amplitude_mm = ws->spectrum_mm[b];
			r->peak_frequency_per_rev = f;
		}
	}
	return 0;
}
