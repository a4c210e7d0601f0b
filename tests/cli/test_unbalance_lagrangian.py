"""A mass unbalance written into the Lagrangian (issue 18, item 4): refused at derive time in
one line that says how to write it as force inputs for `gyro unbalance`, through the cyclic
spin angle (tests/models/unbalanced_rotor_cyclic.py) and through explicit time, the spin
angle as W t (tests/models/unbalanced_rotor_time.py); never a runtime ValueError, and never
an answer as if the time-dependent term were absent.

Why refused rather than derived: the unbalance's term in explicit time is a forcing (mu e W^2
cos W t on x): the rotor's reference is then no equilibrium at any instant, so none of the
runtime's analyses (each an operator about an equilibrium) has a model to work on; the
harmonic response of such a forcing is `gyro unbalance` on two force inputs, which gives it
exactly (tests/methods/test_anymodel.py checks it against the complex 4x4 solve). A time-dependent
operator about an equilibrium that exists (the Mathieu pendulum: a parametric excitation)
still derives, and the runtime refuses it in one line, exit 2, naming what it would need.
"""
from __future__ import annotations

import dataclasses
import io
from pathlib import Path

import pytest

from derive import pipeline
from derive.__main__ import build, load_file
from derive.model import Unsupported
from tests.conftest import run_cli

MODELS = Path(__file__).resolve().parents[1] / "models"
HOW = r"two force inputs .*gyro unbalance MODEL --force-x Fx --force-y Fy --magnitude ME"


def _model(name):
    return build(load_file(MODELS / f"{name}.py"))


def _derive(model):
    return pipeline.derive(model, pipeline.Steps(out=io.StringIO()))


def _one_line_exit_2(rc, out, err, *needles):
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("gyro: deriving")]
    assert rc == 2 and out == "", (rc, out, err)
    assert len(lines) == 1 and lines[0].startswith("gyro: error: "), err
    assert "Traceback" not in err and "inputs, got" not in err, err
    for n in needles:
        assert n in lines[0], (n, lines[0])


def test_an_unbalance_through_the_cyclic_spin_angle_is_refused_saying_how_to_write_it():
    with pytest.raises(Unsupported, match=r"phi \(cyclic\) appears in the Lagrangian; .*mass unbalance .*" + HOW):
        _derive(_model("unbalanced_rotor_cyclic"))


@pytest.mark.parametrize("symmetric", [False, True])
def test_an_unbalance_in_explicit_time_is_refused_at_derive_time_naming_the_forced_coordinates(symmetric):
    """With or without x, y, alpha, beta declared zero on the symmetric set: the time check
    comes first, so the refusal is the one that says what the term is and how to write it."""
    model = _model("unbalanced_rotor_time")
    if symmetric:
        model = dataclasses.replace(model, symmetric_zero=["x", "y", "alpha", "beta"])
    with pytest.raises(Unsupported, match=r"explicit time t enters the equilibrium equations of x, y: .*" + HOW):
        _derive(model)


def test_every_entry_refuses_the_explicit_time_unbalance_in_one_line_exit_2():
    """The model file at a runtime command: derived on first use by `python -m derive`, whose
    exit 2 and one line the command passes on (the same one line, not a ValueError)."""
    rc, out, err = run_cli("frequencies", str(MODELS / "unbalanced_rotor_time.py"), "--json")
    _one_line_exit_2(rc, out, err, "explicit time t enters the equilibrium equations of x, y",
                     "gyro unbalance MODEL --force-x Fx --force-y Fy")


def test_a_parametric_excitation_derives_and_the_runtime_refuses_its_time_dependent_operator():
    """The Mathieu pendulum's time is in its operator only (its equilibrium theta = 0 holds
    at every instant): it derives, and every analysis refuses it before calling a function
    without its time argument (before, `frequencies` said 'numerical failure ... 3 inputs,
    got 2', exit 1: a failure at valid input that was not numerical)."""
    d = _derive(_model("mathieu_pendulum"))
    assert d.time_dependent
    # theta not declared zero: the residual m l (g - a w^2 sin w t) sin(theta) carries t, but
    # its d/dt depends on theta and vanishes at theta = 0, so an equilibrium can absorb it
    free = _derive(dataclasses.replace(_model("mathieu_pendulum"), symmetric_zero=[]))
    assert free.time_dependent and free.model.symmetric_zero == []
    path = str(MODELS / "mathieu_pendulum.py")
    for args in (["frequencies", path, "--json"], ["campbell", path, "--spin", "w", "--json"],
                 ["sweep", path, "--x", "w", "--x-range", "1", "10"]):
        _one_line_exit_2(*run_cli(*args), "mathieu_pendulum: its equilibrium_residual and operator depend "
                         "on the explicit time t", "Floquet")
