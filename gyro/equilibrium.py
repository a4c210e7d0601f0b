"""The one equilibrium solver: relative equilibria of a batch of parameter sets by
Newton's method from the paper's approximation (2.2) (zero where the model has none), with
the operator's stiffness K as the Jacobian, vectorised over the batch.

Steps on angles are damped to MAX_ANGLE_STEP so that each set stays on the branch it
starts from; a set whose K is singular takes a least-squares step (g = 0 leaves the azimuth
free); a set that has not converged after MAX_ITER steps is accepted when its residual is
below 1e-9 (1 + max |p|) and passes the residual test below, as an exact but
ill-conditioned equilibrium does; the equation of
a steadily turning coordinate, which no unknown enters, must hold to the same bound (a
drive balancing friction at these parameters) or the set has no reference motion; inputs
whose operator is beyond double precision never reach LAPACK. With a compiler the iteration
runs in the generated C set by set (templates/equilibrium.c.j2), which answers the sets it
converges on and hands every other back to the NumPy iteration (_newton_numpy). Every
answer, of either, is then held to the equations (residual_test: each residual below
RESIDUAL_TOL of the size of its terms); a set that Newton left off balance after
converging (a singular K at the start: the least-squares step is zero along its null
direction) or that could not start (the equations undefined at the start) is tried again
from moved starts (RESTARTS), and a set balanced by none is
refused (why_not says which equation keeps which residual)."""
from __future__ import annotations

import numpy as np

from gyro import cbackend
from gyro.errors import ParameterError
from gyro.kernels import compiled, function
from gyro.models import Model


class EquilibriumError(RuntimeError):
    pass


def require_time_free(model: Model) -> None:
    """An operator about an equilibrium needs equations free of the explicit time t: a model
    emitted with t in its equilibrium equations or its operator (metadata 'time_dependent';
    the derivation now refuses a time-dependent forcing, a parametric excitation still
    derives) is refused in one line here, before any function is called without its time."""
    timed = [f for f in ("equilibrium_residual", "operator")
             if any(g["name"] == "time" for g in model.meta["functions"].get(f, {}).get("inputs", []))]
    if timed:
        raise ParameterError(f"{model.name}: its {' and '.join(timed)} depend on the explicit time t: the "
                             "analyses take a constant operator about an equilibrium; write a time-dependent "
                             "forcing (a mass unbalance) as force inputs and use `gyro unbalance` "
                             "(docs/models.md); a parametric excitation needs a Floquet analysis, not built")


MAX_ANGLE_STEP = 0.2  # rad: Newton steps on angles are damped to stay on the branch of (2.2)
MAX_ITER = 100
TOL = 1e-14


def wrap(angle):
    """Angles into (-pi, pi]; angles already there are returned untouched (adding and
    subtracting pi would cost a small angle its relative precision)."""
    angle = np.asarray(angle, dtype=float)
    out = (angle + np.pi) % (2 * np.pi) - np.pi
    return np.where(np.abs(angle) <= np.pi, angle, out)


def tame(X) -> np.ndarray:
    """Per matrix of a batch (or for one matrix): finite and far from overflow (LAPACK
    squares entries while scaling; beyond 1e150 it overflows and complains on stderr)."""
    X = np.asarray(X)
    with np.errstate(invalid="ignore"):
        return np.all(np.abs(X) < 1e150, axis=(-2, -1))


def _layout(model: Model):
    """(equilibrium coordinates, the rows of the Newton system, which are angles). The rows
    are the equilibrium coordinates' places among the reduced ones; a model with
    multipliers has all coordinates as unknowns and its own square system (the reduced
    residual and the constraints: equilibrium_system), rows 0..n-1."""
    reduced = model.meta["reduced"]
    names = model.meta["equilibrium_coordinates"]
    if model.meta.get("constraints", {}).get("multipliers"):
        if "equilibrium_system" not in model.meta["functions"]:
            raise ParameterError(f"{model.name}: a model with multipliers emitted without equilibrium_system "
                                 "(derive it again with this version)")
        idx = np.arange(len(names), dtype=int)
    else:
        idx = np.array([reduced.index(c) for c in names], dtype=int)
    units = model.meta.get("coordinate_units", {})
    return names, idx, np.array([units.get(c) == "rad" for c in names], dtype=bool)


def _groups(model: Model) -> np.ndarray:
    """(ne, ne) booleans: coordinates i and j of the same unit (lengths with lengths, angles
    with angles; one without a unit alone). The iteration's convergence test measures each
    step against the largest coordinate of its group: a coordinate at rounding noise about an
    exact zero (the gyrohorizoncompass's beta near 1e-20 rad beside an epsilon of 1 rad) has
    no relative precision for a test of its own to reach."""
    names = model.meta["equilibrium_coordinates"]
    units = model.meta.get("coordinate_units", {})
    key = [units.get(c) or f"#{i}" for i, c in enumerate(names)]
    return np.array([[a == b for b in key] for a in key], dtype=bool).reshape(len(key), len(key))


def equilibria(model: Model, P: np.ndarray, tol: float = TOL, max_iter: int = MAX_ITER):
    """Relative equilibria of a batch P (sets, parameters). Returns (qe, ok): qe (sets,
    equilibrium coordinates), NaN where ok is False."""
    qe, ok, _ = equilibria_reported(model, P, tol, max_iter)
    return qe, ok


def equilibria_reported(model: Model, P, tol=TOL, max_iter=MAX_ITER):
    """equilibria, and _solve's report of each set (why_not reads it)."""
    require_time_free(model)
    P = np.atleast_2d(np.asarray(P, dtype=float))
    names, idx, is_angle = _layout(model)
    n = P.shape[0]
    if "equilibrium_approx" in model.meta["functions"]:
        with np.errstate(all="ignore"):
            qe = function(model, "equilibrium_approx")(P)[0].reshape(n, -1)
        qe = np.where(np.isfinite(qe), qe, 0.0)  # (2.2) divides by g: at g = 0 start from zero
        # an angle beyond 2^26 rad is known to no better than 2^-26 = 1.5e-8 rad (the spacing
        # of doubles there), more than an equilibrium's residual allows (RESIDUAL_TOL): (2.2)
        # at the pole gives 1.6e16; such a start is taken within one turn
        qe = np.where(is_angle & (np.abs(qe) > 2.0**26), wrap(qe), qe)
    else:
        qe = np.zeros((n, len(names)))
    if model.meta.get("constraints", {}).get("multipliers"):
        qe = on_constraints(model, P, qe, is_angle)
    starts = qe.copy()
    qe, ok, report = _solve(model, P, qe, idx, is_angle, tol, max_iter)
    report["degenerate"] = np.zeros(n, bool)
    if model.meta.get("constraints", {}).get("multipliers") and not ok.all():
        for k in np.flatnonzero(~ok & np.all(np.isfinite(P), axis=1)):
            q = augmented_statics(model, P[k], starts[k])
            if q is not None:
                qe[k], ok[k] = q, True
                report["q"][k] = q
    if model.meta.get("constraints", {}).get("multipliers") and ok.any():
        k = np.flatnonzero(ok)
        bad = degenerate_independent(model, P[k], qe[k])
        ok[k[bad]] = False
        report["degenerate"][k[bad]] = True
    resid = function(model, "equilibrium_residual")
    steady = [model.meta["reduced"].index(c) for c in model.meta.get("steady", {})]
    if steady and ok.any():  # a steady coordinate's row: no unknown enters it, it must hold itself
        k = np.flatnonzero(ok)
        with np.errstate(all="ignore"):
            r = resid(P[k], qe[k])[0].reshape(k.size, -1)[:, steady]
        ok[k] = np.max(np.abs(r), axis=1) <= 1e-9 * (1 + np.max(np.abs(P[k]), axis=1))
    qe = np.where(is_angle, wrap(qe), qe)
    qe[~ok] = np.nan
    return qe, ok, report


# starts of the dependent coordinates of a model with multipliers, in their units (angles
# in rad): the first from which the constraints are solved is taken
DEPENDENT_STARTS = (1.0, 0.5, -1.0, 2.0, -0.5, 0.1)


def on_constraints(model: Model, P, q0, is_angle, max_iter: int = 50, starts=(None, *DEPENDENT_STARTS)):
    """The starts of a model with multipliers moved onto its constraints: the independent
    coordinates as they are, the dependent ones solved from phi(q) = 0 by Newton's method on
    the emitted constraints and their Jacobian (quantity `constraints`), from the start as
    given (the model's `equilibrium_approx`: which branch of the constraints it means), then
    from each of DEPENDENT_STARTS in turn (a start of zero puts a pendulum in Cartesian
    coordinates at its pivot, where the constraint's Jacobian vanishes). The first start whose iteration meets
    the constraints to 1e-12 of the coordinates' size answers a set; a set none does keeps
    its start (the equilibrium's own Newton then tries, and its residual test decides).
    `starts` (None: the start as given) the dependent coordinates' starts tried: a motion's
    start and its projections take (None,) alone, the branch they are on
    (gyro.analyses.motion.Constraints)."""
    meta = model.meta
    names = list(meta["equilibrium_coordinates"])
    dep = [names.index(c) for c in meta["constraints"]["dependent"]]
    fn = function(model, "constraints")
    q0 = np.array(q0, float)
    todo = np.arange(P.shape[0])
    for start in starts:  # None: the model's own start (equilibrium_approx) first
        if todo.size == 0:
            break
        q = q0[todo].copy()
        if start is not None:
            q[:, dep] = start
        for _ in range(max_iter):
            with np.errstate(all="ignore"):
                phi, J = fn(P[todo], q)
                phi = np.asarray(phi).reshape(todo.size, -1)
                J = np.asarray(J).reshape(todo.size, len(dep), -1)[:, :, dep]
                step = np.array([_solve_or_lstsq(j, f) if np.all(np.isfinite(j)) and np.all(np.isfinite(f))
                                 else np.full(len(dep), np.nan) for j, f in zip(J, phi)])
            step = np.clip(step, -1.0, 1.0) if is_angle[dep].all() else step
            q[:, dep] -= step
            if not np.all(np.isfinite(q)) or np.max(np.abs(step)) <= 1e-15 * max(1.0, np.max(np.abs(q))):
                break
        with np.errstate(all="ignore"):
            phi = np.asarray(fn(P[todo], q)[0]).reshape(todo.size, -1)
        met = np.all(np.isfinite(q), axis=1) & (np.max(np.abs(phi), axis=1) <= 1e-12 * np.maximum(
            1.0, np.max(np.abs(q), axis=1)))
        q0[todo[met]] = q[met]
        todo = todo[~met]
    return q0


def augmented_statics(model: Model, p, q0):
    """For one set of a model with multipliers whose Newton in the independent coordinates
    failed: the equilibrium from the statics of all coordinates and the multipliers,
    f(q, 0) = Phi_q(q)' lambda and phi(q) = 0 (the first n rows of the emitted forcing at
    rest, the emitted constraints), by scipy's hybrid method from q0 with lambda from least
    squares. It needs no choice of independent coordinates, so it finds an equilibrium
    where the chosen ones do not parametrise the motion (degenerate_independent then says
    so). Returns q, or None where it finds none to 1e-10 of the forces' size."""
    from scipy.optimize import root

    n = len(model.meta["coordinates"])
    forcing, cons = function(model, "forcing"), function(model, "constraints")
    specs = model.meta["functions"]["forcing"]["inputs"][3:]
    extra = [np.zeros((1, len(sp["symbols"]))) for sp in specs]
    P = np.asarray(p, float)[None, :]

    def f0(q):
        return np.asarray(forcing(P, q[None, :], np.zeros((1, n)), *extra)[0]).reshape(-1)[:n]

    def F(x):
        q, lam = x[:n], x[n:]
        phi, J = cons(P, q[None, :])
        J = np.asarray(J).reshape(-1, n)
        return np.concatenate([f0(q) - J.T @ lam, np.asarray(phi).reshape(-1)])

    is_angle = _layout(model)[2]
    with np.errstate(all="ignore"):
        scale = max(float(np.max(np.abs(f0(q0)))), 1.0)
        for shift in (0.0,) + RESTARTS:  # q0 first, then moved as the Newton's restarts are
            q1 = _moved_start(q0[None, :], is_angle, shift)[0] if shift else q0
            J0 = np.asarray(cons(P, q1[None, :])[1]).reshape(-1, n)
            lam0 = (np.linalg.lstsq(J0.T, f0(q1), rcond=None)[0] if np.all(np.isfinite(J0))
                    else np.zeros(J0.shape[0]))
            sol = root(F, np.concatenate([q1, lam0]), method="hybr")
            if sol.success and np.all(np.isfinite(sol.x)) and np.max(np.abs(F(sol.x))) <= 1e-10 * scale:
                return sol.x[:n]
    return None


def degenerate_independent(model: Model, P, qe) -> np.ndarray:
    """Per set of a model with multipliers: True where its constraints cannot be solved for
    the dependent coordinates at the equilibrium (the smallest singular value of their
    block of the constraints' Jacobian below 1e-8 of the whole Jacobian's largest: C then
    carries entries beyond 1e8 and the reduced operator, C' Mq C, loses every digit): the
    independent coordinates `reduced` names do not parametrise the motion there (a pendulum
    in Cartesian coordinates hanging along q1 with q1 independent), and the operator in them
    would be infinite."""
    names = list(model.meta["equilibrium_coordinates"])
    dep = [names.index(c) for c in model.meta["constraints"]["dependent"]]
    with np.errstate(all="ignore"):
        J = np.asarray(function(model, "constraints")(P, qe)[1]).reshape(P.shape[0], len(dep), -1)
        out = np.ones(P.shape[0], bool)
        fin = np.all(np.isfinite(J), axis=(1, 2))
        if fin.any():
            small = np.linalg.svd(J[fin][:, :, dep], compute_uv=False)[:, -1]
            whole = np.linalg.svd(J[fin], compute_uv=False)[:, 0]
            out[fin] = ~(small > 1e-8 * whole)
    return out


def _solve(model: Model, P, q0, idx, is_angle, tol, max_iter):
    """Newton from the starts q0, every answer checked (residual_test), and the sets where
    Newton came to rest without balancing the equations tried again from other starts
    (RESTARTS). Returns (qe, ok, report): qe as Newton left it (NaN where an iterate was not
    finite), ok where it is an equilibrium, report (residual_test's ratio, row and value,
    the point, and whether other starts were tried) of the first try of each set."""
    qe, converged = _newton(model, P, q0.copy(), idx, is_angle, tol, max_iter)
    finite = np.all(np.isfinite(qe), axis=1)
    ratio, row, value = residual_test(model, P, qe, idx)
    balanced = ratio <= RESIDUAL_TOL
    # not converged in max_iter: an exact equilibrium that Newton circles, accepted by its
    # residual as before (absolute, as it always was) and by the residual test
    ok = finite & balanced & converged
    late = np.flatnonzero(~converged & finite & balanced)
    if late.size:
        with np.errstate(all="ignore"):
            r = _rows(model, idx)(P[late], qe[late])
        ok[late] = np.max(np.abs(r), axis=1, initial=0.0) <= 1e-9 * (1 + np.max(np.abs(P[late]), axis=1))
    report = {"ratio": ratio, "row": row, "value": value, "q": qe.copy(), "restarted": converged & ~balanced}
    # Newton that could not start: it "converged" (a zero least-squares step along the null
    # direction of a singular K) where the equations do not hold; again from other starts
    stuck = converged & finite & ~balanced
    # or could not start at all: the equations are not defined at the start (a spring on a
    # pathway of zero length there, k q x0/sqrt(q^2) at q = 0: 0/0)
    lost = np.flatnonzero(~finite & np.all(np.isfinite(P), axis=1))
    if lost.size:
        with np.errstate(all="ignore"):
            r0 = _rows(model, idx)(P[lost], q0[lost])
        stuck[lost[~np.all(np.isfinite(r0), axis=1)]] = True
    stuck = np.flatnonzero(stuck & np.all(np.isfinite(P), axis=1))
    for shift in RESTARTS:
        if stuck.size == 0:
            break
        start = _moved_start(q0[stuck], is_angle, shift)
        q, conv = _newton(model, P[stuck], start, idx, is_angle, tol, max_iter)
        good = conv & np.all(np.isfinite(q), axis=1)
        good &= residual_test(model, P[stuck], q, idx)[0] <= RESIDUAL_TOL
        take = stuck[good]
        qe[take], ok[take] = q[good], True
        stuck = stuck[~good]
    return qe, ok, report


# A residual below RESIDUAL_TOL of the size of the terms that make it up is an equilibrium
# found to rounding: at the answer of Newton's iteration (steps below TOL = 1e-14 of the
# coordinates) the residual is the rounding of evaluating it, a few hundred operations each
# erring by at most u = 1.1e-16 of the terms it combines (~1e-13 of them), plus K dq, at most
# TOL |K| |q| (~1e-14 of them). 1e-8 is five orders above that, and a point whose equations
# miss by more than 1e-8 of their own terms is no equilibrium that rounding explains (the
# cubic spring at x = 0 misses by all of its terms, ratio 1).
RESIDUAL_TOL = 1e-8
SUBNORMAL_FLOOR = 1e3 * np.finfo(float).tiny  # 2.2e-305: rows below it are zero (residual_test)
# starts tried where Newton could not start: the first start moved by these fractions of
# its own coordinates, or by these amounts in the coordinate's units where it is zero
# (angles by at most 1 rad), each with alternating signs over the coordinates, then the
# opposite signs; the first start that ends on an equilibrium answers
RESTARTS = (1e-3, -1e-3, 1e-1, -1e-1, 1.0, -1.0, 10.0, -10.0)


def _moved_start(q0, is_angle, shift):
    sign = np.where(np.arange(q0.shape[1]) % 2 == 0, 1.0, -1.0)
    step = np.where(q0 != 0, np.abs(q0) * shift, shift) * sign
    step = np.where(is_angle, np.clip(step, -1.0, 1.0), step)
    return q0 + step


def residual_test(model: Model, P, qe, idx):
    """Per set: (max_i |r_i| / T_i, the row i of that maximum, r_i), r the residual of the
    equilibrium equations at qe and T_i the size of the terms row i combines, measured as
    sum_j |p_j dr_i/dp_j| + sum_j |K_ij| |q_j| (angles wrapped): each term of r_i that carries p_j (or q_j)
    to the power d contributes d times itself to p_j dr_i/dp_j, so T_i is at least the
    largest term unless terms of the same degree in every parameter and every coordinate
    cancel. p dr/dp by a forward difference with the relative step 2^-20 (its rounding
    about 1e-10 of T, its truncation about 1e-6: it is a scale, not a derivative). A row
    whose terms are all zero (T_i = 0) has r_i = 0 exactly or no equilibrium: its ratio is
    0 or inf. NaN coordinates: ratio inf."""
    n, npar = P.shape
    if n == 0 or len(idx) == 0:
        return np.zeros(n), np.zeros(n, int), np.zeros(n)
    with np.errstate(all="ignore"):
        r, K = _system(model, idx)(P, qe)
        # an angle's size within one turn: an iterate can leave Newton unwrapped
        size = np.abs(np.where(_layout(model)[2], wrap(qe), qe))
        T = np.einsum("bij,bj->bi", np.abs(K), size)
        # the coordinates' part alone passes most sets (a regular K: r = K dq, dq below TOL
        # |q|); the parameters' part, n_p more evaluations, only where it does not
        late = np.flatnonzero(~np.all(np.abs(r) <= RESIDUAL_TOL * T, axis=1))
        if late.size:
            rows, h, m = _rows(model, idx), 2.0**-20, late.size
            Pl = P[late]
            Pall = np.concatenate([Pl * np.where(np.arange(npar) == j, 1 + h, 1.0) for j in range(npar)])
            rall = rows(Pall, np.tile(qe[late], (npar, 1))).reshape(npar, m, -1)
            T[late] += np.sum(np.abs(rall - r[late]), axis=0) / h
        # below the smallest normal double a residual has no relative precision left (a
        # latitude of 2.2e-308 deg leaves rows of 1e-323 beside terms of 1e-318): such a
        # residual is zero to double precision's range, whatever its ratio
        ratio = np.where(np.abs(r) <= SUBNORMAL_FLOOR, 0.0, np.abs(r) / T)
    ratio = np.where(np.isfinite(ratio), ratio, np.inf)
    row = np.argmax(ratio, axis=1)
    k = np.arange(n)
    return ratio[k, row], row, r[k, row]


def _newton(model: Model, P, qe, idx, is_angle, tol, max_iter):
    """The Newton iteration from the starts qe: the generated C set by set where there is a
    compiler, answering the sets it converges on; each set it hands back (an entry of r or K
    not below 1e150, a zero pivot, a step or an iterate not finite, no convergence in
    max_iter steps: where the outcome hangs on the rounding of the solve, or the NumPy
    iteration does otherwise) answered by _newton_numpy from its start; _newton_numpy alone
    without a compiler. Returns (qe, converged): qe NaN where an iterate was not finite."""
    kernel = compiled(cbackend.equilibrium_newton, model)
    if kernel is None:
        return _newton_numpy(model, P, qe.copy(), idx, is_angle, tol, max_iter)
    out, status = kernel(P, qe, tol, max_iter, MAX_ANGLE_STEP)
    converged = status == kernel.CONVERGED
    back = np.flatnonzero(~converged)
    if back.size:
        out[back], converged[back] = _newton_numpy(model, P[back], qe[back], idx, is_angle, tol, max_iter)
    return out, converged


def _newton_numpy(model: Model, P, qe, idx, is_angle, tol, max_iter):
    """The Newton iteration vectorised over the batch, qe (the starts) iterated in place:
    a set whose r or K is not below 1e150 takes a NaN step (it fails), and a set whose K is
    singular takes least squares (its step, and so its answer, is the one it gets alone,
    whatever batch it is in); converged when every
    |dq_i| <= tol max(largest |qe_j| of i's group (_groups), 1e-300) + 1e-300. Returns
    (qe, converged)."""
    n = P.shape[0]
    system = _system(model, idx)
    same = _groups(model)
    active = np.ones(n, bool)
    converged = np.zeros(n, bool)
    for _ in range(max_iter):
        a = np.flatnonzero(active)
        if a.size == 0:
            break
        with np.errstate(all="ignore"):
            r, K = system(P[a], qe[a])
            ok_in = tame(K) & np.all(np.abs(r) < 1e150, axis=1)
            K = np.where(ok_in[:, None, None], K, np.eye(len(idx)))
            r = np.where(ok_in[:, None], r, np.nan)
            # r(q + dq) = r(q) - K dq  (r = dR/dq, K = -d2R/dq2)
            try:
                dq = np.linalg.solve(K, r[..., None])[..., 0]
            except np.linalg.LinAlgError:  # a singular K somewhere: set by set, least squares where singular
                dq = np.array([_solve_or_lstsq(k, v) if t else v for k, v, t in zip(K, r, ok_in)])
        big = np.max(np.abs(np.where(is_angle, dq, 0.0)), axis=1, initial=0.0)
        dq *= np.minimum(1.0, MAX_ANGLE_STEP / np.maximum(big, 1e-300))[:, None]
        qe[a] += dq
        bad = ~np.all(np.isfinite(qe[a]), axis=1)
        scale = np.max(np.where(same, np.abs(qe[a])[:, None, :], 0.0), axis=2, initial=0.0)  # the group's largest
        conv = np.all(np.abs(dq) <= tol * np.maximum(scale, 1e-300) + 1e-300, axis=1)
        converged[a[conv & ~bad]] = True
        active[a[conv | bad]] = False
        qe[a[bad]] = np.nan
    return qe, converged


def _solve_or_lstsq(K, r):
    """K^-1 r, as the batched solve gives it (LAPACK's gesv on this K alone), or least squares
    where K is singular: a set's step is the same whatever batch it is in."""
    try:
        return np.linalg.solve(K, r)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(K, r, rcond=None)[0]


def _rows(model: Model, idx):
    """(P, qe) -> the residual rows of the Newton system, (sets, len(idx))."""
    if model.meta.get("constraints", {}).get("multipliers"):
        system = _system(model, idx)
        return lambda P, qe: system(P, qe)[0]
    resid = function(model, "equilibrium_residual")
    return lambda P, qe: resid(P, qe)[0].reshape(P.shape[0], -1)[:, idx]


def _system(model: Model, idx):
    """(P, qe) -> (r, K) of the Newton step over the equilibrium coordinates: the model's
    equilibrium_system; for a model generated before it existed, the residual's rows idx and
    the operator's K restricted to them (the same values, the whole operator evaluated)."""
    if "equilibrium_system" in model.meta["functions"]:
        fn = function(model, "equilibrium_system")
        ne = len(idx)
        return lambda P, qe: tuple(np.asarray(x).reshape(P.shape[0], *s)
                                   for x, s in zip(fn(P, qe), ((ne,), (ne, ne))))
    resid, oper = function(model, "equilibrium_residual"), function(model, "operator")
    return lambda P, qe: (resid(P, qe)[0].reshape(P.shape[0], -1)[:, idx],
                          oper(P, qe)[2][:, idx][:, :, idx])


def equilibrium(model: Model, params) -> np.ndarray:
    """The relative equilibrium of one parameter set (metadata 'equilibrium_coordinates'),
    or EquilibriumError."""
    qe, ok, report = equilibria_reported(model, np.asarray(params, dtype=float)[None, :])
    if not ok[0]:
        raise EquilibriumError(why_not(model, report))
    return qe[0]


def unbalanced(model: Model, params) -> str | None:
    """For one parameter set: why_not's line where the set has no equilibrium because the
    equations keep a residual at a finite point (not for inputs beyond double precision,
    whose iterates are not finite: a numerical failure), else None."""
    qe, ok, report = equilibria_reported(model, np.asarray(params, dtype=float)[None, :])
    if ok[0] or not np.all(np.isfinite(report["q"][0])) or not report["ratio"][0] > RESIDUAL_TOL:
        return None
    return why_not(model, report)


def why_not(model: Model, report, k: int = 0) -> str:
    """One line on why set k of a batch has no equilibrium: the equation that does not hold
    at the last point tried, and by how much of the size of its terms."""
    names = model.meta["equilibrium_coordinates"]
    ratio, row, value, q, restarted = (report[key][k] for key in ("ratio", "row", "value", "q", "restarted"))
    if report.get("degenerate") is not None and report["degenerate"][k]:
        c = model.meta["constraints"]
        at = ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, q))
        return (f"none in the independent coordinates {', '.join(c['independent'])}: at the equilibrium of all "
                f"coordinates ({at}) the constraints cannot be solved for the dependent ones "
                f"{', '.join(c['dependent'])} (their Jacobian is singular there), so {', '.join(c['independent'])} "
                "do not parametrise the motion about it; name others in the model's `reduced`")
    rows = (list(model.meta["reduced"]) + [f"constraint {j + 1}" for j in range(len(
        model.meta["constraints"]["holonomic"]))]) if model.meta.get("constraints", {}).get("multipliers") else names
    if not np.all(np.isfinite(q)) or not names:
        return "Newton's method did not converge (an iterate was not finite)"
    at = ", ".join(f"{c} = {v:.6g}" for c, v in zip(names, q))
    if ratio <= RESIDUAL_TOL:
        return f"Newton's method did not converge (last at {at})"
    where = ("Newton's method came to rest where" if restarted else "Newton's method did not converge:")
    return (f"{where} the equation of {rows[row]} keeps a residual of {value:.3g} at {at}, {ratio:.2g} of the "
            f"size of its terms (an equilibrium leaves below {RESIDUAL_TOL:g})"
            + (", and so it did from every other start tried" if restarted else ""))


def operators(model: Model, P: np.ndarray, qe: np.ndarray):
    """M, D, K of a batch at its equilibria."""
    require_time_free(model)
    with np.errstate(all="ignore"):
        return function(model, "operator")(P, qe)
