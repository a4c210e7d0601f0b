"""The command-line contract of `gyro frequencies` (exact names, keys, units, exit codes)."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT

NAMES = "m M l l1 l2 A C I1 I2 I3 K0 Kp Kgamma H u phi g".split()


def gyro(*args):
    return subprocess.run([sys.executable, "-m", "gyro", *args], cwd=ROOT, capture_output=True, text=True)


def test_json_has_the_contract_keys_and_ten_ascending_frequencies():
    r = gyro("frequencies", "torsion_gyrocompass", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["model"] == "torsion_gyrocompass"
    assert list(out["params"]) == NAMES
    assert out["params"]["phi"] == 60.0 and out["params"]["m"] == 0.4
    f = out["frequencies"]
    assert len(f) == 10 and all(isinstance(x, float) for x in f) and f == sorted(f)


def test_set_overrides_and_phi_is_in_degrees():
    r = gyro("frequencies", "torsion_gyrocompass", "--json", "--set", "phi=0", "--set", "Kp=1e5")
    out = json.loads(r.stdout)
    assert out["params"]["phi"] == 0.0 and out["params"]["Kp"] == 1e5
    # omega5 = omega_p (3.7) exactly on the J' block: sqrt(Kp/m)
    assert min(abs(w - (1e5 / 0.4) ** 0.5) for w in out["frequencies"]) < 1e-6 * (1e5 / 0.4) ** 0.5


def test_human_output_lists_ten_frequencies():
    r = gyro("frequencies", "torsion_gyrocompass")
    assert r.returncode == 0
    rows = [ln for ln in r.stdout.splitlines() if ln.strip()[:2].strip().isdigit()]
    assert len(rows) == 10


@pytest.mark.parametrize("args, name", [
    (["--set", "foo=1"], "foo"),
    (["--set", "m=abc"], "m"),
    (["--set", "m=nan"], "m"),
    (["--set", "A=inf"], "A"),
    (["--set", "m=0"], "m"),
    (["--set", "M=-0.6"], "M"),
    (["--set", "l2=-1"], "l2"),
    (["--set", "I3=0"], "I3"),
    (["--set", "Kgamma=-5"], "Kgamma"),
    (["--set", "K0=0"], "K0"),
    (["--set", "phi=91"], "phi"),
    (["--set", "Kp"], "Kp"),
])
def test_bad_input_is_one_line_naming_the_parameter_exit_2(args, name):
    r = gyro("frequencies", "torsion_gyrocompass", *args)
    assert r.returncode == 2
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and "Traceback" not in r.stderr


def test_unknown_model_and_bad_command_exit_2():
    for args in (["frequencies", "no_such_model"], ["no_such_command"], ["frequencies"]):
        r = gyro(*args)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
