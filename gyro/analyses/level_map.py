"""The error of one level of a model's hierarchy against another over a grid of two
parameters (`gyro level-map`): for any model that declares levels (docs/hierarchy.md) and
any question both levels answer, the entry at each grid point is the largest relative error
over the question's quantities, `gyro.analyses.scene.level_error`, the question's own
measure (frequencies: relative to each frequency; motion: the largest deviation relative to
the motion's largest excursion). Nothing here knows a model or a question by name.
"""
from __future__ import annotations

import math
import time

import numpy as np

from gyro import levels as hierarchy
from gyro import questions
from gyro.errors import ParameterError, grid_axis

MAX_POINTS = 10**4  # grid points of one map


def parse_axis(flag: str, text: str, names) -> tuple[str, float, float, int]:
    """NAME=LO:HI:N over one of `names` -> (name, lo, hi, n)."""
    return grid_axis(flag, text, names, 200, "parameter")


def question_of(model, level: str, against: str, question: str | None = None) -> str:
    """The question both levels answer (`question`, or the first they share), checking the
    levels: ParameterError naming --level, --against or --question."""
    known = hierarchy.levels(model)
    if not known:
        raise ParameterError(f"level-map: {model.name} declares no levels")
    names = [lv.name for lv in known]  # and a family's name (linear_exact) where it is not a level's own
    names += sorted({lv.family for lv in known if lv.family} - set(names))
    for flag, name in (("--level", level), ("--against", against)):
        if name not in names:
            raise ParameterError(f"{flag}: unknown level {name!r} of {model.name}; known: {', '.join(names)}")
    a, r = hierarchy.get(model, level), hierarchy.get(model, against)
    if a.name == r.name:
        raise ParameterError(f"--against {against}: the same level as --level")
    shared = [q for q in a.answers if q in r.answers and a.answers[q] is not None and r.answers[q] is not None]
    if question is not None:
        if question not in shared:
            raise ParameterError(f"--question {question}: not answered by both {a.name} and {r.name}; "
                                 f"they share: {', '.join(shared) or 'none'}")
        return question
    if not shared:
        raise ParameterError(f"--against {against}: {a.name} and {r.name} answer no common question")
    return shared[0]


def level_map(model, level: str, against: str, xaxis, yaxis, sets: dict, tol: float,
              question: str | None = None, opts: dict | None = None, progress: bool = False):
    """An error Map: the error of `level` against `against` at every point of the grid
    (xaxis, yaxis: (name, lo, hi, n)), the other parameters from `sets` (model names,
    values checked: ParameterError naming the point); NaN where either level could not
    answer (then `failed` says so)."""
    from gyro.analyses.scene import level_error
    from gyro.results import Map

    q = question_of(model, level, against, question)
    if not (math.isfinite(tol) and 0 < tol < 1):
        raise ParameterError(f"--tol must lie in (0, 1), got {tol!r}")
    for ax in (xaxis, yaxis):
        if ax[0] in sets:
            raise ParameterError(f"parameter {ax[0]}: is an axis; do not --set it")
    if xaxis[0] == yaxis[0]:
        raise ParameterError(f"--y {yaxis[0]}: the same parameter as --x")
    xs, ys = np.linspace(*xaxis[1:3], xaxis[3]), np.linspace(*yaxis[1:3], yaxis[3])
    if xs.size * ys.size > MAX_POINTS:
        raise ParameterError(f"--x, --y: {xs.size * ys.size} points; at most {MAX_POINTS}")
    rows = []
    for yv in ys:
        for xv in xs:
            try:
                rows.append(model.vector({**sets, xaxis[0]: xv, yaxis[0]: yv}))
            except ParameterError as exc:
                raise ParameterError(f"at {xaxis[0]} = {xv:g}, {yaxis[0]} = {yv:g}: {exc}") from None
    P = np.array(rows)
    c0 = time.perf_counter()
    err = np.full(P.shape[0], np.nan)
    chunks = np.array_split(np.arange(P.shape[0]), max(1, min(P.shape[0], 50)))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=P.shape[0], desc=f"level-map {level} vs {against}", unit="pt", leave=False)
    for idx in chunks:
        e, _ = level_error(model, q, level, against, P[idx], opts)
        with np.errstate(all="ignore"):
            err[idx] = np.where(np.isnan(e).any(axis=1), np.nan, np.max(e, axis=1, initial=-np.inf))
        if bar is not None:
            bar.update(idx.size)
    if bar is not None:
        bar.close()
    values = err.reshape(ys.size, xs.size)
    failed = {f"{i},{j}": "a level could not answer here" for i, j in zip(*np.nonzero(~np.isfinite(values)))}
    defaults = model.defaults
    changed = {k: float(v) for k, v in sets.items() if float(v) != defaults.get(k)}
    units = {p.name: p.unit for p in model.params}
    measure = f"largest relative error of the {q} question over its quantities ({', '.join(questions.get(q).quantities(model, opts or {}))})"
    info = {"level": hierarchy.get(model, level).name, "against": hierarchy.get(model, against).name,
            "tol": float(tol), "measure": measure, "changed": changed, "failed": failed,
            "seconds": time.perf_counter() - c0}
    return Map("error", model.name, model.meta["title"], xaxis[0], yaxis[0], xs, ys, values, units=units, info=info)
