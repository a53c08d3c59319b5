/*
 * request.c: framing, media type, token and body checks of a request (see request.h).
 */
#include "http/request.h"

#include <ctype.h>
#include <stdio.h>
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

/* ---- multipart/form-data ------------------------------------------------------------------- */

/* RFC 2046 §5.1.1: bchars := DIGIT / ALPHA / "'" / "(" / ")" / "+" / "_" / "," / "-" / "." / "/" /
 * ":" / "=" / "?" / " ", the last not a space. */
static int boundary_char(int c)
{
	return isalnum(c) || (c && strchr("'()+_,-./:=? ", c) != NULL);
}

int prsm_http_multipart_boundary(const char *content_type, char *boundary, size_t cap)
{
	if (!content_type)
		return 0;
	const char *p = content_type;
	while (*p == ' ' || *p == '\t')
		p++;
	static const char want[] = "multipart/form-data";
	if (strncasecmp(p, want, sizeof want - 1) != 0)
		return 0;
	p += sizeof want - 1;
	if (*p && *p != ';' && *p != ' ' && *p != '\t')
		return 0;
	/* the parameters: find boundary= */
	while (*p) {
		while (*p == ';' || *p == ' ' || *p == '\t')
			p++;
		if (strncasecmp(p, "boundary=", 9) == 0) {
			p += 9;
			size_t n = 0;
			const int quoted = *p == '"';
			if (quoted)
				p++;
			while (p[n] && (quoted ? p[n] != '"' : p[n] != ';' && p[n] != ' ' && p[n] != '\t'))
				n++;
			if (quoted && p[n] != '"')
				return -1;
			if (n == 0 || n > PRSM_HTTP_BOUNDARY_MAX || n + 1 > cap || p[n - 1] == ' ')
				return -1;
			for (size_t i = 0; i < n; i++)
				if (!boundary_char((unsigned char)p[i]))
					return -1;
			memcpy(boundary, p, n);
			boundary[n] = '\0';
			return 1;
		}
		while (*p && *p != ';')
			p++;
	}
	return -1;
}

/* First occurrence of needle (m bytes) in hay (n bytes) at or after from, or n. */
static size_t find(const char *hay, size_t n, size_t from, const char *needle, size_t m)
{
	if (m == 0 || n < m)
		return n;
	for (size_t i = from; i + m <= n; i++)
		if (hay[i] == needle[0] && memcmp(hay + i, needle, m) == 0)
			return i;
	return n;
}

/* The next delimiter line at or after from: "\r\n--boundary" (m bytes) followed by "--" (the
 * close) or by optional white space and CRLF (RFC 2046 §5.1.1); a line that only starts with it
 * is content. Its offset, or n. */
static size_t find_delimiter(const char *body, size_t n, size_t from, const char *delim, size_t m)
{
	for (size_t at = find(body, n, from, delim, m); at < n; at = find(body, n, at + 1, delim, m)) {
		size_t j = at + m;
		if (j + 2 <= n && body[j] == '-' && body[j + 1] == '-')
			return at;
		while (j < n && (body[j] == ' ' || body[j] == '\t'))
			j++;
		if (j + 2 <= n && body[j] == '\r' && body[j + 1] == '\n')
			return at;
	}
	return n;
}

/* The value of parameter key (e.g. name) of a Content-Disposition header value v (len bytes)
 * into out; 1 found, 0 not, -1 too long. */
static int disposition_param(const char *v, size_t len, const char *key, char *out, size_t cap)
{
	const size_t kl = strlen(key);
	for (size_t i = 0; i + kl + 1 < len; i++) {
		if (v[i] != ';')
			continue;
		size_t j = i + 1;
		while (j < len && (v[j] == ' ' || v[j] == '\t'))
			j++;
		if (j + kl + 1 > len || strncasecmp(v + j, key, kl) != 0 || v[j + kl] != '=')
			continue;
		j += kl + 1;
		size_t k = 0;
		if (j < len && v[j] == '"') {
			j++;
			while (j < len && v[j] != '"') {
				if (v[j] == '\\' && j + 1 < len)
					j++;
				if (k + 1 >= cap)
					return -1;
				out[k++] = v[j++];
			}
		} else {
			while (j < len && v[j] != ';' && v[j] != ' ' && v[j] != '\t') {
				if (k + 1 >= cap)
					return -1;
				out[k++] = v[j++];
			}
		}
		out[k] = '\0';
		return 1;
	}
	return 0;
}

int prsm_http_multipart_parse(prsm_http_part *parts, int max, int *n, const char *body, size_t len,
                              const char *boundary, prsm_problems *problems)
{
	*n = 0;
	char delim[PRSM_HTTP_BOUNDARY_MAX + 5]; /* "\r\n--" boundary */
	const int dl = snprintf(delim, sizeof delim, "\r\n--%s", boundary);
	if (dl < 5 || (size_t)dl >= sizeof delim) {
		prsm_problems_add(problems, "", "multipart", "the form's boundary is empty or longer than %d characters",
		                  PRSM_HTTP_BOUNDARY_MAX);
		return 400;
	}
	const size_t m = (size_t)dl;
	/* the first delimiter: at the very start (without its CRLF) or after a preamble */
	size_t pos;
	if (len >= m - 2 && memcmp(body, delim + 2, m - 2) == 0) {
		pos = m - 2;
	} else {
		pos = find_delimiter(body, len, 0, delim, m);
		if (pos == len) {
			prsm_problems_add(problems, "", "multipart", "the body has no \"--%s\" line: not the form its "
			                  "Content-Type says", boundary);
			return 400;
		}
		pos += m;
	}
	for (;;) {
		/* after a delimiter: "--" ends the form; else optional white space and CRLF */
		if (pos + 2 <= len && body[pos] == '-' && body[pos + 1] == '-')
			return 0;
		while (pos < len && (body[pos] == ' ' || body[pos] == '\t'))
			pos++;
		if (pos + 2 > len || body[pos] != '\r' || body[pos + 1] != '\n') {
			prsm_problems_add(problems, "", "multipart", "part %d: the boundary line does not end with CRLF (or the "
			                  "form has no closing \"--%s--\")", *n + 1, boundary);
			return 400;
		}
		pos += 2;
		const size_t next = find_delimiter(body, len, pos, delim, m); /* this part's end, at the latest */
		const size_t head_end = find(body, next, pos, "\r\n\r\n", 4);
		size_t content;
		if (pos + 2 <= len && body[pos] == '\r' && body[pos + 1] == '\n')
			content = pos + 2; /* no headers */
		else if (head_end < next)
			content = head_end + 4;
		else {
			prsm_problems_add(problems, "", "multipart", "part %d: its headers do not end with a blank line",
			                  *n + 1);
			return 400;
		}
		const size_t end = content <= next ? find_delimiter(body, len, content, delim, m) : len;
		if (end == len) {
			prsm_problems_add(problems, "", "multipart", "part %d: no closing \"--%s--\" after it", *n + 1,
			                  boundary);
			return 400;
		}
		if (*n == max) {
			prsm_problems_add(problems, "", "multipart", "more than %d parts", max);
			return 400;
		}
		prsm_http_part *pt = &parts[*n];
		memset(pt, 0, sizeof *pt);
		/* the headers: Content-Disposition names the part */
		int named = 0;
		for (size_t h = pos; h + 2 <= content - 2;) {
			size_t eol = find(body, content - 2, h, "\r\n", 2);
			const char *line = body + h;
			const size_t ll = eol - h;
			static const char cd[] = "content-disposition:";
			if (ll > sizeof cd - 1 && strncasecmp(line, cd, sizeof cd - 1) == 0) {
				const char *v = line + sizeof cd - 1;
				size_t vl = ll - (sizeof cd - 1);
				while (vl && (*v == ' ' || *v == '\t'))
					v++, vl--;
				if (vl < 9 || strncasecmp(v, "form-data", 9) != 0) {
					prsm_problems_add(problems, "", "multipart", "part %d: Content-Disposition is not form-data",
					                  *n + 1);
					return 400;
				}
				const int rn = disposition_param(v, vl, "name", pt->name, sizeof pt->name);
				if (rn < 0) {
					prsm_problems_add(problems, "", "multipart", "part %d: its name is longer than %zu bytes",
					                  *n + 1, sizeof pt->name - 1);
					return 400;
				}
				named = rn == 1;
				if (disposition_param(v, vl, "filename", pt->filename, sizeof pt->filename) < 0)
					pt->filename[0] = '\0'; /* a long file name is only a label: dropped */
			}
			h = eol + 2;
		}
		if (!named) {
			prsm_problems_add(problems, "", "multipart", "part %d has no Content-Disposition: form-data; name=\"...\"",
			                  *n + 1);
			return 400;
		}
		pt->data = body + content;
		pt->len = end - content;
		(*n)++;
		pos = end + m;
	}
}

int prsm_http_calibration_form(cJSON **out, const char *body, size_t len, const char *boundary,
                               prsm_problems *problems)
{
	*out = NULL;
	enum { MAX_PARTS = 8 };
	prsm_http_part parts[MAX_PARTS];
	int n = 0;
	int status = prsm_http_multipart_parse(parts, MAX_PARTS, &n, body, len, boundary, problems);
	if (status)
		return status;
	const prsm_http_part *rq = NULL, *csv = NULL;
	for (int i = 0; i < n; i++) {
		const prsm_http_part *p = &parts[i];
		const prsm_http_part **slot = strcmp(p->name, "request") == 0 ? &rq : strcmp(p->name, "measured") == 0 ? &csv : NULL;
		if (!slot) {
			char name[64];
			prsm_json_excerpt(name, sizeof name, p->name);
			prsm_problems_add(problems, "", "multipart", "part \"%s\": a calibration form has the parts \"request\" "
			                  "(the JSON request) and \"measured\" (the TE curve as CSV)", name);
			status = 400;
		} else if (*slot) {
			prsm_problems_add(problems, "", "multipart", "part \"%s\" is given twice", p->name);
			status = 400;
		} else {
			*slot = p;
		}
	}
	if (!rq) {
		prsm_problems_add(problems, "", "multipart", "the form has no part \"request\": the calibration request as "
		                  "JSON (design, dynamics.analysis \"calibrate\", ...)");
		status = 400;
	}
	if (!csv) {
		prsm_problems_add(problems, "", "multipart", "the form has no part \"measured\": the bench's TE curve as "
		                  "CSV (columns screw_angle_rad or travel_mm, and te_um)");
		status = 400;
	} else {
		const size_t bad = prsm_json_utf8_invalid_at(csv->data, csv->len);
		if (bad < csv->len) {
			prsm_problems_add(problems, "", "multipart", "part \"measured\": invalid UTF-8 at byte %zu", bad);
			status = 400;
		} else if (memchr(csv->data, '\0', csv->len)) {
			prsm_problems_add(problems, "", "multipart", "part \"measured\": a NUL byte in the CSV text");
			status = 400;
		}
	}
	if (status)
		return status;
	cJSON *doc = NULL;
	status = prsm_http_parse_body(&doc, rq->data, rq->len, problems);
	if (status)
		return status;
	cJSON *m = cJSON_GetObjectItemCaseSensitive(doc, "measured");
	if (m == NULL) {
		m = cJSON_AddObjectToObject(doc, "measured");
		if (m == NULL) {
			cJSON_Delete(doc);
			prsm_problems_add(problems, "", "memory", "out of memory");
			return 503;
		}
	}
	if (!cJSON_IsObject(m)) {
		prsm_problems_add(problems, "/measured", "type", "measured is %s: it must be an object to take the "
		                  "uploaded curve", prsm_json_type_name(m));
		cJSON_Delete(doc);
		return 422;
	}
	if (cJSON_GetObjectItemCaseSensitive(m, "te_csv") || cJSON_GetObjectItemCaseSensitive(m, "te")) {
		prsm_problems_add(problems, cJSON_GetObjectItemCaseSensitive(m, "te") ? "/measured/te" : "/measured/te_csv",
		                  "one_curve", "the form's part \"measured\" is the TE curve; the request must not give "
		                  "another");
		cJSON_Delete(doc);
		return 422;
	}
	char *text = malloc(csv->len + 1); /* copied into the tree, freed below */
	if (text == NULL) {
		cJSON_Delete(doc);
		prsm_problems_add(problems, "", "memory", "out of memory");
		return 503;
	}
	memcpy(text, csv->data, csv->len);
	text[csv->len] = '\0';
	cJSON *s = cJSON_AddStringToObject(m, "te_csv", text);
	free(text);
	if (s == NULL) {
		cJSON_Delete(doc);
		prsm_problems_add(problems, "", "memory", "out of memory");
		return 503;
	}
	*out = doc;
	return 0;
}
