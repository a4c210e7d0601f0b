"""Routh reduction of the cyclic coordinates (their momenta conserved, inputs of what
follows), and the reduced coordinates of the operator: those left, the unknowns of the
reference among them, the rates of the steady motions. On the multipliers route (no cyclic
coordinates there) the operator's coordinates are the independent ones, and the reference's
unknowns all coordinates, a point on the constraints."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.model import Model, Unsupported

ORDER = 70
ROUTES = ("coordinates", "multipliers")


def run(model: Model, d):
    R = d.work.L0
    with d.work.steps(f"Routh reduction of the cyclic coordinates {', '.join(model.cyclic)}" if model.cyclic
                      else "Routh reduction: no cyclic coordinates"):
        for cname, momentum in model.cyclic.items():
            try:
                R = mech.routhian(R, model.velocity(cname), momentum)
            except ValueError as exc:  # not quadratic in the cyclic rate
                raise Unsupported(f"{model.name}: Routh reduction of {cname}: {exc}") from None
    d.routhian = R
    held = d.work.held  # the multipliers route: the independent coordinates
    d.order = order = held.order if held else model.reduced or [c for c in model.coordinates if c not in model.cyclic]
    d.rq = [model.coordinate(c) for c in order]
    d.rqd = [model.velocity(c) for c in order]
    d.rqdd = [model.acceleration(c) for c in order]
    d.even = [x for x, c in zip(d.rq, order) if c not in model.symmetric_zero and c not in model.steady]
    if held:  # the reference a point on the constraints: every coordinate an unknown of it
        d.even = list(model.q)
    d.rates = {model.velocity(c): sp.sympify(r) for c, r in model.steady.items()}
    return d
