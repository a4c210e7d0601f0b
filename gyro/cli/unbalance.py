"""`gyro unbalance MODEL --force-x NAME --force-y NAME --magnitude ME [--phase PHI] [--spin NAME]
--spin-range LO HI [--points N] [--set ...] [--json] [--out FILE.png]`: the steady response
to the force ME W^2 (cos(W t + PHI), sin(W t + PHI)) on two inputs, W the spin rate, over a
spin range (a Bode figure with --out)."""
from __future__ import annotations

import json
import math
import sys

from gyro.cli.common import (add_json, add_model, add_out, add_points, add_quiet, add_set, check_png_out, has_spin,
                             parse_sets)

ORDER = 62


def register(sub) -> None:
    s = sub.add_parser("unbalance", help="unbalance response over a spin range (any model with inputs)")
    add_model(s, help="the model: an operator, a spin and force inputs", declares=lambda meta: has_spin(meta) and "input_matrix" in meta["functions"])
    s.add_argument("--force-x", required=True, metavar="NAME", help="input that takes ME W^2 cos(W t + PHI)")
    s.add_argument("--force-y", required=True, metavar="NAME", help="input that takes ME W^2 sin(W t + PHI)")
    s.add_argument("--magnitude", required=True, type=float, metavar="ME", help="unbalance m e [kg m]")
    s.add_argument("--phase", type=float, default=0.0, metavar="PHI", help="its angle [rad] (default 0)")
    s.add_argument("--spin", metavar="NAME", default=None,
                   help="the parameter that sets the spin (the model's declared one, as H of the torsion gyrocompass, or a rate in rad/s)")
    s.add_argument("--spin-range", nargs=2, type=float, required=True, metavar=("LO", "HI"),
                   help="the spin parameter's range, in its own unit (LO >= 0)")
    add_points(s, 200, "spin values (default: 200)")
    add_set(s)
    add_json(s)
    add_out(s, required=False, help="also draw the Bode figure into FILE.png")
    add_quiet(s)
    s.set_defaults(run=run)


def run(args) -> int:
    import numpy as np

    from gyro.analyses.harmonic import require_inputs, unbalance_response
    from gyro.analyses.spin import spin_parameter
    from gyro.errors import ParameterError
    from gyro.models import load

    model = load(args.model)
    require_inputs(model)
    values = model.parameters(parse_sets(args.set))
    spin = spin_parameter(model, args.spin, sole_rate=True)
    lo, hi = args.spin_range
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo < 0 or not lo < hi:
        raise ParameterError(f"--spin-range: need finite 0 <= LO < HI, got {lo} {hi}")
    for v in (lo, hi):
        model.parameters({spin: v})  # validates the ends of the range
    if not 2 <= args.points <= 1_000_000:
        raise ParameterError(f"--points: need 2..1000000, got {args.points}")
    out = check_png_out(args.out) if args.out else None
    result = unbalance_response(model, values, args.force_x, args.force_y, args.magnitude, args.phase,
                                spin, lo, hi, args.points, progress=not args.quiet and sys.stderr.isatty())
    bad = ~np.all(np.isfinite(result.X), axis=1) & ~result.resonance
    if bad.all():
        raise RuntimeError("no finite response over the whole spin range (no equilibrium, or the force "
                           "ME W^2 beyond a double)")
    if out is not None:
        result.plot(out)
    if args.json:
        print(json.dumps(result.to_dict(), allow_nan=False))
    else:
        print(result.table())
        if out is not None:
            print(result.summary(out))
    if bad.any():
        print(f"gyro: {int(bad.sum())} spin values have no finite response (no equilibrium, or the force beyond "
              "a double; null in the JSON)", file=sys.stderr)
        return 1
    return 0
