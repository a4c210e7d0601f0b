"""`stability`: the verdict on the equilibrium (stable, marginal, unstable) from the
eigenvalues of the linearised motion; one quantity per root (|lambda|, ascending), whose
relative bound decides whether the real parts can be told from zero; a root the verdict
counts as neutral (an exact zero root, or one not resolved from zero: gyro.results.classify)
is a free direction, bounded by 0 here, since its error does not enter the verdict.

Evaluator kind: `spectrum` (a method of the ladder that computes growth rates). A verdict
is counted only where it is one: 'unknown' (an unbounded root) and 'failed' (a root not
computed) are no verdict, and the level is not enough there. A `boundary` class (rounding
could change the verdict) plugs in at `verdict`: it would be refused the same way.
"""
from __future__ import annotations

import numpy as np

from gyro.questions import Answer, unknown_kind

NAME = "stability"
NO_VERDICT = ("unknown", "failed", "boundary")


def quantities(model, opts) -> list[str]:
    return [f"lambda{j + 1}" for j in range(len(model.meta["reduced"]))]


def requested(model, opts) -> list[int]:
    return list(range(len(model.meta["reduced"])))


def verdict(spec, tol: float):
    """The verdict per set, from the spectrum with a relative noise floor tol."""
    from gyro.results import classify

    return classify(spec, rel=min(tol, 1e-9))


def answer(model, level, P, opts) -> Answer:
    if level.evaluator.get("kind") != "spectrum":
        raise unknown_kind(NAME, level)
    from gyro import ladder

    spec = ladder.spectrum(model, P, level.evaluator["method"])
    lam = np.abs(spec.growth + 1j * spec.frequencies)
    st = verdict(spec, opts.get("tol", 1e-9))
    failed = np.where(np.isin(st.label, NO_VERDICT), "no verdict (" + st.label.astype(str) + ")", "").astype(object)
    # a root the verdict counts as neutral (an exact zero root, or one not resolved from
    # zero: classify) is a free direction; its relative error does not enter the verdict
    est = np.asarray(spec.error_estimate, dtype=float)
    neutral = (lam == 0) | (np.isfinite(est) & (est >= 0.5))
    est = np.where(neutral, 0.0, est)
    return Answer(lam, est, failed,
                  {"label": st.label, "growth_rate": st.growth_rate, "unstable_roots": st.unstable_roots,
                   "growth": spec.growth, "frequencies": spec.frequencies})


def edges(model, ans: Answer, bound: np.ndarray, idx, answered) -> np.ndarray:
    return np.full(ans.values.shape[0], "", object)


def error(ans: Answer, ref: Answer) -> np.ndarray:
    with np.errstate(all="ignore"):
        err = np.abs(ans.values - ref.values) / np.abs(ref.values)
    # a different verdict is an error of the whole answer
    return np.where((ans.extra["label"] != ref.extra["label"])[:, None], np.inf, err)


def document(model, ans: Answer, k: int, idx) -> dict:
    return {"stability": {"class": str(ans.extra["label"][k]),
                          "growth_rate": float(ans.extra["growth_rate"][k]),
                          "unstable_roots": int(ans.extra["unstable_roots"][k])},
            "eigenvalues_re": [float(g) for g in ans.extra["growth"][k]],
            "frequencies": [float(f) for f in ans.extra["frequencies"][k]]}
