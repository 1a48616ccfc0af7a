"""`siloflow hypothesis NAME --dry-run` plans each hypothesis's pair (a dry run: no engine runs, nothing recorded)."""

from __future__ import annotations

import pytest

from siloflow.cli.main import main
from siloflow.engines.hypotheses import HYPOTHESES
from tests.repo import REPO_ROOT

pytestmark = pytest.mark.core_seconds(10)


# one hypothesis: every one's configuration layers are validated by the unit tests, and each dry run builds the
# workflow twice
@pytest.mark.parametrize("name", ["stiffness_silo"])
def test_a_hypothesis_plans_its_base_and_its_variant_to_their_rows_and_records_nothing(name, tmp_path, monkeypatch,
                                                                                        capfd):
    monkeypatch.chdir(REPO_ROOT)  # the pair's configuration layers are the clone's
    record = tmp_path / "record"
    assert main(["hypothesis", name, "--dry-run", "--directory", str(tmp_path), "--record", str(record)]) == 0
    output = "".join(capfd.readouterr())
    group = HYPOTHESES[name].group
    assert output.count(f"rule validation_rows_{group}:") == 2, output[-3000:]
    for member in ("base", "variant"):
        assert (tmp_path / "results" / "hypotheses" / name / member).is_dir()
    assert output.count("This was a dry-run") == 2
    assert not record.exists()
