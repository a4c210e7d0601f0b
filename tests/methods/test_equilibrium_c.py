"""The equilibrium Newton iteration in generated C (templates/equilibrium.c.j2) against the
NumPy iteration it replaces (gyro.equilibrium._newton_numpy), for every model that has it.

The C answers a set only where it converges; what it hands back, the NumPy iteration
answers from the start. Both measure each step against the largest coordinate of its unit
(a coordinate at rounding noise about an exact zero, the gyrohorizoncompass's beta near
1e-20 rad beside an epsilon of 1 rad, has no relative precision for a test of its own: the
iterate circled in it until the test was changed, and the CSE of equilibrium_system moved
the noise so that 56 % of that model's sets were handed back). Against the NumPy iteration
over the same generated C functions the answers are the same to the bit, but for a
coordinate below 1e-12 of its set's largest, which agrees to eps of that largest. Against the
path without a compiler (the generated NumPy functions, which differ from the C in the last
bits: up to 89 eps measured in the gyrohorizoncompass's epsilon) to 10 TOL = 1e-13 of each
coordinate. On the torsion gyrocompass the sets agree to the bit with both."""
from __future__ import annotations

import numpy as np
import pytest

import gyro.equilibrium as E
from gyro import cbackend, load
from gyro.equilibrium import equilibria

EARTH = 7.292115e-5  # rad/s
EPS = np.finfo(float).eps
MODELS = ["torsion_gyrocompass", "gyrohorizoncompass", "gimbal_precession"]


@pytest.fixture(autouse=True)
def _compiled():
    try:
        cbackend.library("torsion_gyrocompass")
    except cbackend.CompilerUnavailable as exc:
        pytest.fail(f"the compiled path is what is tested here: {exc}")


def random_sets(name: str, n: int, seed: int = 7) -> np.ndarray:
    """As bench/speed.py draws them: the spin 0.1x..10x log-uniform, the latitude 1..89 deg
    (for the models that take the Earth's rate by components, the components at it)."""
    model = load(name)
    rng = np.random.default_rng(seed)
    base = dict(model.defaults)
    if name == "gimbal_precession":  # a pendulous casing: the defaults' offset l_x has no equilibrium
        base.update(l_x=0.0, l_z=-0.001)
    P = np.tile(model.vector(base), (n, 1))
    ix = model.param_names.index
    spin = np.exp(rng.uniform(np.log(0.1), np.log(10), n))
    lat = rng.uniform(1, 89, n)
    if name == "torsion_gyrocompass":
        P[:, ix("H")] *= spin
        P[:, ix("phi")] = lat
    elif name == "gyrohorizoncompass":
        P[:, ix("L")] *= spin
        P[:, ix("eta")] = EARTH * np.sin(np.radians(lat))
    else:
        P[:, ix("H")] *= spin
        P[:, ix("u_eta")] = EARTH * np.cos(np.radians(lat))
        P[:, ix("u_zeta")] = EARTH * np.sin(np.radians(lat))
    return P


def starts(model, P):
    names, _, _ = E._layout(model)
    if "equilibrium_approx" not in model.meta["functions"]:
        return np.zeros((len(P), len(names)))
    with np.errstate(all="ignore"):
        q = E.function(model, "equilibrium_approx")(P)[0].reshape(len(P), -1)
    q = np.where(np.isfinite(q), q, 0.0)
    return np.where(E._layout(model)[2] & (np.abs(q) > 2.0**26), E.wrap(q), q)  # as equilibria() starts


def kernel_run(model, P, max_iter=E.MAX_ITER):
    kern = cbackend.equilibrium_newton(model.name)
    return kern(P, starts(model, P), E.TOL, max_iter, E.MAX_ANGLE_STEP)


def numpy_iteration(model, P, **kw):
    """equilibria() with the C iteration unavailable: the NumPy iteration over the generated
    C functions (the code before the C iteration, and the path of every set handed back)."""
    def unavailable(name):
        raise cbackend.CompilerUnavailable("the C iteration left out")

    real = cbackend.equilibrium_newton
    cbackend.equilibrium_newton = unavailable
    try:
        return equilibria(model, P, **kw)
    finally:
        cbackend.equilibrium_newton = real


def no_compiler(model, P, **kw):
    with cbackend.disabled():
        return equilibria(model, P, **kw)


def assert_agree(a, b, rel=0.0):
    """The stated agreement (module doc): each coordinate within rel of itself (rel = 0: to
    the bit), one below 1e-12 of its set's largest within max(rel, eps) of that largest;
    NaN where NaN."""
    assert np.array_equal(np.isnan(a), np.isnan(b))
    a, b = np.nan_to_num(a), np.nan_to_num(b)
    largest = np.max(np.abs(b), axis=1, keepdims=True)
    noise = np.abs(b) < 1e-12 * largest
    bound = np.where(noise, max(rel, EPS) * largest, rel * np.abs(b))
    bad = np.abs(a - b) > bound
    rows = bad.any(axis=1)
    assert not rows.any(), f"{rows.sum()} sets apart, e.g. {a[rows][:2]!r} vs {b[rows][:2]!r}"


def test_every_model_with_equilibria_has_the_c_iteration():
    for name in MODELS:
        cbackend.equilibrium_newton(name)
    with pytest.raises(cbackend.CompilerUnavailable):  # its residual takes the momenta as well
        cbackend.equilibrium_newton("gimbal_gyroscope")


@pytest.mark.parametrize("name", MODELS)
def test_c_and_numpy_agree_on_random_sets(name):
    model, P = load(name), random_sets(name, 3000)
    _, status = kernel_run(model, P)
    answered = status == cbackend.EquilibriumNewton.CONVERGED
    # the C answers nearly all of them: the comparison is of the C (measured: all but 5 of the
    # gyrohorizoncompass's, beta alone near 1e-6 rad, which both iterations circle)
    assert answered.mean() > 0.99
    qc, okc = equilibria(model, P)
    qn, okn = numpy_iteration(model, P)
    assert okn.all() and np.array_equal(okc, okn)
    assert_agree(qc, qn)
    qf, okf = no_compiler(model, P)
    assert np.array_equal(okc, okf)
    assert_agree(qc, qf, rel=10 * E.TOL)
    if name == "torsion_gyrocompass":  # the bench's model: to the bit with both
        assert answered.all() and np.array_equal(qc, qn) and np.array_equal(qc, qf)


@pytest.mark.parametrize("name", MODELS)
def test_one_step_of_the_c_is_one_step_of_numpy(name):
    """From starts far off (every angle 0.7 rad away, so that the step is damped to
    MAX_ANGLE_STEP), one step of the C against one of the NumPy iteration: the same step,
    the same damping, to the forward error of a pivoted solve (8 n eps cond(K) of the step's
    largest component; the two eliminations round differently)."""
    model = load(name)
    P = random_sets(name, 300, seed=11)
    _, idx, is_angle = E._layout(model)
    q0 = starts(model, P) + np.where(is_angle, 0.7, 0.0)
    qc, status = cbackend.equilibrium_newton(name)(P, q0, E.TOL, 1, E.MAX_ANGLE_STEP)
    qn, conv = E._newton_numpy(model, P, q0.copy(), idx, is_angle, E.TOL, 1)
    # none converges in one step from so far: each is handed back, its iterate as it stands
    assert not conv.any() and np.all(status == cbackend.EquilibriumNewton.HANDED_BACK)
    step_c, step_n = qc - q0, qn - q0
    assert np.all(np.max(np.abs(step_c[:, is_angle]), axis=1) <= E.MAX_ANGLE_STEP * (1 + 4 * EPS))
    damped = np.isclose(np.max(np.abs(step_n[:, is_angle]), axis=1), E.MAX_ANGLE_STEP, rtol=1e-12, atol=0)
    assert damped.mean() > 0.5  # the damping acted on most
    K = E.function(model, "operator")(P, q0)[2][:, idx][:, :, idx]
    bound = 8 * len(idx) * EPS * np.linalg.cond(K) * np.max(np.abs(step_n), axis=1)
    assert np.all(np.abs(step_c - step_n) <= bound[:, None])


def singular_batch(model):
    """Six sets of the torsion gyrocompass: no Earth rate with g = 0; no Earth rate and no
    torsion stiffness; g = 0; latitude 90 deg; g = 0 at latitude 90 deg; the defaults."""
    ix = model.param_names.index
    P = np.tile(model.vector(model.defaults), (6, 1))
    P[0, [ix("g"), ix("u")]] = 0.0
    P[1, [ix("u"), ix("Kgamma")]] = 0.0
    P[2, ix("g")] = 0.0
    P[3, ix("phi")] = 90.0
    P[4, [ix("g"), ix("phi")]] = [0.0, 90.0]
    return P


def test_singular_k_is_handed_back_and_answered_as_numpy_answers():
    """No Earth rate with g = 0 (or with no torsion stiffness): K is singular at the start,
    the NumPy iteration takes least squares. g = 0 leaves K singular in exact arithmetic
    only: g = 0 alone, Newton comes to rest at a point of the free azimuth (K's condition
    about 1e16 there, the coordinates of the other group at rounding noise below 1e-28 of
    beta): the C answers it, as the NumPy iteration of that set does, alone or in this
    batch. Latitude 90 deg alone: K regular, the C answers. g = 0 at latitude 90 deg: (2.2)
    starts beta at 1.6e16 rad, an angle without a digit, from which the iteration circled
    for its 100 steps and stopped at beta = -2.364 rad, where the beta equation (-3.3e-5
    cos(beta) N m) misses by 2.35e-5 N m: that start is now taken within one turn, and the C
    converges to beta = -pi/2, an equilibrium."""
    model = load("torsion_gyrocompass")
    P = singular_batch(model)
    _, status = kernel_run(model, P)
    back = status == cbackend.EquilibriumNewton.HANDED_BACK
    assert back[[0, 1]].all() and not back[[2, 3, 4, 5]].any()
    idx = E._layout(model)[1]
    K = E.function(model, "operator")(P[:2], starts(model, P[:2]))[2][:, idx][:, :, idx]
    for k in K:  # singular to LAPACK too: the NumPy iteration's least-squares branch answers them
        with pytest.raises(np.linalg.LinAlgError):
            np.linalg.solve(k, np.ones(len(idx)))
    qc, okc = equilibria(model, P)
    qn, okn = numpy_iteration(model, P)
    assert np.array_equal(okc, okn) and okc[[2, 3, 4, 5]].all()
    # the handed-back sets are the NumPy iteration's answers to the bit; the regular ones the
    # C's, within the stated agreement of the NumPy iteration's
    assert np.array_equal(qc[back], qn[back], equal_nan=True)
    assert_agree(qc[[3, 4, 5]], qn[[3, 4, 5]], rel=10 * E.TOL)
    assert abs(qc[4, E._layout(model)[0].index("beta")] + np.pi / 2) <= 1e-12
    alone, ok2 = numpy_iteration(model, P[2:3])
    assert ok2[0] and okc[2]
    assert_agree(qc[2:3], alone)


def test_numpy_iteration_answers_each_set_as_alone_whatever_its_batch():
    """The NumPy iteration with a singular K in the batch: each set's answer is the one it
    gets alone, to the bit (a singular K's set takes least squares, every other its solve;
    before, every set of the step took least squares, and g = 0 came to another point of
    its free azimuth in the batch than alone)."""
    model = load("torsion_gyrocompass")
    P = singular_batch(model)
    q, ok = numpy_iteration(model, P)
    for k in range(len(P)):
        qk, okk = numpy_iteration(model, P[k:k + 1])
        assert okk[0] == ok[k] and np.array_equal(qk[0], q[k], equal_nan=True), k


def test_a_batch_mixing_regular_and_singular_sets():
    """One set with a singular K among regular ones: the regular ones are the C's answers of
    them alone, the singular one the NumPy iteration's of it alone."""
    model = load("torsion_gyrocompass")
    ix = model.param_names.index
    P = random_sets("torsion_gyrocompass", 50)
    P[17, [ix("g"), ix("u")]] = 0.0
    qc, okc = equilibria(model, P)
    alone_c, _ = equilibria(model, np.delete(P, 17, axis=0))
    assert np.array_equal(np.delete(qc, 17, axis=0), alone_c)
    q17, ok17 = numpy_iteration(model, P[17:18])
    assert np.array_equal(qc[17:18], q17, equal_nan=True) and okc[17] == ok17[0]
    qn, okn = numpy_iteration(model, P)
    assert np.array_equal(okc, okn)
    assert_agree(qc, qn, rel=10 * E.TOL)


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e200, -1e200])
def test_non_finite_and_huge_inputs_are_handed_back(name, bad):
    model = load(name)
    P = random_sets(name, 4)
    big = model.param_names.index("L" if name == "gyrohorizoncompass" else "H")
    P[1, big] = bad
    P[2, :] = bad
    _, status = kernel_run(model, P)
    assert np.all(status[[1, 2]] == cbackend.EquilibriumNewton.HANDED_BACK)
    assert np.all(status[[0, 3]] == cbackend.EquilibriumNewton.CONVERGED)
    qc, okc = equilibria(model, P)
    qn, okn = numpy_iteration(model, P)
    assert np.array_equal(okc, okn) and not okc[[1, 2]].any() and okc[[0, 3]].all()
    assert np.isnan(qc[[1, 2]]).all()
    assert_agree(qc, qn)


def test_a_set_without_an_equilibrium():
    """The gimbal's defaults: the casing's offset l_x turns the outer ring without end (no
    equilibrium). The C does not converge in max_iter, hands the set back, and the NumPy
    iteration finds none either; with a budget of no step or one, every set is handed back
    and accepted or not by its residual as the NumPy iteration does."""
    model = load("gimbal_precession")
    P = np.vstack([model.vector(model.defaults), random_sets("gimbal_precession", 3)])
    _, status = kernel_run(model, P)
    assert status[0] == cbackend.EquilibriumNewton.HANDED_BACK and np.all(status[1:] == 1)
    qc, okc = equilibria(model, P)
    assert not okc[0] and okc[1:].all() and np.isnan(qc[0]).all()
    qn, okn = numpy_iteration(model, P)
    assert np.array_equal(okc, okn)
    assert_agree(qc, qn)
    T = load("torsion_gyrocompass")
    P = random_sets("torsion_gyrocompass", 20)
    for max_iter in (0, 1):
        _, status = kernel_run(T, P, max_iter=max_iter)
        assert np.all(status == cbackend.EquilibriumNewton.HANDED_BACK)
        qc, okc = equilibria(T, P, max_iter=max_iter)
        qn, okn = numpy_iteration(T, P, max_iter=max_iter)
        assert np.array_equal(qc, qn, equal_nan=True) and np.array_equal(okc, okn)


def test_the_wrapper_checks_shapes():
    kern = cbackend.equilibrium_newton("torsion_gyrocompass")
    P = random_sets("torsion_gyrocompass", 3)
    with pytest.raises(ValueError):
        kern(P, np.zeros((3, 4)), E.TOL, 10, E.MAX_ANGLE_STEP)
    with pytest.raises(ValueError):
        kern(P[:, :-1], np.zeros((3, 5)), E.TOL, 10, E.MAX_ANGLE_STEP)


@pytest.mark.parametrize("name", MODELS)
def test_a_package_without_equilibrium_system_takes_the_residual_and_the_operator(name, monkeypatch):
    """A model generated before equilibrium_system existed: the NumPy iteration builds its
    step from the residual's rows and the operator's K (gyro.equilibrium._system), the same
    values through another CSE: K agrees with equilibrium_system's to rounding (each entry to
    1e-12 of its set's largest; r, a difference of far larger terms at the starts, has no
    scale of its own to compare by), and the equilibria to 10 TOL (a coordinate at rounding
    noise to eps of its set's largest), the same sets answered (the path without a compiler,
late acceptance included: a set that Newton circles may stop in another step)."""
    model = load(name)
    P = random_sets(name, 200, seed=5)
    idx = E._layout(model)[1]
    q0 = starts(model, P)
    K1 = E._system(model, idx)(P, q0)[1]
    q1, ok1 = no_compiler(model, P)
    monkeypatch.delitem(model.meta["functions"], "equilibrium_system")
    K0 = E._system(model, idx)(P, q0)[1]
    q0n, ok0 = no_compiler(model, P)
    assert np.all(np.abs(K1 - K0) <= 1e-12 * np.max(np.abs(K0), axis=(1, 2), keepdims=True))
    assert ok1.all() and np.array_equal(ok1, ok0)
    assert_agree(q1, q0n, rel=10 * E.TOL)
