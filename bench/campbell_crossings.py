"""`python -m bench.campbell_crossings`: the Campbell diagram of the torsion gyrocompass over the
default sweep (200 spins, 0.1x..10x H) with and without the crossings of 5 harmonic lines
(k = 1..5, Brent's method on the spin), beside the default method on the same 200 sets in
the same run (medians of 5; the ratios are what a noisy machine keeps). Results:
bench/results/campbell_crossings.json, and the diagram with the lines k omega_c and their
crossings, bench/results/campbell_harmonics.png. Goal (issue 19): the crossings of 5
harmonics in under 2 s."""
from __future__ import annotations

import json
import statistics
import time
from pathlib import Path

import numpy as np

from gyro import ladder, models
from gyro.analyses.campbell import sweep

RESULTS = Path(__file__).resolve().parent / "results"
REPEAT = 5


def _median(f) -> float:
    times = []
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> dict:
    m = models.load("torsion_gyrocompass")
    v = m.defaults
    P = np.tile(m.vector(v), (200, 1))
    P[:, m.param_names.index("H")] = v["H"] * np.geomspace(0.1, 10, 200)
    sweep(m, v, 0.1, 10, 10, harmonics=(1,))  # compiled once, warm
    base = _median(lambda: ladder.spectrum(m, P, "default"))
    plain = _median(lambda: sweep(m, v, 0.1, 10, 200))
    five = _median(lambda: sweep(m, v, 0.1, 10, 200, harmonics=(1, 2, 3, 4, 5)))
    diagram = sweep(m, v, 0.1, 10, 200, harmonics=(1, 2, 3, 4, 5))
    crossings = len(diagram.crossings)
    RESULTS.mkdir(exist_ok=True)
    diagram.plot(RESULTS / "campbell_harmonics.png")  # the README's figure of the resonances
    out = {"default_method_200_sets_s": base, "campbell_200_spins_s": plain, "campbell_5_harmonics_s": five,
           "crossings_only_s": five - plain, "crossings": crossings,
           "campbell_over_default": plain / base, "crossings_over_default": (five - plain) / base,
           "goal_crossings_s": 2.0}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "campbell_crossings.json").write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main()
