"""The steady response of any model to harmonics of its spin angle (`gyro forced`).

A model that declares its spin angle (Model.spin "angle", a cyclic or steady coordinate)
has harmonic inputs: the given functions of that angle, f_s(angle), s = 1..n in the order
of its inputs (paper 003's bearing imperfections (1.10)-(1.11), forces along x1, x2, x3 and
the moments h f1 on gamma1, -h f3 on gamma2, with gamma3 = omega_c t). Each
harmonic f_s = a sin(k angle + phi), the angle turning at its rate at the reference
omega_c (gyro.analyses.spin.spin_rate), is the input u_s = -i a e^{i phi} at the frequency
k omega_c (a sin(theta + phi) = Re(-i a e^{i phi} e^{i theta})), solved by the harmonic
response of any model (gyro.analyses.harmonic) and kept apart; superposition is exact in
the linear model.

A harmonic is a resonance where J(i k omega_c) is singular to working precision, or where,
on an undamped set (D skew), k omega_c equals a natural frequency within that frequency's
own error estimate: amplitude inf, the mode named. What the linear answer neglects is the
model's own: a system's periodic response of its full equations and its measured linear
limit live in its own module, which its forced levels' evaluators name (docs/forced.md).
"""
from __future__ import annotations

import numpy as np

from gyro import ladder
from gyro.analyses.harmonic import harmonic_response, input_names
from gyro.analyses.spin import harmonic_inputs, spin_rate
from gyro.equilibrium import operators
from gyro.models import Model, ParameterError
from gyro.results.harmonic import ForcedResponse, HarmonicResponse

# names the emitted code cannot carry, printed as the papers write them (derive/names.py
# refuses Python's keywords, so the model files write lambda as lam)
PRINTED = {"lam": "lambda"}


def _choices(n: int) -> str:
    return "1" if n == 1 else ", ".join(map(str, range(1, n))) + f" or {n}"


def parse_harmonic(text: str, inputs: int = 3) -> tuple[int, int, float, float]:
    """S:K:AMP[:PHASE] -> (s, k, a, phi), each checked (ParameterError naming --harmonic);
    S indexes the model's `inputs` harmonic inputs from 1."""
    parts = text.split(":")
    if len(parts) not in (3, 4):
        raise ParameterError(f"--harmonic {text!r}: expected S:K:AMP[:PHASE]")
    try:
        s = int(parts[0])
    except ValueError:
        s = None
    if s is None or not 1 <= s <= inputs:
        raise ParameterError(f"--harmonic {text!r}: S (the index of f_s) must be {_choices(inputs)}, got {parts[0]!r}")
    try:
        k = int(parts[1])
    except ValueError:
        k = 0
    if k < 1:
        raise ParameterError(f"--harmonic {text!r}: K (the order k) must be a positive integer, got {parts[1]!r}")
    vals = []
    for label, raw in zip(("AMP", "PHASE"), parts[2:]):
        try:
            v = float(raw)
        except ValueError:
            v = float("nan")
        if not np.isfinite(v):
            raise ParameterError(f"--harmonic {text!r}: {label} must be a finite number, got {raw!r}")
        vals.append(v)
    return s, k, vals[0], (vals[1] if len(vals) > 1 else 0.0)


def harmonic_columns(model: Model) -> list[int]:
    """The columns of the input matrix B that the harmonic inputs f_1..f_n are."""
    _, names = harmonic_inputs(model)
    inputs = input_names(model)
    return [inputs.index(n) for n in names]


def _undamped(D: np.ndarray) -> np.ndarray:
    return np.all(D == -np.swapaxes(D, -1, -2), axis=(-2, -1))


def harmonic_input(model: Model, N: int, s: int, a: float, phi: float) -> np.ndarray:
    """u (N, inputs): f_s = a sin(k angle + phi) as the complex input -i a e^{i phi}."""
    u = np.zeros((N, len(input_names(model))), complex)
    u[:, harmonic_columns(model)[s - 1]] = -1j * a * np.exp(1j * phi)
    return u


def forced_response(model: Model, P, harmonics, method: str = "default") -> ForcedResponse:
    """The steady response of each set of P (sets, n_params) to each harmonic (s, k, a, phi)."""
    _, names = harmonic_inputs(model)
    P = ladder.as_batch(model, P)
    if not harmonics:
        raise ParameterError("--harmonic: give at least one harmonic S:K:AMP[:PHASE]")
    for s, *_ in harmonics:
        if not 1 <= s <= len(names):
            raise ParameterError(f"--harmonic: S = {s}: {model.name} has {len(names)} harmonic inputs")
    spec = ladder.spectrum(model, P, method)
    qe = spec.equilibrium
    W = spin_rate(model, P, qe)
    _, D, _ = operators(model, P, np.where(np.isfinite(qe), qe, 0.0))
    undamped = _undamped(D)
    H = len(harmonics)
    n = len(model.meta["reduced"])
    X = np.full((P.shape[0], H, n), np.nan + 0j)
    res = np.zeros((P.shape[0], H), bool)
    wn, est = spec.frequencies, spec.error_estimate
    # a set without a finite spin rate (no equilibrium, or H and C too far apart for a
    # double) has no forcing frequency: no response there, never an error about an input
    # (omega) the user did not give
    spinning = np.isfinite(W) & (W >= 0)
    for j, (s, k, a, phi) in enumerate(harmonics):
        r = harmonic_response(model, P, np.where(spinning, k * W, 0.0), harmonic_input(model, P.shape[0], s, a, phi),
                              qe=np.where(spinning[:, None], qe, np.nan))
        with np.errstate(invalid="ignore"):
            hit = np.any(np.abs(k * W[:, None] - wn) <= est * wn, axis=1) & undamped
        X[:, j], res[:, j] = r.X, r.resonance | hit
        X[res[:, j], j] = np.inf
    hs = np.array(harmonics, dtype=float).reshape(-1, 4)
    return ForcedResponse(model=model.name, title=model.meta["title"],
                          coordinates=[PRINTED.get(c, c) for c in model.meta["reduced"]],
                          units=[model.meta["coordinate_units"][c] for c in model.meta["reduced"]],
                          param_names=list(model.param_names), params=P, spin_rate=W,
                          s=hs[:, 0].astype(int), k=hs[:, 1].astype(int), amplitude=hs[:, 2], phase=hs[:, 3],
                          X=X, resonance=res, natural=wn, natural_error=est, equilibrium=qe,
                          label=model.meta["spin"]["harmonic_label"], input_unit=model.meta["spin"]["harmonic_unit"])


def response_curve(model: Model, values: dict, harmonic, lo: float, hi: float, points: int) -> HarmonicResponse:
    """Amplitude against spin for one harmonic (s, k, a, phi): the declared spin parameter
    (paper 003's H) swept linearly from lo to hi, each set at its own
    equilibrium; the axis is the spin angle's rate omega_c (rad/s)."""
    from gyro.equilibrium import equilibria

    harmonic_inputs(model)
    s, k, a, phi = harmonic
    P = np.tile(model.vector(values), (points, 1))
    P[:, model.param_names.index(model.meta["spin"]["parameter"])] = np.linspace(lo, hi, points)
    qe, ok = equilibria(model, P)
    qe = np.where(ok[:, None], qe, np.nan)
    W = spin_rate(model, P, qe)
    return harmonic_response(model, P, k * W, harmonic_input(model, points, s, a, phi), qe=qe, x=W, xname="omega_c",
                             xunit="rad/s")
