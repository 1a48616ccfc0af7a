"""The notebooks of examples/: stored without outputs, reading their run from SILOFLOW_RUN (the tiny run of the clone
when it is unset), through the public API only, every figure checked by the assert cell after it, each executed on a
tiny run by an integration test, and each a page of the documentation site."""

from __future__ import annotations

import ast
import base64
import importlib.util
import os
import shutil
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


# --- Without SILOFLOW_RUN a notebook reads the tiny run ---------------------------------------------------------------
# The notebook's first code cell, executed here in a folder laid out as a clone's, with siloflow.open_run replaced by
# one that reports the folder it was given.


class _Opened(Exception):
    """What the replaced siloflow.open_run raises, with the run folder it was given."""


def _opened_run(path: Path, folder: Path, monkeypatch) -> Path:
    """The run folder the notebook's first code cell opens when started in ``folder`` without SILOFLOW_RUN."""
    (source, *_) = _code_cells(nbformat.read(path, as_version=4))
    monkeypatch.delenv("SILOFLOW_RUN", raising=False)
    monkeypatch.chdir(folder)

    def open_run(run):
        raise _Opened(run)

    monkeypatch.setattr(siloflow, "open_run", open_run, raising=False)
    with pytest.raises(_Opened) as opened:
        exec(compile(source, path.name, "exec"), {})
    return Path(opened.value.args[0]).resolve()


def _clone(root: Path) -> Path:
    (root / "config").mkdir(parents=True)
    (root / "config" / "tiny.yaml").write_text("{}\n")
    (root / "examples").mkdir()
    return root


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_without_siloflow_run_a_notebook_reads_the_newest_tiny_run_of_its_case(path, tmp_path, monkeypatch):
    clone = _clone(tmp_path)
    runs = clone / "results" / "tiny" / "results" / path.stem
    for age, name in enumerate(["a-newest", "b-older"]):  # the newest is not the last by name
        (runs / name).mkdir(parents=True)
        (runs / name / "run.json").write_text("{}")
        os.utime(runs / name / "run.json", (1e9 - age, 1e9 - age))
    (runs / "summary").mkdir()  # a folder of the case that holds no run
    # Jupyter starts a notebook in its own folder, examples/; from the clone's root it reads the same run
    assert _opened_run(path, clone / "examples", monkeypatch) == (runs / "a-newest").resolve()
    assert _opened_run(path, clone, monkeypatch) == (runs / "a-newest").resolve()


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_without_siloflow_run_or_a_tiny_run_a_notebook_says_to_make_it(path, tmp_path, monkeypatch):
    clone = _clone(tmp_path)
    (clone / "results" / "tiny" / "results" / path.stem / "unfinished").mkdir(parents=True)  # no run.json
    (source, *_) = _code_cells(nbformat.read(path, as_version=4))
    monkeypatch.delenv("SILOFLOW_RUN", raising=False)
    monkeypatch.chdir(clone / "examples")
    with pytest.raises(RuntimeError, match=r"make run-tiny.*SILOFLOW_RUN"):
        exec(compile(source, path.name, "exec"), {})


# --- The site shows each notebook, executed on the tiny run when the build has it ------------------------------------
# docs/hooks/notebooks.py, the MkDocs hook that renders them; `python -m tests.notebooks` writes the executed copies.


def _hook():
    spec = importlib.util.spec_from_file_location("notebooks_hook", REPO_ROOT / "docs" / "hooks" / "notebooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: a 1 x 1 PNG
PNG = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAAAAAA6fptVAAAACklEQVR4nGNgAAAAAgABSK+kcQAAAABJRU5ErkJggg==")


def _executed_copy(root: Path, path: Path, edit=None) -> None:
    """An executed copy of ``path`` in ``root``'s build/notebooks/: printed text and a figure on its first code cell."""
    notebook = nbformat.read(path, as_version=4)
    cell = next(cell for cell in notebook.cells if cell.cell_type == "code")
    cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text="sphere2-abc: a run\n"),
                    nbformat.v4.new_output("display_data", data={"image/png": base64.b64encode(PNG).decode()})]
    notebook.metadata["siloflow"] = {"run_id": "sphere2-abc", "case": path.stem}
    if edit:
        edit(notebook)
    (root / "build" / "notebooks").mkdir(parents=True, exist_ok=True)
    nbformat.write(notebook, root / "build" / "notebooks" / path.name)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_the_site_shows_a_notebook_executed_on_the_tiny_run_when_the_build_has_it(path, tmp_path):
    hook = _hook()
    (tmp_path / "examples").mkdir()
    shutil.copy(path, tmp_path / "examples" / path.name)
    page = f"notebooks/{path.stem}.md"
    # none executed: the notebook as stored, under a note that says how to build it
    markdown, figures = hook.render(tmp_path, f"examples/{path.name}", page)
    assert "Shown without outputs" in markdown and "make run-tiny" in markdown and figures == []
    assert markdown.startswith("# ") and "```python" in markdown
    # executed on the tiny run: its output and figure, the figure a file beside the page
    _executed_copy(tmp_path, path)
    markdown, figures = hook.render(tmp_path, f"examples/{path.name}", page)
    assert "Executed on the tiny run" in markdown and "`sphere2-abc`" in markdown
    assert "sphere2-abc: a run" in markdown
    assert figures == [(f"notebooks/{path.stem}/figure-1.png", PNG)]
    assert f"![Figure 1]({path.stem}/figure-1.png)" in markdown
    # an executed copy of an earlier version of the notebook is not shown
    _executed_copy(tmp_path, path, edit=lambda notebook: notebook.cells[0].update(source="# An earlier title"))
    markdown, figures = hook.render(tmp_path, f"examples/{path.name}", page)
    assert "Shown without outputs" in markdown and "older than the notebook" in markdown and figures == []


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.name)
def test_each_notebook_has_a_page_of_the_site(path):
    pages = [page for page in (REPO_ROOT / "docs").rglob("*.md")
             if f"<!-- notebook: examples/{path.name} -->" in page.read_text(encoding="utf-8")]
    assert len(pages) == 1, f"no page of docs/ shows examples/{path.name}"
    assert pages[0].relative_to(REPO_ROOT / "docs").as_posix() in (REPO_ROOT / "mkdocs.yml").read_text(encoding="utf-8")
