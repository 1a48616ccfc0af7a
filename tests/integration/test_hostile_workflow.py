"""Plain `snakemake -n` with a hostile config file: the workflow refuses it when it is parsed, naming the key, and
nothing is made (no engine runs; tests/unit/test_hostile_configs.py feeds thirty more through the same checks)."""

from __future__ import annotations

import pytest

from tests.repo import REPO_ROOT
from tests.conftest import run_snakemake

pytestmark = pytest.mark.core_seconds(15)


@pytest.mark.parametrize("text, expected", [
    # Snakemake evaluates the expression when it loads the file (it has no switch to refuse YTE); the workflow then
    # refuses the file before anything runs
    ("__use_yte__: true\ndefaults:\n  seed: ?1 + 1\n", "__use_yte__"),
    ("silo_recirculation:\n  lti:\n    input_csv: feed.csv\n",
     "config key 'silo_recirculation.lti.input_csv' is not a siloflow setting"),
    ("silo_flat:\n  fields:\n    measured_profiles: profiles\n",
     "config key 'silo_flat.fields.measured_profiles': 'profiles' is a folder"),
], ids=["yte", "key-nothing-reads", "measured-profiles-folder"])
def test_plain_snakemake_refuses_a_hostile_config_when_the_workflow_is_parsed(tmp_path, text, expected):
    (tmp_path / "profiles").mkdir()
    config_path = tmp_path / "hostile.yaml"
    config_path.write_text(text)
    result = run_snakemake(tmp_path, "-n", "--cores", "1", "--configfile", str(REPO_ROOT / "config" / "config.yaml"),
                           str(config_path))
    output = result.stdout + result.stderr
    assert result.returncode != 0 and expected in output, output[-3000:]
    assert not (tmp_path / "results").exists()
