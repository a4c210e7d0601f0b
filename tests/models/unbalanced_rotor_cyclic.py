"""The rigid rotor of examples/rigid_rotor.py with a mass unbalance written into its
Lagrangian through the cyclic spin angle phi.

A point mass mu a distance e off the axis at the angle phi (tilt neglected for it) adds
mu/2 ((x' - e phi' sin phi)^2 + (y' + e phi' cos phi)^2) to the kinetic energy: phi is then
no longer ignorable, and the Routh reduction of phi is refused. The refusal is right (the
momentum of phi is not conserved) and its message says how to write the unbalance instead:
two force inputs and `gyro unbalance`.
"""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "unbalanced_rotor_cyclic"
PARAMETERS = [
    Parameter("m", "kg", 30.0, "rotor mass"),
    Parameter("Ip", "kg m^2", 0.15, "polar moment of inertia"),
    Parameter("It", "kg m^2", 1.2, "transverse moment of inertia about the centre of mass"),
    Parameter("k", "N/m", 1.0e6, "bearing stiffness"),
    Parameter("mu", "kg", 1.0e-3, "unbalance mass"),
    Parameter("e", "m", 0.1, "radius of the unbalance mass"),
    Parameter("Omega", "rad/s", 300.0, "spin rate", kind="nonnegative"),
]
m, Ip, It, k, mu, e, Omega = (p.symbol for p in PARAMETERS)
COORDINATES = ["x", "y", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([n + "_d" for n in COORDINATES])
qdd = sp.symbols([n + "_dd" for n in COORDINATES])


def build() -> Model:
    x, y, ph = q
    x_d, y_d, ph_d = qd
    T = m / 2 * (x_d**2 + y_d**2) + Ip / 2 * ph_d**2
    T += mu / 2 * ((x_d - e * ph_d * sp.sin(ph))**2 + (y_d + e * ph_d * sp.cos(ph))**2)
    V = k * (x**2 + y**2) / 2
    return Model(
        name=NAME, title="Rotor with a mass unbalance through the cyclic spin angle", source="tests",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={"x": "m", "y": "m", "phi": "rad"},
        q=list(q), qd=list(qd), qdd=list(qdd), lagrangian=T - V,
        cyclic={"phi": Ip * Omega}, symmetric_zero=["x", "y"],
    )
