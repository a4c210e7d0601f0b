"""The runtime's cache key of a model file (gyro.models.model_key) covers what the
derivation reads: a change to a helper in a package beside the model file derives again
(before, only the Python files directly beside it counted, and an edited helper package
left the stale derivation in use)."""
from __future__ import annotations

from pathlib import Path

from gyro.models import model_key

ROOT = Path(__file__).resolve().parent.parent.parent


def test_a_helper_package_beside_the_model_file_is_in_its_key(tmp_path):
    model = tmp_path / "spring.py"
    model.write_text("from helpers.values import K\n")
    pkg = tmp_path / "helpers"
    (pkg / "deep").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "values.py").write_text("K = 1.0\n")
    (pkg / "deep" / "more.py").write_text("X = 1\n")
    first = model_key(model, ROOT)
    (pkg / "values.py").write_text("K = 2.0\n")
    second = model_key(model, ROOT)
    (pkg / "deep" / "more.py").write_text("X = 2\n")
    third = model_key(model, ROOT)
    assert len({first, second, third}) == 3


def test_a_folder_that_is_no_package_is_not_read(tmp_path):
    """Data or unrelated folders beside a model file cost nothing and change nothing."""
    model = tmp_path / "spring.py"
    model.write_text("x = 1\n")
    other = tmp_path / "runs"
    other.mkdir()
    (other / "scratch.py").write_text("a = 1\n")
    first = model_key(model, ROOT)
    (other / "scratch.py").write_text("a = 2\n")
    assert model_key(model, ROOT) == first
