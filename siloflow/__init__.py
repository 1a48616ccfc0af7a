"""siloflow: DEM calibration, validation and blending of pellets in silos, from config files to plots.

The package holds the neutral model (:mod:`siloflow.model`), the engines and the workflow's planning
(:mod:`siloflow.engines`), the analysis (:mod:`siloflow.analysis`), the calibration (:mod:`siloflow.calibration`),
the Snakemake workflow with its schemas (``siloflow/workflow/``), the engines' templates (``siloflow/templates/``),
the command line (:mod:`siloflow.cli`) and the notebook API (:mod:`siloflow.api`).

The notebook API's names are reachable from the package itself (``from siloflow import open_run``). They are loaded
on first use, so that the command line and the workflow's steps, which import the subpackages, do not load the
analysis stack (numba, pyvista) the notebook API pulls in.
"""

import importlib

#: The notebook API's public names (:mod:`siloflow.api` exports these), resolved on first access.
API_NAMES = frozenset({
    "ExitTimes", "Run", "bulk_friction", "coarse_grain", "default_width", "discharge", "exit_times", "fill_surface",
    "janssen_comparison", "open_run", "residence_time_distribution", "silo_dimensions", "silo_grid", "time_average",
    "velocity_profiles", "vrr",
})

__all__ = sorted(API_NAMES)


def __getattr__(name: str):
    # PEP 562: `from siloflow import open_run` finds the name here the first time it is asked for.
    if name in API_NAMES:
        return getattr(importlib.import_module("siloflow.api"), name)
    raise AttributeError(f"module 'siloflow' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | API_NAMES)
