"""Closed chains in bounded time (derive/constraints.py): a four-bar linkage and a
slider-crank, whose loop closures have no linear solve for any pair of coordinates, carry
two multipliers; their augmented equations are LagrangesMethod's, and the linear operator in
the crank angle at an equilibrium on the loop gives linearize()'s A and B. Compared at 30
digits (RTOL 1e-20 of the largest entry: inputs exact to 30 digits, a few thousand
operations, and the equilibrium found to 1e-28 by mpmath.findroot). A constraint linear in
a coordinate is still eliminated (tests/test_mechanics_style.py's rolling disc), and a
nonholonomic constraint is refused before any constraint is solved."""
from __future__ import annotations

import io
import random

import mpmath
import numpy as np
import pytest
import sympy as sp

from derive import pipeline
from derive.model import Unsupported
from tests.test_mechanics_style import _plain
from tests.test_textbook import MODELS

RTOL = 1e-20
STARTS = {"four_bar": [0.9, 0.3, 1.9], "slider_crank": [1.2, 0.3, 0.45]}


@pytest.fixture(autouse=True)
def thirty_digits():
    with mpmath.workdps(30):  # every mpf operation of these tests, the comparisons' too
        yield


def _derive(name):
    from derive.__main__ import build, load_file

    module = load_file(MODELS / f"{name}.py")
    return module, pipeline.derive(build(module), pipeline.Steps(out=io.StringIO()))


@pytest.fixture(scope="module", params=["four_bar", "slider_crank"])
def chain(request):
    from sympy.physics.mechanics import LagrangesMethod

    module, d = _derive(request.param)
    L, q, hol, loads, N = module.system()
    lm = LagrangesMethod(L, q, hol_coneqs=hol, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    return request.param, module, d, lm, q


def _num(X, pt):
    with mpmath.workdps(30):
        return np.array([[mpmath.re(mpmath.mpmathify(sp.N(sp.sympify(e).xreplace(pt), 30))) for e in row]
                         for row in sp.Matrix(X).tolist()], dtype=object)  # 30 digits, not doubles


def _close(a, b):
    assert max(abs(x) for x in (a - b).ravel()) <= RTOL * max(max(abs(x) for x in b.ravel()), 1), (a, b)


def test_two_multipliers_and_the_augmented_equations_are_lagranges_methods(chain):
    name, _, d, lm, q = chain
    assert d.constraints["multipliers"] == ["lam1", "lam2"] and d.constraints["independent"] == ["q1"]
    n = len(q)
    unknowns = sp.Matrix([sp.Symbol(f"{x.func}_dd") for x in q] + [sp.Symbol("lam1"), sp.Symbol("lam2")])
    ours = (d.mass_matrix * unknowns - d.forcing)
    eom = _plain(lm.eom.xreplace({lm.lam_vec[0]: sp.Symbol("lam1"), lm.lam_vec[1]: sp.Symbol("lam2")}), q)
    rng = random.Random(7)
    names = sorted({str(s) for s in ours.free_symbols | eom.free_symbols})
    for _ in range(2):
        pt = {sp.Symbol(s): sp.Rational(rng.randint(300, 1500), 1000) for s in names}
        _close(_num(ours[:n, :], pt), _num(eom, pt))
        _close(_num(ours[n:, :], pt), _num(_plain(lm.mass_matrix_full[2 * n:, n:] * unknowns - lm.forcing_full[2 * n:, :], q), pt))


def test_operator_in_the_crank_angle_is_linearizes(chain):
    from sympy.physics.mechanics import dynamicsymbols

    name, _, d, lm, q = chain
    par = {sp.Symbol(p.name): sp.Float(p.default, 30) for p in d.model.parameters}
    qs = [sp.Symbol(str(x.func)) for x in q]
    inputs = {s: 0 for s in d.inputs}
    res = [sp.sympify(r).xreplace(par).xreplace(inputs) for r in
           list(d.equilibrium_residual) + [sp.sympify(c) for c in d.constraints["holonomic"]]]
    with mpmath.workdps(50):
        F, J = sp.lambdify(qs, res, "mpmath"), sp.lambdify(qs, sp.Matrix(res).jacobian(qs), "mpmath")
        with mpmath.workdps(30):
            x = mpmath.matrix(mpmath.findroot(F, STARTS[name]))  # damped, to 1e-19 or so
        for _ in range(3):  # then Newton's own steps: 1e-38, below 1e-50
            x -= mpmath.lu_solve(mpmath.matrix(J(*x)), mpmath.matrix(F(*x)))
        qe = list(x)
        assert max(abs(v) for v in F(*qe)) < 1e-40
    at = dict(zip(qs, [sp.Float(v, 50) for v in qe]))
    M, D, K = (_num(X, par | at) for X in (d.operator.M, d.operator.D, d.operator.K))
    Bq = _num(d.input_matrix, par | at)
    zero, one = mpmath.mpf(0), mpmath.mpf(1)
    A_ours = np.array([[zero, one], [-K[0, 0] / M[0, 0], -D[0, 0] / M[0, 0]]], dtype=object)
    B_ours = np.vstack([np.full((1, Bq.shape[1]), zero, dtype=object), Bq / M[0, 0]])
    t = dynamicsymbols._t
    op = {x: at[s] for x, s in zip(q, qs)} | {x.diff(t): 0 for x in q} | {x.diff(t, 2): 0 for x in q}
    op |= {dynamicsymbols(str(s)): 0 for s in d.inputs}
    A, B, _ = lm.linearize(q_ind=q[:1], qd_ind=[q[0].diff(t)], q_dep=q[1:], qd_dep=[x.diff(t) for x in q[1:]],
                           op_point=op | lm.solve_multipliers(op_point=op), A_and_B=True)
    sub = {s: par[sp.Symbol(s.name)] for s in A.free_symbols | B.free_symbols if sp.Symbol(s.name) in par}
    _close(_num(A.xreplace(sub), {}), A_ours)
    _close(_num(B.xreplace(sub), {}), B_ours)


def test_nonholonomic_refused_before_any_constraint_is_solved(monkeypatch):
    """A holonomic constraint beside a rolling one (a Whipple-style bicycle's pitch and its
    wheels): refused as nonholonomic, and nothing was solved."""
    from derive import constraints

    called = []
    monkeypatch.setattr(constraints, "solve_dependent", lambda m: called.append(m) or None)
    x, y, th, xd, yd, thd, xdd, ydd, thdd = sp.symbols("x y theta x_d y_d theta_d x_dd y_dd theta_dd")
    from derive.model import Model, Parameter

    model = Model(name="sled", title="sled", source="test", module=__name__,
                  parameters=[Parameter("m", "kg", 1.0, "mass")], coordinates=["x", "y", "theta"],
                  coordinate_units={"x": "m", "y": "m", "theta": "rad"}, q=[x, y, th], qd=[xd, yd, thd],
                  qdd=[xdd, ydd, thdd], lagrangian=sp.Symbol("m") * (xd**2 + yd**2 + thd**2) / 2,
                  holonomic=[sp.sin(y) ** 3 + y - sp.cos(th) * x], nonholonomic=[xd * sp.sin(th) - yd * sp.cos(th)])
    with pytest.raises(Unsupported, match="nonholonomic"):
        pipeline.derive(model, pipeline.Steps(out=io.StringIO()))
    assert not called
