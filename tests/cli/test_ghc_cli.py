"""The gyrohorizoncompass's item 4 (the conditions (3.6), (4.3) against the spectrum) and the
command-line contract of `gyro stability`, `gyro map` and `gyro simulate gyrohorizoncompass`
(names, keys, exit codes). docs/gyrohorizoncompass.md, section "Item 4"."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gyro.systems import gyrohorizoncompass as ghc
from tests.conftest import run_cli

LAB = {"A": 1.0, "B": 1.05, "C": 1.1, "J": 1.0, "L": 0.5, "I": 1.0, "nu": 1.0, "zeta": 0.5, "eta": 0.2}
LAB_SETS = [f"--set={k}={v}" for k, v in LAB.items()]
BASE = [f"--set={k}={LAB[k]}" for k in ("A", "B", "C", "J", "L", "I", "nu")]


gyro = run_cli  # `gyro ARGS` in this process: (exit code, stdout, stderr)


def _random_sets(rng, n, orbit=False):
    """Sets with an equilibrium: theta, chi in (-0.6, 0.5), lambda = 1 + chi (free in
    (0.2, 1.5) on the orbit)."""
    out = []
    while len(out) < n:
        th, ch = rng.uniform(-0.6, 0.5, 2)
        v = dict(A=2.0 - th, B=2.0 - ch, C=2.0, J=rng.uniform(0.2, 2), L=rng.uniform(0.5, 3), I=1.0, nu=1.0,
                 zeta=rng.uniform(0.05, 1.0), eta=rng.uniform(-1.0, 1.0), lam=1 + ch)
        if orbit:
            v.update(zeta=1.0, eta=0.0, lam=rng.uniform(0.2, 1.5))
        if v["I"] * v["lam"] * v["zeta"] / (2 * v["L"]) < 1:
            out.append(v)
    return out


# --------------------------------------------------------------------------- item 4


@pytest.mark.parametrize("orbit", [False, True])
def test_where_the_condition_holds_the_spectrum_is_on_the_axis(orbit):
    """Wherever (3.6) holds ((4.3) on the orbit, lambda free), no eigenvalue of the
    linearisation has a real part above 1e-9 |eig|max; and the condition is C1 > 0."""
    rng = np.random.default_rng(11 if orbit else 12)
    sets = _random_sets(rng, 2000, orbit)
    a = ghc.analyse(ghc.model().vectors(sets), orbit)
    held = a["sufficient"]
    assert 300 < held.sum() < 1900
    eig = a["eigenvalues"][held]
    assert np.all(eig.real.max(axis=1) <= 1e-9 * np.abs(eig).max(axis=1))
    assert np.all(a["spectrally_stable"][held])
    pd = np.all(np.linalg.eigvalsh(a["C1"]) > 0, axis=1)
    assert np.array_equal(pd, held)


def test_kelvin_tait_chetaev_outside_the_condition():
    """Outside (3.6), C1 with an odd number of negative eigenvalues is always unstable; the
    spectrally stable cases (gyroscopic stabilisation) all have two."""
    sets = _random_sets(np.random.default_rng(13), 3000)
    a = ghc.analyse(ghc.model().vectors(sets))
    index = np.sum(np.linalg.eigvalsh(a["C1"]) < 0, axis=1)
    out = ~a["sufficient"]
    assert not np.any(a["spectrally_stable"][out & (index % 2 == 1)])
    gyro_ = out & a["spectrally_stable"]
    assert gyro_.sum() >= 1 and np.all(index[gyro_] == 2)


@pytest.mark.parametrize("k", range(4))
def test_perturbed_motion_stays_inside_the_bound_of_V(k):
    """Where (3.6) holds (k < 3: random sets; k = 3: the satellite with (4.3)), a motion from
    x(0) off the equilibrium keeps |x(t)| <= sqrt(cond diag(B1, C1)) |x(0)| over 30 periods of
    the slowest mode (x = (q - qe, q'); V = const up to terms of third order in x)."""
    if k < 3:
        sets = [v for v in _random_sets(np.random.default_rng(20 + k), 40)
                if ghc.analyse(ghc.model().vector(v)[None])["sufficient"][0]]
        v = sets[0]
    else:
        v = dict(A=1.2, B=1.0, C=1.1, J=1.0, L=1.0, I=1.0, nu=1.0, zeta=1.0, eta=0.0, lam=0.5)
        assert ghc.analyse(ghc.model().vector(v)[None], True)["sufficient"][0]
    bound = ghc.energy_bound(v)
    assert 1 < bound < math.inf
    w = ghc.frequencies(v)
    t = np.linspace(0, 30 * 2 * np.pi / w[0], 3001)
    rng = np.random.default_rng(30 + k)
    x0 = np.concatenate([rng.uniform(-1, 1, 4) * 1e-3, rng.uniform(-1, 1, 4) * 1e-3 * w[0]])
    y0 = ghc.initial_state(v) + x0
    Y = ghc.integrate(v, y0, t, "cvodes", rtol=1e-10, atol=1e-13)
    x = Y - ghc.initial_state(v)
    ratio = np.linalg.norm(x, axis=1).max() / np.linalg.norm(x0)
    assert ratio <= bound * (1 + 1e-2), (ratio, bound)
    assert ratio > 1.0  # the motion does move away from its start (the bound is not vacuous)


def test_a_gyroscopically_stabilised_motion_stays_small():
    """A spectrally stable set outside (3.6) (laboratory set at eta = 0.93): C1 has two
    negative eigenvalues, V is no Lyapunov function, yet a small perturbation stays small
    over 30 slowest periods."""
    v = ghc.parameters({**LAB, "eta": 0.93})
    s = ghc.stability(v)
    assert not s.sufficient and s.spectrally_stable and s.gyroscopically_stabilised
    assert np.sum(np.linalg.eigvalsh(ghc.analyse(ghc.model().vector(v)[None])["C1"][0]) < 0) == 2
    w = ghc.frequencies(v)
    t = np.linspace(0, 30 * 2 * np.pi / w[0], 2001)
    Y = ghc.integrate(v, ghc.initial_state(v, (1e-4, 0, 1e-4, 0)), t, "cvodes")
    assert np.abs(Y[:, :3]).max() < 1e-2


def test_the_gyroscopically_stabilised_cases_are_counted():
    """The counts docs/gyrohorizoncompass.md gives (README's maps, laboratory set), from the
    flagged maps: a boundary point (rounding could change its verdict) is counted as none
    of the others. In (theta, chi) the row chi = 0.32 lies exactly on the fourth condition
    of (3.6), (1 - 3 chi) nu^2 - eta^2 = 0: det C1 = 0 and a defective zero root, so every
    point of it is a boundary but those with a growing root well off the axis (certainly
    unstable). Off the row, 1 and 199 points are stabilised."""
    base = ghc.parameters({k: LAB[k] for k in BASE_KEYS}, need_equilibrium=False)
    m = ghc.condition_map(dict(base), ("zeta", 0.01, 0.9, 90), ("eta", 0.0, 1.2, 121))
    assert m.counts() == {"sufficient": 5498, "gyroscopic": 119, "unstable": 5273, "boundary": 0}
    # the strip: eta above sqrt(1 - 3 chi) nu (both blocks of C1 indefinite), below 0.96
    yy = np.broadcast_to(m.y[:, None], m.values.shape)[m.values == 1]
    assert yy.min() > math.sqrt(1 - 3 * 0.05) and yy.max() < 0.96
    base = ghc.parameters({**LAB}, need_equilibrium=False)
    m = ghc.condition_map(dict(base), ("theta", -0.5, 0.6, 111), ("chi", -0.5, 0.6, 111))
    assert m.counts() == {"sufficient": 6068, "gyroscopic": 1, "unstable": 6173, "boundary": 79}
    rows = np.unique(np.nonzero(m.boundary)[0])
    assert rows.tolist() == [82] and math.isclose(m.y[82], 0.32, rel_tol=1e-15)
    assert np.all(m.values[82][~m.boundary[82]] == 0)  # the rest of the row: certainly unstable
    m = ghc.condition_map(dict(base), ("theta", 0.2, 0.32, 121), ("chi", 0.3, 0.36, 61))
    assert m.counts() == {"sufficient": 740, "gyroscopic": 199, "unstable": 6356, "boundary": 86}
    assert np.unique(np.nonzero(m.boundary)[0]).tolist() == [20]  # chi = 0.32
    # the wedge at the corner of the (3.6) rectangle theta < 0.2367, chi < 0.32: grid points
    # theta 0.237 to 0.269, chi 0.321 to 0.340
    th, ch = (np.broadcast_to(a, m.values.shape)[m.values == 1] for a in (m.x[None, :], m.y[:, None]))
    assert np.isclose(th.min(), 0.237) and np.isclose(th.max(), 0.269)
    assert np.isclose(ch.min(), 0.321) and np.isclose(ch.max(), 0.340)
    # the smallest growth of a certainly unstable point: far above rounding (the growth of
    # 1e-8 on the row was the square root of rounding, a defective zero root's splitting)
    assert m.growth[m.values == 0].min() > 4e-3


BASE_KEYS = ("A", "B", "C", "J", "L", "I", "nu")


# --------------------------------------------------------------------------- gyro stability


def test_stability_json_has_the_contract_keys():
    rc, out, err = gyro("stability", "gyrohorizoncompass", *LAB_SETS, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert set(d) == {"model", "params", "equilibrium", "theta", "chi", "conditions", "sufficient",
                      "eigenvalues", "spectrally_stable", "boundary", "boundary_reason", "verdict", "margin_bounds"}
    assert d["boundary"] is False and d["boundary_reason"] is None and d["verdict"] == "stable"
    assert set(d["margin_bounds"]) == set(d["conditions"])
    # the bounds are k u sum|terms| (k <= 286 for the last minor, the terms O(1) here): below
    # 2e-12, against margins of 0.06 and more: decided by ten orders of magnitude
    assert all(0 < d["margin_bounds"][k] < 1e-10 * d["conditions"][k] for k in d["conditions"])
    assert d["model"] == "gyrohorizoncompass"
    # the declared names, and lambda (the key before every command printed lam) beside lam
    assert set(d["params"]) == {"A", "B", "C", "J", "L", "I", "nu", "zeta", "eta", "lam", "lambda"}
    assert math.isclose(d["params"]["lambda"], 1.05, rel_tol=1e-14)  # 1 + chi by default
    assert d["params"]["lam"] == d["params"]["lambda"]
    assert set(d["equilibrium"]) == {"alpha", "beta", "gamma", "epsilon0"}
    assert math.isclose(d["equilibrium"]["epsilon0"], math.acos(1.05 * 0.5 / 1.0), rel_tol=1e-14)
    assert math.isclose(d["theta"], 0.1, rel_tol=1e-12) and math.isclose(d["chi"], 0.05, rel_tol=1e-12)
    assert all(v > 0 for v in d["conditions"].values())
    assert math.isclose(d["conditions"]["(3.6) (1 - 3 theta) nu^2 - zeta^2 - eta^2"], 0.41, rel_tol=1e-12)
    assert d["sufficient"] is True and d["spectrally_stable"] is True
    assert len(d["eigenvalues"]) == 8 and all(len(e) == 2 for e in d["eigenvalues"])
    w = sorted(abs(im) for _, im in d["eigenvalues"])[::2]
    np.testing.assert_allclose(w, [0.347299, 0.507281, 0.930640, 1.007274], rtol=1e-5)


def test_stability_text_and_default_set():
    rc, out, err = gyro("stability", "gyrohorizoncompass")
    assert rc == 0, err
    assert "epsilon0" in out and "sufficient (3.6): yes; spectrally stable: yes" in out


def test_orbit_sets_zeta_nu_eta_0_and_uses_4_3():
    sat = ["--set=A=1.2", "--set=B=1.0", "--set=C=1.1", "--set=L=1", "--set=I=1", "--set=nu=1", "--set=J=1"]
    for lam, ok in (("0.5", True), ("0.35", False)):
        rc, out, err = gyro("stability", "gyrohorizoncompass", *sat, f"--set=lambda={lam}", "--orbit", "--json")
        assert rc == 0, err
        d = json.loads(out)
        assert d["params"]["zeta"] == d["params"]["nu"] == 1.0 and d["params"]["eta"] == 0.0
        assert d["params"]["lambda"] == float(lam)
        c43 = {k: v for k, v in d["conditions"].items() if k.startswith("(4.3)")}
        assert len(c43) == 3 and all(v > 0 for v in c43.values()) == ok == d["sufficient"]
        assert d["spectrally_stable"] or not ok


BAD = [
    (["--set=foo=1"], "foo"),
    (["--set=lam=1"], "lam"),
    (["--set=A=x"], "parameter A: not a number"),
    (["--set=B=nan"], "parameter B"),
    (["--set=L=inf"], "parameter L"),
    (["--set=C=-inf"], "parameter C"),
    (["--set=A=0"], "parameter A"),
    (["--set=J=-1"], "parameter J"),
    (["--set=I=0"], "parameter I"),
    (["--set=L=0"], "parameter L"),
    (["--set=nu=-1"], "parameter nu"),
    (["--set=lambda=0"], "parameter lambda"),
    (["--set=L=1e-9"], "I lambda zeta/2L"),
    (["--set=lambda=1.5"], "needs lambda = 1 + chi"),
    (["--set=zeta=1", "--orbit"], "--orbit"),
    (["--set", "A"], "NAME=VALUE"),
]


@pytest.mark.parametrize("args, needle", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_stability_bad_input_exits_2_with_one_line(args, needle):
    rc, out, err = gyro("stability", "gyrohorizoncompass", *args)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err and "Traceback" not in err


def test_eta_0_admits_any_lambda():
    rc, out, err = gyro("stability", "gyrohorizoncompass", *BASE, "--set=zeta=0.5", "--set=eta=0",
                        "--set=lambda=1.3", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["params"]["lambda"] == 1.3 and math.isclose(d["equilibrium"]["epsilon0"], math.acos(1.3 * 0.5))


def test_the_declared_labels_are_the_ones_the_hooks_slice():
    from gyro.analyses.conditions import labels

    every = labels(ghc.model())
    assert (tuple(every[ghc.SYL]), tuple(every[ghc.S36]), tuple(every[ghc.S43])) == (ghc.SYLVESTER, ghc.C36, ghc.C43)


def test_a_model_without_conditions_exits_2():
    for cmd in ("stability", "map"):
        extra = [] if cmd == "stability" else ["--x", "zeta=0:1:3", "--y", "eta=0:1:3", "--out", "x.png"]
        rc, out, err = gyro(cmd, "torsion_gyrocompass", *extra)
        assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
        assert "torsion_gyrocompass declares no conditions (Model.conditions" in err


# --------------------------------------------------------------------------- gyro map


def test_map_json_and_figure(tmp_path):
    out = tmp_path / "m.png"
    rc, so, err = gyro("map", "gyrohorizoncompass", *BASE, "--x", "zeta=0.05:0.85:9", "--y", "eta=0:1:11",
                       "--out", str(out), "--json")
    assert rc == 0, err
    d = json.loads(so)
    assert set(d) == {"x", "y", "values", "kind", "boundary"}
    assert d["x"]["name"] == "zeta" and len(d["x"]["values"]) == 9 and len(d["y"]["values"]) == 11
    v = np.array(d["values"])
    assert v.shape == (11, 9) and set(np.unique(v)) <= {0, 1, 2}
    assert np.array(d["boundary"]).shape == (11, 9) and not np.any(d["boundary"])
    assert "(3.6)" in d["kind"]
    assert out.stat().st_size > 1000
    # 2 exactly where (3.6) holds: (1 - 3 theta) - zeta^2 - eta^2 > 0 and (1 - 3 chi) - eta^2 > 0
    Z, H = np.meshgrid(d["x"]["values"], d["y"]["values"])
    held = (0.7 - Z**2 - H**2 > 0) & (0.85 - H**2 > 0)
    assert np.array_equal(v == 2, held)
    # each value agrees with `gyro stability` at that point
    for i, j in ((0, 0), (10, 8), (5, 4)):
        rc, so2, _ = gyro("stability", "gyrohorizoncompass", *BASE, f"--set=zeta={float(Z[i, j])!r}",
                          f"--set=eta={float(H[i, j])!r}", "--json")
        s = json.loads(so2)
        assert v[i, j] == (2 if s["sufficient"] else 1 if s["spectrally_stable"] else 0)


def test_map_theta_chi_text(tmp_path):
    out = tmp_path / "tc.png"
    rc, so, err = gyro("map", "gyrohorizoncompass", *LAB_SETS, "--x", "theta=0.2:0.32:25", "--y",
                       "chi=0.28:0.36:17", "--out", str(out))
    assert rc == 0, err
    assert so.startswith(f"gyro: wrote {out} (425 points: ") and "spectrally stable outside it" in so


MAP_BAD = [
    (["--x", "zeta=0:1.2:11", "--y", "eta=0:1:11"], "no relative equilibrium (3.1)"),  # zeta = 1.2: I lambda zeta/2L > 1
    (["--x", "foo=0:1:3", "--y", "eta=0:1:3"], "foo"),
    (["--x", "zeta=0:1", "--y", "eta=0:1:3"], "NAME=LO:HI:N"),
    (["--x", "zeta=1:0:3", "--y", "eta=0:1:3"], "LO < HI"),
    (["--x", "zeta=0:nan:3", "--y", "eta=0:1:3"], "finite"),
    (["--x", "zeta=0:0.5:x", "--y", "eta=0:1:3"], "not an integer"),
    (["--x", "zeta=0:0.5:3", "--y", "zeta=0:1:3"], "both"),
    (["--x", "theta=0:2:3", "--y", "eta=0:1:3"], "parameter A"),  # theta = 2: A = C - 2 I < 0
    (["--x", "A=-1:1:3", "--y", "eta=0:1:3"], "parameter A"),
]


@pytest.mark.parametrize("args, needle", MAP_BAD, ids=[" ".join(a) for a, _ in MAP_BAD])
def test_map_bad_input_exits_2_and_writes_nothing(args, needle, tmp_path):
    out = tmp_path / "m.png"
    rc, so, err = gyro("map", "gyrohorizoncompass", *BASE, *args, "--out", str(out))
    assert rc == 2 and so == "" and not out.exists()
    assert len(err.strip().splitlines()) == 1 and needle in err and "Traceback" not in err


def test_map_needs_a_png(tmp_path):
    rc, _, err = gyro("map", "gyrohorizoncompass", "--x", "zeta=0:1e-4:3", "--y", "eta=0:1e-4:3",
                      "--out", str(tmp_path / "m.txt"))
    assert rc == 2 and "PNG" in err


# --------------------------------------------------------------------------- gyro simulate


def test_simulate_json_has_the_contract_keys():
    rc, out, err = gyro("simulate", "gyrohorizoncompass", *LAB_SETS, "--t-end", "20", "--points", "5",
                        "--perturb", "0.01,0.02,-0.01,0.03", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert set(d) == {"t", "alpha", "beta", "gamma", "epsilon", "E", "method"}
    assert d["method"] == "DOP853" and d["t"] == [0.0, 5.0, 10.0, 15.0, 20.0]
    assert [d[k][0] for k in ("alpha", "beta", "gamma")] == [0.01, 0.02, -0.01]
    assert math.isclose(d["epsilon"][0], math.acos(0.525) + 0.03, rel_tol=1e-15)
    E = np.array(d["E"])
    assert np.max(np.abs(E - E[0])) < 1e-10 * abs(E[0])


def test_simulate_default_is_the_equilibrium_and_methods_agree():
    base = ("simulate", "gyrohorizoncompass", *LAB_SETS, "--t-end", "30", "--points", "4", "--json")
    rest = json.loads(gyro(*base)[1])
    assert np.max(np.abs(rest["alpha"])) < 1e-12 and np.ptp(rest["epsilon"]) < 1e-12
    ref = json.loads(gyro(*base, "--perturb", "0.05,0,0.02,0", "--method", "projected")[1])
    assert ref["method"] == "projected"
    E = np.array(ref["E"])
    assert np.max(np.abs(E - E[0])) < 1e-14 * abs(E[0])
    for m in ("DOP853", "cvodes", "cvodes-adams", "Radau"):
        d = json.loads(gyro(*base, "--perturb", "0.05,0,0.02,0", "--method", m)[1])
        for k in ("alpha", "beta", "gamma", "epsilon"):
            assert np.max(np.abs(np.array(d[k]) - ref[k])) < 1e-6, (m, k)


def test_simulate_text_and_plot(tmp_path):
    out = tmp_path / "s.png"
    rc, so, err = gyro("simulate", "gyrohorizoncompass", *LAB_SETS, "--t-end", "5", "--perturb", "0.01,0,0,0",
                       "--out", str(out))
    assert rc == 0, err
    assert "method DOP853" in so and "(1001 points; 11 shown; --json prints all)" in so
    assert out.stat().st_size > 1000


SIM_BAD = [
    (["--perturb", "0.1,0.1"], "--perturb"),
    (["--perturb", "0.1,x,0,0"], "beta"),
    (["--perturb", "0.1,nan,0,0"], "beta"),
    (["--method", "closed_form"], "--method"),
    (["--set=lambda=1.2"], "1 + chi"),
    (["--set=zeta=0.99"], "I lambda zeta/2L"),
    (["--set=eta=inf"], "parameter eta"),
    (["--points", "1"], "--points"),
    (["--points", "2000001"], "--points"),
    (["--method", "idas"], "--method"),
]


@pytest.mark.parametrize("method", ["projected", "DOP853", "cvodes", "cvodes-adams"])
def test_simulate_runaway_stops_in_one_line(method, monkeypatch):
    """A horizon beyond the budget stops with exit 1 and one line saying how far it got."""
    monkeypatch.setattr(ghc, "BUDGET_SECONDS", 1.0)
    monkeypatch.setattr(ghc, "BUDGET_STEPS", 20000)
    rc, so, err = gyro("simulate", "gyrohorizoncompass", *LAB_SETS, "--t-end", "1e7", "--points", "3",
                       "--perturb", "0.01,0,0,0", "--method", method)
    assert rc == 1 and so == ""
    assert len(err.strip().splitlines()) == 1 and "budget" in err and "Traceback" not in err


@pytest.mark.parametrize("args, needle", SIM_BAD, ids=[" ".join(a) for a, _ in SIM_BAD])
def test_simulate_bad_input_exits_2(args, needle):
    rc, so, err = gyro("simulate", "gyrohorizoncompass", *LAB_SETS, "--t-end", "1", *args)
    assert rc == 2 and so == ""
    assert len(err.strip().splitlines()) == 1 and needle in err and "Traceback" not in err


def test_the_gimbal_refuses_perturb_and_keeps_its_default():
    rc, _, err = gyro("simulate", "gimbal_gyroscope", "--t-end", "1", "--perturb", "0,0,0,0")
    assert rc == 2 and "--perturb" in err
    rc, out, _ = gyro("simulate", "gimbal_gyroscope", "--t-end", "1", "--points", "2", "--json")
    assert rc == 0 and json.loads(out)["method"] == "closed_form"


# --------------------------------------------------------------------------- results


def test_results_round_trip(tmp_path):
    from gyro.results import EquilibriumStability, Map, Motion

    v = ghc.parameters(LAB)
    s = ghc.stability(v)
    s.save(tmp_path / "s.npz")
    assert EquilibriumStability.load(tmp_path / "s.npz").to_dict() == s.to_dict()
    m = ghc.condition_map(dict(v), ("zeta", 0.1, 0.8, 4), ("eta", 0.0, 0.9, 5))
    m.save(tmp_path / "m.npz")
    m2 = Map.load(tmp_path / "m.npz")
    assert m2.to_dict() == m.to_dict() and m2.counts() == m.counts()
    tr = ghc.trajectory(v, np.linspace(0, 2, 3), (0.01, 0, 0, 0), "cvodes")
    tr.save(tmp_path / "t.npz")
    back = Motion.load(tmp_path / "t.npz")
    assert back.to_dict() == tr.to_dict() and back.table() == tr.table()
    tr.plot(tmp_path / "t.png")
    assert (tmp_path / "t.png").stat().st_size > 1000


def test_the_printed_3_6_rows_are_left_out_where_lambda_is_not_1_plus_chi():
    """On the orbit at lambda = 0.35 the rows of (3.6) (which assume lambda = 1 + chi) would all
    hold while the set is unstable: they are not reported; (4.3) and the minors are."""
    rc, out, err = gyro("stability", "gyrohorizoncompass", "--orbit", "--set=A=1.2", "--set=B=1", "--set=C=1.1",
                        "--set=J=1", "--set=L=1", "--set=I=1", "--set=nu=1", "--set=lambda=0.35", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert not any(k.startswith("(3.6)") for k in d["conditions"])
    assert d["conditions"]["(4.3) lambda/4 - chi"] < 0 and not d["sufficient"] and not d["spectrally_stable"]
    rc, out, _ = gyro("stability", "gyrohorizoncompass", "--orbit", "--set=A=1.2", "--set=B=1", "--set=C=1.1",
                      "--set=J=1", "--set=L=1", "--set=I=1", "--set=nu=1", "--json")
    d = json.loads(out)  # lambda = 1 + chi: (3.6) and (4.3) both reported, and agree ((4.2))
    c = d["conditions"]
    assert all(c[k] > 0 for k in c if k.startswith("(3.6)")) == all(c[k] > 0 for k in c if k.startswith("(4.3)"))


@pytest.mark.parametrize("args", [["--set=eta=0.2", "--set=lambda=1.2"], ["--set=zeta=0.1"]],
                         ids=["lambda off 1 + chi", "I lambda zeta/2L >= 1"])
def test_without_3_1_the_refusal_names_the_equations_own_equilibrium(args):
    """Where (3.1)-(3.2) does not exist the equations still have an equilibrium (beta != 0;
    a root of the residual to 1e-60 at 60 digits): the refusal says so and names it, and it
    is the one `gyro frequencies` analyses; never "no equilibrium" where there is one."""
    rc, out, err = gyro("stability", "gyrohorizoncompass", *args)
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "no relative equilibrium (3.1)" in err and "another equilibrium here" in err
    beta = float(err.split("beta = ")[1].split(",")[0])
    rc, out, err2 = gyro("frequencies", "gyrohorizoncompass", *args, "--json")
    assert rc == 0, err2
    assert math.isclose(json.loads(out)["equilibrium"]["beta"], beta, rel_tol=1e-5)
