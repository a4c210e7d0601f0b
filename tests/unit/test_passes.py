"""The derivation as passes (derive/passes/): discovered from the folder in their ORDER,
each a function run(model, derivation) -> derivation on the routes it names; the
constraints pass chooses elimination or multipliers within the one derivation."""
from __future__ import annotations

import inspect
import io

import pytest
import sympy as sp

from derive import passes, pipeline
from derive.derivation import Derivation
from derive.model import Model, Parameter
from tests.conftest import ROOT

ROUTES = {"coordinates", "multipliers"}


def test_every_module_of_the_folder_is_a_pass_in_its_order():
    found = passes.passes()
    files = sorted(p.stem for p in (ROOT / "derive" / "passes").glob("*.py") if not p.stem.startswith("_"))
    assert sorted(m.__name__.rsplit(".", 1)[-1] for m in found) == files
    orders = [m.ORDER for m in found]
    assert orders == sorted(orders) and len(set(orders)) == len(orders), orders
    for m in found:
        assert list(inspect.signature(m.run).parameters) == ["model", "d"], m.__name__
        assert m.ROUTES and set(m.ROUTES) <= ROUTES, m.__name__
    # the natural seams, in the order the derivation takes them
    names = [m.__name__.rsplit(".", 1)[-1] for m in found]
    assert names.index("conversion") < names.index("constraints") < names.index("checks") \
        < names.index("equations") < names.index("routh") < names.index("reference") \
        < names.index("operator") < names.index("inputs") < names.index("variants") < names.index("finish")


def _pendulum(holonomic_y: bool) -> Model:
    """A pendulum of length l in Cartesian x, y: on x^2 + y^2 = l^2 (no linear solve, so
    multipliers) or with the constraint y = -l, linear (eliminated)."""
    x, y, xd, yd, xdd, ydd = sp.symbols("x y x_d y_d x_dd y_dd")
    m, g, l = sp.symbols("m g l")
    params = [Parameter("m", "kg", 1.0, "mass"), Parameter("g", "m/s^2", 9.81, "gravity"),
              Parameter("l", "m", 1.0, "length")]
    phi = y + l if holonomic_y else x**2 + y**2 - l**2
    return Model(name="probe", title="probe", source="test", module=__name__, parameters=params,
                 coordinates=["x", "y"], coordinate_units={"x": "m", "y": "m"}, q=[x, y], qd=[xd, yd],
                 qdd=[xdd, ydd], lagrangian=m * (xd**2 + yd**2) / 2 - m * g * y, holonomic=[phi],
                 reduced=["x"])


def _ran(monkeypatch, model) -> tuple[list, Derivation]:
    """The passes that ran on `model`, in the order they ran, each checked to be handed the
    model as the passes before left it and to return the one derivation."""
    ran = []
    for m in passes.passes():
        def spy(model, d, _run=m.run, _name=m.__name__.rsplit(".", 1)[-1]):
            assert model is d.model
            ran.append(_name)
            out = _run(model, d)
            assert out is d
            return out
        monkeypatch.setattr(m, "run", spy)
    return ran, pipeline.derive(model, pipeline.Steps(out=io.StringIO()))


@pytest.mark.parametrize("linear", [True, False])
def test_the_constraints_pass_chooses_elimination_or_multipliers(monkeypatch, linear):
    """Either way every pass runs, in order: the multipliers route forms its equations,
    reference, operator and B in the same passes as the coordinates route (with the
    multiplier columns), so that no step added to one is silently lacking on the other."""
    ran, d = _ran(monkeypatch, _pendulum(holonomic_y=linear))
    assert ran == [m.__name__.rsplit(".", 1)[-1] for m in passes.passes()]
    if linear:  # eliminated
        assert d.route == "coordinates" and d.model.coordinates == ["x"] and "eliminated" in d.constraints
    else:
        assert d.route == "multipliers" and d.constraints["multipliers"] == ["lam1"]
        assert d.mass_matrix.shape == (3, 3) and d.operator.M.shape == (1, 1)
        assert d.route_agreement is None and d.even == list(d.model.q)
    assert d.timings and not vars(d.work)  # what passes handed on is gone


def test_every_pass_runs_on_both_routes():
    """A pass for one route only would leave the other without its step (the multipliers
    route once formed its equations and operator apart, without the passes' checks)."""
    for m in passes.passes():
        assert set(m.ROUTES) == ROUTES, m.__name__


@pytest.mark.parametrize("compiled", [False, True])
def test_the_routes_check_compares_30_digit_values_either_way(monkeypatch, compiled):
    """The two routes' check (derive/passes/operator.py) by N(entry, 30), or compiled in
    mpmath with 60 working digits and each value rounded to 30 (large operators): equal
    entries written differently (sin^2 + cos^2 against 1, a product against its expansion)
    compare to exactly 0, and a term of relative size 1e-12 is seen."""
    from derive import mechanics as mech
    from derive.passes import operator as op_pass

    monkeypatch.setattr(op_pass, "COMPILE_NODES", 0 if compiled else 10**9)
    th, a, b = sp.symbols("theta a b")
    M1 = sp.Matrix([[a * (sp.sin(th) ** 2 + sp.cos(th) ** 2), (a + b) ** 3], [b / (1 + sp.tan(th) ** 2), a]])
    M2 = sp.Matrix([[a, sp.expand((a + b) ** 3)], [b * sp.cos(th) ** 2, a]])
    K = sp.Matrix([[sp.exp(th) * a, 0], [0, b]])
    same = op_pass.compare_operators(mech.LinearOperator(M1, M1 * 0, K), mech.LinearOperator(M2, M2 * 0, K))
    assert same == 0.0
    off = op_pass.compare_operators(mech.LinearOperator(M1, M1 * 0, K),
                                    mech.LinearOperator(M2, M2 * 0, K + sp.Matrix([[0, 0], [0, b * 1e-12]])))
    assert 1e-14 < off < 1e-11
