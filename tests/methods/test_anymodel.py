"""Any model a user writes (issue: models from a path, Campbell diagrams of any spin, modes,
no silent wrong answer on damped models), on the rigid rotor of examples/rigid_rotor.py:
derived once per session from its file through gyro.load (the command line's path), and
checked against its closed form, the 4x4 quadratic eigenproblem solved directly.

Tolerances. The closed-form operator is a few products of the parameters (entries of order
1 to 3e6): equal to rounding, 1e-12 relative to the largest entry. Eigenvalues of the
closed form by LAPACK on the balanced 8x8 companion matrix of a well-separated spectrum
(gaps over 50 rad/s at |lambda| ~ 500) err by ~ 1e2 eps |lambda|; 1e-10 relative is two
orders above that and below any formula error (a dropped damping or gyroscopic term moves a
root by more than 1e-3)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gyro import ladder
from tests.conftest import ROOT, run_cli, error_lines

ROTOR_FILE = ROOT / "examples" / "rigid_rotor.py"


@pytest.fixture(scope="session")
def rotor():
    import gyro

    return gyro.load(ROTOR_FILE)


def closed_form(v: dict):
    """M, D, K of the rigid rotor over (x, y, alpha, beta) by hand (examples/rigid_rotor.py)."""
    a, b = v["a"], v["b"]
    M = np.diag([v["m"], v["m"], v["It"], v["It"]])

    def springs(kx1, ky1, kx2, ky2):
        return np.array([[kx1 + kx2, 0, 0, b * kx2 - a * kx1],
                         [0, ky1 + ky2, a * ky1 - b * ky2, 0],
                         [0, a * ky1 - b * ky2, a**2 * ky1 + b**2 * ky2, 0],
                         [b * kx2 - a * kx1, 0, 0, a**2 * kx1 + b**2 * kx2]])

    K = springs(v["kx1"], v["ky1"], v["kx2"], v["ky2"])
    D = springs(v["cx1"], v["cy1"], v["cx2"], v["cy2"])
    D[2, 3] += v["Ip"] * v["Omega"]
    D[3, 2] -= v["Ip"] * v["Omega"]
    return M, D, K


def exact_roots(M, D, K):
    """The eigenvalues of the quadratic eigenproblem with Im > 0, ascending by |lambda|."""
    n = len(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, D)]])
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 0]
    return lam[np.argsort(np.abs(lam))]


def test_a_model_file_loads_and_its_operator_is_the_closed_form(rotor):
    v = rotor.parameters({"Omega": 450.0})
    M, D, K = rotor.numpy.operator(rotor.vector(v)[None], np.zeros((1, 0)))
    for got, want in zip((M[0], D[0], K[0]), closed_form(v)):
        assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))
    assert rotor.meta["spin"] == {"parameter": "Omega", "rate": "Omega", "whirl": [["x", "y"], ["alpha", "beta"]]}


@pytest.mark.parametrize("method", ["polyroots", "companion", "default"])
def test_damped_rotor_within_the_stated_bound_or_no_verdict(rotor, method):
    """The silent wrong answer: polyroots fitted det J(i w) as real, 4.9 % off at 450 rad/s
    while claiming 1e-11. Every method's answer must lie within its own bound (or the bound
    is infinite and the verdict 'unknown'); growth rates are those of the damped rotor."""
    for omega in (0.0, 450.0, 1200.0):
        v = rotor.parameters({"Omega": omega})
        lam = exact_roots(*closed_form(v))
        s = ladder.spectrum(rotor, rotor.vector(v), method)
        got = s.growth[0] + 1j * s.frequencies[0]
        err = np.abs(got - lam) / np.abs(lam)
        bound = s.error_estimate[0]
        assert np.all(err <= np.maximum(bound, 1e-15) * 10), (method, omega, err, bound)  # 10: a first-order bound
        label = ladder.classify(s).label[0]
        assert label == ("stable" if np.all(np.isfinite(bound)) else "unknown")


def test_the_formulas_refuse_a_model_without_them_through_every_entry(rotor):
    with pytest.raises(gyro_error()) as exc:
        ladder.spectrum(rotor, rotor.vector(), "formulas")
    assert "has no approximate formulas" in str(exc.value) and "\n" not in str(exc.value)
    rc, out, err = run_cli("frequencies", str(ROTOR_FILE), "--method", "formulas")
    assert rc == 2 and "formulas" in err and len(error_lines(err)) == 1


def gyro_error():
    from gyro.errors import ParameterError

    return ParameterError


def test_models_from_anywhere_at_the_command_line(rotor, tmp_path):
    rc, out, err = run_cli("frequencies", str(ROTOR_FILE), "--set", "Omega=450", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    lam = exact_roots(*closed_form(rotor.parameters({"Omega": 450.0})))
    assert np.allclose(doc["frequencies"], lam.imag, rtol=1e-12, atol=0)
    rc, out, err = run_cli("params", str(rotor.directory))  # the emitted folder itself
    assert rc == 0 and "Omega" in out
    for bad, word in ((tmp_path / "none.py", "none.py"), (ROOT / "README.md", "README.md")):
        rc, out, err = run_cli("frequencies", str(bad))
        assert rc == 2 and word in err and len(error_lines(err)) == 1 and out == ""
    notmodel = tmp_path / "notmodel.py"
    notmodel.write_text("x = 1\n")
    rc, out, err = run_cli("frequencies", str(notmodel))
    assert rc == 2 and "not a model" in err.strip().splitlines()[-1] and out == ""


@pytest.fixture(scope="session")
def example(rotor):
    """The worked example of docs/rotordynamics.md (examples/rigid_rotor.py's analyse) on 31
    spins: its Campbell diagram with the 1x line, its unbalance response, and the worst
    relative errors against the closed form that it measures."""
    from derive.__main__ import load_file

    return load_file(ROTOR_FILE).analyse(rotor, points=31)


@pytest.fixture(scope="session")
def rotor_campbell(example):
    return example[0]


def test_the_worked_example_against_its_closed_form(example):
    """Frequencies (the 4x4 quadratic eigenproblem), critical speeds and the unbalance response
    (a complex 4x4 solve of J(i W) X = B u) agree with the closed form: frequencies to the
    default method's bound (1e-10), crossings as argued below, the unbalance response to a few
    hundred ulps of its largest amplitude (LAPACK's solve of a system with condition ~1e3 on
    the example's damping: 1e-12 is two orders above)."""
    _, response, err = example
    assert err["frequencies"] <= 1e-10 and err["crossings"] <= 1e-10 and err["unbalance"] <= 1e-12
    assert response.X.shape == (31, 4) and not response.resonance.any()


def test_campbell_crossings_are_the_closed_forms_critical_speeds(rotor, rotor_campbell):
    """Each crossing: at its spin, the closed form has a root with Im(lambda) = k Omega. Brent's
    method stops at 4 eps relative in Omega; the root's slope in Omega is below 1, so the
    mismatch is ~1e-15 relative; 1e-10 allows the default method's bound (1e-10) and no
    more. A crossing read off the 50 rad/s grid would be off by up to 1e-2."""
    d = rotor_campbell
    assert {(c.k, c.mode) for c in d.crossings} == {(1, j) for j in (1, 2, 3, 4)}
    for c in d.crossings:
        lam = exact_roots(*closed_form(rotor.parameters({"Omega": c.value})))
        assert np.min(np.abs(lam.imag - c.k * c.value)) <= 1e-10 * c.k * c.value
        assert c.spin_rate == c.value and abs(c.frequency - c.k * c.value) <= 1e-10 * c.frequency


def test_campbell_tracks_modes_and_tells_whirl_from_the_gyroscopic_effect(rotor, rotor_campbell):
    """Tracked, not sorted: each column is one mode (its eigenvector's MAC with the next point's
    stays near 1). Forward whirl stiffens with spin, backward softens (Ip Omega couples the
    tilts): the frequency of every point labelled forward rises, of every backward one falls,
    at high spin where the gyroscopic term dominates the bearing anisotropy."""
    from gyro.analyses.campbell import mac

    d = rotor_campbell
    t = d.tracked
    for i in range(len(d.Omega) - 1):
        m = np.diag(mac(t.modes[i], t.modes[i + 1]))
        assert np.all(m > 0.9), (i, m)
    lam = np.array([exact_roots(*closed_form(rotor.parameters({"Omega": w})))
                    for w in d.values_swept])
    assert np.allclose(np.sort(t.frequencies, axis=1), lam.imag, rtol=1e-10, atol=0)
    slope = np.diff(t.frequencies, axis=0)[-5:]
    wh = d.whirl[-6:-1]
    assert np.all(slope[wh == "forward"] > 0) and np.all(slope[wh == "backward"] < 0)
    assert (wh == "forward").any() and (wh == "backward").any()
    assert list(d.whirl[0]) == ["mixed"] * 4  # no spin: no gyroscopic coupling, flat orbits
    zeta = t.damping_ratio()
    assert np.allclose(zeta, -lam_tracked(t).real / np.abs(lam_tracked(t)))
    assert np.allclose(t.log_dec(), 2 * np.pi * zeta / np.sqrt(1 - zeta**2), rtol=1e-12)


def lam_tracked(t):
    return t.growth + 1j * t.frequencies


def test_campbell_json_contract_and_bad_input(rotor, tmp_path):
    rc, out, err = run_cli("campbell", str(ROTOR_FILE), "--spin-range", "0", "1000", "--points", "6",
                           "--harmonics", "1", "--json", "--out", str(tmp_path / "c.png"), "--quiet")
    assert rc == 0, err
    doc = json.loads(out)
    assert set(doc) >= {"model", "spin", "values", "spin_rate", "frequencies", "growth", "damping_ratio",
                        "log_dec", "whirl", "crossings"}
    assert doc["spin"] == "Omega" and doc["values"][0] == 0.0 and len(doc["frequencies"]) == 6
    assert set(doc["crossings"][0]) == {"k", "mode", "value", "spin_rate", "frequency", "branch"}
    assert (tmp_path / "c.png").read_bytes()[:4] == b"\x89PNG"
    for args, word in ((["--spin-range", "-1", "10"], "--spin-range"), (["--spin", "m"], "--spin"),
                       (["--spin", "nope"], "--spin"), (["--harmonics", "1,x"], "--harmonics"),
                       (["--spin-range", "0", "10"], "--out")):
        extra = [] if word == "--out" else ["--json"]
        rc, out, err = run_cli("campbell", str(ROTOR_FILE), *args, *extra, "--quiet")
        assert rc == 2 and word in err and len(error_lines(err)) == 1 and out == "", (args, err)


def test_modes_are_the_closed_forms_eigenvectors(rotor):
    """`gyro frequencies --modes`: J(lambda) x = 0 for each mode of the closed form, to the
    rounding of J (entries up to 3e6: |J x| <= 1e-9 |J|, |x| = 1)."""
    rc, out, err = run_cli("frequencies", str(ROTOR_FILE), "--set", "Omega=450", "--modes", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    M, D, K = closed_form(rotor.parameters({"Omega": 450.0}))
    for w, g, mode in zip(doc["frequencies"], doc["eigenvalues_re"], doc["modes"]):
        lam = g + 1j * w
        x = np.array(mode["re"]) + 1j * np.array(mode["im"])
        J = M * lam**2 + D * lam + K
        assert abs(np.linalg.norm(x) - 1) < 1e-12
        assert np.linalg.norm(J @ x) <= 1e-9 * np.abs(J).max()
    assert doc["coordinates"] == ["x", "y", "alpha", "beta"] and len(doc["damping_ratio"]) == 4
    rc, out, err = run_cli("frequencies", str(ROTOR_FILE))
    assert "damping ratio" in out and "log. decr." in out


def test_a_steady_coordinates_own_zero_root_does_not_make_a_decaying_system_marginal():
    """The zero root a steadily turning coordinate owns (K e_c = 0 by construction) is marked,
    shown for what it is, and leaves the verdict to the other roots; a second root that is
    not resolved from zero (-3 with a relative error of 1) is a boundary all the same:
    rounding decides whether it is a zero root or a decay (gyro.results.verdict)."""
    from types import SimpleNamespace

    from gyro.ladder import steady_roots
    from gyro.results import Spectrum, classify

    model = SimpleNamespace(name="spun", meta={"steady": {"phi": "Omega"}, "title": "t", "reduced": ["x", "phi"],
                                               "functions": {"operator_parts": {}},
                                               "equilibrium_coordinates": []})
    f = np.array([[0.0, 250.0], [0.0, 0.0]])
    g = np.array([[0.0, -12.0], [0.0, -3.0]])
    e = np.array([[0.0, 1e-15], [1.0, 1.0]])
    spec = steady_roots(model, Spectrum("default", f, g, e))
    assert spec.steady.tolist() == [[True, False], [True, False]]
    assert list(classify(spec).label) == ["stable", "boundary"]
    assert "its own zero root" in spec.table(0, model) and "equilibrium: stable" in spec.table(0, model)
    assert list(classify(Spectrum("default", f, g, e)).label) == ["marginal", "boundary"]  # unmarked


def test_fuzz_leftovers():
    """A sweep whose sets escalate to 40 digits stops at its budget in one line; 'unknown' at
    the default method does not advise the default method; a zero answer for a root that is
    not zero carries the bound 1."""
    import gyro
    from gyro.analyses.campbell import SweepBudget, batch_default

    tg = gyro.load("torsion_gyrocompass")
    P = np.tile(tg.vector(), (40, 1))
    P[:, tg.param_names.index("A")] = np.geomspace(1e-300, 1e-200, 40)
    with pytest.raises(SweepBudget, match="would take about"):
        batch_default(tg, P, budget=0.2, watch=0.0)
    rc, out, err = run_cli("frequencies", "torsion_gyrocompass", "--set", "A=1e-300")
    assert "unknown" in out and "try --method default" not in out
    rc, out, err = run_cli("frequencies", "torsion_gyrocompass", "--set", "u=5e-324", "--json")
    doc = json.loads(out)
    assert doc["frequencies"][0] == 0.0 and doc["error_estimate"][0] >= 1.0
