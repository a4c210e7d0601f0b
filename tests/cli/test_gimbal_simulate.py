"""The command-line contract of `gyro simulate gimbal_gyroscope` (names, keys, exit codes)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from tests.conftest import run_cli


gyro = run_cli  # `gyro ARGS` in this process: (exit code, stdout, stderr)


def test_json_has_the_contract_keys():
    rc, out, err = gyro("simulate", "gimbal_gyroscope", "--t-end", "0.5", "--points", "7", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert set(d) == {"t", "theta", "psi", "phi", "method", "integrals"}
    assert d["method"] == "closed_form" and set(d["integrals"]) == {"H", "L", "M"}
    assert d["t"][0] == 0.0 and d["t"][-1] == 0.5
    assert all(len(d[k]) == 7 and all(isinstance(x, float) for x in d[k]) for k in ("t", "theta", "psi", "phi"))


def test_set_initial_conditions_and_integrals_at_t0():
    """H = A3 (phi' + psi' cos theta), L = A0 psi' + H cos theta, M of (1.2) at t = 0."""
    rc, out, _ = gyro("simulate", "gimbal_gyroscope", "--t-end", "1", "--points", "2", "--json",
                      "--set", "theta0=0.9", "--set", "dpsi0=2", "--set", "dphi0=50", "--set", "dtheta0=0.5")
    d = json.loads(out)
    assert rc == 0 and d["theta"][0] == 0.9
    c = math.cos(0.9)
    H = 0.01 * (50 + 2 * c)
    assert math.isclose(d["integrals"]["H"], H, rel_tol=1e-14)
    assert math.isclose(d["integrals"]["L"], 0.02 * 2 + H * c, rel_tol=1e-14)
    G = 5 * 0.01 + 10 * 0.02
    M = 0.02 * 4 + 0.015 * 0.25 + 2 * 5 * 0.002 * math.sin(0.9) + 2 * G * c
    assert math.isclose(d["integrals"]["M"], M, rel_tol=1e-14)


@pytest.mark.parametrize("method", ["DOP853", "cvodes"])
def test_integrators_agree_with_the_closed_form(method):
    """At the CLI tolerances (rtol 1e-10) over 1 s (17 periods): 1e-6 rad."""
    base = ("simulate", "gimbal_gyroscope", "--t-end", "1", "--points", "11", "--json")
    cf = json.loads(gyro(*base)[1])
    it = json.loads(gyro(*base, "--method", method)[1])
    assert it["method"] == method
    for k in ("theta", "psi", "phi"):
        assert np.max(np.abs(np.array(cf[k]) - it[k])) < 1e-6


def test_C0_nonzero_needs_an_integrator():
    rc, _, err = gyro("simulate", "gimbal_gyroscope", "--t-end", "1", "--set", "C0=0.003")
    assert rc == 2 and "C0" in err and len(err.strip().splitlines()) == 1
    rc, out, _ = gyro("simulate", "gimbal_gyroscope", "--t-end", "1", "--points", "3", "--json",
                      "--set", "C0=0.003", "--method", "Radau")
    assert rc == 0 and json.loads(out)["method"] == "Radau"


@pytest.mark.parametrize("args, name", [
    (["--set", "foo=1"], "foo"),
    (["--set", "A0=abc"], "A0"),
    (["--set", "B0=0"], "B0"),
    (["--set", "theta0=nan"], "theta0"),
    (["--set", "dphi0=inf"], "dphi0"),
    (["--set", "dpsi0=x"], "dpsi0"),
    (["--set", "P=-1"], "P"),
    (["--t-end", "0"], "--t-end"),
    (["--t-end", "-3"], "--t-end"),
    (["--t-end", "inf"], "--t-end"),
    (["--points", "1"], "--points"),
    (["--points", "2.5"], "--points"),
    (["--method", "euler"], "--method"),
])
def test_bad_input_is_one_line_naming_it_exit_2(args, name, tmp_path):
    out = tmp_path / "x.png"
    argv = ["simulate", "gimbal_gyroscope", "--t-end", "1", *args, "--out", str(out)]
    rc, _, err = gyro(*argv)
    assert rc == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and name in lines[0] and "Traceback" not in err
    assert not out.exists() and not list(tmp_path.iterdir())


def test_out_writes_a_png(tmp_path):
    out = tmp_path / "motion.png"
    rc, _, _ = gyro("simulate", "gimbal_gyroscope", "--t-end", "0.3", "--points", "50", "--out", str(out))
    assert rc == 0 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["motion.png"]


def test_human_output_and_missing_t_end():
    rc, out, _ = gyro("simulate", "gimbal_gyroscope", "--t-end", "1")
    assert rc == 0 and "motion: periodic" in out and "H =" in out
    rc, _, err = gyro("simulate", "gimbal_gyroscope")
    assert rc == 2 and "--t-end" in err
