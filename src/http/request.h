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

#endif
