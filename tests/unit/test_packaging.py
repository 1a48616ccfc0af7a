"""The package declares what its pipeline imports: every module outside the standard library that a pipeline module
(the packages, the workflow's scripts) imports at run time comes from a distribution in ``pyproject.toml``'s
``dependencies``, or from the optional extra that names it; the licence the package declares is the one it ships."""

from __future__ import annotations

import ast
import functools
import importlib.metadata
import re
import sys
import tomllib

import yaml

from tests.repo import REPO_ROOT

PYPROJECT = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())
#: The project's own top-level packages.
OWN = set(PYPROJECT["tool"]["setuptools"]["packages"]["find"]["include"])
OWN = {name.rstrip("*") for name in OWN}


def _distribution(requirement: str) -> str:
    """The normalised distribution name of a requirement string (``"pyyaml>=6.0"`` -> ``pyyaml``)."""
    return re.split(r"[\s<>=!~;\[]", requirement.strip(), maxsplit=1)[0].lower().replace("_", "-")


@functools.cache
def _providers() -> dict:
    """``{top-level module: [distribution, ...]}`` of the installed distributions (slow: read once)."""
    return importlib.metadata.packages_distributions()


@functools.cache
def _pipeline_imports() -> dict[str, set[str]]:
    """``{top-level module: {file, ...}}`` of every import in the pipeline's modules, function bodies included (an
    import there runs when the function does)."""
    found: dict[str, set[str]] = {}
    files = [path for folder in ("model", "engines", "analysis", "calibration", "siloflow", "siloflow/workflow/scripts")
             for path in (REPO_ROOT / folder).rglob("*.py") if "__pycache__" not in path.parts]
    for path in files:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([alias.name for alias in node.names] if isinstance(node, ast.Import) else
                     [node.module] if isinstance(node, ast.ImportFrom) and node.module and not node.level else [])
            for name in names:
                found.setdefault(name.split(".")[0], set()).add(str(path.relative_to(REPO_ROOT)))
    return found


def test_every_runtime_import_is_declared():
    declared = {_distribution(requirement) for requirement in PYPROJECT["project"]["dependencies"]}
    extras = {extra: {_distribution(requirement) for requirement in requirements}
              for extra, requirements in PYPROJECT["project"]["optional-dependencies"].items()}
    providers = _providers()
    undeclared = {}
    for module, files in _pipeline_imports().items():
        if module in sys.stdlib_module_names or module in OWN or module == "__future__":
            continue
        distributions = {name.lower().replace("_", "-") for name in providers.get(module, [module])}
        if distributions & declared:
            continue
        # an optional reader (the DaVis files) imports its library only where the extra is installed
        if any(distributions & names for extra, names in extras.items() if extra not in ("test",)):
            continue
        undeclared[module] = sorted(files)
    assert not undeclared, f"imported by the pipeline but not in pyproject.toml's dependencies: {undeclared}"


def test_the_pipeline_imports_what_it_declares_and_the_slurm_plugin_is_an_extra():
    imported = {name for module in _pipeline_imports() for name in
                _providers().get(module, [module])}
    imported = {name.lower().replace("_", "-") for name in imported}
    declared = {_distribution(requirement) for requirement in PYPROJECT["project"]["dependencies"]}
    # snakemake runs the workflow (it is the command, not an import of the packages)
    assert declared - imported - {"snakemake"} == set()
    assert "snakemake-executor-plugin-slurm" not in declared
    assert PYPROJECT["project"]["optional-dependencies"]["slurm"] == ["snakemake-executor-plugin-slurm>=1.0"]


def test_the_declared_licence_is_the_one_shipped():
    assert PYPROJECT["project"]["license"]["text"] == "GPL-3.0-or-later"
    text = (REPO_ROOT / "LICENSE").read_text()
    assert text.lstrip().startswith("GNU GENERAL PUBLIC LICENSE") and "Version 3, 29 June 2007" in text


def test_the_workflow_profile_carries_the_rerun_policy_for_every_snakemake_call():
    """Snakemake reads profiles/default/ beside the Snakefile on every call (plain `snakemake`, the Makefile's, the
    SLURM profile's): a code change reruns no finished simulation; the Makefile does not repeat the policy."""
    profile = yaml.safe_load((REPO_ROOT / "siloflow" / "workflow" / "profiles" / "default" / "config.yaml").read_text())
    assert profile == {"rerun-triggers": ["mtime", "params", "input"], "rerun-incomplete": True}
    makefile = (REPO_ROOT / "Makefile").read_text()
    assert "--rerun-triggers" not in makefile and "--rerun-incomplete" not in makefile
