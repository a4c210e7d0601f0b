"""A model's equations of motion as an explicit ODE: y = (q, q'), y' = (q', M(q)^-1 f(q, q', ...)),
from the emitted CasADi mass matrix and forcing. One home for every integrator of the
runtime (the gimbal gyroscope's, the gyrohorizoncompass's, the precession's full level, the
forced response's shooting) and of the tests that integrate a model.

`symbolic(model)` gives the CasADi expressions (for Jacobians, substitutions and
integrators); `rhs(model)` a compiled CasADi Function rhs(y, p, *inputs) -> y', where the
inputs are the forcing's own after (params, q, qd) in the emitted order (the torsion
gyrocompass's given forces and their rates). `numpy_rhs` (SciPy's methods) calls it as C
(`compiled`: CasADi's code generator, compiled once per machine): 2.2 us a call on the
11-coordinate model against 82 us through the CasADi Function, the same bits."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from gyro.models import Model

_CACHE: dict = {}


class IntegrationBudget(RuntimeError):
    """An integration stopped by its budget of time or steps (a runaway on stiff or extreme
    input, a horizon too long for a level), saying how far it got: a numerical limit, exit 1
    at the command line. The one type every integrator of the runtime raises (each analysis
    names it too: gimbal, gyrohorizoncompass, precession, motion)."""


@dataclass(frozen=True)
class Symbolic:
    """y (2n), p (the parameters), inputs (the forcing's further inputs) as CasADi SX, and
    ydot: y' as an SX expression of them."""
    y: object
    p: object
    inputs: tuple
    ydot: object


# CasADi integrator options that keep SUNDIALS' own lines and CasADi's warnings on a NaN
# of the right-hand side (a horizon near 1e308) off stderr: the error raised says it
CASADI_QUIET = {"disable_internal_warnings": True, "show_eval_warnings": False}


class stderr_silenced:
    """Nothing on stderr while a compiled library runs (SUNDIALS' IDAS prints its error lines
    whatever the options, through CasADi's Python streams or file descriptor 2): both go to
    /dev/null; the exception it raises says what failed, in the command's one line."""

    def __enter__(self):
        import os
        import sys

        sys.stderr.flush()
        self.stream, self.saved = sys.stderr, os.dup(2)
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 2)
        os.close(null)
        sys.stderr = open(os.devnull, "w")
        return self

    def __exit__(self, *exc):
        import os
        import sys

        sys.stderr.close()
        sys.stderr = self.stream
        os.dup2(self.saved, 2)
        os.close(self.saved)
        return False


def _key(model: Model, what: str):
    return (what, model.name, str(getattr(model, "directory", "")), id(model))


def symbolic(model: Model, varying: bool = False) -> Symbolic:
    """The explicit ODE of a model as CasADi expressions (cached per model). `varying`: the
    equations with the model's time-varying parameters (metadata 'varying', the emitted
    `mass_matrix_varying`, `forcing_varying`), whose inputs then include the group
    `signals`: each such parameter's value and derivatives at t."""
    key = _key(model, "symbolic_varying" if varying else "symbolic")
    if key not in _CACHE:
        import casadi as ca

        cf = model.casadi
        meta = model.meta["functions"]
        suffix = "_varying" if varying else ""
        n = len(model.meta["coordinates"])
        y = ca.SX.sym("y", 2 * n)
        p = ca.SX.sym("p", len(model.param_names))
        specs = meta["forcing" + suffix]["inputs"][3:]
        extra = tuple(ca.SX.sym(spec["name"], len(spec["symbols"])) for spec in specs)
        f = getattr(cf, "forcing" + suffix)(p, y[:n], y[n:], *extra)
        # the mass matrix's own inputs after (params, q): those of the forcing by name
        by_name = {spec["name"]: x for spec, x in zip(specs, extra)}
        mm = [by_name[spec["name"]] for spec in meta["mass_matrix" + suffix]["inputs"][2:]]
        # with multipliers (metadata 'constraints'), the system's unknowns are (qdd, lambda):
        # the accelerations are its first n (an index-1 form, integrated as it is)
        ydot = ca.vertcat(y[n:], ca.solve(getattr(cf, "mass_matrix" + suffix)(p, y[:n], *mm), f)[:n])
        _CACHE[key] = Symbolic(y, p, extra, ydot)
    return _CACHE[key]


def rhs(model: Model, varying: bool = False):
    """The compiled CasADi Function rhs(y, p, *inputs) -> y' of a model (cached per model)."""
    key = _key(model, "rhs_varying" if varying else "rhs")
    if key not in _CACHE:
        import casadi as ca

        s = symbolic(model, varying)
        _CACHE[key] = ca.Function("rhs", [s.y, s.p, *s.inputs], [s.ydot])
    return _CACHE[key]


def numpy_rhs(model: Model, P, inputs=None):
    """y -> y' (a NumPy vector) at fixed parameters P, and the forcing's further inputs as
    a function of t (inputs(t) -> a tuple of vectors; zeros where None): the form SciPy's
    solve_ivp takes, fun(t, y). Through `compiled(model, "rhs")` where there is a compiler
    (the same operations, the same bits), through the CasADi Function otherwise."""
    s = symbolic(model)
    zeros = tuple(np.zeros(v.numel()) for v in s.inputs)
    c = compiled(model, "rhs")
    if c is not None:
        ins, (out,), call = c.buffers()
        y_buf, p_buf, extra_bufs = ins[0], ins[1], ins[2:]
        p_buf[:] = P
        for b, z in zip(extra_bufs, zeros):
            b[:] = z

        def fun(t, y):
            y_buf[:] = y
            if inputs is not None:
                for b, v in zip(extra_bufs, inputs(t)):
                    b[:] = v
            call()
            return out.copy()

        return fun
    import casadi as ca

    F = rhs(model)
    Pd = ca.DM(np.asarray(P, float))

    def fun(t, y):
        extra = zeros if inputs is None else inputs(t)
        return np.asarray(F(y, Pd, *extra)).ravel()

    return fun


class Compiled:
    """A CasADi Function of this module (`rhs`, `variational`) as C: CasADi's code generator
    writes the Function's own operations, gyro.cbackend compiles them once per machine
    (content-addressed, cached like the model's C). A call from SciPy then costs the C and a
    few copies, not CasADi's argument conversions: on the torsion gyrocompass's right-hand
    side 82 us through the Function, 2.2 us this way (its 1 s motion at rtol 1e-9 and 1e-11
    takes 282,549 calls)."""

    def __init__(self, F, lib):
        import ctypes

        self.fn = getattr(lib, F.name())
        self.fn.restype = ctypes.c_int
        self.sizes_in = [F.nnz_in(i) for i in range(F.n_in())]
        self.sizes_out = [F.nnz_out(i) for i in range(F.n_out())]
        self.sz = (F.sz_arg(), F.sz_res(), F.sz_iw(), F.sz_w())

    def buffers(self):
        """(inputs, outputs, call): arrays of the Function's nonzeros (dense matrices column
        by column, as CasADi orders them) bound to one C call; call() fills the outputs."""
        import ctypes

        ins = [np.zeros(k) for k in self.sizes_in]
        outs = [np.zeros(k) for k in self.sizes_out]
        sz_arg, sz_res, sz_iw, sz_w = (max(k, 1) for k in self.sz)
        iw, w = np.zeros(sz_iw, dtype=np.int64), np.zeros(sz_w)
        arg = (ctypes.c_void_p * max(sz_arg, len(ins)))(*[b.ctypes.data for b in ins])
        res = (ctypes.c_void_p * max(sz_res, len(outs)))(*[b.ctypes.data for b in outs])
        iw_p, w_p, fn = iw.ctypes.data_as(ctypes.c_void_p), w.ctypes.data_as(ctypes.c_void_p), self.fn
        keep = (ins, outs, iw, w, arg, res)

        def call():
            if fn(arg, res, iw_p, w_p, 0):
                raise ArithmeticError("the compiled equations of motion failed")
            return keep

        return ins, outs, call


def compiled(model: Model, what: str) -> Compiled | None:
    """`rhs(model)` or `variational(model)` compiled (cached per model and, as C, per
    machine); None without a compiler or where the build fails, so that the caller takes
    the CasADi Function."""
    key = _key(model, "compiled_" + what)
    if key not in _CACHE:
        import hashlib

        from gyro import cbackend

        F = {"rhs": rhs, "variational": variational}[what](model)
        try:
            cbackend._available()
            import casadi as ca

            cg = ca.CodeGenerator(what, {"with_header": False, "casadi_int": "long long int"})
            cg.add(F)
            text = cg.dump()
            digest = hashlib.sha256(text.encode()).hexdigest()[:16]
            src = cbackend._writable_cache() / "casadi-sources" / f"{what}-{digest}.c"
            if not src.exists() or src.read_text() != text:
                src.parent.mkdir(parents=True, exist_ok=True)
                tmp = src.with_suffix(f".{os.getpid()}.tmp")
                tmp.write_text(text)
                os.replace(tmp, src)  # atomic: another process may write the same bytes
            label = {"rhs": "equations of motion", "variational": "variational equations"}[what]
            # -O1 after the flags' -O3: CasADi's straight-line code gains nothing from -O3
            # (the torsion gyrocompass's variational equations, 2 MB of C: 23 us a call at -O1,
            # 22 us at -O3), whose compile takes 80 s there against 8 s
            lib = cbackend._shared(f"{what}-{digest}", (src,), (), ("-O1",),
                                   notice=f"the generated C of {model.name}'s {label}")
            _CACHE[key] = Compiled(F, lib)
        except cbackend.CompilerUnavailable:
            _CACHE[key] = None
    return _CACHE[key]


def jacobian(model: Model):
    """The compiled CasADi Function jac(y, p, *inputs) -> (y', dy'/dy) of a model (cached per
    model): the equations of motion and their Jacobian in the state."""
    key = _key(model, "jacobian")
    if key not in _CACHE:
        import casadi as ca

        s = symbolic(model)
        _CACHE[key] = ca.Function("jacobian", [s.y, s.p, *s.inputs], [s.ydot, ca.jacobian(s.ydot, s.y)])
    return _CACHE[key]


def variational(model: Model):
    """The compiled CasADi Function var(y, Phi, p, *inputs) -> (y', (dy'/dy) Phi) of a model
    (cached per model): the equations of motion with their variational equations, whose
    solution from Phi(0) = I is the state transition matrix (for a periodic forcing over
    one period, the monodromy matrix)."""
    key = _key(model, "variational")
    if key not in _CACHE:
        import casadi as ca

        s = symbolic(model)
        n = s.y.numel()
        Phi = ca.SX.sym("Phi", n, n)
        _CACHE[key] = ca.Function("variational", [s.y, Phi, s.p, *s.inputs],
                                  [s.ydot, ca.jacobian(s.ydot, s.y) @ Phi])
    return _CACHE[key]


def numpy_variational(model: Model, P, inputs=None):
    """(t, Y) -> Y' for solve_ivp on Y = (y, Phi column-major): the equations of motion at
    fixed parameters P with their variational equations (`variational`), the forcing's
    further inputs a function of t as in `numpy_rhs`. Returns (fun, n), n the state's size."""
    import casadi as ca

    s = symbolic(model)
    n = s.y.numel()
    zeros = tuple(np.zeros(v.numel()) for v in s.inputs)
    c = compiled(model, "variational")
    if c is not None:  # the same operations as the Function below, in C
        ins, (yd, phid), call = c.buffers()
        y_buf, phi_buf, p_buf, extra_bufs = ins[0], ins[1], ins[2], ins[3:]
        p_buf[:] = P
        for b, z in zip(extra_bufs, zeros):
            b[:] = z

        def fun_c(t, Y):
            y_buf[:] = Y[:n]
            phi_buf[:] = Y[n:]  # Phi column-major: CasADi's order of a dense matrix's nonzeros
            if inputs is not None:
                for b, v in zip(extra_bufs, inputs(t)):
                    b[:] = v
            call()
            return np.concatenate([yd, phid])

        return fun_c, n
    F = variational(model)
    Pd = ca.DM(np.asarray(P, float))

    def fun(t, Y):
        extra = zeros if inputs is None else inputs(t)
        yd, phid = F(Y[:n], Y[n:].reshape(n, n, order="F"), Pd, *extra)
        return np.concatenate([np.asarray(yd).ravel(), np.asarray(phid).ravel(order="F")])

    return fun, n


def budgeted(fun, label: str, t_end: float, max_s: float, max_steps: float, error=RuntimeError):
    """fun(t, y) for solve_ivp that raises `error` (IntegrationBudget) past
    max_steps evaluations or max_s seconds from now, saying how far the run got."""
    import time

    start, calls = time.perf_counter(), [0]

    def rhs(tt, y):
        calls[0] += 1
        if calls[0] % 1000 == 0 and (calls[0] > max_steps or time.perf_counter() - start > max_s):
            raise error(f"{label} stopped at t = {tt:.6g} s of {t_end:.6g} s after {calls[0]} "
                        f"evaluations, {time.perf_counter() - start:.0f} s (its budget)")
        return fun(tt, y)

    return rhs


class OverBudget(IntegrationBudget):
    """A watched block of integrations (`watching`) whose predicted cost is over its budget,
    raised after its pilot: `seconds` the prediction, `measured` what it was measured on."""

    def __init__(self, seconds: float, measured: str, budget: float):
        self.seconds, self.budget, self.measured = seconds, budget, measured
        super().__init__(f"about {seconds:.0f} s predicted ({self.measured}), over the budget of {budget:.0f} s")


WATCH = None  # the `watching` block the integrations run in now, or None


class watching:
    """`with watching(label, budget, progress, spent):` every SciPy integration inside
    (integrate_state), and any long work that meters itself (`meter`: the linear motion's
    corrections), shows how far it is (a tqdm bar on stderr where `progress`), and the block
    is held to `budget` seconds (None: none) with `spent` already gone: once a piece has
    taken PILOT seconds, its time so far carried to its end, plus the pieces before it and
    those still planned (`plan`: their costs relative to this one's, two_tolerances declares
    its second run), is the predicted cost, checked as it goes; over the budget the piece
    stops there (OverBudget), a few seconds in rather than at the end."""

    PILOT = 1.0  # s of a run before its prediction is trusted
    EVERY = 100  # evaluations of the right-hand side between two looks at the clock

    def __init__(self, label: str, budget: float | None = None, progress: bool = False, spent: float = 0.0):
        self.label, self.budget, self.progress = label, budget, progress
        self.spent, self.later, self.runs = spent, [], 0  # spent: the command's time before the block

    def __enter__(self):
        global WATCH
        self.saved, WATCH = WATCH, self
        return self

    def __exit__(self, *exc):
        global WATCH
        WATCH = self.saved
        return False

    def plan(self, weights) -> None:
        """The pieces of work to come, each one's cost relative to the first of them."""
        self.later = list(weights)

    def meter(self, what: str):
        """(tick(fraction done), done()) of one piece of work, `what`: its bar, and, once it
        has taken PILOT seconds, its time carried to its end and to the planned pieces after
        it, plus what the block spent before, against the budget (OverBudget)."""
        import sys
        import time

        weight = self.later.pop(0) if self.later else 1.0
        after = sum(self.later) / weight  # the planned pieces after this one, in units of this one
        bar = None
        if self.progress:
            from tqdm import tqdm

            bar = tqdm(total=100, desc=f"{self.label} ({what})", unit="%", leave=False, file=sys.stderr)
        start = time.perf_counter()

        def tick(frac: float) -> None:
            frac = min(max(frac, 0.0), 1.0)
            took = time.perf_counter() - start
            if bar is not None and int(100 * frac) > bar.n:
                bar.update(int(100 * frac) - bar.n)  # drawn at tqdm's own pace
            if self.budget is not None and took >= self.PILOT and frac > 0:
                predicted = self.spent + took / frac * (1 + after)
                if predicted > self.budget:
                    done()
                    raise OverBudget(predicted, f"measured on {100 * frac:.2g}% of {what}", self.budget)

        def done() -> None:
            nonlocal bar
            if bar is not None:
                bar.close()
                bar = None

        def finished() -> None:
            self.spent += time.perf_counter() - start
            done()

        return tick, finished

    def wrap(self, fun, t0: float, t1: float):
        """fun(t, y) for solve_ivp, watched over [t0, t1]; call its done() after the run."""
        self.runs += 1
        tick, finished = self.meter(f"integration {self.runs}")
        calls, span = [0], (t1 - t0) or 1.0

        def rhs(tt, y):
            calls[0] += 1
            if calls[0] % self.EVERY == 0:
                tick((tt - t0) / span)
            return fun(tt, y)

        rhs.done = finished
        return rhs


def two_tolerances(run, rtol: float, finer: float = 1e-2):
    """An integrated answer and its error estimate by two tolerances (the `motion` question's
    integrated levels): run(r) -> the answer (times, columns) at relative tolerance r; the
    answer is the run at rtol * finer, the estimate per column twice its largest difference
    from the run at rtol: an estimate of the coarser run's global error that bounds the
    finer one's where the error falls with the tolerance (not near a separatrix:
    docs/gimbal.md)."""
    if WATCH is not None:  # the second run's cost, of the first's: DOP853's steps go as rtol^(1/8)
        WATCH.plan([1.0, finer ** (-1 / 8)])  # (measured 1.70 on the torsion gyrocompass at 1e-9)
    q1 = run(rtol)
    q2 = run(rtol * finer)
    return q2, 2 * np.max(np.abs(q1 - q2), axis=0)


# SciPy's multistep methods: a restart costs them their history (BDF restarted every 1e-4 s
# at rtol 1e-10 still corrects by 0.7 of the tolerance, its first steps' error), so their runs
# are not projected, only held to the manifold at the samples (`checked`)
MULTISTEP = ("BDF", "LSODA")


def checked(Y, t, method: str, rtol: float, project) -> np.ndarray:
    """The samples Y of an unprojected run (a MULTISTEP method), each projected onto the
    manifold (`project`, integrate_state) as an answer, where each correction is within the
    tolerance; FloatingPointError at the first that is not: the run has left the manifold by
    more than its tolerance allows."""
    out = Y.copy()
    for i in range(1, t.size):
        out[i], ratio = project(Y[i], Y[i - 1])
        if not ratio <= 1.0:
            raise FloatingPointError(f"{method} leaves the constraints by {ratio:.3g} times what rtol {rtol:g} allows "
                                     f"at t = {t[i]:.6g} s (a multistep method is not projected back onto them; "
                                     "DOP853, RK45 and Radau are)")
    return out


SHORTEST = 2.0**-30  # of a sample interval: the shortest piece `projected` runs
# the first piece, of the first sample interval: a whole interval first would be run in vain
# where the drift over it is far over the tolerance (1000 s at once: 3500 times, the four-bar)
FIRST = 64


def projected(fun, t, y0, method: str, rtol: float, atol, kw: dict, project) -> np.ndarray:
    """States (len(t), size) of solve_ivp's `method` on fun from y0, run in pieces, each
    piece's end projected (`project`, integrate_state), every sample time the end of one.
    A piece whose correction is more than its tolerance allows (ratio > 1) is run again,
    shorter: the drift off a manifold grows with the piece's length, as its square for the
    index-1 form of a model with constraints (docs/models.md), so the length is the last
    times 0.5/sqrt(ratio), within [1/100, 1/2]; after an accepted piece it doubles (ratio
    <= 1/4), grows by 1/4 (<= 1/2) or stays. A piece of SHORTEST of its interval still
    corrected by more: FloatingPointError."""
    from scipy.integrate import solve_ivp

    Y = np.empty((t.size, y0.size))
    Y[0] = y = y0
    if t.size < 2:
        return Y
    span = (t[1] - t[0]) / FIRST  # doubled while the corrections are small: a few pieces at most
    for i in range(1, t.size):
        a, b = t[i - 1], t[i]
        while a < b:
            c = b if b - a <= span else a + span
            sol = solve_ivp(fun, (a, c), y, method=method, rtol=rtol, atol=atol, **kw)
            if sol.status != 0:
                raise FloatingPointError(f"{method} stopped at t = {sol.t[-1]:.6g} s: {sol.message}")
            y1, ratio = project(sol.y[:, -1], y)
            if not np.isfinite(ratio):
                raise FloatingPointError(f"at t = {c:.6g} s the motion cannot be put back on its constraints "
                                         "(Newton's method meets no point of them from there)")
            if ratio > 1.0:
                if not c - a > (b - a) * SHORTEST:
                    raise FloatingPointError(
                        f"the motion leaves its constraints faster than the tolerance allows: from t = {a:.6g} s to "
                        f"{c:.6g} s the correction back onto them is {ratio:.3g} times what rtol {rtol:g} allows")
                span = (c - a) * min(max(0.5 / math.sqrt(ratio), 0.01), 0.5)
                continue
            # accepted: never shorter; twice as long where the square of the drift allows it,
            # a little longer where a floor of the correction (a restarted multistep method's
            # first steps: BDF's about 0.25 at any length) says little of the drift
            grow = 2.0 if ratio <= 0.25 else 1.25 if ratio <= 0.5 else 1.0
            if not (c == b and c - a < span):  # a piece ended by its sample time leaves the span
                span = (c - a) * grow
            y, a = y1, c
        Y[i] = y
    return Y


SCIPY_METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA")  # DOP853 first: the default
STIFF = ("Radau", "BDF", "LSODA")  # SciPy's methods that take the Jacobian
# SUNDIALS through CasADi: the integrator and its options (cvodes-adams: non-stiff
# Adams-Moulton with fixed-point iteration; cvodes: BDF, CasADi's default; idas: the DAE form)
SUNDIALS = {"cvodes": ("cvodes", {}), "idas": ("idas", {}),
            "cvodes-adams": ("cvodes", {"linear_multistep_method": "adams", "nonlinear_solver_iteration": "functional"})}


def integrate_state(model: Model, P, y0, t, method: str, rtol: float, atol, budget_s: float = math.inf,
                    budget_steps: float = math.inf, jac: bool = False, inputs=None, label: str | None = None,
                    project=None) -> np.ndarray:
    """States (len(t), 2n) of y' = f(y, P) (the emitted equations of motion; the further
    inputs zero, or for SciPy's methods `inputs(t)` as numpy_rhs takes it) from y0 at t[0],
    at the times t: one integrator for every model's motions; `label` names the run in a
    budget's message (default: the method).

    SciPy's METHODS (solve_ivp; with `jac` the stiff ones take the exact Jacobian), within
    `budget_s` seconds and `budget_steps` evaluations (IntegrationBudget beyond, saying how far
    it got; FloatingPointError where the method fails). SUNDIALS' (cvodes, cvodes-adams,
    idas), budget_steps shared out over the output intervals (at least 500 each; SUNDIALS
    counts steps between outputs), its own lines on stderr silenced: IntegrationBudget where
    it gives up (its budget, or a failed step). The budgets are the command line's; a library
    call without them runs to the end.

    `project` (SciPy's methods): a map onto a manifold the motion keeps (a model's holonomic
    constraints and their rates, gyro.analyses.motion.Constraints), project(y, y_before) ->
    (the point on it, the correction's size in units of what the tolerance allows of each
    component, atol + rtol max(|y|, |y_before|)): the run then goes from one sample time to
    the next (`projected`), each end projected; a MULTISTEP method's samples are only held
    to it (`checked`)."""
    import casadi as ca

    t = np.asarray(t, float)
    y0 = np.asarray(y0, float)
    P = np.asarray(P, float)
    if method in SCIPY_METHODS:
        from scipy.integrate import solve_ivp

        kw = {}
        if jac and method in STIFF:
            J = jacobian(model)
            zeros = [np.zeros(v.numel()) for v in symbolic(model).inputs]
            kw["jac"] = lambda _, Y: np.asarray(J(Y, ca.DM(P), *zeros)[1])
        fun = budgeted(numpy_rhs(model, P, inputs), label or method, t[-1], budget_s, budget_steps, IntegrationBudget)
        if WATCH is not None:
            fun = WATCH.wrap(fun, t[0], t[-1])
        try:
            with np.errstate(all="ignore"):
                if project is not None and method not in MULTISTEP:
                    return projected(fun, t, y0, method, rtol, atol, kw, project)
                sol = solve_ivp(fun, (t[0], t[-1]), y0, method=method, t_eval=t, rtol=rtol, atol=atol, **kw)
        finally:
            if hasattr(fun, "done"):
                fun.done()
        if sol.status != 0 or np.shape(sol.y)[-1] != len(t):
            reached = np.asarray(sol.t, float)  # a list where the method failed at its first step
            raise FloatingPointError(f"{method} stopped at t = {reached[-1] if reached.size else t[0]:.6g} s: "
                                     f"{sol.message}")
        return sol.y.T if project is None else checked(sol.y.T, t, method, rtol, project)
    if method in SUNDIALS:
        if project is not None:
            raise ValueError(f"{method}: a run projected onto constraints is SciPy's methods' only")
        if inputs is not None:
            raise ValueError(f"{method}: the equations' time-varying inputs are SciPy's methods' only")
        name, extra = SUNDIALS[method]
        s = symbolic(model)
        xdot = ca.substitute([s.ydot], [s.p, *s.inputs], [ca.DM(P), *[ca.DM.zeros(v.numel()) for v in s.inputs]])[0]
        per = 10**9 if math.isinf(budget_steps) else max(500, int(budget_steps) // max(1, len(t) - 1))
        opts = {"abstol": atol, "reltol": rtol, "max_num_steps": int(min(per, 10**9)), **CASADI_QUIET, **extra}
        F = ca.integrator("F", name, {"x": s.y, "ode": xdot}, t[0], t[1:], opts)
        try:
            with stderr_silenced():  # SUNDIALS' error lines (IDAS prints them whatever the options)
                Y = np.array(F(x0=y0)["xf"]).T
        except RuntimeError:  # SUNDIALS gives up (its step budget, or a failed step)
            raise IntegrationBudget(f"{method} stopped before t = {t[-1]:.6g} s (its budget of {per:.3g} steps "
                                    "between output times, or a failed step)") from None
        return np.vstack([y0, Y])
    raise ValueError(f"unknown method {method!r}; known: {' '.join(SCIPY_METHODS + tuple(SUNDIALS))}")
