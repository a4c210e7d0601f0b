"""A pendulum on a cart, written as a sympy.physics.mechanics user writes it: coordinates
as dynamicsymbols, parameters as symbols with assumptions, the bodies as a Particle and a
RigidBody (with a product of inertia) in ReferenceFrames, the Lagrangian from
sympy.physics.mechanics.Lagrangian, the cart force F(t) as a dynamicsymbol on a Point.
tests/models/cart_pendulum.py is the same system in the machinery's own symbols."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Particle, Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

from derive.model import Model, Parameter

PARAMETERS = [
    Parameter("M", "kg", 2.0, "cart mass"),
    Parameter("m", "kg", 0.5, "pendulum mass"),
    Parameter("l", "m", 0.4, "pivot to the pendulum's mass centre"),
    Parameter("Ixx", "kg m^2", 0.01, "pendulum inertia about its mass centre, axis x"),
    Parameter("Iyy", "kg m^2", 0.002, "pendulum inertia about its mass centre, axis y"),
    Parameter("Izz", "kg m^2", 0.012, "pendulum inertia about its mass centre, axis z"),
    Parameter("Ixy", "kg m^2", 0.001, "product of inertia xy", kind="real"),
    Parameter("g", "m/s^2", 9.81, "gravity"),
]


def system():
    """(Lagrangian, coordinates, loads, inertial frame) as sympy.physics.mechanics has them."""
    x, th = dynamicsymbols("x theta")
    F = dynamicsymbols("F")
    M, m, l, g = sp.symbols("M m l g", positive=True)
    Ixx, Iyy, Izz = sp.symbols("Ixx Iyy Izz", positive=True)
    Ixy = sp.symbols("Ixy", real=True)
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [th, N.z])
    O = Point("O")
    O.set_vel(N, 0)
    C = O.locatenew("C", x * N.x)  # the cart
    C.set_vel(N, x.diff() * N.x)
    G = C.locatenew("G", -l * A.y)  # the pendulum's mass centre
    G.v2pt_theory(C, N, A)
    cart = Particle("cart", C, M)
    pend = RigidBody("pend", G, A, m, (inertia(A, Ixx, Iyy, Izz, Ixy, 0, 0), G))
    pend.potential_energy = m * g * G.pos_from(O).dot(N.y)
    return Lagrangian(N, cart, pend), [x, th], [(C, F * N.x)], N


def build() -> Model:
    L, q, loads, N = system()
    return Model(
        name="cart_pendulum_mechanics", title="Pendulum on a cart (sympy.physics.mechanics style)",
        source="test", module=__name__, parameters=PARAMETERS,
        coordinates=["x", "theta"], coordinate_units={"x": "m", "theta": "rad"},
        q=q, qd=[], qdd=[], lagrangian=L, loads=loads, frame=N)
