"""What the machinery supports, checked before any equation is formed: the names, the
forces, every symbol declared, the non-smooth terms, the cyclic and steady coordinates;
and the Lagrangian and the forces split into their part without inputs (the equilibrium,
the operator) and the input terms (B)."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive import names, nonsmooth
from derive.model import TIME, Model, Unsupported
from derive.passes.conversion import refuse_nonholonomic

ORDER = 40
ROUTES = ("coordinates", "multipliers")

UNBALANCE_HINT = ("write it as two force inputs (Signal('Fx', 'N', ..., input=True, order=0) and 'Fy', "
                  "with a Load on the rates of the rotor's centre) and use `gyro unbalance MODEL --force-x Fx "
                  "--force-y Fy --magnitude ME` (docs/models.md)")


def generalized_forces(model: Model) -> list | None:
    """Q over all coordinates: Rayleigh dissipation, loads by virtual power, and forces given
    per coordinate. None for a model without forces."""
    if not model.has_forces:
        return None
    n = len(model.coordinates)
    Q = [sp.Integer(0)] * n
    if model.dissipation != 0:
        Q = [a + b for a, b in zip(Q, mech.rayleigh_forces(model.dissipation, model.qd))]
    for load in model.loads:
        Q = [a + b for a, b in zip(Q, mech.load_forces(load.vector, load.velocity, model.qd))]
    for cname, expr in model.generalized_forces.items():
        if cname not in model.coordinates:
            raise Unsupported(f"generalised force on {cname!r}, which is not a coordinate")
        k = model.coordinates.index(cname)
        Q[k] = Q[k] + sp.sympify(expr)
    return Q


def given_symbols(model: Model) -> dict:
    """Given functions of a coordinate (and their derivatives) -> the input symbols that
    stand for their values in the emitted equations."""
    given = {}
    for fn, val, dval in zip(model.given_functions, model.given_values, model.given_derivatives):
        given[sp.Derivative(fn, fn.args[0])] = dval
        given[fn] = val
    return given


def check_declared(model: Model, L, Q, kinks=()) -> None:
    """Every symbol of the Lagrangian and the forces is declared: a parameter, a coordinate
    or its rate, a momentum, a signal, a given value or constant, or time (or a kink of
    derive/nonsmooth.py)."""
    known = set(model.symbols) | set(model.q) | set(model.qd) | set(model.signal_symbols) | {TIME} | set(kinks)
    known |= set(model.given_values) | set(model.given_derivatives) | set(model.given_constants)
    known |= {s for s in model.cyclic.values() if isinstance(s, sp.Symbol)}
    free = set(L.free_symbols).union(*[sp.sympify(x).free_symbols for x in (Q or [])])
    unknown = sorted(map(str, free - known))
    if unknown:
        raise Unsupported(f"{model.name}: {', '.join(unknown)} in the Lagrangian or the forces is not declared "
                          "(not a parameter, coordinate, rate, signal or momentum)")
    for cname, r in model.steady.items():
        bad = sorted(map(str, sp.sympify(r).free_symbols - set(model.symbols)))
        if bad:
            raise Unsupported(f"{model.name}: the steady rate of {cname} uses {', '.join(bad)}, not parameters")


def check_reducible(model: Model, L0, Q0, L_in, Q) -> None:
    """Routh reduction needs each cyclic coordinate ignorable with a conserved momentum; a
    steady motion needs its turning coordinates ignorable. Anything else is refused. L_in
    and Q are the Lagrangian (given functions as their input symbols) and the forces with
    the inputs: an input that depends on such a coordinate would make B a function of it
    (of time, along the motion), and one in its equation would change its momentum.
    Returns the Lagrangian with every such coordinate proved absent set to zero (an
    expression can carry one that cancels only by sin^2 + cos^2 = 1)."""
    refuse_nonholonomic(model)

    for cname in list(model.cyclic) + list(model.steady):
        if cname not in model.coordinates:
            raise Unsupported(f"{model.name}: {cname!r} is not a coordinate")
    both = set(model.cyclic) & set(model.steady)
    if both:
        raise Unsupported(f"{model.name}: {sorted(both)} both Routh-reduced and turning steadily")
    if len(model.cyclic) == len(model.coordinates):
        raise Unsupported(f"{model.name}: every coordinate is cyclic; nothing is left to linearise")
    for cname in list(model.cyclic) + list(model.steady):
        c, v = model.coordinate(cname), model.velocity(cname)
        what = "cyclic" if cname in model.cyclic else "turning steadily"
        if not mech.is_cyclic(L0, c):
            raise Unsupported(f"{model.name}: {cname} ({what}) appears in the Lagrangian; a term with the "
                              f"angle itself (a mass unbalance at {cname}) is a forcing: {UNBALANCE_HINT}")
        L0 = L0.subs(c, 0)
        if L_in is not None and not mech.is_cyclic(L_in, c):
            raise Unsupported(f"{model.name}: an input term of the Lagrangian depends on {cname} ({what})")
        if Q is not None:
            k = model.coordinates.index(cname)
            if any(sp.sympify(Qi).has(c) for Qi in Q):
                raise Unsupported(f"{model.name}: a generalised force depends on {cname} ({what})")
            if cname in model.cyclic and (sp.sympify(Q[k]) != 0 or any(sp.sympify(Qi).has(v) for Qi in Q)):
                raise Unsupported(f"{model.name}: a force acts on the cyclic coordinate {cname} or "
                                  "depends on its rate: its momentum is not conserved; declare a "
                                  "steady motion of it instead")
        if cname in model.cyclic:
            p = sp.diff(model.lagrangian, v)
            if p.free_symbols & set(model.input_signal_symbols) or any(
                    p.has(fn) for fn in model.given_functions):
                raise Unsupported(f"{model.name}: an input enters the momentum of the cyclic {cname}")
    return L0



def run(model: Model, d):
    w, L, kinks = d.work, model.lagrangian, d.work.kinks
    with w.steps("checks: names, what the machinery supports"):
        names.check_model(model)
        w.Q = Q = generalized_forces(model)
        w.given = given = given_symbols(model)
        w.zero_inputs = zero_inputs = {s: 0 for s in model.input_signal_symbols}
        free = {fn: 0 for fn in model.given_functions}  # free vibration
        L0 = L.subs(free).subs(zero_inputs) if zero_inputs else L.subs(free)
        w.Q0 = Q0 = None if Q is None else [sp.sympify(x).subs(zero_inputs) for x in Q]
        w.L_inputs = L_inputs = L - L0  # the terms with inputs: given functions, input signals
        L_in = sp.sympify(mech.substitute([L_inputs], given)[0] if given else L_inputs)
        check_declared(model, L_in + L0, Q, kinks.symbols)
        nonsmooth.check_lagrangian(sp.sympify(L), kinks, list(model.qd) + model.signal_symbols, model.name)
        w.L0 = check_reducible(model, L0, Q0, L_in, Q)
        d.time_dependent = TIME in sp.sympify(L).free_symbols or any(
            TIME in sp.sympify(x).free_symbols for x in (Q or []))
    return d
