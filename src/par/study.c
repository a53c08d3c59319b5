/*
 * study.c: a study over the ranks of an MPI job (see study.h and docs/mpi.md).
 *
 * Rank 0 drives; every phase starts with a command it broadcasts (the plain run, a round of
 * Saltelli replicates, the end), so the others never decide anything on their own and no rank
 * waits for a step another rank skips. In the plain run rank 0 hands out chunks of blocks point
 * to point and each rank sends back the chunk's rows; a round of replicates is gathered. A
 * buffer is a header (the return code and message) and the arrays as they are in memory (the
 * same machine type on every rank: one binary).
 */
#include "par/study.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "par/par.h"
#include "util/clock.h"

enum { CMD_PLAIN = 1, CMD_SOBOL = 2, CMD_END = 3, CMD_STUDY = 4, CMD_FINISH = 5 };

typedef struct {
	uint32_t op;
	int32_t code;          /* CMD_END: rank 0's return code */
	uint64_t round;
	double time_cap_s;     /* CMD_SOBOL: the replicates' time cap (0: none) */
} command;

/* The header of what a rank computed: a chunk of the plain run, or a Saltelli replicate. */
typedef struct {
	int32_t code;          /* 0, or the failure of this rank */
	int32_t sampler;       /* Saltelli: the sampler the replicate used */
	uint64_t n;            /* rows */
	int32_t stop;          /* Saltelli: the replicate's stop reason */
	int32_t pad;
	uint64_t first;        /* plain run: the chunk's first block */
	char message[256];     /* the failure */
	char warning[256];     /* Saltelli: the replicate's warning */
} share_head;

_Static_assert(sizeof(share_head) % 8 == 0, "the arrays after the header stay aligned");

typedef struct {
	const prsm_study *s;
	int size;
	/* the Sobol' phase: the current round's gathered shares */
	prsm_par_blob *blobs;
	uint64_t round;
	int have_round;
	int rank_failed;        /* a rank's share failed (not the study: out of memory, PRSM_PAR_FAULT) */
} leader;

/* Blocks in a chunk of the plain run: one per engine thread of a rank. */
static size_t blocks_per_rank(const prsm_study *s)
{
	return s->mc.threads > 1 ? (size_t)s->mc.threads : 1;
}

static size_t total_blocks(const prsm_study *s)
{
	return (s->mc.samples + s->mc.block_size - 1) / s->mc.block_size;
}

static void bcast_command(command *c)
{
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_par_bcast(c, sizeof *c, &err))
		prsm_par_abort(2, "%s", err.message);
}

static void gather(const void *mine, size_t len, prsm_par_blob *all)
{
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_par_gather(mine, len, all, &err))
		prsm_par_abort(2, "%s", err.message);
}

/* ---- the plain run ------------------------------------------------------------------------ */

/* The plain run's messages between rank 0 and a rank (point to point). */
enum { TAG_CHUNK = 11, TAG_ROWS = 12, TAG_PHASE_END = 13 };

typedef struct {
	uint64_t first, count;  /* blocks first .. first + count - 1 */
} chunk;

/* The split run of blocks [first, first + count), without stop rules (rank 0 applies them to
 * the merged prefix), caps or progress (rank 0's). */
static int chunk_run(prsm_mc_result *res, const prsm_study *s, size_t first, size_t count, prsm_error *err)
{
	prsm_mc_options o = s->mc;
	o.first_block = first;
	o.block_count = count;
	o.n_targets = 0;
	o.failure = PRSM_FAILURE_SKIP;
	o.max_failed_fraction = 1.0;
	o.time_cap_s = 0.0;
	o.cancel = NULL;
	o.progress = NULL;
	o.progress_ctx = NULL;
	if (prsm_par_fault())
		return prsm_error_set(err, PRSM_EIO, NULL, "injected failure (PRSM_PAR_FAULT)");
	return prsm_mc_run(res, &s->model, s->vars, s->d, s->corr, s->n_corr, &o, err);
}

/* A chunk's rows as a buffer: header, x (n x d), y (n x m), fail_code (n), status (n). */
static char *rows_pack(size_t *len, int code, const char *message, size_t first, const prsm_mc_result *res,
                       size_t d, size_t m)
{
	const size_t n = code ? 0 : res->n;
	*len = sizeof(share_head) + n * (d + m) * sizeof(double) + n * sizeof(int) + n;
	char *b = calloc(1, *len);
	if (!b)
		prsm_par_abort(2, "out of memory for %zu samples' rows", n);
	share_head h;
	memset(&h, 0, sizeof h);
	h.code = code;
	h.n = n;
	h.first = first;
	snprintf(h.message, sizeof h.message, "%s", message ? message : "");
	char *p = b;
	memcpy(p, &h, sizeof h);
	p += sizeof h;
	if (n) {
		memcpy(p, res->x, n * d * sizeof(double));
		p += n * d * sizeof(double);
		memcpy(p, res->y, n * m * sizeof(double));
		p += n * m * sizeof(double);
		memcpy(p, res->fail_code, n * sizeof(int));
		p += n * sizeof(int);
		memcpy(p, res->status, n);
	}
	return b;
}

/* The rows of a chunk, wherever they were computed, into their slots of the run. */
static void rows_place(prsm_mc_result *out, size_t first_row, size_t n, const double *x, const double *y,
                       const int *fail_code, const unsigned char *status)
{
	const size_t d = out->d, m = out->m;
	memcpy(out->x + first_row * d, x, n * d * sizeof *out->x);
	memcpy(out->y + first_row * m, y, n * m * sizeof *out->y);
	memcpy(out->fail_code + first_row, fail_code, n * sizeof *out->fail_code);
	memcpy(out->status + first_row, status, n);
}

/* Rows per chunk of blocks [first, first + count). */
static size_t chunk_rows(const prsm_study *s, size_t first, size_t count)
{
	const size_t B = s->mc.block_size, end = (first + count) * B;
	return (end > s->mc.samples ? s->mc.samples : end) - first * B;
}

/* A rank's rows (a TAG_ROWS message) into out: 0, or the rank's failure (err). */
static int rows_unpack(prsm_mc_result *out, unsigned char *block_done, const prsm_study *s, const char *buf,
                       size_t len, const chunk *c, int rank, int size, prsm_error *err)
{
	const size_t d = s->d, m = s->model.n_outputs;
	share_head h;
	if (len < sizeof h)
		prsm_par_abort(2, "rank %d sent %zu bytes for its rows, less than a header", rank, len);
	memcpy(&h, buf, sizeof h);
	h.message[sizeof h.message - 1] = '\0';
	if (h.code)
		return prsm_error_set(err, h.code, NULL, "rank %d of %d failed: %s", rank, size,
		                      h.message[0] ? h.message : prsm_error_name(h.code));
	const size_t n = (size_t)h.n, want = chunk_rows(s, (size_t)c->first, (size_t)c->count);
	if (h.first != c->first || n != want ||
	    len != sizeof h + n * (d + m) * sizeof(double) + n * sizeof(int) + n)
		prsm_par_abort(2, "rank %d sent %zu rows from block %llu for blocks %llu.. (%zu rows)", rank, n,
		               (unsigned long long)h.first, (unsigned long long)c->first, want);
	const char *p = buf + sizeof h;
	const double *x = (const double *)(const void *)p;
	const double *y = x + n * d;
	const int *fc = (const int *)(const void *)(y + n * m);
	const unsigned char *st = (const unsigned char *)(fc + n);
	rows_place(out, (size_t)c->first * s->mc.block_size, n, x, y, fc, st);
	memset(block_done + c->first, 1, (size_t)c->count);
	return 0;
}

/* A follower's plain run: the chunks rank 0 sends, until it says the run is over. */
static void follow_plain(const prsm_study *s)
{
	const size_t d = s->d, m = s->model.n_outputs;
	for (;;) {
		int from, tag;
		char *buf;
		size_t len;
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_par_recv(0, -1, &from, &tag, &buf, &len, NULL, &err))
			prsm_par_abort(2, "%s", err.message);
		if (tag == TAG_PHASE_END) {
			free(buf);
			return;
		}
		chunk c;
		if (tag != TAG_CHUNK || len != sizeof c)
			prsm_par_abort(2, "unexpected message (tag %d, %zu bytes) from rank 0", tag, len);
		memcpy(&c, buf, sizeof c);
		free(buf);
		prsm_mc_result res;
		memset(&res, 0, sizeof res);
		int code = chunk_run(&res, s, (size_t)c.first, (size_t)c.count, &err);
		size_t blen;
		char *b = rows_pack(&blen, code, err.message, (size_t)c.first, &res, d, m);
		prsm_mc_result_free(&res);
		if (prsm_par_send(0, TAG_ROWS, b, blen, &err))
			prsm_par_abort(2, "%s", err.message);
		free(b);
	}
}

/* Rank 0's own chunks, run on a thread of their own so that its main thread keeps handing out
 * chunks and merging (the MPI calls stay on the main thread). */
typedef struct {
	const prsm_study *s;
	chunk c;
	prsm_mc_result res;
	prsm_error err;
	int code;
	atomic_int done;
	pthread_t thread;
	int running;
} local_chunk;

static void *local_main(void *arg)
{
	local_chunk *lc = arg;
	lc->code = chunk_run(&lc->res, lc->s, (size_t)lc->c.first, (size_t)lc->c.count, &lc->err);
	atomic_store(&lc->done, 1);
	return NULL;
}

/* Rank 0's plain run: chunks of k blocks (k: engine threads per rank) handed to whichever rank
 * is free, rank 0's own thread included; the rows land in their blocks' slots; the completed
 * prefix is merged in block order by prsm_mc_prefix_add, and once it says stop (or the time cap
 * or a cancel does) no chunk is handed out, the ones running are waited for and dropped. */
static int lead_plain(prsm_mc_result *out, const prsm_study *s, void *ctx, prsm_error *err)
{
	leader *L = ctx;
	const prsm_mc_options *o = &s->mc;
	const double t0 = prsm_clock_seconds();
	const size_t d = s->d, m = s->model.n_outputs, B = o->block_size, total = total_blocks(s), k = blocks_per_rank(s);
	const int size = L->size;
	memset(out, 0, sizeof *out);
	int rc = prsm_mc_run_check(&s->model, s->vars, d, s->corr, s->n_corr, o, err);
	if (rc)
		return rc;
	command cmd = {CMD_PLAIN, 0, 0, 0.0};
	bcast_command(&cmd);
	const size_t n_rows = o->samples;
	out->d = d;
	out->m = m;
	out->first_sample = 0;
	out->sampler = o->sampler;
	out->status = malloc(n_rows);
	out->fail_code = calloc(n_rows, sizeof *out->fail_code);
	out->x = malloc(n_rows * d * sizeof *out->x);
	out->y = malloc(n_rows * m * sizeof *out->y);
	unsigned char *block_done = calloc(total, 1);
	chunk *busy = calloc((size_t)size, sizeof *busy); /* count 0: idle */
	local_chunk *lc = calloc(1, sizeof *lc);
	if (!out->status || !out->fail_code || !out->x || !out->y || !block_done || !busy || !lc)
		prsm_par_abort(2, "out of memory for %zu samples", n_rows);
	memset(out->status, PRSM_SAMPLE_UNRUN, n_rows);
	lc->s = s;

	prsm_mc_prefix pf;
	prsm_mc_prefix_init(&pf);
	prsm_stop_reason stop = PRSM_STOP_SAMPLE_CAP;
	int stopped = 0, in_flight = 0;
	size_t next = 0;
	double last_progress = -1.0;
	long nap_ns = 50000;
	for (;;) {
		/* hand out chunks to the free ranks, then to this rank's thread */
		for (int r = 1; r < size && !stopped && next < total; r++) {
			if (busy[r].count)
				continue;
			chunk c = {next, total - next < k ? total - next : k};
			if (prsm_par_send(r, TAG_CHUNK, &c, sizeof c, err))
				prsm_par_abort(2, "%s", err->message);
			busy[r] = c;
			in_flight++;
			next += (size_t)c.count;
		}
		if (!lc->running && !stopped && next < total) {
			lc->c = (chunk){next, total - next < k ? total - next : k};
			memset(&lc->res, 0, sizeof lc->res);
			lc->err = (prsm_error)PRSM_ERROR_INIT;
			atomic_init(&lc->done, 0);
			if (pthread_create(&lc->thread, NULL, local_main, lc))
				prsm_par_abort(2, "cannot start a thread");
			lc->running = 1;
			next += (size_t)lc->c.count;
		}
		if (!lc->running && in_flight == 0)
			break;
		/* collect what is done */
		int got = 0;
		if (lc->running && atomic_load(&lc->done)) {
			pthread_join(lc->thread, NULL);
			lc->running = 0;
			got = 1;
			if (lc->code && !rc) {
				L->rank_failed = 1;
				rc = prsm_error_set(err, lc->code, NULL, "rank 0 of %d failed: %s", size,
				                    lc->err.message[0] ? lc->err.message : prsm_error_name(lc->code));
				stopped = 1;
			} else if (!lc->code) {
				if (lc->res.n != chunk_rows(s, (size_t)lc->c.first, (size_t)lc->c.count))
					prsm_par_abort(2, "rank 0 computed %zu rows for blocks from %llu", lc->res.n,
					               (unsigned long long)lc->c.first);
				rows_place(out, (size_t)lc->c.first * B, lc->res.n, lc->res.x, lc->res.y, lc->res.fail_code,
				           lc->res.status);
				memset(block_done + lc->c.first, 1, (size_t)lc->c.count);
			}
			prsm_mc_result_free(&lc->res);
		}
		while (in_flight && prsm_par_probe()) {
			int from, tag;
			char *buf;
			size_t len;
			prsm_error rerr = PRSM_ERROR_INIT;
			if (prsm_par_recv(-1, TAG_ROWS, &from, &tag, &buf, &len, NULL, &rerr))
				prsm_par_abort(2, "%s", rerr.message);
			if (from <= 0 || from >= size || !busy[from].count)
				prsm_par_abort(2, "rows from rank %d, which had no chunk", from);
			int code = rows_unpack(out, block_done, s, buf, len, &busy[from], from, size, &rerr);
			free(buf);
			if (code && !rc) {
				L->rank_failed = 1;
				rc = code;
				*err = rerr;
				stopped = 1;
			}
			busy[from].count = 0;
			in_flight--;
			got = 1;
		}
		/* the completed prefix, in block order: the engine's stop rules */
		while (!stopped && pf.blocks < total && block_done[pf.blocks]) {
			const size_t b = pf.blocks, row0 = b * B, nb = chunk_rows(s, b, 1);
			int code = 0;
			if (prsm_mc_prefix_add(&pf, o, m, total, out->y + row0 * m, out->status + row0, out->fail_code + row0, nb,
			                       &stop, &code, err)) {
				rc = code;
				stopped = 1;
			}
		}
		if (!stopped && pf.blocks < total) {
			if (prsm_cancel_requested(o->cancel)) {
				stop = PRSM_STOP_CANCELLED;
				stopped = 1;
			} else if (o->time_cap_s > 0.0 && prsm_clock_seconds() - t0 > o->time_cap_s) {
				stop = PRSM_STOP_TIME_CAP;
				stopped = 1;
			}
		}
		double now = prsm_clock_seconds();
		if (o->progress && now - last_progress >= 0.2) {
			last_progress = now;
			prsm_mc_prefix_progress(&pf, o, o->samples);
		}
		if (got) {
			nap_ns = 50000;
		} else {
			struct timespec ts = {0, nap_ns};
			nanosleep(&ts, NULL);
			if (nap_ns < 2000000)
				nap_ns *= 2;
		}
	}
	for (int r = 1; r < size; r++) {
		prsm_error serr = PRSM_ERROR_INIT;
		if (prsm_par_send(r, TAG_PHASE_END, NULL, 0, &serr))
			prsm_par_abort(2, "%s", serr.message);
	}
	if (!rc) {
		prsm_mc_prefix_progress(&pf, o, o->samples);
		prsm_mc_prefix_finish(out, &pf, o, stop);
	}
	free(block_done);
	free(busy);
	free(lc);
	out->elapsed_s = prsm_clock_seconds() - t0;
	if (rc)
		prsm_mc_result_free(out);
	return rc;
}

/* ---- the Sobol' phase ---------------------------------------------------------------------- */

/* A replicate as a buffer: header, ys (m x K x n), status (n). */
static char *replicate_pack(size_t *len, int code, const char *message, const prsm_mc_result *sr, size_t m,
                            size_t K)
{
	const size_t n = code ? 0 : sr->n;
	*len = sizeof(share_head) + m * K * n * sizeof(double) + n;
	char *b = calloc(1, *len);
	if (!b)
		prsm_par_abort(2, "out of memory for a replicate of %zu rows", n);
	share_head h;
	memset(&h, 0, sizeof h);
	h.code = code;
	h.n = n;
	h.sampler = code ? 0 : (int32_t)sr->sampler;
	h.stop = code ? 0 : (int32_t)sr->stop;
	snprintf(h.message, sizeof h.message, "%s", message ? message : "");
	if (!code)
		snprintf(h.warning, sizeof h.warning, "%s", sr->warning);
	memcpy(b, &h, sizeof h);
	if (n) {
		memcpy(b + sizeof h, sr->ys, m * K * n * sizeof(double));
		memcpy(b + sizeof h + m * K * n * sizeof(double), sr->status, n);
	}
	return b;
}

/* Replicate q (of rank `rank`'s buffer) into *sr as prsm_mc_run_saltelli would have returned it;
 * or its failure. */
static int replicate_unpack(prsm_mc_result *sr, const prsm_par_blob *b, const prsm_study *s, int rank, int size,
                            prsm_error *err)
{
	const size_t m = s->model.n_outputs, K = s->n_groups + 2;
	share_head h;
	memset(sr, 0, sizeof *sr);
	if (b->len < sizeof h)
		prsm_par_abort(2, "rank %d sent %zu bytes for a replicate, less than a header", rank, b->len);
	memcpy(&h, b->data, sizeof h);
	h.message[sizeof h.message - 1] = '\0';
	h.warning[sizeof h.warning - 1] = '\0';
	if (h.code)
		return prsm_error_set(err, h.code, NULL, "rank %d of %d failed: %s", rank, size,
		                      h.message[0] ? h.message : prsm_error_name(h.code));
	const size_t n = (size_t)h.n;
	if (b->len != sizeof h + m * K * n * sizeof(double) + n)
		prsm_par_abort(2, "rank %d sent a replicate of %zu bytes for %zu rows", rank, b->len, n);
	sr->n = n;
	sr->m = m;
	sr->d = s->d;
	sr->n_groups = s->n_groups;
	sr->sampler = (prsm_sampler_kind)h.sampler;
	sr->stop = (prsm_stop_reason)h.stop;
	snprintf(sr->warning, sizeof sr->warning, "%s", h.warning);
	sr->ys = malloc((m * K * n > 0 ? m * K * n : 1) * sizeof *sr->ys);
	sr->status = malloc(n ? n : 1);
	sr->fail_code = calloc(n ? n : 1, sizeof *sr->fail_code);
	if (!sr->ys || !sr->status || !sr->fail_code) {
		prsm_mc_result_free(sr);
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	}
	memcpy(sr->ys, b->data + sizeof h, m * K * n * sizeof *sr->ys);
	memcpy(sr->status, b->data + sizeof h + m * K * n * sizeof(double), n);
	return 0;
}

static int replicate_run(prsm_mc_result *sr, const prsm_study *s, const prsm_mc_options *mo, prsm_error *err)
{
	if (prsm_par_fault())
		return prsm_error_set(err, PRSM_EIO, NULL, "injected failure (PRSM_PAR_FAULT)");
	return prsm_mc_run_saltelli(sr, &s->model, s->vars, s->d, s->n_groups, s->corr, s->n_corr, mo, err);
}

/* A follower's replicate of round j: q = j size + rank, when there is one. */
static void follow_sobol(const prsm_study *s, uint64_t j, double time_cap_s)
{
	const size_t q = (size_t)j * (size_t)prsm_par_size() + (size_t)prsm_par_rank();
	const size_t m = s->model.n_outputs, K = s->n_groups + 2;
	prsm_mc_result sr;
	memset(&sr, 0, sizeof sr);
	prsm_error err = PRSM_ERROR_INIT;
	int code = 0;
	if (q < prsm_study_sobol_replicates(s)) {
		prsm_mc_options mo;
		prsm_study_sobol_options(&mo, s, q);
		mo.time_cap_s = time_cap_s;
		mo.progress = NULL;
		mo.progress_ctx = NULL;
		code = replicate_run(&sr, s, &mo, &err);
	}
	size_t len;
	char *b = replicate_pack(&len, code, err.message, &sr, m, K);
	prsm_mc_result_free(&sr);
	gather(b, len, NULL);
	free(b);
}

/* Rank 0's replicate q: at the first of a round, the round (its own replicate computed here,
 * the others' gathered); then each from the round's buffers. */
static int lead_replicate(prsm_mc_result *sr, const prsm_study *s, size_t q, const prsm_mc_options *mo, void *ctx,
                          prsm_error *err)
{
	leader *L = ctx;
	const uint64_t j = (uint64_t)(q / (size_t)L->size);
	const int r = (int)(q % (size_t)L->size);
	if (r == 0) {
		prsm_par_blobs_free(L->blobs, L->size);
		L->have_round = 0;
		command c = {CMD_SOBOL, 0, j, mo->time_cap_s};
		bcast_command(&c);
		int rc = replicate_run(sr, s, mo, err);
		gather(NULL, 0, L->blobs);
		L->round = j;
		L->have_round = 1;
		return rc;
	}
	if (!L->have_round || L->round != j)
		prsm_par_abort(2, "replicate %zu asked for out of order", q);
	int rc = replicate_unpack(sr, &L->blobs[r], s, r, L->size, err);
	if (rc)
		L->rank_failed = 1;
	return rc;
}

/* ---- the whole study ---------------------------------------------------------------------- */

/* A follower's part of one study, until rank 0 says it is over: rank 0's return code. */
static int follow(const prsm_study *s)
{
	for (;;) {
		command c;
		memset(&c, 0, sizeof c);
		bcast_command(&c);
		if (c.op == CMD_PLAIN)
			follow_plain(s);
		else if (c.op == CMD_SOBOL)
			follow_sobol(s, c.round, c.time_cap_s);
		else if (c.op == CMD_END)
			return c.code;
		else
			prsm_par_abort(2, "unknown command %u from rank 0 in a study", (unsigned)c.op);
	}
}

/* Rank 0's part of one study: prsm_study_run_with over the ranks, then the end. *rank_failed
 * (may be NULL): the error is a rank's failure, not the study's. */
static int lead(prsm_study_result *r, const prsm_study *s, int *rank_failed, prsm_error *err)
{
	leader L;
	memset(&L, 0, sizeof L);
	L.s = s;
	L.size = prsm_par_size();
	L.blobs = calloc((size_t)L.size, sizeof *L.blobs);
	if (!L.blobs)
		prsm_par_abort(2, "out of memory");
	prsm_study_runner runner = {lead_plain, lead_replicate, &L};
	int rc = prsm_study_run_with(r, s, &runner, err);
	prsm_par_blobs_free(L.blobs, L.size);
	free(L.blobs);
	command end = {CMD_END, rc, 0, 0.0};
	bcast_command(&end);
	if (rank_failed)
		*rank_failed = L.rank_failed;
	return rc;
}

int prsm_par_study_run(prsm_study_result *r, const prsm_study *s, prsm_error *err)
{
	return prsm_par_rank() != 0 ? follow(s) : lead(r, s, NULL, err);
}

/* ---- whole studies on demand (a study service) -------------------------------------------- */

/* prsm_study_service.run on rank 0: the study's document and settings to every rank, then the
 * study over the ranks. */
static int service_run(prsm_study_result *r, const prsm_study *s, const char *source, size_t source_len, void *ctx,
                       prsm_error *err)
{
	(void)ctx;
	/* the broadcasts' buffers are the callers' on every rank: copies of rank 0's */
	char *text = malloc(source_len + 1);
	prsm_study *settings = malloc(sizeof *settings);
	if (!text || !settings)
		prsm_par_abort(2, "out of memory for a study's document");
	memcpy(text, source, source_len);
	text[source_len] = '\0';
	memcpy(settings, s, sizeof *settings);
	command c = {CMD_STUDY, 0, (uint64_t)source_len, 0.0};
	bcast_command(&c);
	size_t len = source_len;
	prsm_error berr = PRSM_ERROR_INIT;
	if (prsm_par_bcast_blob(&text, &len, &berr) || prsm_par_bcast(settings, sizeof *settings, &berr))
		prsm_par_abort(2, "%s", berr.message);
	free(text);
	free(settings);
	/* a rank's failure has no one-process counterpart the caller could report (a robust
	 * constraint would count it against the candidate): it ends the run */
	int rank_failed = 0;
	int rc = lead(r, s, &rank_failed, err);
	if (rc && rank_failed)
		prsm_par_abort(2, "the run ends: %s", err->message);
	return rc;
}

static const prsm_study_service par_service = {service_run, NULL};

const prsm_study_service *prsm_par_study_service(void)
{
	return &par_service;
}

void prsm_par_study_service_finish(int code)
{
	command c = {CMD_FINISH, code, 0, 0.0};
	bcast_command(&c);
}

int prsm_par_study_serve(prsm_par_study_load_fn load, prsm_par_study_release_fn release, void *ctx)
{
	prsm_study *lead_s = malloc(sizeof *lead_s);
	if (!lead_s)
		prsm_par_abort(2, "out of memory for a study");
	for (;;) {
		command c;
		memset(&c, 0, sizeof c);
		bcast_command(&c);
		if (c.op == CMD_FINISH) {
			free(lead_s);
			return c.code;
		}
		if (c.op != CMD_STUDY)
			prsm_par_abort(2, "unknown command %u from rank 0 between studies", (unsigned)c.op);
		char *text = NULL;
		size_t len = 0;
		prsm_error err = PRSM_ERROR_INIT;
		if (prsm_par_bcast_blob(&text, &len, &err) || prsm_par_bcast(lead_s, sizeof *lead_s, &err))
			prsm_par_abort(2, "%s", err.message);
		if (len != (size_t)c.round)
			prsm_par_abort(2, "a study document of %zu bytes where rank 0 announced %llu", len,
			               (unsigned long long)c.round);
		prsm_study *s = NULL;
		void *handle = NULL;
		if (load(ctx, &s, &handle, text, len, &err))
			prsm_par_abort(2, "cannot load the study rank 0 runs: %s", err.message);
		free(text);
		if (prsm_study_adopt(s, lead_s, &err))
			prsm_par_abort(2, "the study rank 0 runs: %s", err.message);
		follow(s);
		release(ctx, handle);
	}
}
