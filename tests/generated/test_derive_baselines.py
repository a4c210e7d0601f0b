"""The derivation's speed against sympy.physics.mechanics (bench/derive_baselines.py): the
baselines of the three small seed models give the generated functions' numbers (run here,
a few seconds each), and the committed record is complete and consistent with itself."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bench import derive_baselines as db

RECORD = Path(__file__).resolve().parents[2] / "bench" / "results" / "derive_baselines.json"


@pytest.fixture(scope="module")
def points():
    return db.points()


@pytest.mark.parametrize("name", ["gimbal_gyroscope", "gyrohorizoncompass", "gimbal_precession"])
def test_the_baseline_gives_the_generated_numbers(points, name):
    import importlib

    pt = points[name]
    base = importlib.import_module(f"bench.baselines.{name}").run(json.loads(json.dumps(pt["point"])))
    diff = db.agreement(pt["values"], base["values"])
    assert max(diff.values()) < 1e-10, diff
    # and the comparison sees a difference where there is one
    wrong = {k: np.asarray(v, dtype=float) * (1 + 1e-8) for k, v in base["values"].items()}
    assert max(db.agreement(pt["values"], wrong).values()) > 1e-9


def test_the_record_holds_every_seed_model_and_its_ratio():
    rec = json.loads(RECORD.read_text())
    assert set(rec["models"]) == set(db.MODELS)
    assert rec["goal_ratio"] == db.GOAL_RATIO
    for name, row in rec["models"].items():
        ours = row["project"]["total_s"]
        assert 0 < row["project"]["import_s"] <= ours
        if row["baseline"]["finished"]:
            assert row["agree"] is True and max(row["max_rel_diff"].values()) <= row["tolerance"] <= 1e-10, name
            assert row["ratio"] == pytest.approx(row["baseline"]["total_s"] / ours, rel=1e-12)
            ratio = row["ratio"]
        else:
            assert row["ratio"] is None
            ratio = row["ratio_lower_bound"]
            assert ratio == pytest.approx(row["timeout_s"] / ours, rel=1e-12)
        assert row["goal_met"] == (ratio >= db.GOAL_RATIO), name
        assert row["project_whole"]["total_s"] >= row["project"]["import_s"]
    md = rec["make_derive"]
    assert md["goal_s"] == db.GOAL_MAKE_DERIVE_S
    assert md["goal_met"] == (md["wall_s"] <= md["goal_s"])
    assert set(md["per_model_s"]) == set(db.MODELS)


def test_a_baseline_past_its_bound_is_reported_as_not_finished():
    """A bound shorter than the baseline's start: no ratio, only its lower bound S / t_project,
    and no agreement claimed."""
    row = db.bench(["gimbal_precession"], timeout=0.05)["gimbal_precession"]
    assert row["baseline"]["finished"] is False and row["ratio"] is None and row["agree"] is None
    assert row["ratio_lower_bound"] == pytest.approx(0.05 / row["project"]["total_s"])
    assert row["goal_met"] is False
