"""A mass free to fall: L = m x'^2/2 - m g x.

Hand computation: the equation of motion m x'' = -m g has no point of rest for g != 0 (the
residual of the equilibrium equation is -m g wherever x is), so there is no equilibrium and
no operator about one to take frequencies of. At g = 0 every x is one (K = 0: a free
coordinate). A test model of tests/methods/test_rightmodel.py, not a model of a paper.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "free_fall"
PARAMETERS = [
    Parameter("m", "kg", 2.0, "mass"),
    Parameter("g", "m/s^2", 9.81, "gravity", kind="real"),
]
m, g = (p.symbol for p in PARAMETERS)
x, x_d, x_dd = sp.symbols("x x_d x_dd")


def build() -> Model:
    return Model(
        name=NAME, title="Mass free to fall", source="textbook", module=__name__,
        parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"},
        q=[x], qd=[x_d], qdd=[x_dd],
        lagrangian=m * x_d**2 / 2 - m * g * x,
    )
