"""Gyroscope in a gimbal on a rotating base: precession theory and the image point (Ishlinsky, 1959).

Source: shared/seeds/002_2fa97989621eaf24.txt; equation numbers are the paper's; the OCR
readings taken are listed in docs/precession.md with their evidence.

Three bodies: the outer ring (axis xi = xi1 of the base), the inner ring or casing (axis
eta1 = y' of the outer ring), the rotor (axis z' of the casing). Angles alpha (outer ring
against the base, about xi), beta (casing against the outer ring, about eta1), phi (rotor
against the casing, about z'). The base turns at the absolute rate u, components
u_xi, u_eta, u_zeta in its own axes: constants, or given functions of time (`BASE_RATE`:
each a signal that makes its parameter time-varying; the full level's equations then carry
u' through d/dt of the kinetic energy, the precession levels u itself). Frames: base xi eta zeta, outer ring
Rx(alpha), casing Rx(alpha) Ry(beta); the kinematics (3)-(5) are the angular velocities of
these frames (`mechanics.angular_velocity`), proved equal to the print in
`kinematics_are_the_papers`.

Moments (all named by the contract's parameters):
- K_xi1 = -f_alpha alpha' (friction of the base on the outer ring), L_y' = -f_beta beta'
  (outer ring on the casing), M_z' = M_motor - f_phi phi' (casing on the rotor: the spin
  motor and the spin-axis friction): a Rayleigh function and a generalised force on phi;
- k_xi1 = k_xi1 cos(alpha): the outer ring's imbalance (its mass centre off the ring's axis
  along eta1, gravity along the base's -zeta: k_xi1 is the moment at alpha = 0);
- l = (l_x, l_y, l_z) on the casing and m = (m_x, m_y, m_z) on the rotor, constants in
  the casing axes x' y' z' (a torque motor, an imbalance of casing or rotor at small angles).

Five levels of one hierarchy, each emitted (`quantities`):
- `full`: the three-body Lagrange equations (the generic `mass_matrix`/`forcing`), the
  outer ring diag(C3, C1, C2) in xi1 eta1 zeta1 (its transverse moments enter only through
  (C2 - C1) omega_eta1 omega_zeta1, the ring's centrifugal moment about xi1 on a turning base:
  at the defaults C1 = C2 = C3 it vanishes and the equations are those of the axial moment
  alone), the casing diag(B2, B1, B3) in x' y' z' (Avdonin's B1 about the casing axis
  eta1 = y', B3 about the spin axis), the rotor A1, A1, A3;
- `rigorous`: (13) for alpha', beta', H' (`rigorous_system`: A r = b in the rates): the
  rotor's momentum taken as H along z' (6), the rings' momenta neglected;
- `image`: (21) in the image point x, y (`image_system`), the same motion as `rigorous`;
- `small`: (28) (`small_system`): rho = 1, rho' = 0, c -> x, m_z' + l_z' -> m_z + l_z;
- `elementary`: (30) H v_x = m_x + l_x, H v_y = m_y + l_y, H' = 0 (`elementary_system`).
The image point of the casing axis z': x = c/c'' = tan(beta)/cos(alpha), y = c'/c'' =
-tan(alpha) in the base axes (the frame xyz of the paper is the base here, omega = u).

The paper prints no numerical example: the defaults are an illustrative laboratory
gyroscope (H = 1 N m s, the Earth's rate at latitude 56 deg, a correction torque l_x).
"""
from __future__ import annotations

import math

import sympy as sp

from derive import mechanics as mech
from derive.model import Load, Parameter, Signal

NAME = "gimbal_precession"
TITLE = "Gyroscope in a gimbal on a rotating base: precession theory of the image point"
SOURCE = "shared/seeds/002_2fa97989621eaf24.txt (Ishlinsky 1959)"

EARTH = 7.2921e-5  # rad/s
LAT = math.radians(56.0)

PARAMETERS = [
    Parameter("H", "N m s", 1.0, "rotor momentum H = A3 (phi' + omega_z') at t = 0"),
    Parameter("alpha0", "rad", 0.0, "outer ring angle at t = 0", kind="real", bounds=(-1.5, 1.5)),
    Parameter("beta0", "rad", 0.0, "casing angle at t = 0 (|beta| < 90 deg: (13) is singular there)",
              kind="real", bounds=(-1.5, 1.5)),
    Parameter("u_xi", "rad/s", 0.0, "base rate along xi (outer ring axis)", kind="real"),
    Parameter("u_eta", "rad/s", round(EARTH * math.cos(LAT), 10), "base rate along eta (Earth, 56 deg)", kind="real"),
    Parameter("u_zeta", "rad/s", round(EARTH * math.sin(LAT), 10), "base rate along zeta (Earth, 56 deg)", kind="real"),
    Parameter("f_alpha", "N m s", 0.0, "viscous friction in the outer ring axis", kind="nonnegative"),
    Parameter("f_beta", "N m s", 0.0, "viscous friction in the casing axis", kind="nonnegative"),
    Parameter("f_phi", "N m s", 0.0, "viscous friction in the rotor axis", kind="nonnegative"),
    Parameter("Mmotor", "N m", 0.0, "spin motor moment on the rotor about z' (M_motor at the command line)", kind="real"),
    Parameter("k_xi1", "N m", 0.0, "outer ring imbalance: its moment about xi1 at alpha = 0", kind="real"),
    Parameter("l_x", "N m", 1e-3, "moment on the casing about x' (a torque motor)", kind="real"),
    Parameter("l_y", "N m", 0.0, "moment on the casing about y'", kind="real"),
    Parameter("l_z", "N m", 0.0, "moment on the casing about z' (the spin axis)", kind="real"),
    Parameter("m_x", "N m", 0.0, "moment on the rotor about x'", kind="real"),
    Parameter("m_y", "N m", 0.0, "moment on the rotor about y'", kind="real"),
    Parameter("m_z", "N m", 0.0, "moment on the rotor about z' (the spin axis)", kind="real"),
    Parameter("C3", "kg m^2", 2e-3, "outer ring's moment of inertia about its axis xi1 (full level)"),
    Parameter("C1", "kg m^2", 2e-3, "outer ring's moment about eta1 (full level; C1 = C2 = C3 by default: "
              "then the ring's transverse moments do not enter)"),
    Parameter("C2", "kg m^2", 2e-3, "outer ring's moment about zeta1 (full level; a flat ring in the plane "
              "eta1 zeta1 has C2 - C1 = C3)"),
    Parameter("B1", "kg m^2", 1.2e-3, "casing's moment about its axis y' = eta1 (full level)"),
    Parameter("B2", "kg m^2", 1.0e-3, "casing's moment about x' (full level)"),
    Parameter("B3", "kg m^2", 0.8e-3, "casing's moment about the spin axis z' (full level)"),
    Parameter("A1", "kg m^2", 0.5e-3, "rotor's equatorial moment of inertia (full level)"),
    Parameter("A3", "kg m^2", 1.0e-3, "rotor's polar moment of inertia (phi' = H/A3 - omega_z')"),
]
Pm = {p.name: p.symbol for p in PARAMETERS}
(H, alpha0, beta0, u_xi, u_eta, u_zeta, f_alpha, f_beta, f_phi, Mmotor, k_xi1,
 l_x, l_y, l_z, m_x, m_y, m_z, C3, C1, C2, B1, B2, B3, A1, A3) = (Pm[p.name] for p in PARAMETERS)

COORDINATES = ["alpha", "beta", "phi"]
COORDINATE_UNITS = {c: "rad" for c in COORDINATES}
q = sp.symbols(COORDINATES)
qd = sp.symbols([c + "_d" for c in COORDINATES])
qdd = sp.symbols([c + "_dd" for c in COORDINATES])
alpha, beta, phi = q
alpha_d, beta_d, phi_d = qd

# the command-line name of each parameter whose symbol differs from it (M_* is a macro
# name space of <math.h>, refused by derive.names)
CLI_NAMES = {"M_motor": "Mmotor"}

# the state of the precession levels besides the angles or the image point
Hs = sp.Symbol("H_t")  # the rotor momentum at time t
x, y = sp.symbols("x y")  # the image point
x_d, y_d, H_d = sp.symbols("x_d y_d H_t_d")

u = sp.Matrix([u_xi, u_eta, u_zeta])
# a time-varying base (a ship's rolling and yaw): u_xi(t), u_eta(t), u_zeta(t) and their
# rates, inputs of every function emitted again as NAME_varying (derive.model.Signal.parameter)
BASE_RATE = [Signal(f"{p}_t", "rad/s", f"the base rate {p} at time t", input=False, order=1, parameter=p)
             for p in ("u_xi", "u_eta", "u_zeta")]
RING = [("x", alpha)]
CASING = [("x", alpha), ("y", beta)]
TABLE = mech.rotation(CASING)  # (17): rows x y z (base), columns x' y' z' (casing)


def ring_rate(rates=(alpha_d,)):
    """(3): the outer ring's absolute angular velocity in its axes xi1 eta1 zeta1."""
    return mech.angular_velocity(RING, rates, base=u)


def casing_rate(rates=(alpha_d, beta_d)):
    """(4): the casing's absolute angular velocity in x' y' z'."""
    return mech.angular_velocity(CASING, rates, base=u)


def rotor_rate():
    """(5): the rotor's, in x' y' z'."""
    return casing_rate() + phi_d * mech.unit("z")


def kinematics_are_the_papers():
    """(3), (4), (5) as printed (with the reading du/dt -> d alpha/dt) minus the rates of the
    frames: all zero."""
    s, c = sp.sin, sp.cos
    w1 = [u_xi + alpha_d, u_eta * c(alpha) + u_zeta * s(alpha), -u_eta * s(alpha) + u_zeta * c(alpha)]
    wc = [(u_xi + alpha_d) * c(beta) - w1[2] * s(beta), w1[1] + beta_d, (u_xi + alpha_d) * s(beta) + w1[2] * c(beta)]
    wr = [wc[0], wc[1], wc[2] + phi_d]
    out = list(ring_rate() - sp.Matrix(w1)) + list(casing_rate() - sp.Matrix(wc)) + list(rotor_rate() - sp.Matrix(wr))
    return [sp.simplify(e) for e in out]


# ----------------------------------------------------------------------------- full level

def kinetic_energy():
    w1, wc, wr = ring_rate(), casing_rate(), rotor_rate()
    return (C3 * w1[0]**2 + C1 * w1[1]**2 + C2 * w1[2]**2 + B2 * wc[0]**2 + B1 * wc[1]**2 + B3 * wc[2]**2
            + A1 * (wr[0]**2 + wr[1]**2) + A3 * wr[2]**2) / 2


def dissipation():
    """Rayleigh's function of the three axes' viscous friction: K = -f_alpha alpha',
    L_y' = -f_beta beta', and the friction part of M_z'."""
    return (f_alpha * alpha_d**2 + f_beta * beta_d**2 + f_phi * phi_d**2) / 2


def loads():
    """The moments on the bodies, each with the angular velocity of its body (virtual power
    (10)): the imbalance on the outer ring, l on the casing, m on the rotor."""
    return [Load(sp.Matrix([k_xi1 * sp.cos(alpha), 0, 0]), ring_rate(), "outer ring imbalance k_xi1"),
            Load(sp.Matrix([l_x, l_y, l_z]), casing_rate(), "moments l on the casing"),
            Load(sp.Matrix([m_x, m_y, m_z]), rotor_rate(), "moments m on the rotor")]


# ----------------------------------------------------------------------------- precession levels

def moments(ad, bd, Hnow, a=alpha, b=beta):
    """The interaction moments of (10) along a motion: K_xi1, k_xi1, L_y', M_z', with
    phi' = H/A3 - omega_z' (H = A3 (phi' + omega_z'), the rotor's axial momentum)."""
    wz = casing_rate((ad, bd)).subs({alpha: a, beta: b})[2]
    return {"K": -f_alpha * ad, "k": k_xi1 * sp.cos(a), "L": -f_beta * bd,
            "M": Mmotor - f_phi * (Hnow / A3 - wz)}


def gyroscopic_couples(ad, bd, Hnow, Hdot):
    """(6): G = -dH/dt in the casing axes, H = Hnow e_z': G_x = -omega_y' H,
    G_y = omega_x' H, G_z = -H'."""
    wc = casing_rate((ad, bd))
    return sp.Matrix([-wc[1] * Hnow, wc[0] * Hnow, -Hdot])


def virtual_power_equations(ad=alpha_d, bd=beta_d, Hnow=Hs, Hdot=H_d):
    """(12): the coefficients of delta alpha', delta beta', delta phi' in (11), each = 0,
    from the virtual power (10) of the moments and the couples (6) over the virtual rates
    (7)-(9) of the three bodies (`mech.load_forces` of each moment over its body's rate)."""
    Mo = moments(ad, bd, Hnow)
    G = gyroscopic_couples(ad, bd, Hnow, Hdot)
    vr = sp.symbols("va vb vp")  # virtual generalised rates
    ring = ring_rate((vr[0],)).subs({u_xi: 0, u_eta: 0, u_zeta: 0})  # (7)
    cas = casing_rate(vr[:2]).subs({u_xi: 0, u_eta: 0, u_zeta: 0})  # (8)
    rot = cas + vr[2] * mech.unit("z")  # (9)
    dW = (sp.Matrix([Mo["K"] + Mo["k"], 0, 0]).dot(ring) + sp.Matrix([l_x, l_y, l_z]).dot(cas)
          + (sp.Matrix([m_x, m_y, m_z]) + G).dot(rot) + Mo["L"] * vr[1] + Mo["M"] * vr[2])
    return [sp.expand(sp.diff(dW, v)) for v in vr]


def rigorous_equations(ad=alpha_d, bd=beta_d, Hnow=Hs, Hdot=H_d):
    """(13) as printed, each 'left - right'."""
    Mo = moments(ad, bd, Hnow)
    wc = casing_rate((ad, bd))
    return [wc[1] * Hnow - (m_x + l_x + (Mo["K"] + Mo["k"]) / sp.cos(beta) - (Mo["M"] - l_z) * sp.tan(beta)),
            -wc[0] * Hnow - (m_y + l_y + Mo["L"]),
            Hdot - (m_z + Mo["M"])]


def linear_system(equations, unknowns):
    """(A, b) of equations linear in the unknowns (the rates), A rates = b: emitted as they
    are (the friction moments carry the rates, so A is not diagonal), solved at run time
    like the mass-matrix form of the full level."""
    A, b = sp.linear_eq_to_matrix(equations, unknowns)
    return A, b


def _solve(equations, unknowns):
    A, b = linear_system(equations, unknowns)
    return A.LUsolve(b)


def rigorous_rates():
    """alpha', beta', H' from (13) (linear in them: the friction moments carry the rates)."""
    return _solve(rigorous_equations(), [alpha_d, beta_d, H_d])


# the image point and the angles: x = tan(beta)/cos(alpha), y = -tan(alpha)
ALPHA_OF = -sp.atan(y)
BETA_OF = sp.atan(x / sp.sqrt(1 + y**2))
RHO = sp.sqrt(1 + x**2 + y**2)  # (23)
_RY = sp.sqrt(1 + y**2)
# the angles' functions as algebraic functions of the image point (no nested radicals):
# c'' = cos(alpha) cos(beta) = 1/rho, c = sin(beta) = x/rho, c' = -sin(alpha) cos(beta) = y/rho
TRIG_OF_IMAGE = {sp.sin(alpha): -y / _RY, sp.cos(alpha): 1 / _RY,
                 sp.sin(beta): x / RHO, sp.cos(beta): _RY / RHO, sp.tan(beta): x / _RY}


def in_image(expr):
    """An expression of alpha, beta written in x, y."""
    return sp.sympify(expr).subs(TRIG_OF_IMAGE)


def image_of(a=alpha, b=beta):
    """(22): x = rho c, y = rho c' with rho = 1/c'' (the point where z' meets z = 1)."""
    c = TABLE[:, 2].subs({alpha: a, beta: b})
    return c[0] / c[2], c[1] / c[2]


def velocity_of_point(xd=x_d, yd=y_d):
    """(1): v = d/dt (x, y, 1) + omega x (x, y, 1), omega = u (the frame xyz is the base)."""
    r = sp.Matrix([x, y, 1])
    return sp.Matrix([xd, yd, 0]) + mech.cross(u, r)


def _angle_rates(xd, yd):
    return (sp.diff(ALPHA_OF, x) * xd + sp.diff(ALPHA_OF, y) * yd,
            sp.diff(BETA_OF, x) * xd + sp.diff(BETA_OF, y) * yd)


def body_moments():
    return sp.Matrix([m_x + l_x, m_y + l_y, m_z + l_z])


def image_equations(rho=None, rho_d=None, xd=x_d, yd=y_d, Hnow=Hs, Hdot=H_d):
    """(21) and the third of (13), each 'left - right', in x, y, H with the cosines of (17)
    and the angles as functions of x, y. rho and rho' are the given symbols (default: (23)
    and its derivative), so that rho = 1, rho' = 0 can be set."""
    rho = RHO if rho is None else rho
    ad, bd = _angle_rates(xd, yd)
    if rho_d is None:
        rho_d = sp.diff(RHO, x) * xd + sp.diff(RHO, y) * yd
    T = TABLE.applyfunc(in_image)
    Mo = {k: in_image(v) for k, v in moments(ad, bd, Hnow).items()}
    S = in_image((Mo["K"] + Mo["k"]) / sp.cos(beta) - (Mo["M"] - l_z) * sp.tan(beta))
    Mxyz = T * body_moments()  # (20)
    v = velocity_of_point(xd, yd)
    Mz_body = m_z + l_z
    eqs = [Hnow * v[i] / rho - (Mxyz[i] + T[i, 0] * S + T[i, 1] * Mo["L"] + T[i, 2] * (Hnow * rho_d / rho - Mz_body))
           for i in range(2)]
    return eqs + [Hdot - (m_z + Mo["M"])]


def image_rates():
    return _solve(image_equations(), [x_d, y_d, H_d])


def small_equations(xd=x_d, yd=y_d, Hnow=Hs, Hdot=H_d):
    """(28): (21) with rho = 1, rho' = 0, c = x, c' = y (24), and m_z' + l_z' replaced by
    m_z + l_z (27); the cosines a, b, a', b' and sec, tan of beta kept as functions of the
    angles, as the paper keeps them."""
    ad, bd = _angle_rates(xd, yd)
    T = TABLE.applyfunc(in_image)
    Mo = {k: in_image(v) for k, v in moments(ad, bd, Hnow).items()}
    S = in_image((Mo["K"] + Mo["k"]) / sp.cos(beta) - (Mo["M"] - l_z) * sp.tan(beta))
    Mxyz = T * body_moments()
    v = velocity_of_point(xd, yd)
    pt = (x, y)
    return [Hnow * v[i] - (Mxyz[i] - pt[i] * Mxyz[2] + T[i, 0] * S + T[i, 1] * Mo["L"]) for i in range(2)] + [
        Hdot - (m_z + Mo["M"])]


def small_rates():
    return _solve(small_equations(), [x_d, y_d, H_d])


def elementary_equations(xd=x_d, yd=y_d, Hnow=Hs, Hdot=H_d):
    """(30): H v_x = m_x + l_x, H v_y = m_y + l_y (moments on rotor and casing about the
    axes x, y, (20)), and H constant."""
    T = TABLE.applyfunc(in_image)
    Mxyz = T * body_moments()
    v = velocity_of_point(xd, yd)
    return [Hnow * v[0] - Mxyz[0], Hnow * v[1] - Mxyz[1], Hdot]


def elementary_rates():
    return _solve(elementary_equations(), [x_d, y_d, H_d])


CONDITIONS_29 = {f_alpha: 0, f_beta: 0, f_phi: 0, Mmotor: 0, k_xi1: 0, m_z: 0, l_z: 0}


def quantities():
    angles, image, mom = ("angles", [alpha, beta]), ("image", [x, y]), ("momentum", [Hs])
    systems = {"rigorous": (rigorous_equations, [alpha_d, beta_d, H_d], angles, "(13)"),
               "virtual_power": (virtual_power_equations, [alpha_d, beta_d, H_d], angles,
                                 "(12), rows the generalised forces on alpha, beta, phi (the rows of the "
                                 "full level's equations)"),
               "image": (image_equations, [x_d, y_d, H_d], image, "(21) with the third of (13)"),
               "small": (small_equations, [x_d, y_d, H_d], image, "(28) with the third of (13)"),
               "elementary": (elementary_equations, [x_d, y_d, H_d], image, "(30), H' = 0")}
    out = {}
    for level, (eqs, unknowns, state, where) in systems.items():
        A, b = linear_system(eqs(), unknowns)
        out[f"{level}_system"] = (["params", state, mom], [("A", A), ("b", b)],
                                  f"Level '{level}': {where} as A r = b in the rates r = "
                                  f"({', '.join(map(str, unknowns))}).")
    return {**out,
        "image_point": (["params", angles], [("xy", sp.Matrix(image_of()))],
                        "The image point (22): x = tan(beta)/cos(alpha), y = -tan(alpha)."),
        "angles_of_image": (["params", image], [("angles", sp.Matrix([ALPHA_OF, BETA_OF]))],
                            "alpha = -atan(y), beta = atan(x/sqrt(1 + y^2)): the angles of an image point."),
        "rotor_momentum": (["params", "q", "qd"], [("H", sp.Matrix([A3 * rotor_rate()[2]]))],
                           "H = A3 (phi' + omega_z') along a motion of the full level."),
        "spin_from_momentum": (["params", angles, ("rates", [alpha_d, beta_d]), mom],
                               [("phi_d", sp.Matrix([Hs / A3 - casing_rate()[2]]))],
                               "phi' = H/A3 - omega_z': the full level's spin rate from the momentum."),
    }


# seconds per set for a 10 s horizon, 201 points, with the bound (bench/precession.py
# --costs, bench/results/precession.json "costs": the median CPU time of the evaluator). The
# four precession levels measured 32-35 ms (the enclosure's constants over the steps and the
# tube in interval arithmetic by the compiled walker, gyro/csrc/intervals.c, with the
# residuals' second-order Taylor form, 22-25 ms without it; 142-195 ms by the NumPy walker with
# the first-order forms, without a compiler): each is declared at their common median, so that
# the declared order, simplest first, breaks the tie; full measured 0.41-0.46 s (the answer and
# the bound's two runs).
PRECESSION_COST = 0.034
COSTS = {"elementary": PRECESSION_COST, "small": PRECESSION_COST, "rigorous": PRECESSION_COST,
         "image": PRECESSION_COST, "full": 0.412}
NEGLECTS = {
    "full": "nothing of the three bodies' Lagrange equations (the integrator's truncation)",
    "rigorous": "the rings' momenta and the rotor's transverse momentum: H along z' only (6)",
    "image": "the same as rigorous: (21) is (13) written in the image point",
    "small": "squares and products of x, y: rho = 1, rho' = 0, c = x, c' = y, m_z' + l_z' = m_z + l_z (24)-(27)",
    "elementary": "all of (29): friction in the axes, the outer ring's imbalance, moments about the spin "
                  "axis (H constant), and x, y small",
}


def levels():
    """The five levels (docs/precession.md): each answers the motion of the image point over
    a horizon, its bound the level's own along its motion (gyro.systems.gimbal_precession: an
    enclosure of the neglected terms from the full equations, docs/precession.md, and the
    integrator's), edges the singular casing angle."""
    from derive.model import Bound, Level

    valid = {"|beta0| < 90 deg (13) regular": sp.cos(beta0) - sp.Rational(1, 1000),
             "|alpha0| < 90 deg (the image point in the plane)": sp.cos(alpha0) - sp.Rational(1, 1000)}
    # the precession is the slow motion only while the base turns slowly against the nutation,
    # whose frequency is at least H |cos beta|/J (J every moment besides the rotor's momentum):
    # an a-priori edge; the enclosure itself refuses where its tube does not close
    J = C1 + C2 + C3 + B1 + B2 + B3 + 2 * A1 + A3
    slow = {**valid, "|u| J/(H cos beta0) < 1/10 (the base slow against the nutation)":
            H * sp.Abs(sp.cos(beta0)) / 10 - sp.sqrt(u_xi**2 + u_eta**2 + u_zeta**2) * J}
    out = []
    for name in ("elementary", "small", "rigorous", "image", "full"):
        out.append(Level(name, NEGLECTS[name],
                         {"kind": "trajectory", "module": "gyro.systems.gimbal_precession", "method": name, "quantities": ["x", "y"],
                          "scale": "excursion"},
                         {"motion": Bound(estimate=True)}, valid=valid if name == "full" else slow, cost=COSTS[name],
                         reference=None if name == "full" else "full",
                         doc=f"level '{name}' of the precession hierarchy"))
    return out


def build():
    from derive.model import Model

    return Model(
        name=NAME, title=TITLE, source=SOURCE, module=__name__,
        parameters=PARAMETERS, coordinates=COORDINATES, coordinate_units=COORDINATE_UNITS,
        q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=kinetic_energy(),
        dissipation=dissipation(),
        loads=loads(),
        generalized_forces={"phi": Mmotor},
        steady={"phi": H / A3},
        identities={"kinematics (3)-(5) are the frames' angular velocities": kinematics_are_the_papers},
        quantities=quantities(),
        simulate={"module": "gyro.systems.gimbal_precession", "options": ["level", "base_rate"],
                  "usage": "--level full, rigorous, image, small or elementary (required); --base-rate "
                           "NAME=AMP:FREQ[:PHASE] (NAME xi, eta or zeta)"},
        levels=levels(),
        aliases=CLI_NAMES,
        signals=BASE_RATE,
    )
