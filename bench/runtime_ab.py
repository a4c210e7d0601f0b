"""The default frequency method against an earlier commit's code, in the same run.

    python -m bench.runtime_ab [REV] [--sets N] [--repeats R]

Checks REV (default: the commit before the runtime took its present shape) out into a
temporary git worktree, and times `ladder.spectrum(model, P, "default")` on the same N
parameter sets (the example spread by +-50 %, seeded) in fresh processes of each tree,
alternating, R times each, after a warm-up call that compiles the C (each tree into its own
cache). Reports the median seconds per set of each and their ratio (new / old), and writes
bench/results/runtime_ab.json."""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
BASE = "cf1d59a"  # the last commit with gyro/ladder.py holding every method and gyro/modal.py

CHILD = r"""
import sys, time, numpy as np
from gyro import ladder, load
model = load("torsion_gyrocompass")
rng = np.random.default_rng(20261130)
P = model.vector(model.defaults) * rng.uniform(0.5, 1.5, (int(sys.argv[1]), len(model.param_names)))
P[:, model.param_names.index("phi")] = rng.uniform(5, 85, len(P))
ladder.spectrum(model, P[:8], "default")  # warm: compile, imports
t0 = time.perf_counter()
s = ladder.spectrum(model, P, "default")
dt = time.perf_counter() - t0
print(dt / len(P), float(np.nansum(s.frequencies)))
"""


def run(tree: Path, sets: int, cache: Path) -> tuple[float, float]:
    env = {"PYTHONPATH": str(tree), "GYRO_CACHE": str(cache), "PATH": "/usr/bin:/bin",
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
    import os

    for k in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "HOME"):
        if k in os.environ:
            env[k] = os.environ[k]
    out = subprocess.run([sys.executable, "-c", CHILD, str(sets)], cwd=tempfile.gettempdir(), env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    return float(out[0]), float(out[1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.runtime_ab", description=__doc__)
    ap.add_argument("rev", nargs="?", default=BASE)
    ap.add_argument("--sets", type=int, default=4000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "old"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(old), args.rev], check=True)
        try:
            times = {"new": [], "old": []}
            sums = {}
            for _ in range(args.repeats):
                for name, tree in (("old", old), ("new", ROOT)):
                    t, s = run(tree, args.sets, Path(tmp) / f"cache-{name}")
                    times[name].append(t)
                    sums[name] = s
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(old)], check=True)
    med = {k: statistics.median(v) for k, v in times.items()}
    out = {"rev": args.rev, "sets": args.sets, "repeats": args.repeats,
           "s_per_set": med, "all_s_per_set": times, "ratio_new_over_old": med["new"] / med["old"],
           "same_answers": abs(sums["new"] - sums["old"]) <= 1e-9 * abs(sums["old"])}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "runtime_ab.json").write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    print(f"default method, {args.sets} sets, median of {args.repeats}: "
          f"{med['old'] * 1e6:.1f} us/set at {args.rev}, {med['new'] * 1e6:.1f} us/set now; "
          f"ratio {out['ratio_new_over_old']:.3f}; same answers: {out['same_answers']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
