"""`gyro map gyrohorizoncompass --x NAME=LO:HI:N --y NAME=LO:HI:N --out FILE.png [--set
NAME=VALUE]... [--orbit] [--json]`: over a grid of two axes (parameters, or theta = (C - A)/I
and chi = (C - B)/I, which move A and B), 2 where (3.6) holds ((4.3) with --orbit), 1 where
the linearisation is spectrally stable outside it (gyroscopic stabilisation), 0 where it is
unstable, -1 where rounding could change the verdict (a boundary; --json: `boundary`, N_y
rows of N_x booleans), -2 where a zero root is exact (marginal). lambda follows 1 + chi at
every point unless set. Every grid point must have a relative equilibrium: otherwise exit
2, naming the point.
"""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_out, add_set, check_png_out, parse_sets, refuse_over_budget
from gyro.errors import ParameterError

ORDER = 33
MODELS = ("gyrohorizoncompass",)
POINT_COST = 1.8e-4  # s a grid point (100 x 100 in 1.8 s, measured; 1000 x 1000 would be 3 min)


def register(sub) -> None:
    s = sub.add_parser("map", help="gyrohorizoncompass: the (3.6) region, the spectrally stable one, the unstable one")
    add_model(s, MODELS, help="the model")
    s.add_argument("--x", required=True, metavar="NAME=LO:HI:N", help="x axis: a parameter, theta or chi")
    s.add_argument("--y", required=True, metavar="NAME=LO:HI:N", help="y axis: a parameter, theta or chi")
    add_set(s, "the other parameters (A B C J L I nu zeta eta lam (or lambda), SI); default: the Earth set")
    s.add_argument("--orbit", action="store_true", help="zeta = nu, eta = 0 at every point; (4.3) as the condition")
    add_out(s, help="the map as PNG")
    add_json(s)
    s.set_defaults(run=run)


def run(args) -> int:
    if args.model not in MODELS:
        raise ParameterError(f"map: unknown model {args.model!r}; it covers {', '.join(MODELS)}")
    from gyro.systems.gyrohorizoncompass import cli_name, condition_map, parameters, parse_axis

    xaxis, yaxis = parse_axis("--x", args.x), parse_axis("--y", args.y)
    if args.orbit and {xaxis[0], yaxis[0]} & {"zeta", "eta"}:
        raise ParameterError("--orbit sets zeta = nu and eta = 0: neither can be an axis")
    sets = {cli_name(k): v for k, v in parse_sets(args.set).items()}  # lam or lambda: one parameter
    for axis in (xaxis, yaxis):
        if axis[0] in sets:
            raise ParameterError(f"parameter {axis[0]}: is an axis; do not --set it")
    refuse_over_budget("--x, --y", xaxis[3] * yaxis[3], POINT_COST, what="grid points", cluster=False)
    out = check_png_out(args.out)
    values = parameters(sets, orbit=args.orbit, need_equilibrium=False)  # each point is checked
    grid = condition_map(values, xaxis, yaxis, orbit=args.orbit, lambda_follows="lambda" not in sets)
    grid.plot(out)
    print(json.dumps(grid.to_dict(), allow_nan=False) if args.json else grid.summary(out))
    return 0
