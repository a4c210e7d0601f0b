"""The harmonic response of any model with inputs (gyro.analyses.harmonic): J(i w) X = B u
against independent solves and a textbook closed form, resonances as resonances, through
the compiled path and the NumPy fallback; the unbalance response of any model."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import cbackend, load
from gyro.analyses.harmonic import RESONANCE_RTOL, harmonic_response, unbalance_response
from gyro.equilibrium import equilibria, operators
from gyro.errors import ParameterError
from gyro.ladder import spectrum

MODEL = load("torsion_gyrocompass")
EPS = np.finfo(float).eps


def _independent(model, P, w, u):
    """X from the generated NumPy operator and input matrix, one set at a time, by a plain
    complex solve: another code path than the batch (C J(i w), batched LAPACK)."""
    qe, _ = equilibria(model, P)
    out = []
    for k in range(P.shape[0]):
        M, D, K = (np.asarray(a) for a in model.numpy.operator(P[k], qe[k]))
        B = np.asarray(model.numpy.input_matrix(P[k], qe[k])).reshape(M.shape[0], -1)
        Z = K - w[k]**2 * M + 1j * w[k] * D
        out.append((np.linalg.solve(Z, B @ u[k]), np.linalg.cond(Z)))
    return out


@pytest.mark.parametrize("compiled", [True, False])
def test_torsion_response_against_an_independent_complex_solve(compiled):
    """Random frequencies between and beside the natural frequencies, damped and undamped
    sets, random complex inputs. Both computations solve the same 10x10 system in double
    precision; each errs by at most ~cond(Z) eps relative to |X| (backward-stable LU), so
    they agree to 10 cond eps (cond asserted below 1e6 so that this is a real test: a wrong
    term in J or B changes X by far more)."""
    rng = np.random.default_rng(7)
    sets = [{}, {"cp": 3.0, "cgamma": 1e-3, "c0": 1.0}, {"H": 0.2, "phi": 20.0, "h": 0.02}]
    P = MODEL.vectors(sets)
    w = rng.uniform(30, 4000, len(sets))
    u = rng.normal(size=(len(sets), 3)) + 1j * rng.normal(size=(len(sets), 3))
    if compiled:
        r = harmonic_response(MODEL, P, w, u)
    else:
        with cbackend.disabled():
            r = harmonic_response(MODEL, P, w, u)
    assert not r.resonance.any()
    for k, (X, cond) in enumerate(_independent(MODEL, P, w, u)):
        assert cond < 1e6
        assert np.max(np.abs(r.X[k] - X)) <= 10 * cond * EPS * np.max(np.abs(X)), k


def test_undamped_resonance_is_a_resonance_and_damping_bounds_it():
    """Driven at a natural frequency (the default method's, relative error ~1e-15), the
    undamped operator is singular to working precision: inf and flagged, not a huge finite
    number. With radial bearing damping the same drive gives a finite amplitude, which
    grows as 1/c (the damped peak of a lightly damped mode is inversely proportional to its
    damping: halving c doubles it, to the order of c itself, here 1e-4 relative)."""
    P = MODEL.vector({})
    wn = spectrum(MODEL, P).frequencies[0]
    j = int(np.argmin(np.abs(wn - 780.0)))  # omega5 = omega_p (3.7): the radial bearing mode
    u = np.array([1.0, 0.0, 1.0])
    r = harmonic_response(MODEL, P, wn[j], u)
    assert r.resonance[0] and np.all(np.isinf(r.amplitudes[0]))
    d = r.to_dict()
    assert d["amplitudes"][0] == [None] * 10 and d["resonance"] == [True]
    # a little off the resonance: finite again, and not flagged
    off = harmonic_response(MODEL, P, wn[j] * (1 + 1e-6), u)
    assert not off.resonance[0] and np.all(np.isfinite(off.amplitudes[0]))
    amps = []
    for c in (0.02, 0.01):
        Pc = MODEL.vector({"cp": c})
        wc = spectrum(MODEL, Pc).frequencies[0][j]
        rc = harmonic_response(MODEL, Pc, wc, u)
        assert not rc.resonance[0]
        amps.append(np.max(rc.amplitudes[0]))
    assert amps[1] / amps[0] == pytest.approx(2.0, rel=1e-3)


def test_resonance_threshold_is_working_precision():
    """The flag is about the solver's precision, not a nearby mode: at a relative distance of
    1e3 RESONANCE_RTOL the set is answered (finite), at the natural frequency flagged."""
    P = MODEL.vector({})
    wn = spectrum(MODEL, P).frequencies[0][4]
    r = harmonic_response(MODEL, np.tile(P, (2, 1)), [wn, wn * (1 + 1e3 * RESONANCE_RTOL)], [1.0, 0, 0])
    assert r.resonance.tolist() == [True, False]
    assert np.all(np.isfinite(r.X[1]))


def test_superposition_time_series_and_save_load(tmp_path):
    """x(t) = Re(X e^{iwt}) satisfies M x'' + D x' + K x = B Re(u e^{iwt}) at sample times
    (residual at rounding of the largest term), and the result round-trips through save/load."""
    from gyro.results import HarmonicResponse

    P = MODEL.vector({"cp": 2.0})
    w, u = 321.0, np.array([0.3, -0.2j, 0.1])
    r = harmonic_response(MODEL, P, w, u)
    qe, _ = equilibria(MODEL, P[None])
    M, D, K = (a[0] for a in operators(MODEL, P[None], qe))
    B = np.asarray(MODEL.numpy.input_matrix(P, qe[0])).reshape(10, 3)
    t = np.linspace(0, 0.05, 7)
    x = r.time_series(t)
    xd = (1j * w * np.exp(1j * w * t)[:, None] * r.X[0]).real
    xdd = (-(w**2) * np.exp(1j * w * t)[:, None] * r.X[0]).real
    rhs = (np.exp(1j * w * t)[:, None] * (B @ u)[None]).real
    lhs = xdd @ M.T + xd @ D.T + x @ K.T
    scale = np.max(np.abs(xdd @ np.abs(M).T) + np.abs(x @ np.abs(K).T) + np.abs(xd @ np.abs(D).T))
    assert np.max(np.abs(lhs - rhs)) <= 1e-10 * scale
    r.save(tmp_path / "r.npz")
    back = HarmonicResponse.load(tmp_path / "r.npz")
    assert np.array_equal(back.X, r.X) and back.coordinates == r.coordinates and back.model == r.model


def test_bad_inputs_are_refused_naming_them():
    P = MODEL.vector({})
    with pytest.raises(ParameterError, match="u: .* 3 inputs"):
        harmonic_response(MODEL, P, 10.0, [1.0, 2.0])
    with pytest.raises(ParameterError, match="omega"):
        harmonic_response(MODEL, P, -1.0, [1.0, 0, 0])
    with pytest.raises(ParameterError, match="omega"):
        harmonic_response(MODEL, P, np.nan, [1.0, 0, 0])
    with pytest.raises(ParameterError, match="no inputs"):
        harmonic_response(load("gimbal_gyroscope"), load("gimbal_gyroscope").vector({}), 1.0, [1.0])
    with pytest.raises(ParameterError, match="--force-x 'Fz'"):
        unbalance_response(MODEL, {}, "Fz", "F3", 1e-6, 0.0, "H", 0.1, 0.5, 5)


# --------------------------------------------------------------------------- textbook


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """The chain as tests/generated/test_textbook.py builds it (shared with it within one session)."""
    from test_textbook import _BUILT, emit_in_process  # the module pytest collects (tests/ on sys.path)

    if "driven_chain" not in _BUILT:
        _BUILT["driven_chain"] = emit_in_process("driven_chain", tmp_path_factory.mktemp("chain"))
    return _BUILT["driven_chain"]


def test_driven_chain_against_its_closed_form_and_unbalance(chain):
    """The driven chain of tests/generated/test_textbook.py (three masses, springs, dampers c, the force
    F on the third): X = (K - w^2 M + i w c I)^-1 e3 F0 with the hand-typed matrices, over a
    batch of frequencies through the resonances (cond < 1e4 with c = 0.5, so the two solves
    agree to 1e4 eps ~ 2e-12 of |X|; 1e-10 asserted). Undamped, at a natural frequency, the
    set is a resonance. The unbalance response on a 1-input model is refused (it needs two
    inputs); the same solve with u = m e W^2 is the k = 1 case."""
    model = chain.runtime
    v = {p.name: p.default for p in chain.model.parameters}
    v["c"] = 0.5
    m1, m2, m3, k1, k2, k3, c = (v[s] for s in ("m1", "m2", "m3", "k1", "k2", "k3", "c"))
    M = np.diag([m1, m2, m3])
    K = np.array([[k1 + k2, -k2, 0], [-k2, k2 + k3, -k3], [0, -k3, k3]])
    wn = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    w = np.linspace(0.1, 1.5 * wn[-1], 40)
    P = np.tile(model.vector(v), (len(w), 1))
    F0 = 1.7 - 0.4j
    r = harmonic_response(model, P, w, [F0])
    for i, wi in enumerate(w):
        Z = K - wi**2 * M + 1j * wi * c * np.eye(3)
        want = np.linalg.solve(Z, np.array([0, 0, F0]))
        assert np.max(np.abs(r.X[i] - want)) <= 1e-10 * np.max(np.abs(want))
    v["c"] = 0.0
    P0 = np.tile(model.vector(v), (3, 1))
    r0 = harmonic_response(model, P0, wn, [1.0])
    assert r0.resonance.all()
    with pytest.raises(ParameterError, match="--force-y"):
        unbalance_response(model, v, "F", "F", 1e-3, 0.0, "k1", 1.0, 2.0, 3)


def test_unbalance_on_torsion_gyrocompass_is_the_rotating_force():
    """The unbalance on F1, F3 (the two radial bearing forces) over a range of H: each row is
    the harmonic response to u = m e W^2 e^{i PHI} (1, 0, -i) at the model's declared spin
    rate W = H/C of its set (the one the Campbell diagram and its harmonic lines use)."""
    from gyro.analyses.spin import spin_rates

    me, phi = 2e-6, 0.3
    r = unbalance_response(MODEL, {"cp": 1.0}, "F1", "F3", me, phi, "H", 0.1, 0.6, 4)
    P = r.params
    W = spin_rates(MODEL, "H", P)
    H, C = (P[:, MODEL.param_names.index(n)] for n in ("H", "C"))
    assert np.allclose(W, H / C, rtol=1e-15, atol=0) and np.array_equal(r.omega, W)
    u = me * W[:, None]**2 * np.exp(1j * phi) * np.array([1.0, 0.0, -1j])
    direct = harmonic_response(MODEL, P, W, u)
    assert np.allclose(r.X, direct.X, rtol=1e-14, atol=0)
    d = r.to_dict()
    assert list(d)[:6] == ["model", "spin", "values", "spin_rate", "coordinates", "units"]
    assert len(d["amplitudes"]) == 4 and len(d["phases"][0]) == 10
