"""Loading a generated model and turning user input into a validated parameter vector."""
from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

GENERATED = Path(__file__).resolve().parent.parent / "generated"


class ParameterError(ValueError):
    """Bad user input; the message is one line naming the parameter."""


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
    """A generated model: its metadata and its NumPy and CasADi functions."""

    def __init__(self, name: str):
        known = available()
        if name not in known:
            raise ParameterError(f"unknown model {name!r}; known: {', '.join(known)}")
        pkg = importlib.import_module(f"generated.{name}")
        self.name = name
        self.meta = pkg.METADATA
        self.params = [Param(p["name"], p["unit"], p["default"], p["description"], p["kind"],
                             tuple(p["bounds"])) for p in self.meta["parameters"]]
        self.param_names = [p.name for p in self.params]
        self.numpy = importlib.import_module(f"generated.{name}.numpy_functions")

    @cached_property
    def casadi(self):
        return importlib.import_module(f"generated.{self.name}.casadi_functions")

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

    def vector(self, values: dict[str, float]) -> np.ndarray:
        return np.array([values[n] for n in self.param_names], dtype=float)

    def vectors(self, batch: list[dict]) -> np.ndarray:
        return np.array([[v[n] for n in self.param_names] for v in batch], dtype=float)


def available() -> list[str]:
    """The generated models: folders of generated/ with a metadata.json."""
    return sorted(p.name for p in GENERATED.iterdir() if (p / "metadata.json").exists())


_CACHE: dict[str, Model] = {}


def load(name: str) -> Model:
    if name not in _CACHE:
        _CACHE[name] = Model(name)
    return _CACHE[name]
