"""`python -m bench.gimbal_integrators`: the gimbal gyroscope's closed form (2.6) against
integrators of the generated equations (1.1): error against CPU time over 100 and 1e4
periods and near the separatrix, the drift of the integrals H, L, M, and the closed
form's evaluation rate. Writes bench/results/gimbal.json and gimbal_integrators.png.

Reference: the closed form. Its own error is measured against the same formula evaluated
in mpmath at 40 digits (sn, cn from mpmath, not the NumPy AGM) at sample points.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
import warnings
from pathlib import Path

import mpmath as mp
import numpy as np

from gyro.systems.gimbal_gyroscope import ClosedForm, Motion, integrals, integrate, kick, stationary_motion

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
DEFAULTS = {"A0": 0.02, "B0": 0.015, "C0": 0.0, "A3": 0.01, "P1": 5.0, "eta20": 0.002,
            "eta30": 0.01, "P": 10.0, "l": 0.02}
OSCILLATION = (1.2, 3.0, 1.0, 200.0)  # period 0.0585 s
SHORT = {"RK45": [1e-6, 1e-8, 1e-10], "DOP853": [1e-8, 1e-10, 1e-12], "Radau": [1e-6, 1e-8, 1e-10],
         "BDF": [1e-6, 1e-8], "cvodes": [1e-6, 1e-8, 1e-10, 1e-12], "idas": [1e-8, 1e-10]}
LONG = {"RK45": [1e-8], "DOP853": [1e-10], "cvodes": [1e-8, 1e-10, 1e-12], "idas": [1e-10]}
NEAR = {"RK45": [1e-10], "DOP853": [1e-12], "cvodes": [1e-12]}
KICKS = [1e-3, 1e-6, 1e-9]  # theta' kick off the unstable stationary motion theta0 = 0.3, H = 0.05


def theta_mp(cf: ClosedForm, tau: float) -> float:
    """(2.6) at 40 digits: wp from mpmath's Jacobi functions, the same unwrapping table."""
    with mp.workdps(40):
        kind, scale, m, _, omega = cf.wp.setup
        k = mp.floor(tau / (2 * omega))
        tr = mp.mpf(tau) - 2 * omega * k
        u = scale * tr
        sn, cn, dn = (mp.ellipfun(f, u, m=m) for f in ("sn", "cn", "dn"))
        if kind == "real":
            e3 = cf.wp.roots[2][2]
            P, W = e3 + scale**2 / sn**2, -2 * scale**3 * cn * dn / sn**3
        else:
            e2, H2 = cf.wp.roots[0], scale**2 / 4
            P, W = e2 + H2 * (1 + cn) / (1 - cn), -4 * H2**1.5 * sn * dn / (1 - cn) ** 2
        Np, Dp, Nw, Dw = cf._pairs(P, W, xp=mp)
        s = Np / Dp if mp.hypot(Np, Dp) >= mp.hypot(Nw, Dw) else Nw / Dw
        j = int(np.sum(cf.jumps[cf.crossings <= float(tr)]))
        return float(cf.motion.theta0 + 2 * mp.atan(s) + 2 * mp.pi * (j + k * cf.net_turns))


def closed_form_run(mo: Motion, t: np.ndarray, n_check: int = 12) -> dict:
    c0 = time.process_time()
    cf = ClosedForm(mo)
    th = cf.theta(t)
    cpu = time.process_time() - c0
    idx = np.linspace(1, len(t) - 1, n_check).astype(int)  # t = 0 is the pole of wp
    err = max(abs(th[i] - theta_mp(cf, t[i] / cf.time_scale)) for i in idx)
    return {"method": "closed_form", "rtol": None, "cpu_s": cpu, "error": float(err), "theta": th, "cf": cf}


def integrator_run(mo: Motion, t: np.ndarray, method: str, rtol: float, ref: np.ndarray) -> dict:
    c0 = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            q, qd = integrate(mo, t, method, rtol=rtol, atol=rtol * 1e-3)
        except FloatingPointError as exc:
            return {"method": method, "rtol": rtol, "failed": str(exc), "cpu_s": time.process_time() - c0}
    cpu = time.process_time() - c0
    I = integrals(mo.params, q, qd)
    drift = {k: float(np.max(np.abs(v - v[0])) / abs(v[0])) for k, v in I.items()}
    return {"method": method, "rtol": rtol, "cpu_s": cpu, "error": float(np.max(np.abs(q[:, 1] - ref))),
            "integral_drift": drift}


def horizon(mo: Motion, periods: float, table: dict, n: int = 2001, label: str = "") -> list[dict]:
    cf = ClosedForm(mo)
    t = np.linspace(0, periods * cf.period, n)
    rows = [closed_form_run(mo, t)]
    ref = rows[0]["theta"]
    for method, tols in table.items():
        for rtol in tols:
            r = integrator_run(mo, t, method, rtol, ref)
            print(f"  {label} {method:>7} rtol {rtol:.0e}: error {r.get('error', float('nan')):.2e} rad, "
                  f"CPU {r['cpu_s']:.2f} s, drift {r.get('integral_drift')}", flush=True)
            rows.append(r)
    for r in rows:
        r.pop("theta", None)
        r.pop("cf", None)
    print(f"  {label} closed form: error {rows[0]['error']:.2e} rad, CPU {rows[0]['cpu_s'] * 1e3:.1f} ms", flush=True)
    return rows


def evaluation_rate(n: int = 10**6, repeat: int = 5) -> dict:
    cf = ClosedForm(Motion(DEFAULTS, *OSCILLATION))
    t = np.linspace(0, 1e4 * cf.period, n)
    cf.theta(t[:100])
    best = min(_timed(lambda: cf.theta(t)) for _ in range(repeat))
    psi_n = n // 10
    best_psi = min(_timed(lambda: cf.psi_phi(t[:psi_n])) for _ in range(2))
    return {"theta_points_per_s": n / best, "psi_phi_points_per_s": psi_n / best_psi, "points": n}


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def chart(res: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    markers = {"closed_form": "*", "RK45": "o", "DOP853": "s", "Radau": "^", "BDF": "v", "cvodes": "D", "idas": "P"}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    panels = [("100 periods", res["periods_100"]), ("1e4 periods", res["periods_1e4"])]
    for ax, (title, rows) in zip(axes[:2], panels):
        for m in markers:
            pts = [(r["cpu_s"], max(r["error"], 1e-16)) for r in rows if r["method"] == m and "error" in r]
            if pts:
                x, y = zip(*pts)
                ax.loglog(x, y, markers[m], label=m, ms=10 if m == "closed_form" else 7)
        ax.set_title(f"oscillation, {title}")
    for i, eps in enumerate(KICKS):
        rows = res["near_separatrix"][str(eps)]["rows"]
        for m in markers:
            pts = [(r["cpu_s"], max(r["error"], 1e-16)) for r in rows if r["method"] == m and "error" in r]
            if pts:
                x, y = zip(*pts)
                axes[2].loglog(x, y, markers[m], color=f"C{i}", label=f"{m}, kick {eps:g}" if m in ("closed_form", "DOP853") else None)
    axes[2].set_title("near the separatrix, 10 periods (colour: kick)")
    for ax in axes:
        ax.set_xlabel("CPU time [s]")
        ax.set_ylabel("max |theta - reference| [rad]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    tmp = path.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=90)
    tmp.replace(path)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.gimbal_integrators", description=__doc__)
    ap.add_argument("--quick", action="store_true", help="1e3 instead of 1e4 periods (a smoke run)")
    args = ap.parse_args(argv)
    RESULTS.mkdir(parents=True, exist_ok=True)
    mo = Motion(DEFAULTS, *OSCILLATION)
    res = {"case": {"params": DEFAULTS, "initial": dict(zip(("theta0", "dtheta0", "dpsi0", "dphi0"), OSCILLATION)),
                    "period_s": ClosedForm(mo).period}}
    print("closed-form evaluation rate ...", flush=True)
    res["rate"] = evaluation_rate()
    print(f"  theta: {res['rate']['theta_points_per_s']:.3g} points/s (goal >= 1e6); "
          f"psi, phi: {res['rate']['psi_phi_points_per_s']:.3g} points/s", flush=True)
    print("100 periods ...", flush=True)
    res["periods_100"] = horizon(mo, 100, SHORT, label="100")
    long_periods = 1e3 if args.quick else 1e4
    print(f"{long_periods:g} periods ...", flush=True)
    res["periods_1e4"] = horizon(mo, long_periods, LONG, n=20001, label=f"{long_periods:g}")
    res["long_periods"] = long_periods
    st = stationary_motion(DEFAULTS, 0.3, 0.05)
    res["near_separatrix"] = {}
    for eps in KICKS:
        m = kick(st, eps)
        cf = ClosedForm(m)
        print(f"near the separatrix, kick {eps:g}: period {cf.period:.4g} s ...", flush=True)
        res["near_separatrix"][str(eps)] = {"period_s": cf.period, "rows": horizon(m, 10, NEAR, label=f"kick {eps:g}")}
    res["machine"] = {"python": platform.python_version(), "processor": platform.machine(),
                      "cores": __import__("os").cpu_count()}
    path = RESULTS / "gimbal.json"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(res, indent=1, sort_keys=True, default=float) + "\n")
    tmp.replace(path)
    chart(res, RESULTS / "gimbal_integrators.png")
    print(f"written {path.relative_to(ROOT)} and bench/results/gimbal_integrators.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
