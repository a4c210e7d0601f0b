"""`python -m bench.forced_curve`: the response curve (amplitude against spin) of one
bearing-imperfection harmonic through a resonance, without and with bearing damping, as a
figure and as data: f3 at k = 1 through the radial bearing mode omega_p = 780 rad/s (x3),
and f1 at k = 1 over the same spins (gamma2, the rotor's angular response).
Writes bench/results/forced_curve.png and forced_curve.json."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gyro import load
from gyro.analyses.forced import response_curve
from gyro.results._io import _pyplot, save_figure

RESULTS = Path(__file__).resolve().parent / "results"
POINTS = 2001
DAMPING = (0.0, 2.0, 10.0)  # cp, N s/m


def main() -> None:
    model = load("torsion_gyrocompass")
    v = model.defaults
    wp = (v["Kp"] / v["m"]) ** 0.5
    lo, hi = 0.6 * wp * v["C"], 1.4 * wp * v["C"]
    plt = _pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True, layout="constrained")
    data = {"model": model.name, "H_range": [lo, hi], "points": POINTS, "curves": []}
    for (s, coord), ax in zip(((3, "x3"), (1, "gamma2")), axes):
        for cp in DAMPING:
            r = response_curve(model, {"cp": cp}, (s, 1, 1.0, 0.0), lo, hi, POINTS)
            i = r.coordinates.index(coord)
            amp = np.where(r.resonance, np.nan, r.amplitudes[:, i])
            ax.semilogy(r.omega, amp, lw=1.0, label=f"cp = {cp:g} N s/m")
            data["curves"].append({"s": s, "k": 1, "a": 1.0, "coordinate": coord, "cp": cp,
                                   "spin_rate": r.omega.tolist(),
                                   "amplitude": [float(x) if np.isfinite(x) else None for x in amp],
                                   "resonance": r.omega[r.resonance].tolist(),
                                   "peak": float(np.nanmax(amp)),
                                   "peak_at": float(r.omega[np.nanargmax(amp)])})
        ax.axvline(wp, color="0.5", ls=":", lw=0.8)
        ax.set_ylabel(f"|{coord}| per newton of f{s} [{r.units[i]}/N]")
        ax.set_title(f"f{s} = sin(omega_c t): response of {coord} against spin", fontsize=9)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=8)
    axes[1].set_xlabel("spin rate omega_c [rad/s] (dotted: omega_p = 780 rad/s)")
    fig.suptitle("Torsion gyrocompass: response curves through the radial bearing resonance", fontsize=10)
    RESULTS.mkdir(exist_ok=True)
    save_figure(fig, RESULTS / "forced_curve.png")
    (RESULTS / "forced_curve.json").write_text(json.dumps(data) + "\n")
    for c in data["curves"]:
        print(f"f{c['s']} {c['coordinate']} cp={c['cp']:g}: peak {c['peak']:.4g} at {c['peak_at']:.6g} rad/s")


if __name__ == "__main__":
    main()
