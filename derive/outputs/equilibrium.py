"""The reference's equations (rest, a relative equilibrium, a steady motion) and the
model's approximate equilibrium."""
from __future__ import annotations

import sympy as sp

from derive.model import Function, Unsupported

ORDER = 10


def functions(d) -> list[Function]:
    model = d.model
    fns = [Function("equilibrium_residual", d.state(), [("r", d.equilibrium_residual)],
                    "Generalised forces dR/dq at rest on the symmetric set (R: Routh function); "
                    f"zero at a relative equilibrium. Rows: {', '.join(d.order)}."
                    + _extra(d))]
    system = _system(d)
    if system is not None:
        fns.append(system)
    if model.equilibrium_approx:
        even_names = [str(x) for x in d.even]
        # a symmetric zero among the equilibrium coordinates (a model with multipliers keeps
        # every coordinate there) starts at its zero; any other must be given
        approx = {**{c: 0 for c in model.symmetric_zero}, **model.equilibrium_approx}
        missing = [c for c in even_names if c not in approx]
        if missing:
            raise Unsupported(f"{model.name}: equilibrium_approx gives no value of {', '.join(missing)} "
                              f"(the equilibrium coordinates: {', '.join(even_names)})")
        fns.append(Function("equilibrium_approx", [("params", model.symbols)],
                            [("qe", sp.Matrix([approx[c] for c in even_names]))],
                            f"The model's approximate equilibrium of {', '.join(even_names)}, where "
                            "the runtime's Newton starts (the torsion gyrocompass's (2.2), the "
                            "gyrohorizoncompass's (3.1))."))
    return fns


def _system(d) -> Function | None:
    """What one Newton step of the equilibria needs and nothing more: the residual's rows of
    the equilibrium coordinates and the operator's stiffness K restricted to them, in one
    function (one CSE: the operator's M, D and the other rows and columns of K are not
    evaluated). None where an equilibrium coordinate is not a reduced one."""
    names, order = [str(x) for x in d.even], list(d.order)
    if d.constraints.get("multipliers"):
        return _constrained_system(d)
    if not names or not set(names) <= set(order):
        return None
    idx = [order.index(c) for c in names]
    r = sp.Matrix([d.equilibrium_residual[i] for i in idx])
    K = d.operator.K.extract(idx, idx)
    return Function("equilibrium_system", d.state(), [("r", r), ("K", K)],
                    "The Newton system of the equilibria: the rows of equilibrium_residual and the "
                    f"rows and columns of the operator's K at the equilibrium coordinates ({', '.join(names)}); "
                    "r(qe + dq) = r(qe) - K dq to first order.", ("K",))


def _constrained_system(d) -> Function:
    """A model with multipliers (derive/constraints.py): its equilibrium has all n
    coordinates as unknowns, on the constraint. The Newton system is the n - m rows of the
    reduced residual C' f0 and the m constraints phi(q) = 0, K = -(their Jacobian in q), so
    that r(qe + dq) = r(qe) - K dq as for every other model."""
    phi = sp.Matrix([sp.sympify(c) for c in d.model.holonomic])
    r = sp.Matrix.vstack(sp.Matrix(d.equilibrium_residual), phi)
    K = -r.jacobian(list(d.even))
    return Function("equilibrium_system", d.state(), [("r", r), ("K", K)],
                    "The Newton system of the equilibrium on the constraints: the rows of "
                    f"equilibrium_residual ({', '.join(d.order)}) and the constraints phi(q) = 0, over all "
                    f"coordinates ({', '.join(map(str, d.even))}); K = -dr/dq, r(qe + dq) = r(qe) - K dq to "
                    "first order.", ("K",))


def _extra(d) -> str:
    parts = []
    if d.model.has_forces:
        parts.append("the generalised forces Q are included")
    if d.rates:
        parts.append("on the steady motion " + ", ".join(f"{v} = {r}" for v, r in d.rates.items()))
    if d.time_dependent or d.model.signals:
        parts.append("less the explicit time derivative of dR/dqd")
    return (" With " + "; ".join(parts) + ".") if parts else ""


def metadata(d) -> dict:
    model = d.model
    meta = {}
    if model.steady:
        meta["steady"] = {c: str(r) for c, r in model.steady.items()}
    if model.signals:
        meta["signals"] = [{"name": s.name, "unit": s.unit, "description": s.description,
                            "input": s.input, "symbols": [str(x) for x in s.symbols]}
                           for s in model.signals]
    if d.time_dependent:
        meta["time_dependent"] = True
    if model.has_forces:
        meta["forces"] = {"dissipation": str(model.dissipation) if model.dissipation != 0 else None,
                          "loads": [ld.name for ld in model.loads],
                          "generalized": sorted(model.generalized_forces)}
    return meta
