"""The rigid rotor of examples/rigid_rotor.py with a mass unbalance written into its
Lagrangian through explicit time: the spin angle is W t, W a parameter.

A point mass mu sits a distance e off the axis at the angle W t; its kinetic energy
mu/2 ((x' - e W sin W t)^2 + (y' + e W cos W t)^2) (tilt neglected for it) puts the force
mu e W^2 (cos W t, sin W t) on x and y: a forcing, not a change of the operator. The rest of
the rotor is the rigid rotor with phi = W t (the gyroscopic term from w3 = W + alpha' sin beta).
No equilibrium exists with this term in the equations (the rotor whirls at W), so the
derivation refuses the model and says how to write the unbalance as two force inputs, for
`gyro unbalance` (docs/models.md, docs/rotordynamics.md).
"""
from __future__ import annotations

import sympy as sp

from derive.model import TIME, Model, Parameter

NAME = "unbalanced_rotor_time"
PARAMETERS = [
    Parameter("m", "kg", 30.0, "rotor mass"),
    Parameter("Ip", "kg m^2", 0.15, "polar moment of inertia"),
    Parameter("It", "kg m^2", 1.2, "transverse moment of inertia about the centre of mass"),
    Parameter("a", "m", 0.25, "bearing 1 before the centre of mass"),
    Parameter("b", "m", 0.35, "bearing 2 behind the centre of mass"),
    Parameter("kx", "N/m", 1.0e6, "bearing stiffness, horizontal"),
    Parameter("ky", "N/m", 1.5e6, "bearing stiffness, vertical"),
    Parameter("c", "N s/m", 400.0, "bearing damping", kind="nonnegative"),
    Parameter("mu", "kg", 1.0e-3, "unbalance mass"),
    Parameter("e", "m", 0.1, "radius of the unbalance mass"),
    Parameter("W", "rad/s", 300.0, "spin rate", kind="nonnegative"),
]
m, Ip, It, a, b, kx, ky, c, mu, e, W = (p.symbol for p in PARAMETERS)
COORDINATES = ["x", "y", "alpha", "beta"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([n + "_d" for n in COORDINATES])
qdd = sp.symbols([n + "_dd" for n in COORDINATES])
SYMMETRIC = []  # tests set all four: the equilibrium on the symmetric set is then refused too


def build() -> Model:
    x, y, al, be = q
    x_d, y_d, al_d, be_d = qd
    ph = W * TIME
    w3 = W + al_d * sp.sin(be)
    T = m / 2 * (x_d**2 + y_d**2) + It / 2 * (al_d**2 * sp.cos(be)**2 + be_d**2) + Ip / 2 * w3**2
    ux, uy = x + e * sp.cos(ph), y + e * sp.sin(ph)  # the unbalance mass, tilt neglected
    T += mu / 2 * ((x_d + sp.diff(ux, TIME))**2 + (y_d + sp.diff(uy, TIME))**2)
    V, F = 0, 0
    for z in (-a, b):
        px, py = x + z * sp.sin(be), y - z * sp.sin(al) * sp.cos(be)
        vx = sum(sp.diff(px, s) * v for s, v in zip(q, qd))
        vy = sum(sp.diff(py, s) * v for s, v in zip(q, qd))
        V += (kx * px**2 + ky * py**2) / 2
        F += c * (vx**2 + vy**2) / 2
    return Model(
        name=NAME, title="Rigid rotor with a mass unbalance in explicit time", source="tests",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={"x": "m", "y": "m", "alpha": "rad", "beta": "rad"},
        q=list(q), qd=list(qd), qdd=list(qdd), lagrangian=T - V, dissipation=F,
        symmetric_zero=list(SYMMETRIC),
    )
