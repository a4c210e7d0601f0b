"""`gyro scene MODEL QUESTION --tol REL [--set NAME=VALUE]... [--modes I,J,...] [--horizon T]
[--harmonic S:K:AMP[:PHASE]] [--json]`

The question answered within the relative tolerance REL by the cheapest level of the
model's hierarchy whose bound meets it (docs/hierarchy.md)."""
from __future__ import annotations

import json
import sys

from gyro.cli.common import add_json, add_model, add_set, has_levels, parse_sets
from gyro.errors import ParameterError, finite_number

ORDER = 15


def register(sub) -> None:
    from gyro.questions import names

    f = sub.add_parser("scene", help="answer a question at a tolerance with the cheapest adequate level")
    add_model(f, help="the model: a hierarchy of levels (Model.levels)", declares=has_levels)
    f.add_argument("question", metavar="QUESTION", choices=names(),
                   help=f"what to answer; one of: {', '.join(names())}")
    f.add_argument("--tol", required=True, metavar="REL", help="relative tolerance, a number in (0, 1)")
    add_set(f)
    for flag, (metavar, help) in _question_options().items():  # each question's own (its OPTIONS)
        f.add_argument(f"--{flag}", metavar=metavar, help=help)
    f.add_argument("--t-end", dest="horizon", metavar="T", help="motion: the same as --horizon")
    add_json(f)
    f.set_defaults(run=run)


def _question_options() -> dict:
    """{flag: (metavar, help)} of every question's OPTIONS, read from the sources."""
    from gyro.catalog import module_constants
    from gyro.questions import __path__ as folder

    out = {}
    for consts in module_constants(folder[0], ("OPTIONS",)).values():
        out.update(consts.get("OPTIONS", {}))
    return out


def _tol(text: str) -> float:
    tol = finite_number("--tol", text)
    if not 0 < tol < 1:
        raise ParameterError(f"--tol: must lie in (0, 1), got {text!r}")
    return tol


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
    initial = {k: finite_number(k, v) for k, v in sets.items() if k in extra}
    own = getattr(q, "OPTIONS", {})
    for flag in _question_options():
        if getattr(args, flag) is not None and flag not in own:
            raise ParameterError(f"--{flag}: not an option of the {args.question} question"
                                 + (f" (it takes {' '.join('--' + o for o in own)})" if own else " (it takes none)"))
    given = {flag: getattr(args, flag) for flag in own}
    opts = q.options(model, model.vector(values), tol, given, initial) if hasattr(q, "options") else {}
    opts.setdefault("modes", None)
    if extra:
        opts["initial"] = initial
    scene = select(model, args.question, model.vector(values), tol, opts)
    if not scene.answered[0]:
        b, lv = scene.best(0)
        offer = f"the best bound is {b:.2e} ({lv})" if lv else "no level gives a finite bound here (" + "; ".join(
            f"{name}: {why}" for name, why in scene.tried(0)) + ")"
        print(f"gyro: error: --tol {tol:g} is below what the hierarchy of {model.name} can promise "
              f"at this set; {offer}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(scene.to_dict(0), allow_nan=False))
    else:
        print(scene.table(0))
    return 0
