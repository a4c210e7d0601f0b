"""A Jeffcott rotor on anisotropic damped bearings whose races are wavy: the forces the
waviness exerts on the disc are functions f1(phi), f2(phi) of the spin angle phi, along x
and y. Written outside the package, it declares its spin angle (`spin` "angle": phi, cyclic
with the momentum Ip Omega), so that `gyro forced` drives it at multiples k Omega of the
spin: by hand, m x'' + c x' + kx x = a sin(k Omega t + p) has the steady response
x = a/|kx - m w^2 + i c w| sin(w t + p - atan2(c w, kx - m w^2)), w = k Omega, y at rest
(tests/cli/test_forced_generic.py)."""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter

NAME = "wavy_rotor"
PARAMETERS = [
    Parameter("m", "kg", 12.0, "disc mass"),
    Parameter("Ip", "kg m^2", 0.08, "polar moment of inertia"),
    Parameter("kx", "N/m", 2.0e6, "bearing stiffness along x"),
    Parameter("ky", "N/m", 3.0e6, "bearing stiffness along y"),
    Parameter("c", "N s/m", 150.0, "bearing damping along x and y", kind="nonnegative"),
    Parameter("Omega", "rad/s", 200.0, "spin rate", kind="nonnegative"),
]
m, Ip, kx, ky, c, Omega = (p.symbol for p in PARAMETERS)
COORDINATES = ["x", "y", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([n + "_d" for n in COORDINATES])
qdd = sp.symbols([n + "_dd" for n in COORDINATES])
f1, f2 = sp.Function("f1"), sp.Function("f2")


def build() -> Model:
    x, y, ph = q
    x_d, y_d, ph_d = qd
    T = m / 2 * (x_d**2 + y_d**2) + Ip / 2 * ph_d**2
    V = (kx * x**2 + ky * y**2) / 2
    U = x * f1(ph) + y * f2(ph)  # the races' forces, along x and y
    return Model(
        name=NAME, title="Jeffcott rotor on wavy bearing races", source="tests",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={"x": "m", "y": "m", "phi": "rad"},
        q=list(q), qd=list(qd), qdd=list(qdd), lagrangian=T - V + U,
        given_functions=[f1(ph), f2(ph)], given_values=list(sp.symbols("F1 F2")),
        given_derivatives=list(sp.symbols("dF1 dF2")),
        dissipation=c * (x_d**2 + y_d**2) / 2,
        cyclic={"phi": Ip * Omega}, symmetric_zero=["x", "y"],
        spin={"parameter": "Omega", "rate": Ip * Omega / Ip, "angle": "phi", "harmonics": ("race waviness", "N")},
    )
