"""gyro.roots: the roots of a batch of real polynomials with proven inclusion radii, in C
(gyro/csrc/polyroots.c) and in NumPy, against roots known by construction and against
each other; the cases that are not proven (a double root, a zero end coefficient) fall back
to the companion's eigenvalues and say so."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import roots as R
from gyro.kernels import function
from gyro.models import load

TG = load("torsion_gyrocompass")


def _from_roots(zs: np.ndarray) -> np.ndarray:
    """Real coefficients, lowest first, of polynomials with the given roots (sets, d)."""
    return np.array([np.real(np.poly(z))[::-1] for z in zs])


def _known(n: int, seed: int) -> np.ndarray:
    """Roots z = -omega^2 spread over 14 orders of magnitude, as the blocks' are, with a
    conjugate pair in some sets (a growing mode)."""
    rng = np.random.default_rng(seed)
    z = -np.exp(rng.uniform(np.log(1e-7), np.log(1e7), (n, 6))) + 0j
    pair = rng.random(n) < 0.3
    z[pair, 4] = z[pair, 4] * (1 + 0.2j)
    z[pair, 5] = np.conj(z[pair, 4])
    return z


def _nearest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each root of a, its distance to the nearest of b, relative to |a|."""
    return np.abs(a[:, :, None] - b[:, None, :]).min(axis=2) / np.abs(a)


@pytest.mark.parametrize("model", [None, TG], ids=["numpy", "compiled"])
def test_the_proven_radius_holds_the_known_roots(model):
    """Polynomials built from known roots: each known root lies within the radius plus the
    coefficients' rounding sensitivity of a computed one (np.poly's coefficients are
    rounded, so the polynomial solved is not exactly the one built), on every set proven."""
    zt = _known(400, seed=3)
    c = _from_roots(zt)
    z, rad, sens, proven = R.roots(c, model)
    assert proven.mean() > 0.95
    dist = _nearest(z[proven], zt[proven])
    assert np.all(dist <= rad[proven] + 4 * sens[proven]), np.max(dist / (rad[proven] + sens[proven]))


def test_compiled_and_numpy_agree_within_their_radii_on_the_models_blocks():
    from bench.levels import joint

    P = joint(2000, seed=5)
    for block in function(TG, "paper_charpoly")(P):
        c = np.reshape(block, (len(P), -1))
        zc, rc, _, okc = R.roots(c, TG)
        zn, rn, _, okn = R.roots(c)
        both = okc & okn
        assert both.mean() > 0.99
        assert np.all(_nearest(zc[both], zn[both]) <= rc[both] + rn[both].max(axis=1, keepdims=True))


def test_the_companions_eigenvalues_are_no_proof_where_the_roots_spread():
    """The J'' block of the paper operator over the joint spread: LAPACK's eigenvalues of the
    companion miss the smallest root (omega1^2, 1e-6 of the next) by far more than the root's
    sensitivity to the coefficients, which the earlier estimate took as their error; the
    proven radius covers the Aberth roots."""
    from bench.levels import joint

    P = joint(2000, seed=3)
    c = np.reshape(function(TG, "paper_charpoly")(P)[1], (len(P), -1))
    z, rad, sens, ok = R.roots(c, TG)
    ze = R._companion(c)
    miss = _nearest(z[ok], ze[ok])
    assert np.max(miss / (sens[ok] + rad[ok])) > 1e3  # the eigenvalues beyond any estimate of theirs


@pytest.mark.parametrize("model", [None, TG], ids=["numpy", "compiled"])
def test_a_double_root_or_a_zero_end_is_not_proven_and_falls_back(model):
    c = np.array([
        _from_roots(np.array([[-1.0, -1.0, -4.0, -9.0]]))[0],  # a double root: disks meet
        [0.0, 2.0, -3.0, 1.0, 0.5],  # a zero root: c0 = 0
        _from_roots(np.array([[-1.0, -2.0, -3.0, -5.0]]))[0],
    ])
    z, rad, sens, proven = R.roots(c, model)
    assert list(proven) == [False, False, True]
    assert np.all(np.isinf(rad[:2])) and np.all(np.isfinite(z))
    assert np.sort(z[2].real) == pytest.approx([-5.0, -3.0, -2.0, -1.0], rel=1e-13)


def test_the_compiled_kernel_refuses_a_degree_above_its_cap():
    zt = -(2.0 ** np.arange(18.0))  # degree 18 > 16, well conditioned
    c = _from_roots(np.array([zt]))
    z, rad, sens, proven = R.roots(c, TG)
    assert np.isfinite(z).all() and proven[0]  # by the companion, its disks checked
    assert np.sort(z[0].real) == pytest.approx(np.sort(zt), rel=1e-10)
