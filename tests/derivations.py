"""Every model's derivation, once per test process (a module of its own: the one cache that
the fixtures of conftest.py and the test files share)."""
from __future__ import annotations

_DERIVED = {}


def derived(name: str):
    """(model, derivation, functions by name) of any model, derived once per session."""
    if name not in _DERIVED:
        import importlib
        import io

        from derive import pipeline
        from derive.models import MODELS

        model = importlib.import_module(MODELS[name]).build()
        d = pipeline.derive(model, pipeline.Steps(out=io.StringIO()))
        _DERIVED[name] = (model, d, {f.name: f for f in pipeline.functions(d)})
    return _DERIVED[name]
