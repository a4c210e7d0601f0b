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
from functools import cached_property

import numpy as np

from gyro import ode
from gyro.errors import ParameterError
from gyro.kernels import function

METHODS = ode.SCIPY_METHODS
RTOL, ATOL = 1e-10, 1e-12
BUDGET_S = 30.0
BUDGET_EVALUATIONS = 5e6


IntegrationBudget = ode.IntegrationBudget  # the one type (gyro/ode.py)


@dataclass
class Start:
    """Where a motion starts: the reference state, the offsets, and the state itself; for a
    model with multipliers its `constraints` (Constraints), and the coordinates and rates
    `solved` from them."""
    q_ref: np.ndarray
    qd_ref: np.ndarray
    y0: np.ndarray
    equilibrium: dict
    constraints: "Constraints | None" = None
    solved: tuple = ()


def carried(model) -> dict | None:
    """The metadata 'constraints' of a model whose holonomic constraints are carried by
    multipliers, else None."""
    c = model.meta.get("constraints") or {}
    return c if c.get("multipliers") else None


class Constraints:
    """The holonomic constraints of a model with multipliers about one reference q_ref, from
    the emitted quantity `constraints` (phi(q) and Phi_q = dphi/dq) and the metadata's
    `dependent` coordinates: `position(q)` keeps q's independent coordinates and solves the
    dependent ones from phi(q) = 0 by Newton's method from their values in q
    (gyro.equilibrium.on_constraints, that start alone), on the reference's branch (the
    sign of det dphi/dq_dep as at q_ref: another branch lies past a point where it
    vanishes); `rates(q, qd)` solves the dependent rates from Phi_q q' = 0; `project(y,
    y_before)` puts a state of the motion back onto phi = 0 and Phi_q q' = 0 (the nearest
    point, `nearest`) and measures the corrections against the integrator's tolerance
    (ode.integrate_state's `project`), the largest accepted one kept per coordinate and rate
    (`drift`)."""

    def __init__(self, model, P, q_ref, rtol: float = 0.0, atol=0.0):
        meta = model.meta
        c = carried(model)
        self.model, self.P = model, np.asarray(P, float)
        self.coords = list(meta["coordinates"])
        if list(meta["equilibrium_coordinates"]) != self.coords:  # on_constraints' layout
            raise ParameterError(f"{model.name}: its multipliers come with coordinates that have no equilibrium "
                                 f"({', '.join(c for c in self.coords if c not in meta['equilibrium_coordinates'])})"
                                 ": its constraints are not solved for a motion")
        self.dependent, self.independent = list(c["dependent"]), list(c["independent"])
        self.dep = np.array([self.coords.index(x) for x in self.dependent], int)
        self.ind = np.array([self.coords.index(x) for x in self.independent], int)
        self.nq = len(self.coords)
        units = meta.get("coordinate_units", {})
        self.is_angle = np.array([units.get(x) == "rad" for x in self.coords], bool)
        self.rtol, self.atol = rtol, atol
        self.branch = self._sign(np.asarray(q_ref, float))
        self.drift = np.zeros(2 * self.nq)  # the largest accepted corrections, q then q'

    def tolerance(self, rtol: float, atol) -> "Constraints":
        """These constraints projecting against another tolerance, their drift from zero."""
        import copy

        out = copy.copy(self)
        out.rtol, out.atol, out.drift = rtol, atol, np.zeros_like(self.drift)
        return out

    def _evaluate(self, q):
        with np.errstate(all="ignore"):
            phi, J = function(self.model, "constraints")(self.P[None], np.asarray(q, float)[None])
        return np.asarray(phi, float).reshape(-1), np.asarray(J, float).reshape(len(self.dep), self.nq)

    def _sign(self, q) -> float:
        J = self._evaluate(q)[1]
        return float(np.sign(np.linalg.det(J[:, self.dep]))) if np.all(np.isfinite(J)) else 0.0

    def position(self, q) -> np.ndarray | None:
        """q with its dependent coordinates solved from phi = 0 on the reference's branch, or
        None where Newton's method from them meets no point of it."""
        from gyro.equilibrium import on_constraints

        out = on_constraints(self.model, self.P[None], np.asarray(q, float)[None], self.is_angle,
                             starts=(None,))[0]
        phi = self._evaluate(out)[0]
        met = np.all(np.isfinite(out)) and np.max(np.abs(phi)) <= 1e-12 * max(1.0, float(np.max(np.abs(out))))
        return out if met and self.branch != 0 and self._sign(out) == self.branch else None

    def rates(self, q, qd) -> np.ndarray:
        """qd with its dependent rates from Phi_q q' = 0 at q (its independent rates as given)."""
        J = self._evaluate(q)[1]
        out = np.array(qd, float)
        out[self.dep] = np.linalg.solve(J[:, self.dep], -J[:, self.ind] @ out[self.ind]) + 0.0  # no -0
        return out

    def nearest(self, q) -> np.ndarray | None:
        """The point of the constraints nearest q (Newton's method with the least-norm step,
        dq = Phi_q' (Phi_q Phi_q')^-1 phi, over all coordinates: it needs no partition, so it
        holds where the dependent block is singular, a bead at its hoop's equator), or None
        where it meets none (phi within 1e-12 of the coordinates' size, as `position`)."""
        q = np.array(q, float)
        for _ in range(20):
            phi, J = self._evaluate(q)
            with np.errstate(all="ignore"):
                try:
                    step = J.T @ np.linalg.solve(J @ J.T, phi)
                except np.linalg.LinAlgError:
                    return None
            if not np.all(np.isfinite(step)):
                return None
            q -= step
            if np.max(np.abs(step), initial=0.0) <= 4 * np.finfo(float).eps * max(1.0, float(np.max(np.abs(q)))):
                break
        phi = self._evaluate(q)[0]
        return q if np.max(np.abs(phi)) <= 1e-12 * max(1.0, float(np.max(np.abs(q)))) else None

    def project(self, y, before):
        """(y on the constraints, the largest correction over what the tolerance allows of its
        component, atol + rtol max(|y|, |before|)); inf where `nearest` finds no point. The
        coordinates to the nearest point of phi = 0, the rates to the nearest of Phi_q q' = 0
        there (q' - Phi_q' (Phi_q Phi_q')^-1 Phi_q q'): the standard orthogonal projection,
        which follows the motion onto any branch it swings to (a bead over its hoop's top)."""
        n = self.nq
        q = self.nearest(y[:n])
        if q is None:
            return y, np.inf
        J = self._evaluate(q)[1]
        qd = y[n:] - J.T @ np.linalg.solve(J @ J.T, J @ y[n:])
        out = np.concatenate([q, qd])
        change = np.abs(out - y)
        allowed = np.broadcast_to(self.atol, y.shape) + self.rtol * np.maximum(np.abs(y), np.abs(before))
        with np.errstate(all="ignore"):
            ratio = float(np.max(np.where(change == 0, 0.0, change / allowed), initial=0.0))
        if ratio <= 1.0:
            self.drift = np.maximum(self.drift, change)
        return out, ratio


def perturbations(model, items: dict) -> dict:
    """{name: value} of --perturb NAME=VALUE, checked: a coordinate or NAME_d, a finite
    number; ParameterError naming the item otherwise."""
    from gyro.errors import finite_number

    coords = list(model.meta["coordinates"])
    known = coords + [f"{c}_d" for c in coords]
    c = carried(model)
    dependent = c["dependent"] if c else []
    out = {}
    for name, raw in items.items():
        if name not in known:
            raise ParameterError(f"--perturb {name}: not a coordinate of {model.name} nor a rate NAME_d; "
                                 f"known: {' '.join(known)}")
        if name.removesuffix("_d") in dependent:
            free = c["independent"] + [f"{x}_d" for x in c["independent"]]
            raise ParameterError(f"--perturb {name}: {name.removesuffix('_d')} is a dependent coordinate of "
                                 f"{model.name}, solved from its constraints at the start; offset the independent "
                                 f"ones: {' '.join(free)}")
        out[name] = finite_number(f"--perturb {name}", raw)
    return out


def start(model, P, offsets: dict, qe: np.ndarray | None = None) -> Start:
    """The reference state of the set P, the offsets added; `qe` the set's equilibrium where
    the caller has found it already."""
    from gyro.equilibrium import EquilibriumError, equilibria

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
        if qe is None:
            qe, ok = equilibria(model, P)
            if not ok[0]:
                raise EquilibriumError(f"{model.name}: no equilibrium at this set: no reference to start from")
        qe = np.asarray(qe, float).reshape(1, -1)
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
    equilibrium = dict(zip(eq_names, map(float, qe[0])))
    if not carried(model):
        return Start(q_ref, qd_ref, np.concatenate([q0, qd0]), equilibrium)
    cons = Constraints(model, P[0], q_ref, RTOL, ATOL)
    q1 = cons.position(q0)
    if q1 is None:
        given = [k for k in offsets if k in coords]
        raise ParameterError(f"--perturb {' '.join(given)}: no point of {model.name}'s constraints near its "
                             f"reference has {' and '.join(f'{k} = {q0[coords.index(k)]:g}' for k in given)} "
                             f"({', '.join(cons.dependent)} solved from them on the reference's branch)")
    solved = tuple(cons.dependent) + tuple(f"{x}_d" for x in cons.dependent)
    return Start(q_ref, qd_ref, np.concatenate([q1, cons.rates(q1, qd0)]), equilibrium, cons, solved)


# the linear motion's fine grid, its samples times the states at the most (some 80 MB an
# array; 25 times the largest the error maps use: the torsion gyrocompass at 10x spin over
# 0.05 s, 3.8e5; about 10 s of work): a horizon past it is refused, not allocated
FINE_BUDGET = 1e7
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
             budget_s: float = BUDGET_S):
    if method not in METHODS:
        raise ParameterError(f"--method: unknown method {method!r}; known: {' '.join(METHODS)}")
    P = model.vector(values)
    st = start(model, P, offsets)
    need, rate = predicted_evaluations(model, P, st.y0, float(t[-1]))
    if not need <= BUDGET_EVALUATIONS:
        raise ParameterError(f"--t-end {t[-1]:g}: the fastest motion at the start turns at {rate:.6g} 1/s, so the "
                             f"integration would need about {need:.2g} evaluations of the equations, over its budget of "
                             f"{BUDGET_EVALUATIONS:.0e}: a shorter horizon")
    t0 = time.perf_counter()
    cons = st.constraints
    try:
        Y = ode.integrate_state(model, P, st.y0, t, method, RTOL, ATOL, budget_s, BUDGET_EVALUATIONS,
                                inputs=_inputs(model), label=f"{method} on {model.name}",
                                project=cons.project if cons else None)
    except ode.IntegrationBudget as exc:
        raise ode.IntegrationBudget(f"{exc}{_switching(model)}") from None
    if not np.all(np.isfinite(Y)):
        raise FloatingPointError("a coordinate is not finite along the motion")
    n = len(model.meta["coordinates"])
    extra = {}
    if cons:
        names = [*cons.coords, *(f"{x}_d" for x in cons.coords)]
        extra = {"start": dict(zip(names, map(float, st.y0))), "solved": list(st.solved),
                 "constraint_residual": dict(zip(names, map(float, cons.drift)))}
    return coordinate_motion(model, method, t, Y[:, :n], Y[:, n:], dict(values), dict(offsets), st.equilibrium,
                             time.perf_counter() - t0, extra)


def _switching(model) -> str:
    """For a budget exhausted on a model with non-smooth terms (metadata 'nondifferentiable',
    derive/nonsmooth.py): the likely reason, named. A term such as sign(x_d) of a Coulomb
    force whose argument stays at its kink (a block that sticks: the spring's pull below the
    friction's bound) switches at every step, and the integrator's steps shrink without end
    (a block from rest plus 0.01 m: 5e6 evaluations for 1.7e-6 s); the smooth equations
    have no motion to give there, so what it would take is said, not a guess made."""
    terms = [d["term"] for d in model.meta.get("nondifferentiable", ()) if d["term"].startswith("sign(")]
    if not terms:
        return ""
    return (f"; the equations hold {', '.join(terms)}: where its argument stays at 0 (sticking under Coulomb "
            "friction) the force switches at every step and no integrator of these equations gets past; "
            "start where it slides, or write a smooth law (tanh(x_d/eps))")


# the generic motion's document: these keys, then each coordinate not among them
HEAD = ["model", "method", "params", "perturb", "equilibrium", "coordinates", "units", "t", "rates", "seconds"]


# and, for a model with multipliers, these after them
CONSTRAINED = ["start", "solved", "constraint_residual"]


def coordinate_motion(model, method: str, t, q, qd, params: dict, perturb: dict, equilibrium: dict,
                      seconds: float = 0.0, constrained: dict | None = None):
    """A motion of any model in its coordinates, as gyro.results.Motion: q and qd (times,
    coordinates) absolute values in the model's units, the series the coordinates and their
    rates NAME_d; the `gyro simulate --json` document of the generic motion: `t`, one list
    per coordinate under its name, `method`, and `rates` ({NAME_d: list}), `coordinates`,
    `units`, `params`, `perturb`, `equilibrium`, `model`, `seconds` (a model file's motion
    of its own may give its own in the same form: tests/models/oscillator_own_motion.py).
    A model with multipliers adds `constrained` (CONSTRAINED): `start`, the state at t = 0
    ({NAME: value, NAME_d: value}), `solved`, which of them were solved from the
    constraints, and `constraint_residual` ({NAME: largest, NAME_d: largest} over the
    coordinates and rates: the largest correction that put the integrated state back onto
    the constraints, each within the integrator's tolerance; the states given are on them
    to Newton's rounding); the text's second line says so."""
    from gyro.results import Motion

    coords = list(model.meta["coordinates"])
    units = [model.meta.get("coordinate_units", {}).get(c, "") for c in coords]
    rates = [f"{c}_d" for c in coords]
    title = model.meta.get("title", model.name)
    heading = [f"{title} ({model.name}), method {method}, from the reference"
               + (" with " + ", ".join(f"{k} {v:+g}" for k, v in perturb.items()) if perturb else "")]
    info = {"params": params, "perturb": perturb, "equilibrium": equilibrium, "coordinates": coords,
            "units": dict(zip(coords, units)), "seconds": seconds, **(constrained or {})}
    if constrained:
        start = constrained["start"]
        heading.append("on the constraints: " + ", ".join(f"{k} = {start[k]:.9g}" for k in constrained["solved"])
                       + " solved at the start; put back onto them along the motion, each correction within "
                       "the tolerance (the largest: constraint_residual)")
    head = HEAD + (CONSTRAINED if constrained else [])
    return Motion(model.name, title, method, np.asarray(t), coords + rates, np.hstack([q, qd]),
                  units + [f"{u}/s" if u else "1/s" for u in units],
                  [f"the coordinate {c}" for c in coords] + [f"the rate of {c}" for c in coords], info=info,
                  keys=head + [c for c in coords if c not in head], groups={"rates": rates}, heading=heading,
                  shown=coords, formats={"t": ">12.6g", **{c: ">16.9g" for c in coords}}, gap="")


# ----------------------------------------------------------------------------- the reduced state
class ReducedState:
    """One set's state about its reference in the operator's coordinates (metadata
    'reduced'): the set P and its values, the equilibrium qe, the coordinates and the
    reduced ones' indices ri, the cyclic ones' ci, the reference (q_ref, qd_ref; the emitted
    `reference_state`). `state(x, xd)` is the full state (q, q') of reduced displacements x
    and rate offsets xd: q = q_ref + x and q' = qd_ref + xd on the reduced coordinates (a
    steady coordinate keeps its declared rate plus xd), the cyclic coordinates' rates from
    their momenta (the emitted `cyclic_rates`: for the torsion gyrocompass gamma3' from the
    integral C r2 = H, (2.3)). A model with multipliers: the reduced coordinates are the
    independent ones, the dependent coordinates and rates solved from the constraints on the
    reference's branch (`constraints`, Constraints; with lib = casadi by CasADi's Newton
    rootfinder, the rates by the linear solve: an implicit map, exact to its tolerance)."""

    def __init__(self, model, values: dict):
        from gyro.equilibrium import equilibrium

        meta = model.meta
        if any(i["name"] == "time" for i in meta["functions"]["forcing"]["inputs"]):
            raise ParameterError(f"{model.name}: its equations hold the time explicitly: no reduced motion about "
                                 "a reference (the linear motion needs autonomous equations)")
        self.model = model
        self.P = model.vector(values)
        self.values = model.parameters(values)
        self.qe = equilibrium(model, self.P) if meta["equilibrium_coordinates"] else np.zeros(0)
        self.coords = list(meta["coordinates"])
        self.ri = np.array([self.coords.index(c) for c in meta["reduced"]], int)
        self.ci = [self.coords.index(c) for c in meta.get("cyclic", {})]
        self.nq, self.n = len(self.coords), len(self.ri)
        st = start(model, self.P, {}, self.qe)
        self.q_ref, self.qd_ref = st.q_ref, st.qd_ref
        self.constraints = st.constraints
        if self.constraints is not None and list(self.constraints.ind) != list(self.ri):
            raise ParameterError(f"{model.name}: its reduced coordinates ({', '.join(meta['reduced'])}) are not its "
                                 f"independent ones ({', '.join(self.constraints.independent)})")
        if self.ci and "cyclic_rates" not in meta["functions"]:
            raise ParameterError(f"{model.name}: emitted without cyclic_rates (derive it again with this version)")

    def state(self, x, xd, lib=np):
        """The full state (q, q') of reduced displacements x and rate offsets xd; with
        lib = casadi, of symbols (an SX column; MX for a model with multipliers)."""
        if self.constraints is not None:
            return self._constrained_state(x, xd, lib)
        if lib is np:
            q, qd = self.q_ref.copy(), self.qd_ref.copy()
            q[self.ri] += x
            qd[self.ri] += xd
            if self.ci:
                with np.errstate(all="ignore"):
                    rates = function(self.model, "cyclic_rates")(self.P[None], q[None], qd[None])[0]
                qd[self.ci] = np.asarray(rates, float).reshape(-1)
            return np.concatenate([q, qd])
        q, qd = [float(v) for v in self.q_ref], [float(v) for v in self.qd_ref]
        for j, i in enumerate(self.ri):
            q[i], qd[i] = q[i] + x[j], qd[i] + xd[j]
        if self.ci:
            rates = self.model.casadi.cyclic_rates(lib.DM(self.P), lib.vertcat(*q), lib.vertcat(*qd))
            for j, i in enumerate(self.ci):
                qd[i] = rates[j]
        return lib.vertcat(*q, *qd)

    def _constrained_state(self, x, xd, lib):
        """state() of a model with multipliers: the independent coordinates and rates offset,
        the dependent ones solved (Constraints; with lib = casadi the rootfinder, `_dependent`)."""
        cons = self.constraints
        if lib is np:
            q, qd = self.q_ref.copy(), self.qd_ref.copy()
            q[self.ri] += x
            qd[self.ri] += xd
            q1 = cons.position(q)
            if q1 is None:
                raise ParameterError(f"--set {' '.join(f'{self.coords[i]}_0' for i in self.ri)}: no point of "
                                     f"{self.model.name}'s constraints near its reference has "
                                     + " and ".join(f"{self.coords[i]} = {q[i]:g}" for i in self.ri)
                                     + f" ({', '.join(cons.dependent)} solved from them on the reference's branch)")
            return np.concatenate([q1, cons.rates(q1, qd)])
        ind = lib.vertcat(*[float(self.q_ref[i]) + x[j] for j, i in enumerate(self.ri)])
        rates = lib.vertcat(*[float(self.qd_ref[i]) + xd[j] for j, i in enumerate(self.ri)])
        dep = self._dependent(lib.DM(self.q_ref[cons.dep]), ind)
        q = [None] * self.nq
        for j, i in enumerate(self.ri):
            q[i] = ind[j]
        for j, i in enumerate(cons.dep):
            q[i] = dep[j]
        q = lib.vertcat(*q)
        J = self.model.casadi.constraints(lib.DM(self.P), q)[1]
        dep_rates = -lib.solve(J[:, list(cons.dep)], J[:, list(self.ri)] @ rates)
        qd = [None] * self.nq
        for j, i in enumerate(self.ri):
            qd[i] = rates[j]
        for j, i in enumerate(cons.dep):
            qd[i] = dep_rates[j]
        return lib.vertcat(q, *qd)

    @cached_property
    def _dependent(self):
        """CasADi's Newton rootfinder (guess, independent coordinates) -> the dependent
        coordinates on phi = 0, from the reference's values: the offsets a reduced motion
        takes are small (CAP), so the reference's branch. Its residual tolerance 1e-14 of
        the constraints' terms at the reference (|Phi_q| |q|; phi's rounding is some 1e-16 of
        them), its step tolerance 1e-15 of the coordinates' size; a Newton that
        does not converge raises (error_on_fail), never an unconverged point."""
        import casadi as ca

        cons = self.constraints
        guess = ca.SX.sym("dependent", len(cons.dep))
        ind = ca.SX.sym("independent", self.n)
        q = [None] * self.nq
        for j, i in enumerate(self.ri):
            q[i] = ind[j]
        for j, i in enumerate(cons.dep):
            q[i] = guess[j]
        phi = self.model.casadi.constraints(ca.DM(self.P), ca.vertcat(*q))[0]
        J = cons._evaluate(self.q_ref)[1]
        terms = float(np.max(np.abs(J) @ np.abs(self.q_ref)))
        terms = terms if terms > 0 else 1.0
        size = max(1.0, float(np.max(np.abs(self.q_ref))))
        G = ca.Function("constraints_dependent", [guess, ind], [phi])
        return ca.rootfinder("dependent", "newton", G, {"error_on_fail": True, "abstol": 1e-14 * terms,
                                                        "abstolStep": 1e-15 * size, "max_iter": 50})

    def state_jacobian(self, Y: np.ndarray) -> np.ndarray:
        """d state / d (x, xd) at full states Y (2 nq, N): (N, 2 nq, 2 n): the identity on the
        reduced rows; the cyclic rates' rows their exact derivatives (CasADi, through
        `cyclic_rates`)."""
        N, n, nq = Y.shape[1], self.n, self.nq
        dY = np.zeros((N, 2 * nq, 2 * n))
        dY[:, np.concatenate([self.ri, nq + self.ri]), np.arange(2 * n)] = 1.0
        if self.ci:
            J = self._rates_jacobian.map(N)(Y)  # (cyclic, 2 nq) per set, stacked along columns
            J = np.asarray(J, float).reshape(len(self.ci), N, 2 * nq).transpose(1, 0, 2)
            cols = np.concatenate([self.ri, nq + self.ri])
            for j, i in enumerate(self.ci):
                dY[:, nq + i, :] = J[:, j, cols]
        return dY

    @cached_property
    def _rates_jacobian(self):
        import casadi as ca

        y = ca.SX.sym("y", 2 * self.nq)
        rates = self.model.casadi.cyclic_rates(ca.DM(self.P), y[:self.nq], y[self.nq:])
        return ca.Function("cyclic_rates_jacobian", [y], [ca.jacobian(rates, y)])

    @cached_property
    def first_order(self) -> np.ndarray:
        """A (2n, 2n) of z' = A z, z = (x, x'), from the generated operator at the reference."""
        from gyro.equilibrium import operators

        from gyro.qep import companion_matrix

        M, D, K = (np.asarray(X, float)[0] for X in operators(self.model, self.P[None], self.qe[None]))
        return companion_matrix(M, D, K)

    @cached_property
    def rhs(self):
        """z -> f(z) (CasADi Function, 2n -> 2n): the full equations in the reduced state, the
        cyclic rates from their momenta, the inputs zero."""
        import casadi as ca

        sym = ode.symbolic(self.model)
        zeros = [ca.DM.zeros(v.numel()) for v in sym.inputs]
        if self.constraints is not None:  # the state through a rootfinder: MX, the equations as a call
            z = ca.MX.sym("z", 2 * self.n)
            Y = self.state(ca.vertsplit(z[:self.n]), ca.vertsplit(z[self.n:]), ca)
            ydot = ode.rhs(self.model)(Y, ca.DM(self.P), *zeros)
        else:
            z = ca.SX.sym("z", 2 * self.n)
            Y = self.state(ca.vertsplit(z[:self.n]), ca.vertsplit(z[self.n:]), ca)
            ydot = ca.substitute([sym.ydot], [sym.y, sym.p, *sym.inputs], [Y, ca.DM(self.P), *zeros])[0]
        return ca.Function("reduced_rhs", [z], [ca.vertcat(z[self.n:], ydot[self.nq + self.ri])])


def uniform_times(t) -> np.ndarray:
    t = np.asarray(t, float)
    if t.ndim != 1 or t.size < 2 or t[0] != 0.0 or np.any(np.diff(t) <= 0):
        raise ValueError("the sample times must be increasing from t = 0")
    if not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0.0):
        raise ValueError("the linear motion takes uniform sample times")
    return t


def first_order_hold(A: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Ad, B0, B1) of one step h of z' = A z + r with r linear over the step, in rows:
    z(h) = z(0) Ad + r(0) B0 + r(h) B1 (the exponential of the augmented matrix, as
    scipy.signal.lsim's interpolating hold)."""
    from scipy.linalg import expm

    n = A.shape[0]
    M = np.zeros((3 * n, 3 * n))
    M[:n, :n], M[:n, n:2 * n], M[n:2 * n, 2 * n:] = A * h, np.eye(n) * h, np.eye(n)
    E = expm(M.T)
    return E[:n, :n], E[n:2 * n, :n] - E[2 * n:, :n], E[2 * n:, :n]


def propagate(Ad: np.ndarray, g: np.ndarray, z0: np.ndarray, chunk: int = 64) -> np.ndarray:
    """z_{k+1} = z_k Ad + g_k (rows), k = 0 .. N - 2, from z0: (N, n). In chunks of `chunk`
    steps: within each the response to g by one product with the powers Ad^j, the chunks'
    starts one after another (the same recurrence as a step-by-step loop, in NumPy's
    matrix products)."""
    N, n = g.shape[0] + 1, z0.size
    c = max(1, min(chunk, N - 1))
    nc = -(-(N - 1) // c)
    G = np.zeros((nc * c, n))
    G[:N - 1] = g
    P = [np.eye(n)]
    for _ in range(c):
        P.append(P[-1] @ Ad)
    P = np.array(P)  # (c + 1, n, n)
    j, i = np.nonzero(np.arange(c)[:, None] < np.arange(c + 1)[None, :])
    T = np.zeros((c, c + 1, n, n))
    T[j, i] = P[i - 1 - j]  # the response at step i of the chunk to g at its step j < i
    S = (G.reshape(nc, c * n) @ T.transpose(0, 2, 1, 3).reshape(c * n, (c + 1) * n)).reshape(nc, c + 1, n)
    X = np.empty((nc + 1, n))
    X[0] = z0
    for m in range(nc):
        X[m + 1] = X[m] @ P[c] + S[m, c]
    z = (np.einsum("mk,ikl->mil", X[:nc], P[:c]) + S[:, :c]).reshape(nc * c, n)
    return np.vstack([z, X[nc:]])[:N]


def linear_motion(red: ReducedState, z0: np.ndarray, t, corrections: int = 2, fine: int = 32):
    """The linear motion z' = A z from z0 and its correction at the sample times t (uniform
    from 0): (z_L, e, steps), each (times, 2n). The linear motion is propagated exactly
    (the exponential of A, `first_order_hold` and `propagate`) over a fine grid, `fine`
    samples per shortest period 2 pi/(2 omega_max) of the remainder's quadratic terms; e
    after `corrections` steps of Picard's iteration e' = A e + r(z_L + e), e(0) = 0,
    r(z) = f(z) - A z (the terms of second and higher order, and the reference's residual
    f(0)), each the linear system driven by the remainder (Duhamel's integral, r linear
    between the samples). `steps` is the fine grid's steps per sample interval (1 without a
    correction: the linear motion alone is exact on the sample grid). A grid of more than
    FINE_BUDGET samples times states stops with IntegrationBudget, before any work. Kept on
    `red` for its later calls with the same arguments (a linear level, then an integrated
    level's scale and the motion question's floor, on one motion: read-only arrays)."""
    memo = red.__dict__.setdefault("_linear_motions", {})
    key = (np.asarray(z0, float).tobytes(), np.asarray(t, float).tobytes(), corrections, fine)
    if key not in memo:
        memo.clear()  # the latest only
        memo[key] = _linear_motion(red, z0, t, corrections, fine)
        for a in memo[key][:2]:
            a.flags.writeable = False
    return memo[key]


def _linear_motion(red: ReducedState, z0: np.ndarray, t, corrections: int, fine: int):
    t = uniform_times(t)
    A = red.first_order
    n2 = A.shape[0]
    w_max = float(np.max(np.abs(np.linalg.eigvals(A))))
    h = 2 * np.pi / (2 * w_max) / fine if w_max > 0 else t[-1]
    per = max(1, int(np.ceil((t[1] - t[0]) / h))) if corrections else 1
    size = ((t.size - 1) * per + 1) * n2
    if not size <= FINE_BUDGET:
        raise IntegrationBudget(f"the linear motion's correction over {t[-1]:.6g} s needs {size / n2:.3g} samples "
                                f"({fine} per period of the remainder's fastest term, |eig|max = {w_max:.6g} 1/s), "
                                f"over its budget of {FINE_BUDGET / n2:.3g}: a shorter horizon")
    tf = np.linspace(0.0, t[-1], (t.size - 1) * per + 1)
    Ad, B0, B1 = first_order_hold(A, tf[1] - tf[0])
    zL = propagate(Ad, np.zeros((tf.size - 1, n2)), np.asarray(z0, float))
    f = red.rhs.map(tf.size) if ode.WATCH is None or tf.size <= CHUNK else None
    e = np.zeros_like(zL)
    if f is None:  # metered: the corrections cost alike
        ode.WATCH.plan([1.0] * corrections)
    for c in range(corrections):
        z = zL + e
        r = _remainder(red, z, f, f"the linear motion's correction {c + 1} of {corrections}") - z @ A.T
        e = propagate(Ad, r[:-1] @ B0 + r[1:] @ B1, np.zeros(n2))
    return zL[::per], e[::per], per


CHUNK = 10_000  # samples of the remainder evaluated at a time where a watch meters it (ode.watching)


def _remainder(red: ReducedState, z: np.ndarray, f, what: str) -> np.ndarray:
    """f(z) over the samples z (rows): at once, or where a watch is on (ode.watching: the
    command line's budget, a terminal's bar) in CHUNKs, metered as `what`; its evaluation
    is most of the linear motion's work (7.6 of 9.8 s on the torsion gyrocompass over 1 s,
    39000 samples)."""
    watch = ode.WATCH
    if watch is None or z.shape[0] <= CHUNK:
        return _evaluated(red, f, z)
    tick, finished = watch.meter(what)
    out = np.empty_like(z)
    each = red.rhs.map(CHUNK)
    try:
        for s in range(0, z.shape[0], CHUNK):
            block = z[s:s + CHUNK]
            g = each if block.shape[0] == CHUNK else red.rhs.map(block.shape[0])
            out[s:s + CHUNK] = _evaluated(red, g, block)
            tick((s + block.shape[0]) / z.shape[0])
    finally:
        finished()
    return out


def _evaluated(red: ReducedState, f, z: np.ndarray) -> np.ndarray:
    """f (a map of red.rhs) over the samples z (rows). For a model with multipliers its
    rootfinder may meet no point of the constraints (a linear motion that swings past their
    reach): one line saying where, CasADi's dump of the inputs kept off stderr."""
    if red.constraints is None:
        return np.asarray(f(z.T)).T
    try:
        with ode.stderr_silenced():
            return np.asarray(f(z.T)).T
    except RuntimeError:
        x = z[np.argmax(np.max(np.abs(z[:, :red.n]), axis=1)), :red.n]
        at = ", ".join(f"{red.coords[i]} = {red.q_ref[i] + v:.6g}" for i, v in zip(red.ri, x))
        raise FloatingPointError(f"the linear motion reaches {at}, where Newton's method finds no point of the "
                                 f"constraints for {', '.join(red.constraints.dependent)} on the reference's "
                                 "branch") from None


def integrate_reduced(red: ReducedState, z0: np.ndarray, t, method: str = "DOP853", rtol: float = 1e-9,
                      scale: np.ndarray | None = None, floor: float = 100.0) -> np.ndarray:
    """The full equations integrated from the reduced state z0: the reduced coordinates
    q_ref + x at the times t (times, n). `scale` (2: the displacements' and the rates' size)
    sets the absolute tolerances, 1e-3 rtol of it (default: the linear motion's largest |x|,
    |x'|), so a small perturbation is resolved, but not below `floor` eps of the reference's
    largest coordinate (and that times the fastest frequency for the rates): there the
    state's rounding, amplified by stiff springs, would stall the steps. A model with
    multipliers: projected onto its constraints (Constraints.project) at each sample time
    and wherever its drift comes near the tolerance (ode.projected)."""

    t = np.asarray(t, float)
    n = red.n
    if scale is None:
        zL = linear_motion(red, z0, t, corrections=0)[0]
        scale = np.array([np.max(np.abs(zL[:, :n])), np.max(np.abs(zL[:, n:]))])
    size = np.max(np.abs(red.q_ref[red.ri])) if n else 0.0
    lo = floor * np.finfo(float).eps * size
    w_max = float(np.max(np.abs(np.linalg.eigvals(red.first_order))))
    atol = np.empty(2 * red.nq)
    atol[:red.nq] = max(1e-3 * rtol * scale[0], lo, np.finfo(float).tiny)
    atol[red.nq:] = max(1e-3 * rtol * scale[1], lo * w_max, np.finfo(float).tiny)
    cons = red.constraints
    project = cons.tolerance(rtol, atol).project if cons is not None else None
    Y = ode.integrate_state(red.model, red.P, red.state(z0[:n], z0[n:]), t, method, rtol, atol, project=project)
    return Y[:, red.ri]


def group_max(v: np.ndarray, units: list) -> np.ndarray:
    """Per entry of x (n) or (x, x') (2n), the largest of its unit group (displacements in m,
    in rad, their rates; `units` per reduced coordinate): the scale of a per-coordinate
    estimate."""
    n = len(units)
    out = np.empty_like(v)
    for half in range(0, v.size, n):
        for unit in set(units):
            idx = [half + j for j, u in enumerate(units) if u == unit]
            out[idx] = np.max(v[idx])
    return out


# ----------------------------------------------------------------------------- the motion question
# The `motion` question's levels for any model (gyro/questions/motion.py): a level declares
# {"kind": "trajectory", "module": "gyro.analyses.motion", "method": "linear" | a SciPy
# method, "rtol": R, "quantities": the reduced coordinates, optionally "cap_of": one of
# CAP_OF}; for_model(model) gives the protocol's INITIAL, Motion and motion_answer. The
# constants are the torsion gyrocompass's, measured there (paper 003's motion levels,
# docs/hierarchy.md), checked on paper 001's gyrohorizon compass (its error map and its joint
# draws toward the cap, bench/levels.py) and on models written outside the package
# (tests/cli/test_motion_generic.py).
FACTOR = 2.0  # the bound over the correction: measured error/bound 0.50..0.55 below the cap (bench)
# the largest estimate, over the linear motion's size (CAP_OF), for which it is a bound:
# measured error over it on the torsion gyrocompass (over the excursion) 0.50..0.55 up to
# 0.15, 0.62 at 0.30, 0.77 at 0.58, 1.0 at 0.84, 2.0 at 1.3; on the gyrohorizon compass (over
# the displacement, at most a radian) at most 0.57 below 0.25, 0.70 at 0.26, 0.77 at 0.61,
# 1.0 at 0.66 (a held-out draw 2 rad off) and 1.2 at 1.2 (bench/results/levels.json
# 'toward_the_cap' of 'torsion_motion_map' and of 'ghc_motion_error_map')
CAP = 0.25
# what the cap is a fraction of (a level's declared "cap_of"): "excursion", the linear
# motion's largest distance from its start (the default; the torsion gyrocompass's question
# scale); "displacement", its largest distance from the reference, at most 1 (a radian of an
# angle): the perturbation's size, which sets the remainder's relative size, for a motion
# that hardly leaves its offset start within the horizon (the gyrohorizon compass's Earth set
# over 2 s: its excursion a tenth of its displacement); beyond a radian an angle's terms of
# every order are alike (docs/hierarchy.md, paper 001's levels)
CAP_OF = ("excursion", "displacement")
ROUNDING = 4.0  # the exponential's rounding per step, in eps of the largest |z_L|
CORRECTIONS = 2  # Picard steps: the second holds every term of third order
FINE = 32  # samples per shortest period 2 pi/(2 omega_max) of the remainder's quadratic terms
FINER = 1e-2  # the integrated level's second run's tolerance, of the first's
FLOOR = 100.0  # the integrator's absolute tolerance, at least this many eps of the reference


def integration_floor(size, rtol: float):
    """The integrated level's smallest estimate (absolute) of a coordinate whose unit group's
    largest magnitude is `size`: twice the finer run's tolerance on it. Known before the
    runs from a prediction of the motion (gyro.questions.motion.floor)."""
    return 2 * rtol * FINER * np.asarray(size, float)


class _Generic:
    """The motion protocol of one model: INITIAL over its reduced coordinates (`<c>_0`, a
    displacement from the reference, `<c>_d0`, a rate offset, all 0 by default), Motion and
    motion_answer."""

    def __init__(self, model):
        self.model = model
        units = model.meta.get("coordinate_units", {})
        self.reduced = list(model.meta["reduced"])
        self.units = [units.get(c, "") for c in self.reduced]
        self.INITIAL = {}
        for c, u in zip(self.reduced, self.units):
            self.INITIAL[f"{c}_0"] = (u, 0.0, f"{c} at t = 0, off its reference")
            self.INITIAL[f"{c}_d0"] = (f"{u}/s" if u else "1/s", 0.0, f"the rate of {c} at t = 0, off its reference")

    def Motion(self, params: dict, **initial):
        unknown = sorted(set(initial) - set(self.INITIAL))
        if unknown:
            raise ParameterError(f"{self.model.name} motion: unknown initial condition {unknown[0]!r}; "
                                 f"it takes {', '.join(self.INITIAL)}")
        vals = {k: float(initial.get(k, v[1])) for k, v in self.INITIAL.items()}
        bad = [k for k, v in vals.items() if not np.isfinite(v)]
        if bad:
            raise ParameterError(f"--set {bad[0]}: the initial condition must be a finite number")
        z0 = np.array([vals[f"{c}_0"] for c in self.reduced] + [vals[f"{c}_d0"] for c in self.reduced])
        return _Motion(self.model, dict(params), z0)

    integration_floor = staticmethod(integration_floor)

    def motion_answer(self, motion, t, method: str = "linear", rtol: float = 1e-9, cap_of: str = CAP_OF[0]):
        """The reduced coordinates q_ref + x at the times t (times, n) and an estimate of each
        one's largest absolute error over t."""
        return motion_answer(motion.reduced, motion.z0, t, self.units, method, rtol, cap_of)


class _Motion:
    def __init__(self, model, params: dict, z0: np.ndarray):
        self.model, self.params, self.z0 = model, params, z0

    @cached_property
    def reduced(self) -> ReducedState:
        return ReducedState(self.model, self.params)


def linear_size(x: np.ndarray, cap_of: str = CAP_OF[0]) -> float:
    """The size of a linear motion x (times, n: displacements from the reference) the cap
    is a fraction of (CAP_OF)."""
    if cap_of not in CAP_OF:
        raise ValueError(f"cap_of {cap_of!r}: one of {', '.join(CAP_OF)}")
    if cap_of == "excursion":
        return float(np.max(np.sqrt(np.sum((x - x[:1]) ** 2, axis=1))))
    return min(float(np.max(np.sqrt(np.sum(x ** 2, axis=1)))), 1.0)


def linear_answer(red: ReducedState, z0: np.ndarray, t, units: list, cap: float = CAP, cap_of: str = CAP_OF[0]):
    """The linear level's answer: q_ref + x_L at the times t (times, n) and its estimate,
    FACTOR times the correction's largest |e| over each coordinate's unit group plus the
    rounding, infinite where its largest exceeds `cap` of the linear motion's size
    (`linear_size`, of `cap_of`; an error map measures the uncapped estimate with cap = inf)."""
    n = red.n
    linear_size(np.zeros((1, n)), cap_of)  # an unknown cap_of refused before the work
    zL, e, per = linear_motion(red, z0, t, CORRECTIONS, FINE)
    est = FACTOR * group_max(np.max(np.abs(e), axis=0), units)[:n]
    est += ROUNDING * np.finfo(float).eps * per * (len(t) - 1) * np.max(np.abs(zL[:, :n]))
    size = linear_size(zL[:, :n], cap_of)
    if not np.max(est) <= cap * size:  # beyond the iteration's reach: no bound
        est = np.full(n, np.inf)
    return red.q_ref[red.ri] + zL[:, :n], est


def motion_answer(red: ReducedState, z0: np.ndarray, t, units: list, method: str = "linear", rtol: float = 1e-9,
                  cap_of: str = CAP_OF[0]):
    """The `motion` question's answer from the reduced state z0: `linear` (linear_answer,
    capped against the linear motion's size of `cap_of`), or the full equations integrated
    by a SciPy method at rtol and rtol FINER, the estimate twice their difference, not below
    twice the finer run's tolerance on the coordinates' size (an error the two runs share
    where both sit at the absolute tolerance's floor)."""
    t = np.asarray(t, float)
    if red.constraints is not None:  # a start the constraints cannot meet: bad input, before any work
        red.state(z0[:red.n], z0[red.n:])
    if method == "linear":
        return linear_answer(red, z0, t, units, cap_of=cap_of)
    n = red.n
    try:
        zL = linear_motion(red, z0, t, CORRECTIONS, FINE)[0]
    except FloatingPointError:  # its correction past the constraints' reach (_evaluated): the scale needs none
        if red.constraints is None:
            raise
        zL = linear_motion(red, z0, t, corrections=0)[0]
    scale = np.array([np.max(np.abs(zL[:, :n])), np.max(np.abs(zL[:, n:]))])
    q, est = ode.two_tolerances(lambda r: integrate_reduced(red, z0, t, method, r, scale, FLOOR), rtol, FINER)
    return q, np.maximum(est, integration_floor(group_max(np.max(np.abs(q), axis=0), units), rtol))



def for_model(model) -> _Generic:
    """The `motion` question's protocol (INITIAL, Motion, motion_answer) for this model."""
    return _Generic(model)
