"""`gyro simulate gimbal_gyroscope [--set NAME=VALUE]... --t-end T [--points N]
[--method NAME] [--json] [--out FILE.png]`: a motion of the gimbal gyroscope by the closed
form (2.6) (default) or by integrating the generated equations (1.1).

`gyro simulate gyrohorizoncompass [--set NAME=VALUE]... --t-end T [--points N] [--perturb
D1,D2,D3,D4] [--method NAME] [--json] [--out FILE.png]`: a motion of the gyrohorizoncompass
from its relative equilibrium (3.1), the angles alpha, beta, gamma, epsilon moved by D1..D4
rad (at rest), by integrating the emitted (1.5)-(1.6) (default DOP853; `projected`: fixed
steps of DOP853's tableau projected onto E = E(0)); E (2.3) along it. Parameters:
A B C J L I nu zeta eta lam (or lambda; it defaults to 1 + chi).

`gyro simulate gimbal_precession --level {full,rigorous,image,small,elementary} --t-end T
[--points N] [--set NAME=VALUE]... [--base-rate NAME=AMP:FREQ[:PHASE]]... [--json] [--out
FILE.png]`: the image point and the gimbal angles by one level of the precession hierarchy
(docs/precession.md). `--base-rate eta=AMP:FREQ:PHASE` turns the base at
u_eta(t) = u_eta + AMP sin(FREQ t + PHASE) (rad/s, rad/s, rad; NAME xi, eta or zeta;
repeated, the terms add). JSON keys: model, level, params, t, x, y, alpha, beta (and H,
seconds, and base_rate for a time-varying base).

`gyro simulate MODEL [--set NAME=VALUE]... --t-end T [--points N] [--perturb NAME=VALUE]...
[--method NAME] [--json] [--out FILE.png]` for every other model (a generated one, a model
file, an emitted folder): the emitted nonlinear equations integrated from the reference (the
equilibrium of the set; steady and cyclic rates as the reference has them), each
`--perturb NAME=VALUE` an offset of a coordinate or, as NAME_d, of its rate (repeatable);
methods DOP853 (default), RK45, Radau, BDF, LSODA; JSON keys t, one list per coordinate
(absolute values, the model's units), method, and rates, coordinates, units, params,
perturb, equilibrium, model, seconds (gyro/analyses/motion.py).

Parameters: the model's (`gyro params gimbal_gyroscope`) and the initial conditions
theta0 dtheta0 dpsi0 dphi0 (rad, rad/s); psi(0) = phi(0) = 0. Every input is checked before
anything is computed; bad input exits with 2 and one line naming it.
"""
from __future__ import annotations

import json
from pathlib import Path

from gyro.cli.common import add_json, add_model, add_out, add_set, check_png_out, parse_sets
from gyro.errors import ParameterError, finite_number

ORDER = 50
MAX_POINTS = 10**6  # time points: 8 MB a coordinate
SIMULATED = ("gimbal_gyroscope", "gyrohorizoncompass", "gimbal_precession")


def register(sub) -> None:
    s = sub.add_parser("simulate", help="a motion of a model from its reference (the emitted nonlinear "
                       "equations integrated; the gimbal gyroscope also by its closed form, gimbal_precession "
                       "by its levels)")
    add_model(s)
    add_set(s, "parameter or, for the gimbal, initial condition (theta0 dtheta0 dpsi0 dphi0), SI units, radians")
    s.add_argument("--t-end", required=True, metavar="T", help="end time in s (> 0)")
    s.add_argument("--points", default="1001", metavar="N", help="number of time points from 0 to T (>= 2)")
    s.add_argument("--method", default=None, metavar="NAME",
                   help="closed_form (the gimbal's default), RK45, DOP853 (the gyrohorizoncompass's default), "
                   "Radau, BDF, LSODA, cvodes, idas (gimbal) or cvodes-adams, projected (gyrohorizoncompass)")
    s.add_argument("--perturb", action="append", default=None, metavar="NAME=VALUE",
                   help="an offset at t = 0 from the reference: a coordinate NAME or its rate NAME_d, in the "
                   "model's units (repeatable); the gyrohorizoncompass also takes D1,D2,D3,D4 (alpha, beta, "
                   "gamma, epsilon - epsilon0, rad)")
    s.add_argument("--level", default=None, metavar="LEVEL",
                   help="gimbal_precession: full, rigorous, image, small or elementary (required)")
    s.add_argument("--base-rate", action="append", default=None, metavar="NAME=AMP:FREQ[:PHASE]",
                   help="gimbal_precession: a time-varying base, u_NAME(t) = u_NAME + AMP sin(FREQ t + PHASE) "
                   "(NAME xi, eta or zeta; AMP in rad/s, FREQ >= 0 in rad/s, PHASE in rad, default 0); repeatable")
    add_json(s)
    add_out(s, required=False, help="also plot the coordinates against t into FILE.png")
    s.set_defaults(run=run)


def _initial_params() -> list:
    from gyro.systems.gimbal_gyroscope import INITIAL
    from gyro.models import Param

    return [Param(n, u, d, desc, "real", (None, None)) for n, (u, d, desc) in INITIAL.items()]


def parse(args):
    """(Motion, times, method) from the arguments, or ParameterError naming the input."""
    from gyro.systems.gimbal_gyroscope import METHODS, Motion
    from gyro.models import load

    if args.perturb is not None:
        raise ParameterError("--perturb: only for gyrohorizoncompass (the gimbal takes --set theta0=...)")
    if args.method is None:
        args.method = "closed_form"
    model = load(args.model)
    ic = {p.name: p for p in _initial_params()}
    sets = parse_sets(args.set)
    known = [*model.param_names, *model.aliases, *ic]
    for key in sets:
        if key not in known:
            raise ParameterError(f"unknown parameter {key!r} for {model.name}; known: {model.known_names()} "
                                 f"{' '.join(ic)}")
    values = model.parameters({k: v for k, v in sets.items() if k not in ic})
    init = {}
    for name, p in ic.items():
        raw = sets.get(name, p.default)
        try:
            init[name] = float(raw)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {name}: not a number: {raw!r}") from None
        p.check(init[name])
    t = _times(args)
    if args.method not in METHODS:
        raise ParameterError(f"--method: unknown method {args.method!r}; known: {' '.join(METHODS)}")
    if args.out is not None:
        check_png_out(args.out)  # a .png in a writable folder, not a folder, not too long a name
    motion = Motion(values, init["theta0"], init["dtheta0"], init["dpsi0"], init["dphi0"])
    return motion, t, args.method


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


def _run_ghc(args) -> int:
    """gyrohorizoncompass: every input checked first (names, numbers, equilibrium, --perturb,
    --t-end, --points, --method, --out), then integrated."""
    from gyro.systems import gyrohorizoncompass as ghc

    values = ghc.parameters(parse_sets(args.set))
    perturb = [0.0] * 4
    if args.perturb is not None and (len(args.perturb) > 1 or "=" in args.perturb[0]):
        names = ("alpha", "beta", "gamma", "epsilon")
        for name, raw in _perturb_items(args.perturb).items():
            if name not in names:
                raise ParameterError(f"--perturb {name}: the gyrohorizoncompass's offsets are of "
                                     f"{', '.join(names)} (rad, at rest)")
            perturb[names.index(name)] = finite_number(f"--perturb {name}", raw)
    elif args.perturb is not None:
        parts = args.perturb[0].split(",")
        if len(parts) != 4:
            raise ParameterError(f"--perturb: expected four numbers D1,D2,D3,D4, got {args.perturb!r}")
        perturb = [finite_number(f"--perturb {n}", p) for n, p in zip(("alpha", "beta", "gamma", "epsilon"), parts)]
    t = _times(args)
    method = args.method or "DOP853"
    if method not in ghc.METHODS:
        raise ParameterError(f"--method: unknown method {method!r}; known: {' '.join(ghc.METHODS)}")
    out = check_png_out(args.out) if args.out is not None else None
    tr = ghc.trajectory(values, t, perturb, method)
    if out is not None:
        tr.plot(out)
    print(json.dumps(tr.to_dict(), allow_nan=False) if args.json else tr.table())
    return 0


def _run_precession(args) -> int:
    """gimbal_precession: every input checked first (names, numbers, --level, --t-end,
    --points, --out, the initial angles), then integrated by the level."""
    from gyro.systems import gimbal_precession as precession

    for flag in ("perturb", "method"):
        if getattr(args, flag) is not None:
            raise ParameterError(f"--{flag}: not for gimbal_precession (its levels: --level)")
    if args.level is None:
        raise ParameterError(f"--level: required for gimbal_precession; one of {', '.join(precession.LEVELS)}")
    if args.level not in precession.LEVELS:
        raise ParameterError(f"--level: unknown level {args.level!r}; known: {', '.join(precession.LEVELS)}")
    values = precession.parameters(parse_sets(args.set))
    terms = [_oscillation(item) for item in args.base_rate or []]
    base = precession.oscillating_base(values, terms) if terms else None
    t = _times(args)
    out = check_png_out(args.out) if args.out is not None else None
    precession.initial_state(args.level, values, base)  # the initial angles away from +-90 deg
    motion = precession.simulate(values, t, args.level, base=base)
    if out is not None:
        motion.plot(out)
    print(json.dumps(motion.to_dict(), allow_nan=False) if args.json else motion.table())
    return 0


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


def _run_generic(args) -> int:
    """Any other model: every input checked first (names, numbers, --perturb, --t-end,
    --points, --method, --out), then integrated from the reference."""
    from gyro.analyses import motion
    from gyro.models import load

    for flag, what in (("level", "--level"), ("base_rate", "--base-rate")):
        if getattr(args, flag) is not None:
            raise ParameterError(f"{what}: only for gimbal_precession")
    model = load(args.model)
    values = model.parameters(parse_sets(args.set))
    offsets = motion.perturbations(model, _perturb_items(args.perturb or []))
    t = _times(args)
    method = args.method or "DOP853"
    if method not in motion.METHODS:
        raise ParameterError(f"--method: unknown method {method!r}; known: {' '.join(motion.METHODS)}")
    out = check_png_out(args.out) if args.out is not None else None
    m = motion.simulate(model, values, offsets, t, method)
    if out is not None:
        m.plot(out)
    print(json.dumps(m.to_dict(), allow_nan=False) if args.json else m.table())
    return 0


def _oscillation(item: str):
    """One --base-rate NAME=AMP:FREQ[:PHASE] as an Oscillation, or ParameterError naming it."""
    from gyro.systems import gimbal_precession as precession

    label = f"--base-rate {item!r}"
    name, sep, spec = item.partition("=")
    parts = spec.split(":")
    if not sep or not name.strip() or len(parts) not in (2, 3):
        raise ParameterError(f"{label}: expected NAME=AMP:FREQ[:PHASE] (NAME xi, eta or zeta)")
    return precession.oscillation(name.strip(), *parts, what=label)


def run(args) -> int:
    import numpy as np

    from gyro.systems.gimbal_gyroscope import trajectory

    if args.model not in SIMULATED:
        return _run_generic(args)
    if args.base_rate is not None and args.model != "gimbal_precession":
        raise ParameterError("--base-rate: only for gimbal_precession")
    if args.model == "gyrohorizoncompass":
        return _run_ghc(args)
    if args.model == "gimbal_precession":
        return _run_precession(args)
    if args.level is not None:
        raise ParameterError("--level: only for gimbal_precession")
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
