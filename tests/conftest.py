"""Shared fixtures: the derivation (run once per session) and the compiled C library."""
from __future__ import annotations

import ctypes
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated"
MODEL = "torsion_gyrocompass"


@pytest.fixture(scope="session")
def tg_model():
    from derive.models import torsion_gyrocompass as tg

    return tg.build()


@pytest.fixture(scope="session")
def tg_derivation(tg_model):
    import io

    from derive import pipeline

    return pipeline.derive(tg_model, pipeline.Steps(out=io.StringIO()))


@pytest.fixture(scope="session")
def tg_functions(tg_derivation):
    from derive import pipeline

    return {f.name: f for f in pipeline.functions(tg_derivation)}


def compile_c(model: str, tmp: Path) -> ctypes.CDLL:
    """Compile the generated C of a model with -Wall -Wextra -Werror into a shared library."""
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.fail("no C compiler found: install gcc to build and test the generated C")
    src = GENERATED / model / f"{model}.c"
    lib = tmp / f"lib{model}.so"
    cmd = [cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "-shared", "-fPIC",
           "-o", str(lib), str(src), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        pytest.fail(f"gcc failed on {src.name}:\n{proc.stderr}")
    return ctypes.CDLL(str(lib))


@pytest.fixture(scope="session")
def tg_clib(tmp_path_factory):
    return compile_c(MODEL, tmp_path_factory.mktemp("clib"))
