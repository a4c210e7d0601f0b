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

import numpy as np

from gyro import ode
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
# Each level's error against `full`, estimated along the level's own motion (docs/precession.md,
# "The bound of each level"):
# - the defect: the rates of the full equations minus the level's at each state of the level's
#   motion, to first order. The full equations' residual R = Mq q'' - f along the motion (q'
#   from (13), q'' by differences on a grid fine enough for the motion's fastest frame rate)
#   is exactly the moment of what the precession theory neglects (the rings' inertia with
#   the outer ring's (C2 - C1) w_eta1 w_zeta1, the rotor's transverse momentum), since the
#   motion satisfies (12) with the momentum H e_z' alone; the full rates differ from (12)'s by
#   A12^-1 R (A12 the matrix of (12) in alpha', beta', H': the sec(beta) by which a moment
#   about the outer axis turns the casing). `small` and `elementary` add their rates' difference
#   from (21) at the same state. The defect is measured as the spin axis's rate on the unit
#   sphere (cos(beta) d alpha', d beta') and d H'/H0;
# - the defect carried along the level's flow: e' <= mu(t) e + |d(t)|, mu the logarithmic norm
#   of the flow's Jacobian in the same measure (a rotation of the base is an isometry of the
#   sphere: mu = 0 for it); the image point's error is rho^2 e (the gnomonic projection's
#   radial scale), the largest over the horizon;
# - the nutation: the precession is the slow motion only while the frames' rates are small
#   against H |cos(beta)|/J (J the sum of the transverse moments, a lower bound of the
#   nutation frequency's); above NUTATION_RATIO the bound is infinite (the level refuses);
#   below it, the nutation a rate defect d excites, at most 2 |d| J/(H |cos beta|) off the
#   drift (a cycloid), is added to e (it matters where the horizon is a few nutation periods);
# - the integrator: the answer (Adams, rtol 1e-12) against an independent method (BDF with
#   Newton's iteration, same tolerance) and against Adams 100x looser, twice the larger.
# The model term is SAFETY times the first-order estimate; relative to the motion's largest
# excursion from its start.

SAFETY = 2.0
LOOSE = 100.0
INTEGRATION_SAFETY = 2.0
PER_RADIAN = 20  # samples of the bound's grid per radian of the fastest frame rate (q'' by differences)
MAX_SAMPLES = 200_000  # a motion that needs more: the bound is not evaluated (infinite)
NUTATION_RATIO = 0.1  # (|u| + |alpha'| + |beta'|) J/(H |cos beta|) above it: no precession level answers


def _scale(m) -> float:
    return float(np.hypot(m.x - m.x[0], m.y - m.y[0]).max())


def transverse_inertia(values: dict) -> float:
    """J: the sum of every moment of inertia besides the rotor's momentum, the largest any
    axis of the gimbal can have (the nutation frequency is at least H |cos beta|/J)."""
    return sum(float(values[k]) for k in ("C1", "C2", "C3", "B1", "B2", "B3", "A1", "A1", "A3"))


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


def defect(values: dict, m) -> np.ndarray:
    """(n, 3): the full rates minus the level's along its motion m, to first order, in
    alpha', beta', H' (see above): A12^-1 R, plus for small and elementary their rates'
    difference from (21)."""
    nf = load(MODEL).numpy
    P = vector(values)
    ab = np.stack([m.alpha, m.beta], axis=-1)
    r3 = _rigorous(P, m.alpha, m.beta, m.H)
    ad, bd = r3[:, 0], r3[:, 1]
    pd = nf.spin_from_momentum(P, ab, np.stack([ad, bd], axis=-1), m.H[:, None])[:, 0]
    q = np.stack([m.alpha, m.beta, np.zeros_like(m.t)], axis=-1)
    qd = np.stack([ad, bd, pd], axis=-1)
    qdd = np.gradient(qd, m.t, axis=0, edge_order=2)
    R = np.einsum("nij,nj->ni", nf.mass_matrix(P, q), qdd) - nf.forcing(P, q, qd)
    A12, b12 = nf.virtual_power_system(P, ab, m.H[:, None])
    out = _solve_rows(A12, R)
    if m.level in ("small", "elementary"):
        xy, Hs = np.stack([m.x, m.y], axis=-1), m.H[:, None]
        img = _solve_rows(*nf.image_system(P, xy, Hs))
        own = _solve_rows(*getattr(nf, f"{m.level}_system")(P, xy, Hs))
        d = img - own
        da, db = _image_to_angle_rates(m.x, m.y, d[:, 0], d[:, 1])
        out = out + np.stack([da, db, d[:, 2]], axis=-1)
    return out


def log_norm(values: dict, m) -> np.ndarray:
    """mu(t): the logarithmic norm of the Jacobian of (13)'s rates in the measure w =
    (cos(beta) d alpha, d beta, d H/H0) (the spin axis's displacement on the unit sphere and
    the momentum's relative change), by central differences along the motion m."""
    P = vector(values)
    st = np.stack([m.alpha, m.beta, m.H], axis=-1)
    H0 = abs(float(values["H"]))
    steps = np.array([1e-6, 1e-6, 1e-6 * H0])
    J = np.empty((len(m.t), 3, 3))
    for j in range(3):
        hi, lo = st.copy(), st.copy()
        hi[:, j] += steps[j]
        lo[:, j] -= steps[j]
        J[:, :, j] = (_rigorous(P, *hi.T) - _rigorous(P, *lo.T)) / (2 * steps[j])
    Sd = np.stack([np.cos(m.beta), np.ones_like(m.t), np.full_like(m.t, 1 / H0)], axis=-1)
    W = Sd[:, :, None] * J / Sd[:, None, :]
    W[:, 0, 0] -= np.tan(m.beta) * _rigorous(P, m.alpha, m.beta, m.H)[:, 1]  # d cos(beta)/dt / cos(beta)
    return np.linalg.eigvalsh((W + np.transpose(W, (0, 2, 1))) / 2)[:, -1]


def _carried(t, mu, d) -> np.ndarray:
    """e(t) with e' = mu e + |d|, e(0) = 0, step by step (mu the larger of each step's ends)."""
    e = np.zeros_like(t)
    for k in range(len(t) - 1):
        h = t[k + 1] - t[k]
        g = np.exp(max(mu[k], mu[k + 1]) * h)
        e[k + 1] = e[k] * g + h * (d[k] * g + d[k + 1]) / 2
    return e


def _bound_grid(values: dict, m):
    """The level's motion on a grid with PER_RADIAN samples per radian of the fastest frame
    rate (the base's |u| plus the largest |alpha'| + |beta'| of (13) on m), m itself where it
    is dense enough; None where that takes more than MAX_SAMPLES."""
    P = vector(values)
    r3 = _rigorous(P, m.alpha, m.beta, m.H)
    u = float(np.linalg.norm([values[b] for b in BASE]))
    w = u + float(np.max(np.abs(r3[:, 0]) + np.abs(r3[:, 1])))
    n = int(np.ceil(float(m.t[-1]) * w * PER_RADIAN)) + 1
    if n > MAX_SAMPLES:
        return None
    return m if n <= len(m.t) else simulate(values, np.linspace(0.0, float(m.t[-1]), n), m.level)


def slow_against_nutation(values: dict, m) -> bool:
    """(|u| + |alpha'| + |beta'|) J/(H |cos beta|) <= NUTATION_RATIO at every sample of m
    (alpha', beta' those of (13))."""
    r3 = _rigorous(vector(values), m.alpha, m.beta, m.H)
    u = float(np.linalg.norm([values[b] for b in BASE]))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = (u + np.abs(r3[:, 0]) + np.abs(r3[:, 1])) * transverse_inertia(values) / (
            np.abs(m.H) * np.abs(np.cos(m.beta)))
    return bool(np.all(ratio <= NUTATION_RATIO))


def model_error(values: dict, m) -> float:
    """The first-order estimate of the largest |P_level - P_full| over the horizon (absolute,
    before SAFETY); inf where the precession is not the slow motion or the grid would be too
    fine (see above)."""
    if not slow_against_nutation(values, m):  # on the answer's samples first: no finer grid for a refusal
        return float("inf")
    g = _bound_grid(values, m)
    if g is None or not slow_against_nutation(values, g):
        return float("inf")
    D = defect(values, g)
    d = np.sqrt((np.cos(g.beta) * D[:, 0])**2 + D[:, 1]**2 + (D[:, 2] / abs(float(values["H"])))**2)
    e = _carried(g.t, log_norm(values, g), d)
    # the nutation the defect excites: a rate defect d moves the gyroscope on a cycloid about
    # the drift d t, at most 2 |d|/omega_n off it, omega_n >= H |cos beta|/J
    nutation = 2 * float(np.max(d)) * float(np.max(transverse_inertia(values) / np.abs(g.H * np.cos(g.beta))))
    return float(np.max((1 + g.x**2 + g.y**2) * (e + nutation)))


def integration_error(values: dict, m) -> float:
    """INTEGRATION_SAFETY times the largest of: the difference of the answer (Adams, rtol
    1e-12) from BDF at the same tolerance, from Adams at a LOOSE times looser one, and the
    integrator's own tolerance on the angles carried to the image point, rho^2 (RTOL (|alpha|
    + |beta|) + ATOL) (absolute): where the motion is small against the angles (a moment of
    1e-12 N m) every run agrees with the others to the last bit and none is more accurate than
    its tolerance on the state."""
    d = float(np.max((1 + m.x**2 + m.y**2) * (RTOL * (np.abs(m.alpha) + np.abs(m.beta)) + ATOL)))
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
    model = 0.0 if m.level == "full" else SAFETY * model_error(values, m)
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
