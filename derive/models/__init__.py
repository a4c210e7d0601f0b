"""The models: one file (or folder) each, found here without a list. A model module defines
`build()` returning a `derive.model.Model` whose name is the module's name."""
from __future__ import annotations

import pkgutil
from pathlib import Path


def _discover() -> dict[str, str]:
    """Modules (files or folders) here that define build(): a model's helper module, one
    without build(), is not taken for a model. Found by reading the source, not importing."""
    here = Path(__file__).parent
    out = {}
    for m in pkgutil.iter_modules([str(here)]):
        if m.name.startswith("_"):
            continue
        src = here / (f"{m.name}/__init__.py" if m.ispkg else f"{m.name}.py")
        if src.exists() and "\ndef build(" in src.read_text():
            out[m.name] = f"{__name__}.{m.name}"
    return out


MODELS = _discover()  # model name -> module
