"""The runtime's shape (docs/architecture.md): no import cycles, lazy imports included; the
flow runs one way, cli -> analyses -> ladder -> methods -> numerics and kernels -> model;
results import no analysis; nothing at run time imports SymPy or the build-time package."""
from __future__ import annotations

import ast
from pathlib import Path

from tests.conftest import ROOT

GYRO = ROOT / "gyro"


def _module(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def import_graph(package: Path = GYRO) -> dict[str, set[str]]:
    """Module -> the modules of `package` it imports, at module level or inside functions."""
    files = {(_module(p)): p for p in package.rglob("*.py")}
    graph = {}
    for mod, path in files.items():
        deps = set()
        pkg = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(pkg.split(".")[: len(pkg.split(".")) - node.level + 1] + ([base] if base else []))
                names = [f"{base}.{a.name}" if f"{base}.{a.name}" in files else base for a in node.names]
            else:
                continue
            for n in names:
                while n and n not in files:
                    n = n.rsplit(".", 1)[0] if "." in n else ""
                if n and n != mod:
                    deps.add(n)
        graph[mod] = deps
    return graph


def _cycle(graph):
    state, stack = {}, []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for d in sorted(graph[m]):
            if state.get(d) == 1:
                return stack[stack.index(d):] + [d]
            if d not in state:
                found = visit(d)
                if found:
                    return found
        state[m] = 2
        stack.pop()
        return None

    for m in sorted(graph):
        if m not in state:
            found = visit(m)
            if found:
                return found
    return None


def test_no_import_cycles_in_the_runtime():
    assert _cycle(import_graph()) is None, " -> ".join(_cycle(import_graph()))


def test_no_import_cycles_in_the_derivation():
    """derive/ too: a step that imports another step's module for the result type closed a
    cycle constraints -> pipeline -> constraints (the result is a leaf, derive/derivation.py)."""
    graph = import_graph(ROOT / "derive")
    assert _cycle(graph) is None, " -> ".join(_cycle(graph))
    assert graph["derive.derivation"] <= {"derive.mechanics", "derive.names", "derive.model"}
    # the passes sit below the pipeline that runs them and the outputs that read their result
    passes = [m for m in graph if m.startswith("derive.passes.")]
    assert len(passes) > 1
    for m in passes:
        assert not [d for d in graph[m] if d in ("derive.pipeline", "derive.emit", "derive.__main__")
                    or d.startswith("derive.outputs")], m


def test_the_cycle_finder_finds_one():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]


def test_the_flow_runs_one_way():
    g = import_graph()
    layer = {"gyro.cli": 5, "gyro.analyses": 4, "gyro.systems": 4, "gyro.questions": 4, "gyro.ladder": 3, "gyro.levels": 3, "gyro.methods": 2, "gyro.qep": 1, "gyro.rounding": 1,
             "gyro.equilibrium": 1, "gyro.kernels": 1, "gyro.executor": 1, "gyro.ode": 1, "gyro.results": 1, "gyro.cbackend": 0, "gyro.models": 0}

    def level(m):
        for prefix, lv in sorted(layer.items(), key=lambda kv: -len(kv[0])):
            if m == prefix or m.startswith(prefix + "."):
                return lv
        return None

    for m, deps in g.items():
        for d in deps:
            if level(m) is not None and level(d) is not None and not m.startswith("gyro.methods"):
                assert level(d) <= level(m), f"{m} (layer {level(m)}) imports {d} (layer {level(d)})"
    results = [m for m in g if m == "gyro.results" or m.startswith("gyro.results.")]
    assert len(results) > 1  # the package and its modules
    for m in results:
        assert not [d for d in g[m] if d.startswith(("gyro.analyses", "gyro.methods", "gyro.ladder", "gyro.cli"))], m


def test_the_runtime_never_imports_sympy_or_the_build_time_package():
    for path in GYRO.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
                for n in names:
                    assert not n.startswith(("sympy", "symengine", "derive", "jinja2")), f"{path}: {n}"


def test_the_wheel_lists_every_package():
    """pyproject.toml lists the packages (the generated models map in from another folder, which
    setuptools' finder cannot combine): every folder of gyro/ with an __init__.py is listed, and
    nothing else but gyro.generated."""
    import tomllib

    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in GYRO.rglob("__init__.py")}
    assert listed - {"gyro.generated"} == found


def test_no_command_or_analysis_knows_a_model_by_name():
    """What only one paper's system has lives in gyro/systems, reached through what the model
    declares: no built-in model's name appears in gyro/cli/ or gyro/analyses/ (code, help or
    docstring), and nothing outside gyro/systems imports it (the runtime loads a declared
    module with gyro.catalog.declared_module)."""
    names = sorted(p.name for p in (ROOT / "generated").iterdir() if (p / "metadata.json").is_file())
    assert len(names) >= 4
    for folder in ("cli", "analyses"):
        for path in sorted((GYRO / folder).rglob("*.py")):
            text = path.read_text()
            found = [n for n in names if n in text]
            assert not found, f"{path.relative_to(ROOT)} names {found}"
    g = import_graph()
    for m, deps in g.items():
        if not m.startswith("gyro.systems"):
            assert not [d for d in deps if d.startswith("gyro.systems")], m
