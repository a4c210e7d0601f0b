"""`python -m bench.estimates [--model NAME] [--seed S] [--sets N] [--method M]`: every
frequency of N random sets, each parameter drawn 0.05x..20x of the model's own values
(log-uniform; latitude, gravity, the Earth rate, the sensor gain lambda and the bearing
damping kept), by a double-precision method, against the 40-digit `reference`: the largest
error over its estimate and how many estimates are beaten, on the sets whose reference is
stable (a frequency of a growing pair is zero and has no relative error). An adversarial
check of the estimates, not a speed bench: docs/methods.md ("The operator's own
rounding") quotes it. Writes bench/results/estimates_<model>_<method>.json."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gyro import ladder
from gyro.models import load

RESULTS = Path(__file__).resolve().parent / "results"
KEPT = ("lam", "phi", "g", "u", "cp", "c0", "cgamma", "h")


def draw(model, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    P = np.tile(model.vector(), (n, 1))
    for j, name in enumerate(model.param_names):
        if name not in KEPT:
            P[:, j] *= np.exp(rng.uniform(np.log(0.05), np.log(20.0), n))
    return P


def check(model_name: str, seed: int, n: int, method: str) -> dict:
    model = load(model_name)
    P = draw(model, n, seed)
    s = ladder.spectrum(model, P, method)
    r = ladder.spectrum(model, P, "reference")
    stable = (np.max(np.abs(r.growth), axis=1) < 1e-30) & np.all(r.frequencies > 1e-30, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(s.frequencies - r.frequencies) / r.frequencies / s.error_estimate
    rr = ratio[stable]
    k, j = np.unravel_index(np.nanargmax(np.where(stable[:, None], ratio, 0.0)), ratio.shape)
    return {"model": model_name, "method": method, "seed": seed, "sets": n, "stable_sets": int(stable.sum()),
            "roots": int(rr.size), "beaten": int(np.sum(rr > 1)), "largest_error_over_estimate": float(np.nanmax(rr)),
            "worst_set": P[k].tolist(), "worst_root": int(j)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(prog="python -m bench.estimates", description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default="gyrohorizoncompass")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--sets", type=int, default=300)
    ap.add_argument("--method", default="default")
    a = ap.parse_args(argv)
    out = check(a.model, a.seed, a.sets, a.method)
    print(json.dumps({k: v for k, v in out.items() if k != "worst_set"}))
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"estimates_{a.model}_{a.method}.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
