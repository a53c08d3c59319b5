/*
 * nominal.c: a catalogue size resolved by the standard rules (MODEL.md §1; nominal.h).
 */
#include "model/nominal.h"

#include <math.h>
#include <string.h>

#include "model/geometry.h"
#include "util/error.h"

int prsm_nominal_resolve(prsm_nominal_geometry *out, const prsm_nominal *n, double beta,
                         double clearance_mm, prsm_problems *errors)
{
	const int before = prsm_problems_total(errors);
	memset(out, 0, sizeof *out);
	const int starts = n->starts > 0 ? n->starts : PRSM_NOMINAL_STARTS_DEFAULT;
	if (!(n->diameter_mm > 0.0) || !isfinite(n->diameter_mm))
		prsm_problems_add(errors, "/nominal/diameter_mm", "range",
		                  "the nominal diameter must be a positive number of mm (got %g)", n->diameter_mm);
	if (!(n->lead_mm > 0.0) || !isfinite(n->lead_mm))
		prsm_problems_add(errors, "/nominal/lead_mm", "range",
		                  "the lead must be a positive number of mm (got %g)", n->lead_mm);
	if (starts < PRSM_NOMINAL_STARTS_MIN)
		prsm_problems_add(errors, "/nominal/starts", "starts_min",
		                  "a catalogue size follows the standard rule r_s = (n-2) r_r, which needs at "
		                  "least 3 starts (got %d)", starts);
	if (prsm_problems_total(errors) > before)
		return PRSM_EINVAL;
	/* MODEL.md §1: L = n P, r_s = (n - 2) r_r, r_n = r_s + 2 r_r = n r_r */
	out->starts = starts;
	out->pitch_mm = n->lead_mm / starts;
	out->screw_radius_mm = 0.5 * n->diameter_mm;
	out->roller_radius_mm = out->screw_radius_mm / (starts - 2);
	out->nut_radius_mm = starts * out->roller_radius_mm;
	/* Z_max with the default roller crest (geometry.c's rule: r_r + P/4 within the arc domain) */
	const double rr = out->roller_radius_mm, R = rr / sin(beta);
	const double crest = fmin(rr + PRSM_ADDENDUM_PER_PITCH * out->pitch_mm, rr + 0.9 * (R - rr));
	const int zmax = prsm_geometry_z_max(crest, clearance_mm, out->screw_radius_mm + rr);
	out->rollers = n->rollers > 0 ? n->rollers : zmax;
	if (out->rollers < 1)
		prsm_problems_add(errors, "/nominal/diameter_mm", "z_max",
		                  "no roller fits: diameter %g mm with %d starts gives rollers of radius %g mm "
		                  "that touch (running clearance %g mm)", n->diameter_mm, starts, rr, clearance_mm);
	if (n->engaged_threads > 0) {
		out->engaged_threads = n->engaged_threads;
	} else {
		const double nt = floor(n->diameter_mm / out->pitch_mm + 0.5);
		out->engaged_threads = nt < PRSM_NOMINAL_THREADS_MIN ? PRSM_NOMINAL_THREADS_MIN
		                       : nt > 500.0                  ? 500
		                                                     : (int)nt;
	}
	return prsm_problems_total(errors) > before ? PRSM_EINVAL : 0;
}
