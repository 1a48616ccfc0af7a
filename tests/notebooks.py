"""Executing a notebook of examples/ on a finished run, as its reader would: in a python3 kernel, with the run folder
in SILOFLOW_RUN (the integration tests give it their tiny runs)."""

from __future__ import annotations

import base64
import os
from pathlib import Path

import nbformat
from jupyter_client.manager import KernelManager
from nbclient import NotebookClient

from tests.repo import REPO_ROOT

EXAMPLES = REPO_ROOT / "examples"
#: Longest a cell may take (s): reading the frames and coarse-graining them, numba's compilation included.
CELL_TIMEOUT_S = 300


def execute_notebook(name: str, run_dir: str | os.PathLike, workdir: str | os.PathLike) -> nbformat.NotebookNode:
    """Execute ``examples/<name>`` on the run in ``run_dir``, working in ``workdir``; return it with its outputs.

    The kernel imports siloflow from this checkout (PYTHONPATH), whatever else is installed.

    Raises
    ------
    nbclient.exceptions.CellExecutionError
        Naming the cell and its error, e.g. an assert cell whose check failed.
    """
    notebook = nbformat.read(EXAMPLES / name, as_version=4)
    path = os.pathsep.join(part for part in (str(REPO_ROOT), os.environ.get("PYTHONPATH", "")) if part)
    # the kernel talks to the client over local files (ipc), so that the tests open no network port
    kernel = KernelManager(kernel_name="python3", transport="ipc", ip=str(Path(workdir) / "kernel"))
    client = NotebookClient(notebook, km=kernel, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                            resources={"metadata": {"path": str(workdir)}})
    # the kernel's own (inline) backend shows the figures: the headless one the tests set would show none
    env = {key: value for key, value in os.environ.items() if key != "MPLBACKEND"}
    client.execute(env={**env, "SILOFLOW_RUN": str(Path(run_dir)), "PYTHONPATH": path})
    return notebook


def figures(notebook: nbformat.NotebookNode) -> list[bytes]:
    """The PNG figures a notebook's outputs show, in order."""
    return [base64.b64decode(output.data["image/png"]) for cell in notebook.cells if cell.cell_type == "code"
            for output in cell.outputs if output.output_type == "display_data" and "image/png" in output.data]
