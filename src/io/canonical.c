/*
 * canonical.c: RFC 8785 canonical JSON from a cJSON tree (see canonical.h).
 *
 * The writer is a bounded growable buffer (a maximum set by the caller; past it the call fails
 * rather than growing without end). Members are sorted with an index array per object; the
 * recursion depth is the tree's own, which cJSON's parser already caps (CJSON_NESTING_LIMIT).
 *
 * Numbers are util/dtoa's ECMAScript form; UTF-8 is checked and member pointers are built with
 * io/json_util's helpers, so the parser and the canonicaliser agree on both.
 */
#include "io/canonical.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/json_util.h"
#include "util/dtoa.h"

_Static_assert(PRSM_CANONICAL_NUMBER_MAX >= PRSM_DTOA_TEXT_MAX, "room for any number");

typedef struct {
	char *data;     /* owned until handed to the caller */
	size_t len, cap, max;
	int failed;
} cbuf;

static int cbuf_reserve(cbuf *b, size_t more)
{
	if (b->failed)
		return -1;
	if (more > b->max || b->len > b->max - more) {
		b->failed = 1;
		return -1;
	}
	size_t need = b->len + more + 1;
	if (need <= b->cap)
		return 0;
	size_t cap = b->cap ? b->cap : 256;
	while (cap < need)
		cap = cap > SIZE_MAX / 2 ? need : cap * 2;
	if (cap > b->max + 1)
		cap = b->max + 1;
	char *p = realloc(b->data, cap);
	if (!p) {
		b->failed = 1;
		return -1;
	}
	b->data = p;
	b->cap = cap;
	return 0;
}

static void cbuf_put(cbuf *b, const char *s, size_t n)
{
	if (cbuf_reserve(b, n))
		return;
	memcpy(b->data + b->len, s, n);
	b->len += n;
	b->data[b->len] = '\0';
}

static void cbuf_putc(cbuf *b, char c)
{
	cbuf_put(b, &c, 1);
}

/* UTF-16 code units of a (valid) UTF-8 string, one at a time. */
typedef struct {
	const unsigned char *p;
	unsigned low; /* pending low surrogate, 0 when none */
} u16_iter;

static long u16_next(u16_iter *it)
{
	if (it->low) {
		long u = it->low;
		it->low = 0;
		return u;
	}
	unsigned c = *it->p;
	if (!c)
		return -1;
	uint32_t cp;
	int k;
	if (c < 0x80)
		cp = c, k = 0;
	else if ((c & 0xE0) == 0xC0)
		cp = c & 0x1F, k = 1;
	else if ((c & 0xF0) == 0xE0)
		cp = c & 0x0F, k = 2;
	else
		cp = c & 0x07, k = 3;
	it->p++;
	for (int j = 0; j < k && *it->p; j++, it->p++)
		cp = (cp << 6) | (*it->p & 0x3F);
	if (cp >= 0x10000) {
		cp -= 0x10000;
		it->low = 0xDC00 + (cp & 0x3FF);
		return 0xD800 + (long)(cp >> 10);
	}
	return (long)cp;
}

int prsm_canonical_key_compare(const char *a, const char *b)
{
	u16_iter x = {(const unsigned char *)a, 0}, y = {(const unsigned char *)b, 0};
	for (;;) {
		long u = u16_next(&x), v = u16_next(&y);
		if (u != v)
			return u < v ? -1 : 1;
		if (u < 0)
			return 0;
	}
}

int prsm_canonical_number(char buf[PRSM_CANONICAL_NUMBER_MAX], double v)
{
	return prsm_dtoa_ecmascript(buf, v) < 0 ? PRSM_EINVAL : 0;
}

static void put_string(cbuf *b, const char *s)
{
	static const char hex[] = "0123456789abcdef";
	cbuf_putc(b, '"');
	const char *run = s;
	for (const char *p = s; *p; p++) {
		unsigned char c = (unsigned char)*p;
		const char *esc = NULL;
		char u[6];
		switch (c) {
		case '"': esc = "\\\""; break;
		case '\\': esc = "\\\\"; break;
		case '\b': esc = "\\b"; break;
		case '\f': esc = "\\f"; break;
		case '\n': esc = "\\n"; break;
		case '\r': esc = "\\r"; break;
		case '\t': esc = "\\t"; break;
		default:
			if (c < 0x20) {
				u[0] = '\\', u[1] = 'u', u[2] = '0', u[3] = '0', u[4] = hex[c >> 4], u[5] = hex[c & 15];
			}
			break;
		}
		if (!esc && c >= 0x20)
			continue;
		cbuf_put(b, run, (size_t)(p - run));
		if (esc)
			cbuf_put(b, esc, strlen(esc));
		else
			cbuf_put(b, u, sizeof u);
		run = p + 1;
	}
	cbuf_put(b, run, strlen(run));
	cbuf_putc(b, '"');
}

static int utf8_ok(const char *s)
{
	size_t n = strlen(s);
	return prsm_json_utf8_invalid_at(s, n) == n;
}

/* Append "/token" (RFC 6901) to the pointer ptr in place. Returns the buffer size the value's
 * own descendants may use: all of it, or nothing past the current text when the token did not
 * fit (ptr then still names the parent, and deeper tokens are not appended to it, so an error
 * names the deepest ancestor that fits rather than a wrong path). */
static size_t pointer_push(char *ptr, size_t size, const char *token)
{
	return prsm_json_pointer_append(ptr, size, ptr, token) == 0 ? size : strlen(ptr) + 1;
}

static int key_cmp(const void *a, const void *b)
{
	const cJSON *x = *(const cJSON *const *)a, *y = *(const cJSON *const *)b;
	return prsm_canonical_key_compare(x->string, y->string);
}

static int write_value(cbuf *b, const cJSON *v, char *ptr, size_t ptr_size, prsm_error *err)
{
	size_t mark = strlen(ptr);
	int rc = 0;
	switch (v->type & 0xFF) {
	case cJSON_NULL: cbuf_put(b, "null", 4); break;
	case cJSON_False: cbuf_put(b, "false", 5); break;
	case cJSON_True: cbuf_put(b, "true", 4); break;
	case cJSON_Number: {
		char num[PRSM_CANONICAL_NUMBER_MAX];
		if (prsm_canonical_number(num, v->valuedouble))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "a number that is not finite");
		cbuf_put(b, num, strlen(num));
		break;
	}
	case cJSON_String:
		if (!v->valuestring || !utf8_ok(v->valuestring))
			return prsm_error_set(err, PRSM_EINVAL, ptr, "a string that is not valid UTF-8");
		put_string(b, v->valuestring);
		break;
	case cJSON_Array: {
		cbuf_putc(b, '[');
		size_t i = 0;
		for (const cJSON *c = v->child; c; c = c->next, i++) {
			if (i)
				cbuf_putc(b, ',');
			char idx[24];
			snprintf(idx, sizeof idx, "%zu", i);
			rc = write_value(b, c, ptr, pointer_push(ptr, ptr_size, idx), err);
			ptr[mark] = '\0';
			if (rc)
				return rc;
		}
		cbuf_putc(b, ']');
		break;
	}
	case cJSON_Object: {
		size_t n = 0;
		for (const cJSON *c = v->child; c; c = c->next)
			n++;
		/* the member order, owned here */
		const cJSON **m = n ? malloc(n * sizeof *m) : NULL;
		if (n && !m)
			return prsm_error_set(err, PRSM_ENOMEM, ptr, "out of memory");
		size_t i = 0;
		for (const cJSON *c = v->child; c; c = c->next) {
			if (!c->string || !utf8_ok(c->string)) {
				free(m);
				return prsm_error_set(err, PRSM_EINVAL, ptr, "a member name that is not valid UTF-8");
			}
			m[i++] = c;
		}
		if (n > 1)
			qsort(m, n, sizeof *m, key_cmp);
		cbuf_putc(b, '{');
		for (i = 0; i < n && !rc; i++) {
			size_t child_size = pointer_push(ptr, ptr_size, m[i]->string);
			if (i && strcmp(m[i]->string, m[i - 1]->string) == 0) {
				rc = prsm_error_set(err, PRSM_EINVAL, ptr, "member \"%.64s\" appears more than once",
				                    m[i]->string);
			} else {
				if (i)
					cbuf_putc(b, ',');
				put_string(b, m[i]->string);
				cbuf_putc(b, ':');
				rc = write_value(b, m[i], ptr, child_size, err);
			}
			ptr[mark] = '\0';
		}
		free(m);
		if (rc)
			return rc;
		cbuf_putc(b, '}');
		break;
	}
	default:
		return prsm_error_set(err, PRSM_EINVAL, ptr, "not a JSON value");
	}
	if (b->failed)
		return prsm_error_set(err, PRSM_ENOMEM, "", "the canonical text exceeds its size limit");
	return 0;
}

int prsm_canonical_json(char **out, size_t *len, const cJSON *tree, size_t max_bytes,
                        prsm_error *err)
{
	*out = NULL;
	if (len)
		*len = 0;
	cbuf b = {NULL, 0, 0, max_bytes, 0};
	char ptr[PRSM_ERROR_POINTER_MAX] = "";
	int rc = tree ? write_value(&b, tree, ptr, sizeof ptr, err)
	              : prsm_error_set(err, PRSM_EINVAL, "", "no document");
	if (!rc && (b.failed || !b.data))
		rc = prsm_error_set(err, PRSM_ENOMEM, "", "the canonical text exceeds its size limit");
	if (rc) {
		free(b.data);
		return rc;
	}
	*out = b.data;
	if (len)
		*len = b.len;
	return 0;
}
