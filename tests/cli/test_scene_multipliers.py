"""`gyro scene` on a model whose constraint is carried by a multiplier: tests/models/hoop_bead.py
(a bead held on a turning hoop by x^2 + y^2 = R^2) declares the exact operator as its level,
the linearisation in the independent coordinate x on the hoop, by a method of the ladder.
At the bottom the bead oscillates at omega^2 = g/R - Omega^2 for Omega^2 < g/R and leaves it,
growing at sqrt(Omega^2 - g/R), beyond (the hand formula of the model's docstring).

Tolerance: the hand formula in double precision errs by a few ulps (a quotient, a
difference of numbers of order 10-50 whose result is of the same order, a square root), so
the answer must lie within its own error bound plus 1e-15 of it; a wrong operator (a lost
multiplier term, the stiffness without lambda0's curvature of the constraint: omega^2 =
-Omega^2) is off by far more."""
from __future__ import annotations

import json

import numpy as np
import pytest

from tests.conftest import ROOT, error_lines, run_cli

HOOP = str(ROOT / "tests" / "models" / "hoop_bead.py")
G, R = 9.81, 0.2  # the model's defaults


@pytest.mark.parametrize("omega_hoop", [3.0, 6.5])
def test_scene_answers_the_frequency_of_a_bead_held_by_a_multiplier(omega_hoop):
    rc, out, err = run_cli("scene", HOOP, "frequencies", "--tol", "1e-9", "--set", f"Omega={omega_hoop}", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["level"].startswith("linear_exact:") and doc["quantities"] == ["omega1"]
    (w,), (bound,) = doc["frequencies"], doc["error_bound"]
    hand = np.sqrt(G / R - omega_hoop**2)
    assert bound <= 1e-9 and abs(w - hand) <= (bound + 1e-15) * hand


def test_scene_says_the_bead_leaves_the_bottom_beyond_the_critical_rate():
    rc, out, err = run_cli("scene", HOOP, "stability", "--tol", "1e-6", "--set", "Omega=8", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["stability"]["class"] == "unstable" and doc["stability"]["unstable_roots"] == 1
    hand = np.sqrt(8.0**2 - G / R)
    assert abs(doc["stability"]["growth_rate"] - hand) <= (doc["error_bound"][0] + 1e-15) * hand


def test_the_40_digit_reference_method_takes_a_model_with_multipliers():
    """The reference rung solved its 40-digit equilibrium in the reduced coordinates only
    ('y' is not in list); it takes the equilibrium system on the constraint, as the double
    methods do."""
    rc, out, err = run_cli("frequencies", HOOP, "--method", "reference", "--json")
    assert rc == 0, error_lines(err)
    (w,) = json.loads(out)["frequencies"]
    hand = np.sqrt(G / R - 3.0**2)
    assert abs(w - hand) <= 1e-15 * hand
