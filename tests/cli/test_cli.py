"""The command-line contract of `gyro frequencies` (exact names, keys, units, exit codes)."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT, error_lines, run_cli

NAMES = "m M l l1 l2 A C I1 I2 I3 K0 Kp Kgamma H u phi g h cp c0 cgamma".split()


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
    (["--set", "Kp=-1"], "Kp"),
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


def test_json_is_strict():
    """No NaN or Infinity: a strict parser reads every output, including the edges."""
    for sets in ([], ["--set", "g=0"], ["--set", "u=0"], ["--set", "phi=90"], ["--set", "H=0"]):
        r = gyro("frequencies", "torsion_gyrocompass", "--json", *sets)
        assert r.returncode == 0, (sets, r.stderr)
        json.loads(r.stdout, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))


@pytest.mark.parametrize("value", ["H=1e300", "m=1e300", "l=1e-300", "Kgamma=1e300"])
def test_valid_but_numerically_impossible_input_fails_in_one_line(value):
    """Finite, positive, but beyond double precision: one line, exit 1, no traceback.
    The contract (gyro/cli.py main): the values pass validation, so not the usage error 2;
    the solvers then meet an overflow (a frequency is not finite) or a singular matrix,
    which is the numerical failure, exit 1. Exit 0 would mean printing numbers that double
    precision cannot represent, which the strict JSON test above forbids."""
    r = gyro("frequencies", "torsion_gyrocompass", "--json", "--set", value)
    assert r.returncode == 1, (r.returncode, r.stderr)
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert "Traceback" not in r.stderr and len(lines) == 1
    assert lines[0].startswith("gyro: error: numerical failure at these parameters")


@pytest.mark.parametrize("name", ["torsion_gyrocompass.numpy_functions", "__init__", "..", "TORSION_GYROCOMPASS"])
def test_only_generated_models_are_models(name):
    r = gyro("frequencies", name)
    assert r.returncode == 2 and "unknown model" in r.stderr and "Traceback" not in r.stderr


def test_an_instability_is_reported_not_hidden():
    """Without gravity (g = 0) the Earth's rotation drives a divergent drift: a real pair
    +-sigma of order u. The JSON keeps its growing member (eigenvalues_re > 0)."""
    r = gyro("frequencies", "torsion_gyrocompass", "--json", "--set", "g=0")
    out = json.loads(r.stdout)
    growth = max(out["eigenvalues_re"])
    u = out["params"]["u"]
    assert 0.01 * u < growth < 10 * u  # 1.1e-5 = 0.15 u


def test_modal_result_saves_and_loads_itself(tmp_path):
    from gyro import load
    from gyro.ladder import natural_frequencies
    from gyro.results import ModalResult

    m = load("torsion_gyrocompass")
    r = natural_frequencies(m, m.parameters({"phi": 45.0}))
    r.save(tmp_path / "modes.json")
    back = ModalResult.load(tmp_path / "modes.json")
    assert back == r and back.frequencies[1] == r.frequencies[1] and back.params["phi"] == 45.0


def test_found_in_review_cli(tmp_path):
    """A range may start at a negative number written with an exponent; campbell needs a
    spin to sweep (exit 2, not a numerical failure); a sweep's JSON holds null where a
    value could not be computed; the formulas give no stability verdict."""
    from gyro.cli import main as gyro_main

    r = gyro("stability-map", "torsion_gyrocompass", "--x", "l2", "--x-range", "-1e-4", "1e-4", "--y", "H",
             "--y-range", "0.1", "1", "--points", "2", "--out", str(tmp_path / "m.png"), "--quiet")
    assert r.returncode == 0, r.stderr
    r = gyro("campbell", "gyrohorizoncompass", "--out", str(tmp_path / "c.png"))
    assert r.returncode == 2 and "declares no spin parameter" in r.stderr
    r = gyro("sweep", "torsion_gyrocompass", "--x", "H", "--x-range", "1", "1e12", "--x-log", "--points", "3", "--json")
    doc = json.loads(r.stdout)
    assert r.returncode == 1 and None in doc["frequencies"][-1] and "no finite spectrum" in r.stderr
    r = gyro("frequencies", "torsion_gyrocompass", "--method", "formulas", "--json")
    assert json.loads(r.stdout)["stability"]["class"] == "unknown"
    assert callable(gyro_main)


def test_scene_takes_each_questions_own_options_and_refuses_the_others():
    """gyro scene registers the options each question declares (OPTIONS) and refuses, in one
    line naming what the question takes, one that the question asked does not take; its
    source names no question."""
    from gyro.cli import scene

    assert set(scene._question_options()) == {"modes", "horizon", "harmonic"}
    source = (ROOT / "gyro" / "cli" / "scene.py").read_text()
    assert not [q for q in ("frequencies", "motion", "forced", "stability") if f'"{q}"' in source]
    for args, says in ((["frequencies", "--horizon", "2"], "--horizon: not an option of the frequencies question "
                                                            "(it takes --modes)"),
                       (["stability", "--modes", "1"], "--modes: not an option of the stability question (it takes "
                                                       "none)"),
                       (["motion", "--harmonic", "1:1:1"], "--harmonic: not an option of the motion question (it "
                                                           "takes --horizon)")):
        rc, out, err = run_cli("scene", "torsion_gyrocompass", args[0], "--tol", "1e-3", *args[1:])
        assert rc == 2 and out == "" and error_lines(err) == [f"gyro: error: {says}"], err


@pytest.mark.parametrize("command, listed, not_listed", [
    ("frequencies", ["torsion_gyrocompass", "gyrohorizoncompass"], ["gimbal_gyroscope"]),
    ("sweep", ["torsion_gyrocompass"], ["gimbal_gyroscope"]),
    ("campbell", ["torsion_gyrocompass"], ["gimbal_gyroscope"]),
    ("unbalance", ["torsion_gyrocompass"], ["gimbal_gyroscope", "gyrohorizoncompass"]),
    ("scene", ["gimbal_gyroscope", "torsion_gyrocompass"], []),
])
def test_a_commands_help_lists_the_models_that_can_answer_it(command, listed, not_listed):
    """The MODEL list of a command's help holds the generated models that declare what it
    needs (an operator about a relative equilibrium, not one of momenta given as inputs; a
    spin; inputs; levels), and says what that is."""
    rc, out, _ = run_cli(command, "--help")
    assert rc == 0
    text = " ".join(out.split())
    models = text.split("one of: ", 1)[1].split(", or a model file", 1)[0].split(", ")
    assert set(listed) <= set(models) and not set(not_listed) & set(models), models
