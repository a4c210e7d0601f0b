"""The wheel: built from the repository, installed into a fresh virtual environment, it
answers from any folder with the generated models, their C and metadata inside it, and
installs no top-level `derive` or `generated` (the build-time package stays behind)."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile

import pytest

from tests.conftest import ROOT


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    # built from a copy of the sources: setuptools writes build/ into the tree it builds, and
    # two workers of the parallel suite, each with one test of this module, built into the
    # same build/ at once (a file vanished under the other's copy)
    src = tmp / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "__pycache__",
                                                             ".pytest_cache"))
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "-q", "-w", str(tmp / "dist")],
                          capture_output=True, text=True, cwd=tmp)
    assert proc.returncode == 0, proc.stderr[-2000:]
    (wheel,) = (tmp / "dist").glob("gyro_dynamics-*.whl")
    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    py = venv / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", "-q", str(wheel)],
                   check=True, capture_output=True)
    # the dependencies (numpy, scipy, ...) from this interpreter's environment, as a plain
    # path: its editable install of the repository is not activated there
    site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                          capture_output=True, text=True, check=True).stdout.strip()
    with open(os.path.join(site, "_deps.pth"), "w") as fh:
        fh.write(sysconfig.get_path("purelib") + "\n")
    env = dict(os.environ, GYRO_CACHE=str(tmp / "cache"), PYTHONPATH="")
    return wheel, venv, env, tmp


def test_the_wheel_carries_the_runtime_and_the_generated_models_only(installed):
    wheel, *_ = installed
    names = zipfile.ZipFile(wheel).namelist()
    for model in ("torsion_gyrocompass", "gimbal_gyroscope"):
        for f in ("metadata.json", f"{model}.c", f"{model}.h", "numpy_functions.py", "mpmath_functions.py"):
            assert f"gyro/generated/{model}/{f}" in names, f
    assert not [n for n in names if n.startswith(("derive/", "generated/", "tests/", "bench/"))]
    # the kernels' C sources, compiled on the user's machine once per operator dimension
    from gyro import cbackend

    sources = {f.name for f in cbackend.CSRC.iterdir() if f.suffix in (".c", ".h")}
    assert {f for fs in cbackend.KERNELS.values() for f in fs} <= sources
    assert sorted(f"gyro/csrc/{f}" for f in sources if f"gyro/csrc/{f}" not in names) == []
    assert any(n.endswith(".dist-info/licenses/LICENSE") or n.endswith("LICENSE") for n in names)


def test_the_installed_tool_answers_outside_the_repository(installed):
    _, venv, env, tmp = installed
    run = lambda *a: subprocess.run([str(venv / "bin" / "gyro"), *a], capture_output=True, text=True, cwd=tmp, env=env)  # noqa: E731
    p = run("params", "torsion_gyrocompass")
    assert p.returncode == 0 and p.stdout.splitlines()[1].startswith("m "), p.stderr
    f = run("frequencies", "torsion_gyrocompass", "--json")
    assert f.returncode == 0, f.stderr
    doc = json.loads(f.stdout)
    from gyro import ladder, load

    here = load("torsion_gyrocompass")
    want = ladder.spectrum(here, here.vector(here.defaults)).frequencies[0]
    assert doc["frequencies"] == [float(w) for w in want]  # the same C from the same source
    probe = subprocess.run([str(venv / "bin" / "python"), "-c",
                            "import importlib.util as u, gyro; print(u.find_spec('derive'), u.find_spec('generated'), gyro.__file__)"],
                           capture_output=True, text=True, cwd=tmp, env=env)
    none_derive, none_generated, where = probe.stdout.split()
    assert none_derive == "None" and none_generated == "None" and str(venv) in where
