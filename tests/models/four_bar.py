"""A planar four-bar linkage as sympy.physics.mechanics' docs and test_jointsmethod set it
up: crank (q1, at O), coupler (q2) and rocker (q3, at D), each angle measured from the
ground link OD, three uniform rods under gravity, a torsion spring k at the crank's pivot
and a torque T(t) on the crank. The loop closes by two configuration constraints,

    l1 cos q1 + l2 cos q2 - l3 cos q3 - l4 = 0,   l1 sin q1 + l2 sin q2 - l3 sin q3 = 0,

which have no unique solution for any two angles (two assembly branches): the equations
carry two multipliers, and the linearisation is in the independent crank angle q1."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

from derive.model import Model, Parameter

PARAMETERS = [
    Parameter("l1", "m", 0.3, "crank length"), Parameter("l2", "m", 1.0, "coupler length"),
    Parameter("l3", "m", 0.8, "rocker length"), Parameter("l4", "m", 1.0, "ground link length"),
    Parameter("m1", "kg", 0.5, "crank mass"), Parameter("m2", "kg", 1.5, "coupler mass"),
    Parameter("m3", "kg", 1.2, "rocker mass"), Parameter("k", "N m/rad", 20.0, "torsion spring at the crank"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
]


def system():
    """(Lagrangian, q, holonomic constraints, loads, frame)."""
    q = dynamicsymbols("q1:4")
    T = dynamicsymbols("T")
    l1, l2, l3, l4, m1, m2, m3, k, g = sp.symbols("l1 l2 l3 l4 m1 m2 m3 k g", positive=True)
    N = ReferenceFrame("N")
    A, B, C = (N.orientnew(n, "Axis", [qi, N.z]) for n, qi in zip("ABC", q))
    O = Point("O")
    O.set_vel(N, 0)
    P1 = O.locatenew("P1", l1 * A.x)  # crank to coupler
    D = O.locatenew("D", l4 * N.x)
    D.set_vel(N, 0)
    G1 = O.locatenew("G1", l1 / 2 * A.x)
    G2 = P1.locatenew("G2", l2 / 2 * B.x)
    G3 = D.locatenew("G3", l3 / 2 * C.x)
    bodies = []
    for name, G, frame, mass, length, base in (("crank", G1, A, m1, l1, O), ("coupler", G2, B, m2, l2, O),
                                                ("rocker", G3, C, m3, l3, D)):
        G.set_vel(N, G.pos_from(base).dt(N))
        body = RigidBody(name, G, frame, mass, (inertia(frame, 0, 0, mass * length**2 / 12), G))
        body.potential_energy = mass * g * G.pos_from(O).dot(N.y)
        bodies.append(body)
    bodies[0].potential_energy += k * q[0] ** 2 / 2
    loop = P1.locatenew("P2", l2 * B.x).pos_from(D) - l3 * C.x
    hol = [loop.dot(N.x), loop.dot(N.y)]
    return Lagrangian(N, *bodies), list(q), hol, [(A, T * N.z)], N


def build() -> Model:
    L, q, hol, loads, N = system()
    return Model(name="four_bar", title="Four-bar linkage", source="sympy docs", module=__name__,
                 parameters=PARAMETERS, coordinates=["q1", "q2", "q3"],
                 coordinate_units={"q1": "rad", "q2": "rad", "q3": "rad"}, q=q, qd=[], qdd=[],
                 lagrangian=L, loads=loads, frame=N, holonomic=hol, reduced=["q1"])
