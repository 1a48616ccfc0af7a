"""The small flat-bottom silo the engine benchmarks run: the default config with a few ``silo_flat`` keys changed."""

from __future__ import annotations

import copy

from siloflow.model.cases.silo_flat import SiloCase, build_silo_case
from siloflow.engines.config import load_config_file, validate_config
from tests.repo import REPO_ROOT
from siloflow.engines.interface import Engine, engine_for


def default_config_with(section: str, overrides: dict) -> dict:
    """The default config, validated, with ``overrides`` on its ``section``."""
    raw = load_config_file(REPO_ROOT / "config" / "config.yaml")
    raw[section] = {**raw[section], **copy.deepcopy(overrides)}
    return validate_config(raw)


def small_silo(overrides: dict) -> tuple[SiloCase, Engine]:
    """The silo case of the default config with ``overrides`` on ``silo_flat``, and the engine that runs it."""
    config = default_config_with("silo_flat", overrides)
    return build_silo_case(config), engine_for(config, "silo_flat")
