"""`frequencies`: the natural frequencies of the linearised motion, ascending (rad/s); one
quantity per mode rank, omega1 the slowest. A bound on quantity j promises that the j-th
smallest frequency of the exact operator lies within bound * omega_j of the answer.

Evaluator kinds: `spectrum` (a method of the ladder on the exact operator, {"method": NAME}),
`charpoly` (the roots in z = p^2 of an emitted function's block characteristic
polynomials, {"function": NAME, "set": {PARAMETER: VALUE}} with parameters overridden, as
u = 0 for decoupled blocks). Edge of the question: where the intervals omega_j (1 +- b_j)
of two neighbouring requested modes touch (veering, a merged root), the rank of a mode is
not decided by the bound, so the bound is not a promise there.
"""
from __future__ import annotations

import numpy as np

from gyro.questions import Answer, unknown_kind

NAME = "frequencies"
VALUES = "frequencies"  # the JSON key of the per-quantity answer (the scene table shows it)
EPS = np.finfo(float).eps


def quantities(model, opts) -> list[str]:
    return [f"omega{j + 1}" for j in range(len(model.meta["reduced"]))]


def requested(model, opts) -> list[int]:
    n = len(model.meta["reduced"])
    modes = opts.get("modes")
    if not modes:
        return list(range(n))
    from gyro.errors import ParameterError

    bad = [m for m in modes if not 1 <= m <= n]
    if bad:
        raise ParameterError(f"--modes: {bad[0]} is not a mode of {model.name} (1..{n})")
    return sorted({m - 1 for m in modes})


def _ascending(f, e, g):
    """The answer in the question's order, ascending by frequency (NaN last; ties, as the
    real roots of a divergent set, in the spectrum's order): a spectrum comes ranked by
    |lambda|, which puts a divergent pair (frequency 0) above a slow oscillation."""
    order = np.argsort(np.where(np.isnan(f), np.inf, f), axis=1, kind="stable")
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    return take(f), take(e), take(g)


def _spectrum(model, level, P):
    from gyro import ladder

    spec = ladder.spectrum(model, P, level.evaluator["method"])
    f, e, g = _ascending(spec.frequencies, spec.error_estimate, spec.growth)
    failed = np.full(f.shape[0], "", object)
    failed[~np.all(np.isfinite(f), axis=1)] = "a frequency could not be computed"
    return Answer(f, e, failed, {"growth": g})


def _poly_roots(c: np.ndarray):
    """Roots of polynomials with coefficients c (sets, degree + 1), lowest first, over the
    batch (eigenvalues of each companion matrix), with the first-order sensitivity of
    each root to a rounding of eps per coefficient: eps sum |c_k| |z|^k / |c'(z)| / |z|."""
    N, d1 = c.shape
    d = d1 - 1
    lead = c[:, -1]
    C = np.zeros((N, d, d))
    C[:, 1:, :-1] = np.eye(d - 1)
    with np.errstate(all="ignore"):
        C[:, :, -1] = -c[:, :-1] / lead[:, None]
        good = np.all(np.isfinite(C), axis=(1, 2))
        z = np.full((N, d), np.nan + 0j)
        if good.any():
            z[good] = np.linalg.eigvals(C[good])
        k = np.arange(d1)
        az = np.abs(z)
        num = np.sum(np.abs(c)[:, None, :] * az[..., None] ** k, axis=2)
        dc = c[:, 1:] * np.arange(1, d1)
        der = np.abs(np.sum(dc[:, None, :] * z[..., None] ** np.arange(d), axis=2))
        est = 4 * d * EPS * num / (der * az)
    return z, est


def _charpoly(model, level, P):
    from gyro.kernels import function

    ev = level.evaluator
    P = P.copy()
    for name, value in ev.get("set", {}).items():
        P[:, model.param_names.index(name)] = value
    blocks = function(model, ev["function"])(P)
    zs, es = zip(*(_poly_roots(np.reshape(b, (P.shape[0], -1))) for b in blocks))
    z, est = np.concatenate(zs, axis=1), np.concatenate(es, axis=1)
    p = np.sqrt(z)
    p = np.where(p.imag < 0, -p, p)
    freq, growth = np.abs(p.imag), p.real
    # a frequency's relative error is half that of its z; an exact zero root (a free
    # direction, as the neutral azimuth at u = 0) has no relative error to give
    est = np.where(z == 0, np.inf, est / 2)
    f, e, g = _ascending(freq, est, growth)
    e = np.where(np.isfinite(e) & (e < 0.5), e, np.inf)
    failed = np.full(f.shape[0], "", object)
    failed[~np.all(np.isfinite(f), axis=1)] = "a root could not be computed"
    return Answer(f, e, failed, {"growth": g})


EVALUATORS = {"spectrum": _spectrum, "charpoly": _charpoly}


def answer(model, level, P, opts) -> Answer:
    kind = level.evaluator.get("kind")
    if kind not in EVALUATORS:
        raise unknown_kind(NAME, level)
    return EVALUATORS[kind](model, level, P)


def edges(model, ans: Answer, bound: np.ndarray, idx) -> np.ndarray:
    """'' per set, or the reason the bound is no promise there: two neighbouring modes (in
    rank, among all of them; answers are ascending in frequency, `_ascending`) whose
    intervals omega (1 +- bound) touch."""
    f = ans.values
    out = np.full(f.shape[0], "", object)
    with np.errstate(invalid="ignore"):
        lo, hi = f * (1 - bound), f * (1 + bound)
        touch = hi[:, :-1] >= lo[:, 1:]  # rank j and j + 1
    want = np.zeros(f.shape[1], bool)
    want[list(idx)] = True
    relevant = want[:-1] | want[1:]
    # a mode a level leaves unanswered (bound inf) is, by the level's declaration, one that
    # keeps its rank (the neutral azimuth at u = 0 below every other mode)
    touch &= relevant[None, :] & np.isfinite(bound[:, :-1]) & np.isfinite(bound[:, 1:])
    for k in np.flatnonzero(touch.any(axis=1)):
        j = int(np.flatnonzero(touch[k])[0])
        out[k] = f"modes {j + 1} and {j + 2} within their bounds of each other (veering or a merged root)"
    return out


def error(ans: Answer, ref: Answer) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.abs(ans.values - ref.values) / np.abs(ref.values)


def document(model, ans: Answer, k: int, idx) -> dict:
    return {"frequencies": [float(ans.values[k, j]) for j in idx]}
