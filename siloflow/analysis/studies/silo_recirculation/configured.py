"""The blending analysis of one recirculation run with its settings taken from a validated ``silo_recirculation``
config section, for every caller that runs it as configured (the analysis and the shortcut's comparison)."""

from __future__ import annotations

from collections.abc import Mapping

from siloflow.analysis.studies.silo_recirculation.study import BlendingResult, Layout, analyse_blending
from siloflow.analysis.numerics.clump_tracks import ClumpTracks

#: The keys of the section that :func:`analyse_configured` reads.
SETTINGS_KEYS = ("layouts", "lti", "concentration_window", "concentration_window_target_vrr", "tracer")


def configured_layouts(settings: Mapping) -> list[Layout]:
    """The batch layouts of ``settings["layouts"]``, in their order."""
    return [Layout(layout["name"], layout["blue_fraction"], layout["sublayers"], layout["blue_at"])
            for layout in settings["layouts"]]


def analyse_configured(tracks: ClumpTracks, domain_bottom: float, domain_top: float, settings: Mapping,
                       with_transit: bool = True) -> BlendingResult:
    """:func:`~siloflow.analysis.studies.silo_recirculation.study.analyse_blending` of ``tracks`` with the
    :data:`SETTINGS_KEYS` of a validated ``silo_recirculation`` section; ``domain_bottom`` and ``domain_top`` are the
    periodic bounds in z [m]."""
    lti, tracer = settings["lti"], settings["tracer"]
    return analyse_blending(
        tracks, configured_layouts(settings), domain_bottom, domain_top, settings["concentration_window"],
        tracer["volume_fraction"], tracer["start_recirculations"], tracer["bins"], lti["period_fractions"],
        lti["passes"], lti["tolerance"], window_target_vrr=settings["concentration_window_target_vrr"],
        with_transit=with_transit,
    )
