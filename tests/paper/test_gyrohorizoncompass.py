"""The gyrohorizoncompass in a Newtonian field (Zavozin 1979, shared/seeds/001): items 1-3.

The paper prints no numerical example: its claims are formulas and conditions, checked here
as symbolic identities, spectra and simulations. Numerics go through the emitted code, derived
into a temporary folder (`python -m derive gyrohorizoncompass --out tmp`). The readings and
the evidence for each: docs/gyrohorizoncompass.md.
"""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

from derive import names
from derive.models import gyrohorizoncompass as ghc

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
q, qd, qdd = ghc.q, ghc.qd, ghc.qdd
A, B, C, J, L, I, nu, zeta, eta, lam = (p.symbol for p in ghc.PARAMETERS)
theta, chi = ghc.theta, ghc.chi


@pytest.fixture(scope="module")
def emitted(tmp_path_factory):
    from gyro.models import load

    out = tmp_path_factory.mktemp("ghc")
    proc = subprocess.run([sys.executable, "-m", "derive", "gyrohorizoncompass", "--out", str(out)],
                          cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return load(out / "gyrohorizoncompass")


def _P(model, values):
    return model.vector(model.parameters(values))


def _eps0(model, P):
    return float(np.ravel(model.numpy.relative_equilibrium(P)[0])[0])


def _E(model, P, y):
    return float(np.ravel(model.numpy.first_integral(P, y[:4], y[4:])[0])[0])


def _frequencies(model, P):
    """|Im| of the linearised system's eigenvalues at (3.1), one per mode, ascending; and
    the largest |Re| (0 for a spectrum on the imaginary axis)."""
    M, D, K = model.numpy.operator(P, np.array([0.0, 0.0, 0.0, _eps0(model, P)]))
    Z = np.zeros((4, 4))
    ev = np.linalg.eigvals(np.block([[Z, np.eye(4)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]]))
    return np.sort(np.abs(ev.imag))[::2], np.max(np.abs(ev.real))


# --------------------------------------------------------------------------- item 1: the model


def test_names_and_the_lambda_mapping():
    assert [p.name for p in ghc.PARAMETERS] == ["A", "B", "C", "J", "L", "I", "nu", "zeta", "eta", "lam"]
    assert names.problem("lambda") == "a keyword of C or Python"
    assert ghc.CLI_NAMES == {"lambda": "lam"}
    for n in [p.name for p in ghc.PARAMETERS] + ghc.COORDINATES:
        assert names.problem(n) is None, n
    assert ghc.COORDINATES == ["alpha", "beta", "gamma", "epsilon"]


def test_direction_cosines_are_1_1():
    """a_ij = a_i . e_j of (1.1) as printed, against S = Rz(alpha) Rx(beta) Ry(gamma)."""
    a, b, g = q[:3]
    ca, sa, cb, sb, cg, sg = sp.cos(a), sp.sin(a), sp.cos(b), sp.sin(b), sp.cos(g), sp.sin(g)
    printed = sp.Matrix([[ca * cg - sa * sb * sg, -sa * cb, ca * sg + sa * sb * cg],
                         [sa * cg + ca * sb * sg, ca * cb, sa * sg - ca * sb * cg],
                         [-cb * sg, sb, cb * cg]])
    S, omega1, omega2, omega, a2, a3 = ghc.frames()
    assert (S - printed).applyfunc(sp.expand) == sp.zeros(3, 3)
    assert (omega - omega1 - omega2).applyfunc(sp.expand) == sp.zeros(3, 1)  # (1.2)
    # (1.3): a_i' = a_i x omega2 (local derivatives in e1, e2, e3)
    for ai in (a2, a3):
        d = ghc.mech.time_derivative(ai, q, qd) - ghc.mech.cross(ai, omega2)
        assert d.applyfunc(lambda e: sp.simplify(e)) == sp.zeros(3, 1)


def test_lagrange_equations_are_1_5_and_1_6():
    """The generic machinery's Lagrange equations, projected: (1.5) on the angles' axes, (1.6)."""
    assert ghc.equations_are_the_papers() == [0, 0, 0, 0]


def test_emitted_equations_are_1_5_and_1_6(emitted):
    """Mq q'' - f of the emitted code equals W' (1.5) and (1.6), evaluated from the printed
    equations at random states of the laboratory set (independent code: SymPy's lambdify)."""
    eq15, eq16 = ghc.printed_equations()
    _, _, _, omega, _, _ = ghc.frames()
    W = omega.jacobian(list(qd[:3]))
    printed = list(W.T * eq15) + [eq16.subs(sp.Symbol("epsilon_dd"), qdd[3])]
    syms = [p.symbol for p in ghc.PARAMETERS] + list(q) + list(qd) + list(qdd)
    f = sp.lambdify(syms, printed, "numpy")
    P = _P(emitted, ghc.LAB)
    rng = np.random.default_rng(1)
    for _ in range(5):
        x, v, a = rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)
        x[3] += 1.0
        lhs = emitted.numpy.mass_matrix(P, x) @ a - emitted.numpy.forcing(P, x, v)
        np.testing.assert_allclose(lhs, f(*P, *x, *v, *a), rtol=0, atol=1e-13)


def test_H_and_I():
    """H = 2 L cos(epsilon) e2; the sensor moment (2.1) N = 2 L^2 sin(2 eps)/(I lambda) is the
    derivative of the E-term 2 L^2 sin^2(eps)/(I lambda): the two readings belong together."""
    assert ghc.kinetic_momentum() == sp.Matrix([0, 2 * L * sp.cos(q[3]), 0])
    U_N = 2 * L**2 * sp.sin(q[3])**2 / (I * lam)
    assert sp.simplify(sp.diff(U_N, q[3]) - ghc.sensor_moment()) == 0
    # without I in (2.1) (the OCR's "2 L^2 sin 2eps / lambda") N is not that derivative
    assert sp.simplify(sp.diff(U_N, q[3]) - 2 * L**2 * sp.sin(2 * q[3]) / lam) != 0


def test_parameter_sets():
    """Earth: theta, chi near 1e-7; laboratory: O(0.1), lambda = 1 + chi in both."""
    for values, lo, hi in ((ghc.EARTH, 1e-8, 1e-6), (ghc.LAB, 0.01, 0.5)):
        th = (values["C"] - values["A"]) / values["I"]
        ch = (values["C"] - values["B"]) / values["I"]
        assert lo < th < hi and lo < ch < hi
        assert math.isclose(values["lam"], 1 + ch, rel_tol=1e-15)
    assert {p.name: p.default for p in ghc.PARAMETERS} == ghc.EARTH
    assert math.isclose(ghc.EARTH["nu"], math.sqrt(9.81 / 6.371e6))


# --------------------------------------------------------------------------- item 2: the integral E


def test_E_is_an_integral_symbolically():
    """dE/dt = omega2 . (1.5) + epsilon' (1.6) identically (the paper's route to (2.2)), and E
    is the Jacobi integral of the Lagrangian less the sensor's potential."""
    assert ghc.energy_is_conserved() == [0, 0, 0]


def _integrator(model, P, steps):
    """`steps` fixed steps of the 8th-order Dormand-Prince tableau (DOP853's coefficients)
    on the emitted CasADi mass matrix and forcing, as one CasADi map over the steps."""
    import casadi as ca
    from scipy.integrate._ivp import dop853_coefficients as dc

    cf = model.casadi
    x, p, h = ca.SX.sym("x", 8), ca.SX.sym("p", len(P)), ca.SX.sym("h")
    f = ca.Function("f", [x, p], [ca.vertcat(x[4:], ca.solve(cf.mass_matrix(p, x[:4]), cf.forcing(p, x[:4], x[4:])))])
    K = []
    for i in range(dc.N_STAGES):
        K.append(f(x + h * sum((dc.A[i, j] * K[j] for j in range(i) if dc.A[i, j] != 0), ca.SX.zeros(8)), p))
    step = ca.Function("step", [x, p, h], [x + h * sum(dc.B[i] * K[i] for i in range(dc.N_STAGES))])
    return step.mapaccum("chunk", steps)


def _drift(model, values, y_offset, periods, steps_per_fast_radian):
    P = _P(model, values)
    w, re = _frequencies(model, P)
    assert re < 1e-9 * w[-1]
    eps0 = _eps0(model, P)
    y = np.concatenate([[0, 0, 0, eps0], np.zeros(4)]) + y_offset
    h = 1.0 / (steps_per_fast_radian * w[-1])
    n = 500
    chunk = _integrator(model, P, n)
    E0 = _E(model, P, y)
    worst, t = 0.0, 0.0
    t_end = periods * 2 * np.pi / w[0]
    while t < t_end:
        out = np.array(chunk(y, P, h))
        y, t = out[:, -1], t + n * h
        worst = max(worst, max(abs(_E(model, P, out[:, j]) - E0) for j in range(49, n, 50)))
    return worst / abs(E0), w, t


def test_E_is_conserved_over_1e3_slowest_periods_laboratory(emitted):
    """Relative drift of E <= 1e-10 over 1e3 periods of the slowest mode (0.347 rad/s, 18 s),
    from a state 0.05 rad off the relative equilibrium (3.1)."""
    off = np.array([0.05, -0.03, 0.04, 0.05, 0.01, 0.0, -0.02, 0.01])
    drift, w, t = _drift(emitted, ghc.LAB, off, 1e3, 10.0)
    assert t >= 1e3 * 2 * np.pi / w[0]
    assert w[-1] / w[0] < 3
    assert drift <= 1e-10, drift


def test_E_is_conserved_earth_set(emitted):
    """Earth set: the modes span 1.2e-3 to 220 rad/s (the Schuler-like precessions and the
    nutations), so 1e3 slowest periods are 2e8 nutation periods, out of reach of a test; E is
    checked over 300 nutation periods (0.03 of the slowest period) instead."""
    P = _P(emitted, ghc.EARTH)
    w, _ = _frequencies(emitted, P)
    assert 1e-3 < w[0] < 1.5e-3 and w[-1] > 100
    off = np.array([1e-3, -1e-3, 2e-3, 1e-3, 0, 0, 0, 0])
    drift, _, _ = _drift(emitted, ghc.EARTH, off, 300 * w[0] / w[-1], 10.0)
    assert drift <= 1e-10, drift


# --------------------------------------------------------------------------- item 3: stability


def _at_equilibrium(expr, lam_value=None):
    subs = {q[0]: 0, q[1]: 0, q[2]: 0, q[3]: ghc.epsilon0()}
    e = expr.subs(subs)
    if lam_value is not None:
        e = e.subs(lam, lam_value)
    return sp.simplify(e)


def test_relative_equilibrium_3_1_3_2():
    """Residual 0 at (3.1) with lambda = 1 + chi. For any lambda the beta row is
    eta zeta I (lambda - 1 - chi): for eta != 0 the equilibrium needs lambda = 1 + chi (3.2),
    for eta = 0 any lambda will do."""
    from conftest import derived

    d = derived("gyrohorizoncompass")[1]
    res = d.equilibrium_residual
    assert [_at_equilibrium(r, 1 + chi) for r in res] == [0, 0, 0, 0]
    free = [_at_equilibrium(r) for r in res]
    assert free[0] == 0 and free[2] == 0 and free[3] == 0
    assert sp.simplify(free[1] - eta * zeta * I * (lam - 1 - chi)) == 0
    assert sp.simplify(free[1].subs(eta, 0)) == 0


def test_no_equilibrium_when_I_lambda_zeta_over_2L_is_1_or_more(emitted):
    P = _P(emitted, dict(ghc.LAB, L=0.5 * 1.05 * 0.5))  # I lambda zeta/2L = 1
    eps0, margins, _ = emitted.numpy.relative_equilibrium(P)
    assert margins[0] <= 1e-15 and abs(float(np.ravel(eps0)[0])) < 1e-7
    with np.errstate(invalid="ignore"):
        P = _P(emitted, dict(ghc.LAB, L=0.2))
        eps0, margins, _ = emitted.numpy.relative_equilibrium(P)
    assert margins[0] < 0 and np.isnan(eps0).all()


def test_B1_C1_are_the_hessian_of_V_and_the_print():
    """Derived B1, C1 against (3.5) entry by entry, at lambda = 1 + chi: equal, with b44 = 2J
    (printed 2I: the casings' inertia, J epsilon'^2 in E, gives 2J)."""
    B1, C1 = ghc.hessians()
    PB, PC = ghc.printed_hessians()
    assert (B1 - PB).applyfunc(sp.simplify) == sp.zeros(4, 4)
    assert (C1 - PC).subs(lam, 1 + chi).applyfunc(sp.simplify) == sp.zeros(4, 4)
    assert [(i, j) for i in range(4) for j in range(4) if C1[i, j] != 0] == \
        [(0, 0), (0, 2), (1, 1), (1, 3), (2, 0), (2, 2), (3, 1), (3, 3)]
    # for any lambda, c22 carries (lambda - 1 - chi) zeta^2
    assert sp.simplify(C1[1, 1] - I * ((1 - 3 * chi) * nu**2 + chi * eta**2 + (lam - 1 - chi) * zeta**2)) == 0


def test_emitted_lyapunov_matrices(emitted):
    """The emitted B1, C1 against the printed entries at the laboratory set, and as the
    Hessian of the emitted V by finite differences."""
    P = _P(emitted, ghc.LAB)
    B1, C1 = emitted.numpy.lyapunov(P)
    syms = [p.symbol for p in ghc.PARAMETERS]
    PB, PC = (sp.lambdify(syms, M_, "numpy")(*P) for M_ in ghc.printed_hessians())
    np.testing.assert_allclose(B1, PB, rtol=1e-14, atol=0)
    np.testing.assert_allclose(C1, PC, rtol=1e-12, atol=1e-14)
    eps0 = _eps0(emitted, P)
    y0 = np.array([0, 0, 0, eps0, 0, 0, 0, 0])
    V = lambda y: float(np.ravel(emitted.numpy.first_integral(P, y[:4], y[4:])[1])[0])  # noqa: E731
    assert abs(V(y0)) < 1e-15
    h = 1e-4
    H = np.zeros((8, 8))
    for i in range(8):
        for j in range(8):
            ei, ej = np.eye(8)[i] * h, np.eye(8)[j] * h
            H[i, j] = (V(y0 + ei + ej) - V(y0 + ei - ej) - V(y0 - ei + ej) + V(y0 - ei - ej)) / (4 * h * h)
    np.testing.assert_allclose(H[:4, :4], C1, atol=1e-7)
    np.testing.assert_allclose(H[4:, 4:], B1, atol=1e-7)
    np.testing.assert_allclose(H[:4, 4:], 0, atol=1e-7)


def test_conditions_3_6_are_sylvester():
    """The leading minors of C1 (order alpha, gamma, beta, epsilon) at lambda = 1 + chi factor
    into the printed conditions (3.6): m1 = I (1 + theta) zeta^2, m2/m1 = I [(1 - 3 theta) nu^2
    - zeta^2 - eta^2], m4/m2 = 4 L^2 sin^2(eps0)/lambda [(1 - 3 chi) nu^2 - eta^2] / c22 ..."""
    _, C1 = ghc.hessians()
    C1 = C1.subs(lam, 1 + chi)
    m1, m2, m3, m4 = [sp.simplify(m) for m in ghc.sylvester_minors(C1)]
    assert sp.simplify(m1 - I * (1 + theta) * zeta**2) == 0
    assert sp.simplify(m2 - m1 * I * ((1 - 3 * theta) * nu**2 - zeta**2 - eta**2)) == 0
    assert sp.simplify(m3 - m2 * C1[1, 1]) == 0
    s2 = 1 - (I * (1 + chi) * zeta / (2 * L))**2
    assert sp.simplify(m4 - m2 * 4 * L**2 * s2 / (1 + chi) * ((1 - 3 * chi) * nu**2 - eta**2)) == 0


def test_conditions_3_6_numerically(emitted):
    """On random sets with lambda = 1 + chi: C1 positive definite iff (3.6) holds, and then the
    linearised spectrum is on the imaginary axis."""
    rng = np.random.default_rng(7)
    agree = 0
    for _ in range(300):
        I_ = 1.0
        th, ch = rng.uniform(-1.2, 0.5), rng.uniform(-1.2, 0.5)
        C_ = 3.0
        v = dict(A=C_ - th * I_, B=C_ - ch * I_, C=C_, J=rng.uniform(0.2, 2), L=rng.uniform(0.5, 3), I=I_,
                 nu=1.0, zeta=rng.uniform(0.05, 1.0), eta=rng.uniform(-1.0, 1.0), lam=1 + ch)
        if v["lam"] <= 0 or v["I"] * v["lam"] * v["zeta"] / (2 * v["L"]) >= 1:
            continue
        P = _P(emitted, v)
        _, C1 = emitted.numpy.lyapunov(P)
        margins = np.ravel(emitted.numpy.conditions(P))  # the declared C1 > 0, (3.6), (4.3)
        syl, printed = margins[:4], margins[4:10]
        pd = bool(np.all(np.linalg.eigvalsh(C1) > 0))
        assert pd == bool(np.all(syl > 0)) == bool(np.all(printed > 0))
        if pd:
            assert _frequencies(emitted, P)[1] < 1e-8
        agree += 1
    assert agree > 100


def test_satellite_4_1_to_4_3():
    """zeta = nu, eta = 0: lambda is free in (0, 2L/(I nu)) (the beta row vanishes); C1 is the
    printed one of section 4 with c22 = I (lambda - 4 chi) nu^2, so the middle condition of
    (4.3) reads chi < lambda/4 (printed chi < 1/lambda); at lambda = 1 + chi it is (4.2)."""
    sat = {zeta: nu, eta: 0}
    _, C1 = ghc.hessians()
    assert (C1.subs(sat) - ghc.printed_satellite_C1().subs(sat)).applyfunc(sp.simplify) == sp.zeros(4, 4)
    # existence: cos eps0 = I lambda nu/2L < 1  <=>  lambda < 2L/(I nu)
    assert sp.solve(sp.Eq(I * lam * nu / (2 * L), 1), lam) == [2 * L / (I * nu)]
    # the margins of (4.3) are the diagonal of C1 over I nu^2
    margins = ghc.conditions_43()
    for k, m in zip((0, 1, 2), margins):
        assert sp.simplify(C1.subs(sat)[k, k] / (I * nu**2) - m * (4 if k == 1 else (3 if k == 2 else 1))) == 0
    # the printed "chi < 1/lambda" is not c22 > 0: lambda = 1, chi = 1/2 passes it, c22 < 0
    c22 = C1.subs(sat)[1, 1]
    point = {lam: 1, I: 1, nu: 1, B: 1, C: sp.Rational(3, 2), L: 2}  # chi = 1/2 < 1/lambda = 1
    assert chi.subs(point) < 1 / point[lam] and c22.subs(point) == -1
    # at lambda = 1 + chi: chi < lambda/4 <=> chi < 1/3, lambda + theta - chi = 1 + theta: (4.2)
    x = sp.Symbol("x", real=True)
    assert sp.solve_univariate_inequality((1 + x) / 4 - x > 0, x) == sp.solve_univariate_inequality(x < sp.Rational(1, 3), x)


def test_satellite_numerically(emitted):
    """Satellite, lambda free: with chi < lambda/4 (and the other two) C1 is positive definite;
    the printed chi < 1/lambda admits sets where it is not."""
    base = dict(ghc.LAB, zeta=1.0, eta=0.0, A=1.2, B=1.0, C=1.1)  # theta = -0.1, chi = 0.1
    for lam_, ok in ((0.5, True), (0.35, False)):  # chi < lam/4 holds, fails (1/lam = 2.9 > chi)
        P = _P(emitted, dict(base, lam=lam_))
        _, C1 = emitted.numpy.lyapunov(P)
        m43 = np.ravel(emitted.numpy.conditions(P))[10:13]
        assert bool(np.all(np.linalg.eigvalsh(C1) > 0)) == ok == bool(np.all(m43 > 0))
        assert 0.1 < 1 / lam_  # the printed condition holds in both


def test_precession_corollary():
    """Precession theory (the gyrosphere's own inertia neglected: theta = chi = 0): (3.6)
    leaves nu^2 - zeta^2 - eta^2 > 0 and nu^2 - eta^2 > 0, i.e. sqrt(zeta^2 + eta^2) < nu."""
    c = [m.subs({A: C, B: C}) for m in ghc.conditions_36()]
    assert c[:4] == [1, sp.Rational(1, 3), 1, sp.Rational(1, 3)]
    assert sp.expand(c[4]) == nu**2 - zeta**2 - eta**2 and sp.expand(c[5]) == nu**2 - eta**2
    # the fifth implies the sixth
    assert sp.expand(c[5] - c[4]) == zeta**2
