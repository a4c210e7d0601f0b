"""Right on every model (issue 37, item 3), on model files written outside the package
(tests/models/) and on examples/rigid_rotor.py, against hand computations.

Tolerances. The cubic spring's equilibrium x_e = -(F/k)^(1/3) is a Newton iterate converged
to steps below 1e-14 of x_e, and omega = sqrt(3 k^(1/3) F^(2/3) / m) a root of a 1x1
problem found to a few eps: 1e-12 relative is two orders above rounding and far below any
wrong branch or formula (another root of k x^3 = -F is complex; a wrong K is off by O(1)).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from gyro import cbackend
from tests.conftest import ROOT, run_cli, error_lines

MODELS = ROOT / "tests" / "models"
CUBIC = str(MODELS / "cubic_spring.py")
FALL = str(MODELS / "free_fall.py")


def load(path):
    import gyro

    return gyro.load(path)


def _without_c_iteration(fn, *args):
    """fn(*args) with the C Newton iteration unavailable: the NumPy iteration alone."""
    def unavailable(name):
        raise cbackend.CompilerUnavailable("the C iteration left out")

    real = cbackend.equilibrium_newton
    cbackend.equilibrium_newton = unavailable
    try:
        return fn(*args)
    finally:
        cbackend.equilibrium_newton = real


def cubic_sets(model):
    """(m, k, F) with F of both signs and over decades: x_e = -(F/k)^(1/3)."""
    rows = [(2.0, 8.0, 1.0), (1.0, 2.0, -3.0), (0.5, 1e3, 1e-4), (3.0, 1e-2, 250.0)]
    return np.array([model.vector(dict(zip(("m", "k", "F"), r))) for r in rows])


# --------------------------------------------------------------------------- equilibrium


@pytest.mark.parametrize("path", ["c", "numpy"])
def test_cubic_spring_equilibrium_where_newton_cannot_start(path):
    """K = 3 k x^2 is zero at the start x = 0: the least-squares step is zero and Newton
    came to rest there (x = 0, omega = 0, 'marginal'). The residual at the answer is F, all
    of its terms: refused, and the solver starts again elsewhere, finding x_e each set, in a
    batch as alone, on the C path and the NumPy path alike."""
    from gyro.equilibrium import equilibria

    model = load(CUBIC)
    P = cubic_sets(model)
    solve = equilibria if path == "c" else (lambda m, p: _without_c_iteration(equilibria, m, p))
    qe, ok = solve(model, P)
    m, k, F = P.T
    want = -np.cbrt(F / k)
    assert ok.all()
    assert np.all(np.abs(qe[:, 0] - want) <= 1e-12 * np.abs(want)), (qe[:, 0], want)
    for i in range(len(P)):
        alone, ok1 = solve(model, P[i:i + 1])
        assert ok1[0] and np.array_equal(alone[0], qe[i])


def test_cubic_spring_frequency_is_the_hand_one():
    rc, out, err = run_cli("frequencies", CUBIC, "--set", "F=-3", "--set", "k=2", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    m, k, F = 2.0, 2.0, -3.0
    assert abs(doc["equilibrium"]["x"] - np.cbrt(-F / k)) <= 1e-12 * np.cbrt(-F / k)
    omega = np.sqrt(3 * np.cbrt(k) * np.cbrt(F * F) / m)
    assert abs(doc["frequencies"][0] - omega) <= 1e-12 * omega
    assert doc["stability"]["class"] == "stable"


def test_free_fall_has_no_equilibrium():
    """m x'' = -m g: no point of rest. Refused in one line naming the equation's residual
    (-m g = -19.62 N at the defaults), exit 1, nothing on stdout; with g = 0 every x is an
    equilibrium (K = 0 and the residual exactly zero: a family, as the gyrocompass's free
    azimuth at g = 0), answered with its zero root."""
    from gyro.equilibrium import equilibria

    model = load(FALL)
    for args in ((), ("--json",)):
        rc, out, err = run_cli("frequencies", FALL, *args)
        assert rc == 1 and out == "" and len(error_lines(err)) == 1, (rc, out, err)
        assert "no equilibrium" in err and "equation of x keeps a residual of -19.6" in err, err
    P = np.array([model.vector({"g": 9.81}), model.vector({"g": 0.0}), model.vector({"g": -1.0})])
    for solve in (equilibria, lambda m, p: _without_c_iteration(equilibria, m, p)):
        qe, ok = solve(model, P)
        assert ok.tolist() == [False, True, False] and np.isnan(qe[[0, 2]]).all() and qe[1, 0] == 0.0
    rc, out, err = run_cli("frequencies", FALL, "--set", "g=0", "--json")
    assert rc == 0 and json.loads(out)["stability"]["class"] == "marginal", err


# --------------------------------------------------------------------------- modes

TOP = str(MODELS / "symmetric_top.py")
TOP_DEFAULTS = dict(A=0.02, C=0.01, m=1.0, g=9.81, l=0.05)


def top_roots(n, A, C, m, g, l):
    """The tilt block's roots, (A p^2 - m g l)^2 + (C n p)^2 = 0 (tests/models/symmetric_top.py):
    A p^2 -+ i C n p - m g l = 0, p = (+-i C n +- sqrt(4 A m g l - C^2 n^2)) / (2 A)."""
    s = np.sqrt(complex(4 * A * m * g * l - (C * n) ** 2))
    return np.array([(sa * 1j * C * n + sb * s) / (2 * A) for sa in (1, -1) for sb in (1, -1)])


def test_a_mode_is_a_conjugate_pair_whatever_re_and_im():
    """The issue's roots +-11.83 +- 7.5i: two modes, one growing and one decaying (the
    decaying pair was dropped where |Re| > |Im|, the growing one shown twice); a real pair
    +-s: its growing member; LAPACK's exact conjugates and a rounded real root alike."""
    from gyro.qep import representatives

    lam = np.array([11.83 + 7.5j, 11.83 - 7.5j, -11.83 + 7.5j, -11.83 - 7.5j])
    assert sorted(representatives(lam, 2), key=lambda z: z.real) == [-11.83 + 7.5j, 11.83 + 7.5j]
    lam = np.array([-3.0, 3.0, 2j, -2j])
    assert sorted(representatives(lam, 2), key=abs) == [2j, 3.0]
    lam = np.array([-3.0 - 1e-20j, 3.0 + 1e-20j, 5.0 - 1e-20j, -5.0 + 1e-20j])  # two divergent pairs
    assert sorted(representatives(lam, 2).real) == [3.0, 5.0]


@pytest.mark.parametrize("n", [10.0, 15.0])
def test_sleeping_top_below_its_critical_spin_has_one_growing_mode(n):
    """Below the critical spin C n < 2 sqrt(A m g l) (19.81 rad/s) the tilts flutter: roots
    +-s +- i w, s = sqrt(4 A m g l - C^2 n^2) / (2 A), w = C n / (2 A); at n = 10, |Re| > |Im|
    (4.27 > 2.5), at n = 15, |Re| < |Im| (3.23 < 3.75): one growing mode either way, and the
    decaying one shown with it (1e-12: a 2x2 block's roots, module doc)."""
    rc, out, err = run_cli("frequencies", TOP, "--set", f"n={n}", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    want = top_roots(n, **TOP_DEFAULTS)
    s, w = abs(want[0].real), abs(want[0].imag)
    got = np.array(doc["eigenvalues_re"]) + 1j * np.array(doc["frequencies"])
    steady = doc["steady_roots"]
    assert steady == [0] and got[0] == 0
    assert np.allclose(sorted(got[1:], key=lambda z: z.real), [-s + 1j * w, s + 1j * w], rtol=1e-12, atol=0)
    assert doc["stability"]["class"] == "unstable" and doc["stability"]["unstable_roots"] == 1
    assert abs(doc["stability"]["growth_rate"] - s) <= 1e-12 * s


def test_the_count_of_growing_modes_has_no_border_at_re_equal_im():
    """Across |Re| = |Im| (n = sqrt(2 A m g l) / C = 14.0 rad/s) the count stays one; at
    n = 0 the two tilts fall each on its own (two real pairs +-sqrt(m g l / A)): two."""
    from gyro import ladder

    model = load(TOP)
    spins = [0.0, 5.0, 13.9, 14.1, 19.0]
    P = np.array([model.vector({"n": n}) for n in spins])
    c = ladder.classify(ladder.spectrum(model, P))
    assert list(c.label) == ["unstable"] * 5 and list(c.unstable_roots) == [2, 1, 1, 1, 1]


# --------------------------------------------------------------------------- boundaries and crashes

ROTOR = str(ROOT / "examples" / "rigid_rotor.py")
ISOTROPIC = ("--set", "Omega=0", "--set", "ky1=1e6", "--set", "ky2=1e6")


def rotor_hand_roots(**over):
    """The rotor's roots from its closed form (tests/methods/test_anymodel.py), Im > 0, by |lambda|."""
    from tests.methods.test_anymodel import closed_form, exact_roots

    model = load(ROTOR)
    return exact_roots(*closed_form(model.parameters(over)))


@pytest.mark.parametrize("method", ["default", "reference"])
def test_damped_isotropic_rotor_at_rest_is_stable_not_boundary(method):
    """Isotropic bearings at rest: two double roots (the x-z and y-z planes alike), every
    Re <= -12.7 1/s. A double root well inside the left half-plane cannot change the
    verdict: 'stable' (it was 'boundary: roots 1 and 2 merge'); no equilibrium coordinate:
    the reference method answers (it raised IndexError). The roots are the closed form's,
    within 1e-10 (tests/methods/test_anymodel.py's argument: LAPACK on an 8x8 companion matrix)."""
    rc, out, err = run_cli("frequencies", ROTOR, *ISOTROPIC, "--method", method, "--json")
    assert rc == 0, err
    doc = json.loads(out)
    want = rotor_hand_roots(Omega=0.0, ky1=1e6, ky2=1e6)
    got = np.array(doc["eigenvalues_re"]) + 1j * np.array(doc["frequencies"])
    assert np.all(np.abs(got - want) <= 1e-10 * np.abs(want)), (got, want)
    assert np.max(want.real) < -12 and doc["stability"]["class"] == "stable", doc["stability"]


def test_isotropic_rotor_campbell_and_sweep_run_through_the_double_root():
    rc, out, err = run_cli("campbell", ROTOR, "--set", "ky1=1e6", "--set", "ky2=1e6", "--spin-range", "0", "600",
                           "--points", "3", "--json")
    assert rc == 0 and err == "", err
    doc = json.loads(out)
    want = rotor_hand_roots(Omega=0.0, ky1=1e6, ky2=1e6)
    assert np.allclose(doc["frequencies"][0], want.imag, rtol=1e-10, atol=0)
    rc, out, err = run_cli("sweep", ROTOR, "--set", "ky1=1e6", "--set", "ky2=1e6", "--x", "Omega",
                           "--x-range", "0", "600", "--points", "3", "--json")
    assert rc == 0 and err == "", err


def test_top_at_its_critical_spin_is_a_boundary_quoting_the_table():
    """At n = 2 sqrt(A m g l) / C to the last digit the tilt roots collide on the axis (a
    Jordan block): the 40-digit roots at the given doubles lie on it 1e-9 apart, and inputs
    moved by 4 eps put them off it (by the square root, 1e-8): rounding decides, 'boundary'
    (it raised IndexError in the reference rung), and the reason quotes the roots as the
    table shows them (omega, not |lambda|)."""
    n = 2 * np.sqrt(TOP_DEFAULTS["A"] * TOP_DEFAULTS["m"] * TOP_DEFAULTS["g"] * TOP_DEFAULTS["l"]) / TOP_DEFAULTS["C"]
    rc, out, err = run_cli("frequencies", TOP, "--set", f"n={float(n)!r}")
    assert rc == 0, err
    last = out.strip().splitlines()[-1]
    assert last.startswith("equilibrium: boundary") and "merge" in last, last
    w = 0.01 * n / (2 * 0.02)
    rows = [line.split() for line in out.splitlines() if line.strip()[:1] in "23"]
    quoted = [r[1] for r in rows]
    assert all(q in last for q in quoted) and all(abs(float(q) - w) < 1e-7 * w for q in quoted), (quoted, last)


def test_a_point_newton_circles_is_no_equilibrium_unless_it_balances():
    """The torsion gyrocompass at g = 0 with Kgamma = 1e-9 and K0 = 1e-6 (a set of the fuzz
    test): Newton circles the nearly free azimuth for its 100 steps and stops where the
    equations miss by 5 % of their terms (the gamma2 equation by 2.2e-5 N m at a stiffness
    of 3.2e-5 N m/rad: the angle off by the order of a radian). It was accepted by an
    absolute residual of 1e-9 (1 + max |p|) = 2.4e-4 (Kp = 243360); now refused in one line."""
    from gyro import load as load_builtin
    from gyro.equilibrium import equilibria

    model = load_builtin("torsion_gyrocompass")
    args = ("--set", "Kgamma=1e-09", "--set", "g=0.0", "--set", "K0=1e-06")
    qe, ok = equilibria(model, model.vector(model.parameters({"Kgamma": 1e-9, "g": 0.0, "K0": 1e-6}))[None])
    assert not ok[0] and np.isnan(qe).all()
    rc, out, err = run_cli("frequencies", "torsion_gyrocompass", *args)
    assert rc == 1 and out == "" and len(error_lines(err)) == 1
    assert "did not converge: the equation of" in err and "keeps a residual" in err, err


def test_merged_disks_inside_the_left_half_plane_decide_the_verdict():
    """verdict.spectrum without `conservative`: two rigorous disks that overlap wholly in
    Re z < 0 hold both roots there: stable (was boundary); one that meets the axis stays a
    boundary; with `conservative` an overlap on the axis stays a possible Krein collision."""
    from gyro.results import verdict

    lam = np.array([[-5 + 1j, -5 + 1j], [-1e-4 + 1j, -1e-4 + 1j]])
    v = verdict.spectrum(lam, np.full(lam.shape, 1e-3), conservative=False)
    assert list(v.label) == ["stable", "boundary"]
    v = verdict.spectrum(np.array([[1j, 1j]]), np.full((1, 2), 1e-3), conservative=True)
    assert v.label[0] == "boundary"
    from gyro.results.verdict import cluster_meets_axis

    # a double root at Re -5 known to 1e-10 relative: R = 2 |lambda| 1e-5, far from the axis
    assert not cluster_meets_axis(np.array([[-5 + 1j, -5 + 1j]]), np.full((1, 2), 1e-9), np.full((1, 2), 1e-10)).any()
    # at Re -1e-6 it may reach the axis
    assert cluster_meets_axis(np.array([[-1e-6 + 1j, -1e-6 + 1j]]), np.full((1, 2), 1e-9), np.full((1, 2), 1e-10)).all()


def test_stability_map_of_the_top_is_maievski_with_one_growing_mode(tmp_path):
    """Over the spin n and the offset l: stable where C^2 n^2 > 4 A m g l (Maievski), one
    growing mode below it on both sides of |Re| = |Im| (the map drew 'two or more' where
    |Re| > |Im|, that is C^2 n^2 < 2 A m g l). The grid's points lie at least 1 % (in C^2 n^2 /
    4 A m g l) from the critical spin: the tilt roots are then 0.1 |lambda| apart, or off
    the axis by as much, resolved far beyond their bounds."""
    rc, out, err = run_cli("stability-map", TOP, "--x", "n", "--x-range", "1", "30", "--y", "l", "--y-range",
                           "0.02", "0.08", "--points", "6", "--out", str(tmp_path / "m.png"), "--json")
    assert rc == 0, err
    doc = json.loads(out)
    A, C, m, g = (TOP_DEFAULTS[k] for k in ("A", "C", "m", "g"))
    n, l = np.meshgrid(doc["x"]["values"], doc["y"]["values"])
    margin = C**2 * n**2 / (4 * A * m * g * l) - 1
    assert np.min(np.abs(margin)) > 0.01
    want = np.where(margin > 0, "stable", "unstable")
    assert np.array_equal(np.array(doc["values"]), want)
    assert np.array_equal(np.array(doc["unstable_roots"]), (margin < 0).astype(int))
    assert np.any(C**2 * n**2 < 2 * A * m * g * l)  # the flutter with |Re| > |Im| is on the grid


@pytest.mark.parametrize("method", ["polyroots", "companion", "default", "reference"])
def test_no_method_raises_at_a_double_root(method):
    """Every rung at the isotropic rotor's double roots (no equilibrium coordinates) and at
    the top's collision: an answer, exit 0, each root of the rotor within ten times its own
    bound of the closed form (a first-order bound, as tests/methods/test_anymodel.py allows) or a
    verdict that claims nothing ('unknown'); the top's collision a boundary or no verdict,
    never 'stable' or 'unstable'."""
    rc, out, err = run_cli("frequencies", ROTOR, *ISOTROPIC, "--method", method, "--json")
    assert rc == 0 and "Traceback" not in err, err
    doc = json.loads(out)
    want = rotor_hand_roots(Omega=0.0, ky1=1e6, ky2=1e6)
    got = np.array(doc["eigenvalues_re"]) + 1j * np.array(doc["frequencies"])
    bound = np.array([np.inf if e is None else e for e in doc["error_estimate"]])
    assert doc["stability"]["class"] == "unknown" or np.all(
        np.abs(got - want) <= 10 * np.maximum(bound, 1e-15) * np.abs(want)), (got, want, bound)
    n = 2 * np.sqrt(TOP_DEFAULTS["A"] * TOP_DEFAULTS["m"] * TOP_DEFAULTS["g"] * TOP_DEFAULTS["l"]) / TOP_DEFAULTS["C"]
    rc, out, err = run_cli("frequencies", TOP, "--set", f"n={float(n)!r}", "--method", method, "--json")
    assert rc == 0 and "Traceback" not in err, err
    assert json.loads(out)["stability"]["class"] in ("boundary", "unknown")


def test_a_subnormal_latitude_keeps_its_equilibrium():
    """phi = 2.2e-308 deg (found by the ladder's property test): rows of the residual of
    1e-323 beside terms of 1e-318 have no relative precision left; they are zero to double
    precision's range (equilibrium.SUBNORMAL_FLOOR), and the set is answered by every rung."""
    from gyro import ladder

    model = load("torsion_gyrocompass")
    p = model.vector(model.parameters({"phi": 2.2250738585072014e-308}))[None]
    for method in ("default", "reference"):
        s = ladder.spectrum(model, p, method)
        assert np.all(np.isfinite(s.frequencies)), method
