"""The double operator's own rounding in every double-precision method's estimate
(gyro.qep.equilibrium_moves): found by an adversarial run of the gyrohorizoncompass over
parameters 0.05x..20x, where the default method's omega3 erred 86 times its estimate
against the 40-digit reference. Each set below beat its estimate before the change."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import ladder
from gyro.models import load

GHC = "gyrohorizoncompass"
SETS = {
    # epsilon0 = 89.99 deg: cos(epsilon0) = 1.3e-4 from epsilon rounded by 8.4e-17 puts M and
    # D entries off by 1e-11 and omega3 by 6.3e-13 (its estimate was 7.3e-15)
    "equilibrium": [0.00891457345593651, 0.07687904974819619, 0.020726864493078076, 0.012161555614522012,
                    39.25726238884601, 4811.424128502412, 8.158136360126162e-05, 2.1605031009658176e-06,
                    0.0009753751426403708, 1.0000000470883692],
    # a K entry formed by cancellation, off by 42 eps: omega2 erred 4.7e-15 against 3.6e-15
    "formation": [0.06570071614910791, 0.0032807731906396203, 0.013666883936714655, 0.00038124304886244845,
                  0.19519644623674662, 3412.590653547689, 0.006089010348727281, 0.00011506680453359225,
                  2.4059294406629664e-05, 1.0000000470883692],
}


@pytest.fixture(scope="module")
def ghc():
    return load(GHC)


@pytest.mark.parametrize("case", sorted(SETS))
@pytest.mark.parametrize("method", ["default", "companion", "polyroots"])
def test_every_double_method_holds_the_operators_rounding(ghc, case, method):
    P = np.array([SETS[case]])
    exact = ladder.spectrum(ghc, P, "reference").frequencies[0]
    s = ladder.spectrum(ghc, P, method)
    err = np.abs(s.frequencies[0] - exact) / exact
    assert np.all(err <= s.error_estimate[0]), (err, s.error_estimate[0])


def test_the_operators_rounding_is_small_where_nothing_amplifies_it(ghc):
    """At the Earth set the operator's change stays within its inputs' moves: each
    parameter moves by 4 eps and each equilibrium coordinate by 2 eps, so an entry that is a
    product of k inputs moves by at most about 4 k eps (21 eps measured, D's entries of five
    factors); 64 eps would take sixteen. No entry that is zero moves: the term is the
    operator's rounding, not a margin."""
    from gyro import qep
    from gyro.equilibrium import equilibria, operators

    P = ghc.vector()[None]
    qe, _ = equilibria(ghc, P)
    M, D, K = operators(ghc, P, qe)
    moves = qep.equilibrium_moves(ghc, P, qe, M, D, K)
    for d, X in zip(moves, (M, D, K)):
        nz = X != 0
        assert np.all(d[nz] <= 64 * qep.EPS * np.abs(X[nz])) and np.all(d[~nz] == 0)


def test_the_compiled_contraction_is_the_numpy_one(ghc):
    """gyro/csrc/qep.c's gyro_qep_moves_batch against gyro.qep.hermitian_moves in NumPy, on
    the torsion gyrocompass's and the gyrohorizoncompass's own roots and vectors (one
    Rayleigh step from the default method's frequencies): the same sums in another order,
    so equal to a few eps of the largest term (measured 1e-15; 1e-13 allows the
    denominator's cancellation where a root's 2 a w + beta is small)."""
    from gyro import qep
    from gyro.equilibrium import equilibria, operators

    for m in (ghc, load("torsion_gyrocompass")):
        P = np.tile(m.vector(), (40, 1)) * np.exp(np.random.default_rng(0).uniform(-0.1, 0.1, (40, len(m.param_names))))
        qe, _ = equilibria(m, P)
        M, D, K = operators(m, P, qe)
        w0 = ladder.spectrum(m, P, "default").frequencies
        z0 = np.ones(w0.shape + (M.shape[-1],), complex) / np.sqrt(M.shape[-1])
        w, z, _, ok = qep.rayleigh_step(M, D, K, w0, z0)
        assert ok.all()
        moves = qep.equilibrium_moves(m, P, qe, M, D, K)
        numpy_side = qep.hermitian_moves(moves, M, D, w, z)
        c_side = qep.hermitian_moves(moves, M, D, w, z, m)
        assert np.all(np.isfinite(numpy_side))
        assert np.allclose(c_side, numpy_side, rtol=1e-13, atol=0), np.max(np.abs(c_side / numpy_side - 1))


def test_the_certificates_count_carries_the_operators_rounding():
    """The count that proves a cheap level's answer (gyro/questions/inertia.c and its NumPy
    twin) takes the operator's own rounding as a perturbation of Q(w): near a frequency,
    where the count's separation from zero is small, a rounding large enough to move a
    frequency across the point leaves the count unproven (-1) instead of a count of the
    double operator's frequencies; with the rounding as probed, the counts are those
    without it away from the frequencies, in C and in NumPy alike."""
    from gyro import cbackend, qep
    from gyro.equilibrium import equilibria, operators
    from gyro.questions.frequencies import _inertia_kernel, counts_at

    _inertia_kernel()  # compiled here: C and NumPy below are two counts, not one twice
    tg = load("torsion_gyrocompass")
    P = np.tile(tg.vector(), (20, 1)) * np.exp(np.random.default_rng(4).uniform(-0.3, 0.3, (20, len(tg.param_names))))
    qe, _ = equilibria(tg, P)
    M, D, K = operators(tg, P, qe)
    moves = qep.equilibrium_moves(tg, P, qe, M, D, K)
    w = ladder.spectrum(tg, P, "default").frequencies
    far = np.concatenate([w * (1 - 1e-6), w * (1 + 1e-6)], axis=1)
    near = np.concatenate([w * (1 - 1e-9), w * (1 + 1e-9)], axis=1)
    big = tuple(1e6 * X for X in moves)  # a million times the probed rounding: ~1e-9 relative
    for disabled in (False, True):
        with cbackend.disabled() if disabled else _nothing():
            plain, probed = counts_at(M, D, K, far), counts_at(M, D, K, far, moves=moves)
            assert np.all(plain >= 0) and np.array_equal(plain, probed)  # the rounding moves no count
            # 1e-9 from every frequency: proven with the rounding as probed, not with a
            # rounding that could move a frequency across the point
            assert np.all(counts_at(M, D, K, near, moves=moves) >= 0)
            assert np.all(counts_at(M, D, K, near, moves=big) == -1)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False
