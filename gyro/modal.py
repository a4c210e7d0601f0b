"""Equilibrium and natural frequencies of a generated model's exact linear operator.

The equilibrium solves the model's equilibrium equations by Newton's method from the
paper's approximation (2.2), with the operator's stiffness K as the Jacobian. The natural
frequencies are the eigenvalues of the quadratic problem (M lambda^2 + D lambda + K) x = 0.
Here are the general solver's parts: a balanced first-order (companion) eigensolver, and
Newton's iteration on J(lambda) with its singular vectors, so that the small precession
root keeps its relative accuracy beside the kilohertz bearing roots (the general rung of
gyro.ladder's default method). `natural_frequencies` answers for one set by the ladder.
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field

import numpy as np
import scipy.linalg as sla

from gyro.models import Model


class EquilibriumError(RuntimeError):
    pass


MAX_ANGLE_STEP = 0.2  # rad: Newton steps on angles are damped to stay on the branch of (2.2)


def _wrap(angle):
    """Angles into (-pi, pi]; angles already there are returned untouched (adding and
    subtracting pi would cost a small angle its relative precision)."""
    angle = np.asarray(angle, dtype=float)
    out = (angle + np.pi) % (2 * np.pi) - np.pi
    return np.where(np.abs(angle) <= np.pi, angle, out)


def equilibrium(model: Model, params: np.ndarray, tol: float = 1e-14, max_iter: int = 100) -> np.ndarray:
    """Relative equilibrium on the symmetric set (metadata 'equilibrium_coordinates').

    Newton's method from the paper's approximation (2.2) where the model has one (zero
    otherwise), with the stiffness K as the Jacobian. Steps on angles are damped to
    MAX_ANGLE_STEP so that the iteration stays on the branch it starts from, and angles are
    returned in (-pi, pi]."""
    nf = model.numpy
    reduced = model.meta["reduced"]
    names = model.meta["equilibrium_coordinates"]
    idx = [reduced.index(c) for c in names]
    units = model.meta.get("coordinate_units", {})
    is_angle = np.array([units.get(c) == "rad" for c in names])
    if hasattr(nf, "equilibrium_approx"):
        with np.errstate(divide="ignore", invalid="ignore"):
            qe = np.asarray(nf.equilibrium_approx(params), dtype=float)
        qe = np.where(np.isfinite(qe), qe, 0.0)  # (2.2) divides by g: at g = 0 start from zero
    else:
        qe = np.zeros(len(names))
    for _ in range(max_iter):
        r = np.asarray(nf.equilibrium_residual(params, qe))[idx]
        _, _, K = nf.operator(params, qe)
        Kee = np.asarray(K)[np.ix_(idx, idx)]
        # r(q + dq) = r(q) - K dq  (r = dR/dq, K = -d2R/dq2)
        dq = np.linalg.lstsq(Kee, r, rcond=None)[0]
        big = np.max(np.abs(dq[is_angle]), initial=0.0)
        if big > MAX_ANGLE_STEP:
            dq = dq * (MAX_ANGLE_STEP / big)
        qe = qe + dq
        if not np.all(np.isfinite(qe)):
            raise EquilibriumError("Newton's method diverged")
        if np.all(np.abs(dq) <= tol * np.maximum(np.abs(qe), 1e-300) + 1e-300):
            break
    else:
        r = np.asarray(nf.equilibrium_residual(params, qe))[idx]
        if np.max(np.abs(r)) > 1e-9 * (1 + np.max(np.abs(params))):
            raise EquilibriumError(f"Newton's method did not converge (residual {np.max(np.abs(r)):.3e})")
    return np.where(is_angle, _wrap(qe), qe)


def companion_matrix(M, D, K):
    """The first-order matrix [[0, I], [-M^-1 K, -M^-1 D]] of one operator or of a batch
    (leading axes)."""
    n = M.shape[-1]
    A = np.zeros(M.shape[:-2] + (2 * n, 2 * n))
    A[..., :n, n:] = np.eye(n)
    A[..., n:, :n] = -np.linalg.solve(M, K)
    A[..., n:, n:] = -np.linalg.solve(M, D)
    return A


def _companion_eigenvalues(M, D, K):
    # LAPACK balances A (D A D^-1), which evens out the rows of a spectrum spread over five
    # orders of magnitude, before its QR iteration
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


def representatives(lams: np.ndarray, n: int) -> np.ndarray:
    """One root of each pair of the 2n eigenvalues of a gyroscopic system.

    The spectrum is symmetric under lambda -> -lambda and lambda -> conj(lambda). A root
    that is essentially imaginary (|Im| > |Re|) is represented by its member with Im > 0 (a
    flutter quadruple gives two, growing and decaying); an essentially real pair +-sigma
    (divergent instability) by its member with Re >= 0, so that no growth rate is hidden."""
    imaginary = np.abs(lams.imag) > np.abs(lams.real)
    keep = np.where(imaginary, lams.imag > 0, lams.real >= 0)
    chosen = lams[keep]
    if len(chosen) != n:  # zeros or rounding broke the symmetry: take the n most "upper"
        key = np.where(imaginary, lams.imag, lams.real)
        chosen = lams[np.argsort(-key)[:n]]
    return chosen


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


def natural_frequencies(model: Model, values: dict, method: str = "default") -> ModalResult:
    """The natural frequencies of the exact operator about the exact equilibrium, for one
    parameter set, by a method of the ladder (gyro.ladder; the default one unless told)."""
    from gyro import ladder

    spec = ladder.spectrum(model, model.vector(values), method)
    if not np.all(np.isfinite(spec.frequencies)):
        raise EquilibriumError(f"{model.name}: no finite spectrum at this set (method {method!r})")
    eq = spec.equilibrium[0] if spec.equilibrium is not None else equilibrium(model, model.vector(values))
    return ModalResult(
        model=model.name, params=values,
        equilibrium=dict(zip(model.meta["equilibrium_coordinates"], map(float, eq))),
        frequencies=[float(f) for f in spec.frequencies[0]],
        eigenvalues_re=[float(r) for r in spec.growth[0]],
        error_estimate=[float(e) for e in spec.error_estimate[0]])
