/*
 * server.h: the HTTP/JSON service (DESIGN.md, "Service"; the contract is api/openapi.yaml).
 *
 * libmicrohttpd with its own thread pool and epoll; the handlers only parse, validate, look
 * up the cache, insert a job and answer — studies run on the job layer's workers
 * (job/jobs.h); POST /v1/designs/analyze runs on the HTTP thread within a size and time budget
 * (sync_evaluations, sync_time_s) and becomes an "analysis" job beyond it. Every error is an RFC 7807 application/problem+json document with all the problems
 * of the request and their JSON pointers (schemas/problem.schema.json).
 *
 * Routes: /v1/health, /v1/version, /v1/openapi.json, /v1/schemas/{name},
 * /v1/designs/analyze, and for every job kind (job/kind.h) /v1/<collection>,
 * /v1/<collection>/{id}, /v1/<collection>/{id}/samples.csv; everything else under / is a
 * file of web/ (no path leaves it).
 */
#ifndef PRSM_HTTP_SERVER_H
#define PRSM_HTTP_SERVER_H

#include <stddef.h>

#include "job/jobs.h"
#include "util/error.h"

typedef struct {
	const char *host;            /* address to bind, default 127.0.0.1 */
	int port;                    /* 0: any free port (see prsm_http_port) */
	int threads;                 /* libmicrohttpd's thread pool */
	size_t max_body_bytes;       /* a request body larger than this: 413 */
	size_t body_memory_bytes;    /* bodies being received at once, all connections: past it 503 */
	unsigned timeout_s;          /* an idle connection is closed after this */
	size_t connection_memory_bytes; /* libmicrohttpd's per-connection buffer (headers, reading) */
	unsigned max_connections;
	const char *token;           /* bearer token for POST and DELETE; NULL: none */
	const char *data_dir;        /* holds web/, schemas/ and api/openapi.json */
	/* POST /v1/designs/analyze runs on the HTTP thread only within this budget; heavier work
	 * becomes an "analysis" job (202) */
	double sync_time_s;          /* computation time of one synchronous analysis, s */
	double sync_evaluations;     /* its contact-gap evaluations (prsm_app_analyze_cost) */
} prsm_http_options;

#define PRSM_HTTP_OPTIONS_INIT                                                                     \
	{"127.0.0.1", 8080, 2, 1048576, 67108864, 30, 65536, 512, NULL, ".", 2.0, PRSM_HTTP_SYNC_EVALUATIONS}

/* The default synchronous budget in linear-mode contact-gap evaluations (prsm_assembly_cost):
 * about 0.6 s of work on a 2024 laptop core. Case A with errors, 64 angles per revolution and a
 * 16-revolution record costs 2.4e5; the largest record the request allows, 2e8. */
#define PRSM_HTTP_SYNC_EVALUATIONS 2.0e7

typedef struct prsm_http prsm_http;

/* Load the schemas and the OpenAPI document from o->data_dir and start listening. jobs is
 * borrowed (it must outlive the server). *out owned by the caller (prsm_http_stop). Returns 0,
 * PRSM_EIO (a file is missing, the address cannot be bound) or PRSM_ENOMEM. */
int prsm_http_start(prsm_http **out, const prsm_http_options *o, prsm_jobs *jobs, prsm_error *err);

/* The port it listens on. */
int prsm_http_port(const prsm_http *h);

/* Stop accepting connections; the ones open are served to the end. */
void prsm_http_quiesce(prsm_http *h);

/* Close every connection, stop the threads and free h. */
void prsm_http_stop(prsm_http *h);

#endif
