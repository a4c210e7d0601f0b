"""The heavy gyroscope in a gimbal (Avdonin 1969, seed 000) on the generic pipeline: its
equations (1.1), first integrals (1.2), Routh's modified force function and the stability
test (3.3). The emitted code is checked with every model in tests/generated/test_generated.py."""
from __future__ import annotations

import numpy as np

from gyro import load
import pytest
import sympy as sp

from derive import mechanics as mech
from derive.models import gimbal_gyroscope as gg
from tests.conftest import derived


def test_equations_1_1_as_printed_at_C0_0():
    L = gg.lagrangian().subs(gg.C0, 0)
    E = mech.lagrange_equations(L, gg.q, gg.qd, gg.qdd)
    for e, printed in zip(E, gg.printed_equations()):
        assert sp.simplify(e - printed) == 0


def test_first_integrals_are_conserved_and_a_wrong_one_is_not():
    """(1.2) H, L, M at C0 = 0 and the momenta and energy for general C0 are conserved;
    M with a wrong factor (3 G cos theta instead of 2) is not: the check can fail."""
    assert all(r == 0 for r in gg.integrals_are_conserved())
    printed = gg.printed_integrals()
    wrong = printed["M"] + gg.G * sp.cos(gg.theta)
    (rate,) = mech.integral_rates(gg.lagrangian().subs(gg.C0, 0), gg.q, gg.qd, gg.qdd, [wrong])
    assert sp.simplify(rate) != 0


def _U1():
    """Routh's modified force function of section 3 (C0 = 0)."""
    th = gg.theta
    return -gg.P1 * gg.eta20 * sp.sin(th) - gg.G * sp.cos(th) - (gg.L - gg.H * sp.cos(th))**2 / (2 * gg.A0)


def test_equilibrium_equation_is_U1_prime_and_stationary_motions_are_3_1():
    """The pipeline's equilibrium equation of the Routh function is dU1/dtheta; at L =
    A0 psi0' + H cos(theta0) it is the stationary-motion condition (3.1)."""
    _, d, _ = derived("gimbal_gyroscope")
    r = d.equilibrium_residual[0].subs(gg.C0, 0)
    assert sp.simplify(r - sp.diff(_U1(), gg.theta)) == 0
    psi0d = sp.Symbol("psi0_d")
    at_L = r.subs(gg.L, gg.A0 * psi0d + gg.H * sp.cos(gg.theta))
    printed = (gg.G - gg.H * psi0d) * sp.sin(gg.theta) - gg.P1 * gg.eta20 * sp.cos(gg.theta)  # (3.1)
    assert sp.simplify(at_L - printed) == 0


def test_stiffness_is_minus_U1_second_derivative_3_3():
    """K of the reduced operator is -U1''(theta0): a stationary motion is stable (K > 0)
    where U1 has a maximum, (3.3); with L = A0 psi0' + H cos(theta0), U1'' is the printed
    P1 eta20 sin + (G - H psi0') cos - H^2 sin^2/A0."""
    _, d, _ = derived("gimbal_gyroscope")
    K = d.operator.K[0, 0].subs(gg.C0, 0)
    assert sp.simplify(K + sp.diff(_U1(), gg.theta, 2)) == 0
    psi0d = sp.Symbol("psi0_d")
    th = gg.theta
    U1pp = sp.diff(_U1(), th, 2).subs(gg.L, gg.A0 * psi0d + gg.H * sp.cos(th))
    printed = (gg.P1 * gg.eta20 * sp.sin(th) + (gg.G - gg.H * psi0d) * sp.cos(th)
               - gg.H**2 * sp.sin(th)**2 / gg.A0)
    assert sp.simplify(U1pp - printed) == 0


def test_reduced_operator_has_no_gyroscopic_term_with_one_coordinate():
    _, d, _ = derived("gimbal_gyroscope")
    assert d.operator.D == sp.zeros(1, 1)
    assert sp.simplify(d.operator.M[0, 0] - gg.B0) == 0


# ------------------------------------------------------------------ section 5


def _residuals_along(theta_t, psid_t, t):
    """The Lagrange expressions of all three coordinates (C0 = 0, P1 eta20 = 0) along a
    motion given by theta(t) and psi'(t), with phi' from the integral A3 (phi' + psi' cos) = H."""
    L = gg.lagrangian().subs({gg.C0: 0, gg.eta20: 0})
    E = mech.lagrange_equations(L, gg.q, gg.qd, gg.qdd)
    phid_t = gg.H / gg.A3 - psid_t * sp.cos(theta_t)
    sub = {gg.theta: theta_t, gg.thetad: sp.diff(theta_t, t), sp.Symbol("theta_dd"): sp.diff(theta_t, t, 2),
           gg.psid: psid_t, sp.Symbol("psi_dd"): sp.diff(psid_t, t),
           gg.phid: phid_t, sp.Symbol("phi_dd"): sp.diff(phid_t, t)}
    return [e.subs(sub) for e in E]


def test_section_5_theta_pi_over_2_is_the_motion_and_the_earlier_formula_is_not():
    """theta0 = pi/2, theta0' = 0, G - H psi0' = 0, P1 eta20 = 0: theta = pi/2, psi' = psi0'
    leaves no residual in the equations; the earlier cos(theta) = -cos(H t/sqrt(A0 B0)),
    psi' = psi0' + (H/A0)|cos(H t/sqrt(A0 B0))| leaves one of size H^2/A0 in the theta
    equation (it does not even start at theta0 = pi/2)."""
    t = sp.Symbol("t", positive=True)
    psi0d = gg.G / gg.H  # G - H psi0' = 0
    true = _residuals_along(sp.pi / 2 + 0 * t, psi0d + 0 * t, t)
    assert all(sp.simplify(r) == 0 for r in true)
    w = gg.H / sp.sqrt(gg.A0 * gg.B0)
    earlier = _residuals_along(sp.acos(-sp.cos(w * t)), psi0d + gg.H / gg.A0 * sp.Abs(sp.cos(w * t)), t)
    vals = {gg.A0: 0.02, gg.B0: 0.015, gg.A3: 0.01, gg.P1: 5.0, gg.eta30: 0.01, gg.P: 10.0,
            gg.l: 0.02, gg.H: 2.0}
    scale = float((gg.H**2 / gg.A0).subs(vals))
    for tv in (0.003, 0.011, 0.017):
        r_theta = float(earlier[1].subs(vals).subs(t, tv))
        assert abs(r_theta) > 1e-3 * scale
    assert float(sp.acos(-sp.cos(w * t)).subs(vals).subs(t, 0)) == float(sp.pi)


# ------------------------------------------------------------------ section 3, stationary motions


def _stationary(values, theta0, H):
    """psi0' from (3.1) and L from (1.2) for a stationary motion at theta0 with momentum H."""
    G = values["P1"] * values["eta30"] + values["P"] * values["l"]
    psi0d = (G - values["P1"] * values["eta20"] * np.cos(theta0) / np.sin(theta0)) / H
    L = values["A0"] * psi0d + H * np.cos(theta0)
    return psi0d, L, G


def _U1pp(values, theta0, H):
    """U1''(theta0) = -K of the emitted reduced operator."""
    import generated.gimbal_gyroscope.numpy_functions as nf

    _, L, _ = _stationary(values, theta0, H)
    P = np.array([values[n] for n in ("A0", "B0", "C0", "A3", "P1", "eta20", "eta30", "P", "l")])
    _, _, K = nf.operator(P, [theta0], [H, L])
    r = nf.equilibrium_residual(P, [theta0], [H, L])
    return -K[0, 0], r[0]


DEFAULTS = load("gimbal_gyroscope").defaults  # the model's illustrative set


@pytest.mark.parametrize("theta0, H", [(1.2, 2.0), (1.2, 0.05), (2.4, 2.0), (0.3, 0.5)])
def test_stationary_motion_3_1_and_the_delta_form_of_3_3(theta0, H):
    """At psi0' from (3.1) the emitted equilibrium equation vanishes, and the emitted U1''
    equals the Delta form +-sqrt(Delta) - H^2 P1^2 eta20^2/(A0 Delta), with the sign of
    P1 eta20 sin(theta0) + (G - H psi0') cos(theta0)."""
    v = DEFAULTS
    psi0d, _, G = _stationary(v, theta0, H)
    U1pp, r = _U1pp(v, theta0, H)
    assert abs(r) < 1e-12 * (G + H**2 / v["A0"])
    a, b = v["P1"] * v["eta20"], G - H * psi0d
    Delta = a**2 + b**2
    sign = np.sign(a * np.sin(theta0) + b * np.cos(theta0))
    assert abs(U1pp - (sign * np.sqrt(Delta) - H**2 * a**2 / (v["A0"] * Delta))) < 1e-10 * (np.sqrt(Delta) + H**2 / v["A0"])


def _max_deviation(theta0, H, T, eps=1e-4):
    """Integrate the emitted full equations from the stationary motion with theta0 + eps
    and return the largest |theta - theta0| over [0, T]."""
    from scipy.integrate import solve_ivp

    import generated.gimbal_gyroscope.numpy_functions as nf

    v = DEFAULTS
    psi0d, _, _ = _stationary(v, theta0, H)
    P = np.array([v[n] for n in ("A0", "B0", "C0", "A3", "P1", "eta20", "eta30", "P", "l")])
    phid = H / v["A3"] - psi0d * np.cos(theta0)
    y0 = np.array([0.0, theta0 + eps, 0.0, psi0d, 0.0, phid])

    def rhs(_, y):
        return np.concatenate([y[3:], np.linalg.solve(nf.mass_matrix(P, y[:3]), nf.forcing(P, y[:3], y[3:]))])

    def far(_, y):
        return abs(y[1] - theta0) - 0.1
    far.terminal = True
    sol = solve_ivp(rhs, (0, T), y0, method="DOP853", rtol=1e-10, atol=1e-12, events=far, max_step=T / 2000)
    return np.max(np.abs(sol.y[1] - theta0))


def test_perturbed_stationary_motions_bounded_where_U1_has_a_maximum():
    """(3.3): U1''(theta0) < 0 (a maximum) gives a stable stationary motion: a 1e-4
    perturbation stays of its size; U1'' > 0 (a minimum) an unstable one: it grows past
    0.1 rad. Cases: a fast rotor near the horizontal (stable) and a slow rotor with the
    centre of mass above the support (G > 0 at theta0 = 0.3: unstable, the top falls)."""
    stable = (1.2, 2.0)
    unstable = (0.3, 0.05)
    assert _U1pp(DEFAULTS, *stable)[0] < 0 < _U1pp(DEFAULTS, *unstable)[0]
    assert _max_deviation(*stable, T=20.0) < 1e-3
    assert _max_deviation(*unstable, T=20.0) >= 0.1
