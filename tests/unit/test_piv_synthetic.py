"""Synthetic PIV: rendering discs into an image, and OpenPIV's multipass (the study's 40 px windows, 50 % overlap)
recovering known displacements of a rendered particle pattern: a uniform shift and a linear shear."""

from __future__ import annotations

import numpy as np
import pytest

from siloflow.analysis.piv.accuracy import (
    PivSettings,
    accuracy_row,
    accuracy_table,
    silo_image_scale,
    synthetic_piv,
    visible_top,
)
from siloflow.analysis.piv.calibration import ImageScale
from siloflow.analysis.piv.field import PlanarField
from siloflow.analysis.piv.front_wall import field_errors, front_wall_image, front_wall_spheres, window_mean_velocity
from siloflow.analysis.piv.synthetic import piv_displacements, render_particle_image
from siloflow.analysis.studies.silo_flat.piv_plots import plot_piv_accuracy

HEIGHT, WIDTH = 400, 320


def _pattern(seed=1):
    """Particles of 3 px diameter at 2 % of the pixels, some cut by the image edge."""
    rng = np.random.default_rng(seed)
    n = int(0.02 * HEIGHT * WIDTH)
    return np.column_stack([rng.uniform(-10, WIDTH + 10, n), rng.uniform(-10, HEIGHT + 10, n)])


def _image(points):
    return render_particle_image(points, 1.5, (HEIGHT, WIDTH), void_level=0.0, particle_level=1.0, blur_px=0.7)


def test_a_disc_of_half_a_pixel_at_a_pixel_centre_lights_that_pixel_only():
    image = render_particle_image([[2.0, 1.0]], 0.5, (3, 5), void_level=0.25, particle_level=0.75)
    expected = np.full((3, 5), 0.25)
    expected[1, 2] = 0.75
    assert np.array_equal(image, expected)


def test_a_larger_disc_covers_its_area():
    image = render_particle_image([[20.3, 19.6]], 8.0, (40, 40), void_level=0.0, particle_level=1.0)
    assert image.sum() == pytest.approx(np.pi * 8.0**2, rel=2e-3)
    assert image.max() == 1.0 and image.min() == 0.0


def test_multipass_recovers_a_uniform_shift_within_five_hundredths_of_a_pixel():
    points = _pattern()
    shift = np.array([3.3, -1.7])  # right and up in the image (rows point down)
    x, y, u, v, valid = piv_displacements(_image(points), _image(points + shift))
    assert x.shape == y.shape == (19, 15) and valid.all()
    assert np.sqrt(np.mean((u - shift[0]) ** 2)) < 0.05
    assert np.sqrt(np.mean((v - shift[1]) ** 2)) < 0.05


def test_multipass_recovers_a_linear_shear_within_two_tenths_of_a_pixel():
    points = _pattern(2)
    rate = 0.02  # px of horizontal displacement per px down the image
    sheared = points + np.column_stack([rate * (points[:, 1] - HEIGHT / 2), np.zeros(len(points))])
    x, y, u, v, valid = piv_displacements(_image(points), _image(sheared))
    # rows point down: the vectors' y are image rows, so u follows the shear with the row
    assert np.sqrt(np.mean((u - rate * (y - HEIGHT / 2)) ** 2)) < 0.2
    assert np.sqrt(np.mean(v**2)) < 0.2


@pytest.mark.parametrize("shape_b, window, passes, message", [
    ((40, 40), 16, 1, "one shape"),
    ((64, 64), 48, 2, "do not fit"),
    ((64, 64), 16, 0, "do not fit"),
    ((64, 64), 16, 2, "4 windows per axis"),
])
def test_frames_or_windows_that_do_not_fit_are_refused(shape_b, window, passes, message):
    with pytest.raises(ValueError, match=message):
        piv_displacements(np.zeros((64, 64)), np.zeros(shape_b), window, window // 2, passes)


def test_bad_particles_are_refused():
    with pytest.raises(ValueError, match="finite and radii positive"):
        render_particle_image([[np.nan, 1.0]], 1.0, (4, 4))
    with pytest.raises(ValueError, match="two positive sizes"):
        render_particle_image([[1.0, 1.0]], 1.0, (0, 4))


# ---------------------------------------------------------------------------------------------- DEM at the front wall


def test_spheres_within_the_band_of_the_front_wall_are_the_visible_ones():
    position = np.array([[0.0, 0.001, 0.1], [0.0, 0.004, 0.1], [0.0, 0.0031, 0.1]])
    assert front_wall_spheres(position, band=0.003).tolist() == [True, False, False]


def test_a_sphere_is_drawn_where_the_scale_puts_it():
    scale = ImageScale(1e-4, -0.002, 0.004)  # 0.1 mm per pixel; pixel (0, 0) at x = -2 mm, z = 4 mm
    image = front_wall_image([[0.0, 0.0, 0.002]], [0.5e-4], scale, (41, 41), void_level=0.0, particle_level=1.0)
    # x = 0 is column 20, z = 2 mm is row 20; a radius of half a pixel lights that pixel only
    assert np.argwhere(image == 1.0).tolist() == [[20, 20]] and image.sum() == 1.0


def test_window_means_are_the_mean_velocity_of_the_spheres_in_each_window():
    position = np.array([[0.0, 0.0, 0.0], [0.001, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.0, 0.01]])
    velocity = np.array([[1.0, 9.0, -2.0], [3.0, 9.0, -4.0], [5.0, 9.0, -6.0], [7.0, 9.0, -8.0]])
    field = window_mean_velocity(position, velocity, np.array([0.0, 0.01]), np.array([0.0, 0.01, 0.02]), 0.0025)
    assert field.u[0, 0] == 2.0 and field.w[0, 0] == -3.0  # the first two spheres
    assert field.u[0, 1] == 5.0 and field.u[1, 0] == 7.0
    assert field.valid.tolist() == [[True, True], [True, False], [False, False]]


def test_field_errors_are_bias_and_rms_over_the_nodes_valid_in_both():
    x, z = np.array([0.0, 1.0]), np.array([0.0, 1.0])
    truth = PlanarField(x, z, np.zeros((2, 2)), np.full((2, 2), -1.0), np.array([[True, True], [True, False]]))
    measured = PlanarField(x, z, np.array([[0.1, -0.1], [0.3, 9.0]]), np.array([[-1.0, -1.2], [-1.0, 0.0]]),
                           np.array([[True, True], [True, True]]))
    errors = field_errors(measured, truth)
    assert errors.nodes == 3
    assert errors.bias_u == pytest.approx(0.1) and errors.rms_u == pytest.approx(np.sqrt(0.11 / 3))
    assert errors.bias_w == pytest.approx(-0.2 / 3) and errors.rms_w == pytest.approx(np.sqrt(0.04 / 3))


# ---------------------------------------------------------------------------------------------- the accuracy study


def test_the_silo_image_spans_the_width_from_the_outlet_plane_up():
    scale = silo_image_scale(0.1, (250, 350))
    assert scale.scale == pytest.approx(4e-4)
    x, z = scale.to_silo([0, 249], [349, 0])
    assert x == pytest.approx([-0.05 + 2e-4, 0.05 - 2e-4]) and z == pytest.approx([2e-4, 0.14 - 2e-4])


def test_an_accuracy_row_is_bias_and_rms_over_every_pair_and_the_centreline_error():
    x, z = np.array([-0.01, 0.0, 0.01]), np.array([0.0, 0.01])
    ones = np.ones((2, 3), bool)
    truth = PlanarField(x, z, np.zeros((2, 3)), np.full((2, 3), -0.1), ones)
    first = PlanarField(x, z, np.full((2, 3), 0.01), np.full((2, 3), -0.12), ones)
    second = PlanarField(x, z, np.full((2, 3), -0.01), np.full((2, 3), -0.1), ones)
    row = accuracy_row([(first, truth), (second, truth)])
    assert row["nodes"] == 12 and row["pairs"] == 2
    assert row["bias_u_m_s"] == pytest.approx(0.0) and row["rms_u_m_s"] == pytest.approx(0.01)
    assert row["bias_w_m_s"] == pytest.approx(-0.01) and row["rms_w_m_s"] == pytest.approx(np.sqrt(0.0002))
    assert row["rms_w_spread_m_s"] == pytest.approx(np.std([0.02, 0.0], ddof=1))
    assert row["centreline_w_error_m_s"] == pytest.approx(-0.01)


def test_a_resolution_without_a_valid_vector_is_a_row_that_says_why(tmp_path):
    class Frame:  # no sphere near the front wall: both images are blank
        position = np.array([[0.0, 0.05, 0.01]])
        velocity = np.array([[0.0, 0.0, -0.1]])
        radius = np.array([0.0015])

    rows, profiles = accuracy_table([Frame()], 0.05, [(256, 256)], [100.0],
                                    PivSettings(window_px=32, overlap_px=16, passes=2), heights=[0.01, 0.02])
    assert rows[0]["nodes"] == 0 and np.isnan(rows[0]["rms_w_m_s"]) and "no valid vector" in rows[0]["note"]
    assert [(p["width_px"], p["z_m"], p["nodes"]) for p in profiles] == [(256, 0.01, 0), (256, 0.02, 0)]
    assert all(np.isnan(p["rms_w_m_s"]) for p in profiles)
    good = dict(rows[0], width_px=256, mm_per_px=0.2, rms_w_m_s=0.01, bias_w_m_s=-0.002, rms_w_spread_m_s=0.001)
    path = plot_piv_accuracy([rows[0], good], tmp_path / "piv.png")
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_a_tall_image_over_a_low_fill_is_cut_off_above_the_fill():
    """A camera image mostly of blank head space made OpenPIV's multipass fail everywhere; the image now ends one
    first-pass window above the highest sphere, with its bottom row still at the outlet plane."""
    rng = np.random.default_rng(3)
    n = 700
    position = np.column_stack([rng.uniform(-0.025, 0.025, n), np.full(n, 0.001), rng.uniform(0.0, 0.03, n)])
    velocity = np.tile([0.0, 0.0, -0.05], (n, 1))
    radius = np.full(n, 0.0008)
    resolution = (256, 1024)  # 0.195 mm/px: 200 mm tall over a fill 30 mm high
    scale = silo_image_scale(0.05, resolution)
    top = visible_top([type("Frame", (), {"position": position, "radius": radius})], 0.002)
    assert top == pytest.approx(position[:, 2].max() + 0.0008)
    measured, truth = synthetic_piv(position, velocity, radius, scale, resolution, 100.0, PivSettings(band=0.002),
                                    image_top=top)
    assert 0.0 < measured.z[0] < 40 * scale.scale  # the grid still starts at the outlet plane
    assert measured.z[-1] < 0.0308 + 80 * scale.scale
    errors = field_errors(measured, truth)
    assert errors.nodes > 30 and abs(errors.bias_w) < 0.005 and errors.rms_w < 0.01
