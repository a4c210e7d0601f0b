"""`gyro simulate gimbal_gyroscope [--set NAME=VALUE]... --t-end T [--points N]
[--method NAME] [--json] [--out FILE.png]`: a motion of the gimbal gyroscope by the closed
form (2.6) (default) or by integrating the generated equations (1.1).

Parameters: the model's (`gyro params gimbal_gyroscope`) and the initial conditions
theta0 dtheta0 dpsi0 dphi0 (rad, rad/s); psi(0) = phi(0) = 0. Every input is checked before
anything is computed; bad input exits with 2 and one line naming it.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from gyro.cli.common import add_json, add_set, parse_sets
from gyro.models import Param, ParameterError, load

ORDER = 50
SIMULATED = ("gimbal_gyroscope",)


def register(sub) -> None:
    s = sub.add_parser("simulate", help="a motion of the gimbal gyroscope: closed form or integrator")
    s.add_argument("model")
    add_set(s, "parameter or initial condition (theta0 dtheta0 dpsi0 dphi0), SI units, radians")
    s.add_argument("--t-end", required=True, metavar="T", help="end time in s (> 0)")
    s.add_argument("--points", default="1001", metavar="N", help="number of time points from 0 to T (>= 2)")
    s.add_argument("--method", default="closed_form", metavar="NAME",
                   help="closed_form (default), RK45, DOP853, Radau, BDF, LSODA, cvodes or idas")
    add_json(s)
    s.add_argument("--out", metavar="FILE.png", help="also plot theta, psi, phi against t into FILE.png")
    s.set_defaults(run=run)


def _initial_params() -> list[Param]:
    from gyro.analyses.gimbal import INITIAL

    return [Param(n, u, d, desc, "real", (None, None)) for n, (u, d, desc) in INITIAL.items()]


def _number(name: str, raw: str) -> float:
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: not a number: {raw!r}") from None
    if not math.isfinite(value):
        raise ParameterError(f"{name}: must be a finite number, got {raw!r}")
    return value


def parse(args):
    """(Motion, times, method) from the arguments, or ParameterError naming the input."""
    from gyro.analyses.gimbal import METHODS, Motion

    if args.model not in SIMULATED:
        raise ParameterError(f"simulate: unknown model {args.model!r}; it covers {', '.join(SIMULATED)}")
    model = load(args.model)
    ic = {p.name: p for p in _initial_params()}
    sets = parse_sets(args.set)
    known = [*model.param_names, *ic]
    for key in sets:
        if key not in known:
            raise ParameterError(f"unknown parameter {key!r} for {model.name}; known: {' '.join(known)}")
    values = model.parameters({k: v for k, v in sets.items() if k not in ic})
    init = {}
    for name, p in ic.items():
        raw = sets.get(name, p.default)
        try:
            init[name] = float(raw)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {name}: not a number: {raw!r}") from None
        p.check(init[name])
    t_end = _number("--t-end", args.t_end)
    if not t_end > 0:
        raise ParameterError(f"--t-end must be positive, got {args.t_end!r}")
    try:
        points = int(args.points)
    except ValueError:
        raise ParameterError(f"--points: not an integer: {args.points!r}") from None
    if points < 2:
        raise ParameterError(f"--points must be at least 2, got {points}")
    if args.method not in METHODS:
        raise ParameterError(f"--method: unknown method {args.method!r}; known: {' '.join(METHODS)}")
    if args.out is not None:
        out = Path(args.out)
        if out.suffix.lower() != ".png":
            raise ParameterError(f"--out: expected a .png file name, got {args.out!r}")
        if not out.parent.is_dir() if str(out.parent) else False:
            raise ParameterError(f"--out: no such directory: {str(out.parent)!r}")
    motion = Motion(values, init["theta0"], init["dtheta0"], init["dpsi0"], init["dphi0"])
    return motion, np.linspace(0.0, t_end, points), args.method


def run(args) -> int:
    from gyro.analyses.gimbal import trajectory

    motion, t, method = parse(args)
    tr = trajectory(motion, t, method)
    if not (np.all(np.isfinite(tr.theta)) and np.all(np.isfinite(tr.psi)) and np.all(np.isfinite(tr.phi))):
        raise FloatingPointError("a coordinate is not finite")
    if args.out is not None:
        tr.plot(Path(args.out))
    if args.json:
        print(json.dumps(tr.to_dict(), allow_nan=False))
    else:
        print(tr.table())
    return 0
