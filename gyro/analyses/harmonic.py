"""The steady harmonic response of any emitted model with inputs: J(i omega) X = B u.

For M q'' + D q' + K q = B w with w(t) = Re(u e^{i omega t}) the steady motion about the
equilibrium is q(t) = Re(X e^{i omega t}) with (K - omega^2 M + i omega D) X = B u. M, D,
K come from the generated `operator` (the model's C over the whole batch, its NumPy twin
without a compiler), B from `input_matrix`, both at each set's equilibrium; LAPACK solves
the batch, J scaled to weigh every coordinate alike. Superposition is exact in the linear model, so each harmonic is
solved on its own (docs/forced.md).

A frequency at which J(i omega) is singular to working precision (an undamped model driven
at a natural frequency) is a resonance: the amplitudes are inf and the set is flagged,
never a huge finite number. The test is the smallest singular value of the scaled J(i omega)
against its largest, below RESONANCE_RTOL; it is computed only where the solve's own
amplification ||J|| ||X|| / ||B u|| (a lower bound of the condition number) says the
operator may be that close to singular.
"""
from __future__ import annotations

import numpy as np

from gyro.analyses.spin import spin_parameter, spin_rates
from gyro.equilibrium import EquilibriumError, equilibria, tame
from gyro.kernels import chunks, function
from gyro.models import Model, ParameterError
from gyro.results.harmonic import HarmonicResponse

# J(i omega) singular to working precision: sigma_min <= 1024 eps sigma_max. At a relative
# distance delta from an undamped natural frequency sigma_min/sigma_max is of order delta
# (times the mode's share of the operator's norm), so this flags frequencies within about
# 1e-13 of a natural frequency, where a solve would keep at most three digits (its relative
# error is cond * eps >= 1/1024 * ...); farther away the finite amplitude is computed.
RESONANCE_RTOL = 1024 * np.finfo(float).eps
# the solve's amplification beyond which the singular values are computed (1e-6 of the
# resonance's condition number: every set that could be a resonance is checked)
SUSPECT = 1e-6 / RESONANCE_RTOL
CHUNK = 4096  # sets per call (J takes 1.6 kB a set, complex)


def _state_args(model: Model, fname: str, P: np.ndarray, qe: np.ndarray) -> list:
    """The inputs of a generated function of the state (params, qe) in its call order;
    refused for an operator that depends on anything else (momenta, time, signals)."""
    args = []
    for group in model.meta["functions"][fname]["inputs"]:
        name = group["name"]
        if name == "params":
            args.append(P)
        elif name == "qe":
            args.append(qe)
        elif name == "pval":
            continue
        else:
            raise ParameterError(f"{model.name}: its operator depends on {name!r}; the harmonic "
                                 "response covers models with a constant operator about an equilibrium")
    return args


def input_names(model: Model) -> list[str]:
    """The model's inputs w (the columns of B), in order; [] for a model without inputs."""
    return list(model.meta.get("inputs", []))


def require_inputs(model: Model) -> None:
    if "input_matrix" not in model.meta["functions"]:
        raise ParameterError(f"{model.name}: the model has no inputs (no input matrix B); "
                             "declare input signals or given functions (docs/models.md)")


def input_matrix(model: Model, P: np.ndarray, qe: np.ndarray) -> np.ndarray:
    """B (sets, n_q, n_inputs) at the given equilibria."""
    require_inputs(model)
    with np.errstate(all="ignore"):
        (B,) = function(model, "input_matrix")(*_state_args(model, "input_matrix", P, qe))
    return np.asarray(B, dtype=float).reshape(P.shape[0], -1, len(input_names(model)))


def operator_at(model: Model, P: np.ndarray, qe: np.ndarray):
    """M, D, K (sets, n, n) of the generated operator (the model's C over the batch)."""
    with np.errstate(all="ignore"):
        return function(model, "operator")(*_state_args(model, "operator", P, qe))


def dynamic_stiffness(M, D, K, omega) -> np.ndarray:
    """J(i omega) = K - omega^2 M + i omega D (sets, n, n), complex."""
    w = np.asarray(omega, dtype=float)[:, None, None]
    return (K - w**2 * M) + 1j * (w * D)


def solve_batch(M, D, K, omega, b):
    """X = J(i omega)^-1 b per set, with the resonance flag (J singular to working
    precision). M, D, K (sets, n, n), omega (sets,), b (sets, n) complex. Returns
    (X, resonance): X inf where resonance, NaN where the operator or b is not finite.

    J is scaled symmetrically by s_i = (|K_ii| + omega^2 |M_ii| + omega |D_ii|)^-1/2, the
    size of the terms its diagonal combines, so that translations and angles, stiff and
    soft coordinates weigh alike: the singular values of the scaled J then measure the
    relative distance to a singular operator in the precision its entries carry."""
    N, n = b.shape
    X = np.full((N, n), np.nan + 0j)
    resonance = np.zeros(N, bool)
    fine = (tame(M) & tame(D) & tame(K) & np.all(np.isfinite(b), axis=1)
            & np.all(np.isfinite(M) & np.isfinite(D) & np.isfinite(K), axis=(1, 2)))
    idx = np.flatnonzero(fine)
    if idx.size == 0:
        return X, resonance
    w = np.asarray(omega, dtype=float)[idx]
    Mf, Df, Kf = M[idx], D[idx], K[idx]
    diag = lambda A: np.abs(np.einsum("sii->si", A))  # noqa: E731
    size = diag(Kf) + w[:, None]**2 * diag(Mf) + w[:, None] * diag(Df)
    sc = 1 / np.sqrt(np.where(size > 0, size, 1.0))
    Js = dynamic_stiffness(Mf, Df, Kf, w) * sc[:, :, None] * sc[:, None, :]
    bs = b[idx] * sc
    with np.errstate(all="ignore"):
        try:
            Y = np.linalg.solve(Js, bs[..., None])[..., 0]
        except np.linalg.LinAlgError:  # an exactly singular J somewhere: set by set
            Y = np.empty_like(bs)
            for i in range(len(idx)):
                try:
                    Y[i] = np.linalg.solve(Js[i], bs[i])
                except np.linalg.LinAlgError:
                    Y[i] = np.inf
        amp = (np.linalg.norm(Js, axis=(1, 2)) * np.linalg.norm(Y, axis=1)
               / np.maximum(np.linalg.norm(bs, axis=1), 1e-300))
    suspect = np.flatnonzero(~np.isfinite(amp) | (amp > SUSPECT))
    if suspect.size:
        sv = np.linalg.svd(Js[suspect], compute_uv=False)
        res = suspect[sv[:, -1] <= RESONANCE_RTOL * sv[:, 0]]
        resonance[idx[res]] = True
    with np.errstate(all="ignore"):
        X[idx] = Y * sc
    X[resonance] = np.inf
    return X, resonance


def harmonic_response(model: Model, P, omega, u, qe=None, x=None, xname: str = "",
                      xunit: str = "") -> HarmonicResponse:
    """Steady complex amplitudes X (sets, n_q) of the model's reduced coordinates, x(t) =
    Re(X e^{i omega t}), for the inputs w(t) = Re(u e^{i omega t}).

    P (sets, n_params); omega (sets,) or a scalar, rad/s, >= 0; u (sets, n_inputs) or
    (n_inputs,), complex input amplitudes in the inputs' units; qe the equilibria when
    known (computed otherwise). `x`, `xname`, `xunit` label a swept axis for the plot."""
    require_inputs(model)
    P = np.atleast_2d(np.asarray(P, dtype=float))
    if P.ndim != 2 or P.shape[1] != len(model.param_names):
        raise ParameterError(f"params: expected shape (sets, {len(model.param_names)}), got {P.shape}")
    N = P.shape[0]
    names = input_names(model)
    omega = np.broadcast_to(np.asarray(omega, dtype=float), (N,)).copy()
    if not np.all(np.isfinite(omega)) or np.any(omega < 0):
        raise ParameterError("omega: the forcing frequency must be finite and >= 0 (rad/s)")
    u = np.asarray(u, dtype=complex)
    if u.shape[-1] != len(names):
        raise ParameterError(f"u: {model.name} has {len(names)} inputs ({', '.join(names)}), got {u.shape[-1]}")
    u = np.broadcast_to(u, (N, len(names))).copy()
    if not np.all(np.isfinite(u)):
        raise ParameterError("u: the input amplitudes must be finite")
    if qe is None:
        qe, ok = equilibria(model, P)
    else:
        qe = np.atleast_2d(np.asarray(qe, dtype=float))
        ok = np.all(np.isfinite(qe), axis=1)
    n = len(model.meta["reduced"])
    X = np.full((N, n), np.nan + 0j)
    resonance = np.zeros(N, bool)
    for sl in chunks(N, CHUNK):
        M, D, K = operator_at(model, P[sl], qe[sl])
        B = input_matrix(model, P[sl], qe[sl])
        b = np.einsum("sij,sj->si", B, u[sl])
        X[sl], resonance[sl] = solve_batch(M, D, K, omega[sl], b)
    X[~ok] = np.nan
    resonance &= ok
    return HarmonicResponse(model=model.name, title=model.meta["title"],
                            coordinates=list(model.meta["reduced"]),
                            units=[model.meta.get("coordinate_units", {}).get(c, "") for c in model.meta["reduced"]],
                            inputs=names, param_names=list(model.param_names), params=P, omega=omega,
                            u=u, X=X, resonance=resonance, equilibrium=qe,
                            x=omega.copy() if x is None else np.asarray(x, dtype=float),
                            xname=xname or "omega", xunit=xunit or "rad/s")


def unbalance_response(model: Model, values: dict, force_x: str, force_y: str, magnitude: float,
                       phase: float, spin: str, lo: float, hi: float, points: int,
                       progress: bool = False) -> HarmonicResponse:
    """The response to an unbalance over a spin range: the force ME W^2 (cos(W t + PHI),
    sin(W t + PHI)) on the inputs force_x, force_y, W the spin rate set by the parameter
    `spin` swept linearly from lo to hi (its own unit). Each spin value is its own
    parameter set, at its own equilibrium."""
    names = input_names(model) if "input_matrix" in model.meta["functions"] else []
    require_inputs(model)
    for flag, name in (("--force-x", force_x), ("--force-y", force_y)):
        if name not in names:
            raise ParameterError(f"{flag} {name!r}: {model.name} has no such input; inputs: {', '.join(names)}")
    if force_x == force_y:
        raise ParameterError(f"--force-y {force_y!r}: the same input as --force-x")
    if not np.isfinite(magnitude) or magnitude < 0:
        raise ParameterError(f"--magnitude: need a finite m e >= 0, got {magnitude!r}")
    if not np.isfinite(phase):
        raise ParameterError(f"--phase: need a finite angle in radians, got {phase!r}")
    values = dict(values)
    spin = spin_parameter(model, spin)  # declared, or in rad/s: refused otherwise
    xs = np.linspace(lo, hi, points)
    P = np.tile(model.vector(values), (points, 1))
    P[:, model.param_names.index(spin)] = xs
    parts = []
    for sl in chunks(points, CHUNK, progress, "unbalance"):
        qe, ok = equilibria(model, P[sl])
        W = spin_rates(model, spin, P[sl])
        u = np.zeros((len(W), len(names)), complex)
        rot = magnitude * W**2 * np.exp(1j * phase)
        # a spin value whose rate or force is beyond a double (ME W^2 at W = 1e300) has no
        # response, as one without an equilibrium: never an error about an internal input
        fine = np.isfinite(W) & (W >= 0) & np.isfinite(rot)
        u[:, names.index(force_x)] = np.where(fine, rot, 0)
        u[:, names.index(force_y)] = np.where(fine, -1j * rot, 0)  # sin(W t + PHI) = Re(-i e^{i(W t + PHI)})
        qe = np.where((ok & fine)[:, None], qe, np.nan)
        part = harmonic_response(model, P[sl], np.where(fine, W, 0.0), u, qe=qe)
        part.omega = np.where(fine, W, np.nan)  # no rate shown where there is none
        parts.append(part)
    unit = next(p.unit for p in model.params if p.name == spin)
    out = HarmonicResponse.concat(parts)
    out.x, out.xname, out.xunit = xs, spin, unit
    out.heading = (f"unbalance m e = {magnitude:g} kg m on {force_x}, {force_y}; peak amplitudes |X|, "
                   "x(t) = Re(X e^(i W t))")
    return out


__all__ = ["harmonic_response", "unbalance_response", "solve_batch", "dynamic_stiffness", "operator_at", "input_matrix",
           "input_names", "require_inputs", "spin_rates", "RESONANCE_RTOL", "EquilibriumError"]
