"""What a sympy.physics.mechanics user writes, derived: a model in dynamicsymbols, symbols with
assumptions, a Particle and a RigidBody with a product of inertia, Lagrangian(), a load on a
Point (tests/models/cart_pendulum_mechanics.py) gives exactly the equations of the same
model in the machinery's symbols (tests/models/cart_pendulum.py) and of sympy's
LagrangesMethod, and sympy's linearize() A and B. Non-smooth forces (sign, Abs, Heaviside,
Max, Min) reach the nonlinear equations and every backend; the linearisation where one is
not differentiable is refused in one line. Every broken model is one line, exit 2.

Tolerances: the backends are compared with the symbolic expressions evaluated by mpmath at
30 digits, to RTOL = 1e-12 of the largest entry, as in tests/generated/test_textbook.py (a few dozen
operations on inputs of order one: rounding is ~1e-14)."""
from __future__ import annotations

import contextlib
import io
import textwrap

import mpmath
import numpy as np
import pytest
import sympy as sp

from derive import pipeline
from tests.generated.test_textbook import BACKENDS, MODELS, _finish, assert_close, call, check_symbolic

def _derive(name):
    from derive.__main__ import build, load_file

    module = load_file(MODELS / f"{name}.py")
    model = build(module)
    return module, model, pipeline.derive(model, pipeline.Steps(out=io.StringIO()))


@pytest.fixture(scope="module")
def both():
    return _derive("cart_pendulum_mechanics"), _derive("cart_pendulum")


def _same(A, B):
    return (sp.Matrix(A) - sp.Matrix(B)).applyfunc(sp.expand) == sp.zeros(*sp.Matrix(A).shape)


def test_one_model_written_both_ways_gives_the_same_equations_exactly(both):
    (_, mm, a), (_, pm, b) = both
    assert [str(s) for s in a.model.q + a.model.qd] == ["x", "theta", "x_d", "theta_d"]
    assert a.inputs == b.inputs == [sp.Symbol("F")]
    for what in ("mass_matrix", "forcing", "equilibrium_residual", "input_matrix"):
        assert _same(getattr(a, what), getattr(b, what)), what
    for X, Y in zip((a.operator.M, a.operator.D, a.operator.K), (b.operator.M, b.operator.D, b.operator.K)):
        assert _same(X, Y)
    assert a.mass_matrix[1, 1] == sp.Symbol("Izz") + sp.Symbol("l") ** 2 * sp.Symbol("m")


def test_equations_and_linearisation_agree_with_lagranges_method(both):
    """LagrangesMethod on the same Lagrangian and load: mass matrix and forcing, and
    linearize()'s A and B at rest, exactly (after simplification)."""
    from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

    (module, _, d), _ = both
    L, q, loads, N = module.system()
    lm = LagrangesMethod(L, q, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    t = dynamicsymbols._t
    F = dynamicsymbols("F")
    names = {qi: sp.Symbol(str(qi.func)) for qi in q}
    sub = {qi.diff(t, 2): sp.Symbol(f"{names[qi]}_dd") for qi in q}
    sub |= {qi.diff(t): sp.Symbol(f"{names[qi]}_d") for qi in q} | names | {F: sp.Symbol("F")}
    plain = lambda X: X.subs(sub).subs({s: sp.Symbol(s.name) for s in X.free_symbols})  # noqa: E731
    assert sp.simplify(plain(lm.mass_matrix) - d.mass_matrix) == sp.zeros(2, 2)
    assert sp.simplify(plain(lm.forcing) - d.forcing) == sp.zeros(2, 1)
    op = {qi: 0 for qi in q} | {qi.diff(t): 0 for qi in q}
    A, B, _ = lm.linearize(q_ind=q, qd_ind=[qi.diff(t) for qi in q], A_and_B=True, op_point=op, simplify=True)
    M, D, K = (X.subs({sp.Symbol("x"): 0, sp.Symbol("theta"): 0}) for X in (d.operator.M, d.operator.D, d.operator.K))
    Ainv = M.inv()
    A_ours = sp.Matrix(sp.BlockMatrix([[sp.zeros(2), sp.eye(2)], [-Ainv * K, -Ainv * D]]))
    B_ours = sp.Matrix(sp.BlockMatrix([[sp.zeros(2, 1)], [Ainv * d.input_matrix.subs(sp.Symbol("theta"), 0)]]))
    assert sp.simplify(plain(A) - A_ours) == sp.zeros(4, 4)
    assert sp.simplify(plain(B) - B_ours) == sp.zeros(4, 1)


def test_kinetic_energy_helper_takes_a_full_inertia_tensor():
    from derive import mechanics as mech

    w = sp.Matrix(sp.symbols("w1:4"))
    I = sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"I{min(i, j)}{max(i, j)}"))
    assert sp.expand(mech.kinetic_energy(omega=w, inertia=I) - (w.T * I * w)[0] / 2) == 0
    with pytest.raises(ValueError, match="symmetric"):
        mech.kinetic_energy(omega=w, inertia=sp.Matrix([[1, 2, 0], [0, 1, 0], [0, 0, 1]]))


# --------------------------------------------------------------------------- non-smooth


@pytest.fixture(scope="module")
def belt(tmp_path_factory):
    from derive import emit

    out = tmp_path_factory.mktemp("belt")
    _, model, d = _derive("belt_friction")
    fns = pipeline.functions(d)
    emit.emit(model, fns, pipeline.metadata(d), out / "belt_friction")
    return _finish("belt_friction", model, d, {f.name: f for f in fns}, out)


def test_non_smooth_forces_in_the_nonlinear_equations_and_the_operator(belt):
    d = belt.d
    x, x_d, m, k, k_s, a, mu, g, c, v = sp.symbols("x x_d m k k_s a mu g c v")
    want = -k * x - k_s * sp.Max(0, x - a) - mu * m * g * sp.sign(x_d - v) - c * sp.Abs(x_d) * x_d
    for xv, vv in ((0.5, 0.3), (0.1, -0.2), (-0.3, 0.7), (0.25, 0.5)):
        pt = {x: xv, x_d: vv, m: 1, k: 4, k_s: 40, a: 0.2, mu: 0.3, g: 9.81, c: 0.1, v: 0.5}
        assert abs(float(d.forcing[0].subs(pt)) - float(want.subs(pt))) < 1e-12
    pt = {m: 1, k: 4, k_s: 40, a: 0.2, mu: 0.3, g: 9.81, c: 0.1, v: 0.5}
    assert d.operator.D.subs(pt)[0] == 0 and d.operator.K.subs(pt | {x: 0.3})[0] == 44
    assert d.operator.K.subs(pt | {x: 0.1})[0] == 4 and d.operator.K.subs(pt | {x: 0.2})[0] is sp.nan
    assert d.operator.D.subs(pt | {v: 0})[0] is sp.nan  # the belt at rest: Coulomb at rest


def test_non_smooth_functions_through_every_backend(belt):
    """forcing, operator and equilibrium_residual at points on both sides of every kink and at
    the kinks, in C, NumPy, CasADi and mpmath, against the symbolic result (NaN where the
    operator does not exist: x = a, v = 0)."""
    E = belt
    defaults = {p.name: p.default for p in E.model.parameters}
    points = [dict(x=0.5, x_d=0.3), dict(x=0.1, x_d=-0.2), dict(x=-0.3, x_d=0.5), dict(x=0.2, x_d=0.0),
              dict(x=0.2, x_d=0.0, v=0.0), dict(x=0.3, x_d=0.7, v=-0.5)]
    for pt in points:
        vals = defaults | pt | {"p": 0.7, "p_re": -0.3, "p_im": 1.1}
        for fname, fn in E.functions.items():
            syms = [s for _, ss in fn.inputs for s in ss]
            with mpmath.workdps(30):
                want = [np.array(sp.lambdify(syms, mat, modules="mpmath")(*[mpmath.mpf(vals[str(s)]) for s in syms])
                                 .tolist(), dtype=float) for _, mat in fn.outputs]
            for backend in BACKENDS:
                got = call(E, fname, vals, backend)
                for o, w in zip(got, want):
                    w = w.reshape(o.shape)
                    assert np.array_equal(np.isnan(o), np.isnan(w)), (backend, fname, pt, o, w)
                    ok = ~np.isnan(w)
                    assert_close(o[ok], w[ok], what=f"{backend} {fname} {pt}")
    # the kinks are NaN in the operator, numbers elsewhere
    K = call(E, "operator", defaults | {"x": 0.2}, "c")[2]
    assert np.isnan(K).all() and call(E, "operator", defaults | {"x": 0.3}, "c")[2][0, 0] == 44.0


def test_coulomb_friction_at_rest_derives_its_equations_and_no_operator(tmp_path):
    """A block with Coulomb friction mu m g sign(x') about rest: the full nonlinear
    equations derive and are emitted (sign through every backend, sign(0) = 0); the
    operator's damping entry, which needs the derivative of sign at 0, is NaN at every set,
    and metadata names the term (the runtime refuses the operator with it)."""
    import json

    from derive.__main__ import main

    src = tmp_path / "block.py"
    src.write_text(BODY.format(change="Q = {'x': -sp.Rational(3, 10) * m * 9.81 * sp.sign(x_d)}"))
    assert main(["--model", str(src), "--out", str(tmp_path / "out")]) == 0
    meta = json.loads((tmp_path / "out" / "broken" / "metadata.json").read_text())
    assert meta["nondifferentiable"] == [{"term": "sign(x_d)", "argument_at_reference": "0"}]
    E = _finish("broken", None, None, {}, tmp_path / "out")
    for backend in BACKENDS:
        for xd, want in ((0.3, -0.3 * 9.81 - 4 * 0.1), (-0.3, 0.3 * 9.81 - 4 * 0.1), (0.0, -4 * 0.1)):
            f = call(E, "forcing", {"m": 1.0, "k": 4.0, "x": 0.1, "x_d": xd}, backend)[0]
            assert_close(f.ravel(), np.array([want]), what=f"{backend} forcing at x_d = {xd}")
        M, D, K = call(E, "operator", {"m": 1.0, "k": 4.0, "x": 0.0}, backend)
        assert np.isnan(D).all() and M.ravel()[0] == 1.0 and K.ravel()[0] == 4.0, backend


# --------------------------------------------------------------------------- one-line refusals

BODY = textwrap.dedent('''
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols
    from derive.model import Load, Model, Parameter

    def build():
        x, x_d, x_dd = sp.symbols("x x_d x_dd")
        m, k = sp.symbols("m k")
        L = m * x_d**2 / 2 - k * x**2 / 2
        Q = {{}}
        extra = {{}}
        {change}
        return Model(name="broken", title="broken", source="test", module=__name__,
                     parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 4.0, "spring")],
                     coordinates=["x"], coordinate_units={{"x": "m"}}, q=[x], qd=[x_d], qdd=[x_dd],
                     lagrangian=L, generalized_forces=Q, **extra)
''')


@pytest.mark.parametrize("change, match", [
    ("Q = {'y': k * x}", "generalised force on 'y', which is not a coordinate"),
    ("L = L + sp.nan", "not a finite number"),
    ("L = L + sp.Integral(x**2, x)", "an integral"),
    ("L = 'm*x_d**2/2'", "not a SymPy expression (a str)"),
    ("L = [L]", "not a SymPy expression (a list)"),
    ("L = L + sp.Function('f')(x)", "f(x) is a function that the model does not declare"),
    ("L = L + sp.Piecewise((x, x > 0), (0, True))", "Piecewise"),
    ("L = L - sp.Heaviside(x - 1)", "the Lagrangian jumps where x - 1 = 0"),
    ("L = L + sp.Abs(x_d)", "a non-smooth function of the rates"),
    ("Q = {'x': dynamicsymbols('F').diff()}; extra = dict(signals=[__import__('derive.model', fromlist=['Signal'])"
     ".Signal('F', 'N', 'force', order=0)])", "differentiated 1 times, beyond its declared order 0"),
    ("extra = dict(nonholonomic=[x_d - x])", "nonholonomic"),
    ("extra = dict(holonomic=[x - 1])", "holonomic"),
    ("extra = dict(identities={'boom': lambda: [1 / 0]})", "identity: boom failed: ZeroDivisionError"),
])
def test_every_broken_model_is_one_line_exit_2(tmp_path, change, match):
    from derive.__main__ import main

    src = tmp_path / "broken.py"
    src.write_text(BODY.format(change=change))
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        rc = main(["--model", str(src), "--out", str(tmp_path / "out")])
    last = err.getvalue().strip().splitlines()[-1]
    assert rc == 2 and match in last and last.startswith("derive: "), err.getvalue()
    assert "Traceback" not in err.getvalue()
    assert not (tmp_path / "out" / "broken").exists()


# --------------------------------------------------------------------------- holonomic constraints


def _plain(X, q):
    """sympy's dynamicsymbols as the machinery's symbols: q, q' -> q_d, q'' -> q_dd, F(t) -> F."""
    from sympy.core.function import AppliedUndef
    from sympy.physics.mechanics import dynamicsymbols

    t = dynamicsymbols._t
    X = sp.Matrix(X)
    sub = {qi.diff(t, 2): sp.Symbol(f"{qi.func}_dd") for qi in q}
    sub |= {qi.diff(t): sp.Symbol(f"{qi.func}_d") for qi in q}
    X = X.subs(sub)
    X = X.subs({f: sp.Symbol(str(f.func)) for f in X.atoms(AppliedUndef)})
    return X.subs({s: sp.Symbol(s.name) for s in X.free_symbols})


def _A_B(d, at):
    M, D, K = (X.subs(at) for X in (d.operator.M, d.operator.D, d.operator.K))
    n = M.rows
    Mi = M.inv()
    A = sp.Matrix(sp.BlockMatrix([[sp.zeros(n), sp.eye(n)], [-Mi * K, -Mi * D]]))
    B = sp.Matrix(sp.BlockMatrix([[sp.zeros(n, d.input_matrix.cols)], [Mi * d.input_matrix.subs(at)]]))
    return A, B


def test_nonminimal_pendulum_carries_a_multiplier_and_linearises_as_sympy_does():
    """test_nonminimal_pendulum of sympy.physics.mechanics with a force F(t) across: the
    augmented equations are LagrangesMethod's (M q'' + Phi_q' lambda = f with its lambda),
    and the operator in the independent q2 at (q1, q2) = (L, 0) gives linearize()'s A and B."""
    from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

    module, _, d = _derive("nonminimal_pendulum")
    L, q, hol, loads, N = module.system()
    lm = LagrangesMethod(L, q, hol_coneqs=hol, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    # LagrangesMethod's eom, M q'' - f + Phi_q' lambda (its solve_multipliers' lambda), and
    # the constraint's acceleration row of its mass_matrix_full
    unknowns = sp.Matrix([sp.Symbol("q1_dd"), sp.Symbol("q2_dd"), sp.Symbol("lam1")])
    eom = _plain(lm.eom.subs(lm.lam_vec[0], sp.Symbol("lam1")), q)
    assert sp.simplify(eom - (d.mass_matrix * unknowns - d.forcing)[:2, :]) == sp.zeros(2, 1)
    assert sp.simplify(_plain(lm.mass_matrix_full[4:, 2:], q) - d.mass_matrix[2:, :]) == sp.zeros(1, 3)
    assert sp.simplify(_plain(lm.forcing_full[4:, :], q) - d.forcing[2:, :]) == sp.zeros(1, 1)
    t = dynamicsymbols._t
    Lsym = sp.Symbol("L")
    op = {q[0]: Lsym, q[1]: 0, q[0].diff(t): 0, q[1].diff(t): 0, q[0].diff(t, 2): 0, q[1].diff(t, 2): 0}
    op |= {dynamicsymbols("F"): 0}
    op.update(lm.solve_multipliers(op_point=op))
    A, B, _ = lm.linearize([q[1]], [q[1].diff(t)], [q[0]], [q[0].diff(t)], op_point=op, A_and_B=True)
    A_ours, B_ours = _A_B(d, {sp.Symbol("q1"): Lsym, sp.Symbol("q2"): 0})
    assert sp.simplify(_plain(A, q) - A_ours) == sp.zeros(2, 2)
    assert sp.simplify(_plain(B, q) - B_ours) == sp.zeros(2, 1)
    assert d.constraints["dependent"] == ["q1"] and d.constraints["multipliers"] == ["lam1"]
    assert d.route_agreement is None  # one route: no agreement to claim
    # the constraint force -Phi_q' lambda, at rest hanging: lambda = m g/(2 L), force -m g along q1
    qc = dict(d.model.quantities["constraint_forces"][1])["Qc"]
    lam0 = sp.solve((d.mass_matrix * sp.Matrix(sp.symbols("a1 a2 lam1")) - d.forcing).subs(
        {sp.Symbol("q1"): Lsym, sp.Symbol("q2"): 0, sp.Symbol("q1_d"): 0, sp.Symbol("q2_d"): 0, sp.Symbol("F"): 0}),
        sp.symbols("a1 a2 lam1"), dict=True)[0]
    assert sp.simplify(qc.subs(lam0).subs({sp.Symbol("q1"): Lsym, sp.Symbol("q2"): 0})
                       - sp.Matrix([-sp.Symbol("m") * sp.Symbol("g"), 0])) == sp.zeros(2, 1)


def test_disc_on_an_incline_eliminates_theta_and_linearises_as_sympy_does():
    """test_disc_on_an_incline_plane with a torque tau(t): y = R theta is solved for theta;
    y'' = 2 g sin(alpha)/3 as sympy's rhs(), and linearize()'s A and B with theta dependent."""
    from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

    module, _, d = _derive("disc_incline")
    L, q, hol, loads, N = module.system()
    lm = LagrangesMethod(L, q, hol_coneqs=hol, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    assert d.model.coordinates == ["y"] and d.constraints["eliminated"] == {"theta": "y/R"}
    m, g, alpha, R, tau = sp.symbols("m g alpha R tau")
    assert sp.simplify(d.forcing[0] / d.mass_matrix[0, 0] - (2 * g * sp.sin(alpha) / 3 + 2 * tau / (3 * m * R))) == 0
    t = dynamicsymbols._t
    op = {q[0]: 0, q[1]: 0, q[0].diff(t): 0, q[1].diff(t): 0, q[0].diff(t, 2): 0, q[1].diff(t, 2): 0,
          dynamicsymbols("tau"): 0}
    op.update(lm.solve_multipliers(op_point=op))
    A, B, _ = lm.linearize([q[0]], [q[0].diff(t)], [q[1]], [q[1].diff(t)], op_point=op, A_and_B=True)
    A_ours, B_ours = _A_B(d, {sp.Symbol("y"): 0})
    assert sp.simplify(_plain(A, q) - A_ours) == sp.zeros(2, 2)
    assert sp.simplify(_plain(B, q) - B_ours) == sp.zeros(2, 1)


def test_constrained_models_emit_and_compile(tmp_path):
    """Both constrained models through the emitter: every function in C, NumPy, CasADi and
    mpmath against the symbolic outputs (the dependent coordinates, the constraint forces)."""
    from derive import emit

    rng = np.random.default_rng(3)
    for name in ("nonminimal_pendulum", "disc_incline"):
        _, model, d = _derive(name)
        fns = pipeline.functions(d)
        emit.emit(model, fns, pipeline.metadata(d), tmp_path / name)
        E = _finish(name, model, d, {f.name: f for f in fns}, tmp_path)
        for fname, fn in E.functions.items():
            check_symbolic(E, fname, {str(s): rng.uniform(0.5, 1.5) for _, ss in fn.inputs for s in ss})
