"""A model's hierarchy of levels, as declared beside the model (docs/hierarchy.md).

A level is data: the model file declares it (`derive.model.Level`), the derivation emits
it into metadata.json ('levels') with its a-priori bounds and edges of validity as two
generated functions (`level_bounds`, `level_validity`). This module reads the declaration:
which questions a level answers, its bound per quantity as a rule evaluated per set (the
emitted expression, plus the evaluator's own estimate where declared), where the bound
cannot be evaluated, and its measured cost. It knows no model and no question by name.

A ladder declaration's bound expression is the rounding of its inputs in double precision
(the conditioning of u cos(phi) near the pole); the methods it names in "exact_inputs"
evaluate the parameters in their own precision and carry only their estimate.

One declaration may name several methods ({"kind": ..., "methods": [...]}): it stands for
one level per method, named LEVEL:METHOD, each costing its entry of a declared cost
{METHOD: s}, or, for a method of the frequency ladder, the method's COST. That is the ladder's axis of the hierarchy; the model approximations are
the other.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.models import Model


@dataclass(frozen=True)
class Level:
    """One level as the runtime sees it (one per method for a ladder declaration)."""

    name: str
    neglects: str
    evaluator: dict  # {"kind": ..., options}; a spectrum level has "method"
    answers: dict  # question -> one bound entry {"row", "estimate"} or a list (None: not answered)
    valid: tuple = ()  # ({"name", "row"}, ...)
    declared_cost: float | None = None
    reference: str | None = None
    doc: str = ""
    family: str = ""  # the declaration's name (a ladder declaration's levels share it)
    meta: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def cost(self) -> float:
        """Seconds per set on one core: declared (measured by bench/levels.py), or, for a
        method of the ladder, the method's COST."""
        if self.declared_cost is not None:
            return float(self.declared_cost)
        if "method" in self.evaluator:
            from gyro.methods import get

            return float(get(self.evaluator["method"]).COST)
        return float("inf")  # a level without a measured cost comes last

    def answers_question(self, question: str) -> bool:
        return question in self.answers


# Every model with an operator about its equilibrium and no spectrum level of its own has
# this one: the exact operator by each method of the ladder, bounded by the method's own
# estimate (a model written by a user answers `gyro scene MODEL frequencies` without
# declaring a hierarchy). A model that declares a spectrum level keeps its own.
IMPLICIT_EXACT = {
    "name": "linear_exact",
    "neglects": "nothing of the linearised motion about the model's equilibrium",
    "evaluator": {"kind": "spectrum", "methods": ["polyroots", "companion", "default", "reference"],
                  "default": "default"},
    "answers": {"frequencies": {"estimate": True, "row": None}, "stability": {"estimate": True, "row": None}},
    "valid": [], "cost": None, "reference": "linear_exact:reference",
    "doc": "the exact operator about the equilibrium, by a method of the ladder (implicit: every model "
           "with an operator and no spectrum level of its own has it)",
}


def declarations(model_or_meta) -> list[dict]:
    """The level declarations of a model (its metadata's 'levels'), with IMPLICIT_EXACT
    where the model has an operator and declares no spectrum level."""
    from gyro.models import has_operator

    meta = model_or_meta if isinstance(model_or_meta, dict) else model_or_meta.meta
    found = list(meta.get("levels", []))
    if has_operator(meta) and not any(d["evaluator"].get("kind") == "spectrum" for d in found):
        found.append(IMPLICIT_EXACT)
    return found


def levels(model: Model) -> list[Level]:
    """The model's levels, cheapest first (ties: in the declared order)."""
    out = []
    for d in declarations(model):
        ev = d["evaluator"]
        methods = ev.get("methods")
        if methods:
            for m in methods:
                e = {k: v for k, v in ev.items() if k != "methods"}
                e["method"] = m
                cost = d["cost"].get(m) if isinstance(d["cost"], dict) else d["cost"]
                out.append(Level(f"{d['name']}:{m}", d["neglects"], e, d["answers"], tuple(d["valid"]),
                                 cost, d["reference"], d["doc"], d["name"], d))
        else:
            out.append(Level(d["name"], d["neglects"], ev, d["answers"], tuple(d["valid"]),
                             d["cost"], d["reference"], d["doc"], d["name"], d))
    order = sorted(range(len(out)), key=lambda i: (out[i].cost, i))
    return [out[i] for i in order]


def get(model: Model, name: str) -> Level:
    """One level by name (a ladder declaration's name alone means its first method that is
    the declaration's `default`, else its last)."""
    known = levels(model)
    for lv in known:
        if lv.name == name:
            return lv
    family = [lv for lv in known if lv.family == name]
    if family:
        want = family[0].meta["evaluator"].get("default")
        return next((lv for lv in family if lv.evaluator.get("method") == want), family[-1])
    from gyro.errors import ParameterError

    raise ParameterError(f"level: unknown {name!r} for {model.name}; known: {', '.join(lv.name for lv in known)}")


def _rows(model: Model, function: str, P: np.ndarray) -> np.ndarray:
    """Every row of an emitted bound or validity function over the batch: (sets, rows)."""
    if function not in model.meta["functions"]:
        return np.zeros((P.shape[0], 0))
    from gyro.kernels import function as generated

    with np.errstate(all="ignore"):
        (v,) = generated(model, function)(P)
    return np.reshape(np.asarray(v, dtype=float), (P.shape[0], -1))


@dataclass
class Bounds:
    """A level's a-priori part of the bound over a batch, per quantity, and what it needs
    from the answer: `apriori` (sets, quantities), inf where the quantity is not answered;
    `estimate` (quantities,) whether the evaluator's own estimate is added; `invalid`
    (sets,) the name of the first edge of validity crossed, '' where none."""

    apriori: np.ndarray
    estimate: np.ndarray
    invalid: np.ndarray
    answered: np.ndarray | None = None  # (quantities,) False where the level declares no bound
    bad: np.ndarray | None = None  # (sets,) True beyond an edge (invalid != '')

    def __post_init__(self):
        if self.bad is None:
            self.bad = self.invalid != ""

    def total(self, own_estimate: np.ndarray | None) -> np.ndarray:
        """The bound per set and quantity: the a-priori part plus, where declared, the
        evaluator's estimate; not finite (NaN) counts as unbounded; inf on an invalid set."""
        b = self.apriori.copy()
        if self.estimate.any():
            own = np.full(b.shape, np.inf) if own_estimate is None else np.asarray(own_estimate, dtype=float)
            b = b + np.where(self.estimate[None, :], own, 0.0)
        b[np.isnan(b)] = np.inf
        b[self.bad] = np.inf
        return b


def bounds(model: Model, level: Level, question: str, P: np.ndarray, n_quantities: int) -> Bounds:
    """The declared bound of `level` for `question` over the batch P (sets, parameters),
    for a question of n_quantities quantities (one declared bound for all, or one each)."""
    N = P.shape[0]
    spec = level.answers.get(question)
    if spec is None:
        return Bounds(np.full((N, n_quantities), np.inf), np.zeros(n_quantities, bool),
                      np.full(N, "not answered", object), np.zeros(n_quantities, bool))
    entries = spec if isinstance(spec, list) else [spec] * n_quantities
    if len(entries) != n_quantities:
        raise ValueError(f"level {level.name}: {len(entries)} bounds declared for {question}, "
                         f"the question has {n_quantities} quantities")
    rows = _rows(model, "level_bounds", P) if any(e and e["row"] is not None for e in entries) else None
    apriori = np.zeros((N, n_quantities))
    estimate = np.zeros(n_quantities, bool)
    for j, e in enumerate(entries):
        if e is None:
            apriori[:, j] = np.inf
            continue
        if e["row"] is not None and level.evaluator.get("method") not in level.evaluator.get("exact_inputs", ()):
            apriori[:, j] = np.abs(rows[:, e["row"]])
        estimate[j] = e["estimate"]
    invalid = np.full(N, "", object)
    any_bad = np.zeros(N, bool)
    if level.valid:
        margins = _rows(model, "level_validity", P)
        for v in reversed(level.valid):  # the first edge crossed names the reason
            bad = ~(margins[:, v["row"]] > 0)  # NaN: cannot be evaluated there
            invalid[bad] = v["name"]
            any_bad |= bad
    return Bounds(apriori, estimate, invalid, np.array([e is not None for e in entries]), any_bad)
