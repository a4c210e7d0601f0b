"""An N-link pendulum on a cart, the system of sympy.physics.mechanics'
`models.n_link_pendulum_on_cart(N, cart_force=True)` written from its description as a
model of this project: a cart of mass m0 at q0 on the horizontal x axis, pushed by F(t);
N massless links of lengths l0..l(N-1), link i at the absolute angle q(i+1) from the
upward y axis (its tip at the previous tip plus l_i (-sin q, cos q)), a particle m(i+1) at
each tip; gravity g along -y. The reference is rest upright (q = 0).

`python -m bench.pendulum_chain` writes one model file per N (`build()` returns model(N))
and derives it with `python -m derive --model`."""
from __future__ import annotations

import sympy as sp

from derive.model import Model, Parameter, Signal


def model(n: int) -> Model:
    q = sp.symbols(f"q0:{n + 1}")
    qd = sp.symbols(" ".join(f"q{i}_d" for i in range(n + 1)))
    qdd = sp.symbols(" ".join(f"q{i}_dd" for i in range(n + 1)))
    m = sp.symbols(f"m0:{n + 1}")
    ls = sp.symbols(f"l0:{n}")
    g, F = sp.symbols("g F")
    params = [Parameter(f"m{i}", "kg", 0.01 if i else 1.0, "cart mass" if i == 0 else f"mass at the tip of link {i}")
              for i in range(n + 1)]
    params += [Parameter(f"l{i}", "m", 1.0 / n, f"length of link {i + 1}") for i in range(n)]
    params.append(Parameter("g", "m/s^2", 9.81, "gravity"))
    x, y, xd, yd = q[0], sp.Integer(0), qd[0], sp.Integer(0)
    T = m[0] * qd[0] ** 2 / 2
    V = sp.Integer(0)
    for i in range(n):
        x, y = x - ls[i] * sp.sin(q[i + 1]), y + ls[i] * sp.cos(q[i + 1])
        xd, yd = xd - ls[i] * sp.cos(q[i + 1]) * qd[i + 1], yd - ls[i] * sp.sin(q[i + 1]) * qd[i + 1]
        T += m[i + 1] * (xd**2 + yd**2) / 2
        V += m[i + 1] * g * y
    names = [str(s) for s in q]
    return Model(
        name=f"pendulum_chain_{n}", title=f"{n}-link pendulum on a cart", source="sympy models",
        module=f"pendulum_chain_{n}", parameters=params, coordinates=names,
        coordinate_units={c: ("m" if c == "q0" else "rad") for c in names}, q=list(q), qd=list(qd),
        qdd=list(qdd), lagrangian=T - V, generalized_forces={"q0": F},
        signals=[Signal("F", "N", "force on the cart", input=True, order=0)])
