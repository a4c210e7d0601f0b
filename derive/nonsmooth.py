"""Non-smooth forces and potentials: sign, Abs, Heaviside, Max and Min.

`Abs(u)` is written u sign(u), `Max(a, b)` b + (a - b) H(a - b) and `Min(a, b)`
b + (a - b) H(b - a) (H the Heaviside step), so that two piecewise-constant functions,
sign and H, are left. Each application sign(u) or H(u) is then a symbol of its own (a
"kink") through the derivation: its derivative is zero wherever u != 0, which is the
derivative of the expression there (u sign(u) and (a - b) H(a - b) have no delta part,
since u delta(u) = 0). At the end each kink becomes its function again: sign(u) and
H(u) (H(0) = 1/2). An entry of the linear operator or of B that is the derivative of an
equation with a kink in a variable that its argument depends on does not exist where
the argument is zero: there it is NaN (`undefined_where`), never a number.

What is refused, at derive time, in one line naming the term:
- a kink of a rate in the Lagrangian (its momentum would jump: an impulse);
- a Lagrangian that jumps across a kink (a step potential: an impulsive force);

A reference where the argument of a kink is zero (Coulomb friction sign(x') about rest)
has no linearisation: the entries that need the derivative there are NaN at every set, and
the full nonlinear equations are derived and emitted as everywhere else. A reference where
it is not zero (friction on a moving belt, about rest) is linearised, NaN only at the sets
where it is zero. Each kink whose derivative an entry needs is recorded
(`Kinks.nondifferentiable`: its term, and its argument at the reference) and emitted into
metadata ('nondifferentiable'), so that the runtime names the term when it refuses an
operator that does not exist.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import reduce

import sympy as sp

from derive.model import Unsupported

NONSMOOTH = (sp.sign, sp.Heaviside, sp.Abs, sp.Max, sp.Min)  # what is frozen into kinks


@dataclass(frozen=True)
class Kink:
    symbol: sp.Symbol  # what stands for it during the derivation
    function: object  # sp.sign or sp.Heaviside
    argument: object  # u

    @property
    def term(self):
        return self.function(self.argument)

    @property
    def sides(self) -> tuple:
        return (1, -1) if self.function is sp.sign else (1, 0)


def _max2(a, b):
    return b + (a - b) * sp.Heaviside(a - b)


def _min2(a, b):
    return b + (a - b) * sp.Heaviside(b - a)


def rewrite(expr):
    """Abs, Max and Min in terms of sign and Heaviside (the Heaviside step with H(0) = 1/2)."""
    e = sp.sympify(expr)
    if not e.has(sp.Abs, sp.Max, sp.Min):
        return e
    e = e.replace(lambda x: isinstance(x, sp.Abs), lambda x: x.args[0] * sp.sign(x.args[0]))
    e = e.replace(lambda x: isinstance(x, sp.Max), lambda x: reduce(_max2, x.args))
    e = e.replace(lambda x: isinstance(x, sp.Min), lambda x: reduce(_min2, x.args))
    return e


class Kinks:
    """The kinks of a model: each sign(u) or H(u) once, with its symbol."""

    def __init__(self):
        self.by_term: dict = {}
        # term -> its argument at the reference, for each kink an entry of the operator or
        # of B needs the derivative of (undefined_where): "0" where it never exists
        self.nondifferentiable: dict = {}

    def freeze(self, expr):
        e = rewrite(expr)
        if not e.has(sp.sign, sp.Heaviside):
            return e
        # innermost first: a kink inside another's argument is frozen in it too
        terms = sorted(e.atoms(sp.sign, sp.Heaviside), key=lambda x: sp.count_ops(x))
        for term in terms:
            arg = self.freeze(term.args[0])
            if isinstance(term, sp.Heaviside) and len(term.args) > 1 and term.args[1] != sp.Rational(1, 2):
                raise Unsupported(f"{term}: a Heaviside step with H(0) = {term.args[1]}: write Heaviside(u) (H(0) = 1/2)")
            key = (type(term), arg)
            if key not in self.by_term:
                fn = sp.sign if isinstance(term, sp.sign) else sp.Heaviside
                self.by_term[key] = Kink(sp.Symbol(f"_kink{len(self.by_term)}"), fn, arg)
        mapping = {t: self.by_term[(type(t), self.freeze(t.args[0]))].symbol for t in terms}
        return e.xreplace(mapping)

    @property
    def kinks(self) -> list[Kink]:
        return list(self.by_term.values())

    @property
    def symbols(self) -> set:
        return {k.symbol for k in self.kinks}

    def thaw(self, expr, at: dict | None = None):
        """The expression (or Matrix) with each kink's function back, innermost last, its
        argument taken at `at` (the reference, for what is evaluated there)."""
        if not self.by_term:
            return expr
        mapping = {k.symbol: k.term.subs(at) if at else k.term for k in self.kinks}
        if isinstance(expr, sp.MatrixBase):
            return expr.applyfunc(lambda e: self._thaw1(e, mapping))
        return self._thaw1(expr, mapping)

    @staticmethod
    def _thaw1(e, mapping):
        e = sp.sympify(e)
        for _ in range(len(mapping) + 1):  # arguments may hold other kinks
            if not e.free_symbols & set(mapping):
                return e
            e = e.xreplace(mapping)
        return e


def is_zero(expr) -> bool:
    """expr is identically zero: decided exactly by cancel where it is a rational function of
    its symbols (a kink's argument v - x_d at the reference), by simplify otherwise (0.01-0.04 s
    a call on the smallest argument, the better part of a 1-DOF derivation)."""
    e = sp.sympify(expr)
    if e == 0:
        return True
    if e.is_rational_function():
        return sp.cancel(e) == 0
    return sp.simplify(e) == 0


def check_lagrangian(L, kinks: Kinks, rates, name: str) -> None:
    """The Lagrangian is continuous across each of its kinks and has none in a rate."""
    rates = set(rates)
    for k in kinks.kinks:
        if k.symbol not in L.free_symbols:
            continue
        if k.argument.free_symbols & rates:
            raise Unsupported(f"{name}: {k.term} in the Lagrangian: a non-smooth function of the rates makes "
                              "the momentum jump (an impulse); write it as a force (generalized_forces, dissipation)")
        hi, lo = (L.subs(k.symbol, s) for s in k.sides)
        jump = sp.expand(hi - lo)
        if jump == 0:
            continue
        var = sorted(k.argument.free_symbols, key=str)
        sols = []
        for v in var:
            try:
                sols = sp.solve(sp.Eq(k.argument, 0), v)
            except NotImplementedError:
                sols = []
            if sols:
                break
        if not sols or any(not is_zero(jump.subs(v, s)) for s in sols):
            raise Unsupported(f"{name}: the Lagrangian jumps where {k.argument} = 0 ({k.term}): a step in the "
                              "potential is an impulsive force; write a continuous potential (Abs, Max, "
                              "Heaviside times a power of its argument) or the force in generalized_forces")


def undefined_where(kinks: Kinks, equations, variables, reference: dict, name: str) -> sp.Matrix:
    """Markers for the Jacobian of `equations` in `variables` at the reference: entry (i, j)
    is 0 wherever it exists and NaN where the argument u of a kink of equation i that
    depends on variable j is zero (a Piecewise, NaN where u = 0). At a reference where
    such an argument is zero identically, the derivative exists if the equation and its
    derivative are the same on both sides of the kink (quadratic drag -|v| v at rest);
    anything else (Coulomb friction sign(v) at rest) has no derivative there: NaN at every
    set. Each kink met is recorded in kinks.nondifferentiable."""
    out = sp.zeros(len(equations), len(variables))
    for i, e in enumerate(equations):
        free = sp.sympify(e).free_symbols
        for k in kinks.kinks:
            if k.symbol not in free:
                continue
            u = kinks.thaw(k.argument)
            for j, x in enumerate(variables):
                if sp.diff(u, x) == 0:
                    continue
                at = u.subs(reference)
                if not is_zero(at):
                    out[i, j] += sp.Piecewise((sp.nan, sp.Eq(at, 0)), (0, True))
                    kinks.nondifferentiable[str(kinks.thaw(k.term))] = str(at)
                    continue
                # at the kink: the derivative exists if the equation and its derivative
                # (the kink held) are the same on both sides there, as -|v| v at v = 0
                both = [(e_.subs(k.symbol, side), sp.diff(e_, x).subs(k.symbol, side))
                        for e_ in [sp.sympify(e)] for side in k.sides]
                if any(not is_zero(kinks.thaw(a - b).subs(reference)) for a, b in zip(*both)):
                    out[i, j] = sp.nan  # at every set: the reference sits on the kink
                    kinks.nondifferentiable[str(kinks.thaw(k.term))] = "0"
    return out
