"""The closed form of section 2 (Avdonin 1969): the substitution that gives the quartic,
the readings of (2.6), (2.7), g2, g3 derived symbolically, the vectorised Weierstrass
functions, and agreement with integration of the generated equations (1.1) over 100 periods."""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from gyro import load
from gyro.systems.gimbal_gyroscope import ClosedForm, Motion, Weierstrass, integrate, integrals

DEFAULTS = load("gimbal_gyroscope").defaults  # the model's illustrative set

b0, b1, b2, b3, b4, P, W = sp.symbols("b0 b1 b2 b3 b4 wp wpd")
r = sp.Symbol("r", positive=True)  # sqrt(b0)
G2 = r**2 * b4 - 4 * b1 * b3 + 3 * b2**2  # as printed
G3 = r**2 * b2 * b4 - b1**2 * b4 - b2**3 - r**2 * b3**2 + 2 * b1 * b2 * b3  # as printed


def _R(s):
    return r**2 + 4 * b1 * s + 6 * b2 * s**2 + 4 * b3 * s**3 + b4 * s**4


def _solves_quartic(s, g2=G2, g3=G3):
    """(ds/dtau)^2 - R(s) reduced modulo wp'^2 = 4 wp^3 - g2 wp - g3 (wp'' = 6 wp^2 - g2/2):
    zero iff s(wp(tau), wp'(tau)) solves (ds/dtau)^2 = R(s) for these invariants."""
    ds = sp.diff(s, P) * W + sp.diff(s, W) * (6 * P**2 - g2 / 2)
    num = sp.expand(sp.numer(sp.together(ds**2 - _R(s))))
    rem = sp.rem(sp.Poly(num, W), sp.Poly(W**2 - (4 * P**3 - g2 * P - g3), W))
    return sp.expand(rem.as_expr()) == 0


def _s_26(sign, r_=r):
    """(2.6) read as in ../shared/PAPERS.md: s = tan((theta - theta0)/2)."""
    return 2 * (r_**2 * P + r_**2 * b2 - b1**2) / (sign * r_ * W - 2 * b1 * P - r_**2 * b3 + b1 * b2)


def test_substitution_gives_the_printed_quartic_and_no_factor_x():
    """(2.2) with x^-1 = tan((theta - theta0)/2): (1 + x^2)^2 f = b0 x^4 + 4 b1 x^3 + 6 b2 x^2
    + 4 b3 x + b4 with the printed b's (theta0^2 read theta0'^2), and theta' = -2 x'/(1 + x^2),
    so -2 sqrt(A0 B0) x' = sqrt(quartic): no factor x on the left."""
    A0, B0, a1, G, H, dpsi, dth, th0, x = sp.symbols("A0 B0 Pe G H dpsi dth theta0 x", real=True)
    th = th0 + 2 * sp.atan(1 / x)
    c = sp.cos(th0) - sp.cos(th)
    f = A0 * B0 * dth**2 + 2 * A0 * a1 * (sp.sin(th0) - sp.sin(th)) + 2 * A0 * (G - H * dpsi) * c - H**2 * c**2
    s0, c0 = sp.sin(th0), sp.cos(th0)
    bb = [A0 * B0 * dth**2,
          A0 * (G - H * dpsi) * s0 - A0 * a1 * c0,
          (A0 * B0 * dth**2 + 2 * A0 * (G - H * dpsi) * c0 + 2 * A0 * a1 * s0 - 2 * H**2 * s0**2) / 3,
          A0 * (G - H * dpsi) * s0 - A0 * a1 * c0 - H**2 * sp.sin(2 * th0),
          A0 * B0 * dth**2 + 4 * A0 * (G - H * dpsi) * c0 + 4 * A0 * a1 * s0 - 4 * H**2 * c0**2]
    quartic = bb[0] * x**4 + 4 * bb[1] * x**3 + 6 * bb[2] * x**2 + 4 * bb[3] * x + bb[4]
    diff = sp.expand_trig(sp.expand((1 + x**2) ** 2 * f - quartic))
    for xv in (sp.Rational(3, 7), sp.Rational(-5, 2), 4):  # trig identities: check at exact points
        for t0v in (sp.Rational(1, 3), 2):
            val = diff.subs({x: xv, th0: t0v}).subs({A0: 2, B0: 3, a1: sp.Rational(1, 5), G: 7, H: 5,
                                                    dpsi: sp.Rational(1, 3), dth: sp.Rational(3, 2)})
            assert abs(sp.N(val, 50)) < 1e-40
    t = sp.Symbol("t")
    xf = sp.Function("x")(t)
    thdot = sp.diff(th0 + 2 * sp.atan(1 / xf), t)
    assert sp.simplify(thdot - (-2 * sp.diff(xf, t) / (1 + xf**2))) == 0


@pytest.mark.parametrize("sign", [+1, -1])
def test_2_6_with_both_signs_solves_the_quartic_with_printed_invariants(sign):
    assert _solves_quartic(_s_26(sign))


def test_misreadings_of_2_6_and_g3_fail():
    """The derivation decides between readings: g3 without 2 b1 b2 b3 does not give a
    solution, nor does the OCR's radical over the whole denominator."""
    assert not _solves_quartic(_s_26(-1), g3=G3 - 2 * b1 * b2 * b3)
    # the radical over the whole denominator: the residual at a point of the curve
    whole = 2 * (r**2 * P + r**2 * b2 - b1**2) / sp.sqrt(r**2 * W - 2 * b1 * P - r**2 * b3 + b1 * b2)
    ds = sp.diff(whole, P) * W + sp.diff(whole, W) * (6 * P**2 - G2 / 2)
    vals = {r: 2, b1: sp.Rational(1, 3), b2: sp.Rational(1, 2), b3: sp.Rational(-1, 5), b4: 1, P: 3}
    vals[W] = sp.sqrt((4 * P**3 - G2 * P - G3).subs(vals))
    assert abs(sp.N((ds**2 - _R(whole)).subs(vals), 30)) > 1e-3


def test_sign_minus_starts_increasing_and_2_7_is_the_limit_b0_to_0():
    """Laurent series of wp at 0: s = -+sqrt(b0) tau + b1 tau^2 + ..., so the minus sign of
    (2.6) is theta increasing at t0 (as the text says); s(0) = 0, s'' = 2 b1 = R'(0)/2;
    b0 -> 0 gives (2.7), s = 2 b1 / (2 wp - b2)."""
    tau = sp.Symbol("tau")
    wp = 1 / tau**2 + G2 * tau**2 / 20 + G3 * tau**4 / 28
    for sign, lead in ((-1, r), (+1, -r)):
        ser = sp.series(_s_26(sign).subs({P: wp, W: sp.diff(wp, tau)}), tau, 0, 3).removeO()
        assert sp.expand(ser - (lead * tau + b1 * tau**2)) == 0
    limit = sp.limit(_s_26(-1), r, 0)
    assert sp.simplify(limit - 2 * b1 / (2 * P - b2)) == 0


def test_conjugate_form_is_the_same_function():
    """(2.6) times its conjugate: Dp Dbar = -2 (2 (wp - b2/2)^2 - b0 b4/2)(b0 wp + b0 b2 - b1^2),
    so s = (-+ sqrt(b0) wp' + 2 b1 wp + b0 b3 - b1 b2) / (2 (wp - b2/2)^2 - b0 b4/2), the form
    the runtime uses where (2.6) is 0/0."""
    for sign in (+1, -1):
        Dp = sign * r * W - 2 * b1 * P - r**2 * b3 + b1 * b2
        Dbar = -sign * r * W - 2 * b1 * P - r**2 * b3 + b1 * b2
        Dw = 2 * (P - b2 / 2) ** 2 - r**2 * b4 / 2
        ident = sp.expand(Dp * Dbar + 2 * Dw * (r**2 * P + r**2 * b2 - b1**2))
        rem = sp.rem(sp.Poly(ident, W), sp.Poly(W**2 - (4 * P**3 - G2 * P - G3), W))
        assert sp.expand(rem.as_expr()) == 0


@pytest.mark.parametrize("g2, g3", [(3.0, 0.5), (3.0, -0.9), (1.0, 2.0), (-2.0, 1.0), (12.0, -8.0 + 1e-9)])
def test_weierstrass_satisfies_its_equation_and_has_the_pole_at_0(g2, g3):
    """wp'^2 = 4 wp^3 - g2 wp - g3 (relative 1e-12: a handful of roundings on terms of the size
    of wp'^2), wp' the derivative of wp (central difference, h^2 error ~1e-9 relative),
    wp ~ 1/tau^2 at 0: these fix wp uniquely. The difference quotient's error, h^2/6 times
    the third derivative ~ 2 (h/tau)^2 wp' near the pole, is <= 2e-6 relative here: bound 1e-5. Real and complex roots, one near a double root."""
    import mpmath as mp

    wp = Weierstrass(mp.mpf(g2), mp.mpf(g3))
    om = float(wp.omega)
    tau = np.linspace(0.01, 1.99, 199) * om
    Pv, Wv = wp(tau)
    assert np.all(np.abs(Wv**2 - (4 * Pv**3 - g2 * Pv - g3)) <= 1e-12 * (Wv**2 + 4 * np.abs(Pv) ** 3 + 1))
    h = 1e-5 * om
    Pp, _ = wp(tau + h)
    Pm, _ = wp(tau - h)
    assert np.all(np.abs((Pp - Pm) / (2 * h) - Wv) <= 1e-5 * (np.abs(Wv) + 1))
    small = np.array([1e-4, 1e-3]) * om
    assert np.allclose(wp(small)[0] * small**2, 1, rtol=1e-6, atol=0)
    assert math.isclose(wp(np.array([om]))[0][0], float(wp.e_top), rel_tol=1e-12, abs_tol=1e-12)


# ------------------------------------------------------------------ agreement with integration

# (theta0, dtheta0, dpsi0, dphi0) with the default parameters, one per kind of motion:
CASES = {
    "oscillation, theta0' = 0 (2.7)": (1.2, 0.0, 1.0, 200.0),
    "oscillation, theta increasing at t0": (1.2, 3.0, 1.0, 200.0),
    "oscillation, theta decreasing at t0": (1.2, -3.0, 1.0, 200.0),
    "wide oscillation past theta0 + pi, one real root": (0.3, 0.5, 0.2, 5.0),
    "wide oscillation, theta decreasing": (2.0, -10.0, 0.0, 10.0),
    "rotation": (1.2, 30.0, 1.0, 20.0),
}


RTOL, ATOL = 2.5e-14, 1e-16  # DOP853 near its floor (scipy clamps rtol at 100 eps)


def _compare(ic, periods=100, n=4001):
    mo = Motion(DEFAULTS, *ic)
    cf = ClosedForm(mo)
    t = np.linspace(0, periods * cf.period, n)
    th = cf.theta(t)
    psi, phi = cf.psi_phi(t)
    q, qd = integrate(mo, t, "DOP853", rtol=RTOL, atol=ATOL)
    return cf, th, psi, phi, q, qd


@pytest.mark.parametrize("name", list(CASES))
def test_closed_form_agrees_with_DOP853_over_100_periods(name):
    """theta, psi, phi of the closed form and of DOP853 (rtol 2.5e-14) on the generated
    equations over 100 periods agree to 1e-9 of the largest value each angle takes; H, L,
    M stay constant along the integration to 1e-9 relative. The integrator is the less
    accurate side: its global error grows with the number of periods (at rtol 1e-13 the
    wide oscillations reach 2e-10 and 9e-10, at 2.5e-14 below 2e-10), while the closed
    form's phase error is that of its period, ~1e-15 per period."""
    cf, th, psi, phi, q, qd = _compare(CASES[name])
    assert cf.motion_type == ("monotone" if name == "rotation" else "periodic")
    for closed, integ in ((th, q[:, 1]), (psi, q[:, 0]), (phi, q[:, 2])):
        assert np.max(np.abs(closed - integ)) <= 1e-9 * np.max(np.abs(integ))
    for k, v in integrals(DEFAULTS, q, qd).items():
        assert np.max(np.abs(v - v[0])) <= 1e-9 * max(abs(v[0]), 1e-12)


def test_the_other_sign_in_2_6_is_far_off():
    """The test above can fail: with the plus sign for an increasing start, theta runs
    backwards and misses the integration by far more than 1e-9."""
    mo = Motion(DEFAULTS, *CASES["oscillation, theta increasing at t0"])
    cf = ClosedForm(mo)
    t = np.linspace(0, 2 * cf.period, 401)
    q, _ = integrate(mo, t, "DOP853", rtol=1e-13, atol=1e-15)
    cf.sign = -cf.sign
    assert np.max(np.abs(cf.theta(t) - q[:, 1])) > 1e-3


# 25 draws (~0.5 s each, ~12 s): random from hypothesis, derandomized so that CI runs the
# same sets each time (docs/gimbal.md says so); draws rejected by assume() do not count.
@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(A0=st.floats(0.005, 0.05), B0=st.floats(0.005, 0.05), A3=st.floats(0.002, 0.02),
       P1=st.floats(0.0, 20.0), eta20=st.floats(-0.01, 0.01), eta30=st.floats(-0.02, 0.02),
       P=st.floats(0.0, 20.0), l=st.floats(-0.03, 0.03), theta0=st.floats(-3.0, 3.0),
       dtheta0=st.floats(-20.0, 20.0), dpsi0=st.floats(-5.0, 5.0), dphi0=st.floats(-100.0, 100.0))
def test_closed_form_against_integration_at_random_physical_parameters(A0, B0, A3, P1, eta20, eta30, P, l,
                                                                       theta0, dtheta0, dpsi0, dphi0):
    """Random gyroscopes and initial states over 20 periods (at most 10 s): 1e-9 of max |theta|,
    or of 1 mrad where theta stays smaller (rounding of angles near 0 is absolute, ~1e-16 rad).
    Motions within 1e-4 of a separatrix (1 - m < 1e-4) are left out: there the integrator's
    own error is amplified by the saddle (bench/gimbal_integrators.py shows it)."""
    p = dict(DEFAULTS, A0=A0, B0=B0, A3=A3, P1=P1, eta20=eta20, eta30=eta30, P=P, l=l)
    mo = Motion(p, theta0, dtheta0, dpsi0, dphi0)
    cf = ClosedForm(mo)
    assume(cf.motion_type in ("periodic", "monotone") and cf.m1 > 1e-4)
    T = min(20 * cf.period, 10.0)
    t = np.linspace(0, T, 801)
    q, _ = integrate(mo, t, "DOP853", rtol=RTOL, atol=ATOL)
    th = cf.theta(t)
    assert np.max(np.abs(th - q[:, 1])) <= 1e-9 * max(np.max(np.abs(q[:, 1])), 1e-3)


def test_closed_form_C0_nonzero_is_refused():
    from gyro.systems.gimbal_gyroscope import ClosedFormError

    with pytest.raises(ClosedFormError, match="C0"):
        ClosedForm(Motion(dict(DEFAULTS, C0=0.001), 1.2, 0.0, 1.0, 200.0))


@pytest.mark.parametrize("B0", [0.03125, 0.0333230904802231])
def test_uniform_rotation_without_gravity(B0):
    """No weight, no rotor momentum: theta = theta0 + theta0' t exactly. F has a double root
    (below e), which rounding may tip to one real root, and s passes through infinity at the
    turning instant tau = omega of wp: found by hypothesis, once counted twice (4 pi off)."""
    p = dict(DEFAULTS, A0=0.03125, B0=B0, A3=0.015625, P1=0.0, eta20=0.0, eta30=0.0, P=0.0, l=0.0)
    cf = ClosedForm(Motion(p, 0.0, 1.0, 0.0, 0.0))
    t = np.linspace(0, 10, 1001)
    assert cf.motion_type == "monotone"
    assert np.max(np.abs(cf.theta(t) - t)) < 1e-13 * 10
