/*
 * vib_mc.c: one Monte Carlo sample of the reduced vibration model (vib_mc.h; MODEL-DYNAMICS.md
 * §8.6 on §8.3, §8.4): the linear screen (closed form) and the integration of the samples that
 * lose contact.
 *
 * The gear branch's closed form works in grouped reduced coordinates
 *     rho = (x_0 .. x_{G-1}, V_0, V_1 .. V_G)      (x_g = d_j / b_g of group g's rollers, V as the
 *                                                   state: rates per unit tau; the carrier angle,
 *                                                   a rigid mode, never enters)
 * and takes the linear system rho' = A_s rho + b_s + Re(C_s e^{i w_e tau}) + sum_k Re(D_k e^{i w_k tau})
 * of each stiffness segment s from the model's own right-hand side (vib_rhs with every contact held
 * on its loaded side): the positions enter linearly (exact differences), the friction is
 * linearised about v* by central differences, the mesh error's sin / cos terms and the thread
 * force's (Y, W) terms are exactly linear. Between two stiffness switches the solution is
 * rho(tau + h) = e^{A h} (rho(tau) - rho_p(tau)) + rho_p(tau + h) with the particular solution
 * rho_p of the constant and sinusoidal terms; the periodic solution follows from one linear solve
 * over the mesh period (a shooting step, exact for a linear system), and each TE line's response
 * z_k(tau) = e^{i w_k tau} p_k(tau) from (e^{i w_k T} I - Phi) z_k(0) = r_k.
 */
#include "dyn/vib_mc.h"

#include <complex.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "dyn/vib_internal.h"

typedef double complex cplx;

void prsm_vib_mc_sample_init(prsm_vib_mc_sample *s)
{
	memset(s, 0, sizeof *s);
	s->axial_stiffness_N_per_m = NAN;
	s->axial_half_play_m = NAN;
	s->gear_half_backlash_m = NAN;
	s->mesh_error_m = NAN;
	s->axial_damping_ratio = NAN;
	s->mesh_damping_ratio = NAN;
	s->window_rev = 8.0;
}

void prsm_vib_mc_options_init(prsm_vib_mc_options *o)
{
	memset(o, 0, sizeof *o);
	o->grid_per_segment = 64;
	o->axial_grid_per_cycle = 64;
	o->max_windows = 12;
	o->max_period = 4;
	o->period_tol = 1e-4;
	const prsm_vib_integration in = PRSM_VIB_INTEGRATION_INIT;
	o->integration = in;
	o->integration.rel_tol = 1e-9;
	o->integration.abs_tol = 1e-9;
}

/* ---- applying a sample ---- */

/* lines rounded to multiples of 1 / W, order-0 lines dropped, equal orders merged (phasor sum) */
static int round_lines(prsm_vib_te_line *out, const prsm_vib_te_line *in, int n, double W)
{
	long q[PRSM_VIB_TE_LINES_MAX];
	cplx a[PRSM_VIB_TE_LINES_MAX];
	int k = 0;
	for (int i = 0; i < n; i++) {
		const long qi = lround(in[i].order_per_rev * W);
		if (qi <= 0 || !(in[i].amplitude_m > 0.0))
			continue;
		const cplx ai = in[i].amplitude_m * cexp(I * in[i].phase_rad);
		int j = 0;
		while (j < k && q[j] != qi)
			j++;
		if (j == k) {
			q[k] = qi;
			a[k++] = ai;
		} else {
			a[j] += ai;
		}
	}
	int m = 0;
	for (int j = 0; j < k; j++) {
		if (!(cabs(a[j]) > 0.0))
			continue;
		out[m].order_per_rev = (double)q[j] / W;
		out[m].amplitude_m = cabs(a[j]);
		out[m].phase_rad = carg(a[j]);
		m++;
	}
	return m;
}

int prsm_vib_mc_apply(prsm_vib_model *m, const prsm_vib_mc_sample *s, prsm_error *err)
{
	prsm_vib_params *P = &m->par;
	if (P->kind != PRSM_VIB_REDUCED || P->branches != PRSM_VIB_BRANCHES_BOTH)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics", "the dynamic Monte Carlo takes the reduced model with both branches");
	if (!(s->window_rev > 0.0 && s->window_rev <= 1000.0))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/window_revolutions", "the window must be in (0, 1000] revolutions (got %g)",
		                      s->window_rev);
	if (!isnan(s->axial_stiffness_N_per_m)) {
		if (!(s->axial_stiffness_N_per_m > 0.0 && isfinite(s->axial_stiffness_N_per_m)))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the sample's axial stiffness is %g N/m", s->axial_stiffness_N_per_m);
		m->k_axial = s->axial_stiffness_N_per_m;
	}
	if (!isnan(s->axial_half_play_m)) {
		if (!(s->axial_half_play_m > 0.0 && isfinite(s->axial_half_play_m)))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the sample's axial half play is %g m: the thread has no play",
			                      s->axial_half_play_m);
		P->axial_half_play_m = s->axial_half_play_m;
	}
	if (!isnan(s->gear_half_backlash_m)) {
		if (!(s->gear_half_backlash_m > 0.0 && isfinite(s->gear_half_backlash_m)))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the sample's gear backlash is %g m (must be > 0)", s->gear_half_backlash_m);
		P->gear_half_backlash_m = s->gear_half_backlash_m;
	}
	if (!isnan(s->mesh_error_m)) {
		if (!(s->mesh_error_m >= 0.0 && isfinite(s->mesh_error_m)))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the sample's mesh error is %g m (must be >= 0)", s->mesh_error_m);
		P->mesh_error_m = s->mesh_error_m;
	}
	if (!isnan(s->axial_damping_ratio)) {
		if (!(s->axial_damping_ratio > 0.0 && s->axial_damping_ratio < 1.0))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the sample's axial damping ratio is %g (must be in (0, 1))",
			                      s->axial_damping_ratio);
		P->axial_damping_ratio = s->axial_damping_ratio;
	}
	if (!isnan(s->mesh_damping_ratio)) {
		if (!(s->mesh_damping_ratio > 0.0 && s->mesh_damping_ratio < 1.0))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "the sample's mesh damping ratio is %g (must be in (0, 1))",
			                      s->mesh_damping_ratio);
		P->mesh_damping_ratio = s->mesh_damping_ratio;
	}
	const double W = s->window_rev;
	prsm_vib_te_line tmp[PRSM_VIB_TE_LINES_MAX];
	if (s->te_source) {
		if (s->te_lines < 0 || s->te_lines > PRSM_VIB_TE_LINES_MAX)
			return prsm_error_set(err, PRSM_EINVAL, NULL, "%d TE lines", s->te_lines);
		P->te_lines = round_lines(tmp, s->te_line, s->te_lines, W);
	} else {
		P->te_lines = round_lines(tmp, P->te_line, P->te_lines, W);
	}
	memcpy(P->te_line, tmp, (size_t)P->te_lines * sizeof tmp[0]);
	/* §8.3.3: omega_m = z_2 k* omega_s, its order rounded to the window (vib_mc.h) */
	const long qm = lround(P->teeth_ring * P->carrier_ratio * W);
	if (qm < 1)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/window_revolutions", "the window of %g revolutions is "
		                      "shorter than a mesh period", W);
	m->mesh_order_per_rev = (double)qm / W;
	vib_core_derive(m);
	return 0;
}

/* ---- the screen's phasors, kept from one sample to the next ---- */

/* A study's tolerances change k_a, b_a, the TE lines' amplitudes and phases, b_g, e_g and the
 * damping ratios (§8.6), not the model's structure: the window, the stiffness segments, the
 * grids' times and the line and mesh frequencies are the same for every sample, and so are the
 * arguments of the screen's phasors e^{i x} (cexp) and of the mesh error's sin / cos (§8.3.3),
 * some 1,900 a sample and a sixth of the screen's instructions. The j-th such evaluation of a
 * screen is kept in slot j of a per-thread table with its argument's bits; a later screen whose
 * j-th argument has the same bits takes the kept value (the same function of the same argument:
 * the same bits), any other computes and keeps its own. The slots below memo_*_n have all been
 * written, since a screen's evaluations take the slots in order. The reference loops
 * (o->reference) compute every one. */
#define MEMO_CEXP 3072
#define MEMO_SINCOS 1024
typedef struct {
	uint64_t re, im; /* the argument's bits */
	cplx v;          /* cexp of it */
} memo_cexp_slot;
typedef struct {
	uint64_t x;  /* the argument's bits */
	double s, c; /* sin, cos of it */
} memo_sincos_slot;
static _Thread_local memo_cexp_slot memo_cexp_tab[MEMO_CEXP];
static _Thread_local memo_sincos_slot memo_sincos_tab[MEMO_SINCOS];
static _Thread_local int memo_cexp_n, memo_sincos_n; /* valid slots */

typedef struct {
	int cexp_j, sincos_j; /* the next evaluation's slot in this screen */
} memo_cursor;

static uint64_t dbits(double x)
{
	uint64_t u;
	memcpy(&u, &x, sizeof u);
	return u;
}

/* cexp(z) through the table (mc NULL: the reference, always cexp) */
static cplx memo_cexp(memo_cursor *mc, cplx z)
{
	if (mc == NULL)
		return cexp(z);
	const int j = mc->cexp_j++;
	const uint64_t re = dbits(creal(z)), im = dbits(cimag(z));
	if (j < memo_cexp_n && memo_cexp_tab[j].re == re && memo_cexp_tab[j].im == im)
		return memo_cexp_tab[j].v;
	const cplx v = cexp(z);
	if (j < MEMO_CEXP) {
		memo_cexp_tab[j].re = re;
		memo_cexp_tab[j].im = im;
		memo_cexp_tab[j].v = v;
		if (j >= memo_cexp_n)
			memo_cexp_n = j + 1;
	}
	return v;
}

/* *s = sin(x), *c = cos(x) through the table (mc NULL: always computed) */
static void memo_sincos(memo_cursor *mc, double x, double *s, double *c)
{
	if (mc != NULL) {
		const int j = mc->sincos_j++;
		const uint64_t u = dbits(x);
		if (j < memo_sincos_n && memo_sincos_tab[j].x == u) {
			*s = memo_sincos_tab[j].s;
			*c = memo_sincos_tab[j].c;
			return;
		}
		*s = sin(x);
		*c = cos(x);
		if (j < MEMO_SINCOS) {
			memo_sincos_tab[j].x = u;
			memo_sincos_tab[j].s = *s;
			memo_sincos_tab[j].c = *c;
			if (j >= memo_sincos_n)
				memo_sincos_n = j + 1;
		}
		return;
	}
	*s = sin(x);
	*c = cos(x);
}

/* ---- small dense linear algebra (n <= 2 PRSM_VIB_ROLLERS_MAX + 1) ---- */

/* Solve A x = b in place (A n x n row-major, destroyed; b gets x). Returns 0, or 1 when singular. */
static int csolve(cplx *A, cplx *b, int n)
{
	for (int k = 0; k < n; k++) {
		int p = k;
		for (int i = k + 1; i < n; i++)
			if (cabs(A[i * n + k]) > cabs(A[p * n + k]))
				p = i;
		if (!(cabs(A[p * n + k]) > 0.0))
			return 1;
		if (p != k) {
			for (int j = 0; j < n; j++) {
				const cplx t = A[k * n + j];
				A[k * n + j] = A[p * n + j];
				A[p * n + j] = t;
			}
			const cplx t = b[k];
			b[k] = b[p];
			b[p] = t;
		}
		for (int i = k + 1; i < n; i++) {
			const cplx f = A[i * n + k] / A[k * n + k];
			if (f == 0.0)
				continue;
			for (int j = k; j < n; j++)
				A[i * n + j] -= f * A[k * n + j];
			b[i] -= f * b[k];
		}
	}
	for (int i = n - 1; i >= 0; i--) {
		cplx s = b[i];
		for (int j = i + 1; j < n; j++)
			s -= A[i * n + j] * b[j];
		b[i] = s / A[i * n + i];
	}
	return 0;
}

static void matmul(double *C, const double *A, const double *B, int n)
{
	for (int i = 0; i < n; i++)
		for (int j = 0; j < n; j++) {
			double s = 0.0;
			for (int k = 0; k < n; k++)
				s += A[i * n + k] * B[k * n + j];
			C[i * n + j] = s;
		}
}

/* E = exp(A h): scaling and squaring with a Taylor series of degree 18 (||A h / 2^s|| <= 1/2) */
static void expm(double *E, const double *A, double h, int n, double *w1, double *w2)
{
	double norm = 0.0;
	for (int i = 0; i < n; i++) {
		double r = 0.0;
		for (int j = 0; j < n; j++)
			r += fabs(A[i * n + j] * h);
		norm = fmax(norm, r);
	}
	int s = 0;
	while (norm > 0.5 && s < 60) {
		norm *= 0.5;
		s++;
	}
	const double scale = ldexp(h, -s);
	const size_t nn = (size_t)n * (size_t)n;
	/* w1: term, E: sum */
	for (size_t i = 0; i < nn; i++)
		E[i] = w1[i] = 0.0;
	for (int i = 0; i < n; i++)
		E[i * n + i] = w1[i * n + i] = 1.0;
	for (int k = 1; k <= 18; k++) {
		for (int i = 0; i < n; i++)
			for (int j = 0; j < n; j++) {
				double t = 0.0;
				for (int l = 0; l < n; l++)
					t += w1[i * n + l] * A[l * n + j];
				w2[i * n + j] = t * scale / k;
			}
		memcpy(w1, w2, nn * sizeof *w1);
		for (size_t i = 0; i < nn; i++)
			E[i] += w1[i];
	}
	for (int k = 0; k < s; k++) {
		matmul(w2, E, E, n);
		memcpy(E, w2, nn * sizeof *E);
	}
}

static void matvec(double *y, const double *A, const double *x, int n)
{
	for (int i = 0; i < n; i++) {
		double s = 0.0;
		for (int j = 0; j < n; j++)
			s += A[i * n + j] * x[j];
		y[i] = s;
	}
}

static void cmatvec(cplx *y, const double *A, const cplx *x, int n)
{
	for (int i = 0; i < n; i++) {
		cplx s = 0.0;
		for (int j = 0; j < n; j++)
			s += A[i * n + j] * x[j];
		y[i] = s;
	}
}

/* cmatvec of the fast loops: each part of y[i] is 0 + A[i][0] x[0] + A[i][1] x[1] + ... in that
 * order (a real times a complex is the two parts' products), so the two parts as the two lanes of
 * an SSE2 register give the same bits as cmatvec, in half the operations. */
static void cmatvec_fast(cplx *y, const double *A, const cplx *x, int n)
{
#ifdef __SSE2__
	for (int i = 0; i < n; i++) {
		__m128d s = _mm_setzero_pd();
		for (int j = 0; j < n; j++)
			s = _mm_add_pd(s, _mm_mul_pd(_mm_set1_pd(A[i * n + j]), _mm_loadu_pd((const double *)&x[j])));
		_mm_storeu_pd((double *)&y[i], s);
	}
#else
	cmatvec(y, A, x, n);
#endif
}

/* u e for the fast loops, as the compiler's complex product computes it: (u_r e_r - u_i e_i,
 * u_r e_i + u_i e_r), and the library's product when both parts are NaN. In SSE2 lanes it is
 * u_r (e_r, e_i) + u_i (-e_i, e_r): the first lane's u_r e_r + (-(u_i e_i)) is u_r e_r - u_i e_i
 * exactly (negation is exact, and x + (-y) is x - y). e1 = (e_r, e_i), e2 = (-e_i, e_r). */
#ifdef __SSE2__
static inline __m128d cmul_lanes(const cplx *u, __m128d e1, __m128d e2, cplx e)
{
	const __m128d v = _mm_loadu_pd((const double *)u);
	const __m128d p = _mm_add_pd(_mm_mul_pd(_mm_unpacklo_pd(v, v), e1), _mm_mul_pd(_mm_unpackhi_pd(v, v), e2));
	if (_mm_movemask_pd(_mm_cmpunord_pd(p, p)) == 3) {
		const cplx q = *u * e;
		return _mm_loadu_pd((const double *)&q);
	}
	return p;
}
#endif

/* One grid step of a TE line's envelope in the fast loops: z <- E (z - u e_p) + u e_t, the
 * reference's complex loops (t1, t2: nr scratch) with the products of cmul_lanes and
 * cmatvec_fast, bit for bit. */
static void line_step(cplx *z, const cplx *u, cplx ep, cplx et, const double *E, int nr, cplx *t1, cplx *t2)
{
#ifdef __SSE2__
	const __m128d p1 = _mm_set_pd(cimag(ep), creal(ep)), p2 = _mm_set_pd(creal(ep), -cimag(ep));
	const __m128d q1 = _mm_set_pd(cimag(et), creal(et)), q2 = _mm_set_pd(creal(et), -cimag(et));
	for (int q = 0; q < nr; q++)
		_mm_storeu_pd((double *)&t1[q], _mm_sub_pd(_mm_loadu_pd((const double *)&z[q]), cmul_lanes(&u[q], p1, p2, ep)));
	cmatvec_fast(t2, E, t1, nr);
	for (int q = 0; q < nr; q++)
		_mm_storeu_pd((double *)&z[q], _mm_add_pd(_mm_loadu_pd((const double *)&t2[q]), cmul_lanes(&u[q], q1, q2, et)));
#else
	for (int q = 0; q < nr; q++)
		t1[q] = z[q] - u[q] * ep;
	cmatvec(t2, E, t1, nr);
	for (int q = 0; q < nr; q++)
		z[q] = t2[q] + u[q] * et;
#endif
}

/* ---- the grouped linear gear branch ---- */

#define NR_MAX (2 * PRSM_VIB_ROLLERS_MAX + 1) /* grouped reduced coordinates */
#define SEG_MAX (2 * PRSM_VIB_ROLLERS_MAX + 2) /* stiffness segments of a mesh period */

typedef struct {
	const vib_core *c;
	int G, nr;
	int grp[PRSM_VIB_ROLLERS_MAX];   /* group of roller j */
	int rep[PRSM_VIB_ROLLERS_MAX];   /* a roller of group g */
	double gamma[PRSM_VIB_ROLLERS_MAX]; /* mesh phase of group g */
	double Ystar;                    /* y_0 / b_a */
	signed char mode[PRSM_VIB_CONTACTS_MAX];
} gsys;

/* the grouped derivative at rho with the thread perturbed by (dY, dW) and the mesh time
 * functions (ms, mc) = (sin, cos)(w_e tau) */
static void grhs(const gsys *S, const double *kap, const double *rho, double dY, double dW, double ms, double mc,
                 double *out)
{
	const vib_core *c = S->c;
	double y[PRSM_VIB_STATE_MAX], f[PRSM_VIB_STATE_MAX];
	memset(y, 0, (size_t)c->n * sizeof *y);
	const int G = S->G;
	for (int j = 0; j < c->Z; j++) {
		y[vib_iP(c, j + 1)] = rho[S->grp[j]];
		y[vib_iV(c, j + 1)] = rho[G + 1 + S->grp[j]];
	}
	y[vib_iV(c, 0)] = rho[G];
	y[vib_iY(c)] = S->Ystar + dY;
	y[vib_iW(c)] = dW;
	vib_trig t;
	t.mesh_s = ms;
	t.mesh_c = mc;
	t.pair_c = 0.0;
	t.te_sum = 0.0;
	vib_rhs(c, kap, &t, 0.0, y, f, S->mode);
	for (int g = 0; g < G; g++) {
		out[g] = rho[G] + rho[G + 1 + g];
		out[G + 1 + g] = f[vib_iV(c, S->rep[g] + 1)];
	}
	out[G] = f[vib_iV(c, 0)];
}

static double norm3(const double *v)
{
	return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* A, b, C = c_c - i c_s, and the thread columns cY, cW of one segment (kap) */
static void linearise(const gsys *S, const double *kap, const double *rho_s, double *A, double *b, cplx *C, double *cY,
                      double *cW)
{
	const vib_core *c = S->c;
	const int nr = S->nr, G = S->G;
	double f0[NR_MAX], fp[NR_MAX], fm[NR_MAX], r[NR_MAX];
	grhs(S, kap, rho_s, 0.0, 0.0, 0.0, 0.0, f0);
	const double vs = fmax(norm3(c->vstar), 1e-3);
	for (int j = 0; j < nr; j++) {
		double d = 1e-6;
		if (j >= G) { /* a rate: 1e-7 of the slip v* (§8.4's friction Jacobian step) */
			const double g = j == G ? norm3(c->gpsi) : norm3(c->gphi);
			d = g > 0.0 ? 1e-7 * vs / g : 1e-6;
		}
		memcpy(r, rho_s, (size_t)nr * sizeof *r);
		r[j] += d;
		grhs(S, kap, r, 0.0, 0.0, 0.0, 0.0, fp);
		r[j] = rho_s[j] - d;
		grhs(S, kap, r, 0.0, 0.0, 0.0, 0.0, fm);
		for (int i = 0; i < nr; i++)
			A[i * nr + j] = (fp[i] - fm[i]) / (2.0 * d);
	}
	double Ar[NR_MAX];
	matvec(Ar, A, rho_s, nr);
	for (int i = 0; i < nr; i++)
		b[i] = f0[i] - Ar[i];
	grhs(S, kap, rho_s, 0.0, 0.0, 1.0, 0.0, fp);
	grhs(S, kap, rho_s, 0.0, 0.0, 0.0, 1.0, fm);
	for (int i = 0; i < nr; i++)
		C[i] = (fm[i] - f0[i]) - I * (fp[i] - f0[i]);
	const double dy = 1e-6;
	grhs(S, kap, rho_s, dy, 0.0, 0.0, 0.0, fp);
	grhs(S, kap, rho_s, -dy, 0.0, 0.0, 0.0, fm);
	for (int i = 0; i < nr; i++)
		cY[i] = (fp[i] - fm[i]) / (2.0 * dy);
	grhs(S, kap, rho_s, 0.0, dy, 0.0, 0.0, fp);
	grhs(S, kap, rho_s, 0.0, -dy, 0.0, 0.0, fm);
	for (int i = 0; i < nr; i++)
		cW[i] = (fp[i] - fm[i]) / (2.0 * dy);
}

static int cmp_double(const void *a, const void *b)
{
	const double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static double fracp(double x)
{
	return x - floor(x);
}

typedef struct {
	double key;
	int idx;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
	const double x = ((const keyed *)a)->key, y = ((const keyed *)b)->key;
	return (x > y) - (x < y);
}

/* min over the window of v0[p] + sum_k Re(e^{i w_k m T} v[k][p]) (sign -1: max of it, returned
 * as a max) over points p and mesh periods m, pruned by the bound v0 -+ sum |v_k| */
static double window_extreme(const double *v0, const cplx *v, int P, int L, const cplx *rot, long Nm, int sign,
                             keyed *order)
{
	for (int p = 0; p < P; p++) {
		double a = 0.0;
		for (int k = 0; k < L; k++)
			a += cabs(v[(size_t)k * P + p]);
		order[p].key = sign * v0[p] - a; /* a lower bound of sign x value */
		order[p].idx = p;
	}
	qsort(order, (size_t)P, sizeof *order, cmp_keyed);
	double best = INFINITY;
	for (int q = 0; q < P; q++) {
		if (order[q].key >= best)
			break;
		const int p = order[q].idx;
		cplx ph[PRSM_VIB_TE_LINES_MAX];
		for (int k = 0; k < L; k++)
			ph[k] = v[(size_t)k * P + p];
		for (long mm = 0; mm < Nm; mm++) {
			double s = v0[p];
			for (int k = 0; k < L; k++) {
				s += creal(ph[k]);
				ph[k] *= rot[k];
			}
			if (sign * s < best)
				best = sign * s;
		}
	}
	return sign * best;
}

/* ---- the axial branch's grid (§8.3.2 line sum over the window) ---- */

/* The reference loop (o->reference): complex arithmetic, as first written. Over Na points of the
 * screw angle (step dth, rad) of the window: *ymin = min s y (m), *fworst = min s F (N, dynamic
 * part), *fbest = max s F with a parabola through each local maximum, *xbest = max |X| likewise (m). */
/* The peak of the parabola through three equally spaced points whose middle one a1 is the largest:
 * a1 itself when they are not strictly concave (the peak is there, or the points are flat). */
static inline double parabola_peak(double a0, double a1, double a2)
{
	const double den = a0 - 2.0 * a1 + a2;
	return den < 0.0 ? a1 - 0.125 * (a2 - a0) * (a2 - a0) / den : a1;
}

static void axial_grid_reference(double *ymin_, double *fbest_, double *fworst_, double *xbest_, const cplx *Yk,
                                 const cplx *Xk, const cplx *Fk, const cplx *rot, const prsm_vib_te_line *line, int L,
                                 long Na, double dth, double sa)
{
	cplx ph[PRSM_VIB_TE_LINES_MAX];
	double ymin = INFINITY;
	double xbest = -1.0, fbest = -INFINITY, fworst = INFINITY;
	double xprev2 = 0, xprev = 0, fprev2 = 0, fprev = 0;
	/* one extra pass of two points closes the periodic neighbourhoods */
	for (long n = 0; n < Na + 2; n++) {
		if (n % 256 == 0)
			for (int k = 0; k < L; k++)
				ph[k] = cexp(I * line[k].order_per_rev * dth * (double)(n % Na));
		double yv = 0.0, xs = 0.0, fs = 0.0;
		for (int k = 0; k < L; k++) {
			yv += creal(Yk[k] * ph[k]);
			xs += creal(Xk[k] * ph[k]);
			fs += creal(Fk[k] * ph[k]);
			ph[k] *= rot[k];
		}
		if (n < Na) {
			ymin = fmin(ymin, sa * yv);
			fworst = fmin(fworst, sa * fs);
		}
		if (n >= 2) {
			/* the middle point xprev with neighbours xprev2, xs: a parabola through a local max */
			const double ax = fabs(xprev);
			if (ax >= fabs(xprev2) && ax >= fabs(xs)) {
				const double s = xprev >= 0 ? 1.0 : -1.0;
				xbest = fmax(xbest, parabola_peak(s * xprev2, s * xprev, s * xs));
			}
			const double sf = sa * fprev;
			if (sf >= sa * fprev2 && sf >= sa * fs) {
				fbest = fmax(fbest, parabola_peak(sa * fprev2, sf, sa * fs));
			}
		}
		xprev2 = xprev;
		xprev = xs;
		fprev2 = fprev;
		fprev = fs;
	}
	*ymin_ = ymin;
	*xbest_ = xbest;
	*fbest_ = fbest;
	*fworst_ = fworst;
}

/* The same grid, the same operations in the same order written out in real arithmetic (a complex
 * product's real part is ac - bd, its imaginary part ad + bc, as the complex loop computes them,
 * and fmin / fmax by comparisons that treat NaN alike): bit-identical to the reference, some four
 * times faster (the compiler's complex products check for NaN, fmin and fmax are calls). */
static void axial_grid(double *ymin_, double *fbest_, double *fworst_, double *xbest_, const cplx *Yk,
                       const cplx *Xk, const cplx *Fk, const cplx *rot, const prsm_vib_te_line *line, int L, long Na,
                       double dth, double sa, memo_cursor *mc)
{
	double yr[PRSM_VIB_TE_LINES_MAX], yi[PRSM_VIB_TE_LINES_MAX], xr[PRSM_VIB_TE_LINES_MAX], xi[PRSM_VIB_TE_LINES_MAX];
	double fr[PRSM_VIB_TE_LINES_MAX], fi[PRSM_VIB_TE_LINES_MAX], rr[PRSM_VIB_TE_LINES_MAX], ri[PRSM_VIB_TE_LINES_MAX];
	double pr[PRSM_VIB_TE_LINES_MAX], pi[PRSM_VIB_TE_LINES_MAX];
	for (int k = 0; k < L; k++) {
		yr[k] = creal(Yk[k]);
		yi[k] = cimag(Yk[k]);
		xr[k] = creal(Xk[k]);
		xi[k] = cimag(Xk[k]);
		fr[k] = creal(Fk[k]);
		fi[k] = cimag(Fk[k]);
		rr[k] = creal(rot[k]);
		ri[k] = cimag(rot[k]);
	}
#ifdef __SSE2__
	/* the same sums in SSE2 lanes, each lane the scalar loop's operations in its order: (yv, xs)
	 * += a (yr, xr) - b (yi, xi); (fs, -) += a (fr, 0) - b (fi, 0); the phasor (pr, pi) =
	 * a (rr, ri) + b (-ri, rr), whose first lane a rr + b (-ri) is a rr - b ri exactly (negation is
	 * exact, and x + (-y) is x - y) */
	__m128d vyr[PRSM_VIB_TE_LINES_MAX], vyi[PRSM_VIB_TE_LINES_MAX], vfr[PRSM_VIB_TE_LINES_MAX];
	__m128d vfi[PRSM_VIB_TE_LINES_MAX], vr1[PRSM_VIB_TE_LINES_MAX], vr2[PRSM_VIB_TE_LINES_MAX];
	__m128d vp[PRSM_VIB_TE_LINES_MAX];
	for (int k = 0; k < L; k++) {
		vyr[k] = _mm_set_pd(xr[k], yr[k]);
		vyi[k] = _mm_set_pd(xi[k], yi[k]);
		vfr[k] = _mm_set_pd(0.0, fr[k]);
		vfi[k] = _mm_set_pd(0.0, fi[k]);
		vr1[k] = _mm_set_pd(ri[k], rr[k]);
		vr2[k] = _mm_set_pd(rr[k], -ri[k]);
	}
#endif
	double ymin = INFINITY;
	double xbest = -1.0, fbest = -INFINITY, fworst = INFINITY;
	double xprev2 = 0, xprev = 0, fprev2 = 0, fprev = 0;
	for (long n = 0; n < Na + 2; n++) {
		if (n % 256 == 0)
			for (int k = 0; k < L; k++) {
				const cplx e = memo_cexp(mc, I * line[k].order_per_rev * dth * (double)(n % Na));
				pr[k] = creal(e);
				pi[k] = cimag(e);
#ifdef __SSE2__
				vp[k] = _mm_set_pd(pi[k], pr[k]);
#endif
			}
#ifdef __SSE2__
		__m128d yx = _mm_setzero_pd(), f2 = _mm_setzero_pd();
		for (int k = 0; k < L; k++) {
			const __m128d a = _mm_unpacklo_pd(vp[k], vp[k]), b = _mm_unpackhi_pd(vp[k], vp[k]);
			yx = _mm_add_pd(yx, _mm_sub_pd(_mm_mul_pd(vyr[k], a), _mm_mul_pd(vyi[k], b)));
			f2 = _mm_add_pd(f2, _mm_sub_pd(_mm_mul_pd(vfr[k], a), _mm_mul_pd(vfi[k], b)));
			vp[k] = _mm_add_pd(_mm_mul_pd(a, vr1[k]), _mm_mul_pd(b, vr2[k]));
		}
		const double yv = _mm_cvtsd_f64(yx), xs = _mm_cvtsd_f64(_mm_unpackhi_pd(yx, yx)), fs = _mm_cvtsd_f64(f2);
#else
		double yv = 0.0, xs = 0.0, fs = 0.0;
		for (int k = 0; k < L; k++) {
			const double a = pr[k], b = pi[k];
			yv += yr[k] * a - yi[k] * b;
			xs += xr[k] * a - xi[k] * b;
			fs += fr[k] * a - fi[k] * b;
			pr[k] = a * rr[k] - b * ri[k];
			pi[k] = a * ri[k] + b * rr[k];
		}
#endif
		if (n < Na) {
			const double y = sa * yv, f = sa * fs;
			ymin = y < ymin ? y : ymin;
			fworst = f < fworst ? f : fworst;
		}
		if (n >= 2) {
			const double ax = fabs(xprev);
			if (ax >= fabs(xprev2) && ax >= fabs(xs)) {
				const double s = xprev >= 0 ? 1.0 : -1.0;
				const double pk = parabola_peak(s * xprev2, s * xprev, s * xs);
				xbest = pk > xbest ? pk : xbest;
			}
			const double sf = sa * fprev;
			if (sf >= sa * fprev2 && sf >= sa * fs) {
				const double pk = parabola_peak(sa * fprev2, sf, sa * fs);
				fbest = pk > fbest ? pk : fbest;
			}
		}
		xprev2 = xprev;
		xprev = xs;
		fprev2 = fprev;
		fprev = fs;
	}
	*ymin_ = ymin;
	*xbest_ = xbest;
	*fbest_ = fbest;
	*fworst_ = fworst;
}

/* window_extreme without the sort: the points come out of a binary min-heap of their bounds, in
 * the same nondecreasing order (ties aside, which cannot change a minimum), and each point's
 * periods are summed in real arithmetic with the reference's operations (bit-identical). */
static void sift_down(keyed *h, long n, long i)
{
	for (;;) {
		long l = 2 * i + 1, m = i;
		if (l < n && h[l].key < h[m].key)
			m = l;
		if (l + 1 < n && h[l + 1].key < h[m].key)
			m = l + 1;
		if (m == i)
			return;
		const keyed t = h[i];
		h[i] = h[m];
		h[m] = t;
		i = m;
	}
}

static double window_extreme_fast(const double *v0, const cplx *v, int P, int L, const cplx *rot, long Nm, int sign,
                                  keyed *heap)
{
	double rr[PRSM_VIB_TE_LINES_MAX], ri[PRSM_VIB_TE_LINES_MAX];
#ifdef __SSE2__
	__m128d vr1[PRSM_VIB_TE_LINES_MAX], vr2[PRSM_VIB_TE_LINES_MAX];
#endif
	for (int k = 0; k < L; k++) {
		rr[k] = creal(rot[k]);
		ri[k] = cimag(rot[k]);
#ifdef __SSE2__
		vr1[k] = _mm_set_pd(ri[k], rr[k]);
		vr2[k] = _mm_set_pd(rr[k], -ri[k]);
#endif
	}
	for (int p = 0; p < P; p++) {
		double a = 0.0;
		for (int k = 0; k < L; k++) {
			const double x = creal(v[(size_t)k * P + p]), y = cimag(v[(size_t)k * P + p]);
			a += sqrt(x * x + y * y);
		}
		/* a lower bound of sign x value: sqrt(x^2 + y^2) is within 2 ulp of cabs (1 + 1e-15 covers
		 * it), and a bound never larger than the reference's only evaluates more points, so the
		 * minimum found is the same */
		heap[p].key = sign * v0[p] - a * (1.0 + 1e-15);
		heap[p].idx = p;
	}
	long n = P;
	for (long i = n / 2 - 1; i >= 0; i--)
		sift_down(heap, n, i);
	double best = INFINITY;
	while (n > 0 && heap[0].key < best) {
		const int p = heap[0].idx;
		heap[0] = heap[--n];
		sift_down(heap, n, 0);
#ifdef __SSE2__
		/* the phasors (x, y) as SSE2 pairs, rotated as in axial_grid: x (rr, ri) + y (-ri, rr) */
		__m128d vp[PRSM_VIB_TE_LINES_MAX];
		for (int k = 0; k < L; k++)
			vp[k] = _mm_loadu_pd((const double *)&v[(size_t)k * P + p]);
		for (long mm = 0; mm < Nm; mm++) {
			double s = v0[p];
			for (int k = 0; k < L; k++) {
				const __m128d x = _mm_unpacklo_pd(vp[k], vp[k]), y = _mm_unpackhi_pd(vp[k], vp[k]);
				s += _mm_cvtsd_f64(vp[k]);
				vp[k] = _mm_add_pd(_mm_mul_pd(x, vr1[k]), _mm_mul_pd(y, vr2[k]));
			}
			if (sign * s < best)
				best = sign * s;
		}
#else
		double pr[PRSM_VIB_TE_LINES_MAX], pi[PRSM_VIB_TE_LINES_MAX];
		for (int k = 0; k < L; k++) {
			pr[k] = creal(v[(size_t)k * P + p]);
			pi[k] = cimag(v[(size_t)k * P + p]);
		}
		for (long mm = 0; mm < Nm; mm++) {
			double s = v0[p];
			for (int k = 0; k < L; k++) {
				const double x = pr[k], y = pi[k];
				s += x;
				pr[k] = x * rr[k] - y * ri[k];
				pi[k] = x * ri[k] + y * rr[k];
			}
			if (sign * s < best)
				best = sign * s;
		}
#endif
	}
	return sign * best;
}

/* ---- the largest Floquet exponent (§8.6 lyapunov_max of a screened sample) ---- */

/* log of the spectral radius of A (n x n): log rho = lim (1/k) log ||A^k||, k = 2^m by repeated
 * squaring, each square scaled to unit norm (no overflow; A invertible, a product of
 * exponentials, so nothing underflows). After m squarings the estimate is within log(C) / 2^m of
 * log rho (C: the conditioning of A's dominant eigenvectors, k for a Jordan block): 2^-52 at
 * m = 52. M, w: n x n scratch. */
static double log_spectral_radius(const double *A, int n, double *M, double *w)
{
	const size_t nn = (size_t)n * (size_t)n;
	double s = 0.0;
	for (int i = 0; i < n; i++) {
		double r = 0.0;
		for (int j = 0; j < n; j++)
			r += fabs(A[i * n + j]);
		s = fmax(s, r);
	}
	if (!(s > 0.0) || !isfinite(s))
		return NAN;
	for (size_t i = 0; i < nn; i++)
		M[i] = A[i] / s;
	double est = log(s), scale = 1.0;
	for (int m = 1; m <= 52; m++) {
		matmul(w, M, M, n);
		s = 0.0;
		for (int i = 0; i < n; i++) {
			double r = 0.0;
			for (int j = 0; j < n; j++)
				r += fabs(w[i * n + j]);
			s = fmax(s, r);
		}
		if (!(s > 0.0))
			return -INFINITY;
		for (size_t i = 0; i < nn; i++)
			M[i] = w[i] / s;
		scale *= 0.5;
		est += scale * log(s);
	}
	return est;
}

/* The partials of roller j1's rate equation in the antisymmetric motion of two rollers j1, j2 of
 * one group (P_j1 += d, P_j2 -= d; likewise V), about the linearisation point of segment kap:
 * *a = dV'/dx (per unit tau^2), *b = dV'/dV (per unit tau). The carrier and the axial branch see
 * only sums over a group's rollers, whose partials are equal, so such a motion leaves them alone:
 * it is a mode of its own, x' = V, V' = a x + b V, which the grouped coordinates do not hold. */
static void antisym_partials(const gsys *S, const double *kap, const double *rho_s, int j1, int j2, double *a,
                             double *b)
{
	const vib_core *c = S->c;
	double y[PRSM_VIB_STATE_MAX], yp[PRSM_VIB_STATE_MAX], fp[PRSM_VIB_STATE_MAX], fm[PRSM_VIB_STATE_MAX];
	memset(y, 0, (size_t)c->n * sizeof *y);
	const int G = S->G;
	for (int j = 0; j < c->Z; j++) {
		y[vib_iP(c, j + 1)] = rho_s[S->grp[j]];
		y[vib_iV(c, j + 1)] = rho_s[G + 1 + S->grp[j]];
	}
	y[vib_iV(c, 0)] = rho_s[G];
	y[vib_iY(c)] = S->Ystar;
	vib_trig t;
	t.mesh_s = t.mesh_c = t.pair_c = t.te_sum = 0.0;
	const double vs = fmax(norm3(c->vstar), 1e-3), g = norm3(c->gphi);
	for (int which = 0; which < 2; which++) {
		/* the steps of linearise: 1e-6 of a position, 1e-7 of the slip v* of a rate */
		const double d = which == 0 ? 1e-6 : (g > 0.0 ? 1e-7 * vs / g : 1e-6);
		const int i1 = which == 0 ? vib_iP(c, j1 + 1) : vib_iV(c, j1 + 1);
		const int i2 = which == 0 ? vib_iP(c, j2 + 1) : vib_iV(c, j2 + 1);
		memcpy(yp, y, (size_t)c->n * sizeof *y);
		yp[i1] += d;
		yp[i2] -= d;
		vib_rhs(c, kap, &t, 0.0, yp, fp, S->mode);
		yp[i1] = y[i1] - d;
		yp[i2] = y[i2] + d;
		vib_rhs(c, kap, &t, 0.0, yp, fm, S->mode);
		const double dv = (fp[vib_iV(c, j1 + 1)] - fm[vib_iV(c, j1 + 1)]) / (2.0 * d);
		if (which == 0)
			*a = dv;
		else
			*b = dv;
	}
}

/* ---- the closed form ---- */

int prsm_vib_mc_screen(prsm_vib_mc_out *out, double *state0, const prsm_vib_model *m, const prsm_vib_mc_options *o,
                       prsm_error *err)
{
	const prsm_vib_params *P = &m->par;
	const vib_core *c = &m->c;
	memset(out, 0, sizeof *out);
	if (P->kind != PRSM_VIB_REDUCED || !c->gear || !c->axial || !(m->mesh_order_per_rev > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics", "the screen needs a reduced model with both branches "
		                      "after prsm_vib_mc_apply");
	const int Z = c->Z, L = P->te_lines;
	const double ws = P->screw_speed_rad_s;
	memo_cursor mc_ = {0, 0}, *mc = o->reference ? NULL : &mc_; /* the reference computes every phasor */
	/* the window: W revolutions (every line order and the mesh order are multiples of 1/W) */
	double Wrev = 0.0;
	{
		/* smallest W' with W' x (mesh order) and W' x (each order) integers: the model holds the
		 * rounded orders, and prsm_vib_mc_apply's W makes all of them integers */
		for (int q = 1; q <= 1000 && Wrev == 0.0; q++) {
			int ok = fabs(q * m->mesh_order_per_rev - nearbyint(q * m->mesh_order_per_rev)) < 1e-6;
			for (int k = 0; k < L && ok; k++)
				ok = fabs(q * P->te_line[k].order_per_rev - nearbyint(q * P->te_line[k].order_per_rev)) < 1e-6;
			if (ok)
				Wrev = q;
		}
		if (Wrev == 0.0)
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/window_revolutions", "the line orders have no common "
			                      "window up to 1000 revolutions");
	}
	out->window_s = Wrev * 2.0 * M_PI / ws;
	const double sa = c->F0 >= 0.0 ? 1.0 : -1.0;
	const double sg = P->mean_mesh_force_N >= 0.0 ? 1.0 : -1.0;
	const double ka = P->axial_stiffness_N_per_m, ma = P->axial_mass_kg, ca = P->axial_damping_N_s_per_m;
	const double ba = P->axial_half_play_m, wa = P->axial_frequency_rad_s;

	/* ---- axial branch: the line sum of §8.3.2 ---- */
	cplx Yk[PRSM_VIB_TE_LINES_MAX], Xk[PRSM_VIB_TE_LINES_MAX], Fk[PRSM_VIB_TE_LINES_MAX];
	double wk[PRSM_VIB_TE_LINES_MAX]; /* rad/s */
	double fmax_order = 0.0, sumF2 = 0.0;
	for (int k = 0; k < L; k++) {
		const prsm_vib_te_line *l = &P->te_line[k];
		const double w = l->order_per_rev * ws;
		const cplx A = l->amplitude_m * cexp(I * l->phase_rad);
		wk[k] = w;
		Yk[k] = -ma * w * w * A / (ka - ma * w * w + I * w * ca);
		Xk[k] = Yk[k] - A;
		Fk[k] = (ka + I * w * ca) * Yk[k];
		sumF2 += 0.5 * creal(Fk[k] * conj(Fk[k]));
		fmax_order = fmax(fmax_order, l->order_per_rev);
	}
	out->axial_vibration_rms_m_s2 = sqrt(sumF2) / ma;
	double ymin = 0.0, xpk = 0.0, fpk = 0.0, fmn = 0.0;
	if (L > 0) {
		long Na = (long)ceil(o->axial_grid_per_cycle * fmax_order * Wrev);
		if (Na < 64)
			Na = 64;
		if (Na > 1L << 18)
			Na = 1L << 18;
		cplx rot[PRSM_VIB_TE_LINES_MAX];
		const double dth = 2.0 * M_PI * Wrev / Na; /* screw angle step, rad */
		for (int k = 0; k < L; k++)
			rot[k] = cexp(I * P->te_line[k].order_per_rev * dth);
		ymin = INFINITY;
		fpk = fmn = NAN;
		if (o->reference)
			axial_grid_reference(&ymin, &fpk, &fmn, &xpk, Yk, Xk, Fk, rot, P->te_line, L, Na, dth, sa);
		else
			axial_grid(&ymin, &fpk, &fmn, &xpk, Yk, Xk, Fk, rot, P->te_line, L, Na, dth, sa, mc);
	}
	out->peak_dynamic_te_m = xpk;
	out->peak_thread_force_N = fabs(c->F0) + fpk;
	out->thread_force_min_N = fabs(c->F0) + fmn;
	/* s y - b_a with y = y_0 + dy, y_0 = s b_a + F_0 / k_a */
	out->axial_margin = (fabs(c->F0) / ka + ymin) / ba;

	/* ---- gear branch: the grouped linear time-periodic system (§8.3.3) ---- */
	gsys S;
	memset(&S, 0, sizeof S);
	S.c = c;
	for (int j = 0; j < Z; j++) {
		int g = 0;
		while (g < S.G && S.gamma[g] != c->gamma[j])
			g++;
		if (g == S.G) {
			S.gamma[g] = c->gamma[j];
			S.rep[g] = j;
			S.G++;
		}
		S.grp[j] = g;
	}
	const int G = S.G, nr = 2 * G + 1;
	S.nr = nr;
	S.Ystar = P->axial_static_m / ba;
	for (int j = 0; j < Z; j++)
		S.mode[j] = (signed char)sg;
	S.mode[Z] = (signed char)sa;
	double rho_s[NR_MAX];
	memset(rho_s, 0, sizeof rho_s);
	for (int g = 0; g < G; g++)
		rho_s[g] = P->static_mesh_deflection_m / c->bg;
	/* the stiffness segments of a mesh period (fractions of T): every group's switches at
	 * u = 0 and u = eps_alpha - 1, u = frac(tau / T + gamma) */
	double off[SEG_MAX + 1];
	int ns = 0;
	off[ns++] = 0.0;
	if (c->D > 0.0 && c->D < 1.0)
		for (int g = 0; g < G; g++) {
			const double cand[2] = {fracp(-S.gamma[g]), fracp(c->D - S.gamma[g])};
			for (int q = 0; q < 2; q++) {
				int dup = 0;
				for (int i = 0; i < ns && !dup; i++)
					dup = fabs(off[i] - cand[q]) < 1e-12 || fabs(off[i] - cand[q]) > 1.0 - 1e-12;
				if (!dup && ns < SEG_MAX)
					off[ns++] = cand[q];
			}
		}
	qsort(off, (size_t)ns, sizeof off[0], cmp_double);
	off[ns] = 1.0;
	const double T = 2.0 * M_PI / c->we;                 /* mesh period, tau */
	const double wtau = c->we;                           /* mesh frequency per tau */
	const int n = o->grid_per_segment;
	const int npts = ns * (n + 1);                       /* grid points per mesh period */
	/* per-line complex forcing amplitudes of (Y, W) (scaled) and line frequencies per tau */
	cplx Yh[PRSM_VIB_TE_LINES_MAX], Wh[PRSM_VIB_TE_LINES_MAX];
	double wl[PRSM_VIB_TE_LINES_MAX];
	for (int k = 0; k < L; k++) {
		Yh[k] = Yk[k] / ba;
		Wh[k] = I * wk[k] * Yk[k] / (ba * wa);
		wl[k] = wk[k] / c->wref;
	}
	const size_t nn = (size_t)nr * (size_t)nr;
	/* storage: per segment A, E (sub-step), Eseg, b, C, cY, cW; grid values */
	double *buf = malloc(sizeof(double) * (nn * (size_t)ns * 3 + nn * 3));
	double *vals = malloc(sizeof(double) * (size_t)npts * (size_t)G * 2);              /* g0, F0 per point, group */
	cplx *lv = malloc(sizeof(cplx) * ((size_t)L + 1) * (size_t)npts * (size_t)G * 2); /* lines' g, F */
	keyed *order = malloc(sizeof(keyed) * (size_t)npts * (size_t)G);
	double *vtmp = malloc(sizeof(double) * (size_t)npts * (size_t)G);
	cplx *ctmp = malloc(sizeof(cplx) * ((size_t)L + 1) * (size_t)npts * (size_t)G);
	double *bseg_ = malloc(sizeof(double) * (size_t)(ns * nr)), *rcs_ = malloc(sizeof(double) * (size_t)(ns * nr));
	double *kap_ = malloc(sizeof(double) * (size_t)(ns * Z));
	cplx *Cq_ = malloc(sizeof(cplx) * (size_t)(ns * nr)), *u_ = malloc(sizeof(cplx) * (size_t)(ns * nr));
	cplx *z0_ = malloc(sizeof(cplx) * (size_t)((L + 1) * nr)), *M = malloc(sizeof(cplx) * nn);
	int rc = 0;
	if (!buf || !vals || !lv || !order || !vtmp || !ctmp || !bseg_ || !rcs_ || !kap_ || !Cq_ || !u_ || !z0_ || !M) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the closed form");
		goto done;
	}
	{
		double *Aseg = buf, *Esub = buf + nn * (size_t)ns, *Eseg = buf + 2 * nn * (size_t)ns;
		double *w1 = buf + 3 * nn * (size_t)ns, *w2 = w1 + nn, *Phi = w2 + nn;
#define bseg(s) (bseg_ + (size_t)(s) * nr) /* b of segment s */
#define rc_s(s) (rcs_ + (size_t)(s) * nr)  /* its constant particular solution -A^-1 b */
#define Cq(s) (Cq_ + (size_t)(s) * nr)     /* (i w_e - A)^-1 C */
#define kap(s) (kap_ + (size_t)(s) * Z)    /* k_j / k-bar in segment s */
#define useg(s) (u_ + (size_t)(s) * nr)    /* a line's (i w - A)^-1 D */
#define z0all(k) (z0_ + (size_t)(k) * nr)  /* a line's z(0) */
		double cYs[NR_MAX], cWs[NR_MAX];
		for (int s = 0; s < ns; s++) {
			const double mid = 0.5 * (off[s] + off[s + 1]);
			for (int j = 0; j < Z; j++) {
				const double u = fracp(mid + c->gamma[j]);
				kap(s)[j] = u < c->D ? c->kd : c->ks;
			}
			double *A = Aseg + nn * (size_t)s;
			cplx Cs[NR_MAX];
			linearise(&S, kap(s), rho_s, A, bseg(s), Cs, cYs, cWs);
			cplx v[NR_MAX];
			for (size_t i = 0; i < nn; i++)
				M[i] = -A[i];
			for (int i = 0; i < nr; i++)
				v[i] = bseg(s)[i];
			if (csolve(M, v, nr)) { /* -A rho = b */
				rc = prsm_error_set(err, PRSM_EINVAL, NULL, "a stiffness segment of the gear branch is singular");
				goto done;
			}
			for (int i = 0; i < nr; i++)
				rc_s(s)[i] = creal(v[i]);
			for (size_t i = 0; i < nn; i++)
				M[i] = -A[i];
			for (int i = 0; i < nr; i++) {
				M[i * nr + i] += I * wtau;
				v[i] = Cs[i];
			}
			if (csolve(M, v, nr)) {
				rc = prsm_error_set(err, PRSM_EINVAL, NULL, "the gear branch resonates exactly at the mesh frequency");
				goto done;
			}
			memcpy(Cq(s), v, (size_t)nr * sizeof v[0]);
			const double h = (off[s + 1] - off[s]) * T / n;
			expm(Esub + nn * (size_t)s, A, h, nr, w1, w2);
			/* Eseg = Esub^n (n a power of 2: squarings; otherwise products) */
			double *Es = Eseg + nn * (size_t)s;
			memcpy(Es, Esub + nn * (size_t)s, nn * sizeof *Es);
			int k = 1;
			while (2 * k <= n) {
				matmul(w1, Es, Es, nr);
				memcpy(Es, w1, nn * sizeof *Es);
				k *= 2;
			}
			for (; k < n; k++) {
				matmul(w1, Es, Esub + nn * (size_t)s, nr);
				memcpy(Es, w1, nn * sizeof *Es);
			}
		}
		/* the real periodic solution: rho(T) = Phi rho(0) + r */
		double r[NR_MAX], tmp[NR_MAX], tmp2[NR_MAX];
		memset(Phi, 0, nn * sizeof *Phi);
		for (int i = 0; i < nr; i++)
			Phi[i * nr + i] = 1.0;
		memset(r, 0, sizeof r);
		for (int s = 0; s < ns; s++) {
			const double t0 = off[s] * T, t1 = off[s + 1] * T;
			const cplx e0 = memo_cexp(mc, I * wtau * t0), e1 = memo_cexp(mc, I * wtau * t1);
			for (int i = 0; i < nr; i++)
				tmp[i] = r[i] - (rc_s(s)[i] + creal(Cq(s)[i] * e0));
			matvec(tmp2, Eseg + nn * (size_t)s, tmp, nr);
			for (int i = 0; i < nr; i++)
				r[i] = tmp2[i] + rc_s(s)[i] + creal(Cq(s)[i] * e1);
			matmul(w1, Eseg + nn * (size_t)s, Phi, nr);
			memcpy(Phi, w1, nn * sizeof *Phi);
		}
		/* §8.6 lyapunov_max: the system is linear with period T (tau), block-triangular (the
		 * axial branch drives the gears, not back), so its Lyapunov exponents are the axial
		 * oscillator's -zeta_a omega_a and the gear branch's Floquet exponents log|mu| / T: those
		 * of the grouped monodromy Phi and those of each group's antisymmetric roller motions
		 * (antisym_partials); the carrier angle, a rigid mode, is left out as in §8.4's exponents */
		out->lyapunov_max_per_s = out->lyapunov_gear_per_s = NAN;
		if (o->lyapunov_windows > 0) {
			double lam = c->wref * log_spectral_radius(Phi, nr, w1, w2) / T;
			for (int g = 0; g < G; g++) {
				int j2 = -1;
				for (int j = 0; j < Z && j2 < 0; j++)
					if (S.grp[j] == g && j != S.rep[g])
						j2 = j;
				if (j2 < 0)
					continue; /* a group of one roller has no antisymmetric motion */
				double Psi[4] = {1.0, 0.0, 0.0, 1.0}, B[4], E[4], t4[4], u1[4], u2[4];
				for (int s = 0; s < ns; s++) {
					B[0] = 0.0;
					B[1] = 1.0;
					antisym_partials(&S, kap(s), rho_s, S.rep[g], j2, &B[2], &B[3]);
					expm(E, B, (off[s + 1] - off[s]) * T, 2, u1, u2);
					matmul(t4, E, Psi, 2);
					memcpy(Psi, t4, sizeof Psi);
				}
				lam = fmax(lam, c->wref * log_spectral_radius(Psi, 2, u1, u2) / T);
			}
			out->lyapunov_gear_per_s = lam;
			out->lyapunov_max_per_s = fmax(lam, -P->axial_damping_ratio * P->axial_frequency_rad_s);
		}
		cplx x0[NR_MAX];
		for (int i = 0; i < nr; i++)
			for (int j = 0; j < nr; j++)
				M[i * nr + j] = (i == j ? 1.0 : 0.0) - Phi[i * nr + j];
		for (int i = 0; i < nr; i++)
			x0[i] = r[i];
		if (csolve(M, x0, nr)) {
			rc = prsm_error_set(err, PRSM_EINVAL, NULL, "the gear branch has no unique periodic solution");
			goto done;
		}
		/* the grid of the mesh-periodic part: guard and force per group */
		const double Fscale = 2.0 * c->kbar * c->bg;
		double rho[NR_MAX];
		for (int i = 0; i < nr; i++)
			rho[i] = creal(x0[i]);
		double rho0_state[NR_MAX];
		memcpy(rho0_state, rho, sizeof rho0_state);
		int p = 0;
		for (int s = 0; s < ns; s++) {
			const double h = (off[s + 1] - off[s]) * T / n;
			for (int i = 0; i <= n; i++, p++) {
				const double tau = off[s] * T + i * h;
				if (i > 0) {
					const double tp = tau - h;
					/* one phasor per point (the same value the reference computes per component) */
					const cplx ep = o->reference ? 0.0 : memo_cexp(mc, I * wtau * tp);
					const cplx et = o->reference ? 0.0 : memo_cexp(mc, I * wtau * tau);
					for (int q = 0; q < nr; q++)
						tmp[q] = rho[q] - (rc_s(s)[q] + creal(Cq(s)[q] * (o->reference ? cexp(I * wtau * tp) : ep)));
					matvec(tmp2, Esub + nn * (size_t)s, tmp, nr);
					for (int q = 0; q < nr; q++)
						rho[q] = tmp2[q] + rc_s(s)[q] + creal(Cq(s)[q] * (o->reference ? cexp(I * wtau * tau) : et));
				}
				for (int g = 0; g < G; g++) {
					const double ph = wtau * tau + 2.0 * M_PI * S.gamma[g];
					double sn, cs;
					memo_sincos(mc, ph, &sn, &cs);
					const double e = c->eg * sn, ed = c->eg * wtau * cs;
					const double xr = rho[g] - e;
					vals[((size_t)p * G + g) * 2] = sg * xr - 1.0;
					vals[((size_t)p * G + g) * 2 + 1] =
					    sg * Fscale * (kap(s)[S.rep[g]] * (xr - sg) + c->two_zeta_g * (rho[G] + rho[G + 1 + g] - ed));
				}
			}
			/* the next segment starts where this one ended (same rho: continuous) */
		}
		/* each line: the periodic envelope z(T) = e^{i w T} z(0) */
		cplx rot[PRSM_VIB_TE_LINES_MAX];
		for (int k = 0; k < L; k++) {
			const double w = wl[k];
			rot[k] = memo_cexp(mc, I * w * T);
			for (int s = 0; s < ns; s++) {
				/* the thread columns cY, cW do not depend on the stiffness (friction only) */
				const double *A = Aseg + nn * (size_t)s;
				for (size_t i = 0; i < nn; i++)
					M[i] = -A[i];
				for (int i = 0; i < nr; i++) {
					M[i * nr + i] += I * w;
					useg(s)[i] = cYs[i] * Yh[k] + cWs[i] * Wh[k];
				}
				if (csolve(M, useg(s), nr)) {
					rc = prsm_error_set(err, PRSM_EINVAL, NULL, "the gear branch resonates exactly at a TE line");
					goto done;
				}
			}
			cplx rz[NR_MAX], t1v[NR_MAX], t2v[NR_MAX];
			for (int i = 0; i < nr; i++)
				rz[i] = 0.0;
			for (int s = 0; s < ns; s++) {
				const double ta = off[s] * T, tb = off[s + 1] * T;
				const cplx ea = memo_cexp(mc, I * w * ta), eb = memo_cexp(mc, I * w * tb);
				for (int i = 0; i < nr; i++)
					t1v[i] = rz[i] - useg(s)[i] * ea;
				(o->reference ? cmatvec : cmatvec_fast)(t2v, Eseg + nn * (size_t)s, t1v, nr);
				for (int i = 0; i < nr; i++)
					rz[i] = t2v[i] + useg(s)[i] * eb;
			}
			for (int i = 0; i < nr; i++)
				for (int j = 0; j < nr; j++)
					M[i * nr + j] = (i == j ? rot[k] : 0.0) - Phi[i * nr + j];
			memcpy(z0all(k), rz, (size_t)nr * sizeof rz[0]);
			if (csolve(M, z0all(k), nr)) {
				rc = prsm_error_set(err, PRSM_EINVAL, NULL, "the gear branch has no steady response to a TE line");
				goto done;
			}
			cplx z[NR_MAX];
			memcpy(z, z0all(k), (size_t)nr * sizeof z[0]);
			p = 0;
			for (int s = 0; s < ns; s++) {
				const double h = (off[s + 1] - off[s]) * T / n;
				for (int i = 0; i <= n; i++, p++) {
					const double tau = off[s] * T + i * h;
					if (i > 0) {
						const double tp = tau - h;
						if (o->reference) {
							for (int q = 0; q < nr; q++)
								t1v[q] = z[q] - useg(s)[q] * cexp(I * w * tp);
							cmatvec(t2v, Esub + nn * (size_t)s, t1v, nr);
							for (int q = 0; q < nr; q++)
								z[q] = t2v[q] + useg(s)[q] * cexp(I * w * tau);
						} else {
							const cplx ep = memo_cexp(mc, I * w * tp), et = memo_cexp(mc, I * w * tau);
							line_step(z, useg(s), ep, et, Esub + nn * (size_t)s, nr, t1v, t2v);
						}
					}
					for (int g = 0; g < G; g++) {
						lv[(((size_t)k * npts + p) * G + g) * 2] = sg * z[g];
						lv[(((size_t)k * npts + p) * G + g) * 2 + 1] =
						    sg * Fscale * (kap(s)[S.rep[g]] * z[g] + c->two_zeta_g * (z[G] + z[G + 1 + g]));
					}
				}
			}
		}
		/* the window: Nm mesh periods */
		const long Nm = lround(m->mesh_order_per_rev * Wrev);
		const int PG = npts * G;
		for (int which = 0; which < 2; which++) {
			for (int q = 0; q < PG; q++) {
				vtmp[q] = vals[(size_t)q * 2 + which];
				for (int k = 0; k < L; k++)
					ctmp[(size_t)k * PG + q] = lv[((size_t)k * PG + q) * 2 + which];
			}
			const double ext = o->reference ? window_extreme(vtmp, ctmp, PG, L, rot, Nm, which == 0 ? 1 : -1, order)
			                                : window_extreme_fast(vtmp, ctmp, PG, L, rot, Nm, which == 0 ? 1 : -1, order);
			if (which == 0)
				out->mesh_margin = ext;
			else
				out->mesh_force_peak_N = ext;
		}
		if (state0 != NULL) {
			memset(state0, 0, (size_t)c->n * sizeof *state0);
			double Y = S.Ystar, Wv = 0.0;
			for (int k = 0; k < L; k++) {
				Y += creal(Yh[k]);
				Wv += creal(Wh[k]);
			}
			for (int j = 0; j < Z; j++) {
				const int g = S.grp[j];
				double x = rho0_state[g], v = rho0_state[G + 1 + g];
				for (int k = 0; k < L; k++) {
					x += creal(z0all(k)[g]);
					v += creal(z0all(k)[G + 1 + g]);
				}
				state0[vib_iP(c, j + 1)] = x;
				state0[vib_iV(c, j + 1)] = v;
			}
			double v0 = rho0_state[G];
			for (int k = 0; k < L; k++)
				v0 += creal(z0all(k)[G]);
			state0[vib_iV(c, 0)] = v0;
			state0[vib_iY(c)] = Y;
			state0[vib_iW(c)] = Wv;
		}
	}
	out->screened = out->axial_margin > 0.0 && out->mesh_margin > 0.0 && out->thread_force_min_N > 0.0;
	out->contact_loss = !out->screened;
	out->regime = out->screened ? 1 : -1;
	if (!out->screened)
		out->lyapunov_max_per_s = out->lyapunov_gear_per_s = NAN; /* the linear system is not the sample's */
done:
	free(buf);
	free(vals);
	free(lv);
	free(order);
	free(vtmp);
	free(ctmp);
	free(bseg_);
	free(rcs_);
	free(kap_);
	free(Cq_);
	free(u_);
	free(z0_);
	free(M);
	return rc;
#undef bseg
#undef rc_s
#undef Cq
#undef kap
#undef useg
#undef z0all
}

/* ---- integration of a contact-loss sample ---- */

typedef struct {
	const prsm_vib_model *m;
	double sa, sg, F0, ma, ba, y0, wref;
	int L;
	double te_w[PRSM_VIB_TE_LINES_MAX], te_A[PRSM_VIB_TE_LINES_MAX], te_phi[PRSM_VIB_TE_LINES_MAX];
	double peak_te, peak_fth, peak_mesh, sum_sq, span, prev_sq;
	int started, loss;
	double ybuf[PRSM_VIB_STATE_MAX];
} recorder;

static double rec_point(recorder *r, vib_int *it, double tau, const double *y)
{
	const vib_core *c = it->c;
	double mesh[PRSM_VIB_ROLLERS_MAX], Fth, g[PRSM_VIB_CONTACTS_MAX];
	vib_forces(c, it->kap, tau, y, mesh, &Fth);
	const double t = tau / r->wref;
	double te = 0.0;
	for (int k = 0; k < r->L; k++)
		te += r->te_A[k] * cos(r->te_w[k] * t + r->te_phi[k]);
	const double X = r->ba * y[vib_iY(c)] - te - r->y0;
	r->peak_te = fmax(r->peak_te, fabs(X));
	r->peak_fth = fmax(r->peak_fth, r->sa * Fth);
	for (int j = 0; j < c->Z; j++)
		r->peak_mesh = fmax(r->peak_mesh, r->sg * mesh[j]);
	vib_contacts(c, tau, y, g);
	for (int j = 0; j < c->Z; j++)
		if (r->sg * g[j] <= 1.0)
			r->loss = 1;
	if (r->sa * g[c->Z] <= 1.0)
		r->loss = 1;
	return (Fth - r->F0) * (Fth - r->F0);
}

static int rec_obs(void *ctx, vib_int *it, double tau0, const double *y0, const double *f0, double tau1,
                   const double *y1, const double *f1)
{
	recorder *r = ctx;
	const double h = tau1 - tau0;
	/* the step's start too: a mesh force jumps where the stiffness switches (a step starts there) */
	r->prev_sq = rec_point(r, it, tau0, y0);
	r->started = 1;
	for (int q = 1; q <= 4; q++) {
		const double s = q / 4.0;
		double sq;
		if (q == 4)
			sq = rec_point(r, it, tau1, y1);
		else {
			vib_hermite(it->c, y0, f0, y1, f1, h, s, r->ybuf);
			sq = rec_point(r, it, tau0 + s * h, r->ybuf);
		}
		r->sum_sq += 0.25 * h * 0.5 * (sq + r->prev_sq);
		r->prev_sq = sq;
	}
	r->span += h;
	return 0;
}

int prsm_vib_mc_integrate(prsm_vib_mc_out *out, const prsm_vib_model *m, const double *state0,
                          const prsm_vib_mc_options *o, const prsm_cancel_flag *cancel, prsm_error *err)
{
	const prsm_vib_params *P = &m->par;
	const vib_core *c = &m->c;
	const double window_s = out->window_s > 0.0 ? out->window_s : 0.0;
	if (!(window_s > 0.0))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "integrate after the screen (it sets the window)");
	const double Tw = window_s * c->wref;
	vib_int it;
	int rc = vib_int_init(&it, m, 0, 1, &o->integration, cancel);
	if (rc)
		return prsm_error_set(err, rc, NULL, "out of memory for the integrator");
	double y[PRSM_VIB_STATE_MAX];
	if (state0 != NULL)
		memcpy(y, state0, (size_t)c->n * sizeof *y);
	else
		prsm_vib_static_state(m, y);
	vib_int_set(&it, 0.0, y);
	const int ps = vib_reduced_size(c);
	double *Pn = malloc(sizeof(double) * (size_t)(o->max_windows + 1) * (size_t)ps);
	if (Pn == NULL) {
		vib_int_free(&it);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the Poincaré points");
	}
	vib_project(c, it.y, Pn);
	int found = 0, k = 0;
	double dist = NAN;
	for (k = 1; k <= o->max_windows; k++) {
		if ((rc = vib_int_advance(&it, k * Tw)))
			goto fail;
		vib_project(c, it.y, Pn + (size_t)k * ps);
		const int npts = k + 1;
		if (npts >= 3) {
			const int nn = npts < 2 * o->max_period + 1 ? npts : 2 * o->max_period + 1;
			found = prsm_vib_period_of(Pn + (size_t)(npts - nn) * ps, nn, ps, o->period_tol, o->max_period, &dist);
			if (found > 0)
				break;
		}
	}
	if (k > o->max_windows)
		k = o->max_windows;
	/* record m windows (one when not periodic) */
	recorder r;
	memset(&r, 0, sizeof r);
	r.m = m;
	r.sa = c->F0 >= 0.0 ? 1.0 : -1.0;
	r.sg = P->mean_mesh_force_N >= 0.0 ? 1.0 : -1.0;
	r.F0 = c->F0;
	r.ma = P->axial_mass_kg;
	r.ba = P->axial_half_play_m;
	r.y0 = P->axial_static_m;
	r.wref = c->wref;
	r.L = P->te_lines;
	r.peak_fth = r.peak_mesh = -INFINITY;
	for (int q = 0; q < r.L; q++) {
		r.te_w[q] = P->te_line[q].order_per_rev * P->screw_speed_rad_s;
		r.te_A[q] = P->te_line[q].amplitude_m;
		r.te_phi[q] = P->te_line[q].phase_rad;
	}
	it.obs = rec_obs;
	it.obs_ctx = &r;
	const int rec = found > 0 ? found : 1;
	const double t0 = it.tau;
	if ((rc = vib_int_advance(&it, t0 + rec * Tw)))
		goto fail;
	it.obs = NULL;
	out->integrated = 1;
	out->lyapunov_max_per_s = out->lyapunov_gear_per_s = NAN;
	if (o->lyapunov_windows > 0) {
		/* §8.6 lyapunov_max: Benettin's estimate (§8.4, one tangent vector in the reduced
		 * coordinates, renormalised every window) over lyapunov_windows windows from here */
		vib_int lv;
		prsm_vib_integration li = o->integration;
		if (li.locate_kinks == PRSM_VIB_LOCATE_NEVER)
			li.locate_kinks = PRSM_VIB_LOCATE_AUTO; /* the variational equations jump at the kinks */
		if (vib_int_init(&lv, m, 1, 1, &li, cancel)) {
			rc = PRSM_ENOMEM;
			goto fail;
		}
		double *yv = calloc((size_t)lv.dim, sizeof(double));
		if (yv == NULL) {
			vib_int_free(&lv);
			rc = PRSM_ENOMEM;
			goto fail;
		}
		memcpy(yv, it.y, (size_t)c->n * sizeof(double));
		vib_int_set(&lv, it.tau, yv);
		free(yv);
		prsm_vib_lyapunov ly;
		rc = vib_benettin(&lv, Tw, 0, o->lyapunov_windows, 1, 1, &ly);
		it.effort.steps += lv.effort.steps;
		if (rc) {
			rc = vib_int_error(&lv, rc, err);
			vib_int_free(&lv);
			free(Pn);
			vib_int_free(&it);
			return rc;
		}
		vib_int_free(&lv);
		out->lyapunov_max_per_s = ly.lambda_per_s[0];
	}
	out->windows = k + rec;
	out->regime = found > 0 ? found : 0;
	out->max_return_distance = dist;
	out->contact_loss = r.loss;
	out->peak_dynamic_te_m = r.peak_te;
	out->peak_thread_force_N = r.peak_fth;
	out->mesh_force_peak_N = r.peak_mesh;
	out->axial_vibration_rms_m_s2 = r.span > 0.0 ? sqrt(r.sum_sq / r.span) / r.ma : NAN;
	out->effort = it.effort;
	free(Pn);
	vib_int_free(&it);
	return 0;
fail:
	rc = vib_int_error(&it, rc, err);
	free(Pn);
	vib_int_free(&it);
	return rc;
}

int prsm_vib_mc_eval(prsm_vib_mc_out *out, const prsm_vib_model *m, const prsm_vib_mc_options *o,
                     const prsm_cancel_flag *cancel, prsm_error *err)
{
	double y0[PRSM_VIB_STATE_MAX];
	int rc = prsm_vib_mc_screen(out, y0, m, o, err);
	if (rc)
		return rc;
	if ((out->screened && !o->force_integration) || o->screen_only)
		return 0;
	const int screened = out->screened;
	rc = prsm_vib_mc_integrate(out, m, y0, o, cancel, err);
	out->screened = screened && rc == 0 ? screened : 0;
	return rc;
}
