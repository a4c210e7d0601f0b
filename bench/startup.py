"""Start-up of the command line, as whole processes: `gyro --help` and a warm
`gyro frequencies torsion_gyrocompass --json`, each beside `python -c pass` in the same run.

    python -m bench.startup [--runs N]

Goals: --help under 0.1 s and the warm frequencies under 0.25 s on an idle machine. Writes
bench/results/startup.json with the median, minimum and maximum of each."""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
GOALS = {"gyro --help": 0.1, "gyro frequencies --json (warm)": 0.25}


def _time(cmd, runs):
    out = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True, cwd="/tmp")
        out.append(time.perf_counter() - t0)
    return {"median": statistics.median(out), "min": min(out), "max": max(out)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.startup", description=__doc__)
    ap.add_argument("--runs", type=int, default=21)
    args = ap.parse_args(argv)
    gyro = str(Path(sys.executable).parent / "gyro")
    cmds = {"python -c pass": [sys.executable, "-c", "pass"],
            "gyro --help": [gyro, "--help"],
            "gyro frequencies --json (warm)": [gyro, "frequencies", "torsion_gyrocompass", "--json"]}
    subprocess.run(cmds["gyro frequencies --json (warm)"], capture_output=True, check=True)  # compile, caches
    res = {}
    for _ in range(2):  # interleaved rounds: a load on the machine falls on all alike
        for name, cmd in cmds.items():
            r = _time(cmd, args.runs // 2 + 1)
            res.setdefault(name, []).append(r)
    out = {name: {"median_s": statistics.median(r["median"] for r in rs), "min_s": min(r["min"] for r in rs),
                  "max_s": max(r["max"] for r in rs)} for name, rs in res.items()}
    for name, goal in GOALS.items():
        out[name]["goal_s"] = goal
        out[name]["met"] = out[name]["median_s"] < goal
    out["cpu_count"] = os.cpu_count()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "startup.json").write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    for name in cmds:
        r = out[name]
        goal = f" (goal < {r['goal_s']} s: {'met' if r['met'] else 'NOT met'})" if "goal_s" in r else ""
        print(f"{name:<34} median {r['median_s'] * 1e3:7.1f} ms  [{r['min_s'] * 1e3:.1f}..{r['max_s'] * 1e3:.1f}]{goal}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
