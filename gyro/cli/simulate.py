"""`gyro simulate MODEL [--set NAME=VALUE]... --t-end T [--points N] [--perturb NAME=VALUE]...
[--method NAME] [--json] [--out FILE.png]`: a motion of any model (a generated one, a model
file, an emitted folder): the emitted nonlinear equations integrated from the reference (the
equilibrium of the set; steady and cyclic rates as the reference has them), each
`--perturb NAME=VALUE` an offset of a coordinate or, as NAME_d, of its rate (repeatable);
methods DOP853 (default), RK45, Radau, BDF, LSODA; JSON keys t, one list per coordinate
(absolute values, the model's units), method, and rates, coordinates, units, params,
perturb, equilibrium, model, seconds (gyro/analyses/motion.py).

A model that declares a motion of its own (Model.simulate: a module's simulate_command,
the flags it takes, a line of usage that `gyro params MODEL` prints) is answered by it (the
papers' closed form of a heavy gimbal gyroscope with its initial conditions as --set, an
energy-projected integrator, a hierarchy of precession levels with `--level` and
`--base-rate NAME=AMP:FREQ[:PHASE]`: u_NAME(t) = u_NAME + AMP sin(FREQ t + PHASE)). A flag
the model's motion does not take is refused in one line. Every input is checked before
anything is computed; bad input exits with 2 and one line naming it.
"""
from __future__ import annotations

import json
from pathlib import Path

from gyro.cli.common import add_json, add_model, add_out, add_set, check_png_out, parse_sets
from gyro.errors import ParameterError, finite_number

ORDER = 50
MAX_POINTS = 10**6  # time points: 8 MB a coordinate


def register(sub) -> None:
    s = sub.add_parser("simulate", help="a motion of a model from its reference (the emitted nonlinear equations "
                       "integrated), or by the motion the model declares of its own (Model.simulate)")
    add_model(s)
    add_set(s, "a parameter or, where the model's own motion takes them, an initial condition (gyro params "
            "MODEL lists both), SI units, radians")
    s.add_argument("--t-end", required=True, metavar="T", help="end time in s (> 0)")
    s.add_argument("--points", default="1001", metavar="N", help="number of time points from 0 to T (>= 2)")
    s.add_argument("--method", default=None, metavar="NAME",
                   help="the integrator: DOP853 (default), RK45, Radau, BDF, LSODA; a model's own motion names its "
                   "own (gyro params MODEL)")
    s.add_argument("--perturb", action="append", default=None, metavar="NAME=VALUE",
                   help="an offset at t = 0 from the reference: a coordinate NAME or its rate NAME_d, in the "
                   "model's units (repeatable); a model's own motion may take another form (gyro params MODEL)")
    s.add_argument("--level", default=None, metavar="LEVEL",
                   help="for a model whose own motion has levels (required there; gyro params MODEL lists them)")
    s.add_argument("--base-rate", action="append", default=None, metavar="NAME=AMP:FREQ[:PHASE]",
                   help="for a model whose own motion takes a time-varying base: u_NAME(t) = u_NAME + AMP sin(FREQ t "
                   "+ PHASE) (AMP in rad/s, FREQ >= 0 in rad/s, PHASE in rad, default 0); repeatable")
    add_json(s)
    add_out(s, required=False, help="also plot the coordinates against t into FILE.png")
    s.set_defaults(run=run)


def _times(args):
    import numpy as np

    t_end = finite_number("--t-end", args.t_end)
    if not t_end > 0:
        raise ParameterError(f"--t-end must be positive, got {args.t_end!r}")
    try:
        points = int(args.points)
    except ValueError:
        raise ParameterError(f"--points: not an integer: {args.points!r}") from None
    if not 2 <= points <= MAX_POINTS:
        raise ParameterError(f"--points must lie in 2..{MAX_POINTS}, got {points}")
    return np.linspace(0.0, t_end, points)


def _method(args, known, default: str) -> str:
    """--method, or the motion's default, checked against the methods it has."""
    method = args.method or default
    if method not in known:
        raise ParameterError(f"--method: unknown method {method!r}; known: {' '.join(known)}")
    return method


def _png(out):
    """--out checked (a .png in a writable folder) where given."""
    return check_png_out(out) if out is not None else None


def _perturb_items(items: list) -> dict:
    """--perturb NAME=VALUE items as {name: text}, each name once."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ParameterError(f"--perturb {item!r}: expected NAME=VALUE (a coordinate, or its rate NAME_d)")
        if name in out:
            raise ParameterError(f"--perturb {name}: given twice")
        out[name] = value.strip()
    return out


def _run_generic(model, args):
    """Any model without a motion of its own: every input checked first (names, numbers,
    --perturb, --t-end, --points, --method, --out), then integrated from the reference."""
    from gyro.analyses import motion

    values = model.parameters(parse_sets(args.set))
    offsets = motion.perturbations(model, _perturb_items(args.perturb or []))
    t = _times(args)
    method = _method(args, motion.METHODS, "DOP853")
    out = _png(args.out)
    return motion.simulate(model, values, offsets, t, method), out


FLAGS = {"perturb": "--perturb", "method": "--method", "level": "--level", "base_rate": "--base-rate"}
GENERIC = ("perturb", "method")  # the flags of the generic motion


def run(args) -> int:
    from types import SimpleNamespace

    from gyro.catalog import declared_module
    from gyro.models import load

    model = load(args.model)
    decl = model.meta.get("simulate")
    takes = tuple(decl["options"]) if decl else GENERIC
    for flag, name in FLAGS.items():
        if getattr(args, flag) is not None and flag not in takes:
            own = f"; its motion takes {' '.join(FLAGS[f] for f in takes) or 'none of these'}" + \
                (f" ({decl['usage']})" if decl and decl.get("usage") else "")
            raise ParameterError(f"{name}: not for {model.name}" + (own if decl else
                                 f" (a generic motion from the reference: {name} needs a motion of the "
                                 "model's own, Model.simulate)"))
    if decl:
        cli = SimpleNamespace(sets=parse_sets, times=_times, perturb_items=_perturb_items, png=_png, method=_method)
        result = declared_module(decl["module"], f"{model.name}'s motion", model).simulate_command(model, args, cli)
        out = Path(args.out) if args.out is not None else None
    else:
        result, out = _run_generic(model, args)
    if out is not None:
        result.plot(out)
    print(json.dumps(result.to_dict(), allow_nan=False) if args.json else result.table())
    return 0
