"""What makes the certificate's enclosure cheap keeps it a bound: the compiled enclosure
writes +inf itself where a bound or its value is not finite (no pass over the arrays after
the call), the equilibrium's Krawczyk test in C (gyro/csrc/krawczyk.c) is the NumPy one, and
the certificate counts on the operator the enclosure's twin evaluates, within its bound of
the exact operator (gyro.rounding.operator_enclosed)."""
from __future__ import annotations

import ctypes
from fractions import Fraction

import mpmath
import numpy as np

from bench.operator_rounding import SLACK, distance, draw, exact
from gyro import rounding
from gyro.equilibrium import equilibria
from gyro.models import load


def test_the_compiled_enclosure_writes_inf_where_no_bound_holds():
    """sqrt(-1) (a NaN value, a NaN bound as computed) and floor(inf) (bound 0 as computed,
    its value not finite), inputs exact: the compiled entry point itself writes +inf, and
    the finite case beside them keeps its finite bound."""
    import casadi as ca

    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    F = ca.Function("g", [x, y], [ca.sqrt(x), ca.floor(y), x * y], ["x", "y"], ["a", "b", "c"])
    E = rounding.Enclosure(rounding.enclosure(F, []), 3)
    E([[1.0]], [[1.0]])  # compiled on first use
    assert E.fn is not None
    args = [np.array([[-1.0]]), np.array([[np.inf]])]
    flat = [np.full((1, 1), 7.0) for _ in range(6)]
    P = ctypes.POINTER(ctypes.c_double)
    assert E.fn(ctypes.c_longlong(1), (P * 2)(*[a.ctypes.data_as(P) for a in args]),
                (P * 6)(*[o.ctypes.data_as(P) for o in flat])) == 0
    assert np.isnan(flat[0][0, 0]) and np.isinf(flat[1][0, 0])
    assert np.isinf(flat[3][0, 0]) and np.isinf(flat[4][0, 0])  # the raw call: no NaN, no 0
    assert np.isinf(flat[5][0, 0])  # -1 * inf: not finite
    _, (ea, eb, ec) = E([[-1.0, 4.0]], [[np.inf, 2.5]])
    assert np.isinf(ea[0, 0, 0]) and np.isinf(eb[0, 0, 0]) and np.isfinite(ea[1, 0, 0]) and eb[1, 0, 0] == 0


def _krawczyk_inputs(name, n, seed):
    m = load(name)
    P = draw(m, n, seed)
    qe, ok = equilibria(m, P)
    P, qe = P[ok], qe[ok]
    point = rounding.enclosed(m, "equilibrium_system", (), ("r", "K", "e_r"))
    box = rounding.enclosed(m, "equilibrium_system", ("qe",), ("e_K",))
    (r, Kn), (er,) = point(P, qe)
    return P, qe, r[:, :, 0], er[:, :, 0], Kn, box


def test_the_compiled_krawczyk_is_the_numpy_one():
    """On the torsion gyrocompass and the gyrohorizoncompass (0.05x..20x, a singular Kn
    and a NaN residual added): the same sets live, X within 1e-9 |X| |Kn| |X|, `formed` never
    below |I - X Kn| in exact arithmetic for the C's own X, and the radii of the first box to a
    relative 1e-9 (a radius is proven by either; X differs by rounding)."""
    assert rounding._krawczyk_kernel() is not None
    for name in ("torsion_gyrocompass", "gyrohorizoncompass"):
        P, qe, r, er, Kn, box = _krawczyk_inputs(name, 60, 7)
        Kn[0] = 0.0  # singular: no inverse, no radius
        r[1, 0] = np.nan
        c = rounding._krawczyk_start_c(r, er, Kn)
        npy = rounding._krawczyk_start_numpy(r, er, Kn)
        assert np.array_equal(c[0], npy[0]) and not c[0][0] and not c[0][1] and c[0][2:].all()
        live = c[0]
        aX = np.abs(npy[1][live])  # X's own rounding scale, entry by entry: |X| |Kn| |X|
        assert np.all(np.abs(c[1][live] - npy[1][live]) <= 1e-9 * (aX @ np.abs(Kn[live]) @ aX))
        ne = r.shape[1]
        for k in np.flatnonzero(live)[:20]:  # |I - X Kn| in exact rational arithmetic, the C's own X
            X, A = [[Fraction(v) for v in row] for row in c[1][k]], [[Fraction(v) for v in row] for row in Kn[k]]
            for i in range(ne):
                for j in range(ne):
                    e = abs((i == j) - sum(X[i][t] * A[t][j] for t in range(ne)))
                    assert Fraction(c[3][k, i, j]) >= e, (name, k, i, j)
        todo = np.flatnonzero(live)
        outs = []
        for start, step in ((c, rounding._krawczyk_step_c), (npy, rounding._krawczyk_step_numpy)):
            _, X, base, formed, d = start
            d = d.copy()
            _, (eK,) = box(P[todo], qe[todo], d[todo])
            out = np.full(r.shape, np.inf)
            inside = step(todo, X, formed, base, eK, d, out)
            outs.append((inside, out, d))
        (ic, oc, dc), (inp, on, dn) = outs
        assert np.array_equal(ic, inp) and ic.mean() > 0.9
        assert np.allclose(oc[todo[ic]], on[todo[ic]], rtol=1e-9, atol=0)
        assert np.allclose(dc[todo], dn[todo], rtol=1e-9, atol=0)


def test_the_certificate_counts_on_the_twin_within_its_bound():
    """The frequencies' certificate (gyro.questions.frequencies._exact) takes M, D, K from
    the enclosure's twin: those are within their bound of the exact operator at the exact
    equilibrium (50 digits), entry by entry, every bound finite, and they are the twin's own
    values (not the runtime's operator: nothing of |used - twin| is carried)."""
    from gyro.questions.frequencies import _exact

    m = load("torsion_gyrocompass")
    P = np.vstack([m.vector(), draw(m, 4, 21)])
    ok, M, D, K, dM, dD, dK, zero = _exact(m, P)
    qe = equilibria(m, P)[0][ok]
    twin, _ = rounding.enclosed(m, "operator")(P[ok], qe, rounding.equilibrium_radius(m, P[ok], qe))
    for X, T in zip((M, D, K), twin):
        assert np.array_equal(X, T)
    assert all(np.all(np.isfinite(b)) for b in (dM, dD, dK))
    with mpmath.workdps(50):
        for k in range(len(M)):
            _, ops = exact(m, P[ok][k], qe[k])
            for X, b, Xe in zip((M, D, K), (dM, dD, dK), ops):
                assert np.all(distance(X[k], Xe) <= b[k] + SLACK * np.max(np.abs(X[k])))
