"""Closed chains in bounded time (derive/constraints.py): a four-bar linkage and a
slider-crank, whose loop closures have no linear solve for any pair of coordinates, carry
two multipliers; their augmented equations are LagrangesMethod's, and the linear operator in
the crank angle at an equilibrium on the loop gives linearize()'s A and B. Compared at 30
digits (RTOL 1e-20 of the largest entry: inputs exact to 30 digits, a few thousand
operations, and the equilibrium found to 1e-28 by mpmath.findroot). A constraint linear in
a coordinate is still eliminated (tests/generated/test_mechanics_style.py's rolling disc), and a
nonholonomic constraint is refused before any constraint is solved."""
from __future__ import annotations

import io
import json
import random

import mpmath
import numpy as np
import pytest
import sympy as sp

from derive import pipeline
from derive.model import Unsupported
from tests.generated.test_mechanics_style import _plain
from tests.generated.test_textbook import MODELS

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
        # SymPy's mass_matrix writes the multipliers' columns with the opposite sign of its eom's
        _close(_num(d.mass_matrix[:n, n:], pt), _num(-_plain(lm.mass_matrix[:, n:], q), pt))
        _close(_num(d.mass_matrix[:n, :n], pt), _num(_plain(lm.mass_matrix[:, :n], q), pt))


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


# --------------------------------------------------------------------------- the runtime on them


def test_frequencies_of_a_pendulum_held_by_a_multiplier(tmp_path):
    """gyro frequencies on the Cartesian pendulum (q2 independent): the equilibrium on the
    circle from the constraints (q = (L, 0)) and omega = sqrt(g/L) to rounding; a sweep over
    L follows sqrt(g/L); a motion from it stays on the circle to the integrator's tolerance
    and swings at that frequency."""
    from tests.conftest import ROOT, run_cli

    path = str(ROOT / "tests" / "models" / "nonminimal_pendulum.py")
    rc, out, err = run_cli("frequencies", path, "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["equilibrium"] == {"q1": 0.5, "q2": 0.0}
    assert abs(doc["frequencies"][0] - np.sqrt(9.8 / 0.5)) < 1e-14 * np.sqrt(9.8 / 0.5)
    assert doc["stability"]["class"] == "stable"
    rc, out, err = run_cli("sweep", path, "--x", "L", "--x-range", "0.2", "2", "--points", "4", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    got = np.array(doc["frequencies"])[:, 0]
    assert np.allclose(got, np.sqrt(9.8 / np.array(doc["x"]["values"])), rtol=1e-13, atol=0)
    rc, out, err = run_cli("simulate", path, "--t-end", "1.41923", "--points", "3", "--perturb", "q2_d=0.01",
                           "--json")
    assert rc == 0, err
    doc = json.loads(out)
    q1, q2 = np.array(doc["q1"]), np.array(doc["q2"])
    assert np.max(np.abs(q1**2 + q2**2 - 0.25)) < 1e-9  # the constraint kept along the motion
    # back at the start after one period 2 pi/omega (printed to 6 digits): within 1e-3 of the
    # swing's amplitude 0.01/omega (the period's rounding and its amplitude shift, ~1e-6)
    assert abs(q2[-1]) < 1e-3 * 0.01 / np.sqrt(19.6)


def test_the_four_bar_frequency_is_its_operators_at_the_loop_equilibrium(chain):
    name, _, d, _, q = chain
    from tests.conftest import ROOT, run_cli

    rc, out, err = run_cli("frequencies", str(ROOT / "tests" / "models" / f"{name}.py"), "--json")
    assert rc == 0, err
    doc = json.loads(out)
    par = {sp.Symbol(p.name): p.default for p in d.model.parameters}
    at = {sp.Symbol(k): v for k, v in doc["equilibrium"].items()}
    M, K = (float(X[0].xreplace(par | at)) for X in (d.operator.M, d.operator.K))
    res = [float(sp.sympify(c).xreplace(par | at)) for c in d.constraints["holonomic"]]
    assert max(abs(r) for r in res) < 1e-13
    if K > 0:
        assert abs(doc["frequencies"][0] - np.sqrt(K / M)) < 1e-12 * np.sqrt(K / M)
        assert doc["stability"]["class"] == "stable"
    else:  # the slider-crank at its dead centre: a real pair, one growing at sqrt(-K/M)
        assert abs(doc["stability"]["growth_rate"] - np.sqrt(-K / M)) < 1e-12 * np.sqrt(-K / M)
        assert doc["stability"]["class"] == "unstable"


def test_independent_coordinates_that_do_not_parametrise_the_equilibrium_are_refused(tmp_path):
    """The Cartesian pendulum with q1 independent: at its equilibria q2 = 0, where the
    constraint cannot be solved for q2, and the operator in q1 would be infinite (it was
    8e22 before, 'marginal'). Refused in one line naming `reduced`."""
    from tests.conftest import ROOT, run_cli

    src = tmp_path / "nonminimal_q1.py"
    src.write_text(
        "import sys\nsys.path.insert(0, %r)\n" % str(ROOT)
        + "from tests.models.nonminimal_pendulum import system, PARAMETERS\nfrom derive.model import Model\n\n\n"
        "def build():\n    L, q, hol, loads, N = system()\n"
        "    return Model(name='nonminimal_q1', title='q1 independent', source='test', module=__name__,\n"
        "                 parameters=PARAMETERS, coordinates=['q1', 'q2'], coordinate_units={'q1': 'm', 'q2': 'm'},\n"
        "                 q=q, qd=[], qdd=[], lagrangian=L, loads=loads, frame=N, holonomic=hol)\n")
    rc, out, err = run_cli("frequencies", str(src))
    lines = err.strip().splitlines()  # after the first use's notices (deriving, compiling), one line
    assert rc == 1 and out == "" and all(ln.startswith(("gyro: deriving", "gyro: compiling")) for ln in lines[:-1])
    assert "cannot be solved for the dependent ones q2" in lines[-1] and "`reduced`" in lines[-1], err


def test_coulomb_friction_at_rest_has_no_operator_and_says_which_term(tmp_path):
    """A block with Coulomb friction mu m g sign(x') about rest: the operator does not exist
    (derive/nonsmooth.py emits it NaN and names the term); gyro frequencies refuses in one
    line naming sign(x_d) (it was LAPACK's 'qr failed to converge'); the belt's friction
    sign(x_d - v) is linearised where v != 0 and a sweep through v = 0 fails that point only."""
    from tests.conftest import ROOT, error_lines, run_cli

    src = tmp_path / "coulomb_block.py"
    src.write_text(
        "import sympy as sp\nfrom derive.model import Model, Parameter\n\n\ndef build():\n"
        "    x, x_d, x_dd = sp.symbols('x x_d x_dd')\n    m, k, mu, g = sp.symbols('m k mu g')\n"
        "    return Model(name='coulomb_block', title='Coulomb block', source='test', module=__name__,\n"
        "                 parameters=[Parameter('m', 'kg', 1.0, 'mass'), Parameter('k', 'N/m', 4.0, 'spring'),\n"
        "                             Parameter('mu', '1', 0.3, 'friction', kind='nonnegative'),\n"
        "                             Parameter('g', 'm/s^2', 9.81, 'gravity')],\n"
        "                 coordinates=['x'], coordinate_units={'x': 'm'}, q=[x], qd=[x_d], qdd=[x_dd],\n"
        "                 lagrangian=m * x_d**2 / 2 - k * x**2 / 2, generalized_forces={'x': -mu * m * g * sp.sign(x_d)})\n")
    rc, out, err = run_cli("frequencies", str(src))
    assert rc == 1 and out == "" and len(error_lines(err)) == 1, err
    assert "no linear operator at this set" in err and "sign(x_d), its argument there 0" in err
    belt = str(ROOT / "tests" / "models" / "belt_friction.py")
    rc, out, err = run_cli("sweep", belt, "--x", "v", "--x-range", "-0.5", "0.5", "--points", "3", "--json")
    doc = json.loads(out)
    assert rc == 1 and doc["stability"] == ["stable", "failed", "stable"]
    assert abs(doc["frequencies"][2][0] - np.sqrt(44.0)) < 1e-13 * np.sqrt(44.0)  # k + k_s past the stop


def test_coulomb_friction_equations_are_lagranges_methods():
    """The block with Coulomb friction as SymPy's two methods give it (the issue: refused
    outright before): LagrangesMethod with the friction as a force on its point, mass
    matrix and forcing equal to ours, sign(x') included, at points on both sides of the
    kink and on it."""
    from sympy.physics.mechanics import LagrangesMethod, Lagrangian, Particle, Point, ReferenceFrame, dynamicsymbols

    x = dynamicsymbols("x")
    m, k, mu, g = sp.symbols("m k mu g", positive=True)
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", x * N.x)
    P.set_vel(N, x.diff() * N.x)
    block = Particle("block", P, m)
    block.potential_energy = k * x**2 / 2
    friction = [(P, -mu * m * g * sp.sign(x.diff()) * N.x)]
    lm = LagrangesMethod(Lagrangian(N, block), [x], forcelist=friction, frame=N)
    lm.form_lagranges_equations()
    from derive.model import Model, Parameter

    X, Xd, Xdd = sp.symbols("x x_d x_dd")
    M_, K_, MU, G = sp.symbols("m k mu g")
    model = Model(name="coulomb", title="Coulomb block", source="test", module=__name__,
                  parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 4.0, "spring"),
                              Parameter("mu", "1", 0.3, "friction", kind="nonnegative"),
                              Parameter("g", "m/s^2", 9.81, "gravity")],
                  coordinates=["x"], coordinate_units={"x": "m"}, q=[X], qd=[Xd], qdd=[Xdd],
                  lagrangian=M_ * Xd**2 / 2 - K_ * X**2 / 2, generalized_forces={"x": -MU * M_ * G * sp.sign(Xd)})
    d = pipeline.derive(model, pipeline.Steps(out=io.StringIO()))
    theirs_M, theirs_f = _plain(lm.mass_matrix, [x]), _plain(lm.forcing, [x])
    for xd in (sp.Rational(3, 10), sp.Rational(-3, 10), 0):
        pt = {sp.Symbol("m"): 1, sp.Symbol("k"): 4, sp.Symbol("mu"): sp.Rational(3, 10), sp.Symbol("g"): sp.Rational(981, 100),
              sp.Symbol("x"): sp.Rational(1, 10), sp.Symbol("x_d"): xd}
        assert sp.simplify((d.mass_matrix - theirs_M).xreplace(pt)) == sp.zeros(1, 1)
        assert sp.simplify((d.forcing - theirs_f).xreplace(pt)) == sp.zeros(1, 1), xd


def test_a_model_with_multipliers_runs_its_declared_identities():
    """A declared identity is checked on the multipliers route too (it was skipped there): a
    residual that does not vanish stops the derivation of the bead held on its hoop by a
    multiplier, one that does lets it through."""
    from tests.models import hoop_bead

    model = hoop_bead.build()
    model.identities = {"the hoop's radius is positive": lambda: [0]}
    assert pipeline.derive(model).constraints.get("multipliers")
    model.identities = {"a residual that stays": lambda: [sp.Integer(1)]}
    with pytest.raises(AssertionError, match="identity failed: a residual that stays"):
        pipeline.derive(model)
