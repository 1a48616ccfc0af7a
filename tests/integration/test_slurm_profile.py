"""The SLURM profile plans the full-scale study (a dry run: nothing is submitted, no engine runs)."""

from __future__ import annotations

import pytest

from tests.repo import REPO_ROOT
from tests.conftest import run_snakemake

pytestmark = pytest.mark.core_seconds(20)


def test_slurm_profile_plans_the_thesis_config(tmp_path):
    profile = REPO_ROOT / "config" / "profiles" / "slurm"
    result = run_snakemake(tmp_path, "--profile", str(profile), "-n", "--configfile",
                           str(REPO_ROOT / "config" / "thesis.yaml"))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    output = result.stdout + result.stderr
    assert "This was a dry-run" in output
    # every engine stage of the study is planned as a job
    for rule in ("jenike_run", "silo_run", "silo_recirculation_run", "blender_run"):
        assert rule in output
