"""Each attempt of a run step notes the code's commit and the engine's version in the run's folder."""

import re

from siloflow.engines.layout import RUN_PROVENANCE
from siloflow.engines.provenance import UNKNOWN, code_commit, note_attempt, read_attempts
from tests.repo import REPO_ROOT


def test_each_attempt_is_noted_in_order_and_read_back(tmp_path):
    assert read_attempts(tmp_path) == []
    note_attempt(tmp_path, "liggghts", "3.8.0", "abc")
    attempts = note_attempt(tmp_path, "liggghts", "3.8.0", "def-dirty")
    assert [(a["commit"], a["engine"], a["engine_version"]) for a in attempts] == [
        ("abc", "liggghts", "3.8.0"), ("def-dirty", "liggghts", "3.8.0")]
    assert read_attempts(tmp_path) == attempts and (tmp_path / RUN_PROVENANCE).is_file()
    assert all(re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00", a["started"]) for a in attempts)


def test_the_commit_is_the_clone_s_or_unknown_outside_git(tmp_path):
    assert code_commit(tmp_path) == UNKNOWN
    assert re.fullmatch(r"[0-9a-f]{40}(-dirty)?", code_commit(REPO_ROOT)) or code_commit(REPO_ROOT) == UNKNOWN
