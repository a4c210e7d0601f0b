"""Where the generated models are, and which there are, without importing them (or NumPy).

The emitted models are the package gyro.generated: the repository's generated/ folder,
mapped there by pyproject.toml (an editable install), or carried inside the wheel."""
from __future__ import annotations

import importlib.util
from functools import lru_cache
from pathlib import Path

from gyro.errors import ParameterError

GENERATED_PACKAGE = "gyro.generated"


@lru_cache(maxsize=None)
def generated_dir() -> Path:
    spec = importlib.util.find_spec(GENERATED_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise ParameterError("no generated models installed (gyro.generated is missing): run `make derive`")
    return Path(list(spec.submodule_search_locations)[0]).resolve()


def available() -> list[str]:
    """The generated models: folders of gyro.generated with a metadata.json."""
    return sorted(p.name for p in generated_dir().iterdir() if (p / "metadata.json").exists())


@lru_cache(maxsize=None)
def metadata(name: str) -> dict:
    """A generated model's metadata.json, read once (json only: no NumPy)."""
    import json

    return json.loads((generated_dir() / name / "metadata.json").read_text())


def declaring(predicate) -> list[str]:
    """The generated models whose metadata satisfies `predicate`: the models a command that
    needs a declaration (a spin angle, conditions) lists in its help."""
    return [n for n in available() if predicate(metadata(n))]


def declared_module(spec: str, what: str, model=None):
    """The module a model declares for the runtime (derive.model.runtime_module): a dotted
    name imported as such, or "file:PATH", a model file or a file beside it, loaded from its
    path once; a relative PATH from the folder `model` was loaded from (its
    `source_folder`). ParameterError in one line (naming `what`) where it cannot be loaded."""
    import importlib
    import importlib.util
    import sys

    try:
        if not spec.startswith("file:"):
            return importlib.import_module(spec)
        path = Path(spec[5:])
        if not path.is_absolute():
            base = getattr(model, "source_folder", None)
            if base is None:
                raise ImportError("it lies beside the model file, which is not known here: "
                                  "load the model by its file PATH.py")
            path = base / path
        key = f"_gyro_declared_{abs(hash(str(path))):x}"
        if key not in sys.modules:
            found = importlib.util.spec_from_file_location(key, path)
            if found is None or not path.is_file():
                raise ImportError(f"no file {path}")
            module = importlib.util.module_from_spec(found)
            sys.path.insert(0, str(path.parent))  # the file may import its neighbours
            try:
                found.loader.exec_module(module)
            finally:
                sys.path.remove(str(path.parent))
            sys.modules[key] = module
        return sys.modules[key]
    except ImportError as exc:
        raise ParameterError(f"{what}: the declared module {spec!r} cannot be imported ({exc})") from None


def module_constants(folder, wanted: tuple) -> dict:
    """module name -> {constant: value} of the top-level constants `wanted` (NAME, RUNG, ...)
    of every public module in `folder`, read from the sources without importing them:
    how the methods and the questions are found without a list, and without NumPy."""
    import ast
    import pkgutil

    out = {}
    for m in pkgutil.iter_modules([str(folder)]):
        if m.name.startswith("_"):
            continue
        consts = {}
        for node in ast.parse((Path(folder) / f"{m.name}.py").read_text()).body:
            if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
                if node.targets[0].id in wanted:
                    try:  # a constant, or a literal of constants (a question's OPTIONS)
                        consts[node.targets[0].id] = ast.literal_eval(node.value)
                    except ValueError:
                        pass
        out[m.name] = consts
    return out
def cache_dir() -> Path:
    """The runtime's cache: compiled libraries, and models derived from files ($GYRO_CACHE,
    default ~/.cache/gyro-dynamics)."""
    import os

    return Path(os.environ.get("GYRO_CACHE", Path.home() / ".cache" / "gyro-dynamics"))


def model_source(text: str) -> str | None:
    """What a MODEL argument names: 'builtin' (a generated model's name), 'emitted' (a folder
    DIR/<name> with its metadata.json), 'file' (a model file PATH.py, or a model folder with
    an __init__.py, derived on first use), or None (nothing of these)."""
    if "/" not in text and "\\" not in text and not text.endswith(".py") and text in available():
        return "builtin"
    path = Path(text).expanduser()
    try:
        if path.is_dir():
            if (path / "metadata.json").is_file():
                return "emitted"
            return "file" if (path / "__init__.py").is_file() else None
        if path.is_file() and path.suffix == ".py":
            return "file"
    except OSError as exc:  # a name longer than the file system takes (ENAMETOOLONG), a loop of links
        shown = text if len(text) <= 60 else text[:40] + "..." + text[-12:]
        raise ParameterError(f"model {shown!r}: {exc.strerror or exc} ({len(text.encode(errors='surrogateescape'))} "
                             "bytes)") from None
    return None
