"""The model's hierarchy of levels (docs/hierarchy.md): each level's declaration as
metadata, and its a-priori error bounds and edges of validity as two emitted functions,
`level_bounds` (one row per declared bound expression) and `level_validity` (one row per
edge: > 0 where the bounds hold)."""
from __future__ import annotations

import json

import sympy as sp

from derive.model import Bound, Function, Unsupported, runtime_module

ORDER = 45


def _layout(model):
    """(metadata of every level, bound expressions, validity expressions): rows in order."""
    bounds, margins, levels = [], [], []
    names = [lv.name for lv in model.levels]
    if len(set(names)) != len(names):
        raise Unsupported(f"{model.name}: level names repeat: {names}")
    # a ladder declaration stands for one level per method, LEVEL:METHOD
    names += [f"{lv.name}:{m}" for lv in model.levels for m in lv.evaluator.get("methods", [])]

    def row(b):
        if b is None:
            return None
        if not isinstance(b, Bound):
            raise Unsupported(f"{model.name}: a level's bound must be a Bound or None, got {b!r}")
        expr = sp.sympify(b.expression)
        entry = {"row": None, "estimate": bool(b.estimate)}
        if expr != 0:
            free = expr.free_symbols - set(model.symbols)
            if free:
                raise Unsupported(f"{model.name}: a bound uses symbols that are not parameters: {sorted(map(str, free))}")
            entry["row"] = len(bounds)
            bounds.append(expr)
        return entry

    for lv in model.levels:
        try:
            json.dumps(lv.evaluator)
        except TypeError:
            raise Unsupported(f"{model.name}: level {lv.name}: its evaluator must be JSON data") from None
        if lv.reference is not None and lv.reference not in names:
            raise Unsupported(f"{model.name}: level {lv.name}: unknown reference level {lv.reference!r}")
        answers = {}
        for q, spec in lv.answers.items():
            answers[q] = [row(b) for b in spec] if isinstance(spec, (list, tuple)) else row(spec)
        valid = []
        for vname, expr in lv.valid.items():
            valid.append({"name": vname, "row": len(margins)})
            margins.append(sp.sympify(expr))
        evaluator = dict(lv.evaluator)
        if "module" in evaluator:
            evaluator["module"] = runtime_module(model, evaluator["module"])
        levels.append({"name": lv.name, "neglects": lv.neglects, "evaluator": evaluator,
                       "answers": answers, "valid": valid, "cost": lv.cost,
                       "reference": lv.reference, "doc": lv.doc})
    return levels, bounds, margins


def functions(d) -> list[Function]:
    model, params = d.model, [("params", d.model.symbols)]
    _, bounds, margins = _layout(model)
    fns = []
    if bounds:
        fns.append(Function("level_bounds", params, [("bounds", sp.Matrix(bounds))],
                            "A-priori relative error bounds of the model's levels, in the rows "
                            "of metadata 'levels' (docs/hierarchy.md)."))
    if margins:
        fns.append(Function("level_validity", params, [("margins", sp.Matrix(margins))],
                            "Edges of validity of the model's levels: each row > 0 where the "
                            "level's bounds hold (metadata 'levels')."))
    return fns


def metadata(d) -> dict:
    return {"levels": _layout(d.model)[0]} if d.model.levels else {}
