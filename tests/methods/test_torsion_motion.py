"""The torsion gyrocompass's motion levels (docs/hierarchy.md, gyro.systems.torsion_gyrocompass):
the linear motion is the exponential of the exact operator, its correction is its error
against the integrated 11-coordinate equations, its bound holds at corners of the spreads
and on held-out random sets, and the selector goes from the linear motion to the
integration as the perturbation grows; `gyro scene`'s exit codes."""
from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from gyro import levels as hierarchy
from gyro.systems import torsion_gyrocompass as tm
from gyro.analyses.scene import select
from gyro.models import load
from gyro.questions import motion as Q
from tests.conftest import run_cli

TG = "torsion_gyrocompass"
HORIZON = 0.02  # s: some 12 periods of the fastest nutation at the example (3851 rad/s)


@pytest.fixture(scope="module")
def tg():
    return load(TG)


def both(model, P, initial: dict, horizon: float = HORIZON):
    """(error, linear bound, integrator bound) per set and coordinate, the perturbation
    `initial` alone (the default tilt gamma1 off)."""
    opts = {"horizon": horizon, "points": 41, "initial": {"gamma1_0": 0.0, **initial}}
    lin = Q.answer(model, hierarchy.get(model, "linear_motion"), P, opts)
    full = Q.answer(model, hierarchy.get(model, "nonlinear_motion"), P, opts)
    assert np.all(lin.failed == "") and np.all(full.failed == ""), (lin.failed, full.failed)
    return Q.error(lin, full), lin.estimate, full.estimate


def assert_held(err, b, bn):
    """The error within the linear bound where the integrator resolves it (its own estimate
    a tenth of the error or less), within the sum of both bounds everywhere."""
    assert np.all(np.isfinite(b))
    assert np.all(err <= b + bn), (err, b, bn)
    resolved = err > 10 * bn
    assert resolved.any()
    assert np.all(err[resolved] <= b[resolved]), (err / b)[resolved]


def test_the_module_follows_the_model(tg):
    assert list(tm.REDUCED) == tg.meta["reduced"]
    assert Q.quantities(tg, {}) == list(tm.REDUCED)  # gamma3, the cyclic spin angle, not answered
    assert not set(tm.INITIAL) & set(tg.param_names)
    assert set(Q.initial_conditions(tg)) == set(tm.INITIAL)
    with pytest.raises(ValueError, match="gamma3_0"):
        tm.Motion(tg.defaults, gamma3_0=1.0)


def test_the_linear_motion_is_the_exponential_of_the_linearised_equations(tg):
    """A is the Jacobian of the reduced full equations at the equilibrium (CasADi's, by
    another route than the generated operator), and the motion is expm(A t) z0."""
    import casadi as ca
    from scipy.linalg import expm

    mo = tm.Motion(tg.defaults, gamma1_0=1e-3, beta_d0=0.1, x1_0=1e-6)
    z = ca.SX.sym("z", 20)
    J = np.asarray(ca.Function("J", [z], [ca.jacobian(mo.reduced.rhs(z), z)])(np.zeros(20)))
    A = mo.first_order
    assert np.max(np.abs(A - J)) <= 1e-10 * np.max(np.abs(A))
    t = np.linspace(0.0, HORIZON, 11)
    zL, _, _ = tm.linear_motion(mo, t)
    ref = np.stack([expm(A * s) @ mo.z0 for s in t])
    assert np.max(np.abs(zL - ref), axis=0) == pytest.approx(0.0, abs=1e-9 * np.max(np.abs(ref)))


def test_the_second_picard_step_is_the_error_and_the_first_falls_short(tg, monkeypatch):
    """At a casing tilt gamma of 0.01 rad the correction after two steps equals the error
    (the integrated motion minus the linear one) to 1 %; one step alone gives about half of
    it on gamma (its remainder is of third order, as are the quadratic terms on the first
    step's even coordinates)."""
    mo = tm.Motion(tg.defaults, gamma1_0=0.0, gamma_0=0.01)
    t = np.linspace(0.0, HORIZON, 41)
    S = mo.reduced
    zL, e2, _ = tm.linear_motion(mo, t)
    err = tm.integrate(mo, t, "DOP853", 1e-11) - S.q_ref[S.ri] - zL[:, :10]
    g = tm.REDUCED.index("gamma")
    scale = np.max(np.abs(err))
    assert np.max(np.abs(e2[:, :10] - err)) <= 1e-2 * scale
    monkeypatch.setattr(tm, "CORRECTIONS", 1)
    _, e1, _ = tm.linear_motion(mo, t)
    assert np.max(np.abs(err[:, g])) > 1.5 * np.max(np.abs(e1[:, g]))


CORNERS = [({"H": 0.1}, {"gamma1_0": 1e-3}, HORIZON), ({"H": 10.0}, {"gamma1_0": 1e-3}, 0.002),
           ({"Kp": 10.0, "phi": 89.0}, {"beta_d0": 0.3}, HORIZON), ({"K0": 0.1, "Kgamma": 10.0, "phi": 0.0},
                                                                 {"x1_0": 1e-5}, HORIZON)]


@pytest.mark.parametrize("factors, initial, horizon", CORNERS)
def test_the_linear_bound_holds_at_corners_of_the_spreads(tg, factors, initial, horizon):
    values = {k: (v if k == "phi" else v * tg.defaults[k]) for k, v in factors.items()}
    err, b, bn = both(tg, tg.vector(values)[None, :], initial, horizon)
    assert_held(err, b, bn)
    # and it is the error's size, not a wide margin, on the worst coordinate
    assert np.max(err) >= 0.3 * np.max(b)


@settings(max_examples=3, deadline=None, phases=[Phase.generate], derandomize=True)
@given(st.integers(0, 2**31 - 1))
def test_the_linear_bound_holds_on_held_out_sets(seed):
    """Random sets (spin, K0, Kp, K_gamma 0.3x..3x, latitude 0..89 deg) and a random
    perturbation of one reduced coordinate (up to 0.1 rad, 1 mm) or its rate (ten times that per s)."""
    model = load(TG)
    rng = np.random.default_rng(seed)
    values = {k: model.defaults[k] * float(np.exp(rng.uniform(np.log(0.3), np.log(3.0))))
              for k in ("H", "K0", "Kp", "Kgamma")}
    values["phi"] = float(rng.uniform(0.0, 89.0))
    c = tm.REDUCED[rng.integers(len(tm.REDUCED))]
    rate = bool(rng.integers(2))
    top = (1e-3 if c.startswith("x") else 0.1) * (10.0 if rate else 1.0)  # m or rad (per s)
    a = float(top * np.exp(rng.uniform(np.log(1e-4), 0.0)))
    err, b, bn = both(model, model.vector(values)[None, :], {f"{c}_{'d0' if rate else '0'}": a}, 0.01)
    assert_held(err, b, bn)


def test_the_selector_takes_the_linear_motion_small_and_the_integration_large(tg):
    P = tg.vector()[None, :]
    levels = []
    for a in (1e-3, 0.2):  # the casing tilted: relative error 1.95 a^2 / rad^2 (docs/hierarchy.md)
        opts = {"horizon": HORIZON, "points": 41, "initial": {"gamma1_0": 0.0, "gamma_0": a}}
        s = select(tg, "motion", P, 1e-3, opts)
        levels.append(s.level[0])
        assert np.all(s.bound <= 1e-3)
    assert levels == ["linear_motion", "nonlinear_motion"]
    assert s.tried(0)[0][0] == "linear_motion" and "bound" in s.tried(0)[0][1]


def test_a_batch_with_initial_conditions_per_set_goes_up_set_by_set(tg):
    """Two sets in one batch, the casing tilted by 1e-3 and by 0.2 rad: the first taken by the
    linear motion, the second going up with its own initial condition (the options were
    passed whole to the next level, whose sets are fewer: a broadcast error)."""
    P = tg.vector()[None, :].repeat(2, axis=0)
    opts = {"horizon": HORIZON, "points": 41,
            "initial": {"gamma1_0": 0.0, "gamma_0": np.array([1e-3, 0.2])}}
    s = select(tg, "motion", P, 1e-3, opts)
    assert list(s.level) == ["linear_motion", "nonlinear_motion"]
    gamma = s.document(1)["gamma"]
    assert gamma[0] == pytest.approx(0.2, rel=1e-12)  # the second set's own start


def test_scene_answers_a_motion_and_refuses_what_no_level_promises():
    rc, out, err = run_cli("scene", TG, "motion", "--tol", "1e-3", "--horizon", "0.01", "--set", "gamma1_0=1e-4",
                           "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["level"] == "linear_motion" and d["quantities"] == list(tm.REDUCED)
    assert len(d["gamma1"]) == len(d["t"]) and max(d["error_bound"]) <= 1e-3
    rc, out, err = run_cli("scene", TG, "motion", "--tol", "1e-13", "--horizon", "0.01")
    assert rc == 1 and "can promise" in err and "nonlinear_motion" in err and out == ""


@pytest.mark.parametrize("args, says", [
    (("--set", "gamma_0=nan"), "gamma_0"), (("--set", "gamma_0=x"), "gamma_0"),
    (("--horizon", "-1"), "--horizon"), (("--set", "gamma4_0=1"), "gamma4_0"),
])
def test_scene_motion_refuses_bad_input_in_one_line(args, says):
    rc, out, err = run_cli("scene", TG, "motion", "--tol", "1e-3", *args)
    assert rc == 2 and says in err and len(err.strip().splitlines()) == 1 and out == ""


def test_the_committed_map_holds_the_bound_and_shows_its_cap(tg):
    """bench/results/levels.json 'torsion_motion_map' (python -m bench.levels --torsion-motion):
    no bound beaten where the integrator resolves the error, every error within both
    levels' bounds, the uncapped estimate a bound up to the cap and beaten above it (so the
    cap is needed), the map's run of the current declarations."""
    from pathlib import Path

    d = json.loads((Path(__file__).resolve().parents[2] / "bench" / "results" / "levels.json").read_text())
    m = d["torsion_motion_map"]
    assert m["held"] and m["max_error_over_bound_resolved"] < 1.0
    assert m["cap"] == tm.CAP
    near = [c for c in m["toward_the_cap"] if c["uncapped_bound"] <= tm.CAP]
    past = [c for c in m["toward_the_cap"] if c["uncapped_bound"] > tm.CAP]
    assert near and max(c["error_over_uncapped_bound"] for c in near) < 1.0
    assert past and max(c["error_over_uncapped_bound"] for c in past) >= 1.0
    assert m["declared"] == {k: hierarchy.get(tg, k).cost for k in ("linear_motion", "nonlinear_motion")}
    assert m["seconds_median"]["linear_motion"] < m["seconds_median"]["nonlinear_motion"]


def _spin_free_rate(v: dict, g: dict, gd: dict) -> float:
    """r2 - gamma3' of (1.6) by the frames, written out here (an independent route): the
    Earth rate (1.3) and the casing rate p (1.5) in the casing, frames (1.2), (1.6)."""
    def rot(axis, a):
        c, s = np.cos(a), np.sin(a)
        return np.array({"x": [[1, 0, 0], [0, c, -s], [0, s, c]], "y": [[c, 0, s], [0, 1, 0], [-s, 0, c]],
                         "z": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[axis])

    phi = np.radians(v["phi"])
    u = v["u"] * np.array([0.0, np.cos(phi), np.sin(phi)])
    S = rot("z", g["alpha"]) @ rot("x", g["beta"]) @ rot("y", g["gamma"])
    p = (S.T @ (u + gd["alpha"] * np.array([0, 0, 1.0]))
         + gd["beta"] * np.array([np.cos(g["gamma"]), 0, np.sin(g["gamma"])]) + gd["gamma"] * np.array([0, 1.0, 0]))
    R = rot("z", g["gamma1"]) @ rot("x", g["gamma2"])
    return float((R.T @ (p + gd["gamma1"] * np.array([0, 0, 1.0])) + gd["gamma2"] * np.array([1.0, 0, 0]))[1])


def test_the_emitted_spin_rate_is_the_integral_by_the_frames(tg):
    """gamma3' of the reduced state (the emitted `cyclic_rates`, dL/dgamma3' = H solved) is
    H/C less the rotor's spin-free rate by the frames (1.2)-(1.6), to rounding, on states far
    from the equilibrium (angles to 0.3 rad, rates to 2 rad/s) and at 10x the Earth rate."""
    rng = np.random.default_rng(7)
    for scale in (1e-3, 0.3):
        values = {**tg.defaults, "u": 10 * tg.defaults["u"]}
        S = tm.ReducedState(tg, values)
        x, xd = rng.normal(size=10) * scale, rng.normal(size=10) * 2.0
        Y = S.state(x, xd)
        g, gd = dict(zip(S.coords, Y[:S.nq])), dict(zip(S.coords, Y[S.nq:]))
        want = values["H"] / values["C"] - _spin_free_rate(values, g, gd)
        assert Y[S.nq + S.coords.index("gamma3")] == pytest.approx(want, rel=4 * np.finfo(float).eps)
