"""gyro.intervals: interval evaluation of CasADi SX Functions over boxes encloses every point
of the boxes (random points, and mpmath's own interval arithmetic at 60 digits), never
answers finitely where it cannot enclose, and its matrix bounds hold for random matrices
of the box."""
from __future__ import annotations

import casadi as ca
import mpmath
import numpy as np
import pytest

from gyro import intervals as iv


def _graphs():
    """(name, builder over CasADi or mpmath.iv symbols, input boxes' centres and half widths)."""
    return [
        ("trig", lambda x, y, m: m.sin(x) * m.cos(y) - m.cos(x) ** 2 / (2 + m.sin(y)), (0.3, -1.2), (0.4, 0.7)),
        ("exp-log", lambda x, y, m: m.exp(x - y) * m.log(1 + x * x) + m.sqrt(4 + y) / (3 - x), (0.5, 0.8), (0.3, 0.2)),
        ("atan-tanh", lambda x, y, m: m.atan(x * y) - m.tanh(y - x) + (x - y) ** 3, (-0.7, 0.4), (0.5, 0.5)),
        ("cancel", lambda x, y, m: (x + y) ** 2 - x * x - 2 * x * y - y * y + m.sin(x) ** 2 + m.cos(x) ** 2, (1.1, -0.3), (1e-3, 2e-3)),
        ("wide sin", lambda x, y, m: m.sin(x) + m.cos(y), (2.0, 3.0), (2.5, 1.0)),
    ]


class _CA:
    sin, cos, exp, log, sqrt, atan, tanh = ca.sin, ca.cos, ca.exp, ca.log, ca.sqrt, ca.atan, ca.tanh


class _NP:
    sin, cos, exp, log, sqrt, atan, tanh = np.sin, np.cos, np.exp, np.log, np.sqrt, np.arctan, np.tanh


def _function(build):
    x = ca.SX.sym("x", 2)
    return ca.Function("f", [x], [build(x[0], x[1], _CA)])


@pytest.mark.parametrize("name,build,centre,half", _graphs(), ids=[g[0] for g in _graphs()])
def test_the_interval_encloses_every_point_of_the_boxes(name, build, centre, half):
    f = _function(build)
    rng = np.random.default_rng(1)
    n = 300
    c = np.array(centre)[:, None] + np.array(half)[:, None] * rng.uniform(-1, 1, (2, n))
    w = np.array(half)[:, None] * rng.uniform(0, 1, (2, n))
    lo, hi = c - w, c + w
    (flo, fhi), = iv.evaluate(f, [(lo, hi)])
    assert np.all(np.isfinite(flo)) and np.all(np.isfinite(fhi))
    for _ in range(20):
        pts = lo + rng.uniform(0, 1, lo.shape) * (hi - lo)
        val = np.array(f(pts)).ravel()
        assert np.all(flo <= val) and np.all(val <= fhi), name
    ends = np.array(f(lo)).ravel(), np.array(f(hi)).ravel()  # the corners too
    assert np.all(flo <= np.minimum(*ends)) and np.all(np.maximum(*ends) <= fhi)


@pytest.mark.parametrize("name,build,centre,half", _graphs(), ids=[g[0] for g in _graphs()])
def test_the_interval_holds_mpmaths_60_digit_values(name, build, centre, half):
    """At points (degenerate boxes, where rounding alone decides) the interval holds the
    exact value (mpmath.iv's enclosure at 60 digits; mpmath at 60 digits where mpmath.iv has
    no atan, tanh); on boxes, it holds mpmath.iv's enclosure of the box's centre."""
    f = _function(build)
    rng = np.random.default_rng(2)
    ctx = mpmath.iv if name != "atan-tanh" else mpmath.mp
    old = ctx.dps
    ctx.dps = 60

    class _M:
        sin, cos, exp, log, sqrt = ctx.sin, ctx.cos, ctx.exp, ctx.log, ctx.sqrt
        atan, tanh = getattr(ctx, "atan", None), getattr(ctx, "tanh", None)

    def exact(a, b):  # (lower, upper) of the exact value at the point (a, b), as mpf
        v = build(ctx.mpf(float(a)), ctx.mpf(float(b)), _M)
        return (v.a, v.b) if ctx is mpmath.iv else (v - mpmath.mpf("1e-55"), v + mpmath.mpf("1e-55"))

    try:
        for width in (0.0, 1.0):
            for _ in range(15):
                c = np.array(centre) + np.array(half) * rng.uniform(-1, 1, 2)
                w = width * np.array(half) * rng.uniform(0, 1, 2)
                (flo, fhi), = iv.evaluate(f, [(c - w, c + w)])
                lo_, hi_ = exact(*c)
                assert mpmath.mpf(float(flo[0])) <= lo_ and hi_ <= mpmath.mpf(float(fhi[0])), (name, c, w)
    finally:
        ctx.dps = old


def test_what_it_cannot_enclose_is_the_whole_line():
    x = ca.SX.sym("x")
    cases = {
        "a division by an interval holding 0": 1 / x,
        "a logarithm reaching below 0": ca.log(x + 0.5),
        "a square root reaching below 0": ca.sqrt(x),
        "a comparison (no extension)": ca.if_else(x > 0, x, -x),
        "tan across its pole": ca.tan(x + np.pi / 2),
    }
    for why, expr in cases.items():
        f = ca.Function("f", [x], [expr])
        (lo, hi), = iv.evaluate(f, [(np.array([-1.0]), np.array([1.0]))])
        assert lo[0] == -np.inf and hi[0] == np.inf, why
    f = ca.Function("f", [x], [1 / x])  # away from 0: finite and enclosing
    (lo, hi), = iv.evaluate(f, [(np.array([2.0]), np.array([4.0]))])
    assert lo[0] <= 0.25 and hi[0] >= 0.5 and np.isfinite(lo[0]) and np.isfinite(hi[0])
    f = ca.Function("f", [x], [ca.exp(1000 * x) - ca.exp(999 * x)])  # inf - inf: NaN inside, never a number
    (lo, hi), = iv.evaluate(f, [(np.array([1.0]), np.array([2.0]))])
    assert lo[0] == -np.inf and hi[0] == np.inf


def test_the_centred_form_encloses_and_is_tighter_on_a_cancellation():
    x = ca.SX.sym("x", 2)
    expr = ca.sin(x[0]) * ca.cos(x[0]) - ca.sin(2 * x[0]) / 2 + 1e-6 * x[1] ** 2  # 1e-6 x1^2 exactly
    f = ca.Function("f", [x], [expr])
    J = iv.jacobian_function(f, 0)
    lo, hi = np.array([[0.7], [0.1]]), np.array([[0.71], [0.2]])
    (nlo, nhi), = iv.evaluate(f, [(lo, hi)])
    (clo, chi), = iv.centred(f, J, 0, [(lo, hi)])
    assert clo[0, 0] <= 1e-8 and chi[0, 0] >= 4e-8  # the range: [1e-8, 4e-8]
    assert chi[0, 0] - clo[0, 0] < (nhi[0, 0] - nlo[0, 0]) / 20  # 2e-4 against 1.2e-2: the square of the width


def test_the_matrix_bounds_hold_for_every_matrix_of_the_box():
    rng = np.random.default_rng(4)
    n, k = 200, 3
    A = rng.normal(size=(n, k, k))
    A = (A + np.swapaxes(A, 1, 2)) / 2
    rad = 10.0 ** rng.uniform(-8, -1, (n, 1, 1)) * rng.uniform(0, 1, (n, k, k))
    rad = (rad + np.swapaxes(rad, 1, 2)) / 2
    lo, hi = A - rad, A + rad
    top, bottom = iv.lambda_max_upper(lo, hi), iv.lambda_min_lower(lo, hi)
    M = np.maximum(np.abs(lo), np.abs(hi))
    norm = iv.norm2_upper(M)
    for _ in range(30):
        B = lo + rng.uniform(0, 1, lo.shape) * (hi - lo)
        B = (B + np.swapaxes(B, 1, 2)) / 2
        ev = np.linalg.eigvalsh(B)
        assert np.all(ev[:, -1] <= top) and np.all(ev[:, 0] >= bottom)
        assert np.all(np.linalg.norm(B, 2, axis=(1, 2)) <= norm)
    ev = np.linalg.eigvalsh(A)  # and near the truth: Weyl's margin, not Gershgorin's
    assert np.all(top - ev[:, -1] <= 2 * np.sqrt(np.sum(rad**2, axis=(1, 2))) + 1e-12 * np.abs(ev).max(axis=1) + 1e-300)
