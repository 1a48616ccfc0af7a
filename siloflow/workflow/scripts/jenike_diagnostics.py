"""Snakemake adapter: polar diagrams of wall friction mobilisation and particle rotation of one shear test."""

from pathlib import Path

import numpy as np

from siloflow.model.record import read_run_record
from siloflow.analysis.io.tables import write_json
from siloflow.calibration.charts import plot_polar_histogram
from siloflow.calibration.contact_diagnostics import angular_histogram, mobilised_friction_by_azimuth
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    engine = engine_named(record.engine)
    case = snakemake.params.case
    shear_plane = case.geometry.shear_plane
    band = 2.0 * case.particle.volume ** (1.0 / 3.0)  # about one clump size either side of the plane

    # The last snapshots of the shear stage.
    snapshots = engine.contacts(run_dir, record, "wall")
    if not snapshots:
        raise FileNotFoundError(f"{run_dir}: no particle-wall contacts saved (diagnostics need the rigid lid)")
    contacts = snapshots[-1]
    ring_walls = np.isin(contacts.wall, ("base", "shear_ring"))  # the bottom ring or plate, and the shear ring
    in_plane = ring_walls & (np.abs(contacts.point[:, 2] - shear_plane) <= band)
    points = contacts.point[in_plane]
    normal = contacts.normal_force[in_plane]
    tangential = contacts.tangential_force[in_plane]
    edges, ratio, counts = mobilised_friction_by_azimuth(points, normal, tangential, bins=24)
    plot_polar_histogram(edges, ratio, snakemake.output.friction,
                         "Mean |Ft|/|Fn| at ring-wall contacts in the shear plane\n(as the engine reports them)")

    frame = engine.read_frames(run_dir, record)[-1]
    if frame.angular_velocity is None:
        raise ValueError(f"{run_dir}: the last dump has no angular velocities (omegax omegay omegaz); the Jenike deck "
                         "must dump them for the diagnostics")
    omega_edges, omega_counts = angular_histogram(frame.angular_velocity, axis="y", bins=36)
    plot_polar_histogram(omega_edges, omega_counts, snakemake.output.rotation,
                         "Direction of particle angular velocity in the x-z plane")
    write_json(snakemake.output.summary, {
        "wall_contacts_in_shear_plane": int(in_plane.sum()),
        "mean_mobilised_friction": float(np.sum(ratio * counts) / max(1, counts.sum())),
        "contact_step": contacts.step,
        "particle_step": frame.step,
        "mean_angular_speed_rad_s": float(np.linalg.norm(frame.angular_velocity, axis=1).mean()),
    })
    log.info("%d wall contacts in the shear plane; particle frame at step %d", int(in_plane.sum()), frame.step)
