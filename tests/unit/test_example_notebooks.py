"""The notebooks of examples/: stored without outputs, reading their run from SILOFLOW_RUN, through the public API
only, every figure checked by the assert cell after it, and each executed on a tiny run by an integration test."""

from __future__ import annotations

import ast
from pathlib import Path

import nbformat
import pytest

import siloflow
from tests.repo import REPO_ROOT

NOTEBOOKS = sorted((REPO_ROOT / "examples").glob("*.ipynb"))
#: What a notebook may import: the public API, and what it plots and computes with.
ALLOWED_IMPORTS = {"os", "numpy", "matplotlib.pyplot", "siloflow"}


def _code_cells(notebook) -> list[str]:
    return [cell.source for cell in notebook.cells if cell.cell_type == "code"]


def test_there_are_notebooks():
    assert [path.name for path in NOTEBOOKS] == ["silo_flat.ipynb", "silo_recirculation.ipynb"]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_a_notebook_is_stored_without_outputs_or_execution_counts(path):
    notebook = nbformat.read(path, as_version=4)
    nbformat.validate(notebook)
    for number, cell in enumerate(notebook.cells):
        if cell.cell_type == "code":
            assert cell.outputs == [], f"{path.name}: cell {number} has outputs; strip them"
            assert cell.execution_count is None, f"{path.name}: cell {number} has an execution count"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_a_notebook_reads_its_run_from_the_environment_through_the_public_api(path):
    cells = _code_cells(nbformat.read(path, as_version=4))
    source = "\n".join(cells)
    assert 'os.environ.get("SILOFLOW_RUN")' in source and "raise RuntimeError" in source
    imported, used = set(), set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            imported |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            imported.add(node.module)
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "siloflow":
            used.add(node.attr)
    assert imported <= ALLOWED_IMPORTS, f"{path.name} imports {sorted(imported - ALLOWED_IMPORTS)}"
    assert used and used <= set(siloflow.__all__), f"{path.name} uses {sorted(used - set(siloflow.__all__))}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_every_figure_of_a_notebook_is_checked_by_the_cell_after_it(path):
    cells = _code_cells(nbformat.read(path, as_version=4))
    figures = [number for number, source in enumerate(cells) if "plt.show()" in source]
    assert len(figures) >= 3
    for number in figures:
        assert number + 1 < len(cells) and "assert " in cells[number + 1], (
            f"{path.name}: the figure of code cell {number} has no assert cell after it")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_an_integration_test_executes_each_notebook(path):
    tests = "\n".join(test.read_text(encoding="utf-8") for test in (REPO_ROOT / "tests" / "integration").glob("*.py"))
    assert f'"{path.name}"' in tests, f"no integration test executes examples/{path.name}"
