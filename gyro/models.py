"""Loading a generated model and turning user input into a validated parameter vector."""
from __future__ import annotations

import importlib
import importlib.util
import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from gyro.catalog import GENERATED_PACKAGE, available, generated_dir  # noqa: F401
from gyro.errors import ParameterError

GENERATED = generated_dir()


@dataclass(frozen=True)
class Param:
    name: str
    unit: str
    default: float
    description: str
    kind: str
    bounds: tuple

    def check(self, value: float) -> None:
        if not math.isfinite(value):
            raise ParameterError(f"parameter {self.name}: must be a finite number, got {value!r}")
        if self.kind == "positive" and not value > 0:
            raise ParameterError(f"parameter {self.name} ({self.description}) must be positive, got {value!r}")
        if self.kind == "nonnegative" and not value >= 0:
            raise ParameterError(f"parameter {self.name} ({self.description}) must be non-negative, got {value!r}")
        lo, hi = self.bounds
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            raise ParameterError(f"parameter {self.name} ({self.description}) must lie in "
                                 f"[{lo}, {hi}] {self.unit}, got {value!r}")


class Model:
    """A generated model: its metadata and its NumPy and CasADi functions.

    `Model(name)` is a model of the repository's generated/; `Model(name, directory)` one
    that `python -m derive --model PATH.py --out DIR` emitted into directory = DIR/<name>."""

    def __init__(self, name: str, directory: Path | None = None):
        if directory is None:
            known = available()
            if name not in known:
                raise ParameterError(f"unknown model {name!r}; known: {', '.join(known)}")
            package = f"{GENERATED_PACKAGE}.{name}"
            self.directory = GENERATED / name
        else:
            self.directory = Path(directory).resolve()
            if not (self.directory / "metadata.json").exists():
                raise ParameterError(f"{self.directory}: no generated model there (no metadata.json)")
            package = _import_directory(self.directory)
        pkg = importlib.import_module(package)
        if pkg.METADATA["model"] != name:
            raise ParameterError(f"{self.directory} holds the model {pkg.METADATA['model']!r}, not {name!r}")
        self.package = package
        self.name = name
        self.meta = pkg.METADATA
        self.params = [Param(p["name"], p["unit"], p["default"], p["description"], p["kind"],
                             tuple(p["bounds"])) for p in self.meta["parameters"]]
        self.param_names = [p.name for p in self.params]

    @cached_property
    def numpy(self):
        """The generated NumPy functions (imported on first use: the compiled path needs none)."""
        return importlib.import_module(f"{self.package}.numpy_functions")

    @cached_property
    def casadi(self):
        return importlib.import_module(f"{self.package}.casadi_functions")

    @cached_property
    def mpmath(self):
        return importlib.import_module(f"{self.package}.mpmath_functions")

    @property
    def defaults(self) -> dict[str, float]:
        return {p.name: p.default for p in self.params}

    def parameters(self, overrides: dict | None = None) -> dict[str, float]:
        """Every parameter's value: the paper example's, replaced by `overrides`; validated."""
        values = self.defaults
        by_name = {p.name: p for p in self.params}
        for key, raw in (overrides or {}).items():
            if key not in by_name:
                raise ParameterError(f"unknown parameter {key!r} for {self.name}; known: {' '.join(self.param_names)}")
            try:
                value = float(raw)
            except (TypeError, ValueError):
                raise ParameterError(f"parameter {key}: not a number: {raw!r}") from None
            by_name[key].check(value)
            values[key] = value
        return values

    def vector(self, values: dict[str, float] | None = None) -> np.ndarray:
        """The parameter vector, in the order of param_names: the given values, validated,
        and the paper example's for the others; an unknown name is a ParameterError
        naming it."""
        v = self.parameters(values)
        return np.array([v[n] for n in self.param_names], dtype=float)

    def vectors(self, batch: list[dict]) -> np.ndarray:
        """Parameter vectors of several sets (rows), each completed as `vector` does."""
        return np.array([self.vector(v) for v in batch], dtype=float)


def _import_directory(directory: Path) -> str:
    """Import a generated package from a folder anywhere, under a private name."""
    import hashlib
    import importlib.util
    import sys

    name = "_gyro_model_" + hashlib.sha256(str(directory).encode()).hexdigest()[:12]
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, directory / "__init__.py",
                                                      submodule_search_locations=[str(directory)])
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return name


_CACHE: dict[str, Model] = {}


def load(name: str | Path) -> Model:
    """A generated model by name (generated/<name>), or by the folder it was emitted into
    (a path: DIR/<name> from `python -m derive --model PATH.py --out DIR`); the compiled
    backend then finds it by its name."""
    if isinstance(name, Path) or "/" in str(name) or "\\" in str(name):
        directory = Path(name).resolve()
        model_name = directory.name
        known = _CACHE.get(model_name)
        if known is None or known.directory != directory:
            _CACHE[model_name] = Model(model_name, directory)
        return _CACHE[model_name]
    if name not in _CACHE:
        _CACHE[name] = Model(name)
    return _CACHE[name]
