"""A bead on a rod turning at a constant rate w in a horizontal plane, held by a spring k
towards r0 along the rod, as a sympy.physics.mechanics user writes a rotating frame: the rod's
frame oriented by the explicit angle w t, the bead's position r along it (the rotating-frame
example of the mechanics docs). The equilibrium r = k r0 / (k - m w^2) moves with the spin."""
from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import Lagrangian, LagrangesMethod, Particle, Point, ReferenceFrame, dynamicsymbols

from derive.model import Model, Parameter

PARAMETERS = [Parameter("m", "kg", 0.2, "bead mass"), Parameter("k", "N/m", 50.0, "spring stiffness"),
              Parameter("r0", "m", 0.3, "spring's free length"), Parameter("w", "rad/s", 5.0, "rod's turning rate"),
              Parameter("c", "N s/m", 0.1, "damping along the rod", kind="nonnegative")]


def system():
    r = dynamicsymbols("r")
    m, k, r0, w, c = sp.symbols("m k r0 w c", positive=True)
    t = dynamicsymbols._t
    N = ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [w * t, N.z])
    O = Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", r * A.x)
    P.set_vel(N, P.pos_from(O).dt(N))
    bead = Particle("bead", P, m)
    bead.potential_energy = k * (r - r0) ** 2 / 2
    return Lagrangian(N, bead), [r], [(P, -c * r.diff() * A.x)], N


def reference():
    L, q, loads, N = system()
    lm = LagrangesMethod(L, q, forcelist=loads, frame=N)
    lm.form_lagranges_equations()
    return "lagrange", lm


def build() -> Model:
    L, q, loads, N = system()
    return Model(name="rotating_rod", title="Bead on a turning rod", source="sympy mechanics docs (rotating frame)",
                 module=__name__, parameters=PARAMETERS, coordinates=["r"], coordinate_units={"r": "m"},
                 q=q, qd=[], qdd=[], lagrangian=L, loads=loads, frame=N)
