"""The starts of the default method's refinement (gyro.qep.block_starts): the compiled C
(gyro/csrc/qep_starts.c, eigenvalues of the Hermitian block forms without LAPACK and a
vector per root) against its NumPy path (LAPACK's eigvalsh and batched solves), and the
sets the structured rung must not take."""
from __future__ import annotations

from contextlib import nullcontext

import numpy as np
import pytest

from gyro import cbackend, ladder, load, qep
from gyro.equilibrium import equilibria, operators

MODEL = load("torsion_gyrocompass")


@pytest.fixture(scope="module")
def operators_spread():
    """Seeded sets over the bench's spread: spin 0.1x..10x, latitude 1..89 deg, the other
    parameters +-50 %."""
    rng = np.random.default_rng(20261201)
    p0 = MODEL.vector(MODEL.defaults)
    P = p0 * rng.uniform(0.5, 1.5, (200, len(p0)))
    ix = MODEL.param_names.index
    P[:, ix("H")] = p0[ix("H")] * np.geomspace(0.1, 10, len(P))
    P[:, ix("phi")] = rng.uniform(1, 89, len(P))
    qe, ok = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    return P, M, D, K, ok


def _numpy_path(M, D, K, ok):
    with cbackend.disabled():
        return qep.block_starts(MODEL, M, D, K, ok)


def test_compiled_starts_agree_with_lapack(operators_spread):
    """Both are backward stable: each mu = 1/w carries an absolute error of a few
    eps ||T||, ||T|| = max mu = 1/w_min of its block, so w agrees relatively to
    about m eps w / w_min (m = 12: the block's size; 64 eps allows the factor 5 of the
    reduction's constants). The vectors are each root's block null vector, unique up to a
    phase: |z_c* z_n| = 1 to the accuracy of inverse iteration at a shift that good
    (1e-8: the block's conditioning, gap / w, is at worst 1e-4 here)."""
    _, M, D, K, ok = operators_spread
    hc, wc, zc = qep.block_starts(MODEL, M, D, K, ok)
    hn, wn, zn = _numpy_path(M, D, K, ok)
    assert hc.all() and hn.all()
    wmin = np.concatenate([np.broadcast_to(np.min(wn[:, b], axis=1, keepdims=True), (len(wn), b.stop - b.start))
                           for b in _block_slices()], axis=1)
    assert np.all(np.abs(wc - wn) <= 64 * qep.EPS * wn * wn / wmin)
    overlap = np.abs(np.sum(zc.conj() * zn, axis=-1))
    np.testing.assert_allclose(overlap, 1.0, atol=1e-8)


def _block_slices():
    out, off = [], 0
    for b in qep.blocks(MODEL):
        out.append(slice(off, off + len(b)))
        off += len(b)
    return out


def test_starts_converge_in_one_step_mostly(operators_spread):
    """The block vectors carry only the weak coupling between the blocks: one step on the
    full operator meets 1e-10 for most roots (95.7 % on 4000 bench sets, against 41 % from
    one shared vector; here at least 80 % on both paths), and three steps meet it for all."""
    _, M, D, K, ok = operators_spread
    for h, w, z in (qep.block_starts(MODEL, M, D, K, ok), _numpy_path(M, D, K, ok)):
        _, _, e1, ok1 = qep.rayleigh(MODEL, M, D, K, w, z, 1, ladder.DEFAULT_TOL)
        _, _, e3, ok3 = qep.rayleigh(MODEL, M, D, K, w, z, 3, ladder.DEFAULT_TOL)
        assert np.mean(e1 <= ladder.DEFAULT_TOL) >= 0.8
        assert ok3.all() and np.all(e3 <= ladder.DEFAULT_TOL)


@pytest.mark.parametrize("path", ["compiled", "numpy"])
def test_damping_or_broken_symmetry_goes_to_the_general_rung(operators_spread, path):
    """A damping matrix (a symmetric part of D) moves the roots off the imaginary axis,
    where the Hermitian forms say nothing: such a set is not taken, on either path, even
    for a damping at the last bit; nor an M or K that is not symmetric."""
    _, M, D, K, ok = operators_spread
    M, D, K = M[:4].copy(), D[:4].copy(), K[:4].copy()
    D[0, 1, 1] = 1e-3 * abs(D[0, 0, 1]) + 1e-300  # damping on one coordinate
    D[1, 2, 3] = np.nextafter(D[1, 2, 3], np.inf)  # skew only to rounding
    M[2, 0, 4] = np.nextafter(M[2, 0, 4], np.inf)
    K[3, 5, 1] += 1e-3 * K[3, 1, 1]
    with cbackend.disabled() if path == "numpy" else nullcontext():
        herm, w, z = qep.block_starts(MODEL, M, D, K, np.ones(4, bool))
    assert not herm.any() and w.shape == (0, M.shape[-1])



def test_compiled_hermitian_forms_lane_by_lane(operators_spread):
    """The generated Hermitian block forms (eight sets at a time in lanes): the eigenvalues
    of each T are the NumPy path's 1/w; a set whose block K or M is not positive definite
    (a negative diagonal, a pivot below the margin, a NaN) is refused and leaves the other
    sets of its group of eight to the bit as each gets alone, also in a short last group."""
    _, M, D, K, _ = operators_spread
    M, D, K = M[:11].copy(), D[:11].copy(), K[:11].copy()
    kern = cbackend.qep_hermitian(MODEL.name)
    for b in qep.blocks(MODEL):
        T, ok = kern(M, D, K, b)
        assert ok.all()
        sub = np.ix_(b, b)
        w = qep.hermitian_block(M[:, b][:, :, b], D[:, b][:, :, b], K[:, b][:, :, b])
        mu = np.linalg.eigvalsh(T)[:, len(b):]
        np.testing.assert_allclose(1 / mu, w, rtol=1e-12)
        Mx, Kx = M.copy(), K.copy()
        i, j = b[0], b[1]
        Kx[2][i, i] = -Kx[2][i, i]  # a negative diagonal
        Kb = Kx[5][sub]  # a pivot below 1e3 eps: K's block made singular to rounding
        Kb[1, :] = Kb[0, :] * np.sqrt(Kb[1, 1] / Kb[0, 0])
        Kb[:, 1] = Kb[1, :]
        Kx[5][sub] = Kb
        Mx[9][i, j] = Mx[9][j, i] = np.nan
        T2, ok2 = kern(Mx, D, Kx, b)
        assert ok2.tolist() == [k not in (2, 5, 9) for k in range(11)]
        assert not T2[~ok2].any()
        for k in np.flatnonzero(ok2):
            Tk, okk = kern(Mx[k:k + 1], D[k:k + 1], Kx[k:k + 1], b)
            assert okk[0] and np.array_equal(Tk[0].view(float), T2[k].view(float))
            assert np.array_equal(T[k].view(float), T2[k].view(float))


def test_the_real_form_split_of_the_torsion_operator():
    """derive.emit._real_form: M and K couple coordinates of one group only, D (its skew
    part) coordinates of different groups only, on the derived operator; an odd cycle of
    couplings has no split."""
    import sympy as sp

    from derive.emit import _real_form
    from derive.model import Function

    _, M, D, K, _ = _spread_sample()
    group = np.array([0, 1, 0, 0, 1, 0, 1, 0, 1, 1])  # what the emitter found (the kernels' table)
    assert MODEL.meta["operator_real_form"] == group.tolist()
    same = group[:, None] == group[None, :]
    assert not np.any(M[:, ~same]) and not np.any(K[:, ~same]) and not np.any(D[:, same])
    a, b, c = sp.symbols("a b c")
    ring = sp.Matrix([[0, a, -b], [-a, 0, c], [b, -c, 0]])  # D couples 0-1, 1-2, 2-0: odd
    assert _real_form([Function("operator", [("p", [a, b, c])],
                                [("M", sp.eye(3)), ("D", ring), ("K", sp.eye(3))], "")]) is None
    chain = sp.Matrix([[c, a, 0], [-a, 0, b], [0, -b, 0]])  # a damping c on the diagonal: no matter
    assert _real_form([Function("operator", [("p", [a, b, c])],
                                [("M", sp.eye(3)), ("D", chain), ("K", sp.eye(3))], "")]) == [0, 1, 0]


def _spread_sample():
    rng = np.random.default_rng(7)
    p0 = MODEL.vector(MODEL.defaults)
    P = np.tile(p0, (11, 1))
    P[:, MODEL.param_names.index("H")] *= np.geomspace(0.1, 10, 11)
    P[:, MODEL.param_names.index("phi")] = rng.uniform(1, 89, 11)
    qe, ok = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    return P, M, D, K, ok


def test_a_set_off_the_real_form_is_refined_by_the_complex_steps():
    """A set whose K couples the two groups (symmetric, D still skew: the Hermitian forms
    hold, the real form does not) is taken by the complex steps, in the starts and in the
    refinement: its roots are those of its companion matrix, and its group's other sets keep
    their answers to the bit."""
    _, M, D, K, ok = _spread_sample()
    Kx = K.copy()
    Kx[4, 0, 1] = Kx[4, 1, 0] = 1e-3 * np.sqrt(K[4, 0, 0] * K[4, 1, 1])  # across the groups
    Kx[9, 5, 6] = Kx[9, 6, 5] = 1e-2 * np.sqrt(K[9, 5, 5] * K[9, 6, 6])
    outs = []
    for KK in (K, Kx):
        herm, w0, z0 = qep.block_starts(MODEL, M, D, KK, ok)
        assert herm.all()
        w, _, est, good = qep.rayleigh(MODEL, M, D, KK, w0, z0, 3, ladder.DEFAULT_TOL)
        assert good.all() and np.all(est <= ladder.DEFAULT_TOL)
        outs.append((w0, w, est))
    for k in (4, 9):
        lam = np.linalg.eigvals(qep.companion_matrix(M[k], D[k], Kx[k]))
        exact = np.sort(np.abs(lam.imag[lam.imag > 0]))
        np.testing.assert_allclose(np.sort(outs[1][1][k]), exact, rtol=1e-9)
        assert not np.allclose(np.sort(outs[0][1][k]), exact, rtol=1e-9, atol=0)  # the coupling counts
    rest = [k for k in range(11) if k not in (4, 9)]
    for a, b in zip(outs[0], outs[1]):
        assert np.array_equal(a[rest], b[rest])
    # one step is the complex step (a step of the real form on this set would solve another
    # system: its estimate would send it on, but its first step would not be this one)
    w0 = outs[1][0] * (1 + 1e-6)
    z0 = qep.start_vectors(*w0.shape, w0.shape[1])
    wc, _, ec, okc = cbackend.qep_refine(MODEL.name)(M, D, Kx, w0, z0, 1, 0.0)
    wn, _, en, okn = qep.rayleigh_step(M, D, Kx, w0, np.array(z0))
    assert okc.all() and okn.all()
    np.testing.assert_allclose(wc, wn, rtol=1e-12)
    np.testing.assert_allclose(ec, en, rtol=1e-3)


@pytest.mark.parametrize("path", ["compiled", "numpy"])
def test_sets_near_overflow_go_to_the_general_rung(operators_spread, path):
    """An entry of M, D or K at or above 1e150 in magnitude (gyro.equilibrium.tame), or a
    NaN, keeps a set off the structured rung on either path, symmetry kept; its company
    keeps its starts to the bit."""
    _, M, D, K, ok = operators_spread
    M, D, K = M[:10].copy(), D[:10].copy(), K[:10].copy()
    M[1, 0, 0] = 1e150
    K[3, 0, 2] = K[3, 2, 0] = -1e151
    D[5, 0, 1], D[5, 1, 0] = 1e150, -1e150
    K[7, 1, 1] = np.nan
    with cbackend.disabled() if path == "numpy" else nullcontext():
        herm, w, z = qep.block_starts(MODEL, M, D, K, np.ones(10, bool))
        assert herm.tolist() == [k not in (1, 3, 5, 7) for k in range(10)]
        keep = np.flatnonzero(herm)
        h2, w2, z2 = qep.block_starts(MODEL, M[keep], D[keep], K[keep], np.ones(keep.size, bool))
    assert h2.all() and np.array_equal(w, w2) and np.array_equal(z, z2)


def test_a_set_off_the_real_form_near_a_root_to_the_last_bit_is_still_taken():
    """A coupling across the real form's groups far below rounding (1e-300) turns a block's
    exact zero pivot at a root to the last bit (omega_p) into a tiny one: the complex solve
    then gives no finite vector at the first shift, and the next shifts are tried, as in
    lanes. A coupling that small changes nothing else: the starts take every set they take
    without it, with the same frequencies to the bit, and so do the NumPy starts."""
    from bench.speed import random_sets

    P = random_sets(2000, seed=11)
    qe, ok = equilibria(MODEL, P)
    M, D, K = operators(MODEL, P, qe)
    h0, w0, _ = qep.block_starts(MODEL, M, D, K, ok)
    K[:, 0, 1] = K[:, 1, 0] = 1e-300
    herm, w, _ = qep.block_starts(MODEL, M, D, K, ok)
    hn, _, _ = _numpy_path(M, D, K, ok)
    assert h0.all() and herm.all() and hn.all() and np.array_equal(w, w0)
