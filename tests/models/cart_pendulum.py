"""The pendulum on a cart of tests/models/cart_pendulum_mechanics.py in the machinery's own
symbols: the pendulum's kinetic energy by derive.mechanics.kinetic_energy with its full
inertia tensor (the product of inertia Ixy), the cart force an input Signal on a Load."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.model import Load, Model, Signal
from cart_pendulum_mechanics import PARAMETERS  # beside this file

FORCE = Signal("F", "N", "force on the cart", input=True, order=0)


def build() -> Model:
    M, m, l, Ixx, Iyy, Izz, Ixy, g = (p.symbol for p in PARAMETERS)
    x, th, x_d, th_d, x_dd, th_dd = sp.symbols("x theta x_d theta_d x_dd theta_dd")
    R = mech.rot("z", th)  # the pendulum's axes in the inertial ones
    r_G = sp.Matrix([x, 0, 0]) + R * sp.Matrix([0, -l, 0])
    v_G = mech.time_derivative(r_G, [x, th], [x_d, th_d])
    I_G = sp.Matrix([[Ixx, Ixy, 0], [Ixy, Iyy, 0], [0, 0, Izz]])  # in the pendulum's axes
    T = (mech.kinetic_energy(M, sp.Matrix([x_d, 0, 0]))
         + mech.kinetic_energy(m, v_G, omega=sp.Matrix([0, 0, th_d]), inertia=I_G))
    V = m * g * r_G[1]
    return Model(
        name="cart_pendulum", title="Pendulum on a cart", source="test", module=__name__,
        parameters=PARAMETERS, coordinates=["x", "theta"], coordinate_units={"x": "m", "theta": "rad"},
        q=[x, th], qd=[x_d, th_d], qdd=[x_dd, th_dd], lagrangian=sp.trigsimp(sp.expand(T - V)),
        loads=[Load(sp.Matrix([FORCE.symbol, 0, 0]), sp.Matrix([x_d, 0, 0]), "F on the cart")],
        signals=[FORCE])
