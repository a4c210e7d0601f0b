"""Gyrocompass on a torsion suspension with elastic rotor bearings (Bashirov, 1983).

Source: shared/seeds/003_d8c34eaefd40a65d.txt; equation numbers are the paper's.
This file says what the system IS: coordinates (1.1), frames (1.2)-(1.6), positions and
velocities (1.7)-(1.8), energies (1.9), Pi, (1.10), the paper's printed operator blocks (2.4)
and its approximate formulas (3.2)-(3.28). Everything that follows from it (equations,
equilibrium, operator, polynomials, emission) is done by the generic machinery.
"""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.model import Parameter

NAME = "torsion_gyrocompass"
TITLE = "Gyrocompass on a torsion suspension with elastic rotor bearings"
SOURCE = "shared/seeds/003_d8c34eaefd40a65d.txt (Bashirov 1983)"

# ----------------------------------------------------------------------------- parameters
# The paper's example (end of section 3), as reconstructed in shared/PAPERS.md: the printed
# frequencies omega_0, omega_p, omega_y and Omega give the stiffnesses and H.
_m, _A = 0.4, 1.2e-4
PARAMETERS = [
    Parameter("m", "kg", _m, "rotor mass"),
    Parameter("M", "kg", 0.6, "casing (sensing element without rotor) mass"),
    Parameter("l", "m", 0.15, "torsion bar length"),
    Parameter("l1", "m", 0.15, "distance O' to casing mass centre O1, downward (< 0: above O')", kind="real"),
    Parameter("l2", "m", 0.25, "distance O' to rotor centre O2, downward (< 0: above O')", kind="real"),
    Parameter("A", "kg m^2", _A, "rotor equatorial moment of inertia"),
    Parameter("C", "kg m^2", 1.8e-4, "rotor polar moment of inertia"),
    Parameter("I1", "kg m^2", 1.05e-2, "casing moment of inertia about x1"),
    Parameter("I2", "kg m^2", 1.07e-2, "casing moment of inertia about x2"),
    Parameter("I3", "kg m^2", 3e-4, "casing moment of inertia about x3"),
    Parameter("K0", "N/m", _m * 450.0**2, "axial bearing stiffness (omega_0 = 450 1/s)"),
    Parameter("Kp", "N/m", _m * 780.0**2, "radial bearing stiffness (omega_p = 780 1/s)"),
    Parameter("Kgamma", "N m/rad", _A * 560.0**2, "angular bearing stiffness (omega_y = 560 1/s)"),
    Parameter("H", "kg m^2/s", 0.452316, "rotor angular momentum H = A Omega (Omega = 3769.3)", kind="nonnegative"),
    Parameter("u", "rad/s", 7.29e-5, "Earth rotation rate", kind="nonnegative"),
    Parameter("phi", "deg", 60.0, "latitude", kind="real", bounds=(-90.0, 90.0)),
    Parameter("g", "m/s^2", 9.81, "gravity along the plumb line", kind="nonnegative"),
    # (1.10): the lever of the imperfection forces on gamma1, gamma2. Two radial bearings of
    # stiffness Kp/2 at +-h give the angular stiffness Kgamma = Kp h^2, so the example's
    # h = sqrt(Kgamma/Kp) = 12.4 mm (docs/forced.md); it enters the forcing B only
    Parameter("h", "m", (_A * 560.0**2 / (_m * 780.0**2)) ** 0.5,
              "bearing size (1.10): lever of the imperfection forces on gamma1, gamma2"),
    # optional bearing damping (Rayleigh function per bearing direction, docs/forced.md); the
    # paper's model is conservative, so 0 by default and every printed number stays as it is
    Parameter("cp", "N s/m", 0.0, "radial bearing damping (x1, x3)", kind="nonnegative"),
    Parameter("c0", "N s/m", 0.0, "axial bearing damping (x2)", kind="nonnegative"),
    Parameter("cgamma", "N m s/rad", 0.0, "angular bearing damping (gamma1, gamma2)", kind="nonnegative"),
]
P = {p.name: p.symbol for p in PARAMETERS}
m, M, l, l1, l2, A, C, I1, I2, I3, K0, Kp, Kgamma, H, u, phi, g, h, cp, c0, cgamma = (P[p.name] for p in PARAMETERS)
DAMPING = (cp, c0, cgamma)
phi_rad = phi * sp.pi / 180
u2, u3 = u * sp.cos(phi_rad), u * sp.sin(phi_rad)  # (1.3)

# Symbols that the model uses before they are eliminated (shown symbolically to leave it).
R1, j, nu = sp.symbols("R1 j nu")

# ----------------------------------------------------------------------------- coordinates
# (1.1): sigma = {x1, x2, x3, gamma1, gamma2, gamma3, alpha, beta, gamma, lambda, mu}
COORDINATES = ["x1", "x2", "x3", "gamma1", "gamma2", "gamma3", "alpha", "beta", "gamma", "lam", "mu"]
COORDINATE_UNITS = {c: ("m" if c.startswith("x") else "rad") for c in COORDINATES}
q = sp.symbols(COORDINATES)
qd = sp.symbols([c + "_d" for c in COORDINATES])
qdd = sp.symbols([c + "_dd" for c in COORDINATES])
x1, x2, x3, gamma1, gamma2, gamma3, alpha, beta, gamma, lam, mu = q
x1d, x2d, x3d, gamma1d, gamma2d, gamma3d, alphad, betad, gammad, lamd, mud = qd

CYCLIC = "gamma3"
# (2.4): q = {x1, x3, gamma, mu, x2, gamma1, gamma2, alpha, beta, lambda}; J = diag(J', J'')
REDUCED = ["x1", "x3", "gamma", "mu", "x2", "gamma1", "gamma2", "alpha", "beta", "lam"]
BLOCKS = [["x1", "x3", "gamma", "mu"], ["x2", "gamma1", "gamma2", "alpha", "beta", "lam"]]
# Reflection in the meridian plane (xi1 -> -xi1) with time reversal maps u and H to
# themselves; these coordinates change sign under it, so a symmetric equilibrium has them
# zero. The derivation checks that their equilibrium equations vanish identically there.
ODD = ["x1", "gamma", "mu", "gamma1", "alpha"]

# Imperfection functions f_s(gamma3) of (1.10)-(1.11): symbolic functions, zero for free
# vibration. For emission they are replaced by input values F_s and their derivatives dF_s.
f1, f2, f3 = (sp.Function(f"f{s}") for s in (1, 2, 3))


def frames():
    """Rotation S (1.2), Earth rate (1.3), casing rate p (1.5), rotor rate r (1.6)."""
    S = mech.rotation([("z", alpha), ("x", beta), ("y", gamma)])  # (1.2)
    u_vec = sp.Matrix([0, u2, u3])  # (1.3)
    p = mech.angular_velocity([("z", alpha), ("x", beta), ("y", gamma)], [alphad, betad, gammad], base=u_vec)  # (1.5)
    # (1.6): rotor axes that do not take part in the spin gamma3 (same sequence as alpha,
    # beta, gamma), with the spin rate along the rotor's 2-axis.
    r = mech.angular_velocity([("z", gamma1), ("x", gamma2)], [gamma1d, gamma2d], base=p)
    r = r + gamma3d * mech.unit("y")
    return S, u_vec, p, r


def positions(S):
    """(1.7): torsion end xi, casing centre xi^(1), rotor centre xi^(2) in O xi1 xi2 xi3."""
    xi = sp.Matrix([-l * sp.sin(mu), l * sp.sin(lam) * sp.cos(mu), -l * sp.cos(lam) * sp.cos(mu)])
    e3 = S[:, 2]
    xi1 = xi - l1 * e3
    xi2 = xi + S * sp.Matrix([x1, x2, x3]) - l2 * e3
    return xi1, xi2


def kinetic_energy(V0):
    """(1.9) with the velocities (1.8): V^(h) = V0 + u x xi^(h) + d xi^(h)/dt."""
    S, u_vec, p, r = frames()
    xi1, xi2 = positions(S)
    V1 = V0 + mech.cross(u_vec, xi1) + mech.time_derivative(xi1, q, qd)
    V2 = V0 + mech.cross(u_vec, xi2) + mech.time_derivative(xi2, q, qd)
    return (mech.kinetic_energy(M, V1, (I1, I2, I3), p)
            + mech.kinetic_energy(m, V2, (A, C, A), r))


def bearing_force_function():
    """(1.10): U with imperfection functions f_s(gamma3)."""
    F1, F2, F3 = f1(gamma3), f2(gamma3), f3(gamma3)
    return (x1 * F1 + x2 * F2 + x3 * F3 + h * gamma1 * F1 - h * gamma2 * F3
            - sp.Rational(1, 2) * (Kp * x1**2 + K0 * x2**2 + Kp * x3**2
                                   + Kgamma * gamma1**2 + Kgamma * gamma2**2))


def bearing_dissipation():
    """Rayleigh function of the bearings, per direction: radial (x1, x3), axial (x2) and
    angular (gamma1, gamma2) rates relative to the casing; Q_k = -dF/dqd_k. Not in the
    paper (its model is conservative); zero at the default damping."""
    return sp.Rational(1, 2) * (cp * (x1d**2 + x3d**2) + c0 * x2d**2 + cgamma * (gamma1d**2 + gamma2d**2))


def lagrangian_with_plumb_line():
    """L = T - Pi + U as the paper states it: origin velocity V0 (1.4) and gravity j along
    the plumb line deflected by nu from xi3 (Pi between (1.9) and (1.10))."""
    S, *_ = frames()
    V0 = sp.Matrix([u * R1 * sp.cos(phi_rad), 0, 0])  # (1.4)
    xi1, xi2 = positions(S)
    eta3 = lambda xi_: xi_[2] * sp.cos(nu) - xi_[1] * sp.sin(nu)  # noqa: E731
    Pi = m * j * eta3(xi2) + M * j * eta3(xi1)
    return kinetic_energy(V0) - Pi + bearing_force_function()


def lagrangian():
    """L = T - Pi + U with V0 = 0 and gravity g along -xi3 (the form the derivation uses).

    `plumb_line_reduction` shows that it differs from `lagrangian_with_plumb_line` only by a
    total time derivative and a constant once j cos nu - u2^2 R1 = g, j sin nu - u2 u3 R1 = 0.
    """
    S, *_ = frames()
    xi1, xi2 = positions(S)
    Pi_g = g * (m * xi2[2] + M * xi1[2])
    return kinetic_energy(sp.zeros(3, 1)) - Pi_g + bearing_force_function()


def plumb_line_reduction():
    """The V0 terms of T and the plumb-line Pi combine into gravity g along xi3 (below (2.4)).

    Uses cos(nu) = (g + u2^2 R1)/j and sin(nu) = u2 u3 R1/j, which are the paper's two
    relations solved for cos and sin. Returns the Lagrange expressions of the difference of
    the two Lagrangians: all identically zero, so R1, j and nu leave the model.
    """
    L_paper = lagrangian_with_plumb_line()
    L_g = lagrangian()
    rel = {sp.cos(nu): (g + u2**2 * R1) / j, sp.sin(nu): u2 * u3 * R1 / j}
    dL = (L_paper - L_g).subs(rel)
    return mech.null_lagrangian_residual(dL, q, qd, qdd)


# ----------------------------------------------------------------------------- section 2
m_c = m + M
l_c = (m * l2 + M * l1) / m_c
G = m_c * l_c * g  # (2.4) abbreviations
I2p = I2 + m * l2**2 + M * l1**2
a = (A + I3) / A
b0 = (m * l2**2 + M * l1**2 + A + I1) / A
Omega = H / A
omega_y2, omega_p2, omega_02 = Kgamma / A, Kp / m, K0 / m


def equilibrium_approx():
    """(2.2): approximate stationary solution, valid for m_c l_c g >> H u, Omega >> g/l, u."""
    beta0 = H * u3 / (G + H * u2)
    return {
        "beta": beta0,
        "gamma2": H * u3 / Kgamma,
        "x2": -m * g * beta0 / K0,
        "x3": -m * g / Kp,
        "lam": (l + l_c) * u2 * u3 / g,
    }


# The paper's approximations behind the printed operator (2.4), applied to the exact
# expansion (text below (2.4) and in section 2):
#  1. linearise at q = 0 instead of q0: products q0_i q'_j are second order, so the
#     equilibrium offsets (all proportional to u3 or to g/K) leave the coefficients;
#  2. terms with u3 are dropped (u3 q' terms are of the size of G beta0 q', g lambda0 q');
#  3. terms of second order in the Earth rate (u^2, centrifugal) are dropped;
#  4. in the terms linear in u, A u and I_i u are neglected against H: the moments of
#     inertia A, I1, I2, I3 are set to zero in the coefficient of u (H, m u l are kept).
_u2s, _u3s = sp.symbols("u2 u3")


def paper_approximation(expr):
    """Apply approximations 2-4 above to one entry of M, D or K taken at q = 0 (the paper's
    model has no bearing damping)."""
    e = sp.expand(expr.subs({u2: _u2s, u3: _u3s}).subs({c: 0 for c in DAMPING}))
    e = e.subs(_u3s, 0)
    e0 = e.subs(_u2s, 0)
    e1 = sp.diff(e, _u2s).subs(_u2s, 0).subs({A: 0, I1: 0, I2: 0, I3: 0})
    return sp.expand(e0 + e1 * u2)


# Rows of the print are divided by these factors (translations by m, the rotor and casing
# angles gamma1, gamma2, alpha, beta by A; gamma, mu, lambda as they are).
PRINT_ROW_SCALE = {"x1": m, "x3": m, "gamma": 1, "mu": 1, "x2": m,
                   "gamma1": A, "gamma2": A, "alpha": A, "beta": A, "lam": 1}


def printed_operator(p):
    """The blocks J', J'' exactly as printed in (2.4), rows as in PRINT_ROW_SCALE.

    Returns (J', J'') as SymPy matrices in the operator p. The three entries that differ
    from the derivation are listed in PRINT_CORRECTIONS and in docs/paper_operator.md.
    """
    J59 = l2 * p**2 + g
    J34 = m_c * l_c * l * p**2
    J44 = m_c * (l**2 * p**2 + l * g)
    J66 = p**2 + omega_y2 + Omega * u2
    J99 = b0 * p**2 + Omega * u2 + G / A
    Jp = sp.Matrix([
        [p**2 + omega_p2, 2 * u2 * p, -J59, -l * p**2],
        [-2 * u2 * p, p**2 + omega_p2, 2 * l2 * u2 * p, 2 * l * u2 * p],
        [-m * J59, -m * u2 * l2 * p, I2p * p**2 + G, J34],
        [-m * l * p**2, -m * u2 * l * p, J34, J44],
    ])
    Jpp = sp.Matrix([
        [p**2 + omega_02, 0, 0, 0, J59, l * p**2],
        [0, J66, Omega * p, p**2 + Omega * u2, Omega * p, 0],
        [0, -Omega * p, J66, -Omega * p, p**2 + Omega * u2, 0],
        [0, p**2 + Omega * u2, Omega * p, a * p**2 + Omega * u2, Omega * p, 0],
        [m * J59 / A, -Omega * p, p**2 + Omega * u2, -Omega * p, J99, J34],
        [m * l * p**2, 0, 0, 0, J34, J44],
    ])
    return Jp, Jpp


def print_corrections(p):
    """Entries where the print and the derivation differ: (block, row, col) 1-based ->
    (printed, derived, reason). The derived entry follows from the Lagrangian; the
    gyroscopic matrix D of a Lagrangian system is skew-symmetric, which the print breaks."""
    J34 = m_c * l_c * l * p**2
    skew = ("gyroscopic (Coriolis) coupling must be skew-symmetric: J'[2,{c}] m = {v} "
            "requires J'[{r},2] = -{v}; the print lost the factor 2")
    return {
        ("J'", 3, 2): (-m * u2 * l2 * p, -2 * m * u2 * l2 * p, skew.format(c=3, r=3, v="2 m l2 u2 p")),
        ("J'", 4, 2): (-m * u2 * l * p, -2 * m * u2 * l * p, skew.format(c=4, r=4, v="2 m l u2 p")),
        ("J''", 5, 6): (J34, J34 / A, "row beta is divided by A like its other entries (m J59/A, "
                        "J99 = b0 p^2 + ...); the mass matrix is symmetric, so it is J34/A "
                        "against J''[6,5] = J34"),
    }


# ----------------------------------------------------------------------------- section 3


def L_poly(z, b):
    """(3.8): L(z, b), cubic in z = omega^2; its roots are frequencies of the free gyroscope
    with elastic bearings, with the casing inertia parameter b."""
    wy2, W2 = omega_y2, Omega**2
    return (z**3 * (b - 1) * (a - 1)
            - z**2 * ((2 * a * b - a - b) * wy2 + W2 * (a - 1) * (b - 1))
            + z * (W2 * wy2 * (a + b - 2) + wy2**2 * a * b)
            - wy2**2 * W2)


# the rotor's radial sag in its bearing: the exact equilibrium at u = 0 is the print's
# linearisation point with l2 -> l2 + m g/K_p (docs/frequencies.md); the `_eq` formulas
SAG = {l2: l2 + m * g / Kp}


def delta1_groups():
    """(c2, d2, e1) of Delta1 (3.1) and (3.4)-(3.6): c2 = I2 + m_*(l1 - l2)^2,
    d2 = m_*(l1 - l2) l + M l1^2 + M l1 l + I2, e1 = m_c l_c l + I2'."""
    m_s = m * M / (m + M)
    return (I2 + m_s * (l1 - l2)**2, m_s * (l1 - l2) * l + M * l1**2 + M * l1 * l + I2,
            m_c * l_c * l + I2p)


def Delta1(x):
    """(3.1) Delta1(x), x = omega^2: det J'(p) at u = 0, p^2 = -x, is -l^2 m^2 m_c
    (omega_p^2 - x) Delta1(x); the last term read g m l (docs/frequencies.md)."""
    c2, d2, e1 = delta1_groups()
    return (x**3 * I2 * M / m_c - x**2 * (omega_p2 * c2 + g / l * d2)
            + x * g / l * (omega_p2 * e1 + g * (M * l1 - m * l - m * l2))
            - (g / l)**2 * (omega_p2 * m_c * l_c * l - g * m * l))


def omega2_series(order: int):
    """(x0, [x1, ..., x_order]): the root x(g) = x0 + x1 g + x2 g^2 + ... of Delta1 that
    tends to omega_p^2 c2 m_c/(I2 M) as g -> 0, c2 = I2 + m_*(l1 - l2)^2; (3.4) is its
    first two terms."""
    x = sp.Symbol("x")
    x0 = omega_p2 * delta1_groups()[0] * m_c / (I2 * M)
    return x0, mech.root_series(Delta1(x), x, x0, g, order)


def omega6_series():
    """The first three coefficients of the root z(g) = z1 g + z2 g^2 + z3 g^3 + ... of the
    J'' block's characteristic polynomial at u = 0 (printed (2.4), J''[5,6] = J34/A), the
    root that vanishes with g: the pendulum mode (3.9). det J''(p) carries the factor p^2
    of the neutral azimuth at u = 0, divided out first."""
    p, z = sp.symbols("p z")
    _, Jpp = printed_operator(p)
    Jpp = Jpp.subs(u2, 0)
    Jpp[4, 5] = Jpp[4, 5] / A  # print_corrections: J''[5,6] = J34/A
    c = mech.charpoly_in_p2(Jpp, p, z)
    while sp.expand(c[0]) == 0:
        c = c[1:]
    return [_grouped(zk) for zk in mech.root_series(sum(ck * z**k for k, ck in enumerate(c)), z, 0, g, 3)]


def _grouped(expr):
    """A rational expression of the parameters rewritten in the paper's groups (Omega,
    omega_y^2, omega_0^2, m_c, l_c, a) and collected by powers of Omega, omega_y^2 and
    omega_0^2: the same value with a quarter of the operations (for emission)."""
    W, wy2, w02, mc, lc, a_ = sp.symbols("W_ wy2_ w02_ mc_ lc_ a_", positive=True)
    e = sp.cancel(expr.subs({H: W * A, Kgamma: wy2 * A, K0: w02 * m}))  # canonical p/q: the next cancel's
    e = sp.factor(sp.cancel(e.subs({M: mc - m}).subs({l1: (mc * lc - m * l2) / (mc - m)})))  # input form is moot
    num, den = sp.fraction(e)
    num = sp.collect(sp.expand(num.subs(I3, (a_ - 1) * A)), [W, wy2, w02], func=sp.factor)
    back = {W: H / A, wy2: Kgamma / A, w02: K0 / m, mc: m_c, lc: l_c, a_: (A + I3) / A}
    return (num / den).xreplace(back)


def section3_formulas():
    """The paper's approximate frequencies (3.2)-(3.28) and their abbreviations.

    Returns (name -> expression, name -> the equation and the OCR reading taken). Names
    ending in `_printed` are formulas as printed where the derivation shows them wrong;
    the name without the suffix is the corrected formula (evidence: docs/frequencies.md).
    Names ending in `_eq` take the operator at the exact equilibrium instead of q = 0.
    """
    F, doc = {}, {}

    def put(name, expr, note):
        F[name], doc[name] = expr, note
        return expr

    m_s = put("m_star", m * M / (m + M), "(3.1): reduced mass m_* = m M/(m + M)")
    put("m_c", m_c, "(2.4): m_c = m + M")
    put("l_c", l_c, "(2.2): l_c = (m l2 + M l1)/m_c")
    put("G", G, "(2.4): G = m_c l_c g")
    put("I2p", I2p, "(2.4): I2' = I2 + m l2^2 + M l1^2")
    put("a", a, "(2.4): a = (A + I3)/A")
    put("b0", b0, "(2.4): b0 = (m l2^2 + M l1^2 + A + I1)/A")
    wy = put("omega_y", sp.sqrt(omega_y2), "(2.4): omega_y^2 = K_gamma/A (printed omega_n in the example)")
    wp = put("omega_p", sp.sqrt(omega_p2), "(2.4): omega_p^2 = K_p/m")
    w0 = put("omega_0", sp.sqrt(omega_02), "(2.4): omega_0^2 = K_0/m")
    W = put("Omega", Omega, "(2.4): Omega = H/A")
    put("u2", u2, "(1.3): u2 = u cos phi")
    b1 = put("b1", 1 + (I1 + m_s * (l1 - l2)**2) / A, "(3.8): b' = 1 + [I1 + m_*(l1 - l2)^2]/A")
    b2 = put("b2", 1 + I1 / A, "(3.8): b'' = 1 + I1/A")
    put("delta_b", m_s * (l1 - l2)**2 / A, "(3.8): delta_b = b' - b'' = m_*(l1 - l2)^2/A")
    put("k", W / wy, "(3.16): k = Omega/omega_y")
    put("mu1", omega_y2 / W**2, "(3.26): mu1 = k^-2 = omega_y^2/Omega^2")
    put("eps1", u * sp.sqrt(l / g), "section 3: eps1 = u sqrt(L*/g) with L* = l")
    put("eps2", g / (l * omega_p2), "(3.3): eps2 = g/(l omega_p^2)")
    put("eps3", g / (l * omega_y2), "before (3.8): eps3 = g/(l omega_y^2)")
    put("kappa", (b1 - 1) * K0 / ((b2 - 1) * omega_y2 * m_s), "(3.15): kappa")
    w0p = put("omega_0p", sp.sqrt(K0 * (b1 - 1) / (m_s * (b2 - 1))), "(3.26): omega_0'^2 = K0 (b'-1)/(m_* (b''-1))")

    # omega1, (3.2); "K_v" read as K_gamma
    put("omega1_printed", sp.sqrt(u2**2 + Kgamma * u2 * G / ((Kgamma + G) * H)
                                  * (1 + Kp * m**2 * g**2 / (K0 * (Kp * G - m**2 * g**2)))),
        "(3.2) as printed (K_v read K_gamma): drops the azimuth inertia (A + I3) S/H^2 and "
        "has the axial-bearing bracket wrong")
    Gk = G - m**2 * g**2 / K0
    S = Kgamma * Gk / (Kgamma + Gk)
    put("omega1", sp.sqrt(u2**2 + u2 * S / (H + (A + I3) * S / H)),
        "(3.2) corrected from the slowest root of det J'': G' = G - m^2 g^2/K0 (axial "
        "bearing), S = K_gamma G'/(K_gamma + G') (rotor spring in series), H -> H + (A+I3) S/H")
    Ge = G + m**2 * g**2 / Kp - m**2 * g**2 / K0
    Se = Kgamma * Ge / (Kgamma + Ge)
    put("omega1_eq", sp.sqrt(u2**2 + u2 * Se / (H + (A + I3) * Se / H)),
        "(3.2) corrected, at the exact equilibrium: the rotor's radial sag m g/K_p adds "
        "m^2 g^2/K_p to G")

    # omega2..omega4, (3.3)-(3.6)
    c2, d2, e1 = delta1_groups()
    lead = Kp / m_s * (1 + m_s * (l1 - l2)**2 / I2)
    put("omega2_printed", sp.sqrt(lead + g / l * (d2 * m_c / (I2 * M) - m_c * l_c * l / c2)),
        "(3.4) as printed: second term -m_c l_c l/[I2 + m_*(l1-l2)^2]; error O(eps2)")
    put("omega2", sp.sqrt(lead + g / l * (d2 * m_c / (I2 * M) - e1 / c2)),
        "(3.4) corrected by first-order perturbation of (3.3): -(m_c l_c l + I2')/[I2 + "
        "m_*(l1-l2)^2]; error O(eps2^2)")
    disc = (I2p - m_c * l_c * l)**2 + 4 * m_c**2 * l_c**3 * l
    th1 = put("theta1", (e1 - sp.sqrt(disc)) / (2 * c2), "(3.6): smaller root theta_1")
    th2 = put("theta2", (e1 + sp.sqrt(disc)) / (2 * c2), "(3.6): larger root theta_2")

    def Q(t):  # (3.6): Q(theta) as printed
        return (I2 * M * t**3 / m_c - (I2 + M * l1 * l + M * l1**2 + m_s * (l1 - l2) * l) * t**2
                + (M * l1 * l - m * l**2 - m * l2 * l) * t + m * l**2)

    put("omega3", sp.sqrt(g * th1 / l - (g / (l * wp))**2 * Q(th1) / sp.sqrt(disc)),
        "(3.5) as printed, (g/l omega_p)^2 read g^2/(l^2 omega_p^2); error O(eps2^2)")
    put("omega4", sp.sqrt(g * th2 / l + (g / (l * wp))**2 * Q(th2) / sp.sqrt(disc)),
        "(3.6) as printed; error O(eps2^2)")
    # (3.4) is the series of Delta1's root near omega_p^2 c2 m_c/(I2 M) in g to first order;
    # the next term, derived from Delta1 (3.1) itself, estimates what it omits
    x0, (_, x2) = omega2_series(2)
    put("omega2_next", sp.Abs(x2) * g**2 / x0,
        "(3.4): size of the omitted term g^2 x2 of Delta1's root series, relative to omega^2 "
        "(twice the relative error it causes in omega)")
    put("omega2_next_eq", F["omega2_next"].xreplace(SAG), "(3.4): omega2_next at the exact equilibrium")
    for name in ("omega2", "omega3", "omega4"):
        put(name + "_eq", F[name].xreplace(SAG),
            f"{doc[name].split(' ')[0]} at the exact equilibrium: l2 -> l2 + m g/K_p (the "
            "rotor's radial sag, an O(eps2) effect the linearisation at q = 0 drops)")

    put("omega5", wp, "(3.7): omega5 = omega_p")
    put("omega6", sp.sqrt(g / l * (1 - g / l * (m_c * l_c**2 / A * (a / W**2 + 1 / wy**2)
                                                 + m / (m_c * w0**2)))),
        "(3.9), left side printed omega_0^2 read omega_6^2; error O(delta6^2), delta6 "
        "the relative size of its correction term (0.068 at the example)")
    # (3.9) is the series in g of the root of det J''(p) at u = 0 (z = p^2 = -omega^2) that
    # vanishes with g: z = -g/l + z2 g^2 + z3 g^3 + ...; its first omitted term estimates it
    z1, _, z3 = omega6_series()
    put("omega6_next", sp.Abs(z3) * g**2 / sp.Abs(z1),
        "(3.9): size of the omitted term g^3 z3 of the J'' root series, relative to omega^2 "
        "(twice the relative error it causes in omega)")
    put("omega6_eq", F["omega6"].xreplace(SAG), "(3.9) at the exact equilibrium: l2 -> l2 + m g/K_p")
    put("omega6_next_eq", F["omega6_next"].xreplace(SAG), "(3.9): omega6_next at the exact equilibrium")

    def s8(b):  # (3.14)
        return omega_y2 * W**2 / (a * b * omega_y2 + W**2 * (b - 1))

    def s9(b):  # (3.14)
        return ((W**2 * (b - 1)**3 + b**2 * (b - a) * omega_y2) * omega_y2
                / ((W**2 * (b - 1)**2 * (a - 1) + b * (b - a) * omega_y2) * (b - 1)))

    def s10(b):  # (3.14): the sum of the roots of L minus the other two
        return (a / (a - 1) + b / (b - 1)) * omega_y2 - (s8(b) + s9(b)) + W**2

    for tag, b, label in (("b1", b1, "b'"), ("b2", b2, "b''")):
        for k_, fn in ((8, s8), (9, s9), (10, s10)):
            put(f"omega_star{k_}_{tag}", sp.sqrt(fn(b)), f"(3.14): omega_*{k_}({label}), a root of L(z, b), b > a")
    put("omega_star7", sp.sqrt(K0 / m_s), "(3.11): axial frequency sqrt(K0/m_*), exact when delta_b = 0")

    def pair(sb2, sb1, sign):
        return sp.sqrt((w0p**2 + sb2 + sign * sp.sqrt((w0p**2 - sb2)**2 + 4 * w0p**2 * (sb2 - sb1))) / 2)

    put("omega7", pair(s8(b2), s8(b1), +1), "(3.26), + branch; OCR omega_*s read omega_*8")
    put("omega8", w0p * sp.sqrt(s8(b1)) / F["omega7"],
        "(3.26), - branch (first nutation), as omega_0' omega_*8(b')/omega7 (the product "
        "of the two roots): the same value without cancellation")
    put("omega9", sp.sqrt(s9(b1)), "(3.26): omega9 = omega_*9(b')")
    put("omega10", sp.sqrt(s10(b1)), "(3.26): omega10 = omega_*10(b')")
    put("omega7_smallk", sp.sqrt(s8(b1)), "(3.28), small k: omega7 = omega_*8(b')")
    put("omega8_smallk", sp.sqrt(s10(b1)), "(3.28), small k: omega8 = omega_*10(b')")
    put("omega9_smallk", pair(s9(b2), s9(b1), +1), "(3.28), small k: + branch with omega_*9")
    put("omega10_smallk", w0p * sp.sqrt(s9(b1)) / F["omega9_smallk"],
        "(3.28), small k: - branch with omega_*9, through the product of the roots")
    put("omega7_K0inf", sp.sqrt(w0p**2 + s8(b2) - s8(b1)), "after (3.28): K0 -> oo limit of omega7")
    put("omega_rigid", W / sp.sqrt(a * b1),
        "after (3.28): lim omega_*8(b') as K_gamma -> oo, Omega/sqrt(a b') (printed "
        "Omega/sqrt(I1 b^2), read as such)")
    # small parameters of the estimates of the ladder's `formulas` rung (docs/methods.md)
    put("kappa6", G * l_c / (l * Kgamma),
        "kappa6 = G l_c/(l K_gamma): the pendulum's load on the rotor's angular spring, the "
        "first-order gravity shift of the nutation roots that the g = 0 quartic (3.10) omits")
    put("delta6", g / l * (m_c * l_c**2 / A * (a / W**2 + 1 / wy**2) + m / (m_c * w0**2)),
        "delta6: the relative size of the correction term of (3.9)")
    # the quartic (3.10) K0 L(z, b') - z m_* L(z, b'') = 0, coefficients lowest first
    zs = sp.Symbol("z")
    quartic = sp.Poly(sp.expand(K0 * L_poly(zs, b1) - zs * m_s * L_poly(zs, b2)), zs)
    for k_, c in enumerate(reversed(quartic.all_coeffs())):
        put(f"quartic_c{k_}", c, f"(3.10): coefficient of z^{k_} in K0 L(z,b') - z m_* L(z,b'')")
    # the a-priori bounds of the levels on the paper's operator (levels(), docs/hierarchy.md)
    beta0, gamma20 = H * u3 / (G + H * u2), H * u3 / Kgamma
    paper = put("bound_paper", F["eps2"] + m * g / (Kp * sp.Abs(l2)) + sp.Abs(beta0) + sp.Abs(gamma20)
                + u * (A + I1 + I2 + I3) / H,
                "the bound of the paper operator (2.4) against the exact one: eps2 + m g/(K_p |l2|) (the "
                "sag) + |beta0| + |gamma2| of (2.2) + (A + I1 + I2 + I3) u/H (approximation 4: every A u "
                "and I_i u against H, the casing's as well as the rotor's A u/H = u/Omega)")
    put("bound_blocks", paper + 2 * (H * u2 / Kgamma + H * u2 / G) + 2 * F["eps1"],
        "the bound of the decoupled blocks (u = 0 in (2.4)): bound_paper + 2 (H u2/K_gamma + H u2/G) + 2 eps1")
    return F, doc


# ----------------------------------------------------------------------------- the model


def mode_formulas(F):
    """The ten modes by formulas, each with the relative error estimate of what it neglects
    (docs/methods.md, "Error estimates of the formulas").

    Derived: for (3.4) and (3.9), truncated series in g of a root of Delta1 and of det J''
    at u = 0, the omitted next term (omega2_next, omega6_next; for (3.9) plus delta6^2, the
    size of its own correction squared). Small parameters to their order: eps2 for
    (3.5)-(3.7) (their u-coupling is not of second order), mu1 + kappa6 for (3.26) (first
    order in mu1, plus the gravity shift the quartic omits), k^2 + kappa6 for the small-k
    variant (3.28), omega1/omega_y for (3.2) corrected (the next-order coupling with the
    rotor's angular spring, plus the rounding of u2 near the pole). Those constants are
    calibrated, not derived: 1, except 3 for (3.28) (with 1, a 3000-set sweep of spin, K0,
    Kp, K_gamma 0.1x..10x and latitude 0..89 deg reached ratio 2.8) and 2 for (3.2) (with
    1, the spin / 1000 edge errs by 1.4e-5 against 1.1e-5). The two nutation families are
    candidates of the same four modes: per set, the one whose estimate is smaller applies
    (3.26 when k is large, 3.28 when it is small)."""
    eps2, mu1, k, kappa6 = F["eps2"], F["mu1"], F["k"], F["kappa6"]
    big, small = mu1 + kappa6, 3 * (k**2 + kappa6)
    return [
        # plus the rounding of u2 = u cos(phi) near the pole, where omega1 -> 0
        ("omega1", [("omega1_eq", 2 * F["omega1_eq"] / F["omega_y"] + sp.Float(2.0**-52) * u / F["u2"])]),
        ("omega2", [("omega2_eq", F["omega2_next_eq"])]),
        ("omega3", [("omega3_eq", eps2)]),
        ("omega4", [("omega4_eq", eps2)]),
        ("omega5", [("omega5", eps2)]),
        # the next term of the series, and delta6^2 for a tail that is not small beside it
        ("omega6", [("omega6_eq", F["omega6_next_eq"] + F["delta6"].xreplace(SAG)**2)]),
        ("nutation a", [("omega7", big), ("omega7_smallk", small)]),
        ("nutation b", [("omega8", big), ("omega8_smallk", small)]),
        ("nutation c", [("omega9", big), ("omega9_smallk", small)]),
        ("nutation d", [("omega10", big), ("omega10_smallk", small)]),
    ]


def levels(F):
    """The hierarchy of the torsion gyrocompass (docs/hierarchy.md): what each level
    neglects, its a-priori relative bound per answered quantity, its edges of validity.

    The paper operator (2.4) neglects terms of relative size eps2 = g/(l omega_p^2) (the
    linearisation at q = 0, whose largest offset is the rotor's radial sag m g/K_p against
    l2), beta0 and gamma2 of (2.2) (offsets proportional to u3), and u/Omega (A u, I_i u
    against H); its bound is their sum (measured: at most 0.21 of it over the spreads of
    bench/levels.py). The decoupled blocks (eps1 = 0: u = 0 in (2.4), (3.1)) neglect besides
    the Earth-rate coupling of the blocks: 2 u2/omega for the Coriolis terms (largest at
    the slowest coupled mode, eps1 = u sqrt(l/g)), H u2/K_gamma and H u2/G against the
    stiffnesses; twice their sum (measured: at most 0.43 of it); omega1 (zero at u = 0) is
    not answered. The quartic level takes the nutation modes from the g = 0 quartic (3.10)
    (J'' at u = g = 0), each moved by its first-order gravity shift dz = -g F_g/F_z (F the J''
    polynomial, F_g derived from d/dg of its coefficients), and the other modes from their
    formulas: per mode its estimate, a formula's, or for a nutation root decoupled's bound
    plus the first-order shift itself as the size of the second-order remainder (measured:
    at most 0.34 of the whole over the spreads). The formulas' bound is their derived
    estimate (mode_formulas)."""
    from derive.model import Bound, Level

    # a certificate counts the exact operator as evaluated in double precision; the rounding of
    # its inputs (u cos(phi), linear_exact's a-priori part) separates that from the exact model
    certified = {"inputs": "linear_exact"}

    paper, blocks = F["bound_paper"], F["bound_blocks"]
    blocks_edges = {"Earth rate below the slowest pendulum frequency (eps1 < 1/4)": sp.Rational(1, 4) - F["eps1"],
                    "l2 != 0 (the sag's bound)": sp.Abs(l2)}
    n = len(REDUCED)
    exact = "nothing of the linearised motion about the exact equilibrium (amplitudes, nonlinearity)"
    # the motion question answers the reduced coordinates (not the cyclic gamma3), each error
    # against the perturbation's largest excursion
    motion = {"quantities": list(REDUCED), "scale": "excursion"}
    return [
        Level("formulas", "everything (3.2)-(3.28) drop: each formula's small parameter to its order",
              {"kind": "spectrum", "method": "formulas", "certify": certified}, {"frequencies": Bound(estimate=True)},
              reference="linear_exact",
              doc="the paper's approximate formulas, corrected, with their derived estimates"),
        # costs measured by bench/levels.py (one core, 20,000 sets): since the roots are proven
        # Aberth roots in C, the paper operator's blocks cost less than the formulas with the
        # quartic's roots (2.7-3.2 us against 4.1-4.8 us a set), so quartic comes after them
        Level("quartic", "gravity in the nutation modes (the g = 0 quartic (3.10) of J'' at u = 0), and what "
                         "decoupled neglects; the other modes by their formulas",
              {"kind": "formulas", "roots": {"function": "paper_charpoly", "block": 2, "set": {"u": 0.0, "g": 0.0},
                                             "modes": ["nutation a", "nutation b", "nutation c", "nutation d"],
                                             "shift": {"parameter": "g", "function": "paper_charpoly_dg", "correct": True},
                                             "apriori": "bound_blocks"}, "certify": certified},
              {"frequencies": Bound(estimate=True)},
              valid=blocks_edges,
              cost=4.4e-6, reference="linear_exact",
              doc="the roots of the quartic (3.10) for the four nutation modes, with twice the first-order "
                  "gravity shift of each as its estimate; the other six modes by (3.2)-(3.9)"),
        Level("decoupled", "the Earth-rate coupling of the two blocks (eps1 = 0, (3.1)), and what (2.4) drops",
              {"kind": "charpoly", "function": "paper_charpoly", "set": {"u": 0.0}, "certify": certified},
              {"frequencies": [None] + [Bound(blocks, estimate=True)] * (n - 1)},
              valid=blocks_edges,
              cost=2.9e-6, reference="linear_exact",
              doc="the blocks J', J'' of (2.4) at u = 0: roots of their characteristic polynomials"),
        Level("linear_paper", "linearisation at q = 0 (offsets of (2.2)), u3 terms, u^2 terms, A u and I_i u against H",
              {"kind": "charpoly", "function": "paper_charpoly", "certify": certified},
              {"frequencies": Bound(paper, estimate=True)},
              valid={"l2 != 0 (the sag's bound)": sp.Abs(l2)},
              cost=3.0e-6, reference="linear_exact",
              doc="the paper's printed operator (2.4), corrected: roots of its blocks' characteristic polynomials"),
        Level("linear", "the full equations' terms of second and higher order in the amplitudes",
              # costs: medians over the bench's two ladders of amplitudes (bench/forced_nonlinear.py,
              # first_step_seconds and harmonic_balance.seconds in bench/results/forced_linear_limit.json)
              {"kind": "harmonic", "module": "gyro.systems.torsion_gyrocompass"},
              {"forced": Bound(estimate=True)}, cost=1.5e-2, reference="nonlinear",
              doc="the linear response J(i w) X = B u to one imperfection harmonic, its error estimated by "
                  "harmonic balance's first Newton step (docs/forced.md)"),
        Level("nonlinear", "harmonics of the forcing above the 15th in the periodic response",
              {"kind": "harmonic_balance", "module": "gyro.systems.torsion_gyrocompass"},
              {"forced": Bound(estimate=True)}, cost=4.2e-2,
              doc="the periodic response of the full 11-coordinate equations by harmonic balance, checked "
                  "against the shooting (docs/forced.md)"),
        # the free motion about the equilibrium (gyro.systems.torsion_gyrocompass); costs: median s per set
        # over a horizon of 0.05 s (python -m bench.levels --torsion-motion)
        Level("linear_motion", "the full equations' terms of second and higher order in the perturbation",
              {"kind": "trajectory", "module": "gyro.systems.torsion_gyrocompass", "method": "linear", **motion},
              {"motion": Bound(estimate=True)}, cost=0.4, reference="nonlinear_motion",
              doc="the exact operator's motion M x'' + D x' + K x = 0 by the exponential of its first-order "
                  "matrix, its error estimated by twice the correction of the full equations (the linear system "
                  "driven by their remainder, two Picard steps)"),
        Level("nonlinear_motion", "nothing of the 11-coordinate equations (the integrator's truncation: two "
              "tolerances compared)",
              {"kind": "trajectory", "module": "gyro.systems.torsion_gyrocompass", "method": "DOP853", "rtol": 1e-9, **motion},
              {"motion": Bound(estimate=True)}, cost=3.7,
              doc="the full 11-coordinate equations integrated (DOP853 at rtol 1e-9 and 1e-11, SciPy)"),
        # the double-precision methods take u2 = u cos(phi) rounded: cos(x) at x = phi pi/180 turns
        # the rounding of x into a relative eps |x tan x| of u2 (1e-13 at 89.9 deg), which their
        # estimates do not see where the spectrum is not wide (default: 1.5e-14 against an
        # estimate of 1.26e-14 at H/20, 89.9 deg); omega1^2 is proportional to u2, and a
        # frequency moves at most by the relative change of its stiffness
        Level("linear_exact", exact,
              {"kind": "spectrum", "methods": ["polyroots", "companion", "default", "reference"], "default": "default",
               "exact_inputs": ["reference"]},
              {"frequencies": Bound(sp.Float(2.0**-52) * (sp.Abs(phi_rad * sp.tan(phi_rad)) + 1), estimate=True),
               "stability": Bound(estimate=True)},
              reference="linear_exact:reference",
              doc="the exact operator about the exact equilibrium, by a method of the ladder (docs/methods.md)"),
    ]


def build():
    """The model as data for the generic pipeline."""
    from derive.model import Model, Variant

    given = [f1(gamma3), f2(gamma3), f3(gamma3)]
    formulas, docs = section3_formulas()
    return Model(
        name=NAME, title=TITLE, source=SOURCE, module=__name__,
        parameters=PARAMETERS, coordinates=COORDINATES, coordinate_units=COORDINATE_UNITS, q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=lagrangian(),
        given_functions=given,
        given_values=list(sp.symbols("F1 F2 F3")),
        given_derivatives=list(sp.symbols("dF1 dF2 dF3")),
        dissipation=bearing_dissipation(),
        cyclic={CYCLIC: H},
        # (2.3)-(2.4): the spin rate omega_c = H/C; the spin angle gamma3, whose functions
        # f_s(gamma3) (1.10) are the harmonic inputs `gyro forced` drives
        spin={"parameter": "H", "rate": H / C, "angle": CYCLIC, "harmonics": ("bearing imperfections", "N")},
        reduced=REDUCED,
        symmetric_zero=ODD,
        equilibrium_approx=equilibrium_approx(),
        identities={"plumb line: V0 and Pi reduce to gravity g along xi3 (below (2.4))": plumb_line_reduction},
        variants={"paper": Variant(
            approximate=paper_approximation, row_scale=PRINT_ROW_SCALE,
            printed=printed_operator, corrections=print_corrections,
            doc="the paper's printed operator (2.4): linearised at q = 0, u3 dropped, u^2 "
                "dropped, A u and I_i u neglected against H",
            perturbations=("g",))},
        formulas=formulas, formula_docs=docs, mode_formulas=mode_formulas(formulas),
        levels=levels(formulas),
    )
