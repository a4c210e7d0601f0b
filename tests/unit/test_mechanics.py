"""The generic mechanics on small systems with known answers, and the model's kinematics
against the paper's printed formulas (1.2), (1.5), (1.6)."""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech


def test_rotation_sequence_is_the_printed_S():
    from derive.models import torsion_gyrocompass as tg

    al, be, ga = tg.alpha, tg.beta, tg.gamma
    c, s = sp.cos, sp.sin
    printed = sp.Matrix([  # (1.2)
        [c(al) * c(ga) - s(al) * s(be) * s(ga), -s(al) * c(be), c(al) * s(ga) + s(al) * s(be) * c(ga)],
        [s(al) * c(ga) + s(be) * c(al) * s(ga), c(al) * c(be), s(al) * s(ga) - s(be) * c(al) * c(ga)],
        [-s(ga) * c(be), s(be), c(be) * c(ga)],
    ])
    S, *_ = tg.frames()
    assert sp.simplify(S - printed) == sp.zeros(3, 3)


def test_angular_velocities_are_the_printed_p_and_r():
    from derive.models import torsion_gyrocompass as tg

    S, u_vec, p, r = tg.frames()
    c, s = sp.cos, sp.sin
    ga, g1, g2 = tg.gamma, tg.gamma1, tg.gamma2
    a_u3 = tg.alphad + tg.u3
    printed_p = sp.Matrix([  # (1.5)
        tg.betad * c(ga) + a_u3 * S[2, 0] + tg.u2 * S[1, 0],
        tg.gammad + a_u3 * S[2, 1] + tg.u2 * S[1, 1],
        tg.betad * s(ga) + a_u3 * S[2, 2] + tg.u2 * S[1, 2],
    ])
    assert sp.simplify(p - printed_p) == sp.zeros(3, 1)
    p1, p2, p3 = printed_p
    printed_r = sp.Matrix([  # (1.6)
        p1 * c(g1) + p2 * s(g1) + tg.gamma2d,
        -p1 * s(g1) * c(g2) + p2 * c(g2) * c(g1) + (p3 + tg.gamma1d) * s(g2) + tg.gamma3d,
        p1 * s(g1) * s(g2) - p2 * c(g1) * s(g2) + (p3 + tg.gamma1d) * c(g2),
    ])
    assert sp.simplify(r - printed_r) == sp.zeros(3, 1)


def test_lagrange_equations_of_a_pendulum():
    th, thd, thdd, m, l, g = sp.symbols("theta theta_d theta_dd m l g")
    L = m * l**2 * thd**2 / 2 + m * g * l * sp.cos(th)
    (E,) = mech.lagrange_equations(L, [th], [thd], [thdd])
    assert sp.simplify(E - (m * l**2 * thdd + m * g * l * sp.sin(th))) == 0
    Mq, f = mech.mass_matrix_form(L, [th], [thd])
    assert sp.simplify(Mq[0, 0] * thdd - f[0] - E) == 0


def test_routhian_of_a_spinning_symmetric_top_gives_its_known_reduced_lagrangian():
    """Heavy symmetric top, Euler angles (psi, theta, phi); phi is cyclic with p_phi = C n."""
    th, ps, ph = sp.symbols("theta psi phi")
    thd, psd, phd = sp.symbols("theta_d psi_d phi_d")
    A, C, P, l, n = sp.symbols("A C P l n")
    L = (A * (thd**2 + psd**2 * sp.sin(th)**2) / 2 + C * (phd + psd * sp.cos(th))**2 / 2
         - P * l * sp.cos(th))
    assert mech.is_cyclic(L, ph)
    R = mech.routhian(L, phd, C * n)
    expected = A * (thd**2 + psd**2 * sp.sin(th)**2) / 2 + C * n * psd * sp.cos(th) - P * l * sp.cos(th) - C * n**2 / 2
    assert sp.simplify(R - expected) == 0


def test_quadratic_expansion_of_a_rotating_particle_gives_coriolis_and_centrifugal_terms():
    """A particle on springs in a frame rotating at w: D = [[0, -2mw], [2mw, 0]],
    K = diag(k - m w^2)."""
    x, y, xd, yd, m, k, w = sp.symbols("x y x_d y_d m k w")
    vx, vy = xd - w * y, yd + w * x
    L = m * (vx**2 + vy**2) / 2 - k * (x**2 + y**2) / 2
    op = mech.quadratic_expansion(L, [x, y], [xd, yd], at={x: 0, y: 0})
    assert op.M == sp.diag(m, m)
    assert sp.simplify(op.D - sp.Matrix([[0, -2 * m * w], [2 * m * w, 0]])) == sp.zeros(2, 2)
    assert sp.simplify(op.K - sp.diag(k - m * w**2, k - m * w**2)) == sp.zeros(2, 2)
    E = mech.lagrange_equations(L, [x, y], [xd, yd], sp.symbols("x_dd y_dd"))
    op1 = mech.linearize_equations(E, [x, y], [xd, yd], sp.symbols("x_dd y_dd"), at={x: 0, y: 0})
    assert sp.simplify(op1.D - op.D) == sp.zeros(2, 2) and sp.simplify(op1.K - op.K) == sp.zeros(2, 2)
    # det J(p) is even in p: (m p^2 + k - m w^2)^2 + 4 m^2 w^2 p^2
    p, z = sp.symbols("p z")
    c = mech.charpoly_in_p2(op.J(p), p, z)
    expected = sp.Poly(sp.expand(((m * z + k - m * w**2)**2 + 4 * m**2 * w**2 * z)), z).all_coeffs()[::-1]
    assert [sp.expand(a - b) for a, b in zip(c, expected)] == [0, 0, 0]


def test_eliminating_a_cyclic_velocity_from_the_full_equations_equals_routh():
    th, ps, ph = sp.symbols("theta psi phi")
    thd, psd, phd = sp.symbols("theta_d psi_d phi_d")
    thdd, psdd, phdd = sp.symbols("theta_dd psi_dd phi_dd")
    A, C, P, l, beta = sp.symbols("A C P l beta")
    L = (A * (thd**2 + psd**2 * sp.sin(th)**2) / 2 + C * (phd + psd * sp.cos(th))**2 / 2
         - P * l * sp.cos(th))
    q, qd, qdd = [th, ps, ph], [thd, psd, phd], [thdd, psdd, phdd]
    E = mech.lagrange_equations(L, q, qd, qdd)
    E2 = mech.eliminate_cyclic(E, q, qd, qdd, 2, L, beta)
    R = mech.routhian(L, phd, beta)
    ER = mech.lagrange_equations(R, q[:2], qd[:2], qdd[:2])
    assert all(sp.simplify(a - b) == 0 for a, b in zip(E2, ER))


def test_blocks_find_the_diagonal_blocks_up_to_permutation():
    a, b, c = sp.symbols("a b c")
    J = sp.Matrix([[a, 0, b], [0, c, 0], [b, 0, a]])
    assert mech.blocks(J) == [[0, 2], [1]]


def test_a_total_time_derivative_is_a_null_lagrangian():
    x, y, xd, yd = sp.symbols("x y x_d y_d")
    F = sp.sin(x) * y**2
    dL = mech.time_derivative(F, [x, y], [xd, yd]) + 7
    assert mech.null_lagrangian_residual(dL, [x, y], [xd, yd], sp.symbols("x_dd y_dd")) == [0, 0]


def test_two_coupled_cyclic_coordinates_eliminated_together_equal_routh_twice():
    """Heavy symmetric top: psi and phi are both cyclic, with coupled momenta
    p_psi = A psi' sin^2 + C (phi' + psi' cos) cos, p_phi = C (phi' + psi' cos)."""
    th, ps, ph = sp.symbols("theta psi phi")
    thd, psd, phd = sp.symbols("theta_d psi_d phi_d")
    thdd, psdd, phdd = sp.symbols("theta_dd psi_dd phi_dd")
    A, C, P, l, a, b = sp.symbols("A C P l a b")
    L = (A * (thd**2 + psd**2 * sp.sin(th)**2) / 2 + C * (phd + psd * sp.cos(th))**2 / 2
         - P * l * sp.cos(th))
    q, qd, qdd = [th, ps, ph], [thd, psd, phd], [thdd, psdd, phdd]
    E = mech.lagrange_equations(L, q, qd, qdd)
    (E2,) = mech.eliminate_cyclic(E, q, qd, qdd, [1, 2], L, [a, b])
    R = mech.routhian(mech.routhian(L, phd, b), psd, a)
    (ER,) = mech.lagrange_equations(R, [th], [thd], [thdd])
    assert sp.simplify(E2 - ER) == 0
    # the classical reduced equation: A theta'' = P l sin(th) + ... (no psi', phi' left)
    assert not E2.has(psd) and not E2.has(phd)
