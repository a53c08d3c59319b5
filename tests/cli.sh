#!/usr/bin/env bash
# CLI tests: exit codes (0 ok, 1 invalid, 2 failed, 64 usage), JSON on stdout, problems with
# their pointers, the text summary, validate, bench. Args: PRSM_BINARY SOURCE_DIR
set -u
prsm=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0
fail=0
py=/usr/bin/python3

check() { # name expected_code actual_code
  if [ "$2" = "$3" ]; then pass=$((pass+1)); else echo "FAIL: $1: exit $3, expected $2"; fail=$((fail+1)); fi
}
ok() { # name command...
  local name=$1; shift
  if "$@"; then pass=$((pass+1)); else echo "FAIL: $name"; fail=$((fail+1)); fi
}

# every example design analyses with exit 0 and valid JSON
for f in "$src"/studies/case-a.json "$src"/studies/seed000-stage1.json "$src"/studies/seed000-stage2.json "$src"/studies/large-6start.json; do
  "$prsm" analyze "$f" > "$tmp/out.json" 2> "$tmp/err"; check "analyze $(basename "$f")" 0 $?
  ok "json $(basename "$f")" $py -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["efficiency"]["eta"] > 0.8' "$tmp/out.json"
done

# case A figures through the CLI
"$prsm" analyze "$src/studies/case-a.json" > "$tmp/a.json"; check "analyze case A" 0 $?
ok "case A contact and gap" $py - "$tmp/a.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
c = d["contacts"]["screw_roller"]
assert abs(c["x_mm"] - 9.79727) < 1e-4 and abs(c["y_mm"] - 0.62678) < 1e-4, c
assert abs(c["gap_unthinned_um"] + 82.36) < 0.01, c
assert abs(d["backlash_um"] - 20.0) < 1e-9, d["backlash_um"]
assert abs(d["kinematics"]["carrier_ratio"] - 0.37564) < 5e-6
PY

# stdin and --out
"$prsm" analyze - < "$src/studies/case-a.json" > "$tmp/b.json"; check "analyze stdin" 0 $?
ok "stdin same as file" cmp -s "$tmp/a.json" "$tmp/b.json"
"$prsm" analyze "$src/studies/case-a.json" --out "$tmp/c.json"; check "analyze --out" 0 $?
ok "--out same as stdout" cmp -s "$tmp/a.json" "$tmp/c.json"

# text summary
"$prsm" analyze "$src/studies/case-a.json" --format text > "$tmp/t.txt"; check "analyze text" 0 $?
ok "text mentions carrier ratio" grep -q "carrier ratio 0.3756" "$tmp/t.txt"

# invalid request: exit 1, every problem with its pointer on stderr
cat > "$tmp/bad.json" <<'JSON'
{"geometry": {"starts": 5, "pitch_mm": -2, "roller_radius_mm": 3.25, "rollers": "ten",
              "engaged_threads": 10, "colour": "red"}}
JSON
"$prsm" analyze "$tmp/bad.json" > /dev/null 2> "$tmp/err"; check "analyze invalid" 1 $?
ok "pointer pitch" grep -q "/geometry/pitch_mm" "$tmp/err"
ok "pointer rollers" grep -q "/geometry/rollers" "$tmp/err"
ok "pointer unknown" grep -q "/geometry/colour" "$tmp/err"
"$prsm" validate "$tmp/bad.json" > "$tmp/v.txt"; check "validate invalid" 1 $?
ok "validate lists 3" test "$(grep -c ': /geometry/' "$tmp/v.txt")" -ge 3
"$prsm" validate "$tmp/bad.json" --format json > "$tmp/v.json"; check "validate json" 1 $?
ok "validate json errors" $py -c 'import json,sys; d=json.load(open(sys.argv[1])); assert not d["valid"] and len(d["errors"]) >= 3' "$tmp/v.json"
"$prsm" validate "$src/studies/case-a.json" > /dev/null; check "validate valid" 0 $?

# too many rollers: impossible geometry names the field and the limit
sed 's/"rollers": 10/"rollers": 11/' "$src/studies/case-a.json" > "$tmp/z.json"
"$prsm" analyze "$tmp/z.json" > /dev/null 2> "$tmp/err"; check "Z > Z_max" 1 $?
ok "Z_max named" grep -q "/geometry/rollers.*Z_max = 10" "$tmp/err"

# malformed JSON, NaN-ish numbers
printf '{"geometry": {"starts": 5,' > "$tmp/m.json"
"$prsm" analyze "$tmp/m.json" > /dev/null 2>&1; check "malformed" 1 $?
sed 's/"pitch_mm": 2/"pitch_mm": 1e999/' "$src/studies/case-a.json" > "$tmp/inf.json"
"$prsm" analyze "$tmp/inf.json" > /dev/null 2>&1; check "infinite number" 1 $?

# usage errors
"$prsm" > /dev/null 2>&1; check "no command" 64 $?
"$prsm" frobnicate > /dev/null 2>&1; check "unknown command" 64 $?
"$prsm" analyze > /dev/null 2>&1; check "analyze without file" 64 $?
"$prsm" analyze "$src/studies/case-a.json" --format pdf > /dev/null 2>&1; check "bad format" 64 $?
"$prsm" analyze "$tmp/does-not-exist.json" > /dev/null 2>&1; check "missing file" 64 $?

# bench: the documented JSON shape
"$prsm" bench --seconds 0.05 > "$tmp/bench.json"; check "bench" 0 $?
ok "bench shape" $py - "$tmp/bench.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
names = {b["name"] for b in d["benchmarks"]}
assert "contact_solve_warm" in names, names
for b in d["benchmarks"]:
    assert set(b) == {"name", "value", "unit", "threads"} and b["value"] > 0, b
PY

echo "cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
