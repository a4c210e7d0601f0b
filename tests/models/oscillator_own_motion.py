"""An undamped oscillator m x'' + k x = 0 that declares a motion of its own for `gyro simulate`
(Model.simulate): its closed form x = x0 cos(w t) + v0/w sin(w t), w = sqrt(k/m), from the
initial conditions x0, v0 taken as --set, in this same file (simulate_command, INITIAL).
simulate_command(model, args, cli) gets the parsed arguments and the command line's checks:
cli.sets, cli.times, cli.method(args, known, default), cli.png(out), cli.perturb_items.
Written outside the package: the runtime reaches the module only through the declaration
(tests/cli/test_motion_generic.py)."""
from __future__ import annotations

import numpy as np
import sympy as sp

from derive.model import Model, Parameter

NAME = "oscillator_own_motion"
PARAMETERS = [Parameter("m", "kg", 2.0, "mass"), Parameter("k", "N/m", 50.0, "stiffness")]
m, k = (p.symbol for p in PARAMETERS)
q, qd, qdd = [sp.Symbol("x")], [sp.Symbol("x_d")], [sp.Symbol("x_dd")]
INITIAL = {"x0": ("m", 0.1, "x at t = 0"), "v0": ("m/s", 0.0, "x' at t = 0")}


def build() -> Model:
    return Model(
        name=NAME, title="Oscillator with a closed-form motion of its own", source="tests", module=__name__,
        parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"}, q=q, qd=qd, qdd=qdd,
        lagrangian=m * qd[0]**2 / 2 - k * q[0]**2 / 2,
        simulate={"module": __name__, "options": ["method"], "initial": "the closed form's start",
                  "usage": "--set x0 v0; --method closed_form (the only one)"},
    )


def simulate_command(model, args, cli):
    from gyro.errors import finite_number
    from gyro.analyses.motion import coordinate_motion

    sets = cli.sets(args.set)
    init = {n: finite_number(f"parameter {n}", sets.pop(n, d)) for n, (_, d, _) in INITIAL.items()}
    values = model.parameters(sets)
    t = cli.times(args)
    cli.method(args, ("closed_form",), "closed_form")
    cli.png(args.out)
    w = np.sqrt(values["k"] / values["m"])
    x = init["x0"] * np.cos(w * t) + init["v0"] / w * np.sin(w * t)
    v = -init["x0"] * w * np.sin(w * t) + init["v0"] * np.cos(w * t)
    return coordinate_motion(model, "closed_form", t, x[:, None], v[:, None], values, init, {})
