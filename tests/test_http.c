/*
 * test_http.c: http/ — the request parser (framing, media type, bearer token, body to a JSON
 * object with its problems) and a server on a free loopback port over a temporary database
 * and data directory: health, a schema, the landing page, 404 and 405 (with Allow) as
 * problem documents, two Content-Length refused, a symbolic link out of web/ not followed, a
 * POST without a token when one is required; a calibration sent as multipart/form-data.
 */
#include "test_support.h"

#include <arpa/inet.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "http/request.h"
#include "http/server.h"

static void test_framing_and_types(void **state)
{
	(void)state;
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_http_check_framing(0, NULL, 0, &p), 0);
	assert_int_equal(prsm_http_check_framing(1, "12", 0, &p), 0);
	assert_int_equal(prsm_http_check_framing(0, NULL, 1, &p), 0);
	assert_int_equal(p.count, 0);
	assert_int_equal(prsm_http_check_framing(2, "12", 0, &p), 400);
	assert_int_equal(prsm_http_check_framing(1, "12", 1, &p), 400);
	assert_int_equal(prsm_http_check_framing(1, "1e3", 0, &p), 400);
	assert_int_equal(prsm_http_check_framing(1, "", 0, &p), 400);
	assert_int_equal(p.count, 4);
	assert_string_equal(p.items[0].code, "framing");

	assert_true(prsm_http_is_json_type("application/json"));
	assert_true(prsm_http_is_json_type("Application/JSON; charset=UTF-8"));
	assert_true(prsm_http_is_json_type("application/json;charset=\"utf-8\""));
	assert_false(prsm_http_is_json_type("application/json; charset=latin-1"));
	assert_false(prsm_http_is_json_type("application/jsonx"));
	assert_false(prsm_http_is_json_type("text/plain"));
	assert_false(prsm_http_is_json_type(NULL));

	assert_true(prsm_http_bearer_ok("Bearer abc", "abc"));
	assert_true(prsm_http_bearer_ok("bearer  abc", "abc"));
	assert_false(prsm_http_bearer_ok("Bearer abcd", "abc"));
	assert_false(prsm_http_bearer_ok("Bearer ab", "abc"));
	assert_false(prsm_http_bearer_ok("Basic abc", "abc"));
	assert_false(prsm_http_bearer_ok(NULL, "abc"));
}

static void test_parse_body(void **state)
{
	(void)state;
	static const struct {
		const char *body;
		int status;
		const char *pointer;
	} cases[] = {
		{"{\"a\": [1, 2.385, {\"b\": null}]}", 0, NULL},
		{"", 400, ""},
		{"{\"a\": ", 400, ""},
		{"{\"a\": \"\xc3\x28\"}", 400, ""},
		{"[1, 2]", 422, ""},
		{"\"text\"", 422, ""},
		{"{\"a\": {\"b\": 1, \"b\": 2}}", 400, "/a/b"},
		{"{\"a\": 1} x", 400, ""},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		prsm_problems p;
		prsm_problems_init(&p);
		cJSON *doc = NULL;
		int status = prsm_http_parse_body(&doc, cases[i].body, strlen(cases[i].body), &p);
		if (status != cases[i].status)
			fail_msg("body %zu: status %d, expected %d", i, status, cases[i].status);
		if (status == 0) {
			assert_non_null(doc);
			assert_int_equal(p.count, 0);
		} else {
			assert_null(doc);
			assert_true(p.count >= 1);
			assert_string_equal(p.items[0].pointer, cases[i].pointer);
		}
		cJSON_Delete(doc);
	}
	/* deep nesting is refused, not recursed into */
	size_t n = 20000;
	char *deep = malloc(2 * n + 1);
	memset(deep, '[', n);
	memset(deep + n, ']', n);
	deep[2 * n] = '\0';
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = NULL;
	assert_int_equal(prsm_http_parse_body(&doc, deep, 2 * n, &p), 400);
	free(deep);
}

/* ---- a live server ---- */

static char dir[64], db[96];

static void write_file(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	fclose(f);
}

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof dir, "/tmp/prsm-test-http-XXXXXX");
	if (!mkdtemp(dir))
		return -1;
	char p[160];
	snprintf(p, sizeof p, "%s/schemas", dir);
	mkdir(p, 0755);
	snprintf(p, sizeof p, "%s/api", dir);
	mkdir(p, 0755);
	snprintf(p, sizeof p, "%s/web", dir);
	mkdir(p, 0755);
	snprintf(p, sizeof p, "%s/schemas/x.schema.json", dir);
	write_file(p, "{\"$schema\": \"https://json-schema.org/draft/2020-12/schema\"}");
	snprintf(p, sizeof p, "%s/api/openapi.json", dir);
	write_file(p, "{\"openapi\": \"3.1.0\"}");
	snprintf(p, sizeof p, "%s/web/index.html", dir);
	write_file(p, "<html>landing</html>");
	snprintf(p, sizeof p, "%s/secret.txt", dir);
	write_file(p, "secret");
	char link[160];
	snprintf(link, sizeof link, "%s/web/out.txt", dir);
	if (symlink(p, link))
		return -1;
	snprintf(db, sizeof db, "%s/t.db", dir);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
	return system(cmd) == 0 ? 0 : -1;
}

/* One request over a fresh connection; the response (status line, headers, body) in out. */
static int http_raw(int port, const char *req, char *out, size_t size)
{
	int s = socket(AF_INET, SOCK_STREAM, 0);
	struct sockaddr_in a = {0};
	a.sin_family = AF_INET;
	a.sin_port = htons((uint16_t)port);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	if (connect(s, (struct sockaddr *)&a, sizeof a)) {
		close(s);
		return -1;
	}
	size_t len = strlen(req), sent = 0;
	while (sent < len) {
		ssize_t w = send(s, req + sent, len - sent, MSG_NOSIGNAL);
		if (w <= 0)
			break;
		sent += (size_t)w;
	}
	size_t got = 0;
	ssize_t r;
	while (got + 1 < size && (r = recv(s, out + got, size - 1 - got, 0)) > 0)
		got += (size_t)r;
	out[got] = '\0';
	close(s);
	int status = 0;
	if (sscanf(out, "HTTP/1.1 %d", &status) != 1)
		return -1;
	return status;
}

static void test_server(void **state)
{
	(void)state;
	prsm_jobs_options jo = PRSM_JOBS_OPTIONS_INIT;
	jo.db_path = db;
	prsm_jobs *jobs = NULL;
	prsm_error err = PRSM_ERROR_INIT;
	assert_int_equal(prsm_jobs_open(&jobs, &jo, NULL, &err), 0);
	prsm_http_options ho = PRSM_HTTP_OPTIONS_INIT;
	ho.port = 0;
	ho.data_dir = dir;
	ho.token = "tok";
	prsm_http *h = NULL;
	int rc = prsm_http_start(&h, &ho, jobs, &err);
	if (rc)
		print_error("start: %s\n", err.message);
	assert_int_equal(rc, 0);
	int port = prsm_http_port(h);
	assert_true(port > 0);
	static char out[65536];

	assert_int_equal(http_raw(port, "GET /v1/health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 200);
	assert_non_null(strstr(out, "\"status\":\"ok\""));
	assert_int_equal(http_raw(port, "GET /v1/schemas/x.schema.json HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 200);
	assert_non_null(strstr(out, "application/schema+json"));
	assert_int_equal(http_raw(port, "GET /v1/openapi.json HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 200);
	assert_int_equal(http_raw(port, "GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 200);
	assert_non_null(strstr(out, "landing"));
	assert_int_equal(http_raw(port, "GET /out.txt HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 404);
	assert_null(strstr(out, "secret\r") );
	assert_int_equal(http_raw(port, "GET /../secret.txt HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 404);
	assert_int_equal(http_raw(port, "GET /v1/nothing HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 404);
	assert_non_null(strstr(out, "application/problem+json"));
	assert_int_equal(http_raw(port, "DELETE /v1/health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 405);
	assert_non_null(strstr(out, "Allow: GET, HEAD"));
	assert_int_equal(http_raw(port, "POST /v1/studies HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
	                                "Content-Length: 2\r\nConnection: close\r\n\r\n{}", out, sizeof out), 401);
	assert_int_equal(http_raw(port, "POST /v1/studies HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
	                                "Authorization: Bearer tok\r\nContent-Length: 2\r\nContent-Length: 2\r\n"
	                                "Connection: close\r\n\r\n{}", out, sizeof out), 400);
	assert_int_equal(http_raw(port, "POST /v1/studies HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
	                                "Authorization: Bearer tok\r\nContent-Length: 2\r\nConnection: close\r\n\r\n{}",
	                          out, sizeof out), 422);
	assert_int_equal(http_raw(port, "GET /v1/studies HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", out, sizeof out), 200);
	assert_non_null(strstr(out, "\"items\":[]"));
	prsm_http_quiesce(h);
	prsm_http_stop(h);
	prsm_jobs_close(jobs);
}

/* A calibration form: the boundary from its Content-Type, the parts split at it (a preamble,
 * headers, a part without headers, the closing delimiter), the CSV part into measured.te_csv
 * and every malformation a problem. */
static void test_multipart(void **state)
{
	(void)state;
	char b[PRSM_HTTP_BOUNDARY_MAX + 1];
	assert_int_equal(prsm_http_multipart_boundary("multipart/form-data; boundary=abc-1", b, sizeof b), 1);
	assert_string_equal(b, "abc-1");
	assert_int_equal(prsm_http_multipart_boundary("Multipart/Form-Data;charset=utf-8; boundary=\"a b:c\"", b, sizeof b), 1);
	assert_string_equal(b, "a b:c");
	assert_int_equal(prsm_http_multipart_boundary("multipart/form-data", b, sizeof b), -1);
	assert_int_equal(prsm_http_multipart_boundary("multipart/form-data; boundary=", b, sizeof b), -1);
	assert_int_equal(prsm_http_multipart_boundary("multipart/form-data; boundary=\"unclosed", b, sizeof b), -1);
	assert_int_equal(prsm_http_multipart_boundary("multipart/form-data; boundary=a<b", b, sizeof b), -1);
	char longb[128];
	snprintf(longb, sizeof longb, "multipart/form-data; boundary=%071d", 7);
	assert_int_equal(prsm_http_multipart_boundary(longb, b, sizeof b), -1);
	assert_int_equal(prsm_http_multipart_boundary("multipart/form-dataX; boundary=a", b, sizeof b), 0);
	assert_int_equal(prsm_http_multipart_boundary("application/json", b, sizeof b), 0);
	assert_int_equal(prsm_http_multipart_boundary(NULL, b, sizeof b), 0);

	static const char form[] =
		"preamble, ignored\r\n"
		"--XyZ\r\n"
		"Content-Disposition: form-data; name=\"request\"; filename=\"cal.json\"\r\n"
		"Content-Type: application/json\r\n"
		"\r\n"
		"{\"design\": {\"name\": \"x\"}, \"measured\": {\"cage_ratio\": 0.37}}\r\n"
		"--XyZ  \r\n"
		"content-disposition: form-data; name=measured\r\n"
		"\r\n"
		"screw_angle_rad,te_um\r\n0,1.5\r\n--XyZ not the boundary\r\n1,2.5\r\n"
		"--XyZ--\r\n"
		"epilogue";
	prsm_problems p;
	prsm_problems_init(&p);
	prsm_http_part parts[4];
	int n = -1;
	assert_int_equal(prsm_http_multipart_parse(parts, 4, &n, form, sizeof form - 1, "XyZ", &p), 0);
	assert_int_equal(n, 2);
	assert_string_equal(parts[0].name, "request");
	assert_string_equal(parts[0].filename, "cal.json");
	assert_int_equal(parts[0].len, strlen("{\"design\": {\"name\": \"x\"}, \"measured\": {\"cage_ratio\": 0.37}}"));
	assert_string_equal(parts[1].name, "measured");
	assert_string_equal(parts[1].filename, "");
	static const char csv[] = "screw_angle_rad,te_um\r\n0,1.5\r\n--XyZ not the boundary\r\n1,2.5";
	assert_int_equal(parts[1].len, sizeof csv - 1);
	assert_memory_equal(parts[1].data, csv, sizeof csv - 1);
	assert_int_equal(p.count, 0);
	/* one part too many for the caller's array */
	assert_int_equal(prsm_http_multipart_parse(parts, 1, &n, form, sizeof form - 1, "XyZ", &p), 400);
	assert_int_equal(p.count, 1);

	cJSON *doc = NULL;
	prsm_problems_init(&p);
	assert_int_equal(prsm_http_calibration_form(&doc, form, sizeof form - 1, "XyZ", &p), 0);
	const cJSON *m = cJSON_GetObjectItemCaseSensitive(doc, "measured");
	assert_true(cJSON_GetObjectItemCaseSensitive(m, "cage_ratio")->valuedouble == 0.37);
	assert_string_equal(cJSON_GetObjectItemCaseSensitive(m, "te_csv")->valuestring, csv);
	cJSON_Delete(doc);

	/* malformed forms: each refused with its problem, nothing returned */
	static const struct {
		const char *body;
		int status;
		const char *needle;
	} bad[] = {
		{"no delimiter at all", 400, "no \"--XyZ\" line"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n", 400, "no closing"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n{}\r\n--XyZ--", 400, "blank line"},
		{"--XyZ\r\nContent-Type: text/csv\r\n\r\na\r\n--XyZ--", 400, "no Content-Disposition"},
		{"--XyZ\r\nContent-Disposition: attachment; name=\"a\"\r\n\r\na\r\n--XyZ--", 400, "not form-data"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n--XyZ--", 400, "no part \"measured\""},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 400, "no part \"request\""},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"notes\"\r\n\r\na\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 400, "part \"notes\""},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 400, "twice"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 400, ""},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n[1]\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 422, "must be an object"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{\"measured\": 3}\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 422, "measured is"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{\"measured\": {\"te\": {}}}\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\r\n--XyZ--", 422, "must not give"},
		{"--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n"
		 "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\xff\r\n--XyZ--", 400, "UTF-8"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		prsm_problems_init(&p);
		doc = (cJSON *)1;
		assert_int_equal(prsm_http_calibration_form(&doc, bad[i].body, strlen(bad[i].body), "XyZ", &p), bad[i].status);
		assert_null(doc);
		assert_true(p.count >= 1);
		int found = 0;
		for (int j = 0; j < p.count; j++)
			found |= strstr(p.items[j].message, bad[i].needle) != NULL;
		if (!found)
			fail_msg("case %zu: no problem says \"%s\" (first: %s)", i, bad[i].needle, p.items[0].message);
	}
	/* a NUL byte in the CSV part (the body is bytes, not a C string) */
	static const char nul[] = "--XyZ\r\nContent-Disposition: form-data; name=\"request\"\r\n\r\n{}\r\n"
	                          "--XyZ\r\nContent-Disposition: form-data; name=\"measured\"\r\n\r\na\0b\r\n--XyZ--";
	prsm_problems_init(&p);
	assert_int_equal(prsm_http_calibration_form(&doc, nul, sizeof nul - 1, "XyZ", &p), 400);
	assert_non_null(strstr(p.items[0].message, "NUL"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_framing_and_types),
		cmocka_unit_test(test_parse_body),
		cmocka_unit_test(test_multipart),
		cmocka_unit_test_setup_teardown(test_server, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
