"""`python -m bench.pendulum_chain`: how the derivation scales with the system, against
sympy.physics.mechanics on a family that no one here wrote: the N-link pendulum on a cart of
`sympy.physics.mechanics.models.n_link_pendulum_on_cart(N, cart_force=True)`, for
N = 2, 4, 8, 12, 16, each side a whole process on one core, in one run:

- ours: `python -m derive --model pendulum_chain_N.py --jobs 1` (the model file written
  from the system's description, bench/models/pendulum_chain.py): the derivation (the
  equations, both routes of the operator and their 30-digit check, B), the functions to
  emit (the sensitivities' derivatives among them) and the emission (CSE and the C, NumPy,
  CasADi and mpmath printers through the templates), each step's time from its own report;
- KanesMethod: sympy's own `n_link_pendulum_on_cart` (its kanes_equations) plus
  `linearize()` (the symbolic M, A, B of the implicit linear form);
- LagrangesMethod: the same particles and loads through `Lagrangian`,
  `form_lagranges_equations()` plus `linearize()` of all coordinates.

Each child is bounded by --timeout (s; a side that does not finish is recorded as such).
Per side and step, the growth with N is the exponent of a least-squares line through
log(time) against log(N) over N >= 4 (N = 2 is mostly the imports).

Writes bench/results/pendulum_chain.json and pendulum_chain.png."""
from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench import machine
from bench.baselines.common import fresh

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
NS = (2, 4, 8, 12, 16)
GOAL_KANE = 5.0  # ours whole at least this much faster than KanesMethod's, N = 8..16

KANE = """
import json, time
t0 = time.perf_counter()
from sympy.physics.mechanics.models import n_link_pendulum_on_cart
t1 = time.perf_counter()
kane = n_link_pendulum_on_cart({n}, cart_force=True)
t2 = time.perf_counter()
kane.linearize()
t3 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0, "equations_s": t2 - t1, "linearize_s": t3 - t2}}))
"""

LAGRANGE = """
import json, time
t0 = time.perf_counter()
import sympy as sm
import sympy.physics.mechanics as me
t1 = time.perf_counter()
n = {n}
q = me.dynamicsymbols('q:{{}}'.format(n + 1))
m = sm.symbols('m:{{}}'.format(n + 1))
l = sm.symbols('l:{{}}'.format(n))
g = sm.symbols('g')
F = me.dynamicsymbols('F')
I = me.ReferenceFrame('I')
O = me.Point('O')
O.set_vel(I, 0)
P0 = O.locatenew('P0', q[0] * I.x)
P0.set_vel(I, q[0].diff() * I.x)
parts = [me.Particle('Pa0', P0, m[0])]
forces = [(P0, F * I.x)]
points = [P0]
for i in range(n):
    B = I.orientnew('B{{}}'.format(i), 'Axis', [q[i + 1], I.z])
    P = points[-1].locatenew('P{{}}'.format(i + 1), l[i] * B.y)
    P.v2pt_theory(points[-1], I, B)
    points.append(P)
    pa = me.Particle('Pa{{}}'.format(i + 1), P, m[i + 1])
    pa.potential_energy = m[i + 1] * g * P.pos_from(O).dot(I.y)
    parts.append(pa)
lm = me.LagrangesMethod(me.Lagrangian(I, *parts), q, forcelist=forces, frame=I)
lm.form_lagranges_equations()
t2 = time.perf_counter()
lm.linearize(q_ind=q, qd_ind=[x.diff() for x in q])
t3 = time.perf_counter()
print(json.dumps({{"import_s": t1 - t0, "equations_s": t2 - t1, "linearize_s": t3 - t2}}))
"""

MODEL_FILE = "from bench.models.pendulum_chain import model\n\n\ndef build():\n    return model({n})\n"
STEP = re.compile(r"^\[[^\]]*\] (.*): ([0-9.]+) s$")


def ours(n: int, folder: Path, timeout: float) -> dict | None:
    """The whole `python -m derive --model` process with each step's reported time, or
    None when it did not finish within timeout."""
    src = folder / f"pendulum_chain_{n}.py"
    src.write_text(MODEL_FILE.format(n=n))
    t0 = time.perf_counter()
    try:
        out = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(folder / "out"),
                              "--jobs", "1"], cwd=ROOT, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    wall = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"derive of N = {n} failed:\n{out.stderr[-3000:]}")
    steps = {m.group(1): float(m.group(2)) for m in map(STEP.match, out.stderr.splitlines()) if m}
    emit = sum(v for k, v in steps.items() if k.startswith("emit"))
    functions = steps.get("functions to emit", 0.0)
    derivation = sum(steps.values()) - emit - functions
    return {"whole_s": wall, "derivation_s": derivation, "functions_s": functions, "emission_s": emit,
            "other_s": wall - derivation - functions - emit, "steps": steps}


def baseline(code: str, n: int, timeout: float) -> dict | None:
    res, wall = fresh(["-c", code.format(n=n)], timeout)
    return None if res is None else dict(res, whole_s=wall)


def exponent(ns, ts) -> float | None:
    pts = [(math.log(n), math.log(t)) for n, t in zip(ns, ts) if n >= 4 and t]
    if len(pts) < 2:
        return None
    mx, my = (sum(p[i] for p in pts) / len(pts) for i in (0, 1))
    return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)


def chart(rec: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5))
    rows = rec["rows"]
    series = [("ours, whole process", "ours", "whole_s", "C0", "-o"),
              ("ours: derivation", "ours", "derivation_s", "C0", ":^"),
              ("ours: functions to emit", "ours", "functions_s", "C0", ":s"),
              ("ours: emission (CSE, 4 backends)", "ours", "emission_s", "C0", "--v"),
              ("KanesMethod + linearize(), whole", "kane", "whole_s", "C3", "-o"),
              ("LagrangesMethod + linearize(), whole", "lagrange", "whole_s", "C2", "-o")]
    for label, side, key, color, style in series:
        pts = [(r["N"], r[side][key]) for r in rows if r.get(side) and r[side].get(key)]
        if pts:
            k = rec["exponents"].get(f"{side}.{key}")
            ax.plot(*zip(*pts), style, color=color, label=label + (f" (N^{k:.2f})" if k else ""))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(list(NS))
    ax.set_xticklabels([str(n) for n in NS])
    ax.set_xlabel("links N")
    ax.set_ylabel("time, s (one core)")
    ax.set_title("N-link pendulum on a cart: derivation against sympy.physics.mechanics")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="*", default=list(NS), help="the chain lengths N")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per child process")
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.n:
            row = {"N": n, "ours": ours(n, Path(tmp), args.timeout), "kane": baseline(KANE, n, args.timeout),
                   "lagrange": baseline(LAGRANGE, n, args.timeout)}
            for side in ("kane", "lagrange"):
                if row["ours"] and row[side]:
                    row[f"{side}_over_ours"] = row[side]["whole_s"] / row["ours"]["whole_s"]
            rows.append(row)
            print(json.dumps({k: (round(v, 2) if isinstance(v, float) else v) for k, v in row.items()
                              if not isinstance(v, dict)}
                             | {s: round(row[s]["whole_s"], 2) if row[s] else None for s in ("ours", "kane", "lagrange")}),
                  flush=True)
    ns = [r["N"] for r in rows]
    exps = {}
    for side, keys in (("ours", ("whole_s", "derivation_s", "functions_s", "emission_s")),
                       ("kane", ("whole_s", "equations_s", "linearize_s")), ("lagrange", ("whole_s",))):
        for key in keys:
            exps[f"{side}.{key}"] = exponent(ns, [r[side][key] if r[side] else None for r in rows])
    rec = {"command": "python -m bench.pendulum_chain " + " ".join(argv or sys.argv[1:]), "rows": rows,
           "exponents": exps, "goal_kane_over_ours": GOAL_KANE,
           "goal_met": {str(r["N"]): (r.get("kane_over_ours") or 0) >= (GOAL_KANE if r["N"] >= 8 else 1.0)
                        for r in rows if r["N"] >= 4},
           "machine": machine()}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "pendulum_chain.json").write_text(json.dumps(rec, indent=1) + "\n")
    chart(rec, RESULTS / "pendulum_chain.png")
    print(json.dumps({"exponents": {k: (round(v, 2) if v else None) for k, v in exps.items()}}))


if __name__ == "__main__":
    main()
