"""The full nonlinear equations in mass-matrix form, Mq(q) qdd = f(q, qd), for simulation."""
from __future__ import annotations

from derive.model import TIME, Function
from derive.outputs.operator import MATRICES

ORDER = 50


def functions(d) -> list[Function]:
    model = d.model
    params = ("params", model.symbols)
    timed = ([("time", [TIME])] if d.time_dependent else []) + (
        [("signals", model.signal_symbols)] if model.signals else [])
    given = [("given", model.given_values), ("dgiven", model.given_derivatives)] if model.given_values else []
    if model.given_values and model.given_constants:
        given.append(("constants", model.given_constants))
    extra = []
    if model.has_forces:
        extra.append("generalised forces included")
    if timed:
        extra.append("the explicit time derivative of dL/dqd moved to f")
    note = f" ({'; '.join(extra)})" if extra else ""
    fns = [
        Function("mass_matrix", [params, ("q", model.q)] + timed, [("Mq", d.mass_matrix)],
                 "Mass matrix of the full nonlinear equations: Mq qdd = f.", MATRICES),
        Function("forcing", [params, ("q", model.q), ("qd", model.qd)] + timed + given,
                 [("f", d.forcing)],
                 "Right-hand side f(q, qd) of the full nonlinear equations, "
                 "Mq qdd = f, with the given functions' values and derivatives as inputs"
                 + note + "."),
    ]
    if d.speeds:  # the speeds of the kinematic equations (Model.kinematics), as KanesMethod's
        u = ("speeds", d.speeds["u"])
        fns += [
            Function("kinematics", [params, ("q", model.q), u] + timed, [("qd", d.speeds["kinematics"])],
                     "The coordinates' rates from the speeds: qd = V(q) u + v(q), the kinematic equations "
                     "solved."),
            Function("speeds_mass_matrix", [params, ("q", model.q)] + timed, [("Mu", d.speeds["mass_matrix"])],
                     "Mass matrix of the equations in the speeds, Mu ud = fu: V' Mq V (Kane's equations).",
                     MATRICES),
            Function("speeds_forcing", [params, ("q", model.q), u] + timed + given, [("fu", d.speeds["forcing"])],
                     "Right-hand side fu(q, u) of the equations in the speeds, Mu ud = fu: V' (f - Mq (V' u + "
                     "v')) with qd = V u + v" + note + "."),
        ]
    if d.varying:  # the same equations with parameters made time-varying (Signal.parameter)
        moving = ([("time", [TIME])] if d.time_dependent else []) + [
            ("signals", [s for sig in d.varying["signals"] for s in sig.symbols])]
        which = ", ".join(f"{sig.parameter} = {sig.name}(t)" for sig in d.varying["varying"])
        fns += [
            Function("mass_matrix_varying", [params, ("q", model.q)] + moving, [("Mq", d.varying["mass_matrix"])],
                     f"Mass matrix of the full nonlinear equations with {which}: Mq qdd = f.", MATRICES),
            Function("forcing_varying", [params, ("q", model.q), ("qd", model.qd)] + moving + given,
                     [("f", d.varying["forcing"])],
                     f"Right-hand side f of the full nonlinear equations with {which}, the signals' "
                     "derivatives entering through d/dt" + note + "."),
        ]
    return fns


def metadata(d) -> dict:
    """The parameters made time-varying: each signal's name, parameter, order and rungs (the
    inputs of the functions NAME_varying)."""
    if not d.varying:
        return {}
    return {"varying": [{"name": sig.name, "parameter": sig.parameter, "unit": sig.unit,
                         "description": sig.description, "order": sig.order,
                         "symbols": [str(s) for s in sig.symbols]} for sig in d.varying["varying"]]}
