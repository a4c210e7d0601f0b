"""The machinery's guarantees: explicit time is never dropped, emitted functions are called in
their documented order by every backend, what cannot be derived is refused at derive time
with a message naming the cause, bad names never reach the compiler, and one model's
generated files depend on the shared machinery and on that model alone."""
from __future__ import annotations

import ctypes
import inspect
import io
import json
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import sympy as sp

from derive import mechanics as mech
from derive import pipeline
from derive.model import TIME, Load, Model, Parameter, Signal, Unsupported
from tests.conftest import GENERATED, ROOT

MODELS = sorted(p.name for p in GENERATED.iterdir() if (p / "metadata.json").exists())


# --------------------------------------------------------------------- explicit time


def test_time_derivative_includes_the_partial_derivative_in_t():
    """d/dt [a sin(w t) cos q] = a w cos(w t) cos q - a sin(w t) sin q q'."""
    q, qd, a, w = sp.symbols("q q_d a w")
    e = a * sp.sin(w * TIME) * sp.cos(q)
    want = a * w * sp.cos(w * TIME) * sp.cos(q) - a * sp.sin(w * TIME) * sp.sin(q) * qd
    assert sp.simplify(mech.time_derivative(e, [q], [qd]) - want) == 0


def test_pendulum_on_a_moving_support_keeps_the_support_acceleration():
    """Pendulum of length l hanging from a support at height a sin(w t): the true equation is
    m l^2 q'' + m l (g - a w^2 sin(w t)) sin q = 0. Dropping d/dt|explicit would leave out
    a l m w^2 sin(w t) sin q ... the term the old machinery lost."""
    q, qd, qdd, m, l, g, a, w = sp.symbols("q q_d q_dd m l g a w")
    z = a * sp.sin(w * TIME)
    x, y = l * sp.sin(q), z - l * sp.cos(q)
    vx, vy = (mech.time_derivative(c, [q], [qd]) for c in (x, y))
    L = m * (vx**2 + vy**2) / 2 - m * g * y
    (E,) = mech.lagrange_equations(L, [q], [qd], [qdd])
    assert sp.simplify(E - (m * l**2 * qdd + m * l * (g - a * w**2 * sp.sin(w * TIME)) * sp.sin(q))) == 0
    Mq, f = mech.mass_matrix_form(L, [q], [qd])
    assert sp.simplify(Mq[0, 0] * qdd - f[0] - E) == 0


def test_signal_rungs_are_chained_and_an_undeclared_rung_is_refused():
    s = Signal("zs", "m", "support height", input=False, order=1)
    q, qd = sp.symbols("q q_d")
    zs, zs_d = s.symbols
    assert mech.time_derivative(zs * q, [q], [qd], signals=[s]) == zs_d * q + zs * qd
    with pytest.raises(Unsupported, match="zs_d"):
        mech.time_derivative(zs_d, [q], [qd], signals=[s])


# --------------------------------------------------------------------- small models


def _oscillator(**kw) -> Model:
    """m x'' + c x' + k x = 0 with a force signal: the smallest model with every input kind."""
    m, c, k = sp.symbols("m c k")
    x, xd, xdd = sp.symbols("x x_d x_dd")
    params = [Parameter("m", "kg", 1.0, "mass"), Parameter("c", "N s/m", 0.1, "damping"),
              Parameter("k", "N/m", 4.0, "stiffness")]
    base = dict(name="probe", title="probe", source="test", module=__name__, parameters=params,
                coordinates=["x"], coordinate_units={"x": "m"}, q=[x], qd=[xd], qdd=[xdd],
                lagrangian=m * xd**2 / 2 - k * x**2 / 2, dissipation=c * xd**2 / 2,
                symmetric_zero=["x"])
    base.update(kw)
    return Model(**base)


def _derive(model):
    return pipeline.derive(model, pipeline.Steps(out=io.StringIO()))


def test_damped_oscillator_operator_and_its_parts():
    d = _derive(_oscillator())
    m, c, k = sp.symbols("m c k")
    assert (d.operator.M, d.operator.D, d.operator.K) == (sp.Matrix([[m]]), sp.Matrix([[c]]), sp.Matrix([[k]]))
    names = [f.name for f in pipeline.functions(d)]
    assert "operator_parts" in names and "input_matrix" not in names


def test_input_signal_gives_the_input_matrix():
    F = Signal("Fx", "N", "applied force")
    d = _derive(_oscillator(signals=[F], generalized_forces={"x": F.symbol}))
    assert d.inputs == [F.symbol] and d.input_matrix == sp.Matrix([[1]])


@pytest.mark.parametrize("bad, match", [
    ({"coordinates": ["q"], "q": [sp.Symbol("q")], "qd": [sp.Symbol("q_d")], "qdd": [sp.Symbol("q_dd")],
      "coordinate_units": {"q": "m"}, "symmetric_zero": ["q"]}, "coordinate 'q'"),
    ({"parameters": [Parameter("params", "kg", 1.0, "mass")]}, "parameter 'params'"),
    ({"parameters": [Parameter("t3", "kg", 1.0, "mass")]}, "parameter 't3'"),
    ({"parameters": [Parameter("double", "kg", 1.0, "mass")]}, "parameter 'double'"),
    ({"parameters": [Parameter("t", "s", 1.0, "a time")]}, "t is time"),
    ({"signals": [Signal("sqrt", "N", "force")]}, "signal 'sqrt'"),
    ({"nonholonomic": ["rolling"]}, "nonholonomic"),
    ({"cyclic": {"x": sp.Symbol("px")}, "lagrangian": sp.Symbol("m") * sp.Symbol("x_d")**2 / 2},
     "every coordinate is cyclic"),
    ({"steady": {"x": 1}}, "x \\(turning steadily\\) appears in the Lagrangian"),
    ({"generalized_forces": {"y": 1}}, "'y', which is not a coordinate"),
])
def test_what_cannot_be_derived_is_refused_naming_it(bad, match):
    with pytest.raises(Unsupported, match=match):
        _derive(_oscillator(**bad))


def test_a_load_whose_velocity_is_not_affine_in_the_rates_is_refused():
    x, xd = sp.symbols("x x_d")
    with pytest.raises(Unsupported, match="not affine"):
        _derive(_oscillator(loads=[Load(sp.Matrix([1]), sp.Matrix([xd**2]))]))
    assert mech.load_forces(sp.Matrix([2, 0]), sp.Matrix([xd * sp.cos(x), xd * sp.sin(x)]), [xd]) == [2 * sp.cos(x)]


def _write_model(path, body: str):
    path.write_text(textwrap.dedent(body))
    return path


MODEL_FILE = '''
    import sympy as sp
    from derive.model import Model, Parameter, Signal

    NAME = "{name}"
    x, xd, xdd = sp.symbols("x x_d x_dd")
    th, thd, thdd = sp.symbols("th th_d th_dd")


    def build():
        m, k, c = sp.symbols("m k c")
        tau = Signal("tau", "N m", "torque on the wheel")
        return Model(
            name=NAME, title="cart with a wheel", source="test", module=__name__,
            parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 1.0, "spring"),
                        Parameter("c", "N s/m", 0.1, "damper")],
            coordinates=["x", "th"], coordinate_units={{"x": "m", "th": "rad"}},
            q=[x, th], qd=[xd, thd], qdd=[xdd, thdd],
            lagrangian=m * xd**2 / 2 + m * thd**2 / 4 - k * x**2 / 2,
            dissipation=c * xd**2 / 2, signals=[tau], generalized_forces={{"th": tau.symbol}},
            cyclic={{"th": {momentum}}}, symmetric_zero=["x"])
'''


def test_model_anywhere_with_a_zero_momentum_and_empty_inputs_compiles_pedantic(tmp_path):
    """A model file outside the repository, a cyclic momentum given as 0 (a constant, not an
    input) and no equilibrium unknowns (qe empty): derived, emitted, and its C compiles under
    -std=c99 -Wall -Wextra -Werror -pedantic. A force on the cyclic coordinate is refused."""
    src = _write_model(tmp_path / "wheel_cart.py", MODEL_FILE.format(name="wheel_cart", momentum="0"))
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 2 and "force acts on the cyclic coordinate th" in proc.stderr
    assert proc.stderr.count("\n") >= 1 and "Traceback" not in proc.stderr
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    src.write_text(src.read_text().replace(', generalized_forces={"th": tau.symbol}', ""))
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    gen = tmp_path / "out" / "wheel_cart"
    meta = json.loads((gen / "metadata.json").read_text())
    assert meta["momenta"] == [] and meta["equilibrium_coordinates"] == []
    assert [i["name"] for i in meta["functions"]["operator"]["inputs"]] == ["params", "qe"]
    assert "wheel_cart.py" in (gen / "wheel_cart.c").read_text().splitlines()[1]
    lib = tmp_path / "lib.so"
    cc = subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "-shared",
                         "-fPIC", "-o", str(lib), str(gen / "wheel_cart.c"), "-lm"], capture_output=True, text=True)
    assert cc.returncode == 0, cc.stderr
    # the operator through C in the documented order: M = m, D = c (the wheel's row is gone)
    fn = ctypes.CDLL(str(lib)).wheel_cart_operator
    P = (ctypes.c_double * 3)(2.0, 3.0, 0.5)
    outs = [(ctypes.c_double * 1)() for _ in range(3)]
    fn(P, (ctypes.c_double * 1)(), *outs)
    assert [o[0] for o in outs] == [2.0, 0.5, 3.0]
    # the runtime's compiled batch call with the empty qe, in NumPy's shapes (1x1 matrices)
    from gyro import cbackend
    from gyro.models import load

    model = load(gen)
    M, D, K = cbackend.batch_function("wheel_cart", "operator")([[2.0, 3.0, 0.5]] * 2, np.empty((2, 0)))
    assert M.shape == (2, 1, 1) and model.numpy.operator([2.0, 3.0, 0.5], [])[0].shape == (1, 1)
    np.testing.assert_array_equal(np.concatenate([M, D, K], axis=1)[:, :, 0], [[2.0, 0.5, 3.0]] * 2)


@pytest.mark.parametrize("body, match", [
    ("x = 1\n", "defines no build"),
    ("def build():\n    return 42\n", "returned int"),
    ("import no_such_module_here\n", "importing it failed: ModuleNotFoundError"),
])
def test_a_file_that_is_not_a_model_exits_2_in_one_line(tmp_path, body, match):
    src = _write_model(tmp_path / "notamodel.py", body)
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 2 and match in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


# --------------------------------------------------------------------- call order


@pytest.mark.parametrize("name", MODELS)
def test_every_backend_declares_the_documented_argument_order(name):
    """metadata.json lists each function's inputs in call order; the C prototypes, the NumPy
    signatures and the CasADi input names are that order."""
    import importlib

    meta = json.loads((GENERATED / name / "metadata.json").read_text())["functions"]
    header = (GENERATED / name / f"{name}.h").read_text()
    nf = importlib.import_module(f"generated.{name}.numpy_functions")
    cf = importlib.import_module(f"generated.{name}.casadi_functions")
    for fname, f in meta.items():
        order = [i["name"] for i in f["inputs"]]
        proto = re.search(rf"void {name}_{fname}\(([^)]*)\);", header).group(1)
        assert re.findall(r"const double \*(\w+)", proto) == order, fname
        assert re.findall(r"double \*out_(\w+)", proto) == [o["name"] for o in f["outputs"]], fname
        assert list(inspect.signature(getattr(nf, fname)).parameters) == order, fname
        assert getattr(cf, fname).name_in() == order, fname


@pytest.mark.parametrize("name", MODELS)
def test_compiled_batch_functions_agree_with_numpy_on_every_function(name):
    """gyro.cbackend reads the argument lengths from metadata: every function through C over
    a batch equals NumPy (the gimbal operator once came back with M = 0.2 for 0.015)."""
    from gyro import cbackend
    from gyro.models import load

    model = load(name)
    meta = model.meta["functions"]
    rng = np.random.default_rng(7)
    P = model.vector(model.defaults)
    for fname, f in meta.items():
        args = []
        for i in f["inputs"]:
            k = len(i["symbols"])
            args.append(np.tile(P, (3, 1)) * rng.uniform(0.9, 1.1, (3, k)) if i["name"] == "params"
                        else rng.uniform(-0.5, 0.5, (3, k)) + (0.3 if i["name"] in ("momenta",) else 0))
        got = cbackend.batch_function(name, fname)(*args)
        want = getattr(model.numpy, fname)(*args)
        want = list(want) if isinstance(want, tuple) else [want]
        for g, w in zip(got, want):
            # C and NumPy evaluate the same expressions in another order: an entry whose terms
            # cancel (a mass-matrix coupling at random angles) differs by rounding of its
            # terms, of the size eps times the output's largest entry, not of its own value
            w = np.asarray(w).reshape(g.shape)
            np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-14 * float(np.max(np.abs(w), initial=0.0)) + 1e-300,
                                       err_msg=fname)


# --------------------------------------------------------------------- input hash


def test_a_models_input_hash_covers_the_machinery_and_itself_only():
    from derive import emit

    files = emit.machinery_files()
    assert files and not [f for f in files if "models" in f.relative_to(ROOT).parts]
    assert {f.suffix for f in files} == {".py", ".j2"}
    # the command line and the scheduling over processes cannot change a byte: not inputs
    assert not [f for f in files if f.name in ("__main__.py", "parallel.py") and f.parent.name == "derive"]
    tg = ROOT / "derive" / "models" / "torsion_gyrocompass.py"
    before = emit.input_hash(tg)
    probe = ROOT / "derive" / "models" / "_zz_probe_model.py"  # not a model to discovery (tests run in parallel)
    try:
        probe.write_text("# a new model beside the others\n")
        assert emit.input_hash(tg) == before
    finally:
        probe.unlink()
    meta = json.loads((GENERATED / "torsion_gyrocompass" / "metadata.json").read_text())
    assert meta["generated"]["input_hash"] == before


def test_models_are_found_without_a_list():
    from derive.models import MODELS as found

    on_disk = {p.stem for p in (ROOT / "derive" / "models").glob("*.py") if not p.stem.startswith("_")}
    assert set(found) == on_disk and set(MODELS) <= set(found)


# --------------------------------------------------------------------- emitted model quantities


def test_gimbal_quantities_are_emitted_and_agree_with_the_runtime():
    from gyro.systems import gimbal_gyroscope as gimbal
    from gyro.models import load

    model = load("gimbal_gyroscope")
    p = model.defaults
    P = model.vector(p)
    q, qd = np.array([0.3, 1.1, -0.2]), np.array([0.7, -0.4, 150.0])
    H, L, M, E = model.numpy.first_integrals(P, q, qd)
    ref = gimbal.integrals(p, q, qd)
    np.testing.assert_allclose([H, L, M], [ref["H"], ref["L"], ref["M"]], rtol=1e-13)
    assert model.numpy.gravity_moment(P)[0] == pytest.approx(p["P1"] * p["eta30"] + p["P"] * p["l"], rel=1e-15)
    motion = gimbal.Motion(p, 1.2, 0.3, 1.0, 200.0)
    cf = gimbal.ClosedForm(motion)
    b, g, HL = model.numpy.closed_form(P, [1.2, 0.3, 1.0, 200.0])
    np.testing.assert_allclose(b, cf.b, rtol=1e-9)
    np.testing.assert_allclose(g, [cf.g2, cf.g3], rtol=1e-9)
    np.testing.assert_allclose(HL, [cf.H, cf.L], rtol=1e-13)
    th0 = 1.2
    stat = gimbal.stationary_motion(p, th0, 2.0)
    I = stat.integrals0
    U1, dU1, d2U1 = model.numpy.routh_function(P, [th0], [I["H"], I["L"]])
    assert abs(dU1) < 1e-12 * (abs(U1) + 1)  # a stationary motion: U1' = 0
    assert d2U1 == pytest.approx(gimbal.U1_second(p, th0, I["H"], I["L"]), rel=1e-12)


# --------------------------------------------------------------------- found in review


def _polar(**kw) -> Model:
    """A particle in the plane in polar coordinates (r, ph), on a spring k to the origin."""
    m, k, Om = sp.symbols("m k Om")
    r, ph, rd, phd, rdd, phdd = sp.symbols("r ph r_d ph_d r_dd ph_dd")
    base = dict(name="polar", title="polar", source="test", module=__name__,
                parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 4.0, "spring"),
                            Parameter("Om", "rad/s", 1.0, "rate", kind="real")],
                coordinates=["r", "ph"], coordinate_units={"r": "m", "ph": "rad"},
                q=[r, ph], qd=[rd, phd], qdd=[rdd, phdd],
                lagrangian=m * (rd**2 + r**2 * phd**2) / 2 - k * r**2 / 2)
    base.update(kw)
    return Model(**base)


def test_an_input_that_turns_with_a_steady_or_cyclic_coordinate_is_refused():
    """A force u along the fixed x axis on a particle turning steadily in ph: B would be
    (cos(Om t), -r sin(Om t)), a function of time, not the constant it would come out as."""
    u = Signal("u", "N", "force along x", order=0)
    r, ph, rd, phd = sp.symbols("r ph r_d ph_d")
    v = sp.Matrix([rd * sp.cos(ph) - r * sp.sin(ph) * phd, rd * sp.sin(ph) + r * sp.cos(ph) * phd])
    load = Load(sp.Matrix([u.symbol, 0]), v)
    with pytest.raises(Unsupported, match="depends on ph"):
        _derive(_polar(signals=[u], loads=[load], steady={"ph": sp.Symbol("Om")}))
    lag = _polar().lagrangian + u.symbol * r * sp.cos(ph)
    with pytest.raises(Unsupported, match="input term of the Lagrangian depends on ph"):
        _derive(_polar(signals=[u], lagrangian=lag, steady={"ph": sp.Symbol("Om")}))
    with pytest.raises(Unsupported, match="input term of the Lagrangian depends on ph"):
        _derive(_polar(signals=[u], lagrangian=lag, cyclic={"ph": sp.Symbol("beta")}))


def test_a_force_on_a_cyclic_coordinate_is_refused():
    c = sp.Symbol("c")
    params = _polar().parameters + [Parameter("c", "N m s", 0.1, "damping")]
    with pytest.raises(Unsupported, match="force acts on the cyclic coordinate ph"):
        _derive(_polar(parameters=params, dissipation=c * sp.Symbol("ph_d")**2 / 2, cyclic={"ph": sp.Symbol("beta")}))


@pytest.mark.parametrize("kw, match", [
    ({"lagrangian": sp.Symbol("m") * sp.Symbol("x_d")**2 / 2 - sp.Symbol("kk") * sp.Symbol("x")**2},
     "kk in the Lagrangian or the forces is not declared"),
    ({"parameters": [Parameter("entry", "kg", 1.0, "mass")]}, "parameter 'entry'"),
    ({"parameters": [Parameter("FP_NAN", "kg", 1.0, "mass")]}, "parameter 'FP_NAN'"),
    ({"parameters": [Parameter("M_E", "kg", 1.0, "mass")]}, "parameter 'M_E'"),
    ({"quantities": {"forcing": (["params"], [("f", sp.Matrix([sp.Symbol("m")]))], "clash")}},
     "emitted twice"),
    ({"quantities": {"energy": ([("n", [sp.Symbol("x")])], [("E", sp.Matrix([sp.Symbol("x")]))], "n")}},
     "input group 'n'"),
    ({"quantities": {"energy": ([("x", [sp.Symbol("x")])], [("E", sp.Matrix([sp.Symbol("x")]))], "x")}},
     "input group 'x'"),
    ({"quantities": {"if": (["params"], [("E", sp.Matrix([sp.Symbol("m")]))], "keyword")}}, "function 'if'"),
])
def test_names_and_symbols_that_would_break_the_emitted_code_are_refused(kw, match):
    model = _oscillator(**kw)
    with pytest.raises(Unsupported, match=match):
        d = _derive(model)
        from derive.emit import check_names

        check_names(pipeline.functions(d))


def test_routh_reduction_refuses_what_it_cannot_reduce():
    ph_d = sp.Symbol("ph_d")
    with pytest.raises(Unsupported, match="not quadratic in ph_d"):
        _derive(_polar(lagrangian=_polar().lagrangian + ph_d**4, cyclic={"ph": sp.Symbol("beta")}))
    r_d = sp.Symbol("r_d")
    with pytest.raises(Unsupported, match="every coordinate is cyclic"):
        _derive(_polar(lagrangian=sp.Symbol("m") * (r_d**2 + ph_d**2) / 2,
                       cyclic={"r": sp.Symbol("pr"), "ph": sp.Symbol("beta")}))


def test_a_coordinate_absent_only_by_sin2_plus_cos2_is_ignorable():
    """Body rates of a disc spinning by ph: w1^2 + w2^2 carries ph until simplified."""
    r, ph, rd, phd = sp.symbols("r ph r_d ph_d")
    w1, w2 = rd * sp.cos(ph), rd * sp.sin(ph)
    model = _polar(lagrangian=sp.Symbol("m") * (w1**2 + w2**2) / 2 + sp.Symbol("m") * phd**2 / 2
                   - sp.Symbol("k") * r**2 / 2, steady={"ph": sp.Symbol("Om")})
    d = _derive(model)
    assert d.operator.K == sp.Matrix([[sp.Symbol("k"), 0], [0, 0]])


def test_a_second_folder_of_the_same_model_name_gets_its_own_compiled_code(tmp_path):
    from gyro import cbackend
    from gyro.models import load

    for folder, momentum_k in (("a", "k"), ("b", "2*k")):
        src = _write_model(tmp_path / folder / "cart.py", MODEL_FILE.format(name="cart", momentum="0")
                           .replace(', generalized_forces={"th": tau.symbol}', "")
                           .replace("- k * x**2 / 2", f"- {momentum_k} * x**2 / 2")) \
            if (tmp_path / folder).mkdir() is None else None
        proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / folder / "out")],
                              cwd=ROOT, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
    Ks = []
    for folder in ("a", "b"):
        load(tmp_path / folder / "out" / "cart")
        Ks.append(cbackend.batch_function("cart", "operator")([[1.0, 3.0, 0.1]], np.empty((1, 0)))[2][0, 0, 0])
    assert Ks == [3.0, 6.0]


def test_a_model_file_may_import_a_module_beside_it(tmp_path):
    (tmp_path / "helper_physics.py").write_text("def spring(k, x):\n    return k * x**2 / 2\n")
    body = MODEL_FILE.format(name="cart", momentum="0").replace(', generalized_forces={"th": tau.symbol}', "")
    body = body.replace("    import sympy as sp\n", "    import sympy as sp\n    from helper_physics import spring\n")
    body = body.replace("- k * x**2 / 2", "- spring(k, x)")
    src = _write_model(tmp_path / "cart.py", body)
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_a_build_that_raises_exits_2_in_one_line(tmp_path):
    src = _write_model(tmp_path / "broken.py", "def build():\n    raise RuntimeError('no such body')\n")
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 2 and "build() failed: RuntimeError: no such body" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_a_steady_motion_that_these_parameters_do_not_allow_has_no_equilibrium(tmp_path):
    """A flywheel turning steadily against a damper with a drive torque tq: the reference is
    a motion only where tq = c Om. Derived (a relation of the parameters), and the runtime
    finds an equilibrium there and refuses one elsewhere, never a silent answer."""
    body = '''
    import sympy as sp
    from derive.model import Model, Parameter

    r, ph, r_d, ph_d, r_dd, ph_dd = sp.symbols("r ph r_d ph_d r_dd ph_dd")


    def build():
        m, k, c, Om, tq = sp.symbols("m k c Om tq")
        return Model(
            name="flywheel", title="flywheel on a spring", source="test", module=__name__,
            parameters=[Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 4.0, "spring"),
                        Parameter("c", "N m s", 0.1, "damper"), Parameter("Om", "rad/s", 2.0, "rate"),
                        Parameter("tq", "N m", 0.2, "drive torque", kind="real")],
            coordinates=["r", "ph"], coordinate_units={"r": "m", "ph": "rad"},
            q=[r, ph], qd=[r_d, ph_d], qdd=[r_dd, ph_dd],
            lagrangian=m * r_d**2 / 2 + m * ph_d**2 / 2 - k * r**2 / 2,
            dissipation=c * ph_d**2 / 2, generalized_forces={"ph": tq}, steady={"ph": Om})
    '''
    src = _write_model(tmp_path / "flywheel.py", body)
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(src), "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    from gyro.equilibrium import equilibria
    from gyro.models import load

    model = load(tmp_path / "out" / "flywheel")
    P = np.array([[1.0, 4.0, 0.1, 2.0, 0.2], [1.0, 4.0, 0.1, 2.0, 0.3]])
    qe, ok = equilibria(model, P)
    assert ok.tolist() == [True, False] and qe[0, 0] == 0.0 and np.isnan(qe[1, 0])


def test_an_output_declared_sparse_is_its_nonzeros_with_their_positions():
    """An output a Function declares sparse is emitted as its structural nonzeros, row-major,
    with their (row, column) positions; the other outputs stay matrices. A sparse name that
    is none of the outputs is refused. Through the NumPy template: the values in that order."""
    from derive.emit import NumpyPrinter, _cse, _printed, check_names, environment
    from derive.model import Function, Unsupported

    a, b = sp.symbols("a b")
    fn = Function("thing", [("params", [a, b])], [("X", sp.Matrix([[a, 0, 2], [0, 0, a * b]])),
                                                  ("y", sp.Matrix([a, b]))], "doc", sparse=("X",))
    check_names([fn])
    with pytest.raises(Unsupported, match="declared sparse"):
        check_names([Function("thing", fn.inputs, fn.outputs, "doc", sparse=("Z",))])
    out = _printed(fn, *_cse(fn), NumpyPrinter())
    X, y = out.outputs
    assert X.sparse and X.size == 3 and X.positions() == {"rows": [0, 0, 1], "cols": [0, 2, 2]}
    assert not y.sparse and y.size == 2
    text = environment().get_template("numpy_functions.py.j2").render(
        template="numpy_functions.py.j2", functions=[out], model="m", title="t", paper="p", source="s",
        digest="0", versions={}, prefix="m", qep_n=0, select=None)
    ns: dict = {}
    exec(compile(text, "numpy_functions.py", "exec"), ns)
    Xv, yv = ns["thing"](np.array([[3.0, 5.0], [1.0, 2.0]]))
    assert Xv.tolist() == [[3.0, 2.0, 15.0], [1.0, 2.0, 2.0]] and yv.tolist() == [[3.0, 5.0], [1.0, 2.0]]


# --------------------------------------------------------------------- parameters made time-varying


def _conveyor(**kw) -> Model:
    """A mass on a spring whose anchor moves at the speed v (a parameter): L = m (x' + v)^2/2
    - k x^2/2, so m (x'' + v') + k x = 0; with v(t) a signal the force -m v' appears."""
    m, k, v = sp.symbols("m k v")
    x, xd = sp.symbols("x x_d")
    V = Signal("v_t", "m/s", "the anchor's speed at t", input=False, order=1, parameter="v")
    params = [Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 4.0, "stiffness"),
              Parameter("v", "m/s", 0.5, "anchor speed", kind="real")]
    base = dict(parameters=params, lagrangian=m * (xd + v)**2 / 2 - k * x**2 / 2, dissipation=0,
                signals=[V], quantities={"momentum": (["params", "qd"], [("p", sp.Matrix([m * (xd + v)]))], "p"),
                                         "spring": (["params", "q"], [("F", sp.Matrix([-k * x]))], "F")})
    base.update(kw)
    return _oscillator(**base)


def test_a_parameter_made_time_varying_is_emitted_again_and_the_rest_is_unchanged():
    m, k, v = sp.symbols("m k v")
    x, xd = sp.symbols("x x_d")
    v_t, v_t_d = sp.symbols("v_t v_t_d")
    d = _derive(_conveyor())
    plain = _derive(_conveyor(signals=[]))
    fns, ref = {f.name: f for f in pipeline.functions(d)}, {f.name: f for f in pipeline.functions(plain)}
    # every function of the constant parameter as it is without the signal
    for name, f in ref.items():
        assert fns[name].inputs == f.inputs and fns[name].outputs == f.outputs, name
    assert set(fns) - set(ref) == {"mass_matrix_varying", "forcing_varying", "momentum_varying"}
    fv = fns["forcing_varying"]
    assert [g for g, _ in fv.inputs] == ["params", "q", "qd", "signals"] and fv.inputs[-1][1] == [v_t, v_t_d]
    assert sp.expand(fv.outputs[0][1][0] - (-k * x - m * v_t_d)) == 0  # the anchor's acceleration, by d/dt
    assert sp.expand(fns["forcing"].outputs[0][1][0] - (-k * x)) == 0
    assert fns["momentum_varying"].outputs[0][1] == sp.Matrix([m * (xd + v_t)])
    meta = pipeline.metadata(d)
    assert meta["varying"] == [{"name": "v_t", "parameter": "v", "unit": "m/s", "description": "the anchor's speed at t",
                                "order": 1, "symbols": ["v_t", "v_t_d"]}]
    assert "signals" not in meta and "varying" not in pipeline.metadata(plain)


@pytest.mark.parametrize("signal,needle", [
    (Signal("v_t", "m/s", "speed", input=False, order=1, parameter="w"), "makes 'w' time-varying, which is not a parameter"),
    (Signal("v_t", "m/s", "speed", input=True, order=1, parameter="v"), "it is no input w"),
    (Signal("v_t", "m/s", "speed", input=False, order=0, parameter="v"), "v_t"),
    (Signal("k", "m/s", "speed", input=False, order=1, parameter="v"), "'k' has the name of a parameter"),
])
def test_a_parameter_made_time_varying_wrongly_is_refused(signal, needle):
    with pytest.raises(Unsupported, match=re.escape(needle)):
        _derive(_conveyor(signals=[signal]))


def test_emitted_operation_counts_are_sympys():
    """derive.emit.count_ops (each distinct subexpression once) gives sp.count_ops's sum on
    expressions built at random from every construct the count treats on its own:
    negations, rationals, quotients, exp, powers, functions, and on the tricky ones named."""
    import random

    from derive.emit import count_ops

    x, y, z = sp.symbols("x y z")
    named = [x - y, -x - y, -x + y, -2 * x, -x / 3, 2 / x, -2 / x, sp.exp(1), sp.E * x, 1 / (x + y),
             sp.Max(x, y, z), sp.sign(x - y) * sp.Abs(x), sp.Piecewise((sp.nan, sp.Eq(x, 0)), (0, True)),
             sp.Rational(-3, 4), sp.Integer(0), sp.S.One, (x * y) ** -2, x**2 * y**-3 / 7, sp.Function("f")(x) / -2]
    rng = random.Random(5)

    def rand(depth):
        if depth == 0:
            return rng.choice([x, y, z, sp.Integer(rng.randint(-3, 3)), sp.Rational(rng.randint(-5, 5), rng.randint(1, 4))])
        a, b = rand(depth - 1), rand(depth - 1)
        return rng.choice([lambda: a + b, lambda: a - b, lambda: a * b, lambda: a / b if b != 0 else a,
                           lambda: sp.sin(a), lambda: a ** rng.choice([2, -1, -2, sp.Rational(1, 2)]) if a != 0 else a,
                           lambda: -a, lambda: sp.exp(a)])()

    exprs = named + [rand(rng.randint(1, 5)) for _ in range(400)]
    assert [count_ops([e]) for e in exprs] == [sp.count_ops(e) for e in exprs]
    assert count_ops(exprs) == sum(sp.count_ops(e) for e in exprs)
