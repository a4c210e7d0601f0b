"""Approximate forms of the operator that a paper prints, and the characteristic
polynomial of each of their diagonal blocks."""
from __future__ import annotations

import sympy as sp

from derive.model import Function
from derive.outputs.operator import MATRICES

ORDER = 30


def functions(d) -> list[Function]:
    model, params = d.model, [("params", d.model.symbols)]
    fns = []
    for vname, v in d.variants.items():
        fns.append(Function(f"{vname}_operator", params,
                            [("M", v.operator.M), ("D", v.operator.D), ("K", v.operator.K)],
                            f"Operator of the '{vname}' variant ({model.variants[vname].doc}); "
                            "rows not scaled.", MATRICES))
        fns.append(Function(f"{vname}_charpoly", params,
                            [(f"block{i + 1}", sp.Matrix(c)) for i, c in enumerate(v.charpoly)],
                            f"Characteristic polynomial of each diagonal block of the '{vname}' "
                            "operator: coefficients of det J_block in z = p^2, lowest degree first."))
        for name in model.variants[vname].perturbations:
            sym = _parameter(model, name)
            fns.append(Function(f"{vname}_charpoly_d{name}", params,
                                [(f"block{i + 1}", sp.Matrix([sp.diff(x, sym) for x in c]))
                                 for i, c in enumerate(v.charpoly)],
                                f"The first-order effect of {name} on each block's characteristic "
                                f"polynomial of the '{vname}' operator: d/d{name} of its coefficients "
                                "in z = p^2, lowest degree first."))
    return fns


def _parameter(model, name: str):
    from derive.model import Unsupported

    for s in model.symbols:
        if str(s) == name:
            return s
    raise Unsupported(f"{model.name}: a variant's perturbation {name!r} is not a parameter")


def metadata(d) -> dict:
    return {"variants": {name: {"blocks": [[d.order[i] for i in b] for b in v.blocks]}
                         for name, v in d.variants.items()}}
