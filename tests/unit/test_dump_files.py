"""Reading a user's own LIGGGHTS dumps (siloflow.engines.liggghts.dump_files.read_dump_files) through
siloflow.engines.liggghts.dumps.readable_frames: the step of a VTK file from its name, a text file's own steps, and the
damaged-dump policy, on copies of dumps LIGGGHTS wrote (tests/fixtures/liggghts/)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from siloflow.engines.interface import DumpFile
from siloflow.engines.liggghts.dump_files import read_dump_files
from siloflow.engines.liggghts.dumps import readable_frames
from siloflow.engines.liggghts.vtk_legacy import DumpFormatError

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures" / "liggghts"
TIMESTEP = 2e-5  # s
DENSITY = 2500.0  # kg/m3


def _files(folder: Path) -> list[DumpFile]:
    """Three VTK dumps named as a hand-written deck names them (no step in the legacy VTK file), the middle one
    truncated, then a text dump of steps 0, 750 and 1500."""
    for step in (1500, 2000, 3000):
        shutil.copy(FIXTURES / "spheres_binary_nomass_1500.vtk", folder / f"silo{step}.vtk")
    content = (folder / "silo2000.vtk").read_bytes()
    (folder / "silo2000.vtk").write_bytes(content[: len(content) // 2])
    shutil.copy(FIXTURES / "series.txt", folder / "dump.txt")
    return [DumpFile(folder / f"silo{step}.vtk", step) for step in (1500, 2000, 3000)] + [
        DumpFile(folder / "dump.txt", None)]


def test_a_damaged_dump_raises_naming_it_or_is_skipped_with_a_warning(tmp_path):
    files = _files(tmp_path)
    with pytest.raises(DumpFormatError, match=r"silo2000\.vtk"):
        read_dump_files(files, TIMESTEP, density=DENSITY)
    with pytest.warns(UserWarning, match=r"^skipping damaged dump \(.*silo2000\.vtk"):
        frames = read_dump_files(files, TIMESTEP, density=DENSITY, on_damaged="skip")
    # the VTK files' steps are their names', the text file's its own
    assert [frame.step for frame in frames] == [1500, 3000, 0, 750, 1500]
    assert frames[1].time == pytest.approx(3000 * TIMESTEP, rel=1e-15)
    with pytest.raises(ValueError, match=r"on_damaged must be one of \('error', 'skip'\), got 'ignore'"):
        read_dump_files(files, TIMESTEP, density=DENSITY, on_damaged="ignore")


def test_readable_frames_take_a_step_per_path_and_as_many_as_there_are_paths(tmp_path):
    files = [file for file in _files(tmp_path) if file.step in (1500, 3000)]
    paths = [file.path for file in files]
    frames = list(readable_frames(paths, TIMESTEP, density=DENSITY, steps=[10, 20]))
    assert [frame.step for frame in frames] == [10, 20]
    with pytest.raises(ValueError, match="no step"):
        list(readable_frames(paths, TIMESTEP, density=DENSITY))  # 'silo1500.vtk' gives none
    with pytest.raises(ValueError):
        list(readable_frames(paths, TIMESTEP, density=DENSITY, steps=[10]))
