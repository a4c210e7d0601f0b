"""The input matrix B of M q'' + D q' + K q = B w: how the inputs (applied moments, bearing
imperfections, controls; each rung of an input signal that the equations contain) drive
the linearised system."""
from __future__ import annotations

from derive.model import Function

ORDER = 25


def functions(d) -> list[Function]:
    if d.input_matrix is None:
        return []
    model = d.model
    extra = [("constants", model.given_constants)] if model.given_constants else []
    return [Function("input_matrix", d.state() + extra, [("B", d.input_matrix)],
                     "Input matrix B of M q'' + D q' + K q = B w about the reference, rows "
                     f"({', '.join(d.order)}), columns w = ({', '.join(map(str, d.inputs))}).",
                     ("B",))]


def metadata(d) -> dict:
    if d.input_matrix is None:
        return {}
    return {"inputs": [str(w) for w in d.inputs]}
