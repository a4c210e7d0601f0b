"""Equilibrium and natural frequencies of a generated model's exact linear operator.

The equilibrium solves the model's equilibrium equations by Newton's method from the
paper's approximation (2.2), with the operator's stiffness K as the Jacobian. The natural
frequencies are the eigenvalues of the quadratic problem (M lambda^2 + D lambda + K) x = 0:
found by a balanced first-order (companion) eigensolver, then each refined by Newton's
iteration on J(lambda) with its singular vectors, so that the small precession root keeps
its relative accuracy beside the kilohertz bearing roots.
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field

import numpy as np
import scipy.linalg as sla

from gyro.models import Model


class EquilibriumError(RuntimeError):
    pass


def equilibrium(model: Model, params: np.ndarray, tol: float = 1e-14, max_iter: int = 50) -> np.ndarray:
    """Relative equilibrium on the symmetric set (metadata 'equilibrium_coordinates')."""
    nf = model.numpy
    reduced = model.meta["reduced"]
    idx = [reduced.index(c) for c in model.meta["equilibrium_coordinates"]]
    with np.errstate(divide="ignore", invalid="ignore"):
        qe = np.asarray(nf.equilibrium_approx(params), dtype=float)
    qe = np.where(np.isfinite(qe), qe, 0.0)  # (2.2) divides by g: at g = 0 start from zero
    for _ in range(max_iter):
        r = np.asarray(nf.equilibrium_residual(params, qe))[idx]
        _, _, K = nf.operator(params, qe)
        Kee = np.asarray(K)[np.ix_(idx, idx)]
        # r(q + dq) = r(q) - K dq  (r = dR/dq, K = -d2R/dq2)
        dq = np.linalg.lstsq(Kee, r, rcond=None)[0]
        qe = qe + dq
        scale = np.maximum(np.abs(qe), 1e-300)
        if np.all(np.abs(dq) <= tol * scale + 1e-300):
            return qe
    r = np.asarray(nf.equilibrium_residual(params, qe))[idx]
    if np.max(np.abs(r)) > 1e-9 * (1 + np.max(np.abs(params))):
        raise EquilibriumError(f"Newton's method did not converge (residual {np.max(np.abs(r)):.3e})")
    return qe


def _companion_eigenvalues(M, D, K):
    n = M.shape[0]
    Minv_K = np.linalg.solve(M, K)
    Minv_D = np.linalg.solve(M, D)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv_K, -Minv_D]])
    # balancing evens out the rows of a spectrum spread over five orders of magnitude
    return sla.eigvals(A, check_finite=True, overwrite_a=True, homogeneous_eigvals=False)


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


@dataclass
class ModalResult:
    """Natural frequencies of a model at one parameter set, with the equilibrium used."""

    model: str
    params: dict
    equilibrium: dict
    frequencies: list  # rad/s, ascending
    eigenvalues_re: list = field(default_factory=list)  # real parts, same order (growth if > 0)
    error_estimate: list = field(default_factory=list)  # last Newton step, relative

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=1)

    def save(self, path) -> None:
        with open(path, "w") as fh:
            fh.write(self.to_json())

    @classmethod
    def load(cls, path) -> "ModalResult":
        with open(path) as fh:
            return cls(**json.load(fh))


def natural_frequencies(model: Model, values: dict) -> ModalResult:
    """The natural frequencies of the exact operator about the exact equilibrium."""
    params = model.vector(values)
    qe = equilibrium(model, params)
    M, D, K = (np.asarray(X, dtype=float) for X in model.numpy.operator(params, qe))
    lams = _companion_eigenvalues(M, D, K)
    n = M.shape[0]
    # one of each conjugate pair: the root with non-negative imaginary part; a real pair
    # (divergent instability) gives two real roots of which both are kept
    order = np.argsort(-lams.imag)
    upper = lams[order[:n]]
    refined = [refine(M, D, K, complex(lam)) for lam in upper]
    roots = np.array([r for r, _ in refined])
    errs = np.array([e for _, e in refined])
    freqs = np.abs(roots.imag)
    idx = np.argsort(freqs)
    return ModalResult(
        model=model.name, params=values,
        equilibrium=dict(zip(model.meta["equilibrium_coordinates"], map(float, qe))),
        frequencies=[float(f) for f in freqs[idx]],
        eigenvalues_re=[float(r) for r in roots.real[idx]],
        error_estimate=[float(e) for e in errs[idx]])
