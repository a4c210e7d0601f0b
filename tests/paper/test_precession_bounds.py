"""gimbal_precession: every level's bound holds against the tightest integration of `full`
(CVODES BDF at rtol 1e-14), over spreads wider than any use (issue 36): the casing angle
beta0 up to +-1.5 rad, base rates up to 300 rad/s, the outer ring's moments C1, C2 from
equal to flat (C2 - C1 = C3, the usual gimbal ring) and beyond, H 0.05x..20x, the other
inertias 0.2x..5x, moments from 1e-12 to 1e-2 N m and friction on and off; and through `gyro scene`'s selector at
tolerances 1e-1..1e-10, the level it answers by errs no more than the tolerance.

Kept fast: few examples (derandomized), horizons of 0.3..2 s, the bound's own runs (BDF and
a looser Adams) the cost of the rest. Sets whose motion reaches alpha or beta = +-90 deg are
refused by every level (Singular) and by the reference: hypothesis draws another."""
from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from gyro.systems import gimbal_precession as pr
from gyro.analyses.scene import select
from gyro.models import load

# the reference: BDF at rtol 1e-14. Not Adams there: where the motion is small against the
# angles (moments of 1e-10 N m) Adams at 1e-13 and 1e-14 stood 4e-4..1e-3 of the excursion away
# from BDF at 1e-12..1e-14, Adams at 1e-10..1e-12 and the rigorous level, which agreed to 6e-6
TIGHTEST = {"rtol_scale": 0.01, "multistep": "bdf"}
DEFAULT = {"C3": 2e-3, "B1": 1.2e-3, "B2": 1e-3, "B3": 0.8e-3, "A1": 0.5e-3, "A3": 1e-3}
RINGS = {"equal": (1.0, 1.0), "flat": (1.0, 2.0), "flat across": (2.0, 1.0)}  # (C1, C2) / C3


def _log(lo, hi):
    return st.floats(np.log10(lo), np.log10(hi)).map(lambda e: float(10**e))


def _signed(lo, hi):
    return st.tuples(st.sampled_from([-1.0, 1.0]), _log(lo, hi)).map(lambda p: p[0] * p[1])


def _maybe(strategy):
    return st.one_of(st.just(0.0), strategy)


@st.composite
def sets(draw):
    s = {"beta0": draw(st.floats(-1.5, 1.5)), "alpha0": draw(st.floats(-1.0, 1.0)), "H": draw(_log(0.05, 20.0)),
         # the base: a turn about zeta up to 300 rad/s; about xi, eta up to 1 rad/s (faster, the outer
         # ring turns past 90 deg at once and every level refuses the set)
         "u_zeta": draw(_maybe(_signed(1e-3, 300.0))), "u_xi": draw(_maybe(_signed(1e-6, 1.0))),
         "u_eta": draw(_maybe(_signed(1e-6, 1.0)))}
    for k, v in DEFAULT.items():
        s[k] = v * draw(_log(0.2, 5.0))
    ring = draw(st.sampled_from(sorted(RINGS) + ["spread"]))
    c1, c2 = RINGS[ring] if ring in RINGS else (draw(_log(0.2, 5.0)), draw(_log(0.2, 5.0)))
    s["C1"], s["C2"] = c1 * s["C3"], c2 * s["C3"]
    for k in ("l_x", "l_y", "m_z", "k_xi1"):
        s[k] = draw(_maybe(_signed(1e-12, 1e-2)))
    for k in ("f_alpha", "f_beta"):
        s[k] = draw(_maybe(_log(1e-4, 0.1)))
    return s


def _error(m, ref) -> float:
    """The motion question's measure: each quantity's largest deviation over the exact
    motion's largest excursion from its start."""
    return max(np.abs(m.x - ref.x).max(), np.abs(m.y - ref.y).max()) / pr._scale(ref)


def _reference(s, t):
    v = pr.parameters(s)
    try:
        return v, pr.simulate(v, t, "full", **TIGHTEST)
    except (pr.Singular, pr.IntegrationBudget):
        assume(False)


# the cases: rigorous at beta0 = 1.45 erred 1.1e-4 against a bound of 2.4e-5 (the sec(beta)
# of (13) missing); full's two-tolerance estimate beaten 2.3x on the second
@settings(max_examples=6, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@example({"beta0": 1.45}, 10.0)
@example({"H": 1.0, "beta0": 1.2, "l_x": 0.0, "l_y": -0.002, "f_alpha": 0.1}, 20.0)
@given(sets(), st.floats(0.3, 2.0))
def test_every_levels_bound_holds_against_the_tightest_full(s, T):
    t = np.linspace(0.0, T, 201)
    v, ref = _reference(s, t)
    assume(pr._scale(ref) > 0)
    for lv in pr.LEVELS:
        try:
            m = pr.simulate(v, t, lv)
            b = pr.bound(v, m)
        except (pr.Singular, pr.IntegrationBudget):  # refused: no answer, no bound to beat
            continue
        assert _error(m, ref) <= b, (lv, s, T, _error(m, ref), b)


@settings(max_examples=5, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@example({"beta0": 1.45}, 10.0, -4.0)  # the issue's: rigorous answered, bound 2.4e-5, error 1.1e-4
@given(sets(), st.floats(0.3, 1.0), st.floats(-10.0, -1.0))
def test_the_selectors_answer_is_within_the_tolerance(s, T, log_tol):
    """`gyro scene`'s selector at a tolerance 1e-1..1e-10: the level it answers by errs by
    no more than its bound, which is within the tolerance; a set it cannot answer is said."""
    tol = float(10**log_tol)
    model = load(pr.MODEL)
    v, ref = _reference(s, np.linspace(0.0, T, 201))  # the motion question's 201 samples
    sc = select(model, "motion", model.vector(v)[None, :], tol, {"horizon": T})
    if not sc.answered[0]:
        return
    doc = sc.document(0)
    err = max(np.abs(np.asarray(doc["x"]) - ref.x).max(), np.abs(np.asarray(doc["y"]) - ref.y).max()) / pr._scale(ref)
    assert err <= float(np.max(sc.bound[0])) <= tol, (s, T, tol, sc.level[0], err, sc.bound[0])


def test_the_flat_ring_on_a_turning_base():
    """The issue's case: a flat outer ring (C2 - C1 = C3) on a base turning at u_zeta = 10
    rad/s: the precession levels' enclosure does not close there (the w energy's growth
    exp(lambda T), lambda about |u|, over 2 s), so `full` answers it (the set is also past
    the declared edge |u| J/(H cos beta0) = 0.13 >= 1/10); at 1 rad/s the levels answer, each
    within its bound: the ring's centrifugal moment (C2 - C1) w_eta1 w_zeta1 is in the bound's
    residual (the rigorous level errs 1.0e-5 on the flat ring and 1.5e-3 on the equal ring:
    the ring's moment there partly cancels the casing's inertia moments, and each bound holds
    its own; the equal ring's is refused: a tube of 1e-3 rad, over which the intervals of the
    residuals exceed them)."""
    t = np.linspace(0.0, 2.0, 201)
    for u, refused in ((10.0, True), (1.0, False)):
        s = {"u_zeta": u, "C1": 1e-3, "C2": 3e-3, "alpha0": 0.1, "beta0": 0.1}
        v, ref = _reference(s, t)
        for lv in ("rigorous", "elementary"):
            m = pr.simulate(v, t, lv)
            b = pr.bound(v, m)
            assert (b == np.inf) == refused
            assert _error(m, ref) <= b
        if not refused:  # the ring's term is in full: its motion moves by 1.5e-3 of the excursion
            # from the equal ring's (measured), over the rigorous bound that holds on both (a bound
            # without the ring's term would be beaten)
            v0, ref0 = _reference({**s, "C1": 2e-3, "C2": 2e-3}, t)
            m0 = pr.simulate(v0, t, "rigorous")
            assert _error(m0, ref0) <= pr.bound(v0, m0)
            assert _error(ref, ref0) > pr.bound(v, pr.simulate(v, t, "rigorous"))  # 1.5e-3 against 3.9e-5


# a set with every term of the proof on: friction in all three axes, a flat ring off its
# defaults, a base turning about all three axes, moments on casing and rotor, the imbalance
PROOF_SET = {"alpha0": 0.3, "beta0": -0.7, "H": 0.6, "u_xi": 0.4, "u_eta": -0.3, "u_zeta": 1.1, "f_alpha": 0.01,
             "f_beta": 0.02, "f_phi": 0.003, "Mmotor": 0.002, "k_xi1": 3e-4, "l_x": 1e-3, "l_y": -2e-3, "l_z": 5e-4,
             "m_z": -4e-4, "C1": 1e-3, "C2": 3e-3}


def test_the_enclosures_identities_hold_on_the_full_equations():
    """The derivation's steps (docs/precession.md, "The bound of each level"), checked on the
    generated equations: hrest does not contain H; Kg f = cg is (13); sigma and the energy of
    om are polynomials of degree 2 (no cubic term, so the Hessian at 0 is the whole quadratic
    part); and along a run of `full` (its own state and rates) the slow variable z = s + B Kg^-1
    Mr v moves at Phi(s) + sigma(s, v), the energy of om = w - eta at -om.rho1 + om.Q om."""
    import casadi as ca

    v = pr.parameters(PROOF_SET)
    P = pr.vector(v)
    p, s, vv, _, hrest, _, _, _ = pr._split()
    rng = np.random.default_rng(3)
    S = np.stack([rng.uniform(-1, 1, 5), rng.uniform(-1.2, 1.2, 5), rng.uniform(0.3, 2, 5)])
    V = rng.uniform(-3, 3, (2, 5))
    dH = ca.Function("dH", [p, s, vv], [ca.jacobian(hrest, s[2])])
    assert np.abs(np.array(dH(P, S, V))).max() < 1e-13
    c = pr._at(v, S.T)
    assert np.allclose(c["Phi"], pr._rigorous(P, *S), rtol=1e-12, atol=1e-15)
    e = pr._expressions()
    for expr, var in ((e["sigma"], e["w"]), (e["energy"], e["o"])):  # degree 2: the third derivatives vanish
        third = ca.jacobian(ca.vec(ca.jacobian(ca.jacobian(expr, var), var)), var)
        fun = ca.Function("third", [e["p"], e["s"], var], [third])
        assert np.abs(np.array(fun(P, S[:, 0], [0.3, -0.2]))).max() < 1e-10

    # along full: its state (alpha, beta, phi, rates) at 2001 times over 0.02 s (the nutation at
    # H/J, ~60 rad/s here, resolved: h = 1e-5 s). Measured: z' agrees to 1e-9 of its size (without
    # sigma 3e-2), the energy's rate to 1e-6 (without Q 0.63): the tolerances are the central
    # differences' truncation (h omega)^2/6 ~ 6e-8 of the rates, with room for the stiffer sets
    # a change of PROOF_SET may bring
    T, n = 0.02, 2001
    grid = tuple(np.linspace(0.0, 1.0, n)[1:])
    Fi = pr._integrator("full", grid, pr._steps("full", n), 0.01, "bdf")
    y0 = pr.initial_state("full", v)
    Y = np.vstack([y0, np.array(Fi(x0=y0, p=np.append(P, T))["xf"]).T])
    t = np.linspace(0.0, T, n)
    nf = load(pr.MODEL).numpy
    Hf = nf.rotor_momentum(P, Y[:, :3], Y[:, 3:])[:, 0]
    Sf = np.stack([Y[:, 0], Y[:, 1], Hf], axis=-1)
    vf = Y[:, 3:5]
    cf = pr._at(v, Sf)
    wf = vf - cf["Phi"][:, :2]
    z = Sf + np.einsum("nij,nj->ni", cf["BKM"], vf)
    sig_f = (cf["sigma"] + np.einsum("nij,nj->ni", cf["s1"], wf)
             + 0.5 * np.einsum("nijk,nj,nk->ni", cf["s2"], wf, wf))
    zdot = np.gradient(z, t, axis=0, edge_order=2)[5:-5]
    want = (cf["Phi"] + sig_f)[5:-5]
    scale = np.abs(want).max(axis=0)
    assert np.all(np.abs(zdot - want).max(axis=0) <= 1e-5 * scale + 1e-12), np.abs(zdot - want).max(axis=0) / scale
    om = wf - cf["eta"]
    energy = 0.5 * np.einsum("ni,nij,nj->n", om, cf["Mr"], om)
    edot = np.gradient(energy, t, edge_order=2)[5:-5]
    want = (-np.einsum("ni,ni->n", om, cf["rho1"]) + np.einsum("ni,nij,nj->n", om, cf["Q"], om))[5:-5]
    assert np.abs(edot - want).max() <= 1e-4 * np.abs(want).max()


def test_the_enclosure_is_tight_where_the_first_order_term_dominates():
    """The issue's beta0 = 1.45 (10 s, sec(beta) = 8.4): `rigorous` errs 1.13e-4; the
    enclosure is 1.48e-4 (the first-order defect, carried on the sphere, the remainders
    second order, each constant enclosed over the steps and the tube: 1.16e-4 with them
    sampled); the estimate before it offered twice the first-order term, 2.3e-4. Not above
    1.5x the error, so the proof costs no usefulness here."""
    t = np.linspace(0.0, 10.0, 201)
    v, ref = _reference({"beta0": 1.45}, t)
    m = pr.simulate(v, t, "rigorous")
    err, b = _error(m, ref), pr.bound(v, m)
    assert err <= b <= 1.5 * err, (err, b)
