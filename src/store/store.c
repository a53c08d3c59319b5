/*
 * store.c: the SQLite side of the service (see store.h).
 *
 * Connections: a fixed pool; a call takes the first free one (trylock), or waits for one
 * picked round-robin. Each connection keeps its prepared statements for its lifetime.
 * Writers use BEGIN IMMEDIATE, so two submissions of the same request serialise on the
 * database lock and the second sees the first's row (one job per key in flight); the busy
 * timeout makes a writer wait instead of failing. synchronous=NORMAL in WAL mode keeps every
 * committed transaction across a process crash (kill -9); only a power loss may lose the last
 * ones.
 */
#include "store/store.h"

#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

#include <sqlite3.h>

/* Migrations: migrations[v] takes user_version v to v + 1. */
static const char *const migrations[PRSM_STORE_SCHEMA_VERSION] = {
	"CREATE TABLE jobs ("
	"  seq INTEGER PRIMARY KEY AUTOINCREMENT,"
	"  id TEXT NOT NULL UNIQUE,"
	"  kind TEXT NOT NULL,"
	"  cache_key TEXT NOT NULL,"
	"  state INTEGER NOT NULL,"          /* prsm_job_state */
	"  created_s REAL NOT NULL,"         /* Unix time, s */
	"  started_s REAL NOT NULL DEFAULT 0,"
	"  finished_s REAL NOT NULL DEFAULT 0,"
	"  attempts INTEGER NOT NULL DEFAULT 0,"
	"  samples_done INTEGER NOT NULL DEFAULT 0,"
	"  samples_planned INTEGER NOT NULL DEFAULT 0,"
	"  request TEXT NOT NULL,"
	"  result TEXT,"
	"  problem TEXT);"
	"CREATE INDEX jobs_by_key ON jobs(kind, cache_key, state);"
	"CREATE INDEX jobs_by_state ON jobs(state, seq);"
	"CREATE INDEX jobs_by_kind ON jobs(kind, seq);"
	"CREATE TABLE job_samples ("
	"  id TEXT PRIMARY KEY REFERENCES jobs(id),"
	"  csv BLOB NOT NULL);",
};

#define JOB_COLUMNS "seq, id, kind, cache_key, state, created_s, started_s, finished_s, attempts, samples_done, samples_planned"

enum {
	ST_BEGIN,
	ST_COMMIT,
	ST_ROLLBACK,
	ST_FIND_KEY,
	ST_COUNT_STATE,
	ST_INSERT,
	ST_GET,
	ST_GET_REQUEST,
	ST_GET_RESULT,
	ST_GET_CSV,
	ST_OLDEST_QUEUED,
	ST_START,
	ST_FINISH,
	ST_INSERT_CSV,
	ST_REQUEUE,
	ST_CANCEL,
	ST_RECOVER,
	ST_LIST,
	ST_COUNT
};

static const char *const sql_text[ST_COUNT] = {
	[ST_BEGIN] = "BEGIN IMMEDIATE",
	[ST_COMMIT] = "COMMIT",
	[ST_ROLLBACK] = "ROLLBACK",
	[ST_FIND_KEY] = "SELECT " JOB_COLUMNS " FROM jobs WHERE kind = ?1 AND cache_key = ?2 AND state IN (0, 1, 2)"
	                " ORDER BY state DESC, seq DESC LIMIT 1",
	[ST_COUNT_STATE] = "SELECT count(*) FROM jobs WHERE state = ?1",
	[ST_INSERT] = "INSERT INTO jobs (id, kind, cache_key, state, created_s, request) VALUES (?1, ?2, ?3, 0, ?4, ?5)",
	[ST_GET] = "SELECT " JOB_COLUMNS " FROM jobs WHERE id = ?1",
	[ST_GET_REQUEST] = "SELECT request FROM jobs WHERE id = ?1",
	[ST_GET_RESULT] = "SELECT result, problem FROM jobs WHERE id = ?1",
	[ST_GET_CSV] = "SELECT csv FROM job_samples WHERE id = ?1",
	[ST_OLDEST_QUEUED] = "SELECT " JOB_COLUMNS " FROM jobs WHERE state = 0 ORDER BY seq LIMIT 1",
	[ST_START] = "UPDATE jobs SET state = 1, attempts = attempts + 1, started_s = ?2 WHERE id = ?1",
	[ST_FINISH] = "UPDATE jobs SET state = ?2, finished_s = ?3, result = ?4, problem = ?5, samples_done = ?6,"
	              " samples_planned = ?7 WHERE id = ?1 AND (state = 1 OR (state = 4 AND ?2 = 4 AND result IS NULL))",
	[ST_INSERT_CSV] = "INSERT OR REPLACE INTO job_samples (id, csv) VALUES (?1, ?2)",
	[ST_REQUEUE] = "UPDATE jobs SET state = 0 WHERE id = ?1 AND state = 1",
	[ST_CANCEL] = "UPDATE jobs SET state = 4, finished_s = ?2 WHERE id = ?1 AND state IN (0, 1)",
	[ST_RECOVER] = "UPDATE jobs SET state = 0 WHERE state = 1",
	[ST_LIST] = "SELECT " JOB_COLUMNS " FROM jobs WHERE kind = ?1 AND seq < ?2 ORDER BY seq DESC LIMIT ?3",
};

typedef struct {
	pthread_mutex_t mu;
	sqlite3 *db;
	sqlite3_stmt *st[ST_COUNT]; /* prepared on first use, owned by the connection */
} conn;

struct prsm_store {
	int n;
	unsigned next; /* round-robin start when every connection is busy */
	pthread_mutex_t next_mu;
	conn c[PRSM_STORE_MAX_CONNS];
};

const char *prsm_job_state_name(prsm_job_state s)
{
	switch (s) {
	case PRSM_JOB_QUEUED: return "queued";
	case PRSM_JOB_RUNNING: return "running";
	case PRSM_JOB_DONE: return "done";
	case PRSM_JOB_FAILED: return "failed";
	case PRSM_JOB_CANCELLED: return "cancelled";
	}
	return "unknown";
}

void prsm_store_job_clear(prsm_store_job *j)
{
	free(j->request);
	free(j->result);
	free(j->problem);
	j->request = j->result = j->problem = NULL;
	j->result_len = 0;
}

static double now_unix_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int db_error(prsm_error *err, sqlite3 *db, const char *what)
{
	return prsm_error_set(err, PRSM_EIO, NULL, "database: %s: %s", what, db ? sqlite3_errmsg(db) : "no connection");
}

static conn *acquire(prsm_store *s)
{
	for (int i = 0; i < s->n; i++)
		if (pthread_mutex_trylock(&s->c[i].mu) == 0)
			return &s->c[i];
	pthread_mutex_lock(&s->next_mu);
	unsigned k = s->next++ % (unsigned)s->n;
	pthread_mutex_unlock(&s->next_mu);
	pthread_mutex_lock(&s->c[k].mu);
	return &s->c[k];
}

static void release(conn *c)
{
	pthread_mutex_unlock(&c->mu);
}

/* The cached statement, reset and unbound; NULL when it cannot be prepared. */
static sqlite3_stmt *stmt(conn *c, int which)
{
	if (!c->st[which]) {
		if (sqlite3_prepare_v3(c->db, sql_text[which], -1, SQLITE_PREPARE_PERSISTENT, &c->st[which], NULL) != SQLITE_OK)
			return NULL;
	} else {
		sqlite3_reset(c->st[which]);
		sqlite3_clear_bindings(c->st[which]);
	}
	return c->st[which];
}

static int exec_simple(conn *c, int which)
{
	sqlite3_stmt *q = stmt(c, which);
	if (!q)
		return SQLITE_ERROR;
	int rc = sqlite3_step(q);
	sqlite3_reset(q);
	return rc == SQLITE_DONE ? SQLITE_OK : rc;
}

static void copy_text(char *dst, size_t size, const unsigned char *src)
{
	snprintf(dst, size, "%s", src ? (const char *)src : "");
}

static void read_row(prsm_store_job *j, sqlite3_stmt *q)
{
	memset(j, 0, sizeof *j);
	j->seq = sqlite3_column_int64(q, 0);
	copy_text(j->id, sizeof j->id, sqlite3_column_text(q, 1));
	copy_text(j->kind, sizeof j->kind, sqlite3_column_text(q, 2));
	copy_text(j->key, sizeof j->key, sqlite3_column_text(q, 3));
	j->state = (prsm_job_state)sqlite3_column_int(q, 4);
	j->created_s = sqlite3_column_double(q, 5);
	j->started_s = sqlite3_column_double(q, 6);
	j->finished_s = sqlite3_column_double(q, 7);
	j->attempts = sqlite3_column_int(q, 8);
	j->samples_done = sqlite3_column_int64(q, 9);
	j->samples_planned = sqlite3_column_int64(q, 10);
}

/* A malloc'd copy of a text column (NULL when NULL or out of memory). */
static char *dup_column(sqlite3_stmt *q, int col, size_t *len)
{
	if (sqlite3_column_type(q, col) == SQLITE_NULL)
		return NULL;
	const void *p = sqlite3_column_blob(q, col);
	int n = sqlite3_column_bytes(q, col);
	char *out = malloc((size_t)n + 1); /* handed to the caller */
	if (!out)
		return NULL;
	if (n)
		memcpy(out, p, (size_t)n);
	out[n] = '\0';
	if (len)
		*len = (size_t)n;
	return out;
}

static int configure(sqlite3 *db, prsm_error *err)
{
	sqlite3_busy_timeout(db, 10000);
	char *msg = NULL;
	if (sqlite3_exec(db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON;",
	                 NULL, NULL, &msg) != SQLITE_OK) {
		int rc = prsm_error_set(err, PRSM_EIO, NULL, "database: cannot set WAL mode: %s", msg ? msg : "?");
		sqlite3_free(msg);
		return rc;
	}
	return 0;
}

static int user_version(sqlite3 *db)
{
	sqlite3_stmt *q;
	int v = -1;
	if (sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &q, NULL) == SQLITE_OK) {
		if (sqlite3_step(q) == SQLITE_ROW)
			v = sqlite3_column_int(q, 0);
		sqlite3_finalize(q);
	}
	return v;
}

static int migrate(sqlite3 *db, const char *path, prsm_error *err)
{
	for (;;) {
		if (sqlite3_exec(db, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK)
			return db_error(err, db, "begin migration");
		int v = user_version(db);
		if (v < 0 || v > PRSM_STORE_SCHEMA_VERSION) {
			sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
			return prsm_error_set(err, PRSM_EIO, NULL,
			                      "database %s has schema version %d; this prsm knows up to %d", path, v,
			                      PRSM_STORE_SCHEMA_VERSION);
		}
		if (v == PRSM_STORE_SCHEMA_VERSION) {
			sqlite3_exec(db, "COMMIT", NULL, NULL, NULL);
			return 0;
		}
		char *msg = NULL;
		char pragma[48];
		snprintf(pragma, sizeof pragma, "PRAGMA user_version = %d", v + 1);
		if (sqlite3_exec(db, migrations[v], NULL, NULL, &msg) != SQLITE_OK ||
		    sqlite3_exec(db, pragma, NULL, NULL, &msg) != SQLITE_OK ||
		    sqlite3_exec(db, "COMMIT", NULL, NULL, &msg) != SQLITE_OK) {
			int rc = prsm_error_set(err, PRSM_EIO, NULL, "database %s: migration %d -> %d failed: %s", path, v,
			                        v + 1, msg ? msg : "?");
			sqlite3_free(msg);
			sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
			return rc;
		}
	}
}

int prsm_store_open(prsm_store **out, const char *path, int n_conns, prsm_error *err)
{
	*out = NULL;
	if (n_conns < 1 || n_conns > PRSM_STORE_MAX_CONNS)
		return prsm_error_set(err, PRSM_EINVAL, NULL, "store: %d connections (1..%d)", n_conns, PRSM_STORE_MAX_CONNS);
	prsm_store *s = calloc(1, sizeof *s); /* handed to the caller */
	if (!s)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	pthread_mutex_init(&s->next_mu, NULL);
	int rc = 0;
	for (int i = 0; i < n_conns; i++) {
		pthread_mutex_init(&s->c[i].mu, NULL);
		s->n = i + 1;
		if (sqlite3_open_v2(path, &s->c[i].db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
		                    NULL) != SQLITE_OK) {
			rc = prsm_error_set(err, PRSM_EIO, NULL, "cannot open database %s: %s", path,
			                    s->c[i].db ? sqlite3_errmsg(s->c[i].db) : "out of memory");
			goto fail;
		}
		rc = configure(s->c[i].db, err);
		if (rc)
			goto fail;
		if (i == 0) {
			rc = migrate(s->c[0].db, path, err);
			if (rc)
				goto fail;
		}
	}
	*out = s;
	return 0;
fail:
	prsm_store_close(s);
	return rc;
}

void prsm_store_close(prsm_store *s)
{
	if (!s)
		return;
	for (int i = 0; i < s->n; i++) {
		for (int k = 0; k < ST_COUNT; k++)
			sqlite3_finalize(s->c[i].st[k]);
		sqlite3_close(s->c[i].db);
		pthread_mutex_destroy(&s->c[i].mu);
	}
	pthread_mutex_destroy(&s->next_mu);
	free(s);
}

int prsm_store_schema_version(prsm_store *s)
{
	conn *c = acquire(s);
	int v = user_version(c->db);
	release(c);
	return v;
}

static int begin(conn *c, prsm_error *err)
{
	return exec_simple(c, ST_BEGIN) == SQLITE_OK ? 0 : db_error(err, c->db, "begin");
}

static int commit(conn *c, prsm_error *err)
{
	if (exec_simple(c, ST_COMMIT) == SQLITE_OK)
		return 0;
	int rc = db_error(err, c->db, "commit");
	exec_simple(c, ST_ROLLBACK);
	return rc;
}

static void rollback(conn *c)
{
	if (!sqlite3_get_autocommit(c->db))
		exec_simple(c, ST_ROLLBACK);
}

static int new_id(char id[PRSM_STORE_ID_MAX])
{
	unsigned char b[16];
	size_t got = 0;
	while (got < sizeof b) {
		ssize_t r = getrandom(b + got, sizeof b - got, 0);
		if (r <= 0)
			return -1;
		got += (size_t)r;
	}
	static const char hex[] = "0123456789abcdef";
	for (int i = 0; i < 16; i++) {
		id[2 * i] = hex[b[i] >> 4];
		id[2 * i + 1] = hex[b[i] & 15];
	}
	id[32] = '\0';
	return 0;
}

static int count_state(conn *c, long long *n, prsm_job_state state)
{
	sqlite3_stmt *q = stmt(c, ST_COUNT_STATE);
	if (!q)
		return -1;
	sqlite3_bind_int(q, 1, (int)state);
	int rc = sqlite3_step(q);
	*n = rc == SQLITE_ROW ? sqlite3_column_int64(q, 0) : 0;
	sqlite3_reset(q);
	return rc == SQLITE_ROW ? 0 : -1;
}

int prsm_store_submit(prsm_store *s, prsm_store_job *out, prsm_submit_outcome *outcome,
                      const char *kind, const char *key, const char *request, size_t max_queued,
                      prsm_error *err)
{
	memset(out, 0, sizeof *out);
	conn *c = acquire(s);
	int rc = begin(c, err);
	if (rc)
		goto done;
	sqlite3_stmt *q = stmt(c, ST_FIND_KEY);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
		goto done;
	}
	sqlite3_bind_text(q, 1, kind, -1, SQLITE_STATIC);
	sqlite3_bind_text(q, 2, key, -1, SQLITE_STATIC);
	int step = sqlite3_step(q);
	if (step == SQLITE_ROW) {
		read_row(out, q);
		sqlite3_reset(q);
		*outcome = out->state == PRSM_JOB_DONE ? PRSM_SUBMIT_CACHED : PRSM_SUBMIT_SHARED;
		rc = commit(c, err);
		goto done;
	}
	sqlite3_reset(q);
	if (step != SQLITE_DONE) {
		rc = db_error(err, c->db, "find by key");
		goto done;
	}
	long long queued;
	if (count_state(c, &queued, PRSM_JOB_QUEUED)) {
		rc = db_error(err, c->db, "count");
		goto done;
	}
	if ((size_t)queued >= max_queued) {
		*outcome = PRSM_SUBMIT_FULL;
		rc = commit(c, err);
		goto done;
	}
	char id[PRSM_STORE_ID_MAX];
	if (new_id(id)) {
		rc = prsm_error_set(err, PRSM_EIO, NULL, "no random bytes for a job id");
		goto done;
	}
	double now = now_unix_s();
	q = stmt(c, ST_INSERT);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
		goto done;
	}
	sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
	sqlite3_bind_text(q, 2, kind, -1, SQLITE_STATIC);
	sqlite3_bind_text(q, 3, key, -1, SQLITE_STATIC);
	sqlite3_bind_double(q, 4, now);
	sqlite3_bind_text(q, 5, request, -1, SQLITE_STATIC);
	step = sqlite3_step(q);
	sqlite3_reset(q);
	if (step != SQLITE_DONE) {
		rc = db_error(err, c->db, "insert job");
		goto done;
	}
	out->seq = sqlite3_last_insert_rowid(c->db);
	snprintf(out->id, sizeof out->id, "%s", id);
	snprintf(out->kind, sizeof out->kind, "%s", kind);
	snprintf(out->key, sizeof out->key, "%s", key);
	out->state = PRSM_JOB_QUEUED;
	out->created_s = now;
	*outcome = PRSM_SUBMIT_CREATED;
	rc = commit(c, err);
done:
	if (rc)
		rollback(c);
	release(c);
	return rc;
}

/* Load one job's row (and text columns by flags) on a held connection. */
static int get_locked(conn *c, prsm_store_job *out, const char *id, int flags, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	sqlite3_stmt *q = stmt(c, ST_GET);
	if (!q)
		return db_error(err, c->db, "prepare");
	sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
	int step = sqlite3_step(q);
	if (step == SQLITE_DONE) {
		sqlite3_reset(q);
		return prsm_error_set(err, PRSM_ENOTFOUND, NULL, "no job %.40s", id);
	}
	if (step != SQLITE_ROW) {
		sqlite3_reset(q);
		return db_error(err, c->db, "get job");
	}
	read_row(out, q);
	sqlite3_reset(q);
	int rc = 0;
	if (flags & PRSM_STORE_WITH_REQUEST) {
		q = stmt(c, ST_GET_REQUEST);
		if (!q)
			return db_error(err, c->db, "prepare");
		sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
		if (sqlite3_step(q) == SQLITE_ROW)
			out->request = dup_column(q, 0, NULL);
		if (!out->request)
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory reading a request");
		sqlite3_reset(q);
	}
	if (!rc && (flags & PRSM_STORE_WITH_RESULT)) {
		q = stmt(c, ST_GET_RESULT);
		if (!q)
			return db_error(err, c->db, "prepare");
		sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
		if (sqlite3_step(q) == SQLITE_ROW) {
			out->result = dup_column(q, 0, &out->result_len);
			out->problem = dup_column(q, 1, NULL);
		}
		sqlite3_reset(q);
	}
	if (rc)
		prsm_store_job_clear(out);
	return rc;
}

int prsm_store_get(prsm_store *s, prsm_store_job *out, const char *id, int flags, prsm_error *err)
{
	conn *c = acquire(s);
	int rc = get_locked(c, out, id, flags, err);
	release(c);
	return rc;
}

int prsm_store_get_csv(prsm_store *s, char **csv, size_t *len, const char *id, prsm_error *err)
{
	*csv = NULL;
	*len = 0;
	conn *c = acquire(s);
	int rc = 0;
	sqlite3_stmt *q = stmt(c, ST_GET_CSV);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
	} else {
		sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
		int step = sqlite3_step(q);
		if (step == SQLITE_ROW) {
			*csv = dup_column(q, 0, len);
			if (!*csv)
				rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory reading samples");
		} else if (step == SQLITE_DONE) {
			rc = prsm_error_set(err, PRSM_ENOTFOUND, NULL, "no samples stored for job %.40s", id);
		} else {
			rc = db_error(err, c->db, "get samples");
		}
		sqlite3_reset(q);
	}
	release(c);
	return rc;
}

int prsm_store_claim(prsm_store *s, prsm_store_job *out, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	conn *c = acquire(s);
	int rc = begin(c, err);
	if (rc)
		goto done;
	sqlite3_stmt *q = stmt(c, ST_OLDEST_QUEUED);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
		goto done;
	}
	int step = sqlite3_step(q);
	if (step != SQLITE_ROW) {
		sqlite3_reset(q);
		rc = step == SQLITE_DONE ? prsm_error_set(err, PRSM_ENOTFOUND, NULL, "nothing queued")
		                         : db_error(err, c->db, "claim");
		goto done;
	}
	prsm_store_job row;
	read_row(&row, q);
	sqlite3_reset(q);
	double now = now_unix_s();
	q = stmt(c, ST_START);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
		goto done;
	}
	sqlite3_bind_text(q, 1, row.id, -1, SQLITE_STATIC);
	sqlite3_bind_double(q, 2, now);
	step = sqlite3_step(q);
	sqlite3_reset(q);
	if (step != SQLITE_DONE) {
		rc = db_error(err, c->db, "start job");
		goto done;
	}
	rc = commit(c, err);
	if (!rc)
		rc = get_locked(c, out, row.id, PRSM_STORE_WITH_REQUEST, err);
done:
	if (rc)
		rollback(c);
	release(c);
	return rc;
}

int prsm_store_finish(prsm_store *s, const char *id, prsm_job_state state, const char *result,
                      const char *problem, const char *csv, size_t csv_len,
                      long long samples_done, long long samples_planned, int *applied,
                      prsm_error *err)
{
	if (applied)
		*applied = 0;
	conn *c = acquire(s);
	int rc = begin(c, err);
	if (rc)
		goto done;
	sqlite3_stmt *q = stmt(c, ST_FINISH);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
		goto done;
	}
	sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
	sqlite3_bind_int(q, 2, (int)state);
	sqlite3_bind_double(q, 3, now_unix_s());
	if (result)
		sqlite3_bind_text(q, 4, result, -1, SQLITE_STATIC);
	if (problem)
		sqlite3_bind_text(q, 5, problem, -1, SQLITE_STATIC);
	sqlite3_bind_int64(q, 6, samples_done);
	sqlite3_bind_int64(q, 7, samples_planned);
	int step = sqlite3_step(q);
	sqlite3_reset(q);
	if (step != SQLITE_DONE) {
		rc = db_error(err, c->db, "finish job");
		goto done;
	}
	int changed = sqlite3_changes(c->db);
	if (changed && csv) {
		q = stmt(c, ST_INSERT_CSV);
		if (!q) {
			rc = db_error(err, c->db, "prepare");
			goto done;
		}
		sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
		sqlite3_bind_blob64(q, 2, csv, (sqlite3_uint64)csv_len, SQLITE_STATIC);
		step = sqlite3_step(q);
		sqlite3_reset(q);
		if (step != SQLITE_DONE) {
			rc = db_error(err, c->db, "store samples");
			goto done;
		}
	}
	rc = commit(c, err);
	if (!rc && applied)
		*applied = changed > 0;
done:
	if (rc)
		rollback(c);
	release(c);
	return rc;
}

/* One parameterised UPDATE in its own transaction; *changes the rows it changed. */
static int update_one(prsm_store *s, int which, const char *id, int bind_now, int *changes, prsm_error *err)
{
	conn *c = acquire(s);
	int rc = begin(c, err);
	if (!rc) {
		sqlite3_stmt *q = stmt(c, which);
		if (!q) {
			rc = db_error(err, c->db, "prepare");
		} else {
			if (id)
				sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
			if (bind_now)
				sqlite3_bind_double(q, 2, now_unix_s());
			int step = sqlite3_step(q);
			sqlite3_reset(q);
			if (step != SQLITE_DONE)
				rc = db_error(err, c->db, "update");
			else if (changes)
				*changes = sqlite3_changes(c->db);
		}
		if (!rc)
			rc = commit(c, err);
		if (rc)
			rollback(c);
	}
	release(c);
	return rc;
}

int prsm_store_requeue(prsm_store *s, const char *id, prsm_error *err)
{
	return update_one(s, ST_REQUEUE, id, 0, NULL, err);
}

int prsm_store_recover(prsm_store *s, int *n, prsm_error *err)
{
	int changes = 0;
	int rc = update_one(s, ST_RECOVER, NULL, 0, &changes, err);
	if (n)
		*n = changes;
	return rc;
}

int prsm_store_cancel(prsm_store *s, prsm_store_job *out, const char *id, prsm_error *err)
{
	memset(out, 0, sizeof *out);
	conn *c = acquire(s);
	int rc = begin(c, err);
	if (rc)
		goto done;
	prsm_store_job before;
	rc = get_locked(c, &before, id, 0, err);
	if (rc)
		goto done;
	if (before.state != PRSM_JOB_QUEUED && before.state != PRSM_JOB_RUNNING) {
		*out = before;
		rc = prsm_error_set(err, PRSM_ECANCELLED, NULL, "job %s is already %s", id, prsm_job_state_name(before.state));
		goto done;
	}
	sqlite3_stmt *q = stmt(c, ST_CANCEL);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
		goto done;
	}
	sqlite3_bind_text(q, 1, id, -1, SQLITE_STATIC);
	sqlite3_bind_double(q, 2, now_unix_s());
	int step = sqlite3_step(q);
	sqlite3_reset(q);
	if (step != SQLITE_DONE) {
		rc = db_error(err, c->db, "cancel");
		goto done;
	}
	rc = commit(c, err);
	if (!rc)
		rc = get_locked(c, out, id, 0, err);
done:
	if (rc)
		rollback(c);
	release(c);
	return rc;
}

int prsm_store_list(prsm_store *s, prsm_store_job *items, size_t max, size_t *n, int *more,
                    const char *kind, long long before_seq, prsm_error *err)
{
	*n = 0;
	*more = 0;
	conn *c = acquire(s);
	int rc = 0;
	sqlite3_stmt *q = stmt(c, ST_LIST);
	if (!q) {
		rc = db_error(err, c->db, "prepare");
	} else {
		sqlite3_bind_text(q, 1, kind, -1, SQLITE_STATIC);
		sqlite3_bind_int64(q, 2, before_seq > 0 ? before_seq : INT64_MAX);
		sqlite3_bind_int64(q, 3, (sqlite3_int64)max + 1);
		int step;
		while ((step = sqlite3_step(q)) == SQLITE_ROW) {
			if (*n == max) {
				*more = 1;
				break;
			}
			read_row(&items[(*n)++], q);
		}
		if (step != SQLITE_ROW && step != SQLITE_DONE)
			rc = db_error(err, c->db, "list");
		sqlite3_reset(q);
	}
	release(c);
	return rc;
}

int prsm_store_count(prsm_store *s, long long *n, prsm_job_state state, prsm_error *err)
{
	conn *c = acquire(s);
	int rc = count_state(c, n, state) ? db_error(err, c->db, "count") : 0;
	release(c);
	return rc;
}
