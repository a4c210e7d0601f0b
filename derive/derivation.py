"""The result of a derivation (derive/pipeline.py): what the output kinds of
derive/outputs/ turn into functions and metadata. A leaf: it imports the model's data and
the machinery's types, no step of the derivation, so that every pass of derive/passes/
fills it without importing another step.

A derivation starts as `Derivation(model)`; each pass fills its part. What one pass hands
to a later one and no output kind reads (the Lagrangian without inputs, the kinks, the
second route's operator) is in `work`, emptied by the last pass."""
from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import sympy as sp

from derive import mechanics as mech
from derive import names
from derive.model import TIME, Function, Model


@dataclass
class VariantResult:
    operator: mech.LinearOperator  # unscaled, over the reduced coordinates
    blocks: list[list[int]]  # indices into the reduced coordinates
    charpoly: list[list]  # per block: coefficients of det J_block in z = p^2, lowest first
    scaled: sp.Matrix  # J(p) with rows divided as the print does


@dataclass
class Derivation:
    model: Model
    mass_matrix: sp.Matrix | None = None  # full nonlinear equations: mass_matrix * qdd = forcing
    forcing: sp.Matrix | None = None
    routhian: object = None
    rq: list = field(default_factory=list)  # reduced coordinates, velocities, accelerations (operator order)
    rqd: list = field(default_factory=list)
    rqdd: list = field(default_factory=list)
    even: list = field(default_factory=list)  # reduced coordinates that are unknowns of the reference
    equilibrium_residual: sp.Matrix | None = None  # minus the equations at the reference, function of `even`
    operator: mech.LinearOperator | None = None  # exact, at the reference, function of `even`
    route_agreement: float | None = None  # max |route1 - route2| / max |route2| at random points (None: one route)
    order: list = field(default_factory=list)  # names of the reduced coordinates
    rates: dict = field(default_factory=dict)  # velocity symbol -> rate on a steady motion
    inputs: list = field(default_factory=list)  # w: columns of B (symbols)
    input_matrix: sp.Matrix | None = None  # B of M q'' + D q' + K q = B w
    time_dependent: bool = False  # t appears in the Lagrangian or the forces
    variants: dict[str, VariantResult] = field(default_factory=dict)
    functions: list[Function] = field(default_factory=list)
    timings: list = field(default_factory=list)
    constraints: dict = field(default_factory=dict)  # holonomic: eliminated, or multipliers
    # the parameters made signals (Signal.parameter): {"signals": every signal of the model in
    # its order, "varying": those that make a parameter time-varying, "mass_matrix",
    # "forcing": the full equations with those parameters the signals' values, "sub":
    # parameter symbol -> the signal's value}; empty for a model without them
    varying: dict = field(default_factory=dict)
    # a model given in speeds u with kinematic equations (Model.kinematics): its equations
    # in them, as KanesMethod forms them: {"u", "kinematics": q_d = V u + v, "mass_matrix",
    # "forcing": mass_matrix u_d = forcing in (q, u)} (speeds_equations)
    speeds: dict = field(default_factory=dict)
    # non-smooth terms whose derivative the operator or B needs: term -> its argument at
    # the reference ("0": the reference sits on the kink, the operator exists at no set)
    nondifferentiable: dict = field(default_factory=dict)
    # how the equations are formed: "coordinates" (independent ones, after any elimination
    # of holonomic constraints) or "multipliers" (derive/constraints.py); each pass of
    # derive/passes/ names the routes it runs on (ROUTES)
    route: str = "coordinates"
    # what passes hand to later passes (`steps`, the printer of timed steps, among them)
    work: SimpleNamespace = field(default_factory=SimpleNamespace)

    @property
    def momenta(self) -> list:
        """The cyclic momenta that are inputs (symbols that are not parameters)."""
        return names.momentum_inputs(self.model)

    @property
    def driven(self) -> list:
        """The symbols of the signals that stay in the operator (not inputs w)."""
        return [s for sig in self.model.signals if not sig.input for s in sig.symbols]

    def state(self, with_qe: bool = True) -> list:
        """The input groups of everything about the reference: params, qe, momenta, time,
        the driven signals; each present only when the model has it."""
        g = [("params", self.model.symbols)]
        if with_qe:
            g.append(("qe", self.even))
        if self.momenta:
            g.append(("momenta", self.momenta))
        if self.time_dependent:
            g.append(("time", [TIME]))
        if self.driven:
            g.append(("signals", self.driven))
        return g
