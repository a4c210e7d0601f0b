"""Where the time of the exact frequencies goes, piece by piece, against LAPACK in the same run.

`python -m bench.speed [--sets N] [--repeats R]` (run by `make bench` with the ladder): on N
random sets of the torsion gyrocompass (spin 0.1x..10x log-uniform, latitude 1..89 deg,
seeded) and on one core, times in one process, the pieces alternating within each of R
repetitions and each figure the median of the R:

- the default method end to end, and the formulas (the selector's cheapest level);
- the default method's pieces: equilibria, operators, the starts of the refinement
  (Hermitian block forms, their eigenvalues and a vector per root), the refinement,
  and the starts as they were before (LAPACK's eigvalsh of the block forms, one shared
  start vector) for comparison;
- baselines: LAPACK's eigvals of the 20x20 companion matrix (scipy, set by set: the issue's
  yardstick), and the floors of the refinement: one 10x10 complex LU solve per root
  (LAPACK zgesv through NumPy's batched solve, ten per set) and the memory traffic of the
  batch (M, D, K read, frequencies and estimates written) at the bandwidth of a large copy,
  and that of the formulas (a parameter row read, frequencies, growth and estimates written).

The machine is shared: every figure is a ratio against a baseline measured in the same run,
and medians of several repetitions. Writes bench/results/speed.json.
"""
from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"  # one core: set before NumPy loads its BLAS

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from bench import machine  # noqa: E402
from gyro import cbackend, ladder, load, qep  # noqa: E402
from gyro.equilibrium import equilibria, operators  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
MODEL = load("torsion_gyrocompass")
GOALS = {"default_sets_per_s": 1e5, "default_over_eigvals_speedup": 4.0, "formulas_sets_per_s": 2e7}
COMPANION_SETS = 500  # scipy's eigvals set by set: a sample is enough for its time per set


def random_sets(n: int, seed: int = 20261201) -> np.ndarray:
    rng = np.random.default_rng(seed)
    P = np.tile(MODEL.vector(MODEL.defaults), (n, 1))
    ix = MODEL.param_names.index
    P[:, ix("H")] *= np.exp(rng.uniform(np.log(0.1), np.log(10), n))
    P[:, ix("phi")] = rng.uniform(1, 89, n)
    return P


def floors(M, D, K, w) -> dict:
    """Callables for the floors: one complex LU solve per root (LAPACK, batched), the memory
    traffic of the batch at the speed of a large copy."""
    n = M.shape[-1]
    w = w * (1 + 1e-7)  # near the roots, not on one to the last bit (a singular J)
    J = (K[:, None] - w[..., None, None]**2 * M[:, None] + 1j * w[..., None, None] * D[:, None])
    rhs = np.ones(J.shape[:-1] + (1,), complex)
    big = np.ones(32 * 2**20 // 8)  # 32 MB: beyond the caches
    dst = np.empty_like(big)
    bytes_per_set = 3 * n * n * 8 + 2 * n * 8  # M, D, K read; frequencies, estimates written
    return {"lu_solve_per_root": lambda: np.linalg.solve(J, rhs),
            "copy_32MB": lambda: np.copyto(dst, big), "_bytes_per_set": bytes_per_set,
            "_copy_bytes": 2 * big.nbytes}


def measure(sets: int = 20000, repeats: int = 5) -> dict:
    P = random_sets(sets)
    ladder.spectrum(MODEL, P[:8], "default")  # warm: compile, imports
    ladder.spectrum(MODEL, P[:8], "formulas")
    qe, ok = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    herm, w0, z0 = qep.block_starts(MODEL, M, D, K, ok)
    kern = cbackend.qep_hermitian(MODEL.name)
    blocks = qep.blocks(MODEL)
    forms = [kern(M, D, K, b) for b in blocks]
    shared = qep.start_vectors(sets, M.shape[-1], M.shape[-1])
    A = qep.companion_matrix(M[:COMPANION_SETS], D[:COMPANION_SETS], K[:COMPANION_SETS])
    import scipy.linalg as sla

    fl = floors(M, D, K, w0)
    moves = qep.equilibrium_moves(MODEL, P, qe, M, D, K)
    w_ref, z_ref, _, _ = qep.rayleigh(MODEL, M, D, K, w0, z0, 3, ladder.DEFAULT_TOL)
    tasks = {
        "default": (lambda: ladder.spectrum(MODEL, P, "default"), sets),
        "formulas": (lambda: ladder.spectrum(MODEL, P, "formulas"), sets),
        "eigvals of the companion (LAPACK)": (
            lambda: [sla.eigvals(a, check_finite=False) for a in A], COMPANION_SETS),
        "piece: equilibria": (lambda: equilibria(MODEL, P), sets),
        "piece: operators": (lambda: operators(MODEL, P, qe), sets),
        "piece: starts (block forms, eigenvalues, a vector per root)": (
            lambda: qep.block_starts(MODEL, M, D, K, ok), sets),
        "piece: refinement (<= 3 steps, to 1e-10)": (
            lambda: qep.rayleigh(MODEL, M, D, K, w0, z0, 3, ladder.DEFAULT_TOL), sets),
        "piece: the operator's rounding (two probes)": (
            lambda: qep.equilibrium_moves(MODEL, P, qe, M, D, K), sets),
        "piece: its contraction into the roots (C)": (
            lambda: qep.hermitian_moves(moves, M, D, w_ref, z_ref, MODEL), sets),
        "before: starts by the block forms and LAPACK eigvalsh": (
            lambda: [np.linalg.eigvalsh(kern(M, D, K, b)[0]) for b in blocks], sets),
        "before: refinement from one shared start vector": (
            lambda: qep.rayleigh(MODEL, M, D, K, w0, shared, 3, ladder.DEFAULT_TOL), sets),
        "floor: one 10x10 complex LU solve per root (LAPACK)": (fl["lu_solve_per_root"], sets),
        "floor: copy of 32 MB": (fl["copy_32MB"], 1),
    }
    del forms
    times: dict[str, list[float]] = {k: [] for k in tasks}
    for r in range(repeats):
        print(f"  repetition {r + 1} of {repeats} ...", flush=True)
        for name, (f, count) in tasks.items():
            t0 = time.perf_counter()
            f()
            times[name].append((time.perf_counter() - t0) / count)
    med = {k: statistics.median(v) for k, v in times.items()}
    bandwidth = fl["_copy_bytes"] / med.pop("floor: copy of 32 MB")
    med["floor: memory traffic of the batch"] = fl["_bytes_per_set"] / bandwidth
    # the refinement needs at least one solve per root; one per set is the yardstick
    med["floor: one 10x10 complex LU solve per set (LAPACK)"] = (
        med["floor: one 10x10 complex LU solve per root (LAPACK)"] / M.shape[-1])
    # the formulas read a parameter row and write a spectrum: frequencies, growth, estimates
    med["floor: memory traffic of the formulas"] = (P.shape[1] + 3 * M.shape[-1]) * 8 / bandwidth
    s = ladder.spectrum(MODEL, P, "default")
    steps = _steps(M, D, K, w0, z0)
    eig = med["eigvals of the companion (LAPACK)"]
    return {
        "sets": sets, "repeats": repeats, "seed": 20261201, "threads": 1, "machine": machine(),
        "note": "medians of the repetitions, all pieces alternating in one process on a shared machine",
        "s_per_set": med, "all_s_per_set": times,
        "sets_per_s": {k: 1 / v for k, v in med.items()},
        "over_eigvals": {k: eig / v for k, v in med.items()},
        "memory_bandwidth_bytes_per_s": bandwidth,
        "default_routes": {r: int(np.sum(s.route == r)) for r in sorted(set(s.route))},
        "default_max_estimate": float(np.max(s.error_estimate)),
        "refinement_steps_per_root": steps,
        "goals": GOALS,
        "standing": {"default_sets_per_s": 1 / med["default"],
                     "default_over_eigvals_speedup": eig / med["default"],
                     "formulas_sets_per_s": 1 / med["formulas"]}}


def _steps(M, D, K, w0, z0) -> dict:
    """Mean refinement steps per root from the block vectors and from one shared vector."""
    out = {}
    for name, z in (("block vectors", z0), ("one shared vector", qep.start_vectors(*w0.shape, w0.shape[1]))):
        done = np.zeros(w0.shape, bool)
        total = np.zeros(w0.shape)
        for k in (1, 2, 3):
            _, _, e, _ = qep.rayleigh(MODEL, M, D, K, w0, z, k, ladder.DEFAULT_TOL)
            total += ~done
            done |= e <= ladder.DEFAULT_TOL
        out[name] = {"mean_steps": float(total.mean()), "one_step_fraction": float(np.mean(total == 1))}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.speed", description=__doc__.splitlines()[0])
    ap.add_argument("--sets", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"timing on {args.sets} random sets, one core, median of {args.repeats} (a shared machine: "
          "read the ratios) ...", flush=True)
    out = measure(args.sets, args.repeats)
    eig = out["s_per_set"]["eigvals of the companion (LAPACK)"]
    for k, v in out["s_per_set"].items():
        print(f"  {k:60s} {v * 1e6:9.3f} us per set  ({eig / v:6.2f}x eigvals)")
    st = out["standing"]
    print(f"default: {st['default_sets_per_s']:,.0f} sets/s, {st['default_over_eigvals_speedup']:.2f}x eigvals "
          f"(goals 100,000 and 4x); formulas: {st['formulas_sets_per_s']:,.0f} sets/s (goal 20,000,000)")
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / "speed.json"
    path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
    print(f"written {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
