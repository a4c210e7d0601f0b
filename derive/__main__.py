"""`python -m derive [--out DIR] [MODEL ...]` derives and emits the models of derive/models/;
`python -m derive --model PATH.py --out DIR` a model file that lives anywhere. Each model goes
to DIR/<name>/, step by step with the time of each step."""
from __future__ import annotations

import os

# no BLAS threads: the derivation has no use for them, and --jobs forks this process
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import gc  # noqa: E402
import hashlib  # noqa: E402
import importlib  # noqa: E402
import importlib.util  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from contextlib import contextmanager  # noqa: E402
from pathlib import Path  # noqa: E402

from derive import convert, emit, parallel, pipeline  # noqa: E402
from derive.model import Model, Unsupported  # noqa: E402
from derive.models import MODELS  # noqa: E402


class NotAModel(ValueError):
    """A file or module that does not define a model; the message is one line."""


def _helper_of(name: str, module, folder: Path) -> bool:
    """A module that `import NAME` resolved from the model's folder (sys.path[0] while the
    model runs): NAME's top-level part is a file or package of that folder. The machinery
    (derive) and installed packages are never a model's helpers."""
    top = name.split(".", 1)[0]
    where = getattr(module, "__file__", None)
    if top == "derive" or name.startswith(PRIVATE) or not where:
        return False
    where = Path(where).resolve()
    return where == folder / f"{top}.py" or (folder / top) in where.parents


PRIVATE = "_derive_model_"
_OWN: dict[Path, dict] = {}  # model folder -> the helper modules imported from it


@contextmanager
def namespace(module_or_folder):
    """Run a model's import, build() and derivation with its own folder first on sys.path
    and its own helper modules in sys.modules: a `springs.py` beside one model is never
    the `springs` of another derived in the same call. Modules of that name loaded from
    elsewhere are set aside meanwhile and put back after."""
    folder = getattr(module_or_folder, "__derive_folder__", module_or_folder)
    if not isinstance(folder, Path):  # a model of derive/models/: package-qualified imports
        yield
        return
    own = _OWN.setdefault(folder, {})
    names = {p.stem for p in folder.glob("*.py")} | {p.name for p in folder.iterdir() if p.is_dir()}
    aside = {k: v for k, v in sys.modules.items()
             if k.split(".", 1)[0] in names and own.get(k) is not v and not _helper_of(k, v, folder)
             and not k.startswith(("derive", PRIVATE))}
    for k in aside:
        del sys.modules[k]
    sys.modules.update(own)
    present = set(sys.modules)
    sys.path.insert(0, str(folder))
    importlib.invalidate_caches()
    try:
        yield
    finally:
        sys.path.remove(str(folder))
        for k, v in list(sys.modules.items()):
            if (k in own or k not in present) and _helper_of(k, v, folder):
                own[k] = v
                del sys.modules[k]
        sys.modules.update(aside)


def load_file(path: str | Path):
    """The module of a model file (or of a model folder's __init__.py) anywhere on disk,
    registered under a private name of its own (its stem and a digest of its path: two
    folders may hold a model of the same name), imported in its own namespace."""
    path = Path(path).resolve()
    if path.is_dir():
        path = path / "__init__.py"
    if not path.is_file():
        raise NotAModel(f"{path}: no such model file")
    if path.suffix != ".py":
        raise NotAModel(f"{path}: a model file is a Python file (.py)")
    stem = path.parent.name if path.name == "__init__.py" else path.stem
    modname = f"{PRIVATE}{stem}_{hashlib.sha256(str(path).encode()).hexdigest()[:12]}"
    spec = importlib.util.spec_from_file_location(
        modname, path, submodule_search_locations=[str(path.parent)] if path.name == "__init__.py" else None)
    module = importlib.util.module_from_spec(spec)
    module.__derive_folder__ = path.parent
    sys.modules[modname] = module
    try:
        with namespace(module):
            spec.loader.exec_module(module)
    except Exception as exc:  # a model file's own error, reported in one line
        del sys.modules[modname]
        raise NotAModel(f"{path}: importing it failed: {type(exc).__name__}: {_first_line(exc)}") from exc
    return module


def _first_line(exc) -> str:
    return str(exc).splitlines()[0] if str(exc) else ""


def build(module) -> Model:
    """The Model that a module's build() returns, checked to be one."""
    where = getattr(module, "__file__", module.__name__)
    if not callable(getattr(module, "build", None)):
        raise NotAModel(f"{where}: not a model: it defines no build() function")
    collecting = gc.isenabled()
    gc.disable()  # the points of the bodies build() formed its Lagrangian of live until taken
    try:
        with namespace(module):
            model = module.build()
        if isinstance(model, Model):
            model._live_points = convert.live_points(model)  # noqa: SLF001 - read by convert
    except Unsupported:
        raise
    except Exception as exc:  # the model file's own error, in one line
        raise NotAModel(f"{where}: build() failed: {type(exc).__name__}: {_first_line(exc)}") from exc
    finally:
        if collecting:
            gc.enable()
    if not isinstance(model, Model):
        raise NotAModel(f"{where}: not a model: build() returned {type(model).__name__}, not derive.model.Model")
    if sys.modules.get(model.module) is not module:
        model.module = module.__name__  # the emitter hashes the file this module came from
    return model


def _source_size(module) -> int:
    try:
        return Path(module.__file__).stat().st_size
    except (AttributeError, TypeError, OSError):
        return 0


def _name(module, model) -> str:
    """A job's model name: the built model's, or a seed model's module name (its own)."""
    return model.name if model else module.__name__.rsplit(".", 1)[-1]


def _derive_one(module, model, out: Path) -> str | None:
    """Derive and emit one model into out/<name>/, each step with its time on stderr, its
    emission shared out as derive.parallel.JOBS says. Returns None, or the one line that
    says why it failed."""
    name = _name(module, model)
    steps = pipeline.Steps(prefix=f"[{name}] ")
    try:
        with steps("model: energies and parameters"):
            model = model or build(module)
        with namespace(module):  # identities and quantities may import helpers late
            deriv = pipeline.derive(model, steps)
            with steps("functions to emit"):
                fns = pipeline.functions(deriv)
            with steps("emit: CSE, CasADi, NumPy, mpmath, C through the templates"):
                files = emit.emit(model, fns, pipeline.metadata(deriv), out / model.name)
    except (Unsupported, NotAModel) as exc:
        msg = str(exc) if str(exc).startswith(f"{name}: ") else f"{name}: {exc}"
        return msg.splitlines()[0] if msg else msg
    except Exception as exc:  # what no check foresaw: still one line, naming the step
        step = steps.current or "derivation"
        return f"{name}: {step} failed: {type(exc).__name__}: {_first_line(exc)}"
    sys.stderr.write(f"[{name}] {len(files)} files in {out / model.name}; {steps.total:.1f} s\n")  # one write
    sys.stderr.flush()
    return None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m derive", description=__doc__)
    ap.add_argument("models", nargs="*", help=f"models to derive (default: all of {', '.join(MODELS)})")
    ap.add_argument("--model", metavar="PATH.py", action="append", default=[],
                    help="a model file (or folder) anywhere; may be repeated")
    ap.add_argument("--out", default="generated", help="output folder (default: generated)")
    ap.add_argument("--input-hash", metavar="PATH.py", dest="input_hash",
                    help="print the hash of what a derivation of this model file (or folder) reads, as a "
                         "generated package's metadata.json carries it (generated.input_hash), and stop")
    ap.add_argument("--jobs", type=int, default=1, metavar="N",
                    help="cores to use (Linux): up to N models side by side, each sharing the emission "
                         "of its functions among up to N workers of its own (default 1; this machine "
                         f"has {parallel.usable_cores()})")
    args = ap.parse_args(argv)
    if args.input_hash is not None:
        return _input_hash(Path(args.input_hash))
    if args.jobs < 1:
        print(f"derive: --jobs must be at least 1, got {args.jobs}", file=sys.stderr)
        return 2
    before, parallel.JOBS = parallel.JOBS, args.jobs  # where the derivation's workers take it from
    try:
        return _main(args)
    finally:
        parallel.JOBS = before  # called in a process that goes on (a session, a test)


def _input_hash(path: Path) -> int:
    """The emitter's input hash of a model file, read without importing it: what the runtime
    compares with a generated package's before deriving a file that may be its source."""
    path = path.resolve()
    if path.is_dir():
        path = path / "__init__.py"
    if not path.is_file():
        print(f"derive: {path}: no such model file", file=sys.stderr)
        return 2
    print(emit.input_hash(path))
    return 0


def _main(args) -> int:
    for name in args.models:
        if name not in MODELS:
            print(f"derive: unknown model {name!r}; known: {', '.join(MODELS)}", file=sys.stderr)
            return 2
    try:
        modules = [load_file(p) for p in args.model]
        jobs = [(m, build(m)) for m in modules]
    except NotAModel as exc:
        print(f"derive: {exc}", file=sys.stderr)
        return 2
    if not args.model or args.models:
        for name in args.models or list(MODELS):
            module = importlib.import_module(MODELS[name])
            jobs.append((module, None))
    t_all = time.perf_counter()
    out = Path(args.out)
    names = [_name(module, model) for module, model in jobs]
    if args.jobs == 1 or len(set(names)) < len(names):
        # one at a time, stopping at the first that fails; and where two models of one name
        # go to one folder, so that the last one named is the one left there, as asked
        failures = []
        for module, model in jobs:
            failures.append(_derive_one(module, model, out))
            if failures[-1]:
                break
    else:
        # each model's worker shares its emission out too (the models finish at different
        # times); the longest model file first, a rough measure of its work
        size = [_source_size(m) for m, _ in jobs]
        try:
            failures = parallel.pmap(lambda i: _derive_one(*jobs[i], out), len(jobs),
                                     order=sorted(range(len(jobs)), key=lambda i: -size[i]))
        except parallel.WorkerDied as exc:  # killed (out of memory, a signal): no result to report
            print(f"derive: {exc}", file=sys.stderr)
            return 2
    for failure in failures:  # the first in the models' order
        if failure:
            print(f"derive: {failure}", file=sys.stderr)
            return 2
    (out / "__init__.py").write_text(emit.environment().get_template("generated_init.py.j2").render())
    print(f"derive: done in {time.perf_counter() - t_all:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
