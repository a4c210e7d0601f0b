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
    return fns


def metadata(d) -> dict:
    return {"quantities": sorted(d.model.quantities)} if d.model.quantities else {}
