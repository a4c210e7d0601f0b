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
from gyro.analyses.spin import MODELS, spin_rate
from gyro.equilibrium import operators
from gyro.models import Model, ParameterError
from gyro.results.harmonic import ForcedResponse, HarmonicResponse
INPUTS = ("F1", "F2", "F3")  # f_1, f_2, f_3 of (1.10)


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
def cases(model: Model) -> dict:
    """The two harmonics of the measured linear limit: name -> (parameter values, (s, k, phi)).
    'away': f1, k = 1 at the example (omega_c = 2513 rad/s, 35 % below omega10 = 3851
    rad/s); 'near': f3, k = 1 with H = 0.99 omega_p C, omega_c 1 % below the radial bearing
    mode omega_p = 780 rad/s."""
    v = model.defaults
    wp = (v["Kp"] / v["m"]) ** 0.5
    return {"away": ({}, (1, 1, 0.0)), "near": ({"H": 0.99 * wp * v["C"]}, (3, 1, 0.0))}


LIMIT_FILE = Path(__file__).resolve().parents[2] / "bench" / "results" / "forced_linear_limit.json"

# The amplitude a (N) of one imperfection harmonic at which the linear response differs
# from the periodic response of the full nonlinear equations by 1 % (linear_error), the
# constant c (N^-2) of err = c a^2 below it and the measured order: the first measured
# boundary of the linear level, per case of `cases` ('away': 2.4e3 N, extrapolated from
# 400 N where err = 2.7e-4; 'near': 21.5 N, extrapolated from 16 N where err = 0.76 %).
# From the committed run of bench/forced_nonlinear.py (bench/results/forced_linear_limit.json;
# tests/test_forced.py holds the two equal); docs/forced.md gives the evidence.
LINEAR_LIMIT = {
    "away": {"c": 1.7076756036344526e-09, "order": 1.999773621600764, "a_1percent": 2422.720301222084},
    "near": {"c": 0.0001022772870722193, "order": 1.9912632144662672, "a_1percent": 21.52497736166718},
}


def linear_limit() -> dict:
    """The measured linear limit as the bench wrote it (the evidence behind LINEAR_LIMIT)."""
    return json.loads(LIMIT_FILE.read_text())


# ----------------------------------------------------------------------------- nonlinear check
def _rot(axis: str, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def _spin_free_rate(values: dict, g: dict, gd: dict) -> float:
    """r2 - gamma3' of (1.6): the rotor's absolute rate on its spin axis without the spin,
    from the Earth rate (1.3) and the casing rate p (1.5), frames (1.2), (1.6)."""
    phi = np.radians(values["phi"])
    u = values["u"] * np.array([0.0, np.cos(phi), np.sin(phi)])
    S = _rot("z", g["alpha"]) @ _rot("x", g["beta"]) @ _rot("y", g["gamma"])
    p = (S.T @ (u + gd["alpha"] * np.array([0, 0, 1.0]))
         + gd["beta"] * np.array([np.cos(g["gamma"]), 0, np.sin(g["gamma"])]) + gd["gamma"] * np.array([0, 1.0, 0]))
    R = _rot("z", g["gamma1"]) @ _rot("x", g["gamma2"])
    return float((R.T @ (p + gd["gamma1"] * np.array([0, 0, 1.0])) + gd["gamma2"] * np.array([1.0, 0, 0]))[1])


def nonlinear_response(model: Model, values: dict, harmonic, rtol: float = 1e-12, max_newton: int = 60,
                       periodic_tol: float | None = None, start: dict | None = None):
    """The steady (periodic) response of the full 11-coordinate equations (the emitted
    `mass_matrix` and `forcing`) to one harmonic f_s = a sin(k omega_c t + phi), the
    imperfection an explicit function of time (its derivative in gamma3, a torque on the
    spin that a drive absorbs, left out: the spin keeps its integral C r2 = H).

    gamma3 is cyclic, so the forced equations are periodic in t with T = 2 pi/(k omega_c):
    the periodic motion is found by shooting over one period (DOP853 at rtol), Newton's
    correction with the linear operator's monodromy (exact for the linear part) and
    Broyden's updates for the nonlinear rest.
    Returns (X_nonlinear, X_linear, info): the first Fourier coefficients of the reduced
    coordinates over the period (x = Re(X e^{i w t}) + harmonics and offset) and the linear
    response, info the Newton steps and the final periodicity residual (at most
    periodic_tol of the state's scale, default 10 rtol), and `continuation`: the periodic
    state, which `start` takes to begin a larger amplitude from this one's answer scaled to
    it (continuation in a)."""
    from scipy.integrate import solve_ivp
    from scipy.linalg import expm

    from gyro import ode
    from gyro.equilibrium import equilibrium

    _check_model(model)
    s, k, a, phi = harmonic
    P = model.vector(values)
    values = model.parameters(values)
    qe = equilibrium(model, P)
    W = float(spin_rate(model, P[None], qe[None])[0])
    w = k * W
    T = 2 * np.pi / w
    u = np.zeros(3, complex)
    u[s - 1] = -1j * a * np.exp(1j * phi)
    X_lin = harmonic_response(model, P, w, u, qe=qe[None]).X[0]
    coords, reduced = model.meta["coordinates"], model.meta["reduced"]
    ri = np.array([coords.index(c) for c in reduced])
    k3 = coords.index("gamma3")
    q_ref = np.zeros(len(coords))
    for name, v in zip(model.meta["equilibrium_coordinates"], qe):
        q_ref[coords.index(name)] = v
    zero3 = np.zeros(3)

    def given(t):
        F = np.zeros(3)
        F[s - 1] = a * np.sin(w * t + phi)
        return F, zero3

    rhs = ode.numpy_rhs(model, P, given)

    def full(z):
        q = q_ref.copy()
        q[ri] += z[:len(ri)]
        qd = np.zeros(len(coords))
        qd[ri] = z[len(ri):]
        g, gd = dict(zip(coords, q)), dict(zip(coords, qd))
        qd[k3] = values["H"] / values["C"] - _spin_free_rate(values, g, gd)
        return np.concatenate([q, qd])

    def period(z):
        sol = solve_ivp(rhs, (0.0, T), full(z), method="DOP853", rtol=rtol, atol=1e-30, dense_output=True)
        if not sol.success:
            raise RuntimeError(f"integration failed: {sol.message}")
        yT = sol.y[:, -1]
        zT = np.concatenate([yT[ri] - q_ref[ri], yT[11 + ri]])
        return zT, sol

    M, D, K = (x[0] for x in operators(model, P[None], qe[None]))
    n = len(ri)
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ D]])
    J = expm(A * T) - np.eye(2 * n)
    z = np.concatenate([X_lin.real, (1j * w * X_lin).real])
    if start is not None:  # continuation: the previous amplitude's periodic state, scaled
        z = start["z"] * (a / start["a"])
    scale = np.concatenate([np.abs(X_lin), w * np.abs(X_lin)]) + 1e-300
    # Newton on the periodicity R(z) = z(T) - z, its Jacobian started from the linear
    # operator's monodromy and corrected by Broyden's rank-one updates: the near-neutral
    # azimuth mode (1 - e^{i omega1 T} ~ 3e-5) makes the linear Jacobian's error in its
    # direction matter, which the updates learn. A step that the integrator cannot follow
    # is shortened. Periodic to 10 rtol of the state's scale.
    steps, resid = 0, np.inf
    zT, last = period(z)
    R = zT - z
    for steps in range(1, max_newton + 1):
        resid = float(np.max(np.abs(R)) / scale.max())
        if resid <= (10 * rtol if periodic_tol is None else periodic_tol):
            break
        dz = np.linalg.solve(J, -R)
        for _ in range(6):
            try:
                zT, sol_new = period(z + dz)
                break
            except RuntimeError:
                dz = dz / 4
        else:
            raise RuntimeError("no periodic response: the shooting's steps leave the integrator's reach")
        z = z + dz
        last = sol_new
        R_new = zT - z
        J += np.outer(R_new - R - J @ dz, dz) / (dz @ dz)
        R = R_new
    else:
        raise RuntimeError(f"no periodic response within {max_newton} Newton steps (residual {resid:.2g})")
    sol = last
    N = 64
    t = np.arange(N) * T / N
    x = sol.sol(t)[ri] - q_ref[ri, None]
    X_nl = 2 / N * (x * np.exp(-1j * w * t)[None, :]).sum(axis=1)
    return X_nl, X_lin, {"newton_steps": steps, "residual": resid, "frequency": w, "period": T,
                         "continuation": {"z": z, "J": J, "a": a}}


def linear_error(X_nl: np.ndarray, X_lin: np.ndarray, units: list) -> float:
    """The relative distance of the nonlinear from the linear amplitudes: per unit group
    (translations, angles), the largest |X_nl - X_lin| against the group's largest |X_lin|;
    the worse group."""
    err = 0.0
    for unit in set(units):
        idx = [i for i, u in enumerate(units) if u == unit]
        ref = np.max(np.abs(X_lin[idx]))
        if ref > 0:
            err = max(err, float(np.max(np.abs(X_nl[idx] - X_lin[idx])) / ref))
    return err
