"""docs/api.md runs as written (its Python session by doctest, numbers to 1e-9; its C
program compiled and run), and examples/gyrocompass.ipynb runs cell by cell."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys

from tests.conftest import ROOT
from tests.generated.test_docs_models import blocks, expected_pattern, shell_session

DOC = ROOT / "docs" / "api.md"
NOTEBOOK = ROOT / "examples" / "gyrocompass.ipynb"


def test_the_api_page_runs_as_written(tmp_path):
    env = dict(os.environ, GYRO_CACHE=str(tmp_path / "cache"))
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "generated" / "test_docs_models.py"), "--run", str(tmp_path), str(DOC)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]


def test_the_c_program_of_the_api_page_compiles_and_prints_what_it_shows(tmp_path):
    text = DOC.read_text()
    (c_source,) = [body for lang, body in blocks(text) if lang == "c"]
    (tmp_path / "example.c").write_text(c_source)
    (command, lines), = [c for lang, body in blocks(text) if lang == "console" for c in shell_session(body)]
    proc = subprocess.run(command.replace("generated/", f"{ROOT}/generated/"), shell=True, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert expected_pattern(lines).fullmatch(proc.stdout), proc.stdout


def test_the_notebook_runs(tmp_path):
    nb = json.loads(NOTEBOOK.read_text())
    cells = ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]
    assert len(cells) >= 3
    import matplotlib

    matplotlib.use("Agg")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        namespace = {"__name__": "__main__"}
        for k, source in enumerate(cells):
            exec(compile(source, f"{NOTEBOOK.name}[cell {k}]", "exec"), namespace)
    finally:
        os.chdir(cwd)
        import matplotlib.pyplot as plt

        plt.close("all")
    assert (tmp_path / "campbell.png").exists() and (tmp_path / "stability_map.png").exists()
    assert namespace["exact"].frequencies.shape == (60, 10)
    assert re.search(r"stable", str(namespace["grid"].counts()))
