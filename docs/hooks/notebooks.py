"""MkDocs hook (mkdocs.yml, ``hooks:``): the notebooks of examples/ as pages of the site.

A page whose source holds the line ``<!-- notebook: examples/NAME.ipynb -->`` shows that notebook in its place:
executed, with its printed output and figures, when build/notebooks/NAME.ipynb is an executed copy of it (``python -m
tests.notebooks`` writes one from the tiny run, which `make run-tiny` makes: `make docs` runs it first), or else as
stored, without outputs, under a note that says how to build it. An executed copy whose cells differ from the
notebook's (the notebook was edited since) counts as none. The figures become PNG files of the site beside the page.
Nothing executed is committed: examples/ holds the notebooks without outputs, build/ is not in git.

The notebook is read with nbformat (the docs extra has it); its cells become Markdown, code blocks and output
blocks.
"""

from __future__ import annotations

import base64
import posixpath
import re
from pathlib import Path

import nbformat
from mkdocs.structure.files import File

#: The line that puts a notebook in a page, its path relative to the repository root (mkdocs.yml's folder).
MARKER = re.compile(r"^<!--\s*notebook:\s*(\S+\.ipynb)\s*-->[ \t]*$", re.M)
#: Where the executed copies are, relative to the repository root (tests/notebooks.py writes them).
EXECUTED = Path("build") / "notebooks"
#: The terminal's colour codes in a traceback.
_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")

#: The Markdown of each notebook page of the current build, by the page's source path.
_PAGES: dict[str, str] = {}


def on_files(files, config):
    """Render every page's notebook and add its figures to the site's files."""
    root = Path(config.config_file_path).parent
    _PAGES.clear()
    for page in list(files.documentation_pages()):
        if page.abs_src_path is None:
            continue
        match = MARKER.search(Path(page.abs_src_path).read_text(encoding="utf-8"))
        if match is None:
            continue
        markdown, figures = render(root, match.group(1), page.src_uri)
        for src_uri, png in figures:
            files.append(File.generated(config, src_uri, content=png))
        _PAGES[page.src_uri] = markdown
    return files


def on_page_markdown(markdown, page, config, files):
    """Put the rendered notebook in place of its marker line."""
    if page.file.src_uri not in _PAGES:
        return markdown
    return MARKER.sub(lambda _: _PAGES[page.file.src_uri], markdown, count=1)


def render(root: Path, notebook_path: str, page_uri: str) -> tuple[str, list[tuple[str, bytes]]]:
    """The Markdown of the notebook at ``notebook_path`` (relative to ``root``) for the page ``page_uri`` (its path in
    the site's sources), its executed copy's when there is a current one, and its figures as ``[(path in the site's
    sources, PNG)]``: a folder named after the notebook beside the page."""
    page_dir = posixpath.dirname(page_uri)
    manual = posixpath.relpath("notebooks.md", page_dir or ".")
    figure_folder = posixpath.join(page_dir, Path(notebook_path).stem)
    stored = _read(root / notebook_path)
    executed_path = root / EXECUTED / Path(notebook_path).name
    executed = _read(executed_path) if executed_path.is_file() else None
    if executed is not None and _sources(executed) == _sources(stored):
        run = executed.get("metadata", {}).get("siloflow", {})
        note = ("!!! info \"Executed on the tiny run\"\n"
                f"    The outputs below are the notebook's on the tiny run `{run.get('run_id', '?')}` "
                "(`make run-tiny`, config/tiny.yaml), executed when this site was built: they show what the notebook "
                "makes, not the study's figures, and its numbers are not meaningful. Open it on your own run with "
                f"`SILOFLOW_RUN` ([From a notebook]({manual})).")
        notebook = executed
    else:
        stale = " (the executed copy there is older than the notebook)" if executed is not None else ""
        note = ("!!! note \"Shown without outputs\"\n"
                f"    This build found no executed copy of the notebook in build/notebooks/{stale}. Run "
                "`make run-tiny`, then `make docs`, to see it here with its outputs and figures on the tiny run "
                f"([From a notebook]({manual})).")
        notebook = stored
    blocks, figures = [], []
    for cell in notebook.get("cells", []):
        source = _text(cell.get("source", ""))
        if cell.get("cell_type") == "markdown":
            blocks.append(source)
        elif cell.get("cell_type") == "code":
            blocks.append(_fence("python", source))
            for output in cell.get("outputs", []):
                blocks.extend(_output(output, figures, figure_folder, page_dir))
    # the note goes under the notebook's title, its first cell's heading
    if blocks and blocks[0].lstrip().startswith("# "):
        title, _, rest = blocks[0].lstrip().partition("\n")
        blocks[0:1] = [title, note, rest]
    else:
        blocks.insert(0, note)
    return "\n\n".join(block.strip("\n") for block in blocks if block.strip()) + "\n", figures


def _read(path: Path) -> dict:
    return nbformat.read(path, as_version=4)


def _text(value) -> str:
    """A notebook's multi-line string: one string or a list of lines."""
    return "".join(value) if isinstance(value, list) else str(value)


def _sources(notebook: dict) -> list[tuple[str, str]]:
    return [(cell.get("cell_type", ""), _text(cell.get("source", ""))) for cell in notebook.get("cells", [])]


def _fence(language: str, text: str, title: str | None = None) -> str:
    """A fenced block longer than any run of backticks in ``text``."""
    ticks = "`" * max(3, max((len(run) for run in re.findall(r"`+", text)), default=0) + 1)
    attributes = f' title="{title}"' if title else ""
    return f"{ticks}{language}{attributes}\n{text.rstrip()}\n{ticks}"


def _output(output: dict, figures: list, figure_folder: str, page_dir: str) -> list[str]:
    """The blocks of one output: printed text, a figure (added to ``figures`` as ``figure_folder/figure-<n>.png``,
    linked from the page's folder ``page_dir``), a value or an error."""
    kind = output.get("output_type")
    if kind == "stream":
        return [_fence("text", _text(output.get("text", "")), "Output")]
    if kind == "error":
        traceback = _ANSI.sub("", "\n".join(output.get("traceback", [])))
        return [_fence("text", traceback or f"{output.get('ename')}: {output.get('evalue')}", "Error")]
    data = output.get("data", {})
    if "image/png" in data:
        src_uri = posixpath.join(figure_folder, f"figure-{len(figures) + 1}.png")
        figures.append((src_uri, base64.b64decode(_text(data["image/png"]))))
        return [f"![Figure {len(figures)}]({posixpath.relpath(src_uri, page_dir or '.')})"]
    if "text/plain" in data:
        return [_fence("text", _text(data["text/plain"]), "Output")]
    return []
