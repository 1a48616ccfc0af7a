"""CITATION.cff: a Citation File Format 1.2.0 file for siloflow itself, whose version and licence are pyproject's.
Read with PyYAML and checked key by key, without network (no cffconvert, no schema download)."""

from __future__ import annotations

import tomllib

import yaml

from tests.repo import REPO_ROOT


def _citation() -> dict:
    return yaml.safe_load((REPO_ROOT / "CITATION.cff").read_text(encoding="utf-8"))


def _project() -> dict:
    with open(REPO_ROOT / "pyproject.toml", "rb") as file:
        return tomllib.load(file)["project"]


def test_the_citation_file_has_cff_1_2_0_s_required_keys():
    citation = _citation()
    assert citation["cff-version"] == "1.2.0"
    assert citation["message"] == "If you use siloflow, please cite it using the metadata from this file."
    assert citation["title"] == "siloflow: config-driven DEM pipeline for silos and silo blenders"
    assert citation["authors"] == [{"name": "The siloflow developers"}]
    assert citation["type"] == "software"


def test_the_citation_s_version_and_licence_are_pyproject_s():
    citation, project = _citation(), _project()
    # YAML reads 0.1.0 as a string; the version must not be a number (0.1 would lose its patch part)
    assert citation["version"] == project["version"] == "0.1.0"
    licence = project["license"]["text"] if isinstance(project["license"], dict) else project["license"]
    assert citation["license"] == licence == "GPL-3.0-or-later"


def test_the_citation_describes_siloflow_and_the_study_it_reproduces():
    citation = _citation()
    abstract = citation["abstract"]
    assert abstract.startswith("siloflow is a Snakemake and Jinja orchestration layer for the DEM engines LIGGGHTS and YADE.")
    assert "a PhD thesis on DEM (EDEM 2.7) and PIV of HDPE pellet flow and blending" in abstract
    assert "\n" not in abstract  # a folded block: one paragraph
    assert {"discrete element method", "LIGGGHTS", "YADE", "Jenike direct shear test", "HDPE pellets"} <= set(citation["keywords"])
    # the study's bibliographic details are not at hand: no reference is given rather than an invented one
    assert "references" not in citation
