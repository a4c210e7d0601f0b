"""`gyro tolerance MODEL --spread NAME=normal:SIGMA|uniform:HALFWIDTH ... --samples N [--seed S]
[--set NAME=VALUE]... [--correlate A,B=RHO]... [--harmonics K,...] [--band REL]
[--scheduler local|ADDRESS] [--store DIR] [--json] [--out FILE.png] [--tornado FILE.png]`:
the distribution of every natural frequency over manufacturing spreads (docs/tolerance.md)."""
from __future__ import annotations

import json
import sys

from gyro.cli.common import (add_json, add_model, add_out, add_quiet, add_scheduler, add_set, check_png_out, has_operator,
                             method_cost, model_with_equilibrium, parse_sets, refuse_over_budget,
                             writable_folder)
from gyro.errors import ParameterError

ORDER = 37
MAX_SAMPLES = 10**9


def register(sub) -> None:
    t = sub.add_parser("tolerance", help="frequency distributions over parameter spreads: first order and sampled")
    add_model(t, help="the model: an operator about a relative equilibrium", declares=has_operator)
    add_set(t)
    t.add_argument("--spread", action="append", default=[], required=True, metavar="NAME=normal:SIGMA|uniform:HALFWIDTH",
                   help="a parameter's spread, relative to its value (Kp=normal:0.05 is 5 %%); repeat as needed")
    t.add_argument("--samples", type=int, required=True, metavar="N", help="parameter sets sampled")
    t.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the samples (default: 0)")
    t.add_argument("--correlate", action="append", default=[], metavar="A,B=RHO",
                   help="correlation of two spread parameters (a Gaussian copula); repeat as needed")
    t.add_argument("--harmonics", default=None, metavar="K,...",
                   help="probability that a frequency falls within --band of k omega_c, omega_c the spin rate the model declares (Model.spin; H/C for the torsion gyrocompass)")
    t.add_argument("--band", type=float, default=0.02, metavar="REL", help="half-width of the band, relative (default: 0.02)")
    add_scheduler(t)
    t.add_argument("--store", default=None, metavar="DIR",
                   help="keep the sampled frequencies as .npy files in DIR (written chunk by chunk)")
    add_json(t)
    add_out(t, required=False, help="histograms of the frequencies with the first-order normal, FILE.png")
    add_out(t, required=False, help="a tornado chart of the sensitivities", flag="--tornado")
    add_quiet(t)
    t.set_defaults(run=run)


def parse_pairs(items) -> dict:
    out = {}
    for item in items:
        pair, sep, rho = item.partition("=")
        a, sep2, b = pair.partition(",")
        try:
            r = float(rho)
        except ValueError:
            r = None
        if not sep or not sep2 or r is None:
            raise ParameterError(f"--correlate {item!r}: expected A,B=RHO")
        key = (a.strip(), b.strip())
        if key in out or key[::-1] in out:  # as a repeated --spread: never the last one silently
            raise ParameterError(f"--correlate {key[0]},{key[1]}: the pair is given twice")
        out[key] = r
    return out


def parse_harmonics(text) -> list[int]:
    if text is None:
        return []
    try:
        ks = [int(k) for k in text.split(",")]
    except ValueError:
        raise ParameterError(f"--harmonics {text!r}: expected positive integers K,...") from None
    if not ks or any(k < 1 for k in ks):
        raise ParameterError(f"--harmonics {text!r}: expected positive integers K,...")
    return ks


def run(args) -> int:
    import math
    from pathlib import Path

    from gyro.analyses.tolerance import parse_spread, tolerance

    model = model_with_equilibrium(args.model)
    values = model.parameters(parse_sets(args.set))
    spreads = [parse_spread(s) for s in args.spread]
    if not 2 <= args.samples <= MAX_SAMPLES:  # one sample has no spread: no std to report
        raise ParameterError(f"--samples: need 2..{MAX_SAMPLES} (one sample has no standard deviation), "
                             f"got {args.samples}")
    refuse_over_budget("--samples", args.samples, method_cost("default"), args.scheduler, "samples")
    if not (math.isfinite(args.band) and 0 < args.band < 1):
        raise ParameterError(f"--band: need 0 < REL < 1, got {args.band}")
    if not 0 <= args.seed < 2**63:
        raise ParameterError(f"--seed: need 0 <= S < 2^63, got {args.seed}")
    out = check_png_out(args.out) if args.out else None
    tornado = check_png_out(args.tornado, "--tornado") if args.tornado else None
    store = Path(args.store) if args.store else None
    if store is not None and store.exists() and not store.is_dir():
        raise ParameterError(f"--store {args.store!r}: not a folder")
    if store is not None:  # tried before sampling: the folder, or the nearest one it will be made in
        where = store.resolve()
        while not where.is_dir() and where != where.parent:
            where = where.parent
        writable_folder("--store", args.store, where)
    study = tolerance(model, values, spreads, args.samples, args.seed, parse_pairs(args.correlate),
                      args.scheduler, parse_harmonics(args.harmonics), args.band, store,
                      progress=not args.quiet and sys.stderr.isatty())
    if out is not None:
        study.plot(out)
    if tornado is not None:
        study.sensitivities.plot(tornado, title=f"{model.meta['title']}: sensitivities at the nominal set")
    if args.json:
        print(json.dumps(study.to_dict(), allow_nan=False))
    else:
        print(study.table())
    return 1 if study.failed == study.samples else 0
