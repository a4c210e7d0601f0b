"""Forced vibration from the bearing imperfections (003, section 2): the forcing (1.10)-(1.11)
as the emitted inputs, the response per harmonic, resonances, damping, the `gyro forced` and
`gyro unbalance` contracts, and the frequency methods on a damped gyrocompass."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from conftest import run_cli
from gyro import load
from gyro.analyses.forced import forced_response, parse_harmonic, response_curve, spin_rate
from gyro.analyses.harmonic import harmonic_response
from gyro.errors import ParameterError
from gyro.ladder import spectrum

MODEL = load("torsion_gyrocompass")
PAPER_Q = ["x1", "x3", "gamma", "mu", "x2", "gamma1", "gamma2", "alpha", "beta", "lambda"]


def test_each_harmonic_is_its_input_and_the_sum_is_superposed():
    """f_s = a sin(k omega_c t + phi) is the input u_s = -i a e^{i phi} at k omega_c: the
    result equals harmonic_response with that input bit for bit, its sine-form phase is
    arg X + pi/2, and the time series of two harmonics is the sum of the two."""
    P = MODEL.vector({"cp": 0.5})
    hs = [(1, 1, 0.02, 0.3), (3, 2, 0.01, -1.0)]
    r = forced_response(MODEL, P, hs)
    W = r.spin_rate[0]
    for j, (s, k, a, phi) in enumerate(hs):
        u = np.zeros(3, complex)
        u[s - 1] = -1j * a * np.exp(1j * phi)
        X = harmonic_response(MODEL, P, k * W, u).X[0]
        assert np.array_equal(r.X[0, j], X)
        t = np.linspace(0, 0.01, 5)
        sine = r.amplitudes[0, j][None] * np.sin(k * W * t[:, None] + r.phases[0, j][None])
        assert np.allclose(r.time_series(t, harmonics=[j]), sine, rtol=0, atol=1e-12 * np.max(r.amplitudes[0, j]))
    t = np.linspace(0, 0.02, 9)
    assert np.allclose(r.time_series(t), r.time_series(t, harmonics=[0]) + r.time_series(t, harmonics=[1]),
                       rtol=0, atol=1e-15 * np.max(r.amplitudes))


def test_spin_rate_is_the_cyclic_integral_2_3():
    """omega_c = H/C - u cos(phi) - u sin(phi)(beta0 + gamma20): within u/omega_c of H/C."""
    v = MODEL.defaults
    r = forced_response(MODEL, MODEL.vector({}), [(1, 1, 1.0, 0.0)])
    W = v["H"] / v["C"]
    assert 0 < W - r.spin_rate[0] <= 1.001 * v["u"]
    assert spin_rate(MODEL, MODEL.vector({})[None])[0] == W


def _spin_onto(mode: int, over: dict) -> np.ndarray:
    """A parameter set whose omega_c equals natural frequency `mode` (0-based) to rounding:
    H moved twice by C times the gap (omega_c = H/C less an Earth-rate term, the modes that
    do not involve the rotor's spin nearly independent of H)."""
    v = MODEL.parameters(over)
    H = v["C"] * np.sqrt(v["Kp"] / v["m"])
    for _ in range(3):
        P = MODEL.vector({**over, "H": H})
        r = forced_response(MODEL, P, [(3, 1, 1.0, 0.0)])
        H += v["C"] * (r.natural[0, mode] - r.spin_rate[0])
    return MODEL.vector({**over, "H": H})


def test_resonance_named_and_damping_makes_it_finite():
    """omega_c on the radial bearing mode omega5 = omega_p (3.7), the 8th of the ten in
    ascending order (x3 nearly alone: 780 rad/s to 2e-11): undamped, f3 at k = 1 is a
    resonance, named; with cp > 0 the same drive is finite, a/(omega_p cp) on x3 to the
    coupling of x3 with the rest of J' (3e-7 relative, measured)."""
    P = _spin_onto(7, {})
    r = forced_response(MODEL, P, [(3, 1, 1.0, 0.0)])
    d = r.to_dict()["harmonics"][0]
    assert d["resonance"] is True and d["amplitudes"] == [None] * 10
    assert d["nearest_mode"] == 8 and d["nearest_natural_frequency"] == pytest.approx(d["frequency"], rel=1e-13)
    Pd = P.copy()
    Pd[MODEL.param_names.index("cp")] = 1.0
    damped = forced_response(MODEL, Pd, [(3, 1, 1.0, 0.0)]).to_dict()["harmonics"][0]
    assert damped["resonance"] is False
    wp = np.sqrt(MODEL.defaults["Kp"] / MODEL.defaults["m"])
    assert damped["amplitudes"][1] == pytest.approx(1.0 / (wp * 1.0), rel=1e-5)


def test_response_curve_through_the_radial_resonance():
    """Amplitude of x3 against spin for f3, k = 1, through omega_p: undamped it is
    |Kp - m w^2|^-1 to the coupling of x3 with the rest of J' (3e-7 relative, measured; 1e-6
    asserted; 40 points keep every spin 1e-3 away from the resonance), damped (cp = 2) it
    peaks at a/(omega_p cp) at the grid point on the resonance (41 points), to 1e-5."""
    v = MODEL.defaults
    wp = np.sqrt(v["Kp"] / v["m"])
    C = v["C"]
    r = response_curve(MODEL, {}, (3, 1, 1.0, 0.0), 0.9 * wp * C, 1.1 * wp * C, 40)
    x3 = r.amplitudes[:, r.coordinates.index("x3")]
    assert not r.resonance.any()
    assert np.allclose(x3, 1.0 / np.abs(v["Kp"] - v["m"] * r.omega**2), rtol=1e-6, atol=0)
    rd = response_curve(MODEL, {"cp": 2.0}, (3, 1, 1.0, 0.0), 0.9 * wp * C, 1.1 * wp * C, 41)
    assert np.max(rd.amplitudes[:, 1]) == pytest.approx(1.0 / (wp * 2.0), rel=1e-5)
    assert abs(rd.omega[np.argmax(rd.amplitudes[:, 1])] / wp - 1) < 1e-6


def test_frequency_methods_on_a_damped_gyrocompass():
    """Bearing damping makes D non-skew: the default method hands the set to its general rung
    (the structured path would report growth 0), whose roots agree with an independent dense
    eigensolve of the first-order form (scipy, 20x20) within the rung's own estimates plus
    that solve's error (cond(eigenvector) eps |lambda|, bounded here by 1e-9 |lambda|)."""
    from scipy.linalg import eig

    from gyro.equilibrium import equilibria, operators

    P = MODEL.vector({"cp": 5.0, "c0": 2.0, "cgamma": 1e-3})
    d = spectrum(MODEL, P, "default")
    assert d.route[0] != "structured"
    assert np.all(d.growth[0] < 0)
    qe, _ = equilibria(MODEL, P[None])
    M, D, K = (x[0] for x in operators(MODEL, P[None], qe))
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -D]])
    Bm = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), M]])
    lam = eig(A, Bm, right=False)
    lam = lam[lam.imag >= 0]
    for g, w, e in zip(d.growth[0], d.frequencies[0], d.error_estimate[0]):
        mine = g + 1j * w
        assert np.min(np.abs(lam - mine)) <= (e + 1e-9) * abs(mine), mine


@pytest.mark.parametrize("text, what", [("4:1:1", "S"), ("0:1:1", "S"), ("1:0:1", "K"), ("1:1.5:1", "K"),
                                         ("1:-2:1", "K"), ("1:1:nan", "AMP"), ("1:1:inf", "AMP"),
                                         ("1:1:1:x", "PHASE"), ("1:1", "S:K:AMP")])
def test_bad_harmonic_is_refused(text, what):
    with pytest.raises(ParameterError, match=what):
        parse_harmonic(text)


# --------------------------------------------------------------------------- command line


def test_gyro_forced_json_contract(tmp_path):
    out = tmp_path / "spectrum.png"
    code, stdout, _ = run_cli("forced", "torsion_gyrocompass", "--harmonic", "1:1:0.01", "--harmonic",
                              "3:2:0.02:0.5", "--set", "h=0.01", "--json", "--out", str(out))
    assert code == 0 and out.stat().st_size > 0
    d = json.loads(stdout)
    assert list(d)[:3] == ["model", "params", "coordinates"] and d["coordinates"] == PAPER_Q
    assert d["params"]["h"] == 0.01
    h1, h2 = d["harmonics"]
    for key in ("s", "k", "amplitude", "phase", "frequency", "amplitudes", "phases",
                "nearest_natural_frequency", "nearest_mode", "resonance"):
        assert key in h1
    assert (h1["s"], h1["k"], h1["amplitude"], h1["phase"]) == (1, 1, 0.01, 0.0)
    assert (h2["s"], h2["k"], h2["amplitude"], h2["phase"]) == (3, 2, 0.02, 0.5)
    assert h2["frequency"] == pytest.approx(2 * h1["frequency"], rel=1e-15)
    assert len(h1["amplitudes"]) == len(h1["phases"]) == 10 and h1["resonance"] is False
    # h scales the moments h f1 on gamma1 only: gamma1's response to f1 is linear in h at fixed F
    code, stdout2, _ = run_cli("forced", "torsion_gyrocompass", "--harmonic", "1:1:0.01", "--set", "h=0.02", "--json")
    g1 = PAPER_Q.index("gamma1")
    assert json.loads(stdout2)["harmonics"][0]["amplitudes"][g1] != h1["amplitudes"][g1]


@pytest.mark.parametrize("args, name", [
    ((), "--harmonic"), (("--harmonic", "5:1:1"), "--harmonic"), (("--harmonic", "1:x:1"), "--harmonic"),
    (("--harmonic", "1:1:nan"), "--harmonic"), (("--harmonic", "1:1:1:inf"), "--harmonic"),
    (("--harmonic", "1:1:1", "--set", "cp=-1"), "cp"), (("--harmonic", "1:1:1", "--set", "h=0"), "h"),
])
def test_gyro_forced_bad_input_exits_2_in_one_line(tmp_path, args, name):
    out = tmp_path / "x.png"
    code, stdout, stderr = run_cli("forced", "torsion_gyrocompass", *args, "--out", str(out))
    assert code == 2 and stdout == "" and not out.exists()
    assert len(stderr.strip().splitlines()) == 1 and name in stderr and "Traceback" not in stderr


def test_gyro_unbalance_json_contract_and_errors(tmp_path):
    out = tmp_path / "bode.png"
    code, stdout, _ = run_cli("unbalance", "torsion_gyrocompass", "--force-x", "F1", "--force-y", "F3",
                              "--magnitude", "1e-6", "--phase", "0.2", "--spin", "H", "--spin-range", "0.1", "0.5",
                              "--points", "5", "--set", "cp=1", "--json", "--out", str(out))
    assert code == 0 and out.stat().st_size > 0
    d = json.loads(stdout)
    for key in ("model", "values", "spin_rate", "coordinates", "amplitudes", "phases"):
        assert key in d
    assert d["values"] == pytest.approx(np.linspace(0.1, 0.5, 5).tolist(), rel=1e-15)
    assert len(d["amplitudes"]) == 5 and len(d["amplitudes"][0]) == 10
    for args, name in [(("--force-x", "F9", "--force-y", "F3"), "--force-x"),
                       (("--force-x", "F1", "--force-y", "F1"), "--force-y"),
                       (("--force-x", "F1", "--force-y", "F3", "--spin", "Kp"), "--spin"),
                       (("--force-x", "F1", "--force-y", "F3", "--spin", "nope"), "--spin")]:
        spin = () if "--spin" in args else ("--spin", "H")
        code, stdout, stderr = run_cli("unbalance", "torsion_gyrocompass", *args, *spin, "--magnitude", "1e-6",
                                       "--spin-range", "0.1", "0.5", "--points", "3")
        assert code == 2 and stdout == "" and name in stderr and len(stderr.strip().splitlines()) == 1
    code, _, stderr = run_cli("unbalance", "torsion_gyrocompass", "--force-x", "F1", "--force-y", "F3",
                              "--magnitude", "1e-6", "--spin", "H", "--spin-range", "-1", "0.5")
    assert code == 2 and "--spin-range" in stderr
    code, _, stderr = run_cli("unbalance", "gimbal_gyroscope", "--force-x", "F1", "--force-y", "F3",
                              "--magnitude", "1e-6", "--spin", "H", "--spin-range", "0.1", "0.5")
    assert code == 2 and "no inputs" in stderr


# --------------------------------------------------------------------------- nonlinear check


@pytest.mark.parametrize("case, a", [("away", 50.0), ("near", 0.25)])
def test_nonlinear_periodic_response_agrees_to_second_order(case, a):
    """The periodic response of the full 11-coordinate equations to one harmonic against the
    linear one, away from resonances (f1, k = 1 at the example) and near one (f3, k = 1,
    omega_c 1 % below omega_p), at half the smallest amplitude of the bench's ladder. The
    error is second order in a (the neglected terms are quadratic in the amplitudes and act
    at the forcing frequency through cubic products: err = c a^2, the order measured by
    halving a in bench/forced_nonlinear.py); here it is pinned to the committed run's c
    (LINEAR_LIMIT, equal to bench/results/forced_linear_limit.json) to 2 %: c changes along
    the ladder by its next order only (0.08 % between 100 and 400 N away from resonance),
    and the shooting's tolerances here (rtol 1e-10, periodic to 1e-7 of the state's scale,
    ten times the bench's, for fewer Newton steps) leave the error accurate to about 1e-3 of
    itself (the bench's 1e-8 gives 1e-4, against runs at 1e-12)."""
    from gyro.systems.torsion_gyrocompass import LINEAR_LIMIT, cases, linear_error, linear_limit, nonlinear_response

    assert LINEAR_LIMIT[case] == {k: linear_limit()["cases"][case][k] for k in ("c", "order", "a_1percent")}
    units = [MODEL.meta["coordinate_units"][c] for c in MODEL.meta["reduced"]]
    values, (s, k, phi) = cases(MODEL)[case]
    Xn, Xl, info = nonlinear_response(MODEL, values, (s, k, a, phi), rtol=1e-10, periodic_tol=1e-7)
    err = linear_error(Xn, Xl, units)
    assert err == pytest.approx(LINEAR_LIMIT[case]["c"] * a**2, rel=0.02)


@pytest.mark.parametrize("case", ["away", "near"])
def test_the_measured_one_percent_limit_is_bracketed(case):
    """The linear limit is measured, not extrapolated: the bench's ladder crosses 1 % between
    two measured amplitudes (bench/results/forced_linear_limit.json), and here the error is
    below 1 % at 0.8 a_1% and above it at 1.25 a_1% (the full equations' periodic response,
    Newton with the exact monodromy, the larger from the smaller's motion). Near the radial
    resonance the error grows slowly there (0.98 % at 32 N, 1.05 % at 64 N: the torsion
    angle lambda, 1.1 % of the largest angle's linear amplitude, is lost to the nonlinear
    terms), so the two points decide by about 4 % of the error, against the shooting's 1e-3."""
    from gyro.systems.torsion_gyrocompass import LINEAR_LIMIT, cases, linear_error, linear_limit, nonlinear_response

    bench = linear_limit()["cases"][case]
    assert bench["a_1percent_is"] == "interpolated between measured amplitudes"
    lo, hi = bench["a_1percent_between"]
    assert lo < LINEAR_LIMIT[case]["a_1percent"] < hi
    units = [MODEL.meta["coordinate_units"][c] for c in MODEL.meta["reduced"]]
    values, (s, k, phi) = cases(MODEL)[case]
    a1 = LINEAR_LIMIT[case]["a_1percent"]
    Xn, Xl, info = nonlinear_response(MODEL, values, (s, k, 0.8 * a1, phi), rtol=1e-10, periodic_tol=1e-7)
    below = linear_error(Xn, Xl, units)
    Xn, Xl, info = nonlinear_response(MODEL, values, (s, k, 1.25 * a1, phi), rtol=1e-10, periodic_tol=1e-7,
                                      start=info["continuation"])
    above = linear_error(Xn, Xl, units)
    assert below < 0.01 < above, (below, above)


def test_the_spin_torque_left_out_is_measured():
    """The imperfection's derivative in gamma3 is a torque on the spin that the check leaves
    to a drive. On a periodic motion it averages to zero: omega_c x f_s' = d(x f_s)/dt -
    x' f_s, and over a period x f_s returns while the work of the forces vanishes (no
    dissipation: the energy returns), so the drive supplies no mean power and the spin does
    not drift. On the computed motion, periodic to 1e-7 of its scale, the energy and x f_s
    return to about that part, so the mean's integral over a period is held below 1e-7 of
    the momentum's swing (measured 3e-13: the last Newton step leaves the residual at 3e-13). The
    torque is the emitted forcing's gamma3 row: x1 f1' + x2 f2' + x3 f3' + h gamma1 f1' -
    h gamma2 f3', dU/dgamma3 of (1.10), by hand here for f1 alone."""
    import casadi as ca

    from gyro.systems.torsion_gyrocompass import cases, nonlinear_response, spin_torque

    values, (s, k, phi) = cases(MODEL)["away"]
    a = 400.0
    _, _, info = nonlinear_response(MODEL, values, (s, k, a, phi), rtol=1e-10, periodic_tol=1e-7)
    out = spin_torque(MODEL, values, (s, k, a, phi), info)
    H = MODEL.defaults["H"]
    assert abs(out["torque_mean"]) * info["period"] < 1e-7 * out["momentum_swing"] * H
    assert 0 < out["momentum_swing"] < 1e-3 and out["effect_estimate"] == pytest.approx(
        out["momentum_swing"] * out["sensitivity_to_H"])
    # the torque at one state of the motion, by hand from (1.10)
    coords = MODEL.meta["coordinates"]
    t = 0.3 * info["period"]
    Y = info["motion"](np.array([t]))[:, 0]
    q, qd = Y[:11], Y[11:]
    g = dict(zip(coords, q))
    w = info["frequency"]
    f1d = a * k * np.cos(w * t + phi)
    P = MODEL.vector(values)
    F = np.array([a * np.sin(w * t + phi), 0, 0])
    full = np.asarray(MODEL.casadi.forcing(ca.DM(P), q, qd, F, np.array([f1d, 0, 0]))).ravel()
    none = np.asarray(MODEL.casadi.forcing(ca.DM(P), q, qd, F, np.zeros(3))).ravel()
    k3 = coords.index("gamma3")
    by_hand = (g["x1"] + MODEL.defaults["h"] * g["gamma1"]) * f1d
    assert full[k3] - none[k3] == pytest.approx(by_hand, rel=1e-12)
    # the momentum's swing by another route: the torque by hand along the motion at 2048
    # times, integrated by the trapezoidal rule, its periodic part (review: restated before)
    ts = np.linspace(0.0, info["period"], 2049)
    Ys = info["motion"](ts)
    gs = dict(zip(coords, Ys[:11]))
    tau = (gs["x1"] + MODEL.defaults["h"] * gs["gamma1"]) * a * k * np.cos(w * ts + phi)
    dH = np.concatenate([[0.0], np.cumsum((tau[1:] + tau[:-1]) / 2 * np.diff(ts))])
    dH -= np.trapezoid(dH, ts) / info["period"]
    assert np.max(np.abs(dH)) / H == pytest.approx(out["momentum_swing"], rel=1e-3)


def test_harmonic_balance_is_the_shooting_and_its_first_step_estimates_the_linear_error():
    """Two independent methods for the periodic response of the full equations, the shooting
    (integration over a period, Newton on the monodromy) and harmonic balance (Fourier
    series, residual at 32 times of the period, Newton on the coefficients), give the same
    response: near the radial resonance at 8 N (error 0.41 %), with the shooting at rtol
    1e-11 and periodic to 1e-9, they agree to 1e-9 of the response (on the bench's ladders,
    shooting at rtol 1e-10 and periodic to 1e-8, to 1.1e-9 and 4.4e-9). Harmonic balance's
    first Newton step from the linear response is the linear response's error to 1e-3 of
    itself (measured at most 3.6e-4 away, 4.7e-5 near, up to the 1 % limits): an estimate of
    the linear level's error without the later steps."""
    from gyro.systems.torsion_gyrocompass import cases, harmonic_balance, linear_error, nonlinear_response

    units = [MODEL.meta["coordinate_units"][c] for c in MODEL.meta["reduced"]]
    values, (s, k, phi) = cases(MODEL)["near"]
    Xs, Xl, _ = nonlinear_response(MODEL, values, (s, k, 8.0, phi), rtol=1e-11, periodic_tol=1e-9)
    Xh, _, info = harmonic_balance(MODEL, values, (s, k, 8.0, phi))
    assert linear_error(Xh, Xs, units) < 1e-9  # per unit group, as the error itself
    err = linear_error(Xh, Xl, units)
    assert 3e-3 < err < 6e-3  # a nonlinear effect well above both methods' accuracy
    assert info["first_correction"] == pytest.approx(err, rel=1e-3)
    assert info["residual"] < 1e-10 and info["newton_steps"] <= 3  # Newton with its exact Jacobian


# --------------------------------------------------------------------------- the forced question


def test_the_forced_question_takes_the_linear_level_while_its_estimate_allows():
    """`gyro scene ... forced`: the linear level answers while twice harmonic balance's first
    step stays within the tolerance, the nonlinear level (harmonic balance) above; its
    actual error against the nonlinear level is within the bound it gave, per coordinate,
    away from and near the radial resonance, up to and past the 1 % limits."""
    from gyro.systems.torsion_gyrocompass import cases
    from gyro.analyses.scene import level_error, select

    for case, amps in (("away", (100.0, 2400.0)), ("near", (4.0, 32.0))):
        values, (s, k, phi) = cases(MODEL)[case]
        P = MODEL.vector(values)
        for a in amps:
            opts = {"harmonic": (s, k, a, phi)}
            err, bound = level_error(MODEL, "forced", "linear", "nonlinear", P, opts)
            assert np.all(err <= bound), (case, a, err, bound)
            assert np.nanmax(err) > 0.2 * np.nanmax(bound)  # and not loose: the bound is twice the step
    values, (s, k, phi) = cases(MODEL)["away"]
    P = MODEL.vector(values)
    small = select(MODEL, "forced", P, 1e-3, {"harmonic": (s, k, 100.0, phi)})
    assert small.level[0] == "linear"
    large = select(MODEL, "forced", P, 1e-3, {"harmonic": (s, k, 2400.0, phi)})
    assert large.level[0] == "nonlinear" and [t.level for t in large.trials] == ["linear", "nonlinear"]
    tight = select(MODEL, "forced", P, 1e-9, {"harmonic": (s, k, 100.0, phi)})
    assert tight.level[0] == "" and tight.best(0)[1] == "nonlinear"


def test_the_forced_question_at_the_command_line():
    code, out, err = run_cli("scene", "torsion_gyrocompass", "forced", "--harmonic", "1:1:100", "--tol", "1e-3", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["level"] == "linear" and d["question"] == "forced"
    assert d["coordinates"] == ["x1", "x3", "gamma", "mu", "x2", "gamma1", "gamma2", "alpha", "beta", "lam"]
    assert len(d["amplitudes"]) == len(d["phases"]) == len(d["error_bound"]) == 10
    assert max(d["error_bound"]) <= 1e-3 and d["frequency"] > 0
    # the linear level's amplitudes are gyro forced's
    code, out2, _ = run_cli("forced", "torsion_gyrocompass", "--harmonic", "1:1:100", "--json")
    assert np.allclose(json.loads(out2)["harmonics"][0]["amplitudes"], d["amplitudes"], rtol=1e-12, atol=0)
    for args, name in [((), "--harmonic"), (("--harmonic", "4:1:1"), "--harmonic")]:
        code, out, err = run_cli("scene", "torsion_gyrocompass", "forced", "--tol", "1e-3", *args)
        assert code == 2 and out == "" and name in err and len(err.strip().splitlines()) == 1
    code, out, err = run_cli("scene", "torsion_gyrocompass", "frequencies", "--tol", "1e-3", "--harmonic", "1:1:1")
    assert code == 2 and "--harmonic" in err
    code, out, err = run_cli("scene", "torsion_gyrocompass", "forced", "--harmonic", "1:1:100", "--tol", "1e-9")
    assert code == 1 and "best bound" in err


def test_the_linear_levels_bound_holds_on_held_out_sets_of_the_spread():
    """bench/forced_levels.py maps `linear` against `nonlinear` over spin 0.3x-3x and
    amplitude 10-3000 N (143 points: bound/error 1.97 to 2.04 wherever both answer, at
    least 1.97 per coordinate, errors up to 18 %); here on held-out random points of the
    same spread the bound holds per coordinate too (one near the resonance at 0.45x, 385 N,
    error 9 %, is where a small coordinate's own step fell short: the bound is its unit
    group's largest step), and the committed map says what the bench measured."""
    from gyro.analyses.scene import level_error

    d = json.loads((Path(__file__).resolve().parents[2] / "bench" / "results" / "forced_levels.json").read_text())
    assert d["min_bound_over_error_per_coordinate"] >= 1.0 and d["points"] == 143
    rng = np.random.default_rng(2026)
    checked = 0
    for _ in range(6):
        h, a = np.exp(rng.uniform(np.log(0.3), np.log(3.0))), np.exp(rng.uniform(np.log(10.0), np.log(3000.0)))
        P = MODEL.vector({"H": MODEL.defaults["H"] * h})
        err, bound = level_error(MODEL, "forced", "linear", "nonlinear", P, {"harmonic": (1, 1, a, 0.0)})
        if np.all(np.isfinite(err)):
            assert np.all(err <= bound), (h, a)
            checked += 1
    assert checked >= 4
