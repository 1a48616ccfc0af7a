"""The documentation: the MkDocs site builds with --strict (a broken link, a missing page or an API docstring the
renderer cannot read fails it) and has every page of its navigation, and the README stays a short entry point.
`make docs` runs the same build; this test runs it on every `make test`."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import PurePosixPath

import pytest
import yaml

from engines.config import REPO_ROOT

README_MAX_LINES = 220


def _nav_pages(entries) -> list[str]:
    """Every Markdown page the navigation names, in order (entries are 'page.md', {title: 'page.md'} or
    {title: [entries]})."""
    pages = []
    for entry in entries:
        values = entry.values() if isinstance(entry, dict) else [entry]
        for value in values:
            pages.extend(_nav_pages(value) if isinstance(value, list) else [value])
    return pages


def _built_page(page: str) -> PurePosixPath:
    """Where the site puts a page with ``use_directory_urls: false``: ``a/b.md`` is ``a/b.html``, and a folder's
    ``index.md`` or ``README.md`` is its ``index.html``."""
    path = PurePosixPath(page)
    name = "index" if path.stem in ("index", "README") else path.stem
    return path.with_name(f"{name}.html")


def test_the_navigation_names_pages_that_exist():
    config = yaml.safe_load((REPO_ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    pages = _nav_pages(config["nav"])
    assert pages, "mkdocs.yml has no navigation"
    missing = [page for page in pages if not (REPO_ROOT / "docs" / page).is_file()]
    assert not missing, f"mkdocs.yml names pages that are not in docs/: {missing}"
    assert "validation/README.md" in pages, "the validation record is a page of the site"


@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None,
                    reason="mkdocs is not installed (the docs extra: pip install -e '.[docs]', which make install does)")
def test_the_site_builds_strictly_with_every_page_of_its_navigation(tmp_path):
    site = tmp_path / "site"
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                            cwd=REPO_ROOT, capture_output=True, text=True, timeout=300,
                            env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert result.returncode == 0, f"mkdocs build --strict failed:\n{result.stdout}\n{result.stderr}"
    config = yaml.safe_load((REPO_ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    unbuilt = [page for page in _nav_pages(config["nav"]) if not (site / _built_page(page)).is_file()]
    assert not unbuilt, f"pages of the navigation the build did not write: {unbuilt}"
    # the validation record's links point at the files beside it, which the site must carry
    assert (site / "validation" / "silo" / "runs.csv").is_file()
    # the API reference is rendered from the docstrings, not left as its ::: directives
    api = (site / "api" / "engines.html").read_text(encoding="utf-8")
    assert "engines.interface" in api and ":::" not in api


def test_the_readme_is_a_short_entry_point_with_the_two_commands():
    lines = (REPO_ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines; the manual belongs in docs/"
    text = "\n".join(lines)
    assert "make run" in text and "make test" in text
