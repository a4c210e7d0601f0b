"""Independent pieces of a derivation on several cores: `pmap(task, n, jobs)`.

`make derive` passes `--jobs`: the models are derived side by side, and within a model the
emission of its functions (CSE and four printers each, independent of one another) is
shared out. The workers are forked (concurrent.futures over the "fork" start method), so a
task sees everything its parent had built, the symbolic results included, without pickling
them; only its return value travels back (for the emitter, printed text). Where the
platform cannot fork, or one job is asked for, the tasks run in this process in order.
Either way the results are those of running the tasks one after another: each task is a
pure function of what was built before the workers were forked, and the results come back
in the tasks' order (tests/test_parallel_derive.py holds the emitted files to the bytes of
a run with one job).
"""
from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import os
from typing import Callable

_TASK: list[Callable[[int], object]] = []  # the task of the innermost pmap, for the forked workers


class WorkerDied(RuntimeError):
    """A worker ended without a result (killed by a signal, out of memory); one line."""


def usable_cores() -> int:
    """The cores this process may run on (its affinity where the platform tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def can_fork() -> bool:
    return "fork" in mp.get_all_start_methods()


def _run(i: int):
    return _TASK[-1](i)


def pmap(task: Callable[[int], object], n: int, jobs: int, order: list[int] | None = None) -> list:
    """[task(0), ..., task(n - 1)], on up to `jobs` forked workers. `order` is the order in
    which the tasks are handed out (the longest first balances the workers best); the
    results are returned in index order whatever it is. An exception in a task is raised
    here, as it would be in a plain loop."""
    order = list(range(n)) if order is None else list(order)
    if sorted(order) != list(range(n)):
        raise ValueError("order: not a permutation of the tasks")
    if jobs <= 1 or n <= 1 or not can_fork():
        return [task(i) for i in range(n)]
    _TASK.append(task)
    try:
        with cf.ProcessPoolExecutor(min(jobs, n), mp_context=mp.get_context("fork")) as ex:
            done = dict(zip(order, ex.map(_run, order)))
    except cf.process.BrokenProcessPool as exc:
        raise WorkerDied(f"a worker process ended without its result ({exc}); try --jobs 1") from None
    finally:
        _TASK.pop()
    return [done[i] for i in range(n)]
