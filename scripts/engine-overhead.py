#!/usr/bin/python3
"""The Monte Carlo engine's overhead on case A, counted in instructions (docs/speed.md).

The study: the case-A tolerance set of `prsm bench` (src/cli/bench_study.c, 40 variables: the
screw's and nut's pitch radius, thickness and runout, per-roller pitch radius, thickness and pin
position, the carrier's runout, the phases of the radial errors), outputs backlash, load sharing
and stiffness in linear mode, 20,000 samples on one thread, no SRC or stack. valgrind's callgrind
counts the instructions of `prsm study` on it; the model is everything under the model's eval
(prsm_eval, inclusive), the engine the rest of the run (prsm_mc_run, inclusive, plus the
workers' worker_main where a build runs its blocks on threads): the sampler (Philox), the
quantiles, the copula, the bookkeeping. Deterministic where a timer on a shared machine is not.

    scripts/engine-overhead.py --prsm build/prsm

Prints JSON: instructions of the model and the engine, the engine's share of the model's
(target < 5 %), and its quantile and Philox parts.
"""
import argparse
import json
import os
import re
import subprocess
import tempfile

TOLERANCES = [
    {"parameter": "screw.pitch_radius_um", "tol_um": 4},
    {"parameter": "nut.pitch_radius_um", "tol_um": 5},
    {"parameter": "screw.thickness_um", "tol_um": 3, "cpk": 1.33},
    {"parameter": "nut.thickness_um", "tol_um": 3, "cpk": 1.33},
    {"parameter": "screw.runout_um", "tol_um": 8},
    {"parameter": "nut.runout_um", "distribution": "rayleigh", "sigma": 2.5},
    {"parameter": "roller.pitch_radius_um", "distribution": "normal", "sd": 1.0},
    {"parameter": "roller.thickness_um", "tol_um": 2},
    {"parameter": "roller.pin_radial_um", "distribution": "uniform", "lower": -5, "upper": 5},
    {"parameter": "carrier.runout_um", "distribution": "rayleigh", "sigma": 3.0},
]
STUDY = {
    "design": {"geometry": {"starts": 5, "pitch_mm": 2, "flank_angle_deg": 45, "roller_radius_mm": 3.25,
                            "rollers": 10, "engaged_threads": 10},
               "target_axial_clearance_um": 20,
               "operating_point": {"axial_load_N": 7000, "screw_speed_rpm": 955}},
    "tolerances": TOLERANCES,
    "outputs": ["backlash_um", "load_sharing_factor", "stiffness_N_per_um"],
    "monte_carlo": {"samples": 20000, "block_size": 1024, "seed": 1, "threads": 1},
    "sensitivity": {"src": False, "stack": False},
}


def inclusive(annotated, function):
    """The largest inclusive count callgrind_annotate lists for function (0 when absent)."""
    best = 0
    for line in annotated.splitlines():
        m = re.match(r"\s*([\d,]+)\s+\([^)]*\)\s+(\S+)", line)
        if m and m.group(2).endswith(":" + function):
            best = max(best, int(m.group(1).replace(",", "")))
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--prsm", required=True, help="the prsm binary (e.g. build/prsm)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        doc, out = os.path.join(tmp, "case-a.json"), os.path.join(tmp, "callgrind.out")
        with open(doc, "w") as f:
            json.dump(STUDY, f)
        subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out, a.prsm, "study", doc],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        ann = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", out],
                             capture_output=True, text=True, check=True).stdout
    model = inclusive(ann, "prsm_eval")
    run = inclusive(ann, "prsm_mc_run") + inclusive(ann, "worker_main")
    engine = run - model
    print(json.dumps({
        "model_instructions": model,
        "engine_instructions": engine,
        "engine_percent_of_model": round(100.0 * engine / model, 2),
        "quantile_instructions": inclusive(ann, "prsm_dist_quantile_n") or inclusive(ann, "prsm_dist_quantile"),
        "philox_instructions": inclusive(ann, "prsm_rng_fill_uniform_pos"),
    }, indent=2))


if __name__ == "__main__":
    main()
