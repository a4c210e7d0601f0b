"""Textbook systems with known answers, each a plain model file of tests/models/, through the
whole chain: derived by the pipeline, emitted into a temporary folder, the C compiled with
-std=c99 -Wall -Wextra -Werror -pedantic, and the known answers checked symbolically and
through every backend (C by ctypes in the argument order metadata.json documents, NumPy,
CasADi, mpmath) at random points.

Tolerances. Every emitted entry checked here is at most a few dozen floating-point
operations on inputs of order one to a few hundred, and the known answers are evaluated
independently (hand formulas in double precision, or in mpmath at 30 digits where they
cancel). Each operation rounds by at most 2^-53 ~ 1.1e-16 of the terms it combines, so an
entry errs by a few hundred ulps of the largest term at worst, ~1e-14; RTOL = 1e-12 is two
orders of magnitude above rounding and ten below any wrong term (a missing or wrong term
is of the size of a parameter product, relative error > 1e-3 at random points). The scale
against which an error is measured is the largest term the entry combines (the largest
entry of the matrix, or an explicit bound where an entry cancels), never the possibly
cancelled value itself. Eigenvalues and integrations have their own bounds, argued where
they are asserted.
"""
from __future__ import annotations

import ctypes
import io
import json
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from derive import emit, pipeline
from derive.model import TIME

ROOT = Path(__file__).resolve().parents[2]
MODELS = Path(__file__).resolve().parents[1] / "models"
RTOL = 1e-12
BACKENDS = ("c", "numpy", "casadi", "mpmath")
N_POINTS = 4  # random points per check (each point goes through all four backends)


# --------------------------------------------------------------------------- the chain


@dataclass
class Emitted:
    name: str
    model: object  # derive.model.Model
    d: object  # pipeline.Derivation
    functions: dict  # name -> derive.model.Function
    meta: dict  # metadata.json
    lib: ctypes.CDLL
    runtime: object  # gyro.models.Model of the emitted folder
    folder: Path


def compile_c(folder: Path, name: str) -> ctypes.CDLL:
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.fail("no C compiler found: install gcc to build and test the generated C")
    lib = folder / f"lib{name}.so"
    cmd = [cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "-shared", "-fPIC",
           "-o", str(lib), str(folder / f"{name}.c"), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"gcc failed on {name}.c:\n{proc.stderr}"
    return ctypes.CDLL(str(lib))


def derive_model(name: str):
    """(model, derivation) of tests/models/<name>.py, loaded as `python -m derive --model` does."""
    from derive.__main__ import build, load_file

    model = build(load_file(MODELS / f"{name}.py"))
    return model, pipeline.derive(model, pipeline.Steps(out=io.StringIO()))


def _finish(name, model, d, functions, out: Path) -> Emitted:
    from gyro import models as runtime_models

    folder = out / name
    meta = json.loads((folder / "metadata.json").read_text())
    return Emitted(name, model, d, functions, meta, compile_c(folder, name),
                   runtime_models.load(folder), folder)


def emit_in_process(name: str, out: Path) -> Emitted:
    model, d = derive_model(name)
    fns = pipeline.functions(d)
    emit.emit(model, fns, pipeline.metadata(d), out / name)
    return _finish(name, model, d, {f.name: f for f in fns}, out)


def emit_by_cli(name: str, out: Path) -> Emitted:
    proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(MODELS / f"{name}.py"),
                           "--out", str(out)], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    model, d = derive_model(name)
    return _finish(name, model, d, {f.name: f for f in pipeline.functions(d)}, out)


_BUILT: dict[str, Emitted] = {}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    def get(name: str, cli: bool = False) -> Emitted:
        if name not in _BUILT:
            out = tmp_path_factory.mktemp(name)
            _BUILT[name] = (emit_by_cli if cli else emit_in_process)(name, out)
        return _BUILT[name]
    return get


def call(E: Emitted, fname: str, vals: dict, backend: str) -> list[np.ndarray]:
    """One emitted function through one backend, its inputs taken by name from `vals` in the
    call order that metadata.json documents; outputs reshaped to their documented shapes."""
    fmeta = E.meta["functions"][fname]
    groups = [[float(vals[s]) for s in g["symbols"]] for g in fmeta["inputs"]]
    shapes = [tuple(o["shape"]) for o in fmeta["outputs"]]
    if backend == "c":
        args = [(ctypes.c_double * len(g))(*g) for g in groups]
        outs = [(ctypes.c_double * (len(o["nonzeros"]["rows"]) if "nonzeros" in o else r * c))()
                for (r, c), o in zip(shapes, fmeta["outputs"])]
        fn = getattr(E.lib, f"{E.name}_{fname}")
        fn.restype = None
        fn(*args, *outs)
        res = [list(o) for o in outs]
    elif backend == "numpy":
        res = getattr(E.runtime.numpy, fname)(*[np.array(g) for g in groups])
        res = list(res) if isinstance(res, tuple) else [res]
    elif backend == "casadi":
        res = getattr(E.runtime.casadi, fname)(*[np.array(g) for g in groups])
        res = [r.full() for r in (res if isinstance(res, (tuple, list)) else [res])]
    elif backend == "mpmath":
        with mpmath.workdps(30):
            res = getattr(E.runtime.mpmath, fname)(*groups)
        res = [r.tolist() for r in (res if isinstance(res, tuple) else [res])]
    else:
        raise ValueError(backend)
    assert len(res) == len(shapes), (backend, fname)
    out = []
    for r, s, o in zip(res, shapes, fmeta["outputs"]):
        r = np.asarray(r, dtype=float)
        if "nonzeros" in o:  # emitted as its structural nonzeros: its matrix, zeros elsewhere
            a = np.zeros(s)
            a[o["nonzeros"]["rows"], o["nonzeros"]["cols"]] = r.reshape(-1)
            r = a
        out.append(r.reshape(s))
    return out


def every_backend(E: Emitted, fname: str, vals: dict) -> dict[str, list[np.ndarray]]:
    return {b: call(E, fname, vals, b) for b in BACKENDS}


def assert_close(got, want, scale=None, rtol=RTOL, what=""):
    """|got - want| <= rtol * scale entrywise; scale: the largest |want| unless given."""
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    if want.ndim == 1 and got.shape == (want.size, 1):  # a column given as a vector
        want = want[:, None]
    assert got.shape == want.shape, (what, got.shape, want.shape)
    if scale is None:
        scale = float(np.max(np.abs(want))) if want.size else 1.0
    err = float(np.max(np.abs(got - want))) if want.size else 0.0
    assert err <= rtol * scale, f"{what}: error {err:.3e} > {rtol:g} x {scale:.3e}"


def check_function(E: Emitted, fname: str, vals: dict, want: list, scales=None):
    """Every backend's outputs of `fname` at `vals` against the known answer `want`."""
    for backend, outs in every_backend(E, fname, vals).items():
        assert len(outs) == len(want), (backend, fname)
        for k, (o, w) in enumerate(zip(outs, want)):
            assert_close(o, w, None if scales is None else scales[k],
                         what=f"{backend} {E.name}.{fname}[{k}]")


def symbolic_at(fn, vals: dict) -> list[np.ndarray]:
    """A Function's symbolic outputs at `vals` (by symbol name), evaluated by mpmath at 30
    digits: the answer every backend's outputs are held to."""
    syms = [s for _, ss in fn.inputs for s in ss]
    with mpmath.workdps(30):
        return [np.array(sp.lambdify(syms, mat, modules="mpmath")(*[mpmath.mpf(vals[str(s)]) for s in syms]).tolist(),
                         dtype=float) for _, mat in fn.outputs]


def check_symbolic(E: Emitted, fname: str, vals: dict):
    """Every backend's outputs of `fname` at `vals` against its symbolic outputs (symbolic_at)."""
    check_function(E, fname, vals, [w.reshape(o.shape) for w, o in
                                    zip(symbolic_at(E.functions[fname], vals), call(E, fname, vals, "numpy"))])


def param_point(E: Emitted, rng, **fixed) -> dict:
    """Parameters at 0.5x..2x their defaults, some fixed by the caller."""
    vals = {p.name: p.default * rng.uniform(0.5, 2.0) for p in E.model.parameters}
    vals.update(fixed)
    return vals


def simplified_zero(expr) -> bool:
    return sp.simplify(sp.sympify(expr)) == 0


def test_every_function_of_every_textbook_model_agrees_across_backends(built):
    """All emitted functions of all models, all four backends, against the un-CSE'd symbolic
    outputs evaluated in mpmath at 30 digits, relative to each matrix's largest entry."""
    rng = np.random.default_rng(7)
    for name in ("damped_oscillator", "mathieu_pendulum", "driven_chain", "symmetric_top",
                 "symmetric_top_euler"):
        E = built(name)
        assert set(E.meta["functions"]) == set(E.functions)
        for fname, fn in E.functions.items():
            for _ in range(2):
                vals = {}
                for group, syms in fn.inputs:
                    for s in syms:
                        if group == "params":
                            vals[str(s)] = E.model.param(str(s)).default * rng.uniform(0.5, 2.0)
                        elif group in ("qe", "q") and str(s) == "theta" and name == "symmetric_top_euler":
                            vals[str(s)] = rng.uniform(0.3, 1.3)  # away from the poles
                        else:
                            vals[str(s)] = rng.uniform(-1.0, 1.0)
                syms = [s for _, ss in fn.inputs for s in ss]
                with mpmath.workdps(30):
                    args = [mpmath.mpf(vals[str(s)]) for s in syms]
                    want = [np.array(sp.lambdify(syms, mat, modules="mpmath")(*args).tolist(), dtype=float)
                            if isinstance(mat, sp.MatrixBase) else mat for _, mat in fn.outputs]
                check_function(E, fname, vals, want)


# --------------------------------------------------------------------------- 1. damped oscillator


def test_damped_oscillator_operator_is_m_c_k_symbolically(built):
    E = built("damped_oscillator")
    m, c, k = sp.symbols("m c k")
    x, x_d = sp.symbols("x x_d")
    op = E.d.operator
    assert (op.M, op.D, op.K) == (sp.Matrix([[m]]), sp.Matrix([[c]]), sp.Matrix([[k]]))
    assert E.d.mass_matrix == sp.Matrix([[m]])
    assert simplified_zero(E.d.forcing[0] - (-c * x_d - k * x))
    parts = dict(E.functions["operator_parts"].outputs)
    assert parts["G"] == sp.zeros(1, 1) and parts["Ds"] == sp.Matrix([[c]])
    assert parts["Ks"] == sp.Matrix([[k]]) and parts["Kc"] == sp.zeros(1, 1)
    assert E.d.even == [] and E.meta["functions"]["operator"]["inputs"][1] == {"name": "qe", "symbols": []}


def test_damped_oscillator_roots_are_the_textbook_ones_in_every_backend(built):
    """p = -c/(2m) +- i sqrt(k/m - c^2/(4m^2)): the roots of the emitted m p^2 + c p + k, and
    J(p) of operator_J_complex vanishes there. Roots of a well-separated quadratic (the two
    differ by 2 Im p, of the size of |p|) err by a few ulps of |p|."""
    E = built("damped_oscillator")
    rng = np.random.default_rng(1)
    for _ in range(N_POINTS):
        v = param_point(E, rng)
        m, c, k = v["m"], v["c"], v["k"]
        assert c * c < 4 * k * m  # underdamped at these points
        re, im = -c / (2 * m), np.sqrt(k / m - c**2 / (4 * m**2))
        check_function(E, "operator", v, [[[m]], [[c]], [[k]]])
        check_function(E, "operator_parts", v, [[[0]], [[c]], [[k]], [[0]]], scales=[k, c, k, k])
        x, xd = rng.uniform(-1, 1, 2)
        check_function(E, "forcing", {**v, "x": x, "x_d": xd}, [[-c * xd - k * x]],
                       scales=[abs(c * xd) + abs(k * x)])
        for backend in BACKENDS:
            M, D, K = (float(a[0, 0]) for a in call(E, "operator", v, backend))
            roots = np.sort_complex(np.roots([M, D, K]))
            assert_close(roots.real, [re, re], scale=abs(re + 1j * im), rtol=1e-13, what=backend)
            assert_close(roots.imag, [-im, im], scale=abs(re + 1j * im), rtol=1e-13, what=backend)
            Jre, Jim = call(E, "operator_J_complex", {**v, "p_re": re, "p_im": im}, backend)
            scale = m * (re**2 + im**2) + c * abs(re + 1j * im) + k
            assert_close([Jre[0, 0], Jim[0, 0]], [0.0, 0.0], scale=scale, what=f"J(p) {backend}")


# --------------------------------------------------------------------------- 2. Mathieu pendulum


def _mathieu_symbols():
    return sp.symbols("m l g a w c"), sp.symbols("theta theta_d")


def test_mathieu_pendulum_equation_is_the_mathieu_form_with_the_explicit_time_term(built):
    """m l^2 theta'' + c theta' + m l (g - a w^2 sin(w t)) sin(theta) = 0, derived by hand
    from the support z = a sin(w t) (acceleration -a w^2 sin(w t)) and gravity -g along z:
    the bob feels the apparent gravity g + z''. The support's term m l a w^2 sin(w t)
    sin(theta) comes from the explicit time derivative of dL/dtheta' alone (at fixed theta
    and theta'): a machinery that drops it gets the pendulum of a fixed support."""
    E = built("mathieu_pendulum")
    (m, l, g, a, w, c), (th, thd) = _mathieu_symbols()
    t = TIME
    Mq, f = E.d.mass_matrix, E.d.forcing
    assert simplified_zero(Mq[0, 0] - m * l**2)
    assert simplified_zero(f[0] - (-c * thd - m * l * (g - a * w**2 * sp.sin(w * t)) * sp.sin(th)))
    # the term itself, and that it is what d/dt|explicit of dL/dtheta' contributes
    assert simplified_zero(sp.diff(f[0], a) - m * l * w**2 * sp.sin(w * t) * sp.sin(th))
    L = E.model.lagrangian
    assert simplified_zero(-sp.diff(sp.diff(L, thd), t) - a * l * m * w**2 * sp.sin(w * t) * sp.sin(th))
    # the linear operator about theta = 0, a function of t
    op = E.d.operator
    assert simplified_zero(op.M[0, 0] - m * l**2) and simplified_zero(op.D[0, 0] - c)
    assert simplified_zero(op.K[0, 0] - m * l * (g - a * w**2 * sp.sin(w * t)))
    assert E.d.time_dependent and E.meta.get("time_dependent") is True
    assert E.d.equilibrium_residual == sp.zeros(1, 1)
    for fname in ("operator", "operator_J", "operator_J_complex", "operator_parts",
                  "equilibrium_residual", "mass_matrix", "forcing"):
        names = [g_["name"] for g_ in E.meta["functions"][fname]["inputs"]]
        assert "time" in names, fname
        assert E.meta["functions"][fname]["inputs"][names.index("time")]["symbols"] == ["t"]


def test_mathieu_pendulum_operator_and_equations_in_every_backend(built):
    E = built("mathieu_pendulum")
    rng = np.random.default_rng(2)
    for _ in range(N_POINTS):
        v = param_point(E, rng, t=rng.uniform(0, 10))
        m, l, g, a, w, c, t = (v[s] for s in ("m", "l", "g", "a", "w", "c", "t"))
        K = m * l * (g - a * w**2 * np.sin(w * t))
        scaleK = m * l * (g + a * w**2)  # the two terms of K, which may cancel
        check_function(E, "operator", v, [[[m * l * l]], [[c]], [[K]]],
                       scales=[m * l * l, c, scaleK])
        check_function(E, "operator_parts", v, [[[0]], [[c]], [[K]], [[0]]],
                       scales=[c, c, scaleK, scaleK])
        th, thd = rng.uniform(-1.5, 1.5), rng.uniform(-2, 2)
        s = {**v, "theta": th, "theta_d": thd}
        check_function(E, "mass_matrix", s, [[[m * l * l]]])
        check_function(E, "forcing", s, [[-c * thd - K * np.sin(th)]],
                       scales=[abs(c * thd) + scaleK * abs(np.sin(th)) + m * l * l * thd**2])


def _mathieu_rhs_emitted(nf, params):
    def rhs(t, y):
        q, qd = y[:1], y[1:]
        Mq = nf.mass_matrix(params, q, [t])
        f = nf.forcing(params, q, qd, [t])
        return np.concatenate([qd, np.linalg.solve(Mq, f)])
    return rhs


def test_mathieu_pendulum_simulates_like_the_hand_written_equation(built):
    """The emitted nonlinear equations (NumPy mass_matrix and forcing, with t) integrated
    over 3 s of large swings (1 rad) against the hand-written Mathieu pendulum, the same
    integrator and tolerances (DOP853, rtol 1e-11): both errs by ~1e-10 of the amplitude
    at most, so they agree to 1e-8 (a wrong or missing term is a difference of order one)."""
    from scipy.integrate import solve_ivp

    E = built("mathieu_pendulum")
    v = {"m": 0.5, "l": 0.8, "g": 9.81, "a": 0.05, "w": 7.0, "c": 0.02}
    params = np.array([v[p.name] for p in E.model.parameters])
    m, l, g, a, w, c = (v[s] for s in ("m", "l", "g", "a", "w", "c"))

    def hand(t, y):
        th, thd = y
        return [thd, (-c * thd - m * l * (g - a * w**2 * np.sin(w * t)) * np.sin(th)) / (m * l * l)]

    y0, ts = [1.0, 0.0], np.linspace(0, 3, 31)
    kw = dict(method="DOP853", rtol=1e-11, atol=1e-13, t_eval=ts)
    got = solve_ivp(_mathieu_rhs_emitted(E.runtime.numpy, params), (0, 3), y0, **kw).y
    want = solve_ivp(hand, (0, 3), y0, **kw).y
    assert_close(got, want, scale=1.0, rtol=1e-8, what="theta, theta' (emitted vs hand)")
    # and it is not the fixed-support pendulum: the support's term moves the motion
    fixed = solve_ivp(_mathieu_rhs_emitted(E.runtime.numpy, params * np.array([1, 1, 1, 0, 1, 1])),
                      (0, 3), y0, **kw).y
    assert np.max(np.abs(fixed[0] - want[0])) > 1e-2


def _monodromy(nf, params):
    """Floquet monodromy of the emitted linear operator M x'' + D x' + K(t) x = 0 over one
    period of the support, its columns from the unit initial states."""
    from scipy.integrate import solve_ivp

    T = 2 * np.pi / params[4]

    def rhs(t, y):
        M, D, K = nf.operator(params, [], [t])
        return [y[1], -(D[0, 0] * y[1] + K[0, 0] * y[0]) / M[0, 0]]

    cols = [solve_ivp(rhs, (0, T), e, method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
            for e in ([1.0, 0.0], [0.0, 1.0])]
    return np.array(cols).T, T


def test_mathieu_pendulum_floquet_multipliers(built):
    """Floquet theory of the emitted operator K(t) = m l g (1 - h sin(w t)), h = a w^2/g,
    omega0^2 = g/l. Undamped, the monodromy has determinant 1 (Liouville: the trace of the
    first-order system is 0); damped, exp(-c T/(m l^2)). At the principal parametric
    resonance w = 2 omega0 the motion is unstable with growth rate h omega0/4 to first order
    in h (Landau-Lifshitz, Mechanics, section 27); at w = 3 omega0 (no tongue above
    2 omega0) it is stable, |trace| < 2. With h = 0.1 the neglected terms of the growth rate
    are O(h^2) ~ 1 % relative at most (0.03 % observed): asserted to 1 %. The monodromy
    integrates at rtol 1e-12: its determinant errs by ~1e-13, asserted to 1e-9."""
    E = built("mathieu_pendulum")
    nf = E.runtime.numpy
    m, l, g = 0.5, 0.8, 9.81
    w0 = np.sqrt(g / l)
    h = 0.1
    for w, c, unstable in ((2 * w0, 0.0, True), (3 * w0, 0.0, False), (2 * w0, 0.05, True)):
        a = h * g / w**2
        P, T = _monodromy(nf, np.array([m, l, g, a, w, c]))
        assert abs(np.linalg.det(P) - np.exp(-c * T / (m * l * l))) < 1e-9
        mu = np.linalg.eigvals(P)
        if unstable:
            rate = np.log(np.max(np.abs(mu))) / T + c / (2 * m * l * l)  # damping shifts all by -c/(2 m l^2)
            assert abs(rate / (h * w0 / 4) - 1) < 0.01, rate / (h * w0 / 4)
        else:
            assert abs(np.trace(P)) < 2 and np.allclose(np.abs(mu), 1, atol=1e-9)


# --------------------------------------------------------------------------- 3. driven chain


def _chain_matrices(v):
    m1, m2, m3, k1, k2, k3, c = (v[s] for s in ("m1", "m2", "m3", "k1", "k2", "k3", "c"))
    M = np.diag([m1, m2, m3])
    K = np.array([[k1 + k2, -k2, 0], [-k2, k2 + k3, -k3], [0, -k3, k3]])
    return M, c * np.eye(3), K


def test_driven_chain_input_matrix_and_operator_symbolically(built):
    E = built("driven_chain")
    m1, m2, m3, k1, k2, k3, c = E.model.symbols
    F = sp.Symbol("F")
    q, qd = sp.Matrix(E.model.q), sp.Matrix(E.model.qd)
    K = sp.Matrix([[k1 + k2, -k2, 0], [-k2, k2 + k3, -k3], [0, -k3, k3]])
    e3 = sp.Matrix([0, 0, 1])
    assert E.d.inputs == [F] and E.d.input_matrix == e3
    assert E.meta["inputs"] == ["F"]
    op = E.d.operator
    assert op.M == sp.diag(m1, m2, m3) and op.D == c * sp.eye(3) and op.K == K
    assert E.d.mass_matrix == sp.diag(m1, m2, m3)
    assert (E.d.forcing - (-c * qd - K * q + e3 * F)).applyfunc(sp.expand) == sp.zeros(3, 1)
    # static response: K x = B F, the springs in series
    x = K.LUsolve(e3 * F)
    assert [sp.simplify(x[0] - F / k1), sp.simplify(x[1] - F / k1 - F / k2),
            sp.simplify(x[2] - F / k1 - F / k2 - F / k3)] == [0, 0, 0]


def test_driven_chain_static_and_harmonic_response_in_every_backend(built):
    """B = e3, and the responses computed from each backend's M, K and B: the static
    x = K^-1 B F (springs in series) and the harmonic X = (K - W^2 M)^-1 B F0 against the
    hand-typed matrices. A 3x3 solve with condition number kappa errs by ~kappa eps: W is
    kept between the natural frequencies' neighbourhoods so that kappa < 1e3 (asserted)."""
    E = built("driven_chain")
    rng = np.random.default_rng(3)
    for _ in range(N_POINTS):
        v = param_point(E, rng)
        M, D, K = _chain_matrices(v)
        check_function(E, "operator", v, [M, D, K])
        check_function(E, "input_matrix", v, [np.array([[0.0], [0.0], [1.0]])])
        F = rng.uniform(-3, 3)
        xs = rng.uniform(-1, 1, 3)
        xds = rng.uniform(-1, 1, 3)
        s = {**v, "F": F, **dict(zip(("x1", "x2", "x3"), xs)), **dict(zip(("x1_d", "x2_d", "x3_d"), xds))}
        check_function(E, "forcing", s, [-D @ xds - K @ xs + np.array([0, 0, F])],
                       scales=[np.abs(K).max() * 2 + abs(F) + v["c"]])
        check_function(E, "mass_matrix", s, [M])
        series = F * np.cumsum([1 / v["k1"], 1 / v["k2"], 1 / v["k3"]])
        wn = np.sqrt(np.linalg.eigvals(np.linalg.solve(M, K)).real)
        W = 0.5 * np.min(wn)  # below the first resonance: well conditioned
        F0 = 1.3
        X_hand = np.linalg.solve(K - W**2 * M, np.array([0, 0, F0]))
        assert np.linalg.cond(K - W**2 * M) < 1e3
        for backend in BACKENDS:
            Mb, _, Kb = call(E, "operator", v, backend)
            (B,) = call(E, "input_matrix", v, backend)
            assert_close(np.linalg.solve(Kb, B[:, 0] * F), series, rtol=1e-12, what=f"static {backend}")
            assert_close(np.linalg.solve(Kb - W**2 * Mb, B[:, 0] * F0), X_hand, rtol=1e-12,
                         what=f"harmonic {backend}")


def _chain_rhs(nf, params, force):
    def rhs(t, y):
        q, qd = y[:3], y[3:]
        sig = [force(t)]
        return np.concatenate([qd, np.linalg.solve(nf.mass_matrix(params, q, sig),
                                                   nf.forcing(params, q, qd, sig))])
    return rhs


def test_driven_chain_simulates_to_the_steady_response(built):
    """The emitted nonlinear (here linear) equations with F = F0 cos(W t) as the signal.
    Undamped, started on X = (K - W^2 M)^-1 e3 F0 at rest, the motion is X cos(W t) exactly:
    over 3 periods, DOP853 at rtol 1e-11 errs by ~1e-9 of |X|. Damped (c = 3: every mode
    decays at least as e^(-c t/(2 m_max)), below e^-13 after 20 s), from rest, the last
    period's amplitude converges to |(K - W^2 M + i W D)^-1 e3 F0| to 1e-5."""
    from scipy.integrate import solve_ivp

    E = built("driven_chain")
    nf = E.runtime.numpy
    v = {p.name: p.default for p in E.model.parameters}
    F0 = 2.0
    v["c"] = 0.0
    M, D, K = _chain_matrices(v)
    W = 0.7 * np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    X = np.linalg.solve(K - W**2 * M, np.array([0, 0, F0]))
    params = np.array([v[p.name] for p in E.model.parameters])
    T = 2 * np.pi / W
    ts = np.linspace(0, 3 * T, 40)
    sol = solve_ivp(_chain_rhs(nf, params, lambda t: F0 * np.cos(W * t)), (0, 3 * T),
                    np.concatenate([X, np.zeros(3)]), method="DOP853", rtol=1e-11, atol=1e-13, t_eval=ts)
    assert_close(sol.y[:3].T, np.outer(np.cos(W * ts), X), scale=np.max(np.abs(X)), rtol=1e-8,
                 what="undamped steady motion")

    v["c"] = 3.0
    params = np.array([v[p.name] for p in E.model.parameters])
    M, D, K = _chain_matrices(v)
    Z = np.linalg.solve(K - W**2 * M + 1j * W * D, np.array([0, 0, F0]))
    t_end = 20.0 + T
    ts = np.linspace(20.0, t_end, 400)
    sol = solve_ivp(_chain_rhs(nf, params, lambda t: F0 * np.cos(W * t)), (0, t_end), np.zeros(6),
                    method="DOP853", rtol=1e-10, atol=1e-12, t_eval=ts)
    want = (np.exp(1j * W * ts)[:, None] * Z[None, :]).real  # Re(Z e^{iWt})
    assert_close(sol.y[:3].T, want, scale=np.max(np.abs(Z)), rtol=1e-5, what="damped steady response")


# --------------------------------------------------------------------------- 4. symmetric top


def _top_by_hand():
    """The sleeping top's quadratic Lagrangian for small tilts, by hand: the tilted frame
    turns at (alpha' cos beta, beta', alpha' sin beta); the rotor adds the spin n about the
    axis, so omega3 = n + alpha' sin beta ~ n + alpha' beta; the mass centre's height
    l cos alpha cos beta ~ l (1 - alpha^2/2 - beta^2/2). Returns (M, D, K) over
    (alpha, beta) from its Lagrange equations (SymPy's diff only, not derive.mechanics)."""
    A, C, m, g, l, n = sp.symbols("A C m g l n")
    al, be, ald, bed = sp.symbols("al be ald bed")
    L2 = A * (ald**2 + bed**2) / 2 + C * (n + ald * be)**2 / 2 - m * g * l * (1 - al**2 / 2 - be**2 / 2)
    qs, vs = [al, be], [ald, bed]
    at = {al: 0, be: 0, ald: 0, bed: 0}
    M = sp.Matrix(2, 2, lambda i, j: sp.diff(L2, vs[i], vs[j])).subs(at)
    # d/dt dL/dv_i = sum_j (d2L/dv_i dq_j) q_j' (+ M q''), minus dL/dq_i, linear part
    N = sp.Matrix(2, 2, lambda i, j: sp.diff(L2, vs[i], qs[j]))
    Q = sp.Matrix(2, 2, lambda i, j: sp.diff(L2, qs[i], vs[j]))
    D = (N - Q).subs(at)
    K = -sp.Matrix(2, 2, lambda i, j: sp.diff(L2, qs[i], qs[j])).subs(at)
    return (A, C, m, g, l, n), M, D, K


def test_sleeping_top_characteristic_polynomial_is_maievskis(built):
    """det of the tilt block of J(p) = (A p^2 - m g l)^2 + (C n p)^2, the hand-derived
    operator's; the spin row is C p^2 alone (phi ignorable, turning at n)."""
    E = built("symmetric_top")
    (A, C, m, g, l, n), Mh, Dh, Kh = _top_by_hand()
    p = sp.Symbol("p")
    Jh = Mh * p**2 + Dh * p + Kh
    assert sp.expand(Jh.det() - ((A * p**2 - m * g * l)**2 + (C * n * p)**2)) == 0
    assert E.d.order == ["alpha", "beta", "phi"] and E.d.even == []
    J = E.d.operator.J(p)
    tilt = J.extract([0, 1], [0, 1])
    assert sp.expand(tilt.det() - Jh.det()) == 0
    assert J.extract([0, 1], [0, 1]) == Jh  # the operator itself, coupling sign included
    assert list(J.row(2)) == [0, 0, C * p**2] and list(J.col(2)) == [0, 0, C * p**2]
    assert sp.expand(J.det() - C * p**2 * Jh.det()) == 0


def _qep_eigenvalues(M, D, K):
    """Eigenvalues p of det(M p^2 + D p + K) = 0 by the companion linearisation."""
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ D]])
    return np.linalg.eigvals(A)


def test_sleeping_top_stability_is_maievskis_condition_in_every_backend(built):
    """C^2 n^2 > 4 A m g l: all four tilt eigenvalues purely imaginary, p = i (C n +-
    sqrt(C^2 n^2 - 4 A m g l))/(2A) and conjugates; below, p = (+-sqrt(4 A m g l - C^2 n^2)
    +- i C n)/(2A), one with a positive real part. Spins at 1.5x and 0.6x the threshold keep
    the roots simple and apart (no defective double root), so the companion eigenvalues err
    by a few ulps of the largest |p| times a modest condition number: 1e-10 relative."""
    E = built("symmetric_top")
    rng = np.random.default_rng(4)
    for factor, stable in ((1.5, True), (0.6, False), (3.0, True), (0.2, False)):
        v = param_point(E, rng)
        A, C, m, g, l = (v[s] for s in ("A", "C", "m", "g", "l"))
        v["n"] = factor * 2 * np.sqrt(A * m * g * l) / C * rng.choice([-1, 1])
        n = v["n"]
        Mh = np.diag([A, A, C])
        Dh = np.array([[0, C * n, 0], [-C * n, 0, 0], [0, 0, 0]])
        Kh = np.diag([-m * g * l, -m * g * l, 0])
        check_function(E, "operator", v, [Mh, Dh, Kh])
        disc = complex(C * C * n * n - 4 * A * m * g * l)
        want = np.array([(s1 * 1j * C * n + s2 * 1j * np.sqrt(disc)) / (2 * A)
                         for s1 in (1, -1) for s2 in (1, -1)])
        for backend in BACKENDS:
            M, D, K = call(E, "operator", v, backend)
            p = _qep_eigenvalues(M[:2, :2], D[:2, :2], K[:2, :2])
            scale = np.max(np.abs(want))
            for w_ in want:
                assert np.min(np.abs(p - w_)) < 1e-10 * scale, (backend, p, want)
            if stable:
                assert np.max(np.abs(p.real)) < 1e-10 * scale, (backend, factor, p)
            else:
                assert np.max(p.real) > 0.1 * scale, (backend, factor, p)


# --------------------------------------------------------------------------- 4b. Euler angles


def _effective_potential():
    A, C, m, g, l = sp.symbols("A C m g l")
    th, Lz, H = sp.symbols("theta Lz H")
    V = (Lz - H * sp.cos(th))**2 / (2 * A * sp.sin(th)**2) + m * g * l * sp.cos(th)
    return (A, C, m, g, l), (th, Lz, H), V


def test_top_in_euler_angles_reduces_to_the_effective_potential(built):
    """The Routh reduction of psi (momentum Lz) and phi (H) leaves A theta'^2/2 - V(theta)
    (up to the constant -H^2/(2C)); the reference's equation is -V'(theta) and the operator
    M = A, D = 0, K = V''(theta)."""
    E = built("symmetric_top_euler")
    (A, C, m, g, l), (th, Lz, H), V = _effective_potential()
    thd = sp.Symbol("theta_d")
    assert E.d.order == ["theta"] and E.d.even == [th] and E.d.momenta == [Lz, H]
    assert simplified_zero(E.d.routhian - (A * thd**2 / 2 - V - H**2 / (2 * C)))
    assert simplified_zero(E.d.equilibrium_residual[0] + sp.diff(V, th))
    op = E.d.operator
    assert op.M == sp.Matrix([[A]]) and simplified_zero(op.D[0, 0])
    assert simplified_zero(op.K[0, 0] - sp.diff(V, th, 2))


def test_steady_precession_nutation_frequency_matches_the_effective_potential(built):
    """At a steady precession theta0 (H^2 > 4 A m g l cos theta0: two precession rates),
    Lz from V'(theta0) = 0 by hand: u = Lz - H cos theta0 solves cos(theta0) u^2 -
    H sin^2(theta0) u + A m g l sin^4(theta0) = 0. Each backend's equilibrium_residual
    vanishes there and its operator gives omega^2 = K/M = V''(theta0)/A, V'' evaluated
    from the hand formula in mpmath at 30 digits. The residual's terms (of size
    (Lz - H c)^2/(A s^2) and m g l) cancel: its error is measured against them."""
    E = built("symmetric_top_euler")
    (A_, C_, m_, g_, l_), (th, Lz_, H_), V = _effective_potential()
    Vpp = sp.lambdify([A_, m_, g_, l_, th, Lz_, H_], sp.diff(V, th, 2), modules="mpmath")
    Vp = sp.lambdify([A_, m_, g_, l_, th, Lz_, H_], sp.diff(V, th), modules="mpmath")
    rng = np.random.default_rng(5)
    for k in range(N_POINTS):
        v = param_point(E, rng)
        A, m, g, l = (v[s] for s in ("A", "m", "g", "l"))
        theta0 = rng.uniform(0.3, 1.3)
        H = float(np.sqrt(4 * A * m * g * l * np.cos(theta0)) * rng.uniform(1.5, 4.0))
        with mpmath.workdps(30):
            c0, s0 = mpmath.cos(theta0), mpmath.sin(theta0)
            sign = 1 if k % 2 else -1  # fast and slow precession
            u = s0**2 * (H + sign * mpmath.sqrt(H**2 - 4 * A * m * g * l * c0)) / (2 * c0)
            Lz = float(u + H * c0)
            assert abs(Vp(A, m, g, l, theta0, Lz, H)) < 1e-12 * m * g * l  # Lz rounded to double
            omega2 = float(Vpp(A, m, g, l, theta0, Lz, H) / A)
            scale_r = float((Lz - H * c0)**2 / (A * s0**2) * 4 + abs(Lz * H) / A + m * g * l)
        vals = {**v, "theta": theta0, "Lz": Lz, "H": H}
        assert omega2 > 0  # steady precession of a top is stable
        for backend in BACKENDS:
            (r,) = call(E, "equilibrium_residual", vals, backend)
            assert_close(r, [0.0], scale=scale_r, what=f"residual {backend}")
            M, D, K = call(E, "operator", vals, backend)
            assert_close(M, [[A]], what=backend)
            assert_close(D, [[0.0]], scale=scale_r, what=backend)
            # K combines terms of the size of scale_r x (a few): 1e-12 of that, relative to omega^2
            assert_close(K[0, 0] / M[0, 0], omega2, scale=10 * scale_r / A, what=f"omega^2 {backend}")
            assert abs(K[0, 0] / M[0, 0] / omega2 - 1) < 1e-9, (backend, K[0, 0] / M[0, 0], omega2)


# --------------------------------------------------------------------------- momentum 0


def test_a_momentum_given_as_zero_derives_emits_and_compiles(built):
    """cyclic={'phi': 0}: a constant of the derivation, not an input. Emitted through the
    command line (python -m derive --model PATH --out DIR); the C compiles with -Werror; the
    reduced system is the plane pendulum, M = m l^2, K = m g l cos(theta), residual
    -m g l sin(theta), in every backend."""
    E = built("spherical_pendulum", cli=True)
    m, l, g = E.model.symbols
    th, thd = sp.symbols("theta theta_d")
    assert E.d.momenta == [] and E.meta["momenta"] == [] and E.meta["cyclic"] == {"phi": "0"}
    assert simplified_zero(E.d.routhian - (m * l**2 * thd**2 / 2 + m * g * l * sp.cos(th)))
    for fname, fmeta in E.meta["functions"].items():
        assert "momenta" not in [g_["name"] for g_ in fmeta["inputs"]], fname
    rng = np.random.default_rng(6)
    for _ in range(N_POINTS):
        v = param_point(E, rng, theta=rng.uniform(-1.5, 1.5))
        mv, lv, gv, t0 = v["m"], v["l"], v["g"], v["theta"]
        check_function(E, "equilibrium_residual", v, [[-mv * gv * lv * np.sin(t0)]])
        check_function(E, "operator", v, [[[mv * lv * lv]], [[0.0]], [[mv * gv * lv * np.cos(t0)]]],
                       scales=[mv * lv * lv, 1.0, mv * gv * lv])
    # at the bottom, omega^2 = g/l
    v = param_point(E, rng, theta=0.0)
    for backend in BACKENDS:
        M, _, K = call(E, "operator", v, backend)
        assert abs(K[0, 0] / M[0, 0] / (v["g"] / v["l"]) - 1) < 1e-14
