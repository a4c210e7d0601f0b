"""Damped pendulum on a vertically oscillating support, with a torque at the pivot.

The worked example of docs/models.md. A point mass m on a massless rod of length l hangs
from a pivot that moves vertically as y_s(t) = a sin(w t); theta is the rod's angle from
the downward vertical. Viscous damping c acts at the pivot (a Rayleigh function), and a
torque tau(t) is applied there (an input signal).
"""
from __future__ import annotations

import sympy as sp

from derive.model import TIME, Load, Model, Parameter, Signal

PARAMETERS = [
    Parameter("m", "kg", 1.0, "bob mass"),
    Parameter("l", "m", 0.5, "rod length"),
    Parameter("c", "N m s/rad", 0.05, "viscous damping at the pivot", kind="nonnegative"),
    Parameter("g", "m/s^2", 9.81, "gravity", kind="nonnegative"),
    Parameter("a", "m", 0.01, "amplitude of the support's vertical motion", kind="real"),
    Parameter("w", "rad/s", 30.0, "angular frequency of the support's motion", kind="nonnegative"),
]
m, l, c, g, a, w = (p.symbol for p in PARAMETERS)
t = TIME

theta, theta_d, theta_dd = sp.symbols("theta theta_d theta_dd")
TAU = Signal("tau", "N m", "torque applied at the pivot", input=True, order=0)
tau = TAU.symbol


def build() -> Model:
    y_s = a * sp.sin(w * t)  # the support's height: explicit time
    x = l * sp.sin(theta)  # the bob
    y = y_s - l * sp.cos(theta)
    # velocities by the chain rule: d/dt = partial in t + theta_d * partial in theta
    vx = sp.diff(x, t) + theta_d * sp.diff(x, theta)
    vy = sp.diff(y, t) + theta_d * sp.diff(y, theta)
    T = m / 2 * sp.trigsimp(sp.expand(vx**2 + vy**2))
    V = m * g * y
    return Model(
        name="damped_pendulum",
        title="Damped pendulum on a vertically oscillating support",
        source="docs/models.md (worked example)",
        module=__name__,
        parameters=PARAMETERS,
        coordinates=["theta"],
        coordinate_units={"theta": "rad"},
        q=[theta], qd=[theta_d], qdd=[theta_dd],
        lagrangian=T - V,
        dissipation=c * theta_d**2 / 2,  # Rayleigh: Q = -dF/dtheta_d = -c theta_d
        # the torque as a moment (0, 0, tau) on the rod, whose angular velocity is
        # (0, 0, theta_d): Q = tau by virtual power
        loads=[Load(sp.Matrix([0, 0, tau]), sp.Matrix([0, 0, theta_d]), name="pivot torque")],
        signals=[TAU],
    )
