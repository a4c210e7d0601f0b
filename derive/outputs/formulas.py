"""The paper's approximate formulas, and the approximate natural frequencies per mode with
each candidate's relative error estimate."""
from __future__ import annotations

import sympy as sp

from derive.model import Function
from derive.outputs.operator import MATRICES

ORDER = 40
# every formula's estimate also carries the rounding of evaluating it in double precision
# (a few hundred operations): 64 eps
FORMULA_ROUNDING = sp.Float(2.0**-46)


def functions(d) -> list[Function]:
    model, params = d.model, [("params", d.model.symbols)]
    fns = []
    if model.formulas:
        fns.append(Function("formulas", params,
                            [("values", sp.Matrix(list(model.formulas.values())))],
                            "The paper's approximate formulas, in the order of metadata "
                            "'formulas'."))
    if model.mode_formulas:
        width = max(len(c) for _, c in model.mode_formulas)
        rows = [c + [c[-1]] * (width - len(c)) for _, c in model.mode_formulas]  # pad: repeat
        fns.append(Function("mode_formulas", params,
                            [("omega", sp.Matrix([[model.formulas[n] for n, _ in r] for r in rows])),
                             ("estimate", sp.Matrix([[e + FORMULA_ROUNDING for _, e in r] for r in rows]))],
                            "Approximate natural frequencies, a row per mode (metadata "
                            "'mode_formulas'), a column per candidate formula, with each "
                            "candidate's relative error estimate (plus 64 eps of rounding).", MATRICES))
    return fns


def metadata(d) -> dict:
    model = d.model
    return {"formulas": [{"name": k, "doc": model.formula_docs.get(k, "")} for k in model.formulas],
            "mode_formulas": [{"mode": label, "candidates": [n for n, _ in c]}
                              for label, c in model.mode_formulas]}
