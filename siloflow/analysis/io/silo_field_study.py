"""Writer of the files of one flat-bottom silo field study
(:class:`siloflow.analysis.studies.silo_flat.field_study.SiloFieldStudy`) that every run has, whether siloflow made it or not:
the ParaView time series and time average, the averaged fields' arrays, the flow tables, the summary and the plots of
the flow. What needs the settled fill's contacts (the contact-stress VTI, the Janssen table and plot, the force
chains) is left to the caller. Every table and field file is written atomically (:mod:`siloflow.analysis.io.tables`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from siloflow.analysis.io.fields import save_fields_npz, write_fields_vti, write_pvd
from siloflow.analysis.io.tables import write_flow_table, write_json
from siloflow.analysis.studies.silo_flat.field_study import (
    SiloFieldStudy,
    boundary_rows,
    centreline_rows,
    field_summary,
    instantaneous_profile_rows,
    kinematic_rows,
    profile_rows,
    vtk_series,
)
from siloflow.analysis.studies.silo_flat.plots import (
    plot_centreline_velocity,
    plot_kinematic_constant,
    plot_kinematic_horizontal_velocity,
    plot_profiles_over_silo,
    plot_velocity_contour,
)

__all__ = ["SILO_FIELD_STUDY_FILES", "write_silo_field_study"]

#: The names of the files :func:`write_silo_field_study` writes (as a Snakemake rule's outputs name them).
SILO_FIELD_STUDY_FILES = ("pvd", "arrays", "profiles", "boundaries", "kinematic", "instantaneous", "centreline",
                          "summary", "profile_plot", "contour_plot", "kinematic_plot", "kinematic_u_plot",
                          "centreline_plot")


def write_silo_field_study(outputs: Mapping[str, str | os.PathLike], study: SiloFieldStudy, vtk_every: int,
                           outflow_rate: float, width: float, outlet_width: float, run_name: str,
                           kinematic_findings=None) -> Path:
    """Write a silo field study's fields, tables, summary and flow plots.

    Parameters
    ----------
    outputs : mapping of str to path
        Where each file goes, by the names of :data:`SILO_FIELD_STUDY_FILES` (a Snakemake rule's ``output`` serves as
        it is; other names are not looked at): ``pvd``, the ParaView collection (.pvd) of every ``vtk_every``-th
        frame's fields, each ``fields_<step>.vti`` beside it, with the time average ``averaged.vti``; ``arrays``,
        the time average as .npz; ``profiles``, ``boundaries``, ``kinematic``, ``instantaneous`` and
        ``centreline``, the CSV tables of the depth-averaged and front-wall velocity profiles, the flow channel
        boundary, the kinematic constant B(z), the instantaneous profiles and the centreline velocity (SI units, as
        their columns say); ``summary``, the JSON summary; ``profile_plot``, ``contour_plot``, ``kinematic_plot``,
        ``kinematic_u_plot`` and ``centreline_plot``, the plots (PNG, PDF or SVG, as each suffix says) of the
        time-averaged profiles over the silo, the depth-averaged v_z, B(z), the horizontal velocity against the
        kinematic model's and the centreline velocity.
    study : SiloFieldStudy
        The study (:func:`siloflow.analysis.studies.silo_flat.field_study.analyse_silo_fields`).
    vtk_every : int
        Every how many frames one goes into the time series [-]
        (:func:`~siloflow.analysis.studies.silo_flat.field_study.vtk_series`).
    outflow_rate : float
        The run's measured mass flow rate out of the silo [kg/s], which the summary sets the profile flow rates
        against (:func:`~siloflow.analysis.studies.silo_flat.field_study.field_summary`).
    width, outlet_width : float
        Silo width and outlet width [m], for the silo's outline in the plots.
    run_name : str
        The run's name, in the plots' titles.
    kinematic_findings : sequence of StudyNote, optional
        The study's trend of B(z) drawn beside it (``findings`` of
        :func:`~siloflow.analysis.studies.silo_flat.plots.plot_kinematic_constant`); None: none.

    Returns
    -------
    pathlib.Path
        The folder of the VTI files (that of ``pvd``), where a caller may write more of them.

    Raises
    ------
    ValueError
        When ``outputs`` lacks one of the names; nothing is written then.
    """
    missing = [name for name in SILO_FIELD_STUDY_FILES if name not in outputs.keys()]
    if missing:
        raise ValueError(f"outputs lacks {missing}: a silo field study writes {list(SILO_FIELD_STUDY_FILES)}")
    # ParaView: a time series of every n-th frame and the time average.
    fields_dir = Path(outputs["pvd"]).parent
    series = vtk_series(study.steps, study.times, vtk_every)
    for index, time, name in series:
        write_fields_vti(fields_dir / name, study.grid, study.fields[index], time=time)
    write_pvd(outputs["pvd"], [(time, name) for _, time, name in series])
    write_fields_vti(fields_dir / "averaged.vti", study.grid, study.averaged)
    save_fields_npz(outputs["arrays"], study.averaged)

    write_flow_table(outputs["profiles"], profile_rows(study.profiles, study.front))
    write_flow_table(outputs["boundaries"], boundary_rows(study.profiles, study.uncertainty))
    write_flow_table(outputs["kinematic"], kinematic_rows(study.profiles, study.uncertainty))
    write_flow_table(outputs["instantaneous"],
                     instantaneous_profile_rows(study.times, study.depth_series, study.heights))
    write_flow_table(outputs["centreline"], centreline_rows(study.times, study.heights, study.centreline))
    write_json(outputs["summary"], field_summary(study, outflow_rate))

    plane = study.averaged_depth
    plot_profiles_over_silo(study.profiles, width, outlet_width, study.top, outputs["profile_plot"],
                            f"Time-averaged v_z, {run_name}", uncertainty=study.uncertainty)
    plot_velocity_contour(plane.grid.x, plane.grid.z, plane.velocity[:, 0, :, 2], width, outlet_width,
                          outputs["contour_plot"], f"Depth-averaged v_z, {run_name}")
    plot_kinematic_constant(study.profiles.heights, study.profiles.kinematic_B, outputs["kinematic_plot"],
                            "Kinematic constant B(z)", B_error=study.uncertainty.kinematic_B_error,
                            findings=kinematic_findings)
    plot_kinematic_horizontal_velocity(study.profiles, outputs["kinematic_u_plot"],
                                       "Horizontal velocity: DEM against the kinematic model")
    plot_centreline_velocity(study.times, study.heights, study.centreline, outputs["centreline_plot"],
                             "Centreline velocity")
    return fields_dir
