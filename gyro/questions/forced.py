"""`forced`: the steady response of every coordinate to one harmonic of the bearing
imperfections, f_s = a sin(k omega_c t + phi) (`--harmonic S:K:AMP[:PHASE]`, as `gyro
forced` takes it); one quantity per reduced coordinate (the model's order), its complex
amplitude X (x = Re(X e^{i k omega_c t}) about the equilibrium). The relative error of a
quantity is |X - X_ref| over the largest linear amplitude of its unit group (translations,
angles), the metric of the module's `linear_error` per coordinate: a coordinate whose
response is a millionth of its group's is not asked for six digits of its own.

Evaluator kinds, each with "module": the module whose `harmonic_balance(model, values,
harmonic, first_step_only=...)` -> (X, X_linear, info) the level uses (for the torsion
gyrocompass gyro.systems.torsion_gyrocompass):
- `harmonic`: the linear response J(i w) X = B u; its own estimate is twice the largest first
  Newton step of harmonic balance from it over the coordinate's unit group (measured: that
  step is the linear response's error to 3.6e-4 of itself up to the 1 % limits,
  docs/forced.md; over the spread of bench/forced_levels.py the bound is 1.97-2.04 times the
  error; a small coordinate's own step can fall short of its error);
- `harmonic_balance`: the periodic response of the full 11-coordinate equations by harmonic
  balance; its own estimate is `ESTIMATE_NONLINEAR` (measured: it agrees with the shooting
  to 4.4e-9 of the response on every rung of the bench's ladders).
A set whose evaluator fails (a resonance: the linear amplitude infinite; harmonic balance
not converging) fails with its reason, and the selector goes up. JSON keys: `frequency`
(k omega_c, rad/s), `coordinates`, `amplitudes` (peak, SI units), `phases` (rad, in the
form of the forcing: x = amplitude sin(w t + phase)).
"""
from __future__ import annotations

import numpy as np

from gyro.errors import ParameterError
from gyro.questions import Answer, evaluator_module, unknown_kind

NAME = "forced"
VALUES = "amplitudes"  # the JSON key of the per-quantity answer (the scene table shows it)
OPTIONS = {"harmonic": ("S:K:AMP[:PHASE]", "forced: one harmonic of the spin angle f_S = AMP sin(K omega_c t + "
                                           "PHASE), as gyro forced takes it (required)")}
SAFETY = 2.0  # the linear level's estimate: this many times harmonic balance's first step
ESTIMATE_NONLINEAR = 1e-8  # harmonic balance against the shooting: 4.4e-9 at most, measured
EPS = np.finfo(float).eps


def options(model, P, tol: float, given: dict, initial: dict) -> dict:
    """--harmonic S:K:AMP[:PHASE], required, S among the model's harmonic inputs."""
    from gyro.analyses.forced import parse_harmonic
    from gyro.analyses.spin import harmonic_inputs

    if given.get("harmonic") is None:
        raise ParameterError("--harmonic: the forced question needs one harmonic S:K:AMP[:PHASE]")
    return {"harmonic": parse_harmonic(given["harmonic"], len(harmonic_inputs(model)[1]))}


def quantities(model, opts) -> list[str]:
    return list(model.meta["reduced"])


def requested(model, opts) -> list[int]:
    return list(range(len(quantities(model, opts))))


def harmonic(opts):
    h = opts.get("harmonic")
    if h is None:
        raise ParameterError("--harmonic: the forced question needs one harmonic S:K:AMP[:PHASE]")
    return h


def answer(model, level, P, opts) -> Answer:
    kind = level.evaluator.get("kind")
    if kind not in ("harmonic", "harmonic_balance"):
        raise unknown_kind(NAME, level)
    forced = evaluator_module(level, model)  # its harmonic_balance (the torsion gyrocompass's own)
    s, k, a, phi = harmonic(opts)
    N, n = P.shape[0], len(quantities(model, opts))
    X = np.full((N, n), np.nan, complex)
    est = np.full((N, n), np.inf)
    scale = np.full((N, n), np.nan)
    failed = np.full(N, "", object)
    freq = np.full(N, np.nan)
    for j in range(N):
        values = dict(zip(model.param_names, map(float, P[j])))
        try:
            if kind == "harmonic":
                X1, Xl, info = forced.harmonic_balance(model, values, (s, k, a, phi), first_step_only=True)
                X[j] = Xl
                step = np.abs(X1 - Xl) / info["group"]
                # per coordinate the largest step of its unit group: a small coordinate's own
                # step can fall short of its error where the response is strongly nonlinear
                # (x3 at 9 % near a resonance), the group's does not (bench/forced_levels.py)
                est[j] = (SAFETY * np.array([step[info["group"] == g].max() for g in info["group"]])
                          + solve_rounding(model, P[j], info["frequency"], Xl, info["group"]))
            else:
                Xn, Xl, info = forced.harmonic_balance(model, values, (s, k, a, phi))
                X[j] = Xn
                est[j] = ESTIMATE_NONLINEAR
        except (ArithmeticError, ValueError, RuntimeError, np.linalg.LinAlgError) as exc:
            failed[j] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            continue
        scale[j] = info["group"]
        freq[j] = info["frequency"]
        if not (np.all(np.isfinite(Xl)) and np.all(np.isfinite(X[j]))):
            failed[j] = "a resonance: the linear response is unbounded"
    return Answer(np.abs(X), est, failed, {"X": X, "scale": scale, "frequency": freq})


def solve_rounding(model, p, w, X, group) -> np.ndarray:
    """Per coordinate, the rounding of the linear response X = J(i w)^-1 B u over its unit
    group's scale: the solve of the scaled J_s = S J S (gyro.analyses.harmonic.solve_batch)
    is backward stable, and its forming rounds each entry by eps of its size, so that
    |dY| <= 4 n eps kappa(J_s) |Y| for Y = S^-1 X, and |dX_i| <= s_i |dY|. Near a resonance
    kappa grows as the inverse of the relative distance to it (the floor of 1e-15 alone was
    beaten there: 7e-12 at 1e-5 from the radial resonance)."""
    from gyro.analyses.harmonic import dynamic_stiffness
    from gyro.equilibrium import equilibria, operators

    P = p[None, :]
    M, D, K = operators(model, P, equilibria(model, P)[0])
    n = M.shape[-1]
    diag = lambda A: np.abs(np.einsum("sii->si", A))  # noqa: E731
    with np.errstate(all="ignore"):
        sc = 1 / np.sqrt(diag(K) + w**2 * diag(M) + w * diag(D))[0]
        Js = dynamic_stiffness(M, D, K, np.array([w]))[0] * sc[:, None] * sc[None, :]
        if not np.all(np.isfinite(Js)):
            return np.full(n, np.inf)
        kappa = np.linalg.cond(Js)
        dY = 4 * n * EPS * kappa * np.linalg.norm(X / sc)
        out = sc * dY / group
    return np.where(np.isfinite(out), out, np.inf) + 1e-15


def edges(model, ans: Answer, bound: np.ndarray, idx, answered) -> np.ndarray:
    return np.full(ans.values.shape[0], "", object)


def error(ans: Answer, ref: Answer) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.abs(ans.extra["X"] - ref.extra["X"]) / ref.extra["scale"]


def document(model, ans: Answer, k: int, idx) -> dict:
    X = ans.extra["X"][k]
    return {"frequency": float(ans.extra["frequency"][k]), "coordinates": quantities(model, {}),
            "amplitudes": [float(v) for v in np.abs(X)],
            "phases": [float(v) for v in np.angle(1j * X)]}
