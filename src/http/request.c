/*
 * request.c: framing, media type, token and body checks of a request (see request.h).
 */
#include "http/request.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "io/canonical.h"
#include "io/json_util.h"

int prsm_http_check_framing(int content_length_headers, const char *content_length,
                            int transfer_encoding_headers, prsm_problems *problems)
{
	if (content_length_headers > 1) {
		prsm_problems_add(problems, "", "framing", "more than one Content-Length header");
		return 400;
	}
	if (content_length_headers && transfer_encoding_headers) {
		prsm_problems_add(problems, "", "framing", "Content-Length together with Transfer-Encoding");
		return 400;
	}
	if (content_length_headers && content_length) {
		const char *p = content_length;
		if (!*p) {
			prsm_problems_add(problems, "", "framing", "an empty Content-Length");
			return 400;
		}
		for (; *p; p++)
			if (!isdigit((unsigned char)*p)) {
				prsm_problems_add(problems, "", "framing", "a Content-Length that is not a decimal number");
				return 400;
			}
	}
	return 0;
}

int prsm_http_is_json_type(const char *content_type)
{
	if (!content_type)
		return 0;
	const char *p = content_type;
	while (*p == ' ' || *p == '\t')
		p++;
	static const char want[] = "application/json";
	if (strncasecmp(p, want, sizeof want - 1) != 0)
		return 0;
	p += sizeof want - 1;
	while (*p == ' ' || *p == '\t')
		p++;
	if (!*p)
		return 1;
	if (*p != ';')
		return 0;
	/* parameters: only a charset, and only utf-8 */
	const char *cs = NULL;
	for (const char *q = p; *q; q++)
		if (strncasecmp(q, "charset", 7) == 0) {
			cs = q + 7;
			break;
		}
	if (!cs)
		return 1;
	while (*cs == ' ' || *cs == '=' || *cs == '"')
		cs++;
	return strncasecmp(cs, "utf-8", 5) == 0 || strncasecmp(cs, "utf8", 4) == 0;
}

int prsm_http_bearer_ok(const char *authorization, const char *token)
{
	if (!authorization || !token)
		return 0;
	if (strncasecmp(authorization, "Bearer ", 7) != 0)
		return 0;
	const char *given = authorization + 7;
	while (*given == ' ')
		given++;
	size_t n = strlen(given), m = strlen(token);
	unsigned diff = (unsigned)(n ^ m);
	for (size_t i = 0; i < m; i++)
		diff |= (unsigned)(unsigned char)token[i] ^ (unsigned)(unsigned char)(i < n ? given[i] : 0);
	return diff == 0;
}

int prsm_http_parse_body(cJSON **out, const char *body, size_t len, prsm_problems *problems)
{
	*out = NULL;
	if (len == 0) {
		prsm_problems_add(problems, "", "empty", "the request has no body: send a JSON document");
		return 400;
	}
	cJSON *doc = prsm_json_parse(body, len, problems);
	if (!doc)
		return 400;
	if (!cJSON_IsObject(doc)) {
		prsm_problems_add(problems, "", "type", "the document is %s: it must be an object", prsm_json_type_name(doc));
		cJSON_Delete(doc);
		return 422;
	}
	/* duplicate member names anywhere, numbers out of range: the canonical writer finds them
	 * (I-JSON) */
	char *canon = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	int rc = prsm_canonical_json(&canon, NULL, doc, len * 8 + 64, &err);
	free(canon);
	if (rc == PRSM_EINVAL) {
		prsm_problems_add(problems, err.pointer, "json", "%s", err.message);
		cJSON_Delete(doc);
		return 400;
	}
	*out = doc;
	return 0;
}
