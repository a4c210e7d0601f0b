"""Spin rates: which parameter sets a model's spin, and the spin rate it gives (rad/s).

A model declares its spin (Model.spin: the parameter and the rate as an expression,
emitted as `spin_rate`); without a declaration, a parameter in rad/s is the spin rate
itself. One definition for the Campbell diagram, its harmonic lines and the unbalance
response. The bearing imperfections of the torsion gyrocompass are functions of gamma3,
whose rate at the relative equilibrium is (2.3) (`spin_rate`: the declared H/C less the
Earth rate on the spin axis)."""
from __future__ import annotations

import numpy as np

from gyro.kernels import function
from gyro.models import Model, ParameterError

MODELS = ("torsion_gyrocompass",)  # models whose spin rate is given by (2.3)


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


def spin_parameter(model: Model, name: str | None, sole_rate: bool = False) -> str:
    """The parameter that sets the spin: `name`, or the model's declared one (with
    `sole_rate`, else the model's only parameter in rad/s). A parameter that is neither
    declared nor in rad/s is refused (its spin rate would be a guess)."""
    declared = model.meta.get("spin", {}).get("parameter")
    rates = [p.name for p in model.params if p.unit == "rad/s"]
    if name is None and declared is None and sole_rate and len(rates) == 1:
        return rates[0]
    if name is None:
        if declared is None:
            raise ParameterError(f"--spin: {model.name} declares no spin parameter; name one in rad/s "
                                 f"(--spin NAME; parameters: {' '.join(model.param_names)})")
        return declared
    name = model.param_name(name, "--spin")
    unit = model.params[model.param_names.index(name)].unit
    if name != declared and unit != "rad/s":
        raise ParameterError(f"--spin {name!r}: its unit is {unit}, not rad/s, and {model.name} declares "
                             + (f"the spin as {declared}" if declared else "no spin rate for it (Model.spin)"))
    return name


def spin_rates(model: Model, spin: str, P: np.ndarray) -> np.ndarray:
    """The spin rate in rad/s of each set: the model's emitted spin_rate where it declares
    `spin`, the parameter itself otherwise."""
    if model.meta.get("spin", {}).get("parameter") == spin:
        with np.errstate(all="ignore"):
            return np.asarray(function(model, "spin_rate")(P)[0], float).reshape(len(P))
    return P[:, model.param_names.index(spin)].copy()
