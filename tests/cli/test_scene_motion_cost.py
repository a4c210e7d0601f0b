"""`gyro scene MODEL motion`: a tolerance below what an integrated level can give is known
before the level runs (the motion question's floor), and a long integration is held to the
command line's budget by its cost predicted as it goes (gyro.ode.watching), in one line
naming --horizon and the cost. No test here depends on the machine's speed: the floor is
a number, and the budget is set to a nanosecond where it must refuse."""
from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from gyro import levels as hierarchy
from gyro import ode
from gyro.analyses import motion as generic
from gyro.analyses.scene import select
from gyro.models import load
from gyro.questions import motion as Q
from gyro.results.scene import APRIORI
from tests.conftest import error_lines, run_cli

TG = "torsion_gyrocompass"
OPTS = {"horizon": 0.01, "points": 21, "initial": {"gamma1_0": 0.0, "gamma_0": 1e-3}}


def test_the_floor_is_below_the_integrated_bound_and_refuses_before_the_run():
    tg = load(TG)
    P = tg.vector()[None, :]
    level = hierarchy.get(tg, "nonlinear_motion")
    floor = Q.floor(tg, level, P, OPTS)
    ans = Q.answer(tg, level, P, OPTS)
    assert ans.failed[0] == "" and 0 < floor[0] <= np.max(ans.estimate[0])  # a bound it cannot go below
    # and, predicted from the linear motion, within its estimate of the floor the level found
    # (1.74741e-9 against 1.74753e-9: here the floor is the level's whole estimate)
    found = np.max(generic.integration_floor(np.max(np.abs(ans.values[0]), axis=1), level.evaluator["rtol"])
                   / ans.extra["scale"][0])
    assert 0.99 * found <= floor[0] <= found
    scene = select(tg, "motion", P, floor[0] / 2, OPTS)
    assert scene.level[0] == ""
    trial = next(tr for tr in scene.trials if tr.level == "nonlinear_motion")
    assert trial.code[0] == APRIORI and trial.value[0] == floor[0]  # passed over, never run
    assert scene.best(0) == (floor[0], "nonlinear_motion")


def test_a_motion_over_the_budget_is_refused_in_one_line(monkeypatch):
    """With a budget of a nanosecond, the linear level's corrections (metered in chunks of
    100 samples here) are over it after their first chunk: one line naming --horizon and
    the cost, exit 2."""
    import gyro.cli

    monkeypatch.setattr(gyro.cli, "COMMAND_BUDGET", 1e-9)
    monkeypatch.setattr(generic, "CHUNK", 100)
    monkeypatch.setattr(ode.watching, "PILOT", 0.0)
    monkeypatch.setattr(Q, "_MOTIONS", {})  # no linear motion of this set kept by an earlier test
    rc, out, err = run_cli("scene", TG, "motion", "--tol", "1e-3", "--horizon", "0.01")
    assert rc == 2 and out == "" and len(error_lines(err)) == 1, (rc, err)
    assert "--horizon 0.01: linear_motion follows" in err and "periods of the fastest motion" in err
    assert "of the linear motion's correction 1 of 2" in err and "budget of 0 s" in err and "(the default)" not in err


def test_an_integration_over_the_budget_stops_after_its_pilot(monkeypatch):
    """The integrated level (its scale's linear motion already made by the linear level)
    stops at the first look at the clock once its pilot is over: the time so far carried
    to the horizon's end is over a nanosecond on any machine."""
    from gyro import executor
    from gyro.errors import ParameterError

    tg = load(TG)
    P = tg.vector()[None, :]
    opts = dict(OPTS, initial={"gamma1_0": 0.0, "gamma_0": 0.2})
    monkeypatch.setattr(Q, "_MOTIONS", {})
    assert Q.answer(tg, hierarchy.get(tg, "linear_motion"), P, opts).failed[0] == ""
    monkeypatch.setattr(ode.watching, "PILOT", 0.0)
    with executor.budget(1e-9), pytest.raises(ParameterError, match="nonlinear_motion follows") as got:
        Q.answer(tg, hierarchy.get(tg, "nonlinear_motion"), P, opts)
    assert "of integration 1" in str(got.value) and "--horizon 0.01:" in str(got.value)


def test_a_watched_integration_shows_its_progress():
    tg = load(TG)
    P = tg.vector()[None, :]
    class Terminal(io.StringIO):
        def isatty(self):
            return True

    err = Terminal()
    with contextlib.redirect_stderr(err):
        ans = Q.answer(tg, hierarchy.get(tg, "nonlinear_motion"), P, OPTS)
    assert ans.failed[0] == ""
    assert "nonlinear_motion (integration 1)" in err.getvalue() and "(integration 2)" in err.getvalue()
