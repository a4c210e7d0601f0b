"""`python -m bench.ghc_integrators`: the gyrohorizoncompass's integral E (2.3) against CPU
time for DOP853, Radau, CVODES (BDF and Adams) and an energy-preserving scheme (`projected`: fixed steps of
DOP853's 8th-order tableau, each projected onto E = E(0)), on the laboratory set (`LAB` of
derive/models/gyrohorizoncompass.py), from a state 0.05 rad off the relative equilibrium;
and the maps of the (3.6) region, the spectrally stable one and the unstable one.

Horizon: 1e4 periods of the slowest mode (0.347 rad/s: 1.81e5 s) for every method but
Radau, whose Python-level Newton iterations would take 11 min at rtol 1e-6 alone; Radau
runs 1e3 periods (its drift over 1e4 is at least the one shown). Writes
bench/results/ghc_integrators.json, ghc_integrators.png, ghc_map_zeta_eta.png,
ghc_map_theta_chi.png and ghc_map_theta_chi_zoom.png (`--maps` writes only the maps;
`--only METHOD` reruns one method's points into the existing JSON).
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

from derive.models.gyrohorizoncompass import LAB
from gyro.systems import gyrohorizoncompass as ghc

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
OFFSET = np.array([0.05, -0.03, 0.04, 0.05, 0.01, 0.0, -0.02, 0.01])  # as tests/paper/test_gyrohorizoncompass.py
PERIODS = 1e4
RUNS = [  # (method, tolerance or steps per radian of the fastest mode, periods)
    ("cvodes", 1e-8, PERIODS), ("cvodes", 1e-10, PERIODS), ("cvodes", 1e-12, PERIODS),
    ("cvodes-adams", 1e-10, PERIODS), ("cvodes-adams", 1e-12, PERIODS),
    ("projected", 4.0, PERIODS), ("projected", 10.0, PERIODS),
    ("DOP853", 1e-8, PERIODS), ("DOP853", 1e-10, PERIODS / 10),
    ("Radau", 1e-6, PERIODS / 10),
]
LABELS = {"projected": "DOP853 tableau, fixed step, projected on E (energy-preserving)",
          "cvodes": "CVODES (CasADi), BDF", "cvodes-adams": "CVODES (CasADi), Adams", "DOP853": "DOP853 (SciPy)",
          "Radau": "Radau (SciPy)"}
SAMPLES = 2001  # output points (E is checked there)
MAP_BASE = {k: LAB[k] for k in ("A", "B", "C", "J", "L", "I", "nu")}
MAPS = {  # name -> (base additions, x axis, y axis)
    "zeta_eta": ({}, ("zeta", 0.01, 0.9, 90), ("eta", 0.0, 1.2, 121)),
    "theta_chi": ({"zeta": LAB["zeta"], "eta": LAB["eta"]}, ("theta", -0.5, 0.6, 111), ("chi", -0.5, 0.6, 111)),
    "theta_chi_zoom": ({"zeta": LAB["zeta"], "eta": LAB["eta"]}, ("theta", 0.2, 0.32, 121), ("chi", 0.3, 0.36, 61)),
}


def run(method: str, setting: float, periods: float, values: dict, y0: np.ndarray, slowest: float) -> dict:
    t = np.linspace(0.0, periods * 2 * np.pi / slowest, SAMPLES)
    c0 = time.process_time()
    if method == "projected":
        Y = ghc.integrate(values, y0, t, method, steps_per_radian=setting)
    else:
        Y = ghc.integrate(values, y0, t, method, rtol=setting, atol=setting * 1e-2)
    cpu = time.process_time() - c0
    E = ghc.energy(values, Y)
    drift = float(np.max(np.abs(E - E[0])) / abs(E[0]))
    return {"method": method, "setting": setting, "periods": periods, "t_end": float(t[-1]), "cpu_s": cpu,
            "E_drift": drift, "final_state": Y[-1].tolist()}


def maps(out: Path) -> dict:
    res = {}
    for name, (extra, xa, ya) in MAPS.items():
        values = ghc.parameters({**MAP_BASE, **extra}, need_equilibrium=False)
        m = ghc.condition_map(values, xa, ya)
        m.plot(out / f"ghc_map_{name}.png")
        res[name] = {"x": list(xa), "y": list(ya), "counts": m.counts(), "base": m.base}
        print(f"map {name}: {m.counts()}", flush=True)
    return res


def chart(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gyro.results import save_figure

    colors = {"DOP853": "tab:blue", "Radau": "tab:orange", "cvodes": "tab:green", "cvodes-adams": "tab:olive",
              "projected": "tab:red"}
    fig, ax = plt.subplots(figsize=(7.5, 5.5), layout="constrained")
    for m, color in colors.items():
        rs = sorted((r for r in rows if r["method"] == m), key=lambda r: r["cpu_s"])
        for r in rs:
            full = r["periods"] >= PERIODS
            ax.loglog(r["cpu_s"], max(r["E_drift"], 1e-17), "o" if full else "s", color=color,
                      mfc=color if full else "none", ms=8)
            lab = f"{r['setting']:g}" + (" steps/rad" if m == "projected" else "") + ("" if full else ", 1e3 periods")
            ax.annotate(lab, (r["cpu_s"], max(r["E_drift"], 1e-17)), textcoords="offset points", xytext=(6, 4),
                        fontsize=7)
        ax.plot([], [], "o", color=color, label=LABELS[m])
    ax.plot([], [], "s", mfc="none", color="k", label="open square: 1e3 periods (cost and drift grow with the horizon)")
    ax.set_xlabel("CPU time [s]")
    ax.set_ylabel("max |E - E(0)| / |E(0)|")
    ax.set_title("Gyrohorizoncompass, laboratory set: drift of E over 1e4 periods of the slowest mode\n"
                 "(1.81e5 s, from 0.05 rad off the relative equilibrium; label: rtol or steps per radian)", fontsize=9)
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="upper right")
    save_figure(fig, path)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", action="store_true", help="only the maps")
    ap.add_argument("--only", metavar="METHOD", help="only this method's runs, merged into the existing JSON")
    args = ap.parse_args(argv)
    RESULTS.mkdir(parents=True, exist_ok=True)
    doc = {"python": sys.version.split()[0], "machine": platform.machine(), "set": "LAB", "offset": OFFSET.tolist()}
    doc["maps"] = maps(RESULTS)
    if args.maps:  # the maps' entry of an earlier run's JSON, brought up to date
        path = RESULTS / "ghc_integrators.json"
        old = json.loads(path.read_text()) if path.exists() else doc
        old["maps"] = doc["maps"]
        path.write_text(json.dumps(old, indent=1))
        return 0
    values = ghc.parameters({ghc.cli_name(k): v for k, v in LAB.items()})
    w = ghc.frequencies(values)
    y0 = ghc.initial_state(values) + OFFSET
    doc["modes_rad_s"] = w.tolist()
    rows = []
    path = RESULTS / "ghc_integrators.json"
    if args.only:
        old = json.loads(path.read_text())
        doc["maps"] = old["maps"]
        rows = [r for r in old["runs"] if r["method"] != args.only]
    for method, setting, periods in RUNS:
        if args.only and method != args.only:
            continue
        r = run(method, setting, periods, values, y0, float(w[0]))
        rows.append(r)
        print(f"{method:>10} {setting:<8g} {periods:>7g} periods: {r['cpu_s']:8.2f} s CPU, E drift {r['E_drift']:.2e}",
              flush=True)
    ref = next(r for r in rows if r["method"] == "projected" and r["setting"] == 10.0)
    for r in rows:
        if r["periods"] == ref["periods"]:
            diff = np.subtract(r["final_state"], ref["final_state"])
            r["state_difference_to_projected_10"] = float(np.max(np.abs(diff)))
    doc["runs"] = rows
    path.write_text(json.dumps(doc, indent=1))
    chart(rows, RESULTS / "ghc_integrators.png")
    print(f"wrote {RESULTS / 'ghc_integrators.json'} and ghc_integrators.png", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
