"""The sweep executor (gyro/executor.py): a local Dask cluster of two workers gives the bits
of the in-process run, a worker killed mid-run costs its chunk a retry and not the run,
and results go to .npy memory maps chunk by chunk."""
from __future__ import annotations

import os
import signal
import sys

import numpy as np
import pytest

from gyro import executor
from gyro.analyses.sweep import spectra
from gyro.analyses.tolerance import parse_spread, tolerance
from gyro.models import load

MODEL = "torsion_gyrocompass"


@pytest.fixture(scope="session")
def cluster():
    distributed = pytest.importorskip("distributed")
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers need not import the tests
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cl, distributed.Client(cl) as c:
        yield c


@pytest.fixture(scope="module")
def batch():
    tg = load(MODEL)
    p0 = tg.vector()
    return tg, np.tile(p0, (300, 1)) * (1 + 0.03 * np.random.default_rng(5).standard_normal((300, len(p0))))


def test_dask_gives_the_bits_of_the_in_process_run(cluster, batch):
    tg, P = batch
    # other chunks on Dask: a set's answer is its own, whatever chunk it is computed in
    here = spectra(tg, P, chunk=64)
    there = spectra(tg, P, scheduler=cluster, chunk=37)
    for f in ("frequencies", "growth", "error_estimate", "equilibrium"):
        assert np.array_equal(getattr(here, f), getattr(there, f), equal_nan=True), f
    assert list(here.route) == list(there.route)
    # the compiled kernels were loaded once on each worker (warm), before any task
    assert all(cluster.run(lambda: "gyro.cbackend" in sys.modules).values())


def _crash_once(start, stop, marker, P):
    """A chunk that kills its worker the first time chunk 200 runs (as a machine lost mid-run)."""
    if start == 200 and not os.path.exists(marker):
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return {"y": P[start:stop] * 2.0, "i": np.arange(start, stop)}


def test_a_killed_worker_costs_a_retry_not_the_run(cluster, tmp_path):
    P = np.random.default_rng(1).standard_normal((500, 3))
    marker = str(tmp_path / "killed")
    out = executor.run(_crash_once, 500, 50, (marker, P), cluster)
    assert os.path.exists(marker)  # the worker was killed ...
    assert np.array_equal(out["y"], P * 2.0) and np.array_equal(out["i"], np.arange(500))  # ... and the run finished


def test_results_go_to_memory_maps_chunk_by_chunk(tmp_path, batch):
    tg, P = batch
    folder = tmp_path / "spectra"
    on_disk = spectra(tg, P[:150], chunk=64, folder=folder)
    in_memory = spectra(tg, P[:150], chunk=64)
    stored = np.load(folder / "frequencies.npy", mmap_mode="r")
    assert np.array_equal(stored, in_memory.frequencies) and np.array_equal(on_disk.frequencies, in_memory.frequencies)
    assert executor.bounds(10, 4) == [(0, 4), (4, 8), (8, 10)]


def test_a_tolerance_study_on_dask_is_the_in_process_one(cluster):
    tg = load(MODEL)
    spreads = [parse_spread("Kp=normal:0.05"), parse_spread("Kgamma=uniform:0.1")]
    # other chunks on Dask: the random streams come in blocks of their own, so the samples
    # (and every bit of the answer) do not depend on the chunks
    a = tolerance(tg, tg.defaults, spreads, 700, seed=3, size=256)
    b = tolerance(tg, tg.defaults, spreads, 700, seed=3, scheduler=cluster, size=100)
    assert a.to_dict() == b.to_dict()


def test_maps_and_campbell_diagrams_on_dask_are_the_in_process_ones(cluster):
    """The stability map and the Campbell diagram run their batch on the sweep executor when
    given a scheduler, to the bit the in-process answer (the budgeted in-process batch)."""
    from gyro.analyses.campbell import campbell
    from gyro.analyses.stability_map import stability_grid

    tg = load(MODEL)
    v = tg.parameters({})
    here = stability_grid(tg, v, "H", (0.1, 0.6), "Kp", (1e5, 1e6), 6)
    there = stability_grid(tg, v, "H", (0.1, 0.6), "Kp", (1e5, 1e6), 6, scheduler=cluster)
    assert np.array_equal(here.label, there.label) and np.array_equal(here.growth, there.growth, equal_nan=True)
    assert here.to_dict() == there.to_dict()
    spins = np.linspace(0.05, 0.5, 9)
    a = campbell(tg, v, "H", spins, harmonics=(1, 2))
    b = campbell(tg, v, "H", spins, harmonics=(1, 2), scheduler=cluster)
    assert np.array_equal(a.exact.frequencies, b.exact.frequencies)
    assert a.to_dict() == b.to_dict()
