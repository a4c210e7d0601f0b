"""The generated code (C, NumPy, CasADi) against the symbolic result, and its hygiene:
compiles with -Wall -Wextra -Werror, deterministic bytes, headers, up to date."""
from __future__ import annotations

import ctypes
import functools
import json
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from tests.conftest import GENERATED, MODEL, ROOT, compile_c, derived

MODELS = sorted(p.name for p in GENERATED.iterdir() if (p / "metadata.json").exists())

N_POINTS = 100
RTOL = 1e-12


def _random_inputs(fn, model, rng):
    """A random point of every input of a function: parameters within 0.5x..2x the paper
    example (phi in 5..85 deg), equilibrium offsets up to 1e-3, angles up to 1 rad."""
    vals = {}
    for name, syms in fn.inputs:
        for s in syms:
            if name == "params":
                p = model.param(str(s))
                if p.name == "phi":
                    vals[s] = rng.uniform(5, 85)
                else:
                    vals[s] = p.default * rng.uniform(0.5, 2.0)
            elif name == "qe" and model.name == "torsion_gyrocompass":
                vals[s] = rng.uniform(-1e-3, 1e-3)  # equilibrium offsets are small
            else:
                vals[s] = rng.uniform(-1.0, 1.0)
    return vals


@functools.lru_cache(maxsize=None)
def term_scale(expr):
    """A first-order bound on the size of what evaluating expr goes through: every term of a
    sum in absolute value, and through a power or function the scale of its argument
    propagated by the derivative (|f(x)| + |f'(x)| scale(x)). Floating-point evaluation
    errs by a few ulps of this, however much cancellation leaves of the value itself.
    Memoised (expressions are immutable; the un-CSE'd Jacobians of operator_sensitivity
    repeat their subexpressions thousands of times: 24 s of term scales become 0.7 s, the
    same expressions)."""
    if expr.is_Number or expr.is_Symbol or expr.is_NumberSymbol:
        return sp.Abs(expr)
    if expr.is_Add or expr.is_Mul:
        return expr.func(*[term_scale(a) for a in expr.args])
    if expr.is_Pow:
        b, e = expr.base, expr.exp
        if e.is_Integer and e > 0:
            return sp.Pow(term_scale(b), e)
        return sp.Abs(expr) + sp.Abs(e * sp.Pow(b, e - 1)) * term_scale(b)
    if isinstance(expr, sp.Abs):  # |x| errs as x does
        return term_scale(expr.args[0])
    if len(expr.args) == 1:
        t = sp.Dummy()
        deriv = sp.diff(expr.func(t), t).subs(t, expr.args[0])
        return sp.Abs(expr) + sp.Abs(deriv) * term_scale(expr.args[0])
    raise TypeError(f"no term scale for {expr.func}")


_LAMBDAS = {}


def _reference(fn, vals):
    """The un-CSE'd symbolic outputs and their term scales, evaluated in extended precision
    (x87 long double, 64-bit mantissa: about 1e-19, far below the 1e-12 asserted)."""
    syms = [s for _, ss in fn.inputs for s in ss]
    key = (id(fn), fn.name)
    if key not in _LAMBDAS:
        # the values un-CSE'd (a reference independent of the emitted CSE); the scales, a
        # bound only, with SymPy's CSE (they agree with the un-CSE'd ones to 2e-19 in long
        # double, and lambdify prints operator_sensitivity's in 3 s instead of 14)
        _LAMBDAS[key] = [
            (sp.lambdify(syms, sp.Matrix(mat), modules="numpy"),
             sp.lambdify(syms, sp.Matrix(mat).applyfunc(term_scale), modules="numpy", cse=True))
            for _, mat in fn.outputs]
    args = [np.longdouble(vals[s]) for s in syms]
    out = []
    with np.errstate(all="ignore"):
        for f, fs in _LAMBDAS[key]:
            out.append((np.array(f(*args), dtype=np.longdouble).astype(float),
                        np.array(fs(*args), dtype=np.longdouble).astype(float)))
    return out


@functools.lru_cache(maxsize=None)
def _nonzeros(model, fname):
    """Per output of a function, the (rows, cols) of the values of one emitted as its
    structural nonzeros (metadata.json), else None."""
    outs = json.loads((GENERATED / model / "metadata.json").read_text())["functions"][fname]["outputs"]
    return tuple((np.array(o["nonzeros"]["rows"]), np.array(o["nonzeros"]["cols"])) if "nonzeros" in o else None
                 for o in outs)


def _sizes(fn, model):
    """How many numbers each output of fn is emitted as: its nonzeros if sparse."""
    return [mat.rows * mat.cols if nz is None else len(nz[0])
            for (_, mat), nz in zip(fn.outputs, _nonzeros(model, fn.name))]


def _dense(fn, outs, model):
    """The outputs as their matrices: a sparse one's values put at their positions in a
    matrix of zeros, so that the comparison with the dense symbolic result also checks that
    every entry left out is zero there."""
    res = []
    for o, (_, mat), nz in zip(outs, fn.outputs, _nonzeros(model, fn.name)):
        o = np.asarray(o, dtype=float)
        if nz is None:
            res.append(o.reshape(mat.rows, mat.cols))
            continue
        a = np.zeros((mat.rows, mat.cols))
        a[nz] = o.reshape(-1)
        res.append(a)
    return res


def _call_c(lib, fn, vals, model=MODEL):
    """The single-set entry point into fresh output arrays (ctypes zeroes them: the
    structural zeros are the caller's, model.h)."""
    outs = [(ctypes.c_double * size)() for size in _sizes(fn, model)]
    return _dense(fn, _call_c_into(lib, fn, vals, outs, model), model)


def _call_c_into(lib, fn, vals, outs, model):
    """The single-set entry point at vals into the given ctypes output arrays."""
    args = [(ctypes.c_double * len(syms))(*[vals[s] for s in syms]) for _, syms in fn.inputs]
    getattr(lib, f"{model}_{fn.name}")(*args, *outs)
    return [np.array(list(o)) for o in outs]


def _call_numpy(fn, vals, model=MODEL):
    import importlib

    nf = importlib.import_module(f"generated.{model}.numpy_functions")

    args = [np.array([vals[s] for s in syms]) for _, syms in fn.inputs]
    res = getattr(nf, fn.name)(*args)
    return _dense(fn, list(res) if isinstance(res, tuple) else [res], model)


def _call_casadi(fn, vals, model=MODEL):
    import importlib

    cf = importlib.import_module(f"generated.{model}.casadi_functions")

    args = [np.array([vals[s] for s in syms]) for _, syms in fn.inputs]
    res = getattr(cf, fn.name)(*args)
    res = list(res) if isinstance(res, (tuple, list)) else [res]
    return _dense(fn, [np.array(r.full()) for r in res], model)


def _call_mpmath(fn, vals, model=MODEL):
    """The mpmath backend at 30 digits, rounded to double (compared like the others)."""
    import importlib

    import mpmath

    mf = importlib.import_module(f"generated.{model}.mpmath_functions")
    args = [[vals[s] for s in syms] for _, syms in fn.inputs]
    with mpmath.workdps(30):
        res = getattr(mf, fn.name)(*args)
    res = list(res) if isinstance(res, tuple) else [res]
    # outside a function's real domain (acos of more than 1: no equilibrium) mpmath goes
    # complex where the double-precision backends give NaN
    real = lambda x: float(x) if not isinstance(x, mpmath.mpc) or x.imag == 0 else float("nan")  # noqa: E731
    return _dense(fn, [np.array([[real(x) for x in row] for row in r.tolist()], dtype=float) for r in res], model)


def _call_c_batch(lib, fn, points, model=MODEL):
    """The `_batch` entry point over several points at once, packed set after set."""
    ptr = ctypes.POINTER(ctypes.c_double)
    ins = [np.array([[v[s] for s in syms] for v in points]) for _, syms in fn.inputs]
    outs = [np.zeros((len(points), size)) for size in _sizes(fn, model)]
    getattr(lib, f"{model}_{fn.name}_batch")(ctypes.c_long(len(points)), *[a.ctypes.data_as(ptr) for a in ins + outs])
    return [_dense(fn, [o[k] for o in outs], model) for k in range(len(points))]


def _compare(got, ref, what):
    """Each entry's error relative to its term scale (its value when nothing cancels)."""
    worst = 0.0
    for g, (value, scale) in zip(got, ref):
        g = np.asarray(g, dtype=float)
        # outside the real domain the reference is NaN: so must every backend be
        assert np.array_equal(np.isnan(g), np.isnan(value)), f"{what}: NaN where the reference has none, or not"
        ok = ~np.isnan(value)
        err = np.abs(g - value)[ok]
        denom = np.where(scale > 0, scale, 1.0)[ok]
        worst = max(worst, float(np.max(err / denom, initial=0.0)))
    assert worst <= RTOL, f"{what}: relative error {worst:.3e} > {RTOL}"
    return worst


# one test per emitted function (its own random points), so that the parallel workers share
# the largest model's functions; each worker compiles a model's C once
FUNCTIONS = [(name, fname) for name in MODELS
             for fname in sorted(json.loads((GENERATED / name / "metadata.json").read_text())["functions"])]
_LIBS = {}


@pytest.fixture(scope="session")
def compiled(tmp_path_factory):
    def get(name):
        if name not in _LIBS:
            _LIBS[name] = compile_c(name, tmp_path_factory.mktemp(f"c_{name}"))
        return _LIBS[name]
    return get


@pytest.mark.parametrize("name", MODELS)
def test_the_documented_functions_are_the_derived_ones(name):
    """metadata.json lists exactly the derivation's functions, each with the derivation's
    call order (inputs and outputs): the calls of the test below follow metadata."""
    _, _, functions = derived(name)
    documented = json.loads((GENERATED / name / "metadata.json").read_text())["functions"]
    assert list(documented) == sorted(functions)
    for fname, fn in functions.items():
        assert [(i["name"], i["symbols"]) for i in documented[fname]["inputs"]] == \
            [(g, [str(s) for s in syms]) for g, syms in fn.inputs], fname
        assert [o["name"] for o in documented[fname]["outputs"]] == [o for o, _ in fn.outputs], fname


@pytest.mark.parametrize("name, fname", FUNCTIONS, ids=[f"{n}.{f}" for n, f in FUNCTIONS])
def test_generated_code_matches_symbolic(name, fname, compiled):
    """C (compiled with -Wall -Wextra -Werror), NumPy, CasADi and mpmath at 100 random
    points of every emitted function of every model, each entry to 1e-12 of its term scale;
    the C batch entry point over the same points gives the same bytes as the single calls.
    An output emitted as its structural nonzeros is compared as its matrix (its values at
    their positions, zeros elsewhere): the values and that nothing nonzero was left out."""
    model, _, functions = derived(name)
    lib = compiled(name)
    fn = functions[fname]
    for (oname, mat), nz in zip(fn.outputs, _nonzeros(name, fname)):
        if nz is not None:  # each position once, within the matrix, row-major
            flat = nz[0] * mat.cols + nz[1]
            assert np.all(np.diff(flat) > 0) and np.all((nz[1] >= 0) & (nz[1] < mat.cols)) \
                and np.all((nz[0] >= 0) & (nz[0] < mat.rows)), (fname, oname)
    rng = random.Random(f"2024:{name}:{fname}")  # each function's own points, whatever runs first
    shapes = [(mat.rows, mat.cols) for _, mat in fn.outputs]
    points, singles = [], []
    for k in range(N_POINTS):
        vals = _random_inputs(fn, model, rng)
        ref = _reference(fn, vals)
        points.append(vals)
        singles.append(_call_c(lib, fn, vals, name))
        _compare(singles[-1], ref, f"C {name}.{fname}")
        if k % 5 == 0:  # the Python backends share the printer logic: every 5th point
            for backend, call in (("numpy", _call_numpy), ("casadi", _call_casadi),
                                  ("mpmath", _call_mpmath)):
                got = [np.asarray(g, dtype=float).reshape(s) for g, s in zip(call(fn, vals, name), shapes)]
                _compare(got, ref, f"{backend} {name}.{fname}")
    for one, many in zip(singles, _call_c_batch(lib, fn, points, name)):
        for a, b in zip(one, many):
            np.testing.assert_array_equal(a, b)


SENTINEL = -7.25e307  # no output takes it: left where the C writes nothing


@pytest.mark.parametrize("name, fname", FUNCTIONS, ids=[f"{n}.{f}" for n, f in FUNCTIONS])
def test_c_calling_contract_nonzeros_once_zeroed_and_reused(name, fname, compiled):
    """The contract of model.h: a single-set call writes exactly the structural nonzeros
    of each output (a sentinel survives at the symbolic zeros and nowhere else), so an
    output array zeroed once and called into again with other inputs holds the answer at
    the new inputs, to the bit (no value of the earlier call left); the batch entry point
    writes every entry of arrays that held anything."""
    model, _, functions = derived(name)
    lib = compiled(name)
    fn = functions[fname]
    rng = random.Random(f"contract:{name}:{fname}")
    points = [_random_inputs(fn, model, rng) for _ in range(3)]
    sizes = _sizes(fn, name)
    fresh = lambda: [(ctypes.c_double * k)() for k in sizes]  # noqa: E731  (ctypes zeroes them)
    for (oname, mat), nz, got in zip(fn.outputs, _nonzeros(name, fname),
                                     _call_c_into(lib, fn, points[0], [(ctypes.c_double * k)(*[SENTINEL] * k)
                                                                       for k in sizes], name)):
        if nz is None:
            zero = np.array([sp.sympify(e) == 0 for e in sp.Matrix(mat)])
        else:  # emitted as its nonzeros: every value written
            zero = np.zeros(len(nz[0]), dtype=bool)
        np.testing.assert_array_equal(got == SENTINEL, zero, err_msg=f"{fname}.{oname}: positions written")
    reused = fresh()
    for k, vals in enumerate(points):
        again = _call_c_into(lib, fn, vals, reused, name)
        once = _call_c_into(lib, fn, vals, fresh(), name)
        for a, b in zip(again, once):
            np.testing.assert_array_equal(a, b, err_msg=f"{fname}: call {k} into a reused output")
    ptr = ctypes.POINTER(ctypes.c_double)
    ins = [np.array([[v[s] for s in syms] for v in points]) for _, syms in fn.inputs]
    outs = [np.full((len(points), k), SENTINEL) for k in sizes]
    getattr(lib, f"{name}_{fname}_batch")(ctypes.c_long(len(points)), *[a.ctypes.data_as(ptr) for a in ins + outs])
    for k, vals in enumerate(points):
        for a, b in zip([o[k] for o in outs], _call_c_into(lib, fn, vals, fresh(), name)):
            np.testing.assert_array_equal(a, b, err_msg=f"{fname}: the batch over arrays that held a sentinel")


def test_numpy_functions_broadcast_over_a_batch(tg_model):
    from generated.torsion_gyrocompass import numpy_functions as nf

    p0 = np.array([p.default for p in tg_model.parameters])
    batch = p0 * np.linspace(0.5, 2.0, 7)[:, None]
    qe = nf.equilibrium_approx(batch)
    M, D, K = nf.operator(batch, qe)
    assert M.shape == D.shape == K.shape == (7, 10, 10)
    M3, _, _ = nf.operator(batch[3], qe[3])
    np.testing.assert_array_equal(M3, M[3])


@pytest.mark.parametrize("name", MODELS)
def test_generated_headers_name_source_and_input_hash(name):
    """Every generated file names its template, model and paper; the input hash is in the
    metadata alone (once per model: a change of the machinery that leaves the output alone
    rewrites one line of one file per model, not six)."""
    meta = json.loads((GENERATED / name / "metadata.json").read_text())
    digest = meta["generated"]["input_hash"]
    assert len(digest) == 64
    for f in (GENERATED / name).iterdir():
        if f.suffix in (".py", ".c", ".h"):
            text = f.read_text()
            head = "".join(text.splitlines(keepends=True)[:5])
            assert "DO NOT EDIT" in head and "templates/" in head and "metadata.json" in head, f.name
            assert f"derive/models/{name}.py" in head and digest not in text, f.name


def test_generated_is_current_and_deterministic_across_hash_seeds(tmp_path):
    """A fresh derivation under another PYTHONHASHSEED gives the committed bytes. Under
    `make test` its check-generated step has just done exactly this (the Makefile's
    HASHSEED), and says so in GYRO_GENERATED_CHECKED: the derivation is not run twice."""
    if os.environ.get("GYRO_GENERATED_CHECKED") == "4242":
        pytest.skip("make test's check-generated derived afresh under PYTHONHASHSEED=4242: the committed bytes")
    env = dict(os.environ, PYTHONHASHSEED="4242")
    out = tmp_path / "gen"
    subprocess.run([sys.executable, "-m", "derive", "--out", str(out)],
                   cwd=ROOT, env=env, check=True, capture_output=True)
    for name in MODELS:
        for f in sorted((GENERATED / name).iterdir()):
            if f.is_file():
                assert (out / name / f.name).read_bytes() == f.read_bytes(), f"{name}/{f.name} differs"


def test_generated_op_counts_agree_with_metadata():
    """Each C function states its operation count after CSE, the one metadata.json records."""
    import re

    meta = json.loads((GENERATED / MODEL / "metadata.json").read_text())["functions"]
    text = (GENERATED / MODEL / f"{MODEL}.c").read_text()
    found = dict(re.findall(r"void " + MODEL + r"_(\w+)\(.*\n\{\n\s*// Total ops: (\d+)", text))
    assert set(found) == set(meta)
    for name, ops in found.items():
        assert int(ops) == meta[name]["ops"] and meta[name]["ops"] <= meta[name]["ops_before_cse"]
        if meta[name]["ops_before_cse"] > 100:  # CSE pays wherever there is something to share
            assert meta[name]["ops"] < meta[name]["ops_before_cse"], name


def test_c_printer_parenthesises_powers_in_denominators():
    """x * y**-3 once printed as x/(y)*(y)*(y): small integer powers are products and must
    stay grouped wherever the Mul printer places them. These C expressions are Python too."""
    from derive.emit import CPrinter

    x, y, z = sp.symbols("x y z")
    pr = CPrinter()
    vals = {"x": 1.7, "y": 0.3, "z": 2.9, "sqrt": np.sqrt, "pow": pow}
    for e in (x * y**-3, x / (y**2 * z**3), (x + y)**-2 * z, x**4 / y**4, 1 / (x * y)**2, y**sp.Rational(-1, 2)):
        got = eval(pr.doprint(e), vals)
        want = float(e.subs({x: 1.7, y: 0.3, z: 2.9}))
        assert abs(got / want - 1) < 1e-14, (e, pr.doprint(e))


def _builds():
    """What the runtime compiles: every model's C, the kernels of each operator dimension
    the models have (gyro.cbackend.KERNELS, -DQEP_N=n), the polynomial roots and the
    equilibrium's Krawczyk test."""
    from gyro import cbackend, questions

    dims = sorted({next(o["shape"][0] for o in m["functions"]["operator"]["outputs"] if o["name"] == "M") for m in
                   (json.loads((GENERATED / name / "metadata.json").read_text()) for name in MODELS)
                   if "operator_real_form" in m})
    return ([pytest.param([GENERATED / name / f"{name}.c"], (), id=name) for name in MODELS]
            + [pytest.param([cbackend.CSRC / f for f in cbackend.KERNELS["qep"]], (f"-DQEP_N={n}",), id=f"qep-n{n}")
               for n in dims]
            + [pytest.param([cbackend.CSRC / f for f in cbackend.KERNELS["polyroots"]], (), id="polyroots")]
            + [pytest.param([cbackend.CSRC / f for f in cbackend.KERNELS["krawczyk"]], (), id="krawczyk")]
            # the frequencies' certificate's count (a build that failed once fell back to NumPy unseen)
            + [pytest.param([Path(questions.__file__).parent / "inertia.c"], (), id="inertia")])


@pytest.mark.parametrize("sources, defines", _builds())
def test_c_compiles_without_warnings_under_the_runtime_flags(sources, defines, tmp_path):
    """The runtime's own flags (gyro.cbackend.FLAGS: -O3 -march=native, where the compiler
    sees the lanes as this machine's vectors and warns of what it cannot prove initialised)
    with -Wall -Wextra -Werror -pedantic: a user building with warnings as errors builds,
    a model's C and the kernels of every dimension the models have alike."""
    from gyro import cbackend

    cc = shutil.which("gcc") or shutil.which("cc")
    cmd = [cc, *cbackend.FLAGS, *defines, "-Wall", "-Wextra", "-Werror", "-pedantic", "-I", str(sources[0].parent),
           *map(str, sources), "-o", str(tmp_path / "lib.so"), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[:2000]
