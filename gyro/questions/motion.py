"""`motion`: a motion over a horizon (`--horizon T`, s): the quantities are the
coordinates the level's analysis reports (its evaluator's `quantities`), each over time.

Evaluator kind: `trajectory`, {"kind": "trajectory", "analysis": MODULE, "method": NAME,
"quantities": [...]}: `gyro.analyses.MODULE.level_motion(model, P_row, method, horizon)`
returns (t, series (quantities, times), estimate or None, failure reason or ''), the
estimate the level's own relative error bound of the motion (docs/hierarchy.md).
The error of a motion against another level's: max over t of |q - q_ref| over all
quantities, relative to the largest excursion of q_ref from its start (the motion's own
size); infinite where the reference does not move.
"""
from __future__ import annotations

import importlib

import numpy as np

from gyro.questions import Answer, unknown_kind

NAME = "motion"
DEFAULT_HORIZON = 10.0  # s


def _declared_quantities(model) -> list:
    for d in model.meta.get("levels", []):
        if "motion" in d["answers"] and d["evaluator"].get("kind") == "trajectory":
            return list(d["evaluator"]["quantities"])
    return []


def quantities(model, opts) -> list[str]:
    return _declared_quantities(model)


def requested(model, opts) -> list[int]:
    return list(range(len(_declared_quantities(model))))


def answer(model, level, P, opts) -> Answer:
    ev = level.evaluator
    if ev.get("kind") != "trajectory":
        raise unknown_kind(NAME, level)
    mod = importlib.import_module(f"gyro.analyses.{ev['analysis']}")
    horizon = float(opts.get("horizon") or DEFAULT_HORIZON)
    nq = len(ev["quantities"])
    N = P.shape[0]
    finals = np.full((N, nq), np.nan)
    est = np.full((N, nq), np.inf)
    failed = np.full(N, "", object)
    series, times = [None] * N, [None] * N
    for k in range(N):
        t, s, e, why = mod.level_motion(model, P[k], ev["method"], horizon)
        failed[k] = why
        if not why:
            series[k], times[k] = s, t
            finals[k] = s[:, -1]
            est[k] = np.inf if e is None else e
    return Answer(finals, est, failed, {"series": _objects(series), "t": _objects(times),
                                        "names": _objects([ev["quantities"]] * N)})


def _objects(items) -> np.ndarray:
    """One object per set (an array over time each), not a stacked array."""
    out = np.empty(len(items), dtype=object)
    for k, v in enumerate(items):
        out[k] = v
    return out


def edges(model, ans: Answer, bound: np.ndarray, idx) -> np.ndarray:
    return np.full(ans.values.shape[0], "", object)


def error(ans: Answer, ref: Answer) -> np.ndarray:
    N, nq = ans.values.shape
    err = np.full((N, nq), np.nan)
    for k in range(N):
        a, r = ans.extra["series"][k], ref.extra["series"][k]
        a = None if a is None else np.asarray(a, dtype=float)
        r = None if r is None else np.asarray(r, dtype=float)
        if a is None or r is None or a.shape != r.shape:
            continue
        scale = np.sqrt(((r - r[:, :1]) ** 2).sum(axis=0)).max()
        d = np.sqrt(((a - r) ** 2).sum(axis=0)).max()
        err[k] = d / scale if scale > 0 else np.inf
    return err


def document(model, ans: Answer, k: int, idx) -> dict:
    out = {"t": [float(v) for v in ans.extra["t"][k]], "horizon": float(ans.extra["t"][k][-1])}
    for name, row in zip(ans.extra["names"][k], ans.extra["series"][k]):
        out[name] = [float(v) for v in row]
    return out
