"""The models: one file (or folder) each, found here without a list. A model module defines
`build()` returning a `derive.model.Model` whose name is the module's name."""
from __future__ import annotations

import pkgutil
from pathlib import Path


def _discover() -> dict[str, str]:
    return {m.name: f"{__name__}.{m.name}" for m in pkgutil.iter_modules([str(Path(__file__).parent)])
            if not m.name.startswith("_")}


MODELS = _discover()  # model name -> module
