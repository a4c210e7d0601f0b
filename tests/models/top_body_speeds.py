"""A heavy top about a fixed point as KanesMethod's examples write it: body-fixed 1-2-3
angles q1, q2, q3, generalised speeds u1, u2, u3 that are the body's angular-velocity
components (not the angles' rates), the kinematic differential equations u_i - w . b_i = 0
(kd_eqs), the Lagrangian from sympy.physics.mechanics.Lagrangian in those speeds.

With `kinematics` the machinery derives in the speeds (tests/generated/test_speeds.py holds it to
KanesMethod); `build_without_kinematics()` hands the same speeds over as if they were the
angles' rates, which the machinery must refuse (the angular velocity of B, set in u, is not
the one its orientation gives with u = q')."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

from derive.model import Model, Parameter

PARAMETERS = [
    Parameter("A", "kg m^2", 0.02, "equatorial moment of inertia about the mass centre"),
    Parameter("C", "kg m^2", 0.01, "polar moment of inertia"),
    Parameter("m", "kg", 1.0, "mass"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
    Parameter("l", "m", -0.05, "fixed point to mass centre along the axis (negative: hanging)", kind="real"),
]


def system():
    """(Lagrangian, q, u, kd_eqs, body, frame, gravity load) as a KanesMethod user has them."""
    q = dynamicsymbols("q1:4")
    u = dynamicsymbols("u1:4")
    A, C, m, g = sp.symbols("A C m g", positive=True)
    l = sp.symbols("l", real=True)
    N = ReferenceFrame("N")
    B = ReferenceFrame("B")
    B.orient_body_fixed(N, q, "123")
    w = B.ang_vel_in(N)  # from the orientation, in q'
    kd = [u[0] - w.dot(B.x), u[1] - w.dot(B.y), u[2] - w.dot(B.z)]
    B.set_ang_vel(N, u[0] * B.x + u[1] * B.y + u[2] * B.z)
    O = Point("O")
    O.set_vel(N, 0)
    G = O.locatenew("G", l * B.z)
    G.v2pt_theory(O, N, B)
    body = RigidBody("top", G, B, m, (inertia(B, A, A, C), G))
    body.potential_energy = m * g * G.pos_from(O).dot(N.z)
    return Lagrangian(N, body), q, u, kd, body, N, (G, -m * g * N.z)


def _model(name, kinematics: bool) -> Model:
    L, q, u, kd, _, N, _ = system()
    return Model(
        name=name, title="Heavy top in body-rate speeds", source="test", module=__name__,
        parameters=PARAMETERS, coordinates=["q1", "q2", "q3"], coordinate_units={f"q{i}": "rad" for i in (1, 2, 3)},
        q=q, qd=u, qdd=[], lagrangian=L, frame=N, kinematics=kd if kinematics else [], symmetric_zero=["q1", "q2"],
        reduced=["q1", "q2", "q3"])


def build() -> Model:
    return _model("top_body_speeds", True)


def build_without_kinematics() -> Model:
    return _model("top_body_speeds_as_rates", False)
