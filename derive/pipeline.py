"""The derivation as a sequence of generic steps over a `Model`, each printed with its time.

model -> checks (what the machinery supports, names) -> identities -> equations of motion
with generalised forces, explicit time and signals -> Routh reduction of cyclic coordinates
-> equations of the reference (rest, a relative equilibrium, or a declared steady motion)
-> linear operator by two routes (must agree) -> input matrix B -> approximate variants ->
functions to emit, contributed by the output kinds of `derive/outputs/`.
"""
from __future__ import annotations

import dataclasses
import random
import sys
import time
from contextlib import contextmanager

import sympy as sp

from derive import constraints, convert
from derive import mechanics as mech
from derive import names, nonsmooth, parallel
from derive.derivation import Derivation, VariantResult  # noqa: F401  (pipeline.Derivation, as before)
from derive.model import TIME, Function, Load, Model, Unsupported, runtime_module

P_SYMBOL = sp.Symbol("p")  # the operator d/dt
Z_SYMBOL = sp.Symbol("z")  # p^2


class Steps:
    """Prints each step of a long run with its duration, as it goes."""

    def __init__(self, out=sys.stderr, prefix=""):
        self.out, self.prefix, self.timings = out, prefix, []
        self.t_start = time.perf_counter()
        self.current = None  # the step running, for a one-line report of its failure

    @contextmanager
    def __call__(self, name: str):
        t0 = time.perf_counter()
        print(f"{self.prefix}{name} ...", file=self.out, flush=True)
        self.current = name
        yield
        self.current = None
        dt = time.perf_counter() - t0
        self.timings.append((name, dt))
        print(f"{self.prefix}{name}: {dt:.2f} s", file=self.out, flush=True)

    @property
    def total(self) -> float:
        return time.perf_counter() - self.t_start


def _random_point(symbols, rng):
    """Exact rational values in [1/2, 2] for every symbol: no rounding in the check."""
    return {s: sp.Rational(rng.randint(500, 2000), 1000) for s in symbols}


def compare_operators(op1: mech.LinearOperator, op2: mech.LinearOperator, points=3, seed=0) -> float:
    """Largest difference of the two operators relative to the largest entry, evaluated
    with 30 digits at random exact rational points of all their symbols."""
    rng = random.Random(seed)
    mats = [op1.M, op1.D, op1.K, op2.M, op2.D, op2.K]
    syms = sorted(set().union(*[m_.free_symbols for m_ in mats]), key=str)
    worst = 0.0
    for _ in range(points):
        pt = _random_point(syms, rng)
        for A1, A2 in ((op1.M, op2.M), (op1.D, op2.D), (op1.K, op2.K)):
            v1 = [sp.N(e.xreplace(pt), 30) for e in A1]
            v2 = [sp.N(e.xreplace(pt), 30) for e in A2]
            scale = max(abs(x) for x in v2) or 1
            worst = max(worst, float(max(abs(x - y) for x, y in zip(v1, v2)) / scale))
    return worst


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


def _given_symbols(model: Model) -> dict:
    """Given functions of a coordinate (and their derivatives) -> the input symbols that
    stand for their values in the emitted equations."""
    given = {}
    for fn, val, dval in zip(model.given_functions, model.given_values, model.given_derivatives):
        given[sp.Derivative(fn, fn.args[0])] = dval
        given[fn] = val
    return given


def _check_declared(model: Model, L, Q, kinks=()) -> None:
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


def _refuse_nonholonomic(model: Model) -> None:
    if model.nonholonomic:
        raise Unsupported(f"{model.name}: nonholonomic constraints are not supported (the machinery "
                          "has no multipliers for velocity constraints): write the system in independent "
                          "coordinates")


def _check_reducible(model: Model, L0, Q0, L_in, Q) -> None:
    """Routh reduction needs each cyclic coordinate ignorable with a conserved momentum; a
    steady motion needs its turning coordinates ignorable. Anything else is refused. L_in
    and Q are the Lagrangian (given functions as their input symbols) and the forces with
    the inputs: an input that depends on such a coordinate would make B a function of it
    (of time, along the motion), and one in its equation would change its momentum.
    Returns the Lagrangian with every such coordinate proved absent set to zero (an
    expression can carry one that cancels only by sin^2 + cos^2 = 1)."""
    _refuse_nonholonomic(model)

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


UNBALANCE_HINT = ("write it as two force inputs (Signal('Fx', 'N', ..., input=True, order=0) and 'Fy', "
                  "with a Load on the rates of the rotor's centre) and use `gyro unbalance MODEL --force-x Fx "
                  "--force-y Fy --magnitude ME` (docs/models.md)")


def _refuse_time_forcing(model: Model, order, residual, even) -> None:
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


def _split_varying(model: Model) -> tuple[Model, list, list]:
    """(the model without the signals that make a parameter time-varying, those signals, all
    the model's signals): everything is derived at the parameters' constant values from the
    first; `_varying_equations` derives the full equations again with the signals."""
    varying = [s for s in model.signals if s.parameter is not None]
    if not varying:
        return model, [], list(model.signals)
    names.check_model(model)  # the signals' names among every other emitted symbol
    params = {p.name for p in model.parameters}
    seen = set()
    for sig in varying:
        if sig.parameter not in params:
            raise Unsupported(f"{model.name}: signal {sig.name!r} makes {sig.parameter!r} time-varying, "
                              "which is not a parameter")
        if sig.input:
            raise Unsupported(f"{model.name}: signal {sig.name!r} makes the parameter {sig.parameter} "
                              "time-varying: it stays in the equations (input=False), it is no input w")
        if sig.parameter in seen:
            raise Unsupported(f"{model.name}: the parameter {sig.parameter} is made time-varying twice")
        seen.add(sig.parameter)
    if model.holonomic:
        raise Unsupported(f"{model.name}: a parameter made time-varying (signal {varying[0].name!r}) "
                          "together with holonomic constraints")
    return dataclasses.replace(model, signals=[s for s in model.signals if s.parameter is None]), varying, list(
        model.signals)


def _varying_equations(model: Model, L, Q, given, varying: list, signals: list) -> dict:
    """The full equations in mass-matrix form with each parameter of `varying` replaced by
    its signal's value: its derivatives enter through every d/dt (mechanics.chain), to the
    signal's declared order (Unsupported beyond it)."""
    sub = {model.param(sig.parameter).symbol: sig.symbol for sig in varying}
    Lv = sp.sympify(L).xreplace(sub)
    Qv = None if Q is None else [sp.sympify(x).xreplace(sub) for x in Q]
    Mq, f = mech.mass_matrix_form(Lv, model.q, model.qd, Qv, signals)
    f = sp.Matrix(mech.substitute(list(f), given))
    return {"signals": signals, "varying": varying, "mass_matrix": Mq, "forcing": f, "sub": sub}


def derive(model: Model, steps: Steps | None = None) -> Derivation:
    steps = steps or Steps()
    model = convert.convert(model)  # dynamicsymbols, assumptions, vectors: the machinery's symbols
    _refuse_nonholonomic(model)  # before anything is solved
    model, varying, all_signals = _split_varying(model)
    eliminated = {}
    if model.speeds and model.holonomic:
        raise Unsupported(f"{model.name}: kinematic equations together with holonomic constraints: write the "
                          "model in its independent coordinates, or in their rates")
    if model.holonomic:
        with steps("holonomic constraints: dependent coordinates solved for, or multipliers"):
            found = constraints.solve_dependent(model)
            if found:
                model, eliminated = constraints.eliminate(model, *found)
        if not found:
            return _with_multipliers(model, steps)
    source, kinks = model, nonsmooth.Kinks()
    model = _frozen(model, kinks)  # sign, Heaviside, Abs, Max, Min: a symbol per kink
    q, qd, qdd = model.q, model.qd, model.qdd
    L = model.lagrangian
    signals = model.signals

    with steps("checks: names, what the machinery supports"):
        names.check_model(model)
        Q = generalized_forces(model)
        given = _given_symbols(model)
        zero_inputs = {s: 0 for s in model.input_signal_symbols}
        free = {fn: 0 for fn in model.given_functions}  # free vibration
        L0 = L.subs(free).subs(zero_inputs) if zero_inputs else L.subs(free)
        Q0 = None if Q is None else [sp.sympify(x).subs(zero_inputs) for x in Q]
        L_inputs = L - L0  # the terms with inputs: given functions, input signals
        L_in = sp.sympify(mech.substitute([L_inputs], given)[0] if given else L_inputs)
        _check_declared(model, L_in + L0, Q, kinks.symbols)
        nonsmooth.check_lagrangian(sp.sympify(L), kinks, list(qd) + model.signal_symbols, model.name)
        L0 = _check_reducible(model, L0, Q0, L_in, Q)
        time_dependent = TIME in sp.sympify(L).free_symbols or any(
            TIME in sp.sympify(x).free_symbols for x in (Q or []))

    for name, identity in model.identities.items():
        with steps(f"identity: {name}"):
            residual = identity()
            bad = [r for r in residual if r != 0]
            if bad:
                raise AssertionError(f"identity failed: {name}: {bad[0]}")

    with steps("equations of all coordinates, mass-matrix form"):
        Mq, f = mech.mass_matrix_form(L, q, qd, Q, signals)
        f = sp.Matrix(mech.substitute(list(f), given))

    moving = {}
    if varying:
        with steps(f"equations of all coordinates with {', '.join(s.parameter for s in varying)} "
                   "time-varying (signals)"):
            moving = _varying_equations(model, L, Q, given, varying, all_signals)

    R = L0
    with steps(f"Routh reduction of the cyclic coordinates {', '.join(model.cyclic)}" if model.cyclic
               else "Routh reduction: no cyclic coordinates"):
        for cname, momentum in model.cyclic.items():
            try:
                R = mech.routhian(R, model.velocity(cname), momentum)
            except ValueError as exc:  # not quadratic in the cyclic rate
                raise Unsupported(f"{model.name}: Routh reduction of {cname}: {exc}") from None

    order = model.reduced or [c for c in model.coordinates if c not in model.cyclic]
    rq = [model.coordinate(c) for c in order]
    rqd = [model.velocity(c) for c in order]
    rqdd = [model.acceleration(c) for c in order]
    zero_set = {model.coordinate(c): 0 for c in list(model.symmetric_zero) + list(model.steady)}
    even = [x for x, c in zip(rq, order) if c not in model.symmetric_zero and c not in model.steady]
    rates = {model.velocity(c): sp.sympify(r) for c, r in model.steady.items()}
    Q0r = None if Q0 is None else [Q0[model.coordinates.index(c)] for c in order]

    reference = {v: rates.get(v, 0) for v in qd} | zero_set | zero_inputs
    reference |= {s: 0 for s in list(model.given_values) + list(model.given_derivatives)}

    with steps("equations of the reference and their symmetric zeros"):
        residual = mech.equilibrium_equations(R, rq, rqd, at=zero_set, rates=rates, Q=Q0r, signals=signals)
        if time_dependent:
            _refuse_time_forcing(model, order, residual, even)
        for c in model.symmetric_zero:
            r = sp.expand(residual[order.index(c)])
            if r != 0:
                raise Unsupported(f"{model.name}: the equilibrium equation of {c} does not vanish on "
                                  f"the symmetric set: {r}")
        # a row that no equilibrium coordinate enters (a steady coordinate's) can still hold
        # for some parameters (a drive torque balancing friction): the runtime checks it
        # at each set and reports no equilibrium where it does not (gyro.equilibrium)

    with steps("linear operator, route 2: second variation of the Routhian, forces linearised"):
        op2 = mech.quadratic_expansion(R, rq, rqd, at=zero_set, rates=rates, signals=signals)
        if Q0r is not None:
            Qq, Qv = mech.linearize_forces(Q0r, rq, rqd, at=zero_set, rates=rates)
            op2 = mech.LinearOperator(op2.M, op2.D - Qv, op2.K - Qq)

    cyc_idx = [model.coordinates.index(c) for c in model.cyclic]
    names_after = [c for c in model.coordinates if c not in model.cyclic]

    def reduced_equations(Lx, Qx):
        E = mech.lagrange_equations(Lx, q, qd, qdd, Qx, signals)
        if model.cyclic:
            E = mech.eliminate_cyclic(E, q, qd, qdd, cyc_idx, L0, list(model.cyclic.values()), signals)
        return [E[names_after.index(c)] for c in order]

    with steps("linear operator, route 1: linearising the full equations with the integral"):
        E = reduced_equations(L0, Q0)
        op1 = mech.linearize_equations(E, rq, rqd, rqdd, at=zero_set, rates=rates)

    undefined = None
    if kinks.kinks:  # where the non-smooth terms leave an entry without a derivative
        undefined = [nonsmooth.undefined_where(kinks, E, xs, reference, model.name) for xs in (rqdd, rqd, rq)]

    def agree(agreement: float) -> float:
        if agreement > 1e-25:
            raise AssertionError(f"routes 1 and 2 disagree: {agreement:.3e}")
        return agreement

    # a check that nothing below needs until the metadata: beside the next steps where the
    # derivation has more than one core (derive.parallel.JOBS), else here
    with steps("the two routes agree (30 digits, random rational points)"
               + (", beside the next steps" if parallel.beside() else "")):
        check = parallel.later(lambda: compare_operators(op1, op2))
        agreement = None if check.beside else agree(check.result())

    deriv = Derivation(model=model, mass_matrix=Mq, forcing=f, routhian=R, rq=rq, rqd=rqd,
                       rqdd=rqdd, even=even, equilibrium_residual=residual, operator=op2,
                       route_agreement=agreement, order=order, rates=rates,
                       time_dependent=time_dependent)

    w = list(model.given_values) + list(model.given_derivatives) + list(model.input_signal_symbols)
    if w:
        with steps("input matrix B: the equations' Jacobian in the inputs at the reference"):
            # the equations of the input terms (given functions still functions, so that
            # their time derivatives are taken), then the functions' values as inputs
            Qin = None if Q is None else [sp.sympify(a) - b for a, b in zip(Q, Q0)]
            Ein = mech.lagrange_equations(L_inputs, q, qd, qdd, Qin, signals)
            Ein = mech.substitute(Ein, given) if given else Ein
            if model.cyclic:
                Ein = mech.eliminate_cyclic(Ein, q, qd, qdd, cyc_idx, L0, list(model.cyclic.values()), signals)
            Ein = [Ein[names_after.index(c)] for c in order]
            B = mech.input_matrix(Ein, w, rq, rqd, rqdd, at=zero_set, rates=rates)
            if kinks.kinks:
                B = kinks.thaw(B, reference) + nonsmooth.undefined_where(kinks, Ein, w, reference, model.name)
            keep = [j for j in range(len(w)) if any(B[i, j] != 0 for i in range(B.rows))]
            deriv.inputs = [w[j] for j in keep]
            deriv.input_matrix = B.extract(list(range(B.rows)), keep) if keep else None

    for vname, variant in model.variants.items():
        with steps(f"variant '{vname}': approximations, blocks, polynomials per block"):
            at0 = {x: 0 for x in rq}
            opv = op2.subs(at0).applyfunc(variant.approximate)
            J = opv.J(P_SYMBOL)
            blk = mech.blocks(J)
            polys = [mech.charpoly_in_p2(J.extract(b, b), P_SYMBOL, Z_SYMBOL) for b in blk]
            scale = [variant.row_scale.get(c, 1) for c in order]
            scaled = sp.Matrix(len(order), len(order), lambda i, j: sp.expand(J[i, j] / scale[i]))
            deriv.variants[vname] = VariantResult(opv, blk, polys, scaled)

    if check.beside:
        with steps("the two routes agree: the check beside the steps above"):
            deriv.route_agreement = agree(check.result())
    deriv.timings = steps.timings
    if moving and kinks.kinks:  # a kink's argument with the parameter time-varying too
        for key in ("mass_matrix", "forcing"):
            moving[key] = kinks.thaw(moving[key]).xreplace(moving["sub"])
    deriv.varying = moving
    if kinks.kinks:  # each kink its function again; NaN where a derivative does not exist
        _thawed(deriv, kinks, reference, undefined)
    deriv.model = source
    deriv.constraints = eliminated
    deriv.nondifferentiable = dict(kinks.nondifferentiable)
    if source.speeds:
        with steps("equations in the speeds of the kinematic equations (Kane's form)"):
            deriv.speeds = speeds_equations(source, deriv.mass_matrix, deriv.forcing)
    return deriv


def speeds_equations(model: Model, Mq: sp.Matrix, f: sp.Matrix) -> dict:
    """The equations Mq q'' = f in the speeds u of the kinematic equations, q' = V u + v:
    with q'' = V u' + V' u + v' (V' and v' along the motion), premultiplied by V^T, which
    is what Kane's equations are (the partial velocities of u_r are those of q' taken
    through V's column r): V^T Mq V u' = V^T (f - Mq (V' u + v')), q' replaced by V u + v.
    Refused with holonomic constraints (eliminated coordinates change the rates)."""
    sp_ = model.speeds
    u, V, v = sp.Matrix(sp_["u"]), sp_["V"], sp_["v"]
    q, qd = model.q, model.qd
    rate = {a: b for a, b in zip(qd, V * u + v)}

    def dt(X):
        return sum((X.diff(x) * r for x, r in zip(q, qd)), X.diff(TIME))

    Vu = V.xreplace(rate)
    accel = (dt(V) * u + dt(v)).xreplace(rate)
    M = Vu.T * Mq.xreplace(rate) * Vu  # as they come: expanding took a top's 0.6 s
    F = Vu.T * (f.xreplace(rate) - Mq.xreplace(rate) * accel)
    return {"u": list(u), "kinematics": (V * u + v), "mass_matrix": M, "forcing": F}


def _with_multipliers(model: Model, steps: Steps) -> Derivation:
    """A model whose holonomic constraints have no unique solution: derive/constraints.py."""
    with steps("checks: names, what the machinery supports"):
        names.check_model(model)
        _refuse_nonholonomic(model)
        if model.speeds:
            raise Unsupported(f"{model.name}: kinematic equations together with holonomic constraints that "
                              "need multipliers")
        Q = generalized_forces(model)
        exprs = [sp.sympify(model.lagrangian)] + [sp.sympify(x) for x in (Q or [])]
        if any(e.has(*NONSMOOTH) for e in exprs):
            raise Unsupported(f"{model.name}: non-smooth functions together with holonomic constraints "
                              "that need multipliers")
        _check_declared(model, exprs[0], Q)
    d = constraints.multipliers(model, Q, steps)
    d.timings = steps.timings
    return d


def _frozen(model: Model, kinks: nonsmooth.Kinks) -> Model:
    """The model with each sign(u), H(u) (Abs, Max, Min rewritten in them) a kink symbol."""
    import dataclasses

    fr = kinks.freeze
    frozen = dataclasses.replace(
        model, lagrangian=fr(model.lagrangian), dissipation=fr(model.dissipation),
        loads=[Load(sp.Matrix(ld.vector).applyfunc(fr), sp.Matrix(ld.velocity).applyfunc(fr), ld.name)
               for ld in model.loads] if any(sp.Matrix(ld.vector).has(*NONSMOOTH) or sp.Matrix(ld.velocity).has(
                   *NONSMOOTH) for ld in model.loads) else model.loads,
        generalized_forces={k: fr(v) for k, v in model.generalized_forces.items()})
    return frozen if kinks.kinks else model


NONSMOOTH = (sp.sign, sp.Heaviside, sp.Abs, sp.Max, sp.Min)


def _thawed(d: Derivation, kinks: nonsmooth.Kinks, reference: dict, undefined: list) -> None:
    """Each kink its function again: in the nonlinear equations as they are, in what is
    taken at the reference with its argument there; the operator NaN where it does not
    exist (nonsmooth.undefined_where). B was thawed where it was made."""
    d.mass_matrix, d.forcing = kinks.thaw(d.mass_matrix), kinks.thaw(d.forcing)
    d.routhian = kinks.thaw(d.routhian)
    d.equilibrium_residual = kinks.thaw(d.equilibrium_residual, reference)
    M, D, K = (kinks.thaw(X, reference) + U for X, U in zip((d.operator.M, d.operator.D, d.operator.K), undefined))
    d.operator = mech.LinearOperator(M, D, K)
    for v in d.variants.values():
        v.operator = v.operator.applyfunc(lambda e: kinks.thaw(e, reference))
        v.charpoly = [[kinks.thaw(c, reference) for c in block] for block in v.charpoly]
        v.scaled = kinks.thaw(v.scaled, reference)


def functions(d: Derivation) -> list[Function]:
    """The functions to emit for a derived model: each output kind of `derive/outputs/`
    contributes its own, in the kinds' order."""
    from derive import outputs

    # in this process: built in a worker and pickled back, SymPy's expressions come back
    # equal but not always in the same form, and their CSE then differs (tried: 1019
    # against 1026 operations in one function)
    fns = []
    for kind in outputs.kinds():
        fns.extend(kind.functions(d))
    return fns


def metadata(d: Derivation) -> dict:
    """JSON-serialisable facts the runtime needs without SymPy."""
    from derive import outputs

    model = d.model
    meta = {
        "model": model.name,
        "title": model.title,
        "paper": model.source,
        "parameters": [
            {"name": p.name, "unit": p.unit, "default": p.default, "description": p.description,
             "kind": p.kind, "bounds": list(p.bounds)} for p in model.parameters],
        "coordinates": model.coordinates,
        "coordinate_units": model.coordinate_units,
        "cyclic": {c: str(s) for c, s in model.cyclic.items()},
        "momenta": [str(s) for s in d.momenta],
        "reduced": d.order,
        "equilibrium_coordinates": [str(x) for x in d.even],
        "symmetric_zero": model.symmetric_zero,
        "given": [str(s) for s in model.given_values + model.given_derivatives + model.given_constants],
        "route_agreement": d.route_agreement,
    }
    if d.constraints:
        meta["constraints"] = d.constraints
    if d.nondifferentiable:
        meta["nondifferentiable"] = [{"term": t, "argument_at_reference": a}
                                     for t, a in sorted(d.nondifferentiable.items())]
    if model.aliases:
        unknown = sorted(set(model.aliases.values()) - {p.name for p in model.parameters})
        if unknown:
            raise Unsupported(f"aliases name no parameter: {', '.join(unknown)}")
        meta["aliases"] = dict(model.aliases)
    if model.simulate:
        meta["simulate"] = simulate_declaration(model)
    for kind in outputs.kinds():
        meta.update(getattr(kind, "metadata", lambda _: {})(d))
    return meta


SIMULATE_KEYS = {"module", "options", "usage", "initial"}
SIMULATE_OPTIONS = ("perturb", "method", "level", "base_rate")


def simulate_declaration(model) -> dict:
    """Model.simulate checked: a dotted module name, options among SIMULATE_OPTIONS."""
    decl = dict(model.simulate)
    unknown = sorted(set(decl) - SIMULATE_KEYS)
    if unknown:
        raise Unsupported(f"simulate: unknown keys {unknown}; known: {', '.join(sorted(SIMULATE_KEYS))}")
    module = decl.get("module")
    if not isinstance(module, str) or not all(part.isidentifier() for part in module.split(".")):
        raise Unsupported(f"simulate: 'module' must be a dotted module name, got {module!r}")
    options = list(decl.get("options", []))
    bad = [o for o in options if o not in SIMULATE_OPTIONS]
    if bad:
        raise Unsupported(f"simulate: unknown options {bad}; known: {', '.join(SIMULATE_OPTIONS)}")
    return {"module": runtime_module(model, module), "options": options, "usage": str(decl.get("usage", "")),
            "initial": str(decl.get("initial", ""))}
