"""One validity policy and one set of units and axes across PIV programs: the configuration's valid kinds, a file's
units against the configuration's, metres that must be silo coordinates, a calibrated PIVlab export against the same
result in pixels with wall markers, and the schema's defaults against the code's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from siloflow.analysis.io.measured_piv import load_measured_piv
from siloflow.analysis.io.piv import PivReadOptions, read_options, read_pivlab_txt
from siloflow.analysis.piv.calibration import ImageScale
from siloflow.analysis.piv.field import (
    DEFAULT_VALID_KINDS,
    INTERPOLATED,
    MEASURED,
    NODE_KINDS,
    SECOND_PEAK,
    UNFLAGGED,
    PivRows,
    PlanarField,
    field_from_rows,
    kind_codes,
)
from siloflow.analysis.piv.measured import MeasuredPiv, measured_fields, measured_piv_settings
from siloflow.engines.config import ConfigError, validate_config

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "piv"


def _measured(**changes) -> dict:
    """A validated silo_flat.piv.measured section with ``changes``."""
    section = validate_config({"silo_flat": {"piv": {"measured": changes}}})
    return section["silo_flat"]["piv"]["measured"]


def test_the_schema_defaults_are_the_readers_and_the_policys_defaults():
    measured = _measured()
    assert read_options(measured) == PivReadOptions() == read_options({})
    assert tuple(measured["valid"]) == DEFAULT_VALID_KINDS == ("measured", "second_peak")
    assert MeasuredPiv(False, None, 100.0).valid_kinds == DEFAULT_VALID_KINDS


def test_the_reading_options_come_from_the_configuration():
    options = read_options(_measured(y_down=False, openpiv={"fifth_column": "sig2noise", "sig2noise_threshold": 1.3},
                                     pivlab={"field": "original"}, davis={"choice": "first", "out_of_plane": "keep"}))
    assert options == PivReadOptions(False, "sig2noise", 1.3, "original", "first", "keep")


@pytest.mark.parametrize("section, key", [
    ({"valid": ["measured", "masked"]}, "valid"),
    ({"valid": []}, "valid"),
    ({"pivlab": {"field": "smoothed"}}, "field"),
    ({"davis": {"choice": "second"}}, "choice"),
    ({"openpiv": {"fifth_column": "flags"}}, "fifth_column"),
])
def test_a_policy_or_option_the_schema_does_not_know_is_refused_before_anything_runs(section, key):
    with pytest.raises(ConfigError, match=key):
        _measured(**section)


def _frame() -> PivRows:
    """3 x 4 vectors 32 px apart, 2 px right and 4 px down per frame, one of each kind along the top row."""
    y, x = np.mgrid[16:112:32, 16:144:32].astype(float)
    u, v = np.full(x.shape, 2.0), np.full(x.shape, 4.0)
    kind = np.full(x.shape, MEASURED, dtype=np.int8)
    kind[0, :] = kind_codes(["second_peak", "interpolated", "masked", "invalid"])
    u[0, 2:] = v[0, 2:] = np.nan
    return PivRows(x, y, u, v, kind, True, True)


SCALE = ImageScale(1e-4, -0.01, 0.05)


@pytest.mark.parametrize("valid, counted", [
    (("measured", "second_peak"), {"measured", "second_peak"}),
    (("measured",), {"measured"}),
    (("measured", "second_peak", "interpolated"), {"measured", "second_peak", "interpolated"}),
])
def test_the_configured_kinds_are_the_valid_nodes_and_the_field_records_every_kind(valid, counted):
    settings = MeasuredPiv(True, SCALE, 100.0, hampel_noise_floor=1.0, valid_kinds=valid)
    (field,) = measured_fields([_frame()], settings)
    # z is up, so the image's top row is the field's last row
    assert [NODE_KINDS[k] for k in field.kind[-1]] == ["second_peak", "interpolated", "masked", "invalid"]
    assert (field.kind[:-1] == MEASURED).all()
    assert field.valid[-1].tolist() == [k in counted for k in ("second_peak", "interpolated", "masked", "invalid")]
    assert field.valid[:-1].all()


def test_unflagged_vectors_are_refused_unless_the_policy_counts_them():
    frame = _frame()
    unflagged = PivRows(frame.x, frame.y, frame.u, frame.v, np.where(np.isfinite(frame.u), UNFLAGGED, 4), True, True)
    with pytest.raises(ValueError, match="PIVlab.txt, frame 0: 10 vector.s. without a flag .* list unflagged in "
                                         "silo_flat.piv.measured.valid"):
        measured_fields([unflagged], MeasuredPiv(True, SCALE, 100.0), "PIVlab.txt")
    (field,) = measured_fields([unflagged], MeasuredPiv(True, SCALE, 100.0, valid_kinds=("unflagged",)))
    assert field.valid.sum() == 10


def test_a_file_in_other_units_than_configured_is_refused_naming_both():
    rows = read_pivlab_txt(FIXTURES / "pivlab_3.13_calibrated_m.txt")
    with pytest.raises(ValueError, match=r"calibrated_m.txt, frame 0: the file is in metres, the configuration says "
                                         r"pixels \(silo_flat.piv.measured.units\)"):
        measured_fields([rows], MeasuredPiv(True, SCALE, 250.0), "pivlab_3.13_calibrated_m.txt")


def test_metres_with_y_down_the_image_are_refused_as_not_silo_coordinates():
    frame = _frame()
    metres_down = PivRows(frame.x * 1e-4, frame.y * 1e-4, frame.u, frame.v, frame.kind, True, False)
    with pytest.raises(ValueError, match="piv.txt, frame 0: positions in metres with y pointing down the image are "
                                         "not silo coordinates"):
        measured_fields([metres_down], MeasuredPiv(False, None, 100.0), "piv.txt")


def test_a_calibrated_pivlab_export_gives_the_field_of_the_same_result_in_pixels_with_markers(tmp_path):
    # PIVlab's calibration of the fixture: 0.25 mm/px, 4 ms between images, y increasing to the top, offsets
    # x = 0 at column 60 px and y = 0 at row 100 px of a 128 px high image; markers at two image corners say the same
    calxy, frame_rate = 2.5e-4, 250.0
    x0, z0 = -60 * calxy, 100 * calxy
    markers = [{"image": [0.0, 0.0], "silo": [x0, z0]},
               {"image": [100.0, 100.0], "silo": [x0 + 100 * calxy, z0 - 100 * calxy]}]
    pixels = _measured(files=["px"], format="pivlab_txt", units="pixels", frame_rate=frame_rate, markers=markers,
                       hampel={"threshold": 100.0})
    metres = _measured(files=["m"], format="pivlab_txt", units="metres", frame_rate=frame_rate,
                       hampel={"threshold": 100.0})
    (from_pixels,) = load_measured_piv(pixels, measured_piv_settings(pixels),
                                       [FIXTURES / "pivlab_3.13_calibrated_px.txt"])
    (from_metres,) = load_measured_piv(metres, measured_piv_settings(metres),
                                       [FIXTURES / "pivlab_3.13_calibrated_m.txt"])
    assert from_pixels.x == pytest.approx(from_metres.x, abs=1e-12)
    assert from_pixels.z == pytest.approx(from_metres.z, abs=1e-12)
    assert np.array_equal(from_pixels.valid, from_metres.valid) and np.array_equal(from_pixels.kind, from_metres.kind)
    assert from_pixels.valid.sum() == 9  # 12 nodes less the masked, the interpolated and the one left empty
    np.testing.assert_allclose(from_pixels.u, from_metres.u, rtol=1e-12, atol=0)
    np.testing.assert_allclose(from_pixels.w, from_metres.w, rtol=1e-12, atol=0)
    # and the metres are not scaled again by markers: a pixel configuration refuses the calibrated file
    with pytest.raises(ValueError, match="the file is in metres, the configuration says pixels"):
        load_measured_piv(pixels, measured_piv_settings(pixels), [FIXTURES / "pivlab_3.13_calibrated_m.txt"])


def test_a_configured_pivlab_session_is_read_with_the_configured_field():
    section = _measured(files=["s"], format="pivlab_mat", frame_rate=100.0, field_interval=0.5, start_time=1.0,
                        markers=[{"image": [0.0, 0.0], "silo": [0.0, 0.1]},
                                 {"image": [100.0, 100.0], "silo": [0.01, 0.09]}],
                        pivlab={"field": "original"}, hampel={"threshold": 100.0})
    fields = load_measured_piv(section, measured_piv_settings(section), [FIXTURES / "pivlab_3.14_session_v73.mat"])
    assert [f.time for f in fields] == [1.0, 1.5]
    # the original field's types are measured or masked only: its outliers count, until the Hampel filter
    assert set(NODE_KINDS[k] for k in np.unique(fields[0].kind)) == {"measured", "masked"}
    assert fields[0].valid.sum() == 11


def test_kinds_go_onto_the_grid_with_their_nodes():
    field = field_from_rows([0.0, 1.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [1, 2, 3, 4], [5, 6, 7, 8], [1, 1, 1, 0],
                            kind=[MEASURED, SECOND_PEAK, INTERPOLATED, UNFLAGGED])
    assert field.kind.tolist() == [[INTERPOLATED, SECOND_PEAK], [MEASURED, UNFLAGGED]]
    with pytest.raises(ValueError, match="unknown PIV node kind.s. 'outlier'"):
        kind_codes(["outlier"])


def test_a_field_refuses_kinds_that_do_not_fit_its_grid():
    x, z = np.array([0.0, 1.0]), np.array([0.0])
    with pytest.raises(ValueError, match=r"kind has shape \(2,\), expected \(nz, nx\) = \(1, 2\)"):
        PlanarField(x, z, [[1.0, 2.0]], [[0.0, 0.0]], [[True, True]], kind=np.array([0, 0]))
    with pytest.raises(ValueError, match="kind holds codes other than 0 to 5"):
        PlanarField(x, z, [[1.0, 2.0]], [[0.0, 0.0]], [[True, True]], kind=np.array([[0, 9]]))
