#!/usr/bin/python3
"""prsm against OpenTURNS on the same computation, measured side by side, as ratios.

The case: Sobol' first and total indices of the Ishigami function (a = 7, b = 0.1, inputs
uniform on [-pi, pi]) from a Saltelli design of N = 16384 base rows (N (d + 2) = 81920
evaluations), with Sobol' sampling and with plain random sampling, by the estimators prsm uses
(Saltelli 2010 first order, Jansen 1999 total).

  * OpenTURNS (Debian's python3-openturns): design + evaluation + indices inside one Python
    process that has already imported openturns (its start-up is not counted).
  * prsm, whole process: `prsm study` on the same study (1,024 plain samples for the summary,
    then the Saltelli run; one thread), timed from fork to exit, reading the document and
    writing the result included.
  * prsm, engine: the study's own timing_s.sensitivity (the Saltelli run and the indices).

The runs alternate (OpenTURNS, prsm, OpenTURNS, ...) so that both see the same machine load;
each figure is the best of --repeat runs. Prints JSON: the times, the largest error of each
against the exact indices, and the ratios prsm / OpenTURNS (below 1: prsm is faster).

    apt-get install python3-openturns
    scripts/bench-openturns.py --prsm build/prsm [--repeat 15]

Without --prsm only the OpenTURNS figures are printed.
"""
import argparse
import json
import math
import os
import subprocess
import tempfile
import time

import openturns as ot

N = 16384
EXACT_S = (0.31390519114781146, 0.4424111447900409, 0.0)
EXACT_ST = (0.5575888552099592, 0.4424111447900409, 0.2436836640621477)

model = ot.SymbolicFunction(["x1", "x2", "x3"], ["sin(x1) + 7 * sin(x2)^2 + 0.1 * x3^4 * sin(x1)"])
dist = ot.ComposedDistribution([ot.Uniform(-math.pi, math.pi)] * 3)


def max_error(first, total):
    return max(max(abs(first[i] - EXACT_S[i]), abs(total[i] - EXACT_ST[i])) for i in range(3))


def openturns_run(sampler):
    ot.RandomGenerator.SetSeed(1)
    t0 = time.perf_counter()
    if sampler == "sobol":
        exp = ot.LowDiscrepancyExperiment(ot.SobolSequence(), dist, N, False)
        exp.setRandomize(True)
        design = ot.SobolIndicesExperiment(exp, False).generate()
    else:
        design = ot.SobolIndicesExperiment(dist, N, False).generate()
    y = model(design)
    # first order: Saltelli 2010; total: Jansen 1999 (OpenTURNS' SaltelliSensitivityAlgorithm is
    # Saltelli for both, JansenSensitivityAlgorithm Jansen for both)
    s1 = ot.SaltelliSensitivityAlgorithm(design, y, N).getFirstOrderIndices()
    st = ot.JansenSensitivityAlgorithm(design, y, N).getTotalOrderIndices()
    return time.perf_counter() - t0, max_error(s1, st)


def study_document(sampler):
    tol = {"distribution": "uniform", "lower": -math.pi, "upper": math.pi}
    sobol = {"samples": N, "sampler": sampler}
    if sampler == "random":
        sobol["bootstrap"] = 0  # OpenTURNS computes no intervals here either
    return {"model": {"benchmark": "ishigami", "a": 7, "b": 0.1},
            "tolerances": [dict(tol, parameter=p) for p in ("x1", "x2", "x3")],
            "monte_carlo": {"samples": 1024, "seed": 1, "threads": 1},
            "sensitivity": {"src": False, "stack": False, "sobol": sobol}}


def prsm_run(prsm, path):
    t0 = time.perf_counter()
    out = subprocess.run([prsm, "study", path], stdout=subprocess.PIPE, check=True).stdout
    wall = time.perf_counter() - t0
    r = json.loads(out)
    by = r["outputs"]["y"]["sensitivity"]["tolerances"]
    first = [g["sobol_first"] for g in by]
    total = [g["sobol_total"] for g in by]
    return wall, r["timing_s"]["sensitivity"], max_error(first, total)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--prsm", help="the prsm binary (e.g. build/prsm); without it, OpenTURNS alone")
    ap.add_argument("--repeat", type=int, default=15, help="runs of each, the best is kept (default 15)")
    a = ap.parse_args()
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for sampler in ("sobol", "random"):
            path = os.path.join(tmp, f"ishigami-{sampler}.json")
            with open(path, "w") as f:
                json.dump(study_document(sampler), f)
            ot_best, ot_err = math.inf, None
            whole, engine, p_err = math.inf, math.inf, None
            for _ in range(a.repeat):
                t, ot_err = openturns_run(sampler)
                ot_best = min(ot_best, t)
                if a.prsm:
                    w, e, p_err = prsm_run(a.prsm, path)
                    whole, engine = min(whole, w), min(engine, e)
            row = {"case": f"sobol_indices_ishigami_{N}_{sampler}", "openturns": ot.__version__,
                   "openturns_s": round(ot_best, 4), "openturns_max_error": round(ot_err, 5)}
            if a.prsm:
                row.update({"prsm_process_s": round(whole, 4), "prsm_engine_s": round(engine, 4),
                            "prsm_max_error": round(p_err, 5),
                            "ratio_process": round(whole / ot_best, 3),
                            "ratio_engine": round(engine / ot_best, 3)})
            out.append(row)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
