"""``default``: scaled and structure-aware.

Per diagonal block of the operator, the gyroscopic problem with K > 0 is the Hermitian
pencil diag(K, M) z = omega B z with B = [[-iD, M], [M, 0]]; after a diagonal scaling and
Cholesky factors it is one small Hermitian eigenproblem (LAPACK), whose eigenvalues
1/omega are real. Each root is then refined on the full exact operator, where the blocks
are coupled weakly: one step of inverse iteration on J(i omega) and the Rayleigh
functional z* J(i omega) z = 0 (a quadratic in omega). Its estimate is a residual bound
plus the rounding floor of evaluating J. Sets where a block's K is not positive definite,
roots leave the real axis, two roots merge, or the estimate exceeds the tolerance,
escalate by themselves: first to the general companion solver with Newton refinement,
then to ``reference``. The block forms and the refinement run as compiled C (gyro/csrc/,
the kernels of the model's dimension), set by set and root by root in one call per batch; without a
compiler, as NumPy.
"""
from __future__ import annotations

import numpy as np

from gyro import qep
from gyro.equilibrium import EquilibriumError, equilibria, operators, tame
from gyro.kernels import chunks
from gyro.methods import DEFAULT_TOL
from gyro.models import Model
from gyro.results import Spectrum

NAME = "default"
RUNG = 4
COST = 3.6e-5  # s per set on one core, compiled (bench/results/ladder.json)
CHUNK = 8192


def solve(model: Model, P: np.ndarray, tol: float = DEFAULT_TOL) -> Spectrum:
    """The structured rung, escalating set by set to the general rung and then to the
    reference method where it cannot answer within tol."""
    if P.shape[0] > CHUNK:  # bounded memory: the block forms take 3 kB a set
        return Spectrum.concat([solve(model, P[s], tol) for s in chunks(P.shape[0], CHUNK)])
    N = P.shape[0]
    qe, ok = equilibria(model, P)
    M, D, K = operators(model, P, qe)
    moves = qep.equilibrium_moves(model, P, qe, M, D, K)  # the operator's own rounding, estimated
    n = M.shape[-1]
    freq = np.full((N, n), np.nan)
    growth = np.zeros((N, n))
    est = np.full((N, n), np.inf)
    # the structured path assumes a conservative gyroscopic operator (M, K symmetric, D skew
    # to the bit) far from overflow (tame); block_starts hands any other set (bearing
    # damping) to the general rung, which takes the sets tame among them
    herm, w0, z0 = qep.block_starts(model, M, D, K, ok)
    good = herm.copy()
    rest = np.flatnonzero(ok & ~herm)
    good[rest] = tame(M[rest]) & tame(D[rest]) & tame(K[rest])
    # which rung answered; "none" where no rung could (no equilibrium in any precision)
    route = np.where(good, "structured", "none").astype(object)
    h = np.flatnonzero(herm)
    if h.size:
        take = slice(None) if h.size == N else h
        Mh, Dh, Kh = M[take], D[take], K[take]
        w, z, e, fine = qep.rayleigh(model, Mh, Dh, Kh, w0, z0, 3, tol, overwrite=True)  # the starts' own arrays
        e = e + qep.hermitian_moves(tuple(X[take] for X in moves), Mh, Dh, w, z, model)
        ws_sorted = np.sort(w, axis=1)
        distinct = np.all(np.diff(ws_sorted, axis=1) > 1e-8 * ws_sorted[:, 1:], axis=1)
        # a root far below the others (omega1 -> 0 toward the pole or as u -> 0) carries the
        # rounding of the inputs themselves: measured by solving again with moved inputs
        wide = np.flatnonzero(np.all(fine, axis=1) & (np.min(w, axis=1) < qep.WIDE * np.max(w, axis=1)))
        if wide.size:
            e[wide] += qep.input_rounding_structured(model, P[h[wide]], w[wide], z[wide])
        fine = np.all(fine, axis=1) & distinct & np.all(e <= tol, axis=1)
        hf = h[fine]
        freq[hf], est[hf] = w[fine], e[fine]
        herm[h[~fine]] = False
    zero_root = np.zeros((N, n), bool)
    for k in np.flatnonzero(good & ~herm):
        route[k] = "general"
        roots, e = qep.general(M[k], D[k], K[k], tuple(X[k] for X in moves))  # with the operator's rounding
        e = e + qep.input_rounding(model, P[k], roots, lambda Pp: qep.general_at(model, Pp))
        freq[k], growth[k], est[k] = np.abs(roots.imag), roots.real, e
        # an exact zero root (omega1 without Earth rate, u = 0: a free azimuth). lambda = 0 is
        # a root exactly when K is singular; where K is singular in double precision to the
        # last bit (its smallest singular value is 0, not merely small: u cos(phi) = 1e-17
        # at the pole, or a tiny u, leave a small true root that the 40-digit rung resolves)
        # the smallest root, within tol of the spectrum's scale while the others are
        # answered, is that zero: 0 with a relative error of 1 (marginal), cheaply
        lam = np.abs(roots)
        j = int(np.argmin(lam))
        others = np.arange(n) != j
        if e[j] > tol and lam[j] <= tol * np.max(lam) and np.all(e[others] <= tol):
            sv = np.linalg.svd(K[k], compute_uv=False)
            if sv[-1] == 0.0:
                freq[k, j], growth[k, j], est[k, j] = 0.0, 0.0, 1.0
                zero_root[k, j] = True
                route[k] = "general, a zero root"
    for k in np.flatnonzero(~good | (np.max(np.where(zero_root, 0.0, est), axis=1) > tol)):
        try:
            from gyro.methods import reference  # the last rung, imported when reached

            ref = reference.solve(model, P[k:k + 1])
        except (EquilibriumError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            # extended precision cannot answer either (a singular equilibrium problem, as at
            # g = 0, or inputs beyond any precision): the general rung's answer stands, with
            # its own (larger) estimate
            continue
        route[k] = "reference"
        freq[k], growth[k], est[k] = ref.frequencies[0], ref.growth[0], ref.error_estimate[0]
        qe[k] = ref.equilibrium[0]
    f, g, e = qep.sort_spectrum(freq, growth, est)
    return Spectrum("default", f, g, e, qe, route)
