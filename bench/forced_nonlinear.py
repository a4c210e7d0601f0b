"""`python -m bench.forced_nonlinear`: where the linear forced response stops holding.

For one harmonic of the bearing imperfections, away from a resonance (f1, k = 1 at the
example: omega_c = 2513 rad/s, 35 % below omega10) and near one (f3, k = 1 with H set so
that omega_c is 1 % below the radial bearing mode omega_p = 780 rad/s), the periodic
response of the full 11-coordinate equations (gyro.analyses.forced.nonlinear_response)
against the linear one: the relative error at a ladder of amplitudes a (each halving
shows the order of the neglected terms) and the amplitude a_1% where they differ by 1 %
(the error is measured as err = c a^p; a_1% from the fit, then checked by one more run).
Writes bench/results/forced_linear_limit.json: the first measured boundary of the linear
level (gyro.analyses.forced.LINEAR_LIMIT, docs/forced.md).
"""
from __future__ import annotations

import json
import platform
import time
from pathlib import Path

import numpy as np

from gyro import load
from gyro.analyses.forced import linear_error, nonlinear_response

RESULTS = Path(__file__).resolve().parent / "results"
RTOL = 1e-12  # the integration's tolerance: the errors measured are >= 1e-5


def cases(model):
    C = model.defaults["C"]
    wp = (model.defaults["Kp"] / model.defaults["m"]) ** 0.5
    return {
        "away": {"values": {}, "harmonic": (1, 1, None, 0.0), "a0": 400.0,
                 "what": "f1, k = 1 at the example (omega_c = 2513 rad/s, 35 % below omega10 = 3851 rad/s)"},
        "near": {"values": {"H": 0.99 * wp * C}, "harmonic": (3, 1, None, 0.0), "a0": 4.0,
                 "what": "f3, k = 1, H = 0.99 omega_p C: omega_c 1 % below the radial bearing mode omega_p = 780 rad/s"},
    }


def measure(model, values, harmonic, a):
    units = [model.meta["coordinate_units"][c] for c in model.meta["reduced"]]
    s, k, _, phi = harmonic
    t0 = time.perf_counter()
    Xn, Xl, info = nonlinear_response(model, values, (s, k, a, phi), rtol=RTOL)
    row = {"a": a, "error": linear_error(Xn, Xl, units), "newton_steps": info["newton_steps"],
           "residual": info["residual"], "seconds": time.perf_counter() - t0,
           "peak_linear": {u: float(np.max(np.abs(Xl)[[i for i, v in enumerate(units) if v == u]])) for u in set(units)}}
    print(f"  a = {a:.6g} N: error {row['error']:.5g} ({row['newton_steps']} Newton steps, "
          f"residual {row['residual']:.2g}, {row['seconds']:.1f} s)", flush=True)
    return row


def main() -> None:
    model = load("torsion_gyrocompass")
    out = {"model": model.name, "rtol": RTOL, "machine": platform.machine(), "cases": {}}
    for name, case in cases(model).items():
        print(f"{name}: {case['what']}", flush=True)
        a0 = case["a0"]
        while True:  # two amplitudes a0, a0/2 with errors above 1e-5 (far above the integration's)
            rows = [measure(model, case["values"], case["harmonic"], a) for a in (a0, a0 / 2)]
            if rows[1]["error"] > 1e-5:
                break
            a0 *= min(1e3, (1e-3 / rows[0]["error"]) ** 0.5)
        order = float(np.log2(rows[0]["error"] / rows[1]["error"]))
        # err = c a^order through the first point: a_1% = a (0.01/err)^(1/order), then checked
        a1 = rows[0]["a"] * (0.01 / rows[0]["error"]) ** (1 / order)
        for _ in range(3):
            r = measure(model, case["values"], case["harmonic"], a1)
            rows.append(r)
            if abs(r["error"] / 0.01 - 1) < 0.02:
                break
            # local order from the last two points
            p = np.log(r["error"] / rows[-2]["error"]) / np.log(r["a"] / rows[-2]["a"])
            a1 = r["a"] * (0.01 / r["error"]) ** (1 / p)
        out["cases"][name] = {"what": case["what"], "values": case["values"],
                              "harmonic": {"s": case["harmonic"][0], "k": case["harmonic"][1], "phase": case["harmonic"][3]},
                              "order": order, "a_1percent": rows[-1]["a"], "error_at_limit": rows[-1]["error"],
                              "runs": rows}
        print(f"  order {order:.3f}; a_1% = {rows[-1]['a']:.4g} N", flush=True)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "forced_linear_limit.json").write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {RESULTS / 'forced_linear_limit.json'}")


if __name__ == "__main__":
    main()
