"""sympy's test_linearize_pendulum_kane_nonminimal: a pendulum in Cartesian q1 (along gravity),
q2, speeds u = q' by kde, the constraint |P| - L = 0 (a square root), g = 9.8 a float."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import KanesMethod, Lagrangian, Particle, Point, ReferenceFrame, dynamicsymbols

from derive.model import Model, Parameter

PARAMETERS = [Parameter("L", "m", 0.5, "length"), Parameter("m", "kg", 1.0, "mass")]
INDEPENDENT = ["q2"]


def system():
    q1, q2 = dynamicsymbols("q1:3")
    q1d, q2d = dynamicsymbols("q1:3", level=1)
    u1, u2 = dynamicsymbols("u1:3")
    L, m, t = sp.symbols("L, m, t")
    g = 9.8
    N = ReferenceFrame("N")
    pN = Point("N*")
    pN.set_vel(N, 0)
    theta1 = sp.atan(q2 / q1)
    A = N.orientnew("A", "axis", [theta1, N.z])
    P = pN.locatenew("P1", q1 * N.x + q2 * N.y)
    pP = Particle("pP", P, m)
    kde = sp.Matrix([q1d - u1, q2d - u2])
    dq_dict = sp.solve(kde, [q1d, q2d])
    P.set_vel(N, P.pos_from(pN).dt(N).subs(dq_dict))
    f_c = sp.Matrix([P.pos_from(pN).magnitude() - L])
    f_v = sp.Matrix([P.vel(N).express(A).dot(A.x)])
    f_v.simplify()
    f_a = f_v.diff(t)
    f_a.simplify()
    return dict(N=N, q=[q1, q2], u=[u1, u2], kde=kde, f_c=f_c, f_v=f_v, f_a=f_a, pP=pP, loads=[(P, m * g * N.x)])


def reference():
    s = system()
    q1, q2 = s["q"]
    u1, u2 = s["u"]
    KM = KanesMethod(s["N"], q_ind=[q2], u_ind=[u2], q_dependent=[q1], u_dependent=[u1],
                     configuration_constraints=s["f_c"], velocity_constraints=s["f_v"],
                     acceleration_constraints=s["f_a"], kd_eqs=s["kde"])
    KM.kanes_equations([s["pP"]], s["loads"])
    return "kane", KM


def build() -> Model:
    s = system()
    return Model(name="pendulum_kane_nonminimal", title="Nonminimal pendulum (Kane)", source="sympy test_linearize",
                 module=__name__, parameters=PARAMETERS, coordinates=["q1", "q2"],
                 coordinate_units={"q1": "m", "q2": "m"}, q=s["q"], qd=s["u"], qdd=[],
                 lagrangian=Lagrangian(s["N"], s["pP"]), loads=s["loads"], frame=s["N"],
                 kinematics=list(s["kde"]), holonomic=list(s["f_c"]), reduced=INDEPENDENT)
