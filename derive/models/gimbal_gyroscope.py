"""Heavy gyroscope in a gimbal with a vertical outer axis (Avdonin, 1969).

Source: shared/seeds/000_67a37024195e6e42.txt; equation numbers are the paper's.
Euler angles psi (precession of the outer ring about the vertical xi3), theta (nutation:
the casing's turn about its axis eta1 in the outer ring), phi (the rotor's spin about its
symmetry axis eta3). Kinetic energy and force function as printed in section 1; the
generic pipeline derives (1.1), reduces the two cyclic coordinates psi and phi with their
momenta L and H, and emits the equations.

The paper has no numerical example: the defaults below are an illustrative
laboratory-sized gyroscope, not the paper's.
"""
from __future__ import annotations

import sympy as sp

from derive import mechanics as mech
from derive.model import Parameter

NAME = "gimbal_gyroscope"
TITLE = "Heavy gyroscope in a gimbal with a vertical outer axis"
SOURCE = "shared/seeds/000_67a37024195e6e42.txt (Avdonin 1969)"

PARAMETERS = [
    Parameter("A0", "kg m^2", 0.02, "A0 = C3 + B2 + A1: inertia about the vertical (illustrative)"),
    Parameter("B0", "kg m^2", 0.015, "B0 = A1 + B1: inertia about the casing axis eta1 (illustrative)"),
    Parameter("C0", "kg m^2", 0.0, "C0 = B2 + A1 - B3 (the closed form needs C0 = 0)", kind="real"),
    Parameter("A3", "kg m^2", 0.01, "rotor polar moment of inertia (illustrative)"),
    Parameter("P1", "N", 5.0, "weight of the casing (illustrative)", kind="nonnegative"),
    Parameter("eta20", "m", 0.002, "casing mass centre along eta2 (illustrative)", kind="real"),
    Parameter("eta30", "m", 0.01, "casing mass centre along eta3 (illustrative)", kind="real"),
    Parameter("P", "N", 10.0, "weight of the rotor (illustrative)", kind="nonnegative"),
    Parameter("l", "m", 0.02, "rotor mass centre along the symmetry axis eta3 (illustrative)", kind="real"),
]
Pm = {p.name: p.symbol for p in PARAMETERS}
A0, B0, C0, A3, P1, eta20, eta30, P, l = (Pm[p.name] for p in PARAMETERS)
G = P1 * eta30 + P * l  # (1.1)

COORDINATES = ["psi", "theta", "phi"]
COORDINATE_UNITS = {c: "rad" for c in COORDINATES}
q = sp.symbols(COORDINATES)
qd = sp.symbols([c + "_d" for c in COORDINATES])
qdd = sp.symbols([c + "_dd" for c in COORDINATES])
psi, theta, phi = q
psid, thetad, phid = qd

# the momenta of the cyclic coordinates, constants of the motion (1.2)
H, L = sp.symbols("H L")


def kinetic_energy():
    """2T of section 1, with C0 general (the paper then sets C0 = 0)."""
    return (psid**2 * (A0 - C0 * sp.cos(theta)**2) + thetad**2 * B0
            + A3 * (phid + psid * sp.cos(theta))**2) / 2


def force_function():
    """U = -P1 eta20 sin(theta) - (P1 eta30 + P l) cos(theta)."""
    return -P1 * eta20 * sp.sin(theta) - G * sp.cos(theta)


def lagrangian():
    return kinetic_energy() + force_function()


def printed_equations():
    """(1.1) as printed (C0 = 0), each as 'left - right', in the order psi, theta, phi."""
    w = phid + psid * sp.cos(theta)
    return [
        mech.time_derivative(A0 * psid + A3 * sp.cos(theta) * w, q, qd, qdd),
        B0 * sp.Symbol("theta_dd") + A3 * psid * sp.sin(theta) * w
        - (-P1 * eta20 * sp.cos(theta) + G * sp.sin(theta)),
        A3 * mech.time_derivative(w, q, qd, qdd),
    ]


def printed_integrals():
    """(1.2) as printed (C0 = 0): H, L, M."""
    w = phid + psid * sp.cos(theta)
    return {
        "H": A3 * w,
        "L": A0 * psid + A3 * w * sp.cos(theta),
        "M": A0 * psid**2 + B0 * thetad**2 + 2 * P1 * eta20 * sp.sin(theta) + 2 * G * sp.cos(theta),
    }


def integrals():
    """First integrals for general C0: the cyclic momenta and the energy T - U."""
    Lg = lagrangian()
    return {
        "H": mech.cyclic_integral(Lg, phid),
        "L": mech.cyclic_integral(Lg, psid),
        "E": kinetic_energy() - force_function(),
    }


def integrals_are_conserved():
    """d/dt of each first integral along the equations of motion (accelerations from the
    mass-matrix form): all zero for general C0, and for the printed (1.2) at C0 = 0."""
    out = mech.integral_rates(lagrangian(), q, qd, qdd, list(integrals().values()))
    out += [r.subs(C0, 0) for r in
            mech.integral_rates(lagrangian().subs(C0, 0), q, qd, qdd, list(printed_integrals().values()))]
    return [sp.simplify(r) for r in out]


def routh_function():
    """Routh's function U1(theta) = U - (L - H cos theta)^2 / (2 (A0 - C0 cos^2 theta)) (3.3):
    psi' eliminated through L; at C0 = 0 the printed -P1 eta20 sin - G cos - (L - H cos)^2/2A0."""
    return force_function() - (L - H * sp.cos(theta))**2 / (2 * (A0 - C0 * sp.cos(theta)**2))


# initial conditions of a motion at t = 0 (the closed form's inputs)
theta0, dtheta0, dpsi0, dphi0 = sp.symbols("theta0 dtheta0 dpsi0 dphi0")


def closed_form_coefficients():
    """b0..b4 of (ds/dtau)^2 = b0 + 4 b1 s + 6 b2 s^2 + 4 b3 s^3 + b4 s^4 (section 2,
    s = tan((theta - theta0)/2)), the invariants g2, g3 of wp (2.6), and H, L, at the
    initial conditions; C0 = 0 (the closed form's assumption)."""
    s0, c0 = sp.sin(theta0), sp.cos(theta0)
    Hm = A3 * (dphi0 + dpsi0 * c0)
    a, g, h = A0 * P1 * eta20, A0 * (G - Hm * dpsi0), Hm**2
    b0 = A0 * B0 * dtheta0**2
    b1 = g * s0 - a * c0
    b2 = (b0 + 2 * a * s0 + 2 * g * c0 - 2 * h * s0**2) / 3
    b3 = g * s0 - a * c0 - 2 * h * s0 * c0
    b4 = b0 + 4 * a * s0 + 4 * g * c0 - 4 * h * c0**2
    g2 = b0 * b4 - 4 * b1 * b3 + 3 * b2**2
    g3 = b0 * b2 * b4 - b1**2 * b4 - b2**3 - b0 * b3**2 + 2 * b1 * b2 * b3
    return sp.Matrix([b0, b1, b2, b3, b4]), g2, g3, Hm, A0 * dpsi0 + Hm * c0


def quantities():
    """What the runtime's analyses need, emitted rather than retyped: G (1.1), the integrals,
    Routh's U1 with its derivatives, and the closed form's coefficients."""
    I = integrals()
    M_int = 2 * I["E"] - I["H"]**2 / A3  # the printed M of (1.2), an integral for any C0
    U1 = routh_function()
    b, g2, g3, Hm, Lm = closed_form_coefficients()
    psi_rate = (L - H * sp.cos(theta)) / (A0 - C0 * sp.cos(theta)**2)
    return {
        "gravity_moment": (["params"], [("G", sp.Matrix([G]))], "G = P1 eta30 + P l (1.1)."),
        "first_integrals": (["params", "q", "qd"],
                            [("values", sp.Matrix([I["H"], I["L"], M_int, I["E"]]))],
                            "First integrals (1.2) along a state: H, L, M = 2E - H^2/A3 (the "
                            "printed A0 psi'^2 + B0 theta'^2 + 2 P1 eta20 sin + 2 G cos at C0 = 0), "
                            "and the energy E = T - U."),
        "routh_function": (["params", "qe", "momenta"],
                           [("U1", sp.Matrix([U1, sp.diff(U1, theta), sp.diff(U1, theta, 2)]))],
                           "Routh's function U1(theta) (3.3) and its first and second derivatives "
                           "in theta: a stationary motion has U1' = 0, a stable one U1'' < 0."),
        "rates_from_momenta": (["params", "qe", "momenta"],
                               [("rates", sp.Matrix([psi_rate, H / A3 - psi_rate * sp.cos(theta)]))],
                               "psi' and phi' at theta from the integrals (1.2): L = (A0 - C0 cos^2) psi' "
                               "+ H cos theta, H = A3 (phi' + psi' cos theta)."),
        "stationary_precession": (["params", "qe", ("spin", [H])],
                                  [("dpsi", sp.Matrix([(G - P1 * eta20 * sp.cos(theta) / sp.sin(theta)) / H]))],
                                  "psi0' of the stationary motion (3.1) at theta with rotor momentum H "
                                  "(C0 = 0): (G - H psi0') sin theta = P1 eta20 cos theta."),
        "closed_form": (["params", ("initial", [theta0, dtheta0, dpsi0, dphi0])],
                        [("b", b), ("g", sp.Matrix([g2, g3])), ("HL", sp.Matrix([Hm, Lm]))],
                        "Section 2 at C0 = 0: b0..b4 of (ds/dtau)^2, the invariants g2, g3 of "
                        "wp in (2.6), and the momenta H, L, at the initial conditions "
                        "theta0, theta0', psi0', phi0'."),
    }


def levels():
    """The hierarchy of the gimbal gyroscope (docs/hierarchy.md): the closed form (2.6)/(2.7)
    of section 2, exact for C0 = 0 (it refuses C0 != 0, and the selector goes on to the
    integrators), and the equations (1.1) integrated, any C0. Both bound the motion by the
    evaluator's own estimate (gyro.systems.gimbal_gyroscope.motion_answer). Costs: s per set at the
    default motion over a horizon of 1 s (bench/levels.py)."""
    from derive.model import Bound, Level

    return [
        Level("closed_form", "nothing of (1.1) at C0 = 0 (rounding only; it grows near the separatrix)",
              {"kind": "trajectory", "module": "gyro.systems.gimbal_gyroscope", "method": "closed_form"},
              {"motion": Bound(estimate=True)}, cost=8e-3, reference="integrated:DOP853",
              doc="theta by (2.6)/(2.7) through Weierstrass's wp, psi and phi by quadrature of (2.1), (2.3)"),
        Level("integrated", "nothing of (1.1) (the integrator's truncation: two tolerances compared)",
              {"kind": "trajectory", "module": "gyro.systems.gimbal_gyroscope", "methods": ["DOP853", "Radau"], "rtol": 1e-10,
               "default": "DOP853"},
              {"motion": Bound(estimate=True)}, cost={"DOP853": 0.6, "Radau": 4.0}, reference="closed_form",
              doc="the generated equations (1.1) integrated at rtol and rtol/100 (SciPy)"),
    ]


def build():
    from derive.model import Model

    return Model(
        name=NAME, title=TITLE, source=SOURCE, module=__name__,
        parameters=PARAMETERS, coordinates=COORDINATES, coordinate_units=COORDINATE_UNITS,
        q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=lagrangian(),
        cyclic={"phi": H, "psi": L},
        reduced=["theta"],
        identities={"first integrals (1.2): H, L and the energy are conserved": integrals_are_conserved},
        quantities=quantities(),
        simulate={"module": "gyro.systems.gimbal_gyroscope", "options": ["method"],
                  "initial": "psi(0) = phi(0) = 0",
                  "usage": "--set theta0 dtheta0 dpsi0 dphi0 (psi(0) = phi(0) = 0); --method closed_form (default), "
                           "RK45, DOP853, Radau, BDF, LSODA, cvodes, idas"},
        levels=levels(),
    )
