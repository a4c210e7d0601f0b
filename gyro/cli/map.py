"""`gyro map MODEL --x NAME=LO:HI:N --y NAME=LO:HI:N --out FILE.png [--set NAME=VALUE]...
[--orbit] [--json]`: for any model that declares sufficient conditions (Model.conditions),
over a grid of two axes (parameters, or an axis its system adds: theta = (C - A)/I and
chi = (C - B)/I, which move A and B), 2 where the condition holds, 1
where the linearisation is spectrally stable outside it, 0 where it is unstable, -1 where
rounding could change the verdict (a boundary; --json: `boundary`, N_y rows of N_x
booleans), -2 where a zero root is exact (marginal) (gyro/analyses/conditions.py). Every
grid point must have an equilibrium: otherwise exit 2, naming the point.
"""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_out, add_set, check_png_out, parse_sets, refuse_over_budget

ORDER = 33
POINT_COST = 1.8e-4  # s a grid point (100 x 100 in 1.8 s, measured; 1000 x 1000 would be 3 min)
NEEDS = "needs declared conditions (Model.conditions: named sets of margins > 0, docs/models.md)"


def register(sub) -> None:
    s = sub.add_parser("map", help=f"where the sufficient condition holds, the spectrally stable and unstable regions; "
                                   f"{NEEDS}",
                       description=f"The model's sufficient condition against the spectrum over a grid of two axes. "
                                   f"MODEL {NEEDS}.")
    add_model(s, help=f"the model ({NEEDS})", declares=lambda meta: bool(meta.get("conditions")))
    s.add_argument("--x", required=True, metavar="NAME=LO:HI:N", help="x axis: a parameter (or an axis the model's "
                   "system adds, as theta, chi)")
    s.add_argument("--y", required=True, metavar="NAME=LO:HI:N", help="y axis: as --x")
    add_set(s, "the other parameters (gyro params MODEL lists them); default: the model's defaults")
    s.add_argument("--orbit", action="store_true", help="a satellite on a circular orbit: zeta = nu, eta = 0 at "
                   "every point, (4.3) as the condition; an option of the model's system, only a model whose "
                   "system takes it")
    add_out(s, help="the map as PNG")
    add_json(s)
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses import conditions
    from gyro.models import load

    model = load(args.model)
    conditions.require(model)
    options = {"orbit": True} if args.orbit else {}
    conditions.check_options(model, options)
    xaxis, yaxis = conditions.parse_axis(model, "--x", args.x), conditions.parse_axis(model, "--y", args.y)
    sets = parse_sets(args.set)
    conditions.check_axes(model, xaxis, yaxis, options, sets)
    refuse_over_budget("--x, --y", xaxis[3] * yaxis[3], POINT_COST, what="grid points", cluster=False)
    out = check_png_out(args.out)
    grid = conditions.condition_map(model, sets, xaxis, yaxis, options)
    grid.plot(out)
    print(json.dumps(grid.to_dict(), allow_nan=False) if args.json else grid.summary(out))
    return 0
