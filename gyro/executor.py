"""The one sweep executor: N parameter sets cut into chunks of a fixed size, each chunk a
pure function of its inputs, run in this process (serially, the default) or on Dask
(`dask.distributed`: a local cluster of processes, or any running scheduler).

A chunk is `fn(start, stop, *args) -> {name: array}` with every array's first axis
`stop - start`; `fn` is a module-level function (Dask ships it by reference) and `args`
are small or shared (a large array is scattered to the workers once). The chunk bounds
depend on N and the chunk size only, never on the executor, so that every executor gives
the same bits: the same function of the same inputs on the same machine code.

Results are written as they come, chunk by chunk, into one array per name: in memory, or,
given a folder, into `.npy` files opened as memory maps (`numpy.load(path, mmap_mode='r')`
reads them back), so that a result larger than memory is never held whole. On Dask at most
`inflight` chunks are under way at once (bounded memory on the client too); a worker that
dies costs its chunk a retry on another worker (the scheduler's allowed failures), not the
run. Before the first chunk every worker machine loads the compiled kernels once
(`warm(worker)`: one worker per host first, which compiles; the others then load the
sealed library), never once per task."""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

SERIAL = None  # the in-process executor
BUDGET: float | None = None  # seconds a run in this process may take (the command line sets it: budget())
STARTED = 0.0  # time.perf_counter() when the budget was set: a command's work predicted as it goes
# counts what it spent before (gyro.ode.watching)


class budget:
    """`with budget(seconds):` runs in this process are held to `seconds`: the time of the
    chunks done so far, carried to all of them, is checked after each chunk, and a run that
    would go over stops there (after the first chunk where the request is large: one line
    naming the cost, ParameterError). A run on Dask is not held to it (the cluster is the
    user's)."""

    def __init__(self, seconds: float | None):
        self.seconds = seconds

    def __enter__(self):
        global BUDGET, STARTED
        self.saved, BUDGET = (BUDGET, STARTED), self.seconds
        STARTED = time.perf_counter()
        return self

    def __exit__(self, *exc):
        global BUDGET, STARTED
        BUDGET, STARTED = self.saved
        return False


def over_budget(n: int, done: int, seconds: float, limit: float) -> None:
    """ParameterError when n sets at the pace of `done` in `seconds` would take over `limit`."""
    from gyro.errors import ParameterError

    each = seconds / max(done, 1)
    if n * each > limit:
        raise ParameterError(f"{n} parameter sets would take about {n * each:.0f} s in this process "
                             f"({each * 1e3:.2g} ms a set, measured on {done}), over the command line's budget "
                             f"of {limit:.0f} s: ask for fewer, or run them on --scheduler local or a cluster")


def bounds(n: int, chunk: int) -> list[tuple[int, int]]:
    """The chunks of range(n): the same for every executor."""
    if chunk < 1:
        raise ValueError(f"chunk: need >= 1, got {chunk}")
    return [(s, min(s + chunk, n)) for s in range(0, n, chunk)]


class Sink:
    """One array per output name, allocated at the first chunk (its shapes and dtypes),
    filled chunk by chunk: in memory, or as .npy memory maps in `folder`."""

    def __init__(self, n: int, folder: Path | None):
        self.n, self.folder, self.arrays = n, folder, {}
        if folder is not None:
            Path(folder).mkdir(parents=True, exist_ok=True)

    def put(self, start: int, part: dict) -> None:
        for name, a in part.items():
            a = np.asarray(a)
            if name not in self.arrays:
                shape = (self.n,) + a.shape[1:]
                if self.folder is None:
                    self.arrays[name] = np.empty(shape, a.dtype)
                else:
                    self.arrays[name] = np.lib.format.open_memmap(Path(self.folder) / f"{name}.npy", "w+",
                                                                  a.dtype, shape)
            self.arrays[name][start:start + a.shape[0]] = a

    def close(self) -> dict:
        for a in self.arrays.values():
            if isinstance(a, np.memmap):
                a.flush()
        return self.arrays


def client(scheduler):
    """A dask.distributed Client: `local` starts a local cluster of one single-threaded
    worker process per core; anything else is a running scheduler's address; a Client is
    taken as it is."""
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        return scheduler
    if scheduler == "local":
        import logging

        # the workers' own log lines (ports, memory, a worker restarted) are not the command's
        # output: its one line says what failed (silence_logs is the level shown, WARN by default)
        cluster = LocalCluster(n_workers=max(1, os.cpu_count() or 1), threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.CRITICAL)
        return Client(cluster)
    try:
        return Client(scheduler, timeout="10s")
    except (OSError, ValueError, TypeError) as exc:  # TimeoutError is an OSError
        from gyro.errors import ParameterError

        raise ParameterError(f"--scheduler {scheduler!r}: no Dask scheduler answers there ({exc})") from None


def _warm_on(c, warm, workers, *args) -> None:
    if warm is None or not workers:
        return
    c.run(warm, *args, workers=list(workers))


def warm_workers(c, warm, *args) -> None:
    """warm(*args) on every worker, one per host first: the compiled kernels are built once
    per machine (the disk cache of gyro.cbackend), then loaded by the others."""
    info = c.scheduler_info(n_workers=-1)["workers"]
    by_host: dict[str, list[str]] = {}
    for addr, w in info.items():
        by_host.setdefault(w.get("host", addr), []).append(addr)
    _warm_on(c, warm, [ws[0] for ws in by_host.values()], *args)
    _warm_on(c, warm, [w for ws in by_host.values() for w in ws[1:]], *args)


def run(fn, n: int, chunk: int, args: tuple = (), scheduler=SERIAL, folder: Path | None = None,
        progress: bool = False, desc: str = "", warm=None, warm_args: tuple = (), inflight: int | None = None) -> dict:
    """fn over the chunks of range(n): {name: array of first axis n}. `scheduler` is None
    (this process), 'local', an address, or a dask.distributed Client."""
    sink = Sink(n, folder)
    spans = bounds(n, chunk)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n, desc=desc, unit="set", leave=False, file=sys.stderr)
    try:
        if scheduler is SERIAL:
            limit = BUDGET
            if limit is not None and warm is not None:
                warm(*warm_args)  # a first compile or load is not the pace of the run
            t0 = time.perf_counter()
            for s, e in spans:
                sink.put(s, fn(s, e, *args))
                if bar is not None:
                    bar.update(e - s)
                if limit is not None and e < n:
                    over_budget(n, e, time.perf_counter() - t0, limit)
        else:
            _run_dask(fn, spans, args, scheduler, sink, bar, warm, warm_args, inflight)
    finally:
        if bar is not None:
            bar.close()
    return sink.close()


def _run_dask(fn, spans, args, scheduler, sink, bar, warm, warm_args, inflight) -> None:
    from distributed import Client, as_completed

    c = client(scheduler)
    own = not isinstance(scheduler, Client)
    try:
        warm_workers(c, warm, *warm_args)
        # large arguments go to every worker once, not with every task
        shipped = tuple(c.scatter(a, broadcast=True) if isinstance(a, np.ndarray) and a.nbytes > 1 << 16 else a
                        for a in args)
        workers = max(1, len(c.scheduler_info(n_workers=-1)["workers"]))
        limit = inflight or 4 * workers
        todo = iter(spans)
        starts = {}

        def submit():
            span = next(todo, None)
            if span is None:
                return None
            f = c.submit(fn, span[0], span[1], *shipped, pure=False)
            starts[f.key] = span
            return f

        pending = [f for f in (submit() for _ in range(limit)) if f is not None]
        queue = as_completed(pending)
        for f in queue:
            s, e = starts.pop(f.key)
            sink.put(s, f.result())
            f.release()
            if bar is not None:
                bar.update(e - s)
            nxt = submit()
            if nxt is not None:
                queue.add(nxt)
    finally:
        if own:
            cluster = getattr(c, "cluster", None)
            c.close()
            if cluster is not None:
                cluster.close()
