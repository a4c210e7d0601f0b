"""A model written in the machinery's own symbols (a `Model` of plain symbols: q, q_d, q_dd,
signals F, F_d, given functions f(phi)) handed to sympy.physics.mechanics as its user hands
a system over: the same Lagrangian in dynamicsymbols, each force on a point of its own
whose velocity gives that force's generalised forces by SymPy's partial velocities, the
same holonomic constraints. Imports only SymPy (bench/sympy_systems.py times it beside the
machinery, each in a process of its own).

- q_i -> q_i(t), q_d -> q_i', explicit time t -> dynamicsymbols._t, a signal F with its
  derivative symbols F_d, ... -> F(t), F', ...; a given function f(phi) -> f(phi(t));
- a Rayleigh function F(q') -> the force -dF/dq_k' on a point P_k with velocity q_k' N.x
  (its partial velocity in q_j' is delta_jk N.x: the generalised force -dF/dq_k' on q_k);
- a generalised force Q on coordinate k -> Q N.x on such a point P_k;
- a Load (vector, velocity) of up to three components -> the vector on a point whose
  velocity is the load's velocity in N's components (virtual power: the same Q_k);
  longer ones are cut into threes.

Cyclic coordinates, steady motions and symmetric zeros are the machinery's own reduction
and reference: SymPy's method derives the full equations of all coordinates and
linearises them where they are (its linearize without an operating point)."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Point, ReferenceFrame, dynamicsymbols

T = dynamicsymbols._t


def to_dynamic(model) -> dict:
    """The machinery's plain symbols -> their dynamicsymbols (and derivatives)."""
    sub = {}
    for name, x, xd, xdd in zip(model.coordinates, model.q, model.qd, model.qdd or [None] * len(model.q)):
        f = dynamicsymbols(name)
        sub[x], sub[xd] = f, f.diff(T)
        if xdd is not None:
            sub[xdd] = f.diff(T, 2)
    for sig in model.signals:
        f = dynamicsymbols(sig.name)
        for k, s in enumerate(sig.symbols):
            sub[s] = f.diff(T, k) if k else f
    return sub


def lagranges_system(model):
    """(L, q, holonomic constraints, loads, N) as LagrangesMethod takes them."""
    sub = to_dynamic(model)
    dyn = lambda e: sp.sympify(e).xreplace(sub)  # noqa: E731
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    q = [sub[x] for x in model.q]
    loads = []

    def on_point(name, force, velocity):
        for k in range(0, len(force), 3):
            P = O.locatenew(f"{name}_{k}", 0)
            basis = (N.x, N.y, N.z)
            P.set_vel(N, sum((dyn(v) * b for v, b in zip(velocity[k:k + 3], basis)), 0 * N.x))
            loads.append((P, sum((dyn(f) * b for f, b in zip(force[k:k + 3], basis)), 0 * N.x)))

    if sp.sympify(model.dissipation) != 0:
        for j, v in enumerate(model.qd):
            Qj = -sp.diff(model.dissipation, v)
            if Qj != 0:
                on_point(f"R{j}", [Qj], [v])
    for cname, Qc in model.generalized_forces.items():
        j = model.coordinates.index(cname)
        on_point(f"Q{j}", [Qc], [model.qd[j]])
    for i, ld in enumerate(model.loads):
        on_point(f"L{i}", list(sp.Matrix(ld.vector)), list(sp.Matrix(ld.velocity)))
    return dyn(model.lagrangian), q, [dyn(c) for c in model.holonomic], loads, N


def independent(model, q, m: int) -> tuple[list, list]:
    """(independent, dependent) coordinates of a system with m constraints: the model's
    `reduced` where it has one, else the first n - m."""
    if m == 0:
        return list(q), []
    names = list(model.reduced) if model.reduced else model.coordinates[: len(q) - m]
    ind = [x for x, c in zip(q, model.coordinates) if c in names]
    return ind, [x for x in q if x not in ind]
