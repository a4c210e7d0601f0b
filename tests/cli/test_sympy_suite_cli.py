"""The commands on systems from SymPy's own suite (tests/models/sympy_suite/,
docs/sympy_suite.md), their numbers against SymPy's linearize at the same point.

A cart on a PrismaticJoint with a pendulum on a PinJoint, a LinearSpring and a LinearDamper
on the pathway from the wall to the cart: the spring's force k (|q1| - x0) q1/|q1| is not
defined at q1 = 0, the solver's start (0/0). The equilibrium q1 = x0, q2 = 0 is found from a
moved start, and the frequencies there are SymPy's (linearize's A, its eigenvalues at 30
digits): to 1e-12 of each (the gyro frequencies are double precision with error estimates
near 1e-15 on this operator of well separated roots)."""
from __future__ import annotations

import json

import mpmath
import sympy as sp

from tests.conftest import ROOT, run_cli

SUITE = ROOT / "tests" / "models" / "sympy_suite"


def _sympy_frequencies(module, doc):
    """The imaginary parts > 0 of the eigenvalues of KanesMethod's linearised A at the
    equilibrium the command reports, to 30 digits."""
    from sympy.physics.mechanics import dynamicsymbols

    _, km = module.reference()
    t = dynamicsymbols._t
    op = {x: sp.Float(doc["equilibrium"][x.func.__name__], 30) for x in km.q}
    op |= {x.diff(t): 0 for x in km.q} | {u: 0 for u in km.u} | {u.diff(t): 0 for u in km.u}
    A = km.linearize(A_and_B=True, op_point=op)[0]
    par = {s: sp.Float(doc["params"][s.name], 30) for s in A.free_symbols}
    with mpmath.workdps(30):
        ev = mpmath.eig(mpmath.matrix(A.xreplace(par).evalf(30).tolist()), left=False, right=False)
        return sorted(float(e.imag) for e in ev if e.imag > 0), max(float(e.real) for e in ev)


def test_the_cart_on_joints_finds_its_equilibrium_off_the_springs_singular_start():
    from derive.__main__ import load_file

    path = SUITE / "joints_cart.py"
    rc, out, err = run_cli("frequencies", str(path), "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert abs(doc["equilibrium"]["q1"] - doc["params"]["x0"]) <= 1e-15 and doc["equilibrium"]["q2"] == 0.0
    freqs, growth = _sympy_frequencies(load_file(path), doc)
    assert len(doc["frequencies"]) == len(freqs) == 2
    for ours, theirs in zip(sorted(doc["frequencies"]), freqs):
        assert abs(ours - theirs) <= 1e-12 * theirs
    assert doc["stability"]["class"] == "stable" and growth < 0
    rc, out, err = run_cli("simulate", str(path), "--t-end", "0.5", "--points", "2", "--perturb", "q2=0.01", "--json")
    assert rc == 0, err
    assert json.loads(out)["q1"][0] == doc["equilibrium"]["q1"]
