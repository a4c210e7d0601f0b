"""Printed items of Avdonin (1969, seed 000) that the other gimbal tests do not check:
the inertia sums of 2T from the three bodies (section 1), (2.4)/(2.5) and the w scaling
(section 2), the global stability condition (section 3), V' of section 4, the sn(tau + K)
diagnosis of section 5 and the multiple-root clauses of section 6. Verdicts:
docs/paper_check.md (paper 000)."""
from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.special import ellipj, ellipk

from derive.models import gimbal_gyroscope as gg
from generated.gimbal_gyroscope import numpy_functions as nf

t = sp.Symbol("t")


# --- section 1: 2T from the outer ring, the casing and the rotor ---------------------------

def _rot(axis, a):
    c, s = sp.cos(a), sp.sin(a)
    if axis == "x":
        return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _body_rate(R):
    """Angular velocity in body axes: the axial vector of R^T R'."""
    W = sp.simplify(R.T * R.diff(t))
    return sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])


def _two_T_of_bodies(rotor_axis=2):
    """2T = outer ring + casing + rotor, each from its own angular velocity.
    Outer ring: psi about the vertical xi3, moment C3 about xi3. Casing (eta frame): the
    ring's frame turned by theta about eta1, principal moments B1, B2, B3. Rotor: the casing
    frame turned by phi about its symmetry axis (eta3 in the paper's reading, index 2 here),
    moments A1 = A2 equatorial, A3 polar."""
    C3, B1, B2, B3, A1, A3 = sp.symbols("C3 B1 B2 B3 A1 A3", positive=True)
    psi, th, ph = (sp.Function(n)(t) for n in ("psi", "theta", "phi"))
    R_ring = _rot("z", psi)
    R_case = R_ring * _rot("x", th)
    spin = sp.zeros(3, 1)
    spin[rotor_axis] = ph.diff(t)
    w_ring = _body_rate(R_ring)
    w_case = _body_rate(R_case)
    w_rot = w_case + spin  # the rotor's spin about its own axis, fixed in the casing
    I_rot = [A1, A1, A1]
    I_rot[rotor_axis] = A3
    two_T = (C3 * w_ring[2]**2
             + B1 * w_case[0]**2 + B2 * w_case[1]**2 + B3 * w_case[2]**2
             + sum(I_rot[i] * w_rot[i]**2 for i in range(3)))
    sub = {psi.diff(t): gg.psid, th.diff(t): gg.thetad, ph.diff(t): gg.phid}
    two_T = two_T.subs(sub).subs({psi: gg.psi, th: gg.theta, ph: gg.phi})
    return sp.expand(two_T), (C3, B1, B2, B3, A1, A3)


def test_inertia_sums_of_2T_from_the_three_bodies():
    """2T of ring + casing + rotor equals the model's 2T with A0 = C3 + B2 + A1,
    B0 = A1 + B1, C0 = B2 + A1 - B3 (as printed), the rotor's axis being eta3."""
    two_T, (C3, B1, B2, B3, A1, A3) = _two_T_of_bodies(rotor_axis=2)
    sums = {gg.A0: C3 + B2 + A1, gg.B0: A1 + B1, gg.C0: B2 + A1 - B3, gg.A3: A3}
    model = sp.expand(2 * gg.kinetic_energy().subs(sums))
    assert sp.simplify(two_T - model) == 0
    # and the casing's attitude matches the force function: xi3 in casing axes is
    # (0, sin theta, cos theta), so the mass centre (0, eta20, eta30) is at height
    # eta20 sin theta + eta30 cos theta, U = -P1 (that) - P l cos theta as printed
    xi3 = _rot("x", gg.theta).T * sp.Matrix([0, 0, 1])
    assert list(xi3) == [0, sp.sin(gg.theta), sp.cos(gg.theta)]


def test_the_sums_fail_with_other_assignments():
    """The check can fail: with the rotor's axis along eta2 (the OCR's 'eta2 ... along the
    symmetry axis') 2T has no A3 (phi' + psi' cos theta)^2 term, and swapping B2 and B3 in
    the sums gives a different 2T."""
    two_T, (C3, B1, B2, B3, A1, A3) = _two_T_of_bodies(rotor_axis=1)
    sums = {gg.A0: C3 + B2 + A1, gg.B0: A1 + B1, gg.C0: B2 + A1 - B3, gg.A3: A3}
    assert sp.simplify(two_T - sp.expand(2 * gg.kinetic_energy().subs(sums))) != 0
    two_T, (C3, B1, B2, B3, A1, A3) = _two_T_of_bodies(rotor_axis=2)
    wrong = {gg.A0: C3 + B3 + A1, gg.B0: A1 + B1, gg.C0: B3 + A1 - B2, gg.A3: A3}
    assert sp.simplify(two_T - sp.expand(2 * gg.kinetic_energy().subs(wrong))) != 0


# --- section 2: (2.4), (2.5) and w = sqrt(b0/(A0 B0)) (t - t0)/2 ----------------------------

c2, c3, c4, y, z = sp.symbols("c2 c3 c4 y z")
b0, b1, b2, b3, b4 = sp.symbols("b0:5")
Q = y**4 + 6 * c2 * y**2 + 4 * c3 * y + c4
PR_24 = 4 * c2 * y**2 + 4 * c3 * y + c4 + 4 * y**2 * z + 4 * c2 * z - 4 * z**2 - c2**2
G2P = c4 + 3 * c2**2           # g2' of (2.5)
G3P = c2 * c4 - c3**2 - c2**3  # g3' of (2.5)


def test_2_4_is_the_square_of_the_substitution():
    """-sqrt(Q) = y^2 + c2 - 2z squared: Q - (y^2 + c2 - 2z)^2 is the printed (2.4) (= 0)."""
    assert sp.expand(Q - (y**2 + c2 - 2 * z)**2 - PR_24) == 0


def test_differential_of_2_4_has_a_minus_sign():
    """d(2.4) = 0 gives dy/(y^2 + c2 - 2z) = -dz/(2 c2 y + 2 y z + c3): the minus of the
    later chain of equalities; the first display, printed without it, is a misprint."""
    Fy, Fz = sp.diff(PR_24, y), sp.diff(PR_24, z)
    # dy/dz = -Fz/Fy along (2.4)
    assert sp.simplify(-Fz / Fy - (y**2 + c2 - 2 * z) / (-(2 * c2 * y + 2 * y * z + c3))) == 0
    assert sp.simplify(-Fz / Fy - (y**2 + c2 - 2 * z) / (2 * c2 * y + 2 * y * z + c3)) != 0


def test_2_5_solves_2_4_and_its_invariants():
    """(2.5): y = (-c3 +- sqrt(4 z^3 - g2' z - g3'))/(2 (z + c2)) solves (2.4), with
    g2' = c4 + 3 c2^2, g3' = c2 c4 - c3^2 - c2^3; equivalently
    (2 z y + 2 c2 y + c3)^2 = 4 z^3 - g2' z - g3' on (2.4)."""
    F = 4 * z**3 - G2P * z - G3P
    # (2zy + 2c2y + c3)^2 - F is (z + c2) times the left side of (2.4)
    assert sp.expand((2 * z * y + 2 * c2 * y + c3)**2 - F - (z + c2) * PR_24) == 0
    r = sp.Symbol("r")  # r = sqrt(F)
    for sgn in (1, -1):
        ysol = (-c3 + sgn * r) / (2 * (z + c2))
        num = sp.numer(sp.together(PR_24.subs(y, ysol)))
        assert sp.expand(sp.rem(sp.expand(num), r**2 - F, r)) == 0
    # a wrong g3' (sign of c3^2 flipped) fails
    Fw = 4 * z**3 - G2P * z - (c2 * c4 + c3**2 - c2**3)
    assert sp.expand((2 * z * y + 2 * c2 * y + c3)**2 - Fw - (z + c2) * PR_24) != 0


def test_c_coefficients_and_homogeneity_give_g2_g3():
    """x = y - b1/b0 turns the quartic into b0 (y^4 + 6 c2 y^2 + 4 c3 y + c4) with the printed
    c2, c3, c4; and b0^2 g2' = g2, b0^3 g3' = g3 (the invariants of (2.6)), which is what the
    homogeneity wp(sqrt(b0) tau; g2', g3') = wp(tau; g2, g3)/b0 needs."""
    cs = {c2: (b0 * b2 - b1**2) / b0**2,
          c3: (b3 * b0**2 - 3 * b0 * b1 * b2 + 2 * b1**3) / b0**3,
          c4: (b4 * b0**3 - 4 * b0**2 * b1 * b3 + 6 * b0 * b1**2 * b2 - 3 * b1**4) / b0**4}
    x = y - b1 / b0
    quartic = b0 * x**4 + 4 * b1 * x**3 + 6 * b2 * x**2 + 4 * b3 * x + b4
    assert sp.simplify(quartic - b0 * Q.subs(cs)) == 0
    g2 = b0 * b4 - 4 * b1 * b3 + 3 * b2**2
    g3 = b0 * b2 * b4 - b1**2 * b4 - b2**3 - b0 * b3**2 + 2 * b1 * b2 * b3
    assert sp.simplify(b0**2 * G2P.subs(cs) - g2) == 0
    assert sp.simplify(b0**3 * G3P.subs(cs) - g3) == 0


def test_w_scaling():
    """With z = wp(w; g2', g3') and y from (2.5), (dy/dw)^2 = Q(y) identically (wp'' =
    6 wp^2 - g2'/2, wp'^2 = 4 wp^3 - g2' wp - g3'), both signs. So dy/dw = -+sqrt(Q), and
    -2 sqrt(A0 B0) x' = sqrt(b0 Q) (the reading without the factor x) gives
    w = sqrt(b0/(A0 B0)) (t - t0)/2 as printed; with the factor x it would not be linear in t."""
    Pw, Ppw = sp.symbols("wp wpp")  # wp(w), wp'(w)
    F = 4 * Pw**3 - G2P * Pw - G3P
    for sgn in (1, -1):
        yw = (-c3 + sgn * Ppw) / (2 * (Pw + c2))
        dy = sp.diff(yw, Pw) * Ppw + sp.diff(yw, Ppw) * (6 * Pw**2 - G2P / 2)
        num = sp.numer(sp.together(dy**2 - Q.subs(y, yw)))
        red = sp.rem(sp.expand(num), Ppw**2 - F, Ppw)
        assert sp.expand(red) == 0


# --- section 3: the global stability condition A0 Delta^(3/2) < H^2 P1^2 eta20^2 -----------

def _params(rng):
    A0, B0, A3 = rng.uniform(0.01, 0.05), rng.uniform(0.01, 0.05), rng.uniform(0.005, 0.02)
    P1, eta20, eta30, P, l = (rng.uniform(1, 10), rng.uniform(-0.02, 0.02),
                              rng.uniform(-0.02, 0.02), rng.uniform(1, 10), rng.uniform(-0.03, 0.03))
    return np.array([A0, B0, 0.0, A3, P1, eta20, eta30, P, l])


def _stationary_thetas(p, H, dpsi0):
    """All stationary theta in [-pi, pi) for given H and psi0': roots of (3.1),
    (G - H psi0') sin theta - P1 eta20 cos theta, found by a sign scan and refined."""
    a, g = p[4] * p[5], p[4] * p[6] + p[7] * p[8] - H * dpsi0
    th = np.linspace(-np.pi, np.pi, 4001)[:-1]
    f = g * np.sin(th) - a * np.cos(th)
    idx = np.nonzero(np.sign(f) != np.sign(np.roll(f, -1)))[0]
    out = []
    for i in idx:
        lo, hi = th[i], th[i] + 2 * np.pi / 4000
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if np.sign(g * np.sin(mid) - a * np.cos(mid)) == np.sign(g * np.sin(lo) - a * np.cos(lo)):
                lo = mid
            else:
                hi = mid
        out.append(0.5 * (lo + hi))
    return np.array(out), a, g


def test_global_condition_all_stationary_motions_stable():
    """For fixed H and psi0' the stationary motions (3.1) are theta0 and theta0 +- pi
    (two per turn). The generated U1'' (routh_function, each with its own
    L = A0 psi0' + H cos theta0) has opposite sqrt(Delta) terms at the two, and both are < 0
    exactly when A0 Delta^(3/2) < H^2 P1^2 eta20^2; otherwise they alternate in sign
    along theta (stable separated by unstable). 400 random cases, both regimes."""
    rng = np.random.default_rng(0)
    n_all, n_alt = 0, 0
    for _ in range(400):
        p = _params(rng)
        # G - H psi0' = r P1 eta20: psi0' chosen so that both regimes occur
        H = rng.choice([-1, 1]) * 10**rng.uniform(-3, 0)
        Gp = p[4] * p[6] + p[7] * p[8]
        dpsi0 = (Gp - rng.uniform(-3, 3) * p[4] * p[5]) / H
        ths, a, g = _stationary_thetas(p, H, dpsi0)
        assert len(ths) == 2 and abs(abs(ths[1] - ths[0]) - np.pi) < 1e-9
        Delta = a**2 + g**2
        L = p[0] * dpsi0 + H * np.cos(ths)
        U = nf.routh_function(p, ths[:, None], np.stack([np.full(2, H), L], axis=1))
        assert np.allclose(U[:, 1], 0, atol=1e-9 * (abs(a) + abs(g) + H**2 / p[0]))
        d2 = U[:, 2]
        # the Delta form, with the signs +- sqrt(Delta) at theta0 and theta0 + pi
        pm = np.sort(d2 + H**2 * a**2 / (p[0] * Delta))
        assert np.allclose(pm, [-np.sqrt(Delta), np.sqrt(Delta)], rtol=1e-9, atol=1e-12)
        lhs, rhs = p[0] * Delta**1.5, H**2 * a**2
        if abs(lhs - rhs) < 1e-6 * max(lhs, rhs):
            continue
        if lhs < rhs:
            n_all += 1
            assert np.all(d2 < 0)
        else:
            n_alt += 1
            assert np.sign(d2[0]) == -np.sign(d2[1])
    assert n_all > 20 and n_alt > 20


def test_theta0_plus_pi_is_not_an_equilibrium_of_the_same_U1():
    """The reading matters: theta0 +- pi is stationary for the same H and psi0' (another L),
    not a critical point of the same Routh function (same L) unless H^2 sin 2theta0 = 0."""
    p = np.array([0.02, 0.015, 0.0, 0.01, 5.0, 0.002, 0.01, 10.0, 0.02])
    H, dpsi0 = 0.5, 3.0
    ths, a, g = _stationary_thetas(p, H, dpsi0)
    L0 = p[0] * dpsi0 + H * np.cos(ths[0])
    U = nf.routh_function(p, ths[:, None], np.array([H, L0]))
    assert abs(U[0, 1]) < 1e-12 and abs(U[1, 1]) > 1e-3


# --- section 4: V = theta' U1, V' = U1'(theta) (U1 + theta'^2) ------------------------------

def test_section4_V_derivative():
    """Along theta'' = dU1/dtheta (4.1), V = theta' U1(theta) has V' = U1'(U1 + theta'^2)."""
    th = sp.Function("theta")(t)
    U1 = sp.Function("U1")
    V = th.diff(t) * U1(th)
    Vd = V.diff(t).subs(th.diff(t, 2), sp.diff(U1(th), th))
    assert sp.simplify(Vd - sp.diff(U1(th), th) * (U1(th) + th.diff(t)**2)) == 0
    # and with the gimbal's own U1 (3.3) and its equation B0 theta'' = dU1/dtheta at B0 = 1
    U1g = gg.routh_function().subs(gg.C0, 0)
    Ug = U1g.subs(gg.theta, th)
    Vg = th.diff(t) * Ug
    Vgd = Vg.diff(t).subs(th.diff(t, 2), sp.diff(U1g, gg.theta).subs(gg.theta, th))
    assert sp.simplify(Vgd - sp.diff(U1g, gg.theta).subs(gg.theta, th) * (Ug + th.diff(t)**2)) == 0


# --- section 5: u = u1 sn(tau + K(u1)), not sn(tau - K) -------------------------------------

@pytest.mark.parametrize("u1", [-0.3, -0.7, -0.95])
def test_section5_u1_sn_tau_plus_K(u1):
    """du/dtau = sqrt((u - u1)(u2 - u)(1 - u^2)), u1 + u2 = 0, u(0) = u1 (u1 < 0 < u2):
    u = u1 sn(tau + K, k = |u1|) meets u(0) = u1, the ODE (sign included) and the
    second-order form integrated from the turning point; sn(tau - K) (modulus |u1|)
    starts at -1, not u1, and leaves an ODE residual."""
    m = u1**2
    K = ellipk(m)
    tau = np.linspace(0, 4 * K, 801)
    sn, cn, dn, _ = ellipj(tau + K, m)
    u = u1 * sn
    du = u1 * cn * dn
    rhs2 = (u - u1) * (-u1 - u) * (1 - u**2)
    assert abs(u[0] - u1) < 1e-14
    assert np.allclose(du**2, rhs2, atol=1e-13)
    # the sign: u increases from u1 during the first half period, where the root is taken +
    half = tau < 2 * K
    assert np.all(du[half][1:-1] > 0)
    # the second-order form u'' = (1/2) d/du of the radicand, started at the turning point
    sol = solve_ivp(lambda s, Y: [Y[1], 2 * Y[0]**3 - (1 + u1**2) * Y[0]],
                    (0, tau[-1]), [u1, 0.0], t_eval=tau, rtol=1e-12, atol=1e-14, method="DOP853")
    assert np.max(np.abs(sol.y[0] - u)) < 1e-8
    # the earlier reading
    snm, cnm, dnm, _ = ellipj(tau - K, m)
    assert abs(snm[0] - u1) > 1e-2
    res = (cnm * dnm)**2 - (snm - u1) * (-u1 - snm) * (1 - snm**2)
    assert np.max(np.abs(res)) > 1e-2
    # sn(tau - K) = -sn(tau + K): the printed correct form is -u1 times the earlier one
    assert np.allclose(u, -u1 * snm, atol=1e-14)


# --- section 6: e = sqrt(g2/12) and the clause (g2/3)^(3/2) = +-g3 --------------------------

def test_multiple_root_e_sqrt_g2_over_12():
    """F = 4 z^3 - g2 z - g3 has a double root c iff g2 = 12 c^2, g3 = -8 c^3; the double root
    is the largest (c > 0) iff (g2/3)^(3/2) = -g3, and then e = sqrt(g2/12) (as printed in
    the last clause). With (g2/3)^(3/2) = +g3 the double root is -sqrt(g2/12) < 0 and the
    largest root is the simple 2 sqrt(g2/12) = sqrt(g2/3)."""
    c, zz = sp.symbols("c z")
    g2s, g3s = sp.symbols("g2 g3", positive=True)
    Fc = sp.expand(4 * (zz - c)**2 * (zz + 2 * c))
    assert sp.Poly(Fc, zz).all_coeffs() == [4, 0, -12 * c**2, 8 * c**3]
    cp = sp.sqrt(g2s / 12)
    assert sp.simplify(-8 * cp**3 + (g2s / 3)**sp.Rational(3, 2)) == 0   # c > 0: g3 = -(g2/3)^(3/2)
    assert sp.simplify(-8 * (-cp)**3 - (g2s / 3)**sp.Rational(3, 2)) == 0  # c < 0: g3 = +(g2/3)^(3/2)
    assert sp.simplify(2 * cp - sp.sqrt(g2s / 3)) == 0


def test_case3_clause_g3_equals_plus_g2_over_3_cubed_half():
    """Case 3 (b0 = 0, b4 > 0): when (g2/3)^(3/2) = g3 (a double root below the largest,
    simple root e = sqrt(g2/3)), e < b2/2, as printed; when (g2/3)^(3/2) = -g3 the
    largest root is double and equals sqrt(g2/12). Built from random b1, b2, b3 with b4
    solved from g3 (linear in b4 at b0 = 0); checked against numpy's roots of F."""
    rng = np.random.default_rng(1)
    n_plus = n_minus = 0
    for _ in range(6000):
        B1, B2, B3 = rng.normal(size=3)
        g2 = -4 * B1 * B3 + 3 * B2**2
        if g2 <= 0.05 or abs(B1) < 0.1:
            continue
        for sgn in (1, -1):
            g3 = sgn * (g2 / 3)**1.5
            B4 = (-g3 - B2**3 + 2 * B1 * B2 * B3) / B1**2   # g3 = -b1^2 b4 - b2^3 + 2 b1 b2 b3
            if B4 <= 0:
                continue
            r = np.sort(np.roots([4, 0, -g2, -g3]).real)
            e = r[-1]
            assert abs(4 * (B2 / 2)**3 - g2 * B2 / 2 - g3 - B1**2 * B4) < 1e-9 * (1 + abs(g3))
            if sgn == 1:
                n_plus += 1
                assert abs(e - np.sqrt(g2 / 3)) < 1e-6 * np.sqrt(g2)
                assert e < B2 / 2
            else:
                n_minus += 1
                assert abs(e - np.sqrt(g2 / 12)) < 1e-6 * np.sqrt(g2)
                assert abs(r[-2] - e) < 1e-6 * np.sqrt(g2)   # the largest root is double
    assert n_plus > 30 and n_minus > 30, (n_plus, n_minus)
