"""The results layout is defined once (siloflow/engines/layout.py): the rule files build every path from its names, and never
write a folder of results/ themselves."""

from __future__ import annotations

import re

from tests.repo import REPO_ROOT
from siloflow.engines.layout import (CALIBRATED_PARAMETERS, CALIBRATION_DIR, CROSS_ENGINE_DIR, RESULTS, SUMMARY_DIR, VALIDATION_RECORD,
                            VERIFICATION_DIR, case_root)
from siloflow.model.cases.kinds import configured_kinds


def test_the_rule_files_write_no_results_folder_of_their_own():
    for path in sorted((REPO_ROOT / "siloflow" / "workflow" / "rules").glob("*.smk")):
        text = path.read_text()
        assert not re.search(r"\{RESULTS\}/", text.replace('{RESULTS}/ (', "")), f"{path.name} builds a results path"
        assert '"results/' not in text, f"{path.name} names a results folder"


def test_the_folders_across_runs_lie_in_results_and_the_case_roots_apart():
    folders = [CALIBRATION_DIR, SUMMARY_DIR, VERIFICATION_DIR, CROSS_ENGINE_DIR]
    assert all(folder.startswith(f"{RESULTS}/") for folder in folders) and len(set(folders)) == 4
    assert CALIBRATED_PARAMETERS == "results/calibration/parameters.yaml"
    assert VALIDATION_RECORD == "results/summary/record"
    # the Jenike runs sit inside the calibration's folder; no other case root is a folder across runs
    assert case_root("jenike").startswith(f"{CALIBRATION_DIR}/")
    assert not {case_root(kind) for kind in configured_kinds() if kind != "jenike"} & set(folders)
    # the verification suite's problems are a case kind without a config section; their runs fill its folder
    assert case_root("verification") == VERIFICATION_DIR
