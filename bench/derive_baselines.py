"""`python -m bench.derive_baselines`: this project's derivation against sympy.physics.mechanics
(LagrangesMethod and its Linearizer, bench/baselines/) on every seed model, each side in a
fresh process, and the whole `make derive` against its 30 s goal.

Per model, the quantity both sides produce:
- torsion_gyrocompass: the operator M, D, K of the ten reduced coordinates about the
  approximate relative equilibrium (2.2), the spin eliminated by its integral;
- gimbal_gyroscope: the operator (1 x 1, theta) about a steady precession, psi and phi
  eliminated by their momenta L, H;
- gyrohorizoncompass: the operator (4 x 4) about the relative equilibrium (3.1);
- gimbal_precession: the `full` level's mass matrix and forcing (three bodies), at a state.

This project's time is the whole child process from before its imports to the symbolic
quantity (`--project MODEL`; the parameters symbolic throughout). The baseline's is its
child's from before its imports to the numbers at the point (its Linearizer needs them to
finish in reasonable time on the torsion gyrocompass); it is bounded by `--timeout`. The
agreement is that of the baseline's numbers with the project's generated functions at the
same point (largest difference over the largest entry, per matrix). `--pipeline MODEL`
times the project's whole per-model derivation (`derive.pipeline.derive`: checks,
identities, the full equations, both routes of the operator and their 30-digit comparison,
the variants) with each step's time: where the time goes.

Writes bench/results/derive_baselines.json.
"""
from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench import machine
from bench.baselines.common import fresh

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
MODELS = ("torsion_gyrocompass", "gimbal_gyroscope", "gyrohorizoncompass", "gimbal_precession")
QUANTITY = {
    "torsion_gyrocompass": "operator M, D, K (10 x 10) about the approximate equilibrium (2.2)",
    "gimbal_gyroscope": "operator M, D, K (1 x 1) about a steady precession (psi, phi eliminated)",
    "gyrohorizoncompass": "operator M, D, K (4 x 4) about the relative equilibrium (3.1)",
    "gimbal_precession": "full level: mass matrix (3 x 3) and forcing (3) of the three bodies",
}
GOAL_RATIO = 100.0
GOAL_MAKE_DERIVE_S = 30.0


# ----------------------------------------------------------------------------- this project

def _project_torsion_gyrocompass():
    from derive import mechanics as mech
    from derive.models import torsion_gyrocompass as tg

    L = tg.lagrangian().subs({f: 0 for f in (tg.f1(tg.gamma3), tg.f2(tg.gamma3), tg.f3(tg.gamma3))})
    R = mech.routhian(L, tg.gamma3d, tg.H)
    q = [tg.q[tg.COORDINATES.index(c)] for c in tg.REDUCED]
    qd = [tg.qd[tg.COORDINATES.index(c)] for c in tg.REDUCED]
    op = mech.quadratic_expansion(R, q, qd, at={tg.q[tg.COORDINATES.index(c)]: 0 for c in tg.ODD})
    return [op.M, op.D, op.K]


def _project_gimbal_gyroscope():
    from derive import mechanics as mech
    from derive.models import gimbal_gyroscope as gg

    R = mech.routhian(gg.lagrangian(), gg.phid, gg.H)
    R = mech.routhian(R, gg.psid, gg.L)
    op = mech.quadratic_expansion(R, [gg.theta], [gg.thetad])
    return [op.M, op.D, op.K]


def _project_gyrohorizoncompass():
    from derive import mechanics as mech
    from derive.models import gyrohorizoncompass as ghc

    q, qd = list(ghc.q), list(ghc.qd)
    op = mech.quadratic_expansion(ghc.lagrangian(), q, qd)
    Qq, Qv = mech.linearize_forces([0, 0, 0, ghc.sensor_moment()], q, qd)
    return [op.M, op.D - Qv, op.K - Qq]


def _project_gimbal_precession():
    # the steps of pipeline.derive for these equations: generalised forces (Rayleigh's
    # function, the loads by virtual power, the motor on phi), then the mass-matrix form
    from derive import mechanics as mech
    from derive.models import gimbal_precession as gp

    q, qd = list(gp.q), list(gp.qd)
    Q = mech.rayleigh_forces(gp.dissipation(), qd)
    for load in gp.loads():
        Q = [a + b for a, b in zip(Q, mech.load_forces(load.vector, load.velocity, qd))]
    Q[2] = Q[2] + gp.Mmotor
    Mq, f = mech.mass_matrix_form(gp.kinetic_energy(), q, qd, Q)
    return [Mq, f]


def project_child(name: str) -> dict:
    """The project's derivation of the model's quantity, timed from before the imports."""
    t0 = time.perf_counter()
    import derive.mechanics  # noqa: F401  (sympy, symengine and the machinery)

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    mats = globals()[f"_project_{name}"]()
    t_derive = time.perf_counter() - t1
    return {"import_s": t_import, "derive_s": t_derive, "total_s": t_import + t_derive,
            "ops": int(sum(sum(e.count_ops() for e in m) for m in mats))}


def pipeline_child(name: str) -> dict:
    """The project's whole derivation of one model (no emission), each step timed."""
    t0 = time.perf_counter()
    import io

    from derive import pipeline
    from derive.models import MODELS as FOUND
    import importlib

    t_import = time.perf_counter() - t0
    t1 = time.perf_counter()
    model = importlib.import_module(FOUND[name]).build()
    t_build = time.perf_counter() - t1
    steps = pipeline.Steps(out=io.StringIO())
    pipeline.derive(model, steps)
    t_total = time.perf_counter() - t0
    return {"import_s": t_import, "build_s": t_build, "total_s": t_total,
            "steps_s": {k: v for k, v in steps.timings}}


# ----------------------------------------------------------------------------- the points

def points() -> dict:
    """Per model: the point given to the baseline and the project's generated numbers there."""
    from gyro import load

    out = {}
    rng = np.random.default_rng(23)

    m = load("torsion_gyrocompass")
    P = m.vector(m.defaults)
    qe = np.ravel(m.numpy.equilibrium_approx(P))
    q0 = dict(zip(m.meta["equilibrium_coordinates"], map(float, qe)))
    names = ("m M l l1 l2 A C I1 I2 I3 K0 Kp Kgamma H u phi g").split()
    Mo, Do, Ko = m.numpy.operator(P, qe)
    out["torsion_gyrocompass"] = {
        "point": {"params": {k: m.defaults[k] for k in names}, "q0": q0},
        "order": m.meta["reduced"], "values": {"M": Mo, "D": Do, "K": Ko},
        "where": "the defaults (the paper example), at the approximate equilibrium (2.2)"}

    m = load("gimbal_gyroscope")
    d = m.defaults
    P = m.vector(d)
    theta0, H = 1.0, 3.0
    dpsi = float(np.ravel(m.numpy.stationary_precession(P, [theta0], [H]))[0])
    L = (d["A0"] - d["C0"] * math.cos(theta0)**2) * dpsi + H * math.cos(theta0)
    Mo, Do, Ko = m.numpy.operator(P, [theta0], [H, L])
    A1, B2 = 0.006, 0.004  # the bodies' moments: their sums A0, B0, C0 are the defaults
    bodies = {"C3": d["A0"] - B2 - A1, "B1": d["B0"] - A1, "B2": B2, "B3": B2 + A1 - d["C0"], "A1": A1,
              "A3": d["A3"]}
    out["gimbal_gyroscope"] = {
        "point": {**bodies, **{k: d[k] for k in ("P1", "P", "eta20", "eta30", "l")},
                  "theta": theta0, "H": H, "L": L},
        "values": {"M": Mo, "D": Do, "K": Ko},
        "where": f"the defaults, theta0 = {theta0} rad, H = {H} N m s, psi0' = {dpsi:.6g} rad/s "
                 "of the stationary precession (3.1), L from (1.2)"}

    m = load("gyrohorizoncompass")
    P = m.vector(m.defaults)
    eps0 = float(np.ravel(m.numpy.relative_equilibrium(P)[0])[0])
    qe = [0.0, 0.0, 0.0, eps0]
    Mo, Do, Ko = m.numpy.operator(P, qe)
    out["gyrohorizoncompass"] = {
        "point": {**m.defaults, "epsilon0": eps0}, "values": {"M": Mo, "D": Do, "K": Ko},
        "where": f"the defaults (Earth set), epsilon0 = {eps0:.10g} rad (3.1)"}

    m = load("gimbal_precession")
    d = dict(m.defaults)
    for k in ("u_xi", "f_alpha", "f_beta", "f_phi", "Mmotor", "k_xi1", "l_y", "l_z", "m_x", "m_y", "m_z"):
        d[k] = float(rng.uniform(1e-4, 1e-3))  # every term of the equations present
    d["C1"], d["C2"] = 0.5 * d["C3"], 1.5 * d["C3"]  # a flat ring: C2 - C1 = C3 enters,
    d["u_eta"], d["u_zeta"] = 0.3, 0.7  # through (C2 - C1) times the base rate's eta1, zeta1 components
    P = m.vector(d)
    qv = rng.uniform(-1, 1, 3).tolist()
    qdv = rng.uniform(-2, 2, 3).tolist()
    qdv[2] = 900.0
    out["gimbal_precession"] = {
        "point": {**d, "q": qv, "qd": qdv},
        "values": {"mass_matrix": m.numpy.mass_matrix(P, qv), "forcing": np.ravel(m.numpy.forcing(P, qv, qdv))},
        "where": "the defaults with the zero moments, frictions and u_xi drawn in [1e-4, 1e-3], "
                 "a flat outer ring (C1 = C3/2, C2 = 3 C3/2) on a base turning at u_eta = 0.3, "
                 "u_zeta = 0.7 rad/s, at a random state (phi' = 900 rad/s)"}
    return out


def agreement(ours: dict, theirs: dict, order=None, their_order=None) -> dict:
    """Per matrix: max |ours - theirs| / max(|ours|, |theirs|) (0 where both are zero, as the
    gimbal gyroscope's D is), the baseline's rows and columns put in the project's order
    first."""
    out = {}
    for k, a in ours.items():
        a = np.atleast_1d(np.asarray(a, dtype=float))
        b = np.atleast_1d(np.asarray(theirs[k], dtype=float))
        if order is not None:
            idx = [their_order.index(c) for c in order]
            b = b[np.ix_(idx, idx)]
        scale = max(np.max(np.abs(a)), np.max(np.abs(b)))
        out[k] = float(np.max(np.abs(a - b)) / scale) if scale > 0 else 0.0
    return out


# ----------------------------------------------------------------------------- the bench

def bench(models, timeout: float, tolerance: float = 1e-10) -> dict:
    from bench.baselines.common import run_child

    pts = points()
    res = {}
    for name in models:
        print(f"{name}: {QUANTITY[name]}", flush=True)
        ours, ours_wall = fresh(["-m", "bench.derive_baselines", "--project", name])
        print(f"  this project: {ours['total_s']:.2f} s (imports {ours['import_s']:.2f} s)", flush=True)
        whole, whole_wall = fresh(["-m", "bench.derive_baselines", "--pipeline", name])
        top = max(whole["steps_s"].items(), key=lambda kv: kv[1])
        print(f"  this project, whole per-model derivation: {whole['total_s']:.2f} s "
              f"(largest step: {top[0]} {top[1]:.2f} s)", flush=True)
        pt = pts[name]
        base, base_wall = run_child(name, json.loads(json.dumps(pt["point"])), timeout)
        row = {"quantity": QUANTITY[name], "where": pt["where"],
               "project": {**ours, "wall_s": ours_wall,
                           "command": f"python -m bench.derive_baselines --project {name}"},
               "project_whole": {**whole, "wall_s": whole_wall,
                                 "command": f"python -m bench.derive_baselines --pipeline {name}"},
               "baseline_command": f"python -m bench.baselines.{name} --json POINT",
               "timeout_s": timeout}
        if base is None:
            row["baseline"] = {"finished": False, "wall_s": base_wall}
            row["ratio"] = None
            row["ratio_lower_bound"] = timeout / ours["total_s"]
            row["agree"] = None
            print(f"  baseline: did not finish within {timeout:g} s: ratio > {row['ratio_lower_bound']:.0f}x")
        else:
            row["baseline"] = {"finished": True, "wall_s": base_wall,
                               **{k: v for k, v in base.items() if k not in ("values", "order")}}
            row["ratio"] = base["total_s"] / ours["total_s"]
            row["ratio_whole"] = base["total_s"] / whole["total_s"]
            # both sides without their imports (sympy, symengine, the machinery): the
            # derivation proper against LagrangesMethod, its Linearizer and its numbers
            row["ratio_without_imports"] = (base["derive_s"] + base["evaluate_s"]) / ours["derive_s"]
            diff = agreement(pt["values"], base["values"], pt.get("order"), base.get("order"))
            row["max_rel_diff"] = diff
            row["tolerance"] = tolerance
            row["agree"] = bool(max(diff.values()) <= tolerance)
            print(f"  baseline: {base['total_s']:.2f} s (imports {base['import_s']:.2f} s, derivation "
                  f"{base['derive_s']:.2f} s, numbers {base['evaluate_s']:.2f} s); ratio "
                  f"{row['ratio']:.1f}x ({row['ratio_without_imports']:.1f}x without the imports); "
                  f"agreement {max(diff.values()):.1e}", flush=True)
        row["goal_met"] = bool((row["ratio"] or row["ratio_lower_bound"]) >= GOAL_RATIO)
        res[name] = row
    return res


MAKE_JOBS = 2  # the Makefile's JOBS: `make derive` runs python -m derive --jobs 2


def _derive_run(jobs: int) -> tuple[float, str]:
    """Wall time and stderr of `python -m derive --out DIR --jobs N` (all four models), a
    fresh process."""
    tmp = Path(tempfile.mkdtemp())
    try:
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-m", "derive", "--out", str(tmp / "generated"), "--jobs", str(jobs)],
                             cwd=ROOT, check=True, capture_output=True, text=True)
        return time.perf_counter() - t0, out.stderr
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def bench_make_derive() -> dict:
    """`make derive`'s work: `python -m derive --out DIR --jobs 2` (all four models, on the
    machine's two cores, as the Makefile runs it), and the same with one job (the work
    itself, one model after another); each model's total and its steps' times as the
    one-job run prints them."""
    import re

    wall, _ = _derive_run(MAKE_JOBS)
    wall_one, err = _derive_run(1)
    steps, per_model = {}, {}
    for line in err.splitlines():
        m = re.match(r"\[(\w+)\] (.*): ([0-9.]+) s$", line)
        if m:
            steps.setdefault(m[1], {})[m[2]] = float(m[3])
        m = re.match(r"\[(\w+)\] \d+ files in .*; ([0-9.]+) s$", line)
        if m:
            per_model[m[1]] = float(m[2])
    print(f"make derive (python -m derive --out DIR --jobs {MAKE_JOBS}, all four models): {wall:.1f} s "
          f"(goal <= {GOAL_MAKE_DERIVE_S:g} s); with one job {wall_one:.1f} s", flush=True)
    for name, total in per_model.items():
        top = sorted(steps[name].items(), key=lambda kv: -kv[1])[:2]
        print(f"  {name}: {total:.1f} s; " + "; ".join(f"{k} {v:.1f} s" for k, v in top), flush=True)
    return {"wall_s": wall, "wall_s_one_job": wall_one, "jobs": MAKE_JOBS, "goal_s": GOAL_MAKE_DERIVE_S,
            "goal_met": wall <= GOAL_MAKE_DERIVE_S, "per_model_s": per_model, "steps_s": steps,
            "command": f"python -m derive --out DIR --jobs {MAKE_JOBS} (and --jobs 1)"}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.derive_baselines", description=__doc__.split("\n\n")[0])
    ap.add_argument("--project", choices=MODELS, help="(child) time this project's derivation of MODEL")
    ap.add_argument("--pipeline", choices=MODELS, help="(child) time the whole derivation of MODEL")
    ap.add_argument("--models", default=",".join(MODELS), help="comma-separated models to bench")
    ap.add_argument("--timeout", type=float, default=300.0, help="bound on each baseline (s)")
    ap.add_argument("--no-make-derive", action="store_true", help="skip timing `make derive`")
    ap.add_argument("--out", default=str(RESULTS / "derive_baselines.json"))
    ap.add_argument("--update", action="store_true",
                    help="keep the other models' rows (and make derive's, if skipped) of the existing record")
    args = ap.parse_args(argv)
    if args.project:
        print(json.dumps(project_child(args.project)))
        return 0
    if args.pipeline:
        print(json.dumps(pipeline_child(args.pipeline)))
        return 0
    models = [m for m in args.models.split(",") if m]
    path = Path(args.out)
    old = json.loads(path.read_text()) if args.update and path.exists() else {}
    command = "python -m bench.derive_baselines " + " ".join(argv if argv is not None else sys.argv[1:])
    new = bench(models, args.timeout)
    for row in new.values():
        row["bench_command"] = command
    rows = {**old.get("models", {}), **new}
    res = {"models": rows, "goal_ratio": GOAL_RATIO, "command": command,
           "machine": machine()}
    if not args.no_make_derive:
        res["make_derive"] = bench_make_derive()
    elif "make_derive" in old:
        res["make_derive"] = old["make_derive"]
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(res, indent=1, sort_keys=True) + "\n")
    tmp.replace(path)
    print(f"written {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
