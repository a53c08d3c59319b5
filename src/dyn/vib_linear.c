/*
 * vib_linear.c: the linearised vibration model (docs/model §8.4 "Linearisation, natural
 * frequencies, modes, FRF" and "Half-power damping"): about the steady state with the mean mesh
 * stiffness and every contact closed,
 *     M q'' + C q' + K q = 0,  C = -dQ_fric/dq' + 2 c_g W^T W,  K = 2 k-bar W^T W,
 * on q = (psi, phi_0 .. phi_{Z-1}) plus the axial branch (m_a, c_a, k_a) with the one-way
 * coupling dQ_fric/dy, dQ_fric/dy' in its column (the friction's normal force follows F_th).
 * The friction Jacobian is by central differences with a step 1e-7 |v*| of slip per generalised
 * rate. Eigenvalues of the first-order form (GSL nonsymmv) after a diagonal scaling to the
 * model's scaled coordinates and time (eigenvalues are invariant, conditioning is not); FRFs by
 * complex LU of (-omega^2 M + i omega C + K) in the same scaling.
 */
#include "dyn/vib_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_complex_math.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>

void prsm_vib_linear_free(prsm_vib_linear *l)
{
	free(l->M);
	free(l->C);
	free(l->K);
	free(l->eig_re);
	free(l->eig_im);
	free(l->frequency_Hz);
	free(l->damping_ratio);
	free(l->kind);
	free(l->shape_re);
	free(l->shape_im);
	memset(l, 0, sizeof *l);
}

/* The friction's generalised forces (§8.3.3), N m: Q_psi then Q_phi_j, at rates qd (rad/s) and
 * thread force Fth (N). */
static void q_fric(const vib_core *c, double Fth, const double *qd, double *Q)
{
	const int Z = c->Z;
	const int same = (Fth >= 0.0) == (c->F0 >= 0.0);
	const double *Gphi = same ? c->Gphi : c->Gphi_o, *Gpsi = same ? c->Gpsi : c->Gpsi_o;
	const double nz = same ? c->nz : c->nz_o;
	Q[0] = 0.0;
	for (int j = 0; j < Z; j++) {
		double v[3];
		for (int i = 0; i < 3; i++)
			v[i] = c->vstar[i] + Gpsi[i] * qd[0] + Gphi[i] * qd[1 + j];
		const double inv = 1.0 / sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + c->veps2);
		const double N = (-Fth / Z) / (nz - c->mu * v[2] * inv);
		const double fac = -c->mu * N * inv;
		Q[1 + j] = fac * (v[0] * Gphi[0] + v[1] * Gphi[1] + v[2] * Gphi[2]);
		Q[0] += fac * (v[0] * Gpsi[0] + v[1] * Gpsi[1] + v[2] * Gpsi[2]);
	}
}

static int order_cmp_kind(int k)
{
	return k == PRSM_VIB_EIG_OSCILLATORY ? 1 : 0;
}

typedef struct {
	double re, im;
	int idx;
	int kind;
} eig_entry;

static int eig_cmp(const void *a, const void *b)
{
	const eig_entry *x = a, *y = b;
	const int kx = order_cmp_kind(x->kind), ky = order_cmp_kind(y->kind);
	if (kx != ky)
		return kx - ky;
	if (kx == 0) {
		const double ax = hypot(x->re, x->im), ay = hypot(y->re, y->im);
		return ax < ay ? -1 : (ax > ay ? 1 : 0);
	}
	const double ix = fabs(x->im), iy = fabs(y->im);
	if (ix < iy * (1.0 - 1e-12))
		return -1;
	if (ix > iy * (1.0 + 1e-12))
		return 1;
	return (x->im >= 0.0 ? 0 : 1) - (y->im >= 0.0 ? 0 : 1);
}

/* the coordinate scales: q_k = s_k x_k with x the scaled coordinate (P, Y) */
static void scales(const prsm_vib_model *m, int dofs, double *s)
{
	const vib_core *c = &m->c;
	if (c->pair) {
		s[0] = 1.0;
		return;
	}
	int k = 0;
	if (c->gear) {
		s[k++] = c->bg / c->rb2;
		for (int j = 0; j < c->Z; j++)
			s[k++] = c->bg / c->rb1;
	}
	if (c->axial)
		s[k++] = c->ba;
	(void)dofs;
}

static double time_unit(const prsm_vib_model *m)
{
	return m->c.pair ? 1.0 : m->c.wref;
}

int prsm_vib_linearise(prsm_vib_linear *out, const prsm_vib_model *m, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	const vib_core *c = &m->c;
	const int Z = c->Z;
	int n;
	if (c->pair)
		n = 1;
	else
		n = (c->gear ? Z + 1 : 0) + (c->axial ? 1 : 0);
	out->dofs = n;
	out->eigenvalues = 2 * n;
	out->shape_size = c->pair ? 1 : (c->gear ? Z : 0) + (c->axial ? 1 : 0);
	const size_t nn = (size_t)n * n;
	out->M = calloc(nn, sizeof(double));
	out->C = calloc(nn, sizeof(double));
	out->K = calloc(nn, sizeof(double));
	out->eig_re = malloc((size_t)(2 * n) * sizeof(double));
	out->eig_im = malloc((size_t)(2 * n) * sizeof(double));
	out->frequency_Hz = malloc((size_t)(2 * n) * sizeof(double));
	out->damping_ratio = malloc((size_t)(2 * n) * sizeof(double));
	out->kind = malloc((size_t)(2 * n) * sizeof(int));
	out->shape_re = malloc((size_t)(2 * n) * out->shape_size * sizeof(double));
	out->shape_im = malloc((size_t)(2 * n) * out->shape_size * sizeof(double));
	if (!out->M || !out->C || !out->K || !out->eig_re || !out->eig_im || !out->frequency_Hz ||
	    !out->damping_ratio || !out->kind || !out->shape_re || !out->shape_im) {
		prsm_vib_linear_free(out);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the linear model");
	}
	double *M = out->M, *C = out->C, *K = out->K;
	if (c->pair) {
		/* §8.3.5 with the mean stiffness: x'' + 2 zeta x' + x = 0 */
		M[0] = 1.0;
		C[0] = 2.0 * c->zeta;
		K[0] = 1.0;
	} else {
		const prsm_vib_params *P = &m->par;
		int ya = -1;
		if (c->gear) {
			/* the arrow mass matrix, K = 2 k-bar W^T W, C = 2 c_g W^T W - dQ/dq' */
			const double kb = 2.0 * c->kbar, cg = 2.0 * P->mesh_damping_N_s_per_m;
			M[0] = c->Mpp;
			K[0] = kb * Z * c->rb2 * c->rb2;
			C[0] = cg * Z * c->rb2 * c->rb2;
			for (int j = 1; j <= Z; j++) {
				M[j] = M[(size_t)j * n] = c->Mpf;
				M[(size_t)j * n + j] = c->Mff;
				K[j] = K[(size_t)j * n] = kb * c->rb2 * c->rb1;
				K[(size_t)j * n + j] = kb * c->rb1 * c->rb1;
				C[j] = C[(size_t)j * n] = cg * c->rb2 * c->rb1;
				C[(size_t)j * n + j] = cg * c->rb1 * c->rb1;
			}
			/* friction Jacobian by central differences */
			const double vs = sqrt(c->vstar[0] * c->vstar[0] + c->vstar[1] * c->vstar[1] + c->vstar[2] * c->vstar[2]);
			double qd[PRSM_VIB_ROLLERS_MAX + 1] = {0}, Qp[PRSM_VIB_ROLLERS_MAX + 1], Qm[PRSM_VIB_ROLLERS_MAX + 1];
			for (int k = 0; k <= Z; k++) {
				const double *G = k == 0 ? c->Gpsi : c->Gphi;
				const double d = 1e-7 * fmax(vs, 1e-3 * sqrt(c->veps2) + 1e-12) / sqrt(G[0] * G[0] + G[1] * G[1] + G[2] * G[2]);
				qd[k] = d;
				q_fric(c, c->F0, qd, Qp);
				qd[k] = -d;
				q_fric(c, c->F0, qd, Qm);
				qd[k] = 0.0;
				for (int i = 0; i <= Z; i++)
					C[(size_t)i * n + k] -= (Qp[i] - Qm[i]) / (2.0 * d);
			}
			if (c->axial) {
				/* the coupling column: Q follows F_th = k_a (y - y_0) + c_a y' + F_0 */
				ya = Z + 1;
				const double dF = 1e-6 * fmax(fabs(c->F0), 1.0);
				q_fric(c, c->F0 + dF, qd, Qp);
				q_fric(c, c->F0 - dF, qd, Qm);
				for (int i = 0; i <= Z; i++) {
					const double dQdF = (Qp[i] - Qm[i]) / (2.0 * dF);
					K[(size_t)i * n + ya] = -dQdF * m->k_axial;
					C[(size_t)i * n + ya] = -dQdF * P->axial_damping_N_s_per_m;
				}
			}
		} else {
			ya = 0;
		}
		if (c->axial) {
			M[(size_t)ya * n + ya] = m->m_axial;
			C[(size_t)ya * n + ya] = P->axial_damping_N_s_per_m;
			K[(size_t)ya * n + ya] = m->k_axial;
		}
	}
	/* first-order form in scaled coordinates and time: x = S^-1 q, tau = w t */
	double s[PRSM_VIB_ROLLERS_MAX + 2];
	scales(m, n, s);
	const double w = time_unit(m);
	gsl_matrix *Ms = gsl_matrix_alloc((size_t)n, (size_t)n), *A = gsl_matrix_alloc((size_t)(2 * n), (size_t)(2 * n));
	gsl_matrix *Minv = gsl_matrix_alloc((size_t)n, (size_t)n);
	gsl_permutation *perm = gsl_permutation_alloc((size_t)n);
	gsl_vector_complex *eval = gsl_vector_complex_alloc((size_t)(2 * n));
	gsl_matrix_complex *evec = gsl_matrix_complex_alloc((size_t)(2 * n), (size_t)(2 * n));
	gsl_eigen_nonsymmv_workspace *ws = gsl_eigen_nonsymmv_alloc((size_t)(2 * n));
	eig_entry *e = malloc((size_t)(2 * n) * sizeof *e);
	int rc = 0;
	if (!Ms || !A || !Minv || !perm || !eval || !evec || !ws || !e) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the eigenproblem");
		goto cleanup;
	}
	/* scaled: M~ = S M S, C~ = S C S / w, K~ = S K S / w^2 (rows and columns) */
	for (int i = 0; i < n; i++)
		for (int j = 0; j < n; j++)
			gsl_matrix_set(Ms, (size_t)i, (size_t)j, s[i] * M[(size_t)i * n + j] * s[j]);
	int sg;
	gsl_linalg_LU_decomp(Ms, perm, &sg);
	if (gsl_linalg_LU_invert(Ms, perm, Minv) != 0) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the mass matrix is singular");
		goto cleanup;
	}
	gsl_matrix_set_zero(A);
	for (int i = 0; i < n; i++) {
		gsl_matrix_set(A, (size_t)i, (size_t)(n + i), 1.0);
		for (int j = 0; j < n; j++) {
			double kk = 0.0, cc = 0.0;
			for (int l = 0; l < n; l++) {
				const double mi = gsl_matrix_get(Minv, (size_t)i, (size_t)l);
				kk += mi * s[l] * K[(size_t)l * n + j] * s[j] / (w * w);
				cc += mi * s[l] * C[(size_t)l * n + j] * s[j] / w;
			}
			gsl_matrix_set(A, (size_t)(n + i), (size_t)j, -kk);
			gsl_matrix_set(A, (size_t)(n + i), (size_t)(n + j), -cc);
		}
	}
	gsl_eigen_nonsymmv_params(1, ws);
	if (gsl_eigen_nonsymmv(A, eval, evec, ws) != 0) {
		rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the eigenvalues did not converge");
		goto cleanup;
	}
	for (int k = 0; k < 2 * n; k++) {
		const gsl_complex z = gsl_vector_complex_get(eval, (size_t)k);
		e[k].re = GSL_REAL(z) * w;
		e[k].im = GSL_IMAG(z) * w;
		e[k].idx = k;
		const double mag = hypot(e[k].re, e[k].im);
		e[k].kind = mag < 1e-9 * w ? PRSM_VIB_EIG_RIGID
		            : (fabs(e[k].im) <= 1e-9 * mag ? PRSM_VIB_EIG_REAL : PRSM_VIB_EIG_OSCILLATORY);
		if (e[k].kind != PRSM_VIB_EIG_OSCILLATORY)
			e[k].im = 0.0;
	}
	qsort(e, (size_t)(2 * n), sizeof *e, eig_cmp);
	for (int k = 0; k < 2 * n; k++) {
		out->eig_re[k] = e[k].re;
		out->eig_im[k] = e[k].im;
		out->kind[k] = e[k].kind;
		const double mag = hypot(e[k].re, e[k].im);
		out->frequency_Hz[k] = c->pair ? fabs(e[k].im) : fabs(e[k].im) / (2.0 * M_PI);
		out->damping_ratio[k] = mag > 0.0 ? -e[k].re / mag : NAN;
		/* shape: d_j = r_b2 psi + r_b1 phi_j, y, from the displacement half (unscaled) */
		double sre[PRSM_VIB_ROLLERS_MAX + 1], sim[PRSM_VIB_ROLLERS_MAX + 1];
		double q_re[PRSM_VIB_ROLLERS_MAX + 2], q_im[PRSM_VIB_ROLLERS_MAX + 2];
		for (int i = 0; i < n; i++) {
			const gsl_complex z = gsl_matrix_complex_get(evec, (size_t)i, (size_t)e[k].idx);
			q_re[i] = GSL_REAL(z) * s[i];
			q_im[i] = GSL_IMAG(z) * s[i];
		}
		int ns = 0;
		if (c->pair) {
			sre[ns] = q_re[0];
			sim[ns++] = q_im[0];
		} else {
			if (c->gear)
				for (int j = 0; j < Z; j++) {
					sre[ns] = c->rb2 * q_re[0] + c->rb1 * q_re[1 + j];
					sim[ns++] = c->rb2 * q_im[0] + c->rb1 * q_im[1 + j];
				}
			if (c->axial) {
				sre[ns] = q_re[n - 1];
				sim[ns++] = q_im[n - 1];
			}
		}
		int big = 0;
		for (int i = 1; i < ns; i++)
			if (hypot(sre[i], sim[i]) > hypot(sre[big], sim[big]))
				big = i;
		const double br = sre[big], bi = sim[big], b2 = br * br + bi * bi;
		for (int i = 0; i < ns; i++) {
			double r = 0.0, im = 0.0;
			if (b2 > 0.0) { /* divide by the largest entry: it becomes 1 */
				r = (sre[i] * br + sim[i] * bi) / b2;
				im = (sim[i] * br - sre[i] * bi) / b2;
			}
			out->shape_re[(size_t)k * ns + i] = r;
			out->shape_im[(size_t)k * ns + i] = im;
		}
	}
cleanup:
	gsl_matrix_free(Ms);
	gsl_matrix_free(A);
	gsl_matrix_free(Minv);
	gsl_permutation_free(perm);
	gsl_vector_complex_free(eval);
	gsl_matrix_complex_free(evec);
	if (ws != NULL)
		gsl_eigen_nonsymmv_free(ws);
	free(e);
	if (rc)
		prsm_vib_linear_free(out);
	return rc;
}

int prsm_vib_frf(double *re, double *im, const prsm_vib_model *m, const prsm_vib_linear *l, int input, int input_index,
                 int output, int output_index, const double *omega, size_t count, prsm_error *err)
{
	const vib_core *c = &m->c;
	const int n = l->dofs, Z = c->Z;
	const int ya = c->pair ? -1 : (c->axial ? n - 1 : -1);
	if (input < PRSM_VIB_IN_MESH_ERROR || input > PRSM_VIB_IN_TE || output < PRSM_VIB_OUT_MESH_DEFLECTION ||
	    output > PRSM_VIB_OUT_THREAD_FORCE)
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/frf", "unknown FRF input or output");
	if (c->pair) {
		if (input == PRSM_VIB_IN_TE || output != PRSM_VIB_OUT_MESH_DEFLECTION)
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/frf",
			                      "the gear pair has the inputs mesh_error and force, the output x");
	} else {
		if ((input == PRSM_VIB_IN_MESH_ERROR || output == PRSM_VIB_OUT_MESH_DEFLECTION) && !c->gear)
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/frf", "the gear branch is off");
		if ((input != PRSM_VIB_IN_MESH_ERROR || output != PRSM_VIB_OUT_MESH_DEFLECTION) && !c->axial &&
		    !(input == PRSM_VIB_IN_MESH_ERROR && output == PRSM_VIB_OUT_MESH_DEFLECTION))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/frf", "the axial branch is off");
		if ((input == PRSM_VIB_IN_MESH_ERROR && (input_index < 0 || input_index >= Z)) ||
		    (output == PRSM_VIB_OUT_MESH_DEFLECTION && (output_index < 0 || output_index >= Z)))
			return prsm_error_set(err, PRSM_EINVAL, "/dynamics/frf", "a roller index is 0 to %d", Z - 1);
	}
	double s[PRSM_VIB_ROLLERS_MAX + 2];
	scales(m, n, s);
	const double w = time_unit(m);
	gsl_matrix_complex *D = gsl_matrix_complex_alloc((size_t)n, (size_t)n);
	gsl_vector_complex *F = gsl_vector_complex_alloc((size_t)n), *X = gsl_vector_complex_alloc((size_t)n);
	gsl_permutation *perm = gsl_permutation_alloc((size_t)n);
	int rc = 0;
	if (!D || !F || !X || !perm) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for the FRF");
		goto cleanup;
	}
	const prsm_vib_params *P = &m->par;
	for (size_t f = 0; f < count; f++) {
		const double om = omega[f];
		/* S (-om^2 M + i om C + K) S X~ = S F, with q = S X~; scaled by 1/w^2 */
		for (int i = 0; i < n; i++)
			for (int j = 0; j < n; j++) {
				const size_t ij = (size_t)i * n + j;
				const double sc = s[i] * s[j] / (w * w);
				gsl_matrix_complex_set(D, (size_t)i, (size_t)j,
				                       gsl_complex_rect((l->K[ij] - om * om * l->M[ij]) * sc, om * l->C[ij] * sc));
			}
		gsl_vector_complex_set_zero(F);
		if (c->pair) {
			/* mesh error: epsilon Omega^2 per unit epsilon (x relative to the error); force: 1 */
			gsl_vector_complex_set(F, 0, gsl_complex_rect(input == PRSM_VIB_IN_MESH_ERROR ? om * om : 1.0, 0.0));
		} else if (input == PRSM_VIB_IN_MESH_ERROR) {
			/* the mesh force 2 (k-bar + i om c_g) e_j through W^T */
			const gsl_complex g = gsl_complex_rect(2.0 * c->kbar, 2.0 * om * P->mesh_damping_N_s_per_m);
			gsl_vector_complex_set(F, 0, gsl_complex_mul_real(g, c->rb2));
			gsl_vector_complex_set(F, (size_t)(1 + input_index), gsl_complex_mul_real(g, c->rb1));
		} else if (input == PRSM_VIB_IN_NUT_FORCE) {
			gsl_vector_complex_set(F, (size_t)ya, gsl_complex_rect(1.0, 0.0));
		} else {
			gsl_vector_complex_set(F, (size_t)ya, gsl_complex_rect(-m->m_axial * om * om, 0.0));
		}
		for (int i = 0; i < n; i++)
			gsl_vector_complex_set(F, (size_t)i, gsl_complex_mul_real(gsl_vector_complex_get(F, (size_t)i), s[i] / (w * w)));
		int sg;
		gsl_linalg_complex_LU_decomp(D, perm, &sg);
		if (gsl_linalg_complex_LU_solve(D, perm, F, X) != 0) {
			rc = prsm_error_set(err, PRSM_ENOCONVERGE, NULL, "the FRF system is singular at %g", om);
			goto cleanup;
		}
		gsl_complex y;
		if (c->pair) {
			y = gsl_complex_mul_real(gsl_vector_complex_get(X, 0), s[0]);
		} else if (output == PRSM_VIB_OUT_MESH_DEFLECTION) {
			y = gsl_complex_add(gsl_complex_mul_real(gsl_vector_complex_get(X, 0), s[0] * c->rb2),
			                    gsl_complex_mul_real(gsl_vector_complex_get(X, (size_t)(1 + output_index)),
			                                         s[1 + output_index] * c->rb1));
		} else {
			y = gsl_complex_mul_real(gsl_vector_complex_get(X, (size_t)ya), s[ya]);
			if (output == PRSM_VIB_OUT_THREAD_FORCE)
				y = gsl_complex_mul(y, gsl_complex_rect(m->k_axial, om * P->axial_damping_N_s_per_m));
		}
		re[f] = GSL_REAL(y);
		im[f] = GSL_IMAG(y);
	}
cleanup:
	gsl_matrix_complex_free(D);
	gsl_vector_complex_free(F);
	gsl_vector_complex_free(X);
	gsl_permutation_free(perm);
	return rc;
}

void prsm_vib_half_power_of(prsm_vib_half_power *out, const double *omega, const double *mag, size_t n)
{
	memset(out, 0, sizeof *out);
	out->modal_damping_ratio = NAN;
	out->modal_omega = NAN;
	out->damping_ratio = NAN;
	out->grid = n;
	if (n < 3) {
		snprintf(out->reason, sizeof out->reason, "fewer than three frequencies");
		return;
	}
	size_t p = 0;
	for (size_t i = 1; i < n; i++)
		if (mag[i] > mag[p])
			p = i;
	if (p == 0 || p == n - 1) {
		snprintf(out->reason, sizeof out->reason, "the peak is at the edge of the frequency range");
		return;
	}
	/* parabola through the top three points */
	const double x0 = omega[p - 1], x1 = omega[p], x2 = omega[p + 1];
	const double y0 = mag[p - 1], y1 = mag[p], y2 = mag[p + 1];
	const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), a = (d12 - d01) / (x2 - x0);
	double xp = x1, yp = y1;
	if (a < 0.0) {
		const double b = d01 - a * (x0 + x1);
		xp = -b / (2.0 * a);
		yp = y0 + d01 * (xp - x0) + a * (xp - x0) * (xp - x1);
	}
	out->peak_omega = xp;
	out->peak_magnitude = yp;
	const double half = yp / sqrt(2.0);
	/* left and right, within the same peak (|H| falling all the way) */
	size_t i = p;
	while (i > 0 && mag[i - 1] >= half) {
		if (mag[i - 1] > mag[i]) {
			snprintf(out->reason, sizeof out->reason, "a neighbouring peak lies inside the half-power band");
			return;
		}
		i--;
	}
	if (i == 0) {
		snprintf(out->reason, sizeof out->reason, "the half-power band leaves the frequency range (below)");
		return;
	}
	out->omega_1 = omega[i - 1] + (half - mag[i - 1]) * (omega[i] - omega[i - 1]) / (mag[i] - mag[i - 1]);
	size_t j = p;
	while (j + 1 < n && mag[j + 1] >= half) {
		if (mag[j + 1] > mag[j]) {
			snprintf(out->reason, sizeof out->reason, "a neighbouring peak lies inside the half-power band");
			return;
		}
		j++;
	}
	if (j + 1 == n) {
		snprintf(out->reason, sizeof out->reason, "the half-power band leaves the frequency range (above)");
		return;
	}
	out->omega_2 = omega[j] + (half - mag[j]) * (omega[j + 1] - omega[j]) / (mag[j + 1] - mag[j]);
	out->damping_ratio = (out->omega_2 - out->omega_1) / (2.0 * xp);
	out->defined = 1;
}

int prsm_vib_half_power_run(prsm_vib_half_power *out, const prsm_vib_model *m, const prsm_vib_linear *l, int input,
                            int input_index, int output, int output_index, double lo, double hi, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	if (!(lo > 0.0 && hi > lo && isfinite(hi)))
		return prsm_error_set(err, PRSM_EINVAL, "/dynamics/frf", "the band must be 0 < lo < hi");
	/* step <= zeta omega / 50 of the least-damped mode inside the band */
	const double to_rad = m->c.pair ? 1.0 : 2.0 * M_PI;
	double step = (hi - lo) / 2000.0;
	for (int k = 0; k < l->eigenvalues; k++) {
		if (l->kind[k] != PRSM_VIB_EIG_OSCILLATORY)
			continue;
		const double wk = l->frequency_Hz[k] * to_rad;
		if (wk >= lo && wk <= hi)
			step = fmin(step, l->damping_ratio[k] * wk / 50.0);
	}
	double nn = ceil((hi - lo) / step) + 1.0;
	if (nn > 200000.0)
		nn = 200000.0;
	const size_t n = (size_t)nn;
	double *w = calloc(n, sizeof *w), *re = calloc(n, sizeof *re), *im = calloc(n, sizeof *im);
	if (!w || !re || !im) {
		free(w);
		free(re);
		free(im);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu frequencies", n);
	}
	for (size_t i = 0; i < n; i++)
		w[i] = lo + (hi - lo) * (double)i / (double)(n - 1);
	int rc = prsm_vib_frf(re, im, m, l, input, input_index, output, output_index, w, n, err);
	if (rc == 0) {
		for (size_t i = 0; i < n; i++)
			re[i] = hypot(re[i], im[i]);
		prsm_vib_half_power_of(out, w, re, n);
		/* the modal damping of the eigenvalue at the peak; another distinct mode inside the band */
		double best = INFINITY;
		for (int k = 0; k < l->eigenvalues; k++) {
			if (l->kind[k] != PRSM_VIB_EIG_OSCILLATORY)
				continue;
			const double wk = l->frequency_Hz[k] * to_rad;
			if (fabs(wk - out->peak_omega) < best) {
				best = fabs(wk - out->peak_omega);
				out->modal_omega = wk;
				out->modal_damping_ratio = l->damping_ratio[k];
			}
		}
		if (out->defined) {
			for (int k = 0; k < l->eigenvalues; k++) {
				if (l->kind[k] != PRSM_VIB_EIG_OSCILLATORY)
					continue;
				const double wk = l->frequency_Hz[k] * to_rad;
				if (wk >= out->omega_1 && wk <= out->omega_2 && fabs(wk - out->modal_omega) > 1e-6 * out->modal_omega) {
					out->defined = 0;
					out->damping_ratio = NAN;
					snprintf(out->reason, sizeof out->reason,
					         "another mode (%.6g) lies inside the half-power band [%.6g, %.6g]", wk, out->omega_1,
					         out->omega_2);
					break;
				}
			}
		}
		out->grid = n;
	}
	free(w);
	free(re);
	free(im);
	return rc;
}
