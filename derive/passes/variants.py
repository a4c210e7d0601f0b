"""The model's approximate variants (Model.variants): the operator at q = 0 with the
variant's approximations, its blocks, the characteristic polynomial of each in z = p^2,
and J(p) with rows scaled as the variant prints them."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.derivation import VariantResult
from derive.model import Model

ORDER = 110
ROUTES = ("coordinates", "multipliers")

P_SYMBOL = sp.Symbol("p")  # the operator d/dt
Z_SYMBOL = sp.Symbol("z")  # p^2


def run(model: Model, d):
    for vname, variant in model.variants.items():
        with d.work.steps(f"variant '{vname}': approximations, blocks, polynomials per block"):
            at0 = {x: 0 for x in d.rq}
            opv = d.operator.subs(at0).applyfunc(variant.approximate)
            J = opv.J(P_SYMBOL)
            blk = mech.blocks(J)
            polys = [mech.charpoly_in_p2(J.extract(b, b), P_SYMBOL, Z_SYMBOL) for b in blk]
            scale = [variant.row_scale.get(c, 1) for c in d.order]
            scaled = sp.Matrix(len(d.order), len(d.order), lambda i, j: sp.expand(J[i, j] / scale[i]))
            d.variants[vname] = VariantResult(opv, blk, polys, scaled)
    return d
