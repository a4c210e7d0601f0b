"""Spin rates: which parameter sets a model's spin, and the spin rate it gives (rad/s).

A model declares its spin (Model.spin: the parameter and the rate as an expression,
emitted as `spin_rate`); without a declaration, a parameter in rad/s is the spin rate
itself. One definition for the Campbell diagram, its harmonic lines and the unbalance
response. A model that also declares its spin angle (Model.spin "angle") has harmonic
inputs, the given functions of that angle, which turn at the angle's rate at the
reference: the emitted `reference_state`'s rate of that coordinate (for the torsion
gyrocompass gamma3' of (2.3), H/C less the Earth rate on the spin axis, from the integral
C r2 = H)."""
from __future__ import annotations

import numpy as np

from gyro.kernels import function
from gyro.models import Model, ParameterError


def harmonic_inputs(model: Model) -> tuple[str, list[str]]:
    """(the spin angle, its harmonic inputs) the model declares; ParameterError in one line
    naming the declaration it lacks."""
    spin = model.meta.get("spin", {})
    if not spin.get("angle"):
        raise ParameterError(f"{model.name} declares no spin angle (Model.spin 'angle': a cyclic or steady "
                             "coordinate whose given functions are the harmonic inputs; docs/models.md)")
    if not spin.get("harmonic_inputs"):
        raise ParameterError(f"{model.name} declares the spin angle {spin['angle']} but no given function of it "
                             "(the harmonic inputs; docs/models.md)")
    return spin["angle"], list(spin["harmonic_inputs"])


def spin_rate(model: Model, P: np.ndarray, qe: np.ndarray | None = None) -> np.ndarray:
    """The spin angle's rate (rad/s) of each set: at the reference (the emitted
    `reference_state`) of the equilibria qe, or the declared spin rate where qe is None.
    NaN where the set has no equilibrium (qe NaN)."""
    angle, _ = harmonic_inputs(model)
    P = np.atleast_2d(np.asarray(P, float))
    if qe is None:
        with np.errstate(all="ignore"):
            return np.asarray(function(model, "spin_rate")(P)[0], float).reshape(len(P))
    args = [P]
    if model.meta["equilibrium_coordinates"]:
        args.append(np.atleast_2d(np.asarray(qe, float)))
    if any(i["name"] == "time" for i in model.meta["functions"]["reference_state"]["inputs"]):
        args.append(np.zeros((len(P), 1)))
    with np.errstate(all="ignore"):
        _, qd = function(model, "reference_state")(*args)
    qd = np.asarray(qd, float).reshape(len(P), -1)
    return qd[:, list(model.meta["coordinates"]).index(angle)]


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
