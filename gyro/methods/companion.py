"""``companion``: eigenvalues of the balanced first-order (companion) matrix by LAPACK.
The estimate is eps ||A|| / |lambda| (Bauer-Fike for a well-conditioned root)."""
from __future__ import annotations

import numpy as np

from gyro import qep
from gyro.equilibrium import equilibria, operators, tame
from gyro.models import Model
from gyro.results import Spectrum

NAME = "companion"
RUNG = 3  # place on the ladder of accuracy (docs/methods.md)
COST = 5.8e-5  # s per set on one core (bench/results/ladder.json): the relative cost


def solve(model: Model, P: np.ndarray, tol: float | None = None) -> Spectrum:
    """Eigenvalues of the balanced companion matrix of each set (LAPACK), one per pair."""
    qe, ok = equilibria(model, P)
    M, D, K = operators(model, P, qe)
    n = M.shape[-1]
    A = qep.companion_matrix(M, D, K)
    good = ok & tame(A)
    lam = np.full((P.shape[0], n), np.nan + 0j)
    if good.any():
        lam[good] = qep.pairs(np.linalg.eigvals(A[good]), n)
    # LAPACK balances A (D A D^-1) before its backward-stable QR iteration
    norm = np.linalg.norm(A, ord=1, axis=(1, 2))
    est = 2 * n * qep.EPS * norm[:, None] / np.abs(lam)
    f, g, e = qep.sort_spectrum(np.abs(lam.imag), lam.real, est)
    return Spectrum("companion", f, g, e, qe)
