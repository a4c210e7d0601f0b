"""`python -m bench.forced_speed`: speed of the harmonic response beside the default frequency
method, in one run (medians of several repeats; ratios are what holds on a shared machine).

- one harmonic's steady response for a batch of parameter sets (gyro.analyses.harmonic,
  the equilibria included, and with the equilibria given), us per set;
- the response curve of one harmonic over 1e4 spin values (gyro.analyses.forced.response_curve), s.
Writes bench/results/forced_speed.json.
"""
from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from gyro import load
from gyro.analyses.forced import response_curve
from gyro.analyses.harmonic import harmonic_response
from gyro.equilibrium import equilibria
from gyro.ladder import spectrum

RESULTS = Path(__file__).resolve().parent / "results"
SETS = 4096
REPEATS = 5


def _median(f, repeats=REPEATS):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def main() -> None:
    model = load("torsion_gyrocompass")
    rng = np.random.default_rng(1)
    P = np.tile(model.vector({}), (SETS, 1))
    for name, lo, hi in (("H", 0.1, 1.0), ("phi", 0.0, 80.0), ("Kp", 1e5, 4e5)):
        P[:, model.param_names.index(name)] = rng.uniform(lo, hi, SETS)
    W = P[:, model.param_names.index("H")] / P[:, model.param_names.index("C")]
    u = np.array([0, 0, -1j])  # f3 = sin(omega_c t)
    harmonic_response(model, P[:64], W[:64], u)  # compile and warm up
    spectrum(model, P[:64])
    qe, _ = equilibria(model, P)
    t_default = _median(lambda: spectrum(model, P, "default")) / SETS
    t_full = _median(lambda: harmonic_response(model, P, W, u)) / SETS
    t_given = _median(lambda: harmonic_response(model, P, W, u, qe=qe)) / SETS
    C = model.defaults["C"]
    wp = (model.defaults["Kp"] / model.defaults["m"]) ** 0.5
    t_curve = _median(lambda: response_curve(model, {}, (3, 1, 1.0, 0.0), 0.5 * wp * C, 2 * wp * C, 10_000), 3)
    out = {"sets": SETS, "repeats": REPEATS, "machine": platform.machine(), "cpus": os.cpu_count(),
           "load_average": os.getloadavg()[0],
           "default_method_us_per_set": t_default * 1e6,
           "harmonic_response_us_per_set": t_full * 1e6,
           "harmonic_response_equilibria_given_us_per_set": t_given * 1e6,
           "ratio_to_default": t_full / t_default,
           "response_curve_1e4_spins_s": t_curve,
           "goals": {"harmonic_response_us_per_set": 20.0, "response_curve_1e4_spins_s": 1.0}}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "forced_speed.json").write_text(json.dumps(out, indent=1) + "\n")
    for k, v in out.items():
        print(f"{k}: {v}")


if __name__ == "__main__":
    main()
