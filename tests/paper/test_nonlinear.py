"""The emitted full nonlinear equations (1.13) against the equilibrium: a relative
equilibrium, with the spin rate given by the integral C r2 = H, is a steady motion of the
11-coordinate equations. The two sides come from different code: `mass_matrix`/`forcing`
from the Lagrangian with all 11 coordinates, the equilibrium from the Routh function."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import load
from gyro.equilibrium import equilibrium

MODEL = load("torsion_gyrocompass")


def _rot(axis, a):
    c, s = np.cos(a), np.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def _earth_rate_on_spin_axis(values, g):
    """Absolute rate of the non-spinning rotor axes at rest, component on the spin axis
    (the part of r2 in (1.6) that is not gamma3'); frames as in (1.2), (1.6)."""
    phi = np.radians(values["phi"])
    u = values["u"] * np.array([0.0, np.cos(phi), np.sin(phi)])
    S = _rot("z", g["alpha"]) @ _rot("x", g["beta"]) @ _rot("y", g["gamma"])
    R = _rot("z", g["gamma1"]) @ _rot("x", g["gamma2"])
    return float((R.T @ S.T @ u)[1])


@pytest.mark.parametrize("over", [{}, {"phi": 20}, {"H": 1.2, "Kgamma": 10.0}, {"phi": -45, "u": 1e-3}])
def test_relative_equilibrium_is_a_steady_motion_of_the_full_equations(over):
    values = MODEL.parameters(over)
    P = MODEL.vector(values)
    coords = MODEL.meta["coordinates"]
    q = np.zeros(len(coords))
    for name, v in zip(MODEL.meta["equilibrium_coordinates"], equilibrium(MODEL, P)):
        q[coords.index(name)] = v
    qd = np.zeros(len(coords))
    qd[coords.index("gamma3")] = values["H"] / values["C"] - _earth_rate_on_spin_axis(values, dict(zip(coords, q)))
    nf = MODEL.numpy
    Mq = nf.mass_matrix(P, q)
    f = nf.forcing(P, q, qd, np.zeros(3), np.zeros(3))
    acc = np.linalg.solve(Mq, f)
    # what the accelerations are made of: gravity over the lever, stiffness over masses
    scale = values["g"] / values["l"] + values["Kp"] / values["m"] * abs(q[coords.index("x3")])
    tol = 1e-10 * scale
    assert np.max(np.abs(acc)) < tol, dict(zip(coords, acc))
    # the check is sensitive: with the spin 1 % off, the unbalanced gyroscopic moment
    # gives accelerations a thousand times the tolerance
    qd[coords.index("gamma3")] *= 1.01
    acc_bad = np.linalg.solve(Mq, nf.forcing(P, q, qd, np.zeros(3), np.zeros(3)))
    assert np.max(np.abs(acc_bad)) > 1e3 * tol


def _spin_axis_rate(values, q, qd, coords):
    """r2 - gamma3' of (1.6): the rotor's absolute rate on its spin axis without the spin,
    from the casing rate p (1.5) with all coordinate rates."""
    g = dict(zip(coords, q))
    gd = dict(zip(coords, qd))
    phi = np.radians(values["phi"])
    u = values["u"] * np.array([0.0, np.cos(phi), np.sin(phi)])
    S = _rot("z", g["alpha"]) @ _rot("x", g["beta"]) @ _rot("y", g["gamma"])
    p = (S.T @ (u + gd["alpha"] * np.array([0, 0, 1.0]))
         + gd["beta"] * np.array([np.cos(g["gamma"]), 0, np.sin(g["gamma"])])
         + gd["gamma"] * np.array([0, 1.0, 0]))
    R = _rot("z", g["gamma1"]) @ _rot("x", g["gamma2"])
    r = R.T @ (p + gd["gamma1"] * np.array([0, 0, 1.0])) + gd["gamma2"] * np.array([1.0, 0, 0])
    return r[1]


@pytest.mark.parametrize("mode", [1, 3])  # 5.07 and 19.03 rad/s: the two pendulum modes of J'
def test_nonlinear_small_oscillation_has_the_linear_frequency(mode):
    """Start the full 11-coordinate equations on one eigenvector of the linear operator
    (amplitude 1e-7) with the spin from the integral C r2 = H, integrate three periods, and
    measure the period from zero crossings. The nonlinear shift is O(amplitude^2) ~ 1e-14
    and the integrator's phase error ~ its tolerance 1e-11 per period, so the measured
    frequency must agree with the linear one to 1e-7 (the crossings are interpolated from
    dense output)."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    from gyro import ode
    from gyro.ladder import natural_frequencies

    values = MODEL.parameters()
    P = MODEL.vector(values)
    coords = MODEL.meta["coordinates"]
    reduced = MODEL.meta["reduced"]
    res = natural_frequencies(MODEL, values)
    w = res.frequencies[mode]
    qe = equilibrium(MODEL, P)
    M, D, K = MODEL.numpy.operator(P, qe)
    lam = 1j * w
    _, _, Vh = np.linalg.svd(M * lam**2 + D * lam + K)
    x = Vh[-1].conj()
    x = x / x[np.argmax(np.abs(x))] * 1e-7
    q0 = np.zeros(len(coords))
    for name, v in zip(MODEL.meta["equilibrium_coordinates"], qe):
        q0[coords.index(name)] = v
    qd0 = np.zeros(len(coords))
    for i, name in enumerate(reduced):
        q0[coords.index(name)] += x[i].real
        qd0[coords.index(name)] = (lam * x[i]).real
    k = coords.index("gamma3")
    qd0[k] = values["H"] / values["C"] - _spin_axis_rate(values, q0, qd0, coords)
    rhs = ode.numpy_rhs(MODEL, P)  # the emitted CasADi equations, no given forces
    T = 3 * 2 * np.pi / w
    sol = solve_ivp(rhs, (0, T), np.concatenate([q0, qd0]), method="DOP853", rtol=1e-11, atol=1e-18,
                    dense_output=True)
    assert sol.success
    i_max = int(np.argmax(np.abs(x)))
    j = coords.index(reduced[i_max])
    rest = q0[j] - x[i_max].real  # the coordinate's equilibrium value

    def dev(tt):
        return sol.sol(tt)[j] - rest

    t = np.linspace(0, T, 6001)
    s = dev(t)
    up = np.where((s[:-1] < 0) & (s[1:] >= 0))[0]
    crossings = [brentq(dev, t[i], t[i + 1], xtol=1e-14) for i in up]
    assert len(crossings) >= 3
    period = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert abs(2 * np.pi / period / w - 1) < 1e-7, (2 * np.pi / period, w)
