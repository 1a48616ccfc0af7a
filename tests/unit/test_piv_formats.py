"""Each reader on a file of each layout its program wrote (tests/fixtures/piv, README there for where each comes from):
positions, velocities, units, orientation and the kind of every vector, against the file read independently (its
text with numpy, its MATLAB variables with scipy.io or h5py, its DaVis components with lvpyio) and the program's own
documented meaning of its flags; and each layout's refusals, naming the file and the reason."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.io

from siloflow.analysis.io.piv import PivFormatError, read_davis, read_openpiv, read_pivlab_mat, read_pivlab_txt
from siloflow.analysis.piv.field import NODE_KINDS

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "piv"


def kinds(rows) -> list[str]:
    return [NODE_KINDS[k] for k in rows.kind]


# ---------------------------------------------------------------------------------------------- OpenPIV


def test_the_current_layout_written_by_openpiv_itself_flags_and_mask():
    path = FIXTURES / "openpiv_0.26_flags_mask.txt"
    assert path.read_text().splitlines()[0] == "# x\ty\tu\tv\tflags\tmask"
    x, y, u, v, flags, mask = np.loadtxt(path).T
    rows = read_openpiv(path)
    assert rows.x.tolist() == x.tolist() and rows.y.tolist() == y.tolist()
    assert rows.u.tolist() == u.tolist() and rows.v.tolist() == v.tolist()
    assert rows.y_down and rows.pixels is None  # y grows from the first grid row to the next: image rows
    # OpenPIV's docstring: flags 0 valid, 1 invalid, 2 interpolated; mask 1 inside the image mask
    meaning = {0: "measured", 1: "invalid", 2: "interpolated"}
    expected = ["masked" if m else meaning[int(f)] for f, m in zip(flags, mask)]
    assert kinds(rows) == expected and expected.count("masked") == 1 and "interpolated" in expected
    assert u[mask == 1].tolist() == [0.0]  # tools.save writes a masked vector as 0: it must not count as measured
    assert rows.valid.tolist() == [k == "measured" for k in expected]


def test_the_layout_of_0_23_4_to_0_24_2_mask_marks_invalid_vectors_with_y_and_v_up():
    path = FIXTURES / "openpiv_0.23.9_mask.txt"
    assert path.read_text().splitlines()[0] == "# x\ty\tu\tv\tmask"
    x, y, u, v, mask = np.loadtxt(path).T
    rows = read_openpiv(path)
    assert not rows.y_down  # windef's transform_coordinates: the top grid row has the largest y
    assert rows.y.tolist() == y.tolist() and rows.v.tolist() == v.tolist()
    assert kinds(rows) == ["invalid" if m else "measured" for m in mask] and mask.sum() == 2


def test_the_windef_layout_with_the_signal_to_noise_ratio_and_a_summed_mask():
    path = FIXTURES / "openpiv_0.23.3_s2n_mask.txt"
    assert path.read_text().splitlines()[0] == "# x\ty\tu\tv\ts2n\tmask"
    x, y, u, v, s2n, mask = np.loadtxt(path).T
    assert 2.0 in mask  # two validations failed there
    rows = read_openpiv(path)
    assert kinds(rows) == ["invalid" if m else "measured" for m in mask]
    rows = read_openpiv(path, sig2noise_threshold=1.5)
    assert kinds(rows) == ["invalid" if m or s < 1.5 else "measured" for s, m in zip(s2n, mask)]
    assert 0 < sum(s < 1.5 for s in s2n[mask == 0])  # the threshold removes some the mask kept


def test_the_headerless_layout_of_0_19_to_0_22_with_v_up_next_to_y_down():
    path = FIXTURES / "openpiv_0.22.2_mask.txt"
    assert not path.read_text().startswith("#")
    x, y, u, v, mask = np.loadtxt(path).T
    # as 0.21 and 0.22's process module returned them: rows written top first with y growing (down), v up
    rows = read_openpiv(path, y_down=False)
    assert rows.y_down and rows.y.tolist() == y.tolist()
    assert rows.v.tolist() == (-v).tolist()  # v turned to point the way y does
    assert kinds(rows) == ["invalid" if m else "measured" for m in mask]
    unturned = read_openpiv(path)  # not told: v is taken to point the way y does
    assert unturned.v.tolist() == v.tolist()


def test_pivpys_openpiv_sample_with_the_signal_to_noise_ratio_fifth():
    path = FIXTURES / "openpiv_exp1_001_b_s2n.txt"
    x, y, u, v, s2n = np.loadtxt(path).T
    rows = read_openpiv(path, fifth_column="sig2noise")
    assert rows.x.tolist() == x.tolist() and rows.u.tolist() == u.tolist() and rows.y_down
    assert kinds(rows) == ["unflagged"] * 12  # the file says nothing of validation
    rows = read_openpiv(path, fifth_column="sig2noise", sig2noise_threshold=50.0)
    assert kinds(rows) == ["measured" if s >= 50.0 else "invalid" for s in s2n] and 0 < (s2n < 50).sum() < 12
    with pytest.raises(PivFormatError, match=r"exp1_001_b_s2n.txt: line 1, column 5 \(mask\) is not a whole number "
                                             r">= 0; if the column holds the signal-to-noise ratio, set "
                                             r"silo_flat.piv.measured.openpiv.fifth_column: sig2noise$"):
        read_openpiv(path)


@pytest.mark.parametrize("content, message", [
    ("# x y u v vorticity\n16 16 1 1 0\n", r"the header on line 1 has 5 names \(not all OpenPIV's\), none of "
                                           r"OpenPIV's: '# x y u v s2n mask' \(windef.save"),
    ("\n# x y u v flags\n16 16 1 1 0\n", r"the header on line 2 names x, y, u, v, flags, none of OpenPIV's: '# x y "),
    ("16 16 1 1 0 0\n", r"6 columns, expected 5 \(OpenPIV wrote five columns \(x y u v mask\) without a header"),
    ("# x y u v flags mask\n16 16 1 1 3 0\n", r"line 2, column 5 \(flags\) holds a flag OpenPIV does not write; "
                                              r"OpenPIV writes 0 \(valid\), 1 \(invalid\) or 2 \(interpolated\) there"),
    ("# x y u v flags mask\n16 16 1 1 0 0.5\n", r"line 2, column 6 \(mask\) is not a whole number >= 0; OpenPIV "
                                                r"writes 0 or 1 \(inside the image mask\) there"),
    ("# x y u v mask\n16 16 1 1 0\n\n16 48 1 1 -1\n", r"line 4, column 5 \(mask\) is not a whole number >= 0"),
    ("# x y u v flags mask\n16 16 1 1 0 0\n48 16 1 1 0 0\n", "a single grid row does not show which way y points"),
    ("# x y u v flags mask\n48 16 1 1 0 0\n16 16 1 1 0 0\n", "x decreases along a grid row"),
])
def test_an_openpiv_file_of_no_openpiv_layout_is_refused_naming_it(tmp_path, content, message):
    path = tmp_path / "field.txt"
    path.write_text(content)
    with pytest.raises(PivFormatError, match=f"field.txt: {message}"):
        read_openpiv(path)


# ---------------------------------------------------------------------------------------------- PIVlab text

#: PIVlab's vector types (its export's information: 0 masked, 1 regular, 2 filtered; 3.14's second peak)
PIVLAB_TYPES = {0: "masked", 1: "measured", 2: "interpolated", 3: "second_peak"}


def pivlab_kind(vector_type: float, u: float) -> str:
    if np.isnan(u) and vector_type != 0:
        return "invalid"  # rejected by validation and left empty
    return PIVLAB_TYPES[int(vector_type)]


@pytest.mark.parametrize("name, delimiter, preamble, columns, typed", [
    ("pivlab_2.36_4col.txt", ",", 3, 4, False),
    ("pivlab_2.36_11col.txt", "\t", 3, 11, False),
    ("pivlab_2.37_12col.txt", " ", 3, 12, False),
    ("pivlab_3.13_5col.txt", ",", 3, 5, True),
    ("pivlab_3.13_12col.txt", "\t", 1, 12, True),
    ("pivlab_3.14_13col.txt", ",", 3, 13, True),
    ("pivlab_3.14_14col.txt", " ", 3, 14, True),
])
def test_every_pivlab_text_layout_in_pixels(name, delimiter, preamble, columns, typed):
    path = FIXTURES / name
    assert b"\r\n" in path.read_bytes()  # PIVlab's CR LF line ends
    table = np.genfromtxt(path, delimiter=delimiter, skip_header=preamble)
    assert table.shape == (12, columns)
    x, y, u, v = table[:, :4].T
    rows = read_pivlab_txt(path)
    assert rows.x.tolist() == x.tolist() and rows.y.tolist() == y.tolist()
    assert np.array_equal(rows.u, u, equal_nan=True) and np.array_equal(rows.v, v, equal_nan=True)
    assert rows.pixels is True and rows.y_down  # px header; y grows down the first grid column
    if typed:
        assert kinds(rows) == [pivlab_kind(t, a) for t, a in zip(table[:, 4], u)]
    else:  # no type: NaN is all the file says
        assert kinds(rows) == ["masked" if np.isnan(a) else "unflagged" for a in u]
    assert ("second_peak" in kinds(rows)) == name.startswith("pivlab_3.14")


def test_a_calibrated_pivlab_export_says_metres_and_y_up():
    path = FIXTURES / "pivlab_3.13_calibrated_m.txt"
    x, y, u, v, t = np.genfromtxt(path, delimiter=",", skip_header=3).T
    rows = read_pivlab_txt(path)
    assert rows.pixels is False and not rows.y_down  # y axis "increase to top": y falls down the grid column
    assert rows.x.tolist() == x.tolist() and rows.y.tolist() == y.tolist()
    assert np.array_equal(rows.v, v, equal_nan=True)


def test_a_pivlab_text_without_header_or_information_lines_leaves_the_units_open(tmp_path):
    lines = (FIXTURES / "pivlab_3.13_5col.txt").read_bytes().split(b"\r\n")
    path = tmp_path / "bare.txt"
    path.write_bytes(b"\r\n".join(lines[3:]))
    assert read_pivlab_txt(path).pixels is None


def _without_header(tmp_path, name: str, keep: slice) -> Path:
    lines = (FIXTURES / name).read_bytes().split(b"\r\n")
    path = tmp_path / name
    path.write_bytes(b"\r\n".join(lines[keep]))
    return path


@pytest.mark.parametrize("name, keep, message", [
    ("pivlab_3.13_12col.txt", slice(1, None), "12 columns without a header: PIVlab 2.37 to 2.43 wrote"),
    ("pivlab_2.37_12col.txt", slice(3, None), "12 columns without a header"),
])
def test_twelve_columns_without_the_header_that_tells_them_apart_are_refused(tmp_path, name, keep, message):
    with pytest.raises(PivFormatError, match=f"{name}: {message}"):
        read_pivlab_txt(_without_header(tmp_path, name, keep))


CALIBRATED = "PIVlab, ASCII chart output - 28-Nov-2026\r\nFRAME: 1, filenames: a.bmp & b.bmp, conversion factor xy " \
             "(px -> m): {xy}, conversion factor uv (px/frame -> m/s): {uv}\r\n{header}\r\n{rows}"


@pytest.mark.parametrize("xy, uv, header, rows, message", [
    ("0.00025", "0.00025", "x [m],y [m],u [m/frame],v [m/frame],Vector type [-]", "0,0,1,1,1\r\n0,0.1,1,1,1",
     "velocities in m/frame"),
    ("0.00025", "0.00025", "x [m],y [m],u [m/s],v [m/s],Vector type [-]", "0,0,1,1,1\r\n0,0.1,1,1,1",
     "line 2: the conversion factors xy and uv are equal: PIVlab's displacement-only"),
    ("1", "1", "x [m],y [m],u [m/s],v [m/s],Vector type [-]", "0,0,1,1,1\r\n0,0.1,1,1,1",
     "the header says m, the conversion factors say px"),
    ("1", "1", "x [px],y [px],u [m/s],v [m/s],Vector type [-]", "0,0,1,1,1\r\n0,1,1,1,1",
     r"the header on line 3 gives units x \[px\], u \[m/s\]; PIVlab writes px with px/frame or m with m/s"),
    ("1", "1", "x [px],y [px],u [px/frame],v [px/frame],Vector type [-]", "16,16,1,1,4\r\n16,48,1,1,1",
     "line 4 has a vector type PIVlab does not write; PIVlab's types are 0 .masked."),
    ("1", "1", "x [px],y [px],u [px/frame],v [px/frame],Vector type [-]", "48,16,1,1,1\r\n16,16,1,1,1",
     "x increases to the left"),
    ("0.001", "0.25", "x [m],y [m],u [m/s],v [m/s],Vector type [-]", "0,0,1,1,1\r\n0.1,0,1,1,1",
     "a single grid row does not show which way PIVlab's y axis points"),
])
def test_pivlab_text_that_siloflow_cannot_read_right_is_refused_naming_why(tmp_path, xy, uv, header, rows, message):
    path = tmp_path / "PIVlab_0001.txt"
    path.write_bytes(CALIBRATED.format(xy=xy, uv=uv, header=header, rows=rows).encode())
    with pytest.raises(PivFormatError, match=f"PIVlab_0001.txt: {message}"):
        read_pivlab_txt(path)


# ---------------------------------------------------------------------------------------------- PIVlab MATLAB


def _cells(value) -> list[np.ndarray]:
    return [np.asarray(c, dtype=float) for c in np.asarray(value, dtype=object).ravel()]


def _check_frame(rows, x, y, u, v, types, pixels=True):
    """One frame against its MATLAB arrays, in PIVlab's column-major order."""
    x, y, u, v, types = (np.asarray(a, dtype=float).ravel(order="F") for a in (x, y, u, v, types))
    assert rows.x.tolist() == x.tolist() and rows.y.tolist() == y.tolist()
    assert np.array_equal(rows.u, u, equal_nan=True) and np.array_equal(rows.v, v, equal_nan=True)
    assert rows.pixels is pixels and rows.y_down
    assert kinds(rows) == [pivlab_kind(t, a) for t, a in zip(types, u)]


@pytest.mark.parametrize("field", ["original", "filtered"])
def test_the_gui_export_of_all_frames_matlab_5(field):
    path = FIXTURES / "pivlab_3.13_gui_v5.mat"
    raw = scipy.io.loadmat(path)
    assert str(raw["units"][0]) == "[px] respectively [px/frame]"
    frames = read_pivlab_mat(path, field)
    assert len(frames) == 2
    for n, rows in enumerate(frames):
        _check_frame(rows, *(_cells(raw[name])[n] for name in
                             ("x", "y", f"u_{field}", f"v_{field}", f"typevector_{field}")))
    if field == "original":  # the correlation's own types: measured or masked, the outliers included
        assert set(kinds(frames[0])) == {"measured", "masked"}
    else:
        assert {"second_peak", "interpolated", "invalid", "masked"} <= set(kinds(frames[0]))


def test_the_gui_export_of_the_current_frame_holds_plain_arrays():
    path = FIXTURES / "pivlab_3.13_gui_current_frame_v5.mat"
    raw = scipy.io.loadmat(path)
    assert raw["u_filtered"].dtype == float
    (rows,) = read_pivlab_mat(path)
    _check_frame(rows, raw["x"], raw["y"], raw["u_filtered"], raw["v_filtered"], raw["typevector_filtered"])


def _h5(handle, node) -> np.ndarray:
    """A MATLAB 7.3 numeric array in MATLAB's axis order (HDF5 keeps the axes reversed)."""
    return np.asarray(node[()], dtype=float).T


def test_the_gui_export_in_matlab_7_3_hdf5():
    path = FIXTURES / "pivlab_3.13_gui_v73.mat"
    assert path.read_bytes()[:19] == b"MATLAB 7.3 MAT-file"
    (rows,) = read_pivlab_mat(path)
    with h5py.File(path, "r") as handle:
        arrays = [_h5(handle, handle[handle[name][()].ravel()[0]]) for name in
                  ("x", "y", "u_filtered", "v_filtered", "typevector_filtered")]
    _check_frame(rows, *arrays)


def test_the_command_line_workspace_of_cells_matlab_5():
    path = FIXTURES / "pivlab_commandline_cells_v5.mat"
    raw = scipy.io.loadmat(path)
    frames = read_pivlab_mat(path)
    assert len(frames) == 2
    for n, rows in enumerate(frames):
        _check_frame(rows, *(_cells(raw[k])[n] for k in ("x", "y", "u_filt", "v_filt", "typevector_filt")))
    for n, rows in enumerate(read_pivlab_mat(path, "original")):
        _check_frame(rows, *(_cells(raw[k])[n] for k in ("x", "y", "u", "v", "typevector")))


def test_the_command_line_workspace_of_three_dimensional_arrays_matlab_7_3():
    path = FIXTURES / "pivlab_commandline_3d_v73.mat"
    with h5py.File(path, "r") as handle:
        arrays = {k: _h5(handle, handle[k]) for k in ("x", "y", "u_filt", "v_filt", "typevector_filt")}
    assert arrays["u_filt"].shape == (3, 4, 2)  # rows, columns, image pairs
    frames = read_pivlab_mat(path)
    assert len(frames) == 2
    for n, rows in enumerate(frames):
        _check_frame(rows, *(arrays[k][:, :, n] for k in ("x", "y", "u_filt", "v_filt", "typevector_filt")))


PIVLAB_JET = FIXTURES / "pivlab_example_jet_commandline_v5.mat"


def test_pivlabs_own_jet_result_keeps_the_command_line_workspace_as_matlab_saved_it():
    """The copy of PIVlab's sample is what the reader must face: MATLAB 5, cells of single-precision arrays."""
    assert PIVLAB_JET.read_bytes()[:10] == b"MATLAB 5.0"
    classes = {name: (shape, matlab_class) for name, shape, matlab_class in scipy.io.whosmat(PIVLAB_JET)}
    for name in ("x", "y", "u", "v", "typevector", "u_filt", "v_filt", "typevector_filt", "correlation_map"):
        assert classes[name] == ((3, 1), "cell")  # one cell per image pair
    assert "units" not in classes and "u_original" not in classes  # no GUI export: nothing says the units
    raw = scipy.io.loadmat(PIVLAB_JET, mat_dtype=True)
    assert {raw[k][0, 0].dtype for k in ("x", "y", "u", "v", "u_filt", "typevector_filt")} == {np.dtype(np.float32)}
    assert raw["amount"][0, 0] == 20 and raw["pairwise"][0, 0] == 1  # 20 images as pairs A+B, C+D, ...


@pytest.mark.parametrize("field, names", [("original", ("u", "v", "typevector")),
                                          ("filtered", ("u_filt", "v_filt", "typevector_filt"))])
def test_pivlabs_own_jet_result_read_against_its_variables(field, names):
    raw = scipy.io.loadmat(PIVLAB_JET)
    frames = read_pivlab_mat(PIVLAB_JET, field)
    assert len(frames) == 3
    for n, rows in enumerate(frames):  # in pair order, each against its own cells
        x, y, u, v, types = (_cells(raw[k])[n] for k in ("x", "y") + names)
        _check_frame(rows, x, y, u, v, types)  # positions, velocities, pixels, y down, kinds
        assert y[1, 0] > y[0, 0] and x[0, 1] > x[0, 0]  # image axes: y grows down the grid column, x to the right
        assert rows.x.dtype == float and rows.u.tolist() == u.astype(float).ravel(order="F").tolist()
    # the script does not calibrate: its calibration factors r{1,2} and r{2,2} only scale the velocity limits
    calibration = raw["r"]
    assert calibration[0, 1][0, 0] == 1 and calibration[1, 1][0, 0] == 1
    if field == "original":  # the correlation's own types: no mask, so every vector measured
        assert {k for rows in frames for k in kinds(rows)} == {"measured"}
    else:  # validation rejected some and PIVlab_commandline.m filled them in (inpaint_nans): type 2, finite
        assert [kinds(rows).count("interpolated") for rows in frames] == [2, 4, 4]
        assert all(np.isfinite(rows.u).all() for rows in frames)


def test_pivlabs_own_jet_result_replaced_what_its_validation_rejected():
    """The two fields differ exactly where the filtered types say PIVlab interpolated: the reader picks the right
    variables for each."""
    raw = scipy.io.loadmat(PIVLAB_JET)
    for original, filtered, u, u_filt in zip(read_pivlab_mat(PIVLAB_JET, "original"),
                                             read_pivlab_mat(PIVLAB_JET, "filtered"), _cells(raw["u"]),
                                             _cells(raw["u_filt"])):
        interpolated = np.array(kinds(filtered)) == "interpolated"
        assert original.x.tolist() == filtered.x.tolist() and original.y.tolist() == filtered.y.tolist()
        assert (original.u != filtered.u).tolist() == interpolated.tolist()
        assert ((u != u_filt).ravel(order="F")).tolist() == interpolated.tolist()


@pytest.mark.parametrize("field, first", [("original", 2), ("filtered", 6)])
def test_a_session_is_read_from_its_resultslist(field, first):
    path = FIXTURES / "pivlab_3.14_session_v73.mat"
    frames = read_pivlab_mat(path, field)
    assert len(frames) == 2
    with h5py.File(path, "r") as handle:
        references = handle["resultslist"][()]  # (frames, rows): MATLAB's (rows, frames) reversed
        for n, rows in enumerate(frames):
            x, y, u, v, types = (_h5(handle, handle[references[n, r]]) for r in (0, 1, first, first + 1, first + 2))
            _check_frame(rows, x, y, u, v, types)
    assert frames[1].u[0] == frames[0].u[0] + 1  # frame order kept: the second frame is shifted by one


def _gui(**changes) -> dict:
    raw = scipy.io.loadmat(FIXTURES / "pivlab_3.13_gui_current_frame_v5.mat")
    variables = {k: v for k, v in raw.items() if not k.startswith("__")}
    variables.update(changes)
    return variables


@pytest.mark.parametrize("changes, message", [
    ({"units": "[m] respectively [m/frame]"}, "velocities in m/frame"),
    ({"units": "[mm] respectively [mm/s]"}, "the units variable is none of PIVlab's: '.px. respectively .px/frame.' "
                                            "or '.m. respectively .m/s.'"),
    ({"u_filtered": np.zeros((0, 0))}, r"frame 1: u_filtered empty \(PIVlab fills the filtered field only for frames"),
    ({"typevector_filtered": np.full((3, 4), 5.0)}, "frame 1: vector 1 has a vector type PIVlab does not write"),
    ({"v_filtered": np.zeros((2, 4))}, "frame 1: arrays of different shapes"),
])
def test_a_pivlab_mat_file_siloflow_cannot_read_right_is_refused_naming_why(tmp_path, changes, message):
    path = tmp_path / "PIVlab.mat"
    scipy.io.savemat(path, _gui(**changes))
    with pytest.raises(PivFormatError, match=f"PIVlab.mat: {message}"):
        read_pivlab_mat(path)


# ---------------------------------------------------------------------------------------------- DaVis


def _davis_raw(path: Path):
    lvpyio = pytest.importorskip("lvpyio", reason="DaVis files need the optional extra siloflow[davis]")
    return lvpyio.read_buffer(str(path))[0]


def _scaled(frame, name: str, axis_slope: float) -> np.ndarray:
    """A stored component through the intensity scale, along its axis (DaVis' convention, as lvpyio documents)."""
    i = frame.scales.i
    return (i.offset + frame.components[name].planes[0].astype(float) * i.slope) * np.sign(axis_slope)


@pytest.mark.parametrize("choice", ["active", "first"])
def test_a_davis_field_with_every_vector_choice(choice):
    path = FIXTURES / "davis_urban_canopy_B00001_4x5.vc7"
    frame = _davis_raw(path)
    (rows,) = read_davis(path, choice)
    comp = {k: frame.components[k].planes[0] for k in ("ACTIVE_CHOICE", "ENABLED", "MASK")}
    active, enabled, mask = (comp[k].ravel() for k in ("ACTIVE_CHOICE", "ENABLED", "MASK"))
    assert set(active.tolist()) >= {0, 1, 4} and 0 in enabled and 0 in mask
    sx, sy, grid = frame.scales.x, frame.scales.y, frame.grid
    assert (sx.unit, frame.scales.i.unit) == ("mm", "m/s") and sy.slope < 0
    j, i = np.meshgrid(np.arange(4), np.arange(5), indexing="ij")
    assert rows.x == pytest.approx(1e-3 * ((i.ravel() + 0.5) * grid.x * sx.slope + sx.offset), rel=1e-12)
    assert rows.y == pytest.approx(1e-3 * ((j.ravel() + 0.5) * grid.y * sy.slope + sy.offset), rel=1e-12)
    assert rows.pixels is False and not rows.y_down
    # the peak each vector takes: the active one (4 and 5, filled or smoothed, in the last peak's slot), or the first
    slot = np.where(active >= 4, frame.choices - 1, active) if choice == "active" else np.zeros_like(active)
    u = np.choose(slot, [_scaled(frame, f"U{c}", sx.slope).ravel() for c in range(4)])
    v = np.choose(slot, [_scaled(frame, f"V{c}", sy.slope).ravel() for c in range(4)])
    usable = (enabled == 1) & (mask == 1)
    assert rows.u[usable] == pytest.approx(u[usable], rel=1e-12)
    assert rows.v[usable] == pytest.approx(v[usable], rel=1e-12)
    if choice == "active":
        by_choice = {0: "measured", 1: "second_peak", 2: "second_peak", 3: "second_peak", 4: "interpolated",
                     5: "interpolated"}
    else:
        by_choice = {0: "measured", 1: "invalid", 2: "invalid", 3: "invalid", 4: "invalid", 5: "invalid"}
    assert kinds(rows) == ["masked" if m == 0 else "invalid" if e == 0 else by_choice[a]
                           for a, e, m in zip(active, enabled, mask)]


def test_a_stereo_davis_field_is_refused_or_its_third_component_kept_apart():
    path = FIXTURES / "davis_3C_3x3.vc7"
    frame = _davis_raw(path)
    assert "W0" in frame.components
    with pytest.raises(PivFormatError, match="davis_3C_3x3.vc7: a stereo field of three velocity components"):
        read_davis(path)
    (rows,) = read_davis(path, out_of_plane="keep")
    active = frame.components["ACTIVE_CHOICE"].planes[0].ravel()
    assert set(active.tolist()) == {0}
    w = _scaled(frame, "W0", frame.scales.z.slope).ravel()
    assert rows.out_of_plane == pytest.approx(w, rel=1e-12)
    assert rows.u == pytest.approx(_scaled(frame, "U0", frame.scales.x.slope).ravel(), rel=1e-12)


def _davis_variant(tmp_path: Path, change) -> Path:
    """The urban-canopy fixture with ``change(frame)`` applied, written back by lvpyio."""
    lvpyio = pytest.importorskip("lvpyio", reason="DaVis files need the optional extra siloflow[davis]")
    buffer = lvpyio.read_buffer(str(FIXTURES / "davis_urban_canopy_B00001_4x5.vc7"))
    change(lvpyio, buffer[0])
    path = tmp_path / "B00001.vc7"
    lvpyio.write_buffer(buffer, str(path))
    return path


def test_an_uncalibrated_davis_field_is_in_pixels_with_y_down(tmp_path):
    def uncalibrated(lvpyio, frame):
        frame.scales = lvpyio.Scales(lvpyio.Scale(1.0, 0.0, "pixel", ""), lvpyio.Scale(1.0, 0.0, "pixel", ""),
                                     frame.scales.z, lvpyio.Scale(1.0, 0.0, "pixel", ""))

    (rows,) = read_davis(_davis_variant(tmp_path, uncalibrated))
    assert rows.pixels is True and rows.y_down
    assert rows.x[:2].tolist() == [8.0, 24.0] and rows.y[[0, 5]].tolist() == [8.0, 24.0]  # (i + 0.5) 16 px


@pytest.mark.parametrize("length, speed, units", [
    ("mm", "mm", "units mm and mm"),
    # units this reader does not know are the file's text: not quoted
    ("SECRET_TOKEN=abc", "m/s", "a length or velocity unit this reader does not know"),
])
def test_davis_units_other_than_pixels_or_metres_are_refused_quoting_only_known_units(tmp_path, length, speed, units):
    def other_units(lvpyio, frame):
        scales = frame.scales
        frame.scales = lvpyio.Scales(lvpyio.Scale(scales.x.slope, scales.x.offset, length, ""), scales.y, scales.z,
                                     lvpyio.Scale(scales.i.slope, scales.i.offset, speed, ""))

    path = _davis_variant(tmp_path, other_units)
    with pytest.raises(PivFormatError) as raised:
        read_davis(path)
    assert str(raised.value) == f"{path}: {units}; expected pixel, or mm or m with m/s or mm/s"


def test_a_davis_active_choice_davis_does_not_write_is_refused(tmp_path):
    def odd(lvpyio, frame):
        frame.components["ACTIVE_CHOICE"].planes[0][0, 0] = 7

    with pytest.raises(PivFormatError, match=r"B00001.vc7: vector 1 \(row by row\) has an active choice DaVis does "
                                             r"not write; DaVis writes 0 to 3"):
        read_davis(_davis_variant(tmp_path, odd))


def test_a_davis_image_is_not_a_vector_field(tmp_path):
    lvpyio = pytest.importorskip("lvpyio", reason="DaVis files need the optional extra siloflow[davis]")
    path = tmp_path / "B00001.im7"
    lvpyio.write_buffer(lvpyio.arrays_to_buffer(np.zeros((4, 4), dtype=np.uint16)), str(path))
    with pytest.raises(PivFormatError, match="B00001.im7: an image frame, not vectors"):
        read_davis(path)
