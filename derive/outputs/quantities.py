"""Model quantities that analyses need (integrals, Routh's function, closed-form
coefficients), declared in the model file and emitted like everything else, so that the
runtime never retypes physics."""
from __future__ import annotations

import sympy as sp

from derive.model import TIME, Function, Unsupported

ORDER = 60


def _groups(d) -> dict:
    model = d.model
    return {"params": model.symbols, "q": model.q, "qd": model.qd, "momenta": d.momenta,
            "time": [TIME], "signals": model.signal_symbols, "qe": d.even}


def functions(d) -> list[Function]:
    groups, fns = _groups(d), []
    for name, (inputs, outputs, doc) in d.model.quantities.items():
        ins = []
        for g in inputs:
            if isinstance(g, str):
                if g not in groups:
                    raise Unsupported(f"quantity {name}: unknown input group {g!r}; known: {', '.join(groups)}")
                ins.append((g, groups[g]))
            else:
                ins.append((g[0], list(g[1])))
        outs = [(o, sp.Matrix(m)) for o, m in outputs]
        # a one-column output is a vector; wider ones are matrices
        fns.append(Function(name, ins, outs, doc, tuple(o for o, m in outs if m.cols > 1)))
        if d.varying and any(m.free_symbols & set(d.varying["sub"]) for _, m in outs):
            fns.append(_varying(d, name, ins, outs, doc))
    return fns


def _varying(d, name, ins, outs, doc) -> Function:
    """A quantity that contains a parameter made time-varying (Signal.parameter), once more
    with the parameter the signal's value: NAME_varying, the signals' rungs its input group
    `signals` (every signal of the model, in its order)."""
    if name + "_varying" in d.model.quantities:
        raise Unsupported(f"quantity {name}_varying: the name of quantity {name} with its parameters time-varying")
    sub = d.varying["sub"]
    every = [s for sig in d.varying["signals"] for s in sig.symbols]
    ins = [g for g in ins if g[0] != "signals"] + [("signals", every)]
    which = ", ".join(f"{sig.parameter} = {sig.name}(t)" for sig in d.varying["varying"])
    outs = [(o, m.xreplace(sub)) for o, m in outs]
    return Function(name + "_varying", ins, outs, f"{doc} With {which}.", tuple(o for o, m in outs if m.cols > 1))


def metadata(d) -> dict:
    return {"quantities": sorted(d.model.quantities)} if d.model.quantities else {}
