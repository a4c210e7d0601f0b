"""The derivation as passes: each module here is one step of it, a function
`run(model, d) -> d` of the model as the passes before have left it (`d.model`) and the one
`derive.derivation.Derivation` they fill, with `ORDER` (its place in the derivation) and
`ROUTES` (the routes it runs on: "coordinates", the equations in independent coordinates;
"multipliers", holonomic constraints carried by Lagrange multipliers, chosen by the
constraints pass; every pass takes both, tests/unit/test_passes.py). Each prints its steps with their times through `d.work.steps`.
Discovered as the output kinds of derive/outputs/ are: adding a pass is adding a module.
"""
from __future__ import annotations

import importlib
import pkgutil
from functools import lru_cache


@lru_cache(maxsize=None)
def passes() -> tuple:
    """The pass modules, in their ORDER."""
    mods = [importlib.import_module(f"{__name__}.{m.name}") for m in pkgutil.iter_modules(__path__)
            if not m.name.startswith("_")]
    return tuple(sorted(mods, key=lambda m: (m.ORDER, m.__name__)))


def run(d):
    """Every pass whose ROUTES hold the derivation's route, in their order."""
    for p in passes():
        if d.route in p.ROUTES:
            d = p.run(d.model, d)
    return d
