"""`gyro forced MODEL --harmonic S:K:AMP[:PHASE]... [--set NAME=VALUE]... [--json] [--out
FILE.png]`: the steady response to harmonics of the model's spin angle, f_S = AMP sin(K angle
+ PHASE), the angle turning at its rate at the reference omega_c. Any model that declares its
spin angle (Model.spin "angle") and given functions of it (its harmonic inputs f_1..f_n, in
the order of its inputs): for the torsion gyrocompass the bearing imperfections (1.11),
gamma3 = omega_c t, `--set h=...` the bearing size, `--set cp=... c0=... cgamma=...` the
optional bearing damping (docs/forced.md)."""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_out, add_set, check_png_out, parse_sets

ORDER = 60


def register(sub) -> None:
    s = sub.add_parser("forced", help="steady response to harmonics of the spin angle (a model declaring its spin "
                                      "angle and given functions of it: the torsion gyrocompass's bearing imperfections)")
    add_model(s, help="a model that declares its spin angle (Model.spin 'angle') and given functions of it",
              declares=lambda meta: bool(meta.get("spin", {}).get("harmonic_inputs")))
    s.add_argument("--harmonic", action="append", nargs="+", default=[], metavar="S:K:AMP[:PHASE]",
                   help="f_S = AMP sin(K angle + PHASE): S the index of the harmonic input (1..n), K a positive "
                        "integer, AMP in the input's unit (N for the bearing imperfections), PHASE in rad (default 0); "
                        "repeat as needed")
    add_set(s)
    add_json(s)
    add_out(s, required=False, help="also draw the amplitude spectrum into FILE.png")
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses.forced import forced_response, parse_harmonic
    from gyro.analyses.spin import harmonic_inputs
    from gyro.errors import ParameterError
    from gyro.models import load

    items = [h for group in args.harmonic for h in group]
    model = load(args.model)
    _, inputs = harmonic_inputs(model)
    if not items:
        raise ParameterError("--harmonic: give at least one harmonic S:K:AMP[:PHASE]")
    harmonics = [parse_harmonic(h, len(inputs)) for h in items]
    values = model.parameters(parse_sets(args.set))
    out = check_png_out(args.out) if args.out else None
    result = forced_response(model, model.vector(values), harmonics)
    doc = result.to_dict(0)
    if not all(a is not None or h["resonance"] for h in doc["harmonics"] for a in h["amplitudes"]):
        given = " ".join(f"--set {k}={v}" for k, v in parse_sets(args.set).items()) or "the paper's set"
        raise RuntimeError(f"no finite steady response: no equilibrium, spin rate or operator at {given}")
    if out is not None:
        result.plot(out)
    if args.json:
        print(json.dumps(doc, allow_nan=False))
    else:
        print(result.table(0))
        if out is not None:
            print(f"gyro: wrote {out}")
    return 0
