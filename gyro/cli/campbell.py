"""`gyro campbell MODEL [--spin NAME] [--spin-range LO HI | --range LO HI] [--points N]
[--harmonics K1,K2,...] [--set NAME=VALUE]... [--json] [--out FILE.png]`"""
from __future__ import annotations

import json
import math
import sys

from gyro.cli.common import (add_json, add_model, add_out, add_points, add_quiet, add_scheduler, add_set, has_spin,
                             check_png_out, model_with_equilibrium, parse_sets)
from gyro.errors import ParameterError

ORDER = 20
MAX_POINTS = 100_000  # spins: the default method takes about 40 us each
MAX_HARMONIC = 1000


def register(sub) -> None:
    c = sub.add_parser("campbell", help="Campbell diagram: frequencies against spin, whirl, damping, "
                                        "harmonic lines and critical speeds")
    add_model(c, help="the model: an operator and a spin (Model.spin, or a parameter in rad/s)", declares=has_spin)
    add_set(c)
    add_out(c, required=False, help="the figure (--out or --json or both)")
    add_json(c)
    c.add_argument("--spin", metavar="NAME", help="the parameter that sets the spin (default: the one the model "
                                                  "declares; without a declaration, a parameter in rad/s)")
    c.add_argument("--spin-range", nargs=2, type=float, metavar=("LO", "HI"),
                   help="absolute range of the spin parameter, in its unit, LO >= 0 (linearly spaced)")
    c.add_argument("--range", nargs=2, type=float, default=None, metavar=("LO", "HI"),
                   help="spin range as multiples of the set's value (default: 0.1 10, log-spaced)")
    c.add_argument("--harmonics", metavar="K1,K2,...",
                   help="lines k x spin rate, and their crossings with the modes (critical speeds)")
    add_points(c, 200, "spins in the sweep (default: 200)")
    add_quiet(c)
    add_scheduler(c)
    c.set_defaults(run=run)


def harmonics(text: str | None) -> list[int]:
    if text is None:
        return []
    out = []
    for item in text.split(","):
        try:
            k = int(item.strip())
        except ValueError:
            raise ParameterError(f"--harmonics: {item.strip()!r} is not a positive integer") from None
        if not 1 <= k <= MAX_HARMONIC:
            raise ParameterError(f"--harmonics: need integers 1..{MAX_HARMONIC}, got {k}")
        out.append(k)
    return sorted(set(out))


def run(args) -> int:
    import numpy as np

    from gyro.analyses.campbell import campbell, spin_parameter, sweep

    model = model_with_equilibrium(args.model)
    values = model.parameters(parse_sets(args.set))
    spin = spin_parameter(model, args.spin)
    ks = harmonics(args.harmonics)
    if not 2 <= args.points <= MAX_POINTS:
        raise ParameterError(f"--points: need 2..{MAX_POINTS}, got {args.points}")
    if args.out is None and not args.json:
        raise ParameterError("campbell: give --out FILE.png or --json (or both)")
    if args.spin_range is not None and args.range is not None:
        raise ParameterError("--spin-range: give it or --range, not both")
    if args.spin_range is not None:
        lo, hi = args.spin_range
        if not (0 <= lo < hi) or not math.isfinite(hi):
            raise ParameterError(f"--spin-range: need finite 0 <= LO < HI, got {lo} {hi}")
        for v in (lo, hi):
            model.parameters({spin: v})  # the ends are valid values of the parameter
    else:
        lo, hi = args.range or (0.1, 10.0)
        if not (0 < lo < hi) or not math.isfinite(hi) or not math.isfinite(hi * values[spin]):
            raise ParameterError(f"--range: need finite 0 < LO < HI ({spin} x HI finite), got {lo} {hi}")
    out = check_png_out(args.out) if args.out else None
    progress = not args.quiet and sys.stderr.isatty()
    if args.spin_range is not None:
        diagram = campbell(model, values, spin, np.linspace(lo, hi, args.points), ks, progress,
                           scheduler=args.scheduler)
    else:
        diagram = sweep(model, values, lo, hi, args.points, progress, spin, ks, scheduler=args.scheduler)
    if out is not None:
        diagram.plot(out)
    if args.json:
        print(json.dumps(diagram.to_dict(), allow_nan=False))
    else:
        print(diagram.summary(out))
        if ks:
            print(diagram.table())
    return 0
