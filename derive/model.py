"""What a model is, as data: coordinates, parameters and the functions to emit.

A model file in `derive/models/` builds a `Model`; the machinery in `derive/mechanics.py`
derives from it and `derive/emit.py` writes it out. A model never knows how it is emitted.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import sympy as sp


@dataclass(frozen=True)
class Parameter:
    """A physical parameter: its symbol, SI unit, the paper example's value and its valid range.

    `kind` says what a bad value is: 'positive' (mass, inertia, length, stiffness: > 0),
    'nonnegative' (>= 0), or 'real'. `bounds` closes the range further (inclusive).
    """

    name: str
    unit: str
    default: float
    description: str
    kind: str = "positive"
    bounds: tuple[float | None, float | None] = (None, None)

    @property
    def symbol(self) -> sp.Symbol:
        return sp.Symbol(self.name)  # no assumptions: SymEngine round trips drop them

    def check(self, value: float) -> str | None:
        """None if value is valid, else a one-line reason."""
        if not math.isfinite(value):
            return f"{self.name} must be a finite number, got {value!r}"
        if self.kind == "positive" and not value > 0:
            return f"{self.name} ({self.description}) must be positive, got {value!r}"
        if self.kind == "nonnegative" and not value >= 0:
            return f"{self.name} ({self.description}) must be non-negative, got {value!r}"
        lo, hi = self.bounds
        if lo is not None and value < lo or hi is not None and value > hi:
            return f"{self.name} ({self.description}) must lie in [{lo}, {hi}] {self.unit}, got {value!r}"
        return None


@dataclass
class Function:
    """One emitted function: named inputs (each a list of scalar symbols) and named outputs
    (each a SymPy Matrix). `doc` says what it is and where it comes from in the paper."""

    name: str
    inputs: list[tuple[str, list]]
    outputs: list[tuple[str, sp.Matrix]]
    doc: str
    # outputs that are matrices even when 1x1 (an operator of one coordinate); any other
    # one-column output is a vector
    matrices: tuple = ()


@dataclass
class Variant:
    """An approximate form of the linear operator that a paper prints.

    `approximate` maps one entry of M, D or K (taken at q = 0) to the paper's approximation;
    `row_scale` divides each equation as the print does; `printed(p)` returns the printed
    diagonal blocks; `corrections(p)` the entries where print and derivation differ."""

    approximate: Callable
    row_scale: dict
    printed: Callable | None = None
    corrections: Callable | None = None
    doc: str = ""


@dataclass
class Model:
    """A mechanical system as data: what the generic pipeline needs to derive and emit it."""

    name: str
    title: str
    source: str  # paper file it comes from
    module: str  # the Python module that defines it (its file is part of the input hash)
    parameters: list[Parameter]
    coordinates: list[str]
    coordinate_units: dict  # coordinate -> unit ('m', 'rad')
    q: list
    qd: list
    qdd: list
    lagrangian: object  # L = T - Pi + U, SymPy expression in q, qd and parameters
    # Given functions in L (e.g. imperfections f_s(gamma3)): each applied function and its
    # derivative is replaced by an input symbol in the emitted nonlinear equations.
    given_functions: list = field(default_factory=list)
    given_values: list = field(default_factory=list)
    given_derivatives: list = field(default_factory=list)
    given_constants: list = field(default_factory=list)  # symbols used only with them (e.g. h)
    cyclic: dict = field(default_factory=dict)  # coordinate -> momentum parameter symbol
    reduced: list[str] = field(default_factory=list)  # order of the operator's coordinates
    symmetric_zero: list[str] = field(default_factory=list)  # zero at the equilibrium
    equilibrium_approx: dict = field(default_factory=dict)  # coordinate -> formula
    identities: dict = field(default_factory=dict)  # name -> callable() -> residuals == 0
    variants: dict = field(default_factory=dict)  # name -> Variant
    formulas: dict = field(default_factory=dict)  # name -> SymPy expression in parameters
    formula_docs: dict = field(default_factory=dict)  # name -> equation number and reading
    # approximate natural frequencies, one entry per mode: (label, [(formula name, relative
    # error estimate as an expression in the parameters), ...]); the runtime takes, per
    # parameter set and mode, the candidate whose own estimate is smallest
    mode_formulas: list = field(default_factory=list)

    def param(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def symbols(self) -> list[sp.Symbol]:
        return [p.symbol for p in self.parameters]

    @property
    def defaults(self) -> dict[str, float]:
        return {p.name: p.default for p in self.parameters}

    def coordinate(self, name: str):
        return self.q[self.coordinates.index(name)]

    def velocity(self, name: str):
        return self.qd[self.coordinates.index(name)]

    def acceleration(self, name: str):
        return self.qdd[self.coordinates.index(name)]
