"""`gyro level-map MODEL --level LEVEL --against LEVEL --x NAME=LO:HI:N --y NAME=LO:HI:N
[--t-end T] [--tol TOL] [--set NAME=VALUE]... --out FILE.png [--json] [--quiet]`: the error
of one level of the model's hierarchy against a more exact one over a grid of two
parameters, drawn with the contour at --tol (where the cheaper level stops being enough).
JSON keys: x, y (the grid values), values (N_y rows of N_x relative errors, null where a
level could not be computed), level, against, tol; and model, x_name, y_name, measure,
changed, failed (grid point "i,j" -> reason), seconds.
"""
from __future__ import annotations

import json
import sys

from gyro.cli.common import add_json, add_out, add_quiet, add_set, check_png_out, parse_sets
from gyro.errors import ParameterError, finite_number

ORDER = 36


def register(sub) -> None:
    s = sub.add_parser("level-map", help="the error of one level of a hierarchy against a more exact one "
                       "over two parameters")
    s.add_argument("model", metavar="MODEL", help="a model with levels (gimbal_precession)")
    s.add_argument("--level", required=True, metavar="LEVEL", help="the cheaper level")
    s.add_argument("--against", required=True, metavar="LEVEL", help="the more exact level")
    s.add_argument("--x", required=True, metavar="NAME=LO:HI:N", help="x axis: a parameter")
    s.add_argument("--y", required=True, metavar="NAME=LO:HI:N", help="y axis: a parameter")
    s.add_argument("--t-end", default="10", metavar="T", help="horizon of the motion in s (default 10)")
    s.add_argument("--tol", default="1e-2", metavar="TOL", help="relative tolerance drawn as a contour (default 1e-2)")
    add_set(s, "the other parameters (SI units, radians)")
    add_out(s, help="the map as PNG")
    add_json(s)
    add_quiet(s)
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses.level_map import check_levels, hierarchy, level_map, parse_axis

    h = hierarchy(args.model)
    check_levels(h, args.level, args.against)
    names = list(h.defaults())
    xaxis, yaxis = parse_axis("--x", args.x, names), parse_axis("--y", args.y, names)
    t_end = finite_number("--t-end", args.t_end)
    tol = finite_number("--tol", args.tol)
    if not 0 < tol < 1:
        raise ParameterError(f"--tol must lie in (0, 1), got {args.tol!r}")
    out = check_png_out(args.out)
    sets = parse_sets(args.set)
    for k, v in sets.items():
        sets[k] = finite_number(f"parameter {k}", v)
    grid = level_map(h, args.level, args.against, xaxis, yaxis, sets, t_end, tol,
                     progress=not args.quiet and sys.stderr.isatty())
    grid.plot(out)
    print(json.dumps(grid.to_dict(), allow_nan=False) if args.json else grid.summary(out))
    return 0
