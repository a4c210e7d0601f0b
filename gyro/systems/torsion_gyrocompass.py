"""The torsion gyrocompass (003): what only it has. Its free motion about the relative
equilibrium (sections 1-2), the `motion` question's levels `linear_motion` and
`nonlinear_motion` (docs/hierarchy.md); and the periodic response of its full equations to
the bearing imperfections (section 2), the `forced` question's levels `linear` (harmonic
balance's first step its estimate) and `nonlinear` (harmonic balance), with the measured
linear limit (docs/forced.md). The linear steady response of any model with a spin angle is
gyro.analyses.forced.

A motion starts from the exact equilibrium q0 (gyro.equilibrium) displaced by x(0) and
moving at x'(0) in the reduced coordinates (2.4) (INITIAL: `<coordinate>_0`, `<coordinate>_d0`),
the spin's momentum C r2 = H (2.3) (gamma3's rate from the integral, as the forced
response's states, ReducedState, below). Answered: the ten reduced coordinates
q0 + x(t) (metres, radians), without the cyclic spin angle gamma3.

- `linear`: the motion of the linearised equations M x'' + D x' + K x = 0 with the exact
  operator about the exact equilibrium (the generated `operator`, the one `linear_exact`
  solves for the frequencies), exactly: the first-order matrix A = [[0, I], [-M^-1 K, -M^-1 D]]
  propagated by its exponential over a uniform fine grid (scipy.signal.lsim; FINE samples per
  shortest period of the quadratic terms). Its error estimate is the correction of the full
  equations about it: with z' = f(z) the reduced equations (the emitted mass matrix and
  forcing, gyro.ode, at the integral's spin rate) and r(z) = f(z) - A z their remainder (the
  terms of second and higher order, and the equilibrium's residual f(0)), the error
  e = z - z_L solves e' = A e + r(z_L + e), e(0) = 0: the linear system driven by the
  remainder (Duhamel's integral, by the same lsim with r linear between the samples),
  solved by CORRECTIONS = 2 steps of Picard's iteration from e = 0. The first step alone,
  the linear response to r(z_L), falls short by half on the odd coordinates (gamma, mu:
  their remainder is of third order, the order of the quadratic terms acting on the first
  step's even coordinates); the second holds every term of third order (measured: equal to
  the error to 4 digits at a casing tilt gamma of 0.01 rad). The estimate per coordinate is
  FACTOR times the largest |e| over its unit group (m or rad) and the horizon, plus the
  propagation's rounding (ROUNDING eps per step of the largest |z_L|); infinite where it
  exceeds CAP of the motion's largest excursion (no longer a bound there).
- any SciPy method (`DOP853`): the full 11-coordinate equations integrated from the same
  state (gyro.ode.numpy_rhs, the imperfections f_s = 0), gamma3 a coordinate beside the
  others; its estimate twice the difference of the runs at rtol and rtol/100
  (gyro.ode.two_tolerances, as the gimbal gyroscope's integrated level).
"""
from __future__ import annotations

import json
from functools import cached_property
from pathlib import Path

import numpy as np

from gyro.analyses import motion as generic
from gyro.analyses.forced import harmonic_input as forced_input
from gyro.analyses.harmonic import harmonic_response
from gyro.analyses.spin import spin_rate
from gyro.models import Model, ParameterError, load

MODEL = "torsion_gyrocompass"
# the reduced coordinates (2.4), metadata 'reduced' (tests/methods/test_torsion_motion.py holds them equal)
REDUCED = ("x1", "x3", "gamma", "mu", "x2", "gamma1", "gamma2", "alpha", "beta", "lam")
_WHAT = {"x1": "the rotor's shift along x1 in its bearings", "x2": "the rotor's shift along x2 (the spin axis)",
         "x3": "the rotor's shift along x3", "gamma1": "the rotor's tilt gamma1 in its bearings",
         "gamma2": "the rotor's tilt gamma2 in its bearings", "alpha": "the casing's azimuth alpha",
         "beta": "the casing's tilt beta", "gamma": "the casing's tilt gamma",
         "lam": "the torsion bar's direction lambda", "mu": "the torsion bar's direction mu"}
_UNIT = {c: ("m" if c.startswith("x") else "rad") for c in REDUCED}
DEFAULT = {"gamma1_0": 1e-3}  # the rotor tilted by 1 mrad in its bearings and let go
INITIAL = {}  # name -> (unit, default, description): the initial perturbation at t = 0
for _c in REDUCED:
    INITIAL[f"{_c}_0"] = (_UNIT[_c], DEFAULT.get(f"{_c}_0", 0.0),
                          f"{_WHAT[_c]} at t = 0, off its equilibrium value")
    INITIAL[f"{_c}_d0"] = (_UNIT[_c] + "/s", 0.0, f"the rate of {_WHAT[_c]} at t = 0")

# the linear level's constants, measured on this model (bench/results/levels.json
# 'toward_the_cap', docs/hierarchy.md) and shared by the generic machinery, which keeps them
# (gyro.analyses.motion: FACTOR, CAP, ROUNDING, CORRECTIONS, FINE, FINER, FLOOR)
CAP, FINE, CORRECTIONS, FLOOR = generic.CAP, generic.FINE, generic.CORRECTIONS, generic.FLOOR
integration_floor = generic.integration_floor  # the motion question's floor of the DOP853 level


class Motion:
    """A free motion of the torsion gyrocompass: the parameters and the initial perturbation
    (INITIAL's names; those not given at their defaults)."""

    def __init__(self, params: dict, **initial):
        unknown = sorted(set(initial) - set(INITIAL))
        if unknown:
            raise ParameterError(f"{MODEL} motion: unknown initial condition {unknown[0]!r}; "
                                 f"it takes {', '.join(INITIAL)}")
        vals = {k: float(initial.get(k, v[1])) for k, v in INITIAL.items()}
        bad = [k for k, v in vals.items() if not np.isfinite(v)]
        if bad:
            raise ParameterError(f"--set {bad[0]}: the initial condition must be a finite number")
        self.params = dict(params)
        self.x0 = np.array([vals[f"{c}_0"] for c in REDUCED])
        self.xd0 = np.array([vals[f"{c}_d0"] for c in REDUCED])

    @cached_property
    def reduced(self):
        """The set's equilibrium and full state (ReducedState, below)."""
        model = load(MODEL)
        if tuple(model.meta["reduced"]) != REDUCED:
            raise RuntimeError(f"{MODEL}: the reduced coordinates changed; REDUCED must follow them")
        return ReducedState(model, self.params)

    @property
    def first_order(self) -> np.ndarray:
        """A (2n, 2n) of z' = A z, z = (x, x'), from the generated operator at the equilibrium."""
        return self.reduced.first_order

    @property
    def z0(self) -> np.ndarray:
        return np.concatenate([self.x0, self.xd0])


def linear_motion(motion: Motion, t):
    """The linear motion and its correction at the sample times t (uniform from 0): (z_L, e,
    steps), each (times, 2n), e after CORRECTIONS steps of Picard's iteration
    (gyro.analyses.motion.linear_motion)."""
    return generic.linear_motion(motion.reduced, motion.z0, t, CORRECTIONS, FINE)


def integrate(motion: Motion, t, method: str = "DOP853", rtol: float = 1e-9, scale: np.ndarray | None = None):
    """The full 11-coordinate equations integrated from the motion's state: the reduced
    coordinates q0 + x at the times t (times, n); the absolute tolerances from `scale`, not
    below FLOOR eps of the equilibrium (gyro.analyses.motion.integrate_reduced)."""
    if scale is None:
        zL = linear_motion(motion, t)[0]
        n = motion.reduced.n
        scale = np.array([np.max(np.abs(zL[:, :n])), np.max(np.abs(zL[:, n:]))])
    return generic.integrate_reduced(motion.reduced, motion.z0, t, method, rtol, scale, FLOOR)


def linear_answer(motion: Motion, t, cap: float = CAP):
    """The linear level's answer (gyro.analyses.motion.linear_answer with this model's
    constants, which the generic machinery shares)."""
    return generic.linear_answer(motion.reduced, motion.z0, np.asarray(t, float), [_UNIT[c] for c in REDUCED], cap)


def motion_answer(motion: Motion, t, method: str = "linear", rtol: float = 1e-9):
    """The `motion` question's evaluator (gyro/questions/motion.py): the reduced coordinates
    q0 + x at the times t (times, 10) and an estimate of each one's largest absolute error
    over t (m, rad), by the generic machinery (gyro.analyses.motion.motion_answer)."""
    return generic.motion_answer(motion.reduced, motion.z0, t, [_UNIT[c] for c in REDUCED], method, rtol)


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
# boundary of the linear level, per case of `cases` ('away': 2457 N, measured between 2400 N,
# err 0.96 %, and 3200 N, err 1.66 %; 'near': 37.0 N, between 32 N, 0.98 %, and 40 N,
# 1.01 %). From the committed run of bench/forced_nonlinear.py
# (bench/results/forced_linear_limit.json; tests/cli/test_forced.py holds the two equal and
# brackets each limit); docs/forced.md gives the evidence.
LINEAR_LIMIT = {
    "away": {"c": 1.7076741252670077e-09, "order": 1.9997807431819703, "a_1percent": 2457.025350187822},
    "near": {"c": 0.00010236318728218986, "order": 1.9897656077155963, "a_1percent": 37.03701980729408},
}


def linear_limit() -> dict:
    """The measured linear limit as the bench wrote it (the evidence behind LINEAR_LIMIT)."""
    return json.loads(LIMIT_FILE.read_text())


# ----------------------------------------------------------------------------- nonlinear check
class ReducedState(generic.ReducedState):
    """The full 11-coordinate state about the relative equilibrium of one set
    (gyro.analyses.motion.ReducedState): gamma3's rate from the integral C r2 = H (2.3), the
    emitted `cyclic_rates`, bit for bit the rate the frames (1.2)-(1.6) give (it replaced
    their hand-typed form here; tests/methods/test_torsion_motion.py)."""

    def __init__(self, model: Model, values: dict):
        if model.name != MODEL:
            raise ParameterError(f"{model.name}: the periodic response of the full equations is {MODEL}'s only")
        super().__init__(model, values)


class _Periodic(ReducedState):
    """What the periodic responses to one harmonic share: ReducedState's, the forcing
    frequency w = k omega_c and period T, and the linear response X_lin."""

    def __init__(self, model: Model, values: dict, harmonic):
        super().__init__(model, values)
        s, k, a, phi = harmonic
        self.w = k * float(spin_rate(model, self.P[None], self.qe[None])[0])
        self.T = 2 * np.pi / self.w
        u = forced_input(model, 1, s, a, phi)[0]
        self.X_lin = harmonic_response(model, self.P, self.w, u, qe=self.qe[None]).X[0]


def nonlinear_response(model: Model, values: dict, harmonic, rtol: float = 1e-12, max_newton: int = 12,
                       periodic_tol: float | None = None, start: dict | None = None, halvings: int = 6):
    """The steady (periodic) response of the full 11-coordinate equations (the emitted
    `mass_matrix` and `forcing`) to one harmonic f_s = a sin(k omega_c t + phi), the
    imperfection an explicit function of time (its derivative in gamma3, a torque on the
    spin that a drive absorbs, left out: the spin keeps its integral C r2 = H; `spin_torque`
    measures what that leaves out).

    gamma3 is cyclic, so the forced equations are periodic in t with T = 2 pi/(k omega_c):
    the periodic motion is found by shooting over one period (DOP853 at rtol), Newton's
    method on the periodicity z(T) - z = 0 with its exact Jacobian, the monodromy matrix
    of the variational equations integrated beside the motion (`gyro.ode.variational`):
    the near-neutral azimuth mode (1 - e^{i omega1 T} ~ 3e-5) makes the periodicity
    ill-conditioned in its direction, where any approximate Jacobian (the linear operator's
    monodromy, Broyden's updates) stalls as the amplitude grows.
    Returns (X_nonlinear, X_linear, info): the first Fourier coefficients of the reduced
    coordinates over the period (x = Re(X e^{i w t}) + harmonics and offset) and the linear
    response, info the Newton steps and the final periodicity residual (at most
    periodic_tol of the state's scale, default 10 rtol, as is the last Newton step), `motion` (t -> the 11 coordinates
    and their rates over the period) and `continuation`: the periodic state, which `start`
    takes to begin a larger amplitude from this one's answer scaled to it (continuation in
    a). Where Newton from the start does not converge (its residual grows, or max_newton
    steps pass), the response at a/2 is found first and continued from (up to `halvings`
    times; info's `continued_from` lists the amplitudes climbed): from the linear start
    Newton leaves the basin above about 1e3 N away from resonance."""
    from scipy.integrate import solve_ivp

    from gyro import ode

    S = _Periodic(model, values, harmonic)
    s, k, a, phi = harmonic
    P, values, w, T, X_lin = S.P, S.values, S.w, S.T, S.X_lin
    ri, nq, n, q_ref = S.ri, S.nq, S.n, S.q_ref
    zero3 = np.zeros(3)

    def given(t):
        F = np.zeros(3)
        F[s - 1] = a * np.sin(w * t + phi)
        return F, zero3

    fun, ny = ode.numpy_variational(model, P, given)
    # the motion to rtol of itself; the transition matrix, whose entries are O(1) per unit
    # of the state they come from (O(T) for a rate's), to 1e-3 rtol absolutely (a relative
    # control alone would chase its structural zeros)
    atol = np.concatenate([np.full(ny, 1e-30), np.full(ny * ny, 1e-3 * rtol)])
    rows = np.concatenate([ri, nq + ri])

    def full(z):
        return S.state(z[:n], z[n:])

    def period(z):
        Y0 = np.concatenate([full(z), np.eye(ny).ravel(order="F")])
        sol = solve_ivp(fun, (0.0, T), Y0, method="DOP853", rtol=rtol, atol=atol, dense_output=True)
        if not sol.success:
            raise RuntimeError(f"integration failed: {sol.message}")
        YT = sol.y[:, -1]
        zT = np.concatenate([YT[ri] - q_ref[ri], YT[nq + ri]])
        monodromy = YT[ny:].reshape(ny, ny, order="F")[rows] @ S.state_jacobian(full(z)[:, None])[0]
        return zT, monodromy, sol

    z = np.concatenate([X_lin.real, (1j * w * X_lin).real])
    if start is not None:  # continuation: the previous amplitude's periodic state, scaled
        z = start["z"] * (a / start["a"])
    scale = np.concatenate([np.abs(X_lin), w * np.abs(X_lin)]) + 1e-300
    tol = 10 * rtol if periodic_tol is None else periodic_tol
    # Newton on R(z) = z(T) - z with the exact Jacobian; a step the integrator cannot follow
    # is shortened. Periodic to tol of the state's scale, and the last Newton step within
    # tol of it too: the near-neutral azimuth mode multiplies a residual some hundred times
    # in the answer, so a small residual alone does not make an accurate answer, while
    # after a small step of a quadratically converging Newton the error is its square.

    def newton(z):
        zT, Phi, sol = period(z)
        R = zT - z
        resid = float(np.max(np.abs(R)) / scale.max())
        steps, grew, moved = 0, 0, np.inf
        while resid > tol or moved > tol:
            steps += 1
            if steps > max_newton or grew >= 2:
                raise RuntimeError(f"no periodic response within {steps - 1} Newton steps (residual {resid:.2g})")
            dz = np.linalg.solve(Phi - np.eye(2 * n), -R)
            for _ in range(6):
                try:
                    zT, Phi_new, sol_new = period(z + dz)
                    break
                except RuntimeError:
                    dz = dz / 4
            else:
                raise RuntimeError("no periodic response: the shooting's steps leave the integrator's reach")
            z, Phi, sol = z + dz, Phi_new, sol_new
            moved = float(np.max(np.abs(dz)) / scale.max())
            R = zT - z
            last, resid = resid, float(np.max(np.abs(R)) / scale.max())
            grew = grew + 1 if resid > last else 0
        return z, sol, steps, resid

    climbed: list = []
    try:
        z, sol, steps, resid = newton(z)
    except RuntimeError:
        if halvings <= 0:
            raise
        half = nonlinear_response(model, values, (s, k, a / 2, phi), rtol, max_newton, periodic_tol,
                                  start if start is not None and abs(start["a"]) < abs(a) / 2 else None,
                                  halvings - 1)[2]
        climbed = half["continued_from"] + [a / 2]
        z, sol, steps, resid = newton(half["continuation"]["z"] * 2)
    N = 64
    t = np.arange(N) * T / N
    x = sol.sol(t)[ri] - q_ref[ri, None]
    X_nl = 2 / N * (x * np.exp(-1j * w * t)[None, :]).sum(axis=1)
    return X_nl, X_lin, {"newton_steps": steps, "residual": resid, "frequency": w, "period": T,
                         "motion": lambda tt: sol.sol(tt)[:ny], "q_ref": q_ref, "continued_from": climbed,
                         "continuation": {"z": z, "a": a}}


def harmonic_balance(model: Model, values: dict, harmonic, samples: int = 32, tol: float = 1e-10,
                     max_newton: int = 20, first_step_only: bool = False):
    """The steady (periodic) response of the full 11-coordinate equations to one harmonic, as
    `nonlinear_response` finds it by shooting, here by harmonic balance: the reduced
    coordinates as Fourier series in w t (w = k omega_c; harmonics 0 .. samples/2 - 1), the
    equations' residual r = x'' - a(x, x', t) (a the emitted equations' accelerations,
    `gyro.ode`, gamma3's rate from its integral) at `samples` times of the period, turned
    into the harmonics' residuals R_h, solved for R = 0 by Newton's method on the real and
    imaginary parts of the coefficients, each scaled by the linear response of its
    coordinate; the Jacobian is the linear operator's, J(i h w) / M per harmonic, plus the
    nonlinear terms' by forward differences once per step.
    Returns (X_nonlinear, X_linear, info) as `nonlinear_response` does, info `newton_steps`,
    `residual` (the largest |R_h| over the largest |w^2 X_lin|) and `first_correction`
    (the relative size, in the metric of `linear_error`, of the first Newton step from the
    linear response: an estimate of the linear level's error). Newton that does not reach
    tol is RuntimeError, never an unconverged answer (`nonlinear_response` is the
    reference). With `first_step_only`, the answer after the first Newton step alone (info
    `converged` False unless the linear response already met tol): the linear level's
    error estimate, not the nonlinear response."""
    import casadi as ca

    from gyro import ode

    S = _Periodic(model, values, harmonic)
    s, k, a, phi = harmonic
    w, n, N = S.w, S.n, int(samples)
    H = N // 2 - 1  # harmonics 0..H: below the Nyquist one
    t = np.arange(N) * S.T / N
    Fin = np.zeros((3, N))
    Fin[s - 1] = a * np.sin(w * t + phi)
    h = np.arange(H + 1)
    units = [model.meta["coordinate_units"][c] for c in model.meta["reduced"]]
    # per coordinate the scale of its unit group's linear response (as linear_error's metric)
    group = np.array([max(np.abs(S.X_lin)[[i for i, u in enumerate(units) if u == units[j]]]) for j in range(n)])

    def unpack(z):  # z: scaled (Re C_0, Re C_h, Im C_h for h >= 1) per coordinate
        Z = z.reshape(2 * H + 1, n) * group
        C = np.zeros((H + 1, n), complex)
        C[0] = Z[0]
        C[1:] = Z[1:H + 1] + 1j * Z[H + 1:]
        return C

    # the real basis of the scaled unknowns at the samples: x_j = sum_m B[j, m] z_m (per
    # coordinate, times its group scale), m = Re C_0, Re C_h, Im C_h; its rate and acceleration
    c, sn = np.cos(np.outer(t, h[1:] * w)), np.sin(np.outer(t, h[1:] * w))
    hw = h[1:] * w
    Bx = np.hstack([np.ones((N, 1)), c, -sn])
    Bv = np.hstack([np.zeros((N, 1)), -hw * sn, -hw * c])
    Ba = np.hstack([np.zeros((N, 1)), -hw**2 * c, hw**2 * sn])
    # the projection of r_j onto the harmonics' real and imaginary parts, the residual's scale
    Proj = np.vstack([np.ones((1, N)) / N, 2 / N * c.T, -2 / N * sn.T])
    jac = ode.jacobian(model).map(N)

    def samples_of(z):
        Z = z.reshape(2 * H + 1, n) * group
        return Bx @ Z, Bv @ Z, Ba @ Z

    def residual(z):
        """The scaled residual at z and its Jacobian."""
        x, xd, xdd = samples_of(z)
        Y = np.stack([S.state(x[j], xd[j]) for j in range(N)], axis=1)
        yd, Jy = jac(Y, ca.DM(S.P), Fin, np.zeros((3, N)))
        acc = np.asarray(yd)[S.nq + S.ri].T
        Jy = np.asarray(Jy).reshape(2 * S.nq, N, 2 * S.nq).transpose(1, 0, 2)  # (N, 22, 22): mapped column blocks
        dY = S.state_jacobian(Y)  # d state / d (x, xd) per sample
        A = np.einsum("jrs,jsk->jrk", Jy[:, S.nq + S.ri, :], dY)  # (N, n, 2n): d acc / d (x, xd)
        Ax, Av = A[:, :, :n], A[:, :, n:]
        # d r_(j,i) / d z_(m,i') = (Ba[j,m] delta_ii' - Ax[j,i,i'] Bx[j,m] - Av[j,i,i'] Bv[j,m]) group_i'
        G = (np.einsum("jm,ik->jimk", Ba, np.eye(n)) - np.einsum("jik,jm->jimk", Ax, Bx)
             - np.einsum("jik,jm->jimk", Av, Bv)) * group[None, None, None, :]
        Jm = np.einsum("pj,jimk->pimk", Proj, G) / (w**2 * group)[None, :, None, None]
        r = (Proj @ (xdd - acc) / (w**2 * group)).ravel()
        return r, Jm.reshape(r.size, r.size)

    z = np.zeros((2 * H + 1, n))
    z[1] = S.X_lin.real / group
    z[H + 1] = S.X_lin.imag / group
    z = z.ravel()
    r, Jm = residual(z)
    steps, first = 0, None
    while np.max(np.abs(r)) > tol:
        steps += 1
        if steps > max_newton or not np.all(np.isfinite(r)):
            raise RuntimeError(f"harmonic balance: no convergence in {max_newton} Newton steps "
                               f"(residual {np.max(np.abs(r)):.2g})")
        dz = np.linalg.solve(Jm, -r)
        if first is None:
            first = linear_error(unpack(z + dz)[1], S.X_lin, units)
        z = z + dz
        if first_step_only:
            return unpack(z)[1], S.X_lin, {"newton_steps": steps, "first_correction": first, "converged": False,
                                           "frequency": w, "period": S.T, "group": group}
        r, Jm = residual(z)
    return unpack(z)[1], S.X_lin, {"newton_steps": steps, "residual": float(np.max(np.abs(r))),
                                   "first_correction": 0.0 if first is None else first, "converged": True,
                                   "frequency": w, "period": S.T, "group": group}


def spin_torque(model: Model, values: dict, harmonic, info: dict, samples: int = 256) -> dict:
    """What the nonlinear check leaves out, measured on its periodic motion: the
    imperfection's derivative in gamma3, a torque on the spin tau = dU/dgamma3 (the emitted
    `forcing`'s gamma3 row with the given functions' derivatives in gamma3, less without
    them), which a drive absorbs there. Without the drive it would change the spin's
    momentum H by the integral of tau: `torque_mean` (N m, its mean over the period: a drive
    must supply it, or the spin drifts by torque_mean / H per second, `drift_per_second`),
    `momentum_swing` (the largest |delta H| / H of its periodic part) and
    `effect_estimate`, momentum_swing times the linear response's relative sensitivity to H
    at the forcing frequency (the error metric of `linear_error` per unit relative change
    of H): the order of the change it would make in the amplitudes compared with the
    linear ones, against their measured difference."""
    import casadi as ca

    s, k, a, phi = harmonic
    P = model.vector(values)
    vals = model.parameters(values)
    coords = model.meta["coordinates"]
    k3 = coords.index("gamma3")
    nq = len(coords)
    T, w = info["period"], info["frequency"]
    t = np.arange(samples) * T / samples
    Y = info["motion"](t)
    f = model.casadi.forcing
    F = np.zeros((3, samples))
    dF = np.zeros((3, samples))
    F[s - 1] = a * np.sin(w * t + phi)
    dF[s - 1] = a * k * np.cos(w * t + phi)  # d f_s / d gamma3 along gamma3 = omega_c t
    tau = np.empty(samples)
    Pd = ca.DM(P)
    for j in range(samples):
        with_d = f(Pd, Y[:nq, j], Y[nq:, j], F[:, j], dF[:, j])
        without = f(Pd, Y[:nq, j], Y[nq:, j], F[:, j], np.zeros(3))
        tau[j] = float(with_d[k3] - without[k3])
    mean = float(tau.mean())
    # the periodic part of its integral, by the spectrum: delta H = sum over n != 0 of
    # tau_n / (i n w) e^{i n w t}
    c = np.fft.rfft(tau - mean) / samples
    nw = np.arange(c.size) * w
    dH = np.zeros(samples)
    for m in range(1, c.size):
        dH += 2 * (c[m] / (1j * nw[m]) * np.exp(1j * nw[m] * t)).real
    H = vals["H"]
    swing = float(np.max(np.abs(dH)) / H)
    # the linear response's relative sensitivity to H at the fixed forcing frequency
    from gyro.equilibrium import equilibrium
    units = [model.meta["coordinate_units"][c] for c in model.meta["reduced"]]
    u = forced_input(model, 1, s, a, phi)[0]
    eps = 1e-6
    X = []
    for sign in (-1, 1):
        Pi = model.vector({**values, "H": H * (1 + sign * eps)})
        X.append(harmonic_response(model, Pi, w, u, qe=equilibrium(model, Pi)[None]).X[0])
    X0 = harmonic_response(model, P, w, u, qe=equilibrium(model, P)[None]).X[0]
    sens = linear_error(X0 + (X[1] - X[0]) / (2 * eps), X0, units)
    return {"torque_mean": mean, "drift_per_second": mean / H, "momentum_swing": swing,
            "sensitivity_to_H": sens, "effect_estimate": swing * sens}


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
