"""The scene figures of the README (bench/results/scene_<model>.png) are drawn from
bench/results/scenes.json; these tests keep that data from going stale: at a few points of
each sweep, rebuilt by the bench's own code (`bench.levels.scene_sweeps`), the level the
selector picks now is the one recorded (`python -m bench.levels --scenes` draws them again)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gyro.analyses.scene import select
from gyro.models import load
from tests.conftest import ROOT, run_cli

DATA = json.loads((ROOT / "bench" / "results" / "scenes.json").read_text())


def _sweep(model: str):
    from bench.levels import scene_sweeps

    d = DATA[model]
    (sw,) = [s for s in scene_sweeps(d["quick"]) if s.model == model]
    assert np.allclose(sw.x, d["x"], rtol=1e-15, atol=0), "the sweep was changed: run python -m bench.levels --scenes"
    return sw, d


def _point(sw, k: int):
    """(P with the one set, the question's options) of the sweep's k-th point."""
    if len(sw.groups) == 1:
        P, opts = sw.groups[0]
        return P[k:k + 1], opts
    return sw.groups[k]


# (model, point index, tolerances): cheap points (the gimbal gyroscope's near the separatrix
# tries both integrators before it says no level meets it; one tolerance there)
CASES = [("torsion_gyrocompass", 0, ("0.01", "1e-05", "1e-09")),
         ("torsion_gyrocompass", -1, ("0.01", "1e-09")),
         ("gyrohorizoncompass", 7, ("0.01", "1e-09")),
         ("gimbal_gyroscope", 0, ("0.01", "1e-05", "1e-09")),
         ("gimbal_gyroscope", -1, ("1e-05",))]


@pytest.mark.parametrize("model, k, tols", CASES)
def test_figure_data_are_what_the_selector_picks(model, k, tols):
    sw, d = _sweep(model)
    k = k % len(d["x"])
    P, opts = _point(sw, k)
    m = load(model)
    for tol in tols:
        sc = select(m, sw.question, P, float(tol), opts)
        assert str(sc.level[0]) == d["picked"][tol][k], (model, d["x"][k], tol)


def test_figures_are_committed_and_named_in_the_readme():
    readme = (ROOT / "README.md").read_text()
    for model, d in DATA.items():
        assert (ROOT / "bench" / "results" / d["figure"]).exists()
        assert f"bench/results/{d['figure']}" in readme, model


def test_gyro_scene_picks_what_the_precession_figure_shows():
    """The command line, at the imbalance where the elementary theory stops meeting 1e-2."""
    d = DATA["gimbal_precession"]
    k = d["x"].index(min(d["x"], key=lambda v: abs(v - 1e-5)))
    for tol in ("0.01", "1e-09"):
        rc, out, err = run_cli("scene", "gimbal_precession", "motion", "--tol", tol, "--horizon",
                               str(d["options"][0]["horizon"]), "--set", f"k_xi1={d['x'][k]!r}", "--json")
        assert rc == (0 if d["picked"][tol][k] else 1), err
        if rc == 0:
            assert json.loads(out)["level"] == d["picked"][tol][k]
