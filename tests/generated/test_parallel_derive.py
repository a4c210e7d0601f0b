"""`python -m derive --jobs N` (derive.parallel): the models side by side and each model's
functions emitted side by side give the files of one job to the byte, the results in the
tasks' order whatever order they ran in; a failure in a worker is one line and exit 2; two
models of one name are still derived one after the other, the last named left."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from derive import parallel
from tests.conftest import ROOT


def _pid(i: int) -> tuple[int, int]:
    return i, os.getpid()


def test_pmap_gives_the_results_in_index_order_from_other_processes():
    order = [5, 3, 1, 0, 2, 4]
    out = parallel.pmap(_pid, 6, 2, order=order)
    assert [i for i, _ in out] == list(range(6))
    if parallel.can_fork():
        assert all(pid != os.getpid() for _, pid in out)
    assert parallel.pmap(_pid, 6, 1, order=order) == [(i, os.getpid()) for i in range(6)]  # one job: here, in order


def test_pmap_raises_a_tasks_exception_and_refuses_a_bad_order():
    def task(i):
        if i == 3:
            raise ArithmeticError(f"task {i}")
        return i

    for jobs in (1, 2):
        with pytest.raises(ArithmeticError, match="task 3"):
            parallel.pmap(task, 5, jobs)
    with pytest.raises(ValueError, match="order"):
        parallel.pmap(task, 3, 2, order=[0, 1, 1])
    assert parallel._TASK == []  # nothing left behind for a later pmap


def test_pmap_raises_the_first_failure_by_index_and_one_that_cannot_travel():
    """Two tasks fail, handed out last first: the one raised is the first by index, as a
    loop raises it. An exception that cannot be rebuilt in the parent arrives as its type
    and message, not as a dead worker, also where a package has made exceptions pickle
    their context (tblib's reducers, which importing dask.distributed installs: the
    condition under which the full suite first met it)."""
    import distributed  # noqa: F401

    class Odd(Exception):
        def __init__(self, a, b):  # pickles, but cannot be rebuilt from its args
            super().__init__(f"odd {a} {b}")

    def task(i):
        if i in (1, 3):
            raise LookupError(f"task {i}")
        if i == 4:
            raise Odd(1, 2)
        return i

    for jobs in (1, 2):
        with pytest.raises(LookupError, match="task 1"):
            parallel.pmap(task, 4, jobs, order=[3, 2, 1, 0])
        with pytest.raises(Exception, match="odd 1 2"):
            parallel.pmap(lambda i: task(4) if i == 1 else i, 2, jobs)


NESTED = """
import os, signal, sys, time
sys.path.insert(0, {root!r})
from derive import parallel

def inner(i):
    if i == 1:
        os.kill(os.getppid(), signal.SIGKILL)  # the outer worker, parent of this one, dies
    time.sleep(0.5)
    return i

def outer(i):
    return parallel.pmap(inner, 2, 2) if i == 0 else (time.sleep(1), i)[1]

try:
    parallel.pmap(outer, 2, 2)
except parallel.WorkerDied as exc:
    print("died:", exc)
"""


def test_a_worker_killed_while_its_own_workers_run_is_reported_and_none_is_left(tmp_path):
    """A worker that dies while its own pool (a model's emission) runs: the command learns of
    it (its children die with it, and with them the pipes it waits on), reports it in one
    line and ends; no worker of either level is left running."""
    if not parallel.can_fork():
        pytest.skip("workers only where they can be tied to their parent (Linux)")
    script = tmp_path / "nested.py"
    script.write_text(NESTED.format(root=str(ROOT)))
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert proc.stdout.startswith("died: a worker process ended without its result"), proc.stdout + proc.stderr
    left = subprocess.run(["pgrep", "-f", str(script)], capture_output=True, text=True).stdout.split()
    assert left == []


def test_two_jobs_derive_and_emit_in_other_processes(tmp_path, monkeypatch):
    """--jobs 2 does what it says: every function of both models is emitted in a process
    other than the command's, at least two of them; with one job, all in the command's."""
    import contextlib
    import io

    from derive import emit
    from derive.__main__ import main

    log = tmp_path / "pids.txt"
    real = emit._cse

    def recording(fn):
        with open(log, "a") as f:
            f.write(f"{os.getpid()} {fn.name}\n")
        return real(fn)

    monkeypatch.setattr(emit, "_cse", recording)
    for jobs in ("2", "1"):
        log.write_text("")
        with contextlib.redirect_stderr(io.StringIO()):
            assert main(["gimbal_gyroscope", "gimbal_precession", "--out", str(tmp_path / jobs), "--jobs", jobs]) == 0
        lines = log.read_text().splitlines()
        pids = {int(line.split()[0]) for line in lines}
        # every function of both models emitted once, wherever
        emitted = sorted(line.split()[1] for line in lines)
        assert emitted == sorted(f for m in ("gimbal_gyroscope", "gimbal_precession")
                                 for f in json.loads((tmp_path / jobs / m / "metadata.json").read_text())["functions"])
        assert parallel.JOBS == 1  # main leaves the process as it found it
        if jobs == "1" or not parallel.can_fork():
            assert pids == {os.getpid()}
        else:
            assert os.getpid() not in pids and len(pids) >= 2


def _derive(out, *args, jobs=1):
    return subprocess.run([sys.executable, "-m", "derive", *args, "--out", str(out), "--jobs", str(jobs)],
                          cwd=ROOT, capture_output=True, text=True)


def _files(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
            and "__pycache__" not in p.parts}


def test_two_jobs_write_the_bytes_of_one_job(tmp_path):
    """Two seed models side by side, each one's functions emitted by two workers: every file
    the same to the byte as one model and one function after another."""
    one, two = _derive(tmp_path / "one", "gimbal_gyroscope", "gimbal_precession"), \
        _derive(tmp_path / "two", "gimbal_gyroscope", "gimbal_precession", jobs=2)
    assert one.returncode == 0 and two.returncode == 0, one.stderr + two.stderr
    a, b = _files(tmp_path / "one"), _files(tmp_path / "two")
    assert len(a) == 15 and a.keys() == b.keys()
    assert [k for k in a if a[k] != b[k]] == []
    assert "[gimbal_precession] emit: CSE" in two.stderr and "derive: done in" in two.stderr


def test_a_failure_in_a_worker_is_one_line_and_exit_2(tmp_path):
    """A model that builds but whose derivation is refused (a force on a cyclic coordinate),
    beside one that derives: exit 2, the refusal in one line naming the model, no traceback."""
    from tests.unit.test_machinery import MODEL_FILE, _write_model

    (tmp_path / "good").mkdir()
    bad = _write_model(tmp_path / "wheel_cart.py", MODEL_FILE.format(name="wheel_cart", momentum="0"))
    good = _write_model(tmp_path / "good" / "wheel_free.py",
                        MODEL_FILE.format(name="wheel_free", momentum="0").replace(
                            ', generalized_forces={"th": tau.symbol}', ""))
    proc = _derive(tmp_path / "out", "--model", str(good), "--model", str(bad), jobs=2)
    assert proc.returncode == 2
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("derive: wheel_cart") and "force acts on the cyclic coordinate th" in last
    assert "Traceback" not in proc.stderr
    proc = _derive(tmp_path / "out", "--model", str(good), jobs=0)
    assert proc.returncode == 2 and proc.stderr.strip() == "derive: --jobs must be at least 1, got 0"


def test_a_model_worker_killed_is_one_line_and_exit_2(tmp_path):
    """A model whose derivation kills its own process (an identity that sends itself
    SIGKILL), beside one that derives, with --jobs 2: one line naming what happened, exit 2,
    no traceback, within a bound."""
    from tests.unit.test_model_namespace import PARALLEL, SERIES, _folder

    good = _folder(tmp_path, "a", "series", SERIES, "two in series")
    bad = _folder(tmp_path, "b", "parallel", PARALLEL, "two in parallel")
    bad.write_text("import os, signal\n\ndef _dies():\n    os.kill(os.getpid(), signal.SIGKILL)\n"
                   + bad.read_text().replace('symmetric_zero=["x"])', 'symmetric_zero=["x"], identities={"dies": _dies})'))
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(good), "--model", str(bad),
                           "--out", str(tmp_path / "out"), "--jobs", "2"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    if not parallel.can_fork():
        pytest.skip("workers only where they can be tied to their parent (Linux)")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("derive: a worker process ended without its result"), proc.stderr


def test_two_models_of_one_name_leave_the_last_named_with_two_jobs(tmp_path):
    """Two files that both build a model 'chain' (one folder): with --jobs 2 they are not
    written side by side into it; the one named last is what the folder holds, as with one
    job."""
    from derive import emit
    from tests.unit.test_model_namespace import chains

    files = chains(tmp_path)
    for order in (files, files[::-1]):
        proc = _derive(tmp_path / "both", *[a for f in order for a in ("--model", str(f))], jobs=2)
        assert proc.returncode == 0, proc.stderr
        meta = json.loads((tmp_path / "both" / "chain" / "metadata.json").read_text())
        assert meta["generated"]["input_hash"] == emit.input_hash(order[-1])


def test_a_worker_killed_is_reported_not_waited_for():
    """A worker that dies without a result (here: it kills itself) raises WorkerDied in one
    line; it neither hangs nor hands back a partial list."""
    import signal

    def task(i):
        if i == 1:
            os.kill(os.getpid(), signal.SIGKILL)
        return i

    if not parallel.can_fork():
        pytest.skip("no fork on this platform: the tasks run in this process")
    with pytest.raises(parallel.WorkerDied, match="without its result"):
        parallel.pmap(task, 3, 2)
    assert parallel._TASK == []


def test_later_runs_beside_with_jobs_and_here_without(monkeypatch):
    """parallel.later: with JOBS > 1 in a worker (another pid), its value or its exception
    at result(); with one job, now and here."""
    def boom():
        raise ArithmeticError("routes disagree")

    for jobs in (2, 1):
        monkeypatch.setattr(parallel, "JOBS", jobs)
        job = parallel.later(os.getpid)
        assert job.beside == (jobs > 1 and parallel.can_fork())
        assert (job.result() != os.getpid()) == job.beside
        if jobs > 1:
            failing = parallel.later(boom)
            with pytest.raises(ArithmeticError, match="routes disagree"):
                failing.result()
        else:
            with pytest.raises(ArithmeticError, match="routes disagree"):
                parallel.later(boom)


def test_the_routes_check_beside_the_next_steps_still_stops_a_disagreement(monkeypatch):
    """The comparison of the two routes run beside the later steps (JOBS 2): a disagreement
    still stops the derivation, as it does run in its place; an agreement is the same
    number in the metadata either way."""
    from derive import pipeline
    from derive.models import gimbal_gyroscope as gg
    from derive.passes import operator as operator_pass

    out = {}
    for jobs in (2, 1):
        monkeypatch.setattr(parallel, "JOBS", jobs)
        d = pipeline.derive(gg.build(), pipeline.Steps(out=open(os.devnull, "w")))
        out[jobs] = pipeline.metadata(d)["route_agreement"]
    assert out[2] == out[1] is not None
    monkeypatch.setattr(operator_pass, "compare_operators", lambda a, b: 1.0)
    for jobs in (2, 1):
        monkeypatch.setattr(parallel, "JOBS", jobs)
        with pytest.raises(AssertionError, match="routes 1 and 2 disagree"):
            pipeline.derive(gg.build(), pipeline.Steps(out=open(os.devnull, "w")))
