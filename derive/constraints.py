"""Holonomic constraints phi(q, t) = 0 (the model's `holonomic` field).

Where the constraints are linear in some of the coordinates (a rolling disc's
y - R theta = 0: theta = y/R), they are solved for those by one linear solve and eliminated
symbolically: the
dependent coordinates and their rates are substituted into the Lagrangian, the
dissipation and the loads, a generalised force on a dependent coordinate is carried to
the independent ones by virtual work (Q_i += Q_dep d q_dep / d q_i), and the model goes
on in its independent coordinates. The values of the dependent coordinates and their
rates are emitted as the quantity `dependent_coordinates`.

Otherwise (a pendulum in Cartesian coordinates, x^2 + y^2 - L^2 = 0: two branches) the
equations carry Lagrange multipliers lambda, in sympy's convention

    Mq qdd + Phi_q' lambda = f,    Phi_q qdd = -gamma   (gamma = phi'' at qdd = 0),

emitted as one mass-matrix system of n + m unknowns (qdd, lambda): `mass_matrix` is
[[Mq, Phi_q'], [Phi_q, 0]] and `forcing` [f; -gamma]. The constraint forces on the
coordinates, -Phi_q' lambda, are the quantity `constraint_forces`, the constraints and
their Jacobian the quantity `constraints`. The linearisation about rest at q0 (qe, all
coordinates, on the constraint) is that of the constrained system in its independent
coordinates (`reduced`, default the first n - m), as sympy's linearize gives it:
dq = C dq_ind with C = [I; -Phi_dep^-1 Phi_ind], lambda0 from the dependent rows at rest
(Phi_dep' lambda0 = f_dep), and

    M = C' Mq C,  D = C' (dE/dqd) C,  K = C' (dE/dq + sum_j lambda0_j d2 phi_j/dq2) C,
    B = C' B_q,

E = Mq qdd - f. What is refused: constraints on rates (nonholonomic), explicit time or
signals in a constraint that must be carried by multipliers, cyclic or steady
coordinates, given functions or variants together with multipliers.
"""
from __future__ import annotations

import dataclasses
from itertools import combinations
from types import SimpleNamespace

import sympy as sp

from derive import mechanics as mech
from derive.model import TIME, Load, Model, Unsupported


def _constraints(model: Model) -> list:
    phis = [sp.sympify(c) for c in model.holonomic]
    rates = set(model.qd) | set(model.qdd)
    for k, c in enumerate(phis):
        if c.free_symbols & rates:
            raise Unsupported(f"{model.name}: holonomic constraint {k + 1} ({c}) has rates: a constraint on "
                              "velocities is nonholonomic (give a holonomic one as phi(q, t))")
        if not c.free_symbols & set(model.q):
            raise Unsupported(f"{model.name}: holonomic constraint {k + 1} ({c}) has no coordinate")
    if len(phis) >= len(model.q):
        raise Unsupported(f"{model.name}: {len(phis)} holonomic constraints on {len(model.q)} coordinates "
                          "leave no independent coordinate")
    return phis


def _tidy(e):
    """A solution entry in its simplest form: cancel, exact and cheap, for a rational
    function of its symbols (y/R: 1 ms against simplify's 17 ms); simplify otherwise."""
    return sp.cancel(e) if e.is_rational_function() else sp.simplify(e)


def solve_dependent(model: Model):
    """(indices of the dependent coordinates, their solution) where the constraints are
    linear in some m coordinates with a Jacobian free of them and not identically singular
    (the last ones tried first): one solution, by one linear solve, in bounded time. Else
    None, and the constraints are carried by multipliers: a general nonlinear solve has no
    bound on its work (a four-bar linkage's loop closure kept sympy.solve busy for over
    900 s) and mostly several branches (x^2 + y^2 = L^2), which elimination cannot take."""
    phis = _constraints(model)
    q, m = list(model.q), len(phis)
    Phi = sp.Matrix(phis)
    for deps in combinations(reversed(range(len(q))), m):
        dq = [q[i] for i in sorted(deps)]
        J = Phi.jacobian(dq)
        if J.has(*dq) or sp.expand(J.det()) == 0:
            continue
        rest = Phi.xreplace({x: 0 for x in dq})
        sol = (-J.LUsolve(rest)).applyfunc(_tidy)
        return sorted(deps), dict(zip(dq, sol))
    return None


def eliminate(model: Model, deps: list, sol: dict) -> tuple[Model, dict]:
    """The model in its independent coordinates, and what was eliminated (for metadata)."""
    keep = [i for i in range(len(model.q)) if i not in deps]
    names = [model.coordinates[i] for i in deps]
    for field_name in ("cyclic", "steady"):
        bad = sorted(set(getattr(model, field_name)) & set(names))
        if bad:
            raise Unsupported(f"{model.name}: {bad} ({field_name}) is eliminated by a holonomic constraint")
    q = [model.q[i] for i in keep]
    qd = [model.qd[i] for i in keep]
    rates = {model.qd[i]: mech.time_derivative(sol[model.q[i]], q, qd, signals=model.signals) for i in deps}
    sub = {**sol, **rates}
    s = lambda e: sp.sympify(e).subs(sub)  # noqa: E731
    forces = {c: s(v) for c, v in model.generalized_forces.items() if c not in names}
    for c, Qc in model.generalized_forces.items():
        if c in names:  # virtual work: dq_dep = sum_i d g / d q_i dq_i
            g = sol[model.coordinate(c)]
            for i in keep:
                carried = sp.diff(g, model.q[i])
                if carried != 0:
                    cn = model.coordinates[i]
                    forces[cn] = forces.get(cn, 0) + s(Qc) * carried
    dep_q = sp.Matrix([sol[model.q[i]] for i in deps])
    dep_qd = sp.Matrix([rates[model.qd[i]] for i in deps])
    groups = ["params", "q", "qd"] + (["time"] if TIME in (dep_q.free_symbols | dep_qd.free_symbols) else []) + (
        ["signals"] if model.signals else [])
    quantities = dict(model.quantities)
    quantities["dependent_coordinates"] = (
        groups, [("q_dep", dep_q), ("qd_dep", dep_qd)],
        f"Values and rates of the coordinates ({', '.join(names)}) eliminated by the holonomic constraints.")
    reduced = [c for c in model.reduced if c not in names]
    out = dataclasses.replace(
        model, coordinates=[model.coordinates[i] for i in keep],
        coordinate_units={c: u for c, u in model.coordinate_units.items() if c not in names},
        q=q, qd=qd, qdd=[model.qdd[i] for i in keep], lagrangian=s(model.lagrangian),
        dissipation=s(model.dissipation),
        loads=[Load(sp.Matrix(ld.vector).applyfunc(s), sp.Matrix(ld.velocity).applyfunc(s), ld.name)
               for ld in model.loads],
        generalized_forces=forces, symmetric_zero=[c for c in model.symmetric_zero if c not in names],
        reduced=reduced, holonomic=[], quantities=quantities)
    info = {"holonomic": [str(c) for c in model.holonomic],
            "eliminated": {c: str(sol[model.coordinate(c)]) for c in names}}
    return out, info


def multipliers(model: Model) -> tuple[Model, SimpleNamespace, dict]:
    """The multipliers route chosen (derive/passes/constraints.py): what it refuses, and
    (the model with the quantities `constraints` and `constraint_forces`, what the equation,
    reference, operator and input passes take of the constraints, the metadata)."""
    phis = _constraints(model)
    m, n = len(phis), len(model.q)
    for what, present in (("cyclic coordinates", model.cyclic), ("steady motions", model.steady),
                          ("given functions", model.given_functions), ("variants", model.variants)):
        if present:
            raise Unsupported(f"{model.name}: {what} together with holonomic constraints that need multipliers")
    explicit = {TIME} | set(model.signal_symbols)
    if any(c.free_symbols & explicit for c in phis):
        raise Unsupported(f"{model.name}: a holonomic constraint with explicit time that cannot be solved for "
                          "dependent coordinates (multipliers at a moving constraint are not derived)")
    order = model.reduced or [c for c in model.coordinates][: n - m]
    if len(order) != n - m or not set(order) <= set(model.coordinates):
        raise Unsupported(f"{model.name}: `reduced` names the {n - m} independent coordinates of a system "
                          f"with {m} constraints on {n}")
    ind = [model.coordinates.index(c) for c in order]
    dep = [i for i in range(n) if i not in ind]
    Phi = sp.Matrix(phis)
    Pq = Phi.jacobian(list(model.q))
    lam = sp.symbols(f"lam1:{m + 1}")
    quantities = dict(model.quantities)
    quantities["constraints"] = (["params", "q"], [("phi", Phi), ("Phi_q", Pq)],
                                 "The holonomic constraints phi(q) (zero on a motion) and their Jacobian.")
    quantities["constraint_forces"] = (
        ["params", "q", ("multipliers", list(lam))], [("Qc", -Pq.T * sp.Matrix(lam))],
        "Constraint forces on the coordinates, -Phi_q' lambda, with lambda the last m unknowns of "
        "mass_matrix [qdd; lambda] = forcing.")
    held = SimpleNamespace(phis=phis, Pq=Pq, lam=list(lam), order=order, ind=ind, dep=dep)
    info = {"holonomic": [str(c) for c in phis], "multipliers": [str(x) for x in lam],
            "independent": order, "dependent": [model.coordinates[i] for i in dep]}
    return dataclasses.replace(model, quantities=quantities), held, info


def augmented(held, Mq: sp.Matrix, f: sp.Matrix, q: list, qd: list) -> tuple[sp.Matrix, sp.Matrix]:
    """The equations of n + m unknowns (q'', lambda): [[Mq, Phi_q'], [Phi_q, 0]] and
    [f; -gamma], gamma = (Phi_q q')' at q'' = 0."""
    Pq, m = held.Pq, len(held.phis)
    gamma = mech.time_derivative(Pq * sp.Matrix(qd), q, qd)
    return (sp.Matrix(sp.BlockMatrix([[Mq, Pq.T], [Pq, sp.zeros(m, m)]])),
            sp.Matrix(sp.BlockMatrix([[f], [-gamma]])))


def projection(model: Model, held) -> sp.Matrix:
    """C of dq = C dq_ind on the constraints: [I; -Phi_dep^-1 Phi_ind] in the coordinates'
    order (refused where Phi_dep is singular: other independent coordinates)."""
    Pq, ind, dep = held.Pq, held.ind, held.dep
    m, n = len(dep), len(model.q)
    P_dep, P_ind = Pq.extract(list(range(m)), dep), Pq.extract(list(range(m)), ind)
    if P_dep.det() == 0:
        raise Unsupported(f"{model.name}: the constraints cannot be solved for the dependent coordinates "
                          f"({', '.join(model.coordinates[i] for i in dep)}): choose others in `reduced`")
    C = sp.zeros(n, n - m)
    for k, i in enumerate(ind):
        C[i, k] = 1
    Cdep = -P_dep.inv(method="ADJ") * P_ind  # adjugate over det: GE's pivot search simplifies (4.4 s)
    for r, i in enumerate(dep):
        for k in range(n - m):
            C[i, k] = Cdep[r, k]
    held.P_dep = P_dep
    return C


def constrained_operator(held, C: sp.Matrix, E0: sp.Matrix, f0: sp.Matrix, q, qd, qdd, rest: dict):
    """The operator about rest in the independent coordinates, as sympy's linearize gives
    it: lambda0 from the dependent rows at rest (Phi_dep' lambda0 = f_dep), then
    M = C' Mq C, D = C' (dE/dq') C, K = C' (dE/dq + sum_j lambda0_j d2 phi_j/dq2) C."""
    lam0 = held.P_dep.T.inv(method="ADJ") * sp.Matrix([f0[i] for i in held.dep])
    H = sp.zeros(len(q), len(q))
    for j, phi in enumerate(held.phis):
        H += lam0[j] * sp.hessian(phi, q)
    return mech.LinearOperator(C.T * E0.jacobian(qdd).subs(rest) * C, C.T * E0.jacobian(qd).subs(rest) * C,
                               C.T * (E0.jacobian(q).subs(rest) + H) * C)
