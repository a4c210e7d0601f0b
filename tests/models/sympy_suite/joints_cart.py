"""A cart on a PrismaticJoint with a pendulum on a PinJoint, as sympy.physics.mechanics'
System and joints examples write it: a LinearSpring and a LinearDamper on a LinearPathway
between the wall and the cart, a TorqueActuator T(t) between the cart and the pendulum,
gravity by System.apply_uniform_gravity; the joints' coordinates and speeds (q_J, u_J) with
the joints' kinematic equations, the Lagrangian of the bodies."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import (Lagrangian, LinearDamper, LinearPathway, LinearSpring, PinJoint, Point,
                                     PrismaticJoint, ReferenceFrame, RigidBody, System, TorqueActuator,
                                     dynamicsymbols, inertia)

from derive.model import Model, Parameter

PARAMETERS = [Parameter("mc", "kg", 2.0, "cart mass"), Parameter("mp", "kg", 0.5, "pendulum mass"),
              Parameter("l", "m", 0.4, "pivot to the pendulum's mass centre"),
              Parameter("Ip", "kg m^2", 0.01, "pendulum inertia about its mass centre"),
              Parameter("k", "N/m", 40.0, "spring"), Parameter("x0", "m", 0.2, "spring's free length"),
              Parameter("c", "N s/m", 0.8, "damper", kind="nonnegative"),
              Parameter("g", "m/s^2", 9.81, "gravity")]


def system():
    mc, mp, l, Ip, k, x0, c, g = sp.symbols("mc mp l Ip k x0 c g", positive=True)
    q1, q2, u1, u2 = dynamicsymbols("q1 q2 u1 u2")
    T = dynamicsymbols("T")
    ground = RigidBody("ground")
    N, O = ground.frame, ground.masscenter
    cart = RigidBody("cart", mass=mc)
    pend = RigidBody("pend", mass=mp)
    pend.inertia = (inertia(pend.frame, 0, 0, Ip), pend.masscenter)
    slider = PrismaticJoint("slider", ground, cart, coordinates=q1, speeds=u1, joint_axis=N.x)
    pin = PinJoint("pin", cart, pend, coordinates=q2, speeds=u2, joint_axis=cart.frame.z,
                   child_point=l * pend.frame.y)
    sys_ = System.from_newtonian(ground)
    sys_.add_joints(slider, pin)
    path = LinearPathway(O, cart.masscenter)
    sys_.add_actuators(LinearSpring(k, path, x0), LinearDamper(c, path),
                       TorqueActuator(T, cart.frame.z, pend, cart))
    sys_.apply_uniform_gravity(-g * N.y)
    return sys_, Lagrangian(N, cart, pend)


def reference():
    s, _ = system()
    s.form_eoms()
    return "kane", s.eom_method


def build() -> Model:
    s, L = system()
    loads = list(s.loads) + [ld for a in s.actuators for ld in a.to_loads()]
    return Model(name="joints_cart", title="Pendulum on a cart, from joints and actuators", source="sympy joints/System",
                 module=__name__, parameters=PARAMETERS, coordinates=["q1", "q2"],
                 coordinate_units={"q1": "m", "q2": "rad"}, q=list(s.q), qd=list(s.u), qdd=[], lagrangian=L,
                 loads=loads, frame=s.frame, kinematics=list(s.kdes))
