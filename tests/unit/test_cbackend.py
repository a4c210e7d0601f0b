"""The kernels' libraries (gyro/csrc compiled by gyro.cbackend): keyed by what can change
them, shared by the models of one operator dimension, built by two processes at once
without harm, and absent without a compiler, where the NumPy paths answer exactly as under
cbackend.disabled()."""
from __future__ import annotations

import functools
import json
import os
import shutil
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from gyro import cbackend
from tests.conftest import ROOT

NOTICE = "gyro: compiling the generated C's kernels"


def _uncached(monkeypatch, tmp_path):
    """A fresh cache folder and a fresh in-process memo of the kernels' libraries."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("GYRO_CACHE", str(cache))
    monkeypatch.setattr(cbackend, "_kernel_library", functools.lru_cache(None)(cbackend._kernel_library.__wrapped__))
    return cache


def test_a_changed_kernel_source_recompiles_and_an_unchanged_one_does_not(monkeypatch, tmp_path, capfd):
    cache = _uncached(monkeypatch, tmp_path)
    src = tmp_path / "csrc"
    shutil.copytree(cbackend.CSRC, src)
    build = cbackend._kernel_library.__wrapped__  # no memo: every call looks at the cache
    build(str(src), "polyroots", None)
    assert NOTICE in capfd.readouterr().err
    first = sorted(cache.glob("kernel-polyroots-*.so"))
    build(str(src), "polyroots", None)  # the same sources: loaded, not compiled
    assert NOTICE not in capfd.readouterr().err and sorted(cache.glob("kernel-polyroots-*.so")) == first
    (src / "polyroots.c").write_text((src / "polyroots.c").read_text() + "\n/* a fix */\n")
    lib = build(str(src), "polyroots", None)
    assert NOTICE in capfd.readouterr().err
    assert len(list(cache.glob("kernel-polyroots-*.so"))) == 2 and lib.gyro_poly_roots_batch


def test_the_kernel_key_covers_the_headers_the_dimension_the_flags_and_no_model():
    cc = "gcc"
    sources = tuple(cbackend.CSRC / f for f in cbackend.KERNELS["qep"])
    headers = tuple(sorted(cbackend.CSRC.glob("*.h")))
    key = cbackend._key(cc, sources, headers, ("-DQEP_N=4",))
    assert key == cbackend._key(cc, sources, headers, ("-DQEP_N=4",))
    assert key != cbackend._key(cc, sources, headers, ("-DQEP_N=3",))
    assert key != cbackend._key("clang", sources, headers, ("-DQEP_N=4",))
    assert key != cbackend._key(cc, sources, headers[1:], ("-DQEP_N=4",))  # a header is part of it
    # what gyro.cbackend builds for a model of dimension 4: these files and that macro alone
    assert {p.name for p in headers} == {"kernels.h", "qep_common.h"}


def _stub(name, directory, n, form):
    """A model as the kernels see it: the operator's shape and its real form."""
    meta = {"functions": {"operator": {"outputs": [{"name": "M", "shape": [n, n]}]}}, "operator_real_form": form}
    return SimpleNamespace(name=name, directory=directory, meta=meta)


def test_two_models_of_one_dimension_share_one_kernel_build(monkeypatch, tmp_path, capfd):
    """Two models of dimension 4 (one with a real form, one without) take one library,
    compiled once, and answer as the gyrohorizoncompass's own kernels (dimension 4) do."""
    from gyro import load, qep
    from gyro.equilibrium import equilibria, operators

    hc = load("gyrohorizoncompass")
    P = np.tile(hc.vector(hc.defaults), (9, 1))
    P[:, 0] *= np.linspace(0.5, 2.0, 9)
    M, D, K = operators(hc, P, equilibria(hc, P)[0])
    herm, w0, z0 = qep.block_starts(hc, M, D, K, np.ones(len(P), bool))
    assert herm.all()
    want = cbackend.QepRefine("gyrohorizoncompass")(M, D, K, w0, z0, 3, 1e-10)
    cache = _uncached(monkeypatch, tmp_path)
    capfd.readouterr()
    models = {"a": _stub("a", tmp_path / "a", 4, [0, 1, 0, 1]), "b": _stub("b", tmp_path / "b", 4, None)}
    monkeypatch.setattr(cbackend, "load", models.__getitem__)
    a, b = cbackend.QepRefine("a"), cbackend.QepRefine("b")
    assert capfd.readouterr().err.count(NOTICE) == 1
    assert len(list(cache.glob("kernel-qep-n4-*.so"))) == 1 and not list(cache.glob("a-*.so"))
    assert a.group.tolist() == [0, 1, 0, 1] and b.group is None
    for got in (a(M, D, K, w0, z0, 3, 1e-10), b(M, D, K, w0, z0, 3, 1e-10)):
        assert all(x.tobytes() == y.tobytes() for x, y in zip(got, want))


def test_a_real_form_that_is_not_one_group_per_coordinate_is_refused(monkeypatch, tmp_path):
    _uncached(monkeypatch, tmp_path)
    models = {"short": _stub("short", tmp_path, 3, [0, 1]), "odd": _stub("odd", tmp_path, 3, [0, 2, 1])}
    monkeypatch.setattr(cbackend, "load", models.__getitem__)
    for name in models:
        with pytest.raises(ValueError, match="operator_real_form"):
            cbackend.QepRefine(name)


def test_two_processes_compiling_one_kernel_at_once_both_load_a_whole_library(tmp_path):
    """Each compiles into a folder of its own and renames into place (gyro.cbackend._build):
    both load the library, one sealed library is left, and a third process loads it
    without compiling."""
    env = dict(os.environ, GYRO_CACHE=str(tmp_path / "cache"))
    code = ("from gyro import cbackend; lib = cbackend.kernel_library('qep', 2); "
            "print(bool(lib.gyro_qep_refine_batch))")
    run = lambda: subprocess.Popen([sys.executable, "-c", code], env=env, cwd=ROOT,  # noqa: E731
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    procs = [run(), run()]
    outs = [p.communicate(timeout=300) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [e for _, e in outs]
    assert [o.strip() for o, _ in outs] == ["True", "True"]
    assert any(NOTICE in e for _, e in outs)
    (so,) = (tmp_path / "cache").glob("kernel-qep-n2-*.so")
    assert cbackend._intact(so) and {p.name for p in so.parent.iterdir()} == {so.name, so.with_suffix(".sha256").name}
    third = run()
    out, err = third.communicate(timeout=300)
    assert third.returncode == 0 and out.strip() == "True" and err == ""


def test_without_a_compiler_every_kernel_falls_back_and_the_answers_are_numpys(tmp_path):
    """CC naming no compiler: no library is built, every kernel is None to its callers, and
    the default method and the polynomial roots give, to the bit, what they give under
    cbackend.disabled() (the NumPy paths)."""
    code = """
import json, numpy as np
from gyro import cbackend, ladder, load, roots
from gyro.kernels import compiled
m = load("gyrohorizoncompass")
P = np.tile(m.vector(m.defaults), (3, 1)); P[:, 0] *= [0.5, 1.0, 2.0]
kinds = [compiled(k, m) for k in (cbackend.qep_refine, cbackend.qep_block_starts, cbackend.qep_hermitian,
                                  cbackend.sens_null_vectors, cbackend.sens_contract, cbackend.poly_roots)]
s = ladder.spectrum(m, P, "default")
z = roots.roots(np.array([[2.0, -3.0, 1.0], [1.0, 0.0, 1.0]]), m)[0]
print(json.dumps({"none": all(k is None for k in kinds), "f": s.frequencies.tolist(),
                  "e": s.error_estimate.tolist(), "z": [[x.real, x.imag] for x in z.ravel()]}))
"""
    env = dict(os.environ, GYRO_CACHE=str(tmp_path / "cache"), CC=str(tmp_path / "no-such-cc"))
    proc = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    got = json.loads(proc.stdout)
    assert got["none"] and not (tmp_path / "cache").exists()
    from gyro import ladder, load, roots

    m = load("gyrohorizoncompass")
    P = np.tile(m.vector(m.defaults), (3, 1))
    P[:, 0] *= [0.5, 1.0, 2.0]
    with cbackend.disabled():
        s = ladder.spectrum(m, P, "default")
        z = roots.roots(np.array([[2.0, -3.0, 1.0], [1.0, 0.0, 1.0]]), m)[0]
    assert got["f"] == s.frequencies.tolist() and got["e"] == s.error_estimate.tolist()
    assert got["z"] == [[x.real, x.imag] for x in z.ravel()]


def test_the_generated_c_holds_no_kernel_and_the_input_hash_none_of_their_sources():
    """The kernels live in gyro/csrc alone: no model's C defines one of their entry points,
    and no kernel source is among the files each model's input hash covers."""
    import re

    from derive.emit import machinery_files
    from gyro.catalog import available
    from tests.conftest import GENERATED

    assert not [f for f in machinery_files() if cbackend.CSRC in f.parents]
    entry = re.compile(r"\w+_(qep_refine|qep_block_starts|qep_hermitian|sens_null_vectors|sens_contract|poly_roots)_batch\b")
    for name in available():
        assert not entry.search((GENERATED / name / f"{name}.c").read_text()), name


def test_a_source_that_does_not_compile_says_so_once(tmp_path, monkeypatch, capsys):
    """A build that fails (a broken source, not a missing compiler) says so on stderr, once
    per process, and the caller's NumPy path answers: found when a NULL without its header
    made the certificate's count fall back to NumPy unseen."""
    from gyro import cbackend

    monkeypatch.setattr(cbackend, "cache_dir", lambda: tmp_path)
    src = tmp_path / "broken.c"
    src.write_text("double f(void) { return undeclared_name; }\n")
    for _ in range(2):
        with pytest.raises(cbackend.CompilerUnavailable):
            cbackend._shared("broken", (src,), (), notice="the generated C of a broken test source")
    err = capsys.readouterr().err
    assert err.count("failed (") == 1 and "undeclared_name" in err and "NumPy paths answer" in err
