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
import os
import sys
from pathlib import Path

import numpy as np

from gyro.models import Param, ParameterError, load

SIMULATED = ("gimbal_gyroscope",)
RTOL, ATOL = 1e-10, 1e-12  # the integrators' tolerances from the command line


def add_parser(sub) -> None:
    """Register `simulate` on the `gyro` subparsers."""
    s = sub.add_parser("simulate", help="a motion of the gimbal gyroscope: closed form or integrator")
    s.add_argument("model")
    s.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="parameter or initial condition (theta0 dtheta0 dpsi0 dphi0), SI units, radians")
    s.add_argument("--t-end", required=True, metavar="T", help="end time in s (> 0)")
    s.add_argument("--points", default="1001", metavar="N", help="number of time points from 0 to T (>= 2)")
    s.add_argument("--method", default="closed_form", metavar="NAME",
                   help="closed_form (default), RK45, DOP853, Radau, BDF, LSODA, cvodes or idas")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.add_argument("--out", metavar="FILE.png", help="also plot theta, psi, phi against t into FILE.png")
    s.set_defaults(run=run)


def _initial_params() -> list[Param]:
    from gyro.gimbal import INITIAL

    return [Param(n, u, d, desc, "real", (None, None)) for n, (u, d, desc) in INITIAL.items()]


def parse(args):
    """(Motion, times, method) from the arguments, or ParameterError naming the input."""
    from gyro.cli import _parse_sets
    from gyro.gimbal import METHODS, Motion

    if args.model not in SIMULATED:
        raise ParameterError(f"simulate: unknown model {args.model!r}; it covers {', '.join(SIMULATED)}")
    model = load(args.model)
    ic = {p.name: p for p in _initial_params()}
    sets = _parse_sets(args.set)
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


def _number(name: str, raw: str) -> float:
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: not a number: {raw!r}") from None
    if not math.isfinite(value):
        raise ParameterError(f"{name}: must be a finite number, got {raw!r}")
    return value


def motion_path(motion, t: np.ndarray, method: str):
    """theta, psi, phi at the times t by the closed form or an integrator."""
    from gyro.gimbal import ClosedForm, integrate

    if method == "closed_form":
        cf = ClosedForm(motion)
        psi, phi = cf.psi_phi(t)
        return cf.theta(t), psi, phi, cf
    q, _ = integrate(motion, t, method, RTOL, ATOL)
    return q[:, 1], q[:, 0], q[:, 2], None


def run(args) -> int:
    motion, t, method = parse(args)
    theta, psi, phi, cf = motion_path(motion, t, method)
    if not (np.all(np.isfinite(theta)) and np.all(np.isfinite(psi)) and np.all(np.isfinite(phi))):
        raise FloatingPointError("a coordinate is not finite")
    I = motion.integrals0
    if args.out is not None:
        _plot(Path(args.out), t, theta, psi, phi, method)
    if args.json:
        print(json.dumps({"t": t.tolist(), "theta": theta.tolist(), "psi": psi.tolist(),
                          "phi": phi.tolist(), "method": method, "integrals": I}, allow_nan=False))
        return 0
    model = load(args.model)
    print(f"{model.meta['title']} ({model.name}), method {method}")
    print(f"integrals at t = 0: H = {I['H']:.9g}, L = {I['L']:.9g}, M = {I['M']:.9g}")
    if cf is not None:
        period = "none (stationary or on the separatrix)" if not math.isfinite(cf.period) else f"{cf.period:.9g} s"
        print(f"motion: {cf.motion_type}; period of theta {period}")
    rows = range(len(t)) if len(t) <= 21 else np.unique(np.linspace(0, len(t) - 1, 11).round().astype(int))
    print(f"{'t [s]':>14} {'theta [rad]':>18} {'psi [rad]':>18} {'phi [rad]':>18}")
    for i in rows:
        print(f"{t[i]:>14.6g} {theta[i]:>18.12g} {psi[i]:>18.12g} {phi[i]:>18.12g}")
    if len(t) > 21:
        print(f"({len(t)} points; 11 shown; --json prints all)")
    return 0


def _plot(path: Path, t, theta, psi, phi, method: str) -> None:
    """theta, psi, phi against t into path, written whole or not at all."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
    for ax, y, name in zip(axes, (theta, psi, phi), ("theta", "psi", "phi")):
        ax.plot(t, y, lw=1)
        ax.set_ylabel(f"{name} [rad]")
    axes[0].set_title(f"gimbal gyroscope, {method}")
    axes[-1].set_xlabel("t [s]")
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp.png")
    try:
        fig.savefig(tmp, dpi=100)
        tmp.replace(path)
    finally:
        plt.close(fig)
        tmp.unlink(missing_ok=True)


if __name__ == "__main__":
    from gyro.cli import main

    sys.exit(main(["simulate", *sys.argv[1:]]))
