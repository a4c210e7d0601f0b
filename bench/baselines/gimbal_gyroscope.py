"""Baseline: the heavy gyroscope in a gimbal (derive/models/gimbal_gyroscope.py) with
sympy.physics.mechanics, its linear operator about a steady precession.

Three bodies as a user writes them: the outer ring turning by psi about the vertical N.z
(moment C3 about it), the casing turning by theta about the ring's axis eta1 = R.x
(central inertia diag(B1, B2, B3) in its axes eta1 eta2 eta3, mass centre at
eta20 eta2 + eta30 eta3, weight P1), the rotor spinning by phi about eta3 (A1, A1, A3, mass
centre at l eta3, weight P); gravity as potential energy. LagrangesMethod -> Linearizer
about theta = theta0, psi' = psi0', phi' = phi0' (the rates given by the momenta L, H);
the cyclic psi and phi eliminated through their linearised first integrals (zero
perturbation of L and H), which is the Routh reduction the project's operator is made by.

The model's parameters are the sums A0 = C3 + B2 + A1, B0 = A1 + B1, C0 = B2 + A1 - B3
(kinetic energy of section 1); the point carries the bodies' moments, chosen so that these
sums are the model's defaults.
"""
from __future__ import annotations

import time

import numpy as np


def run(point: dict) -> dict:
    t0 = time.perf_counter()
    import sympy as sp
    import sympy.physics.mechanics as me

    from bench.baselines.common import eliminate_cyclic, linearized_mdk

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    C3, B1, B2, B3, A1, A3 = sp.symbols("C3 B1 B2 B3 A1 A3", positive=True)
    P1, P, eta20, eta30, l = sp.symbols("P1 P eta20 eta30 l")
    psi, theta, phi = q = me.dynamicsymbols("psi theta phi")
    t = me.dynamicsymbols._t
    qd = [x.diff(t) for x in q]
    qdd = [x.diff(t, 2) for x in q]

    N = me.ReferenceFrame("N")
    Rg = N.orientnew("Rg", "Axis", [psi, N.z])  # outer ring
    Cs = Rg.orientnew("Cs", "Axis", [theta, Rg.x])  # casing (inner ring)
    Rt = Cs.orientnew("Rt", "Axis", [phi, Cs.z])  # rotor
    O = me.Point("O")
    O.set_vel(N, 0)
    G1 = O.locatenew("G1", eta20 * Cs.y + eta30 * Cs.z)
    G2 = O.locatenew("G2", l * Cs.z)
    G1.v2pt_theory(O, N, Cs)
    G2.v2pt_theory(O, N, Rt)
    ring = me.RigidBody("ring", O, Rg, 0, (me.inertia(Rg, 0, 0, C3), O))
    # the model's moments are about the fixed point O (section 1): the bodies carry them with
    # zero mass, so that no translational energy of the centres is added; the weights P1, P
    # act at the mass centres through the potential energy
    casing = me.RigidBody("casing", G1, Cs, 0, (me.inertia(Cs, B1, B2, B3), G1))
    rotor = me.RigidBody("rotor", G2, Rt, 0, (me.inertia(Rt, A1, A1, A3), G2))
    casing.potential_energy = P1 * G1.pos_from(O).dot(N.z)
    rotor.potential_energy = P * G2.pos_from(O).dot(N.z)
    Lag = me.Lagrangian(N, ring, casing, rotor)
    LM = me.LagrangesMethod(Lag, q, frame=N)
    LM.form_lagranges_equations()
    lin = LM.to_linearizer(q_ind=q, qd_ind=qd)
    t_derive = time.perf_counter() - t1

    # the steady precession: psi0', phi0' from the momenta L = d Lag/d psi', H = d Lag/d phi'
    t2 = time.perf_counter()
    par = {C3: point["C3"], B1: point["B1"], B2: point["B2"], B3: point["B3"], A1: point["A1"],
           A3: point["A3"], P1: point["P1"], P: point["P"], eta20: point["eta20"], eta30: point["eta30"],
           l: point["l"]}
    q_op = {psi: 0.0, theta: point["theta"], phi: 0.0}
    mom = [sp.diff(Lag, qd[0]), sp.diff(Lag, qd[2])]
    rates = sp.symbols("r_psi r_phi")
    eqs = [me.msubs(e, {qd[0]: rates[0], qd[2]: rates[1], qd[1]: 0}, q_op, par) - v
           for e, v in zip(mom, (point["L"], point["H"]))]
    sol = sp.solve(eqs, rates, dict=True)[0]
    qd_op = {qd[0]: float(sol[rates[0]]), qd[1]: 0.0, qd[2]: float(sol[rates[1]])}
    M, D, K = linearized_mdk(lin, 3, [q_op, qd_op, {x: 0.0 for x in qdd}, par])
    Mr, Dr, Kr = eliminate_cyclic(M, D, K, cyclic=[0, 2], keep=[1])
    t_eval = time.perf_counter() - t2
    return {"import_s": t_import, "derive_s": t_derive, "evaluate_s": t_eval,
            "total_s": t_import + t_derive + t_eval,
            "values": {"M": Mr.tolist(), "D": Dr.tolist(), "K": Kr.tolist()}}


if __name__ == "__main__":
    from bench.baselines.common import main

    main(run)
