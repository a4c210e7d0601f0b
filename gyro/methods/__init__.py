"""The frequency methods, one module each, found here without a list. A method module has
NAME (the command line's name), RUNG (its place on the ladder of accuracy), COST (seconds
per set on one core, measured by bench/ladder.py: the relative cost a selector compares)
and `solve(model, P, tol) -> gyro.results.Spectrum` over a batch P (sets, parameters).
`names()` reads NAME and RUNG from the sources (no NumPy: the command line's choices);
`get(name)` imports one method."""
from __future__ import annotations

import importlib
from functools import lru_cache

DEFAULT_TOL = 1e-10  # the relative error the default method answers within


@lru_cache(maxsize=None)
def _declared() -> dict:
    """module -> (NAME, RUNG), from each module's source."""
    from gyro.catalog import module_constants

    return {m: (c["NAME"], c.get("RUNG", 99)) for m, c in module_constants(__path__[0], ("NAME", "RUNG")).items()
            if "NAME" in c}


def names() -> tuple:
    """The methods' names in the order of the ladder (RUNG)."""
    return tuple(n for n, _ in sorted(_declared().values(), key=lambda nr: nr[1]))


def get(name: str):
    """The module of one method."""
    mod = {n: m for m, (n, _) in _declared().items()}[name]
    return importlib.import_module(f"{__name__}.{mod}")
