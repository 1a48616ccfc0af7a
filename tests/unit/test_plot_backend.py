"""No module of siloflow chooses a matplotlib backend when imported: a notebook that imports siloflow's analysis keeps
its own. The headless choice belongs to the entry points (the Snakefile and tests/conftest.py set MPLBACKEND=Agg)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from tests.repo import REPO_ROOT

#: The packages whose every module is imported; the notebook API (``siloflow.api``) only where it exists.
PACKAGES = ("siloflow.analysis", "siloflow.calibration", "siloflow.engines", "siloflow.model")
OPTIONAL_PACKAGES = ("siloflow.api",)
#: A backend other than the default that works without a display, as a notebook's own choice stands for.
OWN_BACKEND = "svg"

# Run in a fresh interpreter: this test process has imported matplotlib already, with the backend of tests/conftest.py.
IMPORT_EVERY_MODULE = """
import importlib, json, pkgutil, sys

import matplotlib

packages, optional = sys.argv[1].split(","), sys.argv[2].split(",")
before = matplotlib.get_backend()
modules, failed = [], {}
for package in packages + optional:
    try:
        root = importlib.import_module(package)
    except ModuleNotFoundError as error:
        if package in optional and error.name == package:
            continue
        raise
    modules.append(package)
    walked = pkgutil.walk_packages(root.__path__, package + ".", onerror=lambda name: failed.setdefault(name, "walk"))
    modules += [info.name for info in walked]
for name in modules:
    try:
        importlib.import_module(name)
    except Exception as error:
        failed[name] = repr(error)
print(json.dumps({"before": before, "after": matplotlib.get_backend(), "modules": modules, "failed": failed,
                  "pyplot": "matplotlib.pyplot" in sys.modules}))
"""


def test_importing_every_module_keeps_the_backend_the_user_chose():
    environment = {**os.environ, "MPLBACKEND": OWN_BACKEND, "PYTHONPATH": str(REPO_ROOT)}
    result = subprocess.run([sys.executable, "-c", IMPORT_EVERY_MODULE, ",".join(PACKAGES), ",".join(OPTIONAL_PACKAGES)],
                            cwd=REPO_ROOT, env=environment, capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout.splitlines()[-1])
    assert not found["failed"], f"modules that did not import: {found['failed']}"
    assert {"siloflow.analysis.io.plots", "siloflow.calibration.charts", "siloflow.analysis.studies.silo_flat.plots"} <= set(found["modules"])
    assert found["pyplot"], "no module imported pyplot: the test would not see a backend switched on its import"
    assert found["before"] == OWN_BACKEND
    assert found["after"] == OWN_BACKEND, f"importing siloflow switched matplotlib's backend to {found['after']!r}"
