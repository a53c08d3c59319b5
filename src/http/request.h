/*
 * request.h: the service's request parser, kept apart from the sockets so it can be fuzzed
 * (tests/fuzz): the checks of a request's framing headers, its media type, its bearer token,
 * and its body from bytes to a JSON tree with every problem and its JSON pointer.
 */
#ifndef PRSM_HTTP_REQUEST_H
#define PRSM_HTTP_REQUEST_H

#include <stddef.h>

#include <cJSON.h>

#include "util/problems.h"

/* Framing: how the request said its body's length. Refused (400): more than one
 * Content-Length, a Content-Length together with Transfer-Encoding (RFC 9112 §6.3: request
 * smuggling), a Content-Length that is not a plain decimal. Returns 0 or the status with one
 * problem added. */
int prsm_http_check_framing(int content_length_headers, const char *content_length,
                            int transfer_encoding_headers, prsm_problems *problems);

/* 1 when the Content-Type is application/json (any case, parameters allowed; charset, when
 * given, utf-8), else 0. NULL is 0. */
int prsm_http_is_json_type(const char *content_type);

/* 1 when the Authorization header is "Bearer <token>" (constant time in the token). */
int prsm_http_bearer_ok(const char *authorization, const char *token);

/* The body as a JSON object: valid UTF-8, well-formed JSON (prsm_json_parse's strict
 * grammar and depth limit), no duplicate member names, an object at the top. Returns 0 with
 * *out (owned by the caller: cJSON_Delete), or the HTTP status (400 malformed, 422 a
 * well-formed document that is not an object) with every problem found. */
int prsm_http_parse_body(cJSON **out, const char *body, size_t len, prsm_problems *problems);

/* ---- multipart/form-data (RFC 7578): a calibration's request and its bench file in one POST --- */

/* Longest boundary RFC 2046 allows. */
#define PRSM_HTTP_BOUNDARY_MAX 70

/* The boundary of a multipart/form-data Content-Type into boundary (cap >= PRSM_HTTP_BOUNDARY_MAX
 * + 1; quoted or not). Returns 1 when the type is multipart/form-data with a valid boundary,
 * 0 when it is another type (or NULL), -1 when it is multipart/form-data without a usable
 * boundary. */
int prsm_http_multipart_boundary(const char *content_type, char *boundary, size_t cap);

/* One part of a form: its name (Content-Disposition: form-data; name="..."), the file name
 * when one was sent, and its content (pointing into the body). */
typedef struct {
	char name[64];
	char filename[128];
	const char *data;
	size_t len;
} prsm_http_part;

/* Split body (len bytes) at boundary into at most max parts. Every malformation (no first
 * delimiter, a part without a blank line after its headers, a part without a form-data name,
 * no closing delimiter, more than max parts) is one problem at pointer "". Returns 0 with *n
 * parts, or 400. */
int prsm_http_multipart_parse(prsm_http_part *parts, int max, int *n, const char *body, size_t len,
                              const char *boundary, prsm_problems *problems);

/* A calibration sent as a form (docs/service.md): the part "request" is the calibration request
 * as JSON (as prsm_http_parse_body reads it), the part "measured" the bench's TE curve as CSV
 * text (UTF-8, no NUL byte), which becomes the request's measured.te_csv; no other part. Returns
 * 0 with *out (the caller's: cJSON_Delete), or the HTTP status (400: a malformed form or JSON,
 * 422: a well-formed request whose measured section cannot take the file) with every problem. */
int prsm_http_calibration_form(cJSON **out, const char *body, size_t len, const char *boundary,
                               prsm_problems *problems);

#endif
