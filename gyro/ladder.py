"""Natural frequencies by a ladder of methods, vectorised over a batch of parameter sets.

Every method returns, for each parameter set, the ten frequencies in ascending order with
a relative error estimate for each (docs/methods.md):

- ``formulas``: the paper's approximate formulas (3.2)-(3.28), corrected where the derivation
  shows them wrong, emitted by `make derive` and run as compiled C over the batch. The
  estimate is the size of what each formula neglects (its small parameter to its order).
- ``polyroots``: roots of the characteristic polynomial det J(p), a polynomial of degree
  n in s = p^2 whose coefficients are fitted in double precision (the naive baseline).
  The estimate is the root's sensitivity to the coefficients' rounding.
- ``companion``: eigenvalues of the balanced first-order (companion) matrix by LAPACK.
  The estimate is eps ||A|| / |lambda| (Bauer-Fike for a well-conditioned root).
- ``default``: scaled and structure-aware. Per diagonal block of the operator, the
  gyroscopic problem with K > 0 is the Hermitian pencil diag(K, M) z = omega B z with
  B = [[-iD, M], [M, 0]]; after a diagonal scaling and Cholesky factors it is one small
  Hermitian eigenproblem (LAPACK), whose eigenvalues 1/omega are real. Each root is then
  refined on the full exact operator, where the blocks are coupled weakly: one step of
  inverse iteration on J(i omega) and the Rayleigh functional z* J(i omega) z = 0 (a
  quadratic in omega). Its estimate is a residual bound plus the rounding floor of
  evaluating J. Sets where a block's K is not positive definite, roots leave the real
  axis, two roots merge, or the estimate exceeds the tolerance, escalate by themselves:
  first to the general companion solver with Newton refinement, then to ``reference``.
  The block forms and the refinement run as the model's generated C (templates/qep.c.j2),
  set by set and root by root in one call per batch; without a compiler, as NumPy.
- ``reference``: equilibrium, operator and eigenvalues in arbitrary precision (mpmath, 40
  digits), each root polished by Newton on det J in the same precision; the estimate is
  the size of the last Newton step.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import mpmath
import numpy as np

from gyro import modal
from gyro.models import Model

METHODS = ("formulas", "polyroots", "companion", "default", "reference")
DEFAULT_TOL = 1e-10
EPS = np.finfo(float).eps
REFERENCE_DPS = 40
FORMULA_CHUNK = 8192
DEFAULT_CHUNK = 8192
WIDE = 1e-6  # a root below WIDE x the largest: the spectrum spans more than six decades


@dataclass
class Spectrum:
    """The result of one method over a batch: arrays of shape (sets, modes)."""

    method: str
    frequencies: np.ndarray  # rad/s, ascending per set
    growth: np.ndarray  # real parts of the eigenvalues (> 0: growing), same order
    error_estimate: np.ndarray  # relative error bound per frequency
    equilibrium: np.ndarray | None = None  # (sets, equilibrium coordinates)
    route: np.ndarray = field(default=None)  # per set: which rung answered (default only)


# --------------------------------------------------------------------------- batch helpers


def _fn(model: Model, name: str):
    """A generated function over a batch: compiled C when a compiler is there, NumPy otherwise."""
    from gyro.cbackend import CompilerUnavailable, batch_function

    try:
        f = batch_function(model.name, name)
    except CompilerUnavailable:
        g = getattr(model.numpy, name)

        def f(*args):
            out = g(*args)
            return list(out) if isinstance(out, tuple) else [out]
    return f


def as_batch(model: Model, params) -> np.ndarray:
    P = np.asarray(params, dtype=float)
    if P.ndim == 1:
        P = P[None, :]
    if P.ndim != 2 or P.shape[1] != len(model.param_names):
        raise ValueError(f"params: expected shape (sets, {len(model.param_names)}), got {P.shape}")
    return P


def equilibria(model: Model, P: np.ndarray, tol: float = 1e-14, max_iter: int = 40):
    """Relative equilibria of a batch by Newton's method from (2.2), vectorised; the damping
    and the branch are those of gyro.modal.equilibrium. Returns (qe, ok)."""
    reduced = model.meta["reduced"]
    names = model.meta["equilibrium_coordinates"]
    idx = np.array([reduced.index(c) for c in names])
    units = model.meta.get("coordinate_units", {})
    is_angle = np.array([units.get(c) == "rad" for c in names])
    n = P.shape[0]
    if "equilibrium_approx" in model.meta["functions"]:
        with np.errstate(all="ignore"):
            qe = _fn(model, "equilibrium_approx")(P)[0].reshape(n, -1)
        qe = np.where(np.isfinite(qe), qe, 0.0)
    else:
        qe = np.zeros((n, len(names)))
    active = np.ones(n, bool)
    resid, oper = _fn(model, "equilibrium_residual"), _fn(model, "operator")
    for _ in range(max_iter):
        a = np.flatnonzero(active)
        if a.size == 0:
            break
        with np.errstate(all="ignore"):
            r = resid(P[a], qe[a])[0].reshape(a.size, -1)[:, idx]
            K = oper(P[a], qe[a])[2][:, idx][:, :, idx]
            tame = _tame(K) & np.all(np.abs(r) < 1e150, axis=1)
            K = np.where(tame[:, None, None], K, np.eye(len(idx)))
            r = np.where(tame[:, None], r, np.nan)
            try:
                dq = np.linalg.solve(K, r[..., None])[..., 0]
            except np.linalg.LinAlgError:
                dq = np.array([np.linalg.lstsq(k, v, rcond=None)[0] if t else v
                               for k, v, t in zip(K, r, tame)])
        big = np.max(np.abs(np.where(is_angle, dq, 0.0)), axis=1)
        dq *= np.minimum(1.0, modal.MAX_ANGLE_STEP / np.maximum(big, 1e-300))[:, None]
        qe[a] += dq
        bad = ~np.all(np.isfinite(qe[a]), axis=1)
        conv = np.all(np.abs(dq) <= tol * np.maximum(np.abs(qe[a]), 1e-300) + 1e-300, axis=1)
        active[a[conv | bad]] = False
        qe[a[bad]] = np.nan
    ok = np.all(np.isfinite(qe), axis=1) & ~active
    qe = np.where(is_angle, modal._wrap(qe), qe)
    for k in np.flatnonzero(~ok):  # the set-by-set solver, with its acceptance test (g = 0)
        with np.errstate(all="ignore"):
            finite = all(_tame(X).all() for X in oper(P[k:k + 1], np.zeros((1, len(names)))))
        if not finite:  # inputs beyond double precision: LAPACK must not see them
            qe[k] = np.nan
            continue
        try:
            qe[k] = modal.equilibrium(model, P[k])
            ok[k] = True
        except (modal.EquilibriumError, np.linalg.LinAlgError, ValueError, ArithmeticError):
            qe[k] = np.nan
    return qe, ok


def operators(model: Model, P: np.ndarray, qe: np.ndarray):
    with np.errstate(all="ignore"):
        return _fn(model, "operator")(P, qe)


def _tame(X) -> np.ndarray:
    """Per matrix of a batch (or for one matrix): finite and far from overflow (LAPACK
    squares entries while scaling; beyond 1e150 it overflows and complains on stderr)."""
    X = np.asarray(X)
    with np.errstate(invalid="ignore"):
        return np.all(np.abs(X) < 1e150, axis=(-2, -1))


def _blocks(model: Model) -> list[np.ndarray]:
    """Index sets of the operator's diagonal blocks (coupled weakly in the exact operator)."""
    reduced = model.meta["reduced"]
    for v in model.meta.get("variants", {}).values():
        if v.get("blocks"):
            return [np.array([reduced.index(c) for c in b]) for b in v["blocks"]]
    return [np.arange(len(reduced))]


def _sorted(freq, growth, est):
    """Ascending by |lambda|: by frequency for a stable set, and the real roots of an
    unstable set (frequency 0 up to rounding) by their growth rate, in every method alike."""
    order = np.argsort(np.abs(growth + 1j * freq), axis=1)
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    return take(freq), take(growth), take(est)


# --------------------------------------------------------------------------- companion


def _pairs(lams: np.ndarray, n: int) -> np.ndarray:
    """One eigenvalue per pair, for each set (gyro.modal.representatives, batched)."""
    return np.array([modal.representatives(l, n) for l in lams])


def companion(model: Model, P: np.ndarray) -> Spectrum:
    qe, ok = equilibria(model, P)
    M, D, K = operators(model, P, qe)
    n = M.shape[-1]
    A = modal.companion_matrix(M, D, K)
    good = ok & _tame(A)
    lam = np.full((P.shape[0], n), np.nan + 0j)
    if good.any():
        lam[good] = _pairs(np.linalg.eigvals(A[good]), n)
    # LAPACK balances A (D A D^-1) before its backward-stable QR iteration
    norm = np.linalg.norm(A, ord=1, axis=(1, 2))
    est = 2 * n * EPS * norm[:, None] / np.abs(lam)
    f, g, e = _sorted(np.abs(lam.imag), lam.real, est)
    return Spectrum("companion", f, g, e, qe)


# --------------------------------------------------------------------------- polynomial


def polyroots(model: Model, P: np.ndarray) -> Spectrum:
    """det J(p) = c(s), s = p^2, degree n, is fitted from n + 1 Chebyshev points of s in
    [-R, 0] (R bounds omega_max^2 by Gershgorin on M^-1 K) in double precision, converted
    to the power basis and solved by numpy.roots: the textbook route."""
    qe, ok = equilibria(model, P)
    M, D, K = operators(model, P, qe)
    N, n = P.shape[0], M.shape[-1]
    freq = np.full((N, n), np.nan)
    growth = np.full((N, n), np.nan)
    est = np.full((N, n), np.inf)
    with np.errstate(all="ignore"):
        R = 1.5 * np.max(np.sum(np.abs(np.linalg.solve(M, K)), axis=2), axis=1)
        t = np.cos(np.pi * (np.arange(n + 1) + 0.5) / (n + 1))  # Chebyshev nodes in [-1, 1]
        s = -R[:, None] * (1 + t[None, :]) / 2  # in [-R, 0]
        p = np.sqrt(s.astype(complex))
        J = (M[:, None] * s[..., None, None] + D[:, None] * p[..., None, None] + K[:, None])
        dets = np.linalg.det(J).real  # J(i w) is Hermitian: det is real
    for k in np.flatnonzero(ok & np.all(np.isfinite(dets), axis=1)):
        # in x = -1 - 2 s / R the nodes are t; the power basis in s follows by substitution
        x_of_s = np.polynomial.polynomial.Polynomial([-1.0, -2.0 / R[k]])

        def to_s(cheb):
            coef = np.polynomial.polynomial.Polynomial(np.polynomial.chebyshev.cheb2poly(cheb))(x_of_s).coef
            return np.pad(coef, (0, n + 1 - len(coef)))

        c = to_s(np.polynomial.chebyshev.chebfit(t, dets[k], n))
        roots_s = np.roots(c[::-1])
        lam = np.sqrt(roots_s.astype(complex))  # p = sqrt(s), the upper member
        lam = np.where(lam.imag < 0, -lam, lam)
        if len(lam) != n:
            continue
        # the fit errs by about eps max|det| per Chebyshev coefficient; carried into the power
        # basis by the conversion (its matrix in absolute value), then into each root by
        # |ds| <= sum_j |dc_j| |s|^j / |c'(s)|
        conv = np.abs(np.array([to_s(np.eye(n + 1)[j]) for j in range(n + 1)]))  # (cheb, power)
        dc = EPS * (n + 1) * np.max(np.abs(dets[k])) * conv.sum(axis=0)
        ds = np.polynomial.polynomial.polyval(np.abs(roots_s), dc) / np.abs(
            np.polynomial.polynomial.polyval(roots_s, np.polynomial.polynomial.polyder(c)))
        freq[k], growth[k] = np.abs(lam.imag), lam.real
        e = 0.5 * ds / np.maximum(np.abs(roots_s), 1e-300)
        est[k] = np.where(e < 0.5, e, np.inf)  # a first-order bound past 1/2 bounds nothing
    f, g, e = _sorted(freq, growth, est)
    return Spectrum("polyroots", f, g, e, qe)


# --------------------------------------------------------------------------- default


def _hermitian_block(M, D, K):
    """Roots omega > 0 of a gyroscopic block with K > 0, for a batch.

    With d = 1/sqrt(diag K), e = 1/sqrt(diag M) and the Cholesky factors K_s = Lk Lk^T,
    M_s = Lm Lm^T of the scaled matrices, the eigenvalues mu = 1/omega of the Hermitian
    T = [[-i Lk^-1 D_s Lk^-T, Lk^-1 C Lm^-T], [.^H, 0]], C = d M e, are real: LAPACK's
    Hermitian solver finds each with an absolute error of order eps ||T|| = eps / omega_min,
    so the smallest omega keeps its relative accuracy."""
    N, n = M.shape[0], M.shape[-1]
    d = 1 / np.sqrt(np.einsum("bii->bi", K))
    e = 1 / np.sqrt(np.einsum("bii->bi", M))
    Lk_inv = np.linalg.inv(np.linalg.cholesky(K * d[:, :, None] * d[:, None, :]))
    Lm_inv = np.linalg.inv(np.linalg.cholesky(M * e[:, :, None] * e[:, None, :]))
    T = np.zeros((N, 2 * n, 2 * n), complex)
    T[:, :n, :n] = -1j * (Lk_inv @ (D * d[:, :, None] * d[:, None, :]) @ Lk_inv.transpose(0, 2, 1))
    T12 = Lk_inv @ (M * d[:, :, None] * e[:, None, :]) @ Lm_inv.transpose(0, 2, 1)
    T[:, :n, n:] = T12
    T[:, n:, :n] = T12.transpose(0, 2, 1)
    mu = np.linalg.eigvalsh(T)
    return 1 / mu[:, n:]  # the n positive mu, ascending: omega descending


def _start_vectors(N, n, r):
    """A fixed generic complex start vector for inverse iteration (seeded: reproducible)."""
    rng = np.random.default_rng(20261124)
    v = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    return np.broadcast_to(v, (N, r, n))


def _mv(A, z, sym):
    """A z for a batch of real (B, n, n) matrices and complex vectors z (B, r, n); A is
    symmetric (sym = 1) or skew (sym = -1), so that z @ A^T = sym z @ A."""
    out = np.matmul(z.real, A) + 1j * np.matmul(z.imag, A)
    return out if sym == 1 else -out


def _rayleigh_step(M, D, K, w, z):
    """One step on a batch: M, D, K (B, n, n), shifts w (B, r), vectors z (B, r, n).

    Inverse iteration on the full Hermitian J(i w) = K - w^2 M + i w D, z <- J^-1 J' z, then
    w from the Rayleigh functional z* J(i w) z = 0 (a quadratic in w: its root nearest the
    shift). The estimate is the first-order bound |J z| / |z* J' z| from the residual, plus
    the rounding floor of forming J z. Returns (w, z, estimate, ok)."""
    n = M.shape[-1]
    ws = w[..., None, None]
    J = np.empty(w.shape + (n, n), complex)
    np.multiply(ws**2, M[:, None], out=J.real)  # in place: no (B, r, n, n) temporaries
    np.subtract(K[:, None], J.real, out=J.real)
    np.multiply(ws, D[:, None], out=J.imag)
    rhs = -2 * w[..., None] * _mv(M, z, 1) + 1j * _mv(D, z, -1)
    zn = None
    for shift in (0.0, 64 * EPS, 1e-10, 1e-7):
        # a shift on a root to the last bit makes J exactly singular (omega_p = 780 at the
        # example); inverse iteration only needs a shift near the root, so move it a little
        if shift:
            wt = ws * (1 + shift)
            np.multiply(wt**2, M[:, None], out=J.real)
            np.subtract(K[:, None], J.real, out=J.real)
            np.multiply(wt, D[:, None], out=J.imag)
        try:
            zn = np.linalg.solve(J, rhs[..., None])[..., 0]
            break
        except np.linalg.LinAlgError:
            continue
    if zn is None:  # singular at every shift (e.g. a zero mass): this rung gives up
        nan = np.full(w.shape, np.nan)
        return nan, z, np.full(w.shape, np.inf), np.zeros(w.shape, bool)
    zn /= np.linalg.norm(zn, axis=-1, keepdims=True)
    Mz, Dz, Kz = _mv(M, zn, 1), _mv(D, zn, -1), _mv(K, zn, 1)
    zc = zn.conj()
    a = np.sum(zc * Mz, axis=-1).real
    beta = np.sum(zc * Dz, axis=-1).imag
    c = np.sum(zc * Kz, axis=-1).real
    # a w^2 + beta w - c = 0: roots q/a and -c/q, without cancellation
    disc = beta**2 + 4 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    q = -(beta + np.copysign(sq, beta)) / 2
    r1, r2 = q / a, -c / q
    wn = np.where(np.abs(r1 - w) < np.abs(r2 - w), r1, r2)
    wc = wn[..., None]
    res = np.linalg.norm(Kz - wc**2 * Mz + 1j * wc * Dz, axis=-1)
    az = np.abs(zn) + 0j
    floor = np.linalg.norm(_mv(np.abs(K), az, 1).real + wc**2 * _mv(np.abs(M), az, 1).real
                           + np.abs(wc) * _mv(np.abs(D), az, 1).real, axis=-1)
    est = (res + 4 * n * EPS * floor) / (np.abs(2 * wn * a + beta) * np.abs(wn))
    ok = (disc > 0) & np.isfinite(est) & (wn > 0)
    return wn, zn, est, ok


def _rayleigh(model: Model, M, D, K, w, z, iters, tol, chunk=256):
    """Steps of _rayleigh_step on every root until its estimate is <= tol (at most `iters`).
    Compiled: the model's generated refinement (templates/qep.c.j2), root by root. Without
    a compiler: _rayleigh_step on every root, in chunks of sets (cache-sized), then further
    steps only on the roots whose estimate still exceeds tol. Returns (w, z, estimate, ok)."""
    from gyro.cbackend import CompilerUnavailable, qep_refine

    try:
        return qep_refine(model.name)(M, D, K, w, z, iters, tol)
    except CompilerUnavailable:
        pass
    N = M.shape[0]
    w, z = w.copy(), np.array(np.broadcast_to(z, w.shape + (M.shape[-1],)), dtype=complex)
    est = np.full(w.shape, np.inf)
    ok = np.zeros(w.shape, bool)
    for s in range(0, N, chunk):
        sl = slice(s, s + chunk)
        w[sl], z[sl], est[sl], ok[sl] = _rayleigh_step(M[sl], D[sl], K[sl], w[sl], z[sl])
    for _ in range(iters - 1):
        bi, ri = np.nonzero(ok & (est > tol))
        if bi.size == 0:
            break
        wn, zn, e, o = _rayleigh_step(M[bi], D[bi], K[bi], w[bi, ri][:, None], z[bi, ri][:, None])
        w[bi, ri], z[bi, ri], est[bi, ri], ok[bi, ri] = wn[:, 0], zn[:, 0], e[:, 0], o[:, 0]
    return w, z, est, ok


def _general(M, D, K):
    """The general rung for one set: companion eigenvalues, each refined by Newton on J.

    The estimate is the last Newton step (quadratic convergence leaves far less) plus the
    rounding floor eps |y| (|M||l|^2 + |D||l| + |K|) |x| / (|l| |y* J'(l) x|) of the root,
    with x, y the singular vectors of J(l) at its smallest singular value."""
    n = M.shape[0]
    if not (_tame(M) and _tame(D) and _tame(K)):
        return np.full(n, np.nan + 0j), np.full(n, np.inf)
    lams = modal._companion_eigenvalues(M, D, K)
    roots, errs = modal.refine_all(M, D, K, lams, modal.representatives(lams, n))
    est = np.empty(n)
    for j, lam in enumerate(roots):
        U, _, Vh = np.linalg.svd(M * lam**2 + D * lam + K)
        x, y = Vh[-1].conj(), U[:, -1]
        scale = np.abs(y) @ (np.abs(M) * abs(lam)**2 + np.abs(D) * abs(lam) + np.abs(K)) @ np.abs(x)
        slope = abs(y.conj() @ (2 * M * lam + D) @ x) * max(abs(lam), 1e-300)
        est[j] = errs[j] + 4 * n * EPS * scale / max(slope, 1e-300)
    return roots, est


def _moved(p, rel):
    """Parameters (last axis; NumPy or a list of mpf) each moved by rel relative, with
    alternating signs: a fixed, reproducible perturbation of the inputs."""
    if isinstance(p, np.ndarray):
        return p * (1 + rel * np.where(np.arange(p.shape[-1]) % 2 == 0, 1.0, -1.0))
    return [v * (1 + (rel if i % 2 == 0 else -rel)) for i, v in enumerate(p)]


def _general_at(model: Model, p: np.ndarray) -> np.ndarray:
    qe, _ = equilibria(model, p[None])
    M, D, K = operators(model, p[None], qe)
    return _general(M[0], D[0], K[0])[0]


def _input_rounding(model: Model, p, roots, solve, rel=4 * EPS) -> np.ndarray:
    """The part of each root's error that comes from rounding the inputs: when a root lies
    far below the others (ratio < WIDE), the set is solved again with every parameter
    moved by `rel` relative (_moved: signs fixed, reproducible) and the change of each
    root, relative, is the estimate; zero otherwise. E.g. at phi = 90 deg, cos(pi phi/180)
    rounds to 6e-17 instead of 0 and omega1 is rounding noise: the estimate says so."""
    mags = np.abs(roots)
    if not np.min(mags) < WIDE * np.max(mags):
        return np.zeros(len(roots))
    moved = np.sort(np.abs(np.asarray(solve(_moved(np.asarray(p), rel)))))
    order = np.argsort(mags)
    out = np.empty(len(roots))
    out[order] = np.abs(moved - mags[order]) / np.maximum(mags[order], 1e-300)
    return out


def _input_rounding_structured(model: Model, P, w, z, rel=4 * EPS):
    """_input_rounding for the structured rung, batched: the smallest root of each set is
    followed to the moved inputs by one Rayleigh step from its converged vector."""
    Pm = _moved(P, rel)
    qe, _ = equilibria(model, Pm)
    M, D, K = operators(model, Pm, qe)
    j = np.argmin(w, axis=1)
    rows = np.arange(len(w))
    w_small = w[rows, j]
    wm, _, _, ok = _rayleigh(model, M, D, K, w_small[:, None], z[rows, j][:, None], 1, 0.0)
    change = np.where(ok[:, 0], np.abs(wm[:, 0] - w_small) / w_small, np.inf)
    out = np.zeros(w.shape)
    out[rows, j] = change
    return out


def _pivots_above(A, floor) -> np.ndarray:
    """Per matrix of a batch of symmetric A: every Cholesky pivot above floor (positive
    definite with a margin), the pivots being the ratios of the leading principal minors
    (the test of the generated <model>_qep_hermitian_batch, for the NumPy path)."""
    ok = np.ones(A.shape[0], bool)
    prev = np.ones(A.shape[0])
    with np.errstate(all="ignore"):
        for k in range(1, A.shape[-1] + 1):
            det = np.linalg.det(np.where(np.isfinite(A[:, :k, :k]), A[:, :k, :k], 0.0))
            ok &= (prev > 0) & (det > floor * prev) & np.all(np.isfinite(A[:, :k, :k]), axis=(1, 2))
            prev = det
    return ok


def _block_starts(model: Model, M, D, K, good):
    """Which sets take the Hermitian path (K > 0 and M > 0 in every diagonal block, with a
    margin) and, for those, the block problems' frequencies (sets taken, n): the starts of
    the refinement. Compiled: the model's generated block form (templates/qep.c.j2), whose
    Cholesky pivots must exceed 1e3 eps; without a compiler: the same test on the leading
    principal minors (_pivots_above), then _hermitian_block."""
    from gyro.cbackend import CompilerUnavailable, qep_hermitian

    blocks = _blocks(model)
    try:
        forms = [qep_hermitian(model.name)(M, D, K, b) for b in blocks]
    except CompilerUnavailable:
        forms = None
    if forms is not None:
        herm = good & np.all([ok for _, ok in forms], axis=0)
        take = slice(None) if herm.all() else np.flatnonzero(herm)  # no copy when all take it
        mu = [np.linalg.eigvalsh(T[take])[:, len(b):] for (T, _), b in zip(forms, blocks)]
        return herm, 1 / np.concatenate(mu, axis=1)  # mu ascending: w descending per block
    dK, dM = np.einsum("bii->bi", K), np.einsum("bii->bi", M)
    herm = good & np.all(dK > 0, axis=1) & np.all(dM > 0, axis=1)
    for b in blocks:
        for X, d in ((K, dK), (M, dM)):
            with np.errstate(all="ignore"):
                s = 1 / np.sqrt(d[:, b])
                herm &= _pivots_above(X[:, b][:, :, b] * s[:, :, None] * s[:, None, :], 1e3 * EPS)
    h = np.flatnonzero(herm)
    Mh, Dh, Kh = M[h], D[h], K[h]
    return herm, np.concatenate([_hermitian_block(Mh[:, b][:, :, b], Dh[:, b][:, :, b], Kh[:, b][:, :, b])
                                 for b in blocks], axis=1)


def _in_chunks(method, model: Model, P: np.ndarray, size: int, *args) -> Spectrum:
    """A method over a large batch, piece by piece (its working arrays sized to the piece)."""
    parts = [method(model, P[s:s + size], *args) for s in range(0, P.shape[0], size)]
    cat = {f: (None if getattr(parts[0], f) is None else np.concatenate([getattr(x, f) for x in parts]))
           for f in ("frequencies", "growth", "error_estimate", "equilibrium", "route")}
    return Spectrum(parts[0].method, **cat)


def default(model: Model, P: np.ndarray, tol: float = DEFAULT_TOL) -> Spectrum:
    if P.shape[0] > DEFAULT_CHUNK:  # bounded memory: the block forms take 3 kB a set
        return _in_chunks(default, model, P, DEFAULT_CHUNK, tol)
    N = P.shape[0]
    qe, ok = equilibria(model, P)
    M, D, K = operators(model, P, qe)
    n = M.shape[-1]
    freq = np.full((N, n), np.nan)
    growth = np.zeros((N, n))
    est = np.full((N, n), np.inf)
    good = ok & _tame(M) & _tame(D) & _tame(K)
    # which rung answered; "none" where no rung could (no equilibrium in any precision)
    route = np.where(good, "structured", "none").astype(object)
    herm, w0 = _block_starts(model, M, D, K, good)
    h = np.flatnonzero(herm)
    if h.size:
        take = slice(None) if h.size == N else h
        Mh, Dh, Kh = M[take], D[take], K[take]
        w, z, e, fine = _rayleigh(model, Mh, Dh, Kh, w0, _start_vectors(h.size, n, n), 3, tol)
        ws_sorted = np.sort(w, axis=1)
        distinct = np.all(np.diff(ws_sorted, axis=1) > 1e-8 * ws_sorted[:, 1:], axis=1)
        # a root far below the others (omega1 -> 0 toward the pole or as u -> 0) carries the
        # rounding of the inputs themselves: measured by solving again with moved inputs
        wide = np.flatnonzero(np.all(fine, axis=1) & (np.min(w, axis=1) < WIDE * np.max(w, axis=1)))
        if wide.size:
            e[wide] += _input_rounding_structured(model, P[h[wide]], w[wide], z[wide])
        fine = np.all(fine, axis=1) & distinct & np.all(e <= tol, axis=1)
        hf = h[fine]
        freq[hf], est[hf] = w[fine], e[fine]
        herm[h[~fine]] = False
    for k in np.flatnonzero(good & ~herm):
        route[k] = "general"
        roots, e = _general(M[k], D[k], K[k])
        e = e + _input_rounding(model, P[k], roots, lambda Pp: _general_at(model, Pp))
        freq[k], growth[k], est[k] = np.abs(roots.imag), roots.real, e
    for k in np.flatnonzero(~good | (np.max(est, axis=1) > tol)):
        try:
            ref = reference(model, P[k:k + 1])
        except (modal.EquilibriumError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            # extended precision cannot answer either (a singular equilibrium problem, as at
            # g = 0, or inputs beyond any precision): the general rung's answer stands, with
            # its own (larger) estimate
            continue
        route[k] = "reference"
        freq[k], growth[k], est[k] = ref.frequencies[0], ref.growth[0], ref.error_estimate[0]
        qe[k] = ref.equilibrium[0]
    f, g, e = _sorted(freq, growth, est)
    return Spectrum("default", f, g, e, qe, route)


# --------------------------------------------------------------------------- reference


def _mp_equilibrium(mf, p, q0, idx, max_iter=60):
    q = [mpmath.mpf(v) for v in q0]
    tol = mpmath.mpf(10) ** (-mpmath.mp.dps + 5)
    for _ in range(max_iter):
        r = mf.equilibrium_residual(p, q)
        _, _, K = mf.operator(p, q)
        Kee = mpmath.matrix([[K[i, j] for j in idx] for i in idx])
        dq = mpmath.lu_solve(Kee, mpmath.matrix([r[i] for i in idx]))
        q = [qi + dqi for qi, dqi in zip(q, dq)]
        if all(abs(d) <= tol * max(abs(v), mpmath.mpf(10) ** -300) for d, v in zip(dq, q)):
            return q
    raise modal.EquilibriumError("Newton's method in extended precision did not converge")


def _reference_roots(mf, p, start, idx):
    """One set in the working precision: (roots, their last Newton steps relative, q)."""
    q = _mp_equilibrium(mf, p, start, idx)
    M, D, K = mf.operator(p, q)
    n = M.rows
    Minv = mpmath.inverse(M)
    A = mpmath.zeros(2 * n, 2 * n)
    B, C = -Minv * K, -Minv * D
    for i in range(n):
        A[i, n + i] = 1
        for j in range(n):
            A[n + i, j], A[n + i, n + j] = B[i, j], C[i, j]
    lams = mpmath.eig(A, left=False, right=False)
    lam_c = np.array([complex(v) for v in lams])
    roots, steps = [], []
    for r in modal.representatives(lam_c, n):
        lam = lams[int(np.argmin(np.abs(lam_c - r)))]
        J = M * lam**2 + D * lam + K
        dJ = M * (2 * lam) + D
        Jinv = mpmath.inverse(J)
        step = 1 / sum(Jinv[c, i] * dJ[i, c] for c in range(n) for i in range(n))
        lam = lam - step
        roots.append(lam)
        steps.append(abs(step) / abs(lam) if lam != 0 else mpmath.inf)
    return roots, steps, q


def reference(model: Model, P: np.ndarray, dps: int = REFERENCE_DPS) -> Spectrum:
    """Arbitrary precision: the equilibrium by Newton from the double one, the companion
    eigenvalues by mpmath.eig, each root polished by Newton on det J (trace of J^-1 J').
    The estimate is the last Newton step, floored at 10^(5 - dps), plus the effect of the
    inputs' rounding in this precision where a root lies far below the others."""
    import importlib

    mf = importlib.import_module(f"generated.{model.name}.mpmath_functions")
    reduced = model.meta["reduced"]
    idx = [reduced.index(c) for c in model.meta["equilibrium_coordinates"]]
    N = P.shape[0]
    qe_d, ok = equilibria(model, P)
    out = None
    with mpmath.workdps(dps):
        for k in range(N):
            p = [mpmath.mpf(float(v)) for v in P[k]]
            if not ok[k]:  # equilibria() has tried the set-by-set solver as well
                raise modal.EquilibriumError(f"no equilibrium in double precision to start from (set {k})")
            start = qe_d[k]
            roots, steps, q = _reference_roots(mf, p, start, idx)
            n = len(roots)
            if out is None:
                out = [np.full((N, n), np.nan), np.full((N, n), np.nan), np.full((N, n), np.inf),
                       np.full((N, len(idx)), np.nan)]
            lam = np.array([complex(r) for r in roots])
            est = np.maximum(np.array([float(x) for x in steps]), 10.0 ** (5 - dps))

            def solve_moved(_, p=p, start=start):  # the same move, in this precision
                moved = _moved(p, mpmath.mpf(10) ** (3 - dps))
                return [complex(r) for r in _reference_roots(mf, moved, start, idx)[0]]

            est = est + _input_rounding(model, P[k], lam, solve_moved)
            out[0][k], out[1][k], out[2][k] = np.abs(lam.imag), lam.real, est
            out[3][k] = [float(v) for v in q]
    f, g, e = _sorted(out[0], out[1], out[2])
    return Spectrum("reference", f, g, e, out[3])


# --------------------------------------------------------------------------- formulas


def formulas(model: Model, P: np.ndarray) -> Spectrum:
    """The model's mode formulas (metadata 'mode_formulas') over the batch: for each mode,
    among its candidate formulas the one whose own error estimate is smallest, sorted by
    frequency. Compiled: one pass of the generated C (templates/mode_select.c.j2); without a
    compiler, NumPy."""
    from gyro.cbackend import CompilerUnavailable, mode_formulas_selected

    try:
        with np.errstate(all="ignore"):
            f, e = mode_formulas_selected(model.name)(P)
        return Spectrum("formulas", f, np.zeros(f.shape), e)
    except CompilerUnavailable:
        pass
    if P.shape[0] > FORMULA_CHUNK:  # cache-sized pieces: the selection is memory-bound
        return _in_chunks(formulas, model, P, FORMULA_CHUNK)
    with np.errstate(all="ignore"):
        omega, estimate = getattr(model.numpy, "mode_formulas")(P)
    N = P.shape[0]
    n = len(model.meta["mode_formulas"])
    omega, estimate = np.reshape(omega, (N, n, -1)), np.reshape(estimate, (N, n, -1))
    f, e = omega[..., 0], estimate[..., 0]
    for j in range(1, omega.shape[2]):
        better = estimate[..., j] < e
        f = np.where(better, omega[..., j], f)
        e = np.where(better, estimate[..., j], e)
    e = np.where(np.isfinite(f) & (f > 0), e, np.inf)  # a formula outside its domain (0/0)
    order = np.argsort(f, axis=1, kind="stable")  # as the C's insertion sort: ties keep their order
    f, e = np.take_along_axis(f, order, 1), np.take_along_axis(e, order, 1)
    return Spectrum("formulas", f, np.zeros(f.shape), e)


# --------------------------------------------------------------------------- API


def spectrum(model: Model, params, method: str = "default", tol: float = DEFAULT_TOL) -> Spectrum:
    """Natural frequencies of a batch of parameter sets (rows of `params`, in the order of
    model.param_names) by one method of the ladder."""
    if method not in METHODS:
        raise ValueError(f"method: unknown {method!r}; known: {', '.join(METHODS)}")
    P = as_batch(model, params)
    if method == "default":
        return default(model, P, tol)
    return {"formulas": formulas, "polyroots": polyroots, "companion": companion,
            "reference": reference}[method](model, P)


# --------------------------------------------------------------------------- stability


@dataclass
class Stability:
    """Per set: 'stable', 'unstable' (with its growth rate, 1/s) or 'marginal' (a root
    whose real part, or whose frequency, is zero only within its error estimate)."""

    label: np.ndarray  # (sets,) str
    growth_rate: np.ndarray  # (sets,) largest real part, 1/s (0 when stable)
    unstable_roots: np.ndarray  # (sets,) int: growing modes (eigenvalue pairs, or quadruples, with a growing member)
    slowest_growth: np.ndarray  # (sets,) smallest growing real part, 1/s (0 when stable)


def classify(spec: Spectrum, rel: float = 1e-9) -> Stability:
    """Stability of each set's equilibrium from its spectrum.

    A root grows when its real part exceeds what its error allows: max(estimate, rel)
    times |lambda| (the conservative gyroscopic spectrum lies on the imaginary axis, so a
    real part within rounding of it is noise). A root with |lambda| within its own error of
    zero (estimate >= 1: a neutral direction, omega1 at the pole or without Earth rate) is
    marginal."""
    lam = np.abs(spec.growth + 1j * spec.frequencies)
    allow = np.maximum(np.nan_to_num(spec.error_estimate, nan=np.inf), rel) * lam
    growing = spec.growth > allow
    neutral = np.nan_to_num(spec.error_estimate, nan=np.inf) >= 1
    label = np.where(growing.any(axis=1), "unstable", np.where(neutral.any(axis=1), "marginal", "stable"))
    rate = np.where(growing, spec.growth, 0.0).max(axis=1)
    slowest = np.where(growing, spec.growth, np.inf).min(axis=1)
    return Stability(label.astype(object), rate, growing.sum(axis=1), np.where(np.isfinite(slowest), slowest, 0.0))
