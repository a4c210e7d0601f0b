"""`gyro campbell MODEL [--set NAME=VALUE]... --out FILE.png [--range LO HI] [--points N]`"""
from __future__ import annotations

import math
import sys

from gyro.cli.common import add_model, add_out, add_points, add_quiet, add_set, check_png_out, model_with_equilibrium, parse_sets
from gyro.errors import ParameterError

ORDER = 20
MAX_POINTS = 100_000  # spins: the default method takes about 40 us each


def register(sub) -> None:
    c = sub.add_parser("campbell", help="Campbell diagram: frequencies against spin, formulas overlaid")
    add_model(c)
    add_set(c)
    add_out(c)
    c.add_argument("--range", nargs=2, type=float, default=(0.1, 10.0), metavar=("LO", "HI"),
                   help="spin range as multiples of the set's H (default: 0.1 10)")
    add_points(c, 200, "spins in the sweep (default: 200)")
    add_quiet(c)
    c.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses.campbell import sweep

    model = model_with_equilibrium(args.model)
    if "H" not in model.param_names:
        raise ParameterError(f"campbell: {model.name} has no rotor momentum H to sweep")
    values = model.parameters(parse_sets(args.set))
    lo, hi = args.range
    if not (0 < lo < hi) or not math.isfinite(hi) or not math.isfinite(hi * values.get("H", 1.0)):
        raise ParameterError(f"--range: need finite 0 < LO < HI (H x HI finite), got {lo} {hi}")
    if not 2 <= args.points <= MAX_POINTS:
        raise ParameterError(f"--points: need 2..{MAX_POINTS}, got {args.points}")
    out = check_png_out(args.out)
    diagram = sweep(model, values, lo, hi, args.points, progress=not args.quiet and sys.stderr.isatty())
    diagram.plot(out)
    print(diagram.summary(out))
    return 0
