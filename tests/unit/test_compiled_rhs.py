"""gyro.ode.numpy_rhs and numpy_variational through CasADi's own C (gyro.ode.compiled): the same operations
as the CasADi Function, so the same bits, with the forcing's further inputs given as a
function of time; and the CasADi Function where there is no compiler."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from gyro import cbackend, ode
from gyro.models import load


@pytest.mark.parametrize("name", ["torsion_gyrocompass", "gyrohorizoncompass", "gimbal_precession"])
def test_the_compiled_equations_are_the_casadi_functions_to_the_bit(name):
    m = load(name)
    P = m.vector()
    n = len(m.meta["coordinates"])
    s = ode.symbolic(m)
    rng = np.random.default_rng(1)
    extra = tuple(rng.normal(size=v.numel()) for v in s.inputs)  # the torsion gyrocompass's given forces
    assert ode.compiled(m, "rhs") is not None
    fun = ode.numpy_rhs(m, P, (lambda t: extra) if extra else None)
    F = ode.rhs(m)
    for _ in range(5):
        y = rng.normal(size=2 * n) * 1e-2
        want = np.asarray(F(y, ca.DM(P), *extra)).ravel()
        got = fun(0.3, y)
        assert np.array_equal(got, want)
        assert got is not fun(0.3, y)  # a fresh array each call: SciPy keeps the ones it gets


def test_without_a_compiler_the_casadi_function_answers():
    m = load("gimbal_precession")
    P = m.vector()
    y = np.full(2 * len(m.meta["coordinates"]), 0.01)
    want = ode.numpy_rhs(m, P)(0.0, y)
    ode._CACHE.pop(ode._key(m, "compiled_rhs"), None)
    try:
        with cbackend.disabled():
            assert ode.compiled(m, "rhs") is None
            assert np.array_equal(ode.numpy_rhs(m, P)(0.0, y), want)
    finally:
        ode._CACHE.pop(ode._key(m, "compiled_rhs"), None)


def test_the_compiled_variational_equations_are_the_casadi_functions_to_the_bit():
    """The monodromy's right-hand side (the periodic forced response's shooting)."""
    m = load("torsion_gyrocompass")
    P = m.vector()
    s = ode.symbolic(m)
    rng = np.random.default_rng(2)
    extra = tuple(rng.normal(size=v.numel()) for v in s.inputs)
    fun, n = ode.numpy_variational(m, P, lambda t: extra)
    assert ode.compiled(m, "variational") is not None
    F = ode.variational(m)
    Y = rng.normal(size=n + n * n) * 1e-2
    yd, phid = F(Y[:n], Y[n:].reshape(n, n, order="F"), ca.DM(P), *extra)
    want = np.concatenate([np.asarray(yd).ravel(), np.asarray(phid).ravel(order="F")])
    assert np.array_equal(fun(0.1, Y), want)
