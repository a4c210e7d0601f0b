"""Precession theory of a gyroscope in a gimbal on a rotating base (Ishlinsky 1959, seed 002):
the five levels of its hierarchy integrated from one parameter set.

Levels, most exact first (docs/precession.md):
- `full`: the three-body Lagrange equations (generated `mass_matrix`, `forcing`), started
  on the precession: alpha'(0), beta'(0) those of (13), phi'(0) = H/A3 - omega_z';
- `rigorous`: (13) in alpha, beta, H (`rigorous_system`);
- `image`: (21) in x, y, H (`image_system`): the same motion as `rigorous`;
- `small`: (28) (`small_system`);
- `elementary`: (30) (`elementary_system`), H constant.
Each precession level is emitted as a linear system A r = b in its rates r (the friction
moments carry the rates), solved at each step.
Every level is integrated by CasADi's CVODES (Adams, rtol 1e-12) over the generated CasADi
functions, one integrator per level built once with the parameters as its input (the bound
integrates it again by BDF, `multistep="bdf"`, an independent method).
The image point and the angles are converted by the generated `image_point` and
`angles_of_image`. (13) is singular at beta = +-90 deg, and the image point leaves the
picture plane at alpha = +-90 deg: a motion that reaches either (|cos| < 1e-3) is refused.

A time-varying base: `simulate(..., base=u)` with u(t) -> (u_xi, u_eta, u_zeta) in rad/s, a
closed form in t of NumPy functions (`oscillating_base` builds the command line's
u_NAME + AMP sin(FREQ t + PHASE)). It is evaluated on a CasADi symbol, so that CVODES
integrates the emitted `*_varying` functions (the model's base rate made signals) with u(t)
exactly and the full level's u'(t) is its exact derivative; the parameters u_xi, u_eta,
u_zeta are then unused.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from gyro import intervals, ode
from gyro.errors import ParameterError, finite_number
from gyro.models import load

MODEL = "gimbal_precession"
LEVELS = ("full", "rigorous", "image", "small", "elementary")  # most exact first
SINGULAR_COS = 1e-3  # |cos beta| (or |cos alpha|) below this: at the singularity (|angle| > 89.94 deg)
RTOL, ATOL = 1e-12, 1e-14
MAX_STEPS = 2 * 10**6  # full, over the horizon: its nutation at H/J rad/s sets the step
MAX_STEPS_PRECESSION = 10**4  # between two output times (CVODES counts per output interval); the precession
# levels take a few hundred for an hour at rtol 1e-12, so more means the singularity at beta = +-90 deg


BASE = ("u_xi", "u_eta", "u_zeta")  # the components of the base rate, in the order base(t) gives them


class Singular(ParameterError):
    """A motion that reaches beta = +-90 deg (where (13) is singular) or alpha = +-90 deg
    (where the image point leaves the picture plane)."""


def parameters(sets: dict | None = None) -> dict:
    """Model values (by model symbol) from NAME=VALUE text or numbers by command-line name;
    each checked (unknown name, not a number, NaN, inf, a non-positive inertia or H, an
    angle out of range): ParameterError naming it."""
    model = load(MODEL)
    known = [*model.param_names, *model.aliases]  # the declared names, and M_motor for Mmotor
    out = {}
    for key, raw in (sets or {}).items():
        if key not in known:
            raise ParameterError(f"unknown parameter {key!r} for {MODEL}; known: {model.known_names()}")
        if model.canonical(key) in out:
            raise ParameterError(f"parameter {model.canonical(key)}: given twice (as {key} and another name)")
        out[model.canonical(key)] = finite_number(f"parameter {key}", raw)
    return model.parameters(out)


def vector(values: dict) -> np.ndarray:
    return load(MODEL).vector(values)


def named(values: dict) -> dict:
    """The values by their declared names, and by M_motor (the JSON's key before) too."""
    return load(MODEL).named(values)


@lru_cache(maxsize=64)
def _integrator(level: str, grid: tuple, steps: int, rtol_scale: float = 1.0, multistep: str = "adams"):
    """A CVODES integrator of one level, parameters as its input p, outputs at the times of
    `grid` (in [0, 1]) scaled by its input: y(s) with dy/ds = T f(y); at most `steps` steps
    between two output times; `multistep` "adams" (the answer's) or "bdf" (the bound's
    second, independent run)."""
    import casadi as ca

    cf = load(MODEL).casadi
    npar = len(load(MODEL).param_names)
    P = ca.SX.sym("P", npar + 1)  # parameters and the horizon T
    p, T = P[:npar], P[npar]
    if level == "full":

        s = ode.symbolic(load(MODEL))
        y = s.y
        rhs = ca.substitute(s.ydot, s.p, p)
    else:
        y = ca.SX.sym("y", 3)
        A, b = getattr(cf, f"{level}_system")(p, y[:2], y[2])
        rhs = ca.solve(A, b)
    return ca.integrator(f"F_{level}", "cvodes", {"x": y, "p": P, "ode": T * rhs}, 0.0, list(grid),
                         _options(steps, rtol_scale, multistep))


MULTISTEP = {"adams": "functional", "bdf": "newton"}  # CVODES' method and its nonlinear iteration


def _options(steps: int, rtol_scale: float, multistep: str = "adams") -> dict:
    return {"abstol": ATOL * rtol_scale, "reltol": RTOL * rtol_scale, "max_num_steps": int(steps),
            "linear_multistep_method": multistep, "nonlinear_solver_iteration": MULTISTEP[multistep],
            **ode.CASADI_QUIET}  # no CasADi warning of a NaN rate near +-90 deg: the error says it


CHECK_POINTS = 1001  # the motion is checked for +-90 deg at these times of the horizon besides the asked ones


def _steps(level: str, n: int) -> int:
    """The step budget between two of n output times: full, MAX_STEPS over the whole horizon
    shared among the intervals (CVODES counts per interval), so a runaway horizon stops
    after as many steps however many points are asked for; the precession levels,
    MAX_STEPS_PRECESSION per interval."""
    return max(500, MAX_STEPS // max(1, n - 1)) if level == "full" else MAX_STEPS_PRECESSION


def _check_grid(t: np.ndarray):
    """(grid, where) of the check: the asked times t / T with CHECK_POINTS evenly spaced ones
    among them (a motion that passes +-90 deg and returns between two asked times is seen
    there), and where the asked times are in it; None where no gap between asked times is
    wider than the check's (decided by the widest gap, not by how many times are asked:
    the times may be uneven)."""
    asked = t / float(t[-1])
    if np.max(np.diff(asked)) <= 1.0 / (CHECK_POINTS - 1):  # as dense as the check already, everywhere
        return None
    grid = np.union1d(asked, np.linspace(0.0, 1.0, CHECK_POINTS))
    return tuple(float(g) for g in grid), np.searchsorted(grid, asked)


@dataclass(frozen=True)
class Oscillation:
    """One harmonic term of a time-varying base: u_NAME(t) gains AMP sin(FREQ t + PHASE)
    (rad/s, rad/s, rad), NAME one of xi, eta, zeta (a ship's rolling or yaw)."""
    component: str
    amplitude: float
    frequency: float
    phase: float = 0.0

    def describe(self) -> dict:
        return {"amplitude": self.amplitude, "frequency": self.frequency, "phase": self.phase}


def oscillation(component: str, amplitude, frequency, phase=0.0, what: str = "base rate") -> Oscillation:
    """An Oscillation with every number checked: a known component, finite numbers, a
    frequency >= 0; ParameterError naming `what` otherwise."""
    names = [b.split("_", 1)[1] for b in BASE]
    if component not in names:
        raise ParameterError(f"{what}: unknown component {component!r}; known: {', '.join(names)}")
    amp = finite_number(f"{what} amplitude", amplitude)
    freq = finite_number(f"{what} frequency", frequency)
    ph = finite_number(f"{what} phase", phase)
    if freq < 0:
        raise ParameterError(f"{what}: the frequency must be >= 0 rad/s, got {freq!r}")
    return Oscillation(component, amp, freq, ph)


@dataclass(frozen=True)
class OscillatingBase:
    """u(t) = `constant` (u_xi, u_eta, u_zeta) plus each Oscillation's AMP sin(FREQ t + PHASE)
    on its component: a base(t) for `simulate`; equal bases share their integrators."""
    constant: tuple
    terms: tuple

    def __call__(self, t):
        u = list(self.constant)
        for o in self.terms:
            k = BASE.index("u_" + o.component)
            u[k] = u[k] + o.amplitude * np.sin(o.frequency * t + o.phase)
        return tuple(u)

    def describe(self) -> dict:
        """The JSON form: {u_NAME: [{amplitude, frequency, phase}, ...]} of each component
        that oscillates, about the parameters' constants."""
        out = {}
        for o in self.terms:
            out.setdefault("u_" + o.component, []).append(o.describe())
        return out


def oscillating_base(values: dict, terms) -> OscillatingBase:
    """The base of the parameters' constant rate `values` (u_xi, u_eta, u_zeta) and the
    Oscillations `terms` about it."""
    return OscillatingBase(tuple(float(values[b]) for b in BASE), tuple(terms))


# CasADi operations that make a function of t jump (a step, a comparison, a branch, a
# sawtooth): their derivative is taken as 0, so the impulse u' of a jump would be lost
_JUMPS = ("OP_LT", "OP_LE", "OP_EQ", "OP_NE", "OP_NOT", "OP_AND", "OP_OR", "OP_IF_ELSE_ZERO", "OP_FLOOR",
          "OP_CEIL", "OP_FMOD", "OP_REMAINDER", "OP_SIGN", "OP_COPYSIGN",
          "OP_ATAN2",  # its branch cut: atan2(sin t, cos t) is a sawtooth
          "OP_LOW", "OP_CALL")  # a table lookup, a call of another function: not seen into


def _base_signals(base):
    """(t, the rungs of the model's time-varying parameters as a CasADi SX column in the
    emitted order (metadata 'varying': each value, then its derivatives), a Function of t
    giving them, the Function serialised: the key of its integrators): base(t) evaluated
    on a symbol, its derivatives exact. A base that jumps (a step, a comparison, floor,
    mod, sign) is refused: its derivative would be 0 where it is an impulse."""
    import casadi as ca

    t = ca.SX.sym("t")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)  # NumPy functions on a CasADi symbol
            u = base(t)
        u = [ca.SX(c) for c in u]
    except Exception as exc:  # noqa: BLE001 - any failure of the user's function says the same
        why = (str(exc).strip().splitlines() or [""])[0]
        raise ParameterError(f"base: the base rate must be a function of t giving (u_xi, u_eta, u_zeta) as a "
                             f"closed form of NumPy functions ({type(exc).__name__}: {why})") from None
    if len(u) != len(BASE) or any(c.numel() != 1 for c in u):
        raise ParameterError(f"base: the base rate must give three numbers (u_xi, u_eta, u_zeta), got {len(u)}")
    rungs = []
    for sig in load(MODEL).meta["varying"]:
        r = u[BASE.index(sig["parameter"])]
        rungs.append(r)
        for _ in range(sig["order"]):
            r = ca.jacobian(r, t)
            rungs.append(r)
    col = ca.densify(ca.vertcat(*rungs))
    fun = ca.Function("base_rate", [t], [col])
    values = ca.Function("base_value", [t], u)
    jumps = {getattr(ca, name) for name in _JUMPS if hasattr(ca, name)}
    if any(values.instruction_id(k) in jumps for k in range(values.n_instructions())):
        raise ParameterError("base: the base rate may jump (a step, comparison, branch, floor, mod, sign or "
                             "atan2 of t, or a lookup or call): "
                             "its derivative, an impulse, would be lost; write it as a smooth function of t")
    return t, col, fun, fun.serialize()


def base_rungs(base, t) -> np.ndarray:
    """The rungs of a base base(t) at the times t, (len(t), rungs) in the emitted order of the
    `*_varying` functions' group `signals` (u_xi, u_xi', u_eta, u_eta', u_zeta, u_zeta')."""
    return _signals_at(_base_signals(base)[2], t)


def _signals_at(fun, t) -> np.ndarray:
    """The rungs at the times t: (len(t), rungs), or one row for a number t."""
    t = np.atleast_1d(np.asarray(t, float))
    out = np.array(fun(t[None, :])).T if t.size > 1 else np.array(fun(t[0])).reshape(1, -1)
    if not np.all(np.isfinite(out)):
        raise ParameterError("base: the base rate or its derivative is not finite on the horizon")
    return out


_VARYING: dict = {}


def _integrator_varying(level: str, grid: tuple, steps: int, rtol_scale: float, signals, multistep: str = "adams"):
    """As `_integrator` with the base rate in the emitted `*_varying` functions, `signals`
    its `_base_signals`: the input p is (parameters, the horizon T, the start time t0),
    t = t0 + T s. Integrators are kept by the base's expression to the last bit (its
    serialised form), never by the function's identity: a function whose result changes
    between calls (a global, a mutable object) is integrated as it is now."""
    import casadi as ca

    key = (level, grid, steps, rtol_scale, signals[3], multistep)
    if key in _VARYING:
        return _VARYING[key]
    if len(_VARYING) >= 16:
        _VARYING.clear()

    cf = load(MODEL).casadi
    npar = len(load(MODEL).param_names)
    P = ca.SX.sym("P", npar + 2)
    p, T, t0 = P[:npar], P[npar], P[npar + 1]
    s = ca.SX.sym("s")
    tb, col = signals[0], signals[1]
    sig = ca.substitute(col, tb, t0 + T * s)
    if level == "full":

        so = ode.symbolic(load(MODEL), varying=True)
        y = so.y
        rhs = ca.substitute(ca.substitute(so.ydot, so.p, p), so.inputs[0], sig)
    else:
        y = ca.SX.sym("y", 3)
        A, b = getattr(cf, f"{level}_system_varying")(p, y[:2], y[2], sig)
        rhs = ca.solve(A, b)
    F = ca.integrator(f"F_{level}_varying", "cvodes", {"x": y, "t": s, "p": P, "ode": T * rhs}, 0.0, list(grid),
                      _options(steps, rtol_scale, multistep))
    _VARYING[key] = F
    return F


def rates(level: str, P, state2, H_now, signals=None) -> np.ndarray:
    """The rates of a precession level at one state (angles or image point, and H) from its
    emitted linear system A r = b; `signals` the base rate's rungs at that instant (the
    `*_varying` system) or None (the constant base of the parameters)."""
    nf = load(MODEL).numpy
    if signals is None:
        A, b = getattr(nf, f"{level}_system")(P, state2, [H_now])
    else:
        A, b = getattr(nf, f"{level}_system_varying")(P, state2, [H_now], signals)
    return np.linalg.solve(A, b)


def initial_state(level: str, values: dict, base=None) -> np.ndarray:
    nf = load(MODEL).numpy
    P = vector(values)
    a0, b0, H0 = values["alpha0"], values["beta0"], values["H"]
    for name, ang in (("beta0", b0), ("alpha0", a0)):
        if abs(np.cos(ang)) < SINGULAR_COS:
            raise Singular(f"parameter {name}: at +-90 deg, where (13) is singular or the image point leaves the plane")
    if level == "full":
        if base is None:
            ad, bd, _ = rates("rigorous", P, [a0, b0], H0)
            (pd,) = nf.spin_from_momentum(P, [a0, b0], [ad, bd], [H0])
        else:  # on the precession of the base rate at t = 0
            s0 = _signals_at(_base_signals(base)[2], 0.0)[0]
            ad, bd, _ = rates("rigorous", P, [a0, b0], H0, s0)
            (pd,) = nf.spin_from_momentum_varying(P, [a0, b0], [ad, bd], [H0], s0)
        return np.array([a0, b0, 0.0, ad, bd, pd])
    if level == "rigorous":
        return np.array([a0, b0, H0])
    x0, y0 = nf.image_point(P, [a0, b0])
    return np.array([x0, y0, H0])


IntegrationBudget = ode.IntegrationBudget  # the one type (gyro/ode.py)


NEAR_SINGULAR_COS = 0.05  # |cos| of beta or alpha at the last state reached: on the way to +-90 deg


def _why_stopped(level: str, P, y0, T: float, rtol_scale: float = 1.0, base=None,
                 multistep: str = "adams") -> Exception:
    """Why CVODES stopped before T: the motion is integrated again over doubling horizons
    T 2^-40, T 2^-39, ..., T (one output each, restarting from the state reached: the
    levels are autonomous) until one fails, and on from there by halved steps (60 tries,
    never past T); the last state reached says whether beta or alpha was on the way to +-90
    deg (Singular, bad input for the level) or not (the step budget: IntegrationBudget).
    The full level, whose pieces would each cost its whole budget again, is said to have
    stopped by its budget or a failed step (its samples show the singularity where it
    integrates). With a time-varying base each piece starts at the time it has reached."""
    if level == "full":  # its pieces would cost the whole budget again (seconds): said as it is
        return IntegrationBudget(f"full: CVODES stopped before t = {T:.6g} s (its step budget of "
                                 f"{MAX_STEPS:.3g} steps over the horizon, or a failed step)")
    nf = load(MODEL).numpy
    if base is None:
        F = _integrator(level, (0.0, 1.0), _steps(level, 2), rtol_scale, multistep)

        def inputs(dt, _t0):
            return np.append(P, dt)
    else:
        F = _integrator_varying(level, (0.0, 1.0), _steps(level, 2), rtol_scale, _base_signals(base), multistep)

        def inputs(dt, t0):
            return np.append(P, [dt, t0])
    y, reached, step = np.asarray(y0, float), 0.0, 0.0
    for k in range(41):
        target = T * 2.0 ** (k - 40)
        try:
            y = np.array(F(x0=y, p=inputs(target - reached, reached))["xf"])[:, -1]
        except RuntimeError:
            step = target - reached
            break
        reached = target
    if reached >= T:  # the whole horizon in pieces: the run's own budget per output interval was short
        return IntegrationBudget(f"{level}: the integration stopped by its step budget between two output "
                                 f"times before t = {T:.6g} s (fewer --points take more steps each)")
    for _ in range(60):  # closer to where it stops, advancing by halved steps, never past T
        step = min(step / 2, T - reached)
        if step <= 0:
            break
        try:
            y = np.array(F(x0=y, p=inputs(step, reached))["xf"])[:, -1]
            reached += step
            step *= 2
        except RuntimeError:
            continue
    if level == "rigorous":
        alpha, beta = y[0], y[1]
    else:
        alpha, beta = nf.angles_of_image(P, [y[0], y[1]])
    if not (np.isfinite(alpha) and np.isfinite(beta)) or min(abs(np.cos(alpha)), abs(np.cos(beta))) < NEAR_SINGULAR_COS:
        return Singular(f"{level}: the integration stopped near t = {reached:.6g} s of {T:.6g} s with beta or alpha "
                        "near +-90 deg, where (13) is singular")
    return IntegrationBudget(f"{level}: the integration stopped by its step budget near t = {reached:.6g} s of "
                             f"{T:.6g} s, beta {np.degrees(beta):.3g} deg and alpha {np.degrees(alpha):.3g} deg there, "
                             "not at +-90 deg; a shorter --t-end")


def simulate(values: dict, t, level: str, rtol_scale: float = 1.0, base=None, multistep: str = "adams"):
    """The motion of one level at the times t (t[0] = 0): a gyro.results.Motion of the image
    point x, y (22), the gimbal angles alpha, beta (rad) and the rotor momentum H (N m s),
    with its `level`, `params` (by their command-line names), `seconds` (CPU time of the
    integration) and `base_rate` (None, or the base's description). Singular when it
    reaches beta or alpha = +-90 deg; IntegrationBudget when the integrator stops by its
    step budget elsewhere. `base`: None (the constant base rate of the parameters) or a
    function of t giving (u_xi, u_eta, u_zeta) in rad/s (see the module's doc); its
    `describe()`, where it has one, is the result's `base_rate`."""
    if level not in LEVELS:
        raise ParameterError(f"--level: unknown level {level!r} of {MODEL}; known: {', '.join(LEVELS)}")
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 2 or t[0] != 0 or not np.all(np.diff(t) > 0) or not np.isfinite(t[-1]):
        raise ParameterError("t: the output times must start at 0 and increase, at least two of them")
    nf = load(MODEL).numpy
    P = vector(values)
    y0 = initial_state(level, values, base)
    T = float(t[-1])
    grid, steps = tuple(float(g) for g in t / T), _steps(level, len(t))
    signals = None if base is None else _base_signals(base)

    def integrate(grid, steps):
        if base is None:
            F, p = _integrator(level, grid, steps, rtol_scale, multistep), np.append(P, T)
        else:
            F, p = _integrator_varying(level, grid, steps, rtol_scale, signals, multistep), np.append(P, [T, 0.0])
        try:
            Y = np.array(F(x0=y0, p=p)["xf"]).T
        except RuntimeError:
            raise _why_stopped(level, P, y0, T, rtol_scale, base, multistep) from None
        return np.vstack([y0, Y]) if len(grid) != Y.shape[0] else Y

    c0 = time.process_time()
    Y = integrate(grid, steps)
    seconds = time.process_time() - c0
    where = np.arange(len(t))
    check = _check_grid(t)
    if check is not None:  # the same motion on a denser grid, checked there (its time not the level's cost)
        grid, where = check
        Yc = integrate(grid, _steps(level, len(grid)))
        Yc[where] = Y  # the answer is the asked grid's run, to its last bit
        Y = Yc
    tg = np.asarray(grid) * T  # the motion on the whole grid, checked there; answered at t
    if signals is not None:
        S = _signals_at(signals[2], tg)
    if level in ("full", "rigorous"):
        alpha, beta = Y[:, 0], Y[:, 1]
        xy = nf.image_point(P, np.stack([alpha, beta], axis=-1))
        x, y = xy[:, 0], xy[:, 1]
        if level == "full" and base is not None:
            H = nf.rotor_momentum_varying(P, Y[:, :3], Y[:, 3:], S)[:, 0]
        elif level == "full":
            H = nf.rotor_momentum(P, Y[:, :3], Y[:, 3:])[:, 0]
        else:
            H = Y[:, 2]
    else:
        x, y, H = Y[:, 0], Y[:, 1], Y[:, 2]
        ab = nf.angles_of_image(P, np.stack([x, y], axis=-1))
        alpha, beta = ab[:, 0], ab[:, 1]
    if not (np.all(np.isfinite(alpha)) and np.all(np.isfinite(beta)) and np.all(np.isfinite(H))):
        raise Singular(f"{level}: the motion leaves the domain (beta or alpha reaches +-90 deg)")
    cb, ca_ = np.cos(beta), np.cos(alpha)
    near = (np.abs(cb) < SINGULAR_COS) | (np.abs(ca_) < SINGULAR_COS)
    near[1:] |= (np.sign(cb[1:]) != np.sign(cb[:-1])) | (np.sign(ca_[1:]) != np.sign(ca_[:-1]))  # passed between samples
    bad = np.flatnonzero(near)
    if bad.size:
        k = bad[0]
        which = "beta" if abs(cb[k]) < SINGULAR_COS or (k > 0 and np.sign(cb[k]) != np.sign(cb[k - 1])) else "alpha"
        raise Singular(f"{level}: {which} reaches +-90 deg by t = {tg[k]:.6g} s, where (13) is singular "
                       "or the image point leaves the picture plane")
    described = getattr(base, "describe", None)
    x, y, alpha, beta, H = (np.asarray(v, float)[where] for v in (x, y, alpha, beta, H))
    return motion_result(level, named(values), t, np.stack([x, y, alpha, beta, H], axis=1), seconds,
                         described() if callable(described) else None)


# the series of a level's motion: name, unit, description, the table's column format
SERIES = (("x", "", "the image point in the picture plane z = 1 (22)", ">16.10g"),
          ("y", "", "the image point in the picture plane z = 1 (22)", ">16.10g"),
          ("alpha", "rad", "the outer ring's angle", ">16.10g"),
          ("beta", "rad", "the casing's angle", ">16.10g"),
          ("H", "N m s", "the rotor's angular momentum", ">14.9g"))


def motion_result(level: str, params: dict, t, values, seconds: float, base_rate: dict | None):
    """The gyro.results.Motion of one level: `values` (times, 5) the SERIES; `base_rate` the
    command line's {u_NAME: [{amplitude, frequency, phase}, ...]} of a time-varying base
    (the JSON's `base_rate` and the table's lines), None for a constant one."""
    from gyro.results import Motion

    names, units, descriptions, formats = (list(c) for c in zip(*SERIES))
    heading = [f"gimbal gyroscope on a rotating base ({MODEL}), level {level}"]
    for name, terms in (base_rate or {}).items():
        waves = " + ".join(f"{o['amplitude']:g} sin({o['frequency']:g} t + {o['phase']:g})" for o in terms)
        heading.append(f"base rate {name}(t) = {name} + {waves} rad/s")
    info = {"level": level, "params": params, "seconds": seconds, "base_rate": base_rate}
    keys = ["model", "level", "params", "t", *names, "seconds"] + (["base_rate"] if base_rate is not None else [])
    return Motion(MODEL, "gimbal gyroscope on a rotating base", level, t, names, values, units, descriptions,
                  info=info, keys=keys, heading=heading, formats={"t": ">12.6g", **dict(zip(names, formats))},
                  path=["x", "y"])


def image_error(a, b) -> float:
    """The error measure of the motion question: max over t of |P_a - P_b| (the image
    points) relative to the largest displacement of P_b from its start, max |P_b(t) - P_b(0)|.
    NaN where P_b does not move (no scale)."""
    d = np.hypot(a.x - b.x, a.y - b.y).max()
    scale = np.hypot(b.x - b.x[0], b.y - b.y[0]).max()
    return float(d / scale) if scale > 0 else float("nan")




# ----------------------------------------------------------------------------- the levels' bounds
#
# Each level's error against `full`, enclosed along the level's own motion (docs/precession.md,
# "The bound of each level", the derivation step by step). In s = (alpha, beta, H) and the
# full level's angle rates v, the full equations are exactly (the phi row eliminated: H is
# the rotor's axial momentum, H' = g(s, v) in every level)
#     Mr(q) v' + hrest(s, v) + Kg(s) v - cg(s) = 0,    H' = g(s, v),
# Mr the rings' and the rotor's transverse inertia (the Schur complement of the mass matrix
# on phi), Kg v - cg the rows alpha, beta of (12) (Kg = H cos(beta) times a rotation plus
# the friction's symmetric part), hrest the rest of the Lagrange terms of the rings and the
# rotor's transverse momentum (the outer ring's (C2 - C1) w_eta1 w_zeta1 among them). The
# precession (13) is Kg f = cg: s' = Phi(s) = (f(s), g(s, f(s))). With w = v - f(s) and
# B(s) = (I; dg/dv), s' = Phi(s) + B w exactly, and
# - the energy of w: d/dt (w.Mr w/2) = -w.rho0(s) + w.Q(s) w exactly (no cubic term: the
#   Lagrangian's structure; rho0 = hrest(s, f) + Mr Df Phi, the residual of the full
#   equations along the precession's vector field), so |w|_Mr <= W, W' = lambda W +
#   |rho0|_Mr^-1, lambda the largest eigenvalue of Q against Mr (the friction in Q: < 0);
# - the momentum: Kg w = -(Mr v' + hrest), so with P = Kg^-1 Mr v the slow variable z = s +
#   B P moves at z' = Phi(s) + sigma(s, v), sigma = B' P + B ((Kg^-1 Mr)' v - Kg^-1 hrest),
#   quadratic in v: no v' in it (the nutation is inside W);
# - z - s_l (s_l the level's motion, s_l' = Phi(s_l) - d_l, d_l its rates' difference from
#   (13) at its own state: 0 for rigorous and image) in the metric G = diag(cos beta_l, 1,
#   1/H0) (the spin axis on the unit sphere, the momentum relative): E' = mu E + L |G B P|
#   + |G sigma| + |G d_l|, E(0) = |G B P(0)| (full starts on (13): w(0) = 0), mu the
#   logarithmic norm of G DPhi G^-1 + G' G^-1 over the tube, L the norm of G DPhi G^-1;
# - the error s - s_l within E + |G B P| on the sphere, the image point within rho^2 of it.
# Every constant is the largest over the tube |G (s - s_l)| <= r about the level's motion,
# over each step of the bound's grid, ENCLOSED (gyro/intervals.py, `_enclosed_constants`): the
# level's motion over a step is held in a box by an a priori enclosure (`_level_boxes`: if
# s_k + [0, h] R(X) lies in X, R the level's rates over X, the motion stays in X); the full
# state in that box widened by r / G_j per axis; the tube function (every piece the
# constants need) evaluated in interval arithmetic over both boxes, outward rounded (the
# cancelling residuals rho1, eta, sigma also by the centred form f(c) + J(X)(X - c)); the
# constants from the interval matrices by closed forms (2 x 2 eigenvalues), Weyl's bound
# with a verified eigenvalue of the midpoint, and norms of the entrywise magnitudes. No
# sampled allowance, no floor. The radius is closed by a bootstrap: the bound computed with
# the constants of radius r must come out below r, else r is raised; a tube that reaches
# beta or alpha = +-90 deg, a step's motion not enclosed, or no closing within BOOTSTRAP
# tries: the level refuses (the bound is infinite). Where the bound is far from the
# samples' guess and a step's box is wider than the tube, the grid is refined (REFINE).
# The integrator's term: the answer (Adams, rtol 1e-12) against an independent method (BDF
# with Newton's iteration, same tolerance) and against Adams 100x looser, twice the larger.

LOOSE = 100.0
INTEGRATION_SAFETY = 2.0
PER_RADIAN = 20  # samples of the bound's grid per radian of the fastest frame rate
MAX_SAMPLES = 50_000  # a motion that needs more: the bound is not evaluated (infinite; the intervals' cost)
MIN_SAMPLES = 401  # the bound's grid has at least these
REFINE = (1, 4)  # the bound's grid: these times finer in turn, while the bound is far from its guess
REFINE_CLOSE = 2.0  # a bound within this factor of the samples' guess: no finer grid
REFINE_MAX_SAMPLES = 5_000  # a refined grid no longer than this (its cost)
REFINE_INF = 1e-3  # a refused set is tried on a finer grid only where its guess is below this of the limit
BOOTSTRAP = 6  # tries to close the tube's radius
TUBE_GROWTH = 2.0  # a try that does not close raises the radius to this times its bound

def _scale(m) -> float:
    return float(np.hypot(m.x - m.x[0], m.y - m.y[0]).max())


def _solve_rows(A, b):
    return np.linalg.solve(A, b[..., None])[..., 0]


def _rigorous(P, alpha, beta, H):
    nf = load(MODEL).numpy
    A, b = nf.rigorous_system(P, np.stack([alpha, beta], axis=-1), H[:, None])
    return _solve_rows(A, b)


def _image_to_angle_rates(x, y, dx, dy):
    """d(alpha, beta)/dt of an image point moving at (dx, dy): alpha = -atan(y), beta =
    atan(x/sqrt(1 + y^2))."""
    r2 = 1 + y**2
    s = x / np.sqrt(r2)
    ds = dx / np.sqrt(r2) - x * y * dy / r2**1.5
    return -dy / r2, ds / (1 + s**2)


@lru_cache(maxsize=1)
def _split():
    """The CasADi pieces of the full equations at a state s = (alpha, beta, H) and angle
    rates v (see above): (p, s, v, Mr, hrest, Kg, cg, g), from the generated mass matrix,
    forcing, spin_from_momentum and virtual_power_system."""
    import casadi as ca

    cf = load(MODEL).casadi
    p = ca.SX.sym("p", len(load(MODEL).param_names))
    s, v = ca.SX.sym("s", 3), ca.SX.sym("v", 2)
    ang, H = s[:2], s[2]
    q3 = ca.vertcat(ang, 0)  # phi is cyclic
    M3 = cf.mass_matrix(p, q3)
    F3 = cf.forcing(p, q3, ca.vertcat(v, cf.spin_from_momentum(p, ang, v, H)))
    Mr = M3[:2, :2] - M3[:2, 2] @ M3[2, :2] / M3[2, 2]  # the phi row eliminated (phi'' from it)
    N = -(F3[:2] - M3[:2, 2] * F3[2] / M3[2, 2])  # full: Mr v' + N(s, v) = 0
    A12, b12 = cf.virtual_power_system(p, ang, H)
    g = (b12[2] - A12[2, :2] @ v) / A12[2, 2]  # H' from the phi row of (12): the full level's too
    prec = -(A12[:2, :2] @ v + A12[:2, 2] * g - b12[:2])  # the rows alpha, beta of (12), as in N
    Kg = ca.jacobian(prec, v)
    cg = -ca.substitute(prec, v, ca.DM.zeros(2))
    return p, s, v, Mr, N - prec, Kg, cg, g


@lru_cache(maxsize=1)
def _expressions() -> dict:
    """The enclosure's pieces as CasADi expressions of the parameters p, the state s and a
    rate deviation w (or om = w - eta, the symbol o): Phi, DPhi, f, eta, rho1, Q, Mr, B Kg^-1
    Mr, D pi, sigma at v = f + w, and the energy rate of om (a polynomial of degree 2 in o:
    the Lagrangian's cubic terms cancel; tests check it)."""
    import casadi as ca

    p, s, v, Mr, hrest, Kg, cg, g = _split()
    f = ca.solve(Kg, cg)
    Phi = ca.vertcat(f, ca.substitute(g, v, f))
    DPhi = ca.jacobian(Phi, s)
    Df = DPhi[:2, :]
    w, o = ca.SX.sym("w", 2), ca.SX.sym("o", 2)
    vw = f + w
    sdot = ca.vertcat(vw, ca.substitute(g, v, vw))  # s' of the full motion at v = f + w
    rho0 = ca.substitute(hrest, v, f) + Mr @ Df @ Phi  # the full equations' residual along Phi
    eta = -ca.solve(Kg, rho0)  # w's slow part: the first-order rate defect
    # d/dt (om.Mr om/2) along the full equations, om = w - eta: Mr v' = -N(s, v), w' = v' - Df s'
    wdot = ca.solve(Mr, -ca.substitute(hrest + Kg @ v - cg, v, vw)) - Df @ sdot
    om = w - eta
    energy = ca.substitute(om.T @ ca.jtimes(Mr, s, sdot) @ om / 2 + om.T @ Mr @ (wdot - ca.jtimes(eta, s, sdot)),
                           w, eta + o)
    B = ca.vertcat(ca.DM.eye(2), ca.jacobian(g, v))
    KiM = ca.solve(Kg, Mr)
    sigma = (ca.jtimes(B, s, sdot) @ KiM @ vw + B @ (ca.jtimes(KiM, s, sdot) @ vw
                                                      - ca.solve(Kg, ca.substitute(hrest, v, vw))))
    return {"p": p, "s": s, "w": w, "o": o, "Phi": Phi, "DPhi": DPhi, "f": f, "eta": eta, "energy": energy, "rho0": rho0,
            "Mr": Mr, "BKM": B @ KiM, "Dpi": ca.jacobian(B @ KiM @ f, s), "sigma": sigma}


@lru_cache(maxsize=1)
def _tube_function():
    """A CasADi Function of (p, s) giving, stacked in one column, what the enclosure needs at
    a state s: Phi (3), DPhi (3x3), rho1 (2), Q (2x2), Mr (2x2), eta (2), B Kg^-1 Mr (3x2),
    D pi (3x3) (pi = B Kg^-1 Mr f, the nutation's centre), sigma(s, f) (3), d sigma/dw (3x2),
    d2 sigma/dw2 (3 of 2x2)."""
    import casadi as ca

    e = _expressions()
    w, o, sigma, energy = e["w"], e["o"], e["sigma"], e["energy"]
    rho1 = -ca.gradient(energy, o)
    Q = ca.hessian(energy, o)[0] / 2
    s1 = ca.jacobian(sigma, w)
    s2 = [ca.hessian(sigma[i], w)[0] for i in range(3)]
    outs = [e["Phi"], e["DPhi"], rho1, Q, e["Mr"], e["eta"], e["BKM"], e["Dpi"], sigma, s1, *s2, e["rho0"]]
    outs = [ca.substitute(ca.substitute(ca.vec(x), w, ca.DM.zeros(2)), o, ca.DM.zeros(2)) for x in outs]
    return ca.Function("precession_tube", [e["p"], e["s"]], [ca.vertcat(*outs)], {"cse": True})


def _at(values: dict, S: np.ndarray) -> dict:
    """The tube function at the states S (n, 3), unpacked (each (n, ...))."""
    return _unpack(np.array(_tube_function()(vector(values), S.T)).T)


def _norm2(A):
    return np.linalg.norm(A, ord=2, axis=(-2, -1))


def _constants(c: dict, Gd: np.ndarray, Gdot: np.ndarray, kappa: np.ndarray) -> dict:
    """The enclosure's constants from the tube function's values c (`_at`) at n states, in
    the metric diag(Gd) (n, 3) with G' G^-1 = diag(Gdot), kappa (n, 3) the drift of the
    nutation's centre along the level's motion: each a number per state."""
    Mr = c["Mr"]
    Li = np.linalg.inv(np.linalg.cholesky(Mr))
    Qs = (c["Q"] + np.transpose(c["Q"], (0, 2, 1))) / 2
    GD = Gd[:, :, None] * c["DPhi"] / Gd[:, None, :]
    Wsym = (GD + np.transpose(GD, (0, 2, 1))) / 2 + np.einsum("ni,ij->nij", Gdot, np.eye(3))
    return {"lam": np.linalg.eigvalsh(Li @ Qs @ np.transpose(Li, (0, 2, 1)))[:, -1],
            "rho": np.linalg.norm(np.einsum("nij,nj->ni", Li, c["rho1"]), axis=-1),  # |rho1|_Mr^-1
            "rho0": np.linalg.norm(np.einsum("nij,nj->ni", Li, c["rho0"]), axis=-1),  # its floor's scale
            "eta": np.linalg.norm(c["eta"], axis=-1), "eta_M": np.sqrt(np.einsum("ni,nij,nj->n", c["eta"], Mr, c["eta"])),
            "mmin": np.linalg.eigvalsh(Mr)[:, 0], "mu": np.linalg.eigvalsh(Wsym)[:, -1], "L": _norm2(GD),
            "PK": _norm2(Gd[:, :, None] * c["BKM"]), "Lpi": _norm2(Gd[:, :, None] * c["Dpi"] / Gd[:, None, :]),
            "chi": np.linalg.norm(Gd * (c["sigma"] - kappa), axis=-1), "s1": _norm2(Gd[:, :, None] * c["s1"]),
            "s2": np.sqrt(np.sum((Gd[:, :, None, None] * c["s2"])**2, axis=(1, 2, 3)))}


def _bound_grid(values: dict, m, factor: int = 1):
    """The level's motion on a grid with PER_RADIAN samples per radian of the fastest frame
    rate (the base's |u| plus the largest |alpha'| + |beta'| of (13) on m), at least
    MIN_SAMPLES, both times `factor` (a refined grid: the level integrated again with those
    output times); m's own samples, thinned, where it is denser; None where that takes more
    than MAX_SAMPLES (REFINE_MAX_SAMPLES for a refined grid)."""
    P = vector(values)
    r3 = _rigorous(P, m.alpha, m.beta, m.H)
    u = float(np.linalg.norm([values[b] for b in BASE]))
    w = u + float(np.max(np.abs(r3[:, 0]) + np.abs(r3[:, 1])))
    n = int(np.ceil(float(m.t[-1]) * w * PER_RADIAN)) + 1
    if factor > 1:
        n = (max(n, MIN_SAMPLES, len(m.t)) - 1) * factor + 1
        if n > REFINE_MAX_SAMPLES:
            return None
    if n > MAX_SAMPLES:
        return None
    if n > len(m.t):
        return simulate(values, np.linspace(0.0, float(m.t[-1]), n), m.level)
    keep = np.unique(np.linspace(0, len(m.t) - 1, max(n, MIN_SAMPLES)).round().astype(int))
    if len(keep) >= len(m.t):
        return m
    return SimpleNamespace(level=m.level, t=m.t[keep], x=m.x[keep], y=m.y[keep], alpha=m.alpha[keep],
                           beta=m.beta[keep], H=m.H[keep])


EDGE = float(np.arccos(SINGULAR_COS))  # a tube past this angle reaches the singularity


@lru_cache(maxsize=4)
def _level_function(level: str):
    """A CasADi Function of (p, s), s = (alpha, beta, H), giving the level's own rates in
    alpha', beta', H' (3) and d_l = Phi(s) - those rates (3): 0 for rigorous and image ((21)
    is (13) in x, y exactly); for small and elementary the difference of (21)'s rates from
    theirs at the same image point, carried to the angle rates (one expression, so that
    its centred interval form sees the cancellation)."""
    import casadi as ca

    cf = load(MODEL).casadi
    e = _expressions()
    p, s = e["p"], e["s"]
    Phi = ca.substitute(ca.substitute(e["Phi"], e["w"], ca.DM.zeros(2)), e["o"], ca.DM.zeros(2))
    if level not in ("small", "elementary"):
        return ca.Function(f"rates_{level}", [p, s], [ca.vertcat(Phi, ca.DM.zeros(3))], {"cse": True})
    xy = cf.image_point(p, s[:2])
    d = ca.solve(*cf.image_system(p, xy, s[2])) - ca.solve(*getattr(cf, f"{level}_system")(p, xy, s[2]))
    x, y = xy[0], xy[1]
    r2 = 1 + y**2
    q = x / ca.sqrt(r2)
    dq = d[0] / ca.sqrt(r2) - x * y * d[1] / (r2 * ca.sqrt(r2))
    dl = ca.vertcat(-d[1] / r2, dq / (1 + q**2), d[2])  # (alpha, beta) of the image point's rates
    return ca.Function(f"rates_{level}", [p, s], [ca.vertcat(Phi - dl, dl)], {"cse": True})


@lru_cache(maxsize=4)
def _level_jacobian(level: str):
    return intervals.jacobian_function(_level_function(level), 1)


def _level_rates(values: dict, level: str, lo, hi):
    """Intervals (lo, hi) of the level's rates and of d_l over the boxes [lo, hi] (n, 3) of
    its state (the centred form: d_l is a small difference of near-equal rates)."""
    P = vector(values)
    (rl, rh), = intervals.centred(_level_function(level), _level_jacobian(level), 1, [(P, P), (lo.T, hi.T)])
    return (rl[:3].T, rh[:3].T), (rl[3:].T, rh[3:].T)


LEVEL_BOX_TRIES = 8  # the a priori enclosure of the level's motion over a step: tries


def _level_boxes(values: dict, g):
    """Per step of the grid g, a box (lo, hi) (n - 1, 3) in (alpha, beta, H) that holds the
    level's motion over the step (the flow from the step's first sample and its last
    sample), and the intervals of its rates and of d_l over it; None where a step's box
    is not found. A priori enclosure: if s_k + [0, h] R(X) lies in X, R(X) the rates'
    interval over X, the flow from s_k stays in X over the step (it cannot leave X first:
    until then its rates are in R(X)). X starts as the hull of the two samples, then
    grows to the candidate found, half as wide again."""
    S = np.stack([g.alpha, g.beta, g.H], axis=-1)
    a, b = S[:-1], S[1:]
    h = intervals.up(np.diff(g.t))[:, None]  # the step lengths, rounded up
    lo = np.minimum(a, b)
    hi = np.maximum(a, b)
    pad = (hi - lo) / 4 + 1e-12 * (1 + np.abs(a))
    lo, hi = lo - pad, hi + pad
    done = np.zeros(len(a), bool)
    for _ in range(LEVEL_BOX_TRIES):
        todo = np.flatnonzero(~done)
        if not todo.size:
            break
        (Rl, Rh), _ = _level_rates(values, g.level, lo[todo], hi[todo])
        ylo = np.minimum(intervals.down(a[todo] + intervals.down(h[todo] * Rl)), a[todo])
        yhi = np.maximum(intervals.up(a[todo] + intervals.up(h[todo] * Rh)), a[todo])
        ylo, yhi = np.minimum(ylo, b[todo]), np.maximum(yhi, b[todo])
        if not (np.all(np.isfinite(ylo)) and np.all(np.isfinite(yhi))):  # rates not enclosed: refused
            return None
        inside = np.all((ylo >= lo[todo]) & (yhi <= hi[todo]), axis=-1)
        good = todo[inside]
        lo[good], hi[good] = ylo[inside], yhi[inside]
        done[good] = True
        bad = todo[~inside]
        grow = (yhi[~inside] - ylo[~inside]) / 4 + 1e-12 * (1 + np.abs(a[bad]))
        lo[bad] = np.minimum(lo[bad], ylo[~inside] - grow)
        hi[bad] = np.maximum(hi[bad], yhi[~inside] + grow)
    if not np.all(done) or not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        return None
    rates_, dl = _level_rates(values, g.level, lo, hi)  # over the box found (the motion is in it)
    return (lo, hi), rates_, dl


_SHAPES = {"Phi": (3,), "DPhi": (3, 3), "rho1": (2,), "Q": (2, 2), "Mr": (2, 2), "eta": (2,), "BKM": (3, 2),
           "Dpi": (3, 3), "sigma": (3,), "s1": (3, 2), "s2": (3, 2, 2), "rho0": (2,)}


def _unpack(col: np.ndarray) -> dict:
    """The tube function's column (n, 62), unpacked by _SHAPES (each (n, ...))."""
    out, k = {}, 0
    for name, shape in _SHAPES.items():
        size = int(np.prod(shape))
        block = col[:, k:k + size]
        if len(shape) == 2:  # CasADi's vec is column-major
            block = block.reshape(-1, shape[1], shape[0]).transpose(0, 2, 1)
        elif len(shape) == 3:
            block = block.reshape(-1, shape[0], shape[2], shape[1]).transpose(0, 1, 3, 2)
        out[name] = block.reshape((-1, *shape))
        k += size
    return out


CANCELLING = (("rho1", "eta", "sigma"), ("Q",))  # small differences of large terms: the centred form's
# (each group one Function: the centred form of one piece depends on the algorithm CasADi
# builds for its group's Jacobian, and Q in the first group widens eta and sigma's)


@lru_cache(maxsize=2)
def _cancelling_function(group: tuple = CANCELLING[0]):
    """The tube function's pieces `group` (rho1: second order; eta and sigma: the first-order
    defect, a residual of the full equations; Q: the energy rate's quadratic form, its terms
    of Mr's change along the motion and the Coriolis moments, which cancel in part), as a
    Function of (p, s), and its Jacobian in s."""
    import casadi as ca

    f = _tube_function()
    p, s = ca.SX.sym("p", f.sparsity_in(0)), ca.SX.sym("s", f.sparsity_in(1))
    col = f(p, s)
    k, pick = 0, []
    for name, shape in _SHAPES.items():
        size = int(np.prod(shape))
        if name in group:
            pick.append(col[k:k + size])
        k += size
    fun = ca.Function("precession_cancelling_" + "_".join(group), [p, s], [ca.vertcat(*pick)], {"cse": True})
    return fun, intervals.jacobian_function(fun, 1)


@lru_cache(maxsize=1)
def _cancelling_hessian():
    """The Hessian in s of the first CANCELLING group (its Jacobian's Jacobian)."""
    return intervals.jacobian_function(_cancelling_function(CANCELLING[0])[1], 1)


def _intersect(L: dict, H: dict, group: tuple, flo, fhi) -> None:
    """The pieces `group` of (L, H) intersected with another enclosure (flo, fhi) of them over
    the first boxes (as many as flo has), stacked as the group's Function stacks them (in the
    tube function's order)."""
    k, m = 0, flo.shape[1]
    for name, shape in _SHAPES.items():
        if name in group:
            size = int(np.prod(shape))
            L[name][:m] = np.maximum(L[name][:m], flo[k:k + size].T.reshape((m, *shape)))
            H[name][:m] = np.minimum(H[name][:m], fhi[k:k + size].T.reshape((m, *shape)))
            k += size


def _tube_intervals(values: dict, lo, hi, rows: int | None = None) -> dict:
    """Each piece of the tube function as an interval (lo, hi) over the boxes [lo, hi]
    (n, 3): for every state in a box, its value is inside (gyro.intervals): the natural
    interval extension, and for the pieces CANCELLING the centred form (f(c) + J(X) (X - c)),
    whose excess is of the square of the box's width where the natural one's is of the width;
    for rho1, eta and sigma also the second-order Taylor form (f(c) + J(c) (X - c) + (X -
    c)^T H(X) (X - c) / 2: their Jacobians cancel too, and J(X) carries the cancelling terms
    times the width); each the intersection of its enclosures. `rows`: those forms over the
    first `rows` boxes only (the others' cancelling pieces are not needed). The Taylor form
    and Q's centred form only with the compiled walker (gyro.intervals.compiled): in NumPy
    they cost 0.4 s a bound, more than `full`; without them the bound is the first-order
    forms' (an enclosure too, refused more often)."""
    P = vector(values)
    (clo, chi), = intervals.evaluate(_tube_function(), [(P, P), (lo.T, hi.T)])
    L, H = _unpack(clo.T), _unpack(chi.T)
    rows = len(lo) if rows is None else rows
    if not rows:
        return {k: (L[k], H[k]) for k in L}
    box = [(P, P), (lo[:rows].T, hi[:rows].T)]
    tight = intervals.compiled()  # in NumPy the Taylor form and Q's centred form would cost more than `full`
    for group in CANCELLING if tight else CANCELLING[:1]:
        fun, jac = _cancelling_function(group)
        _intersect(L, H, group, *intervals.centred(fun, jac, 1, box, natural=False)[0])
    if tight:  # the residuals: also their second-order Taylor form
        fun, jac = _cancelling_function(CANCELLING[0])
        _intersect(L, H, CANCELLING[0], *intervals.taylor2(fun, jac, _cancelling_hessian(), 1, box)[0])
    return {k: (L[k], H[k]) for k in L}


def _imul(a, b):
    return intervals._mul(a, b)


def _matvec(A, x):
    """Interval matrix (n, i, j) times interval vector (n, j): (n, i)."""
    out = None
    for j in range(A[0].shape[-1]):
        t = _imul((A[0][..., j], A[1][..., j]), (x[0][:, None, j], x[1][:, None, j]))
        out = t if out is None else intervals._add(out, t)
    return out


def _scale_rows_cols(G, A, cols=True):
    """G_i A_ij / G_j (or G_i A_ij with cols False) over intervals, G (n, 3) intervals."""
    r = _imul((G[0][:, :, None], G[1][:, :, None]), A)
    if not cols:
        return r
    return intervals._div(r, (G[0][:, None, :], G[1][:, None, :]))


def _enclosed_constants(values: dict, box, rates_, dl, r: float, start) -> dict:
    """The enclosure's constants (docs/precession.md, steps 2-4) over each step: the largest
    (for mmin the smallest) over every time of the step and every state of the tube
    |G (s - s_l)| <= r about it, from interval evaluations: the level's box `box` (n - 1, 3)
    for G, G' G^-1 and kappa = D pi(s_l) s_l', the box widened by r / G_j per axis (G_j's
    smallest over the step) for the full state's pieces. Each a number per step; "W0" an
    upper bound of Omega(0) = |eta(s(0))|_Mr at the start `start` (1, 3), a point."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # inf and NaN mean refused, below
        return _enclosed_constants_of(values, box, rates_, dl, r, start)


def _enclosed_constants_of(values: dict, box, rates_, dl, r: float, start) -> dict:
    iv = intervals
    lo, hi = box
    H0 = abs(float(values["H"]))
    cb = iv._fabs(iv._cos((lo[:, 1], hi[:, 1])))  # |cos beta_l| over the step
    if not np.all(cb[0] > 0):
        return None
    n = len(lo)
    ones = np.ones(n)
    inv_h = (iv.down(1 / H0) * ones, iv.up(1 / H0) * ones)
    G = (np.stack([cb[0], ones, inv_h[0]], -1), np.stack([cb[1], ones, inv_h[1]], -1))
    reach = np.stack([iv.up(r / cb[0]), np.full(n, r), np.full(n, iv.up(r * H0))], -1)
    # the cancelling pieces' centred and Taylor forms over the tube only: of the level's box
    # only D pi is used (kappa), of the start (a point) eta and Mr
    both = _tube_intervals(values, np.vstack([iv.down(lo - reach), lo, start]), np.vstack([iv.up(hi + reach), hi, start]),
                           rows=n)
    tube = {k: (x[0][:n], x[1][:n]) for k, x in both.items()}
    own = {k: (x[0][n:2 * n], x[1][n:2 * n]) for k, x in both.items()}
    at0 = {k: (x[0][2 * n:], x[1][2 * n:]) for k, x in both.items()}
    # G' G^-1 = diag(-tan(beta_l) beta_l', 0, 0); kappa = D pi(s_l) s_l' (the level's own rates)
    gdot = iv._neg(_imul(iv._tan((lo[:, 1], hi[:, 1])), (rates_[0][:, 1], rates_[1][:, 1])))
    kappa = _matvec(own["Dpi"], rates_)

    Mr, Q = tube["Mr"], tube["Q"]
    m11, m22 = (Mr[0][:, 0, 0], Mr[1][:, 0, 0]), (Mr[0][:, 1, 1], Mr[1][:, 1, 1])
    m12 = (np.maximum(Mr[0][:, 0, 1], Mr[0][:, 1, 0]), np.minimum(Mr[1][:, 0, 1], Mr[1][:, 1, 0]))  # Mr symmetric
    q11, q22 = (Q[0][:, 0, 0], Q[1][:, 0, 0]), (Q[0][:, 1, 1], Q[1][:, 1, 1])
    q12 = iv._mul(iv._add((Q[0][:, 0, 1], Q[1][:, 0, 1]), (Q[0][:, 1, 0], Q[1][:, 1, 0])), (0.5, 0.5))
    det_m = iv._sub(iv._mul(m11, m22), iv._sq(m12))
    Msym = (np.stack([np.stack([m11[0], m12[0]], -1), np.stack([m12[0], m22[0]], -1)], -2),
            np.stack([np.stack([m11[1], m12[1]], -1), np.stack([m12[1], m22[1]], -1)], -2))
    mmin = iv.lambda_min_lower(*Msym)
    # lambda: the largest root of det(Q - lambda Mr) = 0, det(Mr) l^2 - bq l + det(Q) = 0
    bq = iv._sub(iv._add(iv._mul(q11, m22), iv._mul(q22, m11)), iv._twice(iv._mul(q12, m12)))
    disc = iv._sub(iv._sq(bq), iv._mul((4.0, 4.0), iv._mul(det_m, iv._sub(iv._mul(q11, q22), iv._sq(q12)))))
    disc = (np.maximum(disc[0], 0.0), disc[1])  # real roots: the true discriminant is >= 0
    lam = iv._div(iv._add(bq, iv._sqrt(disc)), iv._twice(det_m))[1]
    # |rho1|_Mr^-1 = sqrt(rho1.adj(Mr) rho1 / det Mr)
    r1, r2 = (tube["rho1"][0][:, 0], tube["rho1"][1][:, 0]), (tube["rho1"][0][:, 1], tube["rho1"][1][:, 1])
    quad = iv._add(iv._sub(iv._mul(m22, iv._sq(r1)), iv._twice(iv._mul(m12, iv._mul(r1, r2)))), iv._mul(m11, iv._sq(r2)))
    rho = iv.up(np.sqrt(np.maximum(iv._div(quad, det_m)[1], 0.0)))
    rho = np.where(det_m[0] > 0, rho, np.inf)

    GD = _scale_rows_cols(G, tube["DPhi"])
    Wlo = (GD[0] + np.swapaxes(GD[0], 1, 2)) / 2
    Whi = (GD[1] + np.swapaxes(GD[1], 1, 2)) / 2
    Wlo, Whi = iv.down(Wlo), iv.up(Whi)
    Wlo[:, 0, 0] = iv.down(Wlo[:, 0, 0] + gdot[0])
    Whi[:, 0, 0] = iv.up(Whi[:, 0, 0] + gdot[1])
    sig = iv._sub(tube["sigma"], kappa)
    dlG = _imul(G, dl)
    return {"lam": lam, "rho": rho, "mmin": mmin,
            "eta": iv.norm_upper(iv.mag(tube["eta"]), (1,)),
            "mu": iv.lambda_max_upper(Wlo, Whi), "L": iv.norm2_upper(iv.mag(GD)),
            "PK": iv.norm2_upper(iv.mag(_scale_rows_cols(G, tube["BKM"], cols=False))),
            "Lpi": iv.norm2_upper(iv.mag(_scale_rows_cols(G, tube["Dpi"]))),
            "chi": iv.norm_upper(iv.mag(_imul(G, sig)), (1,)),
            "s1": iv.norm2_upper(iv.mag(_scale_rows_cols(G, tube["s1"], cols=False))),
            "s2": iv.norm_upper(iv.mag(_imul((G[0][:, :, None, None], G[1][:, :, None, None]), tube["s2"])), (1, 2, 3)),
            "dl": iv.norm_upper(iv.mag(dlG), (1,)), "W0": _energy_norm(at0["eta"], at0["Mr"])}


def _constants_at(values: dict, level: str, SL: np.ndarray, S: np.ndarray, own_l: dict | None = None,
                  own: dict | None = None) -> dict:
    """The constants at the level's states SL (n, 3) (its metric G, G' G^-1, kappa, d_l) and
    the full states S (n, 3) (the tube's pieces), points: what `_enclosed_constants` holds
    over a step's box and its tube; `own_l`, `own` the tube function at SL, S if at hand."""
    P, H0 = vector(values), abs(float(values["H"]))
    own_l = _at(values, SL) if own_l is None else own_l
    own = _at(values, S) if own is None else own
    out = np.array(_level_function(level)(P, SL.T)).T
    rate, dl = out[:, :3], out[:, 3:]
    cb = np.cos(SL[:, 1])
    Gd = np.stack([np.abs(cb), np.ones_like(cb), np.full_like(cb, 1 / H0)], -1)
    Gdot = np.stack([-np.tan(SL[:, 1]) * rate[:, 1], np.zeros_like(cb), np.zeros_like(cb)], -1)
    c = _constants(own, Gd, Gdot, np.einsum("nij,nj->ni", own_l["Dpi"], rate))
    c["dl"] = np.linalg.norm(Gd * dl, axis=-1)
    return c


def _point_constants(values: dict, g, own: dict) -> dict:
    """The constants at the grid's samples (no tube), per step the larger end (the smaller
    for mmin): a first guess of the tube's radius only, never a bound."""
    S = np.stack([g.alpha, g.beta, g.H], axis=-1)
    c = _constants_at(values, g.level, S, S, own, own)
    return {k: np.maximum(v[:-1], v[1:]) if k != "mmin" else np.minimum(v[:-1], v[1:]) for k, v in c.items()}


def _energy_norm(eta, Mr) -> float:
    """An upper bound of sqrt(eta.Mr eta) over one box's intervals (1, 2), (1, 2, 2)."""
    q = None
    for i in range(2):
        for j in range(2):
            t = _imul(_imul((eta[0][:, i], eta[1][:, i]), (Mr[0][:, i, j], Mr[1][:, i, j])), (eta[0][:, j], eta[1][:, j]))
            q = t if q is None else intervals._add(q, t)
    return float(intervals.up(np.sqrt(max(float(q[1][0]), 0.0))))


ROUNDING_GROWTH = 32  # the recurrences' floating-point error: (1 + eps)^(32 n) over n steps (below)


def _propagate(c: dict, h: np.ndarray, W0: float, limit: float, rigorous: bool):
    """Steps 2-4 integrated as upper solutions over the grid with the per-step constants c:
    the largest |G (s - s_l)| over the horizon (inf where it reaches `limit`, overflows, or
    mmin <= 0 or l_pi >= 1). With `rigorous`, the result is raised by (1 + eps)^(32 n) - 1
    relative: the exponents, 1/(1 - l_pi) and sqrt(m) are rounded outward, and every other
    quantity of the loop is >= 0, with fewer than 32 roundings per step (each at most eps
    relative) on the way to the next."""
    if not all(np.all(~np.isnan(x)) for x in c.values()) or not (np.all(c["mmin"] > 0) and np.all(c["Lpi"] < 1)):
        return float("inf")
    E = worst = 0.0
    W = W0
    up, down = intervals.up, intervals.down
    k1 = up(1 / down(1 - c["Lpi"]))
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused below, not warned
        # the exponents rounded up (mu may be negative: a signed sum), the rest nonnegative
        gl = up(np.exp(up(c["lam"] * h)), intervals.TRANSCENDENTAL_ULPS)
        gm = up(np.exp(up(up(c["mu"] + up(up(c["L"] * c["Lpi"]) * k1)) * h)), intervals.TRANSCENDENTAL_ULPS)
        sq = down(np.sqrt(c["mmin"]))
        for k in range(len(h)):
            Wsup = (W + h[k] * c["rho"][k]) * max(1.0, gl[k])  # |w|_Mr over the step
            W = W * gl[k] + h[k] * c["rho"][k] * max(1.0, gl[k])
            wmax = c["eta"][k] + Wsup / sq[k]  # |w| <= |eta| + |om| over the step
            F = (c["L"][k] * c["PK"][k] * k1[k] * wmax + c["s1"][k] * wmax + c["s2"][k] * wmax**2 / 2
                 + c["chi"][k] + c["dl"][k])
            Esup = (E + h[k] * F) * max(1.0, gm[k])
            E = E * gm[k] + h[k] * F * max(1.0, gm[k])
            here = (Esup + c["PK"][k] * wmax) * k1[k]  # |G (s - s_l)| over the step
            if not here < limit:  # an overflow (inf, or inf * 0), or past the limit: no enclosure worth offering
                return float("inf")
            worst = max(worst, here)
    if rigorous:
        worst *= 1 + ROUNDING_GROWTH * (len(h) + 1) * 2 * intervals.EPS
    return worst if worst < limit else float("inf")


def _image_bound(g, box, worst: float) -> float:
    """Step 5: the image point's error from the largest |G e| over the horizon, over each
    step's box of the level's state: the arc on the sphere within max(1, cos beta /
    |cos beta_l|) |G e|, the image point within rho^2 = 1/(cos alpha cos beta)^2 of it;
    inf where the tube reaches +-90 deg. Rounded up: the cosines within 1e-12 relative
    (a few roundings, each far below, where |cos| >= 1e-3)."""
    lo, hi = box
    aa = np.maximum(np.abs(lo[:, 0]), np.abs(hi[:, 0]))
    ba = np.maximum(np.abs(lo[:, 1]), np.abs(hi[:, 1]))
    bmin = np.where(lo[:, 1] * hi[:, 1] <= 0, 0.0, np.minimum(np.abs(lo[:, 1]), np.abs(hi[:, 1])))
    cbl = np.cos(ba) * (1 - 1e-12)  # the smallest |cos beta_l| over the step
    if np.any(ba + worst >= EDGE) or np.any(cbl <= SINGULAR_COS) or np.any(aa + worst / cbl >= EDGE):
        return float("inf")
    cos_b = np.cos(np.maximum(bmin - worst, 0.0)) * (1 + 1e-12) / cbl
    c_far = np.cos(aa + worst / cbl) * np.cos(ba + worst) * (1 - 1e-12)
    if np.any(c_far <= SINGULAR_COS):
        return float("inf")
    return float(np.max(np.maximum(1.0, cos_b) / c_far**2) * worst * (1 + 1e-12))


def _guess(values: dict, g, own: dict, limit: float = np.inf) -> float:
    """The largest |G (s - s_l)| with the constants at the grid's samples and no tube: the
    first radius of the bootstrap, never a bound; `own` the tube function at the samples."""
    c = _point_constants(values, g, own)
    W0 = float(np.sqrt(own["eta"][0] @ own["Mr"][0] @ own["eta"][0]))
    return _propagate(c, np.diff(g.t), W0, limit, rigorous=False)


def model_error(values: dict, m, limit: float = np.inf, negligible: float = 0.0) -> float:
    """The enclosure of the largest |P_level - P_full| over the horizon (absolute; the
    derivation above); inf where the level refuses: the level's motion over a step is not
    enclosed, the tube does not close within BOOTSTRAP tries, reaches +-90 deg, or the grid
    would be too fine; inf also where a try's bound reaches `limit` (a bound no use: the
    caller's relative bound would be >= 1). On the grid of PER_RADIAN samples per radian, then
    on grids REFINE times finer where a step's box is wider than the tube (the intervals'
    excess falls as the square of a step's width; where the tube's radius is the wider, a
    finer grid does not help) and the bound is above REFINE_CLOSE times the samples' guess
    and above `negligible` (what the caller adds anyway: the integrator's floor), or infinite
    while the guess is below REFINE_INF times `limit`. Every bound found is an enclosure; the
    smallest is returned."""
    best = float("inf")
    for factor in REFINE:
        g = _bound_grid(values, m, factor)
        if g is None:
            break
        bound_, guess, wide = _model_error_on(values, g, min(limit, best))
        best = min(best, bound_)
        if not (np.isfinite(guess) and wide) or best <= max(REFINE_CLOSE * guess, negligible):
            break
        if not np.isfinite(best) and not guess < REFINE_INF * limit:
            break
    return best


def _model_error_on(values: dict, g, limit: float):
    """(the enclosure on the grid g, the guess's image bound, whether a step's box is wider
    than the guessed tube in alpha or beta): the first radius is a guess
    from the constants at the samples; each try's constants are enclosed over the tube of
    that radius (`_enclosed_constants`), and the tube is closed where the bound they give is
    below it."""
    inf = float("inf")
    own = _at(values, np.stack([g.alpha, g.beta, g.H], axis=-1))
    guess = _guess(values, g, own, limit)
    if not np.isfinite(guess):
        return inf, inf, False
    lb = _level_boxes(values, g)
    if lb is None:
        return inf, inf, False
    box, rates_, dl = lb
    guess_image = _image_bound(g, box, guess)
    r = TUBE_GROWTH * guess + 1e-300
    wide = bool(np.max(box[1][:, :2] - box[0][:, :2]) > r)
    h = intervals.up(np.diff(g.t))
    start = np.array([[g.alpha[0], g.beta[0], g.H[0]]])
    for _ in range(BOOTSTRAP):
        if np.any(np.maximum(np.abs(box[0][:, 1]), np.abs(box[1][:, 1])) + r >= EDGE):
            return inf, guess_image, wide
        c = _enclosed_constants(values, box, rates_, dl, r, start)
        if c is None:
            return inf, guess_image, wide
        worst = _propagate(c, h, c.pop("W0"), limit, rigorous=True)
        if not np.isfinite(worst):
            return inf, guess_image, wide
        if worst < r:  # closed: the tube of radius r holds the full motion over the horizon
            return _image_bound(g, box, worst), guess_image, wide
        r = TUBE_GROWTH * worst
    return inf, guess_image, wide


def _integration_floor(m) -> float:
    """The integration term's floor (its tolerance on the angles carried to the image point,
    times INTEGRATION_SAFETY): the least the bound adds to the model's term."""
    return INTEGRATION_SAFETY * float(np.max((1 + m.x**2 + m.y**2) * (RTOL * (np.abs(m.alpha) + np.abs(m.beta)) + ATOL)))


def integration_error(values: dict, m) -> float:
    """INTEGRATION_SAFETY times the largest of: the difference of the answer (Adams, rtol
    1e-12) from BDF at the same tolerance, from Adams at a LOOSE times looser one, and the
    integrator's own tolerance on the angles carried to the image point, rho^2 (RTOL (|alpha|
    + |beta|) + ATOL) (absolute): where the motion is small against the angles (a moment of
    1e-12 N m) every run agrees with the others to the last bit and none is more accurate than
    its tolerance on the state."""
    d = _integration_floor(m) / INTEGRATION_SAFETY
    for other in (simulate(values, m.t, m.level, multistep="bdf"), simulate(values, m.t, m.level, rtol_scale=LOOSE)):
        d = max(d, float(np.hypot(m.x - other.x, m.y - other.y).max()))
    return INTEGRATION_SAFETY * d


def bound(values: dict, m) -> float:
    """The relative error bound of motion m (one level's) against `full` (see above),
    relative to the exact motion's excursion: an absolute bound b E on the level's
    excursion E is b/(1 - b) of the exact one's, which is at least E (1 - b) (both start
    at the same point); infinite from b = 1."""
    scale = _scale(m)
    if not scale > 0:
        return float("inf")
    model = 0.0 if m.level == "full" else model_error(values, m, limit=scale, negligible=_integration_floor(m))
    if not model / scale < 1:  # no bound: the integrator's runs are not needed
        return float("inf")
    b = (model + integration_error(values, m)) / scale
    return b / (1 - b) if b < 1 else float("inf")


INITIAL: dict = {}  # the initial state is the parameters' (alpha0, beta0, H): no extra conditions


class Motion:
    """The motion question's input (gyro/questions/motion.py): a parameter set by the model's names."""

    def __init__(self, params: dict):
        self.params = params


def motion_answer(motion: Motion, t, method: str, rtol: float = RTOL):
    """The motion question's evaluator: the image point x, y at the times t (times, 2) and the
    level's bound as an absolute error of each (its relative bound times the motion's largest
    excursion, the scale the evaluator declares). Singular (a ValueError) where the motion
    reaches beta or alpha = +-90 deg."""
    m = simulate(motion.params, np.asarray(t, float), method)
    b = bound(motion.params, m)
    ex = _scale(m)
    return np.stack([m.x, m.y], axis=-1), np.full(2, b * ex)


# ------------------------------------------------------------------ gyro simulate

def simulate_command(model, args, cli):
    """`gyro simulate gimbal_precession --level LEVEL` (the model's `simulate` declaration):
    every input checked first (names, numbers, --level, --base-rate, --t-end, --points,
    --out, the initial angles away from +-90 deg), then integrated by the level. Returns
    the PrecessionMotion."""
    if args.level is None:
        raise ParameterError(f"--level: required for {MODEL}; one of {', '.join(LEVELS)}")
    if args.level not in LEVELS:
        raise ParameterError(f"--level: unknown level {args.level!r}; known: {', '.join(LEVELS)}")
    values = parameters(cli.sets(args.set))
    terms = [_base_rate_item(item) for item in args.base_rate or []]
    base = oscillating_base(values, terms) if terms else None
    t = cli.times(args)
    cli.png(args.out)
    initial_state(args.level, values, base)  # the initial angles away from +-90 deg
    return simulate(values, t, args.level, base=base)


def _base_rate_item(item: str) -> Oscillation:
    """One --base-rate NAME=AMP:FREQ[:PHASE] as an Oscillation, or ParameterError naming it."""
    label = f"--base-rate {item!r}"
    name, sep, spec = item.partition("=")
    parts = spec.split(":")
    if not sep or not name.strip() or len(parts) not in (2, 3):
        raise ParameterError(f"{label}: expected NAME=AMP:FREQ[:PHASE] (NAME xi, eta or zeta)")
    return oscillation(name.strip(), *parts, what=label)
