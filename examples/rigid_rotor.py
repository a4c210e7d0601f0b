"""Rigid rotor on two damped, anisotropic bearings: a model file, and the worked example of
docs/rotordynamics.md when run as a script.

A rigid rotor of mass m, polar moment Ip and transverse moment It (about an axis through its
centre of mass) spins at the rate Omega about its axis. Bearing 1 sits a distance a before the
centre of mass, bearing 2 a distance b behind it; each is a pair of springs and dampers
(kx, cx horizontal; ky, cy vertical), so the bearings are anisotropic. The rotor's attitude is
Rx(alpha) Ry(beta) Rz(phi): alpha and beta tilt the axis, phi is the spin angle, cyclic, with
the momentum Ip Omega (Routh-reduced: Omega is the spin rate at the reference exactly). Forces
Fx, Fy act at the centre of mass (inputs: an unbalance is one). No gravity: the bearings
centre the rotor.

    python -m derive --model examples/rigid_rotor.py --out DIR     # derive it
    gyro campbell examples/rigid_rotor.py --spin-range 0 1500 --harmonics 1 --json
    .venv/bin/python examples/rigid_rotor.py OUT_DIR               # the worked example

Closed form of the operator over (x, y, alpha, beta), to first order:
M = diag(m, m, It, It); K couples x with beta and y with alpha,
K = [[kx1 + kx2, 0, 0, b kx2 - a kx1], [0, ky1 + ky2, a ky1 - b ky2, 0],
     [0, a ky1 - b ky2, a^2 ky1 + b^2 ky2, 0], [b kx2 - a kx1, 0, 0, a^2 kx1 + b^2 kx2]],
D the same with the c's, plus the gyroscopic Ip Omega in D[alpha, beta] = -D[beta, alpha].
"""
from __future__ import annotations

import sympy as sp

from derive.model import Load, Model, Parameter, Signal

NAME = "rigid_rotor"
PARAMETERS = [
    Parameter("m", "kg", 30.0, "rotor mass"),
    Parameter("Ip", "kg m^2", 0.15, "polar moment of inertia"),
    Parameter("It", "kg m^2", 1.2, "transverse moment of inertia about the centre of mass"),
    Parameter("a", "m", 0.25, "bearing 1 before the centre of mass"),
    Parameter("b", "m", 0.35, "bearing 2 behind the centre of mass"),
    Parameter("kx1", "N/m", 1.0e6, "bearing 1 stiffness, horizontal"),
    Parameter("ky1", "N/m", 1.5e6, "bearing 1 stiffness, vertical"),
    Parameter("kx2", "N/m", 1.0e6, "bearing 2 stiffness, horizontal"),
    Parameter("ky2", "N/m", 1.5e6, "bearing 2 stiffness, vertical"),
    Parameter("cx1", "N s/m", 400.0, "bearing 1 damping, horizontal", kind="nonnegative"),
    Parameter("cy1", "N s/m", 400.0, "bearing 1 damping, vertical", kind="nonnegative"),
    Parameter("cx2", "N s/m", 400.0, "bearing 2 damping, horizontal", kind="nonnegative"),
    Parameter("cy2", "N s/m", 400.0, "bearing 2 damping, vertical", kind="nonnegative"),
    Parameter("Omega", "rad/s", 300.0, "spin rate", kind="nonnegative"),
]
m, Ip, It, a, b, kx1, ky1, kx2, ky2, cx1, cy1, cx2, cy2, Omega = (p.symbol for p in PARAMETERS)
COORDINATES = ["x", "y", "alpha", "beta", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([n + "_d" for n in COORDINATES])
qdd = sp.symbols([n + "_dd" for n in COORDINATES])
FX = Signal("Fx", "N", "horizontal force at the centre of mass", input=True, order=0)
FY = Signal("Fy", "N", "vertical force at the centre of mass", input=True, order=0)


def build() -> Model:
    x, y, al, be, ph = q
    x_d, y_d, al_d, be_d, ph_d = qd
    # body angular velocity of Rx(alpha) Ry(beta) Rz(phi), in body axes (1, 2 transverse, 3 polar)
    w1 = al_d * sp.cos(be) * sp.cos(ph) + be_d * sp.sin(ph)
    w2 = -al_d * sp.cos(be) * sp.sin(ph) + be_d * sp.cos(ph)
    w3 = ph_d + al_d * sp.sin(be)
    T = m / 2 * (x_d**2 + y_d**2) + It / 2 * sp.trigsimp(sp.expand(w1**2 + w2**2)) + Ip / 2 * w3**2
    V, F = 0, 0
    for z, kx, ky, cx, cy in ((-a, kx1, ky1, cx1, cy1), (b, kx2, ky2, cx2, cy2)):
        # the axis point at z: (x, y) + z (sin beta, -sin alpha cos beta)
        px, py = x + z * sp.sin(be), y - z * sp.sin(al) * sp.cos(be)
        vx = sum(sp.diff(px, c) * v for c, v in zip(q, qd))
        vy = sum(sp.diff(py, c) * v for c, v in zip(q, qd))
        V += (kx * px**2 + ky * py**2) / 2
        F += (cx * vx**2 + cy * vy**2) / 2
    return Model(
        name=NAME, title="Rigid rotor on two damped anisotropic bearings", source="examples/rigid_rotor.py",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={"x": "m", "y": "m", "alpha": "rad", "beta": "rad", "phi": "rad"},
        q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T - V,
        dissipation=F,
        loads=[Load(sp.Matrix([FX.symbol, FY.symbol]), sp.Matrix([x_d, y_d]), "force at the centre of mass")],
        signals=[FX, FY],
        cyclic={"phi": Ip * Omega},
        symmetric_zero=["x", "y", "alpha", "beta"],
        spin={"parameter": "Omega", "whirl": [("x", "y"), ("alpha", "beta")]},
    )
