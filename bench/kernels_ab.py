"""The kernels of gyro/csrc against the same kernels as they were rendered into each model's C.

`python -m bench.kernels_ab [--rev REV] [--sets N] [--repeats R]`: for the torsion
gyrocompass (n = 10, with a real form) and the gyrohorizoncompass (n = 4, without), builds
the model's C of revision REV (default c4f2f5a, the last with templates/qep.c.j2, where the
kernels were rendered into it) and this checkout's kernels (gyro/csrc, -DQEP_N=n) under
gyro.cbackend.FLAGS, calls both on the same N operators (random sets, seeded), and says
per kernel whether every output is the same to the byte, then times them alternately in
one process (R repetitions; the median of the ratios and their quartiles: the machine is
shared). docs/architecture.md quotes it.
"""
from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import ctypes  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from gyro import cbackend, load, qep  # noqa: E402
from gyro.equilibrium import equilibria, operators  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
D_, L_, I_ = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_long), ctypes.POINTER(ctypes.c_int)


def _p(a, t=D_):
    return None if a is None else a.ctypes.data_as(t)


def _build(out: Path, sources, defines=()) -> ctypes.CDLL:
    subprocess.run(["gcc", *cbackend.FLAGS, *defines, "-I", str(sources[0].parent), *map(str, sources),
                    "-o", str(out), "-lm"], check=True)
    return ctypes.CDLL(str(out))


def _operators(name: str, sets: int):
    """The operators of `sets` parameter sets: bench.speed's for the torsion gyrocompass,
    every parameter within a factor e^0.3 of its default for another model (seeded)."""
    from bench.speed import random_sets

    m = load(name)
    if name == "torsion_gyrocompass":
        P = random_sets(sets)
    else:
        P = np.tile(m.vector(m.defaults), (sets, 1))
        P *= np.exp(np.random.default_rng(20261206).uniform(-0.3, 0.3, P.shape))
    M, D, K = operators(m, P, equilibria(m, P)[0])
    keep = np.all(np.isfinite(M) & np.isfinite(D) & np.isfinite(K), axis=(1, 2))
    return m, *(np.ascontiguousarray(X[keep]) for X in (M, D, K))


def compare(name: str, rev: str, sets: int, repeats: int, tmp: Path) -> dict:
    m, M, D, K = _operators(name, sets)
    N, n = M.shape[0], M.shape[-1]
    old_dir = tmp / f"old_{name}"
    old_dir.mkdir()
    for ext in ("c", "h"):
        (old_dir / f"{name}.{ext}").write_bytes(subprocess.run(
            ["git", "show", f"{rev}:generated/{name}/{name}.{ext}"], cwd=ROOT, check=True, capture_output=True).stdout)
    old = _build(tmp / f"old_{name}.so", [old_dir / f"{name}.c"])
    new = _build(tmp / f"new_{n}.so", [cbackend.CSRC / f for f in cbackend.KERNELS["qep"]], (f"-DQEP_N={n}",))
    roots_new = _build(tmp / "new_polyroots.so", [cbackend.CSRC / f for f in cbackend.KERNELS["polyroots"]])
    form = m.meta.get("operator_real_form")
    group = None if form is None else np.ascontiguousarray(form, dtype=np.intc)
    blocks = qep.blocks(m)
    idx = np.ascontiguousarray(np.concatenate(blocks), dtype=np.int64)
    sizes = np.array([len(b) for b in blocks], dtype=np.int64)
    rhs = np.ascontiguousarray(qep.start_vectors(1, n, 1)[0, 0], dtype=complex)
    fn = lambda lib, kernel: getattr(lib, f"{name}_{kernel}" if lib is old else f"gyro_{kernel}")  # noqa: E731
    g = lambda lib: [_p(group, I_)] if lib is not old else []  # noqa: E731

    def starts(lib):
        w, z, ok = np.empty((N, n)), np.empty((N, n, n), complex), np.empty(N)
        fn(lib, "qep_block_starts_batch")(ctypes.c_long(N), ctypes.c_long(len(blocks)), _p(sizes, L_), _p(idx, L_),
                                          *g(lib), _p(rhs.view(float)), _p(M), _p(D), _p(K), _p(w), _p(z.view(float)), _p(ok))
        return w, z, ok

    w0, z0, _ = starts(old)
    w0 = np.where(np.isfinite(w0), w0, 1.0)

    def refine(lib):
        w, z, est, ok = w0.copy(), z0.copy(), np.empty((N, n)), np.empty((N, n))
        fn(lib, "qep_refine_batch")(ctypes.c_long(N), ctypes.c_long(n), ctypes.c_long(3), ctypes.c_double(1e-10),
                                    *g(lib), _p(M), _p(D), _p(K), _p(w), _p(z.view(float)), _p(est), _p(ok))
        return w, z, est, ok

    lam = np.ascontiguousarray(1j * refine(old)[0])
    herm = np.zeros(N)

    def null_vectors(lib):
        x, y, s = np.empty((N, n, n), complex), np.empty((N, n, n), complex), np.empty((N, n))
        fn(lib, "sens_null_vectors_batch")(ctypes.c_long(N), ctypes.c_long(n), _p(M), _p(D), _p(K), _p(lam.view(float)),
                                           _p(herm), _p(rhs.view(float)), _p(x.view(float)), _p(y.view(float)), _p(s))
        return x, y, s

    x, y, _ = null_vectors(old)
    rng = np.random.default_rng(3)
    nnz, ncols = 3 * n, 5
    rows = np.sort(rng.choice(3 * n * n, nnz, replace=False)).astype(np.int64)
    cols = rng.integers(0, ncols, nnz).astype(np.int64)
    vals = rng.standard_normal((N, nnz))

    def contract(lib):
        h, den = np.empty((N, n, ncols), complex), np.empty((N, n), complex)
        fn(lib, "sens_contract_batch")(ctypes.c_long(N), ctypes.c_long(n), ctypes.c_long(nnz), ctypes.c_long(ncols),
                                       _p(rows, L_), _p(cols, L_), _p(vals), _p(M), _p(D), _p(lam.view(float)),
                                       _p(x.view(float)), _p(y.view(float)), _p(h.view(float)), _p(den.view(float)))
        return h, den

    c = rng.standard_normal((N, 9))  # degree 8: within polyroots.c's cap of 16

    def poly_roots(lib):
        lib = roots_new if lib is new else lib
        d = c.shape[1] - 1
        z, rad, sens, ok = np.empty((N, d), complex), np.empty((N, d)), np.empty((N, d)), np.empty(N)
        fn(lib, "poly_roots_batch")(ctypes.c_long(N), ctypes.c_long(d), _p(c), _p(z.view(float)), _p(rad), _p(sens), _p(ok))
        return z, rad, sens, ok

    out = {"sets": N, "n": n, "real_form": group is not None}
    for kernel in (starts, refine, null_vectors, contract, poly_roots):
        same = all(a.tobytes() == b.tobytes() for a, b in zip(kernel(old), kernel(new)))
        to, tn = [], []
        for _ in range(repeats):
            for lib, ts in ((old, to), (new, tn)):
                t = time.perf_counter()
                kernel(lib)
                ts.append(time.perf_counter() - t)
        r = sorted(b / a for a, b in zip(to, tn))
        out[kernel.__name__] = {"same_bytes": same, "old_us_per_set": 1e6 * min(to) / N, "new_us_per_set": 1e6 * min(tn) / N,
                                "ratio_median": statistics.median(r), "ratio_quartiles": (r[len(r) // 4], r[3 * len(r) // 4])}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="c4f2f5a")
    ap.add_argument("--sets", type=int, default=4000)
    ap.add_argument("--repeats", type=int, default=21)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("torsion_gyrocompass", "gyrohorizoncompass"):
            res = compare(name, args.rev, args.sets, args.repeats, Path(tmp))
            print(f"{name}: {res['sets']} sets, n = {res['n']}, real form: {res['real_form']}")
            for k, v in res.items():
                if isinstance(v, dict):
                    print(f"  {k:14s} same bytes: {v['same_bytes']}  old {v['old_us_per_set']:.3f} us/set, "
                          f"new {v['new_us_per_set']:.3f} us/set, new/old {v['ratio_median']:.3f} "
                          f"({v['ratio_quartiles'][0]:.3f}-{v['ratio_quartiles'][1]:.3f})")


if __name__ == "__main__":
    main()
