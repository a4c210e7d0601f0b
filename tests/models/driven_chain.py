"""Chain of three masses and three springs (k1 from the wall to mass 1, k2, k3 between
neighbours) driven by a force F(t) on the last mass; light viscous damping c on each mass.

F is an input signal: the force is a Load on mass 3 (its velocity x3'), so B = e3.
Textbook answers: K x = B F at rest (springs in series: x1 = F/k1, x2 = x1 + F/k2,
x3 = x2 + F/k3), and, undamped, X = (K - W^2 M)^{-1} B F0 for F = F0 cos(W t).
"""
from __future__ import annotations

import sympy as sp

from derive.model import Load, Model, Parameter, Signal

NAME = "driven_chain"
PARAMETERS = [
    Parameter("m1", "kg", 1.0, "mass 1"),
    Parameter("m2", "kg", 1.5, "mass 2"),
    Parameter("m3", "kg", 0.7, "mass 3"),
    Parameter("k1", "N/m", 100.0, "spring from the wall to mass 1"),
    Parameter("k2", "N/m", 80.0, "spring between masses 1 and 2"),
    Parameter("k3", "N/m", 60.0, "spring between masses 2 and 3"),
    Parameter("c", "N s/m", 0.5, "viscous damping of each mass", kind="nonnegative"),
]
m1, m2, m3, k1, k2, k3, c = (p.symbol for p in PARAMETERS)
COORDINATES = ["x1", "x2", "x3"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([n + "_d" for n in COORDINATES])
qdd = sp.symbols([n + "_dd" for n in COORDINATES])
FORCE = Signal("F", "N", "force on mass 3", input=True, order=0)


def build() -> Model:
    x1, x2, x3 = q
    T = (m1 * qd[0]**2 + m2 * qd[1]**2 + m3 * qd[2]**2) / 2
    V = (k1 * x1**2 + k2 * (x2 - x1)**2 + k3 * (x3 - x2)**2) / 2
    return Model(
        name=NAME, title="Driven chain of three masses", source="textbook", module=__name__,
        parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={n: "m" for n in COORDINATES}, q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T - V,
        dissipation=c * sum(v**2 for v in qd) / 2,
        loads=[Load(sp.Matrix([FORCE.symbol]), sp.Matrix([qd[2]]), "F on mass 3")],
        signals=[FORCE],
        symmetric_zero=COORDINATES,
    )
