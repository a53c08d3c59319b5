#!/usr/bin/python3
"""Reference timing for `prsm bench`'s Sobol entries: the same computation in OpenTURNS.

Sobol' first and total indices of the Ishigami function (a = 7, b = 0.1) from a Saltelli design
of N = 16384 base samples (N (d + 2) = 81920 evaluations), plain Monte Carlo and Sobol' sampling,
with OpenTURNS' Saltelli (first) and Jansen (total) estimators: the estimators prsm uses. Prints
seconds (design + evaluation + indices, best of 5) and the largest error against the exact indices
of reference/benchmarks.md. Needs Debian's python3-openturns (not installed by `make test`):

    apt-get install python3-openturns && scripts/bench-openturns.py
"""
import json
import math
import time

import openturns as ot

N = 16384
EXACT_S = (0.31390519114781146, 0.4424111447900409, 0.0)
EXACT_ST = (0.5575888552099592, 0.4424111447900409, 0.2436836640621477)

model = ot.SymbolicFunction(["x1", "x2", "x3"], ["sin(x1) + 7 * sin(x2)^2 + 0.1 * x3^4 * sin(x1)"])
dist = ot.ComposedDistribution([ot.Uniform(-math.pi, math.pi)] * 3)


def run(sampler):
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
    dt = time.perf_counter() - t0
    err = max(max(abs(s1[i] - EXACT_S[i]), abs(st[i] - EXACT_ST[i])) for i in range(3))
    return dt, err


out = []
for sampler in ("sobol", "random"):
    best = min(run(sampler)[0] for _ in range(5))
    _, err = run(sampler)
    out.append({"name": f"openturns_sobol_indices_ishigami_16384_{sampler}", "seconds": round(best, 4),
                "max_error": round(err, 5), "openturns": ot.__version__})
print(json.dumps(out, indent=2))
