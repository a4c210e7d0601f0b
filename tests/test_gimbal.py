"""The heavy gyroscope in a gimbal (Avdonin 1969, seed 000) on the generic pipeline: its
equations (1.1), first integrals (1.2), Routh's modified force function and the stability
test (3.3). The emitted code is checked with every model in tests/test_generated.py."""
from __future__ import annotations

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
