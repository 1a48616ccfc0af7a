"""The one comparison of rendered engine inputs with their golden files in tests/golden/.

``SILOFLOW_UPDATE_GOLDEN=1 python -m pytest ...`` rewrites the golden files instead (review the diff).
"""

from __future__ import annotations

import os
from pathlib import Path

GOLDEN = Path(__file__).resolve().parent / "golden"


def assert_matches_golden(rendered: str, name: str) -> None:
    """Compare ``rendered`` with ``tests/golden/<name>``, or rewrite that file when SILOFLOW_UPDATE_GOLDEN is set."""
    golden = GOLDEN / name
    if os.environ.get("SILOFLOW_UPDATE_GOLDEN"):
        golden.write_text(rendered)
    assert rendered == golden.read_text(), f"{name} differs from the rendered input; if intended, regenerate it"
