"""The input matrix B of M q'' + D q' + K q = B w: the equations' Jacobian in the inputs w
(given functions' values and derivatives, input signals) at the reference; on the
multipliers route that of the equations of all coordinates projected on the constraints."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive import nonsmooth
from derive.model import Model
from derive.passes.operator import reduced_order

ORDER = 100
ROUTES = ("coordinates", "multipliers")


def run(model: Model, d):
    w_ = list(model.given_values) + list(model.given_derivatives) + list(model.input_signal_symbols)
    if not w_:
        return d
    w, kinks, held = d.work, d.work.kinks, d.work.held
    with w.steps("input matrix B: the equations' Jacobian in the inputs at the reference"):
        if held:  # the multipliers route: projected on the constraints, B = C' B_q
            E = held.Mq * sp.Matrix(model.qdd) - held.f
            B = held.C.T * -E.jacobian(w_).subs(held.rest)
        else:
            # the equations of the input terms (given functions still functions, so that
            # their time derivatives are taken), then the functions' values as inputs
            Qin = None if w.Q is None else [sp.sympify(a) - b for a, b in zip(w.Q, w.Q0)]
            Ein = mech.lagrange_equations(w.L_inputs, model.q, model.qd, model.qdd, Qin, model.signals)
            Ein = reduced_order(model, d, mech.substitute(Ein, w.given) if w.given else Ein)
            B = mech.input_matrix(Ein, w_, d.rq, d.rqd, d.rqdd, at=w.zero_set, rates=d.rates)
        if kinks.kinks:
            B = kinks.thaw(B, w.reference) + nonsmooth.undefined_where(kinks, Ein, w_, w.reference, model.name)
        keep = [j for j in range(len(w_)) if any(B[i, j] != 0 for i in range(B.rows))]
        d.inputs = [w_[j] for j in keep]
        d.input_matrix = B.extract(list(range(B.rows)), keep) if keep else None
    return d
