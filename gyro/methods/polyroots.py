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
        dc = qep.EPS * (n + 1) * np.max(np.abs(dets[k])) * conv.sum(axis=0)
        ds = np.polynomial.polynomial.polyval(np.abs(roots_s), dc) / np.abs(
            np.polynomial.polynomial.polyval(roots_s, np.polynomial.polynomial.polyder(c)))
        freq[k], growth[k] = np.abs(lam.imag), lam.real
        e = 0.5 * ds / np.maximum(np.abs(roots_s), 1e-300)
        est[k] = np.where(e < 0.5, e, np.inf)  # a first-order bound past 1/2 bounds nothing
    f, g, e = qep.sort_spectrum(freq, growth, est)
    return Spectrum("polyroots", f, g, e, qe)
