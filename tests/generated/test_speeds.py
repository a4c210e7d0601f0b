"""Generalised speeds with kinematic differential equations (Model.kinematics, as
KanesMethod's kd_eqs): the machinery derives in the speeds exactly as KanesMethod does, and
speeds handed over as rates without kinematic equations are checked, never guessed
(derive/convert.py).

The heavy top in body-rate speeds (tests/models/top_body_speeds.py) against KanesMethod:
mass matrix and forcing in the speeds at random points to 30 digits (RTOL 1e-25 of the
largest entry: exact rational inputs, 30-digit evaluation of two expressions of a few
hundred operations); the emitted functions through every backend against the symbolic
expressions at 1e-12 (tests/generated/test_textbook.py's tolerance). Read as rates without the
kinematic equations the same speeds would give another top (M = diag(A + m l^2, A + m l^2,
C) everywhere): refused in one line."""
from __future__ import annotations

import contextlib
import io
import random
import textwrap

import mpmath
import numpy as np
import pytest
import sympy as sp

from derive import pipeline
from derive.model import Unsupported
from tests.generated.test_textbook import MODELS, _finish, check_symbolic


def _load(name="top_body_speeds"):
    from derive.__main__ import load_file

    return load_file(MODELS / f"{name}.py")


@pytest.fixture(scope="module")
def top():
    module = _load()
    return module, pipeline.derive(module.build(), pipeline.Steps(out=io.StringIO()))


def _plain(X):
    from sympy.core.function import AppliedUndef

    t = sp.Symbol("t")
    X = sp.Matrix(X)
    ders = {d: sp.Symbol(f"{d.expr.func.__name__}_d") for d in X.atoms(sp.Derivative)}
    X = X.xreplace(ders)
    X = X.xreplace({f: sp.Symbol(f.func.__name__) for f in X.atoms(AppliedUndef) if f.args == (t,)})
    return X.xreplace({s: sp.Symbol(s.name) for s in X.free_symbols})


def _at(X, pt):
    """X at the point, 30 digits (lambdified for mpmath: an xreplace and N of the unsimplified
    speeds' forcing, 9,012 operations, took 36 s)."""
    syms = sorted(X.free_symbols, key=str)
    with mpmath.workdps(30):
        f = sp.lambdify(syms, X, modules="mpmath")
        vals = f(*[mpmath.mpf(pt[s].p) / pt[s].q for s in syms])
        return np.array(vals.tolist(), dtype=object)


def test_equations_in_the_speeds_are_kanes(top):
    from sympy.physics.mechanics import KanesMethod

    module, d = top
    _, q, u, kd, body, N, gravity = module.system()
    km = KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd)
    km.kanes_equations([body], [gravity])
    ours_M, ours_f = d.speeds["mass_matrix"], d.speeds["forcing"]
    theirs_M, theirs_f = _plain(km.mass_matrix), _plain(km.forcing)
    rng = random.Random(1)
    names = sorted({str(s) for s in (ours_M.free_symbols | ours_f.free_symbols | theirs_f.free_symbols)})
    for _ in range(3):
        pt = {sp.Symbol(n): sp.Rational(rng.randint(-1500, 1500), 1000) for n in names}
        for ours, theirs in ((ours_M, theirs_M), (ours_f, theirs_f)):
            with mpmath.workdps(30):
                a, b = _at(ours, pt), _at(theirs, pt)
                assert max(abs(x) for x in (a - b).ravel()) <= 1e-25 * max(abs(x) for x in b.ravel()), (a, b)
    # the rates from the speeds: KanesMethod's kindiffdict
    kin = _plain(sp.Matrix([km.kindiffdict()[x.diff()] for x in q]))
    pt = {sp.Symbol(n): sp.Rational(rng.randint(-1500, 1500), 1000) for n in ("q1", "q2", "q3", "u1", "u2", "u3")}
    with mpmath.workdps(30):
        assert max(abs(x) for x in (_at(d.speeds["kinematics"], pt) - _at(kin, pt)).ravel()) < 1e-25


def test_the_operator_in_the_angles_is_the_tops(top):
    """About the hanging rest (l < 0) the rates and the speeds coincide: M = diag(A + m l^2,
    A + m l^2, C), K = diag(-m g l, -m g l, 0)."""
    _, d = top
    A, C, m, g, l = sp.symbols("A C m g l")
    at0 = {sp.Symbol(f"q{i}"): 0 for i in (1, 2, 3)}
    M, K = (X.xreplace(at0).applyfunc(sp.simplify) for X in (d.operator.M, d.operator.K))
    assert M == sp.diag(A + m * l**2, A + m * l**2, C)
    assert K == sp.diag(-m * g * l, -m * g * l, 0)


def test_speeds_functions_through_every_backend(top, tmp_path):
    from derive import emit

    module, d = top
    fns = pipeline.functions(d)
    assert {"kinematics", "speeds_mass_matrix", "speeds_forcing"} <= {f.name for f in fns}
    emit.emit(d.model, fns, pipeline.metadata(d), tmp_path / "top_body_speeds")
    E = _finish("top_body_speeds", d.model, d, {f.name: f for f in fns}, tmp_path)
    rng = np.random.default_rng(3)
    defaults = {p.name: p.default for p in d.model.parameters}
    for _ in range(2):
        vals = defaults | {n: float(rng.uniform(-1.2, 1.2)) for n in ("q1", "q2", "q3", "u1", "u2", "u3")}
        for fname in ("kinematics", "speeds_mass_matrix", "speeds_forcing"):
            check_symbolic(E, fname, vals)


def test_speeds_read_as_rates_are_refused_in_one_line():
    module = _load()
    with pytest.raises(Unsupported, match=r"the speed u1 is not the rate of q1 in the angular velocity of B in N"):
        pipeline.derive(module.build_without_kinematics(), pipeline.Steps(out=io.StringIO()))


PENDULUM = textwrap.dedent('''
    import sympy as sp
    from sympy.physics.mechanics import Lagrangian, Particle, Point, ReferenceFrame, dynamicsymbols
    from derive.model import Model, Parameter

    def build():
        th, u = dynamicsymbols("theta u")
        m, l, g = sp.symbols("m l g", positive=True)
        N = ReferenceFrame("N")
        A = N.orientnew("A", "Axis", [th, N.z])
        {angvel}
        O = Point("O")
        O.set_vel(N, 0)
        P = O.locatenew("P", -l * A.y)
        P.v2pt_theory(O, N, A)
        bob = Particle("bob", P, m)
        bob.potential_energy = m * g * P.pos_from(O).dot(N.y)
        frame = {frame}
        return Model(name="pend", title="pendulum", source="test", module=__name__,
                     parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("l", "m", 1.0, "length"),
                                 Parameter("g", "m/s^2", 9.81, "gravity")],
                     coordinates=["theta"], coordinate_units={{"theta": "rad"}}, q=[th], qd=[u], qdd=[],
                     lagrangian=Lagrangian(N, bob), frame=frame, kinematics={kin})
''')


@pytest.mark.parametrize("angvel, frame, kin, match", [
    # u is theta' where it enters: accepted, the pendulum's own equation
    ("A.set_ang_vel(N, u * N.z)", "N", "[]", None),
    # u is 2 theta': refused
    ("A.set_ang_vel(N, 2 * u * N.z)", "N", "[]", "the speed u is not the rate of theta in the angular velocity of A"),
    # nothing to check u against: refused, never guessed
    ("A.set_ang_vel(N, u * N.z)", "None", "[]", "enters no velocity of the model's frames or load points"),
    # with kinematic equations u = 2 theta' is what it says
    ("A.set_ang_vel(N, u / 2 * N.z)", "N", "[u - 2 * th.diff()]", None),
    ("A.set_ang_vel(N, u * N.z)", "N", "[u**2 - th.diff()]", "not linear in the speeds"),
    ("A.set_ang_vel(N, u * N.z)", "N", "[u - 0 * th.diff()]", "cannot be solved for the coordinates' derivatives"),
    ("A.set_ang_vel(N, u * N.z)", "N", "[u - th.diff(), u]", "2 kinematic equations for 1 coordinates"),
])
def test_speeds_checked_or_refused(tmp_path, angvel, frame, kin, match):
    from derive.__main__ import main

    src = tmp_path / "pend.py"
    src.write_text(PENDULUM.format(angvel=angvel, frame=frame, kin=kin))
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        rc = main(["--model", str(src), "--out", str(tmp_path / "out")])
    if match is None:
        assert rc == 0, err.getvalue()
        import json
        meta = json.loads((tmp_path / "out" / "pend" / "metadata.json").read_text())
        assert meta["coordinates"] == ["theta"]
        return
    last = err.getvalue().strip().splitlines()[-1]
    assert rc == 2 and match in last and "Traceback" not in err.getvalue(), err.getvalue()
    assert not (tmp_path / "out" / "pend").exists()


def test_the_kinematic_pendulum_has_the_pendulums_frequency(tmp_path):
    """u = 2 theta' with its kinematic equation: the operator in theta is the pendulum's
    about theta = 0, m l^2 theta'' + m g l theta = 0; in u, theta' = V u with V = 1/2, so
    Mu = V m l^2 V = m l^2/4 and fu = V (-m g l sin theta) = -m g l sin(theta)/2."""
    from derive.__main__ import build, load_file

    src = tmp_path / "pend2.py"
    src.write_text(PENDULUM.format(angvel="A.set_ang_vel(N, u / 2 * N.z)", frame="N", kin="[u - 2 * th.diff()]"))
    d = pipeline.derive(build(load_file(src)), pipeline.Steps(out=io.StringIO()))
    m, l, g, th, u = sp.symbols("m l g theta u")
    M, K = (X[0].subs(th, 0) for X in (d.operator.M, d.operator.K))
    assert sp.simplify(M - m * l**2) == 0 and sp.simplify(K - m * g * l) == 0
    assert sp.simplify(d.speeds["mass_matrix"][0] - m * l**2 / 4) == 0
    assert sp.simplify(d.speeds["forcing"][0] + m * g * l * sp.sin(th) / 2) == 0
    assert sp.simplify(d.speeds["kinematics"][0] - u / 2) == 0
