"""Forced vibration of the torsion gyrocompass from its bearing imperfections (003, section 2).

The imperfections (1.10)-(1.11): f_s(gamma3) = sum_i a_is sin(k_is gamma3 + phi_is),
s = 1, 2, 3, forces along x1, x2, x3 (and the moments h f1 on gamma1, -h f3 on gamma2), with
gamma3 = omega_c t along the spin. They are the inputs w = (F1, F2, F3) of the emitted B, so
each harmonic (s, k, a, phi) is the input u_s = -i a e^{i phi} at the frequency k omega_c
(a sin(theta + phi) = Re(-i a e^{i phi} e^{i theta})), solved by the harmonic response of any
model (gyro.analyses.harmonic) and kept apart; superposition is exact in the linear model.

A harmonic is a resonance where J(i k omega_c) is singular to working precision, or where,
on an undamped set (D skew: no bearing damping), k omega_c equals a natural frequency
within that frequency's own error estimate: amplitude inf, the mode named. The linear
answer's amplitude limit, measured against the full nonlinear equations, is
LINEAR_LIMIT (bench/results/forced_linear_limit.json; docs/forced.md).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gyro import ladder
from gyro.analyses.harmonic import harmonic_response
from gyro.equilibrium import operators
from gyro.models import Model, ParameterError
from gyro.results.harmonic import ForcedResponse, HarmonicResponse

MODELS = ("torsion_gyrocompass",)
INPUTS = ("F1", "F2", "F3")  # f_1, f_2, f_3 of (1.10)


def sets_spin(model: Model, name: str) -> bool:
    """Whether the parameter `name` sets the spin rate that spin_rate gives (H, here)."""
    return model.name in MODELS and name == "H"


def spin_rate(model: Model, P: np.ndarray, qe: np.ndarray | None = None) -> np.ndarray:
    """omega_c = gamma3' at the relative equilibrium, (2.3) at rest: H/C less the Earth rate
    on the spin axis, u cos(phi) + u sin(phi) (beta0 + gamma20) (within u/omega_c = 3e-8
    of H/C at the example; tests/test_paper_items.py)."""
    if model.name not in MODELS:
        raise ParameterError(f"{model.name}: no spin rate of the bearing imperfections (torsion gyrocompass only)")
    P = np.atleast_2d(P)
    col = {n: P[:, i] for i, n in enumerate(model.param_names)}
    W = col["H"] / col["C"]
    if qe is None:
        return W
    eq = model.meta["equilibrium_coordinates"]
    phi = np.radians(col["phi"])
    tilt = qe[:, eq.index("beta")] + qe[:, eq.index("gamma2")]
    return W - col["u"] * np.cos(phi) - col["u"] * np.sin(phi) * tilt


def parse_harmonic(text: str) -> tuple[int, int, float, float]:
    """S:K:AMP[:PHASE] -> (s, k, a, phi), each checked (ParameterError naming --harmonic)."""
    parts = text.split(":")
    if len(parts) not in (3, 4):
        raise ParameterError(f"--harmonic {text!r}: expected S:K:AMP[:PHASE]")
    try:
        s = int(parts[0])
    except ValueError:
        s = None
    if s not in (1, 2, 3):
        raise ParameterError(f"--harmonic {text!r}: S (the index of f_s) must be 1, 2 or 3, got {parts[0]!r}")
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


def _check_model(model: Model) -> None:
    if model.name not in MODELS or list(model.meta.get("inputs", [])) != list(INPUTS):
        raise ParameterError(f"{model.name}: the bearing imperfections f_1..f_3 are inputs of "
                             f"{', '.join(MODELS)} only; for any model use gyro unbalance or "
                             "gyro.analyses.harmonic")


def _undamped(D: np.ndarray) -> np.ndarray:
    return np.all(D == -np.swapaxes(D, -1, -2), axis=(-2, -1))


def forced_response(model: Model, P, harmonics, method: str = "default") -> ForcedResponse:
    """The steady response of each set of P (sets, n_params) to each harmonic (s, k, a, phi)."""
    _check_model(model)
    P = ladder.as_batch(model, P)
    if not harmonics:
        raise ParameterError("--harmonic: give at least one harmonic S:K:AMP[:PHASE]")
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
    for j, (s, k, a, phi) in enumerate(harmonics):
        u = np.zeros((P.shape[0], 3), complex)
        u[:, s - 1] = -1j * a * np.exp(1j * phi)
        r = harmonic_response(model, P, k * W, u, qe=qe)
        with np.errstate(invalid="ignore"):
            hit = np.any(np.abs(k * W[:, None] - wn) <= est * wn, axis=1) & undamped
        X[:, j], res[:, j] = r.X, r.resonance | hit
        X[res[:, j], j] = np.inf
    hs = np.array(harmonics, dtype=float).reshape(-1, 4)
    # the paper's names of q (2.4): lambda where the model file writes lam
    names = ["lambda" if c == "lam" else c for c in model.meta["reduced"]]
    return ForcedResponse(model=model.name, title=model.meta["title"], coordinates=names,
                          units=[model.meta["coordinate_units"][c] for c in model.meta["reduced"]],
                          param_names=list(model.param_names), params=P, spin_rate=W,
                          s=hs[:, 0].astype(int), k=hs[:, 1].astype(int), amplitude=hs[:, 2], phase=hs[:, 3],
                          X=X, resonance=res, natural=wn, natural_error=est, equilibrium=qe)


def response_curve(model: Model, values: dict, harmonic, H_lo: float, H_hi: float, points: int) -> HarmonicResponse:
    """Amplitude against spin for one harmonic (s, k, a, phi): H swept linearly from H_lo to
    H_hi, each set at its own equilibrium; the axis is the spin rate omega_c (rad/s)."""
    _check_model(model)
    from gyro.equilibrium import equilibria

    s, k, a, phi = harmonic
    P = np.tile(model.vector(values), (points, 1))
    P[:, model.param_names.index("H")] = np.linspace(H_lo, H_hi, points)
    qe, ok = equilibria(model, P)
    qe = np.where(ok[:, None], qe, np.nan)
    W = spin_rate(model, P, qe)
    u = np.zeros((points, 3), complex)
    u[:, s - 1] = -1j * a * np.exp(1j * phi)
    return harmonic_response(model, P, k * W, u, qe=qe, x=W, xname="omega_c", xunit="rad/s")


# ----------------------------------------------------------------------------- the linear limit
LIMIT_FILE = Path(__file__).resolve().parents[2] / "bench" / "results" / "forced_linear_limit.json"


def linear_limit() -> dict:
    """The measured amplitude limit of the linear response (the first measured boundary of
    the linear level): bench/forced_nonlinear.py's result, read from
    bench/results/forced_linear_limit.json (docs/forced.md)."""
    return json.loads(LIMIT_FILE.read_text())
