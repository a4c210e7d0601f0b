"""Gyrohorizoncompass in a Newtonian field of gravitation (Zavozin, 1979).

Source: shared/seeds/001_2381afb5196645c6.txt; equation numbers are the paper's; the OCR
readings taken are listed in docs/gyrohorizoncompass.md with their evidence.

A gyrosphere (inertia Lambda = diag(A, B, C) about the suspension point O, mass centre at
-l e3) carries two identical gyroscopes of angular momentum L each, their casings turned
about axes parallel to e3 by +epsilon and -epsilon (coupled: equal and opposite angles),
so that H = 2 L cos(epsilon) e2. O moves over a sphere of radius R; the Darboux trihedron
a1, a2, a3 (a1 along the absolute velocity v, a3 up the geocentric vertical) turns at the
absolute rate omega1 = zeta a2 + eta a3 (1.2), zeta = v/R and eta constant. The angles
alpha, beta, gamma of (1.1) take it to the gyrosphere's axes e1, e2, e3:
S = Rz(alpha) Rx(beta) Ry(gamma), a_ij = a_i . e_j = S[i, j].

The paper writes (1.5)-(1.6) in the moving frame. They are Lagrange's equations of

    L = 1/2 omega . Lambda omega + H(epsilon) . omega + J epsilon'^2          (kinetic)
        + I (nu^2 - zeta^2) a33 + I zeta eta a23 - 3/2 nu^2 a3 . Lambda a3      (force function)

with omega = omega1 + omega2 the absolute rate of the gyrosphere (omega1 a function of the
angles only, since zeta and eta are constant in the Darboux axes), H . omega the Routh term
of the two rotors (cyclic spins, momenta L), J epsilon'^2 the two casings' turns, and the
force function made of gravity m g a3 x l (g = nu^2 R, I = m l R), the transport
acceleration w = R zeta eta a2 - R zeta^2 a3 (its potential m w . l) and the gravity
gradient 3 nu^2 a3 x Lambda a3 (MacCullagh). The sensor's moment N(epsilon) (2.1) is a
generalised force on epsilon. `equations_are_the_papers` proves the equality: the Lagrange
equations in alpha, beta, gamma are (1.5) projected on the rotation axes of the three
angles, and the epsilon equation is (1.6).

No explicit time, signal, cyclic or steady coordinate is needed: the model's Lagrangian is
autonomous, and the paper's integral E (2.3) is its Jacobi integral less the sensor's
potential.

Parameters (the command line's names; `lambda` is a keyword of C and Python, so the
parameter symbol is `lam`, and the runtime maps the name `lambda` to it):
    A B C J L I nu zeta eta lambda(-> lam)
"""
from __future__ import annotations

import functools
import math

import sympy as sp

from derive import mechanics as mech
from derive.model import Conditions, Parameter

NAME = "gyrohorizoncompass"
TITLE = "Gyrohorizoncompass in a Newtonian field of gravitation"
SOURCE = "shared/seeds/001_2381afb5196645c6.txt (Zavozin 1979)"

# the command-line name of each parameter whose symbol differs from it
CLI_NAMES = {"lambda": "lam"}

# ----------------------------------------------------------------------------- parameter sets
# The paper prints no numerical example. Earth set: a marine gyrosphere at rest on the Earth
# at latitude 60 deg. m = 2 kg, l = 5 mm, R = 6.371e6 m give I = m l R = 63710 kg m^2;
# g = 9.81 m/s^2 gives nu = sqrt(g/R); the point's absolute velocity is the Earth's
# rotation, v = u R cos(phi) eastward, so zeta = u cos(phi), eta = u sin(phi), u = 7.2921e-5
# rad/s. Lambda ~ 0.02 kg m^2 makes theta = (C - A)/I, chi = (C - B)/I about 1e-7.
# lambda = 1 + chi (3.2). L = 2 kg m^2/s puts epsilon0 = arccos(I lambda zeta/2L) near 54 deg.
_u, _phi, _R, _g = 7.2921e-5, math.radians(60.0), 6.371e6, 9.81
_I = 2.0 * 0.005 * _R
_A, _B, _C = 0.020, 0.022, 0.025
EARTH = {"A": _A, "B": _B, "C": _C, "J": 0.005, "L": 2.0, "I": _I,
         "nu": math.sqrt(_g / _R), "zeta": _u * math.cos(_phi), "eta": _u * math.sin(_phi),
         "lam": 1.0 + (_C - _B) / _I}

# Laboratory set, scaled so that theta = (C - A)/I = 0.1 and chi = (C - B)/I = 0.05 (O(0.1)):
# the gyrosphere's inertia is comparable with I, and the four modes lie within a factor 2.9
# (0.347 to 1.007 rad/s), so that 1e3 periods of the slowest are a short simulation. The
# conditions (3.6) hold with margins (1 - 3 theta) nu^2 - zeta^2 - eta^2 = 0.41 and
# (1 - 3 chi) nu^2 - eta^2 = 0.81; lambda = 1 + chi; epsilon0 = arccos(0.525) = 58 deg.
LAB = {"A": 1.0, "B": 1.05, "C": 1.1, "J": 1.0, "L": 0.5, "I": 1.0,
       "nu": 1.0, "zeta": 0.5, "eta": 0.2, "lam": 1.05}

PARAMETERS = [
    Parameter("A", "kg m^2", EARTH["A"], "gyrosphere moment of inertia about e1 (at O)"),
    Parameter("B", "kg m^2", EARTH["B"], "gyrosphere moment of inertia about e2 (along H)"),
    Parameter("C", "kg m^2", EARTH["C"], "gyrosphere moment of inertia about e3 (casing axes)"),
    Parameter("J", "kg m^2", EARTH["J"], "moment of inertia of one gyroscope about its casing axis"),
    Parameter("L", "kg m^2/s", EARTH["L"], "angular momentum of one gyroscope"),
    Parameter("I", "kg m^2", EARTH["I"], "I = m l R (mass, mass-centre depth, sphere radius)"),
    Parameter("nu", "rad/s", EARTH["nu"], "Schuler frequency nu = sqrt(g/R)"),
    Parameter("zeta", "rad/s", EARTH["zeta"], "zeta = v/R: Darboux rate about a2 (v the absolute speed)",
              kind="nonnegative"),
    Parameter("eta", "rad/s", EARTH["eta"], "vertical component of the Darboux trihedron's rate",
              kind="real"),
    Parameter("lam", "1", EARTH["lam"], "sensor gain lambda of (2.1) (command line: lambda; "
              "(3.2): 1 + chi)"),
]
P = {p.name: p.symbol for p in PARAMETERS}
A, B, C, J, L, I, nu, zeta, eta, lam = (P[p.name] for p in PARAMETERS)
chi = (C - B) / I  # (3.2)
theta = (C - A) / I  # (3.5)

# ----------------------------------------------------------------------------- coordinates
COORDINATES = ["alpha", "beta", "gamma", "epsilon"]
COORDINATE_UNITS = {c: "rad" for c in COORDINATES}
q = sp.symbols(COORDINATES)
qd = sp.symbols([c + "_d" for c in COORDINATES])
qdd = sp.symbols([c + "_dd" for c in COORDINATES])
alpha, beta, gamma, epsilon = q
alphad, betad, gammad, epsilond = qd
SEQUENCE = [("z", alpha), ("x", beta), ("y", gamma)]  # (1.1)
LAMBDA = sp.diag(A, B, C)


def frames():
    """S (1.1); omega1, omega2, omega (1.2) and a2, a3, in the gyrosphere's axes e1, e2, e3."""
    S = mech.rotation(SEQUENCE)
    w1_darboux = sp.Matrix([0, zeta, eta])
    omega1 = S.T * w1_darboux
    omega2 = mech.angular_velocity(SEQUENCE, [alphad, betad, gammad])
    omega = mech.angular_velocity(SEQUENCE, [alphad, betad, gammad], base=w1_darboux)
    a2, a3 = S.T * mech.unit("y"), S.T * mech.unit("z")
    return S, omega1, omega2, omega, a2, a3


def kinetic_momentum():
    """H = 2 L cos(epsilon) e2: the two rotors' momenta L at +-epsilon from e2."""
    return sp.Matrix([0, 2 * L * sp.cos(epsilon), 0])


def sensor_moment():
    """(2.1), read N = 2 L^2 sin(2 epsilon)/(I lambda)."""
    return 2 * L**2 * sp.sin(2 * epsilon) / (I * lam)


def force_function():
    """Gravity, transport acceleration and gravity gradient (1.4): U with the moments of
    (1.5) as its torques. (a23 = e3 . a2, a33 = e3 . a3.)"""
    _, _, _, _, a2, a3 = frames()
    return (I * (nu**2 - zeta**2) * a3[2] + I * zeta * eta * a2[2]
            - sp.Rational(3, 2) * nu**2 * (a3.T * LAMBDA * a3)[0])


def lagrangian():
    _, _, _, omega, _, _ = frames()
    T = (omega.T * LAMBDA * omega)[0] / 2 + (kinetic_momentum().T * omega)[0] + J * epsilond**2
    return sp.expand(T) + force_function()


def printed_equations():
    """(1.5) as a vector in e1, e2, e3 and (1.6), each 'left - right'.

    H' and omega' are local derivatives in the gyrosphere's axes: the time derivatives of
    the components."""
    _, _, _, omega, a2, a3 = frames()
    H = kinetic_momentum()
    e3 = mech.unit("z")
    Hd = mech.time_derivative(H, q, qd, qdd)
    wd = mech.time_derivative(omega, q, qd, qdd)
    lhs = Hd + LAMBDA * wd + mech.cross(omega, H + LAMBDA * omega)
    rhs = (I * zeta * eta * mech.cross(e3, a2)
           + mech.cross(I * (nu**2 - zeta**2) * e3 - 3 * nu**2 * LAMBDA * a3, a3))
    eq15 = lhs - rhs
    eq16 = 2 * J * sp.Symbol("epsilon_dd") + 2 * omega[1] * L * sp.sin(epsilon) - sensor_moment()
    return eq15, eq16


def _zero(e):
    """A trigonometric polynomial in the angles, reduced to a canonical form: multiple angles
    expanded, then cos^2 -> 1 - sin^2. An identity's residual comes out as 0."""
    e = sp.expand(sp.expand_trig(e))
    if e == 0:
        return e
    return sp.expand(e.replace(
        lambda a: a.is_Pow and a.exp.is_Integer and a.exp >= 2 and a.base.func == sp.cos,
        lambda a: (1 - sp.sin(a.base.args[0])**2)**(a.exp // 2) * a.base**(a.exp % 2)))


def equations_are_the_papers():
    """The Lagrange equations of `lagrangian` with the force N on epsilon are (1.5)-(1.6):
    E_alpha, E_beta, E_gamma = W' (1.5), W = d omega/d(alpha', beta', gamma') (the rotation
    axes of the angles in e1, e2, e3), and E_epsilon = (1.6). Residuals: all zero."""
    _, _, _, omega, _, _ = frames()
    E = mech.lagrange_equations(lagrangian(), q, qd, qdd, [0, 0, 0, sensor_moment()])
    eq15, eq16 = printed_equations()
    W = omega.jacobian([alphad, betad, gammad])
    proj = W.T * eq15
    return [_zero(E[k] - proj[k]) for k in range(3)] + [_zero(E[3] - eq16)]


# ----------------------------------------------------------------------------- section 2


def energy_integral():
    """(2.3) as printed (readings: J epsilon'^2, the sensor term -2 L^2 sin^2(eps)/(I lambda))."""
    _, omega1, omega2, _, a2, a3 = frames()
    H = kinetic_momentum()
    return (-(omega1.T * LAMBDA * omega1)[0] / 2 + (omega2.T * LAMBDA * omega2)[0] / 2
            - (omega1.T * H)[0] + J * epsilond**2 - 2 * L**2 * sp.sin(epsilon)**2 / (I * lam)
            - I * zeta * eta * a2[2] - I * (nu**2 - zeta**2) * a3[2]
            + sp.Rational(3, 2) * nu**2 * (a3.T * LAMBDA * a3)[0])


def energy_is_conserved():
    """The paper's route to (2.2): (1.5) dotted with omega2 plus (1.6) times epsilon' is the
    time derivative of E, identically in the accelerations; so E' = 0 on the equations.
    Also: E is the Jacobi integral of `lagrangian` less the sensor's potential."""
    _, _, omega2, _, _, _ = frames()
    eq15, eq16 = printed_equations()
    eq16 = eq16.subs(sp.Symbol("epsilon_dd"), qdd[3])
    E = energy_integral()
    dE = mech.time_derivative(E, q, qd, qdd)
    Lg = lagrangian()
    jacobi = sum(v * sp.diff(Lg, v) for v in qd) - Lg
    U_N = 2 * L**2 * sp.sin(epsilon)**2 / (I * lam)
    return [_zero(dE - (omega2.T * eq15)[0] - epsilond * eq16), _zero(E - (jacobi - U_N)),
            _zero(sp.diff(U_N, epsilon) - sensor_moment())]


# ----------------------------------------------------------------------------- section 3


def epsilon0():
    """(3.1): epsilon0 = arccos(I lambda zeta/2L); exists iff I lambda zeta/2L < 1."""
    return sp.acos(I * lam * zeta / (2 * L))


EQUILIBRIUM = {alpha: 0, beta: 0, gamma: 0}
REST = {v: 0 for v in qd}


@functools.lru_cache(maxsize=None)
def hessians(at_eps=None):
    """B1 and C1 of (3.5): the Hessians of E in the rates and in the angles at the relative
    equilibrium (3.1) (epsilon = at_eps, default epsilon0), x = (alpha, beta, gamma,
    epsilon - epsilon0). 2V = x'. B1 x' + x . C1 x + (order 3) with V = E - E0; E has no
    terms of first degree in the rates, so there are no mixed terms."""
    at_eps = epsilon0() if at_eps is None else at_eps
    E = energy_integral()
    at = dict(EQUILIBRIUM)
    at[epsilon] = at_eps
    B1 = sp.hessian(E, list(qd)).subs(REST).subs(at)
    C1 = sp.hessian(E.subs(REST), list(q)).subs(at)
    return B1.applyfunc(sp.simplify), C1.applyfunc(sp.simplify)


def printed_hessians(eps0=None, xi=zeta):
    """B1, C1 of (3.5) as printed, with the readings b44 = 2J (printed 2I) and xi = zeta."""
    s = sp.sin(epsilon0() if eps0 is None else eps0)
    B1 = sp.diag(C, A, B, 2 * J)
    C1 = sp.zeros(4, 4)
    C1[0, 0] = I * (1 + theta) * xi**2
    C1[1, 1] = I * ((1 - 3 * chi) * nu**2 + chi * eta**2)
    C1[2, 2] = I * ((1 - 3 * theta) * nu**2 - xi**2 + theta * eta**2)
    C1[3, 3] = 4 * L**2 * s**2 / (I * lam)
    C1[0, 2] = C1[2, 0] = -I * (1 + theta) * xi * eta
    C1[1, 3] = C1[3, 1] = 2 * eta * L * s
    return B1, C1


def printed_satellite_C1(eps0=None):
    """C1 of section 4 as printed (zeta = nu, eta = 0, lambda free)."""
    s = sp.sin(epsilon0() if eps0 is None else eps0)
    return sp.diag(I * (lam + theta - chi) * nu**2, I * (lam - 4 * chi) * nu**2,
                   -3 * I * theta * nu**2, 4 * L**2 * s**2 / (I * lam))


def conditions_36():
    """(3.6) as printed (xi read zeta), each as a margin that must be positive."""
    return [1 + theta, sp.Rational(1, 3) - theta, 1 + chi, sp.Rational(1, 3) - chi,
            (1 - 3 * theta) * nu**2 - zeta**2 - eta**2, (1 - 3 * chi) * nu**2 - eta**2]


def conditions_43():
    """(4.3) with the reading chi < lambda/4 (printed chi < 1/lambda): margins > 0."""
    return [lam + theta - chi, lam / 4 - chi, -theta]


def sylvester_minors(C1):
    """Leading principal minors of C1 in the order (alpha, gamma, beta, epsilon), which puts
    its two blocks {alpha, gamma} and {beta, epsilon} first and second."""
    order = [0, 2, 1, 3]
    M = C1.extract(order, order)
    return [M[:k, :k].det() for k in range(1, 5)]


# ----------------------------------------------------------------------------- quantities


def quantities():
    """What the runtime's analyses need, emitted rather than retyped."""
    E = energy_integral()
    eps0 = epsilon0()
    E0 = E.subs(REST).subs(EQUILIBRIUM).subs(epsilon, eps0)
    B1, C1 = hessians()
    ratio = I * lam * zeta / (2 * L)
    return {
        "first_integral": (["params", "q", "qd"],
                           [("E", sp.Matrix([E])), ("V", sp.Matrix([E - E0]))],
                           "The integral E of (2.2)-(2.3) along a state, and V = E - E0 (3.4), "
                           "E0 its value at the relative equilibrium (3.1) (NaN where there is none)."),
        "relative_equilibrium": (["params"],
                                 [("epsilon0", sp.Matrix([eps0])),
                                  ("margins", sp.Matrix([1 - ratio, eta * (lam - 1 - chi)])),
                                  ("theta_chi", sp.Matrix([theta, chi]))],
                                 "(3.1)-(3.2): epsilon0 = arccos(I lambda zeta/2L); margins: "
                                 "1 - I lambda zeta/2L (> 0 for the equilibrium to exist) and "
                                 "eta (lambda - 1 - chi) (= 0 for it to be one); theta = (C - A)/I, "
                                 "chi = (C - B)/I."),
        "lyapunov": (["params"], [("B1", B1), ("C1", C1)],
                     "(3.5): B1 and C1, the Hessians of V = E - E0 in the rates and in "
                     "x = (alpha, beta, gamma, epsilon - epsilon0) at the relative equilibrium "
                     "(derived, for any lambda)."),
    }


# the labels of the margins, as `gyro stability` prints them
SYLVESTER_LABELS = ("C1 minor 1 (alpha)", "C1 minor 2 (alpha, gamma)", "C1 minor 3 (alpha, gamma, beta)",
                    "C1 minor 4 (all)")
LABELS_36 = ("(3.6) 1 + theta", "(3.6) 1/3 - theta", "(3.6) 1 + chi", "(3.6) 1/3 - chi",
             "(3.6) (1 - 3 theta) nu^2 - zeta^2 - eta^2", "(3.6) (1 - 3 chi) nu^2 - eta^2")
LABELS_43 = ("(4.3) lambda + theta - chi", "(4.3) lambda/4 - chi", "(4.3) -theta")


def conditions():
    """The sufficient conditions of sections 3 and 4 (Model.conditions), emitted with their
    rounding bounds as `conditions` and `conditions_rounding` (derive/outputs/conditions.py):
    C1 > 0 by Sylvester's criterion (margins 0-3), (3.6) (4-9) and (4.3) (10-12). Which
    applies where (the orbit, lambda = 1 + chi) is the runtime's gyro.systems.gyrohorizoncompass."""
    _, C1 = hessians()
    return {
        "C1 > 0": Conditions(list(zip(SYLVESTER_LABELS, sylvester_minors(C1))),
                             "Sylvester's criterion on C1 of (3.5), the Hessian of V = E - E0 in the angles: "
                             "its leading minors in the order alpha, gamma, beta, epsilon (V positive "
                             "definite: Lyapunov stability of (3.1), any lambda)"),
        "(3.6)": Conditions(list(zip(LABELS_36, conditions_36())),
                            "(3.6) as printed (zeta for xi): C1 > 0 where lambda = 1 + chi (3.2), with "
                            "zeta != 0 and epsilon0 != 0"),
        "(4.3)": Conditions(list(zip(LABELS_43, conditions_43())),
                            "(4.3) on a circular orbit (zeta = nu, eta = 0, lambda free), read "
                            "chi < lambda/4"),
    }


def levels():
    """The hierarchy of the gyrohorizoncompass (docs/hierarchy.md): its linearised operator
    about the relative equilibrium (3.1)-(3.2) by the ladder's methods (their estimates are
    the bounds); and the motion of a perturbed equilibrium, by the linearised equations
    (the generic linear level, gyro.analyses.motion: exact, e^{A t}; bounded by twice their
    correction after two Picard steps toward (1.5)-(1.6), capped at a quarter of the linear
    motion's displacement from (3.1), at most a radian) or by
    (1.5)-(1.6) integrated (bounded by two tolerances compared). Motion costs: s per set
    at the default motion of the Earth set over a horizon of 1 s (bench/levels.py)."""
    from derive.model import Bound, Level

    return [
        Level("linear", "the terms of second and higher order in the perturbation of (3.1) in (1.5)-(1.6)",
              {"kind": "trajectory", "module": "gyro.systems.gyrohorizoncompass", "method": "linear",
               "cap_of": "displacement"},
              {"motion": Bound(estimate=True)}, cost=0.03, reference="integrated:DOP853",
              doc="the linearised equations about (3.1) solved exactly (gyro.analyses.motion); the estimate "
                  "twice the correction after two Picard steps, infinite beyond a quarter of the displacement"),
        Level("integrated", "nothing of (1.5)-(1.6) (the integrator's truncation: two tolerances compared)",
              {"kind": "trajectory", "module": "gyro.systems.gyrohorizoncompass", "methods": ["DOP853", "Radau"],
               "rtol": 1e-10, "default": "DOP853"},
              {"motion": Bound(estimate=True)}, cost={"DOP853": 1.5, "Radau": 20.0}, reference="linear",
              doc="the emitted equations (1.5)-(1.6) integrated at rtol and rtol/100 (SciPy)"),
        Level("linear_exact", "nothing of the linearised motion about the exact relative equilibrium (3.1)",
              {"kind": "spectrum", "methods": ["polyroots", "companion", "default", "reference"], "default": "default"},
              {"frequencies": Bound(estimate=True), "stability": Bound(estimate=True)},
              reference="linear_exact:reference",
              doc="the exact operator about the relative equilibrium, by a method of the ladder"),
    ]


def build():
    from derive.model import Model

    return Model(
        name=NAME, title=TITLE, source=SOURCE, module=__name__,
        parameters=PARAMETERS, coordinates=COORDINATES, coordinate_units=COORDINATE_UNITS,
        q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=lagrangian(),
        generalized_forces={"epsilon": sensor_moment()},
        identities={
            "the Lagrange equations are (1.5)-(1.6)": equations_are_the_papers,
            "the integral E (2.2)-(2.3): its derivative is (1.5).omega2 + (1.6) epsilon'": energy_is_conserved,
        },
        quantities=quantities(),
        simulate={"module": "gyro.systems.gyrohorizoncompass", "options": ["perturb", "method"],
                  "usage": "--perturb D1,D2,D3,D4 or alpha=.. beta=.. gamma=.. epsilon=.. (rad, at rest, from the "
                           "relative equilibrium (3.1)); --method DOP853 (default), RK45, Radau, BDF, LSODA, cvodes, "
                           "cvodes-adams, projected (onto E = E(0))"},
        levels=levels(),
        aliases=CLI_NAMES,
        conditions=conditions(),
        system="gyro.systems.gyrohorizoncompass",
        # the start of the runtime's Newton: (3.1) itself (from zero it found the other
        # relative equilibrium, epsilon = 0 with beta = 1.1e-3 at the Earth set, unstable)
        equilibrium_approx={"alpha": sp.Integer(0), "beta": sp.Integer(0), "gamma": sp.Integer(0),
                            "epsilon": epsilon0()},
    )
