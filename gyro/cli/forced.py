"""`gyro forced torsion_gyrocompass --harmonic S:K:AMP[:PHASE]... [--set NAME=VALUE]... [--json]
[--out FILE.png]`: the steady response to harmonics of the bearing imperfections (1.11),
f_S = AMP sin(K gamma3 + PHASE), gamma3 = omega_c t; `--set h=...` the bearing size,
`--set cp=... c0=... cgamma=...` the optional bearing damping (docs/forced.md)."""
from __future__ import annotations

import json

from gyro.cli.common import add_json, add_model, add_out, add_set, check_png_out, parse_sets

ORDER = 60


def register(sub) -> None:
    s = sub.add_parser("forced", help="steady response to the bearing imperfections' harmonics")
    add_model(s, models=["torsion_gyrocompass"])
    s.add_argument("--harmonic", action="append", nargs="+", default=[], metavar="S:K:AMP[:PHASE]",
                   help="f_S = AMP sin(K gamma3 + PHASE): S 1..3, K a positive integer, AMP in N, "
                        "PHASE in rad (default 0); repeat as needed")
    add_set(s)
    add_json(s)
    add_out(s, required=False, help="also draw the amplitude spectrum into FILE.png")
    s.set_defaults(run=run)


def run(args) -> int:
    from gyro.analyses.forced import forced_response, parse_harmonic
    from gyro.errors import ParameterError
    from gyro.models import load

    items = [h for group in args.harmonic for h in group]
    if not items:
        raise ParameterError("--harmonic: give at least one harmonic S:K:AMP[:PHASE]")
    harmonics = [parse_harmonic(h) for h in items]
    model = load(args.model)
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
