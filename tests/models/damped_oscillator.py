"""Damped linear oscillator m x'' + c x' + k x = 0, the damping through a Rayleigh function.

Textbook answer: the roots of m p^2 + c p + k are p = -c/(2m) +- i sqrt(k/m - c^2/(4m^2));
the operator is M = m, D = c (all dissipative: D_s = c, G = 0), K = k. A test model of
tests/generated/test_textbook.py, not a model of a paper.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "damped_oscillator"
PARAMETERS = [
    Parameter("m", "kg", 2.0, "mass"),
    Parameter("c", "N s/m", 0.3, "viscous damping coefficient", kind="nonnegative"),
    Parameter("k", "N/m", 50.0, "spring stiffness"),
]
m, c, k = (p.symbol for p in PARAMETERS)
x, x_d, x_dd = sp.symbols("x x_d x_dd")


def build() -> Model:
    return Model(
        name=NAME, title="Damped linear oscillator", source="textbook", module=__name__,
        parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"},
        q=[x], qd=[x_d], qdd=[x_dd],
        lagrangian=m * x_d**2 / 2 - k * x**2 / 2,
        dissipation=c * x_d**2 / 2,
        symmetric_zero=["x"],
    )
