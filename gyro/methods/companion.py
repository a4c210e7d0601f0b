"""``companion``: eigenvalues of the balanced first-order (companion) matrix by LAPACK.
The estimate is each root's condition number (right and left eigenvectors) times the
backward error of forming and solving the first-order problem, over |lambda|: it holds on
damped, non-normal operators, where eps ||A|| / |lambda| does not (gyro.qep.eigen_radii)."""
from __future__ import annotations

import numpy as np

from gyro import qep
from gyro.equilibrium import equilibria, operators
from gyro.models import Model
from gyro.results import Spectrum

NAME = "companion"
RUNG = 3  # place on the ladder of accuracy (docs/methods.md)
COST = 1.5e-4  # s per set on one core: 2.6x the eigenvalues-only 5.8e-5 of bench/results/ladder.json (side by side, 2.4x..5.8x under load: balancing set by set and the eigenvectors for the condition numbers)


def solve(model: Model, P: np.ndarray, tol: float | None = None) -> Spectrum:
    """Eigenvalues of the balanced companion matrix of each set (LAPACK), one per pair,
    each with its condition number's estimate (gyro.qep.companion_roots)."""
    qe, ok = equilibria(model, P)
    M, D, K = operators(model, P, qe)
    n = M.shape[-1]
    lam = np.full((P.shape[0], n), np.nan + 0j)
    est = np.full((P.shape[0], n), np.inf)
    if ok.any():
        lam[ok], est[ok] = qep.companion_roots(M[ok], D[ok], K[ok])
        # the operator's own rounding, estimated (gyro.qep.equilibrium_moves: two probes)
        moves = qep.equilibrium_moves(model, P[ok], qe[ok], M[ok], D[ok], K[ok])
        est[ok] += qep.general_moves(moves, M[ok], D[ok], K[ok], lam[ok])
    f, g, e = qep.sort_spectrum(np.abs(lam.imag), lam.real, est)
    return Spectrum("companion", f, g, e, qe)
