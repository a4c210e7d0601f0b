"""The questions a level can answer, one module each, found here without a list
(docs/hierarchy.md, "Adding a question").

A question module has NAME (the command line's name) and:

- `quantities(model, opts) -> list[str]`: the quantities it answers, in order; a level
  declares one bound for all of them or one each, in this order;
- `requested(model, opts) -> list[int]`: the indices the user asked for (`--modes`);
- `answer(model, level, P, opts) -> Answer`: the level's answer over a batch, by the
  level's evaluator kind (`level.evaluator["kind"]`); a kind the question does not know
  is a ValueError naming it;
- `edges(model, answer, bound, idx, answered) -> array of str`: per set, the question's own
  edge of validity crossed ('' where none: veering of two modes, a merged root, no
  verdict); `answered` (quantities,) is False where the level declares no bound;
- `error(answer, reference) -> (sets, quantities)`: the relative error against another
  level's answer (error maps);
- `document(model, answer, k, idx) -> dict`: the question's JSON keys for set k.
- optionally `subset(opts, rows, n) -> opts`: the options for the sets `rows` of a batch
  of n, where an option is given per set (the motion's initial conditions);
- optionally VALUES: the key of `document` holding the per-quantity answer, which the
  scene's table shows beside each quantity's bound;
- optionally `certify(model, level, P, answer, bound, idx) -> array of str` and
  `certificate_cost(level, idx) -> s`: for a level whose evaluator says "certify", the
  proof of each set's answer within `bound` against the exact model ('' where proven, the
  reason otherwise) and its cost per set, which the selector adds to the level's in its
  order (gyro.analyses.scene.proven, candidates); optionally `certificate_data(model, P)`:
  what the certificates of the levels a set tries share (made once per set), an object
  with `take(rows)` whose view certify gets as `data=`.

- optionally `floor(model, level, P, opts) -> (sets,)`: per set, a bound below which the
  level cannot answer the requested quantities, known before it runs (an integrator's
  tolerance on the motion's size): the selector passes the level over where it is above
  the tolerance, as it does for the a-priori part of a bound (gyro.analyses.scene).

- optionally OPTIONS: {flag: help} of the command-line options it takes (`gyro scene`
  registers every question's and refuses one the question asked does not take), and
  `options(model, P, tol, given, initial) -> opts`: `given` {flag: text} parsed and checked
  (ParameterError naming the flag), with `initial` the question's own inputs given.

`names()` reads NAME from the sources (no NumPy); `get(name)` imports one.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np


@dataclass
class Answer:
    """One level's answer over a batch: values (sets, quantities), the evaluator's own
    relative error estimate of each (None where it gives none), a per-set failure reason
    ('' where it answered) and the question's other per-set data."""

    values: np.ndarray
    estimate: np.ndarray | None
    failed: np.ndarray
    extra: dict = field(default_factory=dict)

    def take(self, rows) -> "Answer":
        pick = lambda a: None if a is None else a[rows]  # noqa: E731
        return Answer(self.values[rows], pick(self.estimate), self.failed[rows],
                      {k: pick(v) for k, v in self.extra.items()})


@lru_cache(maxsize=None)
def _declared() -> dict:
    """NAME -> module, from each module's source."""
    from gyro.catalog import module_constants

    return {c["NAME"]: m for m, c in module_constants(__path__[0], ("NAME",)).items() if "NAME" in c}


def names() -> tuple:
    return tuple(sorted(_declared()))


def get(name: str):
    from gyro.errors import ParameterError

    if name not in _declared():
        raise ParameterError(f"question: unknown {name!r}; known: {', '.join(names())}")
    return importlib.import_module(f"{__name__}.{_declared()[name]}")


def evaluator_module(level, model=None):
    """The module a level's evaluator declares ("module": a dotted name; gyro.systems.<system>
    for the papers' models, any importable module for a user's); ParameterError in one line
    where it is missing or cannot be imported."""
    from gyro.errors import ParameterError

    name = level.evaluator.get("module")
    if not name:
        raise ParameterError(f"level {level.name}: its evaluator of kind {level.evaluator.get('kind')!r} names no "
                             "module (\"module\": a dotted name)")
    from gyro.catalog import declared_module

    return declared_module(name, f"level {level.name}", model)


def unknown_kind(question: str, level) -> ValueError:
    return ValueError(f"level {level.name}: the question {question!r} has no evaluator of kind "
                      f"{level.evaluator.get('kind')!r}")
