"""A block with Coulomb friction that sticks: the spring's pull (k x = 0.2 N from rest plus
0.01 m) below the friction's bound (mu m g = 0.98 N). sign(x_d) then switches at every step,
the integrator's steps shrink without end, and its budget stops it (5e6 evaluations for
1.7e-6 s at the command line's budget). The one line says why, naming the term, rather than
a bare "numerical failure"; a start where the block slides still answers."""
from __future__ import annotations

import numpy as np

from tests.conftest import error_lines, run_cli

BLOCK = '''
import sympy as sp
from sympy.physics.mechanics import Lagrangian, Particle, Point, ReferenceFrame, dynamicsymbols

from derive.model import Model, Parameter

PARAMETERS = [Parameter("m", "kg", 1.0, "mass"), Parameter("k", "N/m", 20.0, "spring"),
              Parameter("mu", "1", 0.1, "friction coefficient", kind="nonnegative"),
              Parameter("g", "m/s^2", 9.81, "gravity")]


def build() -> Model:
    x = dynamicsymbols("x")
    m, k, mu, g = sp.symbols("m k mu g", positive=True)
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    P = O.locatenew("P", x * N.x)
    P.set_vel(N, x.diff() * N.x)
    block = Particle("block", P, m)
    block.potential_energy = k * x**2 / 2
    return Model(name="coulomb_block", title="Block with Coulomb friction", source="test", module=__name__,
                 parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"}, q=[x], qd=[], qdd=[],
                 lagrangian=Lagrangian(N, block), loads=[(P, -mu * m * g * sp.sign(x.diff()) * N.x)], frame=N)
'''


def test_a_sticking_block_is_refused_naming_the_switching_term(tmp_path, monkeypatch):
    from gyro.analyses import motion

    path = tmp_path / "coulomb_block.py"
    path.write_text(BLOCK)
    monkeypatch.setattr(motion, "BUDGET_EVALUATIONS", 2e5)  # the same stall, sooner
    rc, out, err = run_cli("simulate", str(path), "--t-end", "1", "--perturb", "x=0.01")
    lines = error_lines(err)
    assert rc == 1 and out == "" and len(lines) == 1, err
    assert "sign(x_d)" in lines[0] and "sticking under Coulomb friction" in lines[0], lines[0]
    # pulled past the friction's bound (k x = 2 N > 0.98 N) it slides, and the motion answers
    rc, out, err = run_cli("simulate", str(path), "--t-end", "0.05", "--perturb", "x=0.1", "--json")
    assert rc == 0, err
    import json

    x = np.array(json.loads(out)["x"])
    assert x[0] == 0.1 and x[-1] < 0.1
