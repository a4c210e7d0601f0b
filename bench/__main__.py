"""`python -m bench` (or `make bench`): speed of the derivation against a baseline, in one run,
the accuracy-against-speed chart of the frequency methods (bench/ladder.py), where the
formulas' error estimates hold (bench/formula_sweep.py) and where the default method's time
goes, against LAPACK in the same run (bench/speed.py).

The baseline derives the same operator J(p) with sympy.physics.mechanics (LagrangesMethod
and its linearizer, bench/baseline_mechanics.py), bounded by 600 s; this project's
derivation is timed in a fresh process as well. Results go to bench/results/derive.json.
"""
from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from bench.baselines.common import fresh

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"


def bench_derive(timeout: float, skip_baseline: bool) -> dict:
    print("this project: derivation of J(p) in a fresh process ...", flush=True)
    ours, _ = fresh(["-m", "bench.derive_speed"])
    print(f"  J(p): {ours['derive_J_s']:.2f} s (imports {ours['import_s']:.2f} s)", flush=True)
    print("this project: full `python -m derive` (all steps and emission) ...", flush=True)
    _, full_wall = fresh(["-m", "derive", "--out", str(RESULTS / "_derive_tmp"), "--jobs", "2"])  # as the Makefile
    print(f"  make derive: {full_wall:.2f} s", flush=True)
    result = {"ours": ours, "ours_make_derive_s": full_wall}
    if skip_baseline:
        return result
    print(f"baseline: sympy.physics.mechanics, bounded by {timeout:.0f} s ...", flush=True)
    base, wall = fresh(["bench/baseline_mechanics.py", "--json"], timeout=timeout)
    if base is None:
        base_time, finished = timeout, False
        print(f"  did not finish within {timeout:.0f} s: {timeout:.0f} s is reported as its time")
    else:
        base_time, finished = base["total_s"], True
        print(f"  derive {base['derive_s']:.1f} s + first linearize {base['linearize_s']:.1f} s "
              f"= {base_time:.1f} s", flush=True)
    result["baseline"] = {"finished": finished, "time_s": base_time, "wall_s": wall, **(base or {})}
    t_ours = ours["import_s"] + ours["derive_J_s"]
    result["ratio_J"] = base_time / t_ours
    result["ratio_make_derive"] = base_time / full_wall
    if finished:
        # the baseline linearises at the approximate equilibrium (2.2): compare there
        from gyro import load
        from gyro.qep import companion_eigenvalues as _companion_eigenvalues, refine_all, representatives

        m = load("torsion_gyrocompass")
        P = m.vector(m.defaults)
        M, D, K = m.numpy.operator(P, m.numpy.equilibrium_approx(P))
        lams = _companion_eigenvalues(M, D, K)
        roots, _ = refine_all(M, D, K, lams, representatives(lams, 10))
        ours_at_22 = np.sort(np.abs(roots.imag))
        result["max_rel_freq_diff_at_2_2"] = float(np.max(np.abs(np.array(base["frequencies"]) / ours_at_22 - 1)))
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    ap.add_argument("--timeout", type=float, default=600.0, help="bound on the baseline (s)")
    ap.add_argument("--skip-baseline", action="store_true", help="time this project only")
    ap.add_argument("--only", choices=("derive", "ladder"), help="run one bench only")
    args = ap.parse_args(argv)
    RESULTS.mkdir(parents=True, exist_ok=True)
    if args.only != "derive":
        # accuracy against speed of the frequency methods, in a fresh one-thread process
        subprocess.run([sys.executable, "-m", "bench.ladder"], cwd=ROOT, check=True)
        subprocess.run([sys.executable, "-m", "bench.formula_sweep"], cwd=ROOT, check=True)
        subprocess.run([sys.executable, "-m", "bench.speed"], cwd=ROOT, check=True)
    if args.only == "ladder":
        return 0
    res = bench_derive(args.timeout, args.skip_baseline)
    res["machine"] = {"python": platform.python_version(), "processor": platform.machine(),
                      "cores": __import__("os").cpu_count()}
    import shutil

    shutil.rmtree(RESULTS / "_derive_tmp", ignore_errors=True)
    if "ratio_J" in res:
        print(f"speed-up on J(p): {res['ratio_J']:.0f}x (goal >= 20x); "
              f"against the whole `make derive`: {res['ratio_make_derive']:.0f}x")
    path = RESULTS / "derive.json"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(res, indent=1, sort_keys=True) + "\n")
    tmp.replace(path)
    print(f"written {path.relative_to(ROOT)}")
    subprocess.run([sys.executable, "-m", "bench.gimbal_integrators"], cwd=ROOT, check=True)
    for module in ("bench.startup", "bench.runtime_ab"):
        subprocess.run([sys.executable, "-m", module], cwd=ROOT, check=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
