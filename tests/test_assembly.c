/*
 * test_assembly.c: docs/model/errors-and-assembly.md and §4 at the assembly level — part errors to every flank gap
 * (linear against exact), backlash, the elastic load sharing against closed forms and finite
 * differences, transmission error and its spectrum, invariance under relabelling.
 */
#include "test_support.h"

#include <stdlib.h>
#include <string.h>

#include "model/analysis.h"
#include "model/assembly.h"
#include "model/assembly_report.h"
#include "util/clock.h"

typedef struct {
	prsm_design d;
	prsm_analysis a;
	prsm_assembly as;
	prsm_assembly_gaps plus, minus, ref, ref2;
} fixture;

/* Case A (docs/model/geometry-and-meshing.md), 20 um of total axial play, 7000 N. */
static fixture *make(int starts, double pitch, double rr, double beta_deg, int Z, int nt, int hand)
{
	fixture *f = calloc(1, sizeof *f);
	assert_non_null(f);
	standard_design(&f->d, starts, pitch, rr, beta_deg, Z, nt);
	f->d.hand = hand;
	f->d.target_axial_clearance_mm = 0.020;
	f->d.thinning_rule = PRSM_THINNING_EQUAL_GAPS;
	f->d.axial_load_N = 7000.0;
	prsm_problems w;
	prsm_problems_init(&w);
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_analysis_nominal(&f->a, &f->d, &w, &err), 0);
	assert_int_equal(prsm_assembly_init(&f->as, &f->d, &f->a, &err), 0);
	return f;
}

static fixture *make_case_a(void)
{
	return make(5, 2.0, 3.25, 45.0, 10, 10, PRSM_HAND_RIGHT);
}

/* deterministic high-entropy numbers in [-1, 1) */
static double rnd(unsigned *s)
{
	*s = *s * 1664525u + 1013904223u;
	return (double)(*s >> 8) / (double)(1u << 23) - 1.0;
}

/* A random error set with lengths up to `um` micrometres (angles scaled alike). The three
 * sources of a roller's axis offset (pin hole, run-out, carrier) share `um` between them, so
 * that no perturbation of a pair exceeds it. */
static void random_errors(prsm_errors *e, int Z, int n, double um, unsigned seed)
{
	unsigned s = seed;
	const double L = um * 1e-3, ang = um * 1e-4; /* 50 um ~ 5 mrad */
	prsm_errors_zero(e, Z);
	prsm_body_errors *b[2] = {&e->screw, &e->nut};
	for (int i = 0; i < 2; i++) {
		b[i]->pitch_radius_mm = L * rnd(&s);
		b[i]->thickness_mm = L * rnd(&s);
		b[i]->flank_angle_rad = ang * rnd(&s);
		b[i]->runout_mm = L * fabs(rnd(&s));
		b[i]->runout_phase_rad = M_PI * rnd(&s);
		b[i]->lead_deviation = L / 300.0 * rnd(&s);
		b[i]->lead_periodic_mm = L * fabs(rnd(&s));
		b[i]->lead_periodic_phase_rad = M_PI * rnd(&s);
		for (int k = 0; k < n; k++)
			b[i]->start_index_rad[k] = ang * rnd(&s);
		b[i]->tilt_rad = 0.1 * ang * fabs(rnd(&s));
		b[i]->tilt_phase_rad = M_PI * rnd(&s);
	}
	e->carrier.runout_mm = L / 3.0 * fabs(rnd(&s));
	e->carrier.runout_phase_rad = M_PI * rnd(&s);
	for (int j = 0; j < Z; j++) {
		prsm_roller_errors *r = &e->roller[j];
		r->pitch_radius_mm = L * rnd(&s);
		r->thickness_mm = L * rnd(&s);
		r->arc_radius_mm = L * rnd(&s);
		r->runout_mm = L / 3.0 * fabs(rnd(&s));
		r->runout_phase_rad = M_PI * rnd(&s);
		r->lead_deviation = L / 300.0 * rnd(&s);
		r->lead_periodic_mm = L * fabs(rnd(&s));
		r->lead_periodic_phase_rad = M_PI * rnd(&s);
		r->pin_radial_mm = L / 3.0 * rnd(&s);
		r->pin_tangential_mm = L / 3.0 * rnd(&s);
		r->gear_phase_rad = ang * rnd(&s);
		r->tilt_radial_rad = 0.1 * ang * rnd(&s);
		r->tilt_tangential_rad = 0.1 * ang * rnd(&s);
	}
}

static const double *gap(const prsm_assembly_gaps *g, const fixture *f, int side, int j)
{
	return &g->gap_mm[side][j * f->as.threads];
}

/* With no errors every gap is the nominal one and B = 2 (g_sr + g_nr), at every angle. */
static void test_zero_errors_nominal(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	for (int i = 0; i < 5; i++) {
		const double th = 1.37 * i;
		prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, th, PRSM_MODE_EXACT);
		prsm_assembly_gaps_at(&f->minus, &f->as, &e, PRSM_DIR_MINUS, th, PRSM_MODE_EXACT);
		assert_int_equal(f->plus.edge_contacts + f->plus.failed_contacts, 0);
		for (int j = 0; j < f->as.rollers * f->as.threads; j++) {
			assert_close(f->plus.gap_mm[0][j], f->a.screw.gap_mm, 1e-12);
			assert_close(f->plus.gap_mm[1][j], f->a.nut.gap_mm, 1e-12);
			assert_close(f->minus.gap_mm[0][j], f->a.screw.gap_mm, 1e-12);
			assert_close(f->minus.gap_mm[1][j], f->a.nut.gap_mm, 1e-12);
		}
		assert_close(prsm_assembly_backlash(&f->as, &f->plus, &f->minus, NULL, NULL), 0.020, 1e-12);
	}
	free(f);
}

/* docs/model/errors-and-assembly.md: linear within 1 % of the gap change of exact, for random error sets up to 50 um,
 * both hands, at several angles. "Gap change" is the sum of the first-order contributions'
 * magnitudes. Profile errors (roller arc radius, flank angles) are left out here: at the nut's
 * conformal contact their first-order effect vanishes and the whole change is the second-order
 * profile mismatch (test_profile_errors_second_order bounds it). */
static void test_linear_matches_exact(void **state)
{
	(void)state;
	double worst = 0.0;
	for (int hand = -1; hand <= 1; hand += 2) {
		fixture *f = make(5, 2.0, 3.25, 45.0, 10, 10, hand);
		for (int trial = 0; trial < 6; trial++) {
			prsm_errors e;
			random_errors(&e, f->as.rollers, f->as.starts, 50.0, 977u * (unsigned)trial + 13u);
			e.screw.flank_angle_rad = e.nut.flank_angle_rad = 0.0;
			for (int j = 0; j < f->as.rollers; j++)
				e.roller[j].arc_radius_mm = 0.0;
			const double th = 0.913 * trial - 1.1;
			for (int dir = 0; dir < 2; dir++) {
				prsm_assembly_gaps_at(&f->plus, &f->as, &e, dir, th, PRSM_MODE_LINEAR);
				assert_int_equal(prsm_assembly_gaps_at(&f->ref, &f->as, &e, dir, th, PRSM_MODE_EXACT), 0);
				for (int side = 0; side < 2; side++)
					for (int j = 0; j < f->as.rollers; j++)
						for (int k = 0; k < f->as.threads; k++) {
							double p[PRSM_PERTURB_COUNT], scale = 0.0;
							prsm_assembly_perturbation(p, &f->as, &e, j, k, side, dir, th);
							for (int i = 0; i < PRSM_PERTURB_COUNT; i++)
								scale += fabs(f->as.pairs[side][dir].sens[i] * p[i]);
							const double lin = gap(&f->plus, f, side, j)[k];
							const double ex = gap(&f->ref, f, side, j)[k];
							worst = fmax(worst, fabs(lin - ex) / scale);
							assert_close(lin, ex, 0.01 * scale + 1e-12);
							/* the bulk path and the one-contact path agree */
							double gl = prsm_assembly_gap_linear(&f->as.pairs[side][dir], p);
							assert_close(gl, lin, 1e-12);
						}
			}
		}
		free(f);
	}
	print_message("worst |linear - exact| / scale: %.4f\n", worst);
}

/* Every field of the error set: the gap sensitivity of linear mode (um of gap per unit of the
 * error, a central difference of linear mode, which is exact for it) against a central finite
 * difference of exact mode, at a random base set of 10 um, for every contact. */
static void test_error_sensitivities_fd(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors base;
	random_errors(&base, f->as.rollers, f->as.starts, 10.0, 2024u);
	/* the fields: every double of screw, nut, carrier and rollers 0 and 5 */
	double *fields[80];
	int nf = 0;
	double *blocks[4] = {(double *)&base.screw, (double *)&base.nut, (double *)&base.roller[0],
	                     (double *)&base.roller[5]};
	const size_t sizes[4] = {sizeof base.screw, sizeof base.nut, sizeof base.roller[0], sizeof base.roller[5]};
	for (int b = 0; b < 4; b++)
		for (size_t i = 0; i < sizes[b] / sizeof(double) && nf < 78; i++)
			fields[nf++] = blocks[b] + i;
	fields[nf++] = &base.carrier.runout_mm;
	fields[nf++] = &base.carrier.runout_phase_rad;
	const double h = 1e-4; /* 0.1 um or 0.1 mrad */
	const double th = 0.77;
	int checked = 0;
	for (int i = 0; i < nf; i++) {
		const double keep = *fields[i];
		for (int dir = 0; dir < 2; dir++) {
			*fields[i] = keep + h;
			prsm_assembly_gaps_at(&f->plus, &f->as, &base, dir, th, PRSM_MODE_LINEAR);
			prsm_assembly_gaps_at(&f->ref, &f->as, &base, dir, th, PRSM_MODE_EXACT);
			*fields[i] = keep - h;
			prsm_assembly_gaps_at(&f->minus, &f->as, &base, dir, th, PRSM_MODE_LINEAR);
			prsm_assembly_gaps_at(&f->ref2, &f->as, &base, dir, th, PRSM_MODE_EXACT);
			*fields[i] = keep;
			for (int side = 0; side < 2; side++)
				for (int c = 0; c < f->as.rollers * f->as.threads; c++) {
					const double lin = (f->plus.gap_mm[side][c] - f->minus.gap_mm[side][c]) / (2 * h);
					const double ex = (f->ref.gap_mm[side][c] - f->ref2.gap_mm[side][c]) / (2 * h);
					/* second order at a 10 um base: a few percent of the sensitivity, plus the
					 * profile terms whose first order is nil at the nut (up to 0.035 um per um or per mrad at
					 * 10 um): a wrong sign or factor in the mapping is O(1) */
					assert_close(lin, ex, 0.03 * fabs(ex) + 0.05);
					checked += fabs(ex) > 1e-3;
				}
		}
	}
	print_message("%d fields, %d non-zero sensitivities checked\n", nf, checked);
	assert_true(checked > 1000);
	free(f);
}

/* Profile errors alone (roller arc radius up to 50 um, flank angles up to 5 mrad, together):
 * linear mode misses the second-order mismatch of the flank profiles, which at the nut's
 * conformal contact is all there is. Measured: 0.65 um at most; the bound held here is 1 um
 * (2 % of the largest error). docs/errors-and-assembly.md tells users to take exact mode for profile studies. */
static void test_profile_errors_second_order(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	unsigned s = 99u;
	double worst = 0.0;
	for (int trial = 0; trial < 8; trial++) {
		prsm_errors_zero(&e, f->as.rollers);
		e.screw.flank_angle_rad = 0.005 * rnd(&s);
		e.nut.flank_angle_rad = 0.005 * rnd(&s);
		for (int j = 0; j < f->as.rollers; j++)
			e.roller[j].arc_radius_mm = 0.050 * rnd(&s);
		for (int dir = 0; dir < 2; dir++) {
			prsm_assembly_gaps_at(&f->plus, &f->as, &e, dir, 0.0, PRSM_MODE_LINEAR);
			prsm_assembly_gaps_at(&f->ref, &f->as, &e, dir, 0.0, PRSM_MODE_EXACT);
			for (int side = 0; side < 2; side++)
				for (int i = 0; i < f->as.rollers * f->as.threads; i++) {
					const double d = fabs(f->plus.gap_mm[side][i] - f->ref.gap_mm[side][i]);
					worst = fmax(worst, d);
					assert_true(d < 0.001);
				}
		}
	}
	print_message("profile errors: worst |linear - exact| %.3f um\n", worst * 1e3);
	free(f);
}

/* A pure thickness error moves every gap of that part 1:1 per flank, and the backlash by the
 * thickness change (both directions). */
static void test_thickness_one_to_one(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	e.screw.thickness_mm = 0.0123;
	for (int mode = 0; mode < 2; mode++) {
		prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, 0.4, mode);
		prsm_assembly_gaps_at(&f->minus, &f->as, &e, PRSM_DIR_MINUS, 0.4, mode);
		for (int j = 0; j < f->as.rollers * f->as.threads; j++) {
			assert_close(f->plus.gap_mm[0][j], f->a.screw.gap_mm - 0.00615, 1e-12);
			assert_close(f->minus.gap_mm[0][j], f->a.screw.gap_mm - 0.00615, 1e-12);
			assert_close(f->plus.gap_mm[1][j], f->a.nut.gap_mm, 1e-12);
		}
		assert_close(prsm_assembly_backlash(&f->as, &f->plus, &f->minus, NULL, NULL), 0.020 - 0.0123, 1e-12);
	}
	free(f);
}

/* A roller's radial shift moves its two gaps by equal and opposite amounts (+1.008, -1.000 in
 * case A) in both directions; the other rollers do not move. */
static void test_roller_radial_shift(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	const double da = 0.0171;
	e.roller[3].pin_radial_mm = da;
	for (int dir = 0; dir < 2; dir++) {
		prsm_assembly_gaps_at(&f->plus, &f->as, &e, dir, 2.2, PRSM_MODE_EXACT);
		for (int j = 0; j < f->as.rollers; j++)
			for (int k = 0; k < f->as.threads; k++) {
				const double ds = gap(&f->plus, f, 0, j)[k] - f->a.screw.gap_mm;
				const double dn = gap(&f->plus, f, 1, j)[k] - f->a.nut.gap_mm;
				if (j != 3) {
					assert_close(ds, 0.0, 1e-12);
					assert_close(dn, 0.0, 1e-12);
					continue;
				}
				assert_close(ds / da, 1.008, 2e-3);
				assert_close(dn / da, -1.000, 2e-3);
				assert_close(ds + dn, 0.0, 0.02 * da); /* the chain barely moves */
			}
	}
	free(f);
}

/* Screw run-out e: the chain of each roller changes by about e tan(beta) times the cosine of the
 * angle between the offset and the roller (docs/model/errors-and-assembly.md), closing where the screw leans towards
 * the roller. At beta = 38.5 and 52 deg as well. */
static void test_screw_runout_chain(void **state)
{
	(void)state;
	const double betas[] = {45.0, 38.5, 52.0};
	for (int b = 0; b < 3; b++) {
		fixture *f = make(5, 2.0, 3.25, betas[b], 10, 10, PRSM_HAND_RIGHT);
		prsm_errors e;
		prsm_errors_zero(&e, f->as.rollers);
		const double ecc = 0.0137, phi = 0.77;
		e.screw.runout_mm = ecc;
		e.screw.runout_phase_rad = phi;
		const double g0 = f->a.screw.gap_mm + f->a.nut.gap_mm;
		double amp = 0.0;
		for (int i = 0; i < 48; i++) {
			const double th = 2.0 * M_PI * i / 48;
			prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, th, PRSM_MODE_EXACT);
			for (int j = 0; j < f->as.rollers; j++) {
				const double psi = 2.0 * M_PI * j / f->as.rollers + f->as.carrier_ratio * th;
				const double c = cos(th + phi - psi);
				const double dchain = gap(&f->plus, f, 0, j)[0] + gap(&f->plus, f, 1, j)[0] - g0;
				/* the closing part follows -e tan(beta) cos */
				assert_close(dchain, -ecc * tan(betas[b] * DEG) * c, 0.12 * ecc);
				amp = fmax(amp, fabs(dchain));
			}
		}
		assert_close(amp / (ecc * tan(betas[b] * DEG)), 1.0, 0.1);
		free(f);
	}
}

/* Equal gaps: every roller carries F/Z, and u is the closed form of two Hertz contacts in
 * series per thread, computed here from prsm_hertz_solve directly. */
static void test_equal_sharing_closed_form(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, 0.0, PRSM_MODE_LINEAR);
	prsm_assembly_state st;
	const double F = 7000.0;
	prsm_assembly_solve(&st, &f->as, &f->plus, F, 0);
	assert_close(st.sharing_factor, 1.0, 1e-9);
	assert_int_equal(st.loaded_rollers, 10);
	for (int j = 0; j < 10; j++)
		assert_close(st.roller_load_N[j], 700.0, 1e-7);
	/* each contact: axial 70 N, normal Q = 70 / |n_z|, approach along z = delta_n / |n_z| */
	const prsm_material *m = &f->d.screw_material;
	double u = f->a.screw.gap_mm + f->a.nut.gap_mm;
	const prsm_contact *c[2] = {&f->a.screw, &f->a.nut};
	for (int s = 0; s < 2; s++) {
		prsm_hertz h;
		const double nz = fabs(c[s]->normal[2]);
		assert_int_equal(prsm_hertz_solve(&h, c[s]->curvature_per_mm[0], c[s]->curvature_per_mm[1],
		                                  m->E_MPa, m->poisson, m->E_MPa, m->poisson, 70.0 / nz), 0);
		u += h.delta_mm / nz;
	}
	assert_close(st.u_mm, u, 1e-10);
	/* stiffness against a central difference of the solve and the nominal formula */
	prsm_assembly_state a = st, b = st;
	prsm_assembly_solve(&a, &f->as, &f->plus, F * 1.001, 1);
	prsm_assembly_solve(&b, &f->as, &f->plus, F * 0.999, 1);
	assert_close(st.stiffness_N_per_mm, 0.002 * F / (a.u_mm - b.u_mm), 1e-4 * st.stiffness_N_per_mm);
	assert_close(st.stiffness_N_per_mm, f->as.nominal_stiffness_N_per_mm, 1e-9 * st.stiffness_N_per_mm);
	free(f);
}

/* Random unequal gaps: the solution is an equilibrium (roller sides balance, loads sum to F),
 * stiffness is a finite difference of u(F), and the warm start gives the same answer. */
static void test_elastic_equilibrium(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	for (int trial = 0; trial < 4; trial++) {
		random_errors(&e, f->as.rollers, f->as.starts, 10.0 + 8.0 * trial, 31u + 7u * (unsigned)trial);
		prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, 0.3 * trial, PRSM_MODE_LINEAR);
		const double loads[] = {5.0, 50.0, 7000.0, 70000.0};
		for (int l = 0; l < 4; l++) {
			const double F = loads[l];
			prsm_assembly_state st, warm;
			assert_int_equal(prsm_assembly_solve(&st, &f->as, &f->plus, F, 0), 0);
			assert_int_equal(st.converged, 1);
			assert_true(st.iterations < PRSM_ASSEMBLY_MAX_ITERATIONS);
			double sum = 0.0;
			for (int j = 0; j < f->as.rollers; j++) {
				double S = 0.0, N = 0.0;
				const double *gs = gap(&f->plus, f, 0, j), *gn = gap(&f->plus, f, 1, j);
				for (int k = 0; k < f->as.threads; k++) {
					double ds = st.w_mm[j] - gs[k], dn = st.u_mm - st.w_mm[j] - gn[k];
					S += ds > 0 ? f->as.k_axial[0] * pow(ds, 1.5) : 0.0;
					N += dn > 0 ? f->as.k_axial[1] * pow(dn, 1.5) : 0.0;
				}
				assert_close(S, N, 1e-9 * F + 1e-12);
				assert_close(st.roller_load_N[j], S, 1e-9 * F + 1e-12);
				sum += S;
			}
			assert_close(sum, F, 1e-9 * F);
			prsm_assembly_state a = st, b = st;
			prsm_assembly_solve(&a, &f->as, &f->plus, F * 1.0001, 1);
			prsm_assembly_solve(&b, &f->as, &f->plus, F * 0.9999, 1);
			assert_close(st.stiffness_N_per_mm, 0.0002 * F / (a.u_mm - b.u_mm), 2e-3 * st.stiffness_N_per_mm);
			warm = st;
			warm.u_mm += 1e-3;
			prsm_assembly_solve(&warm, &f->as, &f->plus, F, 1);
			assert_close(warm.u_mm, st.u_mm, 1e-12);
		}
	}
	free(f);
}

/* A path of screw angles solved warm, as the TE record and the revolution are (Newton on the whole
 * system from the previous angle, moved with the gaps), gives every angle's cold nested solve to
 * the solves' tolerances: u, each roller's load, the stiffness and the sharing factor. Random
 * errors of 5 to 40 um, light and operating loads, coarse and fine angle steps; and a warm start
 * from a state far off (u 50 um away, the rollers misplaced) still lands on the same state. */
static void test_warm_path_matches_cold(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	const double loads[] = {5.0, 50.0, 7000.0};
	const int steps[] = {16, 64};
	for (int trial = 0; trial < 6; trial++) {
		random_errors(&e, f->as.rollers, f->as.starts, 5.0 + 7.0 * trial, 977u + 13u * (unsigned)trial);
		for (int l = 0; l < 3; l++)
			for (int s = 0; s < 2; s++) {
				const double F = loads[l];
				prsm_assembly_state warm, cold;
				for (int i = 0; i < 2 * steps[s]; i++) {
					prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, 2.0 * M_PI * i / steps[s],
					                      PRSM_MODE_LINEAR);
					assert_int_equal(prsm_assembly_solve(&cold, &f->as, &f->plus, F, 0), 0);
					assert_int_equal(prsm_assembly_solve(&warm, &f->as, &f->plus, F, i > 0), 0);
					assert_int_equal(warm.converged, 1);
					/* both stop at |sum of loads - F| <= 1e-11 F: u within that over the stiffness */
					const double du = 4e-11 * F / cold.stiffness_N_per_mm + 1e-15;
					assert_close(warm.u_mm, cold.u_mm, du);
					for (int j = 0; j < f->as.rollers; j++)
						assert_close(warm.roller_load_N[j], cold.roller_load_N[j], 1e-9 * F);
					assert_close(warm.stiffness_N_per_mm, cold.stiffness_N_per_mm,
					             1e-7 * cold.stiffness_N_per_mm);
					assert_close(warm.sharing_factor, cold.sharing_factor, 1e-8);
					assert_int_equal(warm.loaded_rollers, cold.loaded_rollers);
				}
				prsm_assembly_state far = warm;
				far.u_mm += 0.05;
				for (int j = 0; j < f->as.rollers; j++)
					far.w_mm[j] -= 0.01 * (j % 3);
				assert_int_equal(prsm_assembly_solve(&far, &f->as, &f->plus, F, 1), 0);
				assert_close(far.u_mm, warm.u_mm, 4e-11 * F / warm.stiffness_N_per_mm + 1e-15);
			}
	}
	free(f);
}

/* One roller's gap opened: it carries less than F/Z, the others more, and the stiffness drops. */
static void test_open_roller_carries_less(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	e.roller[4].thickness_mm = -0.008; /* thinner: 4 um more play on each of its flanks */
	prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, 0.0, PRSM_MODE_EXACT);
	prsm_assembly_state st;
	prsm_assembly_solve(&st, &f->as, &f->plus, 7000.0, 0);
	assert_true(st.roller_load_N[4] < 0.9 * 700.0);
	for (int j = 0; j < 10; j++)
		if (j != 4)
			assert_true(st.roller_load_N[j] > 700.0);
	assert_true(st.sharing_factor > 1.0);
	assert_true(st.stiffness_N_per_mm < 0.99 * f->as.nominal_stiffness_N_per_mm);
	/* at a light load the opened roller carries nothing at all */
	prsm_assembly_solve(&st, &f->as, &f->plus, 50.0, 0);
	assert_close(st.roller_load_N[4], 0.0, 0.0);
	assert_int_equal(st.loaded_rollers, 9);
	free(f);
}

/* docs/model/errors-and-assembly.md: a solve that cannot balance is reported, never returned as a result. A gap that
 * is not finite (a corrupted perturbation), a load that is not finite or not positive: each
 * returns PRSM_ENOCONVERGE with converged 0, and the TE record counts it as failed. Before this
 * check the solver ran its 200 iterations and returned 0 with NaN loads. */
static void test_nonconvergence_reported(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	prsm_assembly_gaps_at(&f->plus, &f->as, &e, PRSM_DIR_PLUS, 0.0, PRSM_MODE_LINEAR);
	prsm_assembly_state st;
	memset(&st, 0, sizeof st);
	const double bad_loads[] = {NAN, INFINITY, 0.0, -5.0};
	for (int i = 0; i < 4; i++) {
		assert_int_equal(prsm_assembly_solve(&st, &f->as, &f->plus, bad_loads[i], 0), PRSM_ENOCONVERGE);
		assert_int_equal(st.converged, 0);
	}
	const double bad_gaps[] = {NAN, INFINITY, -INFINITY};
	for (int i = 0; i < 3; i++) {
		prsm_assembly_gaps g = f->plus;
		g.gap_mm[1][3 * f->as.threads + 2] = bad_gaps[i]; /* roller 3, thread 2, nut side */
		assert_int_equal(prsm_assembly_solve(&st, &f->as, &g, 7000.0, 0), PRSM_ENOCONVERGE);
		assert_int_equal(st.converged, 0);
	}
	/* the same gaps, all finite: converges */
	assert_int_equal(prsm_assembly_solve(&st, &f->as, &f->plus, 7000.0, 0), 0);
	assert_int_equal(st.converged, 1);
	free(f);
}

static prsm_assembly_workspace *workspace(const fixture *f, const prsm_assembly_options *o);
static void free_workspace(prsm_assembly_workspace *ws);

/* The service's budget: the cost counts every gap the analysis evaluates (record + three passes
 * over the revolution, two sides of every contact), exact mode weighted; a raised cancel flag or
 * a deadline already past stops the analysis with PRSM_ECANCELLED, and neither changes the
 * result when it does not fire. */
static void test_cost_and_stop(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	random_errors(&e, f->as.rollers, f->as.starts, 12.0, 4242u);
	prsm_assembly_options o;
	prsm_assembly_options_default(&o);
	o.stroke_mm = 37.0;
	int n, m;
	prsm_assembly_record_length(&n, &m, &f->as, &o);
	const double contacts = 2.0 * f->as.rollers * f->as.threads;
	assert_close(prsm_assembly_cost(&f->as, &o), contacts * (n + 3.0 * o.angles_per_revolution), 0.0);
	o.mode = PRSM_MODE_EXACT;
	assert_close(prsm_assembly_cost(&f->as, &o), PRSM_ASSEMBLY_EXACT_COST * contacts * (n + 3.0 * o.angles_per_revolution),
	             0.0);
	o.mode = PRSM_MODE_LINEAR;

	prsm_assembly_workspace *ws = workspace(f, &o);
	prsm_assembly_report ref, r;
	assert_int_equal(prsm_assembly_analyse(&ref, &f->as, &e, &o, ws), 0);
	prsm_cancel_flag flag = 0;
	o.cancel = &flag;
	o.deadline_s = prsm_clock_seconds() + 3600.0;
	assert_int_equal(prsm_assembly_analyse(&r, &f->as, &e, &o, ws), 0);
	const double got[] = {r.backlash_mm, r.backlash_mean_mm, r.sharing_factor_max, r.operating.u_mm,
	                      r.stiffness_ratio, r.te_revolution_pp_mm, r.te_stroke_pp_mm, r.lead_deviation,
	                      r.peak_amplitude_mm, r.line_amplitude_mm[0]};
	const double want[] = {ref.backlash_mm, ref.backlash_mean_mm, ref.sharing_factor_max, ref.operating.u_mm,
	                       ref.stiffness_ratio, ref.te_revolution_pp_mm, ref.te_stroke_pp_mm, ref.lead_deviation,
	                       ref.peak_amplitude_mm, ref.line_amplitude_mm[0]};
	assert_memory_equal(got, want, sizeof got); /* bit for bit */
	prsm_cancel_set(&flag, 1);
	assert_int_equal(prsm_assembly_analyse(&r, &f->as, &e, &o, ws), PRSM_ECANCELLED);
	o.cancel = NULL;
	o.deadline_s = prsm_clock_seconds() - 1.0;
	assert_int_equal(prsm_assembly_analyse(&r, &f->as, &e, &o, ws), PRSM_ECANCELLED);
	free_workspace(ws);
	free(f);
}

static prsm_assembly_workspace *workspace(const fixture *f, const prsm_assembly_options *o)
{
	int n, m;
	prsm_assembly_record_length(&n, &m, &f->as, o);
	prsm_assembly_workspace *ws = calloc(1, sizeof *ws);
	assert_non_null(ws);
	ws->te_mm = calloc((size_t)n, sizeof(double));
	ws->spectrum_mm = calloc((size_t)m, sizeof(double));
	assert_non_null(ws->te_mm);
	assert_non_null(ws->spectrum_mm);
	return ws;
}

static void free_workspace(prsm_assembly_workspace *ws)
{
	free(ws->te_mm);
	free(ws->spectrum_mm);
	free(ws);
}

/* No errors: TE is identically zero and the load is shared equally over the revolution. */
static void test_zero_errors_te(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	prsm_assembly_options o;
	prsm_assembly_options_default(&o);
	o.stroke_mm = 100.0;
	prsm_assembly_workspace *ws = workspace(f, &o);
	prsm_assembly_report r;
	prsm_assembly_analyse(&r, &f->as, &e, &o, ws);
	for (int i = 0; i < r.record_length; i++)
		assert_close(ws->te_mm[i], 0.0, 1e-15);
	assert_close(r.te_revolution_pp_mm, 0.0, 1e-15);
	assert_close(r.sharing_factor_max, 1.0, 1e-9);
	assert_close(r.backlash_min_mm, 0.020, 1e-12);
	assert_close(r.backlash_max_mm, 0.020, 1e-12);
	assert_close(r.stiffness_ratio, 1.0, 1e-9);
	free_workspace(ws);
	free(f);
}

/* A cumulative screw lead error: TE grows linearly over the stroke and the lead deviation per
 * 300 mm reads the error back. */
static void test_lead_error_linear_te(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_errors e;
	prsm_errors_zero(&e, f->as.rollers);
	e.screw.lead_deviation = 0.0123 / 300.0; /* 12.3 um per 300 mm */
	prsm_assembly_options o;
	prsm_assembly_options_default(&o);
	o.stroke_mm = 250.0;
	prsm_assembly_workspace *ws = workspace(f, &o);
	prsm_assembly_report r;
	prsm_assembly_analyse(&r, &f->as, &e, &o, ws);
	assert_true(r.has_stroke);
	assert_close(r.lead_deviation * 300.0, 0.0123, 1e-9);
	assert_close(r.te_stroke_residual_pp_mm, 0.0, 1e-9);
	/* |TE| at the end of the stroke: 250 mm x 12.3/300 um/mm */
	const int ns = (int)ceil(250.0 / 10.0 * 64) + 1;
	assert_close(fabs(ws->te_mm[ns - 1]), 0.0123 * 250.0 / 300.0, 1e-9);
	free_workspace(ws);
	free(f);
}

/* Spectrum helper: a sine of known amplitude and frequency over a trend reads back. */
static void test_signal_amplitude(void **state)
{
	(void)state;
	const int per_rev = 64, n = 64 * 16 + 1;
	double *x = malloc(n * sizeof *x);
	for (int i = 0; i < n; i++)
		x[i] = 0.3 + 0.002 * i + 1.7 * sin(2.0 * M_PI * 2.375 * i / per_rev + 0.4) +
		       0.2 * cos(2.0 * M_PI * 6.25 * i / per_rev);
	assert_close(prsm_signal_amplitude(x, n, per_rev, 2.375), 1.7, 0.01);
	assert_close(prsm_signal_amplitude(x, n, per_rev, 6.25), 0.2, 0.005);
	assert_close(prsm_signal_amplitude(x, n, per_rev, 4.1), 0.0, 0.01);
	free(x);
}

/* docs/model/errors-and-assembly.md frequencies: a roller-fixed error is seen at the roller's spin rate; screw run-out
 * alone cancels at its first harmonic 1 - k_c among evenly spaced rollers and shows at the
 * roller pass frequency Z (1 - k_c); nut run-out at Z k_c; one roller's position error breaks
 * the cancellation. */
static void test_te_spectrum_frequencies(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	prsm_assembly_options o;
	prsm_assembly_options_default(&o);
	o.angles_per_revolution = 128;
	o.spectrum_revolutions = 24;
	prsm_assembly_workspace *ws = workspace(f, &o);
	prsm_assembly_report r;
	prsm_errors e;
	prsm_assembly_frequencies fr;
	prsm_assembly_frequencies_of(&fr, &f->as);
	const double bin = 2.0 / 24.0; /* the Hann main lobe half-width */

	/* roller 3 wobbles (periodic lead error): its spin rate */
	prsm_errors_zero(&e, f->as.rollers);
	e.roller[3].lead_periodic_mm = 0.004;
	prsm_assembly_analyse(&r, &f->as, &e, &o, ws);
	print_message("roller wobble: peak %.4f /rev %.3f um; spin %.4f\n", r.peak_frequency_per_rev,
	              r.peak_amplitude_mm * 1e3, fr.roller_spin);
	assert_close(r.peak_frequency_per_rev, fr.roller_spin, bin);

	/* screw run-out alone */
	prsm_errors_zero(&e, f->as.rollers);
	e.screw.runout_mm = 0.008;
	e.screw.runout_phase_rad = 0.3;
	prsm_assembly_analyse(&r, &f->as, &e, &o, ws);
	const double cancelled = r.line_amplitude_mm[0];
	print_message("screw run-out: peak %.4f /rev %.3f um; 1-kc line %.4f um, pass %.4f\n",
	              r.peak_frequency_per_rev, r.peak_amplitude_mm * 1e3, cancelled * 1e3,
	              fr.roller_pass_screw);
	assert_close(r.peak_frequency_per_rev, fr.roller_pass_screw, bin);
	assert_true(cancelled < 0.05 * r.peak_amplitude_mm);

	/* ... with one roller's pin hole off: the first harmonic comes back */
	e.roller[0].pin_tangential_mm = 0.010;
	e.roller[0].thickness_mm = -0.004;
	prsm_assembly_analyse(&r, &f->as, &e, &o, ws);
	print_message("screw run-out + roller 0: 1-kc line %.4f um\n", r.line_amplitude_mm[0] * 1e3);
	assert_true(r.line_amplitude_mm[0] > 10.0 * cancelled);
	assert_true(r.line_amplitude_mm[0] > 0.1e-3);

	/* nut run-out alone: Z k_c */
	prsm_errors_zero(&e, f->as.rollers);
	e.nut.runout_mm = 0.008;
	prsm_assembly_analyse(&r, &f->as, &e, &o, ws);
	print_message("nut run-out: peak %.4f /rev; pass %.4f; kc line %.5f um\n", r.peak_frequency_per_rev,
	              fr.roller_pass_nut, r.line_amplitude_mm[1] * 1e3);
	assert_close(r.peak_frequency_per_rev, fr.roller_pass_nut, bin);
	assert_true(r.line_amplitude_mm[1] < 0.05 * r.peak_amplitude_mm);
	free_workspace(ws);
	free(f);
}

/* Rotating the whole assembly by one roller pitch (roller j's errors to roller j + 1, directions
 * of run-out and tilt + 2 pi/Z, phases of periodic errors - 2 pi/Z) changes nothing. Start
 * errors are left out: a rotation by 2 pi/Z maps starts onto starts only when Z divides n. */
static void test_rotation_invariance(void **state)
{
	(void)state;
	fixture *f = make_case_a();
	const int Z = f->as.rollers;
	const double d = 2.0 * M_PI / Z;
	prsm_errors e, r;
	random_errors(&e, Z, f->as.starts, 20.0, 4242u);
	memset(e.screw.start_index_rad, 0, sizeof e.screw.start_index_rad);
	memset(e.nut.start_index_rad, 0, sizeof e.nut.start_index_rad);
	r = e;
	for (int j = 0; j < Z; j++)
		r.roller[(j + 1) % Z] = e.roller[j];
	prsm_body_errors *b[2] = {&r.screw, &r.nut};
	for (int i = 0; i < 2; i++) {
		b[i]->runout_phase_rad += d;
		b[i]->tilt_phase_rad += d;
		b[i]->lead_periodic_phase_rad -= d;
	}
	r.carrier.runout_phase_rad += d;
	prsm_assembly_options o;
	prsm_assembly_options_default(&o);
	o.spectrum_revolutions = 2;
	prsm_assembly_workspace *w1 = workspace(f, &o), *w2 = workspace(f, &o);
	for (int mode = 0; mode < 2; mode++) {
		o.mode = mode;
		prsm_assembly_report r1, r2;
		prsm_assembly_analyse(&r1, &f->as, &e, &o, w1);
		prsm_assembly_analyse(&r2, &f->as, &r, &o, w2);
		for (int j = 0; j < Z; j++)
			for (int k = 0; k < f->as.threads; k++)
				for (int side = 0; side < 2; side++)
					assert_close(gap(&w2->plus, f, side, (j + 1) % Z)[k], gap(&w1->plus, f, side, j)[k], 1e-12);
		assert_close(r2.backlash_mm, r1.backlash_mm, 1e-12);
		assert_close(r2.backlash_min_mm, r1.backlash_min_mm, 1e-12);
		assert_close(r2.operating.u_mm, r1.operating.u_mm, 1e-12);
		assert_close(r2.operating.sharing_factor, r1.operating.sharing_factor, 1e-9);
		for (int i = 0; i < r1.record_length; i++)
			assert_close(w2->te_mm[i], w1->te_mm[i], 1e-12);
	}
	free_workspace(w1);
	free_workspace(w2);
	free(f);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_zero_errors_nominal),
		cmocka_unit_test(test_linear_matches_exact),
		cmocka_unit_test(test_error_sensitivities_fd),
		cmocka_unit_test(test_profile_errors_second_order),
		cmocka_unit_test(test_thickness_one_to_one),
		cmocka_unit_test(test_roller_radial_shift),
		cmocka_unit_test(test_screw_runout_chain),
		cmocka_unit_test(test_equal_sharing_closed_form),
		cmocka_unit_test(test_elastic_equilibrium),
		cmocka_unit_test(test_warm_path_matches_cold),
		cmocka_unit_test(test_open_roller_carries_less),
		cmocka_unit_test(test_nonconvergence_reported),
		cmocka_unit_test(test_cost_and_stop),
		cmocka_unit_test(test_zero_errors_te),
		cmocka_unit_test(test_lead_error_linear_te),
		cmocka_unit_test(test_signal_amplitude),
		cmocka_unit_test(test_te_spectrum_frequencies),
		cmocka_unit_test(test_rotation_invariance),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
