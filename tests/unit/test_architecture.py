"""The layout holds: layers point one way, no import circles, no function-local imports, and only the LIGGGHTS
package and templates know LIGGGHTS (its code, file names and formats).

Layers, as subpackages of ``siloflow``: workflow -> engines, analysis, calibration; calibration -> analysis;
engines and analysis -> the neutral model (``model``), which imports nothing else of siloflow; engines import nothing
of analysis, analysis nothing of engines. The notebook API (``siloflow.api``) and the command line
(``siloflow.cli``) are the top layer: nothing imports them, and neither imports the other.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from tests.repo import REPO_ROOT
from siloflow.engines.interface import ENGINE_KINDS, engine_named

#: The package's Python modules, the workflow's scripts apart (they run inside Snakemake).
PACKAGES = ("siloflow/model", "siloflow/engines", "siloflow/analysis", "siloflow/calibration", "siloflow/api",
            "siloflow/cli", "siloflow/__init__.py")
#: The top layer: user-facing entry points that nothing else of siloflow imports.
TOP_LAYERS = ("api", "cli")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(REPO_ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _python_files(*folders: str) -> list[Path]:
    found = []
    for folder in folders:
        root = REPO_ROOT / folder
        found += [root] if root.is_file() else [p for p in root.rglob("*.py") if "__pycache__" not in p.parts]
        if not root.exists() and (single := root.with_suffix(".py")).is_file():
            found.append(single)
    return sorted(found)


def _layer(module: str) -> str:
    """The subpackage of ``siloflow`` a module belongs to (``siloflow.engines.config`` -> ``engines``)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(path: Path) -> tuple[list[tuple[int, str]], list[tuple[int, str]]]:
    """(runtime imports, imports inside functions or classes) of a file as (line, module)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    runtime, local = [], []

    def modules(node) -> list[str]:
        if isinstance(node, ast.Import):
            return [alias.name for alias in node.names]
        if node.level:  # relative imports are not used in this project; resolve them anyway
            base = _module_name(path).rsplit(".", node.level)[0]
            return [f"{base}.{node.module}" if node.module else base]
        return [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]

    def visit(nodes, inside_code: bool, type_only: bool) -> None:
        for node in nodes:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for module in modules(node):
                    (local if inside_code else runtime if not type_only else []).append((node.lineno, module))
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                visit(node.body, True, type_only)
            elif isinstance(node, ast.If):
                visit(node.body, inside_code, type_only or _is_type_checking(node))
                visit(node.orelse, inside_code, type_only)
            elif isinstance(node, (ast.Try, ast.With)):
                for block in (getattr(node, "body", []), getattr(node, "orelse", []), getattr(node, "finalbody", [])):
                    visit(block, inside_code, type_only)
                for handler in getattr(node, "handlers", []):
                    visit(handler.body, inside_code, type_only)
            elif hasattr(node, "body") and isinstance(node.body, list):
                visit(node.body, inside_code, type_only)

    visit(tree.body, False, False)
    return runtime, local


def _internal(module: str, known: set[str]) -> str | None:
    """The project module an imported name refers to (``from a.b import c`` may name module a.b.c or a name in a.b)."""
    while module and module not in known:
        module = module.rpartition(".")[0]
    return module or None


def _graph() -> dict[str, set[str]]:
    files = _python_files(*PACKAGES)
    known = {_module_name(p) for p in files}
    graph = {}
    for path in files:
        name = _module_name(path)
        runtime, _ = _imports(path)
        graph[name] = {target for _, module in runtime if (target := _internal(module, known)) and target != name}
    return graph


def test_no_function_local_imports():
    found = [f"{path.relative_to(REPO_ROOT)}:{line} imports {module}"
             for path in _python_files(*PACKAGES, "siloflow/workflow/scripts", "tests")
             for line, module in _imports(path)[1]]
    assert not found, "imports belong at the top of a module:\n" + "\n".join(found)


def test_layers_point_one_way():
    wrong = []
    for module, targets in _graph().items():
        top = _layer(module)
        for target in targets:
            other = _layer(target)
            if top == "model" and other != "model":
                wrong.append(f"{module} -> {target} (the neutral model depends on nothing above it)")
            if top == "analysis" and other not in ("analysis", "model"):
                wrong.append(f"{module} -> {target} (analysis imports nothing from {other})")
            if top == "calibration" and other not in ("calibration", "analysis", "model"):
                wrong.append(f"{module} -> {target} (calibration may use analysis and the model only)")
            if top == "engines" and other not in ("engines", "model"):
                wrong.append(f"{module} -> {target} (engines take only the neutral model)")
            if other in TOP_LAYERS and top != other:
                wrong.append(f"{module} -> {target} (the notebook API and the command line are the top layer: "
                             "nothing imports them)")
    assert not wrong, "\n".join(sorted(wrong))


def test_the_workflow_does_not_go_through_the_notebook_api():
    found = [f"{path.relative_to(REPO_ROOT)}:{line} imports {module}" for path in _python_files("siloflow/workflow/scripts")
             for line, module in _imports(path)[0] if module.split(".")[:2] in (["siloflow", "api"], ["siloflow"])]
    assert not found, "the workflow calls the library, not the notebook API built on it:\n" + "\n".join(found)


def test_no_import_circles():
    graph = _graph()
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def strongly_connected(node):  # Tarjan
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in graph.get(node, ()):
            if target not in index:
                strongly_connected(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for node in graph:
        if node not in index:
            strongly_connected(node)
    # a package importing its own submodules in __init__ is not a circle of concern unless a submodule imports back
    # the package's __init__ names; those appear as components too, so none may exist
    assert not cycles, f"import circles: {cycles}"


#: What names LIGGGHTS' code, file names or formats; only siloflow/engines/liggghts/ and siloflow/templates/liggghts/ may say these.
LIGGGHTS_NAMES = re.compile(
    r"engines\.liggghts|siloflow/engines/liggghts|liggghts/\w+\.(?:lmp\.)?j2|in\.liggghts|log\.liggghts|\.lmp\b|custom/vtk|"
    r"wall/gran|pair/gran|mesh/surface|dump_prefix|CONTACT_PREFIX|read_force_history|forces\.txt|wall_forces\.txt|"
    r"id_multisphere|particles_\*|boundingBox"
)


#: What names YADE's code, file names or formats; only siloflow/engines/yade/ and siloflow/templates/yade/ may say these.
YADE_NAMES = re.compile(
    r"engines\.yade|siloflow/engines/yade|yade/\w+\.py\.j2|log\.yade|yade-double|wall_force_history|\bO\.(?:bodies|engines|save|load)\b|"
    r"appendClumped|MindlinPhys|settled_fill_\w*\.npz|particles_\w*\.npz"
)
#: Per engine: the pattern of its names and the package that alone may say them.
ENGINE_NAMES = {"liggghts": (LIGGGHTS_NAMES, ("siloflow", "engines", "liggghts")),
                "yade": (YADE_NAMES, ("siloflow", "engines", "yade"))}


@pytest.mark.parametrize("engine", sorted(ENGINE_NAMES))
@pytest.mark.parametrize("folder", ["siloflow/engines", "siloflow/analysis", "siloflow/calibration", "siloflow/api",
                                    "siloflow/cli", "siloflow/workflow", "Snakefile"])
def test_only_an_engines_package_names_its_files_and_formats(folder, engine):
    pattern, package = ENGINE_NAMES[engine]
    root = REPO_ROOT / folder
    paths = [root] if root.is_file() else [p for p in root.rglob("*") if p.is_file() and p.suffix in (".py", ".smk", ".yaml", ".rst")]
    found = []
    for path in paths:
        relative = path.relative_to(REPO_ROOT)
        if relative.parts[:3] == package or "__pycache__" in relative.parts:
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            match = pattern.search(line)
            if match:
                found.append(f"{relative}:{number}: {match.group(0)!r} in {line.strip()[:100]}")
    assert not found, f"{engine} names outside {'/'.join(package)}/:\n" + "\n".join(found)


def test_every_engine_kind_is_registered_and_names_its_base_template():
    from_registry = []
    for name in ENGINE_KINDS:
        engine = engine_named(name)
        assert engine.name == name
        assert (REPO_ROOT / "siloflow" / "templates" / engine.base_template).is_file()
        from_registry.append(name)
    assert from_registry == ["liggghts", "yade"]
