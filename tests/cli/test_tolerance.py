"""Tolerance analysis (gyro/analyses/tolerance.py, `gyro tolerance`): first order against
sampling, the samples' spreads and correlations, the band probability, and the
command-line contract."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gyro.analyses.tolerance import (copula_correlation, correlation, parse_spread, samples, tolerance)
from gyro.models import load
from tests.conftest import run_cli

MODEL = "torsion_gyrocompass"
N = 2048


@pytest.fixture(scope="module")
def tg():
    return load(MODEL)


@pytest.fixture(scope="module")
def study(tg):
    spreads = [parse_spread("Kp=normal:0.01"), parse_spread("Kgamma=uniform:0.02"), parse_spread("H=normal:0.005")]
    return tolerance(tg, tg.defaults, spreads, N, seed=11, harmonics=(1,), band=0.02, size=1024)


def test_first_order_against_sampling(study):
    """With spreads of 1-2 % the frequencies are linear in the parameters to 1e-4 of the
    spread (second-order terms are the spread squared), so the sampled std agrees with the
    first-order one within sampling error: its relative standard error is
    sqrt((kurtosis - 1) / 4N), 1.6 % for N = 2048 normal samples; four of them bound it.
    The mean lies within four standard errors std / sqrt(N) of the nominal frequency."""
    se = study.sampling_error()
    assert np.all(np.abs(study.first_order_std / study.std - 1) <= 4 * se)
    assert np.all(np.abs(study.mean - study.nominal) <= 4 * study.std / np.sqrt(N))
    # at N = 2048 three standard errors are 4.7 %: first order cannot be shown within 5 %
    # here, but nothing says it fails
    assert not np.any(study.first_order_verdict() == "fails") and study.failed == 0
    q = study.quantiles
    assert np.all((q[:, 0] < q[:, 1]) & (q[:, 1] < q[:, 2]))


def test_samples_have_the_spreads_and_correlations_asked():
    spreads = [parse_spread("a=normal:0.1"), parse_spread("b=uniform:0.2"), parse_spread("c=uniform:0.3")]
    corr = np.eye(3)
    corr[0, 1] = corr[1, 0] = 0.6
    corr[1, 2] = corr[2, 1] = -0.5
    chol = np.linalg.cholesky(corr)
    nominal = np.array([2.0, 3.0, 5.0])
    P = samples(nominal, np.arange(3), np.array([0.1, 0.2, 0.3]), np.array([False, True, True]), chol, 1, 0,
                100_000)
    dev = P / nominal - 1
    # 1e5 samples: standard errors of 0.3 % on a std and 0.003 on a correlation; bounds of four
    assert abs(dev[:, 0].std() / 0.1 - 1) < 0.012
    assert abs(dev[:, 1].std() / (0.2 / np.sqrt(3)) - 1) < 0.012
    assert np.all(np.abs(dev[:, 1]) <= 0.2) and np.all(np.abs(dev[:, 2]) <= 0.3)  # uniform within the tolerance
    expect = copula_correlation(spreads, corr)
    got = np.corrcoef(dev.T)
    assert np.all(np.abs(got - expect) < 0.012), (got, expect)


def test_correlations_are_checked(tg):
    spreads = [parse_spread("Kp=normal:0.05"), parse_spread("K0=normal:0.05"), parse_spread("m=normal:0.01")]
    with pytest.raises(Exception, match="positive definite"):
        correlation(spreads, {("Kp", "K0"): 0.9, ("K0", "m"): 0.9, ("Kp", "m"): -0.9})
    with pytest.raises(Exception, match="has no --spread"):
        correlation(spreads, {("Kp", "A"): 0.5})


def test_band_probability(study):
    """No mode of the paper's set lies within 2 % of the spin rate H/C = 2513 rad/s (the
    nearest, omega9 = 1114 and omega10 = 3851, are 56 % and 53 % away, dozens of standard
    deviations): both probabilities are zero."""
    for row in study.band_probability:
        assert row[0]["probability"] == 0 and row[0]["first_order_probability"] < 1e-12


def test_band_probability_at_a_band_edge(tg):
    """A spread of C alone moves no frequency (the operator has H, not C) but the spin rate
    omega_c = H/C: with a band of 55 % the lower edge 0.45 omega_c = 1131 lies 1.5 % above
    omega9 = 1114, so omega9 is inside when C > 0.45 H / omega9, a probability known in
    closed form, 1 - Phi(z*), z* = (0.45 H / (omega9 C0) - 1) / sigma (about 0.068); the
    sampled one lies within four binomial standard errors of it (0.0016 for N = 4096), and
    the first-order one is the lower edge linearised, omega9 - 0.45 omega_c normal with the
    std 0.45 omega_c sigma: Phi((omega9 / (0.45 omega_c) - 1) / sigma), to rounding. With
    the edge's std taken as omega_c sigma (the factor 0.45 lost) it would be 0.25."""
    from scipy.special import ndtr

    n, sigma, band = 4096, 0.01, 0.55
    st = tolerance(tg, tg.defaults, [parse_spread(f"C=normal:{sigma}")], n, seed=5, harmonics=(1,), band=band)
    H, C0 = tg.defaults["H"], tg.defaults["C"]
    w9, wc = st.nominal[8], H / C0
    got = st.band_probability[8][0]
    assert got["omega"] == wc
    exact = 1 - ndtr(((1 - band) * H / (w9 * C0) - 1) / sigma)
    assert abs(got["probability"] - exact) <= 4 * np.sqrt(exact * (1 - exact) / n), (got, exact)
    assert abs(got["first_order_probability"] - ndtr((w9 / ((1 - band) * wc) - 1) / sigma)) < 1e-12, got


def test_a_frequency_the_spreads_do_not_move(tg):
    """omega_p = sqrt(Kp/m) under a spread of H: its samples differ by rounding only (a
    histogram of them needs a range of its own), and its spreads are nil to rounding."""
    st = tolerance(tg, tg.defaults, [parse_spread("H=normal:0.01")], 256, seed=1)
    i = int(np.argmin(np.abs(st.nominal - 780)))
    assert st.failed == 0 and st.std[i] < 1e-9 * st.nominal[i] and st.first_order_std[i] < 1e-9 * st.nominal[i]
    assert np.all(np.diff(st.edges[i]) > 0) and st.counts[i].sum() == 256


def test_a_mode_without_sensitivities_has_no_first_order(tg):
    """At u = 0 the azimuth is free: omega1 = 0 is a double root (with its mirror), so it has
    no sensitivities, and neither a first-order std nor a first-order band probability: null
    in the JSON and said in the table, never a number (a point mass would give 0 or 1)."""
    st = tolerance(tg, {**tg.defaults, "u": 0.0}, [parse_spread("Kp=normal:0.01")], 64, seed=1, harmonics=(1,))
    doc = json.loads(json.dumps(st.to_dict(), allow_nan=False))
    assert doc["frequencies"][0]["first_order_std"] is None and doc["frequencies"][0]["first_order_holds"] is None
    assert doc["band_probability"][0][0]["first_order_probability"] is None
    assert doc["band_probability"][8][0]["first_order_probability"] is not None
    assert "none (a double root at the nominal set)" in st.table().splitlines()[3]


def test_cli_contract(tg, tmp_path):
    out = tmp_path / "h.png"
    rc, text, err = run_cli("tolerance", MODEL, "--spread", "Kp=normal:0.05", "--spread", "Kgamma=uniform:0.1",
                            "--samples", "300", "--seed", "4", "--json", "--out", str(out), "--harmonics", "1,2")
    assert rc == 0, err
    doc = json.loads(text)
    assert {"model", "samples", "seed", "frequencies", "sensitivities", "failed"} <= set(doc)
    assert doc["model"] == MODEL and doc["samples"] == 300 and doc["seed"] == 4 and doc["failed"] == 0
    mode = doc["frequencies"][0]
    assert {"mean", "std", "quantiles", "first_order_std"} <= set(mode)
    assert set(mode["quantiles"]) == {"0.01", "0.5", "0.99"}
    assert len(doc["sensitivities"]) == len(doc["frequencies"]) and len(doc["sensitivities"][0]) == len(tg.param_names)
    assert len(doc["band_probability"][0]) == 2
    assert out.stat().st_size > 10_000
    for bad, what in ((["--spread", "Kq=normal:0.05"], "Kq"), (["--spread", "Kp=gauss:0.05"], "--spread"),
                      (["--spread", "Kp=normal:-1"], "--spread Kp"), (["--spread", "Kp=normal:0.05", "--samples", "0"], "--samples"),
                      (["--spread", "Kp=normal:0.05", "--correlate", "Kp,K0=0.5"], "K0"),
                      (["--spread", "Kp=normal:0.05", "--harmonics", "0"], "--harmonics"),
                      (["--spread", "Kp=normal:0.05", "--harmonics", "1", "--set", "H=0"], "--harmonics"),
                      (["--spread", "Kp=normal:0.05", "--out", str(tmp_path / "x.jpg")], "--out")):
        args = ["tolerance", MODEL, *bad] + ([] if "--samples" in bad else ["--samples", "10"])
        rc, text, err = run_cli(*args)
        assert rc == 2 and what in err and len(err.strip().splitlines()) == 1 and text == "", (bad, err)


def test_the_first_order_verdict_is_three_way(study):
    """holds / fails only where three standard errors of sampling leave no doubt about the
    5 % criterion; undecided between; none without a first order. With N = 2048 samples and
    kurtosis 3 the margin is 3 sqrt(2 / 4N) = 4.7 %: a difference of 0.1 % holds, 20 %
    fails, 5 % is undecided (it was called 'holds', within 5 % + the margin)."""
    from dataclasses import replace

    n = len(study.nominal)
    err = np.full(n, 0.001)
    err[1], err[2], err[3] = 0.2, 0.05, np.nan
    s = replace(study, std=np.ones(n), first_order_std=1 + err, kurtosis=np.full(n, 3.0), failed=0, samples=2048)
    v = s.first_order_verdict()
    assert list(v[:4]) == ["holds", "fails", "undecided", "none"] and set(v[4:]) == {"holds"}
    doc = s.to_dict()["frequencies"]
    assert [(f["first_order"], f["first_order_holds"]) for f in doc[:4]] == \
        [("holds", True), ("fails", False), ("undecided", None), ("none", None)]
    assert "undecided (+5.0 %)" in s.table().splitlines()[5]


def test_a_band_probability_with_failed_samples_says_its_range(tg):
    """With failed samples (negative stiffnesses of a 40 % spread) the sampled band
    probability is conditional on the answered ones; over all samples it lies in
    probability_range, from none of the failed in the band to all of them."""
    s = tolerance(tg, tg.defaults, [parse_spread("Kp=normal:0.4"), parse_spread("K0=normal:0.4")], 2000, seed=2,
                  harmonics=(1,), band=0.02)
    assert s.failed > 0
    for row in s.to_dict()["band_probability"]:
        b = row[0]
        lo, hi = b["probability_range"]
        assert lo == pytest.approx(b["probability"] * s.answered / s.samples) and hi == pytest.approx(lo + s.failed / s.samples)
    assert f"of the {s.answered} answered samples" in s.table()


def test_harmonics_of_any_model_that_declares_its_spin():
    """--harmonics takes the spin as the model declares it (Model.spin, the emitted
    spin_rate and its gradient), not parameters named H and C: the rigid rotor of
    examples/rigid_rotor.py (spin Omega) answers, with each harmonic at k Omega, the sampled
    and first-order probabilities of its second mode within three standard errors of the
    sampled one, sqrt(p (1 - p) / 400) = 0.024 at p = 0.33 (the study's own test of first
    order: 0.07); a model that declares no spin is refused in one line."""
    from tests.conftest import ROOT, run_cli

    rotor = str(ROOT / "examples" / "rigid_rotor.py")
    rc, out, err = run_cli("tolerance", rotor, "--spread", "ky1=normal:0.05", "--harmonics", "1,2",
                           "--samples", "400", "--set", "Omega=300", "--json")
    assert rc == 0, err
    bands = json.loads(out)["band_probability"]
    assert [b["omega"] for b in bands[0]] == [300.0, 600.0]
    hit = bands[1][0]
    p = hit["probability"]
    assert 0.1 < p < 0.6 and abs(p - hit["first_order_probability"]) < 3 * np.sqrt(p * (1 - p) / 400)
    rc, out, err = run_cli("tolerance", str(ROOT / "tests" / "models" / "damped_oscillator.py"), "--spread",
                           "k=normal:0.05", "--harmonics", "1", "--samples", "50")
    assert rc == 2 and out == "" and "damped_oscillator declares no spin" in err
