"""The rigid lid's sphere layout reaches the rim and covers the lid plane."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from siloflow.model.cases.jenike_lids import lid_sphere_layout


@pytest.mark.parametrize("outer", [0.0182, 0.0457])
def test_lid_layout_reaches_the_rim_and_covers_the_lid_plane(outer):
    sphere_radius = 0.0015
    centres = lid_sphere_layout(outer, 1.4 * sphere_radius)
    radii = np.hypot(centres[:, 0], centres[:, 1])
    assert radii.max() == pytest.approx(outer, rel=1e-14)
    grid = np.mgrid[-outer:outer:300j, -outer:outer:300j].reshape(2, -1).T
    grid = grid[np.hypot(*grid.T) <= outer]
    gap, _ = cKDTree(centres).query(grid)
    assert gap.max() < sphere_radius  # no point of the lid plane is uncovered
    nearest, _ = cKDTree(centres).query(centres, k=2)
    assert nearest[:, 1].max() <= 1.4 * sphere_radius + 1e-12
