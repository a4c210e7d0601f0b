"""`gyro stability gyrohorizoncompass [--set NAME=VALUE]... [--orbit] [--json]`: the relative
equilibrium (3.1)-(3.2), the margins of the sufficient conditions (3.6) (or (4.3) on a
circular orbit, --orbit: zeta = nu, eta = 0) and of C1's Sylvester minors, and the spectrum
of the linearisation (companion eigensolve of the emitted operator), with the verdict:
`boundary` (and `boundary_reason`, one line) where rounding could change it.

Parameters: A B C J L I nu zeta eta lam (SI; lambda is taken for lam; it defaults to 1 + chi). Bad input, or a
set without a relative equilibrium, exits with 2 and one line naming the parameter or the
reason.
"""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_set, parse_sets
from gyro.errors import ParameterError

ORDER = 32
MODELS = ("gyrohorizoncompass",)


def register(sub) -> None:
    s = sub.add_parser("stability", help="gyrohorizoncompass: conditions (3.6)/(4.3) against the spectrum")
    add_model(s, MODELS, help="the model")
    add_set(s, "A B C J L I nu zeta eta lam (or lambda), SI units (lam defaults to 1 + chi)")
    s.add_argument("--orbit", action="store_true", help="a satellite on a circular orbit: zeta = nu, eta = 0 (4.1)")
    add_json(s)
    s.set_defaults(run=run)


def run(args) -> int:
    if args.model not in MODELS:
        raise ParameterError(f"stability: unknown model {args.model!r}; it covers {', '.join(MODELS)}")
    from gyro.systems.gyrohorizoncompass import parameters, stability

    values = parameters(parse_sets(args.set), orbit=args.orbit)
    res = stability(values, orbit=args.orbit)
    print(json.dumps(res.to_dict(), allow_nan=False) if args.json else res.table())
    return 0
