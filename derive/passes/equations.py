"""The full nonlinear equations of all coordinates in mass-matrix form, never inverted
symbolically; on the multipliers route with the multiplier columns and the constraints'
acceleration rows (derive/constraints.py); again with the parameters made time-varying by
signals, where there are."""
from __future__ import annotations

import sympy as sp

from derive import constraints
from derive import mechanics as mech
from derive.model import Model

ORDER = 60
ROUTES = ("coordinates", "multipliers")


def varying_equations(model: Model, L, Q, given, varying: list, signals: list) -> dict:
    """The full equations in mass-matrix form with each parameter of `varying` replaced by
    its signal's value: its derivatives enter through every d/dt (mechanics.chain), to the
    signal's declared order (Unsupported beyond it)."""
    sub = {model.param(sig.parameter).symbol: sig.symbol for sig in varying}
    Lv = sp.sympify(L).xreplace(sub)
    Qv = None if Q is None else [sp.sympify(x).xreplace(sub) for x in Q]
    Mq, f = mech.mass_matrix_form(Lv, model.q, model.qd, Qv, signals)
    f = sp.Matrix(mech.substitute(list(f), given))
    return {"signals": signals, "varying": varying, "mass_matrix": Mq, "forcing": f, "sub": sub}


def run(model: Model, d):
    w, L = d.work, model.lagrangian
    with w.steps("equations of all coordinates, mass-matrix form"):
        Mq, f = mech.mass_matrix_form(L, model.q, model.qd, w.Q, model.signals)
        d.mass_matrix, d.forcing = Mq, sp.Matrix(mech.substitute(list(f), w.given))
    if w.held:  # the multipliers route: n + m unknowns (q'', lambda)
        with w.steps(f"with {len(w.held.phis)} Lagrange multiplier(s): mass-matrix form of n + m unknowns"):
            w.held.Mq, w.held.f = d.mass_matrix, d.forcing
            d.mass_matrix, d.forcing = constraints.augmented(w.held, Mq, d.forcing, model.q, model.qd)
    if w.varying:
        with w.steps(f"equations of all coordinates with {', '.join(s.parameter for s in w.varying)} "
                     "time-varying (signals)"):
            d.varying = varying_equations(model, L, w.Q, w.given, w.varying, w.all_signals)
    return d
