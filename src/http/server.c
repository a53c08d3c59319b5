/*
 * server.c: the service's routes on libmicrohttpd (see server.h).
 *
 * A request's life: on the first call of the access handler (headers read, no body yet) the
 * framing headers, the route and method, the bearer token, the media type and the declared
 * length are checked, and a refusal is answered at once (libmicrohttpd then closes the
 * connection without reading the body). The body is collected in a bounded buffer (past the
 * cap it is discarded and answered 413; a client that keeps sending far past it is
 * disconnected); the bytes being received on all connections at once are capped too (503).
 * On the last call the route's handler answers. Documents that never change (schemas, the
 * OpenAPI document, /v1/version) are loaded once at start and served from memory.
 */
#include "http/server.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <netdb.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gsl/gsl_version.h>
#include <microhttpd.h>
#include <nettle/version.h>
#include <sqlite3.h>

#include "http/mhd.h"
#include "http/request.h"
#include "app/validate.h"
#include "io/analysis_json.h"
#include "app/analyze.h"
#include "io/analyze_request.h"
#include "io/global.h"
#include "util/clock.h"
#include "util/file.h"
#include "util/version.h"

#define MAX_SCHEMAS 64
#define SCHEMA_NAME_MAX 96
#define DOC_MAX_BYTES (4u * 1024u * 1024u)
#define LIST_MAX 100
#define LIST_DEFAULT 20

typedef struct {
	char name[SCHEMA_NAME_MAX];
	char *text;  /* owned by the server */
	size_t len;
} loaded_doc;

struct prsm_http {
	struct MHD_Daemon *d;
	prsm_http_options o;
	prsm_jobs *jobs;            /* borrowed */
	char token[512];            /* "" when none */
	char web_root[PATH_MAX];    /* real path of web/, "" when there is none */
	int port;
	double started_s;
	atomic_size_t body_bytes;   /* request bodies held now, all connections */
	atomic_int sync_running;    /* analyses running on HTTP threads now */
	size_t n_schemas;
	loaded_doc schemas[MAX_SCHEMAS];
	loaded_doc openapi;
	loaded_doc version;
};

typedef enum {
	R_NONE,
	R_HEALTH,
	R_VERSION,
	R_OPENAPI,
	R_SCHEMA,
	R_ANALYZE,
	R_VALIDATE,
	R_COLLECTION,
	R_JOB,
	R_SAMPLES,
	R_STATIC
} route_kind;

typedef struct {
	route_kind kind;
	const prsm_job_kind *job_kind;
	char arg[SCHEMA_NAME_MAX];  /* job id or schema name */
	const char *allow;          /* methods of the route, for 405's Allow */
} route;

/* One request's state, from its first handler call to its completion (owned by the
 * connection: freed in request_completed). */
typedef struct {
	route rt;
	int answered;               /* a response was queued at the headers */
	char *body;                 /* bounded by max_body_bytes */
	size_t len, cap;
	int too_large, over_budget;
	size_t discarded;
	int form;                   /* a calibration sent as multipart/form-data (docs/service.md) */
	char boundary[PRSM_HTTP_BOUNDARY_MAX + 1];
} request;

/* ---- responses ---------------------------------------------------------------------------- */

static enum MHD_Result send_response(struct MHD_Connection *c, unsigned status, const char *type, void *buf,
                                     size_t len, enum MHD_ResponseMemoryMode mode, const char *hname,
                                     const char *hvalue)
{
	struct MHD_Response *r = prsm_mhd.create_response_from_buffer(len, buf, mode);
	if (!r) {
		if (mode == MHD_RESPMEM_MUST_FREE)
			free(buf);
		return MHD_NO;
	}
	prsm_mhd.add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
	prsm_mhd.add_response_header(r, "X-Content-Type-Options", "nosniff");
	if (hname && hvalue)
		prsm_mhd.add_response_header(r, hname, hvalue);
	enum MHD_Result ok = prsm_mhd.queue_response(c, status, r);
	prsm_mhd.destroy_response(r);
	return ok;
}

static enum MHD_Result send_json_text(struct MHD_Connection *c, unsigned status, char *text, size_t len,
                                      const char *hname, const char *hvalue)
{
	return send_response(c, status, "application/json", text, len, MHD_RESPMEM_MUST_FREE, hname, hvalue);
}

/* cJSON allocation failures on this thread when the request being answered was dispatched: a
 * response document built since then is sent only when nothing was dropped from it (global.h). */
static _Thread_local unsigned long response_mark;

/* The answer when a response document could not be built whole: static text, no allocation. */
static enum MHD_Result send_out_of_memory(struct MHD_Connection *c)
{
	static const char body[] = "{\"type\":\"about:blank\",\"title\":\"Service Unavailable\",\"status\":503,"
	                           "\"detail\":\"out of memory writing the response\",\"errors\":[{\"pointer\":\"\","
	                           "\"code\":\"memory\",\"message\":\"out of memory writing the response\"}]}";
	return send_response(c, 503, "application/problem+json", (void *)(uintptr_t)body, sizeof body - 1,
	                     MHD_RESPMEM_PERSISTENT, "Retry-After", "1");
}

static enum MHD_Result send_tree(struct MHD_Connection *c, unsigned status, cJSON *tree, const char *hname,
                                 const char *hvalue)
{
	char *text = prsm_json_print_whole(tree, response_mark, 0); /* freed by libmicrohttpd */
	cJSON_Delete(tree);
	if (!text)
		return send_out_of_memory(c);
	return send_json_text(c, status, text, strlen(text), hname, hvalue);
}

static const char *status_title(unsigned status)
{
	switch (status) {
	case 400: return "Bad Request";
	case 401: return "Unauthorized";
	case 404: return "Not Found";
	case 405: return "Method Not Allowed";
	case 409: return "Conflict";
	case 413: return "Content Too Large";
	case 415: return "Unsupported Media Type";
	case 422: return "Unprocessable Content";
	case 429: return "Too Many Requests";
	case 503: return "Service Unavailable";
	default: return status >= 500 ? "Internal Server Error" : "Bad Request";
	}
}

static enum MHD_Result send_problems(struct MHD_Connection *c, unsigned status, const prsm_problems *p,
                                     const char *hname, const char *hvalue)
{
	prsm_problems one;
	if (p->count == 0) {
		prsm_problems_init(&one);
		prsm_problems_add(&one, "", NULL, "%s", status_title(status));
		p = &one;
	}
	cJSON *doc = prsm_io_problem_document((int)status, status_title(status), p);
	char *text = prsm_json_print_whole(doc, response_mark, 0); /* freed by libmicrohttpd */
	cJSON_Delete(doc);
	if (!text)
		return send_out_of_memory(c);
	return send_response(c, status, "application/problem+json", text, strlen(text), MHD_RESPMEM_MUST_FREE, hname,
	                     hvalue);
}

static enum MHD_Result send_problem(struct MHD_Connection *c, unsigned status, const char *pointer,
                                    const char *code, const char *hname, const char *hvalue, const char *fmt, ...)
	__attribute__((format(printf, 7, 8)));

static enum MHD_Result send_problem(struct MHD_Connection *c, unsigned status, const char *pointer,
                                    const char *code, const char *hname, const char *hvalue, const char *fmt, ...)
{
	char msg[PRSM_PROBLEM_MESSAGE_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_problems_add(&p, pointer, code, "%s", msg);
	return send_problems(c, status, &p, hname, hvalue);
}

/* ---- routing ------------------------------------------------------------------------------ */

static int id_ok(const char *s, size_t n)
{
	if (n == 0 || n >= PRSM_STORE_ID_MAX + 32)
		return 0;
	for (size_t i = 0; i < n; i++)
		if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z') ||
		      s[i] == '-' || s[i] == '_'))
			return 0;
	return 1;
}

static void resolve(route *rt, const char *url)
{
	memset(rt, 0, sizeof *rt);
	rt->allow = "GET, HEAD";
	if (strncmp(url, "/v1/", 4) != 0 && strcmp(url, "/v1") != 0) {
		rt->kind = R_STATIC;
		return;
	}
	const char *p = url + 3;
	if (*p == '/')
		p++;
	if (strcmp(p, "health") == 0) {
		rt->kind = R_HEALTH;
	} else if (strcmp(p, "version") == 0) {
		rt->kind = R_VERSION;
	} else if (strcmp(p, "openapi.json") == 0) {
		rt->kind = R_OPENAPI;
	} else if (strncmp(p, "schemas/", 8) == 0 && p[8] && !strchr(p + 8, '/') && strlen(p + 8) < SCHEMA_NAME_MAX) {
		rt->kind = R_SCHEMA;
		snprintf(rt->arg, sizeof rt->arg, "%s", p + 8);
	} else if (strcmp(p, "designs/analyze") == 0) {
		rt->kind = R_ANALYZE;
		rt->allow = "POST";
	} else if (strcmp(p, "validate") == 0) {
		rt->kind = R_VALIDATE;
		rt->allow = "POST";
	} else {
		/* <collection>[/<id>[/samples.csv]] */
		const char *s1 = strchr(p, '/');
		size_t clen = s1 ? (size_t)(s1 - p) : strlen(p);
		char coll[32];
		if (clen == 0 || clen >= sizeof coll)
			return;
		memcpy(coll, p, clen);
		coll[clen] = '\0';
		const prsm_job_kind *k = prsm_job_kind_by_collection(coll);
		if (!k)
			return;
		rt->job_kind = k;
		if (!s1) {
			rt->kind = R_COLLECTION;
			rt->allow = "GET, HEAD, POST";
			return;
		}
		const char *id = s1 + 1;
		const char *s2 = strchr(id, '/');
		size_t ilen = s2 ? (size_t)(s2 - id) : strlen(id);
		if (!id_ok(id, ilen) || ilen >= sizeof rt->arg)
			return;
		memcpy(rt->arg, id, ilen);
		rt->arg[ilen] = '\0';
		if (!s2) {
			rt->kind = R_JOB;
			rt->allow = "GET, HEAD, DELETE";
		} else if (strcmp(s2, "/samples.csv") == 0 && k->has_samples_csv) {
			rt->kind = R_SAMPLES;
		}
	}
}

static int method_allowed(const char *allow, const char *method)
{
	size_t n = strlen(method);
	for (const char *p = allow; *p;) {
		const char *e = strchr(p, ',');
		size_t len = e ? (size_t)(e - p) : strlen(p);
		if (len == n && strncmp(p, method, n) == 0)
			return 1;
		if (!e)
			break;
		p = e + 1;
		while (*p == ' ')
			p++;
	}
	return 0;
}

/* ---- the first call: headers ---------------------------------------------------------------- */

typedef struct {
	int content_length, transfer_encoding;
	const char *content_length_value;
} framing;

static enum MHD_Result count_headers(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
	(void)kind;
	framing *f = cls;
	if (strcasecmp(key, "Content-Length") == 0) {
		f->content_length++;
		f->content_length_value = value;
	} else if (strcasecmp(key, "Transfer-Encoding") == 0) {
		f->transfer_encoding++;
	}
	return MHD_YES;
}

/* Checks at the headers; 0 when the request may go on, else it was answered (or failed). */
static int precheck(prsm_http *h, struct MHD_Connection *c, const char *url, const char *method, request *r,
                    enum MHD_Result *ret)
{
	prsm_problems p;
	prsm_problems_init(&p);
	framing f = {0, 0, NULL};
	prsm_mhd.get_connection_values(c, MHD_HEADER_KIND, count_headers, &f);
	int status = prsm_http_check_framing(f.content_length, f.content_length_value, f.transfer_encoding, &p);
	if (status) {
		*ret = send_problems(c, (unsigned)status, &p, "Connection", "close");
		return 1;
	}
	resolve(&r->rt, url);
	if (r->rt.kind == R_NONE) {
		*ret = send_problem(c, 404, "", "not_found", NULL, NULL, "no such resource: %.160s", url);
		return 1;
	}
	if (!method_allowed(r->rt.allow, method)) {
		*ret = send_problem(c, 405, "", "method", "Allow", r->rt.allow, "%.16s is not allowed here; use %s", method,
		                    r->rt.allow);
		return 1;
	}
	int writes = strcmp(method, "POST") == 0 || strcmp(method, "DELETE") == 0;
	if (writes && h->token[0] &&
	    !prsm_http_bearer_ok(prsm_mhd.lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_AUTHORIZATION),
	                         h->token)) {
		*ret = send_problem(c, 401, "", "token", "WWW-Authenticate", "Bearer realm=\"prsm\"",
		                    "this service needs 'Authorization: Bearer <token>' for %s", method);
		return 1;
	}
	if (strcmp(method, "POST") == 0) {
		const char *type = prsm_mhd.lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
		/* a calibration may come as a form: its JSON request and the bench's CSV file */
		const int takes_form = r->rt.kind == R_COLLECTION && r->rt.job_kind == &prsm_job_kind_calibration;
		const int form = takes_form ? prsm_http_multipart_boundary(type, r->boundary, sizeof r->boundary) : 0;
		if (form < 0) {
			*ret = send_problem(c, 400, "", "media_type", NULL, NULL,
			                    "Content-Type %.80s: multipart/form-data needs a boundary parameter of 1 to %d "
			                    "characters (RFC 2046)", type, PRSM_HTTP_BOUNDARY_MAX);
			return 1;
		}
		r->form = form == 1;
		if (!r->form && !prsm_http_is_json_type(type)) {
			const char *accept = takes_form ? "application/json, multipart/form-data" : "application/json";
			*ret = send_problem(c, 415, "", "media_type", "Accept-Post", accept,
			                    takes_form ? "Content-Type %.80s: send application/json, or multipart/form-data with "
			                                 "the parts request (JSON) and measured (the TE curve as CSV)"
			                               : "Content-Type %.80s: send application/json",
			                    type ? type : "(none)");
			return 1;
		}
		if (f.content_length_value) {
			unsigned long long n = strtoull(f.content_length_value, NULL, 10);
			if (n > h->o.max_body_bytes) {
				*ret = send_problem(c, 413, "", "too_large", "Connection", "close",
				                    "the body is %llu bytes; this service takes at most %zu", n,
				                    h->o.max_body_bytes);
				return 1;
			}
		}
	}
	return 0;
}

/* Collect a chunk of the body; 0, or -1 to drop the connection. */
static int collect(prsm_http *h, request *r, const char *data, size_t n)
{
	if (r->too_large || r->over_budget) {
		r->discarded += n;
		return r->discarded > 4 * h->o.max_body_bytes ? -1 : 0;
	}
	if (n > h->o.max_body_bytes - r->len) {
		r->too_large = 1;
		r->discarded = r->len + n;
		return 0;
	}
	if (r->len + n + 1 > r->cap) {
		size_t cap = r->cap ? r->cap : 4096;
		while (cap < r->len + n + 1)
			cap *= 2;
		if (cap > h->o.max_body_bytes + 1)
			cap = h->o.max_body_bytes + 1;
		size_t grow = cap - r->cap;
		size_t before = atomic_fetch_add(&h->body_bytes, grow);
		if (before + grow > h->o.body_memory_bytes) {
			atomic_fetch_sub(&h->body_bytes, grow);
			r->over_budget = 1;
			r->discarded = r->len + n;
			return 0;
		}
		char *b = realloc(r->body, cap); /* owned by the request */
		if (!b) {
			atomic_fetch_sub(&h->body_bytes, grow);
			r->over_budget = 1;
			return 0;
		}
		r->body = b;
		r->cap = cap;
	}
	memcpy(r->body + r->len, data, n);
	r->len += n;
	r->body[r->len] = '\0';
	return 0;
}

/* ---- handlers ------------------------------------------------------------------------------ */

static enum MHD_Result on_health(prsm_http *h, struct MHD_Connection *c)
{
	int workers, running;
	prsm_jobs_counts(h->jobs, &workers, &running);
	char buf[256];
	int n = snprintf(buf, sizeof buf, "{\"status\":\"ok\",\"uptime_s\":%.3f,\"workers\":%d,\"jobs_running\":%d}",
	                 prsm_clock_seconds() - h->started_s, workers, running);
	return send_response(c, 200, "application/json", buf, (size_t)n, MHD_RESPMEM_MUST_COPY, NULL, NULL);
}

static enum MHD_Result on_doc(struct MHD_Connection *c, const loaded_doc *d)
{
	return send_response(c, 200, "application/json", d->text, d->len, MHD_RESPMEM_PERSISTENT, NULL, NULL);
}

static enum MHD_Result on_schema(prsm_http *h, struct MHD_Connection *c, const char *name)
{
	for (size_t i = 0; i < h->n_schemas; i++)
		if (strcmp(h->schemas[i].name, name) == 0)
			return send_response(c, 200, "application/schema+json", h->schemas[i].text, h->schemas[i].len,
			                     MHD_RESPMEM_PERSISTENT, NULL, NULL);
	return send_problem(c, 404, "", "not_found", NULL, NULL, "no schema %.80s (GET /v1/openapi.json lists them)", name);
}

/* The body as a JSON object, or an answered refusal (returns NULL, *ret set). */
static cJSON *body_doc(prsm_http *h, struct MHD_Connection *c, request *r, enum MHD_Result *ret)
{
	(void)h;
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = NULL;
	int status = prsm_http_parse_body(&doc, r->body ? r->body : "", r->len, &p);
	if (status)
		*ret = send_problems(c, (unsigned)status, &p, NULL, NULL);
	return doc;
}

static enum MHD_Result send_view(struct MHD_Connection *c, unsigned status, const prsm_job_view *v,
                                 const char *hname, const char *hvalue)
{
	char *text;
	size_t len;
	if (prsm_job_view_to_text(&text, &len, v))
		return send_problem(c, 503, "", "memory", NULL, NULL, "out of memory");
	return send_json_text(c, status, text, len, hname, hvalue);
}

/* Queue doc as a job of kind k and answer: 202 with Location, 200 when the cache has it, 503 when
 * the queue is full, the problems otherwise. */
static enum MHD_Result submit_and_answer(prsm_http *h, struct MHD_Connection *c, const prsm_job_kind *k,
                                         const cJSON *doc)
{
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_job_view v;
	memset(&v, 0, sizeof v);
	prsm_submit_outcome oc = PRSM_SUBMIT_FULL;
	prsm_error err = PRSM_ERROR_INIT;
	enum MHD_Result ret;
	int rc = prsm_jobs_submit(h->jobs, &v, &oc, k, doc, &p, &err);
	if (rc) {
		if (!p.count)
			prsm_problems_add(&p, err.pointer, NULL, "%s", err.message[0] ? err.message : prsm_error_name(rc));
		ret = send_problems(c, (unsigned)prsm_error_http_status(rc), &p, NULL, NULL);
	} else if (oc == PRSM_SUBMIT_FULL) {
		ret = send_problem(c, 503, "", "queue_full", "Retry-After", "5", "the job queue is full; submit again later");
	} else if (oc == PRSM_SUBMIT_CACHED) {
		ret = send_view(c, 200, &v, NULL, NULL);
	} else {
		char loc[160];
		snprintf(loc, sizeof loc, "/v1/%s/%s", k->collection, v.row.id);
		ret = send_view(c, 202, &v, MHD_HTTP_HEADER_LOCATION, loc);
	}
	prsm_job_view_clear(&v);
	return ret;
}

/* POST /v1/designs/analyze. Answered here while the work fits the synchronous budget: at most
 * sync_evaluations contact-gap evaluations (prsm_app_analyze_cost), at most sync_time_s of
 * computation (a deadline the error analysis checks), and at most threads - 1 such requests at
 * once, so one HTTP thread is always free for health checks and cached reads. Anything heavier,
 * or a request that runs out of time, becomes an "analysis" job (202, Location
 * /v1/analyses/{id}), which the cache then answers for identical requests. */
static enum MHD_Result on_analyze(prsm_http *h, struct MHD_Connection *c, request *r)
{
	enum MHD_Result ret = MHD_NO;
	cJSON *doc = body_doc(h, c, r, &ret);
	if (!doc)
		return ret;
	prsm_problems p, warnings;
	prsm_problems_init(&p);
	prsm_problems_init(&warnings);
	prsm_analyze_request *rq = calloc(1, sizeof *rq); /* freed below */
	if (!rq) {
		cJSON_Delete(doc);
		return send_out_of_memory(c);
	}
	int rc = prsm_app_analyze_load(rq, doc, &warnings, &p);
	int queued = 0;
	if (rc == 0) {
		const int slots = h->o.threads > 1 ? h->o.threads - 1 : 1;
		if (prsm_app_analyze_cost(rq) > h->o.sync_evaluations) {
			queued = 1;
		} else if (atomic_fetch_add(&h->sync_running, 1) >= slots) {
			atomic_fetch_sub(&h->sync_running, 1);
			queued = 1;
		} else {
			rq->options.deadline_s = prsm_clock_seconds() + h->o.sync_time_s;
			rc = prsm_app_analyze_run(rq);
			atomic_fetch_sub(&h->sync_running, 1);
			if (rc == PRSM_ECANCELLED)
				queued = 1; /* out of time: the queue has no such budget */
		}
	}
	if (queued) {
		prsm_io_analyze_free(rq);
		free(rq);
		ret = submit_and_answer(h, c, &prsm_job_kind_analysis, doc);
		cJSON_Delete(doc);
		return ret;
	}
	cJSON_Delete(doc);
	cJSON *out = rc == 0 ? prsm_io_analyze_to_json(rq, &warnings) : NULL;
	prsm_io_analyze_free(rq);
	free(rq);
	if (rc == 0)
		return send_tree(c, 200, out, NULL, NULL);
	if (!p.count)
		prsm_problems_add(&p, "", "computation", "the analysis failed (%s)", prsm_error_name(rc));
	return send_problems(c, (unsigned)prsm_error_http_status(rc), &p, NULL, NULL);
}

/* The job kind a document of kind k is submitted as (NULL: a design, analysed at once). */
static const prsm_job_kind *job_kind_of(prsm_doc_kind k)
{
	switch (k) {
	case PRSM_DOC_STUDY: return &prsm_job_kind_study;
	case PRSM_DOC_OPTIMIZATION: return &prsm_job_kind_optimization;
	case PRSM_DOC_ALLOCATION: return &prsm_job_kind_allocation;
	case PRSM_DOC_SIMULATION: return &prsm_job_kind_simulation;
	case PRSM_DOC_CALIBRATION: return &prsm_job_kind_calibration;
	case PRSM_DOC_DESIGN: break;
	}
	return NULL;
}

/* POST /v1/validate: any request read as its command reads it (app/validate.h), then, when it
 * is valid, held to this service's limits as its collection's submission holds it; 200 with the
 * validation result (schemas/validation.schema.json), valid or not. Runs on the HTTP thread in
 * one of the synchronous slots of /v1/designs/analyze (503 when none is free): reading a study
 * analyses its nominal design, an allocation linearises its model. */
static enum MHD_Result on_validate(prsm_http *h, struct MHD_Connection *c, request *r)
{
	enum MHD_Result ret = MHD_NO;
	cJSON *doc = body_doc(h, c, r, &ret);
	if (!doc)
		return ret;
	const int slots = h->o.threads > 1 ? h->o.threads - 1 : 1;
	if (atomic_fetch_add(&h->sync_running, 1) >= slots) {
		atomic_fetch_sub(&h->sync_running, 1);
		cJSON_Delete(doc);
		return send_problem(c, 503, "", "busy", "Retry-After", "1",
		                    "every synchronous slot is busy; validate again in a moment");
	}
	prsm_problems p, warnings;
	prsm_problems_init(&p);
	prsm_problems_init(&warnings);
	prsm_doc_kind kind = PRSM_DOC_DESIGN;
	int rc = prsm_app_validate(doc, NULL, &kind, &warnings, &p);
	const prsm_job_kind *k = job_kind_of(kind);
	if (rc == 0 && k) {
		const prsm_job_limits lim = prsm_jobs_limits(h->jobs);
		cJSON *norm = NULL;
		rc = k->normalise(&norm, doc, &lim, &p);
		cJSON_Delete(norm);
	}
	atomic_fetch_sub(&h->sync_running, 1);
	cJSON_Delete(doc);
	if (rc == PRSM_ENOMEM)
		return send_out_of_memory(c);
	cJSON *out = prsm_app_validation_to_json(rc, kind, &warnings, &p);
	if (out == NULL)
		return send_out_of_memory(c);
	return send_tree(c, 200, out, NULL, NULL);
}

static enum MHD_Result on_submit(prsm_http *h, struct MHD_Connection *c, request *r)
{
	enum MHD_Result ret = MHD_NO;
	cJSON *doc = NULL;
	if (r->form) {
		prsm_problems p;
		prsm_problems_init(&p);
		int status = prsm_http_calibration_form(&doc, r->body ? r->body : "", r->len, r->boundary, &p);
		if (status)
			return send_problems(c, (unsigned)status, &p, NULL, NULL);
	} else {
		doc = body_doc(h, c, r, &ret);
	}
	if (!doc)
		return ret;
	ret = submit_and_answer(h, c, r->rt.job_kind, doc);
	cJSON_Delete(doc);
	return ret;
}

static enum MHD_Result on_list(prsm_http *h, struct MHD_Connection *c, request *r)
{
	const char *ls = prsm_mhd.lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "limit");
	const char *cs = prsm_mhd.lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "cursor");
	long limit = LIST_DEFAULT;
	long long cursor = 0;
	if (ls) {
		char *end;
		errno = 0;
		limit = strtol(ls, &end, 10);
		if (!*ls || *end || errno || limit < 1 || limit > LIST_MAX)
			return send_problem(c, 400, "", "query", NULL, NULL, "limit: an integer 1..%d", LIST_MAX);
	}
	if (cs) {
		char *end;
		errno = 0;
		cursor = strtoll(cs, &end, 10);
		if (!*cs || *end || errno || cursor < 1)
			return send_problem(c, 400, "", "query", NULL, NULL, "cursor: the value of a page's next_cursor");
	}
	prsm_job_view items[LIST_MAX];
	size_t n = 0;
	long long next = 0;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_jobs_list(h->jobs, items, (size_t)limit, &n, &next, r->rt.job_kind, cursor, &err))
		return send_problem(c, 500, "", "store", NULL, NULL, "%s", err.message);
	cJSON *doc = cJSON_CreateObject();
	cJSON *arr = cJSON_AddArrayToObject(doc, "items");
	for (size_t i = 0; i < n; i++) {
		cJSON_AddItemToArray(arr, prsm_job_view_to_json(&items[i]));
		prsm_job_view_clear(&items[i]);
	}
	cJSON_AddNumberToObject(doc, "limit", (double)limit);
	if (next) {
		char buf[160];
		snprintf(buf, sizeof buf, "%lld", next);
		cJSON_AddStringToObject(doc, "next_cursor", buf);
		snprintf(buf, sizeof buf, "/v1/%s?limit=%ld&cursor=%lld", r->rt.job_kind->collection, limit, next);
		cJSON_AddStringToObject(doc, "next", buf);
	} else {
		cJSON_AddNullToObject(doc, "next_cursor");
		cJSON_AddNullToObject(doc, "next");
	}
	return send_tree(c, 200, doc, NULL, NULL);
}

static enum MHD_Result job_error(struct MHD_Connection *c, int rc, const prsm_error *err)
{
	return send_problem(c, (unsigned)prsm_error_http_status(rc), "", rc == PRSM_ENOTFOUND ? "not_found" : NULL, NULL,
	                    NULL, "%s", err->message[0] ? err->message : prsm_error_name(rc));
}

static enum MHD_Result on_job(prsm_http *h, struct MHD_Connection *c, request *r, int cancel)
{
	prsm_job_view v;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = cancel ? prsm_jobs_cancel(h->jobs, &v, r->rt.job_kind, r->rt.arg, &err)
	                : prsm_jobs_get(h->jobs, &v, r->rt.job_kind, r->rt.arg, PRSM_STORE_WITH_RESULT, &err);
	if (rc) {
		if (rc != PRSM_ENOTFOUND)
			prsm_job_view_clear(&v);
		return job_error(c, rc, &err);
	}
	enum MHD_Result ret = send_view(c, 200, &v, NULL, NULL);
	prsm_job_view_clear(&v);
	return ret;
}

static enum MHD_Result on_samples(prsm_http *h, struct MHD_Connection *c, request *r)
{
	char *csv;
	size_t len;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_jobs_csv(h->jobs, &csv, &len, r->rt.job_kind, r->rt.arg, &err);
	if (rc)
		return job_error(c, rc, &err);
	return send_response(c, 200, "text/csv; charset=utf-8", csv, len, MHD_RESPMEM_MUST_FREE, NULL, NULL);
}

static const char *content_type_of(const char *path)
{
	static const struct {
		const char *ext, *type;
	} types[] = {
		{".html", "text/html; charset=utf-8"}, {".css", "text/css; charset=utf-8"},
		{".js", "text/javascript; charset=utf-8"}, {".mjs", "text/javascript; charset=utf-8"},
		{".json", "application/json"}, {".svg", "image/svg+xml"}, {".png", "image/png"},
		{".ico", "image/x-icon"}, {".txt", "text/plain; charset=utf-8"}, {".woff2", "font/woff2"},
	};
	const char *dot = strrchr(path, '.');
	if (dot)
		for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
			if (strcasecmp(dot, types[i].ext) == 0)
				return types[i].type;
	return "application/octet-stream";
}

/* A file of web/: each segment of plain characters, none hidden or "..", and its real path
 * inside the real web root (a symbolic link out of it is refused too). */
static enum MHD_Result on_static(prsm_http *h, struct MHD_Connection *c, const char *url)
{
	if (!h->web_root[0] || url[0] != '/')
		return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
	char rel[PATH_MAX];
	int n = snprintf(rel, sizeof rel, "%s%s", url + 1,
	                 url[strlen(url) - 1] == '/' ? "index.html" : "");
	if (n < 0 || (size_t)n >= sizeof rel)
		return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
	for (const char *seg = rel; *seg;) {
		const char *e = strchr(seg, '/');
		size_t len = e ? (size_t)(e - seg) : strlen(seg);
		if (len == 0 || seg[0] == '.')
			return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
		for (size_t i = 0; i < len; i++) {
			char ch = seg[i];
			if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
			      ch == '-' || ch == '_'))
				return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
		}
		if (!e)
			break;
		seg = e + 1;
	}
	char path[PATH_MAX * 2], real[PATH_MAX];
	snprintf(path, sizeof path, "%s/%s", h->web_root, rel);
	size_t rootlen = strlen(h->web_root);
	if (!realpath(path, real) || strncmp(real, h->web_root, rootlen) != 0 || real[rootlen] != '/')
		return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
	int fd = open(real, O_RDONLY | O_CLOEXEC);
	if (fd < 0)
		return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
	struct stat st;
	if (fstat(fd, &st) || !S_ISREG(st.st_mode)) {
		close(fd);
		return send_problem(c, 404, "", "not_found", NULL, NULL, "no such file");
	}
	struct MHD_Response *resp = prsm_mhd.create_response_from_fd((uint64_t)st.st_size, fd); /* takes fd */
	if (!resp) {
		close(fd);
		return MHD_NO;
	}
	prsm_mhd.add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, content_type_of(real));
	prsm_mhd.add_response_header(resp, "X-Content-Type-Options", "nosniff");
	enum MHD_Result ok = prsm_mhd.queue_response(c, 200, resp);
	prsm_mhd.destroy_response(resp);
	return ok;
}

static enum MHD_Result dispatch(prsm_http *h, struct MHD_Connection *c, const char *url, const char *method,
                                request *r)
{
	response_mark = prsm_json_alloc_failures();
	if (r->too_large)
		return send_problem(c, 413, "", "too_large", "Connection", "close",
		                    "the body is over %zu bytes, the most this service takes", h->o.max_body_bytes);
	if (r->over_budget)
		return send_problem(c, 503, "", "busy", "Retry-After", "1",
		                    "too many request bodies are being received at once; try again");
	int post = strcmp(method, "POST") == 0;
	switch (r->rt.kind) {
	case R_HEALTH: return on_health(h, c);
	case R_VERSION: return on_doc(c, &h->version);
	case R_OPENAPI: return on_doc(c, &h->openapi);
	case R_SCHEMA: return on_schema(h, c, r->rt.arg);
	case R_ANALYZE: return on_analyze(h, c, r);
	case R_VALIDATE: return on_validate(h, c, r);
	case R_COLLECTION: return post ? on_submit(h, c, r) : on_list(h, c, r);
	case R_JOB: return on_job(h, c, r, strcmp(method, "DELETE") == 0);
	case R_SAMPLES: return on_samples(h, c, r);
	case R_STATIC: return on_static(h, c, url);
	case R_NONE: break;
	}
	return send_problem(c, 404, "", "not_found", NULL, NULL, "no such resource");
}

static enum MHD_Result handle(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                              const char *version, const char *upload_data, size_t *upload_data_size,
                              void **con_cls)
{
	(void)version;
	prsm_http *h = cls;
	request *r = *con_cls;
	if (!r) {
		r = calloc(1, sizeof *r); /* owned by the connection until request_completed */
		if (!r)
			return MHD_NO;
		*con_cls = r;
		enum MHD_Result ret = MHD_YES;
		if (precheck(h, c, url, method, r, &ret)) {
			r->answered = 1;
			return ret;
		}
		return MHD_YES;
	}
	if (r->answered) {
		*upload_data_size = 0;
		return MHD_YES;
	}
	if (*upload_data_size) {
		int rc = collect(h, r, upload_data, *upload_data_size);
		*upload_data_size = 0;
		return rc ? MHD_NO : MHD_YES;
	}
	r->answered = 1;
	return dispatch(h, c, url, method, r);
}

static void request_completed(void *cls, struct MHD_Connection *c, void **con_cls,
                              enum MHD_RequestTerminationCode toe)
{
	(void)c;
	(void)toe;
	prsm_http *h = cls;
	request *r = *con_cls;
	if (!r)
		return;
	if (r->cap)
		atomic_fetch_sub(&h->body_bytes, r->cap);
	free(r->body);
	free(r);
	*con_cls = NULL;
}

/* ---- start and stop ------------------------------------------------------------------------- */

static int load_doc(loaded_doc *d, const char *name, const char *path, prsm_error *err)
{
	snprintf(d->name, sizeof d->name, "%s", name);
	return prsm_file_read(&d->text, &d->len, path, DOC_MAX_BYTES, err);
}

static int load_schemas(prsm_http *h, prsm_error *err)
{
	char dir[PATH_MAX];
	snprintf(dir, sizeof dir, "%s/schemas", h->o.data_dir);
	DIR *dp = opendir(dir);
	if (!dp)
		return prsm_error_set(err, PRSM_EIO, NULL, "cannot open %s (--data-dir names the directory that holds "
		                                           "schemas/, api/ and web/)", dir);
	struct dirent *e;
	int rc = 0;
	while (!rc && (e = readdir(dp))) {
		size_t n = strlen(e->d_name);
		if (n < 6 || n >= SCHEMA_NAME_MAX || strcmp(e->d_name + n - 5, ".json") != 0 || e->d_name[0] == '.')
			continue;
		if (h->n_schemas == MAX_SCHEMAS) {
			rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "more than %d schemas in %s", MAX_SCHEMAS, dir);
			break;
		}
		char path[PATH_MAX + 260];
		snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
		rc = load_doc(&h->schemas[h->n_schemas], e->d_name, path, err);
		if (!rc)
			h->n_schemas++;
	}
	closedir(dp);
	return rc;
}

/* /v1/version: the prsm version, the analysis engine and model (from an analysis of a small
 * design, so they are the code's own strings), every job kind's version, the libraries. */
static int build_version(prsm_http *h)
{
	cJSON *v = cJSON_CreateObject();
	cJSON_AddStringToObject(v, "prsm", PRSM_VERSION);
	cJSON_AddStringToObject(v, "build", prsm_engine_build());
	cJSON_AddStringToObject(v, "git_revision", prsm_git_revision());
	cJSON_AddStringToObject(v, "api", "v1");
	cJSON *an = cJSON_AddObjectToObject(v, "analysis");
	const char *design = "{\"geometry\": {\"starts\": 5, \"pitch_mm\": 2, \"roller_radius_mm\": 3.25, \"flank_angle_deg\": 45,"
	                     " \"rollers\": 10, \"engaged_threads\": 10}, \"target_axial_clearance_um\": 20}";
	cJSON *doc = cJSON_Parse(design), *res = NULL;
	prsm_problems p;
	prsm_problems_init(&p);
	const cJSON *eng = NULL;
	if (doc && prsm_app_analyze(&res, doc, &p) == 0)
		eng = cJSON_GetObjectItemCaseSensitive(res, "engine");
	const cJSON *ev = cJSON_GetObjectItemCaseSensitive(eng, "version");
	const cJSON *em = cJSON_GetObjectItemCaseSensitive(eng, "model");
	cJSON_AddStringToObject(an, "engine", cJSON_IsString(ev) ? ev->valuestring : "unknown");
	cJSON_AddStringToObject(an, "model", cJSON_IsString(em) ? em->valuestring : "unknown");
	cJSON_Delete(doc);
	cJSON_Delete(res);
	cJSON *kinds = cJSON_AddArrayToObject(v, "job_kinds");
	for (size_t i = 0; i < prsm_job_kind_count; i++) {
		const prsm_job_kind *k = prsm_job_kinds[i];
		cJSON *o = cJSON_CreateObject();
		cJSON_AddStringToObject(o, "kind", k->name);
		cJSON_AddStringToObject(o, "collection", k->collection);
		cJSON_AddStringToObject(o, "version", k->version());
		cJSON_AddStringToObject(o, "request_schema", k->request_schema);
		cJSON_AddStringToObject(o, "result_schema", k->result_schema);
		cJSON_AddItemToArray(kinds, o);
	}
	cJSON *lib = cJSON_AddObjectToObject(v, "libraries");
	char buf[32];
	cJSON_AddStringToObject(lib, "libmicrohttpd", prsm_mhd.get_version());
	cJSON_AddStringToObject(lib, "sqlite", sqlite3_libversion());
	cJSON_AddStringToObject(lib, "cjson", cJSON_Version());
	cJSON_AddStringToObject(lib, "gsl", gsl_version);
	snprintf(buf, sizeof buf, "%d.%d", nettle_version_major(), nettle_version_minor());
	cJSON_AddStringToObject(lib, "nettle", buf);
	h->version.text = cJSON_PrintUnformatted(v); /* owned by the server */
	cJSON_Delete(v);
	if (!h->version.text)
		return PRSM_ENOMEM;
	h->version.len = strlen(h->version.text);
	return 0;
}

static void free_docs(prsm_http *h)
{
	for (size_t i = 0; i < h->n_schemas; i++)
		free(h->schemas[i].text);
	free(h->openapi.text);
	free(h->version.text);
}

int prsm_http_start(prsm_http **out, const prsm_http_options *o, prsm_jobs *jobs, prsm_error *err)
{
	*out = NULL;
	int rc = prsm_mhd_load(err);
	if (rc)
		return rc;
	prsm_http *h = calloc(1, sizeof *h); /* handed to the caller */
	if (!h)
		return prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	h->o = *o;
	h->jobs = jobs;
	h->started_s = prsm_clock_seconds();
	atomic_init(&h->body_bytes, 0);
	if (o->token)
		snprintf(h->token, sizeof h->token, "%s", o->token);
	rc = load_schemas(h, err);
	if (!rc) {
		char path[PATH_MAX];
		snprintf(path, sizeof path, "%s/api/openapi.json", o->data_dir);
		rc = load_doc(&h->openapi, "openapi.json", path, err);
	}
	if (!rc && build_version(h))
		rc = prsm_error_set(err, PRSM_ENOMEM, NULL, "out of memory");
	if (rc)
		goto fail;
	char web[PATH_MAX];
	snprintf(web, sizeof web, "%s/web", o->data_dir);
	if (!realpath(web, h->web_root))
		h->web_root[0] = '\0';

	struct sockaddr_storage addr;
	memset(&addr, 0, sizeof addr);
	unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | MHD_USE_ITC;
	struct sockaddr_in *a4 = (struct sockaddr_in *)&addr;
	struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)&addr;
	if (inet_pton(AF_INET, o->host, &a4->sin_addr) == 1) {
		a4->sin_family = AF_INET;
		a4->sin_port = htons((uint16_t)o->port);
	} else if (inet_pton(AF_INET6, o->host, &a6->sin6_addr) == 1) {
		a6->sin6_family = AF_INET6;
		a6->sin6_port = htons((uint16_t)o->port);
		flags |= MHD_USE_IPv6;
	} else {
		rc = prsm_error_set(err, PRSM_EINVAL, NULL, "--host %s: give a numeric IPv4 or IPv6 address", o->host);
		goto fail;
	}
	h->d = prsm_mhd.start_daemon(flags, (uint16_t)o->port, NULL, NULL, handle, h,
	                        MHD_OPTION_NOTIFY_COMPLETED, request_completed, h,
	                        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
	                        MHD_OPTION_THREAD_POOL_SIZE, (unsigned)(o->threads > 1 ? o->threads : 1),
	                        MHD_OPTION_CONNECTION_TIMEOUT, o->timeout_s,
	                        MHD_OPTION_CONNECTION_MEMORY_LIMIT, o->connection_memory_bytes,
	                        MHD_OPTION_CONNECTION_LIMIT, o->max_connections,
	                        MHD_OPTION_END);
	if (!h->d) {
		rc = prsm_error_set(err, PRSM_EIO, NULL, "cannot listen on %s port %d (in use, or not an address of this machine)",
		                    o->host, o->port);
		goto fail;
	}
	const union MHD_DaemonInfo *info = prsm_mhd.get_daemon_info(h->d, MHD_DAEMON_INFO_BIND_PORT);
	h->port = info ? info->port : o->port;
	*out = h;
	return 0;
fail:
	free_docs(h);
	free(h);
	return rc;
}

int prsm_http_port(const prsm_http *h)
{
	return h->port;
}

void prsm_http_quiesce(prsm_http *h)
{
	if (h && h->d) {
		MHD_socket s = prsm_mhd.quiesce_daemon(h->d);
		if (s != MHD_INVALID_SOCKET)
			close(s);
	}
}

void prsm_http_stop(prsm_http *h)
{
	if (!h)
		return;
	if (h->d)
		prsm_mhd.stop_daemon(h->d);
	free_docs(h);
	free(h);
}
