"""The error of one level of a model's hierarchy against a more exact one, over a grid of two
parameters (`gyro level-map`).

Generic over models: a model's levels are offered by an analysis module that defines
`HIERARCHY`, an object with `model`, `levels` (names, most exact first), `measure` (what
the error measures), `parameters(sets)` (validated values from NAME=VALUE text),
`units()`, `defaults()`, `answer(level, values, t_end)` and `error(answer, exact_answer)`
(a relative error, NaN where it has no scale). The modules are found by reading the
sources of gyro/analyses for a top-level `HIERARCHY =`, without importing them.
"""
from __future__ import annotations

import importlib
import math
import pkgutil
import time
from pathlib import Path

import numpy as np

from gyro.errors import ParameterError, finite_number

MAX_POINTS = 10**4  # grid points of one map (each integrates two levels)


def providers() -> dict:
    """model name -> analysis module that declares its hierarchy."""
    import re

    here = Path(__file__).parent
    out = {}
    for m in pkgutil.iter_modules([str(here)]):
        src = (here / f"{m.name}.py").read_text() if (here / f"{m.name}.py").exists() else ""
        if "\nHIERARCHY = " in src:
            found = re.search(r'^MODEL = "([A-Za-z0-9_]+)"', src, re.M)
            if found:
                out[found.group(1)] = f"{__package__}.{m.name}"
    return out


def hierarchy(model: str):
    known = providers()
    if model not in known:
        raise ParameterError(f"level-map: model {model!r} declares no levels; models with levels: "
                             f"{', '.join(sorted(known)) or 'none'}")
    return importlib.import_module(known[model]).HIERARCHY


def parse_axis(flag: str, text: str, names) -> tuple[str, float, float, int]:
    """NAME=LO:HI:N -> (name, lo, hi, n), or ParameterError naming the flag."""
    name, sep, rng = str(text).partition("=")
    parts = rng.split(":")
    if not sep or len(parts) != 3:
        raise ParameterError(f"{flag} {text!r}: expected NAME=LO:HI:N")
    name = name.strip()
    if name not in names:
        raise ParameterError(f"{flag} {name!r}: unknown parameter; known: {' '.join(names)}")
    lo, hi = (finite_number(f"{flag} {name}", p) for p in parts[:2])
    try:
        n = int(parts[2])
    except ValueError:
        raise ParameterError(f"{flag} {name}: N not an integer: {parts[2]!r}") from None
    if not lo < hi:
        raise ParameterError(f"{flag} {name}: need LO < HI, got {lo!r}:{hi!r}")
    if not 2 <= n <= 200:
        raise ParameterError(f"{flag} {name}: N must lie in [2, 200], got {n}")
    return name, lo, hi, n


def check_levels(h, level: str, against: str) -> None:
    for flag, name in (("--level", level), ("--against", against)):
        if name not in h.levels:
            raise ParameterError(f"{flag}: unknown level {name!r} of {h.model}; known: {', '.join(h.levels)}")
    if not h.levels.index(against) < h.levels.index(level):
        raise ParameterError(f"--against {against}: must be more exact than --level {level} "
                             f"(levels, most exact first: {', '.join(h.levels)})")


def level_map(h, level: str, against: str, xaxis, yaxis, sets: dict, t_end: float, tol: float,
              progress: bool = False):
    """LevelMap: the error of `level` against `against` at every point of the grid
    (xaxis, yaxis: (name, lo, hi, n)), the other parameters from `sets`. Every point's
    parameters are checked before anything is integrated (ParameterError naming the point);
    a point where a level cannot be computed (a singular motion, a failed integration) is
    NaN, its reason in `failed`."""
    from gyro.results import LevelMap

    check_levels(h, level, against)
    if not (math.isfinite(tol) and 0 < tol < 1):
        raise ParameterError(f"--tol must lie in (0, 1), got {tol!r}")
    if not (math.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"--t-end must be positive, got {t_end!r}")
    for ax in (xaxis, yaxis):
        if ax[0] in sets:
            raise ParameterError(f"parameter {ax[0]}: is an axis; do not --set it")
    if xaxis[0] == yaxis[0]:
        raise ParameterError(f"--y {yaxis[0]}: the same parameter as --x")
    xs, ys = np.linspace(*xaxis[1:3], xaxis[3]), np.linspace(*yaxis[1:3], yaxis[3])
    if xs.size * ys.size > MAX_POINTS:
        raise ParameterError(f"--x, --y: {xs.size * ys.size} points; at most {MAX_POINTS}")
    points = []
    for yv in ys:
        for xv in xs:
            try:
                points.append(h.parameters({**sets, xaxis[0]: xv, yaxis[0]: yv}))
            except ParameterError as exc:
                raise ParameterError(f"at {xaxis[0]} = {xv:g}, {yaxis[0]} = {yv:g}: {exc}") from None
    values = np.full((ys.size, xs.size), np.nan)
    failed = {}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(points), desc=f"level-map {level} vs {against}", unit="pt", leave=False)
    c0 = time.perf_counter()
    for k, p in enumerate(points):
        i, j = divmod(k, xs.size)
        try:
            e = h.error(h.answer(level, p, t_end), h.answer(against, p, t_end))
            values[i, j] = e
            if not math.isfinite(e):
                failed[f"{i},{j}"] = "no scale: the exact level's answer does not move"
        except (ParameterError, FloatingPointError, RuntimeError) as exc:
            failed[f"{i},{j}"] = str(exc)
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    defaults = h.defaults()
    changed = {k: float(v) for k, v in sets.items() if float(v) != defaults.get(k)}
    return LevelMap(h.model, level, against, xaxis[0], yaxis[0], xs, ys, values, float(tol), h.measure,
                    h.units(), changed, failed, time.perf_counter() - c0)
