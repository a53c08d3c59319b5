#!/usr/bin/env bash
# prsm calibrate (issue 17, docs/measured-data.md): validation case V6 of the dynamics
# specification (the line model on tests/data/v6-measured-te.csv, case A, 15 revolutions: every
# parameter with its standard error, checked for plausibility against the noise it was made with
# and case A's statics TE lines; its truth is held back), the result against
# schemas/measured-result.schema.json, the text summary with the caveats, the physical model,
# friction and carrier drag; bad CSV files refused with their line and column, bad documents
# with their JSON pointer, a million-row CSV refused at the cap. Args: PRSM_BINARY SOURCE_DIR
set -u
prsm=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0
fail=0
py=/usr/bin/python3
v6doc="$src/tests/data/calibrate-case-a-v6.json"
v6csv="$src/tests/data/v6-measured-te.csv"

check() { # name expected_code actual_code
  if [ "$2" = "$3" ]; then pass=$((pass+1)); else echo "FAIL: $1: exit $3, expected $2"; fail=$((fail+1)); fi
}
ok() { # name command...
  local name=$1; shift
  if "$@"; then pass=$((pass+1)); else echo "FAIL: $name"; fail=$((fail+1)); fi
}

# ---- V6: the line model ----
"$prsm" calibrate "$v6doc" --measured "$v6csv" > "$tmp/v6.json" 2> "$tmp/err"; check "V6 calibrate" 0 $?
"$prsm" analyze "$src/studies/case-a-measured.json" > "$tmp/statics.json"; check "case A measured statics" 0 $?
ok "V6: the result matches its schema" $py - "$src/schemas/measured-result.schema.json" "$tmp/v6.json" <<'PY'
import json, sys
from jsonschema import Draft202012Validator
errors = list(Draft202012Validator(json.load(open(sys.argv[1]))).iter_errors(json.load(open(sys.argv[2]))))
assert not errors, [e.message for e in errors[:3]]
PY
ok "V6: plausible estimates" $py - "$tmp/v6.json" "$tmp/statics.json" <<'PY'
import json, math, sys
d = json.load(open(sys.argv[1]))
st = json.load(open(sys.argv[2]))["assembly"]["transmission_error"]
c = d["calibration"]
print("V6, line model (estimate +- standard error):")
for p in c["parameters"]:
    print(f"  {p['name']:28s} {p['estimate']:+.8f} +- {p['standard_error']:.3g} {p['unit']}")
for l in c["lines"]:
    print(f"  line {l['name']:18s} order {l['order_per_rev']:.6f}: {l['amplitude_um']:.5f} +- {l['amplitude_se_um']:.5f} um, "
          f"phase {l['phase_deg']:.3f} +- {l['phase_se_deg']:.3f} deg")
print(f"  s {c['residual_sd_um']:.5f} um, r1 {c['residual_lag1_autocorrelation']:.4f}, "
      f"condition {c['condition_number']:.3g} ({c['condition_number_scaled']:.3g} scaled)")
# 960 points, 17 parameters, noise 0.1 um: s within 5 standard errors of s (sigma / sqrt(2 (N - p)))
assert abs(c["residual_sd_um"] - 0.1) < 5 * 0.1 / math.sqrt(2 * (960 - 17)), c["residual_sd_um"]
assert c["converged"] and c["inflation"] == 1 and abs(c["residual_lag1_autocorrelation"]) < 0.2
# every named order of the line model, the mesh line (31.66, below the Nyquist order 32) included
assert len(c["parameters"]) == 17 and all(p["standard_error"] > 0 for p in c["parameters"])
assert [l["name"] for l in c["lines"]][-1] == "mesh" and c["dropped_lines"] == [], c["dropped_lines"]
assert abs(c["lines"][-1]["amplitude_um"]) < 3 * c["lines"][-1]["amplitude_se_um"]
k = c["carrier_ratio"]
assert 0.36 < k["estimate"] < 0.39 and k["standard_error"] < 1e-3, k
assert k["grid"]["points"] == 2001 and abs(k["grid"]["to"] - k["grid"]["from"] - 0.05) < 1e-12
# the lines of case A's statics TE (the error set of studies/case-a-measured.json: the lines V5
# names) within 0.03 um, the lead deviation within 4 standard errors
stat = {l["name"]: l["amplitude_um"] for l in st["spectrum"]["lines"]}
stat["screw_rev"] = st["spectrum"]["peak"]["amplitude_um"]
fit = {l["name"]: l for l in c["lines"]}
for name in ("screw_rev", "screw", "carrier", "roller_spin", "roller_pass_nut"):
    assert abs(fit[name]["amplitude_um"] - stat[name]) < 0.03, (name, fit[name], stat[name])
slope = c["estimates"]["slope_um_per_300mm"]
assert abs(slope - st["stroke"]["lead_deviation_um_per_300mm"]) < 4 * c["standard_errors"]["slope_um_per_300mm"], slope
# the identification by spectrum sees the same lines
ident = {l["name"]: l for l in d["identification"]["lines"]}
for name in ("screw_rev", "screw", "roller_spin", "roller_pass_nut"):
    assert abs(ident[name]["amplitude_um"] - fit[name]["amplitude_um"]) < 0.03, name
assert abs(d["identification"]["lead_deviation_um_per_300mm"] - slope) < 0.5
assert {cv["code"] for cv in c["caveats"]} == {"resolution", "slope_low_order", "screw_runout", "same_part_order",
                                                 "roller_sum", "correlated_residuals"}
assert not any(cv["triggered"] for cv in c["caveats"])
PY
"$prsm" calibrate "$v6doc" --measured "$v6csv" --format text > "$tmp/v6.txt"; check "V6 text" 0 $?
ok "V6 text: estimates and the caveats" grep -q "identifiability caveats" "$tmp/v6.txt"
ok "V6 text: k" grep -q "calibration, line model: k = 0.372" "$tmp/v6.txt"
ok "prsm help lists calibrate" sh -c "'$prsm' help | grep -q 'calibrate FILE'"

# the same curve from the document's arrays gives the same estimates
$py - "$v6doc" "$v6csv" "$tmp/v6-arrays.json" <<'PY'
import csv, json, sys
d = json.load(open(sys.argv[1]))
rows = [r for r in csv.reader(l for l in open(sys.argv[2]) if not l.startswith("#"))][1:]
d["measured"]["te"] = {"screw_angle_rad": [float(r[0]) for r in rows], "te_um": [float(r[2]) for r in rows]}
json.dump(d, open(sys.argv[3], "w"))
PY
"$prsm" calibrate "$tmp/v6-arrays.json" > "$tmp/v6a.json"; check "V6 from arrays" 0 $?
# (the CSV's travel column has 12 decimals, the arrays' travel comes from the angle)
ok "V6 from arrays: the same estimates" $py -c 'import json,sys
A = json.load(open(sys.argv[1]))["calibration"]; B = json.load(open(sys.argv[2]))["calibration"]
a, b, se = A["estimates"], B["estimates"], A["standard_errors"]
assert a.keys() == b.keys() and all(abs(a[k] - b[k]) <= 1e-6 * se[k] for k in a), (a, b)' "$tmp/v6.json" "$tmp/v6a.json"

ok "V6: the fitted curve is the line model at every point (an independent evaluation) and gives s" $py - "$tmp/v6.json" "$v6csv" <<'PY'
import csv, json, math, sys
d = json.load(open(sys.argv[1]))
c = d["calibration"]
rows = [r for r in csv.reader(l for l in open(sys.argv[2]) if not l.startswith("#"))]
cols = {n: [float(r[i]) for r in rows[1:]] for i, n in enumerate(rows[0])}
th, s, te, f = cols["screw_angle_rad"], cols["travel_mm"], cols["te_um"], c["fitted_te_um"]
e = c["estimates"]
worst = 0.0
for i in range(len(te)):
    v = e["offset_um"] + e["slope_um_per_300mm"] * s[i] / 300
    for l in c["lines"]:
        v += e[l["name"] + "_cos_um"] * math.cos(l["order_per_rev"] * th[i]) + e[l["name"] + "_sin_um"] * math.sin(l["order_per_rev"] * th[i])
    worst = max(worst, abs(v - f[i]))
assert worst < 1e-9, worst
n, p = len(te), len(c["parameters"])
sd = math.sqrt(sum((m - y) ** 2 for m, y in zip(te, f)) / (n - p))
assert abs(sd / c["residual_sd_um"] - 1) < 1e-9, (sd, c["residual_sd_um"])
PY

# ---- the physical model, friction, carrier drag ----
$py - "$v6doc" "$tmp/phys.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["dynamics"]["calibrate"] = {"model": "physical", "parameters": ["screw.lead_deviation_um_per_300mm"]}
d["measured"].update({"efficiency": 0.8913, "efficiency_sd": 0.0047, "efficiency_axial_load_N": 5230,
                      "cage_ratio": 0.3702, "cage_ratio_sd": 0.0015})
json.dump(d, open(sys.argv[2], "w"))
PY
"$prsm" calibrate "$tmp/phys.json" --measured "$v6csv" > "$tmp/phys-out.json"; check "physical model" 0 $?
ok "physical model: the lead error, friction and drag" $py - "$tmp/phys-out.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
c = d["calibration"]
assert c["model"] == "physical"
lead = c["estimates"]["screw.lead_deviation_um_per_300mm"]
assert abs(lead - 12.11) < 0.1, lead
# the unmodelled lines leave correlated residuals: flagged and the errors inflated
cv = {x["code"]: x for x in c["caveats"]}
assert cv["correlated_residuals"]["triggered"] and c["inflation"] > 2
f = d["friction"]
assert f["found"] and 0.04 < f["mu"] < 0.07 and f["mu_standard_error"] > 0, f
assert abs(d["comparison"]["efficiency"]["axial_load_N"] - 5230) < 1e-9
k = d["carrier_drag"]
assert k["found"] and not k["above_min_slip"] and k["carrier_drag_Nm_s_per_rad"] > 0, k
assert d["comparison"]["cage_ratio"]["z_min_slip"] < 0
PY
ok "physical model: the fitted curve is the calibrated lead error's straight line, and gives s" $py - "$tmp/phys-out.json" "$v6csv" <<'PY'
import csv, json, math, sys
d = json.load(open(sys.argv[1]))
c = d["calibration"]
rows = [r for r in csv.reader(l for l in open(sys.argv[2]) if not l.startswith("#"))]
cols = {n: [float(r[i]) for r in rows[1:]] for i, n in enumerate(rows[0])}
s, te, f = cols["travel_mm"], cols["te_um"], c["fitted_te_um"]
assert len(f) == len(te) == 960
# a lead error alone moves the nut in proportion to the travel: the fitted TE is a straight line
# whose slope is the estimate per 300 mm (least squares, independent of the engine)
n = len(s); ms, mf = sum(s) / n, sum(f) / n
b = sum((x - ms) * (y - mf) for x, y in zip(s, f)) / sum((x - ms) ** 2 for x in s)
dev = max(abs(y - (mf + b * (x - ms))) for x, y in zip(s, f))
assert dev < 1e-6, dev
assert abs(b * 300 - c["estimates"]["screw.lead_deviation_um_per_300mm"]) < 1e-6, (b * 300, c["estimates"])
p = len(c["parameters"])
sd = math.sqrt(sum((m - y) ** 2 for m, y in zip(te, f)) / (n - p))
assert abs(sd / c["residual_sd_um"] - 1) < 1e-9, (sd, c["residual_sd_um"])
PY
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); d["measured"]["cage_ratio"]=0.3781; json.dump(d,open(sys.argv[2],"w"))' "$tmp/phys.json" "$tmp/above.json"
"$prsm" calibrate "$tmp/above.json" --measured "$v6csv" > "$tmp/above-out.json"; check "cage ratio above k*" 0 $?
ok "cage ratio above k*: flagged" $py -c 'import json,sys; d=json.load(open(sys.argv[1]))
assert d["carrier_drag"]["above_min_slip"] and not d["carrier_drag"]["found"]
assert [w["code"] for w in d["warnings"]] == ["above_min_slip"], d["warnings"]' "$tmp/above-out.json"

# ---- bad CSV files: line and column ----
bad_csv() { # name expected-message-fragment (the CSV on stdin)
  cat > "$tmp/bad.csv"
  "$prsm" calibrate "$v6doc" --measured "$tmp/bad.csv" > "$tmp/out" 2> "$tmp/err"; check "bad CSV: $1" 1 $?
  ok "bad CSV: $1: nothing on stdout" test ! -s "$tmp/out"
  ok "bad CSV: $1: '$2'" grep -qF "$2" "$tmp/err"
}
$py -c '
import sys
for i in range(400):
    a = 6.283185307179586 * i / 64
    print(f"{a:.12f},{a * 10 / 6.283185307179586:.12f},{0.1 * i % 1:.6f}")' > "$tmp/rows.csv"
{ echo "screw_angle_rad,travel_mm,te_um"; cat "$tmp/rows.csv"; } > "$tmp/good.csv"
sed '57s/^\([^,]*\),/0.5,/' "$tmp/good.csv" | bad_csv "non-monotonic angle" "line 57, column 1 (screw_angle_rad): the screw angle must increase strictly"
sed '31s/,[^,]*$/,abc/' "$tmp/good.csv" | bad_csv "bad number" 'line 31, column 3 (te_um): "abc" is not a number'
sed '44s/,[^,]*$/,NaN/' "$tmp/good.csv" | bad_csv "NaN" 'line 44, column 3 (te_um): "NaN" is not a finite number'
sed '1s/te_um/te/' "$tmp/good.csv" | bad_csv "missing column" "line 1: the header has no te_um column"
sed '12s/,[^,]*$//' "$tmp/good.csv" | bad_csv "short row" "line 12, column 3 (te_um): the row has 2 fields"
head -200 "$tmp/good.csv" | bad_csv "fewer than four revolutions" "line 200, column 1 (screw_angle_rad): the TE record covers 3.094 screw revolutions"
sed '90s/^\([^,]*\),\([^,]*\),/\1,99,/' "$tmp/good.csv" | bad_csv "travel against the lead" "line 90, column 2 (travel_mm): the travel"
$py -c '
print("screw_angle_rad,te_um")
import sys
w = sys.stdout.write
for i in range(1000000):
    w(f"{i * 0.0981747704:.10f},{i % 97 * 0.001:.3f}\n")' | bad_csv "a million rows" "line 200002: more than 200000 data rows"
"$prsm" calibrate "$v6doc" --measured "$tmp/none.csv" > /dev/null 2> "$tmp/err"; check "missing CSV file" 1 $?
ok "missing CSV file: said so" grep -q "cannot open the measured CSV" "$tmp/err"

# ---- bad documents: JSON pointers ----
bad_doc() { # name pointer python-edit
  $py -c "import json,sys; d=json.load(open(sys.argv[1])); $3; json.dump(d,open(sys.argv[2],'w'))" "$v6doc" "$tmp/bad.json"
  "$prsm" calibrate "$tmp/bad.json" --measured "$v6csv" > "$tmp/out" 2> "$tmp/err"; check "bad document: $1" 1 $?
  ok "bad document: $1 at $2" grep -qF ": $2: " "$tmp/err"
}
bad_doc "sd without its value" /measured/cage_ratio_sd 'd["measured"]["cage_ratio_sd"] = 0.001'
bad_doc "efficiency above 1" /measured/efficiency 'd["measured"]["efficiency"] = 1.2'
bad_doc "unknown line" /dynamics/calibrate/lines/1 'd["dynamics"]["calibrate"]["lines"] = ["screw", "carier"]'
bad_doc "physical without parameters" /dynamics/calibrate/parameters 'd["dynamics"]["calibrate"]["model"] = "physical"'
bad_doc "an unknown error field" /dynamics/calibrate/parameters/0 'd["dynamics"]["calibrate"] = {"model": "physical", "parameters": ["nut.runout_mm"]}'
bad_doc "a roller out of range" /dynamics/calibrate/parameters/0 'd["dynamics"]["calibrate"] = {"model": "physical", "parameters": ["roller.10.runout_um"]}'
bad_doc "another analysis" /dynamics/analysis 'd["dynamics"]["analysis"] = "transient"'
bad_doc "a design problem" /design/geometry/pitch_mm 'd["design"]["geometry"]["pitch_mm"] = -2'
bad_doc "a bad curve in the document" /measured/te/te_um/2 'd["measured"]["te"] = {"screw_angle_rad": [0, 1, 2], "te_um": [0, 1, "x"]}'
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); d["measured"]["te"]={"travel_mm":[i*0.5 for i in range(90)],"te_um":[0.0]*90}; d["measured"]["te"]["travel_mm"][33]=3; json.dump(d,open(sys.argv[2],"w"))' "$v6doc" "$tmp/bad.json"
"$prsm" calibrate "$tmp/bad.json" > /dev/null 2> "$tmp/err"; check "non-monotonic travel in the document" 1 $?
ok "non-monotonic travel in the document: its pointer" grep -qF "/measured/te/travel_mm/33: " "$tmp/err"
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); del d["measured"]; json.dump(d,open(sys.argv[2],"w"))' "$v6doc" "$tmp/bad.json"
"$prsm" calibrate "$tmp/bad.json" > /dev/null 2> "$tmp/err"; check "nothing measured" 1 $?
ok "nothing measured: said so" grep -qF "/measured: nothing measured" "$tmp/err"
# ---- the curve as CSV text in the request (measured.te_csv, what a service upload becomes) ----
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); d["measured"]["te_csv"]=open(sys.argv[3]).read(); json.dump(d,open(sys.argv[2],"w"))' "$v6doc" "$tmp/te_csv.json" "$v6csv"
"$prsm" calibrate "$tmp/te_csv.json" > "$tmp/te_csv.out" 2> "$tmp/err"; check "V6 with measured.te_csv" 0 $?
ok "measured.te_csv: the same estimates as --measured, the source csv without a file" $py - "$tmp/v6.json" "$tmp/te_csv.out" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
assert a["calibration"] == b["calibration"], "the calibrations differ"
assert b["measured"]["source"] == "csv" and "file" not in b["measured"] and a["measured"]["file"].endswith(".csv")
PY
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); d["measured"]["te_csv"]=open(sys.argv[3]).read().replace("\n0.19", "\n0.1q", 1); json.dump(d,open(sys.argv[2],"w"))' "$v6doc" "$tmp/bad.json" "$v6csv"
"$prsm" calibrate "$tmp/bad.json" > /dev/null 2> "$tmp/err"; check "a bad measured.te_csv" 1 $?
ok "a bad measured.te_csv: at /measured/te_csv with line and column" grep -qF "/measured/te_csv: line 5, column 1 (screw_angle_rad)" "$tmp/err"
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); d["measured"]["te_csv"]="x"; d["measured"]["te"]={"te_um":[1]}; json.dump(d,open(sys.argv[2],"w"))' "$v6doc" "$tmp/bad.json"
"$prsm" calibrate "$tmp/bad.json" > /dev/null 2> "$tmp/err"; check "te and te_csv both" 1 $?
ok "te and te_csv both: said at /measured/te_csv" grep -qF "/measured/te_csv: the TE curve is given twice" "$tmp/err"

# ---- prsm validate knows a calibration request ----
"$prsm" validate "$v6doc" --measured "$v6csv" --format text > "$tmp/out" 2>&1; check "validate V6 with its CSV" 0 $?
"$prsm" validate "$tmp/te_csv.json" > "$tmp/out" 2>&1; check "validate V6 with te_csv" 0 $?
ok "validate: valid" grep -qF "te_csv.json: valid" "$tmp/out"
"$prsm" validate "$v6doc" --format text > "$tmp/out" 2>&1; check "validate V6 without a curve" 1 $?
ok "validate V6 without a curve: nothing measured" grep -qF "/measured: nothing measured" "$tmp/out"
$py -c 'import json,sys; d=json.load(open(sys.argv[1])); d["dynamics"]["calibrate"]["grid_pointz"]=3; json.dump(d,open(sys.argv[2],"w"))' "$v6doc" "$tmp/bad.json"
"$prsm" validate "$tmp/bad.json" --measured "$v6csv" --format text > "$tmp/out" 2>&1; check "validate a misspelt calibration option" 1 $?
ok "validate: did you mean grid_points" grep -qF 'did you mean "grid_points"' "$tmp/out"
"$prsm" calibrate > /dev/null 2>&1; check "usage" 64 $?
"$prsm" calibrate "$v6doc" --format xml > /dev/null 2>&1; check "bad format" 64 $?

echo "calibrate: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
