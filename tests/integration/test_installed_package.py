"""A non-editable install of siloflow carries its workflow, schemas and templates: installed from a wheel into a
fresh virtual environment, `siloflow check` validates and plans a configuration from a folder outside the clone.

The wheel goes in without its dependencies, which the new environment reads from this one's (a path in a .pth
file: this environment's own .pth files, the editable install's finder among them, are not processed), so that the
test takes seconds rather than minutes of pip (the build itself fetches setuptools, as any install does); what is under test is the package and its data, not pip's
resolver.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

from tests.repo import REPO_ROOT

pytestmark = [pytest.mark.integration, pytest.mark.core_seconds(30)]


def _site_packages(environment: Path) -> Path:
    return Path(sysconfig.get_path("purelib", vars={"base": str(environment), "platbase": str(environment)}))


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """A fresh virtual environment with siloflow installed from its wheel."""
    work = tmp_path_factory.mktemp("installed")
    source = work / "source"
    # a copy of the tracked files, so that the build writes nothing into the clone
    tracked = subprocess.run(["git", "ls-files", "-z"], cwd=REPO_ROOT, capture_output=True, check=True).stdout
    for name in filter(None, tracked.decode().split("\0")):
        origin = REPO_ROOT / name
        if origin.is_file() and not origin.is_symlink():
            (source / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(origin, source / name)
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet",
                            "--wheel-dir", str(work / "wheel"), str(source)], capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-3000:]
    environment = work / "venv"
    venv.create(environment, with_pip=False)
    _site_packages(environment).joinpath("siloflow-test-dependencies.pth").write_text(
        str(Path(sysconfig.get_path("purelib"))) + "\n")
    (wheel,) = (work / "wheel").glob("siloflow-*.whl")
    install = subprocess.run([sys.executable, "-m", "pip", "--python", str(environment / "bin" / "python"), "install",
                              "--no-deps", "--no-index", "--quiet", str(wheel)], capture_output=True, text=True)
    assert install.returncode == 0, install.stderr[-3000:]
    return environment


def test_the_wheel_carries_the_workflow_schemas_and_templates(installed):
    package = _site_packages(installed) / "siloflow"
    for name in ("workflow/Snakefile", "workflow/rules/common.smk", "workflow/scripts/case_run.py",
                 "workflow/schemas/config.schema.yaml", "workflow/schemas/cases/silo_flat.schema.yaml",
                 "workflow/report/workflow.rst", "workflow/profiles/default/config.yaml",
                 "templates/liggghts/base.lmp.j2", "templates/yade/base.py.j2", "cli/main.py", "api/runs.py"):
        assert (package / name).is_file(), name


def test_the_installed_command_checks_a_configuration_outside_the_clone(installed, tmp_path):
    shutil.copytree(REPO_ROOT / "config", tmp_path / "config")
    where = subprocess.run([str(installed / "bin" / "python"), "-c", "import siloflow.cli.main as m; print(m.__file__)"],
                           cwd=tmp_path, capture_output=True, text=True)
    assert where.returncode == 0 and Path(where.stdout.strip()).is_relative_to(installed), where.stdout + where.stderr
    checked = subprocess.run([str(installed / "bin" / "siloflow"), "check", "--config", "config/config.yaml"],
                             cwd=tmp_path, capture_output=True, text=True)
    assert checked.returncode == 0, checked.stderr
    assert checked.stdout.startswith("config/config.yaml: valid. 17 engine runs")
