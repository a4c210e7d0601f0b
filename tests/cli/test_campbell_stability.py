"""Instability shown where people look (issue 37, item 4): the Campbell diagram's summary,
figure and JSON name the unstable spins, `gyro sweep`'s table has a stability column, and
critical speeds are numbered as `gyro frequencies` numbers the modes at their spin.

Held against hand computations on models outside the package: a Jeffcott rotor on a
cross-coupled bearing (a model file written here), whose roots are those of
m s^2 + c s + k -+ i kq Omega = 0, unstable exactly above Omega = c sqrt(k/m)/kq; and the
rigid rotor of examples/rigid_rotor.py, stable at every spin.

Tolerances: the closed-form roots by numpy.roots of a quadratic with |s| ~ 100 err by a few
eps |s|; the default method's stated bound is ~1e-14 relative on this 2x2 operator; 1e-10
|lambda| allows both with four orders to spare and is far below the growth rates compared
(0.1 to 15 1/s)."""
from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest

from gyro import ladder
from tests.conftest import ROOT, run_cli

ROTOR_FILE = ROOT / "examples" / "rigid_rotor.py"
M, K, C, KQ = 1.0, 1.0e4, 2.0, 3.0
THRESHOLD = C * np.sqrt(K / M) / KQ  # 66.67 rad/s: unstable above

CROSS_ROTOR = textwrap.dedent(f'''
    """Jeffcott rotor on a cross-coupled bearing: k_xy = -k_yx = kq Omega (a fluid film)."""
    import sympy as sp

    from derive.model import Load, Model, Parameter

    NAME = "cross_rotor"
    PARAMETERS = [
        Parameter("m", "kg", {M!r}, "rotor mass"),
        Parameter("k", "N/m", {K!r}, "bearing stiffness"),
        Parameter("c", "N s/m", {C!r}, "bearing damping", kind="nonnegative"),
        Parameter("kq", "N s/m", {KQ!r}, "cross-coupled stiffness per spin rate"),
        Parameter("Omega", "rad/s", 300.0, "spin rate", kind="nonnegative"),
    ]
    m, k, c, kq, Omega = (p.symbol for p in PARAMETERS)
    x, y, x_d, y_d, x_dd, y_dd = sp.symbols("x y x_d y_d x_dd y_dd")


    def build():
        return Model(
            name=NAME, title="Jeffcott rotor on a cross-coupled bearing", source="test", module=__name__,
            parameters=PARAMETERS, coordinates=["x", "y"], coordinate_units={{"x": "m", "y": "m"}},
            q=[x, y], qd=[x_d, y_d], qdd=[x_dd, y_dd],
            lagrangian=m * (x_d**2 + y_d**2) / 2 - k * (x**2 + y**2) / 2,
            dissipation=c * (x_d**2 + y_d**2) / 2,
            loads=[Load(sp.Matrix([-kq * Omega * y, kq * Omega * x]), sp.Matrix([x_d, y_d]), "cross-coupling")],
            symmetric_zero=["x", "y"],
            spin={{"parameter": "Omega", "whirl": [("x", "y")]}},
        )
''')


@pytest.fixture(scope="module")
def cross_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("models") / "cross_rotor.py"
    path.write_text(CROSS_ROTOR)
    return path


def hand_growth(omega: float) -> float:
    """The largest real part of the roots of m s^2 + c s + k -+ i kq Omega (by hand: the
    cross-coupling's two circular whirls)."""
    roots = np.concatenate([np.roots([M, C, K - 1j * KQ * omega]), np.roots([M, C, K + 1j * KQ * omega])])
    return float(np.max(roots.real))


def test_cross_coupled_rotor_campbell_names_the_unstable_spins(cross_file, tmp_path):
    """34 spins from 10 to 1000 rad/s (every 30): unstable from 70 rad/s, just above the
    threshold 66.7; the summary says so, the JSON says so per spin, one tracked branch (the
    forward whirl) grows at each unstable spin, at the closed form's rate."""
    out = tmp_path / "c.png"
    rc, text, err = run_cli("campbell", str(cross_file), "--spin-range", "10", "1000", "--points", "34",
                            "--out", str(out), "--quiet")
    assert rc == 0, err
    spins = np.linspace(10, 1000, 34)
    unstable = spins > THRESHOLD
    assert text.strip() == (f"gyro: wrote {out} (34 spins, unstable at {int(unstable.sum())} of 34 spins, "
                            f"from {spins[unstable][0]:.6g} rad/s)")
    assert int(unstable.sum()) == 32 and spins[unstable][0] == pytest.approx(70)
    rc, text, err = run_cli("campbell", str(cross_file), "--spin-range", "10", "1000", "--points", "34",
                            "--json", "--quiet")
    assert rc == 0, err
    doc = json.loads(text)
    assert doc["stability"] == ["unstable" if u else "stable" for u in unstable]
    assert doc["growing_modes"] == [int(u) for u in unstable]
    assert doc["stability_reason"] == [None] * 34
    grow = np.array(doc["growing"])
    assert grow.shape == (34, 2) and list(grow.sum(axis=1)) == doc["growing_modes"]
    whirl = np.array(doc["whirl"], dtype=object)
    assert np.all(whirl[grow] == "forward")  # the whirl the cross-coupling drives
    for w, g, lam_g, f in zip(spins, doc["growth_rate"], doc["growth"], doc["frequencies"]):
        want = hand_growth(w)
        assert abs((g if want > 0 else max(lam_g)) - want) <= 1e-10 * max(np.abs(f))


def test_cross_coupled_rotor_figure_draws_the_growing_branch(cross_file):
    """The figure's legend holds the growing branch and the band of unstable spins, and its
    damping-ratio scale runs below zero (the growing root's zeta < 0)."""
    import matplotlib.pyplot as plt

    import gyro
    from gyro.analyses.campbell import campbell

    model = gyro.load(cross_file)
    d = campbell(model, model.defaults, "Omega", np.linspace(10, 1000, 34))
    figs = [plt.figure()]
    d.plot(figs[0])  # drawn into the figure given
    ax = figs[0].axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert "growing branch (unstable)" in labels and "unstable spins" in labels
    bar = figs[0].axes[-1]
    assert bar.get_ylabel().startswith("damping ratio zeta") and bar.get_ylim()[0] < 0
    plt.close(figs[0])


def test_sweep_table_has_a_stability_column(cross_file):
    """The top-heavy gyrocompass (l2 = -0.5, -0.3: omega1 = omega2 = 0, two real roots that
    grow) shows unstable rows; the cross-coupled rotor's rows are unstable above the
    threshold, with one growing mode at the closed form's rate."""
    rc, text, err = run_cli("sweep", "torsion_gyrocompass", "--x", "l2", "--x-range", "-0.5", "0.3", "--points", "5")
    assert rc == 0, err
    lines = text.splitlines()
    assert lines[0].split()[-1] == "stability"
    rows = [line.split("  ")[-1] for line in lines[1:]]
    assert [r.split(" (")[0] for r in rows] == ["unstable", "unstable", "stable", "stable", "stable"]
    assert all(r.startswith("unstable (2 growing modes, the fastest at ") for r in rows[:2])
    rc, text, err = run_cli("sweep", str(cross_file), "--x", "Omega", "--x-range", "10", "190", "--points", "4",
                            "--json")
    assert rc == 0, err
    doc = json.loads(text)
    x = np.array(doc["x"]["values"])
    assert doc["stability"] == ["unstable" if v > THRESHOLD else "stable" for v in x]
    assert doc["growing_modes"] == [int(v > THRESHOLD) for v in x]
    for v, g in zip(x, doc["growth_rate"]):
        assert abs(g - max(hand_growth(v), 0.0)) <= 1e-10 * np.sqrt(K / M)
    rc, text, err = run_cli("sweep", str(cross_file), "--x", "Omega", "--x-range", "10", "190", "--points", "4")
    rows = text.splitlines()[1:]
    assert [r.rsplit("  ", 1)[-1] for r in rows] == [
        "stable", *(f"unstable (1 growing mode, the fastest at {hand_growth(v):.4g} 1/s)" for v in x[1:])]


def test_critical_speeds_numbered_as_gyro_frequencies_numbers_them():
    """At each crossing's spin, `gyro frequencies` has the crossing's frequency as omega_mode.
    Tracked from the lowest spin, three of the gyrocompass's twelve crossings were numbered
    by their branch instead (the rising branch is omega9 at H = 0.2006, its branch 10)."""
    import gyro
    from gyro.analyses.campbell import sweep

    m = gyro.load("torsion_gyrocompass")
    d = sweep(m, m.defaults, 0.1, 10, 20, harmonics=(1, 2, 3, 4, 5))
    assert len(d.crossings) == 12
    for c in d.crossings:
        f = ladder.spectrum(m, m.vector(m.parameters({"H": c.value})), "default").frequencies[0]
        gaps = np.abs(f - c.frequency)
        assert int(np.argmin(gaps)) == c.mode - 1 and gaps[c.mode - 1] <= 1e-9 * c.frequency
        assert np.sort(gaps)[1] > 1e-3 * c.frequency  # no other root there to confuse it with
    assert sum(c.mode != c.branch for c in d.crossings) == 3
    c = next(c for c in d.crossings if c.k == 1 and c.frequency > 1000)
    rc, text, err = run_cli("frequencies", "torsion_gyrocompass", "--set", f"H={c.value!r}", "--json")
    assert rc == 0, err
    f = json.loads(text)["frequencies"]
    assert c.mode == 9 and abs(f[c.mode - 1] - c.frequency) <= 1e-9 * c.frequency
    # the figure's numbers at the right: as `gyro frequencies` numbers them at the last spin
    last = ladder.spectrum(m, m.vector(m.parameters({"H": d.values_swept[-1]})), "default").frequencies[0]
    assert np.array_equal(last[d.numbers(-1) - 1], d.tracked.frequencies[-1])
    doc = d.to_dict()
    assert doc["crossings"][0]["mode"] == d.crossings[0].mode and "branch" in doc["crossings"][0]
    assert doc["mode_number"][-1] == [int(j) for j in d.numbers(-1)]


def test_rigid_rotor_stable_at_every_spin_and_numbered_as_frequencies(tmp_path):
    """examples/rigid_rotor.py, damped on anisotropic bearings: stable at every spin (the
    summary adds nothing), its four critical speeds numbered as `gyro frequencies` does."""
    out = tmp_path / "r.png"
    rc, text, err = run_cli("campbell", str(ROTOR_FILE), "--spin-range", "0", "1500", "--points", "16",
                            "--harmonics", "1", "--out", str(out), "--json", "--quiet")
    assert rc == 0, err
    doc = json.loads(text)
    assert doc["stability"] == ["stable"] * 16 and not np.any(doc["growing"])
    import gyro

    rotor = gyro.load(ROTOR_FILE)
    for c in doc["crossings"]:
        f = ladder.spectrum(rotor, rotor.vector(rotor.parameters({"Omega": c["value"]})), "default").frequencies[0]
        assert int(np.argmin(np.abs(f - c["frequency"]))) == c["mode"] - 1
    rc, text, err = run_cli("campbell", str(ROTOR_FILE), "--spin-range", "0", "1500", "--points", "16",
                            "--out", str(out), "--quiet")
    assert text.strip() == f"gyro: wrote {out} (16 spins)"


def test_campbell_of_a_model_with_a_multiplier_is_the_hand_formula(tmp_path):
    """tests/models/hoop_bead.py: a bead on a hoop turning at Omega, in Cartesian coordinates
    held on the circle by a Lagrange multiplier, its bottom given as the start
    (equilibrium_approx; the top is the constraint's other branch). By hand omega^2 =
    g/R - Omega^2 below the critical rate sqrt(g/R) = 7.0036 rad/s, growth
    sqrt(Omega^2 - g/R) beyond; the summary names the unstable spins."""
    hoop = str(ROOT / "tests" / "models" / "hoop_bead.py")
    rc, out, err = run_cli("campbell", hoop, "--spin-range", "0", "10", "--points", "11", "--json")
    assert rc == 0, err
    d = json.loads(out)
    gR = 9.81 / 0.2
    for W, (w,), (s,) in zip(d["spin_rate"], d["frequencies"], d["growth"]):
        if W**2 < gR:
            assert w == pytest.approx(np.sqrt(gR - W**2), rel=1e-12) and s == 0.0
        else:
            assert w == 0.0 and s == pytest.approx(np.sqrt(W**2 - gR), rel=1e-12)
    rc, out, err = run_cli("campbell", hoop, "--spin-range", "0", "10", "--points", "11", "--out",
                           str(tmp_path / "hoop.png"))
    assert rc == 0 and "unstable at 3 of 11 spins, from 8 rad/s" in out, err
    rc, out, _ = run_cli("frequencies", hoop, "--set", "Omega=3")
    assert rc == 0 and "6.32850693" in out and "equilibrium: stable" in out
