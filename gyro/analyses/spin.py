"""Spin rates: which parameter sets a model's spin, and the spin rate it gives (rad/s).

A parameter in rad/s is the spin rate itself; the torsion gyrocompass's rotor momentum H
gives the rotor's spin rate at the relative equilibrium, (2.3). Shared by the harmonic
response (the unbalance over a spin range) and the bearing imperfections' forcing."""
from __future__ import annotations

import numpy as np

from gyro.models import Model, ParameterError

MODELS = ("torsion_gyrocompass",)  # models whose spin rate is given by (2.3)


def sets_spin(model: Model, name: str) -> bool:
    """Whether the parameter `name` sets the spin rate that spin_rate gives (H, here)."""
    return model.name in MODELS and name == "H"


def spin_rate(model: Model, P: np.ndarray, qe: np.ndarray | None = None) -> np.ndarray:
    """omega_c = gamma3' at the relative equilibrium, (2.3) at rest: H/C less the Earth rate
    on the spin axis, u cos(phi) + u sin(phi) (beta0 + gamma20) (within u/omega_c = 3e-8
    of H/C at the example; tests/test_paper_items.py)."""
    if model.name not in MODELS:
        raise ParameterError(f"{model.name}: no spin rate of the bearing imperfections (torsion gyrocompass only)")
    P = np.atleast_2d(P)
    col = {n: P[:, i] for i, n in enumerate(model.param_names)}
    W = col["H"] / col["C"]
    if qe is None:
        return W
    eq = model.meta["equilibrium_coordinates"]
    phi = np.radians(col["phi"])
    tilt = qe[:, eq.index("beta")] + qe[:, eq.index("gamma2")]
    return W - col["u"] * np.cos(phi) - col["u"] * np.sin(phi) * tilt


def spin_rates(model: Model, P: np.ndarray, spin: str, qe: np.ndarray | None = None) -> np.ndarray:
    """The spin rate W (rad/s) of each set, set by the parameter `spin`: the parameter itself
    when its unit is rad/s; for the torsion gyrocompass's momentum H the rotor's spin rate
    at the relative equilibrium (spin_rate). Anything else is refused."""
    unit = next((p.unit for p in model.params if p.name == spin), None)
    if unit is None:
        raise ParameterError(f"--spin {spin!r}: unknown parameter; known: {' '.join(model.param_names)}")
    if unit == "rad/s":
        return P[:, model.param_names.index(spin)].copy()
    if sets_spin(model, spin):
        return spin_rate(model, P, qe)
    raise ParameterError(f"--spin {spin!r}: its unit is {unit}, not rad/s, and {model.name} "
                         "declares no spin rate for it")
