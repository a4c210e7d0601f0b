"""`gyro scene` on a model that declares no hierarchy: every model with an operator about
its equilibrium has the implicit exact level (gyro.levels.IMPLICIT_EXACT), the exact
operator by each method of the ladder, bounded by the method's own estimate."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gyro import levels as hierarchy
from gyro.models import load
from tests.conftest import error_lines, run_cli

ROOT = Path(__file__).resolve().parent.parent.parent
GYROPENDULUM = str(ROOT / "tests" / "models" / "gyropendulum.py")


def test_a_model_without_levels_answers_frequencies_by_the_exact_operator():
    rc, out, err = run_cli("scene", GYROPENDULUM, "frequencies", "--tol", "1e-9", "--json")
    assert rc == 0 and not error_lines(err), err
    d = json.loads(out)
    assert d["level"] == "linear_exact:default"
    rc, out, _ = run_cli("frequencies", GYROPENDULUM, "--json")
    f = json.loads(out)
    # the same method, the same numbers; the bound is the method's own estimate
    assert d["frequencies"] == f["frequencies"]
    assert d["error_bound"] == f["error_estimate"]


def test_stability_prints_words_not_a_mapping():
    rc, out, err = run_cli("scene", GYROPENDULUM, "stability", "--tol", "1e-6")
    assert rc == 0, err
    assert "stability: class stable, growth_rate 0, unstable_roots 0" in out
    assert "{" not in out and "np.float64" not in out


def test_a_declared_spectrum_level_is_not_doubled():
    """The torsion gyrocompass and the hoop bead declare their own linear_exact: one family
    of four methods each, not two."""
    for name in ("torsion_gyrocompass", str(ROOT / "tests" / "models" / "hoop_bead.py")):
        m = load(name)
        family = [lv.name for lv in hierarchy.levels(m) if lv.family == "linear_exact"]
        assert sorted(family) == ["linear_exact:companion", "linear_exact:default", "linear_exact:polyroots",
                                  "linear_exact:reference"], (name, family)


def test_the_implicit_level_is_in_the_models_hierarchy_and_in_help():
    m = load(GYROPENDULUM)
    assert [lv.name for lv in hierarchy.levels(m)][0].startswith("linear_exact:")
    assert not any(d["evaluator"].get("kind") == "spectrum" for d in m.meta.get("levels", []))  # motion levels only
    rc, out, _ = run_cli("scene", "--help")
    assert rc == 0 and "gyrohorizoncompass" in out
    P = m.vector()[None]
    b = hierarchy.bounds(m, hierarchy.get(m, "linear_exact"), "frequencies", P, 2)
    assert np.all(b.estimate) and np.all(b.apriori == 0)
