"""A model given in speeds u with kinematic equations (Model.kinematics, derive/convert.py):
its equations in them, as Kane's method forms them."""
from __future__ import annotations

import sympy as sp

from derive.model import TIME, Model

ORDER = 140
ROUTES = ("coordinates", "multipliers")


def speeds_equations(model: Model, Mq: sp.Matrix, f: sp.Matrix) -> dict:
    """The equations Mq q'' = f in the speeds u of the kinematic equations, q' = V u + v:
    with q'' = V u' + V' u + v' (V' and v' along the motion), premultiplied by V^T, which
    is what Kane's equations are (the partial velocities of u_r are those of q' taken
    through V's column r): V^T Mq V u' = V^T (f - Mq (V' u + v')), q' replaced by V u + v.
    Refused with holonomic constraints (eliminated coordinates change the rates)."""
    sp_ = model.speeds
    u, V, v = sp.Matrix(sp_["u"]), sp_["V"], sp_["v"]
    q, qd = model.q, model.qd
    rate = {a: b for a, b in zip(qd, V * u + v)}

    def dt(X):
        return sum((X.diff(x) * r for x, r in zip(q, qd)), X.diff(TIME))

    Vu = V.xreplace(rate)
    accel = (dt(V) * u + dt(v)).xreplace(rate)
    M = Vu.T * Mq.xreplace(rate) * Vu  # as they come: expanding took a top's 0.6 s
    F = Vu.T * (f.xreplace(rate) - Mq.xreplace(rate) * accel)
    return {"u": list(u), "kinematics": (V * u + v), "mass_matrix": M, "forcing": F}


def run(model: Model, d):
    if model.speeds:
        with d.work.steps("equations in the speeds of the kinematic equations (Kane's form)"):
            d.speeds = speeds_equations(model, d.mass_matrix, d.forcing)
    return d
