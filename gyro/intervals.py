"""Interval evaluation of a CasADi SX Function over boxes: compiled (gyro/csrc/intervals.c,
the same operations with the same roundings, one interpreter for every Function) where
there is a compiler, vectorised in NumPy otherwise.

`evaluate(fun, inputs)` walks the Function's algorithm (`Function.instructions`: each
instruction's operation, its work-vector inputs and output, its constant) once, with every
register an interval (lo, hi) of NumPy arrays over N boxes at once: each operation's natural
interval extension, rounded outward, so that for every point of the input boxes the Function's
exact value (the real-number value of its algorithm) lies in the output intervals.

Outward rounding. The basic operations (+, -, *, /, sqrt) are correctly rounded in IEEE
arithmetic: the exact result is within half an ulp of the computed one, and one `np.nextafter`
step down (lo) and up (hi) covers it, subnormals and underflow to 0 included. The library's
transcendental functions (sin, cos, exp, log, atan, ...) are not correctly rounded: glibc
documents at most 1-2 ulps for double on x86_64, NumPy's SIMD routines at most 4; their
results are widened by TRANSCENDENTAL_ULPS (8) ulps relative and one nextafter step, twice
the largest documented error. Transcendentals are enclosed by monotonicity (exp, log, sqrt,
atan, tanh, ...) or by the extrema they pass (sin, cos: +-1 where the interval holds pi/2 +
k pi).

Never a silent finite answer: a division by an interval that holds 0, a logarithm or square
root of an interval reaching below 0, an operation without an extension here (a comparison,
a branch, a call): the result is [-inf, inf]; inf - inf, 0 * inf and the like give NaN, which
propagates (np.minimum, np.maximum propagate it) and comes out as [-inf, inf].

The walker is general: `Program` is the instruction list of any SX Function, run by
`Program.run` with an arithmetic (here intervals); another arithmetic (a running rounding
error) is another set of operations over the same loop.
"""
from __future__ import annotations

import numpy as np

TRANSCENDENTAL_ULPS = 8
EPS = np.finfo(float).eps
INF = np.inf


# ------------------------------------------------------------------ rounding outward

TINY = 2.0**-1074  # the smallest subnormal: the spacing of the numbers below 2^-1022


def down(x, ulps: int = 0):
    """A number below every real z whose rounding is x, z within `ulps` ulps of x (0: x is a
    correctly rounded result, within half an ulp): x - max(|x| (ulps + 2) eps, TINY). For a
    normal x, the exact x - 2 eps |x| is at least 1.5 ulp(x) below z and its rounding moves
    it by at most half an ulp; below 2^-1022 the spacing is TINY and sums are exact there.
    (max, not a sum: arithmetic on the subnormal TINY is slow on x86.)"""
    return x - np.maximum(np.abs(x) * ((ulps + 2) * EPS), TINY)


def up(x, ulps: int = 0):
    return x + np.maximum(np.abs(x) * ((ulps + 2) * EPS), TINY)


# ------------------------------------------------------------------ the operations

def _add(a, b):
    return down(a[0] + b[0]), up(a[1] + b[1])


def _sub(a, b):
    return down(a[0] - b[1]), up(a[1] - b[0])


def _neg(a):
    return -a[1], -a[0]


def _twice(a):
    return 2.0 * a[0], 2.0 * a[1]  # exact (overflow to inf is an upper bound)


def _mul(a, b):
    if np.all(a[0] >= 0) and np.all(b[0] >= 0):  # both nonnegative in every box: the ends' products
        return down(a[0] * b[0]), up(a[1] * b[1])
    p1, p2, p3, p4 = a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1]
    lo = np.minimum(np.minimum(p1, p2), np.minimum(p3, p4))
    hi = np.maximum(np.maximum(p1, p2), np.maximum(p3, p4))
    return down(lo), up(hi)


def _div(a, b):
    with np.errstate(divide="ignore", invalid="ignore"):
        q1, q2, q3, q4 = a[0] / b[0], a[0] / b[1], a[1] / b[0], a[1] / b[1]
    lo = np.minimum(np.minimum(q1, q2), np.minimum(q3, q4))
    hi = np.maximum(np.maximum(q1, q2), np.maximum(q3, q4))
    zero = (b[0] <= 0) & (b[1] >= 0)  # the divisor holds 0: no enclosure
    return np.where(zero, -INF, down(lo)), np.where(zero, INF, up(hi))


def _inv(a):
    return _div((1.0, 1.0), a)


def _sq(a):
    l2, h2 = a[0] * a[0], a[1] * a[1]
    straddle = (a[0] < 0) & (a[1] > 0)
    lo = np.where(straddle, 0.0, np.minimum(l2, h2))
    return np.maximum(down(lo), 0.0), up(np.maximum(l2, h2))


def _fabs(a):
    la, ha = np.abs(a[0]), np.abs(a[1])
    straddle = (a[0] < 0) & (a[1] > 0)
    return np.where(straddle, 0.0 * la, np.minimum(la, ha)), np.maximum(la, ha)  # exact; NaN stays NaN


def _monotone(f, lo_domain=-INF, open_domain=False, ulps=TRANSCENDENTAL_ULPS):
    """An increasing function on [lo_domain, inf) (open at lo_domain if `open_domain`):
    [f(lo), f(hi)] rounded outward; [-inf, inf] where the interval reaches outside."""
    def op(a):
        with np.errstate(all="ignore"):
            lo, hi = f(a[0]), f(a[1])
        outside = (a[0] <= lo_domain) if open_domain else (a[0] < lo_domain)
        return np.where(outside, -INF, down(lo, ulps)), np.where(outside, INF, up(hi, ulps))
    return op


def _sqrt(a):
    with np.errstate(invalid="ignore"):
        lo, hi = np.sqrt(a[0]), np.sqrt(a[1])
    outside = a[0] < 0
    return np.where(outside, -INF, np.maximum(down(lo), 0.0)), np.where(outside, INF, up(hi))


def _sin(a, shift=0.0):
    """sin over [lo, hi] (cos with shift pi/2: cos x = sin(x + pi/2), the shift applied to
    the extrema's positions only, never to the argument): the ends' values, and +-1 where
    the interval may hold pi/2 + 2k pi (-pi/2 + 2k pi); the test is loosened by SLACK (a
    loose test only adds an extremum, always an enclosure)."""
    lo, hi = a
    f = np.cos if shift else np.sin
    with np.errstate(all="ignore"):
        vl, vh = f(lo), f(hi)
        vmin, vmax = np.minimum(vl, vh), np.maximum(vl, vh)
        slack = 1e-12 * (1.0 + np.abs(lo) + np.abs(hi))

        def holds(c):  # an extremum at c + 2 k pi in [lo - slack, hi + slack]
            k = np.ceil((lo - slack - c) / (2 * np.pi))
            return c + 2 * np.pi * k <= hi + slack

        top = holds(np.pi / 2 - shift)
        bottom = holds(-np.pi / 2 - shift)
    wide = ~(hi - lo < np.pi) | ~(np.abs(lo) < 1e9) | ~(np.abs(hi) < 1e9)  # NaN, inf, or too wide/far: [-1, 1]
    rlo = np.where(bottom | wide, -1.0, np.maximum(down(vmin, TRANSCENDENTAL_ULPS), -1.0))
    rhi = np.where(top | wide, 1.0, np.minimum(up(vmax, TRANSCENDENTAL_ULPS), 1.0))
    nan = np.isnan(lo) | np.isnan(hi)
    return np.where(nan, np.nan, rlo), np.where(nan, np.nan, rhi)


def _cos(a):
    return _sin(a, shift=np.pi / 2)


def _tan(a):
    lo, hi = a
    with np.errstate(all="ignore"):
        k = np.ceil((lo - 1e-12 * (1 + np.abs(lo)) - np.pi / 2) / np.pi)
        pole = np.pi / 2 + np.pi * k <= hi + 1e-12 * (1 + np.abs(hi))
        vl, vh = np.tan(lo), np.tan(hi)
    bad = pole | ~(np.abs(lo) < 1e9) | ~(np.abs(hi) < 1e9)
    return np.where(bad, -INF, down(vl, TRANSCENDENTAL_ULPS)), np.where(bad, INF, up(vh, TRANSCENDENTAL_ULPS))


def _cosh(a):
    m = _fabs(a)
    with np.errstate(over="ignore"):
        return np.maximum(down(np.cosh(m[0]), TRANSCENDENTAL_ULPS), 1.0), up(np.cosh(m[1]), TRANSCENDENTAL_ULPS)


def _pow_int(a, n: int):
    """a^n for an integer n: by the parity of n (negative n: 1 / a^|n|)."""
    if n == 0:
        return 1.0 + 0.0 * a[0], 1.0 + 0.0 * a[1]
    if n < 0:
        return _inv(_pow_int(a, -n))
    r = None
    base = a
    m = n
    while m:  # binary powering: every product an interval product (a^2 by _sq, never below 0)
        if m & 1:
            r = base if r is None else _mul(r, base)
        m >>= 1
        if m:
            base = _sq(base)
    if n % 2 == 0:  # even: never below 0, and 0 where a straddles it
        straddle = (a[0] < 0) & (a[1] > 0)
        return np.where(straddle, 0.0, np.maximum(r[0], 0.0)), r[1]
    return r


def _pow(a, b):
    """a^b: for a constant integer b by parity; else exp(b log a) for a > 0."""
    bl, bh = b
    if np.ndim(bl) == 0 and bl == bh and float(bl).is_integer() and abs(bl) < 64:
        return _pow_int(a, int(bl))
    return _exp(_mul(b, _log(a)))


def _fmin(a, b):
    return np.minimum(a[0], b[0]), np.minimum(a[1], b[1])


def _fmax(a, b):
    return np.maximum(a[0], b[0]), np.maximum(a[1], b[1])


def _entire(*args):
    """No enclosure here: [-inf, inf] (NaN where an input is NaN: it comes out as [-inf, inf])."""
    shape = np.broadcast(*[x for a in args for x in a]).shape if args else ()
    return np.full(shape, -INF), np.full(shape, INF)


_exp = _monotone(np.exp)
_log = _monotone(np.log, 0.0, open_domain=True)


def _ops():
    import casadi as ca

    table = {
        "OP_ADD": _add, "OP_SUB": _sub, "OP_MUL": _mul, "OP_DIV": _div, "OP_NEG": _neg, "OP_TWICE": _twice,
        "OP_INV": _inv, "OP_SQ": _sq, "OP_SQRT": _sqrt, "OP_FABS": _fabs, "OP_SIN": _sin, "OP_COS": _cos,
        "OP_TAN": _tan, "OP_EXP": _exp, "OP_LOG": _log, "OP_POW": _pow, "OP_CONSTPOW": _pow,
        "OP_ATAN": _monotone(np.arctan), "OP_TANH": _monotone(np.tanh), "OP_SINH": _monotone(np.sinh),
        "OP_ASINH": _monotone(np.arcsinh), "OP_COSH": _cosh, "OP_FMIN": _fmin, "OP_FMAX": _fmax,
        "OP_ERF": _monotone(__import__("scipy.special", fromlist=["erf"]).erf),
    }
    return {getattr(ca, k): f for k, f in table.items() if hasattr(ca, k)}


_OPS: dict = {}
CHUNK = 8192  # boxes evaluated at once (each register holds two arrays of this length)
_PROGRAMS: dict = {}


def instructions(fun) -> list:
    """A CasADi SX Function's algorithm in its evaluation order: (op, output registers, input
    registers, constant) per instruction. Read once here for every walker of it: this
    module's interval arithmetic and gyro.rounding's running error bound."""
    return [(fun.instruction_id(k), fun.instruction_output(k), fun.instruction_input(k), fun.instruction_constant(k))
            for k in range(fun.n_instructions())]


class Program:
    """The instruction list of a CasADi SX Function: (op, output register, input registers,
    constant) per instruction, and the Function's input and output shapes (nonzeros)."""

    def __init__(self, fun):
        import casadi as ca

        if not _OPS:
            _OPS.update(_ops())
        self.fun = fun
        self.n_in = [fun.nnz_in(i) for i in range(fun.n_in())]
        self.n_out = [fun.nnz_out(i) for i in range(fun.n_out())]
        self.numel_out = [fun.numel_out(i) for i in range(fun.n_out())]
        self.where_out = [np.asarray(fun.sparsity_out(i).find(), int) for i in range(fun.n_out())]  # column-major
        self.size_w = fun.sz_w()
        self.code = instructions(fun)
        self.INPUT, self.OUTPUT, self.CONST = ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST
        self.bytecode = None  # the compiled walker's arrays (`_bytecode`), built on first use

    def run(self, inputs, ops, const, entire):
        """The walk: `inputs` per Function input a sequence of its nonzeros' values (any
        arithmetic's), `ops` the operations by op code, `const(value)` a constant's value,
        `entire(*args)` the result of an operation `ops` does not have. Returns per output
        a list of its nonzeros' values (None where structurally zero)."""
        w = [None] * self.size_w
        outs = [[None] * n for n in self.n_out]
        for op, o, i, c in self.code:
            if op == self.INPUT:
                w[o[0]] = inputs[i[0]][i[1]]
            elif op == self.OUTPUT:
                outs[o[0]][o[1]] = w[i[0]]
            elif op == self.CONST:
                w[o[0]] = const(c)
            else:
                f = ops.get(op)
                args = [w[j] for j in i]
                if f is not None:
                    w[o[0]] = f(*args)
                else:  # no extension here: every output of the instruction (a call may have several)
                    for j in o:
                        w[j] = entire(*args)
        return outs


# The compiled walker (gyro/csrc/intervals.c): its operation codes, in the order of its enum.
C_OPS = ("INPUT", "OUTPUT", "CONST", "ADD", "SUB", "MUL", "DIV", "NEG", "TWICE", "INV", "SQ", "SQRT", "FABS",
         "SIN", "COS", "TAN", "EXP", "LOG", "POWI", "POW", "ATAN", "TANH", "SINH", "ASINH", "COSH", "FMIN",
         "FMAX", "ERF", "ENTIRE")
_C_CODE = {name: k for k, name in enumerate(C_OPS)}


def _bytecode(prog: Program):
    """The Program as the arrays of gyro/csrc/intervals.c (op, out, in0, in1, constant): the
    CasADi operation by name (OP_CONSTPOW and OP_POW by a constant integer exponent below 64
    in magnitude, known from the register's last OP_CONST, as `_pow` decides: IV_POWI with n in
    in1; else exp(b log a)); an operation without a C extension: IV_ENTIRE on each output."""
    import casadi as ca

    names = {getattr(ca, n): n[3:] for n in dir(ca) if n.startswith("OP_")}
    rows, const = [], {}
    for op, o, i, c in prog.code:
        name = names.get(op, "")
        if op == prog.INPUT:
            rows.append((_C_CODE["INPUT"], o[0], i[0], i[1], 0.0))
        elif op == prog.OUTPUT:
            rows.append((_C_CODE["OUTPUT"], o[0], i[0], int(prog.where_out[o[0]][o[1]]), 0.0))
        elif op == prog.CONST:
            rows.append((_C_CODE["CONST"], o[0], 0, 0, float(c)))
        elif name in ("POW", "CONSTPOW"):
            e = const.get(i[1])
            if e is not None and float(e).is_integer() and abs(e) < 64:
                rows.append((_C_CODE["POWI"], o[0], i[0], int(e), 0.0))
            else:
                rows.append((_C_CODE["POW"], o[0], i[0], i[1], 0.0))
        elif name in _C_CODE and name not in ("INPUT", "OUTPUT", "CONST", "POWI", "ENTIRE") and op in _OPS:
            rows.append((_C_CODE[name], o[0], i[0], i[1] if len(i) > 1 else i[0], 0.0))
        else:
            rows.extend((_C_CODE["ENTIRE"], j, 0, 0, 0.0) for j in o)
        for j in o if op != prog.OUTPUT else ():  # a register's constant while it holds one
            const.pop(j, None)
        if op == prog.CONST:
            const[o[0]] = float(c)
    ints = np.array([r[:4] for r in rows], dtype=np.intc).reshape(-1, 4)
    return (np.ascontiguousarray(ints[:, 0]), np.ascontiguousarray(ints[:, 1]), np.ascontiguousarray(ints[:, 2]),
            np.ascontiguousarray(ints[:, 3]), np.array([r[4] for r in rows], float))


def _kernel():
    """The compiled walker's entry point, or None (no compiler, or within
    gyro.cbackend.disabled(): the NumPy walker answers)."""
    from gyro import cbackend

    try:
        lib = cbackend.kernel_library("intervals")
    except cbackend.CompilerUnavailable:
        return None
    fn = lib.gyro_intervals_run
    fn.restype = None
    return fn


def compiled() -> bool:
    """Whether `evaluate` runs the compiled walker here (a compiler, and not within
    gyro.cbackend.disabled()): callers choose their forms by the cost (tighter forms with more
    instructions where each costs about a nanosecond per box, not a dozen NumPy calls)."""
    return _kernel() is not None


def _run_c(fn, prog: Program, ins, width: int):
    """The Program over `width` boxes by the compiled walker: `ins` per input (lo, hi) arrays
    (nnz, width); per output (lo, hi) (numel, width) as `evaluate`'s."""
    import ctypes

    if prog.bytecode is None:
        prog.bytecode = _bytecode(prog)
    op, out, in0, in1, cst = prog.bytecode
    lo_in = [np.ascontiguousarray(np.broadcast_to(np.asarray(lo, float).reshape(n, -1), (n, width)))
             for (lo, _), n in zip(ins, prog.n_in)]
    hi_in = [np.ascontiguousarray(np.broadcast_to(np.asarray(hi, float).reshape(n, -1), (n, width)))
             for (_, hi), n in zip(ins, prog.n_in)]
    outs = [(np.zeros((numel, width)), np.zeros((numel, width))) for numel in prog.numel_out]
    w = np.empty((2, max(prog.size_w, 1) * C_CHUNK))
    V = ctypes.c_void_p
    arr = lambda xs: (V * max(len(xs), 1))(*[x.ctypes.data for x in xs])  # noqa: E731
    fn(ctypes.c_long(width), ctypes.c_long(len(op)), *[V(a.ctypes.data) for a in (op, out, in0, in1, cst)],
       ctypes.c_long(prog.size_w), ctypes.c_int(TRANSCENDENTAL_ULPS), arr(lo_in), arr(hi_in),
       arr([o[0] for o in outs]), arr([o[1] for o in outs]), V(w[0].ctypes.data), V(w[1].ctypes.data))
    return outs


C_CHUNK = 64  # gyro/csrc/intervals.c's CH: the boxes one pass of the instructions takes


def program(fun) -> Program:
    """The Program of an SX Function, built once per Function object."""
    key = id(fun)
    if key not in _PROGRAMS or _PROGRAMS[key].fun is not fun:
        _PROGRAMS[key] = Program(fun)
    return _PROGRAMS[key]


def evaluate(fun, inputs, compiled: bool = True):
    """Interval values of `fun` over boxes: `inputs` per Function input a pair (lo, hi) of
    arrays (nnz,) or (nnz, N) (N boxes; a point is lo = hi). Returns per output a pair (lo,
    hi) of arrays (numel, N) (or (numel,) where no input has N; the output dense,
    column-major, its structural zeros 0): for every point of the boxes,
    the Function's exact value lies in [lo, hi]; [-inf, inf] where it is not enclosed.
    By the compiled walker (gyro/csrc/intervals.c, the same operations in C) where there is a
    compiler and `compiled`; else by NumPy."""
    prog = program(fun)
    width = max((np.shape(x)[1] for b in inputs for x in b if np.ndim(x) == 2), default=0)
    if width > CHUNK:  # the work vector's registers for all boxes at once would not fit: in pieces
        parts = [evaluate(fun, [tuple(x[:, k:k + CHUNK] if np.ndim(x) == 2 else x for x in b) for b in inputs], compiled)
                 for k in range(0, width, CHUNK)]
        return [(np.concatenate([p[i][0] for p in parts], axis=1), np.concatenate([p[i][1] for p in parts], axis=1))
                for i in range(len(parts[0]))]
    ins = []
    for (lo, hi), n in zip(inputs, prog.n_in):
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        if lo.shape[0] != n or hi.shape != lo.shape:
            raise ValueError(f"an input of {fun.name()} has {n} nonzeros, got boxes of shape {lo.shape}, {hi.shape}")
        if np.any(~(lo <= hi)):
            raise ValueError(f"an input box of {fun.name()} is empty or NaN (lo > hi)")
        ins.append([(lo[k], hi[k]) for k in range(n)])
    shape = np.broadcast(*[np.asarray(x)[0] for b in inputs for x in b if np.size(x)]).shape
    fn = _kernel() if compiled else None
    if fn is not None:
        outs = _run_c(fn, prog, inputs, shape[0] if shape else 1)
        return outs if shape else [(lo[:, 0], hi[:, 0]) for lo, hi in outs]
    with np.errstate(over="ignore", invalid="ignore"):
        outs = prog.run(ins, _OPS, lambda c: (c, c), _entire)
    result = []
    for out, numel, where in zip(outs, prog.numel_out, prog.where_out):
        lo, hi = np.zeros((numel, *shape)), np.zeros((numel, *shape))  # structural zeros: exactly 0
        for k, v in zip(where, out):
            if v is not None:
                lo[k], hi[k] = v
        bad = np.isnan(lo) | np.isnan(hi)
        result.append((np.where(bad, -INF, lo), np.where(bad, INF, hi)))
    return result


def centred(fun, jac, which: int, inputs, natural: bool = True):
    """The mean-value form over the boxes, intersected with the natural extension: f(X) in
    f(c) + J(X) (X - c), c the boxes' centres in input `which` (the others as given), J(X)
    the interval Jacobian of every output in that input (`jac`, a Function of the same
    inputs giving d out_k / d in_which for each output k, dense, (nnz_out_k, nnz_which)
    nonzeros column-major). Tight to the square of the boxes' widths where the natural
    extension is to their width (cancellations: residuals, differences of near-equal
    terms). `natural` False: the mean-value form alone (the caller has the natural
    extension already). Returns per output a pair (lo, hi) as `evaluate`."""
    lo, hi = (np.asarray(x, float) for x in inputs[which])
    c = lo + (hi - lo) / 2  # a point inside the box (rounded: any point inside will do)
    c = np.minimum(np.maximum(c, lo), hi)
    at_c = evaluate(fun, [(c, c) if k == which else x for k, x in enumerate(inputs)])
    natural = evaluate(fun, inputs) if natural else [(-INF, INF)] * len(at_c)
    J = evaluate(jac, inputs)
    d = (down(lo - c), up(hi - c))  # X - c, rounded outward (lo - c <= 0 <= hi - c)
    d = (np.minimum(d[0], 0.0), np.maximum(d[1], 0.0))
    n = lo.shape[0]
    out = []
    for (flo, fhi), (nlo, nhi), (jlo, jhi) in zip(at_c, natural, J):
        m = flo.shape[0]
        jl = jlo.reshape(n, m, *jlo.shape[1:]).swapaxes(0, 1)  # (m, n, ...): column-major nonzeros
        jh = jhi.reshape(n, m, *jhi.shape[1:]).swapaxes(0, 1)
        slo, shi = flo, fhi
        for k in range(n):
            t = _mul((jl[:, k], jh[:, k]), (d[0][k], d[1][k]))
            slo, shi = _add((slo, shi), t)
        out.append((np.maximum(slo, nlo), np.minimum(shi, nhi)))
    return out


def taylor2(fun, jac, hess, which: int, inputs):
    """The second-order Taylor form over the boxes: f(X) in f(c) + J(c) (X - c) + (X - c)^T
    H(X) (X - c) / 2 (Taylor's theorem with the Lagrange remainder, H at a point of the segment
    from c, inside the box), c the boxes' centres in input `which`; f(c) and J(c) enclosed at
    the point c (narrow: no excess of the box's width), H(X) the interval Hessian (`hess`:
    `jacobian_function(jac, which)`, per output (nnz_out * nnz_which, nnz_which) nonzeros
    column-major). Where J itself is a difference of near-equal terms (the Jacobian of a
    residual), J(X) of the centred form is wide by those terms times the width, and this
    form's excess is of the square of the width times the second derivatives only. Returns
    per output a pair (lo, hi) as `evaluate`."""
    lo, hi = (np.asarray(x, float) for x in inputs[which])
    c = np.minimum(np.maximum(lo + (hi - lo) / 2, lo), hi)
    at_c = [x if k != which else (c, c) for k, x in enumerate(inputs)]
    F, J, H = evaluate(fun, at_c), evaluate(jac, at_c), evaluate(hess, inputs)
    d = (np.minimum(down(lo - c), 0.0), np.maximum(up(hi - c), 0.0))
    n = lo.shape[0]
    out = []
    for (flo, fhi), (jlo, jhi), (hlo, hhi) in zip(F, J, H):
        m = flo.shape[0]
        jl = jlo.reshape(n, m, *jlo.shape[1:]).swapaxes(0, 1)
        jh = jhi.reshape(n, m, *jhi.shape[1:]).swapaxes(0, 1)
        hl = hlo.reshape(n, n, m, *hlo.shape[1:])  # (l, k, i): d2 f_i / dx_k dx_l, column-major nonzeros
        hh = hhi.reshape(n, n, m, *hhi.shape[1:])
        slo, shi = flo, fhi
        for k in range(n):
            slo, shi = _add((slo, shi), _mul((jl[:, k], jh[:, k]), (d[0][k], d[1][k])))
        q = None
        for k in range(n):
            for l in range(n):
                dd = _sq((d[0][k], d[1][k])) if k == l else _mul((d[0][k], d[1][k]), (d[0][l], d[1][l]))
                t = _mul((hl[l, k], hh[l, k]), dd)
                q = t if q is None else _add(q, t)
        slo, shi = _add((slo, shi), _mul(q, (0.5, 0.5)))  # (rounded outward: a subnormal's half is not exact)
        out.append((slo, shi))
    return out


def jacobian_function(fun, which: int):
    """The Function of the same inputs giving, for each output, its dense Jacobian in input
    `which` (the `centred` form's J)."""
    import casadi as ca

    ins = [ca.SX.sym(fun.name_in(i), fun.sparsity_in(i)) for i in range(fun.n_in())]
    outs = fun(*ins)
    outs = outs if isinstance(outs, (list, tuple)) else [outs]
    jacs = [ca.densify(ca.jacobian(ca.densify(ca.vec(o)), ins[which])) for o in outs]
    return ca.Function(fun.name() + "_jac", ins, jacs, {"cse": True})


# ------------------------------------------------------------------ interval matrices
#
# Boxes of small matrices (n, k, k) or (n, a, b), as pairs (lo, hi), and upper bounds of
# their eigenvalues and norms that hold for every matrix in the box.

def mag(x):
    """The largest |value| of each interval: an upper bound, exact."""
    return np.maximum(np.abs(x[0]), np.abs(x[1]))


def _det2(B):
    return _sub(_mul(B(0, 0), B(1, 1)), _mul(B(0, 1), B(1, 0)))


def _det3(B):
    t1 = _mul(B(0, 0), _sub(_mul(B(1, 1), B(2, 2)), _mul(B(1, 2), B(2, 1))))
    t2 = _mul(B(0, 1), _sub(_mul(B(1, 0), B(2, 2)), _mul(B(1, 2), B(2, 0))))
    t3 = _mul(B(0, 2), _sub(_mul(B(1, 0), B(2, 1)), _mul(B(1, 1), B(2, 0))))
    return _add(_sub(t1, t2), t3)


def definite_below(lo, hi, t):
    """True where t I - A is positive definite for every A in the box [lo, hi] (n, k, k),
    k <= 3, A symmetric: every leading principal minor's interval (over the box, a_ij and
    a_ji taken apart: a superset) above 0 (Sylvester's criterion)."""
    k = lo.shape[-1]
    eye = np.eye(k)
    Blo = t[:, None, None] * eye - hi
    Bhi = t[:, None, None] * eye - lo
    Blo, Bhi = down(Blo), up(Bhi)  # t I - A rounded outward

    def B(i, j):
        return Blo[:, i, j], Bhi[:, i, j]

    ok = B(0, 0)[0] > 0
    if k >= 2:
        ok &= _det2(B)[0] > 0
    if k >= 3:
        ok &= _det3(B)[0] > 0
    if k > 3:
        raise ValueError("definite_below: matrices up to 3 x 3")
    return ok


def lambda_max_upper(lo, hi):
    """An upper bound of the largest eigenvalue of every symmetric matrix in the box [lo, hi]
    (n, k, k), k <= 3: Weyl's, lambda_max(mid) + ||rad||_F (rad the box's half widths,
    ||rad||_2 <= ||rad||_F), lambda_max(mid) the eigensolver's plus a margin for its
    rounding, verified by `definite_below` on the point mid; where that check fails,
    Gershgorin's (a_ii + sum |a_ij|, always an upper bound); the smaller of the two where
    both hold. inf where the box is not finite."""
    finite = np.all(np.isfinite(lo) & np.isfinite(hi), axis=(-2, -1))
    lo = np.where(finite[:, None, None], lo, 0.0)
    hi = np.where(finite[:, None, None], hi, 0.0)
    mid = (lo + hi) / 2
    mid = (mid + np.swapaxes(mid, -1, -2)) / 2
    rad = up(np.maximum(up(mid - lo), up(hi - mid)))
    fro = up(np.sqrt(up(np.sum(rad * rad, axis=(-2, -1)) * (1 + 4 * rad.shape[-1] ** 2 * EPS))))
    scale = np.sqrt(np.sum(mid * mid, axis=(-2, -1)))
    t_mid = up(np.linalg.eigvalsh(mid)[:, -1] + 1e-12 * scale) + 1e-300
    ok = definite_below(mid, mid, t_mid)
    k = lo.shape[-1]
    off = np.sum(np.maximum(np.abs(lo), np.abs(hi)), axis=-1) - np.maximum(np.abs(np.diagonal(lo, 0, -2, -1)),
                                                                           np.abs(np.diagonal(hi, 0, -2, -1)))
    gersh = up(np.max(up(np.diagonal(hi, 0, -2, -1) + up(off * (1 + 4 * k * EPS))), axis=-1))
    out = np.where(ok, np.minimum(up(t_mid + fro), gersh), gersh)
    return np.where(finite, out, INF)


def lambda_min_lower(lo, hi):
    """A lower bound of the smallest eigenvalue of every symmetric matrix in the box."""
    return -lambda_max_upper(-hi, -lo)


def norm2_upper(M):
    """An upper bound of ||A||_2 for every A with |A| <= M entrywise (M >= 0, (n, a, b)):
    ||A||_2 <= || |A| ||_2 <= ||M||_2 (monotone for nonnegative matrices), and ||M||_2^2 the
    largest eigenvalue of M^T M, enclosed (its products rounded outward). inf where M is not finite."""
    MtM_lo = down(np.einsum("nia,nib->nab", M, M) * (1 - 2 * M.shape[-2] * EPS))
    MtM_hi = up(np.einsum("nia,nib->nab", M, M) * (1 + 2 * M.shape[-2] * EPS))
    if M.shape[-1] == 1:
        lam = MtM_hi[:, 0, 0]
    else:
        lam = lambda_max_upper(np.maximum(MtM_lo, 0.0), MtM_hi)
    return up(np.sqrt(np.maximum(lam, 0.0)))


def norm_upper(M, axes):
    """An upper bound of the Euclidean (Frobenius) norm over `axes` of every array with
    |A| <= M: sqrt(sum M^2) rounded up."""
    n = int(np.prod([M.shape[a] for a in axes]))
    return up(np.sqrt(up(np.sum(M * M, axis=axes) * (1 + 2 * n * EPS))))
