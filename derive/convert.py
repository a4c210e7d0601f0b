"""A model as a sympy.physics.mechanics user writes it, converted once, at the start of the
derivation, to the machinery's own symbols (`derive/model.py`): plain SymPy symbols for the
coordinates, their rates and accelerations, with no assumptions.

- Coordinates given as `dynamicsymbols('theta')`: theta(t) becomes the symbol `theta`, its
  derivative theta' the symbol `theta_d` and theta'' `theta_dd` (or whatever `qd`, `qdd`
  name). `qd` and `qdd` may be left empty, or given as speeds `dynamicsymbols('u')`. With
  kinematic equations (`kinematics`, KanesMethod's kd_eqs) a speed is what they say: every
  u is replaced by its expression in q and q', and the record of q' = V u + v goes to the
  derivation, which forms the equations in the speeds (derive/passes/speeds.py); with
  holonomic constraints only kinematic equations u_i = q_i' (a joint's) are taken, the
  speeds then being the rates. Without
  them a speed stands for its coordinate's derivative, and must be it in every velocity of
  the model's frames and points it enters; a speed that is not, or that enters none
  the machinery can see, is refused (_check_velocities), never guessed. Every velocity
  the model's frames and points set must be the time derivative of their orientation or
  position: one that is not holds a velocity constraint (a rolling disc formed from its
  contact point up), nonholonomic, refused.
- Any other function of time, F(t), is an input: the `Signal` of that name when the model
  declares one (its rungs F, F_d, ... for F, F', ...), else an input signal made here of
  the order the derivation needs, as sympy's linearize takes every such function as an
  input r.
- Symbols with assumptions (`symbols('m g l', positive=True)`, coordinates with
  `real=True`) are the machinery's symbols of the same name.
- Loads written with `sympy.physics.vector` vectors: `Load(F, v)` with F and v Vectors, or
  sympy's own loads `(Point, Vector)`, `(ReferenceFrame, Vector)`, `Force`, `Torque` with
  the model's inertial `frame`: their components in one frame, the velocity of the point
  (the angular velocity of the body) in `frame`.

Nothing else changes: a model written in plain symbols is returned as it is.
"""
from __future__ import annotations

import dataclasses
import sys

import sympy as sp
from sympy.core.function import AppliedUndef

from derive.model import TIME, Load, Model, Signal, Unsupported


def _is_dynamic(e) -> bool:
    return isinstance(e, AppliedUndef) and e.args == (TIME,) or (
        isinstance(e, AppliedUndef) and len(e.args) == 1 and e.args[0].is_Symbol and e.args[0].name == "t")


def _plain(s):
    """The machinery's symbol of that name (no assumptions); s itself when it is one."""
    if not isinstance(s, sp.Symbol) or type(s) is not sp.Symbol:
        return s
    p = sp.Symbol(s.name)
    return s if p == s else p


def _vector_types():
    try:
        from sympy.physics.vector import Point, ReferenceFrame, Vector
    except ImportError:  # pragma: no cover - sympy always has it
        return None
    return Vector, Point, ReferenceFrame


def _is_vector(x) -> bool:
    if "sympy.physics.vector" not in sys.modules:  # no Vector exists before its module is
        return False  # imported: a model without one does not pay that import (0.1-0.35 s)
    types = _vector_types()
    return types is not None and isinstance(x, types[0])


def _frame_of(*vectors):
    for v in vectors:
        for _, frame in getattr(v, "args", ()):
            return frame
    return None


def _components(vector, frame) -> sp.Matrix:
    if not _is_vector(vector):
        return sp.Matrix(vector)
    if not vector.args:
        return sp.zeros(3, 1)
    try:
        return vector.to_matrix(frame)
    except Exception as exc:  # frames not oriented to each other
        raise Unsupported(f"a load's vector cannot be expressed in {frame}: {type(exc).__name__}: "
                          f"{str(exc).splitlines()[0] if str(exc) else ''}") from None


def _load(ld, frame, name: str) -> Load:
    """A Load with Matrix components, from a Load of Vectors or a sympy load."""
    Vector, Point, ReferenceFrame = _vector_types()
    if isinstance(ld, Load):
        vector, velocity, lname = ld.vector, ld.velocity, ld.name
        if not (_is_vector(vector) or _is_vector(velocity)):
            return ld
    else:
        where, vector = (ld.location, ld.vector) if hasattr(ld, "location") else tuple(ld)
        lname = name
        if frame is None:
            raise Unsupported(f"{name}: a load given as (point or frame, vector) needs the model's "
                              "inertial `frame` for the velocity of its point")
        if isinstance(where, Point):
            velocity = where.vel(frame)
        elif isinstance(where, ReferenceFrame):
            velocity = where.ang_vel_in(frame)
        else:
            raise Unsupported(f"{name}: a load acts on a Point or a ReferenceFrame, not {type(where).__name__}")
    common = _frame_of(vector, velocity) or frame
    return Load(_components(vector, common), _components(velocity, common), lname)


def _dynamic_rates(model: Model):
    """(map of the coordinates' functions of time and their derivatives to symbols,
    coordinates, rates, accelerations)."""
    mapping, q, qd, qdd, claimed = {}, [], [], [], []
    given_qd, given_qdd = list(model.qd), list(model.qdd)
    for i, x in enumerate(model.q):
        dyn = _is_dynamic(x)
        q.append(sp.Symbol(type(x).__name__) if dyn else _plain(x))
        if dyn:
            mapping[x] = q[-1]
        v = given_qd[i] if i < len(given_qd) else (x.diff(TIME) if dyn else None)
        a = given_qdd[i] if i < len(given_qdd) else (x.diff(TIME, 2) if dyn else None)
        if v is None or a is None:
            raise Unsupported(f"{model.name}: coordinate {model.coordinates[i] if i < len(model.coordinates) else x}: "
                              "no rate or acceleration given (qd, qdd)")
        if isinstance(v, sp.Derivative) or _is_dynamic(v):  # q' itself, or a speed u = q'
            vs = sp.Symbol(f"{q[-1]}_d") if isinstance(v, sp.Derivative) else sp.Symbol(type(v).__name__)
            mapping[v] = vs
            if dyn and _is_dynamic(v):  # a speed of its own, said to be the rate: checked
                claimed.append((x, v))
            if dyn:
                mapping[x.diff(TIME)] = vs
        else:
            vs = _plain(v)
        qd.append(vs)
        if isinstance(a, sp.Derivative) or _is_dynamic(a):
            asym = sp.Symbol(f"{vs}d" if str(vs).endswith("_d") else f"{vs}_d")
            asym = sp.Symbol(type(a).__name__) if _is_dynamic(a) else asym
            mapping[a] = asym
            if dyn:
                mapping[x.diff(TIME, 2)] = asym
            if _is_dynamic(v):
                mapping[v.diff(TIME)] = asym
        else:
            asym = _plain(a)
        qdd.append(asym)
    return mapping, q, qd, qdd, claimed


def _kinematics(model: Model):
    """The speeds of `kinematics` (KanesMethod's kd_eqs): (speeds u(t), {u(t): u as an
    expression of q(t), q'(t)}, V, v with q' = V u + v), or None without kinematics. The
    equations must be linear in the speeds and in q', n of them for n coordinates and n
    speeds, solvable for either (refused in one line otherwise)."""
    if not model.kinematics:
        return None
    name = model.name
    us = list(model.qd)
    if not all(_is_dynamic(x) for x in model.q) or not us or not all(_is_dynamic(u) for u in us):
        raise Unsupported(f"{name}: kinematic equations take coordinates and speeds as dynamicsymbols "
                          "(q(t) in `q`, u(t) in `qd`), as KanesMethod's kd_eqs do")
    if len(us) != len(model.q) or len(model.kinematics) != len(us):
        raise Unsupported(f"{name}: {len(model.kinematics)} kinematic equations for {len(model.q)} coordinates "
                          f"and {len(us)} speeds: one per coordinate and speed")
    qdots = [x.diff(TIME) for x in model.q]
    kd = sp.Matrix([_expression(e, f"kinematic equation {k + 1}", name) for k, e in enumerate(model.kinematics)])
    Wu, Wq = kd.jacobian(us), kd.jacobian(qdots)
    for W, what in ((Wu, "the speeds"), (Wq, "the coordinates' derivatives")):
        if W.has(*us) or W.has(*qdots):
            raise Unsupported(f"{name}: the kinematic equations are not linear in {what}")
    rest = kd.xreplace({**{u: 0 for u in us}, **{d: 0 for d in qdots}})
    if any(e.has(sp.Derivative) for e in rest) or any(e.has(sp.Derivative) for e in Wu):
        raise Unsupported(f"{name}: the kinematic equations have a derivative other than the coordinates' "
                          "first derivatives")
    import random

    for W, what in ((Wu, "the speeds"), (Wq, "the coordinates' derivatives")):
        if _numerically_zero([W.det(method="berkowitz")], random.Random(3)):  # at two random points
            raise Unsupported(f"{name}: the kinematic equations cannot be solved for {what} (their "
                              "Jacobian is singular): the speeds must be independent")
    # the solutions as they come, not simplified (sp.simplify took 2.4 s of a top's 3.8 s)
    solve_u = -Wu.LUsolve(Wq * sp.Matrix(qdots) + rest)
    V, v = -Wq.LUsolve(Wu), -Wq.LUsolve(rest)
    return us, dict(zip(us, solve_u)), V, v


def _rates_themselves(kin) -> bool:
    """The kinematic equations say u_i = q_i' for each i, in order (q' = V u + v with V the
    identity and v zero), as the kdes of sympy's joints do."""
    V, v = kin[2], kin[3]
    return all(sp.expand(e) == 0 for e in list(V - sp.eye(V.rows)) + list(v))


def _numerically_zero(exprs, rng) -> bool:
    """Every expression (in functions of time, their derivatives and symbols) zero at two
    random rational points, to 30 digits: each value a 30-digit Float, so that every
    subexpression is evaluated as the values go in (evalf of the exact rationals' tree took
    4 s of a heavy top's conversion)."""
    exprs = [sp.sympify(e) for e in exprs]

    def value(lo, hi):
        return sp.Float(sp.Rational(rng.randint(lo, hi), 1000), 30)

    for _ in range(2):
        pt = {}
        for e in exprs:
            for d in e.atoms(sp.Derivative):
                pt.setdefault(d, value(-2000, 2000))
        sub = [e.xreplace(pt) for e in exprs]
        pt2 = {f: value(-2000, 2000) for e in sub for f in e.atoms(AppliedUndef)}
        sub = [e.xreplace(pt2) for e in sub]
        pt3 = {s: value(500, 2000) for e in sub for s in e.free_symbols}
        if any(abs(complex(sp.N(e.xreplace(pt3), 30))) > 1e-20 for e in sub):
            return False
    return True


def live_points(model: Model) -> list:
    """The points alive now whose velocity in the model's inertial frame (that very object)
    is set: those of the bodies and particles its Lagrangian was formed of, which nothing
    else holds (a Lagrangian is a scalar). Points that locate one another hold each other
    in a cycle, so they live until the cyclic collector runs: derive.__main__.build takes
    them right after build() returns, with the collector held off meanwhile, and keeps them
    on the model (`_live_points`); a model built elsewhere is scanned when it is converted."""
    types = _vector_types()
    if model.frame is None or types is None:
        return []
    import gc

    return [o for o in gc.get_objects() if isinstance(o, types[1])
            and any(f is model.frame for f in getattr(o, "_vel_dict", {}))]


def _frames_and_points(model: Model):
    """The reference frames connected to the model's inertial frame by orientations or set
    angular velocities; the points whose velocity in that frame (the very object) is set
    (those of its bodies and particles, found among the live objects: a Lagrangian is a
    scalar, and the bodies it was formed of are nowhere else), the points of its loads, and
    those connected to them by positions."""
    frames, todo = [], [model.frame] if model.frame is not None else []
    while todo:
        f = todo.pop()
        if f is None or any(f is g for g in frames):
            continue
        frames.append(f)
        todo += list(getattr(f, "_dcm_dict", {})) + list(getattr(f, "_ang_vel_dict", {}))
    types = _vector_types()
    points, todo = [], []
    for ld in model.loads:
        where = getattr(ld, "location", None) or getattr(ld, "point", None)
        if where is None and isinstance(ld, tuple) and ld:
            where = ld[0]
        if types is not None and isinstance(where, types[1]):
            todo.append(where)
    live = getattr(model, "_live_points", None)
    todo += live if live is not None else live_points(model)
    while todo:
        p = todo.pop()
        if any(p is g for g in points):
            continue
        points.append(p)
        todo += list(getattr(p, "_pos_dict", {}))
    return frames, points


def _w_of_dcm(f, other):
    """The angular velocity of f in other that f's orientation gives, in f's components
    (w x = C C'^T in f, C = f.dcm(other)), as it comes: sympy's own (_w_diff_dcm)
    trigsimps each component, 4 s of a heavy top's 4.6 s conversion."""
    C = f.dcm(other)
    Cd = C.applyfunc(lambda e: e.diff(TIME))
    return C.row(2).dot(Cd.row(1)) * f.x + C.row(0).dot(Cd.row(2)) * f.y + C.row(1).dot(Cd.row(0)) * f.z


ORIENTATION = "its orientation gives"


def _check_velocities(model: Model, claimed: list, kin, as_kdes: bool = False) -> None:
    """Every velocity the model's points set, and every angular velocity its frames set in
    speeds, held to the one their position or orientation gives: a set velocity against its
    neighbour's plus the time derivative of the position between them (each pair once), a
    set angular velocity against the one its orientation gives (one in q' alone is the one
    sympy's orientation set), with each speed what it is (its expression in q and q' where
    kinematic equations say, else the rate of its coordinate). At two random points, to 30
    digits.

    A mismatch where a speed given without kinematic equations (u(t) in `qd` for q(t))
    enters is that speed not being its coordinate's rate: refused in one line, kinematic
    equations say what a speed is (Model.kinematics). Any other is a velocity that is no
    time derivative of a position, a velocity constraint built into the kinematics (a disc
    formed from its contact point up, whose centre's velocity is the rolling constraint):
    nonholonomic, refused in one line (Lagrange's equations of such a Lagrangian are not
    the system's, and LagrangesMethod's are not KanesMethod's). A claimed speed that enters
    no velocity the machinery can check is refused too (the Lagrangian is a scalar: it
    cannot tell u from q')."""
    import random

    rng = random.Random(0)
    as_rate = {u: x.diff(TIME) for x, u in claimed}
    speeds = dict(kin[1]) if kin else {}
    sub = {**as_rate, **speeds}
    seen: set = set()
    fix = ("give the kinematic equations (kinematics=[q' - u, ...] or the body's, as KanesMethod's "
           "kd_eqs), or write the coordinate's derivative itself")
    if as_kdes:  # kinematic equations u = q' beside holonomic constraints: rates, to be shown as such
        fix = ("beside holonomic constraints, speeds are taken as their coordinates' rates (kinematic "
               "equations u = q'), and must be shown to be them in the model's frame")
    frames, points = _frames_and_points(model)
    checks = []
    for f in frames:
        for other, w in getattr(f, "_ang_vel_dict", {}).items():
            if other in getattr(f, "_dcm_dict", {}) and f is not model.frame:  # each pair from its body's side
                checks.append((w, lambda f=f, other=other: _w_of_dcm(f, other), other,
                               f"the angular velocity of {f} in {other}", ORIENTATION, (w,)))
    inertial = model.frame
    pairs = set()
    for p in points:
        vp = getattr(p, "_vel_dict", {}).get(inertial)
        for o, r in getattr(p, "_pos_dict", {}).items():
            vo = getattr(o, "_vel_dict", {}).get(inertial)
            if vp is not None and vo is not None and (id(o), id(p)) not in pairs:  # each pair once
                pairs.add((id(p), id(o)))
                checks.append((vp, lambda vo=vo, r=r: vo + r.dt(inertial), inertial,
                               f"the velocity of {p} in {inertial}", f"its position from {o} gives", (vp, vo)))
    given = list(sub)
    for w, implied, frame, what, gives, entered in checks:  # a speed in either velocity of a pair is checked
        inside = [u for u in as_rate if any(v.args and any(m.has(u) for m, _ in v.args) for v in entered)]
        if gives == ORIENTATION and not (given and w.args and any(m.has(*given) for m, _ in w.args)):
            continue  # an angular velocity in q' alone: the one its orientation set (sympy's orient)
        try:
            diff = (w.xreplace(sub) - implied().xreplace(sub)).to_matrix(frame)
        except Exception:  # frames not oriented to each other: nothing to hold it to
            continue
        if not _numerically_zero(list(diff), rng):
            if inside:
                u = inside[0]
                x = next(x for x, v in claimed if v == u)
                raise Unsupported(f"{model.name}: the speed {type(u).__name__} is not the rate of "
                                  f"{type(x).__name__} in {what}: {fix}")
            raise Unsupported(f"{model.name}: {what} is not the one {gives}: a velocity constraint (rolling "
                              "without slip?) is nonholonomic, which the machinery does not derive; write "
                              "the velocities as time derivatives of positions")
        seen.update(inside)
    unchecked = [u for _, u in claimed if u not in seen]
    if unchecked:
        x = next(x for x, v in claimed if v == unchecked[0])
        raise Unsupported(f"{model.name}: the speed {type(unchecked[0]).__name__} of {type(x).__name__} enters no "
                          f"velocity of the model's frames or load points that shows it is {type(x).__name__}'s "
                          f"rate: {fix}")


def _exprs(model: Model, loads) -> list:
    """Every expression of the model that the conversion reads."""
    out = [model.lagrangian, model.dissipation]
    out += [c for ld in loads for c in list(ld.vector) + list(ld.velocity)]
    out += list(model.generalized_forces.values()) + list(model.nonholonomic) + list(model.holonomic)
    out += list(model.steady.values()) + list(model.cyclic.values())
    return [sp.sympify(e) for e in out]


def _inputs(model: Model, exprs, mapping, known_q) -> tuple[dict, list]:
    """Functions of time that are neither coordinates nor speeds: the declared signals of
    their name, or input signals of the order the derivation needs."""
    declared = {s.name: s for s in model.signals}
    found: dict[str, int] = {}
    in_lagrangian: set = set()
    for j, e in enumerate(exprs):
        for d in e.atoms(sp.Derivative):
            f = d.expr
            if _is_dynamic(f) and f not in known_q and d not in mapping:
                found[type(f).__name__] = max(found.get(type(f).__name__, 0), d.derivative_count)
                if j == 0:
                    in_lagrangian.add(type(f).__name__)
        for f in e.atoms(AppliedUndef):
            if _is_dynamic(f) and f not in known_q and f not in mapping:
                found.setdefault(type(f).__name__, 0)
                if j == 0:
                    in_lagrangian.add(type(f).__name__)
    new, extra = {}, []
    for name, order in sorted(found.items()):
        need = order + (1 if name in in_lagrangian else 0)  # Lagrange's d/dt of dL/dqd
        sig = declared.get(name)
        if sig is None:
            sig = Signal(name, "", f"{name}(t), an input given as a function of time", input=True, order=need)
            extra.append(sig)
        elif order > sig.order:
            raise Unsupported(f"{model.name}: the signal {name} appears differentiated {order} times, "
                              f"beyond its declared order {sig.order}")
        f = sp.Function(name)(TIME)
        for k, s in enumerate(sig.symbols[:order + 1]):
            new[f.diff(TIME, k) if k else f] = s
    return new, extra


def _expression(value, what: str, name: str):
    """A SymPy expression (or a number) that the machinery can derive, else refused in one
    line naming what it is: not an expression, a NaN or infinite constant, an integral."""
    if isinstance(value, (bool, str, bytes)) or value is None:
        raise Unsupported(f"{name}: {what} is not a SymPy expression (a {type(value).__name__})")
    if _is_vector(value):
        raise Unsupported(f"{name}: {what} is a vector, not a scalar expression")
    try:
        e = sp.sympify(value, strict=True)
    except (sp.SympifyError, TypeError, ValueError, AttributeError):
        raise Unsupported(f"{name}: {what} is not a SymPy expression (a {type(value).__name__})") from None
    if not isinstance(e, sp.Expr) or isinstance(e, sp.MatrixBase):
        raise Unsupported(f"{name}: {what} is not a scalar SymPy expression (a {type(e).__name__})")
    bad = [a for a in e.atoms(sp.Number) if not a.is_finite]
    if bad or e.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise Unsupported(f"{name}: {what} has a constant that is not a finite number "
                          f"({bad[0] if bad else 'nan or oo'})")
    for kind, why in ((sp.Integral, "an integral"), (sp.Sum, "a sum"), (sp.Piecewise, "a Piecewise (write it "
                      "with Heaviside, sign, Abs, Max or Min)"), (sp.DiracDelta, "a Dirac delta (an impulse)")):
        found = e.atoms(kind)
        if found:
            raise Unsupported(f"{name}: {what} has {why}, which the machinery cannot derive: {next(iter(found))}")
    return e


def _check_scalars(model: Model) -> None:
    name = model.name
    _expression(model.lagrangian, "the Lagrangian", name)
    _expression(model.dissipation, "the dissipation function", name)
    for cname, Qc in model.generalized_forces.items():
        _expression(Qc, f"the generalised force on {cname}", name)
    for k, c in enumerate(model.holonomic):  # a nonholonomic one is refused as such, whatever it is
        _expression(c, f"holonomic constraint {k + 1}", name)


def _check_expressions(model: Model) -> None:
    """Every expression of the model that the derivation differentiates, checked."""
    name = model.name
    _check_scalars(model)
    given = set(model.given_functions)
    exprs = [sp.sympify(model.lagrangian), sp.sympify(model.dissipation)] + [
        sp.sympify(v) for v in model.generalized_forces.values()]
    for e in exprs:
        for f in e.atoms(AppliedUndef):
            if f not in given:
                raise Unsupported(f"{name}: {f} is a function that the model does not declare (a function of "
                                  "time is a dynamicsymbol or a Signal; of a coordinate, a given function)")
        for dv in e.atoms(sp.Derivative):
            if dv.expr not in given:
                raise Unsupported(f"{name}: {dv} is an unevaluated derivative the machinery cannot take")
    for k, ld in enumerate(model.loads):
        if not isinstance(ld, Load):
            raise Unsupported(f"{name}: load {k + 1} is a {type(ld).__name__}, not a Load")
        for what, vec in (("vector", ld.vector), ("velocity", ld.velocity)):
            try:
                comps = sp.Matrix(vec)
            except Exception:
                raise Unsupported(f"{name}: load {k + 1} ({ld.name}): its {what} is not a column of "
                                  f"expressions (a {type(vec).__name__})") from None
            for c in comps:
                _expression(c, f"the {what} of load {k + 1} ({ld.name})", name)


def convert(model: Model) -> Model:
    """The model in the machinery's symbols; the model itself when it already is."""
    _check_scalars(model)
    out = _convert(model)
    _check_expressions(out)
    return out


def _convert(model: Model) -> Model:
    loads = [ld if isinstance(ld, Load) and not (_is_vector(ld.vector) or _is_vector(ld.velocity))
             else _load(ld, model.frame, f"{model.name}: load {k + 1}") for k, ld in enumerate(model.loads)]
    kin = _kinematics(model)
    as_kdes = bool(kin and model.holonomic and _rates_themselves(kin))
    if as_kdes:
        # u_i = q_i' (a joint's kdes): the speeds are the rates, claimed and checked as such, and
        # the constraints take the route of a model in rates (speeds with constraints are not derived)
        model, kin = dataclasses.replace(model, kinematics=[]), None
    mapping, q, qd, qdd, claimed = _dynamic_rates(dataclasses.replace(model, qd=[], qdd=[]) if kin else model)
    if claimed or model.frame is not None:
        _check_velocities(model, claimed, kin, as_kdes)
    # with kinematic equations, each speed u(t) is its expression in q and q' everywhere
    speed_sub = {}
    if kin:
        us, sol = kin[0], kin[1]
        speed_sub = {u.diff(TIME): sol[u].diff(TIME) for u in us} | sol
    exprs = [e.xreplace(speed_sub) for e in _exprs(model, loads)]
    known = {x for x in model.q if _is_dynamic(x)} | {x for x in model.qd if _is_dynamic(x)}
    signal_map, extra = _inputs(model, exprs, mapping, known)
    mapping.update(signal_map)
    free = set().union(*[e.free_symbols for e in exprs]) | set(model.q) | set(model.qd) | set(model.qdd)
    mapping.update({s: _plain(s) for s in free if isinstance(s, sp.Symbol) and _plain(s) != s})
    if not mapping and loads == list(model.loads):
        return model
    # derivatives first (their inner functions are replaced with them), then the functions
    order = sorted(mapping.items(), key=lambda kv: -int(isinstance(kv[0], sp.Derivative)) * (
        kv[0].derivative_count if isinstance(kv[0], sp.Derivative) else 0))
    ders = {k: v for k, v in order if isinstance(k, sp.Derivative)}
    rest = {k: v for k, v in order if not isinstance(k, sp.Derivative)}

    def conv(e):
        if e is None:
            return e
        if isinstance(e, (int, float)):
            return e
        if isinstance(e, sp.MatrixBase):
            return e.applyfunc(conv)
        e = sp.sympify(e)
        e = e.xreplace(speed_sub) if speed_sub else e
        e = e.xreplace(ders) if ders else e
        e = e.xreplace(rest) if rest else e
        left = [f for f in e.atoms(AppliedUndef) if _is_dynamic(f)] + [
            d for d in e.atoms(sp.Derivative) if _is_dynamic(d.expr)]
        if left:
            raise Unsupported(f"{model.name}: {left[0]} is left after converting the functions of time "
                              "(a derivative of a coordinate beyond its acceleration?)")
        return e

    def conv_dict(d):
        return {k: conv(v) for k, v in d.items()}

    speeds = {}
    if kin:
        speeds = {"u": [sp.Symbol(type(u).__name__) for u in kin[0]], "V": conv(kin[2]), "v": conv(kin[3])}
    quantities = {name: (ins, [(o, conv(sp.Matrix(m))) for o, m in outs], doc)
                  for name, (ins, outs, doc) in model.quantities.items()}
    return dataclasses.replace(
        model, q=q, qd=qd, qdd=qdd, lagrangian=conv(model.lagrangian), dissipation=conv(model.dissipation),
        loads=[Load(conv(ld.vector), conv(ld.velocity), ld.name) for ld in loads],
        generalized_forces=conv_dict(model.generalized_forces),
        nonholonomic=[conv(c) for c in model.nonholonomic], holonomic=[conv(c) for c in model.holonomic],
        steady=conv_dict(model.steady), cyclic=conv_dict(model.cyclic),
        equilibrium_approx=conv_dict(model.equilibrium_approx), formulas=conv_dict(model.formulas),
        quantities=quantities, signals=list(model.signals) + extra, kinematics=[], speeds=speeds,
        given_functions=[conv(f) for f in model.given_functions])
