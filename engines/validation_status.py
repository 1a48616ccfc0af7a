"""`make validate-status` and `make validate GROUP=<name>`'s check: the validation record's groups against the plan.

``python -m engines.validation_status status CONFIG RECORD_DIR`` prints, per group, whether the record in
``RECORD_DIR`` (``docs/validation``) is complete, stale or missing against the runs ``CONFIG`` plans;
``python -m engines.validation_status check GROUP`` refuses an unknown group before anything runs. The record's
provenance is read here, at the edge; the comparison is :func:`engines.validation_groups.group_status`.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path
from typing import Sequence

from engines.config import load_config
from engines.planning import config_estimates
from engines.validation_groups import GROUPS, STALE, MISSING, check_group, group_status, planned_runs, status_lines

#: The provenance file of a group's record: one row per run behind its rows (column ``run_id`` among others).
RECORD_RUNS = "runs.csv"


def recorded_runs(record_dir: str | Path) -> dict[str, set[str]]:
    """``{group: {run id}}`` from each group's provenance (``<record_dir>/<group>/runs.csv``); a group without the
    file is absent."""
    recorded = {}
    for name in GROUPS:
        path = Path(record_dir) / name / RECORD_RUNS
        if path.is_file():
            with open(path, newline="", encoding="utf-8") as handle:
                rows = list(csv.DictReader(handle))
            if rows and "run_id" not in rows[0]:
                raise ValueError(f"{path}: the provenance has no run_id column")
            recorded[name] = {row["run_id"] for row in rows}
    return recorded


def main(argv: Sequence[str] | None = None) -> int:
    """Command line; returns 0 when every group is complete (status) or the group exists (check), 1 when a group is
    stale or missing, 2 on a usage error."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) == 2 and argv[0] == "check":
        try:
            check_group(argv[1])
        except ValueError as error:
            print(f"siloflow: {error}", file=sys.stderr)
            return 2
        return 0
    if len(argv) == 3 and argv[0] == "status":
        planned = planned_runs(config_estimates(load_config(argv[1])))
        recorded = recorded_runs(argv[2])
        print(f"The validation record in {argv[2]} against the runs {argv[1]} plans:")
        print("\n".join(status_lines(planned, recorded)))
        return 1 if {STALE, MISSING} & set(group_status(planned, recorded).values()) else 0
    print("usage: python -m engines.validation_status status CONFIG RECORD_DIR | check GROUP", file=sys.stderr)
    return 2


if __name__ == "__main__":
    raise SystemExit(main())
