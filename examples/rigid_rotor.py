"""Rigid rotor on two damped, anisotropic bearings: a model file, and the worked example of
docs/rotordynamics.md when run as a script.

A rigid rotor of mass m, polar moment Ip and transverse moment It (about an axis through its
centre of mass) spins at the rate Omega about its axis. Bearing 1 sits a distance a before the
centre of mass, bearing 2 a distance b behind it; each is a pair of springs and dampers
(kx, cx horizontal; ky, cy vertical), so the bearings are anisotropic. The rotor's attitude is
Rx(alpha) Ry(beta) Rz(phi): alpha and beta tilt the axis, phi is the spin angle, cyclic, with
the momentum Ip Omega (Routh-reduced: Omega is the spin rate at the reference exactly). Forces
Fx, Fy act at the centre of mass (inputs: an unbalance is one). No gravity: the bearings
centre the rotor.

    python -m derive --model examples/rigid_rotor.py --out DIR     # derive it
    gyro campbell examples/rigid_rotor.py --spin-range 0 1500 --harmonics 1 --json
    .venv/bin/python examples/rigid_rotor.py OUT_DIR               # the worked example

Closed form of the operator over (x, y, alpha, beta), to first order:
M = diag(m, m, It, It); K couples x with beta and y with alpha,
K = [[kx1 + kx2, 0, 0, b kx2 - a kx1], [0, ky1 + ky2, a ky1 - b ky2, 0],
     [0, a ky1 - b ky2, a^2 ky1 + b^2 ky2, 0], [b kx2 - a kx1, 0, 0, a^2 kx1 + b^2 kx2]],
D the same with the c's, plus the gyroscopic Ip Omega in D[alpha, beta] = -D[beta, alpha].
"""
from __future__ import annotations

import sys
from pathlib import Path

import sympy as sp

if __name__ == "__main__":  # run as a script: the build-time package is beside examples/
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from derive.model import Load, Model, Parameter, Signal

NAME = "rigid_rotor"
PARAMETERS = [
    Parameter("m", "kg", 30.0, "rotor mass"),
    Parameter("Ip", "kg m^2", 0.15, "polar moment of inertia"),
    Parameter("It", "kg m^2", 1.2, "transverse moment of inertia about the centre of mass"),
    Parameter("a", "m", 0.25, "bearing 1 before the centre of mass"),
    Parameter("b", "m", 0.35, "bearing 2 behind the centre of mass"),
    Parameter("kx1", "N/m", 1.0e6, "bearing 1 stiffness, horizontal"),
    Parameter("ky1", "N/m", 1.5e6, "bearing 1 stiffness, vertical"),
    Parameter("kx2", "N/m", 1.0e6, "bearing 2 stiffness, horizontal"),
    Parameter("ky2", "N/m", 1.5e6, "bearing 2 stiffness, vertical"),
    Parameter("cx1", "N s/m", 400.0, "bearing 1 damping, horizontal", kind="nonnegative"),
    Parameter("cy1", "N s/m", 400.0, "bearing 1 damping, vertical", kind="nonnegative"),
    Parameter("cx2", "N s/m", 400.0, "bearing 2 damping, horizontal", kind="nonnegative"),
    Parameter("cy2", "N s/m", 400.0, "bearing 2 damping, vertical", kind="nonnegative"),
    Parameter("Omega", "rad/s", 300.0, "spin rate", kind="nonnegative"),
]
m, Ip, It, a, b, kx1, ky1, kx2, ky2, cx1, cy1, cx2, cy2, Omega = (p.symbol for p in PARAMETERS)
COORDINATES = ["x", "y", "alpha", "beta", "phi"]
q = sp.symbols(COORDINATES)
qd = sp.symbols([n + "_d" for n in COORDINATES])
qdd = sp.symbols([n + "_dd" for n in COORDINATES])
FX = Signal("Fx", "N", "horizontal force at the centre of mass", input=True, order=0)
FY = Signal("Fy", "N", "vertical force at the centre of mass", input=True, order=0)


def build() -> Model:
    x, y, al, be, ph = q
    x_d, y_d, al_d, be_d, ph_d = qd
    # body angular velocity of Rx(alpha) Ry(beta) Rz(phi), in body axes (1, 2 transverse, 3 polar)
    w1 = al_d * sp.cos(be) * sp.cos(ph) + be_d * sp.sin(ph)
    w2 = -al_d * sp.cos(be) * sp.sin(ph) + be_d * sp.cos(ph)
    w3 = ph_d + al_d * sp.sin(be)
    T = m / 2 * (x_d**2 + y_d**2) + It / 2 * sp.trigsimp(sp.expand(w1**2 + w2**2)) + Ip / 2 * w3**2
    V, F = 0, 0
    for z, kx, ky, cx, cy in ((-a, kx1, ky1, cx1, cy1), (b, kx2, ky2, cx2, cy2)):
        # the axis point at z: (x, y) + z (sin beta, -sin alpha cos beta)
        px, py = x + z * sp.sin(be), y - z * sp.sin(al) * sp.cos(be)
        vx = sum(sp.diff(px, c) * v for c, v in zip(q, qd))
        vy = sum(sp.diff(py, c) * v for c, v in zip(q, qd))
        V += (kx * px**2 + ky * py**2) / 2
        F += (cx * vx**2 + cy * vy**2) / 2
    return Model(
        name=NAME, title="Rigid rotor on two damped anisotropic bearings", source="examples/rigid_rotor.py",
        module=__name__, parameters=PARAMETERS, coordinates=COORDINATES,
        coordinate_units={"x": "m", "y": "m", "alpha": "rad", "beta": "rad", "phi": "rad"},
        q=list(q), qd=list(qd), qdd=list(qdd),
        lagrangian=T - V,
        dissipation=F,
        loads=[Load(sp.Matrix([FX.symbol, FY.symbol]), sp.Matrix([x_d, y_d]), "force at the centre of mass")],
        signals=[FX, FY],
        cyclic={"phi": Ip * Omega},
        symmetric_zero=["x", "y", "alpha", "beta"],
        spin={"parameter": "Omega", "whirl": [("x", "y"), ("alpha", "beta")]},
    )


# --------------------------------------------------------------------------- the worked example
# (docs/rotordynamics.md; run: .venv/bin/python examples/rigid_rotor.py OUT_DIR)


def closed_form(v: dict):
    """M, D, K over (x, y, alpha, beta) and B over (Fx, Fy), by hand (the module's docstring)."""
    import numpy as np

    a_, b_ = v["a"], v["b"]

    def springs(k1x, k1y, k2x, k2y):
        return np.array([[k1x + k2x, 0, 0, b_ * k2x - a_ * k1x],
                         [0, k1y + k2y, a_ * k1y - b_ * k2y, 0],
                         [0, a_ * k1y - b_ * k2y, a_**2 * k1y + b_**2 * k2y, 0],
                         [b_ * k2x - a_ * k1x, 0, 0, a_**2 * k1x + b_**2 * k2x]])

    M = np.diag([v["m"], v["m"], v["It"], v["It"]])
    D = springs(v["cx1"], v["cy1"], v["cx2"], v["cy2"])
    D[2, 3] += v["Ip"] * v["Omega"]
    D[3, 2] -= v["Ip"] * v["Omega"]
    return M, D, springs(v["kx1"], v["ky1"], v["kx2"], v["ky2"]), np.eye(4)[:, :2]


def exact_roots(v: dict):
    """The four roots with Im > 0 of the closed form's quadratic eigenproblem (8x8 companion)."""
    import numpy as np

    M, D, K, _ = closed_form(v)
    A = np.block([[np.zeros((4, 4)), np.eye(4)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 0]
    return lam[np.argsort(np.abs(lam))]


ME = 1e-4  # kg m: the unbalance, 30 kg with its centre of mass 3.3 um off the axis


def analyse(model, points=301, top=1500.0):
    """The Campbell diagram with the 1x line and the unbalance response over 0..top rad/s, and
    each against the closed form: (diagram, response, worst relative errors)."""
    import numpy as np

    from gyro.analyses.campbell import campbell
    from gyro.analyses.harmonic import unbalance_response

    spins = np.linspace(0.0, top, points)
    diagram = campbell(model, model.defaults, "Omega", spins, harmonics=(1,))
    response = unbalance_response(model, model.defaults, "Fx", "Fy", ME, 0.0, "Omega", 0.0, top, points)
    err = {"frequencies": 0.0, "crossings": 0.0, "unbalance": 0.0}
    for i, w in enumerate(spins):
        v = model.parameters({"Omega": w})
        lam = exact_roots(v)
        got = np.sort(diagram.tracked.growth[i] + 1j * diagram.tracked.frequencies[i])
        err["frequencies"] = max(err["frequencies"], float(np.max(np.abs(np.sort(lam) - got) / np.abs(lam))))
        M, D, K, B = closed_form(v)
        u = ME * w**2 * np.array([1.0, -1j])  # (cos, sin)(W t) = Re((1, -i) e^{i W t})
        X = np.linalg.solve(K - w**2 * M + 1j * w * D, B @ u)
        scale = max(np.max(np.abs(X)), 1e-300)
        if w > 0:
            err["unbalance"] = max(err["unbalance"], float(np.max(np.abs(response.X[i] - X)) / scale))
    for c in diagram.crossings:
        lam = exact_roots(model.parameters({"Omega": c.value}))
        err["crossings"] = max(err["crossings"], float(np.min(np.abs(lam.imag - c.k * c.value)) / c.value))
    return diagram, response, err


if __name__ == "__main__":
    import gyro

    out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    rotor = gyro.load(Path(__file__))
    diagram, response, err = analyse(rotor)
    diagram.plot(out / "rigid_rotor_campbell.png")
    response.plot(out / "rigid_rotor_unbalance.png")
    print(diagram.table())
    peaks = response.amplitudes
    for j, name in enumerate(response.coordinates):
        i = int(peaks[:, j].argmax())
        print(f"peak of |{name}|: {peaks[i, j]:.4g} {response.units[j]} at Omega = {response.x[i]:.1f} rad/s")
    print("worst relative error against the closed form: " + ", ".join(f"{k} {v:.1e}" for k, v in err.items()))
