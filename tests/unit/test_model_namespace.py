"""Each model derives in its own namespace: a helper module beside a model file is that
model's own, in one `python -m derive --model A --model B` call as in two, and a model's
input hash covers the helpers it imports from beside itself and nothing of another model."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.conftest import ROOT

MODEL = textwrap.dedent('''
    """A mass on {what} springs of stiffness k each: K = {K}."""
    import sympy as sp
    import springs
    from derive.model import Model, Parameter

    def build():
        x, x_d, x_dd = sp.symbols("x x_d x_dd")
        k = sp.Symbol("k")
        return Model(name="{name}", title="mass on springs", source="test", module=__name__,
                     parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 4.0, "one spring")],
                     coordinates=["x"], coordinate_units={{"x": "m"}}, q=[x], qd=[x_d], qdd=[x_dd],
                     lagrangian=sp.Symbol("m") * x_d**2 / 2 - springs.stiffness(k) * x**2 / 2,
                     symmetric_zero=["x"])
''')
SERIES = "def stiffness(k):\n    return k / 2\n"  # two springs in series: K = k/2 = 2
PARALLEL = "def stiffness(k):\n    return 2 * k\n"  # in parallel: K = 2 k = 8


def _folder(tmp: Path, sub: str, name: str, helper: str, what: str) -> Path:
    d = tmp / sub
    d.mkdir(parents=True)
    (d / "springs.py").write_text(helper)
    (d / f"{name}.py").write_text(MODEL.format(name=name, what=what, K="k/2" if "k / 2" in helper else "2 k"))
    return d / f"{name}.py"


def _derive(out: Path, *files: Path, cli: bool = False) -> dict:
    """`python -m derive --model F ... --out OUT`, in a new process or in this one."""
    args = [a for f in files for a in ("--model", str(f))] + ["--out", str(out)]
    if cli:
        proc = subprocess.run([sys.executable, "-m", "derive", *args], cwd=ROOT, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
    else:
        import contextlib
        import io

        from derive.__main__ import main

        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            assert main(args) == 0, err.getvalue()
    return {f.stem: json.loads((out / f.stem / "metadata.json").read_text()) for f in files}


def _stiffness(out: Path, name: str) -> float:
    from gyro.models import load

    model = load(out / name)
    return float(model.numpy.operator(model.vector(model.defaults), [])[2][0, 0])


@pytest.fixture(scope="module")
def two(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("two")
    return tmp, _folder(tmp, "a", "series", SERIES, "two in series"), _folder(tmp, "b", "parallel", PARALLEL, "two in parallel")


def test_two_models_with_a_springs_py_each_keep_their_own_in_one_call_in_either_order(two):
    tmp, a, b = two
    for order, out, cli in (((a, b), tmp / "ab", False), ((b, a), tmp / "ba", False)):
        _derive(out, *order, cli=cli)
        assert _stiffness(out, "series") == 2.0 and _stiffness(out, "parallel") == 8.0, order


def test_in_one_process_each_model_builds_with_its_own_helper(two):
    """The same through derive.__main__'s loading, as a session (the docs) uses it."""
    from derive.__main__ import build, load_file

    _, a, b = two
    ma, mb = load_file(a), load_file(b)
    k = __import__("sympy").Symbol("k")
    for _ in range(2):  # and again, after both were loaded
        La, Lb = build(ma).lagrangian, build(mb).lagrangian
        assert La.coeff(__import__("sympy").Symbol("x") ** 2) == -k / 4
        assert Lb.coeff(__import__("sympy").Symbol("x") ** 2) == -k
    assert "springs" not in sys.modules  # set aside between models, not left to the next


def chains(tmp: Path) -> list[Path]:
    """Two files chain.py, in folders p and q, each with a springs.py beside it: the same
    model 'chain' but for its gain, 1 and 3."""
    files = []
    for sub, gain in (("p", "1"), ("q", "3")):
        d = tmp / sub
        d.mkdir()
        (d / "springs.py").write_text(SERIES)
        (d / "chain.py").write_text(MODEL.format(name="chain", what="two", K="k/2").replace(
            "springs.stiffness(k)", f"{gain} * springs.stiffness(k)"))
        files.append(d / "chain.py")
    return files


def test_input_hash_tells_models_apart_and_covers_their_helpers(tmp_path):
    """Two files of the same name and contents but for one constant, in two folders: derived
    together, each gets the hash it gets alone, and the two differ. A helper's constant
    changes the hash of the model beside it and of no other."""
    files = chains(tmp_path)
    from derive import emit

    together = [emit.input_hash(f) for f in files]
    assert together[0] != together[1]
    # derived in one call (the same out folder name: each into its own out)
    for f, h in zip(files, together):
        meta = _derive(f.parent / "out", f)["chain"]  # alone
        assert meta["generated"]["input_hash"] == h
    _derive(tmp_path / "both", *files)
    # the second overwrote the first's folder (one name): its hash is its own, not the first's
    meta = json.loads((tmp_path / "both" / "chain" / "metadata.json").read_text())
    assert meta["generated"]["input_hash"] == together[1]
    # a helper's constant: the model beside it changes, the other does not
    helper = files[0].parent / "springs.py"
    helper.write_text(SERIES.replace("k / 2", "k / 5"))
    assert emit.input_hash(files[0]) != together[0] and emit.input_hash(files[1]) == together[1]
    assert emit.model_files(files[0]) == [files[0].resolve(), helper.resolve()]


def test_helpers_found_by_reading_imports_of_every_form(tmp_path):
    """import x, from x import y, a package's submodule, an import inside a function, a helper
    that imports another helper; installed packages and the machinery are not helpers."""
    from derive import emit

    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text("")
    (tmp_path / "pkg" / "inertia.py").write_text("from . import shapes\n")
    (tmp_path / "pkg" / "shapes.py").write_text("X = 1\n")
    (tmp_path / "lazy.py").write_text("import deep\n")
    (tmp_path / "deep.py").write_text("Y = 2\n")
    (tmp_path / "unused.py").write_text("Z = 3\n")
    (tmp_path / "m.py").write_text("import sympy\nfrom derive import mechanics\nfrom pkg import inertia\n"
                                   "def build():\n    import lazy\n")
    got = {f.relative_to(tmp_path.resolve()).as_posix() for f in emit.model_files(tmp_path / "m.py")}
    assert got == {"m.py", "pkg/__init__.py", "pkg/inertia.py", "pkg/shapes.py", "lazy.py", "deep.py"}
