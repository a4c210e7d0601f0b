"""Roots of many real polynomials at once (the characteristic polynomials of a level's
blocks over a batch of parameter sets), each with a proven inclusion radius.

The Aberth-Ehrlich iteration, simultaneous over the batch: every root of every polynomial
moves by its Newton correction w = p/p' deflated by the others,
z_i <- z_i - w_i / (1 - w_i sum_{j != i} 1/(z_i - z_j)), from starts on the circles of the
Newton polygon of the coefficients (the upper convex hull of (k, log|c_k|): one circle per
edge, of radius (|c_a|/|c_b|)^(1/(b - a)), with b - a starts on it), which put roots that
span many orders of magnitude (z from 1e-7 to 1e7 for the torsion gyrocompass's blocks) on
their own scales from the first step. The theorem that makes the answer a proof: with the
Weierstrass corrections W_i = p(z_i) / (c_d prod_{j != i}(z_i - z_j)), the disks
|z - z_i| <= d |W_i| hold all the roots, and where they are pairwise disjoint each holds
exactly one (Braess and Hadeler; Carstensen). |p(z_i)| is taken with its rounding bound
added, so the radius holds for the polynomial as given. A polynomial whose iteration does
not settle, or whose evaluation does not stay finite, is solved by the eigenvalues of its
companion matrix, and its disks are checked the same way; where they overlap (a merged
root, a cluster) nothing is proven and the radius is infinite. The eigenvalues alone are no
proof: with roots from 1e-7 to 1e9 (the J'' block over the spreads) the smallest comes out
of LAPACK with a relative error of 1.4e-8 where the sensitivity to the coefficients is 1e-14.

`roots(c) -> (z, radius, sensitivity, proven)`: c (sets, degree + 1), lowest first; z
(sets, degree) complex; radius the inclusion radius of each root (relative to |z|, inf
where not proven); sensitivity each root's first-order relative sensitivity to a rounding
of eps per coefficient (the coefficients, computed, carry such roundings); proven (sets,)
False where no disk is proven (the radius inf).
"""
from __future__ import annotations

import numpy as np

EPS = np.finfo(float).eps
ITERATIONS = 60  # at most; a start on its Newton polygon's circle settles in 5-12
OFFSET = 0.7  # start angles turned off the real axis (real coefficients: conjugate starts stall)


def _starts(c: np.ndarray) -> np.ndarray:
    """Starts on the Newton polygon's circles (c with no zero coefficient at either end)."""
    N, d1 = c.shape
    d = d1 - 1
    with np.errstate(divide="ignore"):
        y = np.log(np.abs(c))
    k = np.arange(d1)
    vertex = np.isfinite(y)
    # k is on the upper hull where no chord i < k < j passes above it
    for m in range(1, d):
        for i in range(m):
            for j in range(m + 1, d1):
                chord = y[:, i] + (y[:, j] - y[:, i]) * (m - i) / (j - i)
                vertex[:, m] &= ~(np.isfinite(chord) & (chord >= y[:, m]))
    below = np.maximum.accumulate(np.where(vertex, k, -1), axis=1)[:, :d]  # a: last vertex <= t
    above = np.minimum.accumulate(np.where(vertex, k, d1)[:, ::-1], axis=1)[:, ::-1][:, 1:]  # b: first > t
    t = k[:d]
    ya, yb = np.take_along_axis(y, below, 1), np.take_along_axis(y, above, 1)
    span = above - below
    radius = np.exp((ya - yb) / span)
    angle = 2 * np.pi * (t - below) / span + np.pi / span + OFFSET
    return radius * np.exp(1j * angle)


def _newton(c: np.ndarray, z: np.ndarray):
    """p(z)/p'(z) and |p(z)| with its rounding bound, at every z (sets, roots); for |z| > 1
    by the reversed polynomial in y = 1/z (p = z^d q(y), p' = z^(d-1) (d q - y q')), which
    keeps large roots from overflowing."""
    N, d1 = c.shape
    d = d1 - 1
    big = np.abs(z) > 1
    with np.errstate(all="ignore"):
        x = np.where(big, 1 / z, z)
    # Horner for both orders at once: p (small) or q (big), and their derivatives
    coef = np.where(big[..., None], c[:, None, :], c[:, None, ::-1])  # highest first for Horner
    p = coef[..., 0].astype(complex)
    dp = np.zeros_like(p)
    ap = np.abs(coef[..., 0])
    ax = np.abs(x)
    for k in range(1, d1):
        dp = dp * x + p
        p = p * x + coef[..., k]
        ap = ap * ax + np.abs(coef[..., k])
    with np.errstate(all="ignore"):
        w = np.where(big, z * p / (d * p - x * dp), p / dp)
        # |p(z)| itself (for the Weierstrass correction), with 2 d eps sum |c_k||z|^k
        zd = np.where(big, z ** d, 1.0)
        pz = np.abs(p * zd) + 2 * d1 * EPS * ap * np.abs(zd)
    return w, pz


def _aberth(c: np.ndarray):
    N, d1 = c.shape
    d = d1 - 1
    z = _starts(c)
    done = np.zeros(N, bool)
    off = ~np.eye(d, dtype=bool)
    for _ in range(ITERATIONS):
        live = np.flatnonzero(~done)
        if live.size == 0:
            break
        zl = z[live]
        w, _ = _newton(c[live], zl)
        diff = zl[:, :, None] - zl[:, None, :]
        with np.errstate(all="ignore"):
            s = np.sum(np.where(off, 1 / np.where(off, diff, 1), 0), axis=2)
            step = w / (1 - w * s)
        zl = zl - step
        z[live] = zl
        with np.errstate(invalid="ignore"):
            settled = np.all(np.abs(step) <= 4 * EPS * np.abs(zl), axis=1) | ~np.all(np.isfinite(zl), axis=1)
        done[live[settled]] = True
    return z, done


def radii(c: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The inclusion radius d |W_i| of every root approximation, relative to |z_i|."""
    N, d1 = c.shape
    d = d1 - 1
    _, pz = _newton(c, z)
    diff = z[:, :, None] - z[:, None, :]
    prod = np.prod(np.where(np.eye(d, dtype=bool), 1, diff), axis=2)
    with np.errstate(all="ignore"):
        return d * pz / (np.abs(c[:, -1])[:, None] * np.abs(prod)) / np.abs(z)


def roots(c: np.ndarray, model=None):
    """(z, relative inclusion radius, proven) of the polynomials c (sets, degree + 1),
    lowest coefficient first (module docstring). With a model, its compiled library's
    version (gyro/csrc/polyroots.c) where there is a compiler; NumPy otherwise."""
    c = np.asarray(c, dtype=float)
    N, d1 = c.shape
    d = d1 - 1
    z = np.full((N, d), np.nan + 0j)
    rad = np.full((N, d), np.inf)
    proven = np.zeros(N, bool)
    sens = np.full((N, d), np.inf)
    if d == 0:
        return z, rad, sens, np.ones(N, bool)
    kernel = None
    if model is not None:
        from gyro import cbackend
        from gyro.kernels import compiled

        kernel = compiled(cbackend.poly_roots, model)
    if kernel is not None:
        z, rad, sens, proven = kernel(c)
    else:
        rows = np.flatnonzero(np.all(np.isfinite(c), axis=1) & (c[:, 0] != 0) & (c[:, -1] != 0))
        if rows.size:
            zr, settled = _aberth(c[rows])
            z[rows[settled]] = zr[settled]
            proven[rows[settled]] = True
    # the others by the companion's eigenvalues; every approximation's disks checked here
    # (the theorem holds for any approximations: only their disjointness is needed)
    rest = np.flatnonzero(~proven)
    if rest.size:
        z[rest] = _companion(c[rest])
    check = rest if kernel is not None else np.arange(N)
    if check.size:
        r = radii(c[check], z[check])
        with np.errstate(invalid="ignore"):
            apart = np.all(np.isfinite(r), axis=1) & _disjoint(z[check], r)
        rad[check] = np.where(apart[:, None], r, np.inf)
        proven[check] = apart
        sens[check] = sensitivity(c[check], z[check])
    return z, rad, sens, proven


def sensitivity(c: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Each root's first-order relative sensitivity to a rounding of eps per coefficient,
    4 d eps sum |c_k| |z|^k / (|p'(z)| |z|)."""
    N, d1 = c.shape
    d = d1 - 1
    with np.errstate(all="ignore"):
        k = np.arange(d1)
        az = np.abs(z)
        num = np.sum(np.abs(c)[:, None, :] * az[..., None] ** k, axis=2)
        dc = c[:, 1:] * np.arange(1, d1)
        der = np.abs(np.sum(dc[:, None, :] * z[..., None] ** np.arange(d), axis=2))
        return 4 * d * EPS * num / (der * az)


def _disjoint(z: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(sets,) True where the disks |x - z_i| <= r_i |z_i| are pairwise disjoint."""
    d = z.shape[1]
    reach = r * np.abs(z)
    gap = np.abs(z[:, :, None] - z[:, None, :])
    return np.all(np.eye(d, dtype=bool) | (gap > reach[:, :, None] + reach[:, None, :]), axis=(1, 2))


def _companion(c: np.ndarray) -> np.ndarray:
    """Eigenvalues of each companion matrix (NaN where a coefficient is not finite or the
    leading one is zero)."""
    N, d1 = c.shape
    d = d1 - 1
    C = np.zeros((N, d, d))
    C[:, 1:, :-1] = np.eye(d - 1)
    with np.errstate(all="ignore"):
        C[:, :, -1] = -c[:, :-1] / c[:, -1:]
    good = np.all(np.isfinite(C), axis=(1, 2))
    z = np.full((N, d), np.nan + 0j)
    if good.any():
        z[good] = np.linalg.eigvals(C[good])
    return z
