"""Names that emitted code can carry: every symbol of a model becomes a C local, a Python
local and a CasADi variable, so it must be an identifier in both languages and must not
collide with the names the templates use (input arrays, temporaries, loop indices, math
functions, keywords). A bad name is refused at derive time with a message naming it."""
from __future__ import annotations

import keyword
import re

import sympy as sp

from derive.model import TIME, Model, Unsupported

IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
C_KEYWORDS = set("""auto break case char const continue default do double else enum extern float
for goto if inline int long register restrict return short signed sizeof static struct switch
typedef union unsigned void volatile while _Bool _Complex _Imaginary""".split())
# input arrays, the operator's argument, loop variables and module names of the templates
TEMPLATE_NAMES = set("""params qe momenta q qd time signals given dgiven constants pval p p_re
p_im z i numpy mpmath ca casadi math""".split())
MATH_NAMES = set("""sin cos tan asin acos atan atan2 sinh cosh tanh exp log log10 sqrt fabs pow
abs floor ceil fmod hypot cbrt erf gamma_fn M_PI NAN INFINITY HUGE_VAL""".split())
TEMP = re.compile(r"t\d+\Z")  # common-subexpression temporaries
# macros of <math.h> (C99 and the GNU and POSIX extensions): a local of that name is
# replaced by the preprocessor
MATH_MACRO = re.compile(r"(M_[A-Za-z0-9_]+|FP_[A-Z_]+|MATH_ERR[A-Z]*|math_errhandling|HUGE_VAL[FL]?|"
                        r"INFINITY|NAN|isnan|isinf|isfinite|isnormal|signbit|fpclassify)\Z")


def _printer_reserved() -> set:
    """Words the SymPy printers of the emitter rename (C99 prints `entry` as `entry_`)."""
    from sympy.printing.c import C99CodePrinter
    from sympy.printing.pycode import MpmathPrinter, PythonCodePrinter

    return set(C99CodePrinter.reserved_words) | set(PythonCodePrinter.reserved_words) | set(
        MpmathPrinter.reserved_words)


def problem(name: str) -> str | None:
    """None if `name` can be emitted, else why not."""
    if not IDENTIFIER.match(name):
        return "not an identifier (letters, digits and _, starting with a letter)"
    if (name in C_KEYWORDS or keyword.iskeyword(name) or keyword.issoftkeyword(name)
            or name in _printer_reserved()):
        return "a keyword of C or Python"
    if name in TEMPLATE_NAMES:
        return "a name the generated code uses for its inputs or loops"
    if name in MATH_NAMES or MATH_MACRO.match(name):
        return "the name of a math function or constant of the generated code"
    if TEMP.match(name) or name.startswith("out_"):
        return "the form of the generated code's temporaries and outputs (t0, t1, ..., out_*)"
    return None


def momentum_inputs(model: Model) -> list:
    """Cyclic momenta that are inputs of the emitted functions: symbols, not parameters
    (a momentum given as a number, 0 say, is a constant of the derivation)."""
    return [s for s in model.cyclic.values()
            if isinstance(s, sp.Symbol) and s not in model.symbols]


def model_symbols(model: Model) -> list[tuple[str, object]]:
    """(what, symbol) for every symbol that the emitted functions can take as input."""
    out = [("parameter", p.symbol) for p in model.parameters]
    out += [("coordinate", x) for x in model.q] + [("velocity", x) for x in model.qd]
    out += [("acceleration", x) for x in model.qdd]
    out += [("momentum", s) for s in momentum_inputs(model)]
    out += [("signal", s) for s in model.signal_symbols]
    out += [("given value", s) for s in model.given_values + model.given_derivatives]
    out += [("given constant", s) for s in model.given_constants]
    return out


def check_model(model: Model) -> None:
    """Every symbol emittable, none twice, the model's name a C and Python identifier, and
    the time symbol used for time only."""
    bad = problem(model.name) if model.name not in TEMPLATE_NAMES else "a name the generated code uses"
    if bad:
        raise Unsupported(f"{model.name}: the model's name cannot be emitted: {bad}")
    seen = {}
    for what, s in model_symbols(model):
        name = str(s)
        if s == TIME:
            raise Unsupported(f"{model.name}: {what} {name!r}: t is time, reserved for explicit time")
        why = problem(name)
        if why:
            raise Unsupported(f"{model.name}: {what} {name!r} cannot be emitted: {why}")
        if name in seen:
            raise Unsupported(f"{model.name}: {what} {name!r} has the name of a {seen[name]}")
        seen[name] = what
    n = len(model.coordinates)
    if not (len(model.q) == len(model.qd) == len(model.qdd) == n):
        raise Unsupported(f"{model.name}: {n} coordinates but {len(model.q)} q, {len(model.qd)} qd, "
                          f"{len(model.qdd)} qdd")
    for c in model.symmetric_zero:
        if c not in model.coordinates:
            raise Unsupported(f"{model.name}: symmetric_zero names {c!r}, not a coordinate")
    for sig in model.signals:
        if not sig.order >= 0:
            raise Unsupported(f"{model.name}: signal {sig.name!r} has a negative order")
