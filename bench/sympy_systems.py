"""`python -m bench.sympy_systems`: the derivation against sympy.physics.mechanics' own
method on the same system, for every model of tests/models that is written as a SymPy user
writes it (its `system()` gives what SymPy's methods take), each side a fresh process on one
core, in one run:

- ours: the model file's build() and `derive.pipeline.derive` (the equations, the operator
  by both routes and their 30-digit check, B; multipliers or elimination; the speeds'
  equations with kinematic equations): the equations and the linearisation, no emission;
- SymPy: LagrangesMethod(L, q, hol_coneqs, forcelist, frame).form_lagranges_equations() and
  linearize() in the independent coordinates (the dependent ones given where there are
  constraints), or, for a model in generalised speeds, KanesMethod(frame, q, u, kd_eqs)
  .kanes_equations() and linearize().

Both times include the process's imports and the system's construction (the same module
builds both); each child is bounded by --timeout. The goal: ours never slower.

Writes bench/results/sympy_systems.json."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from bench import machine
from bench.baselines.common import fresh

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
SYSTEMS = ("cart_pendulum_mechanics", "nonminimal_pendulum", "disc_incline", "four_bar", "slider_crank",
           "top_body_speeds")

OURS = """
import io, json, time
t0 = time.perf_counter()
from derive import pipeline
from derive.__main__ import build, load_file
t1 = time.perf_counter()
model = build(load_file({path!r}))
pipeline.derive(model, pipeline.Steps(out=io.StringIO()))
t2 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0, "derive_s": t2 - t1}}))
"""

SYMPY = """
import json, time
t0 = time.perf_counter()
import sympy.physics.mechanics as me
from derive.__main__ import load_file
t1 = time.perf_counter()
mod = load_file({path!r})
out = mod.system()
t = me.dynamicsymbols._t
if len(out) == 7:  # generalised speeds: KanesMethod
    L, q, u, kd, body, N, gravity = out
    km = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd)
    km.kanes_equations([body], [gravity])
    km.linearize()
else:
    if len(out) == 4:
        (L, q, loads, N), hol = out, []
    else:
        L, q, hol, loads, N = out
    lm = me.LagrangesMethod(L, q, hol_coneqs=hol or None, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    m = len(hol)
    ind, dep = (q[: len(q) - m], q[len(q) - m:]) if {reduced!r} is None else (
        [x for x in q if x.func.__name__ in {reduced!r}], [x for x in q if x.func.__name__ not in {reduced!r}])
    lm.linearize(q_ind=ind, qd_ind=[x.diff(t) for x in ind], q_dep=dep, qd_dep=[x.diff(t) for x in dep])
t2 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0, "derive_s": t2 - t1}}))
"""


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per child process")
    ap.add_argument("--repeats", type=int, default=3, help="runs per side; the median is kept")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from derive.__main__ import build, load_file

    rows = []
    for name in SYSTEMS:
        path = str(ROOT / "tests" / "models" / f"{name}.py")
        reduced = build(load_file(path)).reduced or None
        sides = {}
        for side, code in (("ours", OURS), ("sympy", SYMPY)):
            runs = []
            for _ in range(args.repeats):
                res, wall = fresh(["-c", code.format(path=path, reduced=reduced)], args.timeout)
                runs.append(None if res is None else dict(res, whole_s=wall))
            done = [r for r in runs if r]
            sides[side] = sorted(done, key=lambda r: r["whole_s"])[len(done) // 2] if done else None
        row = {"system": name, **sides}
        if sides["ours"] and sides["sympy"]:
            row["sympy_over_ours_whole"] = sides["sympy"]["whole_s"] / sides["ours"]["whole_s"]
            row["sympy_over_ours_derive"] = sides["sympy"]["derive_s"] / sides["ours"]["derive_s"]
        rows.append(row)
        print(json.dumps({k: (round(v, 3) if isinstance(v, float) else v) for k, v in row.items()
                          if not isinstance(v, dict)}), flush=True)
    rec = {"command": "python -m bench.sympy_systems " + " ".join(argv or sys.argv[1:]), "rows": rows,
           "never_slower_whole": all(r.get("sympy_over_ours_whole", 0) >= 1 for r in rows),
           "machine": machine()}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "sympy_systems.json").write_text(json.dumps(rec, indent=1) + "\n")


if __name__ == "__main__":
    main()
