"""Gyrohorizoncompass in a Newtonian field (Zavozin 1979, seed 001): the relative equilibrium
(3.1)-(3.2), the sufficient conditions (3.6) and (4.3) against the spectrum of the
linearisation, maps of the three regions, and motions by integrating the emitted equations.

Everything numerical comes from generated/gyrohorizoncompass/: the equilibrium epsilon0 and
its existence margins (`relative_equilibrium`), B1 and C1 (`lyapunov`), the margins of the
declared conditions (`conditions`: C1 > 0, (3.6), (4.3)), the operator M, D, K (`operator`),
E (`first_integral`), and the equations of motion (`mass_matrix`, `forcing`). `gyro stability`
and `gyro map` are the generic gyro.analyses.conditions, which reaches this module through
the model's declaration `system` for what only this system has (the hooks below: which
condition applies where, theta and chi as axes, --orbit, lambda following 1 + chi, (3.1)).

The spectrum: the eigenvalues of the companion matrix [[0, I], [-M^-1 K, -M^-1 D]] of the
emitted operator at (0, 0, 0, epsilon0) (LAPACK, balanced; gyro.qep.companion_matrix). The
ladder's default method assumes gyroscopic blocks with K > 0, which fails exactly where this
module looks (gyroscopic stabilisation, K indefinite), so the companion eigensolve is used
throughout. Each eigenvalue carries an error radius (`gyro.qep.eigen_radii`: its condition number
times a bound on the rounding of the companion matrix), and each condition's margin a
rounding bound (the emitted `conditions_rounding`); the verdicts are read through
gyro.results.verdict: 'unstable' where a root's disk lies right of the axis, 'boundary'
where two disks overlap or a margin lies within its bound of zero (rounding could change
the answer), 'stable' otherwise (docs/gyrohorizoncompass.md, "Boundaries").

Names: the paper's `lambda` is the model's `lam` (a keyword of C and Python); every command
prints `lam` and takes either, and this module works in `lambda` (NAMES). Its
default is 1 + chi of the given A, B, C, I (3.2). `theta` = (C - A)/I and `chi` = (C - B)/I
may be map axes: they move A and B with C and I fixed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from gyro.errors import finite_number
from gyro.kernels import function
from gyro.models import ParameterError, load
from gyro import ode, qep

MODEL = "gyrohorizoncompass"
NAMES = ("A", "B", "C", "J", "L", "I", "nu", "zeta", "eta", "lambda")
DERIVED = ("theta", "chi")  # map axes besides the parameters
U = qep.UNIT_ROUNDOFF  # the unit roundoff of double precision
LAMBDA_TOL = 1e-12  # lambda = 1 + chi to this relative tolerance when eta != 0

C36 = ("(3.6) 1 + theta", "(3.6) 1/3 - theta", "(3.6) 1 + chi", "(3.6) 1/3 - chi",
       "(3.6) (1 - 3 theta) nu^2 - zeta^2 - eta^2", "(3.6) (1 - 3 chi) nu^2 - eta^2")
C43 = ("(4.3) lambda + theta - chi", "(4.3) lambda/4 - chi", "(4.3) -theta")
SYLVESTER = ("C1 minor 1 (alpha)", "C1 minor 2 (alpha, gamma)", "C1 minor 3 (alpha, gamma, beta)",
             "C1 minor 4 (all)")


def model():
    return load(MODEL)


def cli_name(name: str) -> str:
    """This module's name for a parameter named by its declared name or the other name taken
    for it (the model's aliases: lambda for lam)."""
    return {v: k for k, v in model().aliases.items()}.get(model().canonical(name), name)


def _number(name: str, raw) -> float:
    return finite_number(f"parameter {name}", raw)


def _check(name: str, value: float) -> None:
    """The model's own check of a parameter, its message naming the command-line name."""
    by_name = {p.name: p for p in model().params}
    replace(by_name[model().canonical(name)], name=name).check(value)


def parameters(sets: dict | None = None, orbit: bool = False, base: dict | None = None,
               need_equilibrium: bool = True) -> dict:
    """The model's values (keys A ... eta, lam) from command-line NAME=VALUE pairs (keys
    A ... eta, lambda; values text or numbers), over `base` (model keys; default: the
    defaults, the Earth set), with lambda = 1 + chi unless given and, with `orbit`,
    zeta = nu, eta = 0 (4.1). Checked: names, numbers, signs, and that the relative
    equilibrium exists (I lambda zeta/2L < 1; eta != 0 needs lambda = 1 + chi).
    Raises ParameterError naming the parameter or the reason."""
    sets = dict(sets or {})
    values = dict(model().defaults if base is None else base)
    given = {}  # this module's name: the name typed
    for typed, raw in sets.items():
        key = cli_name(typed)
        if key not in NAMES:
            raise ParameterError(f"unknown parameter {typed!r} for {MODEL}; known: {model().known_names()}")
        if key in given:
            raise ParameterError(f"parameter {model().canonical(key)}: given twice (as {given[key]} and {typed})")
        v = _number(key, raw)
        _check(key, v)
        values[model().canonical(key)] = v
        given[key] = typed
    if orbit:
        for key in ("zeta", "eta"):
            if key in given:
                raise ParameterError(f"parameter {key}: --orbit sets zeta = nu and eta = 0; do not --set {key}")
        values["zeta"], values["eta"] = values["nu"], 0.0
    if "lambda" not in given:
        values["lam"] = 1.0 + (values["C"] - values["B"]) / values["I"]
        if not values["lam"] > 0:
            raise ParameterError(f"parameter lambda: its default 1 + chi = {values['lam']!r} is not positive "
                                 "(chi = (C - B)/I <= -1); give B, C, I with chi > -1 or set lambda")
    if need_equilibrium:
        check_equilibrium(values)
    return values


def check_equilibrium(values: dict) -> None:
    """ParameterError unless the relative equilibrium (3.1)-(3.2) exists at these values.
    Where it does not, the equations may still have an equilibrium of their own, off the
    family (3.1) (beta != 0: at zeta = 0.1 on the Earth set beta = 6.3e-4 rad, epsilon = 0;
    at eta = 0.2, lambda = 1.2 beta = -3.0e-5 rad; each a root of the emitted residual to
    1e-60 at 60 digits): the message names it, so that no one reads "no equilibrium" where
    there is one."""
    ratio = values["I"] * values["lam"] * values["zeta"] / (2 * values["L"])
    if not ratio < 1:
        raise ParameterError(f"no relative equilibrium (3.1): I lambda zeta/2L = {ratio:.6g} >= 1 (lower zeta, I "
                             f"or lambda, or raise L){_other_equilibrium(values)}")
    one_chi = 1.0 + (values["C"] - values["B"]) / values["I"]
    if values["eta"] != 0 and abs(values["lam"] - one_chi) > LAMBDA_TOL * max(1.0, abs(one_chi)):
        raise ParameterError(f"no relative equilibrium (3.1): eta = {values['eta']!r} != 0 needs lambda = 1 + chi = "
                             f"{one_chi!r} (3.2), got lambda = {values['lam']!r}{_other_equilibrium(values)}")


def _other_equilibrium(values: dict) -> str:
    """'; the equations' own equilibrium here: ...' where the generic Newton (gyro.equilibrium,
    its residual test) finds one at these values, '; nor any other equilibrium from the
    Newton's starts' where it does not."""
    from gyro.equilibrium import equilibria

    m = model()
    with np.errstate(all="ignore"):
        qe, ok = equilibria(m, m.vector(values)[None, :])
    if not ok[0]:
        return "; nor does the generic Newton find another equilibrium from its starts"
    at = ", ".join(f"{c} = {x:.6g}" for c, x in zip(m.meta["equilibrium_coordinates"], qe[0]))
    return (f"; the equations have another equilibrium here, {at} rad, off (3.1): "
            f"`gyro frequencies {m.name}` analyses it")


def with_axis(values: dict, name: str, value: float) -> dict:
    """`values` with one axis set: a parameter (command-line name), or theta/chi, which move
    A or B (C and I fixed)."""
    v = dict(values)
    if name == "theta":
        v["A"] = v["C"] - value * v["I"]
    elif name == "chi":
        v["B"] = v["C"] - value * v["I"]
    else:
        v[model().canonical(name)] = value
    return v


def cli_params(values: dict) -> dict:
    """The values by the model's declared names (the results add the other names to their JSON)."""
    return {k: float(v) for k, v in values.items()}


# ------------------------------------------------------------------ conditions and spectrum


def on_orbit(values: dict) -> bool:
    return values["zeta"] == values["nu"] and values["eta"] == 0


def _closed_form(m, P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(epsilon0 (sets,), the existence margins (sets, 2), theta and chi (sets, 2)) of (3.1)-(3.2)."""
    n = P.shape[0]
    with np.errstate(all="ignore"):
        eps0, margins, tc = (np.asarray(x).reshape(n, -1) for x in function(m, "relative_equilibrium")(P))
    return eps0[:, 0], margins, tc


def _exact(P: np.ndarray, tc: np.ndarray) -> np.ndarray:
    """lambda = 1 + chi to LAMBDA_TOL: the printed rows of (3.6) assume it."""
    return np.abs(P[:, 9] - (1 + tc[:, 1])) <= LAMBDA_TOL * np.maximum(1.0, np.abs(1 + tc[:, 1]))


def analyse(P: np.ndarray, orbit: np.ndarray | bool = False) -> dict:
    """Batch P (sets, 10) of model vectors: epsilon0, theta, chi, the margins, `sufficient`,
    the eigenvalues (sets, 8), `spectrally_stable`, B1, C1 and the residual at (3.1): the
    generic analysis of the declared conditions (gyro/analyses/conditions.py) through this
    module's hooks below, with what only this system has.

    `sufficient`: C1 > 0 by the paper's own conditions: (4.3) on the orbit (`orbit`), (3.6)
    where lambda = 1 + chi, and where lambda != 1 + chi (eta = 0 off the orbit, where the
    printed rows are not C1's minors) the Sylvester minors of C1 they stand for."""
    from gyro.analyses import conditions

    m = model()
    P = np.atleast_2d(np.asarray(P, float))
    n = P.shape[0]
    a = conditions.analyse(m, P, {"orbit": orbit})
    eps0, margins, tc = _closed_form(m, P)
    with np.errstate(all="ignore"):
        B1, C1 = (np.asarray(x).reshape(n, 4, 4) for x in function(m, "lyapunov")(P))
        resid = np.asarray(function(m, "equilibrium_residual")(P, a["qe"])[0]).reshape(n, -1)
    marg, bnd = a["margins"], a["bounds"]
    return {"epsilon0": eps0, "exists": margins[:, 0], "theta": tc[:, 0], "chi": tc[:, 1],
            "lambda_is_1_chi": _exact(P, tc),
            "sylvester": marg[:, SYL], "c36": marg[:, S36], "c43": marg[:, S43], "sufficient": a["sufficient"],
            "eigenvalues": a["eigenvalues"], "radius": a["radius"],
            "margin_bounds": [bnd[:, SYL], bnd[:, S36], bnd[:, S43]], "condition_decided": a["condition_decided"],
            "spectrum_verdict": a["spectrum_verdict"], "verdict": a["verdict"], "boundary": a["boundary"],
            "spectrally_stable": a["spectrally_stable"], "growth": a["growth"], "B1": B1, "C1": C1, "residual": resid}


def free_coordinate(K: np.ndarray) -> np.ndarray:
    """Per set: how many coordinates the stiffness leaves free (an exactly zero row and
    column: no restoring moment, as alpha at zeta = 0); each has an exact double zero root,
    unless the zero entries are a rounding coincidence, which the analysis rules out by the
    margins' bounds."""
    z = np.all(K == 0, axis=2) & np.all(K == 0, axis=1)
    return np.sum(z, axis=1)


# ------------------------------------------------------------------ the conditions' hooks
# (gyro/analyses/conditions.py calls these through the model's declaration `system`)

OPTIONS = ("orbit",)  # `gyro stability --orbit`, `gyro map --orbit`: a circular orbit (4.1)
# the declared margins (derive/models/gyrohorizoncompass.py `conditions`), in their order
SYL, S36, S43 = slice(0, 4), slice(4, 10), slice(10, 13)


def condition_parameters(m, sets: dict, options: dict, need_equilibrium: bool) -> dict:
    return parameters(sets, orbit=options.get("orbit", False), need_equilibrium=need_equilibrium)


def condition_equilibrium(m, P: np.ndarray):
    """The relative equilibrium (3.1) in closed form: (0, 0, 0, epsilon0)."""
    eps0, _, _ = _closed_form(m, P)
    qe = np.zeros((P.shape[0], 4))
    qe[:, 3] = eps0
    return qe, np.isfinite(eps0)


def condition_conservative(m, M, D, K) -> np.ndarray:
    """(1.5)-(1.6) have gyroscopic and potential forces only (the sensor's moment (2.1) is
    the gradient of its potential): a Hamiltonian spectrum at every set."""
    return np.ones(len(M), bool)


def condition_free(m, M, D, K) -> np.ndarray:
    return free_coordinate(K)


def conditions_in_force(m, P: np.ndarray, marg: np.ndarray, bnd: np.ndarray, options: dict) -> list:
    """The sufficient condition in force at each set, its margins and their rounding bounds:
    (4.3) on the orbit, (3.6) where lambda = 1 + chi, C1's minors alone elsewhere; C1's
    minors are required with the printed rows, which are C1 > 0 only given zeta != 0 and
    epsilon0 != 0 (the paper's own proviso), so that zeta = 0 exactly (m1 = 0: no compass
    effect, V only semidefinite) is no 'stable'."""
    n = P.shape[0]
    _, margins, tc = _closed_form(m, P)
    orbit = np.broadcast_to(np.asarray(options.get("orbit", False), bool) | bool(options.get("on_orbit")), (n,))
    syl, c36, c43 = marg[:, SYL], marg[:, S36], marg[:, S43]
    b_syl, b36, b43 = bnd[:, SYL], bnd[:, S36], bnd[:, S43]
    # 3: (3.6) with eta != 0, where (3.2) makes lambda = 1 + chi exact at the decimal inputs,
    # so that m2 = m1 I row5, m3 = m2 c22, m4 = m2 c44 row6 exactly: given the printed rows,
    # C1 > 0 needs only m1 > 0 (zeta != 0) and c44 > 0 (epsilon0 != 0: I lambda zeta/2L < 1).
    # The expanded bounds of m2..m4 are hundreds of times looser than those of the factored
    # rows: required, they made a set 1e-13 off the row chi = 0.32 a boundary although its
    # rows and its spectrum both decide it.
    which = np.where(orbit, 2, np.where(_exact(P, tc), np.where(P[:, 8] != 0, 3, 1), 0))
    ratio = 1 - margins[:, :1]
    # the existence margin 1 - I lambda zeta/2L by the rule of conditions_rounding: d = 4
    # factors, N = 2 terms, k = 2 d + N = 10, sum |t| = 1 + ratio (lambda itself computed as
    # 1 + (C - B)/I: a few u more, inside the factor)
    exists_bound = 10 * U * (1 + np.abs(ratio))
    both = lambda a, b: np.concatenate([a, b], axis=1)  # noqa: E731
    return [(which == 0, syl, b_syl, SYLVESTER),
            (which == 1, both(c36, syl), both(b36, b_syl), C36 + SYLVESTER),
            (which == 2, both(c43, syl), both(b43, b_syl), C43 + SYLVESTER),
            (which == 3, both(both(c36, syl[:, :1]), margins[:, :1]), both(both(b36, b_syl[:, :1]), exists_bound),
             C36 + SYLVESTER[:1] + ("(3.1) 1 - I lambda zeta/2L",))]


def condition_options(m, values: dict, options: dict) -> dict:
    """One set's analysis takes (4.3) where the set lies on the orbit (zeta = nu, eta = 0)
    without --orbit too (its name stays (3.6))."""
    return dict(options, on_orbit=on_orbit(values))


def condition_name(m, options: dict) -> str:
    return "(4.3)" if options.get("orbit") else "(3.6)"


def condition_report(m, values: dict, a: dict, options: dict) -> dict:
    """What `gyro stability` shows: the rows of (3.6) where lambda = 1 + chi (which they
    assume), the rows of (4.3) on the orbit, and C1's Sylvester minors always."""
    P = m.vector(values)[None]
    eps0, _, tc = _closed_form(m, P)
    shown = list(C36) if _exact(P, tc)[0] else []
    if options.get("orbit") or options.get("on_orbit"):
        shown += list(C43)
    shown += list(SYLVESTER)
    theta, chi = float(tc[0, 0]), float(tc[0, 1])
    return {"equilibrium": {"alpha": 0.0, "beta": 0.0, "gamma": 0.0, "epsilon0": float(eps0[0])},
            "extra": {"theta": theta, "chi": chi}, "shown": shown, "condition": condition_name(m, options),
            "lines": ["relative equilibrium (3.1): alpha = beta = gamma = 0, "
                      f"epsilon0 = {float(eps0[0]):.9g} rad",
                      f"theta = (C - A)/I = {theta:.6g}, chi = (C - B)/I = {chi:.6g}"]}


def condition_axes(m) -> tuple:
    return DERIVED


def condition_check_axes(m, names, options: dict) -> None:
    if options.get("orbit") and set(map(cli_name, names)) & {"zeta", "eta"}:
        raise ParameterError("--orbit sets zeta = nu and eta = 0: neither can be an axis")


def _lambda_follows(sets: dict) -> bool:
    return "lambda" not in {cli_name(k) for k in sets}


def condition_point(m, base: dict, axes: dict, options: dict, sets: dict) -> dict:
    """The values at one grid point: the axes set (theta and chi move A and B), zeta = nu and
    eta = 0 on the orbit, lambda = 1 + chi unless given or an axis; checked, the
    equilibrium (3.1) included (ParameterError naming the point)."""
    v = dict(base)
    for name, value in axes.items():
        v = with_axis(v, cli_name(name), value)
    if options.get("orbit"):
        v["zeta"], v["eta"] = v["nu"], 0.0
    if _lambda_follows(sets) and "lambda" not in map(cli_name, axes):
        v["lam"] = 1.0 + (v["C"] - v["B"]) / v["I"]
    where = "at " + ", ".join(f"{cli_name(k)} = {x:.6g}" for k, x in axes.items())
    for k, p in v.items():
        try:
            _check(cli_name(k), p)
        except ParameterError as exc:
            raise ParameterError(f"{exc} ({where})") from None
    try:
        check_equilibrium(v)
    except ParameterError as exc:
        raise ParameterError(f"{exc} ({where})") from None
    return v


def condition_moved(m, names, options: dict, sets: dict) -> set:
    """The declared parameters a map moves: its axes (theta moves A, chi B), lambda where
    it follows 1 + chi, zeta and eta on the orbit."""
    names = set(map(cli_name, names))
    moved = {m.canonical(k) for k in names} | {k for k, d in (("A", "theta"), ("B", "chi")) if d in names}
    if _lambda_follows(sets):
        moved.add("lam")
    if options.get("orbit"):
        moved |= {"zeta", "eta"}
    return moved


def stability(values: dict, orbit: bool = False):
    """The relative equilibrium of one set, its conditions and its spectrum, as a
    gyro.results.EquilibriumStability (the `gyro stability --json` document)."""
    from gyro.analyses import conditions

    return conditions.stability(model(), values, {"orbit": orbit} if orbit else {})


def frequencies(values: dict) -> np.ndarray:
    """|eig| of the linearisation, one per mode, ascending (rad/s)."""
    eig = analyse(model().vector(values)[None])["eigenvalues"][0]
    return np.sort(np.abs(eig))[::2]


def energy_bound(values: dict) -> float:
    """sqrt(cond(diag(B1, C1))): where C1 > 0, V = const keeps |x(t)| below this times |x(0)|
    (x = (q - qe, q'), to second order in x)."""
    a = analyse(model().vector(values)[None])
    w = np.concatenate([np.linalg.eigvalsh(a["B1"][0]), np.linalg.eigvalsh(a["C1"][0])])
    return float(math.sqrt(w.max() / w.min())) if w.min() > 0 else math.inf


# ------------------------------------------------------------------ maps


def condition_map(base: dict, xaxis, yaxis, orbit: bool = False, lambda_follows: bool = True):
    """The (3.6) region, the spectrally stable one and the unstable one over a grid of two
    axes ((name, lo, hi, n) each: parameters or theta, chi), lambda following 1 + chi when
    `lambda_follows` (and lambda is no axis): gyro.analyses.conditions.condition_map over
    the values `base` (model keys)."""
    from gyro.analyses import conditions

    sets = {cli_name(k): v for k, v in base.items() if cli_name(k) not in (xaxis[0], yaxis[0])}
    if lambda_follows:
        sets.pop("lambda", None)
    if orbit:
        sets.pop("zeta", None), sets.pop("eta", None)
    if xaxis[0] == yaxis[0]:
        raise ParameterError(f"--x and --y are both {xaxis[0]!r}")
    return conditions.condition_map(model(), sets, xaxis, yaxis, {"orbit": orbit} if orbit else {})


# ------------------------------------------------------------------ motions

SCIPY_METHODS = ode.SCIPY_METHODS
CASADI_METHODS = ("cvodes", "cvodes-adams")  # cvodes: BDF (CasADi's default); cvodes-adams: Adams-Moulton
PROJECTED = "projected"  # fixed-step DOP853 tableau, each step projected onto E = E(0)
METHODS = (*SCIPY_METHODS, *CASADI_METHODS, PROJECTED)
RTOL, ATOL = 1e-10, 1e-12  # the command line's tolerances
STEPS_PER_RADIAN = 10.0  # `projected`: steps per radian of the fastest mode
BUDGET_SECONDS = 25.0  # the command line's integrations: wall time at the most
BUDGET_STEPS = 2 * 10**6  # and steps (right-hand sides for SciPy, steps per output for CasADi, fixed steps)
CHUNK = 1000  # `projected`: fixed steps per compiled call


IntegrationBudget = ode.IntegrationBudget  # the one type (gyro/ode.py)


def _casadi_rhs():
    """y' = F(y, P), y = (q, q'), from the emitted CasADi mass matrix and forcing; and E(y, P)."""
    import casadi as ca

    s = ode.symbolic(model())
    y, p = s.y, s.p
    E = model().casadi.first_integral(p, y[:4], y[4:])[0]
    return ca, y, p, s.ydot, E


def projected_stepper(P: np.ndarray, h: float, n: int, iterations: int = 2):
    """A CasADi function y -> the states after each of n fixed steps of length h: the
    8th-order Dormand-Prince tableau (DOP853's), each step followed by the orthogonal
    projection onto E = E0 (Newton along grad E; E0 an input): Hairer, Lubich and Wanner's
    standard projection, an energy-preserving scheme."""
    from scipy.integrate._ivp import dop853_coefficients as dc

    ca, y, p, ydot, E = _casadi_rhs()
    f = ca.Function("f", [y, p], [ydot])
    Ef = ca.Function("E", [y, p], [E, ca.gradient(E, y)])
    x, e0 = ca.SX.sym("x", 8), ca.SX.sym("e0")
    k = []
    for i in range(dc.N_STAGES):
        k.append(f(x + h * sum((dc.A[i, j] * k[j] for j in range(i) if dc.A[i, j] != 0), ca.SX.zeros(8)), P))
    z = x + h * sum(dc.B[i] * k[i] for i in range(dc.N_STAGES))
    for _ in range(iterations):
        e, g = Ef(z, P)
        z = z - (e - e0) / ca.dot(g, g) * g
    step = ca.Function("step", [x, e0], [z])
    return step.mapaccum("steps", n)


def integrate(values: dict, y0: np.ndarray, t: np.ndarray, method: str = "DOP853",
              rtol: float = RTOL, atol: float = ATOL, steps_per_radian: float = STEPS_PER_RADIAN,
              budget_s: float | None = None, budget_steps: int | None = None) -> np.ndarray:
    """States (len(t), 8) = (q, q') from y0 at t[0] by one of METHODS; the equations are the
    emitted (1.5)-(1.6). `projected` takes fixed steps of at most 1/(steps_per_radian
    |eig|max) between the output times (which it needs evenly spaced). With a budget (the
    command line's), a run that needs more seconds or steps stops with IntegrationBudget."""
    import time

    t = np.asarray(t, float)
    P = model().vector(values)
    y0 = np.asarray(y0, float)
    start = time.perf_counter()
    max_s = math.inf if budget_s is None else budget_s
    max_steps = math.inf if budget_steps is None else budget_steps
    if method in SCIPY_METHODS or method in CASADI_METHODS:
        return ode.integrate_state(model(), P, y0, t, method, rtol, atol, max_s - (time.perf_counter() - start),
                                   max_steps, jac=True)
    if method == PROJECTED:
        if len(t) < 2:
            return y0[None]
        dt = np.diff(t)
        if not np.allclose(dt, dt[0], rtol=1e-9, atol=0):
            raise ParameterError("method projected: needs evenly spaced output times")
        w = float(np.max(np.abs(analyse(P[None])["eigenvalues"][0])))
        n = max(1, math.ceil(dt[0] * steps_per_radian * w))
        total = n * (len(t) - 1)
        if total > max_steps:
            raise IntegrationBudget(f"projected: {total:.3g} fixed steps needed (|eig|max = {w:.6g} rad/s, "
                                    f"{steps_per_radian:g} steps per radian), over its budget of {max_steps:.3g}")
        h = dt[0] / n
        full, rest = divmod(n, CHUNK)
        chunk = projected_stepper(P, h, CHUNK) if full else None
        last = projected_stepper(P, h, rest) if rest else None
        E0 = energy(values, y0[None])[0]
        out, y = [y0], y0
        for k in range(len(t) - 1):
            for j in range(full):
                if time.perf_counter() - start > max_s:
                    raise IntegrationBudget(f"projected stopped at t = {t[k] + j * CHUNK * h:.6g} s of "
                                            f"{t[-1]:.6g} s after {time.perf_counter() - start:.0f} s (its budget)")
                y = np.array(chunk(y, E0))[:, -1]
            if last is not None:
                y = np.array(last(y, E0))[:, -1]
            out.append(y)
        return np.array(out)
    raise ParameterError(f"--method: unknown method {method!r}; known: {' '.join(METHODS)}")


def energy(values: dict, Y: np.ndarray) -> np.ndarray:
    """E (2.3) along states Y (..., 8), the emitted `first_integral`."""
    Y = np.atleast_2d(np.asarray(Y, float))
    P = np.broadcast_to(model().vector(values), (len(Y), 10))
    return np.asarray(function(model(), "first_integral")(np.ascontiguousarray(P), np.ascontiguousarray(Y[:, :4]),
                                                         np.ascontiguousarray(Y[:, 4:]))[0]).reshape(-1)


def initial_state(values: dict, perturb=(0.0, 0.0, 0.0, 0.0)) -> np.ndarray:
    """(q, q') at t = 0: the relative equilibrium (0, 0, 0, epsilon0) plus `perturb` in the
    angles, at rest."""
    eps0 = float(analyse(model().vector(values)[None])["epsilon0"][0])
    y = np.zeros(8)
    y[3] = eps0
    y[:4] += np.asarray(perturb, float)
    return y


def trajectory(values: dict, t, perturb=(0.0, 0.0, 0.0, 0.0), method: str = "DOP853"):
    """A perturbed motion about the relative equilibrium as a gyro.results.Motion: the
    angles alpha, beta, gamma, epsilon and the integral E along it, whose relative drift
    max |E - E(0)| / |E(0)| is its `drift` (the command line's: within the integration
    budget)."""
    from gyro.results import Motion

    t = np.asarray(t, float)
    y0 = initial_state(values, perturb)
    Y = integrate(values, y0, t, method, budget_s=BUDGET_SECONDS, budget_steps=BUDGET_STEPS)
    if not np.all(np.isfinite(Y)):
        raise FloatingPointError(f"{method}: a coordinate is not finite")
    E = energy(values, Y)
    dE = np.max(np.abs(E - E[0]))
    drift = float(dE / abs(E[0])) if E[0] != 0 else float(dE)
    angles = ["alpha", "beta", "gamma", "epsilon"]
    title = model().meta["title"]
    return Motion(MODEL, title, method, t, [*angles, "E"], np.column_stack([Y[:, :4], E]), ["rad"] * 4 + [""],
                  [f"the angle {a} (3.1)" for a in angles] + ["the integral E (2.3)"],
                  info={"params": cli_params(values), "drift": drift}, keys=["t", *angles, "E", "method"],
                  heading=[f"{title} ({MODEL}), method {method}",
                           f"E(0) = {E[0]:.12g}; max |E - E(0)|/|E(0)| = {drift:.2g}"],
                  shown=angles, formats={"t": ">12.6g", **{a: ">18.11g" for a in angles}}, gap="",
                  invariants=["E"])


# ------------------------------------------------------------------ the motion question

# the `motion` question's inputs beside the parameters (gyro/questions/motion.py): the
# perturbation of the relative equilibrium (3.1), alpha = beta = gamma = 0, epsilon = epsilon0,
# at rest, at t = 0
INITIAL = {
    "alpha0": ("rad", 1e-3, "alpha at t = 0 (0 at the relative equilibrium (3.1))"),
    "beta0": ("rad", 1e-3, "beta at t = 0 (0 at the relative equilibrium)"),
    "gamma0": ("rad", 1e-3, "gamma at t = 0 (0 at the relative equilibrium)"),
    "delta_epsilon0": ("rad", 1e-3, "epsilon - epsilon0 at t = 0 (epsilon0 = arccos(I lambda zeta/2L), (3.1))"),
    "dalpha0": ("rad/s", 0.0, "alpha' at t = 0"),
    "dbeta0": ("rad/s", 0.0, "beta' at t = 0"),
    "dgamma0": ("rad/s", 0.0, "gamma' at t = 0"),
    "depsilon0": ("rad/s", 0.0, "epsilon' at t = 0"),
}
LINEAR = "linear"  # motion_answer's method: the linearised equations about (3.1)
# the linear level's cap is a fraction of the linear motion's displacement from (3.1), at
# most a radian (gyro.analyses.motion.CAP_OF; the level's declared "cap_of"): on the Earth
# set over 2 s the slow modes hardly move, so the motion's excursion from its offset start
# is a tenth of its displacement (docs/hierarchy.md)
CAP_OF = "displacement"


@dataclass(frozen=True)
class Motion:
    """A motion of the gyrohorizoncompass: parameters (model keys, `lam`) and the perturbation
    of the relative equilibrium at t = 0 (INITIAL)."""

    params: dict
    alpha0: float = INITIAL["alpha0"][1]
    beta0: float = INITIAL["beta0"][1]
    gamma0: float = INITIAL["gamma0"][1]
    delta_epsilon0: float = INITIAL["delta_epsilon0"][1]
    dalpha0: float = 0.0
    dbeta0: float = 0.0
    dgamma0: float = 0.0
    depsilon0: float = 0.0

    @property
    def perturbation(self) -> np.ndarray:
        """x0 = y(0) - ye, y = (q, q')."""
        return np.array([self.alpha0, self.beta0, self.gamma0, self.delta_epsilon0,
                         self.dalpha0, self.dbeta0, self.dgamma0, self.depsilon0], float)


def motion_answer(motion: Motion, t, method: str = LINEAR, rtol: float = RTOL, cap_of: str = CAP_OF):
    """The `motion` question's evaluator (gyro/questions/motion.py, docs/hierarchy.md): the
    coordinates alpha, beta, gamma, epsilon at the times t (times, 4) from the perturbed
    relative equilibrium, and an estimate of each one's largest absolute error over t (rad).

    `linear`: the generic linear level (gyro.analyses.motion.linear_answer) about the
    equilibrium (3.1), the perturbation (INITIAL) its z0: the motion of the linearised
    equations, exact (the exponential of the emitted operator's first-order matrix), and
    its estimate, twice the correction after two Picard steps toward (1.5)-(1.6) (the
    largest over the four angles, one unit) plus the rounding; infinite where that exceeds
    a quarter of the linear motion's size of `cap_of` (the level declares `displacement`:
    its largest distance from (3.1), at most a radian).

    An integrator of METHODS: the equations (1.5)-(1.6) integrated at rtol and rtol/100
    (gyro.ode.two_tolerances; within the command line's budget)."""
    from gyro.analyses import motion as generic

    t = np.asarray(t, float)
    values = motion.params
    check_equilibrium(values)  # the reason in one line where (3.1) does not exist
    if method == LINEAR:
        red = generic.ReducedState(model(), values)
        return generic.linear_answer(red, motion.perturbation, t, ["rad"] * 4, cap_of=cap_of)
    y0 = initial_state(values) + motion.perturbation
    return ode.two_tolerances(lambda r: integrate(values, y0, t, method, r, r * 1e-2, budget_s=BUDGET_SECONDS,
                                                  budget_steps=BUDGET_STEPS)[:, :4], rtol)


# ------------------------------------------------------------------ gyro simulate

ANGLES = ("alpha", "beta", "gamma", "epsilon")


def simulate_command(model, args, cli):
    """`gyro simulate gyrohorizoncompass` (the model's `simulate` declaration): every input
    checked first (names, numbers, equilibrium, --perturb as D1,D2,D3,D4 or NAME=VALUE
    over ANGLES, --t-end, --points, --method, --out), then integrated. Returns the
    Motion."""
    values = parameters(cli.sets(args.set))
    perturb = [0.0] * 4
    if args.perturb is not None and (len(args.perturb) > 1 or "=" in args.perturb[0]):
        for name, raw in cli.perturb_items(args.perturb).items():
            if name not in ANGLES:
                raise ParameterError(f"--perturb {name}: the gyrohorizoncompass's offsets are of "
                                     f"{', '.join(ANGLES)} (rad, at rest)")
            perturb[ANGLES.index(name)] = finite_number(f"--perturb {name}", raw)
    elif args.perturb is not None:
        parts = args.perturb[0].split(",")
        if len(parts) != 4:
            raise ParameterError(f"--perturb: expected four numbers D1,D2,D3,D4, got {args.perturb!r}")
        perturb = [finite_number(f"--perturb {n}", p) for n, p in zip(ANGLES, parts)]
    t, method = cli.times(args), cli.method(args, METHODS, "DOP853")
    cli.png(args.out)
    return trajectory(values, t, perturb, method)
