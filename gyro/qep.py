"""Numerics of the quadratic eigenproblem (M lambda^2 + D lambda + K) x = 0 over a batch:
the companion (first-order) eigensolver, Newton's iteration on J(lambda) through its
singular vectors, the Hermitian block form of a gyroscopic block with K > 0, and inverse
iteration with the Rayleigh functional on J(i omega). The frequency methods of
gyro.methods are built from these; compiled twins of the batched pieces are the kernels of
gyro/csrc/ (qep.c, qep_starts.c), dispatched by gyro.kernels.
"""
from __future__ import annotations

import numpy as np

from gyro import cbackend
from gyro.equilibrium import equilibria, operators, tame
from gyro.kernels import compiled
from gyro.models import Model

EPS = np.finfo(float).eps
UNIT_ROUNDOFF = 2.0**-53  # u = EPS / 2
WIDE = 1e-6  # a root below WIDE x the largest: the spectrum spans more than six decades


def companion_matrix(M, D, K):
    """The first-order matrix [[0, I], [-M^-1 K, -M^-1 D]] of one operator or of a batch
    (leading axes)."""
    n = M.shape[-1]
    A = np.zeros(M.shape[:-2] + (2 * n, 2 * n))
    A[..., :n, n:] = np.eye(n)
    A[..., n:, :n] = -np.linalg.solve(M, K)
    A[..., n:, n:] = -np.linalg.solve(M, D)
    return A


def companion_eigenvalues(M, D, K):
    # LAPACK balances A (D A D^-1), which evens out the rows of a spectrum spread over five
    # orders of magnitude, before its QR iteration
    import scipy.linalg as sla  # imported where needed: the default rung rarely comes here

    return sla.eigvals(companion_matrix(M, D, K), check_finite=True, overwrite_a=True,
                       homogeneous_eigvals=False)


def refine(M, D, K, lam: complex, iters: int = 8) -> tuple[complex, float]:
    """Newton's iteration on det J(lambda) = 0 through the smallest singular triplet of
    J(lambda) = M lambda^2 + D lambda + K: lambda -= y* J x / y* J' x.
    Returns the root and the last relative step (an estimate of its error)."""
    step = np.inf
    for _ in range(iters):
        J = M * lam**2 + D * lam + K
        U, s, Vh = np.linalg.svd(J)
        x, y = Vh[-1].conj(), U[:, -1]
        dJ = 2 * M * lam + D
        den = y.conj() @ dJ @ x
        res = y.conj() @ J @ x
        if den == 0:  # a root where J' annihilates the null vector (e.g. lambda = 0 at g = 0)
            step = 0.0 if res == 0 else np.inf
            break
        d = res / den
        lam = lam - d
        step = abs(d) / max(abs(lam), 1e-300)
        if step < 1e-15:
            break
    return lam, step


def representatives(lams: np.ndarray, n: int) -> np.ndarray:
    """One root of each pair of the 2n eigenvalues of a real quadratic eigenproblem: a mode.

    The eigenvalues of a real problem come in conjugate pairs lambda, conj(lambda); a mode
    is such a pair, whatever |Re| and |Im| are, and is represented by its member with
    Im > 0. A flutter quadruple +-a +- ib of a gyroscopic system is two modes, one growing
    (a + ib) and one decaying (-a + ib). Real roots are their own conjugates: the 2c complex
    roots give c modes, and the n - c further representatives are the real roots of largest
    Re (a divergent pair +-sigma gives +sigma, so that no growth rate is hidden)."""
    return lams[representative_indices(lams, n)]


def representative_indices(lams: np.ndarray, n: int) -> np.ndarray:
    """The indices into lams of `representatives`, in the same order. A root counts as
    real where |Im| <= REAL |lambda| (the rounding of a real root's imaginary part by an
    eigensolver that does not return exact conjugates; LAPACK's are exact)."""
    lams = np.asarray(lams)
    real = np.abs(lams.imag) <= REAL * np.abs(lams)
    upper = ~real & (lams.imag > 0)
    need = n - int(upper.sum())
    if 0 <= need <= int(real.sum()) and int((~real & (lams.imag < 0)).sum()) == int(upper.sum()):
        r = np.flatnonzero(real)
        keep = np.concatenate([np.flatnonzero(upper), r[np.argsort(-lams.real[r], kind="stable")[:need]]])
        return np.sort(keep)
    # rounding broke the pairing: the n most "upper", then the largest Re
    return np.sort(np.lexsort((-lams.real, -np.round(lams.imag / np.maximum(np.abs(lams), 1e-300), 12)))[:n])


REAL = 64 * EPS


def refine_all(M, D, K, lams: np.ndarray, chosen: np.ndarray):
    """Refine each chosen root; keep a refinement only if it stays within half the distance
    to the nearest other eigenvalue (otherwise Newton has left the root's basin)."""
    roots, errs = [], []
    for lam in chosen:
        others = lams[np.abs(lams - lam) > 0]
        gap = np.min(np.abs(others - lam)) if len(others) else np.inf
        new, err = refine(M, D, K, complex(lam))
        if abs(new - lam) <= 0.5 * gap:
            roots.append(new)
            errs.append(err)
        else:
            roots.append(complex(lam))
            errs.append(np.inf)
    return np.array(roots), np.array(errs)


def blocks(model: Model) -> list[np.ndarray]:
    """Index sets of the operator's diagonal blocks (coupled weakly in the exact operator)."""
    reduced = model.meta["reduced"]
    for v in model.meta.get("variants", {}).values():
        if v.get("blocks"):
            return [np.array([reduced.index(c) for c in b]) for b in v["blocks"]]
    return [np.arange(len(reduced))]


def sort_spectrum(freq, growth, est):
    """Ascending by |lambda|: by frequency for a stable set, and the real roots of an
    unstable set (frequency 0 up to rounding) by their growth rate, in every method alike."""
    order = np.argsort(np.abs(growth + 1j * freq), axis=1)
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    return take(freq), take(growth), take(est)


def eigen_radii(A: np.ndarray, M: np.ndarray):
    """Eigenvalues of a batch of companion matrices A (sets, 2n, 2n) and a radius each that
    bounds its distance to the exact eigenvalue at the decimal inputs: n_A kappa_i ||E||_2,
    with kappa_i = ||x_i|| ||y_i|| / |y_i^H x_i| (right and left eigenvectors; the rows of
    X^-1 are the left ones) and ||E||_2 <= ||E||_F <= u ||A||_F (2 n_A + 3 n_A cond_2(M)):
    n_A for the rounding of the inputs and of M, D, K (measured: at most 2.4 u ||A||_F
    against 40 digits, tests/paper/test_verdict.py), n_A for LAPACK's QR iteration (backward
    error p(n) u ||A||, p(n) ~ n), 3 n_A cond(M) for the two solves with M (LU, growth 1 for
    M > 0). The factor n_A: every eigenvalue of A + E lies in a disk of radius
    n_A kappa_i ||E||_2 about some lambda_i (a Bauer-Fike theorem with individual condition
    numbers, Demmel 1997, Thm 4.5), not only to first order. A defective eigenvalue has
    kappa = inf: its radius is infinite. docs/gyrohorizoncompass.md, "Boundaries"."""
    nA = A.shape[-1]
    with np.errstate(all="ignore"):
        w, X = np.linalg.eig(A)
        kappa = np.full(w.shape, np.inf)
        try:
            kappa[:] = np.linalg.norm(X, axis=1) * np.linalg.norm(np.linalg.inv(X), axis=2)
        except np.linalg.LinAlgError:  # an exactly singular X somewhere: set by set
            for k in range(len(A)):
                try:
                    kappa[k] = np.linalg.norm(X[k], axis=0) * np.linalg.norm(np.linalg.inv(X[k]), axis=1)
                except np.linalg.LinAlgError:
                    continue
        E = UNIT_ROUNDOFF * np.linalg.norm(A, axis=(1, 2)) * (2 * nA + 3 * nA * np.linalg.cond(M))
        radius = nA * np.where(np.isfinite(kappa), kappa, np.inf) * E[:, None]
    return w, np.where(np.isfinite(radius), radius, np.inf)


def balanced_radii(A: np.ndarray, M: np.ndarray):
    """eigen_radii on each set's balanced first-order matrix B = T^-1 A T (LAPACK's own
    balancing, scipy.linalg.matrix_balance, an exact similarity by powers of 2): the
    eigenvalues are B's (and A's), the condition numbers and the norm B's, and cond(M) that
    of M scaled to a unit diagonal. The QR iteration's backward error is relative to ||B||,
    not ||A||; the rounding of the inputs and of forming -M^-1 K, -M^-1 D is relative entry
    by entry, so it maps into B with ||T^-1 E T||_F <= the same multiple of ||B||_F; and the
    solves with M err as its diagonally scaled condition number says (van der Sluis). On an
    operator whose entries span decades (the torsion gyrocompass's eleven) the unbalanced
    radii are 1e5..1e7 times these."""
    import scipy.linalg as sla

    d = 1 / np.sqrt(np.abs(np.einsum("bii->bi", M)))
    Ms = M * d[:, :, None] * d[:, None, :]
    B = np.empty_like(A)
    for k in range(len(A)):
        B[k] = sla.matrix_balance(A[k], permute=False)[0]
    return eigen_radii(B, Ms)


def companion_roots(M, D, K):
    """One root per pair of each set's first-order matrix (LAPACK, balanced), and its
    relative error estimate: balanced_radii's radius over |lambda|, the root's own condition
    number times the backward error of forming and solving the first-order problem. A
    damped or circulatory operator's first-order matrix can be far from normal, where
    eps ||A|| / |lambda| (Bauer-Fike for a normal matrix) is beaten by orders of magnitude
    (tests/methods/test_companion_bound.py); a defective or non-finite set gets an infinite one."""
    N, n = M.shape[0], M.shape[-1]
    A = companion_matrix(M, D, K)
    lam = np.full((N, n), np.nan + 0j)
    est = np.full((N, n), np.inf)
    good = tame(A)
    if good.any():
        w, r = balanced_radii(A[good], M[good])
        idx = np.array([representative_indices(x, n) for x in w])
        rows = np.arange(len(w))[:, None]
        lam[good] = w[rows, idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            est[good] = np.where(np.abs(lam[good]) > 0, r[rows, idx] / np.abs(lam[good]), np.inf)
    return lam, est


def pairs(lams: np.ndarray, n: int) -> np.ndarray:
    """One eigenvalue per pair, for each set (gyro.representatives, batched)."""
    return np.array([representatives(l, n) for l in lams])


def hermitian_block(M, D, K):
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


def start_vectors(N, n, r):
    """A fixed generic complex start vector for inverse iteration (seeded: reproducible)."""
    rng = np.random.default_rng(20261124)
    v = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    return np.broadcast_to(v, (N, r, n))


def _mv(A, z, sym):
    """A z for a batch of real (B, n, n) matrices and complex vectors z (B, r, n); A is
    symmetric (sym = 1) or skew (sym = -1), so that z @ A^T = sym z @ A."""
    out = np.matmul(z.real, A) + 1j * np.matmul(z.imag, A)
    return out if sym == 1 else -out


def rayleigh_step(M, D, K, w, z):
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


def rayleigh(model: Model, M, D, K, w, z, iters, tol, chunk=256, overwrite=False):
    """Steps of rayleigh_step on every root until its estimate is <= tol (at most `iters`).
    Compiled: the refinement of the model's dimension (gyro/csrc/qep.c), root by root (with
    overwrite, in the caller's w and z where their layout allows: no copy of the vectors).
    Without a compiler: rayleigh_step on every root, in chunks of sets (cache-sized), then
    further steps only on the roots whose estimate still exceeds tol. Returns (w, z,
    estimate, ok)."""
    kernel = compiled(cbackend.qep_refine, model)
    if kernel is not None:
        return kernel(M, D, K, w, z, iters, tol, overwrite=overwrite)
    N = M.shape[0]
    w, z = w.copy(), np.array(np.broadcast_to(z, w.shape + (M.shape[-1],)), dtype=complex)
    est = np.full(w.shape, np.inf)
    ok = np.zeros(w.shape, bool)
    for s in range(0, N, chunk):
        sl = slice(s, s + chunk)
        w[sl], z[sl], est[sl], ok[sl] = rayleigh_step(M[sl], D[sl], K[sl], w[sl], z[sl])
    for _ in range(iters - 1):
        bi, ri = np.nonzero(ok & (est > tol))
        if bi.size == 0:
            break
        wn, zn, e, o = rayleigh_step(M[bi], D[bi], K[bi], w[bi, ri][:, None], z[bi, ri][:, None])
        w[bi, ri], z[bi, ri], est[bi, ri], ok[bi, ri] = wn[:, 0], zn[:, 0], e[:, 0], o[:, 0]
    return w, z, est, ok


def general(M, D, K, moves=None):
    """The general rung for one set: companion eigenvalues, each refined by Newton on J.

    The estimate is the last Newton step (quadratic convergence leaves far less) plus the
    rounding floor eps |y| (|M||l|^2 + |D||l| + |K|) |x| / (|l| |y* J'(l) x|) of the root,
    with x, y the singular vectors of J(l) at its smallest singular value; with `moves`
    (|dM|, |dD|, |dK|: the operator's own rounding, equilibrium_moves) also the same form
    in them (as general_moves, from the same vectors)."""
    n = M.shape[0]
    if not (tame(M) and tame(D) and tame(K)):
        return np.full(n, np.nan + 0j), np.full(n, np.inf)
    lams = companion_eigenvalues(M, D, K)
    roots, errs = refine_all(M, D, K, lams, representatives(lams, n))
    est = np.empty(n)
    for j, lam in enumerate(roots):
        U, _, Vh = np.linalg.svd(M * lam**2 + D * lam + K)
        x, y = Vh[-1].conj(), U[:, -1]
        scale = np.abs(y) @ (np.abs(M) * abs(lam)**2 + np.abs(D) * abs(lam) + np.abs(K)) @ np.abs(x)
        slope = abs(y.conj() @ (2 * M * lam + D) @ x) * max(abs(lam), 1e-300)
        est[j] = errs[j] + 4 * n * EPS * scale / max(slope, 1e-300)
        if moves is not None:
            dM, dD, dK = moves
            op = np.abs(y) @ (dM * abs(lam)**2 + dD * abs(lam) + dK) @ np.abs(x)
            est[j] += 0.0 if op == 0 else op / slope if slope > 0 else np.inf
    return roots, est


EQ_MOVE = 2 * EPS  # each equilibrium coordinate moved by this, relative: 4x its rounding's u |q|
INPUT_MOVE = 4 * EPS  # each parameter moved by this, relative (as input_rounding moves them)


def equilibrium_moves(model: Model, P, qe, M, D, K):
    """An estimate (not a bound) of the double operator's own rounding, entrywise in absolute
    value, beyond what an estimate of the eigenproblem at the given M, D, K sees, for the
    double methods' estimates (the certificate's count takes an enclosure instead:
    gyro.rounding.operator_rounding; two probes in fixed directions miss an entry whose
    rounding they do not move, tests/methods/test_rounding_enclosure.py): the largest
    change of M, D, K over two fixed perturbations, each moving every equilibrium coordinate by EQ_MOVE and
    every parameter by INPUT_MOVE relative, with signs alternating in runs of 1 and of 2
    (one pattern alone leaves a product or a ratio of two inputs unmoved).
    - The equilibrium's rounding: large where the operator turns a coordinate's absolute
      rounding into a large relative one, the gyrohorizoncompass at epsilon0 = 89.99 deg:
      cos(epsilon0) = 1.3e-4 from epsilon rounded by 8.4e-17 put M and D entries off by 1e-11
      and omega3 by 6.3e-13, against an estimate of 7.3e-15 without this.
    - The entries' own formation: an entry formed by cancellation (a K entry off by 42 eps,
      omega2 by 4.7e-15 against 3.6e-15) moves with its inputs as it moves with the rounding
      of its terms.
    A coordinate that is exactly zero (a symmetric equilibrium) does not move."""
    P, qe = np.asarray(P, dtype=float), np.asarray(qe, dtype=float)
    out = None
    with np.errstate(all="ignore"):  # a non-finite change stays one: no bound there
        for period in (1, 2):
            Pm, qm = moved(P, INPUT_MOVE, period), moved(qe, EQ_MOVE, period)
            d = operators(model, Pm, qm)  # fresh arrays of our own: changed in place
            for X, Y in zip(d, (M, D, K)):
                np.abs(np.subtract(X, Y, out=X), out=X)
            out = d if out is None else [np.fmax(a, b, out=a) for a, b in zip(out, d)]
    return tuple(out)


def hermitian_moves(moves, M, D, w, z, model: Model | None = None) -> np.ndarray:
    """Each root's move, relative, under an entrywise change |dM|, |dD|, |dK| of a
    gyroscopic operator, to first order from its vector z (B, r, n): the Rayleigh functional
    a w^2 + beta w - c moves by at most |z|^T (w^2 |dM| + w |dD| + |dK|) |z|, the root by
    that over |2 a w + beta| (gyro.qep.rayleigh_step's estimate, with |dJ| for eps |J|).
    Compiled (gyro/csrc/qep.c) where there is a compiler, this NumPy otherwise."""
    if model is not None:
        kernel = compiled(cbackend.qep_moves, model)
        if kernel is not None:
            return kernel(moves, M, D, w, z)
    dM, dD, dK = moves
    x, y = np.ascontiguousarray(z.real), np.ascontiguousarray(z.imag)  # (B, r, n)
    az = np.abs(z)

    def form(u, A, v):  # u_r' A v_r for every set and root (batched matmul: the fast route)
        return np.einsum("bri,bri->br", u, v @ A.transpose(0, 2, 1))

    with np.errstate(all="ignore"):
        num = form(az, dK, az) + w**2 * form(az, dM, az) + w * form(az, dD, az)
        # z* M z = x'Mx + y'My (M symmetric), Im z* D z = 2 x'Dy (D skew)
        a = form(x, M, x) + form(y, M, y)
        beta = 2 * form(x, D, y)
        out = num / (np.abs(2 * a * w + beta) * w)
    return np.where(np.isfinite(out), out, np.inf)


def general_moves(moves, M, D, K, lam, chunk=1024) -> np.ndarray:
    """Each root's move, relative, under an entrywise change |dM|, |dD|, |dK|, for any
    operator (damped, circulatory): x, y the singular vectors of J(lam) at its smallest
    singular value, |y|^T (|dM| |lam|^2 + |dD| |lam| + |dK|) |x| / (|lam| |y* J'(lam) x|),
    to first order; per set and root (B, r), inf where a root or a change is not finite."""
    dM, dD, dK = moves
    B, r = lam.shape
    out = np.full((B, r), np.inf)
    fine = np.isfinite(lam) & np.all(np.isfinite(dM) & np.isfinite(dD) & np.isfinite(dK), axis=(1, 2))[:, None]
    fine &= np.all(np.isfinite(M) & np.isfinite(D) & np.isfinite(K), axis=(1, 2))[:, None]
    b_all, j_all = np.nonzero(fine)
    for s in range(0, len(b_all), chunk):
        b, j = b_all[s:s + chunk], j_all[s:s + chunk]
        l = lam[b, j][:, None, None]
        U, _, Vh = np.linalg.svd(M[b] * l**2 + D[b] * l + K[b])
        x, y = Vh[:, -1].conj(), U[:, :, -1]
        al = np.abs(l)
        scale = np.einsum("ki,kij,kj->k", np.abs(y), dM[b] * al**2 + dD[b] * al + dK[b], np.abs(x))
        slope = np.abs(np.einsum("ki,kij,kj->k", y.conj(), 2 * M[b] * l + D[b], x)) * np.maximum(al[:, 0, 0], 1e-300)
        with np.errstate(divide="ignore", invalid="ignore"):  # no change moves nothing (a zero root of a zero block)
            out[b, j] = np.where(scale == 0, 0.0, np.where(slope > 0, scale / slope, np.inf))
    return out


def moved(p, rel, period: int = 1):
    """Parameters (last axis; NumPy or a list of mpf) each moved by rel relative, with signs
    alternating in runs of `period`: a fixed, reproducible perturbation of the inputs."""
    if isinstance(p, np.ndarray):
        return p * (1 + rel * np.where((np.arange(p.shape[-1]) // period) % 2 == 0, 1.0, -1.0))
    return [v * (1 + (rel if (i // period) % 2 == 0 else -rel)) for i, v in enumerate(p)]


def general_at(model: Model, p: np.ndarray) -> np.ndarray:
    qe, _ = equilibria(model, p[None])
    M, D, K = operators(model, p[None], qe)
    return general(M[0], D[0], K[0])[0]


def input_rounding(model: Model, p, roots, solve, rel=4 * EPS) -> np.ndarray:
    """The part of each root's error that comes from rounding the inputs: when a root lies
    far below the others (ratio < WIDE), the set is solved again with every parameter
    moved by `rel` relative (moved: signs fixed, reproducible) and the change of each
    root, relative, is the estimate; zero otherwise. E.g. at phi = 90 deg, cos(pi phi/180)
    rounds to 6e-17 instead of 0 and omega1 is rounding noise: the estimate says so."""
    mags = np.abs(roots)
    if not np.min(mags) < WIDE * np.max(mags):
        return np.zeros(len(roots))
    after = np.sort(np.abs(np.asarray(solve(moved(np.asarray(p), rel)))))
    order = np.argsort(mags)
    out = np.empty(len(roots))
    out[order] = np.abs(after - mags[order]) / np.maximum(mags[order], 1e-300)
    return out


CLOSE = 1e-6  # roots within CLOSE of each other, relative: a cluster, sensitive to the inputs


def cluster_rounding(p, roots, solve, rel=4 * EPS) -> np.ndarray:
    """The part of each root's error that comes from rounding the inputs, for the roots of a
    cluster (another root within CLOSE of it, relative): a c-fold root moves by the c-th root
    of a perturbation (a near-Jordan block at a collision: by its square root, 1e-8 for
    4 eps), which no estimate of the solve at the given inputs sees. The set is solved again
    with every parameter moved by +rel and by -rel relative (moved: signs alternating over
    the parameters, fixed), and each clustered root's distance to the nearest root of each,
    relative, is the estimate (the larger of the two); zero for the other roots. E.g. a
    sleeping top at its critical spin to the last digit: the 40-digit roots are on the axis
    and 1e-9 apart at the given doubles, and off it at inputs moved by 4 eps."""
    lam = np.asarray(roots, complex)
    mags = np.abs(lam)
    d = np.abs(lam[:, None] - lam[None, :]) + np.diag(np.full(len(lam), np.inf))
    close = (mags > 0) & np.any(d <= CLOSE * np.maximum(mags[:, None], mags[None, :]), axis=1)
    out = np.zeros(len(lam))
    if not close.any():
        return out
    for sign in (1.0, -1.0):
        after = np.asarray(solve(moved(np.asarray(p, dtype=float), sign * rel)), complex)
        change = np.min(np.abs(lam[close][:, None] - after[None, :]), axis=1) / mags[close]
        out[close] = np.maximum(out[close], np.where(np.isfinite(change), change, np.inf))
    return out


def input_rounding_structured(model: Model, P, w, z, rel=4 * EPS):
    """input_rounding for the structured rung, batched: the smallest root of each set is
    followed to the moved inputs by one Rayleigh step from its converged vector."""
    Pm = moved(P, rel)
    qe, _ = equilibria(model, Pm)
    M, D, K = operators(model, Pm, qe)
    j = np.argmin(w, axis=1)
    rows = np.arange(len(w))
    w_small = w[rows, j]
    wm, _, _, ok = rayleigh(model, M, D, K, w_small[:, None], z[rows, j][:, None], 1, 0.0)
    change = np.where(ok[:, 0], np.abs(wm[:, 0] - w_small) / w_small, np.inf)
    out = np.zeros(w.shape)
    out[rows, j] = change
    return out


def pivots_above(A, floor) -> np.ndarray:
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


def gyroscopic(M, D, K) -> np.ndarray:
    """Per set: M and K symmetric and D skew to the bit, the structure the Hermitian forms
    and the refinement rest on (a damping matrix, a symmetric part of D, moves the roots
    off the imaginary axis: such sets go to the general rung)."""
    T = lambda X: X.swapaxes(-1, -2)  # noqa: E731
    return np.all((M == T(M)) & (K == T(K)) & (D == -T(D)), axis=(-1, -2))


def block_vectors(M, D, K, w, blocks_, rhs):
    """A unit start vector per root (sets, n, n): for the roots w (sets, n) of the blocks,
    listed block after block, one step of inverse iteration on the block's own
    J_b(i w) = K_b - w^2 M_b + i w D_b from the fixed rhs, zero outside the block. Its
    error is the weak coupling between the blocks, so that one step on the full operator
    mostly meets the tolerance (a shared start vector left 59 % of the roots needing a
    second step: docs/methods.md)."""
    N, n = w.shape
    z = np.zeros((N, n, n), complex)
    off = 0
    for b in blocks_:
        nb = len(b)
        wb = w[:, off:off + nb, None, None]
        Mb, Db, Kb = (X[:, b][:, :, b][:, None] for X in (M, D, K))
        x = None
        for shift in (0.0, 64 * EPS, 1e-10, 1e-7):  # as in rayleigh_step: a root to the last bit
            ws = wb * (1 + shift)
            try:
                x = np.linalg.solve(Kb - ws**2 * Mb + 1j * ws * Db,
                                    np.broadcast_to(rhs[b], (N, nb, nb))[..., None])[..., 0]
                break
            except np.linalg.LinAlgError:
                continue
        if x is None:
            return z, np.zeros(N, bool)
        z[:, off:off + nb, b] = x
        off += nb
    nrm = np.linalg.norm(z, axis=-1, keepdims=True)
    fine = np.all(np.isfinite(nrm[..., 0]) & (nrm[..., 0] > 0), axis=1)
    with np.errstate(all="ignore"):
        return z / nrm, fine


def block_starts(model: Model, M, D, K, good):
    """Which sets take the Hermitian path (gyroscopic: M, K symmetric and D skew, every
    entry far from overflow as gyro.equilibrium.tame has it; K > 0 and
    M > 0 in every diagonal block, with a margin) and, for those, the block problems' frequencies (sets taken, n) and a vector
    per root (sets taken, n, n): the starts of the refinement. Compiled: the model's
    block forms and their eigenvalues without LAPACK (gyro/csrc/qep_starts.c),
    whose Cholesky pivots must exceed 1e3 eps; without a compiler: the same test on the
    leading principal minors (pivots_above), hermitian_block and block_vectors."""
    kernel = compiled(cbackend.qep_block_starts, model)
    blocks_ = blocks(model)
    n = M.shape[-1]
    rhs = start_vectors(1, n, 1)[0, 0]
    if kernel is not None:
        w, z, ok = kernel(M, D, K, blocks_, rhs)
        herm = good & ok
        if herm.all():  # no copy when all take it
            return herm, w, z
        h = np.flatnonzero(herm)
        return herm, w[h], z[h]
    dK, dM = np.einsum("bii->bi", K), np.einsum("bii->bi", M)
    herm = (good & np.all(dK > 0, axis=1) & np.all(dM > 0, axis=1) & gyroscopic(M, D, K)
            & tame(M) & tame(D) & tame(K))
    for b in blocks_:
        for X, d in ((K, dK), (M, dM)):
            with np.errstate(all="ignore"):
                s = 1 / np.sqrt(d[:, b])
                herm &= pivots_above(X[:, b][:, :, b] * s[:, :, None] * s[:, None, :], 1e3 * EPS)
    h = np.flatnonzero(herm)
    Mh, Dh, Kh = M[h], D[h], K[h]
    w = np.concatenate([hermitian_block(Mh[:, b][:, :, b], Dh[:, b][:, :, b], Kh[:, b][:, :, b])
                        for b in blocks_], axis=1)
    z, fine = block_vectors(Mh, Dh, Kh, w, blocks_, rhs)
    herm[h[~fine]] = False
    return herm, w[fine], z[fine]


EIGENVECTOR_CHUNK = 2048  # sets per pass: J(lambda) of every root is (sets, r, n, n) complex


def eigenvectors(M, D, K, lam) -> np.ndarray:
    """Right eigenvectors x of J(lambda) x = 0 for a batch: M, D, K (B, n, n), roots lam
    (B, r); x (B, r, n) the right singular vector of J(lambda) at its smallest singular value,
    of unit length, its largest component real and positive (a mode shape, in the
    coordinates' own units). NaN where lambda is not finite. The batch is taken
    EIGENVECTOR_CHUNK sets at a time (each set's vectors are its own): a Campbell diagram of
    1e5 spins held 5.2 GB at once, J and its shifted copy for every root of every spin."""
    lam = np.asarray(lam, complex)
    B = lam.shape[0]
    if B > EIGENVECTOR_CHUNK:
        return np.concatenate([_eigenvectors(M[i:i + EIGENVECTOR_CHUNK], D[i:i + EIGENVECTOR_CHUNK],
                                             K[i:i + EIGENVECTOR_CHUNK], lam[i:i + EIGENVECTOR_CHUNK])
                               for i in range(0, B, EIGENVECTOR_CHUNK)])
    return _eigenvectors(M, D, K, lam)


def _eigenvectors(M, D, K, lam) -> np.ndarray:
    lam = np.asarray(lam, complex)
    good = np.isfinite(lam)
    lz = np.where(good, lam, 0.0)[..., None, None]
    J = M[:, None] * lz**2 + D[:, None] * lz + K[:, None]
    with np.errstate(all="ignore"):
        J = np.where(np.isfinite(J), J, 0.0)
        x = _inverse_iteration(M, D, K, lz, J)
        # where two steps of inverse iteration leave a residual above 1e-10 |J| (a shift that
        # makes J exactly singular, a multiple root), the singular vector of J itself
        res = np.linalg.norm(np.einsum("...ij,...j->...i", J, x), axis=-1)
        bad = ~(res <= 1e-10 * np.max(np.abs(J), axis=(-2, -1)))
        if bad.any():
            x[bad] = np.linalg.svd(J[bad])[2][..., -1, :].conj()
    big = np.take_along_axis(x, np.argmax(np.abs(x), axis=-1)[..., None], axis=-1)
    x = x * (np.abs(big) / np.where(big == 0, 1.0, big))
    x /= np.maximum(np.linalg.norm(x, axis=-1, keepdims=True), 1e-300)
    x[~good] = np.nan
    return x


def _inverse_iteration(M, D, K, lz, J, steps=2):
    """Two steps of inverse iteration on J(lambda (1 + 2^-40)) from a fixed generic vector:
    the eigenvector of a root known to ~1e-14 comes out to rounding, at the cost of two
    batched solves (a singular value decomposition costs ten times more)."""
    n = M.shape[-1]
    shifted = lz * (1 + 2.0**-40) + (lz == 0) * 2.0**-40
    Js = M[:, None] * shifted**2 + D[:, None] * shifted + K[:, None]
    Js = np.where(np.isfinite(Js), Js, 0.0)
    x = np.broadcast_to(start_vectors(1, n, 1)[0, 0], J.shape[:-1]).copy()
    for _ in range(steps):
        try:
            x = np.linalg.solve(Js, x[..., None])[..., 0]
        except np.linalg.LinAlgError:
            return np.full(J.shape[:-1], np.nan + 0j)
        x /= np.maximum(np.linalg.norm(x, axis=-1, keepdims=True), 1e-300)
    return x
