"""The engines' side of what the workflow checks when it is parsed, before any step runs, as one function.

The config files are read again as plain data (:mod:`siloflow.engines.config_yaml`: Snakemake has already read them, through
YTE when a file asks for it), the configuration is validated and filled (:func:`siloflow.engines.config.validate_config`), every
case is built and accepted by its engine and every run estimated, each engine in use finds its programs, and the runs
siloflow did not make are found. The workflow (``siloflow/workflow/rules/common.smk``) calls :func:`preflight` first, then
reads the measured files the configuration names (:func:`siloflow.analysis.io.measured_inputs.check_measured_inputs`), so that
`snakemake -n` takes this path too, as do the tests of hostile configurations. Each refusal is one
:class:`PreflightError` whose message names the key.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from siloflow.model.cases import cases_of
from siloflow.model.cases.kinds import configured_kinds
from siloflow.engines.config import ConfigError, engines_in_use, validate_config
from siloflow.engines.config_yaml import ConfigFileError, read_config_file
from siloflow.engines.existing_runs import check_existing_runs
from siloflow.engines.interface import ENGINE_KINDS, CaseNotSupported, EngineNotFound, EngineOptions, engine_for, engine_named
from siloflow.engines.planning import config_estimates

__all__ = ["Preflight", "PreflightError", "preflight"]


class PreflightError(ValueError):
    """A configuration the workflow refuses before any step runs; the message names the key."""


@dataclass(frozen=True)
class Preflight:
    """A configuration the workflow accepted.

    Attributes
    ----------
    config : dict
        The validated configuration, every default filled in.
    cases : dict
        ``{case kind: {run id: case}}``: every case it defines (the flat-bottom silo's as configured, before
        calibration).
    existing_dumps : dict
        ``{name: [DumpFile, ...]}``: the dump files of each run siloflow did not make.
    estimates : list of RunEstimate
        The cost estimate of every run (:func:`siloflow.engines.planning.config_estimates`).
    """

    config: dict
    cases: dict
    estimates: list = field(default_factory=list)
    existing_dumps: dict = field(default_factory=dict)


def _read_files(config_files: Iterable[str | os.PathLike]) -> None:
    for path in config_files:
        try:
            read_config_file(path)
        except ConfigFileError as error:
            raise PreflightError(f"Invalid configuration: {error}") from None
        except OSError as error:
            raise PreflightError(f"Invalid configuration: config file {str(path)!r} cannot be read "
                                 f"({error.strerror})") from None


def _cases(config: Mapping) -> dict:
    """Build every case and let its engine accept it: geometry, sizing and engine limits fail here, first."""
    built = {}
    for kind in configured_kinds():
        try:
            built[kind] = cases_of(config, kind)
            engine = engine_for(config, kind)
            for case in built[kind].values():
                engine.check_case(case)
        except CaseNotSupported as error:
            raise PreflightError(f"The {kind} runs cannot run on their engine: {error}") from None
        except (ValueError, KeyError) as error:
            raise PreflightError(f"Invalid {kind} configuration: {error}") from None
    return built


def _engines_installed(config: Mapping) -> None:
    """Each engine that runs a case (both when the verification suite runs) finds its programs, named by
    ``engine.*``; the cross-engine check, run on request, finds them when it starts."""
    kinds = engines_in_use(config) | (set(ENGINE_KINDS) if config["verification"]["enabled"] else set())
    for kind in sorted(kinds):
        try:
            engine_named(kind).check_installed(EngineOptions.from_config(config, kind))
        except EngineNotFound as error:
            raise PreflightError(f"Invalid configuration: {error}") from None


def _existing_runs(config: Mapping) -> dict:
    try:
        return check_existing_runs(config)
    except ConfigError as error:
        raise PreflightError(f"Invalid existing run (silo_flat.existing_runs): {error}") from None


def preflight(config: Mapping, config_files: Iterable[str | os.PathLike] = ()) -> Preflight:
    """Check a configuration as the workflow does when it is parsed, before any step runs.

    Parameters
    ----------
    config : mapping
        The configuration as Snakemake merged it from ``config_files`` (and ``--config``).
    config_files : iterable of path
        The config files it came from, read again as plain data. Relative paths in the configuration (PIV files,
        measured profiles, existing runs) are relative to the working directory.

    Returns
    -------
    Preflight
        The validated configuration, its cases and the files it names.

    Raises
    ------
    PreflightError
        The first refusal, naming the key (or the file and its line).
    """
    _read_files(config_files)
    try:
        filled = validate_config(config)
    except ConfigError as error:
        raise PreflightError(f"Invalid configuration: {error}") from None
    cases = _cases(filled)
    try:
        estimates = config_estimates(filled)
    except ValueError as error:
        raise PreflightError(f"Invalid configuration: {error}") from None
    _engines_installed(filled)
    return Preflight(config=filled, cases=cases, estimates=estimates, existing_dumps=_existing_runs(filled))
