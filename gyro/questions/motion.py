"""`motion`: the motion over a horizon [0, T] (`--horizon`, s) from initial conditions; one
quantity per coordinate (in the model's order), its relative error the largest deviation
over the horizon divided by the coordinate's largest magnitude (at least 1 rad) there.

Evaluator kind: `trajectory`, {"module": MODULE, "method": NAME, "rtol": R}: the module
MODULE (a dotted name the model declares: gyro.systems.<system> for the papers' models,
gyro.analyses.motion for any model's linear motion and its integration, any importable
module for a user's; a module with for_model(model) gives the following per model) offers INITIAL (name -> (unit, default, description): the initial
conditions, which `gyro scene` takes with --set), `Motion(params, **initial)` and
`motion_answer(motion, t, method, rtol) -> (q (times, coordinates), absolute error
estimate per coordinate)`. An evaluator that refuses a set (the closed form with C0 != 0)
fails it with its reason, and the selector goes up. JSON keys: `horizon`, `t`, and one
list per coordinate at the sample times.

Two options of the evaluator, for a motion whose quantities are not the model's coordinates
(the image point of a gyroscope's spin axis, gimbal_precession): "quantities" names the
columns motion_answer returns (default: the coordinates); "scale": "excursion" measures
each quantity's error against the motion's largest excursion from its start (the norm over
the quantities), not against its largest magnitude (at least 1): the drift of a point
near the origin is the answer, so its size is the scale.

A linear level on the generic machinery may declare "cap_of" (gyro.analyses.motion.CAP_OF:
what its estimate's cap is a fraction of); motion_answer then takes it as a keyword.
"""
from __future__ import annotations

import numpy as np

from gyro.questions import Answer, evaluator_module, unknown_kind

NAME = "motion"
POINTS = 201  # sample times over the horizon
PASSED = ("cap_of",)  # evaluator options passed on to motion_answer where a level declares them
DEFAULT_HORIZON = 1.0  # s
OPTIONS = {"horizon": ("T", "motion: the time span in s (also --t-end)")}
EPS = 2.220446049250313e-16  # a double's relative rounding: no answer printed as one is closer
MAX_PERIODS = 10_000  # of the fastest motion over a motion's horizon (a linear motion level of
# the papers' models: 350 periods of omega4 = 219.6 rad/s in 6 s, 3500 in 28 s, measured)


def options(model, P, tol: float, given: dict, initial: dict) -> dict:
    """--horizon T, positive; refused at once: a tolerance below a double's rounding (every
    level of a motion integrates in doubles: 38 s at 1e-30 before, then no answer), and a
    horizon of more than MAX_PERIODS periods of the fastest motion (--horizon 1e6: 52-77 s
    before)."""
    from gyro.errors import ParameterError, finite_number

    if tol < EPS:
        raise ParameterError(f"--tol {tol:g}: below a double's rounding ({EPS:.2g}), which bounds every "
                             "level of a motion (each integrates in doubles)")
    if given.get("horizon") is None:
        return {}
    horizon = finite_number("--horizon", given["horizon"])
    if not horizon > 0:
        raise ParameterError(f"--horizon: must be positive, got {given['horizon']!r}")
    extra = initial_conditions(model)
    w = _fastest(model, P, {**{k: d[1] for k, d in extra.items()}, **initial}, extra)
    periods = horizon * w / (2 * np.pi)
    if periods > MAX_PERIODS:
        raise ParameterError(f"--horizon {horizon:g}: {periods:.3g} periods of the fastest motion ({w:.4g} rad/s), "
                             f"over the {MAX_PERIODS} a motion question takes; a shorter horizon")
    return {"horizon": horizon}


def _fastest(model, P, initial: dict, extra: dict) -> float:
    """The fastest rate of the motion in rad/s: the largest natural frequency about the
    equilibrium (a model that has one) and the largest initial rate given in rad/s."""
    rates = [abs(v) for k, v in initial.items() if extra[k][0] == "rad/s"]
    if not model.meta.get("momenta"):
        from gyro import ladder

        w = ladder.spectrum(model, P, "default").frequencies[0]
        rates += [float(np.max(w))] if np.all(np.isfinite(w)) else []
    return max(rates, default=0.0)


def _analysis(level, model):
    """The level's evaluator: its module, or what the module gives for this model where it
    serves any model (gyro.analyses.motion.for_model)."""
    mod = evaluator_module(level, model)
    return mod.for_model(model) if hasattr(mod, "for_model") else mod


def initial_conditions(model) -> dict:
    """name -> (unit, default, description) of every analysis the model's motion levels
    name: the question's inputs beside the model's parameters."""
    from gyro.levels import levels

    out = {}
    for lv in levels(model):
        if lv.answers_question(NAME) and lv.evaluator.get("kind") == "trajectory":
            out.update(_analysis(lv, model).INITIAL)
    return out


def _declared(model) -> dict:
    """The motion levels' evaluator options shared by all of them (quantities, scale)."""
    for d in model.meta.get("levels", []):
        ev = d["evaluator"]
        if NAME in d["answers"] and ev.get("kind") == "trajectory" and "quantities" in ev:
            return {"quantities": list(ev["quantities"]), "scale": ev.get("scale", "magnitude")}
    return {"quantities": list(model.meta["coordinates"]), "scale": "magnitude"}


def quantities(model, opts) -> list[str]:
    return _declared(model)["quantities"]


def requested(model, opts) -> list[int]:
    return list(range(len(quantities(model, opts))))


def _scale(q: np.ndarray, kind: str) -> np.ndarray:
    """Per quantity (columns of q, times x quantities): the error's scale."""
    if kind == "excursion":
        ex = float(np.max(np.sqrt(np.sum((q - q[:1]) ** 2, axis=1))))
        return np.full(q.shape[1], ex if ex > 0 else np.nan)  # no excursion: no relative error
    return np.maximum(np.max(np.abs(q), axis=0), 1.0)


def times(opts) -> np.ndarray:
    return np.linspace(0.0, float(opts.get("horizon", DEFAULT_HORIZON)), int(opts.get("points", POINTS)))


def subset(opts: dict, rows: np.ndarray, n: int) -> dict:
    """The options for the sets `rows` of a batch of n: an initial condition given per set
    (an array of n) taken at those rows, one given for all kept."""
    init = opts.get("initial")
    if not init:
        return opts
    out = dict(opts)
    out["initial"] = {k: (np.asarray(v)[rows] if np.ndim(v) and np.shape(v)[0] == n else v) for k, v in init.items()}
    return out


def _initial(mod, opts) -> dict:
    init = {k: v[1] for k, v in mod.INITIAL.items()}  # (unit, default, description)
    init.update(opts.get("initial", {}))
    return init


_MOTIONS: dict = {}  # (module, model, set, initial) -> its Motion, the latest few: one motion for
# every level that a set tries and for the floor, which share its work (its linear motion)


def _motions(mod, model, level, P, init):
    """(k, a function making the module's Motion of set k: it may refuse the set) for each
    set of P."""
    N = P.shape[0]
    for k in range(N):
        ic = {n: float(np.broadcast_to(v, (N,))[k]) for n, v in init.items()}
        key = (level.evaluator["module"], str(model.directory), P[k].tobytes(), tuple(sorted(ic.items())))

        def made(k=k, ic=ic, key=key):
            if key not in _MOTIONS:
                _MOTIONS[key] = mod.Motion(dict(zip(model.param_names, map(float, P[k]))), **ic)
                while len(_MOTIONS) > 8:
                    del _MOTIONS[next(iter(_MOTIONS))]
            return _MOTIONS[key]

        made.initial = ic
        yield k, made


def floor(model, level, P, opts) -> np.ndarray:
    """Per set, a bound below which `level` cannot answer, known before it runs (the selector
    passes a level over where it is above the tolerance, gyro.analyses.scene): an integrated
    level's estimate is at least its module's integration_floor of each coordinate's size
    (gyro.analyses.motion: the finer run's tolerance), over the error's scale. The motion is
    predicted by the module's linear level within its own estimate d (per coordinate, over
    the horizon): a size of at least max|q_L| - d, a scale of at most the linear motion's
    plus 2|d| (the excursion) or max|q_L| + d (the magnitude). 0 where nothing is known (a
    linear level, a module without integration_floor, a linear motion without an estimate).
    Measured on the torsion gyrocompass's DOP853 level at rtol 1e-9 over 1 s: 1.41e-11
    (its bound found there is 2.08e-8, the two runs' difference); `--tol 1e-13` is refused
    without integrating (it integrated for 38 s before)."""
    from gyro import ode
    from gyro.errors import ParameterError

    out = np.zeros(P.shape[0])
    mod = _analysis(level, model)
    if level.evaluator.get("method") == "linear" or not hasattr(mod, "integration_floor"):
        return out
    t, kind, rtol = times(opts), _declared(model)["scale"], level.evaluator.get("rtol", 1e-10)
    for k, motion in _motions(mod, model, level, P, _initial(mod, opts)):
        try:  # the linear level's answer (its work kept on the motion where it ran before)
            with _watched(level):
                qL, d = mod.motion_answer(motion(), t, "linear")
        except ode.OverBudget as exc:
            raise ParameterError(_over_budget(model, P[k], motion.initial, t[-1], level.name, exc, opts)) from None
        except (ArithmeticError, ValueError, RuntimeError):
            continue
        if not (np.all(np.isfinite(qL)) and np.all(np.isfinite(d))):
            continue
        size = np.maximum(np.max(np.abs(qL), axis=0) - d, 0.0)
        if kind == "excursion":
            scale = _scale(qL, kind) + 2 * float(np.sqrt(np.sum(d ** 2)))
        else:
            scale = np.maximum(np.max(np.abs(qL), axis=0) + d, 1.0)
        with np.errstate(all="ignore"):
            f = np.max(mod.integration_floor(size, rtol) / scale)
        out[k] = f if np.isfinite(f) else 0.0
    return out


def _watched(level):
    """A level's long work shows how far it is on a terminal, and is held to the command
    line's budget by its cost predicted as it goes (gyro.ode.watching)."""
    import sys
    import time

    from gyro import executor, ode

    spent = time.perf_counter() - executor.STARTED if executor.BUDGET is not None else 0.0
    return ode.watching(level.name, executor.BUDGET, sys.stderr.isatty(), spent)


def answer(model, level, P, opts) -> Answer:
    from gyro import ode
    from gyro.errors import ParameterError

    if level.evaluator.get("kind") != "trajectory":
        raise unknown_kind(NAME, level)
    mod = _analysis(level, model)
    t = times(opts)
    init = _initial(mod, opts)
    kind = _declared(model)["scale"]
    N, nc = P.shape[0], len(quantities(model, opts))
    values = np.full((N, nc, t.size), np.nan)
    est = np.full((N, nc), np.inf)
    scales = np.full((N, nc), np.nan)
    failed = np.full(N, "", object)
    extra = {k: level.evaluator[k] for k in PASSED if k in level.evaluator}
    for k, motion in _motions(mod, model, level, P, init):
        try:
            with _watched(level):
                q, e = mod.motion_answer(motion(), t, level.evaluator["method"], level.evaluator.get("rtol", 1e-10),
                                         **extra)
        except ode.OverBudget as exc:  # the request's, not the set's: raised past the next clause
            raise ParameterError(_over_budget(model, P[k], motion.initial, t[-1], level.name, exc, opts)) from None
        except (ArithmeticError, ValueError, RuntimeError) as exc:  # a refusal or a failure: its reason
            failed[k] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            continue
        values[k] = q.T
        scales[k] = _scale(q, kind)
        est[k] = e / scales[k]
        if not np.all(np.isfinite(q)):
            failed[k] = "the motion could not be computed"
        elif not np.all(np.isfinite(scales[k])):
            failed[k] = "the motion does not move: no scale for a relative error"
    return Answer(values, est, failed, {"t": np.broadcast_to(t, (N, t.size)), "scale": scales})


def _over_budget(model, p, init: dict, horizon: float, level: str, exc, opts) -> str:
    """The one line of a motion whose work is over the command line's budget (`init`: the
    set's initial conditions)."""
    extra = initial_conditions(model)
    w = _fastest(model, p[None, :], {n: v for n, v in init.items() if n in extra}, extra)
    given = "" if "horizon" in opts else " (the default)"
    return (f"--horizon {horizon:g}{given}: {level} follows {horizon * w / (2 * np.pi):.3g} periods of the "
            f"fastest motion ({w:.4g} rad/s), about {exc.seconds:.0f} s in this process ({exc.measured}), "
            f"over the command line's budget of {exc.budget:.0f} s: a shorter --horizon, or a larger --tol")


def edges(model, ans: Answer, bound: np.ndarray, idx, answered) -> np.ndarray:
    return np.full(ans.values.shape[0], "", object)


def error(ans: Answer, ref: Answer) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.max(np.abs(ans.values - ref.values), axis=2) / ref.extra["scale"]


def document(model, ans: Answer, k: int, idx) -> dict:
    t = ans.extra["t"][k]
    out = {"horizon": float(t[-1]), "t": [float(x) for x in t]}
    for j, c in enumerate(quantities(model, {})):
        out[c] = [float(x) for x in ans.values[k, j]]
    return out
