"""A slider-crank: crank angle q1 (length r, inertia about its pivot Jc), connecting rod
angle q2 (length l, uniform, mass m2), slider position x (mass m3) along the line of the
pivot, a spring k on the slider towards x0 and a force F(t) on it. The loop closes by

    r cos q1 + l cos q2 - x = 0,   r sin q1 - l sin q2 = 0,

linear in x but not in q2: no coordinate pair has a linear solve, so the equations carry
two multipliers; the linearisation is in the crank angle q1."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Particle, Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

from derive.model import Model, Parameter

PARAMETERS = [
    Parameter("r", "m", 0.1, "crank length"), Parameter("l", "m", 0.4, "rod length"),
    Parameter("Jc", "kg m^2", 0.01, "crank inertia about its pivot"), Parameter("m2", "kg", 0.8, "rod mass"),
    Parameter("m3", "kg", 1.0, "slider mass"), Parameter("k", "N/m", 500.0, "slider spring"),
    Parameter("x0", "m", 0.45, "slider spring's free position"),
]


def system():
    q1, q2, x = dynamicsymbols("q1 q2 x")
    F = dynamicsymbols("F")
    r, l, Jc, m2, m3, k, x0 = sp.symbols("r l Jc m2 m3 k x0", positive=True)
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [q1, N.z])
    B = N.orientnew("B", "Axis", [-q2, N.z])
    O = Point("O")
    O.set_vel(N, 0)
    Ac = O.locatenew("Ac", 0 * N.x)
    Ac.set_vel(N, 0)
    crank = RigidBody("crank", Ac, A, 1, (inertia(A, 0, 0, Jc), Ac))
    P = O.locatenew("P", r * A.x)
    G = P.locatenew("G", l / 2 * B.x)
    G.set_vel(N, G.pos_from(O).dt(N))
    rod = RigidBody("rod", G, B, m2, (inertia(B, 0, 0, m2 * l**2 / 12), G))
    S = O.locatenew("S", x * N.x)
    S.set_vel(N, x.diff() * N.x)
    slider = Particle("slider", S, m3)
    slider.potential_energy = k * (x - x0) ** 2 / 2
    closure = P.locatenew("E", l * B.x).pos_from(S)
    return Lagrangian(N, crank, rod, slider), [q1, q2, x], [closure.dot(N.x), closure.dot(N.y)], [(S, F * N.x)], N


def build() -> Model:
    L, q, hol, loads, N = system()
    return Model(name="slider_crank", title="Slider-crank", source="test", module=__name__,
                 parameters=PARAMETERS, coordinates=["q1", "q2", "x"],
                 coordinate_units={"q1": "rad", "q2": "rad", "x": "m"}, q=q, qd=[], qdd=[],
                 lagrangian=L, loads=loads, frame=N, holonomic=hol, reduced=["q1"])
