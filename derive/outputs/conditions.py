"""The sufficient stability conditions a model declares (Model.conditions): named sets, each a
list of (label, margin) that holds where every margin > 0. Emitted as `conditions` (every
margin of every set, in the declared order, one vector) and `conditions_rounding` (each
margin's rounding bound over the unit roundoff: `rounding_scale`), with the sets' names,
labels and docs in metadata.json (`conditions`), and the model's runtime module for what only
its system has (`system`, Model.system). `gyro stability` and `gyro map` read them
(gyro/analyses/conditions.py)."""
from __future__ import annotations

import re

import sympy as sp

from derive.model import Conditions, Function, Unsupported, runtime_module

ORDER = 66
DOTTED = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*\Z")


def rounding_scale(margin, parameters) -> sp.Expr:
    """k * sum |t| over the terms t of a margin expanded as a Laurent polynomial in the
    parameters, k = 2 d + N (d the largest number of factors in a term, N the number of
    terms): times the unit roundoff u it bounds, to first order in u, how far the margin
    computed in floating point from inputs rounded to double can lie from its exact value
    at the given decimal inputs (docs/gyrohorizoncompass.md, "Boundaries"). Each term
    t = c p1^k1 ... carries at most d input roundings (1 + delta_i, |delta_i| <= u, one per
    factor) and d - 1 product roundings; a sum of N terms adds at most N - 1 more.
    `parameters`: the model's Parameters; |t| is the term with |c| for c where its
    parameters cannot be negative ('positive', 'nonnegative') or occur to even powers, and
    carries |p| for a 'real' parameter p to an odd power. Unsupported for a margin that is
    not a Laurent polynomial in the parameters (a square root, a sine: no rule here)."""
    kinds = {p.symbol: p.kind for p in parameters}
    terms = sp.Add.make_args(sp.expand(margin))
    degree, total = 0, sp.Integer(0)
    for t in terms:
        c, mono = t.as_coeff_Mul()
        if not c.is_Rational and not c.is_Float:
            raise Unsupported(f"rounding bound: the coefficient {c} of {t} is not a number")
        powers = {} if mono == 1 else mono.as_powers_dict()
        size = sp.Integer(1)
        for base, k in powers.items():
            if not (base.is_Symbol and k.is_Integer and base in kinds):
                raise Unsupported(f"rounding bound: {t} is not a monomial in the parameters "
                                  "(a margin must be a Laurent polynomial in them)")
            size *= (sp.Abs(base) if kinds[base] == "real" and k % 2 else base)**k
        degree = max(degree, sum(abs(int(k)) for k in powers.values()))
        total += abs(c) * size
    return (2 * degree + len(terms)) * total


def declared(model) -> list[tuple[str, list, str]]:
    """[(set name, [(label, margin)], doc)] in the declared order, checked: Unsupported
    naming what is wrong."""
    if not isinstance(model.conditions, dict):
        raise Unsupported(f"{model.name}: conditions: a dict {{name: Conditions([...], doc)}}")
    out, labels = [], set()
    symbols = set(model.symbols)
    for name, cond in model.conditions.items():
        if not isinstance(cond, Conditions):
            raise Unsupported(f"{model.name}: conditions {name!r}: a derive.model.Conditions, got {type(cond).__name__}")
        if not isinstance(name, str) or not name.strip():
            raise Unsupported(f"{model.name}: conditions: a set's name must be a non-empty string, got {name!r}")
        if not cond.margins:
            raise Unsupported(f"{model.name}: conditions {name!r}: no margin")
        margins = []
        for item in cond.margins:
            if not (isinstance(item, (tuple, list)) and len(item) == 2 and isinstance(item[0], str)):
                raise Unsupported(f"{model.name}: conditions {name!r}: each margin is (label, expression), got {item!r}")
            label, expr = item
            if label in labels:
                raise Unsupported(f"{model.name}: conditions: the label {label!r} is given twice")
            labels.add(label)
            expr = sp.sympify(expr)
            bad = sorted(map(str, expr.free_symbols - symbols))
            if bad:
                raise Unsupported(f"{model.name}: conditions {name!r}: the margin {label!r} uses "
                                  f"{', '.join(bad)}, not parameters")
            margins.append((label, expr))
        out.append((name, margins, cond.doc))
    if model.system is not None and not (isinstance(model.system, str) and DOTTED.match(model.system)):
        raise Unsupported(f"{model.name}: system: a dotted module name (gyro.systems.NAME), got {model.system!r}")
    return out


def functions(d) -> list[Function]:
    sets = declared(d.model)
    if not sets:
        return []
    labels = [label for _, margins, _ in sets for label, _ in margins]
    exprs = [e for _, margins, _ in sets for _, e in margins]
    bounds = []
    for label, e in zip(labels, exprs):
        try:
            bounds.append(rounding_scale(e, d.model.parameters))
        except Unsupported as exc:
            raise Unsupported(f"{d.model.name}: conditions: the margin {label!r}: {exc}") from None
    names = ", ".join(name for name, _, _ in sets)
    return [Function("conditions", [("params", d.model.symbols)], [("margins", sp.Matrix(exprs))],
                     f"The margins of the declared sufficient conditions ({names}), every set's in "
                     "the declared order: a set holds where each of its margins is > 0."),
            Function("conditions_rounding", [("params", d.model.symbols)], [("bounds", sp.Matrix(bounds))],
                     "Rounding bounds of the margins of `conditions`, over the unit roundoff: u times "
                     "each bounds how far the computed margin can lie from the exact one at the decimal "
                     "inputs (first order in u; k sum |t| over its terms, k = 2 d + N).")]


def metadata(d) -> dict:
    sets = declared(d.model)
    out = {}
    if sets:
        out["conditions"] = [{"name": name, "labels": [label for label, _ in margins], "doc": doc}
                             for name, margins, doc in sets]
    if d.model.system is not None:
        out["system"] = runtime_module(d.model, d.model.system)
    return out
