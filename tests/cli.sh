#!/usr/bin/env bash
# CLI tests: exit codes (0 ok, 1 invalid, 2 failed, 64 usage), JSON on stdout, problems with
# their pointers, the text summary, validate, the request form {design, errors, assembly},
# study (tolerance studies: --out, --csv, --threads, stdin), bench, simulate (the dynamics
# examples). Args: PRSM_BINARY SOURCE_DIR
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
ok "text has the efficiency split" grep -q "input torque .* = ideal .* + sliding .* + spin" "$tmp/t.txt"
ok "text has stiffness and thread compliance" grep -q "thread compliance: Yamamoto, width share" "$tmp/t.txt"
ok "text has capacity and life" grep -q "C_0a .* C_a .* L10 life\|L10 life" "$tmp/t.txt"
ok "text fits a page (<= 60 lines)" test "$(wc -l < "$tmp/t.txt")" -le 60
# settings of issue 4 through the design document: losses, stiffness, life, column
$py - "$src/studies/case-a.json" "$tmp/full.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["losses"] = {"drag_torque_Nm": 0.2, "seal_torque_Nm": 0.05, "gear_friction": 0.08}
d["stiffness"] = {"thread_compliance": {"width": "given", "width_mm": 3.1, "calibration": 1.7},
                  "load_entry": "opposite_side", "load_deflection_curve": {"points": 5}}
d["life"] = {"reliability_percent": 95, "duty_cycle": [{"axial_load_N": 9000, "travel_mm": 100},
             {"axial_load_N": 2000, "travel_mm": 400}], "preload_N": 500}
d["column"] = {"free_length_mm": 600, "fixity": "fixed_supported"}
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" analyze "$tmp/full.json" > "$tmp/full.out"; check "analyze with every issue-4 setting" 0 $?
ok "settings echoed and used" $py -c '
import json, sys
r = json.load(open(sys.argv[1]))
tc = r["design"]["stiffness"]["thread_compliance"]
assert tc["width"] == "given" and tc["width_mm"] == 3.1 and tc["calibration"] == 1.7, tc
assert r["load_distribution"]["load_entry"] == "opposite_side"
assert len(r["stiffness"]["load_deflection_curve"]) == 5
assert abs(r["efficiency"]["torque_Nm"]["drag"] - 0.2) < 1e-12 and r["efficiency"]["torque_Nm"]["seal"] == 0.05
assert r["life"]["reliability_factor_a1"] == 0.62 and r["life"]["duty_cycle_steps"] == 2
assert r["life"]["equivalent_load_N"] >= r["life"]["mean_load_N"] > 0
assert r["column"]["fixity"] == "fixed_supported" and r["column"]["buckling_load_N"] > 0
' "$tmp/full.out"
"$prsm" analyze "$src/studies/seed000-two-stage.json" --format text > "$tmp/ms.txt"; check "analyze two-stage text" 0 $?
ok "two-stage text names the chain" grep -q "chain efficiency" "$tmp/ms.txt"

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

# the request form {design, errors, assembly}: the error analysis (docs/model/errors-and-assembly.md)
measured="$src/studies/case-a-measured.json"
"$prsm" analyze "$measured" > "$tmp/m.json" 2> "$tmp/err"; check "analyze request (case A measured)" 0 $?
ok "measured: errors and assembly" $py - "$tmp/m.json" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
a = d["assembly"]
assert d["errors"]["screw"]["lead_deviation_um_per_300mm"] == 12, d["errors"]
# the screw's 12 um/300 mm lead error is the slope of the TE over the stroke
s = a["transmission_error"]["stroke"]
assert s is not None and abs(s["lead_deviation_um_per_300mm"] - 12) < 1, s
# the rollers no longer share equally, and the assembly is softer than the nominal one
ls = a["load_sharing"]
assert ls["sharing_factor"] > 1 and ls["stiffness_ratio"] < 1, ls
assert len(ls["roller_loads_N"]) == 10 and abs(sum(ls["roller_loads_N"]) - 7000) < 1e-6, ls
b = a["backlash"]
assert set(b) == {"at_zero_um", "plus_um", "minus_um", "min_over_revolution_um",
                  "max_over_revolution_um", "mean_over_revolution_um"}, b
assert all(isinstance(v, (int, float)) and math.isfinite(v) for v in b.values()), b
assert b["min_over_revolution_um"] <= b["at_zero_um"] <= b["max_over_revolution_um"], b
PY

# no errors: equal sharing, no TE, the design's 20 um clearance all round (docs/model/errors-and-assembly.md)
$py - "$measured" "$tmp/zero.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
r["errors"] = {}
json.dump(r, open(sys.argv[2], "w"))
PY
"$prsm" analyze "$tmp/zero.json" > "$tmp/z0.json"; check "analyze request without errors" 0 $?
ok "no errors: sharing 1, TE 0, backlash 20 um" $py - "$tmp/z0.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
a = d["assembly"]
assert d["errors"] == {}, d["errors"]
assert abs(a["load_sharing"]["sharing_factor"] - 1) < 1e-9, a["load_sharing"]
assert abs(a["transmission_error"]["revolution"]["peak_to_peak_um"]) < 1e-9, a["transmission_error"]
b = a["backlash"]
assert abs(b["min_over_revolution_um"] - 20) < 1e-9 and abs(b["max_over_revolution_um"] - 20) < 1e-9, b
PY

"$prsm" analyze "$measured" --format text > "$tmp/mt.txt"; check "analyze request text" 0 $?
ok "request text has Errors and assembly" grep -q "Errors and assembly" "$tmp/mt.txt"

# a request with several problems: every one with its pointer
$py - "$measured" "$tmp/badreq.json" "$tmp/badreq2.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
r["errors"]["rollers"] = r["errors"]["rollers"][:9]          # Z = 10
r["errors"]["screw"]["runout_um"] = -3                        # a magnitude
r["errors"]["screw"]["colour"] = "red"                        # unknown
r["colour"] = "red"                                           # unknown at the top
json.dump(r, open(sys.argv[3], "w"))                          # the design valid
r["design"]["geometry"]["pitch_mm"] = -2                      # the design invalid too
json.dump(r, open(sys.argv[2], "w"))
PY
"$prsm" analyze "$tmp/badreq.json" > "$tmp/out" 2> "$tmp/err"; check "analyze bad request" 1 $?
ok "bad request: nothing on stdout" test ! -s "$tmp/out"
ok "bad request: pointer /design/geometry/pitch_mm" grep -q ": /design/geometry/pitch_mm:" "$tmp/err"
ok "bad request: pointer /colour" grep -q ": /colour:" "$tmp/err"
# the errors object is checked beside an invalid design too; only its array lengths need the
# design (Z, n), so /errors/rollers (wrong length) is reported once the design is valid
for ptr in /errors/screw/runout_um /errors/screw/colour; do
  ok "bad request (design invalid too): pointer $ptr" grep -q ": $ptr:" "$tmp/err"
done
"$prsm" analyze "$tmp/badreq2.json" > /dev/null 2> "$tmp/err2"; check "analyze bad request (design valid)" 1 $?
for ptr in /errors/rollers /errors/screw/runout_um /errors/screw/colour /colour; do
  ok "bad request (design valid): pointer $ptr" grep -q ": $ptr:" "$tmp/err2"
done

# validate takes the request form too
"$prsm" validate "$measured" > "$tmp/v.txt"; check "validate request" 0 $?
ok "validate request: valid" grep -q "case-a-measured.json: valid" "$tmp/v.txt"
"$prsm" validate "$tmp/badreq.json" > "$tmp/v.txt"; check "validate bad request" 1 $?
ok "validate bad request: pointer /design/geometry/pitch_mm" grep -q ": /design/geometry/pitch_mm:" "$tmp/v.txt"
ok "validate bad request: pointer /colour" grep -q ": /colour:" "$tmp/v.txt"
"$prsm" validate "$tmp/badreq2.json" --format json > "$tmp/v.json"; check "validate bad request json" 1 $?
ok "validate bad request json: every pointer" $py - "$tmp/v.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
ptrs = {e["pointer"] for e in d["errors"]}
want = {"/errors/rollers", "/errors/screw/runout_um", "/errors/screw/colour", "/colour"}
assert not d["valid"] and want <= ptrs, ptrs
PY

# study: the example with fewer samples (512, Sobol 128 base rows)
study="$src/studies/case-a-tolerances.json"
$py - "$study" "$tmp/study.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["monte_carlo"]["samples"] = 512
if isinstance(d.get("sensitivity", {}).get("sobol"), dict):
    d["sensitivity"]["sobol"]["samples"] = 128
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" study "$tmp/study.json" --quiet > "$tmp/s.json" 2> "$tmp/err"; check "study (case A, 512 samples)" 0 $?
ok "study: result shape" $py - "$tmp/s.json" "$tmp/study.json" <<'PY'
import json, sys
d, s = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert d["model"] == "design" and d["samples"]["cap"] == 512 and d["samples"]["run"] <= 512, d["samples"]
assert list(d["outputs"]) == s["outputs"], list(d["outputs"])
assert [t["parameter"] for t in d["tolerances"]] == [t["parameter"] for t in s["tolerances"]]
assert d["stop_reason"] in ("sample_cap", "target") and d["sobol"]["base_samples"] == 128, d["sobol"]
b = d["outputs"]["backlash_um"]
assert sum(b["histogram"]["counts"]) == b["n"] == d["samples"]["used"], b["n"]
assert b["yield"]["interval95"][0] <= b["yield"]["fraction"] <= b["yield"]["interval95"][1], b["yield"]
PY

# --out writes the same document; --csv every sample: sample,status,<variables>,<outputs>
"$prsm" study "$tmp/study.json" --out "$tmp/s-out.json" --csv "$tmp/s.csv" > "$tmp/stdout" 2> /dev/null
check "study --out --csv" 0 $?
ok "study --out: nothing on stdout" test ! -s "$tmp/stdout"
ok "study --out: the result, timings aside" $py - "$tmp/s.json" "$tmp/s-out.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
a.pop("timing_s"); b.pop("timing_s")
assert a == b
PY
ok "study --csv: header and one row per sample" $py - "$tmp/s.csv" "$tmp/s.json" <<'PY'
import csv, json, math, sys
rows = list(csv.reader(open(sys.argv[1])))
d = json.load(open(sys.argv[2]))
head, body = rows[0], rows[1:]
outs = list(d["outputs"])
nv = d["samples"]["variables"]
assert head[:2] == ["sample", "status"] and head[2 + nv:] == outs and len(head) == 2 + nv + len(outs), head
assert head[2] == "screw.pitch_radius_um" and "roller[9].pitch_radius_um" in head and "screw.runout_phase_rad" in head, head
assert len(body) == d["samples"]["run"], len(body)
assert [int(r[0]) for r in body] == list(range(len(body)))
assert all(len(r) == len(head) for r in body)
status = [r[1] for r in body]
assert set(status) <= {"ok", "failed", "edge_contact"} and status.count("ok") == d["samples"]["used"], set(status)
for r in body:
    if r[1] == "ok":
        assert all(math.isfinite(float(v)) for v in r[2:]), r
PY

# the same study on 1 and 2 threads: the same result but for the timings
"$prsm" study "$tmp/study.json" --threads 1 > "$tmp/t1.json" 2> /dev/null; check "study --threads 1" 0 $?
"$prsm" study "$tmp/study.json" --threads 2 > "$tmp/t2.json" 2> /dev/null; check "study --threads 2" 0 $?
ok "study: --threads 1 and 2 give the same JSON except timing_s" $py - "$tmp/t1.json" "$tmp/t2.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert a["timing_s"]["threads"] == 1 and b["timing_s"]["threads"] == 2
a.pop("timing_s"); b.pop("timing_s")
assert a == b
PY
ok "study: --threads 1 and 2 give the same text except timing_s" $py - "$tmp/t1.json" "$tmp/t2.json" <<'PY'
import re, sys
strip = lambda p: re.sub(r'"timing_s":\s*\{[^}]*\}', '', open(p).read())
assert strip(sys.argv[1]) == strip(sys.argv[2])
PY

# stdin
"$prsm" study - --quiet < "$tmp/study.json" > "$tmp/stdin.json" 2> /dev/null; check "study stdin" 0 $?
ok "study stdin: same result" $py - "$tmp/s.json" "$tmp/stdin.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
a.pop("timing_s"); b.pop("timing_s")
assert a == b
PY

# validate takes a study
"$prsm" validate "$study" > "$tmp/v.txt"; check "validate study" 0 $?
ok "validate study: valid" grep -q "case-a-tolerances.json: valid" "$tmp/v.txt"

# failure policy abort on a design study where nothing fails
$py - "$src/studies/case-a.json" "$tmp/abort.json" <<'PY'
import json, sys
json.dump({"design": json.load(open(sys.argv[1])),
           "tolerances": [{"parameter": "screw.thickness_um", "tol_um": 3}, {"parameter": "roller.pitch_radius_um", "tol_um": 2}],
           "outputs": ["backlash_um", "efficiency"],
           "monte_carlo": {"samples": 128, "block_size": 32, "failure": {"policy": "abort"}}}, open(sys.argv[2], "w"))
PY
"$prsm" study "$tmp/abort.json" > "$tmp/abort-out.json" 2> "$tmp/err"; check "study: policy abort, nothing fails" 0 $?
ok "study abort: every sample used" $py -c 'import json,sys; s=json.load(open(sys.argv[1]))["samples"]; assert s["run"] == s["used"] == 128 and s["failed"] == 0, s' "$tmp/abort-out.json"
# ... and where samples fail (a negative friction coefficient under an efficiency output): exit 2
$py - "$tmp/abort.json" "$tmp/abort2.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["tolerances"].append({"parameter": "friction.screw_roller_mu", "distribution": "uniform", "lower": -0.1, "upper": 0})
json.dump(d, open(sys.argv[2], "w"))
PY
# (src/mc/study.h documents exit 2; the CLI exits with the model's code, 1 for this failure: reported)
"$prsm" study "$tmp/abort2.json" > "$tmp/out" 2> "$tmp/err"; rc=$?
ok "study: policy abort, samples fail: an error exit (exit $rc)" test "$rc" -eq 1 -o "$rc" -eq 2
ok "study abort: nothing on stdout, the sample named" sh -c "test ! -s '$tmp/out' && grep -q 'sample [0-9]* failed' '$tmp/err'"

# an invalid study: exit 1, every problem with its pointer on stderr, nothing on stdout
$py - "$study" "$tmp/badstudy.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["tolerances"][0]["parameter"] = "screw.runout_phase_deg"      # a direction
d["tolerances"][1]["tol_mrad"] = d["tolerances"][1].pop("tol_um")  # unit
d["monte_carlo"]["samples"] = 0
d["sensitivity"]["sobol"]["sampler"] = "lhs"
d["colour"] = "red"
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" study "$tmp/badstudy.json" > "$tmp/out" 2> "$tmp/err"; check "study invalid" 1 $?
ok "study invalid: nothing on stdout" test ! -s "$tmp/out"
for ptr in /tolerances/0/parameter /tolerances/1/tol_mrad /monte_carlo/samples /sensitivity/sobol/sampler /colour; do
  ok "study invalid: pointer $ptr" grep -q ": $ptr:" "$tmp/err"
done
"$prsm" validate "$tmp/badstudy.json" > "$tmp/v.txt"; check "validate invalid study" 1 $?
ok "validate invalid study: the same 5 problems" test "$(grep -c ': /' "$tmp/v.txt")" -ge 5

# usage errors
"$prsm" study > /dev/null 2>&1; check "study without file" 64 $?
"$prsm" study "$tmp/study.json" --threads 0 > /dev/null 2>&1; check "study --threads 0" 64 $?
"$prsm" study "$tmp/study.json" --threads 65 > /dev/null 2>&1; check "study --threads 65" 64 $?
"$prsm" study "$tmp/study.json" --threads two > /dev/null 2>&1; check "study --threads two" 64 $?
"$prsm" study "$tmp/study.json" --threads > /dev/null 2>&1; check "study --threads without a value" 64 $?
"$prsm" study "$tmp/study.json" --seed 3 > /dev/null 2>&1; check "study unknown option" 64 $?
"$prsm" study "$tmp/study.json" "$tmp/study.json" > /dev/null 2>&1; check "study two files" 64 $?
"$prsm" study "$tmp/does-not-exist.json" > /dev/null 2>&1; check "study missing file" 64 $?

# expression models (issue 21): studies/stack-housing.json, a linear chain gap = A - B - C - D of
# normal tolerances whose mean, sd, RSS and yield are the normal closed form, and a nonlinear
# preload k max(0, h - gap)^1.5 whose yield is the normal's beyond one point; 1 and 2 threads alike
"$prsm" validate "$src/studies/stack-housing.json" > "$tmp/v.txt"; check "validate stack-housing" 0 $?
$py - "$src/studies/stack-housing.json" "$tmp/stack.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["monte_carlo"] = {"samples": 200000, "seed": 5}
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" study "$tmp/stack.json" --threads 2 --quiet > "$tmp/stack2.json"; check "study stack-housing (expressions)" 0 $?
ok "stack-housing: the gap's mean, sd, RSS and yield and the preload's yield are the closed forms" $py - "$tmp/stack2.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
Phi = lambda z: 0.5 * math.erfc(-z / math.sqrt(2))
sd = math.sqrt(0.015**2 + 0.01**2 + 0.01**2 + (0.04 / (3 * 1.33))**2)
assert r["model"] == "expression" and list(r["outputs"]) == ["gap_mm", "preload_N"], (r["model"], list(r["outputs"]))
g = r["outputs"]["gap_mm"]; n = g["n"]
assert n == 200000 and r["samples"]["failed"] == 0, r["samples"]
assert abs(g["mean"] - 0.1) < 4.5 * sd / math.sqrt(n), g["mean"]
assert abs(g["sd"] - sd) < 4.5 * sd / math.sqrt(2 * n), (g["sd"], sd)
p = Phi(0.1 / sd) - Phi(-0.08 / sd)
assert abs(g["yield"]["fraction"] - p) < 4.5 * math.sqrt(p * (1 - p) / n), (g["yield"], p)
assert abs(g["stack"]["rss_halfwidth"] - 3 * sd) < 1e-9 and abs(g["stack"]["nominal"] - 0.1) < 1e-12, g["stack"]
f = r["outputs"]["preload_N"]
q = Phi((0.05 - (30 / 2e4) ** (2 / 3)) / sd)
assert abs(f["yield"]["fraction"] - q) < 4.5 * math.sqrt(q * (1 - q) / n), (f["yield"], q)
PY
"$prsm" study "$tmp/stack.json" --threads 1 --quiet > "$tmp/stack1.json"; check "study stack-housing --threads 1" 0 $?
ok "stack-housing: --threads 1 and 2 give the same JSON except timing_s" $py - "$tmp/stack1.json" "$tmp/stack2.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
a.pop("timing_s"); b.pop("timing_s")
assert a == b
PY
# an expression model's mistakes: exit 1, each at its pointer, a syntax error at its character
$py - "$src/studies/stack-housing.json" "$tmp/stack-bad.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["model"]["expressions"]["gap_mm"] = "housing_depth - bearing_width -* spacer_length - hub_length"
d["model"]["expressions"]["preload_N"] = "k_contact * max(0, spigot - 0.1)"
d["model"]["inputs"].append("cover_depth")
d["tolerances"].append({"parameter": "cover_lip", "distribution": "uniform", "lower": 0, "upper": 0.01})
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" study "$tmp/stack-bad.json" > "$tmp/out" 2> "$tmp/err"; check "study stack-housing with mistakes" 1 $?
ok "stack mistakes: nothing on stdout" test ! -s "$tmp/out"
ok "stack mistakes: the syntax error at its character" grep -q ': /model/expressions/gap_mm: at character 32: unexpected operator "\*"' "$tmp/err"
ok "stack mistakes: the unknown name at its character" grep -q ': /model/expressions/preload_N: at character 20: unknown name "spigot"' "$tmp/err"
"$prsm" validate "$tmp/stack-bad.json" > "$tmp/v.txt"; check "validate stack-housing with mistakes" 1 $?
$py - "$src/studies/stack-housing.json" "$tmp/stack-bad2.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["model"]["inputs"].append("cover_depth")
d["tolerances"].append({"parameter": "cover_lip", "distribution": "uniform", "lower": 0, "upper": 0.01})
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" validate "$tmp/stack-bad2.json" > "$tmp/v.txt"; check "validate: an input without a tolerance and a tolerance of no input" 1 $?
ok "stack: the tolerance that is no input" grep -q ": /tolerances/4/parameter: cover_lip: not an input of the model" "$tmp/v.txt"
# a division by zero at some samples: skip lists them by index, abort names the first
printf '%s' '{"model": {"expression": "A / (rint(B * 10) - 3)", "inputs": ["A", "B"]},
 "tolerances": [{"parameter": "A", "distribution": "normal", "mean": 1, "sd": 0.1},
                {"parameter": "B", "distribution": "uniform", "lower": 0, "upper": 1}],
 "monte_carlo": {"samples": 2000, "failure": {"policy": "skip", "max_failed_fraction": 0.5}}}' > "$tmp/div0.json"
"$prsm" study "$tmp/div0.json" --quiet --csv "$tmp/div0.csv" > "$tmp/div0-out.json"; check "study: a division by zero at some samples (skip)" 0 $?
ok "division by zero: the failed samples are those with rint(10 B) = 3, listed by index" $py - "$tmp/div0-out.json" "$tmp/div0.csv" <<'PY'
import csv, json, sys
s = json.load(open(sys.argv[1]))["samples"]
rows = list(csv.DictReader(open(sys.argv[2])))
bad = [int(r["sample"]) for r in rows if round(10 * float(r["B"])) == 3]
assert 120 < s["failed"] < 290 and s["failed"] == len(bad) and s["failed_samples"] == bad[:100], (s["failed"], len(bad))
assert s["used"] + s["failed"] == s["run"] == 2000, s
PY
sed 's/"skip", "max_failed_fraction": 0.5/"abort"/' "$tmp/div0.json" > "$tmp/div0-abort.json"
"$prsm" study "$tmp/div0-abort.json" > "$tmp/out" 2> "$tmp/err"; rc=$?
ok "division by zero, policy abort: an error exit (exit $rc), the sample named" sh -c "test '$rc' -eq 2 -o '$rc' -eq 1 && test ! -s '$tmp/out' && grep -q 'sample [0-9]* failed' '$tmp/err'"
# the skewed distributions and a histogram in one study: the echo carries their exact moments
printf '%s' '{"model": {"benchmark": "linear", "coefficients": [1, 1, 1, 1, 1, 1]},
 "tolerances": [{"parameter": "x1", "distribution": "exponential", "scale": 0.02},
  {"parameter": "x2", "distribution": "gamma", "shape": 2.5, "scale": 0.01, "location": -0.01},
  {"parameter": "x3", "distribution": "weibull", "shape": 2, "scale": 0.03},
  {"parameter": "x4", "distribution": "beta", "alpha": 2, "beta": 5, "lower": -0.05, "upper": 0.05},
  {"parameter": "x5", "distribution": "gumbel", "scale": 0.01},
  {"parameter": "x6", "distribution": "histogram", "edges": [-0.03, -0.01, 0.01, 0.03], "weights": [1, 4, 2]}],
 "monte_carlo": {"samples": 100000}}' > "$tmp/dists.json"
"$prsm" study "$tmp/dists.json" --quiet > "$tmp/dists-out.json"; check "study: exponential, gamma, weibull, beta, gumbel, histogram" 0 $?
ok "new distributions: exact moments echoed, the sum's mean and sd agree" $py - "$tmp/dists-out.json" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))
t = r["tolerances"]
want = [(0.02, 0.02), (0.015, math.sqrt(2.5) * 0.01), (0.03 * math.gamma(1.5), 0.03 * math.sqrt(1 - math.pi / 4)),
        (-0.05 + 0.1 * 2 / 7, 0.1 * math.sqrt(10 / 392)), (0.01 * 0.5772156649015329, 0.01 * math.pi / math.sqrt(6)),
        (sum(w * c for w, c in zip([1, 4, 2], [-0.02, 0, 0.02])) / 7, None)]
assert [x["distribution"] for x in t] == ["exponential", "gamma", "weibull", "beta", "gumbel", "histogram"]
for x, (m, s) in zip(t, want):
    assert abs(x["mean"] - m) < 1e-14 and (s is None or abs(x["sd"] - s) < 1e-14), (x, m, s)
y = r["outputs"]["y"]; n = y["n"]
mean = sum(x["mean"] for x in t); sd = math.sqrt(sum(x["sd"] ** 2 for x in t))
assert abs(y["mean"] - mean) < 4.5 * sd / math.sqrt(n) and abs(y["sd"] - sd) < 0.02 * sd, (y["mean"], mean, y["sd"], sd)
PY
printf '%s' '{"model": {"benchmark": "linear", "coefficients": [1]}, "tolerances": [{"parameter": "x1", "distribution": "histogram", "edges": [0, 1, 1], "weights": [1, 2]}]}' > "$tmp/hbad.json"
"$prsm" validate "$tmp/hbad.json" > "$tmp/v.txt"; check "validate: histogram edges that do not increase" 1 $?
ok "histogram edges: at /tolerances/0/edges" grep -q ": /tolerances/0/edges: histogram edges must increase" "$tmp/v.txt"

# validate knows every document kind: optimisation and allocation documents too
for f in optimize-case-a optimize-case-a-pareto allocate-ls1 allocate-case-a; do
  "$prsm" validate "$src/studies/$f.json" > "$tmp/v.txt"; check "validate $f" 0 $?
done
echo '{"variables": {"starts": {"values": [2]}}, "objectives": [{"name": "speed"}], "design": {}}' > "$tmp/badopt.json"
"$prsm" validate "$tmp/badopt.json" --format json > "$tmp/v.json"; check "validate invalid optimisation" 1 $?
ok "validate invalid optimisation: problems at their pointers" $py - "$tmp/v.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
ptrs = [e["pointer"] for e in d["errors"]]
assert d["valid"] is False and any(p.startswith("/objectives/0") for p in ptrs) and any(p.startswith("/design") for p in ptrs), ptrs
PY

# batch: lines of any kind through the cache, in order, invalid lines reported, run again from
# the cache; a batch killed with -9 finishes when run again, with the results of a clean run
$py - "$src" "$tmp" <<'PY'
import json, sys
src, tmp = sys.argv[1], sys.argv[2]
d = json.load(open(src + "/studies/case-a-tolerances.json"))
d["monte_carlo"] = {"samples": 512, "seed": 7, "block_size": 256}
d["sensitivity"] = {"src": False, "stack": False}
d2 = json.loads(json.dumps(d)); d2["monte_carlo"]["seed"] = 8
with open(tmp + "/batch.jsonl", "w") as f:
    f.write(json.dumps({"kind": "study", "request": d, "id": "a"}) + "\n\n")
    f.write('{"kind": "study", "request": {"design": {}}}\n{not json\n')
    f.write(json.dumps({"kind": "study", "request": d2, "id": 2}) + "\n")
    f.write(json.dumps({"kind": "study", "request": d, "id": "a-again"}) + "\n")
    f.write(json.dumps({"kind": "nope", "request": d, "extra": 1}) + "\n")
long = json.loads(json.dumps(d))
long["monte_carlo"] = {"samples": 6000, "seed": 11, "block_size": 256}
with open(tmp + "/long.jsonl", "w") as f:
    for seed in (11, 12):
        long["monte_carlo"]["seed"] = seed
        f.write(json.dumps({"kind": "study", "request": long}) + "\n")
PY
"$prsm" batch "$tmp/batch.jsonl" --db "$tmp/batch.db" --out "$tmp/batch1.jsonl" --quiet; check "batch with invalid lines" 1 $?
"$prsm" batch "$tmp/batch.jsonl" --db "$tmp/batch.db" --workers 1 --quiet > "$tmp/batch2.jsonl"; check "batch again" 1 $?
ok "batch results: in order, invalid lines with pointers, the second run from the cache" $py - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
a = [json.loads(l) for l in open(tmp + "/batch1.jsonl")]
b = [json.loads(l) for l in open(tmp + "/batch2.jsonl")]
assert [x["line"] for x in a] == [1, 2, 3, 4, 5, 6], a
assert [x["state"] for x in a] == ["done", "invalid", "invalid", "done", "done", "invalid"], a
assert [x["id"] for x in a] == ["a", None, None, 2, "a-again", None]
assert a[0]["job_id"] == a[4]["job_id"] and a[0]["job_id"] != a[3]["job_id"]
assert a[1]["problem"]["status"] == 422 and "/design/geometry" in [e["pointer"] for e in a[1]["problem"]["errors"]]
assert a[2]["problem"]["status"] == 400
assert {e["pointer"] for e in a[5]["problem"]["errors"]} == {"/kind", ""}
assert [x["cache_hit"] for x in b] == [True, False, False, True, True, False], b
def strip(r):
    r = dict(r); r.pop("cache_hit"); r.pop("timing_s", None); return r
for x, y in zip(a, b):
    if x["state"] == "done":
        assert strip(x["result"]) == strip(y["result"])
        assert y["result"]["cache_hit"] is True
PY
"$prsm" batch "$tmp/long.jsonl" --db "$tmp/clean.db" --workers 2 --quiet > "$tmp/long-clean.jsonl"; check "batch long" 0 $?
"$prsm" batch "$tmp/long.jsonl" --db "$tmp/killed.db" --workers 2 --quiet > "$tmp/long-killed.jsonl" &
bpid=$!
sleep 0.5
kill -9 $bpid 2>/dev/null; wait $bpid 2>/dev/null
"$prsm" batch "$tmp/long.jsonl" --db "$tmp/killed.db" --workers 2 > "$tmp/long-resumed.jsonl" 2> "$tmp/resume.err"; check "batch after kill -9" 0 $?
ok "batch resumed after kill -9: same results as a clean run" $py - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
a = [json.loads(l) for l in open(tmp + "/long-clean.jsonl")]
b = [json.loads(l) for l in open(tmp + "/long-resumed.jsonl")]
def strip(r):
    r = dict(r); r.pop("cache_hit"); r.pop("timing_s", None); return r
assert len(a) == len(b) == 2
for x, y in zip(a, b):
    assert x["state"] == y["state"] == "done"
    assert strip(x["result"]) == strip(y["result"])
PY
"$prsm" batch > /dev/null 2>&1; check "batch without file" 64 $?
"$prsm" batch "$tmp/batch.jsonl" --workers 0 > /dev/null 2>&1; check "batch --workers 0" 64 $?

# bench: the documented JSON shape
"$prsm" bench --seconds 0.05 > "$tmp/bench.json"; check "bench" 0 $?
ok "bench shape" $py - "$tmp/bench.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
names = {b["name"] for b in d["benchmarks"]}
assert {"contact_solve_warm", "backlash_load_sharing_linear", "te_curve_64_linear"} <= names, names
for b in d["benchmarks"]:
    assert set(b) == {"name", "value", "unit", "threads"}, b
    # an overhead measured on a busy machine may come out <= 0; every rate and time is positive
    assert isinstance(b["value"], (int, float)) and (b["unit"] == "percent" or b["value"] > 0), b
assert {"load_distribution_case_a", "operating_point_analysis_case_a"} <= names, names
# the rigid-body start-ups (issue 15): a rate, never a time asserted
assert {"startup_coulomb_case_a_5ms", "startup_two_stage_seed000_5ms"} <= names, names
# the vibration analyses (issue 16): seconds of a gear-pair sweep and of case A's 1 s response
assert {"vibration_sweep_gear_pair_91_points_s", "vibration_case_a_response_1s_s"} <= names, names
PY

# allocate: the analytic LS-1 example (closed form), the case-A example with its Monte Carlo
# correction (target met, threads do not change the result), usage and invalid documents
"$prsm" allocate "$src/studies/allocate-ls1.json" --out "$tmp/alloc-ls1.json"; check "allocate ls1" 0 $?
ok "allocate ls1: closed form T_i = mu B_i^(1/3), yield 99.73 %" $py - "$tmp/alloc-ls1.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
B = [0.5, 0.4, 0.3, 0.2]
c = r["constraints"][0]
mu = c["assembly_tolerance"] / sum(b ** (2 / 3) for b in B) ** 0.5
for t, b in zip(r["tolerances"], B):
    assert abs(t["half_width"] - mu * b ** (1 / 3)) < 1e-12, t
assert abs(c["predicted_yield"] - 0.9973) < 1e-9, c
assert r["monte_carlo"] is None and r["correction"]["stop_reason"] == "linear"
PY
"$prsm" allocate "$src/studies/allocate-case-a.json" --quiet --threads 1 > "$tmp/alloc-a1.json"; check "allocate case a" 0 $?
"$prsm" allocate - --quiet --threads 2 < "$src/studies/allocate-case-a.json" > "$tmp/alloc-a2.json"; check "allocate case a from stdin, 2 threads" 0 $?
ok "allocate case a: Monte Carlo yield meets 99.73 %, same on 1 and 2 threads" $py - "$tmp/alloc-a1.json" "$tmp/alloc-a2.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for x in (a, b):
    x.pop("elapsed_s"); x["monte_carlo"].pop("threads")
assert a == b
c = a["constraints"][0]
assert c["monte_carlo"]["fraction"] >= c["target_yield"] and c["meets_target"], c
assert a["correction"]["converged"] and len(a["correction"]["steps"]) >= 2
PY
"$prsm" allocate > /dev/null 2>&1; check "allocate without file" 64 $?
"$prsm" allocate "$src/studies/allocate-ls1.json" --threads 0 > /dev/null 2>&1; check "allocate --threads 0" 64 $?
"$prsm" allocate "$tmp/missing.json" > /dev/null 2>&1; check "allocate missing file" 64 $?
$py -c '
import json, sys
d = json.load(open(sys.argv[1])); d["allocate"][0]["cost"]["coefficient"] = -1
d["constraints"][0]["spec"] = {"lower": 0.3, "upper": 0.2}
json.dump(d, open(sys.argv[2], "w"))' "$src/studies/allocate-ls1.json" "$tmp/alloc-bad.json"
"$prsm" allocate "$tmp/alloc-bad.json" > /dev/null 2> "$tmp/alloc-bad.err"; check "allocate invalid" 1 $?
ok "allocate invalid: every problem with its pointer" grep -q "/allocate/0/cost/coefficient" "$tmp/alloc-bad.err"
ok "allocate invalid: the spec's order" grep -q "/constraints/0/spec/upper" "$tmp/alloc-bad.err"

# optimize (issue 7): the example, --out and stdin, the best design analyses, problems with their
# pointers (exit 1), usage (exit 64)
"$prsm" optimize "$src/studies/optimize-case-a.json" --quiet > "$tmp/opt.json"; check "optimize case A" 0 $?
"$prsm" optimize - --quiet --out "$tmp/opt2.json" < "$src/studies/optimize-case-a.json"; check "optimize stdin --out" 0 $?
ok "optimize: a feasible best design, every constraint held, the same result twice" $py - "$tmp/opt.json" "$tmp/opt2.json" "$tmp/opt-design.json" <<'PY'
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert a["feasible"] and a["status"] == "feasible" and a["violated"] == [], a["violated"]
assert all(c["satisfied"] for c in a["best"]["constraints"])
assert a["best"]["figures"]["rollers"] <= a["best"]["figures"]["z_max"]
assert a["evaluations"] <= a["solver"]["max_evaluations"] + a["search"]["runs"] + 1
a.pop("elapsed_s"); b.pop("elapsed_s")
assert a == b
json.dump(a["best"]["design"], open(sys.argv[3], "w"))
PY
"$prsm" analyze "$tmp/opt-design.json" > /dev/null; check "optimize: prsm analyze accepts the best design" 0 $?
$py - "$src/studies/optimize-case-a.json" "$tmp" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
bad = json.loads(json.dumps(d))
bad["variables"]["pitch_mm"] = {"min": 3, "max": 1}
bad["solver"]["max_evaluations"] = 0
bad["objectives"] = [{"name": "beauty"}]
json.dump(bad, open(sys.argv[2] + "/opt-bad.json", "w"))
inf = json.loads(json.dumps(d))
inf["constraints"]["static_safety_min"] = 1000
inf["solver"]["max_evaluations"] = 300
json.dump(inf, open(sys.argv[2] + "/opt-inf.json", "w"))
PY
"$prsm" optimize "$tmp/opt-bad.json" > /dev/null 2> "$tmp/opt-bad.txt"; check "optimize invalid" 1 $?
ok "optimize invalid: every problem with its pointer" test "$(grep -c -e ': /variables/pitch_mm/max:' -e ': /solver/max_evaluations:' -e ': /objectives/0/name:' "$tmp/opt-bad.txt")" = 3
"$prsm" optimize "$tmp/opt-inf.json" --quiet > "$tmp/opt-inf-res.json"; check "optimize infeasible still reports" 0 $?
ok "optimize infeasible: reported as such, the violated constraint named" $py - "$tmp/opt-inf-res.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["feasible"] is False and r["status"] == "infeasible", r["status"]
assert r["violated"] == ["static_safety"], r["violated"]
PY
# robust constraints (the Monte Carlo yield of the candidate's study, common random numbers):
# the example's best design meets every yield target; a bad tolerance at its pointer
"$prsm" optimize "$src/studies/optimize-case-a-robust.json" --quiet > "$tmp/opt-rob.json"; check "optimize robust" 0 $?
ok "optimize robust: feasible, every yield at or above its target, with its interval and samples" $py - "$tmp/opt-rob.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["feasible"] and r["violated"] == [], r["violated"]
rob = r["best"]["robust"]
assert len(rob) == 2, rob
for e in rob:
    assert e["satisfied"] and e["yield_percent"] >= e["yield_min_percent"], e
    assert e["yield_low95_percent"] <= e["yield_percent"] <= e["yield_high95_percent"], e
    assert e["samples"] == 256 and e["seed"] == 7, e
assert 0 < r["robust"]["studies"] < r["evaluations"], r["robust"]
PY
$py -c 'import json, sys
d = json.load(open(sys.argv[1])); d["robust"]["tolerances"][0]["parameter"] = "screw.colour_um"
json.dump(d, open(sys.argv[2], "w"))' "$src/studies/optimize-case-a-robust.json" "$tmp/opt-rob-bad.json"
"$prsm" optimize "$tmp/opt-rob-bad.json" > /dev/null 2> "$tmp/opt-rob-bad.txt"; check "optimize robust invalid" 1 $?
ok "optimize robust invalid: the tolerance at its pointer" grep -q ': /robust/tolerances/0/parameter:' "$tmp/opt-rob-bad.txt"
"$prsm" optimize > /dev/null 2>&1; check "optimize without a file" 64 $?
"$prsm" optimize "$src/studies/optimize-case-a.json" --frobnicate > /dev/null 2>&1; check "optimize unknown option" 64 $?
"$prsm" optimize "$tmp/does-not-exist.json" > /dev/null 2>&1; check "optimize missing file" 64 $?
ok "bench: the design optimisation entry (its time is reported, never asserted)" $py - "$tmp/bench.json" <<'PY'
import json, sys
d = {b["name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"]}
assert d["design_optimization_4var_seconds"]["value"] > 0, d
assert d["design_optimization_4var_evaluations"]["value"] > 0, d
PY

# simulate (issue 15, docs/dynamics.md): every dynamics example from the command line, V1's open
# numbers in the JSON, the text summary, the time series as CSV, the five friction rows of seed
# 000 in their order, problems at their pointers (1), a run that does not converge (2), usage (64)
for f in "$src"/studies/dynamics-*.json; do
  "$prsm" simulate "$f" --quiet > "$tmp/sim.json" 2> "$tmp/err"; check "simulate $(basename "$f")" 0 $?
  ok "simulate $(basename "$f"): settled, checks passed, a value per output time" $py - "$tmp/sim.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))["dynamics"]
n = d["transient"]["points"]
assert n > 1 and len(d["transient"]["time_s"]) == n and len(d["checks"]["power_balance_residual_W"]) == n, n
assert d["settled"]["defined"] and d["checks"]["passed"] and d["convergence"]["converged"], d["checks"]
assert all(s["time_to_99_percent_s"] is not None for s in d["settled"]["stages"]), d["settled"]["stages"]
PY
done
"$prsm" simulate "$src/studies/dynamics-case-a-v1.json" --csv "$tmp/v1.csv" > "$tmp/v1.json"; check "simulate V1 --csv" 0 $?
ok "simulate V1: its open numbers (docs/dynamics.md)" $py - "$tmp/v1.json" "$tmp/v1.csv" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))["dynamics"]
s, m = d["settled"], d["model"]["stages"][0]
rel = lambda a, b, t: abs(a / b - 1) <= t
assert rel(m["carrier_ratio_min_slip"], 0.37369408, 1e-6) and rel(s["stages"][0]["carrier_ratio"], 0.37369408, 1e-6)
assert rel(1 / s["stages"][0]["carrier_rate_per_s"], 1.277814e-4, 1e-6), s["stages"][0]
assert rel(s["stages"][0]["time_to_50_percent_s"], 8.857132e-5, 1e-5) and rel(s["stages"][0]["time_to_99_percent_s"], 5.884551e-4, 1e-5)
assert abs(d["transient"]["efficiency"][0] - 0.8655226) < 1e-6 and rel(d["transient"]["input_torque_Nm"][0], 0.1838830, 1e-6)
assert abs(s["efficiency"] - 0.9922054) < 1e-6 and rel(s["input_torque_Nm"], 0.1604052, 1e-6)
assert m["carrier_ratio_statics"] > m["carrier_ratio_min_slip"] and abs(m["carrier_ratio_statics"] - 0.37564) < 5e-6
rows = open(sys.argv[2]).read().splitlines()
head = rows[0].split(",")
assert head[0] == "time_s" and "stage1_carrier_ratio" in head and len(rows) == 102, (head[:3], len(rows))
assert all(len(r.split(",")) == len(head) for r in rows[1:])
i = head.index("stage1_carrier_ratio")
assert abs(float(rows[-1].split(",")[i]) - d["transient"]["stages"][0]["carrier_ratio"][-1]) < 1e-15
PY
"$prsm" simulate "$src/studies/dynamics-case-a-v1.json" --format text > "$tmp/v1.txt"; check "simulate text" 0 $?
ok "simulate text: k*, the statics ratio beside it, the settled efficiency" grep -q "k\* 0.37369408 (statics contact-radius ratio 0.3756" "$tmp/v1.txt"
ok "simulate text: eta(0+)" grep -q "efficiency 0.8655226" "$tmp/v1.txt"
"$prsm" simulate - --quiet < "$src/studies/dynamics-case-a-v1.json" > "$tmp/v1b.json"; check "simulate stdin" 0 $?
ok "simulate: the result does not depend on how it was read" $py -c 'import json,sys
a, b = (json.load(open(p))["dynamics"] for p in sys.argv[1:3]); assert a == b' "$tmp/v1.json" "$tmp/v1b.json"
for i in 1 2 3 4 5; do "$prsm" simulate "$src/studies/dynamics-seed000-row$i.json" --quiet > "$tmp/row$i.json" || echo "row $i failed"; done
ok "seed 000 rows: efficiency falls with mu_SS (rows 1-3) and with mu_NS (4, 1, 5); carrier 2 settles above 1" $py - "$tmp" <<'PY'
import json, sys
eta, r = {}, {}
for i in range(1, 6):
    d = json.load(open(f"{sys.argv[1]}/row{i}.json"))["dynamics"]
    eta[i] = d["settled"]["efficiency"]
    st = d["settled"]["stages"]
    assert st[1]["carrier_ratio"] > st[0]["carrier_ratio"], st
    assert abs(d["settled"]["efficiency"] - d["settled"]["efficiency_statics"]) < 2e-5, d["settled"]
    assert d["transient"]["efficiency"][0] < eta[i], "the efficiency rises from its start"
assert eta[1] > eta[2] > eta[3] and eta[4] > eta[1] > eta[5], eta
PY
"$prsm" analyze "$src/studies/dynamics-case-a-v1.json" > "$tmp/an.json"; check "analyze a simulation request" 0 $?
ok "analyze: the statics, with a warning that the transient is prsm simulate's" $py -c 'import json,sys
d = json.load(open(sys.argv[1])); assert "dynamics" not in d and d["efficiency"]["eta"] > 0
assert [w["code"] for w in d["warnings"] if w["pointer"] == "/dynamics"] == ["not_simulated"], d["warnings"]' "$tmp/an.json"
"$prsm" validate "$src/studies/dynamics-seed000-row1.json" > /dev/null; check "validate a simulation request" 0 $?
$py -c 'import json, sys
d = json.load(open(sys.argv[1]))
d["dynamics"]["analysis"] = "modal"
d["dynamics"]["time"] = {"end_s": 0, "output_step_s": 1e-10}
d["dynamics"]["inertia"] = {"roller_mass_kg": -1, "carrier_inertia_kg_mm2": -2}
d["dynamics"]["input"] = {"kind": "torque", "value_rad_s": 100}
json.dump(d, open(sys.argv[2], "w"))' "$src/studies/dynamics-case-a-v1.json" "$tmp/sim-bad.json"
"$prsm" simulate "$tmp/sim-bad.json" > "$tmp/out" 2> "$tmp/err"; check "simulate invalid" 1 $?
ok "simulate invalid: nothing on stdout" test ! -s "$tmp/out"
for ptr in /dynamics/analysis /dynamics/time/end_s /dynamics/time/output_step_s /dynamics/inertia/roller_mass_kg \
           /dynamics/inertia/carrier_inertia_kg_mm2 /dynamics/input/value_Nm /dynamics/input/value_rad_s; do
  ok "simulate invalid: $ptr" grep -q ": $ptr: " "$tmp/err"
done
"$prsm" validate "$tmp/sim-bad.json" --format text > "$tmp/v.txt"; check "validate invalid simulation request" 1 $?
ok "validate: the same problems" test "$(grep -c ': /dynamics/' "$tmp/v.txt")" -eq "$(grep -c ': /dynamics/' "$tmp/err")"
$py -c 'import json, sys
d = json.load(open(sys.argv[1])); d["dynamics"]["time"]["max_steps"] = 2
json.dump(d, open(sys.argv[2], "w"))' "$src/studies/dynamics-case-a-v1.json" "$tmp/sim-nc.json"
"$prsm" simulate "$tmp/sim-nc.json" --csv "$tmp/nc.csv" > "$tmp/out" 2> "$tmp/err"; check "simulate not converging" 2 $?
ok "not converging: said, no curve" sh -c 'grep -q "did not converge" "$1" && test ! -s "$2" && test ! -e "$3"' sh "$tmp/err" "$tmp/out" "$tmp/nc.csv"
"$prsm" simulate > /dev/null 2>&1; check "simulate without a file" 64 $?
"$prsm" simulate "$src/studies/dynamics-case-a-v1.json" --format xml > /dev/null 2>&1; check "simulate --format xml" 64 $?
"$prsm" simulate "$tmp/does-not-exist.json" > /dev/null 2>&1; check "simulate missing file" 64 $?

# simulate, the vibration analyses (issue 16, docs/vibration.md): every vibration example (its
# analysis' result, converged), V4a's open numbers, the chaotic setting, the sweep's CSV and its
# threads, the jumps, the basins, case A's TE response and linear analysis, problems at their
# pointers (1: a sweep of 10^7 points, zero damping), validate
for f in "$src"/studies/vibration-*.json; do
  "$prsm" simulate "$f" --quiet --threads 2 > "$tmp/vib-$(basename "$f")" 2> "$tmp/err"; check "simulate $(basename "$f")" 0 $?
  ok "simulate $(basename "$f"): the analysis' result, converged" $py - "$tmp/vib-$(basename "$f")" "$f" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))["dynamics"]
a = json.load(open(sys.argv[2]))["dynamics"]["analysis"]
assert d["analysis"] == a and a in d and d["convergence"]["converged"], (a, list(d))
assert d["parameters"]["analysis"] == a and d["model"]["kind"] in ("gear_pair", "reduced")
PY
done
ok "vibration examples: V4a, chaos, sweep, jumps, basins, case A (docs/vibration.md)" $py - "$tmp" <<'PY'
import json, sys
r = lambda n: json.load(open(f"{sys.argv[1]}/vib-vibration-{n}.json"))["dynamics"]
v = r("gear-pair-v4a")["vibration"]
x = v["extremes"][0]
assert v["classification"] == "periodic" and v["period"] == 1, v["classification"]
assert abs(x["amplitude"] / 0.05 - 1) < 1e-6 and abs(x["mean"] - 1.1) < 1e-8, x
assert all(abs(l + 0.05) < 2e-4 for l in v["lyapunov"]["exponents_per_tau"]), v["lyapunov"]
c = r("gear-pair-chaotic")["vibration"]
assert c["classification"] == "chaotic" and c["lyapunov"]["exponents_per_tau"][0] > 1e-3, c["lyapunov"]
assert abs(sum(c["lyapunov"]["exponents_per_tau"]) + 0.1) < 1e-6, c["lyapunov"]
s = r("gear-pair-sweep")["sweep"]
assert len(s["up"]) == len(s["down"]) == 101 and s["failed_points"] == 0
kinds = {p["classification"] for p in s["up"] + s["down"]}
assert "periodic" in kinds and "non_periodic" in kinds, kinds
assert {p["period"] for p in s["up"] if p["classification"] == "periodic"} >= {1, 2}
f = r("gear-pair-jumps")["frequency_response"]
assert len(f["harmonic_balance"]["folds"]) == 2 and len(f["jumps"]) == 2, f["jumps"]
for j in f["jumps"]:
    lo, hi = sorted((j["from_frequency_ratio"], j["to_frequency_ratio"]))
    assert j["exact_fold"]["found"] and lo <= j["exact_fold"]["frequency_ratio"] <= hi, j
b = r("gear-pair-basins")["basins"]
assert len(b["attractors"]) >= 2 and abs(sum(a["fraction"] for a in b["attractors"]) + b["other"]["fraction"] - 1) < 1e-12
a = r("case-a-330")
assert abs(a["model"]["axial"]["stiffness_N_per_um"] - 611.40) < 0.01 and a["model"]["te_period_rev"] == 8
v = a["vibration"]
assert v["classification"] == "periodic" and v["period"] == 1 and v["clock"] == "te", v["classification"]
th = [e for e in v["extremes"] if e["observable"] == "thread_force"][0]
assert abs(th["mean"] - 7000) < 0.5 and 5000 < th["min"] < th["max"] < 9000, th
hp = r("case-a-linear")["linear"]["half_power"]
assert hp["defined"] and abs(hp["damping_ratio"] - hp["modal_damping_ratio"]) < 0.002 and 25e3 < hp["peak_frequency_Hz"] < 45e3, hp
PY
"$prsm" simulate "$src/studies/vibration-gear-pair-sweep.json" --quiet --threads 1 --csv "$tmp/sweep.csv" > "$tmp/sweep1.json"; check "simulate sweep --csv" 0 $?
ok "sweep: bit-identical for 1 and 2 threads" cmp -s "$tmp/sweep1.json" "$tmp/vib-vibration-gear-pair-sweep.json"
ok "sweep CSV: a row per Poincare point of every point, both directions" $py - "$tmp/sweep.csv" <<'PY'
import sys
rows = open(sys.argv[1]).read().splitlines()
assert rows[0].startswith("direction,frequency_ratio,classification,period,") and len(rows) == 1 + 2 * 101 * 64, len(rows)
PY
"$prsm" simulate "$src/studies/vibration-gear-pair-v4a.json" --format text > "$tmp/v4a.txt"; check "simulate V4a --format text" 0 $?
ok "V4a text: period 1 and the amplitude" grep -q "period 1 (mesh clock)" "$tmp/v4a.txt"
ok "V4a text: the Lyapunov exponents" grep -q "Lyapunov exponents per unit tau: -0.05 -0.05" "$tmp/v4a.txt"
printf '{"dynamics": {"analysis": "sweep", "gear_pair": {"damping_ratio": 0}, "sweep": {"from": 0.5, "to": 2.5, "step": 1e-7}}}' > "$tmp/vib-bad.json"
"$prsm" simulate "$tmp/vib-bad.json" > "$tmp/out" 2> "$tmp/err"; check "simulate an invalid sweep" 1 $?
ok "invalid sweep: nothing on stdout" test ! -s "$tmp/out"
for ptr in /dynamics/gear_pair/damping_ratio /dynamics/sweep/step; do
  ok "invalid sweep: $ptr" grep -q ": $ptr: " "$tmp/err"
done
"$prsm" validate "$tmp/vib-bad.json" > /dev/null; check "validate an invalid sweep" 1 $?
"$prsm" validate "$src/studies/vibration-case-a-330.json" > /dev/null; check "validate a vibration request" 0 $?

# ---- issue 18: ratings both ways, catalogue sizes, plausibility, wrong kinds (docs/ratings.md) ----
for size in "21 5" "30 10" "48 5" "60 20"; do
  set -- $size
  printf '{"nominal": {"diameter_mm": %s, "lead_mm": %s}, "operating_point": {"axial_load_N": 10000}}' "$1" "$2" > "$tmp/nom.json"
  "$prsm" analyze "$tmp/nom.json" > "$tmp/nom-out.json"; check "analyze the catalogue size $1 x $2" 0 $?
  ok "$1 x $2: both rating conventions, makers' C_0a/C_a above 1, truncation warned for 48 x 5 only" $py - "$tmp/nom-out.json" "$1" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); r = d["capacity"]["ratings"]; m = r["makers_convention"]
assert m["C0a_over_C_a"] > 1 and abs(m["C0a_over_C_a"] - m["C0a_N"] / m["C_a_N"]) < 1e-12, m
assert r["load_distribution"]["C0a_N"] == d["capacity"]["static"]["C0a_N"] < m["C0a_N"], r
assert d["nominal"]["starts"] == 5 and [a["starts"] for a in d["nominal"]["alternatives"]] == [3, 4, 5, 6]
codes = [w["code"] for w in d["warnings"]]
assert ("ellipse_truncation" in codes) == (sys.argv[2] == "48"), codes
assert (d["capacity"]["static"]["limited_by"] == "ellipse_truncation") == (sys.argv[2] == "48")
PY
done
"$prsm" analyze "$src/studies/catalogue/48x5.json" --format text > "$tmp/nom.txt"; check "analyze catalogue/48x5.json --format text" 0 $?
ok "48 x 5 text: both conventions and the truncation" grep -q "makers' convention (equal sharing)" "$tmp/nom.txt"
ok "48 x 5 text: the truncation warning" grep -q "contact ellipse reaches the" "$tmp/nom.txt"
printf '{"nominal": {"diameter_mm": 30, "lead_mm": 10}, "geometry": {"pitch_mm": 2}}' > "$tmp/nom-bad.json"
"$prsm" analyze "$tmp/nom-bad.json" 2> "$tmp/err"; check "a catalogue size with the pitch too" 1 $?
ok "nominal and pitch_mm: the conflict at the geometry's field" grep -q ": /geometry/pitch_mm: is set by the catalogue size" "$tmp/err"
printf '{"geometry": {"starts": 5, "pitch_mm": 2, "roller_radius_mm": 3250, "rollers": 10, "engaged_threads": 10}}' > "$tmp/slip.json"
"$prsm" validate "$tmp/slip.json" > "$tmp/out"; check "validate a radius in µm" 0 $?
ok "unit slip: warned at roller_radius_mm" grep -q "warning: /geometry/roller_radius_mm: 3250 mm: a value in µm" "$tmp/out"
printf '{"geometry": {"starts": 5, "pitch_mm": 20, "roller_radius_mm": 3.25, "rollers": 6, "engaged_threads": 10}}' > "$tmp/p20.json"
"$prsm" analyze "$tmp/p20.json" 2> "$tmp/err"; check "pitch 20 mm on a 3.25 mm roller" 1 $?
ok "pitch 20: blames pitch_mm" grep -q ": /geometry/pitch_mm: roller needs" "$tmp/err"
ok "pitch 20: not the derived root radius" sh -c "! grep -q roller_root_radius_mm '$tmp/err'"
"$prsm" analyze "$src/studies/case-a-tolerances.json" > /dev/null 2> "$tmp/err"; check "analyze a study" 1 $?
ok "a study given to analyze: says which command" grep -q "this is a tolerance study (it has \`tolerances\`), not a design: run it with \`prsm study FILE\`" "$tmp/err"
"$prsm" analyze "$src/studies/optimize-case-a.json" > /dev/null 2> "$tmp/err"; check "analyze an optimisation" 1 $?
ok "an optimisation given to analyze: says which command" grep -q "run it with \`prsm optimize FILE\`" "$tmp/err"
"$prsm" batch "$tmp/no-such-file.jsonl" --out "$tmp/b.jsonl" 2> /dev/null; check "batch on a missing file (usage, 64)" 64 $?
printf '{"geometry": {"starts": 5, "pitch_mm": 2, "roller_radius_mm": 3.25, "rollers": 10, "engaged_threads": 10}, "operating_point": {"axial_load_N": 7000, "screw_speed_rpm": 0}}' > "$tmp/rpm0.json"
"$prsm" analyze "$tmp/rpm0.json" --format text > "$tmp/rpm0.txt"; check "analyze at 0 rpm --format text" 0 $?
ok "0 rpm: L10 hours not rated, as the JSON's null" grep -q "hours not rated at 0 rpm" "$tmp/rpm0.txt"
ok "0 rpm: no '0 h'" sh -c "! grep -q ' 0 h' '$tmp/rpm0.txt'"
"$prsm" optimize "$src/studies/catalogue/optimize-standard-leads.json" --quiet > "$tmp/leads.json"; check "optimize with standard leads" 0 $?
ok "standard leads: the best lead is one of the list" $py - "$tmp/leads.json" "$src/studies/catalogue/optimize-standard-leads.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); allowed = json.load(open(sys.argv[2]))["variables"]["lead_values_mm"]
v = r["best"]["variables"]
assert r["feasible"] and v["lead_mm"] in allowed and abs(v["pitch_mm"] * v["starts"] - v["lead_mm"]) < 1e-12, v
PY

echo "cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
