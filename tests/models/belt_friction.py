"""A mass on a spring, dragged by Coulomb friction from a belt moving at speed v, against a
one-sided stop (a spring k_s that pushes back only beyond x = a) and with quadratic air
drag: every non-smooth function the machinery takes, in a force or in the potential.

    m x'' = -k x - k_s Max(0, x - a) - mu m g sign(x' - v) - c |x'| x'

At rest on the moving belt (x' = 0, belt speed v != 0) the friction is -mu m g sign(-v):
the linearisation exists there (D = 2 c |x'| = 0, K = k + k_s H(x - a)), and is NaN at
x = a where the stop's stiffness jumps and at v = 0 where the friction has no derivative.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

PARAMETERS = [
    Parameter("m", "kg", 1.0, "mass"),
    Parameter("k", "N/m", 4.0, "spring"),
    Parameter("k_s", "N/m", 40.0, "stop spring, beyond x = a"),
    Parameter("a", "m", 0.2, "position of the stop", kind="real"),
    Parameter("mu", "1", 0.3, "friction coefficient", kind="nonnegative"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
    Parameter("c", "kg/m", 0.1, "quadratic drag", kind="nonnegative"),
    Parameter("v", "m/s", 0.5, "belt speed", kind="real"),
]


def build() -> Model:
    m, k, k_s, a, mu, g, c, v = (p.symbol for p in PARAMETERS)
    x, x_d, x_dd = sp.symbols("x x_d x_dd")
    V = k * x**2 / 2 + k_s * sp.Max(0, x - a) ** 2 / 2
    return Model(
        name="belt_friction", title="Mass on a moving belt with a stop", source="test", module=__name__,
        parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"}, q=[x], qd=[x_d], qdd=[x_dd],
        lagrangian=m * x_d**2 / 2 - V,
        generalized_forces={"x": -mu * m * g * sp.sign(x_d - v) - c * sp.Abs(x_d) * x_d})
