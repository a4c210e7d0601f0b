"""`python -m bench.forced_nonlinear`: where the linear forced response stops holding.

For one harmonic of the bearing imperfections, away from a resonance (f1, k = 1 at the
example: omega_c = 2513 rad/s, 35 % below omega10) and near one (f3, k = 1 with H set so
that omega_c is 1 % below the radial bearing mode omega_p = 780 rad/s), the periodic
response of the full 11-coordinate equations (gyro.systems.torsion_gyrocompass.nonlinear_response)
against the linear one, on a ladder of amplitudes a, each twice the last at first and then
closer about 1 %, each rung started from the last one's periodic motion (continuation in a):
the first halving gives the order of the neglected terms, the smallest amplitude the
constant c of err = c a^2, and the amplitude a_1% where they differ by 1 % is interpolated
(log-log) between the two measured rungs about it; a ladder that does not cross 1 % says so
and extrapolates from its top. Writes bench/results/forced_linear_limit.json:
the first measured boundary of the linear level (gyro.systems.torsion_gyrocompass.LINEAR_LIMIT,
docs/forced.md).
"""
from __future__ import annotations

import json
import platform
import time
from pathlib import Path

import numpy as np

from gyro import load
from gyro.systems.torsion_gyrocompass import cases, harmonic_balance, linear_error, nonlinear_response, spin_torque

RESULTS = Path(__file__).resolve().parent / "results"
# the integration's tolerance and the shooting's periodicity: the error measured is then
# accurate to about 1e-4 of itself (against runs at 1e-12 and 1e-11: 1.70767e-5 at 100 N,
# 6.8297e-5 at 200 N, 2.7302e-4 at 400 N for 'away'), and the errors are >= 1e-5
RTOL, PERIODIC_TOL = 1e-10, 1e-8


def bench_cases(model):
    values = cases(model)
    return {
        "away": {"values": values["away"][0], "harmonic": (1, 1, None, 0.0), "ladder": (100.0, 200.0, 400.0, 800.0, 1600.0, 2400.0, 3200.0),
                 "what": "f1, k = 1 at the example (omega_c = 2513 rad/s, 35 % below omega10 = 3851 rad/s)"},
        "near": {"values": values["near"][0], "harmonic": (3, 1, None, 0.0), "ladder": (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 24.0, 32.0, 40.0, 48.0, 64.0, 96.0),
                 "what": "f3, k = 1, H = 0.99 omega_p C: omega_c 1 % below the radial bearing mode omega_p = 780 rad/s"},
    }


def measure(model, values, harmonic, a, start=None):
    units = [model.meta["coordinate_units"][c] for c in model.meta["reduced"]]
    s, k, _, phi = harmonic
    t0 = time.perf_counter()
    Xn, Xl, info = nonlinear_response(model, values, (s, k, a, phi), rtol=RTOL, periodic_tol=PERIODIC_TOL,
                                      start=start)
    dX = np.abs(Xn - Xl)
    worst = max(range(len(units)), key=lambda i: dX[i] / max(np.abs(Xl)[[j for j, v in enumerate(units) if v == units[i]]]))
    row = {"a": a, "error": linear_error(Xn, Xl, units), "newton_steps": info["newton_steps"],
           "residual": info["residual"], "seconds": time.perf_counter() - t0,
           # the coordinate that sets the error, and each coordinate's |X_nl| / |X_lin|
           "worst_coordinate": model.meta["reduced"][worst],
           "ratios": {c: float(abs(Xn[i]) / abs(Xl[i])) if abs(Xl[i]) > 0 else None
                      for i, c in enumerate(model.meta["reduced"])},
           "peak_linear": {u: float(np.max(np.abs(Xl)[[i for i, v in enumerate(units) if v == u]])) for u in set(units)}}
    print(f"  a = {a:.6g} N: error {row['error']:.5g}, set by {row['worst_coordinate']} "
          f"({row['newton_steps']} Newton steps, "
          f"residual {row['residual']:.2g}, {row['seconds']:.1f} s)", flush=True)
    # the same response by harmonic balance (an independent method), and its first Newton
    # step's estimate of the linear response's error
    t0 = time.perf_counter()
    try:
        Xh, _, hb = harmonic_balance(model, values, (s, k, a, phi))
    except RuntimeError as exc:  # recorded as it is, never an unconverged number
        row["harmonic_balance"] = {"failed": str(exc), "seconds": time.perf_counter() - t0}
        print(f"    harmonic balance: {exc}", flush=True)
    else:
        t1 = time.perf_counter()  # the linear level's estimate alone: the first Newton step
        harmonic_balance(model, values, (s, k, a, phi), first_step_only=True)
        row["first_step_seconds"] = time.perf_counter() - t1
        row["harmonic_balance"] = {"error": linear_error(Xh, Xl, units), "first_correction": hb["first_correction"],
                                   "newton_steps": hb["newton_steps"], "residual": hb["residual"],
                                   "seconds": t1 - t0,
                                   "against_shooting": float(np.max(np.abs(Xh - Xn)) / np.max(np.abs(Xl)))}
        print(f"    harmonic balance: error {row['harmonic_balance']['error']:.8g} (shooting {row['error']:.8g}), "
              f"first step's estimate {hb['first_correction']:.5g}, {hb['newton_steps']} Newton steps, "
              f"{row['harmonic_balance']['seconds']:.1f} s", flush=True)
    row["z"] = info["continuation"]["z"]
    return row, info["continuation"]


def main() -> None:
    model = load("torsion_gyrocompass")
    out = {"model": model.name, "rtol": RTOL, "periodic_tol": PERIODIC_TOL, "machine": platform.machine(), "cases": {}}
    for name, case in bench_cases(model).items():
        print(f"{name}: {case['what']}", flush=True)
        # a ladder of amplitudes, each halving showing the order; the first rung from the
        # linear start, each next one from the last one's periodic motion
        rows, start = [], None
        for a in case["ladder"]:
            row, start = measure(model, case["values"], case["harmonic"], a, start)
            rows.append(row)
        # the order from the first halving (the cleanest: the next order smallest there), c
        # from the smallest amplitude
        order = float(np.log2(rows[1]["error"] / rows[0]["error"]))
        c = rows[0]["error"] / rows[0]["a"] ** 2
        errs = np.array([r["error"] for r in rows])
        amps = np.array([r["a"] for r in rows])
        if errs[-1] >= 0.01:  # the ladder crosses 1 %: interpolated on log-log between its ends
            i = int(np.argmax(errs >= 0.01))
            p = np.log(errs[i] / errs[i - 1]) / np.log(amps[i] / amps[i - 1])
            limit, how = float(amps[i - 1] * (0.01 / errs[i - 1]) ** (1 / p)), "interpolated between measured amplitudes"
            bracket = [float(amps[i - 1]), float(amps[i])]
        else:  # extrapolated along the local order of the last two points
            p = np.log(errs[-1] / errs[-2]) / np.log(amps[-1] / amps[-2])
            limit, how = float(amps[-1] * (0.01 / errs[-1]) ** (1 / p)), "extrapolated from the largest amplitude measured"
            bracket = None
        # at the limit itself: the error there (the interpolation's check) and what the
        # left-out torque on the spin would change (gyro.systems.torsion_gyrocompass.spin_torque)
        below = max((r for r in rows if r["a"] <= limit), key=lambda r: r["a"], default=None)
        Xn, Xl, info = nonlinear_response(model, case["values"], (case["harmonic"][0], case["harmonic"][1], limit,
                                                                  case["harmonic"][3]),
                                          rtol=RTOL, periodic_tol=PERIODIC_TOL,
                                          start=None if below is None else {"z": below["z"], "a": below["a"]})
        units = [model.meta["coordinate_units"][c] for c in model.meta["reduced"]]
        at_limit = {"a": limit, "error": linear_error(Xn, Xl, units),
                    "spin_torque": spin_torque(model, case["values"], (case["harmonic"][0], case["harmonic"][1],
                                                                       limit, case["harmonic"][3]), info)}
        print(f"  at a_1%: error {at_limit['error']:.5g}; the left-out spin torque: momentum swing "
              f"{at_limit['spin_torque']['momentum_swing']:.3g} of H, effect ~{at_limit['spin_torque']['effect_estimate']:.2g}",
              flush=True)
        for r in rows:
            r.pop("z")
        out["cases"][name] = {"what": case["what"], "values": case["values"],
                              "harmonic": {"s": case["harmonic"][0], "k": case["harmonic"][1], "phase": case["harmonic"][3]},
                              "order": order, "c": c, "a_1percent": limit, "a_1percent_is": how,
                              "a_1percent_between": bracket,
                              "largest_measured": rows[-1]["a"], "error_at_largest": rows[-1]["error"], "at_limit": at_limit,
                              "runs": rows}
        print(f"  order {order:.4f}; c = {c:.5g} N^-2; a_1% = {limit:.4g} N ({how})", flush=True)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "forced_linear_limit.json").write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {RESULTS / 'forced_linear_limit.json'}")


if __name__ == "__main__":
    main()
