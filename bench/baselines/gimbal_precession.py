"""Baseline: the gyroscope in a gimbal on a rotating base (derive/models/gimbal_precession.py)
with sympy.physics.mechanics, the `full` level's equations of motion: mass matrix and
forcing of the three bodies.

As a user writes it: an inertial frame Ni; the base Bs turning at u = u_xi xi + u_eta eta +
u_zeta zeta (constant components in its own axes); the outer ring Rg = Bs rotated by alpha
about xi (moments C3 about its axis xi1, C1 about eta1, C2 about zeta1); the
casing Cs = Rg rotated by beta about eta1 = y' (diag(B2, B1, B3) in x' y' z'); the rotor
Rt = Cs rotated by phi about z' (A1, A1, A3); all about the fixed centre O. Torques, each
acting on a body with its reaction on the neighbouring one where the model has it:
friction -f_alpha alpha' on the ring (from the base), -f_beta beta' between ring and casing,
M_motor - f_phi phi' between casing and rotor; the ring's imbalance k_xi1 cos(alpha) about
xi1; l on the casing and m on the rotor, constant in the casing axes. LagrangesMethod
gives mass_matrix * q'' = forcing, evaluated at the given state.
"""
from __future__ import annotations

import time


def run(point: dict) -> dict:
    t0 = time.perf_counter()
    import numpy as np
    import sympy as sp
    import sympy.physics.mechanics as me

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    names = ("u_xi u_eta u_zeta f_alpha f_beta f_phi Mmotor k_xi1 l_x l_y l_z m_x m_y m_z "
             "C3 C1 C2 B1 B2 B3 A1 A3")
    syms = sp.symbols(names)
    (u_xi, u_eta, u_zeta, f_alpha, f_beta, f_phi, Mmotor, k_xi1, l_x, l_y, l_z, m_x, m_y, m_z,
     C3, C1, C2, B1, B2, B3, A1, A3) = syms
    alpha, beta, phi = q = me.dynamicsymbols("alpha beta phi")
    t = me.dynamicsymbols._t
    qd = [x.diff(t) for x in q]

    Ni = me.ReferenceFrame("Ni")
    Bs = me.ReferenceFrame("Bs")
    Bs.set_ang_vel(Ni, u_xi * Bs.x + u_eta * Bs.y + u_zeta * Bs.z)
    Rg = Bs.orientnew("Rg", "Axis", [alpha, Bs.x])
    Cs = Rg.orientnew("Cs", "Axis", [beta, Rg.y])
    Rt = Cs.orientnew("Rt", "Axis", [phi, Cs.z])
    O = me.Point("O")
    O.set_vel(Ni, 0)
    ring = me.RigidBody("ring", O, Rg, 0, (me.inertia(Rg, C3, C1, C2), O))
    casing = me.RigidBody("casing", O, Cs, 0, (me.inertia(Cs, B2, B1, B3), O))
    rotor = me.RigidBody("rotor", O, Rt, 0, (me.inertia(Rt, A1, A1, A3), O))
    Lag = me.Lagrangian(Ni, ring, casing, rotor)
    spin = Mmotor - f_phi * qd[2]
    forces = [
        (Rg, (-f_alpha * qd[0] + k_xi1 * sp.cos(alpha)) * Rg.x),
        (Cs, -f_beta * qd[1] * Cs.y), (Rg, f_beta * qd[1] * Cs.y),
        (Rt, spin * Cs.z), (Cs, -spin * Cs.z),
        (Cs, l_x * Cs.x + l_y * Cs.y + l_z * Cs.z),
        (Rt, m_x * Cs.x + m_y * Cs.y + m_z * Cs.z),
    ]
    # Bs turns in Ni by its rate only: the torques' partial angular velocities are taken
    # in Bs (derivatives in the speeds, the same in any frame)
    LM = me.LagrangesMethod(Lag, q, forcelist=forces, frame=Bs)
    LM.form_lagranges_equations()
    mass, forcing = LM.mass_matrix, LM.forcing
    t_derive = time.perf_counter() - t1

    t2 = time.perf_counter()
    par = {s: point[str(s)] for s in syms}
    state = dict(zip(q, point["q"])) | dict(zip(qd, point["qd"]))
    Mn = np.array(me.msubs(mass, state, par).tolist(), dtype=float)
    fn = np.array(me.msubs(forcing, state, par).tolist(), dtype=float).ravel()
    t_eval = time.perf_counter() - t2
    return {"import_s": t_import, "derive_s": t_derive, "evaluate_s": t_eval,
            "total_s": t_import + t_derive + t_eval,
            "values": {"mass_matrix": Mn.tolist(), "forcing": fn.tolist()}}


if __name__ == "__main__":
    from bench.baselines.common import main

    main(run)
