"""`gyro stability MODEL [--set NAME=VALUE]... [--orbit] [--json]`: for any model that declares
sufficient conditions (Model.conditions): the equilibrium, the margins of the conditions
with their rounding bounds, and the spectrum of the linearisation (companion eigensolve of
the emitted operator, each root with its error radius), with the verdict: `boundary` (and
`boundary_reason`, one line) where rounding could change it (gyro/analyses/conditions.py).
What only the model's system has (which condition applies where; --orbit, a satellite on a
circular orbit, where the system takes it) comes through its declaration `system`.

Bad input, a model without conditions, an option its system does not take, or a set
without an equilibrium exits with 2 and one line naming the parameter or the reason.
"""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_set, parse_sets

ORDER = 32
NEEDS = "needs declared conditions (Model.conditions: named sets of margins > 0, docs/models.md)"


def register(sub) -> None:
    s = sub.add_parser("stability", help=f"sufficient conditions against the spectrum; {NEEDS}",
                       description=f"The equilibrium, the margins of the model's sufficient conditions and the "
                                   f"spectrum of its linearisation, with the verdict. MODEL {NEEDS}.")
    add_model(s, help=f"the model ({NEEDS})", declares=lambda meta: bool(meta.get("conditions")))
    add_set(s, "a parameter's value (gyro params MODEL lists them), in the model's units")
    s.add_argument("--orbit", action="store_true",
                   help="a satellite on a circular orbit (zeta = nu, eta = 0 (4.1)): an option of the "
                        "model's system; only a model whose system takes it")
    add_json(s)
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses import conditions
    from gyro.models import load

    model = load(args.model)
    conditions.require(model)
    options = {"orbit": True} if args.orbit else {}
    values = conditions.parameters(model, parse_sets(args.set), options)
    res = conditions.stability(model, values, options)
    print(json.dumps(res.to_dict(), allow_nan=False) if args.json else res.table())
    return 0
