"""Generic analytical mechanics on SymPy expressions, for any model.

Coordinates q, velocities qd and accelerations qdd are plain symbols (not functions of
time); the total time derivative is taken by the chain rule, which keeps expressions small
and derivatives fast. Every step is a plain function that can be called on its own:

- rotations and angular velocities from angle sequences;
- kinetic energy of rigid bodies and particles;
- Lagrange equations of the second kind, and their mass-matrix form M(q) qdd = f(q, qd);
- first integrals of cyclic coordinates, Routh reduction, and elimination of a cyclic
  velocity from the full equations through its integral;
- the second-order expansion of a Lagrangian about an equilibrium into M, D, K and the
  operator J(p) = M p^2 + D p + K;
- block structure of an operator and the characteristic polynomial of each block as
  coefficients in p^2.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Sequence

import sympy as sp


class _WithoutNumpy:
    """A finder that answers an import of NumPy with ModuleNotFoundError, as if absent."""

    @staticmethod
    def find_spec(name, path=None, target=None):
        if name == "numpy" or name.startswith("numpy."):
            raise ModuleNotFoundError("NumPy withheld from symengine's import", name=name)
        return None


def _import_symengine():
    """symengine, imported without NumPy where NumPy is not loaded yet. symengine's wrapper
    imports NumPy only for Lambdify and for converting NumPy scalars and arrays (it checks
    for NumPy and does without), none of which the derivation asks of it; NumPy's import is
    0.06-0.1 s of CPU, as much as the whole derivation of a small model
    (bench/sympy_systems.py: disc_incline's derivation 0.022 s). A process that has NumPy
    already (the runtime deriving a model file) keeps symengine's NumPy support."""
    if "numpy" in sys.modules:
        import symengine

        return symengine
    finder = _WithoutNumpy()
    sys.meta_path.insert(0, finder)
    try:
        import symengine
    finally:
        sys.meta_path.remove(finder)
    return symengine


se = _import_symengine()

# --------------------------------------------------------------------------- rotations

_AXES = {"x": 0, "y": 1, "z": 2, 1: 0, 2: 1, 3: 2}


def rot(axis, angle) -> sp.Matrix:
    """Rotation matrix about a body axis ('x', 'y', 'z' or 1, 2, 3) by `angle`.

    Its columns are the rotated axes in the components of the frame before rotation, so a
    vector with components v in the rotated frame has components rot(axis, a) * v before it.
    """
    c, s = sp.cos(angle), sp.sin(angle)
    k = _AXES[axis]
    if k == 0:
        return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    if k == 1:
        return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rotation(sequence: Sequence[tuple]) -> sp.Matrix:
    """Product of body-axis rotations, [(axis, angle), ...] applied in order."""
    R = sp.eye(3)
    for axis, angle in sequence:
        R = R * rot(axis, angle)
    return R


def unit(axis) -> sp.Matrix:
    e = sp.zeros(3, 1)
    e[_AXES[axis]] = 1
    return e


def angular_velocity(sequence: Sequence[tuple], rates: Sequence, base=None) -> sp.Matrix:
    """Absolute angular velocity, in the components of the final frame, of a frame reached
    from a base frame by the body-axis rotations `sequence` at rates `rates`.

    `base` is the absolute angular velocity of the base frame in its own components
    (zero if None). Each rate contributes along its own rotation axis, carried to the final
    frame through the rotations that follow it.
    """
    omega = sp.zeros(3, 1) if base is None else sp.Matrix(base)
    for (axis, angle), rate in zip(sequence, rates):
        omega = rot(axis, angle).T * omega + rate * unit(axis)
    return omega


def cross(a: sp.Matrix, b: sp.Matrix) -> sp.Matrix:
    return sp.Matrix(a).cross(sp.Matrix(b))


# --------------------------------------------------------------------------- kinematics
# Differentiation runs in SymEngine (the same expressions, differentiated about a hundred
# to a thousand times faster than in SymPy); results come back as SymPy objects.


def _se(x):
    return se.sympify(x)


def _sp(x):
    return sp.sympify(x)


def _se_list(xs):
    return [se.sympify(x) for x in xs]


def jacobian(exprs, wrt) -> sp.Matrix:
    """The matrix d exprs_i / d wrt_j, differentiated in SymEngine, as SymPy."""
    xs = _se_list(wrt)
    rows = []
    for e in exprs:
        f = _se(e)  # once per expression, not once per variable
        rows.append([_sp(f.diff(x)) for x in xs])
    return sp.Matrix(rows)


TIME = sp.Symbol("t")  # explicit time (derive.model.TIME)
_TIME_SE = se.Symbol("t")


def chain(signals: Sequence = ()) -> tuple:
    """The explicit part of d/dt as pairs (symbol, its derivative): t -> 1, and along each
    signal's ladder s -> s_d -> s_dd; the last rung's derivative is None (not declared).
    `signals` are `Signal`s or ladders of symbols [s, s_d, ...]."""
    pairs = [(_TIME_SE, se.Integer(1))]
    for sig in signals:
        ladder = _se_list(getattr(sig, "symbols", sig))
        pairs += list(zip(ladder, ladder[1:] + [None]))
    return tuple(pairs)


def _partial_time_se(e, explicit):
    """The explicit part of the time derivative of e: d/dt at fixed q and qd."""
    out = se.Integer(0)
    for s, ds in explicit:
        d = e.diff(s)
        if d == 0:
            continue
        if ds is None:
            from derive.model import Unsupported

            raise Unsupported(f"the derivative of the signal rung {s} is needed: declare the "
                              "signal with a higher order")
        out += d * ds
    return out


def _time_derivative_se(e, q, qd, qdd=None, explicit=None):
    out = _partial_time_se(e, explicit if explicit is not None else chain())
    for qi, vi in zip(q, qd):
        out += e.diff(qi) * vi
    if qdd is not None:
        for vi, ai in zip(qd, qdd):
            out += e.diff(vi) * ai
    return out


def time_derivative(expr, q: Sequence, qd: Sequence, qdd: Sequence | None = None, signals: Sequence = ()):
    """Total time derivative of expr(q, qd, t, signals) by the chain rule: the partial
    derivative in the time symbol t, each signal's rung times the next one, then q and qd."""
    if isinstance(expr, sp.MatrixBase):
        return expr.applyfunc(lambda e: time_derivative(e, q, qd, qdd, signals))
    qs, vs = _se_list(q), _se_list(qd)
    acc = None if qdd is None else _se_list(qdd)
    return _sp(_time_derivative_se(_se(expr), qs, vs, acc, chain(signals)))


def partial_time(expr, signals: Sequence = ()):
    """d/dt of expr at fixed q and qd: through t and the signals only."""
    return _sp(_partial_time_se(_se(expr), chain(signals)))


def kinetic_energy(mass=0, velocity=None, inertia_diag=None, omega=None, inertia=None):
    """Kinetic energy of a rigid body: translation of its mass centre plus rotation about
    it, in principal axes (inertia_diag with omega in those axes) or with the full inertia
    tensor about the mass centre (`inertia`, a symmetric 3x3 matrix with its products of
    inertia, in the axes of omega): T_rot = omega' I omega / 2."""
    T = sp.Integer(0)
    if velocity is not None:
        v = sp.Matrix(velocity)
        T += sp.Rational(1, 2) * mass * (v.T * v)[0]
    if inertia_diag is not None:
        T += sp.Rational(1, 2) * sum(J * w**2 for J, w in zip(inertia_diag, omega))
    if inertia is not None:
        I, w = sp.Matrix(inertia), sp.Matrix(omega)
        if I.shape != (3, 3) or I != I.T:
            raise ValueError("kinetic_energy: the inertia tensor is a symmetric 3x3 matrix")
        T += sp.Rational(1, 2) * sp.expand((w.T * I * w)[0])
    return T


# --------------------------------------------------------------------------- Lagrange


def _lagrange_se(L, q, qd, qdd, explicit=None):
    return [_time_derivative_se(L.diff(vi), q, qd, qdd, explicit) - L.diff(qi) for qi, vi in zip(q, qd)]


def lagrange_equations(L, q, qd, qdd, Q=None, signals: Sequence = ()) -> list:
    """E_i = d/dt dL/dqd_i - dL/dq_i - Q_i (1.13-type equations; E = 0 on a motion), with
    the generalised forces Q (zero if None) and explicit time and signals in d/dt."""
    Es = _lagrange_se(_se(L), _se_list(q), _se_list(qd), _se_list(qdd), chain(signals))
    if Q is not None:
        Es = [e - _se(Qi) for e, Qi in zip(Es, Q)]
    return [_sp(e) for e in Es]


def mass_matrix_form(L, q, qd, Q=None, signals: Sequence = ()):
    """Mass-matrix form of the equations d/dt dL/dqd - dL/dq = Q: Mq(q) qdd = f(q, qd).

    Mq = d2L/dqd dqd, f = dL/dq - (d2L/dqd dq) qd - d/dt|explicit dL/dqd + Q, the explicit
    part through t and the signals. The mass matrix is never inverted symbolically:
    simulation solves Mq qdd = f numerically.
    """
    Ls, qs, vs = _se(L), _se_list(q), _se_list(qd)
    explicit = chain(signals)
    p = [Ls.diff(v) for v in vs]
    Mq = [[pi.diff(w) for w in vs] for pi in p]
    f = [Ls.diff(qi) - sum((pi.diff(qj) * vj for qj, vj in zip(qs, vs)), se.Integer(0))
         - _partial_time_se(pi, explicit) for qi, pi in zip(qs, p)]
    if Q is not None:
        f = [fi + _se(Qi) for fi, Qi in zip(f, Q)]
    return sp.Matrix(Mq).applyfunc(_sp), sp.Matrix(f).applyfunc(_sp)


# --------------------------------------------------------------------------- forces


def rayleigh_forces(F, qd) -> list:
    """Generalised forces of a Rayleigh dissipation function: Q_k = -dF/dqd_k."""
    Fs = _se(F)
    return [_sp(-Fs.diff(v)) for v in _se_list(qd)]


def load_forces(vector, velocity, qd) -> list:
    """Generalised forces of a force on a point (a moment on a body) by virtual power:
    Q_k = vector . d velocity / d qd_k, velocity that of the point (the angular velocity of
    the body) in the components of vector. The velocity of a holonomic system is affine in
    qd; anything else is refused."""
    from derive.model import Unsupported

    vec, vel = [_se(x) for x in sp.Matrix(vector)], [_se(x) for x in sp.Matrix(velocity)]
    if len(vec) != len(vel):
        raise Unsupported(f"a load's vector has {len(vec)} components and its velocity {len(vel)}")
    vs = _se_list(qd)
    out = []
    for v in vs:
        partial = [c.diff(v) for c in vel]
        if any(pc.diff(w) != 0 for pc in partial for w in vs):
            raise Unsupported("a load's velocity is not affine in the generalised velocities: "
                              "not the velocity of a point of a holonomic system")
        out.append(_sp(se.expand(sum((a * b for a, b in zip(vec, partial)), se.Integer(0)))))
    return out


def is_cyclic(L, coordinate) -> bool:
    """L does not depend on the coordinate: its derivative vanishes, to the letter or after
    simplification (a kinetic energy written in body rates, A (w1^2 + w2^2), carries the
    spin angle through sin^2 + cos^2)."""
    d = _se(L).diff(_se(coordinate))
    return d == 0 or se.expand(d) == 0 or sp.simplify(_sp(d)) == 0


def cyclic_integral(L, velocity):
    """Momentum conjugate to a cyclic coordinate: a first integral of the equations."""
    return _sp(_se(L).diff(_se(velocity)))


def _quadratic_in(L, v):
    """Coefficients (a, b, c) of L = a v^2 / 2 + b v + c; raises if L is not quadratic in v."""
    Ls, vs = _se(L), _se(v)
    a = Ls.diff(vs).diff(vs)
    if a.diff(vs) != 0:
        raise ValueError(f"Lagrangian is not quadratic in {v}")
    b = Ls.diff(vs).subs({vs: 0})
    c = Ls.subs({vs: 0})
    return a, b, c


def routhian(L, velocity, momentum):
    """Routh function R = L - beta v with v eliminated through dL/dv = beta.

    With L = a v^2/2 + b v + c: R = c - b^2/(2a) + beta b/a - beta^2/(2a). The reduced
    Lagrange equations in the remaining coordinates have R in place of L. c - b^2/(2a) is
    expanded so that the part of the energy that carries v cancels to the letter.
    """
    a, b, c = _quadratic_in(L, velocity)
    beta = _se(momentum)
    return _sp(se.expand(c - b**2 / (2 * a)) + beta * b / a - beta**2 / (2 * a))


def eliminate_cyclic(equations, q, qd, qdd, index, L, momentum, signals: Sequence = ()):
    """Substitute the cyclic integrals dL/dv_c = beta_c into the full equations.

    `index` and `momentum` are one coordinate index and its momentum, or lists of them.
    The momenta are linear in the cyclic velocities (possibly coupled, as for precession
    and spin of a top): the velocities are solved from them, and the accelerations from
    their time derivatives d/dt(dL/dv_c) = 0. Returns the equations of the remaining
    coordinates, in their order."""
    idx = [index] if isinstance(index, int) else list(index)
    betas = list(momentum) if isinstance(momentum, (list, tuple)) else [momentum]
    qs, vs, acc = _se_list(q), _se_list(qd), _se_list(qdd)
    Ls = _se(L)
    cv = [vs[i] for i in idx]
    ca = [acc[i] for i in idx]
    pcs = [Ls.diff(v) for v in cv]
    # momenta: p = Kv v_c + b, linear in the cyclic velocities
    Kv = sp.Matrix([[_sp(pc.diff(v)) for v in cv] for pc in pcs])
    b = sp.Matrix([_sp(pc.subs({v: 0 for v in cv})) for pc in pcs])
    v_sol = Kv.LUsolve(sp.Matrix(betas) - b)
    dpcs = [_time_derivative_se(pc, qs, vs, acc, chain(signals)) for pc in pcs]
    Ka = sp.Matrix([[_sp(d.diff(a)) for a in ca] for d in dpcs])
    ba = sp.Matrix([_sp(d.subs({a: 0 for a in ca})) for d in dpcs])
    a_sol = Ka.LUsolve(-ba)
    vmap = {v: _se(s) for v, s in zip(cv, v_sol)}
    amap = {a: _se(s).subs(vmap) for a, s in zip(ca, a_sol)}
    out = []
    for i, e in enumerate(equations):
        if i in idx:
            continue
        out.append(_sp(_se(e).subs(amap).subs(vmap)))
    return out


# --------------------------------------------------------------------------- linear operator


@dataclass
class LinearOperator:
    """M q'' + D q' + K q = 0 about an equilibrium; J(p) = M p^2 + D p + K."""

    M: sp.Matrix
    D: sp.Matrix
    K: sp.Matrix

    def J(self, p) -> sp.Matrix:
        return self.M * p**2 + self.D * p + self.K

    def applyfunc(self, f) -> "LinearOperator":
        return LinearOperator(self.M.applyfunc(f), self.D.applyfunc(f), self.K.applyfunc(f))

    def subs(self, mapping) -> "LinearOperator":
        return self.applyfunc(lambda e: e.subs(mapping))


def _at(e, at):
    return e if not at else e.subs(at)


def _reference(zero, rates=None, at=None):
    """(velocities and the like -> their values on the reference, coordinates -> `at`), in
    SymEngine: `zero` symbols are 0 (velocities at rest, accelerations, inputs), `rates` the
    velocities of a steady motion, `at` a partial point of the coordinates."""
    ref = {_se(v): se.Integer(0) for v in zero}
    ref.update({_se(k): _se(v) for k, v in (rates or {}).items()})
    return ref, {_se(k): _se(v) for k, v in (at or {}).items()}


def equilibrium_equations(L, q, qd, at=None, rates=None, Q=None, signals: Sequence = ()) -> sp.Matrix:
    """Generalised forces at the reference, evaluated at `at` (a partial point): dL/dq + Q
    at qd = 0 (or at the rates of a steady motion, whose turning coordinates are
    ignorable), less the explicit time derivative of dL/dqd there. Minus the equations of
    motion at the reference: a relative equilibrium (a steady motion) is a zero."""
    ref, at_s = _reference(qd, rates, at)
    Ls = _se(L).subs(ref)
    out = [Ls.diff(qi) for qi in _se_list(q)]
    explicit = chain(signals)
    for i, v in enumerate(_se_list(qd)):
        dp = _partial_time_se(_se(L).diff(v), explicit)
        if dp != 0:
            out[i] = out[i] - dp.subs(ref)
    if Q is not None:
        out = [o + _se(Qi).subs(ref) for o, Qi in zip(out, Q)]
    return sp.Matrix([_sp(_at(o, at_s)) for o in out])


def quadratic_expansion(L, q, qd, at=None, rates=None, signals: Sequence = ()) -> LinearOperator:
    """Second variation of L(q, qd, t) about (q0, qd0): the accessory Lagrangian
    L2 = dqd'A dqd/2 + dqd'N dq + dq'C dq/2 with A = L_vv, N = L_vq, C = L_qq there.

    Its Lagrange equations are A dq'' + (N - N' + dA/dt) dq' + (dN/dt - C) dq = 0, so
    M = A, D = N - N' + dA/dt (skew at rest in a time-independent system: gyroscopic and
    Coriolis), K = -C + dN/dt. The time derivatives are the explicit ones (t and signals):
    the reference is rest, or a steady motion whose turning coordinates are ignorable, so
    nothing else changes along it. `at` maps some or all coordinates to values (symbols or
    numbers) after differentiation; `rates` maps velocities to their values on the steady
    motion (zero if absent).
    """
    Ls, qs, vs = _se(L), _se_list(q), _se_list(qd)
    explicit = chain(signals)
    ref, at_s = _reference(vs, rates, at)
    grad_v = [Ls.diff(v) for v in vs]
    A = [[gv.diff(w).subs(ref) for w in vs] for gv in grad_v]
    grad_v0 = [gv.subs(ref) for gv in grad_v]
    N = [[gv.diff(qj) for qj in qs] for gv in grad_v0]
    L0 = Ls.subs(ref)
    grad_q = [L0.diff(qi) for qi in qs]
    K = [[-_at(gq.diff(qj), at_s) for qj in qs] for gq in grad_q]
    n = len(qs)
    D = [[_at(N[i][j], at_s) - _at(N[j][i], at_s) for j in range(n)] for i in range(n)]
    for i in range(n):
        for j in range(n):
            dA, dN = _partial_time_se(A[i][j], explicit), _partial_time_se(N[i][j], explicit)
            if dA != 0:
                D[i][j] += _at(dA, at_s)
            if dN != 0:
                K[i][j] += _at(dN, at_s)
    Mm = [[_at(a, at_s) for a in row] for row in A]
    conv = lambda X: sp.Matrix(X).applyfunc(_sp)  # noqa: E731
    return LinearOperator(conv(Mm), conv(D), conv(K))


def linearize_forces(Q, q, qd, at=None, rates=None) -> tuple:
    """Jacobians of generalised forces Q(q, qd) at the reference: (dQ/dq, dQ/dqd). Added to
    an operator as D - dQ/dqd and K - dQ/dq."""
    Qs, qs, vs = _se_list(Q), _se_list(q), _se_list(qd)
    ref, at_s = _reference(vs, rates, at)
    J = lambda xs: sp.Matrix([[_sp(_at(e.diff(x).subs(ref), at_s)) for x in xs] for e in Qs])  # noqa: E731
    return J(qs), J(vs)


def linearize_equations(equations, q, qd, qdd, at=None, rates=None) -> LinearOperator:
    """Jacobians of the equations E(q, qd, qdd) = 0 at (q0, qd0, 0): E ~ M dq'' + D dq' + K dq.
    `rates` maps velocities to their values on a steady motion (zero if absent)."""
    Es = _se_list(equations)
    qs, vs, acc = _se_list(q), _se_list(qd), _se_list(qdd)
    ref, at_s = _reference(vs + acc, rates, at)
    J = lambda xs: sp.Matrix([[_sp(_at(e.diff(x).subs(ref), at_s)) for x in xs] for e in Es])  # noqa: E731
    return LinearOperator(J(acc), J(vs), J(qs))


def input_matrix(equations, inputs, q, qd, qdd, at=None, rates=None) -> sp.Matrix:
    """B of M q'' + D q' + K q = B w: minus the Jacobian of the equations E in the inputs w
    at the reference (E = 0 on a motion, so the inputs stand on the right)."""
    Es = _se_list(equations)
    vs, acc = _se_list(qd), _se_list(qdd)
    ref, at_s = _reference(vs + acc + list(inputs), rates, at)
    return sp.Matrix([[_sp(-_at(e.diff(_se(w)).subs(ref), at_s)) for w in inputs] for e in Es])


# --------------------------------------------------------------------------- blocks, polynomials


def blocks(J: sp.Matrix) -> list[list[int]]:
    """Connected components of the sparsity graph of a square matrix: the diagonal blocks
    of a block-diagonal operator up to a permutation, each sorted, in order of first index."""
    n = J.shape[0]
    parent = list(range(n))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(n):
        for j in range(n):
            if i != j and J[i, j] != 0:
                parent[find(i)] = find(j)
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return sorted(groups.values(), key=lambda g: g[0])


def _det_sparse(rows):
    """Determinant by cofactor expansion along the sparsest row, with no division: exact
    polynomial entries stay polynomials (SymEngine's LU det would introduce fractions).
    Cheap for the small sparse blocks of an operator (n <= 8 or so)."""
    n = len(rows)
    if n == 1:
        return rows[0][0]
    i = min(range(n), key=lambda r: sum(1 for e in rows[r] if e != 0))
    total = se.Integer(0)
    for j, e in enumerate(rows[i]):
        if e == 0:
            continue
        minor = [[row[k] for k in range(n) if k != j] for r, row in enumerate(rows) if r != i]
        total += (-1) ** (i + j) * e * _det_sparse(minor)
    return total


def charpoly_in_p2(J: sp.Matrix, p, z) -> list:
    """Coefficients c_k of det J(p) = sum_k c_k z^k with z = p^2, lowest degree first.

    Raises if det J(p) has odd powers of p (it cannot, for M, K symmetric and D skew).
    """
    rows = [[_se(J[i, k]) for k in range(J.shape[1])] for i in range(J.shape[0])]
    det = se.expand(_det_sparse(rows))
    poly = sp.Poly(_sp(det), p)
    coeffs = {}
    for (k,), c in poly.terms():
        if k % 2:
            if sp.expand(c) != 0:
                raise ValueError(f"det J(p) has an odd power p^{k}")
            continue
        coeffs[k // 2] = c
    deg = max(coeffs) if coeffs else 0
    return [coeffs.get(k, sp.Integer(0)) for k in range(deg + 1)]


def substitute(exprs, mapping) -> list:
    """Substitute in many large expressions at once (SymEngine), e.g. given functions and
    their derivatives by input symbols."""
    m = {_se(k): _se(v) for k, v in mapping.items()}
    return [_sp(_se(e).subs(m)) for e in exprs]


def null_lagrangian_residual(dL, q, qd, qdd, signals: Sequence = ()) -> list:
    """Lagrange equations of a Lagrangian difference, expanded: all zero iff dL is a total
    time derivative plus a constant (it then changes no equation of motion)."""
    return [_sp(se.expand(e)) for e in _lagrange_se(_se(dL), _se_list(q), _se_list(qd), _se_list(qdd), chain(signals))]


def numeric_equilibrium(equations, unknowns, values: dict, guess: dict, dps: int = 40) -> dict:
    """Solve equilibrium equations numerically in arbitrary precision (mpmath.findroot).

    `equations` are expressions in `unknowns` and parameters; `values` gives the parameters
    (numbers), `guess` a start for each unknown (e.g. the paper's approximation). Returns
    unknown -> mpf. A reference for the runtime's double-precision Newton iteration."""
    import mpmath as mp

    with mp.workdps(dps):
        eqs = [sp.sympify(e).subs({k: sp.Float(v, dps) for k, v in values.items()}) for e in equations]
        eqs = [e for e in eqs if e != 0]
        f = sp.lambdify(list(unknowns), eqs, modules="mpmath")
        jac = sp.lambdify(list(unknowns), sp.Matrix(eqs).jacobian(list(unknowns)), modules="mpmath")
        x0 = [mp.mpf(guess[u]) for u in unknowns]
        sol = mp.findroot(lambda *x: f(*x), x0, J=lambda *x: jac(*x), tol=mp.mpf(10) ** (-dps + 5))
        sol = [sol] if len(unknowns) == 1 else list(sol)
    return dict(zip(unknowns, sol))


def integral_rates(L, q, qd, qdd, integrals, Q=None, signals: Sequence = ()) -> list:
    """Time derivatives of candidate first integrals along the equations of L with forces Q:
    the accelerations are solved from the mass-matrix form (a small symbolic solve, for a
    proof, never for emission). A first integral's rate simplifies to zero."""
    Mq, f = mass_matrix_form(L, q, qd, Q, signals)
    acc = Mq.LUsolve(f)
    sub = dict(zip(qdd, acc))
    return [time_derivative(I, q, qd, qdd, signals).subs(sub) for I in integrals]


def root_series(F, x, x0, eps, order: int) -> list:
    """Taylor coefficients [x1, ..., x_order] of the root x(eps) = x0 + x1 eps + x2 eps^2 + ...
    of F(x, eps) = 0 through a simple root x0 of F(x, 0): order by order, each coefficient
    from a linear equation with the slope dF/dx(x0, 0) as its divisor. The perturbation
    series behind an approximate frequency formula; its first omitted term estimates the
    formula's error. Solved on symbols F_ij for the derivatives d^(i+j)F/dx^i deps^j at
    (x0, 0), which are substituted at the end (no expansion of x0's powers)."""
    if sp.cancel(F.subs({x: x0, eps: 0})) != 0:
        raise ValueError("root_series: x0 is not a root of F(x, 0)")
    d = sp.Symbol("_d")
    Fs = {(i, j): sp.Symbol(f"_F{i}_{j}") for i in range(order + 1) for j in range(order + 1)
          if 0 < i + j <= order}
    T = sum(f * d**i * eps**j / (sp.factorial(i) * sp.factorial(j)) for (i, j), f in Fs.items())
    cs = sp.symbols(f"_c1:{order + 1}")
    G = sp.expand(T.subs(d, sum(c * eps**(k + 1) for k, c in enumerate(cs))))
    out = {}
    for k in range(1, order + 1):
        ck = sp.expand(G.coeff(eps, k).subs(out))
        a = ck.coeff(cs[k - 1])
        out[cs[k - 1]] = -(ck - a * cs[k - 1]) / a
    Fse, xse, ese = _se(F), _se(x), _se(eps)
    at = {xse: _se(x0), ese: se.Integer(0)}
    values = {f: _sp(Fse.diff(*([xse] * i + [ese] * j)).subs(at)) for (i, j), f in Fs.items()}
    return [out[c].subs(values) for c in cs]
