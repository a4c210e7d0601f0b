"""A gyropendulum: a symmetric rotor hanging below a fixed point, tilted by alpha (about the
horizontal x) and beta (about the carried y), spinning about its axis by the cyclic angle
psi with the momentum H. Written outside the package, it declares a hierarchy for the
`motion` question on the generic machinery (gyro.analyses.motion): `linear`, the linearised
equations about the hanging equilibrium solved exactly with its correction as estimate, and
`integrated`, the full equations integrated at two tolerances.

Inertia A (equatorial, about the fixed point) and C (polar), mass m at l below the fixed
point: T = A/2 (w1^2 + w2^2) + C/2 (w3 + psi')^2 with w the tilted frame's rate, V = -m g l
(the height of the mass centre); the linearised tilts obey A a'' + H b' + m g l a = 0,
A b'' - H a' + m g l b = 0 (tests/cli/test_motion_generic.py)."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.model import Bound, Level, Model, Parameter

NAME = "gyropendulum"
PARAMETERS = [
    Parameter("A", "kg m^2", 0.02, "equatorial moment of inertia about the fixed point"),
    Parameter("C", "kg m^2", 0.01, "polar moment of inertia"),
    Parameter("m", "kg", 1.0, "mass"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
    Parameter("l", "m", 0.1, "distance of the mass centre below the fixed point"),
    Parameter("H", "kg m^2/s", 0.5, "the rotor's momentum about its axis", kind="nonnegative"),
]
A, C, m, g, l, H = (p.symbol for p in PARAMETERS)
COORDINATES = ["alpha", "beta", "psi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([x + "_d" for x in COORDINATES])
qdd = sp.symbols([x + "_dd" for x in COORDINATES])
MOTION = "gyro.analyses.motion"


def build() -> Model:
    alpha, beta, _psi = q
    w = mech.angular_velocity([("x", alpha), ("y", beta)], [qd[0], qd[1]])
    T = (A * (w[0]**2 + w[1]**2) + C * (w[2] + qd[2])**2) / 2
    R = mech.rotation([("x", alpha), ("y", beta)])
    V = -m * g * l * R[2, 2]  # the mass centre at -l R e3
    quantities = ["alpha", "beta"]
    return Model(
        name=NAME, title="Gyropendulum: a spinning rotor hanging from a fixed point", source="textbook",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={x: "rad" for x in COORDINATES}, q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T - V, cyclic={"psi": H}, symmetric_zero=["alpha", "beta"],
        levels=[
            Level("linear", "the terms of second and higher order in the tilts",
                  {"kind": "trajectory", "module": MOTION, "method": "linear", "quantities": quantities},
                  {"motion": Bound(estimate=True)}, cost=5e-3, reference="integrated",
                  doc="the linearised equations solved exactly, twice their second Picard correction the estimate"),
            Level("integrated", "nothing (the integrator's tolerance)",
                  {"kind": "trajectory", "module": MOTION, "method": "DOP853", "rtol": 1e-10,
                   "quantities": quantities},
                  {"motion": Bound(estimate=True)}, cost=5e-2,
                  doc="the full equations integrated at rtol and rtol/100"),
        ],
    )
