"""A two-link arm (uniform rods l1, l2, absolute angles q1, q2 from N.x, gravity along -N.y)
whose tip is held on the vertical line x = d by a pin in a slot: one configuration
constraint l1 cos q1 + l2 cos q2 - d = 0, nonlinear in both angles (no cheap solve: one
multiplier), a torque T(t) at the shoulder, a torsion spring k there."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import (Lagrangian, LagrangesMethod, Point, ReferenceFrame, RigidBody,
                                     dynamicsymbols, inertia)

from derive.model import Model, Parameter

PARAMETERS = [Parameter("l1", "m", 0.5, "upper arm"), Parameter("l2", "m", 0.6, "forearm"),
              Parameter("m1", "kg", 1.0, "upper arm mass"), Parameter("m2", "kg", 0.8, "forearm mass"),
              Parameter("d", "m", 0.7, "slot's distance"), Parameter("k", "N m/rad", 15.0, "shoulder spring"),
              Parameter("g", "m/s^2", 9.81, "gravity")]
INDEPENDENT = ["q1"]


def system():
    q1, q2 = dynamicsymbols("q1 q2")
    T = dynamicsymbols("T")
    l1, l2, m1, m2, d, k, g = sp.symbols("l1 l2 m1 m2 d k g", positive=True)
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [q1, N.z])
    B = N.orientnew("B", "Axis", [q2, N.z])
    O = Point("O")
    O.set_vel(N, 0)
    E = O.locatenew("E", l1 * A.x)
    G1 = O.locatenew("G1", l1 / 2 * A.x)
    G2 = E.locatenew("G2", l2 / 2 * B.x)
    G1.v2pt_theory(O, N, A)
    E.v2pt_theory(O, N, A)
    G2.v2pt_theory(E, N, B)
    upper = RigidBody("upper", G1, A, m1, (inertia(A, 0, 0, m1 * l1**2 / 12), G1))
    fore = RigidBody("fore", G2, B, m2, (inertia(B, 0, 0, m2 * l2**2 / 12), G2))
    upper.potential_energy = m1 * g * G1.pos_from(O).dot(N.y) + k * q1**2 / 2
    fore.potential_energy = m2 * g * G2.pos_from(O).dot(N.y)
    tip = E.locatenew("tip", l2 * B.x).pos_from(O)
    return Lagrangian(N, upper, fore), [q1, q2], [tip.dot(N.x) - d], [(A, T * N.z)], N


def reference():
    L, q, hol, loads, N = system()
    lm = LagrangesMethod(L, q, hol_coneqs=hol, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    return "lagrange", lm


def build() -> Model:
    L, q, hol, loads, N = system()
    return Model(name="arm_on_line", title="Two-link arm with its tip in a slot", source="test", module=__name__,
                 parameters=PARAMETERS, coordinates=["q1", "q2"], coordinate_units={"q1": "rad", "q2": "rad"},
                 q=q, qd=[], qdd=[], lagrangian=L, loads=loads, frame=N, holonomic=hol, reduced=INDEPENDENT)
