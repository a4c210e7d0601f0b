"""A motion of any model from its reference (`gyro simulate MODEL` for a model without a
motion of its own; docs/models.md): the emitted nonlinear equations, y = (q, q'),
integrated from the reference state (the emitted `reference_state`: the equilibrium
coordinates at the equilibrium of the set, the others zero; steady and cyclic rates as the
reference has them) plus the offsets asked for (`NAME=VALUE`: a coordinate, or its rate as
`NAME_d`), the given functions and input signals zero, the explicit time t where the
equations have it. The integrators are SciPy's (solve_ivp), bounded by a budget of time
and evaluations that the error names."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from gyro import ode
from gyro.errors import ParameterError

METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
RTOL, ATOL = 1e-10, 1e-12
BUDGET_S = 30.0
BUDGET_EVALUATIONS = 5e6


IntegrationBudget = ode.IntegrationBudget  # the one type (gyro/ode.py)


@dataclass
class Start:
    """Where a motion starts: the reference state, the offsets, and the state itself."""
    q_ref: np.ndarray
    qd_ref: np.ndarray
    y0: np.ndarray
    equilibrium: dict


def perturbations(model, items: dict) -> dict:
    """{name: value} of --perturb NAME=VALUE, checked: a coordinate or NAME_d, a finite
    number; ParameterError naming the item otherwise."""
    from gyro.errors import finite_number

    coords = list(model.meta["coordinates"])
    known = coords + [f"{c}_d" for c in coords]
    out = {}
    for name, raw in items.items():
        if name not in known:
            raise ParameterError(f"--perturb {name}: not a coordinate of {model.name} nor a rate NAME_d; "
                                 f"known: {' '.join(known)}")
        out[name] = finite_number(f"--perturb {name}", raw)
    return out


def start(model, P, offsets: dict) -> Start:
    """The reference state of the set P, the offsets added."""
    from gyro.equilibrium import EquilibriumError, equilibria
    from gyro.kernels import function

    fns = model.meta["functions"]
    if "reference_state" not in fns:
        if model.meta.get("momenta"):
            raise ParameterError(f"{model.name}: its reference is a stationary motion of given momenta "
                                 f"({', '.join(model.meta['momenta'])}), not parameters: the generic motion needs a "
                                 "reference it can compute")
        raise ParameterError(f"{model.name}: emitted without reference_state (derive it again with this version)")
    P = np.asarray(P, float)[None, :]
    eq_names = list(model.meta["equilibrium_coordinates"])
    args = [P]
    if eq_names:
        qe, ok = equilibria(model, P)
        if not ok[0]:
            raise EquilibriumError(f"{model.name}: no equilibrium at this set: no reference to start from")
        args.append(qe)
    else:
        qe = np.zeros((1, 0))
    if any(i["name"] == "time" for i in fns["reference_state"]["inputs"]):
        args.append(np.zeros((1, 1)))
    with np.errstate(all="ignore"):
        q_ref, qd_ref = (np.asarray(x, float).reshape(-1) for x in function(model, "reference_state")(*args))
    if not (np.all(np.isfinite(q_ref)) and np.all(np.isfinite(qd_ref))):
        raise FloatingPointError("the reference state is not finite at this set")
    coords = list(model.meta["coordinates"])
    q0, qd0 = q_ref.copy(), qd_ref.copy()
    for name, value in offsets.items():
        if name in coords:
            q0[coords.index(name)] += value
        else:
            qd0[coords.index(name[:-2])] += value
    return Start(q_ref, qd_ref, np.concatenate([q0, qd0]), dict(zip(eq_names, map(float, qe[0]))))


STEPS_PER_PERIOD = 40  # DOP853 at rtol 1e-10 on a smooth oscillation: 25-60 steps a period
EVALUATIONS_PER_STEP = 12


def predicted_evaluations(model, P, y0, t_end: float) -> tuple[float, float]:
    """(evaluations the integration is expected to need, the fastest rate |lambda| of the
    equations' Jacobian at the start, 1/s): t_end |lambda| / (2 pi) periods of the fastest
    motion, STEPS_PER_PERIOD steps each, EVALUATIONS_PER_STEP evaluations a step. A
    prediction, not a bound: the budget still stops a run that needs more."""
    import casadi as ca

    s = ode.symbolic(model)
    zeros = [np.zeros(v.numel()) for v in s.inputs]
    with np.errstate(all="ignore"):
        _, J = ode.jacobian(model)(y0, ca.DM(np.asarray(P, float)), *zeros)
        J = np.asarray(J, float)
        rate = float(np.max(np.abs(np.linalg.eigvals(J)))) if np.all(np.isfinite(J)) else float("inf")
    return t_end * rate / (2 * np.pi) * STEPS_PER_PERIOD * EVALUATIONS_PER_STEP, rate


def _inputs(model):
    """inputs(t) for ode.numpy_rhs: the explicit time its value, every other input zero."""

    s = ode.symbolic(model)
    specs = model.meta["functions"]["forcing"]["inputs"][3:]
    zeros = [np.zeros(v.numel()) for v in s.inputs]
    timed = [k for k, spec in enumerate(specs) if spec["name"] == "time"]
    if not timed:
        return None
    k = timed[0]

    def inputs(t):
        out = list(zeros)
        out[k] = np.array([t])
        return tuple(out)

    return inputs


def simulate(model, values: dict, offsets: dict, t: np.ndarray, method: str = "DOP853",
             budget_s: float = BUDGET_S) -> "CoordinateMotion":
    from scipy.integrate import solve_ivp

    from gyro.results.trajectory import CoordinateMotion

    if method not in METHODS:
        raise ParameterError(f"--method: unknown method {method!r}; known: {' '.join(METHODS)}")
    P = model.vector(values)
    st = start(model, P, offsets)
    need, rate = predicted_evaluations(model, P, st.y0, float(t[-1]))
    if not need <= BUDGET_EVALUATIONS:
        raise ParameterError(f"--t-end {t[-1]:g}: the fastest motion at the start turns at {rate:.6g} 1/s, so the "
                             f"integration would need about {need:.2g} evaluations of the equations, over its budget of "
                             f"{BUDGET_EVALUATIONS:.0e}: a shorter horizon")
    fun = ode.budgeted(ode.numpy_rhs(model, P, _inputs(model)), f"{method} on {model.name}", float(t[-1]),
                       budget_s, BUDGET_EVALUATIONS, IntegrationBudget)
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        sol = solve_ivp(fun, (0.0, float(t[-1])), st.y0, method=method, t_eval=t, rtol=RTOL, atol=ATOL)
    if sol.status != 0 or sol.y.shape[1] != len(t):
        raise FloatingPointError(f"{method} stopped at t = {sol.t[-1] if sol.t.size else 0.0:.6g} s: {sol.message}")
    if not np.all(np.isfinite(sol.y)):
        raise FloatingPointError("a coordinate is not finite along the motion")
    n = len(model.meta["coordinates"])
    units = model.meta.get("coordinate_units", {})
    return CoordinateMotion(model=model.name, title=model.meta.get("title", model.name), method=method, t=np.asarray(t),
                  coordinates=list(model.meta["coordinates"]), units=[units.get(c, "") for c in model.meta["coordinates"]],
                  q=sol.y[:n].T.copy(), qd=sol.y[n:].T.copy(), params=dict(values), perturb=dict(offsets),
                  equilibrium=st.equilibrium, seconds=time.perf_counter() - t0)
