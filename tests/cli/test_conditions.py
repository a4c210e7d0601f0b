"""`gyro stability` and `gyro map` for any model that declares sufficient conditions (issue 37,
items 1 and 5): a model file written outside the package (tests/models/symmetric_top.py, a
heavy symmetric top sleeping about the vertical with Maievski's condition C^2 n^2 > 4 A m g l
declared, the spin rate n a parameter) against the hand computation; a model without conditions refused in one line; no
built-in model known by name in the generic commands.

Tolerances. Away from the critical spin the tilt roots are simple, and LAPACK finds them to a
few eps of |lambda| (4 to 11 1/s here): 1e-9 relative on the growth rate is far above that
and far below any wrong formula (a growth of s/2, or the |Re| of another root, is off by
O(1)). The margin C^2 r^2 - 4 A m g l is a difference of two products of decimal inputs:
within its declared rounding bound 10 u (C^2 r^2 + 4 A m g l) of the exact value.
"""
from __future__ import annotations

import ast
import json
import math

import numpy as np
import pytest

from tests.conftest import ROOT, run_cli, error_lines

TOP = str(ROOT / "tests" / "models" / "symmetric_top.py")
A, C, M, G, L = 0.025, 0.01, 1.0, 10.0, 0.04  # the critical spin is 20 rad/s exactly: 4 A m g l = 0.04
FIXED = {"A": A, "g": G}  # C and m are the model's defaults
SETS = [f"--set={k}={v}" for k, v in {**FIXED, "l": L}.items()]
R_C = 20.0
U = 2.0**-53
LABEL = "C^2 n^2 - 4 A m g l"


def growth(r, l=L):
    """The tilts' growth rate below the critical spin r: sqrt(4 A m g l - C^2 r^2)/(2 A)."""
    return math.sqrt(4 * A * M * G * l - (C * r)**2) / (2 * A)


def stability(*args):
    rc, out, err = run_cli("stability", TOP, *SETS, *args, "--json")
    assert rc == 0, err
    return json.loads(out)


def test_above_the_critical_spin_the_declared_condition_holds():
    """n = 30 (A = 0.025, g = 10, l = 0.04): the margin C^2 n^2 - 4 A m g l = 0.05 (its bound 10 u (C^2 r^2 + 4 A m g l),
    the rule k sum |t| with d = 4 factors and N = 2 terms), stable by the condition; the
    roots are i (C r +- sqrt(C^2 r^2 - 4 A m g l))/(2 A) and their conjugates, and the spin's
    own double zero root."""
    d = stability("--set", "n=30")
    assert d["verdict"] == "stable" and d["sufficient"] and d["spectrally_stable"] and not d["boundary"]
    assert math.isclose(d["conditions"][LABEL], (C * 30)**2 - 4 * A * M * G * L, rel_tol=1e-14)
    assert math.isclose(d["margin_bounds"][LABEL], 10 * U * ((C * 30)**2 + 4 * A * M * G * L), rel_tol=1e-12)
    root = math.sqrt((C * 30)**2 - 4 * A * M * G * L)
    want = sorted([(C * 30 + root) / (2 * A), (C * 30 - root) / (2 * A)] * 2 + [0.0, 0.0])
    got = sorted(abs(im) for _, im in d["eigenvalues"])
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12)
    assert max(abs(re) for re, _ in d["eigenvalues"]) < 1e-12
    assert d["equilibrium"] == {"alpha": 0.0, "beta": 0.0}


@pytest.mark.parametrize("r", [10.0, 15.0, 19.8])
def test_below_the_critical_spin_unstable_at_the_hand_growth_rate(r):
    """The margin decidedly negative, and the spectrum certainly unstable: its largest real
    part is s = sqrt(4 A m g l - C^2 r^2)/(2 A) (module doc: 1e-9)."""
    d = stability("--set", f"n={r}")
    assert d["verdict"] == "unstable" and not d["sufficient"] and not d["spectrally_stable"]
    assert d["conditions"][LABEL] < -d["margin_bounds"][LABEL]
    assert math.isclose(max(re for re, _ in d["eigenvalues"]), growth(r), rel_tol=1e-9)


def test_boundary_only_where_rounding_decides():
    """At the critical spin itself (decimal inputs with C^2 r^2 = 4 A m g l exactly) the
    margin lies within its rounding bound and the double roots +-4i merge: a boundary,
    naming the margin. Off it by a relative 1e-2 .. 1e-12 on either side the verdict is
    decided and right (stable above, unstable below at the hand growth rate): a boundary
    only within 1e-12 of the critical spin, where the spectrum's error radii (a double root
    moves by sqrt(u) |lambda|) cannot resolve the split."""
    from gyro import load
    from gyro.analyses import conditions

    d = stability("--set", "n=20")
    assert d["verdict"] == "boundary" and d["boundary"] and LABEL in d["boundary_reason"]
    rc, out, _ = run_cli("stability", TOP, *SETS, "--set", "n=20")
    assert rc == 0 and out.splitlines()[-1].startswith("boundary: rounding could change the verdict (the margin")
    model = load(TOP)
    offsets = np.array([s * 10.0**-k for k in range(2, 17) for s in (1, -1)])
    r = R_C * (1 + offsets)
    a = conditions.analyse(model, model.vectors([{**FIXED, "l": L, "n": x} for x in r]))
    label = a["verdict"].label
    assert set(label) <= {"stable", "unstable", "boundary"}
    assert np.all(np.abs(offsets[label == "boundary"]) < 1e-12)
    far = np.abs(offsets) >= 1e-12
    assert np.all(label[far & (offsets > 0)] == "stable") and np.all(a["sufficient"][far & (offsets > 0)])
    below = far & (offsets < 0)
    assert np.all(label[below] == "unstable")
    want = np.array([growth(x) for x in r[below]])
    # near the double root the split s is known to the root's condition (|lambda| u / s):
    # 1e-6 relative at s = 5.7e-6 (offset 1e-12), 1e-9 at offsets above 1e-6
    assert np.allclose(a["growth"][below], want, rtol=1e-6)
    assert np.allclose(a["growth"][below & (np.abs(offsets) >= 1e-6)], want[np.abs(offsets[below]) >= 1e-6], rtol=1e-9)


def test_map_over_spin_and_length_borders_at_the_hand_formula(tmp_path):
    """Over n in [5, 40] and l in [0.01, 0.1] (A = 0.025, g = 10): 2 exactly where C^2 n^2 > 4 A m g l, 0 where
    below (the sleeping top has no gyroscopic stabilisation outside Maievski's condition:
    it is necessary and sufficient), -1 only where the border passes through a grid point
    (n = 10, l = 0.01: C^2 n^2 = 4 A m g l at the decimal inputs); the growth rate of each
    unstable point the hand formula's."""
    from gyro import load
    from gyro.analyses import conditions

    out = tmp_path / "top.png"
    rc, so, err = run_cli("map", TOP, *SETS[:2], "--x", "n=5:40:15", "--y", "l=0.01:0.1:10", "--out", str(out), "--json")
    assert rc == 0, err
    d = json.loads(so)
    assert d["x"]["name"] == "n" and d["y"]["name"] == "l" and "Maievski" in d["kind"]
    v = np.array(d["values"])
    Rg, Lg = np.meshgrid(d["x"]["values"], d["y"]["values"])
    margin = (C * Rg)**2 - 4 * A * M * G * Lg
    assert np.array_equal(v == -1, np.array(d["boundary"]))
    assert v[0, 2] == -1 and Rg[0, 2] == 10.0 and Lg[0, 2] == 0.01
    assert np.all(np.abs(margin[v == -1]) < 1e-15)
    decided = v != -1
    assert np.array_equal(v[decided] == 2, margin[decided] > 0)
    assert np.array_equal(v[decided] == 0, margin[decided] < 0)
    assert out.stat().st_size > 1000
    rc, so, _ = run_cli("map", TOP, *SETS[:2], "--x", "n=5:40:15", "--y", "l=0.01:0.1:10", "--out", str(out))
    assert rc == 0 and so.startswith(f"gyro: wrote {out} (150 points: ") and "where Maievski holds" in so
    grid = conditions.condition_map(load(TOP), FIXED, ("n", 5, 40, 15), ("l", 0.01, 0.1, 10))
    unstable = grid.values == 0
    want = np.sqrt(np.where(unstable, -margin, 0.0)) / (2 * A)
    assert np.allclose(grid.growth[unstable], want[unstable], rtol=1e-9)


@pytest.mark.parametrize("cmd", ["stability", "map"])
def test_a_model_without_conditions_is_refused_in_one_line(cmd):
    extra = [] if cmd == "stability" else ["--x", "k=1:2:3", "--y", "m=1:2:3", "--out", "x.png"]
    path = str(ROOT / "tests" / "models" / "damped_oscillator.py")
    rc, out, err = run_cli(cmd, path, *extra)
    assert rc == 2 and out == "" and len(error_lines(err)) == 1 and "Traceback" not in err
    assert "damped_oscillator declares no conditions (Model.conditions" in err


@pytest.mark.parametrize("args, needle", [
    (["stability", TOP, "--orbit"], "--orbit: symmetric_top has no orbit option"),
    (["map", TOP, "--x", "n=5:40:3", "--y", "l=0.01:0.1:3", "--out", "x.png", "--orbit"],
     "--orbit: symmetric_top has no orbit option"),
    (["stability", TOP, "--set", "nosuch=1"], "nosuch"),
    (["map", TOP, "--x", "n=5:40:3", "--y", "n=0.01:0.1:3", "--out", "x.png"], "both"),
    (["map", TOP, "--x", "n=5:40:3", "--y", "l=0.01:0.1:3", "--set", "l=1", "--out", "x.png"], "is an axis"),
    (["map", TOP, "--x", "n=5:40:3", "--y", "theta=0.01:0.1:3", "--out", "x.png"], "theta"),
    (["map", TOP, "--x", "n=5:40:3", "--y", "l=-1:0.1:3", "--out", "x.png"], "parameter l"),
])
def test_bad_input_exits_2_with_one_line(args, needle, tmp_path):
    args = [str(tmp_path / a) if a == "x.png" else a for a in args]
    rc, out, err = run_cli(*args)
    assert rc == 2 and out == "" and len(error_lines(err)) == 1, err
    assert needle in err and "Traceback" not in err
    assert not (tmp_path / "x.png").exists()


def test_help_says_which_declaration_they_need():
    for cmd in ("stability", "map"):
        rc, out, _ = run_cli(cmd, "--help")
        assert rc == 0 and "Model.conditions" in " ".join(out.split())


def test_no_built_in_model_in_the_generic_commands():
    """The commands and the analysis know no model by name and import no system's module:
    what only one system has comes through its declaration `system`."""
    from gyro.catalog import available

    for rel in ("gyro/cli/stability.py", "gyro/cli/map.py", "gyro/analyses/conditions.py"):
        text = (ROOT / rel).read_text()
        assert not [name for name in available() if name in text], rel
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
                assert not [n for n in names if n.startswith("gyro.systems")], rel


def test_rounding_bound_of_a_margin():
    """derive/outputs/conditions.py's rule, k sum |t| with k = 2 d + N: C^2 r^2 - 4 A m g l has
    d = 4, N = 2; a 'real' parameter to an odd power enters as |p|; a margin that is no
    Laurent polynomial in the parameters is refused (no rule for it)."""
    import sympy as sp

    from derive.model import Parameter, Unsupported
    from derive.outputs.conditions import rounding_scale

    ps = [Parameter("a", "1", 1.0, "a"), Parameter("b", "1", 1.0, "b", kind="real")]
    a, b = (p.symbol for p in ps)
    assert sp.simplify(rounding_scale(a**2 * b**2 - 4 * a, ps) - 10 * (a**2 * b**2 + 4 * a)) == 0
    assert sp.simplify(rounding_scale(b**3 - a / 3, ps) - 8 * (sp.Abs(b)**3 + a / 3)) == 0
    with pytest.raises(Unsupported, match="Laurent polynomial"):
        rounding_scale(sp.sqrt(a) - 1, ps)


DAMPED = '''"""A damped oscillator m x'' + c x' + k x = 0 whose stiffness may be negative, with two
declared sets: c > 0 and k > 0 (Routh-Hurwitz for m p^2 + c p + k), and one with 1/c."""
import sympy as sp

from derive.model import Conditions, Model, Parameter

PARAMETERS = [Parameter("m", "kg", 2.0, "mass"),
              Parameter("c", "N s/m", 0.3, "damping", kind="nonnegative"),
              Parameter("k", "N/m", 50.0, "stiffness", kind="real")]
m, c, k = (p.symbol for p in PARAMETERS)
x, x_d, x_dd = sp.symbols("x x_d x_dd")


def build():
    return Model(name="damped_conditions", title="Damped oscillator with conditions", source="textbook",
                 module=__name__, parameters=PARAMETERS, coordinates=["x"], coordinate_units={"x": "m"},
                 q=[x], qd=[x_d], qdd=[x_dd], lagrangian=m * x_d**2 / 2 - k * x**2 / 2,
                 dissipation=c * x_d**2 / 2, symmetric_zero=["x"],
                 conditions={"Routh-Hurwitz": Conditions([("c", c), ("k", k)]),
                             "over c": Conditions([("k - 1/c", k - 1 / c)])})
'''


def test_a_damped_model_any_set_decides_and_a_margin_without_a_value_is_refused(tmp_path):
    """A damped (not conservative) operator: every root must lie left of the axis. At the
    defaults both sets hold: stable, roots -c/(2 m) +- i sqrt(k/m - c^2/(4 m^2)); with
    k = -1 both fail and the root (-c + sqrt(c^2 - 4 m k))/(2 m) grows (1e-12: a 1x1
    problem's roots); at c = 0 the margin k - 1/c has no value: one line, exit 2."""
    path = tmp_path / "damped_conditions.py"
    path.write_text(DAMPED)
    rc, out, err = run_cli("stability", str(path), "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["verdict"] == "stable" and d["sufficient"] and list(d["conditions"]) == ["c", "k", "k - 1/c"]
    w = math.sqrt(50 / 2 - 0.3**2 / 16)
    assert np.allclose(sorted(d["eigenvalues"]), [[-0.075, -w], [-0.075, w]], rtol=1e-12)
    rc, out, err = run_cli("stability", str(path), "--set", "k=-1", "--json")
    d = json.loads(out)
    assert rc == 0 and d["verdict"] == "unstable" and not d["sufficient"]
    assert math.isclose(max(re for re, _ in d["eigenvalues"]), (-0.3 + math.sqrt(0.09 + 8)) / 4, rel_tol=1e-12)
    rc, out, err = run_cli("stability", str(path), "--set", "c=0")
    assert rc == 2 and out == "" and len(error_lines(err)) == 1
    assert "the margin k - 1/c of damped_conditions is not finite" in err and "inf" not in err.replace("finite", "")
    # a declared system that is not there: refused when the model file is derived, one line
    path.write_text(DAMPED.replace('symmetric_zero=["x"],', 'symmetric_zero=["x"], system="gyro.systems.nosuch",'))
    rc, out, err = run_cli("stability", str(path))
    assert rc == 2 and out == "" and len(error_lines(err)) == 1 and "Traceback" not in err
    assert "the declared module 'gyro.systems.nosuch' cannot be found" in err
