"""The derivation's process imports no NumPy (derive.mechanics withholds it from symengine's
import, which would take it for Lambdify alone) and, with one job, none of the workers'
modules (derive.parallel imports them where workers are used): 0.06-0.1 s and 0.01-0.02 s
of CPU that the smallest models' whole derivation (0.02 s) cannot win back against SymPy's
own method (bench/sympy_systems.py). The equations are the same either way."""
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

SCRIPT = """
import importlib.util, io, json, sys
from derive import pipeline
assert "numpy" not in sys.modules, "NumPy imported with the derivation"
assert "multiprocessing" not in sys.modules, "the workers' modules imported with one job"
sys.path.insert(0, {folder!r})
spec = importlib.util.spec_from_file_location("_m", {path!r})
mod = importlib.util.module_from_spec(spec)
spec.loader.exec_module(mod)
d = pipeline.derive(mod.build(), pipeline.Steps(out=io.StringIO()))
import symengine.lib.symengine_wrapper as w
print(json.dumps({{"numpy": "numpy" in sys.modules, "have_numpy": w.have_numpy,
                  "M": str(d.mass_matrix), "f": str(d.forcing), "K": str(d.operator.K)}}))
"""


def _derive_fresh(name):
    path = ROOT / "tests" / "models" / f"{name}.py"
    out = subprocess.run([sys.executable, "-c", SCRIPT.format(folder=str(path.parent), path=str(path))],
                         capture_output=True, text=True, cwd=ROOT, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_derivation_without_numpy_gives_the_same_equations():
    import io
    import importlib.util

    import numpy  # noqa: F401  (this process has it: symengine keeps its NumPy support here)
    from derive import pipeline

    fresh = _derive_fresh("disc_incline")
    assert fresh["numpy"] is False and fresh["have_numpy"] is False
    path = ROOT / "tests" / "models" / "disc_incline.py"
    spec = importlib.util.spec_from_file_location("_disc_incline_here", path)
    mod = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(path.parent))
    try:
        spec.loader.exec_module(mod)
        d = pipeline.derive(mod.build(), pipeline.Steps(out=io.StringIO()))
    finally:
        sys.path.remove(str(path.parent))
    assert fresh["M"] == str(d.mass_matrix) and fresh["f"] == str(d.forcing) and fresh["K"] == str(d.operator.K)
