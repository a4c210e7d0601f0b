"""``reference``: equilibrium, operator and eigenvalues in arbitrary precision (mpmath, 40
digits), each root polished by Newton on det J in the same precision; the estimate is the
size of the last Newton step."""
from __future__ import annotations

import mpmath
import numpy as np

from gyro import qep
from gyro.equilibrium import EquilibriumError, equilibria_reported, why_not
from gyro.models import Model
from gyro.results import Spectrum

NAME = "reference"
RUNG = 5
COST = 0.63  # s per set (bench/results/ladder.json)
DPS = 40


def _mp_equilibrium(mf, p, q0, idx, max_iter=60):
    """Newton in the working precision from q0. Converged where every step is within tol of
    its coordinate, or, for a coordinate far smaller than the others (the gyrohorizoncompass's
    beta = 5e-20 at (3.1), where its steps stay at the rounding of the others' residual),
    where the largest step is within tol of the largest coordinate and no longer shrinks.
    idx None: a model with multipliers, whose equilibrium has every coordinate as unknown
    and its own square system (the reduced residual and the constraints, the emitted
    equilibrium_system)."""
    q = [mpmath.mpf(v) for v in q0]
    if idx is not None and not idx:  # no equilibrium coordinates (a rotor centred by its bearings)
        return q
    tol = mpmath.mpf(10) ** (-mpmath.mp.dps + 5)
    last = None
    for _ in range(max_iter):
        if idx is None:
            r, Kee = mf.equilibrium_system(p, q)
            dq = mpmath.lu_solve(Kee, r)
        else:
            r = mf.equilibrium_residual(p, q)
            _, _, K = mf.operator(p, q)
            Kee = mpmath.matrix([[K[i, j] for j in idx] for i in idx])
            dq = mpmath.lu_solve(Kee, mpmath.matrix([r[i] for i in idx]))
        q = [qi + dqi for qi, dqi in zip(q, dq)]
        if all(abs(d) <= tol * max(abs(v), mpmath.mpf(10) ** -300) for d, v in zip(dq, q)):
            return q
        step = max(abs(d) for d in dq)
        if last is not None and step <= tol * max(abs(v) for v in q) and step > last / 2:
            return q  # at the rounding floor
        last = step
    raise EquilibriumError("Newton's method in extended precision did not converge")


def companion(M, D, K):
    """The first-order matrix [[0, I], [-M^-1 K, -M^-1 D]] of mpmath matrices, in the
    working precision (gyro.qep.companion_matrix's, in mpmath)."""
    n = M.rows
    Minv = mpmath.inverse(M)
    A = mpmath.zeros(2 * n, 2 * n)
    B, C = -Minv * K, -Minv * D
    for i in range(n):
        A[i, n + i] = 1
        for j in range(n):
            A[n + i, j], A[n + i, n + j] = B[i, j], C[i, j]
    return A


def _reference_roots(mf, p, start, idx):
    """One set in the working precision: (roots, their last Newton steps relative, q)."""
    q = _mp_equilibrium(mf, p, start, idx)
    M, D, K = mf.operator(p, q)
    n = M.rows
    lams = mpmath.eig(companion(M, D, K), left=False, right=False)
    lam_c = np.array([complex(v) for v in lams])
    roots, steps = [], []
    for r in qep.representatives(lam_c, n):
        lam = lams[int(np.argmin(np.abs(lam_c - r)))]
        J = M * lam**2 + D * lam + K
        dJ = M * (2 * lam) + D
        try:
            Jinv = mpmath.inverse(J)
            step = 1 / sum(Jinv[c, i] * dJ[i, c] for c in range(n) for i in range(n))
        except ZeroDivisionError:  # J singular in the working precision: lam is a root to it
            step = mpmath.mpf(0)
        lam = lam - step
        roots.append(lam)
        steps.append(abs(step) / abs(lam) if lam != 0 else mpmath.inf)
    return roots, steps, q


def solve(model: Model, P: np.ndarray, tol: float | None = None, dps: int = DPS) -> Spectrum:
    """Arbitrary precision: the equilibrium by Newton from the double one, the companion
    eigenvalues by mpmath.eig, each root polished by Newton on det J (trace of J^-1 J').
    The estimate is the last Newton step, floored at 10^(5 - dps), plus the effect of the
    inputs' rounding in this precision where a root lies far below the others, plus, for a
    root within 1e-6 of another (qep.cluster_rounding), the effect of rounding the decimal
    inputs to doubles (4 eps), which moves a colliding pair by its square root. A model
    without equilibrium coordinates (a rotor centred by its bearings) solves no equilibrium;
    a set without one is refused in one line naming the equation's residual."""
    mf = model.mpmath
    reduced = model.meta["reduced"]
    multipliers = bool(model.meta.get("constraints", {}).get("multipliers"))
    idx = None if multipliers else [reduced.index(c) for c in model.meta["equilibrium_coordinates"]]
    N = P.shape[0]
    qe_d, ok, report = equilibria_reported(model, P)
    out = None
    with mpmath.workdps(dps):
        for k in range(N):
            p = [mpmath.mpf(float(v)) for v in P[k]]
            if not ok[k]:  # equilibria() has tried the set-by-set solver as well
                raise EquilibriumError((f"set {k}: " if N > 1 else "") + why_not(model, report, k))
            start = qe_d[k]
            roots, steps, q = _reference_roots(mf, p, start, idx)
            n = len(roots)
            if out is None:
                out = [np.full((N, n), np.nan), np.full((N, n), np.nan), np.full((N, n), np.inf),
                       np.full((N, len(q)), np.nan)]
            lam = np.array([complex(r) for r in roots])
            est = np.maximum(np.array([float(x) for x in steps]), 10.0 ** (5 - dps))

            def solve_moved(_, p=p, start=start):  # the same move, in this precision
                moved = qep.moved(p, mpmath.mpf(10) ** (3 - dps))
                return [complex(r) for r in _reference_roots(mf, moved, start, idx)[0]]

            est = est + qep.input_rounding(model, P[k], lam, solve_moved)

            def solve_at(Pp, start=start):  # inputs moved in double precision
                return [complex(r) for r in _reference_roots(mf, [mpmath.mpf(float(v)) for v in Pp], start, idx)[0]]

            # a cluster of roots (a collision) moves with the rounding of the decimal inputs by
            # its square root, which the given doubles do not show
            est = est + qep.cluster_rounding(P[k], lam, solve_at)
            out[0][k], out[1][k], out[2][k] = np.abs(lam.imag), lam.real, est
            out[3][k] = [float(v) for v in q]
    f, g, e = qep.sort_spectrum(out[0], out[1], out[2])
    return Spectrum("reference", f, g, e, out[3])
