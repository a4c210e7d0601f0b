"""The ladder of methods (gyro.ladder): each method against the arbitrary-precision
reference, where each one fails, and that the default method detects the hard cases and
escalates so that its error stays within its stated estimate (and within 1e-10)."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from gyro import ladder, load, qep
from gyro.equilibrium import equilibria, operators
from gyro.methods import default, reference

MODEL = load("torsion_gyrocompass")
TOL = ladder.DEFAULT_TOL
_REF = {}


def params(**over):
    return MODEL.vector(MODEL.parameters(over))


def ref(**over):
    key = tuple(sorted(over.items()))
    if key not in _REF:
        _REF[key] = ladder.spectrum(MODEL, params(**over), "reference")
    return _REF[key]


def lam(s):
    """Eigenvalues growth + i omega, (sets, modes)."""
    return s.growth + 1j * s.frequencies


def rel_err(s, r):
    return np.abs(lam(s)[0] - lam(r)[0]) / np.abs(lam(r)[0])


# regimes where some method fails (docs/methods.md); each is a valid parameter set
EDGES = {
    "example": {},
    "phi 0": {"phi": 0.0},
    "phi 89.99": {"phi": 89.99},
    "spin /1000 (Omega -> 0)": {"H": 0.452316e-3},
    "spin x10": {"H": 4.52316},
    "Kgamma /100": {"Kgamma": 0.37632},
    "delta_b = 0 (l1 = l2)": {"l1": 0.2, "l2": 0.2},
    "crossing of omega_p with the second nutation": {"Kp": 0.4 * 644.4373602**2},
    "top-heavy (l_c < 0)": {"l1": -0.05, "l2": -0.05},
}


@pytest.mark.parametrize("case", list(EDGES))
def test_default_within_its_estimate_and_1e_10(case):
    """On every regime the default meets 1e-10 and its own estimate, whichever rung answers."""
    over = EDGES[case]
    s = ladder.spectrum(MODEL, params(**over), "default")
    err = rel_err(s, ref(**over))
    assert np.all(err <= s.error_estimate[0]), (err, s.error_estimate[0])
    assert np.all(err <= TOL) and np.all(s.error_estimate[0] <= TOL), err


def test_reference_is_self_consistent_across_precisions():
    """40 digits against 60: the reference's estimate bounds its change."""
    p = params()
    r40 = reference.solve(MODEL, p[None], dps=40)
    r60 = reference.solve(MODEL, p[None], dps=60)
    d = np.abs(lam(r40)[0] - lam(r60)[0]) / np.abs(lam(r60)[0])
    assert np.all(d <= r40.error_estimate[0] + 1e-30)


def test_polyroots_loses_omega1_and_says_so():
    """The naive route: the fitted characteristic polynomial carries absolute errors of
    eps max|det| over [-omega_max^2, 0], which drown the small roots: omega1 has no correct
    digit at the example. Its estimate flags every root it loses."""
    s = ladder.spectrum(MODEL, params(), "polyroots")
    err = rel_err(s, ref())
    assert err[0] > 0.1
    lost = err > 1e-6
    assert np.all(s.error_estimate[0][lost] > 1e-6)


def test_companion_loses_digits_on_the_small_root():
    """The companion eigensolver errs by eps ||A|| absolutely: omega1 keeps only what
    ||A||/omega1 leaves. Toward the pole (phi = 89.99, omega1 = 2.2e-4) it misses 1e-10,
    while its estimate eps ||A||/|lambda| bounds the error; the default does not miss."""
    over = {"phi": 89.99}
    s = ladder.spectrum(MODEL, params(**over), "companion")
    err = rel_err(s, ref(**over))
    assert err[0] > TOL
    assert np.all(err <= s.error_estimate[0])
    assert err[-1] < 1e-13  # the large roots are fine


def test_default_escalates_at_the_pole_where_omega1_is_rounding():
    """At phi = 90 deg, u2 = 0 and omega1 = 0; in double cos(pi/2) rounds to 6e-17 and the
    computed omega1 is noise. K is not exactly singular (its smallest singular value is
    2e-17, not 0), so the default does not take omega1 for an exact zero: it measures the
    inputs' rounding, escalates to the reference, and states an estimate >= 1 for omega1
    (no correct digit): the equilibrium is classified a boundary, not stable. At the exact
    pole omega1 is a zero root (marginal); the rounding of pi/2 leaves u2 of either sign,
    a small oscillation or a slow growth: rounding decides (gyro.results.verdict)."""
    s = ladder.spectrum(MODEL, params(phi=90.0), "default")
    assert s.route[0] == "reference"
    assert s.error_estimate[0][0] >= 1 and s.frequencies[0][0] < 1e-8
    assert np.all(s.error_estimate[0][1:] <= TOL)
    st = ladder.classify(s)
    assert st.label[0] == "boundary" and "not resolved from zero" in st.reason[0]
    # and the formulas rung says the same of its omega1 (rounding of u2 in its estimate)
    f = ladder.spectrum(MODEL, params(phi=90.0), "formulas")
    assert f.error_estimate[0][0] >= 1


def test_without_earth_rate_the_azimuth_is_neutral():
    s = ladder.spectrum(MODEL, params(u=0.0), "default")
    assert ladder.classify(s).label[0] == "marginal"
    # K exactly singular: the zero root answered without the 40-digit rung, as 0
    assert s.route[0] == "general, a zero root" and s.frequencies[0][0] == 0.0


@pytest.mark.parametrize("over, label", [
    ({"u": 0.0, "g": 1.0}, "marginal"),  # a zero root found exactly (estimate 0): still neutral
    ({"u": 0.0, "g": 0.0}, "marginal"),  # two zero pairs
    ({"u": 0.0, "H": 1e-9}, "marginal"),
    ({"u": 1e-8, "phi": 89.9999}, "stable"),  # a small true omega1 (2.6e-7): not a zero root
])
def test_zero_roots_are_neutral_and_small_roots_are_not_taken_for_zero(over, label):
    """Found in review: an exact zero root with an estimate of 0 was called stable, and the
    zero-root shortcut fired on a small true root. Both now agree with the reference."""
    s = ladder.spectrum(MODEL, params(**over), "default")
    assert ladder.classify(s).label[0] == label, (over, s.frequencies[0][:2], s.error_estimate[0][:2], s.route)
    if label == "stable":
        r = ladder.spectrum(MODEL, params(**over), "reference")
        assert abs(s.frequencies[0][0] / r.frequencies[0][0] - 1) <= s.error_estimate[0][0]


FORMULA_CASES = {
    "example": {},
    "spin /10": {"H": 0.0452316},
    "spin x10": {"H": 4.52316},
    "Kgamma /10 (kappa6 large)": {"Kgamma": 3.7632},
    "phi 0": {"phi": 0.0},
    "delta_b = 0": {"l1": 0.2, "l2": 0.2},
    "light casing (I2 / 10)": {"I2": 1e-3},
    "heavy casing (M x5)": {"M": 3.0},
    "long torsion bar (l = 0.5)": {"l": 0.5},
}


# The calibrated constants (omega1, (3.26), (3.28); docs/methods.md) were set on random
# sets varying spin, K0, Kp, K_gamma and latitude, and on the spin / 1000 edge: of the cases
# above, "example", "spin /10", "spin x10", "Kgamma /10" and "phi 0" lie in those
# directions. The held-out cases move only parameters the calibration never varied (the
# masses, lengths, inertias and g), each by 1/2 and 2, chosen before looking at the result.
# Measured worst ratio of error to estimate over them: 0.77 (l x2).
HELD_OUT = {f"{k} x{fct:g}": {k: MODEL.defaults[k] * fct}
            for k in ("m", "M", "I1", "I2", "I3", "A", "C", "l", "l1", "l2", "g") for fct in (0.5, 2.0)}


@pytest.mark.parametrize("case", list(FORMULA_CASES) + [f"held out: {k}" for k in HELD_OUT])
def test_formula_estimates_bound_their_errors(case):
    """Each mode's formula against the nearest exact root: the error stays below the
    formula's own estimate (its small parameter to its order), and every formula that errs
    by more than 1 % is flagged (estimate above 1 %)."""
    over = HELD_OUT[case[10:]] if case.startswith("held out: ") else FORMULA_CASES[case]
    f = ladder.spectrum(MODEL, params(**over), "formulas")
    d = ladder.spectrum(MODEL, params(**over), "default")
    err = np.min(np.abs(f.frequencies[0][:, None] / d.frequencies[0][None, :] - 1), axis=1)
    est = f.error_estimate[0]
    ok = np.isfinite(f.frequencies[0])
    assert np.all(err[ok] <= est[ok]), (err, est)
    assert np.all(est[err > 0.01] > 0.01)


def _formula_error(over, name):
    """(error against the nearest exact root, estimate, formula values) of the mode whose
    formula is `name`."""
    f = ladder.spectrum(MODEL, params(**over), "formulas")
    d = ladder.spectrum(MODEL, params(**over), "default")
    F = dict(zip([x["name"] for x in MODEL.meta["formulas"]], MODEL.numpy.formulas(params(**over))))
    j = int(np.argmin(np.abs(f.frequencies[0] - F[name])))
    err = np.min(np.abs(f.frequencies[0][j] / d.frequencies[0] - 1))
    return err, f.error_estimate[0][j], F


@pytest.mark.parametrize("over", [{"l1": 0.2, "l2": 0.2}, {"I2": 1e-3}, {"M": 3.0}],
                         ids=["delta_b = 0", "I2 / 10", "M x5"])
def test_estimate_of_3_4_is_the_next_term_of_its_series(over):
    """(3.4) is the series of Delta1's root in g to first order. Its estimate is the omitted
    term g^2 x2 relative to omega^2, derived from Delta1 (root_series): twice the relative
    error it causes. Where the second-order coefficient is large (delta_b = 0, a light
    casing, a heavy one) the error exceeds the earlier estimate eps2^2, and the derived one
    meets it within 0.4..0.6 of itself: the truncation is that term."""
    err, est, F = _formula_error(over, "omega2_eq")
    assert err > F["eps2"] ** 2
    assert 0.4 < err / est < 0.6, (err, est)


def test_nutation_estimate_is_exceeded_far_from_the_example():
    """A limit of a calibrated estimate, pinned (docs/methods.md): with a long torsion bar
    and a heavy casing about x3 (l = 0.75 m, I3 x5: a = 13.5) the nutation root near 160 1/s
    errs by 10.4 %, 3.0 times its estimate mu1 + kappa6 = 3.5 %. What matters, asserted:
    - the estimate is exceeded (this pins the known limit: when the estimate is replaced,
      this test must change with docs/methods.md);
    - by at most 15.5x, the worst ratio the wide sweep records for the nutation roots
      (bench/results/formula_sweep.json, docs/methods.md): this set is no new extreme;
    - the estimate still says more than 1 %, so the formula is flagged (on the wide sweep
      some sets are not).
    The error is not the gravity shift: between g = u = 0 and the example's g, u the exact
    root moves by 6.3e-5 (asserted below 1e-3), so the 10 % is the distance of the formula
    to the g = 0 root itself."""
    over = {"l": 0.75, "I3": 0.0015}
    f = ladder.spectrum(MODEL, params(**over), "formulas")
    d = ladder.spectrum(MODEL, params(**over), "default")
    err = np.min(np.abs(f.frequencies[0][:, None] / d.frequencies[0][None, :] - 1), axis=1)
    j = int(np.argmax(err / f.error_estimate[0]))
    est = f.error_estimate[0][j]
    assert abs(f.frequencies[0][j] - 160) < 1 and err[j] > 0.09
    assert est < err[j] <= 15.5 * est
    assert est > 0.01
    d0 = ladder.spectrum(MODEL, params(**over, g=0.0, u=0.0), "default")
    w = d.frequencies[0][np.argmin(np.abs(d.frequencies[0] - f.frequencies[0][j]))]
    w0 = d0.frequencies[0][np.argmin(np.abs(d0.frequencies[0] - w))]
    assert abs(w / w0 - 1) < 1e-3


def test_estimate_of_3_9_holds_where_delta6_squared_does_not():
    """(3.9) is the series of the pendulum root of det J''(p) in g to second order (its
    second term is the derived z2, asserted in tests/generated/test_derivation.py). With a long
    torsion bar (l = 0.5 m) delta6^2 underestimates its error by 1.6x. The omitted term
    g^3 z3 relative to omega^2 is twice the relative error it causes, as for (3.4): the
    error is 0.4..0.6 of it, and within the estimate (that term plus delta6^2)."""
    err, est, F = _formula_error({"l": 0.5}, "omega6_eq")
    assert err > F["delta6"] ** 2
    assert 0.4 < err / F["omega6_next_eq"] < 0.6, (err, F["omega6_next_eq"])
    assert err <= est


def test_formulas_pick_the_small_k_family_at_small_spin():
    """(3.26) holds for large k = Omega/omega_y, (3.28) for small k: the rung takes the
    family with the smaller estimate, and at k = 0.03 the small-k one is taken and is
    within k^2 + kappa6 of the exact roots."""
    over = {"H": 0.452316 / 224}
    f = ladder.spectrum(MODEL, params(**over), "formulas")
    with np.errstate(all="ignore"):  # (3.26) leaves its domain there: that is the point
        F = dict(zip([x["name"] for x in MODEL.meta["formulas"]], MODEL.numpy.formulas(params(**over))))
    assert F["k"] < 0.05
    assert np.any(np.isclose(f.frequencies[0], F["omega9_smallk"], rtol=1e-15))
    assert not np.any(np.isclose(f.frequencies[0], F["omega9"], rtol=1e-15))


def test_stability_pendulous_against_top_heavy():
    """l_c > 0 (the example) is stable; l_c < 0 is unstable with a real growth rate that
    the general rung and the reference agree on."""
    stable = ladder.classify(ladder.spectrum(MODEL, params(), "default"))
    top = ladder.spectrum(MODEL, params(l1=-0.05, l2=-0.05), "default")
    c = ladder.classify(top)
    assert stable.label[0] == "stable" and stable.growth_rate[0] == 0
    assert c.label[0] == "unstable"
    r = ref(l1=-0.05, l2=-0.05)
    assert abs(c.growth_rate[0] / np.max(r.growth[0]) - 1) < 1e-10


def test_stability_across_Kgamma():
    """Across the rotor's angular stiffness the pendulous gyrocompass stays stable and the
    top-heavy one stays unstable; the growth rate of the top-heavy one falls as K_gamma
    grows (the stiffer rotor spring couples more of the spin's gyroscopic stiffness)."""
    Kg = np.geomspace(1.0, 1000.0, 7)
    P = np.tile(params(), (len(Kg), 1))
    P[:, MODEL.param_names.index("Kgamma")] = Kg
    assert set(ladder.classify(ladder.spectrum(MODEL, P)).label) == {"stable"}
    P[:, MODEL.param_names.index("l1")] = -0.05
    P[:, MODEL.param_names.index("l2")] = -0.05
    c = ladder.classify(ladder.spectrum(MODEL, P))
    assert set(c.label) == {"unstable"}
    assert np.all(c.growth_rate > 0)


def test_top_heavy_degree_of_instability_and_gyroscopic_slowing():
    """Top-heavy (m l2 + M l1 < 0): two modes grow. The tilt about the spin axis, which the
    rotor's momentum does not reach, grows at a rate independent of H; the tilt about the
    east axis is coupled by H to the azimuth, whose stiffness is the directive moment
    H u cos(phi), so its rate is sqrt(|k_tilt| H u cos(phi)) / H ~ H^(-1/2): slowed, never
    stopped (the pair has one negative stiffness: an odd count, which gyroscopic forces
    cannot stabilise). Between H = 5 and 50 the log-slope is -1/2 to 1e-2 (the neglected
    terms are of relative order A |k_tilt| / H^2 < 1e-4 and the rotor-bearing coupling)."""
    P = np.array([params(l2=-0.4, H=H) for H in (0.5, 5.0, 50.0)])
    c = ladder.classify(ladder.spectrum(MODEL, P, "default"))
    assert list(c.label) == ["unstable"] * 3 and list(c.unstable_roots) == [2, 2, 2]
    # H reaches the spin-axis tilt only through the weak coupling of the blocks, about 1e-4
    # of the entries at the example (docs/methods.md): its rate moves by less than that
    assert np.ptp(c.growth_rate) / c.growth_rate[0] < 1e-4
    slope = np.log10(c.slowest_growth[2] / c.slowest_growth[1])
    assert abs(slope + 0.5) < 1e-2, slope
    assert c.slowest_growth[0] > 3 * c.slowest_growth[1] > 9 * c.slowest_growth[2]


# random parameter sets within the physical ranges of the charts
SPREAD_RANGES = {"H": (0.1, 10.0), "K0": (0.1, 10.0), "Kp": (0.1, 10.0), "Kgamma": (0.1, 10.0),
                 "phi": (0.0, 89.0), "m": (0.5, 2.0), "M": (0.5, 2.0), "I1": (0.5, 2.0), "A": (0.5, 2.0)}
SPREAD = st.fixed_dictionaries({k: st.floats(lo, hi) for k, (lo, hi) in SPREAD_RANGES.items()})


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(SPREAD)
# an eigenvalue exact to 40 digits made J(lambda) singular in the reference's Newton step
@example({"H": 6.391888379046224, "K0": 0.1, "Kp": 7.2037253537765364, "Kgamma": 1.0, "phi": 0.0,
          "m": 1.0, "M": 0.5, "I1": 1.0, "A": 1.0})
def test_default_meets_its_bound_on_random_sets(draw):
    over = {k: (v if k == "phi" else MODEL.defaults[k] * v) for k, v in draw.items()}
    p = MODEL.vector(MODEL.parameters(over))
    s = ladder.spectrum(MODEL, p, "default")
    r = ladder.spectrum(MODEL, p, "reference")
    err = rel_err(s, r)
    assert np.all(err <= s.error_estimate[0]) and np.all(err <= TOL), (over, err)


# Budget: the mpmath reference costs ~0.8 s a set, so the hypothesis test above draws 12
# sets (~10 s). The seeded sweep below takes 400 sets from the same ranges and checks the
# default against the general rung run set by set (companion eigenvalues, each refined by
# Newton on the exact operator, with its own rounding estimate): ~3.5 ms a set, ~1.5 s in
# all. The general rung is a different algorithm from the default's block route (the
# default escalates to it only on hard sets), so an error in either shows.
SWEEP_SETS = 400


def test_default_agrees_with_the_refined_companion_on_a_seeded_sweep():
    rng = np.random.default_rng(20261130)
    names = list(SPREAD_RANGES)
    lo, hi = np.array([SPREAD_RANGES[k] for k in names]).T
    draws = lo + (hi - lo) * rng.random((SWEEP_SETS, len(names)))
    P = np.array([params(**{k: (v if k == "phi" else MODEL.defaults[k] * v) for k, v in zip(names, d)})
                  for d in draws])
    s = ladder.spectrum(MODEL, P, "default")
    worst = 0.0
    for i in range(SWEEP_SETS):
        qe, _ = equilibria(MODEL, P[i:i + 1])
        M, D, K = operators(MODEL, P[i:i + 1], qe)
        g_roots, g_est = qep.general(M[0], D[0], K[0])
        up = g_roots.imag >= 0
        g_roots, g_est = g_roots[up], g_est[up]
        for lam_d, est_d in zip(lam(s)[i], s.error_estimate[i]):
            j = int(np.argmin(np.abs(g_roots - lam_d)))
            d = abs(g_roots[j] - lam_d) / abs(g_roots[j])
            assert d <= est_d + g_est[j] and d <= TOL + g_est[j], (draws[i], lam_d, g_roots[j], est_d, g_est[j])
            worst = max(worst, d)
    assert worst <= TOL


def test_batch_equals_single_sets():
    """Vectorised over a batch: the same answers as set by set."""
    P = np.array([params(), params(H=1.0), params(phi=10.0)])
    batch = ladder.spectrum(MODEL, P, "default")
    for k in range(3):
        one = ladder.spectrum(MODEL, P[k], "default")
        np.testing.assert_allclose(one.frequencies[0], batch.frequencies[k], rtol=1e-14)


def _without_compiler(monkeypatch) -> list:
    """The default method's NumPy path: the generated C kernels reported unavailable. The
    returned list records each refusal."""
    from gyro import cbackend

    refused = []

    def unavailable(name):
        refused.append(name)
        raise cbackend.CompilerUnavailable("test: NumPy path")

    monkeypatch.setattr(cbackend, "qep_refine", unavailable)
    monkeypatch.setattr(cbackend, "qep_hermitian", unavailable)
    monkeypatch.setattr(cbackend, "qep_block_starts", unavailable)
    monkeypatch.setattr(cbackend, "mode_formulas_selected", unavailable)
    return refused


def test_compiled_kernels_agree_with_the_numpy_path(monkeypatch):
    """The generated C (templates/qep.c.j2) and the NumPy path of the default method are the
    same algorithm: on the edges above they take the same route, and their frequencies agree
    to far below the tolerance (their LU factorisations round differently, hence 1e-12)."""
    P = np.array([params(**over) for over in EDGES.values()])
    compiled = ladder.spectrum(MODEL, P, "default")
    refused = _without_compiler(monkeypatch)
    numpy_path = ladder.spectrum(MODEL, P, "default")
    assert len(refused) >= 2  # both kernels were asked for and the NumPy path answered
    assert list(compiled.route) == list(numpy_path.route)
    np.testing.assert_allclose(compiled.frequencies, numpy_path.frequencies, rtol=1e-12)
    np.testing.assert_allclose(compiled.growth, numpy_path.growth, rtol=1e-12, atol=1e-12)
    assert np.all(numpy_path.error_estimate <= TOL) and np.all(compiled.error_estimate <= TOL)


def test_compiled_formula_selection_agrees_with_numpy(monkeypatch):
    """The generated selection and sort of the mode formulas (templates/mode_select.c.j2)
    against the NumPy path: over the edges, the pole itself (omega1 = 0 to rounding: outside
    its formula's domain) and u = 0, where formulas divide 0 by 0. The same candidates, the
    same order, the same domain verdicts; values to rounding (C and NumPy evaluate the
    formulas' expressions with different elementary functions)."""
    P = np.array([params(**over) for over in EDGES.values()] + [params(phi=90.0), params(u=0.0)])
    compiled = ladder.spectrum(MODEL, P, "formulas")
    refused = _without_compiler(monkeypatch)
    numpy_path = ladder.spectrum(MODEL, P, "formulas")
    assert refused == ["torsion_gyrocompass"]
    assert not np.all(np.isfinite(numpy_path.error_estimate))  # the domain check is exercised
    np.testing.assert_array_equal(np.isinf(compiled.error_estimate), np.isinf(numpy_path.error_estimate))
    np.testing.assert_allclose(compiled.frequencies, numpy_path.frequencies, rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(compiled.error_estimate, numpy_path.error_estimate, rtol=1e-12)


def test_compiled_kernels_refuse_wrong_shapes():
    """The kernels check shapes before C reads the arrays: a block index past n, repeated
    indices, a parameter row of the wrong length, operators of the wrong size."""
    from gyro import cbackend

    P = params()[None]
    qe, _ = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    herm = cbackend.qep_hermitian(MODEL.name)
    for idx in ([0, 10], [1, 1], list(range(11)), []):
        with pytest.raises(ValueError, match="block indices"):
            herm(M, D, K, idx)
    with pytest.raises(ValueError, match="params"):
        cbackend.mode_formulas_selected(MODEL.name)(params())  # one set, not a batch
    with pytest.raises(ValueError, match="M, D, K"):
        cbackend.qep_refine(MODEL.name)(M[:, :9, :9], D, K, np.ones((1, 3)), np.ones(10), 1, 0.0)


def test_large_batches_run_in_pieces_with_the_same_answers(monkeypatch):
    """Beyond CHUNK sets the default runs piece by piece (bounded memory): the answers and
    routes are those of the sets alone. With CHUNK at 64 (8192 in use): the same pieces'
    logic on 69 sets, not 8 200."""
    monkeypatch.setattr(default, "CHUNK", 64)
    P = np.array([params(), params(phi=89.99), params(l1=-0.05, l2=-0.05)])
    big = np.tile(P, (default.CHUNK // 3 + 2, 1))
    s = ladder.spectrum(MODEL, big, "default")
    alone = ladder.spectrum(MODEL, P, "default")
    assert s.frequencies.shape == (len(big), 10) and s.equilibrium.shape[0] == len(big)
    for k in (0, default.CHUNK - 1, default.CHUNK, len(big) - 1):
        np.testing.assert_array_equal(s.frequencies[k], alone.frequencies[k % 3])
        assert s.route[k] == alone.route[k % 3]


def test_no_equilibrium_in_any_precision_is_said():
    """Inputs beyond double precision (Kp = 1e300): no rung answers; the route says 'none',
    the frequencies are NaN, and the one-set API raises instead of returning them."""
    from gyro.equilibrium import EquilibriumError

    s = ladder.spectrum(MODEL, params(Kp=1e300), "default")
    assert s.route[0] == "none" and np.all(np.isnan(s.frequencies))
    with pytest.raises(EquilibriumError):
        ladder.natural_frequencies(MODEL, MODEL.parameters({"Kp": 1e300}))


def test_refinement_steps_agree_root_by_root():
    """One step of the C refinement is one step of _rayleigh_step: same shift, same vector,
    the same new frequency, vector (up to rounding) and estimate."""
    from gyro.cbackend import qep_refine

    P = np.array([params(), params(phi=60.0), params(H=0.1)])
    qe, _ = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    n = M.shape[-1]
    rng = np.random.default_rng(1)
    w0 = np.sort(np.abs(ladder.spectrum(MODEL, P, "companion").frequencies), axis=1)
    w0 = w0 * (1 + 1e-4 * rng.standard_normal(w0.shape))
    z0 = qep.start_vectors(len(P), n, n)
    wc, zc, ec, okc = qep_refine(MODEL.name)(M, D, K, w0, z0, 1, 0.0)
    wn, zn, en, okn = qep.rayleigh_step(M, D, K, w0, np.array(z0))
    assert okc.all() and okn.all()
    np.testing.assert_allclose(wc, wn, rtol=1e-12)
    np.testing.assert_allclose(np.abs(np.sum(zc.conj() * zn, axis=-1)), 1.0, rtol=1e-10)
    np.testing.assert_allclose(ec, en, rtol=1e-3)


def test_refinement_in_place_gives_the_same_answers():
    """With overwrite the compiled refinement works in the caller's w and z (no copy of
    the vectors) and answers to the bit as with copies; a z it cannot use as it is (a
    broadcast start, another dtype) is copied as before, the caller's array untouched."""
    from gyro.cbackend import qep_refine

    P = np.array([params(), params(phi=60.0), params(H=0.1)])
    qe, _ = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    n = M.shape[-1]
    w0 = np.sort(np.abs(ladder.spectrum(MODEL, P, "companion").frequencies), axis=1) * (1 + 1e-6)
    z0 = np.array(qep.start_vectors(len(P), n, n))
    refine = qep_refine(MODEL.name)
    ref = refine(M, D, K, w0, z0, 3, ladder.DEFAULT_TOL)
    w1, z1 = w0.copy(), z0.copy()
    got = refine(M, D, K, w1, z1, 3, ladder.DEFAULT_TOL, overwrite=True)
    assert got[0] is w1 and got[1] is z1
    for a, b in zip(ref, got):
        assert np.array_equal(a, b)
    shared = qep.start_vectors(len(P), n, n)  # read-only broadcast: copied
    z2 = z0.astype(np.complex64)
    for z in (shared, z2):
        before = np.array(z)
        got = refine(M, D, K, w0.copy(), z, 3, ladder.DEFAULT_TOL, overwrite=True)
        assert got[1] is not z and np.array_equal(np.array(z), before)
    w3 = w0.copy()
    w3.setflags(write=False)  # a read-only w: copied, not written
    got = refine(M, D, K, w3, z0.copy(), 3, ladder.DEFAULT_TOL, overwrite=True)
    assert got[0] is not w3 and np.array_equal(w3, w0) and np.array_equal(got[0], ref[0])


def test_a_lane_whose_step_fails_is_taken_again_by_the_pivoted_steps():
    """A start on a root to the last bit makes J(i w) exactly singular (here a zero row: M = I,
    D = 0, K = diag(k^2), w = 1): that lane's step in the compiled refinement fails, and the
    set's root is taken again from its start by the scalar steps, whose shifts move off the
    root; the other lanes of its group are not touched, and the set's answer is the one it
    gets alone (a tail of one set, the same path)."""
    from gyro.cbackend import qep_refine

    n, sets = 10, 9  # the torsion gyrocompass operator: 10 x 10
    roots = np.arange(n) + 1.0
    M, D, K = np.tile(np.eye(n), (sets, 1, 1)), np.zeros((sets, n, n)), np.tile(np.diag(roots**2), (sets, 1, 1))
    w0 = np.tile(roots * (1 + 1e-3), (sets, 1))
    w0[3, 0] = 1.0
    z0 = qep.start_vectors(sets, n, n)
    refine = qep_refine(MODEL.name)
    w, _, e, ok = refine(M, D, K, w0, z0, 3, ladder.DEFAULT_TOL)
    assert ok.all() and np.all(e <= ladder.DEFAULT_TOL)
    np.testing.assert_allclose(w, np.tile(roots, (sets, 1)), rtol=1e-14)
    alone = refine(M[3:4], D[3:4], K[3:4], w0[3:4], z0[3:4], 3, ladder.DEFAULT_TOL)
    np.testing.assert_array_equal(alone[0][0], w[3])
    np.testing.assert_array_equal(alone[2][0], e[3])


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "gyro", *args], capture_output=True, text=True)


@pytest.mark.parametrize("method", ladder.METHODS)
def test_cli_method_json(method):
    p = _cli("frequencies", "torsion_gyrocompass", "--method", method, "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["method"] == method
    assert len(out["error_estimate"]) == len(out["frequencies"]) == 10
    assert {"model", "params", "frequencies", "method", "error_estimate"} <= set(out)


def test_cli_default_method_when_none_given():
    out = json.loads(_cli("frequencies", "torsion_gyrocompass", "--json").stdout)
    assert out["method"] == "default" and max(out["error_estimate"]) <= TOL
    assert out["stability"]["class"] == "stable"


def test_cli_bad_method_exits_2_in_one_line():
    p = _cli("frequencies", "torsion_gyrocompass", "--method", "newton")
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "--method" in p.stderr


def test_cli_campbell_writes_a_png(tmp_path):
    out = tmp_path / "c.png"
    p = _cli("campbell", "torsion_gyrocompass", "--out", str(out), "--points", "12", "--quiet")
    assert p.returncode == 0, p.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask  # an ordinary file, not a private temporary


@pytest.mark.parametrize("args, word", [
    (["--out", "c.txt"], "--out"),
    (["--out", "/nonexistent-dir/c.png"], "--out"),
    (["--out", "c.png", "--range", "2", "1"], "--range"),
    (["--out", "c.png", "--points", "1"], "--points"),
    (["--out", "c.png", "--set", "H=-1"], "H"),
])
def test_cli_campbell_bad_input(tmp_path, args, word):
    p = subprocess.run([sys.executable, "-m", "gyro", "campbell", "torsion_gyrocompass", *args],
                       capture_output=True, text=True, cwd=tmp_path)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and word in p.stderr
    assert not list(tmp_path.glob("*.png"))


def test_cli_stability_map(tmp_path):
    out = tmp_path / "s.png"
    p = _cli("stability-map", "torsion_gyrocompass", "--x", "l2", "--x-range", "-0.3", "0.3",
             "--y", "Kgamma", "--y-range", "1", "100", "--points", "6", "--out", str(out), "--quiet")
    assert p.returncode == 0, p.stderr
    assert "stable" in p.stdout and "unstable" in p.stdout and out.exists()


def test_cli_stability_map_log_axis(tmp_path):
    """A log-spaced axis; a log axis through zero is refused in one line, nothing written."""
    out = tmp_path / "s.png"
    p = _cli("stability-map", "torsion_gyrocompass", "--x", "l2", "--x-range", "-0.5", "0.3",
             "--y", "H", "--y-range", "0.01", "10", "--y-log", "--points", "5", "--out", str(out), "--quiet")
    assert p.returncode == 0, p.stderr
    assert out.exists()
    bad = tmp_path / "bad.png"
    p = _cli("stability-map", "torsion_gyrocompass", "--x", "l2", "--x-range", "-0.5", "0.3",
             "--y", "H", "--y-range", "0", "10", "--y-log", "--out", str(bad), "--quiet")
    assert p.returncode == 2 and "--y-log" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not bad.exists()


def test_the_formulas_in_lanes_are_the_set_by_set_formulas_to_the_last_bit():
    """The compiled formulas run eight sets at a time in structure of arrays (templates/
    mode_select.c.j2); over 1,003 joint sets (a short last block) and a set outside the
    formulas' domain (K_gamma < 0: square roots of negatives) and two sets without gravity
    (three modes at exactly zero: ties, which the lanes' network leaves to the set-by-set
    code, as it does a NaN), their frequencies and estimates are those of the set-by-set
    generated function with the selection and sort done in NumPy, bit for bit (NaN where
    NaN). (The tied zeros' estimates are all infinite, a zero being outside every formula's
    domain: the rows written again must be their own sets', which a wrong row would show.)"""
    from bench.levels import joint
    from gyro.methods.formulas import per_mode

    P = joint(1003, seed=9)
    P[17, MODEL.param_names.index("Kgamma")] *= -1.0
    P[[5, 998], MODEL.param_names.index("g")] = 0.0
    lanes = ladder.spectrum(MODEL, P, "formulas")
    f, e = per_mode(MODEL, P)  # the set-by-set C of mode_formulas
    order = np.argsort(f, axis=1, kind="stable")
    f, e = np.take_along_axis(f, order, 1), np.take_along_axis(e, order, 1)
    assert np.isnan(lanes.frequencies[17]).any()
    for k in (5, 998):  # ties without a NaN: the set-by-set code writes these rows
        assert np.any(np.diff(f[k]) == 0) and not np.isnan(f[k]).any()
    np.testing.assert_array_equal(lanes.frequencies, f)
    np.testing.assert_array_equal(lanes.error_estimate, e)


def test_the_sorting_network_of_the_lanes_sorts_every_input():
    """The comparators the lanes sort the modes with (derive.emit.sorting_network) sort
    every sequence of zeros and ones, for up to 16 keys; by the 0-1 principle they then sort
    every sequence, and with (frequency, row) keys, all distinct, every input ends in the one
    order the set-by-set stable insertion sort gives."""
    import itertools

    from derive.emit import sorting_network

    for n in range(1, 17):
        net = sorting_network(n)
        assert all(0 <= a < b < n for a, b in net)
        v = np.array(list(itertools.product((0, 1), repeat=n)))
        for a, b in net:
            lo, hi = np.minimum(v[:, a], v[:, b]), np.maximum(v[:, a], v[:, b])
            v[:, a], v[:, b] = lo, hi
        assert np.all(np.diff(v, axis=1) >= 0), n


def test_the_formulas_outputs_in_huge_pages_are_plain_writable_arrays():
    """gyro.cbackend.empty_huge, where the compiled formulas write: the shape asked for, C
    order, writable, on a 2 MB boundary from 2 MB up on Linux (a view of a longer buffer, not
    a copy); a small one is plain np.empty; the spectrum's two outputs are views of one."""
    import sys

    from gyro import cbackend

    for shape in [(2, 3, 10), (2, 20000, 10), (2, 200001, 10)]:
        a = cbackend.empty_huge(shape)
        assert a.shape == shape and a.dtype == float and a.flags.c_contiguous and a.flags.writeable
        a[...] = 1.5
        assert np.all(a == 1.5) and a[0].flags.c_contiguous and a[1].flags.c_contiguous
        if a.nbytes >= 2 << 20 and sys.platform.startswith("linux"):
            assert a.ctypes.data % (2 << 20) == 0
    P = np.tile(params(), (30000, 1))
    s = ladder.spectrum(MODEL, P, "formulas")
    np.testing.assert_array_equal(s.frequencies, np.tile(ladder.spectrum(MODEL, P[:1], "formulas").frequencies, (30000, 1)))


def test_polyroots_loses_a_root_to_overflow_without_a_warning():
    """A set of the wide spreads (issue 36) on which the determinant polynomial's root
    estimate overflows: that root is answered with no bound (inf), and no RuntimeWarning
    reaches the caller of the API (it did: 'overflow encountered in divide')."""
    import warnings

    from gyro.models import load

    tg = load("torsion_gyrocompass")
    P = np.array([[0.4, 0.6, 0.15, 0.060341442310162696, 0.38448783653475593, 0.00021822064929620196,
                   0.0004888161359542044, 0.005673558477568775, 0.006861221680933348, 0.00023630758107290843,
                   26108.15689035862, 179720.65625778586, 2.117634118678118, 0.2110216246861012,
                   0.0005962656334723807, 46.47128799627344, 9.81, 0.012435236567161171, 0.0, 0.0, 0.0]])
    assert P.shape[1] == len(tg.param_names)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = ladder.spectrum(tg, P, "polyroots")
    assert np.isinf(s.error_estimate).any() and not np.isnan(s.error_estimate).any()
