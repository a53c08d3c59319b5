#!/usr/bin/python3
"""Contract tests of the prsm service against api/openapi.yaml and schemas/.

    run.py --prsm build/prsm [--source DIR]   start servers on free loopback ports with
                                             temporary databases (what CTest runs)
    run.py --url http://host:port [--token T] check a running server (another team's CI)

Every response is checked against the OpenAPI document: its status must be one the operation
documents, its media type the documented one, and a JSON body must validate against the
schema (Debian's python3-jsonschema, 2020-12); a job's result also against the kind's result
schema. The run fails when an operation of the document was never called.

With --prsm it also checks what needs control of the process: the queue cap (503), the bearer
token, SIGTERM (exit 0, the job resumes at the next start) and kill -9 during a job (the
restart finishes it with the same result as `prsm study`). Prints one line per failure and
"contract: N passed, M failed"; exits 1 on a failure.
"""
import argparse
import copy
import http.client
import json
import os
import random
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse

from jsonschema import Draft202012Validator

HERE = os.path.dirname(os.path.abspath(__file__))
BASE_URI = "https://prsm.example/schemas/"

passed = 0
failed = 0
called_ops = set()


def check(name, ok, detail=""):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print(f"FAIL: {name}" + (f": {detail}" if detail else ""), flush=True)
    return ok


# ---- the contract ---------------------------------------------------------------------------------

def load_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


class Contract:
    def __init__(self, source):
        self.source = source
        self.schemas = {}
        for name in sorted(os.listdir(os.path.join(source, "schemas"))):
            if name.endswith(".json"):
                self.schemas[name] = load_json(os.path.join(source, "schemas", name))
        self.store = {s["$id"]: s for s in self.schemas.values() if "$id" in s}
        self.openapi = load_json(os.path.join(source, "api", "openapi.json"))
        self.ops = []  # (method, regex, template, operation)
        for template, item in self.openapi["paths"].items():
            rx = "^" + re.sub(r"\{[^}]+\}", "[^/]+", re.escape(template).replace(r"\{", "{").replace(r"\}", "}")) + "$"
            for method in ("get", "post", "delete", "put", "patch"):
                if method in item:
                    self.ops.append((method.upper(), re.compile(rx), template, item[method]))
        self._validators = {}

    def validator(self, schema):
        key = json.dumps(schema, sort_keys=True)
        if key in self._validators:
            return self._validators[key]
        try:  # jsonschema >= 4.18
            from referencing import Registry, Resource
            from referencing.jsonschema import DRAFT202012
            registry = Registry().with_resources(
                [(uri, Resource.from_contents(s, default_specification=DRAFT202012)) for uri, s in self.store.items()])
            v = Draft202012Validator(schema, registry=registry)
        except ImportError:  # Debian 12: jsonschema 4.10
            from jsonschema import RefResolver
            v = Draft202012Validator(schema, resolver=RefResolver.from_schema(schema, store=self.store))
        self._validators[key] = v
        return v

    def validate(self, schema, doc):
        errs = sorted(self.validator(schema).iter_errors(doc), key=lambda e: list(e.absolute_path))
        return "; ".join(f"/{'/'.join(str(p) for p in e.absolute_path)}: {e.message[:200]}" for e in errs[:3])

    def operation(self, method, path):
        m = "GET" if method == "HEAD" else method
        for meth, rx, template, op in self.ops:
            if meth == m and rx.match(path):
                return template, op
        return None, None

    def resolve_response(self, resp):
        if "$ref" in resp:
            name = resp["$ref"].split("/")[-1]
            return self.openapi["components"]["responses"][name]
        return resp


# ---- HTTP -------------------------------------------------------------------------------------------

class Response:
    def __init__(self, status, headers, body):
        self.status = status
        self.headers = {k.lower(): v for k, v in headers}
        self.body = body
        self._json = None

    def json(self):
        if self._json is None:
            self._json = json.loads(self.body.decode("utf-8"))
        return self._json


class Client:
    def __init__(self, url, contract, token=None):
        u = urllib.parse.urlsplit(url)
        self.host = u.hostname
        self.port = u.port or 80
        self.contract = contract
        self.token = token

    def request(self, method, path, body=None, headers=None, content_type="application/json", auth=True,
                check_contract=True, timeout=30):
        h = {}
        if body is not None:
            if isinstance(body, (dict, list)):
                body = json.dumps(body).encode("utf-8")
            elif isinstance(body, str):
                body = body.encode("utf-8")
            if content_type:
                h["Content-Type"] = content_type
        if self.token and auth and method in ("POST", "DELETE"):
            h["Authorization"] = "Bearer " + self.token
        h.update(headers or {})
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        try:
            conn.request(method, path, body=body, headers=h)
            r = conn.getresponse()
            resp = Response(r.status, r.getheaders(), r.read())
        finally:
            conn.close()
        if check_contract:
            self.check_contract(method, path, resp)
        return resp

    def check_contract(self, method, path, resp):
        c = self.contract
        bare = path.split("?")[0]
        template, op = c.operation(method, bare)
        where = f"{method} {path[:80]} -> {resp.status}"
        if op is None:
            # outside the document: only errors may answer (unknown routes, wrong methods)
            if resp.status in (404, 405, 400, 413, 415):
                self.check_problem(where, resp)
            else:
                check(f"{where}: an undocumented route answered", False)
            return
        called_ops.add(op["operationId"])
        responses = op.get("responses", {})
        spec = responses.get(str(resp.status))
        if spec is None:
            # framing refusals and 404/405 can answer any operation
            if resp.status in (400, 404, 405, 413, 415, 401):
                self.check_problem(where, resp)
                return
            check(f"{where}: status not documented for {op['operationId']}", False)
            return
        spec = c.resolve_response(spec)
        content = spec.get("content", {})
        ctype = resp.headers.get("content-type", "").split(";")[0].strip()
        if method == "HEAD":
            return
        if not content:
            return
        if not check(f"{where}: media type", ctype in content, f"{ctype} not in {list(content)}"):
            return
        schema = content[ctype].get("schema")
        if ctype.endswith("json"):
            try:
                doc = resp.json()
            except ValueError as e:
                check(f"{where}: JSON body", False, str(e))
                return
            if schema:
                err = c.validate(schema, doc)
                check(f"{where}: body against {json.dumps(schema)[:80]}", not err, err)
            if isinstance(doc, dict) and "result" in doc and isinstance(doc.get("links"), dict):
                rs = doc["links"].get("result_schema", "").split("/")[-1]
                if rs in c.schemas:
                    err = c.validate(c.schemas[rs], doc["result"])
                    check(f"{where}: result against {rs}", not err, err)
            if ctype == "application/problem+json":
                self.check_problem_doc(where, resp, doc)

    def check_problem(self, where, resp):
        ctype = resp.headers.get("content-type", "").split(";")[0].strip()
        if not check(f"{where}: problem media type", ctype == "application/problem+json", ctype):
            return
        try:
            doc = resp.json()
        except ValueError as e:
            check(f"{where}: problem JSON", False, str(e))
            return
        err = self.contract.validate(self.contract.schemas["problem.schema.json"], doc)
        check(f"{where}: problem document", not err, err)
        self.check_problem_doc(where, resp, doc)

    def check_problem_doc(self, where, resp, doc):
        check(f"{where}: problem status matches", doc.get("status") == resp.status, str(doc.get("status")))
        check(f"{where}: at least one problem listed", len(doc.get("errors", [])) >= 1)

    def get(self, path, **kw):
        return self.request("GET", path, **kw)

    def post(self, path, body, **kw):
        return self.request("POST", path, body=body, **kw)

    def delete(self, path, **kw):
        return self.request("DELETE", path, **kw)

    def raw(self, data, read_timeout=5):
        """Send raw bytes, return (status or None, raw response)."""
        s = socket.create_connection((self.host, self.port), timeout=read_timeout)
        out = b""
        try:
            s.sendall(data)
            while True:
                b = s.recv(65536)
                if not b:
                    break
                out += b
                m = re.search(rb"Content-Length: (\d+)\r\n", out)
                head_end = out.find(b"\r\n\r\n")
                if m and head_end >= 0 and len(out) >= head_end + 4 + int(m.group(1)):
                    break
        except (socket.timeout, ConnectionResetError, BrokenPipeError):
            pass
        finally:
            s.close()
        m = re.match(rb"HTTP/1\.[01] (\d{3})", out)
        return (int(m.group(1)) if m else None), out


def raw_problem(client, name, data, want):
    status, out = client.raw(data)
    check(f"{name}: status {want}", status == want, f"got {status}: {out[:200]!r}")
    if status == want:
        head, _, body = out.partition(b"\r\n\r\n")
        check(f"{name}: problem+json", b"application/problem+json" in head)
        try:
            doc = json.loads(body.decode("utf-8"))
            err = client.contract.validate(client.contract.schemas["problem.schema.json"], doc)
            check(f"{name}: problem document", not err, err)
        except ValueError as e:
            check(f"{name}: problem JSON", False, str(e))


def alive(client, after):
    r = client.get("/v1/health", check_contract=False)
    check(f"the server is up after {after}", r.status == 200)


# ---- documents ----------------------------------------------------------------------------------------

def small_study(seed, samples=4096):
    u = {"distribution": "uniform", "lower": -3.14159, "upper": 3.14159}
    return {"name": "contract test", "model": {"benchmark": "ishigami"},
            "tolerances": [dict(u, parameter="x1"), dict(u, parameter="x2"), dict(u, parameter="x3")],
            "outputs": ["y"], "specs": {"y": {"lower": -5, "upper": 12}},
            "monte_carlo": {"samples": samples, "seed": seed, "block_size": 512, "sampler": "lhs"},
            "sensitivity": {"src": True, "stack": True}}


def long_study(source, seed, samples):
    d = load_json(os.path.join(source, "studies", "case-a-tolerances.json"))
    d["assembly"]["mode"] = "exact"
    d["monte_carlo"] = {"samples": samples, "seed": seed, "block_size": 256}
    d["sensitivity"] = {"src": False, "stack": False}
    d["outputs"] = ["backlash_um", "load_sharing_factor"]
    d.pop("specs", None)
    return d


def strip_volatile(result):
    r = copy.deepcopy(result)
    r.pop("timing_s", None)
    r.pop("cache_hit", None)
    return r


def wait_job(client, location, states=("done", "failed", "cancelled"), timeout=120, pred=None):
    deadline = time.time() + timeout
    doc = None
    while time.time() < deadline:
        r = client.get(location)
        if r.status != 200:
            return None
        doc = r.json()
        if doc["state"] in states and (pred is None or pred(doc)):
            return doc
        time.sleep(0.05)
    return doc


# ---- the suite (any server) ------------------------------------------------------------------------

def suite_service(client, contract):
    r = client.get("/v1/health")
    check("health 200", r.status == 200)
    r = client.request("HEAD", "/v1/health")
    check("HEAD health 200 without a body", r.status == 200 and r.body == b"")
    r = client.get("/v1/version")
    check("version 200", r.status == 200)
    if r.status == 200:
        v = r.json()
        check("version names the study engine", any("prsm-mc" in k["version"] for k in v["job_kinds"]))
    r = client.get("/v1/openapi.json")
    check("openapi.json is the repository's api/openapi.json", r.status == 200 and r.json() == contract.openapi)
    for name, s in contract.schemas.items():
        r = client.get("/v1/schemas/" + name)
        check(f"schema {name} served as in schemas/", r.status == 200 and r.json() == s)
    r = client.get("/v1/schemas/nothing.schema.json")
    check("unknown schema 404", r.status == 404)
    r = client.get("/")
    check("/ serves the landing page", r.status == 200 and b"<html" in r.body.lower()
          and r.headers.get("content-type", "").startswith("text/html"))
    r = client.get("/index.html", check_contract=False)
    check("/index.html", r.status == 200)
    for path in ("/nothing.html", "/.git/config", "/web/index.html", "/%2e%2e/CMakeLists.txt",
                 "/..%2fCMakeLists.txt", "/%2e%2e/%2e%2e/etc/passwd", "/v1", "/v1/", "/v1/nothing",
                 "/v1/studies/zz$", "/v1/studies/0123/samples.csv/x"):
        r = client.get(path, check_contract=False)
        check(f"GET {path}: 404", r.status == 404, str(r.status))
        client.check_problem(f"GET {path}", r)
    for raw_path in (b"/../CMakeLists.txt", b"/../../../../etc/passwd", b"/./index.html/../../README.md"):
        status, out = client.raw(b"GET " + raw_path + b" HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        check(f"raw GET {raw_path.decode()}: not served", status in (400, 404) and b"cmake_minimum" not in out
              and b"root:" not in out, str(status))
    r = client.request("PUT", "/v1/studies", body={})
    check("PUT /v1/studies: 405 with Allow", r.status == 405 and "POST" in r.headers.get("allow", ""))
    r = client.request("POST", "/v1/health", body={})
    check("POST /v1/health: 405 with Allow", r.status == 405 and r.headers.get("allow") == "GET, HEAD")
    r = client.request("GET", "/v1/designs/analyze")
    check("GET analyze: 405", r.status == 405 and r.headers.get("allow") == "POST")
    r = client.request("POST", "/", body={}, check_contract=False)
    check("POST /: 405", r.status == 405)
    client.check_problem("POST /", r)


def suite_analyze(client, contract, source):
    design = load_json(os.path.join(source, "studies", "case-a.json"))
    r = client.post("/v1/designs/analyze", design)
    check("analyze case A: 200", r.status == 200, r.body[:200])
    measured = load_json(os.path.join(source, "studies", "case-a-measured.json"))
    r = client.post("/v1/designs/analyze", measured)
    check("analyze case A with errors: 200", r.status == 200, r.body[:200])
    bad = copy.deepcopy(design)
    bad["geometry"]["rollers"] = 99
    bad["geometry"]["starts"] = "five"
    bad["friction"] = {"screw_roller": -1, "nut_roller": 0.05}
    r = client.post("/v1/designs/analyze", bad)
    check("invalid design: 422", r.status == 422, str(r.status))
    if r.status == 422:
        ptrs = {e["pointer"] for e in r.json()["errors"]}
        check("invalid design: every problem with its pointer", "/geometry/starts" in ptrs
              and "/friction/screw_roller" in ptrs, str(ptrs))
    r = client.post("/v1/designs/analyze", [1, 2])
    check("array body: 422", r.status == 422)
    r = client.post("/v1/designs/analyze", "{\"geometry\": ")
    check("malformed JSON: 400", r.status == 400)
    r = client.post("/v1/designs/analyze", b"{\"name\": \"\xc3\x28\"}")
    check("invalid UTF-8: 400", r.status == 400)
    r = client.post("/v1/designs/analyze", "[" * 5000 + "]" * 5000)
    check("deep nesting: 400", r.status == 400)
    r = client.post("/v1/designs/analyze", "{\"a\": 1, \"a\": 2}")
    check("duplicate member: 400 or 422", r.status in (400, 422))
    r = client.post("/v1/designs/analyze", "")
    check("empty body: 400", r.status == 400)
    r = client.post("/v1/designs/analyze", design, content_type="text/plain")
    check("text/plain: 415", r.status == 415)
    r = client.post("/v1/designs/analyze", design, content_type="application/json; charset=latin-1")
    check("charset latin-1: 415", r.status == 415)
    r = client.post("/v1/designs/analyze", design, content_type="application/json; charset=utf-8")
    check("charset utf-8: 200", r.status == 200)
    huge = b"{\"name\": \"" + b"x" * (2 * 1024 * 1024) + b"\"}"
    head = (b"POST /v1/designs/analyze HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" + auth_header(client) +
            b"Content-Length: %d\r\n" % len(huge))
    raw_problem(client, "2 MiB body announced with Expect: 100-continue", head + b"Expect: 100-continue\r\n\r\n", 413)
    try:
        status, _ = client.raw(head + b"\r\n" + huge)
    except (BrokenPipeError, ConnectionResetError):
        status = None  # answered and closed before the client finished sending
    check("2 MiB body sent at once: 413 or closed", status in (413, None), str(status))
    alive(client, "the huge body")
    # a huge body sent chunked, without a length
    chunk = b"x" * 65536
    data = b"POST /v1/designs/analyze HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" \
           b"Transfer-Encoding: chunked\r\n" + auth_header(client) + b"\r\n"
    body = b"".join(b"%x\r\n" % len(chunk) + chunk + b"\r\n" for _ in range(24)) + b"0\r\n\r\n"
    try:
        status, _ = client.raw(data + body, read_timeout=10)
    except (BrokenPipeError, ConnectionResetError):
        status = None
    check("1.5 MiB chunked body: 413 or closed", status in (413, None), str(status))
    alive(client, "the chunked huge body")
    body = b"{\"a\":1}"
    raw_problem(client, "two Content-Length",
                b"POST /v1/designs/analyze HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" + auth_header(client) +
                b"Content-Length: 7\r\nContent-Length: 7\r\n\r\n" + body, 400)
    raw_problem(client, "Content-Length with chunked",
                b"POST /v1/designs/analyze HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" + auth_header(client) +
                b"Content-Length: 7\r\nTransfer-Encoding: chunked\r\n\r\n7\r\n" + body + b"\r\n0\r\n\r\n", 400)
    status, _ = client.raw(b"GARBAGE\r\n\r\n")
    check("garbage request line: 400 or closed", status in (400, None), str(status))
    alive(client, "the framing tests")


def auth_header(client):
    return ("Authorization: Bearer " + client.token + "\r\n").encode() if client.token else b""


def suite_studies(client, contract, source):
    seed = random.randrange(1, 2**31)
    study = small_study(seed)
    r = client.post("/v1/studies", study)
    check("submit study: 202", r.status == 202, f"{r.status} {r.body[:300]!r}")
    if r.status != 202:
        return
    job = r.json()
    loc = r.headers.get("location")
    check("Location names the job", loc == f"/v1/studies/{job['id']}", str(loc))
    done = wait_job(client, loc)
    check("the study finishes", done is not None and done["state"] == "done", str(done and done["state"]))
    if not done or done["state"] != "done":
        return
    check("progress at the end", done["progress"]["samples_done"] == 4096
          and done["progress"]["samples_planned"] == 4096, str(done["progress"]))
    r = client.get(loc + "/samples.csv")
    check("samples.csv: 200", r.status == 200)
    lines = r.body.decode("utf-8").splitlines()
    check("samples.csv: header and one row per sample", len(lines) == 4097 and lines[0].startswith("sample"),
          f"{len(lines)} lines, {lines[0][:60] if lines else ''}")
    # the cache: the same request, in another key order and spacing
    shuffled = json.loads(json.dumps(study), object_pairs_hook=lambda kv: dict(reversed(kv)))
    r = client.post("/v1/studies", json.dumps(shuffled, indent=3))
    check("identical request: 200 from the cache", r.status == 200, str(r.status))
    if r.status == 200:
        hit = r.json()
        check("cache hit: the same job", hit["id"] == job["id"])
        check("cache hit flagged", hit["cache_hit"] is True and hit["result"]["cache_hit"] is True)
        check("cache hit: the identical result", strip_volatile(hit["result"]) == strip_volatile(done["result"])
              and hit["result"]["timing_s"] == done["result"]["timing_s"])
    threads_changed = copy.deepcopy(study)
    threads_changed["monte_carlo"]["threads"] = 2
    r = client.post("/v1/studies", threads_changed)
    check("another thread count is the same request", r.status == 200 and r.json()["id"] == job["id"])
    other_seed = copy.deepcopy(study)
    other_seed["monte_carlo"]["seed"] = seed + 1
    r = client.post("/v1/studies", other_seed)
    check("another seed is another job", r.status == 202 and r.json()["id"] != job["id"])
    if r.status == 202:
        wait_job(client, r.headers["location"])

    # invalid studies: every problem with its pointer
    bad = copy.deepcopy(study)
    bad["monte_carlo"]["samples"] = "many"
    bad["tolerances"][0]["distribution"] = "gaussian"
    r = client.post("/v1/studies", bad)
    check("invalid study: 422", r.status == 422, str(r.status))
    if r.status == 422:
        ptrs = {e["pointer"] for e in r.json()["errors"]}
        check("invalid study: both pointers", "/monte_carlo/samples" in ptrs
              and any(p.startswith("/tolerances/0") for p in ptrs), str(ptrs))
    big = copy.deepcopy(study)
    big["monte_carlo"]["samples"] = 4000000
    r = client.post("/v1/studies", big)
    check("over the service's sample cap: 422 at the field", r.status == 422
          and any(e["pointer"] == "/monte_carlo/samples" for e in r.json().get("errors", [])), r.body[:200])
    r = client.post("/v1/studies", "{\"model\": ")
    check("malformed study: 400", r.status == 400)
    r = client.post("/v1/studies", study, content_type="application/x-www-form-urlencoded")
    check("form-encoded study: 415", r.status == 415)

    # concurrent identical submissions make one job
    conc = small_study(random.randrange(1, 2**31), samples=200000)
    ids, statuses = [], []
    barrier = threading.Barrier(8)

    def submit():
        barrier.wait()
        rr = client.post("/v1/studies", conc)
        statuses.append(rr.status)
        if rr.status in (200, 202):
            ids.append(rr.json()["id"])

    ts = [threading.Thread(target=submit) for _ in range(8)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    check("8 concurrent identical submissions: one job", len(ids) == 8 and len(set(ids)) == 1,
          f"{statuses} {set(ids)}")
    if ids:
        d = wait_job(client, f"/v1/studies/{ids[0]}")
        check("the shared job finishes", d is not None and d["state"] == "done")

    # cancel
    long = long_study(source, random.randrange(1, 2**31), 200000)
    # a stop target too small to be met: progress reports its standard error as it runs
    long["monte_carlo"]["targets"] = [{"output": "backlash_um", "standard_error": 1e-9}]
    r = client.post("/v1/studies", long)
    check("long study: 202", r.status == 202, r.body[:200])
    if r.status == 202:
        loc = r.headers["location"]
        running = wait_job(client, loc, states=("running",), timeout=60, pred=lambda d: d["progress"]["samples_done"] > 0)
        check("long study runs with progress", running is not None and running["state"] == "running"
              and running["progress"]["samples_planned"] == 200000 and running["progress"]["eta_s"] is not None,
              str(running and running["progress"]))
        running = wait_job(client, loc, states=("running",), timeout=60,
                           pred=lambda d: d["progress"]["interval_width"] is not None)
        p = running and running["progress"]
        check("a running study with a target reports its interval width and goal",
              p is not None and p["interval_width"] > 1e-9 and p["interval_goal"] == 1e-9
              and p["unit"] == "samples" and p["best_objective"] is None, str(p))
        r = client.delete(loc)
        check("DELETE a running study: 200 cancelled", r.status == 200 and r.json()["state"] == "cancelled")
        r = client.delete(loc)
        check("DELETE again: 409", r.status == 409, str(r.status))
        r = client.get(loc)
        check("cancelled stays cancelled", r.status == 200 and r.json()["state"] == "cancelled")
        r = client.get(loc + "/samples.csv")
        check("no samples for a cancelled study: 404", r.status == 404)
    r = client.delete(f"/v1/studies/{job['id']}")
    check("DELETE a done study: 409", r.status == 409)
    r = client.delete("/v1/studies/" + "0" * 32)
    check("DELETE an unknown study: 404", r.status == 404)
    r = client.get("/v1/studies/" + "0" * 32)
    check("GET an unknown study: 404", r.status == 404)
    r = client.get("/v1/studies/" + "0" * 32 + "/samples.csv")
    check("samples of an unknown study: 404", r.status == 404)

    # paging
    r = client.get("/v1/studies?limit=1")
    check("list, 1 per page", r.status == 200 and len(r.json()["items"]) == 1 and r.json()["next"])
    if r.status == 200 and r.json()["next"]:
        first = r.json()["items"][0]["id"]
        r2 = client.get(r.json()["next"])
        check("next page: an older job", r2.status == 200 and len(r2.json()["items"]) == 1
              and r2.json()["items"][0]["id"] != first)
    r = client.get("/v1/studies")
    check("list, default page", r.status == 200 and 1 <= len(r.json()["items"]) <= 20)
    for q in ("limit=0", "limit=101", "limit=abc", "cursor=x", "cursor=-3"):
        r = client.get("/v1/studies?" + q)
        check(f"list ?{q}: 400", r.status == 400, str(r.status))


def suite_design_jobs(client, contract, source):
    """/v1/optimizations and /v1/allocations: the same job machinery as studies (submit, poll,
    cache, list, cancel with the best point so far kept, 422 with pointers)."""
    opt = load_json(os.path.join(source, "studies", "optimize-case-a.json"))
    opt["solver"]["max_evaluations"] = 400
    opt["solver"]["seed"] = random.randrange(1, 2**31)
    alloc = load_json(os.path.join(source, "studies", "allocate-ls1.json"))
    for coll, doc, unit in (("optimizations", opt, "evaluations"), ("allocations", alloc, "samples")):
        r = client.post(f"/v1/{coll}", doc)
        check(f"submit {coll}: 202 or 200", r.status in (200, 202), f"{r.status} {r.body[:300]!r}")
        if r.status not in (200, 202):
            continue
        job = r.json()
        loc = f"/v1/{coll}/{job['id']}"
        if r.status == 202:
            check(f"{coll}: Location names the job", r.headers.get("location") == loc, str(r.headers.get("location")))
        done = wait_job(client, loc, timeout=120)
        check(f"{coll}: the job finishes", done is not None and done["state"] == "done",
              str(done and (done["state"], done.get("problem"))))
        if not done or done["state"] != "done":
            continue
        check(f"{coll}: progress unit {unit}, work counted, all of it once done", done["progress"]["unit"] == unit
              and done["progress"]["samples_done"] > 0 and done["progress"]["fraction"] == 1, str(done["progress"]))
        check(f"{coll}: result not cancelled", done["result"]["cancelled"] is False)
        again = json.loads(json.dumps(doc), object_pairs_hook=lambda kv: dict(reversed(kv)))
        r = client.post(f"/v1/{coll}", again)
        check(f"{coll}: identical request answered from the cache", r.status == 200 and r.json()["id"] == job["id"]
              and r.json()["cache_hit"] is True, str(r.status))
        if r.status == 200:
            check(f"{coll}: cache hit gives the identical result",
                  strip_volatile(r.json()["result"]) == strip_volatile(done["result"]))
        r = client.get(f"/v1/{coll}?limit=5")
        check(f"list {coll}: the job is there", r.status == 200 and job["id"] in [j["id"] for j in r.json()["items"]])
        r = client.post(f"/v1/{coll}", {"name": 3})
        check(f"{coll}: an invalid document is 422", r.status == 422, str(r.status))
        if r.status == 422:
            ptrs = [e["pointer"] for e in r.json()["errors"]]
            check(f"{coll}: every problem with its pointer", "/name" in ptrs and len(ptrs) >= 2, str(ptrs))
        r = client.delete(loc)
        check(f"DELETE a done {coll[:-1]}: 409", r.status == 409, str(r.status))
        r = client.get(f"/v1/{coll}/" + "0" * 32)
        check(f"unknown {coll[:-1]}: 404", r.status == 404)
    # cancel a long optimisation: it keeps its best point so far
    long = copy.deepcopy(opt)
    long["solver"].update({"max_evaluations": 200000, "multistart": 64, "seed": random.randrange(1, 2**31),
                           "max_time_s": 600})
    r = client.post("/v1/optimizations", long)
    check("long optimisation: 202", r.status == 202, f"{r.status} {r.body[:300]!r}")
    if r.status == 202:
        loc = r.headers["location"]
        running = wait_job(client, loc, states=("running",), timeout=60,
                           pred=lambda d: d["progress"]["best_objective"] is not None)
        check("a running optimisation reports evaluations and the best objective so far", running is not None
              and running["progress"]["unit"] == "evaluations" and running["progress"]["samples_done"] > 0,
              str(running and running["progress"]))
        r = client.delete(loc)
        check("DELETE a running optimisation: 200 cancelled", r.status == 200 and r.json()["state"] == "cancelled",
              str(r.status))
        kept = wait_job(client, loc, states=("cancelled",), timeout=60, pred=lambda d: "result" in d)
        check("a cancelled optimisation keeps its best point so far", kept is not None
              and kept["result"]["cancelled"] is True and kept["result"].get("best") is not None,
              str(kept and kept.get("result", {}).get("cancelled")))
        r = client.delete(loc)
        check("DELETE a cancelled optimisation again: 409", r.status == 409, str(r.status))


def suite_simulations(client, contract, source):
    """/v1/simulations: a start-up transient as a job (progress in simulated nanoseconds, the cache,
    the time series as CSV, cancel, 422 with pointers, the service's cap on output times); and
    POST /v1/designs/analyze with a dynamics object: the statics, saying the transient is not run.
    The vibration analyses (issue 16, docs/vibration.md): a gear-pair sweep as a job (progress in
    sweep points, the result against dynamics-result.schema.json, the bifurcation points as CSV,
    the cache), a bad request refused by the schema and by the service at every pointer, the
    service's cap on recorded values, a long sweep cancelled while it runs."""
    v1 = load_json(os.path.join(source, "studies", "dynamics-case-a-v1.json"))
    r = client.post("/v1/designs/analyze", v1)
    check("analyze a request with dynamics: 200, the statics", r.status == 200 and "efficiency" in r.json(),
          f"{r.status} {r.body[:200]!r}")
    if r.status == 200:
        check("analyze a request with dynamics: a warning says the transient is not run",
              any(w["pointer"] == "/dynamics" and w["code"] == "not_simulated" for w in r.json()["warnings"]),
              str(r.json()["warnings"]))
    r = client.post("/v1/simulations", v1)
    check("submit simulation V1: 202 or 200", r.status in (200, 202), f"{r.status} {r.body[:300]!r}")
    if r.status not in (200, 202):
        return
    job = r.json()
    loc = f"/v1/simulations/{job['id']}"
    if r.status == 202:
        check("simulation: Location names the job", r.headers.get("location") == loc, str(r.headers.get("location")))
    done = wait_job(client, loc, timeout=60)
    check("simulation: the job finishes", done is not None and done["state"] == "done",
          str(done and (done["state"], done.get("problem"))))
    if done and done["state"] == "done":
        p = done["progress"]
        check("simulation: progress in simulated nanoseconds, all of it", p["unit"] == "simulated_ns"
              and p["samples_done"] == p["samples_planned"] == 1000000, str(p))
        d = done["result"]["dynamics"]
        st = d["settled"]["stages"][0]
        check("simulation: V1's k*, settled efficiency and eta(0+) in the result",
              abs(st["carrier_ratio_min_slip"] - 0.37369408) < 1e-6 and abs(d["settled"]["efficiency"] - 0.9922054) < 1e-6
              and abs(d["transient"]["efficiency"][0] - 0.8655226) < 1e-6
              and abs(st["time_to_50_percent_s"] / 8.857132e-5 - 1) < 1e-5, json.dumps(d["settled"])[:300])
        check("simulation: 101 output times, checks passed", d["transient"]["points"] == 101
              and len(d["transient"]["time_s"]) == 101 and d["checks"]["passed"] is True)
        check("simulation: links to its time series", done["links"].get("samples_csv") == loc + "/samples.csv",
              str(done["links"]))
        r = client.get(loc + "/samples.csv")
        lines = r.body.decode("utf-8").splitlines() if r.status == 200 else []
        check("simulation: the time series as CSV (header and 101 rows)", r.status == 200
              and lines[0].startswith("time_s,") and len(lines) == 102, f"{r.status} {len(lines)}")
        again = json.loads(json.dumps(v1), object_pairs_hook=lambda kv: dict(reversed(kv)))
        r = client.post("/v1/simulations", again)
        check("simulation: identical request answered from the cache", r.status == 200 and r.json()["id"] == job["id"]
              and r.json()["cache_hit"] is True, str(r.status))
        r = client.delete(loc)
        check("DELETE a done simulation: 409", r.status == 409, str(r.status))
    r = client.get("/v1/simulations?limit=5")
    check("list simulations: the job is there", r.status == 200 and job["id"] in [j["id"] for j in r.json()["items"]])
    r = client.get("/v1/simulations/" + "0" * 32)
    check("unknown simulation: 404", r.status == 404)
    bad = copy.deepcopy(v1)
    bad["dynamics"]["time"] = {"end_s": 0, "stepper": "rk8pd"}
    bad["dynamics"]["inertia"] = {"roller_mass_kg": -1}
    bad["dynamics"]["analysis"] = "calibrate"
    r = client.post("/v1/simulations", bad)
    check("invalid simulation: 422", r.status == 422, str(r.status))
    if r.status == 422:
        ptrs = {e["pointer"] for e in r.json()["errors"]}
        check("invalid simulation: every problem with its pointer", {"/dynamics/time/end_s",
              "/dynamics/inertia/roller_mass_kg", "/dynamics/analysis"} <= ptrs, str(ptrs))
    r = client.post("/v1/simulations", {"design": v1["design"]})
    check("a simulation without dynamics: 422 at /dynamics", r.status == 422
          and "/dynamics" in [e["pointer"] for e in r.json()["errors"]], f"{r.status} {r.body[:200]!r}")
    fine = copy.deepcopy(v1)
    fine["dynamics"]["time"] = {"end_s": 0.001, "output_step_s": 5e-9}
    r = client.post("/v1/simulations", fine)
    check("more output times than the service keeps: 422 at output_step_s", r.status == 422
          and [(e["pointer"], e["code"]) for e in r.json()["errors"]] == [("/dynamics/time/output_step_s", "service_cap")],
          f"{r.status} {r.body[:300]!r}")
    # a long run, cancelled while it runs: no result
    long = load_json(os.path.join(source, "studies", "dynamics-case-a-coulomb.json"))
    long["dynamics"]["input"] = {"kind": "speed", "shape": "sine", "value_rad_s": 100,
                                 "sine_amplitude_rad_s": 50, "sine_frequency_Hz": 2000 + random.randrange(1000)}
    long["dynamics"]["time"] = {"end_s": 100, "output_step_s": 0.001}
    r = client.post("/v1/simulations", long)
    check("long simulation: 202", r.status == 202, f"{r.status} {r.body[:300]!r}")
    if r.status == 202:
        loc = r.headers["location"]
        running = wait_job(client, loc, states=("running",), timeout=60, pred=lambda d: d["progress"]["samples_done"] > 0)
        check("a running simulation reports simulated time", running is not None
              and running["progress"]["unit"] == "simulated_ns" and 0 < running["progress"]["samples_done"]
              < running["progress"]["samples_planned"] == 100 * 10**9, str(running and running["progress"]))
        r = client.delete(loc)
        check("DELETE a running simulation: 200 cancelled", r.status == 200 and r.json()["state"] == "cancelled",
              str(r.status))
        gone = wait_job(client, loc, states=("cancelled",), timeout=60)
        check("a cancelled simulation has no result", gone is not None and "result" not in gone, str(gone and gone.get("state")))
    suite_vibration(client, contract, source)


def suite_calibrations(client, contract, source, prsm=None):
    """/v1/calibrations (issue 17 item 5): validation case V6 (tests/data/calibrate-case-a-v6.json
    with the curve of tests/data/v6-measured-te.csv inlined as arrays, as web/examples/ has it) as a
    job: 202 or 200, done, the result against measured-result.schema.json (checked for every job
    document by the client), k as `prsm calibrate` gives it for the CSV file (within 1e-6), the
    cache; a bad request refused with 422 at every pointer; list, unknown id, DELETE of a done job."""
    req = load_json(os.path.join(source, "web", "examples", "calibrate-case-a-v6.json"))
    base = load_json(os.path.join(source, "tests", "data", "calibrate-case-a-v6.json"))
    csv_path = os.path.join(source, "tests", "data", "v6-measured-te.csv")
    with open(csv_path, encoding="utf-8") as f:
        rows = [l.strip().split(",") for l in f if l.strip() and not l.startswith("#")]
    inlined = copy.deepcopy(base)
    cols = {name: [float(r[i]) for r in rows[1:]] for i, name in enumerate(rows[0])}
    inlined["measured"]["te"] = cols
    check("web/examples/calibrate-case-a-v6.json is the V6 request with the CSV curve inlined",
          req["measured"].get("te") == cols and {k: v for k, v in req.items() if k != "measured"}
          == {k: v for k, v in base.items() if k != "measured"}
          and {k: v for k, v in req["measured"].items() if k != "te"} == base["measured"])
    cli_k = None
    if prsm:
        out = subprocess.run([prsm, "calibrate", os.path.join(source, "tests", "data", "calibrate-case-a-v6.json"),
                              "--measured", csv_path], capture_output=True, timeout=120)
        if check("prsm calibrate V6 with the CSV file: exit 0", out.returncode == 0, out.stderr.decode()[:300]):
            cli_k = json.loads(out.stdout)["calibration"]["carrier_ratio"]["estimate"]
    r = client.post("/v1/calibrations", req)
    check("submit calibration V6: 202 or 200", r.status in (200, 202), f"{r.status} {r.body[:300]!r}")
    if r.status not in (200, 202):
        return
    job = r.json()
    loc = f"/v1/calibrations/{job['id']}"
    check("calibration: kind and links", job["kind"] == "calibration"
          and job["links"].get("result_schema", "").endswith("measured-result.schema.json"), json.dumps(job["links"]))
    if r.status == 202:
        check("calibration: Location names the job", r.headers.get("location") == loc, str(r.headers.get("location")))
    done = wait_job(client, loc, timeout=120)
    check("calibration: the job finishes", done is not None and done["state"] == "done",
          str(done and (done["state"], done.get("problem"))))
    if done and done["state"] == "done":
        res = done["result"]
        err = contract.validate(contract.schemas["measured-result.schema.json"], res)
        check("calibration: the result validates against measured-result.schema.json", not err, err)
        p = done["progress"]
        check("calibration: progress counts one analysis", p["unit"] == "analyses"
              and p["samples_done"] == p["samples_planned"] == 1, str(p))
        k = res["calibration"]["carrier_ratio"]["estimate"]
        if cli_k is not None:
            check("calibration: k as prsm calibrate gives it (1e-6)", abs(k - cli_k) < 1e-6, f"{k} vs {cli_k}")
        check("calibration: V6's k and slope (docs/measured-data.md)", abs(k - 0.3724996) < 2e-7
              and abs(res["calibration"]["estimates"]["slope_um_per_300mm"] - 12.316) < 1e-3, str(k))
        check("calibration: the curve came as JSON, 960 points", res["measured"]["source"] == "json"
              and res["measured"]["points"] == 960, json.dumps(res["measured"]))
        again = json.loads(json.dumps(req), object_pairs_hook=lambda kv: dict(reversed(kv)))
        r = client.post("/v1/calibrations", again)
        check("calibration: identical request answered from the cache", r.status == 200 and r.json()["id"] == job["id"]
              and r.json()["cache_hit"] is True, str(r.status))
        r = client.delete(loc)
        check("DELETE a done calibration: 409", r.status == 409, str(r.status))
    r = client.get("/v1/calibrations?limit=5")
    check("list calibrations: the job is there", r.status == 200 and job["id"] in [j["id"] for j in r.json()["items"]])
    r = client.get("/v1/calibrations/" + "0" * 32)
    check("unknown calibration: 404", r.status == 404)
    bad = copy.deepcopy(req)
    bad["measured"]["te"]["te_um"] = bad["measured"]["te"]["te_um"][:-5]
    bad["measured"]["cage_ratio_sd"] = 0.001
    bad["dynamics"]["calibrate"]["model"] = "spline"
    bad["design"]["geometry"]["pitch_mm"] = -2
    r = client.post("/v1/calibrations", bad)
    check("invalid calibration: 422", r.status == 422, f"{r.status} {r.body[:300]!r}")
    if r.status == 422:
        ptrs = {e["pointer"] for e in r.json()["errors"]}
        check("invalid calibration: every problem with its pointer", {"/design/geometry/pitch_mm",
              "/dynamics/calibrate/model"} <= ptrs and any(q.startswith("/measured") for q in ptrs), str(ptrs))
    short = copy.deepcopy(req)
    for key in ("screw_angle_rad", "travel_mm", "te_um"):
        short["measured"]["te"][key] = short["measured"]["te"][key][:150]
    r = client.post("/v1/calibrations", short)
    check("a curve of fewer than four revolutions: 422 under /measured/te", r.status == 422
          and any(e["pointer"].startswith("/measured/te") for e in r.json()["errors"]), f"{r.status} {r.body[:300]!r}")
    r = client.post("/v1/calibrations", {"design": req["design"], "measured": {}, "dynamics": {"analysis": "linear"}})
    check("a calibration without a curve and with another analysis: 422", r.status == 422
          and "/dynamics/analysis" in [e["pointer"] for e in r.json()["errors"]], f"{r.status} {r.body[:300]!r}")
    with open(csv_path, encoding="utf-8") as f:
        csv_text = f.read()
    r = client.post("/v1/calibrations", csv_text, content_type="text/csv")
    check("a CSV body alone: 415 naming the two forms taken", r.status == 415
          and "multipart/form-data" in r.headers.get("accept-post", ""), f"{r.status} {r.headers.get('accept-post')}")
    # the bench file uploaded as it is: multipart/form-data with the parts request and measured
    boundary = "prsm-" + "%016x" % random.getrandbits(64)

    def form(parts, b=boundary):
        out = []
        for name, ctype, text in parts:
            out.append(f'--{b}\r\nContent-Disposition: form-data; name="{name}"; filename="{name}.x"\r\n'
                       f'Content-Type: {ctype}\r\n\r\n{text}\r\n')
        return "".join(out) + f"--{b}--\r\n"
    ftype = f'multipart/form-data; boundary="{boundary}"'
    r = client.post("/v1/calibrations", form([("request", "application/json", json.dumps(base)),
                                              ("measured", "text/csv", csv_text)]), content_type=ftype)
    check("calibration as a form (request + measured CSV): 202 or 200", r.status in (200, 202), f"{r.status} {r.body[:300]!r}")
    if r.status in (200, 202):
        done = wait_job(client, f"/v1/calibrations/{r.json()['id']}", timeout=120)
        ok = done is not None and done["state"] == "done"
        check("calibration as a form: done", ok, str(done and (done["state"], done.get("problem"))))
        if ok:
            res = done["result"]
            k = res["calibration"]["carrier_ratio"]["estimate"]
            check("calibration as a form: the curve came as CSV (960 points), k as the CLI's (1e-12)",
                  res["measured"]["source"] == "csv" and res["measured"]["points"] == 960 and "file" not in res["measured"]
                  and (cli_k is None or abs(k - cli_k) <= 1e-12), f"{json.dumps(res['measured'])} {k} {cli_k}")
    bad_csv = csv_text.replace("\n0.", "\nx.", 3)
    r = client.post("/v1/calibrations", form([("request", "application/json", json.dumps(base)),
                                              ("measured", "text/csv", bad_csv)]), content_type=ftype)
    check("a form with a bad CSV: 422 at /measured/te_csv with its line and column", r.status == 422
          and any(e["pointer"] == "/measured/te_csv" and "line " in e["message"] and "column " in e["message"]
                  for e in r.json()["errors"]), f"{r.status} {r.body[:300]!r}")
    r = client.post("/v1/calibrations", form([("request", "application/json", json.dumps(base))]), content_type=ftype)
    check("a form without its CSV part: 400", r.status == 400 and "measured" in r.json()["errors"][0]["message"],
          f"{r.status} {r.body[:200]!r}")
    r = client.post("/v1/calibrations", form([("request", "application/json", "{")] + [("measured", "text/csv", csv_text)]),
                    content_type=ftype)
    check("a form whose request is not JSON: 400", r.status == 400, str(r.status))
    r = client.post("/v1/calibrations", form([("request", "application/json", json.dumps(base)),
                                              ("measured", "text/csv", csv_text)])[:-40], content_type=ftype)
    check("a form cut short: 400", r.status == 400, str(r.status))
    r = client.post("/v1/calibrations", "x", content_type="multipart/form-data")
    check("multipart without a boundary: 400", r.status == 400, str(r.status))
    r = client.post("/v1/studies", form([("request", "application/json", "{}")]), content_type=ftype)
    check("a form on another collection: 415", r.status == 415, str(r.status))
    # cancel: a distinct request (the cache would answer V6), cancelled at once; it may finish first
    other = copy.deepcopy(req)
    other["dynamics"]["calibrate"]["grid_points"] = 2001 + 2 * random.randrange(1, 500)
    r = client.post("/v1/calibrations", other)
    if check("another calibration: 202", r.status == 202, f"{r.status} {r.body[:200]!r}"):
        x = client.delete(r.headers["location"])
        check("cancel a calibration: 200 cancelled, or 409 when it had finished", (x.status == 200 and x.json()["state"] == "cancelled")
              or x.status == 409, str(x.status))


def suite_validate(client, contract, source, prsm=None):
    """POST /v1/validate: every kind of request document read as its command reads it (read_as),
    the same answer as `prsm validate --format json` for documents within the service's limits,
    invalid documents with every problem at its pointer (200, valid false), a study over the
    service's sample cap refused as its submission is, malformed bodies refused as everywhere."""
    docs = {
        "design": load_json(os.path.join(source, "studies", "case-a.json")),
        "study": load_json(os.path.join(source, "studies", "case-a-tolerances.json")),
        "allocation": load_json(os.path.join(source, "studies", "allocate-case-a.json")),
        "optimization": load_json(os.path.join(source, "studies", "optimize-case-a.json")),
        "simulation": load_json(os.path.join(source, "studies", "vibration-case-a-330.json")),
        "calibration": load_json(os.path.join(source, "web", "examples", "calibrate-case-a-v6.json")),
    }
    bad_study = copy.deepcopy(docs["study"])
    bad_study["tolerances"][0]["distribution"] = "nromal"
    bad_study["monte_carlo"]["samples"] = -5
    docs["bad study"] = bad_study
    for label, doc in docs.items():
        r = client.post("/v1/validate", doc)
        if not check(f"validate {label}: 200", r.status == 200, f"{r.status} {r.body[:200]!r}"):
            continue
        v = r.json()
        want_kind = label.split()[-1]
        check(f"validate {label}: read as {want_kind}, valid {label != 'bad study'}", v["read_as"] == want_kind
              and v["valid"] == (label != "bad study"), json.dumps(v)[:300])
        if label == "bad study":
            ptrs = {e["pointer"] for e in v["errors"]}
            check("validate bad study: every problem with its pointer", "/monte_carlo/samples" in ptrs
                  and any(q.startswith("/tolerances/0") for q in ptrs), str(ptrs))
        if prsm:
            path = os.path.join(tempfile.mkdtemp(prefix="prsm-validate-"), "doc.json")
            with open(path, "w", encoding="utf-8") as f:
                json.dump(doc, f)
            out = subprocess.run([prsm, "validate", path, "--format", "json"], capture_output=True, timeout=120)
            try:
                cli = json.loads(out.stdout)
            except ValueError:
                cli = None
            check(f"validate {label}: the service's answer is prsm validate's", cli == v,
                  f"{out.returncode} {out.stdout[:200]!r} vs {json.dumps(v)[:200]}")
            subprocess.run(["rm", "-rf", os.path.dirname(path)])
    # within the command's caps but over the service's: refused as the submission refuses it
    big = copy.deepcopy(docs["study"])
    big["monte_carlo"]["samples"] = 3000000
    r = client.post("/v1/validate", big)
    s = client.post("/v1/studies", big)
    ok = r.status == 200 and not r.json()["valid"] and s.status == 422
    check("validate: a study over the service's sample cap is invalid, as its submission (422) says", ok
          and {e["pointer"] for e in r.json()["errors"]} == {e["pointer"] for e in s.json()["errors"]},
          f"{r.status} {r.body[:300]!r} / {s.status} {s.body[:300]!r}")
    r = client.post("/v1/validate", "{", content_type="application/json")
    check("validate: malformed JSON is a 400", r.status == 400, str(r.status))
    r = client.post("/v1/validate", [1])
    check("validate: a document that is not an object is a 422", r.status == 422, str(r.status))
    r = client.get("/v1/validate")
    check("validate: GET is a 405 with Allow: POST", r.status == 405 and r.headers.get("allow") == "POST", str(r.status))


def suite_vibration(client, contract, source):
    """The vibration analyses on /v1/simulations (docs/vibration.md)."""
    result_schema = contract.schemas["dynamics-result.schema.json"]
    request_schema = contract.schemas["simulation.schema.json"]
    sweep = load_json(os.path.join(source, "studies", "vibration-gear-pair-sweep.json"))
    sweep["dynamics"]["sweep"].update({"from": 0.6, "to": 1.4, "step": 0.1, "transient_periods": 100,
                                       "recorded_periods": 16})
    check("vibration sweep request matches simulation.schema.json", contract.validate(request_schema, sweep) == "",
          contract.validate(request_schema, sweep))
    r = client.post("/v1/simulations", sweep)
    check("submit a gear-pair sweep: 202 or 200", r.status in (200, 202), f"{r.status} {r.body[:300]!r}")
    if r.status not in (200, 202):
        return
    job = r.json()
    loc = f"/v1/simulations/{job['id']}"
    done = wait_job(client, loc, timeout=60)
    check("sweep: the job finishes", done is not None and done["state"] == "done",
          str(done and (done["state"], done.get("problem"))))
    if done and done["state"] == "done":
        p = done["progress"]
        check("sweep: progress in sweep points, all of them (9 points, up and down)",
              p["samples_done"] == p["samples_planned"] == 18 and p["unit"] == "sweep_points"
              and p["fraction"] == 1 and p["phase"] is None, str(p))
        e = contract.validate(result_schema, done["result"])
        check("sweep: the result matches dynamics-result.schema.json", e == "", e)
        d = done["result"]["dynamics"]
        sw = d.get("sweep", {})
        check("sweep: both directions, every point with its frequency ratio, class and 16 Poincare values",
              d["analysis"] == "sweep" and len(sw.get("up", [])) == len(sw.get("down", [])) == 9
              and [round(x["frequency_ratio"], 9) for x in sw["up"]] == [round(0.6 + 0.1 * i, 9) for i in range(9)]
              and all(len(x["poincare"]) == 16 for x in sw["up"] + sw["down"] if x["converged"]), json.dumps(sw)[:300])
        check("sweep: the parameters echoed with their defaults, the convergence flags",
              d["parameters"]["gear_pair"]["contact_ratio"] == 1.5 and d["parameters"]["sweep"]["continuation"] is True
              and d["convergence"]["converged"] is True and d["model"]["kind"] == "gear_pair", json.dumps(d["parameters"]))
        r = client.get(loc + "/samples.csv")
        lines = r.body.decode("utf-8").splitlines() if r.status == 200 else []
        check("sweep: the bifurcation points as CSV (a row per Poincare point)", r.status == 200
              and lines[0].startswith("direction,frequency_ratio,classification") and len(lines) == 1 + 18 * 16,
              f"{r.status} {len(lines)}")
        again = json.loads(json.dumps(sweep), object_pairs_hook=lambda kv: dict(reversed(kv)))
        r = client.post("/v1/simulations", again)
        check("sweep: identical request answered from the cache", r.status == 200 and r.json()["id"] == job["id"]
              and r.json()["cache_hit"] is True, str(r.status))
    bad = {"dynamics": {"analysis": "sweep", "gear_pair": {"damping_ratio": 0, "mean_lod": 0.1},
                        "sweep": {"from": 0, "to": 10, "step": 1e-6, "parameter": "screw_speed_rad_s"},
                        "input": {"value_rad_s": 100}}}
    check("bad vibration request: simulation.schema.json refuses it", contract.validate(request_schema, bad) != "")
    r = client.post("/v1/simulations", bad)
    check("bad vibration request: 422", r.status == 422, f"{r.status} {r.body[:300]!r}")
    if r.status == 422:
        ptrs = {e["pointer"] for e in r.json()["errors"]}
        check("bad vibration request: every problem at its pointer", {"/dynamics/gear_pair/damping_ratio",
              "/dynamics/gear_pair/mean_lod", "/dynamics/sweep/step", "/dynamics/sweep/parameter",
              "/dynamics/input"} <= ptrs, str(ptrs))
    r = client.post("/v1/simulations", {"design": load_json(os.path.join(source, "studies", "case-a.json")),
                                        "dynamics": {"analysis": "vibration", "gear_pair": {}}})
    check("a gear pair with a design: 422 at /dynamics/gear_pair", r.status == 422
          and "/dynamics/gear_pair" in [e["pointer"] for e in r.json()["errors"]], f"{r.status} {r.body[:300]!r}")
    big = copy.deepcopy(sweep)
    big["dynamics"]["sweep"].update({"from": 0.1, "to": 900, "step": 0.05, "recorded_periods": 64, "transient_periods": 10})
    r = client.post("/v1/simulations", big)
    check("more recorded values than the service keeps: 422 at sweep/step", r.status == 422
          and [(e["pointer"], e["code"]) for e in r.json()["errors"]] == [("/dynamics/sweep/step", "service_cap")],
          f"{r.status} {r.body[:300]!r}")
    # a long sweep, cancelled while it runs: no result
    long = copy.deepcopy(sweep)
    long["dynamics"]["sweep"].update({"from": 0.5, "to": 2.5, "step": 0.0005 + random.randrange(1000) * 1e-9,
                                      "transient_periods": 300, "recorded_periods": 16})
    r = client.post("/v1/simulations", long)
    check("long sweep: 202", r.status == 202, f"{r.status} {r.body[:300]!r}")
    if r.status == 202:
        loc = r.headers["location"]
        running = wait_job(client, loc, states=("running",), timeout=60, pred=lambda d: d["progress"]["samples_done"] > 0)
        check("a running sweep reports sweep points", running is not None
              and 0 < running["progress"]["samples_done"] < running["progress"]["samples_planned"], str(running and running["progress"]))
        r = client.delete(loc)
        check("DELETE a running sweep: 200 cancelled", r.status == 200 and r.json()["state"] == "cancelled", str(r.status))
        gone = wait_job(client, loc, states=("cancelled",), timeout=60)
        check("a cancelled sweep has no result", gone is not None and "result" not in gone, str(gone and gone.get("state")))


def suite_slow_client(client, server_timeout_s):
    """A client that sends half a request and stalls: others are served meanwhile; with a known
    server timeout, the stalled connection is closed."""
    s = socket.create_connection((client.host, client.port), timeout=30)
    s.sendall(b"POST /v1/designs/analyze HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
              b"Content-Length: 100\r\n" + auth_header(client) + b"\r\n{\"geometry\"")
    slow2 = socket.create_connection((client.host, client.port), timeout=30)
    slow2.sendall(b"GET /v1/hea")
    alive(client, "two stalled clients")
    if server_timeout_s:
        closed = 0
        for sock in (s, slow2):
            sock.settimeout(server_timeout_s * 4 + 10)
            try:
                data = sock.recv(65536)
                closed += 1 if (data == b"" or data.startswith(b"HTTP/1.1 4")) else 0
            except (socket.timeout, ConnectionResetError):
                pass
        check("stalled connections are closed by the server", closed == 2, f"{closed} of 2")
    s.close()
    slow2.close()
    alive(client, "the stalled clients")


# ---- servers started here ---------------------------------------------------------------------------

def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class Server:
    def __init__(self, prsm, source, db, args=(), env=None):
        self.prsm, self.source, self.db, self.args, self.env = prsm, source, db, list(args), env
        self.proc = None
        self.port = None

    def start(self):
        self.port = free_port()
        env = dict(os.environ)
        env.pop("PRSM_TOKEN", None)
        env.update(self.env or {})
        self.log = tempfile.TemporaryFile()
        self.proc = subprocess.Popen([self.prsm, "serve", "--port", str(self.port), "--db", self.db,
                                      "--data-dir", self.source] + self.args,
                                     stdout=self.log, stderr=subprocess.STDOUT, env=env)
        deadline = time.time() + 20
        while time.time() < deadline:
            if self.proc.poll() is not None:
                break
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1).close()
                return self
            except OSError:
                time.sleep(0.05)
        self.log.seek(0)
        raise RuntimeError(f"prsm serve did not start: {self.log.read()[-2000:]!r}")

    def url(self):
        return f"http://127.0.0.1:{self.port}"

    def output(self):
        self.log.seek(0)
        return self.log.read().decode("utf-8", "replace")

    def stop(self, sig=signal.SIGTERM):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                return self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                return self.proc.wait()
        return self.proc.returncode if self.proc else None


def suite_process(prsm, source, contract, tmp):
    # the queue cap: one worker busy, one job queued, the next refused
    db = os.path.join(tmp, "queue.db")
    srv = Server(prsm, source, db, ["--workers", "1", "--max-queued", "1"]).start()
    try:
        c = Client(srv.url(), contract)
        a = c.post("/v1/studies", long_study(source, 11, 200000))
        wait_job(c, a.headers.get("location", "/v1/studies/x"), states=("running",), timeout=30)
        b = c.post("/v1/studies", long_study(source, 12, 200000))
        full = c.post("/v1/studies", long_study(source, 13, 200000))
        check("queue full: 503 with Retry-After", full.status == 503 and "retry-after" in full.headers,
              f"{a.status} {b.status} {full.status}")
        shared = c.post("/v1/studies", long_study(source, 12, 200000))
        check("queue full: an identical queued request is still shared", shared.status == 202
              and b.status == 202 and shared.json()["id"] == b.json()["id"])
        # SIGTERM: exit 0, the running job is queued again and resumes at the next start
        running_id = a.json()["id"] if a.status == 202 else None
        code = srv.stop(signal.SIGTERM)
        check("SIGTERM: exit 0", code == 0, f"{code}: {srv.output()[-500:]}")
        srv = Server(prsm, source, db, ["--workers", "1", "--max-queued", "1"]).start()
        c = Client(srv.url(), contract)
        if running_id:
            d = wait_job(c, f"/v1/studies/{running_id}", states=("running",), timeout=30)
            check("after SIGTERM the interrupted job runs again", d is not None and d["state"] == "running"
                  and d["attempts"] == 2, str(d and (d["state"], d["attempts"])))
            c.delete(f"/v1/studies/{running_id}")
        if b.status == 202:
            c.delete(f"/v1/studies/{b.json()['id']}")
    finally:
        srv.stop()

    # the bearer token guards POST and DELETE
    db = os.path.join(tmp, "token.db")
    srv = Server(prsm, source, db, [], env={"PRSM_TOKEN": "s3cret-t0ken"}).start()
    try:
        c = Client(srv.url(), contract, token=None)
        r = c.post("/v1/studies", small_study(5))
        check("no token: 401 with WWW-Authenticate", r.status == 401 and "bearer" in r.headers.get("www-authenticate", "").lower())
        r = c.post("/v1/studies", small_study(5), headers={"Authorization": "Bearer wrong"})
        check("wrong token: 401", r.status == 401)
        r = c.delete("/v1/studies/" + "0" * 32)
        check("DELETE without token: 401", r.status == 401)
        r = c.get("/v1/studies")
        check("GET needs no token", r.status == 200)
        c.token = "s3cret-t0ken"
        r = c.post("/v1/studies", small_study(5))
        check("right token: accepted", r.status in (200, 202), str(r.status))
    finally:
        srv.stop()
    token_file = os.path.join(tmp, "token")
    with open(token_file, "w") as f:
        f.write("from-a-file\n")
    srv = Server(prsm, source, db, ["--token-file", token_file]).start()
    try:
        c = Client(srv.url(), contract, token="from-a-file")
        r = c.post("/v1/designs/analyze", load_json(os.path.join(source, "studies", "case-a.json")))
        check("--token-file: accepted with its token", r.status == 200)
    finally:
        srv.stop()

    # kill -9 during a job; the restart finishes it with the result `prsm study` gives
    db = os.path.join(tmp, "crash.db")
    study = long_study(source, 424242, 30000)
    path = os.path.join(tmp, "crash-study.json")
    with open(path, "w") as f:
        json.dump(study, f)
    srv = Server(prsm, source, db).start()
    c = Client(srv.url(), contract)
    r = c.post("/v1/studies", study)
    check("crash study accepted", r.status == 202)
    loc = r.headers.get("location")
    d = wait_job(c, loc, states=("running",), timeout=30, pred=lambda d: d["progress"]["samples_done"] > 0)
    check("crash study running before the kill", d is not None and d["state"] == "running")
    srv.stop(signal.SIGKILL)
    srv = Server(prsm, source, db).start()
    try:
        c = Client(srv.url(), contract)
        d = wait_job(c, loc, timeout=120)
        check("after kill -9 the job resumes and finishes", d is not None and d["state"] == "done",
              str(d and d["state"]))
        if d and d["state"] == "done":
            check("after kill -9: attempts 2", d["attempts"] == 2, str(d["attempts"]))
            cli = subprocess.run([prsm, "study", path, "--quiet"], capture_output=True, timeout=120)
            check("prsm study of the same document", cli.returncode == 0, cli.stderr[-300:])
            if cli.returncode == 0:
                ref = json.loads(cli.stdout)
                check("after kill -9: the same result as prsm study",
                      strip_volatile(ref) == strip_volatile(d["result"]))
            r = c.post("/v1/studies", study)
            check("after kill -9: the result is cached", r.status == 200 and r.json()["id"] == d["id"])
    finally:
        code = srv.stop()
        check("SIGTERM on an idle server: exit 0", code == 0, str(code))


def heavy_analysis(source):
    """Case A with errors in exact mode on a fine grid over a long record: tens of seconds."""
    doc = load_json(os.path.join(source, "studies", "case-a-measured.json"))
    doc["assembly"].update({"mode": "exact", "angles_per_revolution": 1024, "spectrum_revolutions": 256})
    return doc


def suite_analysis_budget(prsm, source, contract, tmp):
    """POST /v1/designs/analyze stays within its synchronous budget: heavier requests become
    analysis jobs (202), and the HTTP threads stay free for health checks."""
    measured = load_json(os.path.join(source, "studies", "case-a-measured.json"))
    design = load_json(os.path.join(source, "studies", "case-a.json"))
    # the reference: answered synchronously by a default server
    srv = Server(prsm, source, os.path.join(tmp, "sync.db")).start()
    try:
        ref = Client(srv.url(), contract).post("/v1/designs/analyze", measured)
        check("budget: a default server answers case A with errors at once", ref.status == 200, str(ref.status))
    finally:
        srv.stop()

    # a zero budget: every error analysis is a job; the nominal analysis still answers at once
    srv = Server(prsm, source, os.path.join(tmp, "budget0.db"), ["--sync-budget", "0", "--workers", "1"]).start()
    try:
        c = Client(srv.url(), contract)
        r = c.post("/v1/designs/analyze", design)
        check("budget 0: a nominal analysis is still synchronous", r.status == 200, str(r.status))
        r = c.post("/v1/designs/analyze", measured)
        loc = r.headers.get("location", "")
        check("budget 0: an error analysis is queued (202, Location /v1/analyses/{id})",
              r.status == 202 and re.match(r"^/v1/analyses/[0-9a-f]{32}$", loc) is not None, f"{r.status} {loc}")
        d = wait_job(c, loc or "/v1/analyses/x", timeout=60)
        check("budget 0: the analysis job finishes", d is not None and d["state"] == "done", str(d and d["state"]))
        if d and d["state"] == "done" and ref.status == 200:
            check("budget 0: the job's result is the synchronous answer", d["result"] == ref.json())
            r = c.post("/v1/designs/analyze", measured)
            check("budget 0: the same request again is the cached job (200)", r.status == 200
                  and r.json().get("id") == d["id"] and r.json().get("state") == "done", str(r.status))
            r = c.delete(loc)
            check("cancel a finished analysis job: 409", r.status == 409, str(r.status))
        r = c.get("/v1/analyses")
        check("list analysis jobs", r.status == 200 and len(r.json().get("items", r.json().get("jobs", []))) >= 1,
              r.body[:200])
        bad = copy.deepcopy(measured)
        bad["assembly"]["angles_per_revolution"] = -4
        bad["design"]["geometry"]["rollers"] = "ten"
        r = c.post("/v1/analyses", bad)
        check("POST /v1/analyses: every problem at once (422)", r.status == 422
              and len(r.json().get("errors", [])) >= 2, r.body[:300])
    finally:
        srv.stop()

    # a time budget: a request that runs out of it becomes a job; health answers meanwhile
    srv = Server(prsm, source, os.path.join(tmp, "budget-time.db"),
                 ["--threads", "2", "--sync-budget", "1000000000000", "--sync-time-ms", "3000",
                  "--workers", "1"]).start()
    try:
        c = Client(srv.url(), contract)
        heavy = heavy_analysis(source)
        slow = {}
        t = threading.Thread(target=lambda: slow.update(r=c.post("/v1/designs/analyze", heavy, timeout=120)))
        t.start()
        time.sleep(0.3)
        other = dict(heavy)
        other["assembly"] = dict(heavy["assembly"], measuring_load_N=60)
        busy = c.post("/v1/designs/analyze", other)
        h = c.get("/v1/health")
        answered_during = t.is_alive()
        check("budget: health answers while an analysis computes on the other HTTP thread",
              h.status == 200 and answered_during)
        check("budget: a second heavy analysis does not take the last HTTP thread (202)", busy.status == 202,
              str(busy.status))
        t.join(120)
        r = slow.get("r")
        check("budget: an analysis that runs out of its time becomes a job (202)", r is not None and r.status == 202,
              str(r and r.status))
        for resp in (r, busy):
            if resp is not None and resp.status == 202:
                x = c.delete(resp.headers["location"])
                check("cancel a queued or running analysis job", x.status == 200 and x.json()["state"] == "cancelled",
                      str(x.status))
    finally:
        code = srv.stop()
        check("budget server: SIGTERM exit 0", code == 0, str(code))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--url", help="check a running server (no process tests)")
    ap.add_argument("--token", help="bearer token of that server, if it needs one")
    ap.add_argument("--prsm", help="the prsm binary: start servers here")
    ap.add_argument("--source", default=os.path.normpath(os.path.join(HERE, "..", "..")),
                    help="repository root (schemas/, api/, studies/, web/)")
    args = ap.parse_args()
    if not args.url and not args.prsm:
        ap.error("give --url or --prsm")
    source = os.path.abspath(args.source)
    contract = Contract(source)
    for name, s in contract.schemas.items():
        try:
            Draft202012Validator.check_schema(s)
            ok, detail = True, ""
        except Exception as e:
            ok, detail = False, str(e).splitlines()[0]
        check(f"{name} against the 2020-12 metaschema", ok, detail)
    try:
        import yaml
        with open(os.path.join(source, "api", "openapi.yaml"), encoding="utf-8") as f:
            check("api/openapi.json is api/openapi.yaml (run api/make-json.py)", yaml.safe_load(f) == contract.openapi)
    except ImportError:
        print("note: python3-yaml missing: api/openapi.yaml not compared with api/openapi.json")
    check("OpenAPI 3.1", contract.openapi.get("openapi", "").startswith("3.1"))
    for ref in set(re.findall(r'"\$ref": "(https://prsm\.example/schemas/[^"#]+)', json.dumps(contract.openapi))):
        check(f"openapi $ref {ref} is a schema", ref in contract.store)

    tmp = tempfile.mkdtemp(prefix="prsm-contract-")
    srv = None
    try:
        if args.url:
            client = Client(args.url, contract, token=args.token)
            timeout = None
        else:
            timeout = 2
            srv = Server(args.prsm, source, os.path.join(tmp, "main.db"),
                         ["--workers", "2", "--timeout-s", str(timeout)]).start()
            client = Client(srv.url(), contract)
        suite_service(client, contract)
        suite_analyze(client, contract, source)
        suite_studies(client, contract, source)
        suite_design_jobs(client, contract, source)
        suite_simulations(client, contract, source)
        suite_calibrations(client, contract, source, args.prsm)
        suite_validate(client, contract, source, args.prsm)
        suite_slow_client(client, timeout)
        if srv:
            code = srv.stop()
            check("main server: SIGTERM exit 0", code == 0, f"{code}: {srv.output()[-800:]}")
            srv = None
            suite_process(args.prsm, source, contract, tmp)
            suite_analysis_budget(args.prsm, source, contract, tmp)
    finally:
        if srv:
            srv.stop()
        subprocess.run(["rm", "-rf", tmp])

    all_ops = {op["operationId"] for _, _, _, op in contract.ops}
    missing = sorted(all_ops - called_ops)
    check("every operation of api/openapi.yaml was called", not missing, ", ".join(missing))
    print(f"contract: {passed} passed, {failed} failed ({len(called_ops)} of {len(all_ops)} operations called)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
