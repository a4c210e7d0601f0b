"""Exact sensitivities d omega_i / d p_j (gyro/analyses/sensitivity.py) against central
differences of the default method and of the 40-digit reference, and double roots reported
as such, never as a number."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gyro import ladder
from gyro.analyses.sensitivity import DOUBLE, _emitted_positions, double_roots, sensitivities
from gyro.methods import reference
from gyro.models import load
from tests.conftest import run_cli

MODEL = "torsion_gyrocompass"


@pytest.fixture(scope="module")
def tg():
    return load(MODEL)


@pytest.fixture(scope="module")
def nominal(tg):
    return sensitivities(tg, tg.vector())


def test_against_central_differences_of_the_default_method(tg, nominal):
    p0 = tg.vector()
    h = 1e-5
    npar = len(p0)
    P = np.repeat(p0[None], 2 * npar, axis=0)
    for j in range(npar):
        P[2 * j, j] *= 1 + h
        P[2 * j + 1, j] *= 1 - h
    spec = ladder.spectrum(tg, P)
    f = spec.frequencies
    w0 = nominal.spectrum.frequencies[0]
    # relative units (p / omega) d omega / d p: the difference quotient's rounding error is
    # the frequencies' own error over the step, est / h, and its truncation h^2 times a
    # relative third derivative of order one (1e-10)
    fd_rel = np.stack([(f[2 * j] - f[2 * j + 1]) / (2 * h) / w0 for j in range(npar)], axis=1)
    est = np.max(spec.error_estimate, axis=0)
    bound = 3 * est[:, None] / h + 1e-9
    err = np.abs(nominal.relative[0] - fd_rel)
    assert np.all(err <= bound), (np.max(err / bound), np.unravel_index(np.argmax(err / bound), err.shape))
    assert not nominal.double.any()


def _mp_roots(tg, p, q0, starts, idx):
    """The roots near `starts` (i omega) in the working precision: the equilibrium by the
    reference method's Newton, then Newton on det J (lambda -= 1 / tr(J^-1 J'))."""
    import mpmath

    q = reference._mp_equilibrium(tg.mpmath, p, q0, idx)
    M, D, K = tg.mpmath.operator(p, q)
    out = []
    for w in starts:
        lam = mpmath.mpc(0, w)
        for _ in range(3):  # from a double root accurate to 1e-14: 1e-28, then 1e-40
            J = M * lam**2 + D * lam + K
            try:
                Jinv = mpmath.inverse(J)
            except ZeroDivisionError:  # singular in the working precision: a root to it
                break
            dJ = M * (2 * lam) + D
            step = 1 / sum(Jinv[c, i] * dJ[i, c] for c in range(M.rows) for i in range(M.rows))
            lam -= step
            if abs(step) < mpmath.mpf(10) ** (-mpmath.mp.dps + 3) * abs(lam):
                break
        out.append(abs(lam.imag))
    return out


def test_against_the_40_digit_reference(tg, nominal):
    """Central differences of the roots in 40 digits (the reference method's equilibrium,
    each root polished by Newton on det J in that precision) in Kgamma, which moves the
    whole spectrum: with a step of 1e-15 relative the difference quotient's
    truncation is 1e-30 and its rounding 1e-40 / 1e-15, so it is the exact derivative to
    far below double precision. The double-precision derivative carries the rounding of
    the operator's entries (eps) through the null vectors and the equilibrium's
    conditioning: 1e-12 of each frequency's largest sensitivity (in relative units) bounds
    it with a margin of two hundred over the 5e-15 measured."""
    import mpmath

    p0 = tg.vector()
    idx = [tg.meta["reduced"].index(c) for c in tg.meta["equilibrium_coordinates"]]
    qe = nominal.spectrum.equilibrium[0]
    w0 = nominal.spectrum.frequencies[0]
    scale = np.max(np.abs(nominal.relative[0]), axis=1)
    for name in ("Kgamma",):
        j = tg.param_names.index(name)
        with mpmath.workdps(reference.DPS):
            h = mpmath.mpf(10) ** -15 * mpmath.mpf(p0[j])
            roots = []
            for sign in (1, -1):
                p = [mpmath.mpf(float(v)) for v in p0]
                p[j] += sign * h
                roots.append(_mp_roots(tg, p, qe, w0, idx))
            exact = np.array([float((a - b) / (2 * h)) for a, b in zip(*roots)])
        rel_exact = exact * p0[j] / w0
        err = np.abs(nominal.relative[0][:, j] - rel_exact)
        assert np.all(err <= 1e-12 * scale), (name, err / scale)


def _crossing(tg):
    """K0 where the axial bearing mode (through 780 upwards with K0) meets omega_p = 780:
    bisection on the sum of the two frequencies near 780 less 2 x 780. At the paper's Earth
    rate the two are weakly coupled, so this is an avoided crossing, not a crossing: their
    least distance is 9.8e-7 relative (K0 = 118721.24), just below DOUBLE, where the
    derivatives exist but hold only for moves below that distance; at u = 0 they cross."""
    p0 = tg.vector()
    j = tg.param_names.index("K0")
    lo, hi = 118600.0, 118900.0

    def g(k0):
        p = p0.copy()
        p[j] = k0
        f = ladder.spectrum(tg, p).frequencies[0]
        return f[6] + f[7] - 2 * 780.0000001

    for _ in range(45):
        mid = 0.5 * (lo + hi)
        if g(mid) < 0:
            lo = mid
        else:
            hi = mid
    p = p0.copy()
    p[j] = 0.5 * (lo + hi)
    return p


def test_a_double_root_has_no_number(tg):
    p = _crossing(tg)
    s = sensitivities(tg, p)
    f = s.spectrum.frequencies[0]
    assert abs(f[7] - f[6]) < DOUBLE * f[7]  # the bisection reached the crossing
    assert s.double[0, 6] and s.double[0, 7] and np.all(np.isnan(s.d[0, 6:8]))
    assert not s.double[0, :6].any() and np.all(np.isfinite(s.d[0, :6]))
    rc, out, err = run_cli("frequencies", MODEL, "--set", f"K0={float(p[tg.param_names.index('K0')])!r}",
                           "--sensitivities", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["sensitivities"][6] == [None] * len(p) and doc["relative_sensitivities"][7] == [None] * len(p)
    assert doc["double_root"][6] and not doc["double_root"][0]
    assert all(v is not None for v in doc["sensitivities"][0])


def test_double_roots_of_a_spectrum():
    from gyro.results import Spectrum

    f = np.array([[1.0, 1.0 + 1e-9, 3.0], [1.0, 1.1, 3.0]])
    spec = Spectrum("default", f, np.zeros_like(f), np.full(f.shape, 1e-14))
    assert double_roots(spec).tolist() == [[True, True, False], [False, False, False]]
    # two roots closer than ten times their error estimates cannot be told apart either
    spec = Spectrum("default", f, np.zeros_like(f), np.full(f.shape, 0.02))
    assert double_roots(spec)[1].tolist() == [True, True, False]
    # an exact zero root (u = 0: a free azimuth, estimate 1) is double with its mirror; its
    # error (1 x 0) leaves the other roots theirs
    z = np.array([[0.0, 5.07, 7.83]])
    spec = Spectrum("default", z, np.zeros_like(z), np.array([[1.0, 1e-14, 1e-14]]))
    assert double_roots(spec).tolist() == [[True, False, False]]


def test_cli_contract(tg, nominal):
    rc, out, err = run_cli("frequencies", MODEL, "--sensitivities", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    n, npar = len(doc["frequencies"]), len(tg.param_names)
    assert len(doc["sensitivities"]) == n and all(len(r) == npar for r in doc["sensitivities"])
    assert doc["sensitivity_parameters"] == tg.param_names  # gyro params order
    rel = np.array(doc["relative_sensitivities"])
    assert np.allclose(rel, nominal.relative[0], rtol=0, atol=0)
    # omega_p = sqrt(Kp / m): relative sensitivities +1/2 and -1/2. At the paper's set the
    # Earth rate couples it weakly (it lies 1.8e-10 above 780 relative), which moves them
    # by 4e-12 and 7e-12: bound 1e-10; at u = 0 it is decoupled, and they are 1/2 to rounding
    i8 = int(np.argmin(np.abs(np.array(doc["frequencies"]) - 780)))
    jKp, jm = tg.param_names.index("Kp"), tg.param_names.index("m")
    assert abs(rel[i8, jKp] - 0.5) < 1e-10 and abs(rel[i8, jm] + 0.5) < 1e-10
    p = tg.vector()
    p[tg.param_names.index("u")] = 0.0
    at0 = sensitivities(tg, p)
    i8 = int(np.argmin(np.abs(at0.spectrum.frequencies[0] - 780)))
    assert abs(at0.relative[0, i8, jKp] - 0.5) < 1e-14 and abs(at0.relative[0, i8, jm] + 0.5) < 1e-14
    rc, out, err = run_cli("frequencies", MODEL, "--sensitivities")
    assert rc == 0 and "relative sensitivities" in out


def test_tornado_chart(nominal, tmp_path):
    out = tmp_path / "tornado.png"
    nominal.plot(out, modes=[0, 7], title="two modes")
    assert out.stat().st_size > 5_000
    rc, out, err = run_cli("frequencies", MODEL, "--sensitivities", "--method", "formulas")
    assert rc == 2 and "--sensitivities" in err and len(err.strip().splitlines()) == 1


def test_the_emitted_jacobians_numpy_and_c(tg, nominal):
    """operator_sensitivity through NumPy and the compiled C, the two the runtime calls (its
    documented call order: params, qe; tests/generated/test_generated.py takes every emitted function
    through all four backends against the symbolic result) at the paper's set and a moved
    one: they agree to rounding (1e-12 of each row's largest entry),
    and the Jacobian of M, D, K is that of central differences of the emitted operator
    (step 1e-6 relative: truncation 1e-12, rounding eps / 1e-6 = 2e-10 of the row's scale;
    bound 1e-8), in relative units p_j dX/dp_j."""
    from gyro import cbackend

    names = [i["name"] for i in tg.meta["functions"]["operator_sensitivity"]["inputs"]]
    assert names == ["params", "qe"]
    npar = len(tg.param_names)
    for P in (tg.vector(), tg.vector() * 1.03):
        qe = nominal.spectrum.equilibrium[0]  # any (p, qe) will do: the functions are evaluated, not solved
        vals, dr = (np.asarray(a) for a in tg.numpy.operator_sensitivity(P, qe))
        c = cbackend.batch_function(tg.name, "operator_sensitivity")(P[None], qe[None])
        # dMDK is emitted as its structural nonzeros: its matrix is they at their positions
        dJ, cJ = np.zeros((2, 3 * tg.numpy.operator(P, qe)[0].shape[0] ** 2, dr.shape[1]))
        dJ[_emitted_positions(tg)], cJ[_emitted_positions(tg)] = vals, c[0][0]
        c[0] = cJ[None]
        for ref, others in ((dJ, (c[0][0],)), (dr, (c[1][0],))):
            scale = np.maximum(np.max(np.abs(ref), axis=1, keepdims=True), 1e-300)
            for o in others:
                assert np.all(np.abs(np.reshape(o, ref.shape) - ref) <= 1e-12 * scale)
        # rows' scale in relative units: the largest p_j dX/dp_j of the entry
        rows_scale = np.maximum(np.max(np.abs(dJ[:, :npar] * P), axis=1), 1e-300)
        for j in (tg.param_names.index("Kp"), tg.param_names.index("H"), tg.param_names.index("phi")):
            h = 1e-6 * P[j]
            Pp, Pm = P.copy(), P.copy()
            Pp[j] += h
            Pm[j] -= h
            fd = (np.concatenate([np.ravel(X) for X in tg.numpy.operator(Pp, qe)])
                  - np.concatenate([np.ravel(X) for X in tg.numpy.operator(Pm, qe)])) / (Pp[j] - Pm[j])
            assert np.all(np.abs(dJ[:, j] - fd) * abs(P[j]) <= 1e-8 * rows_scale), j
        assert dJ.shape[1] == npar + len(qe)


def test_a_method_without_error_bounds_gives_no_derivative(tg):
    """polyroots cannot bound some of its roots' errors: the distance of every root to those
    is unknown, so no root gets a derivative, and the table says why (not 'double')."""
    s = sensitivities(tg, tg.vector(), method="polyroots")
    assert not np.all(np.isfinite(s.spectrum.error_estimate)) and np.all(np.isnan(s.d))
    assert all("unbounded" in line for line in s.table(0).splitlines()[1:])


def _dense_algorithm(tg, P, spec):
    """The sensitivities as computed before the Jacobian was emitted sparse and the null
    vectors and the contraction compiled: the dense emitted Jacobian (`partials`), its live
    rows found by a scan, NumPy's null vectors (the NumPy path's `_null_vectors`), the total
    derivative dense over the parameters, then G @ total. For sets whose spectrum and
    equilibrium are finite."""
    from gyro.analyses import sensitivity as S
    from gyro.equilibrium import operators

    names = tg.meta["equilibrium_coordinates"]
    idx = [tg.meta["reduced"].index(c) for c in names]
    npar, n = len(tg.param_names), spec.frequencies.shape[1]
    qe = spec.equilibrium
    dJ, dr = S.partials(tg, P, qe, "emitted")
    M, D, K = operators(tg, P, qe)
    live = np.flatnonzero(np.any(dJ != 0, axis=(0, 2)))
    dJ = dJ[:, live]
    with np.errstate(all="ignore"):
        dq = S._equilibrium_derivative(dr[:, idx, npar:], dr[:, idx, :npar])
        total = dJ[:, :, :npar] + dJ[:, :, npar:] @ dq
    which, entry = np.divmod(live, n * n)
    row, col = np.divmod(entry, n)
    lam = spec.growth + 1j * spec.frequencies
    T = lambda X: np.swapaxes(X, -1, -2)  # noqa: E731
    hermitian = (np.all(M == T(M), axis=(1, 2)) & np.all(K == T(K), axis=(1, 2)) & np.all(D == -T(D), axis=(1, 2))
                 & np.all(spec.growth == 0, axis=1))
    x, y = S._null_vectors(M, D, K, lam, hermitian)
    yc = np.conj(y)
    den = 2 * lam * np.sum(yc * (x @ T(M)), axis=-1) + np.sum(yc * (x @ T(D)), axis=-1)
    weight = np.stack([lam**2, lam, np.ones_like(lam)], axis=-1)
    G = yc[:, :, row] * x[:, :, col] * weight[:, :, which]
    with np.errstate(all="ignore"):
        d = -(G.real @ total + 1j * (G.imag @ total)) / den[:, :, None]
    d = np.sign(lam.imag)[:, :, None] * d.imag
    d[double_roots(spec)] = np.nan
    return d


def _shifted_J(tg, P, spec):
    from gyro.equilibrium import operators

    M, D, K = operators(tg, P, spec.equilibrium)
    lam = spec.growth + 1j * spec.frequencies
    L = (lam * (1 + 1e-15))[:, :, None, None]
    return M, D, K, lam, M[:, None] * L**2 + D[:, None] * L + K[:, None]


def test_compiled_numpy_and_dense_paths_agree(tg):
    """The compiled null vectors and contraction over the Jacobian's nonzeros, the NumPy
    path (no compiler) and the dense algorithm they replaced give the same sensitivities, to
    1e-12 of each frequency's largest (measured: 1e-14), at perturbed paper sets, damped
    ones (J not Hermitian: the left null vectors from J^H on the same LU) and the set at
    u = 0 (a free azimuth: lambda = 0, J = K exactly singular, a double root with its
    mirror). Roots where NumPy's LU of J meets an exactly zero pivot take the SVD there and
    not in C (unless C's LU meets one too), so they are left out; the C kernel's own
    exactly zero pivots, which go to the NumPy path, are in."""
    from gyro import cbackend
    from gyro.analyses import sensitivity as S

    rng = np.random.default_rng(7)
    p0 = tg.vector()
    damped = p0.copy()
    for name, v in (("cp", 5.0), ("c0", 3.0), ("cgamma", 0.01)):
        damped[tg.param_names.index(name)] = v
    at0 = p0.copy()
    at0[tg.param_names.index("u")] = 0.0
    npar = len(p0)
    P = np.vstack([p0 * (1 + 0.01 * rng.standard_normal((80, npar))),
                   damped * (1 + 0.01 * rng.standard_normal((20, npar))), at0])
    spec = ladder.spectrum(tg, P)
    assert np.all(np.isfinite(spec.equilibrium)) and np.all(np.isfinite(spec.frequencies))
    c = sensitivities(tg, P, spec).d
    with cbackend.disabled():
        numpy_path = sensitivities(tg, P, spec).d
    dense = _dense_algorithm(tg, P, spec)
    M, D, K, lam, A = _shifted_J(tg, P, spec)
    lapack_singular = np.linalg.slogdet(A)[0] == 0
    _, _, c_singular = cbackend.sens_null_vectors(tg.name)(M, D, K, lam, np.zeros(len(P)), S._start(M.shape[-1]))
    double = double_roots(spec)
    assert c_singular[-1, 0] and double[-1, 0]  # the free azimuth at u = 0
    assert np.any(c_singular & ~lapack_singular & ~double)  # C's exact zero pivots, with a number
    assert lapack_singular.sum() <= 5
    keep = ~lapack_singular
    scale = np.max(np.abs(np.nan_to_num(c)), axis=2)
    for other in (numpy_path, dense):
        assert np.array_equal(np.isnan(c), np.isnan(other))
        err = np.max(np.abs(np.nan_to_num(c - other)), axis=2)
        assert np.all(err[keep & ~double] <= 1e-12 * scale[keep & ~double]), np.max(err[keep] / scale[keep])


def test_the_null_vectors_of_one_lu(tg):
    """The compiled right and left null vectors (one LU of J(lambda (1 + 1e-15)) per root)
    are NumPy's (two batched solves) up to a phase, to 1e-11 (measured 1e-13), at damped
    sets where J is not Hermitian, with residuals J x and y* J as small as NumPy's (within
    1e-9 of the largest entry of J: lambda is a root to 1e-14); where J has an exactly zero
    pivot (lambda = 0 at u = 0, J = K) the kernel says so, and the NumPy side gives a unit
    null vector of K."""
    from gyro import cbackend
    from gyro.analyses import sensitivity as S

    p = tg.vector()
    for name, v in (("cp", 5.0), ("c0", 3.0), ("cgamma", 0.01)):
        p[tg.param_names.index(name)] = v
    P = p * (1 + 0.01 * np.random.default_rng(3).standard_normal((30, len(p))))
    spec = ladder.spectrum(tg, P)
    M, D, K, lam, A = _shifted_J(tg, P, spec)
    herm = np.zeros(len(P), bool)
    kernel = cbackend.sens_null_vectors(tg.name)
    xc, yc = S._null_vectors(M, D, K, lam, herm, kernel)
    xn, yn = S._null_vectors(M, D, K, lam, herm)
    for c, n in ((xc, xn), (yc, yn)):
        assert np.allclose(np.linalg.norm(c, axis=-1), 1, rtol=0, atol=1e-14)
        phase = np.sum(np.conj(n) * c, axis=-1, keepdims=True)
        assert np.max(np.abs(c - phase / np.abs(phase) * n)) <= 1e-11
    big = np.max(np.abs(A), axis=(2, 3))
    for x, y in ((xc, yc), (xn, yn)):
        assert np.all(np.max(np.abs(np.einsum("smij,smj->smi", A, x)), axis=2) <= 1e-9 * big)
        assert np.all(np.max(np.abs(np.einsum("smi,smij->smj", np.conj(y), A)), axis=2) <= 1e-9 * big)
    q = tg.vector()
    q[tg.param_names.index("u")] = 0.0
    spec = ladder.spectrum(tg, q[None])
    M, D, K, lam, A = _shifted_J(tg, q[None], spec)
    assert lam[0, 0] == 0
    x, y, singular = kernel(M, D, K, lam, np.ones(1), S._start(M.shape[-1]))
    assert singular[0, 0] and not np.any(x[0, 0]) and not singular[0, 1:].any()
    x, y = S._null_vectors(M, D, K, lam, np.ones(1, bool), kernel)
    assert abs(np.linalg.norm(x[0, 0]) - 1) < 1e-14 and np.max(np.abs(K[0] @ x[0, 0])) <= 1e-12 * np.max(np.abs(K[0]))
    assert np.array_equal(y[0, 0], x[0, 0])


def test_the_emitted_and_casadi_routes_agree(tg):
    """The emitted Jacobian (its nonzeros at their positions from metadata.json) and CasADi's
    AD of the emitted operator are the same dense partials, and give the same sensitivities
    (measured 3e-16 of each frequency's largest), at a few perturbed sets."""
    from gyro.analyses.sensitivity import partials

    P = tg.vector() * (1 + 0.01 * np.random.default_rng(5).standard_normal((12, len(tg.param_names))))
    spec = ladder.spectrum(tg, P)
    (eJ, er), (cJ, cr) = (partials(tg, P, spec.equilibrium, route) for route in ("emitted", "casadi"))
    assert eJ.shape == cJ.shape and er.shape == cr.shape
    for e, c in ((eJ, cJ), (er, cr)):
        scale = np.maximum(np.max(np.abs(e), axis=2, keepdims=True), 1e-300)
        assert np.all(np.abs(e - c) <= 1e-13 * scale)
    e, c = (sensitivities(tg, P, spec, route=r).d for r in ("emitted", "casadi"))
    scale = np.nanmax(np.abs(e), axis=2, keepdims=True)
    assert np.all(np.abs(e - c) <= 1e-13 * scale)


def test_a_model_folder_with_a_dense_jacobian_gives_the_same_sensitivities(tg, monkeypatch):
    """A model folder emitted before outputs could be sparse has a dense dMDK and no
    'nonzeros' in its metadata (found in review: KeyError). Its every entry is a position;
    the contraction adds exact zeros besides the same nonzeros in the same order, so the
    sensitivities are the sparse folder's to the bit."""
    from gyro.analyses import sensitivity as sens

    rng = np.random.default_rng(5)
    P = np.tile(tg.vector(), (6, 1)) * (1 + 0.05 * rng.standard_normal((6, len(tg.param_names))))
    ref = sensitivities(tg, P).d
    rows, cols = _emitted_positions(tg)
    real = sens.function
    n = next(o["shape"][0] for o in tg.meta["functions"]["operator"]["outputs"] if o["name"] == "M")

    def dense(model, name):
        f = real(model, name)
        if name != "operator_sensitivity":
            return f

        def g(P, qe):
            vals, dr = f(P, qe)
            D = np.zeros((vals.shape[0], 3 * n * n, dr.shape[2]))
            D[:, rows, cols] = vals
            return D, dr
        return g

    monkeypatch.setattr(sens, "function", dense)
    monkeypatch.setattr(sens, "_emitted_positions", lambda model: None)
    got = sensitivities(tg, P).d
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    assert np.array_equal(got[~np.isnan(got)], ref[~np.isnan(ref)])
    # the positions are integers (an empty list of them would index as floats)
    assert rows.dtype == np.intp and cols.dtype == np.intp


def test_a_stationary_motions_model_is_refused_with_the_reason():
    """The gimbal gyroscope's operator depends on the momenta of its stationary motion, whose
    derivative in p the machinery does not derive: refused naming them (it raised an
    internal 'equilibrium_residual: 3 inputs, got 2' from the CasADi route)."""
    g = load("gimbal_gyroscope")
    with pytest.raises(ValueError, match="momenta"):
        sensitivities(g, g.vector())
