#!/usr/bin/env bash
# mpi.sh: `prsm study`, `batch`, `allocate`, `optimize` and `simulate` under mpirun (issue 20,
# docs/mpi.md).
#
#   bash tests/mpi.sh PRSM SOURCE_DIR MPI_SONAME
#
# At 1, 2 and 3 ranks (oversubscribed: the test machine may have fewer cores) the JSON is the
# plain process's, byte for byte once the timings, the build identity and the job ids are
# masked (every number is compared as the text printed), for: a case-A study that stops on its
# target (and, at 2 ranks with 2 threads each, its samples CSV), a study with Sobol' indices,
# a batch, case A's allocation (its corrections' studies over the ranks), a robust optimisation
# (its candidates' studies over the ranks), a gear pair's sweep up and down and its basins (and
# their CSVs); a study whose failure policy aborts stops at the same sample with the same
# message. A failing rank ends a study, an allocation, an optimisation or a basin grid with an
# error naming it (PRSM_PAR_FAULT, the test hook), a rank that exits at once ends it too, never
# a hang, and a batch cut short that way resumes. Skipped (exit 77) when prsm was built without
# MPI or mpirun is missing.
set -euo pipefail

prsm=$(realpath "$1")
src=$(realpath "$2")
soname=${3:-}
if [ -z "$soname" ]; then
  echo "mpi: skipped: prsm was built without MPI (PRSM_MPI found none: install libopenmpi-dev and openmpi-bin, reconfigure)"
  exit 77
fi
if ! command -v mpirun >/dev/null 2>&1; then
  echo "mpi: skipped: no mpirun (install openmpi-bin)"
  exit 77
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
# Open MPI refuses root unless asked; the runs are small and the machine may have fewer cores
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
run_mpi() { # N ARGS...: prsm under mpirun -n N, at most 120 s
  local n=$1
  shift
  timeout 120 mpirun --allow-run-as-root --oversubscribe -n "$n" "$prsm" "$@"
}
fail() {
  echo "mpi: FAIL: $*" >&2
  exit 1
}

# The masked text of a JSON document, or of each line of a .jsonl file: object keys in order,
# numbers as printed, timing_s, versions.build, elapsed_s and job_id (and cache_hit when asked)
# replaced by "MASKED".
cat > mask.py <<'EOF'
import json, sys
mask = {"timing_s", "build", "elapsed_s", "job_id"} | set(sys.argv[2:])
def walk(v):
    if isinstance(v, dict):
        return {k: ("MASKED" if k in mask else walk(x)) for k, x in v.items()}
    if isinstance(v, list):
        return [walk(x) for x in v]
    return v
text = open(sys.argv[1], encoding="utf-8").read()
docs = text.splitlines() if sys.argv[1].endswith(".jsonl") else [text]
for d in docs:
    if d.strip():
        print(json.dumps(walk(json.loads(d, parse_float=str, parse_int=str)), ensure_ascii=False))
EOF
mask() { /usr/bin/python3 mask.py "$@"; }

# The documents: case A's tolerance study with a standard-error target it reaches early; the
# same with Sobol' indices (8 randomised-QMC replicates) and no target; a batch of small studies
# (one twice, one invalid line).
/usr/bin/python3 - "$src" <<'EOF'
import json, sys, copy
base = json.load(open(sys.argv[1] + "/studies/case-a-tolerances.json"))
t = copy.deepcopy(base)
t["monte_carlo"].update(samples=3000, block_size=128, min_samples=256,
                        targets=[{"output": "backlash_um", "standard_error": 0.25}])
t["sensitivity"] = {"src": True, "stack": True}
json.dump(t, open("target.json", "w"))
s = copy.deepcopy(base)
s["monte_carlo"].update(samples=384, block_size=128, targets=[])
s["sensitivity"] = {"src": True, "stack": False, "sobol": {"samples": 256}}
json.dump(s, open("sobol.json", "w"))
a = copy.deepcopy(t)
for tol in a["tolerances"]:
    if tol["parameter"] == "friction.screw_roller_mu":
        tol.update(lower=-0.058, mode=0.0, upper=0.03)  # a few negative coefficients: failed samples
a["monte_carlo"].update(samples=2000, targets=[], failure={"policy": "abort"})
json.dump(a, open("abort.json", "w"))
# case A's allocation with few samples (its corrections' studies: 8 blocks of 256) and the robust
# optimisation with small studies (4 blocks of 32 samples) and a small evaluation budget
al = json.load(open(sys.argv[1] + "/studies/allocate-case-a.json"))
al["monte_carlo"].update(samples=2048, max_corrections=4)
al["study"]["monte_carlo"].update(block_size=256)
json.dump(al, open("alloc.json", "w"))
ro = json.load(open(sys.argv[1] + "/studies/optimize-case-a-robust.json"))
ro["robust"]["monte_carlo"].update(samples=128, block_size=32)
ro["solver"].update(max_evaluations=120, multistart=1)
json.dump(ro, open("robust.json", "w"))
# the gear pair's bifurcation sweep up and down (its two directions over the ranks) and its
# basins of attraction (the cells over the ranks), on coarser grids
sw = json.load(open(sys.argv[1] + "/studies/vibration-gear-pair-sweep.json"))
sw["dynamics"]["sweep"].update(step=0.05)
json.dump(sw, open("sweep.json", "w"))
ba = json.load(open(sys.argv[1] + "/studies/vibration-gear-pair-basins.json"))
ba["dynamics"]["basins"].update(deflection_cells=11, rate_cells=11)
json.dump(ba, open("basins.json", "w"))
b = copy.deepcopy(base)
b["monte_carlo"].update(samples=256, block_size=64, targets=[])
b["sensitivity"] = {"src": True, "stack": False}
with open("batch.jsonl", "w") as f:
    for i, seed in enumerate([1, 2, 3, 1, 4]):
        d = copy.deepcopy(b)
        d["monte_carlo"]["seed"] = seed
        f.write(json.dumps({"id": "s%d" % i, "kind": "study", "request": d}) + "\n")
    f.write(json.dumps({"id": "bad", "kind": "study", "request": {"tolerances": 1}}) + "\n")
EOF

# --- the plain process ---------------------------------------------------------------------
"$prsm" study target.json --quiet --csv target.plain.csv > target.plain.json
jq -e '.stop_reason == "target" and .samples.run < .samples.cap' target.plain.json > /dev/null ||
  fail "the target study did not stop on its target"
"$prsm" study sobol.json --quiet > sobol.plain.json
jq -e '.sobol.replicates == 8' sobol.plain.json > /dev/null || fail "the Sobol study ran no replicates"
rc=0
"$prsm" batch batch.jsonl --out batch.plain.jsonl --db plain.db --quiet || rc=$?
[ "$rc" = 1 ] || fail "plain batch: exit $rc, expected 1 (one invalid line)"
mask target.plain.json > target.plain.m
mask sobol.plain.json > sobol.plain.m
mask batch.plain.jsonl > batch.plain.m
"$prsm" allocate alloc.json --quiet > alloc.plain.json
jq -e '.monte_carlo.samples_total > .monte_carlo.samples' alloc.plain.json > /dev/null ||
  fail "the allocation ran no Monte Carlo correction"
"$prsm" optimize robust.json --quiet > robust.plain.json
jq -e '.robust.studies >= 2' robust.plain.json > /dev/null || fail "the robust optimisation ran fewer than 2 studies"
mask alloc.plain.json > alloc.plain.m
mask robust.plain.json > robust.plain.m
"$prsm" simulate sweep.json --quiet --csv sweep.plain.csv > sweep.plain.json
"$prsm" simulate basins.json --quiet --csv basins.plain.csv > basins.plain.json
mask sweep.plain.json > sweep.plain.m
mask basins.plain.json > basins.plain.m

# --- 1, 2 and 3 ranks: byte-identical ------------------------------------------------------
for n in 1 2 3; do
  run_mpi "$n" study target.json --quiet > "target.$n.json"
  mask "target.$n.json" | cmp -s - target.plain.m || fail "target study at $n ranks differs from the plain process"
  run_mpi "$n" study sobol.json --quiet > "sobol.$n.json"
  mask "sobol.$n.json" | cmp -s - sobol.plain.m || fail "Sobol study at $n ranks differs from the plain process"
  rc=0
  run_mpi "$n" batch batch.jsonl --out "batch.$n.jsonl" --db "batch$n.db" --quiet 2> "batch.$n.err" || rc=$?
  [ "$rc" = 1 ] || { cat "batch.$n.err" >&2; fail "batch at $n ranks: exit $rc, expected 1"; }
  mask "batch.$n.jsonl" | cmp -s - batch.plain.m || fail "batch at $n ranks differs from the plain process"
  run_mpi "$n" allocate alloc.json --quiet > "alloc.$n.json"
  mask "alloc.$n.json" | cmp -s - alloc.plain.m || fail "allocation at $n ranks differs from the plain process"
  run_mpi "$n" optimize robust.json --quiet > "robust.$n.json"
  mask "robust.$n.json" | cmp -s - robust.plain.m || fail "robust optimisation at $n ranks differs from the plain process"
  for v in sweep basins; do
    run_mpi "$n" simulate "$v.json" --quiet --csv "$v.$n.csv" > "$v.$n.json"
    mask "$v.$n.json" | cmp -s - "$v.plain.m" || fail "$v at $n ranks differs from the plain process"
    cmp -s "$v.$n.csv" "$v.plain.csv" || fail "the $v CSV at $n ranks differs"
  done
  echo "mpi: $n rank(s): target study, Sobol study, batch, allocation, robust optimisation, sweep and basins byte-identical to the plain process"
done
# two engine threads per rank (chunks of 2 blocks), the samples CSV from rank 0, the document
# from standard input (which the launcher gives to rank 0, which broadcasts it)
run_mpi 2 study - --quiet --threads 2 --csv target.2t.csv < target.json > target.2t.json
mask target.2t.json | cmp -s - target.plain.m || fail "target study at 2 ranks x 2 threads from stdin differs"
cmp -s target.2t.csv target.plain.csv || fail "the samples CSV at 2 ranks x 2 threads differs"
echo "mpi: 2 ranks x 2 threads, the CSV, the document from standard input: byte-identical"
# without --quiet rank 0 prints a progress line at the start and at the end of each run (stderr
# is not a terminal here), and none for a phase with nothing to sample ("0 / 0")
run_mpi 2 study target.json > /dev/null 2> progress.err
grep -q "samples on 2 ranks" progress.err || fail "no progress lines under MPI: $(cat progress.err)"
! grep -q " 0 / 0 " progress.err || fail "a progress line of a phase with nothing to sample: $(cat progress.err)"
# the run stops early on its target: the count it stopped at, then the summary phase
grep -q "samples on 2 ranks, interval .* (goal 0.25)" progress.err || fail "no line of the count the run stopped at: $(cat progress.err)"
grep -q "^prsm study: summary on 2 ranks" progress.err || fail "no line of the summary phase: $(cat progress.err)"
echo "mpi: progress lines on rank 0: the count the run stopped at, the summary phase, no 0 / 0"

# the failure policy `abort` stops at the same sample with the same message
rc=0
"$prsm" study abort.json --quiet > /dev/null 2> abort.plain.err || rc=$?
[ "$rc" = 2 ] && grep -q "abort.json: sample [0-9]* failed" abort.plain.err || fail "the abort study did not abort (exit $rc)"
rc=0
run_mpi 3 study abort.json --quiet > abort.3.json 2> abort.3.err || rc=$?
[ "$rc" = 2 ] || fail "the abort study at 3 ranks: exit $rc, expected 2"
grep -qxF "$(cat abort.plain.err)" abort.3.err || { cat abort.3.err >&2; fail "the abort study at 3 ranks says otherwise"; }
[ ! -s abort.3.json ] || fail "an aborted study wrote a result"
echo "mpi: the failure policy abort stops at 3 ranks where one process stops, with its message"

# --- a failing rank ------------------------------------------------------------------------
rc=0
PRSM_PAR_FAULT=fail:1 run_mpi 2 study target.json --quiet > fault.json 2> fault.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "a failing rank: exit $rc (124: timed out)"
grep -q "target.json: rank 1 of 2 failed: injected failure" fault.err || { cat fault.err >&2; fail "the failing rank is not named"; }
[ ! -s fault.json ] || fail "a failed study wrote a result"
rc=0
PRSM_PAR_FAULT=exit:2 run_mpi 3 study sobol.json --quiet > exit.json 2> exit.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "a rank that exits: exit $rc (124: timed out)"
grep -q "rank 2 of 3: exiting at once" exit.err || { cat exit.err >&2; fail "the exiting rank said nothing"; }
rc=0
PRSM_PAR_FAULT=fail:1 run_mpi 2 allocate alloc.json --quiet > afault.json 2> afault.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "a failing rank in an allocation: exit $rc (124: timed out)"
grep -q "rank 1 of 2 failed: injected failure" afault.err || { cat afault.err >&2; fail "the allocation's failing rank is not named"; }
[ ! -s afault.json ] || fail "a failed allocation wrote a result"
rc=0
PRSM_PAR_FAULT=fail:2 run_mpi 3 optimize robust.json --quiet > ofault.json 2> ofault.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "a failing rank in a robust optimisation: exit $rc (124: timed out)"
grep -q "rank 2 of 3 failed: injected failure" ofault.err || { cat ofault.err >&2; fail "the optimisation's failing rank is not named"; }
[ ! -s ofault.json ] || fail "a robust optimisation with a failed rank wrote a result"
rc=0
PRSM_PAR_FAULT=exit:1 run_mpi 2 optimize robust.json --quiet > oexit.json 2> oexit.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "an exiting rank in a robust optimisation: exit $rc (124: timed out)"
[ ! -s oexit.json ] || fail "a robust optimisation with an exiting rank wrote a result"
rc=0
PRSM_PAR_FAULT=fail:1 run_mpi 2 simulate basins.json --quiet > bfault.json 2> bfault.err || rc=$?
[ "$rc" = 2 ] || fail "a failing rank in a basin grid: exit $rc, expected 2"
grep -q "basins.json: rank 1 of 2 failed: injected failure" bfault.err || { cat bfault.err >&2; fail "the basin grid's failing rank is not named"; }
[ ! -s bfault.json ] || fail "a basin grid with a failed rank wrote a result"
rc=0
PRSM_PAR_FAULT=exit:1 run_mpi 2 simulate sweep.json --quiet > sexit.json 2> sexit.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "an exiting rank in a sweep: exit $rc (124: timed out)"
[ ! -s sexit.json ] || fail "a sweep with an exiting rank wrote a result"
echo "mpi: a failing rank and an exiting rank end the run with an error (study, allocation, optimisation, basins, sweep)"

# --- a batch cut short by a dying rank resumes --------------------------------------------
rc=0
PRSM_PAR_FAULT=exit:2 run_mpi 3 batch batch.jsonl --out resume.jsonl --db resume.db --quiet 2> resume.err || rc=$?
[ "$rc" != 0 ] && [ "$rc" != 124 ] || fail "a batch with a dying rank: exit $rc (124: timed out)"
[ "$(grep -c . resume.jsonl || true)" -lt 6 ] || fail "the batch with a dying rank was not cut short"
rc=0
run_mpi 2 batch batch.jsonl --out resume.jsonl --db resume.db --quiet 2> resume2.err || rc=$?
[ "$rc" = 1 ] || { cat resume2.err >&2; fail "the resumed batch: exit $rc, expected 1"; }
mask resume.jsonl cache_hit | cmp -s - <(mask batch.plain.jsonl cache_hit) || fail "the resumed batch differs from the plain one"
echo "mpi: a batch cut short by a dying rank resumed, same results"
echo "mpi: ok"
