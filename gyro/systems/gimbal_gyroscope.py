"""Heavy gyroscope in a gimbal (Avdonin 1969, seed 000): the closed form of section 2,
the motion types of section 6, and integration of the generated equations (1.1).

Equation numbers are the paper's. With C0 = 0 the energy integral (1.2) gives (2.2),

    A0 B0 theta'^2 = f(theta) = b0 + 2 A0 P1 eta20 (sin theta0 - sin theta)
                     + 2 A0 (G - H psi0') (cos theta0 - cos theta) - H^2 (cos theta0 - cos theta)^2,

and with s = tan((theta - theta0)/2) = 1/x and tau = (t - t0) / (2 sqrt(A0 B0)),

    (ds/dtau)^2 = b0 + 4 b1 s + 6 b2 s^2 + 4 b3 s^3 + b4 s^4.

Its solution with s(0) = 0 is (2.6):

    s = 2 (b0 wp + b0 b2 - b1^2) / (+-sqrt(b0) wp' - 2 b1 wp - b0 b3 + b1 b2),

wp = wp(tau; g2, g3), minus sign when theta increases at t0; (2.7) is its limit b0 -> 0,
s = 2 b1 / (2 wp - b2). Multiplying (2.6) by its conjugate gives the same s as

    s = (-+sqrt(b0) wp' + 2 b1 wp + b0 b3 - b1 b2) / (2 (wp - b2/2)^2 - b0 b4 / 2),

(the conjugate form, Weierstrass's own). Each form is 0/0 at isolated instants where the
other is regular; the evaluation takes, point by point, the form whose numerator and
denominator are larger. theta follows s continuously: the arctangent gets +-pi at every
instant where s passes through infinity, found once per parameter set from
wp = b2/2 +- sqrt(b0 b4)/2, and theta gains 2 pi times their net sign over each real
period 2 omega of wp (zero for an oscillation, +-2 pi for a monotone rotation).

wp and wp' come from the roots e1, e2, e3 of F(z) = 4 z^3 - g2 z - g3 (6.1) through Jacobi's
sn, cn, dn. The scalar set-up (the b's, g2, g3, the roots, the modulus m and 1 - m, the
crossing instants) runs in mpmath at 40 digits, so that near a multiple root (the
separatrix, where the period grows without bound) 1 - m keeps its digits; the evaluation
over time is vectorised NumPy (an AGM for sn, cn, dn that takes 1 - m as given).
psi and phi follow by quadrature of (2.1), (2.3) (Gauss-Legendre panels over one period).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import mpmath as mp
import numpy as np

from gyro import ode
from gyro.models import ParameterError, load

MODEL = "gimbal_gyroscope"
PARAMS = ("A0", "B0", "C0", "A3", "P1", "eta20", "eta30", "P", "l")
INITIAL = {  # extra parameters of a motion: the initial conditions at t = 0
    "theta0": ("rad", 1.2, "nutation angle at t = 0"),
    "dtheta0": ("rad/s", 0.0, "nutation rate theta' at t = 0"),
    "dpsi0": ("rad/s", 1.0, "precession rate psi' at t = 0"),
    "dphi0": ("rad/s", 200.0, "spin rate phi' (relative to the casing) at t = 0"),
}
_DPS = 40


class ClosedFormError(ParameterError):
    """The closed form does not apply to these parameters (C0 != 0): bad input, one line."""


def param_vector(p: dict) -> np.ndarray:
    return np.array([float(p[n]) for n in PARAMS])


def integrals(p: dict, q, qd) -> dict:
    """The first integrals (1.2) along states q = (psi, theta, phi), qd (last axis 3):
    H = A3 (phi' + psi' cos theta), L = dT/dpsi', and M = 2 (T - U) - H^2/A3, which is the
    printed A0 psi'^2 + B0 theta'^2 + 2 P1 eta20 sin theta + 2 G cos theta at C0 = 0 and
    stays an integral for any C0 (the generated `first_integrals`)."""
    v = load(MODEL).numpy.first_integrals(param_vector(p), np.asarray(q, float), np.asarray(qd, float))
    return {"H": v[..., 0], "L": v[..., 1], "M": v[..., 2]}


def _routh(p: dict, theta, H, L) -> np.ndarray:
    """Routh's U1(theta) (3.3) and its first and second derivatives (the generated
    `routh_function`), last axis 3."""
    theta = np.asarray(theta, float)
    return load(MODEL).numpy.routh_function(param_vector(p), theta[..., None],
                                            np.broadcast_to([H, L], theta.shape + (2,)))


def _gravity_moment(p: dict) -> float:
    """G = P1 eta30 + P l (1.1), the generated `gravity_moment`."""
    return float(load(MODEL).numpy.gravity_moment(param_vector(p))[0])


def _agm(u, m: float, m1: float):
    """sn, cn, dn(u | m) by the arithmetic-geometric mean (A&S 16.4), m1 = 1 - m given."""
    a, b, c = 1.0, math.sqrt(m1), math.sqrt(m)
    an, cn_ = [a], [c]
    while abs(c) > 1e-17 * a and len(an) < 40:
        a, b, c = (a + b) / 2, math.sqrt(a * b), (a - b) / 2
        an.append(a)
        cn_.append(c)
    n = len(an) - 1
    phi = (2.0**n * an[n]) * u
    for k in range(n, 0, -1):
        phi = (phi + np.arcsin(cn_[k] / an[k] * np.sin(phi))) / 2
    sn, cn = np.sin(phi), np.cos(phi)
    return sn, cn, np.sqrt(m1 + m * cn * cn)


def jacobi(u, m: float, m1: float, K: float | None = None):
    """sn, cn, dn(u | m) for real u, 0 <= m <= 1, with m1 = 1 - m given separately (so that
    m close to 1 keeps its digits); vectorised. With the quarter period K given, points
    within K/2 of K or 3K use sn(K - v) = cd v, cn(K - v) = sqrt(m1) sd v, dn(K - v) =
    sqrt(m1) nd v: there cn and dn are small, and the AGM's cos(am u) would leave them only
    absolute accuracy (relative 1e-7 at 1 - m = 1e-18)."""
    u = np.asarray(u, float)
    if m1 == 0.0:
        t = np.tanh(u)
        s = 1.0 / np.cosh(u)
        return t, s, s
    sn, cn, dn = _agm(u, m, m1)
    if K is None:
        return sn, cn, dn
    w = np.mod(u, 4 * K)
    for centre, sign in ((K, 1.0), (3 * K, -1.0)):
        near = np.abs(w - centre) < K / 2
        if np.any(near):
            s, c, d = _agm(centre - w[near], m, m1)
            r = math.sqrt(m1)
            sn[near], cn[near], dn[near] = sign * c / d, sign * r * s / d, r / d
    return sn, cn, dn


@dataclass(frozen=True)
class Weierstrass:
    """wp(tau; g2, g3) and wp'(tau) on the real axis for real invariants, from the roots of
    F(z) = 4 z^3 - g2 z - g3 (6.1); built in mpmath, evaluated in NumPy."""

    g2: mp.mpf
    g3: mp.mpf

    @cached_property
    def roots(self):
        """(e_top, kind, e's): the real roots in descending order, or for one real root
        that root and the complex pair."""
        r = mp.polyroots([4, 0, -self.g2, -self.g3], maxsteps=200, extraprec=200)
        disc = self.g2**3 - 27 * self.g3**2
        if disc >= 0:
            e = sorted((mp.re(x) for x in r), reverse=True)
            return e[0], "real", e
        # the real root is the isolated one (near a double root the pair is almost real too)
        i = max(range(3), key=lambda k: min(abs(r[k] - r[j]) for j in range(3) if j != k))
        e2, others = r[i], [r[j] for j in range(3) if j != i]
        return mp.re(e2), "complex", [mp.re(e2), *others]

    @cached_property
    def setup(self):
        """kind, scale, m, m1 and the half-period omega (real, in tau)."""
        e_top, kind, e = self.roots
        if kind == "real":
            e1, e2, e3 = e
            lam2 = e1 - e3
            if lam2 == 0:  # triple root 0: wp = 1/tau^2
                return "rational", mp.mpf(0), mp.mpf(0), mp.mpf(1), mp.inf
            lam = mp.sqrt(lam2)
            m, m1 = (e2 - e3) / lam2, (e1 - e2) / lam2
            return kind, lam, m, m1, mp.ellipk(m) / lam if m1 > 0 else mp.inf
        e2, e1 = e[0], e[1]
        H2 = abs(e2 - e1)
        m1 = (2 * H2 + 3 * e2) / (4 * H2)
        m = 1 - m1
        nu = 2 * mp.sqrt(H2)
        return kind, nu, m, m1, 2 * mp.ellipk(m) / nu if m1 > 0 else mp.inf

    @property
    def omega(self):
        return self.setup[4]

    @property
    def e_top(self):
        return self.roots[0]

    def __call__(self, tau):
        """(wp, wp') at real tau (NumPy arrays; tau = 0 mod 2 omega gives inf)."""
        kind, scale, m, m1, _ = self.setup
        tau = np.asarray(tau, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            if kind == "rational":
                return 1 / tau**2, -2 / tau**3
            sn, cn, dn = jacobi(float(scale) * tau, float(m), max(float(m1), 1e-300), float(mp.ellipk(m)))
            if kind == "real":
                lam, e3 = float(scale), float(self.roots[2][2])
                return e3 + lam**2 / sn**2, -2 * lam**3 * cn * dn / sn**3
            H2 = float(scale) ** 2 / 4
            e2 = float(self.roots[0])
            omc = np.where(cn > 0, sn * sn / (1 + cn), 1 - cn)  # 1 - cn without cancellation
            return e2 + H2 * (2 - omc) / omc, -4 * H2**1.5 * sn * dn / omc**2

    def inverse(self, z):
        """The tau in [0, omega] with wp(tau) = z, for real z >= e_top (mpmath)."""
        kind, scale, m, _, _ = self.setup
        if kind == "rational":
            return 1 / mp.sqrt(z)
        if kind == "real":
            e3 = self.roots[2][2]
            return mp.ellipf(mp.asin(min(mp.sqrt(scale**2 / (z - e3)), 1)), m) / scale  # z = e1 may round over
        e2, H2 = self.roots[0], scale**2 / 4
        return mp.ellipf(mp.acos(max(min((z - e2 - H2) / (z - e2 + H2), 1), -1)), m) / scale


# ------------------------------------------------------------------ the closed form


@dataclass(frozen=True)
class Motion:
    """A motion of the gimbal gyroscope: parameters and initial conditions at t = 0."""

    params: dict
    theta0: float
    dtheta0: float
    dpsi0: float
    dphi0: float

    @property
    def q0(self):
        return np.array([0.0, self.theta0, 0.0])

    @property
    def qd0(self):
        return np.array([self.dpsi0, self.dtheta0, self.dphi0])

    @property
    def integrals0(self) -> dict:
        return {k: float(v) for k, v in integrals(self.params, self.q0, self.qd0).items()}


class ClosedForm:
    """theta(t) by (2.6), or (2.7) when b0 = 0; psi(t), phi(t) by quadrature of (2.1), (2.3).
    Needs C0 = 0."""

    GL_NODES = 16

    def __init__(self, motion: Motion):
        p = motion.params
        if p["C0"] != 0:
            raise ClosedFormError(f"the closed form (2.6) needs C0 = 0, got C0 = {p['C0']!r}; "
                                  "use an integrator (--method DOP853, cvodes, ...)")
        self.motion = motion
        with mp.workdps(_DPS):
            self._setup_mp()

    # ---------------------------------------------------------- set-up (mpmath)

    def _setup_mp(self):
        mo = self.motion
        # b0..b4, g2, g3, H, L at 40 digits from the generated mpmath `closed_form`
        b, g, HL = load(MODEL).mpmath.closed_form(list(param_vector(mo.params)),
                                                  [mo.theta0, mo.dtheta0, mo.dpsi0, mo.dphi0])
        b0, b1, b2, b3, b4 = (b[k] for k in range(5))
        self.b_mp = (b0, b1, b2, b3, b4)
        self.b = tuple(float(x) for x in self.b_mp)
        self.g2_mp, self.g3_mp = g[0], g[1]
        self.g2, self.g3 = float(self.g2_mp), float(self.g3_mp)
        self.H, self.L = float(HL[0]), float(HL[1])
        self.time_scale = 2 * math.sqrt(mo.params["A0"] * mo.params["B0"])  # t = time_scale * tau
        # sign of the radical in (2.6): minus when theta increases at t0
        self.sign = -1.0 if mo.dtheta0 > 0 else 1.0
        self.stationary = b0 == 0 and b1 == 0
        self.wp = Weierstrass(self.g2_mp, self.g3_mp)
        if self.stationary:
            self.omega, self.crossings, self.jumps = math.inf, np.array([]), np.array([], int)
            return
        omega = self.wp.omega
        self.omega = float(omega)
        self.m1 = float(self.wp.setup[3])
        crossings = []
        F = lambda z: 4 * z**3 - self.g2_mp * z - self.g3_mp  # noqa: E731
        cands = {b2 / 2} if b0 * b4 == 0 else ({b2 / 2 + mp.sqrt(b0 * b4) / 2, b2 / 2 - mp.sqrt(b0 * b4) / 2}
                                               if b0 * b4 > 0 else set())
        for z in cands:
            if z < self.wp.e_top:
                continue
            t1 = self.wp.inverse(z)
            wpd = mp.sqrt(max(F(z), 0))
            # z = e_top: the one instant tau = omega (a crossing there, as in a uniform
            # rotation, or a tangency, where theta just reaches theta0 +- pi and jump is 0)
            pair = [(t1, -wpd)] if omega - t1 <= mp.mpf(10) ** (-_DPS // 2) * omega else \
                [(t1, -wpd), (2 * omega - t1, wpd)]
            for tc, w in pair:
                j = self._jump_mp(z, w)
                if j and tc < 2 * omega:
                    crossings.append((tc, j))
        crossings.sort()
        self.crossings = np.array([float(c) for c, _ in crossings])
        self.jumps = np.array([j for _, j in crossings], int)
        self.net_turns = int(self.jumps.sum())  # theta gains 2 pi net_turns per period

    def _pairs(self, P, W, xp=np):
        """(Np, Dp) of (2.6) and (Nw, Dw) of the conjugate form at wp = P, wp' = W."""
        b0, b1, b2, b3, b4 = self.b_mp if xp is mp else self.b
        r = mp.sqrt(b0) if xp is mp else math.sqrt(b0)
        Np = 2 * (b0 * P + b0 * b2 - b1**2)
        Dp = self.sign * r * W - 2 * b1 * P - b0 * b3 + b1 * b2
        Nw = self.sign * r * W + 2 * b1 * P + b0 * b3 - b1 * b2
        Dw = 2 * (P - b2 / 2) ** 2 - b0 * b4 / 2
        return Np, Dp, Nw, Dw

    def _jump_mp(self, z, w):
        """+1 / -1 when s passes through infinity with theta increasing / decreasing at the
        instant where wp = z, wp' = w; 0 when s stays finite there."""
        Np, Dp, Nw, Dw = self._pairs(z, w, xp=mp)
        N, D = (Np, Dp) if mp.hypot(Np, Dp) >= mp.hypot(Nw, Dw) else (Nw, Dw)
        if abs(D) > mp.mpf(10) ** (-_DPS // 2) * abs(N):
            return 0
        b0, b1, b2 = self.b_mp[:3]
        wpp = 6 * z**2 - self.g2_mp / 2
        terms = ([self.sign * mp.sqrt(b0) * wpp, -2 * b1 * w] if N is Np else [4 * (z - b2 / 2) * w])
        dD = sum(terms)
        # x = 1/s = D/N passes through 0 and theta' ~ -2 x'; x' = 0 (to the working precision
        # against its terms) is a tangency: theta touches theta0 +- pi and turns, no jump
        if abs(dD) <= mp.mpf(10) ** (-_DPS // 2) * sum(abs(x) for x in terms):
            return 0
        return -1 if dD / N > 0 else 1

    # ---------------------------------------------------------- evaluation (NumPy)

    def s_of_tau(self, tau):
        """s = tan((theta - theta0)/2) by (2.6) (b0 > 0) or (2.7) (b0 = 0), tau in (0, 2 omega)."""
        P, W = self.wp(tau)
        with np.errstate(all="ignore"):
            if self.b[0] == 0:
                s = 2 * self.b[1] / (2 * P - self.b[2])  # (2.7)
            else:
                Np, Dp, Nw, Dw = self._pairs(P, W)
                use_p = np.hypot(Np, Dp) >= np.hypot(Nw, Dw)
                s = np.where(use_p, Np / Dp, Nw / Dw)  # (2.6) or its conjugate form
        return np.where(np.isfinite(P), s, 0.0)  # at tau = 0 mod 2 omega, theta = theta0

    def _reduce(self, tau):
        if not math.isfinite(self.omega):
            return np.zeros_like(tau), tau
        k = np.floor(tau / (2 * self.omega))
        if np.any(np.abs(k) > 2.0**52):  # past 4.5e15 periods no digit of the phase is left
            raise ArithmeticError(f"t reaches {np.max(np.abs(k)):.3g} periods of theta: the phase "
                                  "within a period has no digit left in double precision")
        return k, tau - k * (2 * self.omega)

    def theta_tau(self, tau):
        tau = np.asarray(tau, float)
        th0 = self.motion.theta0
        if self.stationary:
            return np.full(tau.shape, th0)
        k, tr = self._reduce(tau)
        s = self.s_of_tau(tr)
        cum = np.concatenate([[0], np.cumsum(self.jumps)])
        j = cum[np.searchsorted(self.crossings, tr, side="right")]
        return th0 + 2 * np.arctan(s) + 2 * np.pi * (j + k * self.net_turns)

    def theta(self, t):
        """theta(t), vectorised over t (seconds from t0 = 0)."""
        return self.theta_tau(np.asarray(t, float) / self.time_scale)

    @property
    def period(self) -> float:
        """Real period of wp in t: the period of theta (oscillation or rotation); inf on the
        separatrix and for a stationary motion."""
        return 2 * self.omega * self.time_scale

    # ---------------------------------------------------------- psi, phi by quadrature

    @cached_property
    def _panels(self):
        """Cumulative integrals of cos(theta) and cos^2(theta) over tau at the panel edges
        of one period, panels doubled until the period's integrals agree to 1e-15."""
        x, w = np.polynomial.legendre.leggauss(self.GL_NODES)
        span = 2 * self.omega
        n, prev = 16, None
        while True:
            h = span / n
            nodes = (np.arange(n)[:, None] + (x[None, :] + 1) / 2) * h
            c = np.cos(self.theta_tau(nodes))
            per = np.stack([c @ w, (c * c) @ w], axis=-1) * h / 2  # panels x 2
            tot = per.sum(axis=0)
            if prev is not None and np.all(np.abs(tot - prev) <= 1e-15 * span) or n >= 2**16:
                break
            prev, n = tot, 2 * n
        return h, np.concatenate([np.zeros((1, 2)), np.cumsum(per, axis=0)]), tot

    def _cos_integrals(self, tau):
        """int_0^tau cos(theta), int_0^tau cos^2(theta) d tau (arrays tau.shape + (2,))."""
        tau = np.asarray(tau, float)
        if self.stationary:
            c = math.cos(self.motion.theta0)
            return np.stack([c * tau, c * c * tau], axis=-1)
        h, cum, tot = self._panels
        k, tr = self._reduce(tau)
        j = np.clip(np.floor(tr / h), 0, len(cum) - 2)  # tr may round to just outside [0, 2 omega)
        left = j * h
        x, w = np.polynomial.legendre.leggauss(self.GL_NODES)
        nodes = left[..., None] + (tr - left)[..., None] * (x + 1) / 2
        c = np.cos(self.theta_tau(nodes))
        part = np.stack([c @ w, (c * c) @ w], axis=-1) * ((tr - left) / 2)[..., None]
        return cum[j.astype(int)] + part + k[..., None] * tot

    def psi_phi(self, t):
        """psi(t), phi(t) with psi(0) = phi(0) = 0: (2.1) psi' = (L - H cos theta)/A0 and
        (2.3) phi' = H/A3 - psi' cos theta, integrated."""
        t = np.asarray(t, float)
        p = self.motion.params
        I = self._cos_integrals(t / self.time_scale) * self.time_scale
        psi = (self.L * t - self.H * I[..., 0]) / p["A0"]
        phi = self.H / p["A3"] * t - (self.L * I[..., 0] - self.H * I[..., 1]) / p["A0"]
        return psi, phi

    # ---------------------------------------------------------- section 6

    @property
    def motion_type(self) -> str:
        """stationary, asymptotic, monotone or periodic (section 6), decided to 1e-12
        relative: stationary when theta0 is a double root of f (theta0' = 0, so b0 = 0,
        and b1 below 1e-12 of the largest b: the rounding of psi0' from (3.1)), asymptotic when e is a multiple root of F (relative discriminant below
        1e-12: the input's rounding of 1e-16 leaves a double root split by up to ~1e-8
        relative, as at a turning point computed on the separatrix)."""
        B = max(abs(x) for x in self.b)
        if self.stationary or (self.b[0] == 0 and abs(self.b[1]) <= 1e-12 * B):
            return "stationary"
        disc = self.g2_mp**3 - 27 * self.g3_mp**2
        if abs(disc) <= 1e-12 * (abs(self.g2_mp) ** 3 + 27 * self.g3_mp**2) and self._top_is_multiple():
            return "asymptotic"
        return "monotone" if self.net_turns else "periodic"

    def _top_is_multiple(self) -> bool:
        """The largest real root e is the multiple one (not the two lower ones)."""
        e_top, kind, e = self.wp.roots
        if kind == "complex":
            return mp.re(e[1]) > e_top
        return e[0] - e[1] <= e[1] - e[2]


# ------------------------------------------------------------------ section 6: cases by F(z)


def section6_case(b1: float, b2: float, b3: float, b4: float) -> dict:
    """For b0 = 0: the largest real root e of F(z) (6.1) and the paper's statement of its
    relation to b2/2, case 1 (b4 < 0), 2 (b4 = 0, with the roots z1, z2, z3), 3 (b4 > 0)."""
    g2 = -4 * b1 * b3 + 3 * b2**2
    g3 = -b1**2 * b4 - b2**3 + 2 * b1 * b2 * b3
    roots = np.roots([4.0, 0.0, -g2, -g3])
    e = float(max(r.real for r in roots if abs(r.imag) <= 1e-9 * (1 + abs(r))))
    out = {"g2": g2, "g3": g3, "e": e, "F_half_b2": 4 * (b2 / 2) ** 3 - g2 * b2 / 2 - g3}
    if b4 < 0:
        out["case"] = 1
        out["paper_says"] = "b2/2 < e"
    elif b4 == 0:
        out["case"] = 2
        d6 = 9 * b2**2 - 16 * b1 * b3  # the Delta of section 6
        z1 = b2 / 2
        z2 = (-b2 + math.sqrt(d6)) / 4 if d6 >= 0 else math.nan
        out.update(z1=z1, z2=z2, Delta6=d6)
        if b2 >= 0:
            out["paper_e"] = z2 if b1 * b3 <= 0 else z1
        else:
            out["paper_e"] = z2 if d6 >= 0 else z1
    else:
        out["case"] = 3
        out["paper_says"] = "e < b2/2 iff one real root, or b1 b3 > 0 and b2 > 0 with three"
    return out


def theta1_property_a(b1: float, b2: float, e: float) -> float:
    """a): the far turning point theta1 - theta0 = 2 Arctg[2 b1 / (2 e - b2)], the Arctg
    taken along the motion from 0 (so past pi/2 when e < b2/2)."""
    x = math.atan(2 * b1 / (2 * e - b2))
    if 2 * e - b2 < 0:
        x += math.copysign(math.pi, b1)
    return 2 * x


def mean_drift_paper(motion: Motion, theta_a: float, theta_b: float) -> float:
    """<psi'> by the paper's integral (section 6) between the roots theta_a, theta_b of f
    that bound the motion: (1/A0) int (L - H cos) / sqrt(f) / int 1 / sqrt(f), f the
    radicand of (2.2) (tanh-sinh quadrature in mpmath, which takes the 1/sqrt ends)."""
    p, I = motion.params, motion.integrals0
    routh = load(MODEL).mpmath.routh_function
    P = list(param_vector(p))
    with mp.workdps(30):
        A0, H, L, M = (mp.mpf(x) for x in (p["A0"], I["H"], I["L"], I["M"]))

        def f(th):  # A0 B0 theta'^2 = A0 (M + 2 U1(theta)) from the integrals (1.2)
            return A0 * (M + 2 * routh(P, [th], [H, L])[0])

        # the roots to 30 digits: an end off by d costs ~sqrt(d) in the integrals
        lo, hi = sorted(mp.findroot(f, mp.mpf(x)) for x in (theta_a, theta_b))
        num = mp.quad(lambda th: (L - H * mp.cos(th)) / mp.sqrt(abs(f(th))), [lo, hi])
        den = mp.quad(lambda th: 1 / mp.sqrt(abs(f(th))), [lo, hi])
        return float(num / den / A0)


# ------------------------------------------------------------------ integrating (1.1)

SCIPY_METHODS = ode.SCIPY_METHODS
CASADI_METHODS = ("cvodes", "idas")
METHODS = ("closed_form", *SCIPY_METHODS, *CASADI_METHODS)


IntegrationBudget = ode.IntegrationBudget  # the one type (gyro/ode.py)


BUDGET_SECONDS = 25.0  # an integrator's wall time at the most (a command stays under 30 s)
BUDGET_STEPS = 2 * 10**6  # and its steps (right-hand sides for SciPy, internal steps for CasADi)


def integrate(motion: Motion, t, method: str = "DOP853", rtol: float = 1e-12, atol: float = 1e-12,
              budget_s: float | None = None, budget_steps: int = BUDGET_STEPS):
    """Integrate the generated equations (1.1) (any C0) in psi, theta, phi from the motion's
    initial state; returns (q, qd) at the times t (arrays len(t) x 3). A run that needs
    more than `budget_steps` steps, or more than `budget_s` seconds where one is given (the
    command line's BUDGET_SECONDS), stops with IntegrationBudget, saying how far it got.
    A library call has no wall-time budget: how long a run takes depends on the machine's
    load, how far it gets must not."""
    t = np.asarray(t, float)
    P = param_vector(motion.params)
    y0 = np.concatenate([motion.q0, motion.qd0])
    budget_s = math.inf if budget_s is None else budget_s
    if method not in SCIPY_METHODS + CASADI_METHODS:
        raise ParameterError(f"unknown method {method!r}; known: {' '.join(METHODS)}")
    Y = ode.integrate_state(load(MODEL), P, y0, t, method, rtol, atol, budget_s, budget_steps)
    return Y[:, :3], Y[:, 3:]


# ------------------------------------------------------------------ motions of section 3 and 6


def _rates(params: dict, theta: float, H: float, L: float) -> tuple[float, float]:
    """psi', phi' at theta from the integrals H, L (the generated `rates_from_momenta`)."""
    r = load(MODEL).numpy.rates_from_momenta(param_vector(params), [theta], [H, L])
    return float(r[0]), float(r[1])


def stationary_motion(params: dict, theta0: float, H: float) -> Motion:
    """The stationary motion (3.1)-(3.2) at theta0 with rotor momentum H: theta0' = 0,
    (G - H psi0') sin theta0 = P1 eta20 cos theta0 (the generated `stationary_precession`),
    phi0' from H = A3 (phi' + psi' cos)."""
    nf, P = load(MODEL).numpy, param_vector(params)
    dpsi = float(nf.stationary_precession(P, [theta0], [H])[0])
    # phi0' from the generated integral H, which is affine in phi'
    H0, H1 = (float(nf.first_integrals(P, [0.0, theta0, 0.0], [dpsi, 0.0, w])[0]) for w in (0.0, 1.0))
    return Motion(params, theta0, 0.0, dpsi, (H - H0) / (H1 - H0))


def U1_second(params: dict, theta0: float, H: float, L: float) -> float:
    """U1''(theta0) of Routh's function U1 = -P1 eta20 sin - G cos - (L - H cos)^2 / 2 A0 (3.3)."""
    return float(_routh(params, theta0, H, L)[..., 2])


def kick(motion: Motion, dtheta: float) -> Motion:
    """The same H and L with theta' = dtheta at t = 0 (a stationary motion kicked in theta)."""
    return Motion(motion.params, motion.theta0, dtheta, motion.dpsi0, motion.dphi0)


def turning_motion(motion: Motion, theta_t: float) -> Motion:
    """A motion with the integrals H, L of `motion` that starts at rest in theta at theta_t."""
    p, I = motion.params, motion.integrals0
    dpsi, dphi = _rates(p, theta_t, float(I["H"]), float(I["L"]))
    return Motion(p, theta_t, 0.0, dpsi, dphi)


def turning_points(motion: Motion, n: int = 4096) -> np.ndarray:
    """The roots of f(theta) = A0 B0 theta'^2 (2.2) in [theta0 - pi, theta0 + pi) at the
    motion's integrals (grid and bisection); empty for a rotation."""
    from scipy.optimize import brentq

    p, I = motion.params, motion.integrals0
    G = _gravity_moment(p)

    # A0 (M - A0 psi'^2 - 2 P1 eta20 sin - 2 G cos) with psi' from L, which is A0 (M + 2 U1):
    # kept in this order of operations, because section 6's asymptotic motion starts at the
    # far turning point of a separatrix and one ulp there decides its motion type
    # (tests/paper/test_gimbal_section6.py::test_asymptotic_type_property_e; docs/gimbal.md)
    def f(th):
        dpsi = (I["L"] - I["H"] * np.cos(th)) / p["A0"]
        return p["A0"] * (I["M"] - p["A0"] * dpsi**2 - 2 * p["P1"] * p["eta20"] * np.sin(th) - 2 * G * np.cos(th))

    th = motion.theta0 - np.pi + 2 * np.pi * np.arange(n + 1) / n
    v = f(th)
    idx = np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]
    return np.array([brentq(f, th[i], th[i + 1], xtol=1e-15) for i in idx])


# ------------------------------------------------------------------ a motion as a result


RTOL, ATOL = 1e-10, 1e-12  # the integrators' tolerances of `trajectory`


# the series of a motion: name, unit, description (the Euler angles of the module's doc)
SERIES = (("theta", "rad", "nutation: the casing's turn about its axis eta1 in the outer ring"),
          ("psi", "rad", "precession of the outer ring about the vertical xi3"),
          ("phi", "rad", "the rotor's spin about its symmetry axis eta3"))


def trajectory(motion: Motion, t, method: str = "closed_form"):
    """theta, psi, phi at the times t by the closed form or an integrator, as a
    gyro.results.Motion (with the integrals at t = 0 and, from the closed form, the motion
    type and the period of theta in its `info`)."""
    from gyro.results import Motion as MotionResult

    t = np.asarray(t, dtype=float)
    model = load(MODEL)
    kind = period = None
    if method == "closed_form":
        cf = ClosedForm(motion)
        psi, phi = cf.psi_phi(t)
        theta, kind, period = cf.theta(t), cf.motion_type, cf.period
    else:
        q, _ = integrate(motion, t, method, RTOL, ATOL, budget_s=BUDGET_SECONDS)
        theta, psi, phi = q[:, 1], q[:, 0], q[:, 2]
    I, title = motion.integrals0, model.meta["title"]
    heading = [f"{title} ({MODEL}), method {method}",
               f"integrals at t = 0: H = {I['H']:.9g}, L = {I['L']:.9g}, M = {I['M']:.9g}"]
    if kind is not None:
        shown = ("none (stationary or on the separatrix)" if not math.isfinite(period) else f"{period:.9g} s")
        heading.append(f"motion: {kind}; period of theta {shown}")
    names, units, descriptions = (list(c) for c in zip(*SERIES))
    return MotionResult(MODEL, title, method, t, names, np.stack([theta, psi, phi], axis=1), units, descriptions,
                  info={"integrals": I, "motion_type": kind, "period": period},
                  keys=["t", *names, "method", "integrals"], heading=heading,
                  formats={"t": ">14.6g", **{n: ">18.12g" for n in names}})


def motion_answer(motion: Motion, t, method: str = "closed_form", rtol: float = RTOL):
    """The `motion` question's evaluator (gyro/questions/motion.py, docs/hierarchy.md): the
    coordinates psi, theta, phi at the times t (times, 3) and an estimate of each one's
    largest absolute error over t (rad).

    Closed form: its rounding grows with the periods run and as 1 - m -> 0 near the
    separatrix, eps (16 (1 + n) + 4/sqrt(1 - m)) (measured, bench/results/gimbal.json:
    1.3e-15 over 100 periods, 1.8e-13 over 1e4, 1.1e-8 at 1 - m ~ 1e-18, each below it).
    An integrator: twice the difference to a second run at rtol/100 (the answer is the finer
    run), an estimate of the coarser run's global error that bounds the finer one's where
    the error falls with the tolerance (it does not near a separatrix: docs/gimbal.md)."""
    t = np.asarray(t, dtype=float)
    eps = np.finfo(float).eps
    if method == "closed_form":
        cf = ClosedForm(motion)
        psi, phi = cf.psi_phi(t)
        q = np.stack([psi, cf.theta(t), phi], axis=1)
        if cf.stationary:
            return q, np.full(3, 16 * eps * (1 + np.max(np.abs(q))))
        n = (t[-1] - t[0]) / cf.period if math.isfinite(cf.period) else math.inf
        est = eps * (16 * (1 + n) + 4 / math.sqrt(max(cf.m1, 1e-300)))
        return q, np.full(3, est * max(1.0, float(np.max(np.abs(q)))))

    return ode.two_tolerances(lambda r: integrate(motion, t, method, r, r * 1e-2, budget_s=BUDGET_SECONDS)[0], rtol)


# ------------------------------------------------------------------ gyro simulate

def simulate_command(model, args, cli):
    """`gyro simulate gimbal_gyroscope` (the model's `simulate` declaration): the parameters
    and the initial conditions INITIAL as --set NAME=VALUE, every input checked first; the
    closed form (2.6) by default, or an integrator of METHODS. Returns the Motion."""
    from gyro.models import Param

    ic = {n: Param(n, u, d, desc, "real", (None, None)) for n, (u, d, desc) in INITIAL.items()}
    sets = cli.sets(args.set)
    known = [*model.param_names, *model.aliases, *ic]
    for key in sets:
        if key not in known:
            raise ParameterError(f"unknown parameter {key!r} for {model.name}; known: {model.known_names()} "
                                 f"{' '.join(ic)}")
    values = model.parameters({k: v for k, v in sets.items() if k not in ic})
    init = {}
    for name, p in ic.items():
        raw = sets.get(name, p.default)
        try:
            init[name] = float(raw)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {name}: not a number: {raw!r}") from None
        p.check(init[name])
    t, method = cli.times(args), cli.method(args, METHODS, "closed_form")
    cli.png(args.out)
    tr = trajectory(Motion(values, init["theta0"], init["dtheta0"], init["dpsi0"], init["dphi0"]), t, method)
    if not (np.all(np.isfinite(tr.theta)) and np.all(np.isfinite(tr.psi)) and np.all(np.isfinite(tr.phi))):
        raise FloatingPointError("a coordinate is not finite")
    return tr
