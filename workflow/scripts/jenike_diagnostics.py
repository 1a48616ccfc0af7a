"""Snakemake adapter: polar diagrams of wall friction mobilisation and particle rotation of one shear test."""

import json
from pathlib import Path

import numpy as np

from engines.liggghts.dumps import list_dumps, read_frame
from analysis.io.tables import write_json
from calibration.charts import plot_polar_histogram
from calibration.friction import angular_histogram, mobilised_friction_by_azimuth
from engines.liggghts.jenike import WALL_CONTACT_PREFIX, read_contact_dump
from engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = json.loads(Path(snakemake.input.record).read_text())
    case = json.loads(Path(snakemake.input.case).read_text())
    shear_plane = case["geometry"]["shear_plane"]
    band = 2.0 * case["clump_volume_m3"] ** (1.0 / 3.0)  # about one clump size either side of the plane

    # The last snapshots of the shear stage.
    contact_dumps = sorted((run_dir / "dumps").glob(f"{WALL_CONTACT_PREFIX}_*.txt"),
                           key=lambda path: int(path.stem.rsplit("_", 1)[1]))
    if not contact_dumps:
        raise FileNotFoundError(f"{run_dir / 'dumps'}: no wall contact dumps (diagnostics need the rigid lid)")
    contacts = read_contact_dump(contact_dumps[-1])
    ring_walls = np.isin(contacts["id1"], (0, 1))  # mesh 0: bottom ring or plate, mesh 1: shear ring
    in_plane = ring_walls & (np.abs(contacts["z1"] - shear_plane) <= band)
    points = np.column_stack([contacts["x1"], contacts["y1"], contacts["z1"]])[in_plane]
    normal = np.column_stack([contacts["fn_x"], contacts["fn_y"], contacts["fn_z"]])[in_plane]
    tangential = np.column_stack([contacts["ft_x"], contacts["ft_y"], contacts["ft_z"]])[in_plane]
    edges, ratio, counts = mobilised_friction_by_azimuth(points, normal, tangential, bins=24)
    plot_polar_histogram(edges, ratio, snakemake.output.friction,
                         "Mean |Ft|/|Fn| at ring-wall contacts in the shear plane\n(as reported by compute wall/gran/local)")

    frame = read_frame(list_dumps(run_dir / "dumps", record["dump_prefix"])[-1], record["timestep_s"])
    if frame.angular_velocity is None:
        raise ValueError(f"{run_dir}: the last dump has no angular velocities (omegax omegay omegaz); the Jenike deck "
                         "must dump them for the diagnostics")
    omega_edges, omega_counts = angular_histogram(frame.angular_velocity, axis="y", bins=36)
    plot_polar_histogram(omega_edges, omega_counts, snakemake.output.rotation,
                         "Direction of particle angular velocity in the x-z plane")
    write_json(snakemake.output.summary, {
        "wall_contacts_in_shear_plane": int(in_plane.sum()),
        "mean_mobilised_friction": float(np.sum(ratio * counts) / max(1, counts.sum())),
        "contact_step": int(contacts["step"][0]) if contacts["step"].size else None,
        "particle_step": frame.step,
        "mean_angular_speed_rad_s": float(np.linalg.norm(frame.angular_velocity, axis=1).mean()),
    })
    log.info("%d wall contacts in the shear plane; particle frame at step %d", int(in_plane.sum()), frame.step)
