"""Running error bounds of CasADi functions: an enclosure of a double evaluation's rounding.

`enclosure(F)` walks the algorithm of a CasADi SX Function (its instructions, in the order
CasADi evaluates them) and builds a Function that returns, besides each output of F as
evaluated in double precision op by op, an entrywise bound of |computed - exact|, where
"exact" is F's value in exact arithmetic at inputs anywhere within given radii of the double
inputs (radius 0: at the doubles themselves). Each operation carries its computed value v
and a bound e of its distance from the exact value, from its operands' (a, e_a), (b, e_b):

- + and -: e_a + e_b + u |v|   (the standard model in the form |fl(x) - x| <= u |fl(x)|,
  Higham (2.5), u = 2^-53, round to nearest);
- *: |a| e_b + |b| e_a + e_a e_b + u |v| + 2^-1074 (the last: underflow's absolute error);
- /: (e_a + |v| e_b) / (|b| - e_b) + u |v| + 2^-1074, and +inf where |b| <= e_b;
  1/a, a^2, 2a, -a, |a| likewise (2a, -a, |a| exact);
- sqrt: e_a / sqrt(a) (|sqrt a - sqrt x| = |a - x| / (sqrt a + sqrt x)) + u |v|, +inf where
  a <= e_a (the exact operand may be negative);
- the elementary functions: the derivative's largest magnitude over [a - e_a, a + e_a],
  bounded in closed form (sin: e_a (|cos a| + e_a + libm); cos alike; tan: e_a / (|cos a| -
  e_a - libm)^2; exp: e_a |v| (1 + e_a + e_a^2) for e_a <= 1; log: e_a / (a - e_a); atan,
  tanh: e_a; asin, acos: e_a / sqrt((1 - t)(1 + t)), t = |a| + e_a; sinh, cosh: e_a
  cosh(|a| + e_a); atan2: the distance moved over the smallest radius, +inf where the box
  meets the branch cut or the origin; a constant power by its derivative at the box's
  ends), plus libm's own error, taken as LIBM_ULPS = 9 ulps of the result (an ulp of v is at
  most 2u |v|): glibc does not round these correctly; its manual ("Known Maximum Errors in
  Math Functions") gives its goal as "within a few ulp" and lists measured maxima per
  function and machine, and its test suite refuses a listed error above 9 ulps for a double
  function (a sanity limit set at the largest figure listed then). 9 is that limit: an
  assumption on the machine's libm, the one part of this bound not derived here;
- comparisons, sign, floor, ceil, if_else_zero: exact where the operands are exact (or, for
  a comparison, apart by more than their bounds); +inf otherwise;
- any other operation (and pow with an uncertain exponent): +inf, never a finite guess.

The bound itself is evaluated in double precision: every formula above combines
non-negative quantities, monotone in the operands' bounds, by at most 16 roundings, each of
which can make it smaller by at most a factor 1 + u, and FLOOR = 16 * 2^-1074 added to each
covers their underflow; so a computed bound is at least the exact one over (1 + u)^(16 T), T
the instructions of F, and it is multiplied by 1 + 32 (T + 1) u (5.7e-12 for the torsion
gyrocompass's operator) at the outputs and wherever it enters against the grain (a
denominator |b| - e_b, a test e_a <= 1): an upper bound. A value or a bound that is not
finite gives a bound of +inf (NaN included: `Enclosure` turns it so after the call).

Constants of the graph: a double that is a short dyadic number (an integer or a fraction
with a power of two below 2^20 as its denominator, as 0.5, 1.5, -2, 4 are) is the model's
constant exactly; any other (pi/180 as 0.017453292519943295) is taken within 4u of it (one
rounding of the literal, and up to three where CasADi folded products of constants).

`Enclosure` compiles such a Function into C through gyro.cbackend, as gyro.ode.compiled
does, but by an emitter of its own (`_simd_source`: one statement per instruction, four sets
a vector, since CasADi's generated code keeps every value in a work array and ran 12x
slower on the gyrohorizoncompass's operator); ISO C99 keeps -ffp-contract=off, so the
compiled code performs the operations the bound was derived for, to the bit those of
CasADi's own evaluation, which answers without a compiler. `operator_rounding` is the
operator's rounding, the equilibrium's and the difference to the operator actually used;
`operator_enclosed`, what the frequencies' certificate takes, is the twin's operator itself
with its rounding and the equilibrium's (one evaluation: no runtime operator, no difference).
The equilibrium's Krawczyk test does its linear algebra in C (gyro/csrc/krawczyk.c), NumPy
without a compiler.
"""
from __future__ import annotations

import math
import os
import re
import threading

import numpy as np

U = 2.0**-53  # the unit roundoff of double precision, round to nearest
TINY = 2.0**-1074  # the smallest subnormal: underflow's absolute error is at most half of it
LIBM_ULPS = 9  # libm's error in sin, cos, tan, exp, log, atan, ..., taken in ulps (above)
LIBM = 2 * LIBM_ULPS * U  # that relative to the result: an ulp of v is at most 2u |v|
GROW = 1 + 32 * U  # a sum or product of a few non-negative doubles made an upper bound
FLOOR = 16 * TINY  # added to each operation's bound: the underflow of its own evaluation


def _short_dyadic(c: float) -> bool:
    """A constant that a model's exact expression holds as it is (integers, halves,
    quarters, ...: a power of two below 2^20 as its denominator)."""
    if not math.isfinite(c):
        return False
    s = c * 2.0**20
    return s == math.floor(s) and abs(s) < 2.0**53


def enclosure(F, uncertain=None, name: str | None = None, keep=None):
    """The Function (inputs of F, then a radius for each input named in `uncertain` (all
    inputs where None), laid out as that input) -> (each output of F densified, then a
    bound of each output's rounding, densified, named "e_" + the output's name): the
    module's docstring says how. An input not in `uncertain` is exact as given. `keep`: the
    names of the outputs to return (of both kinds, in that order; None: all), the algorithm
    pruned to what they need."""
    import casadi as ca

    from gyro.intervals import instructions

    names = [F.name_in(i) for i in range(F.n_in())]
    uncertain = names if uncertain is None else list(uncertain)
    for nm in uncertain:
        if nm not in names:
            raise ValueError(f"enclosure: {F.name()} has no input {nm!r}")
    xs = [ca.SX.sym(nm, F.sparsity_in(i)) for i, nm in enumerate(names)]
    rs = {nm: ca.SX.sym("r_" + nm, F.sparsity_in(names.index(nm))) for nm in uncertain}
    x_nz = [[x.nz[j] for j in range(x.nnz())] for x in xs]
    r_nz = {nm: [r.nz[j] for j in range(r.nnz())] for nm, r in rs.items()}
    out_v = [[None] * F.nnz_out(i) for i in range(F.n_out())]
    out_e = [[None] * F.nnz_out(i) for i in range(F.n_out())]
    zero, inf = ca.SX(0.0), ca.SX(np.inf)
    fabs = ca.fabs

    # The bound's own rounding: each operation's formula combines non-negative numbers,
    # monotone in its operands' bounds, by at most 16 roundings, each shrinking it by at most
    # a factor 1 + u, and FLOOR added to each covers their underflow (below 2^-1022 a
    # rounding loses at most 2^-1075 absolute): so the computed bound is at least the exact
    # one over (1 + u)^(16 T), T the instructions, and `hi` (times 1 + 32 (T + 1) u >= that)
    # makes it an upper bound where a bound enters against the grain (a denominator, a
    # test), and at the outputs.
    grow = 1 + 32 * (F.n_instructions() + 1) * U

    def up(x):
        return x + FLOOR

    def hi(x):
        return x * grow

    def libm(av):  # the library function's own error, LIBM_ULPS ulps of its result |v|
        return LIBM * av + LIBM_ULPS * TINY

    v, e, const, absv = {}, {}, {}, {}
    for op, o, i, c in instructions(F):
        if op == ca.OP_INPUT:
            nm = names[i[0]]
            v[o[0]] = x_nz[i[0]][i[1]]
            e[o[0]] = r_nz[nm][i[1]] if nm in r_nz else zero
            const.pop(o[0], None)
            absv.pop(o[0], None)
            continue
        if op == ca.OP_OUTPUT:
            ex = e[i[0]]  # made an upper bound (hi), an exact output's 0 kept
            out_v[o[0]][o[1]], out_e[o[0]][o[1]] = v[i[0]], (ex if ex.is_zero() else hi(ex) + FLOOR)
            continue
        if op == ca.OP_CONST:
            c = float(c)
            v[o[0]] = ca.SX(c)
            e[o[0]] = zero if _short_dyadic(c) else ca.SX(4 * U * abs(c))
            const[o[0]] = c
            absv.pop(o[0], None)
            continue
        a, ea = v[i[0]], e[i[0]]
        binary = len(i) > 1 and op not in _UNARY
        b, eb = (v[i[1]], e[i[1]]) if binary else (None, None)
        val = ca.SX.binary(op, a, b) if binary else ca.SX.unary(op, a)
        # |a|, |b|, |val| made once per value and shared by its uses (an unused one is pruned)
        aa = absv[i[0]] if i[0] in absv else absv.setdefault(i[0], fabs(a))
        ab = (absv[i[1]] if i[1] in absv else absv.setdefault(i[1], fabs(b))) if binary else None
        av = fabs(val)
        err = _bound(ca, op, val, a, ea, b, eb, const.get(i[1]) if binary else None, up, hi, libm, zero, inf,
                     aa, ab, av)
        v[o[0]], e[o[0]], absv[o[0]] = val, err, av
        const.pop(o[0], None)
    outs, bounds = [], []
    for j in range(F.n_out()):
        sp = F.sparsity_out(j)
        outs.append(ca.densify(ca.SX(sp, ca.vertcat(*out_v[j])) if out_v[j] else ca.SX(sp)))
        bounds.append(ca.densify(ca.SX(sp, ca.vertcat(*out_e[j])) if out_e[j] else ca.SX(sp)))
    out_names = [F.name_out(j) for j in range(F.n_out())] + ["e_" + F.name_out(j) for j in range(F.n_out())]
    chosen = list(range(len(out_names))) if keep is None else [out_names.index(nm) for nm in keep]
    return ca.Function(name or f"{F.name()}_enclosure", xs + [rs[nm] for nm in uncertain],
                       [(outs + bounds)[j] for j in chosen], names + ["r_" + nm for nm in uncertain],
                       [out_names[j] for j in chosen])


_UNARY = set()  # filled below: the operations of one operand (CasADi lists two inputs for some)


def _bound(ca, op, val, a, ea, b, eb, cb, up, hi, libm, zero, inf, aa, ab, av):
    """The bound of one operation's result (the module's docstring): val = op(a, b) as
    computed, a and b within ea, eb of their exact values; cb: b's value where b is a
    constant of the graph (a power's exponent); aa, ab, av: |a|, |b|, |val|."""
    fabs, if_else = ca.fabs, ca.if_else
    rnd = U * av  # one correctly rounded operation
    if op in (ca.OP_ASSIGN, ca.OP_NEG, ca.OP_FABS):
        return ea
    if op == ca.OP_TWICE:
        return 2 * ea
    if op in (ca.OP_ADD, ca.OP_SUB):
        return up(ea + eb + rnd)
    if op == ca.OP_MUL:
        return up((aa + ea) * eb + ab * ea + rnd)
    if op == ca.OP_SQ:
        return up((2 * aa + ea) * ea + rnd)
    if op == ca.OP_DIV:
        den = ab - hi(eb)
        return if_else(den > 0, up((ea + av * eb) / den + rnd), inf)
    if op == ca.OP_INV:
        den = aa - hi(ea)
        return if_else(den > 0, up(av * ea / den + rnd), inf)
    if op == ca.OP_SQRT:
        return if_else(ea == 0, rnd, if_else(a - hi(ea) > 0, up(ea / val + rnd), inf))
    if op == ca.OP_SIN:
        return up(ea * (fabs(ca.cos(a)) + ea + LIBM) + libm(av))
    if op == ca.OP_COS:
        return up(ea * (fabs(ca.sin(a)) + ea + LIBM) + libm(av))
    if op == ca.OP_TAN:
        den = fabs(ca.cos(a)) - hi(ea) - LIBM
        return if_else(den > 0, up(ea / (den * den) + libm(av)), inf)
    if op == ca.OP_EXP:
        return if_else(hi(ea) <= 1, up(ea * av * (1 + LIBM) * (1 + ea + ea * ea) + libm(av)), inf)
    if op == ca.OP_EXPM1:  # derivative exp(x)
        return if_else(hi(ea) <= 1, up(ea * (av + 1) * (1 + LIBM) * (1 + ea + ea * ea) + libm(av)), inf)
    if op == ca.OP_LOG:
        den = a - hi(ea)
        return if_else(den > 0, up(ea / den + libm(av)), inf)
    if op == ca.OP_LOG1P:
        den = 1 + a - hi(ea)
        return if_else(den > 0, up(ea / den + libm(av)), inf)
    if op in (ca.OP_ATAN, ca.OP_TANH):  # |derivative| <= 1
        return up(ea + libm(av))
    if op == ca.OP_ERF:  # |derivative| <= 2 / sqrt(pi) < 1.13
        return up(1.13 * ea + libm(av))
    if op in (ca.OP_ASIN, ca.OP_ACOS):
        t = aa + hi(ea)
        den = (1 - t) * (1 + t)
        return if_else(ea == 0, libm(av), if_else(den > 0, up(ea / ca.sqrt(den) + libm(av)), inf))
    if op in (ca.OP_SINH, ca.OP_COSH):
        return up(ea * ca.cosh(fabs(a) + ea) * (1 + LIBM) + libm(av))
    if op == ca.OP_ATAN2:  # val = atan2(a, b): a = y, b = x
        s = hi(ea + eb)
        r = ca.sqrt(a * a + b * b) * (1 - 8 * U)
        cut = ca.logic_and(b - hi(eb) < 0, aa <= hi(ea))
        return if_else(s == 0, libm(av), if_else(ca.logic_and(r - s > 0, ca.logic_not(cut)),
                                                  up(s / (r - s) + libm(av)), inf))
    if op == ca.OP_CONSTPOW and cb is not None:
        return _constpow(ca, a, ea, cb, av, up, hi, libm, inf)
    if op == ca.OP_POW:
        if cb is not None:
            return _constpow(ca, a, ea, cb, av, up, hi, libm, inf)
        return if_else(ca.logic_and(ea == 0, eb == 0), libm(av), inf)
    if op in (ca.OP_FMIN, ca.OP_FMAX):  # Lipschitz 1 in each operand: max(ea, eb) <= ea + eb
        return up(ea + eb)
    if op in (ca.OP_LT, ca.OP_LE, ca.OP_EQ, ca.OP_NE):  # exact where it cannot flip
        apart = fabs(a - b) * (1 - 4 * U) > hi(ea + eb)
        return if_else(ca.logic_or(ca.logic_and(ea == 0, eb == 0), apart), zero, inf)
    if op in (ca.OP_NOT,):
        return ea
    if op in (ca.OP_AND, ca.OP_OR):  # a boolean's bound is 0 (exact) or inf
        return ea + eb
    if op == ca.OP_IF_ELSE_ZERO:
        return if_else(ea == 0, if_else(a != 0, eb, zero), inf)
    if op == ca.OP_SIGN:
        return if_else(ca.logic_or(ea == 0, aa > hi(ea)), zero, inf)
    if op in (ca.OP_FLOOR, ca.OP_CEIL, ca.OP_COPYSIGN, ca.OP_FMOD):  # exact on exact operands
        exact = ea == 0 if eb is None else ca.logic_and(ea == 0, eb == 0)
        return if_else(exact, zero, inf)
    return inf  # an operation this module does not bound


def _constpow(ca, a, ea, c, av, up, hi, libm, inf):
    """a^c for a constant c: its derivative's magnitude over the box at its ends."""
    fabs, if_else = ca.fabs, ca.if_else
    if c == 0:
        return ca.SX(0.0)
    if c == 1:
        return ea
    if c == math.floor(c) and c > 0:  # an integer power: |c| (|a| + ea)^(c - 1) ea, any sign
        d = abs(c) * (fabs(a) + ea) ** (c - 1) * (1 + LIBM)
        return up(d * ea + libm(av))
    if c == math.floor(c):  # a negative integer: |c| (|a| - ea)^(c - 1), the box clear of 0
        lo = fabs(a) - hi(ea)
        return if_else(lo > 0, up(abs(c) * lo ** (c - 1) * (1 + LIBM) * ea + libm(av)), inf)
    lo = a - hi(ea)  # any other: a positive box, the derivative monotone: both ends summed
    d = abs(c) * (lo ** (c - 1) + (a + ea) ** (c - 1)) * (1 + LIBM)
    return if_else(ea == 0, libm(av), if_else(lo > 0, up(d * ea + libm(av)), inf))


def _fill_unary():
    import casadi as ca

    for nm in ("ASSIGN", "NEG", "FABS", "TWICE", "SQ", "SQRT", "SIN", "COS", "TAN", "EXP", "EXPM1", "LOG",
               "LOG1P", "ATAN", "TANH", "ERF", "ASIN", "ACOS", "SINH", "COSH", "ASINH", "ACOSH", "ATANH",
               "INV", "NOT", "SIGN", "FLOOR", "CEIL", "ERFINV"):
        _UNARY.add(getattr(ca, "OP_" + nm))


_fill_unary()


class Enclosure:
    """An enclosure Function over a batch: compiled C with a loop over the sets (cached per
    machine by the source's hash, as gyro.ode.compiled), or CasADi's own evaluation without
    a compiler. Call with one array per input (sets, nonzeros), then the radii; returns
    (values, bounds), each a list of (sets, rows, cols) arrays, a bound +inf wherever it (or,
    where the values are kept, its value) is not finite.

    Enclosure(G, n_values): of the enclosure Function G, whose first n_values outputs are
    values. `enclosed` makes one lazily instead (`spec`): where the C of that Function is
    already in the cache under its stamp, neither the model's CasADi functions nor the
    enclosure are built in this process (they take a second or two, every `gyro scene`)."""

    def __init__(self, G=None, n_values: int = 0, spec=None):
        self._G, self._build = G, None
        if G is not None:
            self.label, self.stamp = G.name(), None
            self.sizes_in = [G.nnz_in(i) for i in range(G.n_in())]
            self.shapes_out = [G.size_out(j) for j in range(G.n_out())]
            self.n_values = n_values
        else:
            self._build, self.label, self.stamp, self.sizes_in, self.shapes_out, self.n_values = spec
        self.lib = self.fn = None
        self._tried = False  # compiled on first use outside gyro.cbackend.disabled()

    def _compiled(self):
        """The compiled entry point, or None (no compiler, an operation _simd_source has no C
        for, or within gyro.cbackend.disabled(): CasADi's own evaluation answers)."""
        from gyro import cbackend

        if cbackend._disabled:
            return None
        if not self._tried:
            self._tried = True
            try:
                self.fn = self._compile()
            except (cbackend.CompilerUnavailable, NotImplementedError):
                self.fn = None
        return self.fn

    @property
    def G(self):
        if self._G is None:
            self._G = self._build()
        return self._G

    def _compile(self):
        import ctypes
        import hashlib

        from gyro import cbackend

        cbackend._available()
        folder = cbackend._writable_cache() / "casadi-sources"
        stamped = folder / f"{self.label}-{self.stamp}.c" if self.stamp else None
        if stamped is not None and stamped.exists():
            text = stamped.read_text()
        else:
            text = _simd_source(self.G, f"{self.label}_batch", self.n_values)
        digest = hashlib.sha256(text.encode()).hexdigest()[:16]
        src = stamped or folder / f"{self.label}-{digest}.c"
        if not src.exists() or src.read_text() != text:
            src.parent.mkdir(parents=True, exist_ok=True)
            tmp = src.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(text)
            os.replace(tmp, src)  # atomic: another process may write the same bytes
        # -O1 (gyro.ode.compiled's reason: straight-line code, a compile of seconds)
        lib = cbackend._shared(f"{self.label}-{digest}", (src,), (), ("-O1",),
                               notice=f"the generated C of the rounding enclosure {self.label}")
        self.lib = lib
        fn = getattr(lib, f"{self.label}_batch")
        fn.restype = ctypes.c_int
        return fn

    def __call__(self, *inputs):
        n = max(np.asarray(x).reshape(-1, k).shape[0] if k else 1 for x, k in zip(inputs, self.sizes_in))
        args = [np.ascontiguousarray(np.broadcast_to(np.asarray(x, dtype=float).reshape(-1, k), (n, k)))
                if k else np.zeros((n, 0)) for x, k in zip(inputs, self.sizes_in)]
        flat = [np.empty((n, r * c)) for r, c in self.shapes_out]
        fn = self._compiled()
        if fn is not None:
            import ctypes

            V = ctypes.c_void_p  # the arrays' addresses (data_as costs ~3 us each: a batch of one set)
            ins = (V * len(args))(*[a.ctypes.data for a in args])
            outs = (V * len(flat))(*[o.ctypes.data for o in flat])
            with np.errstate(all="ignore"):
                if fn(ctypes.c_longlong(n), ins, outs):
                    raise ArithmeticError(f"{self.label}: the compiled enclosure failed")
        elif n:
            res = self.G.map(n, "serial")(*[a.T for a in args])
            res = res if isinstance(res, tuple) else (res,)
            for o, r, (rows, cols) in zip(flat, res, self.shapes_out):  # (rows, sets * cols)
                o[:] = np.asarray(r).reshape(rows, n, cols).transpose(1, 0, 2).reshape(n, rows * cols)
        values, bounds = flat[:self.n_values], flat[self.n_values:]  # row-major: _simd_source
        if fn is None:  # (the compiled code writes them so: _simd_source's n_values)
            with np.errstate(invalid="ignore"):
                for j, b in enumerate(bounds):  # in place: NaN and a value not finite have no bound
                    b[~(b < np.inf)] = np.inf
                    if len(values) == len(bounds):
                        b[~np.isfinite(values[j])] = np.inf
        shape = [(n, r, c) for r, c in self.shapes_out]
        return ([x.reshape(s) for x, s in zip(values, shape)],
                [x.reshape(s) for x, s in zip(bounds, shape[self.n_values:])])


_CACHE: dict = {}
_LOCK = threading.Lock()


def enclosed(model, fname: str, uncertain=("qe",), keep=None) -> Enclosure:
    """The Enclosure of a model's generated function `fname` (its CasADi twin, model.casadi),
    radii on the inputs `uncertain` (those it has), the outputs `keep` (enclosure's): cached
    per model, function and choice; its C found in the machine's cache by a stamp of the
    model's generated inputs (metadata's input_hash), the choice, this module's source and
    CasADi's version, without building anything where it is there."""
    key = (model.name, str(getattr(model, "directory", "")), fname, tuple(uncertain), keep and tuple(keep))
    with _LOCK:
        if key not in _CACHE:
            meta = model.meta["functions"][fname]
            ins = [(i["name"], len(i["symbols"])) for i in meta["inputs"]]
            outs_meta = {o["name"]: o for o in meta["outputs"]}
            has = [nm for nm in uncertain if nm in dict(ins)]
            names = [o["name"] for o in meta["outputs"]]
            outs = names + ["e_" + nm for nm in names] if keep is None else list(keep)
            tag = "" if keep is None and has == ["qe"] else "_" + "_".join(has + ["to"] + list(keep or names))
            label = re.sub(r"\W", "_", f"gyro_enclosure_{model.name}_{fname}{tag}")
            n_values = sum(not nm.startswith("e_") for nm in outs)

            def build():
                return enclosure(getattr(model.casadi, fname), has, label, keep)

            made = model.meta.get("generated", {}).get("input_hash")
            plain = all("nonzeros" not in outs_meta[nm.removeprefix("e_")] for nm in outs)
            if made and plain:
                import hashlib

                import casadi as ca

                h = hashlib.sha256(repr((made, model.name, fname, has, outs, LANES, ca.__version__)).encode())
                h.update(open(__file__, "rb").read())
                sizes = [k for _, k in ins] + [dict(ins)[nm] for nm in has]
                shapes = [tuple(outs_meta[nm.removeprefix("e_")]["shape"]) for nm in outs]
                _CACHE[key] = Enclosure(spec=(build, label, h.hexdigest()[:16], sizes, shapes, n_values))
            else:
                _CACHE[key] = Enclosure(build(), n_values)
        return _CACHE[key]


KRAWCZYK_TRIES = 4  # boxes tried per set (each one enclosure of the Newton system over it)


def equilibrium_radius(model, P, qe) -> np.ndarray:
    """Per set and equilibrium coordinate, a radius within which the exact equilibrium lies
    (of the exact equations at the double parameters P): +inf where none is proven.

    Krawczyk's test on the model's Newton system (r, Kn) = equilibrium_system(P, q), r the
    residual rows of the unknowns and Kn = -dr/dq: with X a computed inverse of Kn at qe,
    rho >= |r(qe)| the residual's enclosure at qe (|r| + its running bound) and, over the box
    |q - qe| <= d, R >= |I - X Kn(q)| (|I - X Kn| as computed, plus (n + 2) u |X| |Kn| for
    that product's rounding, plus |X| times Kn's enclosure over the box), the Krawczyk map
    qe + X r(qe) + (I - X Kn(box)) (box - qe) lies within |X| rho + R d of qe. Where that is
    at most d componentwise, the box holds an exact equilibrium (Brouwer) and every
    equilibrium of the box lies within |X| rho + R d of qe (Krawczyk): that is the radius.
    Rigorous (both enclosures are, the sums here inflated for their own rounding); the box
    is 2 |X| rho first, then twice the last map's radius, KRAWCZYK_TRIES boxes at most. The
    linear algebra (X, |X| rho, |I - X Kn|, the map's reach) in C where a compiler is at hand
    (gyro/csrc/krawczyk.c, the same formulas), else in NumPy (`_krawczyk_*_numpy`)."""
    P, qe = np.ascontiguousarray(P, dtype=float), np.ascontiguousarray(qe, dtype=float)
    N, ne = qe.shape
    out = np.full((N, ne), np.inf)
    if ne == 0:
        return out
    if "equilibrium_system" not in model.meta["functions"]:
        return out  # generated before the Newton system was emitted: nothing proven
    r_name, k_name = (o["name"] for o in model.meta["functions"]["equilibrium_system"]["outputs"])
    # at qe: the residual, Kn and the residual's bound (qe exact); over a box: Kn's bound alone
    point = enclosed(model, "equilibrium_system", (), (r_name, k_name, "e_" + r_name))
    box = enclosed(model, "equilibrium_system", ("qe",), ("e_" + k_name,))
    (r, Kn), (er,) = point(P, qe)
    r, er = r[:, :, 0], er[:, :, 0]
    kernel = _krawczyk_kernel()
    first = _krawczyk_start_numpy if kernel is None else _krawczyk_start_c
    live, X, base, formed, d = first(r, er, Kn)
    live &= np.all(np.isfinite(qe), axis=1)
    step = _krawczyk_step_numpy if kernel is None else _krawczyk_step_c
    todo = np.flatnonzero(live)
    for _ in range(KRAWCZYK_TRIES):
        if todo.size == 0:
            break
        every = todo.size == N  # no copies of the batch where every set is tried
        _, (eK,) = box(P, qe, d) if every else box(P[todo], qe[todo], d[todo])
        inside = step(todo, X, formed, base, eK, d, out)
        todo = todo[~inside & np.all(np.isfinite(d[todo]), axis=1)]
    return out


def _krawczyk_kernel():
    """The compiled linear algebra of Krawczyk's test (gyro/csrc/krawczyk.c), or None (no
    compiler, or within gyro.cbackend.disabled(): the NumPy version answers)."""
    from gyro import cbackend

    try:
        lib = cbackend.kernel_library("krawczyk")
    except cbackend.CompilerUnavailable:
        return None
    return lib


def _krawczyk_start_numpy(r, er, Kn):
    """(live, X, base, formed, d) of equilibrium_radius's test (its docstring), per set:
    X a computed inverse of Kn, base >= |X| rho, formed >= |I - X Kn| with that product's
    rounding, d = 2 base the first box; live where every input and X are finite."""
    ne = r.shape[1]
    live = np.all(np.isfinite(er), axis=1) & np.all(np.isfinite(r), axis=1) & np.all(np.isfinite(Kn), axis=(1, 2))
    grow = 1 + 4 * (ne + 2) * U
    X = np.full_like(Kn, np.nan)
    with np.errstate(all="ignore"):
        k = np.flatnonzero(live)
        try:
            X[k] = np.linalg.inv(Kn[k])
        except np.linalg.LinAlgError:  # a singular Kn somewhere: set by set, that set unproven
            for j in k:
                try:
                    X[j] = np.linalg.inv(Kn[j])
                except np.linalg.LinAlgError:
                    pass
        live &= np.all(np.isfinite(X), axis=(1, 2))
        aX = np.abs(X)
        rho = (np.abs(r) + er) * GROW
        base = np.einsum("bij,bj->bi", aX, rho) * grow + 4 * ne * TINY  # |X| rho
        formed = np.abs(np.eye(ne) - X @ Kn) + (ne + 2) * U * grow * (aX @ np.abs(Kn))
    return live, X, base, formed, 2 * base


def _krawczyk_step_numpy(todo, X, formed, base, eK, d, out):
    """One box of the test for the sets `todo` (eK: Kn's enclosure over their boxes |q - qe|
    <= d): out[set] = the Krawczyk map's reach where it lies within the box; d of those sets
    made twice the reach (the next box; +inf where not finite), in place. -> inside (todo,)."""
    ne = X.shape[1]
    grow = 1 + 4 * (ne + 2) * U
    with np.errstate(all="ignore"):
        R = (formed[todo] + np.abs(X[todo]) @ eK) * grow
        reach = (base[todo] + np.einsum("bij,bj->bi", R, d[todo])) * grow + 4 * ne * TINY
        inside = np.all(reach <= d[todo], axis=1) & np.all(np.isfinite(reach), axis=1)
        out[todo[inside]] = reach[inside]
        d[todo] = 2 * np.where(np.isfinite(reach), reach, np.inf)
    return inside


def _krawczyk_start_c(r, er, Kn):
    """_krawczyk_start_numpy in C (gyro/csrc/krawczyk.c: Gauss-Jordan's X, formed never
    smaller than the NumPy formula's for the same X)."""
    import ctypes

    N, ne = r.shape
    if ne > 64:  # the kernel's fixed size
        return _krawczyk_start_numpy(r, er, Kn)
    r, er, Kn = (np.ascontiguousarray(a, dtype=float) for a in (r, er, Kn))
    X, formed = np.empty((N, ne, ne)), np.empty((N, ne, ne))
    base, d = np.empty((N, ne)), np.empty((N, ne))
    live = np.empty(N, np.uint8)
    fn = _krawczyk_kernel().gyro_krawczyk_start
    fn.restype = None
    with np.errstate(all="ignore"):
        fn(ctypes.c_long(N), ctypes.c_long(ne),
           *[ctypes.c_void_p(a.ctypes.data) for a in (r, er, Kn, X, base, formed, d, live)])
    return live.astype(bool), X, base, formed, d


def _krawczyk_step_c(todo, X, formed, base, eK, d, out):
    """_krawczyk_step_numpy in C (the same formulas and order of sums)."""
    import ctypes

    ne = X.shape[1]
    if ne > 64:
        return _krawczyk_step_numpy(todo, X, formed, base, eK, d, out)
    rows = np.ascontiguousarray(todo, dtype=np.int64)
    eK = np.ascontiguousarray(eK, dtype=float)
    inside = np.empty(rows.size, np.uint8)
    fn = _krawczyk_kernel().gyro_krawczyk_step
    fn.restype = None
    with np.errstate(all="ignore"):
        fn(ctypes.c_long(rows.size), ctypes.c_long(ne),
           *[ctypes.c_void_p(a.ctypes.data) for a in (rows, X, formed, base, eK, d, out, inside)])
    return inside.astype(bool)


def operator_rounding(model, P, qe, M, D, K):
    """An entrywise bound of |X - X_exact| for the operator X = M, D, K the runtime formed at
    (P, qe) (gyro.equilibrium.operators: the model's C or its NumPy), X_exact the exact
    operator at the exact equilibrium of the double parameters P: the operator's CasADi twin
    enclosed (`enclosure`) over the box |q - qe| <= equilibrium_radius(P, qe), plus the
    difference of the operator used from the twin (|X - X_twin| + e_twin bounds |X - X_exact|
    whatever the C compiler or NumPy did). Rigorous up to libm's assumed accuracy
    (LIBM_ULPS); +inf for every entry that depends on qe where no equilibrium is proven."""
    P, qe = np.asarray(P, dtype=float), np.asarray(qe, dtype=float)
    delta = equilibrium_radius(model, P, qe)
    E = enclosed(model, "operator")
    twin, bounds = E(P, qe, delta)
    out = []
    with np.errstate(all="ignore"):
        for X, T, e in zip((M, D, K), twin, bounds):
            d = np.subtract(X, T)  # in place from here: this runs on every set a certificate tries
            np.abs(d, out=d)
            d += e
            d *= GROW
            d[np.isnan(d)] = np.inf
            out.append(d)
    return tuple(out)


def operator_enclosed(model, P, qe):
    """(M, D, K, dM, dD, dK): the operator at (P, qe) as its CasADi twin evaluates it in
    double precision, and an entrywise bound of its distance from the exact operator at the
    exact equilibrium of the double parameters P: operator_rounding of the twin's own values,
    from one evaluation. The twin's values are an operator evaluated at qe like any other (the
    count of gyro.questions.frequencies proves the exact operator's frequencies from whichever
    double operator it is given and that operator's distance from the exact one), so the
    certificate takes them and neither forms the runtime's operator nor bounds |used - twin|
    (0 here; the bound is the enclosure's, times GROW as operator_rounding gives it)."""
    P, qe = np.asarray(P, dtype=float), np.asarray(qe, dtype=float)
    delta = equilibrium_radius(model, P, qe)
    twin, bounds = enclosed(model, "operator")(P, qe, delta)
    with np.errstate(all="ignore"):
        for e in bounds:  # in place; a bound is +inf where its value is not finite (Enclosure)
            e *= GROW
    return (*twin, *bounds)


LANES = 4  # sets per vector of the compiled enclosure (GCC's vector extension)

_C_BINARY = {"OP_ADD": "{a} + {b}", "OP_SUB": "{a} - {b}", "OP_MUL": "{a} * {b}", "OP_DIV": "{a} / {b}",
             "OP_LT": "B({a} < {b})", "OP_LE": "B({a} <= {b})", "OP_EQ": "B({a} == {b})",
             "OP_NE": "B({a} != {b})", "OP_AND": "B(({a} != 0) & ({b} != 0))",
             "OP_OR": "B(({a} != 0) | ({b} != 0))", "OP_IF_ELSE_ZERO": "(vd)((vl){b} & ({a} != 0))",
             "OP_FMIN": "L2(fmin, {a}, {b})", "OP_FMAX": "L2(fmax, {a}, {b})", "OP_POW": "L2(pow, {a}, {b})",
             "OP_CONSTPOW": "L2(pow, {a}, {b})", "OP_ATAN2": "L2(atan2, {a}, {b})",
             "OP_COPYSIGN": "L2(copysign, {a}, {b})", "OP_FMOD": "L2(fmod, {a}, {b})"}
_C_UNARY = {"OP_ASSIGN": "{a}", "OP_NEG": "-{a}", "OP_TWICE": "{a} + {a}", "OP_SQ": "{a} * {a}",
            "OP_INV": "1.0 / {a}", "OP_FABS": "(vd)((vl){a} & 0x7fffffffffffffffLL)",
            "OP_NOT": "B({a} == 0)"}
_C_LIBM = {"OP_SQRT": "sqrt", "OP_SIN": "sin", "OP_COS": "cos", "OP_TAN": "tan", "OP_EXP": "exp",
           "OP_EXPM1": "expm1", "OP_LOG": "log", "OP_LOG1P": "log1p", "OP_ATAN": "atan", "OP_TANH": "tanh",
           "OP_ERF": "erf", "OP_ASIN": "asin", "OP_ACOS": "acos", "OP_SINH": "sinh", "OP_COSH": "cosh",
           "OP_FLOOR": "floor", "OP_CEIL": "ceil", "OP_SIGN": "SIGN"}


def _simd_source(G, entry: str, n_values: int | None = None) -> str:
    """C99 of an SX Function over a batch, LANES sets at a time in GCC's vector extension:
    one statement per instruction of G's algorithm, in its order, each the one IEEE operation
    (ISO C99: no contraction, no reassociation; libm's functions lane by lane), single
    assignment, so the compiler keeps the values in registers. `entry(n, in, out)`: in[i] is
    input i over the sets (sets, nonzeros), out[j] likewise. The outputs of a block are kept
    in vectors and written set by set at its end; with `n_values` (G an enclosure whose first
    n_values outputs are values, the rest bounds), a bound is written as +inf where it is not
    below +inf (NaN) or, where each value has its bound, where its value is not finite: what
    `Enclosure` does to CasADi's own evaluation, here without a pass over the arrays."""
    import casadi as ca

    names = {getattr(ca, n): n for n in dir(ca) if n.startswith("OP_")}
    L = LANES
    sizes = [G.size_out(j) for j in range(G.n_out())]
    for j, (rows, cols) in enumerate(sizes):
        if G.nnz_out(j) != rows * cols:
            raise NotImplementedError(f"{G.name()}: a sparse output")
    head = [
        "#include <math.h>",
        f"typedef double vd __attribute__((vector_size({8 * L})));",
        f"typedef long long vl __attribute__((vector_size({8 * L})));",
        "#define B(m) __builtin_convertvector(-(m), vd)",
        f"#define L1(f, x) ({{ vd _x = (x), _r; for (int _i = 0; _i < {L}; ++_i) _r[_i] = f(_x[_i]); _r; }})",
        f"#define L2(f, x, y) ({{ vd _x = (x), _y = (y), _r; for (int _i = 0; _i < {L}; ++_i) "
        "_r[_i] = f(_x[_i], _y[_i]); _r; })",
        "static double SIGN(double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : x; }",
        f"int {entry}(long long n, const double* const* in, double* const* out) {{",
        *[f"  vd o{j}[{max(r * c, 1)}];" for j, (r, c) in enumerate(sizes)],
        f"  for (long long k = 0; k < n; k += {L}) {{",
        f"    long long s[{L}];",
        f"    for (int i = 0; i < {L}; ++i) s[i] = k + i < n ? k + i : n - 1;",
    ]
    body, reg = [], {}
    for k in range(G.n_instructions()):
        op = names[G.instruction_id(k)]
        i, o = G.instruction_input(k), G.instruction_output(k)
        if op == "OP_INPUT":
            nnz = G.nnz_in(i[0])
            lanes = ", ".join(f"in[{i[0]}][s[{q}] * {nnz} + {i[1]}]" for q in range(L))
            expr = f"(vd){{{lanes}}}"
        elif op == "OP_OUTPUT":  # a dense output's entries row by row (CasADi's nonzeros go by column)
            rows, cols = sizes[o[0]]
            body.append(f"    o{o[0]}[{(o[1] % rows) * cols + o[1] // rows}] = {reg[i[0]]};")
            continue
        elif op == "OP_CONST":
            c = float(G.instruction_constant(k))
            lit = "INFINITY" if c == np.inf else "-INFINITY" if c == -np.inf else "NAN" if c != c else repr(c)
            expr = f"((vd){{0}} + {lit})"
        elif op in _C_UNARY:
            expr = _C_UNARY[op].format(a=reg[i[0]])
        elif op in _C_LIBM:
            expr = f"L1({_C_LIBM[op]}, {reg[i[0]]})"
        elif op in _C_BINARY:
            expr = _C_BINARY[op].format(a=reg[i[0]], b=reg[i[1]])
        else:
            raise NotImplementedError(f"{G.name()}: no C for {op}")
        body.append(f"    vd a{k} = {expr};")
        reg[o[0]] = f"a{k}"
    tail = [f"    for (int i = 0; i < {L} && k + i < n; ++i) {{"]
    nv = G.n_out() if n_values is None else n_values
    paired = n_values is not None and 2 * nv == G.n_out()
    for j, (rows, cols) in enumerate(sizes):
        size = rows * cols
        if not size:
            continue
        tail.append(f"      double* d{j} = out[{j}] + (k + i) * {size};")
        if j < nv:
            tail.append(f"      for (int t = 0; t < {size}; ++t) d{j}[t] = o{j}[t][i];")
        elif paired:
            tail.append(f"      for (int t = 0; t < {size}; ++t) {{ double b = o{j}[t][i]; "
                        f"d{j}[t] = b < INFINITY && isfinite(o{j - nv}[t][i]) ? b : INFINITY; }}")
        else:
            tail.append(f"      for (int t = 0; t < {size}; ++t) {{ double b = o{j}[t][i]; "
                        f"d{j}[t] = b < INFINITY ? b : INFINITY; }}")
    tail.append("    }")
    return "\n".join(head + body + tail + ["  }", "  return 0;", "}", ""])
