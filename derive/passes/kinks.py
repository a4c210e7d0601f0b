"""Each sign(u), H(u) of the model (Abs, Max, Min rewritten in them) a symbol of its own, a
kink (derive/nonsmooth.py), until the thaw pass makes each its function again."""
from __future__ import annotations

import dataclasses

import sympy as sp

from derive import nonsmooth
from derive.model import Load, Model, Unsupported

ORDER = 30
ROUTES = ("coordinates", "multipliers")


def frozen(model: Model, kinks: nonsmooth.Kinks) -> Model:
    """The model with each sign(u), H(u) (Abs, Max, Min rewritten in them) a kink symbol."""
    fr, nonsmooth_ = kinks.freeze, nonsmooth.NONSMOOTH
    out = dataclasses.replace(
        model, lagrangian=fr(model.lagrangian), dissipation=fr(model.dissipation),
        loads=[Load(sp.Matrix(ld.vector).applyfunc(fr), sp.Matrix(ld.velocity).applyfunc(fr), ld.name)
               for ld in model.loads] if any(sp.Matrix(ld.vector).has(*nonsmooth_) or sp.Matrix(ld.velocity).has(
                   *nonsmooth_) for ld in model.loads) else model.loads,
        generalized_forces={k: fr(v) for k, v in model.generalized_forces.items()})
    return out if kinks.kinks else model


def run(model: Model, d):
    d.work.source, d.work.kinks = model, nonsmooth.Kinks()
    d.model = frozen(model, d.work.kinks)
    if d.work.kinks.kinks and d.route == "multipliers":
        raise Unsupported(f"{model.name}: non-smooth functions together with holonomic constraints "
                          "that need multipliers")
    return d
