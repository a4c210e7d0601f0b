"""The linear operator M p^2 + D p + K about the reference by two routes that must agree:
route 2, the second variation of the Routhian with the forces linearised (the operator
emitted); route 1, the full equations linearised with the cyclic rates eliminated through
their integrals. Their 30-digit comparison runs here, or beside the next passes where the
derivation has more than one core (derive.parallel.JOBS; the agreement pass). On the
multipliers route, the one route of the constrained system (derive/constraints.py)."""
from __future__ import annotations

import random

import mpmath
import sympy as sp

from derive import mechanics as mech
from derive import constraints, nonsmooth, parallel
from derive.model import Model

ORDER = 90
ROUTES = ("coordinates", "multipliers")


def _random_point(symbols, rng):
    """Exact rational values in [1/2, 2] for every symbol: no rounding in the check."""
    return {s: sp.Rational(rng.randint(500, 2000), 1000) for s in symbols}


WORKING_DPS = 60  # digits carried through each entry's arithmetic
CHECK_DPS = 30  # digits each entry is rounded to before the two routes are compared
COMPILE_NODES = 1000  # above this many expression nodes in all, the entries are compiled


def compare_operators(op1: mech.LinearOperator, op2: mech.LinearOperator, points=3, seed=0) -> float:
    """Largest difference of the two operators relative to the largest entry, each entry's
    value rounded to 30 digits, at random exact rational points of all their symbols.

    Small operators: each entry by sympy's N(entry, 30). Large ones (more than
    COMPILE_NODES nodes in all): in mpmath with 60 working digits through one compiled
    function of the entries' common subexpressions, each value then rounded to 30 digits
    as N gives it (N evaluated sin(theta) anew at each of its occurrences: 0.9 s of a top's
    1.2 s derivation in Euler angles, against 0.07 s compiled; compiling costs the first
    lambdify's imports, 0.06 s, which a 1-2 DOF system's whole check does not). An entry's
    two routes, equal, lose at most a few of the 60 digits to cancellation and round to the
    same 30-digit number, so that agreeing routes compare to 0 either way, and a wrong
    term, of relative size 1e-3 or more, is as visible."""
    rng = random.Random(seed)
    mats = [op1.M, op1.D, op1.K, op2.M, op2.D, op2.K]
    syms = sorted(set().union(*[m_.free_symbols for m_ in mats]), key=str)
    entries = [e for m_ in mats for e in m_]
    size = len(op1.M)
    compiled = sum(1 for e in entries for _ in sp.preorder_traversal(e)) > COMPILE_NODES
    evaluate = sp.lambdify(syms, entries, modules="mpmath", cse=True) if compiled else None
    worst = 0.0
    for _ in range(points):
        pt = _random_point(syms, rng)
        if compiled:
            with mpmath.workdps(WORKING_DPS):
                values = evaluate(*[mpmath.mpf(v.p) / v.q for v in pt.values()])
            with mpmath.workdps(CHECK_DPS):
                values = [+mpmath.mpmathify(v) for v in values]
        else:
            values = [sp.N(e.xreplace(pt), CHECK_DPS) for e in entries]
        for k in range(3):
            v1, v2 = values[k * size:(k + 1) * size], values[(k + 3) * size:(k + 4) * size]
            scale = max(abs(x) for x in v2) or 1
            worst = max(worst, float(max(abs(x - y) for x, y in zip(v1, v2)) / scale))
    return worst


def agree(agreement: float) -> float:
    if agreement > 1e-25:
        raise AssertionError(f"routes 1 and 2 disagree: {agreement:.3e}")
    return agreement


def reduced_order(model: Model, d, E) -> list:
    """Equations E of all coordinates with the cyclic rates eliminated through their
    integrals, in the order of the reduced coordinates."""
    if model.cyclic:
        E = mech.eliminate_cyclic(E, model.q, model.qd, model.qdd, [model.coordinates.index(c) for c in model.cyclic],
                                  d.work.L0, list(model.cyclic.values()), model.signals)
    names_after = [c for c in model.coordinates if c not in model.cyclic]
    return [E[names_after.index(c)] for c in d.order]


def run(model: Model, d):
    w, signals = d.work, model.signals
    w.check = None
    if w.held:  # one route: the constrained linearisation (derive/constraints.py)
        with w.steps("linear operator in the independent coordinates (sympy's linearize at rest)"):
            held = w.held
            E0 = (held.Mq * sp.Matrix(model.qdd) - held.f).subs(w.zero_inputs)
            d.operator = constraints.constrained_operator(held, held.C, E0, held.f0, model.q, model.qd, model.qdd,
                                                          held.rest)
        d.route_agreement = None  # one route: no agreement to claim
        return d
    at = {"at": w.zero_set, "rates": d.rates}
    with w.steps("linear operator, route 2: second variation of the Routhian, forces linearised"):
        op2 = mech.quadratic_expansion(d.routhian, d.rq, d.rqd, signals=signals, **at)
        if w.Q0r is not None:
            Qq, Qv = mech.linearize_forces(w.Q0r, d.rq, d.rqd, **at)
            op2 = mech.LinearOperator(op2.M, op2.D - Qv, op2.K - Qq)
    d.operator = op2

    with w.steps("linear operator, route 1: linearising the full equations with the integral"):
        E = reduced_order(model, d, mech.lagrange_equations(w.L0, model.q, model.qd, model.qdd, w.Q0, signals))
        op1 = mech.linearize_equations(E, d.rq, d.rqd, d.rqdd, **at)

    kinks = w.kinks
    w.undefined = None
    if kinks.kinks:  # where the non-smooth terms leave an entry without a derivative
        w.undefined = [nonsmooth.undefined_where(kinks, E, xs, w.reference, model.name)
                       for xs in (d.rqdd, d.rqd, d.rq)]

    # a check that nothing below needs until the metadata: beside the next passes where the
    # derivation has more than one core (derive.parallel.JOBS), else here
    with w.steps("the two routes agree (30 digits, random rational points)"
                 + (", beside the next steps" if parallel.beside() else "")):
        w.check = parallel.later(lambda: compare_operators(op1, op2))
        d.route_agreement = None if w.check.beside else agree(w.check.result())
    return d
