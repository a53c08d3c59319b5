/*
 * test_db.h: a fresh temporary SQLite database path per test (setup) and its removal with the
 * WAL and shared-memory files (teardown), for the store and job tests.
 */
#ifndef PRSM_TEST_DB_H
#define PRSM_TEST_DB_H

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static char db_path[64];

static int setup(void **state)
{
	(void)state;
	snprintf(db_path, sizeof db_path, "/tmp/prsm-test-db-XXXXXX");
	int fd = mkstemp(db_path);
	if (fd < 0)
		return -1;
	close(fd);
	unlink(db_path);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	char p[80];
	unlink(db_path);
	snprintf(p, sizeof p, "%s-wal", db_path);
	unlink(p);
	snprintf(p, sizeof p, "%s-shm", db_path);
	unlink(p);
	return 0;
}

#endif
