"""``polyroots``: roots of the characteristic polynomial det J(p), a polynomial of degree n
in s = p^2 whose coefficients are fitted in double precision (the naive baseline). The
estimate is the root's sensitivity to the coefficients' rounding."""
from __future__ import annotations

import numpy as np

from gyro import qep
from gyro.equilibrium import equilibria, operators
from gyro.models import Model
from gyro.results import Spectrum

NAME = "polyroots"
RUNG = 2
COST = 4.2e-3  # s per set on one core (bench/results/ladder.json)


def solve(model: Model, P: np.ndarray, tol: float | None = None) -> Spectrum:
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
    # a damped or circulatory operator (D not skew, K or M not symmetric beyond rounding):
    # det J(i w) is complex and not a polynomial in p^2; those sets take the full fit in p
    general = ok & ~conservative(M, D, K)
    for k in np.flatnonzero(general):
        freq[k], growth[k], est[k] = _general_fit(M[k], D[k], K[k], R[k])
    for k in np.flatnonzero(ok & ~general & np.all(np.isfinite(dets), axis=1)):
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
        dc = qep.EPS * (n + 1) * np.max(np.abs(dets[k])) * conv.sum(axis=0)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # inf or nan: no bound
            ds = np.polynomial.polynomial.polyval(np.abs(roots_s), dc) / np.abs(
                np.polynomial.polynomial.polyval(roots_s, np.polynomial.polynomial.polyder(c)))
            e = 0.5 * ds / np.maximum(np.abs(roots_s), 1e-300)
        freq[k], growth[k] = np.abs(lam.imag), lam.real
        est[k] = np.where(e < 0.5, e, np.inf)  # a first-order bound past 1/2 bounds nothing
    # the operator's own rounding, estimated (gyro.qep.equilibrium_moves: two probes), where a
    # root was found
    done = np.flatnonzero(ok & np.any(np.isfinite(est), axis=1))
    if done.size:
        moves = qep.equilibrium_moves(model, P[done], qe[done], M[done], D[done], K[done])
        est[done] += qep.general_moves(moves, M[done], D[done], K[done], growth[done] + 1j * freq[done])
    f, g, e = qep.sort_spectrum(freq, growth, est)
    return Spectrum("polyroots", f, g, e, qe)


def conservative(M, D, K, rel: float = 16 * qep.EPS) -> np.ndarray:
    """Per set: M, K symmetric and D skew to rounding (rel of each matrix's largest entry)."""
    def off(X, sign):
        scale = np.max(np.abs(X), axis=(1, 2))
        return np.max(np.abs(X - sign * np.swapaxes(X, 1, 2)), axis=(1, 2)) <= rel * scale

    with np.errstate(all="ignore"):
        return off(M, 1) & off(K, 1) & off(D, -1)


def _general_fit(M, D, K, R):
    """det J(p), a polynomial of degree 2n in p, fitted from 2n + 1 Chebyshev points p = i Y t
    (t in [-1, 1], Y = sqrt(R) bounds the frequencies), complex; roots in x = p/(i Y) by
    numpy.roots. The estimate carries the fit's rounding (eps max|det| per Chebyshev
    coefficient, through the conversion to the power basis) into each root to first order,
    as for the conservative fit; past 1/2 it bounds nothing (inf)."""
    n = M.shape[-1]
    nan = (np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.inf))
    Y = np.sqrt(R)
    if not (np.isfinite(Y) and Y > 0):
        return nan
    t = np.cos(np.pi * (np.arange(2 * n + 1) + 0.5) / (2 * n + 1))
    p = 1j * Y * t
    with np.errstate(all="ignore"):
        dets = np.linalg.det(M * (p**2)[:, None, None] + D * p[:, None, None] + K)
    if not np.all(np.isfinite(dets)):
        return nan
    cheb = np.polynomial.chebyshev.chebfit(t, dets, 2 * n)
    c = np.polynomial.chebyshev.cheb2poly(cheb)
    x = np.roots(c[::-1])
    if len(x) != 2 * n:
        return nan
    lam = 1j * Y * x
    conv = np.abs(np.array([np.pad(b := np.polynomial.chebyshev.cheb2poly(np.eye(2 * n + 1)[j]), (0, 2 * n + 1 - len(b)))
                            for j in range(2 * n + 1)]))  # (cheb, power)
    dc = qep.EPS * (2 * n + 1) * np.max(np.abs(dets)) * conv.sum(axis=0)
    dx = np.polynomial.polynomial.polyval(np.abs(x), dc) / np.abs(
        np.polynomial.polynomial.polyval(x, np.polynomial.polynomial.polyder(c)))
    e = dx / np.maximum(np.abs(x), 1e-300)
    e = np.where(e < 0.5, e, np.inf)
    keep = np.isin(np.arange(2 * n), [int(np.argmin(np.abs(lam - r))) for r in qep.representatives(lam, n)])
    lam, e = lam[keep], e[keep]
    if len(lam) != n:
        return nan
    return np.abs(lam.imag), lam.real, e
