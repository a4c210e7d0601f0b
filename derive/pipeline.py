"""The derivation as passes over a `Model` (derive/passes/, each printed with its time as
it goes), and what the output kinds of `derive/outputs/` make of its result:

model -> conversion -> holonomic constraints (eliminated, or the multipliers route) ->
kinks -> checks (what the machinery supports, names) -> identities -> equations of motion
with generalised forces, explicit time and signals -> Routh reduction of cyclic
coordinates -> equations of the reference (rest, a relative equilibrium, or a declared
steady motion) -> linear operator by two routes (must agree) -> input matrix B ->
approximate variants -> kinks thawed -> equations in speeds; then the functions to emit
and the metadata, contributed by the output kinds.
"""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager

from derive import passes
from derive.derivation import Derivation, VariantResult  # noqa: F401  (pipeline.Derivation, as before)
from derive.model import Function, Model, Unsupported, runtime_module
from derive.passes.variants import P_SYMBOL, Z_SYMBOL  # noqa: F401  (pipeline.P_SYMBOL, as before)

passes.passes()  # the pass modules imported with the pipeline, not within the first derivation


class Steps:
    """Prints each step of a long run with its duration, as it goes."""

    def __init__(self, out=sys.stderr, prefix=""):
        self.out, self.prefix, self.timings = out, prefix, []
        self.t_start = time.perf_counter()
        self.current = None  # the step running, for a one-line report of its failure

    @contextmanager
    def __call__(self, name: str):
        t0 = time.perf_counter()
        self._say(f"{self.prefix}{name} ...")
        self.current = name
        yield
        self.current = None
        dt = time.perf_counter() - t0
        self.timings.append((name, dt))
        self._say(f"{self.prefix}{name}: {dt:.2f} s")

    def _say(self, line: str) -> None:
        """One line in one write (print's text and newline are two, and a worker stopped
        between them left a line without its end, which the parent's error then joined)."""
        self.out.write(line + "\n")
        self.out.flush()

    @property
    def total(self) -> float:
        return time.perf_counter() - self.t_start


def derive(model: Model, steps: Steps | None = None) -> Derivation:
    """The derivation of `model`: the passes of derive/passes/ in their order, each a
    function (model, derivation) -> derivation, each step printed with its time."""
    d = Derivation(model)
    d.work.steps = steps or Steps()
    return passes.run(d)


def functions(d: Derivation) -> list[Function]:
    """The functions to emit for a derived model: each output kind of `derive/outputs/`
    contributes its own, in the kinds' order."""
    from derive import outputs

    # in this process: built in a worker and pickled back, SymPy's expressions come back
    # equal but not always in the same form, and their CSE then differs (tried: 1019
    # against 1026 operations in one function)
    fns = []
    for kind in outputs.kinds():
        fns.extend(kind.functions(d))
    return fns


def metadata(d: Derivation) -> dict:
    """JSON-serialisable facts the runtime needs without SymPy."""
    from derive import outputs

    model = d.model
    meta = {
        "model": model.name,
        "title": model.title,
        "paper": model.source,
        "parameters": [
            {"name": p.name, "unit": p.unit, "default": p.default, "description": p.description,
             "kind": p.kind, "bounds": list(p.bounds)} for p in model.parameters],
        "coordinates": model.coordinates,
        "coordinate_units": model.coordinate_units,
        "cyclic": {c: str(s) for c, s in model.cyclic.items()},
        "momenta": [str(s) for s in d.momenta],
        "reduced": d.order,
        "equilibrium_coordinates": [str(x) for x in d.even],
        "symmetric_zero": model.symmetric_zero,
        "given": [str(s) for s in model.given_values + model.given_derivatives + model.given_constants],
        "route_agreement": d.route_agreement,
    }
    if d.constraints:
        meta["constraints"] = d.constraints
    if d.nondifferentiable:
        meta["nondifferentiable"] = [{"term": t, "argument_at_reference": a}
                                     for t, a in sorted(d.nondifferentiable.items())]
    if model.aliases:
        unknown = sorted(set(model.aliases.values()) - {p.name for p in model.parameters})
        if unknown:
            raise Unsupported(f"aliases name no parameter: {', '.join(unknown)}")
        meta["aliases"] = dict(model.aliases)
    if model.simulate:
        meta["simulate"] = simulate_declaration(model)
    for kind in outputs.kinds():
        meta.update(getattr(kind, "metadata", lambda _: {})(d))
    return meta


SIMULATE_KEYS = {"module", "options", "usage", "initial"}
SIMULATE_OPTIONS = ("perturb", "method", "level", "base_rate")


def simulate_declaration(model) -> dict:
    """Model.simulate checked: a dotted module name, options among SIMULATE_OPTIONS."""
    decl = dict(model.simulate)
    unknown = sorted(set(decl) - SIMULATE_KEYS)
    if unknown:
        raise Unsupported(f"simulate: unknown keys {unknown}; known: {', '.join(sorted(SIMULATE_KEYS))}")
    module = decl.get("module")
    if not isinstance(module, str) or not all(part.isidentifier() for part in module.split(".")):
        raise Unsupported(f"simulate: 'module' must be a dotted module name, got {module!r}")
    options = list(decl.get("options", []))
    bad = [o for o in options if o not in SIMULATE_OPTIONS]
    if bad:
        raise Unsupported(f"simulate: unknown options {bad}; known: {', '.join(SIMULATE_OPTIONS)}")
    return {"module": runtime_module(model, module), "options": options, "usage": str(decl.get("usage", "")),
            "initial": str(decl.get("initial", ""))}
