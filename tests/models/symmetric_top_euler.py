"""Heavy symmetric top about a fixed point in Euler angles: precession psi about the
vertical, nutation theta, spin phi. psi and phi are cyclic with the momenta Lz (vertical)
and H (axial); the Routh reduction leaves theta, whose reference is a steady precession at
an unknown theta0.

Textbook answer: with the effective potential V(theta) = (Lz - H cos theta)^2/(2 A
sin^2 theta) + m g l cos theta, steady precession is V'(theta0) = 0 and the nutation
frequency about it is omega^2 = V''(theta0)/A.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "symmetric_top_euler"
PARAMETERS = [
    Parameter("A", "kg m^2", 0.02, "equatorial moment of inertia about the fixed point"),
    Parameter("C", "kg m^2", 0.01, "polar moment of inertia"),
    Parameter("m", "kg", 1.0, "mass"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
    Parameter("l", "m", 0.05, "distance of the mass centre from the fixed point"),
]
A, C, m, g, l = (p.symbol for p in PARAMETERS)
COORDINATES = ["psi", "theta", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([x + "_d" for x in COORDINATES])
qdd = sp.symbols([x + "_dd" for x in COORDINATES])
Lz, H = sp.symbols("Lz H")  # momenta of psi and phi


def build() -> Model:
    _psi, theta, _phi = q
    psi_d, theta_d, phi_d = qd
    T = (A * (theta_d**2 + psi_d**2 * sp.sin(theta)**2) + C * (phi_d + psi_d * sp.cos(theta))**2) / 2
    return Model(
        name=NAME, title="Heavy symmetric top in Euler angles", source="textbook",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={x: "rad" for x in COORDINATES}, q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T - m * g * l * sp.cos(theta),
        cyclic={"psi": Lz, "phi": H},
        reduced=["theta"],
    )
