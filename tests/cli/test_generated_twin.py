"""A model file whose derivation inputs hash equal to a generated package's (its own source,
or a byte-identical copy under the same name) is that package: nothing derived, the same
answers. A file that differs by one byte derives its own (gyro.models.generated_twin)."""
from __future__ import annotations

import contextlib
import io

from gyro.catalog import generated_dir
from gyro.cli import main
from gyro.models import _source_root, generated_twin, load

MODEL = "torsion_gyrocompass"


def _copy(folder, text):
    folder.mkdir()
    path = folder / f"{MODEL}.py"
    path.write_text(text)
    return path


def _source():
    return (_source_root() / "derive" / "models" / f"{MODEL}.py").read_text()


def _env():
    import os

    return dict(os.environ, PYTHONDONTWRITEBYTECODE="1", PYTHONPATH=str(_source_root()))


def test_a_copy_of_a_generated_models_file_is_that_model(tmp_path, monkeypatch):
    monkeypatch.setenv("GYRO_CACHE", str(tmp_path / "cache"))
    path = _copy(tmp_path / "elsewhere", _source())
    # at once where generated/ is stale (make derive), rather than after a minute's derivation
    assert generated_twin(path, _source_root(), tmp_path / "probe.generated", _env()) == MODEL
    outs = []
    for argv in (["frequencies", str(path), "--json"], ["frequencies", MODEL, "--json"]):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            assert main(argv) == 0
        assert "deriving" not in err.getvalue(), err.getvalue()
        outs.append(out.getvalue())
    assert outs[0] == outs[1]
    assert load(path).directory == generated_dir() / MODEL
    # nothing derived into the cache: the hash's marker alone
    assert [p.suffix for p in (tmp_path / "cache" / "models").iterdir()] == [".generated"]
    assert sorted(p.name for p in path.parent.iterdir()) == [path.name]  # no __pycache__ beside it


def test_a_file_that_differs_by_one_byte_derives_its_own(tmp_path):
    root, env = _source_root(), _env()
    text = _source()
    changed = text.replace('Parameter("M", "kg", 0.6,', 'Parameter("M", "kg", 0.61,')
    assert changed != text
    same = _copy(tmp_path / "same", text)
    other = _copy(tmp_path / "changed", changed)
    assert generated_twin(same, root, tmp_path / "same.generated", env) == MODEL
    assert generated_twin(other, root, tmp_path / "changed.generated", env) is None
    renamed = tmp_path / "same" / "renamed_gyrocompass.py"  # its name is one of its inputs
    renamed.write_text(text)
    assert generated_twin(renamed, root, tmp_path / "renamed.generated", env) is None
    # a marker is taken only while the generated package carries its hash: else computed again
    marker = tmp_path / "stale.generated"
    marker.write_text(f"{MODEL} {'0' * 64}\n")
    assert generated_twin(same, root, marker, env) == MODEL
    assert marker.read_text().split() == (tmp_path / "same.generated").read_text().split()
