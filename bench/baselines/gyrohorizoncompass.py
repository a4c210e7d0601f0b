"""Baseline: the gyrohorizoncompass (derive/models/gyrohorizoncompass.py) with
sympy.physics.mechanics, its linearised operator about the relative equilibrium (3.1).

As a user writes it: an inertial frame Ni; the Darboux trihedron D (a1, a2, a3) turning at
zeta a2 + eta a3 in Ni; the gyrosphere E = D rotated by Rz(alpha) Rx(beta) Ry(gamma)
(1.1), a rigid body with inertia diag(A, B, C) about the suspension point O (the point's
motion over the sphere enters through the force function, as in the paper); the two
casings turned by +epsilon and -epsilon about e3, each with moment J about its axis, the
rotors' momenta L along the casings' spin axes (H = 2 L cos(epsilon) e2), so that the
Lagrangian carries H . omega (the rotors' cyclic spins reduced, as the model does); the
force function (1.4) of gravity, transport acceleration and gravity gradient from the
frames' direction cosines; the sensor's moment N(epsilon) (2.1) as a torque on the casing
with its reaction on the gyrosphere. LagrangesMethod -> Linearizer about alpha = beta =
gamma = 0, epsilon = epsilon0, at rest.
"""
from __future__ import annotations

import time


def run(point: dict) -> dict:
    t0 = time.perf_counter()
    import sympy as sp
    import sympy.physics.mechanics as me

    from bench.baselines.common import linearized_mdk

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    A, B, C, J, L, I, nu, zeta, eta, lam = sp.symbols("A B C J L I nu zeta eta lam")
    alpha, beta, gamma, epsilon = q = me.dynamicsymbols("alpha beta gamma epsilon")
    t = me.dynamicsymbols._t
    qd = [x.diff(t) for x in q]
    qdd = [x.diff(t, 2) for x in q]

    Ni = me.ReferenceFrame("Ni")
    D = me.ReferenceFrame("D")
    D.set_ang_vel(Ni, zeta * D.y + eta * D.z)
    E = D.orientnew("E", "Body", [alpha, beta, gamma], "ZXY")
    Cp = E.orientnew("Cp", "Axis", [epsilon, E.z])  # casing turned by +epsilon
    Cm = E.orientnew("Cm", "Axis", [-epsilon, E.z])  # casing turned by -epsilon
    O = me.Point("O")
    O.set_vel(Ni, 0)
    sphere = me.RigidBody("gyrosphere", O, E, 0, (me.inertia(E, A, B, C), O))
    omega = E.ang_vel_in(Ni)
    # each rotor's momentum L along its casing's y axis: H = 2 L cos(epsilon) e2 (the
    # components along e1 cancel); the casings' own turns J epsilon'^2 / 2 each
    H = L * Cp.y + L * Cm.y
    gyros = H.dot(omega) + 2 * J * epsilon.diff(t)**2 / 2
    Lam = me.inertia(E, A, B, C)
    a2, a3 = D.y, D.z
    U = (I * (nu**2 - zeta**2) * a3.dot(E.z) + I * zeta * eta * a2.dot(E.z)
         - sp.Rational(3, 2) * nu**2 * a3.dot(Lam.dot(a3)))
    Lag = me.Lagrangian(Ni, sphere) + gyros + U
    Nmom = 2 * L**2 * sp.sin(2 * epsilon) / (I * lam)
    forces = [(Cp, Nmom * E.z), (E, -Nmom * E.z)]
    # D turns in Ni by its rate only (no orientation path): the partial angular velocities
    # of the torques are taken in D, which is exact (they are derivatives in the speeds)
    LM = me.LagrangesMethod(Lag, q, forcelist=forces, frame=D)
    LM.form_lagranges_equations()
    lin = LM.to_linearizer(q_ind=q, qd_ind=qd)
    t_derive = time.perf_counter() - t1

    t2 = time.perf_counter()
    par = {s: point[str(s)] for s in (A, B, C, J, L, I, nu, zeta, eta, lam)}
    q_op = {alpha: 0.0, beta: 0.0, gamma: 0.0, epsilon: point["epsilon0"]}
    M, Dm, K = linearized_mdk(lin, 4, [q_op, {x: 0.0 for x in qd}, {x: 0.0 for x in qdd}, par])
    t_eval = time.perf_counter() - t2
    return {"import_s": t_import, "derive_s": t_derive, "evaluate_s": t_eval,
            "total_s": t_import + t_derive + t_eval,
            "values": {"M": M.tolist(), "D": Dm.tolist(), "K": K.tolist()}}


if __name__ == "__main__":
    from bench.baselines.common import main

    main(run)
