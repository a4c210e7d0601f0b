"""What a model is, as data: coordinates, parameters, energies, forces, signals.

A model file (in `derive/models/`, or anywhere: `python -m derive --model PATH.py`) builds a
`Model`; the machinery in `derive/mechanics.py` derives from it, the output kinds in
`derive/outputs/` turn the derivation into functions, and `derive/emit.py` writes them out.
A model never knows how it is emitted.

Time is the symbol `TIME` (t): every total time derivative of the machinery includes the
partial derivative in t, so a Lagrangian or a force may depend on t explicitly. A quantity
given as a function of time that is not a closed-form expression of t (a base rate u(t), a
support motion, an applied moment) is a `Signal`: its value and derivatives are symbols
that the emitted functions take as inputs at each instant.
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


TIME = sp.Symbol("t")  # explicit time in Lagrangians, forces and signals


class Unsupported(ValueError):
    """What the machinery cannot derive (a nonholonomic constraint, a force on a cyclic
    coordinate, a signal differentiated beyond its declared order): refused at derive time,
    with a message naming the cause, never derived wrongly."""


@dataclass(frozen=True)
class Signal:
    """A given function of time: `name`, `name_d`, `name_dd`, ... are its value and its first
    `order` derivatives, inputs of the emitted functions at each instant.

    `input=True` (an applied moment, a bearing imperfection, a control): an input w of the
    linearisation, nominally zero; its columns form B in M q'' + (G + D_s) q' + K q = B w.
    `input=False` (a base rate u(t), a support motion): a time-varying parameter that stays
    in the linear operator, which is then a function of its values."""

    name: str
    unit: str
    description: str
    input: bool = True
    order: int = 2
    # the name of a parameter that this signal makes time-varying (a base rate u_xi(t) of a
    # constant u_xi), with input=False: the model is written in the parameter, derived and
    # emitted at its constant value as if no such signal were declared, and the full
    # equations and each quantity that contains the parameter are emitted once more,
    # NAME_varying, with the parameter the signal's value and its derivatives entering
    # through d/dt (docs/models.md)
    parameter: str | None = None

    @property
    def symbols(self) -> list:
        return [sp.Symbol(self.name + ("_" + "d" * k if k else "")) for k in range(self.order + 1)]

    @property
    def symbol(self) -> sp.Symbol:
        return self.symbols[0]


@dataclass(frozen=True)
class Load:
    """An applied force on a point, or a moment on a body: `vector` and the `velocity` of its
    point (the angular velocity of its body, for a moment), in the same components.
    Its generalised forces are Q_k = vector . d velocity / d qd_k (virtual power)."""

    vector: object
    velocity: object
    name: str = ""


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
    # outputs emitted as their structural nonzeros only: the values in a fixed order
    # (row-major over the matrix), their (row, column) positions in metadata.json
    sparse: tuple = ()


@dataclass
class Variant:
    """An approximate form of the linear operator that a paper prints.

    `approximate` maps one entry of M, D or K (taken at q = 0) to the paper's approximation;
    `row_scale` divides each equation as the print does; `printed(p)` returns the printed
    diagonal blocks; `corrections(p)` the entries where print and derivation differ.
    `perturbations` names parameters whose first-order effect on each block's
    characteristic polynomial is emitted (`<variant>_charpoly_d<name>`: the coefficients
    differentiated by the parameter), for a level that evaluates the polynomial at a limit
    of that parameter and estimates the roots' shift to its actual value."""

    approximate: Callable
    row_scale: dict
    printed: Callable | None = None
    corrections: Callable | None = None
    doc: str = ""
    perturbations: tuple = ()


@dataclass(frozen=True)
class Bound:
    """The a-priori relative error bound of one answered quantity of a level
    (docs/hierarchy.md): `expression`, in the parameters, emitted and evaluated per set,
    plus, with `estimate=True`, the evaluator's own per-quantity error estimate (a method's
    rounding estimate, a formula's derived estimate), evaluated with the answer."""

    expression: object = 0
    estimate: bool = False


@dataclass(frozen=True)
class Level:
    """One level of a model's hierarchy (docs/hierarchy.md): a named way to answer
    questions, a model approximation and the method that evaluates it.

    `neglects` says what the approximation drops; `evaluator` (JSON data) how the runtime
    evaluates it, {"kind": ..., options}, a kind that the answered questions know
    (gyro/questions/); `answers` maps each question to a Bound for all its quantities or a
    list of Bounds, one per quantity in the question's order (None: not answered);
    `valid` names the edges of validity, name -> expression that is > 0 wherever the bounds
    hold; `cost` is the measured time per set on one core (s, bench/levels.py), None to
    take the evaluator's own (a ladder method's COST); `reference` the level its error
    maps are measured against."""

    name: str
    neglects: str
    evaluator: dict
    answers: dict
    valid: dict = field(default_factory=dict)
    cost: float | dict | None = None  # a dict {method: s} for a declaration of several methods
    reference: str | None = None
    doc: str = ""


def runtime_module(model, name: str) -> str:
    """How the runtime finds a module a model declares (a simulate hook, a level's evaluator):
    a dotted name it can import where the module lies outside the model's own folder (the
    package's gyro.systems.<system>), else "file:" and the module's path relative to the
    model file's folder: the model file itself (`__name__`) or a Python file beside it,
    which the runtime cannot import by the name the derivation used, and finds beside the
    file it loads the model from (gyro.catalog.declared_module). Relative, so that no byte
    depends on where a checkout lives: one derivation in the cache serves every checkout
    with the same files (an absolute path named the first checkout, and broke when it went)."""
    import importlib.util
    import sys
    from pathlib import Path

    own = sys.modules.get(model.module)
    folder = Path(own.__file__).resolve().parent if own is not None and getattr(own, "__file__", None) else None
    if name in sys.modules and getattr(sys.modules[name], "__file__", None):
        origin = sys.modules[name].__file__
    else:
        try:
            spec = importlib.util.find_spec(name)
        except (ImportError, ValueError):
            spec = None
        if spec is None or not spec.origin:
            raise Unsupported(f"{model.name}: the declared module {name!r} cannot be found")
        origin = spec.origin
    origin = Path(origin).resolve()
    if name == model.module or (folder is not None and folder in origin.parents and
                                not (Path(__file__).resolve().parents[1] / "gyro") in origin.parents):
        if folder is not None and folder in origin.parents:
            return f"file:{origin.relative_to(folder).as_posix()}"
        return f"file:{origin}"  # a module without a folder of its own: only where it is
    return name


@dataclass(frozen=True)
class Conditions:
    """A named set of sufficient conditions for the stability of the model's equilibrium
    (Model.conditions): it holds where every margin is > 0. `margins` is a list of
    (label, expression in the parameters), each label one line that names the margin (the
    labels of all a model's sets are distinct); `doc` says where the set comes from and what
    it assumes. The derivation emits the margins (`conditions`) and a rounding bound of each
    (`conditions_rounding`, derive/outputs/conditions.py); `gyro stability` and `gyro map`
    read the set against the spectrum of the linearisation (gyro/analyses/conditions.py)."""

    margins: list
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
    # generalised forces beyond the Lagrangian: a Rayleigh dissipation function F(q, qd)
    # (Q_k = -dF/dqd_k), applied forces and moments (Load), and generalised forces given
    # directly (coordinate name -> Q_k); any of them may depend on t and on signals
    dissipation: object = 0
    loads: list = field(default_factory=list)
    generalized_forces: dict = field(default_factory=dict)
    signals: list = field(default_factory=list)  # Signal
    # a steady motion the model declares: coordinate -> its constant rate (an expression of
    # the parameters); those coordinates must be ignorable (absent from L and the forces).
    # The operator is then about q = q0 + rate t, over every coordinate not Routh-reduced.
    steady: dict = field(default_factory=dict)
    # constraints between velocities that are not derivatives of coordinate constraints
    # (rolling, knife edges): the machinery has no multipliers for them and refuses them
    nonholonomic: list = field(default_factory=list)
    # constraints between the coordinates (and time), each an expression that is zero on
    # every motion: eliminated symbolically where they can be solved for dependent
    # coordinates, else carried by Lagrange multipliers (derive/constraints.py)
    holonomic: list = field(default_factory=list)
    # the inertial ReferenceFrame of sympy.physics.mechanics, for loads written as sympy's
    # (Point, Vector) or (ReferenceFrame, Vector) (derive/convert.py)
    frame: object = None
    # model quantities that analyses need, emitted like everything else: name ->
    # (input groups, outputs [(name, Matrix)], doc); groups among params, q, qd, momenta,
    # time, signals, and (name, [symbols]) for inputs of the quantity's own
    quantities: dict = field(default_factory=dict)
    # approximate natural frequencies, one entry per mode: (label, [(formula name, relative
    # error estimate as an expression in the parameters), ...]); the runtime takes, per
    # parameter set and mode, the candidate whose own estimate is smallest
    mode_formulas: list = field(default_factory=list)
    # the model's hierarchy: Level declarations (docs/hierarchy.md), cheapest to most exact
    # or in any order (the runtime orders them by cost)
    levels: list = field(default_factory=list)
    # the spin, for Campbell diagrams and harmonic lines (derive/outputs/spin.py):
    # {"parameter": name of the parameter that sets it, "rate": the spin rate in rad/s as an
    # expression of the parameters (default: the parameter itself), "whirl": [(a, b), ...]
    # pairs of reduced coordinates whose orbit a -> b turns with the spin (forward whirl),
    # "angle": optionally the coordinate that is the spin angle, cyclic or steady; its rate at
    # the reference is the spin's, and the given functions of it are the harmonic inputs;
    # "harmonics": (what those inputs are, their unit), for the output of `gyro forced`}
    spin: dict = field(default_factory=dict)
    # a motion of the model's own for `gyro simulate` (the gimbal gyroscope's closed form, the
    # precession levels), in place of the generic integration from the reference:
    # {"module": a dotted module name offering simulate_command(model, args, cli) -> a result
    # with plot/to_dict/table, "options": the flags it takes among perturb, method, level,
    # base_rate, "usage": one line `gyro params` prints; "initial": where the module's INITIAL
    # (name -> (unit, default, description)) are taken as --set NAME=VALUE, a note on the
    # coordinates they leave out ("psi(0) = phi(0) = 0"), which `gyro params` prints with them}
    simulate: dict = field(default_factory=dict)
    # named sets of sufficient stability conditions: name -> Conditions (each holds where
    # every margin > 0; derive/outputs/conditions.py emits the margins and their rounding
    # bounds); `gyro stability` and `gyro map` need them
    conditions: dict = field(default_factory=dict)
    # the runtime module (dotted name, gyro.systems.<system>) with what only this system has:
    # the hooks the generic analyses call (which condition applies where, derived map axes,
    # options; gyro/analyses/conditions.py lists them); None: the generic analyses alone
    system: str | None = None
    # names a user types for parameters whose symbol the emitted code cannot carry (the
    # paper's lambda is `lam`, M_motor `Mmotor`): {name typed: parameter's name}; every
    # command and the API take either (gyro.models.Model.parameters)
    aliases: dict = field(default_factory=dict)
    # kinematic differential equations (sympy.physics.mechanics' kd_eqs, System's kdes):
    # expressions zero on every motion, linear in the speeds `qd` (dynamicsymbols u(t))
    # and the coordinates' derivatives q'(t), as KanesMethod takes them. With them the
    # speeds are any n independent combinations of the rates (a body's angular-velocity
    # components); without them a speed must be its coordinate's rate (derive/convert.py
    # checks it and refuses what it cannot check)
    kinematics: list = field(default_factory=list)
    # set by the conversion from `kinematics` (derive/convert.py): {"u": the speeds'
    # symbols, "V", "v": the rates q_d = V u + v, in the machinery's symbols}
    speeds: dict = field(default_factory=dict)

    @property
    def signal_symbols(self) -> list:
        return [s for sig in self.signals for s in sig.symbols]

    @property
    def input_signal_symbols(self) -> list:
        return [s for sig in self.signals if sig.input for s in sig.symbols]

    @property
    def has_forces(self) -> bool:
        return bool(self.dissipation != 0 or self.loads or self.generalized_forces)

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
