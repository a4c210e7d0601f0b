"""The model in the machinery's symbols (derive/convert.py), what is refused before anything
is solved, and the parameters made time-varying by signals set aside: everything is derived
at their constant values, and the equations again with the signals (the equations pass)."""
from __future__ import annotations

import dataclasses

from derive import convert, names
from derive.model import Model, Unsupported

ORDER = 10
ROUTES = ("coordinates", "multipliers")


def refuse_nonholonomic(model: Model) -> None:
    if model.nonholonomic:
        raise Unsupported(f"{model.name}: nonholonomic constraints are not supported (the machinery "
                          "has no multipliers for velocity constraints): write the system in independent "
                          "coordinates")


def split_varying(model: Model) -> tuple[Model, list, list]:
    """(the model without the signals that make a parameter time-varying, those signals, all
    the model's signals): everything is derived at the parameters' constant values from the
    first; the equations pass derives the full equations again with the signals."""
    varying = [s for s in model.signals if s.parameter is not None]
    if not varying:
        return model, [], list(model.signals)
    names.check_model(model)  # the signals' names among every other emitted symbol
    params = {p.name for p in model.parameters}
    seen = set()
    for sig in varying:
        if sig.parameter not in params:
            raise Unsupported(f"{model.name}: signal {sig.name!r} makes {sig.parameter!r} time-varying, "
                              "which is not a parameter")
        if sig.input:
            raise Unsupported(f"{model.name}: signal {sig.name!r} makes the parameter {sig.parameter} "
                              "time-varying: it stays in the equations (input=False), it is no input w")
        if sig.parameter in seen:
            raise Unsupported(f"{model.name}: the parameter {sig.parameter} is made time-varying twice")
        seen.add(sig.parameter)
    if model.holonomic:
        raise Unsupported(f"{model.name}: a parameter made time-varying (signal {varying[0].name!r}) "
                          "together with holonomic constraints")
    return dataclasses.replace(model, signals=[s for s in model.signals if s.parameter is None]), varying, list(
        model.signals)


def run(model: Model, d):
    model = convert.convert(model)  # dynamicsymbols, assumptions, vectors: the machinery's symbols
    refuse_nonholonomic(model)  # before anything is solved
    d.model, d.work.varying, d.work.all_signals = split_varying(model)
    if model.speeds and model.holonomic:
        raise Unsupported(f"{model.name}: kinematic equations together with holonomic constraints: write the "
                          "model in its independent coordinates, or in their rates")
    return d
