"""A bead on a hoop of radius R that turns at the rate Omega about its vertical diameter,
written in Cartesian coordinates of the hoop's plane (x across, y up) held on the circle
x^2 + y^2 = R^2: the constraint has two branches, so the equations carry a Lagrange
multiplier. In the hoop's frame the bead feels gravity and the centrifugal potential,
L = m/2 (x'^2 + y'^2) + m/2 Omega^2 x^2 - m g y. At the bottom (x = 0, y = -R) the bead
oscillates at omega^2 = g/R - Omega^2 for Omega^2 < g/R and leaves it, growing at
sqrt(Omega^2 - g/R), beyond (tests/cli/test_campbell_stability.py: the Campbell diagram of
a model with multipliers against this hand formula). Its one level, `linear_exact`, is the
exact operator, the linearisation in the independent coordinate x on the hoop, by a method
of the ladder: `gyro scene` answers frequencies and stability with it
(tests/cli/test_scene_multipliers.py)."""
from __future__ import annotations

import sympy as sp

from derive.model import Bound, Level, Model, Parameter

PARAMETERS = [Parameter("m", "kg", 0.1, "bead mass"), Parameter("R", "m", 0.2, "hoop radius"),
              Parameter("g", "m/s^2", 9.81, "gravity"),
              Parameter("Omega", "rad/s", 3.0, "the hoop's rate about its vertical diameter", kind="nonnegative")]
m, R, g, Omega = (p.symbol for p in PARAMETERS)
q = list(sp.symbols("x y"))
qd = list(sp.symbols("x_d y_d"))
qdd = list(sp.symbols("x_dd y_dd"))


def build() -> Model:
    x, y = q
    L = m / 2 * (qd[0]**2 + qd[1]**2) + m / 2 * Omega**2 * x**2 - m * g * y
    return Model(name="hoop_bead", title="Bead on a turning hoop (Cartesian, a multiplier)", source="textbook",
                 module=__name__, parameters=PARAMETERS, coordinates=["x", "y"],
                 coordinate_units={"x": "m", "y": "m"}, q=q, qd=qd, qdd=qdd, lagrangian=L,
                 holonomic=[x**2 + y**2 - R**2], symmetric_zero=["x"], reduced=["x"],
                 equilibrium_approx={"y": -R},  # the bottom, of the two (the top: y = R)
                 spin={"parameter": "Omega"},
                 levels=[Level("linear_exact", "nothing of the linearised motion about the equilibrium on the hoop",
                               {"kind": "spectrum", "methods": ["polyroots", "companion", "default", "reference"],
                                "default": "default"},
                               {"frequencies": Bound(estimate=True), "stability": Bound(estimate=True)},
                               reference="linear_exact:reference",
                               doc="the exact operator in the independent coordinate x, by a method of the ladder")])
