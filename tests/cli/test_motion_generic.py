"""`gyro simulate MODEL` for any model (gyro/analyses/motion.py): the emitted nonlinear
equations from the reference of the set (derive/outputs/reference.py), offsets by name, on
model files written outside the package.

Tolerances: DOP853 at rtol 1e-10, atol 1e-12 over a few periods of a smooth motion errs by
about 1e-10 of its amplitude; the damped oscillator's closed form is held to 1e-8 of the
offset, two orders above."""
from __future__ import annotations

import json

import numpy as np
import pytest

from tests.conftest import ROOT, run_cli, error_lines

MODELS = ROOT / "tests" / "models"
ROTOR = ROOT / "examples" / "rigid_rotor.py"


def test_the_damped_oscillator_moves_as_its_closed_form():
    rc, out, err = run_cli("simulate", str(MODELS / "damped_oscillator.py"), "--t-end", "3", "--points", "61",
                           "--perturb", "x=0.1", "--perturb", "x_d=-0.2", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    m, c, k = 2.0, 0.3, 50.0
    t = np.array(doc["t"])
    s, w = -c / (2 * m), np.sqrt(k / m - c**2 / (4 * m**2))
    x0, v0 = 0.1, -0.2
    want = np.exp(s * t) * (x0 * np.cos(w * t) + (v0 - s * x0) / w * np.sin(w * t))
    assert np.max(np.abs(np.array(doc["x"]) - want)) < 1e-8 * x0
    assert doc["method"] == "DOP853" and doc["coordinates"] == ["x"] and doc["units"] == {"x": "m"}
    assert doc["perturb"] == {"x": 0.1, "x_d": -0.2} and len(doc["rates"]["x_d"]) == 61


def test_at_the_reference_the_rotor_stays_there():
    """No offset: the rigid rotor on its bearings (examples/rigid_rotor.py) stays at its
    equilibrium, every coordinate within 1e-12 of its reference over 50 ms, but the spin
    angle phi, which turns steadily at Omega (its declared rate)."""
    rc, out, err = run_cli("simulate", str(ROTOR), "--t-end", "0.05", "--points", "11", "--set", "Omega=300",
                           "--json")
    assert rc == 0, err
    doc = json.loads(out)
    t = np.array(doc["t"])
    assert doc["rates"]["phi_d"][0] == 300.0
    for c in doc["coordinates"]:
        want = 300.0 * t if c == "phi" else doc[c][0]
        assert np.max(np.abs(np.array(doc[c]) - want)) < 1e-12 * max(1.0, np.max(np.abs(want))), c


def test_a_time_dependent_model_takes_its_time():
    """The Mathieu pendulum (explicit t in its equations) against its textbook equation
    integrated here, m l^2 theta'' + c theta' + m l (g - a w^2 sin(w t)) sin(theta) = 0
    (tests/models/mathieu_pendulum.py, its default parameters)."""
    from scipy.integrate import solve_ivp

    rc, out, err = run_cli("simulate", str(MODELS / "mathieu_pendulum.py"), "--t-end", "2", "--points", "21",
                           "--perturb", "theta=0.3", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    m, l, g, a, w, c = 0.5, 0.8, 9.81, 0.05, 7.0, 0.01

    def textbook(t, y):
        return [y[1], -(c * y[1] + m * l * (g - a * w**2 * np.sin(w * t)) * np.sin(y[0])) / (m * l**2)]

    sol = solve_ivp(textbook, (0, 2), [0.3, 0.0], method="DOP853", t_eval=np.array(doc["t"]), rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(sol.y[0] - np.array(doc["theta"]))) < 1e-8


@pytest.mark.parametrize("args, match", [
    (["--perturb", "nope=1"], "--perturb nope: not a coordinate of damped_oscillator"),
    (["--perturb", "x=1", "--perturb", "x=2"], "--perturb x: given twice"),
    (["--perturb", "x"], "--perturb 'x': expected NAME=VALUE"),
    (["--perturb", "x=inf"], "--perturb x"),
    (["--method", "Euler"], "--method: unknown method 'Euler'"),
    (["--level", "full"], "--level: not for damped_oscillator (a generic motion from the reference"),
    # 5 rad/s for 1e9 s: about 4e11 evaluations, refused before the start, naming the cost
    (["--t-end", "1e9"], "would need about 3.8e+11 evaluations of the equations, over its budget of 5e+06"),
])
def test_bad_input_is_one_line_exit_2(args, match):
    rc, out, err = run_cli("simulate", str(MODELS / "damped_oscillator.py"), "--t-end", "1", *args)
    assert rc == 2 and out == "" and match in err and len(error_lines(err)) == 1, err


def test_a_reference_of_given_momenta_is_refused_in_one_line():
    rc, out, err = run_cli("simulate", str(MODELS / "symmetric_top_euler.py"), "--t-end", "1")
    assert rc == 2 and out == "" and "stationary motion of given momenta (Lz, H)" in err


OWN = str(MODELS / "oscillator_own_motion.py")


def test_a_model_file_reaches_its_own_motion_through_its_declaration():
    """Model.simulate names a module outside the package: `gyro simulate` answers by its
    closed form, with its initial conditions as --set; `gyro params` lists them and the usage
    line; a flag its motion does not take is one line naming what it takes."""
    rc, out, err = run_cli("simulate", OWN, "--set", "x0=0.2", "--set", "v0=1", "--set", "k=8", "--t-end", "2",
                           "--points", "9", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    t, w = np.array(doc["t"]), 2.0  # sqrt(8/2)
    assert doc["method"] == "closed_form" and doc["params"]["k"] == 8.0
    assert np.max(np.abs(np.array(doc["x"]) - (0.2 * np.cos(w * t) + 0.5 * np.sin(w * t)))) < 1e-15
    rc, out, _ = run_cli("params", OWN)
    assert rc == 0
    assert "initial conditions (gyro simulate; the closed form's start):" in out and out.count("x' at t = 0") == 1
    assert out.rstrip().endswith("gyro simulate oscillator_own_motion: --set x0 v0; --method closed_form (the only one)")
    rc, out, err = run_cli("simulate", OWN, "--t-end", "1", "--perturb", "x=0.1")
    assert rc == 2 and out == ""
    (line,) = error_lines(err)
    assert "--perturb: not for oscillator_own_motion; its motion takes --method (--set x0 v0;" in line


GYROPENDULUM = str(MODELS / "gyropendulum.py")


@pytest.fixture(scope="module")
def gyropendulum():
    from gyro.analyses import motion as M
    from gyro.models import load

    model = load(GYROPENDULUM)
    return model, M.for_model(model)


def test_the_generic_reduced_motion_is_the_hand_linearisation(gyropendulum):
    """The reduced state's first-order matrix is A a'' + H b' + m g l a = 0,
    A b'' - H a' + m g l b = 0 written by hand, and the cyclic spin's rate is H/C less
    alpha' sin(beta) (the momentum C (psi' + alpha' sin beta) = H)."""
    model, G = gyropendulum
    v = model.defaults
    red = G.Motion(v).reduced
    A, H, k = v["A"], v["H"], v["m"] * v["g"] * v["l"]
    want = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-k / A, 0, 0, -H / A], [0, -k / A, H / A, 0]])
    assert np.max(np.abs(red.first_order - want)) <= 1e-14 * np.max(np.abs(want))
    y = red.state(np.array([0.1, 0.2]), np.array([0.3, -0.4]))
    assert y[3 + 2] == pytest.approx(H / v["C"] - 0.3 * np.sin(0.2), rel=1e-15)


def test_the_generic_linear_level_bounds_its_error(gyropendulum):
    """Over tilts 1e-4..0.6 rad and spins from weak to strong gyroscopic coupling (H 0.02..5),
    the linear level's estimate (twice the second Picard correction) is never beaten by its
    error against the full equations integrated at rtol 1e-11 (measured error/estimate 0.42..0.50
    on 35 such sets), and it is infinite, a refusal, where the correction leaves its reach
    (a large tilt over a long horizon)."""
    model, G = gyropendulum
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 1.0, 101)
    finite = 0
    for _ in range(6):
        amp, H = 10 ** rng.uniform(-4, np.log10(0.6)), 10 ** rng.uniform(np.log10(0.02), np.log10(5))
        mo = G.Motion({**model.defaults, "H": H}, alpha_0=amp * rng.uniform(-1, 1), beta_0=amp * rng.uniform(-1, 1),
                      alpha_d0=amp * rng.uniform(-3, 3))
        q, est = G.motion_answer(mo, t, "linear")
        ref, _ = G.motion_answer(mo, t, "DOP853", 1e-11)
        err = np.max(np.abs(q - ref), axis=0)
        assert np.all(err <= est), (amp, H, err, est)
        finite += bool(np.all(np.isfinite(est)))
    assert finite >= 4
    mo = G.Motion({**model.defaults, "H": 0.05}, alpha_0=0.6, beta_0=-0.3)
    assert np.all(np.isinf(G.motion_answer(mo, np.linspace(0.0, 10.0, 401), "linear")[1]))


def test_a_model_file_declares_a_motion_hierarchy_on_the_generic_levels():
    rc, out, err = run_cli("scene", GYROPENDULUM, "motion", "--tol", "1e-3", "--set", "alpha_0=0.01",
                           "--horizon", "2", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["level"] == "linear" and max(doc["error_bound"]) <= 1e-3  # the selector's promise
    assert len(doc["alpha"]) == 201 and doc["alpha"][0] == pytest.approx(0.01, rel=1e-15)
    rc, out, err = run_cli("scene", GYROPENDULUM, "motion", "--tol", "1e-3", "--set", "psi_0=1")
    assert rc == 2 and "psi_0" in err and len(error_lines(err)) == 1


def test_a_declared_file_module_is_found_beside_the_file_loaded_not_where_it_was_derived(tmp_path):
    """The derivation records a model file's own module relative to its folder
    (derive.model.runtime_module), and the runtime finds it beside the file it loads the
    model from. Before, the path was absolute: a derivation in the cache (keyed by the
    files' bytes and their paths inside the checkout) made in one checkout named that
    checkout, and failed from a fresh clone once the first was gone ("no file
    /work/.../oscillator_own_motion.py"): the cached metadata here is moved as such."""
    import shutil
    from pathlib import Path

    from gyro import models
    from gyro.catalog import declared_module
    from gyro.errors import ParameterError

    m = models.load(OWN)
    spec = m.meta["simulate"]["module"]
    assert spec == "file:oscillator_own_motion.py"
    assert m.source_folder == MODELS.resolve()
    # the same emitted folder loaded as a folder: the checkout's file its metadata names
    copy = tmp_path / m.name
    shutil.copytree(m.directory, copy, ignore=shutil.ignore_patterns("__pycache__", "*.so"))
    elsewhere = models.Model(m.name, copy)
    assert elsewhere.source_folder == MODELS.resolve()
    # and where no model file is known (an installed runtime): refused in one line
    elsewhere.source_folder = None
    with pytest.raises(ParameterError, match="load the model by its file PATH.py"):
        declared_module(spec, "its motion", elsewhere)
    # and beside another copy of the file, that copy's module
    (tmp_path / "oscillator_own_motion.py").write_text((MODELS / "oscillator_own_motion.py").read_text())
    elsewhere.source_folder = tmp_path
    assert Path(declared_module(spec, "its motion", elsewhere).__file__).parent == tmp_path
