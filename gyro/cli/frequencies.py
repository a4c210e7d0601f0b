"""`gyro frequencies MODEL [--set NAME=VALUE]... [--method NAME] [--json]`"""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_set, model_with_equilibrium, parse_sets, has_operator
from gyro.errors import ParameterError
from gyro.methods import names as method_names

ORDER = 10


def register(sub) -> None:
    f = sub.add_parser("frequencies", help="natural frequencies of a model's exact linear operator")
    add_model(f, help="the model: an operator about a relative equilibrium", declares=has_operator)
    add_set(f)
    add_json(f)
    f.add_argument("--method", default="default", choices=method_names(),
                   help="rung of the ladder (default: %(default)s; docs/methods.md)")
    f.add_argument("--sensitivities", action="store_true",
                   help="also d omega / d p of every frequency to every parameter (exact, with the "
                        "equilibrium's own dependence), and relative: (p / omega) d omega / d p")
    f.add_argument("--modes", action="store_true",
                   help="with --json: damping ratio, logarithmic decrement and the mode shapes (right eigenvectors)")
    f.set_defaults(run=run)


def run(args) -> int:
    import numpy as np

    from gyro import ladder

    model = model_with_equilibrium(args.model)
    values = model.parameters(parse_sets(args.set))
    if args.method == "formulas" and "mode_formulas" not in model.meta["functions"]:
        raise ParameterError(f"--method formulas: {model.name} has no approximate formulas")
    if args.modes and args.method == "formulas":
        raise ParameterError("--modes: the formulas give frequencies only; use another --method")
    spec = ladder.spectrum(model, model.vector(values), args.method, modes=args.modes)
    if spec.equilibrium is not None and not np.all(np.isfinite(spec.equilibrium[0])):
        from gyro.equilibrium import EquilibriumError, unbalanced

        reason = unbalanced(model, model.vector(values))
        if reason:  # no equilibrium: one line naming the residual
            raise EquilibriumError(reason)
    ladder.require_finite(model, spec)  # no verdict: exit 1, text and JSON alike
    sens = None
    if getattr(args, "sensitivities", False):
        if args.method == "formulas":
            raise ParameterError("--sensitivities: the formulas give no operator to differentiate; "
                                 "use another --method")
        from gyro.analyses.sensitivity import sensitivities

        sens = sensitivities(model, model.vector(values), spec)
    if args.json:
        doc = spec.to_dict(0, model, values)
        if sens is not None:
            doc.update(sens.to_dict(0))
        print(json.dumps(doc, allow_nan=False))
    else:
        print(spec.table(0, model))
        if sens is not None:
            print(sens.table(0))
    return 0
