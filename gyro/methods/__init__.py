"""The frequency methods, one module each, found here without a list. A method module has
NAME (the command line's name), RUNG (its place on the ladder of accuracy), COST (seconds
per set on one core, measured by bench/ladder.py: the relative cost a selector compares)
and `solve(model, P, tol) -> gyro.results.Spectrum` over a batch P (sets, parameters).
`names()` reads NAME and RUNG from the sources (no NumPy: the command line's choices);
`get(name)` imports one method."""
from __future__ import annotations

import ast
import importlib
import pkgutil
from functools import lru_cache
from pathlib import Path

DEFAULT_TOL = 1e-10  # the relative error the default method answers within


@lru_cache(maxsize=None)
def _declared() -> dict:
    """module -> (NAME, RUNG), from each module's source."""
    out = {}
    for m in pkgutil.iter_modules(__path__):
        if m.name.startswith("_"):
            continue
        consts = {}
        for node in ast.parse((Path(__path__[0]) / f"{m.name}.py").read_text()).body:
            if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
                if node.targets[0].id in ("NAME", "RUNG") and isinstance(node.value, ast.Constant):
                    consts[node.targets[0].id] = node.value.value
        if "NAME" in consts:
            out[m.name] = (consts["NAME"], consts.get("RUNG", 99))
    return out


def names() -> tuple:
    """The methods' names in the order of the ladder (RUNG)."""
    return tuple(n for n, _ in sorted(_declared().values(), key=lambda nr: nr[1]))


def get(name: str):
    """The module of one method."""
    mod = {n: m for m, (n, _) in _declared().items()}[name]
    return importlib.import_module(f"{__name__}.{mod}")
