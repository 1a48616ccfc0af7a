"""Executing the notebooks of examples/ on finished runs, as their reader would: in a python3 kernel started in the
notebook's folder, with the run folder in SILOFLOW_RUN. The integration tests execute them on their tiny runs; the
documentation site shows them executed on the tiny run (`make run-tiny`), which this module's command line makes:

    python -m tests.notebooks [--tiny results/tiny] [build/notebooks]

executes every notebook of examples/ on its case's run under the tiny run's folder and writes the executed copies into
build/notebooks/ (ignored by git), where the site's hook (docs/hooks/notebooks.py) reads them. A notebook whose case has
no run there is left out, and an executed copy of it from an earlier build removed: the site then shows the notebook
as stored, without outputs.
"""

from __future__ import annotations

import argparse
import base64
import os
import sys
import tempfile
from pathlib import Path

import nbformat
from jupyter_client.manager import KernelManager
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

from tests.repo import REPO_ROOT

EXAMPLES = REPO_ROOT / "examples"
#: Longest a cell may take (s): reading the frames and coarse-graining them, numba's compilation included.
CELL_TIMEOUT_S = 300
#: Where `make run-tiny` works (its results are in TINY_DIR/results/), and where the executed copies go.
TINY_DIR = REPO_ROOT / "results" / "tiny"
EXECUTED_DIR = REPO_ROOT / "build" / "notebooks"
#: The notebook's metadata key under which an executed copy names its run.
METADATA_KEY = "siloflow"


def execute_notebook(name: str, run_dir: str | os.PathLike | None, workdir: str | os.PathLike,
                     cwd: str | os.PathLike | None = None) -> nbformat.NotebookNode:
    """Execute ``examples/<name>`` on the run in ``run_dir``; return it with its outputs.

    ``run_dir`` None leaves SILOFLOW_RUN unset, so that the notebook finds its run itself (the tiny run of the clone it
    starts in). The kernel starts in ``cwd`` (default ``workdir``; Jupyter starts it in the notebook's folder) and
    talks to the client over local files in ``workdir`` (ipc), so that no network port opens. It imports siloflow from
    this checkout (PYTHONPATH), whatever else is installed.

    Raises
    ------
    nbclient.exceptions.CellExecutionError
        Naming the cell and its error, e.g. an assert cell whose check failed.
    """
    notebook = nbformat.read(EXAMPLES / name, as_version=4)
    path = os.pathsep.join(part for part in (str(REPO_ROOT), os.environ.get("PYTHONPATH", "")) if part)
    kernel = KernelManager(kernel_name="python3", transport="ipc", ip=str(Path(workdir) / "kernel"))
    client = NotebookClient(notebook, km=kernel, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                            resources={"metadata": {"path": str(cwd if cwd is not None else workdir)}})
    # the kernel's own (inline) backend shows the figures: the headless one the tests set would show none
    env = {key: value for key, value in os.environ.items() if key not in ("MPLBACKEND", "SILOFLOW_RUN")}
    if run_dir is not None:
        env["SILOFLOW_RUN"] = str(Path(run_dir))
    client.execute(env={**env, "PYTHONPATH": path})
    return notebook


def figures(notebook: nbformat.NotebookNode) -> list[bytes]:
    """The PNG figures a notebook's outputs show, in order."""
    return [base64.b64decode(output.data["image/png"]) for cell in notebook.cells if cell.cell_type == "code"
            for output in cell.outputs if output.output_type == "display_data" and "image/png" in output.data]


def notebook_case(name: str) -> str:
    """The case kind whose run a notebook of examples/ reads: its name's (``silo_flat.ipynb`` reads ``silo_flat``)."""
    return Path(name).stem


def tiny_run(tiny_dir: str | os.PathLike, case: str) -> Path | None:
    """The finished run of ``case`` in the tiny run's folder (``tiny_dir/results/<case>/<run id>/``, with its
    run.json), as the notebooks find it: the newest, should an earlier config/tiny.yaml have left another; None when
    there is none."""
    folder = Path(tiny_dir) / "results" / case
    runs = [run for run in folder.iterdir() if (run / "run.json").is_file()] if folder.is_dir() else []
    return max(runs, key=lambda run: (run / "run.json").stat().st_mtime, default=None)


def execute_examples(tiny_dir: str | os.PathLike = TINY_DIR, out_dir: str | os.PathLike = EXECUTED_DIR) -> list[Path]:
    """Execute every notebook of examples/ on its case's run in ``tiny_dir`` and write the executed copy into
    ``out_dir`` (the notebook's name), its metadata naming the run; returns the copies written. A notebook whose case
    has no run there is skipped and its copy from an earlier call removed.

    Raises
    ------
    nbclient.exceptions.CellExecutionError
        When a cell fails on the run (an assert cell whose check does not hold): nothing is written for it.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in sorted(EXAMPLES.glob("*.ipynb")):
        target = out / path.name
        target.unlink(missing_ok=True)
        run = tiny_run(tiny_dir, notebook_case(path.name))
        if run is None:
            print(f"{path.name}: no {notebook_case(path.name)} run under {Path(tiny_dir) / 'results'}/ (make run-tiny "
                  "makes it): the site shows the notebook without outputs")
            continue
        with tempfile.TemporaryDirectory(prefix="siloflow-notebook-") as workdir:
            notebook = execute_notebook(path.name, run.resolve(), workdir, cwd=EXAMPLES)
        notebook.metadata[METADATA_KEY] = {"run_id": run.name, "case": notebook_case(path.name)}
        nbformat.write(notebook, target)
        print(f"{path.name}: executed on {run} into {target}")
        written.append(target)
    return written


def main(argv: list[str] | None = None) -> int:
    """The command line: execute the notebooks of examples/ on the tiny run for the documentation site."""
    parser = argparse.ArgumentParser(prog="python -m tests.notebooks", description=(
        "Execute the notebooks of examples/ on the tiny run (make run-tiny) for the documentation site; a notebook "
        "whose case has no run there is left out, and the site shows it without outputs."))
    parser.add_argument("out_dir", nargs="?", default=str(EXECUTED_DIR),
                        help=f"where the executed copies go (default: {EXECUTED_DIR.relative_to(REPO_ROOT)})")
    parser.add_argument("--tiny", default=str(TINY_DIR), metavar="DIR",
                        help=f"the tiny run's folder, results/ inside it (default: {TINY_DIR.relative_to(REPO_ROOT)})")
    args = parser.parse_args(argv)
    try:
        execute_examples(args.tiny, args.out_dir)
    except CellExecutionError as error:
        print(f"a notebook failed on the tiny run, so the site cannot show it executed:\n{error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
