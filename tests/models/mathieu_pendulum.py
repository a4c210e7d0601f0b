"""Pendulum on a vertically vibrating support: the Mathieu pendulum.

The bob (mass m, rod length l, angle theta from the downward vertical) hangs from a support
at height z = a sin(w t), given in closed form of the explicit time t; gravity -g along z,
viscous damping c theta'^2/2 at the pivot. Position (l sin theta, a sin(w t) - l cos theta).

Textbook answer (the Mathieu form): m l^2 theta'' + c theta' + m l (g - a w^2 sin(w t))
sin(theta) = 0; about theta = 0 the operator is M = m l^2, D = c, K(t) = m l (g - a w^2
sin(w t)). The support's acceleration -a w^2 sin(w t) comes from the explicit time
derivative of dL/dtheta': a machinery without it loses the term m l a w^2 sin(w t) sin(theta).
"""
from __future__ import annotations

import sympy as sp

from derive.model import TIME, Model, Parameter

NAME = "mathieu_pendulum"
PARAMETERS = [
    Parameter("m", "kg", 0.5, "mass of the bob"),
    Parameter("l", "m", 0.8, "length of the rod"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
    Parameter("a", "m", 0.05, "amplitude of the support's motion", kind="nonnegative"),
    Parameter("w", "rad/s", 7.0, "circular frequency of the support's motion"),
    Parameter("c", "N m s", 0.01, "viscous damping at the pivot", kind="nonnegative"),
]
m, l, g, a, w, c = (p.symbol for p in PARAMETERS)
theta, theta_d, theta_dd = sp.symbols("theta theta_d theta_dd")
t = TIME


def build() -> Model:
    z = a * sp.sin(w * t)  # support height
    pos = sp.Matrix([l * sp.sin(theta), z - l * sp.cos(theta)])
    vel = pos.diff(theta) * theta_d + pos.diff(t)
    T = m * (vel.T * vel)[0] / 2
    V = m * g * pos[1]
    return Model(
        name=NAME, title="Pendulum on a vertically vibrating support", source="textbook",
        module=__name__, parameters=PARAMETERS, coordinates=["theta"],
        coordinate_units={"theta": "rad"}, q=[theta], qd=[theta_d], qdd=[theta_dd],
        lagrangian=T - V,
        dissipation=c * theta_d**2 / 2,
        symmetric_zero=["theta"],
    )
