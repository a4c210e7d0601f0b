"""The derivation as a sequence of generic steps over a `Model`, each printed with its time.

model -> identities -> Lagrange equations (1.13) -> Routh reduction of cyclic coordinates ->
equilibrium equations -> linear operator by two routes (must agree) -> approximate variants
(printed blocks, characteristic polynomials per block) -> functions to emit.
"""
from __future__ import annotations

import random
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import sympy as sp

from derive import mechanics as mech
from derive.model import Function, Model

P_SYMBOL = sp.Symbol("p")  # the operator d/dt
# every formula's estimate also carries the rounding of evaluating it in double precision
# (a few hundred operations): 64 eps
FORMULA_ROUNDING = sp.Float(2.0**-46)
MATRICES = ("M", "D", "K", "J", "J_re", "J_im", "Mq")  # outputs that stay matrices when 1x1
Z_SYMBOL = sp.Symbol("z")  # p^2


class Steps:
    """Prints each step of a long run with its duration, as it goes."""

    def __init__(self, out=sys.stderr, prefix=""):
        self.out, self.prefix, self.timings = out, prefix, []
        self.t_start = time.perf_counter()

    @contextmanager
    def __call__(self, name: str):
        t0 = time.perf_counter()
        print(f"{self.prefix}{name} ...", file=self.out, flush=True)
        yield
        dt = time.perf_counter() - t0
        self.timings.append((name, dt))
        print(f"{self.prefix}{name}: {dt:.2f} s", file=self.out, flush=True)

    @property
    def total(self) -> float:
        return time.perf_counter() - self.t_start


@dataclass
class VariantResult:
    operator: mech.LinearOperator  # unscaled, over the reduced coordinates
    blocks: list[list[int]]  # indices into the reduced coordinates
    charpoly: list[list]  # per block: coefficients of det J_block in z = p^2, lowest first
    scaled: sp.Matrix  # J(p) with rows divided as the print does


@dataclass
class Derivation:
    model: Model
    mass_matrix: sp.Matrix  # full nonlinear equations: mass_matrix * qdd = forcing
    forcing: sp.Matrix
    routhian: object
    rq: list  # reduced coordinates, velocities, accelerations (operator order)
    rqd: list
    rqdd: list
    even: list  # reduced coordinates that are not zero at the symmetric equilibrium
    equilibrium_residual: sp.Matrix  # dR/dq at rest on the symmetric set, function of `even`
    operator: mech.LinearOperator  # exact, on the symmetric set, function of `even`
    route_agreement: float  # max |route1 - route2| / max |route2| at random points
    variants: dict[str, VariantResult] = field(default_factory=dict)
    functions: list[Function] = field(default_factory=list)
    timings: list = field(default_factory=list)


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


def derive(model: Model, steps: Steps | None = None) -> Derivation:
    steps = steps or Steps()
    q, qd, qdd = model.q, model.qd, model.qdd
    L = model.lagrangian

    for name, identity in model.identities.items():
        with steps(f"identity: {name}"):
            residual = identity()
            bad = [r for r in residual if r != 0]
            if bad:
                raise AssertionError(f"identity failed: {name}: {bad[0]}")

    with steps("Lagrange equations of all coordinates, mass-matrix form"):
        Mq, f = mech.mass_matrix_form(L, q, qd)
        inputs = {}
        for fn, val, dval in zip(model.given_functions, model.given_values, model.given_derivatives):
            arg = fn.args[0]
            inputs[sp.Derivative(fn, arg)] = dval
            inputs[fn] = val
        f = sp.Matrix(mech.substitute(list(f), inputs))

    free = {fn: 0 for fn in model.given_functions}  # free vibration
    L0 = L.subs(free)
    R = L0
    red_names = [c for c in model.coordinates if c not in model.cyclic]
    with steps(f"Routh reduction of the cyclic coordinates {', '.join(model.cyclic)}"):
        for cname, momentum in model.cyclic.items():
            v = model.velocity(cname)
            if not mech.is_cyclic(R, model.coordinate(cname)):
                raise AssertionError(f"{cname} is not cyclic in the free-vibration Lagrangian")
            R = mech.routhian(R, v, momentum)

    order = model.reduced or red_names
    rq = [model.coordinate(c) for c in order]
    rqd = [model.velocity(c) for c in order]
    rqdd = [model.acceleration(c) for c in order]
    zero_set = {model.coordinate(c): 0 for c in model.symmetric_zero}
    even = [x for x, c in zip(rq, order) if c not in model.symmetric_zero]

    with steps("equilibrium equations and their symmetric zeros"):
        residual = mech.equilibrium_equations(R, rq, rqd, at=zero_set)
        for c in model.symmetric_zero:
            r = sp.expand(residual[order.index(c)])
            if r != 0:
                raise AssertionError(f"equilibrium equation of {c} does not vanish on the symmetric set: {r}")

    with steps("linear operator, route 2: second-order expansion of the Routhian"):
        op2 = mech.quadratic_expansion(R, rq, rqd, at=zero_set)

    with steps("linear operator, route 1: linearising the full equations with the integral"):
        E = mech.lagrange_equations(L0, q, qd, qdd)
        if model.cyclic:
            E = mech.eliminate_cyclic(E, q, qd, qdd, [model.coordinates.index(c) for c in model.cyclic],
                                      L0, list(model.cyclic.values()))
        names_after = [c for c in model.coordinates if c not in model.cyclic]
        E = [E[names_after.index(c)] for c in order]
        op1 = mech.linearize_equations(E, rq, rqd, rqdd, at=zero_set)

    with steps("the two routes agree (30 digits, random rational points)"):
        agreement = compare_operators(op1, op2)
        if agreement > 1e-25:
            raise AssertionError(f"routes 1 and 2 disagree: {agreement:.3e}")

    deriv = Derivation(model=model, mass_matrix=Mq, forcing=f, routhian=R, rq=rq, rqd=rqd,
                       rqdd=rqdd, even=even, equilibrium_residual=residual, operator=op2,
                       route_agreement=agreement)

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

    deriv.timings = steps.timings
    return deriv


def functions(d: Derivation) -> list[Function]:
    """The functions to emit for a derived model, with their inputs and outputs."""
    model = d.model
    params = ("params", model.symbols)
    qe = ("qe", d.even)
    # the cyclic momenta that are not parameters (constants of a motion, e.g. H, L of a
    # free gyroscope) are an input of everything that comes from the Routh function
    moms = [s for s in model.cyclic.values() if s not in model.symbols]
    state = [params, qe] + ([("momenta", moms)] if moms else [])
    order = model.reduced or [c for c in model.coordinates if c not in model.cyclic]
    even_names = [str(x) for x in d.even]
    fns = [
        Function("equilibrium_residual", state, [("r", d.equilibrium_residual)],
                 "Generalised forces dR/dq at rest on the symmetric set (R: Routh function); "
                 f"zero at a relative equilibrium. Rows: {', '.join(order)}."),
    ]
    if model.equilibrium_approx:
        fns.append(Function("equilibrium_approx", [params],
                            [("qe", sp.Matrix([model.equilibrium_approx[c] for c in even_names]))],
                            f"Approximate equilibrium (2.2) of {', '.join(even_names)}."))
    op = d.operator
    fns.append(Function("operator", state, [("M", op.M), ("D", op.D), ("K", op.K)],
                        "Exact linear operator about the equilibrium qe: M q'' + D q' + K q = 0 "
                        f"over q = ({', '.join(order)}); M, K symmetric, D skew.", MATRICES))
    fns.append(Function("operator_J", state + [("pval", [P_SYMBOL])], [("J", op.J(P_SYMBOL))],
                        "J(p) = M p^2 + D p + K of the exact operator at a real p.", MATRICES))
    pr, pi = sp.symbols("p_re p_im")
    fns.append(Function("operator_J_complex", state + [("pval", [pr, pi])],
                        [("J_re", op.M * (pr**2 - pi**2) + op.D * pr + op.K),
                         ("J_im", op.M * (2 * pr * pi) + op.D * pi)],
                        "J(p) at a complex p = p_re + i p_im, as real and imaginary parts; "
                        "J(i omega) at p = (0, omega).", MATRICES))
    for vname, v in d.variants.items():
        fns.append(Function(f"{vname}_operator", [params],
                            [("M", v.operator.M), ("D", v.operator.D), ("K", v.operator.K)],
                            f"Operator of the '{vname}' variant ({model.variants[vname].doc}); "
                            "rows not scaled.", MATRICES))
        fns.append(Function(f"{vname}_charpoly", [params],
                            [(f"block{i + 1}", sp.Matrix(c)) for i, c in enumerate(v.charpoly)],
                            f"Characteristic polynomial of each diagonal block of the '{vname}' "
                            "operator: coefficients of det J_block in z = p^2, lowest degree first."))
    if model.formulas:
        fns.append(Function("formulas", [params],
                            [("values", sp.Matrix(list(model.formulas.values())))],
                            "The paper's approximate formulas, in the order of metadata "
                            "'formulas'."))
    if model.mode_formulas:
        width = max(len(c) for _, c in model.mode_formulas)
        rows = [c + [c[-1]] * (width - len(c)) for _, c in model.mode_formulas]  # pad: repeat
        fns.append(Function("mode_formulas", [params],
                            [("omega", sp.Matrix([[model.formulas[n] for n, _ in r] for r in rows])),
                             ("estimate", sp.Matrix([[e + FORMULA_ROUNDING for _, e in r] for r in rows]))],
                            "Approximate natural frequencies, a row per mode (metadata "
                            "'mode_formulas'), a column per candidate formula, with each "
                            "candidate's relative error estimate (plus 64 eps of rounding).", MATRICES))
    fns.append(Function("mass_matrix", [params, ("q", model.q)], [("Mq", d.mass_matrix)],
                        "Mass matrix of the full nonlinear equations: Mq qdd = f.", MATRICES))
    given = [("given", model.given_values), ("dgiven", model.given_derivatives),
             ("constants", model.given_constants)] if model.given_values else []
    fns.append(Function("forcing", [params, ("q", model.q), ("qd", model.qd)] + given,
                        [("f", d.forcing)],
                        "Right-hand side f(q, qd) of the full nonlinear equations, "
                        "Mq qdd = f, with the given functions' values and derivatives as inputs."))
    return fns


def metadata(d: Derivation) -> dict:
    """JSON-serialisable facts the runtime needs without SymPy."""
    model = d.model
    order = model.reduced or [c for c in model.coordinates if c not in model.cyclic]
    return {
        "model": model.name,
        "title": model.title,
        "paper": model.source,
        "parameters": [
            {"name": p.name, "unit": p.unit, "default": p.default, "description": p.description,
             "kind": p.kind, "bounds": list(p.bounds)} for p in model.parameters],
        "coordinates": model.coordinates,
        "coordinate_units": model.coordinate_units,
        "cyclic": {c: str(s) for c, s in model.cyclic.items()},
        "momenta": [str(s) for s in model.cyclic.values() if s not in model.symbols],
        "reduced": order,
        "equilibrium_coordinates": [str(x) for x in d.even],
        "symmetric_zero": model.symmetric_zero,
        "given": [str(s) for s in model.given_values + model.given_derivatives + model.given_constants],
        "variants": {name: {"blocks": [[order[i] for i in b] for b in v.blocks]}
                     for name, v in d.variants.items()},
        "formulas": [{"name": k, "doc": model.formula_docs.get(k, "")} for k in model.formulas],
        "mode_formulas": [{"mode": label, "candidates": [n for n, _ in c]} for label, c in model.mode_formulas],
        "route_agreement": d.route_agreement,
    }
