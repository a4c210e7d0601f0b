"""`python -m bench.forced_levels`: the forced question's levels over a spread, measured.

The error map of the level `linear` against `nonlinear` (gyro/questions/forced.py) for one
imperfection harmonic, f1 with k = 1, over the spin H from 0.3x to 3x the example's and the
amplitude a from 10 N to 3000 N (log grids): per point the measured error (the largest over
the ten coordinates of |X_lin - X_nl| over the coordinate's unit group's largest linear
amplitude) and the bound `linear` gives (twice harmonic balance's largest first Newton step
in each unit group), the smallest bound/error over the ten coordinates, and
where a level fails (a resonance of k omega_c with a natural frequency; harmonic balance
not converging). Writes bench/results/forced_levels.json and forced_levels.png (error and
bound/error over the grid); docs/hierarchy.md cites it.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from gyro import load
from gyro.analyses.scene import level_error

RESULTS = Path(__file__).resolve().parent / "results"
HARMONIC = (1, 1, 0.0)  # s, k, phi


def grid(quick: bool = False):
    n_h, n_a = (5, 4) if quick else (13, 11)
    return np.geomspace(0.3, 3.0, n_h), np.geomspace(10.0, 3000.0, n_a)


def measure(model, H_scale, amps):
    v = model.defaults
    err = np.full((len(amps), len(H_scale)), np.nan)
    bound = np.full_like(err, np.nan)
    worst = np.full_like(err, np.nan)
    s, k, phi = HARMONIC
    for j, h in enumerate(H_scale):
        P = model.vector({"H": v["H"] * h})
        for i, a in enumerate(amps):
            e, b = level_error(model, "forced", "linear", "nonlinear", P, {"harmonic": (s, k, a, phi)})
            if np.all(np.isfinite(e)):
                err[i, j], bound[i, j] = float(np.max(e)), float(np.max(b))
                # per coordinate: the smallest bound / error of the ten (where the error is not 0)
                with np.errstate(divide="ignore"):
                    worst[i, j] = float(np.min(np.where(e > 0, b / e, np.inf)))
    return err, bound, worst


def plot(H_scale, amps, err, bound, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(12, 4.6), constrained_layout=True)
    X, Y = np.meshgrid(H_scale, amps)
    c0 = ax[0].pcolormesh(X, Y, np.log10(err), shading="nearest", cmap="viridis")
    cs = ax[0].contour(X, Y, np.log10(err), levels=[-4, -3, -2], colors="w", linewidths=0.8)
    ax[0].clabel(cs, fmt=lambda x: f"1e{x:.0f}")
    fig.colorbar(c0, ax=ax[0], label="log10 measured error of `linear`")
    c1 = ax[1].pcolormesh(X, Y, bound / err, shading="nearest", cmap="magma", vmin=1.0)
    fig.colorbar(c1, ax=ax[1], label="bound / measured error (>= 1 holds)")
    for a_ in ax:
        a_.set_xscale("log")
        a_.set_yscale("log")
        a_.set_xlabel("spin H / the example's")
        a_.set_ylabel("amplitude a of f1, k = 1 [N]")
    ax[0].set_title("forced, level linear against nonlinear (grey: a level failed)")
    ax[1].set_title("its bound over its measured error")
    for a_ in ax:
        a_.set_facecolor("0.8")
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(quick: bool = False) -> None:
    model = load("torsion_gyrocompass")
    H_scale, amps = grid(quick)
    t0 = time.perf_counter()
    err, bound, worst = measure(model, H_scale, amps)
    seconds = time.perf_counter() - t0
    ok = np.isfinite(err)
    ratio = bound[ok] / err[ok]
    out = {"model": model.name, "harmonic": {"s": HARMONIC[0], "k": HARMONIC[1], "phase": HARMONIC[2]},
           "H_scale": H_scale.tolist(), "amplitudes": amps.tolist(),
           "error": [[None if not np.isfinite(x) else float(x) for x in row] for row in err],
           "bound": [[None if not np.isfinite(x) else float(x) for x in row] for row in bound],
           "points": int(err.size), "failed": int((~ok).sum()),
           "min_bound_over_error": float(ratio.min()), "max_bound_over_error": float(ratio.max()),
           "median_bound_over_error": float(np.median(ratio)),
           "min_bound_over_error_per_coordinate": float(np.nanmin(worst)), "seconds": seconds,
           "command": "python -m bench.forced_levels"}
    RESULTS.mkdir(exist_ok=True)
    if not quick:
        (RESULTS / "forced_levels.json").write_text(json.dumps(out, indent=1) + "\n")
        plot(H_scale, amps, err, bound, RESULTS / "forced_levels.png")
    print(f"{err.size} points in {seconds:.0f} s, {out['failed']} failed (resonances or no convergence); "
          f"bound/error {out['min_bound_over_error']:.3g} .. {out['max_bound_over_error']:.3g} "
          f"(median {out['median_bound_over_error']:.3g}); per coordinate at least "
          f"{out['min_bound_over_error_per_coordinate']:.3g}")


if __name__ == "__main__":
    import sys

    main("--quick" in sys.argv)
