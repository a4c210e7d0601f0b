"""Where the formulas' error estimates hold: a wide sweep against the exact spectrum.

`python -m bench.formula_sweep` (run by `make bench` with the ladder): 4000 random sets of
the torsion gyrocompass, every mass, length, inertia, stiffness and the spin each
0.2x..5x the example's independently (log-uniform), latitude 0..85 deg. Each formula's
frequency is compared with the nearest root of the exact spectrum (the default method),
and the sets where the error exceeds the formula's own estimate are counted per mode, with
the worst ratio. Writes bench/results/formula_sweep.json (docs/methods.md, "Error
estimates of the formulas").
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from gyro import ladder, load
from gyro.kernels import function
from gyro.results import nearest_error

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
MODEL = load("torsion_gyrocompass")
VARIED = ("m", "M", "l", "l1", "l2", "A", "C", "I1", "I2", "I3", "K0", "Kp", "Kgamma", "H")
SETS, SEED, SPREAD = 4000, 5, 5.0


def sweep() -> np.ndarray:
    rng = np.random.default_rng(SEED)
    names = MODEL.param_names
    P = np.tile(MODEL.vector(MODEL.defaults), (SETS, 1))
    for v in VARIED:
        P[:, names.index(v)] *= np.exp(rng.uniform(-np.log(SPREAD), np.log(SPREAD), SETS))
    P[:, names.index("phi")] = rng.uniform(0.0, 85.0, SETS)
    return P


def main() -> int:
    P = sweep()
    f = ladder.spectrum(MODEL, P, "formulas")
    exact = ladder.spectrum(MODEL, P, "default")
    usable = (exact.route == "structured") & np.all(exact.growth == 0, axis=1)  # stable, answered
    err = nearest_error(f.frequencies, exact.frequencies)
    with np.errstate(all="ignore"):
        ratio = err / f.error_estimate
    # which mode's formula each returned frequency is: the nearest candidate value
    omega, _ = function(MODEL, "mode_formulas")(P)
    modes = [x["mode"] for x in MODEL.meta["mode_formulas"]]
    out = {"sets": SETS, "seed": SEED, "spread": SPREAD, "varied": list(VARIED), "usable_sets": int(usable.sum()),
           "per_mode": {m: {"exceeded": 0, "worst_ratio": 0.0, "unflagged_over_1_percent": 0} for m in modes}}
    for k, j in zip(*np.nonzero(usable[:, None] & np.isfinite(f.frequencies))):
        d = np.abs(omega[k] - f.frequencies[k, j])
        mode = out["per_mode"][modes[np.unravel_index(np.nanargmin(d), d.shape)[0]]]
        if ratio[k, j] > 1:
            mode["exceeded"] += 1
            mode["worst_ratio"] = max(mode["worst_ratio"], float(ratio[k, j]))
        if err[k, j] > 0.01 and f.error_estimate[k, j] <= 0.01:
            mode["unflagged_over_1_percent"] += 1
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / "formula_sweep.json"
    path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    print(f"formula estimates on {out['usable_sets']} stable sets, every parameter 0.2x..5x:")
    for m, r in out["per_mode"].items():
        print(f"  {m:11s} exceeded in {r['exceeded']:5d} sets (worst ratio {r['worst_ratio']:6.2f}); "
              f"off by > 1 % unflagged: {r['unflagged_over_1_percent']}")
    print(f"written {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
