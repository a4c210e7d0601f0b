"""Holonomic constraints (derive/constraints.py), the one choice of route: solved for
dependent coordinates and eliminated, the model going on in its independent coordinates
(route "coordinates"); or, where no linear solve finds them, carried by Lagrange
multipliers (route "multipliers"): the model then takes the constraints' quantities, and
what the later passes need of the constraints (their Jacobian, the multipliers, the
independent coordinates) is handed on in `d.work.held`. Every later pass runs on either
route, the equations, reference, operator and input passes with the multiplier columns."""
from __future__ import annotations

from derive import constraints
from derive.model import Model

ORDER = 20
ROUTES = ("coordinates", "multipliers")


def run(model: Model, d):
    d.work.held = None
    if not model.holonomic:
        return d
    with d.work.steps("holonomic constraints: dependent coordinates solved for, or multipliers"):
        found = constraints.solve_dependent(model)
        if found:
            d.model, d.constraints = constraints.eliminate(model, *found)
        else:
            d.route = "multipliers"
            d.model, d.work.held, d.constraints = constraints.multipliers(model)
    return d
