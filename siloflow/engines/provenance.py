"""Which code and engine made a run: each attempt of the run step notes the commit of siloflow's code and the engine's
version in the run's folder (:data:`siloflow.engines.layout.RUN_PROVENANCE`), before the engine starts, so that the
validation record names the code that ran the run, not the code that wrote the record.
"""

from __future__ import annotations

import json
import subprocess
from datetime import datetime, timezone
from pathlib import Path

from siloflow.engines.layout import REPOSITORY_RECORD, RUN_PROVENANCE, write_text_atomic

__all__ = ["UNKNOWN", "code_commit", "note_attempt", "read_attempts"]

#: The commit of code outside a git clone (an installed package).
UNKNOWN = "unknown"


def code_commit(where: str | Path) -> str:
    """The commit of the git clone holding ``where``, ``-dirty`` appended with uncommitted changes to anything but
    the validation record kept in the repository (which `make validate` rewrites group by group); :data:`UNKNOWN`
    outside git."""
    head = subprocess.run(["git", "-C", str(where), "rev-parse", "HEAD"], capture_output=True, text=True, check=False)
    if head.returncode != 0:
        return UNKNOWN
    dirty = subprocess.run(["git", "-C", str(where), "status", "--porcelain", "--untracked-files=no", "--", ":/",
                            f":(top,exclude){REPOSITORY_RECORD}"],
                           capture_output=True, text=True, check=False).stdout.strip()
    return head.stdout.strip() + ("-dirty" if dirty else "")


def note_attempt(run_dir: str | Path, engine: str, engine_version: str, commit: str) -> list[dict]:
    """Append this attempt of the run step (its start, the code's commit, the engine and its version) to the run's
    provenance file, written atomically; returns every attempt noted so far."""
    path = Path(run_dir) / RUN_PROVENANCE
    attempts = read_attempts(run_dir)
    attempts.append({"started": datetime.now(timezone.utc).isoformat(timespec="seconds"), "commit": commit,
                     "engine": engine, "engine_version": engine_version})
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps({"attempts": attempts}, indent=2) + "\n")
    return attempts


def read_attempts(run_dir: str | Path) -> list[dict]:
    """The attempts noted in a run's provenance file, oldest first; none when it has none (a run made before the file
    existed)."""
    path = Path(run_dir) / RUN_PROVENANCE
    if not path.is_file():
        return []
    return list(json.loads(path.read_text(encoding="utf-8")).get("attempts", []))
