"""Where the flat-bottom silo's field series starts on its run's clock.

:func:`siloflow.analysis.studies.silo_flat.field_study.analyse_silo_fields` keeps the frames from the opening of the outlet
on and times its fields from the first of them (``fields/fields.pvd`` starts at 0 s); the particle frames carry the
simulated time. :func:`field_clock_origin` gives the simulated time of that first frame, which put on the fields'
times plays them in step with the particles (the run's ParaView files, ``siloflow/workflow/rules/paraview.smk``). Pure
computation, no file I/O.
"""

from __future__ import annotations

import numpy as np

from siloflow.model.checks import finite_number, positive_number

__all__ = ["field_clock_origin"]


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
