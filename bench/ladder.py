"""Accuracy against speed of the ladder of methods (gyro.ladder), in one run, on one core.

`python -m bench.ladder` (run by `make bench`): on the paper example and on three spreads
(spin Omega 0.1x..10x, bearing stiffnesses K0, Kp, K_gamma together 0.1x..10x, latitude
0..89 deg) every method's frequencies are compared with the 40-digit reference, and each
method's time per parameter set is measured over a batch in the same run. Writes
bench/results/ladder.json and the charts ladder_accuracy_speed.png, campbell.png and
stability_map.png (shown in the README).
"""
from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"  # one core: set before NumPy loads its BLAS

import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from gyro import cbackend, ladder, load  # noqa: E402
from gyro.analyses import campbell  # noqa: E402
from gyro.analyses.stability_map import stability_grid  # noqa: E402
from gyro.results import nearest_error  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
MODEL = load("torsion_gyrocompass")
GOALS = {"default_sets_per_s": 1e5, "default_rel_error": 1e-10, "formulas_sets_per_s": 2e7,
         "reference_s_per_set": 1.0}
FLOORS = ("one 10x10 complex LU solve per root", "memory traffic of the batch")
BATCH = {"formulas": 1_000_000, "polyroots": 300, "companion": 20000, "default": 20000}
# the compiled rungs again on their NumPy paths (a machine without gcc): same algorithm
NUMPY_PATH = {"default, NumPy path": "default", "formulas, NumPy path": "formulas"}
SPREAD_POINTS = 9


def spreads() -> dict[str, np.ndarray]:
    p0 = MODEL.vector(MODEL.defaults)
    ix = {n: i for i, n in enumerate(MODEL.param_names)}
    s = np.geomspace(0.1, 10, SPREAD_POINTS)
    spin = np.tile(p0, (len(s), 1))
    spin[:, ix["H"]] *= s
    stiff = np.tile(p0, (len(s), 1))
    for k in ("K0", "Kp", "Kgamma"):
        stiff[:, ix[k]] *= s
    lat = np.tile(p0, (SPREAD_POINTS, 1))
    lat[:, ix["phi"]] = np.linspace(0, 89, SPREAD_POINTS)
    return {"paper example": p0[None], "spin 0.1x..10x": spin, "bearing stiffness 0.1x..10x": stiff,
            "latitude 0..89 deg": lat}


def rel_errors(s: ladder.Spectrum, r: ladder.Spectrum) -> np.ndarray:
    lam = s.growth + 1j * s.frequencies
    lr = r.growth + 1j * r.frequencies
    return np.abs(lam - lr) / np.abs(lr)


def time_per_set(method: str, P: np.ndarray) -> float:
    if method in NUMPY_PATH:
        with cbackend.disabled():
            return time_per_set(NUMPY_PATH[method], P)
    n = BATCH[method]
    big = np.tile(P, (int(np.ceil(n / len(P))), 1))[:n]
    ladder.spectrum(MODEL, big[:4], method)  # warm: compile, imports
    best = np.inf
    for _ in range(2 if method != "formulas" else 3):
        t0 = time.perf_counter()
        ladder.spectrum(MODEL, big, method)
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def floor_times(P: np.ndarray, sets: int = 20000, repeats: int = 3) -> dict[str, float]:
    """The limits the refinement and a batch cannot beat, timed in this run (medians): one
    10x10 complex LU solve per root (LAPACK through NumPy, ten per set), and the memory
    traffic of a set (M, D, K read, frequencies and estimates written) at the bandwidth of
    a 32 MB copy (bench/speed.py)."""
    from bench.speed import floors
    from gyro.equilibrium import equilibria, operators

    big = np.tile(P, (int(np.ceil(sets / len(P))), 1))[:sets]
    qe, _ = equilibria(MODEL, big)
    M, D, K = operators(MODEL, big, qe)
    w = np.sort(ladder.spectrum(MODEL, big, "default").frequencies, axis=1)
    fl = floors(M, D, K, w)
    lu, copy = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fl["lu_solve_per_root"]()
        lu.append((time.perf_counter() - t0) / sets)
        t0 = time.perf_counter()
        fl["copy_32MB"]()
        copy.append(time.perf_counter() - t0)
    bandwidth = fl["_copy_bytes"] / float(np.median(copy))
    return dict(zip(FLOORS, (float(np.median(lu)), fl["_bytes_per_set"] / bandwidth)))


def main() -> int:
    RESULTS.mkdir(parents=True, exist_ok=True)
    out = {"goals": GOALS, "spreads": {}, "machine": {
        "python": platform.python_version(), "processor": platform.machine(), "threads": 1}}
    all_sets = np.concatenate(list(spreads().values()))
    print("timing each method over a batch (one core) ...", flush=True)
    timing = {m: time_per_set(m, all_sets) for m in [*BATCH, *NUMPY_PATH]}
    for m, t in timing.items():
        print(f"  {m:21s} {t * 1e6:10.3f} us per set ({1 / t:,.0f} sets/s)", flush=True)
    out["floors_s_per_set"] = floor_times(all_sets)
    for k, t in out["floors_s_per_set"].items():
        print(f"  floor: {k:40s} {t * 1e6:10.3f} us per set", flush=True)
    ref_times = []
    for name, P in spreads().items():
        print(f"{name}: reference on {len(P)} sets ...", flush=True)
        t0 = time.perf_counter()
        r = ladder.spectrum(MODEL, P, "reference")
        ref_times.append((time.perf_counter() - t0) / len(P))
        entry = {"sets": len(P), "methods": {}}
        for m in [*ladder.METHODS, *NUMPY_PATH]:
            if m == "reference":
                s = r
            elif m in NUMPY_PATH:
                with cbackend.disabled():
                    s = ladder.spectrum(MODEL, P, NUMPY_PATH[m])
            else:
                s = ladder.spectrum(MODEL, P, m)
            if s.method == "formulas":  # approximate modes: distance to the nearest exact root
                err = nearest_error(s.frequencies, r.frequencies)
            elif m == "reference":
                err = s.error_estimate
            else:
                err = rel_errors(s, r)
            bound_held = bool(np.all(err <= s.error_estimate)) if m != "reference" else True
            entry["methods"][m] = {
                "max_rel_error_per_frequency": [float(x) for x in np.nanmax(err, axis=0)],
                "max_rel_error": float(np.nanmax(err)),
                "estimate_bounds_error": bound_held,
                "routes": (sorted(set(s.route)) if s.route is not None else None)}
            print(f"  {m:21s} max error {np.nanmax(err):9.2e}  estimate bounds it: {bound_held}", flush=True)
        out["spreads"][name] = entry
    timing["reference"] = float(np.mean(ref_times))
    out["seconds_per_set"] = timing
    out["sets_per_s"] = {m: 1 / t for m, t in timing.items()}
    worst_default = max(e["methods"]["default"]["max_rel_error"] for e in out["spreads"].values())
    out["standing"] = {
        "default_sets_per_s": 1 / timing["default"], "default_max_rel_error": worst_default,
        "formulas_sets_per_s": 1 / timing["formulas"], "reference_s_per_set": timing["reference"]}
    chart(out)
    print("Campbell diagram and stability map ...", flush=True)
    data = campbell.sweep(MODEL, MODEL.defaults, 0.1, 10.0, 240)
    data.plot(RESULTS / "campbell.png")
    # the rotor centre's height against the angular momentum: the boundary m l2 + M l1 = 0
    # (l_c = 0) from the derivation, and how H slows the growth it can reach (H^-1/2)
    d = MODEL.defaults
    grid = stability_grid(MODEL, d, "l2", (-0.5, 0.3), "H", (0.01, 10.0), 70, ylog=True)
    lc0 = -d["M"] * d["l1"] / d["m"]
    grid.plot(RESULTS / "stability_map.png",
              lines=[([lc0, lc0], [0.01, 10.0], "l_c = 0 (m l2 + M l1 = 0)")])
    out["campbell_shaded_fraction"] = data.shaded_fraction
    path = RESULTS / "ladder.json"
    path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    st = out["standing"]
    print(f"default: {st['default_sets_per_s']:,.0f} sets/s (goal 100,000), worst error "
          f"{st['default_max_rel_error']:.1e} (goal 1e-10); formulas: {st['formulas_sets_per_s']:,.0f} "
          f"sets/s (goal 20,000,000); reference: {st['reference_s_per_set']:.2f} s/set (goal 1 s)")
    print(f"written {path.relative_to(ROOT)} and the charts in {RESULTS.relative_to(ROOT)}")
    return 0


def chart(out: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    style = {"formulas": ("tab:blue", "s"), "polyroots": ("tab:red", "v"),
             "companion": ("tab:orange", "^"), "default": ("tab:green", "o"),
             "reference": ("tab:purple", "D"), "default, NumPy path": ("tab:green", "o"),
             "formulas, NumPy path": ("tab:blue", "s")}
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5), sharex=True, sharey=True, layout="constrained")
    floor = 1e-17  # an error of exactly zero is drawn here
    # the panels and the floors in the bench's own order, also when drawn again from
    # ladder.json (written with sorted keys)
    names = [k for k in spreads() if k in out["spreads"]] + [k for k in out["spreads"] if k not in spreads()]
    floors_ = {k: out["floors_s_per_set"][k] for k in FLOORS if k in out["floors_s_per_set"]}
    for ax, name in zip(axes.ravel(), names):
        entry = out["spreads"][name]
        for m, (color, marker) in style.items():
            t = out["seconds_per_set"][m]
            raw = np.nan_to_num(np.asarray(entry["methods"][m]["max_rel_error_per_frequency"], float), nan=np.inf)
            errs = np.clip(raw, floor, 10.0)
            clipped = (raw < floor) | (raw > 10.0)  # drawn at the edge, marked: the value lies beyond
            jitter = t * np.exp(np.linspace(-0.12, 0.12, len(errs)))
            hollow = m in NUMPY_PATH  # the same algorithm without the generated C
            ax.scatter(jitter[~clipped], errs[~clipped], marker=marker, s=22, alpha=0.8,
                       label=m if ax is axes[0, 0] else None,
                       facecolors="none" if hollow else color, edgecolors=color)
            for side, sel in (("low", raw < floor), ("high", raw > 10.0)):
                if not sel.any():
                    continue
                ax.scatter(jitter[sel], errs[sel], marker="v" if side == "low" else "^", s=40, color=color,
                           alpha=0.9, facecolors="none" if hollow else color)
                r_ = raw[sel].min() if side == "low" else raw[sel].max()
                text = (f"down to {r_:.0e}" if side == "low" else
                        (f"up to {r_:.0e}" if np.isfinite(r_) else "roots lost"))
                ax.annotate(text, (jitter[sel][-1], errs[sel][-1]), fontsize=6, color=color,
                            xytext=(4, 4 if side == "low" else -9), textcoords="offset points")
            # left of its point where omega1 is drawn at an edge: its value's label is on the right
            ax.annotate("omega1", (jitter[0], errs[0]), fontsize=6, color=color,
                        xytext=(-4, 4) if clipped[0] else (3, 3), textcoords="offset points",
                        ha="right" if clipped[0] else "left")
        ax.axhline(1e-10, color="k", lw=0.7, ls="--")
        ax.axvline(1 / GOALS["default_sets_per_s"], color="tab:green", lw=0.7, ls=":")
        ax.axvline(1 / GOALS["formulas_sets_per_s"], color="tab:blue", lw=0.7, ls=":")
        ax.axvline(GOALS["reference_s_per_set"], color="tab:purple", lw=0.7, ls=":")
        for (k, t), ls in zip(floors_.items(), ("-.", (0, (1, 3)))):
            ax.axvline(t, color="0.35", lw=0.9, ls=ls, label=f"floor: {k}" if ax is axes[0, 0] else None)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(5e-18, 20)
        ax.set_title(f"{name} ({entry['sets']} sets)", fontsize=9)
        ax.grid(True, which="major", alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time per parameter set [s] (one core, batched)")
    for ax in axes[:, 0]:
        ax.set_ylabel("max relative error against the reference")
    fig.legend(fontsize=8, loc="outside lower center", ncol=5)  # wider rows leave the canvas
    fig.suptitle("Natural frequencies of the torsion gyrocompass: accuracy against speed\n(a point per "
                 "method and frequency; dashed: 1e-10, dotted: speed goals, grey: the floors;\nerrors below "
                 "1e-17 or above 10 drawn at the edge as a triangle pointing beyond, with their value)", fontsize=10)
    fig.savefig(RESULTS / "ladder_accuracy_speed.png", dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
