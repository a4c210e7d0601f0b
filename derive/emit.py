"""Emission: one symbolic result -> CasADi, NumPy and C code through jinja2 templates.

For each `Function` of a model, the expressions of all its outputs go through one
common-subexpression elimination; the same CSE is printed four ways:
- `casadi_functions.py`: CasADi `Function` objects (SX graphs built at import);
- `numpy_functions.py`: vectorised NumPy functions over a leading batch of parameter sets;
- `mpmath_functions.py`: the same in arbitrary precision (references for tests and charts);
- `<model>.h`, `<model>.c`: flat, allocation-free C99, each function also over a batch.
An output that its `Function` declares sparse is emitted as its structural nonzeros alone,
in every backend: a flat vector of values (row-major over the matrix) whose (row, column)
positions metadata.json lists under the output's "nonzeros".
The C writes the structural nonzeros of an output alone, each stored as soon as the
temporaries it needs are known (`_schedule`); its structural zeros are the caller's to zero
once (the contract in templates/model.h.j2; the `_batch` entry points zero them themselves).
Every file starts with a header naming the template it came from, saying it must not be
edited, and carrying a hash of the inputs that made it (the shared machinery of `derive/`,
the templates, the model's own file or folder and the pinned SymPy, SymEngine and CasADi
versions; not the other models). Bytes are deterministic: no timestamps, canonical CSE
order, sorted JSON; each function's inputs and outputs are listed in call order.
"""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from importlib import metadata as importlib_metadata
from pathlib import Path

import jinja2
import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import MpmathPrinter, PythonCodePrinter

from derive import parallel
from derive.model import Function

ROOT = Path(__file__).resolve().parent.parent
TEMPLATES = ROOT / "templates"
TOOL_VERSIONS = ("sympy", "symengine", "casadi", "jinja2")
IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


# --------------------------------------------------------------------------- printers


def _float_literal(x) -> str:
    return repr(float(x))


_TERMS: dict = {}  # (Add, order) -> its terms in print order, shared by the printers of one emit


class _SharedOrder:
    """Each printer puts an Add's terms in sympy's order (as_ordered_terms: the terms'
    sort keys), and the four printers print the same expressions: computed once per
    expression and order for all of them, the same lists (a 12-link chain's emission
    spent 6 s of its printing there)."""

    def _as_ordered_terms(self, expr, order=None):
        key = (expr, order or self.order)
        got = _TERMS.get(key)
        if got is None:
            got = _TERMS[key] = super()._as_ordered_terms(expr, order=order)
        return list(got)


class CPrinter(_SharedOrder, C99CodePrinter):
    """C99 with small integer powers as products and constants as double literals."""

    def _print_Pow(self, expr):
        b, e = expr.base, expr.exp
        if e.is_Integer and 2 <= abs(int(e)) <= 8:
            # parenthesised: the Mul printer puts a power in a denominator as it is (x/(A*A*A))
            prod = "*".join([self.parenthesize(b, 1000)] * abs(int(e)))
            return f"({prod})" if e > 0 else f"(1.0/({prod}))"
        if e == sp.Rational(1, 2):
            return f"sqrt({self._print(b)})"
        if e == -sp.Rational(1, 2):
            return f"1.0/sqrt({self._print(b)})"
        if e == -1:
            return f"1.0/{self.parenthesize(b, 1000)}"
        return f"pow({self._print(b)}, {self._print(e)})"

    def _print_Pi(self, expr):
        return _float_literal(sp.pi)

    def _print_Rational(self, expr):
        return f"({_float_literal(expr.p)}/{_float_literal(expr.q)})"


class NumpyPrinter(_SharedOrder, NumPyPrinter):
    def _print_Pi(self, expr):
        return _float_literal(sp.pi)

    def _print_Rational(self, expr):
        return f"({expr.p}/{expr.q})"


class MpPrinter(_SharedOrder, MpmathPrinter):
    """mpmath with exact constants: rationals as mpf quotients, pi at working precision."""

    def _print_Rational(self, expr):
        return f"(mpmath.mpf({expr.p})/{expr.q})"

    def _print_Pow(self, expr, rational=False):
        if expr.exp == sp.Rational(1, 2):
            return f"mpmath.sqrt({self._print(expr.base)})"
        if expr.exp == -sp.Rational(1, 2):
            return f"(1/mpmath.sqrt({self._print(expr.base)}))"
        return super()._print_Pow(expr, rational=rational)


class CasadiPrinter(_SharedOrder, PythonCodePrinter):
    """Python syntax over CasADi SX: elementary functions from the `ca` namespace."""

    _functions = {"sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
                  "exp", "log", "sqrt", "fabs"}

    def _print_Function(self, expr):
        name = expr.func.__name__
        if name in self._functions:
            return f"ca.{name}({', '.join(self._print(a) for a in expr.args)})"
        raise ValueError(f"no CasADi counterpart for {name}")

    _print_sin = _print_cos = _print_tan = _print_atan = _print_atan2 = _print_Function
    _print_exp = _print_log = _print_sinh = _print_cosh = _print_tanh = _print_Function
    _print_asin = _print_acos = _print_Function

    def _print_Pow(self, expr):
        if expr.exp == sp.Rational(1, 2):
            return f"ca.sqrt({self._print(expr.base)})"
        if expr.exp == -sp.Rational(1, 2):  # Python's printer would write 1/math.sqrt
            return f"(1/ca.sqrt({self._print(expr.base)}))"
        return super()._print_Pow(expr, rational=False)

    def _print_Abs(self, expr):
        return f"ca.fabs({self._print(expr.args[0])})"

    # non-smooth functions (derive/nonsmooth.py) as SX expressions: sign(0) = 0, and
    # Heaviside(0) its second argument (1/2, or NaN in a linearisation's jump)
    def _print_sign(self, expr):
        return f"ca.sign({self._print(expr.args[0])})"

    def _print_Heaviside(self, expr):
        x = self._print(expr.args[0])
        h0 = self._print(expr.args[1]) if len(expr.args) > 1 else "0.5"
        return f"ca.if_else({x} < 0, 0, ca.if_else({x} > 0, 1, {h0}))"

    def _print_NaN(self, expr):
        return "float('nan')"

    def _print_Piecewise(self, expr):
        out = self._print(expr.args[-1].expr) if expr.args[-1].cond == sp.true else "float('nan')"
        for piece in reversed(expr.args[:-1] if expr.args[-1].cond == sp.true else expr.args):
            out = f"ca.if_else({self._print(piece.cond)}, {self._print(piece.expr)}, {out})"
        return out

    def _print_Pi(self, expr):
        return _float_literal(sp.pi)

    def _print_Rational(self, expr):
        return f"({expr.p}/{expr.q})"


# --------------------------------------------------------------------------- CSE'd functions


@dataclass
class Output:
    name: str
    rows: int
    cols: int
    entries: list  # (flat index, printed expression) for non-zero entries, row-major
    vector: bool = False  # a column that NumPy returns with shape batch + (rows,)
    # emitted as its structural nonzeros alone: entries[k] is value k of a flat output of
    # len(entries) values, at (row, column) = divmod(entries[k][0], cols) of the matrix
    sparse: bool = False

    @property
    def size(self) -> int:
        """How many numbers the output holds: its nonzeros if sparse, else rows x cols."""
        return len(self.entries) if self.sparse else self.rows * self.cols

    def positions(self) -> dict:
        """A sparse output's (row, column) of each value, in the values' order."""
        return {"rows": [i // self.cols for i, _ in self.entries],
                "cols": [i % self.cols for i, _ in self.entries]}


@dataclass
class Input:
    name: str
    symbols: list  # scalar symbol names, in order


@dataclass
class EmittedFunction:
    name: str
    doc: str
    inputs: list[Input]
    temps: list  # (name, printed expression)
    outputs: list[Output]
    ops: int  # operations after CSE
    ops_before: int  # operations before CSE
    # the C statements in their order (_schedule): (temporary or input symbol, None,
    # expression) or (output name, position in the emitted array, expression); an input is
    # read just before the first statement that needs it (_reads)
    body: list = ()
    unread: list = ()  # the inputs of which the C reads no entry


def count_ops(exprs) -> int:
    """sum(sp.count_ops(e) for e in exprs), the same integer, with each distinct
    subexpression counted once: sp.count_ops walks the tree, and an expression of the
    derivation repeats its subtrees many times (a 12-link chain's sensitivities spent 7 s
    in it). Its count is a sum of what each node it visits adds, each a function of the
    node alone (SUB - ADD adds nothing to the total), so memoising by node gives the
    same sum (tests/unit/test_machinery.py holds it to sp.count_ops)."""
    from sympy.core.function import _coeff_isneg
    from sympy.core.operations import LatticeOp
    from sympy.simplify.radsimp import fraction

    memo: dict = {}

    def local(a):
        """(what node a adds, the nodes sp.count_ops visits after it)."""
        if a.is_Rational:
            if a is not sp.S.One:
                return int(a.p < 0) + int(a.q != 1), ()
        elif a.is_Mul:
            c = 0
            if _coeff_isneg(a):
                c += 1
                a = a.as_two_terms()[1] if a.args[0] is sp.S.NegativeOne else -a
            n, d = fraction(a)
            if n.is_Integer:
                return c + 1 + (1 if n < 0 else 0), (d,)
            if d is not sp.S.One:
                return c + 1, ((d,) if not d.is_Integer else ()) + (n,)
            extra, pushed = _generic(a)
            return c + extra, pushed
        elif a.is_Add:
            c, pushed, negs = 0, [], 0
            for i, ai in enumerate(a.args):
                neg = _coeff_isneg(ai)
                negs += neg
                pushed.append(-ai if neg else ai)
                c += i > 0
            return c + int(negs == len(a.args)), pushed
        return _generic(a)

    def _generic(a):
        if a.is_Pow and a.exp is sp.S.NegativeOne:
            return 1, (a.base,)
        if a == sp.S.Exp1:
            return 1, ()
        if a.is_Pow and a.base == sp.S.Exp1:
            return 1, (a.exp,)
        c = 0
        if a.is_Mul or isinstance(a, LatticeOp):
            c = len(a.args) - 1
        elif a.args and (a.is_Pow or a.is_Function or isinstance(a, (sp.Derivative, sp.Integral, sp.Sum))):
            c = 1
        return c, (() if a.is_Symbol else a.args)

    def total(root) -> int:
        stack = [(root, False)]
        while stack:
            a, expanded = stack.pop()
            if a in memo:
                continue
            c, pushed = local(a)
            if not expanded:
                stack.append((a, True))
                stack.extend((b, False) for b in pushed if b not in memo)
            else:
                memo[a] = c + sum(memo[b] for b in pushed)
        return memo[root]

    out = 0
    for e in exprs:
        e = sp.sympify(e)
        if not isinstance(e, sp.Expr) or e.is_Relational:
            out += sp.count_ops(e)
        else:
            out += total(e)
    return out


def _cse(fn: Function):
    flat = []
    for _, mat in fn.outputs:
        flat.extend(list(sp.Matrix(mat)))
    allowed = {s for _, syms in fn.inputs for s in syms}
    free = set().union(*[sp.sympify(e).free_symbols for e in flat]) if flat else set()
    missing = free - allowed
    if missing:
        raise ValueError(f"{fn.name}: symbols not among its inputs: {sorted(map(str, missing))}")
    ops_before = count_ops(flat)
    temps, reduced = sp.cse(flat, symbols=sp.numbered_symbols("t"), order="canonical")
    ops = count_ops([e for _, e in temps] + list(reduced))
    return temps, reduced, ops, ops_before


def _schedule(temps, reduced) -> list:
    """The order of the C statements: the outputs' nonzero entries in turn (row-major, output
    after output), each preceded by the temporaries it needs that are not computed yet,
    depth first. Values are those of the CSE in its own order (each statement is the same
    expression); what changes is how long a temporary lives: stored into the output as
    soon as it is known, not all temporaries first, which kept hundreds live across the
    calls to sin and cos (spilled to the stack). The temporaries that call a function come
    first (with what they need): little is live across the calls then. Returns ("t", i)
    for temps[i] and ("o", k) for reduced[k], the temporaries no output needs left out."""
    index = {t: i for i, (t, _) in enumerate(temps)}
    uses = lambda e: sorted(index[s] for s in e.free_symbols if s in index)  # noqa: E731
    deps = [uses(e) for _, e in temps]
    done, order = [False] * len(temps), []
    calls = [i for i, (_, e) in enumerate(temps) if e.atoms(sp.Function)]
    for k, e in [(None, None)] + list(enumerate(reduced)):
        if k is not None and e == 0:
            continue
        for root in (calls if k is None else uses(e)):  # post-order depth first, iteratively
            stack = [(root, 0)]
            while stack:
                i, j = stack.pop()
                if done[i]:
                    continue
                if j < len(deps[i]):
                    stack.append((i, j + 1))
                    if not done[deps[i][j]]:
                        stack.append((deps[i][j], 0))
                else:
                    done[i] = True
                    order.append(("t", i))
        if k is not None:
            order.append(("o", k))
    return order


def _printed(fn, temps, reduced, ops, ops_before, printer, schedule=None) -> EmittedFunction:
    outs, k = [], 0
    for name, mat in fn.outputs:
        mat = sp.Matrix(mat)
        entries = []
        for idx in range(mat.rows * mat.cols):
            e = reduced[k + idx]
            if e != 0:
                entries.append((idx, printer.doprint(e)))
        outs.append(Output(name, mat.rows, mat.cols, entries,
                           vector=mat.cols == 1 and name not in fn.matrices, sparse=name in fn.sparse))
        k += mat.rows * mat.cols
    printed_temps = [(str(t), printer.doprint(e)) for t, e in temps]
    body, unread = [], {n for n, _ in fn.inputs}
    if schedule is not None:  # flat entry k -> (output name, position in its emitted array)
        where, k = {}, 0
        for o in outs:
            for pos, (idx, e) in enumerate(o.entries):
                where[k + idx] = (o.name, pos if o.sparse else idx, e)
            k += o.rows * o.cols
        read = {s: (n, j) for n, syms in fn.inputs for j, s in enumerate(syms)}
        for kind, i in _reads(schedule, temps, reduced, read):
            if kind == "i":
                n, j = read[i]
                body.append((str(i), None, f"{n}[{j}]"))
                unread.discard(n)
            else:
                body.append((printed_temps[i][0], None, printed_temps[i][1]) if kind == "t" else where[i])
    return EmittedFunction(
        name=fn.name, doc=fn.doc,
        inputs=[Input(n, [str(s) for s in syms]) for n, syms in fn.inputs],
        temps=printed_temps,
        outputs=outs, ops=int(ops), ops_before=int(ops_before), body=body,
        unread=[n for n, _ in fn.inputs if n in unread])


def _reads(schedule, temps, reduced, inputs) -> list:
    """The schedule with ("i", symbol) for each input symbol it uses, just before the first
    statement that needs it: a value read from the input array where it is used, not all
    of them at the top, where the compiler loaded every one at the start and kept them live
    across the calls to sin and cos (spilled to the stack and back); the statements and
    their values are the schedule's. The C then reads an input after it has stored into an
    output: the outputs must not overlap the inputs (the contract in model.h.j2)."""
    out, seen = [], set()
    for kind, i in schedule:
        e = temps[i][1] if kind == "t" else reduced[i]
        for s in sorted((s for s in e.free_symbols if s in inputs and s not in seen), key=inputs.get):
            seen.add(s)
            out.append(("i", s))
        out.append((kind, i))
    return out


# --------------------------------------------------------------------------- files


def tool_versions() -> dict[str, str]:
    return {name: importlib_metadata.version(name) for name in TOOL_VERSIONS}


def model_files(model_file: Path) -> list[Path]:
    """The files a model is made of: its module file, or every .py of its package folder,
    and every module beside it that these import (helpers, found by reading the imports)."""
    model_file = Path(model_file).resolve()
    if model_file.name == "__init__.py":
        own = sorted(model_file.parent.rglob("*.py"))
    else:
        own = [model_file]
    helpers = [f for f in local_imports(own, model_file.parent) if f not in own]
    return own + sorted(helpers)


def _module_file(base: Path, dotted: str) -> Path | None:
    """base/a/b.py or base/a/b/__init__.py for a dotted name a.b, if it exists."""
    stem = base.joinpath(*dotted.split("."))
    for f in (stem.with_suffix(".py"), stem / "__init__.py"):
        if f.is_file():
            return f.resolve()
    return None


def local_imports(files, folder: Path) -> list[Path]:
    """Every file under `folder` that `files` import, directly or through each other: an
    absolute import resolved from the folder (the model's own sys.path entry) or from the
    repository (derive.models.<other>), a relative one from the importing file's package.
    Read from the sources (import statements anywhere, in functions too), so that the set
    does not depend on which other models were imported first."""
    import ast

    folder = Path(folder).resolve()
    todo, seen = [Path(f).resolve() for f in files], set()
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        try:
            tree = ast.parse(f.read_text())
        except (OSError, SyntaxError, ValueError):
            continue
        names = []
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names += [(0, a.name, None) for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names += [(node.level, node.module or "", a.name) for a in node.names]
        for level, mod, member in names:
            if level:
                base = f.parent
                for _ in range(level - 1):
                    base = base.parent
                bases = [base]
            else:
                bases = [folder, ROOT]
            for base in bases:
                for dotted in filter(None, [mod, f"{mod}.{member}".strip(".") if member else None]):
                    hit = _module_file(base, dotted)
                    if hit is not None and (hit.parent == folder or folder in hit.parents):
                        todo.append(hit)
    return sorted(seen)


def _shown(path: Path) -> str:
    """A path as the generated files show it: relative to the repository when inside it,
    else the file's name alone (bytes must not depend on where a checkout lives)."""
    path = Path(path).resolve()
    try:
        return path.relative_to(ROOT).as_posix()
    except ValueError:
        return path.name


# derive/ sources that cannot change a byte of the output: the command line and the
# scheduling of models over processes (the bytes are the same under --jobs 1 and 2)
NOT_OUTPUT = ("__main__.py", "parallel.py")


def machinery_files() -> list[Path]:
    """The shared machinery that can change the output: every source of derive/ outside
    derive/models/ but NOT_OUTPUT, and the templates."""
    models = ROOT / "derive" / "models"
    skip = {ROOT / "derive" / name for name in NOT_OUTPUT}
    return sorted([f for f in (ROOT / "derive").rglob("*.py") if models not in f.parents and f not in skip]
                  + list(TEMPLATES.glob("*.j2")))


def input_hash(model_module_file: Path) -> str:
    """SHA-256 of what makes one model's generated files: the shared machinery and the
    templates, the model's own file(s) with every module it imports from beside itself,
    and the versions of the symbolic tools. Other models are not part of it (unless one
    imports another): adding or changing a model rewrites only its own files."""
    h = hashlib.sha256()
    mine = model_files(model_module_file)
    base = Path(model_module_file).resolve().parent
    for f in machinery_files():
        h.update(_shown(f).encode())
        h.update(b"\0")
        h.update(f.read_bytes())
    for f in mine:  # the model's file(s), then the helpers it imports from beside itself
        h.update(f.resolve().relative_to(base).as_posix().encode())
        h.update(b"\0")
        h.update(f.read_bytes())
    h.update(json.dumps(tool_versions(), sort_keys=True).encode())
    return h.hexdigest()


GROUP_RESERVED = {"n", "k", "i"}  # the batch entry point's count and loop index, the output loop


def check_names(functions: list[Function]) -> None:
    """Every function, input group, input symbol and output can be emitted: identifiers that
    no keyword, macro or name of the generated code shadows, function names distinct, no
    symbol an input twice and no group named like a symbol of its function."""
    from derive.model import Unsupported
    from derive.names import problem

    seen_fn = set()
    for fn in functions:
        why = problem(fn.name)
        if why:
            raise Unsupported(f"function {fn.name!r} cannot be emitted: {why}")
        if fn.name in seen_fn:
            raise Unsupported(f"function {fn.name!r} is emitted twice (a quantity named like an output kind?)")
        seen_fn.add(fn.name)
        symbols = {str(s) for _, syms in fn.inputs for s in syms}
        seen = set()
        for group, syms in fn.inputs:
            if not IDENT.match(group) or group in GROUP_RESERVED or group in symbols or problem(group) not in (
                    None, "a name the generated code uses for its inputs or loops"):
                raise Unsupported(f"{fn.name}: input group {group!r} cannot be emitted (an identifier that is "
                                  "no keyword, no n, k, i, and not the name of one of its symbols)")
            for s in syms:
                why = None if group == "pval" else problem(str(s))  # pval: the machinery's p
                if why:
                    raise Unsupported(f"{fn.name}: input {s} (in {group}) cannot be emitted: {why}")
                if str(s) in seen:
                    raise Unsupported(f"{fn.name}: input {s} appears twice")
                seen.add(str(s))
        outs = [o for o, _ in fn.outputs]
        for o in outs:
            if not IDENT.match(o) or len(set(outs)) != len(outs):
                raise Unsupported(f"{fn.name}: output {o!r} cannot be emitted (an identifier, once)")
        for o in fn.sparse:
            if o not in outs:
                raise Unsupported(f"{fn.name}: {o!r} is declared sparse but is none of its outputs")


def _operator_dim(functions: list[Function]) -> int:
    """Dimension n of the model's operator (M, D, K), when it has one of n >= 2: the runtime
    then takes the kernels of that dimension (gyro/csrc/), and metadata.json gives them the
    operator's real form ("operator_real_form")."""
    n = max((m.rows for fn in functions if fn.name == "operator" for _, m in fn.outputs), default=0)
    return n if n >= 2 else 0


def _real_form(functions: list[Function]) -> list[int] | None:
    """The operator's real form, when its structure has one: a split of the coordinates into
    two groups (0 and 1 per coordinate) with M and K coupling only coordinates of one group
    and D only coordinates of different groups (no structural nonzero of M or K across the
    groups, none of D within one). Then T = diag(1 on group 0, i on group 1) turns
    J(i w) = K - w^2 M + i w D into the real symmetric T^H J T = K - w^2 M + w S D
    (S D: D with the sign -1 from group 0 to group 1, +1 from 1 to 0) wherever M, K are
    symmetric and D skew: the refinement's LU factors a real matrix. The split is read from
    the patterns of M, K and D's skew part (a damping on D's diagonal vanishes where the
    Hermitian forms hold; the runtime tests each set's whole structure). None where no split
    exists (an odd cycle of couplings)."""
    fn = next((f for f in functions if f.name == "operator"), None)
    if fn is None:
        return None
    mats = {name: sp.Matrix(mat) for name, mat in fn.outputs}
    if set(mats) != {"M", "D", "K"}:
        return None
    n = mats["M"].rows
    D = mats["D"]
    # D's skew (gyroscopic) part: its symmetric (damping) part must vanish for the Hermitian
    # forms anyway, which the runtime tests set by set, as it tests the whole structure
    patterns = ((mats["M"], 0), (mats["K"], 0), (sp.Matrix(n, n, lambda i, j: sp.expand(D[i, j] - D[j, i])), 1))
    edges = [[] for _ in range(n)]  # (neighbour, 0: same group, 1: the other group)
    for mat, parity in patterns:
        for i in range(n):
            for j in range(n):
                if mat[i, j] != 0:
                    edges[i].append((j, parity))
    group: list[int | None] = [None] * n
    for root in range(n):
        if group[root] is not None:
            continue
        group[root], stack = 0, [root]
        while stack:
            i = stack.pop()
            for j, parity in edges[i]:
                want = group[i] ^ parity
                if group[j] is None:
                    group[j] = want
                    stack.append(j)
                elif group[j] != want:
                    return None
    return group


def _newton(functions: list[EmittedFunction], metadata: dict) -> dict | None:
    """Shape of the model's equilibrium Newton iteration (templates/equilibrium.c.j2), when
    its C can do what gyro.equilibrium does: an equilibrium_system (r and K at the
    equilibrium coordinates) that takes (params, qe) alone, r a dense vector and K a dense
    square over the equilibrium coordinates. None otherwise (the runtime then takes its NumPy
    iteration)."""
    system = next((f for f in functions if f.name == "equilibrium_system"), None)
    names, reduced = list(metadata.get("equilibrium_coordinates", [])), list(metadata.get("reduced", []))
    if system is None or not names or not set(names) <= set(reduced):
        return None
    lens = [len(i.symbols) for i in system.inputs]
    ne = len(names)
    outs = {o.name: o for o in system.outputs}
    if (len(lens) != 2 or lens[1] != ne or list(outs) != ["r", "K"] or outs["r"].sparse or outs["K"].sparse
            or outs["r"].size != ne or (outs["K"].rows, outs["K"].cols) != (ne, ne)):
        return None
    units = metadata.get("coordinate_units", {})
    key = [units.get(c) or f"#{i}" for i, c in enumerate(names)]  # as gyro.equilibrium._groups
    return {"ne": ne, "idx": [reduced.index(c) for c in names],
            "angle": [int(units.get(c) == "rad") for c in names],
            "group": [key.index(k) for k in key], "n_params": lens[0]}


def _mode_select(functions: list[Function]) -> dict | None:
    """Shape of the model's mode formulas (modes, candidates, parameters), when it has them:
    the C then also selects and sorts them (templates/mode_select.c.j2)."""
    for fn in functions:
        if fn.name == "mode_formulas":
            omega = dict(fn.outputs)["omega"]
            return {"modes": omega.rows, "cands": omega.cols, "n_params": len(fn.inputs[0][1]),
                    "network": sorting_network(omega.rows)}
    return None


def sorting_network(n: int) -> list[tuple[int, int]]:
    """Batcher's odd-even merge sort of n keys as comparators (a, b), a < b, in order: the
    network for the next power of two with every comparator that touches a key past n
    dropped (those keys count as larger than all, so it would never swap). After it, key a
    is at most key b for every a < b (tests/methods/test_ladder.py checks it on all 0-1 inputs, which
    suffices for a comparator network)."""
    size = 1
    while size < n:
        size *= 2
    out, p = [], 1
    while p < size:
        k = p
        while k >= 1:
            for j in range(k % p, size - k, 2 * k):
                for i in range(min(k, size - j - k)):
                    a, b = i + j, i + j + k
                    if a // (2 * p) == b // (2 * p) and b < n:
                        out.append((a, b))
            k //= 2
        p *= 2
    return out


# calls that are instructions of the compiler's SIMD (no -ffast-math needed to vectorise them)
_VECTOR_CALLS = {"sqrt", "fabs", "fmin", "fmax"}


def _lanes(fn: EmittedFunction) -> dict | None:
    """The C statements of the mode formulas split for a loop over sets in structure of
    arrays (templates/mode_select.c.j2): `pre`, the temporaries that call a function the
    SIMD has no instruction for (cos of the latitude) and those they depend on, computed set
    by set; `post`, the others, computed for all lanes at once. None where an output itself
    makes such a call (the kernel then stays set by set)."""
    names = {t for t, _ in fn.temps}
    calls = lambda e: set(re.findall(r"\b([A-Za-z_]\w*)\s*\(", e)) - _VECTOR_CALLS  # noqa: E731
    if any(calls(e) for o in fn.outputs for _, e in o.entries):
        return None
    deps = {t: set(re.findall(r"\b(t\d+)\b", e)) & names for t, e in fn.temps}
    need, stack = set(), [t for t, e in fn.temps if calls(e)]
    while stack:
        t = stack.pop()
        if t not in need:
            need.add(t)
            stack.extend(deps[t])
    return {"pre": [(t, e) for t, e in fn.temps if t in need],
            "post": [(t, e) for t, e in fn.temps if t not in need],
            "inputs": [(sym, i) for inp in fn.inputs for i, sym in enumerate(inp.symbols)],
            # every entry, zeros written out: a loop inside the lanes' loop would stop its SIMD
            "outputs": {o.name: [(i, dict(o.entries).get(i, "0.0")) for i in range(o.rows * o.cols)]
                        for o in fn.outputs}}


def environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATES)),
        undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True,
        keep_trailing_newline=True, autoescape=False)


def emit(model, functions: list[Function], metadata: dict, outdir: Path, steps=None) -> list[Path]:
    """Write the generated package of one model into outdir (created, files overwritten).
    With more than one job (derive.parallel.JOBS) the functions' CSE and printing are shared
    out among forked workers (the same files to the byte)."""
    import importlib

    import sys

    check_names(functions)
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    module = sys.modules.get(model.module) or importlib.import_module(model.module)
    module_file = Path(module.__file__)
    digest = input_hash(module_file)
    env = environment()
    printers = {"c": CPrinter(), "numpy": NumpyPrinter(), "casadi": CasadiPrinter(),
                "mpmath": MpPrinter()}

    def one(i: int) -> dict:
        fn = functions[i]
        temps, reduced, ops, ops_before = _cse(fn)
        schedule = _schedule(temps, reduced)
        return {key: _printed(fn, temps, reduced, ops, ops_before, printer, schedule if key == "c" else None)
                for key, printer in printers.items()}

    # the largest first, so that the workers finish together
    size = [sum(len(mat) for _, mat in fn.outputs) for fn in functions]
    _TERMS.clear()
    try:
        done = parallel.pmap(one, len(functions), order=sorted(range(len(functions)), key=lambda i: -size[i]))
    finally:
        _TERMS.clear()
    emitted = {k: [d[k] for d in done] for k in printers}
    source = _shown(module_file)
    common = dict(model=model.name, title=model.title, paper=model.source, source=source,
                  digest=digest, versions=tool_versions(), prefix=model.name,
                  select=_mode_select(functions))
    common["newton"] = _newton(emitted["c"], metadata)
    if common["select"]:
        common["select"]["lanes"] = _lanes(next(f for f in emitted["c"] if f.name == "mode_formulas"))
    files = {
        "casadi_functions.py": ("casadi_functions.py.j2", emitted["casadi"]),
        "numpy_functions.py": ("numpy_functions.py.j2", emitted["numpy"]),
        "mpmath_functions.py": ("mpmath_functions.py.j2", emitted["mpmath"]),
        f"{model.name}.h": ("model.h.j2", emitted["c"]),
        f"{model.name}.c": ("model.c.j2", emitted["c"]),
        "__init__.py": ("package_init.py.j2", emitted["numpy"]),
    }
    written = []
    for fname, (template, funcs) in files.items():
        text = env.get_template(template).render(template=template, functions=funcs, **common)
        path = outdir / fname
        path.write_text(text)
        written.append(path)
    meta = dict(metadata)
    meta["generated"] = {"by": "derive", "source": source, "input_hash": digest,
                         "versions": tool_versions()}
    if _operator_dim(functions):  # the kernels' one table from the model (gyro.cbackend)
        meta["operator_real_form"] = _real_form(functions)
    # inputs and outputs as lists, in call order: every backend reads the order from here;
    # a sparse output keeps its matrix's shape and gives the positions of its values
    meta["functions"] = {
        f.name: {"doc": f.doc,
                 "inputs": [{"name": i.name, "symbols": i.symbols} for i in f.inputs],
                 "outputs": [dict({"name": o.name, "shape": [o.rows, o.cols], "vector": o.vector},
                                  **({"nonzeros": o.positions()} if o.sparse else {}))
                             for o in f.outputs],
                 "ops": f.ops, "ops_before_cse": f.ops_before}
        for f in emitted["numpy"]}
    path = outdir / "metadata.json"
    path.write_text(json.dumps(meta, indent=1, sort_keys=True) + "\n")
    written.append(path)
    return written
