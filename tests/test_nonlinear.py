"""The emitted full nonlinear equations (1.13) against the equilibrium: a relative
equilibrium, with the spin rate given by the integral C r2 = H, is a steady motion of the
11-coordinate equations. The two sides come from different code: `mass_matrix`/`forcing`
from the Lagrangian with all 11 coordinates, the equilibrium from the Routh function."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import load
from gyro.modal import equilibrium

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
    f = nf.forcing(P, q, qd, np.zeros(3), np.zeros(3), np.zeros(1))
    acc = np.linalg.solve(Mq, f)
    # what the accelerations are made of: gravity over the lever, stiffness over masses
    scale = values["g"] / values["l"] + values["Kp"] / values["m"] * abs(q[coords.index("x3")])
    tol = 1e-10 * scale
    assert np.max(np.abs(acc)) < tol, dict(zip(coords, acc))
    # the check is sensitive: with the spin 1 % off, the unbalanced gyroscopic moment
    # gives accelerations a thousand times the tolerance
    qd[coords.index("gamma3")] *= 1.01
    acc_bad = np.linalg.solve(Mq, nf.forcing(P, q, qd, np.zeros(3), np.zeros(3), np.zeros(1)))
    assert np.max(np.abs(acc_bad)) > 1e3 * tol
