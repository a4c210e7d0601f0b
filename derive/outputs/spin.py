"""The spin a model declares (Model.spin): which parameter sets it, the spin rate in rad/s
as an expression of the parameters (emitted as `spin_rate`, so that the runtime never
retypes it: the torsion gyrocompass's omega_c = H/C of (2.4)), and the coordinate pairs
whose orbit tells forward from backward whirl. Optionally the spin angle ("angle": a
coordinate whose rate at the reference is the spin's): the given functions of that angle
are then the model's harmonic inputs (the torsion gyrocompass's bearing imperfections
f_s(gamma3)), which `gyro forced` drives at multiples of the angle's rate; "harmonics":
(what they are, their unit) names them in its output."""
from __future__ import annotations

import sympy as sp

from derive.model import Function, Unsupported

ORDER = 65


def _declared(d):
    spin = d.model.spin
    if not spin:
        return None
    model = d.model
    unknown = set(spin) - {"parameter", "rate", "whirl", "angle", "harmonics"}
    if unknown:
        raise Unsupported(f"{model.name}: spin: unknown keys {sorted(unknown)}; known: parameter, rate, whirl, angle, "
                          "harmonics")
    name = spin.get("parameter")
    if name not in [p.name for p in model.parameters]:
        raise Unsupported(f"{model.name}: spin: parameter {name!r} is not a parameter of the model")
    rate = sp.sympify(spin.get("rate", model.param(name).symbol))
    bad = sorted(map(str, rate.free_symbols - set(model.symbols)))
    if bad:
        raise Unsupported(f"{model.name}: spin: the rate uses {', '.join(bad)}, not parameters")
    if not rate.has(model.param(name).symbol):
        raise Unsupported(f"{model.name}: spin: the rate {rate} does not depend on {name}")
    pairs = [tuple(map(str, pr)) for pr in spin.get("whirl", [])]
    for pr in pairs:
        if len(pr) != 2 or any(c not in d.order for c in pr):
            raise Unsupported(f"{model.name}: spin: whirl pair {pr} is not two reduced coordinates "
                              f"({', '.join(d.order)})")
    return name, rate, pairs


def _angle(d) -> tuple[str | None, list]:
    """The declared spin angle (a coordinate) and the harmonic inputs: the given values whose
    function's one argument is that angle, in the order of the model's inputs."""
    model = d.model
    angle = model.spin.get("angle")
    if angle is None:
        return None, []
    angle = str(angle)
    if angle not in model.coordinates:
        raise Unsupported(f"{model.name}: spin: angle {angle!r} is not a coordinate ({', '.join(model.coordinates)})")
    if angle not in model.cyclic and angle not in model.steady:
        raise Unsupported(f"{model.name}: spin: angle {angle!r} turns at no declared rate: it must be cyclic "
                          "(Model.cyclic, its momentum given) or steady (Model.steady, its rate given)")
    qa = model.coordinate(angle)
    harmonic = [str(v) for f, v in zip(model.given_functions, model.given_values) if tuple(f.args) == (qa,)]
    return angle, harmonic


def functions(d) -> list[Function]:
    spin = _declared(d)
    if spin is None:
        return []
    name, rate, _ = spin
    grad = sp.Matrix([[sp.diff(rate, p) for p in d.model.symbols]])
    return [Function("spin_rate", [("params", d.model.symbols)], [("rate", sp.Matrix([rate]))],
                     f"The spin rate in rad/s set by the parameter {name}: {rate}."),
            Function("spin_rate_gradient", [("params", d.model.symbols)], [("grad", grad)],
                     "The spin rate's derivatives by each parameter, in the parameters' order (the "
                     "first-order band probability of a tolerance study).", ("grad",))]


def metadata(d) -> dict:
    spin = _declared(d)
    if spin is None:
        return {}
    name, rate, pairs = spin
    out = {"parameter": name, "rate": str(rate), "whirl": [list(p) for p in pairs]}
    angle, harmonic = _angle(d)
    if angle is not None:
        label, unit = d.model.spin.get("harmonics", ("harmonics of the spin angle", ""))
        out.update(angle=angle, harmonic_inputs=harmonic, harmonic_label=str(label), harmonic_unit=str(unit))
    return {"spin": out}
