"""Loading a generated model and turning user input into a validated parameter vector."""
from __future__ import annotations

import importlib
import importlib.util
import json
import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from gyro.catalog import GENERATED_PACKAGE, available, generated_dir, metadata  # noqa: F401
from gyro.errors import ParameterError

GENERATED = generated_dir()


@dataclass(frozen=True)
class Param:
    name: str
    unit: str
    default: float
    description: str
    kind: str
    bounds: tuple

    def check(self, value: float) -> None:
        if not math.isfinite(value):
            raise ParameterError(f"parameter {self.name}: must be a finite number, got {value!r}")
        if self.kind == "positive" and not value > 0:
            raise ParameterError(f"parameter {self.name} ({self.description}) must be positive, got {value!r}")
        if self.kind == "nonnegative" and not value >= 0:
            raise ParameterError(f"parameter {self.name} ({self.description}) must be non-negative, got {value!r}")
        lo, hi = self.bounds
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            raise ParameterError(f"parameter {self.name} ({self.description}) must lie in "
                                 f"[{lo}, {hi}] {self.unit}, got {value!r}")


class Model:
    """A generated model: its metadata and its NumPy and CasADi functions.

    `Model(name)` is a model of the repository's generated/; `Model(name, directory)` one
    that `python -m derive --model PATH.py --out DIR` emitted into directory = DIR/<name>."""

    def __init__(self, name: str, directory: Path | None = None):
        if directory is None:
            known = available()
            if name not in known:
                raise ParameterError(f"unknown model {name!r}; known: {', '.join(known)}")
            package = f"{GENERATED_PACKAGE}.{name}"
            self.directory = GENERATED / name
        else:
            self.directory = Path(directory).resolve()
            if not (self.directory / "metadata.json").exists():
                raise ParameterError(f"{self.directory}: no generated model there (no metadata.json)")
            package = _import_directory(self.directory)
        pkg = importlib.import_module(package)
        if not isinstance(pkg.METADATA, dict) or "parameters" not in pkg.METADATA or "model" not in pkg.METADATA:
            raise ParameterError(f"{self.directory / 'metadata.json'}: not a generated model's metadata "
                                 "(no model or parameters)")
        if pkg.METADATA["model"] != name:
            raise ParameterError(f"{self.directory} holds the model {pkg.METADATA['model']!r}, not {name!r}")
        self.package = package
        self.name = name
        self.meta = pkg.METADATA
        try:
            self.params = [Param(p["name"], p["unit"], p["default"], p["description"], p["kind"],
                                 tuple(p["bounds"])) for p in self.meta["parameters"]]
        except (KeyError, TypeError, ValueError) as exc:
            raise ParameterError(f"{self.directory / 'metadata.json'}: not a generated model's metadata "
                                 f"(its parameters: {_reason(exc)})") from None
        self.param_names = [p.name for p in self.params]
        # the folder of the model file it was loaded from (load() sets it for a model file;
        # else the checkout's, where the metadata names a source inside it): where a
        # declared "file:" module is found (gyro.catalog.declared_module)
        self.source_folder = _declared_source_folder(self.meta)

    @cached_property
    def numpy(self):
        """The generated NumPy functions (imported on first use: the compiled path needs none)."""
        return importlib.import_module(f"{self.package}.numpy_functions")

    @cached_property
    def casadi(self):
        return importlib.import_module(f"{self.package}.casadi_functions")

    @cached_property
    def mpmath(self):
        return importlib.import_module(f"{self.package}.mpmath_functions")

    @property
    def defaults(self) -> dict[str, float]:
        return {p.name: p.default for p in self.params}

    def canonical(self, name: str) -> str:
        """A parameter's own name for a name a user typed (its alias, as the paper's lambda for
        the symbol lam), or the name itself."""
        return self.meta.get("aliases", {}).get(name, name)

    @property
    def aliases(self) -> dict[str, str]:
        """{another name a command takes: the declared parameter it names} (the paper's lambda
        for lam, M_motor for Mmotor). Every command prints the declared name and takes both."""
        return dict(self.meta.get("aliases", {}))

    def known_names(self) -> str:
        """The declared parameter names, and the other names taken for them."""
        also = ", ".join(f"{a} for {n}" for a, n in self.aliases.items())
        return " ".join(self.param_names) + (f" (also {also})" if also else "")

    def param_name(self, name: str, what: str = "parameter") -> str:
        """The declared name of the parameter a user named, by that name or another name taken
        for it (`aliases`); a ParameterError naming `what` (an option: --x, --spin) otherwise."""
        key = self.canonical(name)
        if key not in self.param_names:
            raise ParameterError(f"{what} {name!r}: unknown parameter; known: {self.known_names()}")
        return key

    def named(self, values: dict) -> dict:
        """Values by the declared names, and also under each other name a command printed them
        by before (the JSON of `gyro stability` and `gyro simulate` keyed lambda and M_motor):
        their readers keep their keys."""
        out = {k: float(v) for k, v in values.items()}
        out.update({a: out[n] for a, n in self.aliases.items() if n in out})
        return out

    def parameters(self, overrides: dict | None = None) -> dict[str, float]:
        """Every parameter's value: the paper example's, replaced by `overrides`; validated."""
        values = self.defaults
        by_name = {p.name: p for p in self.params}
        given = {}
        for typed, raw in (overrides or {}).items():
            key = self.canonical(typed)  # a name typed for a symbol the code cannot carry
            if key in given and given[key] != typed:
                raise ParameterError(f"parameter {key}: given twice (as {given[key]} and {typed})")
            given[key] = typed
            if key not in by_name:
                raise ParameterError(f"unknown parameter {key!r} for {self.name}; known: {self.known_names()}")
            try:
                value = float(raw)
            except (TypeError, ValueError):
                raise ParameterError(f"parameter {key}: not a number: {raw!r}") from None
            by_name[key].check(value)
            values[key] = value
        return values

    def vector(self, values: dict[str, float] | None = None) -> np.ndarray:
        """The parameter vector, in the order of param_names: the given values, validated,
        and the paper example's for the others; an unknown name is a ParameterError
        naming it."""
        v = self.parameters(values)
        return np.array([v[n] for n in self.param_names], dtype=float)

    def vectors(self, batch: list[dict]) -> np.ndarray:
        """Parameter vectors of several sets (rows), each completed as `vector` does."""
        return np.array([self.vector(v) for v in batch], dtype=float)


def has_operator(meta: dict) -> bool:
    """A model whose operator is about a relative equilibrium of its parameters (not of
    momenta given as inputs): what frequencies, sweeps, maps, tolerances and the implicit
    exact level (gyro.levels) need."""
    return "operator" in meta.get("functions", {}) and not meta.get("momenta")


def _declared_source_folder(meta: dict) -> Path | None:
    """The folder of the model's source file as its metadata names it (relative to the
    source checkout), where this runtime runs from that checkout and the file is there."""
    source = (meta.get("generated") or {}).get("source")
    root = _source_root()
    if not isinstance(source, str) or root is None or not (root / source).is_file():
        return None
    return (root / source).parent


def _import_directory(directory: Path) -> str:
    """Import a generated package from a folder anywhere, under a private name."""
    import hashlib
    import importlib.util
    import sys

    name = "_gyro_model_" + hashlib.sha256(str(directory).encode()).hexdigest()[:12]
    if name not in sys.modules:
        meta = directory / "metadata.json"
        try:
            json.loads(meta.read_text())
        except (OSError, ValueError) as exc:  # the file named, not the package's __init__ that reads it
            raise ParameterError(f"{meta}: not a generated model's metadata ({_reason(exc)})") from None
        spec = importlib.util.spec_from_file_location(name, directory / "__init__.py",
                                                      submodule_search_locations=[str(directory)])
        if spec is None:
            raise ParameterError(f"{directory}: no generated model there (no __init__.py)")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        saved = sys.dont_write_bytecode
        sys.dont_write_bytecode = True  # nothing written beside the user's files
        try:
            spec.loader.exec_module(module)
            if not isinstance(getattr(module, "METADATA", None), dict):
                raise ParameterError(f"{directory / '__init__.py'}: not a generated model's package (no METADATA)")
        except BaseException as exc:
            del sys.modules[name]  # a half-imported package is not kept: the next load fails alike
            if isinstance(exc, ParameterError) or not isinstance(exc, Exception):
                raise
            raise ParameterError(f"{directory}: not a generated model ({_reason(exc)})") from None
        finally:
            sys.dont_write_bytecode = saved
    return name


def _reason(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


_CACHE: dict[str, Model] = {}


def load(name: str | Path) -> Model:
    """A model by what names it (gyro.catalog.model_source): a generated model's name
    (generated/<name>); the folder it was emitted into (DIR/<name> from `python -m derive
    --model PATH.py --out DIR`); or a model file PATH.py (or a model folder), derived on
    first use into the cache by the hash of its inputs (derived_folder). A model loaded
    from a path is known by its name for the rest of the session; the compiled backend
    finds it by that name."""
    from gyro.catalog import model_source

    text = str(name)
    if not isinstance(name, Path) and text in _CACHE:  # by name: the model loaded under it (the
        return _CACHE[text]                            # compiled backend's look-up, once per call)
    kind = model_source(text)
    if kind == "builtin" and not isinstance(name, Path):
        _CACHE[text] = Model(text)
        return _CACHE[text]
    if kind is None:
        if not isinstance(name, Path) and "/" not in text and "\\" not in text and not text.endswith(".py"):
            raise ParameterError(f"unknown model {text!r}; known: {', '.join(available())}, "
                                 "or a model file PATH.py, or an emitted folder DIR/<name>")
        if Path(text).expanduser().exists():
            raise ParameterError(f"{text}: not a model (neither a model file *.py, nor a folder with "
                                 "a metadata.json or an __init__.py)")
        raise ParameterError(f"{text}: no such model file or folder")
    directory = (derived_folder(Path(text).expanduser()) if kind == "file"
                 else Path(text).expanduser().resolve())
    model_name = directory.name
    known = _CACHE.get(model_name)
    if known is None or known.directory != directory:
        # a model file whose derivation is a generated package (derived_folder): that model
        builtin = kind == "file" and directory == GENERATED / model_name
        _CACHE[model_name] = Model(model_name) if builtin else Model(model_name, directory)
    if kind == "file":  # this file's folder, wherever a derivation in the cache was made from
        source = Path(text).expanduser().resolve()
        _CACHE[model_name].source_folder = source if source.is_dir() else source.parent
    return _CACHE[model_name]


def _source_root() -> Path | None:
    """The source checkout this runtime runs from (it has derive/ beside gyro/), or None
    (an installed wheel carries no derive/)."""
    root = Path(__file__).resolve().parent.parent
    return root if (root / "derive" / "__main__.py").is_file() and (root / "templates").is_dir() else None


def model_key(path: Path, root: Path) -> str:
    """The hash of everything a derivation of the model file `path` reads: the file (or the
    model folder's Python files), the Python files beside it and in the packages beside it
    (a model file may import them), the machinery (derive/, templates/) and the versions of the symbolic tools."""
    import hashlib
    from importlib.metadata import PackageNotFoundError, version

    h = hashlib.sha256()
    path = path.resolve()
    own = sorted(path.glob("*.py")) if path.is_dir() else [path] + sorted(
        p for p in path.parent.glob("*.py") if p != path)
    # and the packages beside it (a folder with an __init__.py a model file may import from):
    # every Python file in them, as the emitter's input hash has every module imported
    home = path if path.is_dir() else path.parent
    own += sorted(p for d in sorted(home.iterdir()) if d.is_dir() and (d / "__init__.py").is_file()
                  for p in d.rglob("*.py") if "__pycache__" not in p.parts)
    machinery = sorted(p for p in (root / "derive").rglob("*.py") if "__pycache__" not in p.parts)
    machinery += sorted(p for p in (root / "templates").iterdir() if p.is_file())
    for p in own + machinery:
        try:
            data = p.read_bytes()
        except FileNotFoundError:  # removed since the listing (an editor's or a test's temporary file)
            continue
        h.update(str(p.relative_to(root) if p.is_relative_to(root) else p).encode() + b"\0")
        h.update(data + b"\0")
    for dist in ("sympy", "symengine", "casadi", "jinja2"):  # derive.emit's TOOL_VERSIONS
        try:
            h.update(f"{dist}={version(dist)}".encode())
        except PackageNotFoundError:
            pass
    return h.hexdigest()[:20]


def derived_folder(path: Path) -> Path:
    """The emitted folder of a model file, derived on first use by `python -m derive --model`
    (in a subprocess: the runtime imports no SymPy) into <cache>/models/<key>/<name>, where
    key = model_key; said in one line on stderr. A file that is not a model, or that the
    machinery refuses, is a ParameterError carrying derive's one line; without SymPy or
    without the build-time side, one line naming what to install."""
    import importlib.util
    import os
    import shutil
    import subprocess
    import sys

    from gyro.catalog import cache_dir

    root = _source_root()
    if root is None:
        raise ParameterError(f"{path}: deriving a model file needs the build-time side (derive/, "
                             "in a source checkout of gyro-dynamics installed with its [derive] extra)")
    if importlib.util.find_spec("sympy") is None or importlib.util.find_spec("symengine") is None:
        raise ParameterError(f"{path}: deriving a model file needs SymPy: install the [derive] extra "
                             "(pip install -e '.[derive]')")
    home = cache_dir() / "models"
    done = home / model_key(path, root)
    found = [d for d in done.iterdir() if (d / "metadata.json").is_file()] if done.is_dir() else []
    if len(found) == 1:
        return found[0]
    failed = home / f"{done.name}.failed"  # a file the machinery refused: the same inputs, the same line
    if failed.is_file():
        raise ParameterError(failed.read_text().strip())
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1",  # no __pycache__ beside the user's file
               PYTHONPATH=os.pathsep.join([str(root)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    twin = generated_twin(path, root, home / f"{done.name}.generated", env)
    if twin is not None:
        return GENERATED / twin
    home.mkdir(parents=True, exist_ok=True)
    tmp = home / f"{done.name}.tmp-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    notice = _Notice(f"gyro: deriving {_stem(path)} from {path} (first use, {_why(path, root)}cached after in {done})")
    try:
        proc = subprocess.run([sys.executable, "-m", "derive", "--model", str(path.resolve()), "--out", str(tmp)],
                              cwd=root, env=env, capture_output=True, text=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        notice.end(failed=True)
        raise
    if proc.returncode != 0:
        shutil.rmtree(tmp, ignore_errors=True)
        notice.end(failed=True)
        lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()]
        last = lines[-1] if lines else f"exit status {proc.returncode}"
        if proc.returncode == 2:
            message = last.removeprefix("derive: ")
            try:
                if "ModuleNotFoundError" in message or "ImportError" in message:
                    raise OSError("not cached: installing what it imports may mend it")  # written whole or not at all: a concurrent run reads the line or nothing
                part = home / f"{failed.name}.tmp-{os.getpid()}"
                part.write_text(message + "\n")
                os.replace(part, failed)
            except OSError:
                pass
            raise ParameterError(message)
        raise RuntimeError(f"deriving {path} failed: {last}")
    notice.end(failed=False)
    made = [d for d in tmp.iterdir() if (d / "metadata.json").is_file()]
    try:
        os.replace(tmp, done)  # atomic: a concurrent run that finished first keeps its copy
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)
    return done / made[0].name


def generated_twin(path: Path, root: Path, marker: Path, env: dict) -> str | None:
    """The generated model whose package a derivation of the model file `path` would give,
    or None: the one whose metadata's input hash (derive.emit.input_hash: the machinery,
    the templates, the model's own file(s) by their names, the tool versions) equals this
    file's. Same inputs, same bytes (make check-generated), so that package is the answer
    and nothing is derived: a generated model's own source file, or a byte-identical copy
    of it under the same name elsewhere; a file that differs by one byte derives its own.
    The hash is computed by `python -m derive --input-hash` (about a second, the runtime
    imports no derive/) only where a generated model's source has this file's name, and
    is kept in `marker` (under the runtime's own key of the file), checked again against
    the generated package at each use: a package derived again since is not taken."""
    import os
    import subprocess
    import sys

    own = path.resolve() / "__init__.py" if path.is_dir() else path.resolve()
    hashes = {n: metadata(n).get("generated", {}) for n in available()}
    hashes = {n: g["input_hash"] for n, g in hashes.items()
              if isinstance(g, dict) and Path(str(g.get("source", ""))).name == own.name and g.get("input_hash")}
    if not hashes:
        return None
    try:
        name, digest = marker.read_text().split()
        if hashes.get(name) == digest:
            return name
    except (OSError, ValueError):
        pass
    proc = subprocess.run([sys.executable, "-m", "derive", "--input-hash", str(own)],
                          cwd=root, env=env, capture_output=True, text=True)
    digest = proc.stdout.strip() if proc.returncode == 0 else None
    name = next((n for n, h in hashes.items() if h == digest), None)
    if name is not None:
        try:  # written whole or not at all
            marker.parent.mkdir(parents=True, exist_ok=True)
            part = marker.with_name(f"{marker.name}.tmp-{os.getpid()}")
            part.write_text(f"{name} {digest}\n")
            os.replace(part, marker)
        except OSError:
            pass
    return name


def _stem(path: Path) -> str:
    return path.resolve().parent.name if path.is_dir() or path.name == "__init__.py" else path.stem


def _why(path: Path, root: Path) -> str:
    """What a first derivation of `path` is, when it is a generated model's own source file
    (and derives nevertheless: generated/ is not this file's derivation, generated_twin)."""
    own = root / "derive" / "models" / f"{_stem(path)}.py"
    if path.resolve() == own.resolve() and _stem(path) in available():
        return (f"about a minute: generated/{_stem(path)} was derived from other inputs (`make derive` "
                "brings it up to date); ")
    return ""


class _Notice:
    """The one line said while a model file is derived: on a terminal at once, erased when
    the derivation fails (the error is then the one line left); elsewhere only once the
    derivation has taken NOTICE_AFTER seconds (a file that is no model fails within about
    one: its line is then the only one), a one-off notice before the command's own output.
    A failure is cached, so the next call says its one line only."""

    NOTICE_AFTER = 2.0  # s

    def __init__(self, text: str):
        import sys
        import threading

        self.tty, self.timer = sys.stderr.isatty(), None
        if self.tty:
            print(text + " ...", end="", file=sys.stderr, flush=True)
        else:
            stream = sys.stderr  # the stream of the caller's moment (a session may swap it after)
            self.timer = threading.Timer(self.NOTICE_AFTER, lambda: print(text, file=stream, flush=True))
            self.timer.daemon = True
            self.timer.start()

    def end(self, failed: bool) -> None:
        import sys

        if self.timer is not None:
            self.timer.cancel()
        elif self.tty:
            print("\r\033[K" if failed else "", file=sys.stderr, end="" if failed else "\n", flush=True)
