"""siloflow from a notebook: open a finished run and turn its frames into the study's numbers.

The calls in order (every quantity in SI units; see docs/notebooks.md):

1. :func:`open_run` opens a run folder of either engine and any case kind: ``run.record``, ``run.case``,
   ``run.frames()``, ``run.clumps()``, ``run.wall_forces()``, ``run.contacts()``.
2. A flat-bottom silo: :func:`silo_dimensions`, :func:`discharge` (bulk density, steady flow rate, Beverloo),
   :func:`fill_surface`, :func:`silo_grid`, :func:`coarse_grain` with a kernel of :func:`default_width`,
   :func:`time_average`, :func:`velocity_profiles` and :func:`janssen_comparison`.
3. A recirculating silo: :func:`exit_times` (outlet crossings, re-entries and passes of every clump),
   :func:`residence_time_distribution` and :func:`vrr`.
4. A Jenike shear test: :func:`bulk_friction`.

Nothing here draws: the notebooks in ``examples/`` plot with matplotlib, and importing siloflow leaves matplotlib's
backend alone.
"""

from siloflow import API_NAMES
from siloflow.analysis.numerics.coarse_graining import default_width
from siloflow.analysis.numerics.exit_times import ExitTimes, exit_times
from siloflow.api.fields import coarse_grain, silo_grid, time_average, velocity_profiles
from siloflow.api.janssen import janssen_comparison
from siloflow.api.jenike import bulk_friction
from siloflow.api.residence import residence_time_distribution, vrr
from siloflow.api.runs import Run, open_run
from siloflow.api.silo import discharge, fill_surface, silo_dimensions

__all__ = sorted(API_NAMES)
