"""The rolling disc of sympy.physics.mechanics' test_kane and test_lagrange
(test_rolling_disc), as their users write it: 3-1-2 angles q1..q3, the disc's centre Dmc
located from the contact point C, whose velocity is set to zero, and its velocity formed
from C up (Dmc.v2pt_theory(C, N, R)). Rolling without slip is then in that velocity, not
in any position: a nonholonomic constraint. KanesMethod (speeds u1..u3, the disc's angular
velocity in the lean frame, kd_eqs) gives the rolling disc's equations; LagrangesMethod on
the same Lagrangian gives other q1'' and q3'' (Lagrange's equations hold for holonomic
systems only). The machinery must refuse both forms as nonholonomic: `build()` the Kane
form (gravity a load on Dmc), `build_lagrange()` the Lagrange form (gravity a potential:
no load point shows Dmc)."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import (KanesMethod, Lagrangian, LagrangesMethod, Point, ReferenceFrame, RigidBody,
                                     dot, dynamicsymbols, inertia)

from derive.model import Model, Parameter

PARAMETERS = [Parameter("r", "m", 0.3, "radius"), Parameter("m", "kg", 1.0, "mass"),
              Parameter("g", "m/s^2", 9.81, "gravity")]


def _disc(speeds: bool):
    q1, q2, q3, u1, u2, u3 = dynamicsymbols("q1 q2 q3 u1 u2 u3")
    r, m, g = sp.symbols("r m g")
    N = ReferenceFrame("N")
    Y = N.orientnew("Y", "Axis", [q1, N.z])
    L = Y.orientnew("L", "Axis", [q2, Y.x])
    R = L.orientnew("R", "Axis", [q3, L.y])
    w_R_N_qd = R.ang_vel_in(N)
    if speeds:
        R.set_ang_vel(N, u1 * L.x + u2 * L.y + u3 * L.z)
    C = Point("C")
    C.set_vel(N, 0)
    Dmc = C.locatenew("Dmc", r * L.z)
    Dmc.v2pt_theory(C, N, R)
    disc = RigidBody("BodyD", Dmc, R, m, (inertia(L, m / 4 * r**2, m / 2 * r**2, m / 4 * r**2), Dmc))
    kd = [dot(R.ang_vel_in(N) - w_R_N_qd, uv) for uv in L]
    return [q1, q2, q3], [u1, u2, u3], kd, disc, Dmc, Y, N


def system():
    """(Lagrangian, q, u, kd_eqs, bodies, loads, N): test_kane's form."""
    q, u, kd, disc, Dmc, Y, N = _disc(True)
    m, g = sp.symbols("m g")
    return Lagrangian(N, disc), q, u, kd, [disc], [(Dmc, -m * g * Y.z)], N


def system_lagrange():
    """(Lagrangian, q, loads, N): test_lagrange's form, gravity as the disc's potential."""
    q, _, _, disc, _, _, N = _disc(False)
    m, g, r = sp.symbols("m g r")
    disc.potential_energy = -m * g * r * sp.cos(q[1])
    return Lagrangian(N, disc), q, [], N


def kanes_method():
    _, q, u, kd, bodies, loads, N = system()
    km = KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd)
    km.kanes_equations(bodies, loads)
    return km


def reference():
    """SymPy's method on the system as build() gives it."""
    return "kane", kanes_method()


def lagranges_method():
    L, q, _, N = system_lagrange()
    lm = LagrangesMethod(L, q, frame=N)
    lm.form_lagranges_equations()
    return lm


def _model(name, L, q, u, kd, loads, N) -> Model:
    return Model(name=name, title="Rolling disc", source="sympy test_kane, test_lagrange", module=__name__,
                 parameters=PARAMETERS, coordinates=["q1", "q2", "q3"],
                 coordinate_units={c: "rad" for c in ("q1", "q2", "q3")}, q=q, qd=u, qdd=[], lagrangian=L,
                 loads=loads, frame=N, kinematics=kd)


def build() -> Model:
    L, q, u, kd, _, loads, N = system()
    return _model("rolling_disc", L, q, u, kd, loads, N)


def build_lagrange() -> Model:
    L, q, loads, N = system_lagrange()
    return _model("rolling_disc_lagrange", L, q, [], [], loads, N)
