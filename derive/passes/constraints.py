"""Holonomic constraints (derive/constraints.py): solved for dependent coordinates and
eliminated, the model going on in its independent coordinates; or, where no linear solve
finds them, carried by Lagrange multipliers: this pass then forms the equations, the
operator and B of the multipliers route, and the passes of the coordinates route stand
aside (their ROUTES)."""
from __future__ import annotations

import sympy as sp

from derive import constraints, names, nonsmooth
from derive.model import Model, Unsupported
from derive.passes.checks import check_declared, generalized_forces

ORDER = 20
ROUTES = ("coordinates",)


def run(model: Model, d):
    if not model.holonomic:
        return d
    with d.work.steps("holonomic constraints: dependent coordinates solved for, or multipliers"):
        found = constraints.solve_dependent(model)
        if found:
            d.model, d.constraints = constraints.eliminate(model, *found)
    if found:
        return d
    d.route = "multipliers"
    with d.work.steps("checks: names, what the machinery supports"):
        names.check_model(model)
        Q = generalized_forces(model)
        exprs = [sp.sympify(model.lagrangian)] + [sp.sympify(x) for x in (Q or [])]
        if any(e.has(*nonsmooth.NONSMOOTH) for e in exprs):
            raise Unsupported(f"{model.name}: non-smooth functions together with holonomic constraints "
                              "that need multipliers")
        check_declared(model, exprs[0], Q)
    return constraints.multipliers(model, Q, d.work.steps, d)
