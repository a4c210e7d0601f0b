"""Heavy symmetric top about a fixed point, sleeping: tilts alpha (about the horizontal x)
and beta (about the carried y), then the spin phi about the symmetry axis.

Inertia A (equatorial) and C (polar) about the fixed point, mass m, mass centre at l on the
symmetry axis, gravity g. The spin turns steadily at the rate n (a declared steady motion,
phi ignorable since A = B); the reference is the upright top alpha = beta = 0.
Textbook answer (Maievski's condition): the sleeping top is stable iff C^2 n^2 > 4 A m g l;
the tilt block's characteristic polynomial is (A p^2 - m g l)^2 + (C n p)^2. The condition is
declared (Model.conditions) as one margin, C^2 n^2 - 4 A m g l, for `gyro stability` and
`gyro map`.
"""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.model import Conditions, Model, Parameter

NAME = "symmetric_top"
PARAMETERS = [
    Parameter("A", "kg m^2", 0.02, "equatorial moment of inertia about the fixed point"),
    Parameter("C", "kg m^2", 0.01, "polar moment of inertia"),
    Parameter("m", "kg", 1.0, "mass"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
    Parameter("l", "m", 0.05, "distance of the mass centre from the fixed point"),
    Parameter("n", "rad/s", 100.0, "spin rate of the sleeping top", kind="real"),
]
A, C, m, g, l, n = (p.symbol for p in PARAMETERS)
COORDINATES = ["alpha", "beta", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([x + "_d" for x in COORDINATES])
qdd = sp.symbols([x + "_dd" for x in COORDINATES])


def build() -> Model:
    alpha, beta, _phi = q
    # angular velocity of the tilted frame (after alpha, beta) in its own components; the
    # rotor turns in it about its axis 3 at phi': with A = B its energy is free of phi
    w = mech.angular_velocity([("x", alpha), ("y", beta)], [qd[0], qd[1]])
    T = (A * (w[0]**2 + w[1]**2) + C * (w[2] + qd[2])**2) / 2
    R = mech.rotation([("x", alpha), ("y", beta)])
    V = m * g * l * R[2, 2]  # height of the mass centre l R e3
    return Model(
        name=NAME, title="Sleeping heavy symmetric top", source="textbook", module=__name__,
        parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={x: "rad" for x in COORDINATES}, q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T - V,
        steady={"phi": n},
        symmetric_zero=["alpha", "beta"],
        conditions={"Maievski": Conditions([("C^2 n^2 - 4 A m g l", C**2 * n**2 - 4 * A * m * g * l)],
                                           "the sleeping top's condition: the spin's gyroscopic "
                                           "stiffness beats the toppling moment")},
    )
