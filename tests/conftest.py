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


# Tiers (docs/architecture.md): a test file's folder is its tier, and the tier its marker, so
# that `pytest -m unit` (make test-unit) runs the fast tier alone; `make test` runs them all.
TIERS = {
    "unit": "the machinery and the runtime's shape, fast",
    "generated": "the emitted code against the symbolic result, every backend",
    "paper": "the papers' printed numbers and formulas, and the models' physics",
    "methods": "the ladder of frequency methods against each other",
    "properties": "hypothesis properties over physical ranges",
    "cli": "the command-line contract",
}


def _tested_tree_is_this_one() -> None:
    """The gyro package and its generated code that the tests import are this checkout's:
    an environment installed (editable) from another checkout, a git worktree's say, maps
    gyro.generated to that checkout's generated/, and the tests would pass or fail on code
    that is not the one in front of them."""
    import gyro
    import gyro.generated

    where = {"gyro": Path(gyro.__file__).resolve().parent, "gyro.generated": Path(list(gyro.generated.__path__)[0]).resolve()}
    want = {"gyro": (ROOT / "gyro").resolve(), "gyro.generated": GENERATED.resolve()}
    wrong = [f"{k} from {where[k]}" for k in where if where[k] != want[k]]
    if wrong:
        raise pytest.UsageError(f"the tests of {ROOT} import {', '.join(wrong)}: install this checkout "
                                f"(make setup in it, or pip install -e {ROOT}) before testing it")


def pytest_sessionstart(session):
    """The code under test is this checkout's; every generated model's C compiled once
    before the tests (in the controlling process only): the command-line tests hold stderr
    to one line, and the first use of a library after its C changed says on stderr that it
    compiles it."""
    _tested_tree_is_this_one()
    if hasattr(session.config, "workerinput"):
        return
    from gyro import cbackend
    from gyro.catalog import available

    for name in available():
        try:
            cbackend.library(name)
            cbackend.kernel_libraries(name)  # gyro/csrc, once per operator dimension
        except cbackend.CompilerUnavailable:
            pass  # the tests that need the compiler say so themselves


def pytest_collection_modifyitems(config, items):
    for item in items:
        path = Path(str(item.fspath)).resolve()
        tier = path.parent.name if path.parent.parent == ROOT / "tests" else None
        if tier not in TIERS:
            raise pytest.UsageError(f"{path.name} belongs to no tier: put it in a folder tests/TIER/ "
                                    f"(TIER one of {', '.join(TIERS)})")
        item.add_marker(getattr(pytest.mark, tier))


@pytest.fixture(scope="session")
def tg_model():
    return derived(MODEL)[0]


@pytest.fixture(scope="session")
def tg_derivation():
    return derived(MODEL)[1]


@pytest.fixture(scope="session")
def tg_functions():
    return derived(MODEL)[2]


NOTICES = ("gyro: deriving ", "gyro: compiling the generated C")  # models.py: _Notice, cbackend


def error_lines(err: str) -> list[str]:
    """stderr's lines but a model's first-use notices (deriving a model file, compiling its
    C), which a cold cache prints before the command's own line."""
    return [ln for ln in err.strip().splitlines() if not ln.startswith(NOTICES)]


def run_cli(*args):
    """`gyro ARGS` in this process: (exit code, stdout, stderr); argparse's usage errors too."""
    import io
    from contextlib import redirect_stderr, redirect_stdout

    from gyro.cli import main

    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            rc = main(list(args))
        except SystemExit as exc:
            rc = exc.code
    return rc, out.getvalue(), err.getvalue()


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


# the derivations live in one module: pytest imports this file as `conftest` and the test
# files import it again as `tests.conftest`, two module objects with a cache each, which
# derived the torsion gyrocompass twice per process
from tests.derivations import derived  # noqa: E402,F401
