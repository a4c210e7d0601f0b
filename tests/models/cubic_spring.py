"""A mass on a purely cubic spring under a constant force: L = m x'^2/2 - k x^4/4 - F x.

The spring has no linear stiffness, so at x = 0 (where a solver may start) K = 3 k x^2 is
zero and Newton cannot take a step; the force moves the equilibrium off it.
Hand computation: the equation of motion m x'' = -k x^3 - F holds still where
k x^3 = -F, x_e = -(F/k)^(1/3); about it K = 3 k x_e^2 = 3 k^(1/3) F^(2/3), so the one root
pair is +-i omega with omega = sqrt(3 k^(1/3) F^(2/3) / m). At the defaults (m = 2 kg,
k = 8 N/m^3, F = 1 N): x_e = -0.5 m, K = 6 N/m, omega = sqrt(3) rad/s.
A test model of tests/methods/test_rightmodel.py, not a model of a paper.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "cubic_spring"
PARAMETERS = [
    Parameter("m", "kg", 2.0, "mass"),
    Parameter("k", "N/m^3", 8.0, "cubic spring constant"),
    Parameter("F", "N", 1.0, "constant force (along -x)", kind="real"),
]
m, k, F = (p.symbol for p in PARAMETERS)
x, x_d, x_dd = sp.symbols("x x_d x_dd")


def build() -> Model:
    return Model(
        name=NAME, title="Mass on a cubic spring under a constant force", source="textbook",
        module=__name__, parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"},
        q=[x], qd=[x_d], qdd=[x_dd],
        lagrangian=m * x_d**2 / 2 - k * x**4 / 4 - F * x,
    )
