"""Exact first-order sensitivities of every natural frequency to every parameter.

For a simple root lambda of J(lambda; p) = M lambda^2 + D lambda + K with right and left
null vectors x, y (J x = 0, y* J = 0), the derivative is

    d lambda / d p_j = -(y* dJ/dp_j x) / (y* J'(lambda) x),   J' = 2 M lambda + D,

where dJ/dp_j is the total derivative: the operator depends on p directly and through the
equilibrium q_e(p), whose derivative follows from the equilibrium equations r(p, q_e) = 0,
dq_e/dp = -(dr/dq_e)^-1 dr/dp. A frequency omega = |Im lambda| then has
d omega / d p_j = sign(Im lambda) Im(d lambda / d p_j).

The partial derivatives of M, D, K and r come from the derivation (the emitted
`operator_sensitivity`, compiled where there is a compiler; the Jacobian of M, D, K as its
structural nonzeros, their positions in metadata.json), or, for a model emitted without it,
from CasADi's algorithmic differentiation of the emitted `operator` and
`equilibrium_residual` (`route='casadi'`). Both are exact (no step size); bench/scale.py
measures which is faster. The null vectors (one LU of J per root) and the contraction over
the nonzeros are compiled C (gyro/csrc/sensitivity.c), with NumPy the
fallback that gives the same numbers.

A double or nearly double root has no derivative (it is not differentiable where two roots
meet, and first order holds only for moves far below their distance): a root closer than
DOUBLE, relative, to another root of the spectrum (or to its own mirror -lambda, a root
near zero), or closer than ten times the sum of the two roots' errors, is reported as such
(`double`), with NaN in place of a number; so is a root without a finite frequency."""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from gyro import cbackend, ladder
from gyro.equilibrium import operators
from gyro.kernels import compiled, function
from gyro.models import Model
from gyro.results import Sensitivities, Spectrum

DOUBLE = 1e-6  # relative distance between two roots below which they count as one double root
CHUNK = 1024  # sets per call: the Jacobians' nonzeros take about 7 kB a set, the vectors 3 kB


def has_emitted(model: Model) -> bool:
    return "operator_sensitivity" in model.meta["functions"]


@lru_cache(maxsize=None)
def _casadi_function(model: Model):
    """(params, qe) -> the structural nonzeros of (dMDK, dr) by CasADi's AD on the emitted
    functions, with their (row, column) in the layout of the emitted operator_sensitivity:
    rows the entries of M, D, K (row-major) and the residual's rows, columns the
    parameters then the equilibrium coordinates."""
    import casadi as ca

    cf = model.casadi
    p = ca.SX.sym("p", len(model.param_names))
    q = ca.SX.sym("q", len(model.meta["equilibrium_coordinates"]))
    M, D, K = cf.operator(p, q)
    r = cf.equilibrium_residual(p, q)
    v = ca.vertcat(*[ca.vec(X.T) for X in (M, D, K)])  # vec is column-major: of X^T, row-major
    w = ca.vertcat(p, q)
    jac = [ca.jacobian(v, w), ca.jacobian(r, w)]
    where = [(np.array(j.sparsity().get_triplet()[0]), np.array(j.sparsity().get_triplet()[1]), j.shape)
             for j in jac]
    # only the nonzeros leave CasADi: turning its dense matrices into NumPy costs more than AD
    return ca.Function("operator_sensitivity_ad", [p, q], [j.nz[:] for j in jac]), where


@lru_cache(maxsize=None)
def _emitted_positions(model: Model):
    """(rows, cols) of the values of the emitted dMDK, its structural nonzeros (metadata.json),
    or None for a model folder emitted before outputs could be sparse (its dMDK a matrix)."""
    o = next(o for o in model.meta["functions"]["operator_sensitivity"]["outputs"] if o["name"] == "dMDK")
    if "nonzeros" not in o:
        return None
    return (np.asarray(o["nonzeros"]["rows"], dtype=np.intp), np.asarray(o["nonzeros"]["cols"], dtype=np.intp))


def sparse_partials(model: Model, P: np.ndarray, qe: np.ndarray, route: str = "auto"):
    """(values, rows, cols, dr): the structural nonzeros of dMDK, values (sets, nonzeros) at
    (rows, cols) of the layout of `partials`, and dr (sets, n, params + coordinates) dense.
    The emitted route's positions are the derivation's (metadata.json), CasADi's its own
    sparsity of the same Jacobian."""
    if route == "auto":
        route = "emitted" if has_emitted(model) else "casadi"
    if route == "emitted":
        with np.errstate(all="ignore"):
            vals, dr = function(model, "operator_sensitivity")(P, qe)
        where = _emitted_positions(model)
        if where is None:  # a dense dMDK: every entry a position
            rows, cols = np.indices(vals.shape[1:]).reshape(2, -1)
            return vals.reshape(vals.shape[0], -1), rows.astype(np.intp), cols.astype(np.intp), dr
        return (vals, *where, dr)
    if route != "casadi":
        raise ValueError(f"route: 'auto', 'emitted' or 'casadi', got {route!r}")
    N = P.shape[0]
    f, where = _casadi_function(model)
    nz_J, nz_r = f.map(N)(P.T, qe.T)
    (rows, cols, _), (r_rows, r_cols, r_shape) = where
    dr = np.zeros((N,) + r_shape)
    dr[:, r_rows, r_cols] = np.asarray(nz_r).T
    return np.asarray(nz_J).T, rows, cols, dr


def partials(model: Model, P: np.ndarray, qe: np.ndarray, route: str = "auto"):
    """dMDK (sets, 3 n^2, params + coordinates) and dr (sets, n, params + coordinates), dense."""
    vals, rows, cols, dr = sparse_partials(model, P, qe, route)
    n = next(o["shape"][0] for o in model.meta["functions"]["operator"]["outputs"] if o["name"] == "M")
    shape = (3 * n * n, dr.shape[2])
    dJ = np.zeros((P.shape[0],) + shape)
    dJ[:, rows, cols] = vals
    return dJ, dr


def _solve_or_svd(A: np.ndarray, b: np.ndarray, halve: bool = True) -> np.ndarray:
    """One step of inverse iteration on a flat batch (k, n, n) from b (k, n); with `halve`,
    a matrix singular to the last bit (LAPACK refuses the whole batch) is found by halving
    the batch, and takes its null vector from the SVD; without, LinAlgError."""
    try:
        v = np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        if not halve:
            raise
        if A.shape[0] == 1:
            return np.conj(np.linalg.svd(A)[2][:, -1, :])
        # the singular ones found at once by the same LU (an exact zero pivot: slogdet's sign
        # 0), not by halving the batch: a batch with a few hundred of them took as many solves
        sign, _ = np.linalg.slogdet(A)
        bad = sign == 0
        if not bad.any() or bad.all():  # no LU pivot is exactly zero after all: halve
            h = A.shape[0] // 2
            return np.concatenate([_solve_or_svd(A[:h], b[:h], halve), _solve_or_svd(A[h:], b[h:], halve)])
        v = np.empty(b.shape, complex)
        v[~bad] = _solve_or_svd(A[~bad], b[~bad], halve)
        v[bad] = np.conj(np.linalg.svd(A[bad])[2][:, -1, :])
        return v
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _start(n: int) -> np.ndarray:
    """The fixed generic start b of the inverse iteration: unit, no component zero."""
    return np.exp(1j * np.arange(1, n + 1)) / np.sqrt(n)


def _null_vectors(M, D, K, lam, hermitian, kernel=None):
    """Right and left null vectors of J(lambda) for a batch (sets, modes): one step of
    inverse iteration from a fixed generic start, taken at lambda (1 + 1e-15); the left
    one is the right one where J is Hermitian (a conservative set at a root on the
    imaginary axis, `hermitian` per set). The root is accurate to 1e-14, so the step leaves
    the vector's other components at 1e-14 over the relative gap to the next root (at least
    DOUBLE); the move keeps J(lambda) from being singular to the last bit (a decoupled mode,
    omega_p^2 m = Kp exactly, has an exact zero pivot at lambda), and it is relative to the
    root's own scale: a shift of J by a fraction of its largest entry would not be (the
    entries span eleven decades here, and omega1's derivative lost five digits to one).

    With `kernel` (gyro.cbackend.sens_null_vectors), one LU factorisation of J per root
    gives both vectors (J x = b and J^H y = b); a J with an exactly zero pivot in that LU
    goes to `_solve_or_svd`, as on the NumPy path. Without, NumPy's batched solve (a second
    one for the left vectors of the non-Hermitian sets). A root's J is singular to its last
    bits (the shift is below the rounding of its entries), so whether a pivot comes out
    exactly zero depends on the order of the elimination's operations: the two paths meet
    exact zeros at different roots."""
    N, m, n = M.shape[0], lam.shape[1], M.shape[-1]

    def J(rel):
        L = (lam * (1 + rel))[:, :, None, None]
        return M[:, None] * L**2 + D[:, None] * L + K[:, None]

    def left(A):
        return np.conj(np.swapaxes(A, -1, -2))

    b = np.broadcast_to(_start(n), (N * m, n))
    if kernel is not None:
        x, y, singular = kernel(M, D, K, lam, hermitian, _start(n))
        s, t = np.nonzero(singular)
        if s.size:  # an exactly zero pivot in C's LU: these few as the NumPy path takes them
            L = (lam[s, t] * (1 + 1e-15))[:, None, None]
            A = M[s] * L**2 + D[s] * L + K[s]
            x[s, t] = y[s, t] = _solve_or_svd(A, b[:s.size])
            h = np.flatnonzero(~hermitian[s])
            if h.size:
                y[s[h], t[h]] = _solve_or_svd(left(A[h]), b[:h.size])
        return x, y
    A = J(1e-15)
    x = _solve_or_svd(A.reshape(N * m, n, n), b).reshape(N, m, n)
    y = x.copy()
    h = np.flatnonzero(~hermitian)
    if h.size:
        y[h] = _solve_or_svd(left(A[h]).reshape(h.size * m, n, n), b[:h.size * m]).reshape(h.size, m, n)
    return x, y


def _contract(rows, cols, ncols, vals, M, D, lam, x, y, kernel=None):
    """(h, den) for a batch (sets, modes): h[c] = y* (dJ/dw_c) x summed over the structural
    nonzeros (rows, cols) of column c of the Jacobian of M, D, K (rows: which n^2 + row n +
    col, M then D then K, so dJ = dM lambda^2 + dD lambda + dK), and den = y* J'(lambda) x,
    J' = 2 M lambda + D. With `kernel` (gyro.cbackend.sens_contract) in C over the nonzeros
    themselves; without, NumPy over the Jacobian's nonzero rows, dense in the columns."""
    if kernel is not None:
        return kernel(rows, cols, ncols, vals, M, D, lam, x, y)
    n = M.shape[-1]
    live, at = np.unique(rows, return_inverse=True)
    V = np.zeros((vals.shape[0], live.size, ncols))
    V[:, at, cols] = vals
    which, entry = np.divmod(live, n * n)
    row, col = np.divmod(entry, n)
    T = lambda X: np.swapaxes(X, -1, -2)  # noqa: E731
    yc = np.conj(y)
    den = 2 * lam * np.sum(yc * (x @ T(M)), axis=-1) + np.sum(yc * (x @ T(D)), axis=-1)  # y* J'(lambda) x
    weight = np.stack([lam**2, lam, np.ones_like(lam)], axis=-1)  # dM lambda^2 + dD lambda + dK
    G = yc[:, :, row] * x[:, :, col] * weight[:, :, which]  # (sets, modes, live)
    return G.real @ V + 1j * (G.imag @ V), den  # two real products


def _equilibrium_derivative(drq, drp):
    """dq_e/dp = -(dr/dq_e)^-1 dr/dp per set; NaN for a set whose dr/dq_e is singular (its
    equilibrium does not depend smoothly on p: no sensitivity), not the whole batch."""
    try:
        return -np.linalg.solve(drq, drp)
    except np.linalg.LinAlgError:
        out = np.full(drp.shape, np.nan)
        for i in range(drq.shape[0]):
            try:
                out[i] = -np.linalg.solve(drq[i], drp[i])
            except np.linalg.LinAlgError:
                pass
        return out


def double_roots(spec: Spectrum) -> np.ndarray:
    """(sets, modes): the roots that are double or nearly so (module docstring)."""
    lam = spec.growth + 1j * spec.frequencies
    est = np.where(np.isfinite(spec.error_estimate), spec.error_estimate, np.inf)
    mag = np.maximum(np.abs(lam), 1e-300)
    with np.errstate(invalid="ignore"):
        gap = np.minimum(np.abs(lam[:, :, None] - lam[:, None, :]),
                         np.abs(lam[:, :, None] + np.conj(lam[:, None, :])))  # the mirror image too
        n = lam.shape[1]
        gap[:, np.arange(n), np.arange(n)] = 2 * np.abs(lam)  # its own mirror -lambda: a root near zero
        err = est * mag  # absolute error of each root
        close = (gap < DOUBLE * mag[:, :, None]) | (gap < 10 * (err[:, :, None] + err[:, None, :]))
    return close.any(axis=2) | ~np.isfinite(lam) | (spec.frequencies <= 0)


def _chunk(model: Model, P: np.ndarray, spec: Spectrum, route: str) -> np.ndarray:
    N, n = spec.frequencies.shape
    names = model.meta["equilibrium_coordinates"]
    idx = [model.meta["reduced"].index(c) for c in names]
    npar, nq = len(model.param_names), len(names)
    qe = spec.equilibrium
    ok = np.all(np.isfinite(qe), axis=1) & np.all(np.isfinite(spec.frequencies), axis=1)
    out = np.full((N, n, npar), np.nan)
    k = np.flatnonzero(ok)
    if k.size == 0:
        return out
    P, qe = P[k], qe[k]
    vals, rows, cols, dr = sparse_partials(model, P, qe, route)
    if np.any(np.diff(rows) < 0):  # the C contraction takes each entry's nonzeros together
        order = np.argsort(rows, kind="stable")
        vals, rows, cols = vals[:, order], rows[order], cols[order]
    M, D, K = operators(model, P, qe)
    # dq_e/dp from r(p, q_e) = 0, on the rows of the equilibrium equations
    drq, drp = dr[:, idx, npar:], dr[:, idx, :npar]
    with np.errstate(all="ignore"):
        dq = _equilibrium_derivative(drq, drp) if nq else np.zeros((k.size, 0, npar))
    lam = spec.growth[k] + 1j * spec.frequencies[k]  # (sets, modes)
    # J(i omega) is Hermitian for M, K symmetric and D skew (to the last bit) at growth 0
    T = lambda X: np.swapaxes(X, -1, -2)  # noqa: E731
    hermitian = (np.all(M == T(M), axis=(1, 2)) & np.all(K == T(K), axis=(1, 2)) & np.all(D == -T(D), axis=(1, 2))
                 & np.all(spec.growth[k] == 0, axis=1))
    x, y = _null_vectors(M, D, K, lam, hermitian, compiled(cbackend.sens_null_vectors, model))
    with np.errstate(all="ignore"):
        h, den = _contract(rows, cols, npar + nq, vals, M, D, lam, x, y, compiled(cbackend.sens_contract, model))
        # the total derivative: direct, and through the equilibrium, dJ/dq dq/dp
        hq = h[:, :, npar:]
        num = h[:, :, :npar] + (hq.real @ dq + 1j * (hq.imag @ dq))  # (sets, modes, params)
        d = -num / den[:, :, None]
    out[k] = np.sign(lam.imag)[:, :, None] * d.imag
    return out


def sensitivities(model: Model, P, spec: Spectrum | None = None, method: str = "default",
                  route: str = "auto") -> Sensitivities:
    """d omega_i / d p_j for every set (rows of P), frequency and parameter; the spectrum
    by `method` unless given."""
    if model.meta.get("momenta"):  # its reference moves with p through the momenta too: not derived
        raise ValueError(f"{model.name}: its operator depends on the momenta {', '.join(model.meta['momenta'])} "
                         "of a stationary motion; sensitivities cover models with a relative equilibrium")
    P = ladder.as_batch(model, P)
    if spec is None:
        spec = ladder.spectrum(model, P, method)
    if spec.equilibrium is None:
        raise ValueError(f"method {spec.method!r} gives no equilibrium: sensitivities need the exact operator")
    parts = [_chunk(model, P[s:s + CHUNK], _rows(spec, slice(s, s + CHUNK)), route)
             for s in range(0, P.shape[0], CHUNK)]
    d = np.concatenate(parts) if parts else np.zeros((0, spec.frequencies.shape[1], len(model.param_names)))
    double = double_roots(spec)
    d[double] = np.nan
    return Sensitivities(model.name, list(model.param_names), P, spec, d, double)


def _rows(spec: Spectrum, sl: slice) -> Spectrum:
    return Spectrum(spec.method, spec.frequencies[sl], spec.growth[sl], spec.error_estimate[sl],
                    spec.equilibrium[sl], None if spec.route is None else spec.route[sl], spec.growth_known)
