"""`gyro level-map MODEL --level LEVEL --against LEVEL --x NAME=LO:HI:N --y NAME=LO:HI:N
[--t-end T] [--tol TOL] [--set NAME=VALUE]... --out FILE.png [--json] [--question Q] [--quiet]`:
the error of one level of the model's hierarchy (docs/hierarchy.md) against another over a
grid of two parameters, drawn with the contour at --tol (where the level stops being
enough). The question is the first both levels answer, or --question; --t-end is the
motion question's horizon. JSON keys: x, y (the grid values), values (N_y rows of N_x
largest relative errors, null where a level could not answer), level, against, tol; and
model, x_name, y_name, measure, changed, failed (grid point "i,j" -> reason), seconds.
"""
from __future__ import annotations

import json
import sys

from gyro.cli.common import (add_json, add_model, add_out, add_quiet, add_set, check_png_out, has_levels, parse_sets,
                             refuse_over_budget)
from gyro.errors import ParameterError, finite_number

ORDER = 36


def register(sub) -> None:
    s = sub.add_parser("level-map", help="the error of one level of a model's hierarchy against another "
                       "over two parameters")
    add_model(s, help="the model: a hierarchy of levels (Model.levels)", declares=has_levels)
    s.add_argument("--level", required=True, metavar="LEVEL", help="the level whose error is mapped")
    s.add_argument("--against", required=True, metavar="LEVEL", help="the more exact level")
    s.add_argument("--x", required=True, metavar="NAME=LO:HI:N", help="x axis: a parameter")
    s.add_argument("--y", required=True, metavar="NAME=LO:HI:N", help="y axis: a parameter")
    s.add_argument("--t-end", default="10", metavar="T", help="the motion question's horizon in s (default 10)")
    s.add_argument("--tol", default="1e-2", metavar="TOL", help="relative tolerance drawn as a contour (default 1e-2)")
    s.add_argument("--question", default=None, metavar="Q", help="the question (default: the first both levels answer)")
    add_set(s, "the other parameters (the model's names, SI units)")
    add_out(s, help="the map as PNG")
    add_json(s)
    add_quiet(s)
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses.level_map import level_map, parse_axis, question_of
    from gyro.models import load

    model = load(args.model)
    question_of(model, args.level, args.against, args.question)
    names = model.param_names + list(model.meta.get("aliases", {}))
    xaxis, yaxis = ((model.canonical(a[0]),) + a[1:] for a in (parse_axis(f, t, names) for f, t in
                                                              (("--x", args.x), ("--y", args.y))))
    t_end = finite_number("--t-end", args.t_end)
    if not t_end > 0:
        raise ParameterError(f"--t-end must be positive, got {args.t_end!r}")
    tol = finite_number("--tol", args.tol)
    if not 0 < tol < 1:
        raise ParameterError(f"--tol must lie in (0, 1), got {args.tol!r}")
    refuse_over_budget("--x, --y", xaxis[3] * yaxis[3], _cost(model, args.level, args.against), what="grid points",
                       cluster=False)
    out = check_png_out(args.out)
    sets = {model.canonical(k): finite_number(f"parameter {k}", v) for k, v in parse_sets(args.set).items()}
    model.parameters(sets)  # every name and value checked before anything runs
    grid = level_map(model, args.level, args.against, xaxis, yaxis, sets, tol, args.question,
                     {"horizon": t_end}, progress=not args.quiet and sys.stderr.isatty())
    grid.plot(out)
    print(json.dumps(grid.to_dict(), allow_nan=False) if args.json else grid.summary(out))
    return 0


def _cost(model, level: str, against: str) -> float:
    """Seconds a grid point costs: the two levels' measured costs per set (the hierarchy's
    declared ones); 0 where a level has none measured (nothing to refuse on)."""
    import math

    from gyro.levels import get

    each = sum(get(model, name).cost for name in (level, against))
    return each if math.isfinite(each) else 0.0
