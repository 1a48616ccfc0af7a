"""Where the flat-bottom silo's field series starts on its run's clock, and which window of it is averaged.

:func:`siloflow.analysis.studies.silo_flat.field_study.analyse_silo_fields` keeps the frames from the opening of the outlet
on and times its fields from the first of them (``fields/fields.pvd`` starts at 0 s); the particle frames carry the
simulated time. :func:`field_clock_origin` gives the simulated time of that first frame, which put on the fields'
times plays them in step with the particles (the run's ParaView files, ``siloflow/workflow/rules/paraview.smk``).
:func:`averaging_window` says over which times of that clock the fields are averaged: the configured
``silo_flat.fields.average_window`` (the study's 0.5-0.7 s, thesis §5.4.3.4) or the steady flow window, and
which of the two (:data:`WINDOW_CONFIGURED`, :data:`WINDOW_STEADY`, as ``fields.json`` records it). Pure
computation, no file I/O.
"""

from __future__ import annotations

import numpy as np

from siloflow.model.checks import finite_number, positive_number

__all__ = ["WINDOW_CONFIGURED", "WINDOW_STEADY", "averaging_window", "field_clock_origin"]

WINDOW_CONFIGURED = "silo_flat.fields.average_window"
"""The source of an averaging window given as times after the outlet opened (s)."""

WINDOW_STEADY = "silo_flat.steady_window"
"""The source of the steady flow window: discharged-mass fractions that the flow analysis converts to times."""


def averaging_window(configured, steady) -> tuple[tuple[float, float], str]:
    """The window the fields are time-averaged over [s after the outlet opened], and the key it comes from.

    Parameters
    ----------
    configured : sequence of float or None
        ``silo_flat.fields.average_window``, ``(start, end)`` [s after opening]; None (or empty) for none.
    steady : sequence of float
        The steady flow window ``(start, end)`` [s after opening]: the times at which the discharged mass reaches
        the fractions of ``silo_flat.steady_window`` (``steady_window_start_s``, ``steady_window_end_s`` of the run's
        ``flow.json``).

    Returns
    -------
    window : tuple of float
        ``configured`` when given, else ``steady`` [s].
    source : str
        :data:`WINDOW_CONFIGURED` or :data:`WINDOW_STEADY`.

    Raises
    ------
    ValueError
        When the chosen window is not two finite times ``0 <= start < end``.
    """
    chosen, source = (configured, WINDOW_CONFIGURED) if configured else (steady, WINDOW_STEADY)
    if len(chosen) != 2:
        raise ValueError(f"an averaging window is (start, end) in s, got {chosen!r} ({source})")
    start, end = (finite_number("averaging window start", chosen[0]), finite_number("averaging window end", chosen[1]))
    if not 0.0 <= start < end:
        raise ValueError(f"an averaging window must have 0 <= start < end (s after opening), got "
                         f"{[start, end]} ({source})")
    return (start, end), source


def field_clock_origin(frame_times, open_time: float, timestep: float) -> float:
    """The simulated time of the first frame at or after the outlet opened [s].

    Parameters
    ----------
    frame_times : array_like
        Simulated time of every saved frame of the run [s].
    open_time : float
        When the outlet opened [s] (the run record's ``open_time_s``).
    timestep : float
        The run's time step [s]: a frame less than half a step before ``open_time`` is the opening's own (its time
        rounded differently), as the field study keeps the frames whose step is the opening step or later.

    Returns
    -------
    float
        The time 0 of the field series on the run's clock [s].

    Raises
    ------
    ValueError
        When no frame is at or after the opening.
    """
    open_time = finite_number("open_time", open_time)
    timestep = positive_number("timestep", timestep)
    times = np.asarray(frame_times, dtype=float)
    later = times[times >= open_time - 0.5 * timestep]
    if later.size == 0:
        raise ValueError(f"no frame at or after the opening at {open_time!r} s (the last is at "
                         f"{times.max() if times.size else float('nan')!r} s)")
    return float(later.min())
