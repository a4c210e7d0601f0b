"""`gyro sweep MODEL --x NAME=LO:HI[:N] [--x-log] [--points N] [--method NAME]
[--set NAME=VALUE]... [--json] [--out FILE.png]`: natural frequencies against one parameter.
The axis as `gyro map` takes one; `--x NAME --x-range LO HI` is kept as another way to say
it."""
from __future__ import annotations

import json
import math
import sys

from gyro.cli.common import (add_json, add_model, add_out, add_points, add_quiet, add_scheduler, add_set, axis, has_operator,
                             axis_points, check_png_out, model_with_equilibrium, parse_sets)
from gyro.errors import ParameterError
from gyro.methods import names as method_names

ORDER = 35


def register(sub) -> None:
    s = sub.add_parser("sweep", help="natural frequencies against one parameter")
    add_model(s, help="the model: an operator about a relative equilibrium", declares=has_operator)
    add_set(s)
    s.add_argument("--x", required=True, metavar="NAME=LO:HI[:N]", help="the parameter swept and its range "
                   "(or NAME with --x-range)")
    s.add_argument("--x-range", nargs=2, type=float, default=None, metavar=("LO", "HI"),
                   help="the range of --x NAME (the other form of the axis)")
    s.add_argument("--x-log", action="store_true", help="log-spaced (needs 0 < LO)")
    add_points(s, None, "values of the parameter (default: 50, or the axis's N)")
    s.add_argument("--method", default="default", choices=method_names(), help="rung of the ladder (default: %(default)s)")
    add_json(s)
    add_out(s, required=False, help="also plot the frequencies into FILE.png")
    add_quiet(s)
    add_scheduler(s)
    s.set_defaults(run=run)


def run(args) -> int:
    import numpy as np

    from gyro.analyses.sweep import sweep

    model = model_with_equilibrium(args.model)
    values = model.parameters(parse_sets(args.set))
    args.x, args.x_range, n = axis(args, "x")
    args.points = axis_points(args, 50, n)
    args.x = model.param_name(args.x, "--x")  # the declared name (another name taken for it too)
    lo, hi = args.x_range
    if not lo < hi or not (math.isfinite(lo) and math.isfinite(hi)):
        raise ParameterError(f"--x-range: need finite LO < HI, got {lo} {hi}")
    if args.x_log and not lo > 0:
        raise ParameterError(f"--x-range: --x-log needs 0 < LO, got {lo}")
    for v in (lo, hi):
        model.parameters({args.x: v})  # validates the ends of the range
    if not 2 <= args.points <= 100_000:
        raise ParameterError(f"--points: need 2..100000, got {args.points}")
    if args.method == "formulas" and "mode_formulas" not in model.meta["functions"]:
        raise ParameterError(f"--method formulas: {model.name} has no approximate formulas")
    out = check_png_out(args.out) if args.out else None
    result = sweep(model, values, args.x, lo, hi, args.points, args.method, args.x_log,
                   progress=not args.quiet and sys.stderr.isatty(), scheduler=args.scheduler)
    if not np.any(np.all(np.isfinite(result.spectrum.frequencies), axis=1)):  # no table of nothing: one line
        from gyro.ladder import require_finite

        require_finite(model, result.spectrum, f"any {args.x} of the sweep")
    if out is not None:
        result.plot(out)
    if args.json:
        print(json.dumps(result.to_dict(), allow_nan=False))
    elif out is not None:
        print(result.summary(out))
    else:
        print(result.table())
    if not np.all(np.isfinite(result.spectrum.frequencies)):
        print("gyro: some values have no finite spectrum (failed above)", file=sys.stderr)
        return 1
    return 0
