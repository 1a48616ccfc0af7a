"""Where the tests find the clone's files: the repository root (configs, docs, examples) and the package's folder
(workflow, schemas, templates)."""

from pathlib import Path

#: The clone's root: config/, docs/, examples/, tests/.
REPO_ROOT = Path(__file__).resolve().parents[1]
#: The package's folder in the clone.
PACKAGE_ROOT = REPO_ROOT / "siloflow"
