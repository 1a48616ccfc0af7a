"""Measured PIV fields in: the readers of OpenPIV, PIVlab and siloflow CSV files on hand-made files, the image scale
from wall markers, the neutral field and the Hampel filter, each against exact answers. The readers on files in every
layout the programs wrote are in test_piv_formats.py."""

from __future__ import annotations

import h5py
import numpy as np
import openpiv.tools
import pytest
import scipy.io

from siloflow.analysis.io.piv import (
    PivFormatError,
    PivReadOptions,
    read_openpiv,
    read_piv_csv,
    read_piv_file,
    read_pivlab_mat,
    read_pivlab_txt,
    write_piv_csv,
)
from siloflow.analysis.io.piv_base import axis_steps
from siloflow.analysis.piv.calibration import ImageScale, piv_field, scale_from_markers
from siloflow.analysis.piv.field import NODE_KINDS, PivRows, PlanarField, field_from_rows, time_average
from siloflow.analysis.piv.hampel import hampel_filter, hampel_outliers
from siloflow.analysis.piv.measured import MeasuredPiv

# ---------------------------------------------------------------------------------------------- the scale


def test_two_markers_fix_scale_and_origin_exactly_with_image_rows_down():
    # 0.25 mm per pixel, pixel (0, 0) at x = -0.05 m, z = 0.3 m
    truth = ImageScale(2.5e-4, -0.05, 0.3)
    image = np.array([[40.0, 1000.0], [360.0, 200.0]])
    silo = np.column_stack(truth.to_silo(image[:, 0], image[:, 1]))
    fitted = scale_from_markers(image, silo)
    assert fitted.scale == pytest.approx(2.5e-4, rel=1e-12)
    assert (fitted.x0, fitted.z0) == pytest.approx((-0.05, 0.3), abs=1e-12)
    assert fitted.residual < 1e-12


def test_markers_off_a_square_camera_show_in_the_residual():
    image = np.array([[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]])
    silo = np.array([[0.0, 0.0], [0.01, 0.0], [0.0, -0.0101]])  # 1 % taller than wide
    assert scale_from_markers(image, silo).residual > 1e-5


@pytest.mark.parametrize("image, silo, message", [
    ([[10.0, 10.0]], [[0.0, 0.0]], "1 marker"),
    ([[10.0, 10.0], [10.0, 10.0]], [[0.0, 0.0], [0.01, 0.0]], "one image position"),
    ([[0.0, 0.0], [100.0, 0.0]], [[0.01, 0.0], [0.0, 0.0]], "scale of -0.0001"),
    ([[0.0, np.nan], [100.0, 0.0]], [[0.0, 0.0], [0.01, 0.0]], "finite"),
])
def test_markers_that_fix_no_scale_are_refused_naming_them(image, silo, message):
    with pytest.raises(ValueError, match=f"piv.markers: .*{message}"):
        scale_from_markers(image, silo, "piv.markers")


def test_pixel_vectors_become_silo_velocities_with_v_down_turned_up():
    scale = ImageScale(1e-4, 0.0, 0.1)
    # a 2 x 2 grid of window centres (px); 3 px right and 5 px down per frame at 100 frames/s
    x = np.array([16.0, 48.0, 16.0, 48.0])
    y = np.array([16.0, 16.0, 48.0, 48.0])
    field = piv_field(x, y, np.full(4, 3.0), np.full(4, 5.0), np.ones(4, bool), True, scale, 100.0)
    assert field.x.tolist() == pytest.approx([0.0016, 0.0048])
    assert field.z.tolist() == pytest.approx([0.1 - 0.0048, 0.1 - 0.0016])
    assert np.allclose(field.u, 0.03) and np.allclose(field.w, -0.05)


# ---------------------------------------------------------------------------------------------- the readers


def test_the_openpiv_reader_reads_what_openpiv_wrote_with_flags_and_mask(tmp_path):
    y, x = np.mgrid[16:80:32, 16:112:32].astype(float)  # 2 rows x 3 columns of window centres
    u = np.array([[1.5, 2.0, 2.5], [3.0, 3.5, 4.0]])
    v = -u / 2
    flags = np.array([[0, 1, 0], [2, 0, 0]])
    mask = np.array([[0, 0, 0], [0, 0, 1]])
    path = tmp_path / "field_0001.txt"
    openpiv.tools.save(path, x, y, u, v, flags, mask)
    rows = read_openpiv(path, y_down=True)
    assert rows.x.tolist() == x.ravel().tolist() and rows.y.tolist() == y.ravel().tolist()
    assert rows.u.tolist() == u.ravel().tolist() and rows.v.tolist() == v.ravel().tolist()
    assert [NODE_KINDS[k] for k in rows.kind] == ["measured", "invalid", "measured", "interpolated", "measured",
                                                  "masked"]
    assert rows.valid.tolist() == [True, False, True, False, True, False]  # flags 1 and 2, and mask 1, are out
    assert rows.y_down and rows.pixels is None


def test_the_pivlab_reader_takes_its_information_lines_delimiters_and_types(tmp_path):
    text = ("PIVlab by W.Th. & E.J.S., ASCII chart output - 26-Nov-2026\r\n"
            "FRAME: 1, filenames: a.tif & b.tif, conversion factor xy (px -> m): 1, conversion factor uv: 1\r\n"
            "x [px],y [px],u [px/frame],v [px/frame],Vector type [-]\r\n"
            "16,16,1.25,-0.5,1\r\n48,16,NaN,NaN,0\r\n16,48,2,0.25,2\r\n48,48,3,1,1\r\n")
    path = tmp_path / "PIVlab_0001.txt"
    path.write_bytes(text.encode())
    rows = read_pivlab_txt(path)
    assert rows.y_down and rows.pixels and rows.x.tolist() == [16, 48, 16, 48]
    assert rows.u[0] == 1.25 and rows.v[3] == 1.0
    assert [NODE_KINDS[k] for k in rows.kind] == ["measured", "masked", "interpolated", "measured"]
    assert rows.valid.tolist() == [True, False, False, True]


def test_a_csv_field_round_trips_bit_for_bit(tmp_path):
    field = PlanarField(np.array([-0.01, 0.0, 0.01]), np.array([0.02, 0.026]),
                        np.array([[0.1, 0.2, 0.3], [0.4, np.nan, 1 / 3]]),
                        np.array([[-1.0, -2.0, -3.0], [-4.0, np.nan, -2 / 3]]),
                        np.array([[True, True, True], [True, False, True]]), time=1.5)
    path = write_piv_csv(tmp_path / "piv.csv", field)
    back = read_piv_csv(path, time=1.5)
    assert back.x.tolist() == field.x.tolist() and back.z.tolist() == field.z.tolist()
    assert np.array_equal(back.u, field.u, equal_nan=True) and np.array_equal(back.w, field.w, equal_nan=True)
    assert back.valid.tolist() == field.valid.tolist()


@pytest.mark.parametrize("content, message", [
    ("x_m,z_m,u_m_s,w_m_s,valid\n0,0,1,1\n", "4 columns, expected 5"),
    ("x_m,z_m,u_m_s,w_m_s,valid\nnan,0,1,1,1\n", "without a finite position"),
    ("x,z,u,w,valid\n0,0,1,1,1\n", r"the header on line 1 has 5 names \(not all siloflow's\); siloflow's is "
                                     "x_m,z_m,u_m_s,w_m_s,valid"),
    ("z_m,x_m,u_m_s,w_m_s,valid\n0,0,1,1,1\n", "the header on line 1 names z_m, x_m, u_m_s, w_m_s, valid; "),
    ("x_m,z_m,u_m_s,w_m_s,valid\n0,0,1,1,1\n\n0,1,1,x,1\n", "line 4, column 4 is not a number"),
    ("x_m,z_m,u_m_s,w_m_s,valid\n", "no vectors"),
    ("x_m,z_m,u_m_s,w_m_s,valid\n0,0,1,1,1\n0.1,0.1,1,1,1\n", "do not fill a regular grid"),
])
def test_a_bad_csv_is_refused_naming_the_file_and_the_problem(tmp_path, content, message):
    path = tmp_path / "measured.csv"
    path.write_text(content)
    with pytest.raises(PivFormatError, match=f"measured.csv: .*{message}"):
        read_piv_csv(path)


def test_a_bad_openpiv_or_pivlab_file_is_refused_naming_it(tmp_path):
    path = tmp_path / "short.txt"
    path.write_text("# x y u v flags mask\n1 2 3 4 0\n")
    with pytest.raises(PivFormatError, match="short.txt: 5 columns, expected 6"):
        read_openpiv(path, y_down=True)
    path.write_text("x [px],y [px],u [px/frame]\n1,2,3,4\n")
    with pytest.raises(PivFormatError, match="short.txt: the header on line 1 names x, y, u over 4 columns"):
        read_pivlab_txt(path)
    path.write_text("x,y,u,v\n1,2,3,4\n")
    with pytest.raises(PivFormatError, match="short.txt: line 1 is neither PIVlab's information lines, its header "
                                             "nor numbers$"):
        read_pivlab_txt(path)


# ---------------------------------------------------------------------------------------------- field, Hampel


def test_rows_in_any_order_fill_the_grid():
    field = field_from_rows([0.0, 1.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [1, 2, 3, 4], [5, 6, 7, 8], [1, 1, 1, 0])
    assert field.u.tolist()[0] == [3, 2] and field.w[1, 0] == 5 and not field.valid[1, 1] and np.isnan(field.u[1, 1])


def test_hampel_removes_planted_outliers_and_keeps_every_other_node_bit_for_bit():
    z, x = np.mgrid[0:12, 0:15].astype(float)
    rng = np.random.default_rng(3)
    u = 0.01 * x + 0.003 * z + 1e-4 * rng.standard_normal(x.shape)  # a smooth shear with measurement noise
    w = -0.2 + 0.004 * x**2 / 15 + 1e-4 * rng.standard_normal(x.shape)
    planted = [(2, 3), (7, 11), (10, 0), (0, 14)]
    for k, i in planted:
        w[k, i] += 0.1  # a wrong correlation peak, 1000 noise levels off
    u[5, 5] -= 0.3
    field = PlanarField(np.arange(15.0), np.arange(12.0), u, w, np.ones(x.shape, bool))
    # the floor (0.01 m/s) lies above the field's change from node to node (up to 0.0075 m/s at its edge)
    filtered = hampel_filter(field, half_window=1, threshold=5.0, noise_floor=0.01)
    removed = set(zip(*np.nonzero(~filtered.valid)))
    assert removed == set(planted) | {(5, 5)}
    keep = filtered.valid
    assert np.array_equal(filtered.u[keep], field.u[keep]) and np.array_equal(filtered.w[keep], field.w[keep])


def test_hampel_never_flags_an_invalid_node_or_one_without_enough_neighbours():
    values = np.array([[0.0, 0.0, 9.0], [0.0, 0.0, 0.0]])
    valid = np.array([[True, True, True], [False, False, False]])
    # the corner 9 has one valid neighbour (fewer than 3): kept
    assert not hampel_outliers(values, valid).any()


def test_without_a_noise_floor_an_edge_with_a_gradient_looks_like_outliers():
    x = np.tile(np.arange(6.0), (5, 1))
    values = 0.01 * x**2  # every neighbour of the right edge lies to its left and they nearly agree
    assert hampel_outliers(values, np.ones(values.shape, bool), threshold=3.0)[:, -1].any()
    assert not hampel_outliers(values, np.ones(values.shape, bool), threshold=3.0, noise_floor=0.1).any()


def test_time_average_is_the_mean_over_the_window_of_the_valid_values():
    x, z = np.array([0.0, 1.0]), np.array([0.0])
    fields = [PlanarField(x, z, [[1.0, 2.0]], [[-1.0, -2.0]], [[True, True]], time=0.1),
              PlanarField(x, z, [[3.0, 9.0]], [[-3.0, -9.0]], [[True, False]], time=0.2),
              PlanarField(x, z, [[5.0, 4.0]], [[-5.0, -4.0]], [[True, True]], time=0.3),
              PlanarField(x, z, [[99.0, 99.0]], [[0.0, 0.0]], [[True, True]], time=0.9)]  # outside the window
    mean = time_average(fields, 0.1, 0.3)
    assert mean.u.tolist() == [[3.0, 3.0]] and mean.w.tolist() == [[-3.0, -3.0]] and mean.time == pytest.approx(0.2)
    assert time_average(fields, 0.1, 0.3, min_fraction=0.9).valid.tolist() == [[True, False]]
    with pytest.raises(ValueError, match="no PIV field between 1.0 and 2.0 s"):
        time_average(fields, 1.0, 2.0)


# ---------------------------------------------------------------------------------------------- PIVlab .mat, DaVis


def test_a_mat_file_of_per_frame_arrays_x_1_u_1_is_refused_naming_pivlabs_layouts(tmp_path):
    # no PIVlab release writes x_<n>, u_<n>: its GUI export, command-line workspace and session are the layouts
    path = tmp_path / "PIVlab.mat"
    grid = np.ones((2, 3))
    scipy.io.savemat(path, {"x_1": grid, "y_1": grid, "u_1": grid, "v_1": grid, "typevector_1": grid})
    with pytest.raises(PivFormatError, match="PIVlab.mat: none of PIVlab's layouts: the GUI export has x, y, "
                                             "u_original"):
        read_pivlab_mat(path)
    path.write_text("not matlab")
    with pytest.raises(PivFormatError, match="PIVlab.mat: not a MATLAB file"):
        read_pivlab_mat(path)


def test_an_hdf5_file_that_is_not_pivlabs_is_refused_naming_it(tmp_path):
    path = tmp_path / "other.mat"
    with h5py.File(path, "w") as handle:
        handle["velocity"] = np.zeros((2, 2))
    with pytest.raises(PivFormatError, match="other.mat: none of PIVlab's layouts"):
        read_pivlab_mat(path)


def _davis_buffer(lvpyio):
    """A 2 x 3 vector buffer, one vector masked, with DaVis scales."""
    vectors = np.ma.zeros((2, 3), dtype=lvpyio.vec2c)
    vectors["u"] = np.arange(6.0).reshape(2, 3)
    vectors["v"] = -1.0
    vectors[1, 2] = np.ma.masked
    buffer = lvpyio.arrays_to_buffer(vectors)
    # calibrated: 0.1 mm per px, y up (negative slope), 16 px vector grid, velocities 2 m/s per unit
    buffer[0].scales = lvpyio.Scales(lvpyio.Scale(0.1, -5.0, "mm", "x"), lvpyio.Scale(-0.1, 20.0, "mm", "y"),
                                     lvpyio.Scale(1.0, 0.0, "mm", ""), lvpyio.Scale(2.0, 0.0, "m/s", "V"))
    buffer[0].grid = lvpyio.Grid(16, 16, 1)
    return buffer


def test_davis_vectors_come_in_metres_with_y_up_and_davis_masks(tmp_path):
    lvpyio = pytest.importorskip("lvpyio", reason="DaVis files need the optional extra siloflow[davis]")
    path = tmp_path / "B00001.vc7"
    lvpyio.write_buffer(_davis_buffer(lvpyio), str(path))
    (frame,) = read_piv_file(path, "davis")
    assert frame.pixels is False and frame.y_down is False
    assert frame.x[:3] == pytest.approx(1e-3 * (np.array([0.5, 1.5, 2.5]) * 16 * 0.1 - 5.0))
    assert frame.y[[0, 3]] == pytest.approx(1e-3 * (np.array([0.5, 1.5]) * 16 * -0.1 + 20.0))
    assert frame.u.tolist()[:5] == [0.0, 2.0, 4.0, 6.0, 8.0] and frame.v[0] == 2.0  # -1 along a y that points up
    assert frame.valid.tolist() == [True] * 5 + [False]
    assert NODE_KINDS[frame.kind[5]] in ("masked", "invalid")


def test_read_piv_file_names_an_unknown_format_or_a_missing_file(tmp_path):
    with pytest.raises(PivFormatError, match="piv.txt: unknown PIV format 'insight'"):
        read_piv_file(tmp_path / "piv.txt", "insight")
    with pytest.raises(PivFormatError, match="piv.txt: no such file"):
        read_piv_file(tmp_path / "piv.txt", "openpiv")


def test_a_csv_through_read_piv_file_is_one_frame_in_metres(tmp_path):
    field = PlanarField(np.array([-0.01, 0.01]), np.array([0.02]), np.array([[0.1, 0.2]]), np.array([[-1.0, -2.0]]),
                        np.array([[True, False]]))
    (frame,) = read_piv_file(write_piv_csv(tmp_path / "f.csv", field), "csv")
    assert (frame.pixels, frame.y_down) == (False, False)
    assert frame.x.tolist() == [-0.01, 0.01] and frame.y.tolist() == [0.02, 0.02] and frame.valid.tolist() == [True, False]
    assert [NODE_KINDS[k] for k in frame.kind] == ["measured", "invalid"]


def test_the_grid_order_says_which_way_each_axis_points():
    # OpenPIV's order (x fastest) of a 2 x 2 grid with y up, and PIVlab's (y fastest) with x to the left
    assert axis_steps(np.array([16.0, 48.0, 16.0, 48.0]), np.array([80.0, 80.0, 48.0, 48.0]), True) == (32.0, -32.0)
    assert axis_steps(np.array([48.0, 48.0, 16.0, 16.0]), np.array([16.0, 48.0, 16.0, 48.0]), False) == (-32.0, 32.0)
    assert axis_steps(np.array([16.0, 48.0]), np.array([16.0, 16.0]), True) == (32.0, None)  # one grid row


def test_reading_options_a_format_does_not_have_are_refused():
    with pytest.raises(ValueError, match="pivlab_field must be one of original, filtered, got 'smoothed'"):
        PivReadOptions(pivlab_field="smoothed")
    with pytest.raises(ValueError, match="valid kinds .'masked'.: give one or more of measured, second_peak"):
        MeasuredPiv(False, None, 100.0, valid_kinds=("masked",))


def test_rows_made_by_hand_take_true_as_measured_and_refuse_unknown_codes():
    rows = PivRows([0.0, 1.0], [0.0, 0.0], [1.0, 2.0], [3.0, np.nan], np.array([True, True]), True)
    assert [NODE_KINDS[k] for k in rows.kind] == ["measured", "measured"]
    assert rows.valid.tolist() == [True, False]  # a measured vector without a finite velocity does not count
    with pytest.raises(ValueError, match="kind holds codes other than 0 to 5"):
        PivRows([0.0], [0.0], [1.0], [1.0], np.array([7]), True)
    with pytest.raises(ValueError, match="PIV rows of different lengths"):
        PivRows([0.0, 1.0], [0.0], [1.0], [1.0], np.array([0]), True)
