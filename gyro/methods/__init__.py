"""The frequency methods, one module each, found here without a list. A method module has
NAME (the command line's name), RUNG (its place on the ladder of accuracy), COST (seconds
per set on one core, measured by bench/ladder.py: the relative cost a selector compares)
and `solve(model, P, tol) -> gyro.results.Spectrum` over a batch P (sets, parameters)."""
from __future__ import annotations

import importlib
import pkgutil
from functools import lru_cache


@lru_cache(maxsize=None)
def registry() -> dict:
    """NAME -> module, in the order of the ladder (RUNG)."""
    mods = [importlib.import_module(f"{__name__}.{m.name}") for m in pkgutil.iter_modules(__path__)
            if not m.name.startswith("_")]
    return {m.NAME: m for m in sorted(mods, key=lambda m: m.RUNG)}
