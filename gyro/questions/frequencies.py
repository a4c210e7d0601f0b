"""`frequencies`: the natural frequencies of the linearised motion, ascending (rad/s); one
quantity per mode rank, omega1 the slowest. A bound on quantity j promises that the j-th
smallest frequency of the exact operator lies within bound * omega_j of the answer.

Evaluator kinds: `spectrum` (a method of the ladder on the exact operator, {"method": NAME}),
`charpoly` (the roots in z = p^2 of an emitted function's block characteristic
polynomials, {"function": NAME, "set": {PARAMETER: VALUE}} with parameters overridden, as
u = 0 for decoupled blocks). Edge of the question: where the intervals omega_j (1 +- b_j)
of two neighbouring requested modes touch (veering, a merged root), the rank of a mode is
not decided by the bound, so the bound is not a promise there.
"""
from __future__ import annotations

import numpy as np

from gyro.kernels import chunks
from gyro.questions import Answer, unknown_kind

EPS = np.finfo(float).eps

NAME = "frequencies"
VALUES = "frequencies"  # the JSON key of the per-quantity answer (the scene table shows it)
OPTIONS = {"modes": ("I,J,...", "frequencies: only these modes (1 = the slowest)")}


def options(model, P, tol: float, given: dict, initial: dict) -> dict:
    """--modes I,J,... as a list of mode numbers (1 = the slowest), or None for all."""
    text = given.get("modes")
    if text is None:
        return {"modes": None}
    try:
        modes = [int(t) for t in text.split(",")]
    except ValueError:
        from gyro.errors import ParameterError

        raise ParameterError(f"--modes {text!r}: expected mode numbers I,J,... (1 = the slowest)") from None
    return {"modes": modes}


def quantities(model, opts) -> list[str]:
    return [f"omega{j + 1}" for j in range(len(model.meta["reduced"]))]


def requested(model, opts) -> list[int]:
    n = len(model.meta["reduced"])
    modes = opts.get("modes")
    if not modes:
        return list(range(n))
    from gyro.errors import ParameterError

    bad = [m for m in modes if not 1 <= m <= n]
    if bad:
        raise ParameterError(f"--modes: {bad[0]} is not a mode of {model.name} (1..{n})")
    return sorted({m - 1 for m in modes})


def _ascending(f, e, g):
    """The answer in the question's order, ascending by frequency (NaN last; ties, as the
    real roots of a divergent set, in the spectrum's order): a spectrum comes ranked by
    |lambda|, which puts a divergent pair (frequency 0) above a slow oscillation."""
    with np.errstate(invalid="ignore"):
        if f.shape[1] < 2 or np.all(f[:, 1:] >= f[:, :-1]):  # sorted already (NaN compares false)
            return f, e, g
    order = np.argsort(np.where(np.isnan(f), np.inf, f), axis=1, kind="stable")
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    return take(f), take(e), take(g)


def _spectrum(model, level, P):
    from gyro import ladder

    spec = ladder.spectrum(model, P, level.evaluator["method"])
    f, e, g = _ascending(spec.frequencies, spec.error_estimate, spec.growth)
    failed = np.full(f.shape[0], "", object)
    failed[~np.all(np.isfinite(f), axis=1)] = "a frequency could not be computed"
    return Answer(f, e, failed, {"growth": g})


def _poly_roots(c: np.ndarray, model=None):
    """Roots of polynomials with coefficients c (sets, degree + 1), lowest first, over the
    batch (gyro.roots: each with a proven inclusion radius for the coefficients as given),
    and each root's relative error estimate: that radius plus the first-order sensitivity
    of the root to a rounding of eps per coefficient (inf where no radius is proven: a
    merged root, a cluster)."""
    from gyro.roots import roots

    z, radius, sensitivity, _ = roots(c, model)
    return z, radius + sensitivity


def _overridden(model, P, values: dict) -> np.ndarray:
    P = P.copy()
    for name, value in values.items():
        P[:, model.param_names.index(name)] = value
    return P


def _block_roots(model, spec: dict, P):
    """Roots in z = p^2 of the blocks of an emitted function (spec "function"; only block
    spec["block"], counted from 1, if given) at the parameters overridden by spec "set",
    with the exact zero roots there removed (a mode that the limit takes to zero is not
    answered); and each root's relative error estimate: its rounding, and, with spec
    "shift" = {"parameter": NAME, "function": D}, twice the first-order shift of z to the
    parameter's actual value, |dz/z| with dz = -(actual - set) D(z)/c'(z), D the emitted
    d/dNAME of the coefficients (the relative shift of a frequency is half that of its z);
    with "correct": true in the shift, the roots are moved by dz and the estimate of the
    second-order remainder is the first-order shift itself, |dz/z|/2.
    Without "block", the zero roots stay, as exact zeros with an infinite estimate.
    -> (z, the relative error estimate of each root's frequency), each (sets, roots)."""
    from gyro.kernels import function

    Ps = _overridden(model, P, spec.get("set", {}))
    N = P.shape[0]
    blocks = [np.reshape(b, (N, -1)) for b in function(model, spec["function"])(Ps)]
    pick = [spec["block"] - 1] if "block" in spec else range(len(blocks))
    shift = spec.get("shift")
    dblocks = None
    if shift:
        dblocks = [np.reshape(b, (N, -1)) for b in function(model, shift["function"])(Ps)]
        ip = model.param_names.index(shift["parameter"])
        delta = P[:, ip] - Ps[:, ip]
    zs, es = [], []
    for i in pick:
        c = blocks[i]
        zero = np.all(c == 0, axis=0)  # coefficients zero in every set: exact zero roots
        k0 = int(np.argmin(zero)) if not zero.all() else c.shape[1]
        z, est = _poly_roots(c[:, k0:], model)
        est = est / 2  # a frequency's relative error is half that of its z
        z = np.concatenate([np.zeros((N, k0), complex), z], axis=1) if "block" not in spec else z
        est = np.concatenate([np.full((N, k0), np.inf), est], axis=1) if "block" not in spec else est
        if shift:
            with np.errstate(all="ignore"):
                k = np.arange(c.shape[1])
                dc = (c[:, 1:] * k[1:])
                zz = z[..., None]
                der = np.sum(dc[:, None, :] * zz ** k[None, None, :-1], axis=2)
                dF = np.sum(dblocks[i][:, None, :] * zz ** k[None, None, :], axis=2)
                dz = -delta[:, None] * dF / der
                if shift.get("correct"):  # the roots moved by it; what remains is of second order
                    z = z + dz
                    est = est + np.abs(dz / z) / 2
                else:
                    est = est + np.abs(dz / z)
        zs.append(z)
        es.append(est)
    return np.concatenate(zs, axis=1), np.concatenate(es, axis=1)


def _frequency(z):
    p = np.sqrt(z)
    p = np.where(p.imag < 0, -p, p)
    return np.abs(p.imag), p.real


def _charpoly(model, level, P):
    z, est = _block_roots(model, level.evaluator, P)
    freq, growth = _frequency(z)
    # an exact zero root (a free direction, as the neutral azimuth at u = 0) has no
    # relative error to give
    est = np.where(z == 0, np.inf, est)
    f, e, g = _ascending(freq, est, growth)
    e = np.where(np.isfinite(e) & (e < 0.5), e, np.inf)
    failed = np.full(f.shape[0], "", object)
    failed[~np.all(np.isfinite(f), axis=1)] = "a root could not be computed"
    return Answer(f, e, failed, {"growth": g})


def _formulas(model, level, P):
    """The model's mode formulas (metadata 'mode_formulas', per mode the candidate with the
    smallest estimate), the modes named in the evaluator's "roots" {"modes": [...], and a
    `_block_roots` spec} replaced by that block's roots: as the paper's nutation formulas
    (3.26) by the roots of the quartic (3.10) they approximate. "apriori" names an emitted
    formula (metadata 'formulas') added to the roots' estimates: the bound of the operator
    the block comes from, which the other modes' formulas, measured against the exact
    operator, do not carry. A block without one nonzero root per replaced mode is refused."""
    from gyro.methods.formulas import per_mode

    f, e = per_mode(model, P)
    spec = level.evaluator.get("roots")
    failed = np.full(f.shape[0], "", object)
    if spec:
        rows = [[m["mode"] for m in model.meta["mode_formulas"]].index(x) for x in spec["modes"]]
        z, est = _block_roots(model, spec, P)
        if z.shape[1] != len(rows):
            raise ValueError(f"level {level.name}: its block has {z.shape[1]} nonzero roots for "
                             f"{len(rows)} replaced modes")
        freq, _ = _frequency(z)
        if "apriori" in spec:  # the bound of the model the roots come from, for them alone
            from gyro.kernels import function

            names = [x["name"] for x in model.meta["formulas"]]
            with np.errstate(all="ignore"):
                (values,) = function(model, "formulas")(P)
            est = est + np.abs(np.reshape(values, (P.shape[0], -1))[:, [names.index(spec["apriori"])]])
        f[:, rows] = freq
        e[:, rows] = np.where(np.isfinite(est) & (est < 0.5), est, np.inf)
    f, e, _ = _ascending(f, e, np.zeros(f.shape))
    failed[~np.all(np.isfinite(f), axis=1)] = "a frequency could not be computed"
    return Answer(f, e, failed, {})


EVALUATORS = {"spectrum": _spectrum, "charpoly": _charpoly, "formulas": _formulas}


def answer(model, level, P, opts) -> Answer:
    kind = level.evaluator.get("kind")
    if kind not in EVALUATORS:
        raise unknown_kind(NAME, level)
    ans = EVALUATORS[kind](model, level, P)
    if level.evaluator.get("certify"):  # each requested rank is proven by the counts: another mode's
        idx = requested(model, opts)  # missing value leaves the requested ones answered
        ans.failed[np.all(np.isfinite(ans.values[:, idx]), axis=1)] = ""
    return ans


def edges(model, ans: Answer, bound: np.ndarray, idx, answered) -> np.ndarray:
    """'' per set, or the reason the bound is no promise there: two neighbouring modes (in
    rank, among all of them; answers are ascending in frequency, `_ascending`) whose
    intervals omega (1 +- bound) touch; or a mode the level answers (`answered`) without a
    finite bound, whose place among the others is then unknown, so that no rank is decided.
    A mode the level declares unanswered keeps its rank by the declaration (the neutral
    azimuth at u = 0, below every other mode)."""
    f = ans.values
    out = np.full(f.shape[0], "", object)
    answered = np.asarray(answered, bool)
    with np.errstate(invalid="ignore"):
        lo, hi = f * (1 - bound), f * (1 + bound)
        touch = hi[:, :-1] >= lo[:, 1:]  # rank j and j + 1
    want = np.zeros(f.shape[1], bool)
    want[list(idx)] = True
    relevant = want[:-1] | want[1:]
    touch &= relevant[None, :] & np.isfinite(bound[:, :-1]) & np.isfinite(bound[:, 1:])
    _say(out, touch, lambda j: f"modes {j + 1} and {j + 2} within their bounds of each other (veering or a merged root)")
    if want.any():
        lost = ~np.isfinite(bound) & answered[None, :]
        lost &= ~touch.any(axis=1)[:, None]
        _say(out, lost, lambda j: f"mode {j + 1} without a bound: its place among the others, and so every rank, is not decided")
    return out


def _say(out: np.ndarray, flags: np.ndarray, text) -> None:
    """out[k] = text(j) for each set k with a flag, j its first flagged column (the texts
    made once per column, not per set: a million sets may cross an edge)."""
    rows = np.flatnonzero(flags.any(axis=1))
    if rows.size:
        j = np.argmax(flags[rows], axis=1)
        out[rows] = np.array([text(i) for i in range(flags.shape[1])], dtype=object)[j]


# s per set on one core, on the scale of the methods' COST (linear_exact:default 3.6e-5 s): a
# count (the compiled inertia, counts_at) and the rest of a certificate beside its counts (the
# equilibrium, the operator, the count at 0, the bookkeeping), measured in one run of
# `python -m bench.levels --random-speed 100000` (levels.json random_speed.certificate.declare)
# (the rest includes the operator's own rounding: two probes of the operator, 2.5 -> 4.9 us a
# set; since the enclosure (gyro.rounding: Krawczyk's radius of the equilibrium in C and the
# operator enclosed over it, its twin's value the operator counted), 6.4 us of the exact
# answer's 15.5 us in that run)
COUNT_COST = 1.19e-6
OPERATOR_COST = 1.50e-5
# Where the certified levels, tried before the exact operator, answered faster than it alone
# by more than MARGIN in that run (random_speed.modes_1e-3): CERTIFIED_MODES the most modes
# 1..k so requested, CERTIFIED_ALONE the modes so requested alone (each set trying the levels
# in turn, a certificate for each). Elsewhere a level's proof costs its advantage:
# certificate_cost is infinite, and the exact operator, the cheaper proven answer, is tried
# first (the cheap levels retired there). MARGIN: the shared machine moves one run against
# another by 10-20 % (two runs of the same code: modes 1..2 certified 21.1 us against 20.4,
# then 16.4 against 17.4), so an advantage below it is no advantage.
# With the enclosed rounding (gyro.rounding), in the run declared above: modes 1..1 9.0 us
# and 1..2 11.0 us against 14.8 us for the exact operator, 1..3 20.9 us; alone, modes 5 (14.5
# us), 9 (14.9) and 10 (14.3) are not faster by MARGIN.
MARGIN = 1.1
CERTIFIED_MODES = 2
CERTIFIED_ALONE = (1, 2, 3, 4, 6, 7, 8)


def certificate_cost(level, idx) -> float:
    """The certificate's seconds per set for the requested modes idx (0-based; 0 for a
    level that declares none): the rest of it and three counts for one mode, two more per
    mode; infinite for one mode outside CERTIFIED_ALONE and for more than CERTIFIED_MODES
    modes (retired: measured no faster than the exact operator; modes 1..1 is mode 1 alone,
    so CERTIFIED_MODES >= 1 only with 1 in CERTIFIED_ALONE)."""
    if not level.evaluator.get("certify"):
        return 0.0
    if (idx[0] + 1 not in CERTIFIED_ALONE) if len(idx) == 1 else len(idx) > CERTIFIED_MODES:
        return float("inf")
    return OPERATOR_COST + COUNT_COST * (1 + 2 * len(idx))


def counts_below(M, D, K, w, moves=None) -> np.ndarray:
    """Per set, the number of the exact operator's frequencies below w, proven, or -1 where
    the count cannot be proven in double precision.

    For a conservative gyroscopic operator (M > 0, K > 0 symmetric, D skew) the roots are
    lambda = +-i omega and Q(w) = J(i w) = K - w^2 M + i w D is Hermitian. Each eigenvalue
    mu(w) of Q vanishes where w is a frequency, and there dmu/dw = x* Q'(w) x / x* x =
    (-2 w x*Mx + i x*Dx)/|x|^2 = -(w x*Mx + x*Kx / w)/|x|^2 < 0 (x*Q(w)x = 0 gives
    i x*Dx = (w^2 x*Mx - x*Kx)/w): every crossing of zero is from + to -, and Q(0) = K > 0
    has none negative. So the number of negative eigenvalues of Q(w) is the number of
    frequencies in (0, w), multiplicities counted. The eigenvalues are LAPACK's of the
    diagonally scaled S Q S (Sylvester: the same inertia): backward stable, each within
    8 n eps ||SQS||_F of an eigenvalue of the matrix as formed, whose entries are within 64
    eps of their magnitude |K| + w^2 |M| + w |D| of the operator's (its forming and the
    evaluation of the operator); a count is proven where no eigenvalue is within the sum
    of the two of zero (Weyl). With `moves` (dM, dD, dK: the operator's own rounding,
    enclosed by gyro.rounding.operator_rounding) the exact operator's matrix is within
    |dK| + w^2 |dM| + w |dD| of the one formed, and its scaled Frobenius norm joins the sum."""
    n = M.shape[-1]
    w = np.asarray(w, dtype=float)[:, None, None]
    with np.errstate(all="ignore"):
        s = 1 / np.sqrt(np.abs(np.einsum("bii->bi", K)) + w[:, :, 0] ** 2 * np.einsum("bii->bi", M))
        S = s[:, :, None] * s[:, None, :]
        Q = (K - w**2 * M + 1j * w * D) * S
        mag = (np.abs(K) + w**2 * np.abs(M) + w * np.abs(D)) * S
        good = np.all(np.isfinite(Q), axis=(1, 2)) & np.all(np.isfinite(mag), axis=(1, 2))
        Q[~good] = np.eye(n)
        mu = np.linalg.eigvalsh(Q)
        margin = (8 * n * EPS * np.sqrt(np.sum(Q.real**2 + Q.imag**2, axis=(1, 2)))
                  + 64 * EPS * np.sqrt(np.sum(mag**2, axis=(1, 2))))
        if moves is not None:
            dM, dD, dK = moves
            op = (dK + w**2 * dM + w * dD) * S
            margin = margin + np.sqrt(np.sum(op**2, axis=(1, 2)))
            good &= np.isfinite(margin)
        proven = good & (np.min(np.abs(mu), axis=1) > margin)
    return np.where(proven, np.sum(mu < 0, axis=1), -1)


NOT_GYROSCOPIC = -2  # counts_at: M or K not symmetric, or D not skew, to the bit (no count)


def counts_at(M, D, K, W, rows=None, moves=None) -> np.ndarray:
    """counts_below at the points W (sets, points) of each set: the compiled twin
    (gyro/questions/inertia.c: Bunch-Kaufman's LDL^H of the same scaled matrix, its inertia
    that of the blocks, proven by the factorization's backward error against the smallest
    block over ||L^-1||_F^2; in real arithmetic where a 2-colouring of the coordinates makes
    the matrix real) where a compiler is at hand, else LAPACK's eigenvalues in NumPy.
    `rows` (sets,): set k's operator is M[rows[k]] (no copies of a shared batch's); None:
    M[k]. `moves` (dM, dD, dK, laid out as M): the operator's own rounding, which the proof
    then carries (counts_below). -> (sets, points), -1 where not proven, NOT_GYROSCOPIC for
    every point of a set whose operator is not conservative gyroscopic (bearing damping)."""
    from gyro import cbackend
    from gyro.qep import gyroscopic

    N, Pn = W.shape
    try:
        fn = _inertia_kernel()
    except cbackend.CompilerUnavailable:
        if rows is not None:
            M, D, K = M[rows], D[rows], K[rows]
            moves = None if moves is None else tuple(X[rows] for X in moves)
        c = np.empty(W.shape, int)
        for s in chunks(N, max(1, 8192 // max(Pn, 1))):  # bounded memory: a matrix per count
            rep = lambda X: np.repeat(X[s], Pn, axis=0)  # noqa: E731
            mv = None if moves is None else tuple(rep(X) for X in moves)
            c[s] = counts_below(rep(M), rep(D), rep(K), W[s].reshape(-1), mv).reshape(-1, Pn)
        c[~gyroscopic(M, D, K)] = NOT_GYROSCOPIC
        return c
    import ctypes

    arrs = [np.ascontiguousarray(X, dtype=float) for X in (M, D, K)]
    mv = None if moves is None else [np.ascontiguousarray(X, dtype=float) for X in moves]
    w = np.ascontiguousarray(W, dtype=float)
    index = None if rows is None else np.ascontiguousarray(rows, dtype=np.int64)
    out = np.empty(W.shape)
    ptr = ctypes.POINTER(ctypes.c_double)
    fn(ctypes.c_long(N), ctypes.c_long(M.shape[-1]), ctypes.c_long(Pn), *[a.ctypes.data_as(ptr) for a in arrs],
       *([None] * 3 if mv is None else [a.ctypes.data_as(ptr) for a in mv]),
       None if index is None else index.ctypes.data_as(ctypes.POINTER(ctypes.c_long)),
       w.ctypes.data_as(ptr), out.ctypes.data_as(ptr))
    c = out.astype(int)
    # the factorization's bound is the weaker near a frequency (1.4 % of the points at a
    # relative 1e-7 from one, where LAPACK's eigenvalues prove all): those again in NumPy
    k, p = np.nonzero((c == -1) & np.isfinite(W) & (W >= 0))
    if k.size:
        r = k if rows is None else np.asarray(rows)[k]
        c[k, p] = counts_below(M[r], D[r], K[r], W[k, p], None if moves is None else tuple(X[r] for X in moves))
    return c


def _inertia_kernel():
    """The compiled count (gyro/questions/inertia.c, built once per machine as a model's C
    is); CompilerUnavailable where there is none, or within cbackend.disabled()."""
    from pathlib import Path

    from gyro import cbackend

    cbackend._available()
    fn = cbackend._library(str(Path(__file__).parent), "inertia").gyro_inertia_counts
    fn.restype = None
    return fn


class Exact:
    """Per set of a batch, what a certificate needs of the exact model whatever the level:
    the equilibrium, the operator M, D, K there, and the count at 0 (K positive definite),
    made once per set for every certified level the set tries (the selector's batch:
    `certificate_data`; a level's sets are `take(rows)`), and kept where made: a later
    level's counts read them by row (counts_at's `rows`), not copied."""

    def __init__(self, model, P, rows=None, store=None):
        self.model, self.P = model, P
        self.rows = np.arange(P.shape[0]) if rows is None else np.asarray(rows)
        self.store = {"where": np.full(P.shape[0], -1)} if store is None else store

    def take(self, rows) -> "Exact":
        return Exact(self.model, self.P, self.rows[rows], self.store)

    KEYS = ("M", "D", "K", "dM", "dD", "dK", "zero")

    def get(self):
        """(ok (sets,): an equilibrium found; M, D, K; at (ok sets,): the row of M, D, K of
        each such set; zero (ok sets,): its count at 0; moves: (dM, dD, dK), the operator's
        own rounding, laid out as M) for this view's sets."""
        st = self.store
        todo = np.unique(self.rows[st["where"][self.rows] == -1])
        if todo.size:
            ok, *made = _exact(self.model, self.P[todo])
            if "M" not in st:  # the first: kept as made
                base = 0
                st.update(zip(self.KEYS, made))
            else:  # sets a cheaper level did not try (beyond its edges): appended
                base = st["M"].shape[0]
                for key, v in zip(self.KEYS, made):
                    st[key] = np.concatenate([st[key], v])
            st["where"][todo] = -2  # tried: no equilibrium
            st["where"][todo[ok]] = base + np.arange(int(ok.sum()))
        where = st["where"][self.rows]
        ok = where >= 0
        at = where[ok]
        if "M" not in st:  # no set asked yet
            n = len(self.model.meta["reduced"])
            empty = np.zeros((0, n, n))
            return ok, empty, empty, empty, at, at, (empty, empty, empty)
        return ok, st["M"], st["D"], st["K"], at, st["zero"][at], (st["dM"], st["dD"], st["dK"])


def _exact(model, P):
    """(ok, M, D, K of the sets with an equilibrium, their operator's own rounding dM, dD, dK
    (gyro.rounding.operator_enclosed: the operator as the enclosure's CasADi twin evaluates
    it and an enclosure of its distance from the exact operator at the exact equilibrium, the
    equilibrium's own error included), their counts at 0) over the batch P."""
    from gyro import rounding
    from gyro.equilibrium import equilibria

    qe, ok = equilibria(model, P)
    n = len(model.meta["reduced"])
    if not ok.any():
        empty = np.zeros((0, n, n))
        return ok, empty, empty, empty, empty, empty, empty, np.zeros(0, int)
    every = bool(ok.all())  # no copies of the batch where every set has its equilibrium
    Pk, qk = (P, qe) if every else (P[ok], qe[ok])
    # the operator as the enclosure's twin evaluates it, with its distance from the exact one
    M, D, K, *moves = rounding.operator_enclosed(model, Pk, qk)
    zero = counts_at(M, D, K, np.zeros((M.shape[0], 1)), moves=moves)[:, 0]
    return (ok, M, D, K, *moves, zero)


def certificate_data(model, P) -> Exact:
    """What the certificates of the levels a batch tries share (the selector's batch)."""
    return Exact(model, P)


def certify(model, level, P, ans: Answer, bound: np.ndarray, idx, data: Exact | None = None) -> np.ndarray:
    """'' per set where every requested mode j is proven to be the exact operator's j-th
    frequency within its bound b (|f - omega_j| <= b omega_j: omega_j in [f/(1+b),
    f/(1-b)]), the reason otherwise: counts_below at both ends of the interval prove that
    omega_j lies in it (at most j - 1 frequencies below its lower end, at least j below its
    upper one), which proves its value and its rank together, with the count at 0 (K
    positive definite). Where the count cannot be evaluated (no equilibrium, bearing
    damping, K not positive definite, a count not resolved in double precision, b >= 1),
    the set is not answered by the level. `data`: the exact operators of these sets (Exact,
    shared with the other levels they try), made here where not given."""
    N = P.shape[0]
    out = np.full(N, "", object)
    ok, M, D, K, at, zero, moves = (data if data is not None else Exact(model, P)).get()
    out[~ok] = "certificate: no equilibrium to count the exact operator's frequencies at"
    live = np.flatnonzero(ok)
    if live.size == 0:
        return out
    every = live.size == N
    f = ans.values if every else ans.values[live]
    b = bound if every else bound[live]
    W = np.zeros((live.size, 2 * len(idx)))
    with np.errstate(all="ignore"):
        for i, j in enumerate(idx):
            informative = np.isfinite(b[:, j]) & (b[:, j] < 1) & np.isfinite(f[:, j]) & (f[:, j] > 0)
            W[:, 2 * i] = np.where(informative, f[:, j] / (1 + b[:, j]), -1.0)
            W[:, 2 * i + 1] = np.where(informative, f[:, j] / (1 - b[:, j]), -1.0)
    c = counts_at(M, D, K, W, at, moves)  # the operator's own rounding carried by the proof
    c[W < 0] = -1
    reason = np.full(live.size, "", object)
    reason[zero == NOT_GYROSCOPIC] = "certificate: the operator is not conservative gyroscopic (damping): no count"
    reason[(zero != 0) & (reason == "")] = "certificate: K not proven positive definite (no count of the frequencies)"
    for i, j in enumerate(idx):
        lo, hi = c[:, 2 * i], c[:, 2 * i + 1]
        unproven = (lo < 0) | (hi < 0)
        wrong = ~unproven & ((lo > j) | (hi < j + 1))
        todo = reason == ""
        reason[todo & unproven] = (f"certificate: mode {j + 1}'s interval not resolved by a count in double "
                                   "precision (or its bound >= 1)")
        reason[todo & wrong] = (f"certificate: the exact omega{j + 1} is not within the bound of this "
                                "answer (a count of the exact operator's frequencies)")
    out[live] = reason
    return out


def error(ans: Answer, ref: Answer) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.abs(ans.values - ref.values) / np.abs(ref.values)


def document(model, ans: Answer, k: int, idx) -> dict:
    return {"frequencies": [float(ans.values[k, j]) for j in idx]}
