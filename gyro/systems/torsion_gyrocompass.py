"""Free motion of the torsion gyrocompass about its relative equilibrium (003, sections 1-2):
the `motion` question's levels `linear_motion` and `nonlinear_motion` (docs/hierarchy.md).

A motion starts from the exact equilibrium q0 (gyro.equilibrium) displaced by x(0) and
moving at x'(0) in the reduced coordinates (2.4) (INITIAL: `<coordinate>_0`, `<coordinate>_d0`),
the spin's momentum C r2 = H (2.3) (gamma3's rate from the integral, as the forced
response's states, gyro.analyses.forced.ReducedState). Answered: the ten reduced coordinates
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

from functools import cached_property

import numpy as np

from gyro.models import ParameterError, load

MODEL = "torsion_gyrocompass"
# the reduced coordinates (2.4), metadata 'reduced' (tests/test_torsion_motion.py holds them equal)
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

FACTOR = 2.0  # the bound over the correction: measured error/bound 0.50..0.55 below the cap (bench)
# the largest estimate, over the motion's largest excursion (the question's scale), for which
# it is a bound: measured error over it 0.50..0.55 up to 0.15, 0.62 at 0.30, 0.77 at 0.58,
# 1.0 at 0.84, 2.0 at 1.3 (bench/results/levels.json 'toward_the_cap', docs/hierarchy.md)
CAP = 0.25
ROUNDING = 4.0  # the exponential's rounding per step, in eps of the largest |z_L|
CORRECTIONS = 2  # Picard steps: the second holds every term of third order (docs/hierarchy.md)
FINE = 32  # samples per shortest period 2 pi/(2 omega_max) of the remainder's quadratic terms
FINER = 1e-2  # the integrator's second run's tolerance, of the first's
FLOOR = 100.0  # the integrator's absolute tolerance, at least this many eps of the equilibrium


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
        """The set's equilibrium and full state (gyro.analyses.forced.ReducedState)."""
        from gyro.analyses.forced import ReducedState

        model = load(MODEL)
        if tuple(model.meta["reduced"]) != REDUCED:
            raise RuntimeError(f"{MODEL}: the reduced coordinates changed; REDUCED must follow them")
        return ReducedState(model, self.params)

    @cached_property
    def first_order(self) -> np.ndarray:
        """A (2n, 2n) of z' = A z, z = (x, x'), from the generated operator at the equilibrium."""
        from gyro.equilibrium import operators

        S = self.reduced
        M, D, K = (np.asarray(X, float)[0] for X in operators(S.model, S.P[None], S.qe[None]))
        n = S.n
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -np.linalg.solve(M, K)
        A[n:, n:] = -np.linalg.solve(M, D)
        return A

    @cached_property
    def reduced_rhs(self):
        """z -> f(z) (CasADi Function, 2n -> 2n): the full equations in the reduced state, the
        spin's rate from its integral, no imperfections."""
        import casadi as ca

        from gyro import ode

        S = self.reduced
        sym = ode.symbolic(S.model)
        z = ca.SX.sym("z", 2 * S.n)
        Y = S.state(ca.vertsplit(z[:S.n]), ca.vertsplit(z[S.n:]), ca)
        ydot = ca.substitute([sym.ydot], [sym.y, sym.p, *sym.inputs],
                             [Y, ca.DM(S.P), *[ca.DM.zeros(v.numel()) for v in sym.inputs]])[0]
        return ca.Function("reduced_rhs", [z], [ca.vertcat(z[S.n:], ydot[S.nq + S.ri])])

    @property
    def z0(self) -> np.ndarray:
        return np.concatenate([self.x0, self.xd0])


def _uniform(t) -> np.ndarray:
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 2 or t[0] != 0.0 or np.any(np.diff(t) <= 0):
        raise ValueError("the sample times must be increasing from t = 0")
    if not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0.0):
        raise ValueError("the linear motion takes uniform sample times")
    return t


def linear_motion(motion: Motion, t):
    """The linear motion and its correction at the sample times t (uniform from 0): (z_L, e,
    steps), each (times, 2n), e after CORRECTIONS steps of Picard's iteration
    e' = A e + r(z_L + e), e(0) = 0, r(z) = f(z) - A z; steps the fine grid's steps per
    sample interval."""
    from scipy.signal import StateSpace, lsim

    t = _uniform(t)
    A = motion.first_order
    n2 = A.shape[0]
    w_max = float(np.max(np.abs(np.linalg.eigvals(A))))
    h = 2 * np.pi / (2 * w_max) / FINE
    per = max(1, int(np.ceil((t[1] - t[0]) / h)))
    tf = np.linspace(0.0, t[-1], (t.size - 1) * per + 1)
    sys = StateSpace(A, np.eye(n2), np.eye(n2), np.zeros((n2, n2)))
    zero = np.zeros((tf.size, n2))
    zL = lsim(sys, zero, tf, X0=motion.z0, interp=True)[2]
    f = motion.reduced_rhs.map(tf.size)
    e = np.zeros_like(zL)
    for _ in range(CORRECTIONS):  # Picard's iteration about the linear motion: e' = A e + r(z_L + e)
        z = zL + e
        r = np.asarray(f(z.T)).T - z @ A.T
        e = lsim(sys, r, tf, X0=np.zeros(n2), interp=True)[2]
    return zL[::per], e[::per], per


def integrate(motion: Motion, t, method: str = "DOP853", rtol: float = 1e-9, scale: np.ndarray | None = None):
    """The full 11-coordinate equations integrated from the motion's state: the reduced
    coordinates q0 + x at the times t (times, n). `scale` (2: the displacements' and the
    rates' size) sets the absolute tolerances, 1e-3 rtol of it (default: the linear motion's
    largest |x|, |x'|), so a small perturbation is resolved, but not below FLOOR eps of the
    equilibrium's largest coordinate (and that times the fastest frequency for the rates):
    there the state's rounding, amplified by the stiff bearings, would stall the steps."""
    from scipy.integrate import solve_ivp

    from gyro import ode

    S = motion.reduced
    t = np.asarray(t, float)
    n = S.n
    A = motion.first_order
    if scale is None:
        zL = linear_motion(motion, t)[0]
        scale = np.array([np.max(np.abs(zL[:, :n])), np.max(np.abs(zL[:, n:]))])
    floor = FLOOR * np.finfo(float).eps * np.max(np.abs(S.q_ref[S.ri]))
    w_max = float(np.max(np.abs(np.linalg.eigvals(A))))
    atol = np.empty(2 * S.nq)
    atol[:S.nq] = max(1e-3 * rtol * scale[0], floor)
    atol[S.nq:] = max(1e-3 * rtol * scale[1], floor * w_max)
    sol = solve_ivp(ode.numpy_rhs(S.model, S.P), (t[0], t[-1]), S.state(motion.x0, motion.xd0), method=method,
                    t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"{method}: {sol.message}")
    return sol.y[S.ri].T


def _group_max(v: np.ndarray) -> np.ndarray:
    """Per entry of x (n) or (x, x') (2n), the largest of its unit group (displacements in m,
    in rad, their rates): the scale the estimate takes per coordinate."""
    n = len(REDUCED)
    out = np.empty_like(v)
    for half in range(0, v.size, n):
        for unit in set(_UNIT.values()):
            idx = [half + j for j, c in enumerate(REDUCED) if _UNIT[c] == unit]
            out[idx] = np.max(v[idx])
    return out


def linear_answer(motion: Motion, t, cap: float = CAP):
    """The linear level's answer: q0 + x_L at the times t (times, n) and its estimate, FACTOR
    times the correction's largest |e| over each coordinate's unit group plus the rounding,
    infinite where its largest exceeds `cap` of the motion's largest excursion (the error
    map measures the uncapped estimate with cap = inf)."""
    S = motion.reduced
    n = S.n
    zL, e, per = linear_motion(motion, t)
    est = FACTOR * _group_max(np.max(np.abs(e), axis=0))[:n]
    est += ROUNDING * np.finfo(float).eps * per * (len(t) - 1) * np.max(np.abs(zL[:, :n]))
    excursion = np.max(np.sqrt(np.sum((zL[:, :n] - zL[:1, :n]) ** 2, axis=1)))
    if not np.max(est) <= cap * excursion:  # beyond the iteration's reach: no bound
        est = np.full(n, np.inf)
    return S.q_ref[S.ri] + zL[:, :n], est


def motion_answer(motion: Motion, t, method: str = "linear", rtol: float = 1e-9):
    """The `motion` question's evaluator (gyro/questions/motion.py): the reduced coordinates
    q0 + x at the times t (times, 10) and an estimate of each one's largest absolute error
    over t (m, rad)."""
    t = np.asarray(t, float)
    n = motion.reduced.n
    if method == "linear":
        return linear_answer(motion, t)
    from gyro import ode

    zL = linear_motion(motion, t)[0]
    scale = np.array([np.max(np.abs(zL[:, :n])), np.max(np.abs(zL[:, n:]))])
    q, est = ode.two_tolerances(lambda r: integrate(motion, t, method, r, scale), rtol, FINER)
    # not below twice the finer run's tolerance on the coordinates' size (the equilibrium's
    # offsets included): an error the two runs share where both sit at the absolute
    # tolerance's floor, which their difference does not see (the smallest perturbations)
    return q, np.maximum(est, 2 * rtol * FINER * _group_max(np.max(np.abs(q), axis=0)))
