"""`gyro stability-map MODEL --x NAME=LO:HI[:N] --y NAME=LO:HI[:N] [--x-log] [--y-log] --out
FILE.png [--json]` (each axis also as `--x NAME --x-range LO HI`, as before): the figure, and with --json the document of
gyro.results.Map.to_dict of a verdict map (keys x, y as `gyro map`, values: the class per point,
boundary: where rounding could change the verdict) instead of the summary line."""
from __future__ import annotations

import json
import math
import sys

from gyro.cli.common import (add_json, add_model, add_out, add_points, add_quiet, add_scheduler, add_set, axis, has_operator,
                             axis_points, check_png_out, model_with_equilibrium, parse_sets)
from gyro.errors import ParameterError

ORDER = 30
MAX_POINTS = 1000  # per axis: a million sets, about a minute


def register(sub) -> None:
    s = sub.add_parser("stability-map", help="stability of the equilibrium over two parameters")
    add_model(s, help="the model: an operator about a relative equilibrium", declares=has_operator)
    add_set(s)
    s.add_argument("--x", required=True, metavar="NAME=LO:HI[:N]",
                   help="the parameter along the x axis and its range, in its unit (or NAME with --x-range)")
    s.add_argument("--x-range", nargs=2, type=float, default=None, metavar=("LO", "HI"),
                   help="the range of --x NAME (the other form of the axis)")
    s.add_argument("--y", required=True, metavar="NAME=LO:HI[:N]",
                   help="the parameter along the y axis and its range (or NAME with --y-range)")
    s.add_argument("--y-range", nargs=2, type=float, default=None, metavar=("LO", "HI"),
                   help="the range of --y NAME")
    add_points(s, None, "grid points per axis (default: 60, or the axes' N)")
    s.add_argument("--x-log", action="store_true", help="log-spaced x axis (needs 0 < LO)")
    s.add_argument("--y-log", action="store_true", help="log-spaced y axis (needs 0 < LO)")
    add_out(s)
    add_json(s)
    add_quiet(s)
    add_scheduler(s)
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses.stability_map import stability_grid

    model = model_with_equilibrium(args.model)
    values = model.parameters(parse_sets(args.set))
    args.x, args.x_range, nx = axis(args, "x")
    args.y, args.y_range, ny = axis(args, "y")
    args.points = axis_points(args, 60, nx, ny)
    args.x, args.y = model.param_name(args.x, "--x"), model.param_name(args.y, "--y")  # declared names
    for flag, name, (lo, hi), log in (("--x", args.x, args.x_range, args.x_log),
                                      ("--y", args.y, args.y_range, args.y_log)):
        if not lo < hi or not (math.isfinite(lo) and math.isfinite(hi)):
            raise ParameterError(f"{flag}-range: need finite LO < HI, got {lo} {hi}")
        if log and not lo > 0:
            raise ParameterError(f"{flag}-range: {flag}-log needs 0 < LO, got {lo}")
        for v in (lo, hi):
            model.parameters({name: v})  # validates the ends of the range
    if not 2 <= args.points <= MAX_POINTS:
        raise ParameterError(f"--points: need 2..{MAX_POINTS} per axis, got {args.points}")
    out = check_png_out(args.out)
    grid = stability_grid(model, values, args.x, args.x_range, args.y, args.y_range,
                          args.points, progress=not args.quiet and sys.stderr.isatty(), xlog=args.x_log, ylog=args.y_log,
                          scheduler=args.scheduler)
    grid.plot(out)
    print(json.dumps(grid.to_dict(), allow_nan=False) if args.json else grid.summary(out))
    return 0
