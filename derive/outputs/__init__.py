"""Output kinds: each module turns a derivation into the functions it contributes to the
emitted code (and, optionally, the metadata the runtime needs to call them).

A kind is a module here with `ORDER` (its place in the generated files), `functions(d)`
returning a list of `derive.model.Function`, and optionally `metadata(d)` returning a dict
merged into metadata.json. Adding a kind is adding a module: nothing else changes.
"""
from __future__ import annotations

import importlib
import pkgutil
from functools import lru_cache


@lru_cache(maxsize=None)
def kinds() -> tuple:
    """The kind modules, in their ORDER."""
    mods = [importlib.import_module(f"{__name__}.{m.name}") for m in pkgutil.iter_modules(__path__)
            if not m.name.startswith("_")]
    return tuple(sorted(mods, key=lambda m: (m.ORDER, m.__name__)))
