"""Motions of models whose holonomic constraints are carried by Lagrange multipliers
(gyro/analyses/motion.py: Constraints, the start, the projection; docs/models.md): `gyro
simulate` starts on the constraints (the independent coordinates offset, the dependent ones
and their rates solved on the reference's branch) and stays on them (each sample's state
projected back, the correction within the integrator's tolerance, reported as
`constraint_residual`); `gyro scene MODEL motion` answers in the independent coordinates.

Tolerances: the generic motion integrates by DOP853 at rtol 1e-10, atol 1e-12; over a few
periods of a smooth motion it errs by some 1e-13 of its size (measured 4e-14 m on the
pendulum below, whose size is L = 0.5 m), held here to rtol itself of that size, L
1e-10. A state on the constraints is held to 1e-15 of phi's terms (phi's rounding: a few
ulps of R^2 = 0.04 is 2e-17; measured 2.1e-17 after 1000 s); before the projection the
index-1 form drifts off them by 1e-7 of the hoop's radius in 1000 s and by 4e-9 rad of the
four-bar's angles in 100 s."""
from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tests.conftest import ROOT, error_lines, run_cli

MODELS = ROOT / "tests" / "models"
RTOL = 1e-10  # gyro.analyses.motion.RTOL


def _simulate(model: str, *args):
    rc, out, err = run_cli("simulate", str(MODELS / f"{model}.py"), *args, "--json")
    assert rc == 0, error_lines(err)
    return json.loads(out)


def test_the_nonminimal_pendulum_swings_as_the_minimal_one():
    """q1^2 + q2^2 = L^2 with q2 (across gravity) offset by 0.1 m and its rate by 0.3 m/s:
    q1 = L cos theta, q2 = L sin theta with theta'' = -g/L sin theta from theta0 = asin(0.1/L),
    theta0' = 0.3/(L cos theta0). Before: q1 kept its reference L, the start 0.51 m from the
    pivot, and the bead swung on that circle."""
    L, g = 0.5, 9.8
    doc = _simulate("nonminimal_pendulum", "--t-end", "10", "--points", "201", "--perturb", "q2=0.1",
                    "--perturb", "q2_d=0.3")
    t = np.array(doc["t"])
    th0 = np.arcsin(0.1 / L)
    sol = solve_ivp(lambda _, y: [y[1], -g / L * np.sin(y[0])], (0, 10), [th0, 0.3 / (L * np.cos(th0))],
                    method="DOP853", t_eval=t, rtol=1e-13, atol=1e-15)
    th, thd = sol.y
    assert np.max(np.abs(np.array(doc["q1"]) - L * np.cos(th))) < RTOL * L
    assert np.max(np.abs(np.array(doc["q2"]) - L * np.sin(th))) < RTOL * L
    w = np.sqrt(g / L)
    assert np.max(np.abs(np.array(doc["rates"]["q1_d"]) + L * np.sin(th) * thd)) < RTOL * L * w
    assert np.max(np.abs(np.array(doc["rates"]["q2_d"]) - L * np.cos(th) * thd)) < RTOL * L * w
    assert doc["solved"] == ["q1", "q1_d"] and doc["perturb"] == {"q2": 0.1, "q2_d": 0.3}
    assert doc["start"]["q1"] == pytest.approx(np.sqrt(L**2 - 0.01), rel=1e-15)


def test_the_bead_stays_on_its_hoop_for_1000_s():
    """x offset 0.05 m, x' 0.1 m/s: x^2 + y^2 = R^2 and x x' + y y' = 0 at every sample to
    rounding; the corrections that kept it there each within the tolerance (at most
    rtol R + atol, R = 0.2 m; the rates' at most rtol R omega + atol, omega = 6.3 rad/s)."""
    R = 0.2
    doc = _simulate("hoop_bead", "--t-end", "1000", "--points", "201", "--perturb", "x=0.05", "--perturb",
                    "x_d=0.1")
    x, y = np.array(doc["x"]), np.array(doc["y"])
    xd, yd = np.array(doc["rates"]["x_d"]), np.array(doc["rates"]["y_d"])
    assert np.max(np.abs(x**2 + y**2 - R**2)) < 1e-15 * R**2
    assert np.max(np.abs(x * xd + y * yd)) < 1e-15 * R**2 * 6.3
    assert x.min() < -0.04 and x.max() > 0.04  # it swings, on the bottom branch
    assert y.max() < -0.19
    res = doc["constraint_residual"]
    assert set(res) == {"x", "y", "x_d", "y_d"} and 0 < res["y"]
    assert max(res["x"], res["y"]) <= RTOL * R + 1e-12 and max(res["x_d"], res["y_d"]) <= RTOL * R * 6.3 + 1e-12
    assert doc["start"] == {"x": 0.05, "y": pytest.approx(-np.sqrt(R**2 - 0.05**2), rel=1e-15), "x_d": 0.1,
                            "y_d": pytest.approx(0.05 * 0.1 / np.sqrt(R**2 - 0.05**2), rel=1e-14)}


def test_the_bead_goes_over_the_top_of_its_hoop_and_stays_on_it():
    """From the bottom at 3 m/s (over the top takes 2 sqrt(g R) = 2.8 m/s): the motion passes
    the equator, where y is no function of x, and the top; the projection (to the nearest
    point of the hoop, not by solving for y) follows it there."""
    R = 0.2
    doc = _simulate("hoop_bead", "--t-end", "2", "--points", "41", "--perturb", "x_d=3")
    x, y = np.array(doc["x"]), np.array(doc["y"])
    assert y.max() > 0.19  # over the top
    assert np.max(np.abs(x**2 + y**2 - R**2)) < 1e-15 * R**2


@pytest.mark.parametrize("model, dependent", [("four_bar", ["q2", "q3"]), ("slider_crank", ["q2", "x"])])
def test_a_closed_chain_keeps_its_loop_closed(model, dependent):
    """The loop's two constraints hold at every sample to 1e-15 of the links' lengths (1 m;
    a few ulps), their rates too; the index-1 form alone leaves them by 4e-9 in 100 s."""
    from gyro.kernels import function
    from gyro.models import load

    doc = _simulate(model, "--t-end", "40", "--points", "81", "--perturb", "q1=0.2", "--perturb", "q1_d=0.5")
    m = load(str(MODELS / f"{model}.py"))
    P = m.vector(m.parameters({}))
    q = np.array([doc[c] for c in doc["coordinates"]]).T
    qd = np.array([doc["rates"][f"{c}_d"] for c in doc["coordinates"]]).T
    phi, J = function(m, "constraints")(np.tile(P, (len(q), 1)), q)
    phi, J = np.asarray(phi).reshape(len(q), 2), np.asarray(J).reshape(len(q), 2, 3)
    assert np.max(np.abs(phi)) < 1e-15 * 1.0
    assert np.max(np.abs(np.einsum("kij,kj->ki", J, qd))) < 1e-14
    assert doc["solved"] == dependent + [f"{c}_d" for c in dependent]
    assert set(doc["constraint_residual"]) == set(doc["start"]) == {*doc["coordinates"], *doc["rates"]}
    assert max(doc["constraint_residual"].values()) < RTOL * 2.0  # its coordinates and rates: at most ~2


@pytest.mark.parametrize("args, match", [
    (["--perturb", "y=0.01"], "--perturb y: y is a dependent coordinate of hoop_bead, solved from its constraints "
                              "at the start; offset the independent ones: x x_d"),
    (["--perturb", "y_d=0.01"], "--perturb y_d: y is a dependent coordinate"),
    (["--perturb", "x=0.3"], "--perturb x: no point of hoop_bead's constraints near its reference has x = 0.3"),
])
def test_an_offset_the_constraints_do_not_take_is_one_line_exit_2(args, match):
    rc, out, err = run_cli("simulate", str(MODELS / "hoop_bead.py"), "--t-end", "1", *args)
    assert rc == 2 and out == "" and match in err and len(error_lines(err)) == 1, err


@pytest.fixture(scope="module")
def hoop_levels(tmp_path_factory):
    """tests/models/hoop_bead.py with the `motion` question's levels on the generic machinery
    (gyro.analyses.motion) in its independent coordinate x: `linear`, the linearised
    equation solved exactly with its Picard correction as estimate; `integrated`, the full
    equations at two tolerances, projected onto the hoop."""
    src = tmp_path_factory.mktemp("hoop") / "hoop_levels.py"
    src.write_text("from derive.model import Bound, Level\n"
                   "from tests.models import hoop_bead\n\n"
                   "EV = {'kind': 'trajectory', 'module': 'gyro.analyses.motion', 'quantities': ['x']}\n\n\n"
                   "def build():\n"
                   "    m = hoop_bead.build()\n"
                   "    m.name, m.module = 'hoop_levels', __name__\n"
                   "    m.levels = [Level('linear', 'second order', {**EV, 'method': 'linear'}, "
                   "{'motion': Bound(estimate=True)}, cost=1e-3, reference='integrated'),\n"
                   "                Level('integrated', 'nothing', {**EV, 'method': 'DOP853', 'rtol': 1e-10}, "
                   "{'motion': Bound(estimate=True)}, cost=1e-2)]\n"
                   "    return m\n")
    return str(src)


@pytest.mark.parametrize("tol, x0, xd0, level", [(1e-3, 0.05, 0.0, "linear"), (1e-6, 0.05, 0.1, "integrated"),
                                                 (1e-3, 0.19, 0.0, "integrated")])
def test_scene_motion_on_a_model_with_multipliers_keeps_its_bound(hoop_levels, tol, x0, xd0, level):
    """The hoop with motion levels in x (hoop_levels): each level's
    answer within its bound of theta'' = (Omega^2 cos theta - g/R) sin theta, x = R sin
    theta, at rtol 1e-13 (the question's relative error: over max(|x|, 1)). From x = 0.19 m
    of R = 0.2 m the linear motion swings past the hoop (to 0.207 m): the linear level says
    so in one line and the integrated one answers. Before: refused
    ("its constraints are carried by multipliers": tests/cli/test_motion_generic.py said so)."""
    R, g, omega = 0.2, 9.81, 3.0
    rc, out, err = run_cli("scene", hoop_levels, "motion", "--tol", str(tol), "--set",
                           f"x_0={x0}", "--set", f"x_d0={xd0}", "--json")
    assert rc == 0, error_lines(err)
    doc = json.loads(out)
    assert doc["level"] == level
    if x0 == 0.19:
        assert doc["tried"][0]["reason"].startswith("the linear motion reaches x = 0.2068")
    t = np.array(doc["t"])
    th0 = np.arcsin(x0 / R)
    sol = solve_ivp(lambda _, y: [y[1], (omega**2 * np.cos(y[0]) - g / R) * np.sin(y[0])], (0, t[-1]),
                    [th0, xd0 / (R * np.cos(th0))], method="DOP853", t_eval=t, rtol=1e-13, atol=1e-15)
    (bound,) = doc["error_bound"]
    assert bound <= tol
    assert np.max(np.abs(np.array(doc["x"]) - R * np.sin(sol.y[0]))) <= bound * 1.0
