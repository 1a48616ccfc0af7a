"""Logging for workflow scripts: everything a script prints goes to its rule's log file."""

from __future__ import annotations

import contextlib
import logging
import sys
import traceback
from pathlib import Path


@contextlib.contextmanager
def logged_to(log_path: str | Path):
    """Send stdout, stderr and the ``logging`` root logger to ``log_path`` for the duration of the block.

    An exception is written to the log with its traceback and re-raised, so Snakemake reports the failure
    and the log says why.
    """
    log_path = Path(log_path)
    log_path.parent.mkdir(parents=True, exist_ok=True)
    with open(log_path, "w", encoding="utf-8") as log_file:
        handler = logging.StreamHandler(log_file)
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        root = logging.getLogger()
        root.addHandler(handler)
        root.setLevel(logging.INFO)
        saved = sys.stdout, sys.stderr
        sys.stdout = sys.stderr = log_file
        try:
            yield logging.getLogger("siloflow")
        except BaseException:
            traceback.print_exc(file=log_file)
            raise
        finally:
            sys.stdout, sys.stderr = saved
            root.removeHandler(handler)
