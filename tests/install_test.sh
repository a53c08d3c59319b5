#!/usr/bin/env bash
# cmake --install into an empty temporary prefix, then run the installed prsm away from the source
# tree: it finds its data next to itself (share/prsm), serves the web form, the schemas and the
# OpenAPI document, analyzes an installed example, and has its man page and unit example.
# Usage: install_test.sh BUILD_DIR
set -u
build=$1
tmp=$(mktemp -d)
pass=0 fail=0
ok() { local name=$1; shift; if "$@" >/dev/null 2>&1; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: $name"; fi; }
cleanup() { [ -n "${pid:-}" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null; rm -rf "$tmp"; }
trap cleanup EXIT

prefix="$tmp/prefix"
ok "cmake --install into an empty prefix" cmake --install "$build" --prefix "$prefix"
ok "bin/prsm" test -x "$prefix/bin/prsm"
ok "share/prsm/schemas" test -f "$prefix/share/prsm/schemas/design.schema.json"
ok "share/prsm/api/openapi.json" test -f "$prefix/share/prsm/api/openapi.json"
ok "share/prsm/web/index.html" test -f "$prefix/share/prsm/web/index.html"
ok "man page" test -f "$prefix/share/man/man1/prsm.1"
ok "systemd unit example" test -f "$prefix/share/doc/prsm/prsm.service"

# run it from a directory that is neither the source nor the build tree
cd "$tmp"
ok "the installed binary analyzes an installed example" \
  sh -c "'$prefix/bin/prsm' analyze '$prefix/share/prsm/studies/case-a.json' | grep -q '\"engine\"'"
"$prefix/bin/prsm" serve --port 0 --db "$tmp/prsm.db" 2> "$tmp/serve.log" &
pid=$!
port=
for _ in $(seq 1 100); do
  port=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$tmp/serve.log")
  [ -n "$port" ] && break
  sleep 0.1
done
ok "serve --port 0 starts" test -n "$port"
ok "it takes its data from the prefix" grep -q "data $prefix/bin/../share/prsm" "$tmp/serve.log"
fetch() { /usr/bin/python3 -c "import sys, urllib.request; sys.stdout.write(urllib.request.urlopen(sys.argv[1], timeout=10).read().decode())" "$1"; }
ok "the web form" sh -c "$(declare -f fetch); fetch http://127.0.0.1:$port/ | grep -qi '<html'"
ok "a schema" sh -c "$(declare -f fetch); fetch http://127.0.0.1:$port/v1/schemas/design.schema.json | grep -q 'design.schema.json'"
ok "the OpenAPI document" sh -c "$(declare -f fetch); fetch http://127.0.0.1:$port/v1/openapi.json | grep -q '\"openapi\"'"
ok "health" sh -c "$(declare -f fetch); fetch http://127.0.0.1:$port/v1/health | grep -q '\"ok\"'"
kill "$pid"; wait "$pid"; code=$?; pid=
ok "SIGTERM: exit 0" test "$code" -eq 0
# PRSM_DATA_DIR and --data-dir still win
ok "PRSM_DATA_DIR pointing nowhere is refused clearly" \
  sh -c "PRSM_DATA_DIR=$tmp/nowhere '$prefix/bin/prsm' serve --port 0 --db '$tmp/x.db' 2>&1 | grep -q 'nowhere'"

echo "install: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
