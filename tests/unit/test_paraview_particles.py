"""siloflow.analysis.io.particle_series: a run's particle frames as .vtp files with a .pvd on the simulated clock, read back
with pyvista exactly (points, vertex cells, every array the frame carries, times)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from siloflow.analysis.io.particle_series import particle_file_name, write_particle_frame_vtp, write_particle_series
from siloflow.model.frames import ParticleFrame

pyvista = pytest.importorskip("pyvista")


def make_frame(step: int, n: int, timestep: float = 2.5e-5, vectors: bool = False, seed: int = 0) -> ParticleFrame:
    """A frame of ``n`` spheres in two-sphere clumps; with ``vectors``, angular velocity and force too."""
    rng = np.random.default_rng(seed + step)
    return ParticleFrame(
        time=step * timestep, step=step, id=np.arange(1, n + 1), type=np.ones(n, dtype=np.int32),
        clump_id=(np.arange(n) // 2) + 1, position=rng.uniform(-0.07, 0.07, (n, 3)),
        velocity=rng.normal(scale=0.3, size=(n, 3)), angular_velocity=rng.normal(size=(n, 3)) if vectors else None,
        radius=rng.uniform(0.0014, 0.0016, n), mass=np.repeat(rng.uniform(1e-5, 2e-5, (n + 1) // 2), 2)[:n],
        force=rng.normal(scale=1e-3, size=(n, 3)) if vectors else None)


def assert_frame_file(path: Path, frame: ParticleFrame, dtype=np.float32) -> None:
    data = pyvista.read(path)
    assert isinstance(data, pyvista.PolyData)
    assert data.n_points == len(frame)
    assert data.n_cells == len(frame)  # one vertex cell per sphere, so every representation draws it
    assert data.n_verts == len(frame)
    np.testing.assert_array_equal(data.points, frame.position.astype(dtype))
    expected = {
        "id": frame.id, "clump_id": frame.clump_id, "type": frame.type,
        "velocity": frame.velocity.astype(dtype),
        "speed": np.linalg.norm(frame.velocity, axis=1).astype(dtype),
        "radius": frame.radius.astype(dtype), "mass": frame.mass.astype(dtype),
    }
    for name in ("angular_velocity", "force"):
        if getattr(frame, name) is not None:
            expected[name] = getattr(frame, name).astype(dtype)
    assert set(data.point_data.keys()) == set(expected)
    for name, values in expected.items():
        assert data.point_data[name].dtype == values.dtype, name
        np.testing.assert_array_equal(data.point_data[name], values, err_msg=name)
    assert data.point_data.active_scalars_name == "speed"
    assert data.point_data.active_vectors_name == "velocity"
    assert data.field_data["TimeValue"][0] == frame.time
    assert data.field_data["step"][0] == frame.step


def test_a_series_reads_back_frame_by_frame_on_the_simulated_clock(tmp_path):
    frames = [make_frame(step, 40, vectors=step == 4000) for step in (1000, 1217, 4000)]
    pvd = write_particle_series(tmp_path / "paraview" / "particles.pvd", frames)

    assert pvd == tmp_path / "paraview" / "particles.pvd"
    reader = pyvista.PVDReader(pvd)
    assert reader.time_values == [frame.time for frame in frames]  # the physical time, not the file number
    assert [entry.path for entry in reader.datasets] == [f"particles/{particle_file_name(f.step)}" for f in frames]
    for frame in frames:
        assert_frame_file(tmp_path / "paraview" / "particles" / f"particles_{frame.step}.vtp", frame)
    reader.set_active_time_value(frames[1].time)
    assert reader.read()[0].n_points == len(frames[1])
    # atomic writes leave nothing beside the products
    assert sorted(p.name for p in (tmp_path / "paraview").iterdir()) == ["particles", "particles.pvd"]
    assert sorted(p.name for p in (tmp_path / "paraview" / "particles").iterdir()) == [
        "particles_1000.vtp", "particles_1217.vtp", "particles_4000.vtp"]


def test_float64_writes_exact_copies(tmp_path):
    frame = make_frame(7, 25, vectors=True)
    path = write_particle_frame_vtp(tmp_path / "frame.vtp", frame, float_dtype=np.float64)
    assert_frame_file(path, frame, np.float64)


def test_a_frame_without_spheres_is_an_empty_data_set_with_its_time(tmp_path):
    empty = ParticleFrame(time=0.5, step=20000, id=np.empty(0), type=np.empty(0), clump_id=np.empty(0),
                          position=np.empty((0, 3)), velocity=np.empty((0, 3)), angular_velocity=None,
                          radius=np.empty(0), mass=np.empty(0))
    pvd = write_particle_series(tmp_path / "particles.pvd", [make_frame(100, 4), empty])
    data = pyvista.read(tmp_path / "particles" / "particles_20000.vtp")
    assert (data.n_points, data.n_cells) == (0, 0)
    assert data.field_data["TimeValue"][0] == 0.5
    assert pyvista.PVDReader(pvd).time_values == [100 * 2.5e-5, 0.5]


@pytest.mark.parametrize("frames, message", [
    ([], "at least one"),
    ([make_frame(200, 3), make_frame(100, 3)], "times must increase"),
])
def test_a_series_that_cannot_play_is_refused_before_anything_is_written(tmp_path, frames, message):
    with pytest.raises(ValueError, match=message):
        write_particle_series(tmp_path / "particles.pvd", frames)
    assert not list(tmp_path.iterdir())


def test_only_float32_or_float64_is_written(tmp_path):
    with pytest.raises(ValueError, match="float32 or float64"):
        write_particle_frame_vtp(tmp_path / "frame.vtp", make_frame(1, 2), float_dtype=np.float16)
