/*
 * loaddist.c: the spring-chain load distribution over the threads and the axial stiffness of
 * the nut unit (docs/model/kinematics-efficiency-stiffness-life.md, "Load distribution over threads"). The model, the sign conventions
 * and the solver are described in loaddist.h.
 */
#include "model/loaddist.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Band of the Jacobian (unknowns and equations ordered thread by thread, see loaddist.h):
 * KL sub- and KU superdiagonals; LU with partial pivoting needs KL more superdiagonals. */
#define KL 2
#define KU 2
#define LDAB (2 * KL + KU + 1)

/* Unknown (and equation) index of thread i: the contact parameters t_i (screw side), tau_i (nut
 * side), the cumulative loads T_i, U_i (T, U only for i < n_t - 1). */
#define IA(i) (4 * (i))
#define IB(i) (4 * (i) + 1)
#define IT(i) (4 * (i) + 2)
#define IU(i) (4 * (i) + 3)

/* Floor of dq/dt while iterating, relative to its value at the equal share, - */
#define STIFFNESS_FLOOR 1e-12
/* Full steps taken when no damping passes the monotonicity test */
#define MAX_JUMPS 8
/* Smallest damping factor tried, - */
#define STEP_MIN 1e-8

/* Contact law of one side in axial terms: compression = hertz q^(2/3) + linear q. */
typedef struct {
	double hertz;   /* C n_z^(-5/3), mm/N^(2/3) (0: no Hertz term) */
	double linear;  /* thread (+ C/n_z^2 for the linear law), mm/N */
} contact_law;

/* One iterate: unknowns, residuals and the contact states at the unknowns. */
typedef struct {
	double *x;       /* 4 n_t - 2 unknowns: t_i, tau_i (contact parameters: N^(2/3) with a
	                    Hertz term, else N), T_i, U_i (N) */
	double *r;       /* residuals: equilibria (N), compatibilities (mm) */
	double *load[2]; /* per side: axial contact loads q(t), N */
	double *dload[2];/* per side: dq/dt, N per unit of t */
	double *comp[2]; /* per side: compression e(t), mm */
	double *dcomp[2];/* per side: de/dt, mm per unit of t */
	double max_force_residual; /* largest |equilibrium residual|, N */
	double max_compat_residual;/* largest |compatibility residual|, mm */
} iterate;

struct prsm_loaddist_workspace {
	int capacity;    /* largest n_t */
	iterate it[2];   /* current and trial, swapped on acceptance */
	double *band;    /* (4 n_t - 2) x LDAB, column-major band (LAPACK layout) */
	int *piv;        /* pivot rows */
	double *inv_diag;/* reciprocals of the pivots */
	double *step;    /* Newton correction / right-hand side */
	double *step2;   /* simplified Newton correction of a trial */
	double *normal[2]; /* per side: normal loads, N */
};

#define AB(ab, i, j) (ab)[(size_t)(j) * LDAB + (KL + KU) + (i) - (j)]

/* ---- banded LU with partial pivoting (the unblocked LAPACK dgbtf2/dgbtrs scheme) ---- */

/* Factorise the N x N band matrix in ab in place; inv_diag receives the reciprocals of U's
 * diagonal. Returns 0, or -1 for a zero pivot. */
static int band_factor(double *ab, int *piv, double *inv_diag, int N)
{
	for (int j = 0; j < N; j++) {
		const int km = KL < N - 1 - j ? KL : N - 1 - j;
		int p = j;
		double amax = fabs(AB(ab, j, j));
		for (int i = j + 1; i <= j + km; i++)
			if (fabs(AB(ab, i, j)) > amax) {
				amax = fabs(AB(ab, i, j));
				p = i;
			}
		piv[j] = p;
		if (!(amax > 0.0))
			return -1;
		const int ju = j + KL + KU < N - 1 ? j + KL + KU : N - 1;
		if (p != j)
			for (int c = j; c <= ju; c++) {
				const double t = AB(ab, p, c);
				AB(ab, p, c) = AB(ab, j, c);
				AB(ab, j, c) = t;
			}
		const double inv = 1.0 / AB(ab, j, j);
		inv_diag[j] = inv;
		for (int i = j + 1; i <= j + km; i++)
			AB(ab, i, j) *= inv;
		for (int c = j + 1; c <= ju; c++) {
			const double t = AB(ab, j, c);
			if (t != 0.0)
				for (int i = j + 1; i <= j + km; i++)
					AB(ab, i, c) -= AB(ab, i, j) * t;
		}
	}
	return 0;
}

/* Solve with the factors of band_factor; b is overwritten by the solution. */
static void band_solve(const double *ab, const int *piv, const double *inv_diag, int N, double *b)
{
	for (int j = 0; j < N; j++) {
		const int km = KL < N - 1 - j ? KL : N - 1 - j;
		const int p = piv[j];
		if (p != j) {
			const double t = b[p];
			b[p] = b[j];
			b[j] = t;
		}
		for (int i = j + 1; i <= j + km; i++)
			b[i] -= AB(ab, i, j) * b[j];
	}
	for (int j = N - 1; j >= 0; j--) {
		b[j] *= inv_diag[j];
		const double t = b[j];
		for (int i = j - KL - KU > 0 ? j - KL - KU : 0; i < j; i++)
			b[i] -= AB(ab, i, j) * t;
	}
}

/* ---- the contact law (docs/model/kinematics-efficiency-stiffness-life.md: Hertz in series with the thread) ----
 *
 * A contact's state is the parameter t of the curve (compression e, load q), explicit both ways:
 *   Hertz term present: t = q^(2/3) for t > 0:  q = t^(3/2),  e = t (hertz + linear t^(1/2));
 *                       t <= 0 (lift-off):       q = 0,        e = hertz t;
 *   no Hertz term:      t = q for t > 0:         q = t,        e = linear t;  t <= 0: q = 0.
 * de/dt > 0 everywhere (the compression can always move), so no law is inverted while
 * iterating; dq/dt = 0 where the contact carries nothing. */

static int law_is_hertz(const contact_law *law)
{
	return law->hertz > 0.0;
}

/* Parameter t of a contact carrying q >= 0. */
static double law_parameter(const contact_law *law, double q_N)
{
	if (!law_is_hertz(law))
		return q_N;
	const double s = cbrt(q_N);
	return s * s;
}

/* Compression (mm) at parameter t and its derivative. */
static void law_state(const contact_law *law, double t, double *q, double *dq, double *e,
                      double *de)
{
	if (!law_is_hertz(law)) {
		*e = law->linear * t;
		*de = law->linear;
		*q = t > 0.0 ? t : 0.0;
		*dq = t > 0.0 ? 1.0 : 0.0;
		return;
	}
	if (t > 0.0) {
		const double r = sqrt(t);
		*q = t * r;
		*dq = 1.5 * r;
		*e = t * (law->hertz + law->linear * r);
		*de = law->hertz + 1.5 * law->linear * r;
	} else {
		*q = 0.0;
		*dq = 0.0;
		*e = law->hertz * t;
		*de = law->hertz;
	}
}

static void make_laws(contact_law law[2], const prsm_loaddist_params *p)
{
	for (int side = 0; side < 2; side++) {
		const prsm_loaddist_side *s = &p->side[side];
		const double nz = s->axial_component;
		if (p->contact_law == PRSM_LOADDIST_LINEAR) {
			/* delta_n = C Q, Q = q/n_z, axial delta_n/n_z */
			law[side].hertz = 0.0;
			law[side].linear = s->contact_coefficient / (nz * nz) + s->thread_mm_per_N;
		} else {
			/* delta_n = C Q^(2/3), axial delta_n/n_z = C n_z^(-5/3) q^(2/3) */
			law[side].hertz = s->contact_coefficient / (nz * cbrt(nz * nz));
			law[side].linear = s->thread_mm_per_N;
		}
	}
}

static double gap_at(const prsm_loaddist_side *s, int i)
{
	return s->gap_mm ? s->gap_mm[i] : 0.0;
}

/* ---- the spring chain ---- */

/* Segment compliances per roller, mm/N: c_s, c_r, c_n (docs/model/kinematics-efficiency-stiffness-life.md; core and body x Z). */
typedef struct {
	double screw, roller, nut;
} chain;

/* Contact states and residuals of it->x. */
static void evaluate(iterate *it, const prsm_loaddist_params *p, const contact_law law[2],
                     const chain *ch, double W)
{
	const int n = p->threads;
	const double *x = it->x;
	for (int i = 0; i < n; i++) {
		law_state(&law[0], x[IA(i)], &it->load[0][i], &it->dload[0][i], &it->comp[0][i],
		          &it->dcomp[0][i]);
		law_state(&law[1], x[IB(i)], &it->load[1][i], &it->dload[1][i], &it->comp[1][i],
		          &it->dcomp[1][i]);
	}
	double rmax = 0.0, cmax = 0.0;
	for (int i = 0; i < n; i++) {
		const double T_prev = i == 0 ? W : x[IT(i - 1)], U_prev = i == 0 ? W : x[IU(i - 1)];
		const double T = i == n - 1 ? 0.0 : x[IT(i)], U = i == n - 1 ? 0.0 : x[IU(i)];
		/* equilibria: T_{i-1} - T_i = p_i, U_{i-1} - U_i = q_i */
		const double r1 = T_prev - T - it->load[0][i];
		const double r2 = U_prev - U - it->load[1][i];
		it->r[IA(i)] = r1;
		it->r[IB(i)] = r2;
		if (fabs(r1) > rmax) rmax = fabs(r1);
		if (fabs(r2) > rmax) rmax = fabs(r2);
		if (i == n - 1)
			break;
		/* compatibilities over the pitch from thread i to i+1: a = gap + compression */
		const double R = U - T;
		const double N = p->load_entry == PRSM_LOAD_ENTRY_SAME ? -U : W - U;
		const double da = gap_at(&p->side[0], i + 1) - gap_at(&p->side[0], i) +
		                  it->comp[0][i + 1] - it->comp[0][i];
		const double db = gap_at(&p->side[1], i + 1) - gap_at(&p->side[1], i) +
		                  it->comp[1][i + 1] - it->comp[1][i];
		const double r3 = da - (ch->roller * R - ch->screw * T);
		const double r4 = db - (ch->nut * N - ch->roller * R);
		it->r[IT(i)] = r3;
		it->r[IU(i)] = r4;
		if (fabs(r3) > cmax) cmax = fabs(r3);
		if (fabs(r4) > cmax) cmax = fabs(r4);
	}
	it->max_force_residual = rmax;
	it->max_compat_residual = cmax;
}

/* Jacobian of the residuals at it into the band (dq/dt at least dq_floor). */
static void jacobian(double *ab, const iterate *it, const prsm_loaddist_params *p, const chain *ch,
                     double dq_floor)
{
	const int n = p->threads, N = 4 * n - 2;
	memset(ab, 0, (size_t)N * LDAB * sizeof *ab);
	for (int i = 0; i < n; i++) {
		const double ks = it->dload[0][i] > dq_floor ? it->dload[0][i] : dq_floor;
		const double kn = it->dload[1][i] > dq_floor ? it->dload[1][i] : dq_floor;
		/* E1_i = T_{i-1} - T_i - q(t_i), E2_i likewise */
		AB(ab, IA(i), IA(i)) = -ks;
		AB(ab, IB(i), IB(i)) = -kn;
		if (i > 0) {
			AB(ab, IA(i), IT(i - 1)) = 1.0;
			AB(ab, IB(i), IU(i - 1)) = 1.0;
		}
		if (i == n - 1)
			break;
		AB(ab, IA(i), IT(i)) = -1.0;
		AB(ab, IB(i), IU(i)) = -1.0;
		/* C1_i = e(t_{i+1}) - e(t_i) (+ gaps) - c_r (U_i - T_i) + c_s T_i */
		AB(ab, IT(i), IA(i + 1)) = it->dcomp[0][i + 1];
		AB(ab, IT(i), IA(i)) = -it->dcomp[0][i];
		AB(ab, IT(i), IT(i)) = ch->roller + ch->screw;
		AB(ab, IT(i), IU(i)) = -ch->roller;
		/* C2_i = e(tau_{i+1}) - e(tau_i) (+ gaps) - c_n N_i(U_i) + c_r (U_i - T_i) */
		AB(ab, IU(i), IB(i + 1)) = it->dcomp[1][i + 1];
		AB(ab, IU(i), IB(i)) = -it->dcomp[1][i];
		AB(ab, IU(i), IT(i)) = -ch->roller;
		AB(ab, IU(i), IU(i)) = ch->nut + ch->roller; /* dN_i/dU_i = -1 for both entries */
	}
}

/* Norm of a correction v, each unknown over its scale: its size in x, but at least the
 * contact parameter at the equal share or W (Deuflhard's relative scaling). */
static double scaled_norm(const double *v, const double *x, int n, const double t_ref[2], double W)
{
	double sum = 0.0;
	for (int i = 0; i < n; i++) {
		const double a = v[IA(i)] / fmax(fabs(x[IA(i)]), t_ref[0]);
		const double b = v[IB(i)] / fmax(fabs(x[IB(i)]), t_ref[1]);
		sum += a * a + b * b;
		if (i < n - 1) {
			const double T = v[IT(i)] / W, U = v[IU(i)] / W;
			sum += T * T + U * U;
		}
	}
	return sqrt(sum);
}

/* Start: the rigid-body solution, every contact at the equal share W/n_t (all contacts
 * loaded, so the first tangent sees every contact; a gap-aware start that lifts contacts off
 * from the outset converged worse). */
static void start_point(iterate *it, const prsm_loaddist_params *p, const contact_law law[2],
                        double W)
{
	const int n = p->threads;
	double *x = it->x;
	const double share = W / n;
	for (int i = 0; i < n; i++) {
		x[IA(i)] = law_parameter(&law[0], share);
		x[IB(i)] = law_parameter(&law[1], share);
		if (i < n - 1)
			x[IT(i)] = x[IU(i)] = W * (double)(n - 1 - i) / (double)n;
	}
}

static int check_params(const prsm_loaddist_workspace *ws, const prsm_loaddist_params *p,
                        double load_N, prsm_error *err)
{
	if (!ws)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: no workspace (allocate "
		                      "one with prsm_loaddist_alloc)");
	if (p->threads < 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %d engaged threads; "
		                      "needs at least 1", p->threads);
	if (p->threads > ws->capacity)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %d engaged threads, "
		                      "the workspace holds %d", p->threads, ws->capacity);
	if (p->rollers < 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %d rollers; needs at "
		                      "least 1", p->rollers);
	if (p->load_entry != PRSM_LOAD_ENTRY_SAME && p->load_entry != PRSM_LOAD_ENTRY_OPPOSITE)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: unknown load entry %d",
		                      p->load_entry);
	if (p->contact_law != PRSM_LOADDIST_HERTZ && p->contact_law != PRSM_LOADDIST_LINEAR)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: unknown contact law %d",
		                      p->contact_law);
	if (!isfinite(load_N) || !(load_N > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: axial load %g N; needs "
		                      "a finite load > 0 (Hertz contacts have no stiffness at 0)", load_N);
	if (!(p->tolerance > 0.0) || !isfinite(p->tolerance) || p->max_iterations < 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: tolerance %g and "
		                      "iterations %d; need a finite tolerance > 0 and at least 1 iteration",
		                      p->tolerance, p->max_iterations);
	const double seg[3] = {p->screw_segment_mm_per_N, p->roller_segment_mm_per_N,
	                       p->nut_segment_mm_per_N};
	static const char *const seg_name[3] = {"screw", "roller", "nut"};
	for (int k = 0; k < 3; k++)
		if (!isfinite(seg[k]) || seg[k] < 0.0)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %s segment "
			                      "compliance %g mm/N; needs a finite value >= 0", seg_name[k], seg[k]);
	for (int side = 0; side < 2; side++) {
		const prsm_loaddist_side *s = &p->side[side];
		const char *who = side == PRSM_SIDE_SCREW ? "screw-roller" : "nut-roller";
		if (!isfinite(s->contact_coefficient) || s->contact_coefficient < 0.0 ||
		    !isfinite(s->thread_mm_per_N) || s->thread_mm_per_N < 0.0 ||
		    !(s->contact_coefficient > 0.0 || s->thread_mm_per_N > 0.0))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %s contact "
			                      "coefficient %g and thread compliance %g mm/N; need finite values "
			                      ">= 0, not both 0", who, s->contact_coefficient, s->thread_mm_per_N);
		if (!(s->axial_component > 0.0 && s->axial_component <= 1.0))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %s axial component "
			                      "of the normal %g; needs (0, 1]", who, s->axial_component);
		if (s->gap_mm)
			for (int i = 0; i < p->threads; i++)
				if (!isfinite(s->gap_mm[i]))
					return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: %s gap "
					                      "of thread %d is not finite", who, i + 1);
	}
	return 0;
}

prsm_loaddist_workspace *prsm_loaddist_alloc(int max_threads)
{
	if (max_threads < 1 || max_threads > 1000000)
		return NULL;
	prsm_loaddist_workspace *ws = calloc(1, sizeof *ws);
	if (!ws)
		return NULL;
	const size_t n = (size_t)max_threads, N = 4 * n - 2;
	/* one block: 2 iterates (x, r: N; 4 per-contact arrays per side: n), band, step,
	 * simplified correction, reciprocal pivots, normals */
	const size_t doubles = 2 * (2 * N + 8 * n) + N * LDAB + 3 * N + 2 * n;
	double *block = calloc(doubles, sizeof *block);
	ws->piv = calloc(N, sizeof *ws->piv);
	if (!block || !ws->piv) {
		free(block);
		free(ws->piv);
		free(ws);
		return NULL;
	}
	double *q = block;
	for (int k = 0; k < 2; k++) {
		ws->it[k].x = q; q += N;
		ws->it[k].r = q; q += N;
		for (int side = 0; side < 2; side++) {
			ws->it[k].load[side] = q; q += n;
			ws->it[k].dload[side] = q; q += n;
			ws->it[k].comp[side] = q; q += n;
			ws->it[k].dcomp[side] = q; q += n;
		}
	}
	ws->band = q; q += N * LDAB;
	ws->step = q; q += N;
	ws->step2 = q; q += N;
	ws->inv_diag = q; q += N;
	ws->normal[0] = q; q += n;
	ws->normal[1] = q; q += n;
	assert((size_t)(q - block) == doubles);
	ws->capacity = max_threads;
	return ws;
}

void prsm_loaddist_free(prsm_loaddist_workspace *ws)
{
	if (!ws)
		return;
	free(ws->it[0].x); /* the start of the block */
	free(ws->piv);
	free(ws);
}

int prsm_loaddist_capacity(const prsm_loaddist_workspace *ws)
{
	return ws ? ws->capacity : 0;
}

/* Result fields of one side from the loads (docs/model/kinematics-efficiency-stiffness-life.md: p_max ~ Q^(1/3)). */
static void side_result(prsm_loaddist_side_result *out, double *normal, const double *load,
                        const prsm_loaddist_side *s, int n, double W)
{
	int imax = 0, lifted = 0;
	for (int i = 0; i < n; i++) {
		normal[i] = load[i] / s->axial_component;
		if (load[i] > load[imax]) imax = i;
		if (!(load[i] > 0.0)) lifted++;
	}
	out->max_index = imax;
	out->max_axial_N = load[imax];
	out->max_normal_N = normal[imax];
	out->max_over_mean = load[imax] / (W / (double)n);
	out->lifted_off = lifted;
	const prsm_hertz *h = &s->reference;
	if (h->load_N > 0.0 && isfinite(h->load_N)) {
		const double scale = cbrt(normal[imax] / h->load_N);
		out->p_max_MPa = h->p_max_MPa * scale;
		out->a_mm = h->a_mm * scale;
		out->b_mm = h->b_mm * scale;
	} else {
		out->p_max_MPa = out->a_mm = out->b_mm = NAN;
	}
}

int prsm_loaddist_solve(prsm_loaddist_result *out, prsm_loaddist_workspace *ws,
                        const prsm_loaddist_params *p, double load_N, prsm_error *err)
{
	assert(out && p);
	memset(out, 0, sizeof *out);
	int rc = check_params(ws, p, load_N, err);
	if (rc)
		return rc;
	const int n = p->threads, N = 4 * n - 2;
	const double W = load_N / (double)p->rollers; /* N per roller */
	contact_law law[2];
	make_laws(law, p);
	const chain ch = {(double)p->rollers * p->screw_segment_mm_per_N, p->roller_segment_mm_per_N,
	                  (double)p->rollers * p->nut_segment_mm_per_N};
	/* scales at the equal share W/n_t: the contact parameters and compressions there, and
	 * dq/dt there for the dq_floor */
	const double share = W / n;
	double t_ref[2], e_ref = 0.0, dq_floor = INFINITY;
	for (int side = 0; side < 2; side++) {
		double q, dq, e, de;
		t_ref[side] = law_parameter(&law[side], share);
		law_state(&law[side], t_ref[side], &q, &dq, &e, &de);
		e_ref += e; /* mm */
		if (STIFFNESS_FLOOR * dq < dq_floor)
			dq_floor = STIFFNESS_FLOOR * dq;
	}
	/* lengths a compatibility adds up: compressions, gaps, body stretch under W, mm */
	double length = e_ref + (ch.screw + ch.roller + ch.nut) * W;
	for (int side = 0; side < 2; side++)
		for (int i = 0; i < n; i++)
			length = fmax(length, fabs(gap_at(&p->side[side], i)));

	iterate *cur = &ws->it[0], *trial = &ws->it[1];
	start_point(cur, p, law, W);
	evaluate(cur, p, law, &ch, W);
	/* converged: every equilibrium within tolerance x W, every compatibility within
	 * tolerance x the lengths it adds up */
	const double tol = p->tolerance * W, tol_compat = p->tolerance * length;
	int iter = 0, jumps = 0;
	rc = PRSM_ENOCONVERGE;
	while (1) {
		if (cur->max_force_residual <= tol && cur->max_compat_residual <= tol_compat) {
			rc = 0;
			break;
		}
		if (iter >= p->max_iterations)
			break;
		iter++;
		/* Newton correction J dx = -r */
		jacobian(ws->band, cur, p, &ch, dq_floor);
		if (band_factor(ws->band, ws->piv, ws->inv_diag, N))
			break;
		for (int k = 0; k < N; k++)
			ws->step[k] = -cur->r[k];
		band_solve(ws->band, ws->piv, ws->inv_diag, N, ws->step);
		const double norm_dx = scaled_norm(ws->step, cur->x, n, t_ref, W);
		/* damping by the natural monotonicity test (Deuflhard's affine-covariant Newton,
		 * NLEQ-ERR): accept lambda when the simplified correction dxbar = -J^-1 r(x + lambda dx)
		 * is shorter than (1 - lambda/4) |dx|. Unlike a residual norm it does not depend on how
		 * the equations (forces, lengths) are scaled. */
		double lambda = 1.0;
		int accepted = 0;
		while (lambda >= STEP_MIN) {
			for (int k = 0; k < N; k++)
				trial->x[k] = cur->x[k] + lambda * ws->step[k];
			evaluate(trial, p, law, &ch, W);
			if (trial->max_force_residual <= tol && trial->max_compat_residual <= tol_compat) {
				accepted = 1;
				break;
			}
			for (int k = 0; k < N; k++)
				ws->step2[k] = -trial->r[k];
			band_solve(ws->band, ws->piv, ws->inv_diag, N, ws->step2);
			const double norm_bar = scaled_norm(ws->step2, cur->x, n, t_ref, W);
			if (norm_bar <= (1.0 - 0.25 * lambda) * norm_dx) {
				accepted = 1;
				break;
			}
			/* the estimate of the contraction: lambda' = |dx| lambda^2 / (2 |dxbar - (1-lambda) dx|) */
			for (int k = 0; k < N; k++)
				ws->step2[k] -= (1.0 - lambda) * ws->step[k];
			const double mu = 0.5 * norm_dx * lambda * lambda / scaled_norm(ws->step2, cur->x, n, t_ref, W);
			lambda = fmax(0.1 * lambda, fmin(0.5 * lambda, mu));
		}
		if (!accepted) {
			/* no damping passes the test: a lift-off kink or the active set changing across
			 * the step. Take the full step once in a while (the new active set is often the
			 * right one), else give up. */
			if (jumps >= MAX_JUMPS)
				break;
			jumps++;
			for (int k = 0; k < N; k++)
				trial->x[k] = cur->x[k] + ws->step[k];
			evaluate(trial, p, law, &ch, W);
		}
		iterate *t = cur;
		cur = trial;
		trial = t;
	}

	/* results from the last iterate */
	out->threads = n;
	out->rollers = p->rollers;
	out->load_entry = p->load_entry;
	out->load_N = load_N;
	out->roller_load_N = W;
	out->axial_screw_N = cur->load[0];
	out->axial_nut_N = cur->load[1];
	out->normal_screw_N = ws->normal[0];
	out->normal_nut_N = ws->normal[1];
	for (int side = 0; side < 2; side++)
		side_result(&out->side[side], ws->normal[side], cur->load[side], &p->side[side], n, W);
	out->iterations = iter;
	out->residual_N = cur->max_force_residual;
	out->residual_mm = cur->max_compat_residual;
	/* u (loaddist.h): a = gap + compression */
	const double *x = cur->x;
	const int at = p->load_entry == PRSM_LOAD_ENTRY_SAME ? 0 : n - 1;
	double u = gap_at(&p->side[0], at) + cur->comp[0][at] + gap_at(&p->side[1], at) + cur->comp[1][at];
	if (p->load_entry == PRSM_LOAD_ENTRY_OPPOSITE)
		for (int i = 0; i < n - 1; i++)
			u += ch.screw * x[IT(i)];
	out->approach_mm = u;
	out->stiffness_N_per_mm = NAN;
	if (rc)
		return prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "load distribution: Newton stopped "
		                      "after %d iterations with residuals %.3g N and %.3g mm (tolerances "
		                      "%.3g N, %.3g mm)", iter, cur->max_force_residual,
		                      cur->max_compat_residual, tol, tol_compat);

	/* tangent: J dx/dW = -dr/dW with the exact contact stiffnesses (a dq_floor only if singular) */
	jacobian(ws->band, cur, p, &ch, 0.0);
	if (band_factor(ws->band, ws->piv, ws->inv_diag, N)) {
		jacobian(ws->band, cur, p, &ch, dq_floor);
		if (band_factor(ws->band, ws->piv, ws->inv_diag, N))
			return prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "load distribution: the tangent "
			                      "stiffness matrix is singular at the solution");
	}
	double *v = ws->step;
	memset(v, 0, (size_t)N * sizeof *v);
	v[IA(0)] = -1.0; /* dE1_1/dW = dT_0/dW = 1 */
	v[IB(0)] = -1.0;
	if (p->load_entry == PRSM_LOAD_ENTRY_OPPOSITE)
		for (int i = 0; i < n - 1; i++)
			v[IU(i)] = ch.nut; /* dC2_i/dW = -c_n dN_i/dW = -c_n */
	band_solve(ws->band, ws->piv, ws->inv_diag, N, v);
	double du = cur->dcomp[0][at] * v[IA(at)] + cur->dcomp[1][at] * v[IB(at)];
	if (p->load_entry == PRSM_LOAD_ENTRY_OPPOSITE)
		for (int i = 0; i < n - 1; i++)
			du += ch.screw * v[IT(i)];
	/* K = dF/du = Z dW/du */
	out->stiffness_N_per_mm = (double)p->rollers / du;
	return 0;
}

int prsm_loaddist_curve(double *load_N, double *approach_mm, double *stiffness_N_per_mm,
                        prsm_loaddist_workspace *ws, const prsm_loaddist_params *p,
                        double max_load_N, size_t points, prsm_error *err)
{
	if (points < 1)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load-deflection curve: needs at least "
		                      "one point");
	if (!isfinite(max_load_N) || !(max_load_N > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load-deflection curve: maximum load %g N; "
		                      "needs a finite load > 0", max_load_N);
	for (size_t k = 0; k < points; k++) {
		const double F = max_load_N * (double)(k + 1) / (double)points;
		prsm_loaddist_result r;
		const int rc = prsm_loaddist_solve(&r, ws, p, F, err);
		if (rc)
			return rc;
		if (load_N) load_N[k] = F;
		if (approach_mm) approach_mm[k] = r.approach_mm;
		if (stiffness_N_per_mm) stiffness_N_per_mm[k] = r.stiffness_N_per_mm;
	}
	return 0;
}

int prsm_loaddist_params_from_design(prsm_loaddist_params *out, const prsm_design *d,
                                     const prsm_contact *screw_contact,
                                     const prsm_contact *nut_contact,
                                     const prsm_design_compliance *tc,
                                     const prsm_segment_compliance *seg, int load_entry,
                                     prsm_error *err)
{
	const prsm_loaddist_params init = PRSM_LOADDIST_PARAMS_INIT;
	*out = init;
	if (load_entry != PRSM_LOAD_ENTRY_SAME && load_entry != PRSM_LOAD_ENTRY_OPPOSITE)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "load distribution: unknown load entry %d",
		                      load_entry);
	if (d->rollers < 1 || d->engaged_threads < 1)
		return prsm_error_set(err, PRSM_EINVAL, "/assembly", "load distribution: %d rollers and "
		                      "%d engaged threads; needs at least 1 of each", d->rollers,
		                      d->engaged_threads);
	out->threads = d->engaged_threads;
	out->rollers = d->rollers;
	out->load_entry = load_entry;
	out->contact_law = PRSM_LOADDIST_HERTZ;
	const prsm_contact *c[2] = {screw_contact, nut_contact};
	const prsm_material *body[2] = {&d->screw_material, &d->nut_material};
	const prsm_material *mr = &d->roller_material;
	const double thread[2] = {tc->screw_side_mm_per_N, tc->nut_side_mm_per_N};
	for (int side = 0; side < 2; side++) {
		prsm_loaddist_side *s = &out->side[side];
		prsm_hertz *h = &s->reference;
		/* Hertz at a reference load, as in prsm_analysis_nominal (docs/model/kinematics-efficiency-stiffness-life.md) */
		if (prsm_hertz_solve(h, c[side]->curvature_per_mm[0], c[side]->curvature_per_mm[1],
		                     body[side]->E_MPa, body[side]->poisson, mr->E_MPa, mr->poisson,
		                     PRSM_LOADDIST_REFERENCE_LOAD_N) ||
		    !(h->delta_mm > 0.0))
			return prsm_error_set(err, PRSM_EGEOMETRY, "/geometry", "load distribution: the %s "
			                      "contact has non-positive relative curvature: Hertz theory does "
			                      "not apply", side == 0 ? "screw-roller" : "nut-roller");
		const double Q = PRSM_LOADDIST_REFERENCE_LOAD_N, q13 = cbrt(Q);
		s->contact_coefficient = h->delta_mm / (q13 * q13); /* delta = C Q^(2/3) */
		s->axial_component = fabs(c[side]->normal[2]);
		s->thread_mm_per_N = thread[side];
		s->gap_mm = NULL;
	}
	out->screw_segment_mm_per_N = seg->screw_mm_per_N;
	out->roller_segment_mm_per_N = seg->roller_mm_per_N;
	out->nut_segment_mm_per_N = seg->nut_mm_per_N;
	return 0;
}
