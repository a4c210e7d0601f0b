"""What the baselines share: the numeric M, D, K of a Linearizer, Routh-free elimination of
cyclic coordinates through their linearised first integrals, and a child process bounded in
time."""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def linearized_mdk(linearizer, n: int, op_point: list):
    """M, D, K of M dq'' + D dq' + K dq = 0 from `Linearizer.linearize` (implicit form, no
    A and B): the lower block rows are the linearised Lagrange equations
    Mass dq'' = A21 dq + A22 dq', so that K = -A21, D = -A22."""
    M_lin, A_lin, _ = linearizer.linearize(op_point=op_point, A_and_B=False)
    M_lin = np.array(M_lin.tolist(), dtype=float)
    A_lin = np.array(A_lin.tolist(), dtype=float)
    return M_lin[n:, n:], -A_lin[n:, n:], -A_lin[n:, :n]


def eliminate_cyclic(M, D, K, cyclic: list[int], keep: list[int]):
    """The operator over `keep` with the cyclic coordinates eliminated by their linearised
    first integrals at zero perturbation of the momenta: row c of the equations is
    d/dt(Mass[c,:] dq' + D[c,:] dq) = 0 (K's row vanishes, the coordinate being cyclic), so
    dqc' = -Mcc^-1 (Mck dqk' + Dck dqk), substituted with its derivative in the rows `keep`."""
    c, k = np.asarray(cyclic), np.asarray(keep)
    ix = np.ix_
    Mcc_inv = np.linalg.inv(M[ix(c, c)])
    Mkc, Mck, Dkc, Dck = M[ix(k, c)], M[ix(c, k)], D[ix(k, c)], D[ix(c, k)]
    Mr = M[ix(k, k)] - Mkc @ Mcc_inv @ Mck
    Dr = D[ix(k, k)] - Mkc @ Mcc_inv @ Dck - Dkc @ Mcc_inv @ Mck
    Kr = K[ix(k, k)] - Dkc @ Mcc_inv @ Dck
    return Mr, Dr, Kr


def main(run, argv=None) -> None:
    """`--json POINT`: run(point) and print its result as one JSON line."""
    import argparse

    ap = argparse.ArgumentParser()
    ap.add_argument("--json", required=True, help="the evaluation point as JSON")
    args = ap.parse_args(argv)
    print(json.dumps(run(json.loads(args.json))))


def fresh(args: list[str], timeout: float | None = None) -> tuple[dict | None, float]:
    """`python ARGS` in a fresh process from the project's root (caches cold, imports
    counted), bounded by `timeout` seconds: (its last JSON line, {} if it prints none, or
    None when it did not finish; its wall time). A failing child is RuntimeError with its
    stderr's end."""
    t0 = time.perf_counter()
    try:
        out = subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - t0
    wall = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"python {' '.join(args[:2])} failed:\n{out.stderr[-4000:]}")
    lines = [ln for ln in out.stdout.strip().splitlines() if ln.startswith("{")]
    return (json.loads(lines[-1]) if lines else {}), wall


def run_child(module: str, point: dict, timeout: float) -> tuple[dict | None, float]:
    """`python -m bench.baselines.<module> --json POINT` in a fresh process (`fresh`):
    (result or None when it did not finish, the child's wall time)."""
    return fresh(["-m", f"bench.baselines.{module}", "--json", json.dumps(point)], timeout)
