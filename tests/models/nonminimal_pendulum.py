"""A pendulum in Cartesian coordinates (q1 along gravity, q2 across) held on the circle
q1^2 + q2^2 = L^2, as sympy.physics.mechanics' test_nonminimal_pendulum writes it, with a
force F(t) across: the constraint has two branches, so the equations carry a Lagrange
multiplier, and the linearisation is in the independent coordinate q2."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Particle, Point, ReferenceFrame, dynamicsymbols

from derive.model import Model, Parameter

PARAMETERS = [Parameter("m", "kg", 1.0, "mass"), Parameter("L", "m", 0.5, "length"),
              Parameter("g", "m/s^2", 9.8, "gravity")]


def system():
    q1, q2 = dynamicsymbols("q1:3")
    F = dynamicsymbols("F")
    m, L, g = sp.symbols("m L g")
    N = ReferenceFrame("N")
    pN = Point("N*")
    pN.set_vel(N, 0)
    P = pN.locatenew("P1", q1 * N.x + q2 * N.y)
    P.set_vel(N, P.pos_from(pN).dt(N))
    pP = Particle("pP", P, m)
    return Lagrangian(N, pP), [q1, q2], [q1**2 + q2**2 - L**2], [(P, m * g * N.x + F * N.y)], N


def build() -> Model:
    L, q, hol, loads, N = system()
    return Model(name="nonminimal_pendulum", title="Pendulum in Cartesian coordinates", source="sympy tests",
                 module=__name__, parameters=PARAMETERS, coordinates=["q1", "q2"],
                 coordinate_units={"q1": "m", "q2": "m"}, q=q, qd=[], qdd=[], lagrangian=L,
                 loads=loads, frame=N, holonomic=hol, reduced=["q2"])
