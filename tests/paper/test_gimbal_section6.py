"""Section 6 of Avdonin (1969): the cases 1-3 by the roots of F(z) (6.1), the properties
a)-e) of theta(t), the four motion types on examples, and the mean drift <psi'>."""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from gyro import load
from gyro.systems.gimbal_gyroscope import (ClosedForm, Motion, U1_second, integrate, kick, mean_drift_paper, section6_case,
                         stationary_motion, theta1_property_a, turning_motion, turning_points)

DEFAULTS = load("gimbal_gyroscope").defaults  # the model's illustrative set
WIDE = (0.3, 0.5, 0.2, 5.0)  # an oscillation wider than pi (one real root of F)


def test_F_at_half_b2_and_the_roots_of_case_2():
    """b0 = 0: F(b2/2) = b1^2 b4, and at b4 = 0 the roots are z1 = b2/2 and
    z2,3 = (-b2 +- sqrt(9 b2^2 - 16 b1 b3))/4, as printed."""
    b1, b2, b3, b4, z = sp.symbols("b1 b2 b3 b4 z")
    g2 = -4 * b1 * b3 + 3 * b2**2
    g3 = -b1**2 * b4 - b2**3 + 2 * b1 * b2 * b3
    F = 4 * z**3 - g2 * z - g3
    assert sp.expand(F.subs(z, b2 / 2) - b1**2 * b4) == 0
    d = sp.sqrt(9 * b2**2 - 16 * b1 * b3)
    printed = 4 * (z - b2 / 2) * (z - (-b2 + d) / 4) * (z - (-b2 - d) / 4)
    assert sp.expand(F.subs(b4, 0) - printed) == 0


_b = st.floats(-3, 3, allow_nan=False).filter(lambda x: abs(x) > 1e-3)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(b1=_b, b2=_b, b3=_b, b4=_b)
def test_cases_1_2_3_against_the_roots(b1, b2, b3, b4):
    """1: b4 < 0 gives b2/2 < e. 2: b4 = 0, e as the rules (a), (b) say. 3: b4 > 0 gives
    e < b2/2 with one real root, and with three exactly when b1 b3 > 0 and b2 > 0. The
    margins stay clear of rounding: cases with |e - b2/2| below 1e-9 are not decided."""
    c = section6_case(b1, b2, b3, -abs(b4))
    assert c["case"] == 1 and c["e"] > b2 / 2
    c = section6_case(b1, b2, b3, 0.0)
    assert c["case"] == 2 and abs(c["paper_e"] - c["e"]) <= 1e-9 * (1 + abs(c["e"]))
    c = section6_case(b1, b2, b3, abs(b4))
    if abs(c["e"] - b2 / 2) > 1e-9:
        three = c["g2"] ** 3 - 27 * c["g3"] ** 2 >= 0
        assert (c["e"] < b2 / 2) == ((b1 * b3 > 0 and b2 > 0) if three else True)


def _period_extremes(cf, n=20001):
    t = np.linspace(0, cf.period, n)
    th = cf.theta(t)
    return th.min(), th.max()


def _b0_zero(ic):
    """The motion restarted at its turning point beyond theta0 (b0 = 0), section 6."""
    mo = Motion(DEFAULTS, *ic)
    roots = turning_points(mo)
    return mo, turning_motion(mo, roots[np.argmin(np.abs(roots - ic[0]))])


@pytest.mark.parametrize("ic, wide", [((1.2, 3.0, 1.0, 200.0), False), (WIDE, True)])
def test_properties_a_b_d_and_the_restart_at_a_root(ic, wide):
    """a) theta stays between theta0 and theta1 = theta0 + 2 Arctg[2 b1/(2 e - b2)];
    b) e > b2/2 gives |theta1 - theta0| < pi; d) e < b2/2 gives pi < |theta1 - theta0| < 2 pi.
    The b0 != 0 motion restarted at its root (b0 = 0) has the same period (g2, g3 do not
    depend on the starting point) and the same range. Extremes sampled at 2e4 points per
    period agree to 1e-6 rad (quadratic in the sampling step)."""
    mo, mo0 = _b0_zero(ic)
    cf, cf0 = ClosedForm(mo), ClosedForm(mo0)
    assert cf0.b[0] == 0 and cf0.motion_type == "periodic"
    _, b1, b2, _, _ = cf0.b
    e = float(cf0.wp.e_top)
    th1 = mo0.theta0 + theta1_property_a(b1, b2, e)
    lo, hi = _period_extremes(cf0)
    assert abs(min(mo0.theta0, th1) - lo) < 1e-6 and abs(max(mo0.theta0, th1) - hi) < 1e-6
    d = abs(th1 - mo0.theta0)
    assert (e < b2 / 2) == wide
    assert (math.pi < d < 2 * math.pi) if wide else (d < math.pi)
    assert math.isclose(cf.period, cf0.period, rel_tol=1e-12)
    lo1, hi1 = _period_extremes(cf)
    assert abs(lo1 - lo) < 1e-6 and abs(hi1 - hi) < 1e-6


def test_property_c_e_equal_to_half_b2_reaches_theta0_plus_pi():
    """c) e = b2/2 (case 2, b4 = 0 with b1 b3 > 0, b2 > 0): theta1 - theta0 = pi; theta reaches
    the opposite angle and turns there. b4 = 0 holds only to rounding, which splits a double
    root by ~sqrt(1e-16): the far point is pi to 1e-6."""
    th0, H = 0.3, 0.02
    p = DEFAULTS
    a, h, s0, c0 = p["A0"] * p["P1"] * p["eta20"], H**2, math.sin(th0), math.cos(th0)
    g = (h * c0**2 - a * s0) / c0  # b4 = 0
    G = p["P1"] * p["eta30"] + p["P"] * p["l"]
    dpsi = (G - g / p["A0"]) / H
    mo = Motion(p, th0, 0.0, dpsi, H / p["A3"] - dpsi * c0)
    cf = ClosedForm(mo)
    _, b1, b2, b3, b4 = cf.b
    assert abs(b4) < 1e-13 * max(map(abs, cf.b)) and b1 * b3 > 0 and b2 > 0
    c = section6_case(b1, b2, b3, 0.0)
    assert c["paper_e"] == c["z1"] and abs(c["e"] - b2 / 2) < 1e-6 * abs(b2)
    lo, hi = _period_extremes(cf)
    assert abs(max(abs(lo - th0), abs(hi - th0)) - math.pi) < 1e-6
    assert cf.motion_type == "periodic"


def test_stationary_type():
    """(3.1)-(3.2): theta stays at theta0 (to the rounding of psi0' from (3.1), 1e-12 rad)."""
    mo = stationary_motion(DEFAULTS, 1.2, 2.0)
    cf = ClosedForm(mo)
    assert cf.motion_type == "stationary"
    assert np.max(np.abs(cf.theta(np.linspace(0, 10, 1001)) - 1.2)) < 1e-12


def test_monotone_type_gains_2_pi_per_period():
    """No root of f (b0 != 0): theta increases monotonically and gains 2 pi per period of wp."""
    mo = Motion(DEFAULTS, 1.2, 30.0, 1.0, 20.0)
    cf = ClosedForm(mo)
    assert cf.motion_type == "monotone" and len(turning_points(mo)) == 0
    t = np.linspace(0, 3 * cf.period, 30001)
    th = cf.theta(t)
    assert np.all(np.diff(th) > 0)
    assert abs(cf.theta(np.array([cf.period]))[0] - 1.2 - 2 * math.pi) < 1e-12


def test_periodic_type_returns_after_one_period():
    mo = Motion(DEFAULTS, *WIDE)
    cf = ClosedForm(mo)
    t = np.linspace(0, cf.period, 101)
    assert cf.motion_type == "periodic"
    assert np.max(np.abs(cf.theta(t + 7 * cf.period) - cf.theta(t))) < 1e-11


def test_asymptotic_type_property_e():
    """e) e a multiple root: started at the far turning point of the separatrix of an
    unstable stationary motion (U1'' > 0), theta tends to it with the saddle's exponent
    lambda = sqrt(U1''/B0) (fitted over 4 time constants from t = 8 s, where
    theta - theta_s ~ 1e-4 and the nonlinear correction to the rate is of that order: 1e-3), and the integrator agrees
    over the first 2 s (1e-9). Near it, the period grows as (4/lambda) ln(1/eps) with the
    kick eps: two passages near the saddle per period."""
    st_ = stationary_motion(DEFAULTS, 0.3, 0.05)
    I = st_.integrals0
    lam = math.sqrt(U1_second(DEFAULTS, 0.3, I["H"], I["L"]) / DEFAULTS["B0"])
    assert ClosedForm(st_).motion_type == "stationary"
    far = max(turning_points(st_), key=lambda x: abs(x - 0.3))
    mo = turning_motion(st_, far)
    cf = ClosedForm(mo)
    assert cf.motion_type == "asymptotic"
    t = np.linspace(8.0, 8.0 + 4 / lam, 5)
    d = np.abs(cf.theta(t) - 0.3)
    rate = -np.polyfit(t, np.log(d), 1)[0]
    assert abs(rate / lam - 1) < 1e-3
    ts = np.linspace(0, 2, 201)
    q, _ = integrate(mo, ts, "DOP853", rtol=2.5e-14, atol=1e-16)
    assert np.max(np.abs(cf.theta(ts) - q[:, 1])) < 1e-9
    T = [ClosedForm(kick(st_, eps)).period for eps in (1e-4, 1e-7, 1e-10)]
    for T1, T2 in zip(T, T[1:]):
        assert abs((T2 - T1) / (4 / lam * math.log(1e3)) - 1) < 1e-3


# ------------------------------------------------------------------ the mean drift <psi'>


def _drift(mo, periods=100):
    cf = ClosedForm(mo)
    T = periods * cf.period
    psi_cf, _ = cf.psi_phi(np.array([T]))
    q, _ = integrate(mo, np.linspace(0, T, 3), "DOP853", rtol=2.5e-14, atol=1e-16)
    a, b = sorted(turning_points(mo), key=lambda x: abs(x - mo.theta0))[:2]
    return psi_cf[0] / T, q[-1, 0] / T, mean_drift_paper(mo, a, b)


def test_mean_drift_by_the_paper_integral_against_simulation():
    """<psi'> by the paper's integral equals psi(N T)/(N T) of the closed form (1e-10: two
    quadratures) and of DOP853 over 100 periods (1e-9, the integrator's accumulated error);
    here (6.2) does not hold and <psi'> differs from L/A0 by far more."""
    _, mo = _b0_zero((1.2, 3.0, 1.0, 200.0))
    cf_avg, int_avg, paper = _drift(mo)
    assert abs(cf_avg - paper) < 1e-10 * abs(paper)
    assert abs(int_avg - paper) < 1e-9 * abs(paper)
    assert abs(paper - mo.integrals0["L"] / DEFAULTS["A0"]) > 1e-3 * abs(paper)


@pytest.mark.parametrize("G_zero", [False, True])
def test_under_6_2_the_mean_drift_is_L_over_A0(G_zero):
    """(6.2) A0 G = L H: <psi'> = L/A0 (f depends on sin theta only: the motion between
    theta0 and pi - theta0 is symmetric about pi/2). With G = L = 0 the drift vanishes although
    P1 eta20 != 0. The oscillation's extremes are roots of f = H^2 (sin - sin theta0)(sin - s*),
    so it always runs to sin theta = +-1 and back: the symmetry the paper uses always holds."""
    p = dict(DEFAULTS, l=-DEFAULTS["P1"] * DEFAULTS["eta30"] / DEFAULTS["P"]) if G_zero else DEFAULTS
    G = p["P1"] * p["eta30"] + p["P"] * p["l"]
    th0, H = 1.0, 0.05
    L = p["A0"] * G / H
    dpsi = (L - H * math.cos(th0)) / p["A0"]
    mo = Motion(p, th0, 0.0, dpsi, H / p["A3"] - dpsi * math.cos(th0))
    cf_avg, int_avg, paper = _drift(mo)
    scale = abs(H / p["A0"])  # the size of psi' itself
    for v in (cf_avg, int_avg, paper):
        assert abs(v - L / p["A0"]) < 1e-9 * scale
    if G_zero:
        assert abs(L) < 1e-15 and abs(paper) < 1e-9 * scale
