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
    nominal.tornado(out, modes=[0, 7], title="two modes")
    assert out.stat().st_size > 5_000
    rc, out, err = run_cli("frequencies", MODEL, "--sensitivities", "--method", "formulas")
    assert rc == 2 and "--sensitivities" in err and len(err.strip().splitlines()) == 1


def test_the_emitted_jacobians_numpy_and_c(tg, nominal):
    """operator_sensitivity through NumPy and the compiled C, the two the runtime calls (its
    documented call order: params, qe; tests/test_generated.py takes every emitted function
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
