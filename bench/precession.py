"""`python -m bench.precession`: the precession hierarchy of gimbal_precession (002).

- the cost of each level (the motion question's evaluator, 10 s horizon, 201 samples, with its bound):
  median CPU time of 5 runs, the numbers `derive/models/gimbal_precession.py` declares;
- the orders: `small` against `image` over the image point's size A (fitted slope of the
  relative error, expected 2), `rigorous` against `full` over H with and without the base
  rate (expected 1 with it: the cross term J u omega_p; without, at least 2);
- where (2) fails: `elementary` against `rigorous` over two parameters for each condition
  of (29) violated alone (friction in the axes, the outer ring's imbalance, moments about
  the spin axis, the image point not small), the maps and their values at tol 1e-2;
- speed and accuracy: the error of each level against `full` (at a 100x tighter tolerance
  for `full` itself) against CPU time per simulated hour on three scenes.
Writes bench/results/precession.json and the figures precession_speed.png,
precession_map_<condition>.png.
"""
from __future__ import annotations

import json
import platform
import time
from pathlib import Path

import numpy as np

from gyro.systems import gimbal_precession as pr
from gyro.analyses.level_map import level_map
from gyro.models import load

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"

TORQUES = {"l_x": 1e-3, "l_y": 5e-4}
SCENES = {
    "laboratory, (29) met": dict(TORQUES),
    "outer-ring imbalance k_xi1 = 1e-4 N m": {**TORQUES, "k_xi1": 1e-4},
    "axis friction f_alpha = f_beta = 0.02 N m s": {**TORQUES, "f_alpha": 0.02, "f_beta": 0.02},
}
HORIZON = 20.0  # s, the chart's runs (CPU time scaled to one simulated hour)
MAPS = {
    "friction": ("f_alpha=0:0.05:9", "f_beta=0:0.05:9", dict(TORQUES)),
    "imbalance": ("k_xi1=-2e-4:2e-4:9", "l_x=2e-4:2e-3:9", {"l_y": 5e-4}),
    "spin_axis": ("m_z=-2e-3:2e-3:9", "l_z=-2e-3:2e-3:9", dict(TORQUES)),
    "not_small": ("alpha0=-0.3:0.3:9", "beta0=-0.3:0.3:9", dict(TORQUES)),
}
MAP_T, MAP_TOL = 10.0, 1e-2


def costs(reps: int = 5) -> dict:
    from gyro.questions.motion import POINTS

    mo = pr.Motion(pr.parameters({}))
    t = np.linspace(0.0, 10.0, POINTS)
    out = {}
    for lv in pr.LEVELS:
        pr.motion_answer(mo, t, lv)  # build the integrators
        ts = []
        for _ in range(reps):
            c0 = time.process_time()
            pr.motion_answer(mo, t, lv)
            ts.append(time.process_time() - c0)
        out[lv] = float(np.median(ts))
        print(f"cost {lv}: {out[lv]:.3g} s per set (10 s horizon, with its bound)", flush=True)
    return out


def _slope(xs, ys) -> float:
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def orders() -> dict:
    t = np.linspace(0.0, 10.0, 401)
    amps = [0.005, 0.01, 0.02, 0.04, 0.08]
    e_small = []
    for a in amps:
        v = pr.parameters({"alpha0": -0.8 * a, "beta0": 0.6 * a, "l_x": 0, "u_xi": 0, "u_eta": 1e-4, "u_zeta": 0})
        e_small.append(pr.image_error(pr.simulate(v, t, "small"), pr.simulate(v, t, "image")))
    out = {"small_vs_image": {"A": amps, "error": e_small, "slope": _slope(amps, e_small),
                              "scene": "torque-free, u_eta = 1e-4 rad/s, image point at A (0.6, 0.8), 10 s"}}
    t = np.linspace(0.0, 5.0, 401)
    Hs = [0.5, 1.0, 2.0, 4.0, 8.0]
    for key, base in (("with_base_rate", {"u_zeta": 1e-3}), ("without_base_rate", {"u_eta": 0, "u_zeta": 0})):
        errs = []
        for H in Hs:
            v = pr.parameters({"H": H, **TORQUES, **base})
            errs.append(pr.image_error(pr.simulate(v, t, "rigorous"), pr.simulate(v, t, "full")))
        inv = [1 / h for h in Hs]
        # the fit over the points whose error stands above the integrators' (1e-10)
        keep = [i for i, e in enumerate(errs) if e > 1e-10]
        out[f"rigorous_vs_full_{key}"] = {"H": Hs, "error": errs, "order_in_1_over_H":
                                          _slope([inv[i] for i in keep], [errs[i] for i in keep]),
                                          "scene": f"l_x = 1e-3, l_y = 5e-4 N m, {base}, 5 s"}
        print(f"rigorous vs full {key}: errors {['%.2e' % e for e in errs]}", flush=True)
    print(f"small vs image: slope {out['small_vs_image']['slope']:.3f}", flush=True)
    return out


def maps() -> dict:
    from gyro.analyses.level_map import parse_axis

    model = load(pr.MODEL)
    names = model.param_names
    out = {}
    for key, (xa, ya, sets) in MAPS.items():
        g = level_map(model, "elementary", "rigorous", parse_axis("--x", xa, names), parse_axis("--y", ya, names),
                      sets, MAP_TOL, "motion", {"horizon": MAP_T})
        g.plot(RESULTS / f"precession_map_{key}.png")
        out[key] = g.to_dict()
        print(f"map {key}: {int(g.within().sum())} of {g.values.size} within {MAP_TOL}", flush=True)
    return out


def speed() -> dict:
    t = np.linspace(0.0, HORIZON, 401)
    out = {}
    for scene, sets in SCENES.items():
        v = pr.parameters(sets)
        ref = pr.simulate(v, t, "full", rtol_scale=0.01)
        rows = {}
        for lv in pr.LEVELS:
            pr.simulate(v, t, lv)  # the integrator built
            cpu = []
            for _ in range(3):
                m = pr.simulate(v, t, lv)
                cpu.append(m.seconds)
            rows[lv] = {"error": pr.image_error(m, ref), "cpu_per_hour": float(np.median(cpu)) * 3600 / HORIZON}
        out[scene] = rows
        print(scene, {k: f"{r['error']:.1e} / {r['cpu_per_hour']:.2g} s" for k, r in rows.items()}, flush=True)
    return out


def chart(data: dict, path: Path) -> None:
    from gyro.results._io import _pyplot, save_figure

    plt = _pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.6), sharey=True, layout="constrained")
    marks = dict(zip(pr.LEVELS, "osD^v"))
    for ax, (scene, rows) in zip(axes, data.items()):
        for lv, r in rows.items():
            e = max(r["error"], 1e-16)
            ax.loglog(r["cpu_per_hour"], e, marks[lv], ms=8, label=lv)
            ax.annotate(lv, (r["cpu_per_hour"], e), textcoords="offset points", xytext=(6, 4), fontsize=8)
        ax.axhline(1e-2, color="0.6", lw=0.8, ls="--")
        ax.set_title(scene, fontsize=9)
        ax.set_xlabel("CPU time per simulated hour [s]")
    axes[0].set_ylabel("max image-point error / max displacement, against full")
    axes[0].legend(fontsize=8, loc="lower left")
    fig.suptitle(f"gimbal_precession: the five levels (horizon {HORIZON:g} s, scaled to one hour)", fontsize=10)
    save_figure(fig, path)
    plt.close(fig)


def main() -> int:
    import sys

    RESULTS.mkdir(exist_ok=True)
    if sys.argv[1:] in (["--maps"], ["--costs"]):  # the costs (and the maps) alone, into the committed results
        data = json.loads((RESULTS / "precession.json").read_text())
        data["costs"] = costs()
        if sys.argv[1:] == ["--maps"]:
            data["maps"] = maps()
        (RESULTS / "precession.json").write_text(json.dumps(data, indent=1, allow_nan=False) + "\n")
        return 0
    data = {"machine": {"cores": 2, "processor": platform.processor(), "python": platform.python_version()},
            "costs": costs(), "orders": orders(), "speed": speed(), "maps": maps()}
    chart(data["speed"], RESULTS / "precession_speed.png")
    (RESULTS / "precession.json").write_text(json.dumps(data, indent=1, allow_nan=False) + "\n")
    print("wrote bench/results/precession.json, precession_speed.png, precession_map_*.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
