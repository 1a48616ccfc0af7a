"""Writer of a run's ParaView state: a pvpython script that opens the run's ParaView files, ready to play.

The script (``paraview/state.py`` of a run) loads the walls, the particles coloured by their speed (drawn as spheres
of their own radius), the fields, and any lines the run has (tracks, pathlines, force chains: loaded, hidden until
ticked), and sets the animation to the data's times. Open it in ParaView with File > Load State (a Python state), or
run ``pvpython state.py``. Every file is named relative to the script's folder (``__file__``, which pvpython and
ParaView's Python both set), so a copied or moved run folder still opens.

Why plain string templating, not Jinja
--------------------------------------
siloflow's one Jinja environment (:func:`siloflow.engines.templating.deck_environment`) renders engine decks: its loader is
the engines' ``templates/`` folder and its filters admit only deck tokens; the analysis does not import the engines
(one-way layers). The state is Python, where the safe way to put a value into code is Python's own literal, so every
value here enters the script through :func:`repr` of a plain ``str`` or ``float``, and nothing from a configuration is
ever code.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from siloflow.analysis.io.tables import write_text

__all__ = ["StateLines", "paraview_state_script", "write_paraview_state"]

#: Point-data array the particles are coloured by, and the one that gives each sphere its radius.
PARTICLE_COLOUR = "speed"
PARTICLE_RADIUS = "radius"


@dataclass(frozen=True)
class StateLines:
    """A file of lines the state loads hidden, coloured by one of its arrays.

    Attributes
    ----------
    name : str
        Its name in ParaView's pipeline browser (letters, digits, ``_``).
    path : str or os.PathLike
        The .vtp file.
    array : str
        The array to colour by.
    cells : bool
        Whether ``array`` is cell data (else point data).
    """

    name: str
    path: str | os.PathLike
    array: str
    cells: bool = True


def _relative(path, folder: Path) -> str:
    """``path`` relative to ``folder``, with ``/`` separators (the script joins the parts on its own system)."""
    return PurePosixPath(*Path(os.path.relpath(Path(path).resolve(), folder.resolve())).parts).as_posix()


#: Names the script itself uses: a line's pipeline name is a variable of the script, so it may not be one of them.
_RESERVED = frozenset({"os", "RUN", "HERE", "here", "view", "walls", "particles", "fields", "ColorBy",
                       "GetActiveViewOrCreate", "GetAnimationScene", "Hide", "PVDReader", "SetActiveSource", "Show",
                       "XMLPolyDataReader"})


def _name(name: str) -> str:
    if not isinstance(name, str) or not name.isidentifier() or name in _RESERVED or name.endswith("_display"):
        raise ValueError(f"a pipeline name must be an identifier the state does not use itself, got {name!r}")
    return name


def paraview_state_script(script_path: str | os.PathLike, title: str, particles: str | os.PathLike,
                          walls: str | os.PathLike | None = None, fields: str | os.PathLike | None = None,
                          lines: Sequence[StateLines] = ()) -> str:
    """The text of a ParaView state (a pvpython script) that opens a run's files.

    Parameters
    ----------
    script_path : str or os.PathLike
        Where the script will be written: every file is named relative to its folder.
    title : str
        What the run is (e.g. ``"silo_flat run sphere2-917f471200 (liggghts)"``), the script's ``RUN``.
    particles : str or os.PathLike
        The particles' .pvd (:func:`siloflow.analysis.io.particle_series.write_particle_series`), shown coloured by
        ``speed``, each sphere its ``radius``.
    walls : str or os.PathLike, optional
        The walls' .vtp (:func:`siloflow.analysis.io.vtk_walls.write_walls_vtp`), shown translucent.
    fields : str or os.PathLike, optional
        The fields' .pvd, loaded coloured by the velocity's magnitude and hidden (they lie among the particles).
    lines : sequence of StateLines, optional
        Files of lines, loaded and hidden.

    Returns
    -------
    str
        The script.
    """
    folder = Path(script_path).parent

    def here(path) -> str:
        return f"here({_relative(path, folder)!r})"

    text = [
        '"""ParaView state of a siloflow run (RUN): walls, particles coloured by speed, fields and lines.',
        "",
        "Open it in ParaView (File > Load State, a Python state) or run `pvpython -i state.py`. Files are named",
        "relative to this script's folder, so a copied run folder still opens. Written by siloflow",
        "(siloflow.analysis.io.paraview_state).",
        '"""',
        "",
        "import os",
        "",
        "from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, Hide, PVDReader,",
        "                             SetActiveSource, Show, XMLPolyDataReader)",
        "",
        f"RUN = {str(title)!r}",
        "HERE = os.path.dirname(os.path.abspath(__file__))",
        "",
        "",
        "def here(name):",
        '    """A file of the run, named relative to this script\'s folder."""',
        '    return os.path.join(HERE, *name.split("/"))',
        "",
        "",
        'view = GetActiveViewOrCreate("RenderView")',
        "",
    ]
    if walls is not None:
        text += [
            f"walls = XMLPolyDataReader(registrationName='walls', FileName=[{here(walls)}])",
            "walls_display = Show(walls, view)",
            "ColorBy(walls_display, None)",
            "walls_display.Opacity = 0.3",
            "",
        ]
    text += [
        f"particles = PVDReader(registrationName='particles', FileName={here(particles)})",
        "particles_display = Show(particles, view)",
        "# spheres of each sphere's own radius: the radius array, used as it is (no scale function)",
        "particles_display.SetRepresentationType('Point Gaussian')",
        "particles_display.ShaderPreset = 'Sphere'",
        "particles_display.ScaleByArray = 1",
        f"particles_display.SetScaleArray = ['POINTS', {PARTICLE_RADIUS!r}]",
        "particles_display.UseScaleFunction = 0",
        "particles_display.GaussianRadius = 1.0",
        f"ColorBy(particles_display, ('POINTS', {PARTICLE_COLOUR!r}))",
        "particles_display.RescaleTransferFunctionToDataRange(True, False)",
        "particles_display.SetScalarBarVisibility(view, True)",
        "",
    ]
    if fields is not None:
        text += [
            f"fields = PVDReader(registrationName='fields', FileName={here(fields)})",
            "fields_display = Show(fields, view)",
            "ColorBy(fields_display, ('POINTS', 'velocity', 'Magnitude'))",
            "Hide(fields, view)",
            "",
        ]
    for line in lines:
        name = _name(line.name)
        association = "CELLS" if line.cells else "POINTS"
        text += [
            f"{name} = XMLPolyDataReader(registrationName={name!r}, FileName=[{here(line.path)}])",
            f"{name}_display = Show({name}, view)",
            f"ColorBy({name}_display, ({association!r}, {line.array!r}))",
            f"Hide({name}, view)",
            "",
        ]
    text += [
        "# the animation runs on the data's times (simulated seconds), not on file numbers",
        "GetAnimationScene().UpdateAnimationUsingDataTimeSteps()",
        "# from the front wall (y = 0), z up: the view of the silo's PIV camera",
        "view.CameraPosition = [0.0, -1.0, 0.0]",
        "view.CameraFocalPoint = [0.0, 0.0, 0.0]",
        "view.CameraViewUp = [0.0, 0.0, 1.0]",
        "view.ResetCamera()",
        "SetActiveSource(particles)",
    ]
    return "\n".join(text) + "\n"


def write_paraview_state(script_path: str | os.PathLike, title: str, particles: str | os.PathLike,
                         walls: str | os.PathLike | None = None, fields: str | os.PathLike | None = None,
                         lines: Sequence[StateLines] = ()) -> Path:
    """Write :func:`paraview_state_script` to ``script_path``, atomically (same arguments, see there).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    return write_text(script_path, paraview_state_script(script_path, title, particles, walls, fields, lines))
