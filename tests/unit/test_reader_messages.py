"""The readers' messages on hostile files: a configuration may point a reader at any file (/proc/self/environ, a key
file), so every message names the file, the place in it and what was expected, and never quotes what the file holds.
Each file below holds a secret-looking token where the reader fails; the message must be exactly the one given, and
so without the token."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.io

from siloflow.analysis.io import piv_base
from siloflow.analysis.io.measured_piv import measured_piv_paths
from siloflow.analysis.io.piv import PivFormatError, read_piv_file
from siloflow.analysis.io.piv_base import not_a_number
from siloflow.analysis.studies.silo_flat.measured import MeasurementFormatError, read_measured_profiles

SECRET = "SECRET_TOKEN=abc"
#: /proc/self/environ's layout: NAME=value entries separated by NUL bytes, no line end.
ENVIRON = f"{SECRET}\x00SHELL=/bin/sh\x00HOME=/root\x00"
OPENPIV_HEADERS = ("'# x y u v s2n mask' (windef.save of 0.21 to 0.23.3, tools.save of 0.23.0 to 0.23.3); "
                   "'# x y u v mask' (tools.save of 0.23.4 to 0.24.2); '# x y u v flags mask' (tools.save of 0.24.4 "
                   "onwards)")
PIVLAB_INFO = "PIVlab, ASCII chart output - 28-Nov-2026\n"
PIVLAB_FRAME = ("FRAME: 1, filenames: a.bmp & b.bmp, conversion factor xy (px -> m): {xy}, conversion factor uv "
                "(px/frame -> m/s): 1\n")
PIVLAB_HEADER = "x [px],y [px],u [px/frame],v [px/frame],Vector type [-]\n"


def _refusal(error_type, call, *args) -> str:
    with pytest.raises(error_type) as raised:
        call(*args)
    message = str(raised.value)
    assert SECRET.lower() not in message.lower()
    return message


# ---------------------------------------------------------------------------------------------- numpy's message


@pytest.mark.parametrize("error, lines, phrase", [
    # numpy counts the row of a value from 0 and its column from 1: row 1 is the second data line, line 7 of the file
    ("could not convert string 'A=b' to float64 at row 1, column 2.", [3, 7], "line 7, column 2 is not a number"),
    # the text numpy quotes may itself read like a place: only the place at the message's end counts
    ("could not convert string 'x at row 99, column 9.' to float64 at row 0, column 1.", [2],
     "line 2, column 1 is not a number"),
    # numpy counts the row whose count of values changed from 1
    ("the number of columns changed from 5 to 6 at row 2; use `usecols` to select a subset and avoid this error",
     [1, 4], "line 4 holds 6 values where the lines before it hold 5"),
    (f"could not convert string to float: '{SECRET}'", [1], "a value is not a number"),
])
def test_numpys_error_becomes_the_place_in_the_file_without_the_text_found_there(error, lines, phrase):
    assert not_a_number(ValueError(error), lines) == phrase


# ---------------------------------------------------------------------------------------------- PIV text readers


@pytest.mark.parametrize("file_format, content, message", [
    ("csv", f"x_m,z_m,u_m_s,w_m_s,valid\n0,0,1,1,1\n{ENVIRON}", "line 3 holds 1 value where the lines before it "
                                                                  "hold 5"),
    ("csv", f"x_m,z_m,u_m_s,w_m_s,valid\n{ENVIRON},1,1,1,1\n", "line 2, column 1 is not a number"),
    ("csv", f"x_m,z_m,u_m_s,w_m_s,valid\n\n# a comment\n0,0,1,{SECRET},1\n", "line 4, column 4 is not a number"),
    ("csv", f"{SECRET},z_m\n0,0,1,1,1\n", "the header on line 1 has 2 names (not all siloflow's); siloflow's is "
                                          "x_m,z_m,u_m_s,w_m_s,valid"),
    ("csv", ENVIRON, "the header on line 1 has 1 name (not all siloflow's); siloflow's is x_m,z_m,u_m_s,w_m_s,valid"),
    ("openpiv", f"# x y u v flags mask\n16 16 1 1 0 0\n{SECRET} 48 1 1 0 0\n", "line 3, column 1 is not a number"),
    ("openpiv", ENVIRON, "line 1, column 1 is not a number"),
    ("openpiv", f"16 16 1 1 0\n16 48 1 1 0 {SECRET}\n", "line 2 holds 6 values where the lines before it hold 5"),
    ("openpiv", f"# x y u v {SECRET}\n16 16 1 1 0\n",
     f"the header on line 1 has 5 names (not all OpenPIV's), none of OpenPIV's: {OPENPIV_HEADERS}"),
    ("pivlab_txt", f"{PIVLAB_INFO}{SECRET}\n1,2,3,4\n",
     "line 2 is neither PIVlab's information lines, its header nor numbers"),
    ("pivlab_txt", f"{PIVLAB_INFO}{PIVLAB_FRAME.format(xy=1)}{PIVLAB_HEADER}16,16,1,1,1\n16,48,1,{SECRET},1\n",
     "line 5, column 4 is not a number"),
    ("pivlab_txt", f"{PIVLAB_INFO}x [px],y [px],{SECRET} [px/frame],v [px/frame],Vector type [-]\n16,16,1,1,1\n"
                   "16,48,1,1,1\n",
     "the header on line 2 has 5 names (not all PIVlab's) over 5 columns; PIVlab's begin x, y, u, v (then the "
     "vector type since 2.44)"),
    ("pivlab_txt", f"x [{SECRET}],y [px],u [px/frame],v [px/frame],Vector type [-]\n16,16,1,1,1\n16,48,1,1,1\n",
     "the header on line 1 gives units of x and u that are not PIVlab's; PIVlab writes px with px/frame or m with "
     "m/s"),
    ("pivlab_txt", f"{PIVLAB_INFO}{PIVLAB_FRAME.format(xy=SECRET)}{PIVLAB_HEADER}16,16,1,1,1\n16,48,1,1,1\n",
     "line 2: the conversion factors xy and uv are not both numbers"),
])
def test_a_text_piv_file_is_refused_by_line_and_column_without_quoting_it(tmp_path, file_format, content, message):
    path = tmp_path / "environ"
    path.write_text(content)
    assert _refusal(PivFormatError, read_piv_file, path, file_format) == f"{path}: {message}"


def test_bytes_that_are_not_utf8_are_placed_not_quoted(tmp_path):
    path = tmp_path / "field.txt"
    path.write_bytes(b"16 16 1 1 0\n\xff\xfe" + SECRET.encode() + b" 48 1 1 0\n")
    assert _refusal(PivFormatError, read_piv_file, path, "openpiv") == f"{path}: line 2, column 1 is not a number"


# ---------------------------------------------------------------------------------------------- PIV MATLAB, DaVis

GRID = np.array([[16.0, 48.0], [16.0, 48.0]])
TYPES = np.ones((2, 2))


def _gui(**changes) -> dict:
    variables = {"x": GRID, "y": GRID.T, "u_original": TYPES, "v_original": TYPES, "typevector_original": TYPES,
                 "u_filtered": TYPES, "v_filtered": TYPES, "typevector_filtered": TYPES,
                 "units": "[px] respectively [px/frame]"}
    variables.update(changes)
    return variables


def _cells(*frames) -> np.ndarray:
    cells = np.empty((len(frames), 1), dtype=object)
    for n, frame in enumerate(frames):
        cells[n, 0] = frame
    return cells


@pytest.mark.parametrize("variables, message", [
    (_gui(units=SECRET), "the units variable is none of PIVlab's: '[px] respectively [px/frame]' or '[m] "
                         "respectively [m/s]'"),
    (_gui(u_filtered=SECRET), "u_filtered is not numeric"),
    ({name: _cells(TYPES, SECRET if name == "u_filt" else TYPES) for name in
      ("x", "y", "u", "v", "typevector", "u_filt", "v_filt", "typevector_filt")}, "u_filt{2} is not numeric"),
])
def test_a_matlab_variable_of_text_is_refused_without_quoting_it(tmp_path, variables, message):
    path = tmp_path / "PIVlab.mat"
    scipy.io.savemat(path, variables)
    assert _refusal(PivFormatError, read_piv_file, path, "pivlab_mat") == f"{path}: {message}"


@pytest.mark.parametrize("file_format, message", [
    # scipy's own message would quote two of the file's bytes as its version ("version 61, 97")
    ("pivlab_mat", "not a MATLAB file (5 to 7.3) that scipy.io or h5py can read"),
    ("davis", "not a DaVis buffer or set that lvpyio can read (a set is a .set file next to its folder of the same "
              "name)"),
])
def test_a_binary_piv_file_of_another_kind_is_refused_naming_it_alone(tmp_path, file_format, message):
    if file_format == "davis":
        pytest.importorskip("lvpyio", reason="DaVis files need the optional extra siloflow[davis]")
    path = tmp_path / ("field.mat" if file_format == "pivlab_mat" else "field.vc7")
    path.write_text(ENVIRON * 20)
    assert _refusal(PivFormatError, read_piv_file, path, file_format) == f"{path}: {message}"


# ---------------------------------------------------------------------------------------------- folders, permissions


@pytest.mark.parametrize("file_format", ["openpiv", "pivlab_txt", "pivlab_mat", "csv"])
def test_a_folder_is_refused_as_a_folder(tmp_path, file_format):
    folder = tmp_path / "pivdir"
    folder.mkdir()
    assert _refusal(PivFormatError, read_piv_file, folder, file_format) == f"{folder}: a folder, not a file"


@pytest.mark.parametrize("file_format", ["openpiv", "pivlab_txt", "pivlab_mat", "csv"])
def test_a_file_that_cannot_be_read_says_why_in_the_systems_words(tmp_path, monkeypatch, file_format):
    path = tmp_path / "shadow"
    path.write_text(SECRET)

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))

    # the tests may run as root, whom no file mode stops: the system's refusal is stood in for
    monkeypatch.setattr(type(path), "read_text", denied)
    monkeypatch.setattr(piv_base, "open", denied, raising=False)
    assert _refusal(PivFormatError, read_piv_file, path, file_format) == f"{path}: cannot be read (permission denied)"


def test_a_pattern_that_matches_a_folder_is_refused_naming_the_pattern(tmp_path):
    (tmp_path / "pivdir").mkdir()
    (tmp_path / "piv_0001.txt").write_text("16 16 1 1 0\n")
    (tmp_path / "piv_old").mkdir()
    (tmp_path / "piv_older").mkdir()
    where = "silo_flat.piv.measured.files"
    with pytest.raises(ValueError) as raised:
        measured_piv_paths(["pivdir"], tmp_path)
    assert str(raised.value) == f"{where}: 'pivdir' matches a folder, not a file"
    with pytest.raises(ValueError) as raised:
        measured_piv_paths(["piv_0001.txt", "piv_*"], tmp_path)
    assert str(raised.value) == (f"{where}: 'piv_*' matches a folder, not a file: {tmp_path / 'piv_old'} (and 1 more "
                                 "folder(s))")
    assert measured_piv_paths(["piv_*.txt"], tmp_path) == [tmp_path / "piv_0001.txt"]


# ---------------------------------------------------------------------------------------------- measured profiles

PROFILE_HEADER = "# PIV at the front wall\nz_m,x_m,window,v_z_m_s,v_x_m_s,uncertainty_m_s\n"


@pytest.mark.parametrize("content, message", [
    (f"{PROFILE_HEADER}0.12,0.0,0.5-0.7,-0.04,0.0,\n\n0.12,0.01,0.5-0.7,{SECRET},0.0,\n",
     "line 5, column v_z_m_s is not a number"),
    (f"{PROFILE_HEADER}0.12,0.0,0.5-0.7,-0.04,0.0,{SECRET}\n", "line 3, column uncertainty_m_s is not a number"),
    (f"{PROFILE_HEADER}0.12,0.0,0.5-0.7,-0.04,inf,\n", "line 3, column v_x_m_s is not finite"),
    pytest.param(f"{PROFILE_HEADER}0.12,{SECRET * 10000},0.5-0.7,-0.04,0.0,\n", "line 3 is not CSV",
                 id="beyond-the-csv-field-limit"),
    (ENVIRON, "missing column(s) z_m, x_m, window, v_z_m_s, v_x_m_s, uncertainty_m_s; expected "
              "z_m,x_m,window,v_z_m_s,v_x_m_s,uncertainty_m_s"),
])
def test_a_measured_profile_file_is_refused_by_line_and_column_without_quoting_it(tmp_path, content, message):
    path = tmp_path / "profiles.csv"
    path.write_text(content)
    assert _refusal(MeasurementFormatError, read_measured_profiles, path) == f"{path}: {message}"


def test_a_measured_profile_path_that_is_a_folder_or_not_utf8_is_refused_naming_it(tmp_path):
    assert _refusal(MeasurementFormatError, read_measured_profiles, tmp_path) == f"{tmp_path}: a folder, not a file"
    path = tmp_path / "profiles.csv"
    path.write_bytes(PROFILE_HEADER.encode() + b"\xff" + SECRET.encode() + b"\n")
    assert _refusal(MeasurementFormatError, read_measured_profiles, path) == f"{path}: line 3 is not UTF-8 text"
