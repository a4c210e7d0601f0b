"""The generated C of a model and the model-free kernels, compiled once per machine and
called over a batch.

`make derive` emits `<model>.c` with a `<name>_batch(n, inputs..., outputs...)` entry point
per function. Here gcc turns it into a shared library, cached under $GYRO_CACHE (default
~/.cache/gyro-dynamics) by the hash of the source and the flags, and ctypes calls it on
contiguous NumPy arrays: one call per batch, no Python per set. ISO C99 keeps
-ffp-contract=off, so the results are those of the source's operations as written.

The numerics that know no model (the quadratic eigenproblem's refinement and starts, the
roots' sensitivities, polynomial roots: gyro/csrc/, their entry points in kernels.h) are
C sources of this package, compiled the same way into a library of their own, once per
operator dimension (-DQEP_N=n: a constant to the compiler, as when they were rendered into
each model's C) and loaded beside the model's library: they take the arrays its functions
give, and a model's structure as data (its operator's real form, from metadata.json). A fix
to a kernel rebuilds one library per dimension, no model's.
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import sys
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path

import numpy as np

from gyro.models import load

FLAGS = ("-O3", "-march=native", "-std=c99", "-fno-math-errno", "-fPIC", "-shared")


class CompilerUnavailable(RuntimeError):
    pass


_disabled = 0
_FAILED: dict[str, CompilerUnavailable] = {}


@contextmanager
def disabled():
    """Within this block every entry point reports CompilerUnavailable, so the runtime takes
    its NumPy paths (as on a machine without gcc): for benchmarks and comparisons."""
    global _disabled
    _disabled += 1
    try:
        yield
    finally:
        _disabled -= 1


def _available() -> None:
    if _disabled:
        raise CompilerUnavailable("compiled code disabled (gyro.cbackend.disabled)")


@lru_cache(maxsize=None)
def _cached(cls, directory, *args):
    return cls(*args)


def _built(cls, model_name, *args):
    """One instance per (class, the model's folder, arguments), built on first use, unless
    disabled(). The folder is part of the key: two models of one name emitted into two
    folders (an edited model file, say) never share compiled code."""
    _available()
    return _cached(cls, str(load(model_name).directory), model_name, *args)


def cache_dir() -> Path:
    from gyro.catalog import cache_dir as shared

    return shared()


def library(model_name: str) -> ctypes.CDLL:
    """The compiled library of a model's generated C (built on first use, once per folder)."""
    return _library(str(load(model_name).directory), model_name)


def _writable_cache() -> Path:
    """The cache folder, or, where it cannot be written (read-only, not creatable), a
    private temporary folder for this process, said once on stderr."""
    global _FALLBACK
    d = cache_dir()
    try:
        d.mkdir(parents=True, exist_ok=True)
        if os.access(d, os.W_OK | os.X_OK):
            return d
    except OSError:
        pass
    if _FALLBACK is None:
        import tempfile

        _FALLBACK = Path(tempfile.mkdtemp(prefix="gyro-cache-"))
        print(f"gyro: the cache {d} cannot be written; compiling into {_FALLBACK} for this run",
              file=sys.stderr)
    return _FALLBACK


_FALLBACK: Path | None = None


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _intact(so: Path) -> bool:
    """A cached library is loaded only when its bytes are those it was written with (its
    .sha256 beside it): a truncated or overwritten file is rebuilt, never loaded."""
    seal = so.with_suffix(".sha256")
    try:
        return so.is_file() and seal.read_text().strip() == _digest(so)
    except OSError:
        return False


@lru_cache(maxsize=None)
def _library(directory: str, model_name: str) -> ctypes.CDLL:
    src = Path(directory) / f"{model_name}.c"
    return _shared(model_name, (src,), (src.with_suffix(".h"),), notice=f"the generated C of {model_name}")


CSRC = Path(__file__).resolve().parent / "csrc"
# the kernels' libraries: their sources in gyro/csrc/ (every header there is part of each)
KERNELS = {"qep": ("qep.c", "qep_starts.c", "sensitivity.c"), "polyroots": ("polyroots.c",),
           "krawczyk": ("krawczyk.c",), "intervals": ("intervals.c",)}


def kernel_library(kind: str, n: int | None = None) -> ctypes.CDLL:
    """The compiled kernels of one kind (KERNELS), for operators of dimension n where they
    need one: built on first use, once per (kind, n, sources, compiler, flags, machine),
    shared by every model of that dimension."""
    _available()
    return _kernel_library(str(CSRC), kind, n)


@lru_cache(maxsize=None)
def _kernel_library(folder: str, kind: str, n: int | None) -> ctypes.CDLL:
    folder = Path(folder)
    sources = tuple(folder / f for f in KERNELS[kind])
    defines = () if n is None else (f"-DQEP_N={int(n)}",)
    stem = f"kernel-{kind}" + ("" if n is None else f"-n{int(n)}")
    what = " ".join(KERNELS[kind]) + "".join(f" {d}" for d in defines)
    return _shared(stem, sources, tuple(sorted(folder.glob("*.h"))), defines,
                   notice=f"the generated C's kernels ({what})")


def _key(cc: str, sources, headers, defines) -> str:
    """The cache key of a library: its files (names and bytes), the compiler, the flags,
    the macros and the machine."""
    h = hashlib.sha256()
    for f in (*sources, *headers):
        h.update(f.name.encode() + b"\0" + f.read_bytes() + b"\0")
    h.update(" ".join((cc,) + FLAGS + tuple(defines) + (os.uname().machine,)).encode())
    return h.hexdigest()[:16]


def _shared(stem: str, sources, headers, defines=(), notice: str = "") -> ctypes.CDLL:
    """The shared library of sources (with headers, macros), compiled once per machine into
    the cache as <stem>-<key>.so, saying `notice` on stderr when it compiles (every notice
    starts "the generated C": tests/conftest.py's NOTICES); CompilerUnavailable without a
    compiler or where it fails."""
    cc = os.environ.get("CC", "gcc")
    if shutil.which(cc) is None:
        raise CompilerUnavailable(f"no C compiler {cc!r} on PATH")
    key = _key(cc, sources, headers, defines)
    if key in _FAILED:
        raise _FAILED[key]
    name = f"{stem}-{key}.so"
    out = cache_dir() / name
    if not _intact(out):  # missing, truncated or overwritten: built again (where writable)
        out = _writable_cache() / name
        if not _intact(out):
            _build(cc, sources, out, key, defines, notice)
    try:
        return ctypes.CDLL(str(out))
    except OSError as exc:  # sealed but unloadable: remembered, and the NumPy paths answer
        _FAILED[key] = CompilerUnavailable(f"cannot load {out}: {exc}")
        raise _FAILED[key] from None


def _build(cc: str, sources, out: Path, key: str, defines=(), notice: str = "") -> None:
    """Compile sources into out (atomically, with its seal), saying so on stderr: the first
    run on a machine takes some seconds here. Two processes building the same library at
    once each compile into a folder of their own and rename into place: the last rename
    wins, and either file is whole."""
    import subprocess
    import tempfile

    what = " ".join(s.name for s in sources) + "".join(f" {d}" for d in defines)
    print(f"gyro: compiling {notice} once for this machine (into {out.parent}) ...", file=sys.stderr, flush=True)
    with tempfile.TemporaryDirectory(dir=out.parent) as tmp:
        tmp_so = Path(tmp) / out.name
        proc = subprocess.run([cc, *FLAGS, *defines, "-I", str(sources[0].parent), *map(str, sources),
                               "-o", str(tmp_so), "-lm"], capture_output=True, text=True)
        if proc.returncode != 0:  # remembered: one failed build per process, not one per call
            _FAILED[key] = CompilerUnavailable(f"{cc} failed on {what}: {proc.stderr.strip()[:500]}")
            # said once, on the line after the notice: the NumPy paths answer, slower, and a
            # broken source is not mistaken for a machine without a compiler
            first = next((ln for ln in proc.stderr.splitlines() if "error" in ln), proc.stderr.strip()[:200])
            print(f"gyro: compiling {notice} failed ({first.strip()}); the NumPy paths answer instead",
                  file=sys.stderr, flush=True)
            raise _FAILED[key]
        seal = Path(tmp) / "seal"
        seal.write_text(_digest(tmp_so) + "\n")
        os.replace(tmp_so, out)  # atomic: concurrent builders never see half a file
        os.replace(seal, out.with_suffix(".sha256"))


class BatchFunction:
    """A generated function over a batch: f(*inputs) with inputs of shape (n, len_i)
    (broadcast from one set), returning outputs of shape (n,) + output shape, or (n, nonzeros)
    for an output emitted as its structural nonzeros."""

    def __init__(self, model_name: str, fname: str):
        meta = load(model_name).meta["functions"][fname]
        self.name = fname
        # the C signature's order: metadata lists inputs and outputs in call order
        self.in_lens = [len(i["symbols"]) for i in meta["inputs"]]
        # an output emitted as its structural nonzeros is a flat vector of them (the NumPy
        # backend's shape too), its positions in metadata.json
        self.out_shapes = [(len(o["nonzeros"]["rows"]), 1) if "nonzeros" in o else tuple(o["shape"])
                           for o in meta["outputs"]]
        # the NumPy backend's shapes: a column is a vector unless the model says matrix
        self.out_vector = ["nonzeros" in o or o.get("vector", o["shape"][1] == 1) for o in meta["outputs"]]
        self._fn = _entry(model_name, f"{model_name}_{fname}_batch")

    def __call__(self, *inputs):
        if len(inputs) != len(self.in_lens):
            raise ValueError(f"{self.name}: {len(self.in_lens)} inputs, got {len(inputs)}")
        sets = [np.asarray(x, dtype=float).reshape(-1, k).shape[0] for x, k in zip(inputs, self.in_lens) if k]
        n = max(sets, default=1)
        args = [np.ascontiguousarray(np.broadcast_to(np.asarray(x, dtype=float).reshape(-1, k), (n, k)))
                if k else np.zeros((n, 0)) for x, k in zip(inputs, self.in_lens)]
        outs = [np.empty((n, r * c)) for r, c in self.out_shapes]
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(n), *[a.ctypes.data_as(ptr) for a in args + outs])
        return [o.reshape((n, r) if vec else (n, r, c))
                for o, (r, c), vec in zip(outs, self.out_shapes, self.out_vector)]


def _entry(model_name: str, symbol: str):
    """A C entry point of the model's library; CompilerUnavailable when its C has none
    (a model without an operator, say), so that callers take their NumPy paths."""
    try:
        fn = getattr(library(model_name), symbol)
    except AttributeError:
        raise CompilerUnavailable(f"{model_name}: the generated C has no {symbol}") from None
    fn.restype = None
    return fn


def _operator_dim(model_name: str) -> int:
    outs = load(model_name).meta["functions"]["operator"]["outputs"]
    return next(o["shape"][0] for o in outs if o["name"] == "M")


def _dimension(model_name: str) -> int:
    """The dimension of a model's operator, 0 where it has none."""
    return _operator_dim(model_name) if "operator" in load(model_name).meta["functions"] else 0


def _qep_kernel(model_name: str, symbol: str):
    """(entry point, n, group) of the quadratic eigenproblem's kernels for a model with an
    operator (M, D, K) of dimension n >= 2: the library of its dimension, and its operator's
    real form (metadata.json "operator_real_form": 0 or 1 per coordinate, as a C int array,
    or None where it has none). CompilerUnavailable for a model without one, so that
    callers take their NumPy paths."""
    meta = load(model_name).meta
    n = _dimension(model_name)
    if n < 2:
        raise CompilerUnavailable(f"{model_name}: no operator of dimension 2 or more for the kernels")
    form = meta.get("operator_real_form")
    group = None if form is None else np.ascontiguousarray(form, dtype=np.intc)
    _check(group is None or (group.shape == (n,) and bool(np.all((group == 0) | (group == 1)))),
           f"operator_real_form must be {n} groups, each 0 or 1")
    fn = getattr(kernel_library("qep", n), symbol)
    fn.restype = None
    return fn, n, group


def kernel_libraries(model_name: str) -> list:
    """The kernels' libraries a model takes, built on first use: those of its operator's
    dimension where it has one of 2 or more, and the polynomial roots (for a warm cache:
    tests/conftest.py builds them before the tests, as it builds the models' C)."""
    n = _dimension(model_name)
    return ([kernel_library("qep", n)] if n >= 2 else []) + [kernel_library("polyroots")]


def _group_ptr(group):
    return None if group is None else group.ctypes.data_as(ctypes.POINTER(ctypes.c_int))


def _check(cond: bool, what: str) -> None:
    """Shapes are checked before C sees the arrays: a mismatch would read out of bounds."""
    if not cond:
        raise ValueError(f"compiled kernel: {what}")


def batch_function(model_name: str, fname: str) -> BatchFunction:
    return _built(BatchFunction, model_name, fname)


class QepRefine:
    """The root refinement of the operator's quadratic eigenproblem (gyro/csrc/qep.c;
    gyro.ladder._rayleigh_step root by root, in C)."""

    def __init__(self, model_name: str):
        self._fn, self.n, self.group = _qep_kernel(model_name, "gyro_qep_refine_batch")

    def __call__(self, M, D, K, w, z, iters: int, tol: float, overwrite: bool = False):
        """M, D, K (sets, n, n); w (sets, r) and z (sets, r, n) complex: the starts. Returns
        new arrays (w, z, estimate, ok); with overwrite, w and z themselves refined in place
        where they are already writeable C-contiguous arrays of their dtype and shape (the
        caller's starts are then gone), copies otherwise."""
        M, D, K = (np.ascontiguousarray(X, dtype=float) for X in (M, D, K))
        w = np.require(w, float, "CW") if overwrite else np.array(w, dtype=float, order="C")
        _check(all(X.shape == (w.shape[0], self.n, self.n) for X in (M, D, K)) and w.ndim == 2,
               f"M, D, K must be (sets, {self.n}, {self.n}) and w (sets, roots)")
        shape = w.shape + (self.n,)
        if not (overwrite and isinstance(z, np.ndarray) and z.shape == shape and z.dtype == complex
                and z.flags.c_contiguous and z.flags.writeable):
            z = np.array(np.broadcast_to(z, shape), dtype=complex, order="C")
        est, ok = np.empty(w.shape), np.empty(w.shape)
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(w.shape[0]), ctypes.c_long(w.shape[1]), ctypes.c_long(iters),
                 ctypes.c_double(tol), _group_ptr(self.group), *[a.ctypes.data_as(ptr) for a in (M, D, K, w, z, est, ok)])
        return w, z, est, ok.astype(bool)


def qep_refine(model_name: str) -> QepRefine:
    """The compiled refinement of a model (CompilerUnavailable when its C has none)."""
    return _built(QepRefine, model_name)


class QepMoves:
    """The operator's own rounding carried into each root (gyro/csrc/qep.c
    gyro_qep_moves_batch; gyro.qep.hermitian_moves in C)."""

    def __init__(self, model_name: str):
        self._fn, self.n, _ = _qep_kernel(model_name, "gyro_qep_moves_batch")

    def __call__(self, moves, M, D, w, z):
        dM, dD, dK = moves
        M, D, dM, dD, dK = (np.ascontiguousarray(X, dtype=float) for X in (M, D, dM, dD, dK))
        w = np.ascontiguousarray(w, dtype=float)
        z = np.ascontiguousarray(z, dtype=complex)
        _check(all(X.shape == (w.shape[0], self.n, self.n) for X in (M, D, dM, dD, dK)) and w.ndim == 2
               and z.shape == w.shape + (self.n,), f"M, D, dM, dD, dK must be (sets, {self.n}, {self.n}), "
               "w (sets, roots) and z (sets, roots, n)")
        out = np.empty(w.shape)
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(w.shape[0]), ctypes.c_long(w.shape[1]),
                 *[a.ctypes.data_as(ptr) for a in (M, D, dM, dD, dK, w, z, out)])
        return out


def qep_moves(model_name: str) -> QepMoves:
    """The compiled contraction of the operator's rounding (CompilerUnavailable without it)."""
    return _built(QepMoves, model_name)


class QepHermitian:
    """The Hermitian form of a diagonal block of the operator (gyro/csrc/qep.c;
    gyro.qep.hermitian_block's matrix T, in C)."""

    def __init__(self, model_name: str):
        self._fn, self.n, _ = _qep_kernel(model_name, "gyro_qep_hermitian_batch")

    def __call__(self, M, D, K, idx):
        """M, D, K (sets, n, n), idx the block's indices. Returns (T, ok): T (sets, 2nb, 2nb)
        complex Hermitian, ok (sets,) where the block's K and M are positive definite."""
        M, D, K = (np.ascontiguousarray(X, dtype=float) for X in (M, D, K))
        idx = np.ascontiguousarray(idx, dtype=np.dtype(ctypes.c_long))
        N, m = M.shape[0], 2 * len(idx)
        _check(all(X.shape == (N, self.n, self.n) for X in (M, D, K)), f"M, D, K must be (sets, {self.n}, {self.n})")
        _check(idx.ndim == 1 and 0 < len(idx) <= self.n and len(set(idx.tolist())) == len(idx)
               and bool(np.all((idx >= 0) & (idx < self.n))), f"block indices must be distinct, in 0..{self.n - 1}")
        T, ok = np.empty((N, m, m), complex), np.empty(N)
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(N), ctypes.c_long(len(idx)), idx.ctypes.data_as(ctypes.POINTER(ctypes.c_long)),
                 *[a.ctypes.data_as(ptr) for a in (M, D, K, T, ok)])
        return T, ok.astype(bool)


def qep_hermitian(model_name: str) -> QepHermitian:
    """The compiled Hermitian block form of a model (CompilerUnavailable when its C has none)."""
    return _built(QepHermitian, model_name)


class QepBlockStarts:
    """The starts of the refinement (gyro/csrc/qep_starts.c): per diagonal block, the
    Hermitian form's eigenvalues without LAPACK and a vector per root by inverse iteration
    on the block (gyro.qep.block_starts' NumPy path, in C)."""

    def __init__(self, model_name: str):
        self._fn, self.n, self.group = _qep_kernel(model_name, "gyro_qep_block_starts_batch")

    def __call__(self, M, D, K, blocks, rhs):
        """M, D, K (sets, n, n); blocks a partition of 0..n-1 into index arrays; rhs (n,)
        complex. Returns (w, z, ok): w (sets, n) per block descending, z (sets, n, n)
        complex, ok (sets,) where every block is positive definite with a margin."""
        M, D, K = (np.ascontiguousarray(X, dtype=float) for X in (M, D, K))
        N, n = M.shape[0], self.n
        _check(all(X.shape == (N, n, n) for X in (M, D, K)), f"M, D, K must be (sets, {n}, {n})")
        idx = np.ascontiguousarray(np.concatenate(blocks), dtype=np.dtype(ctypes.c_long))
        _check(sorted(idx.tolist()) == list(range(n)), f"blocks must partition 0..{n - 1}")
        sizes = np.array([len(b) for b in blocks], dtype=np.dtype(ctypes.c_long))
        rhs = np.ascontiguousarray(rhs, dtype=complex)
        _check(rhs.shape == (n,), f"rhs must be ({n},)")
        w, z, ok = np.empty((N, n)), np.empty((N, n, n), complex), np.empty(N)
        ptr, lptr = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_long)
        self._fn(ctypes.c_long(N), ctypes.c_long(len(blocks)), sizes.ctypes.data_as(lptr),
                 idx.ctypes.data_as(lptr), _group_ptr(self.group),
                 *[a.ctypes.data_as(ptr) for a in (rhs, M, D, K, w, z, ok)])
        return w, z, ok.astype(bool)


def qep_block_starts(model_name: str) -> QepBlockStarts:
    """The compiled starts of a model's refinement (CompilerUnavailable when its C has none)."""
    return _built(QepBlockStarts, model_name)


class EquilibriumNewton:
    """The generated Newton iteration of the relative equilibria (templates/equilibrium.c.j2;
    gyro.equilibrium._newton_numpy set by set, in C)."""

    CONVERGED, HANDED_BACK = 1, 2

    def __init__(self, model_name: str):
        self._fn = _entry(model_name, f"{model_name}_equilibrium_newton_batch")
        meta = load(model_name).meta
        self.n_params = len(meta["functions"]["equilibrium_residual"]["inputs"][0]["symbols"])
        self.n = len(meta["equilibrium_coordinates"])

    def __call__(self, P, qe, tol: float, max_iter: int, max_angle_step: float):
        """P (sets, parameters); qe (sets, equilibrium coordinates) the starts. Returns new
        arrays (qe, status): status per set CONVERGED (qe the last iterate) or HANDED_BACK
        (qe not to be used: an entry of r or K not below 1e150, a zero pivot, a step or an
        iterate not finite, no convergence in max_iter steps; the NumPy iteration answers
        that set)."""
        P = np.ascontiguousarray(P, dtype=float)
        qe = np.array(qe, dtype=float, order="C")  # a copy: the C iterates in place
        _check(P.ndim == 2 and P.shape[1] == self.n_params and qe.shape == (P.shape[0], self.n),
               f"params must be (sets, {self.n_params}) and qe (sets, {self.n})")
        status = np.empty(P.shape[0], dtype=np.dtype(ctypes.c_long))
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(P.shape[0]), ctypes.c_long(max_iter), ctypes.c_double(tol),
                 ctypes.c_double(max_angle_step), P.ctypes.data_as(ptr), qe.ctypes.data_as(ptr),
                 status.ctypes.data_as(ctypes.POINTER(ctypes.c_long)))
        return qe, status


def equilibrium_newton(model_name: str) -> EquilibriumNewton:
    """The compiled equilibrium Newton iteration of a model (CompilerUnavailable when its C has none)."""
    return _built(EquilibriumNewton, model_name)


_HUGE = 2 << 20  # bytes of a transparent huge page (x86-64, arm64 with 4 kB pages)
_MADV_HUGEPAGE = 14


@lru_cache(maxsize=None)
def _madvise():
    """libc's madvise on Linux, else None (the advice is then not given)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        fn = ctypes.CDLL(None).madvise
    except (OSError, AttributeError):
        return None
    fn.argtypes, fn.restype = (ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int), ctypes.c_int
    return fn


def empty_huge(shape) -> np.ndarray:
    """np.empty(shape) of floats, where it is 2 MB or more placed on a 2 MB boundary with huge
    pages advised (Linux: madvise MADV_HUGEPAGE; ignored where the kernel has them off): fresh
    memory then costs one page fault per 2 MB instead of one per 4 kB. A kernel's outputs are
    fresh pages whenever the heap was trimmed since the last call (in bench.speed the
    formulas' two (sets, 10) outputs took 783 faults per 20,000 sets, 80 ns per set, where
    first touching 3.2 MB costs 57 ns per set in 4 kB pages and 8-12 in huge pages). The
    array is a view of a buffer up to 2 MB longer, freed with it."""
    n = int(np.prod(shape)) * 8
    advise = _madvise()
    if n < _HUGE or advise is None:
        return np.empty(shape)
    raw = np.empty(n + _HUGE, np.uint8)
    off = -raw.ctypes.data % _HUGE
    advise(raw.ctypes.data + off, (raw.nbytes - off) // 4096 * 4096, _MADV_HUGEPAGE)  # advice only: the result is not checked
    return raw[off:off + n].view(float).reshape(shape)


class ModeFormulasSelected:
    """The generated selection and sort of the mode formulas (templates/mode_select.c.j2;
    gyro.ladder.formulas in one pass over the batch)."""

    def __init__(self, model_name: str):
        self._fn = _entry(model_name, f"{model_name}_mode_formulas_selected_batch")
        self.modes = len(load(model_name).meta["mode_formulas"])
        self.n_params = len(load(model_name).param_names)

    def __call__(self, P):
        """P (sets, parameters). Returns (frequencies, estimates), each (sets, modes)."""
        P = np.ascontiguousarray(P, dtype=float)
        _check(P.ndim == 2 and P.shape[1] == self.n_params, f"params must be (sets, {self.n_params})")
        f, e = empty_huge((2, P.shape[0], self.modes))  # one buffer: fresh pages cost per 2 MB
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(P.shape[0]), *[a.ctypes.data_as(ptr) for a in (P, f, e)])
        return f, e


def mode_formulas_selected(model_name: str) -> ModeFormulasSelected:
    """The compiled selection of a model's mode formulas (CompilerUnavailable when it has none)."""
    return _built(ModeFormulasSelected, model_name)


class PolyRoots:
    """The polynomial roots with inclusion radii (gyro/csrc/polyroots.c; gyro.roots in C):
    it knows no model, one library for all."""

    def __init__(self, model_name: str):
        self._fn = kernel_library("polyroots").gyro_poly_roots_batch
        self._fn.restype = None

    def __call__(self, c):
        """c (sets, degree + 1), lowest first. Returns (z complex, relative radius, relative
        sensitivity to the coefficients' rounding, ok)."""
        c = np.ascontiguousarray(c, dtype=float)
        _check(c.ndim == 2 and c.shape[1] >= 2, "coefficients must be (sets, degree + 1)")
        n, d = c.shape[0], c.shape[1] - 1
        z, rad, sens, ok = np.empty((n, d), complex), np.empty((n, d)), np.empty((n, d)), np.empty(n)
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(n), ctypes.c_long(d), *[a.ctypes.data_as(ptr) for a in (c, z, rad, sens, ok)])
        return z, rad, sens, ok.astype(bool)


def poly_roots(model_name: str) -> PolyRoots:
    """The compiled polynomial roots (CompilerUnavailable without a compiler); the model
    only keys the instance, as every kernel's."""
    return _built(PolyRoots, model_name)


class SensitivityNullVectors:
    """The null vectors of the roots (gyro/csrc/sensitivity.c;
    gyro.analyses.sensitivity._null_vectors with one LU per root, in C)."""

    def __init__(self, model_name: str):
        self._fn, self.n, _ = _qep_kernel(model_name, "gyro_sens_null_vectors_batch")

    def __call__(self, M, D, K, lam, hermitian, rhs):
        """M, D, K (sets, n, n); lam (sets, r) complex roots; hermitian (sets,); rhs (n,)
        complex. Returns (x, y, singular): x, y (sets, r, n) complex, singular (sets, r)."""
        M, D, K = (np.ascontiguousarray(X, dtype=float) for X in (M, D, K))
        N, n = M.shape[0], self.n
        lam = np.ascontiguousarray(lam, dtype=complex)
        _check(all(X.shape == (N, n, n) for X in (M, D, K)) and lam.ndim == 2 and lam.shape[0] == N,
               f"M, D, K must be (sets, {n}, {n}) and lam (sets, roots)")
        herm = np.ascontiguousarray(np.broadcast_to(hermitian, (N,)), dtype=float)
        rhs = np.ascontiguousarray(rhs, dtype=complex)
        _check(rhs.shape == (n,), f"rhs must be ({n},)")
        x, y = np.empty(lam.shape + (n,), complex), np.empty(lam.shape + (n,), complex)
        sing = np.empty(lam.shape)
        ptr = ctypes.POINTER(ctypes.c_double)
        self._fn(ctypes.c_long(N), ctypes.c_long(lam.shape[1]),
                 *[a.ctypes.data_as(ptr) for a in (M, D, K, lam, herm, rhs, x, y, sing)])
        return x, y, sing.astype(bool)


def sens_null_vectors(model_name: str) -> SensitivityNullVectors:
    """The compiled null vectors of a model (CompilerUnavailable when its C has none)."""
    return _built(SensitivityNullVectors, model_name)


class SensitivityContract:
    """The contraction of the roots' sensitivities over the structural nonzeros of the
    operator's Jacobian (gyro/csrc/sensitivity.c)."""

    def __init__(self, model_name: str):
        self._fn, self.n, _ = _qep_kernel(model_name, "gyro_sens_contract_batch")

    def __call__(self, rows, cols, ncols, vals, M, D, lam, x, y):
        """rows, cols (nnz,): positions in the layout (3 n^2, ncols); vals (sets, nnz); M, D
        (sets, n, n); lam (sets, r) complex; x, y (sets, r, n) complex. Returns (h, den): h
        (sets, r, ncols) complex, den (sets, r) complex."""
        M, D = (np.ascontiguousarray(X, dtype=float) for X in (M, D))
        N, n = M.shape[0], self.n
        lam = np.ascontiguousarray(lam, dtype=complex)
        x, y = (np.ascontiguousarray(v, dtype=complex) for v in (x, y))
        vals = np.ascontiguousarray(vals, dtype=float)
        rows = np.ascontiguousarray(rows, dtype=np.dtype(ctypes.c_long))
        cols = np.ascontiguousarray(cols, dtype=np.dtype(ctypes.c_long))
        nnz = rows.shape[0]
        _check(all(X.shape == (N, n, n) for X in (M, D)) and lam.ndim == 2 and lam.shape[0] == N
               and x.shape == y.shape == lam.shape + (n,), f"M, D (sets, {n}, {n}), lam (sets, r), x, y (sets, r, {n})")
        _check(ncols >= 1 and rows.shape == cols.shape == (nnz,) and vals.shape == (N, nnz)
               and bool(np.all((rows >= 0) & (rows < 3 * n * n))) and bool(np.all((cols >= 0) & (cols < ncols))),
               f"rows in 0..{3 * n * n - 1}, cols in 0..{ncols - 1}, vals (sets, nnz)")
        h, den = np.empty(lam.shape + (ncols,), complex), np.empty(lam.shape, complex)
        ptr, lptr = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_long)
        self._fn(ctypes.c_long(N), ctypes.c_long(lam.shape[1]), ctypes.c_long(nnz), ctypes.c_long(ncols),
                 rows.ctypes.data_as(lptr), cols.ctypes.data_as(lptr),
                 *[a.ctypes.data_as(ptr) for a in (vals, M, D, lam, x, y, h, den)])
        return h, den


def sens_contract(model_name: str) -> SensitivityContract:
    """The compiled contraction of a model's sensitivities (CompilerUnavailable when its C has none)."""
    return _built(SensitivityContract, model_name)
