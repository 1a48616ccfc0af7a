"""Benchmark: reading one particle dump, siloflow's read_frame against pyvista.read.

Writes a 500,000-sphere dump in the layout LIGGGHTS writes (with pyvista, tests/dump_fixtures.py), once with
the silo decks' fields and once with the Jenike deck's (forces and angular velocities too), and times on the
same file, in the same run:

- ``pyvista.read``: VTK's own legacy reader, the baseline (ratio 1);
- ``read_frame``: what the workflow calls (parse, check, build the :class:`ParticleFrame`);
- ``parse (arrays)``: :func:`parse_legacy_vtk_polydata` alone, which returns what pyvista.read does (arrays);
- ``pyvista.read + frame``: what a read_frame built on pyvista would cost (the same frame from pyvista's arrays);
- ``npz cache load``: loading the frame from an uncompressed ``.npz`` copy, as the removed frame cache did,
  with its size against the dump's.

Prints a table and writes it to ``results/bench/dumps.csv``; times are ratios to ``pyvista.read``, so they hold
when the machine's speed drifts. It also prints what pyvista returns for a truncated dump (the other reason
the reader is hand-written).

Run with ``make bench``.
"""

from __future__ import annotations

import csv
import io
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyvista

from siloflow.model.frames import OPTIONAL_VECTORS, ParticleFrame
from siloflow.engines.liggghts.dumps import DumpFormatError, dump_step, frame_from_arrays, parse_legacy_vtk_polydata, read_frame
from tests.dump_fixtures import write_liggghts_dump

N_SPHERES = 500_000
REPEATS = 15
TIMESTEP = 1e-5  # [s]
FRAME_ARRAYS = ("id", "type", "clump_id", "position", "velocity", "radius", "mass")
SILO_FIELDS = ("id", "id_multisphere", "type", "mass", "v", "radius")
JENIKE_FIELDS = ("id", "id_multisphere", "type", "mass", "v", "f", "radius", "omega")


def synthetic_dump_fields(n: int, names: tuple[str, ...], seed: int = 7) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Points and fields of n spheres in two-sphere clumps, with LIGGGHTS' names and dtypes, in file order."""
    rng = np.random.default_rng(seed)
    points = rng.uniform(-0.075, 0.075, size=(n, 3)).astype(np.float32)
    every = {
        "id": np.arange(1, n + 1, dtype=np.int32),
        "id_multisphere": (np.arange(n, dtype=np.int32) // 2) + 1,
        "type": np.ones(n, dtype=np.int32),
        "mass": np.full(n, 1.836e-5),
        "v": rng.normal(size=(n, 3)),
        "f": rng.normal(size=(n, 3)),
        "radius": np.full(n, 0.0015),
        "omega": rng.normal(size=(n, 3)),
    }
    return points, {name: every[name] for name in names}


def median_times(functions: dict[str, Callable[[], object]], repeats: int = REPEATS) -> dict[str, float]:
    """Median wall time of each function [s], over ``repeats`` rounds that call each once, in turn.

    Interleaving the readers (after one warm-up round) spreads the load of other processes over all of
    them, so their ratios hold on a busy machine.
    """
    times: dict[str, list[float]] = {name: [] for name in functions}
    for round_ in range(repeats + 1):
        for name, function in functions.items():
            start = time.perf_counter()
            function()
            if round_:
                times[name].append(time.perf_counter() - start)
    return {name: statistics.median(values) for name, values in times.items()}


def pyvista_frame(path: Path) -> ParticleFrame:
    """The frame read_frame returns, built from pyvista's arrays."""
    mesh = pyvista.read(path)
    arrays = {name: np.asarray(mesh.point_data[name]) for name in mesh.point_data}
    arrays["points"] = np.asarray(mesh.points)
    step = dump_step(path)
    return frame_from_arrays(arrays, step, step * TIMESTEP, source=str(path))


def write_cache(frame: ParticleFrame, path: Path) -> None:
    """The removed ``.npz`` frame cache: the frame's arrays, uncompressed."""
    arrays = {name: getattr(frame, name) for name in FRAME_ARRAYS}
    arrays.update({name: getattr(frame, name) for name in OPTIONAL_VECTORS if getattr(frame, name) is not None})
    np.savez(path, **arrays)


def load_cache(path: Path) -> ParticleFrame:
    with np.load(path) as data:
        return ParticleFrame(
            time=0.0, step=0, **{name: data[name] if name in data.files else None for name in OPTIONAL_VECTORS},
            **{name: data[name] for name in FRAME_ARRAYS},
        )


def truncated_dump_note(path: Path, scratch: Path) -> str:
    """What pyvista.read and read_frame do with the dump cut in half."""
    cut = scratch / f"cut_{dump_step(path)}.vtk"
    content = path.read_bytes()
    cut.write_bytes(content[: len(content) // 2])
    mesh = pyvista.read(cut)
    try:
        read_frame(cut, TIMESTEP)
        ours = "read_frame returned a frame"
    except DumpFormatError as error:
        ours = f"read_frame raised: {str(error).removeprefix(str(cut) + ': ')}"
    return (
        f"dump cut in half: pyvista.read returned {mesh.n_points} points with arrays {list(mesh.point_data)} "
        f"and no exception; {ours}"
    )


def main(output: Path = Path("results/bench/dumps.csv")) -> list[dict]:
    rows = []
    notes = []
    with tempfile.TemporaryDirectory() as scratch_dir:
        scratch = Path(scratch_dir)
        for deck, names in (("silo", SILO_FIELDS), ("jenike", JENIKE_FIELDS)):
            points, fields = synthetic_dump_fields(N_SPHERES, names)
            path = write_liggghts_dump(scratch / f"{deck}_1000.vtk", points, fields)
            del points, fields
            dump_mb = path.stat().st_size / 1e6
            cache = scratch / f"{deck}_1000.npz"
            write_cache(read_frame(path, TIMESTEP), cache)
            timings = median_times({
                "pyvista.read": lambda: pyvista.read(path),
                "read_frame": lambda: read_frame(path, TIMESTEP),
                "parse (arrays)": lambda: parse_legacy_vtk_polydata(np.fromfile(path, dtype=np.uint8), str(path)),
                "pyvista.read + frame": lambda: pyvista_frame(path),
                "npz cache load": lambda: load_cache(cache),
            })
            sizes = {"npz cache load": cache.stat().st_size / 1e6}
            baseline = timings["pyvista.read"]
            for reader, seconds in timings.items():
                rows.append({
                    "dump": f"{deck} fields ({len(names)} arrays), {N_SPHERES} spheres",
                    "reader": reader,
                    "median_s": round(seconds, 4),
                    "time_over_pyvista_read": round(seconds / baseline, 2),
                    "file_MB": round(sizes.get(reader, dump_mb), 1),
                })
            notes.append(f"{deck}: {truncated_dump_note(path, scratch)}")
    output.parent.mkdir(parents=True, exist_ok=True)
    with open(output, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    table = io.StringIO()
    width = max(len(row["dump"]) for row in rows)
    table.write(f"{'dump':<{width}}  {'reader':<20}  {'median s':>8}  {'/ pyvista.read':>14}  {'MB':>6}\n")
    for row in rows:
        table.write(
            f"{row['dump']:<{width}}  {row['reader']:<20}  {row['median_s']:>8}  "
            f"{row['time_over_pyvista_read']:>14}  {row['file_MB']:>6}\n"
        )
    print(table.getvalue() + "\n".join(notes) + f"\ntable: {output}")
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("results/bench/dumps.csv"))
