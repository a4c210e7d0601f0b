"""Spherical pendulum (mass m, length l, polar angle theta from the downward vertical,
azimuth phi) with the azimuth's momentum given as the number 0: the Routh reduction leaves
the plane pendulum m l^2 theta'' + m g l sin(theta) = 0, regular at theta = 0 (with a
nonzero momentum the reduced potential is singular there). The momentum 0 is a constant of
the derivation, not an input of the emitted functions.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "spherical_pendulum"
PARAMETERS = [
    Parameter("m", "kg", 0.5, "mass of the bob"),
    Parameter("l", "m", 0.8, "length"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
]
m, l, g = (p.symbol for p in PARAMETERS)
COORDINATES = ["theta", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([x + "_d" for x in COORDINATES])
qdd = sp.symbols([x + "_dd" for x in COORDINATES])


def build() -> Model:
    theta, _phi = q
    theta_d, phi_d = qd
    T = m * l**2 * (theta_d**2 + sp.sin(theta)**2 * phi_d**2) / 2
    return Model(
        name=NAME, title="Spherical pendulum, azimuth momentum 0", source="textbook",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={x: "rad" for x in COORDINATES}, q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T + m * g * l * sp.cos(theta),
        cyclic={"phi": 0},
    )
