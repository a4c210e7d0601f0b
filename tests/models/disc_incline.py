"""A disc rolling down an incline, as sympy.physics.mechanics' test_disc_on_an_incline_plane
writes it: y along the incline, theta the disc's angle, rolling without slip y = R theta,
a holonomic constraint with one solution: theta is eliminated. A torque tau(t) on the disc
makes B."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Point, ReferenceFrame, RigidBody, dynamicsymbols

from derive.model import Model, Parameter

PARAMETERS = [Parameter("m", "kg", 1.0, "mass"), Parameter("g", "m/s^2", 9.81, "gravity"),
              Parameter("R", "m", 0.1, "radius"), Parameter("l", "m", 2.0, "length of the incline"),
              Parameter("alpha", "rad", 0.3, "inclination")]


def system():
    y, theta = dynamicsymbols("y theta")
    tau = dynamicsymbols("tau")
    m, g, R, l, alpha = sp.symbols("m g R l alpha")
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [sp.pi / 2 - alpha, N.z])
    B = A.orientnew("B", "Axis", [-theta, A.z])
    Do = Point("Do")
    Do.set_vel(N, y.diff() * A.x)
    D = RigidBody("D", Do, B, m, (m * R**2 / 2 * (B.z | B.z), Do))
    D.potential_energy = m * g * (l - y) * sp.sin(alpha)
    return Lagrangian(N, D), [y, theta], [y - R * theta], [(B, -tau * A.z)], N


def build() -> Model:
    L, q, hol, loads, N = system()
    return Model(name="disc_incline", title="Disc rolling on an incline", source="sympy tests",
                 module=__name__, parameters=PARAMETERS, coordinates=["y", "theta"],
                 coordinate_units={"y": "m", "theta": "rad"}, q=q, qd=[], qdd=[], lagrangian=L,
                 loads=loads, frame=N, holonomic=hol)
