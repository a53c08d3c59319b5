/*
 * assembly.c: part errors to flank gaps, rigid backlash and the elastic load sharing
 * (docs/model/errors-and-assembly.md; conventions in docs/assembly-model.md).
 */
#include "model/assembly.h"

#include <math.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

void prsm_assembly_options_default(prsm_assembly_options *o)
{
	o->mode = PRSM_MODE_LINEAR;
	o->measuring_load_N = 50.0;
	o->angles_per_revolution = 64;
	o->stroke_mm = 0.0;
	o->spectrum_revolutions = 16;
	o->curve = 0;
	o->cancel = NULL;
	o->deadline_s = 0.0;
}

/* The "+" chain (docs/model/errors-and-assembly.md: screw side closes with w_j, nut side with u - w_j) is the nut
 * pair as contact.c models it and the screw pair mirrored; "-" the opposite. */
static int is_mirrored(int side, int dir)
{
	return (side == PRSM_SIDE_SCREW) == (dir == PRSM_DIR_PLUS);
}

static int prepare_pair(prsm_assembly_pair *ap, const prsm_design *d, int side, int dir)
{
	prsm_flank_pair_nominal(&ap->pair, d, side);
	ap->mirrored = is_mirrored(side, dir);
	if (ap->mirrored) {
		/* z -> -z: the other flank of both threads, helices of the opposite hand */
		ap->pair.body_p = -ap->pair.body_p;
		ap->pair.roller_p = -ap->pair.roller_p;
	}
	prsm_contact c;
	int rc = prsm_contact_solve(&c, &ap->pair);
	if (rc)
		return rc;
	ap->x_mm = c.x_mm;
	ap->y_mm = c.y_mm;
	ap->gap_mm = c.gap_mm;
	prsm_perturb_sensitivities(ap->sens, &ap->pair, c.x_mm, c.y_mm);
	const double wx = c.x_mm - ap->pair.roller_x_mm, wy = c.y_mm - ap->pair.roller_y_mm;
	ap->u2_mm2 = wx * wx + wy * wy;
	return 0;
}

/* Axial Hertz constant K (N/mm^1.5): normal approach delta_n = C Q^{2/3} gives K_n = Q /
 * delta_n^{3/2} (any Q); an axial approach delta_a is a normal one of |n_z| delta_a and a
 * normal load Q an axial one of |n_z| Q, so f = K_n |n_z|^{5/2} delta_a^{3/2} (docs/model/errors-and-assembly.md, docs/model/kinematics-efficiency-stiffness-life.md). */
static int axial_constant(double *K, const prsm_contact *c, const prsm_material *mb,
                          const prsm_material *mr)
{
	prsm_hertz h;
	int rc = prsm_hertz_solve(&h, c->curvature_per_mm[0], c->curvature_per_mm[1], mb->E_MPa,
	                          mb->poisson, mr->E_MPa, mr->poisson, 1.0);
	if (rc || !(h.delta_mm > 0.0))
		return PRSM_EGEOMETRY;
	const double nz = fabs(c->normal[2]);
	*K = pow(h.delta_mm, -1.5) * pow(nz, 2.5);
	return 0;
}

int prsm_assembly_init(prsm_assembly *as, const prsm_design *d, const prsm_analysis *a,
                       prsm_error *err)
{
	memset(as, 0, sizeof *as);
	if (d->rollers > PRSM_ERRORS_MAX_ROLLERS ||
	    (long)d->rollers * d->engaged_threads > PRSM_ASSEMBLY_MAX_CONTACTS)
		return prsm_error_set(err, PRSM_EINVAL, "/geometry",
		                      "the error analysis takes at most %d rollers and %d contacts per flank "
		                      "side (rollers x engaged threads); this design has %d x %d",
		                      PRSM_ERRORS_MAX_ROLLERS, PRSM_ASSEMBLY_MAX_CONTACTS, d->rollers,
		                      d->engaged_threads);
	as->design = *d;
	as->rollers = d->rollers;
	as->threads = d->engaged_threads;
	as->starts = d->starts;
	as->hand = d->hand;
	as->pitch_mm = d->pitch_mm;
	as->screw_p = prsm_design_screw_p(d);
	as->roller_p = prsm_design_roller_p(d);
	/* the gear mesh holds the rolling ratios of the pitch circles (docs/model/errors-and-assembly.md, docs/model/kinematics-efficiency-stiffness-life.md) */
	as->carrier_ratio = a->kinematics.carrier_ratio_ideal;
	as->spin_ratio = a->kinematics.roller_spin_ratio_ideal;
	for (int side = 0; side < 2; side++)
		for (int dir = 0; dir < 2; dir++)
			if (prepare_pair(&as->pairs[side][dir], d, side, dir))
				return prsm_error_set(err, PRSM_EGEOMETRY, "/geometry",
				                      "the %s %s flank has no contact point on its flank",
				                      side == PRSM_SIDE_SCREW ? "screw-roller" : "nut-roller",
				                      is_mirrored(side, dir) ? "mirrored" : "modelled");
	if (axial_constant(&as->k_axial[PRSM_SIDE_SCREW], &a->screw, &d->screw_material, &d->roller_material) ||
	    axial_constant(&as->k_axial[PRSM_SIDE_NUT], &a->nut, &d->nut_material, &d->roller_material))
		return prsm_error_set(err, PRSM_EGEOMETRY, "/geometry",
		                      "a contact has non-positive relative curvature: no Hertz constant");
	/* nominal stiffness: every contact carries F / (Z n_t), springs in series per roller */
	const double f = d->axial_load_N / ((double)as->rollers * as->threads);
	if (f > 0.0) {
		double ks = 1.5 * cbrt(f * as->k_axial[0] * as->k_axial[0]); /* df/ddelta = 1.5 K^{2/3} f^{1/3} */
		double kn = 1.5 * cbrt(f * as->k_axial[1] * as->k_axial[1]);
		as->nominal_stiffness_N_per_mm = (double)as->rollers * as->threads * ks * kn / (ks + kn);
	}
	return 0;
}

void prsm_assembly_frequencies_of(prsm_assembly_frequencies *f, const prsm_assembly *as)
{
	f->screw = 1.0 - as->carrier_ratio;
	f->carrier = as->carrier_ratio;
	f->roller_spin = fabs(as->spin_ratio);
	f->roller_pass_screw = as->rollers * (1.0 - as->carrier_ratio);
	f->roller_pass_nut = as->rollers * as->carrier_ratio;
}

/* ---- part errors to pair perturbations ------------------------------------------------- */

/* What the errors do to roller j at screw angle theta, split into the part constant along the
 * engagement (at z = 0) and the part proportional to z (tilt, cumulative lead). Lengths mm.
 * body_*: screw [0] and nut [1]; D = axial displacement of a flank towards +z. */
typedef struct {
	double body_dx[2], body_dy[2], body_dx_z[2], body_dy_z[2]; /* axis offset, per mm of z */
	double body_D[2], body_D_z[2];
	double roller_dx, roller_dy, roller_dx_z, roller_dy_z;
	double roller_D[2], roller_D_z;                          /* [side] */
	int start_offset;                                        /* m_j: starts passed (below) */
} roller_terms;

static void rotate(double *x, double *y, double r, double angle)
{
	if (r == 0.0) {
		*x = *y = 0.0;
		return;
	}
	*x = r * cos(angle);
	*y = r * sin(angle);
}

/* tan x, without the call for x = 0 (tan(+-0) = +-0: the same bits): most error sets have no tilt */
static double tan0(double x)
{
	return x == 0.0 ? x : tan(x);
}

static void compute_terms(roller_terms *t, const prsm_assembly *as, const prsm_errors *e, int j,
                          double theta)
{
	const double slot = 2.0 * M_PI * j / as->rollers;
	const double psi = slot + as->carrier_ratio * theta;       /* carrier angle of roller j */
	const double sigma = as->spin_ratio * theta;               /* spin relative to the carrier */
	const double travel = -as->screw_p * theta;                /* nut position on the screw, mm */
	for (int side = 0; side < 2; side++) {
		const prsm_body_errors *b = side == PRSM_SIDE_SCREW ? &e->screw : &e->nut;
		const double rot = side == PRSM_SIDE_SCREW ? theta : 0.0; /* the part's own angle */
		/* run-out and tilt turn with the part; the pair frame is the ground turned by -psi */
		rotate(&t->body_dx[side], &t->body_dy[side], b->runout_mm, rot + b->runout_phase_rad - psi);
		rotate(&t->body_dx_z[side], &t->body_dy_z[side], tan0(b->tilt_rad),
		       rot + b->tilt_phase_rad - psi);
		/* material angle of the contact on the part: psi - rot */
		double D = b->lead_periodic_mm == 0.0 ? 0.0 :
		           b->lead_periodic_mm * sin(psi - rot + b->lead_periodic_phase_rad);
		if (side == PRSM_SIDE_SCREW)
			D += travel * b->lead_deviation; /* the screw's flanks under the nut at this travel */
		t->body_D[side] = D;
		t->body_D_z[side] = b->lead_deviation;
	}
	const prsm_roller_errors *r = &e->roller[j];
	double cx, cy, rx, ry;
	rotate(&cx, &cy, e->carrier.runout_mm, e->carrier.runout_phase_rad - slot);
	rotate(&rx, &ry, r->runout_mm, sigma + r->runout_phase_rad);
	t->roller_dx = r->pin_radial_mm + cx + rx;
	t->roller_dy = r->pin_tangential_mm + cy + ry;
	t->roller_dx_z = tan0(r->tilt_radial_rad);
	t->roller_dy_z = tan0(r->tilt_tangential_rad);
	/* roller material angle at the contact: screw side pi - sigma, nut side -sigma */
	const double wob = r->lead_periodic_mm == 0.0 ? 0.0 :
	                   r->lead_periodic_mm * sin(r->lead_periodic_phase_rad - sigma);
	const double phase = as->roller_p * r->gear_phase_rad;
	t->roller_D[PRSM_SIDE_SCREW] = phase - wob; /* sin(pi + x) = -sin(x) */
	t->roller_D[PRSM_SIDE_NUT] = phase + wob;
	t->roller_D_z = r->lead_deviation;
	/* starts passed by the flanks at the roller's angle (docs/assembly-model.md) */
	t->start_offset = (int)floor(as->starts * psi / (2.0 * M_PI));
}

/* Perturbation of (side, dir) at z = 0 (e0) and per mm of z (e1), without the start errors. */
static void pair_terms(double *e0, double *e1, const prsm_assembly *as, const prsm_errors *e,
                       const roller_terms *t, int j, int side, int dir)
{
	const prsm_body_errors *b = side == PRSM_SIDE_SCREW ? &e->screw : &e->nut;
	const prsm_roller_errors *r = &e->roller[j];
	/* an axial displacement D towards +z: a modelled pair's body flank closes the gap (shift
	 * -D), its roller flank opens it (+D); a mirrored pair the opposite */
	const double ax = as->pairs[side][dir].mirrored ? -1.0 : 1.0;
	e0[PRSM_PERTURB_BODY_DX] = t->body_dx[side];
	e0[PRSM_PERTURB_BODY_DY] = t->body_dy[side];
	e0[PRSM_PERTURB_BODY_RADIUS] = b->pitch_radius_mm;
	e0[PRSM_PERTURB_BODY_BETA] = b->flank_angle_rad;
	e0[PRSM_PERTURB_BODY_SHIFT] = -0.5 * b->thickness_mm - ax * t->body_D[side];
	e0[PRSM_PERTURB_ROLLER_DX] = t->roller_dx;
	e0[PRSM_PERTURB_ROLLER_DY] = t->roller_dy;
	e0[PRSM_PERTURB_ROLLER_RADIUS] = r->pitch_radius_mm;
	e0[PRSM_PERTURB_ROLLER_ARC] = r->arc_radius_mm;
	e0[PRSM_PERTURB_ROLLER_SHIFT] = -0.5 * r->thickness_mm + ax * t->roller_D[side];
	memset(e1, 0, PRSM_PERTURB_COUNT * sizeof *e1);
	e1[PRSM_PERTURB_BODY_DX] = t->body_dx_z[side];
	e1[PRSM_PERTURB_BODY_DY] = t->body_dy_z[side];
	e1[PRSM_PERTURB_BODY_SHIFT] = -ax * t->body_D_z[side];
	e1[PRSM_PERTURB_ROLLER_DX] = t->roller_dx_z;
	e1[PRSM_PERTURB_ROLLER_DY] = t->roller_dy_z;
	e1[PRSM_PERTURB_ROLLER_SHIFT] = ax * t->roller_D_z;
}

/* z_k of thread k, mm */
static double thread_z(const prsm_assembly *as, int k)
{
	return (k - 0.5 * (as->threads - 1)) * as->pitch_mm;
}

/* Axial displacement (towards +z) of the body flank thread k meets, from its start's index
 * error: thread k meets start (k - hand m_j) mod n. */
static double start_shift(const prsm_assembly *as, const prsm_body_errors *b, int k, int m)
{
	int i = (k - as->hand * m) % as->starts;
	if (i < 0)
		i += as->starts;
	return as->screw_p * b->start_index_rad[i];
}

/* The perturbation of thread k from the roller's parts: e0 + z_k e1 and the start error of
 * the flank it meets (an axial displacement, signed like the others by the mirroring). */
static void thread_perturbation(double *out, const double *e0, const double *e1,
                                const prsm_assembly *as, const prsm_errors *e, int k, int side,
                                int dir, int start_offset)
{
	const double z = thread_z(as, k);
	for (int i = 0; i < PRSM_PERTURB_COUNT; i++)
		out[i] = e0[i] + z * e1[i];
	const prsm_body_errors *b = side == PRSM_SIDE_SCREW ? &e->screw : &e->nut;
	const double ax = as->pairs[side][dir].mirrored ? -1.0 : 1.0;
	out[PRSM_PERTURB_BODY_SHIFT] -= ax * start_shift(as, b, k, start_offset);
}

void prsm_assembly_perturbation(double *out, const prsm_assembly *as, const prsm_errors *e,
                                int j, int k, int side, int dir, double theta)
{
	roller_terms t;
	double e0[PRSM_PERTURB_COUNT], e1[PRSM_PERTURB_COUNT];
	compute_terms(&t, as, e, j, theta);
	pair_terms(e0, e1, as, e, &t, j, side, dir);
	thread_perturbation(out, e0, e1, as, e, k, side, dir, t.start_offset);
}

/* The gap change of the roller's pitch radius (dr) and flank arc radius (dR) deviations, mm: they
 * enter the gap only through z_c - sqrt(R^2 - u^2), evaluated exactly at the frozen contact. */
static inline double radius_change(const prsm_assembly_pair *ap, double dr, double dR)
{
	const double r = ap->pair.roller_radius_mm, R = ap->pair.arc_radius_mm;
	const double r1 = r + dr, R1 = R + dR;
	return sqrt(R1 * R1 - r1 * r1) - sqrt(R * R - r * r) - (sqrt(R1 * R1 - ap->u2_mm2) - sqrt(R * R - ap->u2_mm2));
}

/* Linear-mode gap change of e at the frozen nominal contact. The roller's pitch and arc radii
 * enter G only through z_c - sqrt(R^2 - u^2), which is cheap to evaluate exactly at the fixed
 * point: its curvature would otherwise cost 1.5 % at 50 um of pitch radius (test_perturb). The
 * rest is the envelope theorem (docs/model/errors-and-assembly.md): sens . e. */
static double linear_change(const prsm_assembly_pair *ap, const double *e)
{
	/* the components in index order but the two radii: the loop written out (no branch per
	 * component; the same sums in the same order) */
	_Static_assert(PRSM_PERTURB_COUNT == 10 && PRSM_PERTURB_ROLLER_SHIFT == 9 && PRSM_PERTURB_ROLLER_RADIUS == 7 &&
	                   PRSM_PERTURB_ROLLER_ARC == 8,
	               "linear_change names every perturbation component");
	const double *g = ap->sens;
	double s = 0.0;
	s += g[PRSM_PERTURB_BODY_DX] * e[PRSM_PERTURB_BODY_DX];
	s += g[PRSM_PERTURB_BODY_DY] * e[PRSM_PERTURB_BODY_DY];
	s += g[PRSM_PERTURB_BODY_RADIUS] * e[PRSM_PERTURB_BODY_RADIUS];
	s += g[PRSM_PERTURB_BODY_BETA] * e[PRSM_PERTURB_BODY_BETA];
	s += g[PRSM_PERTURB_BODY_SHIFT] * e[PRSM_PERTURB_BODY_SHIFT];
	s += g[PRSM_PERTURB_ROLLER_DX] * e[PRSM_PERTURB_ROLLER_DX];
	s += g[PRSM_PERTURB_ROLLER_DY] * e[PRSM_PERTURB_ROLLER_DY];
	s += g[PRSM_PERTURB_ROLLER_SHIFT] * e[PRSM_PERTURB_ROLLER_SHIFT];
	const double dr = e[PRSM_PERTURB_ROLLER_RADIUS], dR = e[PRSM_PERTURB_ROLLER_ARC];
	if (dr != 0.0 || dR != 0.0)
		s += radius_change(ap, dr, dR);
	return s;
}

double prsm_assembly_gap_linear(const prsm_assembly_pair *ap, const double *e)
{
	return ap->gap_mm + linear_change(ap, e);
}

/* g0 = gap + linear_change(e0) and g1 = sens . e1 of pair_terms' e0 and e1, without building the
 * two vectors: the same products added in the same order. e1's components that pair_terms leaves
 * at zero are skipped; each would add a zero product to a sum that is never -0 (it starts at +0,
 * and x + (-x) rounds to +0), which leaves the sum's bits as they are. */
static void pair_gap(double *g0, double *g1, const prsm_assembly_pair *ap, const prsm_errors *e,
                     const roller_terms *t, int j, int side)
{
	_Static_assert(PRSM_PERTURB_COUNT == 10 && PRSM_PERTURB_BODY_SHIFT == 4 && PRSM_PERTURB_ROLLER_SHIFT == 9,
	               "pair_gap names every perturbation component in index order");
	const prsm_body_errors *b = side == PRSM_SIDE_SCREW ? &e->screw : &e->nut;
	const prsm_roller_errors *r = &e->roller[j];
	const double ax = ap->mirrored ? -1.0 : 1.0;
	const double *g = ap->sens;
	double s = 0.0;
	s += g[PRSM_PERTURB_BODY_DX] * t->body_dx[side];
	s += g[PRSM_PERTURB_BODY_DY] * t->body_dy[side];
	s += g[PRSM_PERTURB_BODY_RADIUS] * b->pitch_radius_mm;
	s += g[PRSM_PERTURB_BODY_BETA] * b->flank_angle_rad;
	s += g[PRSM_PERTURB_BODY_SHIFT] * (-0.5 * b->thickness_mm - ax * t->body_D[side]);
	s += g[PRSM_PERTURB_ROLLER_DX] * t->roller_dx;
	s += g[PRSM_PERTURB_ROLLER_DY] * t->roller_dy;
	s += g[PRSM_PERTURB_ROLLER_SHIFT] * (-0.5 * r->thickness_mm + ax * t->roller_D[side]);
	const double dr = r->pitch_radius_mm, dR = r->arc_radius_mm;
	if (dr != 0.0 || dR != 0.0)
		s += radius_change(ap, dr, dR);
	*g0 = ap->gap_mm + s;
	double z = 0.0;
	z += g[PRSM_PERTURB_BODY_DX] * t->body_dx_z[side];
	z += g[PRSM_PERTURB_BODY_DY] * t->body_dy_z[side];
	z += g[PRSM_PERTURB_BODY_SHIFT] * (-ax * t->body_D_z[side]);
	z += g[PRSM_PERTURB_ROLLER_DX] * t->roller_dx_z;
	z += g[PRSM_PERTURB_ROLLER_DY] * t->roller_dy_z;
	z += g[PRSM_PERTURB_ROLLER_SHIFT] * (ax * t->roller_D_z);
	*g1 = z;
}

int prsm_assembly_gaps_at(prsm_assembly_gaps *out, const prsm_assembly *as, const prsm_errors *e,
                          int dir, double theta, int mode)
{
	const int Z = as->rollers, nt = as->threads, ns = as->starts;
	int rc = 0;
	out->edge_contacts = out->failed_contacts = 0;
	/* what start_shift and thread_z give, once per call (the same products: the same bits); the
	 * start shifts signed by each side's mirroring and repeated, so that thread k of a roller
	 * whose first thread meets start si takes shift[side][si + k] without a wrap-around (an
	 * engagement of up to 256 threads; a longer one computes them as it goes) */
	double shift[2][PRSM_ERRORS_MAX_STARTS + 256], zk[256];
	const int ztab = nt <= 256;
	for (int side = 0; side < 2; side++) {
		const prsm_body_errors *b = side == PRSM_SIDE_SCREW ? &e->screw : &e->nut;
		const double ax = as->pairs[side][dir].mirrored ? -1.0 : 1.0;
		for (int i = 0; i < ns; i++)
			shift[side][i] = ax * (as->screw_p * b->start_index_rad[i]);
		for (int i = ns; i < ns + nt && ztab; i++)
			shift[side][i] = shift[side][i - ns];
	}
	for (int k = 0; k < nt && ztab; k++)
		zk[k] = thread_z(as, k);
	for (int j = 0; j < Z; j++) {
		roller_terms t;
		compute_terms(&t, as, e, j, theta);
		for (int side = 0; side < 2; side++) {
			const prsm_assembly_pair *ap = &as->pairs[side][dir];
			double g0, g1;
			pair_gap(&g0, &g1, ap, e, &t, j, side);
			double *g = &out->gap_mm[side][j * nt];
			/* linear mode (docs/model/errors-and-assembly.md): nominal gap + sensitivities . perturbation; the shift
			 * sensitivity is exactly 1 */
			/* thread k meets start (k - hand m_j) mod n (start_shift), counted up from k = 0 */
			int si = (-as->hand * t.start_offset) % ns;
			if (si < 0)
				si += ns;
			if (ztab) {
				const double *sh = &shift[side][si];
				int k = 0;
#ifdef __SSE2__
				/* two threads an instruction, each lane the scalar loop's operations */
				const __m128d a = _mm_set1_pd(g0), c = _mm_set1_pd(g1);
				for (; k + 1 < nt; k += 2)
					_mm_storeu_pd(g + k, _mm_sub_pd(_mm_add_pd(a, _mm_mul_pd(c, _mm_loadu_pd(zk + k))),
					                                _mm_loadu_pd(sh + k)));
#endif
				for (; k < nt; k++)
					g[k] = g0 + g1 * zk[k] - sh[k];
			} else {
				for (int k = 0; k < nt; k++) {
					g[k] = g0 + g1 * thread_z(as, k) - shift[side][si];
					if (++si == ns)
						si = 0;
				}
			}
			if (mode != PRSM_MODE_EXACT)
				continue;
			double e0[PRSM_PERTURB_COUNT], e1[PRSM_PERTURB_COUNT];
			pair_terms(e0, e1, as, e, &t, j, side, dir);
			for (int k = 0; k < nt; k++) {
				double ek[PRSM_PERTURB_COUNT], gk;
				thread_perturbation(ek, e0, e1, as, e, k, side, dir, t.start_offset);
				int edge = 0;
				if (prsm_perturb_gap_exact(&gk, &edge, &ap->pair, ap->x_mm, ap->y_mm, ek)) {
					out->failed_contacts++;
					rc = PRSM_ENOCONVERGE;
					continue; /* keeps the linear gap */
				}
				if (edge)
					out->edge_contacts++;
				g[k] = gk;
			}
		}
	}
	return rc;
}

static double min_of(const double *v, int n)
{
	double m = v[0];
	for (int i = 1; i < n; i++)
		if (v[i] < m)
			m = v[i];
	return m;
}

static double chain_backlash(const prsm_assembly *as, const prsm_assembly_gaps *g)
{
	const int nt = as->threads;
	double b = INFINITY;
	for (int j = 0; j < as->rollers; j++) {
		double c = min_of(&g->gap_mm[0][j * nt], nt) + min_of(&g->gap_mm[1][j * nt], nt);
		if (c < b)
			b = c;
	}
	return b;
}

double prsm_assembly_backlash(const prsm_assembly *as, const prsm_assembly_gaps *plus,
                              const prsm_assembly_gaps *minus, double *plus_mm, double *minus_mm)
{
	const double bp = chain_backlash(as, plus), bm = chain_backlash(as, minus);
	if (plus_mm)
		*plus_mm = bp;
	if (minus_mm)
		*minus_mm = bm;
	return bp + bm;
}

/* ---- elastic solve ---------------------------------------------------------------------- */

/* Newton step for an increasing residual r(x) with slope dr, kept inside the bracket [lo, hi],
 * which is first narrowed by the sign of r; bisection when the step leaves it. */
static double safeguarded_step(double x, double r, double dr, double *lo, double *hi)
{
	if (r > 0.0)
		*hi = x;
	else
		*lo = x;
	double nx = dr > 0.0 ? x - r / dr : 0.5 * (*lo + *hi);
	if (!(nx > *lo && nx < *hi))
		nx = 0.5 * (*lo + *hi);
	return nx;
}

/* Sum over contacts of K (x - g_k)_+^{3/2} and its derivative in x. */
static double side_force(const double *g, int n, double K, double x, double *deriv)
{
	/* without a branch (an open contact adds +0 to both sums: the same bits), which a contact
	 * near its gap would mispredict. Two partial sums, the even and the odd threads, added at
	 * the end: with SSE2 (every x86-64) one instruction takes both square roots, the square
	 * roots being most of an elastic solve's time; the scalar loop computes the same lanes with
	 * the same operations, so both give the same bits (max(d0, 0) as the comparison does: 0
	 * for a NaN or a negative zero d0). */
	double f0 = 0.0, f1 = 0.0, s0 = 0.0, s1 = 0.0;
	int k = 0;
#ifdef __SSE2__
	const __m128d xv = _mm_set1_pd(x), zero = _mm_setzero_pd();
	__m128d fv = zero, sv = zero;
	for (; k + 1 < n; k += 2) {
		const __m128d d = _mm_max_pd(_mm_sub_pd(xv, _mm_loadu_pd(g + k)), zero);
		const __m128d r = _mm_sqrt_pd(d);
		fv = _mm_add_pd(fv, _mm_mul_pd(d, r));
		sv = _mm_add_pd(sv, r);
	}
	double lane[2];
	_mm_storeu_pd(lane, fv);
	f0 = lane[0];
	f1 = lane[1];
	_mm_storeu_pd(lane, sv);
	s0 = lane[0];
	s1 = lane[1];
#else
	for (; k + 1 < n; k += 2) {
		const double a = x - g[k], b = x - g[k + 1];
		const double da = a > 0.0 ? a : 0.0, db = b > 0.0 ? b : 0.0;
		const double ra = sqrt(da), rb = sqrt(db);
		f0 += da * ra;
		f1 += db * rb;
		s0 += ra;
		s1 += rb;
	}
#endif
	if (k < n) {
		const double d0 = x - g[k], d = d0 > 0.0 ? d0 : 0.0;
		const double r = sqrt(d);
		f0 += d * r;
		s0 += r;
	}
	*deriv = 1.5 * K * (s0 + s1);
	return K * (f0 + f1);
}

/* Roller j at nut displacement u: the w in which its screw side (closing with w) and nut side
 * (closing with u - w) carry the same load. h(w) = S(w) - N(u - w) is increasing: safeguarded
 * Newton inside the bracket [gs, u - gn]. Returns the roller load; *w is the start point on
 * entry; *dF gets dF_j/du = S'N'/(S' + N') (the two sides in series), *dw dw/du = N'/(S' + N'). */
static double roller_balance(const double *gs, const double *gn, int n, double Ks, double Kn,
                             double u, double gs_min, double gn_min, double *w, double *dF,
                             double *dw, int *converged)
{
	*converged = 1;
	double lo = gs_min, hi = u - gn_min;
	if (!(hi > lo)) {
		/* the chain is open: the roller carries nothing */
		*w = lo;
		*dF = *dw = 0.0;
		return 0.0;
	}
	double x = *w;
	if (!(x > lo && x < hi))
		x = 0.5 * (lo + hi);
	double S = 0.0, dS = 0.0, N = 0.0, dN = 0.0;
	int done = 0;
	for (int it = 0; it < PRSM_ASSEMBLY_MAX_ITERATIONS && !done; it++) {
		S = side_force(gs, n, Ks, x, &dS);
		N = side_force(gn, n, Kn, u - x, &dN);
		const double h = S - N, dh = dS + dN;
		/* balanced to 1e-12 of the load, or the bracket has closed */
		if (fabs(h) <= 1e-12 * (S + N) || hi - lo <= 1e-15 * (1.0 + fabs(x)))
			done = 1;
		else
			x = safeguarded_step(x, h, dh, &lo, &hi);
	}
	*converged = done && isfinite(S) && isfinite(N);
	*w = x;
	*dF = dS + dN > 0.0 ? dS * dN / (dS + dN) : 0.0;
	*dw = dS + dN > 0.0 ? dN / (dS + dN) : 0.5;
	return 0.5 * (S + N);
}

/* The state's summary once u, w, the roller loads and the stiffness are set. */
static int finish(prsm_assembly_state *st, const prsm_assembly *as, double F, int ok, const double *gs_min,
                  const double *gn_min)
{
	const int Z = as->rollers;
	for (int j = 0; j < Z; j++) {
		st->gs_min_mm[j] = gs_min[j];
		st->gn_min_mm[j] = gn_min[j];
	}
	st->gaps_known = 1;
	st->load_N = F;
	st->converged = ok && isfinite(F) && F > 0.0;
	double peak = 0.0;
	st->loaded_rollers = 0;
	for (int j = 0; j < Z; j++) {
		if (st->roller_load_N[j] > 0.0)
			st->loaded_rollers++;
		peak = fmax(peak, st->roller_load_N[j]);
	}
	st->sharing_factor = peak / (F / Z);
	return st->converged ? 0 : PRSM_ENOCONVERGE;
}

/* A warm solve along a path (the TE record and the revolution's angles, docs/model/errors-and-assembly.md
 * "Elastic model"): the previous angle's state is close, so Newton on the whole system at once,
 * unknowns u and every w_j, converges in two or three evaluations of the contacts where the nested
 * solve below re-balances every roller at each of its own iterates of u (about three times the
 * contact evaluations). With h_j = S_j(w_j) - N_j(u - w_j) and R = sum_j N_j - F the Jacobian is an
 * arrow: eliminating dw_j = (N_j' du - h_j) / (S_j' + N_j') leaves one equation for du,
 *     du sum_j S_j' N_j' / (S_j' + N_j') = -R - sum_j N_j' h_j / (S_j' + N_j').
 * It stops at the nested solve's own tests (|R| <= 1e-11 F, every closed roller |h_j| <= 1e-12 of
 * its load), so both give the same state to those tolerances; it gives up (returns 0, the caller
 * runs the bracketed nested solve from the same start) when a step leaves u's bracket or a roller's,
 * or after a few iterations: Newton's convergence here is not guaranteed, the nested solve's is. */
#define JOINT_MAX_ITERATIONS 8

static int solve_joint(prsm_assembly_state *st, const prsm_assembly *as, const prsm_assembly_gaps *g, double F,
                       const double *gs_min, const double *gn_min, double lo, double hi)
{
	const int Z = as->rollers, nt = as->threads;
	const double Ks = as->k_axial[0], Kn = as->k_axial[1];
	double u = st->u_mm, w[PRSM_ERRORS_MAX_ROLLERS];
	double h[PRSM_ERRORS_MAX_ROLLERS], dS[PRSM_ERRORS_MAX_ROLLERS], dN[PRSM_ERRORS_MAX_ROLLERS];
	double load[PRSM_ERRORS_MAX_ROLLERS];
	if (!(u > lo && u < hi))
		return 0;
	for (int j = 0; j < Z; j++)
		w[j] = st->w_mm[j];
	for (int it = 1; it <= JOINT_MAX_ITERATIONS; it++) {
		/* den: the system's stiffness dF/du, sum_j S_j' N_j' / (S_j' + N_j') */
		double R = -F, den = 0.0, num = 0.0;
		int balanced = 1;
		for (int j = 0; j < Z; j++) {
			const double wlo = gs_min[j], whi = u - gn_min[j];
			if (!(whi > wlo)) {
				/* the chain is open: the roller carries nothing (as roller_balance) */
				w[j] = wlo;
				h[j] = dS[j] = dN[j] = load[j] = 0.0;
				continue;
			}
			if (!(w[j] > wlo && w[j] < whi))
				w[j] = 0.5 * (wlo + whi);
			const double S = side_force(&g->gap_mm[0][j * nt], nt, Ks, w[j], &dS[j]);
			const double N = side_force(&g->gap_mm[1][j * nt], nt, Kn, u - w[j], &dN[j]);
			h[j] = S - N;
			load[j] = 0.5 * (S + N);
			R += N;
			if (!(fabs(h[j]) <= 1e-12 * (S + N)))
				balanced = 0;
			const double d = dS[j] + dN[j];
			if (d > 0.0) {
				den += dS[j] * dN[j] / d;
				num += dN[j] * h[j] / d;
			}
		}
		if (!isfinite(R) || !isfinite(num))
			return 0;
		if (balanced && fabs(R) <= 1e-11 * F) {
			st->u_mm = u;
			st->stiffness_N_per_mm = den;
			for (int j = 0; j < Z; j++) {
				st->w_mm[j] = w[j];
				st->roller_load_N[j] = load[j];
			}
			st->iterations = it;
			return 1;
		}
		if (!(den > 0.0))
			return 0;
		const double du = (-R - num) / den, nu = u + du;
		if (!(nu > lo && nu < hi))
			return 0;
		for (int j = 0; j < Z; j++) {
			const double d = dS[j] + dN[j];
			if (d > 0.0)
				w[j] += (dN[j] * du - h[j]) / d;
		}
		u = nu;
	}
	return 0;
}

int prsm_assembly_solve(prsm_assembly_state *st, const prsm_assembly *as,
                        const prsm_assembly_gaps *g, double F, int warm)
{
	const int Z = as->rollers, nt = as->threads;
	const double Ks = as->k_axial[0], Kn = as->k_axial[1];
	double gs_min[PRSM_ERRORS_MAX_ROLLERS], gn_min[PRSM_ERRORS_MAX_ROLLERS];
	double chain_lo = INFINITY, chain_hi = -INFINITY, chain_mean = 0.0;
	/* every gap finite: their sum is (gaps are lengths of a mm or so, far from overflowing) */
	double all = 0.0;
	for (int i = 0; i < Z * nt; i++)
		all += g->gap_mm[0][i] + g->gap_mm[1][i];
	const int finite = isfinite(F) && F > 0.0 && isfinite(all);
	if (!finite) {
		/* docs/model/errors-and-assembly.md: nothing to balance; reported, and the state says so */
		memset(st, 0, sizeof *st);
		st->load_N = F;
		st->u_mm = NAN;
		st->stiffness_N_per_mm = NAN;
		st->sharing_factor = NAN;
		return PRSM_ENOCONVERGE;
	}
	for (int j = 0; j < Z; j++) {
		gs_min[j] = min_of(&g->gap_mm[0][j * nt], nt);
		gn_min[j] = min_of(&g->gap_mm[1][j * nt], nt);
		const double c = gs_min[j] + gn_min[j];
		chain_lo = fmin(chain_lo, c);
		chain_hi = fmax(chain_hi, c);
		chain_mean += c / Z;
	}
	/* bracket (docs/model/errors-and-assembly.md): below the smallest closed chain nothing carries load; once every
	 * chain is closed by the approach that one contact per side needs for F, every roller
	 * carries at least F */
	const double ds = pow(F / Ks, 2.0 / 3.0), dn = pow(F / Kn, 2.0 / 3.0);
	double lo = chain_lo, hi = chain_hi + ds + dn;
	if (warm && st->gaps_known) {
		/* predictor: the chains moved by dc_j; the nut follows their mean weighted by each roller's
		 * stiffness (Hertz: dF/du ~ F^{1/3}), each roller keeps its share of its approach */
		double num = 0.0, den = 0.0;
		for (int j = 0; j < Z; j++) {
			const double k = st->roller_load_N[j];
			num += k * (gs_min[j] + gn_min[j] - st->gs_min_mm[j] - st->gn_min_mm[j]);
			den += k;
		}
		const double u_old = st->u_mm;
		st->u_mm = den > 0.0 ? u_old + num / den : u_old;
		for (int j = 0; j < Z; j++) {
			const double a_old = u_old - st->gs_min_mm[j] - st->gn_min_mm[j];
			const double a_new = st->u_mm - gs_min[j] - gn_min[j];
			const double share = a_old > 0.0 ? (st->w_mm[j] - st->gs_min_mm[j]) / a_old : 0.5;
			st->w_mm[j] = gs_min[j] + (a_new > 0.0 ? a_new : 0.0) * share;
		}
	}
	if (warm && solve_joint(st, as, g, F, gs_min, gn_min, lo, hi))
		return finish(st, as, F, 1, gs_min, gn_min);
	double u;
	if (warm && st->u_mm > lo && st->u_mm < hi) {
		u = st->u_mm;
	} else {
		/* equal sharing over every contact */
		const double f = F / ((double)Z * nt);
		u = chain_mean + pow(f / Ks, 2.0 / 3.0) + pow(f / Kn, 2.0 / 3.0);
		if (!(u > lo && u < hi))
			u = 0.5 * (lo + hi);
		for (int j = 0; j < Z; j++)
			st->w_mm[j] = gs_min[j] + pow(f / Ks, 2.0 / 3.0);
	}
	double total = 0.0, dtotal = 0.0, dw[PRSM_ERRORS_MAX_ROLLERS];
	int it, done = 0, rollers_ok = 1;
	for (it = 1; it <= PRSM_ASSEMBLY_MAX_ITERATIONS; it++) {
		total = dtotal = 0.0;
		rollers_ok = 1;
		for (int j = 0; j < Z; j++) {
			double dF;
			int ok;
			st->roller_load_N[j] = roller_balance(&g->gap_mm[0][j * nt], &g->gap_mm[1][j * nt], nt,
			                                      Ks, Kn, u, gs_min[j], gn_min[j], &st->w_mm[j], &dF,
			                                      &dw[j], &ok);
			rollers_ok &= ok;
			total += st->roller_load_N[j];
			dtotal += dF;
		}
		const double r = total - F;
		if (fabs(r) <= 1e-11 * F) {
			done = 1;
			break;
		}
		const double nu = safeguarded_step(u, r, dtotal, &lo, &hi);
		if (fabs(nu - u) <= 1e-15 * (1.0 + fabs(u)) || hi - lo <= 1e-15 * (1.0 + fabs(u))) {
			u = nu;
			done = 1;
			break;
		}
		/* move the rollers with the nut as the linearisation says: dw/du = N'/(S' + N') */
		for (int j = 0; j < Z; j++)
			st->w_mm[j] += dw[j] * (nu - u);
		u = nu;
	}
	st->u_mm = u;
	st->iterations = done ? it : PRSM_ASSEMBLY_MAX_ITERATIONS;
	st->stiffness_N_per_mm = dtotal;
	/* docs/model/errors-and-assembly.md: a solve that ran out of iterations, or whose last iterate is not finite, is
	 * reported, not passed on as a result */
	return finish(st, as, F, done && rollers_ok && isfinite(u) && isfinite(total), gs_min, gn_min);
}
