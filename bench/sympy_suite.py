"""`python -m bench.sympy_suite`: the systems from SymPy's own suite kept in
tests/models/sympy_suite/ (docs/sympy_suite.md), each against SymPy's own method on it
(the file's `reference()`: KanesMethod / System or LagrangesMethod with its equations
formed): whether the machinery derives it or refuses it, and the CPU time of each side in a
fresh process, median of the runs, the sides interleaved (bench/sympy_systems.py's
children): ours build() and `pipeline.derive` (equations, operator by both routes, B);
SymPy's reference() and `linearize()` (in the independent coordinates the file names,
`INDEPENDENT`, where it has constraints). Writes bench/results/sympy_suite.json."""
from __future__ import annotations

import json
import sys
from pathlib import Path

from bench import machine
from bench.sympy_systems import LOAD, OURS, arguments, interleaved

ROOT = Path(__file__).resolve().parent.parent
SUITE = ROOT / "tests" / "models" / "sympy_suite"
RESULTS = ROOT / "bench" / "results"

# bench/sympy_systems.py's child, a refusal timed as a derivation is (it is the answer)
DERIVE = "pipeline.derive(model, pipeline.Steps(out=io.StringIO()))"
OURS = OURS.replace(DERIVE, "from derive.model import Unsupported\ntry:\n    " + DERIVE
                    + "\nexcept Unsupported:\n    pass")

SYMPY = LOAD + """
t0 = clock()
import sympy.physics.mechanics as me
mod = load({path!r})
t1 = clock()
kind, method = mod.reference()
t2 = clock()
if kind == "kane":
    method.linearize(A_and_B=True)
else:
    t = me.dynamicsymbols._t
    names = getattr(mod, "INDEPENDENT", None)
    ind = [x for x in method.q if names is None or x.func.__name__ in names]
    dep = [x for x in method.q if x not in ind]
    kw = dict(q_dep=dep, qd_dep=[x.diff(t) for x in dep]) if dep else {{}}
    method.linearize(q_ind=ind, qd_ind=[x.diff(t) for x in ind], **kw)
report(t0, t1, t2, clock())
"""


def outcome(path: str) -> dict:
    """{"route": ...} where the machinery derives the file, {"refused": its line} where not."""
    import io

    from derive import pipeline
    from derive.__main__ import build, load_file
    from derive.model import Unsupported

    try:
        return {"route": pipeline.derive(build(load_file(path)), pipeline.Steps(out=io.StringIO())).route}
    except Unsupported as exc:
        return {"refused": str(exc)}


def main(argv=None) -> None:
    args = arguments(argv, 3, SUITE)
    rows = []
    for name in args.names:
        path = str(SUITE / f"{name}.py")
        row = {"system": name} | outcome(path)
        codes = {"ours": OURS.format(folder=str(SUITE), path=path), "sympy": SYMPY.format(folder=str(SUITE), path=path)}
        sides = interleaved(codes, args.repeats, args.timeout)
        row.update(sides)
        if sides["ours"] and sides["sympy"]:
            row["sympy_over_ours_derive_cpu"] = (sides["sympy"]["build_cpu_s"] + sides["sympy"]["derive_cpu_s"]) / (
                sides["ours"]["build_cpu_s"] + sides["ours"]["derive_cpu_s"])
        rows.append(row)
        print(json.dumps({"system": name, "refused": row.get("refused", "")[:80], "route": row.get("route")}
                         | {f"{s}_cpu_s": round(sides[s]["build_cpu_s"] + sides[s]["derive_cpu_s"], 3)
                            for s in sides if sides[s]}), flush=True)
    rec = {"command": "python -m bench.sympy_suite " + " ".join(argv or sys.argv[1:]), "rows": rows,
           "machine": machine()}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "sympy_suite.json").write_text(json.dumps(rec, indent=1) + "\n")


if __name__ == "__main__":
    main()
