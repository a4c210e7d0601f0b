"""The reference motion's state in every coordinate, for the generic motion from it
(`gyro simulate MODEL`, gyro/analyses/motion.py): `reference_state(params, qe[, time]) ->
(q, qd)`, over the model's coordinates in their order.

q: the equilibrium coordinates their values qe, every other coordinate zero (a symmetric
zero; a cyclic or a steadily turning coordinate starts at 0). qd: a steady coordinate's
declared rate; a cyclic coordinate's rate from its momentum parameter, dL/dqd_c = beta_c
solved at the reference (the momenta are linear in the cyclic rates; the other rates those
of the reference, q as above, the given functions and input signals zero); every other rate
zero. A model whose momenta are inputs of a stationary motion (not parameters) has none:
its reference needs their values (`gyro simulate` says so).

`cyclic_rates(params, q, qd) -> rates`: the cyclic coordinates' rates on any state, the same
momenta dL/dqd_c = beta_c solved for them with q and the other rates as given (the cyclic
rates in qd ignored); the reduced motion's state about the reference (the linear motion and
its correction, gyro/analyses/motion.py) takes them, as the torsion gyrocompass's spin rate
from the integral C r2 = H (2.3)."""
from __future__ import annotations

import sympy as sp

from derive.model import TIME, Function

ORDER = 52


def functions(d) -> list[Function]:
    model = d.model
    if d.momenta:
        return []
    names = list(model.coordinates)
    at = {x: 0 for x in model.q}
    at.update({x: x for x in d.even})  # the equilibrium coordinates keep their symbols (inputs qe)
    rates = {v: sp.sympify(r) for v, r in d.rates.items()}
    reference = {v: rates.get(v, 0) for v in model.qd}
    free = {s: 0 for s in list(model.input_signal_symbols) + list(model.given_values)
            + list(model.given_derivatives)}
    cyclic = [model.coordinates.index(c) for c in model.cyclic]
    out = []
    if cyclic:
        Kv, b, beta = _momenta(model, cyclic, free)
        cv = [model.qd[i] for i in cyclic]
        others = {v: r for v, r in reference.items() if v not in cv}
        sol = Kv.xreplace(at).xreplace(others).LUsolve(beta - b.xreplace(at).xreplace(others))
        reference.update({v: sp.simplify(s) for v, s in zip(cv, sol)})
        rates = Kv.LUsolve(beta - b)
        out.append(Function("cyclic_rates", [("params", model.symbols), ("q", list(model.q)), ("qd", list(model.qd))],
                            [("rates", rates)],
                            "The cyclic coordinates' rates (" + ", ".join(model.cyclic) + ") on a state q, qd: "
                            "their momenta dL/dqd_c = beta_c solved for them, the other rates as given."))
    q = sp.Matrix([at[x] for x in model.q])
    qd = sp.Matrix([reference[v] for v in model.qd])
    inputs = [("params", model.symbols)] + ([("qe", list(d.even))] if d.even else [])
    if TIME in (q.free_symbols | qd.free_symbols):
        inputs.append(("time", [TIME]))
    return [Function("reference_state", inputs, [("q", q), ("qd", qd)],
                     "The reference motion's state at t = 0 over the coordinates (" + ", ".join(names)
                     + "): the equilibrium coordinates qe, the others zero; the steady coordinates' "
                     "declared rates, the cyclic ones' from their momenta, the others zero.")] + out


def _momenta(model, cyclic: list, free: dict):
    """The cyclic momenta p = Kv qd_c + b (Kv, b free of the cyclic rates; the given functions
    and signals zero) and their values beta, for p = beta."""
    L = sp.sympify(model.lagrangian)
    if model.given_functions:
        L = L.subs({f: 0 for f in model.given_functions})
    cv = [model.qd[i] for i in cyclic]
    p = [sp.diff(L, v) for v in cv]
    Kv = sp.Matrix([[sp.diff(pc, v) for v in cv] for pc in p]).xreplace(free)
    b = sp.Matrix([pc.xreplace({v: 0 for v in cv}) for pc in p]).xreplace(free)
    beta = sp.Matrix([sp.sympify(model.cyclic[model.coordinates[i]]) for i in cyclic])
    return Kv, b, beta
