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


def _tol(text: str) -> float:
    tol = finite_number("--tol", text)
    if not 0 < tol < 1:
        raise ParameterError(f"--tol: must lie in (0, 1), got {text!r}")
    return tol


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

        opts["harmonic"] = parse_harmonic(args.harmonic)
    elif args.question == "forced":
        raise ParameterError("--harmonic: the forced question needs one harmonic S:K:AMP[:PHASE]")
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
