"""What is read off a planar field (profile, centreline, flow channel boundary, B), measured PIV frames made into
timed, filtered silo fields, and DEM against measured PIV: each against exact answers on hand-made fields and frames."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from siloflow.analysis.io.measured_piv import load_measured_piv, measured_piv_paths
from siloflow.analysis.piv.accuracy import derived_errors, profile_error_rows
from siloflow.analysis.piv.calibration import ImageScale
from siloflow.analysis.piv.compare import comparison_rows, dem_front_wall, error_band, profile_pairs
from siloflow.analysis.piv.derived import field_quantities, planar_profile
from siloflow.analysis.piv.field import PivRows, PlanarField
from siloflow.analysis.piv.measured import MeasuredPiv, check_windows, measured_fields, measured_piv_settings
from siloflow.analysis.studies.silo_flat.piv_plots import plot_piv_comparison

X = np.round(np.arange(-0.05, 0.0501, 0.005), 6)  # 21 nodes, one at x = 0
Z = np.array([0.02, 0.04])


def _gaussian(a=-0.2, b=0.002):
    """The kinematic model's field: w = a exp(-x^2 / (4 b z)) in every row."""
    w = np.array([a * np.exp(-X**2 / (4 * b * z)) for z in Z])
    return PlanarField(X, Z, np.zeros_like(w), w, np.ones(w.shape, bool))


def _triangle(a=-0.3, half_width=0.03):
    """w = a (1 - |x| / L) inside |x| < L: piecewise linear between nodes, so the boundary is exact."""
    w = np.tile(a * np.clip(1 - np.abs(X) / half_width, 0, None), (Z.size, 1))
    return PlanarField(X, Z, np.zeros_like(w), w, np.ones(w.shape, bool))


# ---------------------------------------------------------------------------------------------- derived quantities


def test_the_profile_is_the_valid_nodes_of_the_nearest_row():
    field = _triangle()
    valid = field.valid.copy()
    valid[1, 3] = False
    field = PlanarField(X, Z, field.u, field.w, valid)
    profile = planar_profile(field, 0.033)
    assert profile.z == 0.04 and profile.x.size == 20 and X[3] not in profile.x
    with pytest.raises(ValueError, match="height 0.06 m lies outside"):
        planar_profile(field, 0.06)


def test_centreline_and_flow_channel_boundary_of_a_triangle_are_exact():
    (quantities,) = field_quantities(_triangle(), [0.02], fraction=0.05)
    assert quantities.centreline_w == pytest.approx(-0.3, abs=1e-15)
    # |w| falls to 5 % of its peak at 95 % of the half width
    assert quantities.fcb_left == pytest.approx(-0.0285, abs=1e-12)
    assert quantities.fcb_right == pytest.approx(0.0285, abs=1e-12)


def test_the_kinematic_constant_of_a_gaussian_field_is_recovered():
    quantities = field_quantities(_gaussian(b=0.002), Z)
    assert [q.kinematic_b for q in quantities] == pytest.approx([0.002, 0.002], rel=1e-6)
    assert [q.z for q in quantities] == [0.02, 0.04]


def test_piv_twice_as_fast_as_the_truth_is_off_in_centreline_only():
    truth = _gaussian()
    doubled = PlanarField(X, Z, truth.u, 2 * truth.w, truth.valid)
    errors = derived_errors([(doubled, truth)], Z)
    assert errors["centreline_w_error_m_s"] == pytest.approx(-0.2, abs=1e-12)
    assert errors["fcb_error_m"] == pytest.approx(0.0, abs=1e-12)  # a boundary is a fraction of the centreline
    assert errors["kinematic_b_error_percent"] == pytest.approx(0.0, abs=1e-4)


# ---------------------------------------------------------------------------------------------- measured frames


def _pixel_frame(shift: float) -> PivRows:
    """3 x 4 vectors 32 px apart, all moving (2 + shift) px right and 4 px down per frame; one outlier."""
    y, x = np.mgrid[16:112:32, 16:144:32].astype(float)
    u, v = np.full(x.shape, 2.0 + shift), np.full(x.shape, 4.0)
    u[1, 1] = 40.0
    return PivRows(x.ravel(), y.ravel(), u.ravel(), v.ravel(), np.ones(x.size, bool), True)


def test_measured_frames_are_scaled_timed_and_cleaned_of_outliers():
    settings = MeasuredPiv(pixels=True, scale=ImageScale(1e-4, -0.01, 0.05), frame_rate=200.0, start_time=0.3,
                           field_interval=None, hampel_half_window=1, hampel_threshold=3.0)
    fields = measured_fields([_pixel_frame(0.0), _pixel_frame(1.0)], settings)
    assert [f.time for f in fields] == pytest.approx([0.3, 0.305])
    first = fields[0]
    assert first.x.tolist() == pytest.approx([-0.0084, -0.0052, -0.002, 0.0012])
    assert first.z.tolist() == pytest.approx([0.05 - 0.008, 0.05 - 0.0048, 0.05 - 0.0016])
    # 2 px/frame * 1e-4 m/px * 200 frames/s = 0.04 m/s right; 4 px down = 0.08 m/s down
    assert np.nanmax(np.abs(first.u - 0.04)) < 1e-15 and np.nanmax(np.abs(first.w + 0.08)) < 1e-15
    assert first.valid.sum() == 11 and not first.valid[1, 1]  # the outlier (row 1 from the top is z row 1)
    assert np.nanmax(np.abs(fields[1].u - 0.06)) < 1e-15


def test_measured_frames_in_other_units_than_configured_are_refused():
    frame = _pixel_frame(0.0)
    in_metres = PivRows(frame.x, frame.y, frame.u, frame.v, frame.valid, False, pixels=False)
    settings = MeasuredPiv(pixels=True, scale=ImageScale(1e-4, 0.0, 0.05), frame_rate=100.0)
    with pytest.raises(ValueError, match="piv.txt, frame 0: the file is in metres, the configuration says pixels"):
        measured_fields([in_metres], settings, "piv.txt")
    with pytest.raises(ValueError, match="needs the image scale"):
        MeasuredPiv(pixels=True, scale=None, frame_rate=100.0)


# ---------------------------------------------------------------------------------------------- DEM against PIV


@dataclass
class _Frame:
    time: float
    position: np.ndarray
    velocity: np.ndarray


def _lattice_frame(time: float, w: float) -> _Frame:
    """One sphere at each node of a 3 x 2 lattice next to the front wall moving at w, and one deep inside that the
    camera does not see, moving at +5 m/s."""
    x, z = np.meshgrid([-0.01, 0.0, 0.01], [0.02, 0.04])
    position = np.column_stack([x.ravel(), np.full(x.size, 0.001), z.ravel()])
    position = np.vstack([position, [0.0, 0.01, 0.02]])
    velocity = np.zeros_like(position)
    velocity[:-1, 2], velocity[-1, 2] = w, 5.0
    return _Frame(time, position, velocity)


def test_the_dem_front_wall_is_the_mean_over_the_window_and_its_standard_error():
    frames = [_lattice_frame(0.1, -1.0), _lattice_frame(0.2, -3.0), _lattice_frame(0.5, 7.0)]
    dem = dem_front_wall(frames, np.array([-0.01, 0.0, 0.01]), np.array([0.02, 0.04]), 0.004, 0.002, 0.0, 0.3,
                         min_count=1)
    assert dem.frames == 2 and dem.field.valid.all()
    assert np.all(dem.field.w == -2.0)
    # sample standard deviation of (-1, -3) is sqrt(2); over two frames its standard error is 1
    assert dem.w_standard_error == pytest.approx(np.ones((2, 3)))
    with pytest.raises(ValueError, match="no DEM frame between 1 and 2 s"):
        dem_front_wall(frames, np.array([0.0]), np.array([0.02]), 0.004, 0.002, 1.0, 2.0)


def _profile_rows(width, mm_per_px, rate, errors):
    return [{"width_px": width, "height_px": 1.4 * width, "frame_rate_hz": rate, "mm_per_px": mm_per_px, "z_m": z,
             "rms_w_m_s": error} for z, error in zip((0.02, 0.04), errors)]


PROFILES = [*_profile_rows(250, 0.6, 100.0, (0.03, 0.02)), *_profile_rows(250, 0.6, 250.0, (0.02, 0.01)),
            *_profile_rows(500, 0.3, 100.0, (0.015, 0.01)), *_profile_rows(500, 0.3, 250.0, (0.01, 0.005)),
            *_profile_rows(1000, 0.15, 250.0, (float("nan"), None))]


def test_the_error_band_is_the_synthetic_row_nearest_in_pixel_size_frame_rate_and_height():
    band, note = error_band(PROFILES, 3.2e-4, 200.0, 0.035)
    assert band == 0.005 and "500 x 700 px (0.3 mm/px), 250 frames/s, z = 40 mm" in note
    assert error_band(PROFILES, 3.2e-4, 200.0, 0.025)[0] == 0.01
    assert error_band(PROFILES, 1.5e-4, 250.0, 0.02)[0] == 0.01  # the 0.15 mm/px rows have no value
    band, note = error_band(PROFILES, None, 250.0, 0.02)
    assert np.isnan(band) and "pixel size unknown" in note


def test_the_error_along_a_profile_is_over_the_nodes_of_its_row():
    truth = _triangle()
    w = truth.w.copy()
    w[0, :3] += 0.03  # row z = 0.02: three nodes off by 0.03 m/s
    pairs = [(PlanarField(X, Z, truth.u, w, truth.valid), truth)] * 2
    rows = profile_error_rows(pairs, [0.021, 0.04])
    assert [r["z_m"] for r in rows] == [0.02, 0.04] and [r["nodes"] for r in rows] == [42, 42]
    assert rows[0]["bias_w_m_s"] == pytest.approx(0.03 * 3 / 21) and rows[0]["rms_w_m_s"] == pytest.approx(
        0.03 * np.sqrt(3 / 21))
    assert rows[1]["rms_w_m_s"] == 0.0


def test_a_gap_at_the_axis_leaves_the_centreline_unmeasured():
    field = _triangle()
    valid = field.valid.copy()
    valid[0, 10] = False  # the node at x = 0
    (quantities,) = field_quantities(PlanarField(X, Z, field.u, field.w, valid), [0.02])
    assert np.isnan(quantities.centreline_w) and np.isnan(quantities.fcb_left) and np.isnan(quantities.kinematic_b)


def test_a_difference_is_judged_against_the_piv_band_and_the_dem_noise(tmp_path):
    dem_field = _triangle()
    dem = dem_front_wall([_lattice_frame(0.1, -1.0)], X, Z, 0.004, 0.002, 0.0, 1.0)  # for its type only
    dem = type(dem)(dem_field, np.zeros(dem_field.w.shape), 4)
    measured = PlanarField(X, Z, dem_field.u, dem_field.w + 0.01, dem_field.valid)
    for band, verdict in ((0.02, "no"), (0.006, "no"), (0.004, "yes")):
        pairs = profile_pairs(dem, measured, [0.02], (0.2, 0.6), band)
        (row,) = comparison_rows(dem, measured, pairs)
        assert row["nodes"] == 21 and row["mean_difference_m_s"] == pytest.approx(-0.01, abs=1e-15)
        assert row["rms_difference_m_s"] == pytest.approx(0.01, abs=1e-15)
        assert row["uncertainty_m_s"] == pytest.approx(band) and row["larger_than_2_uncertainties"] == verdict
        assert row["difference_over_uncertainty"] == pytest.approx(0.01 / band)
        assert row["dem_fcb_right_m"] == pytest.approx(0.0285, abs=1e-12)
        assert row["dem_centreline_w_m_s"] - row["measured_centreline_w_m_s"] == pytest.approx(-0.01, abs=1e-15)
    path = plot_piv_comparison(pairs, tmp_path / "compare.png")
    assert path.read_bytes()[:4] == b"\x89PNG"


# ---------------------------------------------------------------------------------------------- the configured sequence


def _measured_config(**changes) -> dict:
    config = {"files": [], "format": "openpiv", "units": "pixels", "y_down": True, "frame_rate": 100.0,
              "field_interval": None, "start_time": 0.2, "pixel_size": None,
              "markers": [{"image": [0.0, 100.0], "silo": [-0.01, 0.0]}, {"image": [100.0, 0.0], "silo": [0.0, 0.01]}],
              "hampel": {"half_window": 1, "threshold": 3.0, "noise_floor": 0.01}, "windows": [],
              "min_valid_fraction": 0.5}
    config.update(changes)
    return config


def _write_openpiv(path, shift=0.0):
    frame = _pixel_frame(shift)
    flags = np.zeros(frame.x.size)
    table = np.column_stack([frame.x, frame.y, frame.u, frame.v, flags, flags])
    np.savetxt(path, table, delimiter="\t", fmt="%.4e", header="x y u v flags mask")
    return path


def test_a_configured_sequence_is_read_in_order_from_its_patterns(tmp_path):
    for n in (2, 1, 3):
        _write_openpiv(tmp_path / f"field_{n:04d}.txt", shift=n)
    paths = measured_piv_paths(["field_*.txt"], tmp_path)
    assert [p.name for p in paths] == ["field_0001.txt", "field_0002.txt", "field_0003.txt"]
    fields = load_measured_piv(_measured_config(), measured_piv_settings(_measured_config()), paths)
    # 1e-4 m/px from the markers at 100 frames/s: (2 + n) px/frame is (2 + n) cm/s
    assert [f.time for f in fields] == pytest.approx([0.2, 0.21, 0.22])
    assert [float(np.nanmean(f.u)) for f in fields] == pytest.approx([0.03, 0.04, 0.05])
    check_windows(fields, [[0.2, 0.21]])
    with pytest.raises(ValueError, match=r"windows\[0\]: no measured field between 0.3 and 0.4 s; the fields span 0.2"):
        check_windows(fields, [[0.3, 0.4]])
    with pytest.raises(ValueError, match="'piv_\\*.txt' matches no file"):
        measured_piv_paths(["piv_*.txt"], tmp_path)


@pytest.mark.parametrize("content, message", [
    ("# x y u v flags mask\n16 16 1 1 0\n", "bad.txt: 5 columns, expected 6"),
    ("# x y u v flags mask\nnan 16 1 1 0 0\n16 48 1 1 0 0\n",
     r"bad.txt: 1 vector.s. without a finite position \(first: line 2\)$"),
    # a configuration that points at /proc/self/environ: the message places the failure, never quotes the file
    ("SECRET_TOKEN=abc\x00SHELL=/bin/sh\x00", "bad.txt: line 1, column 1 is not a number$"),
])
def test_a_bad_measured_file_is_named_with_its_problem(tmp_path, content, message):
    (tmp_path / "bad.txt").write_text(content)
    with pytest.raises(ValueError, match=message):
        load_measured_piv(_measured_config(), measured_piv_settings(_measured_config()), [tmp_path / "bad.txt"])


@pytest.mark.parametrize("changes, message", [
    ({"markers": []}, "markers: 0 marker.s. do not fix the image scale"),
    ({"markers": [{"image": [5.0, 5.0], "silo": [0.0, 0.0]}, {"image": [5.0, 5.0], "silo": [0.01, 0.0]}]},
     "markers: all markers are at one image position"),
    ({"frame_rate": None}, "frame_rate: pixel files need the camera frame rate"),
    ({"units": "metres", "frame_rate": None}, "give the frame rate or the interval between fields"),
])
def test_measured_settings_that_cannot_place_or_time_the_fields_are_refused(changes, message):
    with pytest.raises(ValueError, match=f"silo_flat.piv.measured.*{message}"):
        measured_piv_settings(_measured_config(**changes))
