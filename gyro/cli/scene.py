"""`gyro scene MODEL QUESTION --tol REL [--set NAME=VALUE]... [--modes I,J,...] [--horizon T]
[--harmonic S:K:AMP[:PHASE]] [--json]`

The question answered within the relative tolerance REL by the cheapest level of the
model's hierarchy whose bound meets it (docs/hierarchy.md)."""
from __future__ import annotations

import json
import sys

from gyro.cli.common import add_json, add_model, add_set, parse_sets
from gyro.errors import ParameterError, finite_number

ORDER = 15


def register(sub) -> None:
    from gyro.questions import names

    f = sub.add_parser("scene", help="answer a question at a tolerance with the cheapest adequate level")
    add_model(f)
    f.add_argument("question", metavar="QUESTION", choices=names(),
                   help=f"what to answer; one of: {', '.join(names())}")
    f.add_argument("--tol", required=True, metavar="REL", help="relative tolerance, a number in (0, 1)")
    add_set(f)
    f.add_argument("--modes", metavar="I,J,...", help="frequencies: only these modes (1 = the slowest)")
    f.add_argument("--horizon", metavar="T", help="motion: the time span in s")
    f.add_argument("--t-end", dest="horizon", metavar="T", help="motion: the same as --horizon")
    f.add_argument("--harmonic", metavar="S:K:AMP[:PHASE]",
                   help="forced: the imperfection harmonic f_S = AMP sin(K omega_c t + PHASE), as gyro forced takes it")
    add_json(f)
    f.set_defaults(run=run)


EPS = 2.220446049250313e-16  # a double's relative rounding: no answer printed as one is closer
MAX_PERIODS = 10_000  # of the fastest motion over a motion's horizon (a linear motion level of
# the papers' models: 350 periods of omega4 = 219.6 rad/s in 6 s, 3500 in 28 s, measured)


def _tol(text: str) -> float:
    tol = finite_number("--tol", text)
    if not 0 < tol < 1:
        raise ParameterError(f"--tol: must lie in (0, 1), got {text!r}")
    return tol


def _check_motion_tol(tol: float, text: str) -> None:
    """A motion is integrated in doubles by every level (the frequencies have a 40-digit
    level, the motion none): a tolerance below a double's rounding is refused at once, not
    after every level has tried (38 s at 1e-30)."""
    if tol < EPS:
        raise ParameterError(f"--tol {text}: below a double's rounding ({EPS:.2g}), which bounds every "
                             "level of a motion (each integrates in doubles)")


def _fastest(model, vector, initial: dict, extra: dict) -> float:
    """The fastest rate of the motion in rad/s: the largest natural frequency about the
    equilibrium (a model that has one) and the largest initial rate given in rad/s."""
    import numpy as np

    rates = [abs(v) for k, v in initial.items() if extra[k][0] == "rad/s"]
    if not model.meta.get("momenta"):
        from gyro import ladder

        w = ladder.spectrum(model, vector, "default").frequencies[0]
        rates += [float(np.max(w))] if np.all(np.isfinite(w)) else []
    return max(rates, default=0.0)


def _check_horizon(model, vector, initial: dict, extra: dict, horizon: float) -> None:
    """A horizon's predictable cost: its periods of the fastest motion, refused beyond
    MAX_PERIODS before any level runs (--horizon 1e6: 52-77 s before, then no answer)."""
    import math

    w = _fastest(model, vector, {**{k: d[1] for k, d in extra.items()}, **initial}, extra)
    periods = horizon * w / (2 * math.pi)
    if periods > MAX_PERIODS:
        raise ParameterError(f"--horizon {horizon:g}: {periods:.3g} periods of the fastest motion ({w:.4g} rad/s), "
                             f"over the {MAX_PERIODS} a motion question takes; a shorter horizon")


def _modes(text: str | None) -> list | None:
    if text is None:
        return None
    try:
        modes = [int(t) for t in text.split(",")]
    except ValueError:
        raise ParameterError(f"--modes {text!r}: expected mode numbers I,J,... (1 = the slowest)") from None
    return modes


def run(args) -> int:
    from gyro.analyses.scene import select
    from gyro.models import load

    from gyro import questions

    tol = _tol(args.tol)
    model = load(args.model)
    q = questions.get(args.question)
    sets = {model.canonical(k): v for k, v in parse_sets(args.set).items()}
    # a question's own inputs beside the model's parameters (the motion's initial conditions)
    extra = q.initial_conditions(model) if hasattr(q, "initial_conditions") else {}
    for key in sets:
        if key not in model.param_names and key not in extra:
            raise ParameterError(f"unknown parameter {key!r} for {model.name}; known: "
                                 f"{' '.join([*model.param_names, *extra])}")
    values = model.parameters({k: v for k, v in sets.items() if k not in extra})
    opts = {"modes": _modes(args.modes)}
    if extra:
        opts["initial"] = {k: finite_number(k, v) for k, v in sets.items() if k in extra}
    if args.modes is not None and args.question != "frequencies":
        raise ParameterError(f"--modes: only for the frequencies question, not {args.question!r}")
    if args.horizon is not None:
        if args.question != "motion":
            raise ParameterError(f"--horizon: only for the motion question, not {args.question!r}")
        opts["horizon"] = finite_number("--horizon", args.horizon)
        if not opts["horizon"] > 0:
            raise ParameterError(f"--horizon: must be positive, got {args.horizon!r}")
    if args.harmonic is not None:
        if args.question != "forced":
            raise ParameterError(f"--harmonic: only for the forced question, not {args.question!r}")
        from gyro.analyses.forced import parse_harmonic
        from gyro.analyses.spin import harmonic_inputs

        opts["harmonic"] = parse_harmonic(args.harmonic, len(harmonic_inputs(model)[1]))
    elif args.question == "forced":
        raise ParameterError("--harmonic: the forced question needs one harmonic S:K:AMP[:PHASE]")
    if args.question == "motion":
        _check_motion_tol(tol, args.tol)
    if "horizon" in opts:
        _check_horizon(model, model.vector(values), opts.get("initial", {}), extra, opts["horizon"])
    scene = select(model, args.question, model.vector(values), tol, opts)
    if not scene.answered[0]:
        b, lv = scene.best(0)
        offer = f"the best bound is {b:.2e} ({lv})" if lv else "no level gives a finite bound here"
        print(f"gyro: error: --tol {tol:g} is below what the hierarchy of {model.name} can promise "
              f"at this set; {offer}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(scene.to_dict(0), allow_nan=False))
    else:
        print(scene.table(0))
    return 0
