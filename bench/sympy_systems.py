"""`python -m bench.sympy_systems`: the derivation against sympy.physics.mechanics' own
method on the same system, for every model of tests/models (the textbook set among them),
each side a fresh process on one core, in one run:

- ours: the model file's build() and `derive.pipeline.derive` (the equations, the operator
  by both routes and their 30-digit check, B; multipliers or elimination; the speeds'
  equations with kinematic equations; the Routh reduction and the reference): the
  equations and the linearisation, no emission (not `python -m derive`, which imports
  the emitter as well);
- SymPy: LagrangesMethod(L, q, hol_coneqs, forcelist, frame).form_lagranges_equations() and
  linearize() in the independent coordinates (the dependent ones given where there are
  constraints), or, for a model in generalised speeds, KanesMethod(frame, q, u, kd_eqs)
  .kanes_equations() and linearize(). A model file with `system()` gives what SymPy's
  methods take as a SymPy user writes it; a model in the machinery's own symbols is handed
  over by bench/sympy_translate.py (the same Lagrangian in dynamicsymbols, each force on a
  point of its own), and its equations are checked equal to ours here, at random exact
  points to 30 digits, before anything is timed.

Each side's time in three parts: `import_s` (the packages and the model file, whose own
imports are the model's), `build_s` (build(), or system() / the translation) and
`derive_s` (the derivation alone), each in wall and CPU time (`*_cpu_s`); `whole_s` the
child's wall time, interpreter included, `whole_cpu_s` its CPU time. The ratios and the
verdicts are in CPU time: on a shared machine the wall time is what a contended core gave
(3-6x the CPU time in the committed run, at a load of 5 on 2 cores).
Both sides run with their bytecode cached (PYTHONDONTWRITEBYTECODE lifted for the children,
a cache folder of the bench's own, one uncounted run per side and system first), as an
installed package runs: SymPy's site-packages have theirs, and a tree without (this
machine's default) would charge the project's sources their compilation on every start.
A model the machinery refuses by design (an unbalance through the cyclic angle or explicit
time) is a row with its refusal and no ratio. The goal: ours never slower.

Writes bench/results/sympy_systems.json."""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import sys
import tempfile
from pathlib import Path

from bench import machine
from bench.baselines.common import fresh

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
MODELS = ROOT / "tests" / "models"
# the models whose file gives `system()` as a SymPy user writes it (the rest are translated)
SYSTEMS = ("cart_pendulum_mechanics", "nonminimal_pendulum", "disc_incline", "four_bar", "slider_crank",
           "top_body_speeds")

LOAD = """
import importlib.util, json, sys, time
def clock():
    return time.perf_counter(), time.process_time()
def report(*ts):
    out = {{}}
    for k, part in enumerate(("import", "build", "derive")):
        out[part + "_s"] = ts[k + 1][0] - ts[k][0]
        out[part + "_cpu_s"] = ts[k + 1][1] - ts[k][1]
    print(json.dumps(out))
def load(path):
    sys.path.insert(0, {folder!r})
    spec = importlib.util.spec_from_file_location("_bench_model", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod
"""

OURS = LOAD + """
import io
t0 = clock()
from derive import pipeline
mod = load({path!r})
t1 = clock()
model = mod.build()
t2 = clock()
pipeline.derive(model, pipeline.Steps(out=io.StringIO()))
report(t0, t1, t2, clock())
"""

SYMPY = LOAD + """
t0 = clock()
import sympy.physics.mechanics as me
{extra_import}
mod = load({path!r})
t1 = clock()
t = me.dynamicsymbols._t
{build}
t2 = clock()
{method}
report(t0, t1, t2, clock())
"""

KANE_BUILD = "L, q, u, kd, body, N, gravity = mod.system()"
KANE = """km = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd)
km.kanes_equations([body], [gravity])
km.linearize()"""
LAGRANGE_BUILD = {
    4: "(L, q, loads, N), hol = mod.system(), []\nind, dep = {split}",
    5: "L, q, hol, loads, N = mod.system()\nind, dep = {split}",
    "translated": "L, q, hol, loads, N = lagranges_system(mod.build())\nind, dep = independent(mod.build(), q, len(hol))",
}
LAGRANGE = """lm = me.LagrangesMethod(L, q, hol_coneqs=hol or None, forcelist=loads or None, frame=N)
lm.form_lagranges_equations()
lm.linearize(q_ind=ind, qd_ind=[x.diff(t) for x in ind], q_dep=dep, qd_dep=[x.diff(t) for x in dep])"""


def sympy_code(name: str, model) -> str:
    """The SymPy side's child for tests/models/<name>.py."""
    path, folder = str(MODELS / f"{name}.py"), str(MODELS)
    if name not in SYSTEMS:
        return SYMPY.format(folder=folder, path=path, build=LAGRANGE_BUILD["translated"], method=LAGRANGE,
                            extra_import="from bench.sympy_translate import independent, lagranges_system")
    import importlib.util

    spec = importlib.util.spec_from_file_location("_probe", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    size = len(mod.system())
    if size == 7:
        return SYMPY.format(folder=folder, path=path, build=KANE_BUILD, method=KANE, extra_import="")
    reduced = list(model.reduced) or None
    split = ("(q[: len(q) - len(hol)], q[len(q) - len(hol):])" if reduced is None else
             f"([x for x in q if x.func.__name__ in {reduced!r}], [x for x in q if x.func.__name__ not in {reduced!r}])")
    return SYMPY.format(folder=folder, path=path, build=LAGRANGE_BUILD[size].format(split=split),
                        method=LAGRANGE, extra_import="")


def check_equal(name: str, model, d) -> float:
    """The translated system's equations against ours: LagrangesMethod's eom (its
    multipliers lam_j as ours) against the first n rows of mass_matrix [q''; lam] - forcing,
    at three random exact rational points of every symbol, to 30 digits; the largest
    difference relative to the largest entry (AssertionError beyond 1e-25: not the same
    physics)."""
    import random

    import sympy as sp
    from sympy.physics.mechanics import LagrangesMethod

    from bench.sympy_translate import lagranges_system, to_dynamic
    from derive.passes.checks import given_symbols
    from derive import mechanics as mech

    L, q, hol, loads, N = lagranges_system(model)
    lm = LagrangesMethod(L, q, hol_coneqs=hol or None, forcelist=loads or None, frame=N)
    lm.form_lagranges_equations()
    n, m = len(q), len(hol)
    lam = sp.symbols(f"lam1:{m + 1}")
    back = {v: k for k, v in to_dynamic(model).items()}
    eom = lm.eom.xreplace(dict(zip(lm.lam_vec, lam)) if m else {})
    eom = sp.Matrix(mech.substitute(list(eom.xreplace(back)), given_symbols(model)))
    unknowns = sp.Matrix(list(model.qdd) + list(lam))
    ours = (d.mass_matrix * unknowns - d.forcing)[:n, :]
    rng = random.Random(0)
    syms = sorted(set(eom.free_symbols) | set(ours.free_symbols), key=str)
    worst = 0.0
    for _ in range(3):
        pt = {s: sp.Rational(rng.randint(500, 2000), 1000) for s in syms}
        a = [sp.N(e.xreplace(pt), 30) for e in eom]
        b = [sp.N(e.xreplace(pt), 30) for e in ours]
        scale = max(abs(x) for x in a + b) or 1
        worst = max(worst, float(max(abs(x - y) for x, y in zip(a, b)) / scale))
    if worst > 1e-25:
        raise AssertionError(f"{name}: SymPy's equations of the translated system differ from ours by {worst:.3e}")
    return worst


def child(code: str, timeout: float) -> dict | None:
    """One fresh process (bench.baselines.common.fresh): its phases' wall and CPU times, and
    the whole process's (`whole_s` wall, `whole_cpu_s` its user and system CPU time, from
    the children's resource usage); None when it did not finish in `timeout`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    res, wall = fresh(["-c", code], timeout)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res is None:
        return None
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return dict(res, whole_s=wall, whole_cpu_s=cpu)


def median(runs: list) -> dict | None:
    """Each time's median over the runs that finished (None if none did)."""
    done = [r for r in runs if r]
    if not done:
        return None
    return {k: statistics.median(r[k] for r in done) for k in done[0]} | {"runs": len(done)}


def interleaved(codes: dict, repeats: int, timeout: float) -> dict:
    """Each side's child (`codes`: side -> code) run once uncounted (its bytecode written),
    then `repeats` times, the sides interleaved (a change of the machine's load meets both):
    side -> the medians of its times (`median`)."""
    runs = {side: [] for side in codes}
    for code in codes.values():
        child(code, timeout)
    for _ in range(repeats):
        for side, code in codes.items():
            runs[side].append(child(code, timeout))
    return {side: median(r) for side, r in runs.items()}


def arguments(argv, repeats: int, folder: Path):
    """The bench's command line (--timeout, --repeats, --only NAME...: of the model files in
    `folder`, args.names, all of them by default), with the children's bytecode cached in a
    folder of the bench's own, as an installed package runs (module doc)."""
    where = folder.relative_to(ROOT)
    ap = argparse.ArgumentParser(description=sys.modules["__main__"].__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per child process")
    ap.add_argument("--repeats", type=int, default=repeats, help="runs per side; the median is kept")
    ap.add_argument("--only", nargs="*", help=f"these models of {where} only")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    os.environ["PYTHONPYCACHEPREFIX"] = str(Path(tempfile.gettempdir()) / "gyro-bench-pycache")
    args.names = args.only or sorted(p.stem for p in folder.glob("*.py") if not p.stem.startswith("_"))
    return args


def main(argv=None) -> None:
    args = arguments(argv, 5, MODELS)
    import io

    from derive import pipeline
    from derive.__main__ import build, load_file
    from derive.model import Unsupported

    rows = []
    for name in args.names:
        path = str(MODELS / f"{name}.py")
        model = build(load_file(path))
        row = {"system": name, "sympy_input": "system()" if name in SYSTEMS else "translated"}
        try:
            d = pipeline.derive(model, pipeline.Steps(out=io.StringIO()))
        except Unsupported as exc:
            rows.append(dict(row, refused=str(exc)))
            print(json.dumps({"system": name, "refused": str(exc)[:100]}), flush=True)
            continue
        if name not in SYSTEMS:
            row["equations_differ_by"] = check_equal(name, model, d)
        codes = {"ours": OURS.format(folder=str(MODELS), path=path), "sympy": sympy_code(name, model)}
        sides = interleaved(codes, args.repeats, args.timeout)
        row.update(sides)
        if sides["ours"] and sides["sympy"]:
            for key in ("whole_cpu_s", "derive_cpu_s", "whole_s", "derive_s"):
                row[f"sympy_over_ours_{key[:-2]}"] = sides["sympy"][key] / sides["ours"][key]
        rows.append(row)
        print(json.dumps({k: (round(v, 3) if isinstance(v, float) else v) for k, v in row.items()
                          if not isinstance(v, dict)} | {f"{s}_derive_cpu_s": round(sides[s]["derive_cpu_s"], 3)
                                                         for s in sides if sides[s]}), flush=True)
    timed = [r for r in rows if "refused" not in r]
    rec = {"command": "python -m bench.sympy_systems " + " ".join(argv or sys.argv[1:]), "rows": rows,
           "never_slower_whole_cpu": all(r.get("sympy_over_ours_whole_cpu", 0) >= 1 for r in timed),
           "never_slower_derive_cpu": all(r.get("sympy_over_ours_derive_cpu", 0) >= 1 for r in timed),
           "machine": machine()}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "sympy_systems.json").write_text(json.dumps(rec, indent=1) + "\n")


if __name__ == "__main__":
    main()
