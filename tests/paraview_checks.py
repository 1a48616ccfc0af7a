"""What the ParaView files of a finished run must hold, read back with pyvista and opened with pvpython where ParaView
is installed: the unit tests check the writers on synthetic input, the integration tests a tiny run of each case on
each engine with these checks."""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
import pyvista

from siloflow.analysis.io.paraview_state import StateLines, write_paraview_state
from siloflow.analysis.io.particle_series import write_particle_series
from siloflow.analysis.io.vtk_lines import write_force_chains_vtp
from siloflow.analysis.io.vtk_walls import write_walls_vtp
from siloflow.analysis.numerics.force_chains import all_force_chains
from siloflow.model.cases.kinds import case_kind

#: Run inside pvpython: the state, then what ParaView made of it as JSON. Without a display ParaView cannot render,
#: and setting the animation's time renders; that one call is stubbed then (the GUI makes it for real).
CHECKER = """
import json, os, sys
import paraview.simple as simple

class _Scene:
    def UpdateAnimationUsingDataTimeSteps(self):
        pass

if not os.environ.get("DISPLAY"):
    simple.GetAnimationScene = lambda: _Scene()
path = sys.argv[1]
exec(compile(open(path).read(), path, "exec"), {"__file__": path, "__name__": "__main__"})
found = {}
for (name, _), source in simple.GetSources().items():
    files = source.FileName
    found[name] = {"files": [files] if isinstance(files, str) else list(files),
                   "times": list(getattr(source, "TimestepValues", None) or []),
                   "point": sorted(source.PointData.keys()), "cell": sorted(source.CellData.keys()),
                   "visible": bool(simple.GetDisplayProperties(source).Visibility)}
print("STATE " + json.dumps(found))
"""


def named_files(script: Path) -> list[str]:
    """The files a ParaView state opens: the arguments of its ``here(...)`` calls."""
    tree = ast.parse(script.read_text(encoding="utf-8"))
    return [node.args[0].value for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "here"
            and node.args and isinstance(node.args[0], ast.Constant)]


def open_state_in_pvpython(state: Path, workdir: Path) -> dict:
    """Run the state ``state`` in pvpython; what ParaView made of it: ``{source: {files, times, point, cell,
    visible}}``."""
    checker = workdir / "checker.py"
    checker.write_text(CHECKER, encoding="utf-8")
    # ParaView's own Python and its packages: the test's Python path (another interpreter's) stays out
    env = {key: value for key, value in os.environ.items() if key not in ("PYTHONPATH", "PYTHONHOME")}
    done = subprocess.run([shutil.which("pvpython"), str(checker), str(state)],
                          capture_output=True, text=True, timeout=300, cwd=workdir, env=env)
    lines = [line for line in done.stdout.splitlines() if line.startswith("STATE ")]
    assert done.returncode == 0 and lines, done.stdout[-2000:] + done.stderr[-2000:]
    return json.loads(lines[-1][len("STATE "):])


def check_particles(folder: Path, frames: Sequence) -> None:
    """``particles.pvd`` indexes one file per frame at the frame's simulated time, each with the frame's spheres,
    velocities and their speed."""
    reader = pyvista.PVDReader(folder / "particles.pvd")
    assert reader.time_values == pytest.approx([frame.time for frame in frames], rel=1e-12)
    for index in (0, len(frames) // 2, len(frames) - 1):
        reader.set_active_time_point(index)
        data = reader.read()[0]
        frame = frames[index]
        assert data.n_points == len(frame)
        np.testing.assert_allclose(data.points, frame.position, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(data.point_data["speed"], np.linalg.norm(frame.velocity, axis=1), rtol=1e-6,
                                   atol=1e-7)
        np.testing.assert_array_equal(data.point_data["id"], frame.id)


def check_paraview_folder(run_dir: Path, frames: Sequence, lines: Sequence[str] = (), fields: bool = True,
                          workdir: Path | None = None) -> None:
    """Every ParaView file of the run in ``run_dir`` against its frames: particles on the simulated clock, walls,
    the settled fill's force chains (lines carrying a compressive force), the fields (``fields``) within the frames'
    span, the kind's ``lines`` files (polylines carrying residence time), and the state, which names exactly these
    files relative to itself and opens in pvpython when ParaView is installed (with ``workdir``)."""
    folder = run_dir / "paraview"
    check_particles(folder, frames)
    walls = pyvista.read(folder / "walls.vtp")
    assert walls.n_cells > 0 and walls.n_points >= 3
    chains = pyvista.read(folder / "force_chains.vtp")
    assert chains.n_lines > 0 and chains.cell_data["normal_force"].size == chains.n_lines
    assert np.all(chains.cell_data["normal_force"] >= 0) and chains.cell_data["normal_force"].max() > 0
    expected = {"particles.pvd", "walls.vtp", "force_chains.vtp"}
    if fields:
        reader = pyvista.PVDReader(folder / "fields.pvd")
        times = np.asarray(reader.time_values)
        assert times.size >= 1 and np.all(np.diff(times) > 0)
        assert frames[0].time - 1e-9 <= times[0] and times[-1] <= frames[-1].time + 1e-9
        field = reader.read()[0]
        assert field.n_points > 0 and len(field.point_data.keys()) + len(field.cell_data.keys()) > 0
        expected.add("fields.pvd")
    for name in lines:
        data = pyvista.read(folder / f"{name}.vtp")
        assert data.n_lines > 0 and "residence_time" in data.cell_data
        expected.add(f"{name}.vtp")
    state = folder / "state.py"
    assert set(named_files(state)) == expected
    if workdir is not None and shutil.which("pvpython"):
        found = open_state_in_pvpython(state, workdir)
        assert found["particles"]["times"] == pytest.approx([frame.time for frame in frames], rel=1e-9)
        assert {"speed", "velocity", "radius"} <= set(found["particles"]["point"])


def write_engine_paraview_files(kind: str, case, engine, run_dir: Path, record) -> list:
    """The ParaView files of a run that its engine's own output makes (particles, the settled fill's force chains)
    with its walls and a state, through the calls the workflow's ParaView rules make; the frames they were made of.
    For the runs the integration tests make through an engine, outside the workflow."""
    folder = run_dir / "paraview"
    frames = engine.read_frames(run_dir, record)
    write_particle_series(folder / "particles.pvd", frames)
    write_walls_vtp(folder / "walls.vtp", case_kind(kind).walls(case))
    settled = engine.settled_fill(run_dir, record)[-1]
    write_force_chains_vtp(folder / "force_chains.vtp", all_force_chains(settled.contacts))
    write_paraview_state(folder / "state.py", f"{kind} run {record.run_id} ({record.engine})", folder / "particles.pvd",
                         walls=folder / "walls.vtp",
                         lines=[StateLines("force_chains", folder / "force_chains.vtp", "normal_force")])
    return frames
