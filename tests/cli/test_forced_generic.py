"""`gyro forced` for any model that declares its spin angle (issue: one runtime that knows no
model by name): tests/models/wavy_rotor.py, a Jeffcott rotor on wavy bearing races written
outside the package, against the hand solution of m x'' + c x' + k x = a sin(w t + p):
x = a/|k - m w^2 + i c w| sin(w t + p - atan2(c w, k - m w^2)). The linear solve errs by a
few eps of the condition number (about 30 here): 1e-12 relative is three orders above it."""
from __future__ import annotations

import json
import math

import pytest

from tests.conftest import ROOT, error_lines, run_cli

WAVY = str(ROOT / "tests" / "models" / "wavy_rotor.py")
M, KX, KY, C, OMEGA = 12.0, 2.0e6, 3.0e6, 150.0, 200.0


def _hand(k_stiff, c, w, a, p):
    re, im = k_stiff - M * w**2, c * w
    return a / math.hypot(re, im), p - math.atan2(im, re)


def _wrap(a):
    return math.pi - (math.pi - a) % (2 * math.pi)


def test_the_wavy_rotor_answers_as_by_hand():
    rc, out, err = run_cli("forced", WAVY, "--harmonic", "1:2:0.5:0.3", "--harmonic", "2:1:0.1", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["coordinates"] == ["x", "y"] and doc["spin_rate"] == pytest.approx(OMEGA, rel=1e-15)
    h1, h2 = doc["harmonics"]
    amp, ph = _hand(KX, C, 2 * OMEGA, 0.5, 0.3)
    assert h1["frequency"] == pytest.approx(2 * OMEGA, rel=1e-15)
    assert h1["amplitudes"][0] == pytest.approx(amp, rel=1e-12)
    assert h1["phases"][0] == pytest.approx(_wrap(ph), abs=1e-12)
    # f1 acts along x only: y is not reached, so it has amplitude 0 and no phase
    assert h1["amplitudes"][1] == 0.0 and h1["phases"][1] is None
    amp, ph = _hand(KY, C, OMEGA, 0.1, 0.0)
    assert h2["amplitudes"][1] == pytest.approx(amp, rel=1e-12)
    assert h2["phases"][1] == pytest.approx(_wrap(ph), abs=1e-12)
    assert h2["amplitudes"][0] == 0.0 and h2["phases"][0] is None


def test_an_undamped_harmonic_on_a_natural_frequency_is_a_resonance():
    """c = 0 and 2 Omega = sqrt(kx/m): the amplitude is infinite (null), the mode named, and
    the text says RESONANCE; a hair away from it the amplitude is finite and large."""
    omega = math.sqrt(KX / M) / 2
    rc, out, err = run_cli("forced", WAVY, "--harmonic", "1:2:0.5", "--set", "c=0", "--set", f"Omega={omega!r}",
                           "--json")
    assert rc == 0, err
    (h,) = json.loads(out)["harmonics"]
    assert h["resonance"] and h["amplitudes"][0] is None and h["nearest_mode"] == 1
    rc, out, err = run_cli("forced", WAVY, "--harmonic", "1:2:0.5", "--set", "c=0", "--set", f"Omega={omega * 1.001!r}")
    assert rc == 0, err
    assert "RESONANCE" not in out and "race waviness" in out and "a = 0.5 N" in out


@pytest.mark.parametrize("args, words", [
    (("forced", "gimbal_gyroscope", "--harmonic", "1:1:1"), "gimbal_gyroscope declares no spin angle"),
    (("forced", WAVY, "--harmonic", "3:1:1"), "S (the index of f_s) must be 1 or 2, got '3'"),
    (("forced", WAVY), "--harmonic: give at least one harmonic"),
])
def test_what_a_model_cannot_answer_is_one_line(args, words):
    rc, out, err = run_cli(*args)
    assert rc == 2 and out == ""
    (line,) = error_lines(err)
    assert words in line


def test_the_help_lists_the_models_that_declare_a_spin_angle():
    rc, out, _ = run_cli("forced", "--help")
    assert rc == 0
    text = " ".join(out.split())
    assert "one of: torsion_gyrocompass, or a model file" in text and "Model.spin 'angle'" in text


def test_a_spin_angle_that_turns_at_no_declared_rate_is_refused_at_derive_time():
    from types import SimpleNamespace

    from derive.model import Unsupported
    from derive.outputs import spin
    from tests.models import wavy_rotor

    model = wavy_rotor.build()
    model.spin = {**model.spin, "angle": "x"}
    with pytest.raises(Unsupported, match="angle 'x' turns at no declared rate"):
        spin.metadata(SimpleNamespace(model=model, order=["x", "y"]))
    model.spin = {**model.spin, "angle": "psi"}
    with pytest.raises(Unsupported, match="angle 'psi' is not a coordinate"):
        spin.metadata(SimpleNamespace(model=model, order=["x", "y"]))
