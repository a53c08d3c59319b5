/*
 * test_store.c: store/ on a temporary database — migration to the current user_version and
 * WAL mode, a newer schema refused; submit creates, shares an in-flight job, serves a done one
 * from the cache, refuses past the queue cap; claim order, finish (result, CSV, a cancelled
 * job left alone), cancel of queued/running/finished jobs, recovery of running jobs after a
 * "crash" (reopen without finishing), paging; two threads submitting the same key make one job.
 */
#include "test_support.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <sqlite3.h>

#include "store/store.h"

#include "test_db.h"

static prsm_store *open_store(void)
{
	prsm_store *s = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_store_open(&s, db_path, 4, &err);
	if (rc)
		print_error("open: %s\n", err.message);
	assert_int_equal(rc, 0);
	return s;
}

static void test_migrate_and_wal(void **state)
{
	(void)state;
	prsm_store *s = open_store();
	assert_int_equal(prsm_store_schema_version(s), PRSM_STORE_SCHEMA_VERSION);
	prsm_store_close(s);
	sqlite3 *db;
	assert_int_equal(sqlite3_open(db_path, &db), SQLITE_OK);
	sqlite3_stmt *q;
	assert_int_equal(sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &q, NULL), SQLITE_OK);
	assert_int_equal(sqlite3_step(q), SQLITE_ROW);
	assert_string_equal((const char *)sqlite3_column_text(q, 0), "wal");
	sqlite3_finalize(q);
	/* a database from a newer prsm is refused, not damaged */
	assert_int_equal(sqlite3_exec(db, "PRAGMA user_version = 99", NULL, NULL, NULL), SQLITE_OK);
	sqlite3_close(db);
	prsm_store *t = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_store_open(&t, db_path, 2, &err), PRSM_EIO);
	assert_null(t);
	assert_non_null(strstr(err.message, "schema version 99"));
}

static void test_lifecycle(void **state)
{
	(void)state;
	prsm_store *s = open_store();
	prsm_error err = PRSM_ERROR_INIT;
	prsm_store_job a, b, c;
	prsm_submit_outcome oc;
	assert_int_equal(prsm_store_submit(s, &a, &oc, "study", "k1", "{\"x\":1}", 8, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	assert_int_equal(strlen(a.id), 32);
	assert_int_equal(a.state, PRSM_JOB_QUEUED);
	/* the same key while queued: shared */
	assert_int_equal(prsm_store_submit(s, &b, &oc, "study", "k1", "{\"x\":1}", 8, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_SHARED);
	assert_string_equal(a.id, b.id);
	/* another kind with the same key is another job */
	assert_int_equal(prsm_store_submit(s, &c, &oc, "optimization", "k1", "{}", 8, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	assert_string_not_equal(a.id, c.id);

	/* claim in submission order, with the request */
	prsm_store_job r;
	assert_int_equal(prsm_store_claim(s, &r, &err), 0);
	assert_string_equal(r.id, a.id);
	assert_int_equal(r.state, PRSM_JOB_RUNNING);
	assert_int_equal(r.attempts, 1);
	assert_string_equal(r.request, "{\"x\":1}");
	prsm_store_job_clear(&r);
	/* shared while running */
	assert_int_equal(prsm_store_submit(s, &b, &oc, "study", "k1", "{\"x\":1}", 8, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_SHARED);

	int applied = 0;
	assert_int_equal(prsm_store_finish(s, a.id, PRSM_JOB_DONE, "{\"y\":2}", NULL, "i,y\n0,2\n", 8, 100, 100,
	                                   &applied, &err), 0);
	assert_true(applied);
	/* a second finish does nothing: the job is no longer running */
	assert_int_equal(prsm_store_finish(s, a.id, PRSM_JOB_FAILED, NULL, "{}", NULL, 0, 0, 0, &applied, &err), 0);
	assert_false(applied);
	assert_int_equal(prsm_store_get(s, &r, a.id, PRSM_STORE_WITH_RESULT, &err), 0);
	assert_int_equal(r.state, PRSM_JOB_DONE);
	assert_string_equal(r.result, "{\"y\":2}");
	assert_int_equal(r.result_len, 7);
	assert_null(r.problem);
	assert_int_equal(r.samples_done, 100);
	assert_true(r.finished_s >= r.started_s && r.started_s >= r.created_s);
	prsm_store_job_clear(&r);
	char *csv;
	size_t len;
	assert_int_equal(prsm_store_get_csv(s, &csv, &len, a.id, &err), 0);
	assert_int_equal(len, 8);
	assert_memory_equal(csv, "i,y\n0,2\n", 8);
	free(csv);
	assert_int_equal(prsm_store_get_csv(s, &csv, &len, c.id, &err), PRSM_ENOTFOUND);

	/* done: a cache hit */
	assert_int_equal(prsm_store_submit(s, &b, &oc, "study", "k1", "{\"x\":1}", 8, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_CACHED);
	assert_string_equal(b.id, a.id);

	/* cancel: a finished job is a conflict, a queued one is cancelled */
	assert_int_equal(prsm_store_cancel(s, &r, a.id, &err), PRSM_ECANCELLED);
	assert_int_equal(r.state, PRSM_JOB_DONE);
	assert_int_equal(prsm_store_cancel(s, &r, c.id, &err), 0);
	assert_int_equal(r.state, PRSM_JOB_CANCELLED);
	assert_int_equal(prsm_store_cancel(s, &r, c.id, &err), PRSM_ECANCELLED);
	assert_int_equal(prsm_store_cancel(s, &r, "nope", &err), PRSM_ENOTFOUND);
	assert_int_equal(prsm_store_get(s, &r, "nope", 0, &err), PRSM_ENOTFOUND);
	/* a cancelled job is not reused by a new submission */
	assert_int_equal(prsm_store_submit(s, &b, &oc, "optimization", "k1", "{}", 8, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	assert_string_not_equal(b.id, c.id);
	prsm_store_close(s);
}

static void test_queue_cap_and_cancel_running(void **state)
{
	(void)state;
	prsm_store *s = open_store();
	prsm_error err = PRSM_ERROR_INIT;
	prsm_store_job j, r;
	prsm_submit_outcome oc;
	assert_int_equal(prsm_store_submit(s, &j, &oc, "study", "a", "{}", 2, &err), 0);
	assert_int_equal(prsm_store_submit(s, &j, &oc, "study", "b", "{}", 2, &err), 0);
	assert_int_equal(prsm_store_submit(s, &j, &oc, "study", "c", "{}", 2, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_FULL);
	long long n;
	assert_int_equal(prsm_store_count(s, &n, PRSM_JOB_QUEUED, &err), 0);
	assert_int_equal(n, 2);
	assert_int_equal(prsm_store_claim(s, &r, &err), 0);
	prsm_store_job_clear(&r);
	assert_int_equal(prsm_store_submit(s, &j, &oc, "study", "c", "{}", 2, &err), 0);
	assert_int_equal(oc, PRSM_SUBMIT_CREATED);
	/* cancelling the running job; its late finish is ignored */
	prsm_store_job first;
	assert_int_equal(prsm_store_claim(s, &first, &err), 0);
	assert_int_equal(prsm_store_cancel(s, &r, first.id, &err), 0);
	int applied = 1;
	assert_int_equal(prsm_store_finish(s, first.id, PRSM_JOB_DONE, "{}", NULL, NULL, 0, 1, 1, &applied, &err), 0);
	assert_false(applied);
	assert_int_equal(prsm_store_get(s, &r, first.id, 0, &err), 0);
	assert_int_equal(r.state, PRSM_JOB_CANCELLED);
	prsm_store_job_clear(&first);
	prsm_store_close(s);
}

static void test_recover_and_list(void **state)
{
	(void)state;
	prsm_store *s = open_store();
	prsm_error err = PRSM_ERROR_INIT;
	prsm_store_job j, r;
	prsm_submit_outcome oc;
	char key[8];
	for (int i = 0; i < 5; i++) {
		snprintf(key, sizeof key, "k%d", i);
		assert_int_equal(prsm_store_submit(s, &j, &oc, "study", key, "{}", 100, &err), 0);
	}
	assert_int_equal(prsm_store_claim(s, &r, &err), 0);
	char running[PRSM_STORE_ID_MAX];
	snprintf(running, sizeof running, "%s", r.id);
	prsm_store_job_clear(&r);
	prsm_store_close(s); /* "crash": the running job was never finished */

	s = open_store();
	int n = 0;
	assert_int_equal(prsm_store_recover(s, &n, &err), 0);
	assert_int_equal(n, 1);
	assert_int_equal(prsm_store_get(s, &r, running, 0, &err), 0);
	assert_int_equal(r.state, PRSM_JOB_QUEUED);
	assert_int_equal(prsm_store_claim(s, &r, &err), 0); /* first in line again */
	assert_string_equal(r.id, running);
	assert_int_equal(r.attempts, 2);
	prsm_store_job_clear(&r);

	prsm_store_job items[2];
	size_t got;
	int more;
	assert_int_equal(prsm_store_list(s, items, 2, &got, &more, "study", 0, &err), 0);
	assert_int_equal(got, 2);
	assert_true(more);
	assert_true(items[0].seq > items[1].seq);
	long long seen = items[1].seq;
	size_t total = 2;
	while (more) {
		assert_int_equal(prsm_store_list(s, items, 2, &got, &more, "study", seen, &err), 0);
		assert_true(got > 0);
		assert_true(items[0].seq < seen);
		seen = items[got - 1].seq;
		total += got;
	}
	assert_int_equal(total, 5);
	assert_int_equal(prsm_store_list(s, items, 2, &got, &more, "allocation", 0, &err), 0);
	assert_int_equal(got, 0);
	prsm_store_close(s);
}

typedef struct {
	prsm_store *s;
	char id[PRSM_STORE_ID_MAX];
	int created;
} racer;

static void *race(void *arg)
{
	racer *r = arg;
	prsm_error err = PRSM_ERROR_INIT;
	prsm_store_job j;
	prsm_submit_outcome oc;
	for (int i = 0; i < 20; i++) {
		if (prsm_store_submit(r->s, &j, &oc, "study", "same", "{}", 100, &err) == 0) {
			r->created += oc == PRSM_SUBMIT_CREATED;
			snprintf(r->id, sizeof r->id, "%s", j.id);
		}
	}
	return NULL;
}

static void test_concurrent_submissions(void **state)
{
	(void)state;
	prsm_store *s = open_store();
	racer r[4];
	pthread_t t[4];
	for (int i = 0; i < 4; i++) {
		memset(&r[i], 0, sizeof r[i]);
		r[i].s = s;
		pthread_create(&t[i], NULL, race, &r[i]);
	}
	int created = 0;
	for (int i = 0; i < 4; i++) {
		pthread_join(t[i], NULL);
		created += r[i].created;
	}
	assert_int_equal(created, 1);
	for (int i = 1; i < 4; i++)
		assert_string_equal(r[i].id, r[0].id);
	prsm_store_close(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_migrate_and_wal, setup, teardown),
		cmocka_unit_test_setup_teardown(test_lifecycle, setup, teardown),
		cmocka_unit_test_setup_teardown(test_queue_cap_and_cancel_running, setup, teardown),
		cmocka_unit_test_setup_teardown(test_recover_and_list, setup, teardown),
		cmocka_unit_test_setup_teardown(test_concurrent_submissions, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
