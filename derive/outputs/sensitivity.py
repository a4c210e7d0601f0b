"""Parameter derivatives of the exact operator and of the equilibrium equations: the
pieces of the eigenvalue derivative d lambda / d p_j = -(y* dJ/dp_j x) / (y* J'(lambda) x),
with the equilibrium's own dependence dq_e/dp_j = -(dr/dq_e)^-1 dr/dp_j included by the
runtime (gyro/analyses/sensitivity.py).

dMDK is emitted as its structural nonzeros only (a few hundred of 3 n^2 (params + coordinates)
entries): the runtime contracts over them, with their positions from metadata.json."""
from __future__ import annotations

import sympy as sp

from derive import mechanics
from derive.model import Function

ORDER = 25


def functions(d) -> list[Function]:
    if d.momenta:  # a stationary motion's operator: its reference is not an equilibrium of p alone
        return []
    op = d.operator
    wrt = list(d.model.symbols) + list(d.even)
    entries = [e for X in (op.M, op.D, op.K) for e in X]  # row-major M, then D, then K
    kinks = (sp.sign, sp.Heaviside, sp.Piecewise, sp.Abs, sp.Max, sp.Min, sp.DiracDelta)
    if any(e.has(*kinks) for e in entries) or d.equilibrium_residual.has(*kinks):
        # an operator with a kink (derive/nonsmooth.py) has no derivative where its argument
        # vanishes, and SymPy's would carry DiracDelta and unevaluated Derivatives: no
        # emitted sensitivities (the runtime's CasADi route differentiates away from kinks)
        return []
    dJ = mechanics.jacobian(entries, wrt)
    dr = mechanics.jacobian(list(d.equilibrium_residual), wrt)
    names = ", ".join(str(w) for w in wrt)
    return [Function("operator_sensitivity", d.state(),
                     [("dMDK", dJ), ("dr", dr)],
                     "Jacobians with respect to (" + names + "): dMDK of the entries of M, D and K "
                     "(row-major, M then D then K; one row an entry), as its structural nonzeros "
                     "(their rows and columns in metadata.json), and dr of the equilibrium "
                     "residual (one row an equation).", ("dMDK", "dr"), sparse=("dMDK",))]
