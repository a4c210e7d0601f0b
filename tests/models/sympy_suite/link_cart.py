"""sympy.physics.mechanics.models.n_link_pendulum_on_cart(2, cart_force=True,
joint_torques=True) as its user writes it for the Lagrangian route: a cart q0 with two point
masses on massless links (absolute angles q1, q2 from the upward vertical, the links along
B_i.y), speeds u_i with the kinematic equations q_i' - u_i = 0, gravity as forces on the
particles, a lateral force F(t) on the cart and joint torques T1(t), T2(t)."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, Particle, Point, ReferenceFrame, dynamicsymbols

from derive.model import Model, Parameter

N_LINKS = 2
PARAMETERS = ([Parameter(f"m{i}", "kg", 1.0 - 0.2 * i, f"mass {i}") for i in range(N_LINKS + 1)]
              + [Parameter(f"l{i}", "m", 0.5 - 0.1 * i, f"link {i} length") for i in range(N_LINKS)]
              + [Parameter("g", "m/s^2", 9.81, "gravity")])


def system():
    n = N_LINKS
    q = dynamicsymbols(f"q:{n + 1}")
    u = dynamicsymbols(f"u:{n + 1}")
    T = dynamicsymbols(f"T1:{n + 1}")
    m = sp.symbols(f"m:{n + 1}")
    l = sp.symbols(f"l:{n}")
    g, t = sp.symbols("g t")
    I = ReferenceFrame("I")
    O = Point("O")
    O.set_vel(I, 0)
    P0 = Point("P0")
    P0.set_pos(O, q[0] * I.x)
    P0.set_vel(I, u[0] * I.x)
    points, particles = [P0], [Particle("Pa0", P0, m[0])]
    forces = [(P0, -m[0] * g * I.y)]
    kindiffs = [q[0].diff(t) - u[0]]
    for i in range(n):
        Bi = I.orientnew(f"B{i}", "Axis", [q[i + 1], I.z])
        Bi.set_ang_vel(I, u[i + 1] * I.z)
        Pi = points[-1].locatenew(f"P{i + 1}", l[i] * Bi.y)
        Pi.v2pt_theory(points[-1], I, Bi)
        points.append(Pi)
        particles.append(Particle(f"Pa{i + 1}", Pi, m[i + 1]))
        forces.append((Pi, -m[i + 1] * g * I.y))
        if i == 0:
            forces.append((I, -T[i] * I.z))
        forces.append((Bi, T[i] * I.z - T[i + 1] * I.z) if i < n - 1 else (Bi, T[i] * I.z))
        kindiffs.append(q[i + 1].diff(t) - u[i + 1])
    F = dynamicsymbols("F")
    forces.append((P0, F * I.x))
    return Lagrangian(I, *particles), list(q), list(u), kindiffs, particles, forces, I


def reference():
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart

    return "kane", n_link_pendulum_on_cart(N_LINKS, cart_force=True, joint_torques=True)


def build() -> Model:
    L, q, u, kd, _, forces, I = system()
    names = [f"q{i}" for i in range(N_LINKS + 1)]
    return Model(name="link_cart", title="Two-link pendulum on a cart", source="sympy models.n_link_pendulum_on_cart",
                 module=__name__, parameters=PARAMETERS, coordinates=names,
                 coordinate_units={c: ("m" if c == "q0" else "rad") for c in names},
                 q=q, qd=u, qdd=[], lagrangian=L, loads=forces, frame=I, kinematics=kd)
