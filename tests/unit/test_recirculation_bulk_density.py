"""Flowing bulk density of the recirculating silo, against counts by hand."""

import math

import numpy as np
import pytest

from siloflow.analysis.studies.silo_recirculation.bulk_density import flowing_bulk_density, slab_bulk_density
from siloflow.engines.config import ConfigError, validate_config


def test_slab_density_is_the_mass_of_the_centres_inside_over_the_slab_volume():
    # 4 clumps; slab 10 <= z < 30 mm of a 0.1 x 0.02 m silo: volume 4e-5 m3
    z = np.array([[0.005, 0.010, 0.020, 0.030],
                  [0.015, 0.025, 0.029, 0.031]])
    mass = np.array([1e-3, 2e-3, 3e-3, 4e-3])
    density = slab_bulk_density(z, mass, 0.1, 0.02, (0.01, 0.03))
    np.testing.assert_allclose(density, [(2e-3 + 3e-3) / 4e-5, (1e-3 + 2e-3 + 3e-3) / 4e-5], rtol=1e-14)
    with pytest.raises(ValueError, match="increasing"):
        slab_bulk_density(z, mass, 0.1, 0.02, (0.03, 0.01))
    with pytest.raises(ValueError, match="mass has 3 clumps"):
        slab_bulk_density(z, mass[:3], 0.1, 0.02, (0.01, 0.03))


def test_drop_is_one_minus_the_batch_mean_of_the_flowing_frames_over_the_settled():
    # 10 clumps of 1 g, slab 0 <= z < 1 m of a 1 x 1 m silo (1 m3): settled 10 g/m3. From t = 2 s the frames
    # alternate 9 and 8 clumps inside (4 batches of two frames: every batch mean 8.5 -> error 0).
    times = np.arange(10.0)
    inside = [10, 10, 9, 8, 9, 8, 9, 8, 9, 8]
    z = np.array([[0.5 if k < n else 2.0 for k in range(10)] for n in inside])
    result = flowing_bulk_density(times, z, np.full(10, 1e-3), 1.0, 1.0, (0.0, 1.0), 2.0, n_batches=4)
    assert result.settled == pytest.approx(10e-3 / 1.0, rel=1e-12)
    assert result.flowing == pytest.approx(8.5e-3, rel=1e-12) and result.flowing_error == 0.0
    assert result.drop == pytest.approx(0.15, rel=1e-12) and result.drop_error == 0.0
    assert result.frames == 8 and result.batches == 4
    # batches that differ: two batches of 4 frames, means 8.5 and 9 clumps
    inside = [10, 10, 9, 8, 9, 8, 9, 9, 9, 9]
    z = np.array([[0.5 if k < n else 2.0 for k in range(10)] for n in inside])
    result = flowing_bulk_density(times, z, np.full(10, 1e-3), 1.0, 1.0, (0.0, 1.0), 2.0, n_batches=2)
    assert result.flowing == pytest.approx(8.75e-3, rel=1e-12)
    assert result.flowing_error == pytest.approx(np.std([8.5e-3, 9e-3], ddof=1) / math.sqrt(2), rel=1e-12)
    assert result.drop_error == pytest.approx(result.flowing_error / 10e-3, rel=1e-12)
    assert result.summary()["bulk_density_drop"] == pytest.approx(0.125, rel=1e-12)


def test_a_slab_above_the_fill_or_no_flowing_frames_is_refused():
    times, z, mass = np.arange(3.0), np.full((3, 2), 0.5), np.full(2, 1e-3)
    with pytest.raises(ValueError, match="no clump in the slab"):
        flowing_bulk_density(times, z, mass, 1.0, 1.0, (1.0, 2.0), 1.0)
    with pytest.raises(ValueError, match="fewer than two frames"):
        flowing_bulk_density(times, z, mass, 1.0, 1.0, (0.0, 1.0), 2.0)
    with pytest.raises(ValueError, match="after the first"):
        flowing_bulk_density(times, z, mass, 1.0, 1.0, (0.0, 1.0), 0.0)


def test_the_slab_of_the_config_must_increase():
    with pytest.raises(ConfigError, match="silo_recirculation.bulk_density_slab"):
        validate_config({"silo_recirculation": {"bulk_density_slab": [0.6, 0.2]}})
