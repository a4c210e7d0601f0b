"""The command line survives its environment: a corrupted compiled library is rebuilt, not
loaded; Ctrl-C ends a run in one line with exit 130; a killed run's temporaries are removed
by the next; stdout carries the result alone."""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest


def gyro(*args, env=None, **kw):
    return subprocess.run([sys.executable, "-m", "gyro", *args], capture_output=True, text=True,
                          env=env, **kw)


@pytest.fixture(scope="module")
def built_cache(tmp_path_factory):
    """A cache holding the gyrohorizoncompass's compiled library (its C compiles in a few
    seconds, the torsion gyrocompass's in tens), and the first run's answer."""
    cache = tmp_path_factory.mktemp("built") / "cache"
    first = gyro("frequencies", "gyrohorizoncompass", "--json", env=dict(os.environ, GYRO_CACHE=str(cache)))
    assert first.returncode == 0 and "compiling the generated C" in first.stderr
    return cache, json.loads(first.stdout)


@pytest.mark.parametrize("damage", ["truncate", "zero", "garbage"])
def test_a_corrupted_cached_library_is_rebuilt(tmp_path, damage, built_cache):
    """A model's cached library, damaged three ways, is rebuilt and sealed again."""
    cache = tmp_path / "cache"
    shutil.copytree(built_cache[0], cache)
    env = dict(os.environ, GYRO_CACHE=str(cache))
    (so,) = cache.glob("gyrohorizoncompass-*.so")
    data = so.read_bytes()
    if damage == "truncate":
        so.write_bytes(b"")
    elif damage == "zero":
        so.write_bytes(data[:4096] + bytes(len(data) - 4096))
    else:
        so.write_bytes(data[: len(data) // 2])
    again = gyro("frequencies", "gyrohorizoncompass", "--json", env=env)
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout) == built_cache[1]
    assert "compiling the generated C" in again.stderr and "Traceback" not in again.stderr
    third = gyro("frequencies", "gyrohorizoncompass", "--json", env=env)
    assert third.returncode == 0 and third.stderr == ""  # sealed again: loaded silently


def test_ctrl_c_ends_a_run_in_one_line_with_exit_130(tmp_path):
    proc = subprocess.Popen([sys.executable, "-m", "gyro", "stability-map", "torsion_gyrocompass", "--x", "l2",
                             "--x-range", "-0.5", "0.3", "--y", "H", "--y-range", "0.01", "10", "--points", "100",
                             "--out", str(tmp_path / "m.png"), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            # a terminal's Ctrl-C: SIGINT as the default, also where this test
                            # runs in a parallel worker that ignores it (and its children would)
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    # 10 000 sets, a third of them unstable (the general rung, ~3 ms a set): about 30 s on an
    # idle machine, so the signal comes well inside the sweep, and a projected time within
    # the sweep's budget of 120 s at three times that (at 400 points the projection is 460 s
    # and the budget, not the signal, can end the run first)
    time.sleep(3.0)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip() == "gyro: interrupted" and out == ""
    assert not (tmp_path / "m.png").exists()


def test_a_killed_runs_temporary_is_removed_by_the_next(tmp_path):
    from gyro.results import TMP_TAG, save_figure

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()  # a process that has ended
    stale = tmp_path / f".fig.png.{dead}{TMP_TAG}.png"
    stale.write_bytes(b"")
    fig = plt.figure()
    save_figure(fig, tmp_path / "fig.png")
    plt.close(fig)
    assert not stale.exists() and (tmp_path / "fig.png").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig.png"]


def test_stdout_carries_the_json_alone_even_where_lapack_complains():
    r = gyro("frequencies", "torsion_gyrocompass", "--set", "K0=1e-308", "--json")
    assert r.stdout == "" or json.loads(r.stdout)
    assert r.returncode in (0, 1) and "Traceback" not in r.stderr
    r = gyro("frequencies", "torsion_gyrocompass", "--json")
    assert r.returncode == 0 and json.loads(r.stdout)["model"] == "torsion_gyrocompass"
