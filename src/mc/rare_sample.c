/*
 * rare_sample.c: the sampling estimators of the rare-event engine (rare.h,
 * docs/rare-events.md): plain Monte Carlo and importance sampling in U, and subset simulation.
 *
 * MC and IS. Samples come in blocks of block_size; block b draws from its own Philox stream, a
 * sample being (with several centres) one uniform choosing the mixture component and then d
 * standard normals by inversion (prsm_normal_quantile of prsm_rng_uniform_pos). A round runs
 * up to round_blocks blocks in parallel, as many as the stop rule is projected to need (from the
 * merged prefix: the same for any thread count); the calling thread then merges the blocks in
 * order and checks the stop rule after each, so the kept samples are always the first blocks of
 * one sequence and a round's blocks after the stopping one are discarded (counted in
 * evaluations, not in samples).
 * With centres c_k and mixture weights pi_k the density is h(u) = sum pi_k phi(u - c_k) and the
 * weight of a sample in the failure domain is phi(u) / h(u), taken in logarithms
 * (-|u|^2 / 2 - logsumexp_k(log pi_k - |u - c_k|^2 / 2)); with one centre it is
 * exp(-c.u + |c|^2 / 2).
 *
 * Subset simulation (Au & Beck 2001). Level 0 is plain MC of N samples (N_c blocks, one stream
 * each). At each level the samples are sorted by g (ties by index); b = the mean of the N_c-th and
 * (N_c + 1)-th smallest g is the next threshold (N_c = round(p0 N)), or the run ends when at
 * least N_c samples have g <= 0. The N_c smallest are the seeds; chain c (its own stream) starts
 * at seed c and makes len_c - 1 modified Metropolis steps (len_c = N / N_c, the remainder spread
 * over the first chains): per component a symmetric proposal xi = u_k + width e, kept with
 * probability min(1, phi(xi) / phi(u_k)) (one uniform per component always drawn); then, when a
 * component moved, g of the candidate decides (accepted when g <= b). The chains of a level run in
 * parallel, each writing its own slots. The estimate is the product of the levels' conditional
 * probabilities; its CoV is sqrt(sum delta_j^2), delta_j^2 = (1 - P_j) / (N P_j) (1 + gamma_j),
 * gamma_j = 2 sum_{k=1}^{len-1} (1 - k N_c / N) rho_j(k) from the chains' indicator
 * autocorrelations (Au & Beck's eq. 29), gamma_0 = 0.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_cdf.h>

#include "mc/dist.h"
#include "mc/rare.h"
#include "mc/rare_internal.h"
#include "util/clock.h"
#include "util/rng.h"

#define MAX_CENTRES 64

static double normal_draw(gsl_rng *r)
{
	return prsm_normal_quantile(prsm_rng_uniform_pos(r));
}

/* log Phi(-b) for b >= 0, asymptotic beyond the doubles' range of Q. */
static double log_q(double b)
{
	double q = gsl_cdf_ugaussian_Q(b);
	if (q > 0.0)
		return log(q);
	return -0.5 * b * b - log(b * sqrt(2.0 * M_PI));
}

/* ---- MC and IS ------------------------------------------------------------------------------ */

typedef struct {
	const prsm_rare_options *o;
	size_t d, nc, B;
	const double *centres;
	double logpi[MAX_CENTRES], cum[MAX_CENTRES];
	uint64_t key;
	size_t first_block;
	/* per block of the round */
	double *s1, *s2, *s3, *s4;
	size_t *nf, *ne, *bad;
	int *code, *lscode;
} is_round;

static double is_log_weight(const is_round *r, const double *u)
{
	size_t d = r->d;
	double uu = rare_dot(u, u, d);
	double l[MAX_CENTRES], mx = -INFINITY;
	for (size_t k = 0; k < r->nc; k++) {
		const double *c = r->centres + k * d;
		double s = 0.0;
		for (size_t i = 0; i < d; i++)
			s += (u[i] - c[i]) * (u[i] - c[i]);
		l[k] = r->logpi[k] - 0.5 * s;
		if (l[k] > mx)
			mx = l[k];
	}
	double sum = 0.0;
	for (size_t k = 0; k < r->nc; k++)
		sum += exp(l[k] - mx);
	return -0.5 * uu - (mx + log(sum));
}

static void is_block_task(rare_worker *w, size_t t, void *argp)
{
	is_round *r = argp;
	const prsm_rare_options *o = r->o;
	size_t d = r->d, b = r->first_block + t;
	double *u = w->b;
	prsm_rng_set_stream(w->rng, o->seed, o->stream_offset + r->key + b);
	double s1 = 0.0, s2 = 0.0, s3 = 0.0, s4 = 0.0;
	size_t nf = 0, ne = 0;
	r->code[t] = 0;
	r->lscode[t] = 0;
	r->bad[t] = SIZE_MAX;
	for (size_t i = 0; i < r->B; i++) {
		size_t k = 0;
		if (r->nc > 1) {
			double v = prsm_rng_uniform_pos(w->rng);
			while (k + 1 < r->nc && v > r->cum[k])
				k++;
		}
		for (size_t j = 0; j < d; j++)
			u[j] = normal_draw(w->rng) + (r->nc ? r->centres[k * d + j] : 0.0);
		double g;
		int lc;
		int rc = rare_eval(w, u, &g, &lc);
		if (rc) {
			r->code[t] = rc;
			r->lscode[t] = lc;
			r->bad[t] = i;
			if (rc != RARE_HALTED)
				ne++;
			break;
		}
		ne++;
		if (g <= 0.0) {
			double wt = r->nc ? exp(is_log_weight(r, u)) : 1.0;
			s1 += wt;
			s2 += wt * wt;
			s3 += wt * wt * wt;
			s4 += (wt * wt) * (wt * wt);
			nf++;
		}
	}
	r->s1[t] = s1;
	r->s2[t] = s2;
	r->s3[t] = s3;
	r->s4[t] = s4;
	r->nf[t] = nf;
	r->ne[t] = ne;
}

static void is_fill(const rare_is_state *st, prsm_rare_is_result *out)
{
	double n = (double)st->samples;
	out->samples = st->samples;
	out->failures = st->failures;
	out->evaluations = st->evaluations;
	out->pf = st->samples ? st->s1 / n : NAN;
	double var = st->samples > 1 ? (st->s2 / n - out->pf * out->pf) * n / (n - 1.0) : NAN;
	if (var < 0.0)
		var = 0.0;
	out->se = sqrt(var / n);
	out->cov = out->pf > 0.0 ? out->se / out->pf : NAN;
	/* the CoV's own relative standard error, from the fourth central moment of I w:
	 * se(var^) / var ~ sqrt((mu4 - var^2) / n) / var, halved for the square root */
	out->cov_rel_error = NAN;
	if (st->samples > 1 && var > 0.0) {
		double p = out->pf, m2 = st->s2 / n, m3 = st->s3 / n, m4 = st->s4 / n;
		double mu4 = m4 - 4.0 * p * m3 + 6.0 * p * p * m2 - 3.0 * p * p * p * p;
		double vv = (mu4 - var * var) / n;
		out->cov_rel_error = vv > 0.0 ? 0.5 * sqrt(vv) / var : 0.0;
	}
	out->lower = fmax(0.0, out->pf - RARE_Z95 * out->se);
	out->upper = out->pf + RARE_Z95 * out->se;
}

/* The stop rule of MC and IS: the CoV target met and, for IS, the CoV itself trustworthy (its
 * own relative error within is_max_cov_error): a few heavy weights (a failure domain far from
 * the design point, e.g. the outside of a convex set) can make the sample CoV small while the
 * estimate is still far off. Plain MC's CoV is the binomial one and needs no such check. */
static int is_target_met(const prsm_rare_is_result *out, const prsm_rare_options *o, size_t n_centres)
{
	if (!(out->cov <= o->target_cov))
		return 0;
	return n_centres == 0 || out->cov_rel_error <= o->is_max_cov_error;
}

/* Blocks of the next round: what the stop rule is projected to need, from the merged prefix
 * (so the same for any thread count), 1..round_blocks: min_samples first, then
 * samples (cov / target)^2 (10 % more) and samples min_failures / failures; round_blocks while
 * nothing can be projected (no failure yet) or without a target (the pilot, its own cap). */
static size_t is_round_size(const rare_is_state *st, const prsm_rare_options *o, int check_target, size_t n_centres)
{
	size_t R = o->round_blocks, B = o->block_size;
	if (!check_target)
		return R;
	double n = (double)st->samples, want = (double)o->min_samples;
	if (st->samples >= o->min_samples) {
		if (st->failures == 0)
			return R;
		prsm_rare_is_result tmp;
		memset(&tmp, 0, sizeof tmp);
		is_fill(st, &tmp);
		want = n * 1.1 * (tmp.cov / o->target_cov) * (tmp.cov / o->target_cov);
		if (n_centres && tmp.cov_rel_error > o->is_max_cov_error)
			want = fmax(want, n * 1.1 * (tmp.cov_rel_error / o->is_max_cov_error) *
			                      (tmp.cov_rel_error / o->is_max_cov_error));
		if (st->failures < o->min_failures)
			want = fmax(want, n * (double)o->min_failures / (double)st->failures);
		if (!(want > n))
			want = n + 1.0;
	}
	double blocks = ceil((want - n) / (double)B);
	if (!(blocks >= 1.0))
		return 1;
	return blocks < (double)R ? (size_t)blocks : R;
}

int rare_is_advance(rare_is_state *st, prsm_rare_is_result *out, rare_pool *pool, const double *centres,
                    const double *weights, size_t n_centres, size_t cap_samples, int check_target,
                    size_t budget, prsm_error *err)
{
	const prsm_rare_options *o = pool->o;
	size_t d = pool->space->d, R = o->round_blocks, B = o->block_size;
	is_round r;
	memset(&r, 0, sizeof r);
	r.o = o;
	r.d = d;
	r.nc = n_centres;
	r.B = B;
	r.centres = centres;
	r.key = n_centres ? RARE_KEY_IS : RARE_KEY_MC;
	if (n_centres > MAX_CENTRES)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "at most %d IS centres", MAX_CENTRES);
	/* mixture weights, normalised, in logarithms */
	double mx = -INFINITY;
	for (size_t k = 0; k < n_centres; k++) {
		double lw;
		if (weights) {
			if (!(weights[k] >= 0.0) || !isfinite(weights[k]))
				return prsm_error_set(err, PRSM_EINVAL, NULL, "IS weight %zu must be finite and >= 0", k);
			lw = log(weights[k]);
		} else {
			lw = log_q(rare_norm(centres + k * d, d));
		}
		r.logpi[k] = lw;
		if (lw > mx)
			mx = lw;
	}
	if (n_centres && !(mx > -INFINITY))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "the IS weights are all zero");
	double tot = 0.0;
	for (size_t k = 0; k < n_centres; k++)
		tot += exp(r.logpi[k] - mx);
	double acc = 0.0;
	for (size_t k = 0; k < n_centres; k++) {
		acc += exp(r.logpi[k] - mx) / tot;
		r.cum[k] = acc;
		r.logpi[k] = r.logpi[k] - mx - log(tot);
	}
	r.s1 = malloc(R * sizeof *r.s1);
	r.s2 = malloc(R * sizeof *r.s2);
	r.s3 = malloc(R * sizeof *r.s3);
	r.s4 = malloc(R * sizeof *r.s4);
	r.nf = malloc(R * sizeof *r.nf);
	r.ne = malloc(R * sizeof *r.ne);
	r.bad = malloc(R * sizeof *r.bad);
	r.code = malloc(R * sizeof *r.code);
	r.lscode = malloc(R * sizeof *r.lscode);
	int rc = 0;
	if (!r.s1 || !r.s2 || !r.s3 || !r.s4 || !r.nf || !r.ne || !r.bad || !r.code || !r.lscode) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
		goto done;
	}
	out->n_centres = n_centres;
	out->failed_index = SIZE_MAX;
	if (check_target && !st->done && st->samples >= o->min_samples && st->failures >= o->min_failures) {
		/* a prefix run before (the auto pilot) may already meet the target */
		is_fill(st, out);
		if (is_target_met(out, o, n_centres)) {
			st->done = 1;
			out->stop = PRSM_RARE_STOP_CONVERGED;
		}
	}
	while (!st->done) {
		int h = rare_pool_halted(pool);
		if (h) {
			st->done = 1;
			out->stop = (prsm_rare_stop)h;
			break;
		}
		if (st->samples >= cap_samples) {
			if (check_target) {
				st->done = 1;
				out->stop = PRSM_RARE_STOP_MAX_SAMPLES;
			}
			break;
		}
		size_t nb = is_round_size(st, o, check_target, n_centres);
		size_t need = (cap_samples - st->samples + B - 1) / B;
		if (need < nb)
			nb = need;
		size_t afford = st->evaluations < budget ? (budget - st->evaluations) / B : 0;
		if (afford < nb)
			nb = afford;
		if (nb == 0) {
			st->done = 1;
			out->stop = PRSM_RARE_STOP_MAX_EVALUATIONS;
			break;
		}
		r.first_block = st->next_block;
		rare_pool_run(pool, nb, is_block_task, &r);
		st->next_block += nb;
		for (size_t t = 0; t < nb; t++)
			st->evaluations += r.ne[t];
		for (size_t t = 0; t < nb && !st->done; t++) {
			if (r.code[t] == RARE_HALTED) {
				st->done = 1;
				out->stop = (prsm_rare_stop)rare_pool_halted(pool);
				break;
			}
			if (r.code[t]) {
				char where[96];
				size_t idx = (r.first_block + t) * B + r.bad[t];
				out->failed_index = idx;
				snprintf(where, sizeof where, "%s sample %zu", n_centres ? "IS" : "MC", idx);
				rc = rare_eval_error(err, r.lscode[t], where);
				st->done = 1;
				goto done;
			}
			st->s1 += r.s1[t];
			st->s2 += r.s2[t];
			st->s3 += r.s3[t];
			st->s4 += r.s4[t];
			st->samples += B;
			st->failures += r.nf[t];
			if (check_target && st->samples >= o->min_samples && st->failures >= o->min_failures) {
				is_fill(st, out);
				if (is_target_met(out, o, n_centres)) {
					st->done = 1;
					out->stop = PRSM_RARE_STOP_CONVERGED;
				}
			}
		}
		is_fill(st, out);
		rare_progress(pool, st->evaluations, out->cov, 0);
	}
done:
	is_fill(st, out);
	out->converged = st->done && out->stop == PRSM_RARE_STOP_CONVERGED && rc == 0;
	if (st->done)
		rare_progress(pool, st->evaluations, out->cov, 1);
	free(r.s1);
	free(r.s2);
	free(r.s3);
	free(r.s4);
	free(r.nf);
	free(r.ne);
	free(r.bad);
	free(r.code);
	free(r.lscode);
	return rc;
}

int prsm_rare_is(prsm_rare_is_result *out, const prsm_rare_problem *p, const double *centres,
                 const double *weights, size_t n_centres, const prsm_rare_options *o, prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	memset(out, 0, sizeof *out);
	out->failed_index = SIZE_MAX;
	out->pf = out->se = out->cov = out->lower = out->upper = NAN;
	int rc = prsm_rare_options_check(o, p->d, err);
	if (rc)
		return rc;
	if (n_centres > MAX_CENTRES || (n_centres && !centres))
		return prsm_error_set(err, PRSM_EINVAL, NULL, "IS needs 0..%d centres, given as n x d values", MAX_CENTRES);
	for (size_t i = 0; i < n_centres * p->d; i++)
		if (!isfinite(centres[i]))
			return prsm_error_set(err, PRSM_EINVAL, NULL, "IS centre %zu is not finite", i / p->d);
	rare_space s;
	rare_pool pool;
	rc = rare_setup(&s, &pool, p, o, err);
	if (rc)
		return rc;
	rare_is_state st;
	memset(&st, 0, sizeof st);
	rc = rare_is_advance(&st, out, &pool, centres, weights, n_centres, o->max_samples, 1, o->max_evaluations, err);
	rare_pool_free(&pool);
	rare_space_free(&s);
	out->elapsed_s = prsm_clock_seconds() - t0;
	return rc;
}

/* ---- subset simulation ---------------------------------------------------------------------- */

typedef struct {
	const prsm_rare_options *o;
	size_t d, N, Nc;
	const size_t *len, *off;          /* Nc chains: length, first sample */
	int level;
	double b;                         /* the level's threshold (chains) */
	const double *seed_u, *seed_g;    /* Nc seeds */
	double *u, *g;                    /* the level's samples: N x d, N */
	size_t *ne, *nacc, *bad;          /* per chain */
	int *code, *lscode;
} ss_level;

static void ss_level0_task(rare_worker *w, size_t c, void *argp)
{
	ss_level *L = argp;
	const prsm_rare_options *o = L->o;
	size_t d = L->d;
	prsm_rng_set_stream(w->rng, o->seed, o->stream_offset + RARE_KEY_SUBSET + c);
	L->code[c] = 0;
	L->lscode[c] = 0;
	L->ne[c] = 0;
	L->nacc[c] = 0;
	L->bad[c] = SIZE_MAX;
	for (size_t l = 0; l < L->len[c]; l++) {
		size_t s = L->off[c] + l;
		double *u = L->u + s * d;
		for (size_t j = 0; j < d; j++)
			u[j] = normal_draw(w->rng);
		int rc = rare_eval(w, u, &L->g[s], &L->lscode[c]);
		if (rc) {
			L->code[c] = rc;
			L->bad[c] = l;
			if (rc != RARE_HALTED)
				L->ne[c]++;
			return;
		}
		L->ne[c]++;
	}
}

static void ss_chain_task(rare_worker *w, size_t c, void *argp)
{
	ss_level *L = argp;
	const prsm_rare_options *o = L->o;
	size_t d = L->d;
	prsm_rng_set_stream(w->rng, o->seed, o->stream_offset + RARE_KEY_SUBSET + ((uint64_t)L->level << 32) + c);
	L->code[c] = 0;
	L->lscode[c] = 0;
	L->ne[c] = 0;
	L->nacc[c] = 0;
	L->bad[c] = SIZE_MAX;
	size_t s0 = L->off[c];
	memcpy(L->u + s0 * d, L->seed_u + c * d, d * sizeof *L->u);
	L->g[s0] = L->seed_g[c];
	double *v = w->b;
	int uniform = o->subset_proposal == PRSM_RARE_PROPOSAL_UNIFORM;
	for (size_t l = 1; l < L->len[c]; l++) {
		const double *cur = L->u + (s0 + l - 1) * d;
		double gcur = L->g[s0 + l - 1];
		int moved = 0;
		for (size_t j = 0; j < d; j++) {
			double e = uniform ? 2.0 * prsm_rng_uniform_pos(w->rng) - 1.0 : normal_draw(w->rng);
			double xi = cur[j] + o->subset_width * e;
			double ratio = exp(-0.5 * (xi * xi - cur[j] * cur[j]));
			double a = prsm_rng_uniform_pos(w->rng);
			if (a < ratio) {
				v[j] = xi;
				moved = 1;
			} else {
				v[j] = cur[j];
			}
		}
		double *next = L->u + (s0 + l) * d;
		double gv = gcur;
		int take = 0;
		if (moved) {
			int rc = rare_eval(w, v, &gv, &L->lscode[c]);
			if (rc) {
				L->code[c] = rc;
				L->bad[c] = l;
				if (rc != RARE_HALTED)
					L->ne[c]++;
				return;
			}
			L->ne[c]++;
			take = gv <= L->b;
		}
		if (take) {
			memcpy(next, v, d * sizeof *next);
			L->g[s0 + l] = gv;
			L->nacc[c]++;
		} else {
			memcpy(next, cur, d * sizeof *next);
			L->g[s0 + l] = gcur;
		}
	}
}

typedef struct {
	double g;
	size_t i;
} ss_key;

static int ss_key_cmp(const void *pa, const void *pb)
{
	const ss_key *a = pa, *b = pb;
	if (a->g < b->g)
		return -1;
	if (a->g > b->g)
		return 1;
	return a->i < b->i ? -1 : (a->i > b->i ? 1 : 0);
}

/* gamma of a level's chains for the indicator g <= b (Au & Beck 2001, eq. 29). */
static double ss_gamma(const ss_level *L, double b)
{
	size_t N = L->N, Nc = L->Nc, maxlen = 0, hits = 0;
	for (size_t s = 0; s < N; s++)
		hits += L->g[s] <= b;
	for (size_t c = 0; c < Nc; c++)
		if (L->len[c] > maxlen)
			maxlen = L->len[c];
	double P = (double)hits / (double)N;
	double R0 = P * (1.0 - P);
	if (!(R0 > 0.0))
		return 0.0;
	double gamma = 0.0;
	for (size_t k = 1; k < maxlen; k++) {
		double sum = 0.0;
		size_t m = 0;
		for (size_t c = 0; c < Nc; c++) {
			const double *g = L->g + L->off[c];
			for (size_t l = 0; l + k < L->len[c]; l++) {
				sum += (g[l] <= b && g[l + k] <= b) ? 1.0 : 0.0;
				m++;
			}
		}
		if (m == 0)
			break;
		double Rk = sum / (double)m - P * P;
		gamma += 2.0 * (1.0 - (double)k * (double)Nc / (double)N) * Rk / R0;
	}
	return gamma;
}

/* After a level's batch: 0, a stop (> 0) or an error (< 0). */
static int ss_check(const ss_level *L, rare_pool *pool, prsm_rare_subset_result *out, prsm_error *err)
{
	for (size_t c = 0; c < L->Nc; c++)
		out->evaluations += L->ne[c];
	for (size_t c = 0; c < L->Nc; c++) {
		if (L->code[c] == RARE_HALTED)
			return rare_pool_halted(pool);
		if (L->code[c]) {
			char where[128];
			size_t s = L->off[c] + L->bad[c];
			out->failed_index = (size_t)L->level * L->N + s;
			snprintf(where, sizeof where, "subset level %d, chain %zu, sample %zu of the level", L->level, c, s);
			return rare_eval_error(err, L->lscode[c], where);
		}
	}
	return 0;
}

int prsm_rare_subset(prsm_rare_subset_result *out, const prsm_rare_problem *p, const prsm_rare_options *o,
                     prsm_error *err)
{
	double t0 = prsm_clock_seconds();
	memset(out, 0, sizeof *out);
	out->failed_index = SIZE_MAX;
	out->pf = out->cov = out->lower = out->upper = out->bound = NAN;
	int rc = prsm_rare_options_check(o, p->d, err);
	if (rc)
		return rc;
	size_t d = p->d, N = o->subset_samples;
	size_t Nc = (size_t)floor(o->subset_p0 * (double)N + 0.5);
	out->samples_per_level = N;
	out->chains = Nc;
	rare_space s;
	rare_pool pool;
	rc = rare_setup(&s, &pool, p, o, err);
	if (rc)
		return rc;
	ss_level L;
	memset(&L, 0, sizeof L);
	size_t *len = malloc(Nc * sizeof *len), *off = malloc(Nc * sizeof *off);
	double *u = malloc(N * d * sizeof *u), *g = malloc(N * sizeof *g);
	double *su = malloc(Nc * d * sizeof *su), *sg = malloc(Nc * sizeof *sg);
	ss_key *keys = malloc(N * sizeof *keys);
	L.ne = malloc(Nc * sizeof *L.ne);
	L.nacc = malloc(Nc * sizeof *L.nacc);
	L.bad = malloc(Nc * sizeof *L.bad);
	L.code = malloc(Nc * sizeof *L.code);
	L.lscode = malloc(Nc * sizeof *L.lscode);
	if (!len || !off || !u || !g || !su || !sg || !keys || !L.ne || !L.nacc || !L.bad || !L.code || !L.lscode) {
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory for %zu samples of %zu variables", N, d);
		goto done;
	}
	for (size_t c = 0, at = 0; c < Nc; c++) {
		len[c] = N / Nc + (c < N % Nc ? 1 : 0);
		off[c] = at;
		at += len[c];
	}
	L.o = o;
	L.d = d;
	L.N = N;
	L.Nc = Nc;
	L.len = len;
	L.off = off;
	L.u = u;
	L.g = g;
	L.seed_u = su;
	L.seed_g = sg;
	L.level = 0;
	L.b = INFINITY;

	int stop = 0;
	if (N > o->max_evaluations) {
		stop = PRSM_RARE_STOP_MAX_EVALUATIONS;
	} else {
		stop = rare_pool_halted(&pool);
		if (!stop) {
			rare_pool_run(&pool, Nc, ss_level0_task, &L);
			stop = ss_check(&L, &pool, out, err);
		}
	}
	double prod = 1.0, d2 = 0.0;
	for (int j = 0; stop == 0; j++) {
		out->levels = j + 1;
		for (size_t i = 0; i < N; i++) {
			keys[i].g = g[i];
			keys[i].i = i;
		}
		qsort(keys, N, sizeof *keys, ss_key_cmp);
		size_t fails = 0;
		for (size_t i = 0; i < N; i++)
			fails += g[i] <= 0.0;
		double b;
		int last = fails >= Nc;
		if (last) {
			b = 0.0;
		} else {
			b = 0.5 * (keys[Nc - 1].g + keys[Nc].g);
		}
		size_t hits = 0;
		for (size_t i = 0; i < N; i++)
			hits += g[i] <= b;
		double P = (double)hits / (double)N;
		double gam = j > 0 ? ss_gamma(&L, b) : 0.0;
		out->threshold[j] = b;
		out->p_cond[j] = P;
		out->gamma[j] = gam;
		out->delta[j] = sqrt((1.0 - P) / ((double)N * P) * (1.0 + gam));
		prod *= P;
		d2 += out->delta[j] * out->delta[j];
		out->bound = prod;
		if (last) {
			out->failures = fails;
			out->pf = prod;
			out->cov = sqrt(d2);
			out->lower = fmax(0.0, prod * (1.0 - RARE_Z95 * out->cov));
			out->upper = prod * (1.0 + RARE_Z95 * out->cov);
			out->converged = 1;
			out->stop = PRSM_RARE_STOP_CONVERGED;
			break;
		}
		if (j > 0 && !(b < out->threshold[j - 1])) {
			stop = PRSM_RARE_STOP_STAGNATION;
			break;
		}
		if (j + 1 >= o->subset_max_levels) {
			stop = PRSM_RARE_STOP_MAX_LEVELS;
			break;
		}
		if (out->evaluations + (N - Nc) > o->max_evaluations) {
			stop = PRSM_RARE_STOP_MAX_EVALUATIONS;
			break;
		}
		/* seeds: the Nc smallest, in order */
		for (size_t c = 0; c < Nc; c++) {
			memcpy(su + c * d, u + keys[c].i * d, d * sizeof *su);
			sg[c] = keys[c].g;
		}
		L.level = j + 1;
		L.b = b;
		stop = rare_pool_halted(&pool);
		if (stop)
			break;
		rare_pool_run(&pool, Nc, ss_chain_task, &L);
		stop = ss_check(&L, &pool, out, err);
		size_t acc = 0;
		for (size_t c = 0; c < Nc; c++)
			acc += L.nacc[c];
		out->acceptance[j + 1] = (double)acc / (double)(N - Nc);
		rare_progress(&pool, out->evaluations, sqrt(d2), 0);
	}
	if (stop < 0) {
		rc = stop;
	} else if (stop > 0) {
		out->stop = (prsm_rare_stop)stop;
		out->converged = 0;
	}
	rare_progress(&pool, out->evaluations, out->cov, 1);
done:
	free(len);
	free(off);
	free(u);
	free(g);
	free(su);
	free(sg);
	free(keys);
	free(L.ne);
	free(L.nacc);
	free(L.bad);
	free(L.code);
	free(L.lscode);
	rare_pool_free(&pool);
	rare_space_free(&s);
	out->elapsed_s = prsm_clock_seconds() - t0;
	return rc;
}
