"""The one verdict type (gyro.results.verdict) and the bounds it reads: no stability verdict
that rounding decides. The bounds are tested where they matter: at points placed exactly
on each boundary of (3.6) and (4.3) in exact arithmetic (decimal inputs as fractions, 40
digits), and just off them. docs/gyrohorizoncompass.md, "Boundaries"."""
from __future__ import annotations

import json
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from gyro import qep
from gyro.equilibrium import operators
from gyro.systems import gyrohorizoncompass as ghc
from gyro.methods import reference
from gyro.results import Spectrum, classify, verdict
from tests.conftest import run_cli

NAMES = ("A", "B", "C", "J", "L", "I", "nu", "zeta", "eta", "lam")
U = 2.0**-53


def _decimal_set(**kw) -> dict:
    """A set of exact decimals (Fractions), lambda = 1 + chi unless given."""
    v = {k: Fraction(str(x)) for k, x in dict(A=1, B=1.05, C=1.1, J=1, L=0.5, I=1, nu=1, zeta=0.5, eta=0.2).items()}
    v.update({k: Fraction(str(x)) for k, x in kw.items() if k not in ("theta", "chi")})
    if "theta" in kw:
        v["A"] = v["C"] - Fraction(str(kw["theta"])) * v["I"]
    if "chi" in kw:
        v["B"] = v["C"] - Fraction(str(kw["chi"])) * v["I"]
    v.setdefault("lam", 1 + (v["C"] - v["B"]) / v["I"])
    return v


def _floats(v: dict) -> dict:
    return {k: float(x) for k, x in v.items()}


def _exact_margins(v: dict):
    """The emitted margins at 40 digits from the exact decimal inputs."""
    with mpmath.workdps(40):
        p = [mpmath.mpf(v[k].numerator) / v[k].denominator for k in NAMES]
        return _split(np.array([float(x) for x in ghc.model().mpmath.conditions(p)]))


def _split(x):
    """The declared margins (`conditions`) as [Sylvester minors, (3.6), (4.3)]."""
    return [x[ghc.SYL], x[ghc.S36], x[ghc.S43]]


def _margins(v: dict):
    P = ghc.model().vector(_floats(v))[None]
    m = ghc.model().numpy
    return _split(np.ravel(m.conditions(P))), _split(U * np.ravel(m.conditions_rounding(P)))


# the boundaries of (3.6) (group 1) and (4.3) (group 2), each placed exactly: (set, group, row)
ON_BOUNDARY = {
    "(3.6) 1 + theta = 0": (dict(theta=-1, C=1.1, I=1), 1, 0),
    "(3.6) 1/3 - theta = 0": (dict(theta=Fraction(1, 3), I=3, C=2, A=1, L=4), 1, 1),
    "(3.6) 1/3 - chi = 0": (dict(I=3, C=2, B=1, A=1.9, L=4), 1, 3),
    "(3.6) (1 - 3 theta) nu^2 - zeta^2 - eta^2 = 0": (dict(theta=0, zeta=0.6, eta=0.8, L=2), 1, 4),
    "(3.6) (1 - 3 chi) nu^2 - eta^2 = 0 (the row chi = 0.32)": (dict(chi=0.32), 1, 5),
    "(3.6) (1 - 3 chi) nu^2 - eta^2 = 0 (chi = 1/4, eta = 1/2)": (dict(chi=0.25, eta=0.5), 1, 5),
    "(4.3) lambda + theta - chi = 0": (dict(theta=-0.1, chi=0.1, zeta=1, eta=0, lam=0.2), 2, 0),
    "(4.3) lambda/4 - chi = 0": (dict(theta=-0.1, chi=0.1, zeta=1, eta=0, lam=0.4), 2, 1),
    "(4.3) -theta = 0": (dict(theta=0, chi=0.1, zeta=1, eta=0, lam=0.5), 2, 2),
}


def _fix(kw):
    kw = dict(kw)
    if isinstance(kw.get("theta"), Fraction):  # theta = 1/3 with I = 3: A = C - 1 exactly
        kw.pop("theta")
    return kw


@pytest.mark.parametrize("name", list(ON_BOUNDARY))
def test_a_margin_exactly_on_its_boundary_lies_within_its_bound(name):
    """The exact margin (40 digits from the decimal inputs) is 0; the computed one lies
    within its emitted rounding bound, so the condition is undecided there; a move of the
    set by 1e3 bounds' worth off the boundary decides it."""
    kw, group, row = ON_BOUNDARY[name]
    v = _decimal_set(**_fix(kw))
    exact = _exact_margins(v)[group][row]
    assert abs(exact) < 1e-30, exact
    margins, bounds = _margins(v)
    assert abs(margins[group][row]) <= bounds[group][row], (margins[group][row], bounds[group][row])
    assert bounds[group][row] < 1e-13  # a few hundred unit roundoffs of terms of order 1
    _, decided, reason = verdict.condition(margins[group][None, row:row + 1], bounds[group][None, row:row + 1],
                                           [name])
    assert not decided[0] and "within its rounding bound" in reason[0]
    # off the boundary: one parameter of the margin moved by 1e-9 relative, either way,
    # moves the margin by 1e-11 to 1e-9, over 100 bounds: decided, with the sign of the move
    key = ({0: "lam", 1: "lam", 2: "A"}[row] if group == 2 else
           {0: "A", 1: "A", 3: "B", 4: "nu", 5: "nu"}[row])
    signs = []
    for sign in (1, -1):
        w = dict(v)
        w[key] = v[key] * (1 + sign * Fraction(1, 10**9))
        m2, b2 = _margins(w)
        assert abs(m2[group][row]) > 100 * b2[group][row]
        signs.append(np.sign(m2[group][row]))
    assert signs[0] == -signs[1]


def test_the_margin_bounds_bound_the_rounding_on_random_sets():
    """|computed - exact| <= bound for every margin on random decimal sets (5 digits)."""
    rng = np.random.default_rng(5)
    worst = 0.0
    for _ in range(40):
        th, ch = (round(x, 5) for x in rng.uniform(-0.6, 0.5, 2))
        kw = dict(theta=th, chi=ch, J=round(rng.uniform(0.2, 2), 3), L=round(rng.uniform(1.5, 3), 3),
                  zeta=round(rng.uniform(0.05, 1), 4), eta=round(rng.uniform(-1, 1), 4))
        if rng.uniform() < 0.3:  # eta = 0 and lambda free: the Sylvester minors and (4.3) in force
            kw.update(lam=round(rng.uniform(0.2, 1.5), 4), eta=0)
        v = _decimal_set(**kw)
        exact = _exact_margins(v)
        margins, bounds = _margins(v)
        for e, m, b in zip(exact, margins, bounds):
            assert np.all(np.abs(m - e) <= b), (m - e, b)
            worst = max(worst, float(np.max(np.abs(m - e) / b)))
    assert worst > 1e-4  # the bounds are not vacuous: the rounding is seen


def _exact_eigenvalues(v: dict):
    """The companion matrix's eigenvalues at 40 digits from the exact decimal inputs."""
    mf = ghc.model().mpmath
    with mpmath.workdps(40):
        p = [mpmath.mpf(v[k].numerator) / v[k].denominator for k in NAMES]
        eps0 = mf.relative_equilibrium(p)[0][0]
        A = reference.companion(*mf.operator(p, [0, 0, 0, eps0]))
        w = mpmath.eig(A, left=False, right=False)
        return np.array([complex(x) for x in w]), np.array(A.tolist(), dtype=float)


@pytest.mark.parametrize("case", ["random", "on the row chi = 0.32", "just off the row"])
def test_every_exact_eigenvalue_lies_in_a_disk(case):
    """The radii of gyro.qep.eigen_radii: every exact eigenvalue (40 digits) lies within the radius of
    a computed one, and the computed companion matrix errs by less than n u ||A||_F (the
    share eigen_radii allows the inputs and M, D, K)."""
    rng = np.random.default_rng(3)
    sets = {"random": [_decimal_set(theta=round(rng.uniform(-0.6, 0.5), 3), chi=round(rng.uniform(-0.6, 0.5), 3),
                                    zeta=round(rng.uniform(0.05, 1), 3), eta=round(rng.uniform(-1, 1), 3), L=2)
                       for _ in range(6)],
            "on the row chi = 0.32": [_decimal_set(chi=0.32, theta=t) for t in (0.1, 0.25, 0.3)],
            "just off the row": [_decimal_set(chi=Fraction(32, 100) + Fraction(1, 10**11), theta=0.25)]}[case]
    for v in sets:
        a = ghc.analyse(ghc.model().vector(_floats(v))[None])
        w, r = a["eigenvalues"][0], a["radius"][0]
        exact, A_exact = _exact_eigenvalues(v)
        for z in exact:
            assert np.any(np.abs(w - z) <= r), (z, w, r)
        M, D, K = operators(ghc.model(), ghc.model().vector(_floats(v))[None],
                            np.array([[0, 0, 0, a["epsilon0"][0]]]))
        A = qep.companion_matrix(M, D, K)[0]
        assert np.linalg.norm(A - A_exact) <= 8 * U * np.linalg.norm(A_exact)
        if case == "on the row chi = 0.32":  # a certain growth elsewhere, or a boundary
            assert a["verdict"].label[0] in ("boundary", "unstable")
            if a["verdict"].label[0] == "unstable":  # then a root grows well off the axis
                assert np.max(w.real - r) > 0.1
        if case == "just off the row":
            assert a["verdict"].label[0] in ("stable", "unstable") and not a["boundary"][0]


@pytest.mark.parametrize("name", [n for n in ON_BOUNDARY if "1/3 - " not in n and "1 + theta" not in n])
def test_a_set_on_the_boundary_is_a_boundary_not_stable(name):
    """On each boundary of (3.6) and (4.3) where the other margins hold, the verdict is
    'boundary' (C1 singular: a zero root), neither stable nor stabilised."""
    kw, group, _ = ON_BOUNDARY[name]
    v = _floats(_decimal_set(**_fix(kw)))
    s = ghc.stability(v, orbit=group == 2)
    assert s.verdict == "boundary" and s.boundary and not s.sufficient and not s.gyroscopically_stabilised
    assert s.to_dict()["boundary"] is True and len(s.to_dict()["boundary_reason"].splitlines()) == 1


def test_zeta_0_is_marginal_not_stable():
    """At zeta = 0 exactly (no compass effect) the printed rows of (3.6) all hold, but C1's
    first minor I (1 + theta) zeta^2 is 0: V is only semidefinite, and the stiffness leaves
    alpha free (an exact double zero root). The verdict is marginal, not stable: the rows
    of (3.6) are C1 > 0 only given zeta != 0 (and epsilon0 != 0), so C1's minors are
    required with them."""
    v = ghc.parameters({"A": 1, "B": 1.05, "C": 1.1, "J": 1, "L": 0.5, "I": 1, "nu": 1, "zeta": 0, "eta": 0.2})
    s = ghc.stability(v)
    assert all(s.conditions[k] > 0 for k in s.conditions if k.startswith("(3.6)"))
    assert s.verdict == "marginal" and not s.sufficient and not s.spectrally_stable and not s.boundary
    assert "exact zero root" in s.table().splitlines()[-1]
    s = ghc.stability(dict(v, zeta=1e-3))  # a small compass effect: decided, and stable
    assert s.verdict == "stable" and s.sufficient


def test_the_verdict_module():
    """condition: holds, fails, undecided; spectrum: a simple axis root is stable (the
    conservative argument), a disk right of the axis unstable, two disks that meet a
    boundary, an exact zero of a free coordinate marginal, NaN failed, inf unknown."""
    holds, decided, why = verdict.condition(np.array([[1.0, 2.0], [1.0, 1e-17], [-1.0, 1e-17]]),
                                            np.full((3, 2), 1e-15), ["a", "b"])
    assert holds.tolist() == [True, False, False] and decided.tolist() == [True, False, True]
    assert why[1].startswith("the margin b") and why[0] is None and why[2] is None
    lam = np.array([[1e-17 + 1j, 1e-17 - 1j], [0.1 + 1j, 0.1 - 1j], [1e-9 + 1j, -1e-9 + 1j],
                    [1e-20, -1e-20], [1e-20, -1e-20], [np.nan, 1j], [1j, -1j]])
    rad = np.array([[1e-15] * 2, [1e-15] * 2, [1e-8] * 2, [1e-15] * 2, [1e-15] * 2, [1e-15] * 2, [np.inf] * 2])
    v = verdict.spectrum(lam, rad, exact_zero=np.array([0, 0, 0, 0, 1, 0, 0]))
    assert v.label.tolist() == ["stable", "unstable", "boundary", "boundary", "marginal", "failed", "unknown"]
    assert "collision" in v.reason[2] and "zero root" in v.reason[3]
    assert verdict.spectrum(lam[:1], rad[:1], conservative=False).label[0] == "boundary"
    assert v.counts() == {"stable": 1, "marginal": 1, "unstable": 1, "boundary": 2, "unknown": 1, "failed": 1}
    with pytest.raises(ValueError):
        verdict.make(["stabel"])


def test_classify_flags_merged_and_unresolved_roots():
    """The ladder's classify (every operator model): two roots within their error bounds of
    each other are a boundary (a possible collision), a root not resolved from zero too, an
    exact zero root stays marginal, a growing root stays unstable."""
    f = np.array([[1.0, 1.0 + 1e-12, 2.0], [1e-19, 1.0, 2.0], [0.0, 1.0, 2.0], [1.0, 1.0 + 1e-12, 2.0],
                  [1.0, 1.1, 2.0]])
    g = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0], [0.5, 0, 0], [0, 0, 0]], float)
    e = np.array([[1e-11, 1e-11, 1e-12], [1.2, 1e-12, 1e-12], [1.0, 1e-12, 1e-12], [1e-11, 1e-11, 1e-12],
                  [1e-11, 1e-11, 1e-12]])
    st = classify(Spectrum("default", f, g, e))
    assert st.label.tolist() == ["boundary", "boundary", "marginal", "unstable", "stable"]
    assert "merge" in st.reason[0] and "not resolved from zero" in st.reason[1]
    assert st.reason[2] is None and st.reason[4] is None


def test_cli_contract_boundary_keys(tmp_path):
    """gyro stability --json: boundary, boundary_reason; gyro map --json: boundary (N_y rows
    of N_x booleans); gyro stability-map --json: x, y as gyro map, values, boundary."""
    row = ["--set=A=1", "--set=B=0.78", "--set=C=1.1", "--set=J=1", "--set=L=0.5", "--set=I=1", "--set=nu=1",
           "--set=zeta=0.5", "--set=eta=0.2"]
    rc, out, err = run_cli("stability", "gyrohorizoncompass", *row, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["boundary"] is True and d["verdict"] == "boundary" and not d["sufficient"]
    assert "(1 - 3 chi) nu^2 - eta^2" in d["boundary_reason"] and "\n" not in d["boundary_reason"]
    rc, out, _ = run_cli("stability", "gyrohorizoncompass", *row)
    assert "boundary: rounding could change the verdict" in out and "within rounding of 0" in out
    rc, out, err = run_cli("map", "gyrohorizoncompass", *row[:7], "--set=zeta=0.5", "--set=eta=0.2",
                           "--x", "theta=0.2:0.3:3", "--y", "chi=0.31:0.33:3", "--out", str(tmp_path / "m.png"),
                           "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert np.array(d["boundary"]).tolist() == [[False] * 3, [True, True, False], [False] * 3]
    assert np.array(d["values"])[1].tolist() == [-1, -1, 0]  # theta = 0.3 on the row: certainly unstable
    # (the torsion gyrocompass's boundary at the pole, phi = 90, needs the 40-digit rung, 4 s:
    # tests/methods/test_ladder.py::test_default_escalates_at_the_pole_where_omega1_is_rounding)
    rc, out, err = run_cli("stability-map", "torsion_gyrocompass", "--x", "phi", "--x-range", "60", "80",
                           "--y", "u", "--y-range", "0", "1e-4", "--points", "2", "--out", str(tmp_path / "s.png"),
                           "--json", "--quiet")
    assert rc == 0, err
    d = json.loads(out)
    assert {"x", "y", "values", "boundary"} <= set(d) and d["x"]["name"] == "phi" and len(d["y"]["values"]) == 2
    assert d["values"] == [["marginal"] * 2, ["stable"] * 2]  # u = 0: an exact zero root
    assert d["boundary"] == [[False] * 2] * 2
    assert (tmp_path / "s.png").stat().st_size > 1000


@pytest.mark.parametrize("inertia, rate", [(1e-4, 1), (1e4, 1), (1, 1e-3), (1, 1e3)])
def test_the_boundaries_are_boundaries_at_every_scale(inertia, rate):
    """The set on (4.3)'s lambda + theta - chi = 0 with the inertias (A, B, C, J, I, and L
    with them) scaled by `inertia` and the rates (nu, zeta, eta, and L) by `rate`: the
    verdicts are homogeneous in both scales, so each boundary of (3.6) and (4.3) stays a
    boundary. At these scales c11 rounds to exactly 0 and the companion matrix has a
    computed Jordan block (parallel eigenvectors, an infinite radius): that is a boundary
    too, not 'unknown', which a map would have shown as unstable (value 0)."""
    s, t = Fraction(str(inertia)), Fraction(str(rate))
    for name, (kw, group, _) in ON_BOUNDARY.items():
        if "1/3 - " in name or "1 + theta" in name:  # certainly unstable there (index 1)
            continue
        v = _decimal_set(**_fix(kw))
        v.update({k: v[k] * s for k in ("A", "B", "C", "J", "I")}, L=v["L"] * s * t)
        v.update({k: v[k] * t for k in ("nu", "zeta", "eta")})
        a = ghc.analyse(ghc.model().vector(_floats(v))[None], group == 2)
        assert a["verdict"].label[0] == "boundary", (name, a["verdict"].label[0], a["verdict"].reason[0])


@pytest.mark.parametrize("theta", [0.1, 0.2])
def test_a_set_just_off_the_row_is_decided_by_its_rows(theta):
    """chi = 0.32 -+ 1e-13 (exact decimals) with eta != 0, where (3.2) makes lambda = 1 + chi
    exact: the printed row (1 - 3 chi) nu^2 - eta^2 = +-3e-13 exceeds its bound (9e-15) 30
    times, and the spectrum's disks decide the same. C1's minors m2..m4 are the rows times
    m1 and c44 there, so only m1 > 0 and epsilon0 != 0 are required with the rows: the
    expanded bound of m4 (1.4e-12, against m4 = 1.5e-14) must not make the set a boundary."""
    below = ghc.analyse(ghc.model().vector(_floats(_decimal_set(chi=Fraction(32, 100) - Fraction(1, 10**13),
                                                                 theta=theta)))[None])
    assert below["verdict"].label[0] == "stable" and below["sufficient"][0], below["verdict"].reason[0]
    above = ghc.analyse(ghc.model().vector(_floats(_decimal_set(chi=Fraction(32, 100) + Fraction(1, 10**13),
                                                                 theta=theta)))[None])
    assert above["verdict"].label[0] == "unstable"


def test_a_conservative_spectrum_uses_its_mirror_symmetry():
    """Hamiltonian roots come as z, -conj(z): a disk wholly left of the axis proves a root
    right of it (unstable), and 'stable' needs each root's mirror disk to meet no other disk
    (the argument of the docs), not only the disk itself."""
    left = verdict.spectrum(np.array([[-1e-8 + 1j, -1e-8 - 1j]]), np.full((1, 2), 1e-9))
    assert left.label[0] == "unstable"
    # disk 0 meets the axis and no other disk; its mirror meets disk 1
    lam = np.array([[1e-9 + 1j, -0.5e-9 + (1 + 2.2e-9) * 1j]])
    rad = np.array([[1.7e-9, 0.6e-9]])
    assert not verdict.overlapping(lam, rad).any()
    assert verdict.spectrum(lam, rad).label[0] == "boundary"
    assert verdict.spectrum(lam, rad, conservative=False).label[0] == "boundary"  # on the axis: undecided
