"""gyro.intervals' compiled walker (gyro/csrc/intervals.c) against its NumPy walker: the same
bits for the rational operations and sqrt (the same formulas of outward rounding), within a
few ulps of the interval's ends for the libm functions (another library's sin, exp, ...,
each widened by TRANSCENDENTAL_ULPS), every point of the boxes enclosed, [-inf, inf] where
no enclosure is possible; the precession's tube function the same in both."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from gyro import cbackend
from gyro import intervals as iv


def _compiled():
    if iv._kernel() is None:
        pytest.skip("no C compiler: the NumPy walker answers")


def _every_op():
    """A Function of x (2) using every operation the walker has, and its NumPy twin."""
    x = ca.SX.sym("x", 2)
    a, b = x[0], x[1]
    e = ca.vertcat(
        a + b, a - b, a * b, a / (b + 3), -a, 2 * a, 1 / (b + 3), a ** 2, ca.sqrt(b + 3), ca.fabs(a),
        ca.sin(a * 3), ca.cos(b * 2), ca.tan(a / 2), ca.exp(a), ca.log(b + 3), a ** 3, (b + 3) ** 1.5, a ** -2,
        ca.atan(b), ca.tanh(a), ca.sinh(b), ca.asinh(a), ca.cosh(b), ca.fmin(a, b), ca.fmax(a, b), ca.erf(a),
        (a + 2) ** (b + 2))
    from scipy.special import erf

    def twin(p, q):
        return np.array([p + q, p - q, p * q, p / (q + 3), -p, 2 * p, 1 / (q + 3), p ** 2, np.sqrt(q + 3), np.abs(p),
                         np.sin(p * 3), np.cos(q * 2), np.tan(p / 2), np.exp(p), np.log(q + 3), p ** 3,
                         (q + 3) ** 1.5, p ** -2.0, np.arctan(q), np.tanh(p), np.sinh(q), np.arcsinh(p), np.cosh(q),
                         np.minimum(p, q), np.maximum(p, q), erf(p), (p + 2) ** (q + 2)])
    return ca.Function("every_op", [x], [e]), twin


def _boxes(n, seed):
    r = np.random.default_rng(seed)
    c = r.uniform(-1.5, 1.5, (2, n))
    h = 10.0 ** r.uniform(-12, 0, (2, n)) * r.integers(0, 2, (2, n))  # points too (h = 0)
    return c - h, c + h


def test_every_operation_encloses_random_points_and_matches_numpy():
    _compiled()
    f, twin = _every_op()
    lo, hi = _boxes(500, 1)
    (cl, ch), = iv.evaluate(f, [(lo, hi)])
    (nl, nh), = iv.evaluate(f, [(lo, hi)], compiled=False)
    r = np.random.default_rng(2)
    with np.errstate(all="ignore"):
        for _ in range(20):
            t = r.uniform(size=lo.shape)
            p = lo + t * (hi - lo)
            v = twin(*p)
            ok = np.isnan(v) | ((cl <= v) & (v <= ch))
            assert ok.all(), np.argwhere(~ok)[:5]
    # the same formulas: equal ends, or (libm's functions, a**(non-integer)) within 4 ulps
    # of the ends' magnitude plus the NumPy walker's own width times 1e-12
    fin = np.isfinite(nl) & np.isfinite(nh) & np.isfinite(cl) & np.isfinite(ch)
    assert fin.mean() > 0.9  # (a**-2, 1/x ... where a box holds 0: no enclosure, in both)
    assert np.array_equal(np.isfinite(cl), np.isfinite(nl)) and np.array_equal(np.isfinite(ch), np.isfinite(nh))
    with np.errstate(invalid="ignore"):
        slack = 4 * iv.EPS * np.maximum(np.abs(nl), np.abs(nh)) + 1e-12 * (nh - nl) + iv.TINY
        assert np.all(np.abs(cl - nl)[fin] <= slack[fin]) and np.all(np.abs(ch - nh)[fin] <= slack[fin])
    rational = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 15, 17, 23, 24]  # +, -, *, /, neg, twice, inv, sq, sqrt, fabs, a^n
    assert np.array_equal(cl[rational], nl[rational]) and np.array_equal(ch[rational], nh[rational])


def test_no_enclosure_is_entire_in_c():
    _compiled()
    x = ca.SX.sym("x", 2)
    f = ca.Function("bad", [x], [ca.vertcat(1 / x[0], ca.log(x[1]), ca.sqrt(x[1]), ca.tan(x[0] * 2), x[0] * 2)])
    lo, hi = np.array([[-1.0, 0.5], [-1.0, 0.5]]), np.array([[1.0, 0.6], [2.0, 0.6]])
    (cl, ch), = iv.evaluate(f, [(lo, hi)])
    assert np.all(cl[:4, 0] == -np.inf) and np.all(ch[:4, 0] == np.inf)  # 0 in the divisor, log/sqrt below 0, a pole
    assert np.all(np.isfinite(cl[:, 1])) and np.all(np.isfinite(ch[:, 1]))
    inf = np.array([[np.inf], [0.0]])  # inf * 0: NaN inside, [-inf, inf] outside
    g = ca.Function("nan", [x], [x[0] * x[1] + 1])
    (gl, gh), = iv.evaluate(g, [(inf, inf)])
    assert gl[0, 0] == -np.inf and gh[0, 0] == np.inf


def test_the_precession_tube_is_the_same_in_c_and_numpy_and_without_a_compiler():
    _compiled()
    from gyro.systems import gimbal_precession as pr

    values = pr.parameters({})
    P = pr.vector(values)
    r = np.random.default_rng(3)
    c = np.array([[0.3], [-0.5], [values["H"]]]) + r.normal(size=(3, 70)) * [[0.3], [0.3], [0.01]]
    w = np.abs(r.normal(size=(3, 70))) * [[1e-3], [1e-3], [1e-6]]
    f = pr._tube_function()
    (cl, ch), = iv.evaluate(f, [(P, P), (c - w, c + w)])
    (nl, nh), = iv.evaluate(f, [(P, P), (c - w, c + w)], compiled=False)
    assert np.array_equal(cl, nl) and np.array_equal(ch, nh)
    with cbackend.disabled():  # the fallback: the NumPy walker
        (dl, dh), = iv.evaluate(f, [(P, P), (c - w, c + w)])
    assert np.array_equal(dl, nl) and np.array_equal(dh, nh)
    at = np.array(f(P, (c - w + 2 * w * r.uniform(size=c.shape)))).T  # points of the boxes
    assert np.all((cl.T <= at) & (at <= ch.T))
