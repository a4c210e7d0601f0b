"""The equations of the reference (rest, a relative equilibrium, or a declared steady
motion) and their symmetric zeros; explicit time that no equilibrium absorbs is refused. On
the multipliers route, the forces at rest projected on the constraints, C' f0, in the
independent coordinates (derive/constraints.py)."""
from __future__ import annotations

import sympy as sp

from derive import constraints
from derive import mechanics as mech
from derive.model import TIME, Model, Unsupported
from derive.passes.checks import UNBALANCE_HINT

ORDER = 80
ROUTES = ("coordinates", "multipliers")


def refuse_time_forcing(model: Model, order, residual, even) -> None:
    """Explicit time in the reference's own equations that no equilibrium can absorb (a mass
    unbalance at the angle W t, a force F cos(w t)) is a forcing: a constant equilibrium qe
    needs r(qe, t) = 0 at every t, hence dr/dt(qe, t) = 0; a row whose dr/dt is not zero
    and free of the equilibrium coordinates has no such qe, so no operator about one exists.
    Time that multiplies a function of qe (a support shaken under a pendulum, sin(theta)
    times sin(w t): zero at theta = 0) stays: the Mathieu form."""
    timed = []
    for c, r in zip(order, residual):
        if TIME in sp.sympify(r).free_symbols:
            dr = sp.simplify(sp.diff(r, TIME))
            if dr != 0 and not (dr.free_symbols & set(even)):
                timed.append(c)
    if timed:
        raise Unsupported(f"{model.name}: the explicit time t enters the equilibrium equations of "
                          f"{', '.join(timed)}: a time-dependent forcing (a mass unbalance written as W t, "
                          f"say) leaves no equilibrium to linearise about; {UNBALANCE_HINT}")


def run(model: Model, d):
    w, order, held = d.work, d.order, d.work.held
    symmetric = {model.coordinate(c): 0 for c in list(model.symmetric_zero) + list(model.steady)}
    # on the multipliers route every coordinate stays an unknown of the reference (d.even)
    w.zero_set = {} if held else symmetric
    w.Q0r = None if w.Q0 is None else [w.Q0[model.coordinates.index(c)] for c in order]
    reference = {v: d.rates.get(v, 0) for v in model.qd} | w.zero_set | w.zero_inputs
    w.reference = reference | {s: 0 for s in list(model.given_values) + list(model.given_derivatives)}
    with w.steps("equations of the reference and their symmetric zeros"):
        if held:  # the forces at rest projected on the constraints: C' f0 (derive/constraints.py)
            held.C = constraints.projection(model, held)
            held.rest = {v: 0 for v in model.qd} | {a: 0 for a in model.qdd} | w.zero_inputs
            held.f0 = held.f.subs(held.rest)
            residual = held.C.T * held.f0
        else:
            residual = mech.equilibrium_equations(d.routhian, d.rq, d.rqd, at=w.zero_set, rates=d.rates,
                                                  Q=w.Q0r, signals=model.signals)
        if d.time_dependent:
            refuse_time_forcing(model, order, residual, d.even)
        for c in model.symmetric_zero:
            if c not in order:  # a dependent coordinate of the multipliers route: no row of its own
                continue
            r = sp.expand(residual[order.index(c)].xreplace(symmetric))
            if r != 0:
                raise Unsupported(f"{model.name}: the equilibrium equation of {c} does not vanish on "
                                  f"the symmetric set: {r}")
        # a row that no equilibrium coordinate enters (a steady coordinate's) can still hold
        # for some parameters (a drive torque balancing friction): the runtime checks it
        # at each set and reports no equilibrium where it does not (gyro.equilibrium)
    d.equilibrium_residual = residual
    return d
