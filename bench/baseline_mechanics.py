"""Baseline derivation of the torsion-gyrocompass operator with sympy.physics.mechanics.

What this is
------------
An independent, deliberately "ordinary" derivation of the linear operator

    J(p) = M p**2 + D p + K

of the 11-DOF gyrocompass on a torsion suspension (Bashirov 1983), written the
way a typical user of ``sympy.physics.mechanics`` would write it:

* reference frames, points and two rigid bodies (casing, rotor);
* the Lagrangian ``L = T - V_g - V_b`` with absolute velocities, the
  geographic frame N rotating with the Earth rate ``u = (0, u cos phi,
  u sin phi)`` relative to an inertial frame ``Nin``;
* ``LagrangesMethod`` -> ``form_lagranges_equations`` -> ``to_linearizer``
  -> ``Linearizer.linearize`` about the steady motion (all coordinates
  constant except the spin angle gamma3);
* elimination of the cyclic coordinate gamma3 with the linearised first
  integral ``delta(C r2) = 0``.

All parameters stay symbolic while the equations and the linearizer are
formed; numbers (parameters and operating point) are substituted only when
``Linearizer.linearize`` is called, because the library needs them there to
finish in reasonable time.

How the benchmark uses it
-------------------------
* ``derive_baseline()`` is the timed "derivation" step; it returns a
  ``BaselineSystem`` holding the linearizer and the symbols needed later.
* ``baseline_operator(params, q0)`` returns the numeric 10x10 ``M, D, K`` used
  to check the project's own (fast) derivation.  The first call also pays for
  the linearizer's Jacobians; later calls reuse them.
* ``run_with_timeout(seconds)`` (or ``python baseline_mechanics.py --timeout S``)
  runs derivation + one linearisation at the paper example in a fresh child
  process and reports "did not finish within S s" if the bound is hit.  The
  benchmark uses a 600 s bound.

Conventions
-----------
Reduced coordinates and equation order::

    q = (x1, x3, gamma, mu, x2, gamma1, gamma2, alpha, beta, lam)

and the equations are those of Lagrange, ``d/dt dL/dq' - dL/dq = 0``, so that
``M`` is symmetric positive definite and ``M q'' + D q' + K q = 0``.

Parameter keys (SI, ``phi`` in degrees):
``m M l l1 l2 A C I1 I2 I3 K0 Kp Kgamma H u phi g``.
Equilibrium keys: ``x2 x3 gamma2 beta lam`` (all other coordinates zero).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import sympy as sp
import sympy.physics.mechanics as me

# ---------------------------------------------------------------------------
# Names and the paper example
# ---------------------------------------------------------------------------

#: Parameter names accepted by :func:`baseline_operator`.
PARAM_NAMES = ("m", "M", "l", "l1", "l2", "A", "C", "I1", "I2", "I3",
               "K0", "Kp", "Kgamma", "H", "u", "phi", "g")

#: All 11 generalized coordinates, in the order given to LagrangesMethod.
COORD_NAMES_11 = ("x1", "x2", "x3", "gamma1", "gamma2", "gamma3",
                  "alpha", "beta", "gamma", "lam", "mu")

#: The 10 coordinates of the reduced operator, in output order.
COORD_NAMES_10 = ("x1", "x3", "gamma", "mu", "x2", "gamma1", "gamma2",
                  "alpha", "beta", "lam")

#: Coordinates that may be nonzero at the relative equilibrium.
EQUILIBRIUM_NAMES = ("x2", "x3", "gamma2", "beta", "lam")


def paper_params() -> dict:
    """Example parameter set of Bashirov (1983), SI units, phi in degrees."""
    m, A = 0.4, 1.2e-4
    return {
        "m": m, "M": 0.6, "l": 0.15, "l1": 0.15, "l2": 0.25,
        "A": A, "C": 1.8e-4, "I1": 1.05e-2, "I2": 1.07e-2, "I3": 3e-4,
        "K0": m * 450.0**2, "Kp": m * 780.0**2, "Kgamma": A * 560.0**2,
        "H": A * 3769.3, "u": 7.29e-5, "phi": 60.0, "g": 9.81,
    }


def approximate_equilibrium(params: dict) -> dict:
    """First-order estimate of the relative equilibrium (small quantities).

    beta0 = H u3 / (mc lc g + H u2),  gamma20 = H u3 / Kgamma,
    x20 = -m g beta0 / K0,  x30 = -m g / Kp,  lam0 = (l + lc) u2 u3 / g,
    with mc = m + M and lc = (m l2 + M l1) / mc.
    """
    p = params
    phi = math.radians(p["phi"])
    u2, u3 = p["u"] * math.cos(phi), p["u"] * math.sin(phi)
    mc = p["m"] + p["M"]
    lc = (p["m"] * p["l2"] + p["M"] * p["l1"]) / mc
    beta0 = p["H"] * u3 / (mc * lc * p["g"] + p["H"] * u2)
    return {
        "beta": beta0,
        "gamma2": p["H"] * u3 / p["Kgamma"],
        "x2": -p["m"] * p["g"] * beta0 / p["K0"],
        "x3": -p["m"] * p["g"] / p["Kp"],
        "lam": (p["l"] + lc) * u2 * u3 / p["g"],
    }


# ---------------------------------------------------------------------------
# Symbolic derivation
# ---------------------------------------------------------------------------

@dataclass
class BaselineSystem:
    """Everything produced by :func:`derive_baseline` and reused afterwards."""

    params: dict            # name -> sympy Symbol
    q: list                 # the 11 generalized coordinates (dynamicsymbols)
    qd: list                # their first time derivatives
    qdd: list               # their second time derivatives
    lagranges_method: me.LagrangesMethod
    linearizer: object      # sympy.physics.mechanics.linearize.Linearizer
    r2: sp.Expr             # absolute rotor angular velocity along the spin axis
    timings: dict = field(default_factory=dict)


def derive_baseline(progress=print) -> BaselineSystem:
    """Build the model with sympy.physics.mechanics and create the linearizer.

    ``progress`` receives short status strings (pass ``lambda s: None`` to
    silence it).  The returned object is reused by :func:`baseline_operator`.
    """
    timings = {}
    t0 = time.perf_counter()

    # Parameters (phi in radians here).
    m, M, l, l1, l2 = sp.symbols("m M l l1 l2", positive=True)
    A, C, I1, I2, I3 = sp.symbols("A C I1 I2 I3", positive=True)
    K0, Kp, Kgamma, H = sp.symbols("K0 Kp Kgamma H", positive=True)
    u, phi, g = sp.symbols("u phi g", positive=True)
    params = dict(m=m, M=M, l=l, l1=l1, l2=l2, A=A, C=C, I1=I1, I2=I2, I3=I3,
                  K0=K0, Kp=Kp, Kgamma=Kgamma, H=H, u=u, phi=phi, g=g)
    u2, u3 = u * sp.cos(phi), u * sp.sin(phi)

    # Generalized coordinates.
    x1, x2, x3, gamma1, gamma2, gamma3, alpha, beta, gamma, lam, mu = q = \
        me.dynamicsymbols(" ".join(COORD_NAMES_11))
    t = me.dynamicsymbols._t
    qd = [qi.diff(t) for qi in q]
    qdd = [qi.diff(t, 2) for qi in q]

    # Frames: inertial Nin; geographic N (East, North, up) rotating with the
    # Earth rate; casing B = Rz(alpha) Rx(beta) Ry(gamma); rotor R relative to
    # B = Rz(gamma1) Rx(gamma2) Ry(gamma3), spin about the rotor 2-axis.
    Nin = me.ReferenceFrame("Nin")
    N = me.ReferenceFrame("N")
    N.set_ang_vel(Nin, u2 * N.y + u3 * N.z)
    B = N.orientnew("B", "Body", [alpha, beta, gamma], "ZXY")
    R = B.orientnew("R", "Body", [gamma1, gamma2, gamma3], "ZXY")

    # Points: O fixed in both N and Nin; O' end of the torsion suspension;
    # O1 casing mass centre; O2 nominal rotor centre; P rotor mass centre.
    O = me.Point("O")
    O.set_vel(Nin, 0)
    O.set_vel(N, 0)
    Op = O.locatenew("O'", -l * sp.sin(mu) * N.x
                     + l * sp.sin(lam) * sp.cos(mu) * N.y
                     - l * sp.cos(lam) * sp.cos(mu) * N.z)
    O1 = Op.locatenew("O1", -l1 * B.z)
    O2 = Op.locatenew("O2", -l2 * B.z)
    P = O2.locatenew("P", x1 * B.x + x2 * B.y + x3 * B.z)
    for pt in (O1, P):
        pt.set_vel(Nin, pt.pos_from(O).dt(Nin))

    # Rigid bodies with central principal inertia.
    casing = me.RigidBody("casing", O1, B, M, (me.inertia(B, I1, I2, I3), O1))
    rotor = me.RigidBody("rotor", P, R, m, (me.inertia(R, A, C, A), P))

    # Potential energy: effective gravity along -xi3, elastic bearing.
    casing.potential_energy = g * M * O1.pos_from(O).dot(N.z)
    rotor.potential_energy = (
        g * m * P.pos_from(O).dot(N.z)
        + sp.Rational(1, 2) * (Kp * x1**2 + K0 * x2**2 + Kp * x3**2
                               + Kgamma * gamma1**2 + Kgamma * gamma2**2))

    L = me.Lagrangian(Nin, casing, rotor)
    r2 = R.ang_vel_in(Nin).dot(R.y)
    timings["model"] = time.perf_counter() - t0
    progress(f"model and Lagrangian built in {timings['model']:.2f} s")

    t1 = time.perf_counter()
    LM = me.LagrangesMethod(L, q, frame=Nin)
    LM.form_lagranges_equations()
    timings["lagrange"] = time.perf_counter() - t1
    progress(f"Lagrange equations formed in {timings['lagrange']:.2f} s")

    t2 = time.perf_counter()
    lin = LM.to_linearizer(q_ind=q, qd_ind=qd)
    timings["to_linearizer"] = time.perf_counter() - t2
    progress(f"linearizer created in {timings['to_linearizer']:.2f} s")

    return BaselineSystem(params=params, q=q, qd=qd, qdd=qdd,
                          lagranges_method=LM, linearizer=lin, r2=r2,
                          timings=timings)


# ---------------------------------------------------------------------------
# Linearisation and elimination of the cyclic coordinate
# ---------------------------------------------------------------------------

def _numeric_substitutions(system: BaselineSystem, params: dict) -> dict:
    """Map parameter symbols to floats (phi converted to radians)."""
    missing = set(PARAM_NAMES) - set(params)
    if missing:
        raise KeyError(f"missing parameters: {sorted(missing)}")
    subs = {}
    for name, sym in system.params.items():
        value = float(params[name])
        subs[sym] = math.radians(value) if name == "phi" else value
    return subs


def linearize_full(system: BaselineSystem, params: dict, q0: dict):
    """Linearise all 11 Lagrange equations about the steady motion.

    Returns (M11, D11, K11, spin_rate) as float arrays in the coordinate
    order of ``COORD_NAMES_11`` and the steady value of gamma3'.
    """
    par = _numeric_substitutions(system, params)
    q_op = {qi: 0.0 for qi in system.q}
    for name, value in q0.items():
        if name not in EQUILIBRIUM_NAMES:
            raise KeyError(f"unexpected equilibrium coordinate {name!r}")
        q_op[system.q[COORD_NAMES_11.index(name)]] = float(value)
    qd_zero = {qdi: 0.0 for qdi in system.qd}
    qdd_op = {qddi: 0.0 for qddi in system.qdd}

    # Steady spin rate: r2 is gamma3' plus the transport part, and C*r2 = H.
    transport = float(me.msubs(system.r2, q_op, qd_zero, par))
    spin_rate = float(params["H"]) / float(params["C"]) - transport
    qd_op = dict(qd_zero)
    qd_op[system.qd[COORD_NAMES_11.index("gamma3")]] = spin_rate

    M_lin, A_lin, _ = system.linearizer.linearize(
        op_point=[q_op, qd_op, qdd_op, par], A_and_B=False)

    n = len(system.q)
    M_lin = np.array(M_lin.tolist(), dtype=float)
    A_lin = np.array(A_lin.tolist(), dtype=float)
    # Implicit form  M_lin [dq', dqd']^T = A_lin [dq, dqd]^T ; the lower
    # block rows are the linearised Lagrange equations
    #     Mass dq'' = A21 dq + A22 dq'   ->   K = -A21, D = -A22.
    M11 = M_lin[n:, n:]
    K11 = -A_lin[n:, :n]
    D11 = -A_lin[n:, n:]
    return M11, D11, K11, spin_rate


def baseline_operator(params: dict, q0: dict, system: BaselineSystem = None,
                      progress=None):
    """Numeric 10x10 (M, D, K) of the reduced operator at ``params``, ``q0``.

    The model is derived on first use (and cached at module level); pass a
    ``system`` from :func:`derive_baseline` to reuse a specific one.

    Elimination of gamma3: its Lagrange equation is d/dt(C r2) = 0, and its
    linearised row reads  d/dt( Mass[s,:] dq' + D[s,:] dq ) = 0  (the K row
    vanishes because gamma3 is cyclic).  The first integral with zero
    perturbation,  Mass[s,:] dq' + D[s,:] dq = 0,  gives dgamma3' in terms of
    the other coordinates, which is substituted (with its derivative) into
    the remaining ten equations.
    """
    global _CACHED_SYSTEM
    if system is None:
        if _CACHED_SYSTEM is None:
            _CACHED_SYSTEM = derive_baseline(progress or (lambda s: None))
        system = _CACHED_SYSTEM

    M11, D11, K11, _ = linearize_full(system, params, q0)

    s = COORD_NAMES_11.index("gamma3")
    keep = [COORD_NAMES_11.index(name) for name in COORD_NAMES_10]
    c = M11[s, s]                       # = C
    m_col, m_row = M11[keep, s], M11[s, keep]
    d_col, d_row = D11[keep, s], D11[s, keep]
    # dgamma3'  = -(m_row . dq' + d_row . dq) / c
    # dgamma3'' = -(m_row . dq'' + d_row . dq') / c
    M10 = M11[np.ix_(keep, keep)] - np.outer(m_col, m_row) / c
    D10 = (D11[np.ix_(keep, keep)] - np.outer(m_col, d_row) / c
           - np.outer(d_col, m_row) / c)
    K10 = K11[np.ix_(keep, keep)] - np.outer(d_col, d_row) / c
    return M10, D10, K10


_CACHED_SYSTEM = None


def natural_frequencies(M, D, K) -> np.ndarray:
    """Positive imaginary parts of the roots of det(M p^2 + D p + K) = 0."""
    n = M.shape[0]
    Z, I = np.zeros((n, n)), np.eye(n)
    # First-order form: [[I, 0], [0, M]] z' = [[0, I], [-K, -D]] z.
    A = np.block([[Z, I], [-K, -D]])
    E = np.block([[I, Z], [Z, M]])
    p = scipy.linalg.eig(A, E, right=False)
    return np.sort(p.imag[p.imag > 0])


# ---------------------------------------------------------------------------
# Benchmark entry points
# ---------------------------------------------------------------------------

def run_benchmark(progress=print) -> dict:
    """Derive + one linearisation at the paper example; return times and results."""
    params = paper_params()
    q0 = approximate_equilibrium(params)

    t0 = time.perf_counter()
    system = derive_baseline(progress)
    t_derive = time.perf_counter() - t0

    t1 = time.perf_counter()
    M, D, K = baseline_operator(params, q0, system=system)
    t_lin = time.perf_counter() - t1
    progress(f"first linearisation (Jacobians + substitution) in {t_lin:.2f} s")

    t2 = time.perf_counter()
    baseline_operator(params, q0, system=system)
    t_relin = time.perf_counter() - t2
    progress(f"repeated linearisation (substitution only) in {t_relin:.2f} s")

    freqs = natural_frequencies(M, D, K)
    return {
        "derive_s": t_derive,
        "linearize_s": t_lin,
        "relinearize_s": t_relin,
        "total_s": t_derive + t_lin,
        "steps_s": system.timings,
        "frequencies": freqs.tolist(),
        "M_symmetry_error": float(np.max(np.abs(M - M.T))),
        "M_min_eig": float(np.min(np.linalg.eigvalsh(0.5 * (M + M.T)))),
    }


def _report(result: dict) -> None:
    print(f"derivation (model, Lagrange, linearizer): {result['derive_s']:.2f} s")
    for step, sec in result["steps_s"].items():
        print(f"    {step:<14s} {sec:8.2f} s")
    print(f"first linearisation:                      {result['linearize_s']:.2f} s")
    print(f"repeated linearisation:                   {result['relinearize_s']:.2f} s")
    print(f"derive + one linearisation:               {result['total_s']:.2f} s")
    print(f"M: max|M - M^T| = {result['M_symmetry_error']:.3e}, "
          f"min eig = {result['M_min_eig']:.3e}")
    print("natural frequencies, rad/s:")
    for w in result["frequencies"]:
        print(f"    {w:.6g}")


def run_with_timeout(seconds: float) -> dict | None:
    """Run :func:`run_benchmark` in a fresh Python process bounded by ``seconds``.

    A fresh process keeps sympy's cache cold, as in a real first run.
    Returns the result dict, or None after printing
    "did not finish within S s".
    """
    cmd = [sys.executable, __file__, "--json"]
    try:
        out = subprocess.run(cmd, capture_output=True, text=True,
                             timeout=seconds)
    except subprocess.TimeoutExpired:
        print(f"did not finish within {seconds:g} s")
        return None
    if out.returncode != 0:
        raise RuntimeError("baseline child process failed:\n" + out.stderr[-4000:])
    result = json.loads(out.stdout.strip().splitlines()[-1])
    _report(result)
    return result


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--timeout", type=float, default=None,
                    help="run in a child process and give up after S seconds")
    ap.add_argument("--json", action="store_true",
                    help="print the result as one JSON line (used by --timeout)")
    args = ap.parse_args(argv)

    if args.timeout is not None:
        run_with_timeout(args.timeout)
    elif args.json:
        print(json.dumps(run_benchmark(progress=lambda s: None)))
    else:
        _report(run_benchmark())


if __name__ == "__main__":
    main()
