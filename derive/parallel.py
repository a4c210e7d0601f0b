"""Independent pieces of a derivation on several cores: `pmap(task, n, jobs)`.

`make derive` passes `--jobs`: the models are derived side by side, and within a model the
emission of its functions (CSE and four printers each, independent of one another) is
shared out. The workers are forked (concurrent.futures over the "fork" start method), so a
task sees everything its parent had built, the symbolic results included, without pickling
them; only its return value travels back (for the emitter, printed text). Either way the
results are those of running the tasks one after another: each task is a pure function of
what was built before the workers were forked, the results come back in the tasks' order,
and where tasks fail the one raised is the first by index, as a loop would raise it
(tests/generated/test_parallel_derive.py holds the emitted files to the bytes of a run with one job).

Workers run on Linux only, where each is tied to its parent's life (PR_SET_PDEATHSIG): a
worker whose parent dies (killed, out of memory, a signal) is killed with it, so that no
worker outlives the command or writes after it, and a worker's death closes the pipes its
parent waits on, which is how the parent learns of it (a pool inside a worker is a
grandchild of the command). Elsewhere, or with one job, the tasks run in this process.
"""
from __future__ import annotations

import os
import sys
from functools import lru_cache
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    import concurrent.futures as cf

# concurrent.futures, multiprocessing, pickle, ctypes and signal are imported where workers
# are used, not with the module: with one job (a derivation on one core, the smallest
# models' whole process) they would be 0.01-0.02 s of import for nothing

_TASK: list[Callable[[int], object]] = []  # the task of the innermost pmap, for the forked workers
JOBS = 1  # the cores the derivation may use (python -m derive --jobs): where pmap and later take it
_PR_SET_PDEATHSIG = 1


class WorkerDied(RuntimeError):
    """A worker ended without a result (killed by a signal, out of memory), or none could be
    started; one line."""


def usable_cores() -> int:
    """The cores this process may run on (its affinity where the platform tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


@lru_cache(maxsize=None)
def _prctl():
    import ctypes

    try:
        fn = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    fn.argtypes, fn.restype = (ctypes.c_int, ctypes.c_ulong), ctypes.c_int
    return fn


def can_fork() -> bool:
    """Workers are used where they can be forked and tied to their parent's life: Linux."""
    import multiprocessing as mp

    return sys.platform.startswith("linux") and "fork" in mp.get_all_start_methods() and _prctl() is not None


def beside() -> bool:
    """Whether work goes to workers: more than one job (JOBS), and workers to be had."""
    return JOBS > 1 and can_fork()


def _tie_to_parent(parent: int) -> None:
    """A worker's initializer: killed when its parent dies (and at once if it already has).
    The wake-up pipes of the parent's pools, copied by the fork, are forgotten: at a
    worker's exit concurrent.futures wakes every pool it knows, and writing to a copy the
    parent has meanwhile closed printed "Exception ignored ... OSError: Bad file descriptor"
    (2 runs in 6 where a model worker was killed beside one that went on)."""
    import concurrent.futures as cf
    import signal

    _prctl()(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:
        os._exit(1)
    getattr(cf.process, "_threads_wakeups", {}).clear()


def _run(i: int):
    import pickle
    from multiprocessing.reduction import ForkingPickler

    try:
        return _TASK[-1](i)
    except Exception as exc:
        # one that cannot travel back would reach the parent as a dead pool: pickled as the
        # result queue pickles it (with the reducers other packages register: tblib's,
        # installed by dask.distributed, pickles an exception's context and cause too)
        try:
            pickle.loads(ForkingPickler.dumps(exc))
        except Exception:
            message = f"{type(exc).__name__}: {exc}"
        else:
            raise
    raise RuntimeError(message)  # raised outside the handler: no context to carry along


def _pool(workers: int) -> cf.ProcessPoolExecutor:
    import concurrent.futures as cf
    import multiprocessing as mp

    return cf.ProcessPoolExecutor(workers, mp_context=mp.get_context("fork"),
                                  initializer=_tie_to_parent, initargs=(os.getpid(),))


def _died(exc) -> WorkerDied:
    return WorkerDied(f"a worker process ended without its result ({exc}); try --jobs 1")


def _stop(ex: cf.ProcessPoolExecutor) -> None:
    """The pool shut down with no worker left behind (one waiting on a pool that broke or
    never filled is killed)."""
    left = list((getattr(ex, "_processes", None) or {}).values())
    manager = getattr(ex, "_executor_manager_thread", None)  # shutdown() forgets it
    ex.shutdown(wait=False, cancel_futures=True)
    for p in left:
        if p.is_alive():
            p.kill()
    # the pool's manager thread closes its wake-up pipe as it ends: joined here, so that the
    # interpreter's exit does not write to that pipe while the thread closes it (a race in
    # concurrent.futures that printed "Exception ignored ... OSError: Bad file descriptor"
    # after a model worker was killed)
    if manager is not None and manager.is_alive():
        manager.join(timeout=10)


class later:
    """fn() beside what this process does next, in a forked worker, where JOBS > 1 (and
    workers can be tied to their parent); else now, here. result() gives its value (or
    raises its exception, or WorkerDied), waiting for it; `beside` says which it was."""

    def __init__(self, fn: Callable[[], object]):
        self._future = self._ex = None
        if beside():
            _TASK.append(lambda _: fn())
            try:  # the fork method forks the worker within submit, with the task pushed
                self._ex = _pool(1)
                self._future = self._ex.submit(_run, 0)
            except OSError:  # no process to be had: now, here
                _stop(self._ex)
                self._future = None
            finally:
                _TASK.pop()
        self.beside = self._future is not None
        if not self.beside:
            self._value = fn()

    def result(self):
        if not self.beside:
            return self._value
        import concurrent.futures as cf

        try:
            return self._future.result()
        except cf.process.BrokenProcessPool as exc:
            raise _died(exc) from None
        finally:
            self._ex.shutdown(wait=True)


def pmap(task: Callable[[int], object], n: int, jobs: int | None = None, order: list[int] | None = None) -> list:
    """[task(0), ..., task(n - 1)], on up to `jobs` forked workers (default JOBS). `order` is the order in
    which the tasks are handed out (the longest first balances the workers best); the
    results are returned in index order whatever it is. Where tasks raise, the exception of
    the first by index is raised here, after the others have ended, as a loop would raise
    it; a worker that dies without a result (a signal, out of memory), or workers that
    cannot be started, raise WorkerDied."""
    order = list(range(n)) if order is None else list(order)
    if sorted(order) != list(range(n)):
        raise ValueError("order: not a permutation of the tasks")
    jobs = JOBS if jobs is None else jobs
    if jobs <= 1 or n <= 1 or not can_fork():
        return [task(i) for i in range(n)]
    import concurrent.futures as cf

    _TASK.append(task)
    ex = _pool(min(jobs, n))
    done = False
    try:
        try:
            futures = dict(zip(order, (ex.submit(_run, i) for i in order)))
        except OSError as exc:  # no process or pipe to be had (a limit, memory)
            raise WorkerDied(f"the worker processes could not be started ({exc}); try --jobs 1") from None
        cf.wait(futures.values())
        for i in range(n):
            exc = futures[i].exception()
            if isinstance(exc, cf.process.BrokenProcessPool):
                raise _died(exc) from None
            if exc is not None:
                raise exc
        done = True
        return [futures[i].result() for i in range(n)]
    finally:
        _TASK.pop()
        if done:
            ex.shutdown(wait=True)
        else:
            _stop(ex)
