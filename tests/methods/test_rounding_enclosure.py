"""The operator's rounding enclosed (gyro.rounding): the operator the runtime forms at its
computed equilibrium against the exact operator at the exact equilibrium, both from the
generated mpmath at 50 digits (the equilibrium by Newton on the emitted equilibrium_system
from the double one: five steps take its 1e-16 to below 1e-40), on random sets over
0.05x..20x of every built-in model with an operator and of model files of tests/models.

The reference's own error: a 50-digit evaluation of entries of size |X| errs by about
1e-50 |X| times the cancellation of its terms; 1e-35 of the matrix's largest entry leaves
15 orders for that and is 19 orders below any double rounding (u = 1.1e-16 of an entry),
so it cannot hide a beaten bound (bench.operator_rounding: the same over more sets, and the
cost)."""
from __future__ import annotations

import mpmath
import numpy as np
import pytest

from bench.operator_rounding import GHC_POLE, SLACK, distance, draw, exact
from gyro import qep, rounding
from gyro.equilibrium import equilibria, operators
from gyro.models import load
from tests.conftest import ROOT

MODELS = ROOT / "tests" / "models"


def _model(name):
    if name.endswith(".py"):
        import gyro

        return gyro.load(MODELS / name)
    return load(name)


# the gyrohorizoncompass's sets of test_operator_rounding (epsilon0 = 89.99 deg, and an
# entry formed by cancellation): the sets where the probes were once beaten
GHC_SETS = [GHC_POLE[0],
            [0.06570071614910791, 0.0032807731906396203, 0.013666883936714655, 0.00038124304886244845,
             0.19519644623674662, 3412.590653547689, 0.006089010348727281, 0.00011506680453359225,
             2.4059294406629664e-05, 1.0000000470883692]]
CASES = {"gyrohorizoncompass": 6, "torsion_gyrocompass": 4, "gimbal_precession": 6,
         "spherical_pendulum.py": 4, "nonminimal_pendulum.py": 4, "hoop_bead.py": 4,
         "gyropendulum.py": 3}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_enclosure_is_never_beaten_by_the_exact_operator(name):
    """|X - X_exact| <= the enclosure, entry by entry, and the equilibrium within its
    proven radius, on every set; every bound finite (a bound of +inf is never beaten and
    proves nothing: these sets are all proven)."""
    m = _model(name)
    P = draw(m, 12 * CASES[name], seed=11)  # the first sets with an equilibrium
    qe, ok = equilibria(m, P)
    P, qe = P[ok][:CASES[name]], qe[ok][:CASES[name]]
    if name == "gyrohorizoncompass":
        P = np.vstack([P, GHC_SETS])
        qe = np.vstack([qe, equilibria(m, np.array(GHC_SETS))[0]])
    assert len(P) == CASES[name] + 2 * (name == "gyrohorizoncompass") and np.all(np.isfinite(qe))
    M, D, K = operators(m, P, qe)
    bounds = rounding.operator_rounding(m, P, qe, M, D, K)
    radius = rounding.equilibrium_radius(m, P, qe)
    assert np.all(np.isfinite(radius)) and all(np.all(np.isfinite(b)) for b in bounds)
    with mpmath.workdps(50):
        for k in range(len(P)):
            q, ops = exact(m, P[k], qe[k])
            assert np.all(np.abs(np.array([float(x) for x in q]) - qe[k]) <= radius[k])
            for X, b, Xe in zip((M, D, K), bounds, ops):
                act = distance(X[k], Xe)
                assert np.all(act <= b[k] + SLACK * np.max(np.abs(X[k]))), (k, act, b[k])


def test_the_enclosure_holds_at_any_inputs_within_the_radii():
    """gimbal_gyroscope's operator of (params, qe, momenta), every input given a radius: at
    the corners of the box the exact operator stays within the bound at its centre."""
    m = load("gimbal_gyroscope")
    F = m.casadi.operator
    E = rounding.Enclosure(rounding.enclosure(F), F.n_out())
    rng = np.random.default_rng(3)
    P = draw(m, 5, 5)
    q = rng.uniform(-1.5, 1.5, (5, 1))
    mom = rng.uniform(-1, 1, (5, 2)) * 10.0 ** rng.uniform(-3, 3, (5, 1))
    radii = [np.abs(x) * 1e-12 for x in (P, q, mom)]
    values, bounds = E(P, q, mom, *radii)
    assert all(np.all(np.isfinite(b)) for b in bounds)
    with mpmath.workdps(50):
        for k in range(5):
            for sign in (1, -1):
                at = [[mpmath.mpf(x) + sign * (-1) ** i * mpmath.mpf(r) for i, (x, r) in enumerate(zip(v[k], rr[k]))]
                      for v, rr in zip((P, q, mom), radii)]
                for X, b, Xe in zip(values, bounds, m.mpmath.operator(*at)):
                    assert np.all(distance(X[k], Xe) <= b[k])


def test_the_probes_miss_an_entry_the_enclosure_holds():
    """The two probes of gyro.qep.equilibrium_moves in fixed directions: at this set
    (0.05x..20x of the gyrohorizoncompass, found among 200 random ones; bench.operator_rounding
    finds 22 such entries on 100 sets) neither moves K[3, 3] = 8.6e-4 at all, while the double entry is off
    the exact one by 1.1e-20: an estimate of 0 for a rounding that is there. The
    enclosure holds it (5.8e-18)."""
    m = load("gyrohorizoncompass")
    P = np.array([[0.006144811344599689, 0.005832742863354314, 0.005755671116476416, 0.00359795110641016,
                   2.055250858699009, 87783.10221641204, 0.02415750979850754, 0.0002105457556632642,
                   0.00013131094659988595, 18.719905760455347]])
    qe, ok = equilibria(m, P)
    assert ok.all()
    M, D, K = operators(m, P, qe)
    probes = qep.equilibrium_moves(m, P, qe, M, D, K)
    bounds = rounding.operator_rounding(m, P, qe, M, D, K)
    with mpmath.workdps(50):
        _, (_, _, Ke) = exact(m, P[0], qe[0])
        act = distance(K[0], Ke)
    assert act[3, 3] > probes[2][0, 3, 3]  # the probes' "bound" is beaten
    assert act[3, 3] <= bounds[2][0, 3, 3]


def test_the_bound_covers_the_operator_used_not_only_its_twin():
    """The operator used may differ from the CasADi twin the enclosure follows (another
    evaluation order in the C, NumPy): the difference joins the bound."""
    m = load("gyrohorizoncompass")
    P = draw(m, 3, 2)
    qe, ok = equilibria(m, P)
    M, D, K = operators(m, P[ok], qe[ok])
    base = rounding.operator_rounding(m, P[ok], qe[ok], M, D, K)
    moved = rounding.operator_rounding(m, P[ok], qe[ok], M * (1 + 1e-9), D, K)
    assert np.all(moved[0] >= base[0] + 0.9e-9 * np.abs(M)) and np.array_equal(moved[1], base[1])


def test_the_compiled_enclosure_is_casadis_evaluation():
    """The compiled enclosure (four sets a vector) performs the twin's operations in its
    order: its values and bounds are CasADi's own evaluation's, to the bit."""
    from gyro import cbackend

    m = load("torsion_gyrocompass")
    P = draw(m, 7, 4)
    qe, ok = equilibria(m, P)
    P, qe = P[ok], qe[ok]
    E = rounding.enclosed(m, "operator")
    r = np.abs(qe) * 1e-15
    compiled = E(P, qe, r)
    assert E.fn is not None
    with cbackend.disabled():
        assert E._compiled() is None
        values, bounds = E(P, qe, r)
    for a, b in zip(compiled[0] + compiled[1], values + bounds):
        assert np.array_equal(a, b)


def test_what_cannot_be_bounded_is_infinite():
    """A divisor within its own bound of zero, a logarithm whose operand may be negative,
    an operation without a rule (erfinv), a comparison that may flip: +inf, never a finite
    guess; the same operations on exact operands away from those edges stay finite."""
    import casadi as ca

    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    F = ca.Function("f", [x, y], [x / y, ca.log(y), ca.erfinv(x), ca.if_else(x < y, x, y)], ["x", "y"],
                    ["a", "b", "c", "d"])
    E = rounding.Enclosure(rounding.enclosure(F, ["y"]), 4)
    _, wide = E([[0.5]], [[1e-3]], [[2e-3]])
    assert all(np.isinf(b[0, 0, 0]) for b in wide[:3])
    _, flip = E([[0.5]], [[0.5005]], [[1e-3]])
    assert np.isinf(flip[3][0, 0, 0])
    _, narrow = E([[0.5]], [[1.0]], [[1e-3]])
    assert np.all(np.isfinite([narrow[0], narrow[1], narrow[3]])) and np.isinf(narrow[2][0, 0, 0])


def test_the_certificate_counts_with_the_enclosure():
    """The count that proves a cheap level's answer (gyro.questions.frequencies: Exact,
    _exact) carries the enclosure as the operator's distance from the exact one, not the
    probes; and at the torsion gyrocompass's own set the count at zero stays proven."""
    from gyro.questions.frequencies import Exact

    m = load("torsion_gyrocompass")
    P = np.vstack([m.vector(), draw(m, 3, 9)])
    ok, M, D, K, at, zero, moves = Exact(m, P).get()
    qe = equilibria(m, P)[0][ok]
    expected = rounding.operator_rounding(m, P[ok], qe, M[at], D[at], K[at])
    for a, b in zip(moves, expected):
        assert np.array_equal(a[at], b)
    assert zero[0] == 0
